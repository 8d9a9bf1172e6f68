//! The model parameters in the form the hot path wants, derived once from the aircraft file.

use super::gear::GroundParams;
use crate::aircraft::{Aero, Aircraft, PropSpin, Propulsion};
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
    /// The propeller's torque polynomial in the advance ratio: `CP_poly_J` or `CQ_poly_J`.
    pub torque_poly: [f64; 5],
    /// Propeller torque = `torque_poly(J) rho` times this times `Omega^2`: `(4 / pi^3) R^5`
    /// for a power coefficient (`Qp = CP rho n^3 D^5 / Omega`), `(8 / pi^2) R^5` for a torque
    /// coefficient (`Qp = CQ rho n^2 D^5`).
    pub torque_factor: f64,
    /// The motor.
    pub motor: Motor,
    /// Which way the propeller turns.
    pub spin: PropSpin,
    /// Gravity, m/s^2.
    pub g: f64,
    /// Altitude above mean sea level of the NED origin, m.
    pub home_alt_msl_m: f64,
    /// Home point.
    pub home: GeoPoint,
    /// Landing gear and belly contact.
    pub ground: GroundParams,
}

/// The motor's law, from the aircraft file's `[propulsion]` table.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Motor {
    /// Shaft power in throttle (highest power first), clamped, W: torque `P / Omega`.
    PowerCurve {
        /// Polynomial in throttle, W.
        poly_w: [f64; 3],
        /// Clamp, W.
        clamp_w: [f64; 2],
    },
    /// DC motor: torque `kq ((throttle v_max - kq Omega) / r - i0)`.
    Dc {
        /// Torque (and back-EMF) constant, N m/A.
        kq: f64,
        /// Winding resistance, ohm.
        r_ohm: f64,
        /// No-load current, A.
        i0_a: f64,
        /// Voltage at full throttle, V.
        v_max: f64,
    },
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
        let pr = &a.propulsion;
        // Validation leaves exactly one of CP and CQ, and one motor; the fallbacks only keep an
        // unvalidated file from panicking.
        let (torque_poly, torque_factor) = match (pr.CP_poly_J, pr.CQ_poly_J) {
            (Some(cp), _) => (cp, 4.0 / (PI * PI * PI) * r.powi(5)),
            (None, Some(cq)) => (cq, 8.0 / (PI * PI) * r.powi(5)),
            (None, None) => ([0.0; 5], 0.0),
        };
        let motor = match (&pr.dc_motor, pr.motor_power_poly_throttle_W) {
            (Some(m), _) => Motor::Dc {
                kq: m.kq_nm_per_a(),
                r_ohm: m.resistance_ohm,
                i0_a: m.no_load_current_A,
                v_max: m.max_voltage_V,
            },
            (None, poly) => Motor::PowerCurve {
                poly_w: poly.unwrap_or([0.0; 3]),
                clamp_w: pr.motor_power_clamp_W.unwrap_or([0.0, 0.0]),
            },
        };
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
            torque_poly,
            torque_factor,
            motor,
            spin: a.propulsion.spin,
            g: a.environment.g_mps2,
            home_alt_msl_m: a.environment.home_alt_msl_m,
            home: GeoPoint::from_deg(a.environment.home_lat_deg, a.environment.home_lon_deg),
            ground: GroundParams::new(&a.ground),
        }
    }
}
