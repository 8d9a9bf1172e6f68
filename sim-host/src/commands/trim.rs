//! `sim-host trim`: the thesis's Table 2.3 targets and the steady-heading sideslip, at the
//! aircraft's cruise airspeed or another.

use crate::aircraft::Aircraft;
use crate::analysis::references::{apply_to, umn_trim, ThesisTrim, THESIS_TRIM};
use crate::analysis::trim::{trim_with, TrimResult, TrimTarget};
use crate::plant::params::ModelParams;
use crate::report::table::Table;
use crate::report::{pct, sig};
use serde::Serialize;

/// One trimmed target with its references.
#[derive(Clone, Debug, Serialize)]
pub struct TrimEntry {
    /// Our trim.
    pub result: TrimResult,
    /// Thesis Table 2.3 column, if the thesis has this target.
    pub thesis: Option<ThesisTrim>,
    /// Whether the UMN committed trim applies (level only).
    pub umn_level: bool,
}

/// All trims.
#[derive(Clone, Debug, Serialize)]
pub struct TrimReport {
    /// One entry per target.
    pub trims: Vec<TrimEntry>,
    /// Printed tables.
    pub tables: Vec<Table>,
}

impl TrimReport {
    /// The entry of a target name.
    pub fn get(&self, name: &str) -> Option<&TrimEntry> {
        self.trims.iter().find(|e| e.result.target.name == name)
    }

    /// Names and residuals of targets that did not converge.
    pub fn failures(&self) -> Vec<(String, f64)> {
        self.trims
            .iter()
            .filter(|e| !e.result.converged)
            .map(|e| (e.result.target.name.clone(), e.result.residual_norm))
            .collect()
    }
}

fn diff_cells(ours: f64, reference: Option<f64>, digits: usize) -> [String; 2] {
    match reference {
        Some(r) => {
            let d = ours - r;
            let rel = if r.abs() > 1e-9 {
                format!(" ({:+.2} %)", pct(ours, r))
            } else {
                String::new()
            };
            [sig(r, digits), format!("{}{}", sig(d, 2), rel)]
        }
        None => ["-".into(), "-".into()],
    }
}

/// One table row: quantity, unit, ours, thesis, UMN.
type Row<'a> = (&'a str, &'a str, f64, Option<f64>, Option<f64>);

/// Builds the table of one trim.
pub fn trim_table(e: &TrimEntry) -> Table {
    let r = &e.result;
    let status = if r.converged {
        format!(
            "converged, residual {:.1e}, {} iterations",
            r.residual_norm, r.iterations
        )
    } else {
        format!(
            "NOT CONVERGED: target `{}` residual {:.3e} after {} iterations",
            r.target.name, r.residual_norm, r.iterations
        )
    };
    let mut t = Table::new(
        format!(
            "Trim {} (Va {} m/s, h {} m): {}",
            r.target.description, r.target.va_mps, r.target.alt_msl_m, status
        ),
        &[
            "quantity",
            "unit",
            "ours",
            "thesis",
            "ours - thesis",
            "UMN sim",
            "ours - UMN",
        ],
    );
    let th = e.thesis;
    let umn = e.umn_level;
    let rows: [Row; 14] = [
        (
            "throttle",
            "0..1",
            r.throttle,
            th.map(|x| x.throttle),
            umn.then_some(umn_trim::THROTTLE),
        ),
        (
            "elevator",
            "rad",
            r.elevator,
            th.map(|x| x.elevator),
            umn.then_some(umn_trim::ELEVATOR),
        ),
        (
            "aileron",
            "rad",
            r.aileron,
            th.map(|x| x.aileron),
            umn.then_some(umn_trim::AILERON),
        ),
        (
            "rudder",
            "rad",
            r.rudder,
            th.map(|x| x.rudder),
            umn.then_some(umn_trim::RUDDER),
        ),
        (
            "alpha",
            "rad",
            r.alpha,
            th.map(|x| x.alpha),
            umn.then_some(umn_trim::ALPHA),
        ),
        ("beta", "rad", r.beta, th.map(|_| 0.0), umn.then_some(0.0)),
        (
            "phi",
            "rad",
            r.phi,
            th.map(|x| x.phi),
            umn.then_some(umn_trim::PHI),
        ),
        (
            "theta",
            "rad",
            r.theta,
            th.map(|x| x.theta),
            umn.then_some(umn_trim::THETA),
        ),
        ("gamma", "rad", r.gamma, Some(r.target.gamma_rad), None),
        ("p", "rad/s", r.p, th.map(|x| x.p), umn.then_some(0.0)),
        ("q", "rad/s", r.q, th.map(|x| x.q), umn.then_some(0.0)),
        ("r", "rad/s", r.r, th.map(|x| x.r), umn.then_some(0.0)),
        (
            "Omega",
            "rad/s",
            r.engine_speed,
            None,
            umn.then_some(umn_trim::ENGINE_SPEED),
        ),
        ("thrust", "N", r.thrust_n, None, None),
    ];
    for (name, unit, ours, thesis, umn_v) in rows {
        let [tv, td] = diff_cells(ours, thesis, 3);
        let [uv, ud] = diff_cells(ours, umn_v, 6);
        t.row([
            name.to_string(),
            unit.to_string(),
            sig(ours, 6),
            tv,
            td,
            uv,
            ud,
        ]);
    }
    if umn {
        for (i, axis) in ["x", "y", "z"].iter().enumerate() {
            let [uv, ud] = diff_cells(
                r.specific_force_body[i],
                Some(umn_trim::SPECIFIC_FORCE[i]),
                6,
            );
            t.row([
                format!("specific force {axis}"),
                "m/s^2".into(),
                sig(r.specific_force_body[i], 6),
                "-".into(),
                "-".into(),
                uv,
                ud,
            ]);
        }
    }
    t
}

/// Trims every target at the aircraft's cruise airspeed.
pub fn trim_report(aircraft: &Aircraft) -> TrimReport {
    trim_report_at(aircraft, aircraft.cruise_airspeed_mps())
}

/// Trims every target at `va_mps`; the thesis's and the Minnesota columns only for the
/// Ultra Stick 25e at 17 m/s.
pub fn trim_report_at(aircraft: &Aircraft, va_mps: f64) -> TrimReport {
    let p = ModelParams::new(aircraft);
    let refs = apply_to(aircraft, va_mps);
    let trims: Vec<TrimEntry> = TrimTarget::all()
        .into_iter()
        .map(|target| target.at_airspeed(va_mps))
        .map(|target| TrimEntry {
            result: trim_with(&p, &target),
            thesis: THESIS_TRIM
                .iter()
                .find(|x| refs && x.name == target.name)
                .copied(),
            umn_level: refs && target.name == "level",
        })
        .collect();
    let tables = trims.iter().map(trim_table).collect();
    TrimReport { trims, tables }
}
