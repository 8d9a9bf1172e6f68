//! What the plant is stepped with: the surface and throttle positions, and the air mass around it.

use common::actuators::Surfaces;
use nalgebra::Vector3;

/// Surface and throttle positions the plant sees (after the servos), UMN signs, rad.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Controls {
    /// Elevator, positive trailing edge down (nose down).
    pub elevator: f64,
    /// Left aileron, positive trailing edge down.
    pub aileron_left: f64,
    /// Right aileron, positive trailing edge down.
    pub aileron_right: f64,
    /// Rudder, positive trailing edge left (nose left).
    pub rudder: f64,
    /// Throttle, 0..1.
    pub throttle: f64,
    /// Left flap, positive trailing edge down.
    pub flap_left: f64,
    /// Right flap, positive trailing edge down.
    pub flap_right: f64,
}

impl Controls {
    /// Controls from the combined aileron (`left = -aileron`, `right = +aileron`), no flaps.
    pub fn new(elevator: f64, aileron: f64, rudder: f64, throttle: f64) -> Self {
        Self {
            elevator,
            aileron_left: -aileron,
            aileron_right: aileron,
            rudder,
            throttle,
            flap_left: 0.0,
            flap_right: 0.0,
        }
    }

    /// The combined aileron `(right - left) / 2`, rad (positive rolls left).
    pub fn aileron(&self) -> f64 {
        0.5 * (self.aileron_right - self.aileron_left)
    }

    /// The same controls with both flaps at `flap` rad.
    pub fn with_flaps(self, flap: f64) -> Self {
        Self {
            flap_left: flap,
            flap_right: flap,
            ..self
        }
    }
}

impl From<Surfaces> for Controls {
    fn from(s: Surfaces) -> Self {
        Self::new(
            f64::from(s.elevator),
            f64::from(s.aileron),
            f64::from(s.rudder),
            f64::from(s.throttle),
        )
    }
}

/// What the air mass does around the aircraft.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Environment {
    /// Wind (velocity of the air mass) in NED, m/s: steady wind plus any turbulence.
    pub wind_ned: Vector3<f64>,
}
