//! The choices a loop designer makes, with the thesis's as defaults.

use serde::Serialize;

/// The choices a designer makes; defaults are the thesis's.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct DesignInputs {
    /// Damping ratio of every loop.
    pub zeta: f64,
    /// Aileron deflection the roll design may use, deg (Appendix C: 45).
    pub roll_aileron_max_deg: f64,
    /// Roll error at which the aileron saturates, deg (Appendix C: 15).
    pub roll_error_max_deg: f64,
    /// Bandwidth separation of course from roll (Appendix C: 10).
    pub course_separation: f64,
    /// Bandwidth separation of sideslip from roll (Appendix C: 20).
    pub sideslip_separation: f64,
    /// Elevator deflection the pitch design may use, deg (the servo limit).
    pub pitch_elevator_max_deg: f64,
    /// Pitch error at which the elevator saturates, deg (the pitch-command limit).
    pub pitch_error_max_deg: f64,
    /// Bandwidth separation of altitude from pitch.
    pub altitude_separation: f64,
    /// Separation of the airspeed loops from the feedback low-pass pole.
    pub filter_separation: f64,
    /// Separation of the altitude loop from the feedback low-pass pole (the pitch loop adds
    /// its own lag there).
    pub altitude_filter_separation: f64,
    /// Integrator zero of the inner PID loops, as a fraction of their natural frequency.
    pub integrator_zero_fraction: f64,
    /// Integrator zero of the outer PI loops, as a fraction of their proportional bandwidth
    /// `2 zeta wn` (the pole-placement `ki = wn^2 ...` puts the zero at `wn / (2 zeta)`,
    /// which costs some 20 % overshoot against the thesis's 5 % requirement).
    pub outer_integrator_fraction: f64,
    /// Control sample time, s.
    pub sample_time_s: f64,
    /// Samples of delay in the flight software.
    pub delay_samples: f64,
    /// Phase margin the inner loops must keep with servo and delay, deg.
    pub inner_phase_margin_deg: f64,
}

impl DesignInputs {
    /// The delay in whole control periods, as the sampled model takes it.
    pub fn delay_periods(&self) -> u32 {
        self.delay_samples.round().max(0.0) as u32
    }
}

impl Default for DesignInputs {
    fn default() -> Self {
        Self {
            zeta: 0.707,
            roll_aileron_max_deg: 45.0,
            roll_error_max_deg: 15.0,
            course_separation: 15.0,
            sideslip_separation: 20.0,
            pitch_elevator_max_deg: 25.0,
            pitch_error_max_deg: 20.0,
            altitude_separation: 10.0,
            filter_separation: 4.0,
            altitude_filter_separation: 16.0,
            integrator_zero_fraction: 0.02,
            outer_integrator_fraction: 0.05,
            sample_time_s: 0.02,
            delay_samples: 2.0,
            inner_phase_margin_deg: 45.0,
        }
    }
}
