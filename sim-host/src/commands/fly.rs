//! `sim-host fly`: the firmware flies the plant over the simulator link, commanded by a
//! scripted ground station; writes the log, a `.tlog`, plots and a JSON summary.

use super::flying::{finish_report, fly_qemu, run_on, GROUND_TLOG, MCU_LOG, SIM_TLOG};
use crate::aircraft::Aircraft;
use crate::flight::config::FlightConfig;
use crate::flight::onboard::{spawn_firmware, InprocOnboard};
use crate::flight::runner::FlightOutcome;
use crate::flight::strikes::kind;
use crate::flight::summary::{BatterySummary, MissionSummary};
use crate::link::qemu::QemuConfig;
use crate::link::transport::{Inproc, PtyServer, TcpServer, UdpServer};
use crate::report::sig;
use crate::report::table::Table;
use anyhow::Context;
use firmware::app::App;
use firmware::sitl::SimEndpoint;
use std::path::PathBuf;
use std::time::Duration;

pub use super::flying::{write_flight_files, FlyReport};

/// Which transport carries the simulator link.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LinkKind {
    /// The firmware's application inside this process, through a byte pipe.
    Inproc,
    /// TCP: the simulator listens, the firmware (a thread here) connects.
    Tcp,
    /// UDP.
    Udp,
    /// A pseudo-terminal pair (a virtual serial line).
    Pty,
    /// The MCU image on QEMU's emulated STM32F405: USART1 on the simulator link, USART2 on
    /// the ground link behind the UDP bridge.
    Qemu,
}

impl std::str::FromStr for LinkKind {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "inproc" => Ok(Self::Inproc),
            "tcp" => Ok(Self::Tcp),
            "udp" => Ok(Self::Udp),
            "pty" => Ok(Self::Pty),
            "qemu" => Ok(Self::Qemu),
            _ => Err(format!(
                "link `{s}`: expected inproc, tcp, udp, pty or qemu"
            )),
        }
    }
}

impl LinkKind {
    /// The name the command line uses.
    pub fn name(self) -> &'static str {
        match self {
            Self::Inproc => "inproc",
            Self::Tcp => "tcp",
            Self::Udp => "udp",
            Self::Pty => "pty",
            Self::Qemu => "qemu",
        }
    }
}

/// Options of `sim-host fly` beyond the flight itself.
#[derive(Clone, Debug)]
pub struct FlyOptions {
    /// Transport.
    pub link: LinkKind,
    /// Address the simulator binds for TCP and UDP (port 0: any free port).
    pub bind: String,
    /// Directory for the CSV, `.tlog`, PNG and JSON files; nothing written when `None`.
    pub out: Option<PathBuf>,
    /// Write PNG plots (they take a second or two).
    pub plots: bool,
    /// Gain set (`SYS_GAIN_SET`) to load before arming.
    pub gain_set: Option<u32>,
    /// Gains uploaded parameter by parameter before arming, as a ground station would (the
    /// "computed" set lives on the host, not in the firmware's table of named sets).
    pub upload_gains: Option<common::control::gains::GainSet>,
    /// Fly on the simulator's truth (`SIM_USE_TRUTH` = 1).
    pub use_truth: bool,
    /// The MCU image and the QEMU that runs it, for [`LinkKind::Qemu`].
    pub qemu: QemuConfig,
}

impl Default for FlyOptions {
    fn default() -> Self {
        Self {
            link: LinkKind::Inproc,
            bind: "127.0.0.1:4560".into(),
            out: None,
            plots: true,
            gain_set: None,
            upload_gains: None,
            use_truth: false,
            qemu: QemuConfig::default(),
        }
    }
}

/// The flight of `cfg` with the parameters `opts` asks the station to set.
pub(crate) fn with_params(cfg: &FlightConfig, opts: &FlyOptions) -> FlightConfig {
    let mut cfg = cfg.clone();
    if let Some(g) = opts.gain_set {
        cfg.script.params.push(("SYS_GAIN_SET".into(), g as f32));
    }
    if let Some(g) = &opts.upload_gains {
        for (name, value) in g.params() {
            cfg.script.params.push((name.into(), value));
        }
    }
    if opts.use_truth {
        cfg.script.params.push(("SIM_USE_TRUTH".into(), 1.0));
    }
    cfg
}

/// Flies `cfg` over the transport of `opts`, and writes the files into `opts.out` (also when
/// the link fails during the flight: the error then says where the log is).
pub fn fly_report(
    aircraft: &Aircraft,
    cfg: &FlightConfig,
    opts: &FlyOptions,
) -> anyhow::Result<FlyReport> {
    let mut cfg = with_params(cfg, opts);
    if let Some(dir) = &opts.out {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("cannot create `{}`", dir.display()))?;
    }
    if cfg.scripted_station {
        cfg.ground_tlog = opts.out.as_ref().map(|d| d.join(GROUND_TLOG));
    }
    let tlog = opts.out.as_ref().map(|d| d.join(SIM_TLOG));
    let tlog = tlog.as_deref();
    let wait = Duration::from_secs(10);
    let silence = cfg.link_timeout.max(Duration::from_secs(2));
    let mut mcu = None;
    let mut mcu_profile = None;
    let flown = match opts.link {
        LinkKind::Inproc => run_on(
            aircraft,
            &cfg,
            Inproc::new(App::new()),
            &mut InprocOnboard,
            tlog,
        )?,
        LinkKind::Tcp => {
            let mut fw = None;
            let server = TcpServer::listen(&opts.bind, wait, |addr| {
                fw = Some(spawn_firmware(
                    SimEndpoint::Tcp(addr.to_string()),
                    App::new(),
                    wait,
                    silence,
                ));
            })
            .with_context(|| format!("tcp simulator link on {}", opts.bind))?;
            let mut fw = fw.context("the firmware thread did not start")?;
            let r = run_on(aircraft, &cfg, server, &mut fw, tlog);
            drop(fw);
            r?
        }
        LinkKind::Udp => {
            let mut server = UdpServer::bind(&opts.bind)
                .with_context(|| format!("udp simulator link on {}", opts.bind))?;
            let addr = server.local_addr()?;
            let mut fw = spawn_firmware(
                SimEndpoint::Udp(addr.to_string()),
                App::new(),
                wait,
                silence,
            );
            server
                .wait_for_peer(wait)
                .context("the firmware did not reach the udp simulator link")?;
            run_on(aircraft, &cfg, server, &mut fw, tlog)?
        }
        LinkKind::Pty => {
            let pty = PtyServer::open().context("cannot open a pty")?;
            let path = pty.slave_path().to_path_buf();
            let mut fw = spawn_firmware(SimEndpoint::Serial(path), App::new(), wait, silence);
            run_on(aircraft, &cfg, pty, &mut fw, tlog)?
        }
        LinkKind::Qemu => {
            let (flown, budget, profile) =
                fly_qemu(aircraft, &cfg, &opts.qemu, opts.out.as_deref(), tlog)?;
            mcu = budget;
            mcu_profile = profile;
            flown
        }
    };
    let mut files: Vec<PathBuf> = cfg.ground_tlog.iter().cloned().collect();
    files.extend(tlog.map(std::path::Path::to_path_buf));
    if opts.link == LinkKind::Qemu {
        files.extend(opts.out.as_ref().map(|d| d.join(MCU_LOG)));
    }
    let mut report = finish_report(flown, opts.out.as_deref(), opts.plots, files)?;
    report.mcu = mcu;
    report.mcu_profile = mcu_profile;
    Ok(report)
}

/// The short summary printed after a flight.
pub fn summary_tables(r: &FlightOutcome) -> Vec<Table> {
    let s = &r.summary;
    let mut run = Table::new("Flight", &["quantity", "value"]);
    run.row(["simulated".to_string(), format!("{:.1} s", s.sim_s)]);
    run.row(["wall clock".to_string(), format!("{:.2} s", s.wall_s)]);
    run.row([
        "real-time factor".to_string(),
        if s.real_time_factor < 10.0 {
            format!("{:.2}x", s.real_time_factor)
        } else {
            format!("{:.0}x", s.real_time_factor)
        },
    ]);
    run.row(["frames".to_string(), s.frames.to_string()]);
    run.row(["ended".to_string(), s.ended.describe().to_string()]);
    run.row([
        "armed at".to_string(),
        s.armed_at_s.map_or("never".into(), |t| format!("{t:.1} s")),
    ]);
    if let (None, Some(td)) = (&s.mission, &s.touchdown) {
        // No mission known here (`sim-host sim`): where and how the wheels met the runway.
        run.row([
            "touchdown".to_string(),
            format!(
                "at {:.1} s, {:.1} m N {:.1} m E of home, sink {:.2} m/s, {:.1} m/s over ground, {} bounce(s)",
                td.time_s, td.north_m, td.east_m, td.sink_rate_mps, td.ground_speed_mps, td.bounces
            ),
        ]);
    }
    if let Some(td) = &s.lifted_after_disarm {
        run.row([
            "lifted after the disarm".to_string(),
            format!(
                "the wind lifted the aircraft off the runway; down again at {:.1} s, {:.1} m N {:.1} m E of home (not the landing)",
                td.time_s, td.north_m, td.east_m
            ),
        ]);
    }
    run.row([
        "wind, turbulence".to_string(),
        format!(
            "({}, {}, {}) m/s NED, {}",
            s.wind_ned[0], s.wind_ned[1], s.wind_ned[2], s.turbulence
        ),
    ]);
    let mut tables = vec![run];
    for (e, when) in [
        (&s.estimator, "convergence"),
        (&s.estimator_settled, "30 s after convergence"),
    ] {
        let Some(e) = e else { continue };
        let mut t = Table::new(
            format!("Estimator error from {when} ({:.1} s) to the end", e.from_s),
            &["quantity", "RMS", "max"],
        );
        t.row([
            "roll (deg)".into(),
            sig(e.roll_rms_deg, 3),
            sig(e.roll_max_deg, 3),
        ]);
        t.row([
            "pitch (deg)".into(),
            sig(e.pitch_rms_deg, 3),
            sig(e.pitch_max_deg, 3),
        ]);
        t.row([
            "heading (deg)".into(),
            sig(e.heading_rms_deg, 3),
            sig(e.heading_max_deg, 3),
        ]);
        t.row([
            "altitude in home's datum (m)".into(),
            sig(e.alt_rms_m, 3),
            sig(e.alt_max_m, 3),
        ]);
        t.row([
            "home's altitude, set at arming (m)".into(),
            sig(e.home_alt_error_m, 3),
            "".into(),
        ]);
        t.row([
            "airspeed (m/s)".into(),
            sig(e.airspeed_rms_mps, 3),
            "".into(),
        ]);
        t.row([
            "wind, steady (m/s)".into(),
            sig(e.wind_rms_mps, 3),
            "".into(),
        ]);
        t.row([
            "wind, with turbulence (m/s)".into(),
            sig(e.wind_total_rms_mps, 3),
            "".into(),
        ]);
        tables.push(t);
    }
    let mut seg = Table::new(
        "Scripted commands: true response",
        &[
            "t (s)",
            "command",
            "rise (s)",
            "overshoot (%)",
            "settling (s)",
            "final error",
            "alt. held in turn (m)",
        ],
    );
    for g in &s.segments {
        let unit = if g.signal == "altitude" { "m" } else { "deg" };
        seg.row([
            format!("{:.1}", g.t_s),
            g.what.clone(),
            g.metrics
                .rise_time_s
                .map_or("-".into(), |x| format!("{x:.1}")),
            format!("{:.1}", g.metrics.overshoot_pct),
            g.metrics
                .settling_time_s
                .map_or("-".into(), |x| format!("{x:.1}")),
            format!("{:.2} {unit}", g.final_error_max),
            if g.signal == "course" {
                format!("{:.2}", g.alt_hold_error_max_m)
            } else {
                "-".into()
            },
        ]);
    }
    if !s.segments.is_empty() {
        tables.push(seg);
    }
    if let Some(m) = &s.mission {
        tables.push(mission_table(m));
    }
    if let Some(b) = &s.battery {
        tables.push(battery_table(b));
    }
    tables
}

/// A figure to three significant digits, or "n/a" where it was not measured (the errors
/// against guidance of an autopilot seen only through its links).
fn known(x: f64, digits: usize) -> String {
    if x.is_nan() {
        "n/a".into()
    } else {
        sig(x, digits)
    }
}

/// What the flight took from the battery.
pub fn battery_table(b: &BatterySummary) -> Table {
    let mut t = Table::new("Battery", &["quantity", "value"]);
    t.row([
        "energy used (Wh)".to_string(),
        format!("{:.2}", b.energy_wh),
    ]);
    t.row([
        "charge used (mAh)".to_string(),
        format!("{:.0}", b.charge_mah),
    ]);
    t.row([
        "lowest voltage (V)".to_string(),
        format!("{:.2}", b.min_voltage_v),
    ]);
    t.row([
        "remaining at the end (%)".to_string(),
        if b.final_estimate_pct.is_finite() {
            format!(
                "{:.1} (the autopilot's estimate: {:.1})",
                b.final_remaining_pct, b.final_estimate_pct
            )
        } else {
            format!("{:.1}", b.final_remaining_pct)
        },
    ]);
    t
}

/// The figures of a mission flight.
pub fn mission_table(m: &MissionSummary) -> Table {
    let mut t = Table::new("Mission", &["quantity", "value"]);
    let mut row = |q: &str, v: String| {
        t.row([q.to_string(), v]);
    };
    row(
        "items reached",
        format!(
            "{} of {} navigation items{}",
            m.reached.len(),
            m.nav_items.len(),
            if m.all_reached { ", all" } else { "" }
        ),
    );
    row(
        "cross-track, straight legs (m)",
        format!(
            "{} RMS, {} max",
            known(m.xtrack_rms_m, 3),
            known(m.xtrack_max_m, 3)
        ),
    );
    row(
        "cross-track, on loiter circles (m)",
        format!("{} RMS", known(m.orbit_xtrack_rms_m, 3)),
    );
    row(
        "altitude error (m)",
        format!("{} RMS", known(m.alt_rms_m, 3)),
    );
    row(
        "airspeed error (m/s)",
        format!("{} RMS", known(m.airspeed_rms_mps, 3)),
    );
    row(
        "throttle on a stop in level cruise (%)",
        known(m.throttle_at_stops_pct, 3),
    );
    row("flight time (s)", format!("{:.1}", m.flight_time_s));
    row("motor energy (Wh)", format!("{:.2}", m.energy_wh));
    match &m.touchdown {
        Some(td) => {
            row(
                "touchdown",
                format!(
                    "{:.1} m from the landing point ({:+.1} m along), sink {:.2} m/s, {:.1} m/s over ground, {} bounce(s)",
                    td.distance_m, td.along_m, td.sink_rate_mps, td.ground_speed_mps, td.bounces
                ),
            );
        }
        None => row("touchdown", "none".into()),
    }
    let strikes: Vec<String> = m
        .strikes
        .iter()
        .map(|s| {
            format!(
                "{} at {:.1} s in {}, {:.1} cm deep",
                kind(&s.point),
                s.t_s,
                s.phase,
                s.depth_m * 100.0
            )
        })
        .collect();
    row(
        "strikes",
        if strikes.is_empty() {
            "none".into()
        } else {
            strikes.join("; ")
        },
    );
    row(
        "verdict",
        if m.pass {
            "pass".into()
        } else {
            format!("fail: {}", m.failed.join(", "))
        },
    );
    t
}

/// Where the hand-written notes of a results file begin; `sim-host fly --report` keeps
/// everything from here on when it rewrites the file.
pub const NOTES_MARKER: &str = "\n---\n";

/// `docs/RESULTS-SITL.md`: estimator accuracy of the flight and the step figures of the same
/// scripted flight flown on the estimate and on the truth (`SIM_USE_TRUTH`).
pub fn results_markdown(
    cfg: &FlightConfig,
    est: &FlightOutcome,
    truth: &FlightOutcome,
    command_line: &str,
) -> String {
    use std::fmt::Write;
    let s = &est.summary;
    let mut md = String::new();
    let _ = writeln!(md, "# Firmware in the loop: results\n");
    let _ = writeln!(
        md,
        "Produced by `{command_line}` (the firmware's `App` in-process, lock-step, seed {}, \
         {:.0} s simulated, wind ({}, {}, {}) m/s NED, {} turbulence). The flight starts \
         trimmed and level 100 m above home at 17 m/s; the simulator holds the trim until the \
         ground station has armed the autopilot (a hand launch with a safety pilot), then the \
         autopilot flies: Hold, the +100 m climb, four 90 deg right turns 30 s apart and a \
         +-10 m altitude doublet (`sim_host::flight::Script::thesis`). The script repeats no \
         command after its end; the rest of the flight is held level.\n",
        cfg.seed, s.sim_s, cfg.wind_ned[0], cfg.wind_ned[1], cfg.wind_ned[2], s.turbulence
    );
    let _ = writeln!(
        md,
        "## Estimator accuracy\n\nErrors of the firmware's estimate against the simulator's truth, \
         every frame (100 Hz). Two windows: from the first `converged` (the launch transient \
         included: arming follows within a second and the autopilot pulls the hand-launched \
         aircraft onto its course and into the +100 m climb), and from 30 s after it. Wind error \
         is horizontal, against the total wind at the aircraft (steady plus Dryden: the air mass \
         the wind triangle measures, and the target's reference) and, for comparison, against \
         the steady part alone. Targets: roll and pitch < 0.5 deg, heading < 2 deg, \
         altitude < 1 m, airspeed < 0.5 m/s, wind < 1 m/s.\n"
    );
    let _ = writeln!(
        md,
        "| quantity | RMS from convergence | max | RMS from 30 s after | max | target |\n|---|---|---|---|---|---|"
    );
    if let (Some(e), Some(l)) = (&s.estimator, &s.estimator_settled) {
        let _ = writeln!(
            md,
            "| window starts at (s) | {:.1} | | {:.1} | | |",
            e.from_s, l.from_s
        );
        let rows: [(&str, f64, f64, f64, f64, &str); 7] = [
            (
                "roll (deg)",
                e.roll_rms_deg,
                e.roll_max_deg,
                l.roll_rms_deg,
                l.roll_max_deg,
                "0.5",
            ),
            (
                "pitch (deg)",
                e.pitch_rms_deg,
                e.pitch_max_deg,
                l.pitch_rms_deg,
                l.pitch_max_deg,
                "0.5",
            ),
            (
                "heading (deg)",
                e.heading_rms_deg,
                e.heading_max_deg,
                l.heading_rms_deg,
                l.heading_max_deg,
                "2",
            ),
            (
                "altitude (m)",
                e.alt_rms_m,
                e.alt_max_m,
                l.alt_rms_m,
                l.alt_max_m,
                "1",
            ),
            (
                "airspeed (m/s)",
                e.airspeed_rms_mps,
                f64::NAN,
                l.airspeed_rms_mps,
                f64::NAN,
                "0.5",
            ),
            (
                "wind vs total (m/s)",
                e.wind_total_rms_mps,
                f64::NAN,
                l.wind_total_rms_mps,
                f64::NAN,
                "1",
            ),
            (
                "wind vs steady (m/s)",
                e.wind_rms_mps,
                f64::NAN,
                l.wind_rms_mps,
                f64::NAN,
                "",
            ),
        ];
        let m = |x: f64| if x.is_nan() { String::new() } else { sig(x, 3) };
        for (name, a, b, c, d, t) in rows {
            let _ = writeln!(
                md,
                "| {name} | {} | {} | {} | {} | {t} |",
                sig(a, 3),
                m(b),
                sig(c, 3),
                m(d)
            );
        }
        let _ = writeln!(md);
    }
    let _ = writeln!(
        md,
        "## Step figures: flown on the estimate vs on the truth\n\nThe same flight (same seed, \
         same turbulence) flown twice: on the autopilot's estimator, and with `SIM_USE_TRUTH` = 1 \
         on the simulator's HIL_STATE_QUATERNION. Figures of the true response, as chapter 4 reads \
         them (rise 10-90 %, overshoot, 2 % settling); the difference is (estimate - truth) / truth.\n"
    );
    let _ = writeln!(
        md,
        "| command | rise est. (s) | rise truth (s) | diff | overshoot est. (%) | overshoot truth (%) | settling est. (s) | settling truth (s) | diff | final error est. | final error truth |\n|---|---|---|---|---|---|---|---|---|---|---|"
    );
    let f = |x: Option<f64>| x.map_or("-".to_string(), |v| format!("{v:.1}"));
    let d = |a: Option<f64>, b: Option<f64>| match (a, b) {
        (Some(a), Some(b)) if b != 0.0 => format!("{:+.0} %", (a - b) / b * 100.0),
        _ => "-".into(),
    };
    for (a, b) in s.segments.iter().zip(&truth.summary.segments) {
        let unit = if a.signal == "altitude" { "m" } else { "deg" };
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} | {:.1} | {:.1} | {} | {} | {} | {:.2} {unit} | {:.2} {unit} |",
            a.what,
            f(a.metrics.rise_time_s),
            f(b.metrics.rise_time_s),
            d(a.metrics.rise_time_s, b.metrics.rise_time_s),
            a.metrics.overshoot_pct,
            b.metrics.overshoot_pct,
            f(a.metrics.settling_time_s),
            f(b.metrics.settling_time_s),
            d(a.metrics.settling_time_s, b.metrics.settling_time_s),
            a.final_error_max,
            b.final_error_max,
        );
    }
    if let Some(b) = &s.battery {
        let _ = writeln!(
            md,
            "\nBattery (the simulated 3S 3200 mAh pack, from full at power-up): {:.2} Wh and \
             {:.0} mAh drawn, lowest {:.2} V, {:.1} % left at the end (the autopilot's \
             estimate: {:.1} %).",
            b.energy_wh, b.charge_mah, b.min_voltage_v, b.final_remaining_pct, b.final_estimate_pct
        );
    }
    let _ = writeln!(
        md,
        "\nSpeed of this run: {:.1} s simulated in {:.2} s wall clock ({:.0}x real time, release build).",
        s.sim_s, s.wall_s, s.real_time_factor
    );
    md
}
