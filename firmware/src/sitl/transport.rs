//! The simulator's transports, as the autopilot's end sees them: TCP (the simulator listens),
//! UDP and a serial line (a pty the simulator opened, or a real UART adapter), each behind
//! [`ByteLink`]. `sim-host`'s end reads its sockets and lines with the same functions.

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
