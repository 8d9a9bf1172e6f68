//! The autotune's parameters: its safety limits, the servo it identifies through, the fit
//! quality it accepts, and the coefficients it identified (written by the vehicle, read by a
//! station).

use crate::math::DEG;
use crate::math::GRAVITY;
use crate::param;
use crate::params::{independent, Group, ParamDef};
use crate::tuning::design::DesignModel;

/// No model yet: every coefficient 0.
pub const UNIDENTIFIED: DesignModel = DesignModel {
    va: 0.0,
    a_phi1: 0.0,
    a_phi2: 0.0,
    a_beta1: 0.0,
    a_beta2: 0.0,
    a_theta1: 0.0,
    a_theta2: 0.0,
    a_theta3: 0.0,
    a_v1: 0.0,
    a_v2: 0.0,
    a_gamma: 0.0,
    engine_pole: None,
    servo_bandwidth_hz: 0.0,
    g: GRAVITY,
    pitch_response: None,
};

/// What the autotune is flown with.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AutotuneParams {
    /// Bank beyond which the autotune gives up, rad; the roll excitation is 0.4 of it.
    pub bank_max: f32,
    /// Pitch change from the level pitch beyond which it gives up, rad; the pitch excitation
    /// is 0.4 of it.
    pub pitch_max: f32,
    /// Height it may lose below where it started, m.
    pub height_loss_m: f32,
    /// Throttle step of the airspeed excitation (0..1).
    pub throttle_step: f32,
    /// Least share of an attitude's acceleration or the airspeed's rate a fit must explain.
    pub r2_min: f32,
    /// The surface servos' bandwidth, Hz.
    pub servo_bw_hz: f32,
    /// The surface servos' rate limit, rad/s.
    pub servo_rate: f32,
}

/// Parameters of the autotune.
pub const PARAMS: Group<AutotuneParams> = Group {
    name: "Autotune",
    params: &[
        param!(
            ParamDef::real("ATUN_BANK_MAX", 35.0, 10.0, 60.0, "deg", "Autotune: bank that aborts it"),
            AutotuneParams => bank_max, unit DEG
        ),
        param!(
            ParamDef::real(
                "ATUN_PITCH_MAX",
                15.0,
                5.0,
                30.0,
                "deg",
                "Autotune: pitch change from level that aborts it"
            ),
            AutotuneParams => pitch_max, unit DEG
        ),
        param!(
            ParamDef::real("ATUN_HGT_LOSS", 30.0, 5.0, 200.0, "m", "Autotune: height loss that aborts it"),
            AutotuneParams => height_loss_m
        ),
        param!(
            ParamDef::real("ATUN_THR_STEP", 0.2, 0.05, 0.5, "", "Autotune: throttle step"),
            AutotuneParams => throttle_step
        ),
        param!(
            ParamDef::real("ATUN_R2_MIN", 0.6, 0.1, 0.99, "", "Autotune: least fit quality (R^2)"),
            AutotuneParams => r2_min
        ),
        param!(
            ParamDef::real("SERVO_BW", 8.0, 1.0, 50.0, "Hz", "Surface servos' bandwidth"),
            AutotuneParams => servo_bw_hz
        ),
        param!(
            ParamDef::real("SERVO_RATE", 150.0, 20.0, 1000.0, "deg/s", "Surface servos' rate limit"),
            AutotuneParams => servo_rate, unit DEG
        ),
    ],
    base: || AutotuneParams {
        bank_max: 35.0 * DEG,
        pitch_max: 15.0 * DEG,
        height_loss_m: 30.0,
        throttle_step: 0.2,
        r2_min: 0.6,
        servo_bw_hz: 8.0,
        servo_rate: 150.0 * DEG,
    },
    check: independent,
};

/// The coefficients the last autotune identified, as parameters a station reads (0: none
/// yet), the model its design ran on. Written by the vehicle; a value a station writes is
/// overwritten by the next autotune and used by nothing.
pub const IDENTIFIED: Group<DesignModel> = Group {
    name: "Autotune result",
    params: &[
        param!(
            ParamDef::real("ATUN_A_PHI1", 0.0, -1e4, 1e4, "1/s", "Identified a_phi1"),
            DesignModel => a_phi1
        ),
        param!(
            ParamDef::real("ATUN_A_PHI2", 0.0, -1e5, 1e5, "1/s^2", "Identified a_phi2"),
            DesignModel => a_phi2
        ),
        param!(
            ParamDef::real("ATUN_A_BET1", 0.0, -1e4, 1e4, "1/s", "Identified a_beta1"),
            DesignModel => a_beta1
        ),
        param!(
            ParamDef::real("ATUN_A_BET2", 0.0, -1e4, 1e4, "1/s", "Identified a_beta2"),
            DesignModel => a_beta2
        ),
        param!(
            ParamDef::real("ATUN_A_THT1", 0.0, -1e4, 1e4, "1/s", "Identified a_theta1"),
            DesignModel => a_theta1
        ),
        param!(
            ParamDef::real("ATUN_A_THT2", 0.0, -1e5, 1e5, "1/s^2", "Identified a_theta2"),
            DesignModel => a_theta2
        ),
        param!(
            ParamDef::real("ATUN_A_THT3", 0.0, -1e5, 1e5, "1/s^2", "Identified a_theta3"),
            DesignModel => a_theta3
        ),
        param!(
            ParamDef::real("ATUN_A_V1", 0.0, -1e3, 1e3, "1/s", "Identified a_V1"),
            DesignModel => a_v1
        ),
        param!(
            ParamDef::real("ATUN_A_V2", 0.0, -1e3, 1e3, "m/s^2", "Identified a_V2"),
            DesignModel => a_v2
        ),
        param!(
            ParamDef::real("ATUN_A_GAM", 0.0, -1e3, 1e3, "1/s", "Identified a_gamma"),
            DesignModel => a_gamma
        ),
    ],
    base: || UNIDENTIFIED,
    check: independent,
};
