//! Which messages a side of a link reads and writes: the autopilot's own dialect, and the whole
//! common set for the host's tools.
//!
//! The `mavlink` crate's `MavMessage::parse` and `MavMessage::ser` match every message of the
//! common dialect (over 220 of them), so whoever calls them links every message's decoder and
//! encoder: some 200 KB of an MCU image that speaks about forty. [`Autopilot`] keeps the
//! crate's types (`MavMessage` and its `*_DATA` structs, so the link logic, the host's tools and
//! the tests share them) and calls the crate's own per-message `deser`/`ser` and `EXTRA_CRC`
//! for the messages the autopilot reads and writes, and no others; [`Common`] is the crate's
//! whole dialect. A frame of a message the autopilot does not read is what a frame of an id
//! the common dialect does not know is to the host's tools: counted as an unknown id and
//! dropped.

use super::mav_cmd;
use crate::crc::crc16_mcrf4xx;
use mavlink::dialects::common::*;
use mavlink::error::ParserError;
use mavlink::{MAVLinkV2MessageRaw, MavHeader, MavlinkVersion, Message, MessageData};

/// The messages one side of a link reads and writes.
pub trait Dialect {
    /// The `CRC_EXTRA` of message `id` if this side reads it; `None`: an unknown id here.
    fn extra_crc(id: u32) -> Option<u8>;

    /// Decodes the payload of a frame of message `id` (whose checksum matched).
    ///
    /// # Errors
    /// [`ParserError::UnknownMessage`] for an id this side does not read, or the message's
    /// own decoding error (an enum value it does not know, ...).
    fn decode(version: MavlinkVersion, id: u32, payload: &[u8]) -> Result<MavMessage, ParserError>;

    /// Encodes `message` as a MAVLink 2 frame with `header` into `raw` (a fresh buffer);
    /// `None` for a message this side does not write. Into the caller's buffer: a frame
    /// returned by value is a copy of some 290 bytes per message on the board.
    fn encode_into(
        header: MavHeader,
        message: &MavMessage,
        raw: &mut MAVLinkV2MessageRaw,
    ) -> Option<()>;

    /// [`Dialect::encode_into`] a new buffer.
    fn encode(header: MavHeader, message: &MavMessage) -> Option<MAVLinkV2MessageRaw> {
        let mut raw = MAVLinkV2MessageRaw::new();
        Self::encode_into(header, message, &mut raw)?;
        Some(raw)
    }
}

/// The whole common dialect, as the `mavlink` crate has it: the host's tools (simulator,
/// scripted ground station, tests) read and write every message.
#[derive(Clone, Copy, Debug, Default)]
pub struct Common;

impl Dialect for Common {
    fn extra_crc(id: u32) -> Option<u8> {
        MavMessage::default_message_from_id(id).map(|_| MavMessage::extra_crc(id))
    }

    fn decode(version: MavlinkVersion, id: u32, payload: &[u8]) -> Result<MavMessage, ParserError> {
        MavMessage::parse(version, id, payload)
    }

    fn encode_into(
        header: MavHeader,
        message: &MavMessage,
        raw: &mut MAVLinkV2MessageRaw,
    ) -> Option<()> {
        raw.serialize_message(header, message);
        Some(())
    }
}

/// A payload written into a MAVLink 2 frame's buffer: its length, the message's id and its
/// `CRC_EXTRA`.
pub(crate) type Payload = (usize, u32, u8);

/// Writes `data`'s payload into `raw` with the `mavlink` crate's `ser` (its trailing zeros
/// cut), for [`finish_v2`].
pub(crate) fn write_payload<D: MessageData>(
    raw: &mut MAVLinkV2MessageRaw,
    data: &D,
) -> Option<Payload> {
    let payload = raw.as_mut_slice().get_mut(V2_HEAD..V2_HEAD + 255)?;
    Some((data.ser(MavlinkVersion::V2, payload), D::ID, D::EXTRA_CRC))
}

/// The start marker and the nine bytes of a MAVLink 2 header.
const V2_HEAD: usize = 10;

/// Writes the header and checksum of an unsigned MAVLink 2 frame around the payload
/// [`write_payload`] wrote, as the `mavlink` crate's `serialize_message_data` does. The crate's
/// function reads its header size back from the buffer, and its bounds checks, inlined into
/// this crate's code in the MCU image, would be panic sites of ours
/// (`tests/tests/panic_sites.rs`). `None` for a system id over 255 (MAVLink's 32-bit system
/// ids, which the autopilot never has).
pub(crate) fn finish_v2(
    raw: &mut MAVLinkV2MessageRaw,
    header: MavHeader,
    (len, id, extra_crc): Payload,
) -> Option<()> {
    let system = u8::try_from(header.system_id).ok()?;
    let buf = raw.as_mut_slice();
    let id = id.to_le_bytes();
    let head = [
        0xFD,
        u8::try_from(len).ok()?,
        0,
        0,
        header.sequence,
        system,
        header.component_id,
        id[0],
        id[1],
        id[2],
    ];
    *<&mut [u8; V2_HEAD]>::try_from(buf.get_mut(..V2_HEAD)?).ok()? = head;
    let end = V2_HEAD.checked_add(len)?;
    let crc = crc16_mcrf4xx(crc16_mcrf4xx(0xFFFF, buf.get(1..end)?), &[extra_crc]);
    *<&mut [u8; 2]>::try_from(buf.get_mut(end..end.checked_add(2)?)?).ok()? = crc.to_le_bytes();
    Some(())
}

/// Writes the autopilot's dialect from three lists of `MavMessage` variants and their data
/// types: the messages it reads with the crate's decoders, those it reads with a decoder of
/// this crate's, and the messages it writes.
// The autopilot still answers the deprecated messages ground stations send (SET_MODE,
// MISSION_ITEM, ...), so the dialect names them.
macro_rules! autopilot_dialect {
    (
        reads: [$($r:ident($rd:ident)),* $(,)?],
        reads_by: [$($o:ident($od:ident) by $of:path),* $(,)?],
        writes: [$($w:ident($wd:ident)),* $(,)?] $(,)?
    ) => {
        #[allow(deprecated)]
        mod ids {
            use super::*;
            pub(super) const READS: &[u32] = &[$($rd::ID,)* $($od::ID),*];
            pub(super) const WRITES: &[u32] = &[$($wd::ID),*];
        }

        /// The messages the autopilot reads and writes (the ground link's and the simulator
        /// link's), on the MCU and in SITL alike.
        #[derive(Clone, Copy, Debug, Default)]
        pub struct Autopilot;

        impl Autopilot {
            /// The ids of the messages the autopilot reads.
            pub const READS: &'static [u32] = ids::READS;
            /// The ids of the messages the autopilot writes.
            pub const WRITES: &'static [u32] = ids::WRITES;
        }

        #[allow(deprecated)]
        impl Dialect for Autopilot {
            fn extra_crc(id: u32) -> Option<u8> {
                match id {
                    $($rd::ID => Some($rd::EXTRA_CRC),)*
                    $($od::ID => Some($od::EXTRA_CRC),)*
                    _ => None,
                }
            }

            fn decode(
                version: MavlinkVersion,
                id: u32,
                payload: &[u8],
            ) -> Result<MavMessage, ParserError> {
                match id {
                    $($rd::ID => $rd::deser(version, payload).map(MavMessage::$r),)*
                    $($od::ID => $of(payload).map(MavMessage::$o),)*
                    _ => Err(ParserError::UnknownMessage { id }),
                }
            }

            fn encode_into(
                header: MavHeader,
                message: &MavMessage,
                raw: &mut MAVLinkV2MessageRaw,
            ) -> Option<()> {
                let payload = match message {
                    $(MavMessage::$w(d) => write_payload(raw, d),)*
                    _ => None,
                }?;
                finish_v2(raw, header, payload)?;
                Some(())
            }
        }
    };
}

autopilot_dialect! {
    reads: [
        // Ground link (gcs::GroundLink::handle).
        HEARTBEAT(HEARTBEAT_DATA),
        SETUP_SIGNING(SETUP_SIGNING_DATA),
        FILE_TRANSFER_PROTOCOL(FILE_TRANSFER_PROTOCOL_DATA),
        PARAM_REQUEST_LIST(PARAM_REQUEST_LIST_DATA),
        PARAM_REQUEST_READ(PARAM_REQUEST_READ_DATA),
        PARAM_SET(PARAM_SET_DATA),
        MANUAL_CONTROL(MANUAL_CONTROL_DATA),
        SET_MODE(SET_MODE_DATA),
        MISSION_COUNT(MISSION_COUNT_DATA),
        MISSION_REQUEST_LIST(MISSION_REQUEST_LIST_DATA),
        MISSION_REQUEST_INT(MISSION_REQUEST_INT_DATA),
        MISSION_REQUEST(MISSION_REQUEST_DATA),
        MISSION_ACK(MISSION_ACK_DATA),
        MISSION_CLEAR_ALL(MISSION_CLEAR_ALL_DATA),
        MISSION_SET_CURRENT(MISSION_SET_CURRENT_DATA),
        LOG_REQUEST_LIST(LOG_REQUEST_LIST_DATA),
        LOG_REQUEST_DATA(LOG_REQUEST_DATA_DATA),
        LOG_REQUEST_END(LOG_REQUEST_END_DATA),
        LOG_ERASE(LOG_ERASE_DATA),
        // Simulator link (firmware's app::simlink).
        HIL_SENSOR(HIL_SENSOR_DATA),
        HIL_GPS(HIL_GPS_DATA),
        HIL_STATE_QUATERNION(HIL_STATE_QUATERNION_DATA),
        BATTERY_STATUS(BATTERY_STATUS_DATA),
        DISTANCE_SENSOR(DISTANCE_SENSOR_DATA),
        RC_CHANNELS(RC_CHANNELS_DATA),
    ],
    // Ground link: the messages that carry a MAV_CMD number, decoded without the crate's
    // conversion of the number (`mav_cmd`).
    reads_by: [
        COMMAND_LONG(COMMAND_LONG_DATA) by mav_cmd::command_long,
        COMMAND_INT(COMMAND_INT_DATA) by mav_cmd::command_int,
        MISSION_ITEM_INT(MISSION_ITEM_INT_DATA) by mav_cmd::mission_item_int,
        MISSION_ITEM(MISSION_ITEM_DATA) by mav_cmd::mission_item,
    ],
    writes: [
        // Ground link: telemetry (gcs::telemetry) ...
        HEARTBEAT(HEARTBEAT_DATA),
        SYS_STATUS(SYS_STATUS_DATA),
        ATTITUDE(ATTITUDE_DATA),
        GLOBAL_POSITION_INT(GLOBAL_POSITION_INT_DATA),
        GPS_RAW_INT(GPS_RAW_INT_DATA),
        VFR_HUD(VFR_HUD_DATA),
        SERVO_OUTPUT_RAW(SERVO_OUTPUT_RAW_DATA),
        NAV_CONTROLLER_OUTPUT(NAV_CONTROLLER_OUTPUT_DATA),
        HOME_POSITION(HOME_POSITION_DATA),
        EXTENDED_SYS_STATE(EXTENDED_SYS_STATE_DATA),
        BATTERY_STATUS(BATTERY_STATUS_DATA),
        MISSION_CURRENT(MISSION_CURRENT_DATA),
        CURRENT_MODE(CURRENT_MODE_DATA),
        AVAILABLE_MODES(AVAILABLE_MODES_DATA),
        NAMED_VALUE_INT(NAMED_VALUE_INT_DATA),
        // ... and the protocols' answers.
        AUTOPILOT_VERSION(AUTOPILOT_VERSION_DATA),
        PROTOCOL_VERSION(PROTOCOL_VERSION_DATA),
        COMPONENT_METADATA(COMPONENT_METADATA_DATA),
        COMMAND_ACK(COMMAND_ACK_DATA),
        MESSAGE_INTERVAL(MESSAGE_INTERVAL_DATA),
        STATUSTEXT(STATUSTEXT_DATA),
        PARAM_VALUE(PARAM_VALUE_DATA),
        PARAM_ERROR(PARAM_ERROR_DATA),
        FILE_TRANSFER_PROTOCOL(FILE_TRANSFER_PROTOCOL_DATA),
        MISSION_COUNT(MISSION_COUNT_DATA),
        MISSION_ITEM_INT(MISSION_ITEM_INT_DATA),
        MISSION_REQUEST_INT(MISSION_REQUEST_INT_DATA),
        MISSION_ACK(MISSION_ACK_DATA),
        MISSION_ITEM_REACHED(MISSION_ITEM_REACHED_DATA),
        LOG_ENTRY(LOG_ENTRY_DATA),
        LOG_DATA(LOG_DATA_DATA),
        // Simulator link.
        HIL_ACTUATOR_CONTROLS(HIL_ACTUATOR_CONTROLS_DATA),
    ],
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use crate::link::framing::{FrameParser, Sender};
    use std::vec::Vec;

    /// xorshift: deterministic payload bytes, half of them small (enum values, flags).
    fn noise(state: &mut u32, n: usize) -> Vec<u8> {
        (0..n)
            .map(|_| {
                *state ^= *state << 13;
                *state ^= *state >> 17;
                *state ^= *state << 5;
                let b = (*state >> 8) as u8;
                if *state & 1 == 0 {
                    b & 0x03
                } else {
                    b
                }
            })
            .collect()
    }

    /// Messages of `id` that the whole common dialect decodes from noise: the crate's own
    /// decoder is the expectation every message of the autopilot's dialect is held to.
    fn samples(id: u32) -> Vec<MavMessage> {
        let len = MavMessage::default_message_from_id(id)
            .map(|m| {
                let mut buf = [0u8; 255];
                m.ser(MavlinkVersion::V2, &mut buf);
                buf.len()
            })
            .unwrap_or(255);
        let mut state = 0x9E37_79B9 ^ id;
        let mut out = Vec::new();
        for _ in 0..2000 {
            if let Ok(m) = MavMessage::parse(MavlinkVersion::V2, id, &noise(&mut state, len)) {
                out.push(m);
                if out.len() == 8 {
                    break;
                }
            }
        }
        out
    }

    fn header(sequence: u8) -> MavHeader {
        MavHeader {
            system_id: 1,
            component_id: 1,
            sequence,
        }
    }

    #[test]
    fn every_message_the_autopilot_writes_encodes_byte_for_byte_as_the_common_dialect_does() {
        for &id in Autopilot::WRITES {
            let msgs = samples(id);
            assert!(msgs.len() >= 2, "no varied samples of message {id}");
            for (i, m) in msgs.iter().enumerate() {
                let h = header(i as u8);
                let ours = Autopilot::encode(h, m).expect("a message the autopilot writes");
                let theirs = Common::encode(h, m).unwrap();
                assert_eq!(ours.raw_bytes(), theirs.raw_bytes(), "message {id}");
            }
        }
    }

    #[test]
    fn every_message_the_autopilot_reads_decodes_as_the_common_dialect_decodes_it() {
        for &id in Autopilot::READS {
            let msgs = samples(id);
            assert!(msgs.len() >= 2, "no varied samples of message {id}");
            let mut tx = Sender::new(1, 1);
            let mut ours = FrameParser::autopilot();
            let mut theirs = FrameParser::new();
            let (mut got, mut want) = (Vec::new(), Vec::new());
            for m in &msgs {
                let frame = tx.encode(m);
                ours.push(frame.raw_bytes(), |f| got.push(f.message));
                theirs.push(frame.raw_bytes(), |f| want.push(f.message));
            }
            assert_eq!(got.len(), msgs.len(), "message {id}: {:?}", ours.stats());
            assert_eq!(got, want, "message {id}");
            assert_eq!(
                Autopilot::extra_crc(id),
                Some(MavMessage::extra_crc(id)),
                "{id}"
            );
        }
    }

    #[test]
    fn a_message_the_autopilot_does_not_speak_is_an_unknown_id_and_the_next_frame_arrives() {
        let gimbal = MavMessage::GIMBAL_DEVICE_INFORMATION(GIMBAL_DEVICE_INFORMATION_DATA {
            vendor_name: "gimbals".into(),
            ..Default::default()
        });
        let mut tx = Sender::new(255, 190);
        let mut bytes = tx.encode(&gimbal).raw_bytes().to_vec();
        bytes.extend(
            tx.encode(&MavMessage::HEARTBEAT(HEARTBEAT_DATA::default()))
                .raw_bytes(),
        );

        let mut host = FrameParser::new();
        let mut n = 0;
        host.push(&bytes, |_| n += 1);
        assert_eq!((n, host.stats().unknown_ids), (2, 0), "the host reads both");

        let mut ours = FrameParser::autopilot();
        let mut got = Vec::new();
        ours.push(&bytes, |f| got.push(f.message));
        assert!(
            matches!(got.as_slice(), [MavMessage::HEARTBEAT(_)]),
            "{got:?}"
        );
        let st = ours.stats();
        assert_eq!((st.unknown_ids, st.crc_errors, st.parse_errors), (1, 0, 0));

        // Nor does the autopilot write it, and it spends no sequence number on it.
        let mut ap = Sender::autopilot(1, 1);
        assert!(ap.try_encode(&gimbal).is_none());
        let hb = ap.try_encode(&MavMessage::HEARTBEAT(HEARTBEAT_DATA::default()));
        assert_eq!(hb.map(|r| r.sequence()), Some(0));
    }
}
