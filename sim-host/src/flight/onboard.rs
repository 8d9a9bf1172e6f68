//! Where the autopilot runs, and how the simulator reaches its ground link and its state.
//!
//! - [`InprocOnboard`]: the firmware's [`App`] inside the in-process transport.
//! - [`ThreadOnboard`]: the firmware in a thread of this process, on the firmware's own
//!   SITL byte link ([`firmware::sitl::connect`]) over a real TCP or UDP socket or a pty.
//! - [`OutsideOnboard`]: an autopilot this process cannot look into (the MCU image in QEMU,
//!   an autopilot that connected to `sim-host sim`): the scripted station, if any, speaks to
//!   its ground link over UDP, and the log holds the truth and the autopilot's answers only.
//!
//! A thread rather than a child process: the flight log records the autopilot's estimate and
//! setpoints beside the truth at every frame, and the ground-station script must reach the
//! autopilot; in one process both are a lock away. The thread runs the loop of
//! [`firmware::sitl::run`] (heartbeat first, then every byte of the simulator link into
//! [`App::on_sim_bytes`] and the answer back) with the application behind a mutex, because
//! `sitl::run` holds the application for the whole run.

use crate::link::lockstep::Lockstep;
use crate::link::transport::{Inproc, Transport};
use common::gcs::Dest;
use common::link::framing::FrameParser;
use firmware::app::App;
use firmware::sitl::{self, timed_out, SimEndpoint};
use mavlink::dialects::common::MavMessage;
use std::io;
use std::net::{SocketAddr, UdpSocket};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// What the scripted station waits for after it has spoken, on a link where answers take
/// time (in this process they are there at once).
pub enum Await<'a> {
    /// Nothing: take what has arrived.
    Nothing,
    /// The first frame `done` accepts (an acknowledgement, the next mission request), for at
    /// most [`ANSWER_WAIT`].
    Answer(&'a mut dyn FnMut(&MavMessage) -> bool),
    /// Whatever arrives within this time (the last telemetry of a flight).
    Linger(Duration),
}

/// How long the scripted station waits for an answer over a real link: far longer than a
/// ground link's round trip, short enough that a lost answer costs little.
pub const ANSWER_WAIT: Duration = Duration::from_secs(2);

/// Access to the autopilot: its ground link for the scripted station and, where the
/// application runs in this process, its state for the log.
pub trait Onboard<T: Transport> {
    /// Runs `f` on the application when it runs in this process (`None`: an autopilot seen
    /// only through its links). Called only between lock-step exchanges, when the autopilot
    /// is waiting for the next sensor frame.
    fn with_app<R>(&mut self, link: &mut Lockstep<T>, f: impl FnOnce(&mut App) -> R) -> Option<R>;

    /// The scripted station's turn on the autopilot's ground link: `bytes` (a frame, or
    /// nothing) to the autopilot, and back everything it has sent the station since. The
    /// station takes the application's one outgoing queue: with `others`, every frame taken
    /// is also handed on there with its destination, for the other stations of a port beside
    /// the script (broadcasts are owed to them as well).
    fn talk(
        &mut self,
        link: &mut Lockstep<T>,
        bytes: &[u8],
        _wait: Await,
        mut others: Option<&mut Vec<(Dest, Vec<u8>)>>,
    ) -> Vec<u8> {
        self.with_app(link, |app| {
            if !bytes.is_empty() {
                app.on_gcs_bytes(bytes);
            }
            let mut out = Vec::new();
            app.drain_gcs_to(&mut |dest, frame| {
                if dest.reaches(0) {
                    out.extend_from_slice(frame);
                }
                if let Some(o) = others.as_mut() {
                    o.push((dest, frame.to_vec()));
                }
            });
            out
        })
        .unwrap_or_default()
    }
}

/// The application inside the in-process transport.
#[derive(Clone, Copy, Debug, Default)]
pub struct InprocOnboard;

impl Onboard<Inproc> for InprocOnboard {
    fn with_app<R>(
        &mut self,
        link: &mut Lockstep<Inproc>,
        f: impl FnOnce(&mut App) -> R,
    ) -> Option<R> {
        Some(f(link.transport_mut().app_mut()))
    }
}

/// An autopilot outside this process, reached through its links only.
pub struct OutsideOnboard {
    station: Option<StationSocket>,
}

impl OutsideOnboard {
    /// No ground station here: whoever flies the autopilot does so on its own ground link.
    pub fn unattended() -> Self {
        Self { station: None }
    }

    /// The scripted station speaks to the autopilot's ground link at `ground` (UDP).
    pub fn with_station(ground: SocketAddr) -> io::Result<Self> {
        Ok(Self {
            station: Some(StationSocket::open(ground)?),
        })
    }
}

impl<T: Transport> Onboard<T> for OutsideOnboard {
    fn with_app<R>(
        &mut self,
        _link: &mut Lockstep<T>,
        _f: impl FnOnce(&mut App) -> R,
    ) -> Option<R> {
        None
    }

    /// Other stations reach this autopilot on its own ground link: nothing to hand on.
    fn talk(
        &mut self,
        _link: &mut Lockstep<T>,
        bytes: &[u8],
        wait: Await,
        _others: Option<&mut Vec<(Dest, Vec<u8>)>>,
    ) -> Vec<u8> {
        match self.station.as_mut() {
            Some(s) => s.talk(bytes, wait),
            None => Vec::new(),
        }
    }
}

/// The scripted station's UDP socket to an autopilot's ground link, as QGroundControl's: it
/// sends one frame per datagram and hears the frames the ground link sends back.
struct StationSocket {
    socket: UdpSocket,
    to: SocketAddr,
    parser: FrameParser,
}

impl StationSocket {
    fn open(to: SocketAddr) -> io::Result<Self> {
        let socket = UdpSocket::bind(("127.0.0.1", 0))?;
        Ok(Self {
            socket,
            to,
            parser: FrameParser::new(),
        })
    }

    /// Sends `bytes`, then reads as `wait` says. A station whose autopilot has gone reads
    /// nothing; the simulator link reports that.
    fn talk(&mut self, bytes: &[u8], mut wait: Await) -> Vec<u8> {
        if !bytes.is_empty() {
            let _ = self.socket.send_to(bytes, self.to);
        }
        let start = Instant::now();
        let until = match wait {
            Await::Nothing => Duration::ZERO,
            Await::Answer(_) => ANSWER_WAIT,
            Await::Linger(d) => d,
        };
        let mut out = Vec::new();
        let mut buf = [0u8; 2048];
        loop {
            let left = until.saturating_sub(start.elapsed());
            let r = if left.is_zero() {
                self.socket
                    .set_nonblocking(true)
                    .and_then(|()| self.socket.recv_from(&mut buf))
            } else {
                self.socket
                    .set_nonblocking(false)
                    .and_then(|()| self.socket.set_read_timeout(Some(left)))
                    .and_then(|()| self.socket.recv_from(&mut buf))
            };
            let n = match r {
                Ok((n, from)) if from == self.to => n,
                Ok(_) => continue,
                Err(e)
                    if matches!(
                        e.kind(),
                        io::ErrorKind::ConnectionRefused | io::ErrorKind::Interrupted
                    ) =>
                {
                    continue
                }
                Err(e) if timed_out(&e) && left.is_zero() => return out,
                Err(e) if timed_out(&e) => continue,
                Err(_) => return out,
            };
            out.extend_from_slice(&buf[..n]);
            let mut answered = false;
            if let Await::Answer(done) = &mut wait {
                self.parser
                    .push(&buf[..n], |f| answered |= done(&f.message));
            }
            if answered {
                // What else has already arrived comes with it.
                out.extend(self.talk(&[], Await::Nothing));
                return out;
            }
        }
    }
}

/// The firmware in a thread of this process, on a real socket or pty.
pub struct ThreadOnboard {
    app: Arc<Mutex<App>>,
    stop: Arc<AtomicBool>,
    handle: Option<JoinHandle<io::Result<()>>>,
}

impl ThreadOnboard {
    /// Stops the firmware thread and returns how its link ended.
    pub fn stop(mut self) -> io::Result<()> {
        self.stop.store(true, Ordering::Relaxed);
        match self.handle.take().map(JoinHandle::join) {
            Some(Ok(r)) => r,
            Some(Err(_)) => Err(io::Error::other("the firmware thread panicked")),
            None => Ok(()),
        }
    }
}

impl Drop for ThreadOnboard {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(h) = self.handle.take() {
            let _ = h.join();
        }
    }
}

impl<T: Transport> Onboard<T> for ThreadOnboard {
    fn with_app<R>(&mut self, _link: &mut Lockstep<T>, f: impl FnOnce(&mut App) -> R) -> Option<R> {
        // A poisoned lock means the firmware thread panicked mid-frame; its state is still
        // the last one it wrote, which is what the log wants.
        let mut g = self.app.lock().unwrap_or_else(|p| p.into_inner());
        Some(f(&mut g))
    }
}

/// Starts the firmware in a thread: it connects to the simulator at `endpoint` (retrying for
/// `wait`), announces itself with a heartbeat and answers the simulator until stopped, until
/// the link closes, or until the simulator has been silent for `silence`.
pub fn spawn_firmware(
    endpoint: SimEndpoint,
    app: App,
    wait: Duration,
    silence: Duration,
) -> ThreadOnboard {
    let app = Arc::new(Mutex::new(app));
    let stop = Arc::new(AtomicBool::new(false));
    let (a, s) = (app.clone(), stop.clone());
    let handle = std::thread::spawn(move || -> io::Result<()> {
        let mut link = sitl::connect(&endpoint, wait)?;
        let hello = {
            let mut g = a.lock().unwrap_or_else(|p| p.into_inner());
            firmware::app::heartbeat_frame(&mut g)
        };
        link.write_all_bytes(&hello)?;
        let mut buf = [0u8; 4096];
        let mut out = Vec::with_capacity(512);
        let mut last_rx = Instant::now();
        while !s.load(Ordering::Relaxed) {
            let n = link.read_timeout(&mut buf, Duration::from_millis(20))?;
            if n == 0 {
                if last_rx.elapsed() > silence {
                    return Err(io::Error::new(
                        io::ErrorKind::TimedOut,
                        "simulator silent".to_string(),
                    ));
                }
                continue;
            }
            last_rx = Instant::now();
            out.clear();
            {
                let mut g = a.lock().unwrap_or_else(|p| p.into_inner());
                g.on_sim_bytes(&buf[..n], &mut |b| out.extend_from_slice(b));
            }
            if !out.is_empty() {
                link.write_all_bytes(&out)?;
            }
        }
        Ok(())
    });
    ThreadOnboard {
        app,
        stop,
        handle: Some(handle),
    }
}
