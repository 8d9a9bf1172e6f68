//! The estimator's parameters and the typed configuration built from them.

use crate::param;
use crate::params::{independent, Group, ParamDef};

/// Every tunable number of the estimator. Defaults follow the Ultra Stick 25e's sensor set
/// (UMN SIL sensor model, GPS of the bolderflight set) and are justified in `docs/ESTIMATOR.md`.
pub const PARAMS: Group<EstimatorConfig> = Group {
    name: "Estimator",
    params: &[
        param!(
            ParamDef::real(
                "EKF_GYR_NOISE",
                0.0015,
                1e-5,
                0.1,
                "rad/s/sqrt(Hz)",
                "gyro white-noise density (attitude process noise)",
            ),
            EstimatorConfig => gyro_noise
        ),
        param!(
            ParamDef::real(
                "EKF_GBIAS_RW",
                5e-5,
                0.0,
                0.01,
                "rad/s^2/sqrt(Hz)",
                "gyro bias random-walk density",
            ),
            EstimatorConfig => gyro_bias_rw
        ),
        param!(
            ParamDef::real(
                "EKF_GBIAS_INIT",
                0.05,
                1e-4,
                0.5,
                "rad/s",
                "initial 1-sigma uncertainty of each gyro bias",
            ),
            EstimatorConfig => gyro_bias_init
        ),
        param!(
            ParamDef::real(
                "EKF_ACC_NOISE",
                0.7,
                0.01,
                20.0,
                "m/s^2",
                "accelerometer gravity-reference noise per sample (sensor + unmodelled acceleration)",
            ),
            EstimatorConfig => accel_noise
        ),
        param!(
            ParamDef::real(
                "EKF_ACC_GATE",
                2.5,
                0.1,
                20.0,
                "m/s^2",
                "skip the gravity reference while |compensated accel| differs from g by more",
            ),
            EstimatorConfig => accel_gate
        ),
        param!(
            ParamDef::real(
                "EKF_MAG_NOISE",
                0.02,
                1e-4,
                1.0,
                "gauss",
                "magnetometer noise per axis and sample",
            ),
            EstimatorConfig => mag_noise
        ),
        param!(
            ParamDef::real(
                "MAG_EARTH_N",
                0.18,
                -1.0,
                1.0,
                "gauss",
                "earth field at home, north component",
            ),
            EstimatorConfig => mag_earth[0]
        ),
        param!(
            ParamDef::real(
                "MAG_EARTH_E",
                -0.002,
                -1.0,
                1.0,
                "gauss",
                "earth field at home, east component (IGRF at the UMN field: 0.5 deg W declination)",
            ),
            EstimatorConfig => mag_earth[1]
        ),
        param!(
            ParamDef::real(
                "MAG_EARTH_D",
                0.52,
                -1.0,
                1.0,
                "gauss",
                "earth field at home, down component",
            ),
            EstimatorConfig => mag_earth[2]
        ),
        param!(
            ParamDef::real(
                "EKF_NAV_ACC_N",
                0.1,
                0.001,
                10.0,
                "m/s^2/sqrt(Hz)",
                "accelerometer noise density of the inertial filter (velocity process noise)",
            ),
            EstimatorConfig => nav_accel_noise
        ),
        param!(
            ParamDef::real(
                "EKF_GPS_P_NOISE",
                1.5,
                0.05,
                100.0,
                "m",
                "GPS horizontal position noise (1 sigma per axis)",
            ),
            EstimatorConfig => gps_pos_noise
        ),
        param!(
            ParamDef::real(
                "EKF_GPS_Z_NOISE",
                5.5,
                0.05,
                100.0,
                "m",
                "GPS vertical position noise (1 sigma)",
            ),
            EstimatorConfig => gps_alt_noise
        ),
        param!(
            ParamDef::real(
                "EKF_GPS_V_NOISE",
                0.08,
                0.01,
                10.0,
                "m/s",
                "GPS velocity noise per axis (1 sigma)",
            ),
            EstimatorConfig => gps_vel_noise
        ),
        param!(
            ParamDef::real(
                "EKF_GPS_DELAY",
                0.15,
                0.0,
                0.5,
                "s",
                "age of a GPS fix when it arrives (receiver + link latency)",
            ),
            EstimatorConfig => gps_delay
        ),
        param!(
            ParamDef::real(
                "EKF_GPS_DLY_SD",
                0.04,
                0.0,
                0.2,
                "s",
                "uncertainty of EKF_GPS_DELAY (1 sigma): a fix read at the wrong instant differs \
                 by the acceleration (velocity) times the error, weighed as noise",
            ),
            EstimatorConfig => gps_delay_sd
        ),
        param!(
            ParamDef::real(
                "EKF_BARO_NOISE",
                0.8,
                0.01,
                20.0,
                "m",
                "barometric altitude noise per sample (1 sigma)",
            ),
            EstimatorConfig => baro_noise
        ),
        param!(
            ParamDef::real(
                "EKF_BARO_B_RW",
                0.01,
                0.0,
                1.0,
                "m/sqrt(s)",
                "random walk of the barometer's offset from GPS altitude",
            ),
            EstimatorConfig => baro_bias_rw
        ),
        param!(
            ParamDef::real(
                "EKF_GATE",
                5.0,
                1.0,
                100.0,
                "sigma",
                "innovation gate: larger innovations are rejected",
            ),
            EstimatorConfig => gate_sigma
        ),
        param!(
            ParamDef::real(
                "EKF_DR_V_NOISE",
                1.0,
                0.05,
                20.0,
                "m/s",
                "noise of the air-data velocity used while GPS is lost",
            ),
            EstimatorConfig => dead_reckon_vel_noise
        ),
        param!(
            ParamDef::real(
                "ARSP_TAU",
                0.1,
                0.0,
                5.0,
                "s",
                "time constant of the airspeed low-pass filter",
            ),
            EstimatorConfig => airspeed_tau
        ),
        param!(
            ParamDef::real(
                "ARSP_DTAU",
                0.5,
                0.02,
                5.0,
                "s",
                "time constant of the airspeed-rate filter (along-track acceleration)",
            ),
            EstimatorConfig => airspeed_rate_tau
        ),
        param!(
            ParamDef::real(
                "ARSP_MIN",
                6.0,
                0.0,
                30.0,
                "m/s",
                "airspeed below which wind is not estimated (on the ground)",
            ),
            EstimatorConfig => airspeed_min
        ),
        param!(
            ParamDef::real(
                "WIND_PNOISE",
                0.1,
                0.0,
                5.0,
                "m/s/sqrt(s)",
                "random walk of each horizontal wind component",
            ),
            EstimatorConfig => wind_process_noise
        ),
        param!(
            ParamDef::real(
                "WIND_VA_NOISE",
                0.5,
                0.01,
                10.0,
                "m/s",
                "airspeed noise in the wind filter (1 sigma)",
            ),
            EstimatorConfig => wind_airspeed_noise
        ),
        param!(
            ParamDef::real(
                "WIND_VY_NOISE",
                1.0,
                0.01,
                10.0,
                "m/s",
                "lateral air-velocity noise of the zero-sideslip assumption (1 sigma)",
            ),
            EstimatorConfig => wind_lateral_noise
        ),
        param!(
            ParamDef::real(
                "EST_SENS_TOUT",
                0.5,
                0.02,
                10.0,
                "s",
                "mag, baro and pitot are unhealthy after this long without a good sample",
            ),
            EstimatorConfig => sensor_timeout
        ),
        param!(
            ParamDef::real(
                "EST_GPS_TOUT",
                1.0,
                0.2,
                10.0,
                "s",
                "GPS is unhealthy after this long without a good 3D fix",
            ),
            EstimatorConfig => gps_timeout
        ),
        param!(
            ParamDef::int(
                "EST_HOME_SATS",
                6,
                4,
                30,
                "",
                "satellites a 3D fix needs to set home",
            ),
            EstimatorConfig => home_min_sats, count
        ),
        param!(
            ParamDef::real(
                "EST_HOME_HDOP",
                2.5,
                0.5,
                20.0,
                "",
                "largest HDOP of a fix that sets home",
            ),
            EstimatorConfig => home_max_hdop
        ),
        param!(
            ParamDef::int(
                "EST_MAX_REJECT",
                10,
                1,
                1000,
                "",
                "consecutive rejected samples that make a sensor unhealthy",
            ),
            EstimatorConfig => max_rejections, count
        ),
        param!(
            ParamDef::real(
                "EST_CONV_TILT",
                0.0175,
                0.001,
                0.5,
                "rad",
                "converged: 1-sigma roll/pitch uncertainty below this",
            ),
            EstimatorConfig => conv_tilt
        ),
        param!(
            ParamDef::real(
                "EST_CONV_HDG",
                0.05,
                0.001,
                1.0,
                "rad",
                "converged: 1-sigma heading uncertainty below this",
            ),
            EstimatorConfig => conv_heading
        ),
        param!(
            ParamDef::real(
                "EST_CONV_GBIAS",
                0.005,
                1e-4,
                0.1,
                "rad/s",
                "converged: 1-sigma gyro bias uncertainty (each axis) below this",
            ),
            EstimatorConfig => conv_gyro_bias
        ),
        param!(
            ParamDef::real(
                "EST_CONV_POS",
                3.0,
                0.1,
                100.0,
                "m",
                "converged: 1-sigma horizontal position uncertainty below this",
            ),
            EstimatorConfig => conv_pos
        ),
        param!(
            ParamDef::real(
                "EST_CONV_VEL",
                0.5,
                0.01,
                10.0,
                "m/s",
                "converged: 1-sigma velocity uncertainty below this",
            ),
            EstimatorConfig => conv_vel
        ),
        param!(
            ParamDef::real(
                "EST_CONV_NIS",
                4.0,
                0.5,
                100.0,
                "",
                "converged: averaged normalised GPS-velocity and mag-heading innovations below this",
            ),
            EstimatorConfig => conv_nis
        ),
    ],
    base: || ZERO,
    check: independent,
};

/// The estimator's settings, one field per entry of [`PARAMS`] (in SI units).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EstimatorConfig {
    /// `EKF_GYR_NOISE`, rad/s/sqrt(Hz).
    pub gyro_noise: f32,
    /// `EKF_GBIAS_RW`, rad/s^2/sqrt(Hz).
    pub gyro_bias_rw: f32,
    /// `EKF_GBIAS_INIT`, rad/s.
    pub gyro_bias_init: f32,
    /// `EKF_ACC_NOISE`, m/s^2.
    pub accel_noise: f32,
    /// `EKF_ACC_GATE`, m/s^2.
    pub accel_gate: f32,
    /// `EKF_MAG_NOISE`, gauss.
    pub mag_noise: f32,
    /// `MAG_EARTH_N`, `MAG_EARTH_E`, `MAG_EARTH_D`: earth field in NED, gauss.
    pub mag_earth: [f32; 3],
    /// `EKF_NAV_ACC_N`, m/s^2/sqrt(Hz).
    pub nav_accel_noise: f32,
    /// `EKF_GPS_P_NOISE`, m.
    pub gps_pos_noise: f32,
    /// `EKF_GPS_Z_NOISE`, m.
    pub gps_alt_noise: f32,
    /// `EKF_GPS_V_NOISE`, m/s.
    pub gps_vel_noise: f32,
    /// `EKF_GPS_DELAY`, s.
    pub gps_delay: f32,
    /// `EKF_GPS_DLY_SD`, s.
    pub gps_delay_sd: f32,
    /// `EKF_BARO_NOISE`, m.
    pub baro_noise: f32,
    /// `EKF_BARO_B_RW`, m/sqrt(s).
    pub baro_bias_rw: f32,
    /// `EKF_GATE`, standard deviations.
    pub gate_sigma: f32,
    /// `EKF_DR_V_NOISE`, m/s.
    pub dead_reckon_vel_noise: f32,
    /// `ARSP_TAU`, s.
    pub airspeed_tau: f32,
    /// `ARSP_DTAU`, s.
    pub airspeed_rate_tau: f32,
    /// `ARSP_MIN`, m/s.
    pub airspeed_min: f32,
    /// `WIND_PNOISE`, m/s/sqrt(s).
    pub wind_process_noise: f32,
    /// `WIND_VA_NOISE`, m/s.
    pub wind_airspeed_noise: f32,
    /// `WIND_VY_NOISE`, m/s.
    pub wind_lateral_noise: f32,
    /// `EST_SENS_TOUT`, s.
    pub sensor_timeout: f32,
    /// `EST_GPS_TOUT`, s.
    pub gps_timeout: f32,
    /// `EST_HOME_SATS`.
    pub home_min_sats: u32,
    /// `EST_HOME_HDOP`.
    pub home_max_hdop: f32,
    /// `EST_MAX_REJECT`.
    pub max_rejections: u32,
    /// `EST_CONV_TILT`, rad.
    pub conv_tilt: f32,
    /// `EST_CONV_HDG`, rad.
    pub conv_heading: f32,
    /// `EST_CONV_GBIAS`, rad/s.
    pub conv_gyro_bias: f32,
    /// `EST_CONV_POS`, m.
    pub conv_pos: f32,
    /// `EST_CONV_VEL`, m/s.
    pub conv_vel: f32,
    /// `EST_CONV_NIS`.
    pub conv_nis: f32,
}

/// Every field zero: the base the parameters' defaults are written over.
const ZERO: EstimatorConfig = EstimatorConfig {
    gyro_noise: 0.0,
    gyro_bias_rw: 0.0,
    gyro_bias_init: 0.0,
    accel_noise: 0.0,
    accel_gate: 0.0,
    mag_noise: 0.0,
    mag_earth: [0.0; 3],
    nav_accel_noise: 0.0,
    gps_pos_noise: 0.0,
    gps_alt_noise: 0.0,
    gps_vel_noise: 0.0,
    gps_delay: 0.0,
    gps_delay_sd: 0.0,
    baro_noise: 0.0,
    baro_bias_rw: 0.0,
    gate_sigma: 0.0,
    dead_reckon_vel_noise: 0.0,
    airspeed_tau: 0.0,
    airspeed_rate_tau: 0.0,
    airspeed_min: 0.0,
    wind_process_noise: 0.0,
    wind_airspeed_noise: 0.0,
    wind_lateral_noise: 0.0,
    sensor_timeout: 0.0,
    gps_timeout: 0.0,
    home_min_sats: 0,
    home_max_hdop: 0.0,
    max_rejections: 0,
    conv_tilt: 0.0,
    conv_heading: 0.0,
    conv_gyro_bias: 0.0,
    conv_pos: 0.0,
    conv_vel: 0.0,
    conv_nis: 0.0,
};

impl Default for EstimatorConfig {
    /// The defaults of [`PARAMS`] (the only place they are written).
    fn default() -> Self {
        PARAMS.defaults()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::{validate_defs, ParamError};

    #[test]
    fn params_are_well_formed_and_all_reachable() {
        assert_eq!(validate_defs(PARAMS.defs()), Ok(()));
        let c = EstimatorConfig::default();
        for p in PARAMS.params {
            assert_eq!((p.get)(&c), p.def.default, "{}", p.def.name);
        }
        assert_eq!(c.mag_earth, [0.18, -0.002, 0.52]);
    }

    #[test]
    fn set_refuses_bad_values_and_keeps_the_old_one() {
        let mut c = EstimatorConfig::default();
        let p = PARAMS;
        assert_eq!(
            p.set(&mut c, "EKF_GPS_DELAY", f32::NAN),
            Err(ParamError::NotFinite)
        );
        assert_eq!(
            p.set(&mut c, "EKF_GPS_DELAY", 3.0),
            Err(ParamError::OutOfBounds)
        );
        assert_eq!(p.set(&mut c, "NO_SUCH", 1.0), Err(ParamError::Unknown));
        assert_eq!(
            p.set(&mut c, "EST_MAX_REJECT", 2.5),
            Err(ParamError::NotInteger)
        );
        assert_eq!(c.gps_delay, 0.15);
        assert_eq!(p.set(&mut c, "EKF_GPS_DELAY", 0.2), Ok(()));
        assert_eq!(c.gps_delay, 0.2);
        assert_eq!(p.set(&mut c, "EST_MAX_REJECT", 20.0), Ok(()));
        assert_eq!(c.max_rejections, 20);
    }
}
