//! One loop of the design: the transfer functions it is built from, and what the linear model
//! predicts of it once closed (poles, step figures, margins with servo and delay).

use crate::analysis::lti::{margins, Margins};
use crate::analysis::metrics::step_metrics;
use crate::analysis::transfer::{poly_add, poly_mul, poly_roots, TransferFunction};
use common::tuning::design::Loop;
use nalgebra::Complex;
use serde::Serialize;

/// One designed loop and what the linear model predicts of it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LoopDesign {
    /// Loop name.
    pub name: String,
    /// The on-board design's loop it is (`None`: the sideslip loop, designed on the host
    /// only).
    #[serde(skip)]
    pub onboard: Option<Loop>,
    /// Gains as (parameter, ours, thesis "designed").
    pub gains: Vec<(String, f64, f64)>,
    /// Natural frequency the design aims at, rad/s.
    pub wn_radps: f64,
    /// Closed-loop poles of the reduced model with the inner loops as designed.
    pub poles: Vec<[f64; 2]>,
    /// Predicted 10-90 % rise time, s.
    pub rise_time_s: Option<f64>,
    /// Predicted overshoot, %.
    pub overshoot_pct: f64,
    /// Predicted 2 % settling time, s.
    pub settling_time_s: Option<f64>,
    /// Margins with servo, delay (and feedback filter where the loop has one).
    pub margins: Margins,
}

/// A loop transfer `L(jw)` as a function of `w`, rad/s: what the margins are read from.
pub(super) type Freq = Box<dyn Fn(f64) -> Complex<f64>>;

/// `num / den`.
pub(super) fn tf(num: &[f64], den: &[f64]) -> TransferFunction {
    TransferFunction::new(num, den)
}

/// A gain row of a loop: parameter, computed value, the thesis's designed value.
pub(super) fn gain(name: &str, computed: f64, thesis: f32) -> (String, f64, f64) {
    (name.into(), computed, f64::from(thesis))
}

/// The loop transfer `L(jw)` of an inner loop with the servo and delay that act on it.
pub(super) fn with_actuation(
    l: &TransferFunction,
    actuation: impl Fn(f64) -> Complex<f64> + 'static,
) -> Freq {
    let l = l.clone();
    Box::new(move |w| l.eval(w) * actuation(w))
}

/// The loop transfer of an outer loop: its controller, the inner closed loop (as flown, with
/// servo and delay), the kinematics from the inner loop's output, and the feedback path.
pub(super) fn through_inner(
    controller: &TransferFunction,
    inner: impl Fn(f64) -> Complex<f64> + 'static,
    kinematics: &TransferFunction,
    feedback: &TransferFunction,
) -> Freq {
    let (c, k, f) = (controller.clone(), kinematics.clone(), feedback.clone());
    Box::new(move |w| c.eval(w) * inner(w) * k.eval(w) * f.eval(w))
}

/// `forward / (1 + forward * feedback)`.
pub(super) fn closed(forward: &TransferFunction, feedback: &TransferFunction) -> TransferFunction {
    TransferFunction::new(
        &poly_mul(&forward.num, &feedback.den),
        &poly_add(
            &poly_mul(&forward.den, &feedback.den),
            &poly_mul(&forward.num, &feedback.num),
        ),
    )
}

/// A designed loop: its closed-loop poles and step figures on `closed_loop`, its margins on
/// `loop_gain`.
pub(super) fn predict(
    name: &str,
    onboard: Option<Loop>,
    gains: Vec<(String, f64, f64)>,
    wn: f64,
    closed_loop: &TransferFunction,
    loop_gain: Freq,
    t_end: f64,
) -> LoopDesign {
    let dt = (t_end / 20_000.0).min(1e-3);
    let (t, y) = closed_loop.step_response(t_end, dt);
    let m = step_metrics(&t, &y, 0.0, 1.0, 0.0, t_end + dt);
    LoopDesign {
        name: name.into(),
        onboard,
        gains,
        wn_radps: wn,
        poles: closed_loop.poles().iter().map(|p| [p.re, p.im]).collect(),
        rise_time_s: m.rise_time_s,
        overshoot_pct: m.overshoot_pct,
        settling_time_s: m.settling_time_s,
        margins: margins(loop_gain, 1e-3, 1e3),
    }
}

/// Cancels pole-zero pairs that coincide (the pitch loop's closed form repeats factors).
pub(super) fn reduce(t: &TransferFunction) -> TransferFunction {
    let mut zeros = poly_roots(&t.num);
    let mut poles = poly_roots(&t.den);
    let gain = t.num.first().copied().unwrap_or(0.0);
    let mut i = 0;
    while i < zeros.len() {
        let scale = zeros[i].norm().max(1.0);
        if let Some(j) = poles
            .iter()
            .position(|p| (p - zeros[i]).norm() < 1e-6 * scale)
        {
            poles.remove(j);
            zeros.remove(i);
        } else {
            i += 1;
        }
    }
    let expand = |roots: &[Complex<f64>]| {
        roots
            .iter()
            .fold(vec![Complex::new(1.0, 0.0)], |acc, r| {
                let mut out = vec![Complex::new(0.0, 0.0); acc.len() + 1];
                for (k, a) in acc.iter().enumerate() {
                    out[k] += a;
                    out[k + 1] -= a * r;
                }
                out
            })
            .iter()
            .map(|c| c.re)
            .collect::<Vec<f64>>()
    };
    let num = poly_mul(&[gain], &expand(&zeros));
    TransferFunction::new(&num, &expand(&poles))
}
