//! Flat-earth rigid-body equations of motion with the engine-speed state.

use super::inputs::{Controls, Environment};
use super::params::ModelParams;
use super::state::{quat_of, StateVector};
use super::{aero, ground, propulsion};
use common::math::atmosphere::standard_atmosphere;
use common::math::{body_to_ned, ned_to_body, AirData};
use nalgebra::{Quaternion, Vector3};

/// Everything one model evaluation produces.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Derivatives {
    /// Time derivative of the integrated state vector.
    pub x_dot: StateVector,
    /// Non-gravitational force / mass in body axes, m/s^2 (accelerometer reading).
    pub specific_force_body: Vector3<f64>,
    /// Aerodynamic force, body axes, N.
    pub aero_force_body: Vector3<f64>,
    /// Aerodynamic moment about the CG, body axes, N m.
    pub aero_moment_body: Vector3<f64>,
    /// Propulsion force, body axes, N.
    pub prop_force_body: Vector3<f64>,
    /// Propulsion moment about the CG, body axes, N m.
    pub prop_moment_body: Vector3<f64>,
    /// Ground contact (forces, moment, per-point loads; zero in the air).
    pub ground: ground::GroundContact,
    /// Propulsion details (thrust, torques).
    pub propulsion: propulsion::PropulsionOutput,
    /// Air data relative to the air mass.
    pub air: AirData<f64>,
    /// Air density, kg/m^3.
    pub rho: f64,
}

/// Air data of the body velocity relative to the wind.
pub fn air_data(x: &StateVector, env: &Environment) -> AirData<f64> {
    let q = quat_of(x);
    let v_body = Vector3::new(x[3], x[4], x[5]);
    AirData::from_body_velocity(&(v_body - ned_to_body(&q, &env.wind_ned)))
}

/// Only the state derivative (the integrator's hot path).
#[inline]
pub fn state_derivative(
    p: &ModelParams,
    x: &StateVector,
    c: &Controls,
    env: &Environment,
) -> StateVector {
    derivatives(p, x, c, env).x_dot
}

/// Evaluates the model at one state and input.
pub fn derivatives(
    p: &ModelParams,
    x: &StateVector,
    c: &Controls,
    env: &Environment,
) -> Derivatives {
    let quat = quat_of(x);
    let v_body = Vector3::new(x[3], x[4], x[5]);
    let omega = Vector3::new(x[10], x[11], x[12]);
    let engine_speed = x[13];

    let rho = standard_atmosphere(p.home_alt_msl_m - x[2]).density;
    let air = AirData::from_body_velocity(&(v_body - ned_to_body(&quat, &env.wind_ned)));

    let (fa, ma) = aero::forces_and_moments(p, &air, &omega, c, rho);
    let prop = propulsion::propulsion(p, air.va, engine_speed, c.throttle, rho);
    let (fp, mp) = propulsion::forces_and_moments(p, &prop, &omega, engine_speed);

    let gc = ground::contact(p, x, c);

    let specific_force_body = (fa + fp + gc.force_body) / p.mass;
    let gravity_body = ned_to_body(&quat, &Vector3::new(0.0, 0.0, p.g));
    let v_dot = specific_force_body + gravity_body - omega.cross(&v_body);
    let moment = ma + mp + gc.moment_body;
    let omega_dot = p.inertia_inv * (moment - omega.cross(&(p.inertia * omega)));
    let pos_dot = body_to_ned(&quat, &v_body);
    // Kinematics of the raw (not yet renormalised) quaternion: q_dot = q (x) (0, omega) / 2.
    let qr = Quaternion::new(x[6], x[7], x[8], x[9]);
    let q_dot = qr * Quaternion::from_imag(omega) * 0.5;

    let mut x_dot = StateVector::zeros();
    x_dot.fixed_rows_mut::<3>(0).copy_from(&pos_dot);
    x_dot.fixed_rows_mut::<3>(3).copy_from(&v_dot);
    x_dot[6] = q_dot.w;
    x_dot[7] = q_dot.i;
    x_dot[8] = q_dot.j;
    x_dot[9] = q_dot.k;
    x_dot.fixed_rows_mut::<3>(10).copy_from(&omega_dot);
    x_dot[13] = prop.engine_accel;
    Derivatives {
        x_dot,
        specific_force_body,
        aero_force_body: fa,
        aero_moment_body: ma,
        prop_force_body: fp,
        prop_moment_body: mp,
        ground: gc,
        propulsion: prop,
        air,
        rho,
    }
}

/// Renormalises the quaternion and saturates the engine speed after an integration step.
pub fn normalise(x: &mut StateVector, p: &ModelParams) {
    let n = (x[6] * x[6] + x[7] * x[7] + x[8] * x[8] + x[9] * x[9]).sqrt();
    if n > 0.0 && n.is_finite() {
        for i in 6..10 {
            x[i] /= n;
        }
    }
    let [lo, hi] = p.prop.omega_limits_radps;
    x[13] = x[13].clamp(lo, hi);
}
