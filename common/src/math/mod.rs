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
pub mod elementary;
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
// Not inlined: its two compares and selects were copied into some twenty callers (0.6 KB of the
// MCU image); a call costs a few instructions.
#[inline(never)]
pub fn clamp(x: f32, lo: f32, hi: f32) -> f32 {
    if x < lo {
        lo
    } else if x > hi {
        hi
    } else {
        x
    }
}

/// Largest rotation angle, rad, that [`rotation_from_vector`] takes by its series.
const SERIES_MAX_ANGLE: f32 = 0.3;

/// The rotation by the rotation vector `v` (axis times angle, rad), as nalgebra's
/// `UnitQuaternion::from_scaled_axis`. The filter's rotations (a gyro sample's 10 ms, a
/// correction) are small: below 0.3 rad the half-angle's cosine and `sin(x)/x` are their
/// Taylor series to the x^6 term, whose remainder (below 2e-11) lies far under `f32`'s
/// resolution, in `f32` arithmetic; `libm`'s `sinf`/`cosf` evaluate in `f64`, which the
/// Cortex-M4F does in software. Larger angles take the half angle's sine and cosine
/// ([`elementary`]; nalgebra's on the host).
pub fn rotation_from_vector(v: &nalgebra::Vector3<f32>) -> nalgebra::UnitQuaternion<f32> {
    let theta2 = v.norm_squared();
    if theta2.is_nan() || theta2 >= SERIES_MAX_ANGLE * SERIES_MAX_ANGLE {
        return large_rotation(v, theta2);
    }
    // With h the half angle: cos h and sin(h) / (2 h), so the vector part is v sin(h) / theta.
    let h2 = 0.25 * theta2;
    let cos_h = 1.0 - h2 / 2.0 * (1.0 - h2 / 12.0 * (1.0 - h2 / 30.0));
    let sinc_half = 0.5 * (1.0 - h2 / 6.0 * (1.0 - h2 / 20.0 * (1.0 - h2 / 42.0)));
    let xyz = v * sinc_half;
    nalgebra::UnitQuaternion::new_unchecked(nalgebra::Quaternion::new(cos_h, xyz.x, xyz.y, xyz.z))
}

/// The rotation by a rotation vector of squared length `theta2`, at least 0.3 rad long (or
/// NaN), as nalgebra's `from_scaled_axis` builds it (nalgebra's own on the host).
fn large_rotation(v: &nalgebra::Vector3<f32>, theta2: f32) -> nalgebra::UnitQuaternion<f32> {
    if !elementary::BOARD_ARITHMETIC {
        return nalgebra::UnitQuaternion::from_scaled_axis(*v);
    }
    let theta = libm::sqrtf(theta2);
    let (s, c) = elementary::sin_cos(0.5 * theta);
    let k = s / theta;
    nalgebra::UnitQuaternion::new_unchecked(nalgebra::Quaternion::new(c, v.x * k, v.y * k, v.z * k))
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

    #[test]
    fn the_small_rotation_series_matches_nalgebra_in_f64() {
        use super::rotation_from_vector;
        use nalgebra::{UnitQuaternion, Vector3};
        let mut worst = 0.0_f64;
        for i in 0..2000 {
            let k = f64::from(i);
            let axis = Vector3::new((k * 0.37).sin(), (k * 1.13).cos(), (k * 0.71).sin() + 0.2)
                .normalize();
            // Angles from 0 past the series' limit, where nalgebra takes over.
            let angle = k / 2000.0 * 0.4;
            let v = axis * angle;
            let reference = UnitQuaternion::from_scaled_axis(v);
            let got = rotation_from_vector(&v.cast::<f32>()).cast::<f64>();
            let err = (got.coords - reference.coords).amax();
            worst = worst.max(err);
        }
        // f32's resolution of a unit quaternion's components.
        assert!(worst < 2e-7, "worst component error {worst:e}");
    }
}
