//! The host (SITL) board: the simulator link over TCP, UDP or a serial line (a pty), and the
//! same [`App`] the MCU runs.

use crate::app::persist::Persistence;
use crate::app::App;
use common::gcs::Dest;
use common::storage::{AbRegion, RamFlash, BOARD_MAGIC};
use std::io::{self, Read, Write};
use std::net::{SocketAddr, TcpStream, ToSocketAddrs, UdpSocket};
use std::os::fd::AsFd;
use std::path::PathBuf;
use std::time::{Duration, Instant};

/// A byte link to the simulator.
pub trait ByteLink {
    /// Reads what is available, waiting at most `timeout`; `Ok(0)` means nothing arrived.
    fn read_timeout(&mut self, buf: &mut [u8], timeout: Duration) -> io::Result<usize>;
    /// Writes all bytes.
    fn write_all_bytes(&mut self, bytes: &[u8]) -> io::Result<()>;
}

/// Where the simulator is.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum SimEndpoint {
    /// The simulator listens on TCP (PX4's default: port 4560).
    Tcp(String),
    /// The simulator listens on UDP.
    Udp(String),
    /// A serial device (a pty the simulator created, or a real UART adapter).
    Serial(PathBuf),
}

impl std::str::FromStr for SimEndpoint {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let (kind, rest) = s.split_once(':').ok_or_else(|| {
            format!("'{s}': expected tcp:HOST:PORT, udp:HOST:PORT or serial:PATH")
        })?;
        match kind {
            "tcp" => Ok(Self::Tcp(rest.to_string())),
            "udp" => Ok(Self::Udp(rest.to_string())),
            "serial" | "pty" => Ok(Self::Serial(PathBuf::from(rest))),
            _ => Err(format!(
                "'{s}': unknown link '{kind}' (expected tcp, udp or serial)"
            )),
        }
    }
}

struct Tcp(TcpStream);

/// Whether a read error only means that nothing arrived in time.
pub fn timed_out(e: &io::Error) -> bool {
    matches!(
        e.kind(),
        io::ErrorKind::WouldBlock | io::ErrorKind::TimedOut
    )
}

/// Reads from a TCP stream, waiting at most `timeout`: `Ok(0)` means nothing arrived, a
/// closed connection is an `UnexpectedEof` error saying `who` closed it. Both ends of the
/// simulator link read this way.
pub fn read_tcp(
    stream: &mut TcpStream,
    buf: &mut [u8],
    timeout: Duration,
    who: &str,
) -> io::Result<usize> {
    stream.set_read_timeout(Some(timeout.max(Duration::from_micros(1))))?;
    match stream.read(buf) {
        Ok(0) => Err(io::Error::new(
            io::ErrorKind::UnexpectedEof,
            format!("{who} closed the connection"),
        )),
        Ok(n) => Ok(n),
        Err(e) if timed_out(&e) => Ok(0),
        Err(e) => Err(e),
    }
}

/// Reads from a serial line or pty, waiting at most `timeout` (poll(2)): `Ok(0)` means
/// nothing arrived, a line that hung up is an `UnexpectedEof` error.
pub fn read_serial(
    file: &mut std::fs::File,
    buf: &mut [u8],
    timeout: Duration,
) -> io::Result<usize> {
    use nix::poll::{poll, PollFd, PollFlags, PollTimeout};
    let ms = timeout.as_millis().min(i32::MAX as u128) as i32;
    let mut fds = [PollFd::new(file.as_fd(), PollFlags::POLLIN)];
    let ready = poll(
        &mut fds,
        PollTimeout::try_from(ms).unwrap_or(PollTimeout::MAX),
    )
    .map_err(io::Error::from)?;
    if ready == 0 {
        return Ok(0);
    }
    match file.read(buf) {
        Ok(0) => Err(io::Error::new(
            io::ErrorKind::UnexpectedEof,
            "serial line closed",
        )),
        r => r,
    }
}

impl ByteLink for Tcp {
    fn read_timeout(&mut self, buf: &mut [u8], timeout: Duration) -> io::Result<usize> {
        read_tcp(&mut self.0, buf, timeout, "simulator")
    }

    fn write_all_bytes(&mut self, bytes: &[u8]) -> io::Result<()> {
        self.0.write_all(bytes)
    }
}

struct Udp {
    socket: UdpSocket,
    peer: SocketAddr,
}

impl ByteLink for Udp {
    fn read_timeout(&mut self, buf: &mut [u8], timeout: Duration) -> io::Result<usize> {
        self.socket
            .set_read_timeout(Some(timeout.max(Duration::from_micros(1))))?;
        match self.socket.recv_from(buf) {
            Ok((n, from)) if from == self.peer => Ok(n),
            Ok(_) => Ok(0),
            Err(e) if timed_out(&e) => Ok(0),
            Err(e) => Err(e),
        }
    }

    fn write_all_bytes(&mut self, bytes: &[u8]) -> io::Result<()> {
        self.socket.send_to(bytes, self.peer).map(|_| ())
    }
}

struct Serial(std::fs::File);

impl ByteLink for Serial {
    fn read_timeout(&mut self, buf: &mut [u8], timeout: Duration) -> io::Result<usize> {
        read_serial(&mut self.0, buf, timeout)
    }

    fn write_all_bytes(&mut self, bytes: &[u8]) -> io::Result<()> {
        self.0.write_all(bytes)
    }
}

/// Connects to the simulator, retrying until `wait` runs out (the simulator may start later).
pub fn connect(endpoint: &SimEndpoint, wait: Duration) -> io::Result<Box<dyn ByteLink>> {
    let deadline = Instant::now() + wait;
    loop {
        let attempt: io::Result<Box<dyn ByteLink>> = match endpoint {
            SimEndpoint::Tcp(addr) => TcpStream::connect(addr).and_then(|s| {
                // Lock-step frames are small and latency-bound.
                s.set_nodelay(true)?;
                Ok(Box::new(Tcp(s)) as Box<dyn ByteLink>)
            }),
            SimEndpoint::Udp(addr) => {
                let peer = addr.to_socket_addrs()?.next().ok_or_else(|| {
                    io::Error::new(
                        io::ErrorKind::InvalidInput,
                        format!("no address in '{addr}'"),
                    )
                })?;
                let socket = UdpSocket::bind(("127.0.0.1", 0))?;
                Ok(Box::new(Udp { socket, peer }) as Box<dyn ByteLink>)
            }
            SimEndpoint::Serial(path) => std::fs::OpenOptions::new()
                .read(true)
                .write(true)
                .open(path)
                .and_then(|f| {
                    set_raw(&f)?;
                    Ok(Box::new(Serial(f)) as Box<dyn ByteLink>)
                }),
        };
        match attempt {
            Ok(link) => return Ok(link),
            Err(e) if Instant::now() >= deadline => return Err(e),
            Err(_) => std::thread::sleep(Duration::from_millis(100)),
        }
    }
}

fn set_raw(f: &std::fs::File) -> io::Result<()> {
    use nix::sys::termios::{cfmakeraw, tcgetattr, tcsetattr, SetArg};
    // A regular file (used by tests) has no terminal attributes; that is fine.
    if let Ok(mut t) = tcgetattr(f.as_fd()) {
        cfmakeraw(&mut t);
        tcsetattr(f.as_fd(), SetArg::TCSANOW, &t).map_err(io::Error::from)?;
    }
    Ok(())
}

/// Runs the autopilot against a simulator link until the link closes or stays silent for
/// `silence`.
pub fn run(link: &mut dyn ByteLink, app: &mut App, silence: Duration) -> io::Result<()> {
    run_with(link, app, silence, None, None)
}

/// [`run`] with a ground-station link and persistent storage.
pub fn run_with(
    link: &mut dyn ByteLink,
    app: &mut App,
    silence: Duration,
    mut gcs: Option<&mut GcsUdp>,
    mut storage: Option<&mut FileStorage>,
) -> io::Result<()> {
    // Announce ourselves: a UDP simulator learns our address from the first datagram.
    let hb = crate::app::heartbeat_frame(app);
    link.write_all_bytes(&hb)?;
    let mut buf = [0u8; 2048];
    let mut last_rx = Instant::now();
    loop {
        // Short waits while a ground station is attached, so it is answered even when the
        // simulator pauses.
        let wait = if gcs.is_some() { 5 } else { 100 };
        let n = link.read_timeout(&mut buf, Duration::from_millis(wait))?;
        if let Some(g) = gcs.as_deref_mut() {
            g.service(app)?;
        }
        if let Some(s) = storage.as_deref_mut() {
            if let Err(e) = s.save_changes(app) {
                eprintln!("firmware: {e}");
            }
        }
        if n == 0 {
            if last_rx.elapsed() > silence {
                return Err(io::Error::new(
                    io::ErrorKind::TimedOut,
                    format!("simulator silent for {:.1} s", silence.as_secs_f64()),
                ));
            }
            continue;
        }
        last_rx = Instant::now();
        let mut out = Vec::new();
        app.on_sim_bytes(buf.get(..n).unwrap_or(&[]), &mut |b| {
            out.extend_from_slice(b)
        });
        if !out.is_empty() {
            link.write_all_bytes(&out)?;
        }
        if let Some(g) = gcs.as_deref_mut() {
            g.flush(app);
        }
    }
}

/// The SITL "flash": the board record of `common::storage` (parameters, plan, signing key)
/// in a file, through the same [`Persistence`] as the MCU.
///
/// The record is written A/B with a CRC exactly as on the MCU; the file is the flash image.
pub struct FileStorage {
    path: Option<PathBuf>,
    store: Persistence<RamFlash<STORAGE_BYTES>>,
}

const SECTOR: u32 = 16 * 1024;
const STORAGE_BYTES: usize = 2 * SECTOR as usize;
const REGION: AbRegion = AbRegion {
    magic: BOARD_MAGIC,
    slot_a: 0,
    slot_b: SECTOR,
    slot_len: SECTOR,
};

impl FileStorage {
    /// Storage in `path` (created on the first save); `None` keeps it in memory only.
    pub fn open(path: Option<PathBuf>) -> Self {
        let image = path
            .as_ref()
            .and_then(|p| std::fs::read(p).ok())
            .unwrap_or_default();
        Self {
            path,
            store: Persistence::new(RamFlash::from_image(&image, SECTOR), REGION),
        }
    }

    /// Boots without the saved MAVLink signing key, and saves that at the next change: the
    /// bench recovery of a lost key (`firmware --signing-reset`).
    pub fn forget_signing_key(mut self) -> Self {
        self.store.forget_signing_key();
        self
    }

    /// Loads saved parameters and missions into the autopilot.
    pub fn load_into(&mut self, app: &mut App) -> Vec<String> {
        let l = self.store.load_into(app);
        let mut notes = Vec::new();
        if let Some(r) = l.params {
            notes.push(format!("parameters loaded ({r:?})"));
        }
        if l.mission_items > 0 {
            notes.push(format!("missions loaded ({} items)", l.mission_items));
        }
        if l.key_forgotten {
            notes.push("signing key forgotten (--signing-reset)".into());
        } else if l.signing_key {
            notes.push("signing key loaded: unsigned writes are refused".into());
        }
        if l.unreadable {
            notes.push("saved record unreadable: defaults kept".into());
        }
        notes
    }

    /// Saves what changed since the last save while disarmed, and answers a
    /// `MAV_CMD_PREFLIGHT_STORAGE` once saved (PX4 saves parameters as they change).
    pub fn save_changes(&mut self, app: &mut App) -> io::Result<()> {
        let done = self.store.service(app);
        if done.failed {
            return Err(io::Error::other("save of the board record failed"));
        }
        if done.saved {
            if let Some(p) = &self.path {
                // Write-then-rename: the file is never half written.
                let tmp = p.with_extension("tmp");
                std::fs::write(&tmp, self.store.flash().bytes())?;
                std::fs::rename(&tmp, p)?;
            }
        }
        Ok(())
    }
}

/// The ground-station link over UDP: telemetry to a fixed remote (QGroundControl listens on
/// 14550) and to every station that has sent us a frame lately (MAVSDK, pymavlink, test
/// clients). Each station has its own channel: the fixed remote 0, the others 1 to
/// [`MAX_GCS_PEERS`]; answers go back only to the station that asked, telemetry to all.
pub struct GcsUdp {
    socket: UdpSocket,
    remote: Option<SocketAddr>,
    /// Stations that spoke first, with when each was last heard.
    peers: [Option<(SocketAddr, Instant)>; MAX_GCS_PEERS],
}

/// Most stations besides the fixed remote a SITL link serves at once; a new one takes the
/// place of the one heard longest ago.
pub const MAX_GCS_PEERS: usize = 8;
/// A station silent this long is forgotten (QGroundControl sends a heartbeat every second).
pub const PEER_TIMEOUT: Duration = Duration::from_secs(10);

impl GcsUdp {
    /// Binds `bind` and sends to `remote` as well as to whoever speaks.
    pub fn open(bind: &str, remote: Option<&str>) -> io::Result<Self> {
        let socket = UdpSocket::bind(bind)?;
        socket.set_nonblocking(true)?;
        let remote = match remote {
            Some(r) => r.to_socket_addrs()?.next(),
            None => None,
        };
        Ok(Self {
            socket,
            remote,
            peers: [None; MAX_GCS_PEERS],
        })
    }

    /// The bound address.
    pub fn local_addr(&self) -> io::Result<SocketAddr> {
        self.socket.local_addr()
    }

    /// The channel of a station that sent a datagram at `now`: the fixed remote's, its own,
    /// a free one, or the one of the station heard longest ago.
    fn channel_of(&mut self, from: SocketAddr, now: Instant) -> u8 {
        if Some(from) == self.remote {
            return 0;
        }
        let slot = self
            .peers
            .iter()
            .position(|p| p.is_some_and(|(a, _)| a == from))
            .or_else(|| {
                self.peers.iter().position(|p| {
                    p.is_none_or(|(_, heard)| now.duration_since(heard) > PEER_TIMEOUT)
                })
            })
            .unwrap_or_else(|| {
                let heard = |i: &usize| self.peers.get(*i).copied().flatten().map(|(_, h)| h);
                (0..MAX_GCS_PEERS).min_by_key(heard).unwrap_or(0)
            });
        if let Some(p) = self.peers.get_mut(slot) {
            *p = Some((from, now));
        }
        slot as u8 + 1
    }

    /// Takes every waiting datagram into the autopilot, then sends its answers.
    pub fn service(&mut self, app: &mut App) -> io::Result<()> {
        self.receive(app)?;
        self.flush(app);
        Ok(())
    }

    /// Hands every datagram waiting to the autopilot, each on its station's channel.
    pub fn receive(&mut self, app: &mut App) -> io::Result<()> {
        let mut buf = [0u8; 2048];
        loop {
            match self.socket.recv_from(&mut buf) {
                Ok((n, from)) => {
                    let channel = self.channel_of(from, Instant::now());
                    app.on_gcs_datagram(channel, buf.get(..n).unwrap_or(&[]));
                }
                Err(e) if e.kind() == io::ErrorKind::WouldBlock => return Ok(()),
                // A peer that went away makes the next recv report it (ICMP); keep going.
                Err(e) if e.kind() == io::ErrorKind::ConnectionRefused => continue,
                Err(e) => return Err(e),
            }
        }
    }

    /// Sends what the autopilot has for the ground stations, one frame per datagram: to
    /// everyone, or back to the station it answers.
    pub fn flush(&mut self, app: &mut App) {
        app.drain_gcs_to(&mut |dest, frame| self.send(dest, frame));
    }

    /// Sends one frame the autopilot addressed to `dest`: to everyone (the remote and every
    /// station heard lately), or to the stations of one channel (0: the remote).
    pub fn send(&self, dest: Dest, frame: &[u8]) {
        let now = Instant::now();
        let live = |c: usize| {
            self.peers
                .get(c)
                .copied()
                .flatten()
                .filter(|(_, heard)| now.duration_since(*heard) <= PEER_TIMEOUT)
                .map(|(a, _)| a)
        };
        match dest {
            Dest::All => {
                for to in self
                    .remote
                    .into_iter()
                    .chain((0..MAX_GCS_PEERS).filter_map(live))
                {
                    let _ = self.socket.send_to(frame, to);
                }
            }
            Dest::Channel(0) => {
                if let Some(to) = self.remote {
                    let _ = self.socket.send_to(frame, to);
                }
            }
            Dest::Channel(c) => {
                if let Some(to) = live(usize::from(c) - 1) {
                    let _ = self.socket.send_to(frame, to);
                }
            }
        }
    }
}

#[derive(clap::Parser, Debug)]
#[command(
    name = "firmware",
    about = "The autopilot, host (SITL) build: flies a simulator over PX4's simulator MAVLink interface."
)]
struct Args {
    /// Simulator link: tcp:HOST:PORT (the simulator listens), udp:HOST:PORT, or serial:PATH.
    #[arg(long, default_value = "tcp:127.0.0.1:4560")]
    sim: SimEndpoint,
    /// How long to wait for the simulator to appear, s.
    #[arg(long, default_value_t = 30.0)]
    wait_s: f64,
    /// Give up after the simulator has been silent this long, s.
    #[arg(long, default_value_t = 5.0)]
    silence_s: f64,
    /// Local address of the ground-station link (PX4 SITL uses 18570).
    #[arg(long, default_value = "127.0.0.1:18570")]
    gcs_bind: String,
    /// Where telemetry goes besides every station that speaks (QGroundControl: 14550);
    /// `none` for no fixed remote.
    #[arg(long, default_value = "127.0.0.1:14550")]
    gcs_remote: String,
    /// File holding the saved parameters and missions (the SITL flash); `none` for none.
    #[arg(long, default_value = "sitl-storage.bin")]
    storage: String,
    /// Boot without the saved MAVLink signing key (the bench recovery of a lost key): the
    /// ground link accepts unsigned frames again until a new key is set.
    #[arg(long)]
    signing_reset: bool,
}

/// Entry point of the SITL build.
pub fn main() -> std::process::ExitCode {
    use clap::Parser;
    let args = Args::parse();
    let mut link = match connect(&args.sim, Duration::from_secs_f64(args.wait_s.max(0.0))) {
        Ok(l) => l,
        Err(e) => {
            eprintln!(
                "firmware: cannot reach the simulator at {:?}: {e}",
                args.sim
            );
            return std::process::ExitCode::FAILURE;
        }
    };
    let mut app = App::new();
    let mut storage =
        FileStorage::open((args.storage != "none").then(|| PathBuf::from(&args.storage)));
    if args.signing_reset {
        storage = storage.forget_signing_key();
    }
    for note in storage.load_into(&mut app) {
        eprintln!("firmware: {note}");
    }
    let remote = (args.gcs_remote != "none").then_some(args.gcs_remote.as_str());
    let mut gcs = match GcsUdp::open(&args.gcs_bind, remote) {
        Ok(g) => g,
        Err(e) => {
            eprintln!(
                "firmware: cannot open the ground link on {}: {e}",
                args.gcs_bind
            );
            return std::process::ExitCode::FAILURE;
        }
    };
    eprintln!(
        "firmware: connected to the simulator at {:?}; ground link on udp {} -> {}",
        args.sim, args.gcs_bind, args.gcs_remote
    );
    match run_with(
        link.as_mut(),
        &mut app,
        Duration::from_secs_f64(args.silence_s.max(0.1)),
        Some(&mut gcs),
        Some(&mut storage),
    ) {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            let h = app.sim_health();
            eprintln!(
                "firmware: simulator link ended: {e} ({} sensor frames, {} GPS frames)",
                h.sensor_frames, h.gps_frames
            );
            if e.kind() == io::ErrorKind::UnexpectedEof {
                std::process::ExitCode::SUCCESS
            } else {
                std::process::ExitCode::FAILURE
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mavlink::dialects::common::SETUP_SIGNING_DATA;

    #[test]
    fn a_signing_key_survives_a_reboot_and_the_bench_reset_forgets_it() {
        let path = std::env::temp_dir().join(format!("sitl-signing-{}.bin", std::process::id()));
        let _ = std::fs::remove_file(&path);
        let mut app = App::new();
        let mut storage = FileStorage::open(Some(path.clone()));
        storage.load_into(&mut app);
        let setup = SETUP_SIGNING_DATA {
            initial_timestamp: 1_000_000,
            target_system: 1,
            target_component: 1,
            secret_key: [42; 32],
        };
        assert!(app.signing_mut().setup(&setup, false));
        storage.save_changes(&mut app).expect("saved");

        let mut rebooted = App::new();
        FileStorage::open(Some(path.clone())).load_into(&mut rebooted);
        assert_eq!(rebooted.signing_mut().key(), Some(&[42; 32]));
        // The signing clock carries on from where it was saved, never older.
        assert!(rebooted.signing_mut().timestamp() >= 1_000_000);

        let mut reset = App::new();
        FileStorage::open(Some(path.clone()))
            .forget_signing_key()
            .load_into(&mut reset);
        assert_eq!(reset.signing_mut().key(), None);
        let _ = std::fs::remove_file(&path);
    }
}
