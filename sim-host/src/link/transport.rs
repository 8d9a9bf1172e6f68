//! Byte transports of the simulator link, simulator side.
//!
//! - TCP: the simulator listens (PX4's convention, port 4560) and the autopilot connects.
//! - UDP: the simulator binds a port and answers whoever sent the first datagram.
//! - pty: the simulator opens a pseudo-terminal pair in raw mode; the autopilot opens the
//!   slave end as it would a serial port (its path is printed).
//! - in-process: the firmware's own [`App`](firmware::app::App) runs inside this process; each
//!   send hands it the encoded bytes and collects its encoded answer, with no thread hop.

use firmware::sitl::{read_serial, read_tcp, timed_out};
use std::collections::VecDeque;
use std::io::{self, Write};
use std::net::{SocketAddr, TcpListener, TcpStream, UdpSocket};
use std::os::fd::{AsFd, OwnedFd};
use std::path::PathBuf;
use std::time::{Duration, Instant};

/// A byte transport, simulator side.
pub trait Transport {
    /// Sends all bytes.
    fn send(&mut self, bytes: &[u8]) -> io::Result<()>;
    /// Receives what is available, waiting at most `timeout`; `Ok(0)` means nothing arrived.
    fn recv(&mut self, buf: &mut [u8], timeout: Duration) -> io::Result<usize>;
    /// A description for messages ("tcp 127.0.0.1:4560", ...).
    fn describe(&self) -> String;
    /// What is known about an autopilot that has stopped answering (whether the process
    /// behind the link still runs, and what it said), for the error that ends the flight.
    fn diagnose(&mut self) -> Option<String> {
        None
    }
}

/// TCP: the simulator listens and accepts one autopilot.
pub struct TcpServer {
    stream: TcpStream,
    peer: SocketAddr,
}

impl TcpServer {
    /// Binds `addr`; `on_listening` runs once the port is open (e.g. to start the autopilot),
    /// then this waits up to `wait` for the autopilot to connect.
    pub fn listen(
        addr: &str,
        wait: Duration,
        on_listening: impl FnOnce(SocketAddr),
    ) -> io::Result<Self> {
        let listener = TcpListener::bind(addr)?;
        on_listening(listener.local_addr()?);
        Self::accept(&listener, Some(wait), || Ok(()))
    }

    /// Accepts one autopilot on `listener`, waiting at most `wait` (`None`: until it comes);
    /// `check` runs between attempts and ends the wait with its error (a process that was to
    /// connect has died, the user pressed Ctrl-C).
    pub fn accept(
        listener: &TcpListener,
        wait: Option<Duration>,
        mut check: impl FnMut() -> io::Result<()>,
    ) -> io::Result<Self> {
        listener.set_nonblocking(true)?;
        let deadline = wait.map(|w| Instant::now() + w);
        loop {
            match listener.accept() {
                Ok((stream, peer)) => {
                    stream.set_nonblocking(false)?;
                    stream.set_nodelay(true)?;
                    return Ok(Self { stream, peer });
                }
                Err(e) if timed_out(&e) => {
                    if deadline.is_some_and(|d| Instant::now() >= d) {
                        return Err(io::Error::new(
                            io::ErrorKind::TimedOut,
                            format!(
                                "no autopilot connected to {} within {:?}",
                                listener.local_addr()?,
                                wait.unwrap_or_default()
                            ),
                        ));
                    }
                    check()?;
                    std::thread::sleep(Duration::from_millis(5));
                }
                Err(e) => return Err(e),
            }
        }
    }
}

impl TcpServer {
    /// The connection, for a caller that reads and writes it itself.
    pub fn into_stream(self) -> TcpStream {
        self.stream
    }
}

impl Transport for TcpServer {
    fn send(&mut self, bytes: &[u8]) -> io::Result<()> {
        self.stream.write_all(bytes)
    }

    fn recv(&mut self, buf: &mut [u8], timeout: Duration) -> io::Result<usize> {
        read_tcp(&mut self.stream, buf, timeout, "autopilot")
    }

    fn describe(&self) -> String {
        format!("tcp (autopilot at {})", self.peer)
    }
}

/// UDP: the simulator binds a port; the autopilot's first datagram tells it where to answer.
pub struct UdpServer {
    socket: UdpSocket,
    peer: Option<SocketAddr>,
    pending: VecDeque<Vec<u8>>,
}

impl UdpServer {
    /// Binds `addr`.
    pub fn bind(addr: &str) -> io::Result<Self> {
        Ok(Self {
            socket: UdpSocket::bind(addr)?,
            peer: None,
            pending: VecDeque::new(),
        })
    }

    /// The bound address.
    pub fn local_addr(&self) -> io::Result<SocketAddr> {
        self.socket.local_addr()
    }

    /// Waits up to `wait` for the autopilot's first datagram.
    pub fn wait_for_peer(&mut self, wait: Duration) -> io::Result<SocketAddr> {
        let mut buf = [0u8; 2048];
        self.socket.set_read_timeout(Some(wait))?;
        match self.socket.recv_from(&mut buf) {
            Ok((n, from)) => {
                self.peer = Some(from);
                self.pending.push_back(buf[..n].to_vec());
                Ok(from)
            }
            Err(e) if timed_out(&e) => Err(io::Error::new(
                io::ErrorKind::TimedOut,
                format!("no autopilot datagram within {wait:?}"),
            )),
            Err(e) => Err(e),
        }
    }
}

impl Transport for UdpServer {
    fn send(&mut self, bytes: &[u8]) -> io::Result<()> {
        let peer = self.peer.ok_or_else(|| {
            io::Error::new(io::ErrorKind::NotConnected, "no autopilot has spoken yet")
        })?;
        self.socket.send_to(bytes, peer).map(|_| ())
    }

    fn recv(&mut self, buf: &mut [u8], timeout: Duration) -> io::Result<usize> {
        if let Some(p) = self.pending.pop_front() {
            let n = p.len().min(buf.len());
            buf[..n].copy_from_slice(&p[..n]);
            return Ok(n);
        }
        self.socket
            .set_read_timeout(Some(timeout.max(Duration::from_micros(1))))?;
        match self.socket.recv_from(buf) {
            Ok((n, from)) if Some(from) == self.peer => Ok(n),
            Ok(_) => Ok(0),
            Err(e) if timed_out(&e) => Ok(0),
            Err(e) => Err(e),
        }
    }

    fn describe(&self) -> String {
        match self.peer {
            Some(p) => format!("udp (autopilot at {p})"),
            None => "udp (no autopilot yet)".into(),
        }
    }
}

/// A pseudo-terminal pair: a real virtual serial line.
pub struct PtyServer {
    master: std::fs::File,
    slave_path: PathBuf,
    // Kept open so the line does not hang up before the autopilot opens it.
    _slave: OwnedFd,
}

impl PtyServer {
    /// Opens a raw-mode pty pair.
    pub fn open() -> io::Result<Self> {
        use nix::pty::openpty;
        use nix::sys::termios::{cfmakeraw, tcgetattr, tcsetattr, SetArg};
        let pty = openpty(None, None).map_err(io::Error::from)?;
        for fd in [pty.master.as_fd(), pty.slave.as_fd()] {
            let mut t = tcgetattr(fd).map_err(io::Error::from)?;
            cfmakeraw(&mut t);
            tcsetattr(fd, SetArg::TCSANOW, &t).map_err(io::Error::from)?;
        }
        let slave_path = nix::unistd::ttyname(pty.slave.as_fd()).map_err(io::Error::from)?;
        Ok(Self {
            master: std::fs::File::from(pty.master),
            slave_path,
            _slave: pty.slave,
        })
    }

    /// The serial device the autopilot opens.
    pub fn slave_path(&self) -> &std::path::Path {
        &self.slave_path
    }
}

impl Transport for PtyServer {
    fn send(&mut self, bytes: &[u8]) -> io::Result<()> {
        self.master.write_all(bytes)
    }

    fn recv(&mut self, buf: &mut [u8], timeout: Duration) -> io::Result<usize> {
        read_serial(&mut self.master, buf, timeout)
    }

    fn describe(&self) -> String {
        format!("pty {}", self.slave_path.display())
    }
}

/// The firmware's loop inside this process, fed through a byte pipe.
pub struct Inproc {
    app: firmware::app::App,
    from_app: VecDeque<u8>,
    logs: Option<firmware::sitl::LogFiles>,
}

impl Inproc {
    /// Boots an autopilot in this process. Like the socket board, it announces itself with a
    /// heartbeat first, so the frames on every transport are the same.
    pub fn new(mut app: firmware::app::App) -> Self {
        let hello = firmware::app::heartbeat_frame(&mut app);
        Self {
            app,
            from_app: hello.iter().copied().collect(),
            logs: None,
        }
    }

    /// The autopilot writes a ULog file per armed flight into `dir`, as the SITL board does
    /// beside its storage file.
    pub fn with_logs(mut self, dir: PathBuf) -> Self {
        self.logs = Some(firmware::sitl::LogFiles::new(dir, &mut self.app));
        self
    }

    /// The autopilot, for inspection.
    pub fn app(&self) -> &firmware::app::App {
        &self.app
    }

    /// The autopilot, to reach its ground link between exchanges.
    pub fn app_mut(&mut self) -> &mut firmware::app::App {
        &mut self.app
    }
}

impl Transport for Inproc {
    fn send(&mut self, bytes: &[u8]) -> io::Result<()> {
        let out = &mut self.from_app;
        self.app.on_sim_bytes(bytes, &mut |b| out.extend(b));
        if let Some(logs) = self.logs.as_mut() {
            logs.service(&mut self.app)?;
        }
        Ok(())
    }

    fn recv(&mut self, buf: &mut [u8], _timeout: Duration) -> io::Result<usize> {
        let n = self.from_app.len().min(buf.len());
        for (dst, src) in buf.iter_mut().zip(self.from_app.drain(..n)) {
            *dst = src;
        }
        Ok(n)
    }

    fn describe(&self) -> String {
        "in-process pipe".into()
    }
}
