//! `sim-host fly` as the command line runs it, and the flight `sim-host` flies with no
//! subcommand: the flight built from the options, flown (once more on the truth for
//! `--report`, once more with the host build for `--compare-host`), printed and written.

use super::autotune::autotune_report;
use super::flight::fly_report;
use super::options::{FlyOptions, LinkKind};
use super::results::results_markdown;
use super::tables::summary_tables;
use crate::aircraft::Aircraft;
use crate::analysis::design::computed_gain_set;
use crate::commands::compare::compare_with_host;
use crate::commands::sim::stop_on_ctrl_c;
use crate::commands::{render, Format};
use crate::environment::wind::Turbulence;
use crate::flight::config::{FaultWindow, FlightConfig};
use crate::flight::missions::{
    autotune_then_mission, autotune_then_thesis, default_mission, other_runway_missions,
    runway_mission, stick_doublets,
};
use crate::link::profile::ProfileWindow;
use crate::link::qemu::QemuConfig;
use crate::report::{to_json, NOTES_MARKER};
use anyhow::Context;
use std::path::{Path, PathBuf};

/// What `sim-host fly` was asked.
#[derive(Clone, Debug)]
pub struct FlyCommand {
    /// Transport of the simulator link.
    pub link: LinkKind,
    /// Address the simulator listens on for tcp and udp.
    pub bind: String,
    /// Pace the simulation to the wall clock.
    pub realtime: bool,
    /// Wall-clock pace with `realtime`: simulated seconds per wall second.
    pub speed: f64,
    /// Steady wind, north, east, down, m/s (the direction it blows towards).
    pub wind_ned: [f64; 3],
    /// Turbulence.
    pub turbulence: Turbulence,
    /// Seed of the sensor noise and turbulence.
    pub seed: u64,
    /// Plant integration step, s.
    pub dt_s: f64,
    /// Sensor faults over windows of simulated time.
    pub faults: Vec<FaultWindow>,
    /// The MCU image and its QEMU, for [`LinkKind::Qemu`] (no profile window: see
    /// `profile`).
    pub qemu: QemuConfig,
    /// Simulated time, s (`None`: long enough for the whole script).
    pub duration_s: Option<f64>,
    /// Directory for the flight's files.
    pub out: PathBuf,
    /// Gain set loaded before arming (`SYS_GAIN_SET`).
    pub gains: Option<u32>,
    /// Fly on the simulator's truth (`SIM_USE_TRUTH` = 1).
    pub truth: bool,
    /// Also fly on the truth and write this results document.
    pub report: Option<PathBuf>,
    /// Also fly with the host build in this process and compare the answers.
    pub compare_host: bool,
    /// Profile the MCU image over this window (with [`LinkKind::Qemu`]).
    pub profile: Option<ProfileWindow>,
    /// Print the summary as JSON.
    pub json: bool,
    /// A mission from the runway: a mission file, `default`, `runway-120` or `runway-250`.
    pub mission: Option<PathBuf>,
    /// Fly the stick doublets of an identification flight instead of the thesis's script.
    pub stick_doublets: bool,
    /// Autotune in the air first, then fly the thesis's script (or, with `mission`, the
    /// mission) on its gains.
    pub autotune: bool,
    /// Parameters set before arming, name and value.
    pub params: Vec<(String, f32)>,
    /// Messages asked for before arming: id and rate, Hz.
    pub message_rates: Vec<(u32, f32)>,
}

/// The flight configuration of `--mission`: the built-in default mission, a built-in mission
/// on another runway or a mission file.
pub fn mission_config(aircraft: &Aircraft, which: &Path) -> anyhow::Result<FlightConfig> {
    let home = crate::plant::ModelParams::new(aircraft).home;
    if which == Path::new("default") {
        return Ok(runway_mission(default_mission(home)));
    }
    // `runway-120` and `runway-250`: the built-in missions on other runways, standing on them.
    if let Some(m) = other_runway_missions(home)
        .into_iter()
        .find(|m| which == Path::new(&m.name.replace(' ', "-")))
    {
        return Ok(FlightConfig {
            runway_heading: Some(m.runway_rad),
            ..runway_mission(m.items)
        });
    }
    let file = crate::mission_file::read_mission_file(which)?;
    anyhow::ensure!(
        !file.mission.is_empty(),
        "`{}`: the mission has no items",
        which.display()
    );
    let mut cfg = runway_mission(file.mission);
    cfg.script.fence = file.fence;
    Ok(cfg)
}

/// The throttle of the aircraft's level trim at its cruise airspeed.
pub fn level_trim_throttle(aircraft: &Aircraft) -> anyhow::Result<f32> {
    use crate::analysis::trim::{not_trimmed, trim_with, TrimTarget};
    let target = TrimTarget::cruise(aircraft);
    let trim = trim_with(&crate::plant::params::ModelParams::new(aircraft), &target);
    anyhow::ensure!(trim.converged, "{}", not_trimmed(&trim));
    Ok(trim.throttle as f32)
}

/// Runs `sim-host fly`: flies, prints through `emit` and writes the files asked for.
pub fn fly_command(
    aircraft: &Aircraft,
    a: FlyCommand,
    emit: impl Fn(&str) -> anyhow::Result<()>,
) -> anyhow::Result<()> {
    // What the flight flies without the autotune; with it, the same on the default gains is
    // flown as well, for the side-by-side tables.
    let plain = match &a.mission {
        Some(m) => mission_config(aircraft, m)?,
        None if a.stick_doublets => stick_doublets(level_trim_throttle(aircraft)?),
        None => FlightConfig::default(),
    };
    let base = match (&a.mission, a.autotune) {
        (Some(_), true) => autotune_then_mission(plain.clone()),
        (None, true) => autotune_then_thesis(),
        (_, false) => plain.clone(),
    };
    // Ctrl-C ends the flight as flown so far (and QEMU with it).
    let stop = stop_on_ctrl_c();
    let configure = |base: FlightConfig| {
        let mut cfg = FlightConfig {
            wind_ned: a.wind_ned,
            turbulence: a.turbulence,
            seed: a.seed,
            realtime: a.realtime,
            speed: a.speed,
            progress: true,
            dt_s: a.dt_s,
            // With --realtime, QGroundControl can watch: telemetry to 14550, as from PX4 SITL.
            ground_link: a
                .realtime
                .then(|| ("127.0.0.1:18570".into(), "127.0.0.1:14550".into())),
            stop: Some(stop),
            ..base
        };
        cfg.faults.extend(a.faults.iter().copied());
        if let Some(d) = a.duration_s {
            cfg.duration_s = d;
        }
        cfg.script.params.extend(a.params.iter().cloned());
        cfg.script
            .message_rates
            .extend(a.message_rates.iter().copied());
        cfg
    };
    let cfg = configure(base);
    if let Some(g) = a.gains {
        let names: Vec<&str> = common::control::gains::NAMED
            .iter()
            .map(|(n, _, _)| *n)
            .collect();
        anyhow::ensure!(
            (g as usize) < names.len(),
            "--gains {g}: no such gain set (0..={}: {})",
            names.len() - 1,
            names.join(", ")
        );
    }
    let opts = FlyOptions {
        link: a.link,
        bind: a.bind,
        out: Some(a.out.clone()),
        plots: true,
        gain_set: a.gains,
        // The thesis's scripted flight flies the gains designed here; a mission flies the
        // firmware's defaults, as `sim-host navigation` and a fresh autopilot do.
        upload_gains: match (a.gains, &a.mission) {
            (None, None) if !a.autotune => Some(computed_gain_set(aircraft)?),
            _ => None,
        },
        use_truth: a.truth,
        qemu: QemuConfig {
            profile: a.profile.map(|w| (w, a.out.clone())),
            ..a.qemu
        },
    };
    if a.profile.is_some() && a.link != LinkKind::Qemu {
        anyhow::bail!("--profile profiles the MCU image: it needs --link qemu");
    }
    let r = fly_report(aircraft, &cfg, &opts)?;
    // The same script or mission on the default gains, for the autotune's side-by-side
    // tables.
    let tuned = if a.autotune {
        let plain_cfg = FlightConfig {
            progress: false,
            ..configure(plain)
        };
        let plain_opts = FlyOptions {
            out: Some(a.out.join("default-gains")),
            plots: false,
            ..opts.clone()
        };
        let plain = fly_report(aircraft, &plain_cfg, &plain_opts)?;
        let report = autotune_report(aircraft, &r.outcome, &plain.outcome)?;
        // The tables as docs/AUTOTUNE.md shows them.
        let path = a.out.join("autotune.md");
        std::fs::write(&path, render(&report.tables(), Format::Markdown))
            .with_context(|| format!("cannot write `{}`", path.display()))?;
        Some(report)
    } else {
        None
    };
    if let Some(p) = &r.mcu_profile {
        let path = a.out.join("profile.md");
        std::fs::write(&path, p.markdown(usize::MAX))
            .with_context(|| format!("cannot write `{}`", path.display()))?;
    }
    let compared = if a.compare_host {
        Some(compare_with_host(aircraft, &cfg, &opts)?)
    } else {
        None
    };
    if a.json {
        match (&compared, &r.mcu) {
            (Some(c), mcu) => emit(&to_json(&serde_json::json!({
                "flight": r.outcome.summary,
                "host": c.host.summary,
                "answers": c.answers,
                "mcu": mcu,
            }))?)?,
            // The MCU image's figures of itself (--link qemu): flash, RAM, instructions.
            (None, Some(m)) => {
                let mut doc = serde_json::to_value(&r.outcome.summary)?;
                if let Some(o) = doc.as_object_mut() {
                    let mut mcu = serde_json::to_value(m)?;
                    if let (Some(p), Some(mo)) = (&r.mcu_profile, mcu.as_object_mut()) {
                        mo.insert("profile".into(), serde_json::to_value(p)?);
                    }
                    o.insert("mcu".into(), mcu);
                }
                emit(&to_json(&doc)?)?
            }
            (None, None) => {
                let mut doc = serde_json::to_value(&r.outcome.summary)?;
                if let (Some(t), Some(o)) = (&tuned, doc.as_object_mut()) {
                    o.insert("autotune".into(), serde_json::to_value(t)?);
                }
                emit(&to_json(&doc)?)?
            }
        }
    } else {
        emit(&render(&summary_tables(&r.outcome), Format::Text))?;
        if let Some(t) = &tuned {
            emit(&render(&t.tables(), Format::Text))?;
        }
        if let Some(c) = &compared {
            emit(&render(&[c.table(&r.outcome, opts.link)], Format::Text))?;
        }
        if let Some(p) = &r.mcu_profile {
            emit(&p.markdown(25))?;
        }
        for f in &r.files {
            emit(&format!("wrote {}", f.display()))?;
        }
    }
    for (t, text) in &r.outcome.summary.texts {
        // Arming refusals while the estimator converges are expected (the script retries).
        if text.contains("refused") {
            eprintln!("autopilot at {t:.1} s: {text}");
        }
    }
    if let Some(path) = a.report {
        let truth_opts = FlyOptions {
            use_truth: true,
            out: Some(a.out.join("truth")),
            ..opts
        };
        let t = fly_report(aircraft, &cfg, &truth_opts)?;
        let md = results_markdown(
            &cfg,
            &r.outcome,
            &t.outcome,
            &format!(
                "cargo run --release -p sim-host -- {}",
                std::env::args().skip(1).collect::<Vec<_>>().join(" ")
            ),
        );
        // Notes written by hand below the generated part survive a new run.
        let notes = std::fs::read_to_string(&path)
            .ok()
            .and_then(|old| old.find(NOTES_MARKER).map(|i| old[i..].to_string()))
            .unwrap_or_default();
        std::fs::write(&path, md + &notes)
            .with_context(|| format!("cannot write `{}`", path.display()))?;
        emit(&format!("wrote {}", path.display()))?;
    }
    Ok(())
}

/// `sim-host` with no subcommand: flies the default mission in-process and prints a short
/// summary.
pub fn default_flight(
    aircraft: &Aircraft,
    emit: impl Fn(&str) -> anyhow::Result<()>,
) -> anyhow::Result<()> {
    let cfg = FlightConfig {
        progress: true,
        ..mission_config(aircraft, Path::new("default"))?
    };
    let opts = FlyOptions {
        out: Some(PathBuf::from("out/fly")),
        ..Default::default()
    };
    emit("Flying the firmware in-process, on its own estimates: upload the default mission, arm, take off from the runway, a 600 m x 400 m rectangle, two turns around a corner, approach and landing")?;
    let r = fly_report(aircraft, &cfg, &opts)?;
    emit(&render(&summary_tables(&r.outcome), Format::Text))?;
    emit("\nfiles in out/fly (flight.csv, flight.tlog of the ground link, simlink.tlog, PNG plots, summary.json)")?;
    emit("(see `sim-host --help` for fly, trim, linearize, doublet, design and validation)")?;
    Ok(())
}
