//! `sim-host`: the Ultra Stick 25e simulator and the thesis's analysis commands.

use anyhow::Context;
use clap::{Parser, Subcommand};
use sim_host::aircraft::Aircraft;
use sim_host::analysis::doublet::DoubletConfig;
use sim_host::commands::{self, render, Format};
use sim_host::report::to_json;
use std::path::PathBuf;
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
                let md = commands::scenario::results_markdown(&r, &format!("sim-host {cmdline}"));
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
        Some(Command::Design { out }) => {
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

/// With no subcommand: trim level flight and fly the nonlinear doublet check.
fn default_run(aircraft: &Aircraft) -> anyhow::Result<ExitCode> {
    let trims = commands::trim::trim_report(aircraft);
    if let Some(level) = trims.tables.first() {
        emit(&level.render_text())?;
    }
    let r = commands::doublet::doublet_report(aircraft, &DoubletConfig::default(), None)?;
    emit(&format!("\n{}", render(&r.tables, Format::Text)))?;
    emit("\n(see `sim-host --help` for trim, linearize, doublet and validation)\n")?;
    Ok(ExitCode::SUCCESS)
}
