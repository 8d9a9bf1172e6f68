//! The autopilot's tick, independent of any board.

use common::link::framing::{Frame, FrameParser, LinkStats, Sender};
use common::link::simlink::{self, ActuatorFrame, Rejected};
use common::sensors::GpsFix;
use mavlink::dialects::common::{
    MavAutopilot, MavMessage, MavModeFlag, MavState, MavType, HEARTBEAT_DATA,
};

/// MAVLink identity of the autopilot (DESIGN.md: system 1, component 1).
pub const SYSTEM_ID: u8 = 1;
/// MAVLink component of the autopilot.
pub const COMPONENT_ID: u8 = 1;

/// Counters the autopilot keeps about its simulator link.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SimLinkHealth {
    /// Sensor frames accepted.
    pub sensor_frames: u32,
    /// GPS frames accepted.
    pub gps_frames: u32,
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
    /// Sensor frames whose time did not advance.
    pub stale_frames: u32,
}

/// The autopilot application.
pub struct App {
    sim_parser: FrameParser,
    sim_tx: Sender,
    health: SimLinkHealth,
    last_time_us: Option<u64>,
    last_gps: Option<GpsFix>,
    armed: bool,
}

impl Default for App {
    fn default() -> Self {
        Self::new()
    }
}

impl App {
    /// A freshly booted autopilot.
    pub fn new() -> Self {
        Self {
            sim_parser: FrameParser::new(),
            sim_tx: Sender::new(SYSTEM_ID, COMPONENT_ID),
            health: SimLinkHealth::default(),
            last_time_us: None,
            last_gps: None,
            armed: false,
        }
    }

    /// Counters of the simulator link.
    pub fn sim_health(&self) -> SimLinkHealth {
        self.health
    }

    /// Framing counters of the simulator link.
    pub fn sim_link_stats(&self) -> LinkStats {
        self.sim_parser.stats()
    }

    /// The last accepted GPS fix.
    pub fn last_gps(&self) -> Option<GpsFix> {
        self.last_gps
    }

    /// Feeds bytes from the simulator link; `out` receives the bytes to send back.
    pub fn on_sim_bytes(&mut self, bytes: &[u8], out: &mut impl FnMut(&[u8])) {
        let mut parser = core::mem::take(&mut self.sim_parser);
        parser.push(bytes, |frame| self.on_sim_frame(&frame, out));
        self.sim_parser = parser;
    }

    fn on_sim_frame(&mut self, frame: &Frame, out: &mut impl FnMut(&[u8])) {
        if frame.header.system_id != u32::from(SYSTEM_ID) {
            self.health.foreign_frames += 1;
            return;
        }
        match &frame.message {
            MavMessage::HIL_SENSOR(d) => {
                let (sensors, rejected) = simlink::decode_hil_sensor(d);
                self.count_rejections(rejected);
                if self.last_time_us.is_some_and(|t| sensors.time_us < t) {
                    self.health.stale_frames += 1;
                }
                self.last_time_us = Some(sensors.time_us);
                self.health.sensor_frames += 1;
                let answer = ActuatorFrame {
                    time_us: sensors.time_us,
                    surfaces: Default::default(),
                    armed: self.armed,
                };
                let msg = MavMessage::HIL_ACTUATOR_CONTROLS(simlink::encode_actuators(&answer));
                out(self.sim_tx.encode(&msg).raw_bytes());
            }
            MavMessage::HIL_GPS(d) => match simlink::decode_hil_gps(d) {
                Some(fix) => {
                    self.health.gps_frames += 1;
                    self.last_gps = Some(fix);
                }
                None => self.health.rejected_gps += 1,
            },
            MavMessage::HIL_STATE_QUATERNION(_) | MavMessage::HEARTBEAT(_) => {}
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

/// A heartbeat frame of the autopilot on its simulator link.
pub fn heartbeat_frame(app: &mut App) -> heapless::Vec<u8, 280> {
    let msg = MavMessage::HEARTBEAT(HEARTBEAT_DATA {
        custom_mode: 0,
        mavtype: MavType::MAV_TYPE_FIXED_WING,
        autopilot: MavAutopilot::MAV_AUTOPILOT_GENERIC,
        base_mode: if app.armed {
            MavModeFlag::MAV_MODE_FLAG_SAFETY_ARMED
        } else {
            MavModeFlag::empty()
        },
        system_status: MavState::MAV_STATE_STANDBY,
        mavlink_version: 3,
    });
    let raw = app.sim_tx.encode(&msg);
    heapless::Vec::from_slice(raw.raw_bytes()).unwrap_or_default()
}
