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
use common::tuning::design::{judge_margins, Loop, Margins};
use serde::Serialize;
use std::fmt::Write as _;
use std::path::Path;

/// The margins every loop must keep, as the vehicle judges them: the on-board design's
/// (`common::tuning::design::judge`: 6 dB of gain margin, MIL-F-9490D's; 45 deg of phase
/// margin for the attitude loops, the design's own target, and 30 deg for the outer loops,
/// whose bandwidth the design already separates).
pub use common::tuning::design::{
    GAIN_MARGIN_MIN_DB, INNER_PHASE_MARGIN_MIN_DEG, OUTER_PHASE_MARGIN_MIN_DEG,
};

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
            // Logs identified before the flight path's fit have none: no lag, as the thesis.
            a_gamma: r.coefficient("flight path", "a_gamma").unwrap_or(f64::NAN),
            // A flight without rudder doublets has no sideslip model (the hand-flown
            // Stabilized flight: its rudder is the yaw damper's): the sideslip loop keeps the
            // base set's gains.
            a_beta1: r.coefficient("sideslip", "a_beta1").unwrap_or(f64::NAN),
            a_beta2: r.coefficient("sideslip", "a_beta2").unwrap_or(f64::NAN),
        },
        engine_pole: None,
        servo_bandwidth_hz: 1.0 / (2.0 * std::f64::consts::PI * tau),
        g: STANDARD_GRAVITY,
    })
}

/// Designs on `model` and checks each loop's margins (the host's, from its dense sweep) by the
/// vehicle's own verdict: at least [`GAIN_MARGIN_MIN_DB`], and [`INNER_PHASE_MARGIN_MIN_DEG`]
/// for the attitude loops, [`OUTER_PHASE_MARGIN_MIN_DEG`] for the others.
pub fn design_model_report(model: &ReducedModel) -> anyhow::Result<ModelDesignReport> {
    let inputs = DesignInputs::default();
    let design = design_from_model(model, &inputs)?;
    let checks: Vec<MarginCheck> = design
        .loops
        .iter()
        .map(|l| {
            let (gm, pm) = (l.margins.gain_margin_db, l.margins.phase_margin_deg);
            let margins = Margins {
                gain_margin_db: gm.map(|g| g as f32),
                phase_crossover_radps: l.margins.phase_crossover_radps.map(|w| w as f32),
                phase_margin_deg: pm.map(|p| p as f32),
                gain_crossover_radps: l.margins.gain_crossover_radps.map(|w| w as f32),
            };
            // The sideslip loop, designed on the host only, is judged as an outer loop.
            let pm_min = l
                .onboard
                .map_or(OUTER_PHASE_MARGIN_MIN_DEG, Loop::phase_margin_min_deg);
            let failure = judge_margins(&margins, pm_min)
                .err()
                .map(|reason| reason.to_string());
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
