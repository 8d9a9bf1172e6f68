//! The gain sets a scenario flies: the named sets of `common`, the set designed for the
//! aircraft flown, or a gain file.

use crate::aircraft::Aircraft;
use crate::analysis::design::computed_gain_set_at;
use anyhow::Context;
use common::control::gains::{GainSet, NAMES};

/// Name of the gain set designed from the linear model of the aircraft flown, at the trim
/// airspeed ([`computed_gain_set_at`]).
pub const COMPUTED: &str = "computed";

/// Name of the flight defaults with the altitude modes flown by the total energy control
/// (`LON_LAW` = 1): the set `sim-host laws` holds against `flight`.
pub const FLIGHT_TECS: &str = "flight_tecs";

/// The gain sets the command flies by default: the named sets of `common`, then [`COMPUTED`].
pub fn gain_set_names() -> Vec<&'static str> {
    let mut v = NAMES.to_vec();
    v.push(COMPUTED);
    v
}

/// Every gain-set name the command knows: [`gain_set_names`] and [`FLIGHT_TECS`].
pub fn known_gain_set_names() -> Vec<&'static str> {
    let mut v = gain_set_names();
    v.push(FLIGHT_TECS);
    v
}

/// An unknown gain-set name, with the valid ones.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("unknown gain set `{name}`; valid names: {}", valid.join(", "))]
pub struct UnknownGainSet {
    /// The name asked for.
    pub name: String,
    /// The valid names.
    pub valid: Vec<&'static str>,
}

/// Reads a gain set from a TOML file (the `GainSet` fields: `[lateral]`, `[longitudinal]`,
/// `transfer_tc`; as `sim-host design --write-gains` writes it). Every gain must be there and
/// finite: the error names the file and the gain.
pub fn gain_file(path: &std::path::Path) -> anyhow::Result<GainSet> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("gain file `{}`: cannot read", path.display()))?;
    let de = toml::Deserializer::parse(&text)
        .map_err(|e| anyhow::anyhow!("gain file `{}`: {e}", path.display()))?;
    let g: GainSet = serde_path_to_error::deserialize(de).map_err(|e| {
        anyhow::anyhow!(
            "gain file `{}`: key `{}`: {}",
            path.display(),
            e.path(),
            e.inner()
        )
    })?;
    g.validate().map_err(|e| {
        anyhow::anyhow!(
            "gain file `{}`: gain `{}` refused ({e:?})",
            path.display(),
            e.name()
        )
    })?;
    Ok(g)
}

/// The gain set of this name for `aircraft` at its cruise airspeed: [`gain_set_at`].
pub fn gain_set(aircraft: &Aircraft, name: &str) -> anyhow::Result<GainSet> {
    gain_set_at(aircraft, name, aircraft.cruise_airspeed_mps())
}

/// The gain set of this name for `aircraft` flown at `va_mps` (only [`COMPUTED`] depends on
/// the aircraft and the airspeed: it is designed at the level trim there); a name ending in
/// `.toml` is a gain file.
pub fn gain_set_at(aircraft: &Aircraft, name: &str, va_mps: f64) -> anyhow::Result<GainSet> {
    if name.ends_with(".toml") {
        return gain_file(std::path::Path::new(name));
    }
    if name == COMPUTED {
        return computed_gain_set_at(aircraft, va_mps).context("designing the computed gain set");
    }
    if name == FLIGHT_TECS {
        let mut g = GainSet::FLIGHT;
        g.tecs = common::control::longitudinal::tecs::gains::ENGAGED;
        return Ok(g);
    }
    GainSet::named(name).map_err(|_| {
        UnknownGainSet {
            name: name.to_string(),
            valid: known_gain_set_names(),
        }
        .into()
    })
}
