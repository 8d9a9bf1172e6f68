//! What a log holds, as the reader hands it over: the log, its datasets, texts, parameters,
//! and the errors and warnings of reading it.

use super::format::{self, FieldType, Format, Layout};
use std::collections::BTreeMap;
use std::fmt;
use std::path::PathBuf;
use std::sync::Arc;

/// Bit 0 of the first incompatibility byte: data were appended at `appended_offsets`.
pub(super) const DATA_APPENDED: u8 = 1;

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
    pub(super) fn decode(ty: &FieldType, count: Option<usize>, bytes: &[u8]) -> Option<Self> {
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
    pub(super) timestamps_us: Vec<u64>,
    /// The samples back to back, each `layout.size` bytes.
    pub(super) raw: Vec<u8>,
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
