//! A kinematic truth generator and sensor simulator for the estimator's tests.
//!
//! The aircraft flies coordinated (zero sideslip) at constant true airspeed through a list of
//! segments, each with a target turn rate and flight-path angle reached through a 2 s cosine
//! blend. Attitude is built from the air-relative velocity: `R = Rz(chi) Ry(gamma) Rx(mu)
//! Ry(alpha)`, with the bank `mu` that makes the lift supply the centripetal and climb
//! acceleration, and an angle of attack that grows with the load factor. Everything is f64
//! and analytic where it can be; angular rate comes from a central difference of the attitude.
//!
//! Sensors reproduce the UMN SIL sensor model's noise at its 0.02 s sample time
//! (`variance = noise power / Ts`) and the bolderflight GPS figures, plus a constant gyro bias.

extern crate std;

use crate::math::atmosphere::standard_atmosphere;
use crate::math::geodetic::{offset_point, GeoPoint};
use crate::sensors::{BaroSample, GpsFix, ImuSample, MagSample, PitotSample};
use nalgebra::{UnitQuaternion, Vector3};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};
use std::collections::VecDeque;
use std::vec::Vec;

/// Local gravity of the UMN plant, m/s^2 (the estimator uses standard gravity: the 0.001
/// m/s^2 difference is part of what it must tolerate).
pub const G: f64 = 9.8056;
/// Trim angle of attack at 17 m/s (UMN trim), rad.
pub const ALPHA0: f64 = 0.055;
/// Cosine blend of turn rate and flight-path angle between segments, s.
pub const BLEND_S: f64 = 2.0;
/// Cosine blend of airspeed between segments, s (5 m/s in 5 s peaks at 1.6 m/s^2, about what
/// the Ultra Stick's motor gives).
pub const SPEED_BLEND_S: f64 = 5.0;
/// Airspeed of the UMN trim, m/s (angle of attack scales with (VA0 / Va)^2).
pub const VA0: f64 = 17.0;
/// UMN home (OpenFlight NL_Sim setup).
pub const HOME_LAT: f64 = 44.7258357;
/// UMN home longitude.
pub const HOME_LON: f64 = -93.07501316;
/// Earth field at home used by the simulated magnetometer, gauss NED.
pub const EARTH_FIELD: [f64; 3] = [0.18, -0.002, 0.52];

/// Noise standard deviations (UMN `noise power / 0.02 s`, bolderflight GPS).
pub mod noise {
    /// Gyro, rad/s (power 1e-6).
    pub const GYRO: f64 = 0.007_071;
    /// Accelerometer x, y, z, m/s^2 (power 0.0008, 0.004, 0.004).
    pub const ACCEL: [f64; 3] = [0.2, 0.447_2, 0.447_2];
    /// Magnetometer x, y, z, gauss (power 150, 150, 80000 nT^2 s).
    pub const MAG: [f64; 3] = [0.000_866, 0.000_866, 0.02];
    /// Static pressure, Pa (power 8e-7 kPa^2 s).
    pub const STATIC_PA: f64 = 6.32;
    /// Differential pressure, Pa (power 1.5e-7 kPa^2 s).
    pub const DIFF_PA: f64 = 2.74;
    /// GPS horizontal position per axis, m.
    pub const GPS_H: f64 = 1.5;
    /// GPS vertical position, m.
    pub const GPS_V: f64 = 5.5;
    /// GPS velocity per axis, m/s.
    pub const GPS_VEL: f64 = 0.05;
}

/// One flight segment.
#[derive(Clone, Copy, Debug)]
pub struct Segment {
    /// Length, s.
    pub duration: f64,
    /// Turn rate of the air-relative course, rad/s (positive right).
    pub turn_rate: f64,
    /// Air-relative flight-path angle, rad (positive climbing).
    pub gamma: f64,
    /// True airspeed, m/s.
    pub airspeed: f64,
}

/// The true state at one instant.
#[derive(Clone, Copy, Debug)]
pub struct Truth {
    /// Time, s.
    pub t: f64,
    /// Body-to-NED attitude.
    pub q: UnitQuaternion<f64>,
    /// Body rates, rad/s.
    pub omega: Vector3<f64>,
    /// Specific force in body axes, m/s^2.
    pub specific_force: Vector3<f64>,
    /// Position NED from the origin (ground level at 0 m AMSL), m.
    pub pos: Vector3<f64>,
    /// Ground velocity NED, m/s.
    pub vel: Vector3<f64>,
    /// True airspeed, m/s.
    pub va: f64,
    /// Wind NED, m/s.
    pub wind: Vector3<f64>,
    /// Turn rate at this instant, rad/s.
    pub turn_rate: f64,
}

impl Truth {
    /// Altitude above mean sea level, m.
    pub fn alt_amsl(&self) -> f64 {
        -self.pos.z
    }
}

/// Kinematic trajectory.
pub struct Trajectory {
    segments: Vec<Segment>,
    starts: Vec<f64>,
    va0: f64,
    wind: Vector3<f64>,
    chi: f64,
    pos: Vector3<f64>,
    t: f64,
}

fn blend(tau: f64, length: f64) -> (f64, f64) {
    if tau >= length {
        (1.0, 0.0)
    } else {
        let w = core::f64::consts::PI / length;
        (0.5 * (1.0 - (w * tau).cos()), 0.5 * w * (w * tau).sin())
    }
}

/// The commanded quantities at one instant.
#[derive(Clone, Copy, Debug)]
struct Sched {
    turn: f64,
    gamma: f64,
    gamma_dot: f64,
    va: f64,
    va_dot: f64,
}

impl Trajectory {
    /// Starts at `pos0` on air-relative course `chi0` (rad), at airspeed `va` (each segment
    /// then sets its own).
    pub fn new(
        segments: &[Segment],
        va: f64,
        wind: Vector3<f64>,
        chi0: f64,
        pos0: Vector3<f64>,
    ) -> Self {
        let mut starts = Vec::new();
        let mut t = 0.0;
        for s in segments {
            starts.push(t);
            t += s.duration;
        }
        Self {
            segments: segments.to_vec(),
            starts,
            va0: va,
            wind,
            chi: chi0,
            pos: pos0,
            t: 0.0,
        }
    }

    /// Total length, s.
    pub fn duration(&self) -> f64 {
        self.segments.iter().map(|s| s.duration).sum()
    }

    fn schedule(&self, t: f64) -> Sched {
        let mut prev = (0.0, 0.0, self.va0);
        for (i, s) in self.segments.iter().enumerate() {
            let start = self.starts[i];
            let end = start + s.duration;
            if t < end || i + 1 == self.segments.len() {
                let tau = (t - start).max(0.0);
                let (b, db) = blend(tau, BLEND_S);
                let (bv, dbv) = blend(tau, SPEED_BLEND_S);
                return Sched {
                    turn: prev.0 + (s.turn_rate - prev.0) * b,
                    gamma: prev.1 + (s.gamma - prev.1) * b,
                    gamma_dot: (s.gamma - prev.1) * db,
                    va: prev.2 + (s.airspeed - prev.2) * bv,
                    va_dot: (s.airspeed - prev.2) * dbv,
                };
            }
            prev = (s.turn_rate, s.gamma, s.airspeed);
        }
        Sched {
            turn: 0.0,
            gamma: 0.0,
            gamma_dot: 0.0,
            va: self.va0,
            va_dot: 0.0,
        }
    }

    /// (bank mu, alpha) at time t.
    fn bank_alpha(&self, t: f64) -> (f64, f64) {
        let s = self.schedule(t);
        let lateral = s.va * s.gamma.cos() * s.turn;
        let normal = G * s.gamma.cos() + s.va * s.gamma_dot;
        let load = (lateral * lateral + normal * normal).sqrt() / G;
        // Lift ~ Va^2 alpha: the trim alpha scaled by load factor and dynamic pressure.
        let q_ratio = if s.va > 1.0 {
            (VA0 / s.va).powi(2)
        } else {
            1.0
        };
        (lateral.atan2(normal), ALPHA0 * load * q_ratio)
    }

    fn attitude(&self, chi: f64, t: f64) -> UnitQuaternion<f64> {
        let gamma = self.schedule(t).gamma;
        let (mu, alpha) = self.bank_alpha(t);
        UnitQuaternion::from_axis_angle(&Vector3::z_axis(), chi)
            * UnitQuaternion::from_axis_angle(&Vector3::y_axis(), gamma)
            * UnitQuaternion::from_axis_angle(&Vector3::x_axis(), mu)
            * UnitQuaternion::from_axis_angle(&Vector3::y_axis(), alpha)
    }

    fn air_velocity(va: f64, chi: f64, gamma: f64) -> Vector3<f64> {
        va * Vector3::new(
            gamma.cos() * chi.cos(),
            gamma.cos() * chi.sin(),
            -gamma.sin(),
        )
    }

    /// The truth at the present time.
    pub fn truth(&self) -> Truth {
        let t = self.t;
        let sc = self.schedule(t);
        let chi = self.chi;
        let q = self.attitude(chi, t);
        let h = 1e-3;
        let qm = self.attitude(chi - sc.turn * h, t - h);
        let qp = self.attitude(chi + sc.turn * h, t + h);
        let omega = (qm.inverse() * qp).scaled_axis() / (2.0 * h);
        let (va, gamma, turn, gamma_dot) = (sc.va, sc.gamma, sc.turn, sc.gamma_dot);
        let (sg, cg) = gamma.sin_cos();
        let (sin_chi, cos_chi) = chi.sin_cos();
        let dir = Vector3::new(cg * cos_chi, cg * sin_chi, -sg);
        let ddir = Vector3::new(
            -sg * gamma_dot * cos_chi - cg * sin_chi * turn,
            -sg * gamma_dot * sin_chi + cg * cos_chi * turn,
            -cg * gamma_dot,
        );
        let acc = dir * sc.va_dot + ddir * va;
        let f_ned = acc - Vector3::new(0.0, 0.0, G);
        Truth {
            t,
            q,
            omega,
            specific_force: q.inverse_transform_vector(&f_ned),
            pos: self.pos,
            vel: Self::air_velocity(va, chi, gamma) + self.wind,
            va,
            wind: self.wind,
            turn_rate: turn,
        }
    }

    /// Advances by `dt` (trapezoidal in course and position).
    pub fn step(&mut self, dt: f64) {
        let s0 = self.schedule(self.t);
        let v0 = Self::air_velocity(s0.va, self.chi, s0.gamma) + self.wind;
        let s1 = self.schedule(self.t + dt);
        let chi1 = self.chi + 0.5 * dt * (s0.turn + s1.turn);
        let v1 = Self::air_velocity(s1.va, chi1, s1.gamma) + self.wind;
        self.pos += 0.5 * dt * (v0 + v1);
        self.chi = chi1;
        self.t += dt;
    }
}

/// Samples for one time step. GPS only on its 5 Hz ticks.
pub struct Samples {
    /// IMU.
    pub imu: ImuSample,
    /// Magnetometer.
    pub mag: MagSample,
    /// Barometer.
    pub baro: BaroSample,
    /// Pitot.
    pub pitot: PitotSample,
    /// GPS, when one is due.
    pub gps: Option<GpsFix>,
}

/// Noisy sensors on a trajectory.
pub struct SensorSim {
    rng: ChaCha8Rng,
    /// Constant gyro bias, rad/s.
    pub gyro_bias: Vector3<f64>,
    /// GPS latency, s.
    pub gps_latency: f64,
    /// GPS period, s.
    pub gps_period: f64,
    /// Noise on (false: exact samples).
    pub noisy: bool,
    /// Multiplies the noise of the 50 Hz-specified sensors: `sqrt(0.02 / Ts)` keeps the UMN
    /// noise power at another sample time `Ts`.
    pub rate_scale: f64,
    history: VecDeque<Truth>,
    next_gps: f64,
    /// Origin of the truth's NED frame.
    pub origin: GeoPoint,
}

impl SensorSim {
    /// Seeded simulator with the UMN noise, a gyro bias of (1.15, -0.86, 0.57) deg/s and GPS
    /// at 5 Hz with 0.15 s latency.
    pub fn new(seed: u64) -> Self {
        Self {
            rng: ChaCha8Rng::seed_from_u64(seed),
            gyro_bias: Vector3::new(0.02, -0.015, 0.01),
            gps_latency: 0.15,
            gps_period: 0.2,
            noisy: true,
            rate_scale: 1.0,
            history: VecDeque::new(),
            next_gps: 0.0,
            origin: GeoPoint::from_deg(HOME_LAT, HOME_LON),
        }
    }

    fn n(&mut self, sigma: f64) -> f64 {
        if self.noisy {
            let unit: f64 = StandardNormal.sample(&mut self.rng);
            sigma * unit
        } else {
            0.0
        }
    }

    fn v3(v: Vector3<f64>) -> Vector3<f32> {
        v.cast::<f32>()
    }

    /// Samples at the truth's time.
    pub fn sample(&mut self, tr: &Truth) -> Samples {
        self.history.push_back(*tr);
        while self
            .history
            .front()
            .is_some_and(|h| h.t < tr.t - self.gps_latency - 1.0)
        {
            self.history.pop_front();
        }
        let gyro = tr.omega
            + self.gyro_bias
            + Vector3::new(
                self.n(noise::GYRO * self.rate_scale),
                self.n(noise::GYRO * self.rate_scale),
                self.n(noise::GYRO * self.rate_scale),
            );
        let accel = tr.specific_force
            + Vector3::new(
                self.n(noise::ACCEL[0] * self.rate_scale),
                self.n(noise::ACCEL[1] * self.rate_scale),
                self.n(noise::ACCEL[2] * self.rate_scale),
            );
        let earth = Vector3::new(EARTH_FIELD[0], EARTH_FIELD[1], EARTH_FIELD[2]);
        let mag = tr.q.inverse_transform_vector(&earth)
            + Vector3::new(
                self.n(noise::MAG[0] * self.rate_scale),
                self.n(noise::MAG[1] * self.rate_scale),
                self.n(noise::MAG[2] * self.rate_scale),
            );
        let air = standard_atmosphere(tr.alt_amsl());
        let baro = BaroSample {
            pressure_pa: (air.pressure_pa + self.n(noise::STATIC_PA * self.rate_scale)) as f32,
            temperature_c: (air.temperature_k - 273.15) as f32,
        };
        let pitot = PitotSample {
            diff_pressure_pa: (0.5 * air.density * tr.va * tr.va
                + self.n(noise::DIFF_PA * self.rate_scale)) as f32,
        };
        let mut gps = None;
        if tr.t + 1e-9 >= self.next_gps {
            self.next_gps += self.gps_period;
            let t_fix = tr.t - self.gps_latency;
            if let Some(old) = self
                .history
                .iter()
                .min_by(|a, b| (a.t - t_fix).abs().total_cmp(&(b.t - t_fix).abs()))
                .copied()
            {
                if (old.t - t_fix).abs() < 0.011 {
                    let n = old.pos.x + self.n(noise::GPS_H);
                    let e = old.pos.y + self.n(noise::GPS_H);
                    let alt = old.alt_amsl() + self.n(noise::GPS_V);
                    let vel = old.vel
                        + Vector3::new(
                            self.n(noise::GPS_VEL),
                            self.n(noise::GPS_VEL),
                            self.n(noise::GPS_VEL),
                        );
                    gps = Some(GpsFix {
                        position: offset_point(self.origin, n, e),
                        alt_amsl_m: alt as f32,
                        vel_ned: Self::v3(vel),
                        fix_type: 3,
                        satellites: 10,
                        hdop: 0.8,
                    });
                }
            }
        }
        Samples {
            imu: ImuSample {
                accel: Self::v3(accel),
                gyro: Self::v3(gyro),
            },
            mag: MagSample {
                field: Self::v3(mag),
            },
            baro,
            pitot,
            gps,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn truth_is_a_coordinated_turn_at_the_expected_bank() {
        let turn = 20f64.to_radians();
        let segs = [Segment {
            duration: 30.0,
            turn_rate: turn,
            gamma: 0.0,
            airspeed: 17.0,
        }];
        let mut tr = Trajectory::new(&segs, 17.0, Vector3::zeros(), 0.0, Vector3::zeros());
        for _ in 0..500 {
            tr.step(0.02);
        }
        let s = tr.truth();
        let (phi, theta, _) = s.q.euler_angles();
        // phi = atan(V omega / g) = 31.2 deg for 17 m/s at 20 deg/s.
        let expected = (17.0 * turn / G).atan();
        assert!((phi - expected).abs() < 0.01, "phi {phi} vs {expected}");
        // Coordinated: no lateral specific force; the load factor 1/cos(phi) is on -z.
        assert!(s.specific_force.y.abs() < 1e-3, "{:?}", s.specific_force);
        assert!((s.specific_force.norm() - G / expected.cos()).abs() < 1e-3);
        // Pitch of a level turn with body-axis alpha: positive, a few degrees.
        assert!(theta > 0.02 && theta < 0.1, "theta {theta}");
        // Body rates of a level turn: (0, w sin phi, w cos phi) up to the small alpha tilt.
        assert!((s.omega.y - turn * phi.sin()).abs() < 2e-3, "{:?}", s.omega);
        assert!((s.omega.norm() - turn).abs() < 1e-4);
    }
}
