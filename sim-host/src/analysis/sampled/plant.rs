//! The aircraft as the autopilot sees it: the full linear model (all thirteen states, both axes)
//! with a first-order servo on every surface, held over each control period (zero-order hold)
//! and discretised exactly at the autopilot's rate, read through the measurements the loops use.

use crate::analysis::linearize::{iu, ix, state_of, Linearization, NX};
use common::math::frames::course_and_speed;
use common::math::{AirData, Euler};
use nalgebra::{Complex, DMatrix, DVector, Vector3};

/// What the autopilot commands, in this order.
pub mod cmd {
    /// Elevator, rad (UMN sign).
    pub const ELEVATOR: usize = 0;
    /// Throttle, 0..1.
    pub const THROTTLE: usize = 1;
    /// Combined aileron `(right - left) / 2`, rad.
    pub const AILERON: usize = 2;
    /// Rudder, rad.
    pub const RUDDER: usize = 3;
    /// How many.
    pub const N: usize = 4;
}

/// What the loops measure, in this order.
pub mod out {
    /// Airspeed, m/s.
    pub const AIRSPEED: usize = 0;
    /// Pitch, rad.
    pub const PITCH: usize = 1;
    /// Pitch rate, rad/s.
    pub const PITCH_RATE: usize = 2;
    /// Height, m (up).
    pub const HEIGHT: usize = 3;
    /// Roll, rad.
    pub const ROLL: usize = 4;
    /// Roll rate, rad/s.
    pub const ROLL_RATE: usize = 5;
    /// Yaw rate, rad/s.
    pub const YAW_RATE: usize = 6;
    /// Sideslip, rad.
    pub const SIDESLIP: usize = 7;
    /// Course over ground, rad.
    pub const COURSE: usize = 8;
    /// Heading, rad.
    pub const HEADING: usize = 9;
    /// How many.
    pub const N: usize = 10;
}

/// The rigid-body states kept: all but the north and east positions, which no loop measures
/// (their poles at z = 1 would only make the model singular there).
const KEPT: [usize; 11] = [
    ix::ZE,
    ix::U,
    ix::V,
    ix::W,
    ix::PHI,
    ix::THETA,
    ix::PSI,
    ix::P,
    ix::Q,
    ix::R,
    ix::OMEGA,
];
/// Servo-driven surfaces, each a state after the rigid body's.
const SERVOS: [usize; 4] = [
    iu::ELEVATOR,
    iu::AILERON_LEFT,
    iu::AILERON_RIGHT,
    iu::RUDDER,
];

/// The sampled linear aircraft `x[k+1] = Ad x[k] + Bd u[k]`, `y[k] = C x[k]`.
#[derive(Clone, Debug)]
pub struct SampledPlant {
    /// Control period, s.
    pub period_s: f64,
    ad: DMatrix<f64>,
    bd: DMatrix<f64>,
    c: DMatrix<f64>,
}

/// The measured quantities of a 13-state vector (course from the NED velocity, as the
/// estimator forms it from GPS).
fn outputs(x: &nalgebra::SVector<f64, NX>) -> [f64; out::N] {
    let s = state_of(x);
    let air = AirData::from_body_velocity(&s.vel_body);
    let e = Euler::new(x[ix::PHI], x[ix::THETA], x[ix::PSI]);
    let v_ned: Vector3<f64> = e.body_to_ned() * s.vel_body;
    let (course, _) = course_and_speed(&v_ned);
    [
        air.va,
        x[ix::THETA],
        x[ix::Q],
        -x[ix::ZE],
        x[ix::PHI],
        x[ix::P],
        x[ix::R],
        air.beta,
        course,
        x[ix::PSI],
    ]
}

impl SampledPlant {
    /// The model of `lin` with servos of bandwidth `servo_radps`, sampled every `period_s`.
    pub fn new(lin: &Linearization, servo_radps: f64, period_s: f64) -> Self {
        let nb = KEPT.len();
        let n = nb + SERVOS.len();
        let mut a = DMatrix::<f64>::zeros(n, n);
        let mut b = DMatrix::<f64>::zeros(n, cmd::N);
        for (i, &si) in KEPT.iter().enumerate() {
            for (j, &sj) in KEPT.iter().enumerate() {
                a[(i, j)] = lin.a[(si, sj)];
            }
            for (k, &u) in SERVOS.iter().enumerate() {
                a[(i, nb + k)] = lin.b[(si, u)];
            }
            b[(i, cmd::THROTTLE)] = lin.b[(si, iu::THROTTLE)];
        }
        for k in 0..SERVOS.len() {
            a[(nb + k, nb + k)] = -servo_radps;
        }
        b[(nb, cmd::ELEVATOR)] = servo_radps;
        b[(nb + 1, cmd::AILERON)] = -servo_radps;
        b[(nb + 2, cmd::AILERON)] = servo_radps;
        b[(nb + 3, cmd::RUDDER)] = servo_radps;
        // Zero-order hold, exactly: exp([[A, B], [0, 0]] T) = [[Ad, Bd], [0, I]].
        let mut m = DMatrix::<f64>::zeros(n + cmd::N, n + cmd::N);
        m.view_mut((0, 0), (n, n)).copy_from(&(&a * period_s));
        m.view_mut((0, n), (n, cmd::N)).copy_from(&(&b * period_s));
        let e = m.exp();
        let ad = e.view((0, 0), (n, n)).into_owned();
        let bd = e.view((0, n), (n, cmd::N)).into_owned();
        // Measurements: central differences about the trim, as the linearisation does.
        let mut c = DMatrix::<f64>::zeros(out::N, n);
        for (j, &sj) in KEPT.iter().enumerate() {
            let h = 1e-6 * lin.x0[sj].abs().max(1.0);
            let (mut xp, mut xm) = (lin.x0, lin.x0);
            xp[sj] += h;
            xm[sj] -= h;
            let (yp, ym) = (outputs(&xp), outputs(&xm));
            for i in 0..out::N {
                c[(i, j)] = (yp[i] - ym[i]) / (2.0 * h);
            }
        }
        Self {
            period_s,
            ad,
            bd,
            c,
        }
    }

    /// `C (z I - Ad)^-1 Bd`, measurements per command (no delay), at `z`.
    pub fn response(&self, z: Complex<f64>) -> DMatrix<Complex<f64>> {
        let n = self.ad.nrows();
        let m = DMatrix::<Complex<f64>>::from_fn(n, n, |i, j| {
            let d = if i == j { z } else { Complex::new(0.0, 0.0) };
            d - Complex::new(self.ad[(i, j)], 0.0)
        });
        let bd = self.bd.map(|v| Complex::new(v, 0.0));
        let c = self.c.map(|v| Complex::new(v, 0.0));
        match m.lu().solve(&bd) {
            Some(x) => c * x,
            None => DMatrix::from_element(out::N, cmd::N, Complex::new(f64::NAN, f64::NAN)),
        }
    }

    /// Poles of the sampled aircraft (eigenvalues of `Ad`).
    pub fn poles(&self) -> Vec<Complex<f64>> {
        crate::analysis::lti::eigenvalues(&self.ad)
    }

    /// Number of states (rigid body and servos).
    pub fn states(&self) -> usize {
        self.ad.nrows()
    }

    /// The state one period after `x` with the commands `u` held over it.
    pub fn advance(&self, x: &DVector<f64>, u: &[f64; cmd::N]) -> DVector<f64> {
        &self.ad * x + &self.bd * DVector::from_column_slice(u)
    }

    /// The measurements of state `x`, as deviations from the trim.
    pub fn measure(&self, x: &DVector<f64>) -> [f64; out::N] {
        let y = &self.c * x;
        let mut o = [0.0; out::N];
        o.copy_from_slice(y.as_slice());
        o
    }
}
