//! Raw sensor samples, as the estimator consumes them.
//!
//! On the MCU they come from drivers; in SITL from the simulator's `HIL_SENSOR`, `HIL_GPS` and
//! `BATTERY_STATUS` frames. Units are SI: specific force in m/s^2 (level flight reads z = -g),
//! rates in rad/s, magnetic field in gauss, pressures in Pa, temperatures in deg C, volts and
//! amperes.

pub mod limits;

use crate::math::geodetic::GeoPoint;
use nalgebra::Vector3;

/// One IMU sample in the body frame.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ImuSample {
    /// Specific force (accelerometer), m/s^2.
    pub accel: Vector3<f32>,
    /// Angular rate (gyro), rad/s.
    pub gyro: Vector3<f32>,
}

/// One magnetometer sample in the body frame, gauss.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MagSample {
    /// Field vector, gauss.
    pub field: Vector3<f32>,
}

/// One barometer sample.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BaroSample {
    /// Static pressure, Pa.
    pub pressure_pa: f32,
    /// Temperature, deg C.
    pub temperature_c: f32,
}

/// One differential-pressure (pitot-static) sample.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PitotSample {
    /// Total minus static pressure, Pa.
    pub diff_pressure_pa: f32,
}

/// One GPS fix.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct GpsFix {
    /// Horizontal position.
    pub position: GeoPoint,
    /// Altitude above mean sea level, m.
    pub alt_amsl_m: f32,
    /// Velocity in NED, m/s.
    pub vel_ned: Vector3<f32>,
    /// 0-1: no fix, 2: 2D, 3: 3D (MAVLink `GPS_FIX_TYPE`).
    pub fix_type: u8,
    /// Satellites used.
    pub satellites: u8,
    /// Horizontal dilution of precision.
    pub hdop: f32,
}

/// One reading of the flight battery's power monitor.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BatterySample {
    /// Pack voltage at the terminals, V.
    pub voltage_v: f32,
    /// Current drawn from the pack, A (negative while charging).
    pub current_a: f32,
}

/// One reading of a downward rangefinder (`DISTANCE_SENSOR`, orientation pitch 270).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RangeSample {
    /// Distance along the sensor's axis, m. At or above `max_m`: no echo within range (PX4
    /// reports max + 1 cm); at or below `min_m`: too close to measure.
    pub distance_m: f32,
    /// Shortest distance the sensor measures, m.
    pub min_m: f32,
    /// Longest distance the sensor measures, m.
    pub max_m: f32,
    /// Signal quality as MAVLink gives it: 0 unknown, 1 invalid, 2..=100 poor to perfect.
    pub quality: u8,
}

/// Stick positions, normalised: a ground station's `MANUAL_CONTROL` or the radio's
/// `RC_CHANNELS`.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ManualInput {
    /// Roll stick, -1..1, positive right.
    pub roll: f32,
    /// Pitch stick, -1..1, positive nose up (stick back; MANUAL_CONTROL's x is forward).
    pub pitch: f32,
    /// Yaw stick, -1..1, positive nose right.
    pub yaw: f32,
    /// Throttle, 0..1.
    pub throttle: f32,
    /// When it arrived, us.
    pub time_us: u64,
}

/// One sensor frame: the samples taken at one instant, `None` where a sensor has nothing new.
/// The simulator link decodes `HIL_SENSOR` into it; a board's drivers fill it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SensorFrame {
    /// When the samples were taken, us: the autopilot's clock (the simulator's in lock-step).
    pub time_us: u64,
    /// Accelerometer and gyro.
    pub imu: Option<ImuSample>,
    /// Magnetometer.
    pub mag: Option<MagSample>,
    /// Barometer.
    pub baro: Option<BaroSample>,
    /// Differential pressure.
    pub pitot: Option<PitotSample>,
    /// The source reset its state (`HIL_SENSOR` bit 31).
    pub reset: bool,
}
