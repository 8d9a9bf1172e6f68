//! What the control stages read: the measured state, and the flags that say which of its
//! values (or the command, or the time step) a tick refused.

/// The measured state the autopilot flies on. SI units, radians; body rates in the body frame.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Measurements {
    /// Roll angle phi, rad.
    pub roll: f32,
    /// Pitch angle theta, rad.
    pub pitch: f32,
    /// Course over ground chi, rad (the heading psi in still air, as the thesis assumes).
    pub course: f32,
    /// Roll rate p, rad/s.
    pub roll_rate: f32,
    /// Pitch rate q, rad/s.
    pub pitch_rate: f32,
    /// Yaw rate r, rad/s.
    pub yaw_rate: f32,
    /// Altitude h, m (any datum, the same as the altitude commands').
    pub altitude: f32,
    /// Airspeed Va, m/s.
    pub airspeed: f32,
    /// Sideslip beta, rad.
    pub sideslip: f32,
    /// Ground speed Vg, m/s (0: not measured; the course loop then flies its design's gains).
    pub ground_speed: f32,
}

impl Measurements {
    /// Wings-level, straight flight at this airspeed and altitude, heading north, in still air.
    pub fn level(airspeed: f32, altitude: f32) -> Self {
        Self {
            airspeed,
            altitude,
            ground_speed: airspeed,
            ..Self::default()
        }
    }
}

/// The course the course loop reads: the course over the ground `course` (rad) where the
/// ground speed `ground_speed` (m/s) gives one (over `MIN_COURSE_SPEED_MPS`), and below it the
/// heading `heading` turned by the crab angle of the last reading that did. `crab` (rad, the
/// course less the heading) is kept up to date from each reading that gives one. The heading
/// alone there read a step of the whole crab into the course error: on an approach into a
/// 12 m/s gust the ground speed fell under 3 m/s with 11 deg of crab, the course loop asked
/// 37 deg of bank at once and the aircraft was upset (seed 2's flight 418,
/// docs/RESULTS-MONTECARLO.md).
pub fn course_or_crabbed_heading(
    course: f32,
    heading: f32,
    ground_speed: f32,
    crab: &mut f32,
) -> f32 {
    if ground_speed > crate::math::MIN_COURSE_SPEED_MPS && course.is_finite() {
        let c = crate::math::wrap_pi(course - heading);
        if c.is_finite() {
            *crab = c;
        }
        course
    } else if crab.is_finite() {
        crate::math::wrap_pi(heading + *crab)
    } else {
        heading
    }
}

/// A set of inputs, as bits: which measurements (or the command, or the time step) were refused.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct InputFlags(pub u16);

impl InputFlags {
    /// Roll angle.
    pub const ROLL: Self = Self(1 << 0);
    /// Pitch angle.
    pub const PITCH: Self = Self(1 << 1);
    /// Course.
    pub const COURSE: Self = Self(1 << 2);
    /// Roll rate.
    pub const ROLL_RATE: Self = Self(1 << 3);
    /// Pitch rate.
    pub const PITCH_RATE: Self = Self(1 << 4);
    /// Yaw rate.
    pub const YAW_RATE: Self = Self(1 << 5);
    /// Altitude.
    pub const ALTITUDE: Self = Self(1 << 6);
    /// Airspeed.
    pub const AIRSPEED: Self = Self(1 << 7);
    /// Sideslip.
    pub const SIDESLIP: Self = Self(1 << 8);
    /// A setpoint of the commands.
    pub const COMMAND: Self = Self(1 << 9);
    /// The time step.
    pub const DT: Self = Self(1 << 10);

    /// No flag.
    pub const fn empty() -> Self {
        Self(0)
    }

    /// No flag set.
    pub const fn is_empty(self) -> bool {
        self.0 == 0
    }

    /// All flags of `other` are set.
    pub const fn contains(self, other: Self) -> bool {
        self.0 & other.0 == other.0
    }

    /// Sets (`on`) or clears the flags of `other`.
    pub fn set(&mut self, other: Self, on: bool) {
        if on {
            self.0 |= other.0;
        } else {
            self.0 &= !other.0;
        }
    }
}

impl core::ops::BitOr for InputFlags {
    type Output = Self;
    fn bitor(self, rhs: Self) -> Self {
        Self(self.0 | rhs.0)
    }
}

impl core::ops::BitOrAssign for InputFlags {
    fn bitor_assign(&mut self, rhs: Self) {
        self.0 |= rhs.0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::DEG;

    #[test]
    fn slowing_over_the_ground_reads_the_heading_turned_by_the_last_crab_with_no_step() {
        // Into a strong wind: course 11 deg, heading 22.7 deg (11.7 deg of crab).
        let (course, heading) = (11.0 * DEG, 22.7 * DEG);
        let mut crab = 0.0;
        let fast = course_or_crabbed_heading(course, heading, 4.0, &mut crab);
        assert_eq!(fast, course);
        assert!((crab + 11.7 * DEG).abs() < 1e-6, "{}", crab / DEG);
        // Under 3 m/s over the ground the course is not read: the same 11 deg, not 22.7.
        let slow = course_or_crabbed_heading(f32::NAN, heading, 2.0, &mut crab);
        assert!((slow - course).abs() < 1e-6, "{}", slow / DEG);
        // The nose swinging 5 deg right moves the reading with it.
        let swung = course_or_crabbed_heading(course, heading + 5.0 * DEG, 1.0, &mut crab);
        assert!((swung - 16.0 * DEG).abs() < 1e-5, "{}", swung / DEG);
        // Standing still from boot (no crab yet), the heading itself.
        let mut none = 0.0;
        assert_eq!(
            course_or_crabbed_heading(0.3, heading, 0.0, &mut none),
            heading
        );
    }

    #[test]
    fn a_crab_that_is_not_a_number_leaves_the_heading() {
        let mut crab = f32::NAN;
        assert_eq!(course_or_crabbed_heading(0.1, 0.4, 1.0, &mut crab), 0.4);
        // A course that is not a number at speed keeps the last crab.
        let mut crab = 0.2;
        assert!((course_or_crabbed_heading(f32::NAN, 0.4, 10.0, &mut crab) - 0.6).abs() < 1e-6);
        assert_eq!(crab, 0.2);
    }
}
