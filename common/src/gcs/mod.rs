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
//! One type per service, each in its file: [`mission`] (the mission protocol), [`params`]
//! (the parameter protocol), [`commands`] (commands and their acknowledgements, and the
//! vehicle's requests), [`ftp`] (files), [`texts`] (status texts), [`telemetry`] and
//! [`streams`] (what is sent unasked, and how often). This file routes each message to one
//! of them and orders what they have to send at each poll (`output.rs` builds it). The
//! services never call each other: what one has to send is written to the outbox handed to
//! it, and what one needs of another is handed to it as an argument.
//!
//! Identity: system 1, component 1, `MAV_TYPE_FIXED_WING`, `MAV_AUTOPILOT_GENERIC`; modes in
//! PX4's `custom_mode` encoding (see [`modes`]). `docs/GROUND-STATION.md` describes the
//! behaviour a ground station sees.

// Counts, lengths and offsets here come from outside: every operation on them is checked.
#![cfg_attr(not(test), deny(clippy::arithmetic_side_effects))]

pub mod client;
pub mod commands;
pub mod config;
pub mod ftp;
pub mod logs;
pub mod manual;
pub mod mission;
pub mod modes;
pub mod outbox;
mod output;
pub mod params;
pub mod peer;
pub mod signing;
pub mod streams;
pub mod telemetry;
pub mod texts;
pub mod tune;

/// The system and component a message is addressed to, as the `mavlink` crate's
/// `target_system_id` and `target_component_id` answer, for the messages the autopilot's
/// dialect reads (`link::dialect`); the crate's own answers for any other. The crate's are
/// matches over the whole common dialect's 230 messages (1.2 KB of the MCU image), where the
/// ground link only ever decodes these.
// The deprecated messages ground stations still send (SET_MODE, MISSION_ITEM, ...) are read.
#[allow(deprecated)]
pub(crate) fn targets(msg: &MavMessage) -> (Option<u8>, Option<u8>) {
    use MavMessage as M;
    let both = |s: u8, c: u8| (Some(s), Some(c));
    match msg {
        M::SETUP_SIGNING(d) => both(d.target_system, d.target_component),
        M::FILE_TRANSFER_PROTOCOL(d) => both(d.target_system, d.target_component),
        M::PARAM_REQUEST_LIST(d) => both(d.target_system, d.target_component),
        M::PARAM_REQUEST_READ(d) => both(d.target_system, d.target_component),
        M::PARAM_SET(d) => both(d.target_system, d.target_component),
        M::MANUAL_CONTROL(d) => (Some(d.target), None),
        M::SET_MODE(d) => (Some(d.target_system), None),
        M::MISSION_COUNT(d) => both(d.target_system, d.target_component),
        M::MISSION_REQUEST_LIST(d) => both(d.target_system, d.target_component),
        M::MISSION_REQUEST_INT(d) => both(d.target_system, d.target_component),
        M::MISSION_REQUEST(d) => both(d.target_system, d.target_component),
        M::MISSION_ACK(d) => both(d.target_system, d.target_component),
        M::MISSION_CLEAR_ALL(d) => both(d.target_system, d.target_component),
        M::MISSION_SET_CURRENT(d) => both(d.target_system, d.target_component),
        M::MISSION_ITEM_INT(d) => both(d.target_system, d.target_component),
        M::MISSION_ITEM(d) => both(d.target_system, d.target_component),
        M::LOG_REQUEST_LIST(d) => both(d.target_system, d.target_component),
        M::LOG_REQUEST_DATA(d) => both(d.target_system, d.target_component),
        M::LOG_REQUEST_END(d) => both(d.target_system, d.target_component),
        M::LOG_ERASE(d) => both(d.target_system, d.target_component),
        M::COMMAND_LONG(d) => both(d.target_system, d.target_component),
        M::COMMAND_INT(d) => both(d.target_system, d.target_component),
        M::HEARTBEAT(_)
        | M::HIL_SENSOR(_)
        | M::HIL_GPS(_)
        | M::HIL_STATE_QUATERNION(_)
        | M::BATTERY_STATUS(_)
        | M::DISTANCE_SENSOR(_)
        | M::RC_CHANNELS(_) => (None, None),
        other => other_targets(other),
    }
}

/// A message the autopilot's dialect does not read: only a caller of [`GroundLink::handle`]
/// with the whole common dialect's messages (the host's tests) has one.
#[cfg(not(target_os = "none"))]
fn other_targets(msg: &MavMessage) -> (Option<u8>, Option<u8>) {
    use mavlink::Message;
    (msg.target_system_id(), msg.target_component_id())
}

/// The image decodes nothing outside its dialect (`link::dialect::Autopilot`).
#[cfg(target_os = "none")]
fn other_targets(_: &MavMessage) -> (Option<u8>, Option<u8>) {
    (None, None)
}

#[cfg(test)]
mod tests;

use mavlink::dialects::common::*;
use mavlink::MavHeader;

use crate::vehicle::modes::FlightMode;
use crate::vehicle::requests::VehicleRequests;
use crate::vehicle::snapshot::VehicleSnapshot;
use commands::{CommandContext, CommandService};
use mission::{MissionManager, MissionReply};
use outbox::{Outbox, Pending};
use output::{emit, stream_message, Sources};
use params::ParamService;
use signing::Signing;
use streams::{Scheduler, Stream};

pub use commands::FORCE_ARM_MAGIC;
pub use config::{LinkConfig, Stores, COMPONENT_ID, HEARTBEAT_INTERVAL_US, SYSTEM_ID};
pub use outbox::{CommandAck, Outgoing};
pub use peer::{Dest, Origin, Peer};
pub use texts::STATUSTEXT_LEN;

/// The ground-station link: the services, and the router between them and the stations.
#[derive(Clone, Debug)]
pub struct GroundLink {
    cfg: LinkConfig,
    missions: MissionManager,
    streams: Scheduler,
    commands: CommandService,
    params: ParamService,
    outbox: Outbox,
    next_heartbeat_us: u64,
    gcs_last_seen_us: Option<u64>,
    last_mode: Option<FlightMode>,
    rx_errors: u16,
    signing: Signing,
    ftp: ftp::Ftp,
    logs: logs::LogService,
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
            commands: CommandService::new(),
            params: ParamService::new(cfg.params_per_poll),
            outbox: Outbox::default(),
            next_heartbeat_us: 0,
            gcs_last_seen_us: None,
            last_mode: None,
            rx_errors: 0,
            signing: Signing::default(),
            ftp: ftp::Ftp::new(cfg.files),
            logs: logs::LogService::new(),
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
        self.commands.take_requests()
    }

    /// Time the last ground-station heartbeat arrived, µs (for a link-loss failsafe).
    pub fn gcs_last_seen_us(&self) -> Option<u64> {
        self.gcs_last_seen_us
    }

    /// Outgoing messages dropped because the output queues were full.
    pub fn dropped(&self) -> u32 {
        self.outbox.dropped()
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
        self.outbox.texts_mut().push_str(severity, text);
    }

    /// Tells every station what the autotune reported, in words.
    pub fn send_tune_report(&mut self, r: &crate::tuning::autotune::Report) {
        let (severity, line) = tune::words(r);
        self.outbox.text(severity, &line);
    }

    /// The station whose `MAV_CMD_PREFLIGHT_STORAGE` waits for the board's save (answered
    /// `IN_PROGRESS` so far); the board saves and answers with [`GroundLink::storage_done`].
    pub fn take_storage_request(&mut self) -> Option<Peer> {
        self.commands.take_storage_request()
    }

    /// The final answer to a `MAV_CMD_PREFLIGHT_STORAGE`: ACCEPTED once the save is done,
    /// FAILED (with a status text) when the flash refused it.
    pub fn storage_done(&mut self, to: Peer, saved: bool) {
        self.commands.storage_done(to, saved, &mut self.outbox);
    }

    /// Whether a reboot was asked for (and accepted: disarmed) since the last call.
    pub fn take_reboot_request(&mut self) -> bool {
        self.commands.take_reboot_request()
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
        let (target_system, target_component) = targets(msg);
        if let Some(t) = target_system {
            if t != 0 && t != self.cfg.system_id {
                return;
            }
        }
        if let Some(c) = target_component {
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
        let out = &mut self.outbox;
        let reply = match msg {
            MavMessage::SETUP_SIGNING(d) => {
                let text = self.signing.on_setup(d, signed);
                out.texts_mut()
                    .push_str(MavSeverity::MAV_SEVERITY_INFO, text);
                None
            }
            MavMessage::FILE_TRANSFER_PROTOCOL(d) if d.target_network == 0 => {
                self.ftp.handle(d, from, now_us);
                None
            }
            MavMessage::LOG_REQUEST_LIST(d) => {
                self.logs.on_request_list(d, from);
                None
            }
            MavMessage::LOG_REQUEST_DATA(d) => {
                self.logs.on_request_data(d, from);
                None
            }
            MavMessage::LOG_REQUEST_END(_) => {
                self.logs.on_request_end();
                None
            }
            MavMessage::LOG_ERASE(_) => {
                self.logs.on_erase(vehicle.armed, out);
                None
            }
            MavMessage::HEARTBEAT(h) if h.mavtype == MavType::MAV_TYPE_GCS => {
                self.gcs_last_seen_us = Some(now_us);
                None
            }
            MavMessage::PARAM_REQUEST_LIST(_) => {
                self.params.on_request_list(channel);
                None
            }
            MavMessage::PARAM_REQUEST_READ(d) => {
                self.params.on_read(d, stores.params, from, out);
                None
            }
            MavMessage::PARAM_SET(d) => {
                self.params.on_set(d, stores.params, from, out);
                None
            }
            MavMessage::MANUAL_CONTROL(d) => {
                self.commands.on_manual_control(d, now_us);
                None
            }
            MavMessage::COMMAND_LONG(_) | MavMessage::COMMAND_INT(_) => {
                let cx = CommandContext {
                    now_us,
                    vehicle,
                    stores,
                    streams: &mut self.streams,
                    metadata: self.ftp.general().is_some(),
                    out: &mut *out,
                };
                self.commands.on_command_message(msg, from, cx);
                None
            }
            MavMessage::SET_MODE(d) => {
                self.commands
                    .on_set_mode(d, from, vehicle, stores.plan, out);
                None
            }
            MavMessage::MISSION_SET_CURRENT(d) => {
                self.commands
                    .on_mission_set_current(d, from, stores.plan, out);
                None
            }
            MavMessage::MISSION_COUNT(d) => {
                Some(
                    self.missions
                        .on_count(stores.plan, d.mission_type, d.count, from, now_us),
                )
            }
            MavMessage::MISSION_ITEM_INT(d) => {
                let plan = &mut *stores.plan;
                let r = self.missions.on_item(plan, &stores.rules, d, from, now_us);
                for w in self.missions.take_warnings().iter() {
                    out.text(
                        MavSeverity::MAV_SEVERITY_WARNING,
                        &MissionManager::warning_text(w),
                    );
                }
                r
            }
            // Float items lose precision; this autopilot asks for MISSION_ITEM_INT only.
            MavMessage::MISSION_ITEM(d) if self.missions.busy() => {
                self.missions.on_ack(d.mission_type, from);
                Some(MissionReply::Ack(
                    d.mission_type,
                    MavMissionResult::MAV_MISSION_UNSUPPORTED,
                ))
            }
            MavMessage::MISSION_REQUEST_LIST(d) => {
                Some(
                    self.missions
                        .on_request_list(stores.plan, d.mission_type, from, now_us),
                )
            }
            MavMessage::MISSION_REQUEST_INT(d) => {
                Some(
                    self.missions
                        .on_request(stores.plan, d.mission_type, d.seq, from, now_us),
                )
            }
            // Legacy request: answered with MISSION_ITEM_INT all the same.
            MavMessage::MISSION_REQUEST(d) => {
                Some(
                    self.missions
                        .on_request(stores.plan, d.mission_type, d.seq, from, now_us),
                )
            }
            MavMessage::MISSION_ACK(d) => {
                self.missions.on_ack(d.mission_type, from);
                None
            }
            MavMessage::MISSION_CLEAR_ALL(d) => {
                Some(self.missions.on_clear(stores.plan, d.mission_type))
            }
            _ => None,
        };
        if let Some(r) = reply {
            out.push_to(Pending::Mission(r, from), from.dest());
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
        self.outbox
            .push_to(Pending::Unsupported { command, to }, to.dest());
    }

    /// The vehicle's mission progress: a new current item (MISSION_CURRENT at once, besides
    /// the 1 Hz stream) and an item finished (MISSION_ITEM_REACHED), as PX4 reports them.
    pub fn mission_progress(&mut self, current: Option<u16>, reached: Option<u16>) {
        if let Some(seq) = reached {
            self.outbox.push(Pending::ItemReached(seq));
        }
        if let Some(seq) = current {
            self.outbox.push(Pending::MissionCurrent(Some(seq)));
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
        self.commands.poll_autotune(v, now_us, &mut self.outbox);
        let intended = self.commands.intended_mode(v);
        while let Some((p, dest)) = self.outbox.pop() {
            if let Pending::Unsupported { command, to } = p {
                let ack = CommandAck {
                    command,
                    result: MavResult::MAV_RESULT_UNSUPPORTED,
                    target: to.address(),
                };
                out_raw(dest, Outgoing::Ack(ack));
                continue;
            }
            let src = self.sources(now_us, v, stores, intended);
            emit(p, dest, &src, &mut |d, m| out_raw(d, Outgoing::Message(m)));
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
        self.outbox.texts_mut().drain(out);
        if let Some((reply, to)) = self.missions.poll(now_us) {
            let src = self.sources(now_us, v, stores, intended);
            emit(Pending::Mission(reply, to), to.dest(), &src, out);
        }
        if self.last_mode != Some(v.mode) {
            if self.last_mode.is_some() {
                out(Dest::All, telemetry::current_mode(v, intended));
            }
            self.last_mode = Some(v.mode);
        }
        self.params.stream(stores.params, out);
        let mut due: heapless::Vec<Stream, { streams::STREAM_COUNT }> = heapless::Vec::new();
        self.streams.run(now_us, |s| {
            let _ = due.push(s);
        });
        let src = self.sources(now_us, v, stores, intended);
        for s in due {
            if let Some(m) = stream_message(s, &src) {
                out(Dest::All, m);
            }
        }
    }

    /// Whether a log-protocol request waits for [`GroundLink::serve_logs`].
    pub fn logs_busy(&self) -> bool {
        self.logs.busy() || self.ftp.wants_logs()
    }

    /// Serves the log protocol's requests from the board's `store` (listing, downloading,
    /// erasing), in at most `room` bytes of the board's output (see [`logs`] for how much of
    /// it telemetry keeps); the board calls it after [`GroundLink::poll`], so the streams
    /// have taken their room first. A status text it queues goes out at the next poll.
    pub fn serve_logs<F: FnMut(Dest, Outgoing)>(
        &mut self,
        store: &mut dyn logs::LogStore,
        armed: bool,
        room: usize,
        mut out: F,
    ) {
        // The files first (a station waits for each answer), then the log protocol, in what
        // room is left.
        let mut pace = logs::Pace::new(room, armed);
        while pace.data_fits(logs::FTP_FRAME) {
            let Some((m, to)) = self.ftp.serve_logs(store, pace.packets_mut()) else {
                break;
            };
            out(to.dest(), Outgoing::Message(m));
            pace.spend(logs::FTP_FRAME);
        }
        self.logs.serve(store, &mut pace, &mut self.outbox, |d, m| {
            out(d, Outgoing::Message(m))
        });
    }

    /// What the queued answers and the streams are built from at this poll.
    fn sources<'a, 'b>(
        &'a self,
        now_us: u64,
        vehicle: &'a VehicleSnapshot,
        stores: &'a Stores<'b>,
        intended: FlightMode,
    ) -> Sources<'a, 'b> {
        Sources {
            now_us,
            vehicle,
            stores,
            ftp: &self.ftp,
            intended,
            rx_errors: self.rx_errors,
            uid: self.cfg.uid,
        }
    }
}
