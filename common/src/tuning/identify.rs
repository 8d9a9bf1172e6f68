//! The thesis's reduced models (Beard and McLain, chapter 5) fitted from flight data by least
//! squares: roll, pitch and airspeed as the design by successive loop closure takes them, and
//! the course and altitude loops' kinematics.
//!
//! Each model is an equation error in continuous time, written between two consecutive
//! samples: the state's rate is its difference over the interval, the states on the right are
//! their means over it (the trapezoid: a pole at `-a` comes out at `-a` to 0.3 % for
//! `a T = 0.32`, the 25e's roll at 50 Hz), and the surfaces are where a first-order servo of
//! time constant `servo_tau_s` and rate limit `servo_rate_radps` puts them, held command by
//! command as the servos see it (a pilot's full-stick doublet moves the 25e's aileron 45 deg
//! at its 150 deg/s: 0.3 s on the rate limit, where the first-order lag alone would be done
//! in a tenth of that)
//! (left out, a 20 ms servo lag on a 60 ms roll mode reads as a roll damping and an aileron
//! power a third or more short).
//!
//! The aerodynamic terms scale with the airspeed as the book's expressions do (damping with
//! `Va`, stiffness and control power with `Va^2`), so a fit over a flight's range of airspeeds
//! gives the coefficients at one reference airspeed (`airspeed_ref`, the design's trim):
//!
//! ```text
//! roll      p'  = -a_phi1 v p + a_phi2 v^2 da + k_r v r + k_ay a_y + k_t dt + c v^2
//! pitch     q'  = -a_theta1 v q - a_theta2 v^2 alpha + a_theta3 v^2 de + k_t dt + c v^2
//!                 + k_r r + k_pr p r + k_rr (r^2 - p^2)
//!                                                                          v = Va / Va_ref
//! sideslip  a_y = Va_ref v^2 (-a_beta1 beta + a_beta2 dr) + k_p v p + k_r v r + c v^2
//! airspeed  Va' = -a_V1 (Va - Va_ref) + a_V2 dt - a_V3 theta + k_alpha alpha + k_beta v^2 beta^2 + c
//! course    chi' = k_chi g tan(phi) / Vg + c                               (k_chi = 1 ideal)
//! altitude  h'  = k_h Va theta + c                                         (k_h = 1 ideal)
//! flight    Va gamma' + g cos(gamma) = v^2 cos(phi) (a_gamma Va_ref alpha + c)   gamma = h'/Va
//! ```
//!
//! The sideslip's model is the book's side force, `beta' = -a_beta1 beta + a_beta2 dr` with
//! `a_beta1 = -rho Va S CY_beta / (2 m)` and `a_beta2 = rho Va S CY_dr / (2 m)`: what the
//! accelerometer measures across the body is that force per unit mass, `a_y = Va (-a_beta1 beta
//! + a_beta2 dr)` at the airspeed flown, where both coefficients grow with `Va`, so no rate is
//! differenced and a noisy accelerometer's noise falls on the measured side alone, where least
//! squares averages it out. The rates' side force (`CY_p`, `CY_r`) and the trim's are the `k_p`,
//! `k_r` and `c` terms. The ailerons' (`CY_da`, none on the 25e) is left out: on the rudder
//! doublets the ailerons move only to hold the wings against the sideslip's roll, in step with
//! the sideslip, and a term for them took `a_beta1` 12 % high on the 25e's truth, where without
//! it both coefficients come within 6 %. The sideslip's drag slows the aircraft as its square
//! (`k_beta`): left out, the rudder doublets took the airspeed fit's R^2 from 0.7 to 0.46.
//!
//! The flight path turns as the lift the angle of attack builds (the heave damping: `a_gamma =
//! rho Va S (CL_alpha + CD) / (2 m)`); the altitude loop's design reads its lag behind the
//! pitch from it (`gamma / theta = a_gamma / (s + a_gamma)` at constant airspeed, where the
//! book's altitude model, `h / theta = Va / s`, has none).
//!
//! `k_r`, `k_ay`, `k_t`, `k_alpha` and the constants `c` take up what the reduced models leave
//! to their disturbance terms, so that these do not lean on the coefficients the design uses:
//! the yaw rate's roll; the sideslip's (dihedral) roll, read through the lateral specific force
//! `a_y`, which the sideslip makes in proportion to the dynamic pressure as its rolling moment
//! is (no vane needed); the engine's torque and thrust line with the throttle `dt`; the trim
//! moments; drag with angle of attack; in pitch, the yaw rate (the propeller's gyroscopic
//! moment) and the rates' inertial coupling (`p r`, `r^2 - p^2`), which a turn holds steady. Left out, in the 25e's closed-loop flight of the
//! thesis's script, the turns' sideslip and the climbs' torque took the roll fit's R^2 from
//! 0.96 to 0.40 and `a_phi1` to half its value. Signs are the Minnesota model's: a
//! positive aileron rolls left (`a_phi2 < 0`), a positive elevator pitches down
//! (`a_theta3 < 0`).

use super::least_squares::{Fit, LeastSquares};
use crate::math::frames::wrap_pi;
use crate::math::GRAVITY;
use nalgebra::SVector;

/// One sample of what the models read: SI units, radians, surfaces in the Minnesota signs.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Sample {
    /// Roll rate, rad/s.
    pub p: f32,
    /// Pitch rate, rad/s.
    pub q: f32,
    /// Yaw rate, rad/s.
    pub r: f32,
    /// The sideslip's lateral force: the lateral specific force (accelerometer y, m/s^2)
    /// where it is clean, as a simulator's truth is, or anything in proportion to it (the
    /// vehicle gives `sideslip * airspeed^2`, rad m^2/s^2: a real accelerometer's noise, 0.6
    /// m/s^2 on the 25e's, is larger than the signal, and least squares read it as a smaller
    /// roll term and put `a_phi1` 15 % high). Only its fitted coefficient's scale depends on
    /// which.
    pub ay: f32,
    /// Sideslip of the velocity through the air, rad.
    pub beta: f32,
    /// The speed of that velocity, m/s, which the sideslip model's dynamic pressure is read
    /// from (0 or less: `airspeed`'s). A pitot's low-passed airspeed lags the rudder doublets'
    /// drag, which slows the 25e by 1-2 m/s within a second: through it the rudder's side
    /// force came out 15 % high on average over six flights (+1 to +25 %); through the
    /// velocity less the wind, -4 to +6 %.
    pub air_speed: f32,
    /// Lateral specific force, what an accelerometer's y axis reads, m/s^2.
    pub accel_y: f32,
    /// Roll, rad.
    pub phi: f32,
    /// Pitch, rad.
    pub theta: f32,
    /// Airspeed, m/s.
    pub airspeed: f32,
    /// Angle of attack, rad (the air-relative velocity's, where the wind is known).
    pub alpha: f32,
    /// Climb rate, m/s (up).
    pub climb_rate: f32,
    /// Course over the ground, rad.
    pub course: f32,
    /// Ground speed, m/s.
    pub ground_speed: f32,
    /// Aileron command, rad (Minnesota signs: positive rolls left).
    pub aileron: f32,
    /// Elevator command, rad (positive pitches down).
    pub elevator: f32,
    /// Rudder command, rad (Minnesota signs: positive raises the sideslip).
    pub rudder: f32,
    /// Throttle, 0..1.
    pub throttle: f32,
}

/// What an identification is set up with.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IdentifyConfig {
    /// Airspeed the coefficients are given at, m/s.
    pub airspeed_ref: f32,
    /// Time constant of the surface servos, s (`1 / (2 pi bandwidth)`).
    pub servo_tau_s: f32,
    /// Fastest a surface moves, rad/s (0: no limit).
    pub servo_rate_radps: f32,
    /// Time constant of the low-pass the airspeed equation's regressors and rate go through
    /// together before the fit, s (0: none). The same linear filter on both sides of a linear
    /// equation leaves it true, and takes out of the airspeed's rate the noise its
    /// differences take from a pitot's (the rate of a 50 Hz difference of the 25e's airspeed
    /// sensor's noise swamps the airspeed's own: R^2 0.09 unfiltered); the airspeed's own
    /// time constant (about 4 s) lies far below the corner.
    pub airspeed_filter_tau_s: f32,
    /// Time constant of the low-pass the roll and pitch equations go through on both sides,
    /// s (0: none). The rates' differences amplify a gyro's white noise in proportion to the
    /// sample rate (a rate's difference over 20 ms carries 70 times the gyro's noise), and the
    /// doublets' content lies below 2 Hz: a corner at 5.3 Hz (0.03 s) keeps it and takes the
    /// noise above. From the vehicle's own estimate the Aerosonde's pitch fit explains R^2
    /// 0.49 unfiltered, 0.76 through it (the 25e's 0.74 and 0.84); a slower filter (0.1 s)
    /// reaches into the short period and its servo, and the pitch coefficients fall 7-26 %.
    pub attitude_filter_tau_s: f32,
}

/// The airspeed pre-filter the vehicle fits its own sensors through, s.
pub const AIRSPEED_FILTER_TAU_S: f32 = 0.5;

/// The roll and pitch pre-filter the vehicle fits its own sensors through, s.
pub const ATTITUDE_FILTER_TAU_S: f32 = 0.03;

/// One equation's rows through the pre-filter.
#[derive(Clone, Copy, Debug)]
struct Prefilter<const N: usize> {
    row: SVector<f32, N>,
    rate: f32,
    started: bool,
}

impl<const N: usize> Prefilter<N> {
    fn new() -> Self {
        Self {
            row: SVector::zeros(),
            rate: 0.0,
            started: false,
        }
    }

    /// The row and rate after the filter, `k` the step's share of the way to the input.
    fn pass(&mut self, k: f32, row: SVector<f32, N>, rate: f32) -> (SVector<f32, N>, f32) {
        if !self.started || k >= 1.0 {
            // Starting from the first row: the filter's free response then obeys the same
            // equation as its input.
            self.started = true;
            self.row = row;
            self.rate = rate;
        } else {
            self.row += (row - self.row) * k;
            self.rate += k * (rate - self.rate);
        }
        (self.row, self.rate)
    }
}

/// A first-order low-pass's step of `dt_s` towards its input: the share of the way, 1 (no
/// filter) for a time constant that is not positive.
fn share(dt_s: f32, tau_s: f32) -> f32 {
    if tau_s > 0.0 {
        1.0 - libm::expf(-dt_s / tau_s)
    } else {
        1.0
    }
}

/// Sub-steps a servo is followed with over one interval: the rate limit makes the motion
/// piecewise, so no closed form serves; eight keep the mean within 0.2 % of the surface's
/// travel over the interval.
const SERVO_STEPS: u8 = 8;

/// A first-order servo with a rate limit from `from`, the command `cmd` held for `dt_s`:
/// where it ends and its mean over the interval (each sub-step exact for the first-order
/// motion, clamped to the rate limit).
pub(super) fn servo(c: &IdentifyConfig, from: f32, cmd: f32, dt_s: f32) -> (f32, f32) {
    if c.servo_tau_s <= 0.0 {
        return (cmd, cmd);
    }
    let h = dt_s / f32::from(SERVO_STEPS);
    let k = 1.0 - libm::expf(-h / c.servo_tau_s);
    let max_step = if c.servo_rate_radps > 0.0 {
        c.servo_rate_radps * h
    } else {
        f32::INFINITY
    };
    let (mut x, mut sum) = (from, 0.0);
    for _ in 0..SERVO_STEPS {
        // Not `clamp`: it panics (and brings float formatting into the image) on bounds it
        // cannot order, as a NaN rate would give.
        let step = (k * (cmd - x)).max(-max_step).min(max_step);
        // The sub-step's mean: the exponential's where unclamped, the ramp's where clamped.
        let mean = if step.abs() < max_step {
            cmd + (x - cmd) * c.servo_tau_s / h * k
        } else {
            x + 0.5 * step
        };
        sum += mean;
        x += step;
    }
    (x, sum / f32::from(SERVO_STEPS))
}

/// The loops the models are fitted for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Axis {
    Roll,
    Sideslip,
    Pitch,
    Airspeed,
    Course,
    Altitude,
    FlightPath,
}

impl Axis {
    /// Every axis, in the order of the design (inner loops first).
    pub const ALL: [Axis; 7] = [
        Axis::Roll,
        Axis::Sideslip,
        Axis::Pitch,
        Axis::Airspeed,
        Axis::Course,
        Axis::Altitude,
        Axis::FlightPath,
    ];

    /// Name, as the reports print it.
    pub fn name(self) -> &'static str {
        match self {
            Axis::Roll => "roll",
            Axis::Sideslip => "sideslip",
            Axis::Pitch => "pitch",
            Axis::Airspeed => "airspeed",
            Axis::Course => "course",
            Axis::Altitude => "altitude",
            Axis::FlightPath => "flight path",
        }
    }

    /// Names of the fitted coefficients, in the order of [`AxisFit::coef`].
    pub fn coefficients(self) -> &'static [&'static str] {
        match self {
            Axis::Roll => &["a_phi1", "a_phi2", "k_r", "k_ay", "k_t", "c_phi"],
            Axis::Sideslip => &["a_beta1", "a_beta2", "k_p", "k_r", "c_beta"],
            Axis::Pitch => &[
                "a_theta1", "a_theta2", "a_theta3", "k_t", "c_theta", "k_r", "k_pr", "k_rr",
            ],
            Axis::Airspeed => &["a_V1", "a_V2", "a_V3", "k_alpha", "c_V", "k_beta"],
            Axis::Course => &["k_chi", "c_chi"],
            Axis::Altitude => &["k_h", "c_h"],
            Axis::FlightPath => &["a_gamma", "c_gamma"],
        }
    }

    /// The input whose variation identifies the axis, and the least variation (standard
    /// deviation, in the input's unit: rad, or throttle) that counts as an excitation. A
    /// quarter of a degree of surface is what a servo's dead band and the sensors' noise
    /// leave unresolved; the kinematic loops are excited by bank and pitch changes.
    pub fn input(self) -> (&'static str, f32) {
        match self {
            Axis::Roll => ("aileron", 0.25 * crate::math::DEG),
            Axis::Sideslip => ("rudder", 0.25 * crate::math::DEG),
            Axis::Pitch => ("elevator", 0.25 * crate::math::DEG),
            Axis::Airspeed => ("throttle", 0.02),
            Axis::Course => ("bank", 2.0 * crate::math::DEG),
            Axis::Altitude | Axis::FlightPath => ("pitch", 1.0 * crate::math::DEG),
        }
    }
}

/// Most coefficients an axis has.
pub const COEFS: usize = 8;

/// One axis's fit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AxisFit {
    /// Coefficients in the order of [`Axis::coefficients`] (unused places 0).
    pub coef: [f32; COEFS],
    /// Their standard errors.
    pub std_err: [f32; COEFS],
    /// Share of the state's rate the model explains.
    pub r2: f32,
    /// Sample pairs fitted.
    pub rows: u32,
    /// Standard deviation of the axis's input over those pairs (rad, or throttle).
    pub input_sd: f32,
}

/// Why an axis has no fit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum AxisError {
    /// Its input did not vary enough: the standard deviation it had and the least needed.
    NotExcited {
        input: &'static str,
        sd: f32,
        needed: f32,
    },
    /// Its regressors never varied independently of each other (too few samples, or one
    /// moved only with another).
    Singular,
}

/// Running mean and variance (Welford's update).
#[derive(Clone, Copy, Debug, Default)]
struct Spread {
    n: u32,
    mean: f32,
    m2: f32,
}

impl Spread {
    fn push(&mut self, x: f32) {
        self.n += 1;
        let d = x - self.mean;
        self.mean += d / self.n as f32;
        self.m2 += d * (x - self.mean);
    }

    fn sd(&self) -> f32 {
        if self.n < 2 {
            return 0.0;
        }
        libm::sqrtf(self.m2 / (self.n - 1) as f32)
    }
}

/// The models, fitted as samples arrive.
#[derive(Clone, Debug)]
pub struct Identifier {
    config: IdentifyConfig,
    prev: Option<Sample>,
    /// Where the servos hold the aileron, elevator and rudder at `prev`, rad.
    surfaces: [f32; 3],
    roll: LeastSquares<6>,
    sideslip: LeastSquares<5>,
    pitch: LeastSquares<8>,
    speed: LeastSquares<6>,
    course: LeastSquares<2>,
    altitude: LeastSquares<2>,
    flight_path: LeastSquares<2>,
    roll_filter: Prefilter<6>,
    pitch_filter: Prefilter<8>,
    speed_filter: Prefilter<6>,
    path_filter: Prefilter<2>,
    inputs: [Spread; 6],
    /// Which models take the rows: the sideslip's, the others'.
    rows: (bool, bool),
}

/// Longest interval two samples may be apart and still make a rate, s: longer is a gap in
/// the data (a dropped frame, a log's pause), not a derivative.
const MAX_INTERVAL_S: f32 = 0.1;

impl Identifier {
    /// Nothing fitted yet.
    pub fn new(config: IdentifyConfig) -> Self {
        Self {
            config,
            prev: None,
            surfaces: [0.0; 3],
            roll: LeastSquares::new(),
            sideslip: LeastSquares::new(),
            pitch: LeastSquares::new(),
            speed: LeastSquares::new(),
            course: LeastSquares::new(),
            altitude: LeastSquares::new(),
            flight_path: LeastSquares::new(),
            roll_filter: Prefilter::new(),
            pitch_filter: Prefilter::new(),
            speed_filter: Prefilter::new(),
            path_filter: Prefilter::new(),
            inputs: [Spread::default(); 6],
            rows: (true, true),
        }
    }

    /// Which models take the next rows: the sideslip's (`sideslip`), the others' (`others`);
    /// both from the start. A flight that excites each axis in a stage of its own fits each
    /// model on its stage: the rudder doublets' sideslip is beyond what the other reduced
    /// models hold (its drag and the lift it costs: the 25e's flight-path fit fell from R^2 0.7
    /// to 0.35 with them), and the other stages' rudder moves only with the yaw damper (on its
    /// truth, the 25e's autotune flight put `a_beta2` 15 % short with them, 1.4 % on the
    /// rudder doublets alone).
    pub fn take_rows(&mut self, sideslip: bool, others: bool) {
        self.rows = (sideslip, others);
    }

    /// Forgets the previous sample: the next one starts a new stretch of data (the samples
    /// between are not the model's: on the ground, in a failsafe, or missing).
    pub fn break_chain(&mut self) {
        self.prev = None;
        self.roll_filter = Prefilter::new();
        self.pitch_filter = Prefilter::new();
        self.speed_filter = Prefilter::new();
        self.path_filter = Prefilter::new();
    }

    /// Takes in the sample `dt_s` after the previous one. An interval that is not a positive
    /// finite number under 0.1 s, or a sample with a value that is not finite, starts a new
    /// stretch instead of making a rate.
    // Out of line: inlined into the vehicle's tick, the MCU image held two copies of it,
    // 1.9 KB each.
    #[inline(never)]
    pub fn push(&mut self, dt_s: f32, s: &Sample) {
        let finite = [
            s.p,
            s.q,
            s.r,
            s.ay,
            s.beta,
            s.air_speed,
            s.accel_y,
            s.phi,
            s.theta,
            s.airspeed,
            s.alpha,
            s.climb_rate,
            s.course,
            s.ground_speed,
            s.aileron,
            s.elevator,
            s.rudder,
            s.throttle,
        ]
        .iter()
        .all(|v| v.is_finite());
        if !finite {
            self.break_chain();
            return;
        }
        let Some(a) = self.prev.filter(|_| dt_s > 0.0 && dt_s <= MAX_INTERVAL_S) else {
            self.break_chain();
            self.prev = Some(*s);
            self.surfaces = [s.aileron, s.elevator, s.rudder];
            return;
        };
        // The servos move towards the command held since `a`, no faster than their rate
        // limit: over the interval each surface's mean is what the servo model gives.
        let [ail, ele, rud] = self.surfaces;
        let (ail_end, da) = servo(&self.config, ail, a.aileron, dt_s);
        let (ele_end, de) = servo(&self.config, ele, a.elevator, dt_s);
        let (rud_end, dr) = servo(&self.config, rud, a.rudder, dt_s);
        self.surfaces = [ail_end, ele_end, rud_end];
        let mid = |f: fn(&Sample) -> f32| 0.5 * (f(&a) + f(s));
        let va = mid(|x| x.airspeed);
        let v = va / self.config.airspeed_ref;
        let v2 = v * v;
        let rate = |f: fn(&Sample) -> f32| (f(s) - f(&a)) / dt_s;
        let (p, q, r) = (mid(|x| x.p), mid(|x| x.q), mid(|x| x.r));
        let (phi, theta, alpha) = (mid(|x| x.phi), mid(|x| x.theta), mid(|x| x.alpha));
        let (ay, thr) = (mid(|x| x.ay), a.throttle);
        let k = share(dt_s, self.config.attitude_filter_tau_s);
        // The pre-filters run on every row, so that a model's rows pick up where its filter
        // has followed the flight.
        let (sideslip, others) = self.rows;
        let (row, y) = self.roll_filter.pass(
            k,
            SVector::from([-v * p, v2 * da, v * r, ay, thr, v2]),
            rate(|x| x.p),
        );
        if others {
            self.roll.push(&row, y);
        }
        let vb = mid(|x| {
            if x.air_speed > 0.0 {
                x.air_speed
            } else {
                x.airspeed
            }
        }) / self.config.airspeed_ref;
        let force = self.config.airspeed_ref * vb * vb;
        if sideslip {
            self.sideslip.push(
                &SVector::from([
                    -force * mid(|x| x.beta),
                    force * dr,
                    vb * p,
                    vb * r,
                    vb * vb,
                ]),
                mid(|x| x.accel_y),
            );
        }
        let (row, y) = self.pitch_filter.pass(
            k,
            SVector::from([
                -v * q,
                -v2 * alpha,
                v2 * de,
                thr,
                v2,
                r,
                mid(|x| x.p * x.r),
                mid(|x| x.r * x.r - x.p * x.p),
            ]),
            rate(|x| x.q),
        );
        if others {
            self.pitch.push(&row, y);
        }
        let (row, y) = self.speed_filter.pass(
            share(dt_s, self.config.airspeed_filter_tau_s),
            SVector::from([
                -(va - self.config.airspeed_ref),
                thr,
                -theta,
                alpha,
                1.0,
                v2 * mid(|x| x.beta * x.beta),
            ]),
            rate(|x| x.airspeed),
        );
        if others {
            self.speed.push(&row, y);
        }
        let vg = mid(|x| x.ground_speed);
        if vg > 1.0 && others {
            self.course.push(
                &SVector::from([GRAVITY * crate::math::elementary::tan(phi) / vg, 1.0]),
                wrap_pi(s.course - a.course) / dt_s,
            );
        }
        if others {
            self.altitude
                .push(&SVector::from([va * theta, 1.0]), mid(|x| x.climb_rate));
        }
        // The lift that turns the flight path, `Va gamma' + g cos(gamma) = (qbar S / m) CL
        // cos(phi)`, with `CL = CL_0 + CL_alpha alpha` and the dynamic pressure as `v^2`: the
        // angle of attack's coefficient is `a_gamma Va_ref`, the rest a constant per `v^2`.
        // Through the attitude's pre-filter, as the pitch equation whose doublets excite it:
        // the rate is a difference of the climb rate. Written as `gamma' = a_gamma alpha + c`
        // instead, without the dynamic pressure and the bank, the 25e's fit explained R^2 0.48
        // of it; through the airspeed's slower filter the doublets' content went with the
        // noise (R^2 0.07 at 1 s).
        let [gamma_a, gamma_b] = [&a, s].map(|x| x.climb_rate / x.airspeed.max(1.0));
        if va > 1.0 {
            let gamma = 0.5 * (gamma_a + gamma_b);
            let lift = v2 * crate::math::elementary::cos(phi);
            let (row, y) = self.path_filter.pass(
                k,
                SVector::from([lift * self.config.airspeed_ref * alpha, lift]),
                va * (gamma_b - gamma_a) / dt_s + GRAVITY * crate::math::elementary::cos(gamma),
            );
            if others {
                self.flight_path.push(&row, y);
            }
        }
        let taken = [others, others, others, others, others, sideslip];
        for ((spread, x), taken) in self
            .inputs
            .iter_mut()
            .zip([da, de, thr, phi, theta, dr])
            .zip(taken)
        {
            if taken {
                spread.push(x);
            }
        }
        self.prev = Some(*s);
    }

    /// The fit of `axis` so far.
    pub fn fit(&self, axis: Axis) -> Result<AxisFit, AxisError> {
        let (input, needed) = axis.input();
        let spread = match axis {
            Axis::Roll => self.inputs[0],
            Axis::Pitch => self.inputs[1],
            Axis::Airspeed => self.inputs[2],
            Axis::Course => self.inputs[3],
            Axis::Altitude | Axis::FlightPath => self.inputs[4],
            Axis::Sideslip => self.inputs[5],
        };
        let sd = spread.sd();
        if sd.is_nan() || sd < needed {
            return Err(AxisError::NotExcited { input, sd, needed });
        }
        let fit = match axis {
            Axis::Roll => self.roll.solve().map(widen),
            Axis::Sideslip => self.sideslip.solve().map(widen),
            Axis::Pitch => self.pitch.solve().map(widen),
            Axis::Airspeed => self.speed.solve().map(widen),
            Axis::Course => self.course.solve().map(widen),
            Axis::Altitude => self.altitude.solve().map(widen),
            Axis::FlightPath => self.flight_path.solve().map(widen),
        };
        let (coef, std_err, r2, rows) = fit.ok_or(AxisError::Singular)?;
        Ok(AxisFit {
            coef,
            std_err,
            r2,
            rows,
            input_sd: sd,
        })
    }
}

/// A fit's figures in the fixed places of [`AxisFit`].
fn widen<const N: usize>(f: Fit<N>) -> ([f32; COEFS], [f32; COEFS], f32, u32) {
    let (mut coef, mut err) = ([0.0; COEFS], [0.0; COEFS]);
    for (i, (c, e)) in f.coef.iter().zip(f.std_err.iter()).enumerate().take(COEFS) {
        if let (Some(cs), Some(es)) = (coef.get_mut(i), err.get_mut(i)) {
            *cs = *c;
            *es = *e;
        }
    }
    (coef, err, f.r2, f.rows)
}
