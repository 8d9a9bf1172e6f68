//! Sine and cosine of a latitude, for the MCU image.
//!
//! The geodetic conversions take the sine and cosine of latitudes in `f64`. The `libm` crate's
//! `sin` and `cos` reduce any argument, however large, to within a quarter turn, and carry the
//! code for it (3.2 KB of the image's flash). A latitude never leaves +-pi/2, where two Taylor
//! series (to the 17th and 18th power, whose first omitted terms are under 1e-19 within pi/4)
//! and the complementary angle do as well. The MCU image uses these ([`sin`], [`cos`]); the host
//! build keeps `libm`'s unless `common`'s `bounded-trig` feature is on (sim-host's `mcu-libm`
//! turns it on, so that the host answers bit for bit as the image). The test below states the
//! largest difference from `libm`.

use core::f64::consts::{FRAC_PI_2, FRAC_PI_4};

/// The sine series' coefficients after its first term, `(-1)^k / (2k + 1)!` for k = 1..8 (to
/// its x^17 term; with one term fewer, 2.2e-16 from `libm`).
const SIN_COEFFS: [f64; 8] = [
    -1.0 / 6.0,
    1.0 / 120.0,
    -1.0 / 5_040.0,
    1.0 / 362_880.0,
    -1.0 / 39_916_800.0,
    1.0 / 6_227_020_800.0,
    -1.0 / 1_307_674_368_000.0,
    1.0 / 355_687_428_096_000.0,
];

/// The cosine series' coefficients after its first term, `(-1)^k / (2k)!` for k = 1..9 (to
/// its x^18 term).
const COS_COEFFS: [f64; 9] = [
    -1.0 / 2.0,
    1.0 / 24.0,
    -1.0 / 720.0,
    1.0 / 40_320.0,
    -1.0 / 3_628_800.0,
    1.0 / 479_001_600.0,
    -1.0 / 87_178_291_200.0,
    1.0 / 20_922_789_888_000.0,
    -1.0 / 6_402_373_705_728_000.0,
];

/// `1 + c1 x2 + c2 x2^2 + ...` by Horner's rule: one product and one sum a term, each a
/// software routine on the Cortex-M4F.
fn series(x2: f64, coeffs: &[f64]) -> f64 {
    let q = match coeffs.split_last() {
        Some((last, rest)) => rest.iter().rev().fold(*last, |q, c| q * x2 + c),
        None => 0.0,
    };
    1.0 + x2 * q
}

/// `sin x` for `|x| <= pi/4`.
fn sin_kernel(x: f64) -> f64 {
    x * series(x * x, &SIN_COEFFS)
}

/// `cos x` for `|x| <= pi/4`.
fn cos_kernel(x: f64) -> f64 {
    series(x * x, &COS_COEFFS)
}

/// `|x|` of a latitude within +-pi/2 (beyond, which no valid latitude reaches, the pole's),
/// and whether it lies beyond pi/4, where the complementary angle is the kernels' argument
/// (`pi/2 - a` is exact there: Sterbenz's lemma).
fn reduce(x: f64) -> (f64, bool) {
    let a = x.abs().min(FRAC_PI_2);
    if a <= FRAC_PI_4 {
        (a, false)
    } else {
        (FRAC_PI_2 - a, true)
    }
}

/// `sin x` of a latitude `x` (rad); NaN gives NaN.
pub fn sin(x: f64) -> f64 {
    if x.is_nan() {
        return f64::NAN;
    }
    let (a, complement) = reduce(x);
    let s = if complement {
        cos_kernel(a)
    } else {
        sin_kernel(a)
    };
    s.copysign(x)
}

/// `cos x` of a latitude `x` (rad); NaN gives NaN.
pub fn cos(x: f64) -> f64 {
    if x.is_nan() {
        return f64::NAN;
    }
    let (a, complement) = reduce(x);
    if complement {
        sin_kernel(a)
    } else {
        cos_kernel(a)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Over every latitude (a million steps from -pi/2 to pi/2) the sine and cosine differ
    /// from `libm`'s by at most 2^-53 = 1.1e-16, one unit in the last place of a value between
    /// 0.5 and 1 (measured: 1.1e-16 for both): at the Earth's radius, under a nanometre.
    #[test]
    fn latitude_sine_and_cosine_agree_with_libm_within_one_unit_of_1e_16() {
        let n = 1_000_000;
        let (mut ds, mut dc) = (0.0f64, 0.0f64);
        for i in 0..=n {
            let x = -FRAC_PI_2 + core::f64::consts::PI * f64::from(i) / f64::from(n);
            let (s, c) = (sin(x), cos(x));
            ds = ds.max((s - libm::sin(x)).abs());
            dc = dc.max((c - libm::cos(x)).abs());
        }
        let ulp = f64::EPSILON / 2.0;
        assert!(ds <= ulp && dc <= ulp, "sin {ds:e}, cos {dc:e}");
        assert_eq!((sin(0.0), cos(0.0)), (0.0, 1.0));
        assert!(sin(f64::NAN).is_nan() && cos(f64::NAN).is_nan());
        assert_eq!((sin(10.0), cos(10.0)), (sin(FRAC_PI_2), cos(FRAC_PI_2)));
    }
}
