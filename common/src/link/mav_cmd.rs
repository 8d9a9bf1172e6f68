//! The messages that carry a MAV_CMD number (`COMMAND_LONG`, `COMMAND_INT`, `MISSION_ITEM_INT`,
//! `MISSION_ITEM`), decoded with the number turned into the `mavlink` crate's [`MavCmd`] by a
//! table.
//!
//! The crate's decoders turn the number into a `MavCmd` through `FromPrimitive`, a comparison
//! with each of the dialect's 171 commands: 1.9 KB of an MCU image's code. The same answer
//! comes from a binary search of the commands sorted by number (4 bytes each). The decoders
//! here read the fields in the crate's order and fail with the crate's errors; the tests hold
//! both to the crate's for every 16-bit number and for payloads of every length.

// MISSION_ITEM and a few commands are deprecated; ground stations still send them.
#![allow(deprecated)]

use mavlink::dialects::common::{
    MavCmd, MavFrame, MavMissionType, COMMAND_INT_DATA, COMMAND_LONG_DATA, MISSION_ITEM_DATA,
    MISSION_ITEM_INT_DATA,
};
use mavlink::error::ParserError;
use num_traits::FromPrimitive;

/// Every command of the common dialect, in increasing order of its number.
static BY_NUMBER: [MavCmd; 171] = [
    MavCmd::MAV_CMD_NAV_WAYPOINT,
    MavCmd::MAV_CMD_NAV_LOITER_UNLIM,
    MavCmd::MAV_CMD_NAV_LOITER_TURNS,
    MavCmd::MAV_CMD_NAV_LOITER_TIME,
    MavCmd::MAV_CMD_NAV_RETURN_TO_LAUNCH,
    MavCmd::MAV_CMD_NAV_LAND,
    MavCmd::MAV_CMD_NAV_TAKEOFF,
    MavCmd::MAV_CMD_NAV_LAND_LOCAL,
    MavCmd::MAV_CMD_NAV_TAKEOFF_LOCAL,
    MavCmd::MAV_CMD_NAV_FOLLOW,
    MavCmd::MAV_CMD_NAV_CONTINUE_AND_CHANGE_ALT,
    MavCmd::MAV_CMD_NAV_LOITER_TO_ALT,
    MavCmd::MAV_CMD_DO_FOLLOW,
    MavCmd::MAV_CMD_DO_FOLLOW_REPOSITION,
    MavCmd::MAV_CMD_DO_ORBIT,
    MavCmd::MAV_CMD_DO_FIGURE_EIGHT,
    MavCmd::MAV_CMD_NAV_ARC_WAYPOINT,
    MavCmd::MAV_CMD_NAV_ROI,
    MavCmd::MAV_CMD_NAV_PATHPLANNING,
    MavCmd::MAV_CMD_NAV_SPLINE_WAYPOINT,
    MavCmd::MAV_CMD_NAV_VTOL_TAKEOFF,
    MavCmd::MAV_CMD_NAV_VTOL_LAND,
    MavCmd::MAV_CMD_NAV_GUIDED_ENABLE,
    MavCmd::MAV_CMD_NAV_DELAY,
    MavCmd::MAV_CMD_NAV_PAYLOAD_PLACE,
    MavCmd::MAV_CMD_NAV_LAST,
    MavCmd::MAV_CMD_CONDITION_DELAY,
    MavCmd::MAV_CMD_CONDITION_CHANGE_ALT,
    MavCmd::MAV_CMD_CONDITION_DISTANCE,
    MavCmd::MAV_CMD_CONDITION_YAW,
    MavCmd::MAV_CMD_CONDITION_LAST,
    MavCmd::MAV_CMD_DO_SET_MODE,
    MavCmd::MAV_CMD_DO_JUMP,
    MavCmd::MAV_CMD_DO_CHANGE_SPEED,
    MavCmd::MAV_CMD_DO_SET_HOME,
    MavCmd::MAV_CMD_DO_SET_PARAMETER,
    MavCmd::MAV_CMD_DO_SET_RELAY,
    MavCmd::MAV_CMD_DO_REPEAT_RELAY,
    MavCmd::MAV_CMD_DO_SET_SERVO,
    MavCmd::MAV_CMD_DO_REPEAT_SERVO,
    MavCmd::MAV_CMD_DO_FLIGHTTERMINATION,
    MavCmd::MAV_CMD_DO_CHANGE_ALTITUDE,
    MavCmd::MAV_CMD_DO_SET_ACTUATOR,
    MavCmd::MAV_CMD_DO_RETURN_PATH_START,
    MavCmd::MAV_CMD_DO_LAND_START,
    MavCmd::MAV_CMD_DO_RALLY_LAND,
    MavCmd::MAV_CMD_DO_GO_AROUND,
    MavCmd::MAV_CMD_DO_REPOSITION,
    MavCmd::MAV_CMD_DO_PAUSE_CONTINUE,
    MavCmd::MAV_CMD_DO_SET_REVERSE,
    MavCmd::MAV_CMD_DO_SET_ROI_LOCATION,
    MavCmd::MAV_CMD_DO_SET_ROI_WPNEXT_OFFSET,
    MavCmd::MAV_CMD_DO_SET_ROI_NONE,
    MavCmd::MAV_CMD_DO_SET_ROI_SYSID,
    MavCmd::MAV_CMD_DO_CONTROL_VIDEO,
    MavCmd::MAV_CMD_DO_SET_ROI,
    MavCmd::MAV_CMD_DO_DIGICAM_CONFIGURE,
    MavCmd::MAV_CMD_DO_DIGICAM_CONTROL,
    MavCmd::MAV_CMD_DO_MOUNT_CONFIGURE,
    MavCmd::MAV_CMD_DO_MOUNT_CONTROL,
    MavCmd::MAV_CMD_DO_SET_CAM_TRIGG_DIST,
    MavCmd::MAV_CMD_DO_FENCE_ENABLE,
    MavCmd::MAV_CMD_DO_PARACHUTE,
    MavCmd::MAV_CMD_DO_MOTOR_TEST,
    MavCmd::MAV_CMD_DO_INVERTED_FLIGHT,
    MavCmd::MAV_CMD_DO_GRIPPER,
    MavCmd::MAV_CMD_DO_AUTOTUNE_ENABLE,
    MavCmd::MAV_CMD_NAV_SET_YAW_SPEED,
    MavCmd::MAV_CMD_DO_SET_CAM_TRIGG_INTERVAL,
    MavCmd::MAV_CMD_DO_MOUNT_CONTROL_QUAT,
    MavCmd::MAV_CMD_DO_GUIDED_MASTER,
    MavCmd::MAV_CMD_DO_GUIDED_LIMITS,
    MavCmd::MAV_CMD_DO_ENGINE_CONTROL,
    MavCmd::MAV_CMD_DO_SET_MISSION_CURRENT,
    MavCmd::MAV_CMD_DO_LAST,
    MavCmd::MAV_CMD_PREFLIGHT_CALIBRATION,
    MavCmd::MAV_CMD_PREFLIGHT_SET_SENSOR_OFFSETS,
    MavCmd::MAV_CMD_PREFLIGHT_UAVCAN,
    MavCmd::MAV_CMD_PREFLIGHT_STORAGE,
    MavCmd::MAV_CMD_PREFLIGHT_REBOOT_SHUTDOWN,
    MavCmd::MAV_CMD_OVERRIDE_GOTO,
    MavCmd::MAV_CMD_OBLIQUE_SURVEY,
    MavCmd::MAV_CMD_DO_SET_STANDARD_MODE,
    MavCmd::MAV_CMD_MISSION_START,
    MavCmd::MAV_CMD_ACTUATOR_TEST,
    MavCmd::MAV_CMD_CONFIGURE_ACTUATOR,
    MavCmd::MAV_CMD_COMPONENT_ARM_DISARM,
    MavCmd::MAV_CMD_RUN_PREARM_CHECKS,
    MavCmd::MAV_CMD_ILLUMINATOR_ON_OFF,
    MavCmd::MAV_CMD_DO_ILLUMINATOR_CONFIGURE,
    MavCmd::MAV_CMD_GET_HOME_POSITION,
    MavCmd::MAV_CMD_INJECT_FAILURE,
    MavCmd::MAV_CMD_START_RX_PAIR,
    MavCmd::MAV_CMD_GET_MESSAGE_INTERVAL,
    MavCmd::MAV_CMD_SET_MESSAGE_INTERVAL,
    MavCmd::MAV_CMD_REQUEST_MESSAGE,
    MavCmd::MAV_CMD_REQUEST_PROTOCOL_VERSION,
    MavCmd::MAV_CMD_REQUEST_AUTOPILOT_CAPABILITIES,
    MavCmd::MAV_CMD_REQUEST_CAMERA_INFORMATION,
    MavCmd::MAV_CMD_REQUEST_CAMERA_SETTINGS,
    MavCmd::MAV_CMD_REQUEST_STORAGE_INFORMATION,
    MavCmd::MAV_CMD_STORAGE_FORMAT,
    MavCmd::MAV_CMD_REQUEST_CAMERA_CAPTURE_STATUS,
    MavCmd::MAV_CMD_REQUEST_FLIGHT_INFORMATION,
    MavCmd::MAV_CMD_RESET_CAMERA_SETTINGS,
    MavCmd::MAV_CMD_SET_CAMERA_MODE,
    MavCmd::MAV_CMD_SET_CAMERA_ZOOM,
    MavCmd::MAV_CMD_SET_CAMERA_FOCUS,
    MavCmd::MAV_CMD_SET_STORAGE_USAGE,
    MavCmd::MAV_CMD_SET_CAMERA_SOURCE,
    MavCmd::MAV_CMD_JUMP_TAG,
    MavCmd::MAV_CMD_DO_JUMP_TAG,
    MavCmd::MAV_CMD_DO_SET_GLOBAL_ORIGIN,
    MavCmd::MAV_CMD_DO_GIMBAL_MANAGER_PITCHYAW,
    MavCmd::MAV_CMD_DO_GIMBAL_MANAGER_CONFIGURE,
    MavCmd::MAV_CMD_IMAGE_START_CAPTURE,
    MavCmd::MAV_CMD_IMAGE_STOP_CAPTURE,
    MavCmd::MAV_CMD_REQUEST_CAMERA_IMAGE_CAPTURE,
    MavCmd::MAV_CMD_DO_TRIGGER_CONTROL,
    MavCmd::MAV_CMD_CAMERA_TRACK_POINT,
    MavCmd::MAV_CMD_CAMERA_TRACK_RECTANGLE,
    MavCmd::MAV_CMD_CAMERA_STOP_TRACKING,
    MavCmd::MAV_CMD_VIDEO_START_CAPTURE,
    MavCmd::MAV_CMD_VIDEO_STOP_CAPTURE,
    MavCmd::MAV_CMD_VIDEO_START_STREAMING,
    MavCmd::MAV_CMD_VIDEO_STOP_STREAMING,
    MavCmd::MAV_CMD_REQUEST_VIDEO_STREAM_INFORMATION,
    MavCmd::MAV_CMD_REQUEST_VIDEO_STREAM_STATUS,
    MavCmd::MAV_CMD_LOGGING_START,
    MavCmd::MAV_CMD_LOGGING_STOP,
    MavCmd::MAV_CMD_AIRFRAME_CONFIGURATION,
    MavCmd::MAV_CMD_CONTROL_HIGH_LATENCY,
    MavCmd::MAV_CMD_PANORAMA_CREATE,
    MavCmd::MAV_CMD_DO_VTOL_TRANSITION,
    MavCmd::MAV_CMD_ARM_AUTHORIZATION_REQUEST,
    MavCmd::MAV_CMD_SET_GUIDED_SUBMODE_STANDARD,
    MavCmd::MAV_CMD_SET_GUIDED_SUBMODE_CIRCLE,
    MavCmd::MAV_CMD_CONDITION_GATE,
    MavCmd::MAV_CMD_NAV_FENCE_RETURN_POINT,
    MavCmd::MAV_CMD_NAV_FENCE_POLYGON_VERTEX_INCLUSION,
    MavCmd::MAV_CMD_NAV_FENCE_POLYGON_VERTEX_EXCLUSION,
    MavCmd::MAV_CMD_NAV_FENCE_CIRCLE_INCLUSION,
    MavCmd::MAV_CMD_NAV_FENCE_CIRCLE_EXCLUSION,
    MavCmd::MAV_CMD_NAV_RALLY_POINT,
    MavCmd::MAV_CMD_UAVCAN_GET_NODE_INFO,
    MavCmd::MAV_CMD_DO_SET_SAFETY_SWITCH_STATE,
    MavCmd::MAV_CMD_DO_ADSB_OUT_IDENT,
    MavCmd::MAV_CMD_PAYLOAD_PREPARE_DEPLOY,
    MavCmd::MAV_CMD_PAYLOAD_CONTROL_DEPLOY,
    MavCmd::MAV_CMD_WAYPOINT_USER_1,
    MavCmd::MAV_CMD_WAYPOINT_USER_2,
    MavCmd::MAV_CMD_WAYPOINT_USER_3,
    MavCmd::MAV_CMD_WAYPOINT_USER_4,
    MavCmd::MAV_CMD_WAYPOINT_USER_5,
    MavCmd::MAV_CMD_SPATIAL_USER_1,
    MavCmd::MAV_CMD_SPATIAL_USER_2,
    MavCmd::MAV_CMD_SPATIAL_USER_3,
    MavCmd::MAV_CMD_SPATIAL_USER_4,
    MavCmd::MAV_CMD_SPATIAL_USER_5,
    MavCmd::MAV_CMD_USER_1,
    MavCmd::MAV_CMD_USER_2,
    MavCmd::MAV_CMD_USER_3,
    MavCmd::MAV_CMD_USER_4,
    MavCmd::MAV_CMD_USER_5,
    MavCmd::MAV_CMD_CAN_FORWARD,
    MavCmd::MAV_CMD_FIXED_MAG_CAL_YAW,
    MavCmd::MAV_CMD_DO_WINCH,
    MavCmd::MAV_CMD_GUIDED_CHANGE_SPEED,
    MavCmd::MAV_CMD_GUIDED_CHANGE_ALTITUDE,
    MavCmd::MAV_CMD_GUIDED_CHANGE_HEADING,
    MavCmd::MAV_CMD_EXTERNAL_POSITION_ESTIMATE,
];

/// The command numbered `number`; `None` for a number the common dialect does not know (as
/// `MavCmd::from_u32`).
pub fn mav_cmd(number: u32) -> Option<MavCmd> {
    let i = BY_NUMBER
        .binary_search_by_key(&number, |c| *c as u32)
        .ok()?;
    BY_NUMBER.get(i).copied()
}

/// A payload read field by field in the order of the wire, little-endian, as zero-extended to
/// the message's length (MAVLink 2 cuts a payload's trailing zeros); bytes past the message's
/// fields are not read. Every field's reader answers a `Result`, as the crate's decoders do.
struct Fields<'a>(core::slice::Iter<'a, u8>);

impl Fields<'_> {
    fn bytes<const N: usize>(&mut self) -> [u8; N] {
        let mut out = [0; N];
        for o in &mut out {
            *o = self.0.next().copied().unwrap_or(0);
        }
        out
    }

    fn f32(&mut self) -> Result<f32, ParserError> {
        Ok(f32::from_le_bytes(self.bytes()))
    }

    fn i32(&mut self) -> Result<i32, ParserError> {
        Ok(i32::from_le_bytes(self.bytes()))
    }

    fn u16(&mut self) -> Result<u16, ParserError> {
        Ok(u16::from_le_bytes(self.bytes()))
    }

    fn u8(&mut self) -> Result<u8, ParserError> {
        let [b] = self.bytes();
        Ok(b)
    }

    fn command(&mut self) -> Result<MavCmd, ParserError> {
        let n = self.u16()?;
        mav_cmd(u32::from(n)).ok_or(ParserError::InvalidEnum {
            enum_type: "MavCmd",
            value: u64::from(n),
        })
    }

    fn frame(&mut self) -> Result<MavFrame, ParserError> {
        let n = self.u8()?;
        MavFrame::from_u8(n).ok_or(ParserError::InvalidEnum {
            enum_type: "MavFrame",
            value: u64::from(n),
        })
    }

    fn mission_type(&mut self) -> Result<MavMissionType, ParserError> {
        let n = self.u8()?;
        MavMissionType::from_u8(n).ok_or(ParserError::InvalidEnum {
            enum_type: "MavMissionType",
            value: u64::from(n),
        })
    }
}

/// A decoder `$name` of message `$T` from its fields in the order of the wire, each read by
/// the [`Fields`] reader named after it; an enumeration's number it does not know is the
/// error, the first in that order.
macro_rules! decoder {
    ($(#[$doc:meta])* $name:ident -> $T:ident { $($field:ident: $read:ident),* $(,)? }) => {
        $(#[$doc])*
        ///
        /// # Errors
        /// [`ParserError::InvalidEnum`] for a command, frame or mission type number the common
        /// dialect does not know, as the crate's decoder.
        pub fn $name(payload: &[u8]) -> Result<$T, ParserError> {
            let mut f = Fields(payload.iter());
            Ok($T { $($field: f.$read()?,)* })
        }
    };
}

decoder! {
    /// `COMMAND_LONG` from its payload, as `COMMAND_LONG_DATA::deser`.
    command_long -> COMMAND_LONG_DATA {
        param1: f32, param2: f32, param3: f32, param4: f32, param5: f32, param6: f32, param7: f32,
        command: command, target_system: u8, target_component: u8, confirmation: u8,
    }
}

decoder! {
    /// `COMMAND_INT` from its payload, as `COMMAND_INT_DATA::deser`.
    command_int -> COMMAND_INT_DATA {
        param1: f32, param2: f32, param3: f32, param4: f32, x: i32, y: i32, z: f32,
        command: command, target_system: u8, target_component: u8, frame: frame, current: u8,
        autocontinue: u8,
    }
}

decoder! {
    /// `MISSION_ITEM_INT` from its payload, as `MISSION_ITEM_INT_DATA::deser`.
    mission_item_int -> MISSION_ITEM_INT_DATA {
        param1: f32, param2: f32, param3: f32, param4: f32, x: i32, y: i32, z: f32, seq: u16,
        command: command, target_system: u8, target_component: u8, frame: frame, current: u8,
        autocontinue: u8, mission_type: mission_type,
    }
}

/// `MISSION_ITEM` from its payload, as `MISSION_ITEM_DATA::deser`: the layout of
/// `MISSION_ITEM_INT` with `x` and `y` as `f32` (one decoder for both is 0.3 KB less code).
///
/// # Errors
/// As [`mission_item_int`].
pub fn mission_item(payload: &[u8]) -> Result<MISSION_ITEM_DATA, ParserError> {
    let d = mission_item_int(payload)?;
    Ok(MISSION_ITEM_DATA {
        param1: d.param1,
        param2: d.param2,
        param3: d.param3,
        param4: d.param4,
        x: f32::from_bits(d.x as u32),
        y: f32::from_bits(d.y as u32),
        z: d.z,
        seq: d.seq,
        command: d.command,
        target_system: d.target_system,
        target_component: d.target_component,
        frame: d.frame,
        current: d.current,
        autocontinue: d.autocontinue,
        mission_type: d.mission_type,
    })
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use mavlink::{MavlinkVersion, MessageData};
    use std::format;

    #[test]
    fn the_table_answers_as_the_crates_from_primitive_for_every_number() {
        for n in (0..=u32::from(u16::MAX)).chain([65_536, 1 << 20, u32::MAX]) {
            assert_eq!(mav_cmd(n), MavCmd::from_u32(n), "{n}");
        }
    }

    #[test]
    fn the_table_is_strictly_increasing() {
        assert!(BY_NUMBER.windows(2).all(|w| (w[0] as u32) < (w[1] as u32)));
    }

    /// Payloads of every length up to the message's and a byte more, their bytes from a
    /// xorshift; every command number at the command's place of a full payload.
    fn payloads(len: usize, command_at: usize) -> impl Iterator<Item = std::vec::Vec<u8>> {
        let mut state = 0x2545_F491_u32;
        let mut byte = move || {
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            // Half of them small: frame and mission type numbers the dialect knows.
            if state & 1 == 0 {
                (state >> 8) as u8 & 0x07
            } else {
                (state >> 8) as u8
            }
        };
        let noise: std::vec::Vec<std::vec::Vec<u8>> = (0..4000)
            .map(|i| (0..(i % (len + 2))).map(|_| byte()).collect())
            .collect();
        let every_command = (0..=u16::MAX).map(move |n| {
            let mut p = std::vec![0u8; len];
            p[command_at..command_at + 2].copy_from_slice(&n.to_le_bytes());
            p
        });
        noise.into_iter().chain(every_command)
    }

    const V2: MavlinkVersion = MavlinkVersion::V2;

    /// `ours` answers as the crate's decoder `D::deser` on every payload: the same message, or
    /// the same error.
    fn decodes_as_the_crate<D: MessageData + PartialEq + core::fmt::Debug>(
        ours: fn(&[u8]) -> Result<D, ParserError>,
        command_at: usize,
    ) {
        for p in payloads(D::ENCODED_LEN, command_at) {
            let theirs = D::deser(V2, &p);
            match (ours(&p), theirs) {
                // Bit for bit: NaN parameters are not equal to themselves.
                (Ok(a), Ok(b)) => {
                    let (mut x, mut y) = ([0u8; 255], [0u8; 255]);
                    let (n, m) = (a.ser(V2, &mut x), b.ser(V2, &mut y));
                    assert_eq!((&x[..n], format!("{a:?}")), (&y[..m], format!("{b:?}")));
                }
                (Err(a), Err(b)) => assert_eq!(format!("{a:?}"), format!("{b:?}"), "{p:?}"),
                (a, b) => panic!("{p:?}: {a:?} against the crate's {b:?}"),
            }
        }
    }

    #[test]
    fn the_decoders_answer_as_the_crates_for_payloads_of_every_length_and_every_command() {
        decodes_as_the_crate::<COMMAND_LONG_DATA>(command_long, 28);
        decodes_as_the_crate::<COMMAND_INT_DATA>(command_int, 28);
        decodes_as_the_crate::<MISSION_ITEM_INT_DATA>(mission_item_int, 30);
        decodes_as_the_crate::<MISSION_ITEM_DATA>(mission_item, 30);
    }
}
