//! The nonlinear plant: the University of Minnesota Ultra Stick 25e model, in f64.
//!
//! Block diagram, one module per block:
//! ```text
//! Controls ──► aero (wind-axis forces, body-axis moments) ──┐
//!          └─► propulsion (engine-speed state Omega) ───────┤
//! Environment (wind, US1976 density) ───────────────────────┤
//!                                                           ▼
//!                          dynamics (flat-earth 6-DOF rigid body) ──► integrator (RK4)
//! ```
//! [`servo`] models the surface servos; simulations put it in front of the plant, trim and
//! linearisation do not.
//!
//! State (13 degrees of freedom, 14 numbers): NED position, body velocity, attitude quaternion
//! (body to NED), body rates, engine speed Omega.

pub mod aero;
pub mod dynamics;
pub mod integrator;
pub mod propulsion;
pub mod servo;

use crate::aircraft::{Aero, Aircraft, Propulsion};
use common::actuators::Surfaces;
use common::math::geodetic::{offset_point, GeoPoint};
use common::math::{body_to_ned, AirData, Euler};
use nalgebra::{Matrix3, SVector, UnitQuaternion, Vector3};
use std::f64::consts::PI;

pub use dynamics::Derivatives;
pub use servo::{Servo, ServoBank};

/// Number of numbers in the integrated state vector.
pub const STATE_LEN: usize = 14;
/// The integrated state vector:
/// `[pn, pe, pd, u, v, w, q0, q1, q2, q3, p, q, r, Omega]` (quaternion scalar first).
pub type StateVector = SVector<f64, STATE_LEN>;

/// Surface and throttle positions the plant sees (after the servos), UMN signs, rad.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Controls {
    /// Elevator, positive trailing edge down (nose down).
    pub elevator: f64,
    /// Left aileron, positive trailing edge down.
    pub aileron_left: f64,
    /// Right aileron, positive trailing edge down.
    pub aileron_right: f64,
    /// Rudder, positive trailing edge left (nose left).
    pub rudder: f64,
    /// Throttle, 0..1.
    pub throttle: f64,
    /// Left flap, positive trailing edge down.
    pub flap_left: f64,
    /// Right flap, positive trailing edge down.
    pub flap_right: f64,
}

impl Controls {
    /// Controls from the combined aileron (`left = -aileron`, `right = +aileron`), no flaps.
    pub fn new(elevator: f64, aileron: f64, rudder: f64, throttle: f64) -> Self {
        Self {
            elevator,
            aileron_left: -aileron,
            aileron_right: aileron,
            rudder,
            throttle,
            flap_left: 0.0,
            flap_right: 0.0,
        }
    }

    /// The combined aileron `(right - left) / 2`, rad (positive rolls left).
    pub fn aileron(&self) -> f64 {
        0.5 * (self.aileron_right - self.aileron_left)
    }

    /// The same controls with both flaps at `flap` rad.
    pub fn with_flaps(self, flap: f64) -> Self {
        Self {
            flap_left: flap,
            flap_right: flap,
            ..self
        }
    }
}

impl From<Surfaces> for Controls {
    fn from(s: Surfaces) -> Self {
        Self::new(
            f64::from(s.elevator),
            f64::from(s.aileron),
            f64::from(s.rudder),
            f64::from(s.throttle),
        )
    }
}

/// What the air mass does around the aircraft.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Environment {
    /// Wind (velocity of the air mass) in NED, m/s: steady wind plus any turbulence.
    pub wind_ned: Vector3<f64>,
}

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
        }
    }
}

/// The simulated aircraft: model, state and the last inputs it was stepped with.
#[derive(Clone, Debug)]
pub struct Plant {
    params: ModelParams,
    x: StateVector,
    controls: Controls,
    env: Environment,
    time_s: f64,
}

impl Plant {
    /// A plant of the given aircraft at `state`, time zero, neutral controls, calm air.
    pub fn new(aircraft: &Aircraft, state: State) -> Self {
        Self::from_params(ModelParams::new(aircraft), state)
    }

    /// A plant from already derived parameters.
    pub fn from_params(params: ModelParams, state: State) -> Self {
        Self {
            params,
            x: state.to_vector(),
            controls: Controls::default(),
            env: Environment::default(),
            time_s: 0.0,
        }
    }

    /// The model parameters.
    pub fn params(&self) -> &ModelParams {
        &self.params
    }

    /// Advances the plant by `dt` s with one RK4 step, controls and environment held over it.
    ///
    /// The quaternion is renormalised and the engine speed kept inside its limits after the
    /// step (the Simulink integrator saturates it the same way).
    pub fn step(&mut self, controls: &Controls, env: &Environment, dt: f64) {
        self.controls = *controls;
        self.env = *env;
        let p = &self.params;
        integrator::rk4_step(
            |x| dynamics::state_derivative(p, x, controls, env),
            &mut self.x,
            dt,
        );
        dynamics::normalise(&mut self.x, p);
        self.time_s += dt;
    }

    /// Sets the controls and environment the accessors evaluate with (e.g. the trim, before
    /// the first step), without stepping.
    pub fn set_inputs(&mut self, controls: &Controls, env: &Environment) {
        self.controls = *controls;
        self.env = *env;
    }

    /// Replaces the state (time unchanged).
    pub fn set_state(&mut self, state: State) {
        self.x = state.to_vector();
    }

    /// The state.
    pub fn state(&self) -> State {
        State::from_vector(&self.x)
    }

    /// The raw integrated vector.
    pub fn state_vector(&self) -> &StateVector {
        &self.x
    }

    /// Simulated time, s.
    pub fn time_s(&self) -> f64 {
        self.time_s
    }

    /// Position from the home point, NED, m.
    pub fn position_ned(&self) -> Vector3<f64> {
        self.x.fixed_rows::<3>(0).into_owned()
    }

    /// Altitude above mean sea level, m.
    pub fn alt_msl_m(&self) -> f64 {
        self.params.home_alt_msl_m - self.x[2]
    }

    /// Latitude and longitude of the current position (flat earth about home).
    pub fn geodetic(&self) -> GeoPoint {
        offset_point(self.params.home, self.x[0], self.x[1])
    }

    /// Inertial velocity in NED, m/s.
    pub fn velocity_ned(&self) -> Vector3<f64> {
        body_to_ned(&self.attitude(), &self.velocity_body())
    }

    /// Inertial velocity in body axes, m/s.
    pub fn velocity_body(&self) -> Vector3<f64> {
        self.x.fixed_rows::<3>(3).into_owned()
    }

    /// Attitude quaternion, body to NED.
    pub fn attitude(&self) -> UnitQuaternion<f64> {
        quat_of(&self.x)
    }

    /// Attitude as 3-2-1 Euler angles.
    pub fn euler(&self) -> Euler<f64> {
        Euler::from_quaternion(&self.attitude())
    }

    /// Body rates `(p, q, r)`, rad/s.
    pub fn body_rates(&self) -> Vector3<f64> {
        self.x.fixed_rows::<3>(10).into_owned()
    }

    /// Engine speed, rad/s.
    pub fn engine_speed(&self) -> f64 {
        self.x[13]
    }

    /// Airspeed, angle of attack and sideslip in the last environment.
    pub fn air_data(&self) -> AirData<f64> {
        dynamics::air_data(&self.x, &self.env)
    }

    /// Everything the model computes at the current state with the last controls and
    /// environment: state derivative, specific force, forces, moments, air data, density.
    pub fn derivatives(&self) -> Derivatives {
        dynamics::derivatives(&self.params, &self.x, &self.controls, &self.env)
    }

    /// Specific force in body axes (non-gravitational force / mass), m/s^2: what an
    /// accelerometer at the CG reads (level flight: z close to -g).
    pub fn specific_force_body(&self) -> Vector3<f64> {
        self.derivatives().specific_force_body
    }

    /// Last controls applied.
    pub fn controls(&self) -> &Controls {
        &self.controls
    }

    /// Last environment applied.
    pub fn environment(&self) -> &Environment {
        &self.env
    }
}
