//! Contact with a flat, level ground: the landing gear (a taildragger's or a tricycle's) and the
//! airframe's belly.
//!
//! Each contact point is a spring and damper normal to the ground, acting only while the point is
//! below the ground plane and only in compression (the ground pushes, never pulls). Friction
//! opposes the point's velocity in the ground plane: a wheel rolls along its heading (small
//! rolling friction) and resists sliding across it (large side friction); a belly point slides
//! with one coefficient in every direction. The tail wheel's heading turns with the rudder, as on
//! the Ultra Stick 25e whose tail-wheel wire sits in the rudder; a tricycle's nose wheel is
//! steered by the rudder the same way.
//!
//! Friction is `mu N v / sqrt(v^2 + v_s^2)` rather than `mu N sign(v)`: the discontinuous law
//! chatters under a fixed-step integrator, the smooth one is a stiff viscous friction below the
//! slip speed `v_s` and Coulomb friction above it. The slip speed sets the stiffness
//! `mu N / (v_s m)`, which the file's values keep below what RK4 resolves at the simulator's
//! steps (up to 0.02 s).
//!
//! The ground plane is the NED origin's altitude (`environment.home_alt_msl_m`): home is on the
//! runway.
//!
//! Away from the ground the contact costs one comparison: no point of the airframe lies farther
//! than [`GroundParams::reach_m`] from the CG, so while the CG is higher than that above the
//! plane every force is exactly zero and nothing else is evaluated.

use super::gear::{ContactKind, GroundParams, MAIN_LEFT, MAX_CONTACTS, TAIL};
use super::inputs::Controls;
use super::params::ModelParams;
use super::state::{quat_of, State, StateVector};
use common::math::{body_to_ned, Euler};
use nalgebra::{Matrix3, UnitQuaternion, Vector3};

/// The ground's action on the airframe at one instant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GroundContact {
    /// Total ground force, body axes, N.
    pub force_body: Vector3<f64>,
    /// Its moment about the CG, body axes, N m.
    pub moment_body: Vector3<f64>,
    /// Normal force at each contact point, N (order of [`GroundParams::points`]; zero when
    /// the point is clear of the ground).
    pub normal_n: [f64; MAX_CONTACTS],
    /// Penetration of each contact point below the ground plane, m (zero when clear).
    pub penetration_m: [f64; MAX_CONTACTS],
    /// Sum of the wheels' normal forces, N.
    pub wheel_load_n: f64,
    /// Sum of the belly points' normal forces, N.
    pub belly_load_n: f64,
}

impl Default for GroundContact {
    fn default() -> Self {
        Self {
            force_body: Vector3::zeros(),
            moment_body: Vector3::zeros(),
            normal_n: [0.0; MAX_CONTACTS],
            penetration_m: [0.0; MAX_CONTACTS],
            wheel_load_n: 0.0,
            belly_load_n: 0.0,
        }
    }
}

impl GroundContact {
    /// Weight on wheels: some wheel is pressed onto the ground.
    pub fn weight_on_wheels(&self) -> bool {
        self.wheel_load_n > 0.0
    }

    /// Some point (wheel or belly) is below the ground plane.
    pub fn in_contact(&self) -> bool {
        self.penetration_m.iter().any(|&d| d > 0.0)
    }

    /// Sum of all normal forces, N.
    pub fn normal_total_n(&self) -> f64 {
        self.wheel_load_n + self.belly_load_n
    }
}

/// `v / sqrt(v^2 + v_s^2)`: the sign of `v`, smoothed below the slip speed.
#[inline]
fn slip(v: f64, v_s: f64) -> f64 {
    v / (v * v + v_s * v_s).sqrt()
}

/// Ground force and moment at state `x` with the rudder of `c`.
#[inline]
pub fn contact(p: &ModelParams, x: &StateVector, c: &Controls) -> GroundContact {
    let g = &p.ground;
    if g.clear_of_ground(x[2]) {
        return GroundContact::default();
    }
    contact_near_ground(g, x, c)
}

/// The contact evaluation proper (the CG is within reach of the ground).
fn contact_near_ground(g: &GroundParams, x: &StateVector, c: &Controls) -> GroundContact {
    let quat = quat_of(x);
    // The matrix of the same body-to-NED quaternion: one matrix serves every point.
    let r: Matrix3<f64> = quat.to_rotation_matrix().into_inner();
    let v_body = Vector3::new(x[3], x[4], x[5]);
    let omega = Vector3::new(x[10], x[11], x[12]);
    let mut out = GroundContact::default();
    let mut force_ned = Vector3::zeros();
    for (i, pt) in g.points.iter().enumerate() {
        let rp = pt.pos_body;
        let depth = depth_m(g, x, &r, &rp);
        if depth <= 0.0 {
            continue;
        }
        out.penetration_m[i] = depth;
        let v_pt = r * (v_body + omega.cross(&pt.pos_body));
        let normal = (pt.stiffness_npm * depth + pt.damping_nspm * v_pt.z).max(0.0);
        if normal == 0.0 {
            continue;
        }
        out.normal_n[i] = normal;
        let (vn, ve) = (v_pt.x, v_pt.y);
        let (fn_, fe) = match pt.kind {
            ContactKind::Wheel {
                mu_roll,
                mu_side,
                steer_per_rudder,
            } => {
                out.wheel_load_n += normal;
                let (s, co) = (steer_per_rudder * c.rudder).sin_cos();
                // The wheel's rolling direction (body x turned by the steering about body z),
                // projected onto the ground plane.
                let d = r * Vector3::new(co, s, 0.0);
                let len = (d.x * d.x + d.y * d.y).sqrt();
                if len > 1e-3 {
                    let (ex, ey) = (d.x / len, d.y / len);
                    let v_roll = vn * ex + ve * ey;
                    let v_side = -vn * ey + ve * ex;
                    let f_roll = -mu_roll * normal * slip(v_roll, g.slip_speed_mps);
                    let f_side = -mu_side * normal * slip(v_side, g.slip_speed_mps);
                    (f_roll * ex - f_side * ey, f_roll * ey + f_side * ex)
                } else {
                    // Wheel axis vertical (aircraft on its nose or tail): it can only slide.
                    skid_friction(mu_side, normal, vn, ve, g.slip_speed_mps)
                }
            }
            ContactKind::Skid { mu } => {
                out.belly_load_n += normal;
                skid_friction(mu, normal, vn, ve, g.slip_speed_mps)
            }
        };
        let f_ned = Vector3::new(fn_, fe, -normal);
        force_ned += f_ned;
        let f_body = r.tr_mul(&f_ned);
        out.moment_body += pt.pos_body.cross(&f_body);
    }
    out.force_body = r.tr_mul(&force_ned);
    out
}

/// Isotropic sliding friction `(north, east)`, N.
#[inline]
fn skid_friction(mu: f64, normal: f64, vn: f64, ve: f64, v_s: f64) -> (f64, f64) {
    let k = -mu * normal / (vn * vn + ve * ve + v_s * v_s).sqrt();
    (k * vn, k * ve)
}

/// Height of the lowest contact point above the ground plane, m (negative when below).
pub fn clearance_m(p: &ModelParams, x: &StateVector) -> f64 {
    let r = quat_of(x).to_rotation_matrix().into_inner();
    p.ground
        .points
        .iter()
        .map(|pt| -depth_m(&p.ground, x, &r, &pt.pos_body))
        .fold(f64::INFINITY, f64::min)
}

/// How far the body point `rp` is below the ground plane, m (negative above it), with `r`
/// the body-to-NED matrix of the state `x` (only its down row is needed).
fn depth_m(g: &GroundParams, x: &StateVector, r: &Matrix3<f64>, rp: &Vector3<f64>) -> f64 {
    x[2] + r[(2, 0)] * rp.x + r[(2, 1)] * rp.y + r[(2, 2)] * rp.z - g.ground_down_m
}

/// True when some contact point is below the ground plane (cheap while airborne).
#[inline]
pub fn in_contact(p: &ModelParams, x: &StateVector) -> bool {
    !p.ground.clear_of_ground(x[2]) && clearance_m(p, x) < 0.0
}

/// The aircraft at rest on its three wheels at `(north_m, east_m)` with heading `heading_rad`,
/// engine stopped: the static equilibrium of the gear springs and the weight (wheels
/// compressed; a taildragger's nose-up attitude, a tricycle's about level).
///
/// Solved by Newton's method on the height and pitch for zero vertical force and zero pitching
/// moment (left and right are symmetric, so roll is zero). If the model's gear cannot hold it
/// (no solution near the three-point attitude), the best iterate is returned; the residual is
/// the second element (N and N m, combined norm).
pub fn rest_state(p: &ModelParams, north_m: f64, east_m: f64, heading_rad: f64) -> (State, f64) {
    let g = &p.ground;
    let state = |down: f64, theta: f64| State {
        pos_ned: Vector3::new(north_m, east_m, down),
        vel_body: Vector3::zeros(),
        attitude: Euler::new(0.0, theta, heading_rad).to_quaternion(),
        omega_body: Vector3::zeros(),
        engine_speed: p.prop.omega_limits_radps[0],
    };
    let weight = p.mass * p.g;
    let residual = |down: f64, theta: f64| {
        let x = state(down, theta).to_vector();
        let gc = contact_near_ground(g, &x, &Controls::default());
        let q: UnitQuaternion<f64> = quat_of(&x);
        let f_ned = body_to_ned(&q, &gc.force_body);
        nalgebra::Vector2::new(f_ned.z + weight, gc.moment_body.y)
    };
    // Start at the three-point attitude with uncompressed wheels: the line through the main
    // and third (tail or nose) contact points is level.
    let (m, t) = (g.points[MAIN_LEFT].pos_body, g.points[TAIL].pos_body);
    let mut theta = ((m.z - t.z) / (m.x - t.x)).atan();
    let mut down = g.ground_down_m - (-m.x * theta.sin() + m.z * theta.cos());
    let mut best = (down, theta, f64::INFINITY);
    for _ in 0..50 {
        let f = residual(down, theta);
        let norm = f.norm();
        if norm < best.2 {
            best = (down, theta, norm);
        }
        if norm < 1e-12 {
            break;
        }
        let (hd, ht) = (1e-7, 1e-7);
        let jd = (residual(down + hd, theta) - f) / hd;
        let jt = (residual(down, theta + ht) - f) / ht;
        let jac = nalgebra::Matrix2::from_columns(&[jd, jt]);
        let Some(inv) = jac.try_inverse() else { break };
        let step = inv * f;
        // Small steps keep the wheels on the ground while the solution is approached.
        let scale = (0.01 / step.x.abs().max(1e-300)).min(0.05 / step.y.abs().max(1e-300));
        let scale = scale.min(1.0);
        down -= step.x * scale;
        theta -= step.y * scale;
    }
    (state(best.0, best.1), best.2)
}
