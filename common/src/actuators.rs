//! Surface and throttle commands, in the University of Minnesota model's sign convention, and
//! their mapping to the normalised controls of PX4's `HIL_ACTUATOR_CONTROLS`.
//!
//! Surface signs (UMN): elevator, aileron positive trailing edge down; rudder positive trailing
//! edge left. The combined aileron is `(right - left) / 2`, so a positive aileron rolls left
//! (`Cl_da < 0`), a positive elevator pitches nose down (`Cm_de < 0`) and a positive rudder
//! yaws nose left (`Cn_dr < 0`). PX4's normalised controls have the opposite sense (+1 rolls
//! right, pitches nose up, yaws nose right), each spanning the +-25 deg surface travel.

/// Travel of every surface, rad (+-25 deg).
pub const SURFACE_LIMIT_RAD: f32 = 25.0 * core::f32::consts::PI / 180.0;

/// One set of actuator commands.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Surfaces {
    /// Elevator, rad, positive trailing edge down (nose down).
    pub elevator: f32,
    /// Combined aileron `(right - left) / 2`, rad, positive rolls left.
    pub aileron: f32,
    /// Rudder, rad, positive trailing edge left (nose left).
    pub rudder: f32,
    /// Throttle, 0..1.
    pub throttle: f32,
}

impl Surfaces {
    /// Clamps each surface to +-25 deg and the throttle to 0..1; a non-finite entry becomes
    /// neutral (zero), so no NaN ever reaches an actuator.
    pub fn saturated(self) -> Self {
        let s = |x: f32| {
            if x.is_finite() {
                x.clamp(-SURFACE_LIMIT_RAD, SURFACE_LIMIT_RAD)
            } else {
                0.0
            }
        };
        Self {
            elevator: s(self.elevator),
            aileron: s(self.aileron),
            rudder: s(self.rudder),
            throttle: if self.throttle.is_finite() {
                self.throttle.clamp(0.0, 1.0)
            } else {
                0.0
            },
        }
    }

    /// PX4 normalised controls `[roll, pitch, yaw, throttle]` (roll, pitch, yaw in -1..1).
    pub fn to_px4_controls(self) -> [f32; 4] {
        let s = self.saturated();
        [
            -s.aileron / SURFACE_LIMIT_RAD,
            -s.elevator / SURFACE_LIMIT_RAD,
            -s.rudder / SURFACE_LIMIT_RAD,
            s.throttle,
        ]
    }

    /// Surface commands from PX4 normalised controls `[roll, pitch, yaw, throttle]`; out-of-range
    /// or non-finite entries are clamped or neutralised by [`Surfaces::saturated`].
    pub fn from_px4_controls(c: [f32; 4]) -> Self {
        Self {
            aileron: -c[0] * SURFACE_LIMIT_RAD,
            elevator: -c[1] * SURFACE_LIMIT_RAD,
            rudder: -c[2] * SURFACE_LIMIT_RAD,
            throttle: c[3],
        }
        .saturated()
    }

    /// The outputs as `SERVO_OUTPUT_RAW` reports them, µs, in the order of
    /// [`Surfaces::to_px4_controls`]: a surface's -1..1 on 1000..2000 (1500 neutral), the
    /// throttle's 0..1 on 1000..2000, as PX4's outputs map the same controls.
    pub fn to_pwm_us(self) -> [u16; 4] {
        let c = self.to_px4_controls();
        let us = |x: f32, centre: f32, half_span: f32| (centre + half_span * x + 0.5) as u16;
        [
            us(c[0], PWM_CENTRE_US, PWM_HALF_SPAN_US),
            us(c[1], PWM_CENTRE_US, PWM_HALF_SPAN_US),
            us(c[2], PWM_CENTRE_US, PWM_HALF_SPAN_US),
            us(c[3], PWM_MIN_US, 2.0 * PWM_HALF_SPAN_US),
        ]
    }

    /// The inverse of [`Surfaces::to_pwm_us`] (to its 1 µs steps); out-of-range values are
    /// clamped.
    pub fn from_pwm_us(us: [u16; 4]) -> Self {
        let surface = |x: u16| (f32::from(x) - PWM_CENTRE_US) / PWM_HALF_SPAN_US;
        Self::from_px4_controls([
            surface(us[0]),
            surface(us[1]),
            surface(us[2]),
            (f32::from(us[3]) - PWM_MIN_US) / (2.0 * PWM_HALF_SPAN_US),
        ])
    }
}

/// A surface's neutral pulse, µs.
const PWM_CENTRE_US: f32 = 1500.0;
/// The pulse of no throttle, µs.
const PWM_MIN_US: f32 = 1000.0;
/// Half the pulses' span, µs (a surface's full travel either way).
const PWM_HALF_SPAN_US: f32 = 500.0;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_pulses_carry_the_outputs_to_a_microsecond() {
        let s = Surfaces {
            elevator: -0.1,
            aileron: 0.2,
            rudder: 0.05,
            throttle: 0.37,
        };
        // +0.2 rad of aileron rolls left: -0.458 of PX4's roll control, 1500 - 229 us.
        assert_eq!(s.to_pwm_us(), [1271, 1615, 1443, 1370]);
        let back = Surfaces::from_pwm_us(s.to_pwm_us());
        // One microsecond is 0.05 deg of surface and 0.1 % of throttle.
        let step = SURFACE_LIMIT_RAD / 500.0;
        assert!((back.aileron - s.aileron).abs() <= step / 2.0 + 1e-6);
        assert!((back.elevator - s.elevator).abs() <= step / 2.0 + 1e-6);
        assert!((back.rudder - s.rudder).abs() <= step / 2.0 + 1e-6);
        assert!((back.throttle - s.throttle).abs() <= 0.0005 + 1e-6);
        // Out of range, clamped to the travel.
        assert_eq!(Surfaces::from_pwm_us([0, 3000, 1500, 2500]).throttle, 1.0);
        assert_eq!(
            Surfaces::from_pwm_us([0, 3000, 1500, 2500]).aileron,
            SURFACE_LIMIT_RAD
        );
    }

    #[test]
    fn px4_sense_is_opposite_to_umn_surfaces() {
        // DESIGN.md: +1 roll is aileron -25 deg, +1 pitch is elevator -25 deg.
        let s = Surfaces::from_px4_controls([1.0, 1.0, 1.0, 0.5]);
        assert!((s.aileron + SURFACE_LIMIT_RAD).abs() < 1e-6);
        assert!((s.elevator + SURFACE_LIMIT_RAD).abs() < 1e-6);
        assert!((s.rudder + SURFACE_LIMIT_RAD).abs() < 1e-6);
        let back = s.to_px4_controls();
        for (a, b) in back.iter().zip([1.0, 1.0, 1.0, 0.5]) {
            assert!((a - b).abs() < 1e-6);
        }
    }

    #[test]
    fn saturation_and_nan() {
        let s = Surfaces {
            elevator: 1.0,
            aileron: f32::NAN,
            rudder: -1.0,
            throttle: f32::INFINITY,
        }
        .saturated();
        assert_eq!(s.elevator, SURFACE_LIMIT_RAD);
        assert_eq!(s.aileron, 0.0);
        assert_eq!(s.rudder, -SURFACE_LIMIT_RAD);
        assert_eq!(s.throttle, 0.0);
    }
}
