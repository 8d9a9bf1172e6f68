//! Reference values the analysis is checked against, each with its source.
//!
//! Sources:
//! - THESIS: "Autopilot design for fixed wing UAV" (University of Khartoum, 2017), Table 2.3
//!   (trim), Tables 2.4/2.5 (poles), eqs. 20, 26, 27 (transfer functions), Tables 3.1/3.2
//!   (doublet errors); cleaned in `seed/REFERENCE.md`.
//! - UMN trim: GitHub UASLab/OpenFlight master @ e3562a6, `Simulation/Libraries/UAV_trimcondition.mat`.
//! - UMN linear: same repository, branch `Intermediate` @ 42fe830, `ValidatedDynamics.txt`
//!   (Simulink linearisation of the same model at the level trim).

/// Whether the thesis's and the Minnesota references describe a trim of `aircraft` at
/// `va_mps`: the built-in Ultra Stick 25e at the thesis's 17 m/s only.
pub fn apply_to(aircraft: &crate::aircraft::Aircraft, va_mps: f64) -> bool {
    va_mps == crate::aircraft::DEFAULT_TRIM_AIRSPEED_MPS
        && crate::aircraft::Aircraft::ultrastick25e().is_ok_and(|a| &a == aircraft)
}

/// One row of thesis Table 2.3 (angles rad, rates rad/s).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct ThesisTrim {
    /// Trim target name (as in [`super::trim::TrimTarget`]).
    pub name: &'static str,
    /// Throttle 0..1.
    pub throttle: f64,
    /// Elevator.
    pub elevator: f64,
    /// Rudder.
    pub rudder: f64,
    /// Combined aileron.
    pub aileron: f64,
    /// Angle of attack.
    pub alpha: f64,
    /// Roll.
    pub phi: f64,
    /// Pitch.
    pub theta: f64,
    /// Body roll rate.
    pub p: f64,
    /// Body pitch rate.
    pub q: f64,
    /// Body yaw rate.
    pub r: f64,
}

/// THESIS Table 2.3, columns I to IV.
pub const THESIS_TRIM: [ThesisTrim; 4] = [
    ThesisTrim {
        name: "level",
        throttle: 0.569,
        elevator: -0.0963,
        rudder: 0.00317,
        aileron: 0.01,
        alpha: 0.054,
        phi: -0.00172,
        theta: 0.054,
        p: 0.0,
        q: 0.0,
        r: 0.0,
    },
    ThesisTrim {
        name: "climb",
        throttle: 0.721,
        elevator: -0.102,
        rudder: 0.00436,
        aileron: 0.0138,
        alpha: 0.0529,
        phi: -0.00239,
        theta: 0.14,
        p: 0.0,
        q: 0.0,
        r: 0.0,
    },
    ThesisTrim {
        name: "turn",
        throttle: 0.582,
        elevator: -0.125,
        rudder: -0.00748,
        aileron: 0.0186,
        alpha: 0.0646,
        phi: 0.544,
        theta: 0.0553,
        p: -0.0193,
        q: 0.181,
        r: 0.298,
    },
    ThesisTrim {
        name: "climbing-turn",
        throttle: 0.731,
        elevator: -0.131,
        rudder: -0.00607,
        aileron: 0.0253,
        alpha: 0.0633,
        phi: 0.547,
        theta: 0.141,
        p: -0.0492,
        q: 0.18,
        r: 0.295,
    },
];

/// UMN committed level trim (`UAV_trimcondition.mat`).
pub mod umn_trim {
    /// Throttle.
    pub const THROTTLE: f64 = 0.5694718;
    /// Elevator, rad.
    pub const ELEVATOR: f64 = -0.097198;
    /// Rudder, rad.
    pub const RUDDER: f64 = 0.00317;
    /// Combined aileron, rad.
    pub const AILERON: f64 = 0.010039;
    /// Angle of attack, rad.
    pub const ALPHA: f64 = 0.055062;
    /// Pitch, rad.
    pub const THETA: f64 = 0.055055;
    /// Roll, rad.
    pub const PHI: f64 = -0.001717;
    /// Engine speed, rad/s.
    pub const ENGINE_SPEED: f64 = 826.6721;
    /// Body specific force, m/s^2.
    pub const SPECIFIC_FORCE: [f64; 3] = [0.539576, 0.016809, -9.790675];
}

/// UMN Simulink longitudinal A, states [u, w, q, theta, Ze, Omega] (`ValidatedDynamics.txt`).
pub const UMN_A_LON: [[f64; 6]; 6] = [
    [-0.5945, 0.8081, -0.8912, -9.791, 5.175e-5, 0.0126],
    [-0.7369, -7.56, 15.72, -0.5396, -0.000939, 0.0],
    [1.048, -7.405, -15.81, 0.0, -7.674e-13, -0.01315],
    [0.0, 0.0, 1.0, 0.0, 0.0, 0.0],
    [-0.05503, 0.9985, 0.0, -17.0, 0.0, 0.0],
    [135.5, 7.466, 0.0, 0.0, -0.08254, -5.903],
];
/// UMN Simulink longitudinal B, inputs [elevator, throttle].
pub const UMN_B_LON: [[f64; 2]; 6] = [
    [0.4698, 0.0],
    [-2.703, 0.0],
    [-133.7, 0.0],
    [0.0, 0.0],
    [0.0, 0.0],
    [0.0, 2503.0],
];
/// UMN Simulink lateral A, states [v, p, r, phi, psi].
pub const UMN_A_LAT: [[f64; 5]; 5] = [
    [-0.8726, 0.8968, -16.82, 9.791, 0.0],
    [-2.757, -16.09, 3.368, 0.0, 0.0],
    [1.708, 0.514, -2.775, 0.0, 0.0],
    [0.0, 1.0, 0.05511, -1.507e-8, 0.0],
    [0.0, 0.0, 1.002, -2.739e-7, 0.0],
];
/// UMN Simulink lateral B, inputs [left_aileron, right_aileron, rudder].
pub const UMN_B_LAT: [[f64; 3]; 5] = [
    [0.0, 0.0, 5.302],
    [78.23, -78.23, -4.972],
    [-5.752, 5.752, -82.04],
    [0.0, 0.0, 0.0],
    [0.0, 0.0, 0.0],
];

/// A reference pole `(re, im)` with its mode name and sources.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct RefPole {
    /// Mode.
    pub mode: &'static str,
    /// UMN Simulink value (`ValidatedDynamics.txt`), `(re, im)`.
    pub umn: (f64, f64),
    /// Thesis value (Tables 2.4 and 2.5), when it gives one.
    pub thesis: Option<(f64, f64)>,
}

/// Reference poles at the level trim.
pub const POLES: [RefPole; 7] = [
    RefPole {
        mode: "phugoid",
        umn: (-0.159, 0.641),
        thesis: Some((-0.159, 0.641)),
    },
    RefPole {
        mode: "short period",
        umn: (-11.7, 10.0),
        thesis: Some((-11.7, 10.0)),
    },
    RefPole {
        mode: "engine speed",
        umn: (-6.18, 0.0),
        thesis: None,
    },
    RefPole {
        mode: "altitude",
        umn: (-1.20e-4, 0.0),
        thesis: None,
    },
    RefPole {
        mode: "roll",
        umn: (-16.1, 0.0),
        thesis: Some((-16.1, 0.0)),
    },
    RefPole {
        mode: "dutch roll",
        umn: (-1.84, 5.29),
        thesis: Some((-1.84, 5.28)),
    },
    RefPole {
        mode: "spiral",
        umn: (-0.0090, 0.0),
        thesis: Some((-0.0138, 0.0)),
    },
];

/// THESIS eq. 20: p/da = -156.5 / (s + 16.09).
pub const THESIS_P_DA: ([f64; 1], [f64; 2]) = ([-156.5], [1.0, 16.09]);
/// THESIS eq. 27: q/de = (-133.7 s - 990.7) / (s^2 + 23.37 s + 235.9).
pub const THESIS_Q_DE: ([f64; 2], [f64; 3]) = ([-133.7, -990.7], [1.0, 23.37, 235.9]);
/// THESIS eq. 26: r/dr = (-82.04 s^3 - 1385 s^2 - 1228 s - 2351) /
/// (s^4 + 19.74 s^3 + 90.49 s^2 + 502.2 s + 6.89).
pub const THESIS_R_DR: ([f64; 4], [f64; 5]) = (
    [-82.04, -1385.0, -1228.0, -2351.0],
    [1.0, 19.74, 90.49, 502.2, 6.89],
);
/// UMN Simulink p/da_R (right aileron alone): the p row of `B_lat`.
pub const UMN_P_DA_RIGHT: f64 = -78.23;

/// THESIS Table 3.1: largest linear/nonlinear differences after an elevator doublet
/// `(output, value, unit)`.
pub const THESIS_DOUBLET_LON: [(&str, f64, &str); 4] = [
    ("airspeed", 0.20, "m/s"),
    ("alpha", 0.05, "deg"),
    ("theta", 0.40, "deg"),
    ("q", 1.0, "deg/s"),
];
/// THESIS Table 3.2: lateral differences ("zero errors": no visible difference).
pub const THESIS_DOUBLET_LAT: [(&str, f64, &str); 3] = [
    ("beta", 0.0, "deg"),
    ("p", 0.0, "deg/s"),
    ("r", 0.0, "deg/s"),
];
