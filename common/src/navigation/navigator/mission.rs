//! The mission walk: which item is flown, the `DO_*` items on the way, and the legs between
//! waypoints.
//!
//! - `DO_*` items run when they become current, in the same step, and the walk goes on to the
//!   next navigation item. An item this navigator does not fly is skipped with a
//!   [`NavWarning`]: the mission never stalls on it.
//! - `DO_JUMP` jumps `param2` times (`-1`: for ever, the only way to loop without end); its
//!   count is kept per item and reset when the mission is started afresh. A walk that meets
//!   more than `4 n + 8` items without reaching a navigation item (a jump loop with nothing to
//!   fly) ends the mission with [`NavWarning::JumpLoop`].
//! - `DO_CHANGE_SPEED` sets the airspeed of the legs and circles that follow, within
//!   `NAV_ASPD_MIN..NAV_ASPD_MAX` (`-2`: back to `NAV_ASPD`); `DO_SET_HOME` asks the firmware
//!   to move the home ([`HomeRequest`]).
//! - Waypoints are joined by the fillet path manager; a waypoint followed by a landing turns
//!   onto the final approach through a fillet too.
//! - Items with an item-relative altitude frame are heights above home; absolute (AMSL) frames
//!   are converted with the home altitude; a non-global frame or a NaN altitude keeps the
//!   present altitude, a latitude/longitude of 0/0 the present position.

use super::guide::{horizontal_dist, Flight, Orbit};
use super::io::{HomeRequest, NavOutput, NavState, NavWarning, Phase};
use super::params::NavParams;
use crate::estimator::Home;
use crate::math::{wrap_pi, MIN_COURSE_SPEED_MPS};
use crate::navigation::item::{HomeChange, JumpRepeat, NavCommand, NavItem, Route, SpeedChange};
use crate::navigation::path_manager::{PathManager, Waypoint};
use crate::navigation::plan::MISSION_CAPACITY;
use nalgebra::Vector3;

/// How closely the course must point at the next item before a finished loiter is left,
/// rad (15 deg).
const EXIT_COURSE_TOL: f32 = 0.26;

/// Where the walk through the mission stands.
#[derive(Clone, Copy, Debug)]
pub(super) struct MissionWalk {
    /// Mission item being flown, when the mission is.
    pub seq: Option<u16>,
    /// Jumps done per `DO_JUMP` item.
    jumps: [u16; MISSION_CAPACITY],
    /// `DO_CHANGE_SPEED` airspeed, m/s.
    airspeed: Option<f32>,
    /// The last waypoint reached (where a landing's approach comes from).
    pub prev_waypoint: Option<Vector3<f32>>,
}

impl MissionWalk {
    /// A walk that has not begun.
    pub fn new() -> Self {
        Self {
            seq: None,
            jumps: [0; MISSION_CAPACITY],
            airspeed: None,
            prev_waypoint: None,
        }
    }

    /// Fresh jump counts, the cruise airspeed, no waypoint behind.
    pub fn restart(&mut self) {
        self.jumps = [0; MISSION_CAPACITY];
        self.airspeed = None;
        self.prev_waypoint = None;
    }

    /// The airspeed of the legs and circles, m/s: `DO_CHANGE_SPEED`'s, or `NAV_ASPD`.
    pub fn cruise(&self, p: &NavParams) -> f32 {
        self.airspeed.unwrap_or(p.airspeed)
    }

    /// Walks from item `seq` to the next navigation item, running `DO_*` items on the way, and
    /// makes it current. `None` when there is none to fly: the mission is empty (then nothing
    /// is current), a jump loop has nothing in it, or the walk fell off the end.
    pub fn walk(
        &mut self,
        items: Route<'_>,
        mut seq: usize,
        home: &Home,
        p: &NavParams,
        out: &mut NavOutput,
    ) -> Option<(usize, NavItem)> {
        if items.is_empty() {
            out.warn(NavWarning::NoMission);
            self.seq = None;
            return None;
        }
        let mut budget = 4 * items.len() + 8;
        loop {
            let item = items.get(seq)?;
            let s16 = u16::try_from(seq).unwrap_or(u16::MAX);
            if budget == 0 {
                out.warn(NavWarning::JumpLoop { seq: s16 });
                return None;
            }
            budget -= 1;
            match item.command {
                NavCommand::Jump { target, repeat } => {
                    match jump_step(target, repeat, items.len(), self.jumps.get(seq).copied()) {
                        JumpStep::Jump(t) => {
                            if let Some(c) = self.jumps.get_mut(seq) {
                                *c = c.saturating_add(1);
                            }
                            seq = t;
                        }
                        JumpStep::Next => seq += 1,
                        JumpStep::Bad => {
                            out.warn(NavWarning::BadJump { seq: s16 });
                            seq += 1;
                        }
                    }
                }
                NavCommand::ChangeSpeed(change) => {
                    match change {
                        SpeedChange::To(v) => {
                            self.airspeed = Some(v.max(p.airspeed_min).min(p.airspeed_max));
                        }
                        SpeedChange::Cruise => self.airspeed = None,
                        SpeedChange::Keep => {}
                        SpeedChange::Unsupported => {
                            out.warn(NavWarning::UnsupportedSpeed { seq: s16 });
                        }
                    }
                    seq += 1;
                }
                NavCommand::SetHome(change) => {
                    out.set_home = Some(match change {
                        HomeChange::Here => HomeRequest::Here,
                        HomeChange::At { point, alt } => HomeRequest::At(Home {
                            point,
                            alt_amsl_m: alt.map_or(home.alt_amsl_m, |a| a.amsl_m(home)),
                        }),
                    });
                    seq += 1;
                }
                NavCommand::Waypoint { .. }
                | NavCommand::Loiter { .. }
                | NavCommand::Takeoff { .. }
                | NavCommand::Land { .. }
                | NavCommand::ReturnToLaunch { .. } => {
                    self.seq = Some(s16);
                    return Some((seq, item));
                }
                NavCommand::Unsupported { command } => {
                    out.warn(NavWarning::UnknownCommand { seq: s16, command });
                    seq += 1;
                }
            }
        }
    }

    /// The next navigation item after `seq` as the walk would find it (jumps followed, counts
    /// not spent).
    fn peek_nav(&self, items: Route<'_>, seq: usize) -> Option<NavItem> {
        let mut jumps = self.jumps;
        let mut s = seq + 1;
        for _ in 0..4 * items.len() + 8 {
            let item = items.get(s)?;
            match item.command {
                NavCommand::Jump { target, repeat } => {
                    match jump_step(target, repeat, items.len(), jumps.get(s).copied()) {
                        JumpStep::Jump(t) => {
                            if let Some(c) = jumps.get_mut(s) {
                                *c = c.saturating_add(1);
                            }
                            s = t;
                        }
                        _ => s += 1,
                    }
                }
                c if c.is_nav() => return Some(item),
                _ => s += 1,
            }
        }
        None
    }

    /// Where the leg after waypoint item `seq` (at `target`) goes, when its corner is
    /// rounded: a waypoint or the final approach of a landing follows.
    pub fn corner_after(
        &self,
        items: Route<'_>,
        seq: usize,
        home: &Home,
        target: &Vector3<f32>,
    ) -> Option<Vector3<f32>> {
        match self.peek_nav(items, seq)?.command {
            NavCommand::Waypoint { place, .. } | NavCommand::Land { place } => {
                Some(place.ned(home, target))
            }
            _ => None,
        }
    }

    /// True when the course over ground points within [`EXIT_COURSE_TOL`] of the next
    /// navigation item that has a position (or when there is none, when it lies within one
    /// and a half radii of the circle's centre, or with no ground speed to tell).
    pub fn heading_for_next(
        &self,
        items: Route<'_>,
        home: &Home,
        state: &NavState,
        orbit: &Orbit,
    ) -> bool {
        let Some(seq) = self.seq else {
            return true;
        };
        let pos = state.pos_ned;
        let Some(next) = self
            .peek_nav(items, usize::from(seq))
            .and_then(|n| n.command.place())
            .filter(|n| n.point.is_some())
        else {
            return true;
        };
        let t = next.ned(home, &pos);
        let vg = state.ground_speed();
        if vg < MIN_COURSE_SPEED_MPS || horizontal_dist(&t, &orbit.center) < 1.5 * orbit.radius {
            return true;
        }
        let bearing = libm::atan2f(t.y - pos.y, t.x - pos.x);
        let course = libm::atan2f(state.vel_ned.y, state.vel_ned.x);
        libm::fabsf(wrap_pi(bearing - course)) <= EXIT_COURSE_TOL
    }
}

/// A leg to a waypoint item.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Leg {
    origin: Vector3<f32>,
    target: Vector3<f32>,
    /// Acceptance radius, m.
    accept: f32,
    /// Airspeed, m/s.
    airspeed: f32,
    /// Where the next leg goes, when the corner at `target` is rounded.
    next: Option<Vector3<f32>>,
    /// The leg starts where the aircraft is (after a take-off or a loiter, no corner leads
    /// onto it) and the aircraft is still turning towards the waypoint: the line is drawn
    /// anew from the present position each step until the course is within
    /// [`JOIN_ALIGNED`] of it. Drawn once from a position the aircraft is flying away from,
    /// the line was overshot by up to two turn radii (36 m after a take-off whose item lay
    /// 75 deg off the runway).
    joining: bool,
}

/// Course error under which a leg that starts from the aircraft's position is fixed, rad.
const JOIN_ALIGNED: f32 = 15.0 * crate::math::DEG;

impl Leg {
    /// The leg of a waypoint item from `origin` to `target` (NED from home), at `airspeed`
    /// (m/s), rounding the corner towards `next`; its acceptance radius is the item's
    /// `accept_radius_m`, or `NAV_ACC_RAD` when it gives none. `joining`: the origin is the
    /// aircraft's position, not a waypoint.
    pub fn item(
        accept_radius_m: Option<f32>,
        origin: Vector3<f32>,
        target: Vector3<f32>,
        next: Option<Vector3<f32>>,
        airspeed: f32,
        p: &NavParams,
        joining: bool,
    ) -> Self {
        let accept = accept_radius_m.unwrap_or(p.accept_radius);
        Self {
            origin,
            target,
            accept,
            airspeed,
            next,
            joining,
        }
    }

    /// The waypoint, NED from home.
    pub fn target(&self) -> Vector3<f32> {
        self.target
    }

    /// One step along the leg (the item `seq`): its commands into `out`. True when the
    /// waypoint is reached; this step's commands then already follow the next leg.
    pub fn step(
        &mut self,
        f: &Flight,
        paths: &mut PathManager,
        seq: Option<u16>,
        out: &mut NavOutput,
    ) -> bool {
        let id = seq.unwrap_or(0);
        let pos = f.state.pos_ned;
        if self.joining {
            let v = f.state.vel_ned;
            let to = self.target - pos;
            let err = wrap_pi(libm::atan2f(to.y, to.x) - libm::atan2f(v.y, v.x));
            if libm::fabsf(err) > JOIN_ALIGNED && f.state.ground_speed() > 1.0 {
                // Over the ground only: the line's height profile still starts at the leg's
                // own height (drawn from the aircraft's, a height lost in the turn was never
                // climbed back).
                self.origin = Vector3::new(pos.x, pos.y, self.origin.z);
            } else {
                self.joining = false;
            }
        }
        let mk = |ned, id| Waypoint {
            id,
            ned,
            airspeed: self.airspeed,
            accept_radius: self.accept,
        };
        let mut window: heapless::Vec<Waypoint, 3> = heapless::Vec::new();
        let _ = window.push(mk(self.origin, u16::MAX));
        let _ = window.push(mk(self.target, id));
        if let Some(n) = self.next {
            let _ = window.push(mk(n, id.wrapping_add(1)));
        }
        let step = paths.step(&f.state.pos_ned, &window, f.state.wind_speed);
        let reached = step.as_ref().and_then(|s| s.reached).is_some();
        let path = step
            .map(|s| s.path)
            .unwrap_or(f.circle(&Orbit::loiter(self.target, f.params), self.airspeed));
        f.emit(&path, Some(self.target), Phase::Waypoint, out);
        // Turning onto the leg is no straight flight.
        out.straight &= !self.joining;
        reached
    }
}

enum JumpStep {
    Jump(usize),
    Next,
    Bad,
}

/// What a `DO_JUMP` to `target`, `repeat` times, does in a mission of `len` items given the
/// jumps it has done (`None`: its counter cannot be kept).
fn jump_step(target: Option<usize>, repeat: JumpRepeat, len: usize, done: Option<u16>) -> JumpStep {
    let Some(target) = target.filter(|&t| t < len) else {
        return JumpStep::Bad;
    };
    let Some(done) = done else {
        return JumpStep::Bad;
    };
    let again = match repeat {
        JumpRepeat::Forever => true,
        JumpRepeat::Times(n) => u32::from(done) < n,
    };
    if again {
        JumpStep::Jump(target)
    } else {
        JumpStep::Next
    }
}
