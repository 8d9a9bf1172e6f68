//! What every behaviour flies with: a circle, the guidance's output as autopilot commands,
//! tail-wheel steering on the runway, and the inputs of one step.

use super::io::{NavOutput, NavState, Phase};
use super::params::NavParams;
use crate::control::autopilot::Commands;
use crate::control::lateral::{RollMode, YawMode, RUDDER};
use crate::control::longitudinal::LonMode;
use crate::guidance::{Guidance, GuidanceOutput, OrbitDirection, Path};
use crate::math::wrap_pi;
use nalgebra::Vector3;

/// Largest steering deflection, rad.
const STEER_MAX: f32 = 0.4;

/// A circle to fly round (NED from home; its altitude is `-z`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Orbit {
    pub center: Vector3<f32>,
    pub radius: f32,
    pub direction: OrbitDirection,
}

impl Orbit {
    /// A clockwise circle of `NAV_LOIT_RAD` round `center`.
    pub fn loiter(center: Vector3<f32>, p: &NavParams) -> Self {
        Self {
            center,
            radius: p.loiter_radius,
            direction: OrbitDirection::Clockwise,
        }
    }

    /// The circle as a path for the guidance, flown at `airspeed` (m/s).
    pub fn path(&self, airspeed: f32) -> Path {
        Path::Orbit {
            center: self.center,
            radius: self.radius,
            direction: self.direction,
            airspeed,
        }
    }
}

/// The autopilot's commands that follow a guidance output: course, and altitude and airspeed.
pub(super) fn follow(g: &GuidanceOutput) -> Commands {
    Commands {
        roll: RollMode::Course(g.course),
        yaw: RUDDER,
        lon: LonMode::Altitude {
            altitude: g.altitude,
            airspeed: g.airspeed,
        },
    }
}

/// Distance between two points over the ground, m.
pub(super) fn horizontal_dist(a: &Vector3<f32>, b: &Vector3<f32>) -> f32 {
    libm::hypotf(a.x - b.x, a.y - b.y)
}

/// What a behaviour flies on in one step.
#[derive(Clone, Copy, Debug)]
pub(super) struct Flight<'a> {
    pub params: &'a NavParams,
    pub guidance: &'a Guidance,
    pub state: &'a NavState,
    /// Time since the last step, s (0 when the caller's was not a positive number).
    pub dt: f32,
    /// Airspeed of the legs and circles, m/s: `DO_CHANGE_SPEED`'s, or `NAV_ASPD`.
    pub cruise: f32,
}

impl Flight<'_> {
    /// Follows `path`: its guidance and commands into `out`, with the point flown to and the
    /// phase.
    pub fn emit(
        &self,
        path: &Path,
        target: Option<Vector3<f32>>,
        phase: Phase,
        out: &mut NavOutput,
    ) -> GuidanceOutput {
        let g = self
            .guidance
            .step(path, &self.state.pos_ned, self.state.ground_speed());
        out.guidance = Some(g);
        out.commands = Some(follow(&g));
        out.target = target;
        out.phase = phase;
        out.straight = matches!(path, Path::Line { .. });
        g
    }

    /// Tail-wheel steering towards `course` (rad): on the runway the heading is the course.
    pub fn steer(&self, course: f32) -> YawMode {
        let err = wrap_pi(course - self.state.heading);
        // Positive rudder (trailing edge left) turns the nose left.
        let d = -self.params.steer_k * err;
        YawMode::Rudder(if d.is_finite() {
            d.clamp(-STEER_MAX, STEER_MAX)
        } else {
            0.0
        })
    }
}
