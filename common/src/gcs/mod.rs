//! The ground-station link: what QGroundControl, MAVSDK and pymavlink see of the autopilot.
//!
//! [`GroundLink`] is transport-agnostic logic: the firmware decodes frames with the `mavlink`
//! crate, hands each message to [`GroundLink::handle`], and calls [`GroundLink::poll`] every
//! tick to collect the answers and telemetry to encode and send. The link never acts on the
//! vehicle itself: mode and arming requests it accepted wait in [`VehicleRequests`] for the
//! vehicle to take with [`GroundLink::take_requests`]; the heartbeat always reports the state
//! the vehicle says it is in ([`VehicleSnapshot`]), never what was asked.
//!
//! Identity: system 1, component 1, `MAV_TYPE_FIXED_WING`, `MAV_AUTOPILOT_GENERIC`; modes in
//! PX4's `custom_mode` encoding (see [`modes`]). `docs/GROUND-STATION.md` describes the
//! behaviour a ground station sees.

pub mod client;
pub mod mission;
pub mod modes;
pub mod param_store;
pub mod snapshot;
pub mod streams;
pub mod telemetry;

#[cfg(test)]
mod tests;

use core::fmt::Write;

use crate::navigation::ValidationWarning;
use heapless::{Deque, String};
use mavlink::dialects::common::*;
use mavlink::{MavHeader, Message};
use num_traits::FromPrimitive;

use crate::params::{ParamError, ParamKind};
use mission::{MissionManager, MissionReply, PlanKind};
use modes::FlightMode;
use param_store::{encode_wire, param_id_str, ParamStore, Registry, RegistryError};
use snapshot::{LandedState, VehicleSnapshot};
use streams::{Scheduler, Stream};

pub use mission::MissionItem;
pub use modes::ModeSet;

/// Our MAVLink system id.
pub const SYSTEM_ID: u8 = 1;
/// Our MAVLink component id (`MAV_COMP_ID_AUTOPILOT1`).
pub const COMPONENT_ID: u8 = 1;
/// `param2` of `MAV_CMD_COMPONENT_ARM_DISARM` that skips the checks (MAVLink's magic number).
pub const FORCE_ARM_MAGIC: f32 = 21196.0;
/// Heartbeat interval, µs (1 Hz; QGC drops a vehicle after 3.5 s of silence).
pub const HEARTBEAT_INTERVAL_US: u64 = 1_000_000;
/// Longest STATUSTEXT text.
pub const STATUSTEXT_LEN: usize = 50;

const PENDING_CAPACITY: usize = 32;
const TEXT_CAPACITY: usize = 8;

/// Settings of a link.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LinkConfig {
    /// Our system id.
    pub system_id: u8,
    /// Our component id.
    pub component_id: u8,
    /// `PARAM_VALUE`s sent per [`GroundLink::poll`] while streaming the list: paces a full
    /// download to the link's bandwidth (a 50 Hz loop with 4 per poll sends 200 per second).
    pub params_per_poll: u8,
    /// Hardware unique id reported in `AUTOPILOT_VERSION` (0 when unknown).
    pub uid: u64,
}

impl Default for LinkConfig {
    fn default() -> Self {
        Self {
            system_id: SYSTEM_ID,
            component_id: COMPONENT_ID,
            params_per_poll: 4,
            uid: 0,
        }
    }
}

/// An arming or disarming request the link accepted.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ArmRequest {
    /// `true` to arm, `false` to disarm.
    pub arm: bool,
    /// Forced (param2 = 21196): checks skipped, disarm even in the air.
    pub forced: bool,
}

/// What the ground station asked the vehicle to do, after the link's checks. The vehicle takes
/// these with [`GroundLink::take_requests`] and acts on them.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct VehicleRequests {
    /// Arm or disarm.
    pub arm: Option<ArmRequest>,
    /// Switch to this mode.
    pub mode: Option<FlightMode>,
    /// Make this mission item the current one.
    pub mission_seq: Option<u16>,
    /// Persist the parameters now (`MAV_CMD_PREFLIGHT_STORAGE` write).
    pub save_params: bool,
    /// New altitude setpoint (`MAV_CMD_DO_CHANGE_ALTITUDE`).
    pub altitude: Option<AltitudeSetpoint>,
    /// New airspeed setpoint, m/s (`MAV_CMD_DO_CHANGE_SPEED`, airspeed type).
    pub airspeed: Option<f32>,
    /// New course setpoint, rad in [0, 2 pi) (`MAV_CMD_CONDITION_YAW`, absolute or relative).
    pub course: Option<CourseSetpoint>,
    /// The latest stick positions (`MANUAL_CONTROL`: QGC's virtual joystick or a gamepad).
    pub manual: Option<ManualInput>,
}

/// Stick positions from a ground station, normalised.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ManualInput {
    /// Roll stick, -1..1, positive right.
    pub roll: f32,
    /// Pitch stick, -1..1, positive nose up (stick back; MANUAL_CONTROL's x is forward).
    pub pitch: f32,
    /// Yaw stick, -1..1, positive nose right.
    pub yaw: f32,
    /// Throttle, 0..1.
    pub throttle: f32,
    /// When it arrived, us.
    pub time_us: u64,
}

/// An altitude the ground station asked for.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct AltitudeSetpoint {
    /// Altitude, m.
    pub alt_m: f32,
    /// `true`: above home (`MAV_FRAME_GLOBAL_RELATIVE_ALT`); `false`: above mean sea level.
    pub relative_to_home: bool,
}

/// A course the ground station asked for.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct CourseSetpoint {
    /// Angle, rad.
    pub angle: f32,
    /// `true`: added to the current course (direction already applied); `false`: absolute.
    pub relative: bool,
}

/// Airspeeds a setpoint may ask for, m/s (the Ultra Stick's envelope with margin).
pub const AIRSPEED_SETPOINT_RANGE: (f32, f32) = (10.0, 30.0);

/// A STATUSTEXT waiting to be sent.
#[derive(Clone, Debug, PartialEq)]
struct Text {
    severity: MavSeverity,
    text: String<STATUSTEXT_LEN>,
}

/// Something to send at the next poll.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Pending {
    Ack {
        command: MavCmd,
        result: MavResult,
        to: (u8, u8),
    },
    ParamValue(u16),
    Mission(MissionReply, (u8, u8)),
    MissionCurrent(Option<u16>),
    ItemReached(u16),
    AutopilotVersion,
    AvailableMode(u8),
    CurrentMode,
    Heartbeat,
    Stream(Stream),
    MessageInterval {
        id: u16,
        interval_us: i32,
    },
}

/// Messages that follow a COMMAND_ACK (at most one per mode for AVAILABLE_MODES).
type After = heapless::Vec<Pending, { FlightMode::ALL.len() }>;

/// A command from `COMMAND_LONG` or `COMMAND_INT`, params 5 and 6 as floats.
#[derive(Clone, Copy, Debug)]
struct Command {
    cmd: MavCmd,
    p: [f32; 7],
}

/// The ground-station link state machine.
#[derive(Clone, Debug)]
pub struct GroundLink {
    cfg: LinkConfig,
    params: ParamStore,
    missions: MissionManager,
    streams: Scheduler,
    pending: Deque<Pending, PENDING_CAPACITY>,
    texts: Deque<Text, TEXT_CAPACITY>,
    requests: VehicleRequests,
    param_next: Option<u16>,
    next_heartbeat_us: u64,
    gcs_last_seen_us: Option<u64>,
    last_mode: Option<FlightMode>,
    dropped: u32,
    rx_errors: u16,
}

impl GroundLink {
    /// A link with the default identity serving the parameters of `registry`.
    pub fn new(registry: Registry) -> Result<Self, RegistryError> {
        Self::with_config(registry, LinkConfig::default())
    }

    /// A link with explicit settings.
    pub fn with_config(registry: Registry, cfg: LinkConfig) -> Result<Self, RegistryError> {
        Ok(Self {
            cfg,
            params: ParamStore::new(registry)?,
            missions: MissionManager::new(),
            streams: Scheduler::new(),
            pending: Deque::new(),
            texts: Deque::new(),
            requests: VehicleRequests::default(),
            param_next: None,
            next_heartbeat_us: 0,
            gcs_last_seen_us: None,
            last_mode: None,
            dropped: 0,
            rx_errors: 0,
        })
    }

    /// The parameter store (read values by name or index).
    pub fn params(&self) -> &ParamStore {
        &self.params
    }

    /// The parameter store, writable (loading from flash, marking saved).
    pub fn params_mut(&mut self) -> &mut ParamStore {
        &mut self.params
    }

    /// Mission, fence and rally storage and protocol state.
    pub fn missions(&self) -> &MissionManager {
        &self.missions
    }

    /// Mission storage, writable (loading from flash).
    pub fn missions_mut(&mut self) -> &mut MissionManager {
        &mut self.missions
    }

    /// The telemetry scheduler.
    pub fn streams(&self) -> &Scheduler {
        &self.streams
    }

    /// Takes the requests accepted since the last call.
    pub fn take_requests(&mut self) -> VehicleRequests {
        core::mem::take(&mut self.requests)
    }

    /// Time the last ground-station heartbeat arrived, µs (for a link-loss failsafe).
    pub fn gcs_last_seen_us(&self) -> Option<u64> {
        self.gcs_last_seen_us
    }

    /// Outgoing messages dropped because the output queues were full.
    pub fn dropped(&self) -> u32 {
        self.dropped
    }

    /// Counts a frame the transport could not decode (reported in `SYS_STATUS.errors_comm`).
    pub fn note_rx_error(&mut self) {
        self.rx_errors = self.rx_errors.saturating_add(1);
    }

    /// Queues a STATUSTEXT (event messages from the vehicle: failsafes, mode changes, ...).
    /// Text longer than 50 bytes is cut; when the queue is full the message is dropped and
    /// counted in [`GroundLink::dropped`].
    pub fn send_statustext(&mut self, severity: MavSeverity, text: &str) {
        let mut s = String::new();
        for c in text.chars() {
            if s.push(c).is_err() {
                break;
            }
        }
        self.queue_text(severity, s);
    }

    fn queue_text(&mut self, severity: MavSeverity, text: String<STATUSTEXT_LEN>) {
        if self.texts.push_back(Text { severity, text }).is_err() {
            self.dropped = self.dropped.wrapping_add(1);
        }
    }

    /// Says what an accepted mission will do differently from what its reader may expect.
    fn mission_warning(&mut self, w: ValidationWarning) {
        self.textf(MavSeverity::MAV_SEVERITY_WARNING, format_args!("{w}"));
    }

    fn textf(&mut self, severity: MavSeverity, args: core::fmt::Arguments<'_>) {
        let mut s: String<STATUSTEXT_LEN> = String::new();
        // A text that does not fit is cut, never refused.
        let _ = s.write_fmt(args);
        self.queue_text(severity, s);
    }

    fn push(&mut self, p: Pending) {
        if self.pending.push_back(p).is_err() {
            self.dropped = self.dropped.wrapping_add(1);
        }
    }

    /// Consumes one message from the ground station. Messages addressed to another system or
    /// component, and our own echoes, are ignored.
    // SET_MODE, MISSION_REQUEST, MISSION_SET_CURRENT and MISSION_ITEM are deprecated but still
    // sent by pymavlink and older ground stations; answering them is part of compatibility.
    #[allow(deprecated)]
    pub fn handle(
        &mut self,
        header: &MavHeader,
        msg: &MavMessage,
        now_us: u64,
        vehicle: &VehicleSnapshot,
    ) {
        let Ok(sys) = u8::try_from(header.system_id) else {
            return;
        };
        if sys == self.cfg.system_id && header.component_id == self.cfg.component_id {
            return;
        }
        if let Some(t) = msg.target_system_id() {
            if t != 0 && t != self.cfg.system_id {
                return;
            }
        }
        if let Some(c) = msg.target_component_id() {
            if c != 0 && c != self.cfg.component_id {
                return;
            }
        }
        let from = (sys, header.component_id);
        match msg {
            MavMessage::HEARTBEAT(h) if h.mavtype == MavType::MAV_TYPE_GCS => {
                self.gcs_last_seen_us = Some(now_us);
            }
            MavMessage::PARAM_REQUEST_LIST(_) => {
                // A new request restarts the stream: every index once, in order.
                self.param_next = Some(0);
            }
            MavMessage::PARAM_REQUEST_READ(d) => {
                let index = if d.param_index < 0 {
                    param_id_str(&d.param_id[..]).and_then(|n| self.params.index_of(n))
                } else {
                    Some(d.param_index as usize).filter(|&i| i < self.params.len())
                };
                if let Some(i) = index {
                    self.push(Pending::ParamValue(i as u16));
                }
            }
            MavMessage::PARAM_SET(d) => self.on_param_set(d),
            MavMessage::MANUAL_CONTROL(d) => {
                // Axes are -1000..1000 (throttle 0..1000); INT16_MAX marks an axis as unused.
                let axis = |v: i16| {
                    if v == i16::MAX {
                        0.0
                    } else {
                        (f32::from(v) / 1000.0).clamp(-1.0, 1.0)
                    }
                };
                self.requests.manual = Some(ManualInput {
                    roll: axis(d.y),
                    pitch: -axis(d.x),
                    yaw: axis(d.r),
                    throttle: axis(d.z).clamp(0.0, 1.0),
                    time_us: now_us,
                });
            }
            MavMessage::COMMAND_LONG(d) => {
                let c = Command {
                    cmd: d.command,
                    p: [
                        d.param1, d.param2, d.param3, d.param4, d.param5, d.param6, d.param7,
                    ],
                };
                self.on_command(c, from, now_us, vehicle);
            }
            MavMessage::COMMAND_INT(d) => {
                let c = Command {
                    cmd: d.command,
                    p: [
                        d.param1, d.param2, d.param3, d.param4, d.x as f32, d.y as f32, d.z,
                    ],
                };
                self.on_command(c, from, now_us, vehicle);
            }
            MavMessage::SET_MODE(d) => {
                // PX4 treats SET_MODE as MAV_CMD_DO_SET_MODE and acknowledges it as such.
                let result = if d
                    .base_mode
                    .contains(MavModeFlag::MAV_MODE_FLAG_CUSTOM_MODE_ENABLED)
                {
                    match FlightMode::from_custom_mode(d.custom_mode) {
                        Some(m) => self.request_mode(m, vehicle),
                        None => self.unknown_mode(d.custom_mode),
                    }
                } else {
                    self.textf(
                        MavSeverity::MAV_SEVERITY_WARNING,
                        format_args!("Mode refused: only custom modes"),
                    );
                    MavResult::MAV_RESULT_DENIED
                };
                self.ack(MavCmd::MAV_CMD_DO_SET_MODE, result, from);
            }
            MavMessage::MISSION_COUNT(d) => {
                let r = self
                    .missions
                    .on_count(d.mission_type, d.count, from, now_us);
                self.push(Pending::Mission(r, from));
            }
            MavMessage::MISSION_ITEM_INT(d) => {
                if let Some(r) = self.missions.on_item(d, from, now_us) {
                    self.push(Pending::Mission(r, from));
                }
                for w in self.missions.take_warnings() {
                    self.mission_warning(w);
                }
            }
            // Float items lose precision; this autopilot asks for MISSION_ITEM_INT only.
            MavMessage::MISSION_ITEM(d) if self.missions.busy() => {
                self.missions.on_ack(d.mission_type, from);
                self.push(Pending::Mission(
                    MissionReply::Ack(d.mission_type, MavMissionResult::MAV_MISSION_UNSUPPORTED),
                    from,
                ));
            }
            MavMessage::MISSION_REQUEST_LIST(d) => {
                let r = self.missions.on_request_list(d.mission_type, from, now_us);
                self.push(Pending::Mission(r, from));
            }
            MavMessage::MISSION_REQUEST_INT(d) => {
                let r = self
                    .missions
                    .on_request(d.mission_type, d.seq, from, now_us);
                self.push(Pending::Mission(r, from));
            }
            MavMessage::MISSION_REQUEST(d) => {
                // Legacy request: answered with MISSION_ITEM_INT all the same.
                let r = self
                    .missions
                    .on_request(d.mission_type, d.seq, from, now_us);
                self.push(Pending::Mission(r, from));
            }
            MavMessage::MISSION_ACK(d) => self.missions.on_ack(d.mission_type, from),
            MavMessage::MISSION_CLEAR_ALL(d) => {
                let r = self.missions.on_clear(d.mission_type);
                self.push(Pending::Mission(r, from));
            }
            MavMessage::MISSION_SET_CURRENT(d) => {
                // The message has no ACK: a bad index gets a STATUSTEXT and the current item.
                let ok = self.set_mission_current(d.seq);
                if !ok {
                    self.push(Pending::MissionCurrent(None));
                }
            }
            _ => {}
        }
    }

    fn ack(&mut self, command: MavCmd, result: MavResult, to: (u8, u8)) {
        self.push(Pending::Ack {
            command,
            result,
            to,
        });
    }

    fn on_param_set(&mut self, d: &PARAM_SET_DATA) {
        let Some(name) = param_id_str(&d.param_id[..]) else {
            return;
        };
        let Some(index) = self.params.index_of(name) else {
            self.textf(
                MavSeverity::MAV_SEVERITY_WARNING,
                format_args!("Param {}: unknown", name),
            );
            return;
        };
        let Some(def) = self.params.def(index) else {
            return;
        };
        let int_types = matches!(
            d.param_type,
            MavParamType::MAV_PARAM_TYPE_INT32
                | MavParamType::MAV_PARAM_TYPE_UINT8
                | MavParamType::MAV_PARAM_TYPE_INT8
                | MavParamType::MAV_PARAM_TYPE_UINT16
                | MavParamType::MAV_PARAM_TYPE_INT16
        );
        let candidate = match (def.kind, d.param_type) {
            (ParamKind::Real, MavParamType::MAV_PARAM_TYPE_REAL32) => Ok(d.param_value),
            // Bytewise encoding: the integer's bytes travel in the float field.
            (ParamKind::Int, _) if int_types => Ok(d.param_value.to_bits() as i32 as f32),
            // Tools that send every value as REAL32 (pymavlink's default) may set an
            // integer parameter with a whole number.
            (ParamKind::Int, MavParamType::MAV_PARAM_TYPE_REAL32) => Ok(d.param_value),
            _ => Err("wrong type"),
        };
        let result = candidate.and_then(|v| {
            self.params.set_index(index, v).map_err(|e| match e {
                ParamError::NotFinite => "not a finite number",
                ParamError::OutOfBounds => "out of bounds",
                ParamError::NotInteger => "not an integer",
                ParamError::Unknown => "unknown",
            })
        });
        if let Err(why) = result {
            self.textf(
                MavSeverity::MAV_SEVERITY_WARNING,
                format_args!("Param {} refused: {} [{}, {}]", name, why, def.min, def.max),
            );
        }
        // The echo carries the value now stored, changed or not.
        self.push(Pending::ParamValue(index as u16));
    }

    // GET_MESSAGE_INTERVAL and REQUEST_AUTOPILOT_CAPABILITIES are superseded by
    // REQUEST_MESSAGE but QGC and MAVSDK versions in use still send them.
    #[allow(deprecated)]
    fn on_command(&mut self, c: Command, from: (u8, u8), now_us: u64, v: &VehicleSnapshot) {
        let mut after = After::new();
        let result = match c.cmd {
            MavCmd::MAV_CMD_COMPONENT_ARM_DISARM => self.arm_disarm(&c, v),
            MavCmd::MAV_CMD_DO_SET_MODE => {
                let base = c.p[0] as u32;
                if base & MavModeFlag::MAV_MODE_FLAG_CUSTOM_MODE_ENABLED.bits() as u32 == 0 {
                    self.textf(
                        MavSeverity::MAV_SEVERITY_WARNING,
                        format_args!("Mode refused: only custom modes"),
                    );
                    MavResult::MAV_RESULT_DENIED
                } else {
                    let (main, sub) = (c.p[1] as u8, c.p[2] as u8);
                    match FlightMode::from_px4(main, sub) {
                        Some(m) => self.request_mode(m, v),
                        None => self.unknown_mode((u32::from(main) << 16) | (u32::from(sub) << 24)),
                    }
                }
            }
            MavCmd::MAV_CMD_DO_SET_STANDARD_MODE => {
                match MavStandardMode::from_u32(c.p[0] as u32).and_then(FlightMode::from_standard) {
                    Some(m) => self.request_mode(m, v),
                    None => {
                        self.textf(
                            MavSeverity::MAV_SEVERITY_WARNING,
                            format_args!("Standard mode {} not supported", c.p[0] as u32),
                        );
                        MavResult::MAV_RESULT_FAILED
                    }
                }
            }
            MavCmd::MAV_CMD_MISSION_START => {
                let r = self.request_mode(FlightMode::Mission, v);
                let first = c.p[0];
                if r == MavResult::MAV_RESULT_ACCEPTED
                    && first >= 1.0
                    && (first as usize) < self.missions.store().mission.len()
                {
                    self.requests.mission_seq = Some(first as u16);
                }
                r
            }
            MavCmd::MAV_CMD_NAV_RETURN_TO_LAUNCH => self.request_mode(FlightMode::Return, v),
            MavCmd::MAV_CMD_NAV_TAKEOFF => self.request_mode(FlightMode::Takeoff, v),
            MavCmd::MAV_CMD_NAV_LAND => self.request_mode(FlightMode::Land, v),
            MavCmd::MAV_CMD_DO_SET_MISSION_CURRENT => {
                let seq = c.p[0];
                if (0.0..65536.0).contains(&seq) && self.set_mission_current(seq as u16) {
                    MavResult::MAV_RESULT_ACCEPTED
                } else {
                    MavResult::MAV_RESULT_DENIED
                }
            }
            MavCmd::MAV_CMD_DO_CHANGE_ALTITUDE => {
                // param1 altitude, param2 frame (MAV_FRAME_GLOBAL = 0 or GLOBAL_RELATIVE_ALT = 3).
                let frame = c.p[1] as i32;
                if !c.p[0].is_finite() || !(-500.0..=10_000.0).contains(&c.p[0]) {
                    MavResult::MAV_RESULT_DENIED
                } else if frame != 0 && frame != 3 {
                    MavResult::MAV_RESULT_UNSUPPORTED
                } else {
                    self.requests.altitude = Some(AltitudeSetpoint {
                        alt_m: c.p[0],
                        relative_to_home: frame == 3,
                    });
                    MavResult::MAV_RESULT_ACCEPTED
                }
            }
            MavCmd::MAV_CMD_DO_CHANGE_SPEED => {
                // param1 speed type (0 or 1: airspeed), param2 speed, -1 / -2: no change.
                let (lo, hi) = AIRSPEED_SETPOINT_RANGE;
                if c.p[1] == -1.0 || c.p[1] == -2.0 {
                    MavResult::MAV_RESULT_ACCEPTED
                } else if c.p[0] as i32 > 1 {
                    MavResult::MAV_RESULT_UNSUPPORTED
                } else if !(lo..=hi).contains(&c.p[1]) {
                    self.textf(
                        MavSeverity::MAV_SEVERITY_WARNING,
                        format_args!("Airspeed {} refused: outside [{}, {}] m/s", c.p[1], lo, hi),
                    );
                    MavResult::MAV_RESULT_DENIED
                } else {
                    self.requests.airspeed = Some(c.p[1]);
                    MavResult::MAV_RESULT_ACCEPTED
                }
            }
            MavCmd::MAV_CMD_CONDITION_YAW => {
                // param1 angle deg, param3 direction (-1 ccw, 1 cw) when relative, param4 1 = relative.
                let relative = c.p[3] as i32 == 1;
                if !c.p[0].is_finite() || !(0.0..=360.0).contains(&c.p[0]) {
                    MavResult::MAV_RESULT_DENIED
                } else {
                    let sign = if relative && c.p[2] < 0.0 { -1.0 } else { 1.0 };
                    self.requests.course = Some(CourseSetpoint {
                        angle: sign * c.p[0].to_radians(),
                        relative,
                    });
                    MavResult::MAV_RESULT_ACCEPTED
                }
            }
            MavCmd::MAV_CMD_SET_MESSAGE_INTERVAL => {
                match message_id(c.p[0]) {
                    Some(0) => MavResult::MAV_RESULT_DENIED, // the heartbeat stays at 1 Hz
                    Some(id) => match Stream::from_message_id(id) {
                        Some(s) => {
                            self.streams.set_interval(s, c.p[1], now_us);
                            MavResult::MAV_RESULT_ACCEPTED
                        }
                        None => MavResult::MAV_RESULT_UNSUPPORTED,
                    },
                    None => MavResult::MAV_RESULT_DENIED,
                }
            }
            MavCmd::MAV_CMD_GET_MESSAGE_INTERVAL => match message_id(c.p[0]) {
                Some(id) => {
                    let interval_us = if id == 0 {
                        HEARTBEAT_INTERVAL_US as i32
                    } else {
                        match Stream::from_message_id(id) {
                            Some(s) => self
                                .streams
                                .interval_us(s)
                                .map_or(-1, |i| i.min(i32::MAX as u32) as i32),
                            None => 0,
                        }
                    };
                    let _ = after.push(Pending::MessageInterval {
                        id: id as u16,
                        interval_us,
                    });
                    MavResult::MAV_RESULT_ACCEPTED
                }
                None => MavResult::MAV_RESULT_DENIED,
            },
            MavCmd::MAV_CMD_REQUEST_MESSAGE => {
                let (r, p) = self.request_message(&c, v);
                after = p;
                r
            }
            MavCmd::MAV_CMD_REQUEST_AUTOPILOT_CAPABILITIES => {
                let _ = after.push(Pending::AutopilotVersion);
                MavResult::MAV_RESULT_ACCEPTED
            }
            MavCmd::MAV_CMD_PREFLIGHT_STORAGE => match c.p[0] as i32 {
                1 => {
                    self.requests.save_params = true;
                    MavResult::MAV_RESULT_ACCEPTED
                }
                2 if v.armed => MavResult::MAV_RESULT_DENIED,
                2 => {
                    self.params.reset_to_defaults();
                    self.requests.save_params = true;
                    MavResult::MAV_RESULT_ACCEPTED
                }
                _ => MavResult::MAV_RESULT_UNSUPPORTED,
            },
            _ => MavResult::MAV_RESULT_UNSUPPORTED,
        };
        self.ack(c.cmd, result, from);
        for p in after {
            self.push(p);
        }
    }

    /// `MAV_CMD_REQUEST_MESSAGE`: the result and, when accepted, what to send after the ACK.
    fn request_message(&mut self, c: &Command, v: &VehicleSnapshot) -> (MavResult, After) {
        let mut after = After::new();
        let Some(id) = message_id(c.p[0]) else {
            return (MavResult::MAV_RESULT_DENIED, after);
        };
        let one = match id {
            0 => Some(Pending::Heartbeat),
            148 => Some(Pending::AutopilotVersion),
            436 => Some(Pending::CurrentMode),
            435 => {
                let n = FlightMode::ALL.len();
                let index = c.p[1];
                if index == 0.0 {
                    // 0 asks for every mode.
                    for i in 0..n {
                        let _ = after.push(Pending::AvailableMode(i as u8));
                    }
                    return (MavResult::MAV_RESULT_ACCEPTED, after);
                } else if index >= 1.0 && index <= n as f32 && libm::truncf(index) == index {
                    Some(Pending::AvailableMode(index as u8 - 1))
                } else {
                    return (MavResult::MAV_RESULT_DENIED, after);
                }
            }
            _ => match Stream::from_message_id(id) {
                Some(Stream::HomePosition) if !v.home.valid => {
                    return (MavResult::MAV_RESULT_TEMPORARILY_REJECTED, after)
                }
                Some(s) => Some(Pending::Stream(s)),
                None => return (MavResult::MAV_RESULT_UNSUPPORTED, after),
            },
        };
        if let Some(p) = one {
            let _ = after.push(p);
        }
        (MavResult::MAV_RESULT_ACCEPTED, after)
    }

    fn arm_disarm(&mut self, c: &Command, v: &VehicleSnapshot) -> MavResult {
        let arm = c.p[0] > 0.5;
        let forced = (c.p[1] - FORCE_ARM_MAGIC).abs() < 0.5;
        if arm {
            if v.armed {
                return MavResult::MAV_RESULT_ACCEPTED;
            }
            if !forced {
                if !v.boot_complete {
                    self.textf(
                        MavSeverity::MAV_SEVERITY_CRITICAL,
                        format_args!("Arming denied: system still starting"),
                    );
                    return MavResult::MAV_RESULT_TEMPORARILY_REJECTED;
                }
                if let Some(why) = telemetry::prearm_failure(v) {
                    self.textf(
                        MavSeverity::MAV_SEVERITY_CRITICAL,
                        format_args!("Arming denied: {}", why),
                    );
                    return MavResult::MAV_RESULT_DENIED;
                }
            }
        } else {
            if !v.armed {
                return MavResult::MAV_RESULT_ACCEPTED;
            }
            let flying = matches!(
                v.landed,
                LandedState::InAir | LandedState::Takeoff | LandedState::Landing
            );
            if flying && !forced {
                self.textf(
                    MavSeverity::MAV_SEVERITY_CRITICAL,
                    format_args!("Disarming denied: not landed"),
                );
                return MavResult::MAV_RESULT_DENIED;
            }
        }
        self.requests.arm = Some(ArmRequest { arm, forced });
        MavResult::MAV_RESULT_ACCEPTED
    }

    fn unknown_mode(&mut self, custom_mode: u32) -> MavResult {
        self.textf(
            MavSeverity::MAV_SEVERITY_WARNING,
            format_args!(
                "Mode {}.{} not supported",
                (custom_mode >> 16) & 0xff,
                custom_mode >> 24
            ),
        );
        MavResult::MAV_RESULT_FAILED
    }

    /// Checks a mode change and, when possible, queues it for the vehicle.
    fn request_mode(&mut self, mode: FlightMode, v: &VehicleSnapshot) -> MavResult {
        if mode == FlightMode::Mission && self.missions.store().mission.is_empty() {
            self.textf(
                MavSeverity::MAV_SEVERITY_WARNING,
                format_args!("Mode Mission refused: no mission"),
            );
            return MavResult::MAV_RESULT_DENIED;
        }
        if mode == FlightMode::Return && !v.home.valid {
            self.textf(
                MavSeverity::MAV_SEVERITY_WARNING,
                format_args!("Mode Return refused: no home position"),
            );
            return MavResult::MAV_RESULT_TEMPORARILY_REJECTED;
        }
        if !v.modes_available.contains(mode) {
            let why = if mode.needs_position() && !v.health.position_valid {
                "no position estimate"
            } else {
                "not available now"
            };
            self.textf(
                MavSeverity::MAV_SEVERITY_WARNING,
                format_args!("Mode {} refused: {}", mode.name(), why),
            );
            return MavResult::MAV_RESULT_TEMPORARILY_REJECTED;
        }
        self.requests.mode = Some(mode);
        MavResult::MAV_RESULT_ACCEPTED
    }

    /// The vehicle's mission progress: a new current item (MISSION_CURRENT at once, besides
    /// the 1 Hz stream) and an item finished (MISSION_ITEM_REACHED), as PX4 reports them.
    pub fn mission_progress(&mut self, current: Option<u16>, reached: Option<u16>) {
        if let Some(seq) = reached {
            self.push(Pending::ItemReached(seq));
        }
        if let Some(seq) = current {
            self.push(Pending::MissionCurrent(Some(seq)));
        }
    }

    /// Asks the vehicle to make `seq` current and confirms with MISSION_CURRENT; false (and a
    /// STATUSTEXT) when there is no such item.
    fn set_mission_current(&mut self, seq: u16) -> bool {
        let n = self.missions.store().mission.len();
        if usize::from(seq) >= n {
            self.textf(
                MavSeverity::MAV_SEVERITY_WARNING,
                format_args!("Mission item {} does not exist ({} items)", seq, n),
            );
            return false;
        }
        self.requests.mission_seq = Some(seq);
        self.push(Pending::MissionCurrent(Some(seq)));
        true
    }

    /// Emits everything due at `now_us`: answers to handled messages, the heartbeat, status
    /// texts, mission retries, the parameter stream, then telemetry streams.
    pub fn poll<F: FnMut(MavMessage)>(&mut self, now_us: u64, v: &VehicleSnapshot, mut out: F) {
        while let Some(p) = self.pending.pop_front() {
            self.emit(p, now_us, v, &mut out);
        }
        if now_us >= self.next_heartbeat_us {
            out(telemetry::heartbeat(v));
            self.next_heartbeat_us = self.next_heartbeat_us.saturating_add(HEARTBEAT_INTERVAL_US);
            if self.next_heartbeat_us <= now_us {
                self.next_heartbeat_us = now_us.saturating_add(HEARTBEAT_INTERVAL_US);
            }
        }
        while let Some(t) = self.texts.pop_front() {
            out(MavMessage::STATUSTEXT(STATUSTEXT_DATA {
                severity: t.severity,
                text: t.text.as_str().into(),
                id: 0,
                chunk_seq: 0,
            }));
        }
        if let Some((reply, to)) = self.missions.poll(now_us) {
            self.emit(Pending::Mission(reply, to), now_us, v, &mut out);
        }
        if self.last_mode != Some(v.mode) {
            if self.last_mode.is_some() {
                out(telemetry::current_mode(v, self.intended_mode(v)));
            }
            self.last_mode = Some(v.mode);
        }
        if let Some(next) = self.param_next {
            let n = self.params.len();
            let mut i = usize::from(next);
            for _ in 0..self.cfg.params_per_poll.max(1) {
                if i >= n {
                    break;
                }
                if let Some(m) = self.param_value(i) {
                    out(m);
                }
                i += 1;
            }
            self.param_next = if i >= n { None } else { Some(i as u16) };
        }
        let mut due: heapless::Vec<Stream, { streams::STREAM_COUNT }> = heapless::Vec::new();
        self.streams.run(now_us, |s| {
            let _ = due.push(s);
        });
        for s in due {
            self.emit_stream(s, now_us, v, &mut out);
        }
    }

    fn intended_mode(&self, v: &VehicleSnapshot) -> FlightMode {
        self.requests.mode.unwrap_or(v.mode)
    }

    fn param_value(&self, index: usize) -> Option<MavMessage> {
        let def = self.params.def(index)?;
        let value = self.params.value(index)?;
        Some(MavMessage::PARAM_VALUE(PARAM_VALUE_DATA {
            param_value: encode_wire(def.kind, value),
            param_count: self.params.len() as u16,
            param_index: index as u16,
            param_id: def.name.into(),
            param_type: match def.kind {
                ParamKind::Real => MavParamType::MAV_PARAM_TYPE_REAL32,
                ParamKind::Int => MavParamType::MAV_PARAM_TYPE_INT32,
            },
        }))
    }

    fn mission_ids(&self) -> (u32, u32, u32) {
        let s = self.missions.store();
        (
            s.opaque_id(PlanKind::Mission),
            s.opaque_id(PlanKind::Fence),
            s.opaque_id(PlanKind::Rally),
        )
    }

    fn emit_stream<F: FnMut(MavMessage)>(
        &self,
        s: Stream,
        now_us: u64,
        v: &VehicleSnapshot,
        out: &mut F,
    ) {
        let m = match s {
            Stream::SysStatus => telemetry::sys_status(v, self.rx_errors),
            Stream::GpsRawInt => telemetry::gps_raw_int(v),
            Stream::Attitude => telemetry::attitude(v, now_us),
            Stream::GlobalPositionInt => telemetry::global_position_int(v, now_us),
            Stream::MissionCurrent => telemetry::mission_current(
                v,
                v.mission_seq,
                self.missions.store().mission.len() as u16,
                self.mission_ids(),
            ),
            Stream::NavControllerOutput => telemetry::nav_controller_output(v),
            Stream::VfrHud => telemetry::vfr_hud(v),
            Stream::BatteryStatus => telemetry::battery_status(v),
            Stream::HomePosition => match telemetry::home_position(v, now_us) {
                Some(m) => m,
                None => return,
            },
            Stream::ExtendedSysState => telemetry::extended_sys_state(v),
            Stream::CurrentMode => telemetry::current_mode(v, self.intended_mode(v)),
        };
        out(m);
    }

    fn emit<F: FnMut(MavMessage)>(
        &self,
        p: Pending,
        now_us: u64,
        v: &VehicleSnapshot,
        out: &mut F,
    ) {
        match p {
            Pending::Ack {
                command,
                result,
                to,
            } => out(MavMessage::COMMAND_ACK(COMMAND_ACK_DATA {
                command,
                result,
                progress: 0,
                result_param2: 0,
                target_system: to.0,
                target_component: to.1,
            })),
            Pending::ParamValue(i) => {
                if let Some(m) = self.param_value(usize::from(i)) {
                    out(m);
                }
            }
            Pending::Mission(reply, to) => {
                if let Some(m) = self.mission_message(reply, to, v) {
                    out(m);
                }
            }
            Pending::MissionCurrent(seq) => out(telemetry::mission_current(
                v,
                seq.unwrap_or(v.mission_seq),
                self.missions.store().mission.len() as u16,
                self.mission_ids(),
            )),
            Pending::ItemReached(seq) => out(MavMessage::MISSION_ITEM_REACHED(
                MISSION_ITEM_REACHED_DATA { seq },
            )),
            Pending::AutopilotVersion => out(self.autopilot_version()),
            Pending::AvailableMode(i) => {
                if let Some(m) = FlightMode::ALL.get(usize::from(i)) {
                    out(telemetry::available_mode(usize::from(i), *m));
                }
            }
            Pending::CurrentMode => out(telemetry::current_mode(v, self.intended_mode(v))),
            Pending::Heartbeat => out(telemetry::heartbeat(v)),
            Pending::Stream(s) => self.emit_stream(s, now_us, v, out),
            Pending::MessageInterval { id, interval_us } => {
                out(MavMessage::MESSAGE_INTERVAL(MESSAGE_INTERVAL_DATA {
                    interval_us,
                    message_id: id,
                }))
            }
        }
    }

    fn mission_message(
        &self,
        reply: MissionReply,
        to: (u8, u8),
        v: &VehicleSnapshot,
    ) -> Option<MavMessage> {
        let store = self.missions.store();
        Some(match reply {
            MissionReply::Ack(mission_type, result) => MavMessage::MISSION_ACK(MISSION_ACK_DATA {
                target_system: to.0,
                target_component: to.1,
                mavtype: result,
                mission_type,
                opaque_id: if result == MavMissionResult::MAV_MISSION_ACCEPTED {
                    PlanKind::from_mav(mission_type).map_or(0, |k| store.opaque_id(k))
                } else {
                    0
                },
            }),
            MissionReply::Request(kind, seq) => {
                MavMessage::MISSION_REQUEST_INT(MISSION_REQUEST_INT_DATA {
                    seq,
                    target_system: to.0,
                    target_component: to.1,
                    mission_type: kind.to_mav(),
                })
            }
            MissionReply::Count(kind) => MavMessage::MISSION_COUNT(MISSION_COUNT_DATA {
                count: store.items(kind).len() as u16,
                target_system: to.0,
                target_component: to.1,
                mission_type: kind.to_mav(),
                opaque_id: store.opaque_id(kind),
            }),
            MissionReply::Item(kind, seq) => {
                let item = store.items(kind).get(usize::from(seq))?;
                let current = kind == PlanKind::Mission && seq == v.mission_seq;
                MavMessage::MISSION_ITEM_INT(item.to_mav(seq, kind, current, to)?)
            }
        })
    }

    #[allow(deprecated)] // PARAM_FLOAT is deprecated in favour of the encoding flags, yet
                         // the design names it and older ground stations look for it.
    fn autopilot_version(&self) -> MavMessage {
        type C = MavProtocolCapability;
        let capabilities = C::MAV_PROTOCOL_CAPABILITY_MAVLINK2
            | C::MAV_PROTOCOL_CAPABILITY_MISSION_INT
            | C::MAV_PROTOCOL_CAPABILITY_COMMAND_INT
            | C::MAV_PROTOCOL_CAPABILITY_PARAM_FLOAT
            | C::MAV_PROTOCOL_CAPABILITY_PARAM_ENCODE_BYTEWISE
            | C::MAV_PROTOCOL_CAPABILITY_MISSION_FENCE
            | C::MAV_PROTOCOL_CAPABILITY_MISSION_RALLY;
        MavMessage::AUTOPILOT_VERSION(AUTOPILOT_VERSION_DATA {
            capabilities,
            uid: self.cfg.uid,
            flight_sw_version: FLIGHT_SW_VERSION,
            middleware_sw_version: 0,
            os_sw_version: 0,
            board_version: 0,
            vendor_id: 0,
            product_id: 0,
            flight_custom_version: [0; 8],
            middleware_custom_version: [0; 8],
            os_custom_version: [0; 8],
            uid2: [0; 18],
        })
    }
}

/// A message id carried in a float command parameter.
fn message_id(p: f32) -> Option<u32> {
    if (0.0..16_777_216.0).contains(&p) && libm::truncf(p) == p {
        Some(p as u32)
    } else {
        None
    }
}

const fn parse_u8(s: &str) -> u32 {
    let b = s.as_bytes();
    let mut v = 0u32;
    let mut i = 0;
    while i < b.len() {
        v = v * 10 + (b[i] - b'0') as u32;
        i += 1;
    }
    v & 0xff
}

/// `AUTOPILOT_VERSION.flight_sw_version`: major, minor, patch of this crate and 255
/// (`FIRMWARE_VERSION_TYPE_OFFICIAL`), one byte each, as PX4 packs it.
pub const FLIGHT_SW_VERSION: u32 = (parse_u8(env!("CARGO_PKG_VERSION_MAJOR")) << 24)
    | (parse_u8(env!("CARGO_PKG_VERSION_MINOR")) << 16)
    | (parse_u8(env!("CARGO_PKG_VERSION_PATCH")) << 8)
    | 255;
