//! `sim-host scenario`: the closed-loop tests of thesis chapter 4 on the nonlinear plant, for
//! several gain sets, with CSV, PNG, JSON and a metrics table per scenario.
//!
//! [`run`] flies one scenario with every gain set, [`tables`] prints and writes each result,
//! [`document`] (with [`claims`]) writes the results document.

pub mod claims;
pub mod document;
pub mod gains;
pub mod run;
pub mod tables;

use crate::aircraft::Aircraft;
use crate::scenario::sim::SimConfig;
use crate::scenario::{Scenario, UnknownScenario, SCENARIOS};
use anyhow::{bail, Context};
use std::path::Path;

pub use claims::CLIMB_WINDOW_S;
pub use document::results_markdown;
pub use gains::{
    gain_file, gain_set, gain_set_at, gain_set_names, known_gain_set_names, UnknownGainSet,
    COMPUTED, FLIGHT_TECS,
};
pub use run::{check_noise, fly, level_trim, level_trim_at, ScenarioReport, ScenarioResult};
pub use tables::{metrics_table, write_result};

/// Noise sigma of the noisy half of `scenario all` (thesis: 1e-3 rad on angles, 1e-3 m on
/// altitude).
pub const THESIS_NOISE_SIGMA: f64 = 1e-3;

/// What to fly.
#[derive(Clone, Debug, PartialEq)]
pub struct ScenarioOptions {
    /// Gain sets, by name, in plot order.
    pub gains: Vec<String>,
    /// Noise sigma of single runs; in `all`, the sigma of the noisy half.
    pub noise_sigma: f64,
    /// Noise seed.
    pub seed: u64,
    /// Show a progress bar on standard error (hidden when it is not a terminal).
    pub progress: bool,
}

impl Default for ScenarioOptions {
    fn default() -> Self {
        Self {
            gains: gain_set_names().iter().map(|s| s.to_string()).collect(),
            noise_sigma: 0.0,
            seed: 1,
            progress: false,
        }
    }
}

/// [`scenario_report_at`] from the level trim at `aircraft`'s cruise airspeed.
pub fn scenario_report(
    aircraft: &Aircraft,
    name: &str,
    opts: &ScenarioOptions,
    out_dir: Option<&Path>,
) -> anyhow::Result<ScenarioReport> {
    scenario_report_at(
        aircraft,
        name,
        opts,
        aircraft.cruise_airspeed_mps(),
        out_dir,
    )
}

/// Runs scenario `name` (or `all`: every scenario without noise and with
/// [`ScenarioOptions::noise_sigma`], or [`THESIS_NOISE_SIGMA`] when that is 0) for every gain
/// set of `opts`, from the level trim at `va_mps`; writes CSV, PNG and JSON files into
/// `out_dir` if given.
pub fn scenario_report_at(
    aircraft: &Aircraft,
    name: &str,
    opts: &ScenarioOptions,
    va_mps: f64,
    out_dir: Option<&Path>,
) -> anyhow::Result<ScenarioReport> {
    let sigma = check_noise(opts.noise_sigma)?;
    let plan: Vec<(&Scenario, f64)> = if name == "all" {
        let noisy = if sigma > 0.0 {
            sigma
        } else {
            THESIS_NOISE_SIGMA
        };
        SCENARIOS
            .iter()
            .flat_map(|s| [(s, 0.0), (s, noisy)])
            .collect()
    } else {
        let s = Scenario::by_name(name).map_err(|e: UnknownScenario| anyhow::anyhow!(e))?;
        vec![(s, sigma)]
    };
    if opts.gains.is_empty() {
        bail!(
            "no gain set given; valid names: {}",
            gain_set_names().join(", ")
        );
    }
    // Trimmed before the gains: the computed set's design trims there too, and its error
    // would name the design rather than the scenarios.
    let trim = level_trim_at(aircraft, va_mps)?;
    let sets = opts
        .gains
        .iter()
        .map(|n| Ok((n.clone(), gain_set_at(aircraft, n, va_mps)?)))
        .collect::<anyhow::Result<Vec<_>>>()?;
    if let Some(dir) = out_dir {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("cannot create output directory `{}`", dir.display()))?;
    }
    let bar = if opts.progress {
        let b = indicatif::ProgressBar::new(plan.len() as u64);
        b.set_style(
            indicatif::ProgressStyle::with_template("{bar:30} {pos}/{len} {msg} [{elapsed}]")
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        b
    } else {
        indicatif::ProgressBar::hidden()
    };
    let mut results = Vec::new();
    let mut files = Vec::new();
    for (s, noise_sigma) in plan {
        bar.set_message(format!(
            "{}{}",
            s.name,
            if noise_sigma > 0.0 { " (noise)" } else { "" }
        ));
        let cfg = SimConfig {
            noise_sigma,
            seed: opts.seed,
            ..SimConfig::default()
        };
        let r = fly(aircraft, &trim, s, &sets, &cfg)?;
        if let Some(dir) = out_dir {
            files.extend(write_result(&r, dir)?);
        }
        results.push(r);
        bar.inc(1);
    }
    bar.finish_and_clear();
    let tables = results.iter().map(metrics_table).collect();
    Ok(ScenarioReport {
        trim_airspeed_mps: trim.target.va_mps,
        trim_pitch_deg: trim.theta.to_degrees(),
        results,
        files,
        tables,
    })
}
