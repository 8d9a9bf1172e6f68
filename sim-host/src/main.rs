//! `sim-host`: the Ultra Stick 25e simulator and the thesis's analysis commands.

mod cli;
mod cli_campaign;

use anyhow::Context;
use clap::Parser;
use cli::{Cli, Command, SimArgs};
use sim_host::aircraft::Aircraft;
use sim_host::analysis::doublet::DoubletConfig;
use sim_host::commands::{self, render, Format};
use sim_host::report::to_json;
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
        None => {
            commands::fly::command::default_flight(&aircraft, emit)?;
            Ok(ExitCode::SUCCESS)
        }
        Some(Command::Trim { speed, out }) => {
            let r = commands::trim::trim_report_at(&aircraft, speed.or_cruise(&aircraft));
            if out.json {
                emit(&to_json(&r.trims)?)?;
            } else {
                emit(&render(&r.tables, out.format()))?;
            }
            let failed = r.failures();
            for (name, res) in &failed {
                eprintln!(
                    "trim `{name}` did not converge at {} m/s: residual {res:.3e} (the aircraft cannot hold that condition there)",
                    speed.or_cruise(&aircraft)
                );
            }
            Ok(if failed.is_empty() {
                ExitCode::SUCCESS
            } else {
                ExitCode::FAILURE
            })
        }
        Some(Command::Identify {
            file,
            airspeed,
            window,
            out,
        }) => {
            let r = commands::identify::identify_log(&file, &aircraft, airspeed, window)?;
            if out.json {
                emit(&to_json(&r)?)?;
            } else {
                emit(&render(&r.tables, out.format()))?;
            }
            let failed = r.failures();
            if failed.is_empty() {
                Ok(ExitCode::SUCCESS)
            } else {
                anyhow::bail!("{}: no model for {}", file.display(), failed.join("; "))
            }
        }
        Some(Command::Linearize { trim, speed, out }) => {
            let r = commands::linearize::linearize_report_at(
                &aircraft,
                &trim,
                speed.or_cruise(&aircraft),
            )?;
            if out.json {
                emit(&to_json(&r)?)?;
            } else {
                emit(&render(&r.tables, out.format()))?;
            }
            Ok(ExitCode::SUCCESS)
        }
        Some(Command::Doublet {
            speed,
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
            let r = commands::doublet::doublet_report_at(
                &aircraft,
                &cfg,
                speed.or_cruise(&aircraft),
                Some(&out),
            )?;
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
            speed,
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
            let r = commands::scenario::scenario_report_at(
                &aircraft,
                &name,
                &opts,
                speed.or_cruise(&aircraft),
                Some(&out),
            )?;
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
        Some(Command::Design {
            model: Some(model),
            write_params,
            out,
            ..
        }) => {
            let m = commands::design_model::read_model(&model)?;
            let r = commands::design_model::design_model_report(&m)?;
            if out.json {
                emit(&to_json(&r)?)?;
            } else {
                emit(&render(&r.tables, out.format()))?;
            }
            let failed = r.failures();
            if !failed.is_empty() {
                anyhow::bail!(
                    "{}: the design fails its margins, no gains written: {}",
                    model.display(),
                    failed.join("; ")
                );
            }
            if let Some(path) = &write_params {
                std::fs::write(path, r.params_file())
                    .with_context(|| format!("cannot write `{}`", path.display()))?;
            }
            Ok(ExitCode::SUCCESS)
        }
        Some(Command::Design {
            speed,
            out,
            write_gains,
            ..
        }) => {
            let va = speed.or_cruise(&aircraft);
            if let Some(path) = &write_gains {
                let g = sim_host::analysis::design::computed_gain_set_at(&aircraft, va)?;
                let text = toml::to_string(&g).context("encoding the gain set")?;
                std::fs::write(path, text)
                    .with_context(|| format!("cannot write `{}`", path.display()))?;
            }
            if out.markdown {
                emit(&commands::design::design_markdown_at(&aircraft, va)?)?;
            } else {
                let r = commands::design::design_report_at(&aircraft, va)?;
                if out.json {
                    emit(&to_json(&r)?)?;
                } else {
                    emit(&render(&r.tables, out.format()))?;
                }
            }
            Ok(ExitCode::SUCCESS)
        }
        Some(Command::Fly(args)) => {
            let aircraft = args.env.fitted(&aircraft);
            commands::fly::command::fly_command(&aircraft, args.command(), emit)?;
            Ok(ExitCode::SUCCESS)
        }
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
        Some(Command::Log { file, out, json }) => {
            let r = commands::log::log_report(&file, &out)?;
            // What the reader skipped, or where a cut log ends: the summary is of the rest.
            for w in &r.summary.warnings {
                eprintln!("warning: {}: {w}", file.display());
            }
            print_summary(
                json,
                &r.summary,
                &commands::log::summary_tables(&r.summary),
                &r.files,
            )?;
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

fn sim_command(aircraft: &Aircraft, a: SimArgs) -> anyhow::Result<ExitCode> {
    use sim_host::flight::FlightConfig;
    let fitted = a.env.fitted(aircraft);
    let aircraft = &fitted;
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
    print_summary(
        a.json,
        &r.outcome.summary,
        &commands::fly::summary_tables(&r.outcome),
        &r.files,
    )?;
    Ok(ExitCode::SUCCESS)
}

/// Prints a command's summary, as JSON or as its tables followed by the files it wrote.
fn print_summary(
    json: bool,
    summary: &impl serde::Serialize,
    tables: &[sim_host::report::Table],
    files: &[std::path::PathBuf],
) -> anyhow::Result<()> {
    if json {
        return emit(&to_json(summary)?);
    }
    emit(&render(tables, Format::Text))?;
    for f in files {
        emit(&format!("wrote {}", f.display()))?;
    }
    Ok(())
}
