//! How a stage declares a parameter: its definition ([`ParamDef`]), the field it sets
//! ([`Param`], made with [`crate::param!`]), and the stage's list with its rule ([`Group`]).

/// The kind of a value, and so how it travels over MAVLink.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ParamKind {
    /// A real number (`MAV_PARAM_TYPE_REAL32`).
    Real,
    /// An integer (`MAV_PARAM_TYPE_INT32`), stored exactly in an `f32`.
    Int,
    /// Off (0) or on (1) (`MAV_PARAM_TYPE_INT32`).
    Bool,
    /// One of named values 0, 1, ... (`MAV_PARAM_TYPE_INT32`); the labels in value order.
    Enum(HostOnly<&'static [&'static str]>),
}

impl ParamKind {
    /// Whether values are whole numbers (every kind but [`ParamKind::Real`]).
    pub const fn is_integer(self) -> bool {
        !matches!(self, ParamKind::Real)
    }
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
    pub unit: HostOnly<&'static str>,
    /// One line saying what the parameter does.
    pub description: HostOnly<&'static str>,
    /// What kind of value it is.
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
    /// Not a whole number for an integer, boolean or enumerated parameter.
    NotInteger,
    /// No parameter of that name or index.
    Unknown,
    /// Within its own bounds, but contradicting another value of its stage (a lower limit
    /// above the upper one, a trim outside its travel): the stage would refuse to fly it.
    Inconsistent,
}

impl ParamError {
    /// A few words for a STATUSTEXT.
    pub const fn text(self) -> &'static str {
        match self {
            ParamError::NotFinite => "not a finite number",
            ParamError::OutOfBounds => "out of bounds",
            ParamError::NotInteger => "not an integer",
            ParamError::Unknown => "unknown",
            ParamError::Inconsistent => "contradicts another value",
        }
    }
}

impl core::fmt::Display for ParamError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(self.text())
    }
}

impl core::error::Error for ParamError {}

/// A value the host build keeps and the MCU image does not carry: a parameter's unit,
/// description and labels. They reach a ground station in the parameter metadata file, which
/// the firmware's build script writes on the host and the image serves compressed; nothing on
/// board reads them, so the image carries neither the texts nor room for them (24 bytes of
/// each of some 140 parameter definitions, and the lists of labels: 3.5 KB of flash).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct HostOnly<T: Copy + 'static>(
    #[cfg(not(target_os = "none"))] T,
    #[cfg(target_os = "none")] core::marker::PhantomData<T>,
);

impl<T: Copy + Default + 'static> HostOnly<T> {
    /// `value`, kept on the host only.
    pub const fn new(value: T) -> Self {
        #[cfg(not(target_os = "none"))]
        return Self(value);
        #[cfg(target_os = "none")]
        {
            let _ = value;
            Self(core::marker::PhantomData)
        }
    }

    /// The value on the host; on the MCU the type's default (an empty text or list).
    pub fn get(self) -> T {
        #[cfg(not(target_os = "none"))]
        return self.0;
        #[cfg(target_os = "none")]
        T::default()
    }
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
            unit: HostOnly::new(unit),
            description: HostOnly::new(description),
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
            unit: HostOnly::new(unit),
            description: HostOnly::new(description),
            kind: ParamKind::Int,
        }
    }

    /// A switch: 0 off, 1 on.
    pub const fn boolean(name: &'static str, default: bool, description: &'static str) -> Self {
        Self {
            name,
            default: if default { 1.0 } else { 0.0 },
            min: 0.0,
            max: 1.0,
            unit: HostOnly::new(""),
            description: HostOnly::new(description),
            kind: ParamKind::Bool,
        }
    }

    /// A choice among named values 0, 1, ... `labels.len() - 1`.
    pub const fn choice(
        name: &'static str,
        default: u8,
        labels: &'static [&'static str],
        description: &'static str,
    ) -> Self {
        Self {
            name,
            default: default as f32,
            min: 0.0,
            max: (labels.len() - 1) as f32,
            unit: HostOnly::new(""),
            description: HostOnly::new(description),
            kind: ParamKind::Enum(HostOnly::new(labels)),
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
        if self.kind.is_integer() && libm::truncf(value) != value {
            return Err(ParamError::NotInteger);
        }
        Ok(value)
    }

    /// Like [`ParamDef::check`], for a value converted from a field in other units (degrees
    /// from radians): within 1e-5 relative of a bound it counts as on it, since 25 deg -> rad
    /// -> deg may land a rounding step outside a bound it was set to.
    pub fn check_converted(&self, value: f32) -> Result<f32, ParamError> {
        let near = |bound: f32| libm::fabsf(value - bound) <= 1e-5 * libm::fabsf(bound).max(1.0);
        let v = if value.is_finite() && near(self.max) {
            value.min(self.max)
        } else if value.is_finite() && near(self.min) {
            value.max(self.min)
        } else {
            value
        };
        self.check(v)
    }
}

/// A parameter bound to the field of a stage's settings `C` it sets. The parameter's value is
/// in the parameter's unit; `get` and `set` convert to and from the field (degrees to
/// radians, a number to a count, 0/1 to a flag, an index to an enumeration).
pub struct Param<C: 'static> {
    /// The declaration.
    pub def: ParamDef,
    /// The field's value in the parameter's unit.
    pub get: fn(&C) -> f32,
    /// Writes a value (already checked against `def`) into the field.
    pub set: fn(&mut C, f32),
}

/// An enumeration a [`ParamKind::Enum`] parameter selects.
pub trait Choice: Sized + Copy {
    /// The value of index `i`, if there is one.
    fn from_index(i: u8) -> Option<Self>;
    /// The index of this value.
    fn index(self) -> u8;
}

/// A [`Param`] bound to a field of `$C`:
/// - `param!(def, C => a.b)`: an `f32` field in the parameter's unit;
/// - `param!(def, C => a.b[i])`: one element of an `f32` array;
/// - `param!(def, C => a.b, scale k)`: parameter value = field * k (k = `RAD2DEG` for a
///   parameter in degrees of a field in radians);
/// - `param!(def, C => a.b, unit k)`: field = parameter value * k (k = `DEG` for the same);
/// - `param!(def, C => a.b, count)`: an integer field;
/// - `param!(def, C => a.b, flag)`: a `bool` field (0 / 1);
/// - `param!(def, C => a.b, choice)`: a field of a type implementing [`Choice`].
#[macro_export]
macro_rules! param {
    ($def:expr, $C:ty => $($f:ident).+) => {
        $crate::params::declare::Param::<$C> {
            def: $def,
            get: |c: &$C| c.$($f).+,
            set: |c: &mut $C, v: f32| c.$($f).+ = v,
        }
    };
    ($def:expr, $C:ty => $($f:ident).+ [$i:literal]) => {
        $crate::params::declare::Param::<$C> {
            def: $def,
            get: |c: &$C| c.$($f).+[$i],
            set: |c: &mut $C, v: f32| c.$($f).+[$i] = v,
        }
    };
    ($def:expr, $C:ty => $($f:ident).+, scale $k:expr) => {
        $crate::params::declare::Param::<$C> {
            def: $def,
            get: |c: &$C| c.$($f).+ * $k,
            set: |c: &mut $C, v: f32| c.$($f).+ = v / $k,
        }
    };
    ($def:expr, $C:ty => $($f:ident).+, unit $k:expr) => {
        $crate::params::declare::Param::<$C> {
            def: $def,
            get: |c: &$C| c.$($f).+ / $k,
            set: |c: &mut $C, v: f32| c.$($f).+ = v * $k,
        }
    };
    ($def:expr, $C:ty => $($f:ident).+, count) => {
        $crate::params::declare::Param::<$C> {
            def: $def,
            get: |c: &$C| c.$($f).+ as f32,
            // Checked as a whole number within the bounds before it gets here.
            set: |c: &mut $C, v: f32| c.$($f).+ = v as _,
        }
    };
    ($def:expr, $C:ty => $($f:ident).+, flag) => {
        $crate::params::declare::Param::<$C> {
            def: $def,
            get: |c: &$C| if c.$($f).+ { 1.0 } else { 0.0 },
            set: |c: &mut $C, v: f32| c.$($f).+ = v >= 0.5,
        }
    };
    ($def:expr, $C:ty => $($f:ident).+, choice) => {
        $crate::params::declare::Param::<$C> {
            def: $def,
            get: |c: &$C| f32::from($crate::params::declare::Choice::index(c.$($f).+)),
            set: |c: &mut $C, v: f32| {
                if let Some(e) = $crate::params::declare::Choice::from_index(v as u8) {
                    c.$($f).+ = e;
                }
            },
        }
    };
}

/// A stage's parameters: its settings type `C`, each field's parameter, and the rule its
/// values obey together.
pub struct Group<C: 'static> {
    /// The stage, as the parameter documentation heads it.
    pub name: &'static str,
    /// Every parameter of the stage, in the order a ground station lists them.
    pub params: &'static [Param<C>],
    /// Any valid settings value; every field a parameter binds is overwritten by `load`.
    pub base: fn() -> C,
    /// The stage's own check of a whole set of values; `Err` names the parameter at fault.
    pub check: fn(&C) -> Result<(), &'static str>,
}

/// A group's rule when its values are independent of each other.
pub fn independent<C>(_: &C) -> Result<(), &'static str> {
    Ok(())
}

impl<C: 'static> Group<C> {
    /// The settings with every parameter at its default.
    pub fn defaults(&self) -> C {
        self.settings(None)
    }

    /// The settings from this group's values, in parameter order (as the store keeps them).
    /// Values must have passed their definitions' checks; missing ones keep the base.
    pub fn load(&self, values: &[f32]) -> C {
        self.settings(Some(values))
    }

    /// The values of `c`'s fields in parameter units, in parameter order: what
    /// [`Group::load`] takes back.
    pub fn values<'a>(&'a self, c: &'a C) -> impl Iterator<Item = f32> + 'a {
        self.params.iter().map(move |p| (p.get)(c))
    }

    /// [`Group::load`] of `values`, or [`Group::defaults`] if there are none: one loop for
    /// both, so that a caller that may take either (the parameter store) has one copy of it
    /// for each settings type, not two.
    pub fn settings(&self, values: Option<&[f32]>) -> C {
        let mut c = (self.base)();
        for (i, p) in self.params.iter().enumerate() {
            let v = match values {
                Some(values) => values.get(i).copied(),
                None => Some(p.def.default),
            };
            if let Some(v) = v {
                (p.set)(&mut c, v);
            }
        }
        c
    }

    /// The declarations, in order.
    pub fn defs(&self) -> impl Iterator<Item = &'static ParamDef> + Clone {
        let params: &'static [Param<C>] = self.params;
        params.iter().map(|p| &p.def)
    }

    /// The parameter called `name`.
    pub fn find(&self, name: &str) -> Option<&'static Param<C>> {
        self.params.iter().find(|p| p.def.name == name)
    }

    /// Sets one field by parameter name, after checking the value against its definition
    /// (not against the group's rule: see [`Group::validate`]).
    pub fn set(&self, c: &mut C, name: &str, value: f32) -> Result<(), ParamError> {
        let p = self.find(name).ok_or(ParamError::Unknown)?;
        (p.set)(c, p.def.check(value)?);
        Ok(())
    }

    /// The value of one parameter in `c`, in the parameter's unit.
    pub fn get(&self, c: &C, name: &str) -> Option<f32> {
        self.find(name).map(|p| (p.get)(c))
    }

    /// Checks settings built elsewhere (a gain set from a file, a design): every field within
    /// its parameter's definition, then the group's rule. The error names the parameter.
    pub fn validate(&self, c: &C) -> Result<(), (&'static str, ParamError)> {
        for p in self.params {
            p.def
                .check_converted((p.get)(c))
                .map_err(|e| (p.def.name, e))?;
        }
        (self.check)(c).map_err(|name| (name, ParamError::Inconsistent))
    }
}

/// What the store needs of a group whatever its settings type.
pub trait Stage: Sync {
    /// The stage's name.
    fn name(&self) -> &'static str;
    /// Number of parameters.
    fn len(&self) -> usize;
    /// Whether the stage has no parameter.
    fn is_empty(&self) -> bool {
        self.len() == 0
    }
    /// Definition of parameter `i` of the stage.
    fn def(&self, i: usize) -> Option<&'static ParamDef>;
    /// Index in the stage of the parameter called `name`.
    fn position(&self, name: &str) -> Option<usize>;
    /// The group's rule over its values (in parameter order); `Err` names the parameter.
    fn check(&self, values: &[f32]) -> Result<(), &'static str>;
}

impl<C: 'static> Stage for Group<C> {
    fn name(&self) -> &'static str {
        self.name
    }

    fn len(&self) -> usize {
        self.params.len()
    }

    fn def(&self, i: usize) -> Option<&'static ParamDef> {
        let params: &'static [Param<C>] = self.params;
        params.get(i).map(|p| &p.def)
    }

    // Over the slice itself: one call through the vtable a stage, not one a parameter (the
    // autotune's gains, set by name, took 200 k instructions of one MCU control period).
    fn position(&self, name: &str) -> Option<usize> {
        self.params.iter().position(|p| p.def.name == name)
    }

    fn check(&self, values: &[f32]) -> Result<(), &'static str> {
        (self.check)(&self.load(values))
    }
}

/// Checks that a list of definitions is well formed: names short, ASCII, unique; defaults
/// inside their bounds.
pub fn validate_defs<'a>(defs: impl Iterator<Item = &'a ParamDef> + Clone) -> Result<(), &'a str> {
    for (i, d) in defs.clone().enumerate() {
        if d.name.is_empty() || d.name.len() > MAX_NAME_LEN || !d.name.is_ascii() {
            return Err(d.name);
        }
        if d.check(d.default).is_err() || d.min > d.max {
            return Err(d.name);
        }
        if defs.clone().skip(i + 1).any(|o| o.name == d.name) {
            return Err(d.name);
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Clone, Copy, Debug, PartialEq)]
    enum Law {
        Classic,
        Energy,
    }

    impl Choice for Law {
        fn from_index(i: u8) -> Option<Self> {
            [Law::Classic, Law::Energy].get(usize::from(i)).copied()
        }
        fn index(self) -> u8 {
            self as u8
        }
    }

    #[derive(Clone, Copy, Debug, PartialEq)]
    struct Settings {
        gain: f32,
        limit_rad: f32,
        axes: [f32; 2],
        count: u32,
        on: bool,
        law: Law,
    }

    const ZERO: Settings = Settings {
        gain: 0.0,
        limit_rad: 0.0,
        axes: [0.0; 2],
        count: 0,
        on: false,
        law: Law::Classic,
    };

    const GROUP: Group<Settings> = Group {
        name: "test",
        params: &[
            param!(ParamDef::real("T_GAIN", 0.5, 0.0, 1.0, "", "a gain"), Settings => gain),
            param!(
                ParamDef::real("T_LIM_DEG", 30.0, 0.0, 90.0, "deg", "a limit"),
                Settings => limit_rad,
                scale crate::math::RAD2DEG
            ),
            param!(ParamDef::real("T_AX_Y", -0.25, -1.0, 1.0, "", "an axis"), Settings => axes[1]),
            param!(ParamDef::int("T_COUNT", 7, 1, 9, "", "a count"), Settings => count, count),
            param!(ParamDef::boolean("T_ON", true, "a switch"), Settings => on, flag),
            param!(
                ParamDef::choice("T_LAW", 1, &["classic", "energy"], "a law"),
                Settings => law,
                choice
            ),
        ],
        base: || ZERO,
        check: |s| {
            if s.gain > 0.9 && s.on {
                Err("T_GAIN")
            } else {
                Ok(())
            }
        },
    };

    #[test]
    fn a_group_binds_each_kind_of_field_to_its_parameter() {
        let s = GROUP.defaults();
        assert_eq!(s.gain, 0.5);
        assert!((s.limit_rad - core::f32::consts::FRAC_PI_6).abs() < 1e-7);
        assert_eq!(s.axes, [0.0, -0.25]);
        assert_eq!((s.count, s.on, s.law), (7, true, Law::Energy));
        assert!((GROUP.get(&s, "T_LIM_DEG").unwrap() - 30.0).abs() < 1e-5);
        assert_eq!(GROUP.get(&s, "T_LAW"), Some(1.0));
        let mut t = s;
        assert_eq!(
            GROUP.set(&mut t, "T_COUNT", 2.5),
            Err(ParamError::NotInteger)
        );
        assert_eq!(
            GROUP.set(&mut t, "T_LAW", 2.0),
            Err(ParamError::OutOfBounds)
        );
        assert_eq!(GROUP.set(&mut t, "T_NOPE", 2.0), Err(ParamError::Unknown));
        assert_eq!(t, s);
        GROUP.set(&mut t, "T_ON", 0.0).unwrap();
        assert!(!t.on);
    }

    #[test]
    fn validate_applies_the_bounds_then_the_groups_rule() {
        let mut s = GROUP.defaults();
        assert_eq!(GROUP.validate(&s), Ok(()));
        // 90 deg through radians and back lands a rounding step off the bound: accepted.
        s.limit_rad = 90.0 * crate::math::DEG;
        assert_eq!(GROUP.validate(&s), Ok(()));
        s.gain = 0.95;
        assert_eq!(
            GROUP.validate(&s),
            Err(("T_GAIN", ParamError::Inconsistent))
        );
        s.gain = 2.0;
        assert_eq!(GROUP.validate(&s), Err(("T_GAIN", ParamError::OutOfBounds)));
    }

    #[test]
    fn check_refuses_bad_values() {
        let d = ParamDef::real("RLL_KP", -1.0, -5.0, 0.0, "", "roll gain");
        assert_eq!(d.check(-2.0), Ok(-2.0));
        assert_eq!(d.check(f32::NAN), Err(ParamError::NotFinite));
        assert_eq!(d.check(1.0), Err(ParamError::OutOfBounds));
        let i = ParamDef::int("MODE", 1, 0, 3, "", "a mode");
        assert_eq!(i.check(1.5), Err(ParamError::NotInteger));
        let b = ParamDef::boolean("SW", false, "a switch");
        assert_eq!(b.check(0.5), Err(ParamError::NotInteger));
        assert_eq!(b.check(2.0), Err(ParamError::OutOfBounds));
        assert!(validate_defs([d, i, b].iter()).is_ok());
        assert!(validate_defs([d, d].iter()).is_err());
        let long = ParamDef::real("THIS_NAME_IS_TOO_LONG", 0.0, 0.0, 1.0, "", "");
        assert!(validate_defs([long].iter()).is_err());
    }
}
