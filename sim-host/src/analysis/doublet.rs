//! The linear-versus-nonlinear doublet check of thesis section 3.2.
//!
//! From a trim, a doublet (+A for a half period, then -A, then back to trim) is commanded on
//! one surface. The command passes through the servo model and the servo output drives both the
//! nonlinear plant and the full 13-state linear model about the same trim (RK4, same step), so
//! the two see identical surface motion and only the model differs. The command is held over
//! each step and the servos move inside it, each RK4 stage seeing the surfaces at its time
//! ([`ServoBank::rk4_held`], as in every simulation).

use super::linearize::{ix, u5_of, Linearization, X13};
use super::trim::TrimResult;
use crate::aircraft::Aircraft;
use crate::plant::inputs::{Controls, Environment};
use crate::plant::params::ModelParams;
use crate::plant::servo::ServoBank;
use crate::plant::Plant;
use serde::Serialize;

/// The surface a doublet is applied to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Surface {
    /// Elevator.
    Elevator,
    /// Combined aileron (left -A, right +A).
    Aileron,
    /// Rudder.
    Rudder,
}

impl Surface {
    /// Lower-case name.
    pub fn name(self) -> &'static str {
        match self {
            Surface::Elevator => "elevator",
            Surface::Aileron => "aileron",
            Surface::Rudder => "rudder",
        }
    }
}

/// Doublet timing and size.
#[derive(Clone, Copy, Debug, Serialize, PartialEq)]
pub struct DoubletConfig {
    /// Amplitude, rad.
    pub amplitude_rad: f64,
    /// Start of the doublet, s.
    pub start_s: f64,
    /// Duration of each half (+A, then -A), s.
    pub half_period_s: f64,
    /// Length of the run, s.
    pub duration_s: f64,
    /// Integration step, s.
    pub dt_s: f64,
}

impl Default for DoubletConfig {
    fn default() -> Self {
        Self {
            amplitude_rad: 3f64.to_radians(),
            start_s: 1.0,
            half_period_s: 0.5,
            duration_s: 10.0,
            dt_s: 0.005,
        }
    }
}

/// Outputs compared between the models (SI, rad).
#[derive(Clone, Copy, Debug, Default, Serialize, PartialEq)]
pub struct Outputs {
    /// Airspeed, m/s.
    pub va: f64,
    /// Angle of attack, rad.
    pub alpha: f64,
    /// Sideslip, rad.
    pub beta: f64,
    /// Roll, rad.
    pub phi: f64,
    /// Pitch, rad.
    pub theta: f64,
    /// Yaw, rad.
    pub psi: f64,
    /// Roll rate, rad/s.
    pub p: f64,
    /// Pitch rate, rad/s.
    pub q: f64,
    /// Yaw rate, rad/s.
    pub r: f64,
    /// Engine speed, rad/s.
    pub omega: f64,
}

/// Names, user units and scale factors (SI to user unit) of [`Outputs`], in field order.
pub const OUTPUT_INFO: [(&str, &str, f64); 10] = [
    ("airspeed", "m/s", 1.0),
    ("alpha", "deg", 57.295_779_513_082_32),
    ("beta", "deg", 57.295_779_513_082_32),
    ("phi", "deg", 57.295_779_513_082_32),
    ("theta", "deg", 57.295_779_513_082_32),
    ("psi", "deg", 57.295_779_513_082_32),
    ("p", "deg/s", 57.295_779_513_082_32),
    ("q", "deg/s", 57.295_779_513_082_32),
    ("r", "deg/s", 57.295_779_513_082_32),
    ("Omega", "rad/s", 1.0),
];

impl Outputs {
    /// The outputs as an array in [`OUTPUT_INFO`] order.
    pub fn as_array(&self) -> [f64; 10] {
        [
            self.va, self.alpha, self.beta, self.phi, self.theta, self.psi, self.p, self.q, self.r,
            self.omega,
        ]
    }
}

/// One recorded instant.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct Sample {
    /// Time, s.
    pub t: f64,
    /// Deflection of the doublet surface after the servo, rad (combined for the aileron).
    pub surface: f64,
    /// Nonlinear plant.
    pub nonlinear: Outputs,
    /// Linear model.
    pub linear: Outputs,
}

/// A finished doublet run.
#[derive(Clone, Debug, Serialize)]
pub struct DoubletRun {
    /// Surface.
    pub surface: Surface,
    /// Set-up.
    pub config: DoubletConfig,
    /// Output names with units, in [`OUTPUT_INFO`] order.
    pub outputs: Vec<String>,
    /// Largest |nonlinear - linear| per output, in user units ([`OUTPUT_INFO`] order).
    pub max_abs_diff: Vec<f64>,
    /// Largest |nonlinear - trim| per output, in user units (the size of the response).
    pub max_abs_response: Vec<f64>,
    /// The recording (every step).
    #[serde(skip)]
    pub samples: Vec<Sample>,
}

fn command(trim: &Controls, surface: Surface, cfg: &DoubletConfig, t: f64) -> Controls {
    let t0 = cfg.start_s;
    let a = if t >= t0 && t < t0 + cfg.half_period_s {
        cfg.amplitude_rad
    } else if t >= t0 + cfg.half_period_s && t < t0 + 2.0 * cfg.half_period_s {
        -cfg.amplitude_rad
    } else {
        0.0
    };
    let mut c = *trim;
    match surface {
        Surface::Elevator => c.elevator += a,
        Surface::Aileron => {
            c.aileron_left -= a;
            c.aileron_right += a;
        }
        Surface::Rudder => c.rudder += a,
    }
    c
}

fn linear_outputs(lin: &Linearization, dx: &X13) -> Outputs {
    let x = lin.x0 + dx;
    let air0 = super::linearize::air_outputs(&lin.x0);
    let d_air = lin.c_air * dx;
    Outputs {
        va: air0.x + d_air.x,
        alpha: air0.y + d_air.y,
        beta: air0.z + d_air.z,
        phi: x[ix::PHI],
        theta: x[ix::THETA],
        psi: x[ix::PSI],
        p: x[ix::P],
        q: x[ix::Q],
        r: x[ix::R],
        omega: x[ix::OMEGA],
    }
}

fn nonlinear_outputs(plant: &Plant) -> Outputs {
    let air = plant.air_data();
    let e = plant.euler();
    let w = plant.body_rates();
    Outputs {
        va: air.va,
        alpha: air.alpha,
        beta: air.beta,
        phi: e.phi,
        theta: e.theta,
        psi: e.psi,
        p: w.x,
        q: w.y,
        r: w.z,
        omega: plant.engine_speed(),
    }
}

/// Runs one doublet on both models.
pub fn run(
    aircraft: &Aircraft,
    trim: &TrimResult,
    lin: &Linearization,
    surface: Surface,
    cfg: &DoubletConfig,
) -> DoubletRun {
    let params = ModelParams::new(aircraft);
    let mut plant = Plant::from_params(params, trim.state);
    let mut servos = ServoBank::new(&aircraft.actuators, &trim.controls);
    // Each model has servos of its own, driven by the same command: the same surface motion.
    let mut lin_servos = servos;
    let env = Environment::default();
    let u0 = u5_of(&trim.controls);
    let mut dx = X13::zeros();
    let steps = (cfg.duration_s / cfg.dt_s).round() as usize;
    let mut samples = Vec::with_capacity(steps + 1);
    let mut actual = trim.controls;
    let surface_of = |c: &Controls| match surface {
        Surface::Elevator => c.elevator,
        Surface::Aileron => c.aileron(),
        Surface::Rudder => c.rudder,
    };
    samples.push(Sample {
        t: 0.0,
        surface: surface_of(&actual),
        nonlinear: nonlinear_outputs(&plant),
        linear: linear_outputs(lin, &dx),
    });
    for k in 0..steps {
        let t = k as f64 * cfg.dt_s;
        let cmd = command(&trim.controls, surface, cfg, t);
        actual = plant.step_servos(&mut servos, &cmd, &env, cfg.dt_s);
        lin_servos.rk4_held(&cmd, &mut dx, cfg.dt_s, |c, x| {
            lin.a * x + lin.b * (u5_of(c) - u0)
        });
        samples.push(Sample {
            t: (k + 1) as f64 * cfg.dt_s,
            surface: surface_of(&actual),
            nonlinear: nonlinear_outputs(&plant),
            linear: linear_outputs(lin, &dx),
        });
    }
    let trim_out = samples[0].nonlinear.as_array();
    let mut max_abs_diff = vec![0.0; OUTPUT_INFO.len()];
    let mut max_abs_response = vec![0.0; OUTPUT_INFO.len()];
    for s in &samples {
        let (nl, li) = (s.nonlinear.as_array(), s.linear.as_array());
        for i in 0..OUTPUT_INFO.len() {
            let scale = OUTPUT_INFO[i].2;
            let mut d = nl[i] - li[i];
            let mut resp = nl[i] - trim_out[i];
            if i == 5 {
                d = common::math::wrap_pi(d);
                resp = common::math::wrap_pi(resp);
            }
            max_abs_diff[i] = f64::max(max_abs_diff[i], (d * scale).abs());
            max_abs_response[i] = f64::max(max_abs_response[i], (resp * scale).abs());
        }
    }
    DoubletRun {
        surface,
        config: *cfg,
        outputs: OUTPUT_INFO
            .iter()
            .map(|(n, u, _)| format!("{n} ({u})"))
            .collect(),
        max_abs_diff,
        max_abs_response,
        samples,
    }
}
