//! Ground-station messages chosen by the fuzzer. Each is a message a station could send, its
//! fields picked so that most land where the autopilot does something (a real parameter
//! name, a command it knows, a waypoint near home) and the rest anywhere (any float bit
//! pattern, any enum number, any payload).

use arbitrary::Arbitrary;
use common::gcs::FORCE_ARM_MAGIC;
use common::navigation::plan::MissionItem;
use common::params::ParamStore;
use common::vehicle::modes::FlightMode;
use mavlink::dialects::common::*;
use mavlink::MessageData;
use num_traits::FromPrimitive;

use crate::frames::HOME;

/// A float: often one of the values where code branches, otherwise any bit pattern.
#[derive(Arbitrary, Clone, Copy, Debug)]
pub enum Float {
    Small(i8),
    Whole(i32),
    Tenths(i16),
    Special(u8),
    Bits(u32),
}

impl Float {
    pub fn get(self) -> f32 {
        match self {
            Float::Small(v) => f32::from(v),
            Float::Whole(v) => v as f32,
            Float::Tenths(v) => f32::from(v) / 10.0,
            Float::Special(i) => [
                0.0,
                -0.0,
                f32::NAN,
                f32::INFINITY,
                f32::NEG_INFINITY,
                f32::MAX,
                f32::MIN,
                f32::MIN_POSITIVE,
                f32::EPSILON,
                FORCE_ARM_MAGIC,
                1.0,
                -1.0,
                0.5,
                16_777_217.0,
                1e-45,
            ][usize::from(i) % 15],
            Float::Bits(b) => f32::from_bits(b),
        }
    }
}

/// A value for a parameter: on, near or beyond its bounds, or any float.
#[derive(Arbitrary, Clone, Copy, Debug)]
pub enum ParamValue {
    Min,
    Max,
    Default,
    /// A fraction (0..=255 over 255) of the way from min to max.
    Between(u8),
    BelowMin,
    AboveMax,
    Any(Float),
}

impl ParamValue {
    pub fn get(self, store: &ParamStore, index: usize) -> f32 {
        let Some(d) = store.def(index) else {
            return 0.0;
        };
        match self {
            ParamValue::Min => d.min,
            ParamValue::Max => d.max,
            ParamValue::Default => d.default,
            ParamValue::Between(f) => d.min + (d.max - d.min) * f32::from(f) / 255.0,
            ParamValue::BelowMin => d.min - 1.0,
            ParamValue::AboveMax => d.max + 1.0,
            ParamValue::Any(f) => f.get(),
        }
    }
}

/// A parameter name: one the store has (by index), or any bytes.
#[derive(Arbitrary, Clone, Debug)]
pub enum Name {
    Known(u16),
    Any([u8; 16]),
}

impl Name {
    pub fn id(&self, store: &ParamStore) -> [u8; 16] {
        match self {
            Name::Known(i) => {
                let mut id = [0u8; 16];
                if let Some(d) = store.def(usize::from(*i) % store.len().max(1)) {
                    let n = d.name.len().min(16);
                    id[..n].copy_from_slice(&d.name.as_bytes()[..n]);
                }
                id
            }
            Name::Any(b) => *b,
        }
    }
}

/// `mission_type`: mostly the three lists, sometimes ALL or a number the dialect lacks.
#[derive(Arbitrary, Clone, Copy, Debug)]
pub struct Kind(pub u8);

impl Kind {
    pub fn get(self) -> MavMissionType {
        match self.0 % 8 {
            0..=3 => MavMissionType::MAV_MISSION_TYPE_MISSION,
            4 => MavMissionType::MAV_MISSION_TYPE_FENCE,
            5 => MavMissionType::MAV_MISSION_TYPE_RALLY,
            _ => MavMissionType::MAV_MISSION_TYPE_ALL,
        }
    }
}

/// A mission item: a plausible one near home of a command the list holds, or anything.
#[derive(Arbitrary, Clone, Copy, Debug)]
pub enum Item {
    Near {
        command: u8,
        frame: u8,
        north: i16,
        east: i16,
        alt: i16,
        p: [Float; 4],
    },
    Any {
        command: u16,
        frame: u8,
        x: i32,
        y: i32,
        z: Float,
        p: [Float; 4],
    },
}

#[allow(deprecated)]
const FRAMES: [MavFrame; 5] = [
    MavFrame::MAV_FRAME_GLOBAL_RELATIVE_ALT_INT,
    MavFrame::MAV_FRAME_GLOBAL_RELATIVE_ALT,
    MavFrame::MAV_FRAME_GLOBAL_INT,
    MavFrame::MAV_FRAME_GLOBAL,
    MavFrame::MAV_FRAME_MISSION,
];

const COMMANDS: [u16; 17] = [
    16,   // NAV_WAYPOINT
    16,   // (twice as likely)
    17,   // NAV_LOITER_UNLIM
    18,   // NAV_LOITER_TURNS
    19,   // NAV_LOITER_TIME
    20,   // NAV_RETURN_TO_LAUNCH
    21,   // NAV_LAND
    22,   // NAV_TAKEOFF
    31,   // NAV_LOITER_TO_ALT
    177,  // DO_JUMP
    178,  // DO_CHANGE_SPEED
    179,  // DO_SET_HOME
    183,  // DO_SET_SERVO (not flown)
    5001, // FENCE_POLYGON_VERTEX_INCLUSION
    5002, // FENCE_POLYGON_VERTEX_EXCLUSION
    5003, // FENCE_CIRCLE_INCLUSION
    5100, // NAV_RALLY_POINT
];

impl Item {
    /// The item as stored: command and frame numbers as they are, whatever they name.
    pub fn raw(self) -> MissionItem {
        let (command, frame, x, y, z, p) = match self {
            Item::Near {
                command,
                frame,
                north,
                east,
                alt,
                p,
            } => (
                COMMANDS[usize::from(command) % COMMANDS.len()],
                FRAMES[usize::from(frame) % FRAMES.len()] as u8,
                HOME.lat_e7 + i32::from(north) * 90,
                HOME.lon_e7 + i32::from(east) * 130,
                f32::from(alt) / 10.0,
                p,
            ),
            Item::Any {
                command,
                frame,
                x,
                y,
                z,
                p,
            } => (command, frame, x, y, z.get(), p),
        };
        MissionItem {
            params: p.map(|f| f.get().to_bits()),
            x,
            y,
            z: z.to_bits(),
            command,
            frame,
            autocontinue: true,
        }
    }

    /// The item as sent, `None` when its command or frame number is not in the dialect (a
    /// station cannot send it as a typed message; [`GcsMsg::Raw`] covers that).
    pub fn data(self, seq: u16, kind: MavMissionType) -> Option<MISSION_ITEM_INT_DATA> {
        let it = self.raw();
        Some(MISSION_ITEM_INT_DATA {
            param1: it.param(0),
            param2: it.param(1),
            param3: it.param(2),
            param4: it.param(3),
            x: it.x,
            y: it.y,
            z: it.z_m(),
            seq,
            command: MavCmd::from_u16(it.command)?,
            target_system: 1,
            target_component: 1,
            frame: MavFrame::from_u8(it.frame)?,
            current: 0,
            autocontinue: 1,
            mission_type: kind,
        })
    }
}

/// Commands this autopilot answers, and a few it does not.
const CMDS: [MavCmd; 21] = [
    MavCmd::MAV_CMD_COMPONENT_ARM_DISARM,
    MavCmd::MAV_CMD_DO_SET_MODE,
    MavCmd::MAV_CMD_DO_SET_STANDARD_MODE,
    MavCmd::MAV_CMD_MISSION_START,
    MavCmd::MAV_CMD_NAV_RETURN_TO_LAUNCH,
    MavCmd::MAV_CMD_NAV_TAKEOFF,
    MavCmd::MAV_CMD_NAV_LAND,
    MavCmd::MAV_CMD_DO_SET_MISSION_CURRENT,
    MavCmd::MAV_CMD_DO_CHANGE_ALTITUDE,
    MavCmd::MAV_CMD_DO_CHANGE_SPEED,
    MavCmd::MAV_CMD_CONDITION_YAW,
    MavCmd::MAV_CMD_SET_MESSAGE_INTERVAL,
    MavCmd::MAV_CMD_GET_MESSAGE_INTERVAL,
    MavCmd::MAV_CMD_REQUEST_MESSAGE,
    MavCmd::MAV_CMD_REQUEST_AUTOPILOT_CAPABILITIES,
    MavCmd::MAV_CMD_PREFLIGHT_STORAGE,
    MavCmd::MAV_CMD_DO_REPOSITION,
    MavCmd::MAV_CMD_DO_FLIGHTTERMINATION,
    MavCmd::MAV_CMD_PREFLIGHT_CALIBRATION,
    MavCmd::MAV_CMD_DO_MOTOR_TEST,
    MavCmd::MAV_CMD_REQUEST_PROTOCOL_VERSION,
];

/// Message ids a ground station sends this autopilot, for [`GcsMsg::Raw`].
const IDS: [u32; 21] = [
    0, 11, 20, 21, 23, 39, 40, 41, 43, 44, 45, 47, 51, 69, 73, 75, 76, 110, 300, 66, 256,
];

/// Messages a ground station asks for with `MAV_CMD_REQUEST_MESSAGE`, and one nobody serves.
const REQUESTED: [u32; 7] = [
    HEARTBEAT_DATA::ID,
    AUTOPILOT_VERSION_DATA::ID,
    CURRENT_MODE_DATA::ID,
    PROTOCOL_VERSION_DATA::ID,
    COMPONENT_METADATA_DATA::ID,
    AVAILABLE_MODES_DATA::ID,
    12345,
];

/// MAVLink FTP opcodes: those the server answers, some it refuses, and any.
const FTP_OPS: [u8; 9] = [0, 1, 2, 4, 5, 15, 3, 6, 9];

/// Paths an FTP `OpenFileRO` names: the served files, written as QGroundControl and
/// pymavlink write them, and names that are not served.
const FTP_PATHS: [&[u8]; 7] = [
    b"general.json",
    b"/general.json",
    b"parameters.json.xz",
    b"//parameters.json.xz\0junk",
    b"@MAV_PARAMS/general.json",
    b"",
    b"/",
];

/// Secret keys a station sets up (all zero turns signing off).
pub const KEYS: [[u8; 32]; 3] = [[0; 32], [0x5A; 32], [0xC3; 32]];

/// A `SETUP_SIGNING`'s initial timestamp (10 us units since 2015).
const SIGNING_TIMES: [u64; 5] = [0, 1, 35_000_000_000_000, 0xFFFF_FFFF_FFFF, u64::MAX];

/// A MAVLink FTP request: a header as a client writes it, with any values where they vary.
#[derive(Arbitrary, Clone, Debug)]
pub struct FtpRequest {
    op: u8,
    seq: u16,
    session: u8,
    size: u8,
    /// Most offsets fall inside or just past the served files.
    offset: u32,
    far: bool,
    path: u8,
    /// Not 0: meant for another network, ignored.
    network: u8,
}

impl FtpRequest {
    fn data(&self) -> FILE_TRANSFER_PROTOCOL_DATA {
        let op = if self.op >= 200 {
            self.op
        } else {
            FTP_OPS[usize::from(self.op) % FTP_OPS.len()]
        };
        let offset = if self.far {
            self.offset
        } else {
            self.offset % 20_000
        };
        let mut payload = [0u8; 251];
        payload[..2].copy_from_slice(&self.seq.to_le_bytes());
        payload[2] = self.session % 4;
        payload[3] = op;
        payload[4] = self.size;
        payload[8..12].copy_from_slice(&offset.to_le_bytes());
        if op == 4 {
            let path = FTP_PATHS[usize::from(self.path) % FTP_PATHS.len()];
            payload[12..12 + path.len()].copy_from_slice(path);
            if self.size == 0 {
                payload[4] = path.len() as u8;
            }
        }
        FILE_TRANSFER_PROTOCOL_DATA {
            target_network: if self.network < 240 { 0 } else { self.network },
            target_system: 1,
            target_component: 1,
            payload,
        }
    }
}

/// A target: the autopilot, broadcast, or someone else.
#[derive(Arbitrary, Clone, Copy, Debug)]
pub struct Target(pub u8);

impl Target {
    pub fn get(self) -> (u8, u8) {
        match self.0 % 8 {
            0..=3 => (1, 1),
            4 => (0, 0),
            5 => (1, 0),
            6 => (2, 1),
            _ => (1, 2),
        }
    }
}

/// One message from a ground station.
#[derive(Arbitrary, Clone, Debug)]
pub enum GcsMsg {
    Heartbeat {
        gcs: bool,
    },
    Arm {
        arm: bool,
        force: bool,
    },
    Mode(u8),
    Manual {
        x: i16,
        y: i16,
        z: i16,
        r: i16,
    },
    Command {
        cmd: u8,
        p: [Float; 7],
        int: bool,
        target: Target,
    },
    SetMode {
        custom: u32,
        base: u8,
    },
    ParamSet {
        name: Name,
        value: ParamValue,
        ty: u8,
    },
    ParamRead {
        index: i16,
        name: Name,
    },
    ParamList,
    MissionCount {
        kind: Kind,
        count: u16,
    },
    MissionItem {
        seq: u16,
        kind: Kind,
        item: Item,
    },
    MissionItemFloat {
        seq: u16,
        kind: Kind,
    },
    MissionRequestList {
        kind: Kind,
    },
    MissionRequest {
        seq: u16,
        kind: Kind,
        legacy: bool,
    },
    MissionAck {
        kind: Kind,
        cancel: bool,
    },
    MissionClear {
        kind: Kind,
    },
    MissionSetCurrent {
        seq: u16,
    },
    /// `MAV_CMD_REQUEST_MESSAGE` for one of [`REQUESTED`].
    Request {
        which: u8,
    },
    /// A MAVLink FTP request.
    Ftp(FtpRequest),
    /// `SETUP_SIGNING` with one of [`KEYS`].
    SetupSigning {
        key: u8,
        time: u8,
    },
    /// Any payload for an id the link reads (the dialect may refuse it: unknown enum values,
    /// command ids it has no name for).
    Raw {
        id: u8,
        payload: Vec<u8>,
    },
}

/// What [`GcsMsg::build`] makes: a typed message, or a raw id and payload.
pub enum Built {
    Typed(MavMessage),
    Raw(u32, Vec<u8>),
}

impl GcsMsg {
    /// The message; `store` names the parameters.
    pub fn build(&self, store: &ParamStore) -> Option<Built> {
        use Built::Typed;
        let command = |command: MavCmd, p: [f32; 7]| {
            MavMessage::COMMAND_LONG(COMMAND_LONG_DATA {
                param1: p[0],
                param2: p[1],
                param3: p[2],
                param4: p[3],
                param5: p[4],
                param6: p[5],
                param7: p[6],
                command,
                target_system: 1,
                target_component: 1,
                confirmation: 0,
            })
        };
        Some(match self {
            GcsMsg::Heartbeat { gcs } => Typed(MavMessage::HEARTBEAT(HEARTBEAT_DATA {
                mavtype: if *gcs {
                    MavType::MAV_TYPE_GCS
                } else {
                    MavType::MAV_TYPE_ONBOARD_CONTROLLER
                },
                autopilot: MavAutopilot::MAV_AUTOPILOT_INVALID,
                ..HEARTBEAT_DATA::DEFAULT
            })),
            GcsMsg::Arm { arm, force } => Typed(command(
                MavCmd::MAV_CMD_COMPONENT_ARM_DISARM,
                [
                    f32::from(u8::from(*arm)),
                    if *force { FORCE_ARM_MAGIC } else { 0.0 },
                    0.0,
                    0.0,
                    0.0,
                    0.0,
                    0.0,
                ],
            )),
            GcsMsg::Mode(m) => {
                let mode = FlightMode::ALL[usize::from(*m) % FlightMode::ALL.len()];
                let (main, sub) = mode.px4();
                Typed(command(
                    MavCmd::MAV_CMD_DO_SET_MODE,
                    [1.0, f32::from(main), f32::from(sub), 0.0, 0.0, 0.0, 0.0],
                ))
            }
            GcsMsg::Manual { x, y, z, r } => {
                Typed(MavMessage::MANUAL_CONTROL(MANUAL_CONTROL_DATA {
                    x: *x,
                    y: *y,
                    z: *z,
                    r: *r,
                    target: 1,
                    ..MANUAL_CONTROL_DATA::DEFAULT
                }))
            }
            GcsMsg::Command {
                cmd,
                p,
                int,
                target,
            } => {
                let c = CMDS[usize::from(*cmd) % CMDS.len()];
                let (ts, tc) = target.get();
                let v = p.map(Float::get);
                if *int {
                    Typed(MavMessage::COMMAND_INT(COMMAND_INT_DATA {
                        param1: v[0],
                        param2: v[1],
                        param3: v[2],
                        param4: v[3],
                        x: v[4] as i32,
                        y: v[5] as i32,
                        z: v[6],
                        command: c,
                        target_system: ts,
                        target_component: tc,
                        frame: MavFrame::MAV_FRAME_GLOBAL,
                        current: 0,
                        autocontinue: 0,
                    }))
                } else {
                    let MavMessage::COMMAND_LONG(mut d) = command(c, v) else {
                        return None;
                    };
                    (d.target_system, d.target_component) = (ts, tc);
                    Typed(MavMessage::COMMAND_LONG(d))
                }
            }
            GcsMsg::SetMode { custom, base } => Typed(MavMessage::SET_MODE(SET_MODE_DATA {
                custom_mode: *custom,
                target_system: 1,
                base_mode: MavModeFlag::from_bits_truncate(*base),
            })),
            GcsMsg::ParamSet { name, value, ty } => {
                let id = name.id(store);
                let index = common::params::store::param_id_str(&id)
                    .and_then(|n| store.index_of(n))
                    .unwrap_or(0);
                let v = value.get(store, index);
                let param_type = MavParamType::from_u8(*ty % 12).unwrap_or_default();
                // An integer type carries the integer's bytes (PARAM_ENCODE_BYTEWISE).
                let param_value = if param_type != MavParamType::MAV_PARAM_TYPE_REAL32
                    && v.is_finite()
                    && *ty % 2 == 0
                {
                    f32::from_bits(v as i32 as u32)
                } else {
                    v
                };
                Typed(MavMessage::PARAM_SET(PARAM_SET_DATA {
                    param_value,
                    target_system: 1,
                    target_component: 1,
                    param_id: id.into(),
                    param_type,
                }))
            }
            GcsMsg::ParamRead { index, name } => {
                Typed(MavMessage::PARAM_REQUEST_READ(PARAM_REQUEST_READ_DATA {
                    param_index: *index,
                    target_system: 1,
                    target_component: 1,
                    param_id: name.id(store).into(),
                }))
            }
            GcsMsg::ParamList => Typed(MavMessage::PARAM_REQUEST_LIST(PARAM_REQUEST_LIST_DATA {
                target_system: 1,
                target_component: 1,
            })),
            GcsMsg::MissionCount { kind, count } => {
                Typed(MavMessage::MISSION_COUNT(MISSION_COUNT_DATA {
                    count: *count % 200,
                    target_system: 1,
                    target_component: 1,
                    mission_type: kind.get(),
                    opaque_id: 0,
                }))
            }
            GcsMsg::MissionItem { seq, kind, item } => Typed(MavMessage::MISSION_ITEM_INT(
                item.data(*seq % 200, kind.get())?,
            )),
            GcsMsg::MissionItemFloat { seq, kind } => {
                Typed(MavMessage::MISSION_ITEM(MISSION_ITEM_DATA {
                    seq: *seq,
                    target_system: 1,
                    target_component: 1,
                    mission_type: kind.get(),
                    ..MISSION_ITEM_DATA::DEFAULT
                }))
            }
            GcsMsg::MissionRequestList { kind } => Typed(MavMessage::MISSION_REQUEST_LIST(
                MISSION_REQUEST_LIST_DATA {
                    target_system: 1,
                    target_component: 1,
                    mission_type: kind.get(),
                },
            )),
            GcsMsg::MissionRequest { seq, kind, legacy } => {
                if *legacy {
                    #[allow(deprecated)]
                    Typed(MavMessage::MISSION_REQUEST(MISSION_REQUEST_DATA {
                        seq: *seq,
                        target_system: 1,
                        target_component: 1,
                        mission_type: kind.get(),
                    }))
                } else {
                    Typed(MavMessage::MISSION_REQUEST_INT(MISSION_REQUEST_INT_DATA {
                        seq: *seq,
                        target_system: 1,
                        target_component: 1,
                        mission_type: kind.get(),
                    }))
                }
            }
            GcsMsg::MissionAck { kind, cancel } => {
                Typed(MavMessage::MISSION_ACK(MISSION_ACK_DATA {
                    target_system: 1,
                    target_component: 1,
                    mavtype: if *cancel {
                        MavMissionResult::MAV_MISSION_OPERATION_CANCELLED
                    } else {
                        MavMissionResult::MAV_MISSION_ACCEPTED
                    },
                    mission_type: kind.get(),
                    opaque_id: 0,
                }))
            }
            GcsMsg::MissionClear { kind } => {
                Typed(MavMessage::MISSION_CLEAR_ALL(MISSION_CLEAR_ALL_DATA {
                    target_system: 1,
                    target_component: 1,
                    mission_type: kind.get(),
                }))
            }
            GcsMsg::MissionSetCurrent { seq } =>
            {
                #[allow(deprecated)]
                Typed(MavMessage::MISSION_SET_CURRENT(MISSION_SET_CURRENT_DATA {
                    seq: *seq,
                    target_system: 1,
                    target_component: 1,
                }))
            }
            GcsMsg::Request { which } => Typed(command(
                MavCmd::MAV_CMD_REQUEST_MESSAGE,
                [
                    REQUESTED[usize::from(*which) % REQUESTED.len()] as f32,
                    0.0,
                    0.0,
                    0.0,
                    0.0,
                    0.0,
                    0.0,
                ],
            )),
            GcsMsg::Ftp(r) => Typed(MavMessage::FILE_TRANSFER_PROTOCOL(r.data())),
            GcsMsg::SetupSigning { key, time } => {
                Typed(MavMessage::SETUP_SIGNING(SETUP_SIGNING_DATA {
                    initial_timestamp: SIGNING_TIMES[usize::from(*time) % SIGNING_TIMES.len()],
                    target_system: 1,
                    target_component: 1,
                    secret_key: KEYS[usize::from(*key) % KEYS.len()],
                }))
            }
            GcsMsg::Raw { id, payload } => {
                Built::Raw(IDS[usize::from(*id) % IDS.len()], payload.clone())
            }
        })
    }
}
