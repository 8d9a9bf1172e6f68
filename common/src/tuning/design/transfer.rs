//! Each loop's transfer `L(jw)`, evaluated at one frequency in complex `f32` straight from its
//! factors: no polynomial is formed, so nothing is allocated and no coefficient grows with the
//! loop's order. An inner loop inside an outer one is its closed loop, evaluated at the same
//! point.
//!
//! What the design formulas leave out is in every loop, as the margins must see it: the
//! first-order servo on the surface loops and the flight software's delay `e^{-jw tau}` on
//! all, and the feedback low-pass on the altitude and airspeed loops.
//!
//! `Transfer::eval` returns `L(jw) e^{jw tau}`, the loop without its outermost delay: that
//! part's phase turns slowly with `w` and can be followed (unwrapped) from one sample of a
//! coarse sweep to the next, where the delay's `-w tau` (50 rad at 1000 rad/s) is added in
//! closed form. The inner loops' own delay, inside `1 / (1 + L_inner)`, stays in.

use super::model::{DesignModel, PitchResponse};
use nalgebra::Complex;

/// A complex number in `f32`.
pub(super) type C = Complex<f32>;

/// The gains of one loop, in the controller form the autopilot flies:
/// `u = kp e + ki int(e) - kd rate` (PI loops have `kd` 0).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LoopGains {
    /// Proportional gain.
    pub kp: f32,
    /// Integral gain, per second.
    pub ki: f32,
    /// Rate (derivative) gain, s.
    pub kd: f32,
}

impl LoopGains {
    /// Whether all three are finite.
    pub fn is_finite(&self) -> bool {
        self.kp.is_finite() && self.ki.is_finite() && self.kd.is_finite()
    }

    /// `kp + ki / s`.
    fn pi(&self, s: C) -> C {
        C::from(self.ki) / s + self.kp
    }

    /// `kp + ki / s + kd s` (the rate damper acts on the measured rate, `s` times the output).
    fn pid(&self, s: C) -> C {
        self.pi(s) + s * self.kd
    }
}

/// `pi / 2` in two parts for the argument's reduction (Cody and Waite): the first has 9
/// significant bits, so `k` times it is exact for any quadrant count `k` below 2^15.
const HALF_PI_HI: f32 = 1.570_312_5;
/// `pi / 2 - HALF_PI_HI`.
const HALF_PI_LO: f32 = 4.838_268e-4;

/// `sin x` and `cos x` in `f32` (NaN for a NaN or infinite `x`): the argument reduced to a
/// quarter turn about the nearest multiple of `pi / 2`, then Taylor series to `x^11` and
/// `x^12` (their first omitted terms are under 1e-10 within `pi / 4`). `libm`'s `sincosf` works
/// in `f64`, which the Cortex-M4F does in software: some 3,000 instructions a call against
/// this one's few dozen, at the delay's arguments (up to 50 rad) to within 1e-6 of it.
pub(super) fn sin_cos(x: f32) -> (f32, f32) {
    let k = libm::roundf(x * core::f32::consts::FRAC_2_PI);
    let r = (x - k * HALF_PI_HI) - k * HALF_PI_LO;
    let r2 = r * r;
    let sin = r
        * (1.0
            + r2 * (-1.0 / 6.0
                + r2 * (1.0 / 120.0
                    + r2 * (-1.0 / 5_040.0 + r2 * (1.0 / 362_880.0 - r2 / 39_916_800.0)))));
    let cos = 1.0
        + r2 * (-0.5
            + r2 * (1.0 / 24.0
                + r2 * (-1.0 / 720.0
                    + r2 * (1.0 / 40_320.0 + r2 * (-1.0 / 3_628_800.0 + r2 / 479_001_600.0)))));
    // The quadrant: `as` saturates (NaN gives 0), and `& 3` keeps it in 0..4 for any sign.
    match (k as i32) & 3 {
        0 => (sin, cos),
        1 => (cos, -sin),
        2 => (-sin, -cos),
        _ => (-cos, sin),
    }
}

/// The plant the loops close around: the model, checked finite and in range before any loop
/// is built, with what the loops take of it resolved (its pitch response, engine and servo
/// poles) and the feedback low-pass and delay the design adds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Plant {
    /// The reduced models.
    pub model: DesignModel,
    /// Pitch attitude per elevator, what the pitch loop is judged on.
    pub pitch: PitchResponse,
    /// Engine pole, 1/s.
    pub engine_pole: f32,
    /// Servo pole, rad/s.
    pub servo_pole: f32,
    /// The altitude and airspeed feedback low-pass's pole, rad/s.
    pub lp: f32,
    /// Delay, s.
    pub tau: f32,
}

impl Plant {
    /// `phi / da = a_phi2 / (s (s + a_phi1))`.
    fn roll(&self, s: C) -> C {
        C::from(self.model.a_phi2) / (s * (s + self.model.a_phi1))
    }

    /// `beta / dr = a_beta2 / (s + a_beta1)`.
    fn sideslip(&self, s: C) -> C {
        C::from(self.model.a_beta2) / (s + self.model.a_beta1)
    }

    /// `theta / de`, by Horner's rule.
    fn pitch(&self, s: C) -> C {
        let [n1, n0] = self.pitch.num;
        let [d3, d2, d1, d0] = self.pitch.den;
        (s * n1 + n0) / (((s * d3 + d2) * s + d1) * s + d0)
    }

    /// `gamma / theta`: the flight path's first-order lag behind the pitch, or 1 where it is
    /// not modelled (`a_gamma` 0).
    fn flight_path(&self, s: C) -> C {
        let a = self.model.a_gamma;
        if a > 0.0 {
            C::from(a) / (s + a)
        } else {
            C::from(1.0)
        }
    }

    /// The servo, `p / (s + p)`.
    fn servo(&self, s: C) -> C {
        C::from(self.servo_pole) / (s + self.servo_pole)
    }

    /// The feedback low-pass, `lp / (s + lp)`.
    fn filter(&self, s: C) -> C {
        C::from(self.lp) / (s + self.lp)
    }

    /// `e^{-jw tau}`.
    fn delay(&self, w: f32) -> C {
        let (sin, cos) = sin_cos(w * self.tau);
        C::new(cos, -sin)
    }

    /// An attitude loop closed (`gains` PID on `plant`, servo and delay in the loop), the
    /// attitude per command with its outermost delay taken out:
    /// `PI P S / (1 + PID P S e^{-jw tau})`.
    fn closed(&self, gains: &LoopGains, plant: C, s: C, delay: C) -> C {
        let ps = plant * self.servo(s);
        gains.pi(s) * ps / (C::from(1.0) + gains.pid(s) * ps * delay)
    }
}

/// One loop of the design with its gains, ready to be evaluated.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Transfer {
    /// Roll attitude: PID on the aileron.
    Roll(LoopGains),
    /// Course: PI on the commanded roll, through the roll loop closed.
    Course {
        /// The course loop's gains.
        course: LoopGains,
        /// The roll loop's gains.
        roll: LoopGains,
    },
    /// Sideslip: PI on the rudder.
    Sideslip(LoopGains),
    /// Pitch attitude: PID on the elevator.
    Pitch(LoopGains),
    /// Altitude: PI on the commanded pitch, through the pitch loop closed and the flight
    /// path's lag, fed back filtered.
    Altitude {
        /// The altitude loop's gains.
        altitude: LoopGains,
        /// The pitch loop's gains.
        pitch: LoopGains,
    },
    /// Airspeed: PI on the commanded pitch, through the pitch loop closed and the flight
    /// path's lag, fed back filtered.
    AirspeedPitch {
        /// The airspeed loop's gains.
        airspeed: LoopGains,
        /// The pitch loop's gains.
        pitch: LoopGains,
    },
    /// Airspeed: PI on the throttle through the engine's lag, fed back filtered (no servo).
    AirspeedThrottle(LoopGains),
}

impl Transfer {
    /// `L(jw) e^{jw tau}` at `w`, rad/s (`w` > 0).
    pub fn eval(&self, p: &Plant, w: f32) -> C {
        // The tests count every evaluation here, apart from the designer's own count.
        #[cfg(test)]
        counted::EVALUATIONS.with(|n| n.set(n.get().saturating_add(1)));
        let s = C::new(0.0, w);
        match self {
            Transfer::Roll(g) => g.pid(s) * p.roll(s) * p.servo(s),
            Transfer::Course { course, roll } => {
                let roll = p.closed(roll, p.roll(s), s, p.delay(w));
                course.pi(s) * roll * (p.model.g / p.model.va) / s
            }
            Transfer::Sideslip(g) => g.pi(s) * p.sideslip(s) * p.servo(s),
            Transfer::Pitch(g) => g.pid(s) * p.pitch(s) * p.servo(s),
            Transfer::Altitude { altitude, pitch } => {
                let pitch = p.closed(pitch, p.pitch(s), s, p.delay(w));
                altitude.pi(s) * pitch * p.flight_path(s) * p.model.va / s * p.filter(s)
            }
            Transfer::AirspeedPitch { airspeed, pitch } => {
                let pitch = p.closed(pitch, p.pitch(s), s, p.delay(w));
                let gamma = pitch * p.flight_path(s);
                airspeed.pi(s) * gamma * C::from(-p.model.g) / (s + p.model.a_v1) * p.filter(s)
            }
            Transfer::AirspeedThrottle(g) => {
                let engine = C::from(p.model.a_v2 * p.engine_pole)
                    / ((s + p.model.a_v1) * (s + p.engine_pole));
                g.pi(s) * engine * p.filter(s)
            }
        }
    }
}

/// The evaluations of [`Transfer::eval`] on this thread, for the tests.
#[cfg(test)]
pub(super) mod counted {
    extern crate std;
    std::thread_local! {
        /// Evaluations so far.
        pub static EVALUATIONS: core::cell::Cell<u32> = const { core::cell::Cell::new(0) };
    }
}
