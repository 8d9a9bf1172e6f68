//! The autopilot.
//!
//! One loop, two boards: on the STM32F405 (`thumbv7em-none-eabihf`) it reads its sensors and
//! talks to the ground over UARTs; on the host (SITL) the same loop talks to `sim-host` and
//! the ground station over sockets.
//!
//! - MCU: `cargo run --profile mcu -p firmware --target thumbv7em-none-eabihf` boots the image in
//!   QEMU's `netduinoplus2` (STM32F405) through the runner in `.cargo/config.toml`; QEMU's
//!   flags after `--` (`-serial tcp:127.0.0.1:4560,nodelay=on -serial udp:...`) put its UARTs
//!   on a running `sim-host sim` and a ground station. `sim-host fly --link qemu` flies this
//!   image in the loop (docs/PIL.md).
//! - Host: `cargo run -p firmware` runs the SITL build.
#![cfg_attr(target_os = "none", no_std)]
#![cfg_attr(target_os = "none", no_main)]

#[cfg(target_os = "none")]
mod mcu;
#[cfg(not(target_os = "none"))]
fn main() -> std::process::ExitCode {
    firmware::sitl::main()
}
