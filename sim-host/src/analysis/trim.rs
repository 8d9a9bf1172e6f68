//! Trim: the controls and attitude that hold a steady flight condition.
//!
//! For a target airspeed, flight-path angle, turn rate and sideslip the unknowns are
//! `[alpha, phi, theta, elevator, aileron, rudder, throttle, Omega]`; the body rates follow
//! from the turn rate and attitude (`p = -psi_dot sin theta`, `q = psi_dot sin phi cos theta`,
//! `r = psi_dot cos phi cos theta`), so a zero body-velocity, body-rate and engine-speed
//! derivative plus the flight-path constraint make eight equations in eight unknowns, solved by
//! Levenberg-Marquardt with a central-difference Jacobian.
//!
//! The targets are the thesis's, at 17 m/s; [`TrimTarget::at_airspeed`] moves any of them to
//! another airspeed (an aircraft file's cruise airspeed, or `--airspeed`). The solver starts
//! from the Ultra Stick's 17 m/s trim, and when that does not converge from a guess of the
//! aircraft's own: the angle of attack that lifts its weight, the elevator that balances the
//! pitching moment there, half throttle and the engine speed that holds it.

use crate::aircraft::Aircraft;
use crate::plant::dynamics::derivatives;
use crate::plant::inputs::{Controls, Environment};
use crate::plant::params::ModelParams;
use crate::plant::propulsion::steady_engine_speed;
use crate::plant::state::State;
use common::math::atmosphere::standard_atmosphere;
use common::math::{AirData, Euler};
use nalgebra::{SMatrix, SVector, Vector3};
use serde::Serialize;

const N: usize = 8;
type Z = SVector<f64, N>;

/// A steady flight condition to trim for.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TrimTarget {
    /// Short name used on the command line (`level`, `climb`, ...).
    pub name: String,
    /// Human description.
    pub description: String,
    /// Airspeed, m/s.
    pub va_mps: f64,
    /// Flight-path angle, rad (positive climbing).
    pub gamma_rad: f64,
    /// Turn rate (heading rate), rad/s, positive to the right.
    pub turn_rate_radps: f64,
    /// Sideslip, rad.
    pub beta_rad: f64,
    /// Altitude above mean sea level, m.
    pub alt_msl_m: f64,
}

impl TrimTarget {
    fn new(name: &str, description: &str, gamma_deg: f64, turn_deg_s: f64, beta_deg: f64) -> Self {
        Self {
            name: name.into(),
            description: description.into(),
            va_mps: 17.0,
            gamma_rad: gamma_deg.to_radians(),
            turn_rate_radps: turn_deg_s.to_radians(),
            beta_rad: beta_deg.to_radians(),
            alt_msl_m: 100.0,
        }
    }

    /// Thesis Table 2.3 I: straight and level, Va 17 m/s, h 100 m.
    pub fn level() -> Self {
        Self::new("level", "I straight and level", 0.0, 0.0, 0.0)
    }

    /// Straight and level at `aircraft`'s cruise airspeed (`[performance]
    /// cruise_airspeed_mps`; the 25e's 17 m/s, as [`TrimTarget::level`]), 100 m.
    pub fn cruise(aircraft: &Aircraft) -> Self {
        Self::level().at_airspeed(aircraft.cruise_airspeed_mps())
    }

    /// Thesis Table 2.3 II: 5 deg climb.
    pub fn climb() -> Self {
        Self::new("climb", "II climb, gamma 5 deg", 5.0, 0.0, 0.0)
    }

    /// Thesis Table 2.3 III: level turn at 20 deg/s.
    pub fn turn() -> Self {
        Self::new("turn", "III level turn 20 deg/s", 0.0, 20.0, 0.0)
    }

    /// Thesis Table 2.3 IV: climbing turn, 5 deg and 20 deg/s.
    pub fn climbing_turn() -> Self {
        Self::new(
            "climbing-turn",
            "IV climbing turn, gamma 5 deg, 20 deg/s",
            5.0,
            20.0,
            0.0,
        )
    }

    /// The Minnesota set-up's fifth target: steady-heading sideslip, beta 5 deg.
    pub fn sideslip() -> Self {
        Self::new(
            "sideslip",
            "V steady-heading sideslip, beta 5 deg",
            0.0,
            0.0,
            5.0,
        )
    }

    /// All five targets, in table order.
    pub fn all() -> Vec<Self> {
        vec![
            Self::level(),
            Self::climb(),
            Self::turn(),
            Self::climbing_turn(),
            Self::sideslip(),
        ]
    }

    /// The target with this short name.
    pub fn by_name(name: &str) -> Option<Self> {
        Self::all().into_iter().find(|t| t.name == name)
    }

    /// The same flight condition at airspeed `va_mps`, m/s.
    pub fn at_airspeed(mut self, va_mps: f64) -> Self {
        self.va_mps = va_mps;
        self
    }
}

/// The outcome of one trim.
#[derive(Clone, Debug, Serialize)]
pub struct TrimResult {
    /// What was asked for.
    pub target: TrimTarget,
    /// Whether the residual fell below the tolerance.
    pub converged: bool,
    /// Euclidean norm of the final (scaled) residual.
    pub residual_norm: f64,
    /// Solver iterations used.
    pub iterations: usize,
    /// Angle of attack, rad.
    pub alpha: f64,
    /// Sideslip, rad.
    pub beta: f64,
    /// Roll, rad.
    pub phi: f64,
    /// Pitch, rad.
    pub theta: f64,
    /// Flight-path angle reached, rad.
    pub gamma: f64,
    /// Body roll rate, rad/s.
    pub p: f64,
    /// Body pitch rate, rad/s.
    pub q: f64,
    /// Body yaw rate, rad/s.
    pub r: f64,
    /// Elevator, rad.
    pub elevator: f64,
    /// Combined aileron, rad.
    pub aileron: f64,
    /// Rudder, rad.
    pub rudder: f64,
    /// Throttle, 0..1.
    pub throttle: f64,
    /// Engine speed, rad/s.
    pub engine_speed: f64,
    /// Thrust, N.
    pub thrust_n: f64,
    /// Body specific force at trim, m/s^2.
    pub specific_force_body: [f64; 3],
    /// The trimmed state (heading north, at the target altitude above home).
    #[serde(skip)]
    pub state: State,
    /// The trimmed controls.
    #[serde(skip)]
    pub controls: Controls,
}

/// Residual tolerance (the derivatives are m/s^2 and rad/s^2).
pub const TOLERANCE: f64 = 1e-10;
/// Iteration limit.
pub const MAX_ITERATIONS: usize = 200;

fn unpack(p: &ModelParams, t: &TrimTarget, z: &Z) -> (State, Controls) {
    let (alpha, phi, theta) = (z[0], z[1], z[2]);
    let air = AirData {
        va: t.va_mps,
        alpha,
        beta: t.beta_rad,
    };
    let w = t.turn_rate_radps;
    let state = State {
        pos_ned: Vector3::new(0.0, 0.0, p.home_alt_msl_m - t.alt_msl_m),
        vel_body: air.body_velocity(),
        attitude: Euler::new(phi, theta, 0.0).to_quaternion(),
        omega_body: Vector3::new(
            -w * theta.sin(),
            w * phi.sin() * theta.cos(),
            w * phi.cos() * theta.cos(),
        ),
        engine_speed: z[7],
    };
    (state, Controls::new(z[3], z[4], z[5], z[6]))
}

fn flight_path_angle(pos_dot: &Vector3<f64>) -> f64 {
    (-pos_dot.z / pos_dot.norm().max(1e-9))
        .clamp(-1.0, 1.0)
        .asin()
}

fn residual(p: &ModelParams, t: &TrimTarget, z: &Z) -> Z {
    let (s, c) = unpack(p, t, z);
    let d = derivatives(p, &s.to_vector(), &c, &Environment::default());
    let xd = &d.x_dot;
    let pos_dot = Vector3::new(xd[0], xd[1], xd[2]);
    // The engine acceleration is (Qm - Qp)/Jmp with Jmp ~ 1e-4: scaling by Jmp weighs the torque
    // balance (N m) like the other equations instead of letting it dominate.
    Z::from_column_slice(&[
        xd[3],
        xd[4],
        xd[5],
        xd[10],
        xd[11],
        xd[12],
        xd[13] * p.prop.Jmp_kgm2 * 100.0,
        flight_path_angle(&pos_dot) - t.gamma_rad,
    ])
}

fn clamp_unknowns(p: &ModelParams, z: &mut Z) {
    let surf = 25f64.to_radians();
    z[0] = z[0].clamp(-0.5, 0.5);
    z[1] = z[1].clamp(-1.4, 1.4);
    z[2] = z[2].clamp(-1.4, 1.4);
    for i in 3..6 {
        z[i] = z[i].clamp(-surf, surf);
    }
    z[6] = z[6].clamp(0.0, 1.0);
    let [lo, hi] = p.prop.omega_limits_radps;
    z[7] = z[7].clamp(lo, hi);
}

/// Trims the aircraft for `target`. Never panics: a trim that does not converge comes back
/// with `converged == false` and its residual.
pub fn trim(aircraft: &Aircraft, target: &TrimTarget) -> TrimResult {
    trim_with(&ModelParams::new(aircraft), target)
}

/// [`trim`] with already derived parameters.
pub fn trim_with(p: &ModelParams, target: &TrimTarget) -> TrimResult {
    let guess = Z::from_column_slice(&[
        0.05,
        0.0,
        0.05 + target.gamma_rad,
        -0.09,
        0.0,
        0.0,
        0.56,
        827.0,
    ]);
    let first = solve(p, target, guess);
    if first.converged {
        return first;
    }
    let second = solve(p, target, own_guess(p, target));
    if second.residual_norm < first.residual_norm {
        second
    } else {
        first
    }
}

/// A starting point from the aircraft's own data: the linear lift and pitching moment, and
/// the engine speed at which motor and propeller torques balance at half throttle.
fn own_guess(p: &ModelParams, t: &TrimTarget) -> Z {
    let rho = standard_atmosphere(t.alt_msl_m).density;
    let qbar_s = 0.5 * rho * t.va_mps * t.va_mps * p.s;
    let (lift, pitch) = (&p.aero.lift, &p.aero.pitch);
    let cl = p.mass * p.g * t.gamma_rad.cos() / qbar_s.max(1e-9);
    let alpha = ((cl - lift.CL0) / lift.CL_alpha).clamp(-0.3, 0.3);
    let elevator = if pitch.Cm_de != 0.0 {
        (-(pitch.Cm0 + pitch.Cm_alpha * alpha) / pitch.Cm_de).clamp(-0.4, 0.4)
    } else {
        0.0
    };
    let throttle = 0.5;
    Z::from_column_slice(&[
        alpha,
        0.0,
        alpha + t.gamma_rad,
        elevator,
        0.0,
        0.0,
        throttle,
        steady_engine_speed(p, t.va_mps, throttle, rho),
    ])
}

/// Trims `target` starting from the solution of a nearby trim `near` (continuation: the fixed
/// guess of [`trim_with`] suits airspeeds about 17 m/s only).
pub fn trim_near(p: &ModelParams, target: &TrimTarget, near: &TrimResult) -> TrimResult {
    let guess = Z::from_column_slice(&[
        near.alpha,
        near.phi,
        near.theta,
        near.elevator,
        near.aileron,
        near.rudder,
        near.throttle,
        near.engine_speed,
    ]);
    solve(p, target, guess)
}

fn solve(p: &ModelParams, target: &TrimTarget, mut z: Z) -> TrimResult {
    let norm = |r: &Z| {
        let n = r.norm();
        if n.is_finite() {
            n
        } else {
            f64::INFINITY
        }
    };
    let mut r = residual(p, target, &z);
    let mut rn = norm(&r);
    let mut lambda = 1e-3;
    let mut iterations = 0;
    while iterations < MAX_ITERATIONS && rn > TOLERANCE {
        iterations += 1;
        let mut jac = SMatrix::<f64, N, N>::zeros();
        for j in 0..N {
            let h = 1e-6 * z[j].abs().max(1.0);
            let mut zp = z;
            let mut zm = z;
            zp[j] += h;
            zm[j] -= h;
            let col = (residual(p, target, &zp) - residual(p, target, &zm)) / (2.0 * h);
            jac.set_column(j, &col);
        }
        let jtj = jac.transpose() * jac;
        let jtr = jac.transpose() * r;
        let mut improved = false;
        for _ in 0..12 {
            let mut a = jtj;
            for i in 0..N {
                a[(i, i)] += lambda * jtj[(i, i)].max(1e-12);
            }
            let Some(step) = a.lu().solve(&(-jtr)) else {
                lambda *= 10.0;
                continue;
            };
            let mut zn = z + step;
            clamp_unknowns(p, &mut zn);
            let rnew = residual(p, target, &zn);
            let rnn = norm(&rnew);
            if rnn < rn {
                z = zn;
                r = rnew;
                rn = rnn;
                lambda = (lambda * 0.1).max(1e-12);
                improved = true;
                break;
            }
            lambda *= 10.0;
        }
        if !improved {
            break;
        }
    }
    let (state, controls) = unpack(p, target, &z);
    let d = derivatives(p, &state.to_vector(), &controls, &Environment::default());
    let pos_dot = Vector3::new(d.x_dot[0], d.x_dot[1], d.x_dot[2]);
    TrimResult {
        target: target.clone(),
        converged: rn <= TOLERANCE,
        residual_norm: rn,
        iterations,
        alpha: z[0],
        beta: target.beta_rad,
        phi: z[1],
        theta: z[2],
        gamma: flight_path_angle(&pos_dot),
        p: state.omega_body.x,
        q: state.omega_body.y,
        r: state.omega_body.z,
        elevator: z[3],
        aileron: z[4],
        rudder: z[5],
        throttle: z[6],
        engine_speed: z[7],
        thrust_n: d.propulsion.thrust_n,
        specific_force_body: d.specific_force_body.into(),
        state,
        controls,
    }
}

/// Why a trim failed, in words a user can act on.
pub fn not_trimmed(trim: &TrimResult) -> String {
    format!(
        "the aircraft cannot be trimmed for `{}` at {} m/s: the solver stopped at residual {:.3e} \
         (alpha {:.3} rad, elevator {:.3} rad, throttle {:.3}); try an airspeed nearer the \
         aircraft's cruise",
        trim.target.name,
        trim.target.va_mps,
        trim.residual_norm,
        trim.alpha,
        trim.elevator,
        trim.throttle
    )
}
