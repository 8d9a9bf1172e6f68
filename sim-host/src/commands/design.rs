//! `sim-host design`: the "computed" gain set by successive loop closure, with what the linear
//! model predicts of every loop.

use super::Format;
use crate::aircraft::Aircraft;
use crate::analysis::design::inputs::DesignInputs;
use crate::analysis::design::{describe_poles, design, Design};
use crate::report::sig;
use crate::report::table::Table;
use common::control::gains::GainSet;
use serde::Serialize;

/// Everything `design` computes.
#[derive(Serialize)]
pub struct DesignReport {
    /// The design.
    pub design: Design,
    /// The resulting gain set, as it loads into the parameter store.
    pub gain_set: GainSet,
    /// Tables printed.
    #[serde(skip)]
    pub tables: Vec<Table>,
}

fn opt(x: Option<f64>, digits: usize) -> String {
    x.map_or_else(|| "-".into(), |v| sig(v, digits))
}

/// Designs the loops and tabulates them.
pub fn design_report(aircraft: &Aircraft) -> anyhow::Result<DesignReport> {
    let d = design(aircraft, &DesignInputs::default())?;
    let c = &d.coefficients;
    let mut coeffs = Table::new(
        "Model coefficients at the level trim (Va 17 m/s, h 100 m)",
        &["coefficient", "value", "from"],
    );
    coeffs
        .row([
            "a_phi1 (1/s)".into(),
            sig(c.a_phi1, 5),
            "aero data (Appendix C)".to_string(),
        ])
        .row([
            "a_phi1 (1/s)".into(),
            sig(c.a_phi1_linear, 5),
            "linear model, -A[p,p]".into(),
        ])
        .row([
            "a_phi2".into(),
            sig(c.a_phi2, 5),
            "aero data (Appendix C)".into(),
        ])
        .row([
            "a_phi2".into(),
            sig(c.a_phi2_linear, 5),
            "linear model, B[p, da]".into(),
        ])
        .row([
            "a_beta1 (1/s)".into(),
            sig(c.a_beta1, 4),
            "aero data".into(),
        ])
        .row(["a_beta2".into(), sig(c.a_beta2, 4), "aero data".into()])
        .row([
            "a_theta1 (1/s)".into(),
            sig(c.a_theta1, 4),
            "aero data (reduced model)".into(),
        ])
        .row([
            "a_theta2".into(),
            sig(c.a_theta2, 4),
            "aero data (reduced model)".into(),
        ])
        .row([
            "a_theta3".into(),
            sig(c.a_theta3, 4),
            "aero data (reduced model)".into(),
        ])
        .row([
            "a_V1 (1/s)".into(),
            sig(c.a_v1, 4),
            "linear model, -A[u,u]".into(),
        ])
        .row([
            "a_V2 (m/s^2)".into(),
            sig(c.a_v2, 4),
            "linear model, steady throttle effect".into(),
        ])
        .row([
            "engine pole (1/s)".into(),
            sig(c.engine_pole, 4),
            "linear model".into(),
        ]);

    let a = &d.appendix_c;
    let mut appc = Table::new(
        "Appendix C's roll design as printed, with the servo (8 Hz) and the 50 ms software delay",
        &["wn_phi (rad/s)", "kp", "kd", "phase margin (deg)"],
    );
    appc.row([
        sig(a.wn_phi, 4),
        sig(a.roll_kp, 5),
        sig(a.roll_kd, 4),
        opt(a.phase_margin_deg, 3),
    ]);

    let mut gains = Table::new(
        "Computed gains beside the thesis's designed set",
        &["loop", "parameter", "computed", "thesis designed"],
    );
    let mut pred = Table::new(
        "What the linear model predicts (reduced models, inner loops as designed; margins with servo, delay and feedback filter)",
        &[
            "loop",
            "wn (rad/s)",
            "closed-loop poles (zeta, wn)",
            "rise 10-90 % (s)",
            "overshoot (%)",
            "settling 2 % (s)",
            "gain margin (dB)",
            "phase margin (deg)",
        ],
    );
    for l in &d.loops {
        for (name, ours, thesis) in &l.gains {
            gains.row([l.name.clone(), name.clone(), sig(*ours, 4), sig(*thesis, 4)]);
        }
        let poles = l
            .poles
            .iter()
            .zip(describe_poles(&l.poles))
            .filter(|(p, _)| p[1] >= 0.0)
            .map(|(p, (z, w))| {
                if p[1] > 0.0 {
                    format!(
                        "{}±{}i ({}, {})",
                        sig(p[0], 3),
                        sig(p[1], 3),
                        sig(z, 2),
                        sig(w, 3)
                    )
                } else {
                    sig(p[0], 3)
                }
            })
            .collect::<Vec<_>>()
            .join(", ");
        pred.row([
            l.name.clone(),
            sig(l.wn_radps, 3),
            poles,
            opt(l.rise_time_s, 3),
            sig(l.overshoot_pct, 3),
            opt(l.settling_time_s, 3),
            opt(l.margins.gain_margin_db, 3),
            opt(l.margins.phase_margin_deg, 3),
        ]);
    }
    Ok(DesignReport {
        gain_set: d.gains,
        design: d,
        tables: vec![coeffs, appc, gains, pred],
    })
}

/// The design as a Markdown document.
pub fn design_markdown(aircraft: &Aircraft) -> anyhow::Result<String> {
    let r = design_report(aircraft)?;
    Ok(format!(
        "{}\n{}\n",
        include_str!("design_intro.md"),
        super::render(&r.tables, Format::Markdown)
    ))
}
