//! What each result prints and writes: its metrics table, and its CSV, PNG and JSON files.

use super::run::ScenarioResult;
use crate::report::csv_out::write_csv;
use crate::report::plot::{Figure, Panel, Series};
use crate::report::table::Table;
use crate::report::{sig, sig_or_dash, to_json};
use crate::scenario::Axis;
use anyhow::Context;
use std::path::{Path, PathBuf};

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
        Axis::Pitch | Axis::Altitude | Axis::Airspeed => "peak |elevator| (deg)",
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
            Axis::Pitch | Axis::Altitude | Axis::Airspeed => m.peak_elevator_deg,
        };
        t.row([
            m.gains.clone(),
            sig_or_dash(m.rise_time_s, 3),
            sig(m.overshoot_pct, 3),
            sig_or_dash(m.settling_time_s, 3),
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
    // One series per gain set of the quantity `f` reads from a sample.
    let per_set = |f: fn(&crate::scenario::sim::Sample) -> f64| -> Vec<Series> {
        r.runs
            .iter()
            .map(|run| {
                Series::new(
                    run.gains.clone(),
                    t.clone(),
                    run.samples.iter().map(f).collect(),
                )
            })
            .collect()
    };
    // The command goes last so each gain set keeps the same colour in every panel.
    let mut resp = per_set(|s| s.response);
    resp.push(
        Series::new(
            "command",
            t.clone(),
            first.samples.iter().map(|s| s.command).collect(),
        )
        .dashed(),
    );
    let (sname, sfn): (&str, fn(&crate::scenario::sim::Sample) -> f64) = match axis {
        Axis::Roll | Axis::Heading => ("aileron", |s| s.aileron_deg),
        Axis::Sideslip => ("rudder", |s| s.rudder_deg),
        Axis::Pitch | Axis::Altitude | Axis::Airspeed => ("elevator", |s| s.elevator_deg),
    };
    let surf = per_set(sfn);
    let mut panels = vec![
        Panel::new(format!("{} ({unit})", axis.quantity()), resp),
        Panel::new(format!("{sname} (deg)"), surf),
    ];
    if axis == Axis::Altitude {
        panels.push(Panel::new("pitch (deg)", per_set(|s| s.pitch_deg)));
    }
    let noise = if r.noise_sigma > 0.0 {
        format!(", noise sigma {}", r.noise_sigma)
    } else {
        String::new()
    };
    Figure::new(
        format!(
            "{}{noise}: nonlinear plant, servos, 2-sample delay",
            r.scenario.name
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
