//! The simulator side of PX4's simulator MAVLink interface.
//!
//! [`transport`] moves bytes (TCP, UDP, a pty, or an in-process pipe into the firmware's own
//! loop); [`lockstep::Lockstep`] sends each sensor frame and waits for the autopilot's answer
//! before the plant may advance, so a run is deterministic and as fast as the CPU allows;
//! [`tlog`] records every frame both ways in the `.tlog` format pymavlink and QGroundControl
//! read; [`qemu`] runs the MCU image on QEMU's emulated STM32F405 with its ground UART
//! behind the [`bridge`] to UDP; [`budget`] gives the image's flash, RAM and instructions, and [`profile`] where its
//! instructions go, by function.

pub mod bridge;
pub mod budget;
pub mod lockstep;
pub mod profile;
pub mod qemu;
pub mod tlog;
pub mod transport;
