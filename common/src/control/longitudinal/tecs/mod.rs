//! Total energy control (Lambregts): throttle drives the aircraft's total energy, pitch its
//! distribution between height and airspeed, instead of each loop owning one quantity.
//!
//! ```text
//! h_r_dot = h_dot_c + k_h (h_c - h_r) [-sink..climb] ; h_dot_d = h_r_dot + k_h (h_r - h) [-sink..climb]
//! V_c --[slew +-acc]-------------- V_r ; V_dot_d = k_V (V_r - V)              [+-acc]
//! rates as flight-path angles, rad:  E = h_dot / V + V_dot / g   B = w_h h_dot / V - w_V V_dot / g
//! throttle  = trim + E_d g / a_V2 + PI(E_d - E)     [thr_min..thr_max]
//! theta_c   = trim + B_d          + PI(B_d - B)     [+-pitch_max]  -> the pitch attitude loop
//! ```
//!
//! `h_dot` and `V_dot` come from [`RateEstimator`]s on the altitude and airspeed, so the law
//! needs nothing the successive loop closure does not. Below [`TecsGains::underspeed`] the
//! balance weights move to airspeed only (`w_h` 0, `w_V` 1) and the throttle to its maximum:
//! a slow aircraft gives up height for speed. Both PI loops are [`Pid`]s (conditional
//! integration: the integrators stop at the throttle and pitch limits), engaged bumplessly
//! from the throttle and pitch command they take over. The gains and their design:
//! [`gains`].

pub mod gains;

use super::gains::LongitudinalGains;
use crate::control::filters::RateEstimator;
use crate::control::pid::{Bumpless, Derivative, Pid, PidGains};
use crate::math::{clamp, GRAVITY};
pub use gains::{TecsGains, UNDERSPEED_BAND_MPS};

/// Airspeed below which the rates are not divided by it, m/s: on the ground roll and in a
/// stall the flight-path angle `h_dot / V` means nothing.
const MIN_DIVISOR_MPS: f32 = 5.0;

/// What the energy control is asked for.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TecsDemand {
    /// Altitude, m.
    pub altitude: f32,
    /// Airspeed, m/s.
    pub airspeed: f32,
    /// Rate at which `altitude` moves, m/s (a glide slope); 0 for a fixed altitude.
    pub climb_rate: f32,
}

/// One step's commands and what they came from.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TecsOutput {
    /// Throttle, 0..1.
    pub throttle: f32,
    /// Pitch command for the pitch attitude loop, rad.
    pub pitch_cmd: f32,
    /// Climb-rate demand, m/s.
    pub climb_rate_demand: f32,
    /// Acceleration demand, m/s^2.
    pub accel_demand: f32,
    /// Underspeed priority, 0 (none) to 1 (airspeed only).
    pub underspeed: f32,
}

/// The total energy control's state.
#[derive(Clone, Copy, Debug)]
pub struct Tecs {
    gains: TecsGains,
    height: RateEstimator,
    speed: RateEstimator,
    thr: Pid,
    pitch: Pid,
    /// Shaped height and airspeed demands, `None` until engaged.
    refs: Option<(f32, f32)>,
    /// The altitude demand of the last step, m: its rate is a ramp's feed-forward.
    last_demand: Option<f32>,
    last: TecsOutput,
}

fn thr_gains(t: &TecsGains, g: &LongitudinalGains) -> PidGains {
    PidGains {
        kp: t.thr_kp,
        ki: t.thr_ki,
        kd: 0.0,
        out_min: g.throttle_min,
        out_max: g.throttle_max,
    }
}

fn pitch_gains(t: &TecsGains, g: &LongitudinalGains) -> PidGains {
    PidGains::symmetric(t.pitch_kp, t.pitch_ki, 0.0, g.pitch_max)
}

/// Moves `from` towards `to` by at most `down` (negative) to `up` per second over `dt`;
/// returns the new value and its rate.
fn slew(from: f32, to: f32, down: f32, up: f32, dt: f32) -> (f32, f32) {
    let rate = clamp((to - from) / dt, down, up);
    (from + rate * dt, rate)
}

impl Tecs {
    /// A disengaged energy control; `transfer_tc` (s) fades the engagement's offsets.
    pub fn new(t: &TecsGains, g: &LongitudinalGains, transfer_tc: f32) -> Self {
        Self {
            gains: *t,
            height: RateEstimator::new(t.rate_pole),
            speed: RateEstimator::new(t.rate_pole),
            thr: Pid::new(thr_gains(t, g), transfer_tc),
            pitch: Pid::new(pitch_gains(t, g), transfer_tc),
            refs: None,
            last_demand: None,
            last: TecsOutput::default(),
        }
    }

    /// Replaces the gains; an engaged control goes on from its present commands.
    pub fn set_gains(&mut self, t: &TecsGains, g: &LongitudinalGains, transfer_tc: f32) {
        self.gains = *t;
        self.height.set_pole(t.rate_pole);
        self.speed.set_pole(t.rate_pole);
        self.thr.set_gains(thr_gains(t, g), transfer_tc);
        self.pitch.set_gains(pitch_gains(t, g), transfer_tc);
        if self.refs.is_some() {
            self.thr.reset_to(self.last.throttle, Bumpless::Fade);
            self.pitch.reset_to(self.last.pitch_cmd, Bumpless::Fade);
        }
    }

    /// The gains in use.
    pub fn gains(&self) -> &TecsGains {
        &self.gains
    }

    /// Feeds the altitude and airspeed estimators (every good sample, engaged or not, so the
    /// rates are known when the control engages).
    pub fn observe(&mut self, altitude: f32, airspeed: f32, dt: f32) {
        self.height.step(altitude, dt);
        self.speed.step(airspeed, dt);
    }

    /// Whether the control is engaged.
    pub fn engaged(&self) -> bool {
        self.refs.is_some()
    }

    /// Disengages: the next [`Tecs::step`] needs an [`Tecs::engage`] first.
    pub fn disengage(&mut self) {
        self.refs = None;
    }

    /// Engages: the next step's commands are `throttle` and `pitch_cmd`, and the shaped demands
    /// start from the present altitude and airspeed, so a far demand is approached at the
    /// climb, sink and acceleration limits. Refused (stays disengaged) before the estimators
    /// have had a sample.
    pub fn engage(&mut self, throttle: f32, pitch_cmd: f32) {
        if let (Some((h, _)), Some((v, _))) = (self.height.output(), self.speed.output()) {
            self.refs = Some((h, v));
            self.last_demand = None;
            self.thr.reset_to(throttle, Bumpless::Fade);
            self.pitch.reset_to(pitch_cmd, Bumpless::Fade);
        }
    }

    /// One step after [`Tecs::observe`]: the throttle and the pitch command for `d`, with the
    /// trims and limits of `g`. `None` (nothing changed) when disengaged, when a demand or `dt`
    /// is not finite or not positive, or before the estimators have a sample; the caller then
    /// holds its outputs. A non-finite `climb_rate` only loses its feed-forward.
    pub fn step(&mut self, d: &TecsDemand, g: &LongitudinalGains, dt: f32) -> Option<TecsOutput> {
        let t = self.gains;
        let good = dt.is_finite() && dt > 0.0 && d.altitude.is_finite() && d.airspeed.is_finite();
        let ((h, h_dot), (v, v_dot)) = (self.height.output()?, self.speed.output()?);
        let (h_r, v_r) = self.refs.filter(|_| good)?;

        // Demand shaping: the height reference approaches the demand at `k_h`, the rate of the
        // height loop itself, and at most at the climb and sink limits; the demand's own rate
        // is fed forward when it is one the aircraft can fly (a glide slope, or a leg between
        // waypoints at different heights), so a ramp is followed without the `rate / k_h` lag
        // of the filter, and a faster change is a step, left to it. A reference slewed at the
        // limits instead asked a 2 m step for 3 m/s of climb for 0.7 s, fed forward into 10
        // deg of pitch, and the aircraft, lagging it, overshot by 43 % (`altitude_step_small`).
        // The airspeed reference moves at the acceleration limit.
        let ramp = match self.last_demand {
            Some(last) => {
                let rate = (d.altitude - last) / dt;
                if rate >= -t.sink_max && rate <= t.climb_max {
                    rate
                } else {
                    0.0
                }
            }
            None => 0.0,
        };
        self.last_demand = Some(d.altitude);
        let ff = if d.climb_rate.is_finite() && d.climb_rate != 0.0 {
            clamp(d.climb_rate, -t.sink_max, t.climb_max)
        } else {
            ramp
        };
        let (h_r, h_r_dot) = if libm::fabsf(d.altitude - h_r) <= libm::fabsf(ff) * dt + 1e-3 {
            (d.altitude, ff)
        } else {
            let rate = clamp(
                ff + t.height_k * (d.altitude - h_r),
                -t.sink_max,
                t.climb_max,
            );
            (h_r + rate * dt, rate)
        };
        let (v_r, _) = slew(v_r, d.airspeed, -t.accel_max, t.accel_max, dt);
        let climb_d = clamp(h_r_dot + t.height_k * (h_r - h), -t.sink_max, t.climb_max);
        let accel_d = clamp(t.speed_k * (v_r - v), -t.accel_max, t.accel_max);

        // Slow: airspeed only in the balance, and the throttle driven to its maximum.
        let under = clamp((t.underspeed - v) / UNDERSPEED_BAND_MPS, 0.0, 1.0);
        let w = t.speed_weight + under * (2.0 - t.speed_weight);
        let (w_h, w_v) = ((2.0 - w).min(1.0), w.min(1.0));

        let inv_v = 1.0 / v.max(MIN_DIVISOR_MPS);
        let total_d = climb_d * inv_v + accel_d / GRAVITY;
        let total = h_dot * inv_v + v_dot / GRAVITY;
        let bal_d = w_h * climb_d * inv_v - w_v * accel_d / GRAVITY;
        let bal = w_h * h_dot * inv_v - w_v * v_dot / GRAVITY;

        let thr_ff = g.trim_throttle + total_d * GRAVITY / t.thr_accel;
        let thr = self.thr.step(total_d - total, Derivative::None, thr_ff, dt);
        let throttle = thr + under * (g.throttle_max - thr);
        let pitch_cmd = self
            .pitch
            .step(bal_d - bal, Derivative::None, g.trim_pitch + bal_d, dt);
        self.refs = Some((h_r, v_r));
        self.last = TecsOutput {
            throttle,
            pitch_cmd,
            climb_rate_demand: climb_d,
            accel_demand: accel_d,
            underspeed: under,
        };
        Some(self.last)
    }
}

#[cfg(test)]
mod tests;
