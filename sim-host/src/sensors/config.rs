//! Sensor rates and noise: the `[sensors]` table of the aircraft file.

use serde::{Deserialize, Serialize};

/// GPS receiver model.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GpsConfig {
    /// Fix rate, Hz.
    pub rate_hz: f64,
    /// Horizontal position noise (1 sigma), m.
    pub horiz_m: f64,
    /// Vertical position noise (1 sigma), m.
    pub vert_m: f64,
    /// Velocity noise (1 sigma, each axis), m/s.
    pub vel_mps: f64,
    /// Time from measurement to delivery, s.
    pub latency_s: f64,
    /// Satellites reported.
    pub satellites: u8,
    /// Horizontal dilution of precision reported.
    pub hdop: f64,
    /// Position error of the first fixes after power-up, NED, m: a receiver's solution
    /// converges over a minute or two after a cold start, so the autopilot's home and
    /// initial position are off by about this much. Decays with `startup_tau_s`.
    #[serde(default, skip_serializing_if = "is_zero3")]
    pub startup_offset_m: [f64; 3],
    /// Time constant of that convergence, s.
    #[serde(
        default = "default_startup_tau",
        skip_serializing_if = "is_default_tau"
    )]
    pub startup_tau_s: f64,
}

fn default_startup_tau() -> f64 {
    60.0
}

fn is_default_tau(v: &f64) -> bool {
    *v == default_startup_tau()
}

fn is_zero3(v: &[f64; 3]) -> bool {
    *v == [0.0; 3]
}

impl Default for GpsConfig {
    fn default() -> Self {
        // The UMN legacy library has no GPS; these are the bolderflight re-hosting's values
        // (aircraft file, `gps_secondary_bolderflight`), with a typical u-blox latency.
        Self {
            rate_hz: 5.0,
            horiz_m: 1.5,
            vert_m: 5.5,
            vel_mps: 0.05,
            latency_s: 0.12,
            satellites: 12,
            hdop: 0.8,
            startup_offset_m: [0.0; 3],
            startup_tau_s: default_startup_tau(),
        }
    }
}

/// The flight battery's power monitor (voltage and current), sent as `BATTERY_STATUS`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BatteryMonitorConfig {
    /// Rate, Hz.
    pub rate_hz: f64,
    /// Voltage noise (1 sigma), V.
    #[serde(rename = "voltage_sigma_V")]
    pub voltage_sigma_v: f64,
    /// Current noise (1 sigma), A.
    #[serde(rename = "current_sigma_A")]
    pub current_sigma_a: f64,
}

impl Default for BatteryMonitorConfig {
    fn default() -> Self {
        // Not in the UMN sensor library: a typical analog power module's noise.
        Self {
            rate_hz: 10.0,
            voltage_sigma_v: 0.02,
            current_sigma_a: 0.1,
        }
    }
}

/// A downward rangefinder (sent as `DISTANCE_SENSOR`, orientation pitch 270). The defaults
/// are a Garmin LIDAR-Lite v3's datasheet figures (estimates for the airframe, which flies
/// none in the UMN data).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RangefinderConfig {
    /// Reading rate, Hz.
    pub rate_hz: f64,
    /// Shortest distance measured, m.
    pub min_m: f64,
    /// Longest distance measured, m: beyond it the sensor reports max + 1 cm.
    pub max_m: f64,
    /// Noise (1 sigma), m.
    pub sigma_m: f64,
    /// Full beam width, rad (reported; the model measures along the boresight).
    pub fov_rad: f64,
}

impl Default for RangefinderConfig {
    fn default() -> Self {
        // LIDAR-Lite v3: 40 m range, +-2.5 cm accuracy above 1 m, 8 mrad beam divergence.
        Self {
            rate_hz: 20.0,
            min_m: 0.1,
            max_m: 40.0,
            sigma_m: 0.025,
            fov_rad: 0.008,
        }
    }
}

/// Every sensor's rate and noise.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SensorConfig {
    /// IMU (and lock-step frame) rate, Hz.
    pub imu_rate_hz: f64,
    /// Gyro noise power per axis, (rad/s)^2 s (UMN `gyro_noise_power`).
    pub gyro_noise_power: [f64; 3],
    /// Accelerometer noise power per axis, (m/s^2)^2 s (UMN `accel_noise_power`).
    pub accel_noise_power: [f64; 3],
    /// Gyro turn-on bias per axis, rad/s.
    pub gyro_bias_radps: [f64; 3],
    /// Gyro bias random walk, rad/s per sqrt(s).
    pub gyro_bias_walk: f64,
    /// Accelerometer turn-on bias per axis, m/s^2.
    pub accel_bias_mps2: [f64; 3],
    /// Magnetometer rate, Hz.
    pub mag_rate_hz: f64,
    /// Earth field at home in NED, gauss.
    pub mag_field_ned_gauss: [f64; 3],
    /// Magnetometer noise power per axis, nT^2 s (UMN `mag_noise_power_nT`).
    #[serde(rename = "mag_noise_power_nT")]
    pub mag_noise_power_nt: [f64; 3],
    /// Barometer rate, Hz.
    pub baro_rate_hz: f64,
    /// Static-pressure noise power, kPa^2 s (UMN `ps_noise_power_kPa`).
    #[serde(rename = "ps_noise_power_kPa")]
    pub ps_noise_power_kpa: f64,
    /// Differential-pressure rate, Hz.
    pub pitot_rate_hz: f64,
    /// Differential-pressure noise power, kPa^2 s (UMN `pd_noise_power_kPa`).
    #[serde(rename = "pd_noise_power_kPa")]
    pub pd_noise_power_kpa: f64,
    /// GPS receiver.
    pub gps: GpsConfig,
    /// The battery's power monitor.
    pub battery: BatteryMonitorConfig,
    /// Calibration errors (scale factors, hard iron, pitot offset): none unless the file
    /// has a `[sensors.calibration]` table. Monte Carlo campaigns draw them per flight.
    #[serde(default, skip_serializing_if = "Calibration::is_ideal")]
    pub calibration: Calibration,
    /// A downward rangefinder: none unless the file has a `[sensors.rangefinder]` table (or
    /// `--rangefinder` adds the default one).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rangefinder: Option<RangefinderConfig>,
}

/// What a sensor's calibration leaves: each reading is `scale * truth + offset` before noise
/// and bias. The default is a perfect calibration.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Calibration {
    /// Gyro scale factor per axis (1: exact).
    pub gyro_scale: [f64; 3],
    /// Accelerometer scale factor per axis (1: exact).
    pub accel_scale: [f64; 3],
    /// Magnetometer hard-iron offset, body axes, gauss.
    pub mag_offset_gauss: [f64; 3],
    /// Differential-pressure scale factor (pitot position error and sensor gain; 1: exact).
    pub pitot_scale: f64,
    /// Differential-pressure zero offset, Pa.
    #[serde(rename = "pitot_offset_Pa")]
    pub pitot_offset_pa: f64,
}

impl Default for Calibration {
    fn default() -> Self {
        Self {
            gyro_scale: [1.0; 3],
            accel_scale: [1.0; 3],
            mag_offset_gauss: [0.0; 3],
            pitot_scale: 1.0,
            pitot_offset_pa: 0.0,
        }
    }
}

impl Calibration {
    /// True for a perfect calibration (what an aircraft file without the table means).
    pub fn is_ideal(&self) -> bool {
        *self == Self::default()
    }
}

impl Default for SensorConfig {
    fn default() -> Self {
        Self {
            imu_rate_hz: 100.0,
            gyro_noise_power: [1e-6; 3],
            accel_noise_power: [0.0008, 0.004, 0.004],
            gyro_bias_radps: [0.003, -0.002, 0.0015],
            gyro_bias_walk: 1e-5,
            accel_bias_mps2: [0.02, -0.015, 0.03],
            mag_rate_hz: 50.0,
            // IGRF at the UMN home (44.73 N, 93.08 W): 18 uT north, -0.2 uT east, 52 uT down.
            mag_field_ned_gauss: [0.18, -0.002, 0.52],
            mag_noise_power_nt: [150.0, 150.0, 80_000.0],
            baro_rate_hz: 50.0,
            ps_noise_power_kpa: 8e-7,
            pitot_rate_hz: 50.0,
            pd_noise_power_kpa: 1.5e-7,
            gps: GpsConfig::default(),
            battery: BatteryMonitorConfig::default(),
            calibration: Calibration::default(),
            rangefinder: None,
        }
    }
}

impl SensorConfig {
    /// Checks every rate positive and every noise finite and non-negative; the error is the
    /// dotted key, its value and the reason.
    pub fn validate(&self) -> Result<(), (String, String, &'static str)> {
        if !self.imu_rate_hz.is_finite() || self.imu_rate_hz <= 0.0 {
            return Err((
                "sensors.imu_rate_hz".into(),
                self.imu_rate_hz.to_string(),
                "must be positive",
            ));
        }
        let rates = [
            ("mag_rate_hz", self.mag_rate_hz),
            ("baro_rate_hz", self.baro_rate_hz),
            ("pitot_rate_hz", self.pitot_rate_hz),
            ("gps.rate_hz", self.gps.rate_hz),
            ("battery.rate_hz", self.battery.rate_hz),
        ];
        for (k, v) in rates {
            if !v.is_finite() || v <= 0.0 || v > self.imu_rate_hz {
                return Err((
                    format!("sensors.{k}"),
                    v.to_string(),
                    "must be positive and at most imu_rate_hz",
                ));
            }
        }
        let scalars = [
            ("gyro_bias_walk", self.gyro_bias_walk),
            ("ps_noise_power_kPa", self.ps_noise_power_kpa),
            ("pd_noise_power_kPa", self.pd_noise_power_kpa),
            ("gps.horiz_m", self.gps.horiz_m),
            ("gps.vert_m", self.gps.vert_m),
            ("gps.vel_mps", self.gps.vel_mps),
            ("gps.latency_s", self.gps.latency_s),
            ("gps.hdop", self.gps.hdop),
            ("battery.voltage_sigma_V", self.battery.voltage_sigma_v),
            ("battery.current_sigma_A", self.battery.current_sigma_a),
            ("gps.startup_tau_s", self.gps.startup_tau_s),
            ("calibration.pitot_scale", self.calibration.pitot_scale),
        ];
        for (k, v) in scalars {
            if !v.is_finite() || v < 0.0 {
                return Err((
                    format!("sensors.{k}"),
                    v.to_string(),
                    "must not be negative",
                ));
            }
        }
        let vectors = [
            ("gyro_noise_power", self.gyro_noise_power),
            ("accel_noise_power", self.accel_noise_power),
            ("mag_noise_power_nT", self.mag_noise_power_nt),
        ];
        for (k, v) in vectors {
            if v.iter().any(|x| !x.is_finite() || *x < 0.0) {
                return Err((
                    format!("sensors.{k}"),
                    format!("{v:?}"),
                    "must not be negative",
                ));
            }
        }
        let finite = [
            ("gyro_bias_radps", self.gyro_bias_radps),
            ("accel_bias_mps2", self.accel_bias_mps2),
            ("mag_field_ned_gauss", self.mag_field_ned_gauss),
            ("gps.startup_offset_m", self.gps.startup_offset_m),
            ("calibration.gyro_scale", self.calibration.gyro_scale),
            ("calibration.accel_scale", self.calibration.accel_scale),
            (
                "calibration.mag_offset_gauss",
                self.calibration.mag_offset_gauss,
            ),
        ];
        for (k, v) in finite {
            if v.iter().any(|x| !x.is_finite()) {
                return Err((format!("sensors.{k}"), format!("{v:?}"), "must be finite"));
            }
        }
        if let Some(r) = &self.rangefinder {
            let ok = r.rate_hz.is_finite()
                && r.rate_hz > 0.0
                && r.rate_hz <= self.imu_rate_hz
                && r.min_m >= 0.0
                && r.min_m < r.max_m
                && r.max_m < 650.0
                && r.sigma_m >= 0.0
                && r.sigma_m.is_finite()
                && r.fov_rad >= 0.0
                && r.fov_rad.is_finite();
            if !ok {
                return Err((
                    "sensors.rangefinder".into(),
                    format!("{r:?}"),
                    "needs a rate up to imu_rate_hz, 0 <= min_m < max_m < 650 m, sigma and fov not negative",
                ));
            }
        }
        if !self.calibration.pitot_offset_pa.is_finite() {
            return Err((
                "sensors.calibration.pitot_offset_Pa".into(),
                self.calibration.pitot_offset_pa.to_string(),
                "must be finite",
            ));
        }
        Ok(())
    }
}
