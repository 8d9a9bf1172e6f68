//! The Ultra Stick 25e simulator: plant, analysis and the simulator side of the MAVLink link.
//!
//! - [`aircraft`]: the aircraft file (model parameters), read and validated;
//! - [`plant`]: the nonlinear 6-DOF model (aero, propulsion, rigid body, servos, RK4);
//! - [`environment`]: steady wind and Dryden turbulence;
//! - [`sensors`]: IMU, magnetometer, barometer, pitot and GPS models;
//! - [`flight`]: firmware in the loop: the plant flown by the autopilot over the link, a
//!   scripted ground station, the flight log and its figures;
//! - [`link`]: the simulator end of PX4's simulator MAVLink interface, in lock-step;
//! - [`campaign`]: Monte Carlo campaigns of dispersed flights, their verdicts and report;
//! - [`analysis`]: trim, linearisation, transfer functions, the linear-versus-nonlinear
//!   doublet check of the thesis, and linear-systems tools;
//! - [`mission_file`]: QGroundControl `.plan` and `QGC WPL 110` mission files, read into
//!   mission, geofence and rally items;
//! - [`report`]: tables, JSON, CSV and plots shared by every command;
//! - [`scenario`]: the closed-loop tests of thesis chapter 4 on the nonlinear plant;
//! - [`ulog_read`]: a reader of ULog flight logs, the autopilot's and PX4's.
#![warn(missing_docs)]

pub mod aircraft;
pub mod analysis;
pub mod campaign;
pub mod commands;
pub mod environment;
pub mod flight;
pub mod link;
pub mod mission_file;
pub mod plant;
pub mod report;
pub mod scenario;
pub mod sensors;
pub mod ulog_read;
