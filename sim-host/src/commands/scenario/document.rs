//! The results document (`docs/RESULTS.md`): set-up, scenarios, design requirements per gain
//! set, the computed set's predictions against the flights, the claims and every metric.

use super::claims::{claims, f, findings, first_seg, CLIMB_WINDOW_S};
use super::gains::COMPUTED;
use super::run::ScenarioReport;
use crate::aircraft::Aircraft;
use crate::analysis::design::inputs::DesignInputs;
use crate::analysis::design::{decimal, design_at};
use crate::analysis::sampled::plant::out;
use crate::analysis::sampled::{Arrangement, LatLaw, LoopCase, SampledLoop, SampledLoops, CASES};
use crate::report::sig;
use crate::report::template::block;
use crate::scenario::SCENARIOS;

/// The document's prose.
const PROSE: &str = include_str!("document.md");

/// "yes" or a bold "no".
fn yes(b: bool) -> &'static str {
    if b {
        "yes"
    } else {
        "**no**"
    }
}

/// Design requirements for one set, as `(requirement, figure, met)` rows.
fn requirement_rows(report: &ScenarioReport, set: &str) -> Vec<(String, String, bool)> {
    let mut rows = Vec::new();
    let m = |sc: &str| report.get(sc, false).and_then(|r| r.metrics_of(set));
    if let Some(r) = m("roll_doublet") {
        let rise = r.rise_time_s;
        rows.push((
            "roll rise 10-90 % < 1 s (roll_doublet, slowest step)".into(),
            f(rise, 3),
            rise.is_some_and(|x| x < 1.0),
        ));
    }
    if let Some(r) = m("pitch_doublet") {
        let rise = r.rise_time_s;
        rows.push((
            "pitch rise 10-90 % < 1 s (pitch_doublet, slowest step)".into(),
            f(rise, 3),
            rise.is_some_and(|x| x < 1.0),
        ));
        if let Some(g) = first_seg(r) {
            rows.push((
                "pitch overshoot <= 7 %, first step from trim (pitch_doublet)".into(),
                format!("{} %", sig(g.metrics.overshoot_pct, 3)),
                g.metrics.overshoot_pct <= 7.0,
            ));
        }
        rows.push((
            "pitch overshoot <= 7 %, every step of the doublet".into(),
            format!("{} %", sig(r.overshoot_pct, 3)),
            r.overshoot_pct <= 7.0,
        ));
    }
    for sc in ["heading_doublet", "heading_rectangle"] {
        if let Some(r) = m(sc) {
            rows.push((
                format!("heading overshoot < 5 % ({sc}, every step)"),
                format!("{} %", sig(r.overshoot_pct, 3)),
                r.overshoot_pct < 5.0,
            ));
        }
    }
    for sc in ["altitude_step", "altitude_doublet"] {
        if let Some(r) = m(sc) {
            rows.push((
                format!("altitude overshoot < 5 % ({sc}, every step)"),
                format!("{} %", sig(r.overshoot_pct, 3)),
                r.overshoot_pct < 5.0,
            ));
        }
    }
    if let Some(r) = m("climb") {
        let t = r.time_to_2pct_s;
        rows.push((
            format!(
                "climb 100 m to within 2 m in about 20 s ({}..{} s)",
                CLIMB_WINDOW_S[0], CLIMB_WINDOW_S[1]
            ),
            f(t, 3),
            t.is_some_and(|x| (CLIMB_WINDOW_S[0]..=CLIMB_WINDOW_S[1]).contains(&x)),
        ));
        rows.push((
            "climb: pitch command within +-20 deg; pitch attitude peak".into(),
            format!(
                "command {} deg, attitude {} deg",
                sig(r.peak_pitch_cmd_deg, 3),
                sig(r.peak_pitch_deg, 3)
            ),
            r.peak_pitch_cmd_deg <= 20.0 + 1e-3,
        ));
        rows.push((
            "climb overshoot < 5 %".into(),
            format!("{} %", sig(r.overshoot_pct, 3)),
            r.overshoot_pct < 5.0,
        ));
    }
    rows
}

/// The results document (Markdown): how it was produced, the metrics of every scenario for
/// every gain set, and the verdicts on the thesis's claims and the design requirements.
pub fn results_markdown(report: &ScenarioReport, command: &str, aircraft: &Aircraft) -> String {
    let mut s = String::new();
    s.push_str("# Closed-loop results: the tests of thesis chapter 4 on the nonlinear plant\n\n");
    s.push_str(&block(PROSE, "intro", &[("command", command)]));
    s.push_str("\n\n");
    // Kept wrapped as written (not a template block, whose paragraphs become single lines).
    s.push_str(
        &include_str!("setup.md").replace("{airspeed}", &report.trim_airspeed_mps.to_string()),
    );
    s.push_str("\n## Scenarios\n\n| scenario | loop | command | length (s) |\n|---|---|---|---|\n");
    for sc in SCENARIOS {
        let steps: Vec<String> = sc
            .steps
            .iter()
            .map(|(t, v)| format!("{v:+} {} at {t} s", sc.axis.unit()))
            .collect();
        s.push_str(&format!(
            "| `{}` | {}{} | {} | {} |\n",
            sc.name,
            sc.axis.quantity(),
            if sc.slip_hold {
                ", rudder holds zero sideslip"
            } else {
                ""
            },
            steps.join("; "),
            sc.duration_s
        ));
    }
    let sets: Vec<String> = report
        .results
        .first()
        .map(|r| r.metrics.iter().map(|m| m.gains.clone()).collect())
        .unwrap_or_default();
    s.push_str("\n## Design requirements (thesis section 3.3), per gain set\n\n");
    s.push_str(&block(PROSE, "requirements", &[]));
    s.push_str("\n\n");
    let mut header = vec!["requirement".to_string()];
    header.extend(sets.iter().cloned());
    let mut rows: Vec<Vec<String>> = Vec::new();
    for (i, set) in sets.iter().enumerate() {
        for (k, (req, fig, ok)) in requirement_rows(report, set).into_iter().enumerate() {
            if i == 0 {
                rows.push(vec![req]);
            }
            if let Some(r) = rows.get_mut(k) {
                r.push(format!("{fig} ({})", yes(ok)));
            }
        }
    }
    s.push_str(&format!("| {} |\n", header.join(" | ")));
    s.push_str(&format!("|{}\n", "---|".repeat(header.len())));
    for r in rows {
        s.push_str(&format!("| {} |\n", r.join(" | ")));
    }
    let all_met: Vec<String> = sets
        .iter()
        .filter(|set| {
            requirement_rows(report, set)
                .iter()
                .filter(|(req, _, _)| !req.contains("every step of the doublet"))
                .all(|(_, _, ok)| *ok)
        })
        .map(|x| format!("`{x}`"))
        .collect();
    let all_met = if all_met.is_empty() {
        "none".to_string()
    } else {
        all_met.join(", ")
    };
    s.push('\n');
    s.push_str(&block(PROSE, "all_met", &[("sets", &all_met)]));
    s.push('\n');
    s.push_str(&prediction_vs_flight(report, aircraft));
    s.push_str("\n## The thesis's claims\n\n");
    s.push_str(&claims(report));
    s.push_str(&findings(report));
    s.push_str("\n## Metrics of every scenario\n\n");
    s.push_str(&block(PROSE, "metrics", &[]));
    s.push_str("\n\n");
    for t in &report.tables {
        s.push_str(&t.render_markdown());
        s.push('\n');
    }
    s
}

/// The computed set's linear predictions beside what the nonlinear plant flies, on the small
/// steps: the reduced models of the design (`sim-host design`) and the full linear model
/// sampled at the autopilot's rate ([`SampledLoops`]).
fn prediction_vs_flight(report: &ScenarioReport, aircraft: &Aircraft) -> String {
    let va = report.trim_airspeed_mps;
    let Ok(d) = design_at(aircraft, &DesignInputs::default(), va) else {
        return String::new();
    };
    let inputs = &d.inputs;
    let Ok(model) = SampledLoops::at_level_airspeed(
        aircraft,
        va,
        decimal(inputs.sample_time_s),
        inputs.delay_periods(),
    ) else {
        return String::new();
    };
    // The tests feed the course loop the heading (the thesis's still-air assumption), so its
    // prediction does too.
    let full: Vec<SampledLoop> = CASES
        .iter()
        .map(|c| {
            if c.arrangement.lat != LatLaw::Course {
                return model.judge(&d.gains, c);
            }
            let heading = LoopCase {
                arrangement: Arrangement {
                    lat: LatLaw::Heading,
                    ..c.arrangement
                },
                output: out::HEADING,
                ..*c
            };
            model.judge(&d.gains, &heading)
        })
        .collect();
    let pairs = [
        ("roll attitude", "roll_step_small"),
        ("course", "heading_step_small"),
        ("sideslip", "sideslip_step_small"),
        ("pitch attitude", "pitch_step_small"),
        ("altitude", "altitude_step_small"),
        ("airspeed (throttle)", "airspeed_step_small"),
    ];
    let mut s =
        String::from("\n## The computed set: linear prediction against the nonlinear plant\n\n");
    s.push_str(&block(PROSE, "prediction", &[]));
    s.push_str(
        "\n\n| loop | test | rise, reduced model (s) | rise, full model (s) | rise flown (s) | \
         full model against flown | overshoot, reduced model (%) | overshoot, full model (%) | \
         overshoot flown (%) |\n|---|---|---|---|---|---|---|---|---|\n",
    );
    let opt = |v: Option<f64>| v.map_or_else(|| "-".into(), |v| sig(v, 3));
    for (name, sc) in pairs {
        let (Some(l), Some(f)) = (
            d.loops.iter().find(|l| l.name.starts_with(name)),
            full.iter().find(|l| l.name.starts_with(name)),
        ) else {
            continue;
        };
        let Some(m) = report.get(sc, false).and_then(|r| r.metrics_of(COMPUTED)) else {
            continue;
        };
        let Some(first) = m.segments.first().map(|g| g.metrics) else {
            continue;
        };
        let diff = match (f.rise_time_s, first.rise_time_s) {
            (Some(p), Some(r)) => format!("{:+.0} %", (r - p) / p * 100.0),
            _ => "-".into(),
        };
        s.push_str(&format!(
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} |\n",
            l.name,
            sc,
            opt(l.rise_time_s),
            opt(f.rise_time_s),
            opt(first.rise_time_s),
            diff,
            sig(l.overshoot_pct, 3),
            sig(f.overshoot_pct, 3),
            sig(first.overshoot_pct, 3),
        ));
    }
    s.push_str(include_str!("prediction_notes.md"));
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_report_without_runs_still_states_every_claim() {
        let report = ScenarioReport {
            trim_airspeed_mps: 17.0,
            trim_pitch_deg: 3.0,
            results: Vec::new(),
            files: Vec::new(),
            tables: Vec::new(),
        };
        let aircraft = Aircraft::ultrastick25e().unwrap();
        let md = results_markdown(&report, "sim-host scenario all", &aircraft);
        assert!(
            md.contains("Generated by `sim-host scenario all` (plots"),
            "{md}"
        );
        assert_eq!(
            md.matches("Not evaluated: run with both").count(),
            7,
            "{md}"
        );
        assert!(md.contains("throttle fixed) overshoots: .\n"), "{md}");
        assert!(!md.contains('{'), "a placeholder left unfilled: {md}");
    }
}
