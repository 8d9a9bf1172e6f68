//! The MCU image on QEMU's emulated STM32F405 (machine `netduinoplus2`): processor in the loop.
//!
//! QEMU runs the MCU image (`firmware` for `thumbv7em-none-eabihf`, profile `mcu`) under
//! `-icount` (every instruction advances the virtual clock by the same step, so the image runs the same
//! way on every machine), with its two UARTs on sockets of this process:
//!
//! ```text
//! USART1 (first -serial)  tcp, nodelay  -> the simulator link (lock-step frames)
//! USART2 (second -serial) tcp           -> the ground bridge -> UDP, one frame per datagram
//! ```
//!
//! Both UARTs connect to listeners here, as TCP clients. A stream suits a UART: bytes stay in
//! order and wait in the socket while the image has not read them (QEMU's USART holds one byte
//! and lets the chardev deliver the next only when the guest has read it). QEMU's `udp`
//! chardev would send every byte of USART2 as its own datagram, which ground stations that
//! expect one frame per datagram do not read; the bridge ([`super::bridge`]) cuts the stream
//! into frames.
//!
//! QEMU runs in a process group of its own: Ctrl-C in the terminal reaches `sim-host`, which
//! writes its log and then ends QEMU (and any wrapper around it) by that group.

use super::bridge::GroundBridge;
use super::profile::{ProfileSlot, ProfileWindow, Profiler};
use super::transport::{TcpServer, Transport};
use std::io::{self, Read};
use std::net::{SocketAddr, TcpListener, UdpSocket};
use std::os::unix::process::CommandExt;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitStatus, Stdio};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// The command that builds the MCU image.
pub const BUILD_COMMAND: &str =
    "cargo build --profile mcu -p firmware --target thumbv7em-none-eabihf";

/// The QEMU that runs the image when none is named.
pub const DEFAULT_QEMU: &str = "qemu-system-arm";

/// `-icount shift=N` by default: 2^3 ns of virtual time per instruction, 125 M instructions
/// per virtual second, the order of the STM32F405's 168 MHz.
pub const DEFAULT_ICOUNT_SHIFT: u8 = 3;

/// How long QEMU may take to start and connect both UARTs.
pub const CONNECT_WAIT: Duration = Duration::from_secs(5);

/// Most bytes of QEMU's standard error kept for an error message.
const STDERR_TAIL: usize = 2048;

/// How to run the MCU image.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct QemuConfig {
    /// The QEMU to run: a name on the PATH or a path.
    pub program: PathBuf,
    /// The MCU image (ELF).
    pub elf: PathBuf,
    /// `-icount shift=N`.
    pub icount_shift: u8,
    /// File for QEMU's standard output: the image's defmt log over semihosting (read it with
    /// `defmt-print -e ELF < FILE`). `None`: discarded.
    pub log: Option<PathBuf>,
    /// Host file holding the image's two flash sectors of saved parameters and missions
    /// (QEMU does not emulate the flash controller; the image reaches the file over
    /// semihosting). Created erased when missing. `None`: the image keeps nothing.
    pub storage: Option<PathBuf>,
    /// A window of control periods to profile by function ([`crate::link::profile`]), and
    /// the directory for QEMU's monitor socket and its (transient) instruction trace.
    pub profile: Option<(ProfileWindow, PathBuf)>,
}

impl Default for QemuConfig {
    fn default() -> Self {
        Self {
            program: PathBuf::from(DEFAULT_QEMU),
            elf: default_elf(),
            icount_shift: DEFAULT_ICOUNT_SHIFT,
            log: None,
            storage: None,
            profile: None,
        }
    }
}

/// Where [`BUILD_COMMAND`] puts the image: under `CARGO_TARGET_DIR` when it is set, else under
/// this workspace's `target/`.
pub fn default_elf() -> PathBuf {
    let target = std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| {
            Path::new(env!("CARGO_MANIFEST_DIR"))
                .parent()
                .unwrap_or(Path::new("."))
                .join("target")
        });
    target.join("thumbv7em-none-eabihf/mcu/firmware")
}

/// Why the MCU image could not be run.
#[derive(Debug, thiserror::Error)]
pub enum QemuError {
    /// The image has not been built.
    #[error("the MCU image `{0}` does not exist: build it with `{BUILD_COMMAND}` (or name another with --elf)")]
    NoImage(PathBuf),
    /// QEMU is not installed.
    #[error("`{0}` cannot be run ({1}): install QEMU's Arm system emulator (Debian and Ubuntu: `sudo apt-get install qemu-system-arm`), or name it with --qemu")]
    NoQemu(PathBuf, String),
    /// QEMU did not start or connect.
    #[error("QEMU: {0}")]
    Start(String),
    /// A socket of this side.
    #[error("QEMU link: {0}")]
    Io(#[from] io::Error),
}

impl QemuConfig {
    /// Checks that the image exists and QEMU runs, with errors that say what to do.
    pub fn check(&self) -> Result<(), QemuError> {
        if !self.elf.is_file() {
            return Err(QemuError::NoImage(self.elf.clone()));
        }
        match Command::new(&self.program)
            .arg("--version")
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .status()
        {
            Ok(s) if s.success() => Ok(()),
            Ok(s) => Err(QemuError::NoQemu(
                self.program.clone(),
                format!("`--version` ended with {s}"),
            )),
            Err(e) => Err(QemuError::NoQemu(self.program.clone(), e.to_string())),
        }
    }

    /// The command line: the emulated board, the image, USART1 on `sim` and USART2 on `gcs`.
    pub fn command(&self, sim: SocketAddr, gcs: SocketAddr) -> Command {
        let mut c = Command::new(&self.program);
        c.args(["-machine", "netduinoplus2", "-cpu", "cortex-m4"])
            .arg("-nographic")
            .args(self.profile.as_ref().map_or_else(
                || vec!["-monitor".to_string(), "none".to_string()],
                |(_, dir)| Profiler::qemu_args(dir),
            ))
            .arg("-semihosting-config")
            .arg(semihosting_config(self.storage.as_deref()))
            .arg("-icount")
            .arg(format!("shift={}", self.icount_shift))
            .arg("-serial")
            .arg(format!("tcp:{sim},nodelay=on"))
            .arg("-serial")
            .arg(format!("tcp:{gcs},nodelay=on"))
            .arg("-kernel")
            .arg(&self.elf);
        c
    }
}

impl QemuConfig {
    /// The profiler of [`QemuConfig::profile`], its result going to `slot` (a slot of its
    /// own when `None`).
    pub fn profiler(&self, slot: Option<ProfileSlot>) -> Option<Profiler> {
        let (window, dir) = self.profile.as_ref()?;
        Some(Profiler::new(
            *window,
            dir,
            &self.elf,
            slot.unwrap_or_default(),
        ))
    }
}

/// QEMU's `-semihosting-config` value: semihosting on the host, with the image's storage
/// file as the argument `storage=PATH` when there is one (a comma in the path is doubled, as
/// QEMU's option syntax wants).
pub fn semihosting_config(storage: Option<&Path>) -> String {
    match storage {
        Some(p) => format!(
            "enable=on,target=native,arg=firmware,arg=storage={}",
            p.display().to_string().replace(',', ",,")
        ),
        None => "enable=on,target=native".to_string(),
    }
}

/// The QEMU process, ended with its process group when dropped.
pub struct QemuProcess {
    child: Child,
    stderr: Arc<Mutex<Vec<u8>>>,
    stderr_closed: Arc<AtomicBool>,
    status: Option<ExitStatus>,
}

impl QemuProcess {
    /// Starts QEMU with USART1 on `sim` and USART2 on `gcs`.
    pub fn spawn(cfg: &QemuConfig, sim: SocketAddr, gcs: SocketAddr) -> Result<Self, QemuError> {
        let stdout = match &cfg.log {
            Some(p) => Stdio::from(std::fs::File::create(p).map_err(|e| {
                QemuError::Start(format!("cannot create the log `{}`: {e}", p.display()))
            })?),
            None => Stdio::null(),
        };
        let mut command = cfg.command(sim, gcs);
        command
            .stdin(Stdio::null())
            .stdout(stdout)
            .stderr(Stdio::piped())
            .process_group(0);
        // A sim-host that is killed (no chance to end QEMU itself) takes QEMU with it.
        // SAFETY: only prctl(2), which is async-signal-safe, runs between fork and exec.
        unsafe {
            command.pre_exec(|| {
                nix::sys::prctl::set_pdeathsig(nix::sys::signal::Signal::SIGKILL)
                    .map_err(io::Error::from)
            });
        }
        let mut child = command
            .spawn()
            .map_err(|e| QemuError::NoQemu(cfg.program.clone(), e.to_string()))?;
        let stderr = Arc::new(Mutex::new(Vec::new()));
        let stderr_closed = Arc::new(AtomicBool::new(true));
        if let Some(mut pipe) = child.stderr.take() {
            let (tail, closed) = (stderr.clone(), stderr_closed.clone());
            closed.store(false, Ordering::Relaxed);
            std::thread::spawn(move || {
                let mut buf = [0u8; 512];
                while let Ok(n) = pipe.read(&mut buf) {
                    if n == 0 {
                        break;
                    }
                    let mut t = tail.lock().unwrap_or_else(|p| p.into_inner());
                    t.extend_from_slice(&buf[..n]);
                    let excess = t.len().saturating_sub(STDERR_TAIL);
                    t.drain(..excess);
                }
                closed.store(true, Ordering::Relaxed);
            });
        }
        Ok(Self {
            child,
            stderr,
            stderr_closed,
            status: None,
        })
    }

    /// QEMU's process id.
    pub fn pid(&self) -> u32 {
        self.child.id()
    }

    /// How QEMU ended, if it has.
    pub fn exited(&mut self) -> Option<ExitStatus> {
        if self.status.is_none() {
            self.status = self.child.try_wait().ok().flatten();
        }
        self.status
    }

    /// Waits up to `wait` for QEMU to end (a closed socket comes a moment before the exit).
    fn exited_within(&mut self, wait: Duration) -> Option<ExitStatus> {
        let end = Instant::now() + wait;
        loop {
            if let Some(s) = self.exited() {
                return Some(s);
            }
            if Instant::now() >= end {
                return None;
            }
            std::thread::sleep(Duration::from_millis(10));
        }
    }

    /// `QEMU exited with status 1: <what it printed>`.
    pub fn exit_message(&self, status: ExitStatus) -> String {
        use std::os::unix::process::ExitStatusExt;
        let how = match (status.code(), status.signal()) {
            (Some(c), _) => format!("exited with status {c}"),
            (None, Some(s)) => format!("was killed by signal {s}"),
            _ => format!("ended ({status})"),
        };
        // What it printed last reaches the pipe's reader a moment after the exit.
        let end = Instant::now() + Duration::from_millis(300);
        while !self.stderr_closed.load(Ordering::Relaxed) && Instant::now() < end {
            std::thread::sleep(Duration::from_millis(5));
        }
        let said = String::from_utf8_lossy(&self.stderr.lock().unwrap_or_else(|p| p.into_inner()))
            .trim()
            .to_string();
        if said.is_empty() {
            format!("QEMU (pid {}) {how}", self.pid())
        } else {
            format!("QEMU (pid {}) {how}: {said}", self.pid())
        }
    }

    /// An error if QEMU has ended (for the waits while it starts).
    fn check_alive(&mut self) -> io::Result<()> {
        match self.exited() {
            Some(s) => Err(io::Error::other(self.exit_message(s))),
            None => Ok(()),
        }
    }

    /// Ends QEMU and whatever runs in its process group.
    pub fn kill(&mut self) {
        if self.exited().is_none() {
            if let Ok(pid) = i32::try_from(self.child.id()) {
                let _ = nix::sys::signal::killpg(
                    nix::unistd::Pid::from_raw(pid),
                    nix::sys::signal::Signal::SIGKILL,
                );
            }
            let _ = self.child.kill();
            self.status = self.child.wait().ok();
        }
    }
}

impl Drop for QemuProcess {
    fn drop(&mut self) {
        self.kill();
    }
}

/// The simulator link to the MCU image: its USART1, with QEMU's fate in the errors.
pub struct QemuLink {
    server: TcpServer,
    process: QemuProcess,
    log: Option<PathBuf>,
    elf: PathBuf,
    profiler: Option<Profiler>,
}

impl QemuLink {
    /// The QEMU process.
    pub fn process(&mut self) -> &mut QemuProcess {
        &mut self.process
    }

    /// A transport error, with how QEMU ended when it has.
    fn explain(&mut self, e: io::Error) -> io::Error {
        match self.process.exited_within(Duration::from_millis(500)) {
            Some(s) => io::Error::new(e.kind(), self.process.exit_message(s)),
            None => e,
        }
    }
}

impl Transport for QemuLink {
    fn send(&mut self, bytes: &[u8]) -> io::Result<()> {
        // Each send is one sensor frame (the lock-step link writes a frame's messages at once).
        if let Some(p) = self.profiler.as_mut() {
            p.before_frame();
        }
        self.server.send(bytes).map_err(|e| self.explain(e))
    }

    fn recv(&mut self, buf: &mut [u8], timeout: Duration) -> io::Result<usize> {
        match self.server.recv(buf, timeout) {
            Ok(0) => match self.process.exited() {
                Some(s) => Err(io::Error::new(
                    io::ErrorKind::UnexpectedEof,
                    self.process.exit_message(s),
                )),
                None => Ok(0),
            },
            Ok(n) => Ok(n),
            Err(e) if e.kind() == io::ErrorKind::Interrupted => Err(e),
            Err(e) => Err(self.explain(e)),
        }
    }

    fn describe(&self) -> String {
        format!(
            "QEMU netduinoplus2 (pid {}) running {}, USART1",
            self.process.pid(),
            self.elf.display()
        )
    }

    fn diagnose(&mut self) -> Option<String> {
        Some(match self.process.exited() {
            Some(s) => self.process.exit_message(s),
            None => {
                let log = match &self.log {
                    Some(p) => format!(
                        "; its log: `defmt-print -e {} < {}`",
                        self.elf.display(),
                        p.display()
                    ),
                    None => String::new(),
                };
                format!(
                    "QEMU (pid {}) is still running but the MCU image stopped answering (a panic or a hang){log}",
                    self.process.pid()
                )
            }
        })
    }
}

/// Boots the MCU image: starts QEMU, accepts its two UARTs (within [`CONNECT_WAIT`]) and
/// starts the ground bridge on `gcs_bind` (telemetry also to `gcs_remote`). `check` runs while
/// waiting and aborts the boot with its error (Ctrl-C). With [`QemuConfig::profile`], the
/// profile goes to `profile` once its window has been flown.
pub fn boot(
    cfg: &QemuConfig,
    gcs_bind: &str,
    gcs_remote: Option<&str>,
    profile: Option<ProfileSlot>,
    mut check: impl FnMut() -> io::Result<()>,
) -> Result<(QemuLink, GroundBridge), QemuError> {
    cfg.check()?;
    let local = "127.0.0.1:0";
    let (sim_l, gcs_l) = (TcpListener::bind(local)?, TcpListener::bind(local)?);
    // The ground side first: a port in use is an error before QEMU starts.
    let udp = UdpSocket::bind(gcs_bind).map_err(|e| {
        QemuError::Start(format!(
            "cannot open the ground link on udp {gcs_bind}: {e}"
        ))
    })?;
    // The profiler's trace reader is there before QEMU, which opens its trace at start-up.
    let profiler = cfg.profiler(profile);
    let mut process = QemuProcess::spawn(cfg, sim_l.local_addr()?, gcs_l.local_addr()?)?;
    let mut accept = |l: &TcpListener, what: &str, p: &mut QemuProcess| {
        TcpServer::accept(l, Some(CONNECT_WAIT), || {
            p.check_alive()?;
            check()
        })
        .map_err(|e| {
            let why = if e.kind() == io::ErrorKind::TimedOut {
                format!(
                    "QEMU (pid {}) is running but did not connect it within {CONNECT_WAIT:?}",
                    p.pid()
                )
            } else {
                e.to_string()
            };
            QemuError::Start(format!("{what} did not connect: {why}"))
        })
    };
    let sim = accept(&sim_l, "USART1 (the simulator link)", &mut process)?;
    let gcs = accept(&gcs_l, "USART2 (the ground link)", &mut process)?;
    let remote = match gcs_remote {
        Some(r) => Some(
            r.parse::<SocketAddr>()
                .map_err(|e| QemuError::Start(format!("ground-station address `{r}`: {e}")))?,
        ),
        None => None,
    };
    let bridge = GroundBridge::start(gcs.into_stream(), udp, remote)?;
    Ok((
        QemuLink {
            server: sim,
            process,
            log: cfg.log.clone(),
            elf: cfg.elf.clone(),
            profiler,
        },
        bridge,
    ))
}
