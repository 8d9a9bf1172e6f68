//! Beard and McLain's reduced models (*Small Unmanned Aircraft*, chapter 5): the coefficients
//! of their roll, pitch, airspeed and sideslip transfer functions, two ways.
//!
//! - [`from_linearization`] reads them off the linear model about a trim: each is the
//!   derivative the book's model keeps (`-A[p,p]` for `a_phi1`, the pitch acceleration per
//!   radian of angle of attack at constant airspeed for `a_theta2`, ...). The engine speed,
//!   a state here and an algebraic function of airspeed and throttle in the book, is
//!   eliminated as quasi-steady (its pole is an order of magnitude faster than the airspeed's).
//! - [`closed_form`] evaluates the book's expressions with the aircraft file's values at the
//!   trim: the dynamic pressure, the derivatives, the inertias, the drag coefficient at the
//!   trim, and the slopes of the steady thrust (the engine at its torque balance) in airspeed
//!   and throttle, as mavsim's `compute_tf_model` takes them.
//!
//! The two agree where the model is the book's; where they differ, the linear model holds
//! what the reduced model leaves out (`a_beta1`: the drag's share of the side force with
//! sideslip; `a_V1`, `a_V2`: the thrust's `cos alpha`).
//!
//! Signs follow the Minnesota convention of this model: a positive aileron rolls left, so
//! `a_phi2` is negative where the book's is positive.

use super::linearize::{ix, Linearization};
use super::trim::TrimResult;
use crate::aircraft::Aircraft;
use crate::plant::params::ModelParams;
use crate::plant::propulsion::{propulsion, steady_engine_speed};
use common::math::atmosphere::standard_atmosphere;
use serde::Serialize;

/// The reduced models' coefficients (B&M's names; rates in 1/s, accelerations per radian).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ReducedCoefficients {
    /// Roll damping, 1/s.
    pub a_phi1: f64,
    /// Roll acceleration per radian of combined aileron, 1/s^2.
    pub a_phi2: f64,
    /// Pitch damping, 1/s.
    pub a_theta1: f64,
    /// Pitch stiffness: pitch acceleration per radian of angle of attack, negated, 1/s^2.
    pub a_theta2: f64,
    /// Pitch acceleration per radian of elevator, 1/s^2.
    pub a_theta3: f64,
    /// Airspeed damping, 1/s.
    pub a_v1: f64,
    /// Airspeed acceleration per unit throttle, m/s^2.
    pub a_v2: f64,
    /// Airspeed acceleration per radian of pitch, negated, m/s^2.
    pub a_v3: f64,
    /// The flight path's pole behind the pitch (the heave damping, `-Z_w`: the angle of
    /// attack's rate per radian of it at constant airspeed, negated), 1/s.
    pub a_gamma: f64,
    /// Sideslip damping, 1/s.
    pub a_beta1: f64,
    /// Sideslip rate per radian of rudder, 1/s.
    pub a_beta2: f64,
}

impl ReducedCoefficients {
    /// Name and value of each coefficient, in the book's order.
    pub fn named(&self) -> [(&'static str, f64); 11] {
        [
            ("a_phi1", self.a_phi1),
            ("a_phi2", self.a_phi2),
            ("a_theta1", self.a_theta1),
            ("a_theta2", self.a_theta2),
            ("a_theta3", self.a_theta3),
            ("a_V1", self.a_v1),
            ("a_V2", self.a_v2),
            ("a_V3", self.a_v3),
            ("a_gamma", self.a_gamma),
            ("a_beta1", self.a_beta1),
            ("a_beta2", self.a_beta2),
        ]
    }
}

/// The coefficients the linear model about `trim` holds.
pub fn from_linearization(lin: &Linearization, trim: &TrimResult) -> ReducedCoefficients {
    let (a, b) = (&lin.a, &lin.b);
    let va = trim.target.va_mps;
    let (sa, ca) = trim.alpha.sin_cos();
    // The engine speed at its torque balance: x_dot = (A - a_O a_O^T / A_OO) x + ... .
    let om = ix::OMEGA;
    let a_oo = a[(om, om)];
    let quasi = |row: usize, col: usize| a[(row, col)] - a[(row, om)] * a[(om, col)] / a_oo;
    let quasi_b = |row: usize, input: usize| b[(row, input)] - a[(row, om)] * b[(om, input)] / a_oo;
    // Airspeed along (u, w) = Va (cos alpha, sin alpha); angle of attack across it.
    let va_dot = |col: &dyn Fn(usize) -> f64| ca * col(ix::U) + sa * col(ix::W);
    let a_v1 = -va_dot(&|r| ca * quasi(r, ix::U) + sa * quasi(r, ix::W));
    let a_v2 = va_dot(&|r| quasi_b(r, super::linearize::iu::THROTTLE));
    let a_v3 = -va_dot(&|r| quasi(r, ix::THETA));
    let q_per_alpha = va * (-sa * a[(ix::Q, ix::U)] + ca * a[(ix::Q, ix::W)]);
    // The angle of attack turned at constant airspeed, (du, dw) = Va (-sin, cos) dalpha, and
    // its rate read across the airspeed, (-sin, cos) (u', w') / Va.
    let turned = |r: usize| -sa * quasi(r, ix::U) + ca * quasi(r, ix::W);
    let alpha_dot_per_alpha = -sa * turned(ix::U) + ca * turned(ix::W);
    let lat = &lin.lat;
    // Lateral order v, p, r, phi, psi; inputs left aileron, right aileron, rudder.
    ReducedCoefficients {
        a_phi1: -lat.a[(1, 1)],
        a_phi2: lat.b[(1, 1)] - lat.b[(1, 0)],
        a_theta1: -a[(ix::Q, ix::Q)],
        a_theta2: -q_per_alpha,
        a_theta3: b[(ix::Q, super::linearize::iu::ELEVATOR)],
        a_v1,
        a_v2,
        a_v3,
        a_gamma: -alpha_dot_per_alpha,
        a_beta1: -lat.a[(0, 0)],
        a_beta2: lat.b[(0, 2)] / va,
    }
}

/// Thrust with the engine at its torque balance, N.
pub fn steady_thrust_n(p: &ModelParams, va: f64, throttle: f64, rho: f64) -> f64 {
    let omega = steady_engine_speed(p, va, throttle, rho);
    propulsion(p, va, omega, throttle, rho).thrust_n
}

/// Beard and McLain's closed-form coefficients with the aircraft file's values at `trim`.
pub fn closed_form(aircraft: &Aircraft, trim: &TrimResult) -> ReducedCoefficients {
    let p = ModelParams::new(aircraft);
    let rho = standard_atmosphere(trim.target.alt_msl_m).density;
    let va = trim.target.va_mps;
    let (m, geo, aero) = (&aircraft.mass, &aircraft.geometry, &aircraft.aero);
    let gamma = m.Jx_kgm2 * m.Jz_kgm2 - m.Jxz_kgm2 * m.Jxz_kgm2;
    let (g3, g4) = (m.Jz_kgm2 / gamma, m.Jxz_kgm2 / gamma);
    let c_p_p = g3 * aero.roll.Cl_p + g4 * aero.yaw.Cn_p;
    let c_p_da = g3 * aero.roll.Cl_da + g4 * aero.yaw.Cn_da;
    let qbar = 0.5 * rho * va * va;
    let (s, b, c) = (geo.S_m2, geo.b_m, geo.c_m);
    let pitch = qbar * s * c / m.Jy_kgm2;
    // The drag coefficient at the trim, as the model computes it (rates zero at level trim).
    let air = common::math::AirData {
        va,
        alpha: trim.alpha,
        beta: trim.beta,
    };
    let cd = crate::plant::aero::coefficients(
        &p,
        &air,
        &nalgebra::Vector3::new(trim.p, trim.q, trim.r),
        &trim.controls,
    )
    .cd;
    // Slopes of the steady thrust by central differences, as mavsim's dT_dVa, dT_ddelta_t.
    let (hv, ht) = (0.01, 0.001);
    let t = trim.throttle;
    let dt_dva =
        (steady_thrust_n(&p, va + hv, t, rho) - steady_thrust_n(&p, va - hv, t, rho)) / (2.0 * hv);
    let dt_dthr =
        (steady_thrust_n(&p, va, t + ht, rho) - steady_thrust_n(&p, va, t - ht, rho)) / (2.0 * ht);
    let mass = m.mass_kg;
    ReducedCoefficients {
        a_phi1: -0.25 * rho * va * s * b * b * c_p_p,
        a_phi2: qbar * s * b * c_p_da,
        a_theta1: -pitch * aero.pitch.Cm_q * c / (2.0 * va),
        a_theta2: -pitch * aero.pitch.Cm_alpha,
        a_theta3: pitch * aero.pitch.Cm_de,
        a_v1: rho * va * s * cd / mass - dt_dva / mass,
        a_v2: dt_dthr / mass,
        a_v3: aircraft.environment.g_mps2 * (trim.theta - trim.alpha).cos(),
        a_gamma: rho * va * s * (aero.lift.CL_alpha + cd) / (2.0 * mass),
        a_beta1: -rho * va * s * aero.side.CY_beta / (2.0 * mass),
        a_beta2: rho * va * s * aero.side.CY_dr / (2.0 * mass),
    }
}
