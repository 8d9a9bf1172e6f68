//! Bytes written into a caller's buffer with every step checked: a ULog message is built in
//! one and sent whole, or not at all.

// Lengths here come from names and texts: every operation on them is checked.
#![cfg_attr(not(test), deny(clippy::arithmetic_side_effects))]

/// The message did not fit the buffer, or a ULog message (at most 65,535 payload bytes).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TooLong;

impl core::fmt::Display for TooLong {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str("ULog message longer than its buffer")
    }
}

impl core::error::Error for TooLong {}

/// Bytes written into a caller's buffer, checked at every step.
pub struct Cursor<'a> {
    buf: &'a mut [u8],
    len: usize,
    overflow: bool,
}

impl<'a> Cursor<'a> {
    /// Writes from the start of `buf`.
    pub fn new(buf: &'a mut [u8]) -> Self {
        Self {
            buf,
            len: 0,
            overflow: false,
        }
    }

    /// Appends `bytes`, or marks the cursor overflowed (and writes nothing more).
    pub fn put(&mut self, bytes: &[u8]) -> &mut Self {
        let end = self.len.checked_add(bytes.len());
        match end.and_then(|end| self.buf.get_mut(self.len..end).map(|d| (d, end))) {
            Some((dst, end)) if !self.overflow => {
                dst.copy_from_slice(bytes);
                self.len = end;
            }
            _ => self.overflow = true,
        }
        self
    }

    /// Appends one byte.
    pub fn u8(&mut self, v: u8) -> &mut Self {
        self.put(&[v])
    }

    /// Appends a `u16`, little-endian.
    pub fn u16(&mut self, v: u16) -> &mut Self {
        self.put(&v.to_le_bytes())
    }

    /// Appends a `u32`, little-endian.
    pub fn u32(&mut self, v: u32) -> &mut Self {
        self.put(&v.to_le_bytes())
    }

    /// Appends a `u64`, little-endian.
    pub fn u64(&mut self, v: u64) -> &mut Self {
        self.put(&v.to_le_bytes())
    }

    /// Appends an `i8`.
    pub fn i8(&mut self, v: i8) -> &mut Self {
        self.put(&v.to_le_bytes())
    }

    /// Appends an `i16`, little-endian.
    pub fn i16(&mut self, v: i16) -> &mut Self {
        self.put(&v.to_le_bytes())
    }

    /// Appends an `i32`, little-endian.
    pub fn i32(&mut self, v: i32) -> &mut Self {
        self.put(&v.to_le_bytes())
    }

    /// Appends an `f32`, little-endian.
    pub fn f32(&mut self, v: f32) -> &mut Self {
        self.put(&v.to_le_bytes())
    }

    /// Appends an `f64`, little-endian.
    pub fn f64(&mut self, v: f64) -> &mut Self {
        self.put(&v.to_le_bytes())
    }

    /// Appends a `bool` as one byte (0 or 1).
    pub fn bool(&mut self, v: bool) -> &mut Self {
        self.u8(u8::from(v))
    }

    /// Appends `f32`s.
    pub fn f32s(&mut self, v: &[f32]) -> &mut Self {
        for x in v {
            self.f32(*x);
        }
        self
    }

    /// Appends a number in decimal ASCII (array lengths and string lengths of format keys).
    pub fn decimal(&mut self, v: usize) -> &mut Self {
        let mut digits = [0u8; 20];
        let mut n = v;
        let mut i = digits.len();
        while let Some(j) = i.checked_sub(1) {
            i = j;
            if let Some(d) = digits.get_mut(i) {
                // `n % 10` < 10: the cast and the addition cannot overflow.
                *d = b'0'.saturating_add((n % 10) as u8);
            }
            n /= 10;
            if n == 0 {
                break;
            }
        }
        match digits.get(i..) {
            Some(d) => self.put(d),
            None => self,
        }
    }

    /// Marks what is written as refused (a part of the message that cannot be encoded).
    pub fn refuse(&mut self) {
        self.overflow = true;
    }

    /// Bytes written so far.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether nothing was written.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The bytes written, or [`TooLong`] if anything did not fit.
    pub fn finish(&self) -> Result<usize, TooLong> {
        if self.overflow {
            Err(TooLong)
        } else {
            Ok(self.len)
        }
    }
}
