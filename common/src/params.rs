//! How every stage declares its parameters.
//!
//! As in PX4, each stage of `common` declares its own gains, limits and settings beside its
//! code, as a `&'static [ParamDef]`. The parameter store and the ground-station protocol are
//! built from those lists; nothing else keeps a second copy of a default or a bound.

/// The MAVLink parameter type a value travels as.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ParamKind {
    /// A real number (`MAV_PARAM_TYPE_REAL32`).
    Real,
    /// An integer or enumeration (`MAV_PARAM_TYPE_INT32`), stored exactly in an `f32`.
    Int,
}

/// One parameter: a name of at most 16 characters (MAVLink's `param_id`), a default, bounds,
/// a unit and a description.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ParamDef {
    /// Name as a ground station shows it, at most 16 ASCII characters.
    pub name: &'static str,
    /// Value at first boot and after a reset to defaults.
    pub default: f32,
    /// Smallest accepted value.
    pub min: f32,
    /// Largest accepted value.
    pub max: f32,
    /// Unit, empty when dimensionless.
    pub unit: &'static str,
    /// One line saying what the parameter does.
    pub description: &'static str,
    /// How the value travels over MAVLink.
    pub kind: ParamKind,
}

/// Longest parameter name MAVLink can carry.
pub const MAX_NAME_LEN: usize = 16;

/// Why a value was refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ParamError {
    /// NaN or infinite.
    NotFinite,
    /// Outside `[min, max]`.
    OutOfBounds,
    /// Not a whole number for an integer parameter.
    NotInteger,
    /// No parameter of that name or index.
    Unknown,
}

impl ParamDef {
    /// A real-valued parameter.
    pub const fn real(
        name: &'static str,
        default: f32,
        min: f32,
        max: f32,
        unit: &'static str,
        description: &'static str,
    ) -> Self {
        Self {
            name,
            default,
            min,
            max,
            unit,
            description,
            kind: ParamKind::Real,
        }
    }

    /// An integer-valued parameter.
    pub const fn int(
        name: &'static str,
        default: i32,
        min: i32,
        max: i32,
        unit: &'static str,
        description: &'static str,
    ) -> Self {
        Self {
            name,
            default: default as f32,
            min: min as f32,
            max: max as f32,
            unit,
            description,
            kind: ParamKind::Int,
        }
    }

    /// Checks a candidate value against this definition.
    pub fn check(&self, value: f32) -> Result<f32, ParamError> {
        if !value.is_finite() {
            return Err(ParamError::NotFinite);
        }
        if value < self.min || value > self.max {
            return Err(ParamError::OutOfBounds);
        }
        if self.kind == ParamKind::Int && libm::truncf(value) != value {
            return Err(ParamError::NotInteger);
        }
        Ok(value)
    }
}

/// Looks a parameter up in `defs` and checks a candidate value against it.
pub fn check_param(defs: &[ParamDef], name: &str, value: f32) -> Result<f32, ParamError> {
    defs.iter()
        .find(|d| d.name == name)
        .ok_or(ParamError::Unknown)?
        .check(value)
}

/// The default of a parameter of `defs` (0 when absent, which the tests rule out).
pub const fn default_of(defs: &[ParamDef], name: &str) -> f32 {
    let mut i = 0;
    while i < defs.len() {
        if str_eq(defs[i].name, name) {
            return defs[i].default;
        }
        i += 1;
    }
    0.0
}

const fn str_eq(a: &str, b: &str) -> bool {
    let (a, b) = (a.as_bytes(), b.as_bytes());
    if a.len() != b.len() {
        return false;
    }
    let mut i = 0;
    while i < a.len() {
        if a[i] != b[i] {
            return false;
        }
        i += 1;
    }
    true
}

/// Checks that a list of definitions is well formed: names short, ASCII, unique; defaults
/// inside their bounds. Used by each stage's tests.
pub fn validate_defs(defs: &[ParamDef]) -> Result<(), &'static str> {
    for (i, d) in defs.iter().enumerate() {
        if d.name.is_empty() || d.name.len() > MAX_NAME_LEN || !d.name.is_ascii() {
            return Err(d.name);
        }
        if d.check(d.default).is_err() || d.min > d.max {
            return Err(d.name);
        }
        if defs.iter().skip(i + 1).any(|o| o.name == d.name) {
            return Err(d.name);
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn check_refuses_bad_values() {
        let d = ParamDef::real("RLL_KP", -1.0, -5.0, 0.0, "", "roll gain");
        assert_eq!(d.check(-2.0), Ok(-2.0));
        assert_eq!(d.check(f32::NAN), Err(ParamError::NotFinite));
        assert_eq!(d.check(1.0), Err(ParamError::OutOfBounds));
        let i = ParamDef::int("MODE", 1, 0, 3, "", "a mode");
        assert_eq!(i.check(1.5), Err(ParamError::NotInteger));
        assert!(validate_defs(&[d, i]).is_ok());
        assert!(validate_defs(&[d, d]).is_err());
        let long = ParamDef::real("THIS_NAME_IS_TOO_LONG", 0.0, 0.0, 1.0, "", "");
        assert!(validate_defs(&[long]).is_err());
    }
}
