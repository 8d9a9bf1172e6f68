//! The command line: the subcommands, their options and the parsers of option values.

use clap::{Parser, Subcommand};
use sim_host::commands::{self, Format};
use std::path::PathBuf;

#[derive(Parser)]
#[command(
    name = "sim-host",
    version,
    about = "Ultra Stick 25e 6-DOF simulator and analysis"
)]
pub(crate) struct Cli {
    /// Aircraft file (TOML); the built-in Ultra Stick 25e when absent.
    #[arg(long, global = true, value_name = "FILE")]
    pub(crate) aircraft: Option<PathBuf>,
    #[command(subcommand)]
    pub(crate) command: Option<Command>,
}

#[derive(Clone, Copy, clap::Args)]
pub(crate) struct Output {
    /// Print JSON instead of tables.
    #[arg(long, conflicts_with = "markdown")]
    pub(crate) json: bool,
    /// Print Markdown tables.
    #[arg(long)]
    pub(crate) markdown: bool,
}

impl Output {
    /// How the tables print: Markdown when asked for, aligned text otherwise (JSON is not a
    /// table format: the caller prints it instead).
    pub(crate) fn format(self) -> Format {
        if self.markdown {
            Format::Markdown
        } else {
            Format::Text
        }
    }
}

#[derive(Clone, Copy, clap::Args)]
pub(crate) struct Airspeed {
    /// Trim airspeed, m/s (default: the aircraft file's `[performance] cruise_airspeed_mps`,
    /// else the thesis's 17 m/s).
    #[arg(long, value_name = "M/S", value_parser = positive_airspeed, allow_negative_numbers = true)]
    pub(crate) airspeed: Option<f64>,
}

impl Airspeed {
    /// The airspeed asked for, or the aircraft's cruise airspeed.
    pub(crate) fn or_cruise(self, aircraft: &sim_host::aircraft::Aircraft) -> f64 {
        self.airspeed
            .unwrap_or_else(|| aircraft.cruise_airspeed_mps())
    }
}

/// A finite, positive airspeed in m/s.
fn positive_airspeed(s: &str) -> Result<f64, String> {
    let v: f64 = s
        .parse()
        .map_err(|e| format!("`{s}` is not a number: {e}"))?;
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(format!(
            "`{s}`: an airspeed must be a positive number of m/s"
        ))
    }
}

#[derive(Subcommand)]
pub(crate) enum Command {
    /// Trim the thesis's Table 2.3 targets and the 5 deg sideslip (h 100 m) at the trim
    /// airspeed.
    Trim {
        #[command(flatten)]
        speed: Airspeed,
        #[command(flatten)]
        out: Output,
    },
    /// Linearise about a trim: A/B matrices, poles, transfer functions.
    Linearize {
        /// Trim to linearise about: level, climb, turn, climbing-turn, sideslip.
        #[arg(long, default_value = "level")]
        trim: String,
        #[command(flatten)]
        speed: Airspeed,
        #[command(flatten)]
        out: Output,
    },
    /// Linear-versus-nonlinear elevator, aileron and rudder doublets from the level trim at
    /// the trim airspeed.
    Doublet {
        #[command(flatten)]
        speed: Airspeed,
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
    /// 2-sample input delay, optional sensor noise), for several gain sets, from the level trim
    /// at the trim airspeed: the altitude tests hold that airspeed, the airspeed step is +1 m/s
    /// from it, and the computed set is designed there.
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
        #[command(flatten)]
        speed: Airspeed,
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
        speed: Airspeed,
        #[command(flatten)]
        out: Output,
        /// Also write the computed gain set to this TOML file (a gain file for
        /// `scenario --gains FILE.toml`).
        #[arg(long, value_name = "FILE")]
        write_gains: Option<PathBuf>,
        /// Design on the reduced models of a `sim-host identify --json` report instead of the
        /// aircraft file, and check every loop's margins (6 dB; 45 deg for the attitude
        /// loops, 30 deg for the outer ones).
        #[arg(long, value_name = "MODEL.json", conflicts_with = "write_gains")]
        model: Option<PathBuf>,
        /// With --model: write the gains as a QGroundControl parameter file (`.params`), only
        /// when every loop meets its margins.
        #[arg(long, value_name = "FILE.params", requires = "model")]
        write_params: Option<PathBuf>,
    },
    /// Fly the firmware against the plant over the simulator link, commanded by a scripted
    /// ground station: arm, Hold, +100 m climb, four 90 deg turns, +-10 m altitude doublet.
    Fly(FlyArgs),
    /// The simulator alone, as PX4's simulators are: the plant waits on the runway (or in
    /// the air) for any autopilot that speaks PX4's simulator interface, flies it in
    /// lock-step until the autopilot closes the link, --duration or Ctrl-C, and writes the
    /// log, .tlog, plots and summary. No scripted station: fly it from QGroundControl, MAVSDK
    /// or pymavlink on the autopilot's own ground link.
    Sim(SimArgs),
    /// Fly the longitudinal chapter-4 scenarios and the default mission with both
    /// longitudinal laws (LON_LAW 0 and 1) and write the comparison into the results document.
    Laws {
        /// Results document whose laws section is rewritten (the rest of it is kept); without
        /// it the section is printed.
        #[arg(long)]
        results: Option<PathBuf>,
        /// Seeds of the windy mission flights (wind -3,-4,0 m/s, light turbulence).
        #[arg(long, value_delimiter = ',', default_value = "1,2")]
        seeds: Vec<u64>,
    },
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
        /// Who flies: inproc (the host build in this process) or qemu (the MCU image, about
        /// five minutes a flight).
        #[arg(long, default_value = "inproc")]
        link: commands::fly::LinkKind,
        #[command(flatten)]
        mcu: McuArgs,
    },
    /// The autopilot's parameters: tables, the Markdown of docs/PARAMETERS.md (--markdown),
    /// or the parameter metadata file QGroundControl reads (--json).
    Params {
        #[command(flatten)]
        out: Output,
    },
    /// A Monte Carlo campaign: N flights of a mission, each with its own draw of the
    /// aircraft's model, its sensors, the wind and the runway, judged by named criteria;
    /// `--shard I/N` flies a part of it, `merge` joins the parts.
    Campaign(crate::cli_campaign::CampaignCli),
    /// Read a flight log (ULog, the autopilot's or PX4's): print its summary (duration,
    /// system, modes flown, attitude, altitude, airspeed, distance, battery, dropouts, texts,
    /// parameters, topics and their rates) and draw the figures a simulated flight draws.
    Log {
        /// The log file (`.ulg`).
        file: PathBuf,
        /// Directory for the PNG figures.
        #[arg(long, default_value = "out/log")]
        out: PathBuf,
        /// Print the summary as JSON.
        #[arg(long)]
        json: bool,
    },
    /// Fit the design's reduced models (roll, sideslip, pitch, airspeed; the course and
    /// altitude kinematics) from a simulator link's `.tlog` (`simlink.tlog` of `fly` and
    /// `sim`), a ground station's `.tlog` (`flight.tlog`) with the messages at 50 Hz, or the
    /// autopilot's own flight log at `SDLOG_PROFILE 9`, with each fit's quality
    /// and excitation, beside the aircraft file's
    /// linearisation at the same airspeed. An axis the flight did not excite is an error
    /// naming it (the sideslip's is reported, not an error: without it a design keeps the
    /// base set's sideslip gains).
    Identify {
        /// The log: a `.tlog` of the simulator link, with its truth frames; a ground station's
        /// `.tlog` with ATTITUDE, SERVO_OUTPUT_RAW, GLOBAL_POSITION_INT and VFR_HUD at 50 Hz
        /// (`fly --message-rate`); or the autopilot's flight log (`.ulg`) written with
        /// `SDLOG_PROFILE 9` (100 Hz).
        file: PathBuf,
        /// Airspeed the coefficients are given at, m/s (default: the flown samples' mean).
        #[arg(long, value_name = "M/S", value_parser = positive_airspeed, allow_negative_numbers = true)]
        airspeed: Option<f64>,
        /// Only the samples between these times of the log, s (the simulated time of `sim-host
        /// fly`, as its texts and commands are timed): `--window 19:67`.
        #[arg(long, value_name = "FROM:TO", value_parser = parse_window)]
        window: Option<(f64, f64)>,
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

/// The air and the sensors of a flight, shared by `fly` and `sim`.
#[derive(clap::Args)]
pub(crate) struct EnvArgs {
    /// Steady wind N,E,D in m/s (the direction it blows towards).
    #[arg(long, value_parser = parse_wind, default_value = "0,0,0", allow_hyphen_values = true)]
    pub(crate) wind: [f64; 3],
    /// Turbulence: none, light, moderate or severe (MIL-F-8785C Dryden).
    #[arg(long, default_value = "none", value_parser = sim_host::flight::parse_turbulence)]
    pub(crate) turbulence: sim_host::environment::wind::Turbulence,
    /// Seed of the sensor noise and turbulence.
    #[arg(long, default_value_t = 1)]
    pub(crate) seed: u64,
    /// Plant integration step, s.
    #[arg(long, default_value_t = 0.001)]
    pub(crate) dt: f64,
    /// A sensor fault over a window of simulated time, KIND:FROM-TO in s with KIND gps,
    /// pitot, mag, baro, or (with a rangefinder) range-stuck, range-short or range-drop;
    /// repeatable: `--fault gps:60-90`.
    #[arg(long = "fault", value_name = "KIND:FROM-TO", value_parser = sim_host::flight::parse_fault)]
    pub(crate) faults: Vec<sim_host::flight::FaultWindow>,
    /// Fit the aircraft with a downward rangefinder (a LIDAR-Lite v3: 0.1-40 m, 20 Hz) when
    /// its file has none, sent as DISTANCE_SENSOR.
    #[arg(long)]
    pub(crate) rangefinder: bool,
}

impl EnvArgs {
    /// The aircraft as flown: with the default rangefinder if `--rangefinder` asks for one.
    pub(crate) fn fitted(
        &self,
        aircraft: &sim_host::aircraft::Aircraft,
    ) -> sim_host::aircraft::Aircraft {
        let mut a = aircraft.clone();
        if self.rangefinder && a.sensors.rangefinder.is_none() {
            a.sensors.rangefinder = Some(sim_host::sensors::RangefinderConfig::default());
        }
        a
    }
}

/// The MCU image and its emulator, for `--link qemu`.
#[derive(clap::Args)]
pub(crate) struct McuArgs {
    /// The MCU image (ELF) for --link qemu; built by
    /// `cargo build --profile mcu -p firmware --target thumbv7em-none-eabihf`.
    #[arg(long, value_name = "PATH", default_value_os_t = sim_host::link::qemu::default_elf())]
    pub(crate) elf: PathBuf,
    /// The QEMU that runs it (a name on the PATH or a path).
    #[arg(long, value_name = "PROGRAM", default_value = sim_host::link::qemu::DEFAULT_QEMU)]
    pub(crate) qemu: PathBuf,
    /// File that keeps the image's saved parameters and missions across runs (its two flash
    /// sectors; created when missing). Without it the image starts from defaults every run.
    #[arg(long, value_name = "PATH")]
    pub(crate) mcu_storage: Option<PathBuf>,
}

impl McuArgs {
    pub(crate) fn config(&self) -> sim_host::link::qemu::QemuConfig {
        sim_host::link::qemu::QemuConfig {
            program: self.qemu.clone(),
            elf: self.elf.clone(),
            storage: self.mcu_storage.clone(),
            ..Default::default()
        }
    }
}

#[derive(clap::Args)]
pub(crate) struct FlyArgs {
    /// Simulator link: inproc, tcp, udp, pty (the host build, in this process) or qemu (the
    /// MCU image on QEMU's emulated STM32F405).
    #[arg(long, default_value = "inproc")]
    pub(crate) link: commands::fly::LinkKind,
    /// Address the simulator listens on for tcp and udp.
    #[arg(long, default_value = "127.0.0.1:4560")]
    pub(crate) bind: String,
    /// Pace the simulation to the wall clock.
    #[arg(long)]
    pub(crate) realtime: bool,
    #[command(flatten)]
    pub(crate) env: EnvArgs,
    #[command(flatten)]
    pub(crate) mcu: McuArgs,
    /// Simulated time, s (default: long enough for the whole script).
    #[arg(long)]
    pub(crate) duration: Option<f64>,
    /// Directory for flight.csv, flight.tlog (the ground link as the scripted station saw
    /// it), simlink.tlog, the PNG plots and summary.json.
    #[arg(long, default_value = "out/fly")]
    pub(crate) out: PathBuf,
    /// Gain set loaded before arming (SYS_GAIN_SET): 0 flight (the defaults), 1 designed,
    /// 2 designed_t310, 3 designed_appe, 4 minnesota, 5 minnesota_appe. Without it the
    /// "computed" set (`sim-host design`) is uploaded parameter by parameter, as a ground
    /// station would; with `--mission` the firmware's defaults (the flight set) fly.
    #[arg(long)]
    pub(crate) gains: Option<u32>,
    /// Fly on the simulator's truth instead of the estimator (SIM_USE_TRUTH = 1).
    #[arg(long)]
    pub(crate) truth: bool,
    /// Also fly the same flight on truth and write this Markdown report (estimator accuracy,
    /// step figures on estimates vs on truth).
    #[arg(long, value_name = "FILE")]
    pub(crate) report: Option<PathBuf>,
    /// Also fly the same flight with the host build in this process, and compare the
    /// autopilots' answers (HIL_ACTUATOR_CONTROLS) frame by frame, and the pace of both.
    #[arg(long)]
    pub(crate) compare_host: bool,
    /// With --link qemu: profile the MCU image by function over PERIODS whole 20 ms control
    /// periods (10 by default) from SECONDS of simulated time, from QEMU's instruction trace;
    /// printed, written to OUT/profile.md and given as `mcu.profile` with --json.
    #[arg(long, value_name = "SECONDS[:PERIODS]", value_parser = sim_host::link::profile::ProfileWindow::parse)]
    pub(crate) profile: Option<sim_host::link::profile::ProfileWindow>,
    /// Print the summary as JSON.
    #[arg(long)]
    pub(crate) json: bool,
    /// Fly Stabilized from the hand launch as a pilot flies for identification, instead of the
    /// thesis's script: the simulator's radio (RC_CHANNELS) flies 3-2-1-1 doublets in roll,
    /// then in pitch, three times each, then throttle steps, then doublets in yaw, at the
    /// aircraft's level-trim throttle; `sim-host identify OUT/simlink.tlog` fits the models
    /// (docs/AUTOTUNE.md).
    #[arg(long, conflicts_with = "mission")]
    pub(crate) stick_doublets: bool,
    /// Autotune in the air first, as QGroundControl's autotune button does
    /// (MAV_CMD_DO_AUTOTUNE_ENABLE), from the firmware's default gains, then fly the thesis's
    /// script on the gains it designed; with --mission, take off from the runway (Takeoff),
    /// autotune in Hold, then fly the mission to its landing. Each beside the same flown on
    /// the default gains (docs/AUTOTUNE.md).
    #[arg(long, conflicts_with_all = ["stick_doublets", "gains"])]
    pub(crate) autotune: bool,
    /// Fly a mission from the runway instead of the thesis's script: a QGroundControl `.plan`
    /// or `QGC WPL 110` file (mission and geofence are uploaded), or `default` for the
    /// built-in take-off, rectangle, orbit, return and landing, or `runway-120` / `runway-250`
    /// for the built-in missions from other runways (docs/NAVIGATION.md).
    #[arg(long, value_name = "FILE|default")]
    pub(crate) mission: Option<PathBuf>,
    /// Wall-clock pace with --realtime: simulated seconds per wall second.
    #[arg(long, default_value_t = 1.0)]
    pub(crate) speed: f64,
    /// Set an autopilot parameter before arming (PARAM_SET from the ground station);
    /// repeatable: `--param NAV_LND_SLP_DEG=6`.
    #[arg(long = "param", value_name = "NAME=VALUE", value_parser = parse_param)]
    pub(crate) params: Vec<(String, f32)>,
    /// Set the parameters of a QGroundControl parameter file (`.params`: tab-separated
    /// vehicle, component, name, value, type; `#` comments) before arming, in its order, as
    /// QGroundControl's "Load from file" does; `--param` values follow them.
    #[arg(long = "params", value_name = "FILE.params", value_parser = parse_params_file)]
    pub(crate) params_file: Option<ParamsFile>,
    /// Ask the autopilot for a message at a rate before arming (MAV_CMD_SET_MESSAGE_INTERVAL,
    /// as QGroundControl's MAVLink Inspector or MAVProxy sends it); repeatable:
    /// `--message-rate SERVO_OUTPUT_RAW=50`. The ground link's `.tlog` (OUT/flight.tlog)
    /// then carries it (`sim-host identify` reads ATTITUDE, SERVO_OUTPUT_RAW,
    /// GLOBAL_POSITION_INT and VFR_HUD at 50 Hz; docs/AUTOTUNE.md).
    #[arg(long = "message-rate", value_name = "MESSAGE=HZ", value_parser = parse_message_rate)]
    pub(crate) message_rates: Vec<(u32, f32)>,
}

/// A message of the common dialect and a rate: `SERVO_OUTPUT_RAW=50`.
fn parse_message_rate(s: &str) -> Result<(u32, f32), String> {
    use mavlink::Message;
    let (name, hz) = s
        .split_once('=')
        .ok_or_else(|| format!("`{s}`: expected MESSAGE=HZ"))?;
    let id = mavlink::dialects::common::MavMessage::message_id_from_name(name.trim()).ok_or_else(
        || {
            format!(
                "`{s}`: no message `{}` in MAVLink's common set",
                name.trim()
            )
        },
    )?;
    let hz: f32 = hz
        .trim()
        .parse()
        .map_err(|e| format!("`{s}`: rate `{hz}`: {e}"))?;
    if !(hz.is_finite() && hz > 0.0 && hz <= 1000.0) {
        return Err(format!(
            "`{s}`: rate {hz} Hz: expected over 0 and at most 1000 Hz"
        ));
    }
    Ok((id, hz))
}

/// The parameters of a `.params` file, in its order.
#[derive(Clone, Debug)]
pub(crate) struct ParamsFile(Vec<(String, f32)>);

/// Reads a QGroundControl parameter file, each value checked as [`parse_param`] checks one:
/// an error names the file, the line, the parameter and the value.
fn parse_params_file(path: &str) -> Result<ParamsFile, String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{path}: {e}"))?;
    let mut out = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let fields: Vec<&str> = line.split('\t').collect();
        let (Some(name), Some(value)) = (fields.get(2), fields.get(3)) else {
            return Err(format!(
                "{path}:{}: `{line}`: expected vehicle, component, name, value and type, tab-separated",
                n + 1
            ));
        };
        let p = parse_param(&format!("{name}={value}"))
            .map_err(|e| format!("{path}:{}: {e}", n + 1))?;
        out.push(p);
    }
    Ok(ParamsFile(out))
}

impl FlyArgs {
    /// The command these options ask for.
    pub(crate) fn command(self) -> commands::fly::command::FlyCommand {
        commands::fly::command::FlyCommand {
            link: self.link,
            bind: self.bind,
            realtime: self.realtime,
            speed: self.speed,
            wind_ned: self.env.wind,
            turbulence: self.env.turbulence,
            seed: self.env.seed,
            dt_s: self.env.dt,
            faults: self.env.faults,
            qemu: self.mcu.config(),
            duration_s: self.duration,
            out: self.out,
            gains: self.gains,
            truth: self.truth,
            report: self.report,
            compare_host: self.compare_host,
            profile: self.profile,
            json: self.json,
            mission: self.mission,
            stick_doublets: self.stick_doublets,
            autotune: self.autotune,
            message_rates: self.message_rates,
            params: self
                .params_file
                .map(|f| f.0)
                .unwrap_or_default()
                .into_iter()
                .chain(self.params)
                .collect(),
        }
    }
}

#[derive(clap::Args)]
pub(crate) struct SimArgs {
    /// Simulator link: tcp (the autopilot connects to --bind, PX4's convention), udp (the
    /// autopilot sends first), pty (a virtual serial line; its path is printed) or qemu (this
    /// command boots the MCU image in QEMU on it).
    #[arg(long, default_value = "tcp")]
    pub(crate) link: commands::fly::LinkKind,
    /// Address the simulator listens on for tcp and udp.
    #[arg(long, default_value = "127.0.0.1:4560")]
    pub(crate) bind: String,
    /// Start trimmed in level flight 100 m above home at the aircraft's cruise airspeed (a
    /// hand launch) instead of at rest on the runway at home, heading north.
    #[arg(long)]
    pub(crate) air_start: bool,
    /// Pace the simulation to the wall clock (for a pilot in QGroundControl).
    #[arg(long)]
    pub(crate) realtime: bool,
    /// Wall-clock pace with --realtime: simulated seconds per wall second.
    #[arg(long, default_value_t = 1.0)]
    pub(crate) speed: f64,
    /// Simulated time after which the simulator stops, s (default: until the autopilot
    /// closes the link, or Ctrl-C).
    #[arg(long)]
    pub(crate) duration: Option<f64>,
    /// How long to wait for an autopilot to connect, s (default: until one does, or Ctrl-C).
    #[arg(long)]
    pub(crate) wait: Option<f64>,
    /// How long the autopilot may take to answer a sensor frame, s.
    #[arg(long, default_value_t = 5.0)]
    pub(crate) timeout: f64,
    #[command(flatten)]
    pub(crate) env: EnvArgs,
    #[command(flatten)]
    pub(crate) mcu: McuArgs,
    /// With --link qemu: the UDP address of the MCU image's ground link (PX4 SITL's 18570),
    /// where ground stations send.
    #[arg(long, default_value = "127.0.0.1:18570")]
    pub(crate) gcs_bind: String,
    /// With --link qemu: where its telemetry goes besides every station that speaks
    /// (QGroundControl listens on 14550); `none` for no fixed remote.
    #[arg(long, default_value = "127.0.0.1:14550")]
    pub(crate) gcs_remote: String,
    /// Directory for flight.csv, simlink.tlog (the simulator link; the ground link is the
    /// stations' own to record), the PNG plots and summary.json.
    #[arg(long, default_value = "out/sim")]
    pub(crate) out: PathBuf,
    /// Print the summary as JSON.
    #[arg(long)]
    pub(crate) json: bool,
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
            def.min,
            def.max,
            def.unit.get()
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

/// `FROM:TO`, seconds, `FROM < TO`.
fn parse_window(s: &str) -> Result<(f64, f64), String> {
    let (a, b) = s
        .split_once(':')
        .ok_or_else(|| format!("`{s}`: expected FROM:TO in seconds"))?;
    let num = |x: &str| {
        x.trim()
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| format!("`{x}` in `{s}` is not a number of seconds"))
    };
    let (from, to) = (num(a)?, num(b)?);
    if from >= to {
        return Err(format!("`{s}`: FROM must come before TO"));
    }
    Ok((from, to))
}
