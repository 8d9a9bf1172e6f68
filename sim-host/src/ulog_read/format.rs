//! Format messages: the text of a topic's fields, and the byte layout of one sample it gives
//! once nested formats are resolved.

use common::ulog::Ty;
use std::collections::BTreeMap;

/// Every basic type of the specification, to look C names up.
const BASIC: [Ty; 12] = [
    Ty::U8,
    Ty::I8,
    Ty::U16,
    Ty::I16,
    Ty::U32,
    Ty::I32,
    Ty::U64,
    Ty::I64,
    Ty::F32,
    Ty::F64,
    Ty::Bool,
    Ty::Char,
];

/// The most bytes a sample can have: a data message's size is a `u16`, less the message id.
pub const SAMPLE_MAX: usize = u16::MAX as usize - 2;

/// Nesting deeper than this is taken for a format that contains itself.
const DEPTH_MAX: usize = 16;

/// Elements a layout may expand to: bounds the work a hostile format (arrays of empty nested
/// formats inside arrays) can ask for.
const ELEMENTS_MAX: usize = 1 << 16;

/// Elements all the layouts of one log may expand to: a PX4 log's few hundred topics have a
/// few tens of thousands; this bounds the work of a file that subscribes to many large ones.
pub const LOG_ELEMENTS_MAX: usize = 1 << 21;

/// The type of a field: one of the specification's, or another format by name.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum FieldType {
    /// `int8_t` ... `double`, `bool`, `char`.
    Basic(Ty),
    /// A nested format, laid out in place.
    Nested(String),
}

/// One field of a format message.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FormatField {
    /// Its type.
    pub ty: FieldType,
    /// `Some(n)` for an array of `n`.
    pub count: Option<usize>,
    /// Its name; `_padding...` names bytes that carry nothing.
    pub name: String,
}

impl FormatField {
    /// Whether the field only pads.
    pub fn is_padding(&self) -> bool {
        self.name.starts_with("_padding")
    }
}

/// A format message: `name:type field;type[n] field;...`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Format {
    /// The topic's (or nested type's) name.
    pub name: String,
    /// Its fields in order.
    pub fields: Vec<FormatField>,
}

/// A type text, `float` or `float[4]` or `esc_report[8]`: its type and count.
pub fn parse_type(text: &str) -> Result<(FieldType, Option<usize>), String> {
    let (base, count) = match text.split_once('[') {
        None => (text, None),
        Some((base, rest)) => {
            let n = rest
                .strip_suffix(']')
                .ok_or_else(|| format!("type `{text}`: `[` without its `]`"))?;
            let n: usize = n
                .parse()
                .map_err(|_| format!("type `{text}`: `{n}` is not an array length"))?;
            (base, Some(n))
        }
    };
    if base.is_empty() {
        return Err(format!("type `{text}` has no name"));
    }
    let ty = match BASIC.iter().find(|t| t.c_name() == base) {
        Some(t) => FieldType::Basic(*t),
        None => FieldType::Nested(base.to_string()),
    };
    Ok((ty, count))
}

impl Format {
    /// Parses a format message's text.
    pub fn parse(text: &str) -> Result<Self, String> {
        let (name, fields) = text
            .split_once(':')
            .ok_or_else(|| "no `:` between the name and the fields".to_string())?;
        if name.is_empty() {
            return Err("the format has no name".into());
        }
        let fields = fields
            .split(';')
            .map(str::trim)
            .filter(|f| !f.is_empty())
            .map(|f| {
                let (ty, field) = f
                    .split_once(' ')
                    .ok_or_else(|| format!("field `{f}` is not `type name`"))?;
                let field = field.trim();
                if field.is_empty() {
                    return Err(format!("field `{f}` has no name"));
                }
                let (ty, count) = parse_type(ty)?;
                Ok(FormatField {
                    ty,
                    count,
                    name: field.to_string(),
                })
            })
            .collect::<Result<Vec<_>, String>>()?;
        Ok(Self {
            name: name.to_string(),
            fields,
        })
    }
}

/// One value of a sample once nested formats and arrays are laid flat: `q[0]`,
/// `esc[2].esc_rpm`, as pyulog names them.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FlatField {
    /// The flattened name.
    pub name: String,
    /// Its basic type.
    pub ty: Ty,
    /// Its bytes' offset in the sample (after the message id).
    pub offset: usize,
}

/// Where each value of a topic's sample is.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Layout {
    /// The values, padding left out.
    pub fields: Vec<FlatField>,
    /// Bytes of a whole sample.
    pub size: usize,
    /// Bytes of a sample whose trailing padding was not written (the specification lets a
    /// writer leave a last padding field out).
    pub min_size: usize,
    /// The `timestamp` field, if the format has one at its top level.
    pub timestamp: Option<FlatField>,
}

impl Layout {
    /// The layout of format `name`, nested formats resolved in `formats`; `budget` is the
    /// elements still allowed (the ones laid out are taken from it).
    pub fn of(
        formats: &BTreeMap<String, Format>,
        name: &str,
        budget: &mut usize,
    ) -> Result<Self, String> {
        let top = formats
            .get(name)
            .ok_or_else(|| format!("no format is named `{name}`"))?;
        let mut flat = Flattener {
            formats,
            fields: Vec::new(),
            elements: 0,
            limit: ELEMENTS_MAX.min(*budget),
        };
        let size = flat.format(top, "", 0, 0);
        *budget = budget.saturating_sub(flat.elements);
        let size = size?;
        // The last field, when it pads, may be left out of the data.
        let trailing = match top.fields.last() {
            Some(f) if f.is_padding() => match &f.ty {
                FieldType::Basic(t) => t.size().saturating_mul(f.count.unwrap_or(1)),
                FieldType::Nested(_) => 0,
            },
            _ => 0,
        };
        let timestamp = flat
            .fields
            .iter()
            .find(|f| f.name == "timestamp" && matches!(f.ty, Ty::U8 | Ty::U16 | Ty::U32 | Ty::U64))
            .cloned();
        Ok(Self {
            fields: flat.fields,
            size,
            min_size: size.saturating_sub(trailing),
            timestamp,
        })
    }

    /// The field named `name`.
    pub fn field(&self, name: &str) -> Option<&FlatField> {
        self.fields.iter().find(|f| f.name == name)
    }
}

struct Flattener<'a> {
    formats: &'a BTreeMap<String, Format>,
    fields: Vec<FlatField>,
    elements: usize,
    /// Elements this layout may have: [`ELEMENTS_MAX`], or fewer when the log's budget is
    /// nearly spent.
    limit: usize,
}

impl Flattener<'_> {
    /// Lays `f`'s fields out from `offset`; returns the offset after them.
    fn format(
        &mut self,
        f: &Format,
        prefix: &str,
        offset: usize,
        depth: usize,
    ) -> Result<usize, String> {
        if depth > DEPTH_MAX {
            return Err(format!(
                "`{}` nests more than {DEPTH_MAX} formats deep (a format that contains itself?)",
                f.name
            ));
        }
        let mut at = offset;
        for field in &f.fields {
            for i in 0..field.count.unwrap_or(1) {
                self.elements = self.elements.saturating_add(1);
                if self.elements > self.limit {
                    return Err(if self.limit < ELEMENTS_MAX {
                        format!(
                            "the log's formats expand to more than {LOG_ELEMENTS_MAX} values in all"
                        )
                    } else {
                        format!("`{}` expands to more than {ELEMENTS_MAX} values", f.name)
                    });
                }
                let name = match field.count {
                    Some(_) => format!("{prefix}{}[{i}]", field.name),
                    None => format!("{prefix}{}", field.name),
                };
                at = match &field.ty {
                    FieldType::Basic(ty) => {
                        if !field.is_padding() {
                            self.fields.push(FlatField {
                                name,
                                ty: *ty,
                                offset: at,
                            });
                        }
                        at.saturating_add(ty.size())
                    }
                    FieldType::Nested(inner) => {
                        let nested = self.formats.get(inner).ok_or_else(|| {
                            format!(
                                "field `{}` of `{}` is of type `{inner}`, which no format defines",
                                field.name, f.name
                            )
                        })?;
                        self.format(nested, &format!("{name}."), at, depth.saturating_add(1))?
                    }
                };
                if at > SAMPLE_MAX {
                    return Err(format!(
                        "`{}` is longer than a data message can hold ({SAMPLE_MAX} bytes)",
                        f.name
                    ));
                }
            }
        }
        Ok(at)
    }
}

/// The first `N` bytes of `b`, if it has them.
fn le<const N: usize>(b: &[u8]) -> Option<[u8; N]> {
    b.get(..N)?.try_into().ok()
}

/// The value of a basic type at the start of `bytes`, as a number (`None` if too few bytes,
/// or a `char`).
pub fn number(ty: Ty, bytes: &[u8]) -> Option<f64> {
    Some(match ty {
        Ty::U8 => f64::from(*bytes.first()?),
        Ty::I8 => f64::from(i8::from_le_bytes(le(bytes)?)),
        Ty::Bool => f64::from(u8::from(*bytes.first()? != 0)),
        Ty::U16 => f64::from(u16::from_le_bytes(le(bytes)?)),
        Ty::I16 => f64::from(i16::from_le_bytes(le(bytes)?)),
        Ty::U32 => f64::from(u32::from_le_bytes(le(bytes)?)),
        Ty::I32 => f64::from(i32::from_le_bytes(le(bytes)?)),
        // Beyond 2^53 a 64-bit integer loses its last digits as a number: the integer readers
        // below keep them.
        Ty::U64 => u64::from_le_bytes(le(bytes)?) as f64,
        Ty::I64 => i64::from_le_bytes(le(bytes)?) as f64,
        Ty::F32 => f64::from(f32::from_le_bytes(le(bytes)?)),
        Ty::F64 => f64::from_le_bytes(le(bytes)?),
        Ty::Char => return None,
    })
}

/// The value of a signed integer type at the start of `bytes`, exactly.
pub fn signed(ty: Ty, bytes: &[u8]) -> Option<i64> {
    Some(match ty {
        Ty::I8 => i64::from(i8::from_le_bytes(le(bytes)?)),
        Ty::I16 => i64::from(i16::from_le_bytes(le(bytes)?)),
        Ty::I32 => i64::from(i32::from_le_bytes(le(bytes)?)),
        Ty::I64 => i64::from_le_bytes(le(bytes)?),
        _ => return None,
    })
}

/// The value of an unsigned integer type at the start of `bytes`, exactly.
pub fn unsigned(ty: Ty, bytes: &[u8]) -> Option<u64> {
    Some(match ty {
        Ty::U8 => u64::from(*bytes.first()?),
        Ty::U16 => u64::from(u16::from_le_bytes(le(bytes)?)),
        Ty::U32 => u64::from(u32::from_le_bytes(le(bytes)?)),
        Ty::U64 => u64::from_le_bytes(le(bytes)?),
        _ => return None,
    })
}
