//! The status-text queue: event messages from the vehicle and the services' explanations,
//! sent as `STATUSTEXT` to every station at the next poll, a long one in chunks.

use core::fmt::Write;

use super::peer::Dest;
use heapless::{Deque, String};
use mavlink::dialects::common::{MavMessage, MavSeverity, STATUSTEXT_DATA};

/// Longest text one STATUSTEXT carries; a longer one goes out in chunks.
pub const STATUSTEXT_LEN: usize = 50;
/// Longest status text the link keeps (three chunks).
pub const TEXT_MAX: usize = 3 * STATUSTEXT_LEN;

const TEXT_CAPACITY: usize = 8;

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

    /// Queues a formatted text; a text that does not fit is cut, never refused.
    pub fn pushf(&mut self, severity: MavSeverity, args: core::fmt::Arguments<'_>) {
        let mut s: String<TEXT_MAX> = String::new();
        let _ = s.write_fmt(args);
        self.push(severity, s);
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
