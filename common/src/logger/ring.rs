//! The bytes between the logger and the storage: a ring that takes a message whole or not at
//! all, and gives its oldest bytes as one contiguous run.

/// A ring of `N` bytes.
pub struct ByteRing<const N: usize> {
    buf: [u8; N],
    head: usize,
    len: usize,
}

impl<const N: usize> Default for ByteRing<N> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const N: usize> ByteRing<N> {
    /// An empty ring.
    pub const fn new() -> Self {
        Self {
            buf: [0; N],
            head: 0,
            len: 0,
        }
    }

    /// Bytes held.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether nothing is held.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Room left.
    pub fn free(&self) -> usize {
        N.saturating_sub(self.len)
    }

    /// Appends `bytes` whole, or nothing (`false`) if they do not fit.
    pub fn push(&mut self, bytes: &[u8]) -> bool {
        if bytes.len() > self.free() {
            return false;
        }
        let tail = (self.head.saturating_add(self.len))
            .checked_rem(N)
            .unwrap_or(0);
        let first = bytes.len().min(N.saturating_sub(tail));
        let (a, b) = bytes.split_at(first);
        if let Some(dst) = self.buf.get_mut(tail..tail.saturating_add(a.len())) {
            dst.copy_from_slice(a);
        }
        if let Some(dst) = self.buf.get_mut(..b.len()) {
            dst.copy_from_slice(b);
        }
        self.len = self.len.saturating_add(bytes.len());
        true
    }

    /// The oldest bytes, up to the end of the buffer (the rest follow from its start).
    pub fn front(&self) -> &[u8] {
        let end = self.head.saturating_add(self.len).min(N);
        self.buf.get(self.head..end).unwrap_or(&[])
    }

    /// Drops the `n` oldest bytes (at most all).
    pub fn consume(&mut self, n: usize) {
        let n = n.min(self.len);
        self.head = (self.head.saturating_add(n)).checked_rem(N).unwrap_or(0);
        self.len = self.len.saturating_sub(n);
        if self.len == 0 {
            self.head = 0;
        }
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;

    #[test]
    fn bytes_come_out_in_order_across_the_end_of_the_buffer() {
        let mut r = ByteRing::<8>::new();
        assert!(r.push(&[1, 2, 3, 4, 5]));
        r.consume(4);
        assert!(r.push(&[6, 7, 8, 9, 10, 11]));
        assert_eq!(r.len(), 7);
        let mut out = std::vec::Vec::new();
        while !r.is_empty() {
            let f = r.front().to_vec();
            out.extend_from_slice(&f);
            r.consume(f.len());
        }
        assert_eq!(out, [5, 6, 7, 8, 9, 10, 11]);
    }

    #[test]
    fn a_message_that_does_not_fit_is_refused_whole() {
        let mut r = ByteRing::<8>::new();
        assert!(r.push(&[0; 6]));
        assert!(!r.push(&[1; 3]));
        assert_eq!(r.len(), 6);
        assert!(r.push(&[1; 2]));
        assert_eq!(r.free(), 0);
    }
}
