//! Everything that flies, once, for the MCU and for the host.
//!
//! `common` is `#![no_std]` and never allocates. Its folders follow the data flow of one
//! autopilot tick:
//!
//! ```text
//! sensors -> estimator -> vehicle (commander) -> navigation -> guidance -> control -> actuators
//! ```
//!
//! - [`sensors`]: the samples a sensor frame carries, and their plausibility limits.
//! - [`estimator`]: attitude, position, velocity, air data and wind from raw sensors.
//! - [`vehicle`]: the stages wired together: flight modes, requests, the commander (arming,
//!   mode entry, failsafe reactions, the navigator hand-off), the one parameter registry, the
//!   clock that follows the sensor frames, and the snapshot the vehicle reports.
//! - [`battery`]: the battery monitor: charge used, state of charge, time remaining and the
//!   warning level, from the power monitor's voltage and current.
//! - [`failsafe`]: what the aircraft does on its own when the ground link, GPS, the airspeed
//!   sensor, the geofence or the battery fails it.
//! - [`navigation`]: the plan (stored mission, fence, rally points), the navigator and its
//!   behaviours (mission, take-off, loiter, landing, return), the path manager (fillets),
//!   mission checks and the geofence.
//! - [`guidance`]: vector-field path following: a line or orbit to course, altitude and
//!   airspeed commands.
//! - [`control`]: the successive-loop-closure autopilot of the thesis, each stage with its
//!   gains.
//! - [`actuators`]: surface commands, their limits and their PX4 normalised form.
//!
//! Beside the tick, reading what it flew:
//! - [`tuning`]: the reduced models identified from flight data, and the design by successive
//!   loop closure on them, in steps of bounded work.
//!
//! Beside the tick:
//! - [`params`]: how each stage declares its parameters, and the one store of their values.
//! - [`gcs`]: the ground-station protocols (routing, parameters, missions, commands,
//!   telemetry), transport-agnostic.
//! - [`link`]: MAVLink framing and the simulator interface (`HIL_*` messages).
//! - [`crc`]: the CRC-32 of the stored records and files, MAVLink's CRC-16.
//! - [`decimal`]: numbers in texts as fixed-point decimals, without float formatting.
//! - [`storage`]: power-cut-safe persistence of parameters and missions in flash, and the
//!   flight logs' region.
//! - [`logger`]: the flight log: PX4-named topics at their rates, into a ring the board
//!   drains to its storage.
//! - [`ulog`]: PX4's ULog format, the flight log's encoding.
//! - [`math`]: the one definition of every frame change, rotation, geodetic conversion,
//!   gravity and the standard atmosphere, generic over the float type so the f64 plant and
//!   the f32 firmware share it.
//!
//! Every stage is a plain struct with an explicit `step`/`update` taking its inputs and time
//! step: no globals, no I/O, no clock reads.
#![no_std]
#![forbid(unsafe_code)]
// Nothing from outside may stop the autopilot: no unwrap, no expect, no unchecked index.
#![cfg_attr(
    not(test),
    deny(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing)
)]

pub mod actuators;
pub mod battery;
pub mod control;
pub mod crc;
pub mod decimal;
pub mod estimator;
pub mod failsafe;
pub mod gcs;
pub mod guidance;
pub mod link;
pub mod logger;
pub mod math;
pub mod navigation;
pub mod params;
pub mod sensors;
pub mod storage;
pub mod tuning;
pub mod ulog;
pub mod vehicle;
