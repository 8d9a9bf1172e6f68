//! Everything that flies, once, for the MCU and for the host.
//!
//! `common` is `#![no_std]` and never allocates. Its folders follow the data flow of one
//! autopilot tick:
//!
//! ```text
//! sensors -> estimator -> (navigation, guidance) -> control -> actuator outputs
//! ```
//!
//! - [`math`]: the one definition of every frame change, rotation, geodetic conversion and
//!   the standard atmosphere, generic over the float type so the f64 plant and the f32
//!   firmware share it.
//! - [`params`]: how each stage declares its parameters (name, default, bounds, unit).
//! - [`sensors`]: the raw sensor samples the estimator consumes.
//! - [`estimator`]: attitude, position, velocity, air data and wind from raw sensors.
//! - [`navigation`]: the mission executor, path manager (waypoint switching with fillets),
//!   take-off, landing, return and loiter behaviours, mission validation and the geofence.
//! - [`guidance`]: vector-field path following: a line or orbit to course, altitude and
//!   airspeed commands.
//! - [`failsafe`]: what the aircraft does on its own when the ground link, GPS, the airspeed
//!   sensor or the geofence fails it.
//! - [`control`]: the successive-loop-closure autopilot of the thesis.
//! - [`link`]: MAVLink framing and the simulator interface (`HIL_*` messages).
//! - [`actuators`]: surface commands, their limits and their PX4 normalised form.
//! - [`gcs`]: the ground-station link logic (heartbeat, parameters, missions, commands,
//!   telemetry), transport-agnostic.
//! - [`storage`]: power-cut-safe persistence of parameters and missions in flash.
//!
//! Every stage is a plain struct with an explicit `step`/`update` taking its inputs and time
//! step: no globals, no I/O, no clock reads.
#![no_std]
#![forbid(unsafe_code)]

pub mod actuators;
pub mod control;
pub mod estimator;
pub mod failsafe;
pub mod gcs;
pub mod guidance;
pub mod link;
pub mod math;
pub mod navigation;
pub mod params;
pub mod sensors;
pub mod storage;
pub mod vehicle;
