//! The model parameters in the form the hot path wants, derived once from the aircraft file.

use super::gear::GroundParams;
use crate::aircraft::{Aero, Aircraft, Propulsion};
use common::math::geodetic::GeoPoint;
use nalgebra::{Matrix3, Vector3};
use std::f64::consts::PI;

/// The model parameters in the form the hot path wants (derived quantities precomputed).
#[derive(Clone, Debug)]
pub struct ModelParams {
    /// Mass, kg.
    pub mass: f64,
    /// Inertia matrix, kg m^2.
    pub inertia: Matrix3<f64>,
    /// Its inverse.
    pub inertia_inv: Matrix3<f64>,
    /// Wing span, m.
    pub b: f64,
    /// Mean chord, m.
    pub c: f64,
    /// Wing area, m^2.
    pub s: f64,
    /// `1 / (pi AR e)`.
    pub induced_drag_factor: f64,
    /// Aerodynamic force point from the CG, m.
    pub aero_arm: Vector3<f64>,
    /// Thrust point from the CG, m.
    pub prop_arm: Vector3<f64>,
    /// Aerodynamic derivatives.
    pub aero: Aero,
    /// Propulsion data.
    pub prop: Propulsion,
    /// `(4 / pi^2) R^4`: thrust = `CT rho` times this times `Omega^2`.
    pub thrust_factor: f64,
    /// `(4 / pi^3) R^5`: propeller torque = `CP rho` times this times `Omega^2`.
    pub torque_factor: f64,
    /// Gravity, m/s^2.
    pub g: f64,
    /// Altitude above mean sea level of the NED origin, m.
    pub home_alt_msl_m: f64,
    /// Home point.
    pub home: GeoPoint,
    /// Landing gear and belly contact.
    pub ground: GroundParams,
}

impl ModelParams {
    /// Derives the hot-path parameters from a validated aircraft file.
    pub fn new(a: &Aircraft) -> Self {
        let m = &a.mass;
        let inertia = Matrix3::new(
            m.Jx_kgm2,
            0.0,
            -m.Jxz_kgm2,
            0.0,
            m.Jy_kgm2,
            0.0,
            -m.Jxz_kgm2,
            0.0,
            m.Jz_kgm2,
        );
        // Validation guarantees Jx Jz - Jxz^2 > 0 and positive diagonal: invertible.
        let inertia_inv = inertia.try_inverse().unwrap_or_else(Matrix3::identity);
        let g = &a.geometry;
        let ar = g.b_m * g.b_m / g.S_m2;
        let r = a.propulsion.prop_radius_m;
        Self {
            mass: m.mass_kg,
            inertia,
            inertia_inv,
            b: g.b_m,
            c: g.c_m,
            s: g.S_m2,
            induced_drag_factor: 1.0 / (PI * ar * a.aero.drag.oswald_e),
            aero_arm: Vector3::from(g.aero_arm_from_cg_m),
            prop_arm: Vector3::from(g.prop_arm_from_cg_m),
            aero: a.aero.clone(),
            prop: a.propulsion.clone(),
            thrust_factor: 4.0 / (PI * PI) * r.powi(4),
            torque_factor: 4.0 / (PI * PI * PI) * r.powi(5),
            g: a.environment.g_mps2,
            home_alt_msl_m: a.environment.home_alt_msl_m,
            home: GeoPoint::from_deg(a.environment.home_lat_deg, a.environment.home_lon_deg),
            ground: GroundParams::new(&a.ground),
        }
    }
}
