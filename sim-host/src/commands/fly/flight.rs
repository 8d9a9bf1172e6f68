//! One flight over the transport of the options: the firmware's application in this process,
//! on a thread behind TCP, UDP or a pty, or the MCU image in QEMU; its files written.

use super::options::{with_params, FlyOptions, LinkKind};
use crate::aircraft::Aircraft;
use crate::commands::flying::{
    finish_report, fly_qemu, run_on, FlyReport, GROUND_TLOG, MCU_LOG, SIM_TLOG,
};
use crate::flight::config::FlightConfig;
use crate::flight::onboard::{spawn_firmware, InprocOnboard};
use crate::link::transport::{Inproc, PtyServer, TcpServer, UdpServer};
use anyhow::Context;
use firmware::app::App;
use firmware::sitl::SimEndpoint;
use std::path::PathBuf;
use std::time::Duration;

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
            match &opts.out {
                Some(dir) => Inproc::new(App::new()).with_logs(dir.join("logs")),
                None => Inproc::new(App::new()),
            },
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
