//! A reader of ULog, PX4's flight-log format, as PX4's specification ("ULog File Format",
//! docs.px4.io) defines it: the header, the flag bits (appended data), formats with nested
//! types and arrays, information (`I`, `M`), parameters and their defaults (`P`, `Q`),
//! subscriptions (`A`, `R`), data (`D`), texts (`L`, `C`), sync markers (`S`) and dropouts
//! (`O`).
//!
//! It reads what any ULog writer wrote, this project's (`common::ulog`) as PX4's, and it
//! never panics on what a file holds:
//!
//! - a file that cannot be a log (empty, a wrong magic, a header cut short, flags that forbid
//!   reading on) is an error naming the byte offset and what was wrong ([`ParseError`];
//!   [`read_file`] names the file too);
//! - a file cut in the middle of a message, as a power cut leaves it, reads up to its last
//!   whole message, with a [`Warning`] saying where and how it ends;
//! - a message that makes no sense (data of no subscription, a format that does not parse) is
//!   skipped with a warning; bytes that are no message at all, and a sample its topic's
//!   format cannot hold (the size in its header is what is corrupt), are skipped up to the
//!   next sync marker, which is what the marker is for.
//!
//! Why not a crate: the two maintained Rust readers do not say where a file goes wrong.
//! `px4-ulog` (0.6) reports an error as a kind and a description, and reads a cut file's
//! prefix only since that release; `yule_log` (0.4) stops at a cut with "Unexpected End of
//! File", without a position either.
//! The format is the few hundred lines here, beside the project's own encoder
//! (`common::ulog`), and the tests hold this reader to the specification's bytes and to
//! pyulog's reading of the autopilot's logs.

// What the file holds decides every length and offset here: no indexing, no unchecked
// arithmetic, no unwrap can turn a bad file into a panic.
#![cfg_attr(
    not(test),
    deny(
        clippy::indexing_slicing,
        clippy::arithmetic_side_effects,
        clippy::unwrap_used,
        clippy::expect_used,
        clippy::panic
    )
)]

pub mod format;

use common::ulog::{HEADER_LEN, MAGIC, MSG_HEADER_LEN, SYNC_MAGIC};
pub use format::{FieldType, FlatField, Format, FormatField, Layout};
use std::collections::{BTreeMap, HashMap};
use std::fmt;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Bit 0 of the first incompatibility byte: data were appended at `appended_offsets`.
const DATA_APPENDED: u8 = 1;

/// What makes bytes unreadable as a log, and where.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ParseError {
    /// Byte offset in the file.
    pub offset: usize,
    /// What was wrong.
    pub what: String,
}

impl fmt::Display for ParseError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "byte {}: {}", self.offset, self.what)
    }
}

impl std::error::Error for ParseError {}

/// A log file that could not be read: the file, and why.
#[derive(Debug)]
pub struct FileError {
    /// The file.
    pub path: PathBuf,
    /// Why: the file system's answer, or what was wrong in the bytes and where.
    pub cause: FileErrorCause,
}

/// Why a log file could not be read.
#[derive(Debug)]
pub enum FileErrorCause {
    /// It could not be read at all.
    Io(std::io::Error),
    /// Its bytes are not a ULog log.
    Parse(ParseError),
}

impl fmt::Display for FileError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.cause {
            FileErrorCause::Io(e) => write!(f, "{}: cannot read: {e}", self.path.display()),
            FileErrorCause::Parse(e) => write!(f, "{}: {e}", self.path.display()),
        }
    }
}

impl std::error::Error for FileError {}

/// Something the reader skipped or stopped at, and where: the log reads without it.
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize)]
pub struct Warning {
    /// Byte offset in the file (of the first occurrence, when several were alike).
    pub offset: usize,
    /// What was skipped, and why.
    pub what: String,
    /// How many more like it followed.
    pub more: usize,
}

impl fmt::Display for Warning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "byte {}: {}", self.offset, self.what)?;
        if self.more > 0 {
            write!(f, " (and {} more like it)", self.more)?;
        }
        Ok(())
    }
}

/// A value of an information or parameter message.
#[derive(Clone, Debug, PartialEq)]
pub enum Value {
    /// A signed integer.
    Int(i64),
    /// An unsigned integer.
    UInt(u64),
    /// A real.
    Float(f64),
    /// A `bool`.
    Bool(bool),
    /// A `char[n]`: text (bytes that are not UTF-8 replaced).
    Text(String),
    /// An array of another basic type.
    Array(Vec<Value>),
    /// A value of a nested type, as its bytes.
    Bytes(Vec<u8>),
}

impl Value {
    /// The value as a number, if it is one.
    pub fn as_f64(&self) -> Option<f64> {
        match self {
            Value::Int(v) => Some(*v as f64),
            Value::UInt(v) => Some(*v as f64),
            Value::Float(v) => Some(*v),
            Value::Bool(v) => Some(f64::from(u8::from(*v))),
            _ => None,
        }
    }

    /// Decodes `bytes` as a value of type `ty` (`count` elements for an array).
    fn decode(ty: &FieldType, count: Option<usize>, bytes: &[u8]) -> Option<Self> {
        use common::ulog::Ty;
        let FieldType::Basic(ty) = ty else {
            return Some(Value::Bytes(bytes.to_vec()));
        };
        let one = |b: &[u8]| -> Option<Value> {
            Some(match ty {
                Ty::I8 | Ty::I16 | Ty::I32 | Ty::I64 => Value::Int(format::signed(*ty, b)?),
                Ty::U8 | Ty::U16 | Ty::U32 | Ty::U64 => Value::UInt(format::unsigned(*ty, b)?),
                Ty::F32 | Ty::F64 => Value::Float(format::number(*ty, b)?),
                Ty::Bool => Value::Bool(*b.first()? != 0),
                Ty::Char => Value::Text(String::from_utf8_lossy(b.get(..1)?).into_owned()),
            })
        };
        match (ty, count) {
            (Ty::Char, Some(_)) => Some(Value::Text(String::from_utf8_lossy(bytes).into_owned())),
            (_, None) => one(bytes),
            (_, Some(n)) => {
                let size = ty.size();
                let items = bytes
                    .chunks(size)
                    .take(n)
                    .map(one)
                    .collect::<Option<Vec<_>>>()?;
                (items.len() == n).then_some(Value::Array(items))
            }
        }
    }
}

impl fmt::Display for Value {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Value::Int(v) => write!(f, "{v}"),
            Value::UInt(v) => write!(f, "{v}"),
            Value::Float(v) => write!(f, "{v}"),
            Value::Bool(v) => write!(f, "{v}"),
            Value::Text(v) => write!(f, "{v}"),
            Value::Array(v) => {
                let items: Vec<String> = v.iter().map(Value::to_string).collect();
                write!(f, "[{}]", items.join(", "))
            }
            Value::Bytes(v) => write!(f, "{} bytes", v.len()),
        }
    }
}

/// The flag-bits message.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FlagBits {
    /// Compatible flags (bit 0 of byte 0: the log holds default parameters).
    pub compat: [u8; 8],
    /// Incompatible flags (bit 0 of byte 0: data appended).
    pub incompat: [u8; 8],
    /// Where appended data start (0: none).
    pub appended_offsets: [u64; 3],
}

/// A parameter whose value changed while the log was written (a `P` in the data section).
#[derive(Clone, Debug, PartialEq)]
pub struct ParamChange {
    /// The last timestamp seen before it, us.
    pub timestamp_us: u64,
    /// The parameter.
    pub name: String,
    /// Its new value.
    pub value: Value,
}

/// A parameter's default value (`Q`).
#[derive(Clone, Debug, PartialEq)]
pub struct ParamDefault {
    /// Bit 0: the system-wide default; bit 1: the default of the current configuration.
    pub default_types: u8,
    /// The parameter.
    pub name: String,
    /// Its default.
    pub value: Value,
}

/// A text the system logged (`L`, or `C` with a tag).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Text {
    /// Syslog level, 0 (emergency) to 7 (debug).
    pub level: u8,
    /// The tag of a tagged text.
    pub tag: Option<u16>,
    /// When, us.
    pub timestamp_us: u64,
    /// The text.
    pub text: String,
}

impl Text {
    /// The level's name.
    pub fn level_name(&self) -> &'static str {
        match self.level {
            0 => "emergency",
            1 => "alert",
            2 => "critical",
            3 => "error",
            4 => "warning",
            5 => "notice",
            6 => "info",
            _ => "debug",
        }
    }
}

/// Data the writer lost, and for how long (`O`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Dropout {
    /// The last timestamp seen before it, us.
    pub timestamp_us: u64,
    /// How long, ms.
    pub duration_ms: u16,
}

/// The samples of one instance of one topic.
#[derive(Clone, Debug, PartialEq)]
pub struct Dataset {
    /// The topic's (format's) name.
    pub name: String,
    /// Its instance.
    pub multi_id: u8,
    /// Where each value of a sample is.
    pub layout: Arc<Layout>,
    timestamps_us: Vec<u64>,
    /// The samples back to back, each `layout.size` bytes.
    raw: Vec<u8>,
}

impl Dataset {
    /// Samples read.
    pub fn len(&self) -> usize {
        self.timestamps_us.len()
    }

    /// Whether no sample was read.
    pub fn is_empty(&self) -> bool {
        self.timestamps_us.is_empty()
    }

    /// Each sample's timestamp, us (0 for a format without one).
    pub fn timestamps_us(&self) -> &[u64] {
        &self.timestamps_us
    }

    /// Sample `i`'s bytes.
    pub fn sample(&self, i: usize) -> Option<&[u8]> {
        let size = self.layout.size;
        let start = i.checked_mul(size)?;
        self.raw.get(start..start.checked_add(size)?)
    }

    /// Every sample's value of field `name` (`q[0]`, `esc[1].rpm`) as a number; `None` if
    /// the topic has no such numeric field.
    pub fn field(&self, name: &str) -> Option<Vec<f64>> {
        let f = self.layout.field(name)?;
        if f.ty == common::ulog::Ty::Char {
            return None;
        }
        (0..self.len())
            .map(|i| {
                let b = self.sample(i)?.get(f.offset..)?;
                format::number(f.ty, b)
            })
            .collect()
    }
}

/// A whole log as read.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Ulog {
    /// The format version in the header.
    pub version: u8,
    /// The header's timestamp: when the log started, us on the writer's clock.
    pub start_us: u64,
    /// The flag bits (all clear when the log has none, as the oldest logs do).
    pub flags: FlagBits,
    /// Formats by name.
    pub formats: BTreeMap<String, Format>,
    /// Information (`I`) by key name.
    pub info: BTreeMap<String, Value>,
    /// Multiple information (`M`) by key name: each value, continued ones joined.
    pub info_multi: BTreeMap<String, Vec<Value>>,
    /// Parameters at the start of the log.
    pub params: BTreeMap<String, Value>,
    /// Parameters that changed while it was written.
    pub param_changes: Vec<ParamChange>,
    /// Parameters' defaults.
    pub param_defaults: Vec<ParamDefault>,
    /// One per topic instance, in the order they were subscribed.
    pub datasets: Vec<Dataset>,
    /// Texts, in the order written.
    pub texts: Vec<Text>,
    /// Dropouts, in the order written.
    pub dropouts: Vec<Dropout>,
    /// Sync markers seen.
    pub syncs: usize,
    /// What was skipped, and where reading stopped short of the file's end.
    pub warnings: Vec<Warning>,
    /// Bytes read: the end of the last whole message.
    pub bytes_read: usize,
    /// Bytes of the file.
    pub file_len: usize,
}

impl Ulog {
    /// The lowest instance of topic `name`.
    pub fn dataset(&self, name: &str) -> Option<&Dataset> {
        self.datasets
            .iter()
            .filter(|d| d.name == name)
            .min_by_key(|d| d.multi_id)
    }

    /// Information `key` as text (`sys_name`, `ver_sw`, ...).
    pub fn info_text(&self, key: &str) -> Option<String> {
        self.info.get(key).map(Value::to_string)
    }

    /// The last timestamp in the log (data and texts), us; the header's when it has none.
    pub fn last_us(&self) -> u64 {
        self.datasets
            .iter()
            .filter_map(|d| d.timestamps_us.iter().max())
            .chain(self.texts.iter().map(|t| &t.timestamp_us))
            .copied()
            .max()
            .unwrap_or(self.start_us)
            .max(self.start_us)
    }
}

/// Reads the log in `path`.
pub fn read_file(path: &Path) -> Result<Ulog, FileError> {
    let fail = |cause| FileError {
        path: path.to_path_buf(),
        cause,
    };
    let bytes = std::fs::read(path).map_err(|e| fail(FileErrorCause::Io(e)))?;
    parse(&bytes).map_err(|e| fail(FileErrorCause::Parse(e)))
}

/// Reads a log from its bytes.
pub fn parse(bytes: &[u8]) -> Result<Ulog, ParseError> {
    let at = |offset: usize, what: String| ParseError { offset, what };
    if bytes.is_empty() {
        return Err(at(
            0,
            format!("the file is empty; a ULog file starts with a {HEADER_LEN}-byte header"),
        ));
    }
    let magic = bytes.get(..MAGIC.len()).unwrap_or(bytes);
    if MAGIC.get(..magic.len()) != Some(magic) {
        return Err(at(
            0,
            format!(
                "not a ULog file: it starts with {}, a ULog file with {} (\"ULog\" 01 12 35)",
                hex(magic),
                hex(&MAGIC)
            ),
        ));
    }
    let header = bytes.get(..HEADER_LEN).ok_or_else(|| {
        at(
            bytes.len(),
            format!(
                "the header is {HEADER_LEN} bytes, the file ends after {}",
                bytes.len()
            ),
        )
    })?;
    let mut r = Reader::new(header);
    r.skip(MAGIC.len());
    let version = r.u8().unwrap_or_default();
    let start_us = r.u64().unwrap_or_default();
    let mut p = Parser {
        bytes,
        log: Ulog {
            version,
            start_us,
            bytes_read: HEADER_LEN,
            file_len: bytes.len(),
            ..Ulog::default()
        },
        subscriptions: HashMap::new(),
        layouts: HashMap::new(),
        budget: format::LOG_ELEMENTS_MAX,
        instances: HashMap::new(),
        in_data: false,
        last_us: start_us,
        alike: BTreeMap::new(),
    };
    if version > common::ulog::VERSION {
        p.warn(
            MAGIC.len(),
            format!(
                "format version {version}; this reader knows version {} (read as that)",
                common::ulog::VERSION
            ),
        );
    }
    p.run()?;
    Ok(p.finish())
}

/// Bytes as hex pairs.
fn hex(b: &[u8]) -> String {
    b.iter()
        .map(|x| format!("{x:02X}"))
        .collect::<Vec<_>>()
        .join(" ")
}

/// A little-endian reader over one message's payload.
struct Reader<'a> {
    b: &'a [u8],
}

impl<'a> Reader<'a> {
    fn new(b: &'a [u8]) -> Self {
        Self { b }
    }

    fn take(&mut self, n: usize) -> Option<&'a [u8]> {
        let (head, rest) = (self.b.get(..n)?, self.b.get(n..)?);
        self.b = rest;
        Some(head)
    }

    fn skip(&mut self, n: usize) {
        self.b = self.b.get(n..).unwrap_or(&[]);
    }

    fn array<const N: usize>(&mut self) -> Option<[u8; N]> {
        self.take(N)?.try_into().ok()
    }

    fn u8(&mut self) -> Option<u8> {
        Some(self.array::<1>()?[0])
    }

    fn u16(&mut self) -> Option<u16> {
        Some(u16::from_le_bytes(self.array()?))
    }

    fn u64(&mut self) -> Option<u64> {
        Some(u64::from_le_bytes(self.array()?))
    }

    fn rest(&mut self) -> &'a [u8] {
        std::mem::take(&mut self.b)
    }
}

/// What every message type of the specification is, by its type byte.
fn known_type(t: u8) -> bool {
    matches!(
        t,
        b'B' | b'F' | b'I' | b'M' | b'P' | b'Q' | b'A' | b'R' | b'D' | b'L' | b'C' | b'S' | b'O'
    )
}

/// A type byte for the message log: the letter, or its value.
fn type_name(t: u8) -> String {
    if t.is_ascii_graphic() {
        format!("'{}'", char::from(t))
    } else {
        format!("0x{t:02X}")
    }
}

/// What the bytes at an offset are.
enum Step<'a> {
    /// A whole message: its type, payload, and where the next starts.
    Message(u8, &'a [u8], usize),
    /// A type byte no message has.
    NotAMessage(u8),
    /// Fewer bytes left than a message header (how many).
    HeaderCut(usize),
    /// A message longer than the bytes left: its type, its size, the bytes left.
    BodyCut(u8, u16, usize),
}

struct Parser<'a> {
    bytes: &'a [u8],
    log: Ulog,
    /// Subscribed message ids and the dataset each fills.
    subscriptions: HashMap<u16, usize>,
    /// A subscription, data or text has been seen: `P` now means a change.
    in_data: bool,
    /// The last timestamp seen.
    last_us: u64,
    /// Warnings by kind: the first's offset and text, and how many more.
    alike: BTreeMap<String, (usize, String, usize)>,
    /// Layouts by format name, each worked out once (a file may subscribe to a deep format
    /// many times; formats are all defined before the first subscription).
    layouts: HashMap<String, Result<Arc<Layout>, String>>,
    /// Elements the log's layouts may still expand to.
    budget: usize,
    /// The dataset of each topic instance, by name and `multi_id`.
    instances: HashMap<(String, u8), usize>,
}

impl<'a> Parser<'a> {
    fn warn(&mut self, offset: usize, what: String) {
        self.log.warnings.push(Warning {
            offset,
            what,
            more: 0,
        });
    }

    /// A warning that may repeat for every message of a kind: given once, with a count.
    fn warn_alike(&mut self, kind: String, offset: usize, what: impl FnOnce() -> String) {
        self.alike
            .entry(kind)
            .and_modify(|(_, _, more)| *more = more.saturating_add(1))
            .or_insert_with(|| (offset, what(), 0));
    }

    fn finish(mut self) -> Ulog {
        let alike = std::mem::take(&mut self.alike);
        self.log
            .warnings
            .extend(
                alike
                    .into_values()
                    .map(|(offset, what, more)| Warning { offset, what, more }),
            );
        self.log.warnings.sort_by_key(|w| w.offset);
        self.log
    }

    /// Reads every message: up to the first appended offset, then each appended part.
    fn run(&mut self) -> Result<(), ParseError> {
        let len = self.bytes.len();
        let mut pos = HEADER_LEN;
        // The flag bits, when the log has them, come first and say where its parts are.
        if let Step::Message(b'B', payload, next) = self.step(pos, len) {
            self.message(pos, b'B', payload)?;
            pos = next;
            self.log.bytes_read = next;
        }
        let mut bounds: Vec<usize> = Vec::new();
        if self.log.flags.incompat[0] & DATA_APPENDED != 0 {
            for o in self.log.flags.appended_offsets {
                match usize::try_from(o) {
                    _ if o == 0 => {}
                    Ok(o) if o >= pos && o <= len && bounds.last().is_none_or(|&b| o > b) => {
                        bounds.push(o)
                    }
                    _ => self.warn(
                        HEADER_LEN,
                        format!(
                            "appended data at byte {o}, outside the file ({len} bytes) or out of order: ignored"
                        ),
                    ),
                }
            }
        }
        bounds.push(len);
        let last = bounds.len().saturating_sub(1);
        for (i, &end) in bounds.iter().enumerate() {
            // A part before appended data may end in the middle of a message (that is why
            // data are appended): only the last part's end says the file was cut.
            self.part(pos, end, i == last)?;
            pos = end;
        }
        Ok(())
    }

    /// What is at `pos`, reading no further than `end`.
    fn step(&self, pos: usize, end: usize) -> Step<'a> {
        let left = end.saturating_sub(pos);
        let bytes: &'a [u8] = self.bytes;
        let head = match bytes.get(pos..end).and_then(|b| b.get(..MSG_HEADER_LEN)) {
            Some(h) => h,
            None => return Step::HeaderCut(left),
        };
        let mut h = Reader::new(head);
        let (size, kind) = (h.u16().unwrap_or_default(), h.u8().unwrap_or_default());
        if !known_type(kind) {
            return Step::NotAMessage(kind);
        }
        let start = pos.saturating_add(MSG_HEADER_LEN);
        let next = start.saturating_add(usize::from(size));
        match bytes.get(start..next).filter(|_| next <= end) {
            Some(payload) => Step::Message(kind, payload, next),
            None => Step::BodyCut(kind, size, left.saturating_sub(MSG_HEADER_LEN)),
        }
    }

    /// Reads the messages from `pos` to `end`; `last` is the file's last part, whose cut
    /// end is worth a warning.
    fn part(&mut self, mut pos: usize, end: usize, last: bool) -> Result<(), ParseError> {
        while pos < end {
            match self.step(pos, end) {
                Step::Message(kind, payload, next) => match self.misfit(kind, payload) {
                    // A sample that its own topic's format cannot hold: the size in its
                    // header is what is corrupt, and the next message is not where it says.
                    Some(why) => match self.resync(pos, end, why) {
                        Some(after) => pos = after,
                        None => return Ok(()),
                    },
                    None => {
                        self.message(pos, kind, payload)?;
                        pos = next;
                        self.log.bytes_read = self.log.bytes_read.max(pos);
                    }
                },
                Step::NotAMessage(kind) => {
                    let why = format!("no message starts here (type byte {})", type_name(kind));
                    match self.resync(pos, end, why) {
                        Some(after) => pos = after,
                        None => return Ok(()),
                    }
                }
                Step::HeaderCut(left) => {
                    if last {
                        self.warn(
                            pos,
                            format!(
                                "the file ends inside a message's header ({left} of its {MSG_HEADER_LEN} bytes): read up to byte {pos}"
                            ),
                        );
                    }
                    return Ok(());
                }
                Step::BodyCut(kind, size, left) => {
                    if last {
                        self.warn(
                            pos,
                            format!(
                                "message of type {} claims {size} bytes, only {left} left: the file ends mid-message (as a log cut by a power loss does); read up to byte {pos}",
                                type_name(kind)
                            ),
                        );
                    }
                    return Ok(());
                }
            }
        }
        Ok(())
    }

    /// Skips from corrupt bytes at `pos` to the message after the next sync marker: where to
    /// read on, or `None` when no marker follows (reading stops).
    fn resync(&mut self, pos: usize, end: usize, why: String) -> Option<usize> {
        match self.find_sync(pos.saturating_add(1), end) {
            Some(sync) => {
                self.warn(
                    pos,
                    format!(
                        "{why}: the file is corrupt; skipped {} bytes to the next sync marker",
                        sync.saturating_sub(pos)
                    ),
                );
                self.log.syncs = self.log.syncs.saturating_add(1);
                Some(sync.saturating_add(SYNC_MAGIC.len()))
            }
            None => {
                self.warn(
                    pos,
                    format!(
                        "{why}, and no sync marker follows: the file is corrupt from here; read up to byte {pos}"
                    ),
                );
                None
            }
        }
    }

    /// Why a data message cannot be what its header says: a sample longer or shorter than
    /// its subscription's format.
    fn misfit(&self, kind: u8, payload: &[u8]) -> Option<String> {
        if kind != b'D' {
            return None;
        }
        let mut r = Reader::new(payload);
        let d = self
            .subscriptions
            .get(&r.u16()?)
            .and_then(|&i| self.log.datasets.get(i))?;
        let got = r.rest().len();
        (got < d.layout.min_size || got > d.layout.size).then(|| {
            format!(
                "a sample of `{}` is {got} bytes, its format {}",
                d.name, d.layout.size
            )
        })
    }

    /// The offset of the sync magic next at or after `from` (before `end`), if any.
    fn find_sync(&self, from: usize, end: usize) -> Option<usize> {
        let hay = self.bytes.get(from..end)?;
        hay.windows(SYNC_MAGIC.len())
            .position(|w| w == SYNC_MAGIC)
            .map(|i| from.saturating_add(i))
    }

    fn message(&mut self, pos: usize, kind: u8, payload: &[u8]) -> Result<(), ParseError> {
        let mut r = Reader::new(payload);
        match kind {
            b'B' => self.flag_bits(pos, &mut r)?,
            // Formats belong to the definitions: one after a subscription could change the
            // layout of samples already read.
            b'F' if self.in_data => self.warn_alike("late format".into(), pos, || {
                "format message after the definitions (the specification puts formats before the data): ignored".into()
            }),
            b'F' => match std::str::from_utf8(payload) {
                Ok(text) => match Format::parse(text) {
                    Ok(f) => {
                        self.log.formats.insert(f.name.clone(), f);
                    }
                    Err(e) => self.warn(pos, format!("format message `{text}`: {e}: skipped")),
                },
                Err(_) => self.warn(pos, "format message is not text: skipped".into()),
            },
            b'I' => {
                if let Some((name, value)) = self.keyed(pos, "information", &mut r) {
                    self.log.info.insert(name, value);
                }
            }
            b'M' => {
                let continued = r.u8().unwrap_or_default() != 0;
                if let Some((name, value)) = self.keyed(pos, "information", &mut r) {
                    let values = self.log.info_multi.entry(name).or_default();
                    match (continued, values.last_mut(), value) {
                        (true, Some(Value::Text(a)), Value::Text(b)) => a.push_str(&b),
                        (true, Some(Value::Bytes(a)), Value::Bytes(b)) => a.extend(b),
                        (_, _, value) => values.push(value),
                    }
                }
            }
            b'P' => {
                if let Some((name, value)) = self.keyed(pos, "parameter", &mut r) {
                    if self.in_data {
                        self.log.param_changes.push(ParamChange {
                            timestamp_us: self.last_us,
                            name,
                            value,
                        });
                    } else {
                        self.log.params.insert(name, value);
                    }
                }
            }
            b'Q' => {
                let default_types = r.u8().unwrap_or_default();
                if let Some((name, value)) = self.keyed(pos, "parameter default", &mut r) {
                    self.log.param_defaults.push(ParamDefault {
                        default_types,
                        name,
                        value,
                    });
                }
            }
            b'A' => self.add_logged(pos, &mut r),
            b'R' => {
                self.in_data = true;
                if let Some(id) = r.u16() {
                    self.subscriptions.remove(&id);
                }
            }
            b'D' => self.data(pos, &mut r),
            b'L' | b'C' => {
                self.in_data = true;
                let level = r.u8();
                let tag = if kind == b'C' { r.u16() } else { None };
                match (level, r.u64()) {
                    (Some(level), Some(timestamp_us)) if kind == b'L' || tag.is_some() => {
                        self.last_us = timestamp_us;
                        self.log.texts.push(Text {
                            // Written as the ASCII digit; a raw number read alike.
                            level: if level >= b'0' {
                                level.saturating_sub(b'0').min(7)
                            } else {
                                level.min(7)
                            },
                            tag,
                            timestamp_us,
                            text: String::from_utf8_lossy(r.rest()).into_owned(),
                        });
                    }
                    _ => self.warn_alike("short text".into(), pos, || {
                        "text message too short for its level and timestamp: skipped".into()
                    }),
                }
            }
            b'S' => {
                self.in_data = true;
                if r.rest().get(..SYNC_MAGIC.len()) == Some(&SYNC_MAGIC[..]) {
                    self.log.syncs = self.log.syncs.saturating_add(1);
                } else {
                    self.warn_alike("bad sync".into(), pos, || {
                        "sync message without the sync magic".into()
                    });
                }
            }
            b'O' => {
                self.in_data = true;
                match r.u16() {
                    Some(duration_ms) => self.log.dropouts.push(Dropout {
                        timestamp_us: self.last_us,
                        duration_ms,
                    }),
                    None => self.warn_alike("short dropout".into(), pos, || {
                        "dropout message without its duration: skipped".into()
                    }),
                }
            }
            _ => {}
        }
        Ok(())
    }

    fn flag_bits(&mut self, pos: usize, r: &mut Reader<'_>) -> Result<(), ParseError> {
        if pos != HEADER_LEN {
            self.warn(
                pos,
                "flag bits after the first message (the specification puts them first): ignored"
                    .into(),
            );
            return Ok(());
        }
        let (Some(compat), Some(incompat)) = (r.array::<8>(), r.array::<8>()) else {
            self.warn(
                pos,
                "flag bits shorter than their 16 flag bytes: ignored".into(),
            );
            return Ok(());
        };
        let mut appended_offsets = [0u64; 3];
        for o in &mut appended_offsets {
            *o = r.u64().unwrap_or_default();
        }
        // Unknown incompatible flags mean the file cannot be read as this reader reads it:
        // the specification says to stop.
        let unknown: Vec<String> = incompat
            .iter()
            .enumerate()
            .map(|(i, &b)| (i, if i == 0 { b & !DATA_APPENDED } else { b }))
            .filter(|(_, b)| *b != 0)
            .map(|(i, b)| format!("byte {i}: 0x{b:02X}"))
            .collect();
        if !unknown.is_empty() {
            return Err(ParseError {
                offset: pos,
                what: format!(
                    "the log sets incompatible flags this reader does not know ({}): the specification forbids reading on",
                    unknown.join(", ")
                ),
            });
        }
        self.log.flags = FlagBits {
            compat,
            incompat,
            appended_offsets,
        };
        Ok(())
    }

    /// A key (`type name`) and its value, as information and parameter messages carry them.
    fn keyed(&mut self, pos: usize, what: &str, r: &mut Reader<'_>) -> Option<(String, Value)> {
        let parsed = (|| {
            let n = r.u8().ok_or("no key length")?;
            let key = r
                .take(usize::from(n))
                .ok_or("key longer than the message")?;
            let key = std::str::from_utf8(key).map_err(|_| "key is not text")?;
            let (ty, name) = key.split_once(' ').ok_or("key is not `type name`")?;
            let (ty, count) = format::parse_type(ty).map_err(|_| "key's type does not parse")?;
            let value = Value::decode(&ty, count, r.rest()).ok_or("value shorter than its type")?;
            Ok::<_, &str>((name.to_string(), value))
        })();
        match parsed {
            Ok(kv) => Some(kv),
            Err(why) => {
                self.warn(pos, format!("{what} message: {why}: skipped"));
                None
            }
        }
    }

    fn add_logged(&mut self, pos: usize, r: &mut Reader<'_>) {
        self.in_data = true;
        let (Some(multi_id), Some(msg_id)) = (r.u8(), r.u16()) else {
            self.warn(pos, "subscription message too short: skipped".into());
            return;
        };
        let name = String::from_utf8_lossy(r.rest()).into_owned();
        let (formats, budget) = (&self.log.formats, &mut self.budget);
        let layout = match self
            .layouts
            .entry(name.clone())
            .or_insert_with(|| Layout::of(formats, &name, budget).map(Arc::new))
        {
            Ok(l) => l.clone(),
            Err(e) => {
                let e = e.clone();
                self.warn(
                    pos,
                    format!(
                        "subscription of `{name}` (message id {msg_id}): {e}: its data are skipped"
                    ),
                );
                self.subscriptions.remove(&msg_id);
                return;
            }
        };
        // A topic subscribed again (after an `R`) goes on filling the same samples (its layout
        // is the one worked out for its format).
        let key = (name, multi_id);
        let index = match self.instances.get(&key) {
            Some(&i)
                if self
                    .log
                    .datasets
                    .get(i)
                    .is_some_and(|d| Arc::ptr_eq(&d.layout, &layout)) =>
            {
                i
            }
            _ => {
                self.log.datasets.push(Dataset {
                    name: key.0.clone(),
                    multi_id,
                    layout,
                    timestamps_us: Vec::new(),
                    raw: Vec::new(),
                });
                let i = self.log.datasets.len().saturating_sub(1);
                self.instances.insert(key, i);
                i
            }
        };
        self.subscriptions.insert(msg_id, index);
    }

    fn data(&mut self, pos: usize, r: &mut Reader<'_>) {
        self.in_data = true;
        let Some(msg_id) = r.u16() else {
            self.warn_alike("short data".into(), pos, || {
                "data message without its message id: skipped".into()
            });
            return;
        };
        let Some(d) = self
            .subscriptions
            .get(&msg_id)
            .and_then(|&i| self.log.datasets.get_mut(i))
        else {
            self.warn_alike(format!("unsubscribed {msg_id}"), pos, || {
                format!("data for message id {msg_id}, which no subscription names: skipped")
            });
            return;
        };
        // Its size fits its format (`misfit` saw to it).
        let sample = r.rest();
        let size = d.layout.size;
        let ts = d
            .layout
            .timestamp
            .as_ref()
            .and_then(|t| format::unsigned(t.ty, sample.get(t.offset..)?))
            .unwrap_or_default();
        d.timestamps_us.push(ts);
        d.raw.extend_from_slice(sample);
        // Trailing padding left out: the sample is filled to its whole size.
        d.raw.resize(
            d.raw
                .len()
                .saturating_add(size.saturating_sub(sample.len())),
            0,
        );
        self.last_us = ts;
    }
}

#[cfg(test)]
pub(crate) mod tests;
