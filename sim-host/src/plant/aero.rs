//! Aerodynamic forces and moments of the Minnesota linear-derivative model.
//!
//! Lift, drag and side force are wind-axis coefficients rotated into body axes by
//! `C_bw(alpha, beta)`; the rolling, pitching and yawing coefficients are used directly as
//! body-axis moments (as the Simulink model wires them), plus the moment of the aerodynamic
//! force about the CG through the 4.5 mm arm.

use super::inputs::Controls;
use super::params::ModelParams;
use common::math::{wind_to_body, AirData};
use nalgebra::Vector3;

/// Aerodynamic coefficients at one flight condition (for reports and tests).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct AeroCoefficients {
    /// Lift (wind axes).
    pub cl: f64,
    /// Drag (wind axes).
    pub cd: f64,
    /// Side force (wind axes).
    pub cy: f64,
    /// Rolling moment (body axes).
    pub c_roll: f64,
    /// Pitching moment (body axes).
    pub c_pitch: f64,
    /// Yawing moment (body axes).
    pub c_yaw: f64,
}

/// Nondimensional coefficients of the air data, body rates and surfaces.
///
/// `va_floor` keeps the rate nondimensionalisation finite at zero airspeed (where the dynamic
/// pressure, and so the force, vanishes anyway).
pub fn coefficients(
    p: &ModelParams,
    air: &AirData<f64>,
    omega_body: &Vector3<f64>,
    c: &Controls,
) -> AeroCoefficients {
    let va = air.va.max(0.1);
    let half_b_over_va = 0.5 * p.b / va;
    let p_hat = omega_body.x * half_b_over_va;
    let q_hat = omega_body.y * 0.5 * p.c / va;
    let r_hat = omega_body.z * half_b_over_va;
    let (al, ar) = (c.aileron_left, c.aileron_right);
    let (fl, fr) = (c.flap_left, c.flap_right);
    let d = &p.aero;
    let cl = d.lift.CL0
        + d.lift.CL_alpha * air.alpha
        + d.lift.CL_q * q_hat
        + d.lift.CL_de * c.elevator
        + 0.5 * d.lift.CL_da * (al + ar)
        + 0.5 * d.lift.CL_df * (fl + fr);
    let dl = cl - d.drag.CL_at_CD_min;
    let cd = d.drag.CD_min
        + dl * dl * p.induced_drag_factor
        + (d.drag.CD_de * c.elevator).abs()
        + (0.5 * d.drag.CD_da * al).abs()
        + (0.5 * d.drag.CD_da * ar).abs()
        + (d.drag.CD_dr * c.rudder).abs()
        + (0.5 * d.drag.CD_df * fl).abs()
        + (0.5 * d.drag.CD_df * fr).abs();
    let cy = d.side.CY_beta * air.beta
        + d.side.CY_p * p_hat
        + d.side.CY_r * r_hat
        + d.side.CY_dr * c.rudder
        + 0.5 * d.side.CY_da * (al - ar);
    let c_roll = d.roll.Cl_beta * air.beta
        + d.roll.Cl_p * p_hat
        + d.roll.Cl_r * r_hat
        + 0.5 * d.roll.Cl_da * (ar - al)
        + d.roll.Cl_dr * c.rudder
        + 0.5 * d.roll.Cl_df * (fr - fl);
    let c_pitch = d.pitch.Cm0
        + d.pitch.Cm_alpha * air.alpha
        + d.pitch.Cm_q * q_hat
        + d.pitch.Cm_de * c.elevator
        + 0.5 * d.pitch.Cm_da * (al + ar)
        + 0.5 * d.pitch.Cm_df * (fl + fr);
    let c_yaw = d.yaw.Cn_beta * air.beta
        + d.yaw.Cn_p * p_hat
        + d.yaw.Cn_r * r_hat
        + 0.5 * d.yaw.Cn_da * (ar - al)
        + d.yaw.Cn_dr * c.rudder
        + 0.5 * d.yaw.Cn_df * (fr - fl);
    AeroCoefficients {
        cl,
        cd,
        cy,
        c_roll,
        c_pitch,
        c_yaw,
    }
}

/// Body-axis aerodynamic force (N) and moment about the CG (N m).
pub fn forces_and_moments(
    p: &ModelParams,
    air: &AirData<f64>,
    omega_body: &Vector3<f64>,
    c: &Controls,
    rho: f64,
) -> (Vector3<f64>, Vector3<f64>) {
    let k = coefficients(p, air, omega_body, c);
    let qbar_s = 0.5 * rho * air.va * air.va * p.s;
    let force = wind_to_body(air.alpha, air.beta) * Vector3::new(-k.cd, k.cy, -k.cl) * qbar_s;
    let moment = Vector3::new(p.b * k.c_roll, p.c * k.c_pitch, p.b * k.c_yaw) * qbar_s
        + p.aero_arm.cross(&force);
    (force, moment)
}
