//! Linearisation by central differences about a trim, in the Minnesota state orders.
//!
//! The nonlinear model integrates a quaternion; for linear models the attitude is written as
//! 3-2-1 Euler angles, giving the 13-state vector
//! `[pn, pe, pd, u, v, w, phi, theta, psi, p, q, r, Omega]` and the inputs
//! `[elevator, throttle, left_aileron, right_aileron, rudder]`. The decoupled models take the
//! rows and columns the Minnesota `linearize_UAV.m` takes: longitudinal states
//! `[u, w, q, theta, Ze, Omega]` with inputs `[elevator, throttle]`, lateral states
//! `[v, p, r, phi, psi]` with inputs `[left_aileron, right_aileron, rudder]`.

use super::trim::TrimResult;
use crate::plant::dynamics::derivatives;
use crate::plant::inputs::{Controls, Environment};
use crate::plant::params::ModelParams;
use crate::plant::state::State;
use common::math::{AirData, Euler};
use nalgebra::{Complex, DMatrix, SMatrix, SVector, Vector3};
use serde::Serialize;

/// Number of states of the Euler-angle model.
pub const NX: usize = 13;
/// Number of inputs.
pub const NU: usize = 5;
/// Full state vector `[pn, pe, pd, u, v, w, phi, theta, psi, p, q, r, Omega]`.
pub type X13 = SVector<f64, NX>;
/// Input vector `[elevator, throttle, left_aileron, right_aileron, rudder]`.
pub type U5 = SVector<f64, NU>;

/// Index of each state in [`X13`].
pub mod ix {
    /// North position.
    pub const PN: usize = 0;
    /// East position.
    pub const PE: usize = 1;
    /// Down position (`Ze`).
    pub const ZE: usize = 2;
    /// Body x velocity.
    pub const U: usize = 3;
    /// Body y velocity.
    pub const V: usize = 4;
    /// Body z velocity.
    pub const W: usize = 5;
    /// Roll.
    pub const PHI: usize = 6;
    /// Pitch.
    pub const THETA: usize = 7;
    /// Yaw.
    pub const PSI: usize = 8;
    /// Roll rate.
    pub const P: usize = 9;
    /// Pitch rate.
    pub const Q: usize = 10;
    /// Yaw rate.
    pub const R: usize = 11;
    /// Engine speed.
    pub const OMEGA: usize = 12;
}

/// Index of each input in [`U5`].
pub mod iu {
    /// Elevator.
    pub const ELEVATOR: usize = 0;
    /// Throttle.
    pub const THROTTLE: usize = 1;
    /// Left aileron.
    pub const AILERON_LEFT: usize = 2;
    /// Right aileron.
    pub const AILERON_RIGHT: usize = 3;
    /// Rudder.
    pub const RUDDER: usize = 4;
}

/// Longitudinal state order (Minnesota): u, w, q, theta, Ze, Omega.
pub const LON_STATES: [usize; 6] = [ix::U, ix::W, ix::Q, ix::THETA, ix::ZE, ix::OMEGA];
/// Longitudinal state names.
pub const LON_STATE_NAMES: [&str; 6] = ["u", "w", "q", "theta", "Ze", "Omega"];
/// Longitudinal inputs: elevator, throttle.
pub const LON_INPUTS: [usize; 2] = [iu::ELEVATOR, iu::THROTTLE];
/// Longitudinal input names.
pub const LON_INPUT_NAMES: [&str; 2] = ["elevator", "throttle"];
/// Lateral state order (Minnesota): v, p, r, phi, psi.
pub const LAT_STATES: [usize; 5] = [ix::V, ix::P, ix::R, ix::PHI, ix::PSI];
/// Lateral state names.
pub const LAT_STATE_NAMES: [&str; 5] = ["v", "p", "r", "phi", "psi"];
/// Lateral inputs: left aileron, right aileron, rudder.
pub const LAT_INPUTS: [usize; 3] = [iu::AILERON_LEFT, iu::AILERON_RIGHT, iu::RUDDER];
/// Lateral input names.
pub const LAT_INPUT_NAMES: [&str; 3] = ["left_aileron", "right_aileron", "rudder"];

/// The Euler-angle state of a plant state.
pub fn x13_of(s: &State) -> X13 {
    let e = Euler::from_quaternion(&s.attitude);
    X13::from_column_slice(&[
        s.pos_ned.x,
        s.pos_ned.y,
        s.pos_ned.z,
        s.vel_body.x,
        s.vel_body.y,
        s.vel_body.z,
        e.phi,
        e.theta,
        e.psi,
        s.omega_body.x,
        s.omega_body.y,
        s.omega_body.z,
        s.engine_speed,
    ])
}

/// The plant state of an Euler-angle state.
pub fn state_of(x: &X13) -> State {
    State {
        pos_ned: Vector3::new(x[0], x[1], x[2]),
        vel_body: Vector3::new(x[3], x[4], x[5]),
        attitude: Euler::new(x[6], x[7], x[8]).to_quaternion(),
        omega_body: Vector3::new(x[9], x[10], x[11]),
        engine_speed: x[12],
    }
}

/// The input vector of a set of controls.
pub fn u5_of(c: &Controls) -> U5 {
    U5::from_column_slice(&[
        c.elevator,
        c.throttle,
        c.aileron_left,
        c.aileron_right,
        c.rudder,
    ])
}

/// The controls of an input vector (flaps from `base`).
pub fn controls_of(u: &U5, base: &Controls) -> Controls {
    Controls {
        elevator: u[0],
        throttle: u[1],
        aileron_left: u[2],
        aileron_right: u[3],
        rudder: u[4],
        ..*base
    }
}

/// Derivative of the Euler-angle state (calm air).
pub fn f13(p: &ModelParams, x: &X13, u: &U5, base: &Controls) -> X13 {
    let s = state_of(x);
    let d = derivatives(
        p,
        &s.to_vector(),
        &controls_of(u, base),
        &Environment::default(),
    );
    let e = Euler::new(x[6], x[7], x[8]);
    let euler_dot = e.rates_from_body(&s.omega_body);
    let mut out = X13::zeros();
    for i in 0..6 {
        out[i] = d.x_dot[i];
    }
    out[6] = euler_dot.x;
    out[7] = euler_dot.y;
    out[8] = euler_dot.z;
    out[9] = d.x_dot[10];
    out[10] = d.x_dot[11];
    out[11] = d.x_dot[12];
    out[12] = d.x_dot[13];
    out
}

/// Air data outputs `[Va, alpha, beta]` of an Euler-angle state (calm air).
pub fn air_outputs(x: &X13) -> Vector3<f64> {
    let a = AirData::from_body_velocity(&Vector3::new(x[3], x[4], x[5]));
    Vector3::new(a.va, a.alpha, a.beta)
}

/// A linear model `x_dot = A x + B u` with named states and inputs.
#[derive(Clone, Debug, Serialize)]
pub struct StateSpace {
    /// State names in order.
    pub states: Vec<String>,
    /// Input names in order.
    pub inputs: Vec<String>,
    /// State matrix (row-major rows for JSON readability).
    #[serde(serialize_with = "rows")]
    pub a: DMatrix<f64>,
    /// Input matrix.
    #[serde(serialize_with = "rows")]
    pub b: DMatrix<f64>,
}

fn rows<S: serde::Serializer>(m: &DMatrix<f64>, s: S) -> Result<S::Ok, S::Error> {
    use serde::ser::SerializeSeq;
    let mut seq = s.serialize_seq(Some(m.nrows()))?;
    for r in 0..m.nrows() {
        let row: Vec<f64> = m.row(r).iter().copied().collect();
        seq.serialize_element(&row)?;
    }
    seq.end()
}

impl StateSpace {
    /// The sub-model of the given state and input indices of a full model.
    pub fn select(
        a: &SMatrix<f64, NX, NX>,
        b: &SMatrix<f64, NX, NU>,
        states: &[usize],
        state_names: &[&str],
        inputs: &[usize],
        input_names: &[&str],
    ) -> Self {
        let n = states.len();
        let m = inputs.len();
        Self {
            states: state_names.iter().map(|s| s.to_string()).collect(),
            inputs: input_names.iter().map(|s| s.to_string()).collect(),
            a: DMatrix::from_fn(n, n, |i, j| a[(states[i], states[j])]),
            b: DMatrix::from_fn(n, m, |i, j| b[(states[i], inputs[j])]),
        }
    }

    /// Eigenvalues of `A`, sorted by real part then imaginary part.
    pub fn eigenvalues(&self) -> Vec<Complex<f64>> {
        super::lti::eigenvalues(&self.a)
    }
}

/// The full linearisation about a trim.
#[derive(Clone, Debug)]
pub struct Linearization {
    /// Trim state.
    pub x0: X13,
    /// Trim inputs.
    pub u0: U5,
    /// Trim controls (flaps and all).
    pub controls0: Controls,
    /// Full 13-state `A`.
    pub a: SMatrix<f64, NX, NX>,
    /// Full 13x5 `B`.
    pub b: SMatrix<f64, NX, NU>,
    /// `d[Va, alpha, beta] / dx`.
    pub c_air: SMatrix<f64, 3, NX>,
    /// Longitudinal model (Minnesota order).
    pub lon: StateSpace,
    /// Lateral model (Minnesota order).
    pub lat: StateSpace,
}

fn step_for(x: f64) -> f64 {
    1e-6 * x.abs().max(1.0)
}

/// Central-difference Jacobians of the model at a trim.
pub fn linearize(p: &ModelParams, trim: &TrimResult) -> Linearization {
    let x0 = x13_of(&trim.state);
    let u0 = u5_of(&trim.controls);
    let base = trim.controls;
    let mut a = SMatrix::<f64, NX, NX>::zeros();
    for j in 0..NX {
        let h = step_for(x0[j]);
        let (mut xp, mut xm) = (x0, x0);
        xp[j] += h;
        xm[j] -= h;
        let col = (f13(p, &xp, &u0, &base) - f13(p, &xm, &u0, &base)) / (2.0 * h);
        a.set_column(j, &col);
    }
    let mut b = SMatrix::<f64, NX, NU>::zeros();
    for j in 0..NU {
        // Surfaces at trim are small: a fixed absolute step stays on one side of the |CD d|
        // kink only if the trim deflection is larger than the step, true for every trim here.
        let h = 1e-7;
        let (mut up, mut um) = (u0, u0);
        up[j] += h;
        um[j] -= h;
        let col = (f13(p, &x0, &up, &base) - f13(p, &x0, &um, &base)) / (2.0 * h);
        b.set_column(j, &col);
    }
    let mut c_air = SMatrix::<f64, 3, NX>::zeros();
    for j in 3..6 {
        let h = step_for(x0[j]);
        let (mut xp, mut xm) = (x0, x0);
        xp[j] += h;
        xm[j] -= h;
        c_air.set_column(j, &((air_outputs(&xp) - air_outputs(&xm)) / (2.0 * h)));
    }
    let lon = StateSpace::select(
        &a,
        &b,
        &LON_STATES,
        &LON_STATE_NAMES,
        &LON_INPUTS,
        &LON_INPUT_NAMES,
    );
    let lat = StateSpace::select(
        &a,
        &b,
        &LAT_STATES,
        &LAT_STATE_NAMES,
        &LAT_INPUTS,
        &LAT_INPUT_NAMES,
    );
    Linearization {
        x0,
        u0,
        controls0: base,
        a,
        b,
        c_air,
        lon,
        lat,
    }
}

/// A mode: eigenvalue, damping ratio and natural frequency.
#[derive(Clone, Copy, Debug, Serialize, PartialEq)]
pub struct Mode {
    /// Real part, 1/s.
    pub re: f64,
    /// Imaginary part (positive member of a pair), rad/s.
    pub im: f64,
    /// Damping ratio `-re / |lambda|` (1 for a stable real pole).
    pub damping: f64,
    /// Natural frequency `|lambda|`, rad/s.
    pub wn_radps: f64,
}

impl Mode {
    /// The mode of one eigenvalue.
    pub fn of(l: Complex<f64>) -> Self {
        let wn = l.norm();
        Self {
            re: l.re,
            im: l.im.abs(),
            damping: if wn > 0.0 { -l.re / wn } else { 1.0 },
            wn_radps: wn,
        }
    }
}

/// The named modes of the longitudinal model.
#[derive(Clone, Debug, Serialize)]
pub struct LonModes {
    /// Phugoid (slow oscillatory pair).
    pub phugoid: Mode,
    /// Short period (fast oscillatory pair).
    pub short_period: Mode,
    /// Engine-speed mode (fast real pole).
    pub engine_speed: Mode,
    /// Altitude mode (real pole near zero, from the density gradient).
    pub altitude: Mode,
}

/// The named modes of the lateral model.
#[derive(Clone, Debug, Serialize)]
pub struct LatModes {
    /// Heading (pole at zero).
    pub heading: Mode,
    /// Spiral (slow real pole).
    pub spiral: Mode,
    /// Dutch roll (oscillatory pair).
    pub dutch_roll: Mode,
    /// Roll subsidence (fast real pole).
    pub roll: Mode,
}

fn split(ev: &[Complex<f64>]) -> (Vec<Complex<f64>>, Vec<Complex<f64>>) {
    let scale = ev.iter().map(|l| l.norm()).fold(1.0, f64::max);
    let (mut complex, mut real): (Vec<Complex<f64>>, Vec<Complex<f64>>) =
        ev.iter().partition(|l| l.im.abs() > 1e-9 * scale);
    complex.retain(|l| l.im > 0.0);
    complex.sort_by(|a, b| a.norm().total_cmp(&b.norm()));
    real.sort_by(|a, b| a.norm().total_cmp(&b.norm()));
    (complex, real)
}

/// Names the longitudinal modes; `None` if the pole pattern is not two pairs and two real poles.
pub fn lon_modes(lon: &StateSpace) -> Option<LonModes> {
    let (c, r) = split(&lon.eigenvalues());
    if c.len() != 2 || r.len() != 2 {
        return None;
    }
    Some(LonModes {
        phugoid: Mode::of(c[0]),
        short_period: Mode::of(c[1]),
        altitude: Mode::of(r[0]),
        engine_speed: Mode::of(r[1]),
    })
}

/// Names the lateral modes; `None` if the pole pattern is not one pair and three real poles.
pub fn lat_modes(lat: &StateSpace) -> Option<LatModes> {
    let (c, r) = split(&lat.eigenvalues());
    if c.len() != 1 || r.len() != 3 {
        return None;
    }
    Some(LatModes {
        heading: Mode::of(r[0]),
        spiral: Mode::of(r[1]),
        roll: Mode::of(r[2]),
        dutch_roll: Mode::of(c[0]),
    })
}
