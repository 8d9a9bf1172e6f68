//! Plausibility limits: beyond these a sensor value is a fault, not a measurement. The
//! simulator link's decoder and the estimator check against the same numbers, so a value the
//! link lets through is one the estimator will not refuse on range alone.

use super::{BaroSample, BatterySample, GpsFix, ImuSample, MagSample, PitotSample};
use crate::math::GRAVITY;
use nalgebra::Vector3;

/// Largest specific force per axis, m/s^2 (16 g, the range of common MEMS accelerometers).
pub const ACCEL_MPS2: f32 = 16.0 * GRAVITY;
/// Largest angular rate per axis, rad/s (2000 deg/s, the usual gyro range).
pub const GYRO_RADPS: f32 = 34.9;
/// Magnetic field strength, gauss (the earth's field is 0.25-0.65 G; room for local
/// disturbance).
pub const MAG_GAUSS: (f32, f32) = (0.05, 2.0);
/// Static pressure, Pa (-600 m to 12 km in the standard atmosphere).
pub const BARO_PA: (f32, f32) = (19_000.0, 110_000.0);
/// Air temperature at the barometer, deg C.
pub const TEMP_C: (f32, f32) = (-80.0, 85.0);
/// Differential pressure, Pa (noise at rest reads slightly negative; 20 kPa is about
/// 180 m/s).
pub const PITOT_PA: (f32, f32) = (-500.0, 20_000.0);
/// GPS altitude, m.
pub const GPS_ALT_M: (f32, f32) = (-1_000.0, 20_000.0);
/// Largest GPS speed, m/s.
pub const GPS_SPEED_MPS: f32 = 150.0;

/// Pack voltage, V (up to a 14-cell pack, with room).
pub const BATTERY_V: (f32, f32) = (0.0, 60.0);
/// Pack current, A (a little charging current, up to what a small aircraft's power module
/// measures).
pub const BATTERY_A: (f32, f32) = (-20.0, 300.0);

/// Finite and inside `[lo, hi]`.
pub fn in_range(x: f32, (lo, hi): (f32, f32)) -> bool {
    x.is_finite() && x >= lo && x <= hi
}

/// Every component finite and at most `limit` in magnitude.
pub fn within(v: &Vector3<f32>, limit: f32) -> bool {
    v.iter().all(|c| c.is_finite() && c.abs() <= limit)
}

impl ImuSample {
    /// Every axis finite and inside the accelerometer's and gyro's ranges.
    pub fn plausible(&self) -> bool {
        within(&self.accel, ACCEL_MPS2) && within(&self.gyro, GYRO_RADPS)
    }
}

impl MagSample {
    /// Finite, with a field strength an earth field can have.
    pub fn plausible(&self) -> bool {
        self.field.iter().all(|c| c.is_finite()) && in_range(self.field.norm(), MAG_GAUSS)
    }
}

impl BaroSample {
    /// Pressure and temperature inside their ranges.
    pub fn plausible(&self) -> bool {
        in_range(self.pressure_pa, BARO_PA) && in_range(self.temperature_c, TEMP_C)
    }
}

impl PitotSample {
    /// Differential pressure inside its range.
    pub fn plausible(&self) -> bool {
        in_range(self.diff_pressure_pa, PITOT_PA)
    }
}

impl BatterySample {
    /// Voltage and current finite and inside their ranges.
    pub fn plausible(&self) -> bool {
        in_range(self.voltage_v, BATTERY_V) && in_range(self.current_a, BATTERY_A)
    }
}

impl GpsFix {
    /// A valid position, an altitude and a speed a small aircraft can have, finite numbers
    /// (HDOP may be infinite: unknown).
    pub fn plausible(&self) -> bool {
        self.position.is_valid()
            && in_range(self.alt_amsl_m, GPS_ALT_M)
            && self.vel_ned.iter().all(|c| c.is_finite())
            && self.vel_ned.norm() <= GPS_SPEED_MPS
            && !self.hdop.is_nan()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_level_sample_is_plausible_and_a_nan_or_a_30_g_one_is_not() {
        let level = ImuSample {
            accel: Vector3::new(0.0, 0.0, -GRAVITY),
            gyro: Vector3::zeros(),
        };
        assert!(level.plausible());
        let hard = ImuSample {
            accel: Vector3::new(0.0, 0.0, -30.0 * GRAVITY),
            ..level
        };
        assert!(!hard.plausible());
        let nan = ImuSample {
            gyro: Vector3::new(f32::NAN, 0.0, 0.0),
            ..level
        };
        assert!(!nan.plausible());
        // The earth's field (about 0.5 G) passes; a magnet on the sensor (5 G) does not.
        let earth = MagSample {
            field: Vector3::new(0.18, -0.002, 0.52),
        };
        assert!(earth.plausible());
        assert!(!MagSample {
            field: earth.field * 10.0
        }
        .plausible());
        // Sea level passes; a vacuum does not.
        let sea = BaroSample {
            pressure_pa: 101_325.0,
            temperature_c: 15.0,
        };
        assert!(sea.plausible());
        assert!(!BaroSample {
            pressure_pa: 0.0,
            ..sea
        }
        .plausible());
    }

    #[test]
    fn a_loaded_3s_pack_is_plausible_and_a_nan_or_a_100_v_one_is_not() {
        let pack = BatterySample {
            voltage_v: 11.1,
            current_a: 25.0,
        };
        assert!(pack.plausible());
        for bad in [
            BatterySample {
                voltage_v: f32::NAN,
                ..pack
            },
            BatterySample {
                voltage_v: 100.0,
                ..pack
            },
            BatterySample {
                current_a: -50.0,
                ..pack
            },
            BatterySample {
                current_a: f32::INFINITY,
                ..pack
            },
        ] {
            assert!(!bad.plausible(), "{bad:?}");
        }
    }
}
