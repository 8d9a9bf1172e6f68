//! Parameters: how each stage declares its settings, and the one store that holds them.
//!
//! As in PX4, each stage of `common` declares its own gains, limits and settings beside its
//! code, as a [`Group`]: a list of [`Param`]s, each a [`ParamDef`] (name, kind, default,
//! bounds, unit, description) bound to the field of the stage's settings struct it sets, and
//! the rule that the stage's values must satisfy together. The vehicle composes the groups
//! into one [`Registry`]; the [`store::ParamStore`] holds the current values, the ground
//! link serves them, storage persists them and each stage loads its settings from them.
//! Nothing else keeps a second copy of a name, a default or a bound.

pub mod declare;
pub mod metadata;
pub mod store;

pub use declare::{
    independent, validate_defs, Choice, Group, HostOnly, Param, ParamDef, ParamError, ParamKind,
    Stage, MAX_NAME_LEN,
};
pub use store::{ParamStore, Registry, RegistryError};
