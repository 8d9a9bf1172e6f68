//! Sensor models: what the autopilot's sensors would read on the simulated airplane.
//!
//! Each model follows the University of Minnesota sensor library: `y = truth + bias + noise`,
//! the noise white and band-limited with Simulink's "noise power" `P`: at a sample time `Ts`
//! its variance is `P / Ts`. That is a fixed power spectral density, so the noise level stays
//! physically the same whatever rate a sensor is sampled at here. On top of the UMN model the
//! IMU gets a constant turn-on bias and a random-walk bias drift (the estimator must track
//! them), and the GPS a latency. The battery's power monitor (not in the UMN library) reads the
//! pack's voltage and current with white noise; an optional downward rangefinder reads the
//! boresight's slant range to the flat runway with white noise. Each sensor draws from its own seeded stream, so turning one
//! sensor off or changing its rate does not change the noise of another.

pub mod config;
pub mod models;

pub use config::{BatteryMonitorConfig, GpsConfig, RangefinderConfig, SensorConfig};
pub use models::{SensorFaults, SensorSuite, Truth};
