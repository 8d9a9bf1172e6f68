//! `sim-host scenario`: the closed-loop tests of thesis chapter 4 on the nonlinear plant, for
//! several gain sets, with CSV, PNG, JSON and a metrics table per scenario.

use crate::aircraft::Aircraft;
use crate::analysis::design::computed_gain_set;
use crate::analysis::trim::{trim, TrimResult, TrimTarget};
use crate::report::csv_out::write_csv;
use crate::report::{sig, to_json, Figure, Panel, Series, Table};
use crate::scenario::metrics::{run_metrics, RunMetrics};
use crate::scenario::sim::{simulate, Run, SimConfig};
use crate::scenario::{Axis, Scenario, UnknownScenario, SCENARIOS};
use anyhow::{bail, Context};
use common::control::gains::{GainSet, NAMES};
use serde::Serialize;
use std::path::{Path, PathBuf};

/// Noise sigma of the noisy half of `scenario all` (thesis: 1e-3 rad on angles, 1e-3 m on
/// altitude).
pub const THESIS_NOISE_SIGMA: f64 = 1e-3;

/// Name of the gain set designed from the linear model of the aircraft flown
/// ([`computed_gain_set`]).
pub const COMPUTED: &str = "computed";

/// Every gain set the command can fly: the named sets of `common`, then [`COMPUTED`].
pub fn gain_set_names() -> Vec<&'static str> {
    let mut v = NAMES.to_vec();
    v.push(COMPUTED);
    v
}

/// An unknown gain-set name, with the valid ones.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("unknown gain set `{name}`; valid names: {}", valid.join(", "))]
pub struct UnknownGainSet {
    /// The name asked for.
    pub name: String,
    /// The valid names.
    pub valid: Vec<&'static str>,
}

/// The gain set of this name for `aircraft` (only [`COMPUTED`] depends on the aircraft).
pub fn gain_set(aircraft: &Aircraft, name: &str) -> anyhow::Result<GainSet> {
    if name == COMPUTED {
        return computed_gain_set(aircraft).context("designing the computed gain set");
    }
    GainSet::named(name).map_err(|_| {
        UnknownGainSet {
            name: name.to_string(),
            valid: gain_set_names(),
        }
        .into()
    })
}

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

/// The level trim every scenario starts from (17 m/s, 100 m).
pub fn level_trim(aircraft: &Aircraft) -> anyhow::Result<TrimResult> {
    let tr = trim(aircraft, &TrimTarget::level());
    if !tr.converged {
        bail!(
            "level trim did not converge (residual {:.3e})",
            tr.residual_norm
        );
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

fn opt(x: Option<f64>, digits: usize) -> String {
    x.map_or_else(|| "-".into(), |v| sig(v, digits))
}

/// The metrics table of one result.
pub fn metrics_table(r: &ScenarioResult) -> Table {
    let unit = r.scenario.axis.unit();
    let noise = if r.noise_sigma > 0.0 {
        format!(", noise sigma {}", r.noise_sigma)
    } else {
        String::new()
    };
    let surface = match r.scenario.axis {
        Axis::Roll | Axis::Heading => "peak |aileron| (deg)",
        Axis::Sideslip => "peak |rudder| (deg)",
        Axis::Pitch | Axis::Altitude => "peak |elevator| (deg)",
    };
    let sse = format!("max |ss error| ({unit})");
    let ripple = format!("ripple RMS ({unit})");
    let mut t = Table::new(
        format!("{}: {}{noise}", r.scenario.name, r.scenario.description),
        &[
            "gain set",
            "rise 10-90 % (s)",
            "overshoot (%)",
            "settling 2 % (s)",
            &sse,
            surface,
            &ripple,
            "peak |pitch cmd| (deg)",
            "altitude range (m)",
        ],
    );
    for m in &r.metrics {
        let peak = match r.scenario.axis {
            Axis::Roll | Axis::Heading => m.peak_aileron_deg,
            Axis::Sideslip => m.peak_rudder_deg,
            Axis::Pitch | Axis::Altitude => m.peak_elevator_deg,
        };
        t.row([
            m.gains.clone(),
            opt(m.rise_time_s, 3),
            sig(m.overshoot_pct, 3),
            opt(m.settling_time_s, 3),
            sig(m.steady_state_error.abs(), 2),
            sig(peak, 3),
            sig(m.ripple_rms, 2),
            sig(m.peak_pitch_cmd_deg, 3),
            format!("{:.1} .. {:.1}", m.alt_range_m[0], m.alt_range_m[1]),
        ]);
    }
    t
}

fn figure(r: &ScenarioResult) -> Figure {
    let axis = r.scenario.axis;
    let unit = axis.unit();
    let Some(first) = r.runs.first() else {
        return Figure::new(r.scenario.name, "time (s)", Vec::new());
    };
    let t: Vec<f64> = first.samples.iter().map(|s| s.t).collect();
    let mut resp = vec![Series::new(
        "command",
        t.clone(),
        first.samples.iter().map(|s| s.command).collect(),
    )
    .dashed()];
    for run in &r.runs {
        resp.push(Series::new(
            run.gains.clone(),
            t.clone(),
            run.samples.iter().map(|s| s.response).collect(),
        ));
    }
    let (sname, sfn): (&str, fn(&crate::scenario::sim::Sample) -> f64) = match axis {
        Axis::Roll | Axis::Heading => ("aileron", |s| s.aileron_deg),
        Axis::Sideslip => ("rudder", |s| s.rudder_deg),
        Axis::Pitch | Axis::Altitude => ("elevator", |s| s.elevator_deg),
    };
    let surf = r
        .runs
        .iter()
        .map(|run| {
            Series::new(
                run.gains.clone(),
                t.clone(),
                run.samples.iter().map(sfn).collect(),
            )
        })
        .collect();
    let mut panels = vec![
        Panel::new(format!("{} ({unit})", axis.quantity()), resp),
        Panel::new(format!("{sname} (deg)"), surf),
    ];
    if axis == Axis::Altitude {
        panels.push(Panel::new(
            "pitch (deg)",
            r.runs
                .iter()
                .map(|run| {
                    Series::new(
                        run.gains.clone(),
                        t.clone(),
                        run.samples.iter().map(|s| s.pitch_deg).collect(),
                    )
                })
                .collect(),
        ));
    }
    let noise = if r.noise_sigma > 0.0 {
        format!(", noise sigma {}", r.noise_sigma)
    } else {
        String::new()
    };
    Figure::new(
        format!(
            "{}{noise} (nonlinear plant, servos, 2-sample delay)",
            r.scenario.description
        ),
        "time (s)",
        panels,
    )
}

/// Writes the CSV (time, command, every set's response, every set's surfaces), the PNG and the
/// metrics JSON of one result into `dir`.
pub fn write_result(r: &ScenarioResult, dir: &Path) -> anyhow::Result<Vec<PathBuf>> {
    let axis = r.scenario.axis;
    let unit = axis.unit();
    let q = axis.quantity();
    let mut headers = vec!["t_s".to_string(), format!("command_{q}_{unit}")];
    for run in &r.runs {
        headers.push(format!("{}_{q}_{unit}", run.gains));
    }
    for run in &r.runs {
        for s in ["elevator_deg", "aileron_deg", "rudder_deg", "throttle"] {
            headers.push(format!("{}_{s}", run.gains));
        }
    }
    let n = r.runs.first().map_or(0, |x| x.samples.len());
    let rows: Vec<Vec<f64>> = (0..n)
        .map(|k| {
            let s0 = &r.runs[0].samples[k];
            let mut row = vec![s0.t, s0.command];
            row.extend(r.runs.iter().map(|run| run.samples[k].response));
            for run in &r.runs {
                let s = &run.samples[k];
                row.extend([s.elevator_deg, s.aileron_deg, s.rudder_deg, s.throttle]);
            }
            row
        })
        .collect();
    let stem = r.stem();
    let csv = dir.join(format!("{stem}.csv"));
    write_csv(&csv, &headers, &rows)?;
    let png = dir.join(format!("{stem}.png"));
    figure(r).save_png(&png)?;
    let json = dir.join(format!("{stem}.json"));
    std::fs::write(&json, to_json(r)?)
        .with_context(|| format!("cannot write `{}`", json.display()))?;
    Ok(vec![csv, png, json])
}

/// Runs scenario `name` (or `all`: every scenario without noise and with
/// [`ScenarioOptions::noise_sigma`], or [`THESIS_NOISE_SIGMA`] when that is 0) for every gain
/// set of `opts`; writes CSV, PNG and JSON files into `out_dir` if given.
pub fn scenario_report(
    aircraft: &Aircraft,
    name: &str,
    opts: &ScenarioOptions,
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
    let sets = opts
        .gains
        .iter()
        .map(|n| Ok((n.clone(), gain_set(aircraft, n)?)))
        .collect::<anyhow::Result<Vec<_>>>()?;
    let trim = level_trim(aircraft)?;
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
        results,
        files,
        tables,
    })
}

/// The results document (Markdown): how it was produced, the metrics of every scenario for
/// every gain set, and the verdicts on the thesis's claims and the design requirements.
pub fn results_markdown(report: &ScenarioReport, command: &str) -> String {
    let mut s = String::new();
    s.push_str(&format!("Produced by `{command}`.\n\n"));
    for t in &report.tables {
        s.push_str(&t.render_markdown());
        s.push('\n');
    }
    s
}
