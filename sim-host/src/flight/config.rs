//! What defines a flight: duration, step, wind and turbulence, seed, pacing, the ground
//! station's script, the pilot's radio and the sensor faults.

use super::script::Script;
use crate::environment::wind::Turbulence;
use crate::sensors::models::{RangeFault, SensorFaults};
use std::sync::atomic::{AtomicBool, Ordering};
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
    /// Where the scripted station records the ground link, both ways, as a ground station
    /// records it (the flight's `.tlog`); the simulator link has its own file.
    pub ground_tlog: Option<std::path::PathBuf>,
    /// Fly the scripted ground station. Without it (`sim-host sim`) whoever flies the
    /// autopilot does so on its own ground link, and `script` is not used.
    pub scripted_station: bool,
    /// End the flight, as flown so far, when the autopilot closes the simulator link (a
    /// standalone simulator's end) instead of calling it a failure.
    pub until_link_closes: bool,
    /// Set from outside (Ctrl-C) to end the flight at the next frame, as flown so far.
    pub stop: Option<&'static AtomicBool>,
    /// Send the truth (HIL_STATE_QUATERNION) with every sensor frame. An autopilot flies on it
    /// only with `SIM_USE_TRUTH` set; over a slow link (a UART in QEMU, where each byte costs)
    /// it may be left out otherwise.
    pub truth_frames: bool,
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
    /// The rangefinder fails so (it must be fitted: `--rangefinder`).
    Range(RangeFault),
}

impl FlightConfig {
    /// Whether the scripted station has the autopilot fly on the truth (`SIM_USE_TRUTH`).
    pub fn flies_on_truth(&self) -> bool {
        self.scripted_station
            && self
                .script
                .params
                .iter()
                .any(|(n, v)| n == "SIM_USE_TRUTH" && *v != 0.0)
    }

    /// Whether the flight has been asked to stop.
    pub fn stopped(&self) -> bool {
        self.stop.is_some_and(|s| s.load(Ordering::Relaxed))
    }

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
                Fault::Range(r) => f.range = Some(r),
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
            ground_tlog: None,
            runway_heading: None,
            faults: Vec::new(),
            rc_sticks: Vec::new(),
            scripted_station: true,
            until_link_closes: false,
            stop: None,
            truth_frames: true,
        }
    }
}

/// Parses a sensor fault as the command line spells it: `KIND:FROM-TO` in seconds of
/// simulated time, KIND one of gps, pitot, mag, baro, or a rangefinder's range-stuck,
/// range-short, range-drop (`gps:60-90`).
pub fn parse_fault(s: &str) -> Result<FaultWindow, String> {
    let err = |why: &str| {
        format!("fault `{s}`: {why} (expected KIND:FROM-TO, e.g. gps:60-90; KIND gps, pitot, mag, baro, range-stuck, range-short or range-drop)")
    };
    let (kind, window) = s.split_once(':').ok_or_else(|| err("no `:`"))?;
    let fault = match kind.trim() {
        "gps" => Fault::GpsLost,
        "pitot" => Fault::PitotFailed,
        "mag" => Fault::MagFailed,
        "baro" => Fault::BaroFailed,
        "range-stuck" => Fault::Range(RangeFault::Stuck),
        "range-short" => Fault::Range(RangeFault::Short),
        "range-drop" => Fault::Range(RangeFault::Dropping),
        _ => return Err(err("unknown sensor")),
    };
    let (from, to) = window.split_once('-').ok_or_else(|| err("no `-`"))?;
    let num = |x: &str| x.trim().parse::<f64>().map_err(|e| err(&e.to_string()));
    let (from_s, to_s) = (num(from)?, num(to)?);
    if !(from_s.is_finite() && to_s.is_finite() && 0.0 <= from_s && from_s < to_s) {
        return Err(err("the window must run forwards from 0 s or later"));
    }
    Ok(FaultWindow {
        fault,
        from_s,
        to_s,
    })
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_fault_reads_as_a_sensor_and_a_window_and_a_bad_one_says_what_is_expected() {
        let f = parse_fault("gps:60-90.5").expect("valid");
        assert_eq!((f.fault, f.from_s, f.to_s), (Fault::GpsLost, 60.0, 90.5));
        assert_eq!(
            parse_fault("baro:0-1").map(|f| f.fault),
            Ok(Fault::BaroFailed)
        );
        for bad in [
            "gyro:1-2",
            "gps:9-3",
            "gps:1",
            "gps",
            "pitot:-1-2",
            "mag:x-2",
        ] {
            let e = parse_fault(bad).expect_err(bad);
            assert!(e.contains("KIND:FROM-TO"), "{bad}: {e}");
        }
    }
}
