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

/// The figures a claim's text is filled with.
#[derive(Default)]
struct Figures(Vec<(String, String)>);

impl Figures {
    /// `{name}`.
    fn one(mut self, name: &str, value: impl Into<String>) -> Self {
        self.0.push((name.into(), value.into()));
        self
    }

    /// `{designed_name}` and `{minnesota_name}`: the same figure of both sets' runs.
    fn both(
        self,
        name: &str,
        (designed, minnesota): (&RunMetrics, &RunMetrics),
        figure: impl Fn(&RunMetrics) -> String,
    ) -> Self {
        self.one(&format!("designed_{name}"), figure(designed))
            .one(&format!("minnesota_{name}"), figure(minnesota))
    }
}

/// The runs a claim reads.
struct Runs<'a>(&'a ScenarioReport);

/// What the runs show of one claim: its figures, or `None` when a run it reads is missing.
type Check = fn(&Runs) -> Option<Figures>;

impl Runs<'_> {
    /// The designed set's figures and Minnesota's on scenario `sc`, with noise when `noisy`:
    /// each claim sets one against the other.
    fn both(&self, sc: &str, noisy: bool) -> Option<(RunMetrics, RunMetrics)> {
        let r = self.0.get(sc, noisy)?;
        Some((
            r.metrics_of("designed")?.clone(),
            r.metrics_of("minnesota")?.clone(),
        ))
    }
}

/// The overshoot of a run, to `digits` significant digits.
fn overshoot(digits: usize) -> impl Fn(&RunMetrics) -> String {
    move |m| sig(m.overshoot_pct, digits)
}

/// The thesis's claims (REFERENCE.md "Claims to check"), each with the numbers and a verdict.
pub(super) fn claims(report: &ScenarioReport) -> String {
    let runs = Runs(report);
    let checks: [(&str, Check); 7] = [
        ("roll", roll),
        ("heading", heading),
        ("pitch", pitch),
        ("altitude", altitude),
        ("ripple", ripple),
        ("climb", climb),
        ("noise", noise),
    ];
    checks
        .iter()
        .map(|(name, check)| claim(name, check(&runs)))
        .collect()
}

/// A claim as stated, then what the runs show, or that they do not show it.
fn claim(name: &str, figures: Option<Figures>) -> String {
    let values: Vec<(&str, &str)> = figures
        .as_ref()
        .map(|f| f.0.iter().map(|(k, v)| (k.as_str(), v.as_str())).collect())
        .unwrap_or_default();
    let text = paragraphs(CLAIMS, name, &values);
    let title = text.first().map_or("", String::as_str);
    let finding = match (&figures, text.get(1)) {
        (Some(_), Some(body)) => body.clone(),
        _ => block(CLAIMS, "not_evaluated", &[]),
    };
    format!("- **{title}** {finding}\n\n")
}

/// "Responds faster": the verdict on rise times `ra` (designed) and `rb` (Minnesota), both rise
/// times, both overshoots.
fn faster(ra: f64, rb: f64, runs: (&RunMetrics, &RunMetrics)) -> Figures {
    Figures::default()
        .one("verdict", verdict(ra < rb))
        .one("designed_rise", sig(ra, 3))
        .one("minnesota_rise", sig(rb, 3))
        .both("overshoot", runs, overshoot(3))
}

/// The designed roll loop against Minnesota's: rise, overshoot, settling (roll_doublet).
fn roll(runs: &Runs) -> Option<Figures> {
    let (a, b) = runs.both("roll_doublet", false)?;
    let (ra, rb) = (a.rise_time_s?, b.rise_time_s?);
    Some(
        faster(ra, rb, (&a, &b))
            .both("settling", (&a, &b), |m| f(m.settling_time_s, 3))
            .one("minnesota_error", sig(b.steady_state_error.abs(), 2)),
    )
}

/// The designed heading loop against Minnesota's: the doublet's first step, the rectangle's
/// turns.
fn heading(runs: &Runs) -> Option<Figures> {
    let (a, b) = runs.both("heading_doublet", false)?;
    let (ra, rb) = (
        first_seg(&a)?.metrics.rise_time_s?,
        first_seg(&b)?.metrics.rise_time_s?,
    );
    let (c, e) = runs.both("heading_rectangle", false)?;
    let rectangle_faster = c.rise_time_s? < e.rise_time_s?;
    let error = c.steady_state_error.abs().max(e.steady_state_error.abs());
    Some(
        faster(ra, rb, (&a, &b))
            .one(
                "rectangle_faster",
                if rectangle_faster {
                    "faster"
                } else {
                    "not faster"
                },
            )
            .both("rectangle_rise", (&c, &e), |m| f(m.rise_time_s, 3))
            .both("rectangle_overshoot", (&c, &e), overshoot(3))
            .one("rectangle_error", sig(error, 2)),
    )
}

/// The designed pitch loop's overshoot against Minnesota's: doublet and multi-step.
fn pitch(runs: &Runs) -> Option<Figures> {
    let (a, b) = runs.both("pitch_doublet", false)?;
    let (c, e) = runs.both("pitch_multistep", false)?;
    let less = a.overshoot_pct < b.overshoot_pct && c.overshoot_pct < e.overshoot_pct;
    Some(
        Figures::default()
            .one("verdict", verdict(less))
            .both("overshoot", (&a, &b), overshoot(3))
            .one(
                "designed_first_overshoot",
                sig(first_seg(&a)?.metrics.overshoot_pct, 2),
            )
            .one(
                "minnesota_first_overshoot",
                sig(first_seg(&b)?.metrics.overshoot_pct, 2),
            )
            .both("multistep_overshoot", (&c, &e), overshoot(3)),
    )
}

/// The designed altitude loop against Minnesota's: the 5 m step and the 10 m doublet.
fn altitude(runs: &Runs) -> Option<Figures> {
    let (a, b) = runs.both("altitude_step", false)?;
    let (c, e) = runs.both("altitude_doublet", false)?;
    let rise = a.rise_time_s.zip(b.rise_time_s).is_some_and(|(x, y)| x < y);
    let os = a.overshoot_pct < b.overshoot_pct;
    let settle = match (a.settling_time_s, b.settling_time_s) {
        (Some(x), Some(y)) => x < y,
        (Some(_), None) => true,
        _ => false,
    };
    Some(
        Figures::default()
            .one("verdict", verdict(rise && os && settle))
            .both("rise", (&a, &b), |m| f(m.rise_time_s, 3))
            .one("rise_better", better(rise))
            .both("overshoot", (&a, &b), overshoot(2))
            .one("overshoot_better", better(os))
            .both("settling", (&a, &b), |m| f(m.settling_time_s, 3))
            .one("settling_better", better(settle))
            .one("designed_throttle_low", sig(a.throttle_range_tail[0], 2))
            .one("designed_throttle_high", sig(a.throttle_range_tail[1], 2))
            .one("designed_error", sig(a.steady_state_error.abs(), 2))
            .both("doublet_overshoot", (&c, &e), overshoot(3)),
    )
}

/// Roll ripple with noise: the yaw damper alone, then with the designed sideslip loop engaged.
fn ripple(runs: &Runs) -> Option<Figures> {
    let (a, b) = runs.both("roll_doublet", true)?;
    let (c, e) = runs.both("roll_doublet_slip_hold", true)?;
    let verdict = if a.ripple_rms > b.ripple_rms {
        "Holds."
    } else {
        "Not reproduced with the yaw damper alone; reproduced, as an oscillation, with \
             the designed sideslip loop."
    };
    Some(
        Figures::default()
            .one("verdict", verdict)
            .both("ripple", (&a, &b), |m| sig(m.ripple_rms, 2))
            .both("activity", (&a, &b), |m| sig(m.surface_activity_dps, 3))
            .both("overshoot", (&a, &b), overshoot(3))
            .both("slip_hold_ripple", (&c, &e), |m| sig(m.ripple_rms, 2))
            .both("slip_hold_overshoot", (&c, &e), overshoot(3))
            .one("designed_slip_hold_rudder", sig(c.peak_rudder_deg, 3)),
    )
}

/// The 100 m climb: time to within 2 m, the pitch command, overshoot, the error held after.
fn climb(runs: &Runs) -> Option<Figures> {
    let (a, b) = runs.both("climb", false)?;
    let (ta, tb) = (a.time_to_2pct_s?, b.time_to_2pct_s?);
    let w = CLIMB_WINDOW_S;
    let inside = |t: f64| (w[0]..=w[1]).contains(&t);
    Some(
        Figures::default()
            .one(
                "verdict",
                if inside(ta) && inside(tb) {
                    "Time holds"
                } else {
                    "Time does not hold"
                },
            )
            .one("designed_time", f(Some(ta), 3))
            .one("minnesota_time", f(Some(tb), 3))
            .one("window_low", w[0].to_string())
            .one("window_high", w[1].to_string())
            .both("pitch_command", (&a, &b), |m| sig(m.peak_pitch_cmd_deg, 3))
            .both("overshoot", (&a, &b), overshoot(2))
            .one(
                "overshoot_verdict",
                if a.overshoot_pct < b.overshoot_pct {
                    "the designed set overshoots less"
                } else {
                    "neither overshoots, so \"less overshoot\" cannot be seen"
                },
            )
            .both("error", (&a, &b), |m| sig(m.steady_state_error, 2))
            .one("designed_throttle_low", sig(a.throttle_range_tail[0], 2))
            .one("designed_throttle_high", sig(a.throttle_range_tail[1], 2)),
    )
}

/// Noise against none: the largest change of overshoot over the runs that fly stably.
fn noise(runs: &Runs) -> Option<Figures> {
    let mut worst: (f64, String) = (0.0, String::new());
    let mut compared = 0usize;
    for r in runs.0.results.iter().filter(|r| r.noise_sigma == 0.0) {
        let Some(n) = runs.0.get(r.scenario.name, true) else {
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
        Figures::default()
            .one("verdict", verdict(worst.0 < 2.0))
            .one("runs", compared.to_string())
            .one("worst_change", sig(worst.0, 2))
            .one("worst_run", worst.1)
    })
}

/// Where sets fail on this plant, with the numbers.
pub(super) fn findings(report: &ScenarioReport) -> String {
    let get = |sc: &str, set: &str| report.get(sc, false).and_then(|r| r.metrics_of(set));
    let mut s = block(FINDINGS, "heading", &[]) + "\n\n";
    let mut finding = |name: &str, values: &[(&str, &str)]| {
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
                ("rudder_peak", &sig(a.peak_rudder_deg, 3)),
                ("ripple", &sig(a.ripple_rms, 2)),
                ("overshoot", &sig(a.overshoot_pct, 3)),
                ("roll_overshoot", &sig(b.overshoot_pct, 3)),
            ],
        );
    }
    if let Some(a) = get("sideslip_doublet", "minnesota") {
        finding(
            "minnesota_slip",
            &[("error", &sig(a.steady_state_error.abs(), 2))],
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
                ("trim_pitch", &sig(report.trim_pitch_deg, 3)),
                ("offsets", &offsets.join("; ")),
            ],
        );
    }
    if let Some(a) = get("altitude_step", "designed") {
        finding(
            "throttle_unstable",
            &[
                ("throttle_low", &sig(a.throttle_range_tail[0], 2)),
                ("throttle_high", &sig(a.throttle_range_tail[1], 2)),
                ("ripple", &sig(a.ripple_rms, 2)),
                ("error", &sig(a.steady_state_error, 2)),
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
        finding("climb_pitch", &[("pitch_ranges", &swings.join(", "))]);
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
                &designed.map_or_else(|| "-".into(), |m| sig(m.overshoot_pct, 3)),
            ),
            (
                "pitch_command",
                &designed.map_or_else(|| "-".into(), |m| sig(m.peak_pitch_cmd_deg, 3)),
            ),
            ("doublet_overshoots", &worst("altitude_doublet")),
        ],
    );
    finding(
        "pitch_overshoot",
        &[("overshoots", &worst("pitch_doublet"))],
    );
    s.push('\n');
    s
}
