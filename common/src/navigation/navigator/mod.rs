//! The navigator: the mission and the automatic behaviours (take-off, loiter, landing, return,
//! loiter here), each flown by its own part.
//!
//! [`Navigator::step`] walks the mission items, keeps the one being flown as the *current* item
//! (for `MISSION_CURRENT`), reports each navigation item when it is done (for
//! `MISSION_ITEM_REACHED`), and turns the item into [`Commands`] for the autopilot through the
//! path manager and the guidance.
//!
//! Altitudes: inside, the navigator works in its NED frame from home, so its targets, circles
//! and glide slopes, and the guidance output it reports, are heights above home. The
//! [`Commands`] it hands the autopilot carry altitudes above mean sea level, the datum of the
//! measured altitude the autopilot holds them against: the home's altitude is added on the way
//! out, so the caller passes them through.
//!
//! - [`mission`]: the walk through the items (`DO_*` items, jumps, speed changes, home moves)
//!   and the legs between waypoints.
//! - [`takeoff`]: the runway roll, rotation and climb-out.
//! - [`loiter`]: loiter items, circling until their goal is met.
//! - [`land`]: approach on the glide slope, flare, touchdown and roll-out.
//! - [`rtl`]: the return home, its circle there and its landing.
//! - [`params`]: the navigator's parameters; [`io`]: what it takes in and hands out.
//!
//! After the last item (or when a walk falls off the end) the aircraft circles where it is
//! ([`Phase::Complete`]).
//!
//! Not done here: hold times at waypoints, ground speed (a
//! `DO_CHANGE_SPEED` of ground speed sets the airspeed), terrain, rally points.

mod guide;
mod gust;
pub mod io;
pub mod land;
pub mod loiter;
pub mod mission;
pub mod params;
pub mod rtl;
pub mod takeoff;

use self::guide::{horizontal_dist, Flight, Orbit};
use self::gust::GustMeter;
use self::io::{GroundStage, NavOutput, NavState, Phase};
use self::land::Landing;
use self::loiter::Loiter;
use self::mission::{Leg, MissionWalk};
use self::params::NavParams;
use self::rtl::Return;
use self::takeoff::Takeoff;
use crate::control::autopilot::Commands;
use crate::estimator::Home;
use crate::guidance::{Guidance, GuidanceParams};
use crate::navigation::item::{NavCommand, NavItem, Route};
use crate::navigation::path_manager::{PathManager, PathParams};
use crate::navigation::plan::MissionItem;
use nalgebra::Vector3;

/// The behaviour being flown.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Active {
    Idle,
    Waypoint(Leg),
    Loiter(Loiter),
    Takeoff(Takeoff),
    Land(Landing),
    Return(Return),
    Hold(Orbit),
    Complete(Orbit),
}

/// What the next step starts.
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
    mission: MissionWalk,
    /// Runway course of the last take-off, rad (a return's landing lands on it).
    runway: Option<f32>,
    home: Option<Home>,
    request: Option<Request>,
    /// The airspeed's gust level, measured on every step.
    gust: GustMeter,
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

impl Navigator {
    /// An idle navigator.
    pub fn new(params: NavParams, guidance: Guidance, paths: PathManager) -> Self {
        Self {
            params,
            guidance,
            paths,
            active: Active::Idle,
            mission: MissionWalk::new(),
            runway: None,
            home: None,
            request: None,
            gust: GustMeter::default(),
        }
    }

    /// The navigator's parameters.
    pub fn params(&self) -> &NavParams {
        &self.params
    }

    /// Takes new settings for the navigator, the path manager and the guidance.
    pub fn configure(&mut self, nav: &NavParams, paths: &PathParams, guidance: &GuidanceParams) {
        self.set_params(nav);
        self.paths.configure(paths);
        self.guidance.params = *guidance;
    }

    /// Takes new settings for the navigator.
    pub fn set_params(&mut self, nav: &NavParams) {
        self.params = *nav;
    }

    /// Flies the mission from item `seq` on the next step, with fresh jump counts and the
    /// cruise airspeed.
    pub fn start_mission(&mut self, seq: u16) {
        self.mission.restart();
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

    /// Gives up the landing being flown (a mission's or a return's) for a go-around and a new
    /// approach; returns whether there was an approach or flare to give up.
    pub fn go_around(&mut self) -> bool {
        match &mut self.active {
            Active::Land(l) => l.go_around(),
            Active::Return(r) => r.go_around(),
            _ => false,
        }
    }

    /// Where the behaviour being flown stands near the ground, for what a failsafe may do:
    /// on a take-off's roll, in its climb below `NAV_TKO_CLR_M`, in a landing's flare or
    /// roll-out (a mission's or a return's) or an aborted take-off's, or clear of all that.
    pub fn ground_stage(&self) -> GroundStage {
        match &self.active {
            Active::Takeoff(t) => t.ground_stage(self.params.takeoff_clear),
            Active::Land(l) if l.touching_down() => GroundStage::Touchdown,
            Active::Return(r) if r.touching_down() => GroundStage::Touchdown,
            _ => GroundStage::Clear,
        }
    }

    /// Gives up a take-off still on its roll (below the rotation airspeed) for a roll-out to
    /// a stop on the runway ([`Phase::TakeoffAbort`]); returns whether there was one to give
    /// up.
    pub fn abort_takeoff(&mut self) -> bool {
        match &mut self.active {
            Active::Takeoff(t) => t.abort(),
            _ => false,
        }
    }

    /// Stops: the next steps give no commands.
    pub fn stop(&mut self) {
        self.request = None;
        self.active = Active::Idle;
        self.mission.seq = None;
        self.paths.reset();
    }

    /// The mission item being flown.
    pub fn current_seq(&self) -> Option<u16> {
        self.mission.seq
    }

    /// One step: `items` is the stored mission, `home` the NED origin, `state` the estimate,
    /// `dt` the time since the last step (s). The commands' altitudes are above mean sea
    /// level.
    pub fn step(
        &mut self,
        items: &[MissionItem],
        home: &Home,
        state: &NavState,
        dt: f32,
    ) -> NavOutput {
        self.step_route(Route::Plan(items), home, state, dt)
    }

    /// One step along `items`, the stored mission or an item built on board; otherwise as
    /// [`Navigator::step`].
    pub fn step_route(
        &mut self,
        items: Route<'_>,
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
                Active::Waypoint(_) | Active::Loiter(_) | Active::Land(_) | Active::Takeoff(_) => {
                    if let Some(s) = self.mission.seq {
                        self.mission.prev_waypoint = None;
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
                self.mission.seq = None;
                self.paths.reset();
                self.active = Active::Return(Return::new(pos, land));
            }
            Some(Request::LoiterAt(c)) => {
                self.mission.seq = None;
                let c = c.unwrap_or(pos);
                self.active = Active::Hold(Orbit::loiter(c, &self.params));
            }
            None => {}
        }
        self.gust.update(state.airspeed, dt);
        self.fly(items, home, state, dt, &mut out);
        out.current_seq = self.mission.seq;
        if let Some(t) = out.target {
            out.wp_dist_m = horizontal_dist(&t, &pos);
            out.target_bearing = libm::atan2f(t.y - pos.y, t.x - pos.x);
        }
        // Heights above home to the autopilot's altitudes above mean sea level.
        out.commands = out.commands.map(|c| Commands {
            lon: c.lon.shifted(home.alt_amsl_m),
            ..c
        });
        out
    }

    /// The mission is over: circle the last waypoint reached, or where the aircraft is.
    fn complete(&mut self, pos: &Vector3<f32>) {
        self.paths.reset();
        let center = self.mission.prev_waypoint.unwrap_or(*pos);
        self.active = Active::Complete(Orbit::loiter(center, &self.params));
    }

    /// Walks from item `seq` to the next navigation item and starts it, or completes the
    /// mission when there is none.
    fn walk(
        &mut self,
        items: Route<'_>,
        seq: usize,
        home: &Home,
        state: &NavState,
        out: &mut NavOutput,
    ) {
        self.paths.reset();
        match self.mission.walk(items, seq, home, &self.params, out) {
            Some((seq, item)) => self.activate(items, seq, &item, home, state),
            None => self.complete(&state.pos_ned),
        }
    }

    /// Starts the behaviour that flies navigation item `seq`.
    fn activate(
        &mut self,
        items: Route<'_>,
        seq: usize,
        item: &NavItem,
        home: &Home,
        state: &NavState,
    ) {
        let p = &self.params;
        let pos = state.pos_ned;
        let target = item.command.place().unwrap_or_default().ned(home, &pos);
        let origin = self.mission.prev_waypoint.unwrap_or(pos);
        self.active = match item.command {
            NavCommand::Waypoint {
                accept_radius_m, ..
            } => {
                let next = self.mission.corner_after(items, seq, home, &target);
                let airspeed = self.mission.cruise(p);
                let joining = self.mission.prev_waypoint.is_none();
                let leg = Leg::item(accept_radius_m, origin, target, next, airspeed, p, joining);
                Active::Waypoint(leg)
            }
            NavCommand::Loiter { circle, until, .. } => {
                Active::Loiter(Loiter::item(circle, until, target, p))
            }
            NavCommand::Takeoff { place, yaw } => {
                let t = Takeoff::item(&place, yaw, target, home, state, p);
                self.runway = Some(t.runway());
                Active::Takeoff(t)
            }
            NavCommand::Land { .. } => Active::Land(Landing::item(origin, target, pos)),
            // NAV_RETURN_TO_LAUNCH (the only navigation command left).
            _ => Active::Return(Return::new(pos, p.rtl_land)),
        };
        if !matches!(self.active, Active::Waypoint(_)) {
            self.mission.prev_waypoint = None;
        }
    }

    /// The current item is done: report it and walk on (or hold, without autocontinue).
    fn item_done(
        &mut self,
        items: Route<'_>,
        home: &Home,
        state: &NavState,
        hold: Orbit,
        out: &mut NavOutput,
    ) {
        let Some(seq) = self.mission.seq else {
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

    /// Flies the active behaviour one step.
    fn fly(
        &mut self,
        items: Route<'_>,
        home: &Home,
        state: &NavState,
        dt: f32,
        out: &mut NavOutput,
    ) {
        let f = Flight {
            params: &self.params,
            guidance: &self.guidance,
            state,
            dt,
            cruise: self.mission.cruise(&self.params),
            gust: self.gust.sigma(),
            circle_min: self.paths.circle_radius(self.mission.cruise(&self.params)),
        };
        let seq = self.mission.seq;
        match self.active {
            Active::Idle => {
                out.phase = Phase::Idle;
            }
            Active::Waypoint(mut leg) => {
                let reached = leg.step(&f, &mut self.paths, seq, out);
                self.active = Active::Waypoint(leg);
                if reached {
                    // The new item flies from the next step; this step's commands already
                    // follow the next leg.
                    self.mission.prev_waypoint = Some(leg.target());
                    let hold = Orbit::loiter(leg.target(), f.params);
                    self.item_done(items, home, state, hold, out);
                }
            }
            Active::Loiter(mut l) => {
                let mut done = l.step(&f, seq, out);
                self.active = Active::Loiter(l);
                let orbit = l.orbit();
                // Leave the circle where it heads for the next point (PX4's and ArduPilot's
                // exit): leaving anywhere else turns the aircraft round on the next leg, up
                // to two turn radii off it.
                if done && !self.mission.heading_for_next(items, home, state, &orbit) {
                    done = false;
                }
                if done {
                    self.item_done(items, home, state, orbit, out);
                }
            }
            Active::Takeoff(mut t) => {
                let reached = t.step(&f, out);
                self.active = Active::Takeoff(t);
                if let Some(hold) = reached {
                    self.item_done(items, home, state, hold, out);
                }
            }
            Active::Land(mut l) => {
                let before = l.landed();
                l.step(&f, out);
                self.active = Active::Land(l);
                if !before && l.landed() {
                    out.reached = seq;
                }
            }
            Active::Return(mut r) => {
                r.step(&f, &mut self.paths, self.runway, seq, out);
                self.active = Active::Return(r);
            }
            Active::Hold(o) => {
                f.emit(&f.circle(&o, f.cruise), Some(o.center), Phase::Hold, out);
            }
            Active::Complete(o) => {
                f.emit(
                    &f.circle(&o, f.cruise),
                    Some(o.center),
                    Phase::Complete,
                    out,
                );
            }
        }
    }
}
