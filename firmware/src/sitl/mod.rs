//! The host (SITL) board: the simulator link over TCP, UDP or a serial line (a pty), and the
//! same [`App`] the MCU runs.
//!
//! One job per file, as on the MCU board (`mcu/`): the simulator's transports
//! (`transport.rs`), the UDP ground port (`ground.rs`), the file that stands for the flash
//! (`storage.rs`), the run loop (`run.rs`) and the command line (`args.rs`); this file wires
//! them together.

use crate::app::App;
use std::io;
use std::path::{Path, PathBuf};
use std::time::Duration;

mod args;
mod ground;
mod logs;
mod run;
mod storage;
mod transport;

use args::Args;
pub use ground::{GcsUdp, MAX_GCS_PEERS, PEER_TIMEOUT};
pub use logs::LogFiles;
pub use run::{run, run_with};
pub use storage::FileStorage;
pub use transport::{connect, read_serial, read_tcp, timed_out, ByteLink, SimEndpoint};

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
    // One ULog file per armed flight, in `logs/` beside the storage file.
    let mut logs = (args.storage != "none")
        .then(|| LogFiles::new(LogFiles::beside(Path::new(&args.storage)), &mut app));
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
        logs.as_mut(),
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
