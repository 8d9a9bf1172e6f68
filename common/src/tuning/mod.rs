//! Tuning an airframe by the thesis's own method: identify its reduced models in flight, then
//! design the successive-loop-closure gains from them.
//!
//! - [`least_squares`]: linear least squares taken in a sample at a time (Givens rotations),
//!   fixed memory, `f32`.
//! - [`identify`]: the roll, pitch and airspeed models of the design and the course and
//!   altitude loops' kinematics, fitted from consecutive samples, each with its fit quality
//!   and the excitation it saw.
//! - [`autotune`]: what the vehicle flies to identify itself, the fits and the design run
//!   over control ticks, and the gains handed over when every loop meets its margins.
//! - [`design`]: the successive-loop-closure gains from those models, each loop's margins
//!   checked with servo and delay, in steps of bounded work that the vehicle can spread over
//!   control periods.
//!
//! Nothing here reads a clock or a sensor: the host's log reader (`sim-host identify`) and the
//! vehicle feed the same [`identify::Identifier`] the same samples.

pub mod autotune;
pub mod design;
pub mod identify;
pub mod least_squares;

#[cfg(test)]
mod tests;
