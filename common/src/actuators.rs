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
}

#[cfg(test)]
mod tests {
    use super::*;

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
