//! What a design starts from: Beard and McLain's reduced coefficients at one airspeed, the
//! servos' bandwidth and gravity.

/// Engine pole a design takes where none was identified, 1/s: two orders of magnitude above
/// the airspeed loops, so the throttle acts as at once (the margins it predicts are then an
/// upper bound).
pub const QUASI_STEADY_ENGINE_POLE: f32 = 100.0;

/// Pitch attitude per elevator as a rational function of `s`,
/// `(num[0] s + num[1]) / (den[0] s^3 + den[1] s^2 + den[2] s + den[3])`: what the pitch loop's
/// phase margin (and so its gain) and the outer loops through it are judged on.
///
/// The reduced short period `a_theta3 / (s^2 + a_theta1 s + a_theta2)`
/// ([`PitchResponse::short_period`]) is what a design from identified models has; a design
/// from an aircraft file may judge on the linear model's two-state short period with its free
/// integrator, `(b1 s + b0) / (s (s^2 + a1 s + a0))`, instead.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct PitchResponse {
    /// Numerator coefficients, highest power first (`s^1`, `s^0`).
    pub num: [f32; 2],
    /// Denominator coefficients, highest power first (`s^3` .. `s^0`).
    pub den: [f32; 4],
}

impl PitchResponse {
    /// `a_theta3 / (s^2 + a_theta1 s + a_theta2)`.
    pub fn short_period(a_theta1: f32, a_theta2: f32, a_theta3: f32) -> Self {
        Self {
            num: [0.0, a_theta3],
            den: [0.0, 1.0, a_theta1, a_theta2],
        }
    }

    /// Whether every coefficient is finite and the denominator is not zero.
    pub fn is_finite(&self) -> bool {
        self.num.iter().chain(&self.den).all(|c| c.is_finite())
            && self.den.iter().any(|&c| c != 0.0)
    }
}

/// The reduced models a design starts from (Beard and McLain's names and signs: the Minnesota
/// model's, a positive aileron rolls left so `a_phi2 < 0`, a positive elevator pitches down so
/// `a_theta3 < 0`).
///
/// ```text
/// roll      phi / da      = a_phi2 / (s (s + a_phi1))
/// sideslip  beta / dr     = a_beta2 / (s + a_beta1)
/// pitch     theta / de    = a_theta3 / (s^2 + a_theta1 s + a_theta2)   (or `pitch_response`)
/// airspeed  Va / theta    = -g / (s + a_v1)
///           Va / throttle = a_v2 engine_pole / ((s + a_v1) (s + engine_pole))
/// course    chi / phi     = (g / va) / s
/// flight    gamma / theta = a_gamma / (s + a_gamma)      (1 where a_gamma is 0)
/// altitude  h / gamma     = va / s
/// ```
///
/// The flight path's lag behind the pitch is left out of the book's altitude and airspeed
/// models (`h / theta = va / s`): the lift that turns the flight path is built by the angle of
/// attack, which the pitch must first open. Its pole, `a_gamma = rho Va S (CL_alpha + CD) /
/// (2 m)` (the heave damping, `-Z_w`), is 7.5 1/s on the 25e at 17 m/s and 4.3 on the
/// Aerosonde at 25 (their linearisations'): a decade or less above their outer loops'
/// crossovers, whose phase it lowers.
///
/// Without a sideslip model (`a_beta2` 0) the sideslip loop keeps the base set's gains.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DesignModel {
    /// Airspeed the coefficients hold at, m/s.
    pub va: f32,
    /// Roll damping, 1/s.
    pub a_phi1: f32,
    /// Roll acceleration per radian of combined aileron, 1/s^2.
    pub a_phi2: f32,
    /// Sideslip damping, the side force's per radian of sideslip, 1/s (0 with `a_beta2`:
    /// no sideslip model).
    pub a_beta1: f32,
    /// Sideslip rate per radian of rudder, 1/s (0: no sideslip model).
    pub a_beta2: f32,
    /// Pitch damping, 1/s.
    pub a_theta1: f32,
    /// Pitch stiffness, 1/s^2.
    pub a_theta2: f32,
    /// Pitch acceleration per radian of elevator, 1/s^2.
    pub a_theta3: f32,
    /// Airspeed damping, 1/s.
    pub a_v1: f32,
    /// Steady airspeed acceleration per unit throttle, m/s^2.
    pub a_v2: f32,
    /// The flight path's pole behind the pitch, 1/s (0: not modelled, the flight path
    /// follows the pitch at once as the book's altitude model has it).
    pub a_gamma: f32,
    /// The engine speed's pole, 1/s (`None`: not identified, taken as
    /// [`QUASI_STEADY_ENGINE_POLE`]).
    pub engine_pole: Option<f32>,
    /// The surface servos' bandwidth, Hz (a first-order lag with its pole there).
    pub servo_bandwidth_hz: f32,
    /// Gravity, m/s^2.
    pub g: f32,
    /// What the pitch loop is judged on (`None`: the reduced short period of `a_theta1`,
    /// `a_theta2`, `a_theta3`, as a design from identified models has it).
    pub pitch_response: Option<PitchResponse>,
}

impl DesignModel {
    /// The engine pole the design takes, 1/s.
    pub fn engine_pole(&self) -> f32 {
        self.engine_pole.unwrap_or(QUASI_STEADY_ENGINE_POLE)
    }

    /// The pitch response the design judges on.
    pub fn pitch_response(&self) -> PitchResponse {
        self.pitch_response.unwrap_or_else(|| {
            PitchResponse::short_period(self.a_theta1, self.a_theta2, self.a_theta3)
        })
    }

    /// The coefficients a design takes from identification, under Beard and McLain's names
    /// (as the linearisation's reports name them), in the order of the design.
    pub fn coefficients(&self) -> [(&'static str, f32); 10] {
        [
            ("a_phi1", self.a_phi1),
            ("a_phi2", self.a_phi2),
            ("a_beta1", self.a_beta1),
            ("a_beta2", self.a_beta2),
            ("a_theta1", self.a_theta1),
            ("a_theta2", self.a_theta2),
            ("a_theta3", self.a_theta3),
            ("a_V1", self.a_v1),
            ("a_V2", self.a_v2),
            ("a_gamma", self.a_gamma),
        ]
    }

    /// Whether it has a sideslip model to design the sideslip loop on.
    pub fn has_sideslip(&self) -> bool {
        self.a_beta2 != 0.0
    }

    /// The servo's pole, rad/s.
    pub fn servo_pole(&self) -> f32 {
        2.0 * core::f32::consts::PI * self.servo_bandwidth_hz
    }
}
