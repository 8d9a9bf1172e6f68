//! Every loop of the autopilot judged on the full linear model, as it is flown: sampled at the
//! autopilot's rate, the surfaces through their servos and held over each period, the
//! measurements two periods late, the controllers in the discrete form the flight code runs
//! (backward-Euler integrators, the one-period feedback low-pass, the yaw damper's washout),
//! and all the other loops closed.
//!
//! The reduced models of the design ([`super::design`]) leave out the servo, the delay, the
//! dutch roll, the phugoid and the yaw damper; this model has them all, so its margins and
//! step figures are the ones the flown loops should show (the estimator is taken as exact).
//!
//! A loop's margins are read with the loop broken at its controller's output and every other
//! loop closed, `L = -(M_ii + M_io (I - M_oo)^-1 M_oi)` where `M` maps the controller outputs
//! round the loop back to themselves. Step figures come from the closed loop's frequency
//! response sampled half a bin off the unit circle's integer bins (so `z = 1`, where the
//! heading and height integrate, is never evaluated) and transformed back.

pub mod plant;

use super::linearize::linearize;
use super::lti::{margins, Margins};
use super::metrics::step_metrics;
use super::trim::{trim_near, trim_with, TrimTarget};
use crate::aircraft::Aircraft;
use crate::plant::params::ModelParams;
use common::control::gains::GainSet;
use common::control::scaling::surface_scale;
use nalgebra::{Complex, DMatrix};
use plant::{cmd, out, SampledPlant};
use rustfft::FftPlanner;
use serde::Serialize;

/// The controller outputs round the loop: the commands, then the two attitude commands the
/// outer loops give the inner ones.
mod ch {
    pub use super::plant::cmd::{AILERON, ELEVATOR, RUDDER, THROTTLE};
    /// Commanded pitch, rad.
    pub const PITCH_CMD: usize = 4;
    /// Commanded roll, rad.
    pub const ROLL_CMD: usize = 5;
    /// How many.
    pub const N: usize = 6;
}

/// What the longitudinal loops hold.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum LonLaw {
    /// A commanded pitch, the throttle fixed.
    Pitch,
    /// Altitude by pitch and airspeed by throttle (the altitude-hold regime).
    AltitudeHold,
    /// Airspeed by pitch, the throttle fixed (the climb and descent regimes).
    AirspeedPitch,
    /// The total energy control: throttle on the energy rate, pitch command on its balance,
    /// from the height and airspeed through the control's rate estimators.
    Tecs,
}

/// What the ailerons hold.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum LatLaw {
    /// A commanded roll.
    Roll,
    /// A commanded course through the roll loop.
    Course,
    /// The course loop fed the heading instead, as the thesis's tests fly it (course and
    /// heading differ by the sideslip, which the rudder's yaw moment moves quickly).
    Heading,
}

/// What the rudder does.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum YawLaw {
    /// The washed-out yaw damper alone.
    Damper,
    /// Sideslip hold plus the yaw damper.
    Sideslip,
}

/// The set of loops engaged.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct Arrangement {
    /// Longitudinal.
    pub lon: LonLaw,
    /// Lateral.
    pub lat: LatLaw,
    /// Directional.
    pub yaw: YawLaw,
}

/// References the arrangement can be given, in this order.
pub mod reference {
    /// Pitch, rad.
    pub const PITCH: usize = 0;
    /// Height, m.
    pub const HEIGHT: usize = 1;
    /// Airspeed, m/s.
    pub const AIRSPEED: usize = 2;
    /// Roll, rad.
    pub const ROLL: usize = 3;
    /// Course, rad.
    pub const COURSE: usize = 4;
    /// Sideslip, rad.
    pub const SIDESLIP: usize = 5;
    /// How many.
    pub const N: usize = 6;
}

/// The loops' discrete transfer functions at one `z`: what the flight code computes.
struct Discrete {
    z: Complex<f64>,
    t: f64,
}

impl Discrete {
    /// `kp + ki T z / (z - 1)`: the integrator adds `ki e T` before the output is formed.
    fn pi(&self, kp: f32, ki: f32) -> Complex<f64> {
        f64::from(kp) + f64::from(ki) * self.t * self.z / (self.z - 1.0)
    }
    /// The feedback low-pass, which hands out its previous state: `(1 - p) / (z - p)`.
    fn low_pass(&self, pole: f32) -> Complex<f64> {
        let p = (-f64::from(pole) * self.t).exp();
        (1.0 - p) / (self.z - p)
    }
    /// The washout `y = p y' + u - u'`: `(z - 1) / (z - p)`.
    fn washout(&self, pole: f32) -> Complex<f64> {
        let p = (-f64::from(pole) * self.t).exp();
        (self.z - 1.0) / (self.z - p)
    }
    /// The value and the rate out of the total energy control's rate estimator per unit of
    /// its input: its Euler step `x- = x + r T`, `x = x- + 2 w T (u - x-)`,
    /// `r += w^2 T (u - x-)`, solved at `z`.
    fn rate_estimator(&self, w: f32) -> (Complex<f64>, Complex<f64>) {
        let (w, t, zi) = (f64::from(w), self.t, 1.0 / self.z);
        let (a, b) = (2.0 * w * t, w * w * t);
        // [1 - (1 - a) / z, -T (1 - a) / z; b / z, 1 - (1 - b T) / z] [x; r] = [a; b]
        let (m11, m12) = (1.0 - (1.0 - a) * zi, -t * (1.0 - a) * zi);
        let (m21, m22) = (b * zi, 1.0 - (1.0 - b * t) * zi);
        let det = m11 * m22 - m12 * m21;
        ((a * m22 - m12 * b) / det, (m11 * b - m21 * a) / det)
    }
}

/// The total energy control about the level trim at `va` m/s, no limit reached: throttle
/// `(g / a_V2 + PI) E_d - PI E` and pitch command `(1 + PI) B_d - PI B` from the height and
/// airspeed (`common::control::longitudinal::tecs`).
fn tecs_controller(g: &GainSet, d: &Discrete, va: f64, ky: &mut CMat, kr: &mut CMat) {
    const G: f64 = common::math::STANDARD_GRAVITY;
    let t = &g.tecs;
    let (x, r) = d.rate_estimator(t.rate_pole);
    let w = f64::from(t.speed_weight);
    let (w_h, w_v) = ((2.0 - w).min(1.0), w.min(1.0));
    let (k_h, k_v) = (f64::from(t.height_k), f64::from(t.speed_k));
    let thr = d.pi(t.thr_kp, t.thr_ki);
    let thr_d = thr + G / f64::from(t.thr_accel);
    let pitch = d.pi(t.pitch_kp, t.pitch_ki);
    let pitch_d = pitch + 1.0;
    // Per unit of height and of airspeed: the demands (through the estimated value) and the
    // rates (through the estimated rate), as flight-path angles.
    let (h_demand, v_demand) = (k_h / va, k_v / G);
    let (h_rate, v_rate) = (r / va, r / G);
    ky[(ch::THROTTLE, out::HEIGHT)] = -thr_d * x * h_demand - thr * h_rate;
    ky[(ch::THROTTLE, out::AIRSPEED)] = -thr_d * x * v_demand - thr * v_rate;
    kr[(ch::THROTTLE, reference::HEIGHT)] = thr_d * h_demand;
    kr[(ch::THROTTLE, reference::AIRSPEED)] = thr_d * v_demand;
    ky[(ch::PITCH_CMD, out::HEIGHT)] = -(pitch_d * x * h_demand + pitch * h_rate) * w_h;
    ky[(ch::PITCH_CMD, out::AIRSPEED)] = (pitch_d * x * v_demand + pitch * v_rate) * w_v;
    kr[(ch::PITCH_CMD, reference::HEIGHT)] = pitch_d * h_demand * w_h;
    kr[(ch::PITCH_CMD, reference::AIRSPEED)] = -pitch_d * v_demand * w_v;
}

type CMat = DMatrix<Complex<f64>>;

/// The controller as three maps into its outputs: from the measurements, from its own outputs
/// (the inner loops take the outer loops' commands) and from the references.
struct Controller {
    ky: DMatrix<Complex<f64>>,
    kc: DMatrix<Complex<f64>>,
    kr: DMatrix<Complex<f64>>,
}

fn controller(g: &GainSet, arr: Arrangement, d: &Discrete, va: f64) -> Controller {
    let zero = Complex::new(0.0, 0.0);
    let mut ky = DMatrix::from_element(ch::N, out::N, zero);
    let mut kc = DMatrix::from_element(ch::N, ch::N, zero);
    let mut kr = DMatrix::from_element(ch::N, reference::N, zero);
    let (lon, lat) = (&g.longitudinal, &g.lateral);
    let one = Complex::new(1.0, 0.0);

    // Pitch: elevator = PI (theta_c - theta) - kd q.
    let pitch = d.pi(lon.pitch_kp, lon.pitch_ki);
    kc[(ch::ELEVATOR, ch::PITCH_CMD)] = pitch;
    ky[(ch::ELEVATOR, out::PITCH)] = -pitch;
    ky[(ch::ELEVATOR, out::PITCH_RATE)] = -Complex::from(f64::from(lon.pitch_rate_kd));
    let filter = d.low_pass(lon.feedback_lpf_pole);
    match arr.lon {
        LonLaw::Pitch => kr[(ch::PITCH_CMD, reference::PITCH)] = one,
        LonLaw::AltitudeHold => {
            let alt = d.pi(lon.alt_kp, lon.alt_ki);
            kr[(ch::PITCH_CMD, reference::HEIGHT)] = alt;
            ky[(ch::PITCH_CMD, out::HEIGHT)] = -alt * filter;
            let thr = d.pi(lon.aspd_thr_kp, lon.aspd_thr_ki);
            kr[(ch::THROTTLE, reference::AIRSPEED)] = thr;
            ky[(ch::THROTTLE, out::AIRSPEED)] = -thr * filter;
        }
        LonLaw::AirspeedPitch => {
            let ap = d.pi(lon.aspd_pitch_kp, lon.aspd_pitch_ki);
            kr[(ch::PITCH_CMD, reference::AIRSPEED)] = ap;
            ky[(ch::PITCH_CMD, out::AIRSPEED)] = -ap * filter;
        }
        LonLaw::Tecs => tecs_controller(g, d, va, &mut ky, &mut kr),
    }

    // Roll: aileron = PI (phi_c - phi) - kd p.
    let roll = d.pi(lat.roll_kp, lat.roll_ki);
    kc[(ch::AILERON, ch::ROLL_CMD)] = roll;
    ky[(ch::AILERON, out::ROLL)] = -roll;
    ky[(ch::AILERON, out::ROLL_RATE)] = -Complex::from(f64::from(lat.roll_rate_kd));
    match arr.lat {
        LatLaw::Roll => kr[(ch::ROLL_CMD, reference::ROLL)] = one,
        LatLaw::Course | LatLaw::Heading => {
            let course = d.pi(lat.course_kp, lat.course_ki);
            let measured = if arr.lat == LatLaw::Course {
                out::COURSE
            } else {
                out::HEADING
            };
            kr[(ch::ROLL_CMD, reference::COURSE)] = course;
            ky[(ch::ROLL_CMD, measured)] = -course;
        }
    }

    // Rudder: yaw damper on the washed-out yaw rate, plus PI on sideslip when held.
    ky[(ch::RUDDER, out::YAW_RATE)] = f64::from(lat.yaw_damper_k) * d.washout(lat.washout_pole);
    if arr.yaw == YawLaw::Sideslip {
        let slip = d.pi(lat.slip_kp, lat.slip_ki);
        kr[(ch::RUDDER, reference::SIDESLIP)] = slip;
        ky[(ch::RUDDER, out::SIDESLIP)] = -slip;
    }
    Controller { ky, kc, kr }
}

/// The whole loop at one frequency.
struct AtFrequency {
    /// Controller outputs round the loop back to themselves.
    m: DMatrix<Complex<f64>>,
    /// References into the controller outputs.
    kr: DMatrix<Complex<f64>>,
    /// The true (undelayed) measurements per controller output.
    g: DMatrix<Complex<f64>>,
}

/// The autopilot on the sampled aircraft: where each loop's figures are read.
#[derive(Clone, Debug)]
pub struct SampledLoops {
    plant: SampledPlant,
    delay_samples: i32,
    /// Airspeed of the trim the plant was linearised at, m/s.
    va: f64,
}

impl SampledLoops {
    /// The loops at `aircraft`'s level trim, its servos sampled every `period_s` with the
    /// measurements `delay_samples` periods late.
    pub fn at_level_trim(
        aircraft: &Aircraft,
        period_s: f64,
        delay_samples: u32,
    ) -> anyhow::Result<Self> {
        Self::at_level_airspeed(
            aircraft,
            TrimTarget::level().va_mps,
            period_s,
            delay_samples,
        )
    }

    /// The loops at `aircraft`'s level trim at `airspeed_mps`, as [`Self::at_level_trim`].
    pub fn at_level_airspeed(
        aircraft: &Aircraft,
        airspeed_mps: f64,
        period_s: f64,
        delay_samples: u32,
    ) -> anyhow::Result<Self> {
        let params = ModelParams::new(aircraft);
        let level = TrimTarget::level();
        let mut trim = trim_with(&params, &level);
        // Continuation from the design trim in steps of at most 1 m/s.
        let steps = (airspeed_mps - level.va_mps).abs().ceil().max(1.0) as usize;
        for k in 1..=steps {
            let va = level.va_mps + (airspeed_mps - level.va_mps) * k as f64 / steps as f64;
            let target = TrimTarget {
                va_mps: va,
                ..level.clone()
            };
            trim = trim_near(&params, &target, &trim);
        }
        if !trim.converged {
            // An aircraft other than the Ultra Stick may not trim at 17 m/s at all: straight
            // at the airspeed asked for.
            trim = trim_with(&params, &level.clone().at_airspeed(airspeed_mps));
        }
        anyhow::ensure!(
            trim.converged,
            "the level trim did not converge (residual {:.3e})",
            trim.residual_norm
        );
        let servo = 2.0 * std::f64::consts::PI * aircraft.actuators.bandwidth_Hz;
        let plant = SampledPlant::new(&linearize(&params, &trim), servo, period_s);
        Ok(Self {
            va: trim.target.va_mps,
            ..Self::new(plant, delay_samples)
        })
    }

    /// The loops on `plant` (linearised at the level trim's airspeed), the measurements
    /// `delay_samples` periods late.
    pub fn new(plant: SampledPlant, delay_samples: u32) -> Self {
        Self {
            plant,
            delay_samples: delay_samples.min(100) as i32,
            va: TrimTarget::level().va_mps,
        }
    }

    fn at(&self, gains: &GainSet, arr: Arrangement, z: Complex<f64>) -> AtFrequency {
        let p = self.plant.response(z);
        let zero = Complex::new(0.0, 0.0);
        let mut g = DMatrix::from_element(out::N, ch::N, zero);
        g.view_mut((0, 0), (out::N, cmd::N)).copy_from(&p);
        let k = controller(
            gains,
            arr,
            &Discrete {
                z,
                t: self.plant.period_s,
            },
            self.va,
        );
        let delay = z.powi(-self.delay_samples);
        let m = &k.ky * &g * delay + &k.kc;
        AtFrequency { m, kr: k.kr, g }
    }

    /// The loop transfer at controller output `channel`, broken there with every other loop
    /// of `arr` closed, at `w` rad/s.
    fn loop_gain(&self, gains: &GainSet, arr: Arrangement, channel: usize, w: f64) -> Complex<f64> {
        let z = Complex::new(0.0, w * self.plant.period_s).exp();
        let m = self.at(gains, arr, z).m;
        let others: Vec<usize> = (0..ch::N).filter(|&j| j != channel).collect();
        let n = others.len();
        let mut i_moo = DMatrix::from_fn(n, n, |a, b| -m[(others[a], others[b])]);
        for a in 0..n {
            i_moo[(a, a)] += 1.0;
        }
        let moi = DMatrix::from_fn(n, 1, |a, _| m[(others[a], channel)]);
        let mio = DMatrix::from_fn(1, n, |_, b| m[(channel, others[b])]);
        let back = match i_moo.lu().solve(&moi) {
            Some(x) => (mio * x)[(0, 0)],
            None => Complex::new(f64::NAN, f64::NAN),
        };
        -(m[(channel, channel)] + back)
    }

    /// Closed-loop poles of `arr` that diverge faster than [`SLOWEST_DIVERGENCE_S`] (0:
    /// stable), by the argument principle on the return difference `det(I - M(z))`, whose
    /// zeros outside a circle are the closed loop's poles there and whose poles there are the
    /// open loop's (the aircraft's unstable modes; the controllers' poles lie inside or at 1).
    /// The circle's radius `exp(T / SLOWEST_DIVERGENCE_S)` puts the integrators at `z = 1`
    /// inside it, and with them the height's drift through the air density (an e-fold in hours
    /// where no loop holds the height), which no loop of the autopilot is there to correct.
    pub fn unstable_poles(&self, gains: &GainSet, arr: Arrangement) -> i64 {
        let r = (self.plant.period_s / SLOWEST_DIVERGENCE_S).exp();
        let open = self.plant.poles().iter().filter(|p| p.norm() > r).count() as i64;
        let f = |theta: f64| {
            let z = Complex::from_polar(r, theta);
            let m = self.at(gains, arr, z).m;
            let mut i_m = -m;
            for a in 0..ch::N {
                i_m[(a, a)] += 1.0;
            }
            i_m.determinant()
        };
        // Angles crowd towards z = 1, where the integrators turn the phase quickly.
        let n = 2000;
        let mut angles: Vec<f64> = (0..=n)
            .map(|k| 1e-9 * (std::f64::consts::PI / 1e-9).powf(k as f64 / n as f64))
            .collect();
        let back: Vec<f64> = angles
            .iter()
            .rev()
            .map(|a| 2.0 * std::f64::consts::PI - a)
            .collect();
        angles.extend(back);
        let mut turn = 0.0;
        let mut prev = f(angles[0]);
        let mut prev_theta = angles[0];
        for &theta in &angles[1..] {
            turn += wrap_arg(&f, prev_theta, prev, theta, 0);
            prev = f(theta);
            prev_theta = theta;
        }
        let winding = (turn / (2.0 * std::f64::consts::PI)).round() as i64;
        // Counter-clockwise round the circle, the winding counts zeros minus poles inside; the
        // outside holds the rest of each, with F(infinity) = 1.
        open - winding
    }

    /// Margins of the loop broken at `channel`, up to the Nyquist frequency.
    pub fn margins(&self, gains: &GainSet, arr: Arrangement, channel: usize) -> Margins {
        let nyquist = std::f64::consts::PI / self.plant.period_s;
        margins(
            |w| self.loop_gain(gains, arr, channel, w),
            1e-3,
            0.999 * nyquist,
        )
    }

    /// Measurement `output` after a unit step of reference `input` at 0, every period for
    /// `n` periods (`n` a power of two; the response must have settled well before its end).
    pub fn step(
        &self,
        gains: &GainSet,
        arr: Arrangement,
        input: usize,
        output: usize,
        n: usize,
    ) -> Vec<f64> {
        let zero = Complex::new(0.0, 0.0);
        let mut h: Vec<Complex<f64>> = (0..n)
            .map(|k| {
                let theta = 2.0 * std::f64::consts::PI * (k as f64 + 0.5) / n as f64;
                let z = Complex::new(0.0, theta).exp();
                let f = self.at(gains, arr, z);
                let mut i_m = -f.m;
                for a in 0..ch::N {
                    i_m[(a, a)] += 1.0;
                }
                match i_m.lu().solve(&f.kr) {
                    Some(c) => (f.g * c)[(output, input)],
                    None => zero,
                }
            })
            .collect();
        FftPlanner::new().plan_fft_inverse(n).process(&mut h);
        // Undo the half-bin shift, then sum the impulse response into the step's.
        let mut sum = 0.0;
        h.iter()
            .enumerate()
            .map(|(k, v)| {
                let shift = Complex::new(0.0, std::f64::consts::PI * k as f64 / n as f64).exp();
                sum += (v * shift).re / n as f64;
                sum
            })
            .collect()
    }
}

/// The gains the loops fly with at `airspeed_mps`: the roll, pitch and sideslip loops, the yaw
/// damper and the altitude loop times the flight code's airspeed scaling ([`surface_scale`]),
/// which is 1 for a set without a scaling airspeed. (Scaling a loop's inputs is scaling its
/// gains.)
pub fn scaled_at(gains: &GainSet, airspeed_mps: f64) -> GainSet {
    let k = surface_scale(airspeed_mps as f32, gains.scaling_airspeed);
    let mut g = *gains;
    let (lat, lon) = (&mut g.lateral, &mut g.longitudinal);
    for v in [
        &mut lat.roll_kp,
        &mut lat.roll_ki,
        &mut lat.roll_rate_kd,
        &mut lat.slip_kp,
        &mut lat.slip_ki,
        &mut lat.yaw_damper_k,
        &mut lon.pitch_kp,
        &mut lon.pitch_ki,
        &mut lon.pitch_rate_kd,
        &mut lon.alt_kp,
        &mut lon.alt_ki,
    ] {
        *v *= k;
    }
    g
}

/// The change of `arg f` from `a` (where `f` is `fa`) to `b`, halving the interval until each
/// piece turns by less than a quarter turn.
fn wrap_arg(f: &impl Fn(f64) -> Complex<f64>, a: f64, fa: Complex<f64>, b: f64, depth: u32) -> f64 {
    let fb = f(b);
    let d = (fb / fa).arg();
    if d.abs() < std::f64::consts::FRAC_PI_2 || depth > 30 {
        return d;
    }
    let mid = 0.5 * (a + b);
    let fm = f(mid);
    wrap_arg(f, a, fa, mid, depth + 1) + wrap_arg(f, mid, fm, b, depth + 1)
}

/// One loop's figures on the sampled full model.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SampledLoop {
    /// Loop name (as the design names it).
    pub name: &'static str,
    /// The loops engaged.
    pub arrangement: Arrangement,
    /// Margins with the loop broken at its controller's output.
    pub margins: Margins,
    /// The closed loop has poles outside the unit circle: no step figures.
    pub unstable: bool,
    /// 10-90 % rise time of a small reference step, s.
    pub rise_time_s: Option<f64>,
    /// Overshoot of that step, %.
    pub overshoot_pct: f64,
    /// 2 % settling time, s.
    pub settling_time_s: Option<f64>,
}

/// A loop to judge: its name, the loops engaged, where it is broken, what steps and what
/// answers.
#[derive(Clone, Copy, Debug)]
pub struct LoopCase {
    /// Loop name.
    pub name: &'static str,
    /// Loops engaged.
    pub arrangement: Arrangement,
    /// Controller output it is broken at.
    pub channel: usize,
    /// Reference stepped.
    pub reference: usize,
    /// Measurement read.
    pub output: usize,
}

const fn arrangement(lon: LonLaw, lat: LatLaw, yaw: YawLaw) -> Arrangement {
    Arrangement { lon, lat, yaw }
}

/// Every loop of the computed set, inner to outer, in the arrangement its chapter-4 test flies
/// it (the lateral tests with the pitch held, the longitudinal ones wings level).
pub const CASES: [LoopCase; 7] = [
    LoopCase {
        name: "roll attitude (aileron)",
        arrangement: arrangement(LonLaw::Pitch, LatLaw::Roll, YawLaw::Damper),
        channel: ch::AILERON,
        reference: reference::ROLL,
        output: out::ROLL,
    },
    LoopCase {
        name: "course (commanded roll)",
        arrangement: arrangement(LonLaw::Pitch, LatLaw::Course, YawLaw::Damper),
        channel: ch::ROLL_CMD,
        reference: reference::COURSE,
        output: out::COURSE,
    },
    LoopCase {
        name: "sideslip (rudder)",
        arrangement: arrangement(LonLaw::Pitch, LatLaw::Roll, YawLaw::Sideslip),
        channel: ch::RUDDER,
        reference: reference::SIDESLIP,
        output: out::SIDESLIP,
    },
    LoopCase {
        name: "pitch attitude (elevator)",
        arrangement: arrangement(LonLaw::Pitch, LatLaw::Roll, YawLaw::Damper),
        channel: ch::ELEVATOR,
        reference: reference::PITCH,
        output: out::PITCH,
    },
    LoopCase {
        name: "altitude (commanded pitch)",
        arrangement: arrangement(LonLaw::AltitudeHold, LatLaw::Roll, YawLaw::Damper),
        channel: ch::PITCH_CMD,
        reference: reference::HEIGHT,
        output: out::HEIGHT,
    },
    LoopCase {
        name: "airspeed (commanded pitch)",
        arrangement: arrangement(LonLaw::AirspeedPitch, LatLaw::Roll, YawLaw::Damper),
        channel: ch::PITCH_CMD,
        reference: reference::AIRSPEED,
        output: out::AIRSPEED,
    },
    LoopCase {
        name: "airspeed (throttle)",
        arrangement: arrangement(LonLaw::AltitudeHold, LatLaw::Roll, YawLaw::Damper),
        channel: ch::THROTTLE,
        reference: reference::AIRSPEED,
        output: out::AIRSPEED,
    },
];

/// Slowest divergence counted as instability, s (an e-fold in five minutes).
pub const SLOWEST_DIVERGENCE_S: f64 = 300.0;

/// The total energy control's two loops, wings level: the energy rate broken at the throttle
/// (a height step), the balance broken at the pitch command (an airspeed step).
pub const TECS_CASES: [LoopCase; 2] = [
    LoopCase {
        name: "energy rate (throttle, TECS)",
        arrangement: arrangement(LonLaw::Tecs, LatLaw::Roll, YawLaw::Damper),
        channel: ch::THROTTLE,
        reference: reference::HEIGHT,
        output: out::HEIGHT,
    },
    LoopCase {
        name: "energy balance (pitch command, TECS)",
        arrangement: arrangement(LonLaw::Tecs, LatLaw::Roll, YawLaw::Damper),
        channel: ch::PITCH_CMD,
        reference: reference::AIRSPEED,
        output: out::AIRSPEED,
    },
];

/// Periods of each predicted step: 2^14 at 50 Hz is 328 s, long after the slowest loop
/// (altitude, a few tens of seconds) has settled.
const STEP_PERIODS: usize = 1 << 14;

impl SampledLoops {
    /// Margins and step figures of one case.
    pub fn judge(&self, gains: &GainSet, case: &LoopCase) -> SampledLoop {
        let y = self.step(
            gains,
            case.arrangement,
            case.reference,
            case.output,
            STEP_PERIODS,
        );
        let t: Vec<f64> = (0..y.len())
            .map(|k| k as f64 * self.plant.period_s)
            .collect();
        let end = t.last().copied().unwrap_or(0.0) + 1.0;
        let m = step_metrics(&t, &y, 0.0, 1.0, 0.0, end);
        let margins = self.margins(gains, case.arrangement, case.channel);
        let unstable = self.unstable_poles(gains, case.arrangement) != 0;
        // An unstable loop's transform back is not its response (it never decays).
        let known = |v: Option<f64>| v.filter(|_| !unstable);
        SampledLoop {
            name: case.name,
            arrangement: case.arrangement,
            margins,
            unstable,
            rise_time_s: known(m.rise_time_s),
            overshoot_pct: if unstable { f64::NAN } else { m.overshoot_pct },
            settling_time_s: known(m.settling_time_s),
        }
    }

    /// Every case of [`CASES`].
    pub fn judge_all(&self, gains: &GainSet) -> Vec<SampledLoop> {
        CASES.iter().map(|c| self.judge(gains, c)).collect()
    }

    /// Every case of [`TECS_CASES`] (whatever `LON_LAW` says: the gains are judged as if
    /// flown).
    pub fn judge_tecs(&self, gains: &GainSet) -> Vec<SampledLoop> {
        TECS_CASES.iter().map(|c| self.judge(gains, c)).collect()
    }
}

#[cfg(test)]
mod tests;
