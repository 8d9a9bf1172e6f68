//! Reading an aircraft file: TOML syntax, finite numbers, then shape, each error naming the
//! file, the key and the value; the physical checks follow in [`super::validate`].

use super::{Aircraft, AircraftError, DEFAULT_AIRCRAFT_NAME, DEFAULT_AIRCRAFT_TOML};
use std::path::Path;

impl Aircraft {
    /// The built-in Ultra Stick 25e.
    pub fn ultrastick25e() -> Result<Self, AircraftError> {
        Self::from_toml_str(DEFAULT_AIRCRAFT_TOML, Path::new(DEFAULT_AIRCRAFT_NAME))
    }

    /// Reads and validates an aircraft file.
    pub fn from_file(path: &Path) -> Result<Self, AircraftError> {
        let text = std::fs::read_to_string(path).map_err(|source| AircraftError::Read {
            file: path.to_path_buf(),
            source,
        })?;
        Self::from_toml_str(&text, path)
    }

    /// The file given, or the built-in one when `None`.
    pub fn load(path: Option<&Path>) -> Result<Self, AircraftError> {
        match path {
            Some(p) => Self::from_file(p),
            None => Self::ultrastick25e(),
        }
    }

    /// Parses and validates TOML text; `file` names it in errors.
    pub fn from_toml_str(text: &str, file: &Path) -> Result<Self, AircraftError> {
        let file_buf = file.to_path_buf();
        let table: toml::Table = toml::from_str(text).map_err(|e| AircraftError::Syntax {
            file: file_buf.clone(),
            message: e.message().to_string() + &location(text, e.span()),
        })?;
        check_finite(&toml::Value::Table(table), "", file)?;
        let de = toml::Deserializer::parse(text).map_err(|e| AircraftError::Syntax {
            file: file_buf.clone(),
            message: e.message().to_string(),
        })?;
        let aircraft: Aircraft = serde_path_to_error::deserialize(de).map_err(|e| {
            let key = e.path().to_string();
            let inner = e.into_inner();
            AircraftError::Shape {
                file: file_buf.clone(),
                key,
                message: inner.message().to_string() + &location(text, inner.span()),
            }
        })?;
        aircraft.validate(file)?;
        Ok(aircraft)
    }
}

/// " (line L, column C)" of a byte span, or nothing.
fn location(text: &str, span: Option<std::ops::Range<usize>>) -> String {
    match span {
        Some(r) if r.start <= text.len() => {
            let before = &text[..r.start];
            let line = before.matches('\n').count() + 1;
            let col = before.len() - before.rfind('\n').map_or(0, |i| i + 1) + 1;
            format!(" (line {line}, column {col})")
        }
        _ => String::new(),
    }
}

/// Rejects a NaN or an infinity anywhere in `v`, naming its dotted key (`path` is `v`'s own).
fn check_finite(v: &toml::Value, path: &str, file: &Path) -> Result<(), AircraftError> {
    match v {
        toml::Value::Float(x) if !x.is_finite() => Err(AircraftError::Value {
            file: file.to_path_buf(),
            key: path.to_string(),
            value: x.to_string(),
            reason: "must be a finite number".into(),
        }),
        toml::Value::Table(t) => {
            for (k, v) in t {
                let p = if path.is_empty() {
                    k.clone()
                } else {
                    format!("{path}.{k}")
                };
                check_finite(v, &p, file)?;
            }
            Ok(())
        }
        toml::Value::Array(a) => {
            for (i, v) in a.iter().enumerate() {
                check_finite(v, &format!("{path}[{i}]"), file)?;
            }
            Ok(())
        }
        _ => Ok(()),
    }
}
