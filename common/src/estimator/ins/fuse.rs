//! The measurements the filter fuses, each as scalar components against the error state:
//! delayed GPS position and velocity, barometric altitude, air-data velocity, magnetometer
//! heading and the accelerometer's gravity reference.

// Indexing is on the error-state layout's constants and loop indices below their dimension
// (as in the parent module): no index comes from outside.
#![allow(clippy::indexing_slicing)]

use super::{Fusion, GpsNoise, Ins, Motion, Vecn, GRAVITY, IBG, IBO, IP, ITH, IV};
use crate::estimator::kalman::{gain, Refused};
use nalgebra::Vector3;

/// The span over which the acceleration at a fix's time is read from the stored velocities, µs:
/// shorter than the 5 Hz fixes' interval, so a correction between them does not enter it.
const ACCEL_SPAN_US: u64 = 100_000;

impl Ins {
    /// Fuses one scalar component: `innov` against the error-state row `h`.
    fn fuse_scalar(
        &mut self,
        h: &Vecn,
        innov: f32,
        r: f32,
        gate_sigma: f32,
        t_meas_us: u64,
        out: &mut Fusion,
    ) {
        match gain(&self.cov, h, innov, r, gate_sigma) {
            Ok(g) => {
                if self.apply(&g, t_meas_us) {
                    out.fused += 1;
                    out.nis_sum += g.fused.nis;
                }
            }
            Err(Refused::Gated) => out.gated += 1,
            Err(Refused::Degenerate) => {}
        }
    }

    /// Fuses a GPS fix taken at time `t_meas_us` (µs): position NED from home and velocity NED.
    pub fn fuse_gps(
        &mut self,
        t_meas_us: u64,
        pos: &Vector3<f32>,
        vel: &Vector3<f32>,
        noise: &GpsNoise,
        gate_sigma: f32,
    ) -> (Fusion, Fusion) {
        let mut pos_out = Fusion::default();
        let mut vel_out = Fusion::default();
        if !self.nav_ok {
            return (pos_out, vel_out);
        }
        let past = self.state_at(t_meas_us);
        let (v0, p0) = (self.v, self.p);
        // The latency is known only to within `latency_sd`: a fix taken at another instant than
        // its stamp differs from the state of the stamp by the acceleration (and the velocity)
        // times the error. In a 45 deg turn 9.8 m/s^2 x 0.04 s is 0.4 m/s, five times a
        // receiver's velocity noise; weighed as exact, it is read as a tilt error and the roll
        // estimate walks off at each fix.
        let before = self.state_at(t_meas_us.saturating_sub(ACCEL_SPAN_US));
        let span_s = past.t_us.saturating_sub(before.t_us) as f32 * 1e-6;
        let accel = if span_s > 0.0 {
            (past.v - before.v) / span_s
        } else {
            Vector3::zeros()
        };
        let sd = noise.latency_sd;
        let h2 = noise.horizontal * noise.horizontal;
        let z2 = noise.vertical * noise.vertical;
        let v2 = noise.velocity * noise.velocity;
        // Velocity first: it carries the attitude information, and is the sharper measurement.
        for i in 0..3 {
            let mut h = Vecn::zeros();
            h[IV + i] = 1.0;
            let innov = vel[i] - (past.v[i] + (self.v[i] - v0[i]));
            let r = v2 + (accel[i] * sd) * (accel[i] * sd);
            self.fuse_scalar(&h, innov, r, gate_sigma, t_meas_us, &mut vel_out);
        }
        for (i, r) in [h2, h2, z2].into_iter().enumerate() {
            let mut h = Vecn::zeros();
            h[IP + i] = 1.0;
            let innov = pos[i] - (past.p[i] + (self.p[i] - p0[i]));
            let r = r + (past.v[i] * sd) * (past.v[i] * sd);
            self.fuse_scalar(&h, innov, r, gate_sigma, t_meas_us, &mut pos_out);
        }
        self.flush_shift();
        (pos_out, vel_out)
    }

    /// Fuses a barometric altitude: `home_minus_baro = home_alt - baro_alt` (m).
    pub fn fuse_baro(&mut self, t_us: u64, home_minus_baro: f32, noise: f32, gate: f32) -> Fusion {
        let mut out = Fusion::default();
        if !self.nav_ok {
            return out;
        }
        let mut h = Vecn::zeros();
        h[IP + 2] = 1.0;
        h[IBO] = -1.0;
        let innov = home_minus_baro - (self.p.z - self.baro_offset);
        self.fuse_scalar(&h, innov, noise * noise, gate, t_us, &mut out);
        self.flush_shift();
        out
    }

    /// Fuses a horizontal velocity (north, east) known to `noise` m/s, e.g. from air data.
    /// Not gated: it stands in for GPS while GPS is missing and must not lock itself out.
    pub fn fuse_horizontal_velocity(&mut self, t_us: u64, vn: f32, ve: f32, noise: f32) -> Fusion {
        let mut out = Fusion::default();
        if !self.nav_ok {
            return out;
        }
        // Checked element access (a loop the size-optimised MCU image does not unroll: no
        // panic path for its indices, tests/tests/panic_sites.rs).
        for (i, z) in [(0, vn), (1, ve)] {
            let mut h = Vecn::zeros();
            if let Some(hi) = h.get_mut(IV + i) {
                *hi = 1.0;
            }
            let innov = z - self.v.get(i).copied().unwrap_or(f32::NAN);
            self.fuse_scalar(&h, innov, noise * noise, f32::INFINITY, t_us, &mut out);
        }
        self.flush_shift();
        out
    }

    /// Fuses the magnetic heading: the direction of the magnetometer's field `mag`, rotated
    /// into NED with the estimated attitude, in the horizontal plane, against that of the
    /// earth field `earth_ned`. `noise` is the per-axis field noise, gauss.
    ///
    /// A tilt error moves that direction too (by `B_d / B_h`, about 3 at mid-latitudes, per
    /// radian of roll or pitch about the field's horizontal axis), and the Jacobian says so:
    /// a heading fusion that ignored it would turn every roll error into a heading and gyro
    /// bias error, which the centripetal term of the gravity reference turns back into roll.
    pub fn fuse_mag_heading(
        &mut self,
        t_us: u64,
        mag: &Vector3<f32>,
        earth_ned: &Vector3<f32>,
        noise: f32,
        gate_sigma: f32,
    ) -> Fusion {
        let mut out = Fusion::default();
        let bh2 = earth_ned.x * earth_ned.x + earth_ned.y * earth_ned.y;
        if !self.attitude_ok || bh2 < 1e-6 {
            return out;
        }
        let m_ned = self.q.transform_vector(mag);
        if crate::math::elementary::hypot(m_ned.x, m_ned.y) < 1e-4 {
            return out;
        }
        let innov = crate::math::wrap_pi(
            libm::atan2f(earth_ned.y, earth_ned.x) - libm::atan2f(m_ned.y, m_ned.x),
        );
        let mut h = Vecn::zeros();
        h[ITH] = -earth_ned.z * earth_ned.x / bh2;
        h[ITH + 1] = -earth_ned.z * earth_ned.y / bh2;
        h[ITH + 2] = 1.0;
        let sigma = noise / libm::sqrtf(bh2);
        self.fuse_scalar(&h, innov, sigma * sigma, gate_sigma, t_us, &mut out);
        self.flush_shift();
        out
    }

    /// Fuses the accelerometer as a gravity reference: `accel` is the measured specific force
    /// and `motion` what the aircraft is known to be doing. Skipped (None) when the
    /// compensated specific force is further than `gate_mps2` from g: then the aircraft
    /// accelerates in a way the model does not know.
    pub fn fuse_gravity(
        &mut self,
        t_us: u64,
        accel: &Vector3<f32>,
        motion: &Motion,
        noise: f32,
        gate_mps2: f32,
        gate_sigma: f32,
    ) -> Option<Fusion> {
        if !self.attitude_ok {
            return None;
        }
        let v_air = &motion.v_air_body;
        let maneuver = motion.rates.cross(v_air) + motion.along_body;
        if libm::fabsf((accel - maneuver).norm() - GRAVITY) > gate_mps2 {
            return None;
        }
        let minus_g = Vector3::new(0.0, 0.0, -GRAVITY);
        // The centripetal term carries the bias error too: (w - db) x v = m + [v]x db. Left
        // out, a bias error would read as a tilt and feed itself.
        let bias_jac = v_air.cross_matrix();
        let mut out = Fusion::default();
        for axis in 0..3 {
            let rt = self.q.to_rotation_matrix().into_inner().transpose();
            let predicted = maneuver + rt * minus_g;
            let jac = rt * minus_g.cross_matrix();
            let mut h = Vecn::zeros();
            h.fixed_rows_mut::<3>(ITH)
                .copy_from(&jac.row(axis).transpose());
            h.fixed_rows_mut::<3>(IBG)
                .copy_from(&bias_jac.row(axis).transpose());
            let innov = accel[axis] - predicted[axis];
            self.fuse_scalar(&h, innov, noise * noise, gate_sigma, t_us, &mut out);
        }
        self.flush_shift();
        Some(out)
    }
}
