//! The Ultra Stick 25e simulator: plant, analysis and the simulator side of the MAVLink link.
//!
//! - [`aircraft`]: the aircraft file (model parameters), read and validated;
//! - [`plant`]: the nonlinear 6-DOF model (aero, propulsion, rigid body, servos, RK4);
//! - [`analysis`]: trim, linearisation, transfer functions and the linear-versus-nonlinear
//!   doublet check of the thesis;
//! - [`report`]: tables, JSON, CSV and plots shared by every command.
#![warn(missing_docs)]

pub mod aircraft;
pub mod analysis;
pub mod commands;
pub mod plant;
pub mod report;
