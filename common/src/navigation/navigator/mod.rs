//! The navigator: the mission executor and the automatic behaviours (return, loiter here).
//!
//! [`Navigator::step`] walks the mission items, keeps the one being flown as the *current* item
//! (for `MISSION_CURRENT`), reports each navigation item when it is done (for
//! `MISSION_ITEM_REACHED`), and turns the item into [`Commands`] for the autopilot through the
//! path manager and the guidance.
//!
//! - `DO_*` items run when they become current, in the same step, and the walk goes on to the
//!   next navigation item. An item this navigator does not fly is skipped with a
//!   [`NavWarning`]: the mission never stalls on it.
//! - `DO_JUMP` jumps `param2` times (`-1`: for ever, the only way to loop without end); its
//!   count is kept per item and reset by [`Navigator::start_mission`]. A walk that meets more
//!   than `4 n + 8` items without reaching a navigation item (a jump loop with nothing to fly)
//!   ends the mission with [`NavWarning::JumpLoop`].
//! - Waypoints are joined by the fillet path manager; a waypoint followed by a landing turns
//!   onto the final approach through a fillet too.
//! - Loiters orbit their point (radius `param3`, `param2` for `LOITER_TO_ALT`, or `NAV_LOIT_RAD`
//!   when 0; a negative radius turns counter-clockwise). `LOITER_TURNS` counts the angle swept
//!   round the centre once on the circle; `LOITER_TIME` the time on the circle;
//!   `LOITER_TO_ALT` waits for the altitude. `LOITER_UNLIM` is reported reached on arrival and
//!   never ends.
//! - Take-off is a runway take-off: full throttle, wings level, pitch 0 until the rotation
//!   airspeed, then the thesis's take-off regime (`LonMode::TakeOff`: fixed pitch, full
//!   throttle to the clear height, then climb) to the item's altitude; the course is held along
//!   the runway once above the clear height.
//! - Landing flies the line from the previous waypoint (or from where the item began) to the
//!   land point, level until it meets the glide slope, then down it (`LonMode::Glide`: the
//!   slope's flight-path angle fed forward, a slow integral of the height error, no diving
//!   back onto the slope). The slope aims short of the point by the flare's own length, so
//!   the wheels, not the slope, meet the ground at the point. Below the flare height the
//!   throttle is closed and the pitch follows a sink rate that shrinks with height (past the
//!   point a faster one, so that a gust's extra speed does not float the aircraft far down
//!   the runway); once the wheels have touched (low and rising again) the pitch goes to 0, as
//!   in a wheel landing, so the ground's kick on the main wheels does not bounce the aircraft
//!   back into the air; a second on the ground (height under `NAV_LND_TD_M`, sinking slower
//!   than 0.5 m/s) is the touchdown: [`NavOutput::landed`] for the firmware to disarm once
//!   stopped.
//! - Items with an item-relative altitude frame are heights above home; absolute (AMSL) frames
//!   are converted with the home altitude; a non-global frame or a NaN altitude keeps the
//!   present altitude, a latitude/longitude of 0/0 the present position.
//! - After the last item (or when a walk falls off the end) the aircraft circles where it is
//!   ([`Phase::Complete`]).
//!
//! Not done here: go-around, abort altitude, hold times at waypoints, ground speed (a
//! `DO_CHANGE_SPEED` of ground speed sets the airspeed), terrain, rally points.

pub mod io;
pub mod params;

use self::io::{HomeRequest, NavOutput, NavState, NavWarning, Phase};
use self::params::NavParams;
use crate::control::autopilot::Commands;
use crate::control::lateral::{RollMode, YawMode, RUDDER};
use crate::control::longitudinal::LonMode;
use crate::estimator::Home;
use crate::guidance::{Guidance, GuidanceOutput, GuidanceParams, OrbitDirection, Path};
use crate::math::{wrap_pi, DEG};
use crate::navigation::items::{self, *};
use crate::navigation::path_manager::{PathManager, PathParams, Waypoint};
use crate::navigation::plan::{MissionItem, MISSION_CAPACITY};
use core::f32::consts::TAU;
use nalgebra::Vector3;

/// Largest height the approach's integral may add to or take off the glide slope, m, and the
/// largest height error it integrates: it is there for the metre the proportional loop
/// leaves on the slope, not for a gust's (winding up on those flew the aircraft under the
/// slope once it was back on it).
const SLOPE_TRIM_MAX_M: f32 = 1.5;

/// Ground speed under which a flaring aircraft counts as rolling on the runway, m/s: the
/// estimated height alone carries the barometer's and GPS's offsets (tenths of a metre).
const ROLLING_SPEED: f32 = 5.0;
/// How closely the course must point at the next item before a finished loiter is left,
/// rad (15 deg).
const EXIT_COURSE_TOL: f32 = 0.26;
/// Largest steering deflection, rad.
const STEER_MAX: f32 = 0.4;
/// Ground speed under which a landed aircraft has stopped and may be disarmed, m/s: until
/// then it is steered, since a taildragger rolling free swings round (a ground loop).
const STOPPED_SPEED: f32 = 1.0;

/// Time on the ground that makes a touchdown, s.
const TOUCHDOWN_S: f32 = 1.0;
/// Sink rate under which the aircraft counts as on the ground, m/s.
const TOUCHDOWN_SINK: f32 = 0.5;
/// Fastest sink a flare that has floated past the land point aims for, m/s: two thirds of the
/// 1.5 m/s a small aircraft's landing gear is held to.
const PAST_SINK_MAX: f32 = 1.0;
/// Climb rate that, below the touchdown height, shows the wheels have touched and kicked the
/// aircraft up, m/s.
const BOUNCE_CLIMB: f32 = 0.3;

#[derive(Clone, Copy, Debug, PartialEq)]
enum LoiterGoal {
    Unlimited,
    Turns {
        goal: f32,
        swept: f32,
        last: Option<f32>,
    },
    Time {
        goal: f32,
        elapsed: f32,
    },
    Altitude,
}

#[derive(Clone, Copy, Debug, PartialEq)]
struct Orbit {
    center: Vector3<f32>,
    radius: f32,
    direction: OrbitDirection,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum LandPhase {
    Approach,
    Flare,
    Landed,
}

#[derive(Clone, Copy, Debug, PartialEq)]
struct Landing {
    origin: Vector3<f32>,
    point: Vector3<f32>,
    phase: LandPhase,
    ground_time: f32,
    /// The approach's integral of the height error, m (added to the altitude command).
    slope_trim: f32,
    /// The wheels have touched (low and rising again): the flare is over and the pitch
    /// is held at 0 (a taildragger's main wheels, ahead of the centre of gravity, pitch it up
    /// as they touch; holding the flare's attitude there lifts it off again).
    touched: bool,
}

impl Landing {
    /// An approach from `origin` to the touchdown `point` (both NED from home).
    fn new(origin: Vector3<f32>, point: Vector3<f32>) -> Self {
        Self {
            origin,
            point,
            phase: LandPhase::Approach,
            ground_time: 0.0,
            slope_trim: 0.0,
            touched: false,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum ReturnPhase {
    Home {
        origin: Vector3<f32>,
    },
    Circle,
    ToFinal {
        origin: Vector3<f32>,
        gate: Vector3<f32>,
    },
    Land(Landing),
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Active {
    Idle,
    Waypoint {
        origin: Vector3<f32>,
        target: Vector3<f32>,
        accept: f32,
        airspeed: f32,
        next: Option<Vector3<f32>>,
    },
    Loiter {
        orbit: Orbit,
        goal: LoiterGoal,
        arrived: bool,
    },
    Takeoff {
        start: Vector3<f32>,
        course: f32,
        height: f32,
        rolling: bool,
    },
    Land(Landing),
    Return {
        phase: ReturnPhase,
        land: bool,
    },
    Hold(Orbit),
    Complete(Orbit),
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Request {
    Mission(u16),
    Return { land: bool },
    LoiterAt(Option<Vector3<f32>>),
}

/// The navigator: mission executor plus return and loiter behaviours.
#[derive(Clone, Debug)]
pub struct Navigator {
    params: NavParams,
    guidance: Guidance,
    paths: PathManager,
    active: Active,
    /// Mission item being flown, when the mission is.
    seq: Option<u16>,
    /// Jumps done per `DO_JUMP` item.
    jumps: [u16; MISSION_CAPACITY],
    /// `DO_CHANGE_SPEED` airspeed, m/s.
    airspeed: Option<f32>,
    /// The last waypoint reached (where a landing's approach comes from).
    prev_waypoint: Option<Vector3<f32>>,
    /// Runway course of the last take-off, rad (a return's landing lands on it).
    runway: Option<f32>,
    home: Option<Home>,
    request: Option<Request>,
}

impl Default for Navigator {
    fn default() -> Self {
        Self::new(
            NavParams::default(),
            Guidance::default(),
            PathManager::default(),
        )
    }
}

fn orbit_path(o: &Orbit, airspeed: f32) -> Path {
    Path::Orbit {
        center: o.center,
        radius: o.radius,
        direction: o.direction,
        airspeed,
    }
}

fn follow(g: &GuidanceOutput) -> Commands {
    Commands {
        roll: RollMode::Course(g.course),
        yaw: RUDDER,
        lon: LonMode::Altitude {
            altitude: g.altitude,
            airspeed: g.airspeed,
        },
    }
}

/// How far past the point where the glide slope meets the flare height the flare carries
/// the aircraft at `ground_speed` (m/s) along the approach, m. The flare's sink rate falls
/// linearly with height from the slope's `s_a` to the touchdown's `s_t` over the flare
/// height `h_f`: height decays as `e^(-t/tau)` towards `-s_t tau` with `tau = h_f /
/// (s_a - s_t)`, reaching the ground after `tau ln(s_a / s_t)`.
fn flare_overrun(p: &NavParams, ground_speed: f32) -> f32 {
    let tan_slope = libm::tanf(p.glide_slope);
    let s_a = ground_speed * tan_slope;
    let s_t = p.flare_sink;
    if !(s_a > s_t && s_t > 0.0 && tan_slope > 0.0 && p.flare_alt > 0.0) {
        return 0.0;
    }
    let tau = p.flare_alt / (s_a - s_t);
    let flare_m = ground_speed * tau * libm::logf(s_a / s_t);
    let overrun = flare_m - p.flare_alt / tan_slope;
    if overrun.is_finite() {
        overrun.max(0.0)
    } else {
        0.0
    }
}

fn horizontal_dist(a: &Vector3<f32>, b: &Vector3<f32>) -> f32 {
    libm::hypotf(a.x - b.x, a.y - b.y)
}

impl Navigator {
    /// An idle navigator.
    pub fn new(params: NavParams, guidance: Guidance, paths: PathManager) -> Self {
        Self {
            params,
            guidance,
            paths,
            active: Active::Idle,
            seq: None,
            jumps: [0; MISSION_CAPACITY],
            airspeed: None,
            prev_waypoint: None,
            runway: None,
            home: None,
            request: None,
        }
    }

    /// The navigator's parameters.
    pub fn params(&self) -> &NavParams {
        &self.params
    }

    /// Takes new settings for the executor, the path manager and the guidance.
    pub fn configure(&mut self, nav: &NavParams, paths: &PathParams, guidance: &GuidanceParams) {
        self.set_params(nav);
        self.paths.configure(paths);
        self.guidance.params = *guidance;
    }

    /// Takes new settings for the executor.
    pub fn set_params(&mut self, nav: &NavParams) {
        self.params = *nav;
    }

    /// Flies the mission from item `seq` on the next step, with fresh jump counts and the
    /// cruise airspeed.
    pub fn start_mission(&mut self, seq: u16) {
        self.jumps = [0; MISSION_CAPACITY];
        self.airspeed = None;
        self.prev_waypoint = None;
        self.request = Some(Request::Mission(seq));
    }

    /// Continues the mission at item `seq` (`MISSION_SET_CURRENT`, or resuming after another
    /// mode), keeping jump counts and airspeed.
    pub fn set_current(&mut self, seq: u16) {
        self.request = Some(Request::Mission(seq));
    }

    /// The return behaviour: fly home at `NAV_RTL_ALT`, circle there, then land if `land`.
    pub fn start_return(&mut self, land: bool) {
        self.request = Some(Request::Return { land });
    }

    /// Circle `center` (NED from home; its altitude is `-z`) at the default loiter radius, or
    /// the present position and height when `None`.
    pub fn start_loiter(&mut self, center: Option<Vector3<f32>>) {
        self.request = Some(Request::LoiterAt(center));
    }

    /// Stops: the next steps give no commands.
    pub fn stop(&mut self) {
        self.request = None;
        self.active = Active::Idle;
        self.seq = None;
        self.paths.reset();
    }

    /// The mission item being flown.
    pub fn current_seq(&self) -> Option<u16> {
        self.seq
    }

    fn cruise(&self) -> f32 {
        self.airspeed.unwrap_or(self.params.airspeed)
    }

    fn default_orbit(&self, center: Vector3<f32>) -> Orbit {
        Orbit {
            center,
            radius: self.params.loiter_radius,
            direction: OrbitDirection::Clockwise,
        }
    }

    /// One step: `items` is the stored mission, `home` the NED origin, `state` the estimate,
    /// `dt` the time since the last step (s).
    pub fn step(
        &mut self,
        items: &[MissionItem],
        home: &Home,
        state: &NavState,
        dt: f32,
    ) -> NavOutput {
        let mut out = NavOutput {
            wp_dist_m: f32::NAN,
            target_bearing: f32::NAN,
            ..NavOutput::default()
        };
        let dt = if dt.is_finite() && dt > 0.0 { dt } else { 0.0 };
        // A new home point moves every NED target: fly the present item again from here. Its
        // altitude alone moves as the estimator learns the barometer's offset (heights above
        // home follow the barometer); that moves no point a mission flies to.
        if self.home.is_some_and(|h| h.point != home.point) && self.request.is_none() {
            match self.active {
                Active::Waypoint { .. }
                | Active::Loiter { .. }
                | Active::Land(_)
                | Active::Takeoff { .. } => {
                    if let Some(s) = self.seq {
                        self.prev_waypoint = None;
                        self.request = Some(Request::Mission(s));
                    }
                }
                _ => {}
            }
        }
        self.home = Some(*home);
        let pos = state.pos_ned;
        match self.request.take() {
            Some(Request::Mission(s)) => self.walk(items, usize::from(s), home, state, &mut out),
            Some(Request::Return { land }) => {
                self.seq = None;
                self.begin_return(land, &pos);
            }
            Some(Request::LoiterAt(c)) => {
                self.seq = None;
                let c = c.unwrap_or(pos);
                self.active = Active::Hold(self.default_orbit(c));
            }
            None => {}
        }
        self.fly(items, home, state, dt, &mut out);
        out.current_seq = self.seq;
        if let Some(t) = out.target {
            out.wp_dist_m = horizontal_dist(&t, &pos);
            out.target_bearing = libm::atan2f(t.y - pos.y, t.x - pos.x);
        }
        out
    }

    fn begin_return(&mut self, land: bool, pos: &Vector3<f32>) {
        self.paths.reset();
        self.active = Active::Return {
            phase: ReturnPhase::Home { origin: *pos },
            land,
        };
    }

    fn complete(&mut self, pos: &Vector3<f32>) {
        self.paths.reset();
        let center = self.prev_waypoint.unwrap_or(*pos);
        self.active = Active::Complete(self.default_orbit(center));
    }

    /// Walks from item `seq` to the next navigation item, running `DO_*` items on the way, and
    /// starts it.
    fn walk(
        &mut self,
        items: &[MissionItem],
        mut seq: usize,
        home: &Home,
        state: &NavState,
        out: &mut NavOutput,
    ) {
        self.paths.reset();
        if items.is_empty() {
            out.warn(NavWarning::NoMission);
            self.seq = None;
            self.complete(&state.pos_ned);
            return;
        }
        let mut budget = 4 * items.len() + 8;
        loop {
            let Some(item) = items.get(seq) else {
                self.complete(&state.pos_ned);
                return;
            };
            let s16 = u16::try_from(seq).unwrap_or(u16::MAX);
            if budget == 0 {
                out.warn(NavWarning::JumpLoop { seq: s16 });
                self.complete(&state.pos_ned);
                return;
            }
            budget -= 1;
            match item.command {
                DO_JUMP => match jump_target(item, items.len(), self.jumps.get(seq).copied()) {
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
                },
                DO_CHANGE_SPEED => {
                    let kind = item.param(0);
                    let v = item.param(1);
                    if kind == 0.0 || kind == 1.0 {
                        if v > 0.0 {
                            self.airspeed = Some(
                                v.max(self.params.airspeed_min)
                                    .min(self.params.airspeed_max),
                            );
                        } else if v == -2.0 {
                            self.airspeed = None;
                        }
                    } else {
                        out.warn(NavWarning::UnsupportedSpeed { seq: s16 });
                    }
                    seq += 1;
                }
                DO_SET_HOME => {
                    out.set_home = Some(if item.param(0) == 1.0 {
                        HomeRequest::Here
                    } else {
                        match (items::point(item), items::alt_amsl(item, home)) {
                            (Some(point), Some(alt_amsl_m)) => {
                                HomeRequest::At(Home { point, alt_amsl_m })
                            }
                            (Some(point), None) => HomeRequest::At(Home {
                                point,
                                alt_amsl_m: home.alt_amsl_m,
                            }),
                            _ => HomeRequest::Here,
                        }
                    });
                    seq += 1;
                }
                c if is_nav(c) => {
                    self.seq = Some(s16);
                    self.activate(items, seq, item, home, state);
                    return;
                }
                command => {
                    out.warn(NavWarning::UnknownCommand { seq: s16, command });
                    seq += 1;
                }
            }
        }
    }

    /// The next navigation item after `seq` as the walk would find it (jumps followed, counts
    /// not spent).
    /// True when the course over ground points within [`EXIT_COURSE_TOL`] of the next
    /// navigation item that has a position (or when there is none, when it lies within one
    /// and a half radii of the circle's centre, or with no ground speed to tell).
    fn heading_for_next(
        &self,
        items: &[MissionItem],
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
            .filter(|n| items::point(n).is_some())
        else {
            return true;
        };
        let t = items::target_ned(next, home, &pos);
        let vg = state.ground_speed();
        if vg < 3.0 || horizontal_dist(&t, &orbit.center) < 1.5 * orbit.radius {
            return true;
        }
        let bearing = libm::atan2f(t.y - pos.y, t.x - pos.x);
        let course = libm::atan2f(state.vel_ned.y, state.vel_ned.x);
        libm::fabsf(wrap_pi(bearing - course)) <= EXIT_COURSE_TOL
    }

    fn peek_nav<'a>(&self, items: &'a [MissionItem], seq: usize) -> Option<&'a MissionItem> {
        let mut jumps = self.jumps;
        let mut s = seq + 1;
        for _ in 0..4 * items.len() + 8 {
            let item = items.get(s)?;
            match item.command {
                DO_JUMP => match jump_target(item, items.len(), jumps.get(s).copied()) {
                    JumpStep::Jump(t) => {
                        if let Some(c) = jumps.get_mut(s) {
                            *c = c.saturating_add(1);
                        }
                        s = t;
                    }
                    _ => s += 1,
                },
                c if is_nav(c) => return Some(item),
                _ => s += 1,
            }
        }
        None
    }

    fn activate(
        &mut self,
        items: &[MissionItem],
        seq: usize,
        item: &MissionItem,
        home: &Home,
        state: &NavState,
    ) {
        let pos = state.pos_ned;
        let target = items::target_ned(item, home, &pos);
        let origin = self.prev_waypoint.unwrap_or(pos);
        self.active = match item.command {
            NAV_WAYPOINT => {
                let accept = if item.param(1) > 0.0 {
                    item.param(1)
                } else {
                    self.params.accept_radius
                };
                // The corner after this waypoint is rounded when a waypoint or the final
                // approach of a landing follows.
                let next = self
                    .peek_nav(items, seq)
                    .filter(|n| matches!(n.command, NAV_WAYPOINT | NAV_LAND))
                    .map(|n| items::target_ned(n, home, &target));
                Active::Waypoint {
                    origin,
                    target,
                    accept,
                    airspeed: self.cruise(),
                    next,
                }
            }
            NAV_LOITER_UNLIM | NAV_LOITER_TURNS | NAV_LOITER_TIME | NAV_LOITER_TO_ALT => {
                let r = if item.command == NAV_LOITER_TO_ALT {
                    item.param(1)
                } else {
                    item.param(2)
                };
                let radius = if r.is_finite() && r.abs() >= 1.0 {
                    r.abs()
                } else {
                    self.params.loiter_radius
                };
                let goal = match item.command {
                    NAV_LOITER_TURNS => LoiterGoal::Turns {
                        goal: item.param(0).max(0.0) * TAU,
                        swept: 0.0,
                        last: None,
                    },
                    NAV_LOITER_TIME => LoiterGoal::Time {
                        goal: item.param(0).max(0.0),
                        elapsed: 0.0,
                    },
                    NAV_LOITER_TO_ALT => LoiterGoal::Altitude,
                    _ => LoiterGoal::Unlimited,
                };
                Active::Loiter {
                    orbit: Orbit {
                        center: target,
                        radius,
                        direction: OrbitDirection::from_signed_radius(r),
                    },
                    goal,
                    arrived: false,
                }
            }
            NAV_TAKEOFF => {
                let course = match items::point(item) {
                    Some(_) if horizontal_dist(&target, &pos) > 20.0 => {
                        libm::atan2f(target.y - pos.y, target.x - pos.x)
                    }
                    _ if item.param(3).is_finite() => wrap_pi(item.param(3) * DEG),
                    _ => state.heading,
                };
                self.runway = Some(course);
                Active::Takeoff {
                    start: pos,
                    course,
                    height: items::height(item, home).unwrap_or(self.params.rtl_alt),
                    rolling: state.airspeed.is_nan() || state.airspeed < self.params.takeoff_vr,
                }
            }
            NAV_LAND => {
                let origin = if horizontal_dist(&origin, &target) > 10.0 {
                    origin
                } else {
                    pos
                };
                Active::Land(Landing::new(origin, target))
            }
            // NAV_RETURN_TO_LAUNCH (the only navigation command left).
            _ => Active::Return {
                phase: ReturnPhase::Home { origin: pos },
                land: self.params.rtl_land,
            },
        };
        if !matches!(self.active, Active::Waypoint { .. }) {
            self.prev_waypoint = None;
        }
    }

    /// The current item is done: report it and walk on (or hold, without autocontinue).
    fn item_done(
        &mut self,
        items: &[MissionItem],
        home: &Home,
        state: &NavState,
        hold: Orbit,
        out: &mut NavOutput,
    ) {
        let Some(seq) = self.seq else {
            return;
        };
        out.reached = Some(seq);
        let autocontinue = items.get(usize::from(seq)).is_some_and(|i| i.autocontinue);
        if autocontinue {
            self.walk(items, usize::from(seq) + 1, home, state, out);
        } else {
            self.paths.reset();
            self.active = Active::Hold(hold);
        }
    }

    fn fly(
        &mut self,
        items: &[MissionItem],
        home: &Home,
        state: &NavState,
        dt: f32,
        out: &mut NavOutput,
    ) {
        let pos = state.pos_ned;
        let vg = state.ground_speed();
        let p = self.params;
        match self.active {
            Active::Idle => {
                out.phase = Phase::Idle;
            }
            Active::Waypoint {
                origin,
                target,
                accept,
                airspeed,
                next,
            } => {
                let id = self.seq.unwrap_or(0);
                let mk = |ned, id| Waypoint {
                    id,
                    ned,
                    airspeed,
                    accept_radius: accept,
                };
                let mut window: heapless::Vec<Waypoint, 3> = heapless::Vec::new();
                let _ = window.push(mk(origin, u16::MAX));
                let _ = window.push(mk(target, id));
                if let Some(n) = next {
                    let _ = window.push(mk(n, id.wrapping_add(1)));
                }
                let step = self.paths.step(&pos, &window);
                let reached = step.as_ref().and_then(|s| s.reached).is_some();
                let path = step
                    .map(|s| s.path)
                    .unwrap_or(orbit_path(&self.default_orbit(target), airspeed));
                self.emit(&path, state, Some(target), Phase::Waypoint, out);
                if reached {
                    // The new item flies from the next step; this step's commands already
                    // follow the next leg.
                    self.prev_waypoint = Some(target);
                    let hold = self.default_orbit(target);
                    self.item_done(items, home, state, hold, out);
                }
            }
            Active::Loiter {
                orbit,
                mut goal,
                mut arrived,
            } => {
                let path = orbit_path(&orbit, self.cruise());
                let g = self.emit(&path, state, Some(orbit.center), Phase::Loiter, out);
                let on_circle = g.cross_track.abs() <= p.accept_radius.max(0.1 * orbit.radius);
                let mut done = false;
                if on_circle || arrived {
                    let first = !arrived;
                    arrived = true;
                    let phi = libm::atan2f(pos.y - orbit.center.y, pos.x - orbit.center.x);
                    match &mut goal {
                        LoiterGoal::Unlimited => {
                            if first {
                                out.reached = self.seq;
                            }
                        }
                        LoiterGoal::Turns { goal, swept, last } => {
                            if let Some(l) = *last {
                                *swept += orbit.direction.lambda() * wrap_pi(phi - l);
                            }
                            *last = Some(phi);
                            done = *swept >= *goal;
                        }
                        LoiterGoal::Time { goal, elapsed } => {
                            *elapsed += dt;
                            done = *elapsed >= *goal;
                        }
                        LoiterGoal::Altitude => {
                            done = (state.height() + orbit.center.z).abs() <= p.alt_accept;
                        }
                    }
                }
                self.active = Active::Loiter {
                    orbit,
                    goal,
                    arrived,
                };
                // Leave the circle where it heads for the next point (PX4's and ArduPilot's
                // exit): leaving anywhere else turns the aircraft round on the next leg, up
                // to two turn radii off it.
                if done && !self.heading_for_next(items, home, state, &orbit) {
                    done = false;
                }
                if done {
                    self.item_done(items, home, state, orbit, out);
                }
            }
            Active::Takeoff {
                start,
                course,
                height,
                mut rolling,
            } => {
                if rolling && state.airspeed >= p.takeoff_vr {
                    rolling = false;
                }
                let (dn, de) = (libm::cosf(course), libm::sinf(course));
                let far = start + Vector3::new(dn, de, 0.0) * 1000.0;
                let line = Path::line_between(&start, &far, self.cruise());
                out.target = Some(far);
                if rolling {
                    out.phase = Phase::TakeoffRoll;
                    // Along the runway line: the course to hold comes from the line's vector
                    // field, so a drift sideways is steered back, not just stopped.
                    let course = line
                        .map(|l| self.guidance.step(&l, &pos, vg).course)
                        .unwrap_or(course);
                    out.commands = Some(Commands {
                        roll: RollMode::Roll(0.0),
                        yaw: self.steer(course, state),
                        lon: LonMode::Pitch {
                            pitch: 0.0,
                            throttle: 1.0,
                        },
                    });
                } else {
                    out.phase = Phase::TakeoffClimb;
                    let g = line.map(|l| self.guidance.step(&l, &pos, vg));
                    out.guidance = g;
                    // Along the runway line from lift-off: near the line the vector field asks
                    // for a few degrees of course, so little bank close to the ground.
                    let roll = match g {
                        Some(g) => RollMode::Course(g.course),
                        None => RollMode::Roll(0.0),
                    };
                    out.commands = Some(Commands {
                        roll,
                        yaw: RUDDER,
                        lon: LonMode::TakeOff {
                            altitude: height,
                            airspeed: self.cruise(),
                            clear_altitude: -start.z + p.takeoff_clear,
                        },
                    });
                }
                self.active = Active::Takeoff {
                    start,
                    course,
                    height,
                    rolling,
                };
                if !rolling && state.height() >= height - p.alt_accept {
                    let hold = self.default_orbit(Vector3::new(pos.x, pos.y, -height));
                    self.item_done(items, home, state, hold, out);
                }
            }
            Active::Land(mut l) => {
                let before = l.phase;
                self.fly_landing(&mut l, state, dt, out);
                self.active = Active::Land(l);
                if before != LandPhase::Landed && l.phase == LandPhase::Landed {
                    out.reached = self.seq;
                }
            }
            Active::Return { phase, land } => self.fly_return(phase, land, state, dt, out),
            Active::Hold(o) | Active::Complete(o) => {
                let path = orbit_path(&o, self.cruise());
                let phase = if matches!(self.active, Active::Hold(_)) {
                    Phase::Hold
                } else {
                    Phase::Complete
                };
                self.emit(&path, state, Some(o.center), phase, out);
            }
        }
    }

    fn emit(
        &self,
        path: &Path,
        state: &NavState,
        target: Option<Vector3<f32>>,
        phase: Phase,
        out: &mut NavOutput,
    ) -> GuidanceOutput {
        let g = self
            .guidance
            .step(path, &state.pos_ned, state.ground_speed());
        out.guidance = Some(g);
        out.commands = Some(follow(&g));
        out.target = target;
        out.phase = phase;
        out.straight = matches!(path, Path::Line { .. });
        g
    }

    /// Tail-wheel steering towards `course` (rad): on the runway the heading is the course.
    fn steer(&self, course: f32, state: &NavState) -> YawMode {
        let err = wrap_pi(course - state.heading);
        // Positive rudder (trailing edge left) turns the nose left.
        let d = -self.params.steer_k * err;
        YawMode::Rudder(if d.is_finite() {
            d.clamp(-STEER_MAX, STEER_MAX)
        } else {
            0.0
        })
    }

    fn fly_landing(&self, l: &mut Landing, state: &NavState, dt: f32, out: &mut NavOutput) {
        let p = self.params;
        let pos = state.pos_ned;
        let hagl = state.height() + l.point.z;
        let line = Path::line_between(&l.origin, &l.point, p.land_airspeed).unwrap_or(Path::Line {
            origin: l.point,
            direction: Vector3::x(),
            airspeed: p.land_airspeed,
        });
        let mut g = self.guidance.step(&line, &pos, state.ground_speed());
        // Level at the approach's start height until the glide slope, then down it, the
        // command moving at the slope's rate over the ground so the autopilot can fly the
        // flight-path angle that rate asks for.
        let (signed_to_go, along_speed) = match line {
            Path::Line { direction, .. } => {
                let d = Vector3::new(direction.x, direction.y, 0.0);
                let n = d.norm();
                if n > 0.0 {
                    ((l.point - pos).dot(&d) / n, state.vel_ned.dot(&d) / n)
                } else {
                    (0.0, 0.0)
                }
            }
            Path::Orbit { .. } => (0.0, 0.0),
        };
        let to_go = signed_to_go.max(0.0);
        let start_h = -l.origin.z;
        let tan_slope = libm::tanf(p.glide_slope);
        // The slope aims short of the point by as far as the flare carries past where the
        // slope meets the flare height, so that the wheels touch at the point.
        let along = if along_speed.is_finite() {
            along_speed.max(0.0)
        } else {
            0.0
        };
        let ahead = (to_go - flare_overrun(&p, along)).max(0.0);
        let on_slope = -l.point.z + tan_slope * ahead;
        let top = start_h.max(-l.point.z);
        g.altitude = on_slope.min(top);
        let climb_rate = if ahead > 0.0 && on_slope < top {
            -tan_slope * along
        } else {
            0.0
        };
        out.guidance = Some(g);
        out.target = Some(l.point);
        if l.phase == LandPhase::Approach && hagl < p.flare_alt {
            l.phase = LandPhase::Flare;
        }
        if l.phase == LandPhase::Flare {
            let sink = state.vel_ned.z;
            let on_ground = hagl < p.touchdown_alt || state.ground_speed() < ROLLING_SPEED;
            // Rising again this close to the ground is the wheels' kick (or a gust about to
            // balloon the aircraft): from then on the flare's pitch-up is over.
            if hagl < p.touchdown_alt && sink < -BOUNCE_CLIMB {
                l.touched = true;
            }
            if on_ground && sink < TOUCHDOWN_SINK {
                l.ground_time += dt;
            } else {
                l.ground_time = 0.0;
            }
            if l.ground_time >= TOUCHDOWN_S {
                l.phase = LandPhase::Landed;
            }
        }
        match l.phase {
            LandPhase::Approach => {
                out.phase = Phase::Approach;
                // The altitude loop is proportional: on the slope it settles below it by what
                // its gain needs to make the pitch the slower approach flies at (a metre on
                // the Ultra Stick). A slow integral of the height error takes that out.
                let err = g.altitude - state.height();
                if climb_rate != 0.0 && libm::fabsf(err) < SLOPE_TRIM_MAX_M {
                    l.slope_trim = (l.slope_trim + p.approach_i * err * dt)
                        .clamp(-SLOPE_TRIM_MAX_M, SLOPE_TRIM_MAX_M);
                }
                // Caught high by a gust near the ground, the aircraft is not dived back onto
                // the slope (that arrives at the flare sinking fast): the command stays within
                // `NAV_APP_DIVE_M` below the present height, and the landing is long instead.
                let cmd = (g.altitude + l.slope_trim).max(state.height() - p.approach_dive);
                out.commands = Some(Commands {
                    lon: LonMode::Glide {
                        altitude: cmd,
                        airspeed: g.airspeed,
                        climb_rate,
                    },
                    ..follow(&g)
                });
            }
            LandPhase::Flare => {
                out.phase = Phase::Flare;
                // The sink rate aimed for shrinks from the glide's to the touchdown's with
                // height; pitch up as the aircraft sinks faster than that.
                let approach_sink = along * tan_slope;
                let frac = (hagl / p.flare_alt).clamp(0.0, 1.0);
                let aim = p.flare_sink + (approach_sink - p.flare_sink).max(0.0) * frac;
                // Floating past the point (a gust's extra speed at the flare), the flare gives
                // up on the gentlest touchdown for a nearer one: a faster sink aimed for the
                // farther past, up to `PAST_SINK_MAX`, and the nose may come down to level.
                let past = -signed_to_go;
                let (aim, floor) = if past > 0.0 && p.flare_past_k > 0.0 {
                    (
                        (aim + p.flare_past_k * past).min(PAST_SINK_MAX.max(aim)),
                        0.0,
                    )
                } else {
                    (aim, p.flare_pitch)
                };
                let sink = state.vel_ned.z;
                let pitch = if l.touched {
                    0.0
                } else if sink.is_finite() {
                    (p.flare_pitch + p.flare_k * (sink - aim)).clamp(floor, 15.0 * DEG)
                } else {
                    p.flare_pitch
                };
                // The rudder steers the tail wheel once the wheels are about to touch; in the
                // air it stays the yaw damper, so the aircraft keeps its crab in a crosswind
                // (lining the nose up with the runway there would let it drift downwind).
                let yaw = if hagl < p.touchdown_alt {
                    self.steer(g.course, state)
                } else {
                    RUDDER
                };
                out.commands = Some(Commands {
                    roll: RollMode::Course(g.course),
                    yaw,
                    lon: LonMode::Pitch {
                        pitch,
                        throttle: p.flare_throttle * frac,
                    },
                });
            }
            LandPhase::Landed => {
                out.phase = Phase::Landed;
                out.landed = state.ground_speed() < STOPPED_SPEED;
                out.commands = Some(Commands {
                    roll: RollMode::Roll(0.0),
                    yaw: self.steer(g.path_course, state),
                    lon: LonMode::Pitch {
                        pitch: 0.0,
                        throttle: 0.0,
                    },
                });
            }
        }
    }

    fn fly_return(
        &mut self,
        phase: ReturnPhase,
        land: bool,
        state: &NavState,
        dt: f32,
        out: &mut NavOutput,
    ) {
        let p = self.params;
        let pos = state.pos_ned;
        let home_ned = Vector3::new(0.0, 0.0, -p.rtl_alt);
        let circle = self.default_orbit(home_ned);
        let next = match phase {
            ReturnPhase::Home { origin } => {
                let path = Path::line_between(&origin, &home_ned, self.cruise())
                    .unwrap_or(orbit_path(&circle, self.cruise()));
                self.emit(&path, state, Some(home_ned), Phase::Return, out);
                if horizontal_dist(&pos, &home_ned) <= p.loiter_radius {
                    // A mission's return item counts as reached at home.
                    out.reached = self.seq;
                    ReturnPhase::Circle
                } else {
                    phase
                }
            }
            ReturnPhase::Circle => {
                let g = self.emit(
                    &orbit_path(&circle, self.cruise()),
                    state,
                    Some(home_ned),
                    Phase::ReturnLoiter,
                    out,
                );
                let settled = g.cross_track.abs() <= p.accept_radius
                    && (state.height() - p.rtl_alt).abs() <= p.alt_accept;
                if land && settled {
                    // Final approach along the runway of the last take-off (or from where
                    // the aircraft is), starting where the glide slope meets the return
                    // altitude.
                    let course = self.runway.unwrap_or_else(|| libm::atan2f(-pos.y, -pos.x));
                    let run = p.rtl_alt / libm::tanf(p.glide_slope);
                    let gate = Vector3::new(
                        -libm::cosf(course) * run,
                        -libm::sinf(course) * run,
                        -p.rtl_alt,
                    );
                    self.paths.reset();
                    ReturnPhase::ToFinal { origin: pos, gate }
                } else {
                    phase
                }
            }
            ReturnPhase::ToFinal { origin, gate } => {
                let airspeed = self.cruise();
                let mk = |id, ned| Waypoint {
                    id,
                    ned,
                    airspeed,
                    accept_radius: p.accept_radius,
                };
                let window = [mk(0, origin), mk(1, gate), mk(2, Vector3::zeros())];
                let step = self.paths.step(&pos, &window);
                let reached = step.as_ref().and_then(|s| s.reached).is_some();
                let path = step
                    .map(|s| s.path)
                    .unwrap_or(orbit_path(&circle, airspeed));
                self.emit(&path, state, Some(gate), Phase::Return, out);
                if reached {
                    ReturnPhase::Land(Landing::new(gate, Vector3::zeros()))
                } else {
                    phase
                }
            }
            ReturnPhase::Land(mut l) => {
                self.fly_landing(&mut l, state, dt, out);
                ReturnPhase::Land(l)
            }
        };
        self.active = Active::Return { phase: next, land };
    }
}

enum JumpStep {
    Jump(usize),
    Next,
    Bad,
}

/// What a `DO_JUMP` does given the jumps it has done (`None`: its counter cannot be kept).
fn jump_target(item: &MissionItem, len: usize, done: Option<u16>) -> JumpStep {
    let target = item.param(0);
    let repeat = item.param(1);
    if !(target.is_finite()
        && target >= 0.0
        && target < len as f32
        && libm::truncf(target) == target)
    {
        return JumpStep::Bad;
    }
    let Some(done) = done else {
        return JumpStep::Bad;
    };
    // -1: for ever; otherwise a whole number of repeats.
    let again = if repeat == -1.0 {
        true
    } else {
        repeat.is_finite() && repeat >= 0.0 && f32::from(done) < libm::truncf(repeat)
    };
    if again {
        JumpStep::Jump(target as usize)
    } else {
        JumpStep::Next
    }
}
