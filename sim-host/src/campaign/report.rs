//! The campaign report, made from the flight records alone (so a merged campaign's report is
//! the unsharded one's): the pass rate and its interval, every criterion's failures, each
//! figure's distribution, which dispersions matter, the failing and the ten worst flights.

use super::record::{Figures, FlightRecord};
use super::run::CampaignMeta;
use super::stats::{pct, quantile, spearman, wilson, Z95};
use super::verdict::Criterion;
use crate::report::{sig, sig_or_dash};
use serde::{Deserialize, Serialize};
use std::fmt::Write as _;

/// A figure the report summarises: name in the records, label with its unit, accessor.
pub type FigureDef = (&'static str, &'static str, fn(&Figures) -> Option<f64>);

/// The figures of a flight that the report summarises and plots.
pub const FIGURES: [FigureDef; 20] = [
    ("touchdown_m", "touchdown from the point (m)", |f| {
        f.touchdown_m
    }),
    (
        "touchdown_along_m",
        "touchdown along, past the point + (m)",
        |f| f.touchdown_along_m,
    ),
    ("touchdown_cross_m", "touchdown across, right + (m)", |f| {
        f.touchdown_cross_m
    }),
    ("sink_mps", "sink rate at touchdown (m/s)", |f| f.sink_mps),
    (
        "touchdown_ground_speed_mps",
        "ground speed at touchdown (m/s)",
        |f| f.touchdown_ground_speed_mps,
    ),
    ("max_bank_deg", "largest bank (deg)", |f| f.max_bank_deg),
    ("max_pitch_deg", "largest pitch (deg)", |f| f.max_pitch_deg),
    ("min_clearance_m", "smallest non-wheel clearance (m)", |f| {
        f.min_clearance_m
    }),
    ("xtrack_rms_m", "cross-track RMS, straight legs (m)", |f| {
        f.xtrack_rms_m
    }),
    ("xtrack_max_m", "cross-track max, straight legs (m)", |f| {
        f.xtrack_max_m
    }),
    ("orbit_xtrack_rms_m", "cross-track RMS, loiter (m)", |f| {
        f.orbit_xtrack_rms_m
    }),
    ("alt_rms_m", "altitude error RMS (m)", |f| f.alt_rms_m),
    ("airspeed_rms_mps", "airspeed error RMS (m/s)", |f| {
        f.airspeed_rms_mps
    }),
    ("flight_time_s", "flight time (s)", |f| f.flight_time_s),
    ("energy_wh", "motor energy (Wh)", |f| f.energy_wh),
    ("battery_mah", "charge drawn from the pack (mAh)", |f| {
        f.battery_mah
    }),
    ("battery_min_v", "lowest pack voltage (V)", |f| {
        f.battery_min_v
    }),
    ("battery_left_pct", "charge left at the end (%)", |f| {
        f.battery_left_pct
    }),
    (
        "est_position_error_at_arm_m",
        "estimate's position error at arming (m)",
        |f| f.est_position_error_at_arm_m,
    ),
    (
        "est_heading_rms_deg",
        "estimate's heading error RMS (deg)",
        |f| f.est_heading_rms_deg,
    ),
];

/// The figures each dispersion is correlated with in the report.
pub const SENSITIVITY_FIGURES: [&str; 4] =
    ["touchdown_m", "sink_mps", "alt_rms_m", "airspeed_rms_mps"];

/// Failing flights listed in the Markdown report (all are in `report.json`).
pub const MAX_LISTED: usize = 50;

/// Quantile bins of each quantity for its pass rate.
pub const BINS: usize = 5;

/// One criterion's count.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CriterionCount {
    /// Name.
    pub name: String,
    /// What it asks.
    pub description: String,
    /// Flights that fail it.
    pub failed: u64,
}

/// One figure's distribution over the flights that have it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FigureStats {
    /// Name in the records.
    pub name: String,
    /// Label with unit.
    pub label: String,
    /// Flights with the figure.
    pub n: u64,
    /// Smallest.
    pub min: Option<f64>,
    /// 5 % quantile.
    pub p05: Option<f64>,
    /// Median.
    pub median: Option<f64>,
    /// 95 % quantile.
    pub p95: Option<f64>,
    /// Largest.
    pub max: Option<f64>,
}

/// How one dispersed quantity relates to the outcome.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Sensitivity {
    /// The quantity's name in the records' draws.
    pub quantity: String,
    /// Spearman's rank correlation with the verdict's margin (positive: larger values,
    /// safer flights).
    pub rho_margin: Option<f64>,
    /// Spearman's rank correlation with each of [`SENSITIVITY_FIGURES`].
    pub rho_figures: Vec<(String, Option<f64>)>,
    /// Pass rate in each fifth of the flights ordered by the quantity, lowest first.
    pub pass_rate_by_bin: Vec<f64>,
    /// Upper edge of each bin's values.
    pub bin_upper: Vec<f64>,
}

/// One flight in a list of the report.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FlightBrief {
    /// Index.
    pub index: u64,
    /// Criteria failed.
    pub failed: Vec<String>,
    /// Margin of the verdict.
    pub margin: f64,
    /// Touchdown distance, m.
    pub touchdown_m: Option<f64>,
    /// Sink rate, m/s.
    pub sink_mps: Option<f64>,
    /// Largest bank, deg.
    pub max_bank_deg: Option<f64>,
    /// Headwind on the landing, m/s.
    pub headwind_mps: Option<f64>,
    /// Crosswind on the landing from the right, m/s.
    pub crosswind_mps: Option<f64>,
    /// What went wrong first.
    pub cause: Option<String>,
    /// The command that flies it again.
    pub reproduce: String,
}

/// The report.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Report {
    /// The campaign.
    pub campaign: CampaignMeta,
    /// Flights.
    pub flights: u64,
    /// Flights meeting every criterion.
    pub passed: u64,
    /// Pass rates by turbulence and rangefinder.
    pub by_group: Vec<super::groups::GroupRate>,
    /// `passed / flights`.
    pub pass_rate: f64,
    /// 95 % Wilson interval of the pass rate.
    pub pass_rate_ci95: (f64, f64),
    /// Every criterion's failures.
    pub criteria: Vec<CriterionCount>,
    /// The failing flights by what went wrong first, most frequent first.
    pub causes: Vec<(String, u64)>,
    /// Flights the wind lifted off the runway after the disarm (not their landing).
    pub lifted_after_disarm: u64,
    /// Flights that went around at least once, and how many of them passed.
    pub went_around: (u64, u64),
    /// Every figure's distribution.
    pub figures: Vec<FigureStats>,
    /// Every dispersed quantity against the outcome, strongest relation first.
    pub sensitivity: Vec<Sensitivity>,
    /// The failing flights, by index.
    pub failing: Vec<FlightBrief>,
    /// The ten flights of smallest margin (failing ones first).
    pub worst: Vec<FlightBrief>,
}

fn brief(r: &FlightRecord) -> FlightBrief {
    FlightBrief {
        index: r.index,
        failed: r.verdict.failed.clone(),
        margin: r.verdict.margin,
        touchdown_m: r.figures.touchdown_m,
        sink_mps: r.figures.sink_mps,
        max_bank_deg: r.figures.max_bank_deg,
        headwind_mps: r.draws.get("derived.headwind_mps"),
        crosswind_mps: r.draws.get("derived.crosswind_from_right_mps"),
        cause: r.verdict.cause.clone(),
        reproduce: r.reproduce.clone(),
    }
}

fn figure_stats(records: &[FlightRecord], (name, label, get): &FigureDef) -> FigureStats {
    let mut v: Vec<f64> = records.iter().filter_map(|r| get(&r.figures)).collect();
    v.sort_by(f64::total_cmp);
    let q = |p: f64| (!v.is_empty()).then(|| quantile(&v, p));
    FigureStats {
        name: name.to_string(),
        label: label.to_string(),
        n: v.len() as u64,
        min: v.first().copied(),
        p05: q(0.05),
        median: q(0.5),
        p95: q(0.95),
        max: v.last().copied(),
    }
}

/// Every quantity drawn in any record, in first-seen order.
fn quantity_names(records: &[FlightRecord]) -> Vec<String> {
    let mut names: Vec<String> = Vec::new();
    for r in records {
        for (n, _) in &r.draws.0 {
            if !names.contains(n) {
                names.push(n.clone());
            }
        }
    }
    names
}

fn sensitivity(records: &[FlightRecord], quantity: &str) -> Option<Sensitivity> {
    let mut rows: Vec<(f64, &FlightRecord)> = records
        .iter()
        .filter_map(|r| r.draws.get(quantity).map(|x| (x, r)))
        .collect();
    let first = rows.first()?.0;
    if rows.iter().all(|(x, _)| *x == first) {
        // Not dispersed in this campaign.
        return None;
    }
    rows.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.index.cmp(&b.1.index)));
    let x: Vec<f64> = rows.iter().map(|r| r.0).collect();
    let margin: Vec<f64> = rows.iter().map(|r| r.1.verdict.margin).collect();
    let rho_figures = SENSITIVITY_FIGURES
        .iter()
        .map(|name| {
            let get = FIGURES.iter().find(|f| f.0 == *name).map(|f| f.2);
            let pairs: (Vec<f64>, Vec<f64>) = rows
                .iter()
                .filter_map(|(x, r)| get.and_then(|g| g(&r.figures)).map(|y| (*x, y)))
                .unzip();
            (name.to_string(), spearman(&pairs.0, &pairs.1))
        })
        .collect();
    let n = rows.len();
    let (mut pass_rate_by_bin, mut bin_upper) = (Vec::new(), Vec::new());
    for b in 0..BINS {
        let bin = &rows[b * n / BINS..(b + 1) * n / BINS];
        if bin.is_empty() {
            continue;
        }
        let pass = bin.iter().filter(|r| r.1.verdict.pass).count();
        pass_rate_by_bin.push(pass as f64 / bin.len() as f64);
        bin_upper.push(bin[bin.len() - 1].0);
    }
    Some(Sensitivity {
        quantity: quantity.to_string(),
        rho_margin: spearman(&x, &margin),
        rho_figures,
        pass_rate_by_bin,
        bin_upper,
    })
}

/// A cause without its time and numbers, and with either wing tip as one: what failing
/// flights have in common.
pub fn cause_kind(cause: &str) -> String {
    let c = cause.split(" at ").next().unwrap_or(cause);
    let c = c
        .replace("left wing tip", "wing tip")
        .replace("right wing tip", "wing tip");
    if c.starts_with("hard landing") {
        return "hard landing".into();
    }
    if c.starts_with("landing ") {
        return if c.ends_with("long") {
            "landing long"
        } else {
            "landing short"
        }
        .into();
    }
    if c.contains(" items reached") {
        return "items not reached".into();
    }
    c
}

fn causes(records: &[FlightRecord]) -> Vec<(String, u64)> {
    let mut out: Vec<(String, u64)> = Vec::new();
    for c in records.iter().filter_map(|r| r.verdict.cause.as_deref()) {
        let k = cause_kind(c);
        match out.iter_mut().find(|(n, _)| *n == k) {
            Some(e) => e.1 += 1,
            None => out.push((k, 1)),
        }
    }
    out.sort_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(&b.0)));
    out
}

impl Report {
    /// The report of `records` (any order; read in index order).
    pub fn new(campaign: CampaignMeta, records: &[FlightRecord]) -> Self {
        let mut records = records.to_vec();
        records.sort_by_key(|r| r.index);
        let flights = records.len() as u64;
        let passed = records.iter().filter(|r| r.verdict.pass).count() as u64;
        let criteria = Criterion::ALL
            .iter()
            .map(|c| CriterionCount {
                name: c.name().into(),
                description: c.describe(),
                failed: records
                    .iter()
                    .filter(|r| r.verdict.failed.iter().any(|f| f == c.name()))
                    .count() as u64,
            })
            .collect();
        let mut sens: Vec<Sensitivity> = quantity_names(&records)
            .iter()
            .filter_map(|q| sensitivity(&records, q))
            .collect();
        let strength = |s: &Sensitivity| s.rho_margin.map_or(-1.0, f64::abs);
        sens.sort_by(|a, b| {
            strength(b)
                .total_cmp(&strength(a))
                .then(a.quantity.cmp(&b.quantity))
        });
        let mut order: Vec<&FlightRecord> = records.iter().collect();
        order.sort_by(|a, b| {
            (a.verdict.pass, a.verdict.margin, a.index)
                .partial_cmp(&(b.verdict.pass, b.verdict.margin, b.index))
                .unwrap_or(std::cmp::Ordering::Equal)
        });
        let by_group = super::groups::rates(&campaign, &records);
        Self {
            campaign,
            flights,
            passed,
            pass_rate: if flights > 0 {
                passed as f64 / flights as f64
            } else {
                f64::NAN
            },
            pass_rate_ci95: wilson(passed, flights, Z95),
            by_group,
            criteria,
            causes: causes(&records),
            lifted_after_disarm: records
                .iter()
                .filter(|r| r.figures.lifted_after_disarm == Some(true))
                .count() as u64,
            went_around: {
                let ga: Vec<_> = records
                    .iter()
                    .filter(|r| r.figures.go_arounds.is_some_and(|n| n > 0.0))
                    .collect();
                (
                    ga.len() as u64,
                    ga.iter().filter(|r| r.verdict.pass).count() as u64,
                )
            },
            figures: FIGURES.iter().map(|d| figure_stats(&records, d)).collect(),
            sensitivity: sens,
            failing: records
                .iter()
                .filter(|r| !r.verdict.pass)
                .map(brief)
                .collect(),
            worst: order.iter().take(10).map(|r| brief(r)).collect(),
        }
    }
}

/// Where the report's images are, relative to the Markdown file.
#[derive(Clone, Debug)]
pub struct Images {
    /// Histograms of the figures.
    pub histograms: String,
    /// Touchdown scatter.
    pub touchdowns: String,
    /// The quantities that matter most against the margin.
    pub sensitivity: String,
}

fn brief_table(md: &mut String, flights: &[FlightBrief]) {
    let _ = writeln!(
        md,
        "| flight | what went wrong first | criteria failed | margin | touchdown m | sink m/s | bank deg | headwind m/s | crosswind m/s | re-fly |\n|---|---|---|---|---|---|---|---|---|---|"
    );
    for f in flights {
        let failed = if f.failed.is_empty() {
            "none".to_string()
        } else {
            f.failed.join(", ")
        };
        let _ = writeln!(
            md,
            "| {} | {} | {failed} | {} | {} | {} | {} | {} | {} | `{}` |",
            f.index,
            f.cause.as_deref().unwrap_or("-"),
            sig(f.margin, 3),
            sig_or_dash(f.touchdown_m, 3),
            sig_or_dash(f.sink_mps, 3),
            sig_or_dash(f.max_bank_deg, 3),
            sig_or_dash(f.headwind_mps, 2),
            sig_or_dash(f.crosswind_mps, 2),
            f.reproduce
        );
    }
}

/// The report as Markdown (no wall-clock figure: it must not depend on how it was run).
pub fn markdown(r: &Report, images: &Images, beside: Option<&super::groups::Beside>) -> String {
    let m = &r.campaign;
    let mut md = String::new();
    let _ = writeln!(
        md,
        "# Monte Carlo: {} dispersed flights of the {} mission\n\n\
         Produced by `{}` (add `--out DIR` for the records and the report, `--doc FILE` for \
         this document; `--shard I/N` and `sim-host campaign merge` split it across machines \
         with the same result). Each flight is the firmware's `App` in-process, lock-step, on \
         its own estimator, with the firmware's default parameters: the scripted ground \
         station uploads the mission, sets only `EKF_GPS_DELAY` (the receiver's datasheet \
         latency, not the drawn one; and `SIM_USE_TRUTH` where the campaign file's \
         `[oracle]` asks for the truth), arms once the estimator has converged on the runway and \
         starts the mission. Every flight's draws follow from the campaign seed and its index \
         alone; each record in `flights.jsonl` carries them, its figures, its verdict and the \
         command that flies it again with its log and plots.\n",
        r.flights,
        m.mission,
        m.command() + &beside.map_or(String::new(), |b| format!(" --beside {}", b.dir))
    );
    let (lo, hi) = r.pass_rate_ci95;
    let _ = writeln!(
        md,
        "## Verdict\n\n**{} of {} flights meet every criterion: {} (95 % Wilson interval {} to {}).**\n\n\
         | criterion | what it asks | flights failing it |\n|---|---|---|",
        r.passed,
        r.flights,
        pct(r.pass_rate),
        pct(lo),
        pct(hi)
    );
    for c in &r.criteria {
        // A bar inside a table cell would end it.
        let what = c.description.replace('|', "\\|");
        let _ = writeln!(md, "| `{}` | {what} | {} |", c.name, c.failed);
    }
    if !r.causes.is_empty() {
        let _ = writeln!(
            md,
            "\nWhat went wrong first in each failing flight (the earliest failure that has a \
             time, with the navigator's phase then):\n\n| first failure | flights |\n|---|---|"
        );
        for (c, n) in &r.causes {
            let _ = writeln!(md, "| {c} | {n} |");
        }
    }
    let _ = writeln!(
        md,
        "\nA flight's touchdown is the first contact of the last landing it flew armed. After \
         the disarm the aircraft is the ground crew's: the wind lifted {} of the {} aircraft \
         left on the runway for a second or more (a gust over about 11 m/s at the three-point \
         attitude), which is in each record (`lifted_after_disarm`) and not taken as its landing.",
        r.lifted_after_disarm, r.flights
    );
    let _ = writeln!(
        md,
        "\n{} flights went around (their flare floated or bounced over 20 m past the point in \
         the air, or a gust lifted it out of the flare: `docs/NAVIGATION.md`) and were judged by \
         the landing they made after it; {} of them pass.",
        r.went_around.0, r.went_around.1
    );
    md += "\n";
    md += &super::groups::markdown(&r.by_group, beside);
    let _ = writeln!(
        md,
        "## Figures\n\nOver the flights that have each figure (a flight that never touched \
         down has no touchdown figures).\n\n| figure | flights | min | 5 % | median | 95 % | max |\n|---|---|---|---|---|---|---|"
    );
    for f in &r.figures {
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} | {} | {} | {} |",
            f.label,
            f.n,
            sig_or_dash(f.min, 3),
            sig_or_dash(f.p05, 3),
            sig_or_dash(f.median, 3),
            sig_or_dash(f.p95, 3),
            sig_or_dash(f.max, 3)
        );
    }
    let _ = writeln!(
        md,
        "\n![histograms of the figures]({})\n\n## Touchdowns\n\nWhere each flight touched down, \
         in the frame of its approach (along: past the landing point positive; across: right \
         of the approach positive); the circle is the {} m criterion.\n\n![touchdown scatter]({})\n",
        images.histograms,
        super::verdict::TOUCHDOWN_M,
        images.touchdowns
    );
    let _ = writeln!(
        md,
        "## Which dispersions matter\n\nEach dispersed quantity against the outcome: Spearman's \
         rank correlation with the verdict's margin (the smallest of `1 - value/limit` over \
         touchdown distance, sink rate, bank and pitch, and of the smallest clearance over 5 cm; \
         positive: larger values give safer flights) and with four figures, and the pass rate in each fifth of the flights \
         ordered by the quantity. With {} flights a correlation beyond about +-{:.2} is \
         unlikely by chance (two standard errors). The {} strongest; every quantity is in \
         `report.json`.\n\n| quantity | rho margin | rho touchdown | rho sink | rho altitude RMS | rho airspeed RMS | pass rate by fifth, lowest first |\n|---|---|---|---|---|---|---|",
        r.flights,
        2.0 / (r.flights.max(2) as f64 - 1.0).sqrt(),
        r.sensitivity.len().min(20)
    );
    for s in r.sensitivity.iter().take(20) {
        let rho = |x: Option<f64>| x.map_or("-".into(), |v| format!("{v:+.2}"));
        let figs: Vec<String> = s.rho_figures.iter().map(|(_, v)| rho(*v)).collect();
        let bins: Vec<String> = s
            .pass_rate_by_bin
            .iter()
            .map(|p| format!("{:.0}", 100.0 * p))
            .collect();
        let _ = writeln!(
            md,
            "| `{}` | {} | {} | {} % |",
            s.quantity,
            rho(s.rho_margin),
            figs.join(" | "),
            bins.join(" / ")
        );
    }
    let _ = writeln!(
        md,
        "\n![margin against the strongest quantities]({})\n",
        images.sensitivity
    );
    let _ = writeln!(md, "## Failing flights\n");
    if r.failing.is_empty() {
        let _ = writeln!(md, "None.\n");
    } else {
        let shown = r.failing.len().min(MAX_LISTED);
        brief_table(&mut md, &r.failing[..shown]);
        if shown < r.failing.len() {
            let _ = writeln!(
                md,
                "\n... and {} more, in `report.json` and `flights.jsonl`.",
                r.failing.len() - shown
            );
        }
        md.push('\n');
    }
    let _ = writeln!(md, "## The ten worst flights\n\nSmallest margin first (failing flights before passing ones).\n");
    brief_table(&mut md, &r.worst);
    let spec = toml::to_string(&m.campaign).unwrap_or_default();
    let _ = writeln!(
        md,
        "\n## The dispersions\n\n{}\n\n```toml\n{}```",
        match &m.campaign_file {
            Some(f) => format!("From `{f}`, every key resolved:"),
            None => "The built-in campaign (`sim-host/src/campaign/default_campaign.toml`):".into(),
        },
        spec
    );
    md
}
