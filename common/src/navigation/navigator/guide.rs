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

/// The largest bank a turn's airspeed floor is reckoned at, rad (60 deg: a load factor of 2).
const TURN_FLOOR_BANK_MAX: f32 = core::f32::consts::FRAC_PI_3;

/// The airspeed of the legs and circles at bank `roll` (rad): `cruise`, but no slower than
/// `NAV_ASPD_MIN` raised by the turn's load factor, `NAV_ASPD_MIN sqrt(1 / cos(roll))` (the
/// stall speed grows with the square root of the load factor: PX4's and ArduPlane's floor), nor
/// faster than `NAV_ASPD_MAX`. A mission's `DO_CHANGE_SPEED` to the minimum holds it on the
/// legs; in a 40 deg turn the wing needs 14 % more (the Aerosonde's elevator reached its stop
/// in such turns at its 20 m/s minimum). The bank is counted to 60 deg; one that is not a
/// number leaves `cruise` as it is.
pub(super) fn turn_airspeed(cruise: f32, p: &NavParams, roll: f32) -> f32 {
    if !roll.is_finite() {
        return cruise;
    }
    let bank = roll.abs().min(TURN_FLOOR_BANK_MAX);
    let floor = p.airspeed_min / libm::sqrtf(crate::math::elementary::cos(bank));
    cruise.max(floor.min(p.airspeed_max))
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

/// Holding `course` (rad) at `height` (m) above the ground: the bank allowed widens linearly
/// from `NAV_GND_RLL_DEG` at the ground to 90 deg at `NAV_GND_RLL_M` (the roll limit governs
/// once it is the smaller), so a wing tip cannot touch (the Ultra Stick's does at 17 deg of
/// bank with its wheels on the ground, at 38 deg with them 0.2 m up, at none from 0.45 m).
pub(super) fn course_near_ground(course: f32, height: f32, p: &NavParams) -> RollMode {
    match p.bank_near_ground(height, p.ground_roll_height) {
        Some(roll_max) => RollMode::CourseWithin { course, roll_max },
        None => RollMode::Course(course),
    }
}

/// Holding `course` (rad) at `height` (m) in the take-off, the approach, the flare and the
/// go-around's climb: the bank allowed widens to 90 deg at `widen_m` (m) as in
/// [`course_near_ground`], and is held as a limit above it too, where the roll limit governs.
/// A course held within a limit is one the autopilot does not slew
/// ([`RollMode::CourseWithin`]): its roll command follows the course loop's answer to gusts
/// near the runway at once.
pub(super) fn course_near_runway(
    course: f32,
    height: f32,
    widen_m: f32,
    p: &NavParams,
) -> RollMode {
    RollMode::CourseWithin {
        course,
        roll_max: p
            .bank_near_ground(height, widen_m)
            .unwrap_or(core::f32::consts::FRAC_PI_2),
    }
}

/// Holding `course` (rad) at `height` (m) in the take-off regime's climb from the runway (the
/// take-off's and the go-around's: fixed pitch, full throttle, up to `NAV_TKO_CLR_M`): the bank
/// allowed widens over that height rather than `NAV_GND_RLL_M` alone, as PX4 holds the wings
/// level to `RWTO_NAV_ALT` and ArduPlane to `TKOFF_LVL_ALT`. At the regime's fixed pitch a
/// bank costs the climb its lift's vertical part: nine aircraft of the campaign's 1000 that
/// lifted off into a gust's swing, or 90 deg off the line after a ground loop, turned back
/// at 30-45 deg a metre or two up, sank, and put a wing tip on the runway.
pub(super) fn climb_from_runway(course: f32, height: f32, p: &NavParams) -> RollMode {
    course_near_runway(course, height, p.ground_roll_height.max(p.takeoff_clear), p)
}

/// Distance between two points over the ground, m.
pub(super) fn horizontal_dist(a: &Vector3<f32>, b: &Vector3<f32>) -> f32 {
    crate::math::elementary::hypot(a.x - b.x, a.y - b.y)
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
    /// The airspeed's gust level, m/s (its standard deviation about its slow mean).
    pub gust: f32,
    /// The narrowest circle flown at `cruise`, m
    /// ([`crate::navigation::path_manager::PathManager::circle_radius`]).
    pub circle_min: f32,
}

impl Flight<'_> {
    /// `orbit` as a path flown at `airspeed` (m/s), widened to [`Flight::circle_min`] where it
    /// is narrower.
    // Out of line: inlined at its seven sites, it cost the MCU image some 200 bytes.
    #[inline(never)]
    pub fn circle(&self, orbit: &Orbit, airspeed: f32) -> Path {
        Orbit {
            radius: orbit.radius.max(self.circle_min),
            ..*orbit
        }
        .path(airspeed)
    }

    /// Follows `path`: its guidance and commands into `out`, with the point flown to and the
    /// phase; the bank limited near the ground ([`course_near_ground`], the height above
    /// home), the airspeed no slower than the bank flown needs ([`turn_airspeed`]).
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
        let g = GuidanceOutput {
            airspeed: turn_airspeed(g.airspeed, self.params, self.state.roll),
            ..g
        };
        out.guidance = Some(g);
        // Whatever brought the aircraft this low (a failsafe's return or circle just after
        // the take-off's climb, a go-around's circuit), its wing tips keep off the ground.
        out.commands = Some(Commands {
            roll: course_near_ground(g.course, self.state.height(), self.params),
            ..follow(&g)
        });
        out.target = target;
        out.phase = phase;
        out.straight = matches!(path, Path::Line { .. });
        g
    }

    /// Tail-wheel steering towards `course` (rad): on the runway the heading is the course.
    pub fn steer(&self, course: f32) -> YawMode {
        let k = self.params.steer_k;
        // The error only as far as it can move the wheel (0.27 rad at the default gain): beyond
        // it the wheel is at its stop anyway, and the error's full size would outweigh the
        // yaw-rate term and flip the wheel at every half turn of a spin (in moderate
        // turbulence at 2-5 m/s, an aircraft pirouetted at 150 deg/s for 20 s with the wheel
        // swapping stops each second). Held there, the yaw-rate term stops the spin.
        let reach = if k > 0.0 { STEER_MAX / k } else { 0.0 };
        let err = wrap_pi(course - self.state.heading).max(-reach).min(reach);
        // Positive rudder (trailing edge left) turns the nose left. A taildragger's centre of
        // gravity behind its main wheels makes it swing further once it swings: the yaw-rate
        // term opposes the swing before the heading error has grown.
        let d = -k * err + self.params.steer_d * self.state.yaw_rate;
        YawMode::Rudder(if d.is_finite() {
            d.clamp(-STEER_MAX, STEER_MAX)
        } else {
            0.0
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `NAV_ASPD_MIN` times the root of the load factor, the bank counted to 60 deg, within
    /// `NAV_ASPD_MAX`; a bank that is not a number leaves the cruise.
    #[test]
    fn a_turns_airspeed_floor_is_the_minimum_times_the_root_of_its_load_factor() {
        let p = NavParams {
            airspeed_min: 20.0,
            airspeed_max: 32.0,
            ..NavParams::default()
        };
        let deg = |d: f32| d.to_radians();
        // 40 deg: a load factor of 1.305, 20 m/s becomes 22.85.
        assert!((turn_airspeed(20.0, &p, deg(-40.0)) - 22.85).abs() < 0.01);
        // Level, or a cruise above the floor: the cruise.
        assert_eq!(turn_airspeed(20.0, &p, 0.0), 20.0);
        assert_eq!(turn_airspeed(25.0, &p, deg(40.0)), 25.0);
        // Counted to 60 deg (a load factor of 2), never over the maximum.
        assert!((turn_airspeed(20.0, &p, deg(80.0)) - 28.28).abs() < 0.01);
        let low_max = NavParams {
            airspeed_max: 22.0,
            ..p
        };
        assert_eq!(turn_airspeed(20.0, &low_max, deg(60.0)), 22.0);
        assert_eq!(turn_airspeed(20.0, &p, f32::NAN), 20.0);
    }

    /// The tail wheel in a ground loop: swinging right at 150 deg/s, the wheel stays against
    /// the swing whether the course lies just left or just right of the tail (the
    /// heading error's size, clamped to the wheel's reach, no longer flips it at the half
    /// turn); at rest the error alone steers, as before, the same wheel for any error beyond
    /// its reach.
    #[test]
    fn a_spinning_aircraft_s_tail_wheel_stays_against_the_spin_at_the_half_turn() {
        let p = NavParams::default();
        let g = crate::guidance::Guidance::default();
        let wheel = |heading_err_deg: f32, yaw_rate: f32| {
            let state = NavState {
                heading: 0.0,
                yaw_rate,
                ..NavState::default()
            };
            let f = Flight {
                params: &p,
                guidance: &g,
                state: &state,
                dt: 0.02,
                cruise: 17.0,
                gust: 0.0,
                circle_min: 0.0,
            };
            match f.steer(heading_err_deg.to_radians()) {
                YawMode::Rudder(r) => r,
                other => panic!("{other:?}"),
            }
        };
        let spin = 150f32.to_radians();
        for err in [179.0, -179.0, 90.0, -90.0] {
            // Positive: the nose pushed left, against the swing to the right; at least the
            // yaw-rate term (0.3 s x 2.62 rad/s) less the error's full reach (0.4).
            let r = wheel(err, spin);
            assert!(r > 0.385 && r <= STEER_MAX, "course {err} deg off: {r}");
        }
        assert_eq!(wheel(170.0, 0.0), -STEER_MAX);
        assert_eq!(wheel(-170.0, 0.0), STEER_MAX);
        assert!((wheel(5.0, 0.0) + p.steer_k * 5f32.to_radians()).abs() < 1e-6);
    }

    /// The bank allowed on a course close to the ground: `NAV_GND_RLL_DEG` (5 deg) on it, widening
    /// linearly to 90 deg at `NAV_GND_RLL_M` (3 m), where the roll limit alone governs.
    #[test]
    fn the_bank_allowed_near_the_ground_widens_with_height() {
        let p = NavParams::default();
        for (h, expected) in [(-1.0, 5.0), (0.0, 5.0), (0.3, 13.5), (1.5, 47.5)] {
            match course_near_ground(0.3, h, &p) {
                RollMode::CourseWithin { course, roll_max } => {
                    assert_eq!(course, 0.3);
                    assert!(
                        (roll_max.to_degrees() - expected).abs() < 1e-3,
                        "at {h} m: {} deg",
                        roll_max.to_degrees()
                    );
                }
                other => panic!("at {h} m: {other:?}"),
            }
        }
        for h in [3.0, 50.0, f32::NAN] {
            assert_eq!(
                course_near_ground(0.3, h, &p),
                RollMode::Course(0.3),
                "at {h} m"
            );
        }
    }

    /// Near the runway the course is always held within a limit (so the autopilot does not
    /// slew its roll command): the same bank as `course_near_ground` low down, 90 deg above
    /// the widening height.
    #[test]
    fn near_the_runway_the_course_is_held_within_the_bank_near_the_ground_or_a_right_angle() {
        let p = NavParams::default();
        for h in [0.0, 0.3, 1.5] {
            let RollMode::CourseWithin { roll_max, .. } = course_near_ground(0.3, h, &p) else {
                panic!("at {h} m");
            };
            assert_eq!(
                course_near_runway(0.3, h, p.ground_roll_height, &p),
                RollMode::CourseWithin {
                    course: 0.3,
                    roll_max
                }
            );
        }
        for h in [3.0, 50.0, f32::NAN] {
            assert_eq!(
                course_near_runway(0.3, h, p.ground_roll_height, &p),
                RollMode::CourseWithin {
                    course: 0.3,
                    roll_max: core::f32::consts::FRAC_PI_2
                },
                "at {h} m"
            );
        }
    }

    /// A 2.9 m wing whose tip touches the ground at 8 deg of bank on its wheels (about the
    /// Aerosonde's span): the bank that keeps half the tip's clearance, asin((sin 8 deg +
    /// 2h/2.9) / 2), governs where it is the narrower: 9.96 deg at 0.3 m (the height law
    /// allows 13.5), 35.9 deg at 1.5 m (47.5); at 5 m neither limits. The Ultra Stick's
    /// 1.27 m wing and 17 deg leave the height law governing (8.4 deg on the ground).
    #[test]
    fn a_long_wing_banks_near_the_ground_no_more_than_keeps_half_its_tip_clearance() {
        let p = NavParams {
            wing_span: 2.9,
            tip_ground_bank: 8.0_f32.to_radians(),
            ..NavParams::default()
        };
        for (h, expected) in [(0.3, 9.96), (1.5, 35.9)] {
            match course_near_ground(0.3, h, &p) {
                RollMode::CourseWithin { roll_max, .. } => assert!(
                    (roll_max.to_degrees() - expected).abs() < 0.05,
                    "at {h} m: {} deg",
                    roll_max.to_degrees()
                ),
                other => panic!("at {h} m: {other:?}"),
            }
        }
        assert_eq!(course_near_ground(0.3, 5.0, &p), RollMode::Course(0.3));
        let ultra_stick = NavParams::default();
        let on_ground = ultra_stick.bank_for_tip_clearance(0.0).expect("a limit");
        assert!((on_ground.to_degrees() - 8.41).abs() < 0.05, "{on_ground}");
        for h in [0.0, 0.3, 1.0, 2.0, 2.9] {
            let linear = ultra_stick.ground_roll_max
                + (90.0f32.to_radians() - ultra_stick.ground_roll_max) * h / 3.0;
            let allowed = ultra_stick.bank_near_ground(h, 3.0).expect("a limit");
            assert!((allowed - linear).abs() < 1e-6, "at {h} m: {allowed} rad");
        }
    }
}
