//! What the flight tests share: a flight of the default mission flown in this process, with
//! the log the autopilot wrote of it and the simulator's truth beside it, and the firmware's
//! parameter defaults.

// Each test file uses what it needs of this module.
#![allow(dead_code)]

use sim_host::aircraft::Aircraft;
use sim_host::commands::fly::command::mission_config;
use sim_host::commands::fly::{fly_report, FlyOptions};
use sim_host::flight::{FlightConfig, FlightOutcome};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// A flown flight: its files and what the simulator recorded.
pub struct Flown {
    /// Where its files are (`flight.csv`, `logs/log_001.ulg`, ...).
    pub dir: PathBuf,
    /// The autopilot's log of it.
    pub log: PathBuf,
    /// The simulator's record: the truth every frame, the summary.
    pub outcome: FlightOutcome,
}

/// Flies the default mission from the runway for `duration_s` of simulated time in this
/// process, its files into `dir` (figures left out), the aircraft fitted with the default
/// rangefinder so that every topic of the log has samples.
pub fn fly_default(dir: &Path, duration_s: f64) -> Flown {
    let mut aircraft = Aircraft::load(None).expect("the built-in aircraft");
    aircraft.sensors.rangefinder = Some(sim_host::sensors::RangefinderConfig::default());
    let cfg = FlightConfig {
        duration_s,
        ..mission_config(&aircraft, Path::new("default")).expect("the default mission")
    };
    let opts = FlyOptions {
        out: Some(dir.to_path_buf()),
        plots: false,
        ..Default::default()
    };
    let r = fly_report(&aircraft, &cfg, &opts).expect("the flight flies");
    let log = dir.join("logs").join("log_001.ulg");
    assert!(log.exists(), "one log for the one armed flight");
    Flown {
        dir: dir.to_path_buf(),
        log,
        outcome: r.outcome,
    }
}

/// Seconds of the flight every test of a file shares: the take-off, the climb and the first
/// turns of the mission, in 3,500 samples of the fastest topics.
pub const SECONDS: f64 = 90.0;

/// The flight the tests of one file share, flown once (in the build's scratch directory,
/// fresh each run: the autopilot numbers its logs after those already there).
pub fn flight() -> &'static Flown {
    static FLIGHT: OnceLock<Flown> = OnceLock::new();
    FLIGHT.get_or_init(|| {
        let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(env!("CARGO_CRATE_NAME"));
        let _ = std::fs::remove_dir_all(&dir);
        fly_default(&dir, SECONDS)
    })
}

/// Rows of a CSV file as numbers, with its header.
pub fn csv(path: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{path:?}: {e}"));
    let mut lines = text.lines();
    let header = lines
        .next()
        .expect("a header")
        .split(',')
        .map(str::to_owned)
        .collect();
    let rows = lines
        .map(|l| {
            l.split(',')
                .map(|x| x.parse().unwrap_or(f64::NAN))
                .collect()
        })
        .collect();
    (header, rows)
}

/// The column of `name` in a CSV header.
pub fn col(header: &[String], name: &str) -> usize {
    header
        .iter()
        .position(|h| h == name)
        .unwrap_or_else(|| panic!("no column {name} in {header:?}"))
}

pub fn rms(e: &[f64]) -> f64 {
    (e.iter().map(|x| x * x).sum::<f64>() / e.len() as f64).sqrt()
}

pub fn wrap_deg(a: f64) -> f64 {
    (a + 180.0).rem_euclid(360.0) - 180.0
}

/// The firmware's default value of a parameter (what a user flies without changing it).
pub fn default_of(name: &str) -> f64 {
    let store = common::params::ParamStore::new(firmware::app::REGISTRY);
    store
        .index_of(name)
        .and_then(|i| store.def(i))
        .map(|d| f64::from(d.default))
        .unwrap_or_else(|| panic!("no parameter {name}"))
}

/// Runs the `sim-host` binary with `args`, its files (`--out`) into a fresh directory, kept
/// while the returned one is held.
pub fn sim_host(args: &[&str]) -> (std::process::Output, tempfile::TempDir) {
    let dir = tempfile::tempdir().unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_sim-host"))
        .args(args)
        .args(["--out", dir.path().to_str().unwrap()])
        .output()
        .unwrap();
    (out, dir)
}
