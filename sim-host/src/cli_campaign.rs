//! The command line of `sim-host campaign` and `sim-host campaign merge`.

use clap::{Args, Subcommand};
use sim_host::aircraft::Aircraft;
use sim_host::campaign::{output, Shard};
use sim_host::commands::campaign::{self as cmd, CampaignArgs};
use sim_host::commands::{render, Format};
use sim_host::report::to_json;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// `sim-host campaign`.
#[derive(Args)]
#[command(args_conflicts_with_subcommands = true)]
pub(crate) struct CampaignCli {
    #[command(subcommand)]
    sub: Option<CampaignSub>,
    #[command(flatten)]
    run: RunArgs,
}

#[derive(Subcommand)]
enum CampaignSub {
    /// Join the shards of a campaign (`--shard I/N` runs) into the report of the whole one,
    /// the same bytes as the unsharded run.
    Merge {
        /// The shards' output directories.
        #[arg(required = true, value_name = "DIR")]
        dirs: Vec<PathBuf>,
        /// Directory for the whole campaign.
        #[arg(long, value_name = "DIR")]
        out: PathBuf,
        /// Also write the report as this Markdown document (images in `img/` beside it;
        /// notes below its `---` line are kept).
        #[arg(long, value_name = "FILE")]
        doc: Option<PathBuf>,
        /// Set this campaign's output beside the merged one in the document: the same
        /// flights with one thing changed (its campaign file), flight for flight.
        #[arg(long, value_name = "DIR", requires = "doc")]
        beside: Option<PathBuf>,
        /// Print the report as JSON.
        #[arg(long)]
        json: bool,
    },
}

#[derive(Args)]
struct RunArgs {
    /// Flights in the whole campaign.
    #[arg(long, default_value_t = 100)]
    runs: u64,
    /// Campaign seed: flight i's draws follow from it and i alone.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// `default` (the built-in mission), `generated` (one per flight: rectangle, loiter and
    /// landing direction drawn) or a QGroundControl `.plan` / `QGC WPL 110` file.
    #[arg(long, default_value = "default", value_name = "FILE|default|generated")]
    mission: String,
    /// Campaign file (TOML) of the dispersions; the built-in one when absent
    /// (`--print-campaign` shows it).
    #[arg(long, value_name = "FILE")]
    campaign: Option<PathBuf>,
    /// Fly only part I of N of the flights (0-based), for a cluster's job array.
    #[arg(long, value_name = "I/N", value_parser = Shard::parse, default_value = "0/1")]
    shard: Shard,
    /// Fly only flight I again, writing its record, log and plots into --out.
    #[arg(long, value_name = "I", conflicts_with = "shard")]
    index: Option<u64>,
    /// Threads (0: every core).
    #[arg(long, default_value_t = 0)]
    jobs: usize,
    /// Output directory.
    #[arg(long, default_value = "out/campaign", value_name = "DIR")]
    out: PathBuf,
    /// Also write the report as this Markdown document (images in `img/` beside it; notes
    /// below its `---` line are kept).
    #[arg(long, value_name = "FILE")]
    doc: Option<PathBuf>,
    /// Set this campaign's output beside this one in the document: the same flights (same
    /// seed, mission and aircraft) with one thing changed, such as
    /// `sim-host/campaigns/flare-oracle.toml`'s flare on the truth; pass rates by group,
    /// flight for flight.
    #[arg(long, value_name = "DIR", requires = "doc")]
    beside: Option<PathBuf>,
    /// Print the report (or, with --index, the flight's record) as JSON.
    #[arg(long)]
    json: bool,
    /// Print the campaign file in force (every key resolved) and stop.
    #[arg(long)]
    print_campaign: bool,
}

/// Runs `sim-host campaign ...`.
pub(crate) fn campaign_command(
    aircraft: &Aircraft,
    aircraft_file: Option<&Path>,
    c: CampaignCli,
    emit: impl Fn(&str) -> anyhow::Result<()>,
) -> anyhow::Result<ExitCode> {
    if let Some(CampaignSub::Merge {
        dirs,
        out,
        doc,
        beside,
        json,
    }) = c.sub
    {
        let (_, report) = output::merge(&dirs, &out)?;
        if let Some(d) = &doc {
            let (meta, records) = output::read_campaign(&out)?;
            let beside = beside
                .map(|dir| output::read_beside(&meta, &records, &dir))
                .transpose()?;
            output::write_doc(d, &report, &records, beside.as_ref())?;
        }
        if json {
            emit(&to_json(&report)?)?;
        } else {
            emit(&render(&[cmd::summary_table(&report)], Format::Text))?;
            emit(&format!(
                "merged {} shards into {}",
                dirs.len(),
                out.display()
            ))?;
        }
        return Ok(ExitCode::SUCCESS);
    }
    let r = c.run;
    let args = CampaignArgs {
        runs: r.runs,
        seed: r.seed,
        mission: r.mission,
        campaign: r.campaign,
        shard: r.shard,
        index: r.index,
        jobs: r.jobs,
        out: r.out,
        doc: r.doc,
        beside: r.beside,
    };
    if r.print_campaign {
        let spec = sim_host::campaign::CampaignSpec::load(args.campaign.as_deref())?;
        emit(&toml::to_string(&spec)?)?;
        return Ok(ExitCode::SUCCESS);
    }
    let campaign = cmd::campaign_of(aircraft, aircraft_file, &args)?;
    if let Some(i) = args.index {
        let (record, files) = cmd::fly_one(&campaign, i, &args.out)?;
        if r.json {
            emit(&to_json(&record)?)?;
        } else {
            let verdict = if record.verdict.pass {
                "pass".to_string()
            } else {
                format!("fail: {}", record.verdict.failed.join(", "))
            };
            emit(&format!(
                "flight {i}: {verdict} (margin {:.3})",
                record.verdict.margin
            ))?;
            for f in files {
                emit(&format!("wrote {}", f.display()))?;
            }
        }
        return Ok(ExitCode::SUCCESS);
    }
    let run = cmd::run_campaign(&campaign, &args, true)?;
    let t = &run.timing;
    // Wall-clock figures go to standard error and timing.json, never into the report.
    eprintln!(
        "{} flights in {:.1} s on {} threads: {:.2} flights/s, {:.3} flights/s per thread; \
         {:.1} s of CPU: {:.3} flights per CPU-second",
        t.flights,
        t.wall_s,
        t.threads,
        t.flights_per_s,
        t.flights_per_s_per_thread,
        t.cpu_s,
        t.flights_per_cpu_s
    );
    if r.json {
        emit(&to_json(&run.report)?)?;
    } else {
        emit(&render(&[cmd::summary_table(&run.report)], Format::Text))?;
        for f in &run.files {
            emit(&format!("wrote {}", f.display()))?;
        }
    }
    Ok(ExitCode::SUCCESS)
}
