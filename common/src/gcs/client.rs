//! What a ground station sends the autopilot, built once for every ground station in the
//! workspace (the simulator's scripted one, the system tests' clients, the link's own tests):
//! its heartbeat and a `COMMAND_LONG`.

use super::config::{COMPONENT_ID, SYSTEM_ID};
use mavlink::dialects::common::{
    MavAutopilot, MavCmd, MavMessage, MavModeFlag, MavState, MavType, COMMAND_LONG_DATA,
    HEARTBEAT_DATA,
};

/// A ground station's heartbeat, as QGroundControl sends it once a second.
pub fn gcs_heartbeat() -> MavMessage {
    MavMessage::HEARTBEAT(HEARTBEAT_DATA {
        custom_mode: 0,
        mavtype: MavType::MAV_TYPE_GCS,
        autopilot: MavAutopilot::MAV_AUTOPILOT_INVALID,
        base_mode: MavModeFlag::empty(),
        system_status: MavState::MAV_STATE_ACTIVE,
        mavlink_version: 3,
    })
}

/// `COMMAND_LONG` of `command` with `params` (param1..param7) to this autopilot
/// ([`SYSTEM_ID`], [`COMPONENT_ID`]), first transmission.
pub fn command_long(command: MavCmd, params: [f32; 7]) -> MavMessage {
    let [param1, param2, param3, param4, param5, param6, param7] = params;
    MavMessage::COMMAND_LONG(COMMAND_LONG_DATA {
        param1,
        param2,
        param3,
        param4,
        param5,
        param6,
        param7,
        command,
        target_system: SYSTEM_ID,
        target_component: COMPONENT_ID,
        confirmation: 0,
    })
}
