//! The total energy control's gains, their design and their parameters.
//!
//! # Design rule (from the linear model at the level trim, `sim-host design`)
//! The energy picture: per unit weight the aircraft's energy rate is `V (g h_dot / V + V_dot)`,
//! so the specific energy rates are measured here as flight-path angles, rad:
//! total `E = h_dot / V + V_dot / g`, balance `B = h_dot / V - V_dot / g`. On the linear model
//! throttle moves the total (`V_dot = a_V2 delta_t`: `dE / d delta_t = a_V2 / g`, 0.545 rad
//! per unit throttle with `a_V2` = 5.34 m/s^2) and pitch trades one kind for the other (a
//! pitch step at constant thrust gives `d gamma = d theta` and `V_dot / g = -d gamma`:
//! `dB / d theta = 2`).
//! - Feed-forwards invert those gains: throttle `trim + E_d g / a_V2`, pitch `trim + B_d`
//!   (the flight-path angle the balance asks for). With a perfect model the feedback does
//!   nothing; the two PI loops only remove the model's error.
//! - The inner loops are each the PI times a static gain and the engine lag (5.9 rad/s) or the
//!   pitch loop (5 rad/s crossover), so their crossover is set by the integrator:
//!   `w_E = ki_E a_V2 / g = 1.5 rad/s` (`TECS_THR_KI` 2.75), `w_B = 2 ki_B = 1 rad/s`
//!   (`TECS_PTCH_KI` 0.5), proportional parts below the static loop gain so they damp without
//!   lifting the crossover: `2 kp_B = 0.5` (`TECS_PTCH_KP` 0.25), `kp_E a_V2 / g = 0.16`
//!   (`TECS_THR_KP` 0.3). The throttle's is the smaller because it passes the acceleration
//!   estimate's gust noise straight to the motor: at 0.5 of the static gain (0.92) the
//!   default mission in light turbulence (`sim-host laws`) moved the throttle 0.32 per
//!   second and floated 88 to 121 m past the landing point on seeds 1 and 2.
//! - The outer loops, height error to climb-rate demand and speed error to acceleration
//!   demand, are first order at `TECS_H_K` = 0.4 1/s and `TECS_V_K` = 0.5 1/s (the speed one
//!   as fast as the successive loop closure's airspeed loops, `wn` 0.5 rad/s): three to four
//!   times slower than the inner loops. The height reference approaches a new demand at the
//!   same `TECS_H_K` (the demand's rate fed forward when it is a ramp the aircraft can fly),
//!   so a step within the limits is the first-order lag of 2.5 s: 10-90 % rise
//!   `ln 9 / 0.4` = 5.5 s, no overshoot (flown: 5.46 s and 0.003 % on the 2 m step,
//!   `docs/RESULTS.md`). The climb and speed rates come from
//!   [`crate::control::filters::RateEstimator`] at 5 rad/s, three times the faster inner
//!   crossover, where its lag is `2 atan(1.5 / 5)` = 33 deg (53 deg at 3 rad/s).
//! - Balance weight 0.5 (height 1, airspeed 0.5): a gust moves the airspeed far more than the
//!   height, and with equal weights the pitch chased it (altitude RMS 1.37 m against 0.83 m
//!   with 0.5 on the windy default mission, seed 1).
//! - Climb and sink limits: three quarters of the steady climb at full throttle and sink at
//!   idle, `(thr_max - trim) a_V2 V / g` = 4.0 m/s and `(trim - thr_min) a_V2 V / g`
//!   = 5.3 m/s: 3.0 and 4.0 m/s, so the feedback keeps a quarter of the throttle travel.
//!
//! `sim-host design` shows the margins of the two loops on the full sampled model.

use crate::param;
use crate::params::{Group, ParamDef};
use serde::{Deserialize, Serialize};

/// Gains and limits of the total energy control.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct TecsGains {
    /// The altitude modes fly the total energy control instead of the regimes.
    pub enabled: bool,
    /// Height error to climb-rate demand, 1/s.
    pub height_k: f32,
    /// Airspeed error to acceleration demand, 1/s.
    pub speed_k: f32,
    /// Largest climb-rate demand, m/s.
    pub climb_max: f32,
    /// Largest sink-rate demand, m/s (positive).
    pub sink_max: f32,
    /// Largest acceleration demand and airspeed-demand slew, m/s^2.
    pub accel_max: f32,
    /// Steady acceleration per unit throttle, `a_V2`, m/s^2: the throttle feed-forward.
    pub thr_accel: f32,
    /// Throttle per rad of total energy-rate error.
    pub thr_kp: f32,
    /// Throttle per rad s of integrated total energy-rate error.
    pub thr_ki: f32,
    /// Commanded pitch per rad of energy-balance-rate error.
    pub pitch_kp: f32,
    /// Commanded pitch per rad s of integrated energy-balance-rate error, 1/s.
    pub pitch_ki: f32,
    /// Weight of airspeed against height in the balance, 0 (height only) to 2 (speed only).
    pub speed_weight: f32,
    /// Airspeed below which speed takes priority over height, m/s.
    pub underspeed: f32,
    /// Poles of the climb-rate and acceleration estimators, rad/s.
    pub rate_pole: f32,
}

/// Width of the airspeed band over which the underspeed priority fades in, m/s: full priority
/// this far below [`TecsGains::underspeed`].
pub const UNDERSPEED_BAND_MPS: f32 = 2.0;

/// The designed set (module docs), off: the successive loop closure stays the default.
pub const DESIGNED: TecsGains = TecsGains {
    enabled: false,
    height_k: 0.4,
    speed_k: 0.5,
    climb_max: 3.0,
    sink_max: 4.0,
    accel_max: 1.0,
    thr_accel: 5.34,
    thr_kp: 0.3,
    thr_ki: 2.75,
    pitch_kp: 0.25,
    pitch_ki: 0.5,
    speed_weight: 0.5,
    underspeed: 12.0,
    rate_pole: 5.0,
};

/// [`DESIGNED`] engaged.
pub const ENGAGED: TecsGains = TecsGains {
    enabled: true,
    ..DESIGNED
};

impl Default for TecsGains {
    fn default() -> Self {
        DESIGNED
    }
}

const G: TecsGains = DESIGNED;

/// Parameters of the total energy control; defaults are [`DESIGNED`].
pub const PARAMS: Group<TecsGains> = Group {
    name: "Total energy control",
    params: &[
        param!(
            ParamDef::choice(
                "LON_LAW",
                0,
                &["Successive loop closure", "Total energy control"],
                "Law of the altitude modes (take-off regime and pitch modes unchanged)",
            ),
            TecsGains => enabled, flag
        ),
        param!(
            ParamDef::real(
                "TECS_H_K",
                G.height_k,
                0.05,
                2.0,
                "1/s",
                "Height error to climb-rate demand",
            ),
            TecsGains => height_k
        ),
        param!(
            ParamDef::real(
                "TECS_V_K",
                G.speed_k,
                0.05,
                2.0,
                "1/s",
                "Airspeed error to acceleration demand",
            ),
            TecsGains => speed_k
        ),
        param!(
            ParamDef::real(
                "TECS_CLMB_MAX",
                G.climb_max,
                0.5,
                10.0,
                "m/s",
                "Largest climb-rate demand (below the climb at full throttle)",
            ),
            TecsGains => climb_max
        ),
        param!(
            ParamDef::real(
                "TECS_SINK_MAX",
                G.sink_max,
                0.5,
                10.0,
                "m/s",
                "Largest sink-rate demand (below the sink at idle)",
            ),
            TecsGains => sink_max
        ),
        param!(
            ParamDef::real(
                "TECS_ACC_MAX",
                G.accel_max,
                0.1,
                5.0,
                "m/s^2",
                "Largest acceleration demand and airspeed-demand slew",
            ),
            TecsGains => accel_max
        ),
        param!(
            ParamDef::real(
                "TECS_THR_ACC",
                G.thr_accel,
                0.5,
                50.0,
                "m/s^2",
                "Steady acceleration per unit throttle (a_V2), the throttle feed-forward",
            ),
            TecsGains => thr_accel
        ),
        param!(
            ParamDef::real(
                "TECS_THR_KP",
                G.thr_kp,
                0.0,
                10.0,
                "1/rad",
                "Throttle per total energy-rate error (flight-path angle)",
            ),
            TecsGains => thr_kp
        ),
        param!(
            ParamDef::real(
                "TECS_THR_KI",
                G.thr_ki,
                0.0,
                20.0,
                "1/(rad s)",
                "Throttle per integrated total energy-rate error",
            ),
            TecsGains => thr_ki
        ),
        param!(
            ParamDef::real(
                "TECS_PTCH_KP",
                G.pitch_kp,
                0.0,
                5.0,
                "rad/rad",
                "Commanded pitch per energy-balance-rate error",
            ),
            TecsGains => pitch_kp
        ),
        param!(
            ParamDef::real(
                "TECS_PTCH_KI",
                G.pitch_ki,
                0.0,
                10.0,
                "1/s",
                "Commanded pitch per integrated energy-balance-rate error",
            ),
            TecsGains => pitch_ki
        ),
        param!(
            ParamDef::real(
                "TECS_SPD_W",
                G.speed_weight,
                0.0,
                2.0,
                "",
                "Balance weight: 0 height only, 1 both, 2 airspeed only",
            ),
            TecsGains => speed_weight
        ),
        param!(
            ParamDef::real(
                "TECS_SPD_UNDR",
                G.underspeed,
                3.0,
                30.0,
                "m/s",
                "Below this airspeed, speed takes priority over height (full 2 m/s lower)",
            ),
            TecsGains => underspeed
        ),
        param!(
            ParamDef::real(
                "TECS_RATE_POLE",
                G.rate_pole,
                0.5,
                20.0,
                "rad/s",
                "Poles of the climb-rate and acceleration estimators",
            ),
            TecsGains => rate_pole
        ),
    ],
    base: || DESIGNED,
    check: crate::params::independent,
};
