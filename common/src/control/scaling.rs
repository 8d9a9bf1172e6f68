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
//! airspeed cannot make the gains run away. The airspeed loops are left alone.
//!
//! The course loop's plant is the turn, `chi' = (g / Vg) tan(phi)`: its gain grows as the
//! ground speed falls, and the book's gains carry the ground speed they were designed at
//! (`kp_chi = 2 zeta wn_chi Vg / g`, `ki_chi = wn_chi^2 Vg / g`). Into a headwind the same
//! course error asks the same bank of an aircraft that turns faster for it: at a fifth of the
//! design's ground speed the loop crosses over five times higher, where the roll loop no longer
//! follows, and in moderate turbulence approaches into 10-12 m/s gusts were rolled from
//! stop to stop (seed 1's flight 123, seed 2's 418, docs/RESULTS-MONTECARLO.md). The course
//! loop's error is multiplied by `Vg / v_ref` below the reference ([`course_scale`]), so it
//! keeps the design's bandwidth; faster over the ground it keeps the design's gains (a slower
//! loop than designed, as it always flew downwind).

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

/// The factor on the course loop's error at ground speed `ground_speed` (m/s) for gains
/// designed at `reference` (m/s): `ground_speed / reference` below the reference, no lower than
/// the slowest ground speed a course is read at (`MIN_COURSE_SPEED_MPS`, below which the course
/// loop reads the heading), 1 above it. A reference that is not positive and finite switches it
/// off; a ground speed that is not a positive finite number (not measured) gives 1.
pub fn course_scale(ground_speed: f32, reference: f32) -> f32 {
    if !(reference.is_finite() && reference > 0.0 && ground_speed.is_finite() && ground_speed > 0.0)
    {
        return 1.0;
    }
    clamp(ground_speed, crate::math::MIN_COURSE_SPEED_MPS, reference) / reference
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn into_a_headwind_the_course_loop_keeps_the_bandwidth_it_was_designed_for() {
        // The loop gain is kp g / Vg: scaled by Vg / v_ref it stays kp g / v_ref.
        let g = crate::math::GRAVITY;
        let (kp, v_ref) = (4.0511_f32, 17.0);
        for vg in [4.0, 8.5, 12.0, 17.0] {
            let loop_gain = kp * course_scale(vg, v_ref) * g / vg;
            assert!(
                (loop_gain - kp * g / v_ref).abs() < 1e-4,
                "{vg}: {loop_gain}"
            );
        }
        // Downwind it keeps the design's gains; crawling, the course's slowest.
        assert_eq!(course_scale(25.0, v_ref), 1.0);
        assert!((course_scale(1.0, v_ref) - 3.0 / 17.0).abs() < 1e-6);
    }

    #[test]
    fn without_a_reference_or_a_ground_speed_the_course_gains_are_the_design_s() {
        assert_eq!(course_scale(8.0, 0.0), 1.0);
        assert_eq!(course_scale(f32::NAN, 17.0), 1.0);
        assert_eq!(course_scale(0.0, 17.0), 1.0);
        assert_eq!(course_scale(-2.0, 17.0), 1.0);
        assert_eq!(course_scale(8.0, f32::INFINITY), 1.0);
    }

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
