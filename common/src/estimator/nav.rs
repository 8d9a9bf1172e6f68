//! Position, velocity and barometer offset: a linear Kalman filter in the local NED frame.
//!
//! State (7): position NED from home (m), velocity NED (m/s) and the barometer's offset
//! `b = baro altitude - true altitude` (m). The accelerometer, rotated to NED with the
//! attitude estimate and with gravity added back, is the process input:
//! `p' = v`, `v' = R f + g`, `b' = white noise`.
//!
//! Measurements: GPS position and velocity (delayed, see below), barometric altitude
//! `home_alt - baro_alt = p_d - b`, and while GPS is lost a horizontal velocity from air data.
//!
//! GPS latency: a fix describes the aircraft `delay` seconds ago. The filter keeps the
//! states of the last [`HISTORY`] IMU steps; the innovation is formed against the state of
//! the fix's time, and the correction is applied to the present state and to every stored
//! state after it (the error of a position/velocity filter is nearly constant over 0.1-0.3 s,
//! so one gain serves both times). The residual cost is the change in the error over the
//! delay, a few centimetres at this aircraft's accelerations.

use super::kalman::{condition, scalar_update, Refused};
use nalgebra::{SMatrix, SVector, Vector3};

/// States kept for the delayed GPS update (0.64 s at 100 Hz, 1.28 s at 50 Hz).
pub const HISTORY: usize = 64;

type Mat7 = SMatrix<f32, 7, 7>;
type Vec7 = SVector<f32, 7>;

const IPD: usize = 2;
const IV: usize = 3;
const IB: usize = 6;

#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Snapshot {
    t: f64,
    x: Vec7,
}

/// Result of one vector measurement.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct NavFusion {
    /// Components fused.
    pub fused: u8,
    /// Components refused by the gate.
    pub gated: u8,
}

/// Noise settings of one GPS fix.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GpsNoise {
    /// Horizontal position, m.
    pub horizontal: f32,
    /// Vertical position, m.
    pub vertical: f32,
    /// Velocity per axis, m/s.
    pub velocity: f32,
}

/// The position/velocity/baro-offset filter.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NavFilter {
    x: Vec7,
    p: Mat7,
    history: [Snapshot; HISTORY],
    head: usize,
    len: usize,
    initialized: bool,
}

impl Default for NavFilter {
    fn default() -> Self {
        Self::new()
    }
}

impl NavFilter {
    /// An uninitialised filter.
    pub fn new() -> Self {
        Self {
            x: Vec7::zeros(),
            p: Mat7::identity(),
            history: [Snapshot::default(); HISTORY],
            head: 0,
            len: 0,
            initialized: false,
        }
    }

    /// True once a GPS fix has set the state.
    pub fn is_initialized(&self) -> bool {
        self.initialized
    }

    /// Position NED from home, m.
    pub fn position(&self) -> Vector3<f32> {
        self.x.fixed_rows::<3>(0).into_owned()
    }

    /// Velocity NED, m/s.
    pub fn velocity(&self) -> Vector3<f32> {
        self.x.fixed_rows::<3>(IV).into_owned()
    }

    /// Barometer offset (baro altitude minus true altitude), m.
    pub fn baro_offset(&self) -> f32 {
        self.x[IB]
    }

    /// 1-sigma horizontal position, vertical position and velocity (largest axis) uncertainty.
    pub fn sigmas(&self) -> (f32, f32, f32) {
        let d = self.p.diagonal();
        (
            libm::sqrtf(d[0].max(d[1])),
            libm::sqrtf(d[2]),
            libm::sqrtf(d[3].max(d[4]).max(d[5])),
        )
    }

    /// Starts from a GPS fix taken `delay` s ago: position `pos` (NED from home), velocity
    /// `vel`, barometer offset `baro_offset` (0 when no barometer has been read).
    pub fn initialize(
        &mut self,
        t: f64,
        pos: &Vector3<f32>,
        vel: &Vector3<f32>,
        delay: f32,
        baro_offset: f32,
        noise: &GpsNoise,
    ) {
        let mut x = Vec7::zeros();
        x.fixed_rows_mut::<3>(0).copy_from(&(pos + vel * delay));
        x.fixed_rows_mut::<3>(IV).copy_from(vel);
        x[IB] = baro_offset;
        let h2 = noise.horizontal * noise.horizontal;
        let v2 = noise.vertical * noise.vertical;
        let vel2 = (noise.velocity * noise.velocity).max(0.25);
        self.p = Mat7::from_diagonal(&Vec7::from([h2, h2, v2, vel2, vel2, vel2, v2 + 1.0]));
        self.x = x;
        self.len = 0;
        self.head = 0;
        self.initialized = true;
        self.remember(t);
    }

    /// Propagates with the NED acceleration `acc_ned` (gravity included) over `dt` ending at
    /// time `t`. `acc_noise` is a density (m/s^2/sqrt(Hz)), `baro_rw` a random walk (m/sqrt(s)).
    pub fn predict(
        &mut self,
        t: f64,
        acc_ned: &Vector3<f32>,
        dt: f32,
        acc_noise: f32,
        baro_rw: f32,
    ) {
        if !self.initialized {
            return;
        }
        let mut x = self.x;
        let v = self.velocity();
        let dp = v * dt + acc_ned * (0.5 * dt * dt);
        for i in 0..3 {
            x[i] += dp[i];
            x[IV + i] += acc_ned[i] * dt;
        }
        let mut phi = Mat7::identity();
        for i in 0..3 {
            phi[(i, IV + i)] = dt;
        }
        let qa = acc_noise * acc_noise * dt;
        let mut qd = Mat7::zeros();
        for i in 0..3 {
            // Integrated white acceleration: exact discrete covariance of (p, v).
            qd[(i, i)] = qa * dt * dt / 3.0;
            qd[(i, IV + i)] = qa * dt / 2.0;
            qd[(IV + i, i)] = qa * dt / 2.0;
            qd[(IV + i, IV + i)] = qa;
        }
        qd[(IB, IB)] = baro_rw * baro_rw * dt;
        let mut p = phi * self.p * phi.transpose() + qd;
        if x.iter().all(|c| c.is_finite()) && condition(&mut p, 1e-9, 1e8) {
            self.x = x;
            self.p = p;
        }
        self.remember(t);
    }

    fn remember(&mut self, t: f64) {
        self.head = (self.head + 1) % HISTORY;
        if let Some(s) = self.history.get_mut(self.head) {
            *s = Snapshot { t, x: self.x };
        }
        self.len = (self.len + 1).min(HISTORY);
    }

    /// The stored state closest to time `t` (the present state when nothing is stored).
    fn state_at(&self, t: f64) -> Vec7 {
        let mut best = self.x;
        let mut best_err = f64::INFINITY;
        for k in 0..self.len {
            let i = (self.head + HISTORY - k) % HISTORY;
            if let Some(s) = self.history.get(i) {
                let e = (s.t - t).abs();
                if e < best_err {
                    best_err = e;
                    best = s.x;
                }
            }
        }
        best
    }

    /// Adds a correction to the present state and to the stored states after `t_meas`.
    fn apply(&mut self, dx: &Vec7, t_meas: f64) {
        self.x += dx;
        for k in 0..self.len {
            let i = (self.head + HISTORY - k) % HISTORY;
            if let Some(s) = self.history.get_mut(i) {
                if s.t >= t_meas - 1e-4 {
                    s.x += dx;
                }
            }
        }
    }

    /// Fuses a GPS fix taken at time `t_meas`: position NED from home and velocity NED.
    pub fn fuse_gps(
        &mut self,
        t_meas: f64,
        pos: &Vector3<f32>,
        vel: &Vector3<f32>,
        noise: &GpsNoise,
        gate_sigma: f32,
    ) -> NavFusion {
        let mut out = NavFusion::default();
        if !self.initialized {
            return out;
        }
        let past = self.state_at(t_meas);
        let start = self.x;
        let r = [
            noise.horizontal * noise.horizontal,
            noise.horizontal * noise.horizontal,
            noise.vertical * noise.vertical,
            noise.velocity * noise.velocity,
            noise.velocity * noise.velocity,
            noise.velocity * noise.velocity,
        ];
        let z = [pos.x, pos.y, pos.z, vel.x, vel.y, vel.z];
        for (i, (zi, ri)) in z.iter().zip(r.iter()).enumerate() {
            let mut h = Vec7::zeros();
            h[i] = 1.0;
            // The past state plus the corrections this fix has already made to it.
            let innov = zi - (past[i] + (self.x[i] - start[i]));
            match scalar_update(&mut self.p, &h, innov, *ri, gate_sigma) {
                Ok(f) => {
                    self.apply(&f.dx, t_meas);
                    out.fused += 1;
                }
                Err(Refused::Gated) => out.gated += 1,
                Err(Refused::Degenerate) => {}
            }
        }
        out
    }

    /// Fuses a barometric altitude: `home_minus_baro = home_alt - baro_alt` (m).
    pub fn fuse_baro(&mut self, home_minus_baro: f32, noise: f32, gate_sigma: f32) -> NavFusion {
        let mut out = NavFusion::default();
        if !self.initialized {
            return out;
        }
        let mut h = Vec7::zeros();
        h[IPD] = 1.0;
        h[IB] = -1.0;
        let innov = home_minus_baro - (self.x[IPD] - self.x[IB]);
        match scalar_update(&mut self.p, &h, innov, noise * noise, gate_sigma) {
            Ok(f) => {
                self.x += f.dx;
                out.fused = 1;
            }
            Err(Refused::Gated) => out.gated = 1,
            Err(Refused::Degenerate) => {}
        }
        out
    }

    /// Fuses a horizontal velocity (north, east) known to `noise` m/s, e.g. from air data.
    pub fn fuse_horizontal_velocity(&mut self, vn: f32, ve: f32, noise: f32) -> NavFusion {
        let mut out = NavFusion::default();
        if !self.initialized {
            return out;
        }
        for (i, z) in [(IV, vn), (IV + 1, ve)] {
            let mut h = Vec7::zeros();
            h[i] = 1.0;
            let innov = z - self.x[i];
            // No gate: this replaces GPS while it is missing and must not lock itself out.
            if let Ok(f) = scalar_update(&mut self.p, &h, innov, noise * noise, f32::INFINITY) {
                self.x += f.dx;
                out.fused += 1;
            }
        }
        out
    }

    /// Moves position and velocity to a GPS fix taken `delay` s ago (after a long outage or a
    /// lock-out the filter may have drifted beyond its gate); the baro offset is kept.
    pub fn reset_to_gps(
        &mut self,
        pos: &Vector3<f32>,
        vel: &Vector3<f32>,
        delay: f32,
        noise: &GpsNoise,
    ) {
        let now = pos + vel * delay;
        let mut shift = Vec7::zeros();
        for i in 0..3 {
            shift[i] = now[i] - self.x[i];
            shift[IV + i] = vel[i] - self.x[IV + i];
        }
        if !shift.iter().all(|c| c.is_finite()) {
            return;
        }
        // The stored past moves with the present, so the next delayed fix compares like with
        // like.
        self.apply(&shift, f64::NEG_INFINITY);
        let h2 = noise.horizontal * noise.horizontal;
        let z2 = noise.vertical * noise.vertical;
        let v2 = (noise.velocity * noise.velocity).max(0.25);
        let b = self.p[(IB, IB)];
        self.p = Mat7::from_diagonal(&Vec7::from([h2, h2, z2, v2, v2, v2, b + z2]));
    }

    /// Makes the baro offset agree with one barometric altitude (`home_alt - baro_alt`) after
    /// a lock-out, with its uncertainty back to the GPS's vertical one.
    pub fn reset_baro_offset(&mut self, home_minus_baro: f32) {
        let b = self.x[IPD] - home_minus_baro;
        if !b.is_finite() {
            return;
        }
        self.x[IB] = b;
        for i in 0..7 {
            if i != IB {
                self.p[(i, IB)] = 0.0;
                self.p[(IB, i)] = 0.0;
            }
        }
        self.p[(IB, IB)] = self.p[(IPD, IPD)] + 1.0;
    }
}
