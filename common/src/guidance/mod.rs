//! Vector-field path following (Beard & McLain, *Small Unmanned Aircraft*, chapter 10).
//!
//! A [`Path`] (straight line or orbit, in NED metres from home) becomes a course-over-ground
//! command, an altitude command and an airspeed command. The fields command the course over
//! ground, not the heading, so a steady wind is rejected by the course loop: in a crosswind the
//! aircraft crabs and its track still converges on the path.
//!
//! ```text
//! line  (origin r, unit direction q):
//!   chi_q = atan2(q_e, q_n)
//!   e_py  = -sin(chi_q) (p_n - r_n) + cos(chi_q) (p_e - r_e)        cross-track, + right
//!   chi_c = chi_q - chi_inf * 2/pi * atan(k_path * e_py)             (10.8)
//!   h_c   = -r_d + s * (-q_d / |q_h|),  s = along-track distance    (10.5)
//! orbit (centre c, radius rho, direction lambda = +1 clockwise, -1 counter-clockwise):
//!   d = |p - c|_h,  phi = atan2(p_e - c_e, p_n - c_n)
//!   chi_c = phi + lambda (pi/2 + atan(k_orbit (d - rho) / rho))     (10.14)
//!   h_c   = -c_d
//! ```
//!
//! The book's fields assume the course follows its command at once. The course loop is a lag
//! (time constant `tau`): on a circle, where the course turns at
//! `Vg / rho`, a lag alone would ride outside the circle by about `rho/k_orbit tan(tau Vg/rho)`
//! (12 m on a 50 m circle at 22 m/s). The orbit's command therefore leads the field by
//! `lambda tau Vg / rho` (at most 45 degrees), the rate term of Nelson et al.'s
//! `chi_c = chi_d + chi_dot_d / alpha` for a first-order course loop.
//!
//! The defaults (`NAV_CRS_TAU_S` 0.5 s, `NAV_K_PATH` 0.05 /m) are those that flew the default
//! mission best on the 6-DOF Ultra Stick 25e with the computed gains (straight-leg cross-track
//! 0.45 m RMS in calm air; with a lead of 0, 1 and 2 s the circle was ridden 3.7, 4.9 and 13 m
//! outside, see `docs/NAVIGATION.md`). The kinematic tests fly a 1 s lag and set 1 s.
//!
//! A second deviation: the along-track distance `s` of the line's altitude is signed
//! and clamped at 0, so behind the line's origin the command is the origin's altitude rather
//! than the mirror image of the slope ahead.
//!
//! Altitudes here are heights above home, m, up: the datum the firmware gives the autopilot.

use crate::math::{wrap_pi, DEG};
use crate::param;
use crate::params::{independent, Group, ParamDef};
use core::f32::consts::{FRAC_PI_2, PI};
use nalgebra::Vector3;

/// Parameters of the path-following vector fields.
pub const PARAMS: Group<GuidanceParams> = Group {
    name: "Guidance",
    params: &[
        param!(
            ParamDef::real(
                "NAV_CHI_INF_DEG",
                60.0,
                5.0,
                90.0,
                "deg",
                "Approach angle to a straight path far from it (vector field chi_inf)",
            ),
            GuidanceParams => chi_inf, unit DEG
        ),
        param!(
            ParamDef::real(
                "NAV_K_PATH",
                0.05,
                0.001,
                1.0,
                "1/m",
                "Straight-path field gain: how sharply the approach bends onto the line",
            ),
            GuidanceParams => k_path
        ),
        param!(
            ParamDef::real(
                "NAV_K_ORBIT",
                2.0,
                0.1,
                10.0,
                "",
                "Orbit field gain: how sharply the approach bends onto the circle",
            ),
            GuidanceParams => k_orbit
        ),
        param!(
            ParamDef::real(
                "NAV_CRS_TAU_S",
                0.5,
                0.0,
                5.0,
                "s",
                "Course-loop time constant the orbit lead makes up for (0: no lead)",
            ),
            GuidanceParams => course_tau
        ),
    ],
    base: || ZERO,
    check: independent,
};

/// The vector fields' gains, in SI units.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct GuidanceParams {
    /// Approach angle far from a line, rad (0..pi/2].
    pub chi_inf: f32,
    /// Line field gain, 1/m.
    pub k_path: f32,
    /// Orbit field gain.
    pub k_orbit: f32,
    /// Time constant of the closed course loop, s: an orbit's course command leads the field
    /// by the turn rate times this.
    pub course_tau: f32,
}

const ZERO: GuidanceParams = GuidanceParams {
    chi_inf: 0.0,
    k_path: 0.0,
    k_orbit: 0.0,
    course_tau: 0.0,
};

impl Default for GuidanceParams {
    fn default() -> Self {
        PARAMS.defaults()
    }
}

/// Which way an orbit turns, seen from above.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum OrbitDirection {
    /// Clockwise (right turns), the book's lambda = +1.
    Clockwise,
    /// Counter-clockwise (left turns), lambda = -1.
    CounterClockwise,
}

impl OrbitDirection {
    /// The book's lambda: +1 clockwise, -1 counter-clockwise.
    pub fn lambda(self) -> f32 {
        match self {
            OrbitDirection::Clockwise => 1.0,
            OrbitDirection::CounterClockwise => -1.0,
        }
    }

    /// The direction MAVLink's signed loiter radius means: negative is counter-clockwise.
    pub fn from_signed_radius(r: f32) -> Self {
        if r < 0.0 {
            OrbitDirection::CounterClockwise
        } else {
            OrbitDirection::Clockwise
        }
    }
}

/// A path to follow. Positions NED from home, m (down positive: altitude is `-down`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Path {
    /// A straight line through `origin` along `direction`.
    Line {
        /// A point of the line (where its altitude profile starts).
        origin: Vector3<f32>,
        /// Direction of travel, unit vector; its down component sets the climb or descent.
        direction: Vector3<f32>,
        /// Airspeed to fly, m/s.
        airspeed: f32,
    },
    /// A circle around `center`, flown at the centre's altitude.
    Orbit {
        /// Centre of the circle.
        center: Vector3<f32>,
        /// Radius, m (positive).
        radius: f32,
        /// Turning direction.
        direction: OrbitDirection,
        /// Airspeed to fly, m/s.
        airspeed: f32,
    },
}

impl Path {
    /// The airspeed this path is flown at, m/s.
    pub fn airspeed(&self) -> f32 {
        match *self {
            Path::Line { airspeed, .. } | Path::Orbit { airspeed, .. } => airspeed,
        }
    }

    /// A line from `from` to `to` (NED), flown at `airspeed`; `None` when the two points are
    /// less than 1 cm apart horizontally (no direction to follow).
    pub fn line_between(from: &Vector3<f32>, to: &Vector3<f32>, airspeed: f32) -> Option<Self> {
        let d = to - from;
        let h = crate::math::elementary::hypot(d.x, d.y);
        if h.is_nan() || h <= 0.01 {
            return None;
        }
        Some(Path::Line {
            origin: *from,
            direction: d.normalize(),
            airspeed,
        })
    }
}

/// What the guidance asks of the autopilot, plus the tracking error for telemetry.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct GuidanceOutput {
    /// Course over ground to hold, rad in (-pi, pi].
    pub course: f32,
    /// Height above home to hold, m.
    pub altitude: f32,
    /// Airspeed to hold, m/s.
    pub airspeed: f32,
    /// Cross-track error, m: right of a line positive; outside an orbit positive.
    pub cross_track: f32,
    /// Course of the path itself at the closest point, rad (the line's course, or the orbit's
    /// tangent).
    pub path_course: f32,
}

/// The vector-field follower: a plain stage holding only its gains.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Guidance {
    /// Gains in use.
    pub params: GuidanceParams,
}

impl Guidance {
    /// A follower with these gains.
    pub fn new(params: GuidanceParams) -> Self {
        Self { params }
    }

    /// The gains matched to a first-order course loop of time constant `tau` s with the
    /// line gain `k_path` (1/m), the rest at their defaults: what the kinematic test
    /// aircraft (a 1 s course lag) flies with.
    pub fn for_course_lag(tau: f32, k_path: f32) -> Self {
        Self::new(GuidanceParams {
            course_tau: tau,
            k_path,
            ..GuidanceParams::default()
        })
    }

    /// Commands to follow `path` from `pos` (NED from home, m) at the ground speed
    /// `ground_speed` (m/s, used for the orbit's lead only). Stateless: the same inputs give
    /// the same outputs. A degenerate line (no horizontal direction) is flown as its course
    /// north at the origin's altitude; an orbit radius below 1 m is flown as 1 m. Non-finite
    /// inputs give non-finite commands, which the autopilot refuses (holding its outputs).
    pub fn step(&self, path: &Path, pos: &Vector3<f32>, ground_speed: f32) -> GuidanceOutput {
        match *path {
            Path::Line {
                origin,
                direction: q,
                airspeed,
            } => {
                let qh = crate::math::elementary::hypot(q.x, q.y);
                let chi_q = if qh > 1e-6 {
                    libm::atan2f(q.y, q.x)
                } else {
                    0.0
                };
                let (s, c) = crate::math::elementary::sin_cos(chi_q);
                let e = pos - origin;
                let e_py = -s * e.x + c * e.y;
                let along = (c * e.x + s * e.y).max(0.0);
                let slope = if qh > 1e-6 { -q.z / qh } else { 0.0 };
                let chi_inf = self.params.chi_inf;
                let chi_c = chi_q - chi_inf * (2.0 / PI) * libm::atanf(self.params.k_path * e_py);
                GuidanceOutput {
                    course: wrap_pi(chi_c),
                    altitude: -origin.z + along * slope,
                    airspeed,
                    cross_track: e_py,
                    path_course: wrap_pi(chi_q),
                }
            }
            Path::Orbit {
                center,
                radius,
                direction,
                airspeed,
            } => {
                let rho = radius.max(1.0);
                let (dn, de) = (pos.x - center.x, pos.y - center.y);
                let d = crate::math::elementary::hypot(dn, de);
                let phi = libm::atan2f(de, dn);
                let lambda = direction.lambda();
                let lead = if ground_speed.is_finite() {
                    (self.params.course_tau * ground_speed.max(0.0) / rho).min(FRAC_PI_2 / 2.0)
                } else {
                    0.0
                };
                let chi_c = phi
                    + lambda
                        * (FRAC_PI_2 + libm::atanf(self.params.k_orbit * (d - rho) / rho) + lead);
                GuidanceOutput {
                    course: wrap_pi(chi_c),
                    altitude: -center.z,
                    airspeed,
                    cross_track: d - rho,
                    path_course: wrap_pi(phi + lambda * FRAC_PI_2),
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::{validate_defs, ParamError};
    use approx::assert_abs_diff_eq;

    fn line(chi_q: f32) -> Path {
        Path::Line {
            origin: Vector3::new(100.0, -50.0, -80.0),
            direction: Vector3::new(libm::cosf(chi_q), libm::sinf(chi_q), 0.0),
            airspeed: 17.0,
        }
    }

    #[test]
    fn params_well_formed_and_reachable() {
        assert_eq!(validate_defs(PARAMS.defs()), Ok(()));
        let mut p = GuidanceParams::default();
        for d in PARAMS.defs() {
            assert_abs_diff_eq!(PARAMS.get(&p, d.name).unwrap(), d.default, epsilon = 1e-5);
        }
        let g = PARAMS;
        assert_eq!(
            g.set(&mut p, "NAV_K_PATH", 5.0),
            Err(ParamError::OutOfBounds)
        );
        assert_eq!(g.set(&mut p, "NAV_K_PATH", 0.05), Ok(()));
        assert_eq!(p.k_path, 0.05);
        assert_eq!(g.set(&mut p, "NAV_CHI_INF_DEG", 45.0), Ok(()));
        assert_abs_diff_eq!(p.chi_inf, PI / 4.0, epsilon = 1e-6);
    }

    /// On the line the command is the line's course; far to either side it approaches the
    /// line at chi_inf (book eq. 10.8 limits).
    #[test]
    fn line_field_limits() {
        let g = Guidance::default();
        let chi_inf = g.params.chi_inf;
        for chi_q in [0.3_f32, 2.5, -1.9] {
            let p = line(chi_q);
            let (s, c) = libm::sincosf(chi_q);
            let on = Vector3::new(100.0 + 70.0 * c, -50.0 + 70.0 * s, -80.0);
            let o = g.step(&p, &on, 20.0);
            assert_abs_diff_eq!(wrap_pi(o.course - chi_q), 0.0, epsilon = 1e-4);
            assert_abs_diff_eq!(o.cross_track, 0.0, epsilon = 1e-3);
            // 10 km to the right: turn left by chi_inf (within 0.2 deg).
            let right = on + Vector3::new(-s, c, 0.0) * 10_000.0;
            let o = g.step(&p, &right, 20.0);
            assert_abs_diff_eq!(o.cross_track, 10_000.0, epsilon = 0.05);
            assert_abs_diff_eq!(wrap_pi(o.course - (chi_q - chi_inf)), 0.0, epsilon = 0.004);
            let left = on - Vector3::new(-s, c, 0.0) * 10_000.0;
            let o = g.step(&p, &left, 20.0);
            assert_abs_diff_eq!(wrap_pi(o.course - (chi_q + chi_inf)), 0.0, epsilon = 0.004);
        }
    }

    /// One metre off the line the correction is chi_inf * 2/pi * atan(k_path): the field's own
    /// formula, at a point where the small-angle slope is checked independently.
    #[test]
    fn line_field_slope_near_the_line() {
        let g = Guidance::default();
        let p = line(0.0);
        let o = g.step(&p, &Vector3::new(200.0, -49.0, -80.0), 20.0);
        let expect = -g.params.chi_inf * 2.0 / PI * g.params.k_path; // atan(x) ~ x
        assert_abs_diff_eq!(o.course, expect, epsilon = 1e-4);
    }

    /// A line climbing at 1 in 20 commands origin altitude + s/20 along it.
    #[test]
    fn line_altitude_interpolates_along_track() {
        let g = Guidance::default();
        let from = Vector3::new(0.0, 0.0, -50.0);
        let to = Vector3::new(0.0, 400.0, -70.0);
        let p = Path::line_between(&from, &to, 17.0).unwrap();
        for s in [0.0_f32, 100.0, 400.0] {
            // 30 m off the line: the altitude depends only on the along-track distance.
            let o = g.step(&p, &Vector3::new(30.0, s, -10.0), 20.0);
            assert_abs_diff_eq!(o.altitude, 50.0 + s / 20.0, epsilon = 1e-3);
        }
        let behind = g.step(&p, &Vector3::new(0.0, -100.0, -10.0), 20.0);
        assert_abs_diff_eq!(behind.altitude, 50.0, epsilon = 1e-4);
        assert!(Path::line_between(&from, &Vector3::new(0.0, 0.001, -90.0), 17.0).is_none());
    }

    /// On the circle the command is the tangent in the orbit's direction; far away it points
    /// at the centre; the altitude is the centre's. (Lead off: the book's field.)
    #[test]
    fn orbit_field_tangent_and_capture() {
        let mut g = Guidance::default();
        g.params.course_tau = 0.0;
        let center = Vector3::new(10.0, 20.0, -60.0);
        for dir in [OrbitDirection::Clockwise, OrbitDirection::CounterClockwise] {
            let p = Path::Orbit {
                center,
                radius: 50.0,
                direction: dir,
                airspeed: 15.0,
            };
            // North of the centre: clockwise flies east (+pi/2), counter-clockwise west.
            let o = g.step(&p, &(center + Vector3::new(50.0, 0.0, 0.0)), 20.0);
            assert_abs_diff_eq!(o.course, dir.lambda() * FRAC_PI_2, epsilon = 1e-5);
            assert_abs_diff_eq!(o.cross_track, 0.0, epsilon = 1e-4);
            assert_abs_diff_eq!(o.altitude, 60.0, epsilon = 1e-5);
            assert_eq!(o.airspeed, 15.0);
            // East of the centre: clockwise flies south.
            let o = g.step(&p, &(center + Vector3::new(0.0, 50.0, 0.0)), 20.0);
            let expect = if dir == OrbitDirection::Clockwise {
                PI
            } else {
                0.0
            };
            assert_abs_diff_eq!(wrap_pi(o.course - expect), 0.0, epsilon = 1e-5);
            // 50 km east: head west, at the centre.
            let o = g.step(&p, &(center + Vector3::new(0.0, 50_000.0, 0.0)), 20.0);
            assert_abs_diff_eq!(wrap_pi(o.course + FRAC_PI_2), 0.0, epsilon = 0.01);
        }
    }

    /// With the lead, a first-order course loop of time constant tau fed the command turns at
    /// exactly the circle's rate Vg/rho when on the circle and on its tangent.
    #[test]
    fn orbit_lead_makes_up_for_the_course_lag() {
        let g = Guidance::default();
        let tau = g.params.course_tau;
        assert!(tau > 0.0);
        let p = Path::Orbit {
            center: Vector3::zeros(),
            radius: 50.0,
            direction: OrbitDirection::CounterClockwise,
            airspeed: 17.0,
        };
        let o = g.step(&p, &Vector3::new(50.0, 0.0, 0.0), 20.0);
        // Tangent west (-pi/2); the lag turns at (chi_c - chi)/tau.
        let rate = wrap_pi(o.course + FRAC_PI_2) / tau;
        assert_abs_diff_eq!(rate, -20.0 / 50.0, epsilon = 1e-5);
        // A non-finite ground speed drops the lead rather than the command.
        let o = g.step(&p, &Vector3::new(50.0, 0.0, 0.0), f32::NAN);
        assert_abs_diff_eq!(o.course, -FRAC_PI_2, epsilon = 1e-6);
    }

    #[test]
    fn direction_from_signed_radius() {
        assert_eq!(
            OrbitDirection::from_signed_radius(-30.0),
            OrbitDirection::CounterClockwise
        );
        assert_eq!(
            OrbitDirection::from_signed_radius(30.0),
            OrbitDirection::Clockwise
        );
        assert_eq!(
            OrbitDirection::from_signed_radius(0.0),
            OrbitDirection::Clockwise
        );
    }
}
