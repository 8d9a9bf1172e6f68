//! The scripted ground station: parameters, arming (retried each second until the autopilot
//! accepts), then timed commands, each a COMMAND_LONG answered by a COMMAND_ACK.

use super::onboard::Onboard;
use crate::link::lockstep::Lockstep;
use crate::link::transport::Transport;
use common::link::framing::{FrameParser, Sender};
use mavlink::dialects::common::{
    MavCmd, MavMessage, MavParamType, MavResult, COMMAND_LONG_DATA, PARAM_SET_DATA,
};
use serde::Serialize;

/// System id of the ground station (QGroundControl's).
pub const GCS_SYSTEM_ID: u8 = 255;
/// Component id of the ground station (MAV_COMP_ID_MISSIONPLANNER, what QGC uses).
pub const GCS_COMPONENT_ID: u8 = 190;
/// PX4 main mode ALTCTL (the autopilot's "Altitude").
pub const PX4_ALTCTL: u8 = 2;
/// PX4 main mode POSCTL (the autopilot's "Hold": course, altitude and airspeed hold).
pub const PX4_POSCTL: u8 = 3;

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
    /// First arming attempt, s of simulated time.
    pub first_arm_s: f64,
    /// Retry period while arming is refused, s.
    pub arm_retry_s: f64,
    /// Commands after arming, in time order.
    pub steps: Vec<ScriptStep>,
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
        }
    }

    /// When the autopilot accepted arming, s.
    pub fn armed_at_s(&self) -> Option<f64> {
        self.armed_at_s
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
                self.send(t_s, link, onboard, &msg);
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
                    let (what, msg) = self.encode(&step.action.clone());
                    self.command(t_s, &what, link, onboard, &msg);
                }
            }
            None => {}
        }
        // Telemetry keeps flowing; read it so nothing is dropped and texts are kept.
        self.send_bytes(t_s, link, onboard, &[]);
    }

    fn encode(&self, a: &Action) -> (String, MavMessage) {
        match *a {
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
        let acks = self.send(t_s, link, onboard, msg);
        let result = acks.into_iter().find(|(c, _)| Some(*c) == cmd).map(|x| x.1);
        self.commands.push(CommandRecord {
            t_s,
            what: what.to_string(),
            result: result.map_or("none".into(), |r| format!("{r:?}")),
        });
        result
    }

    fn send<T: Transport, O: Onboard<T>>(
        &mut self,
        t_s: f64,
        link: &mut Lockstep<T>,
        onboard: &mut O,
        msg: &MavMessage,
    ) -> Vec<(MavCmd, MavResult)> {
        let raw = self.sender.encode(msg);
        self.send_bytes(t_s, link, onboard, raw.raw_bytes())
    }

    /// Hands `bytes` to the autopilot's ground link and reads everything it has to say.
    fn send_bytes<T: Transport, O: Onboard<T>>(
        &mut self,
        t_s: f64,
        link: &mut Lockstep<T>,
        onboard: &mut O,
        bytes: &[u8],
    ) -> Vec<(MavCmd, MavResult)> {
        let mut answer = Vec::new();
        onboard.with_app(link, |app| {
            if !bytes.is_empty() {
                app.on_gcs_bytes(bytes);
            }
            app.drain_gcs(&mut |b| answer.extend_from_slice(b));
        });
        let mut acks = Vec::new();
        let texts = &mut self.texts;
        self.parser.push(&answer, |f| match &f.message {
            MavMessage::COMMAND_ACK(a) => acks.push((a.command, a.result)),
            MavMessage::STATUSTEXT(s) => {
                let text = s.text.to_str().unwrap_or("").to_string();
                texts.push((t_s, text));
            }
            _ => {}
        });
        acks
    }
}

fn mode_name(main: u8) -> &'static str {
    match main {
        PX4_ALTCTL => "Altitude",
        PX4_POSCTL => "Hold",
        _ => "other",
    }
}

fn command(cmd: MavCmd, p: [f32; 4]) -> MavMessage {
    MavMessage::COMMAND_LONG(COMMAND_LONG_DATA {
        command: cmd,
        param1: p[0],
        param2: p[1],
        param3: p[2],
        param4: p[3],
        target_system: 1,
        target_component: 1,
        ..Default::default()
    })
}
