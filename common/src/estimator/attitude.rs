//! Attitude and gyro bias: a multiplicative (error-state) extended Kalman filter.
//!
//! Nominal state: the body-to-NED quaternion `q` and the gyro bias `b`. Error state (6): a
//! small rotation `dtheta` expressed in NED (`R_true = (I + [dtheta]x) R`) and the bias error.
//! Expressing the error in NED keeps the heading error a single component (`dtheta.z`) that
//! the accelerometer cannot see and the magnetometer does.
//!
//! - Propagation: `q <- q * exp((gyro - b) dt)`; `d(dtheta)/dt = -R (db + n_gyro)`.
//! - Gravity reference: the accelerometer reads `f = a_body - R^T g`, with the manoeuvre
//!   acceleration `a_body = omega x v_air_body` (a coordinated turn or pull-up) supplied by
//!   the caller; `H = R^T [-g]x`.
//! - Magnetometer: `m = R^T B_earth`; `H = R^T [B_earth]x`.

use super::kalman::{condition, scalar_update, Fused, Refused};
use crate::math::frames::Euler;
use nalgebra::{Matrix3, SMatrix, SVector, UnitQuaternion, Vector3};

/// Standard gravity used for the gravity reference, m/s^2.
pub const GRAVITY: f32 = 9.80665;

type Mat6 = SMatrix<f32, 6, 6>;
type Vec6 = SVector<f32, 6>;

/// Initial 1-sigma roll/pitch uncertainty (the accelerometer levelling is good to a few deg).
const INIT_TILT_SIGMA: f32 = 0.1;
/// Initial 1-sigma heading uncertainty.
const INIT_YAW_SIGMA: f32 = 0.3;

/// The aircraft's motion as the gravity reference needs it: its acceleration is the
/// centripetal `rates x v_air_body` of a turn or pull-up plus `along_body`, the acceleration
/// along the flight path (airspeed changes).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Motion {
    /// Bias-corrected body rates, rad/s.
    pub rates: Vector3<f32>,
    /// Air-relative velocity in body axes, m/s.
    pub v_air_body: Vector3<f32>,
    /// Acceleration along the flight path in body axes, m/s^2.
    pub along_body: Vector3<f32>,
}

/// How one vector measurement went.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct VectorFusion {
    /// Components fused.
    pub fused: u8,
    /// Components refused by the innovation gate.
    pub gated: u8,
    /// Mean normalised innovation squared of the fused components.
    pub nis: f32,
}

/// The multiplicative EKF for attitude and gyro bias.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AttitudeEkf {
    q: UnitQuaternion<f32>,
    bias: Vector3<f32>,
    p: Mat6,
    initialized: bool,
}

impl Default for AttitudeEkf {
    fn default() -> Self {
        Self::new()
    }
}

impl AttitudeEkf {
    /// An uninitialised filter (level, north, zero bias).
    pub fn new() -> Self {
        Self {
            q: UnitQuaternion::identity(),
            bias: Vector3::zeros(),
            p: Mat6::identity(),
            initialized: false,
        }
    }

    /// True once [`AttitudeEkf::initialize`] has succeeded.
    pub fn is_initialized(&self) -> bool {
        self.initialized
    }

    /// Body-to-NED attitude.
    pub fn attitude(&self) -> UnitQuaternion<f32> {
        self.q
    }

    /// Estimated gyro bias, rad/s.
    pub fn gyro_bias(&self) -> Vector3<f32> {
        self.bias
    }

    /// 1-sigma roll/pitch (combined) and heading uncertainty, rad.
    pub fn tilt_heading_sigma(&self) -> (f32, f32) {
        (
            libm::sqrtf(self.p[(0, 0)] + self.p[(1, 1)]),
            libm::sqrtf(self.p[(2, 2)]),
        )
    }

    /// 1-sigma uncertainty of each bias component, rad/s.
    pub fn bias_sigma(&self) -> Vector3<f32> {
        Vector3::new(
            libm::sqrtf(self.p[(3, 3)]),
            libm::sqrtf(self.p[(4, 4)]),
            libm::sqrtf(self.p[(5, 5)]),
        )
    }

    /// Levels from the specific force and takes the heading from the magnetometer (tilt
    /// compensated, against the earth field `earth_ned`). Returns false, and stays
    /// uninitialised, when the vectors are too short to define an attitude.
    pub fn initialize(
        &mut self,
        accel: &Vector3<f32>,
        mag: &Vector3<f32>,
        earth_ned: &Vector3<f32>,
        bias_sigma: f32,
    ) -> bool {
        let horizontal_earth = libm::hypotf(earth_ned.x, earth_ned.y);
        if accel.norm() < 0.5 * GRAVITY || mag.norm() < 1e-3 || horizontal_earth < 1e-3 {
            return false;
        }
        // At rest or in steady flight the accelerometer reads -g rotated into the body.
        let phi = libm::atan2f(-accel.y, -accel.z);
        let theta = libm::atan2f(accel.x, libm::hypotf(accel.y, accel.z));
        let tilt = Euler::new(phi, theta, 0.0).to_quaternion();
        let m_level = tilt.transform_vector(mag);
        let psi = libm::atan2f(earth_ned.y, earth_ned.x) - libm::atan2f(m_level.y, m_level.x);
        let q = Euler::new(phi, theta, crate::math::wrap_pi(psi)).to_quaternion();
        if !q.coords.iter().all(|c| c.is_finite()) {
            return false;
        }
        self.q = q;
        self.bias = Vector3::zeros();
        self.p = Self::initial_covariance(bias_sigma);
        self.initialized = true;
        true
    }

    fn initial_covariance(bias_sigma: f32) -> Mat6 {
        let t = INIT_TILT_SIGMA * INIT_TILT_SIGMA;
        let b = bias_sigma * bias_sigma;
        Mat6::from_diagonal(&Vec6::new(t, t, INIT_YAW_SIGMA * INIT_YAW_SIGMA, b, b, b))
    }

    /// Propagates attitude and covariance over `dt` with a gyro sample.
    ///
    /// `gyro_noise` is the rate-noise density (rad/s/sqrt(Hz)) and `bias_rw` the bias random
    /// walk density (rad/s^2/sqrt(Hz)).
    pub fn predict(&mut self, gyro: &Vector3<f32>, dt: f32, gyro_noise: f32, bias_rw: f32) {
        if !self.initialized {
            return;
        }
        let omega = gyro - self.bias;
        let dq = UnitQuaternion::from_scaled_axis(omega * dt);
        let q = self.q * dq;
        let r = self.q.to_rotation_matrix().into_inner();
        // Phi = [[I, -R dt], [0, I]]
        let mut phi = Mat6::identity();
        phi.fixed_view_mut::<3, 3>(0, 3).copy_from(&(-r * dt));
        let mut qd = Mat6::zeros();
        let g = gyro_noise * gyro_noise * dt;
        let b = bias_rw * bias_rw * dt;
        qd.fixed_view_mut::<3, 3>(0, 0)
            .copy_from(&(Matrix3::identity() * g));
        qd.fixed_view_mut::<3, 3>(3, 3)
            .copy_from(&(Matrix3::identity() * b));
        let p = phi * self.p * phi.transpose() + qd;
        self.commit(q, self.bias, p);
    }

    /// Fuses the accelerometer as a gravity reference.
    ///
    /// `accel` is the measured specific force and `motion` what the aircraft is known to be
    /// doing, from which its acceleration is formed. `noise` is the per-axis standard
    /// deviation. The update is skipped when the compensated specific force is further than
    /// `gate_mps2` from g: then the aircraft accelerates in a way the model does not know.
    pub fn fuse_accel(
        &mut self,
        accel: &Vector3<f32>,
        motion: &Motion,
        noise: f32,
        gate_mps2: f32,
        gate_sigma: f32,
    ) -> Option<VectorFusion> {
        if !self.initialized {
            return None;
        }
        let v_air_body = &motion.v_air_body;
        let maneuver_body = motion.rates.cross(v_air_body) + motion.along_body;
        let gravity_part = accel - maneuver_body;
        if libm::fabsf(gravity_part.norm() - GRAVITY) > gate_mps2 {
            return None;
        }
        let minus_g = Vector3::new(0.0, 0.0, -GRAVITY);
        // The centripetal term carries the bias error too: (omega - db) x v = m + [v]x db.
        let bias_jac = v_air_body.cross_matrix();
        Some(self.fuse_vector(
            accel,
            &maneuver_body,
            &minus_g,
            &bias_jac,
            noise,
            gate_sigma,
        ))
    }

    /// Fuses a magnetometer sample against the earth field `earth_ned` (gauss).
    pub fn fuse_mag(
        &mut self,
        mag: &Vector3<f32>,
        earth_ned: &Vector3<f32>,
        noise: f32,
        gate_sigma: f32,
    ) -> Option<VectorFusion> {
        if !self.initialized {
            return None;
        }
        Some(self.fuse_vector(
            mag,
            &Vector3::zeros(),
            earth_ned,
            &Matrix3::zeros(),
            noise,
            gate_sigma,
        ))
    }

    /// Fuses `z = offset + R^T u` (with `d offset / d bias = bias_jac`) one component at a
    /// time, re-linearising after each.
    fn fuse_vector(
        &mut self,
        z: &Vector3<f32>,
        offset: &Vector3<f32>,
        u_ned: &Vector3<f32>,
        bias_jac: &Matrix3<f32>,
        noise: f32,
        gate_sigma: f32,
    ) -> VectorFusion {
        let mut out = VectorFusion::default();
        let r_meas = noise * noise;
        let mut nis_sum = 0.0;
        for axis in 0..3 {
            let rt = self.q.to_rotation_matrix().into_inner().transpose();
            let predicted = offset + rt * u_ned;
            let jac = rt * u_ned.cross_matrix();
            let mut h = Vec6::zeros();
            h.fixed_rows_mut::<3>(0)
                .copy_from(&jac.row(axis).transpose());
            h.fixed_rows_mut::<3>(3)
                .copy_from(&bias_jac.row(axis).transpose());
            let innov = z[axis] - predicted[axis];
            let mut p = self.p;
            match scalar_update(&mut p, &h, innov, r_meas, gate_sigma) {
                Ok(Fused { dx, nis }) => {
                    let dtheta = Vector3::new(dx[0], dx[1], dx[2]);
                    let db = Vector3::new(dx[3], dx[4], dx[5]);
                    let q = UnitQuaternion::from_scaled_axis(dtheta) * self.q;
                    if self.commit(q, self.bias + db, p) {
                        out.fused += 1;
                        nis_sum += nis;
                    }
                }
                Err(Refused::Gated) => out.gated += 1,
                Err(Refused::Degenerate) => {}
            }
        }
        if out.fused > 0 {
            out.nis = nis_sum / f32::from(out.fused);
        }
        out
    }

    /// Accepts a new state only when everything in it is finite; the covariance is kept
    /// symmetric and bounded. Returns whether the state was accepted.
    fn commit(&mut self, q: UnitQuaternion<f32>, bias: Vector3<f32>, mut p: Mat6) -> bool {
        let q = UnitQuaternion::new_normalize(q.into_inner());
        let finite = q.coords.iter().all(|c| c.is_finite()) && bias.iter().all(|c| c.is_finite());
        if !finite || !condition(&mut p, 1e-12, 10.0) {
            return false;
        }
        self.q = q;
        self.bias = bias;
        self.p = p;
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn initialises_from_gravity_and_field() {
        let truth = Euler::new(0.2_f32, -0.1, 2.0);
        let q = truth.to_quaternion();
        let earth = Vector3::new(0.18, -0.01, 0.52);
        let accel = q.inverse_transform_vector(&Vector3::new(0.0, 0.0, -GRAVITY));
        let mag = q.inverse_transform_vector(&earth);
        let mut f = AttitudeEkf::new();
        assert!(!f.initialize(&Vector3::zeros(), &mag, &earth, 0.05));
        assert!(f.initialize(&accel, &mag, &earth, 0.05));
        let e = Euler::from_quaternion(&f.attitude());
        assert!((e.phi - 0.2).abs() < 1e-4);
        assert!((e.theta + 0.1).abs() < 1e-4);
        assert!((e.psi - 2.0).abs() < 1e-4);
    }

    #[test]
    fn accelerometer_corrects_a_roll_error() {
        let earth = Vector3::new(0.18, -0.01, 0.52);
        let truth = UnitQuaternion::identity();
        let accel = Vector3::new(0.0, 0.0, -GRAVITY);
        let mag = truth.inverse_transform_vector(&earth);
        let mut f = AttitudeEkf::new();
        assert!(f.initialize(&accel, &mag, &earth, 0.05));
        // Knock the estimate 5 deg off in roll; the gravity reference must pull it back.
        f.q = Euler::new(0.087_f32, 0.0, 0.0).to_quaternion();
        for _ in 0..500 {
            f.predict(&Vector3::zeros(), 0.02, 0.0015, 5e-5);
            f.fuse_accel(&accel, &Motion::default(), 0.7, 2.5, 100.0);
        }
        let e = Euler::from_quaternion(&f.attitude());
        assert!(e.phi.abs() < 0.005, "roll {}", e.phi);
    }
}
