//! Airspeed scaling of the surface loops.
//!
//! A surface's moment grows with the dynamic pressure, so with the square of the airspeed: gains
//! designed at the trim airspeed (17 m/s) are 1.7 times too weak at 13 m/s and twice too strong
//! at 25 m/s, where the inner loops lose their damping and phase margin. The roll, pitch and
//! sideslip loops and the yaw damper therefore see their error and rate inputs multiplied by
//! `(v_ref / v)^2` (as PX4's fixed-wing rate controllers scale theirs), with the airspeed
//! bounded so that a bad or ground-roll airspeed cannot make the gains run away. The outer loops
//! (course, altitude, airspeed) are kinematic and are left alone.

use crate::math::clamp;

/// Lowest airspeed the scaling uses, as a fraction of the reference (below it the wing is near
/// its stall and on the ground the airspeed says nothing about the surfaces).
pub const MIN_RATIO: f32 = 0.7;
/// Highest airspeed the scaling uses, as a fraction of the reference.
pub const MAX_RATIO: f32 = 1.6;

/// The factor on the surface loops' inputs at `airspeed` (m/s) for gains designed at
/// `reference` (m/s): `(reference / airspeed)^2`, the airspeed bounded to `[MIN_RATIO,
/// MAX_RATIO] * reference`. A reference of zero (or any non-positive or non-finite one) switches
/// scaling off; an airspeed that is not finite gives the factor of the reference airspeed, 1.
pub fn surface_scale(airspeed: f32, reference: f32) -> f32 {
    if !(reference.is_finite() && reference > 0.0 && airspeed.is_finite()) {
        return 1.0;
    }
    let v = clamp(airspeed, MIN_RATIO * reference, MAX_RATIO * reference);
    let r = reference / v;
    r * r
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_scale_is_the_inverse_square_of_the_airspeed_within_its_bounds() {
        // Dynamic pressure at 13 and 25 m/s against 17 m/s: (17/13)^2 = 1.710, (17/25)^2 = 0.4624.
        assert!((surface_scale(13.0, 17.0) - 1.710).abs() < 1e-3);
        assert!((surface_scale(25.0, 17.0) - 0.4624).abs() < 1e-4);
        assert_eq!(surface_scale(17.0, 17.0), 1.0);
        // A standing aircraft and an over-reading pitot stop at the bounds.
        assert!((surface_scale(0.0, 17.0) - 1.0 / (MIN_RATIO * MIN_RATIO)).abs() < 1e-4);
        assert!((surface_scale(100.0, 17.0) - 1.0 / (MAX_RATIO * MAX_RATIO)).abs() < 1e-4);
    }

    #[test]
    fn without_a_reference_or_an_airspeed_the_gains_are_unscaled() {
        assert_eq!(surface_scale(25.0, 0.0), 1.0);
        assert_eq!(surface_scale(f32::NAN, 17.0), 1.0);
        assert_eq!(surface_scale(f32::INFINITY, 17.0), 1.0);
        assert_eq!(surface_scale(13.0, f32::NAN), 1.0);
        assert_eq!(surface_scale(13.0, -17.0), 1.0);
    }
}
