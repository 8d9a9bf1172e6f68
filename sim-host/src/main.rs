//! `sim-host`: the Ultra Stick 25e simulator and the thesis's analysis commands.

use anyhow::Context;
use clap::{Parser, Subcommand};
use sim_host::aircraft::Aircraft;
use sim_host::analysis::doublet::DoubletConfig;
use sim_host::commands::{self, render, Format};
use sim_host::report::to_json;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "sim-host",
    version,
    about = "Ultra Stick 25e 6-DOF simulator and analysis"
)]
struct Cli {
    /// Aircraft file (TOML); the built-in Ultra Stick 25e when absent.
    #[arg(long, global = true, value_name = "FILE")]
    aircraft: Option<PathBuf>,
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Clone, Copy, clap::Args)]
struct Output {
    /// Print JSON instead of tables.
    #[arg(long, conflicts_with = "markdown")]
    json: bool,
    /// Print Markdown tables.
    #[arg(long)]
    markdown: bool,
}

impl Output {
    fn format(self) -> Format {
        if self.markdown {
            Format::Markdown
        } else {
            Format::Text
        }
    }
}

#[derive(Subcommand)]
enum Command {
    /// Trim the thesis's Table 2.3 targets and the 5 deg sideslip (Va 17 m/s, h 100 m).
    Trim {
        #[command(flatten)]
        out: Output,
    },
    /// Linearise about a trim: A/B matrices, poles, transfer functions.
    Linearize {
        /// Trim to linearise about: level, climb, turn, climbing-turn, sideslip.
        #[arg(long, default_value = "level")]
        trim: String,
        #[command(flatten)]
        out: Output,
    },
    /// Linear-versus-nonlinear elevator, aileron and rudder doublets from level trim.
    Doublet {
        /// Directory for the CSV and PNG files.
        #[arg(long, default_value = "out")]
        out: PathBuf,
        /// Doublet amplitude, deg.
        #[arg(long, default_value_t = 3.0)]
        amplitude_deg: f64,
        /// Duration of each half of the doublet, s.
        #[arg(long, default_value_t = 0.5)]
        half_period_s: f64,
        /// Length of each run, s.
        #[arg(long, default_value_t = 10.0)]
        duration_s: f64,
        /// Integration step, s.
        #[arg(long, default_value_t = 0.005)]
        dt_s: f64,
        #[command(flatten)]
        fmt: Output,
    },
    /// Closed-loop tests of thesis chapter 4 on the nonlinear plant (servos, 50 Hz autopilot,
    /// 2-sample input delay, optional sensor noise), for several gain sets.
    Scenario {
        /// Scenario name, or `all` (every scenario, without noise and with noise 1e-3).
        name: String,
        /// Gain sets, comma separated (default: every named set).
        #[arg(long, value_delimiter = ',', value_name = "SET[,SET...]")]
        gains: Option<Vec<String>>,
        /// White noise sigma on every measurement, SI units (rad, rad/s, m, m/s); with `all`
        /// the sigma of the noisy half (default 1e-3).
        #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
        noise: f64,
        /// Noise seed.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Directory for the CSV, PNG and JSON files.
        #[arg(long, default_value = "out/scenarios")]
        out: PathBuf,
        /// Also write the results document (Markdown, with the verdicts on the thesis's
        /// claims) to this file.
        #[arg(long, value_name = "FILE")]
        results: Option<PathBuf>,
        #[command(flatten)]
        fmt: Output,
    },
    /// Design the "computed" gain set by successive loop closure and predict every loop.
    Design {
        #[command(flatten)]
        out: Output,
        /// Also write the computed gain set to this TOML file (a gain file for
        /// `scenario --gains FILE.toml`).
        #[arg(long, value_name = "FILE")]
        write_gains: Option<PathBuf>,
    },
    /// Fly the firmware against the plant over the simulator link, commanded by a scripted
    /// ground station: arm, Hold, +100 m climb, four 90 deg turns, +-10 m altitude doublet.
    Fly(FlyArgs),
    /// Fly the default mission (calm air, and a 5 m/s wind with light turbulence over five
    /// seeds) and write the navigation results with ground-track plots.
    Navigation {
        /// Markdown file to write (notes below its `---` line are kept).
        #[arg(long, default_value = "docs/NAVIGATION.md")]
        out: PathBuf,
        /// Directory for the ground-track PNGs.
        #[arg(long, default_value = "docs/img")]
        img: PathBuf,
        /// Results document whose missions section is rewritten with the summary (the rest
        /// of it, `sim-host scenario all --results`'s, is kept).
        #[arg(long, default_value = "docs/RESULTS.md")]
        results: PathBuf,
    },
    /// Write the validation document (trim, poles, transfer functions, doublets).
    Validation {
        /// Markdown file to write.
        #[arg(long, default_value = "docs/VALIDATION.md")]
        out: PathBuf,
        /// Directory for the doublet CSV and PNG files.
        #[arg(long, default_value = "out")]
        out_dir: PathBuf,
    },
}

#[derive(clap::Args)]
struct FlyArgs {
    /// Simulator link: inproc, tcp, udp or pty.
    #[arg(long, default_value = "inproc")]
    link: commands::fly::LinkKind,
    /// Address the simulator listens on for tcp and udp.
    #[arg(long, default_value = "127.0.0.1:4560")]
    bind: String,
    /// Pace the simulation to the wall clock.
    #[arg(long)]
    realtime: bool,
    /// Steady wind N,E,D in m/s (the direction it blows towards).
    #[arg(long, value_parser = parse_wind, default_value = "0,0,0", allow_hyphen_values = true)]
    wind: [f64; 3],
    /// Turbulence: none, light, moderate or severe (MIL-F-8785C Dryden).
    #[arg(long, default_value = "none", value_parser = sim_host::flight::parse_turbulence)]
    turbulence: sim_host::environment::wind::Turbulence,
    /// Seed of the sensor noise and turbulence.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Simulated time, s (default: long enough for the whole script).
    #[arg(long)]
    duration: Option<f64>,
    /// Plant integration step, s.
    #[arg(long, default_value_t = 0.001)]
    dt: f64,
    /// Directory for flight.csv, flight.tlog, the PNG plots and summary.json.
    #[arg(long, default_value = "out/fly")]
    out: PathBuf,
    /// Gain set loaded before arming (SYS_GAIN_SET): 0 designed, 1 designed_t310,
    /// 2 designed_appe, 3 minnesota, 4 minnesota_appe. Without it the "computed" set
    /// (`sim-host design`) is uploaded parameter by parameter, as a ground station would;
    /// with `--mission` the firmware's defaults (the designed set) fly.
    #[arg(long)]
    gains: Option<u32>,
    /// Fly on the simulator's truth instead of the estimator (SIM_USE_TRUTH = 1).
    #[arg(long)]
    truth: bool,
    /// Also fly the same flight on truth and write this Markdown report (estimator accuracy,
    /// step figures on estimates vs on truth).
    #[arg(long, value_name = "FILE")]
    report: Option<PathBuf>,
    /// Print the summary as JSON.
    #[arg(long)]
    json: bool,
    /// Fly a mission from the runway instead of the thesis's script: a QGroundControl `.plan`
    /// or `QGC WPL 110` file (mission and geofence are uploaded), or `default` for the
    /// built-in take-off, rectangle, orbit, return and landing.
    #[arg(long, value_name = "FILE|default")]
    mission: Option<PathBuf>,
    /// Wall-clock pace with --realtime: simulated seconds per wall second.
    #[arg(long, default_value_t = 1.0)]
    speed: f64,
    /// Set an autopilot parameter before arming (PARAM_SET from the ground station), after
    /// the mission's own tuning; repeatable: `--param NAV_LND_SLP_DEG=6`.
    #[arg(long = "param", value_name = "NAME=VALUE", value_parser = parse_param)]
    params: Vec<(String, f32)>,
}

/// `NAME=VALUE` for `--param`, checked against the autopilot's parameters (name, bounds).
fn parse_param(s: &str) -> Result<(String, f32), String> {
    let (name, value) = s
        .split_once('=')
        .ok_or_else(|| format!("`{s}`: expected NAME=VALUE"))?;
    let v: f32 = value
        .trim()
        .parse()
        .map_err(|e| format!("`{s}`: value `{value}`: {e}"))?;
    let name = name.trim();
    // The autopilot's own parameter store answers, as it would to the PARAM_SET.
    let store = common::params::ParamStore::new(firmware::app::REGISTRY);
    let def = store
        .index_of(name)
        .and_then(|i| store.def(i))
        .ok_or_else(|| format!("`{s}`: the autopilot has no parameter `{name}`"))?;
    def.check(v).map_err(|e| {
        format!(
            "`{s}`: {name} refuses {v} ({e:?}; bounds {} to {} {})",
            def.min, def.max, def.unit
        )
    })?;
    Ok((name.to_string(), v))
}

fn parse_wind(s: &str) -> Result<[f64; 3], String> {
    let v: Vec<f64> = s
        .split(',')
        .map(|x| x.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|e| format!("wind `{s}`: {e} (expected N,E,D in m/s)"))?;
    match v.as_slice() {
        [n, e, d] if v.iter().all(|x| x.is_finite()) => Ok([*n, *e, *d]),
        _ => Err(format!(
            "wind `{s}`: expected three finite numbers N,E,D in m/s"
        )),
    }
}

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
        Some(Command::Navigation { out, img, results }) => {
            let existing = std::fs::read_to_string(&out).ok();
            let command = format!(
                "cargo run --release -p sim-host -- navigation --out {} --img {} --results {}",
                out.display(),
                img.display(),
                results.display()
            );
            let docs = commands::navigation::navigation_markdown(
                &aircraft,
                &command,
                &img,
                existing.as_deref(),
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
    use sim_host::flight::missions::{default_mission, runway_mission};
    let home = sim_host::plant::ModelParams::new(aircraft).home;
    if which == Path::new("default") {
        return Ok(runway_mission(default_mission(home)));
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
        wind_ned: a.wind,
        turbulence: a.turbulence,
        seed: a.seed,
        realtime: a.realtime,
        speed: a.speed,
        progress: true,
        dt_s: a.dt,
        // With --realtime, QGroundControl can watch: telemetry to 14550, as from PX4 SITL.
        ground_link: a
            .realtime
            .then(|| ("127.0.0.1:18570".into(), "127.0.0.1:14550".into())),
        ..base
    };
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
    };
    let r = commands::fly::fly_report(aircraft, &cfg, &opts)?;
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
    emit("\nfiles in out/fly (flight.csv, flight.tlog, PNG plots, summary.json)")?;
    emit("(see `sim-host --help` for fly, trim, linearize, doublet, design and validation)")?;
    Ok(ExitCode::SUCCESS)
}
