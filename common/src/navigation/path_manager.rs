//! Waypoint switching with fillets (Beard & McLain, *Small Unmanned Aircraft*, section 11.2.2).
//!
//! The manager flies the leg from `window[0]` to `window[1]`. When a following waypoint
//! `window[2]` is known, the corner at `window[1]` is rounded by a fillet, an arc of the turn
//! radius tangent to both legs, so the aircraft turns onto the next leg instead of overshooting
//! the corner and coming back:
//!
//! ```text
//! q_prev, q_next   unit horizontal directions of the two legs
//! rho = acos(-q_prev . q_next)        angle between the legs (pi: straight on)
//! z1  = w - R / tan(rho/2) q_prev     leave the line when crossing H(z1, q_prev)
//! c   = w - R / sin(rho/2) (q_prev - q_next)/|q_prev - q_next|,   lambda = sign(q_prev x q_next)
//! z2  = w + R / tan(rho/2) q_next     fillet done, waypoint reached: H(z2, q_next)
//! H(z, n) = { p : (p - z) . n >= 0 }  half-plane switching, robust to missing a radius
//! ```
//!
//! The radius R is `NAV_TURN_RAD`, widened to the turn at `NAV_TURN_BNK_DEG` of bank over
//! ground when the leg's airspeed and the estimated wind ask for more: `(V_a + W)^2 / (g tan
//! bank)`, laid out when the leg begins.
//!
//! Geometry is horizontal; the line's altitude runs from one waypoint's altitude to the next
//! (the guidance interpolates it) and a fillet is flown at its corner waypoint's altitude.
//!
//! Where a leg is too short for the fillet's tangent length (more than half of either leg), the
//! fillet radius shrinks to fit, so a tight zig-zag is flown with the turn it allows rather than
//! with arcs that overlap; such a corner is turned tighter than the aircraft can and is
//! overshot. Without a following waypoint (or with a turn under 1 degree, or a reversal within
//! 1 degree of 180) the waypoint is reached when inside its acceptance radius or when the
//! half-plane through it is crossed.
//!
//! The caller shifts the window by one after each `reached` event.

use crate::guidance::{OrbitDirection, Path};
use crate::math::RAD2DEG;
use crate::param;
use crate::params::{independent, Group, ParamDef};
use nalgebra::{Vector2, Vector3};

/// Parameters of the path manager. The default fillet radius is the Ultra Stick's turn over
/// ground with the wind behind it: 17 m/s of airspeed and 5 m/s of wind make 22 m/s, and at
/// 35 degrees of bank (the 45-degree limit less room for gusts and the course loop)
/// `22^2 / (g tan 35)` is 70 m. A 50 m fillet held the bank on its limit downwind and let one
/// gust carry the aircraft 20 m outside the corner. Faster, or in more wind, a corner is
/// widened to that turn ([`PathManager::fillet_radius`]): a 135 deg corner flown at 20 m/s
/// with 5 m/s behind was overshot by 58 m on the 70 m fillet. Another aircraft's is
/// `(NAV_ASPD + 5)^2 / (g tan NAV_TURN_BNK_DEG)` the same way.
pub const PARAMS: Group<PathParams> = Group {
    name: "Path manager",
    params: &[
        param!(
            ParamDef::real(
                "NAV_TURN_RAD",
                70.0,
                5.0,
                TURN_RADIUS_MAX,
                "m",
                "Smallest fillet radius at waypoint corners; a corner is widened to the turn at NAV_TURN_BNK_DEG over ground, (airspeed + wind)^2 / (g tan bank), when that is wider",
            ),
            PathParams => turn_radius
        ),
        param!(
            ParamDef::real(
                "NAV_TURN_BNK_DEG",
                TURN_BANK_DEG,
                5.0,
                80.0,
                "deg",
                "Bank a corner's turn and the narrowest loiter are laid out for (LIM_ROLL_DEG less room for gusts)",
            ),
            PathParams => turn_bank, scale RAD2DEG
        ),
    ],
    base: || PathParams {
        turn_radius: 0.0,
        turn_bank: 0.0,
    },
    check: independent,
};

/// The path manager's settings.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct PathParams {
    /// Fillet radius, m.
    pub turn_radius: f32,
    /// `NAV_TURN_BNK_DEG`: bank a fillet is laid out for, rad.
    pub turn_bank: f32,
}

impl Default for PathParams {
    fn default() -> Self {
        PARAMS.defaults()
    }
}

/// Waypoints the manager looks at: the leg's start, its end and the one after.
pub const WINDOW: usize = 3;

/// Turns under this angle are flown through without a fillet, rad (1 deg).
const STRAIGHT_ON: f32 = 1.0 * core::f32::consts::PI / 180.0;

/// `NAV_TURN_BNK_DEG`'s default, deg: the Ultra Stick's 45-degree roll limit less room for
/// gusts and the course loop (`NAV_TURN_RAD`'s default is this turn at 22 m/s over ground).
/// Another aircraft takes its own `LIM_ROLL_DEG` less the same 10 deg.
const TURN_BANK_DEG: f32 = 35.0;
/// Widest fillet, m: `NAV_TURN_RAD`'s upper bound, and the most the wind and airspeed may ask for.
pub const TURN_RADIUS_MAX: f32 = 500.0;

/// One waypoint of the window.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Waypoint {
    /// Caller's identifier, reported back in `reached` (the mission item's sequence number).
    pub id: u16,
    /// Position NED from home, m (down = -height above home).
    pub ned: Vector3<f32>,
    /// Airspeed on the leg towards this waypoint, m/s.
    pub airspeed: f32,
    /// Reached inside this horizontal distance when no fillet rounds it, m.
    pub accept_radius: f32,
}

/// Which part of a leg is being flown.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Segment {
    /// The straight line towards the waypoint.
    Straight,
    /// The fillet arc round the waypoint.
    Fillet,
}

/// Result of one step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PathStep {
    /// The path to follow now.
    pub path: Path,
    /// The id of the waypoint reached on this step, if any.
    pub reached: Option<u16>,
    /// The segment the `path` belongs to.
    pub segment: Segment,
}

/// The fillet path manager.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PathManager {
    turn_radius: f32,
    /// Bank the fillets are laid out for, rad.
    turn_bank: f32,
    /// The leg being flown (its end's id and position), to notice when the caller changes it.
    leg: Option<(u16, Vector3<f32>)>,
    segment: Segment,
    /// The fillet radius of the leg's corner, m, laid out when the leg began.
    leg_radius: f32,
}

impl Default for PathManager {
    fn default() -> Self {
        Self::new(PathParams::default().turn_radius)
    }
}

fn horizontal(v: &Vector3<f32>) -> Vector2<f32> {
    Vector2::new(v.x, v.y)
}

/// Unit vector and length of the horizontal part of `v`; `None` under 1 cm.
fn unit(v: Vector2<f32>) -> Option<(Vector2<f32>, f32)> {
    let n = crate::math::elementary::hypot(v.x, v.y);
    (n > 0.01).then(|| (v / n, n))
}

fn in_half_plane(p: Vector2<f32>, z: Vector2<f32>, n: Vector2<f32>) -> bool {
    (p - z).dot(&n) >= 0.0
}

impl PathManager {
    /// A manager rounding corners with this radius, m (clamped to at least 1 m), and laying
    /// them out for `NAV_TURN_BNK_DEG`'s default bank.
    pub fn new(turn_radius: f32) -> Self {
        let turn_radius = sane_radius(turn_radius);
        Self {
            turn_radius,
            turn_bank: TURN_BANK_DEG / RAD2DEG,
            leg: None,
            segment: Segment::Straight,
            leg_radius: turn_radius,
        }
    }

    /// Takes new settings (the fillet radius, clamped to at least 1 m, and the bank).
    pub fn configure(&mut self, p: &PathParams) {
        self.turn_radius = sane_radius(p.turn_radius);
        self.turn_bank = p.turn_bank;
    }

    /// The fillet radius, m.
    pub fn turn_radius(&self) -> f32 {
        self.turn_radius
    }

    /// Forgets the leg: the next step starts on the straight part of whatever leg it is given.
    pub fn reset(&mut self) {
        self.leg = None;
        self.segment = Segment::Straight;
    }

    /// The present segment.
    pub fn segment(&self) -> Segment {
        self.segment
    }

    /// The fillet radius for a corner flown at up to `airspeed` (m/s) in a wind of
    /// `wind_speed` (m/s): `NAV_TURN_RAD`, or the turn over ground at `NAV_TURN_BNK_DEG` with
    /// the wind behind, `(airspeed + wind)^2 / (g tan bank)`, if that is wider (at most
    /// [`TURN_RADIUS_MAX`]). A non-finite or negative speed counts as none.
    pub fn fillet_radius(&self, airspeed: f32, wind_speed: f32) -> f32 {
        let speed = |v: f32| if v.is_finite() { v.max(0.0) } else { 0.0 };
        self.turn_radius
            .max(self.circle_radius(speed(airspeed) + speed(wind_speed)))
    }

    /// The narrowest circle flown at `airspeed` (m/s) at `NAV_TURN_BNK_DEG` in still air, m:
    /// `airspeed^2 / (g tan bank)` (at most [`TURN_RADIUS_MAX`]; 0 for a speed that is not a
    /// positive number). A loiter narrower than it is widened to it (ArduPlane's
    /// `NAVL1_LIM_BANK`): the bank between it and the roll limit is left for the wind.
    pub fn circle_radius(&self, airspeed: f32) -> f32 {
        let v = if airspeed.is_finite() {
            airspeed.max(0.0)
        } else {
            0.0
        };
        (v * v / (crate::math::GRAVITY * crate::math::elementary::tan(self.turn_bank)))
            .min(TURN_RADIUS_MAX)
    }

    /// One step from the position `pos` (NED from home, m) along the window `[from, to,
    /// next?]`, with the estimated horizontal wind speed `wind_speed` (m/s; 0 when unknown);
    /// `None` when the window holds fewer than two waypoints. A leg shorter than 1 cm is flown
    /// from `pos` straight to `to`. The corner's fillet radius ([`PathManager::fillet_radius`],
    /// at the faster of the two legs' airspeeds) is laid out when the leg begins and kept, so
    /// that a gust does not move the arc under the aircraft.
    pub fn step(
        &mut self,
        pos: &Vector3<f32>,
        window: &[Waypoint],
        wind_speed: f32,
    ) -> Option<PathStep> {
        let (from, to) = match window {
            [a, b, ..] => (a, b),
            _ => return None,
        };
        let next = window.get(2);
        if self.leg != Some((to.id, to.ned)) {
            self.leg = Some((to.id, to.ned));
            self.segment = Segment::Straight;
            let airspeed = next.map_or(to.airspeed, |n| to.airspeed.max(n.airspeed));
            self.leg_radius = self.fillet_radius(airspeed, wind_speed);
        }
        let p = horizontal(pos);
        let w = horizontal(&to.ned);
        let start = if unit(w - horizontal(&from.ned)).is_some() {
            from.ned
        } else {
            *pos
        };
        let line = Path::line_between(&start, &to.ned, to.airspeed);
        let Some(((q_prev, len_prev), line)) = unit(w - horizontal(&start)).zip(line) else {
            // On top of the waypoint: nothing left to fly on this leg.
            return Some(self.reached_step(to, next, pos));
        };

        let fillet = next.and_then(|n| {
            let (q_next, len_next) = unit(horizontal(&n.ned) - w)?;
            let rho = libm::acosf((-q_prev.dot(&q_next)).clamp(-1.0, 1.0));
            // Straight on needs no fillet; a reversal has none (its tangent points are at
            // infinity): both switch at the waypoint.
            if !(STRAIGHT_ON..=core::f32::consts::PI - STRAIGHT_ON).contains(&rho) {
                return None;
            }
            let half = 0.5 * rho;
            let tan_half = crate::math::elementary::tan(half);
            let radius = self
                .leg_radius
                .min(0.5 * len_prev.min(len_next) * tan_half)
                .max(0.01);
            let (dq, _) = unit(q_prev - q_next)?;
            let center = w - radius / crate::math::elementary::sin(half) * dq;
            let cross = q_prev.x * q_next.y - q_prev.y * q_next.x;
            Some(Fillet {
                z1: w - radius / tan_half * q_prev,
                z2: w + radius / tan_half * q_next,
                q_next,
                path: Path::Orbit {
                    center: Vector3::new(center.x, center.y, to.ned.z),
                    radius,
                    direction: if cross >= 0.0 {
                        OrbitDirection::Clockwise
                    } else {
                        OrbitDirection::CounterClockwise
                    },
                    airspeed: to.airspeed,
                },
            })
        });

        let Some(f) = fillet else {
            let inside =
                crate::math::elementary::hypot(p.x - w.x, p.y - w.y) <= to.accept_radius.max(0.0);
            if inside || in_half_plane(p, w, q_prev) {
                return Some(self.reached_step(to, next, pos));
            }
            return Some(PathStep {
                path: line,
                reached: None,
                segment: Segment::Straight,
            });
        };

        if self.segment == Segment::Straight && in_half_plane(p, f.z1, q_prev) {
            self.segment = Segment::Fillet;
        }
        if self.segment == Segment::Fillet && in_half_plane(p, f.z2, f.q_next) {
            return Some(self.reached_step(to, next, pos));
        }
        Some(PathStep {
            path: if self.segment == Segment::Fillet {
                f.path
            } else {
                line
            },
            reached: None,
            segment: self.segment,
        })
    }

    /// `to` is reached: the path becomes the next leg (or, without one, the line through `to`
    /// continued), and the manager waits for the shifted window.
    fn reached_step(
        &mut self,
        to: &Waypoint,
        next: Option<&Waypoint>,
        pos: &Vector3<f32>,
    ) -> PathStep {
        self.segment = Segment::Straight;
        let path = next
            .and_then(|n| Path::line_between(&to.ned, &n.ned, n.airspeed))
            .or_else(|| Path::line_between(pos, &to.ned, to.airspeed))
            .unwrap_or(Path::Orbit {
                center: to.ned,
                radius: self.turn_radius,
                direction: OrbitDirection::Clockwise,
                airspeed: to.airspeed,
            });
        PathStep {
            path,
            reached: Some(to.id),
            segment: Segment::Straight,
        }
    }
}

fn sane_radius(r: f32) -> f32 {
    if r.is_finite() {
        r.max(1.0)
    } else {
        PathParams::default().turn_radius
    }
}

struct Fillet {
    z1: Vector2<f32>,
    z2: Vector2<f32>,
    q_next: Vector2<f32>,
    path: Path,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::guidance::Guidance;
    use crate::navigation::sim::Kinematic;
    use crate::params::{validate_defs, ParamError};
    use approx::assert_abs_diff_eq;

    /// A waypoint flown at 15 m/s, whose still-air turn at 35 deg (33 m) is inside every
    /// fillet radius below: the geometry is the radius given.
    fn wp(id: u16, n: f32, e: f32, h: f32) -> Waypoint {
        Waypoint {
            id,
            ned: Vector3::new(n, e, -h),
            airspeed: 15.0,
            accept_radius: 10.0,
        }
    }

    #[test]
    fn params_well_formed() {
        assert_eq!(validate_defs(PARAMS.defs()), Ok(()));
        let mut m = PathManager::default();
        // The default is the turn over ground of 22 m/s (17 m/s of airspeed, 5 m/s of wind
        // behind) at 35 degrees of bank.
        let r = 22.0f32 * 22.0 / (crate::math::GRAVITY * libm::tanf(35f32.to_radians()));
        assert!(
            (m.turn_radius() - r).abs() < 1.0,
            "{} vs {r}",
            m.turn_radius()
        );
        let mut p = PathParams::default();
        assert_eq!(
            PARAMS.set(&mut p, "NAV_TURN_RAD", 1.0),
            Err(ParamError::OutOfBounds)
        );
        assert_eq!(PARAMS.set(&mut p, "NAV_TURN_RAD", 60.0), Ok(()));
        m.configure(&p);
        assert_eq!(m.turn_radius(), 60.0);
    }

    /// The fillet widens to the turn over ground at 35 deg of bank with the wind behind:
    /// 17 m/s and 5 m/s of wind need 22^2 / (g tan 35) = 70.5 m (the 70 m default's own
    /// design), 20 m/s and 5 m/s 25^2 / (g tan 35) = 91.0 m; 15 m/s in still air (32.8 m)
    /// keeps the parameter's 70 m. A 90 deg corner laid out in that wind at 20 m/s leaves
    /// its line 91 m before the corner, where in still air it keeps to it until 70 m.
    #[test]
    fn the_fillet_widens_with_airspeed_and_wind_to_a_35_degree_turn_over_ground() {
        let m = PathManager::default();
        assert_abs_diff_eq!(m.fillet_radius(17.0, 5.0), 70.5, epsilon = 0.1);
        assert_abs_diff_eq!(m.fillet_radius(20.0, 5.0), 91.0, epsilon = 0.1);
        assert_eq!(m.fillet_radius(15.0, 0.0), 70.0);
        assert_eq!(m.fillet_radius(15.0, f32::NAN), 70.0);
        assert_eq!(m.fillet_radius(f32::INFINITY, 5.0), 70.0);
        assert_eq!(m.fillet_radius(200.0, 0.0), TURN_RADIUS_MAX);
        // An aircraft whose roll limit is 35 deg lays its turns out for 25 deg: 136.7 m.
        let mut p = PathParams::default();
        PARAMS
            .set(&mut p, "NAV_TURN_BNK_DEG", 25.0)
            .expect("in range");
        let mut low = m;
        low.configure(&p);
        assert_abs_diff_eq!(low.fillet_radius(20.0, 5.0), 136.7, epsilon = 0.1);
        let fast = |id| Waypoint {
            airspeed: 20.0,
            ..wp(id, 0.0, 0.0, 50.0)
        };
        let win = [
            fast(0),
            Waypoint {
                ned: Vector3::new(300.0, 0.0, -50.0),
                ..fast(1)
            },
            Waypoint {
                ned: Vector3::new(300.0, 300.0, -50.0),
                ..fast(2)
            },
        ];
        let at = |wind: f32, n: f32| {
            let mut m = PathManager::default();
            m.step(&Vector3::new(100.0, 0.0, -50.0), &win, wind)
                .unwrap();
            m.step(&Vector3::new(n, 0.0, -50.0), &win, wind)
                .unwrap()
                .segment
        };
        assert_eq!(at(5.0, 205.0), Segment::Straight);
        assert_eq!(at(5.0, 212.0), Segment::Fillet);
        assert_eq!(at(0.0, 212.0), Segment::Straight);
        assert_eq!(at(0.0, 232.0), Segment::Fillet);
    }

    /// A 90-degree right turn: the fillet starts R before the corner, is centred R to the
    /// inside of both legs, turns clockwise, and the waypoint is reached R after the corner.
    #[test]
    fn fillet_geometry_of_a_right_angle() {
        let mut m = PathManager::new(40.0);
        let win = [
            wp(0, 0.0, 0.0, 50.0),
            wp(1, 300.0, 0.0, 60.0),
            wp(2, 300.0, 300.0, 60.0),
        ];
        let s = m.step(&Vector3::new(200.0, 0.0, -55.0), &win, 0.0).unwrap();
        assert_eq!(s.segment, Segment::Straight);
        assert!(matches!(s.path, Path::Line { .. }));
        // Just past z1 = (260, 0).
        let s = m.step(&Vector3::new(260.5, 0.0, -60.0), &win, 0.0).unwrap();
        assert_eq!(s.segment, Segment::Fillet);
        match s.path {
            Path::Orbit {
                center,
                radius,
                direction,
                ..
            } => {
                assert_abs_diff_eq!(center.x, 260.0, epsilon = 1e-3);
                assert_abs_diff_eq!(center.y, 40.0, epsilon = 1e-3);
                assert_abs_diff_eq!(center.z, -60.0, epsilon = 1e-6);
                assert_abs_diff_eq!(radius, 40.0, epsilon = 1e-4);
                assert_eq!(direction, OrbitDirection::Clockwise);
            }
            p => panic!("{p:?}"),
        }
        // Before z2 = (300, 40): still turning; past it: reached, next leg.
        let s = m
            .step(&Vector3::new(299.0, 39.0, -60.0), &win, 0.0)
            .unwrap();
        assert_eq!((s.reached, s.segment), (None, Segment::Fillet));
        let s = m
            .step(&Vector3::new(300.0, 40.5, -60.0), &win, 0.0)
            .unwrap();
        assert_eq!(s.reached, Some(1));
        assert!(matches!(s.path, Path::Line { origin, .. } if origin == win[1].ned));
    }

    #[test]
    fn left_turn_is_counter_clockwise_and_short_legs_shrink_the_fillet() {
        let mut m = PathManager::new(40.0);
        let win = [
            wp(0, 0.0, 0.0, 50.0),
            wp(1, 300.0, 0.0, 50.0),
            wp(2, 300.0, -30.0, 50.0),
        ];
        let s = m.step(&Vector3::new(299.0, 0.0, -50.0), &win, 0.0).unwrap();
        match s.path {
            Path::Orbit {
                radius, direction, ..
            } => {
                assert_eq!(direction, OrbitDirection::CounterClockwise);
                // Half of the 30 m leg at 90 degrees.
                assert_abs_diff_eq!(radius, 15.0, epsilon = 1e-3);
            }
            p => panic!("{p:?}"),
        }
    }

    #[test]
    fn a_reversal_switches_at_the_waypoint() {
        let mut m = PathManager::new(40.0);
        let win = [
            wp(0, 0.0, 0.0, 50.0),
            wp(1, 300.0, 0.0, 50.0),
            wp(2, 0.0, 0.0, 50.0),
        ];
        let s = m.step(&Vector3::new(250.0, 0.0, -50.0), &win, 0.0).unwrap();
        assert_eq!((s.reached, s.segment), (None, Segment::Straight));
        let s = m.step(&Vector3::new(300.5, 0.0, -50.0), &win, 0.0).unwrap();
        assert_eq!(s.reached, Some(1));
        match s.path {
            Path::Line { direction, .. } => assert!(direction.x < -0.99),
            p => panic!("{p:?}"),
        }
    }

    #[test]
    fn last_waypoint_reached_by_radius_or_by_passing_it() {
        let mut m = PathManager::new(40.0);
        let win = [wp(0, 0.0, 0.0, 50.0), wp(7, 300.0, 0.0, 50.0)];
        let s = m
            .step(&Vector3::new(280.0, 30.0, -50.0), &win, 0.0)
            .unwrap();
        assert_eq!(s.reached, None);
        let s = m.step(&Vector3::new(295.0, 5.0, -50.0), &win, 0.0).unwrap();
        assert_eq!(s.reached, Some(7));
        let mut m = PathManager::new(40.0);
        let s = m
            .step(&Vector3::new(301.0, 80.0, -50.0), &win, 0.0)
            .unwrap();
        assert_eq!(s.reached, Some(7));
        assert!(m.step(&Vector3::zeros(), &win[..1], 0.0).is_none());
    }

    struct Lap {
        max_outside: f32,
        max_straight_xtrack: f32,
        reached: heapless::Vec<u16, 64>,
    }

    /// Flies the kinematic aircraft round the rectangle 0-(400,0)-(400,300)-(0,300) (clockwise
    /// seen from above) for `laps`, with the given fillet radius; statistics from lap 2 on.
    fn fly_rectangle(turn_radius: f32, laps: usize) -> Lap {
        // The kinematic aircraft's course lag is 1 s: the lead and line gain that match it.
        fly_rect(turn_radius, laps, Guidance::for_course_lag(1.0, 0.03))
    }

    fn fly_rect(turn_radius: f32, laps: usize, g: Guidance) -> Lap {
        let corners = [(0.0, 0.0), (400.0, 0.0), (400.0, 300.0), (0.0, 300.0)];
        let wps: [Waypoint; 4] =
            core::array::from_fn(|i| wp(i as u16, corners[i].0, corners[i].1, 100.0));
        let mut m = PathManager::new(turn_radius);
        // Start 60 m west of the first leg, heading north, 20 m low; wind 5 m/s from the west.
        let mut k = Kinematic::new(Vector3::new(-20.0, -60.0, -80.0), 0.0, 17.0);
        k.wind = Vector3::new(0.0, 5.0, 0.0);
        let mut cur = 0usize; // leg from wps[cur] to wps[cur + 1]
        let mut lap = Lap {
            max_outside: 0.0,
            max_straight_xtrack: 0.0,
            reached: heapless::Vec::new(),
        };
        let dt = 0.05;
        let mut t = 0.0;
        while cur < 4 * laps {
            let win: [Waypoint; 3] = core::array::from_fn(|j| wps[(cur + j) % 4]);
            let s = m.step(&k.pos, &win, 0.0).unwrap();
            let o = g.step(&s.path, &k.pos, k.ground_velocity().xy().norm());
            if let Some(id) = s.reached {
                lap.reached.push(id).unwrap();
                cur += 1;
            }
            if cur >= 4 {
                let (n, e) = (k.pos.x, k.pos.y);
                let outside = (-n).max(n - 400.0).max(-e).max(e - 300.0);
                lap.max_outside = lap.max_outside.max(outside);
                // Straight part, past the settling distance after the previous fillet.
                let from = win[0].ned;
                let along = (k.pos - from)
                    .xy()
                    .dot(&(win[1].ned - from).xy().normalize());
                if s.segment == Segment::Straight
                    && s.reached.is_none()
                    && along > 0.5 * (win[1].ned - from).xy().norm()
                {
                    lap.max_straight_xtrack = lap.max_straight_xtrack.max(o.cross_track.abs());
                }
            }
            k.step(o.course, o.altitude, dt);
            t += dt;
            assert!(t < 2000.0, "stuck on leg {cur}");
        }
        // Altitude converged on the 100 m of the waypoints.
        assert_abs_diff_eq!(-k.pos.z, 100.0, epsilon = 0.5);
        lap
    }

    /// The rectangle in a 5 m/s wind. Fillet radius 50 m: the smallest ground-track radius of a
    /// 45-degree bank turn downwind, (17 + 5)^2 / g = 49 m. Over laps 2 and 3 the cross-track
    /// on the second half of every straight part stays under 0.5 m, and the track never leaves
    /// the rectangle by more than 3 m (a fillet cuts the corner; what is left is the lag of the
    /// course loop as the arc begins and ends, measured 2.3 m).
    #[test]
    fn rectangle_with_fillets_converges_and_does_not_overshoot() {
        let lap = fly_rectangle(50.0, 3);
        assert!(
            lap.max_straight_xtrack < 0.5,
            "cross-track {}",
            lap.max_straight_xtrack
        );
        assert!(lap.max_outside < 3.0, "overshoot {}", lap.max_outside);
        let expect: [u16; 12] = [1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3, 0];
        assert_eq!(&lap.reached[..], &expect[..]);
    }

    /// The same flight with a 5 m "fillet" (switching at the corner, as without fillets):
    /// the aircraft's turn radius (30 to 49 m over ground) carries it far outside, which the
    /// bound above would catch.
    #[test]
    fn without_fillets_the_corners_are_overshot() {
        let lap = fly_rectangle(5.0, 2);
        assert!(lap.max_outside > 10.0, "overshoot {}", lap.max_outside);
    }
}
