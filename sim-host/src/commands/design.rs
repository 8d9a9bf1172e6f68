//! `sim-host design`: the "computed" gain set by successive loop closure, with what the linear
//! model predicts of every loop.

use super::Format;
use crate::aircraft::Aircraft;
use crate::analysis::design::inputs::DesignInputs;
use crate::analysis::design::{decimal, describe_poles, design_at, Design};
use crate::analysis::references::apply_to;
use crate::analysis::sampled::{scaled_at, SampledLoop, SampledLoops};
use crate::report::table::Table;
use crate::report::{sig, sig_or_dash};
use common::control::gains::GainSet;
use serde::Serialize;

/// Everything `design` computes.
#[derive(Serialize)]
pub struct DesignReport {
    /// The design.
    pub design: Design,
    /// The resulting gain set, as it loads into the parameter store.
    pub gain_set: GainSet,
    /// Every loop of the computed set, the flight defaults and the thesis's designed set on
    /// the full linear model sampled at the autopilot's rate: (set, loops).
    pub sampled: Vec<(String, Vec<SampledLoop>)>,
    /// The flight set at each airspeed of [`SCALING_AIRSPEEDS_MPS`], without and with the
    /// airspeed scaling of its surface loops: (airspeed m/s, unscaled, scaled).
    pub scaling: Vec<(f64, Vec<SampledLoop>, Vec<SampledLoop>)>,
    /// The total energy control's two loops (`LON_LAW` = 1) with the flight defaults, on the
    /// same model.
    pub tecs: Vec<SampledLoop>,
    /// Tables printed.
    #[serde(skip)]
    pub tables: Vec<Table>,
}

/// Designs the loops at the level trim at `va_mps` and tabulates them. The airspeed-scaling
/// table judges the firmware's flight set between the Ultra Stick's mission limits, so it
/// comes with the Ultra Stick at 17 m/s only.
pub fn design_report_at(aircraft: &Aircraft, va_mps: f64) -> anyhow::Result<DesignReport> {
    let d = design_at(aircraft, &DesignInputs::default(), va_mps)?;
    let c = &d.coefficients;
    let mut coeffs = Table::new(
        format!("Model coefficients at the level trim (Va {va_mps} m/s, h 100 m)"),
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
        sig_or_dash(a.phase_margin_deg, 3),
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
            sig_or_dash(l.rise_time_s, 3),
            sig(l.overshoot_pct, 3),
            sig_or_dash(l.settling_time_s, 3),
            sig_or_dash(l.margins.gain_margin_db, 3),
            sig_or_dash(l.margins.phase_margin_deg, 3),
        ]);
    }
    let inputs = &d.inputs;
    let model = SampledLoops::at_level_airspeed(
        aircraft,
        va_mps,
        decimal(inputs.sample_time_s),
        inputs.delay_periods(),
    )?;
    let sampled: Vec<(String, Vec<SampledLoop>)> = [
        ("computed", d.gains),
        ("flight", common::control::gains::FLIGHT),
        ("designed", common::control::gains::DESIGNED),
    ]
    .into_iter()
    .map(|(name, g)| (name.to_string(), model.judge_all(&g)))
    .collect();
    let mut full = Table::new(
        "On the full linear model at 50 Hz (every state of both axes, 8 Hz servos held over each period, measurements two periods late, every other loop closed): each loop broken at its controller's output, and a small step of its command",
        &[&["loop", "set"][..], &FIGURES].concat(),
    );
    for (i, l) in d.loops.iter().enumerate() {
        for (set, loops) in &sampled {
            let Some(s) = loops.get(i) else { continue };
            debug_assert_eq!(s.name, l.name);
            full.row([l.name.clone(), set.clone()].into_iter().chain(figures(s)));
        }
    }
    let (scaling, scaling_table) = if apply_to(aircraft, va_mps) {
        scaling_report(aircraft, inputs)?
    } else {
        (
            Vec::new(),
            Table::new(
                "Airspeed scaling: judged for the Ultra Stick 25e at 17 m/s only",
                &["loop"],
            ),
        )
    };
    let tecs = model.judge_tecs(&common::control::gains::FLIGHT);
    let mut energy = Table::new(
        "The total energy control (LON_LAW = 1, its designed gains, the flight defaults' pitch loop) on the same model: the energy rate broken at the throttle with a small height step, the balance broken at the pitch command with a small airspeed step",
        &[&["loop"][..], &FIGURES].concat(),
    );
    for s in &tecs {
        energy.row(std::iter::once(s.name.to_string()).chain(figures(s)));
    }
    Ok(DesignReport {
        gain_set: d.gains,
        design: d,
        sampled,
        scaling,
        tecs,
        tables: vec![coeffs, appc, gains, pred, full, scaling_table, energy],
    })
}

/// Airspeeds the flight set's scaling is judged at, m/s: the lowest and highest a mission may
/// set (`NAV_ASPD_MIN`, `NAV_ASPD_MAX`) and the trim. Level flight ends at 23.6 m/s, where the
/// throttle reaches its stop.
pub const SCALING_AIRSPEEDS_MPS: [f64; 3] = [13.0, 17.0, 23.0];

type ScalingRows = Vec<(f64, Vec<SampledLoop>, Vec<SampledLoop>)>;

/// The flight set on the full sampled model at the trims of [`SCALING_AIRSPEEDS_MPS`], without
/// and with airspeed scaling.
fn scaling_report(
    aircraft: &Aircraft,
    inputs: &DesignInputs,
) -> anyhow::Result<(ScalingRows, Table)> {
    let flight = common::control::gains::FLIGHT;
    let unscaled = GainSet {
        scaling_airspeed: 0.0,
        ..flight
    };
    let mut rows = Vec::new();
    for va in SCALING_AIRSPEEDS_MPS {
        let model = SampledLoops::at_level_airspeed(
            aircraft,
            va,
            decimal(inputs.sample_time_s),
            inputs.delay_periods(),
        )?;
        rows.push((
            va,
            model.judge_all(&unscaled),
            model.judge_all(&scaled_at(&flight, va)),
        ));
    }
    let mut t = Table::new(
        "Airspeed scaling: the flight set on the full sampled model at the level trims of 13, 17 and 23 m/s, its surface loops (roll, pitch, sideslip, yaw damper) and altitude loop unscaled and scaled by 17 / Va (ASPD_SCL_REF)",
        &[
            "loop",
            "airspeed (m/s)",
            "phase margin unscaled (deg)",
            "phase margin scaled (deg)",
            "gain margin unscaled (dB)",
            "gain margin scaled (dB)",
            "overshoot unscaled (%)",
            "overshoot scaled (%)",
        ],
    );
    let over = |l: &SampledLoop| {
        if l.unstable {
            "unstable".to_string()
        } else {
            sig(l.overshoot_pct, 3)
        }
    };
    for i in 0..rows.first().map_or(0, |r| r.1.len()) {
        for (va, plain, scaled) in &rows {
            let (Some(p), Some(s)) = (plain.get(i), scaled.get(i)) else {
                continue;
            };
            t.row([
                p.name.to_string(),
                sig(*va, 3),
                sig_or_dash(p.margins.phase_margin_deg, 3),
                sig_or_dash(s.margins.phase_margin_deg, 3),
                sig_or_dash(p.margins.gain_margin_db, 3),
                sig_or_dash(s.margins.gain_margin_db, 3),
                over(p),
                over(s),
            ]);
        }
    }
    Ok((rows, t))
}

/// The design at `va_mps` as a Markdown document.
pub fn design_markdown_at(aircraft: &Aircraft, va_mps: f64) -> anyhow::Result<String> {
    let r = design_report_at(aircraft, va_mps)?;
    Ok(format!(
        "{}\n{}\n",
        include_str!("design_intro.md"),
        super::render(&r.tables, Format::Markdown)
    ))
}

/// Headers of [`figures`].
const FIGURES: [&str; 6] = [
    "phase margin (deg)",
    "gain margin (dB)",
    "crossover (rad/s)",
    "rise 10-90 % (s)",
    "overshoot (%)",
    "settling 2 % (s)",
];

/// A loop's figures on the sampled model, as the tables print them: margins, crossover, step.
fn figures(s: &SampledLoop) -> [String; 6] {
    [
        sig_or_dash(s.margins.phase_margin_deg, 3),
        sig_or_dash(s.margins.gain_margin_db, 3),
        sig_or_dash(s.margins.gain_crossover_radps, 3),
        sig_or_dash(s.rise_time_s, 3),
        if s.unstable {
            "unstable".into()
        } else {
            sig(s.overshoot_pct, 3)
        },
        sig_or_dash(s.settling_time_s, 3),
    ]
}
