//! Flying over a transport, and the files a flight leaves: the lock-step link around the flight
//! loop, the MCU image booted in QEMU, and the log, `.tlog`, plots and summary written whether
//! the flight ended well or its link failed.

use crate::aircraft::Aircraft;
use crate::flight::config::FlightConfig;
use crate::flight::onboard::{Onboard, OutsideOnboard};
use crate::flight::plots::write_log_and_plots;
use crate::flight::runner::{fly, FlightError, FlightOutcome};
use crate::link::budget::{image_size, McuBudget};
use crate::link::lockstep::Lockstep;
use crate::link::profile::{McuProfile, ProfileSlot};
use crate::link::qemu::{boot, QemuConfig};
use crate::link::tlog::TlogWriter;
use crate::link::transport::Transport;
use crate::report::to_json;
use anyhow::Context;
use std::path::{Path, PathBuf};

/// A flown flight and the files it left.
#[derive(Clone, Debug)]
pub struct FlyReport {
    /// Log and summary.
    pub outcome: FlightOutcome,
    /// Files written.
    pub files: Vec<PathBuf>,
    /// The MCU image's budget as it measured itself (`--link qemu` only).
    pub mcu: Option<McuBudget>,
    /// Where the MCU image's instructions went in the profiled window (`--link qemu` with a
    /// [`QemuConfig::profile`] window that the flight reached).
    pub mcu_profile: Option<McuProfile>,
}

/// A flight, or why it could not be flown: the outer error is this side's (a file that
/// cannot be written), the inner one the flight's.
pub(crate) type Flown = anyhow::Result<Result<FlightOutcome, FlightError>>;

pub(crate) fn run_on<T: Transport, O: Onboard<T>>(
    aircraft: &Aircraft,
    cfg: &FlightConfig,
    transport: T,
    onboard: &mut O,
    tlog: Option<&Path>,
) -> Flown {
    run_on_with(aircraft, cfg, transport, onboard, tlog, |_| Ok(()))
}

/// [`run_on`], with `before` run on the link first (waiting for an autopilot to speak).
pub(crate) fn run_on_with<T: Transport, O: Onboard<T>>(
    aircraft: &Aircraft,
    cfg: &FlightConfig,
    transport: T,
    onboard: &mut O,
    tlog: Option<&Path>,
    before: impl FnOnce(&mut Lockstep<T>) -> anyhow::Result<()>,
) -> Flown {
    let mut link = Lockstep::new(transport, cfg.link_timeout);
    if let Some(p) = tlog {
        let w =
            TlogWriter::create(p).with_context(|| format!("cannot create `{}`", p.display()))?;
        link = link.with_tlog(w);
    }
    before(&mut link)?;
    let flown = fly(aircraft, cfg, &mut link, onboard);
    // The log of a flight that failed is kept as well.
    link.finish().context("cannot write the tlog")?;
    Ok(flown)
}

/// A flight of the MCU image, its figures of itself and its profile (when one was asked for).
pub(crate) type QemuFlown = (
    Result<FlightOutcome, FlightError>,
    Option<McuBudget>,
    Option<McuProfile>,
);

/// Boots the MCU image in QEMU and flies `cfg` against it, the scripted station on the UDP
/// side of its ground bridge. The bridge serves `cfg.ground_link` when one is asked for
/// (QGroundControl watching), else a free port for the scripted station alone. Also returns
/// the image's budget: its size and what it measured of itself in flight, and the profile of
/// its instructions when one was asked for.
pub(crate) fn fly_qemu(
    aircraft: &Aircraft,
    cfg: &FlightConfig,
    qemu: &QemuConfig,
    out: Option<&Path>,
    tlog: Option<&Path>,
) -> anyhow::Result<QemuFlown> {
    let (bind, remote) = match &cfg.ground_link {
        Some((b, r)) => (b.clone(), Some(r.clone())),
        None => ("127.0.0.1:0".to_string(), None),
    };
    let qemu = QemuConfig {
        log: out.map(|d| d.join(MCU_LOG)),
        ..qemu.clone()
    };
    let slot = ProfileSlot::default();
    let (sim, bridge) = boot(&qemu, &bind, remote.as_deref(), Some(slot.clone()), || {
        stop_requested(cfg)
    })?;
    let mut onboard = OutsideOnboard::with_station(bridge.local_addr())
        .context("cannot open the scripted station's socket")?;
    // The bridge is the autopilot's ground link; no port into an application here.
    let cfg = FlightConfig {
        ground_link: None,
        truth_frames: uart_truth_frames(cfg),
        ..cfg.clone()
    };
    let flown = run_on(aircraft, &cfg, sim, &mut onboard, tlog)?;
    let size = image_size(&qemu.elf)?;
    let profile = match slot.lock().unwrap_or_else(|p| p.into_inner()).take() {
        Some(p) => Some(p.map_err(anyhow::Error::msg)?),
        None if qemu.profile.is_some() => {
            anyhow::bail!("the flight ended before the profile's window closed")
        }
        None => None,
    };
    Ok((
        flown,
        McuBudget::from_reports(size, &bridge.named_values()),
        profile,
    ))
}

/// Whether the truth goes to the MCU image: only when it flies on it. Each byte a UART
/// receives costs QEMU a pass of its main loop, and the truth is half of the bytes of a frame
/// (76 of 152 on average).
pub(crate) fn uart_truth_frames(cfg: &FlightConfig) -> bool {
    cfg.truth_frames && cfg.flies_on_truth()
}

/// File of the ground link as the scripted station saw it, both ways (QGroundControl's
/// replay and MAVExplorer open it as a flight).
pub const GROUND_TLOG: &str = "flight.tlog";

/// File of the simulator link, both ways (sensor frames and the autopilot's answers).
pub const SIM_TLOG: &str = "simlink.tlog";

/// File of the MCU image's defmt log (QEMU's semihosting output) in the output directory.
pub const MCU_LOG: &str = "mcu.defmt";

/// An error once the flight has been asked to stop (Ctrl-C), for the waits before it.
pub(crate) fn stop_requested(cfg: &FlightConfig) -> std::io::Result<()> {
    if cfg.stopped() {
        Err(std::io::Error::new(
            std::io::ErrorKind::Interrupted,
            "stopped (Ctrl-C)",
        ))
    } else {
        Ok(())
    }
}

/// Writes the files of a flight into `out` (those of a failed flight too, up to the failure:
/// the error then says where they are) beside `files` already written.
pub(crate) fn finish_report(
    flown: Result<FlightOutcome, FlightError>,
    out: Option<&Path>,
    plots: bool,
    mut files: Vec<PathBuf>,
) -> anyhow::Result<FlyReport> {
    match flown {
        Ok(outcome) => {
            if let Some(dir) = out {
                files.extend(write_flight_files(dir, &outcome, plots)?);
            }
            Ok(FlyReport {
                outcome,
                files,
                mcu: None,
                mcu_profile: None,
            })
        }
        Err(e) => match (e.partial(), out) {
            (Some(partial), Some(dir)) => {
                write_flight_files(dir, partial, plots)?;
                Err(anyhow::Error::new(e).context(format!(
                    "the flight failed; its log up to the failure is in `{}`",
                    dir.display()
                )))
            }
            _ => Err(e.into()),
        },
    }
}

/// Writes the CSV log (and the PNG plots when `plots`) and `summary.json` into `dir`.
pub fn write_flight_files(
    dir: &Path,
    outcome: &FlightOutcome,
    plots: bool,
) -> anyhow::Result<Vec<PathBuf>> {
    let mut files = Vec::new();
    if plots {
        files.extend(write_log_and_plots(dir, &outcome.samples)?);
    } else {
        let csv = dir.join("flight.csv");
        let rows: Vec<Vec<f64>> = outcome
            .samples
            .iter()
            .map(crate::flight::record::csv_row)
            .collect();
        crate::report::csv_out::write_csv(&csv, &crate::flight::record::csv_headers(), &rows)?;
        files.push(csv);
    }
    let json = dir.join("summary.json");
    std::fs::write(&json, to_json(&outcome.summary)?)
        .with_context(|| format!("cannot write `{}`", json.display()))?;
    files.push(json);
    Ok(files)
}
