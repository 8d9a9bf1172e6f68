//! Sines, cosines, tangents, arcsines, hypotenuses and powers in the board's `f32`.
//!
//! The `libm` crate's `f32` functions are written for every argument a float can hold: `sinf`,
//! `cosf` and `tanf` reduce arguments up to 1e38 by Payne and Hanek's method and evaluate their
//! kernels in `f64`, as do `asinf` and `hypotf`; the Cortex-M4F's FPU is single precision, so
//! each call runs software `f64` routines; with the reduction and `powf` they took 7,256 B of
//! the image's flash, and a tenth of a control period's instructions. The flight code's
//! angles are attitudes, courses and slopes, within a few turns of zero; here they are reduced
//! by three parts of pi/2 (Cody and Waite's method: exact below 12,868 rad, the 8,192nd
//! quarter turn) and the kernels are the Taylor series that reach below `f32`'s resolution
//! within a quarter turn, all in `f32`. The arcsine and the hypotenuse are `libm`'s
//! `f32`-only `atan2f` and `sqrtf` over exact or scaled arguments; the power is `libm`'s
//! `expf` of `y ln x`. The tests state each one's largest difference from `f64`.
//!
//! The MCU image takes these ([`sin_cos`], [`sin`], [`cos`], [`tan`], [`asin`], [`hypot`],
//! [`powf`], and [`Elementary`] in code generic over the float); the host build keeps `libm`'s
//! and nalgebra's unless `common`'s `bounded-trig` feature is on (sim-host's `mcu-libm` turns it
//! on, so that the host answers bit for bit as the image).

use nalgebra::RealField;

/// The functions of this module as the board computes them, for every build to test.
pub mod bounded {
    use core::f32::consts::{FRAC_2_PI, TAU};

    /// pi/2 in three parts: the first with 8 significant bits and the second with 11, so that
    /// their products with a quarter-turn count below 2^13 are exact in `f32`; the third is the
    /// rest, rounded.
    const PIO2_1: f32 = 1.570_312_5;
    const PIO2_2: f32 = 4.837_513e-4;
    const PIO2_3: f32 = 7.549_79e-8;

    /// Largest argument reduced exactly: 8,192 quarter turns.
    const EXACT_MAX: f32 = 12_867.0;

    /// The sine's coefficients after its first term, `(-1)^k / (2k + 1)!` to the x^9 term: the
    /// first omitted term is under 1.7e-9 within pi/4, a thirtieth of `f32`'s resolution.
    const SIN: [f32; 4] = [-1.0 / 6.0, 1.0 / 120.0, -1.0 / 5_040.0, 1.0 / 362_880.0];
    /// The cosine's, `(-1)^k / (2k)!` to the x^10 term (first omitted term under 1.2e-10).
    const COS: [f32; 5] = [
        -1.0 / 2.0,
        1.0 / 24.0,
        -1.0 / 720.0,
        1.0 / 40_320.0,
        -1.0 / 3_628_800.0,
    ];

    /// `c0 + c1 x2 + c2 x2^2 + ...` by Horner's rule.
    fn horner(x2: f32, c: &[f32]) -> f32 {
        c.iter().rev().fold(0.0, |q, k| q * x2 + k)
    }

    /// The remainder of `x` within pi/4 of a quarter turn, and that quarter turn's count
    /// modulo 4. Beyond 12,867 rad the argument is first taken modulo `f32`'s 2 pi (no flight
    /// quantity is that large; the result stays a sine and cosine of some angle).
    fn reduce(x: f32) -> (f32, i32) {
        let x = if x.abs() > EXACT_MAX { x % TAU } else { x };
        let half = if x < 0.0 { -0.5 } else { 0.5 };
        // Rounded to the nearest quarter turn; within +-8,193, so exact as an f32.
        let k = (x * FRAC_2_PI + half) as i32;
        let kf = k as f32;
        (((x - kf * PIO2_1) - kf * PIO2_2) - kf * PIO2_3, k & 3)
    }

    /// `sin x` and `cos x` (rad); NaN or infinite `x` gives NaNs.
    pub fn sin_cos(x: f32) -> (f32, f32) {
        if !x.is_finite() {
            return (f32::NAN, f32::NAN);
        }
        let (r, quadrant) = reduce(x);
        let r2 = r * r;
        let s = r + r * r2 * horner(r2, &SIN);
        let c = 1.0 + r2 * horner(r2, &COS);
        match quadrant {
            0 => (s, c),
            1 => (c, -s),
            2 => (-s, -c),
            _ => (-c, s),
        }
    }

    /// `sin x` (rad).
    pub fn sin(x: f32) -> f32 {
        sin_cos(x).0
    }

    /// `cos x` (rad).
    pub fn cos(x: f32) -> f32 {
        sin_cos(x).1
    }

    /// `tan x` (rad), the sine over the cosine.
    pub fn tan(x: f32) -> f32 {
        let (s, c) = sin_cos(x);
        s / c
    }

    /// `asin x` (rad) in [-pi/2, pi/2]: the angle whose cosine is `sqrt((1 - x)(1 + x))`, a
    /// product with no cancellation near +-1; NaN beyond +-1.
    pub fn asin(x: f32) -> f32 {
        libm::atan2f(x, libm::sqrtf((1.0 - x) * (1.0 + x)))
    }

    /// Arguments whose squares and their sum stay normal `f32`s.
    const SQUARE_SAFE: core::ops::RangeInclusive<f32> = 1e-18..=1e18;

    /// `sqrt(x^2 + y^2)` without overflow or underflow: infinite if either is, else NaN if
    /// either is NaN.
    pub fn hypot(x: f32, y: f32) -> f32 {
        let (a, b) = (x.abs(), y.abs());
        if a == f32::INFINITY || b == f32::INFINITY {
            return f32::INFINITY;
        }
        let (hi, lo) = if a >= b { (a, b) } else { (b, a) };
        if SQUARE_SAFE.contains(&hi) {
            libm::sqrtf(a * a + b * b)
        } else if hi > 0.0 {
            let r = lo / hi;
            hi * libm::sqrtf(1.0 + r * r)
        } else {
            // Both zero, or a NaN (which fails every comparison above).
            a + b
        }
    }

    /// `x^y` for `x > 0` as `exp(y ln x)`; NaN for `x <= 0` or NaN (the flight code raises only
    /// positive bases: pressure ratios, gain steps, frequency ratios).
    pub fn powf(x: f32, y: f32) -> f32 {
        if x > 0.0 {
            libm::expf(y * libm::logf(x))
        } else {
            f32::NAN
        }
    }
}

/// Whether this build computes as the board does: the MCU image, or a host build with
/// `common`'s `bounded-trig` feature. The one switch of the functions here, the local frame's
/// radii and the flight code's geodetic offsets (`geodetic::flight_ned_offset`).
pub const BOARD_ARITHMETIC: bool = cfg!(any(target_os = "none", feature = "bounded-trig"));

#[cfg(any(target_os = "none", feature = "bounded-trig"))]
pub use bounded::{asin, cos, hypot, powf, sin, sin_cos, tan};

#[cfg(not(any(target_os = "none", feature = "bounded-trig")))]
pub use libm::{asinf as asin, cosf as cos, hypotf as hypot, powf, sinf as sin, tanf as tan};

/// `sin x` and `cos x` (rad).
#[cfg(not(any(target_os = "none", feature = "bounded-trig")))]
pub fn sin_cos(x: f32) -> (f32, f32) {
    libm::sincosf(x)
}

/// The elementary functions of code generic over the float: `f32` takes this module's, `f64`
/// (the plant's) nalgebra's, unchanged.
pub trait Elementary: RealField + Copy {
    /// `sin x` and `cos x` (rad).
    fn sin_cos_el(self) -> (Self, Self);
    /// `tan x` (rad).
    fn tan_el(self) -> Self;
    /// `asin x` (rad).
    fn asin_el(self) -> Self;
    /// `self^y` for a positive `self`.
    fn powf_el(self, y: Self) -> Self;
}

/// `Elementary` through nalgebra's scalar functions (std's or `libm`'s, as simba picks).
macro_rules! through_nalgebra {
    ($t:ty) => {
        impl Elementary for $t {
            fn sin_cos_el(self) -> (Self, Self) {
                nalgebra::ComplexField::sin_cos(self)
            }
            fn tan_el(self) -> Self {
                nalgebra::ComplexField::tan(self)
            }
            fn asin_el(self) -> Self {
                nalgebra::ComplexField::asin(self)
            }
            fn powf_el(self, y: Self) -> Self {
                nalgebra::ComplexField::powf(self, y)
            }
        }
    };
}

through_nalgebra!(f64);

#[cfg(any(target_os = "none", feature = "bounded-trig"))]
impl Elementary for f32 {
    fn sin_cos_el(self) -> (Self, Self) {
        bounded::sin_cos(self)
    }
    fn tan_el(self) -> Self {
        bounded::tan(self)
    }
    fn asin_el(self) -> Self {
        bounded::asin(self)
    }
    fn powf_el(self, y: Self) -> Self {
        bounded::powf(self, y)
    }
}

#[cfg(not(any(target_os = "none", feature = "bounded-trig")))]
through_nalgebra!(f32);

#[cfg(test)]
mod tests {
    use super::bounded;

    /// One unit in the last place of an `f32` between 0.5 and 1.
    const ULP: f64 = f32::EPSILON as f64 / 2.0;

    /// The largest difference from `f64` over `n` steps of `[lo, hi]`, in units of 2^-24.
    fn worst(lo: f64, hi: f64, n: u32, f: impl Fn(f32) -> f32, exact: impl Fn(f64) -> f64) -> f64 {
        (0..=n)
            .map(|i| {
                let x = (lo + (hi - lo) * f64::from(i) / f64::from(n)) as f32;
                (f64::from(f(x)) - exact(f64::from(x))).abs() / ULP
            })
            .fold(0.0, f64::max)
    }

    /// Over two turns either way (a million steps) the sine and cosine are within 1.5 units of
    /// 2^-24 of `f64`'s at the same `f32` argument (measured 1.31 and 1.39; `libm`'s `sinf`,
    /// rounded in `f64`, 0.50); between 11,000 and 12,000 rad, the exact reduction's end, as
    /// well (measured 1.19).
    #[test]
    fn sine_and_cosine_are_within_one_and_a_half_units_of_2_pow_minus_24_over_two_turns() {
        let turns = 2.0 * core::f64::consts::TAU;
        let s = worst(-turns, turns, 1_000_000, bounded::sin, libm::sin);
        let c = worst(-turns, turns, 1_000_000, bounded::cos, libm::cos);
        assert!(s <= 1.5 && c <= 1.5, "sin {s}, cos {c}");
        let libm = worst(-turns, turns, 1_000_000, libm::sinf, libm::sin);
        assert!(libm <= 1.0, "libm sinf {libm}");
        let far = worst(11_000.0, 12_000.0, 100_000, bounded::sin, libm::sin);
        assert!(far <= 1.5, "sin far out {far}");
        assert_eq!(bounded::sin_cos(0.0), (0.0, 1.0));
        let (s, c) = bounded::sin_cos(f32::NAN);
        assert!(s.is_nan() && c.is_nan() && bounded::sin(f32::INFINITY).is_nan());
        // Far beyond any flight quantity: still a sine and cosine of some angle.
        let (s, c) = bounded::sin_cos(3.0e9);
        assert!(
            (libm::hypot(f64::from(s), f64::from(c)) - 1.0).abs() < 1e-6,
            "{s} {c}"
        );
    }

    /// Tangents of slopes and bank angles (to 80 deg) within 4 units of 2^-24 relative (a
    /// quotient of two values each within 1.5; measured 3.48), arcsines over [-1, 1] within 2
    /// units (measured 1.94).
    #[test]
    fn tangent_and_arcsine_are_within_a_few_units_of_2_pow_minus_24() {
        let n = 200_000;
        let tan_worst = (0..=n)
            .map(|i| {
                let x = (-1.4 + 2.8 * f64::from(i) / f64::from(n)) as f32;
                let exact = libm::tan(f64::from(x));
                (f64::from(bounded::tan(x)) - exact).abs() / exact.abs().max(1.0) / ULP
            })
            .fold(0.0, f64::max);
        assert!(tan_worst <= 4.0, "tan {tan_worst}");
        let asin = worst(-1.0, 1.0, 1_000_000, bounded::asin, libm::asin);
        assert!(asin <= 2.0, "asin {asin}");
        assert!(bounded::asin(1.5).is_nan() && bounded::asin(f32::NAN).is_nan());
        assert_eq!(bounded::asin(1.0), core::f32::consts::FRAC_PI_2);
    }

    /// The hypotenuse within 1.5 units of 2^-24 relative (measured 1.45) from 1e-30 to 1e30,
    /// where the plain sum of squares would underflow or overflow; infinite with an infinite side even
    /// beside a NaN, as IEEE 754's `hypot`.
    #[test]
    fn the_hypotenuse_is_within_one_and_a_half_units_and_never_overflows() {
        let mut worst = 0.0f64;
        for e in -30..=30 {
            for (a, b) in [(3.0, 4.0), (1.0, 1e-3), (0.7, 0.69), (1.0, 0.0)] {
                let scale = libm::pow(10.0, f64::from(e));
                let (x, y) = ((a * scale) as f32, (b * scale) as f32);
                let exact = libm::hypot(f64::from(x), f64::from(y));
                let got = f64::from(bounded::hypot(x, -y));
                worst = worst.max((got - exact).abs() / exact / ULP);
            }
        }
        assert!(worst <= 1.5, "hypot {worst}");
        assert_eq!(bounded::hypot(0.0, 0.0), 0.0);
        assert_eq!(bounded::hypot(f32::NEG_INFINITY, f32::NAN), f32::INFINITY);
        assert!(bounded::hypot(f32::NAN, 1.0).is_nan());
    }

    /// Relative to `f64`'s, in units of 2^-24: the pressure altitude's exponent 0.19 on
    /// pressure ratios of 0.2 to 1.1 within 1.5 (measured 1.24); the pressure's 5.26 on
    /// temperature ratios within 14 (measured 13.0: the logarithm's rounding, times the
    /// exponent; 8e-7 of the pressure, 0.08 Pa or 7 mm of height); the designer's ratios to 1e4
    /// within 10 (measured 8.9). Non-positive bases give NaN.
    #[test]
    fn powers_of_positive_bases_are_within_a_few_units_of_2_pow_minus_24() {
        let worst = |lo: f64, hi: f64, y: f32| {
            (0..=10_000)
                .map(|i| {
                    let x = (lo + (hi - lo) * f64::from(i) / 10_000.0) as f32;
                    let exact = libm::pow(f64::from(x), f64::from(y));
                    (f64::from(bounded::powf(x, y)) - exact).abs() / exact / ULP
                })
                .fold(0.0, f64::max)
        };
        let altitude = worst(0.2, 1.1, 0.190_263);
        let pressure = worst(0.2, 1.1, 5.255_88);
        assert!(altitude <= 1.5 && pressure <= 14.0, "{altitude} {pressure}");
        let wide = worst(1.0, 1e4, 0.37).max(worst(1.0, 1e4, 1.0));
        assert!(wide <= 10.0, "wide {wide}");
        assert!(bounded::powf(0.0, 2.0).is_nan() && bounded::powf(-1.0, 2.0).is_nan());
    }
}
