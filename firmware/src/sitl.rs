//! The host (SITL) board layer.

/// Entry point of the SITL build.
pub fn main() -> std::process::ExitCode {
    println!("firmware (SITL): no simulator link yet");
    std::process::ExitCode::SUCCESS
}
