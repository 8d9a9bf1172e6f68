//! The parameter store: every stage's parameters, flattened into one indexed table of current
//! values.
//!
//! The index order is the registry order (stage by stage, each stage in declaration order), so
//! the index and count the ground station sees are stable for a given firmware. Values are
//! `f32` in each parameter's unit, exactly as they were set (what a ground station reads back
//! is what it wrote); integer parameters hold whole numbers, exact up to 2^24. A value is
//! taken only if its stage's rule accepts the stage's values with it, so every stage can
//! always load and fly what the store holds.

use heapless::{String, Vec};
use serde::ser::SerializeSeq;
use serde::{Deserialize, Serialize, Serializer};

use super::declare::{validate_defs, Group, ParamDef, ParamError, ParamKind, Stage, MAX_NAME_LEN};

/// Most parameters the store holds.
pub const MAX_PARAMS: usize = 256;

/// A registry: one [`Group`] per stage, e.g. `&[&lateral::PARAMS, &estimator::PARAMS]`.
pub type Registry = &'static [&'static dyn Stage];

/// Why a registry cannot be used.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum RegistryError {
    /// More than [`MAX_PARAMS`] parameters.
    TooMany,
    /// A name too long, empty, non-ASCII, duplicated (also across stages), a default outside
    /// its bounds, or defaults its stage's rule refuses; the offending name.
    BadDef(&'static str),
}

impl core::fmt::Display for RegistryError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            RegistryError::TooMany => write!(f, "more than {MAX_PARAMS} parameters"),
            RegistryError::BadDef(name) => write!(f, "bad parameter definition: {name}"),
        }
    }
}

impl core::error::Error for RegistryError {}

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
#[derive(Clone)]
pub struct ParamStore {
    registry: Registry,
    values: Vec<f32, MAX_PARAMS>,
    changes: u32,
    saved_changes: u32,
}

impl core::fmt::Debug for ParamStore {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("ParamStore")
            .field("len", &self.values.len())
            .field("changes", &self.changes)
            .finish()
    }
}

impl ParamStore {
    /// Checks a registry: at most [`MAX_PARAMS`] parameters, names short, ASCII and unique
    /// across stages, defaults inside their bounds and accepted by their stage's rule.
    pub fn validate(registry: Registry) -> Result<(), RegistryError> {
        let all = || {
            registry
                .iter()
                .flat_map(|s| (0..s.len()).filter_map(|i| s.def(i)))
        };
        if all().count() > MAX_PARAMS {
            return Err(RegistryError::TooMany);
        }
        validate_defs(all()).map_err(RegistryError::BadDef)?;
        for stage in registry.iter() {
            let mut values: Vec<f32, MAX_PARAMS> = Vec::new();
            for d in (0..stage.len()).filter_map(|i| stage.def(i)) {
                values.push(d.default).map_err(|_| RegistryError::TooMany)?;
            }
            stage.check(&values).map_err(RegistryError::BadDef)?;
        }
        Ok(())
    }

    /// A store holding every parameter of `registry` at its default. The registry is a
    /// constant of the firmware, checked by [`ParamStore::validate`] in its tests; parameters
    /// beyond [`MAX_PARAMS`] would be left out.
    /// Not inlined: see `Vehicle::fresh`.
    #[inline(never)]
    pub fn new(registry: Registry) -> Self {
        let mut values: Vec<f32, MAX_PARAMS> = Vec::new();
        for stage in registry.iter() {
            for d in (0..stage.len()).filter_map(|i| stage.def(i)) {
                let _ = values.push(d.default);
            }
        }
        Self {
            registry,
            values,
            changes: 0,
            saved_changes: 0,
        }
    }

    /// Number of parameters (`param_count`).
    pub fn len(&self) -> usize {
        self.values.len()
    }

    /// Whether the store holds no parameter.
    pub fn is_empty(&self) -> bool {
        self.values.is_empty()
    }

    /// The registry the store was built from.
    pub fn registry(&self) -> Registry {
        self.registry
    }

    /// The stage holding `index`, and where its values start.
    fn stage_of(&self, index: usize) -> Option<(&'static dyn Stage, usize)> {
        let mut start = 0;
        for stage in self.registry.iter() {
            if index < start + stage.len() {
                return Some((*stage, start));
            }
            start += stage.len();
        }
        None
    }

    /// Definition of the parameter at `index`.
    pub fn def(&self, index: usize) -> Option<&'static ParamDef> {
        let (stage, start) = self.stage_of(index)?;
        stage.def(index - start)
    }

    /// Index of the parameter called `name`.
    pub fn index_of(&self, name: &str) -> Option<usize> {
        let mut start = 0;
        for stage in self.registry.iter() {
            if let Some(i) = stage.position(name) {
                return Some(start + i);
            }
            start += stage.len();
        }
        None
    }

    /// A stage's settings as the store holds them (its defaults if the group is not in the
    /// registry, which the vehicle's tests rule out).
    pub fn load<C>(&self, group: &Group<C>) -> C {
        let first = group.params.first().map(|p| p.def.name);
        group.settings(self.group_values(first, group.params.len()))
    }

    /// The `len` values of the group whose first parameter is called `first`: the stage
    /// that begins with it, one name compared a stage. Apart from [`ParamStore::load`] and not
    /// inlined: the search is the same for every settings type, and the vehicle loads some
    /// fifteen of them in one function.
    #[inline(never)]
    fn group_values(&self, first: Option<&str>, len: usize) -> Option<&[f32]> {
        let start = self.stage_start(first?)?;
        self.values.get(start..start.checked_add(len)?)
    }

    /// Where the values of the stage whose first parameter is called `first` start.
    fn stage_start(&self, first: &str) -> Option<usize> {
        let mut start: usize = 0;
        for stage in self.registry.iter() {
            if stage.def(0).is_some_and(|d| d.name == first) {
                return Some(start);
            }
            start += stage.len();
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

    /// Sets the parameter at `index` after checking it against its definition and its
    /// stage's values against the stage's rule; returns the stored value. A refused value
    /// leaves the store unchanged.
    pub fn set_index(&mut self, index: usize, value: f32) -> Result<f32, ParamError> {
        let (stage, start) = self.stage_of(index).ok_or(ParamError::Unknown)?;
        let def = stage.def(index - start).ok_or(ParamError::Unknown)?;
        let v = def.check(value)?;
        let old = *self.values.get(index).ok_or(ParamError::Unknown)?;
        if old.to_bits() == v.to_bits() {
            return Ok(v);
        }
        self.put(index, v);
        let values = self.values.get(start..start + stage.len()).unwrap_or(&[]);
        if stage.check(values).is_err() {
            self.put(index, old);
            return Err(ParamError::Inconsistent);
        }
        self.changes = self.changes.wrapping_add(1);
        Ok(v)
    }

    fn put(&mut self, index: usize, v: f32) {
        if let Some(slot) = self.values.get_mut(index) {
            *slot = v;
        }
    }

    /// Writes whole stages at once, as one change: each of `stages` in turn takes the next
    /// values of `values`, one a parameter in its declared order (the order of the settings'
    /// own `params` and of the registry). Each value is checked against its definition and
    /// each stage's values against its rule; no parameter is looked up by name, no other stage
    /// is asked. Refused as a whole (the store unchanged) with the first offending name.
    pub fn set_stages(
        &mut self,
        stages: &[&dyn Stage],
        mut values: impl Iterator<Item = f32>,
    ) -> Result<(), (&'static str, ParamError)> {
        let before = self.values.clone();
        match self.write_stages(stages, &mut values) {
            Ok(()) => {
                if self.values != before {
                    self.changes = self.changes.wrapping_add(1);
                }
                Ok(())
            }
            Err(e) => {
                self.values.clone_from(&before);
                Err(e)
            }
        }
    }

    /// Writes a stage's settings `c` (the inverse of [`ParamStore::load`]), as
    /// [`ParamStore::set_stages`] writes a stage.
    pub fn save<C>(&mut self, group: &Group<C>, c: &C) -> Result<(), (&'static str, ParamError)> {
        self.set_stages(&[group], group.values(c))
    }

    /// [`ParamStore::set_stages`]'s writes and checks, the store left as they leave it.
    fn write_stages(
        &mut self,
        stages: &[&dyn Stage],
        values: &mut dyn Iterator<Item = f32>,
    ) -> Result<(), (&'static str, ParamError)> {
        for stage in stages {
            let first = stage.def(0).map_or(stage.name(), |d| d.name);
            let start = self
                .stage_start(first)
                .ok_or((first, ParamError::Unknown))?;
            for i in 0..stage.len() {
                let d = stage.def(i).ok_or((first, ParamError::Unknown))?;
                let v = values.next().ok_or((d.name, ParamError::Unknown))?;
                self.put(start + i, d.check(v).map_err(|e| (d.name, e))?);
            }
            let now = self.values.get(start..start + stage.len()).unwrap_or(&[]);
            stage
                .check(now)
                .map_err(|at| (at, ParamError::Inconsistent))?;
        }
        Ok(())
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

    /// Loads persisted values by name; unknown names are dropped, values outside the current
    /// bounds keep the default, and a stage whose loaded values its rule refuses keeps the
    /// values it had (its records count as rejected). Order within the image does not matter.
    /// Does not count as a change to persist.
    pub fn import(&mut self, image: &ParamImage) -> ImportReport {
        self.import_with(|put| image.iter().for_each(|r| put(r.name.as_str(), r.value)))
    }

    /// As [`ParamStore::import`], from records that `records` hands to its argument, name and
    /// value, each time it is called (once, and once more for each stage whose rule refuses
    /// what was loaded): a record streamed from flash needs no image in RAM.
    pub fn import_with(
        &mut self,
        mut records: impl FnMut(&mut dyn FnMut(&str, f32)),
    ) -> ImportReport {
        let mut report = ImportReport::default();
        let before = self.values.clone();
        records(&mut |name, value| {
            let Some(i) = self.index_of(name) else {
                report.unknown += 1;
                return;
            };
            match self.def(i).map(|d| d.check(value)) {
                Some(Ok(v)) => {
                    self.put(i, v);
                    report.loaded += 1;
                }
                _ => report.rejected += 1,
            }
        });
        let mut start = 0;
        for stage in self.registry.iter() {
            let range = start..start + stage.len();
            start = range.end;
            let values = self.values.get(range.clone()).unwrap_or(&[]);
            if stage.check(values).is_ok() {
                continue;
            }
            // The stage's records that were loaded (those its definitions refused are counted
            // already).
            let mut refused = 0u16;
            records(&mut |name, value| {
                let loaded = (0..stage.len())
                    .filter_map(|i| stage.def(i))
                    .any(|d| d.name == name && d.check(value).is_ok());
                refused += u16::from(loaded);
            });
            report.loaded = report.loaded.saturating_sub(refused);
            report.rejected = report.rejected.saturating_add(refused);
            if let (Some(now), Some(was)) = (self.values.get_mut(range.clone()), before.get(range))
            {
                now.copy_from_slice(was);
            }
        }
        if self.values != before {
            self.changes = self.changes.wrapping_add(1);
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

/// The float a parameter travels as in `PARAM_VALUE`: REAL32 as is, INT32 (integers,
/// switches, choices) with its bytes in the float field (`PARAM_ENCODE_BYTEWISE`).
pub fn encode_wire(kind: ParamKind, value: f32) -> f32 {
    if kind.is_integer() {
        f32::from_bits((value as i32) as u32)
    } else {
        value
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
    use crate::param;
    use crate::params::declare::Group;

    #[derive(Clone, Copy, Default)]
    struct A {
        gain: f32,
        mode: u8,
    }
    #[derive(Clone, Copy, Default)]
    struct B {
        low: f32,
        high: f32,
    }
    const GA: Group<A> = Group {
        name: "a",
        params: &[
            param!(ParamDef::real("A_GAIN", 1.0, 0.0, 10.0, "", "a gain"), A => gain),
            param!(ParamDef::int("A_MODE", 2, 0, 5, "", "a mode"), A => mode, count),
        ],
        base: A::default,
        check: crate::params::independent,
    };
    const GB: Group<B> = Group {
        name: "b",
        params: &[
            param!(ParamDef::real("B_LOW", -3.0, -5.0, 5.0, "rad", "a lower limit"), B => low),
            param!(ParamDef::real("B_HIGH", 3.0, -5.0, 5.0, "rad", "an upper limit"), B => high),
        ],
        base: B::default,
        check: |b| if b.low < b.high { Ok(()) } else { Err("B_LOW") },
    };
    const REG: Registry = &[&GA, &GB];

    #[test]
    fn flattens_registry_in_order() {
        let s = ParamStore::new(REG);
        assert_eq!(s.len(), 4);
        assert_eq!(s.def(2).unwrap().name, "B_LOW");
        assert_eq!(s.index_of("A_MODE"), Some(1));
        assert_eq!(s.get("B_LOW"), Some(-3.0));
        assert!(s.def(4).is_none());
        assert_eq!(s.load(&GB).high, 3.0);
        assert_eq!(s.load(&GA).mode, 2);
    }

    #[test]
    fn duplicate_across_stages_refused() {
        assert_eq!(
            ParamStore::validate(&[&GA, &GA]).unwrap_err(),
            RegistryError::BadDef("A_GAIN")
        );
    }

    #[test]
    fn set_counts_changes_and_refuses_bad_values() {
        let mut s = ParamStore::new(REG);
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
    fn a_value_its_stage_refuses_is_not_stored() {
        let mut s = ParamStore::new(REG);
        // Within its bounds, but above the upper limit: the stage could not fly it.
        assert_eq!(s.set("B_LOW", 4.0), Err(ParamError::Inconsistent));
        assert_eq!(s.get("B_LOW"), Some(-3.0));
        assert_eq!(s.change_count(), 0);
        assert_eq!(s.set("B_HIGH", 4.5), Ok(4.5));
        assert_eq!(s.set("B_LOW", 4.0), Ok(4.0));
        assert_eq!(s.load(&GB).low, 4.0);
    }

    #[test]
    fn import_takes_a_consistent_image_in_any_order_and_refuses_an_inconsistent_stage() {
        let rec = |name: &str, value| ParamRecord {
            name: String::try_from(name).unwrap(),
            value,
        };
        let mut s = ParamStore::new(REG);
        // Set one at a time, B_LOW first would be refused; as an image it is consistent.
        let image: ParamImage = [rec("B_LOW", 4.0), rec("B_HIGH", 4.5), rec("A_GAIN", 2.0)]
            .into_iter()
            .collect();
        let r = s.import(&image);
        assert_eq!((r.loaded, r.rejected), (3, 0));
        assert_eq!((s.get("B_LOW"), s.get("A_GAIN")), (Some(4.0), Some(2.0)));
        assert!(!s.is_dirty());
        let bad: ParamImage = [rec("B_LOW", 1.0), rec("B_HIGH", 0.5), rec("A_MODE", 3.0)]
            .into_iter()
            .collect();
        let r = s.import(&bad);
        assert_eq!((r.loaded, r.rejected), (1, 2));
        assert_eq!((s.get("B_LOW"), s.get("B_HIGH")), (Some(4.0), Some(4.5)));
        assert_eq!(s.get("A_MODE"), Some(3.0));
    }

    #[test]
    fn whole_stages_are_written_in_order_checked_by_their_own_rules_and_refused_as_a_whole() {
        let mut s = ParamStore::new(REG);
        // B_LOW above the present B_HIGH would be refused alone; written with its stage, whose
        // values are consistent, it is taken.
        let both = [7.0, 1.0, 4.0, 4.5];
        assert_eq!(s.set_stages(&[&GA, &GB], both.into_iter()), Ok(()));
        assert_eq!((s.load(&GA).gain, s.load(&GA).mode), (7.0, 1));
        assert_eq!((s.load(&GB).low, s.load(&GB).high), (4.0, 4.5));
        assert_eq!(s.change_count(), 1);
        // The same values again: nothing moved, no change counted.
        assert_eq!(s.set_stages(&[&GB], [4.0, 4.5].into_iter()), Ok(()));
        assert_eq!(s.change_count(), 1);
        // The second stage inconsistent: the first is not written either.
        let bad = [2.0, 3.0, 1.0, 0.5];
        assert_eq!(
            s.set_stages(&[&GA, &GB], bad.into_iter()),
            Err(("B_LOW", ParamError::Inconsistent))
        );
        assert_eq!(
            s.set_stages(&[&GA], [2.0, 9.0].into_iter()),
            Err(("A_MODE", ParamError::OutOfBounds))
        );
        assert_eq!(
            s.set_stages(&[&GA], [2.0].into_iter()),
            Err(("A_MODE", ParamError::Unknown))
        );
        // A stage the store does not hold.
        let unknown = ParamStore::new(&[&GB]).set_stages(&[&GA], [1.0, 1.0].into_iter());
        assert_eq!(unknown, Err(("A_GAIN", ParamError::Unknown)));
        assert_eq!(s.load(&GA).gain, 7.0);
        assert_eq!(s.change_count(), 1);
        // A stage's settings saved are what it loads back.
        let b = B {
            low: -1.0,
            high: 2.0,
        };
        assert_eq!(s.save(&GB, &b), Ok(()));
        assert_eq!((s.load(&GB).low, s.load(&GB).high), (-1.0, 2.0));
    }

    #[test]
    fn bytewise_int_encoding() {
        assert_eq!(encode_wire(ParamKind::Int, 3.0).to_bits(), 3);
        assert_eq!(encode_wire(ParamKind::Int, -1.0).to_bits(), u32::MAX);
        assert_eq!(encode_wire(ParamKind::Bool, 1.0).to_bits(), 1);
        assert_eq!(encode_wire(ParamKind::Real, 0.5), 0.5);
    }
}
