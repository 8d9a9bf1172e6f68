//! The longitudinal autopilot's gains, their thesis values and their parameters.

use crate::math::{DEG, RAD2DEG};
use crate::param;
use crate::params::{Group, ParamDef};
use serde::{Deserialize, Serialize};

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

/// The thesis's designed longitudinal gains, chapter-3 tables: pitch Table 3.6, altitude Table
/// 3.7, airspeed by pitch Table 3.8, airspeed by throttle Table 3.9; pitch limit 20 deg and
/// elevator travel 25 deg (section 3.3, Appendix F); low-pass Appendix E; trims Table 2.3 trim
/// I. Take-off pitch, band and hysteresis are not in the thesis: chosen here.
pub const THESIS: LongitudinalGains = LongitudinalGains {
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
};

/// The flight defaults: [`THESIS`] with the two airspeed loops replaced, because on the full
/// linear model (sampled at 50 Hz, servo, two-sample delay, every other loop closed:
/// `sim-host design`, docs/GAIN-DESIGN.md) the thesis's are unstable: airspeed by throttle
/// 1.0 / 24 by -114 deg of phase margin (in flight the throttle beats between its stops),
/// airspeed by pitch -0.866 / 0 by -23 deg (the climb's pitch beats between its limits).
/// - Airspeed by throttle: 0.15 / 0.04, the University of Minnesota's own (thesis Appendix E,
///   "classic"): 67 deg of phase margin, a 1 m/s step rises in 1.6 s and overshoots 6 %.
/// - Airspeed by pitch: -0.1 / -0.02, chosen on the same model: 67 deg, rise 1.3 s, 3 %.
///
/// With them the altitude loop keeps 56 deg (44.5 deg beside the thesis's throttle loop).
pub const FLIGHT: LongitudinalGains = LongitudinalGains {
    aspd_pitch_kp: -0.1,
    aspd_pitch_ki: -0.02,
    aspd_thr_kp: 0.15,
    aspd_thr_ki: 0.04,
    ..THESIS
};

const G: LongitudinalGains = FLIGHT;

/// Limits in order and trims inside them: otherwise a regime could not reach its trim.
fn consistent(g: &LongitudinalGains) -> Result<(), &'static str> {
    if g.throttle_min >= g.throttle_max {
        return Err("THR_MIN");
    }
    if !(g.throttle_min..=g.throttle_max).contains(&g.trim_throttle) {
        return Err("TRIM_THR");
    }
    if libm::fabsf(g.trim_elevator) > g.elevator_max {
        return Err("TRIM_ELEV_DEG");
    }
    if g.takeoff_pitch > g.pitch_max {
        return Err("TKO_PTCH_DEG");
    }
    Ok(())
}

/// Parameters of the longitudinal autopilot; defaults are the thesis's designed set (trims:
/// Table 2.3 trim I; take-off pitch, band and hysteresis: not in the thesis, chosen here). The
/// bounds of the loop gains admit only the sign that stabilises the loop in the UMN convention.
pub const PARAMS: Group<LongitudinalGains> = Group {
    name: "Longitudinal autopilot",
    params: &[
        param!(
            ParamDef::real(
                "PTCH_KP",
                G.pitch_kp,
                -10.0,
                0.0,
                "rad/rad",
                "Pitch attitude P gain, elevator per pitch error (UMN sign: negative)",
            ),
            LongitudinalGains => pitch_kp
        ),
        param!(
            ParamDef::real(
                "PTCH_KI",
                G.pitch_ki,
                -10.0,
                0.0,
                "1/s",
                "Pitch attitude I gain, elevator per integrated pitch error",
            ),
            LongitudinalGains => pitch_ki
        ),
        param!(
            ParamDef::real(
                "PTCH_RATE_KD",
                G.pitch_rate_kd,
                -2.0,
                0.0,
                "s",
                "Pitch-rate damper, elevator per pitch rate beyond a coordinated turn's, applied as -kd*q",
            ),
            LongitudinalGains => pitch_rate_kd
        ),
        param!(
            ParamDef::real(
                "ALT_KP",
                G.alt_kp,
                0.0,
                1.0,
                "rad/m",
                "Altitude hold P gain, commanded pitch per altitude error",
            ),
            LongitudinalGains => alt_kp
        ),
        param!(
            ParamDef::real(
                "ALT_KI",
                G.alt_ki,
                0.0,
                1.0,
                "rad/(m s)",
                "Altitude hold I gain, commanded pitch per integrated altitude error",
            ),
            LongitudinalGains => alt_ki
        ),
        param!(
            ParamDef::real(
                "ASPD_PTCH_KP",
                G.aspd_pitch_kp,
                -5.0,
                0.0,
                "rad s/m",
                "Airspeed-by-pitch P gain, commanded pitch per airspeed error",
            ),
            LongitudinalGains => aspd_pitch_kp
        ),
        param!(
            ParamDef::real(
                "ASPD_PTCH_KI",
                G.aspd_pitch_ki,
                -5.0,
                0.0,
                "rad/m",
                "Airspeed-by-pitch I gain, per integrated airspeed error",
            ),
            LongitudinalGains => aspd_pitch_ki
        ),
        param!(
            ParamDef::real(
                "ASPD_THR_KP",
                G.aspd_thr_kp,
                0.0,
                5.0,
                "s/m",
                "Airspeed-by-throttle P gain, throttle per airspeed error",
            ),
            LongitudinalGains => aspd_thr_kp
        ),
        param!(
            ParamDef::real(
                "ASPD_THR_KI",
                G.aspd_thr_ki,
                0.0,
                50.0,
                "1/m",
                "Airspeed-by-throttle I gain, throttle per integrated airspeed error",
            ),
            LongitudinalGains => aspd_thr_ki
        ),
        param!(
            ParamDef::real(
                "LIM_PTCH_DEG",
                G.pitch_max * RAD2DEG,
                5.0,
                45.0,
                "deg",
                "Largest commanded pitch angle (either sign)",
            ),
            LongitudinalGains => pitch_max, scale RAD2DEG
        ),
        param!(
            ParamDef::real(
                "LIM_ELEV_DEG",
                25.0,
                1.0,
                25.0,
                "deg",
                "Elevator travel the autopilot may use",
            ),
            LongitudinalGains => elevator_max, scale RAD2DEG
        ),
        param!(
            ParamDef::real(
                "THR_MIN",
                G.throttle_min,
                0.0,
                1.0,
                "",
                "Throttle in the descent regime and lowest throttle",
            ),
            LongitudinalGains => throttle_min
        ),
        param!(
            ParamDef::real(
                "THR_MAX",
                G.throttle_max,
                0.0,
                1.0,
                "",
                "Throttle in take-off and climb and highest throttle",
            ),
            LongitudinalGains => throttle_max
        ),
        param!(
            ParamDef::real(
                "TRIM_ELEV_DEG",
                G.trim_elevator * RAD2DEG,
                -25.0,
                25.0,
                "deg",
                "Elevator trim, feed-forward of the pitch loop (trim I)",
            ),
            LongitudinalGains => trim_elevator, scale RAD2DEG
        ),
        param!(
            ParamDef::real(
                "TRIM_THR",
                G.trim_throttle,
                0.0,
                1.0,
                "",
                "Throttle trim, feed-forward of the airspeed-by-throttle loop",
            ),
            LongitudinalGains => trim_throttle
        ),
        param!(
            ParamDef::real(
                "TRIM_PTCH_DEG",
                G.trim_pitch * RAD2DEG,
                -20.0,
                20.0,
                "deg",
                "Pitch at trim, feed-forward of the altitude and airspeed-by-pitch loops (trim I)",
            ),
            LongitudinalGains => trim_pitch, scale RAD2DEG
        ),
        param!(
            ParamDef::real(
                "FB_LPF_POLE",
                G.feedback_lpf_pole,
                0.1,
                50.0,
                "rad/s",
                "Pole of the low-pass on altitude and airspeed feedback",
            ),
            LongitudinalGains => feedback_lpf_pole
        ),
        param!(
            ParamDef::real(
                "TKO_PTCH_DEG",
                G.takeoff_pitch * RAD2DEG,
                0.0,
                30.0,
                "deg",
                "Pitch held in the take-off regime",
            ),
            LongitudinalGains => takeoff_pitch, scale RAD2DEG
        ),
        param!(
            ParamDef::real(
                "ALT_BAND_M",
                G.alt_band,
                1.0,
                500.0,
                "m",
                "Altitude-hold band: hold regime entered inside +-band",
            ),
            LongitudinalGains => alt_band
        ),
        param!(
            ParamDef::real(
                "ALT_HYST_M",
                G.alt_hysteresis,
                0.0,
                100.0,
                "m",
                "Hold regime left only beyond +-(band + hysteresis)",
            ),
            LongitudinalGains => alt_hysteresis
        ),
    ],
    base: || FLIGHT,
    check: consistent,
};
