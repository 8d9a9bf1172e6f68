//! One closed-loop run: the autopilot of `common` flying the nonlinear plant.
//!
//! Per control tick (50 Hz): the plant truth is sampled into measurements (plus optional white
//! noise), pushed through a delay line of [`SimConfig::delay_samples`] ticks, the autopilot
//! steps on the delayed sample, and its surface commands, held until the next tick, drive the
//! servos (first order, rate and position limited) and the plant, advanced together in
//! [`SimConfig::substeps`] RK4 steps ([`Plant::step_servos`]).

use super::{Axis, Scenario};
use crate::aircraft::Aircraft;
use crate::analysis::trim::TrimResult;
use crate::plant::inputs::{Controls, Environment};
use crate::plant::servo::ServoBank;
use crate::plant::Plant;
use common::actuators::Surfaces;
use common::control::autopilot::{Autopilot, Measurements};
use common::control::gains::GainSet;
use common::control::longitudinal::Regime;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use serde::Serialize;
use std::collections::VecDeque;

/// How a run is flown.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct SimConfig {
    /// Control period, s (thesis: 0.02).
    pub dt_s: f64,
    /// Plant RK4 steps per control period (4: 5 ms).
    pub substeps: usize,
    /// Control periods by which the autopilot sees its inputs late (thesis: 2).
    pub delay_samples: usize,
    /// Standard deviation of the white noise added to every measurement in its SI unit (rad,
    /// rad/s, m, m/s); 0 for none (thesis: 1e-3).
    pub noise_sigma: f64,
    /// Seed of the noise generator (ChaCha8: the same sequence on every platform and release).
    pub seed: u64,
}

impl Default for SimConfig {
    fn default() -> Self {
        Self {
            dt_s: 0.02,
            substeps: 4,
            delay_samples: 2,
            noise_sigma: 0.0,
            seed: 1,
        }
    }
}

/// One control tick of a run. Angles in degrees, as plotted and written to CSV.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct Sample {
    /// Time, s.
    pub t: f64,
    /// Command of the loop under test (deg or m).
    pub command: f64,
    /// Its true response (deg or m; heading unwrapped).
    pub response: f64,
    /// Roll, deg.
    pub roll_deg: f64,
    /// Pitch, deg.
    pub pitch_deg: f64,
    /// Heading, deg, unwrapped (continuous through +-180).
    pub heading_deg: f64,
    /// Altitude above mean sea level, m.
    pub alt_msl_m: f64,
    /// Airspeed, m/s.
    pub airspeed_mps: f64,
    /// Sideslip, deg.
    pub sideslip_deg: f64,
    /// Elevator at the servo, deg.
    pub elevator_deg: f64,
    /// Combined aileron at the servos, deg.
    pub aileron_deg: f64,
    /// Rudder at the servo, deg.
    pub rudder_deg: f64,
    /// Throttle, 0..1.
    pub throttle: f64,
    /// Pitch angle the pitch loop was asked for, deg (NaN when off).
    pub pitch_cmd_deg: f64,
    /// Roll angle the roll loop was asked for, deg (NaN when off).
    pub roll_cmd_deg: f64,
    /// Longitudinal regime (altitude modes), as its index in Figure 3-16 order: 0 take-off,
    /// 1 climb, 2 altitude hold, 3 descent; -1 none.
    pub regime: i8,
}

/// A finished run.
#[derive(Clone, Debug, Serialize)]
pub struct Run {
    /// Scenario flown.
    pub scenario: &'static str,
    /// Gain-set name.
    pub gains: String,
    /// How it was flown.
    pub config: SimConfig,
    /// One sample per control tick, from t = 0.
    pub samples: Vec<Sample>,
    /// Ticks on which the autopilot refused an input (should be 0).
    pub rejected_ticks: u32,
}

fn regime_index(r: Option<Regime>) -> i8 {
    match r {
        Some(Regime::TakeOff) => 0,
        Some(Regime::Climb) => 1,
        Some(Regime::AltitudeHold) => 2,
        Some(Regime::Descent) => 3,
        None => -1,
    }
}

fn truth(plant: &Plant) -> Measurements {
    let e = plant.euler();
    let w = plant.body_rates();
    let air = plant.air_data();
    Measurements {
        roll: e.phi as f32,
        pitch: e.theta as f32,
        // Still air: course over ground is the heading.
        course: e.psi as f32,
        roll_rate: w.x as f32,
        pitch_rate: w.y as f32,
        yaw_rate: w.z as f32,
        altitude: plant.alt_msl_m() as f32,
        airspeed: air.va as f32,
        sideslip: air.beta as f32,
        ground_speed: plant.velocity_ned().xy().norm() as f32,
    }
}

fn add_noise(m: &mut Measurements, noise: &Normal<f64>, rng: &mut ChaCha8Rng) {
    for v in [
        &mut m.roll,
        &mut m.pitch,
        &mut m.course,
        &mut m.roll_rate,
        &mut m.pitch_rate,
        &mut m.yaw_rate,
        &mut m.altitude,
        &mut m.airspeed,
        &mut m.sideslip,
    ] {
        *v += noise.sample(rng) as f32;
    }
}

fn surfaces_of(c: &Controls) -> Surfaces {
    Surfaces {
        elevator: c.elevator as f32,
        aileron: c.aileron() as f32,
        rudder: c.rudder as f32,
        throttle: c.throttle as f32,
    }
}

/// Unwraps `angle` (rad) to the branch nearest `previous`.
fn unwrap_near(angle: f64, previous: f64) -> f64 {
    let two_pi = 2.0 * std::f64::consts::PI;
    angle + two_pi * ((previous - angle) / two_pi).round()
}

/// Flies `scenario` from the level trim with `gains`.
///
/// The servos and the autopilot's loops start at the trim surfaces (handed over, so engaging
/// gives no jump). Errors: an invalid gain set, or a configuration that cannot be flown
/// (non-positive or non-finite time step, no substeps, negative or non-finite noise).
pub fn simulate(
    aircraft: &Aircraft,
    trim: &TrimResult,
    gains_name: &str,
    gains: &GainSet,
    scenario: &Scenario,
    cfg: &SimConfig,
) -> anyhow::Result<Run> {
    anyhow::ensure!(
        cfg.dt_s.is_finite() && cfg.dt_s > 0.0 && cfg.substeps > 0,
        "scenario: control period {} s with {} substeps cannot be flown",
        cfg.dt_s,
        cfg.substeps
    );
    anyhow::ensure!(
        cfg.noise_sigma.is_finite() && cfg.noise_sigma >= 0.0,
        "scenario: noise sigma {} must be finite and >= 0",
        cfg.noise_sigma
    );
    let mut ap = Autopilot::new(gains)
        .map_err(|e| anyhow::anyhow!("gain set `{gains_name}` refused: {e}"))?;
    ap.handover(surfaces_of(&trim.controls));
    let mut plant = Plant::new(aircraft, trim.state);
    let env = Environment::default();
    plant.set_inputs(&trim.controls, &env);
    let mut servos = ServoBank::new(&aircraft.actuators, &trim.controls);
    let mut applied = trim.controls;
    let noise = Normal::new(0.0, cfg.noise_sigma)?;
    let mut rng = ChaCha8Rng::seed_from_u64(cfg.seed);
    let first = truth(&plant);
    let mut delay: VecDeque<Measurements> = std::iter::repeat_n(first, cfg.delay_samples).collect();
    let ticks = (scenario.duration_s / cfg.dt_s).round() as usize;
    let deg = 180.0 / std::f64::consts::PI;
    let unit = 1.0 / scenario.axis.si_per_unit();
    let h = cfg.dt_s / cfg.substeps as f64;
    let mut heading = plant.euler().psi;
    let mut samples = Vec::with_capacity(ticks + 1);
    for k in 0..=ticks {
        let t = k as f64 * cfg.dt_s;
        let e = plant.euler();
        heading = unwrap_near(e.psi, heading);
        let air = plant.air_data();
        let mut m = truth(&plant);
        if cfg.noise_sigma > 0.0 {
            add_noise(&mut m, &noise, &mut rng);
        }
        delay.push_back(m);
        let seen = delay.pop_front().unwrap_or(m);
        let cmds = scenario.commands(trim, t);
        let out = ap.step(&seen, &cmds, cfg.dt_s as f32);
        let response_si = match scenario.axis {
            Axis::Roll => e.phi,
            Axis::Heading => heading,
            Axis::Sideslip => air.beta,
            Axis::Pitch => e.theta,
            Axis::Altitude => plant.alt_msl_m(),
            Axis::Airspeed => air.va,
        };
        samples.push(Sample {
            t,
            command: scenario.command_si(trim, t) * unit,
            response: response_si * unit,
            roll_deg: e.phi * deg,
            pitch_deg: e.theta * deg,
            heading_deg: heading * deg,
            alt_msl_m: plant.alt_msl_m(),
            airspeed_mps: air.va,
            sideslip_deg: air.beta * deg,
            elevator_deg: applied.elevator * deg,
            aileron_deg: applied.aileron() * deg,
            rudder_deg: applied.rudder * deg,
            throttle: applied.throttle,
            pitch_cmd_deg: f64::from(out.status.pitch_cmd) * deg,
            roll_cmd_deg: f64::from(out.status.roll_cmd) * deg,
            regime: regime_index(out.status.regime),
        });
        if k == ticks {
            break;
        }
        let cmd = Controls::from(out.surfaces);
        for _ in 0..cfg.substeps {
            applied = plant.step_servos(&mut servos, &cmd, &env, h);
        }
    }
    Ok(Run {
        scenario: scenario.name,
        gains: gains_name.to_string(),
        config: *cfg,
        samples,
        rejected_ticks: ap.counters().rejected_ticks,
    })
}
