//! The autopilot's tick, independent of any board.
//!
//! One [`App`] owns every stage of `common` and both MAVLink links:
//!
//! ```text
//! sim link bytes -> FrameParser -> HIL_SENSOR / HIL_GPS -> Estimator
//!                                  every 20 ms: mode logic -> Autopilot -> Surfaces
//!                               <- HIL_ACTUATOR_CONTROLS (one per sensor frame, lock-step)
//! GCS link bytes -> FrameParser -> GroundLink (params, missions, commands) -> requests
//!                               <- telemetry, acknowledgements, STATUSTEXT
//! ```
//!
//! The clock is the simulator's (`time_usec` of the sensor frames) in SITL and the board's
//! sensor timestamps on the MCU; nothing here reads a clock of its own.

use common::actuators::Surfaces;
use common::control::autopilot::{Autopilot, Commands, Measurements};
use common::control::gains::{GainSet, DESIGNED, NAMED, STAGE_PARAMS};
use common::control::lateral::{RollMode, RUDDER};
use common::control::longitudinal::LonMode;
use common::estimator::{EstimatedState, Estimator, EstimatorConfig};
use common::failsafe::{FailsafeConfig, FailsafeInputs, Failsafes, Reaction};
use common::gcs::mission::{MissionItem, PlanKind, PlanRules};
use common::gcs::modes::{FlightMode, ModeSet};
use common::gcs::param_store::Registry;
use common::gcs::snapshot::{
    Battery, GpsRaw, Home, LandedState, MissionRunState, NavOutput as NavTelemetry, SensorHealth,
    VehicleSnapshot,
};
use common::gcs::{GroundLink, ManualInput, VehicleRequests};
use common::link::framing::{Frame, FrameParser, LinkStats, Sender};
use common::link::simlink::{self, ActuatorFrame, Rejected};
use common::navigation::{
    self, breached, FenceParams, HomeRequest, MissionLimits, NavOutput, NavState, Navigator, Phase,
    PARAM_LISTS,
};
use common::params::ParamDef;
use common::sensors::GpsFix;
use mavlink::dialects::common::{MavMessage, MavSeverity};

/// MAVLink identity of the autopilot (DESIGN.md: system 1, component 1).
pub const SYSTEM_ID: u8 = 1;
/// MAVLink component of the autopilot.
pub const COMPONENT_ID: u8 = 1;

/// Control period, us: the thesis's 50 Hz.
pub const CONTROL_PERIOD_US: u64 = 20_000;

/// Settings of the application itself.
pub const PARAMS: &[ParamDef] = &[
    ParamDef::int(
        "SYS_GAIN_SET",
        0,
        0,
        (NAMED.len() - 1) as i32,
        "",
        "Gain set loaded into the control parameters: 0 designed, 1 designed_t310, 2 designed_appe, 3 minnesota, 4 minnesota_appe",
    ),
    ParamDef::int(
        "SIM_USE_TRUTH",
        0,
        0,
        1,
        "",
        "1: fly on the simulator's truth (HIL_STATE_QUATERNION) instead of the estimator, to measure what estimation costs",
    ),
    ParamDef::real(
        "FW_AIRSPD_TRIM",
        17.0,
        10.0,
        30.0,
        "m/s",
        "Airspeed held in the altitude-holding modes until a ground station changes it",
    ),
];

/// Every parameter the autopilot has: the control stages, the estimator and the application.
pub const REGISTRY: Registry = &[
    STAGE_PARAMS[0],
    STAGE_PARAMS[1],
    STAGE_PARAMS[2],
    common::estimator::config::PARAMS,
    PARAM_LISTS[0],
    PARAM_LISTS[1],
    PARAM_LISTS[2],
    PARAM_LISTS[3],
    PARAM_LISTS[4],
    common::failsafe::PARAMS,
    PARAMS,
];

/// Counters the autopilot keeps about its simulator link.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SimLinkHealth {
    /// Sensor frames accepted.
    pub sensor_frames: u32,
    /// GPS frames accepted.
    pub gps_frames: u32,
    /// Frames from a system other than ours.
    pub foreign_frames: u32,
    /// Frames of a message the sim link does not carry.
    pub ignored_frames: u32,
    /// Sensor groups dropped as implausible, per group.
    pub rejected_imu: u32,
    /// Magnetometer groups dropped.
    pub rejected_mag: u32,
    /// Barometer groups dropped.
    pub rejected_baro: u32,
    /// Differential-pressure groups dropped.
    pub rejected_pitot: u32,
    /// GPS frames dropped.
    pub rejected_gps: u32,
    /// Sensor frames whose time did not advance.
    pub stale_frames: u32,
    /// RC_CHANNELS frames without a usable signal.
    pub rejected_rc: u32,
    /// Bytes to the ground station dropped because its buffer was full.
    pub gcs_bytes_dropped: u32,
}

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

/// Simulator truth, for logging and for the `SIM_USE_TRUTH` comparison only.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Truth {
    m: Measurements,
    time_us: u64,
}

const GCS_OUT: usize = 8192;

/// The autopilot application.
pub struct App {
    sim_parser: FrameParser,
    sim_tx: Sender,
    gcs_parser: FrameParser,
    gcs_tx: Sender,
    gcs: GroundLink,
    gcs_out: heapless::Vec<u8, GCS_OUT>,
    estimator: Estimator,
    autopilot: Autopilot,
    health: SimLinkHealth,
    last_time_us: Option<u64>,
    last_imu_us: Option<u64>,
    last_control_us: Option<u64>,
    last_gps: Option<GpsFix>,
    armed: bool,
    mode: FlightMode,
    setpoints: Setpoints,
    surfaces: Surfaces,
    params_seen: Option<u32>,
    gain_set_seen: f32,
    truth: Option<Truth>,
    use_truth: bool,
    sticks: Option<ManualInput>,
    navigator: Navigator,
    nav: NavOutput,
    /// The mode the navigator was last started for.
    nav_for: Option<FlightMode>,
    mission_seq: u16,
    mission_state: MissionRunState,
    failsafes: Failsafes,
    fs_cfg: FailsafeConfig,
    fence: FenceParams,
    limits: MissionLimits,
    reaction: Reaction,
    /// Altitude (AMSL, m) held while a GPS failsafe flies wings level.
    wings_level: Option<f32>,
}

/// Sticks older than this are ignored (the ground station stopped sending), us.
const STICK_TIMEOUT_US: u64 = 500_000;

impl Default for App {
    fn default() -> Self {
        Self::new()
    }
}

impl App {
    /// A freshly booted autopilot with default parameters: disarmed, in Manual.
    pub fn new() -> Self {
        // Both are constants checked by tests (unique parameter names, a valid gain set): no
        // input reaches these two lines.
        let gcs = GroundLink::new(REGISTRY).expect("REGISTRY has unique names (tested)");
        let autopilot = Autopilot::new(&DESIGNED).expect("DESIGNED validates (tested)");
        let mut app = Self {
            sim_parser: FrameParser::new(),
            sim_tx: Sender::new(SYSTEM_ID, COMPONENT_ID),
            gcs_parser: FrameParser::new(),
            gcs_tx: Sender::new(SYSTEM_ID, COMPONENT_ID),
            gcs,
            gcs_out: heapless::Vec::new(),
            estimator: Estimator::new(EstimatorConfig::default()),
            autopilot,
            health: SimLinkHealth::default(),
            last_time_us: None,
            last_imu_us: None,
            last_control_us: None,
            last_gps: None,
            armed: false,
            mode: FlightMode::Manual,
            setpoints: Setpoints {
                course: 0.0,
                alt_amsl_m: 100.0,
                airspeed: 17.0,
            },
            surfaces: trim_surfaces(&DESIGNED),
            params_seen: None,
            gain_set_seen: 0.0,
            truth: None,
            use_truth: false,
            sticks: None,
            navigator: Navigator::default(),
            nav: NavOutput::default(),
            nav_for: None,
            mission_seq: 0,
            mission_state: MissionRunState::NotStarted,
            failsafes: Failsafes::new(),
            fs_cfg: FailsafeConfig::default(),
            fence: FenceParams::default(),
            limits: MissionLimits::default(),
            reaction: Reaction::None,
            wings_level: None,
        };
        app.apply_params();
        app
    }

    /// Counters of the simulator link.
    pub fn sim_health(&self) -> SimLinkHealth {
        self.health
    }

    /// Framing counters of the simulator link.
    pub fn sim_link_stats(&self) -> LinkStats {
        self.sim_parser.stats()
    }

    /// Framing counters of the ground link.
    pub fn gcs_link_stats(&self) -> LinkStats {
        self.gcs_parser.stats()
    }

    /// The last accepted GPS fix.
    pub fn last_gps(&self) -> Option<GpsFix> {
        self.last_gps
    }

    /// The estimator's current state.
    pub fn estimate(&self) -> EstimatedState {
        self.estimator.state()
    }

    /// Armed (throttle live).
    pub fn armed(&self) -> bool {
        self.armed
    }

    /// Mode being flown: the pilot's choice, or what a failsafe put in its place.
    pub fn mode(&self) -> FlightMode {
        self.flown_mode()
    }

    /// The mode the pilot (or ground station) chose.
    pub fn chosen_mode(&self) -> FlightMode {
        self.mode
    }

    /// What a failsafe has the aircraft do instead of the chosen mode.
    pub fn failsafe_reaction(&self) -> Reaction {
        self.reaction
    }

    /// The navigator's last output (phase, mission item, guidance errors).
    pub fn navigation(&self) -> &NavOutput {
        &self.nav
    }

    fn flown_mode(&self) -> FlightMode {
        match self.reaction {
            Reaction::None => self.mode,
            Reaction::WingsLevel => FlightMode::Altitude,
            Reaction::Loiter => FlightMode::Loiter,
            Reaction::Return => FlightMode::Return,
        }
    }

    /// What the autopilot is holding: the guided modes' set points, or in a navigation mode
    /// what guidance commands (its altitude as AMSL).
    pub fn setpoints(&self) -> Setpoints {
        if !self.flown_mode().needs_navigator() {
            return self.setpoints;
        }
        let home_alt = self.estimator.state().home.map_or(0.0, |h| h.alt_amsl_m);
        match self.nav.guidance {
            Some(g) => Setpoints {
                course: g.course,
                alt_amsl_m: g.altitude + home_alt,
                airspeed: g.airspeed,
            },
            None => self.setpoints,
        }
    }

    /// The last surface commands.
    pub fn surfaces(&self) -> Surfaces {
        self.surfaces
    }

    /// The ground link (parameters, missions).
    pub fn ground_link(&self) -> &GroundLink {
        &self.gcs
    }

    /// The ground link, mutably (to load persisted parameters at start-up).
    pub fn ground_link_mut(&mut self) -> &mut GroundLink {
        &mut self.gcs
    }

    /// Feeds bytes from the simulator link; `out` receives the bytes to send back.
    pub fn on_sim_bytes(&mut self, bytes: &[u8], out: &mut impl FnMut(&[u8])) {
        let mut parser = core::mem::take(&mut self.sim_parser);
        parser.push(bytes, |frame| self.on_sim_frame(&frame, out));
        self.sim_parser = parser;
    }

    /// Feeds bytes from the ground station; the answers wait in [`App::drain_gcs`].
    pub fn on_gcs_bytes(&mut self, bytes: &[u8]) {
        let mut parser = core::mem::take(&mut self.gcs_parser);
        let before = parser.stats();
        let now = self.last_time_us.unwrap_or(0);
        let snapshot = self.snapshot();
        parser.push(bytes, |frame| {
            self.gcs
                .handle(&frame.header, &frame.message, now, &snapshot);
        });
        let after = parser.stats();
        let bad = after.crc_errors.wrapping_sub(before.crc_errors)
            + after.parse_errors.wrapping_sub(before.parse_errors);
        for _ in 0..bad.min(64) {
            self.gcs.note_rx_error();
        }
        self.gcs_parser = parser;
        self.apply_requests();
        self.poll_gcs(now);
    }

    /// Hands out the bytes waiting for the ground station.
    pub fn drain_gcs(&mut self, out: &mut impl FnMut(&[u8])) {
        if !self.gcs_out.is_empty() {
            out(&self.gcs_out);
            self.gcs_out.clear();
        }
    }

    fn on_sim_frame(&mut self, frame: &Frame, out: &mut impl FnMut(&[u8])) {
        if frame.header.system_id != u32::from(SYSTEM_ID) {
            self.health.foreign_frames += 1;
            return;
        }
        match &frame.message {
            MavMessage::HIL_SENSOR(d) => {
                let (sensors, rejected) = simlink::decode_hil_sensor(d);
                self.count_rejections(rejected);
                let t = sensors.time_us;
                if self.last_time_us.is_some_and(|last| t <= last) {
                    self.health.stale_frames += 1;
                }
                self.last_time_us = Some(t.max(self.last_time_us.unwrap_or(0)));
                self.health.sensor_frames += 1;
                // The gyro integrates over the time since the last *accepted* IMU sample, so a
                // rejected sample does not lose its share of the rotation.
                if let Some(imu) = sensors.imu {
                    if let Some(last) = self.last_imu_us.filter(|&l| t > l) {
                        self.estimator.update_imu(&imu, (t - last) as f32 * 1e-6);
                    }
                    self.last_imu_us = Some(t);
                }
                if let Some(m) = sensors.mag {
                    self.estimator.update_mag(&m);
                }
                if let Some(b) = sensors.baro {
                    self.estimator.update_baro(&b);
                }
                if let Some(p) = sensors.pitot {
                    self.estimator.update_pitot(&p);
                }
                self.tick(t);
                let answer = ActuatorFrame {
                    time_us: t,
                    surfaces: self.surfaces,
                    armed: self.armed,
                };
                let msg = MavMessage::HIL_ACTUATOR_CONTROLS(simlink::encode_actuators(&answer));
                out(self.sim_tx.encode(&msg).raw_bytes());
            }
            MavMessage::HIL_GPS(d) => match simlink::decode_hil_gps(d) {
                Some(fix) => {
                    self.health.gps_frames += 1;
                    self.last_gps = Some(fix);
                    self.estimator.update_gps(&fix);
                }
                None => self.health.rejected_gps += 1,
            },
            MavMessage::HIL_STATE_QUATERNION(d) => {
                if let Some(m) = truth_measurements(d) {
                    self.truth = Some(Truth {
                        m,
                        time_us: d.time_usec,
                    });
                }
            }
            MavMessage::RC_CHANNELS(d) => {
                // The radio: the sticks of the manual and stabilised modes, like a ground
                // station's MANUAL_CONTROL; a frame without signal is ignored and the sticks
                // time out.
                let t = self.last_time_us.unwrap_or(0);
                match simlink::decode_rc_channels(d, t) {
                    Some(m) => self.sticks = Some(m),
                    None => self.health.rejected_rc += 1,
                }
            }
            MavMessage::HEARTBEAT(_) => {}
            _ => self.health.ignored_frames += 1,
        }
    }

    fn count_rejections(&mut self, r: Rejected) {
        self.health.rejected_imu += u32::from(r.imu);
        self.health.rejected_mag += u32::from(r.mag);
        self.health.rejected_baro += u32::from(r.baro);
        self.health.rejected_pitot += u32::from(r.pitot);
    }

    /// Everything after the sensors: requests, parameters, control at 50 Hz, telemetry.
    fn tick(&mut self, now_us: u64) {
        self.apply_requests();
        self.apply_params();
        let due = self
            .last_control_us
            .is_none_or(|t| now_us >= t + CONTROL_PERIOD_US);
        if due {
            let dt = self
                .last_control_us
                .map_or(CONTROL_PERIOD_US as f32 * 1e-6, |t| {
                    (now_us - t) as f32 * 1e-6
                });
            self.last_control_us = Some(now_us);
            // One estimate for the whole control step.
            let e = self.estimator.state();
            self.check_failsafes(now_us, &e);
            self.control(dt, &e);
        }
        self.poll_gcs(now_us);
    }

    fn measurements(&self, e: &EstimatedState) -> Measurements {
        if self.use_truth {
            if let Some(t) = self.truth {
                return t.m;
            }
        }
        Measurements {
            roll: e.euler.phi,
            pitch: e.euler.theta,
            // Course needs ground speed; on the ground or in a hover-like crawl use heading.
            course: if e.ground_speed > 3.0 {
                e.course
            } else {
                e.euler.psi
            },
            roll_rate: e.body_rates.x,
            pitch_rate: e.body_rates.y,
            yaw_rate: e.body_rates.z,
            altitude: e.alt_amsl_m,
            airspeed: e.airspeed,
            sideslip: e.sideslip,
        }
    }

    fn control(&mut self, dt: f32, e: &EstimatedState) {
        let m = self.measurements(e);
        let sp = self.setpoints;
        let gains = *self.autopilot.gains();
        let level = gains.longitudinal;
        let now = self.last_time_us.unwrap_or(0);
        let sticks = self
            .sticks
            .filter(|s| now.saturating_sub(s.time_us) <= STICK_TIMEOUT_US);
        if self.mode == FlightMode::Manual {
            // Pass-through: sticks straight to the surfaces (PX4's normalised sense), trim
            // when no stick is live.
            self.surfaces = match sticks {
                Some(s) => Surfaces::from_px4_controls([s.roll, s.pitch, s.yaw, s.throttle]),
                None => trim_surfaces(&gains),
            };
            // The loops start from these positions when a stabilised mode engages.
            self.autopilot.handover(self.surfaces);
            return;
        }
        let flown = self.flown_mode();
        if let (Reaction::WingsLevel, Some(alt)) = (self.reaction, self.wings_level) {
            let commands = Commands {
                roll: RollMode::Roll(0.0),
                yaw: RUDDER,
                lon: LonMode::Altitude {
                    altitude: alt,
                    airspeed: sp.airspeed,
                },
            };
            self.surfaces = self.autopilot.step(&m, &commands, dt).surfaces;
            return;
        }
        if flown.needs_navigator() {
            let commands = match self.navigate(flown, dt, e) {
                Some(c) => c,
                // No home yet (refused before, so only after a reset): hold what we have.
                None => Commands {
                    roll: RollMode::Roll(0.0),
                    yaw: RUDDER,
                    lon: LonMode::Altitude {
                        altitude: sp.alt_amsl_m,
                        airspeed: sp.airspeed,
                    },
                },
            };
            self.surfaces = self.autopilot.step(&m, &commands, dt).surfaces;
            return;
        }
        let commands = match flown {
            FlightMode::Stabilized => Commands {
                // Sticks command attitude within the loops' limits; centred: wings level.
                roll: RollMode::Roll(sticks.map_or(0.0, |s| s.roll * gains.lateral.roll_max)),
                yaw: RUDDER,
                lon: LonMode::Pitch {
                    pitch: sticks.map_or(0.0, |s| s.pitch * level.pitch_max),
                    throttle: sticks.map_or(level.trim_throttle, |s| s.throttle),
                },
            },
            FlightMode::Altitude => Commands {
                roll: RollMode::Roll(0.0),
                yaw: RUDDER,
                lon: LonMode::Altitude {
                    altitude: sp.alt_amsl_m,
                    airspeed: sp.airspeed,
                },
            },
            FlightMode::Hold => Commands {
                roll: RollMode::Course(sp.course),
                yaw: RUDDER,
                lon: LonMode::Altitude {
                    altitude: sp.alt_amsl_m,
                    airspeed: sp.airspeed,
                },
            },
            _ => Commands::OFF,
        };
        let out = self.autopilot.step(&m, &commands, dt);
        self.surfaces = out.surfaces;
    }

    /// Runs the navigator for a navigation mode: starts it when the mode has changed, steps
    /// it, reports mission progress. `None` until home is set.
    fn navigate(&mut self, flown: FlightMode, dt: f32, e: &EstimatedState) -> Option<Commands> {
        let home = e.home?;
        if self.nav_for != Some(flown) {
            self.nav_for = Some(flown);
            match flown {
                FlightMode::Mission => {
                    self.navigator.set_current(self.mission_seq);
                    self.mission_state = MissionRunState::Active;
                }
                FlightMode::Loiter => self.navigator.start_loiter(None),
                FlightMode::Return => self
                    .navigator
                    .start_return(self.navigator.params().rtl_land),
                FlightMode::Land => self.navigator.start_return(true),
                _ => self.navigator.start_mission(0),
            }
        }
        let takeoff = [takeoff_item(self.navigator.params().rtl_alt)];
        let items: &[MissionItem] = match flown {
            FlightMode::Mission => self.gcs.missions().store().items(PlanKind::Mission),
            FlightMode::Takeoff => &takeoff,
            _ => &[],
        };
        let out = self
            .navigator
            .step(items, &home, &NavState::from_estimate(e), dt);
        if flown == FlightMode::Mission {
            let current = out.current_seq.filter(|&c| c != self.mission_seq);
            if let Some(c) = out.current_seq {
                self.mission_seq = c;
            }
            self.gcs.mission_progress(current, out.reached);
            if out.phase == Phase::Complete || out.phase == Phase::Landed {
                self.mission_state = MissionRunState::Complete;
            }
        }
        for w in &out.warnings {
            self.gcs
                .send_statustext(MavSeverity::MAV_SEVERITY_WARNING, w.text());
        }
        if let Some(req) = out.set_home {
            let here = match req {
                HomeRequest::Here => common::estimator::Home {
                    point: e.position,
                    alt_amsl_m: e.alt_amsl_m,
                },
                HomeRequest::At(h) => h,
            };
            self.estimator.set_home(here);
        }
        if out.landed && self.armed {
            self.armed = false;
            self.gcs
                .send_statustext(MavSeverity::MAV_SEVERITY_INFO, "Landed, disarmed");
        }
        let commands = out.commands.map(|c| amsl_commands(c, home.alt_amsl_m));
        self.nav = out;
        commands
    }

    /// Watches the failsafes at the control rate and acts on their reaction.
    fn check_failsafes(&mut self, now_us: u64, e: &EstimatedState) {
        let flying = self.armed && in_air(e);
        let fence_breached = match e.home {
            Some(h) => breached(
                self.gcs.missions().store().items(PlanKind::Fence),
                &h,
                &e.pos_ned,
                &self.fence,
            )
            .is_some(),
            None => false,
        };
        let inputs = FailsafeInputs {
            t_s: now_us as f64 * 1e-6,
            flying,
            gcs_heard_s: self.gcs.gcs_last_seen_us().map(|t| t as f64 * 1e-6),
            gps_ok: e.health.gps.healthy,
            airspeed_ok: e.health.pitot.healthy,
            fence_breached,
        };
        let (reaction, events) = self.failsafes.update(&self.fs_cfg, &inputs);
        for ev in events {
            let sev = if ev.raises() {
                MavSeverity::MAV_SEVERITY_CRITICAL
            } else {
                MavSeverity::MAV_SEVERITY_INFO
            };
            self.gcs.send_statustext(sev, ev.text());
        }
        if reaction == Reaction::WingsLevel && self.wings_level.is_none() {
            self.wings_level = Some(e.alt_amsl_m);
        }
        if reaction != Reaction::WingsLevel {
            self.wings_level = None;
        }
        self.reaction = reaction;
    }

    /// Acts on what the ground station asked for.
    fn apply_requests(&mut self) {
        let r: VehicleRequests = self.gcs.take_requests();
        let e = self.estimator.state();
        if let Some(a) = r.arm {
            if a.arm && !self.armed && !in_air(&e) {
                // Home is where the aircraft is armed, as in PX4: the first fix set it from one
                // GPS altitude (5 m of vertical noise); the estimate at arming has averaged
                // GPS and barometer for as long as the estimator took to converge, and the
                // landing aims at this height.
                if let Some(h) = e.home {
                    let here = common::estimator::Home {
                        point: e.position,
                        alt_amsl_m: e.alt_amsl_m,
                    };
                    if here != h {
                        self.estimator.set_home(here);
                    }
                }
            }
            if a.arm != self.armed {
                self.armed = a.arm;
                if !a.arm {
                    self.navigator.stop();
                    self.nav_for = None;
                    self.failsafes.acknowledge();
                }
                self.gcs.send_statustext(
                    MavSeverity::MAV_SEVERITY_INFO,
                    if a.arm { "Armed" } else { "Disarmed" },
                );
            }
        }
        if let Some(mode) = r.mode {
            if mode != self.mode {
                // Entering a guided mode holds where the aircraft is.
                if matches!(mode, FlightMode::Hold | FlightMode::Altitude)
                    && !matches!(self.mode, FlightMode::Hold | FlightMode::Altitude)
                {
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
                self.navigator.set_current(seq);
            }
        }
        if let Some(alt) = r.altitude {
            let base = if alt.relative_to_home {
                e.home.map(|h| h.alt_amsl_m)
            } else {
                Some(0.0)
            };
            match base {
                Some(b) => self.setpoints.alt_amsl_m = b + alt.alt_m,
                None => self.gcs.send_statustext(
                    MavSeverity::MAV_SEVERITY_WARNING,
                    "Altitude above home refused: no home yet",
                ),
            }
        }
        if let Some(v) = r.airspeed {
            self.setpoints.airspeed = v;
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
            self.setpoints.course = common::math::wrap_two_pi(base + c.angle);
        }
    }

    /// Pushes changed parameters into the stages.
    fn apply_params(&mut self) {
        let count = self.gcs.params().change_count();
        if self.params_seen == Some(count) {
            return;
        }
        self.params_seen = Some(count);
        let store = self.gcs.params();
        // A new gain set overwrites the control parameters with its values.
        let set = store.get("SYS_GAIN_SET").unwrap_or(0.0);
        if set != self.gain_set_seen {
            self.gain_set_seen = set;
            if let Some((_, g, _)) = NAMED.get(set as usize) {
                let values: heapless::Vec<(&str, f32), 64> = g.params().collect();
                for (name, v) in values {
                    let _ = self.gcs.params_mut().set(name, v);
                }
            }
        }
        let store = self.gcs.params();
        match GainSet::from_params(|n| store.get(n)) {
            Ok(g) => {
                if self.autopilot.set_gains(&g).is_err() {
                    self.gcs.send_statustext(
                        MavSeverity::MAV_SEVERITY_WARNING,
                        "Gains refused: inconsistent set, previous kept",
                    );
                }
            }
            Err(_) => self.gcs.send_statustext(
                MavSeverity::MAV_SEVERITY_WARNING,
                "Gains refused: previous set kept",
            ),
        }
        let store = self.gcs.params();
        // Stored values are within their bounds, so no stage refuses them.
        let load = |defs: &[ParamDef], set: &mut dyn FnMut(&str, f32)| {
            for d in defs {
                if let Some(v) = store.get(d.name) {
                    set(d.name, v);
                }
            }
        };
        let mut cfg = *self.estimator.config();
        load(common::estimator::config::PARAMS, &mut |n, v| {
            let _ = cfg.set(n, v);
        });
        self.estimator.set_config(cfg);
        let nav = &mut self.navigator;
        for defs in [
            common::guidance::PARAMS,
            navigation::path_manager::PARAMS,
            navigation::executor::PARAMS,
        ] {
            load(defs, &mut |n, v| {
                let _ = nav.set_param(n, v);
            });
        }
        let limits = &mut self.limits;
        load(navigation::validate::PARAMS, &mut |n, v| {
            let _ = limits.set(n, v);
        });
        let fence = &mut self.fence;
        load(navigation::fence::PARAMS, &mut |n, v| {
            let _ = fence.set(n, v);
        });
        self.fs_cfg = FailsafeConfig::from_params(|n| store.get(n));
        self.use_truth = store.get("SIM_USE_TRUTH").unwrap_or(0.0) >= 0.5;
        if let Some(v) = store.get("FW_AIRSPD_TRIM") {
            if self.params_seen == Some(0) || self.mode == FlightMode::Manual {
                self.setpoints.airspeed = v;
            }
        }
    }

    fn poll_gcs(&mut self, now_us: u64) {
        let e = self.estimator.state();
        let rules = PlanRules {
            home: e.home,
            limits: self.limits,
            nav: *self.navigator.params(),
        };
        self.gcs.missions_mut().set_rules(rules);
        let snapshot = self.snapshot_of(&e);
        let (tx, buf, dropped) = (
            &mut self.gcs_tx,
            &mut self.gcs_out,
            &mut self.health.gcs_bytes_dropped,
        );
        self.gcs.poll(now_us, &snapshot, |msg| {
            let raw = tx.encode(&msg);
            if buf.extend_from_slice(raw.raw_bytes()).is_err() {
                *dropped = dropped.saturating_add(raw.raw_bytes().len() as u32);
            }
        });
    }

    /// What the ground link reports and checks.
    pub fn snapshot(&self) -> VehicleSnapshot {
        self.snapshot_of(&self.estimator.state())
    }

    fn snapshot_of(&self, e: &EstimatedState) -> VehicleSnapshot {
        let h = &e.health;
        let health = SensorHealth {
            gyro_ok: h.imu.healthy,
            accel_ok: h.imu.healthy,
            mag_ok: h.mag.healthy,
            baro_ok: h.baro.healthy,
            airspeed_ok: h.pitot.healthy,
            gps_ok: h.gps.healthy,
            attitude_converged: e.converged,
            position_valid: e.position_valid,
        };
        let home = e.home.map_or(Home::default(), |h| Home {
            valid: true,
            lat_e7: h.point.lat_e7,
            lon_e7: h.point.lon_e7,
            alt_amsl_m: h.alt_amsl_m,
        });
        let gps = self.last_gps.map_or(GpsRaw::default(), |g| {
            let (course, speed) = common::math::course_and_speed(&g.vel_ned);
            GpsRaw {
                time_usec: self.last_time_us.unwrap_or(0),
                fix_type: g.fix_type,
                lat_e7: g.position.lat_e7,
                lon_e7: g.position.lon_e7,
                alt_amsl_m: g.alt_amsl_m,
                hdop: g.hdop,
                vdop: g.hdop * 1.5,
                ground_speed_m_s: speed,
                course: common::math::wrap_two_pi(course),
                satellites: g.satellites,
            }
        });
        let mut modes = ModeSet::EMPTY
            .with(FlightMode::Manual)
            .with(FlightMode::Stabilized);
        if e.converged || e.attitude_valid {
            modes = modes.with(FlightMode::Altitude);
        }
        if e.position_valid {
            modes = modes.with(FlightMode::Hold);
            if home.valid {
                for m in [
                    FlightMode::Mission,
                    FlightMode::Loiter,
                    FlightMode::Return,
                    FlightMode::Takeoff,
                    FlightMode::Land,
                ] {
                    modes = modes.with(m);
                }
            }
        }
        let in_air = in_air(e);
        VehicleSnapshot {
            boot_complete: self.last_time_us.is_some(),
            hil: true,
            armed: self.armed,
            failsafe: self.failsafes.active(),
            mode: self.flown_mode(),
            modes_available: modes,
            landed: if in_air {
                LandedState::InAir
            } else {
                LandedState::OnGround
            },
            health,
            roll: e.euler.phi,
            pitch: e.euler.theta,
            yaw: e.euler.psi,
            roll_rate: e.body_rates.x,
            pitch_rate: e.body_rates.y,
            yaw_rate: e.body_rates.z,
            lat_e7: e.position.lat_e7,
            lon_e7: e.position.lon_e7,
            alt_amsl_m: e.alt_amsl_m,
            alt_rel_home_m: e.alt_amsl_m - home.alt_amsl_m,
            vel_n: e.vel_ned.x,
            vel_e: e.vel_ned.y,
            vel_d: e.vel_ned.z,
            airspeed: e.airspeed,
            throttle: if self.armed {
                self.surfaces.throttle
            } else {
                0.0
            },
            home,
            gps,
            battery: Battery {
                present: false,
                ..Battery::default()
            },
            nav: self.nav_telemetry(e),
            mission_seq: self.mission_seq,
            mission_state: self.mission_state,
            cpu_load: 0.0,
        }
    }
}

impl App {
    /// NAV_CONTROLLER_OUTPUT from the navigator's last step (zeros outside navigation modes).
    fn nav_telemetry(&self, e: &EstimatedState) -> NavTelemetry {
        if !self.flown_mode().needs_navigator() {
            return NavTelemetry::default();
        }
        let finite = |x: f32| if x.is_finite() { x } else { 0.0 };
        let g = self.nav.guidance;
        NavTelemetry {
            roll_cmd: 0.0,
            pitch_cmd: 0.0,
            course_cmd: g.map_or(0.0, |g| common::math::wrap_two_pi(g.course)),
            target_bearing: finite(common::math::wrap_two_pi(self.nav.target_bearing)),
            wp_dist_m: finite(self.nav.wp_dist_m),
            alt_error_m: g.map_or(0.0, |g| finite(g.altitude + e.pos_ned.z)),
            airspeed_error_m_s: g.map_or(0.0, |g| finite(g.airspeed - e.airspeed)),
            xtrack_error_m: g.map_or(0.0, |g| finite(g.cross_track)),
        }
    }
}

/// Armed flight is told from the ground by airspeed and height (there is no weight-on-wheels
/// switch): above 8 m/s and 5 m above home.
fn in_air(e: &EstimatedState) -> bool {
    let height = e.home.map_or(0.0, |h| e.alt_amsl_m - h.alt_amsl_m);
    e.airspeed > 8.0 && height > 5.0
}

/// The navigator's commands carry heights above home; the autopilot flies altitudes above
/// mean sea level (the estimator's datum).
fn amsl_commands(mut c: Commands, home_alt_amsl_m: f32) -> Commands {
    c.lon = c.lon.shifted(home_alt_amsl_m);
    c
}

/// The Takeoff mode's one item: climb out along the present heading to the return altitude.
fn takeoff_item(height_m: f32) -> MissionItem {
    MissionItem {
        params: [0, 0, 0, f32::NAN.to_bits()],
        x: 0,
        y: 0,
        z: height_m.to_bits(),
        command: mavlink::dialects::common::MavCmd::MAV_CMD_NAV_TAKEOFF as u16,
        frame: mavlink::dialects::common::MavFrame::MAV_FRAME_GLOBAL_RELATIVE_ALT as u8,
        autocontinue: true,
    }
}

fn trim_surfaces(g: &GainSet) -> Surfaces {
    Surfaces {
        elevator: g.longitudinal.trim_elevator,
        aileron: g.lateral.trim_aileron,
        rudder: g.lateral.trim_rudder,
        throttle: g.longitudinal.trim_throttle,
    }
}

/// Truth as the autopilot's measurements (`HIL_STATE_QUATERNION`: attitude quaternion, body
/// rates, altitude in mm, velocity in cm/s, true airspeed in cm/s).
fn truth_measurements(
    d: &mavlink::dialects::common::HIL_STATE_QUATERNION_DATA,
) -> Option<Measurements> {
    let q = d.attitude_quaternion;
    if q.iter().any(|x| !x.is_finite()) {
        return None;
    }
    let uq =
        nalgebra::UnitQuaternion::try_new(nalgebra::Quaternion::new(q[0], q[1], q[2], q[3]), 1e-6)?;
    let e = common::math::Euler::from_quaternion(&uq);
    let v = nalgebra::Vector3::new(f32::from(d.vx), f32::from(d.vy), f32::from(d.vz)) / 100.0;
    let (chi, vg) = common::math::course_and_speed(&v);
    let course = if vg > 3.0 { chi } else { e.psi };
    Some(Measurements {
        roll: e.phi,
        pitch: e.theta,
        course,
        roll_rate: d.rollspeed,
        pitch_rate: d.pitchspeed,
        yaw_rate: d.yawspeed,
        altitude: d.alt as f32 / 1000.0,
        airspeed: f32::from(d.true_airspeed) / 100.0,
        sideslip: 0.0,
    })
}

/// A heartbeat frame of the autopilot on its simulator link (the ground link's heartbeat, so
/// both links describe the vehicle the same way).
pub fn heartbeat_frame(app: &mut App) -> heapless::Vec<u8, 280> {
    let msg = common::gcs::telemetry::heartbeat(&app.snapshot());
    let raw = app.sim_tx.encode(&msg);
    heapless::Vec::from_slice(raw.raw_bytes()).unwrap_or_default()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_registry_builds_and_every_name_is_unique() {
        assert!(GroundLink::new(REGISTRY).is_ok());
        assert!(common::params::validate_defs(PARAMS).is_ok());
    }

    extern crate std;
    use common::link::simlink::{encode_hil_sensor, SensorFrame};
    use common::sensors::ImuSample;
    use mavlink::dialects::common::MANUAL_CONTROL_DATA;
    use std::vec::Vec;

    fn sensor_frame(k: u64) -> Vec<u8> {
        let f = SensorFrame {
            time_us: k * 10_000,
            imu: Some(ImuSample {
                accel: nalgebra::Vector3::new(0.0, 0.0, -9.8),
                gyro: nalgebra::Vector3::zeros(),
            }),
            ..Default::default()
        };
        let mut sim = Sender::new(1, 51);
        sim.encode(&MavMessage::HIL_SENSOR(encode_hil_sensor(&f, 0.0)))
            .raw_bytes()
            .to_vec()
    }

    fn actuators(app: &mut App, k: u64) -> [f32; 16] {
        let mut out = Vec::new();
        app.on_sim_bytes(&sensor_frame(k), &mut |b| out.extend_from_slice(b));
        let mut p = FrameParser::new();
        let mut controls = [f32::NAN; 16];
        p.push(&out, |f| {
            if let MavMessage::HIL_ACTUATOR_CONTROLS(d) = f.message {
                controls = d.controls;
            }
        });
        controls
    }

    #[test]
    fn manual_mode_passes_the_sticks_through() {
        let mut app = App::new();
        assert_eq!(app.mode(), FlightMode::Manual);
        // No stick yet: the trim (UMN elevator -0.0963 rad is nose-up: positive PX4 pitch).
        let c = actuators(&mut app, 0);
        assert!(c[1] > 0.0 && c[1] < 0.3, "{c:?}");
        // Full right roll, half nose-up (stick back is negative x), some right yaw.
        let mut gcs = Sender::new(255, 190);
        let stick = MavMessage::MANUAL_CONTROL(MANUAL_CONTROL_DATA {
            x: -500,
            y: 1000,
            z: 600,
            r: 250,
            target: 1,
            ..Default::default()
        });
        app.on_gcs_bytes(gcs.encode(&stick).raw_bytes());
        // The next control tick (50 Hz: the frame at 20 ms) applies them.
        let c = actuators(&mut app, 2);
        assert!(
            (c[0] - 1.0).abs() < 1e-5 && (c[1] - 0.5).abs() < 1e-5,
            "{c:?}"
        );
        assert!((c[2] - 0.25).abs() < 1e-5, "{c:?}");
        // Disarmed: no throttle reaches the motor whatever the stick says.
        assert_eq!(c[3], 0.0);
        // Sticks that stop arriving fall back to the trim.
        let c = actuators(&mut app, 80);
        assert!(c[0].abs() < 0.1, "{c:?}");
    }

    #[test]
    fn the_application_fits_the_stm32f405_ram_with_room_for_the_stack() {
        // 128 KiB of SRAM: the whole application state must leave most of it to the stack.
        assert!(
            core::mem::size_of::<App>() < 40 * 1024,
            "{}",
            core::mem::size_of::<App>()
        );
    }
}
