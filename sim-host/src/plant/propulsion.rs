//! The electric motor and propeller, with the engine speed as a state.
//!
//! Two motor laws: the Minnesota shaft-power curve in throttle, and Beard and McLain's DC motor
//! (torque falling with speed through the back-EMF). With the DC motor the engine speed at which
//! motor and propeller torques balance is the root of Beard and McLain's quadratic in `Omega`,
//! so a trim reproduces their steady propulsion; the engine-speed state adds the spin-up lag
//! their model leaves out.

use super::params::{ModelParams, Motor};
use crate::aircraft::PropSpin;
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

/// Shaft power the motor delivers at `throttle` (0..1) and engine speed `omega` (rad/s), W:
/// the UMN power curve, clamped (it does not depend on the speed), or the DC motor's torque
/// times the speed (none while the propeller drives the motor: no regeneration into the pack).
pub fn motor_power_w(p: &ModelParams, throttle: f64, omega: f64) -> f64 {
    match p.motor {
        Motor::PowerCurve { poly_w, clamp_w } => {
            polyval(&poly_w, throttle).clamp(clamp_w[0], clamp_w[1])
        }
        Motor::Dc { .. } => {
            let [lo, hi] = p.prop.omega_limits_radps;
            let omega_c = omega.clamp(lo, hi);
            (motor_torque_nm(p, throttle, omega_c) * omega_c).max(0.0)
        }
    }
}

/// Motor torque at `throttle` and the (clamped, positive) engine speed `omega_c`, N m.
fn motor_torque_nm(p: &ModelParams, throttle: f64, omega_c: f64) -> f64 {
    match p.motor {
        Motor::PowerCurve { poly_w, clamp_w } => {
            polyval(&poly_w, throttle).clamp(clamp_w[0], clamp_w[1]) / omega_c
        }
        Motor::Dc {
            kq,
            r_ohm,
            i0_a,
            v_max,
        } => kq * ((throttle * v_max - kq * omega_c) / r_ohm - i0_a),
    }
}

/// The engine speed at which motor and propeller torques balance at airspeed `va` and
/// `throttle`, rad/s (bisection within the engine's limits: the net torque falls with the
/// speed; a limit when it does not cross zero inside them).
pub fn steady_engine_speed(p: &ModelParams, va: f64, throttle: f64, rho: f64) -> f64 {
    let [mut lo, mut hi] = p.prop.omega_limits_radps;
    for _ in 0..80 {
        let mid = 0.5 * (lo + hi);
        if propulsion(p, va, mid, throttle, rho).engine_accel > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
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
    let cq = polyval(&p.torque_poly, j);
    let w2 = omega * omega;
    let thrust_n = ct * rho * p.thrust_factor * w2;
    let prop_torque_nm = cq * rho * p.torque_factor * w2;
    let motor_torque_nm = motor_torque_nm(p, throttle, omega_c);
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
/// engine speed); the gyroscopic term is `omega_body x [Jmp Omega, 0, 0]` as wired there. A
/// propeller turning the other way ([`PropSpin::RightHand`]) has both mirrored.
pub fn forces_and_moments(
    p: &ModelParams,
    out: &PropulsionOutput,
    omega_body: &Vector3<f64>,
    engine_speed: f64,
) -> (Vector3<f64>, Vector3<f64>) {
    let force = Vector3::new(out.thrust_n, 0.0, 0.0);
    let roll = Vector3::new(2.0 * out.motor_torque_nm - out.prop_torque_nm, 0.0, 0.0);
    let gyro = omega_body.cross(&Vector3::new(p.prop.Jmp_kgm2 * engine_speed, 0.0, 0.0));
    // Summed in the Minnesota order, so the built-in aircraft's moments keep every bit.
    let moment = match p.spin {
        PropSpin::Minnesota => p.prop_arm.cross(&force) + roll + gyro,
        PropSpin::RightHand => p.prop_arm.cross(&force) - roll - gyro,
    };
    (force, moment)
}
