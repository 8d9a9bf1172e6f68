//! `sim-host design --model MODEL.json`: the successive-loop-closure design on reduced models
//! identified from flight (`sim-host identify --json`), with each loop's margins checked
//! against its targets, and the gains as a QGroundControl parameter file.

use crate::analysis::design::inputs::DesignInputs;
use crate::analysis::design::{design_from_model, Design, ReducedModel};
use crate::analysis::reduced::ReducedCoefficients;
use crate::commands::identify::IdentifyReport;
use crate::report::table::Table;
use crate::report::{sig, sig_or_dash};
use anyhow::{anyhow, bail, Context};
use common::math::STANDARD_GRAVITY;
use serde::Serialize;
use std::fmt::Write as _;
use std::path::Path;

/// Gain margin every loop must keep, dB (MIL-F-9490D's 6 dB).
pub const GAIN_MARGIN_MIN_DB: f64 = 6.0;

/// Phase margin an outer loop must keep, deg: the classical lower bound for a loop whose
/// bandwidth the design already separates from the inner loop's; the inner attitude loops
/// keep the design's own target (`DesignInputs::inner_phase_margin_deg`, 45 deg).
pub const OUTER_PHASE_MARGIN_MIN_DEG: f64 = 30.0;

/// Whether a loop of the design is an inner (attitude) loop.
fn inner(name: &str) -> bool {
    name.contains("attitude")
}

/// One loop's margins against the targets.
#[derive(Clone, Debug, Serialize)]
pub struct MarginCheck {
    /// The loop.
    pub name: String,
    /// Its gain and phase margins (`None`: no crossing in the band, unbounded).
    pub gain_margin_db: Option<f64>,
    /// Phase margin, deg.
    pub phase_margin_deg: Option<f64>,
    /// Why it fails its targets (`None`: it meets them).
    pub failure: Option<String>,
}

/// What `design --model` reports.
#[derive(Clone, Debug, Serialize)]
pub struct ModelDesignReport {
    /// The model designed on.
    pub model: ReducedModel,
    /// The design.
    pub design: Design,
    /// Every loop's margins against the targets.
    pub checks: Vec<MarginCheck>,
    /// Tables printed.
    #[serde(skip)]
    pub tables: Vec<Table>,
}

impl ModelDesignReport {
    /// The loops that fail their margins, with the reason.
    pub fn failures(&self) -> Vec<String> {
        self.checks
            .iter()
            .filter_map(|c| c.failure.as_ref().map(|f| format!("{}: {f}", c.name)))
            .collect()
    }

    /// The designed gains as a QGroundControl parameter file (tab-separated: vehicle,
    /// component, name, value, MAV_PARAM_TYPE 9 = REAL32), for vehicle 1, component 1.
    pub fn params_file(&self) -> String {
        let mut out = String::from(
            "# Onboard parameters for Vehicle 1\n#\n# Gains designed by successive loop closure on identified reduced models (sim-host design --model)\n#\n# Vehicle-Id Component-Id Name Value Type\n",
        );
        for l in &self.design.loops {
            for (name, value, _) in &l.gains {
                let _ = writeln!(out, "1\t1\t{name}\t{}\t9", *value as f32);
            }
        }
        out
    }
}

/// Reads the model of a `sim-host identify --json` report (its [`IdentifyReport`]).
pub fn read_model(path: &Path) -> anyhow::Result<ReducedModel> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    let r: IdentifyReport = serde_json::from_str(&text).with_context(|| {
        format!(
            "{}: not a `sim-host identify --json` report",
            path.display()
        )
    })?;
    let (va, tau) = (r.airspeed_ref_mps, r.servo_tau_s);
    if !(va.is_finite() && va > 0.0 && tau.is_finite() && tau > 0.0) {
        bail!(
            "{}: `airspeed_ref_mps` {va} and `servo_tau_s` {tau} must be positive",
            path.display()
        );
    }
    let coefficient = |axis: &str, name: &str| {
        r.coefficient(axis, name)
            .map_err(|e| anyhow!("{}: {e}", path.display()))
    };
    Ok(ReducedModel {
        va,
        coefficients: ReducedCoefficients {
            a_phi1: coefficient("roll", "a_phi1")?,
            a_phi2: coefficient("roll", "a_phi2")?,
            a_theta1: coefficient("pitch", "a_theta1")?,
            a_theta2: coefficient("pitch", "a_theta2")?,
            a_theta3: coefficient("pitch", "a_theta3")?,
            a_v1: coefficient("airspeed", "a_V1")?,
            a_v2: coefficient("airspeed", "a_V2")?,
            a_v3: coefficient("airspeed", "a_V3")?,
            a_beta1: f64::NAN,
            a_beta2: f64::NAN,
        },
        engine_pole: None,
        servo_bandwidth_hz: 1.0 / (2.0 * std::f64::consts::PI * tau),
        g: STANDARD_GRAVITY,
    })
}

/// Designs on `model` and checks each loop's margins: at least [`GAIN_MARGIN_MIN_DB`], and
/// the design's own phase-margin target (`DesignInputs::inner_phase_margin_deg`) for the
/// attitude loops, [`OUTER_PHASE_MARGIN_MIN_DEG`] for the others.
pub fn design_model_report(model: &ReducedModel) -> anyhow::Result<ModelDesignReport> {
    let inputs = DesignInputs::default();
    let design = design_from_model(model, &inputs)?;
    let checks: Vec<MarginCheck> = design
        .loops
        .iter()
        .map(|l| {
            let (gm, pm) = (l.margins.gain_margin_db, l.margins.phase_margin_deg);
            let pm_min = if inner(&l.name) {
                inputs.inner_phase_margin_deg
            } else {
                OUTER_PHASE_MARGIN_MIN_DEG
            };
            let failure = match (gm, pm) {
                (Some(g), _) if g.is_nan() || g < GAIN_MARGIN_MIN_DB => Some(format!(
                    "gain margin {} dB, at least {GAIN_MARGIN_MIN_DB} needed",
                    sig(g, 3)
                )),
                (_, Some(p)) if p.is_nan() || p < pm_min => Some(format!(
                    "phase margin {} deg, at least {pm_min} needed",
                    sig(p, 3)
                )),
                _ => None,
            };
            MarginCheck {
                name: l.name.clone(),
                gain_margin_db: gm,
                phase_margin_deg: pm,
                failure,
            }
        })
        .collect();
    let mut t = Table::new(
        format!(
            "Gains designed on the identified model (Va {} m/s, servo {} Hz{}), with the margins the model predicts",
            sig(model.va, 3),
            sig(model.servo_bandwidth_hz, 3),
            if model.engine_pole.is_none() {
                ", engine lag not identified: taken as quasi-steady"
            } else {
                ""
            }
        ),
        &["loop", "parameter", "value", "gain margin (dB)", "phase margin (deg)", "targets"],
    );
    for (l, c) in design.loops.iter().zip(&checks) {
        for (name, value, _) in &l.gains {
            t.row([
                l.name.clone(),
                name.clone(),
                sig(*value, 4),
                sig_or_dash(c.gain_margin_db, 3),
                sig_or_dash(c.phase_margin_deg, 3),
                c.failure.clone().unwrap_or_else(|| "met".into()),
            ]);
        }
    }
    Ok(ModelDesignReport {
        model: model.clone(),
        design,
        checks,
        tables: vec![t],
    })
}
