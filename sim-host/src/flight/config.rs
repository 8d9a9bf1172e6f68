//! What defines a flight: duration, step, wind and turbulence, seed, pacing, the ground
//! station's script, the pilot's radio and the sensor faults.

use super::script::Script;
use crate::environment::wind::Turbulence;
use crate::sensors::models::SensorFaults;
use std::time::Duration;

/// Everything that defines a flight.
#[derive(Clone, Debug)]
pub struct FlightConfig {
    /// Simulated time, s.
    pub duration_s: f64,
    /// Plant integration step, s (several per sensor frame).
    pub dt_s: f64,
    /// Steady wind, NED, m/s (the direction it blows towards).
    pub wind_ned: [f64; 3],
    /// Turbulence severity.
    pub turbulence: Turbulence,
    /// Seed of the sensor noise and the turbulence.
    pub seed: u64,
    /// Pace the flight to the wall clock.
    pub realtime: bool,
    /// With `realtime`: simulated seconds per wall second (1: real time).
    pub speed: f64,
    /// End the flight once the autopilot, having flown, has disarmed on the ground (after a
    /// landing), instead of at `duration_s`.
    pub stop_when_landed: bool,
    /// Show a progress bar.
    pub progress: bool,
    /// The ground station's script.
    pub script: Script,
    /// How long to wait for an answer of the autopilot before calling it silent.
    pub link_timeout: Duration,
    /// A ground-station port beside the script, `(bind, remote)`: the autopilot's telemetry
    /// goes to `remote` (QGroundControl listens on 127.0.0.1:14550) and to any station that
    /// sends to `bind`, whose frames reach the autopilot's ground link.
    pub ground_link: Option<(String, String)>,
    /// Start at rest on the runway at home, pointing this way (rad from north), instead of
    /// the hand launch at 100 m. Engine off until the autopilot is armed.
    pub runway_heading: Option<f64>,
    /// Sensor faults injected over windows of simulated time.
    pub faults: Vec<FaultWindow>,
    /// The pilot's radio: stick positions from a time on, sent as RC_CHANNELS at 50 Hz on
    /// the simulator link (none: no radio).
    pub rc_sticks: Vec<RcSticks>,
}

/// Stick positions held from a time on.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RcSticks {
    /// From, s of simulated time.
    pub from_s: f64,
    /// Roll stick, -1..1, right positive.
    pub roll: f32,
    /// Pitch stick, -1..1, back (nose up) positive.
    pub pitch: f32,
    /// Throttle, 0..1.
    pub throttle: f32,
    /// Yaw stick, -1..1, right positive.
    pub yaw: f32,
}

/// A sensor fault over a window of simulated time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FaultWindow {
    /// Which sensor fails.
    pub fault: Fault,
    /// From, s of simulated time.
    pub from_s: f64,
    /// Until, s (exclusive).
    pub to_s: f64,
}

/// A sensor the simulator can fail.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Fault {
    /// No GPS fixes.
    GpsLost,
    /// No differential pressure.
    PitotFailed,
    /// No magnetometer.
    MagFailed,
    /// No barometer.
    BaroFailed,
    /// No battery power monitor (no BATTERY_STATUS).
    BatteryMonitorFailed,
}

impl FlightConfig {
    /// The faults active at `t_s`.
    pub fn faults_at(&self, t_s: f64) -> SensorFaults {
        let mut f = SensorFaults::default();
        for w in self
            .faults
            .iter()
            .filter(|w| (w.from_s..w.to_s).contains(&t_s))
        {
            match w.fault {
                Fault::GpsLost => f.gps_lost = true,
                Fault::PitotFailed => f.pitot_failed = true,
                Fault::MagFailed => f.mag_failed = true,
                Fault::BaroFailed => f.baro_failed = true,
                Fault::BatteryMonitorFailed => f.battery_failed = true,
            }
        }
        f
    }
}

impl Default for FlightConfig {
    fn default() -> Self {
        let script = Script::thesis();
        Self {
            // About 10 s to converge and arm, then the script.
            duration_s: (10.0 + script.length_s()).ceil(),
            dt_s: 0.001,
            wind_ned: [0.0; 3],
            turbulence: Turbulence::None,
            seed: 1,
            realtime: false,
            speed: 1.0,
            stop_when_landed: false,
            progress: false,
            script,
            link_timeout: Duration::from_secs(5),
            ground_link: None,
            runway_heading: None,
            faults: Vec::new(),
            rc_sticks: Vec::new(),
        }
    }
}

/// Parses a turbulence severity as the command line spells it.
pub fn parse_turbulence(s: &str) -> Result<Turbulence, String> {
    match s {
        "none" => Ok(Turbulence::None),
        "light" => Ok(Turbulence::Light),
        "moderate" => Ok(Turbulence::Moderate),
        "severe" => Ok(Turbulence::Severe),
        _ => Err(format!(
            "turbulence `{s}`: expected none, light, moderate or severe"
        )),
    }
}

/// The name of a turbulence severity.
pub fn turbulence_name(t: Turbulence) -> &'static str {
    match t {
        Turbulence::None => "none",
        Turbulence::Light => "light",
        Turbulence::Moderate => "moderate",
        Turbulence::Severe => "severe",
    }
}
