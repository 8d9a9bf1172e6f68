//! The sensor suite, sampled at the lock-step frame rate.

use super::config::SensorConfig;
use common::link::simlink::SensorFrame;
use common::math::atmosphere::standard_atmosphere;
use common::math::geodetic::{offset_point, GeoPoint};
use common::math::ned_to_body;
use common::sensors::{
    BaroSample, BatterySample, GpsFix, ImuSample, MagSample, PitotSample, RangeSample,
};
use nalgebra::{UnitQuaternion, Vector3};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};
use std::collections::VecDeque;

/// What the sensors see of the plant at one instant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Truth {
    /// Position from home, NED, m.
    pub pos_ned: Vector3<f64>,
    /// Inertial velocity, NED, m/s.
    pub vel_ned: Vector3<f64>,
    /// Body-to-NED rotation.
    pub attitude: UnitQuaternion<f64>,
    /// Body rates, rad/s.
    pub omega_body: Vector3<f64>,
    /// Specific force (non-gravitational acceleration) in body axes, m/s^2.
    pub specific_force_body: Vector3<f64>,
    /// True airspeed, m/s.
    pub airspeed_mps: f64,
}

fn gauss(rng: &mut ChaCha8Rng) -> f64 {
    StandardNormal.sample(rng)
}

fn gauss3(rng: &mut ChaCha8Rng, sigma: [f64; 3]) -> Vector3<f64> {
    Vector3::new(
        sigma[0] * gauss(rng),
        sigma[1] * gauss(rng),
        sigma[2] * gauss(rng),
    )
}

/// Standard deviation of Simulink band-limited white noise of power `p` sampled every `ts`.
fn sigma(p: f64, ts: f64) -> f64 {
    (p / ts).sqrt()
}

fn decimation(frame_hz: f64, rate_hz: f64) -> u64 {
    ((frame_hz / rate_hz).round() as u64).max(1)
}

/// How the rangefinder fails: the failures that flared landings early or not at all (PX4
/// issues 6456 and 9843, ArduPilot 26932).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RangeFault {
    /// The reading freezes at the last one before the fault.
    Stuck,
    /// A false echo [`SHORT_ECHO_M`] away (grass, rain, an insect), with the sensor's noise.
    Short,
    /// The echo comes and goes, each second: 0.3 s of nothing, 0.15 s of readings at the
    /// minimum (a lost echo some drivers report as 0), 0.1 s out of range (max + 1 cm), then
    /// 0.45 s of good readings.
    Dropping,
}

/// Distance of the [`RangeFault::Short`] echo, m.
pub const SHORT_ECHO_M: f64 = 1.0;

/// Faults a test or a user can inject.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SensorFaults {
    /// No GPS fixes.
    pub gps_lost: bool,
    /// No differential pressure.
    pub pitot_failed: bool,
    /// No magnetometer.
    pub mag_failed: bool,
    /// No barometer.
    pub baro_failed: bool,
    /// No battery power monitor (no BATTERY_STATUS).
    pub battery_failed: bool,
    /// The rangefinder's failure, if it has one.
    pub range: Option<RangeFault>,
}

/// Every sensor of the airplane.
pub struct SensorSuite {
    cfg: SensorConfig,
    home: GeoPoint,
    home_alt_amsl_m: f64,
    frame: u64,
    period_us: u64,
    gyro_bias: Vector3<f64>,
    rng_imu: ChaCha8Rng,
    rng_mag: ChaCha8Rng,
    rng_baro: ChaCha8Rng,
    rng_pitot: ChaCha8Rng,
    rng_gps: ChaCha8Rng,
    rng_battery: ChaCha8Rng,
    rng_range: ChaCha8Rng,
    /// The last reading sent, and the one a stuck rangefinder holds, m.
    range_last: Option<f64>,
    range_stuck: Option<f64>,
    gps_queue: VecDeque<(u64, GpsFix)>,
    /// Injected faults.
    pub faults: SensorFaults,
}

impl SensorSuite {
    /// A suite at `home` (ground level `home_alt_amsl_m` above mean sea level), seeded.
    pub fn new(cfg: SensorConfig, home: GeoPoint, home_alt_amsl_m: f64, seed: u64) -> Self {
        let stream =
            |k: u64| ChaCha8Rng::seed_from_u64(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ k);
        let period_us = (1e6 / cfg.imu_rate_hz).round() as u64;
        Self {
            gyro_bias: Vector3::from(cfg.gyro_bias_radps),
            cfg,
            home,
            home_alt_amsl_m,
            frame: 0,
            period_us,
            rng_imu: stream(1),
            rng_mag: stream(2),
            rng_baro: stream(3),
            rng_pitot: stream(4),
            rng_gps: stream(5),
            rng_battery: stream(6),
            rng_range: stream(7),
            range_last: None,
            range_stuck: None,
            gps_queue: VecDeque::new(),
            faults: SensorFaults::default(),
        }
    }

    /// Time between frames, us.
    pub fn period_us(&self) -> u64 {
        self.period_us
    }

    /// The current gyro bias, rad/s (truth for judging the estimator).
    pub fn gyro_bias(&self) -> Vector3<f64> {
        self.gyro_bias
    }

    /// The next frame's time, us.
    pub fn next_time_us(&self) -> u64 {
        self.frame * self.period_us
    }

    /// The power monitor's reading of the pack at `voltage_v` and `current_a`, if one is due
    /// at frame time `time_us` (its own noise stream: the other sensors read the same with or
    /// without it).
    pub fn sample_battery(
        &mut self,
        time_us: u64,
        voltage_v: f64,
        current_a: f64,
    ) -> Option<BatterySample> {
        let b = &self.cfg.battery;
        let n = decimation(self.cfg.imu_rate_hz, b.rate_hz);
        if !(time_us / self.period_us.max(1)).is_multiple_of(n) || self.faults.battery_failed {
            return None;
        }
        Some(BatterySample {
            voltage_v: (voltage_v + b.voltage_sigma_v * gauss(&mut self.rng_battery)) as f32,
            current_a: (current_a + b.current_sigma_a * gauss(&mut self.rng_battery)) as f32,
        })
    }

    /// The rangefinder's reading, if the aircraft carries one and a reading is due at frame time
    /// `time_us`: the boresight's slant range to the flat runway at home's altitude, the
    /// height over cos(roll) cos(pitch), with noise (its own stream) and the injected fault;
    /// max + 1 cm beyond the range (as PX4 reports), the minimum below it.
    pub fn sample_range(&mut self, time_us: u64, t: &Truth) -> Option<RangeSample> {
        let r = self.cfg.rangefinder.as_ref()?;
        let n = decimation(self.cfg.imu_rate_hz, r.rate_hz);
        if !(time_us / self.period_us.max(1)).is_multiple_of(n) {
            return None;
        }
        let cos_tilt = t.attitude.to_rotation_matrix()[(2, 2)];
        let height = -t.pos_ned.z;
        let slant = if cos_tilt > 0.0 && height > 0.0 {
            height / cos_tilt
        } else {
            // Inverted or under the runway: no echo comes back.
            f64::INFINITY
        };
        let noise = r.sigma_m * gauss(&mut self.rng_range);
        let mut d = slant + noise;
        let fault = self.faults.range;
        if fault != Some(RangeFault::Stuck) {
            self.range_stuck = None;
        }
        match fault {
            Some(RangeFault::Stuck) => {
                d = *self
                    .range_stuck
                    .get_or_insert(self.range_last.unwrap_or(r.max_m + 0.01));
            }
            Some(RangeFault::Short) => d = SHORT_ECHO_M + noise,
            Some(RangeFault::Dropping) => match time_us % 1_000_000 {
                0..300_000 => return None,
                300_000..450_000 => d = r.min_m,
                450_000..550_000 => d = f64::INFINITY,
                _ => {}
            },
            None => {}
        }
        let d = if d >= r.max_m {
            r.max_m + 0.01
        } else {
            d.max(r.min_m)
        };
        self.range_last = Some(d);
        let in_range = d > r.min_m && d < r.max_m;
        Some(RangeSample {
            distance_m: d as f32,
            min_m: r.min_m as f32,
            max_m: r.max_m as f32,
            quality: if in_range { 100 } else { 0 },
        })
    }

    /// The rangefinder's noise (1 sigma) and beam width, m and rad, for its messages.
    pub fn range_noise_and_fov(&self) -> Option<(f32, f32)> {
        self.cfg
            .rangefinder
            .as_ref()
            .map(|r| (r.sigma_m as f32, r.fov_rad as f32))
    }

    /// Samples every sensor due at the next frame time; returns the frame and a GPS fix if one
    /// is delivered now.
    pub fn sample(&mut self, t: &Truth) -> (SensorFrame, Option<GpsFix>) {
        let time_us = self.next_time_us();
        let frame = self.frame;
        self.frame += 1;
        let cfg = &self.cfg;
        let fr = cfg.imu_rate_hz;
        let ts = 1.0 / fr;

        // IMU every frame, with a bias that wanders.
        let walk = cfg.gyro_bias_walk * ts.sqrt();
        self.gyro_bias += gauss3(&mut self.rng_imu, [walk; 3]);
        let gyro_sigma = cfg.gyro_noise_power.map(|p| sigma(p, ts));
        let accel_sigma = cfg.accel_noise_power.map(|p| sigma(p, ts));
        let cal = &cfg.calibration;
        let gyro = t.omega_body.component_mul(&Vector3::from(cal.gyro_scale))
            + self.gyro_bias
            + gauss3(&mut self.rng_imu, gyro_sigma);
        let accel = t
            .specific_force_body
            .component_mul(&Vector3::from(cal.accel_scale))
            + Vector3::from(cfg.accel_bias_mps2)
            + gauss3(&mut self.rng_imu, accel_sigma);
        let mut out = SensorFrame {
            time_us,
            imu: Some(ImuSample {
                accel: accel.cast(),
                gyro: gyro.cast(),
            }),
            ..Default::default()
        };

        let alt_amsl = self.home_alt_amsl_m - t.pos_ned.z;
        let air = standard_atmosphere(alt_amsl);

        let n = decimation(fr, cfg.mag_rate_hz);
        if frame.is_multiple_of(n) && !self.faults.mag_failed {
            let ts = n as f64 / fr;
            let s = cfg.mag_noise_power_nt.map(|p| sigma(p, ts) * 1e-5);
            let field = ned_to_body(&t.attitude, &Vector3::from(cfg.mag_field_ned_gauss))
                + Vector3::from(cfg.calibration.mag_offset_gauss)
                + gauss3(&mut self.rng_mag, s);
            out.mag = Some(MagSample {
                field: field.cast(),
            });
        }
        let n = decimation(fr, cfg.baro_rate_hz);
        if frame.is_multiple_of(n) && !self.faults.baro_failed {
            let ts = n as f64 / fr;
            let noise_pa = sigma(cfg.ps_noise_power_kpa, ts) * 1e3 * gauss(&mut self.rng_baro);
            out.baro = Some(BaroSample {
                pressure_pa: (air.pressure_pa + noise_pa) as f32,
                temperature_c: (air.temperature_k - 273.15) as f32,
            });
        }
        let n = decimation(fr, cfg.pitot_rate_hz);
        if frame.is_multiple_of(n) && !self.faults.pitot_failed {
            let ts = n as f64 / fr;
            let noise_pa = sigma(cfg.pd_noise_power_kpa, ts) * 1e3 * gauss(&mut self.rng_pitot);
            let q = 0.5 * air.density * t.airspeed_mps * t.airspeed_mps;
            let cal = &cfg.calibration;
            out.pitot = Some(PitotSample {
                diff_pressure_pa: (cal.pitot_scale * q + cal.pitot_offset_pa + noise_pa) as f32,
            });
        }

        // GPS: measured now, delivered after its latency.
        let g = &cfg.gps;
        let n = decimation(fr, g.rate_hz);
        if frame.is_multiple_of(n) {
            // The receiver's start-up error fades as its solution converges.
            let startup = if g.startup_tau_s > 0.0 {
                Vector3::from(g.startup_offset_m)
                    * (-(time_us as f64 * 1e-6) / g.startup_tau_s).exp()
            } else {
                Vector3::zeros()
            };
            let p =
                t.pos_ned + startup + gauss3(&mut self.rng_gps, [g.horiz_m, g.horiz_m, g.vert_m]);
            let v = t.vel_ned + gauss3(&mut self.rng_gps, [g.vel_mps; 3]);
            let fix = GpsFix {
                position: offset_point(self.home, p.x, p.y),
                alt_amsl_m: (self.home_alt_amsl_m - p.z) as f32,
                vel_ned: v.cast(),
                fix_type: 3,
                satellites: g.satellites,
                hdop: g.hdop as f32,
            };
            let release = time_us + (g.latency_s * 1e6).round() as u64;
            if !self.faults.gps_lost {
                self.gps_queue.push_back((release, fix));
            }
        }
        let gps = match self.gps_queue.front() {
            Some((release, _)) if *release <= time_us => self.gps_queue.pop_front().map(|(_, f)| f),
            _ => None,
        };
        (out, gps)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use common::math::geodetic::ned_offset;

    fn level_truth() -> Truth {
        Truth {
            pos_ned: Vector3::new(0.0, 0.0, -100.0),
            vel_ned: Vector3::new(17.0, 0.0, 0.0),
            attitude: UnitQuaternion::identity(),
            omega_body: Vector3::zeros(),
            specific_force_body: Vector3::new(0.0, 0.0, -9.8056),
            airspeed_mps: 17.0,
        }
    }

    #[test]
    fn noise_statistics_follow_the_umn_noise_power() {
        let cfg = SensorConfig::default();
        let mut s = SensorSuite::new(cfg.clone(), GeoPoint::from_deg(44.7, -93.0), 0.0, 7);
        let t = level_truth();
        let n = 20_000;
        let mut sum = 0.0;
        let mut sum2 = 0.0;
        let mut dp = Vec::new();
        for _ in 0..n {
            let (f, _) = s.sample(&t);
            let gz = f64::from(f.imu.map(|i| i.gyro.z).unwrap_or(f32::NAN));
            sum += gz;
            sum2 += gz * gz;
            if let Some(p) = f.pitot {
                dp.push(f64::from(p.diff_pressure_pa));
            }
        }
        let mean = sum / n as f64;
        let sd = (sum2 / n as f64 - mean * mean).sqrt();
        // Power 1e-6 at 100 Hz: sigma = sqrt(1e-6 / 0.01) = 0.01 rad/s.
        assert!((sd - 0.01).abs() < 0.0005, "gyro sigma {sd}");
        // The mean is the bias (0.0015 rad/s) plus a small random walk.
        assert!((mean - 0.0015).abs() < 0.001, "gyro mean {mean}");
        // Dynamic pressure at 17 m/s and 100 m: 0.5 * 1.21328 * 17^2 = 175.32 Pa.
        let m = dp.iter().sum::<f64>() / dp.len() as f64;
        assert!((m - 175.32).abs() < 0.2, "pitot mean {m}");
        assert_eq!(dp.len(), n / 2, "pitot at 50 Hz");
    }

    #[test]
    fn gps_arrives_at_5hz_after_its_latency() {
        let mut s = SensorSuite::new(
            SensorConfig::default(),
            GeoPoint::from_deg(44.7, -93.0),
            250.0,
            1,
        );
        let t = level_truth();
        let mut times = Vec::new();
        let mut alts = Vec::new();
        for _ in 0..500 {
            let time = s.next_time_us();
            if let (_, Some(fix)) = s.sample(&t) {
                times.push(time);
                alts.push(fix.alt_amsl_m);
            }
        }
        // 5 s at 5 Hz, the first one delivered 0.12 s after it was measured at t = 0.
        assert_eq!(times[0], 120_000);
        assert_eq!(times[1] - times[0], 200_000);
        assert!(times.len() >= 24);
        let mean = alts.iter().sum::<f32>() / alts.len() as f32;
        assert!((mean - 350.0).abs() < 3.0, "GPS altitude {mean}");
    }

    #[test]
    fn calibration_errors_scale_and_offset_the_readings_and_the_gps_start_up_offset_fades() {
        // Noise and bias off, to read the calibration alone.
        let mut cfg = SensorConfig {
            gyro_noise_power: [0.0; 3],
            accel_noise_power: [0.0; 3],
            gyro_bias_radps: [0.0; 3],
            gyro_bias_walk: 0.0,
            accel_bias_mps2: [0.0; 3],
            pd_noise_power_kpa: 0.0,
            ..SensorConfig::default()
        };
        cfg.gps.horiz_m = 0.0;
        cfg.gps.vert_m = 0.0;
        cfg.gps.latency_s = 0.0;
        cfg.calibration.accel_scale = [1.0, 1.0, 1.02];
        cfg.calibration.gyro_scale = [1.1, 1.0, 1.0];
        cfg.calibration.pitot_scale = 0.9;
        cfg.calibration.pitot_offset_pa = 2.0;
        cfg.gps.startup_offset_m = [4.0, 0.0, 0.0];
        cfg.gps.startup_tau_s = 10.0;
        let mut s = SensorSuite::new(cfg, GeoPoint::from_deg(44.7, -93.0), 0.0, 3);
        let t = Truth {
            omega_body: Vector3::new(0.1, 0.0, 0.0),
            ..level_truth()
        };
        let (f, fix) = s.sample(&t);
        let imu = f.imu.unwrap();
        assert!((f64::from(imu.accel.z) + 9.8056 * 1.02).abs() < 1e-4);
        assert!((f64::from(imu.gyro.x) - 0.11).abs() < 1e-6);
        // 0.9 * 175.32 Pa + 2 Pa.
        let dp = f64::from(f.pitot.unwrap().diff_pressure_pa);
        assert!((dp - (0.9 * 175.32 + 2.0)).abs() < 0.05, "{dp}");
        let north =
            |fix: GpsFix| ned_offset::<f64>(GeoPoint::from_deg(44.7, -93.0), fix.position).0;
        assert!((north(fix.unwrap()) - 4.0).abs() < 0.02);
        // 10 s later, one time constant: 4/e.
        let mut last = None;
        for _ in 0..1000 {
            if let (_, Some(x)) = s.sample(&t) {
                last = Some(x);
            }
        }
        assert!((north(last.unwrap()) - 4.0 / std::f64::consts::E).abs() < 0.05);
    }

    #[test]
    fn the_same_seed_gives_the_same_readings_and_faults_silence_a_sensor() {
        let mk = || SensorSuite::new(SensorConfig::default(), GeoPoint::default(), 0.0, 42);
        let (mut a, mut b) = (mk(), mk());
        for _ in 0..100 {
            assert_eq!(a.sample(&level_truth()), b.sample(&level_truth()));
        }
        b.faults.gps_lost = true;
        b.faults.pitot_failed = true;
        for k in 0..200 {
            let (f, g) = b.sample(&level_truth());
            assert!(f.pitot.is_none());
            // A fix measured before the loss may still be in flight for one latency.
            assert!(g.is_none() || k < 12, "GPS fix {k} frames after the loss");
        }
    }

    #[test]
    fn the_power_monitor_reads_at_10_hz_with_its_noise_until_it_fails() {
        let mut s = SensorSuite::new(SensorConfig::default(), GeoPoint::default(), 0.0, 3);
        let mut v = Vec::new();
        for k in 0..10_000u64 {
            if let Some(b) = s.sample_battery(k * 10_000, 11.1, 8.0) {
                v.push(b);
            }
        }
        assert_eq!(v.len(), 1000, "10 Hz of 100 Hz frames");
        let n = v.len() as f64;
        let mean = v.iter().map(|b| f64::from(b.voltage_v)).sum::<f64>() / n;
        let sd = (v
            .iter()
            .map(|b| (f64::from(b.voltage_v) - mean).powi(2))
            .sum::<f64>()
            / n)
            .sqrt();
        let amps = v.iter().map(|b| f64::from(b.current_a)).sum::<f64>() / n;
        // 20 mV and 0.1 A of noise: the means within 4 standard errors.
        assert!((mean - 11.1).abs() < 4.0 * 0.02 / n.sqrt(), "{mean}");
        assert!((sd - 0.02).abs() < 0.002, "{sd}");
        assert!((amps - 8.0).abs() < 4.0 * 0.1 / n.sqrt(), "{amps}");
        s.faults.battery_failed = true;
        assert!((0..100u64).all(|k| s.sample_battery(k * 10_000, 11.1, 8.0).is_none()));
    }

    #[test]
    fn the_rangefinder_reads_height_over_cos_roll_cos_pitch_and_fails_as_told() {
        let cfg = SensorConfig {
            rangefinder: Some(super::super::RangefinderConfig::default()),
            ..SensorConfig::default()
        };
        let mut s = SensorSuite::new(cfg, GeoPoint::default(), 0.0, 5);
        // 10 m up, banked 20 deg and pitched 10 deg: 10 / (cos 20 cos 10) = 10.806 m.
        let t = Truth {
            pos_ned: Vector3::new(0.0, 0.0, -10.0),
            attitude: UnitQuaternion::from_euler_angles(
                20f64.to_radians(),
                10f64.to_radians(),
                0.3,
            ),
            ..level_truth()
        };
        let d: Vec<f64> = (0..2000u64)
            .filter_map(|k| s.sample_range(k * 10_000, &t))
            .map(|r| f64::from(r.distance_m))
            .collect();
        assert_eq!(d.len(), 400, "20 Hz of 100 Hz frames");
        let n = d.len() as f64;
        let mean = d.iter().sum::<f64>() / n;
        let expect = 10.0 / (20f64.to_radians().cos() * 10f64.to_radians().cos());
        assert!(
            (mean - expect).abs() < 4.0 * 0.025 / n.sqrt(),
            "{mean} vs {expect}"
        );
        // Beyond 40 m: PX4's out-of-range reading, max + 1 cm.
        let high = Truth {
            pos_ned: Vector3::new(0.0, 0.0, -60.0),
            ..level_truth()
        };
        assert_eq!(s.sample_range(0, &high).map(|r| r.distance_m), Some(40.01));
        s.faults.range = Some(RangeFault::Stuck);
        let stuck: Vec<f32> = (0..100u64)
            .filter_map(|k| s.sample_range(k * 10_000, &t))
            .map(|r| r.distance_m)
            .collect();
        assert!(stuck.iter().all(|x| *x == 40.01), "holds the last reading");
        s.faults.range = Some(RangeFault::Short);
        let r = s.sample_range(0, &t).unwrap();
        assert!((f64::from(r.distance_m) - SHORT_ECHO_M).abs() < 0.15);
        s.faults.range = Some(RangeFault::Dropping);
        let kinds: Vec<Option<f32>> = (0..20u64)
            .map(|k| s.sample_range(k * 50_000, &t).map(|r| r.distance_m))
            .collect();
        assert!(kinds[..6].iter().all(Option::is_none));
        assert!(kinds[6..9].iter().all(|x| *x == Some(0.1)));
        assert!(kinds[9..11].iter().all(|x| *x == Some(40.01)));
        assert!(kinds[11..]
            .iter()
            .all(|x| x.is_some_and(|d| (d - 10.806).abs() < 0.15)));
    }
}
