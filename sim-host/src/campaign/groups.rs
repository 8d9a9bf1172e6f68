//! Pass rates by group (the turbulence each flight met, whether its aircraft carried a
//! rangefinder) and, beside them, the same flights of a campaign that changed one thing (the
//! flare flown on the simulator's truth, say): what that one change did, flight for flight.
//!
//! Two campaigns of the same seed, mission and aircraft draw the same flights (a flight's
//! draws follow from the seed and its index alone, and a change that draws nothing new leaves
//! them as they were), so their verdicts pair up by index: the difference is the change's,
//! not the luck of other gusts.

use super::record::FlightRecord;
use super::run::CampaignMeta;
use super::stats::{pct, wilson, Z95};
use anyhow::bail;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;

/// Name of the draw that says whether the aircraft carried a rangefinder (1) or not (0).
pub const RANGEFINDER_DRAW: &str = "rangefinder.fitted";
/// Name of the draw that gives the turbulence, an index into the campaign's severities.
pub const TURBULENCE_DRAW: &str = "wind.turbulence_index";

/// One group's pass rate.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct GroupRate {
    /// The group, as the document names it.
    pub group: String,
    /// Flights in it.
    pub flights: u64,
    /// Of which passed.
    pub passed: u64,
    /// 95 % Wilson interval of the pass rate.
    pub ci95: (f64, f64),
}

/// A group's pass rate here and in the campaign beside.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PairedRate {
    /// This campaign's rate.
    pub here: GroupRate,
    /// The same flights' in the campaign beside.
    pub beside: GroupRate,
    /// Flights that pass here only.
    pub only_here: u64,
    /// Flights that pass beside only.
    pub only_beside: u64,
}

/// Another campaign of the same flights, with one thing changed.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Beside {
    /// Its output directory.
    pub dir: String,
    /// The command that flew it.
    pub command: String,
    /// What its campaign file changed, `key: here -> beside`.
    pub changes: Vec<String>,
    /// Every group's rates, paired.
    pub rows: Vec<PairedRate>,
}

/// Which flights make a group.
type Member = Box<dyn Fn(&FlightRecord) -> bool>;

/// The groups: every flight, each turbulence severity the campaign draws from (when more than
/// one), and, where the rangefinder is drawn, each of those with and without one.
fn groups(meta: &CampaignMeta, records: &[FlightRecord]) -> Vec<(String, Member)> {
    let names = &meta.campaign.wind.turbulence;
    let mut air: Vec<(String, Option<usize>)> = vec![("every flight".into(), None)];
    if names.len() > 1 {
        air.extend(
            names
                .iter()
                .enumerate()
                .map(|(i, n)| (format!("{n} turbulence"), Some(i))),
        );
    }
    let drawn = records
        .iter()
        .any(|r| r.draws.get(RANGEFINDER_DRAW).is_some());
    let mut out: Vec<(String, Member)> = Vec::new();
    for (name, level) in air {
        let in_air = move |r: &FlightRecord| {
            level.is_none_or(|l| r.draws.get(TURBULENCE_DRAW) == Some(l as f64))
        };
        if drawn {
            for (tag, fitted) in [("with a rangefinder", 1.0), ("without", 0.0)] {
                out.push((
                    format!("{name}, {tag}"),
                    Box::new(move |r: &FlightRecord| {
                        in_air(r) && r.draws.get(RANGEFINDER_DRAW) == Some(fitted)
                    }),
                ));
            }
        }
        out.push((name, Box::new(in_air)));
    }
    out
}

fn rate(group: &str, records: &[&FlightRecord]) -> GroupRate {
    let flights = records.len() as u64;
    let passed = records.iter().filter(|r| r.verdict.pass).count() as u64;
    GroupRate {
        group: group.into(),
        flights,
        passed,
        ci95: wilson(passed, flights, Z95),
    }
}

/// The pass rate of every group of the campaign.
pub fn rates(meta: &CampaignMeta, records: &[FlightRecord]) -> Vec<GroupRate> {
    groups(meta, records)
        .iter()
        .map(|(name, member)| {
            let mine: Vec<&FlightRecord> = records.iter().filter(|r| member(r)).collect();
            rate(name, &mine)
        })
        .collect()
}

/// The campaign in `dir` beside this one, flight for flight; refused when its flights are not
/// this campaign's (another seed, mission or aircraft, or other flight indices).
pub fn beside(
    meta: &CampaignMeta,
    records: &[FlightRecord],
    dir: &Path,
    other: (&CampaignMeta, &[FlightRecord]),
) -> anyhow::Result<Beside> {
    let (om, orecs) = other;
    let same = [
        ("seed", meta.seed.to_string(), om.seed.to_string()),
        ("mission", meta.mission.clone(), om.mission.clone()),
        (
            "mission items",
            format!("{:?}", meta.mission_hash),
            format!("{:?}", om.mission_hash),
        ),
        (
            "aircraft",
            meta.aircraft_hash.clone(),
            om.aircraft_hash.clone(),
        ),
    ];
    for (what, mine, theirs) in same {
        if mine != theirs {
            bail!(
                "`{}` is not beside this campaign: its {what} is {theirs}, this one's {mine}",
                dir.display()
            );
        }
    }
    let by_index: BTreeMap<u64, &FlightRecord> = orecs.iter().map(|r| (r.index, r)).collect();
    let mut mine: Vec<&FlightRecord> = records.iter().collect();
    mine.sort_by_key(|r| r.index);
    if mine.len() != by_index.len() || mine.iter().any(|r| !by_index.contains_key(&r.index)) {
        bail!(
            "`{}` is not beside this campaign: it flew {} flights, not this campaign's {}",
            dir.display(),
            by_index.len(),
            mine.len()
        );
    }
    let rows = groups(meta, records)
        .iter()
        .map(|(name, member)| {
            let here: Vec<&FlightRecord> = mine.iter().copied().filter(|r| member(r)).collect();
            let there: Vec<&FlightRecord> = here.iter().map(|r| by_index[&r.index]).collect();
            let pairs = here.iter().zip(&there);
            PairedRate {
                here: rate(name, &here),
                beside: rate(name, &there),
                only_here: pairs
                    .clone()
                    .filter(|(a, b)| a.verdict.pass && !b.verdict.pass)
                    .count() as u64,
                only_beside: pairs
                    .filter(|(a, b)| !a.verdict.pass && b.verdict.pass)
                    .count() as u64,
            }
        })
        .collect();
    Ok(Beside {
        dir: dir.display().to_string(),
        command: format!("{} --out {}", om.command(), dir.display()),
        changes: changes(meta, om),
        rows,
    })
}

/// The keys of the campaign files that differ, with both values.
fn changes(a: &CampaignMeta, b: &CampaignMeta) -> Vec<String> {
    let flat = |m: &CampaignMeta| {
        let mut out = BTreeMap::new();
        if let Ok(toml::Value::Table(t)) = toml::Value::try_from(&m.campaign) {
            flatten(&t, "", &mut out);
        }
        out
    };
    let (x, y) = (flat(a), flat(b));
    let keys: std::collections::BTreeSet<&String> = x.keys().chain(y.keys()).collect();
    keys.into_iter()
        .filter(|k| x.get(*k) != y.get(*k))
        .map(|k| {
            let show = |m: &BTreeMap<String, String>| m.get(k).cloned().unwrap_or("-".into());
            format!("`{k}`: {} here, {} beside", show(&x), show(&y))
        })
        .collect()
}

fn flatten(t: &toml::Table, path: &str, out: &mut BTreeMap<String, String>) {
    for (k, v) in t {
        let key = if path.is_empty() {
            k.clone()
        } else {
            format!("{path}.{k}")
        };
        match v {
            toml::Value::Table(inner) => flatten(inner, &key, out),
            other => {
                out.insert(key, other.to_string());
            }
        }
    }
}

fn cell(r: &GroupRate) -> String {
    format!(
        "{} of {} ({}; {} to {})",
        r.passed,
        r.flights,
        pct(r.passed as f64 / r.flights.max(1) as f64),
        pct(r.ci95.0),
        pct(r.ci95.1)
    )
}

/// The document's section: every group's rate, and the campaign beside when there is one.
pub fn markdown(rates: &[GroupRate], beside: Option<&Beside>) -> String {
    let mut md =
        String::from("## Pass rate by group\n\nPass count, rate and its 95 % Wilson interval.\n\n");
    match beside {
        None => {
            md += "| group | passed |\n|---|---|\n";
            for r in rates {
                let _ = writeln!(md, "| {} | {} |", r.group, cell(r));
            }
        }
        Some(b) => {
            let _ = writeln!(
                md,
                "Beside: the same flights, draw for draw, flown by `{}`, which changed {}.\n\n\
                 | group | passed | passed beside | pass here only | pass beside only |\n\
                 |---|---|---|---:|---:|",
                b.command,
                if b.changes.is_empty() {
                    "nothing in the campaign file".to_string()
                } else {
                    b.changes.join("; ")
                }
            );
            for r in &b.rows {
                let _ = writeln!(
                    md,
                    "| {} | {} | {} | {} | {} |",
                    r.here.group,
                    cell(&r.here),
                    cell(&r.beside),
                    r.only_here,
                    r.only_beside
                );
            }
        }
    }
    md.push('\n');
    md
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_change_of_one_key_is_named_with_both_values() {
        let c = crate::campaign::Campaign {
            seed: 1,
            runs: 10,
            spec: crate::campaign::CampaignSpec::default(),
            spec_file: None,
            mission: crate::campaign::MissionChoice::Default,
            aircraft: crate::aircraft::Aircraft::ultrastick25e().expect("built in"),
            aircraft_file: None,
        };
        let mut oracle = c.clone();
        oracle.spec.oracle.flare_on_truth = true;
        let shard = crate::campaign::Shard::parse("0/1").expect("whole");
        assert_eq!(
            changes(&c.meta(shard), &oracle.meta(shard)),
            vec!["`oracle.flare_on_truth`: false here, true beside".to_string()]
        );
    }
}
