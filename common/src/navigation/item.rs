//! Mission items as the navigator flies them: each MAVLink item decoded once into a
//! [`NavItem`], with the rules for absent and out-of-range parameters in one place.
//!
//! The plan keeps its items as they were uploaded (they go back to a ground station bit for
//! bit); the navigator decodes an item where it takes it, through a [`Route`].
//!
//! Decode rules, per command (MAVLink's `param1..param4` are `p1..p4` here):
//! - positions and altitudes: as [`Place::of`] reads them (a 0/0 or non-global position and a
//!   NaN or non-global altitude are left to the aircraft's present ones);
//! - `NAV_WAYPOINT`: acceptance radius `p2` when positive;
//! - `NAV_LOITER_*`: radius `p3` (`p2` for `LOITER_TO_ALT`) when finite and at least 1 m in
//!   size, turning counter-clockwise when negative; turns and time `p1`, negative or NaN as 0;
//! - `NAV_TAKEOFF`: yaw `p4` in degrees when finite;
//! - `DO_JUMP`: target `p1` when a whole, non-negative number; repeats `p2` (`-1`: for ever;
//!   a whole count when finite and non-negative; none otherwise);
//! - `DO_CHANGE_SPEED`: speed type `p1` 0 or 1 (air or ground speed), speed `p2` when positive,
//!   `-2` for the cruise airspeed;
//! - `DO_SET_HOME`: `p1` 1 for the present position, else the item's point and altitude.

use super::items::{
    Altitude, Place, DO_CHANGE_SPEED, DO_JUMP, DO_SET_HOME, NAV_LAND, NAV_LOITER_TIME,
    NAV_LOITER_TO_ALT, NAV_LOITER_TURNS, NAV_LOITER_UNLIM, NAV_RETURN_TO_LAUNCH, NAV_TAKEOFF,
    NAV_WAYPOINT,
};
use super::plan::MissionItem;
use crate::guidance::OrbitDirection;
use crate::math::geodetic::GeoPoint;
use crate::math::{wrap_pi, DEG};

/// One mission item, decoded.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NavItem {
    /// What the item does.
    pub command: NavCommand,
    /// Go on to the next item when this one is done.
    pub autocontinue: bool,
}

/// What a mission item does.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum NavCommand {
    /// `NAV_WAYPOINT`: fly to the place.
    Waypoint {
        /// Where.
        place: Place,
        /// Acceptance radius, m; `None`: `NAV_ACC_RAD`.
        accept_radius_m: Option<f32>,
    },
    /// `NAV_LOITER_UNLIM`, `_TURNS`, `_TIME`, `_TO_ALT`: circle the place.
    Loiter {
        /// The circle's centre.
        place: Place,
        /// Its radius and direction.
        circle: Circle,
        /// What ends it.
        until: LoiterEnd,
    },
    /// `NAV_TAKEOFF`: climb out to the place's altitude.
    Takeoff {
        /// Where the climb goes to.
        place: Place,
        /// Runway course, rad in (-pi, pi], when the item gives one.
        yaw: Option<f32>,
    },
    /// `NAV_LAND`: land at the place.
    Land {
        /// The touchdown point.
        place: Place,
    },
    /// `NAV_RETURN_TO_LAUNCH`: fly home. The item's place is still the next position a loiter
    /// before it heads for.
    ReturnToLaunch {
        /// The place the item names (not flown to).
        place: Place,
    },
    /// `DO_JUMP`: go back (or on) to another item a number of times.
    Jump {
        /// The item jumped to; `None` when `p1` names no item.
        target: Option<usize>,
        /// How often.
        repeat: JumpRepeat,
    },
    /// `DO_CHANGE_SPEED`.
    ChangeSpeed(SpeedChange),
    /// `DO_SET_HOME`.
    SetHome(HomeChange),
    /// A command this navigator does not execute.
    Unsupported {
        /// Its `MAV_CMD` number.
        command: u16,
    },
}

/// A loiter's circle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Circle {
    /// Radius, m; `None`: `NAV_LOIT_RAD`.
    pub radius_m: Option<f32>,
    /// Which way round.
    pub direction: OrbitDirection,
}

/// What ends a loiter.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LoiterEnd {
    /// Nothing: `LOITER_UNLIM`.
    Unlimited,
    /// A number of turns once on the circle (not negative).
    Turns(f32),
    /// A time on the circle, s (not negative).
    Time(f32),
    /// Reaching the place's altitude: `LOITER_TO_ALT`.
    Altitude,
}

/// How often a `DO_JUMP` jumps.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum JumpRepeat {
    /// For ever (`-1`).
    Forever,
    /// This many times.
    Times(u32),
}

/// What a `DO_CHANGE_SPEED` does.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SpeedChange {
    /// Fly at this airspeed, m/s (before the navigator's limits).
    To(f32),
    /// Back to the cruise airspeed, `NAV_ASPD`.
    Cruise,
    /// A speed type this navigator knows, with no speed to set.
    Keep,
    /// A speed type this navigator does not fly.
    Unsupported,
}

/// Where a `DO_SET_HOME` puts home.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum HomeChange {
    /// Where the aircraft is.
    Here,
    /// At a point, at an altitude when the item gives one (else home's own).
    At {
        /// Home's new point.
        point: GeoPoint,
        /// Its altitude, when given.
        alt: Option<Altitude>,
    },
}

impl NavCommand {
    /// A navigation command (one that flies somewhere), not a `DO_*` one.
    pub fn is_nav(&self) -> bool {
        self.place().is_some()
    }

    /// The place a navigation command names.
    pub fn place(&self) -> Option<Place> {
        match *self {
            NavCommand::Waypoint { place, .. }
            | NavCommand::Loiter { place, .. }
            | NavCommand::Takeoff { place, .. }
            | NavCommand::Land { place }
            | NavCommand::ReturnToLaunch { place } => Some(place),
            _ => None,
        }
    }
}

impl NavItem {
    /// Decodes a MAVLink mission item.
    pub fn decode(item: &MissionItem) -> Self {
        let p = |i| item.param(i);
        let place = Place::of(item);
        let command = match item.command {
            NAV_WAYPOINT => NavCommand::Waypoint {
                place,
                accept_radius_m: (p(1) > 0.0).then_some(p(1)),
            },
            NAV_LOITER_UNLIM | NAV_LOITER_TURNS | NAV_LOITER_TIME | NAV_LOITER_TO_ALT => {
                let r = if item.command == NAV_LOITER_TO_ALT {
                    p(1)
                } else {
                    p(2)
                };
                let until = match item.command {
                    NAV_LOITER_TURNS => LoiterEnd::Turns(p(0).max(0.0)),
                    NAV_LOITER_TIME => LoiterEnd::Time(p(0).max(0.0)),
                    NAV_LOITER_TO_ALT => LoiterEnd::Altitude,
                    _ => LoiterEnd::Unlimited,
                };
                NavCommand::Loiter {
                    place,
                    circle: Circle {
                        radius_m: (r.is_finite() && r.abs() >= 1.0).then_some(r.abs()),
                        direction: OrbitDirection::from_signed_radius(r),
                    },
                    until,
                }
            }
            NAV_TAKEOFF => NavCommand::Takeoff {
                place,
                yaw: p(3).is_finite().then(|| wrap_pi(p(3) * DEG)),
            },
            NAV_LAND => NavCommand::Land { place },
            NAV_RETURN_TO_LAUNCH => NavCommand::ReturnToLaunch { place },
            DO_JUMP => NavCommand::Jump {
                target: jump_target(p(0)),
                repeat: jump_repeat(p(1)),
            },
            DO_CHANGE_SPEED => NavCommand::ChangeSpeed(speed_change(p(0), p(1))),
            DO_SET_HOME => NavCommand::SetHome(match place.point {
                Some(point) if p(0) != 1.0 => HomeChange::At {
                    point,
                    alt: place.alt,
                },
                _ => HomeChange::Here,
            }),
            command => NavCommand::Unsupported { command },
        };
        Self {
            command,
            autocontinue: item.autocontinue,
        }
    }
}

/// A jump's target item: a whole, non-negative number.
fn jump_target(t: f32) -> Option<usize> {
    // `as` saturates: a target past any plan stays past it.
    (t.is_finite() && t >= 0.0 && libm::truncf(t) == t).then_some(t as usize)
}

/// A jump's repeat count: `-1` for ever, the whole part of a finite non-negative count, no
/// repeat for anything else.
fn jump_repeat(r: f32) -> JumpRepeat {
    if r == -1.0 {
        JumpRepeat::Forever
    } else if r.is_finite() && r >= 0.0 {
        // `as` saturates: more repeats than a u32 holds are more than a jump counter counts.
        JumpRepeat::Times(libm::truncf(r) as u32)
    } else {
        JumpRepeat::Times(0)
    }
}

/// A speed change from its speed type and speed.
fn speed_change(kind: f32, speed: f32) -> SpeedChange {
    if kind == 0.0 || kind == 1.0 {
        if speed > 0.0 {
            SpeedChange::To(speed)
        } else if speed == -2.0 {
            SpeedChange::Cruise
        } else {
            SpeedChange::Keep
        }
    } else {
        SpeedChange::Unsupported
    }
}

/// The items the navigator flies: the stored mission, as uploaded, or one item built on board
/// (the Takeoff mode's climb-out).
#[derive(Clone, Copy, Debug)]
pub enum Route<'a> {
    /// The stored mission's items.
    Plan(&'a [MissionItem]),
    /// A single item.
    Item(&'a NavItem),
}

impl Route<'_> {
    /// How many items.
    pub fn len(&self) -> usize {
        match self {
            Route::Plan(items) => items.len(),
            Route::Item(_) => 1,
        }
    }

    /// No items.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Item `seq`, decoded.
    pub fn get(&self, seq: usize) -> Option<NavItem> {
        match self {
            Route::Plan(items) => items.get(seq).map(NavItem::decode),
            Route::Item(item) => (seq == 0).then_some(**item),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::navigation::tests::{home, item};

    fn decode(command: u16, params: [f32; 4]) -> NavCommand {
        NavItem::decode(&item(command, params, 100.0, 50.0, 80.0)).command
    }

    #[test]
    fn a_waypoint_without_a_positive_radius_takes_the_default() {
        for r in [0.0, -3.0, f32::NAN] {
            assert!(matches!(
                decode(NAV_WAYPOINT, [0.0, r, 0.0, 0.0]),
                NavCommand::Waypoint {
                    accept_radius_m: None,
                    ..
                }
            ));
        }
        assert!(matches!(
            decode(NAV_WAYPOINT, [0.0, 12.0, 0.0, 0.0]),
            NavCommand::Waypoint {
                accept_radius_m: Some(12.0),
                ..
            }
        ));
    }

    #[test]
    fn a_negative_loiter_radius_turns_counter_clockwise_and_a_tiny_one_is_the_default() {
        let NavCommand::Loiter { circle, until, .. } =
            decode(NAV_LOITER_TURNS, [2.0, 0.0, -40.0, 0.0])
        else {
            panic!("not a loiter");
        };
        assert_eq!(circle.radius_m, Some(40.0));
        assert_eq!(circle.direction, OrbitDirection::CounterClockwise);
        assert_eq!(until, LoiterEnd::Turns(2.0));
        let NavCommand::Loiter { circle, until, .. } =
            decode(NAV_LOITER_TO_ALT, [0.0, 0.5, 90.0, 0.0])
        else {
            panic!("not a loiter");
        };
        assert_eq!(circle.radius_m, None);
        assert_eq!(until, LoiterEnd::Altitude);
        let NavCommand::Loiter { until, .. } = decode(NAV_LOITER_TIME, [f32::NAN, 0.0, 0.0, 0.0])
        else {
            panic!("not a loiter");
        };
        assert_eq!(until, LoiterEnd::Time(0.0));
    }

    #[test]
    fn a_takeoff_yaw_is_read_in_degrees_only_when_finite() {
        let NavCommand::Takeoff { yaw, place } = decode(NAV_TAKEOFF, [0.0, 0.0, 0.0, 90.0]) else {
            panic!("not a take-off");
        };
        assert!((yaw.unwrap() - core::f32::consts::FRAC_PI_2).abs() < 1e-6);
        assert_eq!(place.height(&home()), Some(80.0));
        assert!(matches!(
            decode(NAV_TAKEOFF, [0.0, 0.0, 0.0, f32::NAN]),
            NavCommand::Takeoff { yaw: None, .. }
        ));
    }

    #[test]
    fn jumps_need_a_whole_target_and_a_count_of_minus_one_loops_for_ever() {
        let jump = |t, r| decode(DO_JUMP, [t, r, 0.0, 0.0]);
        assert_eq!(
            jump(3.0, -1.0),
            NavCommand::Jump {
                target: Some(3),
                repeat: JumpRepeat::Forever
            }
        );
        assert_eq!(
            jump(1.5, 2.7),
            NavCommand::Jump {
                target: None,
                repeat: JumpRepeat::Times(2)
            }
        );
        assert_eq!(
            jump(-1.0, f32::NAN),
            NavCommand::Jump {
                target: None,
                repeat: JumpRepeat::Times(0)
            }
        );
    }

    #[test]
    fn speed_changes_of_an_unknown_type_are_unsupported() {
        let speed = |k, v| decode(DO_CHANGE_SPEED, [k, v, 0.0, 0.0]);
        assert_eq!(
            speed(0.0, 18.0),
            NavCommand::ChangeSpeed(SpeedChange::To(18.0))
        );
        assert_eq!(
            speed(1.0, -2.0),
            NavCommand::ChangeSpeed(SpeedChange::Cruise)
        );
        assert_eq!(speed(1.0, -1.0), NavCommand::ChangeSpeed(SpeedChange::Keep));
        assert_eq!(
            speed(2.0, 18.0),
            NavCommand::ChangeSpeed(SpeedChange::Unsupported)
        );
    }

    #[test]
    fn set_home_with_no_point_or_p1_of_one_is_here() {
        assert_eq!(
            decode(DO_SET_HOME, [1.0, 0.0, 0.0, 0.0]),
            NavCommand::SetHome(HomeChange::Here)
        );
        let mut at = item(DO_SET_HOME, [0.0; 4], 0.0, 0.0, 20.0);
        at.x = 0;
        at.y = 0;
        assert_eq!(
            NavItem::decode(&at).command,
            NavCommand::SetHome(HomeChange::Here)
        );
        assert!(matches!(
            decode(DO_SET_HOME, [0.0; 4]),
            NavCommand::SetHome(HomeChange::At {
                alt: Some(Altitude::AboveHome(80.0)),
                ..
            })
        ));
    }

    #[test]
    fn a_route_of_one_item_holds_only_item_zero() {
        let it = NavItem::decode(&item(NAV_LAND, [0.0; 4], 0.0, 0.0, 0.0));
        let r = Route::Item(&it);
        assert_eq!(r.len(), 1);
        assert_eq!(r.get(0), Some(it));
        assert_eq!(r.get(1), None);
        let plan = [item(NAV_LAND, [0.0; 4], 0.0, 0.0, 0.0)];
        assert_eq!(Route::Plan(&plan).get(0), Some(it));
    }
}
