//! Flights through the truth generator: accuracy, bad input, outages.

extern crate std;

use super::truth::{Segment, SensorSim, Trajectory, Truth};
use super::*;
use crate::math::frames::wrap_pi;
use std::println;

const DT: f64 = 0.02;
const DEG: f64 = core::f64::consts::PI / 180.0;

struct Flight {
    est: Estimator,
    traj: Trajectory,
    sim: SensorSim,
}

impl Flight {
    fn new(segments: &[Segment], seed: u64, cfg: EstimatorConfig) -> Self {
        let wind = Vector3::new(3.0, -4.0, 0.0);
        Self {
            est: Estimator::new(cfg),
            traj: Trajectory::new(
                segments,
                17.0,
                wind,
                30.0 * DEG,
                Vector3::new(0.0, 0.0, -100.0),
            ),
            sim: SensorSim::new(seed),
        }
    }

    /// One 50 Hz step; `gps_on` false drops the fixes, `mag_on` false the magnetometer.
    fn step_with(&mut self, gps_on: bool, mag_on: bool) -> Truth {
        self.traj.step(DT);
        let tr = self.traj.truth();
        let s = self.sim.sample(&tr);
        self.est.update_imu(&s.imu, DT as f32);
        if mag_on {
            self.est.update_mag(&s.mag);
        }
        self.est.update_baro(&s.baro);
        self.est.update_pitot(&s.pitot);
        if let (Some(g), true) = (s.gps, gps_on) {
            self.est.update_gps(&g);
        }
        tr
    }

    fn step(&mut self) -> Truth {
        self.step_with(true, true)
    }

    fn horizontal_error(&self, tr: &Truth) -> f64 {
        let st = self.est.state();
        let (n, e): (f64, f64) = ned_offset(self.sim.origin, st.position);
        ((n - tr.pos.x).powi(2) + (e - tr.pos.y).powi(2)).sqrt()
    }
}

#[derive(Default)]
struct Rms {
    sum: f64,
    n: usize,
    max: f64,
}

impl Rms {
    fn add(&mut self, e: f64) {
        self.sum += e * e;
        self.n += 1;
        self.max = self.max.max(e.abs());
    }
    fn rms(&self) -> f64 {
        (self.sum / self.n.max(1) as f64).sqrt()
    }
}

fn level(duration: f64) -> Segment {
    Segment {
        duration,
        turn_rate: 0.0,
        gamma: 0.0,
    }
}

fn turn(duration: f64, deg_per_s: f64, gamma_deg: f64) -> Segment {
    Segment {
        duration,
        turn_rate: deg_per_s * DEG,
        gamma: gamma_deg * DEG,
    }
}

/// Straight and level, 20 deg/s turns both ways (one while climbing), a 5 deg climb, in a
/// steady 5 m/s wind: 240 s.
fn mission() -> [Segment; 8] {
    [
        level(40.0),
        turn(36.0, 20.0, 0.0),
        level(20.0),
        turn(20.0, 0.0, 5.0),
        turn(27.0, -20.0, 5.0),
        level(20.0),
        turn(36.0, 20.0, 0.0),
        level(41.0),
    ]
}

fn euler_of(q: &nalgebra::UnitQuaternion<f64>) -> (f64, f64, f64) {
    q.euler_angles()
}

#[test]
fn accuracy_over_a_four_minute_flight() {
    let mut f = Flight::new(&mission(), 7, EstimatorConfig::default());
    let (mut roll, mut pitch, mut hdg, mut alt, mut va, mut wind, mut wind_turn, mut pos, mut vel) = (
        Rms::default(),
        Rms::default(),
        Rms::default(),
        Rms::default(),
        Rms::default(),
        Rms::default(),
        Rms::default(),
        Rms::default(),
        Rms::default(),
    );
    let mut converged_at = None;
    let steps = (f.traj.duration() / DT) as usize - 1;
    let mut last = None;
    for _ in 0..steps {
        let tr = f.step();
        let st = f.est.state();
        if st.converged && converged_at.is_none() {
            converged_at = Some(tr.t);
        }
        last = Some(tr);
        // Scored from 60 s: the filters have had a straight leg and the first turn to settle.
        if tr.t < 60.0 {
            continue;
        }
        let (phi, theta, psi) = euler_of(&tr.q);
        let e = st.euler;
        roll.add(wrap_pi(f64::from(e.phi) - phi));
        pitch.add(wrap_pi(f64::from(e.theta) - theta));
        hdg.add(wrap_pi(f64::from(e.psi) - psi));
        alt.add(f64::from(st.alt_amsl_m) - tr.alt_amsl());
        va.add(f64::from(st.airspeed) - tr.va);
        let dw = (st.wind_ned.cast::<f64>() - tr.wind).xy().norm();
        wind.add(dw);
        if tr.turn_rate.abs() > 15.0 * DEG {
            wind_turn.add(dw);
        }
        pos.add(f.horizontal_error(&tr));
        vel.add((st.vel_ned.cast::<f64>() - tr.vel).norm());
        assert!(st.converged, "lost convergence at t = {}", tr.t);
    }
    let tr = last.unwrap();
    let bias_err = (f.est.state().gyro_bias.cast::<f64>() - f.sim.gyro_bias).abs();
    println!(
        "converged at {:?} s; RMS (max) from 60 s: roll {:.3} ({:.3}) deg, pitch {:.3} ({:.3}) deg, \
         heading {:.3} ({:.3}) deg, alt {:.3} ({:.3}) m, airspeed {:.3} ({:.3}) m/s, \
         wind {:.3} ({:.3}) m/s, wind in turns {:.3} ({:.3}) m/s, horiz pos {:.3} ({:.3}) m, \
         vel {:.3} ({:.3}) m/s; gyro bias error {:.4?} deg/s at {} s",
        converged_at,
        roll.rms() / DEG,
        roll.max / DEG,
        pitch.rms() / DEG,
        pitch.max / DEG,
        hdg.rms() / DEG,
        hdg.max / DEG,
        alt.rms(),
        alt.max,
        va.rms(),
        va.max,
        wind.rms(),
        wind.max,
        wind_turn.rms(),
        wind_turn.max,
        pos.rms(),
        pos.max,
        vel.rms(),
        vel.max,
        bias_err / DEG,
        tr.t
    );
    assert!(converged_at.is_some_and(|t| t < 60.0));
    assert!(roll.rms() < 0.5 * DEG, "roll {}", roll.rms() / DEG);
    assert!(pitch.rms() < 0.5 * DEG, "pitch {}", pitch.rms() / DEG);
    assert!(hdg.rms() < 2.0 * DEG, "heading {}", hdg.rms() / DEG);
    assert!(alt.rms() < 1.0, "alt {}", alt.rms());
    assert!(va.rms() < 0.5, "airspeed {}", va.rms());
    assert!(wind.rms() < 1.0, "wind {}", wind.rms());
    assert!(
        wind_turn.n > 1000 && wind_turn.rms() < 1.0,
        "wind in turns {}",
        wind_turn.rms()
    );
    // The bias is 1.15, -0.86, 0.57 deg/s; each axis must be found to 0.1 deg/s.
    assert!(
        bias_err.max() < 0.1 * DEG,
        "bias error {:?}",
        bias_err / DEG
    );
}
