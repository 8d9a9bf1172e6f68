//! The command line of the SITL build.

use super::transport::SimEndpoint;

#[derive(clap::Parser, Debug)]
#[command(
    name = "firmware",
    about = "The autopilot, host (SITL) build: flies a simulator over PX4's simulator MAVLink interface."
)]
pub(super) struct Args {
    /// Simulator link: tcp:HOST:PORT (the simulator listens), udp:HOST:PORT, or serial:PATH.
    #[arg(long, default_value = "tcp:127.0.0.1:4560")]
    pub(super) sim: SimEndpoint,
    /// How long to wait for the simulator to appear, s.
    #[arg(long, default_value_t = 30.0)]
    pub(super) wait_s: f64,
    /// Give up after the simulator has been silent this long, s.
    #[arg(long, default_value_t = 5.0)]
    pub(super) silence_s: f64,
    /// Local address of the ground-station link (PX4 SITL uses 18570).
    #[arg(long, default_value = "127.0.0.1:18570")]
    pub(super) gcs_bind: String,
    /// Where telemetry goes besides every station that speaks (QGroundControl: 14550);
    /// `none` for no fixed remote.
    #[arg(long, default_value = "127.0.0.1:14550")]
    pub(super) gcs_remote: String,
    /// File holding the saved parameters and missions (the SITL flash); `none` for none.
    #[arg(long, default_value = "sitl-storage.bin")]
    pub(super) storage: String,
    /// Boot without the saved MAVLink signing key (the bench recovery of a lost key): the
    /// ground link accepts unsigned frames again until a new key is set.
    #[arg(long)]
    pub(super) signing_reset: bool,
}
