//! The autopilot application: the loop that both boards run.
//!
//! [`app::App`] owns every stage of `common` and the two MAVLink links; a board layer only
//! moves bytes. The MCU board (`mcu/`, in the binary) reads UARTs; the host board
//! ([`sitl`]) uses sockets, a pty or an in-process pipe, so `sim-host` can run this very loop
//! inside its own process.
#![cfg_attr(target_os = "none", no_std)]
// Nothing from outside may stop the autopilot: no unwrap, no expect, no unchecked index.
#![cfg_attr(
    not(test),
    deny(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing)
)]

pub mod app;
#[cfg(not(target_os = "none"))]
pub mod sitl;
