//! A campaign's directory, and shards merged into one.
//!
//! ```text
//! campaign.json   what identifies the campaign (seed, runs, mission, dispersions, criteria,
//!                 aircraft, shard)
//! flights.jsonl   one record per flight, in index order
//! report.json     the report's numbers        report.md   the report
//! histograms.png  touchdowns.png  sensitivity.png
//! timing.json     wall-clock figures of this run (not part of the campaign's result)
//! ```
//!
//! The report is always made from `flights.jsonl` as read back from the disk, by the same
//! code for a run and for a merge, and carries no wall-clock value: a merge of shards writes
//! the same bytes as the unsharded run.

use super::groups::{self, Beside};
use super::plots;
use super::record::FlightRecord;
use super::report::{markdown, Images, Report};
use super::run::{CampaignMeta, Shard, FORMAT};
use crate::report::NOTES_MARKER;
use anyhow::{bail, Context};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Identity file.
pub const META_FILE: &str = "campaign.json";
/// Records.
pub const RECORDS_FILE: &str = "flights.jsonl";
/// Wall-clock figures.
pub const TIMING_FILE: &str = "timing.json";
/// The files whose bytes are the campaign's result (everything but the timing).
pub const RESULT_FILES: [&str; 7] = [
    META_FILE,
    RECORDS_FILE,
    "report.json",
    "report.md",
    "histograms.png",
    "touchdowns.png",
    "sensitivity.png",
];

fn write(path: &Path, text: &str) -> anyhow::Result<()> {
    std::fs::write(path, text).with_context(|| format!("cannot write `{}`", path.display()))
}

/// Writes the identity and the records, then the report made from the records as written.
pub fn write_campaign(
    dir: &Path,
    meta: &CampaignMeta,
    records: &[FlightRecord],
) -> anyhow::Result<Report> {
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create `{}`", dir.display()))?;
    write(
        &dir.join(META_FILE),
        &(serde_json::to_string_pretty(meta)? + "\n"),
    )?;
    let mut lines = String::new();
    let mut sorted: Vec<&FlightRecord> = records.iter().collect();
    sorted.sort_by_key(|r| r.index);
    for r in sorted {
        lines += &serde_json::to_string(r)?;
        lines.push('\n');
    }
    write(&dir.join(RECORDS_FILE), &lines)?;
    let (meta, records) = read_campaign(dir)?;
    let report = Report::new(meta, &records);
    write(
        &dir.join("report.json"),
        &(serde_json::to_string_pretty(&report)? + "\n"),
    )?;
    let images = Images {
        histograms: "histograms.png".into(),
        touchdowns: "touchdowns.png".into(),
        sensitivity: "sensitivity.png".into(),
    };
    write(&dir.join("report.md"), &markdown(&report, &images, None))?;
    draw(dir, &images, &report, &records)?;
    Ok(report)
}

fn draw(
    dir: &Path,
    images: &Images,
    report: &Report,
    records: &[FlightRecord],
) -> anyhow::Result<()> {
    plots::histograms(records, &dir.join(&images.histograms))?;
    plots::touchdowns(records, &dir.join(&images.touchdowns))?;
    plots::sensitivity(report, records, &dir.join(&images.sensitivity))
}

/// The campaign in `dir`, paired flight for flight with `records` of the campaign `meta`.
pub fn read_beside(
    meta: &CampaignMeta,
    records: &[FlightRecord],
    dir: &Path,
) -> anyhow::Result<Beside> {
    let (other, theirs) = read_campaign(dir)?;
    groups::beside(meta, records, dir, (&other, &theirs))
}

/// Reads a campaign directory's identity and records; errors name the file and the line.
pub fn read_campaign(dir: &Path) -> anyhow::Result<(CampaignMeta, Vec<FlightRecord>)> {
    let mp = dir.join(META_FILE);
    let text = std::fs::read_to_string(&mp).with_context(|| {
        format!(
            "cannot read `{}` (is `{}` a campaign's output?)",
            mp.display(),
            dir.display()
        )
    })?;
    let meta: CampaignMeta =
        serde_json::from_str(&text).with_context(|| format!("`{}`", mp.display()))?;
    if meta.format != FORMAT {
        bail!(
            "`{}`: format {} (this sim-host reads format {FORMAT})",
            mp.display(),
            meta.format
        );
    }
    let rp = dir.join(RECORDS_FILE);
    let text =
        std::fs::read_to_string(&rp).with_context(|| format!("cannot read `{}`", rp.display()))?;
    let records = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty())
        .map(|(i, l)| {
            serde_json::from_str::<FlightRecord>(l)
                .with_context(|| format!("`{}` line {}", rp.display(), i + 1))
        })
        .collect::<anyhow::Result<Vec<_>>>()?;
    Ok((meta, records))
}

/// The first key at which two campaigns' identities differ, shard aside, with both values.
fn difference(a: &CampaignMeta, b: &CampaignMeta) -> Option<(String, String, String)> {
    let strip = |m: &CampaignMeta| {
        let mut v = serde_json::to_value(m).unwrap_or_default();
        if let Some(o) = v.as_object_mut() {
            o.remove("shard");
        }
        v
    };
    fn walk(
        a: &serde_json::Value,
        b: &serde_json::Value,
        path: &str,
    ) -> Option<(String, String, String)> {
        match (a, b) {
            (serde_json::Value::Object(x), serde_json::Value::Object(y)) => {
                let mut keys: Vec<&String> = x.keys().chain(y.keys()).collect();
                keys.sort();
                keys.dedup();
                keys.into_iter().find_map(|k| {
                    let p = if path.is_empty() {
                        k.clone()
                    } else {
                        format!("{path}.{k}")
                    };
                    let null = serde_json::Value::Null;
                    walk(x.get(k).unwrap_or(&null), y.get(k).unwrap_or(&null), &p)
                })
            }
            _ if a != b => Some((path.to_string(), a.to_string(), b.to_string())),
            _ => None,
        }
    }
    walk(&strip(a), &strip(b), "")
}

/// Joins the shards in `dirs` into the whole campaign in `out`; refuses shards of different
/// campaigns, a shard given twice, a missing shard, or a shard whose records are not its own.
pub fn merge(dirs: &[PathBuf], out: &Path) -> anyhow::Result<(CampaignMeta, Report)> {
    let Some(first) = dirs.first() else {
        bail!("merge: name the shards' directories");
    };
    let mut shards: Vec<(PathBuf, CampaignMeta, Vec<FlightRecord>)> = Vec::new();
    for d in dirs {
        let (meta, records) = read_campaign(d)?;
        if let Some((_, m0, _)) = shards.first() {
            if let Some((key, theirs, ours)) = difference(&meta, m0) {
                bail!(
                    "`{}` is a shard of another campaign than `{}`: `{key}` is {theirs} there and {ours} here",
                    d.display(),
                    first.display()
                );
            }
            if meta.shard.count != m0.shard.count {
                bail!(
                    "`{}` is shard {} but `{}` is shard {}: the campaign was split two ways",
                    d.display(),
                    meta.shard,
                    first.display(),
                    m0.shard
                );
            }
        }
        if let Some((other, _, _)) = shards.iter().find(|(_, m, _)| m.shard == meta.shard) {
            bail!(
                "shard {} given twice: `{}` and `{}`",
                meta.shard,
                other.display(),
                d.display()
            );
        }
        let want: Vec<u64> = meta.shard.indices(meta.runs).collect();
        let mut have: Vec<u64> = records.iter().map(|r| r.index).collect();
        have.sort_unstable();
        if have != want {
            bail!(
                "`{}`: shard {} holds flights {} but should hold {:?}",
                d.display(),
                meta.shard,
                summarise(&have),
                want.first().zip(want.last()).map(|(a, b)| a..=b)
            );
        }
        shards.push((d.clone(), meta, records));
    }
    let count = shards[0].1.shard.count;
    let missing: Vec<String> = (0..count)
        .filter(|i| !shards.iter().any(|(_, m, _)| m.shard.index == *i))
        .map(|i| format!("{i}/{count}"))
        .collect();
    if !missing.is_empty() {
        bail!("merge: shard(s) {} missing", missing.join(", "));
    }
    let mut meta = shards[0].1.clone();
    meta.shard = Shard::WHOLE;
    let records: Vec<FlightRecord> = shards.into_iter().flat_map(|s| s.2).collect();
    let report = write_campaign(out, &meta, &records)?;
    Ok((meta, report))
}

/// `0-9, 12` style list of sorted indices.
fn summarise(v: &[u64]) -> String {
    let mut s = String::new();
    let mut i = 0;
    while i < v.len() {
        let mut j = i;
        while j + 1 < v.len() && v[j + 1] == v[j] + 1 {
            j += 1;
        }
        if !s.is_empty() {
            s += ", ";
        }
        let _ = if i == j {
            write!(s, "{}", v[i])
        } else {
            write!(s, "{}-{}", v[i], v[j])
        };
        i = j + 1;
    }
    if s.is_empty() {
        "none".into()
    } else {
        s
    }
}

/// Writes the report as a document at `doc`, its images beside it in `img/montecarlo-*.png`,
/// keeping the notes below [`NOTES_MARKER`] of the document already there.
pub fn write_doc(
    doc: &Path,
    report: &Report,
    records: &[FlightRecord],
    beside: Option<&Beside>,
) -> anyhow::Result<Vec<PathBuf>> {
    let dir = doc
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let img = dir.join("img");
    std::fs::create_dir_all(&img).with_context(|| format!("cannot create `{}`", img.display()))?;
    let images = Images {
        histograms: "img/montecarlo-histograms.png".into(),
        touchdowns: "img/montecarlo-touchdowns.png".into(),
        sensitivity: "img/montecarlo-sensitivity.png".into(),
    };
    draw(dir, &images, report, records)?;
    let notes = std::fs::read_to_string(doc)
        .ok()
        .and_then(|old| old.find(NOTES_MARKER).map(|i| old[i..].to_string()))
        .unwrap_or_default();
    write(doc, &(markdown(report, &images, beside) + &notes))?;
    Ok(vec![
        doc.to_path_buf(),
        dir.join(&images.histograms),
        dir.join(&images.touchdowns),
        dir.join(&images.sensitivity),
    ])
}
