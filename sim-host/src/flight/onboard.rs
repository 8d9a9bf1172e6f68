//! Where the autopilot runs, and how the simulator reaches its ground link and its state.
//!
//! - [`InprocOnboard`]: the firmware's [`App`] inside the in-process transport.
//! - [`ThreadOnboard`]: the firmware in a thread of this process, on the firmware's own
//!   SITL byte link ([`firmware::sitl::connect`]) over a real TCP or UDP socket or a pty.
//!
//! A thread rather than a child process: the flight log records the autopilot's estimate and
//! setpoints beside the truth at every frame, and the ground-station script must reach the
//! autopilot; in one process both are a lock away. The thread runs the loop of
//! [`firmware::sitl::run`] (heartbeat first, then every byte of the simulator link into
//! [`App::on_sim_bytes`] and the answer back) with the application behind a mutex, because
//! `sitl::run` holds the application for the whole run.

use crate::link::lockstep::Lockstep;
use crate::link::transport::{Inproc, Transport};
use firmware::app::App;
use firmware::sitl::{self, SimEndpoint};
use std::io;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// Access to the autopilot's application: its ground link and, for the log, its state.
pub trait Onboard<T: Transport> {
    /// Runs `f` on the application. Called only between lock-step exchanges, when the
    /// autopilot is waiting for the next sensor frame.
    fn with_app<R>(&mut self, link: &mut Lockstep<T>, f: impl FnOnce(&mut App) -> R) -> R;
}

/// The application inside the in-process transport.
#[derive(Clone, Copy, Debug, Default)]
pub struct InprocOnboard;

impl Onboard<Inproc> for InprocOnboard {
    fn with_app<R>(&mut self, link: &mut Lockstep<Inproc>, f: impl FnOnce(&mut App) -> R) -> R {
        f(link.transport_mut().app_mut())
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
    fn with_app<R>(&mut self, _link: &mut Lockstep<T>, f: impl FnOnce(&mut App) -> R) -> R {
        // A poisoned lock means the firmware thread panicked mid-frame; its state is still
        // the last one it wrote, which is what the log wants.
        let mut g = self.app.lock().unwrap_or_else(|p| p.into_inner());
        f(&mut g)
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
