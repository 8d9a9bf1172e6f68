//! What the queued answers and the due streams become at a poll: each built from the
//! vehicle's snapshot and the stores at the moment it is sent, not when it was asked for.

use super::commands::autopilot_version;
use super::config::Stores;
use super::ftp::{self, Ftp};
use super::mission::mission_message;
use super::outbox::Pending;
use super::params::param_value;
use super::peer::Dest;
use super::streams::Stream;
use super::telemetry;
use crate::navigation::plan::{MissionStore, PlanKind};
use crate::vehicle::modes::FlightMode;
use crate::vehicle::snapshot::VehicleSnapshot;
use mavlink::dialects::common::*;

/// What a message is built from at a poll.
pub(crate) struct Sources<'a, 'b> {
    /// The time of the poll, µs.
    pub now_us: u64,
    /// The vehicle as it is.
    pub vehicle: &'a VehicleSnapshot,
    /// The parameters and the plan.
    pub stores: &'a Stores<'b>,
    /// The files served (the metadata's URI and CRC).
    pub ftp: &'a Ftp,
    /// The mode the vehicle will fly (a requested one that it has not taken yet).
    pub intended: FlightMode,
    /// Frames the transport could not decode (`SYS_STATUS.errors_comm`).
    pub rx_errors: u16,
    /// The board's unique id (`AUTOPILOT_VERSION`).
    pub uid: u64,
}

/// The ids of the stored mission, fence and rally lists.
fn mission_ids(s: &MissionStore) -> (u32, u32, u32) {
    (
        s.opaque_id(PlanKind::Mission),
        s.opaque_id(PlanKind::Fence),
        s.opaque_id(PlanKind::Rally),
    )
}

/// The message of a stream; `None` when it has nothing to say (no home yet).
pub(crate) fn stream_message(s: Stream, src: &Sources<'_, '_>) -> Option<MavMessage> {
    let (v, now_us, plan) = (src.vehicle, src.now_us, &*src.stores.plan);
    Some(match s {
        Stream::SysStatus => telemetry::sys_status(v, src.rx_errors),
        Stream::GpsRawInt => telemetry::gps_raw_int(v),
        Stream::Attitude => telemetry::attitude(v, now_us),
        Stream::GlobalPositionInt => telemetry::global_position_int(v, now_us),
        Stream::MissionCurrent => telemetry::mission_current(
            v,
            v.mission_seq,
            plan.mission.len() as u16,
            mission_ids(plan),
        ),
        Stream::NavControllerOutput => telemetry::nav_controller_output(v),
        Stream::VfrHud => telemetry::vfr_hud(v),
        Stream::BatteryStatus => telemetry::battery_status(v),
        Stream::HomePosition => telemetry::home_position(v, now_us)?,
        Stream::ExtendedSysState => telemetry::extended_sys_state(v),
        Stream::CurrentMode => telemetry::current_mode(v, src.intended),
        Stream::ServoOutputRaw => telemetry::servo_output_raw(v, now_us),
    })
}

/// Sends a queued answer to `dest`.
pub(crate) fn emit<F: FnMut(Dest, MavMessage)>(
    p: Pending,
    dest: Dest,
    src: &Sources<'_, '_>,
    out: &mut F,
) {
    let (v, now_us, stores) = (src.vehicle, src.now_us, src.stores);
    let mut out = |m| out(dest, m);
    match p {
        // Sent as raw data by the poll.
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
            if let Some(f) = src.ftp.general() {
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
            progress,
            to,
        } => out(MavMessage::COMMAND_ACK(COMMAND_ACK_DATA {
            command,
            result,
            progress,
            result_param2: 0,
            target_system: to.system,
            target_component: to.component,
        })),
        Pending::ParamValue(i) => {
            if let Some(m) = param_value(stores.params, usize::from(i)) {
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
            mission_ids(stores.plan),
        )),
        Pending::ItemReached(seq) => out(MavMessage::MISSION_ITEM_REACHED(
            MISSION_ITEM_REACHED_DATA { seq },
        )),
        Pending::AutopilotVersion => out(autopilot_version(src.uid, !src.ftp.files().is_empty())),
        Pending::AvailableMode(i) => {
            if let Some(m) = FlightMode::ALL.get(usize::from(i)) {
                out(telemetry::available_mode(usize::from(i), *m));
            }
        }
        Pending::CurrentMode => out(telemetry::current_mode(v, src.intended)),
        Pending::Heartbeat => out(telemetry::heartbeat(v)),
        Pending::Stream(s) => {
            if let Some(m) = stream_message(s, src) {
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
