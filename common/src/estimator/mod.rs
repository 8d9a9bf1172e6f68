//! State estimation from raw sensors: attitude, gyro bias, position, velocity, air data, wind.
//!
//! [`Estimator`] is the facade the autopilot loop talks to. It owns three filters, each a plain
//! struct with its own `predict`/`update` (see `docs/ESTIMATOR.md` for the design):
//! - [`ins::Ins`]: error-state EKF on attitude, velocity, position, gyro bias and barometer
//!   offset, driven by the IMU and corrected by delayed GPS position and velocity (which level
//!   it whatever the aircraft's accelerations), the barometer, the magnetic heading, and,
//!   while GPS is missing, by the accelerometer as a gravity reference and by air data;
//! - [`air::AirspeedFilter`]: true airspeed from the pitot and the barometer's density;
//! - [`air::WindFilter`]: horizontal wind from airspeed and zero sideslip.
//!
//! Home and the NED origin's rules (the provisional home of the first fix, the home held once
//! set) are in `origin`; [`Home`] is re-exported here.
//!
//! The clock is the sum of the IMU time steps; every other sensor is stamped with it when it
//! arrives. Each input is checked before use: a non-finite or physically absurd sample is
//! counted and dropped, and the state stays as it was.

pub mod air;
pub mod config;
pub mod hagl;
pub mod health;
pub mod ins;
pub mod kalman;
mod origin;

#[cfg(test)]
mod tests;
#[cfg(test)]
pub(crate) mod truth;

pub use config::{EstimatorConfig, PARAMS};
pub use health::{SensorHealth, SensorStatus};
pub use origin::Home;

use crate::math::atmosphere::pressure_altitude;
use crate::math::frames::{course_and_speed, AirData, Euler};
use crate::math::geodetic::{flight_offset_point, GeoPoint};
use crate::sensors::{BaroSample, GpsFix, ImuSample, MagSample, PitotSample, RangeSample};
use air::{air_density, true_airspeed, AirspeedFilter, WindFilter, WindNoise};
use ins::{Fusion, GpsNoise, Ins, Motion, ProcessNoise};
use nalgebra::{UnitQuaternion, Vector3};
use origin::Origin;

/// Largest accepted IMU time step, s (a longer gap is a stalled loop, not a time step).
pub const MAX_IMU_DT_S: f32 = 0.2;
/// Samples of the other sensors after which a silent IMU is declared unhealthy (the IMU is
/// the clock, so its silence can only be seen through the others).
pub const IMU_STALE_SAMPLES: u32 = 50;
/// Consecutive gated GPS fixes after which position and velocity are moved to GPS.
pub const GPS_RESET_FIXES: u32 = 5;
/// Consecutive gated samples of a 50 Hz sensor (about 1 s) after which the filter part it
/// corrects is taken to be lost and restarted from the measurements: a filter whose
/// innovations are all beyond the gate would otherwise never listen again.
pub const LOCKOUT_SAMPLES: u32 = 50;
/// Density used until the barometer has been read, kg/m^3 (sea-level standard).
const DEFAULT_DENSITY: f32 = 1.225;
/// Averaging weight of the magnetometer innovation monitor (about 1 s at 50 Hz).
const NIS_WEIGHT: f32 = 0.02;
/// Averaging weight of the GPS velocity innovation monitor (about 2 s at 5 Hz).
const GPS_NIS_WEIGHT: f32 = 0.1;
/// GPS fixes fused into velocity before the estimate may be called converged (5 s at 5 Hz):
/// long enough for a tilt error to show in the velocity innovations, which it does at
/// `g * tilt` per second.
pub const CONV_MIN_FIXES: u32 = 25;

/// Everything the estimator knows, as the rest of the autopilot reads it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EstimatedState {
    /// Estimator clock (sum of accepted IMU time steps, each to the microsecond), µs.
    pub time_us: u64,
    /// Body-to-NED attitude.
    pub attitude: UnitQuaternion<f32>,
    /// The same attitude as 3-2-1 Euler angles, rad.
    pub euler: Euler<f32>,
    /// Body rates with the estimated gyro bias removed, rad/s.
    pub body_rates: Vector3<f32>,
    /// Estimated gyro bias, rad/s.
    pub gyro_bias: Vector3<f32>,
    /// Position from home in NED, m; down is the barometer's fall since home was set.
    pub pos_ned: Vector3<f32>,
    /// Horizontal position.
    pub position: GeoPoint,
    /// Altitude above mean sea level, m: home's altitude plus the height above it (barometric
    /// alone until the first GPS fix).
    pub alt_amsl_m: f32,
    /// The NED origin (`alt_amsl_m + pos_ned.z` is its altitude): provisional from the first
    /// good fix, its altitude following what the estimator learns of the barometer's offset;
    /// held unchanged once set by arming or `DO_SET_HOME`.
    pub home: Option<Home>,
    /// Velocity over ground in NED, m/s.
    pub vel_ned: Vector3<f32>,
    /// True airspeed, m/s: the pitot's (low-passed) while it is healthy, otherwise synthetic
    /// (see `airspeed_synthetic`).
    pub airspeed: f32,
    /// The pitot has failed and `airspeed` is the ground velocity minus the last wind
    /// estimate (frozen since the failure): good while the wind does not change.
    pub airspeed_synthetic: bool,
    /// Angle of attack from the wind triangle, rad (0 without wind estimate).
    pub alpha: f32,
    /// Sideslip from the wind triangle, rad (near 0 by the wind filter's assumption).
    pub sideslip: f32,
    /// Course over ground, rad in (-pi, pi].
    pub course: f32,
    /// Horizontal speed over ground, m/s.
    pub ground_speed: f32,
    /// Wind in NED (velocity of the air mass), m/s; down is 0.
    pub wind_ned: Vector3<f32>,
    /// Per-sensor health and rejection counters.
    pub health: SensorHealth,
    /// The attitude filter has been initialised.
    pub attitude_valid: bool,
    /// Position and velocity come from a filter that has seen GPS.
    pub position_valid: bool,
    /// The wind filter has been initialised.
    pub wind_valid: bool,
    /// GPS is lost and position/velocity are carried by inertial + air-data dead reckoning.
    pub dead_reckoning: bool,
    /// Fit to arm: see [`Estimator::is_converged`].
    pub converged: bool,
    /// Height above the ground from the rangefinder, m, while its readings pass the gates of
    /// [`hagl`]; `None` without a rangefinder or with a failed one.
    pub range_hagl_m: Option<f32>,
}

/// The estimator facade.
#[derive(Clone, Debug)]
pub struct Estimator {
    cfg: EstimatorConfig,
    ins: Ins,
    wind: WindFilter,
    airspeed: AirspeedFilter,
    health: SensorHealth,
    /// The clock, µs: integer, so that the health checks and the delayed fusion compare and
    /// subtract times without software f64 on the MCU, and it never loses resolution.
    t_us: u64,
    rates: Vector3<f32>,
    last_accel: Option<Vector3<f32>>,
    last_mag: Option<Vector3<f32>>,
    baro_alt: Option<f32>,
    density: f32,
    /// Home and the NED origin.
    origin: Origin,
    mag_nis: f32,
    vel_nis: f32,
    aided_fixes: u32,
    last_pitot_us: Option<u64>,
    imu_silent_samples: u32,
    alpha_memory: f32,
    pending_dt: f32,
    hagl: hagl::Hagl,
}

impl Default for Estimator {
    fn default() -> Self {
        Self::new(EstimatorConfig::default())
    }
}

impl Estimator {
    /// A fresh estimator with the given settings.
    /// Not inlined: see `Vehicle::fresh`.
    #[inline(never)]
    pub fn new(cfg: EstimatorConfig) -> Self {
        Self {
            cfg,
            ins: Ins::new(),
            wind: WindFilter::default(),
            airspeed: AirspeedFilter::default(),
            health: SensorHealth::default(),
            t_us: 0,
            rates: Vector3::zeros(),
            last_accel: None,
            last_mag: None,
            baro_alt: None,
            density: DEFAULT_DENSITY,
            origin: Origin::new(),
            mag_nis: 0.0,
            vel_nis: 0.0,
            aided_fixes: 0,
            last_pitot_us: None,
            imu_silent_samples: 0,
            alpha_memory: 0.0,
            pending_dt: 0.0,
            hagl: hagl::Hagl::default(),
        }
    }

    /// The settings in use.
    pub fn config(&self) -> &EstimatorConfig {
        &self.cfg
    }

    /// Replaces the settings (the filters keep their state).
    pub fn set_config(&mut self, cfg: EstimatorConfig) {
        self.cfg = cfg;
    }

    fn earth_field(&self) -> Vector3<f32> {
        let m = self.cfg.mag_earth;
        Vector3::new(m[0], m[1], m[2])
    }

    fn gps_noise(&self) -> GpsNoise {
        GpsNoise {
            horizontal: self.cfg.gps_pos_noise,
            vertical: self.cfg.gps_alt_noise,
            velocity: self.cfg.gps_vel_noise,
            latency_sd: self.cfg.gps_delay_sd,
        }
    }

    fn wind_noise(&self) -> WindNoise {
        WindNoise {
            process: self.cfg.wind_process_noise,
            airspeed: self.cfg.wind_airspeed_noise,
            lateral: self.cfg.wind_lateral_noise,
        }
    }

    fn refresh_health(&mut self) {
        let t = self.t_us;
        let c = self.cfg;
        let h = &mut self.health;
        // The IMU is the clock: it is judged by rejections and by the other sensors' samples
        // that arrived while it was silent.
        h.imu.evaluate(t, f32::INFINITY, c.max_rejections);
        h.imu.healthy &= self.imu_silent_samples < IMU_STALE_SAMPLES;
        h.mag.evaluate(t, c.sensor_timeout, c.max_rejections);
        h.baro.evaluate(t, c.sensor_timeout, c.max_rejections);
        h.pitot.evaluate(t, c.sensor_timeout, c.max_rejections);
        h.gps.evaluate(t, c.gps_timeout, c.max_rejections);
    }

    fn note_other_sensor(&mut self) {
        self.imu_silent_samples = self.imu_silent_samples.saturating_add(1);
    }

    /// Restarts the attitude from the latest accelerometer and magnetometer samples, with the
    /// centripetal term of body-frame quantities only (the old attitude is not trusted).
    fn restart_attitude(&mut self) {
        if let (Some(a), Some(m)) = (self.last_accel, self.last_mag) {
            let va = if self.health.pitot.healthy {
                self.airspeed.value()
            } else {
                0.0
            };
            let gravity = a - self.rates.cross(&Vector3::new(va, 0.0, 0.0));
            let earth = self.earth_field();
            self.ins
                .align(&gravity, &m, &earth, self.cfg.gyro_bias_init);
            self.wind = WindFilter::default();
            self.mag_nis = 0.0;
            self.aided_fixes = 0;
        }
    }

    fn try_initialize_attitude(&mut self) {
        if self.ins.attitude_initialized() {
            return;
        }
        if let (Some(a), Some(m)) = (self.last_accel, self.last_mag) {
            let earth = self.earth_field();
            self.ins.align(&a, &m, &earth, self.cfg.gyro_bias_init);
        }
    }

    /// GPS is levelling the filter: velocity is observed, so the accelerometer is not needed
    /// (and must not be used) as a gravity reference.
    fn gps_aided(&self) -> bool {
        self.ins.nav_initialized() && self.health.gps.healthy
    }

    /// Air-relative velocity in body axes, for the centripetal term of the gravity reference.
    fn air_velocity_body(&self) -> Vector3<f32> {
        let q = self.ins.attitude();
        if self.ins.nav_initialized() && self.wind.is_initialized() {
            // The wind triangle carries the angle of attack, which (omega x v) needs: at
            // 3 deg and 20 deg/s it is worth 0.15 m/s^2, about 1 deg of pitch.
            q.inverse_transform_vector(&(self.ins.velocity() - self.wind.wind()))
        } else if self.health.pitot.healthy {
            let va = self.airspeed.value();
            let (s, c) = crate::math::elementary::sin_cos(self.alpha_memory);
            Vector3::new(va * c, 0.0, va * s)
        } else {
            Vector3::zeros()
        }
    }

    fn process_noise(&self) -> ProcessNoise {
        let c = &self.cfg;
        ProcessNoise {
            gyro: c.gyro_noise,
            gyro_bias: c.gyro_bias_rw,
            accel: c.nav_accel_noise,
            baro_offset: c.baro_bias_rw,
        }
    }

    /// One IMU sample over the time step `dt` (s) that ended with it. This advances the clock,
    /// propagates every filter and, while GPS does not level the filter, fuses the gravity
    /// reference.
    pub fn update_imu(&mut self, sample: &ImuSample, dt: f32) {
        if !(dt.is_finite() && dt > 0.0 && dt <= MAX_IMU_DT_S) {
            self.health.imu.reject();
            self.refresh_health();
            return;
        }
        if !sample.plausible() {
            // The time still passed: the next good sample is held over it, so the state
            // stays that of the last good sample and no interval is lost.
            self.pending_dt = (self.pending_dt + dt).min(MAX_IMU_DT_S);
            self.health.imu.reject();
            self.refresh_health();
            return;
        }
        let dt = (dt + self.pending_dt).min(MAX_IMU_DT_S);
        self.pending_dt = 0.0;
        self.t_us = self.t_us.saturating_add(micros(dt).max(1));
        self.health.imu.accept(self.t_us);
        self.imu_silent_samples = 0;
        self.last_accel = Some(sample.accel);
        self.refresh_health();
        self.try_initialize_attitude();
        if !self.ins.attitude_initialized() {
            return;
        }
        let c = self.cfg;
        let noise = self.process_noise();
        self.ins
            .predict(self.t_us, &sample.accel, &sample.gyro, dt, &noise);
        self.rates = sample.gyro - self.ins.gyro_bias();
        let wn = self.wind_noise();
        self.wind.predict(dt, &wn);
        if self.gps_aided() {
            return;
        }
        let v_air = self.air_velocity_body();
        // Speeding up or slowing down tilts the apparent gravity nose-up or down: the
        // airspeed's rate of change, along the air velocity, is the acceleration's other part.
        let along = if self.health.pitot.healthy && v_air.norm() > c.airspeed_min {
            v_air.normalize() * self.airspeed.rate()
        } else {
            Vector3::zeros()
        };
        let motion = Motion {
            rates: self.rates,
            v_air_body: v_air,
            along_body: along,
        };
        if let Some(f) = self.ins.fuse_gravity(
            self.t_us,
            &sample.accel,
            &motion,
            c.accel_noise,
            c.accel_gate,
            c.gate_sigma,
        ) {
            if self.health.imu.gate(f.gated, f.fused == 0, LOCKOUT_SAMPLES) {
                self.restart_attitude();
            }
        }
    }

    /// One magnetometer sample.
    pub fn update_mag(&mut self, sample: &MagSample) {
        self.note_other_sensor();
        if !sample.plausible() {
            self.health.mag.reject();
            self.refresh_health();
            return;
        }
        self.health.mag.accept(self.t_us);
        self.last_mag = Some(sample.field);
        self.refresh_health();
        if !self.ins.attitude_initialized() {
            self.try_initialize_attitude();
            return;
        }
        let earth = self.earth_field();
        let c = self.cfg;
        let f =
            self.ins
                .fuse_mag_heading(self.t_us, &sample.field, &earth, c.mag_noise, c.gate_sigma);
        if f.fused == 0 && f.gated == 0 {
            return;
        }
        if self.health.mag.gate(f.gated, f.fused == 0, LOCKOUT_SAMPLES) {
            self.restart_attitude();
        }
        self.mag_nis += NIS_WEIGHT * (monitored_nis(&f, c.gate_sigma) - self.mag_nis);
    }

    /// One barometer sample.
    pub fn update_baro(&mut self, sample: &BaroSample) {
        self.note_other_sensor();
        let p = sample.pressure_pa;
        let tc = sample.temperature_c;
        let ok = sample.plausible();
        let (Some(alt), Some(rho), true) = (pressure_altitude(p), air_density(p, tc), ok) else {
            self.health.baro.reject();
            self.refresh_health();
            return;
        };
        self.health.baro.accept(self.t_us);
        self.refresh_health();
        self.baro_alt = Some(alt);
        self.density = rho;
        if let Some(home) = self.origin.datum() {
            let c = self.cfg;
            let f =
                self.ins
                    .fuse_baro(self.t_us, home.alt_amsl_m - alt, c.baro_noise, c.gate_sigma);
            if self
                .health
                .baro
                .gate(f.gated, f.fused == 0, LOCKOUT_SAMPLES)
            {
                // A barometer that jumped is not believed: heights above home carry on from
                // where they were.
                let before = self.ins.baro_offset();
                self.ins.reset_baro_offset(home.alt_amsl_m - alt);
                self.origin.shift_baro(self.ins.baro_offset() - before);
            }
        }
    }

    /// One differential-pressure sample.
    pub fn update_pitot(&mut self, sample: &PitotSample) {
        self.note_other_sensor();
        let dp = sample.diff_pressure_pa;
        if !sample.plausible() {
            self.health.pitot.reject();
            self.refresh_health();
            return;
        }
        self.health.pitot.accept(self.t_us);
        self.refresh_health();
        let dt = match self.last_pitot_us {
            Some(last) => seconds(self.t_us.saturating_sub(last)).clamp(0.0, 1.0),
            None => 0.0,
        };
        self.last_pitot_us = Some(self.t_us);
        let c = self.cfg;
        let va = self.airspeed.update(
            true_airspeed(dp, self.density),
            dt,
            c.airspeed_tau,
            c.airspeed_rate_tau,
        );
        if !self.ins.attitude_initialized() || !self.ins.nav_initialized() || va < c.airspeed_min {
            return;
        }
        let q = self.ins.attitude();
        if self.health.gps.healthy {
            let x = q.transform_vector(&Vector3::x());
            let y = q.transform_vector(&Vector3::y());
            let wn = self.wind_noise();
            let v = self.ins.velocity();
            let gated = self.wind.update(va, &v, &x, &y, &wn, c.gate_sigma);
            if self.health.pitot.gate(gated, gated == 2, LOCKOUT_SAMPLES) {
                // Starts again from the wind triangle at the next sample.
                self.wind = WindFilter::default();
            }
            if self.wind.is_initialized() {
                let body = q.inverse_transform_vector(&(v - self.wind.wind()));
                let ad = AirData::from_body_velocity(&body);
                if ad.alpha.is_finite() {
                    self.alpha_memory = ad.alpha.clamp(-0.3, 0.3);
                }
            }
        } else if self.wind.is_initialized() {
            // GPS lost: the air-data velocity (last angle of attack, frozen wind) keeps the
            // horizontal velocity, and so the position drift, bounded.
            let (sa, ca) = crate::math::elementary::sin_cos(self.alpha_memory);
            let body = Vector3::new(va * ca, 0.0, va * sa);
            let v = q.transform_vector(&body) + self.wind.wind();
            self.ins
                .fuse_horizontal_velocity(self.t_us, v.x, v.y, c.dead_reckon_vel_noise);
        }
    }

    /// One GPS fix. Fixes without a 3D solution are ignored (GPS then times out); fixes with
    /// non-finite or impossible numbers are rejected and counted.
    pub fn update_gps(&mut self, fix: &GpsFix) {
        self.note_other_sensor();
        let ok = fix.plausible();
        if !ok {
            self.health.gps.reject();
            self.refresh_health();
            return;
        }
        if fix.fix_type < 3 {
            self.refresh_health();
            return;
        }
        let was_healthy = self.health.gps.healthy;
        self.health.gps.accept(self.t_us);
        self.refresh_health();
        if !self.ins.attitude_initialized() {
            return;
        }
        let c = self.cfg;
        let noise = self.gps_noise();
        let Some(home) = self.origin.datum() else {
            // Home is the datum of every altitude and position after it: only a good fix.
            let hdop_ok = fix.hdop.is_finite() && fix.hdop <= c.home_max_hdop;
            if u32::from(fix.satellites) < c.home_min_sats || !hdop_ok {
                return;
            }
            let home = Home {
                point: fix.position,
                alt_amsl_m: fix.alt_amsl_m,
            };
            self.origin.set_first(home);
            let baro_offset = self.baro_alt.map_or(0.0, |b| b - fix.alt_amsl_m);
            self.ins.start_nav(
                self.t_us,
                &Vector3::zeros(),
                &fix.vel_ned,
                c.gps_delay,
                baro_offset,
                &noise,
            );
            self.origin.anchor_baro(self.ins.baro_offset());
            self.ins.reopen_attitude(c.gyro_bias_init);
            self.restart_gps_monitor();
            return;
        };

        let (n, e) = self.origin.ned_of(home.point, fix.position);
        let pos = Vector3::new(n, e, home.alt_amsl_m - fix.alt_amsl_m);
        let t_fix = self.t_us.saturating_sub(micros(c.gps_delay));
        let (fp, fv) = self
            .ins
            .fuse_gps(t_fix, &pos, &fix.vel_ned, &noise, c.gate_sigma);
        if fv.fused > 0 || fv.gated > 0 {
            self.vel_nis += GPS_NIS_WEIGHT * (monitored_nis(&fv, c.gate_sigma) - self.vel_nis);
        }
        if fv.fused > 0 {
            self.aided_fixes = self.aided_fixes.saturating_add(1);
        }
        let gated = fp.gated + fv.gated;
        let limit = if was_healthy { GPS_RESET_FIXES } else { 1 };
        // Back from an outage, dead reckoning may have drifted beyond the gate: the first
        // refused fix moves the state at once.
        if self.health.gps.gate(gated, gated > 0, limit) {
            self.ins
                .reset_to_gps(&pos, &fix.vel_ned, c.gps_delay, &noise, c.gyro_bias_init);
            self.restart_gps_monitor();
        }
    }

    fn restart_gps_monitor(&mut self) {
        self.vel_nis = 0.0;
        self.aided_fixes = 0;
    }

    /// True when the estimate is fit to arm on: attitude aligned with roll/pitch and heading
    /// uncertainty below `EST_CONV_TILT` / `EST_CONV_HDG`, gyro bias uncertainty below
    /// `EST_CONV_GBIAS` on every axis, home set with horizontal position and velocity
    /// uncertainty below `EST_CONV_POS` / `EST_CONV_VEL`, every sensor healthy, and the
    /// estimate agreeing with the sensors: at least [`CONV_MIN_FIXES`] GPS velocities fused
    /// since the last start, and both the averaged normalised GPS velocity innovation and the
    /// magnetic heading innovation below `EST_CONV_NIS`. A wrong attitude cannot pass the last
    /// test for long: a tilt error makes the velocity drift by `g * tilt` per second, which
    /// the GPS velocity (a few cm/s) sees.
    pub fn is_converged(&self) -> bool {
        let c = &self.cfg;
        let h = &self.health;
        self.ins.attitude_initialized()
            && self.mag_nis < c.conv_nis
            && self.ins.nav_initialized()
            && self.aided_fixes >= CONV_MIN_FIXES
            && self.vel_nis < c.conv_nis
            && self.ins.sigmas_within(
                c.conv_tilt,
                c.conv_heading,
                c.conv_gyro_bias,
                c.conv_pos,
                c.conv_vel,
            )
            && h.imu.healthy
            && h.mag.healthy
            && h.baro.healthy
            && h.pitot.healthy
            && h.gps.healthy
    }

    /// Sets home (arming on the ground, `DO_SET_HOME`): positions are from then on NED from
    /// `home`, altitudes unchanged, and home is held where it was put (see
    /// [`EstimatedState::home`]). Refused (false) for an invalid point or altitude, or before
    /// the first fix has set a provisional home.
    pub fn set_home(&mut self, home: Home) -> bool {
        self.origin.set_home(&mut self.ins, home)
    }

    /// What the estimator has learnt of the barometer's offset since the first fix set home,
    /// m: how far heights above home and the GPS-aided altitude have come apart.
    pub fn baro_drift_m(&self) -> f32 {
        self.origin.baro_drift_m(&self.ins)
    }

    /// Averaged normalised GPS velocity innovation (about 1 when the estimate agrees with GPS).
    pub fn gps_innovation_ratio(&self) -> f32 {
        self.vel_nis
    }
    /// Averaged normalised magnetometer innovation (about 1 when the field fits the model).
    pub fn mag_innovation_ratio(&self) -> f32 {
        self.mag_nis
    }

    /// 1-sigma uncertainty of the gyro bias, rad/s.
    pub fn gyro_bias_sigma(&self) -> Vector3<f32> {
        self.ins.bias_sigma()
    }

    /// The navigation filter's states and its error state's variances
    /// ([`Ins::states_and_variances`]), and the 1-sigma horizontal and vertical position
    /// uncertainty, m: what the flight log records of the filter.
    pub fn filter_states(&self) -> ([f32; ins::N + 1], [f32; ins::N], f32, f32) {
        let (x, var) = self.ins.states_and_variances();
        let (h, v, _) = self.ins.nav_sigmas();
        (x, var, h, v)
    }

    /// Replaces the rangefinder's settings.
    pub fn set_range_config(&mut self, cfg: hagl::RangeParams) {
        self.hagl.set_config(cfg);
    }

    /// The height-above-ground stage (its failure flag and rejection count).
    pub fn hagl(&self) -> &hagl::Hagl {
        &self.hagl
    }

    /// A rangefinder reading, taken now, judged against the attitude and the height above home.
    pub fn update_range(&mut self, sample: &RangeSample) {
        // cos(roll) cos(pitch): the body z axis's share of the vertical.
        let q = self.ins.attitude();
        let cos_tilt = 1.0 - 2.0 * (q.i * q.i + q.j * q.j);
        // The height above home as `state` gives it (the runway is at home's altitude).
        let drift = self.baro_drift_m();
        let z = self.ins.position().z;
        let z = if self.origin.datum().is_some() && drift.is_finite() {
            z - drift
        } else {
            z
        };
        let height = if self.ins.nav_initialized() {
            -z
        } else {
            f32::NAN
        };
        self.hagl.update(self.t_us, sample, cos_tilt, height);
    }

    /// Home as [`EstimatedState::home`] gives it, without forming the whole estimate.
    pub fn home(&self) -> Option<Home> {
        self.origin.home(self.baro_drift_m())
    }

    /// The specific force of the last IMU sample taken in, body axes, m/s^2 (as measured: the
    /// accelerometer's bias left in); `None` before the first.
    pub fn specific_force(&self) -> Option<Vector3<f32>> {
        self.last_accel
    }

    /// The current estimate.
    pub fn state(&self) -> EstimatedState {
        let q = self.ins.attitude();
        let vel = self.ins.velocity();
        let pos = self.ins.position();
        let (course, ground_speed) = course_and_speed(&vel);
        let wind = self.wind.wind();
        let (alpha, sideslip) = if self.wind.is_initialized() && self.ins.nav_initialized() {
            let ad = AirData::from_body_velocity(&q.inverse_transform_vector(&(vel - wind)));
            (ad.alpha, ad.beta)
        } else {
            (0.0, 0.0)
        };
        let synthetic =
            !self.health.pitot.healthy && self.wind.is_initialized() && self.ins.nav_initialized();
        let (airspeed, airspeed_synthetic) = if synthetic {
            ((vel - wind).norm(), true)
        } else {
            (self.airspeed.value(), false)
        };
        // Height above home is the barometer's rise since home was set (as on PX4 and
        // ArduPilot), not the GPS-aided altitude's: while GPS averages its altitude noise
        // down, the altitude above sea level moves by a metre or more, and a home fixed on
        // that scale would move the runway under a landing. The first fix's home is
        // provisional: its altitude follows what the estimator learns of the barometer's
        // offset. Once set (arming), home is held, and altitudes above sea level are given in
        // its datum, home's altitude plus the height above it, so that what a ground station
        // shows of home and of the aircraft never drifts apart in flight.
        let drift = self.baro_drift_m();
        let pos = if self.origin.datum().is_some() && drift.is_finite() {
            Vector3::new(pos.x, pos.y, pos.z - drift)
        } else {
            pos
        };
        let home = self.home();
        let (position, alt_amsl_m) = match home {
            Some(h) => match self.origin.frame_about(h.point) {
                Some(f) => (f.offset_point(pos.x, pos.y), h.alt_amsl_m - pos.z),
                None => (
                    flight_offset_point(h.point, pos.x, pos.y),
                    h.alt_amsl_m - pos.z,
                ),
            },
            None => (GeoPoint::default(), self.baro_alt.unwrap_or(0.0)),
        };
        EstimatedState {
            time_us: self.t_us,
            attitude: q,
            euler: Euler::from_quaternion(&q),
            body_rates: self.rates,
            gyro_bias: self.ins.gyro_bias(),
            pos_ned: pos,
            position,
            alt_amsl_m,
            home,
            vel_ned: vel,
            airspeed,
            airspeed_synthetic,
            alpha,
            sideslip,
            course,
            ground_speed,
            wind_ned: wind,
            health: self.health,
            attitude_valid: self.ins.attitude_initialized(),
            position_valid: self.ins.nav_initialized(),
            wind_valid: self.wind.is_initialized(),
            dead_reckoning: self.ins.nav_initialized() && !self.health.gps.healthy,
            converged: self.is_converged(),
            range_hagl_m: self.hagl.value(self.t_us, -pos.z),
        }
    }
}

/// A duration in seconds as whole microseconds, to the nearest (negative and NaN give 0).
fn micros(s: f32) -> u64 {
    // `as` saturates: an absurd duration cannot wrap the clock.
    (s * 1e6 + 0.5) as u64
}

/// A duration in microseconds as seconds (saturating as [`health::micros_f32`]).
fn seconds(us: u64) -> f32 {
    health::micros_f32(us) * 1e-6
}

/// The normalised innovation a monitor averages: a gated component enters at the gate, so a
/// sensor that no longer matches the estimate shows up instead of vanishing.
fn monitored_nis(f: &Fusion, gate_sigma: f32) -> f32 {
    if f.fused > 0 && f.gated == 0 {
        f.nis()
    } else {
        gate_sigma * gate_sigma
    }
}
