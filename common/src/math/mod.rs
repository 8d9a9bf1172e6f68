//! Frames, rotations, geodetic conversions and the standard atmosphere.
//!
//! Every function here is generic over the float type (`nalgebra::RealField`): the plant
//! calls them in `f64`, the firmware in `f32`, and both therefore agree on every convention.
//!
//! Conventions (fixed for the whole project):
//! - inertial frame NED (north, east, down), flat earth about a home point;
//! - body frame x forward, y right, z down;
//! - attitude as 3-2-1 Euler angles (yaw psi, pitch theta, roll phi) or the equivalent unit
//!   quaternion that rotates body vectors into NED.

pub mod atmosphere;
pub mod frames;
pub mod geodetic;

pub use frames::*;

/// One degree in radians, in the board's float.
pub const DEG: f32 = core::f32::consts::PI / 180.0;

/// Standard gravity, m/s^2 (the plant's `f64` view).
pub const STANDARD_GRAVITY: f64 = 9.80665;
/// Standard gravity, m/s^2, in the `f32` of the firmware.
pub const GRAVITY: f32 = STANDARD_GRAVITY as f32;
/// Degrees per radian, in the board's float.
pub const RAD2DEG: f32 = 180.0 / core::f32::consts::PI;

/// `x` limited to `[lo, hi]`, as `f32::clamp`, without its panic: with bounds from parameters
/// (inverted or NaN only if a check failed) the autopilot keeps flying. A NaN `x` stays NaN;
/// with inverted bounds the result is `lo` below `lo`, else `hi` above `hi`; a NaN bound
/// limits nothing.
#[inline]
pub fn clamp(x: f32, lo: f32, hi: f32) -> f32 {
    if x < lo {
        lo
    } else if x > hi {
        hi
    } else {
        x
    }
}

#[cfg(test)]
mod tests {
    use super::clamp;

    #[test]
    fn clamp_is_f32_clamp_for_ordered_bounds_and_never_panics() {
        for x in [
            -3.0,
            -1.0,
            -0.5,
            0.0,
            0.5,
            1.0,
            3.0,
            f32::INFINITY,
            f32::NEG_INFINITY,
        ] {
            assert_eq!(clamp(x, -1.0, 1.0), x.clamp(-1.0, 1.0));
        }
        assert!(clamp(f32::NAN, -1.0, 1.0).is_nan());
        assert_eq!(clamp(5.0, 1.0, -1.0), -1.0);
        assert_eq!(clamp(-5.0, 1.0, -1.0), 1.0);
        assert_eq!(clamp(5.0, f32::NAN, f32::NAN), 5.0);
    }
}
