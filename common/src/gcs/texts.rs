//! The status-text queue: event messages from the vehicle and the services' explanations,
//! sent as `STATUSTEXT` to every station at the next poll, a long one in chunks.

use super::peer::Dest;
use heapless::{Deque, String};
use mavlink::dialects::common::{MavMessage, MavSeverity, STATUSTEXT_DATA};

/// Longest text one STATUSTEXT carries; a longer one goes out in chunks.
pub const STATUSTEXT_LEN: usize = 50;
/// Longest status text the link keeps (three chunks).
pub const TEXT_MAX: usize = 3 * STATUSTEXT_LEN;

const TEXT_CAPACITY: usize = 8;

/// A text built from pieces without `core::fmt`: the status texts, the file listings and the
/// boot text of the MCU image. `write!` into a `heapless::String` brought `core::fmt`'s
/// machinery into the image (its `write`, padding, integer formatting and the `String`
/// writers: some 3 KB with `Decimal`'s `Display`) for a few dozen short texts. As `write!`
/// does, each piece is taken whole, and once one does not fit nothing more is.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Line<const N: usize> {
    text: String<N>,
    cut: bool,
}

impl<const N: usize> Line<N> {
    /// An empty text.
    pub fn new() -> Self {
        Self {
            text: String::new(),
            cut: false,
        }
    }

    /// Appends `piece` (what `{}` of a `&str` and a format's literal text write). Not
    /// inlined, nor are the other pieces: a text is a row of calls.
    #[inline(never)]
    pub fn str(&mut self, piece: &str) -> &mut Self {
        let _ = self.put(piece);
        self
    }

    /// Appends `v` in decimal, as `{}` writes an unsigned integer.
    #[inline(never)]
    pub fn uint(&mut self, v: u64) -> &mut Self {
        let mut buf = [0u8; 20];
        self.str(crate::decimal::digits(v, &mut buf))
    }

    /// Appends `v` as `{:#010x}` writes it: `0x`, then eight hexadecimal digits, the leading
    /// zeros one by one as the padding.
    pub fn hex8(&mut self, v: u32) -> &mut Self {
        const HEX: &[u8; 16] = b"0123456789abcdef";
        let mut buf = [b'0'; 8];
        for (i, d) in buf.iter_mut().rev().enumerate() {
            let nibble = v.checked_shr((i as u32).saturating_mul(4)).unwrap_or(0) & 0xf;
            *d = HEX.get(nibble as usize).copied().unwrap_or(b'0');
        }
        // The digits `{:x}` writes (one at least), after as many padding zeros as they lack.
        let significant = (u32::BITS.saturating_sub(v.leading_zeros()))
            .div_ceil(4)
            .max(1) as usize;
        let padding = buf.len().saturating_sub(significant);
        self.str("0x");
        for _ in 0..padding {
            self.str("0");
        }
        let digits = buf
            .get(padding..)
            .and_then(|d| core::str::from_utf8(d).ok());
        self.str(digits.unwrap_or(""))
    }

    /// Appends `d` as its `Display` writes it.
    #[inline(never)]
    pub fn decimal(&mut self, d: crate::decimal::Decimal) -> &mut Self {
        let _ = d.write_with(&mut |piece| self.put(piece));
        self
    }

    fn put(&mut self, piece: &str) -> Result<(), ()> {
        if self.cut || self.text.push_str(piece).is_err() {
            self.cut = true;
            return Err(());
        }
        Ok(())
    }

    /// Whether a piece did not fit (what `write!` answers with an error).
    pub fn is_cut(&self) -> bool {
        self.cut
    }

    /// The text.
    pub fn as_str(&self) -> &str {
        self.text.as_str()
    }

    /// The text, to keep.
    pub fn into_string(self) -> String<N> {
        self.text
    }
}

/// A STATUSTEXT waiting to be sent.
#[derive(Clone, Debug, PartialEq)]
struct Text {
    severity: MavSeverity,
    text: String<TEXT_MAX>,
}

/// Status texts waiting for the next poll.
#[derive(Clone, Debug, Default)]
pub struct TextQueue {
    texts: Deque<Text, TEXT_CAPACITY>,
    /// The `id` of the last status text sent in chunks.
    text_id: u16,
    dropped: u32,
}

impl TextQueue {
    /// An empty queue.
    pub fn new() -> Self {
        Self::default()
    }

    /// Queues `text`, cut to [`TEXT_MAX`] bytes at a character boundary; dropped (and
    /// counted) when the queue is full.
    pub fn push_str(&mut self, severity: MavSeverity, text: &str) {
        let mut s = String::new();
        for c in text.chars() {
            if s.push(c).is_err() {
                break;
            }
        }
        self.push(severity, s);
    }

    /// Queues a text built by pieces ([`Line`]); one that did not fit is cut, never refused.
    pub fn push_line(&mut self, severity: MavSeverity, line: Line<TEXT_MAX>) {
        self.push(severity, line.into_string());
    }

    fn push(&mut self, severity: MavSeverity, text: String<TEXT_MAX>) {
        if self.texts.push_back(Text { severity, text }).is_err() {
            self.dropped = self.dropped.wrapping_add(1);
        }
    }

    /// Texts dropped because the queue was full.
    pub fn dropped(&self) -> u32 {
        self.dropped
    }

    /// Sends every queued text to every station, in the order queued.
    pub fn drain<F: FnMut(Dest, MavMessage)>(&mut self, out: &mut F) {
        while let Some(t) = self.texts.pop_front() {
            let bytes = t.text.as_bytes();
            if bytes.len() <= STATUSTEXT_LEN {
                let text = MavMessage::STATUSTEXT(STATUSTEXT_DATA {
                    severity: t.severity,
                    text: t.text.as_str().into(),
                    id: 0,
                    chunk_seq: 0,
                });
                out(Dest::All, text);
                continue;
            }
            // Chunks of one text share a non-zero id; the last is shorter than 50 bytes (its
            // NUL ends the text), an empty one when the text fills its chunks exactly.
            self.text_id = self.text_id.wrapping_add(1).max(1);
            let chunks = (bytes.len() / STATUSTEXT_LEN).saturating_add(1);
            for (seq, start) in (0..chunks).map(|i| (i, i.saturating_mul(STATUSTEXT_LEN))) {
                let part = bytes.get(start..).unwrap_or(&[]);
                let part = part.get(..STATUSTEXT_LEN).unwrap_or(part);
                let mut text = [0u8; STATUSTEXT_LEN];
                for (d, b) in text.iter_mut().zip(part) {
                    *d = *b;
                }
                let chunk = MavMessage::STATUSTEXT(STATUSTEXT_DATA {
                    severity: t.severity,
                    text: text.into(),
                    id: self.text_id,
                    chunk_seq: seq as u8,
                });
                out(Dest::All, chunk);
            }
        }
    }
}
