//! The parameter store: every stage's [`ParamDef`] list, flattened into one indexed table of
//! current values.
//!
//! The index order is the registry order (stage by stage, each stage in declaration order), so
//! the index and count the ground station sees are stable for a given firmware. Values are
//! `f32`; integer parameters hold whole numbers, exact up to 2^24.

use heapless::{String, Vec};
use serde::ser::SerializeSeq;
use serde::{Deserialize, Serialize, Serializer};

use crate::params::{ParamDef, ParamError, ParamKind, MAX_NAME_LEN};

/// Most parameters the store holds.
pub const MAX_PARAMS: usize = 256;

/// A registry: one `PARAMS` list per stage, e.g. `&[control::PARAMS, estimator::PARAMS]`.
pub type Registry = &'static [&'static [ParamDef]];

/// Why a registry cannot be used.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum RegistryError {
    /// More than [`MAX_PARAMS`] parameters.
    TooMany,
    /// A name too long, empty, non-ASCII, duplicated (also across stages), or a default
    /// outside its bounds; the offending name.
    BadDef(&'static str),
}

/// One persisted value, keyed by name so a reordered or extended table still loads.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ParamRecord {
    /// Parameter name.
    pub name: String<MAX_NAME_LEN>,
    /// Value.
    pub value: f32,
}

/// All values of a store in their persisted form.
pub type ParamImage = Vec<ParamRecord, MAX_PARAMS>;

/// Result of loading a [`ParamImage`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ImportReport {
    /// Values taken.
    pub loaded: u16,
    /// Names this firmware does not have (dropped).
    pub unknown: u16,
    /// Values refused by the current bounds (the default stays).
    pub rejected: u16,
}

/// The current value of every registered parameter.
#[derive(Clone, Debug)]
pub struct ParamStore {
    registry: Registry,
    values: Vec<f32, MAX_PARAMS>,
    changes: u32,
    saved_changes: u32,
}

impl ParamStore {
    /// A store holding every parameter of `registry` at its default.
    pub fn new(registry: Registry) -> Result<Self, RegistryError> {
        let mut values = Vec::new();
        for (si, stage) in registry.iter().enumerate() {
            if let Err(name) = crate::params::validate_defs(stage) {
                return Err(RegistryError::BadDef(name));
            }
            for d in stage.iter() {
                // Names must be unique across stages too: a ground station addresses by name.
                let dup = registry
                    .iter()
                    .skip(si + 1)
                    .any(|later| later.iter().any(|o| o.name == d.name));
                if dup {
                    return Err(RegistryError::BadDef(d.name));
                }
                values.push(d.default).map_err(|_| RegistryError::TooMany)?;
            }
        }
        Ok(Self {
            registry,
            values,
            changes: 0,
            saved_changes: 0,
        })
    }

    /// Number of parameters (`param_count`).
    pub fn len(&self) -> usize {
        self.values.len()
    }

    /// Whether the store holds no parameter.
    pub fn is_empty(&self) -> bool {
        self.values.is_empty()
    }

    /// Definition of the parameter at `index`.
    pub fn def(&self, index: usize) -> Option<&'static ParamDef> {
        let mut i = index;
        for stage in self.registry.iter() {
            if i < stage.len() {
                return stage.get(i);
            }
            i -= stage.len();
        }
        None
    }

    /// Index of the parameter called `name`.
    pub fn index_of(&self, name: &str) -> Option<usize> {
        let mut base = 0;
        for stage in self.registry.iter() {
            if let Some(i) = stage.iter().position(|d| d.name == name) {
                return Some(base + i);
            }
            base += stage.len();
        }
        None
    }

    /// Value at `index`.
    pub fn value(&self, index: usize) -> Option<f32> {
        self.values.get(index).copied()
    }

    /// Value of the parameter called `name`.
    pub fn get(&self, name: &str) -> Option<f32> {
        self.index_of(name).and_then(|i| self.value(i))
    }

    /// Sets the parameter at `index` after checking it against its definition; returns the
    /// stored value. A refused value leaves the store unchanged.
    pub fn set_index(&mut self, index: usize, value: f32) -> Result<f32, ParamError> {
        let def = self.def(index).ok_or(ParamError::Unknown)?;
        let v = def.check(value)?;
        let slot = self.values.get_mut(index).ok_or(ParamError::Unknown)?;
        if slot.to_bits() != v.to_bits() {
            *slot = v;
            self.changes = self.changes.wrapping_add(1);
        }
        Ok(v)
    }

    /// Sets the parameter called `name`; see [`ParamStore::set_index`].
    pub fn set(&mut self, name: &str, value: f32) -> Result<f32, ParamError> {
        let i = self.index_of(name).ok_or(ParamError::Unknown)?;
        self.set_index(i, value)
    }

    /// Puts every parameter back to its default.
    pub fn reset_to_defaults(&mut self) {
        for i in 0..self.values.len() {
            if let (Some(d), Some(slot)) = (self.def(i), self.values.get_mut(i)) {
                if slot.to_bits() != d.default.to_bits() {
                    *slot = d.default;
                    self.changes = self.changes.wrapping_add(1);
                }
            }
        }
    }

    /// Counts every change of a value; a stage can re-read its gains when it moves.
    pub fn change_count(&self) -> u32 {
        self.changes
    }

    /// Whether values changed since the last [`ParamStore::mark_saved`].
    pub fn is_dirty(&self) -> bool {
        self.changes != self.saved_changes
    }

    /// Records that the current values have been persisted.
    pub fn mark_saved(&mut self) {
        self.saved_changes = self.changes;
    }

    /// Every value that differs from its default, by name (defaults need not be stored: a
    /// new firmware's defaults then apply to parameters the user never touched).
    pub fn export(&self) -> ParamImage {
        let mut image = ParamImage::new();
        for (i, v) in self.values.iter().enumerate() {
            if let Some(d) = self.def(i) {
                if v.to_bits() != d.default.to_bits() {
                    let mut name = String::new();
                    // Names were validated to fit at construction.
                    let _ = name.push_str(d.name);
                    let _ = image.push(ParamRecord { name, value: *v });
                }
            }
        }
        image
    }

    /// Loads persisted values by name; unknown names are dropped and values outside the
    /// current bounds keep the default. Does not count as a change to persist.
    pub fn import(&mut self, image: &ParamImage) -> ImportReport {
        let mut report = ImportReport::default();
        for rec in image.iter() {
            match self.set(rec.name.as_str(), rec.value) {
                Ok(_) => report.loaded += 1,
                Err(ParamError::Unknown) => report.unknown += 1,
                Err(_) => report.rejected += 1,
            }
        }
        self.saved_changes = self.changes;
        report
    }
}

/// Serialises the values [`ParamStore::export`] would return, in the same encoding as a
/// [`ParamImage`], without building one (the image is 8 KiB: too much for the stack of a
/// flying MCU when it saves).
pub struct ParamExport<'a>(pub &'a ParamStore);

impl Serialize for ParamExport<'_> {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let store = self.0;
        let changed = || {
            (0..store.len()).filter_map(move |i| {
                let d = store.def(i)?;
                let v = store.value(i)?;
                (v.to_bits() != d.default.to_bits()).then_some((d.name, v))
            })
        };
        let mut seq = serializer.serialize_seq(Some(changed().count()))?;
        for rec in changed() {
            // (name, value) encodes exactly as a ParamRecord.
            seq.serialize_element(&rec)?;
        }
        seq.end()
    }
}

/// The float a parameter travels as in `PARAM_VALUE`: REAL32 as is, INT32 with its bytes in
/// the float field (`PARAM_ENCODE_BYTEWISE`).
pub fn encode_wire(kind: ParamKind, value: f32) -> f32 {
    match kind {
        ParamKind::Real => value,
        ParamKind::Int => f32::from_bits((value as i32) as u32),
    }
}

/// Trims the NUL padding of a MAVLink `param_id`; `None` if it is not ASCII.
pub fn param_id_str(raw: &[u8]) -> Option<&str> {
    let end = raw.iter().position(|&b| b == 0).unwrap_or(raw.len());
    let bytes = raw.get(..end)?;
    if !bytes.is_ascii() {
        return None;
    }
    core::str::from_utf8(bytes).ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    const A: &[ParamDef] = &[
        ParamDef::real("A_GAIN", 1.0, 0.0, 10.0, "", "a gain"),
        ParamDef::int("A_MODE", 2, 0, 5, "", "a mode"),
    ];
    const B: &[ParamDef] = &[ParamDef::real("B_LIM", -3.0, -5.0, 0.0, "rad", "a limit")];

    #[test]
    fn flattens_registry_in_order() {
        let s = ParamStore::new(&[A, B]).unwrap();
        assert_eq!(s.len(), 3);
        assert_eq!(s.def(2).unwrap().name, "B_LIM");
        assert_eq!(s.index_of("A_MODE"), Some(1));
        assert_eq!(s.get("B_LIM"), Some(-3.0));
        assert!(s.def(3).is_none());
    }

    #[test]
    fn duplicate_across_stages_refused() {
        assert_eq!(
            ParamStore::new(&[A, A]).unwrap_err(),
            RegistryError::BadDef("A_GAIN")
        );
    }

    #[test]
    fn set_counts_changes_and_refuses_bad_values() {
        let mut s = ParamStore::new(&[A, B]).unwrap();
        assert!(!s.is_dirty());
        assert_eq!(s.set("A_GAIN", 2.5), Ok(2.5));
        assert_eq!(s.change_count(), 1);
        assert!(s.is_dirty());
        assert_eq!(s.set("A_GAIN", f32::NAN), Err(ParamError::NotFinite));
        assert_eq!(s.set("A_MODE", 1.5), Err(ParamError::NotInteger));
        assert_eq!(s.set("A_MODE", 9.0), Err(ParamError::OutOfBounds));
        assert_eq!(s.set("NOPE", 1.0), Err(ParamError::Unknown));
        assert_eq!(s.get("A_GAIN"), Some(2.5));
        assert_eq!(s.change_count(), 1);
        s.mark_saved();
        assert!(!s.is_dirty());
    }

    #[test]
    fn bytewise_int_encoding() {
        assert_eq!(encode_wire(ParamKind::Int, 3.0).to_bits(), 3);
        assert_eq!(encode_wire(ParamKind::Int, -1.0).to_bits(), u32::MAX);
        assert_eq!(encode_wire(ParamKind::Real, 0.5), 0.5);
    }
}
