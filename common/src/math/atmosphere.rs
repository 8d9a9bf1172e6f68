//! The U.S. Standard Atmosphere 1976, troposphere (0 to 11 km geopotential altitude).
//!
//! The plant takes air density from it and the barometer model its static pressure; the
//! estimator inverts it to turn pressure into altitude. One set of constants serves all three.

use super::elementary::Elementary;
use nalgebra::RealField;

/// Sea-level standard pressure, Pa.
pub const P0_PA: f64 = 101_325.0;
/// Sea-level standard temperature, K.
pub const T0_K: f64 = 288.15;
/// Tropospheric lapse rate, K/m.
pub const LAPSE_K_PER_M: f64 = 0.0065;
/// Specific gas constant of dry air, J/(kg K) (US1976: R* / M0).
pub const R_AIR: f64 = 287.052_87;
/// Standard gravity of the atmosphere model, m/s^2 (not the plant's local g).
pub const G0: f64 = super::STANDARD_GRAVITY;
/// Top of the troposphere, m.
pub const TROPOPAUSE_M: f64 = 11_000.0;

fn c<T: RealField + Copy>(x: f64) -> T {
    T::from_subset(&x)
}

/// Temperature, static pressure and density at one altitude.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AirState<T> {
    /// Temperature, K.
    pub temperature_k: T,
    /// Static pressure, Pa.
    pub pressure_pa: T,
    /// Density, kg/m^3.
    pub density: T,
}

/// The standard atmosphere at `alt_m` above mean sea level, clamped to 0..11 km.
pub fn standard_atmosphere<T: Elementary>(alt_m: T) -> AirState<T> {
    let h = alt_m.clamp(c(-500.0), c(TROPOPAUSE_M));
    let temperature_k = c::<T>(T0_K) - c::<T>(LAPSE_K_PER_M) * h;
    let exponent = c::<T>(G0 / (R_AIR * LAPSE_K_PER_M));
    let pressure_pa = c::<T>(P0_PA) * (temperature_k / c(T0_K)).powf_el(exponent);
    AirState {
        temperature_k,
        pressure_pa,
        density: pressure_pa / (c::<T>(R_AIR) * temperature_k),
    }
}

/// Pressure altitude (m above mean sea level) of a static pressure, the inverse of
/// [`standard_atmosphere`]. Non-positive pressure returns `None`.
pub fn pressure_altitude<T: Elementary>(pressure_pa: T) -> Option<T> {
    if pressure_pa <= T::zero() || !pressure_pa.is_finite() {
        return None;
    }
    let exponent = c::<T>(R_AIR * LAPSE_K_PER_M / G0);
    let ratio = (pressure_pa / c(P0_PA)).powf_el(exponent);
    Some(c::<T>(T0_K / LAPSE_K_PER_M) * (T::one() - ratio))
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn matches_the_us1976_tables() {
        // Density at 100 m that reproduces the UMN trim (aircraft data file).
        assert_relative_eq!(
            standard_atmosphere(100.0_f64).density,
            1.21328,
            epsilon = 5e-6
        );
        // US1976 table values at 1000 m: 89 876 Pa, 1.1117 kg/m^3, 281.65 K.
        let a = standard_atmosphere(1000.0_f64);
        assert_relative_eq!(a.pressure_pa, 89_876.0, epsilon = 2.0);
        assert_relative_eq!(a.density, 1.1117, epsilon = 1e-4);
        assert_relative_eq!(a.temperature_k, 281.65, epsilon = 1e-9);
    }

    #[test]
    fn pressure_altitude_inverts() {
        for h in [0.0_f32, 100.0, 523.0, 3000.0] {
            let p = standard_atmosphere(h).pressure_pa;
            assert_relative_eq!(pressure_altitude(p).unwrap_or(f32::NAN), h, epsilon = 0.2);
        }
        assert!(pressure_altitude(-1.0_f32).is_none());
        assert!(pressure_altitude(f32::NAN).is_none());
    }
}
