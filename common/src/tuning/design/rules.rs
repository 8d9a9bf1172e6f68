//! The design rules in closed form: each loop's gains from the model, the designer's inputs and
//! the loop inside it. What is not closed form, the attitude gains' limit by phase margin, is
//! the designer's ([`super::designer`]); a report may read the rules' own numbers (Appendix
//! C's roll design before that limit, say) here.

use super::inputs::DesignInputs;
use super::model::DesignModel;
use super::transfer::{LoopGains, Plant};
use crate::control::autopilot::GainSet;

/// The factor each step of the attitude gains' limit lowers the gain by: 1 %.
pub const GAIN_STEP: f32 = 0.99;

/// Steps of [`GAIN_STEP`] the attitude gains' limit may take, 400 (the gain down to 1.8 % of
/// the rule's): where none keeps the margin, the gain of the last step is judged, and fails.
pub const GAIN_STEPS: u16 = 400;

/// The rules, on one plant with one set of inputs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rules {
    pub(super) plant: Plant,
    pub(super) inputs: DesignInputs,
}

impl Rules {
    /// The rules on `model` with `inputs`, the feedback low-pass `base`'s.
    pub fn new(model: &DesignModel, inputs: &DesignInputs, base: &GainSet) -> Self {
        Self {
            plant: Plant {
                model: *model,
                pitch: model.pitch_response(),
                engine_pole: model.engine_pole(),
                servo_pole: model.servo_pole(),
                lp: base.longitudinal.feedback_lpf_pole,
                tau: inputs.delay_s(),
            },
            inputs: *inputs,
        }
    }

    fn zeta(&self) -> f32 {
        self.inputs.zeta
    }

    /// Appendix C's roll natural frequency,
    /// `wn_phi = sqrt(|a_phi2| da_max sqrt(1 - zeta^2) / e_phi_max)`, rad/s.
    pub fn roll_wn_appendix_c(&self) -> f32 {
        let i = &self.inputs;
        let z = self.zeta();
        libm::sqrtf(
            libm::fabsf(self.plant.model.a_phi2)
                * i.roll_aileron_max_deg
                * libm::sqrtf(1.0 - z * z)
                / i.roll_error_max_deg,
        )
    }

    /// Appendix C's roll gain, `wn_phi^2 / a_phi2`: where the limit by phase margin starts.
    pub fn roll_kp_appendix_c(&self) -> f32 {
        let wn = self.roll_wn_appendix_c();
        wn * wn / self.plant.model.a_phi2
    }

    /// Appendix C's rate damper, `(2 zeta wn_phi - a_phi1) / a_phi2`, kept whatever `kp`.
    fn roll_kd(&self) -> f32 {
        (2.0 * self.zeta() * self.roll_wn_appendix_c() - self.plant.model.a_phi1)
            / self.plant.model.a_phi2
    }

    /// The roll natural frequency `kp` gives, `sqrt(a_phi2 kp)`, rad/s (NaN for a `kp` of the
    /// wrong sign).
    pub fn roll_wn(&self, kp: f32) -> f32 {
        libm::sqrtf(self.plant.model.a_phi2 * kp)
    }

    /// The roll loop's gains at `kp`: the integrator's zero at `wn` times the inner fraction.
    pub fn roll(&self, kp: f32) -> LoopGains {
        let wn = libm::sqrtf((self.plant.model.a_phi2 * kp).max(0.0));
        LoopGains {
            kp,
            ki: kp * wn * self.inputs.integrator_zero_fraction,
            kd: self.roll_kd(),
        }
    }

    /// Course, `wn_chi = wn_phi / separation` (times `share`): `kp = 2 zeta wn_chi Va / g`,
    /// the integrator's zero at the outer fraction of `2 zeta wn_chi`. Gains and `wn_chi`.
    pub fn course(&self, wn_phi: f32, share: f32) -> (LoopGains, f32) {
        let wn = share * wn_phi / self.inputs.course_separation;
        let kp = 2.0 * self.zeta() * wn * self.plant.model.va / self.plant.model.g;
        let ki = kp * 2.0 * self.zeta() * wn * self.inputs.outer_integrator_fraction;
        (LoopGains { kp, ki, kd: 0.0 }, wn)
    }

    /// Sideslip on `beta / dr = a_beta2 / (s + a_beta1)` (Appendix C), by pole placement at
    /// `wn_beta = wn_phi / separation` (times `share`): `kp = (2 zeta wn_beta - a_beta1) /
    /// a_beta2`, `ki = wn_beta^2 / a_beta2`. Where the aircraft's own side force damps the
    /// sideslip more than the placement asks (`a_beta1 > 2 zeta wn_beta`), `kp` is 0, not the
    /// negative gain that would take damping away. Gains and `wn_beta`.
    pub fn sideslip(&self, wn_phi: f32, share: f32) -> (LoopGains, f32) {
        let m = &self.plant.model;
        let wn = share * wn_phi / self.inputs.sideslip_separation;
        let kp = ((2.0 * self.zeta() * wn - m.a_beta1) / m.a_beta2).max(0.0);
        let ki = wn * wn / m.a_beta2;
        (LoopGains { kp, ki, kd: 0.0 }, wn)
    }

    /// The pitch rule's gain, `sign(a_theta3) de_max / e_theta_max`: where the limit by phase
    /// margin starts.
    pub fn pitch_kp_nominal(&self) -> f32 {
        let i = &self.inputs;
        libm::copysignf(1.0, self.plant.model.a_theta3) * i.pitch_elevator_max_deg
            / i.pitch_error_max_deg
    }

    /// The pitch natural frequency `kp` gives, `sqrt(a_theta2 + kp a_theta3)` (0 where that
    /// is negative), rad/s.
    pub fn pitch_wn(&self, kp: f32) -> f32 {
        libm::sqrtf((self.plant.model.a_theta2 + kp * self.plant.model.a_theta3).max(0.0))
    }

    /// The pitch loop's gains at `kp`: the damper from the nominal design,
    /// `(2 zeta wn - a_theta1) / a_theta3`, the integrator's zero at `wn` times the inner
    /// fraction.
    pub fn pitch(&self, kp: f32) -> LoopGains {
        let wn_nominal = self.pitch_wn(self.pitch_kp_nominal());
        let kd = (2.0 * self.zeta() * wn_nominal - self.plant.model.a_theta1)
            / self.plant.model.a_theta3;
        LoopGains {
            kp,
            ki: kp * self.pitch_wn(kp) * self.inputs.integrator_zero_fraction,
            kd,
        }
    }

    /// Altitude on `h / theta = Va / s` (the flight path's lag left to the margins): `wn_h` the
    /// lower of `wn_theta / separation` and the feedback pole over its separation (times
    /// `share`); `kp = 2 zeta wn_h / Va`, the integrator's zero at the outer fraction of
    /// `2 zeta wn_h`. Gains and `wn_h`.
    pub fn altitude(&self, wn_theta: f32, share: f32) -> (LoopGains, f32) {
        let i = &self.inputs;
        let wn = share
            * (wn_theta / i.altitude_separation).min(self.plant.lp / i.altitude_filter_separation);
        let kp = 2.0 * self.zeta() * wn / self.plant.model.va;
        let ki = kp * 2.0 * self.zeta() * wn * i.outer_integrator_fraction;
        (LoopGains { kp, ki, kd: 0.0 }, wn)
    }

    /// Airspeed by pitch on `Va / theta = -g / (s + a_V1)`, by pole placement at the lower of
    /// `wn_theta / separation` and the feedback pole over the filter separation (times
    /// `share`). Gains and `wn`.
    pub fn airspeed_pitch(&self, wn_theta: f32, share: f32) -> (LoopGains, f32) {
        let i = &self.inputs;
        let p = &self.plant;
        let wn = share * (wn_theta / i.altitude_separation).min(p.lp / i.filter_separation);
        let kp = (p.model.a_v1 - 2.0 * self.zeta() * wn) / p.model.g;
        let ki = -wn * wn / p.model.g;
        (LoopGains { kp, ki, kd: 0.0 }, wn)
    }

    /// Airspeed by throttle on `Va / throttle = a_V2 / (s + a_V1)` (the engine's lag left to
    /// the margins), by pole placement at the feedback pole over the filter separation (times
    /// `share`). Gains and `wn`.
    pub fn airspeed_throttle(&self, share: f32) -> (LoopGains, f32) {
        let p = &self.plant;
        let wn = share * p.lp / self.inputs.filter_separation;
        let kp = (2.0 * self.zeta() * wn - p.model.a_v1) / p.model.a_v2;
        let ki = wn * wn / p.model.a_v2;
        (LoopGains { kp, ki, kd: 0.0 }, wn)
    }
}
