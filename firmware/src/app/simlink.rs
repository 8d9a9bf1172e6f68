//! The simulator port: `HIL_SENSOR`, `HIL_GPS`, `BATTERY_STATUS` and `DISTANCE_SENSOR` decoded with their
//! plausibility checks into the vehicle's ways in for sensors, `HIL_ACTUATOR_CONTROLS` back for every sensor frame
//! (lock-step), the radio's `RC_CHANNELS` to the sticks and the simulator's truth to the
//! vehicle for the `SIM_USE_TRUTH` comparison.

use common::control::inputs::Measurements;
use common::link::dialect::Autopilot;
use common::link::framing::{Frame, FrameParser, LinkStats, Sender};
use common::link::simlink::{self, ActuatorFrame, Rejected};
use common::vehicle::{TruthSample, Vehicle};
use mavlink::dialects::common::{MavMessage, HIL_STATE_QUATERNION_DATA};

use super::ground::GroundPort;
use super::log::FlightLog;
use common::gcs::{COMPONENT_ID, SYSTEM_ID};

/// Counters the autopilot keeps about its simulator link.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SimLinkHealth {
    /// Sensor frames accepted.
    pub sensor_frames: u32,
    /// GPS frames accepted.
    pub gps_frames: u32,
    /// Power-monitor frames (BATTERY_STATUS) accepted.
    pub battery_frames: u32,
    /// Frames from a system other than ours.
    pub foreign_frames: u32,
    /// Frames of a message the sim link does not carry.
    pub ignored_frames: u32,
    /// Sensor groups dropped as implausible, per group.
    pub rejected_imu: u32,
    /// Magnetometer groups dropped.
    pub rejected_mag: u32,
    /// Barometer groups dropped.
    pub rejected_baro: u32,
    /// Differential-pressure groups dropped.
    pub rejected_pitot: u32,
    /// GPS frames dropped.
    pub rejected_gps: u32,
    /// BATTERY_STATUS frames dropped: no voltage or current, or implausible.
    pub rejected_battery: u32,
    /// DISTANCE_SENSOR frames dropped: not looking down, or range limits that make no sense.
    pub rejected_range: u32,
    /// Sensor frames whose time did not advance.
    pub stale_frames: u32,
    /// RC_CHANNELS frames without a usable signal.
    pub rejected_rc: u32,
    /// Bytes to the ground station dropped because its buffer was full.
    pub gcs_bytes_dropped: u32,
}

/// The simulator link with its framing and counters.
pub struct SimPort {
    parser: FrameParser<Autopilot>,
    answers: Answers,
}

/// What the frames' handling needs besides the parser: borrowed apart from it, so the parser
/// is not moved out of the port and back for every chunk of bytes (two copies of its buffer).
struct Answers {
    tx: Sender<Autopilot>,
    health: SimLinkHealth,
}

impl Default for SimPort {
    fn default() -> Self {
        Self::new()
    }
}

impl SimPort {
    /// A port with the autopilot's identity and nothing received.
    /// Not inlined: see `App::fresh`.
    #[inline(never)]
    pub fn new() -> Self {
        Self {
            parser: FrameParser::autopilot(),
            answers: Answers {
                tx: Sender::autopilot(SYSTEM_ID, COMPONENT_ID),
                health: SimLinkHealth::default(),
            },
        }
    }

    /// Counters of the frames received (the vehicle's stale-frame count filled in by the app).
    pub fn health(&self) -> SimLinkHealth {
        self.answers.health
    }

    /// Framing counters.
    pub fn stats(&self) -> LinkStats {
        self.parser.stats()
    }

    /// Encodes a message from the autopilot on this link (nothing for a message outside the
    /// autopilot's dialect).
    pub fn encode(&mut self, msg: &MavMessage) -> heapless::Vec<u8, 280> {
        self.answers
            .tx
            .try_encode(msg)
            .and_then(|raw| heapless::Vec::from_slice(raw.raw_bytes()).ok())
            .unwrap_or_default()
    }

    /// Bytes the parser needs before it can check its next frame
    /// ([`FrameParser::bytes_wanted`]).
    pub fn bytes_wanted(&self) -> usize {
        self.parser.bytes_wanted()
    }

    /// Bytes from the simulator; `out` receives the answers.
    pub fn on_bytes(
        &mut self,
        bytes: &[u8],
        vehicle: &mut Vehicle,
        ground: &mut GroundPort,
        log: &mut FlightLog,
        out: &mut impl FnMut(&[u8]),
    ) {
        let answers = &mut self.answers;
        self.parser.push(bytes, |frame| {
            answers.on_frame(&frame, vehicle, ground, log, out)
        });
    }
}

impl Answers {
    fn on_frame(
        &mut self,
        frame: &Frame,
        vehicle: &mut Vehicle,
        ground: &mut GroundPort,
        log: &mut FlightLog,
        out: &mut impl FnMut(&[u8]),
    ) {
        if frame.header.system_id != u32::from(SYSTEM_ID) {
            self.health.foreign_frames += 1;
            return;
        }
        match &frame.message {
            MavMessage::HIL_SENSOR(d) => {
                let (sensors, rejected) = simlink::decode_hil_sensor(d);
                self.count_rejections(rejected);
                self.health.sensor_frames += 1;
                vehicle.on_sensors(&sensors, &ground.from_ground());
                log.after_frame(vehicle, &sensors, &ground.log_figures());
                // Texts wait while the log's opening goes out, and are not kept without a log.
                if !log.recording() {
                    ground.forget_log_texts();
                }
                while log.takes_texts() {
                    let Some((t, severity, text)) = ground.take_log_text() else {
                        break;
                    };
                    log.text(t, severity, text);
                }
                ground.poll(vehicle.time_us().unwrap_or(0), vehicle);
                // The answer names the frame it answers, in the simulator's own time.
                let answer = ActuatorFrame {
                    time_us: sensors.time_us,
                    surfaces: vehicle.surfaces(),
                    armed: vehicle.armed(),
                };
                let msg = MavMessage::HIL_ACTUATOR_CONTROLS(simlink::encode_actuators(&answer));
                let mut raw = mavlink::MAVLinkV2MessageRaw::new();
                if self.tx.try_encode_into(&msg, &mut raw).is_some() {
                    out(raw.raw_bytes());
                }
            }
            MavMessage::HIL_GPS(d) => match simlink::decode_hil_gps(d) {
                Some(fix) => {
                    self.health.gps_frames += 1;
                    vehicle.on_gps(&fix);
                }
                None => self.health.rejected_gps += 1,
            },
            MavMessage::BATTERY_STATUS(d) => match simlink::decode_battery_status(d) {
                Some(s) => {
                    self.health.battery_frames += 1;
                    vehicle.on_battery(&s);
                }
                None => self.health.rejected_battery += 1,
            },
            MavMessage::DISTANCE_SENSOR(d) => match simlink::decode_distance_sensor(d) {
                Some(s) => vehicle.on_range(&s),
                None => self.health.rejected_range += 1,
            },
            MavMessage::HIL_STATE_QUATERNION(d) => {
                if let Some(t) = truth_sample(d) {
                    vehicle.on_truth(t);
                }
            }
            MavMessage::RC_CHANNELS(d) => {
                // The radio: the sticks of the manual and stabilised modes, like a ground
                // station's MANUAL_CONTROL; a frame without signal is ignored and the sticks
                // time out.
                let t = vehicle.time_us().unwrap_or(0);
                match simlink::decode_rc_channels(d, t) {
                    Some(m) => vehicle.on_sticks(m),
                    None => self.health.rejected_rc += 1,
                }
            }
            MavMessage::HEARTBEAT(_) => {}
            _ => self.health.ignored_frames += 1,
        }
    }

    fn count_rejections(&mut self, r: Rejected) {
        self.health.rejected_imu += u32::from(r.imu);
        self.health.rejected_mag += u32::from(r.mag);
        self.health.rejected_baro += u32::from(r.baro);
        self.health.rejected_pitot += u32::from(r.pitot);
    }
}

/// Truth as the autopilot's measurements (`HIL_STATE_QUATERNION`: attitude quaternion, body
/// rates, altitude in mm, velocity in cm/s, true airspeed in cm/s).
fn truth_sample(d: &HIL_STATE_QUATERNION_DATA) -> Option<TruthSample> {
    let q = d.attitude_quaternion;
    if q.iter().any(|x| !x.is_finite()) {
        return None;
    }
    let uq =
        nalgebra::UnitQuaternion::try_new(nalgebra::Quaternion::new(q[0], q[1], q[2], q[3]), 1e-6)?;
    let e = common::math::Euler::from_quaternion(&uq);
    let v = nalgebra::Vector3::new(f32::from(d.vx), f32::from(d.vy), f32::from(d.vz)) / 100.0;
    let (chi, vg) = common::math::course_and_speed(&v);
    let course = if vg > common::math::MIN_COURSE_SPEED_MPS {
        chi
    } else {
        e.psi
    };
    Some(TruthSample {
        loops: Measurements {
            roll: e.phi,
            pitch: e.theta,
            course,
            roll_rate: d.rollspeed,
            pitch_rate: d.pitchspeed,
            yaw_rate: d.yawspeed,
            altitude: d.alt as f32 / 1000.0,
            airspeed: f32::from(d.true_airspeed) / 100.0,
            sideslip: 0.0,
            ground_speed: vg,
        },
        vel_down_mps: v.z,
    })
}
