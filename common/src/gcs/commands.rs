//! The command service: `COMMAND_LONG` / `COMMAND_INT` checked against the vehicle's
//! snapshot, answered with `COMMAND_ACK`, accepted ones queued as requests for the vehicle;
//! the other messages that ask the vehicle for something (`SET_MODE`, `MISSION_SET_CURRENT`,
//! `MANUAL_CONTROL`) land in the same requests. Saves and reboots are the board's: the
//! service keeps them until the board takes them.

use super::config::{Stores, HEARTBEAT_INTERVAL_US};
use super::manual::manual_input;
use super::outbox::{After, Command, Outbox, Pending};
use super::peer::Peer;
use super::streams::{Scheduler, Stream};
use super::telemetry;
use super::texts::Line;
use super::tune::TuneService;
use crate::decimal::trimmed;
use crate::navigation::plan::MissionStore;
use crate::vehicle::modes::FlightMode;
use crate::vehicle::requests::{AltitudeSetpoint, ArmRequest, CourseSetpoint, VehicleRequests};
use crate::vehicle::snapshot::{LandedState, VehicleSnapshot};
use mavlink::dialects::common::*;
use mavlink::MessageData;
use num_traits::FromPrimitive;

/// `param2` of `MAV_CMD_COMPONENT_ARM_DISARM` that skips the checks (MAVLink's magic number).
pub const FORCE_ARM_MAGIC: f32 = 21196.0;

/// What a command reads and writes besides the service's own state.
pub(crate) struct CommandContext<'a, 'b> {
    /// When the command arrived, µs.
    pub now_us: u64,
    /// The vehicle as it is.
    pub vehicle: &'a VehicleSnapshot,
    /// The parameters (reset by a storage command) and the plan (checked by mode changes).
    pub stores: &'a mut Stores<'b>,
    /// The telemetry streams' rates (`MAV_CMD_SET_MESSAGE_INTERVAL`).
    pub streams: &'a mut Scheduler,
    /// Whether the link serves a `general.json`, so `COMPONENT_METADATA` can be asked for.
    pub metadata: bool,
    /// Where the answers go.
    pub out: &'a mut Outbox,
}

/// The command service's state: the requests accepted for the vehicle, and the save and
/// reboot the board owes.
#[derive(Clone, Debug, Default)]
pub struct CommandService {
    requests: VehicleRequests,
    /// A `MAV_CMD_PREFLIGHT_STORAGE` save the board owes, and who asked.
    storage_request: Option<Peer>,
    /// A `MAV_CMD_PREFLIGHT_REBOOT_SHUTDOWN` reboot the board owes.
    reboot_request: bool,
    /// The autotune a station started, owed its final answer.
    tune: TuneService,
}

impl CommandService {
    /// Nothing requested, nothing owed.
    pub fn new() -> Self {
        Self::default()
    }

    /// Answers the station whose autotune ended (see [`TuneService::poll`]).
    pub(crate) fn poll_autotune(&mut self, v: &VehicleSnapshot, now_us: u64, out: &mut Outbox) {
        self.tune.poll(v, now_us, out);
    }

    /// Takes the requests accepted since the last call.
    pub fn take_requests(&mut self) -> VehicleRequests {
        core::mem::take(&mut self.requests)
    }

    /// The mode the vehicle will fly: the one requested, when a request waits, else the one
    /// it flies.
    pub fn intended_mode(&self, v: &VehicleSnapshot) -> FlightMode {
        self.requests.mode.unwrap_or(v.mode)
    }

    /// `COMMAND_LONG` or `COMMAND_INT` (its position as integers, taken as the same seven
    /// parameters): acknowledged, and a request for the vehicle where it asks for one.
    pub(crate) fn on_command_message(
        &mut self,
        msg: &MavMessage,
        from: Peer,
        cx: CommandContext<'_, '_>,
    ) {
        let c = match msg {
            MavMessage::COMMAND_LONG(d) => Command {
                cmd: d.command,
                p: [
                    d.param1, d.param2, d.param3, d.param4, d.param5, d.param6, d.param7,
                ],
            },
            MavMessage::COMMAND_INT(d) => Command {
                cmd: d.command,
                p: [
                    d.param1, d.param2, d.param3, d.param4, d.x as f32, d.y as f32, d.z,
                ],
            },
            _ => return,
        };
        self.on_command(c, from, cx);
    }

    /// `MANUAL_CONTROL`: the sticks, for the vehicle to take with the other requests.
    pub fn on_manual_control(&mut self, d: &MANUAL_CONTROL_DATA, now_us: u64) {
        self.requests.manual = Some(manual_input(d, now_us));
    }

    /// `SET_MODE`: PX4 treats it as `MAV_CMD_DO_SET_MODE` and acknowledges it as such.
    // SET_MODE is deprecated but still sent by pymavlink and older ground stations.
    #[allow(deprecated)]
    pub(crate) fn on_set_mode(
        &mut self,
        d: &SET_MODE_DATA,
        from: Peer,
        v: &VehicleSnapshot,
        plan: &MissionStore,
        out: &mut Outbox,
    ) {
        let result = if d
            .base_mode
            .contains(MavModeFlag::MAV_MODE_FLAG_CUSTOM_MODE_ENABLED)
        {
            match FlightMode::from_custom_mode(d.custom_mode) {
                Some(m) => self.request_mode(m, v, plan, out),
                None => unknown_mode(d.custom_mode, out),
            }
        } else {
            out.texts_mut().push_str(
                MavSeverity::MAV_SEVERITY_WARNING,
                "Mode refused: only custom modes",
            );
            MavResult::MAV_RESULT_DENIED
        };
        out.ack(MavCmd::MAV_CMD_DO_SET_MODE, result, from);
    }

    /// `MISSION_SET_CURRENT`: the message has no ACK, so a bad index gets a STATUSTEXT and the
    /// current item.
    // MISSION_SET_CURRENT is deprecated but still sent by pymavlink and older ground stations.
    #[allow(deprecated)]
    pub(crate) fn on_mission_set_current(
        &mut self,
        d: &MISSION_SET_CURRENT_DATA,
        from: Peer,
        plan: &MissionStore,
        out: &mut Outbox,
    ) {
        if !self.set_mission_current(d.seq, plan, out) {
            out.push_to(Pending::MissionCurrent(None), from.dest());
        }
    }

    // GET_MESSAGE_INTERVAL and REQUEST_AUTOPILOT_CAPABILITIES are superseded by
    // REQUEST_MESSAGE but QGC and MAVSDK versions in use still send them.
    #[allow(deprecated)]
    fn on_command(&mut self, c: Command, from: Peer, cx: CommandContext<'_, '_>) {
        let CommandContext {
            now_us,
            vehicle: v,
            stores,
            streams,
            metadata,
            out,
        } = cx;
        if cfg!(feature = "autotune") && c.cmd == MavCmd::MAV_CMD_DO_AUTOTUNE_ENABLE {
            let (result, progress, ask) = self.tune.command(c.p[0] > 0.5, v, now_us, from, out);
            self.requests.autotune = ask.or(self.requests.autotune);
            out.ack_progress(c.cmd, result, progress, from);
            return;
        }
        let mut after = After::new();
        let result = match c.cmd {
            MavCmd::MAV_CMD_COMPONENT_ARM_DISARM => self.arm_disarm(&c, v, out),
            MavCmd::MAV_CMD_DO_SET_MODE => {
                let base = c.p[0] as u32;
                if base & MavModeFlag::MAV_MODE_FLAG_CUSTOM_MODE_ENABLED.bits() as u32 == 0 {
                    out.texts_mut().push_str(
                        MavSeverity::MAV_SEVERITY_WARNING,
                        "Mode refused: only custom modes",
                    );
                    MavResult::MAV_RESULT_DENIED
                } else {
                    match FlightMode::from_set_mode_params(c.p[1], c.p[2]) {
                        Ok(m) => self.request_mode(m, v, stores.plan, out),
                        Err(word) => unknown_mode(word, out),
                    }
                }
            }
            MavCmd::MAV_CMD_DO_SET_STANDARD_MODE => {
                match MavStandardMode::from_u32(c.p[0] as u32).and_then(FlightMode::from_standard) {
                    Some(m) => self.request_mode(m, v, stores.plan, out),
                    None => {
                        out.text(
                            MavSeverity::MAV_SEVERITY_WARNING,
                            Line::new()
                                .str("Standard mode ")
                                .uint(u64::from(c.p[0] as u32))
                                .str(" not supported"),
                        );
                        MavResult::MAV_RESULT_FAILED
                    }
                }
            }
            MavCmd::MAV_CMD_MISSION_START => {
                let r = self.request_mode(FlightMode::Mission, v, stores.plan, out);
                let first = c.p[0];
                if r == MavResult::MAV_RESULT_ACCEPTED
                    && first >= 1.0
                    && (first as usize) < stores.plan.mission.len()
                {
                    self.requests.mission_seq = Some(first as u16);
                }
                r
            }
            MavCmd::MAV_CMD_NAV_RETURN_TO_LAUNCH => {
                self.request_mode(FlightMode::Return, v, stores.plan, out)
            }
            MavCmd::MAV_CMD_NAV_TAKEOFF => {
                self.request_mode(FlightMode::Takeoff, v, stores.plan, out)
            }
            MavCmd::MAV_CMD_NAV_LAND => self.request_mode(FlightMode::Land, v, stores.plan, out),
            MavCmd::MAV_CMD_DO_GO_AROUND => {
                // Only a landing can be given up (param1, the altitude, is not used: the
                // go-around climbs to its circuit's height). A landing already rolling out is
                // refused by the vehicle, which says so.
                if v.armed && v.landed == LandedState::Landing {
                    self.requests.go_around = true;
                    MavResult::MAV_RESULT_ACCEPTED
                } else {
                    MavResult::MAV_RESULT_TEMPORARILY_REJECTED
                }
            }
            MavCmd::MAV_CMD_DO_SET_MISSION_CURRENT => {
                let seq = c.p[0];
                if (0.0..65536.0).contains(&seq)
                    && self.set_mission_current(seq as u16, stores.plan, out)
                {
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
                let (lo, hi) = v.airspeed_range_m_s;
                if c.p[1] == -1.0 || c.p[1] == -2.0 {
                    MavResult::MAV_RESULT_ACCEPTED
                } else if c.p[0] as i32 > 1 {
                    MavResult::MAV_RESULT_UNSUPPORTED
                } else if !(lo..=hi).contains(&c.p[1]) {
                    out.text(
                        MavSeverity::MAV_SEVERITY_WARNING,
                        Line::new()
                            .str("Airspeed ")
                            .decimal(trimmed(c.p[1], 2))
                            .str(" refused: outside [")
                            .decimal(trimmed(lo, 2))
                            .str(", ")
                            .decimal(trimmed(hi, 2))
                            .str("] m/s"),
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
                    // The heartbeat stays at 1 Hz.
                    Some(HEARTBEAT_DATA::ID) => MavResult::MAV_RESULT_DENIED,
                    Some(id) => match Stream::from_message_id(id) {
                        // A NaN interval asks for nothing: refused, the rate kept.
                        Some(s) if streams.set_interval(s, c.p[1], now_us) => {
                            MavResult::MAV_RESULT_ACCEPTED
                        }
                        Some(_) => MavResult::MAV_RESULT_DENIED,
                        None => MavResult::MAV_RESULT_UNSUPPORTED,
                    },
                    None => MavResult::MAV_RESULT_DENIED,
                }
            }
            MavCmd::MAV_CMD_GET_MESSAGE_INTERVAL => match message_id(c.p[0]) {
                Some(id) => {
                    let interval_us = if id == HEARTBEAT_DATA::ID {
                        HEARTBEAT_INTERVAL_US as i32
                    } else {
                        match Stream::from_message_id(id) {
                            Some(s) => streams
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
                let (r, p) = request_message(&c, v, metadata);
                after = p;
                r
            }
            // QGroundControl 4 asks for it after AUTOPILOT_VERSION and falls back to MAVLink 1
            // without an answer.
            MavCmd::MAV_CMD_REQUEST_PROTOCOL_VERSION => {
                let _ = after.push(Pending::ProtocolVersion);
                MavResult::MAV_RESULT_ACCEPTED
            }
            MavCmd::MAV_CMD_REQUEST_AUTOPILOT_CAPABILITIES => {
                let _ = after.push(Pending::AutopilotVersion);
                MavResult::MAV_RESULT_ACCEPTED
            }
            // The save is the board's: IN_PROGRESS now, ACCEPTED or FAILED once it is done
            // (CommandService::storage_done). Erasing flash stalls the processor, so never armed.
            MavCmd::MAV_CMD_PREFLIGHT_STORAGE => match c.p[0] as i32 {
                1 if v.armed => MavResult::MAV_RESULT_TEMPORARILY_REJECTED,
                1 => {
                    self.storage_request = Some(from);
                    MavResult::MAV_RESULT_IN_PROGRESS
                }
                2 if v.armed => MavResult::MAV_RESULT_DENIED,
                2 => {
                    stores.params.reset_to_defaults();
                    self.storage_request = Some(from);
                    MavResult::MAV_RESULT_IN_PROGRESS
                }
                _ => MavResult::MAV_RESULT_UNSUPPORTED,
            },
            // param1: 0 nothing for the autopilot, 1 reboot it (the board does, once the
            // answer is sent); shutdown and the bootloader are not offered.
            MavCmd::MAV_CMD_PREFLIGHT_REBOOT_SHUTDOWN => match c.p[0] as i32 {
                _ if v.armed => MavResult::MAV_RESULT_DENIED,
                0 => MavResult::MAV_RESULT_ACCEPTED,
                1 => {
                    self.reboot_request = true;
                    MavResult::MAV_RESULT_ACCEPTED
                }
                _ => MavResult::MAV_RESULT_UNSUPPORTED,
            },
            _ => MavResult::MAV_RESULT_UNSUPPORTED,
        };
        out.ack(c.cmd, result, from);
        // By reference: a heapless vector's by-value iterator checks a slice bound on drop.
        for p in after.iter().copied() {
            out.push_to(p, from.dest());
        }
    }

    fn arm_disarm(&mut self, c: &Command, v: &VehicleSnapshot, out: &mut Outbox) -> MavResult {
        let arm = c.p[0] > 0.5;
        let forced = (c.p[1] - FORCE_ARM_MAGIC).abs() < 0.5;
        if arm {
            if v.armed {
                return MavResult::MAV_RESULT_ACCEPTED;
            }
            if !forced {
                if !v.boot_complete {
                    out.texts_mut().push_str(
                        MavSeverity::MAV_SEVERITY_CRITICAL,
                        "Arming denied: system still starting",
                    );
                    return MavResult::MAV_RESULT_TEMPORARILY_REJECTED;
                }
                if let Some(why) = telemetry::prearm_failure(v) {
                    out.text(
                        MavSeverity::MAV_SEVERITY_CRITICAL,
                        Line::new().str("Arming denied: ").str(why.reason()),
                    );
                    return why.result();
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
                out.texts_mut().push_str(
                    MavSeverity::MAV_SEVERITY_CRITICAL,
                    "Disarming denied: not landed",
                );
                return MavResult::MAV_RESULT_DENIED;
            }
        }
        self.requests.arm = Some(ArmRequest { arm, forced });
        MavResult::MAV_RESULT_ACCEPTED
    }

    /// Checks a mode change and, when possible, queues it for the vehicle.
    fn request_mode(
        &mut self,
        mode: FlightMode,
        v: &VehicleSnapshot,
        plan: &MissionStore,
        out: &mut Outbox,
    ) -> MavResult {
        if mode == FlightMode::Mission && plan.mission.is_empty() {
            out.texts_mut().push_str(
                MavSeverity::MAV_SEVERITY_WARNING,
                "Mode Mission refused: no mission",
            );
            return MavResult::MAV_RESULT_DENIED;
        }
        if mode == FlightMode::Return && !v.home.valid {
            out.texts_mut().push_str(
                MavSeverity::MAV_SEVERITY_WARNING,
                "Mode Return refused: no home position",
            );
            return MavResult::MAV_RESULT_TEMPORARILY_REJECTED;
        }
        if !v.modes_available.contains(mode) {
            let why = if mode.needs_position() && !v.health.position_valid {
                "no position estimate"
            } else {
                "not available now"
            };
            out.text(
                MavSeverity::MAV_SEVERITY_WARNING,
                Line::new()
                    .str("Mode ")
                    .str(mode.name())
                    .str(" refused: ")
                    .str(why),
            );
            return MavResult::MAV_RESULT_TEMPORARILY_REJECTED;
        }
        self.requests.mode = Some(mode);
        MavResult::MAV_RESULT_ACCEPTED
    }

    /// Asks the vehicle to make `seq` current and confirms with MISSION_CURRENT; false (and a
    /// STATUSTEXT) when there is no such item.
    fn set_mission_current(&mut self, seq: u16, plan: &MissionStore, out: &mut Outbox) -> bool {
        let n = plan.mission.len();
        if usize::from(seq) >= n {
            out.text(
                MavSeverity::MAV_SEVERITY_WARNING,
                Line::new()
                    .str("Mission item ")
                    .uint(u64::from(seq))
                    .str(" does not exist (")
                    .uint(n as u64)
                    .str(" items)"),
            );
            return false;
        }
        self.requests.mission_seq = Some(seq);
        out.push(Pending::MissionCurrent(Some(seq)));
        true
    }
}

/// `MAV_CMD_REQUEST_MESSAGE`: the result and, when accepted, what to send after the ACK.
// PROTOCOL_VERSION is deprecated in the dialect, yet QGroundControl 4 asks for it.
#[allow(deprecated)]
fn request_message(c: &Command, v: &VehicleSnapshot, metadata: bool) -> (MavResult, After) {
    let mut after = After::new();
    let Some(id) = message_id(c.p[0]) else {
        return (MavResult::MAV_RESULT_DENIED, after);
    };
    let one = match id {
        HEARTBEAT_DATA::ID => Some(Pending::Heartbeat),
        AUTOPILOT_VERSION_DATA::ID => Some(Pending::AutopilotVersion),
        CURRENT_MODE_DATA::ID => Some(Pending::CurrentMode),
        PROTOCOL_VERSION_DATA::ID => Some(Pending::ProtocolVersion),
        COMPONENT_METADATA_DATA::ID if metadata => Some(Pending::ComponentMetadata),
        AVAILABLE_MODES_DATA::ID => {
            let n = FlightMode::ALL.len();
            let index = c.p[1];
            if index == 0.0 {
                // 0 asks for every mode.
                for i in 0..n {
                    let _ = after.push(Pending::AvailableMode(i as u8));
                }
                return (MavResult::MAV_RESULT_ACCEPTED, after);
            } else if index >= 1.0 && index <= n as f32 && libm::truncf(index) == index {
                Some(Pending::AvailableMode((index as u8).saturating_sub(1)))
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

/// A mode this autopilot does not fly: FAILED, and a status text naming PX4's numbers.
fn unknown_mode(custom_mode: u32, out: &mut Outbox) -> MavResult {
    out.text(
        MavSeverity::MAV_SEVERITY_WARNING,
        Line::new()
            .str("Mode ")
            .uint(u64::from((custom_mode >> 16) & 0xff))
            .str(".")
            .uint(u64::from(custom_mode >> 24))
            .str(" not supported"),
    );
    MavResult::MAV_RESULT_FAILED
}

/// `AUTOPILOT_VERSION`: what this autopilot speaks (FTP when it serves files, `ftp`) and
/// the board's unique id.
// PARAM_FLOAT is deprecated in favour of the encoding flags, yet the design names it and
// older ground stations look for it.
#[allow(deprecated)]
pub(crate) fn autopilot_version(uid: u64, ftp: bool) -> MavMessage {
    type C = MavProtocolCapability;
    let mut capabilities = C::MAV_PROTOCOL_CAPABILITY_MAVLINK2
        | C::MAV_PROTOCOL_CAPABILITY_MISSION_INT
        | C::MAV_PROTOCOL_CAPABILITY_COMMAND_INT
        | C::MAV_PROTOCOL_CAPABILITY_PARAM_FLOAT
        | C::MAV_PROTOCOL_CAPABILITY_PARAM_ENCODE_BYTEWISE
        | C::MAV_PROTOCOL_CAPABILITY_MISSION_FENCE
        | C::MAV_PROTOCOL_CAPABILITY_MISSION_RALLY;
    if ftp {
        capabilities |= C::MAV_PROTOCOL_CAPABILITY_FTP;
    }
    MavMessage::AUTOPILOT_VERSION(AUTOPILOT_VERSION_DATA {
        capabilities,
        uid,
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

/// A message id carried in a float command parameter.
fn message_id(p: f32) -> Option<u32> {
    if (0.0..16_777_216.0).contains(&p) && libm::truncf(p) == p {
        Some(p as u32)
    } else {
        None
    }
}

// Runs at compile time only, on the crate's own version numbers.
#[allow(clippy::indexing_slicing, clippy::arithmetic_side_effects)]
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

/// What the board owes a station after a storage or reboot command.
impl CommandService {
    /// The station whose `MAV_CMD_PREFLIGHT_STORAGE` waits for the board's save (answered
    /// `IN_PROGRESS` so far); the board saves, and the link answers once it is done.
    pub fn take_storage_request(&mut self) -> Option<Peer> {
        self.storage_request.take()
    }

    /// The final answer to a `MAV_CMD_PREFLIGHT_STORAGE`: ACCEPTED once the save is done,
    /// FAILED (with a status text) when the flash refused it.
    pub(crate) fn storage_done(&self, to: Peer, saved: bool, out: &mut Outbox) {
        let result = if saved {
            MavResult::MAV_RESULT_ACCEPTED
        } else {
            out.texts_mut().push_str(
                MavSeverity::MAV_SEVERITY_ERROR,
                "Parameters not saved: flash error",
            );
            MavResult::MAV_RESULT_FAILED
        };
        out.ack(MavCmd::MAV_CMD_PREFLIGHT_STORAGE, result, to);
    }

    /// Whether a reboot was asked for (and accepted: disarmed) since the last call.
    pub fn take_reboot_request(&mut self) -> bool {
        core::mem::take(&mut self.reboot_request)
    }
}
