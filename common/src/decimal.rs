//! Numbers in texts (STATUSTEXT) as fixed-point decimals, without core's float formatting.
//!
//! `core::fmt` writes an `f32` through Grisu with a Dragon4 fallback: some 17 KB of an MCU
//! image, for a handful of numbers in warning texts. A number with a fixed count of decimals
//! needs none of it: an `f32` is `m * 2^e` exactly, so `m * 10^places / 2^-e`, rounded half to
//! even, is the exact answer in 64-bit integers (`m` < 2^24, `10^9` < 2^30), and the digits are
//! an integer's. The crates made for small formatting (`ufmt`, `numtoa`, `itoa`) write
//! integers only, and `ryu` writes the shortest form with its own tables and exponents, so this
//! module is that arithmetic and nothing more.
//!
//! [`fixed`] writes what `format!("{:.N}", x)` writes, for every `f32` (the tests hold it to
//! std's own output); [`trimmed`] drops the trailing zeros of that, for texts where `0.05` and
//! `17` read better than `0.050000` and `17.000000`.

use core::fmt;
use core::num::NonZeroU64;

/// The most decimals written: `10^9 * 2^24` still fits in 64 bits.
pub const MAX_PLACES: u8 = 9;

/// An `f32` written with a fixed count of decimals ([`fixed`], [`trimmed`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Decimal {
    value: f32,
    places: u8,
    trim: bool,
}

/// `value` with `places` decimals (at most [`MAX_PLACES`]), as `format!("{:.places$}")` writes
/// it: rounded half to even on the exact binary value, `-` on every negative value (`-0.00`),
/// `NaN`, `inf` and `-inf` for the non-finite.
pub fn fixed(value: f32, places: u8) -> Decimal {
    Decimal {
        value,
        places: places.min(MAX_PLACES),
        trim: false,
    }
}

/// As [`fixed`], without the trailing zeros of the decimals (nor the point, when none is
/// left): `17.000` is `17`, `0.050` is `0.05`.
pub fn trimmed(value: f32, places: u8) -> Decimal {
    Decimal {
        trim: true,
        ..fixed(value, places)
    }
}

impl fmt::Display for Decimal {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.write_with(&mut |piece| f.write_str(piece))
    }
}

impl Decimal {
    /// Writes what [`Display`](fmt::Display) writes, as pieces of text handed to `put`, the
    /// same pieces as a `write!` of the number would hand a `core::fmt::Write` (the digits of
    /// an integer part or of the decimals whole, each padding zero and each digit of a number
    /// of 2^24 or more on its own); stops at the first piece `put` refuses. Without
    /// `core::fmt`: the MCU image's texts write numbers this way ([`crate::gcs::texts::Line`]).
    pub fn write_with<E>(&self, put: &mut dyn FnMut(&str) -> Result<(), E>) -> Result<(), E> {
        let x = self.value;
        if x.is_nan() {
            return put("NaN");
        }
        if x.is_sign_negative() {
            put("-")?;
        }
        if x.is_infinite() {
            return put("inf");
        }
        let bits = x.to_bits();
        let biased = (bits >> 23) & 0xFF;
        let fraction = bits & 0x7F_FFFF;
        // value = m * 2^e (subnormals have no implicit bit).
        let (m, e) = if biased == 0 {
            (fraction, -149)
        } else {
            (fraction | 0x80_0000, biased as i32 - 150)
        };
        let places = u32::from(self.places.min(MAX_PLACES));
        if let Ok(shift) = u32::try_from(e) {
            // A whole number, no fraction to round.
            write_whole(put, m, shift)?;
            return self.write_fraction(put, 0, places);
        }
        let shift = e.unsigned_abs();
        // Never zero; as `NonZeroU64` the divisions below carry no panic path.
        let scale = NonZeroU64::new(10u64.pow(places)).unwrap_or(NonZeroU64::MIN);
        let scaled = u64::from(m) * scale.get();
        // Below 2^-64, m * 10^places < 2^54 is under half a unit: it rounds to zero.
        let q = if shift >= 64 {
            0
        } else {
            let q = scaled >> shift;
            let rest = scaled & ((1u64 << shift) - 1);
            let half = 1u64 << (shift - 1);
            if rest > half || (rest == half && q & 1 == 1) {
                q + 1
            } else {
                q
            }
        };
        let mut buf = [0u8; 20];
        put(digits(q / scale, &mut buf))?;
        self.write_fraction(put, q % scale, places)
    }
}

/// `v` in decimal, as `{}` writes it, in the end of `buf`.
pub(crate) fn digits(v: u64, buf: &mut [u8; 20]) -> &str {
    let mut n = v;
    let mut i = buf.len();
    while let Some(j) = i.checked_sub(1) {
        i = j;
        if let Some(d) = buf.get_mut(i) {
            *d = b'0' + (n % 10) as u8;
        }
        n /= 10;
        if n == 0 {
            break;
        }
    }
    // ASCII digits: always UTF-8.
    buf.get(i..)
        .and_then(|d| core::str::from_utf8(d).ok())
        .unwrap_or("")
}

/// Writes `m * 2^shift` (below 2^128: at most 39 digits) by doubling its decimal digits, so
/// the image needs no 128-bit formatting for the few texts that could carry such a number.
fn write_whole<E>(put: &mut dyn FnMut(&str) -> Result<(), E>, m: u32, shift: u32) -> Result<(), E> {
    // Least significant digit first; `len` of them in use.
    let mut digits = [0u8; 39];
    let mut len = 0;
    let mut v = m;
    while v > 0 {
        if let Some(d) = digits.get_mut(len) {
            *d = (v % 10) as u8;
        }
        v /= 10;
        len += 1;
    }
    for _ in 0..shift {
        let mut carry = 0;
        for d in digits.iter_mut().take(len) {
            let t = *d * 2 + carry;
            *d = t % 10;
            carry = t / 10;
        }
        if let Some(d) = digits.get_mut(len).filter(|_| carry > 0) {
            *d = carry;
            len += 1;
        }
    }
    for &d in digits.iter().take(len.max(1)).rev() {
        put(DIGITS.get(usize::from(d)..=usize::from(d)).unwrap_or("0"))?;
    }
    Ok(())
}

const DIGITS: &str = "0123456789";

impl Decimal {
    /// Writes `.` and `digits` (`places` of them, zero-padded; trimmed if asked).
    fn write_fraction<E>(
        &self,
        put: &mut dyn FnMut(&str) -> Result<(), E>,
        digits: u64,
        places: u32,
    ) -> Result<(), E> {
        let (mut digits, mut places) = (digits, places);
        if self.trim {
            while places > 0 && digits % 10 == 0 {
                digits /= 10;
                places -= 1;
            }
        }
        if places == 0 {
            return Ok(());
        }
        put(".")?;
        let mut buf = [0u8; 20];
        let text = self::digits(digits, &mut buf);
        for _ in text.len()..places as usize {
            put("0")?;
        }
        put(text)
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use std::format;
    use std::string::{String, ToString};

    fn std_trimmed(s: String) -> String {
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s
        }
    }

    fn check(x: f32) {
        for p in 0..=MAX_PLACES {
            let want = format!("{:.*}", usize::from(p), x);
            assert_eq!(fixed(x, p).to_string(), want, "{x:e} with {p} places");
            let want = std_trimmed(want);
            assert_eq!(trimmed(x, p).to_string(), want, "{x:e} trimmed to {p}");
        }
    }

    #[test]
    fn fixed_decimals_are_what_std_writes_for_chosen_values() {
        let values = [
            0.0,
            -0.0,
            1.0,
            -1.0,
            0.1,
            -0.1,
            0.5,
            1.5,
            2.5,
            -2.5,
            0.125,
            0.375,
            -0.625,
            0.05,
            17.3,
            -273.15,
            9.999_999,
            99.995,
            1e-5,
            -1e-5,
            1e-10,
            f32::MIN_POSITIVE,
            1e-45,
            -1e-45,
            8_388_607.5,
            16_777_216.0,
            1e20,
            -3.0e38,
            f32::MAX,
            f32::MIN,
            f32::EPSILON,
        ];
        for x in values {
            check(x);
        }
    }

    #[test]
    fn non_finite_values_are_written_as_std_writes_them() {
        for x in [f32::NAN, -f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
            check(x);
        }
    }

    #[test]
    fn fixed_decimals_are_what_std_writes_for_every_kind_of_f32() {
        // xorshift over the bit patterns: every exponent, subnormals and ties included.
        let mut s: u32 = 0x2545_F491;
        for _ in 0..20_000 {
            s ^= s << 13;
            s ^= s >> 17;
            s ^= s << 5;
            check(f32::from_bits(s));
            // Numbers of the size texts carry, with few significant bits (exact ties).
            check((s % 200_000) as f32 / 64.0 - 1_000.0);
        }
    }

    #[test]
    fn more_places_than_the_most_are_the_most() {
        assert_eq!(fixed(0.1, 30).to_string(), format!("{:.9}", 0.1f32));
    }
}
