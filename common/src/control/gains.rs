//! Gains as data: every gain, limit, trim and filter constant of the autopilot in one
//! [`GainSet`], the named sets of the thesis, and the mapping to named parameters.
//!
//! All values are SI and radians. Sign convention: the University of Minnesota model's (positive
//! aileron rolls left, positive elevator pitches nose down, positive rudder yaws nose left), so
//! the roll and pitch loop gains are negative, as in the thesis. Every loop computes
//! `u = trim + kp e + ki int(e) - kd rate` with `e = setpoint - measurement`.
//!
//! # Where the thesis contradicts itself
//! Each reading is kept as its own named set (see [`NAMED`]):
//! - roll `ki` is -0.1 in Table 3.3 but -0.01 in Table 3.10 and Appendix D; the roll-rate `kd` is
//!   -0.0618 in Table 3.3 but -0.072 in Table 3.10 / Appendix D; course `ki` is 0.01 in Table 3.4
//!   but 0.008 in Table 3.10: [`DESIGNED`] takes the chapter-3 tables, [`DESIGNED_T310`] Table
//!   3.10 / Appendix D.
//! - Appendix E lists "designed" outer loops (airspeed by throttle 0.091 / 0.02, altitude 0.021,
//!   heading 1.2) and "classic" ones (0.15 / 0.04, 0.023 / 0.0010, 1.5) that differ from Tables
//!   3.7, 3.9 and 3.10: [`DESIGNED_APPE`] and [`MINNESOTA_APPE`].
//! - Table 3.5 prints the sideslip gains as kp = -3, ki = -0.8. In the UMN convention a positive
//!   rudder increases sideslip (`CY_dr > 0`, `Cn_dr < 0`, `Cn_beta > 0`: the steady sideslip per
//!   rudder is `-Cn_dr / Cn_beta > 0`), so a PI on `e = beta_c - beta` stabilises only with
//!   positive gains; with the printed signs it would feed sideslip back positively. The same
//!   design method (Appendix C, Beard and McLain) gives positive gains for the UMN data too. The
//!   magnitudes 3 and 0.8 are kept, the sign is the stabilising one; the parameter bounds refuse
//!   the other sign.
//! - The Minnesota baseline has no sideslip loop (only the yaw damper) and no airspeed-by-pitch
//!   loop: [`MINNESOTA`] sets the sideslip gains to zero (rudder = trim + yaw damper) and borrows
//!   the designed airspeed-by-pitch gain (Table 3.8), which the regime machine needs.
//!
//! Not in the thesis, chosen here and documented at their parameters: the trims (Table 2.3 trim
//! I of the linear models), the take-off pitch, the altitude band and its hysteresis, and the
//! bumpless-transfer fade time.

use super::{autopilot, lateral, longitudinal};
use crate::params::{ParamDef, ParamError};
use serde::{Deserialize, Serialize};

/// Radians per degree.
pub(crate) use crate::math::{DEG, RAD2DEG};

/// Gains and limits of the lateral-directional autopilot (ailerons and rudder).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LateralGains {
    /// Roll attitude, proportional: aileron rad per rad of roll error (negative, UMN).
    pub roll_kp: f32,
    /// Roll attitude, integral: aileron rad per rad s of roll error (negative, UMN).
    pub roll_ki: f32,
    /// Roll-rate damper: aileron rad per rad/s of roll rate, applied as `-kd p` (negative, UMN).
    pub roll_rate_kd: f32,
    /// Course hold, proportional: commanded roll rad per rad of course error.
    pub course_kp: f32,
    /// Course hold, integral: commanded roll rad per rad s of course error.
    pub course_ki: f32,
    /// Sideslip hold, proportional: rudder rad per rad of sideslip error (positive, UMN).
    pub slip_kp: f32,
    /// Sideslip hold, integral: rudder rad per rad s of sideslip error (positive, UMN).
    pub slip_ki: f32,
    /// Yaw damper: rudder rad per rad/s of washed-out yaw rate, `+k r` (positive: opposes r).
    pub yaw_damper_k: f32,
    /// Pole of the yaw-damper washout `s / (s + a)`, rad/s.
    pub washout_pole: f32,
    /// Largest commanded roll angle, rad.
    pub roll_max: f32,
    /// Aileron travel the loops may use, rad (at most the servo limit).
    pub aileron_max: f32,
    /// Rudder travel the loops may use, rad (at most the servo limit).
    pub rudder_max: f32,
    /// Aileron trim, the feed-forward of the roll loop, rad.
    pub trim_aileron: f32,
    /// Rudder trim, the feed-forward of the rudder loops, rad.
    pub trim_rudder: f32,
}

/// Gains and limits of the longitudinal autopilot (elevator and throttle) and its regimes.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LongitudinalGains {
    /// Pitch attitude, proportional: elevator rad per rad of pitch error (negative, UMN).
    pub pitch_kp: f32,
    /// Pitch attitude, integral: elevator rad per rad s (negative, UMN).
    pub pitch_ki: f32,
    /// Pitch-rate damper: elevator rad per rad/s of pitch rate, applied as `-kd q` (negative).
    pub pitch_rate_kd: f32,
    /// Altitude hold, proportional: commanded pitch rad per m of altitude error.
    pub alt_kp: f32,
    /// Altitude hold, integral: commanded pitch rad per m s.
    pub alt_ki: f32,
    /// Airspeed by pitch, proportional: commanded pitch rad per m/s of airspeed error (negative:
    /// too slow, nose down).
    pub aspd_pitch_kp: f32,
    /// Airspeed by pitch, integral: commanded pitch rad per m (negative).
    pub aspd_pitch_ki: f32,
    /// Airspeed by throttle, proportional: throttle per m/s of airspeed error.
    pub aspd_thr_kp: f32,
    /// Airspeed by throttle, integral: throttle per m of airspeed error (per m/s s).
    pub aspd_thr_ki: f32,
    /// Largest commanded pitch angle, rad.
    pub pitch_max: f32,
    /// Elevator travel the loops may use, rad (at most the servo limit).
    pub elevator_max: f32,
    /// Lowest throttle (descent regime), 0..1.
    pub throttle_min: f32,
    /// Highest throttle (take-off and climb regimes), 0..1.
    pub throttle_max: f32,
    /// Elevator trim, the feed-forward of the pitch loop, rad.
    pub trim_elevator: f32,
    /// Throttle trim, the feed-forward of the airspeed-by-throttle loop, 0..1.
    pub trim_throttle: f32,
    /// Pitch at trim, rad: the feed-forward of the altitude and airspeed-by-pitch loops, whose
    /// design (thesis chapter 3) is about the trim, so their output is a pitch *offset*.
    pub trim_pitch: f32,
    /// Pole of the low-pass on the altitude and airspeed feedback, rad/s.
    pub feedback_lpf_pole: f32,
    /// Pitch held in the take-off regime, rad.
    pub takeoff_pitch: f32,
    /// Altitude-hold band: the hold regime is entered when |altitude error| < band, m.
    pub alt_band: f32,
    /// Hysteresis of the band: the hold regime is left when |error| > band + hysteresis, m.
    pub alt_hysteresis: f32,
}

/// Every number the autopilot flies with.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct GainSet {
    /// Ailerons and rudder.
    pub lateral: LateralGains,
    /// Elevator and throttle.
    pub longitudinal: LongitudinalGains,
    /// Time constant with which a bumpless-transfer offset fades, s.
    pub transfer_tc: f32,
}

/// The thesis's designed gains, chapter-3 tables: roll Table 3.3, course Table 3.4, sideslip
/// Table 3.5 (sign corrected, see the module docs), pitch Table 3.6, altitude Table 3.7, airspeed
/// by pitch Table 3.8, airspeed by throttle Table 3.9; saturations section 3.3 / Appendix F
/// (roll 45 deg, pitch 20 deg, surfaces 25 deg); filters Appendices D and E.
pub const DESIGNED: GainSet = GainSet {
    lateral: LateralGains {
        roll_kp: -1.1216,
        roll_ki: -0.1,
        roll_rate_kd: -0.0618,
        course_kp: 4.0511,
        course_ki: 0.01,
        slip_kp: 3.0,
        slip_ki: 0.8,
        yaw_damper_k: 0.065,
        washout_pole: 2.0,
        roll_max: 45.0 * DEG,
        aileron_max: 25.0 * DEG,
        rudder_max: 25.0 * DEG,
        trim_aileron: 0.01,
        trim_rudder: 0.00317,
    },
    longitudinal: LongitudinalGains {
        pitch_kp: -0.97,
        pitch_ki: -0.1,
        pitch_rate_kd: -0.072,
        alt_kp: 0.06,
        alt_ki: 0.0,
        aspd_pitch_kp: -0.866,
        aspd_pitch_ki: 0.0,
        aspd_thr_kp: 1.0,
        aspd_thr_ki: 24.0,
        pitch_max: 20.0 * DEG,
        elevator_max: 25.0 * DEG,
        throttle_min: 0.0,
        throttle_max: 1.0,
        trim_elevator: -0.0963,
        trim_throttle: 0.569,
        trim_pitch: 0.054,
        feedback_lpf_pole: 2.0,
        takeoff_pitch: 10.0 * DEG,
        alt_band: 10.0,
        alt_hysteresis: 2.0,
    },
    transfer_tc: 1.0,
};

/// [`DESIGNED`] with the inner-loop reading of Table 3.10 and Appendix D ("My parameters":
/// `kp_RT = -1.1216, ki_RT = -.01, kp_RD = -0.072`) and Table 3.10's course `ki` 0.008.
pub const DESIGNED_T310: GainSet = {
    let mut g = DESIGNED;
    g.lateral.roll_ki = -0.01;
    g.lateral.roll_rate_kd = -0.072;
    g.lateral.course_ki = 0.008;
    g
};

/// Appendix E's "designed" outer loops (`kp_VT = 0.091, ki_VT = 0.02, kp_AT = 0.021, ki_AT = 0,
/// kp_HT = 1.2`, heading P only) on the Table 3.10 / Appendix D inner loops.
pub const DESIGNED_APPE: GainSet = {
    let mut g = DESIGNED_T310;
    g.lateral.course_kp = 1.2;
    g.lateral.course_ki = 0.0;
    g.longitudinal.alt_kp = 0.021;
    g.longitudinal.alt_ki = 0.0;
    g.longitudinal.aspd_thr_kp = 0.091;
    g.longitudinal.aspd_thr_ki = 0.02;
    g
};

/// The University of Minnesota baseline ("classic") as Table 3.10 gives it: roll -0.52 / -0.2 /
/// damper -0.07, pitch -0.84 / -0.23 / damper -0.08, heading P 1.2, altitude 0.021 / 0.0017.
/// Airspeed by throttle 0.15 / 0.04 from Appendix E (the only source). No sideslip loop (yaw
/// damper only); airspeed by pitch borrowed from Table 3.8.
pub const MINNESOTA: GainSet = {
    let mut g = DESIGNED;
    g.lateral.roll_kp = -0.52;
    g.lateral.roll_ki = -0.2;
    g.lateral.roll_rate_kd = -0.07;
    g.lateral.course_kp = 1.2;
    g.lateral.course_ki = 0.0;
    g.lateral.slip_kp = 0.0;
    g.lateral.slip_ki = 0.0;
    g.longitudinal.pitch_kp = -0.84;
    g.longitudinal.pitch_ki = -0.23;
    g.longitudinal.pitch_rate_kd = -0.08;
    g.longitudinal.alt_kp = 0.021;
    g.longitudinal.alt_ki = 0.0017;
    g.longitudinal.aspd_thr_kp = 0.15;
    g.longitudinal.aspd_thr_ki = 0.04;
    g
};

/// [`MINNESOTA`] with Appendix E's "classic" outer loops: heading 1.5, altitude 0.023 / 0.0010.
pub const MINNESOTA_APPE: GainSet = {
    let mut g = MINNESOTA;
    g.lateral.course_kp = 1.5;
    g.longitudinal.alt_kp = 0.023;
    g.longitudinal.alt_ki = 0.0010;
    g
};

/// The named sets: name, set, one-line source.
pub const NAMED: &[(&str, GainSet, &str)] = &[
    ("designed", DESIGNED, "thesis Tables 3.3-3.9"),
    (
        "designed_t310",
        DESIGNED_T310,
        "thesis Table 3.10 / Appendix D inner loops",
    ),
    (
        "designed_appe",
        DESIGNED_APPE,
        "thesis Appendix E designed outer loops",
    ),
    ("minnesota", MINNESOTA, "UMN baseline per thesis Table 3.10"),
    (
        "minnesota_appe",
        MINNESOTA_APPE,
        "UMN baseline per thesis Appendix E",
    ),
];

/// Names of the sets in [`NAMED`].
pub const NAMES: &[&str] = &[
    "designed",
    "designed_t310",
    "designed_appe",
    "minnesota",
    "minnesota_appe",
];

/// A set name that is not one of [`NAMES`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct UnknownSet {
    /// The valid names.
    pub valid: &'static [&'static str],
}

impl core::fmt::Display for UnknownSet {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str("unknown gain set; valid names:")?;
        for n in self.valid {
            write!(f, " {n}")?;
        }
        Ok(())
    }
}

/// Why a gain set or a parameter value was refused; each names the parameter.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum GainError {
    /// No value given for this parameter.
    Missing(&'static str),
    /// NaN or infinite.
    NotFinite(&'static str),
    /// Outside the parameter's bounds (which also fix each loop gain's stabilising sign).
    OutOfBounds(&'static str),
    /// Contradicts another value (a lower limit above an upper one, a trim outside its travel).
    Inconsistent(&'static str),
    /// No parameter of that name.
    Unknown,
}

impl GainError {
    /// The parameter the error is about (empty for [`GainError::Unknown`]).
    pub fn name(&self) -> &'static str {
        match *self {
            GainError::Missing(n)
            | GainError::NotFinite(n)
            | GainError::OutOfBounds(n)
            | GainError::Inconsistent(n) => n,
            GainError::Unknown => "",
        }
    }
}

impl core::fmt::Display for GainError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            GainError::Missing(n) => write!(f, "gain {n} missing"),
            GainError::NotFinite(n) => write!(f, "gain {n} is not finite"),
            GainError::OutOfBounds(n) => write!(f, "gain {n} outside its bounds"),
            GainError::Inconsistent(n) => write!(f, "gain {n} contradicts another limit"),
            GainError::Unknown => f.write_str("no such gain parameter"),
        }
    }
}

/// One field of [`GainSet`] bound to the parameter that carries it. The parameter value is
/// `field * scale` (scale converts radians to the degrees some parameters are shown in).
#[derive(Clone, Copy)]
pub struct Binding {
    /// Parameter name (as in the stage's `PARAMS`).
    pub name: &'static str,
    /// Reads the field, SI / radians.
    pub get: fn(&GainSet) -> f32,
    /// Writes the field, SI / radians.
    pub set: fn(&mut GainSet, f32),
    /// Parameter value per field value.
    pub scale: f32,
}

macro_rules! bind {
    ($name:literal, $($f:ident).+, $scale:expr) => {
        Binding {
            name: $name,
            get: |g: &GainSet| g.$($f).+,
            set: |g: &mut GainSet, v: f32| g.$($f).+ = v,
            scale: $scale,
        }
    };
}

/// Every field of [`GainSet`] and its parameter; one entry per parameter of [`all_params`].
pub const BINDINGS: &[Binding] = &[
    bind!("RLL_KP", lateral.roll_kp, 1.0),
    bind!("RLL_KI", lateral.roll_ki, 1.0),
    bind!("RLL_RATE_KD", lateral.roll_rate_kd, 1.0),
    bind!("CRS_KP", lateral.course_kp, 1.0),
    bind!("CRS_KI", lateral.course_ki, 1.0),
    bind!("SLIP_KP", lateral.slip_kp, 1.0),
    bind!("SLIP_KI", lateral.slip_ki, 1.0),
    bind!("YAW_DAMP_K", lateral.yaw_damper_k, 1.0),
    bind!("YAW_WO_POLE", lateral.washout_pole, 1.0),
    bind!("LIM_ROLL_DEG", lateral.roll_max, RAD2DEG),
    bind!("LIM_AIL_DEG", lateral.aileron_max, RAD2DEG),
    bind!("LIM_RUD_DEG", lateral.rudder_max, RAD2DEG),
    bind!("TRIM_AIL_DEG", lateral.trim_aileron, RAD2DEG),
    bind!("TRIM_RUD_DEG", lateral.trim_rudder, RAD2DEG),
    bind!("PTCH_KP", longitudinal.pitch_kp, 1.0),
    bind!("PTCH_KI", longitudinal.pitch_ki, 1.0),
    bind!("PTCH_RATE_KD", longitudinal.pitch_rate_kd, 1.0),
    bind!("ALT_KP", longitudinal.alt_kp, 1.0),
    bind!("ALT_KI", longitudinal.alt_ki, 1.0),
    bind!("ASPD_PTCH_KP", longitudinal.aspd_pitch_kp, 1.0),
    bind!("ASPD_PTCH_KI", longitudinal.aspd_pitch_ki, 1.0),
    bind!("ASPD_THR_KP", longitudinal.aspd_thr_kp, 1.0),
    bind!("ASPD_THR_KI", longitudinal.aspd_thr_ki, 1.0),
    bind!("LIM_PTCH_DEG", longitudinal.pitch_max, RAD2DEG),
    bind!("LIM_ELEV_DEG", longitudinal.elevator_max, RAD2DEG),
    bind!("THR_MIN", longitudinal.throttle_min, 1.0),
    bind!("THR_MAX", longitudinal.throttle_max, 1.0),
    bind!("TRIM_ELEV_DEG", longitudinal.trim_elevator, RAD2DEG),
    bind!("TRIM_THR", longitudinal.trim_throttle, 1.0),
    bind!("TRIM_PTCH_DEG", longitudinal.trim_pitch, RAD2DEG),
    bind!("FB_LPF_POLE", longitudinal.feedback_lpf_pole, 1.0),
    bind!("TKO_PTCH_DEG", longitudinal.takeoff_pitch, RAD2DEG),
    bind!("ALT_BAND_M", longitudinal.alt_band, 1.0),
    bind!("ALT_HYST_M", longitudinal.alt_hysteresis, 1.0),
    bind!("XFER_TC_S", transfer_tc, 1.0),
];

/// The parameter lists of the control stages, in the order of [`BINDINGS`].
pub const STAGE_PARAMS: &[&[ParamDef]] =
    &[lateral::PARAMS, longitudinal::PARAMS, autopilot::PARAMS];

/// Finds the definition of a control parameter by name.
pub fn param_def(name: &str) -> Option<&'static ParamDef> {
    STAGE_PARAMS
        .iter()
        .flat_map(|list| list.iter())
        .find(|d| d.name == name)
}

/// Every control parameter definition, stage by stage.
pub fn all_params() -> impl Iterator<Item = &'static ParamDef> {
    STAGE_PARAMS.iter().flat_map(|list| list.iter())
}

fn binding(name: &str) -> Option<&'static Binding> {
    BINDINGS.iter().find(|b| b.name == name)
}

/// A field value in parameter units.
fn to_param(b: &Binding, field: f32) -> f32 {
    field * b.scale
}

/// Checks a parameter value against its definition. A value converted from radians may land a
/// rounding step outside a bound it was set to (25 deg -> rad -> deg); within 1e-5 relative of a
/// bound it counts as on it.
fn check(b: &Binding, def: &ParamDef, v: f32) -> Result<f32, ParamError> {
    let near = |bound: f32| libm::fabsf(v - bound) <= 1e-5 * libm::fabsf(bound).max(1.0);
    let v = if b.scale != 1.0 && v.is_finite() && near(def.max) {
        v.min(def.max)
    } else if b.scale != 1.0 && v.is_finite() && near(def.min) {
        v.max(def.min)
    } else {
        v
    };
    def.check(v)
}

impl GainSet {
    /// The named set, or the list of valid names.
    pub fn named(name: &str) -> Result<GainSet, UnknownSet> {
        NAMED
            .iter()
            .find(|(n, _, _)| *n == name)
            .map(|(_, g, _)| *g)
            .ok_or(UnknownSet { valid: NAMES })
    }

    /// Checks every value: finite, inside its parameter's bounds (the bounds of the loop gains
    /// admit only the stabilising sign in the UMN convention), and consistent (throttle minimum
    /// below maximum, trims inside the travel). The error names the first offending parameter.
    pub fn validate(&self) -> Result<(), GainError> {
        for b in BINDINGS {
            let v = to_param(b, (b.get)(self));
            let def = param_def(b.name).ok_or(GainError::Unknown)?;
            match check(b, def, v) {
                Ok(_) => {}
                Err(ParamError::NotFinite) => return Err(GainError::NotFinite(b.name)),
                Err(_) => return Err(GainError::OutOfBounds(b.name)),
            }
        }
        let lat = &self.lateral;
        let lon = &self.longitudinal;
        if lon.throttle_min >= lon.throttle_max {
            return Err(GainError::Inconsistent("THR_MIN"));
        }
        if !(lon.throttle_min..=lon.throttle_max).contains(&lon.trim_throttle) {
            return Err(GainError::Inconsistent("TRIM_THR"));
        }
        if libm::fabsf(lat.trim_aileron) > lat.aileron_max {
            return Err(GainError::Inconsistent("TRIM_AIL_DEG"));
        }
        if libm::fabsf(lat.trim_rudder) > lat.rudder_max {
            return Err(GainError::Inconsistent("TRIM_RUD_DEG"));
        }
        if libm::fabsf(lon.trim_elevator) > lon.elevator_max {
            return Err(GainError::Inconsistent("TRIM_ELEV_DEG"));
        }
        if lon.takeoff_pitch > lon.pitch_max {
            return Err(GainError::Inconsistent("TKO_PTCH_DEG"));
        }
        Ok(())
    }

    /// The set as parameter values `(name, value)` in parameter units, in [`BINDINGS`] order.
    pub fn params(&self) -> impl Iterator<Item = (&'static str, f32)> + '_ {
        BINDINGS
            .iter()
            .map(move |b| (b.name, to_param(b, (b.get)(self))))
    }

    /// The value of one parameter, in parameter units.
    pub fn param(&self, name: &str) -> Option<f32> {
        binding(name).map(|b| to_param(b, (b.get)(self)))
    }

    /// Sets one parameter (parameter units) after checking it against its definition. The rest
    /// of the set is not re-validated: call [`GainSet::validate`] before flying the result.
    pub fn set_param(&mut self, name: &str, value: f32) -> Result<(), GainError> {
        let b = binding(name).ok_or(GainError::Unknown)?;
        let def = param_def(b.name).ok_or(GainError::Unknown)?;
        match check(b, def, value) {
            Ok(v) => {
                (b.set)(self, v / b.scale);
                Ok(())
            }
            Err(ParamError::NotFinite) => Err(GainError::NotFinite(b.name)),
            Err(_) => Err(GainError::OutOfBounds(b.name)),
        }
    }

    /// Builds a set from parameter values looked up by name (parameter units), e.g. from the
    /// parameter store. Every parameter must be present and valid, and the result must pass
    /// [`GainSet::validate`].
    pub fn from_params(mut lookup: impl FnMut(&str) -> Option<f32>) -> Result<GainSet, GainError> {
        let mut g = DESIGNED;
        for b in BINDINGS {
            let v = lookup(b.name).ok_or(GainError::Missing(b.name))?;
            g.set_param(b.name, v)?;
        }
        g.validate()?;
        Ok(g)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::validate_defs;

    #[test]
    fn named_lookup_and_unknown_lists_names() {
        assert_eq!(GainSet::named("designed"), Ok(DESIGNED));
        assert_eq!(GainSet::named("minnesota"), Ok(MINNESOTA));
        let err = GainSet::named("classic").unwrap_err();
        assert_eq!(err.valid, NAMES);
        extern crate std;
        use std::string::ToString;
        let text = err.to_string();
        for n in NAMES {
            assert!(text.contains(n), "{text}");
        }
        assert_eq!(NAMED.len(), NAMES.len());
        for ((n, _, _), m) in NAMED.iter().zip(NAMES) {
            assert_eq!(n, m);
        }
    }

    #[test]
    fn every_named_set_is_valid_and_carries_its_sources_numbers() {
        for (name, g, _) in NAMED {
            assert_eq!(g.validate(), Ok(()), "{name}");
        }
        // Spot checks against the thesis (REFERENCE.md's gain table).
        assert_eq!(DESIGNED.lateral.roll_kp, -1.1216);
        assert_eq!(DESIGNED.lateral.roll_ki, -0.1);
        assert_eq!(DESIGNED.lateral.roll_rate_kd, -0.0618);
        assert_eq!(DESIGNED_T310.lateral.roll_ki, -0.01);
        assert_eq!(DESIGNED_T310.lateral.roll_rate_kd, -0.072);
        assert_eq!(DESIGNED_T310.lateral.course_ki, 0.008);
        assert_eq!(DESIGNED_APPE.longitudinal.alt_kp, 0.021);
        assert_eq!(DESIGNED_APPE.longitudinal.aspd_thr_kp, 0.091);
        assert_eq!(DESIGNED_APPE.longitudinal.aspd_thr_ki, 0.02);
        assert_eq!(MINNESOTA.longitudinal.pitch_rate_kd, -0.08);
        assert_eq!(MINNESOTA_APPE.lateral.course_kp, 1.5);
        assert_eq!(MINNESOTA_APPE.longitudinal.alt_ki, 0.0010);
        assert!((DESIGNED.lateral.roll_max - 45.0 * DEG).abs() < 1e-7);
        assert!((DESIGNED.longitudinal.pitch_max - 20.0 * DEG).abs() < 1e-7);
    }

    #[test]
    fn validate_names_the_bad_gain() {
        let mut g = DESIGNED;
        g.longitudinal.alt_kp = f32::NAN;
        assert_eq!(g.validate(), Err(GainError::NotFinite("ALT_KP")));
        let mut g = DESIGNED;
        g.lateral.roll_rate_kd = f32::INFINITY;
        assert_eq!(g.validate(), Err(GainError::NotFinite("RLL_RATE_KD")));
        // The thesis's printed sideslip sign would be destabilising: refused.
        let mut g = DESIGNED;
        g.lateral.slip_kp = -3.0;
        assert_eq!(g.validate(), Err(GainError::OutOfBounds("SLIP_KP")));
        let mut g = DESIGNED;
        g.lateral.roll_kp = 1.1216;
        assert_eq!(g.validate(), Err(GainError::OutOfBounds("RLL_KP")));
        let mut g = DESIGNED;
        g.longitudinal.throttle_min = 0.9;
        g.longitudinal.throttle_max = 0.5;
        assert_eq!(g.validate(), Err(GainError::Inconsistent("THR_MIN")));
    }

    #[test]
    fn param_lists_are_well_formed_unique_and_match_the_bindings() {
        for list in STAGE_PARAMS {
            assert_eq!(validate_defs(list), Ok(()));
        }
        let all: heapless::Vec<ParamDef, 64> = all_params().copied().collect();
        assert_eq!(validate_defs(&all), Ok(()), "duplicate across stages");
        assert_eq!(all.len(), BINDINGS.len());
        for b in BINDINGS {
            let def = param_def(b.name).unwrap();
            // Defaults are the designed set.
            let designed = DESIGNED.param(b.name).unwrap();
            assert!(
                (def.default - designed).abs() <= 1e-6 * designed.abs().max(1.0),
                "{}: default {} designed {}",
                b.name,
                def.default,
                designed
            );
        }
        // Same parameters, same order: the stage lists and the bindings describe one table.
        for (def, b) in all.iter().zip(BINDINGS) {
            assert_eq!(def.name, b.name);
        }
    }

    #[test]
    fn params_round_trip_and_missing_is_named() {
        for (_, g, _) in NAMED {
            let values: heapless::Vec<(&str, f32), 64> = g.params().collect();
            let back =
                GainSet::from_params(|n| values.iter().find(|(m, _)| *m == n).map(|(_, v)| *v))
                    .unwrap();
            for b in BINDINGS {
                let (x, y) = ((b.get)(g), (b.get)(&back));
                assert!(
                    (x - y).abs() <= 1e-6 * x.abs().max(1e-3),
                    "{} {x} {y}",
                    b.name
                );
            }
        }
        let err = GainSet::from_params(|n| {
            if n == "PTCH_KI" {
                None
            } else {
                DESIGNED.param(n)
            }
        });
        assert_eq!(err, Err(GainError::Missing("PTCH_KI")));
        let err = GainSet::from_params(|n| {
            if n == "CRS_KP" {
                Some(f32::NAN)
            } else {
                DESIGNED.param(n)
            }
        });
        assert_eq!(err, Err(GainError::NotFinite("CRS_KP")));
        let mut g = DESIGNED;
        assert_eq!(g.set_param("LIM_ROLL_DEG", 30.0), Ok(()));
        assert!((g.lateral.roll_max - 30.0 * DEG).abs() < 1e-6);
        assert_eq!(
            g.set_param("LIM_ROLL_DEG", 95.0),
            Err(GainError::OutOfBounds("LIM_ROLL_DEG"))
        );
        assert_eq!(g.set_param("NOPE", 1.0), Err(GainError::Unknown));
    }

    #[test]
    fn serde_round_trip_with_postcard() {
        let mut buf = [0u8; 512];
        for (_, g, _) in NAMED {
            let bytes = postcard::to_slice(g, &mut buf).unwrap();
            let back: GainSet = postcard::from_bytes(bytes).unwrap();
            assert_eq!(&back, g);
        }
        // A truncated record (a missing gain) is refused, not zero-filled.
        let bytes = postcard::to_slice(&DESIGNED, &mut buf).unwrap();
        let n = bytes.len();
        assert!(postcard::from_bytes::<GainSet>(&buf[..n - 4]).is_err());
    }
}
