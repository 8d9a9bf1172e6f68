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
//! [`ground`] adds the contact of the landing gear and belly points ([`gear`]) with the runway
//! (zero in the air). [`state`], [`inputs`] and [`params`] hold what every block reads.
//! [`servo`] models the surface servos; simulations put it in front of the plant
//! ([`Plant::step_servos`]: the command held over the step, the servos moving inside it), trim
//! and linearisation do not. [`battery`] is the flight pack, stepped beside the plant by the
//! flights (not part of the UMN model; it does not feed back into thrust).
//!
//! State (13 degrees of freedom, 14 numbers): NED position, body velocity, attitude quaternion
//! (body to NED), body rates, engine speed Omega.

pub mod aero;
pub mod battery;
pub mod dynamics;
pub mod gear;
pub mod ground;
pub mod inputs;
pub mod integrator;
pub mod params;
pub mod propulsion;
pub mod servo;
pub mod state;

use crate::aircraft::Aircraft;
use common::math::geodetic::{offset_point, GeoPoint};
use common::math::{body_to_ned, AirData, Euler};
use nalgebra::{UnitQuaternion, Vector3};
use state::quat_of;

pub use dynamics::Derivatives;
pub use inputs::{Controls, Environment};
pub use params::ModelParams;
pub use servo::{Servo, ServoBank};
pub use state::{State, StateVector, STATE_LEN};

/// The first contact of a landing: what a landing report reads.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Touchdown {
    /// Time of the first contact, s (extrapolated inside the step from the state before it).
    pub time_s: f64,
    /// Position of the CG at that instant, NED, m.
    pub pos_ned: Vector3<f64>,
    /// Inertial velocity at that instant, NED, m/s (`z` is the sink rate, positive down).
    pub vel_ned: Vector3<f64>,
    /// Index of the first point that touched ([`gear::GroundParams::points`]).
    pub point: usize,
    /// Contacts after airborne phases shorter than [`MIN_FLIGHT_S`] since then (bounces).
    pub bounces: u32,
}

impl Touchdown {
    /// Sink rate at touchdown, m/s (positive down).
    pub fn sink_rate_mps(&self) -> f64 {
        self.vel_ned.z
    }

    /// Horizontal distance of the touchdown point from `(north_m, east_m)`, m.
    pub fn distance_from_m(&self, north_m: f64, east_m: f64) -> f64 {
        (self.pos_ned.x - north_m).hypot(self.pos_ned.y - east_m)
    }
}

/// Shortest airborne phase after which a contact counts as a new touchdown rather than a
/// bounce, s.
pub const MIN_FLIGHT_S: f64 = 1.0;

/// The simulated aircraft: model, state and the last inputs it was stepped with.
#[derive(Clone, Debug)]
pub struct Plant {
    params: ModelParams,
    x: StateVector,
    controls: Controls,
    env: Environment,
    time_s: f64,
    /// Some point below the ground plane after the last step.
    in_contact: bool,
    /// Start of the current airborne phase (`None` while in contact).
    airborne_since_s: Option<f64>,
    touchdown: Option<Touchdown>,
    liftoff_s: Option<f64>,
    /// The state it is held still in until the throttle first reaches
    /// [`HOLD_RELEASE_THROTTLE`]: see [`Plant::hold_until_throttle`].
    hold: Option<StateVector>,
}

/// Throttle at which a held aircraft is let go: the take-off roll's run-up.
pub const HOLD_RELEASE_THROTTLE: f64 = 0.2;

impl Plant {
    /// A plant of the given aircraft at `state`, time zero, neutral controls, calm air.
    pub fn new(aircraft: &Aircraft, state: State) -> Self {
        Self::from_params(ModelParams::new(aircraft), state)
    }

    /// A plant from already derived parameters.
    pub fn from_params(params: ModelParams, state: State) -> Self {
        let x = state.to_vector();
        let in_contact = ground::in_contact(&params, &x);
        Self {
            params,
            x,
            controls: Controls::default(),
            env: Environment::default(),
            time_s: 0.0,
            in_contact,
            airborne_since_s: (!in_contact).then_some(0.0),
            touchdown: None,
            liftoff_s: None,
            hold: None,
        }
    }

    /// A plant at rest on its wheels at `(north_m, east_m)` from home, nose towards
    /// `heading_rad`, engine stopped, controls neutral: the static equilibrium of the gear
    /// (see [`ground::rest_state`]).
    pub fn at_rest_on_ground(
        aircraft: &Aircraft,
        north_m: f64,
        east_m: f64,
        heading_rad: f64,
    ) -> Self {
        let params = ModelParams::new(aircraft);
        let (state, _) = ground::rest_state(&params, north_m, east_m, heading_rad);
        Self::from_params(params, state)
    }

    /// Holds the aircraft still where it stands until the throttle first reaches
    /// [`HOLD_RELEASE_THROTTLE`], as a helper's hand (or chocks and a tie-down) does before a
    /// take-off. Without it a parked taildragger creeps round into the wind (the friction law
    /// is smooth below its slip speed, so has no static friction: 84 deg before arming in
    /// 5 m/s of wind), and a gust above its lift-off speed on the three-point attitude lifts
    /// it off the ground.
    pub fn hold_until_throttle(&mut self) {
        self.hold = Some(self.x);
    }

    /// The model parameters.
    pub fn params(&self) -> &ModelParams {
        &self.params
    }

    /// Advances the plant by `dt` s with one RK4 step, surfaces, throttle and environment
    /// held over it (trim checks and the plant's own tests; flights go through the servos with
    /// [`Plant::step_servos`]).
    pub fn step(&mut self, controls: &Controls, env: &Environment, dt: f64) {
        self.advance(env, dt, |p, x| {
            integrator::rk4_step(
                |_, x| dynamics::state_derivative(p, x, controls, env),
                x,
                dt,
            );
            *controls
        });
    }

    /// Advances the plant by `dt` s with `command` held at the servos' inputs (zero-order
    /// hold, as the flight software's output is held between its frames): the servos move
    /// inside the step and every RK4 stage sees the surfaces where they are at its time
    /// ([`ServoBank::rk4_held`]). Returns the surfaces at the end of the step.
    pub fn step_servos(
        &mut self,
        servos: &mut ServoBank,
        command: &Controls,
        env: &Environment,
        dt: f64,
    ) -> Controls {
        self.advance(env, dt, |p, x| {
            servos.rk4_held(command, x, dt, |c, x| {
                dynamics::state_derivative(p, x, c, env)
            })
        });
        self.controls
    }

    /// One step of `integrate` (which moves the state and returns the controls at the end of
    /// the step), then what every step does after it.
    ///
    /// The quaternion is renormalised and the engine speed kept inside its limits after the
    /// step (the Simulink integrator saturates it the same way).
    fn advance(
        &mut self,
        env: &Environment,
        dt: f64,
        integrate: impl FnOnce(&ModelParams, &mut StateVector) -> Controls,
    ) {
        let x0 = self.x;
        self.controls = integrate(&self.params, &mut self.x);
        self.env = *env;
        let p = &self.params;
        dynamics::normalise(&mut self.x, p);
        if let Some(held) = self.hold {
            if self.controls.throttle >= HOLD_RELEASE_THROTTLE {
                self.hold = None;
            } else {
                // Still, but the engine turns with the throttle.
                let engine = self.x[13];
                self.x = held;
                self.x[13] = engine;
            }
        }
        self.time_s += dt;
        self.track_contact(&x0, dt);
    }

    /// Records touchdowns, bounces and lift-off after a step from `x0`.
    fn track_contact(&mut self, x0: &StateVector, dt: f64) {
        let now = ground::in_contact(&self.params, &self.x);
        if now == self.in_contact {
            return;
        }
        self.in_contact = now;
        if !now {
            self.airborne_since_s = Some(self.time_s);
            if self.liftoff_s.is_none() {
                self.liftoff_s = Some(self.time_s);
            }
            return;
        }
        let airborne_s = self
            .airborne_since_s
            .take()
            .map_or(0.0, |t0| self.time_s - t0);
        if airborne_s < MIN_FLIGHT_S && self.touchdown.is_some() {
            if let Some(td) = self.touchdown.as_mut() {
                td.bounces += 1;
            }
            return;
        }
        if airborne_s < MIN_FLIGHT_S && self.liftoff_s.is_some() {
            // A hop during the take-off run is not a landing.
            return;
        }
        // The instant the lowest point crossed the plane, extrapolated from the last state
        // before contact with its (contact-free) derivative: the state at the end of the step
        // has already felt the gear, which at large steps would understate the sink rate.
        let h0 = ground::clearance_m(&self.params, x0).max(0.0);
        let x0_dot = dynamics::state_derivative(&self.params, x0, &self.controls, &self.env);
        let sink0 = body_to_ned(&quat_of(x0), &Vector3::new(x0[3], x0[4], x0[5])).z;
        let tc = if sink0 > 0.0 {
            (h0 / sink0).min(dt)
        } else {
            dt
        };
        let xi = x0 + x0_dot * tc;
        let s = State::from_vector(&xi);
        let q = quat_of(&xi);
        let point = self
            .params
            .ground
            .points
            .iter()
            .enumerate()
            .map(|(i, pt)| (i, xi[2] + body_to_ned(&q, &pt.pos_body).z))
            .fold((0, f64::NEG_INFINITY), |a, b| if b.1 > a.1 { b } else { a })
            .0;
        self.touchdown = Some(Touchdown {
            time_s: self.time_s - dt + tc,
            pos_ned: s.pos_ned,
            vel_ned: body_to_ned(&s.attitude, &s.vel_body),
            point,
            bounces: 0,
        });
    }

    /// The last landing's first contact (after at least [`MIN_FLIGHT_S`] in the air), if any.
    pub fn touchdown(&self) -> Option<&Touchdown> {
        self.touchdown.as_ref()
    }

    /// Time the aircraft first left the ground, s (`None` if it never stood on it).
    pub fn liftoff_s(&self) -> Option<f64> {
        self.liftoff_s
    }

    /// Some point of the airframe touches the ground (after the last step).
    pub fn on_ground(&self) -> bool {
        self.in_contact
    }

    /// The ground's action at the current state and last controls (zero in the air).
    pub fn ground_contact(&self) -> ground::GroundContact {
        ground::contact(&self.params, &self.x, &self.controls)
    }

    /// Weight on wheels: some wheel is pressed onto the ground.
    pub fn weight_on_wheels(&self) -> bool {
        self.in_contact && self.ground_contact().weight_on_wheels()
    }

    /// Sets the controls and environment the accessors evaluate with (e.g. the trim, before
    /// the first step), without stepping.
    pub fn set_inputs(&mut self, controls: &Controls, env: &Environment) {
        self.controls = *controls;
        self.env = *env;
    }

    /// Replaces the state (time unchanged); the contact record starts over from it.
    pub fn set_state(&mut self, state: State) {
        self.x = state.to_vector();
        self.in_contact = ground::in_contact(&self.params, &self.x);
        self.airborne_since_s = (!self.in_contact).then_some(self.time_s);
        self.touchdown = None;
        self.liftoff_s = None;
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
        if self.hold.is_some() {
            // Held still, whatever holds it takes the rest: the reading is the ground's
            // reaction to gravity alone.
            let g_ned = Vector3::new(0.0, 0.0, -self.params.g);
            return quat_of(&self.x).inverse_transform_vector(&g_ned);
        }
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
