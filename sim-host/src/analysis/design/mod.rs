//! Gain design by successive loop closure (thesis chapter 3 and Appendix C, after Beard and
//! McLain), from the aircraft data and the linear model at the level trim, or from identified
//! reduced models alone.
//!
//! The rules and the attitude gains' limit by phase margin are the on-board design's
//! (`common::tuning::design`, whose documentation states each rule and why it departs from
//! Appendix C where it does): the host runs that same code, in `f32`, on the reduced models
//! it forms, and adds what only the host predicts. Each loop is then judged on that same
//! reduced model with the inner loops as designed (closed-loop poles, rise time, overshoot),
//! and its stability margins are computed again from a dense `f64` sweep with what the
//! design formulas leave out: the 8 Hz servo and the flight software's delay (two 20 ms
//! samples plus half a sample of zero-order hold, 50 ms in all), and on the altitude and
//! airspeed loops the 2 rad/s feedback low-pass.
//!
//! From the aircraft file, the roll and pitch rules take Beard and McLain's coefficients from
//! the aero data, and the pitch loop is limited and predicted on the linear model's two-state
//! short period `q / de` (with its free integrator to `theta`); from identified models, on the
//! reduced short period `a_theta3 / (s^2 + a_theta1 s + a_theta2)`.
//!
//! The sideslip loop (PI on rudder) is the on-board design's too, where there is a sideslip
//! model (the aircraft file's, or an identified one): `wn_beta = wn_phi / 20`, `kp = (2 zeta
//! wn - a_beta1) / a_beta2` (0 where that is negative), `ki = wn^2 / a_beta2`; here it is
//! predicted.

pub mod inputs;
pub mod loops;

use super::linearize::{linearize, Linearization};
use super::lti::{damping_and_frequency, margins};
use super::reduced::ReducedCoefficients;
use super::transfer::TransferFunction;
use super::trim::{trim_with, TrimResult, TrimTarget};
use crate::aircraft::Aircraft;
use crate::plant::params::ModelParams;
use common::control::gains::{GainSet, DESIGNED};
use common::math::atmosphere::standard_atmosphere;
use common::tuning::design::{
    DesignModel, Designer, Loop, LoopDesign as OnboardLoop, PitchResponse, Rules, Step,
    QUASI_STEADY_ENGINE_POLE,
};
use loops::{closed, gain, predict, reduce, tf, through_inner, with_actuation};
use nalgebra::Complex;
use serde::Serialize;
use std::f64::consts::PI;

pub use inputs::DesignInputs;
pub use loops::LoopDesign;

/// Model coefficients the design rules use.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Coefficients {
    /// Airspeed, m/s.
    pub va: f64,
    /// Density, kg/m^3.
    pub rho: f64,
    /// `a_phi1` from the aero data, 1/s.
    pub a_phi1: f64,
    /// `a_phi2` from the aero data, rad/s^2 per rad.
    pub a_phi2: f64,
    /// `-A[p,p]` of the linear model (the roll-subsidence pole), 1/s.
    pub a_phi1_linear: f64,
    /// Combined-aileron `B[p]` of the linear model.
    pub a_phi2_linear: f64,
    /// `a_beta1`, 1/s.
    pub a_beta1: f64,
    /// `a_beta2`, 1/s.
    pub a_beta2: f64,
    /// `a_theta1`, 1/s.
    pub a_theta1: f64,
    /// `a_theta2`, 1/s^2.
    pub a_theta2: f64,
    /// `a_theta3`, 1/s^2.
    pub a_theta3: f64,
    /// Speed damping `-A[u,u]`, 1/s.
    pub a_v1: f64,
    /// Steady-state airspeed acceleration per unit throttle, m/s^2.
    pub a_v2: f64,
    /// Engine-speed pole `-A[Omega,Omega]`, 1/s.
    pub engine_pole: f64,
    /// The flight path's pole behind the pitch, 1/s (0: none, the thesis's altitude and
    /// airspeed models `h / theta = Va / s`, `Va / theta = -g / (s + a_V1)`).
    pub a_gamma: f64,
}

/// Appendix C's roll numbers, and the phase margin they leave once servo and delay are in the
/// loop.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct AppendixC {
    /// Natural frequency, rad/s.
    pub wn_phi: f64,
    /// Roll kp.
    pub roll_kp: f64,
    /// Roll-rate kd.
    pub roll_kd: f64,
    /// Phase margin with the 8 Hz servo and the 50 ms delay, deg.
    pub phase_margin_deg: Option<f64>,
}

/// The whole design.
#[derive(Clone, Debug, Serialize)]
pub struct Design {
    /// The designer's choices.
    pub inputs: DesignInputs,
    /// Model coefficients.
    pub coefficients: Coefficients,
    /// Appendix C's roll design as printed, before the delay is accounted for.
    pub appendix_c: AppendixC,
    /// Every loop, inner to outer.
    pub loops: Vec<LoopDesign>,
    /// The gain set ("computed").
    #[serde(skip)]
    pub gains: GainSet,
}

/// Designs every loop at the level trim of `aircraft` at its cruise airspeed.
pub fn design(aircraft: &Aircraft, inputs: &DesignInputs) -> anyhow::Result<Design> {
    design_at(aircraft, inputs, aircraft.cruise_airspeed_mps())
}

/// Designs every loop at the level trim of `aircraft` at `va_mps`.
pub fn design_at(
    aircraft: &Aircraft,
    inputs: &DesignInputs,
    va_mps: f64,
) -> anyhow::Result<Design> {
    let params = ModelParams::new(aircraft);
    let trim: TrimResult = trim_with(&params, &TrimTarget::level().at_airspeed(va_mps));
    if !trim.converged {
        anyhow::bail!("{}; cannot design", super::trim::not_trimmed(&trim));
    }
    let lin: Linearization = linearize(&params, &trim);
    let va = trim.target.va_mps;
    let rho =
        standard_atmosphere(aircraft.environment.home_alt_msl_m + trim.target.alt_msl_m).density;
    let g = aircraft.environment.g_mps2;
    let (m, geo, aero) = (&aircraft.mass, &aircraft.geometry, &aircraft.aero);

    // Roll: Appendix C's coefficients from the aero data.
    let gamma = m.Jx_kgm2 * m.Jz_kgm2 - m.Jxz_kgm2 * m.Jxz_kgm2;
    let (g3, g4) = (m.Jz_kgm2 / gamma, m.Jxz_kgm2 / gamma);
    let c_p_p = g3 * aero.roll.Cl_p + g4 * aero.yaw.Cn_p;
    let c_p_da = g3 * aero.roll.Cl_da + g4 * aero.yaw.Cn_da;
    let a_phi1 = -0.25 * rho * va * geo.S_m2 * geo.b_m * geo.b_m * c_p_p;
    let a_phi2 = 0.5 * rho * va * va * geo.S_m2 * geo.b_m * c_p_da;
    // Lateral model order v, p, r, phi, psi; inputs left, right aileron, rudder.
    let a_phi1_linear = -lin.lat.a[(1, 1)];
    let a_phi2_linear = lin.lat.b[(1, 1)] - lin.lat.b[(1, 0)];
    // Sideslip.
    let a_beta1 = -rho * va * geo.S_m2 * aero.side.CY_beta / (2.0 * m.mass_kg);
    let a_beta2 = rho * va * geo.S_m2 * aero.side.CY_dr / (2.0 * m.mass_kg);
    // Pitch (Beard and McLain's reduced model, from the aero data).
    let qbar_sc = 0.5 * rho * va * va * geo.S_m2 * geo.c_m;
    let a_theta1 = -rho * va * geo.c_m * geo.c_m * geo.S_m2 * aero.pitch.Cm_q / (4.0 * m.Jy_kgm2);
    let a_theta2 = -qbar_sc * aero.pitch.Cm_alpha / m.Jy_kgm2;
    let a_theta3 = qbar_sc * aero.pitch.Cm_de / m.Jy_kgm2;
    // Speed: longitudinal order u, w, q, theta, Ze, Omega; inputs elevator, throttle.
    let lon = &lin.lon;
    let a_v1 = -lon.a[(0, 0)];
    let engine_pole = -lon.a[(5, 5)];
    let a_v2 = lon.a[(0, 5)] * lon.b[(5, 1)] / engine_pole;

    let coefficients = Coefficients {
        va,
        rho,
        a_phi1,
        a_phi2,
        a_phi1_linear,
        a_phi2_linear,
        a_beta1,
        a_beta2,
        a_theta1,
        a_theta2,
        a_theta3,
        a_v1,
        a_v2,
        engine_pole,
        // The thesis's altitude and airspeed models: the computed set is the thesis's
        // design. The flight path's lag is the identified models' (`--model`, the autotune).
        a_gamma: 0.0,
    };
    // Pitch: predicted on the linear short period.
    let q_de = &super::transfer::thesis_transfer_functions(&lin).q_over_de;
    let theta_de = q_de.series(&tf(&[1.0], &[1.0, 0.0]));
    let plant = Plant {
        coefficients,
        theta_de,
        servo_bandwidth_hz: aircraft.actuators.bandwidth_Hz,
        g,
    };
    design_loops(inputs, plant, Some(&trim))
}

/// What the loops are designed on.
struct Plant {
    coefficients: Coefficients,
    /// Pitch attitude per elevator, the loop's prediction model.
    theta_de: TransferFunction,
    servo_bandwidth_hz: f64,
    g: f64,
}

/// The reduced models a design from flight data starts from (`sim-host identify`): no
/// aircraft file, no linearisation.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ReducedModel {
    /// Airspeed the coefficients hold at, m/s.
    pub va: f64,
    /// Beard and McLain's coefficients; those not identified are NaN (the sideslip's: its
    /// loop is then not designed).
    pub coefficients: ReducedCoefficients,
    /// The engine speed's pole, 1/s (`None`: not identified, taken as quasi-steady).
    pub engine_pole: Option<f64>,
    /// The servos' bandwidth, Hz.
    pub servo_bandwidth_hz: f64,
    /// Gravity, m/s^2.
    pub g: f64,
}

/// Designs every loop on a reduced model alone: the pitch loop predicted on its reduced
/// short period `a_theta3 / (s^2 + a_theta1 s + a_theta2)`, the sideslip loop not designed (no
/// sideslip model: the base set's gains stay), the trims left to the aircraft's own.
pub fn design_from_model(model: &ReducedModel, inputs: &DesignInputs) -> anyhow::Result<Design> {
    let m = &model.coefficients;
    let c = Coefficients {
        va: model.va,
        rho: f64::NAN,
        a_phi1: m.a_phi1,
        a_phi2: m.a_phi2,
        a_phi1_linear: m.a_phi1,
        a_phi2_linear: m.a_phi2,
        a_beta1: m.a_beta1,
        a_beta2: m.a_beta2,
        a_theta1: m.a_theta1,
        a_theta2: m.a_theta2,
        a_theta3: m.a_theta3,
        a_v1: m.a_v1,
        a_v2: m.a_v2,
        engine_pole: model
            .engine_pole
            .unwrap_or(f64::from(QUASI_STEADY_ENGINE_POLE)),
        // A model without the flight path's fit (or with a pole that is no lag) keeps the
        // thesis's lag-free altitude model.
        a_gamma: if m.a_gamma.is_finite() && m.a_gamma > 0.0 {
            m.a_gamma
        } else {
            0.0
        },
    };
    let theta_de = tf(&[m.a_theta3], &[1.0, m.a_theta1, m.a_theta2]);
    let plant = Plant {
        coefficients: c,
        theta_de,
        servo_bandwidth_hz: model.servo_bandwidth_hz,
        g: model.g,
    };
    design_loops(inputs, plant, None)
}

/// `theta_de` as the on-board design takes it: at most a first-order numerator over a cubic.
fn pitch_response(t: &TransferFunction) -> anyhow::Result<PitchResponse> {
    fn padded<const N: usize>(c: &[f64]) -> Option<[f32; N]> {
        let first = c.iter().position(|x| *x != 0.0).unwrap_or(c.len());
        let c = &c[first..];
        let mut out = [0.0f32; N];
        let start = N.checked_sub(c.len())?;
        for (o, x) in out[start..].iter_mut().zip(c) {
            *o = *x as f32;
        }
        Some(out)
    }
    match (padded::<2>(&t.num), padded::<4>(&t.den)) {
        (Some(num), Some(den)) => Ok(PitchResponse { num, den }),
        _ => anyhow::bail!(
            "the pitch response {} is of higher order than the design takes",
            t.format(4)
        ),
    }
}

/// An `f32` design input as the decimal it was written as (`0.02`, not the `f32`'s
/// 0.0199999995...), for the host's `f64` predictions.
pub fn decimal(x: f32) -> f64 {
    x.to_string().parse().unwrap_or(f64::from(x))
}

/// The loops, inner to outer, on `plant`, flown about `trim` (`None`: the base set's trims).
///
/// The gains are the on-board design's (`common::tuning::design`: the same rules and the same
/// gain limit, in `f32`), run to its end on the plant's reduced models with the pitch loop
/// judged on `theta_de`; this adds the host's own predictions of each loop (closed-loop poles,
/// step figures, and margins from a dense `f64` sweep) and the sideslip loop where there is a
/// sideslip model. A loop that misses its margins is designed and predicted all the same: the
/// margins are judged by [`crate::commands::design_model`].
fn design_loops(
    inputs: &DesignInputs,
    plant: Plant,
    trim: Option<&TrimResult>,
) -> anyhow::Result<Design> {
    let Plant {
        coefficients,
        theta_de,
        servo_bandwidth_hz,
        g,
    } = plant;
    let Coefficients {
        va,
        a_phi1,
        a_phi2,
        a_beta1,
        a_beta2,
        a_v1,
        a_v2,
        engine_pole,
        a_gamma,
        ..
    } = coefficients;
    let d = &DESIGNED;

    // The gains: the on-board design on this plant.
    let model = DesignModel {
        va: va as f32,
        a_phi1: a_phi1 as f32,
        a_phi2: a_phi2 as f32,
        // Without a sideslip model (an aircraft file without the side force's derivatives):
        // none, and the sideslip loop keeps the base set's gains.
        a_beta1: if a_beta1.is_finite() {
            a_beta1 as f32
        } else {
            0.0
        },
        a_beta2: if a_beta2.is_finite() {
            a_beta2 as f32
        } else {
            0.0
        },
        a_theta1: coefficients.a_theta1 as f32,
        a_theta2: coefficients.a_theta2 as f32,
        a_theta3: coefficients.a_theta3 as f32,
        a_v1: a_v1 as f32,
        a_v2: a_v2 as f32,
        a_gamma: a_gamma as f32,
        engine_pole: Some(engine_pole as f32),
        servo_bandwidth_hz: servo_bandwidth_hz as f32,
        g: g as f32,
        pitch_response: Some(pitch_response(&theta_de)?),
    };
    let mut designer = Designer::new(&model, inputs, d);
    let designed = loop {
        match designer.step() {
            Step::Pending => {}
            Step::Done(designed) => break designed,
            Step::Failed(f) => match designer.designed() {
                // Every loop designed, one missed its margins: predicted all the same.
                Some(designed) => break designed,
                None => anyhow::bail!("the design stopped: {f}"),
            },
        }
    };
    let onboard = designed.loops;
    let pid = |l: &OnboardLoop| {
        (
            f64::from(l.gains.kp),
            f64::from(l.gains.ki),
            f64::from(l.gains.kd),
            f64::from(l.wn_radps),
        )
    };

    // What the formulas leave out: servo and delay.
    let servo_w = 2.0 * PI * servo_bandwidth_hz;
    let tau = (decimal(inputs.delay_samples) + 0.5) * decimal(inputs.sample_time_s);
    let servo_delay = move |w: f64| {
        let s = Complex::new(0.0, w);
        servo_w / (s + servo_w) * Complex::new(0.0, -w * tau).exp()
    };
    let lp = d.longitudinal.feedback_lpf_pole as f64;
    let filter = tf(&[lp], &[1.0, lp]);
    let mut loops = Vec::new();

    // --- Roll.
    let roll_plant = tf(&[a_phi2], &[1.0, a_phi1, 0.0]);
    let (roll_kp, roll_ki, roll_kd, wn_phi) = pid(&onboard.roll);
    // Appendix C's own design, before the gain is limited by the margin with servo and delay.
    let rules = Rules::new(&model, inputs, d);
    let kp_appendix_c = rules.roll_kp_appendix_c();
    let appendix_c_pid = rules.roll(kp_appendix_c);
    let appendix_c = AppendixC {
        wn_phi: f64::from(rules.roll_wn_appendix_c()),
        roll_kp: f64::from(kp_appendix_c),
        roll_kd: f64::from(appendix_c_pid.kd),
        phase_margin_deg: {
            let (kp, ki, kd) = (
                f64::from(appendix_c_pid.kp),
                f64::from(appendix_c_pid.ki),
                f64::from(appendix_c_pid.kd),
            );
            let l = tf(&[kd, kp, ki], &[1.0, 0.0]).series(&roll_plant);
            margins(move |w| l.eval(w) * servo_delay(w), 1e-3, 1e3).phase_margin_deg
        },
    };
    let roll_pid = tf(&[roll_kd, roll_kp, roll_ki], &[1.0, 0.0]);
    let roll_cl = tf(
        &[a_phi2 * roll_kp, a_phi2 * roll_ki],
        &[
            1.0,
            a_phi1 + a_phi2 * roll_kd,
            a_phi2 * roll_kp,
            a_phi2 * roll_ki,
        ],
    );
    let roll_loop = roll_pid.series(&roll_plant);
    let roll_real = {
        let l = roll_loop.clone();
        let pi_part = tf(&[roll_kp, roll_ki], &[1.0, 0.0]).series(&roll_plant);
        // phi/phi_c with servo and delay in the loop, for the outer loops' margins.
        move |w: f64| {
            let sd = servo_delay(w);
            let lw = l.eval(w) * sd;
            pi_part.eval(w) * sd / (1.0 + lw)
        }
    };
    loops.push(predict(
        "roll attitude (aileron)",
        Some(Loop::Roll),
        vec![
            gain("RLL_KP", roll_kp, d.lateral.roll_kp),
            gain("RLL_KI", roll_ki, d.lateral.roll_ki),
            gain("RLL_RATE_KD", roll_kd, d.lateral.roll_rate_kd),
        ],
        wn_phi,
        &roll_cl,
        with_actuation(&roll_loop, servo_delay),
        3.0,
    ));

    // --- Course.
    let (course_kp, course_ki, _, wn_chi) = pid(&onboard.course);
    let course_pi = tf(&[course_kp, course_ki], &[1.0, 0.0]);
    let kin = tf(&[g / va], &[1.0, 0.0]);
    let course_fwd = course_pi.series(&roll_cl).series(&kin);
    let course_cl = course_fwd.closed_loop();
    loops.push(predict(
        "course (commanded roll)",
        Some(Loop::Course),
        vec![
            gain("CRS_KP", course_kp, d.lateral.course_kp),
            gain("CRS_KI", course_ki, d.lateral.course_ki),
        ],
        wn_chi,
        &course_cl,
        through_inner(
            &course_pi,
            roll_real.clone(),
            &kin,
            &TransferFunction::gain(1.0),
        ),
        20.0,
    ));

    // --- Sideslip (where there is a sideslip model): the on-board design's.
    if model.has_sideslip() {
        let (slip_kp, slip_ki, _, wn_beta) = pid(&onboard.sideslip);
        let slip_plant = tf(&[a_beta2], &[1.0, a_beta1]);
        let slip_loop = tf(&[slip_kp, slip_ki], &[1.0, 0.0]).series(&slip_plant);
        loops.push(predict(
            "sideslip (rudder)",
            Some(Loop::Sideslip),
            vec![
                gain("SLIP_KP", slip_kp, d.lateral.slip_kp),
                gain("SLIP_KI", slip_ki, d.lateral.slip_ki),
            ],
            wn_beta,
            &slip_loop.closed_loop(),
            with_actuation(&slip_loop, servo_delay),
            20.0,
        ));
    }

    // --- Pitch: predicted on `theta_de`.
    let (pitch_kp, pitch_ki, pitch_kd, wn_theta) = pid(&onboard.pitch);
    let pitch_pid = tf(&[pitch_kd, pitch_kp, pitch_ki], &[1.0, 0.0]);
    let pitch_loop = pitch_pid.series(&theta_de);
    let pitch_pi_fwd = tf(&[pitch_kp, pitch_ki], &[1.0, 0.0]).series(&theta_de);
    // theta/theta_c = PI P / (1 + PID P).
    let pitch_cl = {
        use super::transfer::{poly_add, poly_mul};
        TransferFunction::new(
            &poly_mul(&pitch_pi_fwd.num, &pitch_loop.den),
            &poly_mul(
                &pitch_pi_fwd.den,
                &poly_add(&pitch_loop.den, &pitch_loop.num),
            ),
        )
    };
    let pitch_cl = reduce(&pitch_cl);
    let pitch_real = {
        let (l, f) = (pitch_loop.clone(), pitch_pi_fwd.clone());
        move |w: f64| {
            let sd = servo_delay(w);
            f.eval(w) * sd / (1.0 + l.eval(w) * sd)
        }
    };
    loops.push(predict(
        "pitch attitude (elevator)",
        Some(Loop::Pitch),
        vec![
            gain("PTCH_KP", pitch_kp, d.longitudinal.pitch_kp),
            gain("PTCH_KI", pitch_ki, d.longitudinal.pitch_ki),
            gain("PTCH_RATE_KD", pitch_kd, d.longitudinal.pitch_rate_kd),
        ],
        wn_theta,
        &pitch_cl,
        with_actuation(&pitch_loop, servo_delay),
        4.0,
    ));

    // --- Altitude by pitch.
    let (alt_kp, alt_ki, _, wn_h) = pid(&onboard.altitude);
    let alt_pi = tf(&[alt_kp, alt_ki], &[1.0, 0.0]);
    // The flight path per pitch, `a_gamma / (s + a_gamma)`, or 1 without its lag.
    let path = if a_gamma > 0.0 {
        tf(&[a_gamma], &[1.0, a_gamma])
    } else {
        tf(&[1.0], &[1.0])
    };
    let climb = path.series(&tf(&[va], &[1.0, 0.0]));
    let alt_fwd = alt_pi.series(&pitch_cl).series(&climb);
    loops.push(predict(
        "altitude (commanded pitch)",
        Some(Loop::Altitude),
        vec![
            gain("ALT_KP", alt_kp, d.longitudinal.alt_kp),
            gain("ALT_KI", alt_ki, d.longitudinal.alt_ki),
        ],
        wn_h,
        &reduce(&closed(&alt_fwd, &filter)),
        through_inner(&alt_pi, pitch_real.clone(), &climb, &filter),
        40.0,
    ));

    // --- Airspeed by pitch (climb and descent regimes).
    let (aspd_pitch_kp, aspd_pitch_ki, _, wn_v2) = pid(&onboard.airspeed_pitch);
    let v_theta = path.series(&tf(&[-g], &[1.0, a_v1]));
    let ap_pi = tf(&[aspd_pitch_kp, aspd_pitch_ki], &[1.0, 0.0]);
    let ap_fwd = ap_pi.series(&pitch_cl).series(&v_theta);
    loops.push(predict(
        "airspeed (commanded pitch)",
        Some(Loop::AirspeedPitch),
        vec![
            gain("ASPD_PTCH_KP", aspd_pitch_kp, d.longitudinal.aspd_pitch_kp),
            gain("ASPD_PTCH_KI", aspd_pitch_ki, d.longitudinal.aspd_pitch_ki),
        ],
        wn_v2,
        &reduce(&closed(&ap_fwd, &filter)),
        through_inner(&ap_pi, pitch_real.clone(), &v_theta, &filter),
        40.0,
    ));

    // --- Airspeed by throttle (altitude-hold regime).
    let (aspd_thr_kp, aspd_thr_ki, _, wn_v) = pid(&onboard.airspeed_throttle);
    let v_dt = tf(
        &[a_v2 * engine_pole],
        &[1.0, a_v1 + engine_pole, a_v1 * engine_pole],
    );
    let at_pi = tf(&[aspd_thr_kp, aspd_thr_ki], &[1.0, 0.0]);
    let at_fwd = at_pi.series(&v_dt);
    loops.push(predict(
        "airspeed (throttle)",
        Some(Loop::AirspeedThrottle),
        vec![
            gain("ASPD_THR_KP", aspd_thr_kp, d.longitudinal.aspd_thr_kp),
            gain("ASPD_THR_KI", aspd_thr_ki, d.longitudinal.aspd_thr_ki),
        ],
        wn_v,
        &closed(&at_fwd, &filter),
        Box::new({
            let (l, f) = (at_fwd.clone(), filter.clone());
            move |w| l.eval(w) * f.eval(w) * Complex::new(0.0, -w * tau).exp()
        }),
        40.0,
    ));

    // The on-board design's set (the base's with its loops' gains), with the trims where this
    // design has them.
    let mut gains = designed.gains;
    if let Some(trim) = trim {
        gains.lateral.trim_aileron = trim.aileron as f32;
        gains.lateral.trim_rudder = trim.rudder as f32;
        let lon_g = &mut gains.longitudinal;
        lon_g.trim_elevator = trim.elevator as f32;
        lon_g.trim_throttle = trim.throttle as f32;
        lon_g.trim_pitch = trim.theta as f32;
    }
    if let Err(e) = gains.validate() {
        anyhow::bail!("the computed gains are outside their parameter bounds: {e}");
    }
    Ok(Design {
        inputs: *inputs,
        coefficients,
        appendix_c,
        loops,
        gains,
    })
}

/// The "computed" gain set: [`design`] with the thesis's design inputs.
pub fn computed_gain_set(aircraft: &Aircraft) -> anyhow::Result<GainSet> {
    computed_gain_set_at(aircraft, aircraft.cruise_airspeed_mps())
}

/// [`computed_gain_set`] designed at the level trim at `va_mps`.
pub fn computed_gain_set_at(aircraft: &Aircraft, va_mps: f64) -> anyhow::Result<GainSet> {
    Ok(design_at(aircraft, &DesignInputs::default(), va_mps)?.gains)
}

/// Damping and natural frequency of each pole, for reports.
pub fn describe_poles(poles: &[[f64; 2]]) -> Vec<(f64, f64)> {
    poles
        .iter()
        .map(|p| damping_and_frequency(Complex::new(p[0], p[1])))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn appendix_c_numbers_are_reproduced() {
        let a = Aircraft::ultrastick25e().expect("built-in aircraft");
        let d = design(&a, &DesignInputs::default()).expect("design");
        let c = &d.coefficients;
        // The aero-data roll coefficients equal the linear model's p/da (thesis eq. 20).
        assert!((c.a_phi1 - 16.09).abs() < 0.02, "{}", c.a_phi1);
        assert!((c.a_phi2 + 156.5).abs() < 0.2, "{}", c.a_phi2);
        assert!((c.a_phi1 - c.a_phi1_linear).abs() / c.a_phi1 < 0.01);
        // Thesis section 3.4.1: kd_phi = -0.0618 moves the roll pole from -16.09 to -25.76.
        let kd = d.appendix_c.roll_kd;
        assert!((kd + 0.0618).abs() < 5e-4, "kd {kd}");
        assert!((c.a_phi1 + c.a_phi2 * kd - 25.76).abs() < 0.05);
        // Appendix C's kp = wn^2 / a_phi2 = -(45 / 15) sqrt(1 - 0.707^2) = -2.1216.
        assert!((d.appendix_c.roll_kp + 2.1216).abs() < 1e-3);
        // With the servo and the 50 ms software delay that design keeps almost no phase
        // margin, so the computed set is slower.
        assert!(d.appendix_c.phase_margin_deg.unwrap_or(0.0) < 10.0);
        assert!(d.gains.lateral.roll_kp.abs() < 2.0);
        // B&M sideslip coefficients: a_beta1 = 0.796, a_beta2 = 0.312 at 17 m/s.
        assert!((c.a_beta1 - 0.7963).abs() < 1e-3 && (c.a_beta2 - 0.3116).abs() < 1e-3);
        // Short-period elevator effectiveness: a_theta3 matches q/de's -133.7 within 1 %.
        assert!((c.a_theta3 + 133.7).abs() < 1.4, "{}", c.a_theta3);
    }

    #[test]
    fn every_loop_is_stable_with_margins() {
        let a = Aircraft::ultrastick25e().expect("built-in aircraft");
        let d = design(&a, &DesignInputs::default()).expect("design");
        for l in &d.loops {
            assert!(
                l.poles.iter().all(|p| p[0] < 0.0),
                "{} unstable: {:?}",
                l.name,
                l.poles
            );
            let pm = l.margins.phase_margin_deg.unwrap_or(90.0);
            assert!(pm > 30.0, "{}: phase margin {pm}", l.name);
            if let Some(gm) = l.margins.gain_margin_db {
                assert!(gm > 6.0, "{}: gain margin {gm}", l.name);
            }
        }
        // Inner loops meet the thesis's rise-time requirement on the linear model.
        for name in ["roll", "pitch"] {
            let l = d
                .loops
                .iter()
                .find(|l| l.name.starts_with(name))
                .expect("loop");
            assert!(
                l.rise_time_s.unwrap_or(9.0) < 1.0,
                "{name}: {:?}",
                l.rise_time_s
            );
        }
    }
}
