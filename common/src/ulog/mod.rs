//! ULog, PX4's flight-log format: the encoder the on-board log is written with.
//!
//! A ULog file is a 16-byte header, then messages, each `msg_size: u16 LE`, `msg_type: u8` and
//! `msg_size` bytes of payload, every number little-endian and nothing aligned:
//!
//! ```text
//! header      "ULog" 0x01 0x12 0x35, version 1, timestamp u64 (us)
//! definitions 'B' flag bits (first, 40 bytes), 'F' formats, 'I' info, 'P' parameters
//! data        'A' subscriptions, 'D' data, 'L' texts, 'S' sync, 'O' dropouts
//! ```
//!
//! A format is text (`vehicle_attitude:uint64_t timestamp;float[4] q;`), its first field
//! always `uint64_t timestamp`, which [`Format`] writes itself so no topic can leave it out.
//! pyulog, PlotJuggler, Flight Review and QGroundControl read topics by these names and
//! fields, which is why the topics keep PX4's where one exists.
//!
//! Every function here encodes one whole message into a caller's buffer and returns its
//! length, or [`TooLong`] with nothing to send: the log's storage takes a message whole or not
//! at all, so a full buffer never leaves half a message in the file.
//!
//! The format is PX4's published specification ("ULog File Format", docs.px4.io); nothing
//! maintained encodes it without `std` and a heap, so the few lines of byte layout are here.

// Lengths here come from names and texts: every operation on them is checked.
#![cfg_attr(not(test), deny(clippy::arithmetic_side_effects))]

pub mod cursor;
pub mod topic;

pub use cursor::{Cursor, TooLong};
use topic::Value;
pub use topic::{Field, Format, Ty};

/// The file's first seven bytes.
pub const MAGIC: [u8; 7] = [b'U', b'L', b'o', b'g', 0x01, 0x12, 0x35];
/// The format version this encoder writes.
pub const VERSION: u8 = 1;
/// Bytes of the file header.
pub const HEADER_LEN: usize = 16;
/// Bytes of a message's own header (`msg_size`, `msg_type`).
pub const MSG_HEADER_LEN: usize = 3;
/// The sync message's payload: a reader that lost its place finds the next message after it.
pub const SYNC_MAGIC: [u8; 8] = [0x2F, 0x73, 0x13, 0x20, 0x25, 0x0C, 0xBB, 0x12];

/// The message types this encoder writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub enum MsgType {
    /// Compatibility flags; the first message after the header.
    FlagBits = b'B',
    /// A topic's format.
    Format = b'F',
    /// One key and value about the whole log (system name, software version, ...).
    Info = b'I',
    /// A parameter's value at the start of the log.
    Parameter = b'P',
    /// A subscription: a message id for one instance of a format.
    AddLogged = b'A',
    /// One sample of a subscribed topic.
    Data = b'D',
    /// A text, with its level and time.
    Logging = b'L',
    /// A sync marker.
    Sync = b'S',
    /// Data lost, and for how long.
    Dropout = b'O',
}

/// Log levels of a text message (syslog's, as ULog takes them: ASCII '0'..'7').
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub enum Level {
    /// The system is unusable.
    Emergency = b'0',
    /// Act at once.
    Alert = b'1',
    /// A critical condition.
    Critical = b'2',
    /// An error.
    Error = b'3',
    /// A warning.
    Warning = b'4',
    /// Normal but significant.
    Notice = b'5',
    /// Information.
    Info = b'6',
    /// Debugging.
    Debug = b'7',
}

/// Encodes one message: its header, then what `body` writes after it, with `msg_size` the
/// count of those bytes.
pub fn message(
    buf: &mut [u8],
    kind: MsgType,
    body: impl FnOnce(&mut Cursor<'_>),
) -> Result<usize, TooLong> {
    let (head, rest) = if buf.len() >= MSG_HEADER_LEN {
        buf.split_at_mut(MSG_HEADER_LEN)
    } else {
        return Err(TooLong);
    };
    let mut c = Cursor::new(rest);
    body(&mut c);
    let size = c.finish()?;
    let size16 = u16::try_from(size).map_err(|_| TooLong)?;
    let mut h = Cursor::new(head);
    h.u16(size16).u8(kind as u8);
    h.finish()?;
    size.checked_add(MSG_HEADER_LEN).ok_or(TooLong)
}

/// The file header: magic, version and the time the log starts, in us.
pub fn header(buf: &mut [u8], timestamp_us: u64) -> Result<usize, TooLong> {
    let mut c = Cursor::new(buf);
    c.put(&MAGIC).u8(VERSION).u64(timestamp_us);
    c.finish()
}

/// The flag bits, which must follow the header: no compatibility or incompatibility flag
/// set, no appended data (the log is written front to back, never patched).
pub fn flag_bits(buf: &mut [u8]) -> Result<usize, TooLong> {
    message(buf, MsgType::FlagBits, |c| {
        c.put(&[0; 8]).put(&[0; 8]).u64(0).u64(0).u64(0);
    })
}

/// A topic's format (its fields; the timestamp first).
pub fn format(buf: &mut [u8], f: &Format) -> Result<usize, TooLong> {
    message(buf, MsgType::Format, |c| f.write_text(c))
}

/// An information message with a text value: key `char[len] name`.
pub fn info_str(buf: &mut [u8], name: &str, value: &str) -> Result<usize, TooLong> {
    message(buf, MsgType::Info, |c| {
        key(c, |k| {
            k.put(b"char[")
                .decimal(value.len())
                .put(b"] ")
                .put(name.as_bytes());
        });
        c.put(value.as_bytes());
    })
}

/// An information message with a `uint32_t` value.
pub fn info_u32(buf: &mut [u8], name: &str, value: u32) -> Result<usize, TooLong> {
    scalar(buf, MsgType::Info, name, value)
}

/// A parameter with a real value: key `float NAME`.
pub fn parameter_f32(buf: &mut [u8], name: &str, value: f32) -> Result<usize, TooLong> {
    scalar(buf, MsgType::Parameter, name, value)
}

/// A parameter with an integer value: key `int32_t NAME`.
pub fn parameter_i32(buf: &mut [u8], name: &str, value: i32) -> Result<usize, TooLong> {
    scalar(buf, MsgType::Parameter, name, value)
}

/// A keyed message with one scalar: key `TYPE NAME` (the C name a topic's field of that type
/// has), then the value.
fn scalar<V: Value>(buf: &mut [u8], kind: MsgType, name: &str, value: V) -> Result<usize, TooLong> {
    message(buf, kind, |c| {
        key(c, |k| {
            k.put(V::TY.c_name().as_bytes())
                .put(b" ")
                .put(name.as_bytes());
        });
        value.put(c);
    })
}

/// A subscription: data messages with `msg_id` are instance `multi_id` of format `name`.
pub fn add_logged(buf: &mut [u8], multi_id: u8, msg_id: u16, name: &str) -> Result<usize, TooLong> {
    message(buf, MsgType::AddLogged, |c| {
        c.u8(multi_id).u16(msg_id).put(name.as_bytes());
    })
}

/// One sample of subscription `msg_id`: the timestamp, then what `fields` writes, in the
/// order of the format's fields.
pub fn data(
    buf: &mut [u8],
    msg_id: u16,
    timestamp_us: u64,
    fields: impl FnOnce(&mut Cursor<'_>),
) -> Result<usize, TooLong> {
    message(buf, MsgType::Data, |c| {
        c.u16(msg_id).u64(timestamp_us);
        fields(c);
    })
}

/// Bytes before a sample's fields in a data message: the message's header, the message id
/// and the timestamp.
pub const DATA_HEADER_LEN: usize = MSG_HEADER_LEN + 2 + 8;

/// Writes a sample's fields where a data message holds them in `buf` (from
/// [`DATA_HEADER_LEN`] on), for [`data_in_place`] to put the header in front: their length,
/// or [`TooLong`].
pub fn data_fields(buf: &mut [u8], fields: impl FnOnce(&mut Cursor<'_>)) -> Result<usize, TooLong> {
    let mut c = Cursor::new(buf.get_mut(DATA_HEADER_LEN..).ok_or(TooLong)?);
    fields(&mut c);
    c.finish()
}

/// [`data`] with the fields already in place: they are `fields` bytes from
/// [`DATA_HEADER_LEN`] on in `buf` (or did not fit: [`TooLong`]), and the message's header,
/// id and timestamp go in front of them. The bytes are [`data`]'s; a caller that encodes its
/// sample where it stands (the logger) keeps only the fields' encoding its own.
pub fn data_in_place(
    buf: &mut [u8],
    msg_id: u16,
    timestamp_us: u64,
    fields: Result<usize, TooLong>,
) -> Result<usize, TooLong> {
    let n = fields?.checked_add(DATA_HEADER_LEN).ok_or(TooLong)?;
    if n > buf.len() {
        return Err(TooLong);
    }
    let size = u16::try_from(n.checked_sub(MSG_HEADER_LEN).ok_or(TooLong)?).map_err(|_| TooLong)?;
    let mut c = Cursor::new(buf.get_mut(..DATA_HEADER_LEN).ok_or(TooLong)?);
    c.u16(size)
        .u8(MsgType::Data as u8)
        .u16(msg_id)
        .u64(timestamp_us);
    c.finish()?;
    Ok(n)
}

/// A text with its level and time.
pub fn logging(
    buf: &mut [u8],
    level: Level,
    timestamp_us: u64,
    text: &str,
) -> Result<usize, TooLong> {
    message(buf, MsgType::Logging, |c| {
        c.u8(level as u8).u64(timestamp_us).put(text.as_bytes());
    })
}

/// A sync marker.
pub fn sync(buf: &mut [u8]) -> Result<usize, TooLong> {
    message(buf, MsgType::Sync, |c| {
        c.put(&SYNC_MAGIC);
    })
}

/// Data lost for `duration_ms` (saturated at 65,535 ms).
pub fn dropout(buf: &mut [u8], duration_ms: u32) -> Result<usize, TooLong> {
    message(buf, MsgType::Dropout, |c| {
        c.u16(u16::try_from(duration_ms).unwrap_or(u16::MAX));
    })
}

/// A key: its length (one byte), then the text `body` writes.
fn key(c: &mut Cursor<'_>, body: impl FnOnce(&mut Cursor<'_>)) {
    let mut text = [0u8; 255];
    let mut k = Cursor::new(&mut text);
    body(&mut k);
    match (k.finish(), u8::try_from(k.len())) {
        (Ok(n), Ok(len)) => {
            c.u8(len);
            if let Some(t) = text.get(..n) {
                c.put(t);
            }
        }
        // Longer than a key may be: the whole message is refused.
        _ => c.refuse(),
    }
}

#[cfg(test)]
mod tests;
