//! `sim-host sim`: the simulator alone, as PX4's simulators are.
//!
//! The plant waits on the runway at home (or trimmed in the air) for any autopilot that speaks
//! PX4's simulator interface: the host build (`cargo run -p firmware -- --sim tcp:...`), the
//! MCU image in QEMU (`--link qemu`, booted here), or another autopilot. It flies it in
//! lock-step, as fast as the autopilot answers or paced to the wall clock, with no scripted
//! ground station: whoever flies the aircraft does so from QGroundControl, MAVSDK or pymavlink
//! on the autopilot's own ground link. The flight ends when the autopilot closes the link, at
//! the duration, or on Ctrl-C; in each case the log, `.tlog`, plots and summary are written.

use super::fly::LinkKind;
use super::flying::{finish_report, run_on_with, stop_requested, FlyReport, MCU_LOG, SIM_TLOG};
use crate::aircraft::Aircraft;
use crate::flight::config::FlightConfig;
use crate::flight::onboard::OutsideOnboard;
use crate::link::lockstep::{LinkError, Lockstep};
use crate::link::qemu::{boot, QemuConfig};
use crate::link::transport::{PtyServer, TcpServer, Transport, UdpServer};
use anyhow::Context;
use std::net::{SocketAddr, TcpListener};
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// Options of `sim-host sim` beyond the flight itself.
#[derive(Clone, Debug)]
pub struct SimOptions {
    /// Transport: tcp, udp, pty or qemu.
    pub link: LinkKind,
    /// Address the simulator binds for tcp and udp (PX4's 127.0.0.1:4560).
    pub bind: String,
    /// How long to wait for an autopilot (`None`: until one comes, or Ctrl-C).
    pub wait: Option<Duration>,
    /// Directory for the files; nothing written when `None`.
    pub out: Option<PathBuf>,
    /// Write PNG plots.
    pub plots: bool,
    /// The MCU image and its QEMU, for `qemu`.
    pub qemu: QemuConfig,
    /// For `qemu`: the UDP address of the image's ground link.
    pub gcs_bind: String,
    /// For `qemu`: where its telemetry goes besides every station that speaks.
    pub gcs_remote: Option<String>,
}

impl Default for SimOptions {
    fn default() -> Self {
        Self {
            link: LinkKind::Tcp,
            bind: "127.0.0.1:4560".into(),
            wait: None,
            out: None,
            plots: true,
            qemu: QemuConfig::default(),
            gcs_bind: "127.0.0.1:18570".into(),
            gcs_remote: Some("127.0.0.1:14550".into()),
        }
    }
}

/// Where the simulator waits for its autopilot, once it does.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Ready {
    /// The simulator link: what an autopilot connects to.
    pub sim_link: String,
    /// With `qemu`: the MCU image's ground link, where ground stations send.
    pub ground: Option<SocketAddr>,
}

impl Ready {
    /// In words, for the terminal.
    pub fn describe(&self) -> String {
        match self.ground {
            Some(g) => format!(
                "{} is flying; its ground link is udp {g} (QGroundControl: connect to it, or listen on the telemetry remote)",
                self.sim_link
            ),
            None => format!("waiting for an autopilot on {}", self.sim_link),
        }
    }
}

static CTRL_C: AtomicBool = AtomicBool::new(false);

/// Makes Ctrl-C (SIGINT) end the flight at its next frame, with the log written; a second
/// Ctrl-C ends the process at once. Returns the flag for [`FlightConfig::stop`].
///
/// Call it before any thread starts: SIGINT is blocked in this thread, and so in every thread
/// started after it, and one thread waits for it. No read of a socket is then cut short by
/// the signal (a read with a timeout is not restarted after a handler). Child processes
/// (QEMU) start with no signal blocked.
pub fn stop_on_ctrl_c() -> &'static AtomicBool {
    use nix::sys::signal::{SigSet, Signal};
    static WAITER: std::sync::Once = std::sync::Once::new();
    WAITER.call_once(|| {
        let mut set = SigSet::empty();
        set.add(Signal::SIGINT);
        if let Err(e) = set.thread_block() {
            eprintln!("sim-host: Ctrl-C will end the process without writing the log ({e})");
            return;
        }
        std::thread::spawn(move || {
            while set.wait().is_ok() {
                if CTRL_C.swap(true, Ordering::Relaxed) {
                    std::process::exit(130);
                }
            }
        });
    });
    &CTRL_C
}

/// Waits, in short slices so that Ctrl-C is heard, until the autopilot has spoken.
fn until_heard<T: Transport>(
    link: &mut Lockstep<T>,
    cfg: &FlightConfig,
    wait: Option<Duration>,
) -> anyhow::Result<()> {
    let start = Instant::now();
    loop {
        match link.wait_for_autopilot(Duration::from_millis(200)) {
            Ok(()) => return Ok(()),
            Err(LinkError::Silent { .. }) => {}
            Err(e) => return Err(e.into()),
        }
        stop_requested(cfg).context("no autopilot came")?;
        if let Some(w) = wait.filter(|w| start.elapsed() >= *w) {
            anyhow::bail!(
                "no autopilot spoke on {} within {w:?}",
                link.transport().describe()
            );
        }
    }
}

/// Serves one autopilot with the plant of `aircraft` as `cfg` says (its `scripted_station`
/// is not used: nobody here commands the autopilot). `ready` is told where the simulator
/// waits once it does.
pub fn sim_report(
    aircraft: &Aircraft,
    cfg: &FlightConfig,
    opts: &SimOptions,
    ready: impl FnOnce(&Ready),
) -> anyhow::Result<FlyReport> {
    let cfg = FlightConfig {
        scripted_station: false,
        ground_link: None,
        ..cfg.clone()
    };
    if let Some(dir) = &opts.out {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("cannot create `{}`", dir.display()))?;
    }
    // The ground link runs between the autopilot and its stations, not through here: the
    // station records it (QGroundControl writes its own .tlog).
    let tlog = opts.out.as_ref().map(|d| d.join(SIM_TLOG));
    let tlog = tlog.as_deref();
    let mut onboard = OutsideOnboard::unattended();
    let waiting = |what: &str| format!("no autopilot connected to the {what} simulator link");
    let flown = match opts.link {
        LinkKind::Inproc => anyhow::bail!(
            "sim serves an autopilot outside this process: --link tcp, udp, pty or qemu (`sim-host fly` flies the firmware in-process)"
        ),
        LinkKind::Tcp => {
            let listener = TcpListener::bind(&opts.bind)
                .with_context(|| format!("cannot listen on tcp {}", opts.bind))?;
            ready(&Ready {
                sim_link: format!("tcp {}", listener.local_addr()?),
                ground: None,
            });
            let server = TcpServer::accept(&listener, opts.wait, || stop_requested(&cfg))
                .with_context(|| waiting("tcp"))?;
            run_on_with(aircraft, &cfg, server, &mut onboard, tlog, |l| {
                until_heard(l, &cfg, opts.wait)
            })?
        }
        LinkKind::Udp => {
            let mut server = UdpServer::bind(&opts.bind)
                .with_context(|| format!("cannot bind udp {}", opts.bind))?;
            ready(&Ready {
                sim_link: format!("udp {}", server.local_addr()?),
                ground: None,
            });
            let start = Instant::now();
            loop {
                match server.wait_for_peer(Duration::from_millis(200)) {
                    Ok(_) => break,
                    Err(e)
                        if matches!(
                            e.kind(),
                            std::io::ErrorKind::TimedOut | std::io::ErrorKind::Interrupted
                        ) => {}
                    Err(e) => return Err(e).with_context(|| waiting("udp")),
                }
                stop_requested(&cfg).with_context(|| waiting("udp"))?;
                if opts.wait.is_some_and(|w| start.elapsed() >= w) {
                    anyhow::bail!("{} within {:?}", waiting("udp"), opts.wait.unwrap_or_default());
                }
            }
            run_on_with(aircraft, &cfg, server, &mut onboard, tlog, |l| {
                until_heard(l, &cfg, opts.wait)
            })?
        }
        LinkKind::Pty => {
            let pty = PtyServer::open().context("cannot open a pty")?;
            ready(&Ready {
                sim_link: format!("serial:{}", pty.slave_path().display()),
                ground: None,
            });
            run_on_with(aircraft, &cfg, pty, &mut onboard, tlog, |l| {
                until_heard(l, &cfg, opts.wait)
            })?
        }
        LinkKind::Qemu => {
            let qemu = QemuConfig {
                log: opts.out.as_ref().map(|d| d.join(MCU_LOG)),
                ..opts.qemu.clone()
            };
            let (sim, bridge) = boot(
                &qemu,
                &opts.gcs_bind,
                opts.gcs_remote.as_deref(),
                None,
                || stop_requested(&cfg),
            )?;
            ready(&Ready {
                sim_link: sim.describe(),
                ground: Some(bridge.local_addr()),
            });
            let r = run_on_with(aircraft, &cfg, sim, &mut onboard, tlog, |_| Ok(()));
            drop(bridge);
            r?
        }
    };
    let mut files: Vec<PathBuf> = tlog.iter().map(|t| t.to_path_buf()).collect();
    if opts.link == LinkKind::Qemu {
        files.extend(opts.out.as_ref().map(|d| d.join(MCU_LOG)));
    }
    finish_report(flown, opts.out.as_deref(), opts.plots, files)
}
