//! `sim-host`: the Ultra Stick 25e simulator and the thesis's analysis commands.

mod cli;
mod cli_campaign;

use anyhow::Context;
use clap::Parser;
use cli::{Cli, Command, FlyArgs, SimArgs};
use sim_host::aircraft::Aircraft;
use sim_host::analysis::doublet::DoubletConfig;
use sim_host::commands::{self, render, Format};
use sim_host::report::to_json;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

fn main() -> ExitCode {
    match run() {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}

fn run() -> anyhow::Result<ExitCode> {
    let cli = Cli::parse();
    let aircraft = Aircraft::load(cli.aircraft.as_deref())?;
    match cli.command {
        None => default_run(&aircraft),
        Some(Command::Trim { out }) => {
            let r = commands::trim::trim_report(&aircraft);
            if out.json {
                emit(&to_json(&r.trims)?)?;
            } else {
                emit(&render(&r.tables, out.format()))?;
            }
            let failed = r.failures();
            for (name, res) in &failed {
                eprintln!("trim `{name}` did not converge: residual {res:.3e}");
            }
            Ok(if failed.is_empty() {
                ExitCode::SUCCESS
            } else {
                ExitCode::FAILURE
            })
        }
        Some(Command::Linearize { trim, out }) => {
            let r = commands::linearize::linearize_report(&aircraft, &trim)?;
            if out.json {
                emit(&to_json(&r)?)?;
            } else {
                emit(&render(&r.tables, out.format()))?;
            }
            Ok(ExitCode::SUCCESS)
        }
        Some(Command::Doublet {
            out,
            amplitude_deg,
            half_period_s,
            duration_s,
            dt_s,
            fmt,
        }) => {
            let cfg = DoubletConfig {
                amplitude_rad: amplitude_deg.to_radians(),
                half_period_s,
                duration_s,
                dt_s,
                ..DoubletConfig::default()
            };
            anyhow::ensure!(
                dt_s > 0.0 && duration_s > 0.0 && half_period_s > 0.0 && amplitude_deg.is_finite(),
                "doublet: --dt-s, --duration-s and --half-period-s must be positive, --amplitude-deg finite"
            );
            let r = commands::doublet::doublet_report(&aircraft, &cfg, Some(&out))?;
            if fmt.json {
                emit(&to_json(&r)?)?;
            } else {
                emit(&render(&r.tables, fmt.format()))?;
                for f in &r.files {
                    emit(&format!("wrote {}\n", f.display()))?;
                }
            }
            Ok(ExitCode::SUCCESS)
        }
        Some(Command::Scenario {
            name,
            gains,
            noise,
            seed,
            out,
            results,
            fmt,
        }) => {
            let opts = commands::scenario::ScenarioOptions {
                gains: gains.unwrap_or_else(|| {
                    commands::scenario::gain_set_names()
                        .iter()
                        .map(|s| s.to_string())
                        .collect()
                }),
                noise_sigma: noise,
                seed,
                progress: true,
            };
            let r = commands::scenario::scenario_report(&aircraft, &name, &opts, Some(&out))?;
            if let Some(path) = &results {
                let cmdline = std::env::args().skip(1).collect::<Vec<_>>().join(" ");
                let md = commands::scenario::results_markdown(
                    &r,
                    &format!("sim-host {cmdline}"),
                    &aircraft,
                );
                // The missions section belongs to `sim-host navigation`: kept as it is.
                let old = std::fs::read_to_string(path).unwrap_or_default();
                let md = sim_host::report::carry_section(&old, &md, commands::navigation::SECTION);
                // So does the laws section, `sim-host laws`'s.
                let md = sim_host::report::carry_section(&old, &md, commands::laws::SECTION);
                if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
                    std::fs::create_dir_all(dir)
                        .with_context(|| format!("cannot create `{}`", dir.display()))?;
                }
                std::fs::write(path, md)
                    .with_context(|| format!("cannot write `{}`", path.display()))?;
            }
            if fmt.json {
                emit(&to_json(&r)?)?;
            } else {
                emit(&render(&r.tables, fmt.format()))?;
                for f in r.files.iter().chain(results.iter()) {
                    emit(&format!("wrote {}\n", f.display()))?;
                }
            }
            Ok(ExitCode::SUCCESS)
        }
        Some(Command::Design { out, write_gains }) => {
            if let Some(path) = &write_gains {
                let g = sim_host::analysis::design::computed_gain_set(&aircraft)?;
                let text = toml::to_string(&g).context("encoding the gain set")?;
                std::fs::write(path, text)
                    .with_context(|| format!("cannot write `{}`", path.display()))?;
            }
            if out.markdown {
                emit(&commands::design::design_markdown(&aircraft)?)?;
            } else {
                let r = commands::design::design_report(&aircraft)?;
                if out.json {
                    emit(&to_json(&r)?)?;
                } else {
                    emit(&render(&r.tables, out.format()))?;
                }
            }
            Ok(ExitCode::SUCCESS)
        }
        Some(Command::Fly(args)) => fly_command(&aircraft, args),
        Some(Command::Sim(args)) => sim_command(&aircraft, args),
        Some(Command::Campaign(c)) => {
            cli_campaign::campaign_command(&aircraft, cli.aircraft.as_deref(), c, emit)
        }
        Some(Command::Laws { results, seeds }) => {
            let seeds_arg = seeds
                .iter()
                .map(u64::to_string)
                .collect::<Vec<_>>()
                .join(",");
            let command = match &results {
                Some(p) => format!(
                    "cargo run --release -p sim-host -- laws --seeds {seeds_arg} --results {}",
                    p.display()
                ),
                None => format!("cargo run --release -p sim-host -- laws --seeds {seeds_arg}"),
            };
            let md = commands::laws::laws_markdown(&aircraft, &command, &seeds)?;
            match results {
                Some(path) => {
                    let old = std::fs::read_to_string(&path).unwrap_or_default();
                    let doc = sim_host::report::splice_section(&old, commands::laws::SECTION, &md);
                    std::fs::write(&path, doc)
                        .with_context(|| format!("cannot write `{}`", path.display()))?;
                    emit(&format!("wrote {}\n", path.display()))?;
                }
                None => emit(&md)?,
            }
            Ok(ExitCode::SUCCESS)
        }
        Some(Command::Navigation {
            out,
            img,
            results,
            link,
            mcu,
        }) => {
            anyhow::ensure!(
                matches!(
                    link,
                    commands::fly::LinkKind::Inproc | commands::fly::LinkKind::Qemu
                ),
                "navigation --link {}: inproc or qemu",
                link.name()
            );
            let existing = std::fs::read_to_string(&out).ok();
            let on_qemu = if link == commands::fly::LinkKind::Qemu {
                " --link qemu"
            } else {
                ""
            };
            let command = format!(
                "cargo run --release -p sim-host -- navigation --out {} --img {} --results {}{on_qemu}",
                out.display(),
                img.display(),
                results.display()
            );
            let opts = commands::fly::FlyOptions {
                link,
                qemu: mcu.config(),
                bind: "127.0.0.1:0".into(),
                ..Default::default()
            };
            let docs = commands::navigation::navigation_markdown(
                &aircraft,
                &command,
                &img,
                existing.as_deref(),
                &opts,
            )?;
            std::fs::write(&out, docs.navigation)
                .with_context(|| format!("cannot write `{}`", out.display()))?;
            emit(&format!("wrote {}\n", out.display()))?;
            let old = std::fs::read_to_string(&results).unwrap_or_default();
            let md = sim_host::report::splice_section(
                &old,
                commands::navigation::SECTION,
                &docs.results_section,
            );
            std::fs::write(&results, md)
                .with_context(|| format!("cannot write `{}`", results.display()))?;
            emit(&format!("wrote {}\n", results.display()))?;
            Ok(ExitCode::SUCCESS)
        }
        Some(Command::Params { out }) => {
            let registry = firmware::app::REGISTRY;
            if out.json {
                emit(&format!(
                    "{}\n",
                    serde_json::to_string_pretty(&commands::params::metadata_json(registry))?
                ))?;
            } else if out.markdown {
                emit(&commands::params::markdown(registry))?;
            } else {
                emit(&render(&commands::params::tables(registry), Format::Text))?;
            }
            Ok(ExitCode::SUCCESS)
        }
        Some(Command::Validation { out, out_dir }) => {
            let md = commands::validation::validation_markdown(&aircraft, Some(&out_dir))?;
            if let Some(dir) = out.parent().filter(|d| !d.as_os_str().is_empty()) {
                std::fs::create_dir_all(dir)
                    .with_context(|| format!("cannot create `{}`", dir.display()))?;
            }
            std::fs::write(&out, md)
                .with_context(|| format!("cannot write `{}`", out.display()))?;
            emit(&format!("wrote {}\n", out.display()))?;
            Ok(ExitCode::SUCCESS)
        }
    }
}

/// Writes to standard output; a closed pipe (`sim-host trim | head`) ends quietly.
fn emit(text: &str) -> anyhow::Result<()> {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    let text = if text.ends_with('\n') {
        text.to_string()
    } else {
        format!("{text}\n")
    };
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => std::process::exit(0),
        other => Ok(other?),
    }
}

/// The flight configuration of `--mission`: the built-in default mission or a mission file.
fn mission_config(
    aircraft: &Aircraft,
    which: &Path,
) -> anyhow::Result<sim_host::flight::FlightConfig> {
    use sim_host::flight::missions::{default_mission, other_runway_missions, runway_mission};
    let home = sim_host::plant::ModelParams::new(aircraft).home;
    if which == Path::new("default") {
        return Ok(runway_mission(default_mission(home)));
    }
    // `runway-120` and `runway-250`: the built-in missions on other runways, standing on them.
    if let Some(m) = other_runway_missions(home)
        .into_iter()
        .find(|m| which == Path::new(&m.name.replace(' ', "-")))
    {
        return Ok(sim_host::flight::FlightConfig {
            runway_heading: Some(m.runway_rad),
            ..runway_mission(m.items)
        });
    }
    let file = sim_host::mission_file::read_mission_file(which)?;
    anyhow::ensure!(
        !file.mission.is_empty(),
        "`{}`: the mission has no items",
        which.display()
    );
    let mut cfg = runway_mission(file.mission);
    cfg.script.fence = file.fence;
    Ok(cfg)
}

fn fly_command(aircraft: &Aircraft, a: FlyArgs) -> anyhow::Result<ExitCode> {
    use sim_host::flight::FlightConfig;
    let base = match &a.mission {
        Some(m) => mission_config(aircraft, m)?,
        None => FlightConfig::default(),
    };
    let mut cfg = FlightConfig {
        wind_ned: a.env.wind,
        turbulence: a.env.turbulence,
        seed: a.env.seed,
        realtime: a.realtime,
        speed: a.speed,
        progress: true,
        dt_s: a.env.dt,
        // With --realtime, QGroundControl can watch: telemetry to 14550, as from PX4 SITL.
        ground_link: a
            .realtime
            .then(|| ("127.0.0.1:18570".into(), "127.0.0.1:14550".into())),
        // Ctrl-C ends the flight as flown so far (and QEMU with it).
        stop: Some(commands::sim::stop_on_ctrl_c()),
        ..base
    };
    cfg.faults.extend(a.env.faults.iter().copied());
    if let Some(d) = a.duration {
        cfg.duration_s = d;
    }
    cfg.script.params.extend(a.params.iter().cloned());
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
    let opts = commands::fly::FlyOptions {
        link: a.link,
        bind: a.bind,
        out: Some(a.out.clone()),
        plots: true,
        gain_set: a.gains,
        // The thesis's scripted flight flies the gains designed here; a mission flies the
        // firmware's defaults, as `sim-host navigation` and a fresh autopilot do.
        upload_gains: match (a.gains, &a.mission) {
            (None, None) => Some(sim_host::analysis::design::computed_gain_set(aircraft)?),
            _ => None,
        },
        use_truth: a.truth,
        qemu: sim_host::link::qemu::QemuConfig {
            profile: a.profile.map(|w| (w, a.out.clone())),
            ..a.mcu.config()
        },
    };
    if a.profile.is_some() && a.link != commands::fly::LinkKind::Qemu {
        anyhow::bail!("--profile profiles the MCU image: it needs --link qemu");
    }
    let r = commands::fly::fly_report(aircraft, &cfg, &opts)?;
    if let Some(p) = &r.mcu_profile {
        let path = a.out.join("profile.md");
        std::fs::write(&path, p.markdown(usize::MAX))
            .with_context(|| format!("cannot write `{}`", path.display()))?;
    }
    let compared = if a.compare_host {
        Some(commands::compare::compare_with_host(aircraft, &cfg, &opts)?)
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
            (None, None) => emit(&to_json(&r.outcome.summary)?)?,
        }
    } else {
        emit(&render(
            &commands::fly::summary_tables(&r.outcome),
            Format::Text,
        ))?;
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
        let truth_opts = commands::fly::FlyOptions {
            use_truth: true,
            out: Some(a.out.join("truth")),
            ..opts
        };
        let t = commands::fly::fly_report(aircraft, &cfg, &truth_opts)?;
        let md = commands::fly::results_markdown(
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
            .and_then(|old| {
                old.find(commands::fly::NOTES_MARKER)
                    .map(|i| old[i..].to_string())
            })
            .unwrap_or_default();
        std::fs::write(&path, md + &notes)
            .with_context(|| format!("cannot write `{}`", path.display()))?;
        emit(&format!("wrote {}", path.display()))?;
    }
    Ok(ExitCode::SUCCESS)
}

fn sim_command(aircraft: &Aircraft, a: SimArgs) -> anyhow::Result<ExitCode> {
    use sim_host::flight::FlightConfig;
    let secs = |what: &str, s: f64| {
        anyhow::ensure!(
            s.is_finite() && s > 0.0,
            "--{what} {s}: must be a positive number of seconds"
        );
        Ok(std::time::Duration::from_secs_f64(s))
    };
    let cfg = FlightConfig {
        duration_s: a.duration.unwrap_or(f64::INFINITY),
        wind_ned: a.env.wind,
        turbulence: a.env.turbulence,
        seed: a.env.seed,
        dt_s: a.env.dt,
        faults: a.env.faults.clone(),
        realtime: a.realtime,
        speed: a.speed,
        progress: true,
        runway_heading: (!a.air_start).then_some(0.0),
        link_timeout: secs("timeout", a.timeout)?,
        scripted_station: false,
        until_link_closes: true,
        stop: Some(commands::sim::stop_on_ctrl_c()),
        ..FlightConfig::default()
    };
    let opts = commands::sim::SimOptions {
        link: a.link,
        bind: a.bind,
        wait: a.wait.map(|w| secs("wait", w)).transpose()?,
        out: Some(a.out.clone()),
        plots: true,
        qemu: a.mcu.config(),
        gcs_bind: a.gcs_bind,
        gcs_remote: (a.gcs_remote != "none").then_some(a.gcs_remote),
    };
    let gps_delay = aircraft.sensors.gps.latency_s;
    let r = commands::sim::sim_report(aircraft, &cfg, &opts, |ready| {
        eprintln!("sim-host sim: {}", ready.describe());
        eprintln!(
            "sim-host sim: the simulated GPS reports {gps_delay} s late: set the autopilot's EKF_GPS_DELAY to {gps_delay}; Ctrl-C ends the flight and writes the log"
        );
    })?;
    if a.json {
        emit(&to_json(&r.outcome.summary)?)?;
    } else {
        emit(&render(
            &commands::fly::summary_tables(&r.outcome),
            Format::Text,
        ))?;
        for f in &r.files {
            emit(&format!("wrote {}", f.display()))?;
        }
    }
    Ok(ExitCode::SUCCESS)
}

/// With no subcommand: fly the scripted flight in-process and print a short summary.
fn default_run(aircraft: &Aircraft) -> anyhow::Result<ExitCode> {
    let cfg = sim_host::flight::FlightConfig {
        progress: true,
        ..mission_config(aircraft, Path::new("default"))?
    };
    let opts = commands::fly::FlyOptions {
        out: Some(PathBuf::from("out/fly")),
        ..Default::default()
    };
    emit("Flying the firmware in-process, on its own estimates: upload the default mission, arm, take off from the runway, a 600 m x 400 m rectangle, two turns around a corner, approach and landing")?;
    let r = commands::fly::fly_report(aircraft, &cfg, &opts)?;
    emit(&render(
        &commands::fly::summary_tables(&r.outcome),
        Format::Text,
    ))?;
    emit("\nfiles in out/fly (flight.csv, flight.tlog of the ground link, simlink.tlog, PNG plots, summary.json)")?;
    emit("(see `sim-host --help` for fly, trim, linearize, doublet, design and validation)")?;
    Ok(ExitCode::SUCCESS)
}
