//! The parameter metadata file QGroundControl reads (component metadata of type PARAMETER):
//! every declaration of a registry as JSON, written to any `core::fmt::Write` without a heap.
//!
//! QGroundControl's parser wants `version` 1, and for each parameter at least `name` and a
//! `type` matching the `PARAM_VALUE` type (`Float` for `MAV_PARAM_TYPE_REAL32`, `Int32` for
//! `MAV_PARAM_TYPE_INT32`); it shows `shortDesc`, `units`, `min`, `max`, `default`,
//! `decimalPlaces` (a float without it shows as a whole number), `group` and, for switches
//! and choices, the labels in `values`. The host tools print this file
//! (`sim-host params --json`); the firmware's build writes it once, compressed, and serves
//! it over MAVLink FTP, so the image never formats a float at run time.

use core::fmt::{self, Write};

use super::declare::{ParamDef, ParamKind};
use super::store::Registry;

/// Decimal places that show a value as declared: the most any of default, min and max needs,
/// 1 to 6.
pub fn decimal_places(d: &ParamDef) -> usize {
    [d.default, d.min, d.max]
        .iter()
        .map(|&x| {
            let mut counter = Places::default();
            // Display of an f32 is its shortest decimal, never an exponent.
            let _ = write!(counter, "{x}");
            counter.after_point
        })
        .max()
        .unwrap_or(0)
        .clamp(1, 6)
}

/// Counts the digits after the decimal point of what is written.
#[derive(Default)]
struct Places {
    seen_point: bool,
    after_point: usize,
}

impl Write for Places {
    fn write_str(&mut self, s: &str) -> fmt::Result {
        for c in s.chars() {
            if self.seen_point {
                self.after_point = self.after_point.saturating_add(1);
            }
            if c == '.' {
                self.seen_point = true;
            }
        }
        Ok(())
    }
}

/// The labels of a switch or a choice, `(value, label)`.
fn labels(d: &ParamDef) -> impl Iterator<Item = (usize, &'static str)> {
    let names: &'static [&'static str] = match d.kind {
        ParamKind::Bool => &["off", "on"],
        ParamKind::Enum(names) => names.get(),
        ParamKind::Real | ParamKind::Int => &[],
    };
    names.iter().copied().enumerate()
}

/// A JSON string (the declarations are ASCII; quotes and backslashes escaped all the same).
fn string(w: &mut impl Write, s: &str) -> fmt::Result {
    w.write_char('"')?;
    for c in s.chars() {
        match c {
            '"' => w.write_str("\\\"")?,
            '\\' => w.write_str("\\\\")?,
            c if (c as u32) < 0x20 => write!(w, "\\u{:04x}", c as u32)?,
            c => w.write_char(c)?,
        }
    }
    w.write_char('"')
}

/// A value in the parameter's own type.
fn number(w: &mut impl Write, d: &ParamDef, x: f32) -> fmt::Result {
    if d.kind.is_integer() {
        write!(w, "{}", x as i64)
    } else {
        write!(w, "{x}")
    }
}

/// Writes the metadata file of every parameter of `registry`, stage by stage.
pub fn write_json(registry: Registry, w: &mut impl Write) -> fmt::Result {
    w.write_str("{\"version\":1,\"parameters\":[")?;
    let mut first = true;
    for stage in registry.iter() {
        for d in (0..stage.len()).filter_map(|i| stage.def(i)) {
            if !first {
                w.write_char(',')?;
            }
            first = false;
            w.write_str("{\"name\":")?;
            string(w, d.name)?;
            let ty = if d.kind.is_integer() {
                "Int32"
            } else {
                "Float"
            };
            write!(w, ",\"type\":\"{ty}\",\"shortDesc\":")?;
            string(w, d.description.get())?;
            if !d.unit.get().is_empty() {
                w.write_str(",\"units\":")?;
                string(w, d.unit.get())?;
            }
            w.write_str(",\"default\":")?;
            number(w, d, d.default)?;
            w.write_str(",\"min\":")?;
            number(w, d, d.min)?;
            w.write_str(",\"max\":")?;
            number(w, d, d.max)?;
            if !d.kind.is_integer() {
                write!(w, ",\"decimalPlaces\":{}", decimal_places(d))?;
            }
            w.write_str(",\"group\":")?;
            string(w, stage.name())?;
            w.write_str(",\"category\":\"Standard\"")?;
            let mut values = labels(d).peekable();
            if values.peek().is_some() {
                w.write_str(",\"values\":[")?;
                for (i, (v, label)) in values.enumerate() {
                    if i > 0 {
                        w.write_char(',')?;
                    }
                    write!(w, "{{\"value\":{v},\"description\":")?;
                    string(w, label)?;
                    w.write_char('}')?;
                }
                w.write_char(']')?;
            }
            w.write_char('}')?;
        }
    }
    w.write_str("]}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decimal_places_show_the_declared_values() {
        // The lower bound 1e-5 needs five places.
        let d = ParamDef::real("X", 0.0015, 1e-5, 0.1, "", "");
        assert_eq!(decimal_places(&d), 5);
        let d = ParamDef::real("Y", 17.0, 8.0, 30.0, "m/s", "");
        assert_eq!(decimal_places(&d), 1);
        let d = ParamDef::real("Z", 0.25, 0.0, 1.0, "", "");
        assert_eq!(decimal_places(&d), 2);
    }
}
