//! The thesis's claims checked against the runs, and where its numbers do not hold on this
//! plant. The prose is in `claims.md` and `findings.md`; this module supplies the figures.

use super::run::ScenarioReport;
use crate::report::sig;
use crate::report::template::{block, paragraphs};
use crate::scenario::metrics::{RunMetrics, Segment};
use common::control::gains::GainSet;

/// The claims and what the runs show of each.
const CLAIMS: &str = include_str!("claims.md");
/// The findings, each given when the runs it reads were flown.
const FINDINGS: &str = include_str!("findings.md");

/// The first step of a run's command, the one from trim.
pub(super) fn first_seg(r: &RunMetrics) -> Option<&Segment> {
    r.segments.first()
}

/// A time in seconds, or "never".
pub(super) fn f(x: Option<f64>, digits: usize) -> String {
    x.map_or_else(|| "never".into(), |v| format!("{} s", sig(v, digits)))
}

/// Lower and upper bound (s) taken as "about 20 s" for the 100 m climb: 15 s is below what the
/// pitch limit allows (100 m at 17 m/s and 20 deg takes 17.2 s), 25 s is 25 % over the thesis.
pub const CLIMB_WINDOW_S: [f64; 2] = [15.0, 25.0];

/// A claim's verdict.
fn verdict(holds: bool) -> &'static str {
    if holds {
        "Holds"
    } else {
        "Does not hold"
    }
}

/// "better" or "not better".
fn better(b: bool) -> &'static str {
    if b {
        "better"
    } else {
        "not better"
    }
}

/// The thesis's claims (REFERENCE.md "Claims to check"), each with the numbers and a verdict.
pub(super) fn claims(report: &ScenarioReport) -> String {
    // Each claim sets the designed gains against Minnesota's on one scenario.
    let both = |sc: &str, noisy: bool| {
        let r = report.get(sc, noisy)?;
        Some((
            r.metrics_of("designed")?.clone(),
            r.metrics_of("minnesota")?.clone(),
        ))
    };
    let mut s = String::new();
    // The claim as stated, then what the runs show, or that they do not show it.
    let mut claim = |name: &str, values: Option<Vec<(&str, String)>>| {
        let text = paragraphs(CLAIMS, name, values.as_deref().unwrap_or_default());
        let title = text.first().map_or("", String::as_str);
        let finding = match (&values, text.get(1)) {
            (Some(_), Some(body)) => body.clone(),
            _ => block(CLAIMS, "not_evaluated", &[]),
        };
        s.push_str(&format!("- **{title}** {finding}\n\n"));
    };
    claim(
        "roll",
        (|| {
            let (a, b) = both("roll_doublet", false)?;
            let (ra, rb) = (a.rise_time_s?, b.rise_time_s?);
            Some(vec![
                ("verdict", verdict(ra < rb).into()),
                ("designed_rise", sig(ra, 3)),
                ("minnesota_rise", sig(rb, 3)),
                ("designed_overshoot", sig(a.overshoot_pct, 3)),
                ("minnesota_overshoot", sig(b.overshoot_pct, 3)),
                ("designed_settling", f(a.settling_time_s, 3)),
                ("minnesota_settling", f(b.settling_time_s, 3)),
                ("minnesota_error", sig(b.steady_state_error.abs(), 2)),
            ])
        })(),
    );
    claim(
        "heading",
        (|| {
            let (a, b) = both("heading_doublet", false)?;
            let (ra, rb) = (
                first_seg(&a)?.metrics.rise_time_s?,
                first_seg(&b)?.metrics.rise_time_s?,
            );
            let (c, e) = both("heading_rectangle", false)?;
            let faster = c.rise_time_s? < e.rise_time_s?;
            Some(vec![
                ("verdict", verdict(ra < rb).into()),
                ("designed_rise", sig(ra, 3)),
                ("minnesota_rise", sig(rb, 3)),
                ("designed_overshoot", sig(a.overshoot_pct, 3)),
                ("minnesota_overshoot", sig(b.overshoot_pct, 3)),
                (
                    "rectangle_faster",
                    if faster { "faster" } else { "not faster" }.into(),
                ),
                ("designed_rectangle_rise", f(c.rise_time_s, 3)),
                ("minnesota_rectangle_rise", f(e.rise_time_s, 3)),
                ("designed_rectangle_overshoot", sig(c.overshoot_pct, 3)),
                ("minnesota_rectangle_overshoot", sig(e.overshoot_pct, 3)),
                (
                    "rectangle_error",
                    sig(
                        c.steady_state_error.abs().max(e.steady_state_error.abs()),
                        2,
                    ),
                ),
            ])
        })(),
    );
    claim(
        "pitch",
        (|| {
            let (a, b) = both("pitch_doublet", false)?;
            let (c, e) = both("pitch_multistep", false)?;
            Some(vec![
                (
                    "verdict",
                    verdict(a.overshoot_pct < b.overshoot_pct && c.overshoot_pct < e.overshoot_pct)
                        .into(),
                ),
                ("designed_overshoot", sig(a.overshoot_pct, 3)),
                ("minnesota_overshoot", sig(b.overshoot_pct, 3)),
                (
                    "designed_first_overshoot",
                    sig(first_seg(&a)?.metrics.overshoot_pct, 2),
                ),
                (
                    "minnesota_first_overshoot",
                    sig(first_seg(&b)?.metrics.overshoot_pct, 2),
                ),
                ("designed_multistep_overshoot", sig(c.overshoot_pct, 3)),
                ("minnesota_multistep_overshoot", sig(e.overshoot_pct, 3)),
            ])
        })(),
    );
    claim(
        "altitude",
        (|| {
            let (a, b) = both("altitude_step", false)?;
            let (c, e) = both("altitude_doublet", false)?;
            let rise = a.rise_time_s.zip(b.rise_time_s).is_some_and(|(x, y)| x < y);
            let os = a.overshoot_pct < b.overshoot_pct;
            let settle = match (a.settling_time_s, b.settling_time_s) {
                (Some(x), Some(y)) => x < y,
                (Some(_), None) => true,
                _ => false,
            };
            Some(vec![
                ("verdict", verdict(rise && os && settle).into()),
                ("designed_rise", f(a.rise_time_s, 3)),
                ("minnesota_rise", f(b.rise_time_s, 3)),
                ("rise_better", better(rise).into()),
                ("designed_overshoot", sig(a.overshoot_pct, 2)),
                ("minnesota_overshoot", sig(b.overshoot_pct, 2)),
                ("overshoot_better", better(os).into()),
                ("designed_settling", f(a.settling_time_s, 3)),
                ("minnesota_settling", f(b.settling_time_s, 3)),
                ("settling_better", better(settle).into()),
                ("designed_throttle_low", sig(a.throttle_range_tail[0], 2)),
                ("designed_throttle_high", sig(a.throttle_range_tail[1], 2)),
                ("designed_error", sig(a.steady_state_error.abs(), 2)),
                ("designed_doublet_overshoot", sig(c.overshoot_pct, 3)),
                ("minnesota_doublet_overshoot", sig(e.overshoot_pct, 3)),
            ])
        })(),
    );
    claim(
        "ripple",
        (|| {
            let (a, b) = both("roll_doublet", true)?;
            let (c, e) = both("roll_doublet_slip_hold", true)?;
            let held = a.ripple_rms > b.ripple_rms;
            Some(vec![
                (
                    "verdict",
                    if held {
                        "Holds."
                    } else {
                        "Not reproduced with the yaw damper alone; reproduced, as an \
                         oscillation, with the designed sideslip loop."
                    }
                    .into(),
                ),
                ("designed_ripple", sig(a.ripple_rms, 2)),
                ("minnesota_ripple", sig(b.ripple_rms, 2)),
                ("designed_activity", sig(a.surface_activity_dps, 3)),
                ("minnesota_activity", sig(b.surface_activity_dps, 3)),
                ("designed_overshoot", sig(a.overshoot_pct, 3)),
                ("minnesota_overshoot", sig(b.overshoot_pct, 3)),
                ("designed_slip_hold_ripple", sig(c.ripple_rms, 2)),
                ("designed_slip_hold_overshoot", sig(c.overshoot_pct, 3)),
                ("designed_slip_hold_rudder", sig(c.peak_rudder_deg, 3)),
                ("minnesota_slip_hold_ripple", sig(e.ripple_rms, 2)),
                ("minnesota_slip_hold_overshoot", sig(e.overshoot_pct, 3)),
            ])
        })(),
    );
    claim(
        "climb",
        (|| {
            let (a, b) = both("climb", false)?;
            let (ta, tb) = (a.time_to_2pct_s?, b.time_to_2pct_s?);
            let w = CLIMB_WINDOW_S;
            let inside = |t: f64| (w[0]..=w[1]).contains(&t);
            Some(vec![
                (
                    "verdict",
                    if inside(ta) && inside(tb) {
                        "Time holds"
                    } else {
                        "Time does not hold"
                    }
                    .into(),
                ),
                ("designed_time", f(Some(ta), 3)),
                ("minnesota_time", f(Some(tb), 3)),
                ("window_low", w[0].to_string()),
                ("window_high", w[1].to_string()),
                ("designed_pitch_command", sig(a.peak_pitch_cmd_deg, 3)),
                ("minnesota_pitch_command", sig(b.peak_pitch_cmd_deg, 3)),
                ("designed_overshoot", sig(a.overshoot_pct, 2)),
                ("minnesota_overshoot", sig(b.overshoot_pct, 2)),
                (
                    "overshoot_verdict",
                    if a.overshoot_pct < b.overshoot_pct {
                        "the designed set overshoots less"
                    } else {
                        "neither overshoots, so \"less overshoot\" cannot be seen"
                    }
                    .into(),
                ),
                ("designed_error", sig(a.steady_state_error, 2)),
                ("designed_throttle_low", sig(a.throttle_range_tail[0], 2)),
                ("designed_throttle_high", sig(a.throttle_range_tail[1], 2)),
                ("minnesota_error", sig(b.steady_state_error, 2)),
            ])
        })(),
    );
    claim("noise", {
        let mut worst: (f64, String) = (0.0, String::new());
        let mut compared = 0usize;
        for r in report.results.iter().filter(|r| r.noise_sigma == 0.0) {
            let Some(n) = report.get(r.scenario.name, true) else {
                continue;
            };
            for m in &r.metrics {
                if r.scenario.slip_hold && m.gains.starts_with("designed") {
                    continue;
                }
                let Some(k) = n.metrics_of(&m.gains) else {
                    continue;
                };
                compared += 1;
                let d = (k.overshoot_pct - m.overshoot_pct).abs();
                if d > worst.0 {
                    worst = (d, format!("{} / {}", r.scenario.name, m.gains));
                }
            }
        }
        (compared > 0).then(|| {
            vec![
                ("verdict", verdict(worst.0 < 2.0).into()),
                ("runs", compared.to_string()),
                ("worst_change", sig(worst.0, 2)),
                ("worst_run", worst.1),
            ]
        })
    });
    s
}

/// Where sets fail on this plant, with the numbers.
pub(super) fn findings(report: &ScenarioReport) -> String {
    let get = |sc: &str, set: &str| report.get(sc, false).and_then(|r| r.metrics_of(set));
    let mut s = block(FINDINGS, "heading", &[]) + "\n\n";
    let mut finding = |name: &str, values: &[(&str, String)]| {
        s.push_str(&block(FINDINGS, name, values));
        s.push('\n');
    };
    if let (Some(a), Some(b)) = (
        get("sideslip_doublet", "designed"),
        get("roll_doublet_slip_hold", "designed"),
    ) {
        finding(
            "sideslip_unstable",
            &[
                ("rudder_peak", sig(a.peak_rudder_deg, 3)),
                ("ripple", sig(a.ripple_rms, 2)),
                ("overshoot", sig(a.overshoot_pct, 3)),
                ("roll_overshoot", sig(b.overshoot_pct, 3)),
            ],
        );
    }
    if let Some(a) = get("sideslip_doublet", "minnesota") {
        finding(
            "minnesota_slip",
            &[("error", sig(a.steady_state_error.abs(), 2))],
        );
    }
    let theta = report.trim_pitch_deg.to_radians();
    let offsets: Vec<String> = ["designed", "designed_appe"]
        .iter()
        .filter_map(|n| {
            let g = GainSet::named(n).ok()?;
            let m = get("altitude_step", n)?;
            let kp = f64::from(g.longitudinal.alt_kp);
            (g.longitudinal.alt_ki == 0.0 && kp > 0.0).then(|| {
                format!(
                    "`{n}` (kp {}): {} m without the feed-forward, {} m flown",
                    sig(kp, 2),
                    sig(theta / kp, 2),
                    sig(m.steady_state_error, 2)
                )
            })
        })
        .collect();
    if !offsets.is_empty() {
        finding(
            "trim_pitch",
            &[
                ("trim_pitch", sig(report.trim_pitch_deg, 3)),
                ("offsets", offsets.join("; ")),
            ],
        );
    }
    if let Some(a) = get("altitude_step", "designed") {
        finding(
            "throttle_unstable",
            &[
                ("throttle_low", sig(a.throttle_range_tail[0], 2)),
                ("throttle_high", sig(a.throttle_range_tail[1], 2)),
                ("ripple", sig(a.ripple_rms, 2)),
                ("error", sig(a.steady_state_error, 2)),
            ],
        );
    }
    let swings: Vec<String> = report
        .get("climb", false)
        .map(|r| {
            r.metrics
                .iter()
                .filter_map(|m| {
                    m.climb_regime_pitch_deg
                        .map(|[lo, hi]| format!("{} {:.1}..{:.1} deg", m.gains, lo, hi))
                })
                .collect()
        })
        .unwrap_or_default();
    if !swings.is_empty() {
        finding("climb_pitch", &[("pitch_ranges", swings.join(", "))]);
    }
    let worst = |sc: &str| {
        report
            .get(sc, false)
            .map(|r| {
                r.metrics
                    .iter()
                    .filter(|m| !(r.scenario.slip_hold && m.gains.starts_with("designed")))
                    .map(|m| format!("{} {} %", m.gains, sig(m.overshoot_pct, 3)))
                    .collect::<Vec<_>>()
                    .join(", ")
            })
            .unwrap_or_default()
    };
    let designed = get("altitude_step", "designed");
    finding(
        "altitude_gain",
        &[
            (
                "overshoot",
                designed.map_or_else(|| "-".into(), |m| sig(m.overshoot_pct, 3)),
            ),
            (
                "pitch_command",
                designed.map_or_else(|| "-".into(), |m| sig(m.peak_pitch_cmd_deg, 3)),
            ),
            ("doublet_overshoots", worst("altitude_doublet")),
        ],
    );
    finding("pitch_overshoot", &[("overshoots", worst("pitch_doublet"))]);
    s.push('\n');
    s
}
