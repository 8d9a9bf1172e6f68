//! Flying one scenario with every gain set, and what the runs give.

use crate::aircraft::Aircraft;
use crate::analysis::trim::{not_trimmed, trim, TrimResult, TrimTarget};
use crate::report::table::Table;
use crate::scenario::metrics::{run_metrics, RunMetrics};
use crate::scenario::sim::{simulate, Run, SimConfig};
use crate::scenario::Scenario;
use anyhow::bail;
use common::control::gains::GainSet;
use serde::Serialize;
use std::path::PathBuf;

/// One scenario at one noise level, every gain set.
#[derive(Clone, Debug, Serialize)]
pub struct ScenarioResult {
    /// The scenario.
    pub scenario: Scenario,
    /// Noise sigma.
    pub noise_sigma: f64,
    /// Figures per gain set, in option order.
    pub metrics: Vec<RunMetrics>,
    /// The runs (time series), not serialised.
    #[serde(skip)]
    pub runs: Vec<Run>,
}

impl ScenarioResult {
    /// The figures of one gain set.
    pub fn metrics_of(&self, gains: &str) -> Option<&RunMetrics> {
        self.metrics.iter().find(|m| m.gains == gains)
    }

    /// The run of one gain set.
    pub fn run_of(&self, gains: &str) -> Option<&Run> {
        self.runs.iter().find(|r| r.gains == gains)
    }

    /// File stem: scenario name, `_noise` when noisy.
    pub fn stem(&self) -> String {
        if self.noise_sigma > 0.0 {
            format!("{}_noise", self.scenario.name)
        } else {
            self.scenario.name.to_string()
        }
    }
}

/// All results of a command, the files written and the printed tables.
#[derive(Clone, Debug, Serialize)]
pub struct ScenarioReport {
    /// Airspeed of the level trim every run starts from, m/s.
    pub trim_airspeed_mps: f64,
    /// Pitch of that trim, deg.
    pub trim_pitch_deg: f64,
    /// Per scenario and noise level.
    pub results: Vec<ScenarioResult>,
    /// Files written.
    pub files: Vec<PathBuf>,
    /// Printed tables.
    #[serde(skip)]
    pub tables: Vec<Table>,
}

impl ScenarioReport {
    /// The result of a scenario at a noise level (0 for none).
    pub fn get(&self, scenario: &str, noisy: bool) -> Option<&ScenarioResult> {
        self.results
            .iter()
            .find(|r| r.scenario.name == scenario && (r.noise_sigma > 0.0) == noisy)
    }
}

/// Checks a noise sigma from the user.
pub fn check_noise(sigma: f64) -> anyhow::Result<f64> {
    if !sigma.is_finite() || sigma < 0.0 {
        bail!("--noise {sigma}: the noise sigma must be finite and >= 0");
    }
    Ok(sigma)
}

/// The level trim the scenarios start from when flown at the thesis's airspeed (17 m/s, 100 m).
pub fn level_trim(aircraft: &Aircraft) -> anyhow::Result<TrimResult> {
    level_trim_at(aircraft, TrimTarget::level().va_mps)
}

/// The level trim at `va_mps` (100 m) the scenarios start from; an airspeed the aircraft
/// cannot be trimmed at is an error naming it.
pub fn level_trim_at(aircraft: &Aircraft, va_mps: f64) -> anyhow::Result<TrimResult> {
    let tr = trim(aircraft, &TrimTarget::level().at_airspeed(va_mps));
    if !tr.converged {
        bail!("{}; cannot fly the scenarios", not_trimmed(&tr));
    }
    Ok(tr)
}

/// Flies one scenario with every gain set of `sets` (in parallel, one thread per set).
pub fn fly(
    aircraft: &Aircraft,
    trim: &TrimResult,
    scenario: &Scenario,
    sets: &[(String, GainSet)],
    cfg: &SimConfig,
) -> anyhow::Result<ScenarioResult> {
    let runs: Vec<anyhow::Result<Run>> = std::thread::scope(|s| {
        let handles: Vec<_> = sets
            .iter()
            .map(|(name, g)| s.spawn(move || simulate(aircraft, trim, name, g, scenario, cfg)))
            .collect();
        handles
            .into_iter()
            .map(|h| {
                h.join()
                    .unwrap_or_else(|_| Err(anyhow::anyhow!("a simulation thread panicked")))
            })
            .collect()
    });
    let runs = runs.into_iter().collect::<anyhow::Result<Vec<_>>>()?;
    let metrics = runs.iter().map(|r| run_metrics(scenario, r)).collect();
    Ok(ScenarioResult {
        scenario: *scenario,
        noise_sigma: cfg.noise_sigma,
        metrics,
        runs,
    })
}
