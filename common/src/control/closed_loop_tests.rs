//! Closed-loop tests of the autopilot against linear models of the Ultra Stick 25e built from
//! the thesis's transfer functions (REFERENCE.md): the stages run in f32 at 50 Hz exactly as in
//! flight, the plant in f64 with RK4 sub-steps and the surfaces held over each sample (zero-order
//! hold). No sensor delay: the thesis's two-sample delay belongs to its simulation set-up, and the
//! nonlinear-plant tests elsewhere in the project include it.
//!
//! Trims are zeroed: the linear models are about trim I, in deviation variables.

extern crate std;
use std::vec::Vec;

use super::autopilot::{Autopilot, Commands};
use super::gains::{GainSet, DESIGNED, DESIGNED_T310, MINNESOTA};
use super::inputs::Measurements;
use super::lateral::{Lateral, RollMode, YawMode};
use super::longitudinal::LonMode;

const DT: f32 = 0.02;
const SUB: usize = 20;
const VA: f64 = 17.0;
const G0: f64 = crate::math::STANDARD_GRAVITY;
const D: f64 = core::f64::consts::PI / 180.0;

/// A linear plant x' = f(x, u), stepped with RK4 over one control sample with u held.
fn rk4<const N: usize>(x: &mut [f64; N], u: f64, f: impl Fn(&[f64; N], f64) -> [f64; N]) {
    let h = DT as f64 / SUB as f64;
    for _ in 0..SUB {
        let add = |a: &[f64; N], k: &[f64; N], s: f64| {
            let mut r = *a;
            for i in 0..N {
                r[i] += s * k[i];
            }
            r
        };
        let k1 = f(x, u);
        let k2 = f(&add(x, &k1, h / 2.0), u);
        let k3 = f(&add(x, &k2, h / 2.0), u);
        let k4 = f(&add(x, &k3, h), u);
        for i in 0..N {
            x[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
        }
    }
}

/// Step-response figures of a sampled response to a step of size `target` from 0.
#[derive(Debug)]
struct StepInfo {
    rise_10_90: f64,
    overshoot: f64,
    final_error: f64,
    t_63: f64,
}

/// Step figures of the part of a response after `t0` (when the step was commanded), relative to
/// the value `y0` before it.
fn step_after(t: &[f64], y: &[f64], t0: f64, y0: f64, size: f64) -> StepInfo {
    let (tt, yy): (Vec<f64>, Vec<f64>) = t
        .iter()
        .zip(y)
        .filter(|(t, _)| **t > t0 + 1e-9)
        .map(|(t, y)| (t - t0, y - y0))
        .unzip();
    step_info(&tt, &yy, size)
}

fn step_info(t: &[f64], y: &[f64], target: f64) -> StepInfo {
    let first = |frac: f64| {
        t.iter()
            .zip(y)
            .find(|(_, v)| **v / target >= frac)
            .map(|(t, _)| *t)
            .unwrap_or(f64::INFINITY)
    };
    let peak = y.iter().map(|v| v / target).fold(f64::MIN, f64::max);
    StepInfo {
        rise_10_90: first(0.9) - first(0.1),
        overshoot: (peak - 1.0).max(0.0),
        final_error: (y.last().unwrap() / target - 1.0).abs(),
        t_63: first(0.632),
    }
}

fn no_trim(mut g: GainSet) -> GainSet {
    g.lateral.trim_aileron = 0.0;
    g.lateral.trim_rudder = 0.0;
    g.longitudinal.trim_elevator = 0.0;
    g.longitudinal.trim_throttle = 0.0;
    g.longitudinal.trim_pitch = 0.0;
    g
}

/// Roll: p/da = -156.5 / (s + 16.09) (eq. 20), phi = integral of p. Optionally the course
/// kinematics chi' = g / Va tan(phi) (eq. 24). States (p, phi, chi).
fn roll_plant(x: &[f64; 3], da: f64) -> [f64; 3] {
    [-16.09 * x[0] - 156.5 * da, x[0], G0 / VA * x[1].tan()]
}

fn fly_lateral(
    g: &GainSet,
    mode: impl Fn(f64) -> RollMode,
    secs: f64,
) -> (Vec<f64>, Vec<[f64; 3]>) {
    fly_lateral_over_the_ground(g, mode, secs, VA, 1.0)
}

/// As [`fly_lateral`] at `vg` m/s over the ground (the turn `chi' = g / vg tan(phi)`), the
/// course loop's error scaled by `course_scale` (1: the design's gains).
fn fly_lateral_over_the_ground(
    g: &GainSet,
    mode: impl Fn(f64) -> RollMode,
    secs: f64,
    vg: f64,
    course_scale: f32,
) -> (Vec<f64>, Vec<[f64; 3]>) {
    let g = no_trim(*g);
    let mut lat = Lateral::new(&g.lateral, g.transfer_tc);
    lat.set_course_scale(course_scale);
    let plant = |x: &[f64; 3], da: f64| {
        let [p, phi, _] = roll_plant(x, da);
        [p, phi, G0 / vg * x[1].tan()]
    };
    let mut x = [0.0f64; 3];
    let (mut ts, mut xs) = (Vec::new(), Vec::new());
    let n = (secs / DT as f64) as usize;
    for k in 0..n {
        let t = k as f64 * DT as f64;
        let m = Measurements {
            roll: x[1] as f32,
            roll_rate: x[0] as f32,
            course: x[2] as f32,
            ..Measurements::level(VA as f32, 100.0)
        };
        let o = lat.step(&m, mode(t), YawMode::Off, DT);
        rk4(&mut x, o.aileron as f64, plant);
        ts.push(t + DT as f64);
        xs.push(x);
    }
    (ts, xs)
}

/// Engaged wings level for 1 s, then a 10 deg roll command.
fn roll_step(g: &GainSet) -> StepInfo {
    let cmd = |t: f64| RollMode::Roll(if t < 1.0 { 0.0 } else { (10.0 * D) as f32 });
    // 30 s: the slow tail of the PI zero at ki/kp (see `pitch_step`).
    let (t, x) = fly_lateral(g, cmd, 31.0);
    let phi: Vec<f64> = x.iter().map(|x| x[1]).collect();
    step_after(&t, &phi, 1.0, 0.0, 10.0 * D)
}

/// Thesis requirement for the inner loops: rise time < 1 s, overshoot < 5 %. On the first-order
/// roll model the designed PD part alone gives wn = sqrt(156.5 * 1.1216) = 13.2 rad/s, zeta =
/// (16.09 + 156.5 * 0.0618) / (2 wn) = 0.97, i.e. a 10-90 % rise time near 0.25 s.
#[test]
fn designed_roll_loop_meets_thesis_requirements() {
    for (name, g) in [("designed", DESIGNED), ("designed_t310", DESIGNED_T310)] {
        let s = roll_step(&g);
        std::println!("{name} roll 10 deg: {s:?}");
        assert!(s.rise_10_90 < 1.0, "{name}: {s:?}");
        assert!(
            s.rise_10_90 > 0.15 && s.rise_10_90 < 0.4,
            "{name}: against the PD prediction {s:?}"
        );
        assert!(s.overshoot < 0.05, "{name}: {s:?}");
        assert!(s.final_error < 0.01, "{name}: {s:?}");
    }
}

/// Thesis claim (chapter 4): the designed roll loop responds faster than Minnesota's.
#[test]
fn designed_roll_is_faster_than_minnesota() {
    let d = roll_step(&DESIGNED);
    let m = roll_step(&MINNESOTA);
    std::println!("minnesota roll 10 deg: {m:?}");
    assert!(
        d.rise_10_90 < m.rise_10_90,
        "designed {d:?} minnesota {m:?}"
    );
}

/// Course hold over the roll loop. With the roll loop as unity gain (successive loop closure),
/// chi / chi_c = (g/Va)(kp s + ki) / (s^2 + (g/Va) kp s + (g/Va) ki); for the designed kp = 4.05,
/// ki = 0.01 that is nearly first order with tau = Va / (g kp) = 0.43 s (the slow pole at
/// -0.0025 is almost cancelled by the zero at -ki/kp). Minnesota's kp = 1.2 gives tau = 1.44 s.
/// A 5 deg step keeps the roll command below its 45 deg limit.
#[test]
fn course_hold_follows_successive_loop_closure_prediction() {
    let tau = |g: &GainSet| VA / (G0 * g.lateral.course_kp as f64);
    let mut t63 = [0.0; 2];
    for (i, g) in [DESIGNED, MINNESOTA].iter().enumerate() {
        let cmd = |t: f64| RollMode::Course(if t < 1.0 { 0.0 } else { (5.0 * D) as f32 });
        let (t, x) = fly_lateral(g, cmd, 16.0);
        let chi: Vec<f64> = x.iter().map(|x| x[2]).collect();
        let s = step_after(&t, &chi, 1.0, 0.0, 5.0 * D);
        std::println!(
            "course 5 deg, kp {}: {s:?} (tau {:.3})",
            g.lateral.course_kp,
            tau(g)
        );
        // The inner roll loop adds a lag of roughly its own time constant (~0.15 s); an inner
        // loop that overshoots (Minnesota's roll, ~9 %) can instead make the response a few per
        // cent faster than the unity-inner-loop prediction.
        assert!(s.t_63 > 0.9 * tau(g) && s.t_63 < tau(g) + 0.25, "{s:?}");
        assert!(s.overshoot < 0.05, "{s:?}");
        assert!(s.final_error < 0.01, "{s:?}");
        t63[i] = s.t_63;
    }
    assert!(
        t63[0] < t63[1],
        "designed heading faster than Minnesota (thesis claim)"
    );
    // Across +-180 deg: from 175 deg to -175 deg is a 10 deg right turn, not a 350 deg left one.
    let g = no_trim(DESIGNED);
    let mut lat = Lateral::new(&g.lateral, g.transfer_tc);
    let mut x = [0.0, 0.0, 175.0 * D];
    let mut min_roll = 0.0f64;
    for k in 0..600 {
        let m = Measurements {
            roll: x[1] as f32,
            roll_rate: x[0] as f32,
            course: crate::math::wrap_pi(x[2]) as f32,
            ..Measurements::level(VA as f32, 100.0)
        };
        let chi_c = if k < 50 { 175.0 * D } else { -175.0 * D };
        let o = lat.step(&m, RollMode::Course(chi_c as f32), YawMode::Off, DT);
        rk4(&mut x, o.aileron as f64, roll_plant);
        min_roll = min_roll.min(x[1]);
    }
    assert!(
        (crate::math::wrap_pi(x[2]) + 175.0 * D).abs() < 0.2 * D,
        "{}",
        x[2] / D
    );
    assert!(min_roll > -0.5 * D, "never banked left");
}

/// A 5 deg course step at `vg` m/s over the ground, the course loop's error scaled by
/// `course` (1: the design's gains).
fn course_step_over_the_ground(vg: f64, course: f32) -> StepInfo {
    let cmd = |t: f64| RollMode::Course(if t < 1.0 { 0.0 } else { (5.0 * D) as f32 });
    let (t, x) = fly_lateral_over_the_ground(&DESIGNED, cmd, 16.0, vg, course);
    let chi: Vec<f64> = x.iter().map(|x| x[2]).collect();
    step_after(&t, &chi, 1.0, 0.0, 5.0 * D)
}

/// At 4 m/s over the ground (17 m/s of airspeed into 13 m/s of wind) the designed course loop
/// crosses over at `g kp / Vg` = 9.9 rad/s, above the roll loop's own bandwidth, and rings;
/// scaled by `Vg / Va` ([`super::scaling::course_scale`]) it answers as designed at 17 m/s
/// (`tau = Va / (g kp)`, 0.43 s, as `course_hold_follows_successive_loop_closure_prediction`).
#[test]
fn into_a_headwind_the_scaled_course_loop_answers_as_designed_and_the_unscaled_one_rings() {
    let vg = 4.0;
    let tau = VA / (G0 * DESIGNED.lateral.course_kp as f64);
    let scaled =
        course_step_over_the_ground(vg, super::scaling::course_scale(vg as f32, VA as f32));
    let unscaled = course_step_over_the_ground(vg, 1.0);
    std::println!("course 5 deg at Vg {vg}: scaled {scaled:?}, unscaled {unscaled:?}");
    assert!(
        scaled.t_63 > 0.9 * tau && scaled.t_63 < tau + 0.25,
        "{scaled:?}"
    );
    assert!(scaled.overshoot < 0.05, "{scaled:?}");
    assert!(unscaled.overshoot > 0.15, "{unscaled:?}");
}

/// Throttle trim at trim I (Table 2.3).
const THR_TRIM: f64 = 0.569;
/// Acceleration per unit throttle, m/s^2, from Table 2.3: trim II needs 0.721 - 0.569 more
/// throttle than trim I to add m g sin(5 deg) of thrust, so X_dt = g sin(5 deg) / 0.152.
const X_DT: f64 = 5.62;

/// Short period: q/de = (-133.7 s - 990.7) / (s^2 + 23.37 s + 235.9) (eq. 27) in controllable
/// canonical form, theta = integral of q, h' = Va theta (eq. 28), and the airspeed deviation
/// from the u row of A_lon (u' = -0.5944 u - 9.791 theta, w and q terms dropped) plus the
/// throttle. States (x1, x2, theta, h, du); inputs (elevator, throttle).
fn lon_plant(x: &[f64; 5], u: (f64, f64)) -> [f64; 5] {
    let q = -990.7 * x[0] - 133.7 * x[1];
    [
        x[1],
        -235.9 * x[0] - 23.37 * x[1] + u.0,
        q,
        VA * x[2],
        -0.5944 * x[4] - 9.791 * x[2] + X_DT * (u.1 - THR_TRIM),
    ]
}

fn pitch_q(x: &[f64; 5]) -> f64 {
    -990.7 * x[0] - 133.7 * x[1]
}

fn rk4_lon(x: &mut [f64; 5], u: (f64, f64)) {
    let h = DT as f64 / SUB as f64;
    for _ in 0..SUB {
        let add = |a: &[f64; 5], k: &[f64; 5], s: f64| {
            let mut r = *a;
            for i in 0..5 {
                r[i] += s * k[i];
            }
            r
        };
        let k1 = lon_plant(x, u);
        let k2 = lon_plant(&add(x, &k1, h / 2.0), u);
        let k3 = lon_plant(&add(x, &k2, h / 2.0), u);
        let k4 = lon_plant(&add(x, &k3, h), u);
        for i in 0..5 {
            x[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
        }
    }
}

struct LonRun {
    t: Vec<f64>,
    x: Vec<[f64; 5]>,
    throttle: Vec<f64>,
    regimes: Vec<Option<super::longitudinal::Regime>>,
}

/// Flies the longitudinal model from (theta0, h0) on trim airspeed. Elevator trim is zeroed
/// (deviation model); the throttle trim stays, the model subtracts it.
fn fly_longitudinal(
    g: &GainSet,
    mode: impl Fn(f64) -> LonMode,
    theta0: f64,
    h0: f64,
    secs: f64,
) -> LonRun {
    let mut g = no_trim(*g);
    g.longitudinal.trim_throttle = THR_TRIM as f32;
    let mut ap = Autopilot::new(&g).unwrap();
    let mut x = [0.0, 0.0, theta0, h0, 0.0];
    let mut run = LonRun {
        t: Vec::new(),
        x: Vec::new(),
        throttle: Vec::new(),
        regimes: Vec::new(),
    };
    for k in 0..(secs / DT as f64) as usize {
        let t = k as f64 * DT as f64;
        let m = Measurements {
            pitch: x[2] as f32,
            pitch_rate: pitch_q(&x) as f32,
            altitude: x[3] as f32,
            airspeed: (VA + x[4]) as f32,
            ..Measurements::default()
        };
        let c = Commands {
            lon: mode(t),
            ..Commands::OFF
        };
        let o = ap.step(&m, &c, DT);
        rk4_lon(
            &mut x,
            (o.surfaces.elevator as f64, o.surfaces.throttle as f64),
        );
        if run.regimes.last() != Some(&o.status.regime) {
            run.regimes.push(o.status.regime);
        }
        run.t.push(t + DT as f64);
        run.x.push(x);
        run.throttle.push(o.surfaces.throttle as f64);
    }
    run
}

/// Engaged level for 1 s, then a 5 deg pitch command.
fn pitch_step(g: &GainSet) -> StepInfo {
    let mode = |t: f64| LonMode::Pitch {
        pitch: if t < 1.0 { 0.0 } else { (5.0 * D) as f32 },
        throttle: THR_TRIM as f32,
    };
    // 30 s: the PI zero at ki/kp = 0.1 rad/s leaves a slow tail (the integrator's charge from
    // the transient bleeds off with a ~10 s time constant).
    let r = fly_longitudinal(g, mode, 0.0, 100.0, 31.0);
    let theta: Vec<f64> = r.x.iter().map(|x| x[2]).collect();
    step_after(&r.t, &theta, 1.0, 0.0, 5.0 * D)
}

/// Thesis requirement for pitch attitude: rise time < 1 s, overshoot up to 7 %.
#[test]
fn designed_pitch_loop_meets_thesis_requirements() {
    let s = pitch_step(&DESIGNED);
    std::println!("designed pitch 5 deg: {s:?}");
    assert!(s.rise_10_90 < 1.0, "{s:?}");
    assert!(s.overshoot <= 0.07, "{s:?}");
    assert!(s.final_error < 0.01, "{s:?}");
}

/// Thesis claim: the designed pitch loop overshoots less than Minnesota's.
#[test]
fn designed_pitch_overshoots_less_than_minnesota() {
    let d = pitch_step(&DESIGNED);
    let m = pitch_step(&MINNESOTA);
    std::println!("minnesota pitch 5 deg: {m:?}");
    assert!(d.overshoot <= m.overshoot, "designed {d:?} minnesota {m:?}");
}

/// The altitude loop of successive loop closure: pitch loop as unity gain, h' = Va theta_c,
/// theta_c = kp (h_c - h_f), h_f the 2 rad/s low-pass of h. Closed loop
/// Va kp (s + 2) / (s^2 + 2 s + 2 Va kp): wn = 1.43 rad/s, zeta = 0.70 for kp = 0.06, but the
/// zero at -2 (the filter sits in the feedback path only) adds overshoot. Integrated here (RK4,
/// f64) for the reference figures.
fn altitude_reduced_model(kp: f64) -> StepInfo {
    let (mut h, mut hf) = (0.0f64, 0.0f64);
    let dt = 0.001;
    let (mut t, mut y) = (Vec::new(), Vec::new());
    let f = |h: f64, hf: f64| (VA * kp * (1.0 - hf), 2.0 * (h - hf));
    for k in 0..40_000 {
        let (a1, b1) = f(h, hf);
        let (a2, b2) = f(h + dt / 2.0 * a1, hf + dt / 2.0 * b1);
        let (a3, b3) = f(h + dt / 2.0 * a2, hf + dt / 2.0 * b2);
        let (a4, b4) = f(h + dt * a3, hf + dt * b3);
        h += dt / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4);
        hf += dt / 6.0 * (b1 + 2.0 * b2 + 2.0 * b3 + b4);
        t.push((k + 1) as f64 * dt);
        y.push(h);
    }
    step_info(&t, &y, 1.0)
}

fn altitude_step(alt_kp: f32) -> StepInfo {
    // Throttle fixed at trim (pitch by altitude only): the airspeed-hold loop is a separate test.
    let mut g = DESIGNED;
    g.longitudinal.alt_kp = alt_kp;
    g.longitudinal.alt_band = 500.0;
    g.longitudinal.aspd_thr_kp = 0.0;
    g.longitudinal.aspd_thr_ki = 0.0;
    let mode = |t: f64| LonMode::Altitude {
        altitude: if t < 1.0 { 100.0 } else { 102.0 },
        airspeed: VA as f32,
    };
    let r = fly_longitudinal(&g, mode, 0.0, 100.0, 41.0);
    let h: Vec<f64> = r.x.iter().map(|x| x[3]).collect();
    step_after(&r.t, &h, 1.0, 100.0, 2.0)
}

/// Altitude hold by commanded pitch inside the band, against [`altitude_reduced_model`], with
/// the altitude gain a fifth of the designed one (0.012 rad/m) so that the pitch loop is well
/// over 5 times faster, as successive loop closure assumes: the implementation then matches the
/// reduced model.
#[test]
fn altitude_hold_follows_successive_loop_closure_prediction() {
    let s = altitude_step(0.012);
    let pred = altitude_reduced_model(0.012);
    std::println!("altitude 2 m, kp 0.012: {s:?}\n  reduced model: {pred:?}");
    // Time to 63 %, within 5 %: the pitch loop's remaining lag (t63 ~0.3 s) against 4.4 s. (The
    // 10-90 % rise of this overdamped loop is set by its slow pole at -0.23 rad/s and moves
    // by 10 % with any small change of the loop; the 63 % time does not.)
    assert!((s.t_63 / pred.t_63 - 1.0).abs() < 0.05, "{s:?} vs {pred:?}");
    assert!(
        (s.overshoot - pred.overshoot).abs() < 0.02,
        "{s:?} vs {pred:?}"
    );
    assert!(s.final_error < 0.005, "{s:?}");
}

/// With the designed altitude gain (0.06 rad/m, Table 3.7) the altitude loop (wn 1.43 rad/s) is
/// only 3 to 5 times slower than the pitch loop, and the 2 rad/s filter sits in its feedback
/// path: on this model it overshoots a 2 m step by far more than the reduced model's 7 % and the
/// thesis's 5 % outer-loop requirement. This records that finding; the nonlinear-plant tests
/// elsewhere decide how the set flies.
#[test]
fn designed_altitude_gain_overshoots_beyond_the_requirement() {
    let s = altitude_step(DESIGNED.longitudinal.alt_kp);
    let pred = altitude_reduced_model(DESIGNED.longitudinal.alt_kp as f64);
    std::println!("altitude 2 m, kp 0.06: {s:?}\n  reduced model: {pred:?}");
    assert!((pred.overshoot - 0.072).abs() < 0.005, "{pred:?}");
    assert!(s.overshoot > 0.15, "{s:?}");
    assert!(s.final_error < 0.005, "{s:?}");
    // Appendix E's 0.021 (and Minnesota's 0.023) stays within the requirement.
    let e = altitude_step(super::gains::DESIGNED_APPE.longitudinal.alt_kp);
    std::println!("altitude 2 m, kp 0.021: {e:?}");
    assert!(e.overshoot < 0.05, "{e:?}");
}

/// Climb from 100 m to a 130 m setpoint, on the model with airspeed: climb regime (full
/// throttle, airspeed by pitch) until inside the 10 m band, then altitude hold (altitude by
/// pitch, airspeed by throttle). Run for every named set whose throttle loop is stable on this
/// model (see `table_3_9_throttle_gains_are_unstable_behind_the_feedback_filter`).
#[test]
fn climb_then_hold_sequence() {
    use super::longitudinal::Regime::*;
    for (name, g) in [
        ("designed_appe", super::gains::DESIGNED_APPE),
        ("minnesota", MINNESOTA),
    ] {
        let mode = |_| LonMode::Altitude {
            altitude: 130.0,
            airspeed: VA as f32,
        };
        let r = fly_longitudinal(&g, mode, 0.0, 100.0, 90.0);
        let last = r.x.last().unwrap();
        let max_h = r.x.iter().map(|x| x[3]).fold(0.0, f64::max);
        let t_band = r.t[r.x.iter().position(|x| x[3] > 120.0).unwrap()];
        std::println!(
            "{name}: regimes {:?}, h {:.2}, dV {:.3}, max h {max_h:.2}, 120 m at {t_band:.1} s",
            r.regimes,
            last[3],
            last[4]
        );
        assert_eq!(r.regimes, [Some(Climb), Some(AltitudeHold)], "{name}");
        assert!((last[3] - 130.0).abs() < 0.2, "{name}: h {}", last[3]);
        assert!(last[4].abs() < 0.2, "{name}: airspeed error {}", last[4]);
        assert!(max_h < 130.0 + 0.05 * 30.0, "{name}: overshoot {max_h}");
        // Full throttle in the climb, between the limits afterwards.
        assert_eq!(r.throttle[0], 1.0);
    }
}

/// Table 3.9's airspeed-by-throttle gains (kp 1, ki 24) behind the thesis's own 2 rad/s feedback
/// filter: with the speed model above the loop is (s + 0.5944)(s + 2) s + 2 X_dt (kp s + ki) = 0,
/// s^3 + 2.594 s^2 + (1.189 + 11.24) s + 269.8, which fails the Routh test (2.594 * 12.43 = 32.2
/// < 269.8). Appendix E's 0.091 / 0.02 pass it. The simulated airspeed therefore does not
/// settle with Table 3.9's gains and does with Appendix E's.
#[test]
fn table_3_9_throttle_gains_are_unstable_behind_the_feedback_filter() {
    let routh_ok = |kp: f64, ki: f64| {
        let (a2, a1, a0) = (
            0.5944 + 2.0,
            2.0 * 0.5944 + 2.0 * X_DT * kp,
            2.0 * X_DT * ki,
        );
        a2 > 0.0 && a1 > 0.0 && a0 > 0.0 && a2 * a1 > a0
    };
    assert!(!routh_ok(1.0, 24.0));
    assert!(routh_ok(0.091, 0.02));
    assert!(routh_ok(0.15, 0.04));
    let spread = |g: &GainSet| {
        // Pitch held level, airspeed by throttle from 1 m/s below the setpoint.
        let mode = |_| LonMode::Altitude {
            altitude: 100.0,
            airspeed: (VA + 1.0) as f32,
        };
        let r = fly_longitudinal(g, mode, 0.0, 100.0, 60.0);
        let tail = &r.x[r.x.len() - 500..];
        let lo = tail.iter().map(|x| x[4]).fold(f64::MAX, f64::min);
        let hi = tail.iter().map(|x| x[4]).fold(f64::MIN, f64::max);
        std::println!("airspeed over the last 10 s: {lo:.3} .. {hi:.3}");
        (lo, hi)
    };
    let (lo, hi) = spread(&DESIGNED);
    assert!(hi - lo > 0.5, "Table 3.9 gains settled: {lo} .. {hi}");
    let (lo, hi) = spread(&super::gains::DESIGNED_APPE);
    assert!(
        hi - lo < 0.05 && (lo - 1.0).abs() < 0.1,
        "Appendix E gains: {lo} .. {hi}"
    );
}

/// Lateral model for the yaw damper: r/dr (eq. 26) in controllable canonical form. Its dutch
/// roll is -1.84 +- 5.28i (zeta 0.329, Table 2.5); the damper's purpose is to raise that damping.
fn yaw_plant(x: &[f64; 4], dr: f64) -> [f64; 4] {
    [
        x[1],
        x[2],
        x[3],
        -6.89 * x[0] - 502.2 * x[1] - 90.49 * x[2] - 19.74 * x[3] + dr,
    ]
}

fn yaw_r(x: &[f64; 4]) -> f64 {
    -2351.0 * x[0] - 1228.0 * x[1] - 1385.0 * x[2] - 82.04 * x[3]
}

/// Total variation of r over 1..8 s after a rudder pulse: the dutch-roll oscillation dominates it
/// (the spiral and roll modes contribute slow, monotone tails).
fn dutch_roll_activity(damper: bool) -> f64 {
    let g = no_trim(DESIGNED);
    let mut lat = Lateral::new(&g.lateral, g.transfer_tc);
    let mut x = [0.0f64; 4];
    let mut r = Vec::new();
    for k in 0..400 {
        let mode = if damper {
            YawMode::Damper
        } else {
            YawMode::Off
        };
        let m = Measurements {
            yaw_rate: yaw_r(&x) as f32,
            ..Measurements::level(VA as f32, 100.0)
        };
        let o = lat.step(&m, RollMode::Off, mode, DT);
        let pulse = if (10..15).contains(&k) { 0.02 } else { 0.0 };
        rk4(&mut x, o.rudder as f64 + pulse, yaw_plant);
        r.push(yaw_r(&x));
    }
    r[50..].windows(2).map(|w| (w[1] - w[0]).abs()).sum()
}

/// Damping ratio of the least damped complex pole pair of the continuous yaw loop: r/dr with
/// dr = k s/(s+a) r closed around it (k = 0 for the open loop).
fn dutch_roll_zeta(k: f64, a: f64) -> f64 {
    use nalgebra::{Matrix5, RowVector4};
    let c = RowVector4::new(-2351.0, -1228.0, -1385.0, -82.04);
    // x' = A x + B dr, w' = -a w + r, dr = k (r - a w).
    let mut m = Matrix5::<f64>::zeros();
    m[(0, 1)] = 1.0;
    m[(1, 2)] = 1.0;
    m[(2, 3)] = 1.0;
    let den = [-6.89, -502.2, -90.49, -19.74];
    for j in 0..4 {
        m[(3, j)] = den[j] + k * c[j];
        m[(4, j)] = c[j];
    }
    m[(3, 4)] = -k * a;
    m[(4, 4)] = -a;
    m.complex_eigenvalues()
        .iter()
        .filter(|l| l.im.abs() > 1e-6)
        .map(|l| -l.re / l.re.hypot(l.im))
        .fold(f64::MAX, f64::min)
}

/// The yaw damper (0.065 on r through s/(s+2)) exists to damp the dutch roll (-1.84 +- 5.28i,
/// zeta 0.329, Table 2.5). Checked twice: the continuous closed loop's poles (the gain's sign and
/// size), and the discrete stage flying the r/dr model (the implementation).
#[test]
fn yaw_damper_raises_dutch_roll_damping() {
    let open = dutch_roll_zeta(0.0, 2.0);
    let closed = dutch_roll_zeta(0.065, 2.0);
    let wrong_sign = dutch_roll_zeta(-0.065, 2.0);
    std::println!(
        "dutch roll zeta: open {open:.3}, damped {closed:.3}, wrong sign {wrong_sign:.3}"
    );
    assert!(
        (open - 0.329).abs() < 0.005,
        "model reproduces Table 2.5: {open}"
    );
    assert!(closed > open + 0.1, "{closed}");
    assert!(wrong_sign < open);
    let (a_open, a_closed) = (dutch_roll_activity(false), dutch_roll_activity(true));
    std::println!("r total variation after a rudder pulse: open {a_open:.4}, damped {a_closed:.4}");
    assert!(a_closed < 0.6 * a_open, "open {a_open} damped {a_closed}");
}

/// Sideslip on the thesis's own design model for it (Appendix C, Beard and McLain):
/// beta' = -a_b1 beta + a_b2 dr, a_b1 = -rho Va S CY_beta / (2 m), a_b2 = rho Va S CY_dr / (2 m),
/// with the UMN data (aircraft/ultrastick25e.toml: CY_beta = -0.4889, CY_dr = 0.1913, S = 0.3097
/// m^2, m = 1.959 kg, rho = 1.2133 kg/m^3 at 100 m). The closed loop is s^2 + (a_b1 + a_b2 kp) s +
/// a_b2 ki: with the designed gains (3, 0.8) both coefficients are positive (stable); with Table
/// 3.5's printed signs (-3, -0.8) they are negative (unstable). That is why the sideslip gains
/// are stored positive (see `gains`).
#[test]
fn sideslip_hold_sign_on_the_design_model() {
    let k = 1.2133 * VA * 0.3097 / (2.0 * 1.959);
    let (a1, a2) = (-k * -0.4889, k * 0.1913);
    let fly = |kp: f32, ki: f32| {
        let mut g = no_trim(DESIGNED);
        g.lateral.slip_kp = kp;
        g.lateral.slip_ki = ki;
        g.lateral.yaw_damper_k = 0.0;
        // Built directly, bypassing validation, so the printed signs can be flown too.
        let mut lat = Lateral::new(&g.lateral, g.transfer_tc);
        let mut x = [2.0 * D];
        let mut max = 0.0f64;
        for _ in 0..(30.0 / DT) as usize {
            let m = Measurements {
                sideslip: x[0] as f32,
                ..Measurements::level(VA as f32, 100.0)
            };
            let o = lat.step(&m, RollMode::Off, YawMode::Sideslip(0.0), DT);
            rk4(&mut x, o.rudder as f64, |x: &[f64; 1], dr| {
                [-a1 * x[0] + a2 * dr]
            });
            max = max.max(x[0].abs());
        }
        (x[0], max)
    };
    let (end, _) = fly(3.0, 0.8);
    std::println!(
        "sideslip from 2 deg, designed: {:.4} deg after 30 s",
        end / D
    );
    assert!(end.abs() < 0.02 * D, "{}", end / D);
    // With the printed signs the sideslip runs away until the rudder sits on its 25 deg stop,
    // which holds beta at a_b2 / a_b1 * 25 deg = 9.8 deg.
    let (end, max) = fly(-3.0, -0.8);
    let stop = a2 / a1 * 25.0 * D;
    assert!(max > 4.0 * 2.0 * D, "printed signs: max {}", max / D);
    assert!(
        (end.abs() - stop).abs() < 0.1 * D,
        "{} vs {}",
        end / D,
        stop / D
    );
}
