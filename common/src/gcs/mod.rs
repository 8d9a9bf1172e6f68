//! The ground-station link: what QGroundControl, MAVSDK and pymavlink see of the autopilot.
//!
//! [`GroundLink`] is transport-agnostic logic: the firmware decodes frames with the `mavlink`
//! crate, hands each message to [`GroundLink::handle`], and calls [`GroundLink::poll`] every
//! tick to collect the answers and telemetry to encode and send. The link never acts on the
//! vehicle itself: mode and arming requests it accepted wait in [`VehicleRequests`] for the
//! vehicle to take with [`GroundLink::take_requests`]; the heartbeat always reports the state
//! the vehicle says it is in ([`VehicleSnapshot`]), never what was asked. The parameters and
//! the stored plan are the vehicle's ([`Stores`]): the link reads them and writes what the
//! protocols accept, through the store's own checks.
//!
//! One file per service: [`mission`] (the mission protocol), [`params`] (the parameter
//! protocol), [`commands`] (commands and their acknowledgements), [`telemetry`] and
//! [`streams`] (what is sent unasked, and how often); this file routes messages to them.
//!
//! Identity: system 1, component 1, `MAV_TYPE_FIXED_WING`, `MAV_AUTOPILOT_GENERIC`; modes in
//! PX4's `custom_mode` encoding (see [`modes`]). `docs/GROUND-STATION.md` describes the
//! behaviour a ground station sees.

// Counts, lengths and offsets here come from outside: every operation on them is checked.
#![cfg_attr(not(test), deny(clippy::arithmetic_side_effects))]

pub mod client;
pub mod commands;
pub mod ftp;
pub mod mission;
pub mod modes;
pub mod outbox;
pub mod params;
pub mod peer;
pub mod signing;
pub mod streams;
pub mod telemetry;

#[cfg(test)]
mod tests;

use core::fmt::Write;

use heapless::{Deque, String};
use mavlink::dialects::common::*;
use mavlink::{MavHeader, Message};

use crate::navigation::plan::{MissionStore, PlanKind};
use crate::navigation::validate::PlanRules;
use crate::navigation::validate::ValidationWarning;
use crate::params::store::ParamStore;
use crate::sensors::ManualInput;
use crate::vehicle::modes::FlightMode;
use crate::vehicle::requests::VehicleRequests;
use crate::vehicle::snapshot::VehicleSnapshot;
use mission::{mission_message, MissionManager, MissionReply};
use outbox::{Command, Pending, Text, TEXT_MAX};

pub use outbox::{CommandAck, Outgoing};
pub use peer::{Dest, Origin, Peer};

pub use outbox::STATUSTEXT_LEN;
use signing::Signing;
use streams::{Scheduler, Stream};

/// Our MAVLink system id.
pub const SYSTEM_ID: u8 = 1;
/// Our MAVLink component id (`MAV_COMP_ID_AUTOPILOT1`).
pub const COMPONENT_ID: u8 = 1;
/// `param2` of `MAV_CMD_COMPONENT_ARM_DISARM` that skips the checks (MAVLink's magic number).
pub const FORCE_ARM_MAGIC: f32 = 21196.0;
/// Heartbeat interval, µs (1 Hz; QGC drops a vehicle after 3.5 s of silence).
pub const HEARTBEAT_INTERVAL_US: u64 = 1_000_000;

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
    /// The files served over MAVLink FTP; with a `general.json` among them, the link answers
    /// requests for `COMPONENT_METADATA` with its URI.
    pub files: &'static [ftp::File],
}

impl Default for LinkConfig {
    fn default() -> Self {
        Self {
            system_id: SYSTEM_ID,
            component_id: COMPONENT_ID,
            params_per_poll: 4,
            uid: 0,
            files: &[],
        }
    }
}

/// What the link reads and writes besides the vehicle's snapshot: the parameter values, the
/// stored plan, and what a finished upload is checked against.
pub struct Stores<'a> {
    /// Every parameter of the vehicle.
    pub params: &'a mut ParamStore,
    /// The mission, geofence and rally lists.
    pub plan: &'a mut MissionStore,
    /// Home and the navigator's limits, for the upload checks.
    pub rules: PlanRules,
}

/// The ground-station link state machine.
#[derive(Clone, Debug)]
pub struct GroundLink {
    cfg: LinkConfig,
    missions: MissionManager,
    streams: Scheduler,
    pending: Deque<(Pending, Dest), PENDING_CAPACITY>,
    texts: Deque<Text, TEXT_CAPACITY>,
    requests: VehicleRequests,
    /// A `MAV_CMD_PREFLIGHT_STORAGE` save the board owes, and who asked.
    storage_request: Option<Peer>,
    /// A `MAV_CMD_PREFLIGHT_REBOOT_SHUTDOWN` reboot the board owes.
    reboot_request: bool,
    /// The next index of a parameter list download, and the channel that asked for it.
    param_next: Option<(u16, u8)>,
    next_heartbeat_us: u64,
    gcs_last_seen_us: Option<u64>,
    last_mode: Option<FlightMode>,
    dropped: u32,
    rx_errors: u16,
    signing: Signing,
    /// The `id` of the last status text sent in chunks.
    text_id: u16,
    ftp: ftp::Ftp,
}

impl Default for GroundLink {
    fn default() -> Self {
        Self::new(LinkConfig::default())
    }
}

impl GroundLink {
    /// A link with these settings.
    /// Not inlined: see `Vehicle::fresh`.
    #[inline(never)]
    pub fn new(cfg: LinkConfig) -> Self {
        Self {
            cfg,
            missions: MissionManager::new(),
            streams: Scheduler::new(),
            pending: Deque::new(),
            texts: Deque::new(),
            requests: VehicleRequests::default(),
            storage_request: None,
            reboot_request: false,
            param_next: None,
            next_heartbeat_us: 0,
            gcs_last_seen_us: None,
            last_mode: None,
            dropped: 0,
            rx_errors: 0,
            signing: Signing::default(),
            text_id: 0,
            ftp: ftp::Ftp::new(cfg.files),
        }
    }

    /// MAVLink 2 signing: the key and its policy.
    pub fn signing(&self) -> &Signing {
        &self.signing
    }

    /// MAVLink 2 signing, writable (loading a persisted key at start-up).
    pub fn signing_mut(&mut self) -> &mut Signing {
        &mut self.signing
    }

    /// The mission protocol's state (a transfer in progress).
    pub fn missions(&self) -> &MissionManager {
        &self.missions
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

    /// Queues a status text (event messages from the vehicle: failsafes, mode changes, ...).
    /// Text longer than 50 bytes goes out as STATUSTEXT chunks (MAVLink 2's `id` and
    /// `chunk_seq`), up to 150 bytes; when the queue is full the text is dropped and counted in
    /// [`GroundLink::dropped`].
    pub fn send_statustext(&mut self, severity: MavSeverity, text: &str) {
        let mut s = String::new();
        for c in text.chars() {
            if s.push(c).is_err() {
                break;
            }
        }
        self.queue_text(severity, s);
    }

    fn queue_text(&mut self, severity: MavSeverity, text: String<TEXT_MAX>) {
        if self.texts.push_back(Text { severity, text }).is_err() {
            self.dropped = self.dropped.wrapping_add(1);
        }
    }

    /// Says what an accepted mission will do differently from what its reader may expect.
    fn mission_warning(&mut self, w: ValidationWarning) {
        self.textf(MavSeverity::MAV_SEVERITY_WARNING, format_args!("{w}"));
    }

    fn textf(&mut self, severity: MavSeverity, args: core::fmt::Arguments<'_>) {
        let mut s: String<TEXT_MAX> = String::new();
        // A text that does not fit is cut, never refused.
        let _ = s.write_fmt(args);
        self.queue_text(severity, s);
    }

    /// Queues a message for every station.
    fn push(&mut self, p: Pending) {
        self.push_to(p, Dest::All);
    }

    fn push_to(&mut self, p: Pending, dest: Dest) {
        if self.pending.push_back((p, dest)).is_err() {
            self.dropped = self.dropped.wrapping_add(1);
        }
    }

    /// Consumes one message from a ground station, received on the board's `channel` (with
    /// its signature block, when it was signed and a key is installed). Messages addressed to
    /// another system or component, our own echoes, and whatever the signing policy refuses
    /// are ignored.
    // SET_MODE, MISSION_REQUEST, MISSION_SET_CURRENT and MISSION_ITEM are deprecated but still
    // sent by pymavlink and older ground stations; answering them is part of compatibility.
    #[allow(deprecated)]
    pub fn handle(
        &mut self,
        header: &MavHeader,
        msg: &MavMessage,
        now_us: u64,
        vehicle: &VehicleSnapshot,
        stores: &mut Stores,
        origin: Origin,
    ) {
        let Origin { channel, signed } = origin;
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
        if self
            .signing
            .admit(sys, header.component_id, msg, signed)
            .is_err()
        {
            return;
        }
        let from = Peer {
            system: sys,
            component: header.component_id,
            channel,
        };
        match msg {
            MavMessage::SETUP_SIGNING(d) => {
                let with_key = signed.is_some_and(|s| s.valid);
                let text = if !self.signing.setup(d, with_key) {
                    "Signing setup refused: not signed with the key"
                } else if self.signing.key().is_some() {
                    "Signing on: unsigned writes are refused"
                } else {
                    "Signing off"
                };
                self.send_statustext(MavSeverity::MAV_SEVERITY_INFO, text);
            }
            MavMessage::FILE_TRANSFER_PROTOCOL(d) if d.target_network == 0 => {
                self.ftp.handle(d, from, now_us);
            }
            MavMessage::HEARTBEAT(h) if h.mavtype == MavType::MAV_TYPE_GCS => {
                self.gcs_last_seen_us = Some(now_us);
            }
            MavMessage::PARAM_REQUEST_LIST(_) => {
                // A new request restarts the stream: every index once, in order, to the
                // channel that asked.
                self.param_next = Some((0, channel));
            }
            MavMessage::PARAM_REQUEST_READ(d) => {
                self.on_param_read(d, stores.params, from);
            }
            MavMessage::PARAM_SET(d) => self.on_param_set(d, stores.params, from),
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
                self.on_command(c, from, now_us, vehicle, stores);
            }
            MavMessage::COMMAND_INT(d) => {
                let c = Command {
                    cmd: d.command,
                    p: [
                        d.param1, d.param2, d.param3, d.param4, d.x as f32, d.y as f32, d.z,
                    ],
                };
                self.on_command(c, from, now_us, vehicle, stores);
            }
            MavMessage::SET_MODE(d) => {
                // PX4 treats SET_MODE as MAV_CMD_DO_SET_MODE and acknowledges it as such.
                let result = if d
                    .base_mode
                    .contains(MavModeFlag::MAV_MODE_FLAG_CUSTOM_MODE_ENABLED)
                {
                    match FlightMode::from_custom_mode(d.custom_mode) {
                        Some(m) => self.request_mode(m, vehicle, stores.plan),
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
                    .on_count(stores.plan, d.mission_type, d.count, from, now_us);
                self.push_to(Pending::Mission(r, from), from.dest());
            }
            MavMessage::MISSION_ITEM_INT(d) => {
                let plan = &mut *stores.plan;
                if let Some(r) = self.missions.on_item(plan, &stores.rules, d, from, now_us) {
                    self.push_to(Pending::Mission(r, from), from.dest());
                }
                for w in self.missions.take_warnings().iter().copied() {
                    self.mission_warning(w);
                }
            }
            // Float items lose precision; this autopilot asks for MISSION_ITEM_INT only.
            MavMessage::MISSION_ITEM(d) if self.missions.busy() => {
                self.missions.on_ack(d.mission_type, from);
                let nack =
                    MissionReply::Ack(d.mission_type, MavMissionResult::MAV_MISSION_UNSUPPORTED);
                self.push_to(Pending::Mission(nack, from), from.dest());
            }
            MavMessage::MISSION_REQUEST_LIST(d) => {
                let r = self
                    .missions
                    .on_request_list(stores.plan, d.mission_type, from, now_us);
                self.push_to(Pending::Mission(r, from), from.dest());
            }
            MavMessage::MISSION_REQUEST_INT(d) => {
                let r = self
                    .missions
                    .on_request(stores.plan, d.mission_type, d.seq, from, now_us);
                self.push_to(Pending::Mission(r, from), from.dest());
            }
            MavMessage::MISSION_REQUEST(d) => {
                // Legacy request: answered with MISSION_ITEM_INT all the same.
                let r = self
                    .missions
                    .on_request(stores.plan, d.mission_type, d.seq, from, now_us);
                self.push_to(Pending::Mission(r, from), from.dest());
            }
            MavMessage::MISSION_ACK(d) => self.missions.on_ack(d.mission_type, from),
            MavMessage::MISSION_CLEAR_ALL(d) => {
                let r = self.missions.on_clear(stores.plan, d.mission_type);
                self.push_to(Pending::Mission(r, from), from.dest());
            }
            MavMessage::MISSION_SET_CURRENT(d) => {
                // The message has no ACK: a bad index gets a STATUSTEXT and the current item.
                let ok = self.set_mission_current(d.seq, stores.plan);
                if !ok {
                    self.push_to(Pending::MissionCurrent(None), from.dest());
                }
            }
            _ => {}
        }
    }

    /// A frame whose checksum matched but whose payload the dialect could not decode: a
    /// command with an id this autopilot does not know gets `MAV_RESULT_UNSUPPORTED`, as the
    /// command protocol asks, when it is addressed to us.
    pub fn handle_undecoded(&mut self, header: &MavHeader, id: u32, payload: &[u8], channel: u8) {
        // Whether it was signed cannot be told here: with signing on, no answer.
        if self.signing.key().is_some() {
            return;
        }
        let Some((command, ts, tc)) = outbox::undecoded_command(id, payload) else {
            return;
        };
        let Ok(sys) = u8::try_from(header.system_id) else {
            return;
        };
        let ours =
            (ts == 0 || ts == self.cfg.system_id) && (tc == 0 || tc == self.cfg.component_id);
        let echo = sys == self.cfg.system_id && header.component_id == self.cfg.component_id;
        if !ours || echo {
            return;
        }
        let to = Peer {
            system: sys,
            component: header.component_id,
            channel,
        };
        self.push_to(Pending::Unsupported { command, to }, to.dest());
    }

    fn ack(&mut self, command: MavCmd, result: MavResult, to: Peer) {
        self.push_to(
            Pending::Ack {
                command,
                result,
                to,
            },
            to.dest(),
        );
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

    /// Emits everything due at `now_us`, each with where it goes: answers to handled messages
    /// (back on the asker's channel), the heartbeat, status texts, mission retries, the
    /// parameter stream, then telemetry streams.
    pub fn poll<F: FnMut(Dest, Outgoing)>(
        &mut self,
        now_us: u64,
        v: &VehicleSnapshot,
        stores: &Stores,
        mut out_raw: F,
    ) {
        self.signing.tick(now_us);
        while let Some((p, dest)) = self.pending.pop_front() {
            if let Pending::Unsupported { command, to } = p {
                let ack = CommandAck {
                    command,
                    result: MavResult::MAV_RESULT_UNSUPPORTED,
                    target: to.address(),
                };
                out_raw(dest, Outgoing::Ack(ack));
                continue;
            }
            self.emit(p, dest, now_us, v, stores, &mut |d, m| {
                out_raw(d, Outgoing::Message(m))
            });
        }
        let mut out_msg = |d, m| out_raw(d, Outgoing::Message(m));
        let out = &mut out_msg;
        let mut budget = ftp::BURST_PER_POLL;
        while let Some((m, to)) = self.ftp.next(&mut budget) {
            out(to.dest(), m);
        }
        if now_us >= self.next_heartbeat_us {
            out(Dest::All, telemetry::heartbeat(v));
            self.next_heartbeat_us = self.next_heartbeat_us.saturating_add(HEARTBEAT_INTERVAL_US);
            if self.next_heartbeat_us <= now_us {
                self.next_heartbeat_us = now_us.saturating_add(HEARTBEAT_INTERVAL_US);
            }
        }
        while let Some(t) = self.texts.pop_front() {
            let bytes = t.text.as_bytes();
            if bytes.len() <= STATUSTEXT_LEN {
                let text = MavMessage::STATUSTEXT(STATUSTEXT_DATA {
                    severity: t.severity,
                    text: t.text.as_str().into(),
                    id: 0,
                    chunk_seq: 0,
                });
                out(Dest::All, text);
                continue;
            }
            // Chunks of one text share a non-zero id; the last is shorter than 50 bytes (its
            // NUL ends the text), an empty one when the text fills its chunks exactly.
            self.text_id = self.text_id.wrapping_add(1).max(1);
            let chunks = (bytes.len() / STATUSTEXT_LEN).saturating_add(1);
            for (seq, start) in (0..chunks).map(|i| (i, i.saturating_mul(STATUSTEXT_LEN))) {
                let part = bytes.get(start..).unwrap_or(&[]);
                let part = part.get(..STATUSTEXT_LEN).unwrap_or(part);
                let mut text = [0u8; STATUSTEXT_LEN];
                for (d, b) in text.iter_mut().zip(part) {
                    *d = *b;
                }
                let chunk = MavMessage::STATUSTEXT(STATUSTEXT_DATA {
                    severity: t.severity,
                    text: text.into(),
                    id: self.text_id,
                    chunk_seq: seq as u8,
                });
                out(Dest::All, chunk);
            }
        }
        if let Some((reply, to)) = self.missions.poll(now_us) {
            self.emit(
                Pending::Mission(reply, to),
                to.dest(),
                now_us,
                v,
                stores,
                out,
            );
        }
        if self.last_mode != Some(v.mode) {
            if self.last_mode.is_some() {
                out(Dest::All, telemetry::current_mode(v, self.intended_mode(v)));
            }
            self.last_mode = Some(v.mode);
        }
        self.stream_params(stores.params, out);
        let mut due: heapless::Vec<Stream, { streams::STREAM_COUNT }> = heapless::Vec::new();
        self.streams.run(now_us, |s| {
            let _ = due.push(s);
        });
        for s in due {
            if let Some(m) = self.stream_message(s, now_us, v, stores.plan) {
                out(Dest::All, m);
            }
        }
    }

    fn intended_mode(&self, v: &VehicleSnapshot) -> FlightMode {
        self.requests.mode.unwrap_or(v.mode)
    }

    fn mission_ids(s: &MissionStore) -> (u32, u32, u32) {
        (
            s.opaque_id(PlanKind::Mission),
            s.opaque_id(PlanKind::Fence),
            s.opaque_id(PlanKind::Rally),
        )
    }

    fn stream_message(
        &self,
        s: Stream,
        now_us: u64,
        v: &VehicleSnapshot,
        plan: &MissionStore,
    ) -> Option<MavMessage> {
        Some(match s {
            Stream::SysStatus => telemetry::sys_status(v, self.rx_errors),
            Stream::GpsRawInt => telemetry::gps_raw_int(v),
            Stream::Attitude => telemetry::attitude(v, now_us),
            Stream::GlobalPositionInt => telemetry::global_position_int(v, now_us),
            Stream::MissionCurrent => telemetry::mission_current(
                v,
                v.mission_seq,
                plan.mission.len() as u16,
                Self::mission_ids(plan),
            ),
            Stream::NavControllerOutput => telemetry::nav_controller_output(v),
            Stream::VfrHud => telemetry::vfr_hud(v),
            Stream::BatteryStatus => telemetry::battery_status(v),
            Stream::HomePosition => telemetry::home_position(v, now_us)?,
            Stream::ExtendedSysState => telemetry::extended_sys_state(v),
            Stream::CurrentMode => telemetry::current_mode(v, self.intended_mode(v)),
        })
    }

    fn emit<F: FnMut(Dest, MavMessage)>(
        &self,
        p: Pending,
        dest: Dest,
        now_us: u64,
        v: &VehicleSnapshot,
        stores: &Stores,
        out: &mut F,
    ) {
        let mut out = |m| out(dest, m);
        match p {
            // Sent as raw data by `poll`.
            Pending::Unsupported { .. } => {}
            Pending::ParamError {
                index,
                name,
                error,
                to,
            } => out(MavMessage::PARAM_ERROR(PARAM_ERROR_DATA {
                param_index: index,
                target_system: to.system,
                target_component: to.component,
                param_id: name.into(),
                error,
            })),
            // Deprecated in the dialect since 2025, but QGroundControl 4 still asks for it.
            #[allow(deprecated)]
            Pending::ProtocolVersion => out(MavMessage::PROTOCOL_VERSION(PROTOCOL_VERSION_DATA {
                // MAVLink 2 spoken (and sent); MAVLink 1 frames still read.
                version: 200,
                min_version: 100,
                max_version: 200,
                spec_version_hash: [0; 8],
                library_version_hash: [0; 8],
            })),
            Pending::ComponentMetadata => {
                if let Some(f) = self.ftp.general() {
                    out(MavMessage::COMPONENT_METADATA(COMPONENT_METADATA_DATA {
                        time_boot_ms: (now_us / 1000) as u32,
                        file_crc: ftp::file_crc(f.bytes),
                        uri: ftp::uri(f).as_str().into(),
                    }));
                }
            }
            Pending::Ack {
                command,
                result,
                to,
            } => out(MavMessage::COMMAND_ACK(COMMAND_ACK_DATA {
                command,
                result,
                progress: 0,
                result_param2: 0,
                target_system: to.system,
                target_component: to.component,
            })),
            Pending::ParamValue(i) => {
                if let Some(m) = params::param_value(stores.params, usize::from(i)) {
                    out(m);
                }
            }
            Pending::Mission(reply, to) => {
                if let Some(m) = mission_message(reply, to.address(), stores.plan, v.mission_seq) {
                    out(m);
                }
            }
            Pending::MissionCurrent(seq) => out(telemetry::mission_current(
                v,
                seq.unwrap_or(v.mission_seq),
                stores.plan.mission.len() as u16,
                Self::mission_ids(stores.plan),
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
            Pending::Stream(s) => {
                let m = self.stream_message(s, now_us, v, stores.plan);
                if let Some(m) = m {
                    out(m);
                }
            }
            Pending::MessageInterval { id, interval_us } => {
                out(MavMessage::MESSAGE_INTERVAL(MESSAGE_INTERVAL_DATA {
                    interval_us,
                    message_id: id,
                }))
            }
        }
    }
}
