//! The electric motor and propeller, with the engine speed as a state.

use super::params::ModelParams;
use nalgebra::Vector3;
use std::f64::consts::PI;

/// What the propulsion produces at one instant.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PropulsionOutput {
    /// Thrust along body x, N.
    pub thrust_n: f64,
    /// Motor torque, N m.
    pub motor_torque_nm: f64,
    /// Propeller (aerodynamic) torque, N m.
    pub prop_torque_nm: f64,
    /// Engine-speed derivative, rad/s^2.
    pub engine_accel: f64,
    /// Advance ratio after clamping.
    pub advance_ratio: f64,
}

/// Horner evaluation of a polynomial stored highest power first.
#[inline]
pub fn polyval<const N: usize>(coeffs: &[f64; N], x: f64) -> f64 {
    coeffs.iter().fold(0.0, |acc, c| acc * x + c)
}

/// Shaft power the motor delivers at `throttle` (0..1), W: the UMN power curve, clamped.
pub fn motor_power_w(p: &ModelParams, throttle: f64) -> f64 {
    let pr = &p.prop;
    polyval(&pr.motor_power_poly_throttle_W, throttle)
        .clamp(pr.motor_power_clamp_W[0], pr.motor_power_clamp_W[1])
}

/// Thrust, torques and engine acceleration at airspeed `va`, engine speed `omega` and `throttle`.
pub fn propulsion(
    p: &ModelParams,
    va: f64,
    omega: f64,
    throttle: f64,
    rho: f64,
) -> PropulsionOutput {
    let pr = &p.prop;
    let [om_lo, om_hi] = pr.omega_limits_radps;
    let omega_c = omega.clamp(om_lo, om_hi);
    let j = (PI * va / (omega_c * pr.prop_radius_m)).clamp(pr.J_clamp[0], pr.J_clamp[1]);
    let ct = polyval(&pr.CT_poly_J, j);
    let cp = polyval(&pr.CP_poly_J, j);
    let w2 = omega * omega;
    let thrust_n = ct * rho * p.thrust_factor * w2;
    let prop_torque_nm = cp * rho * p.torque_factor * w2;
    let power_w = motor_power_w(p, throttle);
    let motor_torque_nm = power_w / omega_c;
    PropulsionOutput {
        thrust_n,
        motor_torque_nm,
        prop_torque_nm,
        engine_accel: (motor_torque_nm - prop_torque_nm) / pr.Jmp_kgm2,
        advance_ratio: j,
    }
}

/// Body force (N) and moment about the CG (N m) of the propulsion.
///
/// The roll torque `2 Qm - Qp` is the Simulink wiring (it equals the reaction `Qp` at steady
/// engine speed); the gyroscopic term is `omega_body x [Jmp Omega, 0, 0]` as wired there.
pub fn forces_and_moments(
    p: &ModelParams,
    out: &PropulsionOutput,
    omega_body: &Vector3<f64>,
    engine_speed: f64,
) -> (Vector3<f64>, Vector3<f64>) {
    let force = Vector3::new(out.thrust_n, 0.0, 0.0);
    let moment = p.prop_arm.cross(&force)
        + Vector3::new(2.0 * out.motor_torque_nm - out.prop_torque_nm, 0.0, 0.0)
        + omega_body.cross(&Vector3::new(p.prop.Jmp_kgm2 * engine_speed, 0.0, 0.0));
    (force, moment)
}
