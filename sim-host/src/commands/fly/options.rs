//! What `sim-host fly` flies over: the transport of the simulator link, and the options of a
//! flight beyond the flight itself (output, plots, the gains and parameters the station sets).

use crate::flight::config::FlightConfig;
use crate::link::qemu::QemuConfig;
use std::path::PathBuf;

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
