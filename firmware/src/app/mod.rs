//! The autopilot's application, independent of any board: the [`Vehicle`] of `common` and its
//! two MAVLink ports.
//!
//! ```text
//! sim link bytes -> SimPort (HIL_SENSOR / HIL_GPS decoding) -> Vehicle::on_sensors
//!                <- HIL_ACTUATOR_CONTROLS (one per sensor frame, lock-step)
//! GCS link bytes -> GroundPort -> GroundLink (params, missions, commands) -> requests
//!                <- telemetry, acknowledgements, STATUSTEXT
//! ```
//!
//! - [`simlink`]: the simulator port.
//! - [`ground`]: the ground-station port.
//!
//! The clock is the simulator's (`time_usec` of the sensor frames) in SITL and the board's
//! sensor timestamps on the MCU; nothing here reads a clock of its own.

pub mod flash_logs;
pub mod ground;
pub mod log;
pub mod persist;
pub mod reset;
pub mod simlink;

use common::actuators::Surfaces;
use common::estimator::EstimatedState;
use common::failsafe::Reaction;
use common::gcs::{Dest, GroundLink};
use common::link::framing::LinkStats;
use common::navigation::NavOutput;
use common::sensors::GpsFix;
use common::vehicle::modes::FlightMode;
use common::vehicle::snapshot::VehicleSnapshot;
use common::vehicle::Vehicle;
use ground::GroundPort;
use log::FlightLog;
use simlink::SimPort;

pub use simlink::SimLinkHealth;

pub use common::vehicle::commander::Setpoints;
pub use common::vehicle::params::REGISTRY;
pub use common::vehicle::CONTROL_PERIOD_US;

/// MAVLink identity of the autopilot (DESIGN.md: system 1, component 1).
pub use common::gcs::{COMPONENT_ID, SYSTEM_ID};

/// The autopilot application.
pub struct App {
    vehicle: Vehicle,
    sim: SimPort,
    ground: GroundPort,
    log: FlightLog,
}

impl Default for App {
    fn default() -> Self {
        Self::new()
    }
}

impl App {
    /// A freshly booted autopilot with default parameters: disarmed, in Manual.
    pub fn new() -> Self {
        let mut app = Self::fresh();
        app.apply_params();
        app
    }

    /// The application before the vehicle's parameters are applied to its stages
    /// ([`App::apply_params`]; [`App::new`] does both). Built where the caller binds it, with
    /// no copy: the MCU binds it in `main`'s frame, where `App::new` would build it once more
    /// for its return (13.6 KiB of the vehicle's on the stack besides the application).
    #[inline(never)]
    pub fn fresh() -> Self {
        Self {
            vehicle: Vehicle::fresh(),
            sim: SimPort::new(),
            ground: GroundPort::new(),
            log: FlightLog::new(),
        }
    }

    /// Hands the vehicle's parameters to its stages (after [`App::fresh`]).
    pub fn apply_params(&mut self) {
        self.vehicle.apply_params();
    }

    /// The vehicle.
    pub fn vehicle(&self) -> &Vehicle {
        &self.vehicle
    }

    /// The vehicle, writable (loading persisted parameters and missions at start-up).
    pub fn vehicle_mut(&mut self) -> &mut Vehicle {
        &mut self.vehicle
    }

    /// The flight log (off until the board enables it).
    pub fn flight_log(&self) -> &FlightLog {
        &self.log
    }

    /// The flight log, writable: the board enables it and drains it into its storage.
    pub fn flight_log_mut(&mut self) -> &mut FlightLog {
        &mut self.log
    }

    /// Counters of the simulator link.
    pub fn sim_health(&self) -> SimLinkHealth {
        SimLinkHealth {
            stale_frames: self.vehicle.stale_frames(),
            gcs_bytes_dropped: self.ground.bytes_dropped(),
            ..self.sim.health()
        }
    }

    /// Framing counters of the simulator link.
    pub fn sim_link_stats(&self) -> LinkStats {
        self.sim.stats()
    }

    /// Framing counters of the ground link.
    pub fn gcs_link_stats(&self) -> LinkStats {
        self.ground.stats()
    }

    /// The last accepted GPS fix.
    pub fn last_gps(&self) -> Option<GpsFix> {
        self.vehicle.last_gps()
    }

    /// The estimator's current state.
    pub fn estimate(&self) -> EstimatedState {
        self.vehicle.estimate()
    }

    /// Armed (throttle live).
    pub fn armed(&self) -> bool {
        self.vehicle.armed()
    }

    /// Mode being flown: the pilot's choice, or what a failsafe put in its place.
    pub fn mode(&self) -> FlightMode {
        self.vehicle.commander().flown_mode()
    }

    /// The mode the pilot (or ground station) chose.
    pub fn chosen_mode(&self) -> FlightMode {
        self.vehicle.commander().chosen_mode()
    }

    /// What a failsafe has the aircraft do instead of the chosen mode.
    pub fn failsafe_reaction(&self) -> Reaction {
        self.vehicle.commander().reaction()
    }

    /// The navigator's last output (phase, mission item, guidance errors).
    pub fn navigation(&self) -> &NavOutput {
        self.vehicle.commander().navigation()
    }

    /// What the autopilot is holding (see [`Vehicle::setpoints`]).
    pub fn setpoints(&self) -> Setpoints {
        self.vehicle.setpoints()
    }

    /// The last surface commands.
    pub fn surfaces(&self) -> Surfaces {
        self.vehicle.surfaces()
    }

    /// The ground link's protocol state.
    pub fn ground_link(&self) -> &GroundLink {
        self.ground.link()
    }

    /// The ground link, writable (the board answers storage and reboot requests).
    pub fn ground_link_mut(&mut self) -> &mut GroundLink {
        self.ground.link_mut()
    }

    /// A STATUSTEXT from the board to every station (why it reset): a warning or information.
    pub fn announce(&mut self, warning: bool, text: &str) {
        use mavlink::dialects::common::MavSeverity;
        let severity = if warning {
            MavSeverity::MAV_SEVERITY_WARNING
        } else {
            MavSeverity::MAV_SEVERITY_INFO
        };
        self.ground.link_mut().send_statustext(severity, text);
        self.poll_ground();
    }

    /// Encodes what the ground link has due now (an answer the board produced between
    /// frames, such as a finished save), ready for [`App::drain_gcs`].
    pub fn poll_ground(&mut self) {
        let now = self.vehicle.time_us().unwrap_or(0);
        self.ground.poll(now, &mut self.vehicle);
    }

    /// Serves the ground stations' log requests (list, download, erase) from the board's
    /// `store`, in at most `room` bytes of its output, ready for [`App::drain_gcs`]. A board
    /// calls it when [`GroundLink::logs_busy`] says something waits.
    pub fn serve_logs(&mut self, store: &mut dyn common::gcs::logs::LogStore, room: usize) {
        let armed = self.vehicle.armed();
        self.ground.serve_logs(store, armed, room);
    }

    /// MAVLink 2 signing of the ground link (loading a persisted key at start-up).
    pub fn signing_mut(&mut self) -> &mut common::gcs::signing::Signing {
        self.ground.signing_mut()
    }

    /// What the ground link reports and checks.
    pub fn snapshot(&self) -> VehicleSnapshot {
        self.vehicle.snapshot()
    }

    /// A figure the board measures of itself (instructions per control period, stack peak)
    /// to every ground station as NAMED_VALUE_INT; `name` is cut to its 10 characters.
    pub fn report_figure(&mut self, name: &str, value: i32) {
        use mavlink::dialects::common::{MavMessage, NAMED_VALUE_INT_DATA};
        let time_boot_ms = (self.vehicle.time_us().unwrap_or(0) / 1000) as u32;
        self.ground
            .send(&MavMessage::NAMED_VALUE_INT(NAMED_VALUE_INT_DATA {
                time_boot_ms,
                name: name.into(),
                value,
            }));
    }

    /// Feeds bytes from the simulator link; `out` receives the bytes to send back.
    pub fn on_sim_bytes(&mut self, bytes: &[u8], out: &mut impl FnMut(&[u8])) {
        self.sim.on_bytes(
            bytes,
            &mut self.vehicle,
            &mut self.ground,
            &mut self.log,
            out,
        );
    }

    /// Bytes the simulator link's parser needs before it can check its next frame: a board
    /// that hands it over no fewer (when that many have arrived) parses a frame in one or two
    /// calls instead of one per byte, with the same frames at the same moments.
    pub fn sim_bytes_wanted(&self) -> usize {
        self.sim.bytes_wanted()
    }

    /// As [`App::sim_bytes_wanted`], for the ground link of a single-link board (channel 0).
    pub fn gcs_bytes_wanted(&self) -> usize {
        self.ground.bytes_wanted(0)
    }

    /// Feeds bytes from the ground station of a single-link board (channel 0); the answers
    /// wait in [`App::drain_gcs`].
    pub fn on_gcs_bytes(&mut self, bytes: &[u8]) {
        self.ground.on_bytes(0, bytes, false, &mut self.vehicle);
    }

    /// Feeds one datagram from the ground stations on `channel` (a board with several: one
    /// per UDP peer); the answers wait in [`App::drain_gcs_to`]. A frame cut short at the
    /// datagram's end is dropped, so it never holds back the ones behind it.
    pub fn on_gcs_datagram(&mut self, channel: u8, datagram: &[u8]) {
        self.ground
            .on_bytes(channel, datagram, true, &mut self.vehicle);
    }

    /// Hands out the frames waiting for the ground station of a single-link board (channel
    /// 0), one call per frame.
    pub fn drain_gcs(&mut self, out: &mut impl FnMut(&[u8])) {
        self.ground.drain(&mut |dest, frame| {
            if dest.reaches(0) {
                out(frame)
            }
        });
    }

    /// Hands out the frames waiting, one call per frame with where it goes.
    pub fn drain_gcs_to(&mut self, out: &mut impl FnMut(Dest, &[u8])) {
        self.ground.drain(out);
    }
}

/// A heartbeat frame of the autopilot on its simulator link (the ground link's heartbeat, so
/// both links describe the vehicle the same way).
pub fn heartbeat_frame(app: &mut App) -> heapless::Vec<u8, 280> {
    let msg = common::gcs::telemetry::heartbeat(&app.vehicle.snapshot());
    app.sim.encode(&msg)
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    #[test]
    fn the_registry_builds_and_every_name_is_unique() {
        assert_eq!(common::params::ParamStore::validate(REGISTRY), Ok(()));
    }

    extern crate std;
    use common::link::framing::{FrameParser, Sender};
    use common::link::simlink::encode_hil_sensor;
    use common::sensors::{ImuSample, SensorFrame};
    use mavlink::dialects::common::MavMessage;
    use mavlink::dialects::common::MANUAL_CONTROL_DATA;
    use std::vec::Vec;

    fn sensor_frame(k: u64) -> Vec<u8> {
        frame_at(k * 10_000)
    }

    /// A frame of the sensors at rest at `time_us`, through the simulator link.
    pub(crate) fn frame_at(time_us: u64) -> Vec<u8> {
        let f = SensorFrame {
            time_us,
            imu: Some(ImuSample {
                accel: nalgebra::Vector3::new(0.0, 0.0, -common::math::GRAVITY),
                gyro: nalgebra::Vector3::zeros(),
            }),
            ..Default::default()
        };
        let mut sim = Sender::new(1, 51);
        sim.encode(&MavMessage::HIL_SENSOR(encode_hil_sensor(&f, 0.0)))
            .raw_bytes()
            .to_vec()
    }

    fn actuators(app: &mut App, k: u64) -> [f32; 16] {
        answer(app, &sensor_frame(k))
    }

    fn answer(app: &mut App, frame: &[u8]) -> [f32; 16] {
        let mut out = Vec::new();
        app.on_sim_bytes(frame, &mut |b| out.extend_from_slice(b));
        let mut p = FrameParser::new();
        let mut controls = [f32::NAN; 16];
        p.push(&out, |f| {
            if let MavMessage::HIL_ACTUATOR_CONTROLS(d) = f.message {
                controls = d.controls;
            }
        });
        controls
    }

    #[test]
    fn manual_mode_passes_the_sticks_through() {
        let mut app = App::new();
        assert_eq!(app.mode(), FlightMode::Manual);
        // No stick yet: the trim (UMN elevator -0.0963 rad is nose-up: positive PX4 pitch).
        let c = actuators(&mut app, 0);
        assert!(c[1] > 0.0 && c[1] < 0.3, "{c:?}");
        // Full right roll, half nose-up (stick back is negative x), some right yaw.
        let mut gcs = Sender::new(255, 190);
        let stick = MavMessage::MANUAL_CONTROL(MANUAL_CONTROL_DATA {
            x: -500,
            y: 1000,
            z: 600,
            r: 250,
            target: 1,
            ..Default::default()
        });
        app.on_gcs_bytes(gcs.encode(&stick).raw_bytes());
        // The next control tick (50 Hz: the frame at 20 ms) applies them.
        let c = actuators(&mut app, 2);
        assert!(
            (c[0] - 1.0).abs() < 1e-5 && (c[1] - 0.5).abs() < 1e-5,
            "{c:?}"
        );
        assert!((c[2] - 0.25).abs() < 1e-5, "{c:?}");
        // Disarmed: no throttle reaches the motor whatever the stick says.
        assert_eq!(c[3], 0.0);
        // Sticks that stop arriving fall back to the trim.
        for k in 3..80 {
            actuators(&mut app, k);
        }
        let c = actuators(&mut app, 80);
        assert!(c[0].abs() < 0.1, "{c:?}");
    }

    #[test]
    fn an_application_built_in_two_steps_answers_as_one_built_by_new() {
        let mut two_steps = App::fresh();
        two_steps.apply_params();
        let in_place = &mut two_steps;
        let mut by_value = App::new();
        for k in 0..5 {
            let (a, b) = (actuators(in_place, k), actuators(&mut by_value, k));
            assert_eq!(a.map(f32::to_bits), b.map(f32::to_bits), "frame {k}");
        }
        assert_eq!(in_place.mode(), FlightMode::Manual);
        assert!(!in_place.armed());
    }

    #[test]
    fn the_application_fits_the_stm32f405_ram_with_room_for_the_stack() {
        // 128 KiB of SRAM: the whole application state must leave most of it to the stack.
        // The image builds it in `main`'s frame inside its 56 KiB stack region, whose painted
        // peak measured 52,756 B with a 40,960 B bound here; the autotune's sideslip model
        // (its fit, the rudder's servo state, the held wind) took the state to 41,168 B,
        // which that region still holds with 3 KiB to spare (the budget test measures it,
        // the image's own autotune included: docs/PERFORMANCE.md).
        assert!(
            core::mem::size_of::<App>() < 41 * 1024 + 512,
            "{}",
            core::mem::size_of::<App>()
        );
    }

    fn roll_stick(app: &mut App, y: i16) {
        let mut gcs = Sender::new(255, 190);
        let stick = MavMessage::MANUAL_CONTROL(MANUAL_CONTROL_DATA {
            y,
            target: 1,
            ..Default::default()
        });
        app.on_gcs_bytes(gcs.encode(&stick).raw_bytes());
    }

    fn heartbeats(app: &mut App) -> usize {
        let mut n = 0;
        let mut p = FrameParser::new();
        app.drain_gcs(&mut |b| {
            p.push(b, |f| {
                n += usize::from(matches!(f.message, MavMessage::HEARTBEAT(_)))
            })
        });
        n
    }

    /// Flies `frames` regular frames of 10 ms from `from_us`, moving the roll stick full right
    /// half-way: the aileron follows within two control periods and the heartbeat keeps its
    /// 1 Hz.
    fn still_alive(app: &mut App, from_us: u64, frames: u64) {
        heartbeats(app);
        roll_stick(app, 0);
        let mut rolled = false;
        for k in 0..frames {
            if k == frames / 2 {
                roll_stick(app, 1000);
            }
            let c = answer(app, &frame_at(from_us + k * 10_000));
            rolled |= k > frames / 2 + 4 && (c[0] - 1.0).abs() < 1e-5;
        }
        assert!(rolled, "the surfaces follow the sticks");
        let beats = heartbeats(app);
        assert!(beats as u64 >= frames / 100 - 1, "{beats} heartbeats");
        roll_stick(app, 0);
    }

    #[test]
    fn one_sensor_time_from_the_far_future_freezes_nothing() {
        for hostile in [1u64 << 62, u64::MAX, u64::MAX - 1] {
            let mut app = App::new();
            still_alive(&mut app, 0, 200);
            // One frame from the far future, then the simulator carries on.
            answer(&mut app, &frame_at(hostile));
            still_alive(&mut app, 2_000_000, 300);
            assert_eq!(app.vehicle().clock_stats().refused, 1);
        }
    }

    #[test]
    fn a_simulator_three_seconds_back_costs_a_few_frames_not_three_seconds() {
        let mut app = App::new();
        still_alive(&mut app, 0, 500);
        let before = app.vehicle().time_us().unwrap();
        // The time base restarts 3 s earlier and continues regularly.
        still_alive(&mut app, 2_000_000, 300);
        assert_eq!(app.vehicle().clock_stats().resyncs, 1);
        // The vehicle's clock never went back, and lost only the frames before the resync.
        let after = app.vehicle().time_us().unwrap();
        assert!(after > before + 2_900_000, "{before} -> {after}");
    }

    /// A `COMMAND_LONG` with a command id the dialect has no name for.
    struct UnknownCommand(u16);

    impl mavlink::MessageData for UnknownCommand {
        type Message = MavMessage;
        const ID: u32 = 76;
        const NAME: &'static str = "COMMAND_LONG";
        const EXTRA_CRC: u8 = 152;
        const ENCODED_LEN: usize = 33;
        fn ser(&self, _: mavlink::MavlinkVersion, p: &mut [u8]) -> usize {
            p[..33].fill(0);
            p[28..30].copy_from_slice(&self.0.to_le_bytes());
            (p[30], p[31]) = (1, 1);
            32
        }
        fn deser(
            _: mavlink::MavlinkVersion,
            _: &[u8],
        ) -> Result<Self, mavlink::error::ParserError> {
            Err(mavlink::error::ParserError::UnknownMessage { id: 76 })
        }
    }

    #[test]
    fn a_command_the_dialect_does_not_know_is_answered_unsupported() {
        use mavlink::MessageData;
        // The dialect's own checksum seed for COMMAND_LONG, so the frame is a valid one.
        assert_eq!(
            UnknownCommand::EXTRA_CRC,
            mavlink::dialects::common::COMMAND_LONG_DATA::EXTRA_CRC
        );
        let mut app = App::new();
        actuators(&mut app, 0);
        for id in [31999u16, 12345, 42424] {
            let mut gcs = Sender::new(255, 190);
            app.on_gcs_bytes(gcs.encode_data(&UnknownCommand(id)).raw_bytes());
            let mut acks = Vec::new();
            let mut p = FrameParser::new();
            app.drain_gcs(&mut |b| {
                p.push_with(
                    b,
                    |_| {},
                    |raw| {
                        if raw.id == 77 {
                            acks.push((
                                u16::from_le_bytes([raw.payload[0], raw.payload[1]]),
                                raw.payload[2],
                            ));
                        }
                    },
                )
            });
            // MAV_RESULT_UNSUPPORTED is 3.
            assert_eq!(acks, [(id, 3)], "command {id}");
        }
    }

    #[test]
    fn a_throttle_limit_below_the_trim_is_refused_and_reads_back_as_flown() {
        use mavlink::dialects::common::{MavParamType, PARAM_SET_DATA};
        let mut app = App::new();
        actuators(&mut app, 0);
        let mut gcs = Sender::new(255, 190);
        let set = MavMessage::PARAM_SET(PARAM_SET_DATA {
            param_value: 0.3,
            target_system: 1,
            target_component: 1,
            param_id: "THR_MAX".into(),
            param_type: MavParamType::MAV_PARAM_TYPE_REAL32,
        });
        app.on_gcs_bytes(gcs.encode(&set).raw_bytes());
        let mut echo = None;
        let mut texts = Vec::new();
        let mut p = FrameParser::new();
        app.drain_gcs(&mut |b| {
            p.push(b, |f| match f.message {
                MavMessage::PARAM_VALUE(v) => echo = Some(v.param_value),
                MavMessage::STATUSTEXT(t) => texts.push(t.text.to_str().unwrap_or("").to_string()),
                _ => {}
            })
        });
        // The trim throttle (0.569, Table 2.3) lies above 0.3: the stage could not fly it, so
        // the store keeps 1.0 and the echo says so.
        assert_eq!(echo, Some(1.0));
        assert_eq!(app.vehicle().params().get("THR_MAX"), Some(1.0));
        assert!(
            texts
                .iter()
                .any(|t| t.contains("THR_MAX") && t.contains("contradicts")),
            "{texts:?}"
        );
    }
}
