//! Gain design by successive loop closure (thesis chapter 3 and Appendix C, after Beard and
//! McLain) on reduced models, in bounded steps: the design `sim-host design` runs, here for
//! the vehicle too, so that a model identified in flight ([`super::identify`]) gives gains on
//! board with the same rules.
//!
//! Each loop is designed on its reduced model with the loops inside it taken as closed, and its
//! stability margins are computed with what the design formulas leave out: the servo (a
//! first-order lag at its bandwidth) and the flight software's delay (`delay_samples` plus half
//! a sample of zero-order hold: 50 ms at the thesis's 2 samples of 20 ms), and on the altitude
//! and airspeed loops the feedback low-pass (the base set's `FB_LPF_POLE`, 2 rad/s).
//!
//! Loops and rules (`zeta` = 0.707 throughout; [`DesignInputs`] holds every choice):
//! - roll (PID on aileron): `wn_phi = sqrt(|a_phi2| da_max sqrt(1 - zeta^2) / e_phi_max)`,
//!   `kp = wn^2 / a_phi2`, `kd = (2 zeta wn - a_phi1) / a_phi2` (Appendix C, with its
//!   `da_max` = 45 deg and `e_phi_max` = 15 deg). That `kp` keeps only a few degrees of phase
//!   margin once the servo and the delay are in the loop, so the design keeps Appendix C's
//!   damper and lowers `kp` by 1 % steps until the margin is 45 deg; `ki` puts the integrator
//!   zero at `wn / 50`;
//! - course (PI on commanded roll): `kp = 2 zeta wn Va / g` with `wn_chi = wn_phi / 15`
//!   rather than Appendix C's `/ 10` (with servo, delay and the roll loop's own overshoot,
//!   `/ 10` overshot a heading step by 11 % on the nonlinear plant, `/ 15` by about 1 %); the
//!   integrator's zero at 1/20 of the proportional bandwidth `2 zeta wn` (Appendix C's
//!   `ki = wn^2 Va / g` puts it inside the bandwidth: some 20 % overshoot);
//! - pitch (PID on elevator): `kp = sign(a_theta3) de_max / e_theta_max` (25 deg of elevator
//!   for the 20 deg pitch-command range), `wn_theta = sqrt(a_theta2 + kp a_theta3)`,
//!   `kd = (2 zeta wn - a_theta1) / a_theta3`, then `kp` limited by the same 45 deg phase
//!   margin, judged on the reduced short period `a_theta3 / (s^2 + a_theta1 s + a_theta2)`
//!   (or the model's own [`PitchResponse`]); `ki` at `wn / 50`;
//! - altitude (PI on commanded pitch), airspeed by pitch and airspeed by throttle: separated
//!   from the pitch loop by bandwidth (factor 10) and, since all three see their feedback
//!   through the low-pass, also kept below its pole (factor 4 for airspeed, 16 for altitude,
//!   which couples with the throttle loop in a climb); `kp`, `ki` by pole placement on
//!   `h / theta = Va / s` (the integrator's zero at 1/20 of `2 zeta wn`),
//!   `Va / theta = -g / (s + a_V1)` and `Va / throttle = a_V2 / (s + a_V1)`, the engine's lag
//!   in the throttle loop's margins.
//!
//! - sideslip (PI on the rudder, Appendix C): `wn_beta = wn_phi / 20`, by pole placement on
//!   `beta / dr = a_beta2 / (s + a_beta1)`, `kp = (2 zeta wn_beta - a_beta1) / a_beta2` (0
//!   where the side force alone damps more), `ki = wn_beta^2 / a_beta2`; on a model without a
//!   sideslip model (`a_beta2` 0) the base set's sideslip gains stay. The base set's trims
//!   stay.
//!
//! Margins: every inner loop at least [`GAIN_MARGIN_MIN_DB`] and [`INNER_PHASE_MARGIN_MIN_DEG`],
//! every outer loop [`GAIN_MARGIN_MIN_DB`] and [`OUTER_PHASE_MARGIN_MIN_DEG`] ([`judge`]),
//! read from `L(jw)` evaluated point by point ([`margins`]).
//!
//! - [`inputs`]: the designer's choices and the margin targets.
//! - [`model`]: the reduced models a design starts from.
//! - `transfer`: each loop's transfer at one frequency, and [`LoopGains`].
//! - [`margins`]: gain and phase margins from a sweep, one point at a time.
//! - [`verdict`]: the loops, their targets, and why a design fails.
//! - [`rules`]: the rules in closed form.
//! - [`designer`]: the design as a state machine of bounded steps, and [`design`] to run it
//!   through.

pub mod designer;
pub mod inputs;
pub mod margins;
pub mod model;
pub mod rules;
mod transfer;
pub mod verdict;

pub use designer::{design, Designed, Designer, LoopDesign, Loops, Step, POINTS_PER_STEP};
pub use inputs::{
    DesignInputs, GAIN_MARGIN_MIN_DB, INNER_PHASE_MARGIN_MIN_DEG, OUTER_PHASE_MARGIN_MIN_DEG,
};
pub use margins::Margins;
pub use model::{DesignModel, PitchResponse, QUASI_STEADY_ENGINE_POLE};
pub use rules::{Rules, GAIN_STEP, GAIN_STEPS};
pub use transfer::LoopGains;
pub use verdict::{judge, judge_margins, DesignFailure, Loop, Reason};

#[cfg(test)]
mod tests;
