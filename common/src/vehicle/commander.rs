//! The commander: what the vehicle is doing and what it asks of the control stages.
//!
//! It keeps the armed state and the chosen mode, takes the requests a ground link accepted
//! (arming, mode entry, set points, the current mission item: [`Commander::apply`], as they
//! arrive), and once a control tick ([`Commander::step`]) watches for a landing, reacts to the
//! failsafes (the mode actually flown), hands the navigation modes to the navigator and turns
//! the flown mode into [`Commands`] for the autopilot, or into surfaces directly in Manual.
//! What each mode commands is its row of the table of mode facts
//! ([`super::modes::MODES`]). Everything it has to say goes out as [`Notice`]s.
//!
//! The [`Navigator`] is the vehicle's, lent to the commander by `&mut` for a request or a
//! step: the vehicle configures it from the parameters and the plan's checks and the reports
//! read its settings, none of which is the commander's business, while what it flies, when it
//! starts and what becomes of its output (mission progress, a new home, the disarm after a
//! landing) is decided within the commander's step, in the same order as it is flown.

use heapless::Deque;

use super::land_detector::{reported_state, LandDetector, LandInputs, LandParams};
use super::modes::{Commanded, FlightMode, NavTask};
use super::requests::VehicleRequests;
use super::snapshot::{LandedState, MissionRunState};
use crate::actuators::Surfaces;
use crate::battery::Warning;
use crate::control::autopilot::{Commands, GainSet};
use crate::control::lateral::{RollMode, YawMode, RUDDER};
use crate::control::longitudinal::LonMode;
use crate::estimator::{EstimatedState, Home};
use crate::failsafe::{FailsafeConfig, FailsafeInputs, Failsafes, Reaction};
use crate::navigation::fence::{breached, FenceParams};
use crate::navigation::item::{NavCommand, NavItem, Route};
use crate::navigation::items::{Altitude, Place};
use crate::navigation::navigator::io::{
    GroundStage, HeightOracle, HomeRequest, NavOutput, NavState, Phase,
};
use crate::navigation::navigator::Navigator;
use crate::navigation::plan::{MissionStore, PlanKind};
use crate::sensors::ManualInput;

/// Sticks older than this are ignored (the ground station or the radio stopped sending), us.
pub const STICK_TIMEOUT_US: u64 = 500_000;

/// A failsafe on the take-off roll gave the take-off up.
pub const TEXT_ABORTED: &str = "Failsafe on the runway: take-off aborted";
/// A failsafe in the take-off's climb waits for `NAV_TKO_CLR_M`, wings level.
pub const TEXT_CLIMB_FIRST: &str = "Failsafe in the climb-out: wings level up first";
/// A failsafe in a flare or roll-out waits for the stop.
pub const TEXT_LANDING_FIRST: &str = "Failsafe at touchdown: the landing goes on";
/// The aborted take-off has rolled to a stop and disarmed.
pub const TEXT_ABORT_DISARMED: &str = "Take-off aborted, stopped: disarmed";

/// How urgent a [`Notice`] is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Severity {
    /// Something happened as asked.
    Info,
    /// Something was refused or is not as expected.
    Warning,
    /// A failsafe or a refusal that grounds the aircraft.
    Critical,
}

/// What the vehicle has to tell its ground station.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Notice {
    /// A status text.
    Text(Severity, &'static str),
    /// Mission progress: a new current item, an item finished.
    Mission {
        /// The new current item.
        current: Option<u16>,
        /// The item just finished.
        reached: Option<u16>,
    },
    /// The autotune's progress or result (the link words it).
    Tune(crate::tuning::autotune::Report),
}

/// Notices kept until the vehicle's owner collects them (more are dropped).
pub const NOTICE_CAPACITY: usize = 16;

/// What the autopilot is asked to hold in the guided modes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Setpoints {
    /// Course over ground, rad.
    pub course: f32,
    /// Altitude above mean sea level, m.
    pub alt_amsl_m: f32,
    /// Airspeed, m/s.
    pub airspeed: f32,
}

/// What the flown mode asks of the actuators this tick.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Demand {
    /// Surfaces set directly (Manual: the sticks, or the trim without them).
    Surfaces(Surfaces),
    /// Commands for the autopilot's loops.
    Commands(Commands),
}

/// The failsafes' settings and the fence they watch.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Watch {
    /// Failsafe timeouts and actions.
    pub failsafe: FailsafeConfig,
    /// Geofence settings.
    pub fence: FenceParams,
}

/// What the commander is handed for one control tick.
#[derive(Debug)]
pub struct CommanderInputs<'a> {
    /// The vehicle's clock, us.
    pub now_us: u64,
    /// Time since the last control tick, s.
    pub dt: f32,
    /// The estimate for the whole tick.
    pub estimate: &'a EstimatedState,
    /// The vehicle's navigator, flown in the navigation modes.
    pub navigator: &'a mut Navigator,
    /// The stored mission and geofence.
    pub plan: &'a MissionStore,
    /// The autopilot's gains (its trims and limits).
    pub gains: &'a GainSet,
    /// The failsafes' settings and the fence.
    pub watch: &'a Watch,
    /// The land detector's settings.
    pub land: &'a LandParams,
    /// Magnitude of the last accelerometer sample, m/s^2.
    pub specific_force: Option<f32>,
    /// When a ground station was last heard, us (the link-loss failsafe).
    pub gcs_heard_us: Option<u64>,
    /// The battery monitor's warning, `None` when no battery is monitored.
    pub battery: Option<Warning>,
    /// The simulator's truth for the flare (`SIM_USE_TRUTH`), handed to the navigator.
    pub oracle: Option<HeightOracle>,
}

/// What one control tick of the commander decided.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CommanderOutput {
    /// What the flown mode asks of the actuators.
    pub demand: Demand,
    /// A new home, for the vehicle to hand to the estimator (a mission item's DO_SET_HOME).
    pub home: Option<Home>,
}

/// The commander's state.
#[derive(Clone, Debug)]
pub struct Commander {
    armed: bool,
    mode: FlightMode,
    setpoints: Setpoints,
    sticks: Option<ManualInput>,
    reaction: Reaction,
    /// Altitude (AMSL, m) held while a GPS failsafe flies wings level.
    wings_level: Option<f32>,
    /// Where a raised failsafe's reaction is held back near the ground (the take-off's
    /// climb-out, a touchdown), `None` when it is not.
    held_at: Option<GroundStage>,
    /// The navigator's last output.
    nav: NavOutput,
    /// The mode the navigator was last started for.
    nav_for: Option<FlightMode>,
    mission_seq: u16,
    mission_state: MissionRunState,
    failsafes: Failsafes,
    land: LandDetector,
    notices: Deque<Notice, NOTICE_CAPACITY>,
    dropped_notices: u32,
    /// This tick's truth for the flare, if the simulation gives one.
    oracle: Option<HeightOracle>,
}

impl Default for Commander {
    fn default() -> Self {
        Self::new()
    }
}

/// The arming rule's test of a take-off already made: above 8 m/s and 5 m above home, arming
/// does not move home (an air start keeps the home it has). It decides nothing else: whether
/// the aircraft is flying is the land detector's ([`Commander::landed_state`]).
pub fn in_air(e: &EstimatedState) -> bool {
    let height = e.home.map_or(0.0, |h| e.alt_amsl_m - h.alt_amsl_m);
    e.airspeed > 8.0 && height > 5.0
}

/// An altitude above mean sea level from a height above `home`, m; `None` without a home.
/// The commander's heights take the navigator's one conversion ([`Altitude::amsl_m`]), so
/// home's altitude is added in one place.
pub fn above_home(home: Option<Home>, height_m: f32) -> Option<f32> {
    home.map(|h| Altitude::AboveHome(height_m).amsl_m(&h))
}

/// A home at the aircraft's estimated position and altitude.
fn here(e: &EstimatedState) -> Home {
    Home {
        point: e.position,
        alt_amsl_m: e.alt_amsl_m,
    }
}

/// The trims of a gain set as surface positions.
pub fn trim_surfaces(g: &GainSet) -> Surfaces {
    Surfaces {
        elevator: g.longitudinal.trim_elevator,
        aileron: g.lateral.trim_aileron,
        rudder: g.lateral.trim_rudder,
        throttle: g.longitudinal.trim_throttle,
    }
}

/// The Takeoff mode's one item: climb out along the present heading to the return altitude.
fn takeoff_item(height_m: f32) -> NavItem {
    NavItem {
        command: NavCommand::Takeoff {
            place: Place {
                point: None,
                alt: height_m
                    .is_finite()
                    .then_some(Altitude::AboveHome(height_m)),
            },
            yaw: None,
        },
        autocontinue: true,
    }
}

impl Commander {
    /// Disarmed, in Manual, holding 100 m AMSL at 17 m/s when a guided mode engages.
    pub fn new() -> Self {
        Self {
            armed: false,
            mode: FlightMode::Manual,
            setpoints: Setpoints {
                course: 0.0,
                alt_amsl_m: 100.0,
                airspeed: 17.0,
            },
            sticks: None,
            reaction: Reaction::None,
            wings_level: None,
            held_at: None,
            nav: NavOutput::default(),
            nav_for: None,
            mission_seq: 0,
            mission_state: MissionRunState::NotStarted,
            failsafes: Failsafes::new(),
            land: LandDetector::new(),
            notices: Deque::new(),
            dropped_notices: 0,
            oracle: None,
        }
    }

    /// Armed (throttle live).
    pub fn armed(&self) -> bool {
        self.armed
    }

    /// The mode the pilot (or ground station) chose.
    pub fn chosen_mode(&self) -> FlightMode {
        self.mode
    }

    /// Mode being flown: the pilot's choice, or what a failsafe put in its place.
    pub fn flown_mode(&self) -> FlightMode {
        match self.reaction {
            Reaction::None => self.mode,
            Reaction::WingsLevel => FlightMode::Altitude,
            Reaction::Loiter => FlightMode::Loiter,
            Reaction::Return => FlightMode::Return,
            Reaction::Land => FlightMode::Land,
        }
    }

    /// The land detector's verdict: on the ground.
    pub fn landed(&self) -> bool {
        self.land.landed()
    }

    /// Armed and not on the ground: the failsafes watch, a disarm must be forced.
    pub fn flying(&self) -> bool {
        self.armed && !self.land.landed()
    }

    /// Steps the land detector at the control rate: `specific_force` is the magnitude of the
    /// last accelerometer sample, m/s^2.
    pub(crate) fn detect_landing(
        &mut self,
        p: &LandParams,
        e: &EstimatedState,
        specific_force: Option<f32>,
        dt: f32,
    ) {
        let inputs = LandInputs {
            armed: self.armed,
            ground_speed: e.ground_speed,
            vel_down: e.vel_ned.z,
            airspeed: e.airspeed,
            specific_force,
            rolling_out: self.rolling_out(),
        };
        self.land.update(p, &inputs, dt);
    }

    /// The landed state reported (`EXTENDED_SYS_STATE`): the land detector's verdict, told
    /// apart by what the navigator flies. Taking off: armed in the take-off roll or in the
    /// climb to the take-off altitude. Landing: airborne on a landing's approach or flare (or
    /// rolling out fast enough to count as moving, after a landing or a take-off given up).
    /// In the air: airborne otherwise. On the ground: the detector's landed, outside a
    /// take-off.
    pub fn landed_state(&self) -> LandedState {
        reported_state(self.land.landed(), self.navigated_phase())
    }

    /// In the navigator's roll-out, where it stays once it disarms the aircraft.
    fn rolling_out(&self) -> bool {
        self.navigator_flies() && self.nav.phase.rolls_out()
    }

    /// The navigator has a plan and the flown mode is one it flies (armed or not).
    fn navigator_flies(&self) -> bool {
        self.nav_for.is_some() && self.flown_mode().needs_navigator()
    }

    /// The navigator's phase while it flies the armed aircraft.
    fn navigated_phase(&self) -> Option<Phase> {
        (self.armed && self.navigator_flies()).then_some(self.nav.phase)
    }

    /// What a failsafe has the aircraft do instead of the chosen mode.
    pub fn reaction(&self) -> Reaction {
        self.reaction
    }

    /// Whether any failsafe is raised.
    pub fn failsafe_active(&self) -> bool {
        self.failsafes.active()
    }

    /// Where a raised failsafe's reaction is held back near the ground (a take-off's
    /// climb-out, a touchdown), `None` when it is not.
    pub fn held_at(&self) -> Option<GroundStage> {
        self.held_at
    }

    /// The guided modes' set points.
    pub fn setpoints(&self) -> Setpoints {
        self.setpoints
    }

    /// The navigator's last output (phase, mission item, guidance errors).
    pub fn navigation(&self) -> &NavOutput {
        &self.nav
    }

    /// The current mission item and how far the mission has come.
    pub fn mission(&self) -> (u16, MissionRunState) {
        (self.mission_seq, self.mission_state)
    }

    /// The airspeed the altitude-holding modes hold, m/s.
    pub fn set_cruise_airspeed(&mut self, v: f32) {
        self.setpoints.airspeed = v;
    }

    /// The latest stick positions (a ground station's or the radio's).
    pub fn on_sticks(&mut self, s: ManualInput) {
        self.sticks = Some(s);
    }

    /// Queues a notice for the owner (dropped and counted when the queue is full).
    pub fn notify(&mut self, n: Notice) {
        if self.notices.push_back(n).is_err() {
            self.dropped_notices = self.dropped_notices.saturating_add(1);
        }
    }

    /// The next notice, oldest first.
    pub fn next_notice(&mut self) -> Option<Notice> {
        self.notices.pop_front()
    }

    /// Notices dropped because nobody collected them.
    pub fn dropped_notices(&self) -> u32 {
        self.dropped_notices
    }

    fn text(&mut self, s: Severity, t: &'static str) {
        self.notify(Notice::Text(s, t));
    }

    /// Acts on what the ground station asked for, as it arrives (between control ticks too).
    /// Returns a new home when arming on the ground moves it.
    pub fn apply(
        &mut self,
        r: &VehicleRequests,
        e: &EstimatedState,
        navigator: &mut Navigator,
    ) -> Option<Home> {
        let mut rehome = None;
        if let Some(a) = r.arm {
            if a.arm && !self.armed && !in_air(e) {
                // Home is where the aircraft is armed, as in PX4: the first fix set it from one
                // GPS altitude (5 m of vertical noise); the estimate at arming has averaged
                // GPS and barometer for as long as the estimator took to converge, and the
                // landing aims at this height.
                if let Some(h) = e.home {
                    let here = here(e);
                    if here != h {
                        rehome = Some(here);
                    }
                }
            }
            if a.arm != self.armed {
                self.armed = a.arm;
                if a.arm {
                    self.failsafes.new_flight();
                } else {
                    navigator.stop();
                    self.nav_for = None;
                    self.failsafes.acknowledge();
                }
                self.text(Severity::Info, if a.arm { "Armed" } else { "Disarmed" });
            }
        }
        if let Some(mode) = r.mode {
            if mode != self.mode {
                // Entering a guided mode holds where the aircraft is.
                if mode.holds_setpoints() && !self.mode.holds_setpoints() {
                    self.setpoints.course = e.course;
                    self.setpoints.alt_amsl_m = e.alt_amsl_m;
                }
                if self.mode == FlightMode::Mission {
                    self.mission_state = MissionRunState::Paused;
                }
                self.mode = mode;
                self.nav_for = None;
            }
            // Choosing a mode, even the same one, takes over from a failsafe's return.
            self.failsafes.acknowledge();
        }
        if let Some(seq) = r.mission_seq {
            self.mission_seq = seq;
            if self.nav_for == Some(FlightMode::Mission) {
                navigator.set_current(seq);
            }
        }
        if let Some(alt) = r.altitude {
            let target = if alt.relative_to_home {
                above_home(e.home, alt.alt_m)
            } else {
                Some(0.0 + alt.alt_m)
            };
            match target {
                Some(a) => self.setpoints.alt_amsl_m = a,
                None => self.text(
                    Severity::Warning,
                    "Altitude above home refused: no home yet",
                ),
            }
        }
        if let Some(v) = r.airspeed {
            self.setpoints.airspeed = v;
        }
        if r.go_around {
            if navigator.go_around() {
                self.text(Severity::Info, "Going around");
            } else {
                self.text(
                    Severity::Warning,
                    "Go-around refused: not in the air on a landing",
                );
            }
        }
        if r.manual.is_some() {
            self.sticks = r.manual;
        }
        if let Some(c) = r.course {
            let base = if c.relative {
                self.setpoints.course
            } else {
                0.0
            };
            self.setpoints.course = crate::math::wrap_two_pi(base + c.angle);
        }
        rehome
    }

    /// One control tick: the land detector, the failsafes and their reaction, then what the
    /// flown mode asks of the actuators (stepping the navigator in its modes), in that order.
    pub fn step(&mut self, i: CommanderInputs<'_>) -> CommanderOutput {
        self.detect_landing(i.land, i.estimate, i.specific_force, i.dt);
        self.check_failsafes(
            i.now_us,
            i.estimate,
            i.watch,
            i.plan,
            (i.gcs_heard_us, i.battery),
            i.navigator,
        );
        self.oracle = i.oracle;
        let armed = self.armed;
        let (demand, home) = self.demand(i.now_us, i.dt, i.estimate, i.navigator, i.plan, i.gains);
        if armed && !self.armed {
            // Disarmed on this tick (the navigator's landing): the landed state it reports is
            // the disarmed aircraft's.
            self.land.disarmed(i.land, self.rolling_out());
        }
        CommanderOutput { demand, home }
    }

    /// Watches the failsafes at the control rate and acts on their reaction (near the ground
    /// as [`Commander::near_the_ground`] has it). `link` is when a ground station was last
    /// heard (us) and the battery monitor's warning (`None` when no battery is monitored).
    pub(crate) fn check_failsafes(
        &mut self,
        now_us: u64,
        e: &EstimatedState,
        watch: &Watch,
        plan: &MissionStore,
        link: (Option<u64>, Option<Warning>),
        navigator: &mut Navigator,
    ) {
        let (gcs_heard_us, battery) = link;
        let stage = if self.navigator_flies() {
            navigator.ground_stage()
        } else {
            GroundStage::Clear
        };
        // The take-off roll is watched from its first metre, before its speed shows the land
        // detector a flight: the failsafe gives the take-off up there.
        let flying = self.flying() || (self.armed && stage == GroundStage::TakeoffRoll);
        let fence_breached = match e.home {
            Some(h) => {
                breached(plan.items(PlanKind::Fence), &h, &e.pos_ned, &watch.fence).is_some()
            }
            None => false,
        };
        let inputs = FailsafeInputs {
            t_us: now_us,
            flying,
            gcs_heard_us,
            gps_ok: e.health.gps.healthy,
            airspeed_ok: e.health.pitot.healthy,
            fence_breached,
            battery,
        };
        let (reaction, events) = self.failsafes.update(&watch.failsafe, &inputs);
        for ev in events {
            let sev = match (ev.raises(), ev.advisory()) {
                (false, _) => Severity::Info,
                (true, true) => Severity::Warning,
                (true, false) => Severity::Critical,
            };
            self.text(sev, ev.text());
        }
        let reaction = self.near_the_ground(reaction, stage, navigator);
        if reaction == Reaction::WingsLevel && self.wings_level.is_none() {
            self.wings_level = Some(e.alt_amsl_m);
        }
        if reaction != Reaction::WingsLevel {
            self.wings_level = None;
        }
        self.reaction = reaction;
    }

    /// The reaction flown for the failsafes' `raised` one with the take-off or landing at
    /// `stage`, as PX4 and ArduPlane users expect: on the take-off roll the take-off is given
    /// up (throttle closed, wings level, steered to a stop on the runway; the plant has no
    /// brakes to apply), past the rotation it climbs on wings level to `NAV_TKO_CLR_M` before
    /// the reaction turns it, and a flare or roll-out finishes the landing. A reaction
    /// already flown stays, and a cleared one (the pilot's choice of mode) ends at once.
    fn near_the_ground(
        &mut self,
        raised: Reaction,
        stage: GroundStage,
        navigator: &mut Navigator,
    ) -> Reaction {
        let change = raised != Reaction::None && raised != self.reaction;
        let held = match stage {
            _ if !change => None,
            GroundStage::Clear => None,
            GroundStage::TakeoffRoll if !self.armed => None,
            GroundStage::TakeoffRoll => {
                if navigator.abort_takeoff() {
                    self.text(Severity::Critical, TEXT_ABORTED);
                    if self.nav_for == Some(FlightMode::Mission) {
                        self.mission_state = MissionRunState::Paused;
                    }
                }
                // The roll-out to a stop is the navigator's from its next step.
                Some(GroundStage::Touchdown)
            }
            GroundStage::ClimbOut | GroundStage::Touchdown => Some(stage),
        };
        if held != self.held_at {
            match (stage, held) {
                (GroundStage::ClimbOut, Some(_)) => self.text(Severity::Warning, TEXT_CLIMB_FIRST),
                (GroundStage::Touchdown, Some(_)) => {
                    self.text(Severity::Warning, TEXT_LANDING_FIRST)
                }
                _ => {}
            }
        }
        self.held_at = held;
        if held.is_some() {
            self.reaction
        } else {
            raised
        }
    }

    /// What the flown mode asks of the actuators this tick, at `now_us`, `dt` after the last
    /// one. The second value is a home a mission item moved (DO_SET_HOME).
    pub(crate) fn demand(
        &mut self,
        now_us: u64,
        dt: f32,
        e: &EstimatedState,
        navigator: &mut Navigator,
        plan: &MissionStore,
        gains: &GainSet,
    ) -> (Demand, Option<Home>) {
        let sp = self.setpoints;
        let level = gains.longitudinal;
        let sticks = self
            .sticks
            .filter(|s| now_us.saturating_sub(s.time_us) <= STICK_TIMEOUT_US);
        // On the ground with no pilot on the sticks, the motor idles and the surfaces rest at
        // trim, as PX4 idles a landed fixed wing: otherwise arming would run it at its trim
        // throttle (57 %) at once, and the loops of the holding modes would wind up against
        // the wheels. The loops take over from these positions once airborne.
        let idle = Surfaces {
            throttle: 0.0,
            ..trim_surfaces(gains)
        };
        if self.mode.commands() == Commanded::Surfaces {
            // Pass-through: sticks straight to the surfaces (PX4's normalised sense), trim
            // when no stick is live (idle on the ground).
            let s = match sticks {
                Some(s) => Surfaces::from_px4_controls([s.roll, s.pitch, s.yaw, s.throttle]),
                None if self.land.landed() => idle,
                None => trim_surfaces(gains),
            };
            return (Demand::Surfaces(s), None);
        }
        let flown = self.flown_mode();
        let hold = |altitude| Commands {
            roll: RollMode::Roll(0.0),
            yaw: RUDDER,
            lon: LonMode::Altitude {
                altitude,
                airspeed: sp.airspeed,
            },
        };
        if let (Reaction::WingsLevel, Some(alt)) = (self.reaction, self.wings_level) {
            return (Demand::Commands(hold(alt)), None);
        }
        // Disarmed after a landing, the surfaces rest at trim even while the aircraft still
        // rolls: the roll-out's steering and tail-down pitch, run on with no one to stop them,
        // drove the rudder and elevator to their stops and hopped the aircraft into the air.
        if !self.armed && self.nav.phase.rolls_out() && flown.needs_navigator() {
            return (Demand::Surfaces(idle), None);
        }
        if let Some(task) = flown.nav_task() {
            let (commands, home) = self.navigate(flown, task, dt, e, navigator, plan);
            // No home yet (refused before, so only after a reset): hold what we have.
            let mut c = commands.unwrap_or(hold(sp.alt_amsl_m));
            // A failsafe waiting for the climb-out's height: wings level until then, the
            // take-off's pitch and throttle kept.
            if self.held_at == Some(GroundStage::ClimbOut) {
                c.roll = RollMode::Roll(0.0);
            }
            return (Demand::Commands(c), home);
        }
        let unflown = match flown.commands() {
            Commanded::Altitude | Commanded::Course => true,
            Commanded::Attitude => sticks.is_none(),
            Commanded::Surfaces | Commanded::Navigator(_) => false,
        };
        if self.land.landed() && unflown {
            return (Demand::Surfaces(idle), None);
        }
        let commands = match flown.commands() {
            Commanded::Attitude => Commands {
                // Sticks command attitude within the loops' limits; centred: wings level. The
                // yaw stick moves the rudder over the damper (PX4's sense: right yaw, rudder
                // right, which is negative here).
                roll: RollMode::Roll(sticks.map_or(0.0, |s| s.roll * gains.lateral.roll_max)),
                yaw: sticks.map_or(RUDDER, |s| {
                    YawMode::DamperPlus(-s.yaw * gains.lateral.rudder_max)
                }),
                lon: LonMode::Pitch {
                    pitch: sticks.map_or(0.0, |s| s.pitch * level.pitch_max),
                    throttle: sticks.map_or(level.trim_throttle, |s| s.throttle),
                },
            },
            Commanded::Altitude => hold(sp.alt_amsl_m),
            Commanded::Course => Commands {
                roll: RollMode::Course(sp.course),
                ..hold(sp.alt_amsl_m)
            },
            // Flown only when chosen, pass-through answered above; the navigator's above too.
            Commanded::Surfaces | Commanded::Navigator(_) => Commands::OFF,
        };
        (Demand::Commands(commands), None)
    }

    /// Runs the navigator for a navigation mode: starts it when the mode has changed, steps
    /// it, reports mission progress. No commands until home is set.
    fn navigate(
        &mut self,
        flown: FlightMode,
        task: NavTask,
        dt: f32,
        e: &EstimatedState,
        navigator: &mut Navigator,
        plan: &MissionStore,
    ) -> (Option<Commands>, Option<Home>) {
        let Some(home) = e.home else {
            return (None, None);
        };
        if self.nav_for != Some(flown) {
            self.nav_for = Some(flown);
            match task {
                NavTask::Mission => {
                    navigator.set_current(self.mission_seq);
                    self.mission_state = MissionRunState::Active;
                }
                NavTask::Loiter => navigator.start_loiter(None),
                NavTask::Return => navigator.start_return(navigator.params().rtl_land),
                NavTask::Land => navigator.start_return(true),
                NavTask::Takeoff => navigator.start_mission(0),
            }
        }
        let takeoff = takeoff_item(navigator.params().rtl_alt);
        let items = match task {
            NavTask::Mission => Route::Plan(plan.items(PlanKind::Mission)),
            NavTask::Takeoff => Route::Item(&takeoff),
            NavTask::Loiter | NavTask::Return | NavTask::Land => Route::Plan(&[]),
        };
        let state = NavState {
            oracle: self.oracle,
            ..NavState::from_estimate(e)
        };
        let out = navigator.step_route(items, &home, &state, dt);
        if task == NavTask::Mission {
            let current = out.current_seq.filter(|&c| c != self.mission_seq);
            if let Some(c) = out.current_seq {
                self.mission_seq = c;
            }
            if current.is_some() || out.reached.is_some() {
                self.notify(Notice::Mission {
                    current,
                    reached: out.reached,
                });
            }
            if out.phase == Phase::Complete || out.phase == Phase::Landed {
                self.mission_state = MissionRunState::Complete;
            } else if out.phase == Phase::TakeoffAbort {
                // As after a failsafe's abort: the mission waits for the station.
                self.mission_state = MissionRunState::Paused;
            }
        }
        for w in &out.warnings {
            self.text(Severity::Warning, w.text());
        }
        let rehome = out.set_home.map(|req| match req {
            HomeRequest::Here => here(e),
            HomeRequest::At(h) => h,
        });
        if out.landed && self.armed {
            self.armed = false;
            let said = if out.phase == Phase::TakeoffAbort {
                TEXT_ABORT_DISARMED
            } else {
                "Landed, disarmed"
            };
            self.text(Severity::Info, said);
        }
        let commands = out.commands;
        self.nav = out;
        (commands, rehome)
    }
}
