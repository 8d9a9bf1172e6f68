//! The host (SITL) board: the simulator link over TCP, UDP or a serial line (a pty), and the
//! same [`App`] the MCU runs.

use crate::app::App;
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

impl ByteLink for Tcp {
    fn read_timeout(&mut self, buf: &mut [u8], timeout: Duration) -> io::Result<usize> {
        self.0
            .set_read_timeout(Some(timeout.max(Duration::from_micros(1))))?;
        match self.0.read(buf) {
            Ok(0) => Err(io::Error::new(
                io::ErrorKind::UnexpectedEof,
                "simulator closed the connection",
            )),
            Ok(n) => Ok(n),
            Err(e)
                if matches!(
                    e.kind(),
                    io::ErrorKind::WouldBlock | io::ErrorKind::TimedOut
                ) =>
            {
                Ok(0)
            }
            Err(e) => Err(e),
        }
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
            Err(e)
                if matches!(
                    e.kind(),
                    io::ErrorKind::WouldBlock | io::ErrorKind::TimedOut
                ) =>
            {
                Ok(0)
            }
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
        use nix::poll::{poll, PollFd, PollFlags, PollTimeout};
        let ms = timeout.as_millis().clamp(0, i32::MAX as u128) as i32;
        let mut fds = [PollFd::new(self.0.as_fd(), PollFlags::POLLIN)];
        let ready = poll(
            &mut fds,
            PollTimeout::try_from(ms).unwrap_or(PollTimeout::MAX),
        )
        .map_err(io::Error::from)?;
        if ready == 0 {
            return Ok(0);
        }
        match self.0.read(buf) {
            Ok(0) => Err(io::Error::new(
                io::ErrorKind::UnexpectedEof,
                "serial line closed",
            )),
            r => r,
        }
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
    // Announce ourselves: a UDP simulator learns our address from the first datagram.
    let hb = crate::app::heartbeat_frame(app);
    link.write_all_bytes(&hb)?;
    let mut buf = [0u8; 2048];
    let mut last_rx = Instant::now();
    loop {
        let n = link.read_timeout(&mut buf, Duration::from_millis(100))?;
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
        app.on_sim_bytes(&buf[..n], &mut |b| out.extend_from_slice(b));
        if !out.is_empty() {
            link.write_all_bytes(&out)?;
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
    eprintln!("firmware: connected to the simulator at {:?}", args.sim);
    match run(
        link.as_mut(),
        &mut app,
        Duration::from_secs_f64(args.silence_s.max(0.1)),
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
