//! The named gain sets of the thesis, composed from each control stage's gains (each stage
//! declares its own gains and their parameters: [`super::lateral::PARAMS`],
//! [`super::longitudinal::PARAMS`], [`super::autopilot::PARAMS`]; [`GainSet`] holds one of each).
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

pub use super::autopilot::{GainError, GainSet};
pub use super::lateral::LateralGains;
pub use super::longitudinal::LongitudinalGains;

/// The thesis's designed gains, chapter-3 tables: roll Table 3.3, course Table 3.4, sideslip
/// Table 3.5 (sign corrected, see the module docs), pitch Table 3.6, altitude Table 3.7, airspeed
/// by pitch Table 3.8, airspeed by throttle Table 3.9; saturations section 3.3 / Appendix F
/// (roll 45 deg, pitch 20 deg, surfaces 25 deg); filters Appendices D and E.
pub const DESIGNED: GainSet = GainSet::THESIS;

/// The flight defaults (every parameter's default): [`DESIGNED`] with the sideslip and both
/// airspeed loops replaced, which the full linear model shows unstable as the thesis gives
/// them ([`super::lateral::FLIGHT`], [`super::longitudinal::FLIGHT`]).
pub const FLIGHT: GainSet = GainSet::FLIGHT;

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
    (
        "flight",
        FLIGHT,
        "the flight defaults: designed, airspeed and sideslip loops replaced",
    ),
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

/// The sets of [`NAMED`], in its order, as the vehicle loads them by `SYS_GAIN_SET`'s index:
/// without the sources, which only the host's tools print (in the MCU image they were some
/// 300 bytes).
pub const SETS: [GainSet; 6] = [
    FLIGHT,
    DESIGNED,
    DESIGNED_T310,
    DESIGNED_APPE,
    MINNESOTA,
    MINNESOTA_APPE,
];

/// Names of the sets in [`NAMED`].
pub const NAMES: &[&str] = &[
    "flight",
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

impl core::error::Error for UnknownSet {}

impl GainSet {
    /// The named set, or the list of valid names.
    pub fn named(name: &str) -> Result<GainSet, UnknownSet> {
        NAMED
            .iter()
            .find(|(n, _, _)| *n == name)
            .map(|(_, g, _)| *g)
            .ok_or(UnknownSet { valid: NAMES })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::DEG;

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
        assert_eq!(NAMED.len(), SETS.len());
        for (((n, g, _), m), set) in NAMED.iter().zip(NAMES).zip(&SETS) {
            assert_eq!(n, m);
            assert_eq!(g, set, "{n}");
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
    fn the_stages_parameters_default_to_the_flight_set() {
        use crate::control::{autopilot, lateral, longitudinal};
        use crate::params::{ParamStore, Registry};
        const CONTROL: Registry = &[
            &lateral::PARAMS,
            &longitudinal::PARAMS,
            &longitudinal::tecs::gains::PARAMS,
            &autopilot::PARAMS,
        ];
        assert_eq!(ParamStore::validate(CONTROL), Ok(()));
        let store = ParamStore::new(CONTROL);
        let loaded = GainSet::from_store(&store);
        for ((n, x), (m, y)) in FLIGHT.params().zip(loaded.params()) {
            assert_eq!(n, m);
            assert!((x - y).abs() <= 1e-6 * x.abs().max(1.0), "{n}: {x} {y}");
        }
        assert_eq!(FLIGHT.params().count(), store.len());
        // The flight set is the designed one but for the loops it replaces and the scaling.
        let differ = FLIGHT
            .params()
            .zip(DESIGNED.params())
            .filter(|((_, x), (_, y))| x != y)
            .map(|((n, _), _)| n);
        assert!(differ.eq([
            "SLIP_KP",
            "SLIP_KI",
            "ASPD_PTCH_KP",
            "ASPD_PTCH_KI",
            "ASPD_THR_KP",
            "ASPD_THR_KI",
            "ASPD_SCL_REF"
        ]));
    }

    #[test]
    fn params_round_trip_and_bad_values_are_named() {
        for (_, g, _) in NAMED {
            let mut back = MINNESOTA;
            for (n, v) in g.params() {
                back.set_param(n, v).unwrap();
            }
            for ((n, x), (_, y)) in g.params().zip(back.params()) {
                assert!((x - y).abs() <= 1e-6 * x.abs().max(1e-3), "{n} {x} {y}");
            }
        }
        let mut g = DESIGNED;
        assert_eq!(
            g.set_param("CRS_KP", f32::NAN),
            Err(GainError::NotFinite("CRS_KP"))
        );
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
