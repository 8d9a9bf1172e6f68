//! `sim-host campaign`: a Monte Carlo campaign of dispersed flights (or one shard of it, or one
//! flight of it flown again with its log), and `sim-host campaign merge` of shards.

use crate::aircraft::Aircraft;
use crate::campaign::groups;
use crate::campaign::output::{self, TIMING_FILE};
use crate::campaign::{Campaign, CampaignSpec, MissionChoice, Report, Shard};
use crate::flight::plots::write_log_and_plots;
use crate::report::table::Table;
use crate::report::to_json;
use anyhow::Context;
use serde::Serialize;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// What `sim-host campaign` was asked.
#[derive(Clone, Debug)]
pub struct CampaignArgs {
    /// Flights in the whole campaign.
    pub runs: u64,
    /// Campaign seed.
    pub seed: u64,
    /// `default`, `generated` or a mission file.
    pub mission: String,
    /// Campaign file.
    pub campaign: Option<PathBuf>,
    /// This run's part.
    pub shard: Shard,
    /// Fly only this flight, with its log and plots.
    pub index: Option<u64>,
    /// Threads (0: every core).
    pub jobs: usize,
    /// Output directory.
    pub out: PathBuf,
    /// Also write the report as this document.
    pub doc: Option<PathBuf>,
    /// The output of a campaign of the same flights to set beside this one in the document.
    pub beside: Option<PathBuf>,
}

/// Wall-clock figures of a run, kept apart from its result (`timing.json`).
#[derive(Clone, Debug, Serialize)]
pub struct Timing {
    /// Flights flown.
    pub flights: u64,
    /// Threads of the pool.
    pub threads: usize,
    /// Wall-clock time of the flights, s.
    pub wall_s: f64,
    /// Flights per second.
    pub flights_per_s: f64,
    /// Flights per second per thread.
    pub flights_per_s_per_thread: f64,
    /// Simulated seconds flown, summed.
    pub simulated_s: f64,
    /// CPU time of the process over the flights, s (all threads).
    pub cpu_s: f64,
    /// Flights per CPU-second: flights per second per core when every core is this run's,
    /// whatever else the machine was doing.
    pub flights_per_cpu_s: f64,
}

/// The process's CPU time, s (all threads), from its CPU clock.
fn cpu_time_s() -> f64 {
    use nix::time::{clock_gettime, ClockId};
    clock_gettime(ClockId::CLOCK_PROCESS_CPUTIME_ID)
        .map_or(f64::NAN, |t| t.tv_sec() as f64 + t.tv_nsec() as f64 * 1e-9)
}

/// Builds the campaign the arguments describe.
pub fn campaign_of(
    aircraft: &Aircraft,
    aircraft_file: Option<&Path>,
    a: &CampaignArgs,
) -> anyhow::Result<Campaign> {
    anyhow::ensure!(a.runs > 0, "--runs {}: fly at least one flight", a.runs);
    Ok(Campaign {
        seed: a.seed,
        runs: a.runs,
        spec: CampaignSpec::load(a.campaign.as_deref())?,
        spec_file: a.campaign.clone(),
        mission: MissionChoice::parse(&a.mission)?,
        aircraft: aircraft.clone(),
        aircraft_file: aircraft_file.map(Path::to_path_buf),
    })
}

/// What a run printed and wrote.
pub struct CampaignRun {
    /// The report of the flights flown.
    pub report: Report,
    /// Their timing.
    pub timing: Timing,
    /// Files written.
    pub files: Vec<PathBuf>,
}

/// Flies the campaign's flights of `a.shard` and writes its directory (and the document).
pub fn run_campaign(c: &Campaign, a: &CampaignArgs, progress: bool) -> anyhow::Result<CampaignRun> {
    let threads = if a.jobs == 0 {
        std::thread::available_parallelism().map_or(1, |n| n.get())
    } else {
        a.jobs
    };
    // Read before flying: a wrong directory is refused before the flights, not after.
    let beside = match (&a.doc, &a.beside) {
        (Some(_), Some(dir)) => Some((dir, output::read_campaign(dir)?)),
        (None, Some(dir)) => anyhow::bail!(
            "--beside {} sets a campaign beside this one in the document: it needs --doc",
            dir.display()
        ),
        _ => None,
    };
    let (start, cpu0) = (Instant::now(), cpu_time_s());
    let records = c.run(a.shard, threads, progress)?;
    let (wall_s, cpu_s) = (start.elapsed().as_secs_f64(), cpu_time_s() - cpu0);
    let flights = records.len() as u64;
    let timing = Timing {
        flights,
        threads,
        wall_s,
        flights_per_s: flights as f64 / wall_s,
        flights_per_s_per_thread: flights as f64 / wall_s / threads as f64,
        simulated_s: records.iter().filter_map(|r| r.figures.sim_s).sum(),
        cpu_s,
        flights_per_cpu_s: flights as f64 / cpu_s,
    };
    let report = output::write_campaign(&a.out, &c.meta(a.shard), &records)?;
    std::fs::write(a.out.join(TIMING_FILE), to_json(&timing)? + "\n")
        .with_context(|| format!("cannot write `{}`", a.out.join(TIMING_FILE).display()))?;
    let mut files: Vec<PathBuf> = output::RESULT_FILES.iter().map(|f| a.out.join(f)).collect();
    files.push(a.out.join(TIMING_FILE));
    if let Some(doc) = &a.doc {
        let (meta, records) = output::read_campaign(&a.out)?;
        let beside = beside
            .map(|(dir, (m, r))| groups::beside(&meta, &records, dir, (&m, &r)))
            .transpose()?;
        files.extend(output::write_doc(doc, &report, &records, beside.as_ref())?);
    }
    Ok(CampaignRun {
        report,
        timing,
        files,
    })
}

/// Flies flight `index` again and writes its record, summary, log and plots into `out`.
pub fn fly_one(
    c: &Campaign,
    index: u64,
    out: &Path,
) -> anyhow::Result<(crate::campaign::FlightRecord, Vec<PathBuf>)> {
    std::fs::create_dir_all(out).with_context(|| format!("cannot create `{}`", out.display()))?;
    let (record, outcome) = c.fly(index);
    let mut files = Vec::new();
    let path = out.join("record.json");
    std::fs::write(&path, to_json(&record)? + "\n")
        .with_context(|| format!("cannot write `{}`", path.display()))?;
    files.push(path);
    if let Some(o) = outcome {
        let path = out.join("summary.json");
        std::fs::write(&path, to_json(&o.summary)?)
            .with_context(|| format!("cannot write `{}`", path.display()))?;
        files.push(path);
        files.extend(write_log_and_plots(out, &o.samples)?);
    }
    Ok((record, files))
}

/// The short summary a run prints.
pub fn summary_table(r: &Report) -> Table {
    let mut t = Table::new(
        format!(
            "Campaign: {} flights of the {} mission",
            r.flights, r.campaign.mission
        ),
        &["quantity", "value"],
    );
    let (lo, hi) = r.pass_rate_ci95;
    t.row([
        "passed".to_string(),
        format!(
            "{} of {} ({:.1} %, 95 % interval {:.1} to {:.1} %)",
            r.passed,
            r.flights,
            100.0 * r.pass_rate,
            100.0 * lo,
            100.0 * hi
        ),
    ]);
    for c in &r.criteria {
        t.row([format!("failing `{}`", c.name), c.failed.to_string()]);
    }
    if let Some(w) = r.worst.first() {
        t.row([
            "worst flight".to_string(),
            format!("{} (re-fly: {})", w.index, w.reproduce),
        ]);
    }
    t
}
