//! The scripted ground station: a heartbeat every second (as QGroundControl sends it),
//! parameters, the mission and geofence uploaded with the mission protocol, arming (retried
//! each second until the autopilot accepts), then timed commands, each a COMMAND_LONG answered
//! by a COMMAND_ACK.
//!
//! Each request waits for its answer (PARAM_VALUE, the next MISSION_REQUEST_INT or the
//! MISSION_ACK, COMMAND_ACK) before the next sensor frame goes out. The autopilot handles a
//! ground frame as it arrives, so the request has taken effect at the same frame whether the
//! autopilot runs in this process or beyond a UDP socket and a UART.

use super::onboard::{Await, Onboard};
use crate::link::lockstep::Lockstep;
use crate::link::tlog::{split_frames, TlogWriter};
use crate::link::transport::Transport;
use common::gcs::client::{command_long, gcs_heartbeat};
use common::gcs::Dest;
use common::link::framing::{FrameParser, Sender};
use common::vehicle::modes::FlightMode;
use mavlink::dialects::common::{
    MavCmd, MavLandedState, MavMessage, MavMissionResult, MavMissionType, MavParamType, MavResult,
    MISSION_COUNT_DATA, MISSION_ITEM_INT_DATA, PARAM_REQUEST_READ_DATA, PARAM_SET_DATA,
};
use serde::Serialize;

/// How long the station listens after the last frame of a flight: the frames of that frame
/// (the last MISSION_ITEM_REACHED, the disarming) cross a UART, the bridge and a socket.
const LAST_WORDS: std::time::Duration = std::time::Duration::from_millis(300);

/// System id of the ground station (QGroundControl's).
pub const GCS_SYSTEM_ID: u8 = 255;
/// Component id of the ground station (MAV_COMP_ID_MISSIONPLANNER, what QGC uses).
pub const GCS_COMPONENT_ID: u8 = 190;
/// PX4 main mode STABILIZED (roll and pitch held, the sticks command them).
pub const PX4_STABILIZED: u8 = FlightMode::Stabilized.px4().0;
/// PX4 main mode ALTCTL (the autopilot's "Altitude").
pub const PX4_ALTCTL: u8 = FlightMode::Altitude.px4().0;
/// PX4 main mode POSCTL (the autopilot's "Hold": course, altitude and airspeed hold).
pub const PX4_POSCTL: u8 = FlightMode::Hold.px4().0;
/// PX4 main mode AUTO (the navigator's modes).
pub const PX4_AUTO: u8 = FlightMode::Loiter.px4().0;
/// PX4 AUTO sub-mode LOITER.
pub const PX4_AUTO_LOITER: u8 = FlightMode::Loiter.px4().1;

/// One ground-station command.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub enum Action {
    /// `MAV_CMD_DO_SET_MODE` with a PX4 main mode.
    Mode(u8),
    /// `MAV_CMD_DO_CHANGE_ALTITUDE` above the field (home), m; sent as AMSL (frame 0) from
    /// the field elevation the pilot knows, so it does not depend on where the autopilot
    /// happened to set its home.
    AltitudeAboveHome(f32),
    /// `MAV_CMD_DO_CHANGE_SPEED`, airspeed, m/s.
    Airspeed(f32),
    /// `MAV_CMD_CONDITION_YAW` relative to the current course setpoint, deg (positive right).
    Turn(f32),
    /// `MAV_CMD_MISSION_START`: fly the uploaded mission from its current item.
    MissionStart,
    /// `MAV_CMD_NAV_TAKEOFF` (QGroundControl's Takeoff action): the Takeoff mode, a runway
    /// take-off along the present heading to `NAV_RTL_ALT`, then a circle there.
    Takeoff,
    /// `MAV_CMD_NAV_RETURN_TO_LAUNCH`.
    Return,
    /// `MAV_CMD_DO_SET_MODE` AUTO.LOITER: circle here.
    Loiter,
    /// `MAV_CMD_DO_AUTOTUNE_ENABLE`: start (`true`) or stop / revert (`false`) the autotune.
    Autotune(bool),
    /// `PARAM_REQUEST_READ` of each parameter named, its `PARAM_VALUE` recorded.
    ReadParams(Vec<String>),
    /// Stop sending heartbeats (the ground link is lost).
    Silence,
    /// Send heartbeats again, the first at once (the ground link is back).
    Resume,
}

/// A command at a time after arming.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ScriptStep {
    /// Seconds after the autopilot accepted arming.
    pub after_arm_s: f64,
    /// What to send.
    pub action: Action,
}

/// The whole ground-station script.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Script {
    /// Parameters set (PARAM_SET) at the first frame, before arming.
    pub params: Vec<(String, f32)>,
    /// Streams asked for at the first frame, after the parameters
    /// (`MAV_CMD_SET_MESSAGE_INTERVAL`, as QGroundControl's MAVLink Inspector and MAVProxy's
    /// `long` command send it): message id and rate, Hz.
    pub message_rates: Vec<(u32, f32)>,
    /// First arming attempt, s of simulated time.
    pub first_arm_s: f64,
    /// Retry period while arming is refused, s.
    pub arm_retry_s: f64,
    /// Commands after arming, in time order.
    pub steps: Vec<ScriptStep>,
    /// Mission uploaded (MISSION_COUNT, then each item on request) before arming.
    #[serde(skip)]
    pub mission: Vec<MISSION_ITEM_INT_DATA>,
    /// Geofence uploaded before arming.
    #[serde(skip)]
    pub fence: Vec<MISSION_ITEM_INT_DATA>,
}

impl Script {
    /// The thesis's flight, flown in Hold: the +100 m climb (100 to 200 m above home), a
    /// rectangle of four 90 degree right turns 30 s apart, and a +-10 m altitude doublet.
    pub fn thesis() -> Self {
        let s = |t: f64, action| ScriptStep {
            after_arm_s: t,
            action,
        };
        Self {
            params: Vec::new(),
            message_rates: Vec::new(),
            first_arm_s: 1.0,
            arm_retry_s: 1.0,
            steps: vec![
                s(0.0, Action::Mode(PX4_POSCTL)),
                s(5.0, Action::AltitudeAboveHome(200.0)),
                s(75.0, Action::Turn(90.0)),
                s(105.0, Action::Turn(90.0)),
                s(135.0, Action::Turn(90.0)),
                s(165.0, Action::Turn(90.0)),
                s(195.0, Action::AltitudeAboveHome(210.0)),
                s(220.0, Action::AltitudeAboveHome(190.0)),
                s(245.0, Action::AltitudeAboveHome(200.0)),
            ],
            mission: Vec::new(),
            fence: Vec::new(),
        }
    }

    /// Time after arming by which the script has been flown, with 25 s to settle.
    pub fn length_s(&self) -> f64 {
        self.steps.last().map_or(0.0, |s| s.after_arm_s) + 25.0
    }
}

/// What the autopilot answered to one command.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CommandRecord {
    /// Simulated time it was sent, s.
    pub t_s: f64,
    /// What was sent.
    pub what: String,
    /// The COMMAND_ACK result (`MAV_RESULT_*`), or `none` when no ACK came.
    pub result: String,
}

/// The ground station's state.
pub struct GroundStation {
    script: Script,
    home_alt_amsl_m: f64,
    sender: Sender,
    parser: FrameParser,
    params_sent: bool,
    next_arm_s: f64,
    armed_at_s: Option<f64>,
    next_step: usize,
    /// Every command and its answer.
    pub commands: Vec<CommandRecord>,
    /// STATUSTEXT messages from the autopilot: time, text.
    pub texts: Vec<(f64, String)>,
    /// Uploads: what (mission or fence), time, the final MISSION_ACK result.
    pub uploads: Vec<(String, f64, String)>,
    /// MISSION_ITEM_REACHED: time, item.
    pub reached: Vec<(f64, u16)>,
    /// Parameters read (PARAM_VALUE): time, name, value.
    pub params_read: Vec<(f64, String, f32)>,
    /// The landed state of EXTENDED_SYS_STATE each time it changed: time, state.
    pub landed_states: Vec<(f64, MavLandedState)>,
    /// When the autopilot first accepted `MAV_CMD_MISSION_START`, s.
    mission_started_s: Option<f64>,
    uploaded: bool,
    next_heartbeat_s: f64,
    silent: bool,
    /// Frames the station took from the autopilot's queue for the stations beside it
    /// (`Some` when there are any).
    beside: Option<Vec<(Dest, Vec<u8>)>>,
    /// The station's own view of the link, both ways, as a ground station records it.
    tlog: Option<TlogWriter>,
}

impl GroundStation {
    /// A ground station flying `script` at a field `home_alt_amsl_m` above mean sea level.
    pub fn new(script: Script, home_alt_amsl_m: f64) -> Self {
        Self {
            next_arm_s: script.first_arm_s,
            script,
            home_alt_amsl_m,
            sender: Sender::new(GCS_SYSTEM_ID, GCS_COMPONENT_ID),
            parser: FrameParser::new(),
            params_sent: false,
            armed_at_s: None,
            next_step: 0,
            commands: Vec::new(),
            texts: Vec::new(),
            uploads: Vec::new(),
            reached: Vec::new(),
            params_read: Vec::new(),
            landed_states: Vec::new(),
            mission_started_s: None,
            uploaded: false,
            next_heartbeat_s: 0.0,
            silent: false,
            beside: None,
            tlog: None,
        }
    }

    /// Records the station's link, both ways, into `tlog` (the flight's `.tlog`).
    pub fn with_tlog(mut self, tlog: TlogWriter) -> Self {
        self.tlog = Some(tlog);
        self
    }

    /// Hands every frame it takes from the autopilot on to [`Self::take_beside`] as well,
    /// for stations on a port beside the script.
    pub fn with_stations_beside(mut self) -> Self {
        self.beside = Some(Vec::new());
        self
    }

    /// The frames taken for the stations beside the script since the last call, each with
    /// where the autopilot addressed it.
    pub fn take_beside(&mut self) -> Vec<(Dest, Vec<u8>)> {
        self.beside.as_mut().map(std::mem::take).unwrap_or_default()
    }

    /// Flushes and hands back the `.tlog` writer, if any.
    pub fn finish_tlog(&mut self) -> std::io::Result<Option<TlogWriter>> {
        if let Some(t) = self.tlog.as_mut() {
            t.flush()?;
        }
        Ok(self.tlog.take())
    }

    /// When the autopilot accepted arming, s.
    pub fn armed_at_s(&self) -> Option<f64> {
        self.armed_at_s
    }

    /// When the autopilot first accepted the mission's start (`MAV_CMD_MISSION_START`), s.
    pub fn mission_started_s(&self) -> Option<f64> {
        self.mission_started_s
    }

    /// The script.
    pub fn script(&self) -> &Script {
        &self.script
    }

    /// Does what is due at simulated time `t_s` and reads the autopilot's answers.
    pub fn poll<T: Transport, O: Onboard<T>>(
        &mut self,
        t_s: f64,
        link: &mut Lockstep<T>,
        onboard: &mut O,
    ) {
        if !self.params_sent {
            self.params_sent = true;
            for (name, value) in self.script.params.clone() {
                let msg = MavMessage::PARAM_SET(PARAM_SET_DATA {
                    param_value: value,
                    target_system: 1,
                    target_component: 1,
                    param_id: name.as_str().into(),
                    param_type: MavParamType::MAV_PARAM_TYPE_REAL32,
                });
                let mut done = |m: &MavMessage| matches!(m, MavMessage::PARAM_VALUE(v) if v.param_id.to_str().is_ok_and(|id| id == name));
                self.exchange(t_s, link, onboard, &msg, Await::Answer(&mut done));
            }
            for (id, hz) in self.script.message_rates.clone() {
                let msg = command(
                    MavCmd::MAV_CMD_SET_MESSAGE_INTERVAL,
                    [id as f32, (1e6 / f64::from(hz)) as f32, 0.0, 0.0],
                );
                let name = <MavMessage as mavlink::Message>::default_message_from_id(id)
                    .map_or_else(
                        || id.to_string(),
                        |m| mavlink::Message::message_name(&m).to_string(),
                    );
                self.command(t_s, &format!("{name} at {hz} Hz"), link, onboard, &msg);
            }
        }
        if !self.silent && t_s >= self.next_heartbeat_s {
            self.next_heartbeat_s = t_s + 1.0;
            self.exchange(t_s, link, onboard, &gcs_heartbeat(), Await::Nothing);
        }
        if !self.uploaded {
            self.uploaded = true;
            for (what, kind) in [
                ("mission", MavMissionType::MAV_MISSION_TYPE_MISSION),
                ("fence", MavMissionType::MAV_MISSION_TYPE_FENCE),
            ] {
                let items = match kind {
                    MavMissionType::MAV_MISSION_TYPE_FENCE => self.script.fence.clone(),
                    _ => self.script.mission.clone(),
                };
                if !items.is_empty() {
                    let r = self.upload(t_s, link, onboard, kind, &items);
                    self.uploads.push((what.to_string(), t_s, format!("{r:?}")));
                }
            }
        }
        match self.armed_at_s {
            None if t_s >= self.next_arm_s => {
                self.next_arm_s = t_s + self.script.arm_retry_s;
                let msg = command(MavCmd::MAV_CMD_COMPONENT_ARM_DISARM, [1.0, 0.0, 0.0, 0.0]);
                let r = self.command(t_s, "arm", link, onboard, &msg);
                if r == Some(MavResult::MAV_RESULT_ACCEPTED) {
                    self.armed_at_s = Some(t_s);
                }
            }
            Some(t0) => {
                while let Some(step) = self.script.steps.get(self.next_step) {
                    if t_s < t0 + step.after_arm_s {
                        break;
                    }
                    self.next_step += 1;
                    match &step.action {
                        Action::Silence => self.silent = true,
                        Action::ReadParams(names) => {
                            for name in names.clone() {
                                self.read_param(t_s, &name, link, onboard);
                            }
                        }
                        Action::Resume => {
                            self.silent = false;
                            self.next_heartbeat_s = t_s;
                        }
                        action => {
                            let start = *action == Action::MissionStart;
                            if let Some((what, msg)) = self.encode(&action.clone()) {
                                let r = self.command(t_s, &what, link, onboard, &msg);
                                if start && r == Some(MavResult::MAV_RESULT_ACCEPTED) {
                                    self.mission_started_s.get_or_insert(t_s);
                                }
                            }
                        }
                    }
                }
            }
            None => {}
        }
        // Telemetry keeps flowing; read it so nothing is dropped and texts are kept.
        self.send_bytes(t_s, link, onboard, &[], Await::Nothing);
    }

    /// Reads what the autopilot said about the last frame of a flight (over a real link it
    /// is still on its way).
    pub fn finish<T: Transport, O: Onboard<T>>(
        &mut self,
        t_s: f64,
        link: &mut Lockstep<T>,
        onboard: &mut O,
    ) {
        self.send_bytes(t_s, link, onboard, &[], Await::Linger(LAST_WORDS));
    }

    /// The COMMAND_LONG of a command action (`None` for the station's own link actions).
    fn encode(&self, a: &Action) -> Option<(String, MavMessage)> {
        Some(match *a {
            Action::Mode(main) => (
                format!("mode {}", mode_name(main)),
                command(
                    MavCmd::MAV_CMD_DO_SET_MODE,
                    [1.0, f32::from(main), 0.0, 0.0],
                ),
            ),
            Action::AltitudeAboveHome(h) => (
                format!("altitude {h} m above home"),
                command(
                    MavCmd::MAV_CMD_DO_CHANGE_ALTITUDE,
                    [(self.home_alt_amsl_m + f64::from(h)) as f32, 0.0, 0.0, 0.0],
                ),
            ),
            Action::Airspeed(v) => (
                format!("airspeed {v} m/s"),
                command(MavCmd::MAV_CMD_DO_CHANGE_SPEED, [0.0, v, -1.0, 0.0]),
            ),
            Action::Turn(deg) => (
                format!("turn {deg:+} deg"),
                command(
                    MavCmd::MAV_CMD_CONDITION_YAW,
                    [deg.abs(), 0.0, if deg < 0.0 { -1.0 } else { 1.0 }, 1.0],
                ),
            ),
            Action::MissionStart => (
                "mission start".into(),
                command(MavCmd::MAV_CMD_MISSION_START, [0.0; 4]),
            ),
            Action::Takeoff => (
                "takeoff".into(),
                command(MavCmd::MAV_CMD_NAV_TAKEOFF, [0.0; 4]),
            ),
            Action::Return => (
                "return".into(),
                command(MavCmd::MAV_CMD_NAV_RETURN_TO_LAUNCH, [0.0; 4]),
            ),
            Action::Loiter => (
                "mode Loiter".into(),
                command(MavCmd::MAV_CMD_DO_SET_MODE, {
                    let (main, sub) = FlightMode::Loiter.px4();
                    [1.0, f32::from(main), f32::from(sub), 0.0]
                }),
            ),
            Action::Autotune(on) => (
                if on { "autotune" } else { "autotune off" }.into(),
                command(
                    MavCmd::MAV_CMD_DO_AUTOTUNE_ENABLE,
                    [if on { 1.0 } else { 0.0 }, 0.0, 0.0, 0.0],
                ),
            ),
            Action::Silence | Action::Resume | Action::ReadParams(_) => return None,
        })
    }

    /// The mission protocol's upload: MISSION_COUNT, each item as the autopilot requests it,
    /// until its MISSION_ACK.
    fn upload<T: Transport, O: Onboard<T>>(
        &mut self,
        t_s: f64,
        link: &mut Lockstep<T>,
        onboard: &mut O,
        kind: MavMissionType,
        items: &[MISSION_ITEM_INT_DATA],
    ) -> MavMissionResult {
        let count = MavMessage::MISSION_COUNT(MISSION_COUNT_DATA {
            count: items.len() as u16,
            target_system: 1,
            target_component: 1,
            mission_type: kind,
            opaque_id: 0,
        });
        let mut done = |m: &MavMessage| match m {
            MavMessage::MISSION_ACK(a) => a.mission_type == kind,
            MavMessage::MISSION_REQUEST_INT(r) => r.mission_type == kind,
            _ => false,
        };
        let mut answer = self.exchange(t_s, link, onboard, &count, Await::Answer(&mut done));
        // Each round trip is answered at once in-process; the bound only stops a runaway.
        for _ in 0..4 * items.len() + 4 {
            let mut next = None;
            for m in &answer {
                match m {
                    MavMessage::MISSION_ACK(a) if a.mission_type == kind => return a.mavtype,
                    MavMessage::MISSION_REQUEST_INT(r) if r.mission_type == kind => {
                        next = Some(r.seq)
                    }
                    _ => {}
                }
            }
            let Some(item) = next.and_then(|seq| items.get(usize::from(seq))) else {
                break;
            };
            let mut item = item.clone();
            item.mission_type = kind;
            item.target_system = 1;
            item.target_component = 1;
            answer = self.exchange(
                t_s,
                link,
                onboard,
                &MavMessage::MISSION_ITEM_INT(item),
                Await::Answer(&mut done),
            );
        }
        MavMissionResult::MAV_MISSION_ERROR
    }

    fn exchange<T: Transport, O: Onboard<T>>(
        &mut self,
        t_s: f64,
        link: &mut Lockstep<T>,
        onboard: &mut O,
        msg: &MavMessage,
        wait: Await,
    ) -> Vec<MavMessage> {
        let raw = self.sender.encode(msg);
        self.send_bytes(t_s, link, onboard, raw.raw_bytes(), wait)
    }

    /// `PARAM_REQUEST_READ` of `name`; its `PARAM_VALUE`, when one comes, is recorded.
    fn read_param<T: Transport, O: Onboard<T>>(
        &mut self,
        t_s: f64,
        name: &str,
        link: &mut Lockstep<T>,
        onboard: &mut O,
    ) {
        let msg = MavMessage::PARAM_REQUEST_READ(PARAM_REQUEST_READ_DATA {
            param_index: -1,
            target_system: 1,
            target_component: 1,
            param_id: name.into(),
        });
        let is_it = |m: &MavMessage| matches!(m, MavMessage::PARAM_VALUE(v) if v.param_id.to_str().is_ok_and(|id| id == name));
        let mut done = is_it;
        let answer = self.exchange(t_s, link, onboard, &msg, Await::Answer(&mut done));
        if let Some(MavMessage::PARAM_VALUE(v)) = answer.iter().find(|m| is_it(m)) {
            self.params_read
                .push((t_s, name.to_string(), v.param_value));
        }
    }

    fn command<T: Transport, O: Onboard<T>>(
        &mut self,
        t_s: f64,
        what: &str,
        link: &mut Lockstep<T>,
        onboard: &mut O,
        msg: &MavMessage,
    ) -> Option<MavResult> {
        let cmd = match msg {
            MavMessage::COMMAND_LONG(c) => Some(c.command),
            _ => None,
        };
        let mut done =
            |m: &MavMessage| matches!(m, MavMessage::COMMAND_ACK(a) if Some(a.command) == cmd);
        let answer = self.exchange(t_s, link, onboard, msg, Await::Answer(&mut done));
        let result = answer.iter().find_map(|m| match m {
            MavMessage::COMMAND_ACK(a) if Some(a.command) == cmd => Some(a.result),
            _ => None,
        });
        self.commands.push(CommandRecord {
            t_s,
            what: what.to_string(),
            result: result.map_or("none".into(), |r| format!("{r:?}")),
        });
        result
    }

    /// Hands `bytes` to the autopilot's ground link and reads everything it has to say; texts
    /// and reached items are logged.
    fn send_bytes<T: Transport, O: Onboard<T>>(
        &mut self,
        t_s: f64,
        link: &mut Lockstep<T>,
        onboard: &mut O,
        bytes: &[u8],
        wait: Await,
    ) -> Vec<MavMessage> {
        let answer = onboard.talk(link, bytes, wait, self.beside.as_mut());
        if let Some(t) = self.tlog.as_mut() {
            let t_us = (t_s * 1e6).round() as u64;
            // A log that cannot be written must not stop the flight; its end says so.
            for frame in std::iter::once(bytes)
                .filter(|b| !b.is_empty())
                .chain(split_frames(&answer))
            {
                let _ = t.write(t_us, frame);
            }
        }
        let mut messages = Vec::new();
        let (texts, reached, landed) =
            (&mut self.texts, &mut self.reached, &mut self.landed_states);
        self.parser.push(&answer, |f| {
            match &f.message {
                MavMessage::STATUSTEXT(s) => {
                    let text = s.text.to_str().unwrap_or("").to_string();
                    texts.push((t_s, text));
                }
                MavMessage::MISSION_ITEM_REACHED(r) => reached.push((t_s, r.seq)),
                MavMessage::EXTENDED_SYS_STATE(x)
                    if landed.last().is_none_or(|&(_, l)| l != x.landed_state) =>
                {
                    landed.push((t_s, x.landed_state));
                }
                _ => {}
            }
            messages.push(f.message.clone());
        });
        messages
    }
}

/// The name a command's record gives a PX4 main mode: the two the scripts fly by name, every
/// other "other" (the records of flights already made say so).
fn mode_name(main: u8) -> &'static str {
    match FlightMode::from_px4(main, 0) {
        Some(m @ (FlightMode::Altitude | FlightMode::Hold)) => m.name(),
        Some(
            FlightMode::Manual
            | FlightMode::Stabilized
            | FlightMode::Mission
            | FlightMode::Loiter
            | FlightMode::Return
            | FlightMode::Takeoff
            | FlightMode::Land,
        )
        | None => "other",
    }
}

/// A command with its first four parameters, the rest 0.
fn command(cmd: MavCmd, p: [f32; 4]) -> MavMessage {
    command_long(cmd, [p[0], p[1], p[2], p[3], 0.0, 0.0, 0.0])
}
