//! The plant's state: the integrated vector and its readable form.

use nalgebra::{SVector, UnitQuaternion, Vector3};

/// Number of numbers in the integrated state vector.
pub const STATE_LEN: usize = 14;
/// The integrated state vector:
/// `[pn, pe, pd, u, v, w, q0, q1, q2, q3, p, q, r, Omega]` (quaternion scalar first).
pub type StateVector = SVector<f64, STATE_LEN>;

/// The plant state in readable form.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct State {
    /// Position from the home point, NED, m.
    pub pos_ned: Vector3<f64>,
    /// Inertial velocity in body axes, m/s.
    pub vel_body: Vector3<f64>,
    /// Attitude, body to NED.
    pub attitude: UnitQuaternion<f64>,
    /// Body rates `(p, q, r)`, rad/s.
    pub omega_body: Vector3<f64>,
    /// Engine (motor and propeller) speed, rad/s.
    pub engine_speed: f64,
}

impl State {
    /// Packs the state into the integrated vector.
    pub fn to_vector(&self) -> StateVector {
        let q = self.attitude.quaternion();
        let mut x = StateVector::zeros();
        x.fixed_rows_mut::<3>(0).copy_from(&self.pos_ned);
        x.fixed_rows_mut::<3>(3).copy_from(&self.vel_body);
        x[6] = q.w;
        x[7] = q.i;
        x[8] = q.j;
        x[9] = q.k;
        x.fixed_rows_mut::<3>(10).copy_from(&self.omega_body);
        x[13] = self.engine_speed;
        x
    }

    /// Unpacks an integrated vector (normalising its quaternion).
    pub fn from_vector(x: &StateVector) -> Self {
        Self {
            pos_ned: x.fixed_rows::<3>(0).into_owned(),
            vel_body: x.fixed_rows::<3>(3).into_owned(),
            attitude: quat_of(x),
            omega_body: x.fixed_rows::<3>(10).into_owned(),
            engine_speed: x[13],
        }
    }
}

/// The unit quaternion of an integrated vector.
#[inline]
pub(crate) fn quat_of(x: &StateVector) -> UnitQuaternion<f64> {
    UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(x[6], x[7], x[8], x[9]))
}
