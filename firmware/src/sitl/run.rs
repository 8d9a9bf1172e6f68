//! The run loop: every byte of the simulator link into the application and its answers back,
//! with the ground port and the storage served between reads.

use super::ground::GcsUdp;
use super::logs::LogFiles;
use super::storage::FileStorage;
use super::transport::ByteLink;
use crate::app::App;
use common::gcs::logs::{LogStore, NoLogs};
use std::io;
use std::time::{Duration, Instant};

/// Runs the autopilot against a simulator link until the link closes or stays silent for
/// `silence`.
pub fn run(link: &mut dyn ByteLink, app: &mut App, silence: Duration) -> io::Result<()> {
    run_with(link, app, silence, None, None, None)
}

/// [`run`] with a ground-station link, persistent storage and flight-log files.
pub fn run_with(
    link: &mut dyn ByteLink,
    app: &mut App,
    silence: Duration,
    mut gcs: Option<&mut GcsUdp>,
    mut storage: Option<&mut FileStorage>,
    mut logs: Option<&mut LogFiles>,
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
        if let Some(l) = logs.as_deref_mut() {
            if let Err(e) = l.service(app) {
                // A log that cannot be written stops logging, never flying.
                eprintln!("firmware: flight log: {e}; logging stopped");
                app.flight_log_mut().enable(false);
                logs = None;
            }
        }
        if let Some(g) = gcs.as_deref_mut() {
            if app.ground_link().logs_busy() {
                // Without a log folder the list is empty.
                let store: &mut dyn LogStore = match logs.as_deref_mut() {
                    Some(l) => l,
                    None => &mut NoLogs,
                };
                app.serve_logs(store, usize::MAX);
                g.flush(app);
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
