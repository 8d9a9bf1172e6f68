//! The successive-loop-closure autopilot of the thesis (chapter 3).
//!
//! # Block diagram
//!
//! Each loop is closed around the one inside it; an outer loop is 5 to 10 times slower than its
//! inner loop, so the inner loop can be taken as unity gain when the outer one is designed.
//!
//! ```text
//! LATERAL (ailerons, rudder)                                           lateral.rs
//!
//!   course chi_c ─► [PI course, err wrapped to ±pi] ─► phi_c ±45° ─► [PI roll] ─┬─► aileron ±25°
//!                    (outer, ~1 s)                                   (inner)   │  = trim + kp e
//!                                                                  roll rate p ┘    + ki ∫e - kd p
//!                                                                 (rate damper, innermost)
//!   sideslip beta_c ─► [PI sideslip] ─► + trim + 0.065 · s/(s+2) · r ─► rudder ±25°
//!                                          (yaw damper through washout)
//!
//! LONGITUDINAL (elevator, throttle)                                longitudinal.rs
//!
//!   regime machine (Fig. 3-16) on e = h_c - LPF(h), band ± hysteresis picks the sources:
//!     take-off: theta_c = fixed,                 throttle = max
//!     climb:    theta_c = PI(Va_c - LPF(Va)),    throttle = max
//!     hold:     theta_c = PI(h_c - LPF(h)),      throttle = trim + PI(Va_c - LPF(Va))
//!     descent:  theta_c = PI(Va_c - LPF(Va)),    throttle = min
//!   theta_c ±20° ─► [PI pitch] ─┬─► elevator ±25° = trim + kp e + ki ∫e - kd q
//!                   pitch rate q┘ (rate damper, innermost)
//!   LPF = 2 rad/s first-order low-pass on altitude and airspeed (y[k+1] = 0.9608 y[k] + 0.0392 u[k])
//!   LON_LAW = 1: outside the take-off regime the total energy control gives theta_c and the
//!   throttle instead (throttle on the energy rate, pitch on its balance: longitudinal/tecs/)
//! ```
//!
//! All stages run once per tick at the sample time of the thesis, 0.02 s (50 Hz), but every step
//! takes its own `dt`, and the filter coefficients are derived from it. The thesis's
//! software-in-the-loop set-up delays the flight software's inputs by two samples
//! (`IntegerTimeDelay = 2`): that delay belongs to the simulation set-up (sensor path and
//! scheduling), not to these stages, which add no delay of their own beyond the strictly proper
//! low-pass filter of the thesis.
//!
//! # Pieces
//! - [`pid`]: the PID building block (saturation, conditional-integration anti-windup,
//!   derivative on the measurement or a measured rate, bumpless re-initialisation).
//! - [`filters`]: the feedback low-pass and the yaw-damper washout.
//! - [`inputs`]: the measured state the stages read, and the flags of what a tick refused.
//! - [`lateral`], [`longitudinal`]: the two autopilots, each with its gains and their
//!   parameters (`PARAMS`).
//! - [`autopilot`]: one tick of both, input validation, status; [`Autopilot`] is the entry
//!   point; [`GainSet`] holds one gain value of each stage.
//! - [`gains`]: the named sets of the thesis, composed from the stages' gains.
//!
//! Sign convention throughout: the University of Minnesota model's (see
//! [`crate::actuators::Surfaces`]).

pub mod autopilot;
pub mod filters;
pub mod gains;
pub mod inputs;
pub mod lateral;
pub mod longitudinal;
pub mod pid;
pub mod scaling;

#[cfg(test)]
mod closed_loop_tests;

pub use autopilot::{Autopilot, Commands, GainError, GainSet, Output, Status};
pub use inputs::{InputFlags, Measurements};
pub use lateral::{RollMode, YawMode};
pub use longitudinal::{LonMode, Regime};
