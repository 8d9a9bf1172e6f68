//! A logged topic's format: its name and fields, as ULog's format message writes them.

use super::cursor::Cursor;

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

/// A value a topic's field holds: its ULog type and how it is written.
pub trait Value {
    /// The element type.
    const TY: Ty;
    /// `None` for a scalar, `Some(n)` for an array of `n`.
    const COUNT: Option<u16>;
    /// Appends the value, little-endian.
    fn put(&self, c: &mut Cursor<'_>);
}

macro_rules! scalar_value {
    ($($t:ty => $ty:ident, $put:ident);* $(;)?) => {$(
        impl Value for $t {
            const TY: Ty = Ty::$ty;
            const COUNT: Option<u16> = None;
            fn put(&self, c: &mut Cursor<'_>) {
                c.$put(*self);
            }
        }
    )*};
}

scalar_value! {
    u8 => U8, u8;
    i8 => I8, i8;
    u16 => U16, u16;
    i16 => I16, i16;
    u32 => U32, u32;
    i32 => I32, i32;
    u64 => U64, u64;
    f32 => F32, f32;
    f64 => F64, f64;
    bool => Bool, bool;
}

impl<T: Value, const N: usize> Value for [T; N] {
    const TY: Ty = T::TY;
    // Topics hold short arrays (quaternions, outputs): N < 2^16 by construction.
    #[allow(clippy::cast_possible_truncation)]
    const COUNT: Option<u16> = Some(N as u16);
    fn put(&self, c: &mut Cursor<'_>) {
        for v in self {
            v.put(c);
        }
    }
}

/// A logged topic: a plain struct whose fields are its format's, in order.
pub trait Topic {
    /// Its format.
    const FORMAT: Format;
    /// Appends its fields (not the timestamp), in the format's order.
    fn encode(&self, c: &mut Cursor<'_>);
}

/// Declares a topic: the struct and its [`Topic`] implementation from one list of fields, so
/// the format a reader is told and the bytes written cannot disagree.
#[macro_export]
macro_rules! ulog_topic {
    (
        $(#[$m:meta])*
        $name:ident = $topic:literal {
            $($(#[$fm:meta])* $field:ident : $ty:ty),* $(,)?
        }
    ) => {
        $(#[$m])*
        #[derive(Clone, Copy, Debug, Default, PartialEq)]
        pub struct $name {
            $($(#[$fm])* pub $field: $ty,)*
        }

        impl $crate::ulog::topic::Topic for $name {
            const FORMAT: $crate::ulog::topic::Format = $crate::ulog::topic::Format {
                name: $topic,
                fields: &[$($crate::ulog::topic::Field {
                    name: stringify!($field),
                    ty: <$ty as $crate::ulog::topic::Value>::TY,
                    count: <$ty as $crate::ulog::topic::Value>::COUNT,
                }),*],
            };
            fn encode(&self, c: &mut $crate::ulog::cursor::Cursor<'_>) {
                $($crate::ulog::topic::Value::put(&self.$field, c);)*
            }
        }
    };
}
