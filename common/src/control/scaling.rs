//! Airspeed scaling of the surface loops and of the altitude loop.
//!
//! A surface's moment grows with the square of the airspeed, but the aircraft's own damping
//! (roll, pitch, yaw) only with the airspeed, and the servo and the software's delay stay what
//! they are. Scaling the gains by `(v_ref / v)^2` (the dynamic pressure alone) keeps each loop's
//! bandwidth but not its damping: on the full sampled model (`sim-host design`,
//! docs/GAIN-DESIGN.md) the roll loop keeps 33.5 deg of phase margin at 13 m/s against 53.5
//! unscaled. `v_ref / v` keeps every loop's margin above 38 deg from 13 to 23 m/s (the lowest
//! unscaled: 37.9 deg, roll at 23 m/s), and raises the roll, sideslip and altitude loops' at
//! 23 m/s to 51-59 deg. The altitude loop takes the same factor for a reason of its own: a pitch
//! change climbs at `v` times it.
//!
//! So the roll, pitch and sideslip loops, the yaw damper and the altitude loop see their error
//! and rate inputs multiplied by `v_ref / v`, the airspeed bounded so that a bad or ground-roll
//! airspeed cannot make the gains run away. The course and airspeed loops are left alone.

use crate::math::clamp;

/// Lowest airspeed the scaling uses, as a fraction of the reference (below it the wing is near
/// its stall and on the ground the airspeed says nothing about the surfaces).
pub const MIN_RATIO: f32 = 0.7;
/// Highest airspeed the scaling uses, as a fraction of the reference.
pub const MAX_RATIO: f32 = 1.6;

/// The factor on the scaled loops' inputs at `airspeed` (m/s) for gains designed at
/// `reference` (m/s): `reference / airspeed`, the airspeed bounded to `[MIN_RATIO,
/// MAX_RATIO] * reference`. A reference of zero (or any non-positive or non-finite one) switches
/// scaling off; an airspeed that is not finite gives the factor of the reference airspeed, 1.
pub fn surface_scale(airspeed: f32, reference: f32) -> f32 {
    if !(reference.is_finite() && reference > 0.0 && airspeed.is_finite()) {
        return 1.0;
    }
    reference / clamp(airspeed, MIN_RATIO * reference, MAX_RATIO * reference)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_scale_is_the_inverse_of_the_airspeed_within_its_bounds() {
        assert!((surface_scale(13.0, 17.0) - 17.0 / 13.0).abs() < 1e-6);
        assert!((surface_scale(23.0, 17.0) - 17.0 / 23.0).abs() < 1e-6);
        assert_eq!(surface_scale(17.0, 17.0), 1.0);
        // A standing aircraft and an over-reading pitot stop at the bounds.
        assert!((surface_scale(0.0, 17.0) - 1.0 / MIN_RATIO).abs() < 1e-5);
        assert!((surface_scale(100.0, 17.0) - 1.0 / MAX_RATIO).abs() < 1e-5);
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
