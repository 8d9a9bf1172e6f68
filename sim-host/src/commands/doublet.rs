//! `sim-host doublet`: the linear-versus-nonlinear doublet check (thesis section 3.2).

use crate::aircraft::Aircraft;
use crate::analysis::doublet::{run, DoubletConfig, DoubletRun, Surface, OUTPUT_INFO};
use crate::analysis::linearize::linearize;
use crate::analysis::references::{apply_to, THESIS_DOUBLET_LAT, THESIS_DOUBLET_LON};
use crate::analysis::trim::{not_trimmed, trim_with, TrimResult, TrimTarget};
use crate::plant::params::ModelParams;
use crate::report::csv_out::write_csv;
use crate::report::plot::{Figure, Panel, Series};
use crate::report::sig;
use crate::report::table::Table;
use anyhow::{bail, Context};
use serde::Serialize;
use std::path::{Path, PathBuf};

/// The three doublets and where their files went.
#[derive(Clone, Debug, Serialize)]
pub struct DoubletReport {
    /// The level trim the doublets start from and the linear model is taken at.
    pub trim: TrimResult,
    /// Elevator, aileron and rudder runs.
    pub runs: Vec<DoubletRun>,
    /// Files written (CSV and PNG).
    pub files: Vec<PathBuf>,
    /// Printed tables.
    pub tables: Vec<Table>,
}

impl DoubletReport {
    /// Largest difference of an output (by [`OUTPUT_INFO`] name) in the run of `surface`.
    pub fn max_diff(&self, surface: Surface, output: &str) -> Option<f64> {
        let i = OUTPUT_INFO.iter().position(|o| o.0 == output)?;
        self.runs
            .iter()
            .find(|r| r.surface == surface)
            .map(|r| r.max_abs_diff[i])
    }
}

const LON_OUTPUTS: [&str; 4] = ["airspeed", "alpha", "theta", "q"];
const LAT_OUTPUTS: [&str; 4] = ["beta", "p", "r", "phi"];

fn figure(run: &DoubletRun, va_mps: f64) -> Figure {
    let t: Vec<f64> = run.samples.iter().map(|s| s.t).collect();
    let names = if run.surface == Surface::Elevator {
        LON_OUTPUTS
    } else {
        LAT_OUTPUTS
    };
    let deg = 180.0 / std::f64::consts::PI;
    let mut panels = vec![Panel::new(
        format!("{} (deg)", run.surface.name()),
        vec![Series::new(
            "servo output",
            t.clone(),
            run.samples.iter().map(|s| s.surface * deg).collect(),
        )],
    )];
    for name in names {
        let Some(i) = OUTPUT_INFO.iter().position(|o| o.0 == name) else {
            continue;
        };
        let (_, unit, scale) = OUTPUT_INFO[i];
        panels.push(Panel::new(
            format!("{name} ({unit})"),
            vec![
                Series::new(
                    "nonlinear",
                    t.clone(),
                    run.samples
                        .iter()
                        .map(|s| s.nonlinear.as_array()[i] * scale)
                        .collect(),
                ),
                Series::new(
                    "linear",
                    t.clone(),
                    run.samples
                        .iter()
                        .map(|s| s.linear.as_array()[i] * scale)
                        .collect(),
                )
                .dashed(),
            ],
        ));
    }
    Figure::new(
        format!(
            "{} doublet {:.1} deg from level trim at {va_mps} m/s: nonlinear vs linear",
            run.surface.name(),
            run.config.amplitude_rad * deg
        ),
        "time (s)",
        panels,
    )
}

fn write_run(run: &DoubletRun, va_mps: f64, dir: &Path) -> anyhow::Result<Vec<PathBuf>> {
    let mut headers = vec!["t_s".to_string(), format!("{}_deg", run.surface.name())];
    for prefix in ["nonlinear", "linear"] {
        for (name, unit, _) in OUTPUT_INFO {
            headers.push(format!("{prefix}_{name}_{}", unit.replace('/', "p")));
        }
    }
    let deg = 180.0 / std::f64::consts::PI;
    let rows: Vec<Vec<f64>> = run
        .samples
        .iter()
        .map(|s| {
            let mut r = vec![s.t, s.surface * deg];
            for o in [s.nonlinear.as_array(), s.linear.as_array()] {
                r.extend(o.iter().zip(OUTPUT_INFO.iter()).map(|(v, info)| v * info.2));
            }
            r
        })
        .collect();
    let csv = dir.join(format!("doublet_{}.csv", run.surface.name()));
    write_csv(&csv, &headers, &rows)?;
    let png = dir.join(format!("doublet_{}.png", run.surface.name()));
    figure(run, va_mps).save_png(&png)?;
    Ok(vec![csv, png])
}

/// [`doublet_report_at`] about the level trim at `aircraft`'s cruise airspeed.
pub fn doublet_report(
    aircraft: &Aircraft,
    cfg: &DoubletConfig,
    out_dir: Option<&Path>,
) -> anyhow::Result<DoubletReport> {
    doublet_report_at(aircraft, cfg, aircraft.cruise_airspeed_mps(), out_dir)
}

/// Runs the three doublets from the level trim at `va_mps`, the linear model taken there;
/// writes CSV and PNG files into `out_dir` if given. The thesis's Tables 3.1 and 3.2 are
/// quoted only where they apply (the Ultra Stick 25e at 17 m/s).
pub fn doublet_report_at(
    aircraft: &Aircraft,
    cfg: &DoubletConfig,
    va_mps: f64,
    out_dir: Option<&Path>,
) -> anyhow::Result<DoubletReport> {
    let p = ModelParams::new(aircraft);
    let trim = trim_with(&p, &TrimTarget::level().at_airspeed(va_mps));
    if !trim.converged {
        bail!("{}; cannot run the doublets", not_trimmed(&trim));
    }
    let refs = apply_to(aircraft, va_mps);
    let lin = linearize(&p, &trim);
    let mut runs = Vec::new();
    let mut files = Vec::new();
    if let Some(dir) = out_dir {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("cannot create output directory `{}`", dir.display()))?;
    }
    for s in [Surface::Elevator, Surface::Aileron, Surface::Rudder] {
        let r = run(aircraft, &trim, &lin, s, cfg);
        if let Some(dir) = out_dir {
            files.extend(write_run(&r, va_mps, dir)?);
        }
        runs.push(r);
    }
    let deg = 180.0 / std::f64::consts::PI;
    let mut t = Table::new(
        format!(
            "Largest |nonlinear - linear| after a {:.1} deg doublet ({} s each way, from t = {} s, {} s run, RK4 dt {} s, servo model on both)",
            cfg.amplitude_rad * deg,
            cfg.half_period_s,
            cfg.start_s,
            cfg.duration_s,
            cfg.dt_s
        ),
        &["doublet", "output", "unit", "max |NL - lin|", "peak response", "diff / peak", "thesis (Tables 3.1, 3.2)"],
    );
    for r in &runs {
        let names: &[&str] = if r.surface == Surface::Elevator {
            &LON_OUTPUTS
        } else {
            &LAT_OUTPUTS
        };
        for name in names {
            let Some(i) = OUTPUT_INFO.iter().position(|o| o.0 == *name) else {
                continue;
            };
            let thesis = THESIS_DOUBLET_LON
                .iter()
                .chain(THESIS_DOUBLET_LAT.iter())
                .find(|x| refs && x.0 == *name)
                .filter(|_| (r.surface == Surface::Elevator) == LON_OUTPUTS.contains(name))
                .map(|x| {
                    if x.1 > 0.0 {
                        sig(x.1, 2)
                    } else {
                        "0 (no visible error)".into()
                    }
                })
                .unwrap_or_else(|| "-".into());
            let (d, peak) = (r.max_abs_diff[i], r.max_abs_response[i]);
            t.row([
                r.surface.name().to_string(),
                name.to_string(),
                OUTPUT_INFO[i].1.to_string(),
                sig(d, 3),
                sig(peak, 3),
                format!("{:.1} %", 100.0 * d / peak.max(1e-12)),
                thesis,
            ]);
        }
    }
    Ok(DoubletReport {
        trim,
        runs,
        files,
        tables: vec![t],
    })
}
