//! A logged topic's format: its name and fields, as ULog's format message writes them.

use super::Cursor;

/// A field's element type, with the C name ULog writes for it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Ty {
    /// `uint8_t`
    U8,
    /// `int8_t`
    I8,
    /// `uint16_t`
    U16,
    /// `int16_t`
    I16,
    /// `uint32_t`
    U32,
    /// `int32_t`
    I32,
    /// `uint64_t`
    U64,
    /// `int64_t`
    I64,
    /// `float`
    F32,
    /// `double`
    F64,
    /// `bool` (one byte)
    Bool,
    /// `char` (one byte; arrays of it are texts without a terminating NUL)
    Char,
}

impl Ty {
    /// Bytes of one element.
    pub const fn size(self) -> usize {
        match self {
            Ty::U8 | Ty::I8 | Ty::Bool | Ty::Char => 1,
            Ty::U16 | Ty::I16 => 2,
            Ty::U32 | Ty::I32 | Ty::F32 => 4,
            Ty::U64 | Ty::I64 | Ty::F64 => 8,
        }
    }

    /// The C name in a format message.
    pub const fn c_name(self) -> &'static str {
        match self {
            Ty::U8 => "uint8_t",
            Ty::I8 => "int8_t",
            Ty::U16 => "uint16_t",
            Ty::I16 => "int16_t",
            Ty::U32 => "uint32_t",
            Ty::I32 => "int32_t",
            Ty::U64 => "uint64_t",
            Ty::I64 => "int64_t",
            Ty::F32 => "float",
            Ty::F64 => "double",
            Ty::Bool => "bool",
            Ty::Char => "char",
        }
    }
}

/// One field of a format: a scalar, or an array of `count` elements.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Field {
    /// The field's name (PX4's where the topic is PX4's).
    pub name: &'static str,
    /// The element type.
    pub ty: Ty,
    /// Elements: `None` for a scalar, `Some(n)` for `ty[n]`.
    pub count: Option<u16>,
}

impl Field {
    /// A scalar field.
    pub const fn scalar(name: &'static str, ty: Ty) -> Self {
        Self {
            name,
            ty,
            count: None,
        }
    }

    /// An array field of `n` elements.
    pub const fn array(name: &'static str, ty: Ty, n: u16) -> Self {
        Self {
            name,
            ty,
            count: Some(n),
        }
    }

    /// Bytes of the field in a data message.
    pub const fn size(&self) -> usize {
        match self.count {
            None => self.ty.size(),
            Some(n) => self.ty.size().saturating_mul(n as usize),
        }
    }
}

/// A topic's format: its name and its fields after the timestamp every ULog format starts
/// with (written here, so no topic can leave it out).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Format {
    /// The topic's name (PX4's where one exists: `vehicle_attitude`, `actuator_outputs`, ...).
    pub name: &'static str,
    /// The fields after `uint64_t timestamp`.
    pub fields: &'static [Field],
}

/// The field every format starts with.
pub const TIMESTAMP: Field = Field::scalar("timestamp", Ty::U64);

impl Format {
    /// Bytes of one sample in a data message, its timestamp included (not the message
    /// header nor the message id).
    pub fn size(&self) -> usize {
        self.fields
            .iter()
            .fold(TIMESTAMP.size(), |n, f| n.saturating_add(f.size()))
    }

    /// Writes the format text: `name:uint64_t timestamp;type name;...;`.
    pub fn write_text(&self, c: &mut Cursor<'_>) {
        c.put(self.name.as_bytes()).put(b":");
        for f in core::iter::once(&TIMESTAMP).chain(self.fields) {
            c.put(f.ty.c_name().as_bytes());
            if let Some(n) = f.count {
                c.put(b"[").decimal(usize::from(n)).put(b"]");
            }
            c.put(b" ").put(f.name.as_bytes()).put(b";");
        }
    }
}
