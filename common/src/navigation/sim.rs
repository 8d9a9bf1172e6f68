//! A kinematic aircraft for the navigation tests: the course follows its command with a
//! first-order lag (time constant 1 s, turn rate limited to a 45-degree bank at the airspeed),
//! the altitude with a first-order lag (2 s, climb and sink limited to 3 m/s), constant
//! airspeed through a steady wind. It stands for the autopilot's closed loops, which are
//! tested on their own in `control`.

use crate::math::wrap_pi;
use nalgebra::Vector3;

const G: f32 = crate::math::GRAVITY;

pub(crate) struct Kinematic {
    pub pos: Vector3<f32>,
    pub heading: f32,
    pub airspeed: f32,
    pub wind: Vector3<f32>,
    pub tau_course: f32,
    pub tau_alt: f32,
    pub max_vz: f32,
}

impl Kinematic {
    pub fn new(pos: Vector3<f32>, heading: f32, airspeed: f32) -> Self {
        Self {
            pos,
            heading,
            airspeed,
            wind: Vector3::zeros(),
            tau_course: 1.0,
            tau_alt: 2.0,
            max_vz: 3.0,
        }
    }

    /// Velocity over ground, NED (horizontal).
    pub fn ground_velocity(&self) -> Vector3<f32> {
        let (s, c) = crate::math::elementary::sin_cos(self.heading);
        Vector3::new(self.airspeed * c, self.airspeed * s, 0.0) + self.wind
    }

    pub fn course(&self) -> f32 {
        let v = self.ground_velocity();
        libm::atan2f(v.y, v.x)
    }

    /// Turns towards `course_cmd` and climbs or sinks towards `alt_cmd`.
    pub fn step(&mut self, course_cmd: f32, alt_cmd: f32, dt: f32) {
        let max_rate =
            G * crate::math::elementary::tan(45f32.to_radians()) / self.airspeed.max(1.0);
        let rate =
            (wrap_pi(course_cmd - self.course()) / self.tau_course).clamp(-max_rate, max_rate);
        self.heading = wrap_pi(self.heading + rate * dt);
        let h = -self.pos.z;
        let vz = ((alt_cmd - h) / self.tau_alt).clamp(-self.max_vz, self.max_vz);
        self.move_by(vz, dt);
    }

    /// Moves along the ground velocity with this climb rate, m/s.
    pub fn move_by(&mut self, climb: f32, dt: f32) {
        let v = self.ground_velocity();
        self.pos += Vector3::new(v.x, v.y, -climb) * dt;
    }
}
