//! Attitude, velocity, position, gyro bias and barometer offset: one error-state (multiplicative)
//! extended Kalman filter with the IMU as its process input, aided by GPS.
//!
//! Why one filter: an attitude filter that takes the accelerometer for gravity is wrong
//! whenever the aircraft accelerates in a way it cannot model, and a gust at 17 m/s on a
//! 2 kg aircraft is exactly that (light Dryden turbulence moves the specific force by
//! several m/s^2). Here the accelerometer is never a gravity measurement while GPS is
//! healthy: it is integrated into velocity, and a tilt error shows as a growing velocity
//! error (`g * tilt` per second) that the GPS velocity, good to 0.05 m/s, sees within a
//! fix or two. Gusts then cost nothing: the IMU measures the acceleration they cause.
//!
//! Nominal state: body-to-NED quaternion `q`, NED velocity `v`, NED position from home `p`,
//! gyro bias `b` and barometer offset `o` (baro altitude minus true altitude). Error state
//! (13): a small rotation `dtheta` in NED (`R_true = (I + [dtheta]x) R`, so the heading
//! error is the single component `dtheta.z`), `dv`, `dp`, `db`, `do`.
//!
//! - Propagation: `q <- q exp((w - b) dt)`, `v <- v + (R f + g) dt`, `p <- p + v dt`;
//!   `d(dtheta)' = -R db`, `dv' = -[R f]x dtheta`, `dp' = dv`.
//! - GPS position and velocity, delayed: innovations are formed against the state of the
//!   fix's time (a short history is kept) and the correction is applied to the present
//!   state and to the stored states after the fix (the error is nearly constant over the
//!   0.1-0.2 s of latency).
//! - Barometer: `home_alt - baro_alt = p_d - o`.
//! - Magnetometer: heading only (tilt-compensated with the estimated roll and pitch), so a
//!   field that does not match the model can never tilt the attitude.
//! - Gravity reference from the accelerometer: only while nothing else levels the filter
//!   (before the first fix, or GPS lost), with the centripetal acceleration of turns removed.
//! - Air-data velocity while GPS is lost keeps the horizontal velocity bounded.

// The filter's matrices are fixed-size (nalgebra's SMatrix) and indexed with the state
// layout's constants and loop indices below their dimension: no index comes from outside.
#![allow(clippy::indexing_slicing)]

use super::kalman::condition;
use crate::math::frames::Euler;
use nalgebra::{Matrix3, SMatrix, SVector, UnitQuaternion, Vector3};

mod fuse;
mod history;

/// Standard gravity, m/s^2.
pub use crate::math::GRAVITY;
/// States kept for the delayed GPS update (0.64 s at 100 Hz).
pub const HISTORY: usize = 64;
/// Size of the error state.
pub const N: usize = 13;

type Mat = SMatrix<f32, N, N>;
type Vecn = SVector<f32, N>;

const ITH: usize = 0;
const IV: usize = 3;
const IP: usize = 6;
const IBG: usize = 9;
const IBO: usize = 12;

/// Initial 1-sigma roll/pitch uncertainty (accelerometer levelling is good to a few deg).
const INIT_TILT_SIGMA: f32 = 0.1;
/// Initial 1-sigma heading uncertainty.
const INIT_YAW_SIGMA: f32 = 0.3;
/// Velocity uncertainty before the first fix, m/s (only attitude is meaningful then).
const UNAIDED_VEL_SIGMA: f32 = 30.0;
/// Position uncertainty before the first fix, m.
const UNAIDED_POS_SIGMA: f32 = 100.0;

/// The aircraft's motion as the gravity reference needs it: its acceleration is the
/// centripetal `rates x v_air_body` of a turn or pull-up plus `along_body`, the acceleration
/// along the flight path (airspeed changes).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Motion {
    /// Bias-corrected body rates, rad/s.
    pub rates: Vector3<f32>,
    /// Air-relative velocity in body axes, m/s.
    pub v_air_body: Vector3<f32>,
    /// Acceleration along the flight path in body axes, m/s^2.
    pub along_body: Vector3<f32>,
}

/// How one measurement (all its components) went.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Fusion {
    /// Components fused.
    pub fused: u8,
    /// Components refused by the innovation gate.
    pub gated: u8,
    /// Sum of the normalised innovations squared of the fused components.
    pub nis_sum: f32,
}

impl Fusion {
    /// Mean normalised innovation squared of the fused components (0 when none).
    pub fn nis(&self) -> f32 {
        if self.fused == 0 {
            0.0
        } else {
            self.nis_sum / f32::from(self.fused)
        }
    }
}

/// Noise settings of one GPS fix.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GpsNoise {
    /// Horizontal position, m.
    pub horizontal: f32,
    /// Vertical position, m.
    pub vertical: f32,
    /// Velocity per axis, m/s.
    pub velocity: f32,
    /// Uncertainty of the fix's latency, s (1 sigma).
    pub latency_sd: f32,
}

/// Process noise densities.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProcessNoise {
    /// Gyro white noise, rad/s/sqrt(Hz).
    pub gyro: f32,
    /// Gyro bias random walk, rad/s^2/sqrt(Hz).
    pub gyro_bias: f32,
    /// Accelerometer white noise (and unmodelled accelerometer error), m/s^2/sqrt(Hz).
    pub accel: f32,
    /// Barometer offset random walk, m/sqrt(s).
    pub baro_offset: f32,
}

/// One stored state: attitude, velocity and position at time `t_us`.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Snapshot {
    /// Estimator clock, µs.
    t_us: u64,
    q: UnitQuaternion<f32>,
    v: Vector3<f32>,
    p: Vector3<f32>,
}

impl Default for Snapshot {
    fn default() -> Self {
        Self {
            t_us: 0,
            q: UnitQuaternion::identity(),
            v: Vector3::zeros(),
            p: Vector3::zeros(),
        }
    }
}

/// The inertial navigation filter.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ins {
    q: UnitQuaternion<f32>,
    v: Vector3<f32>,
    p: Vector3<f32>,
    bias: Vector3<f32>,
    baro_offset: f32,
    cov: Mat,
    history: [Snapshot; HISTORY],
    head: usize,
    len: usize,
    /// Corrections of the fusions in progress, to be carried into the stored states once the
    /// measurement's components are all fused: from time `t_us` on, rotated by `q`, velocity
    /// moved by `v` and position by `p`.
    pending: Option<Snapshot>,
    attitude_ok: bool,
    nav_ok: bool,
}

impl Default for Ins {
    fn default() -> Self {
        Self::new()
    }
}

impl Ins {
    /// An uninitialised filter (level, north, zero bias, no position).
    /// Not inlined: see `Vehicle::fresh`.
    #[inline(never)]
    pub fn new() -> Self {
        Self {
            q: UnitQuaternion::identity(),
            v: Vector3::zeros(),
            p: Vector3::zeros(),
            bias: Vector3::zeros(),
            baro_offset: 0.0,
            cov: Mat::identity(),
            history: [Snapshot::default(); HISTORY],
            head: 0,
            len: 0,
            pending: None,
            attitude_ok: false,
            nav_ok: false,
        }
    }

    /// True once the attitude has been levelled and aligned ([`Ins::align`]).
    pub fn attitude_initialized(&self) -> bool {
        self.attitude_ok
    }

    /// True once a GPS fix has set position and velocity.
    pub fn nav_initialized(&self) -> bool {
        self.nav_ok
    }

    /// Body-to-NED attitude.
    pub fn attitude(&self) -> UnitQuaternion<f32> {
        self.q
    }

    /// Estimated gyro bias, rad/s.
    pub fn gyro_bias(&self) -> Vector3<f32> {
        self.bias
    }

    /// Velocity NED, m/s.
    pub fn velocity(&self) -> Vector3<f32> {
        self.v
    }

    /// Position NED from home, m.
    pub fn position(&self) -> Vector3<f32> {
        self.p
    }

    /// Barometer offset (baro altitude minus true altitude), m.
    pub fn baro_offset(&self) -> f32 {
        self.baro_offset
    }

    fn sigma(&self, i: usize) -> f32 {
        libm::sqrtf(self.cov[(i, i)])
    }

    /// 1-sigma roll/pitch (combined) and heading uncertainty, rad.
    pub fn tilt_heading_sigma(&self) -> (f32, f32) {
        (
            libm::sqrtf(self.cov[(ITH, ITH)] + self.cov[(ITH + 1, ITH + 1)]),
            self.sigma(ITH + 2),
        )
    }

    /// 1-sigma uncertainty of each gyro bias component, rad/s.
    pub fn bias_sigma(&self) -> Vector3<f32> {
        Vector3::new(self.sigma(IBG), self.sigma(IBG + 1), self.sigma(IBG + 2))
    }

    /// Whether the attitude, gyro-bias and navigation uncertainties are all within their
    /// 1-sigma bounds (rad, rad, rad/s, m, m/s): roll/pitch combined, heading, each bias axis,
    /// horizontal position and velocity (largest axis). Compared as variances, so without a
    /// square root (a software one on the MCU, asked several times a control period); a
    /// bound that is not positive is never met.
    pub fn sigmas_within(&self, tilt: f32, heading: f32, bias: f32, pos: f32, vel: f32) -> bool {
        let d = self.cov.diagonal();
        let within = |var: f32, bound: f32| bound > 0.0 && var < bound * bound;
        within(d[ITH] + d[ITH + 1], tilt)
            && within(d[ITH + 2], heading)
            && within(d[IBG].max(d[IBG + 1]).max(d[IBG + 2]), bias)
            && within(d[IP].max(d[IP + 1]), pos)
            && within(d[IV].max(d[IV + 1]).max(d[IV + 2]), vel)
    }

    /// The filter's states for the flight log, in PX4's order (attitude quaternion w x y z,
    /// velocity NED, position NED, gyro bias, the barometer's offset), and the variances of
    /// its error state in the filter's own order (attitude error, velocity, position, gyro
    /// bias, the barometer's offset).
    pub fn states_and_variances(&self) -> ([f32; N + 1], [f32; N]) {
        let q = self.q.quaternion();
        let mut x = [0.0; N + 1];
        x[0] = q.w;
        x[1] = q.i;
        x[2] = q.j;
        x[3] = q.k;
        for k in 0..3 {
            x[4 + k] = self.v[k];
            x[7 + k] = self.p[k];
            x[10 + k] = self.bias[k];
        }
        x[N] = self.baro_offset;
        let d = self.cov.diagonal();
        let mut var = [0.0; N];
        for (v, dk) in var.iter_mut().zip(d.iter()) {
            *v = *dk;
        }
        (x, var)
    }

    /// 1-sigma horizontal position, vertical position and velocity (largest axis) uncertainty.
    pub fn nav_sigmas(&self) -> (f32, f32, f32) {
        let d = self.cov.diagonal();
        (
            libm::sqrtf(d[IP].max(d[IP + 1])),
            libm::sqrtf(d[IP + 2]),
            libm::sqrtf(d[IV].max(d[IV + 1]).max(d[IV + 2])),
        )
    }

    /// Levels from the specific force `gravity` (the accelerometer with any known acceleration
    /// removed) and takes the heading from the magnetometer against the earth field
    /// `earth_ned`. Returns false, and changes nothing, when the vectors are too short to
    /// define an attitude. Velocity and position keep their values; their correlation with
    /// the old attitude is dropped.
    pub fn align(
        &mut self,
        gravity: &Vector3<f32>,
        mag: &Vector3<f32>,
        earth_ned: &Vector3<f32>,
        bias_sigma: f32,
    ) -> bool {
        let horizontal_earth = crate::math::elementary::hypot(earth_ned.x, earth_ned.y);
        if gravity.norm() < 0.5 * GRAVITY || mag.norm() < 1e-3 || horizontal_earth < 1e-3 {
            return false;
        }
        // In steady flight or at rest the accelerometer reads -g rotated into the body.
        let phi = libm::atan2f(-gravity.y, -gravity.z);
        let theta = libm::atan2f(
            gravity.x,
            crate::math::elementary::hypot(gravity.y, gravity.z),
        );
        let Some(psi) = mag_heading(phi, theta, mag, earth_ned) else {
            return false;
        };
        let q = Euler::new(phi, theta, psi).to_quaternion();
        if !q.coords.iter().all(|c| c.is_finite()) {
            return false;
        }
        self.q = q;
        self.bias = Vector3::zeros();
        self.reset_attitude_covariance(bias_sigma, false);
        if !self.nav_ok {
            self.reset_nav_covariance(
                UNAIDED_POS_SIGMA,
                UNAIDED_POS_SIGMA,
                UNAIDED_VEL_SIGMA,
                UNAIDED_POS_SIGMA,
            );
        }
        self.attitude_ok = true;
        true
    }

    /// Raises the attitude and gyro-bias uncertainty back to their initial values (never
    /// lowering one) and forgets their correlations: what the gravity reference taught the
    /// filter before GPS (or during an outage) is a coarse alignment, made under assumptions
    /// about the aircraft's motion, and GPS velocity should be free to overrule it.
    pub fn reopen_attitude(&mut self, bias_sigma: f32) {
        self.reset_attitude_covariance(bias_sigma, true);
    }

    fn reset_attitude_covariance(&mut self, bias_sigma: f32, keep_larger: bool) {
        let t = INIT_TILT_SIGMA * INIT_TILT_SIGMA;
        let b = bias_sigma * bias_sigma;
        let initial = [t, t, INIT_YAW_SIGMA * INIT_YAW_SIGMA, b, b, b];
        let states = [ITH, ITH + 1, ITH + 2, IBG, IBG + 1, IBG + 2];
        // Checked element access: the loop over the states is not unrolled in the size-optimised
        // MCU image, so indexing would leave panic paths (tests/tests/panic_sites.rs).
        for (k, init) in states.into_iter().zip(initial) {
            let d = match self.cov.get((k, k)) {
                Some(&v) if keep_larger => v.max(init),
                _ => init,
            };
            for i in 0..N {
                for ij in [(i, k), (k, i)] {
                    if let Some(v) = self.cov.get_mut(ij) {
                        *v = 0.0;
                    }
                }
            }
            if let Some(v) = self.cov.get_mut((k, k)) {
                *v = d;
            }
        }
    }

    /// Starts navigation from a GPS fix taken `delay` s ago: position `pos` (NED from home),
    /// velocity `vel`, barometer offset `baro_offset` (0 without a barometer reading).
    pub fn start_nav(
        &mut self,
        t_us: u64,
        pos: &Vector3<f32>,
        vel: &Vector3<f32>,
        delay: f32,
        baro_offset: f32,
        noise: &GpsNoise,
    ) {
        self.p = pos + vel * delay;
        self.v = *vel;
        self.baro_offset = baro_offset;
        let vel_sigma = noise.velocity.max(0.5);
        self.reset_nav_covariance(
            noise.horizontal,
            noise.vertical,
            vel_sigma,
            libm::sqrtf(noise.vertical * noise.vertical + 1.0),
        );
        self.len = 0;
        self.head = 0;
        self.nav_ok = true;
        self.remember(t_us);
    }

    /// Sets the velocity, position and baro-offset variances and drops their correlations.
    fn reset_nav_covariance(&mut self, horizontal: f32, vertical: f32, vel: f32, offset: f32) {
        for k in IV..IBG {
            for i in 0..N {
                self.cov[(i, k)] = 0.0;
                self.cov[(k, i)] = 0.0;
            }
        }
        for i in 0..N {
            self.cov[(i, IBO)] = 0.0;
            self.cov[(IBO, i)] = 0.0;
        }
        let v2 = vel * vel;
        let h2 = horizontal * horizontal;
        for k in 0..3 {
            self.cov[(IV + k, IV + k)] = v2;
        }
        self.cov[(IP, IP)] = h2;
        self.cov[(IP + 1, IP + 1)] = h2;
        self.cov[(IP + 2, IP + 2)] = vertical * vertical;
        self.cov[(IBO, IBO)] = offset * offset;
    }

    /// Propagates the state and covariance over `dt` ending at time `t_us` (µs) with one IMU sample
    /// (specific force `accel`, m/s^2, and rates `gyro`, rad/s, both body axes). Not inlined:
    /// the prediction stays a function of its own in the MCU image's profile (one call a
    /// sensor frame).
    #[inline(never)]
    pub fn predict(
        &mut self,
        t_us: u64,
        accel: &Vector3<f32>,
        gyro: &Vector3<f32>,
        dt: f32,
        noise: &ProcessNoise,
    ) {
        if !self.attitude_ok {
            return;
        }
        let r = self.q.to_rotation_matrix().into_inner();
        let f_ned = r * accel;
        let a = f_ned + Vector3::new(0.0, 0.0, GRAVITY);
        let omega = gyro - self.bias;
        let q = self.q * crate::math::rotation_from_vector(&(omega * dt));
        let (v, p) = if self.nav_ok {
            (self.v + a * dt, self.p + self.v * dt + a * (0.5 * dt * dt))
        } else {
            (self.v, self.p)
        };
        // The transition is the identity plus four 3x3 blocks; with the position and velocity
        // blocks only once navigation runs.
        let rdt = -r * dt;
        let fx = f_ned.cross_matrix();
        let (fdt, fdt2) = (-fx * dt, -fx * (0.5 * dt * dt));
        let idt = Matrix3::identity() * dt;
        let all = [
            (ITH, IBG, &rdt),
            (IV, ITH, &fdt),
            (IP, ITH, &fdt2),
            (IP, IV, &idt),
        ];
        let blocks = if self.nav_ok { &all[..] } else { &all[..1] };
        // The covariance is propagated in place, a copy kept only to fall back on: a refused
        // step leaves the state and the covariance as they were (one copy of the matrix per
        // step rather than three).
        if let Some(state) = self.checked_state(q, v, p, self.bias, self.baro_offset) {
            let before = self.cov;
            if self.propagate_covariance(blocks, dt, noise) {
                self.set_state(state);
            } else {
                self.cov = before;
            }
        }
        if self.nav_ok {
            self.remember(t_us);
        }
    }

    /// Propagates the covariance over `dt` through the transition's `blocks` with the process
    /// noise, and conditions it. False when the result is not finite (the covariance is then
    /// left half-done: the caller restores it).
    fn propagate_covariance(
        &mut self,
        blocks: &[(usize, usize, &Matrix3<f32>)],
        dt: f32,
        noise: &ProcessNoise,
    ) -> bool {
        let cov = &mut self.cov;
        propagate(cov, blocks);
        let g = noise.gyro * noise.gyro * dt;
        let qa = noise.accel * noise.accel * dt;
        let b = noise.gyro_bias * noise.gyro_bias * dt;
        for k in 0..3 {
            cov[(ITH + k, ITH + k)] += g;
            cov[(IBG + k, IBG + k)] += b;
            if self.nav_ok {
                // Integrated white acceleration: the exact discrete covariance of (p, v).
                cov[(IV + k, IV + k)] += qa;
                cov[(IP + k, IP + k)] += qa * dt * dt / 3.0;
                cov[(IP + k, IV + k)] += qa * dt / 2.0;
                cov[(IV + k, IP + k)] += qa * dt / 2.0;
            }
        }
        cov[(IBO, IBO)] += noise.baro_offset * noise.baro_offset * dt;
        condition(cov, MIN_VAR, MAX_VAR)
    }

    /// Moves position and velocity to a GPS fix taken `delay` s ago (after a long outage or a
    /// lock-out the filter may have drifted beyond its gate). The attitude and gyro-bias
    /// uncertainty is raised back to its initial value (`bias_sigma` for the bias), so an
    /// attitude error that caused the drift is learned again rather than believed.
    pub fn reset_to_gps(
        &mut self,
        pos: &Vector3<f32>,
        vel: &Vector3<f32>,
        delay: f32,
        noise: &GpsNoise,
        bias_sigma: f32,
    ) {
        let now = pos + vel * delay;
        let (dp, dv) = (now - self.p, vel - self.v);
        if !(dp.iter().all(|c| c.is_finite()) && dv.iter().all(|c| c.is_finite())) {
            return;
        }
        self.p = now;
        self.v = *vel;
        self.shift_stored(0, &UnitQuaternion::identity(), &dv, &dp);
        let offset = libm::sqrtf(self.cov[(IBO, IBO)] + noise.vertical * noise.vertical);
        self.reset_nav_covariance(
            noise.horizontal,
            noise.vertical,
            noise.velocity.max(0.5),
            offset,
        );
        self.reopen_attitude(bias_sigma);
    }

    /// Moves the NED origin: every position (present and stored) shifts by `delta`, m.
    pub fn shift_origin(&mut self, delta: &Vector3<f32>) {
        if !delta.iter().all(|c| c.is_finite()) {
            return;
        }
        self.p += delta;
        self.shift_stored(0, &UnitQuaternion::identity(), &Vector3::zeros(), delta);
    }

    /// Makes the baro offset agree with one barometric altitude (`home_alt - baro_alt`) after
    /// a lock-out, with its uncertainty back to the vertical position's.
    pub fn reset_baro_offset(&mut self, home_minus_baro: f32) {
        let b = self.p.z - home_minus_baro;
        if !b.is_finite() {
            return;
        }
        self.baro_offset = b;
        for i in 0..N {
            self.cov[(i, IBO)] = 0.0;
            self.cov[(IBO, i)] = 0.0;
        }
        self.cov[(IBO, IBO)] = self.cov[(IP + 2, IP + 2)] + 1.0;
    }

    /// The state with its quaternion normalised, if everything in it is finite.
    fn checked_state(
        &self,
        q: UnitQuaternion<f32>,
        v: Vector3<f32>,
        p: Vector3<f32>,
        bias: Vector3<f32>,
        baro_offset: f32,
    ) -> Option<State> {
        let q = UnitQuaternion::new_normalize(q.into_inner());
        let finite = q.coords.iter().all(|c| c.is_finite())
            && v.iter().all(|c| c.is_finite())
            && p.iter().all(|c| c.is_finite())
            && bias.iter().all(|c| c.is_finite())
            && baro_offset.is_finite();
        finite.then_some(State {
            q,
            v,
            p,
            bias,
            baro_offset,
        })
    }

    fn set_state(&mut self, s: State) {
        self.q = s.q;
        self.v = s.v;
        self.p = s.p;
        self.bias = s.bias;
        self.baro_offset = s.baro_offset;
    }
}

/// A whole state, checked finite (see `Ins::checked_state`).
struct State {
    q: UnitQuaternion<f32>,
    v: Vector3<f32>,
    p: Vector3<f32>,
    bias: Vector3<f32>,
    baro_offset: f32,
}

/// Bounds of the covariance's diagonal, kept by every commit.
const MIN_VAR: f32 = 1e-12;
const MAX_VAR: f32 = 1e8;

type Gain = super::kalman::Gain<N>;

/// `P <- phi P phi'` in place, for `phi = I + A` where `A` is zero but for the 3x3 `blocks`
/// `(row, column, block)`, none on the diagonal, listed so that no block's column range is
/// the row range of a block listed after it. `phi P` changes only the rows of the blocks
/// (27 products per block and column instead of a dense 13x13x13 product), `(phi P) phi'`
/// only their columns; the blocks are taken last first, so each reads rows (then columns)
/// not yet changed and no copy of the matrix is made. The caller's conditioning makes the
/// result exactly symmetric.
fn propagate(p: &mut Mat, blocks: &[(usize, usize, &Matrix3<f32>)]) {
    // The columns of `p` as arrays, and the block offsets' ranges taken with `get`: the
    // offsets are the filter's own constants, but the image carries no panic path for them
    // (tests/tests/panic_sites.rs). Plain loops over arrays: as fast optimised for size as
    // for speed (no unrolling needed to drop nalgebra's checked 2-D indexing).
    let cols = &mut p.data.0;
    for &(row, col, b) in blocks.iter().rev() {
        let bt = b.transpose();
        for c in cols.iter_mut() {
            let Some(&[x0, x1, x2]) = c.get(col..col + 3) else {
                continue;
            };
            let y = mul3(&bt, [x0, x1, x2]);
            if let Some([d0, d1, d2]) = c.get_mut(row..row + 3) {
                *d0 += y[0];
                *d1 += y[1];
                *d2 += y[2];
            }
        }
    }
    for &(row, col, b) in blocks.iter().rev() {
        let bt = b.transpose();
        let Some(&[s0, s1, s2]) = cols.get(col..col + 3) else {
            continue;
        };
        let Some([d0, d1, d2]) = cols.get_mut(row..row + 3) else {
            continue;
        };
        for r in 0..N {
            let y = mul3(&bt, [s0[r], s1[r], s2[r]]);
            d0[r] += y[0];
            d1[r] += y[1];
            d2[r] += y[2];
        }
    }
}

/// `b x` given `bt`, the transpose of `b` (its rows as arrays), with nalgebra's order of
/// operations for a 3x3 matrix times a vector (the columns of `b` weighted and accumulated
/// left to right), so the result is the same to the bit.
#[inline(always)]
fn mul3(bt: &Matrix3<f32>, x: [f32; 3]) -> [f32; 3] {
    let [r0, r1, r2] = &bt.data.0;
    [
        r0[0] * x[0] + r0[1] * x[1] + r0[2] * x[2],
        r1[0] * x[0] + r1[1] * x[1] + r1[2] * x[2],
        r2[0] * x[0] + r2[1] * x[1] + r2[2] * x[2],
    ]
}

/// Heading from a magnetometer sample levelled with roll `phi` and pitch `theta`, against the
/// earth field `earth_ned` (so the declination is included). None for a degenerate field.
pub fn mag_heading(
    phi: f32,
    theta: f32,
    mag: &Vector3<f32>,
    earth_ned: &Vector3<f32>,
) -> Option<f32> {
    let tilt = Euler::new(phi, theta, 0.0).to_quaternion();
    let m_level = tilt.transform_vector(mag);
    if crate::math::elementary::hypot(m_level.x, m_level.y) < 1e-4 {
        return None;
    }
    let psi = libm::atan2f(earth_ned.y, earth_ned.x) - libm::atan2f(m_level.y, m_level.x);
    let psi = crate::math::wrap_pi(psi);
    psi.is_finite().then_some(psi)
}

#[cfg(test)]
mod tests {
    use super::*;

    const EARTH: Vector3<f32> = Vector3::new(0.18, -0.01, 0.52);

    fn noise() -> ProcessNoise {
        ProcessNoise {
            gyro: 0.0015,
            gyro_bias: 5e-5,
            accel: 0.2,
            baro_offset: 0.01,
        }
    }

    fn gps() -> GpsNoise {
        GpsNoise {
            horizontal: 1.5,
            vertical: 5.5,
            velocity: 0.05,
            latency_sd: 0.0,
        }
    }

    #[test]
    fn aligns_from_gravity_and_field() {
        let truth = Euler::new(0.2_f32, -0.1, 2.0);
        let q = truth.to_quaternion();
        let accel = q.inverse_transform_vector(&Vector3::new(0.0, 0.0, -GRAVITY));
        let mag = q.inverse_transform_vector(&EARTH);
        let mut f = Ins::new();
        assert!(!f.align(&Vector3::zeros(), &mag, &EARTH, 0.05));
        assert!(f.align(&accel, &mag, &EARTH, 0.05));
        let e = Euler::from_quaternion(&f.attitude());
        assert!((e.phi - 0.2).abs() < 1e-4);
        assert!((e.theta + 0.1).abs() < 1e-4);
        assert!((e.psi - 2.0).abs() < 1e-4);
    }

    /// Straight flight north at 17 m/s with a vertical specific force that jumps by +-4 m/s^2
    /// every half second (a gusty ride): the filter starts 8 deg off in roll and 6 deg in
    /// pitch and must level itself from GPS velocity alone, the accelerometer never being
    /// taken for gravity.
    #[test]
    fn gps_velocity_levels_a_tilted_start_in_gusts() {
        let mut f = Ins::new();
        let level_accel = Vector3::new(0.0, 0.0, -GRAVITY);
        let mag = EARTH;
        assert!(f.align(&level_accel, &mag, &EARTH, 0.01));
        f.q = Euler::new(0.14_f32, 0.10, 0.0).to_quaternion();
        let vel = Vector3::new(17.0, 0.0, 0.0);
        f.start_nav(0, &Vector3::zeros(), &vel, 0.0, 0.0, &gps());
        let dt = 0.01;
        let mut v_true = vel;
        let mut p_true = Vector3::zeros();
        for k in 1..=3000_u16 {
            let t = u64::from(k) * 10_000;
            // Gust load: the true specific force and the true vertical acceleration agree.
            let gust = if (k / 50) % 2 == 0 { 4.0 } else { -4.0 };
            let accel = Vector3::new(0.0, 0.0, -GRAVITY - gust);
            v_true.z += -gust * dt;
            p_true += v_true * dt;
            f.predict(t, &accel, &Vector3::zeros(), dt, &noise());
            if k % 20 == 0 {
                f.fuse_gps(t, &p_true, &v_true, &gps(), 5.0);
                f.fuse_mag_heading(t, &mag, &EARTH, 0.02, 5.0);
            }
        }
        let e = Euler::from_quaternion(&f.attitude());
        assert!(e.phi.abs() < 0.005, "roll {}", e.phi);
        assert!(e.theta.abs() < 0.005, "pitch {}", e.theta);
        assert!(e.psi.abs() < 0.01, "heading {}", e.psi);
        // Confident enough to pass the default convergence threshold (EST_CONV_TILT).
        let (tilt, _) = f.tilt_heading_sigma();
        assert!(tilt < 0.0175, "tilt sigma {tilt}");
    }

    /// The convergence bounds, compared as variances, say what the 1-sigma figures say:
    /// each bound is met just above its sigma and missed just below, and a bound that is not
    /// positive is never met.
    #[test]
    fn the_convergence_bounds_say_what_the_sigmas_say() {
        let f = Ins::new();
        let (tilt, heading) = f.tilt_heading_sigma();
        let bias = f.bias_sigma().max();
        let (pos, _, vel) = f.nav_sigmas();
        let all = [tilt, heading, bias, pos, vel];
        let above = all.map(|x| x * 1.001);
        assert!(f.sigmas_within(above[0], above[1], above[2], above[3], above[4]));
        for i in 0..5 {
            let mut b = above;
            b[i] = all[i] * 0.999;
            assert!(!f.sigmas_within(b[0], b[1], b[2], b[3], b[4]), "bound {i}");
            b[i] = 0.0;
            assert!(
                !f.sigmas_within(b[0], b[1], b[2], b[3], b[4]),
                "bound {i} at 0"
            );
            b[i] = -1e9;
            assert!(
                !f.sigmas_within(b[0], b[1], b[2], b[3], b[4]),
                "bound {i} negative"
            );
        }
    }

    #[test]
    fn heading_fusion_corrects_heading_and_keeps_a_good_tilt() {
        let mut f = Ins::new();
        let accel = Vector3::new(0.0, 0.0, -GRAVITY);
        let truth = Euler::new(0.0_f32, 0.0, 0.5).to_quaternion();
        let mag = truth.inverse_transform_vector(&EARTH);
        assert!(f.align(&accel, &EARTH, &EARTH, 0.01));
        for k in 0..500_u16 {
            let t = u64::from(k) * 20_000;
            f.predict(t, &accel, &Vector3::zeros(), 0.02, &noise());
            // At rest, the accelerometer holds the tilt while the heading is corrected.
            f.fuse_gravity(t, &accel, &Motion::default(), 0.7, 2.5, 100.0);
            f.fuse_mag_heading(t, &mag, &EARTH, 0.02, 1e3);
        }
        let e = Euler::from_quaternion(&f.attitude());
        assert!(e.phi.abs() < 1e-3 && e.theta.abs() < 1e-3, "{e:?}");
        assert!((e.psi - 0.5).abs() < 0.01, "{e:?}");
    }

    #[test]
    fn gravity_reference_corrects_a_roll_error_without_gps() {
        let accel = Vector3::new(0.0, 0.0, -GRAVITY);
        let mut f = Ins::new();
        assert!(f.align(&accel, &EARTH, &EARTH, 0.05));
        f.q = Euler::new(0.087_f32, 0.0, 0.0).to_quaternion();
        for k in 0..500_u16 {
            let t = u64::from(k) * 20_000;
            f.predict(t, &accel, &Vector3::zeros(), 0.02, &noise());
            f.fuse_gravity(t, &accel, &Motion::default(), 0.7, 2.5, 100.0);
        }
        let e = Euler::from_quaternion(&f.attitude());
        assert!(e.phi.abs() < 0.005, "roll {}", e.phi);
    }

    #[test]
    fn the_structured_propagation_equals_the_dense_product() {
        // A full covariance and the transition of a flight with navigation on: the dense
        // textbook product, in f64, is the reference.
        let a = SMatrix::<f64, N, N>::from_fn(|i, j| ((i * 5 + j * 11) % 7) as f64 * 0.2 - 0.6);
        let p64 = a * a.transpose() + SMatrix::<f64, N, N>::identity();
        let dt = 0.01_f32;
        let r = UnitQuaternion::from_euler_angles(0.3_f32, -0.2, 1.1)
            .to_rotation_matrix()
            .into_inner();
        let fx = Vector3::new(1.5_f32, -0.7, -9.9).cross_matrix();
        let (rdt, fdt, fdt2) = (-r * dt, -fx * dt, -fx * (0.5 * dt * dt));
        let idt = Matrix3::identity() * dt;
        let blocks = [
            (ITH, IBG, &rdt),
            (IV, ITH, &fdt),
            (IP, ITH, &fdt2),
            (IP, IV, &idt),
        ];
        let mut phi = SMatrix::<f64, N, N>::identity();
        for &(row, col, b) in &blocks {
            phi.fixed_view_mut::<3, 3>(row, col)
                .copy_from(&b.cast::<f64>());
        }
        let dense = phi * p64 * phi.transpose();
        let mut got = p64.cast::<f32>();
        // To the bit what nalgebra's 3x3 products of the same blocks give, in the same order
        // (rows first, then columns, the blocks taken last first).
        let mut by_blocks = got;
        for &(row, col, b) in blocks.iter().rev() {
            for c in 0..N {
                let y = b * by_blocks.fixed_view::<3, 1>(col, c);
                let mut d = by_blocks.fixed_view_mut::<3, 1>(row, c);
                d += y;
            }
        }
        for &(row, col, b) in blocks.iter().rev() {
            for r in 0..N {
                let y = b * by_blocks.fixed_view::<1, 3>(r, col).transpose();
                let mut d = by_blocks.fixed_view_mut::<1, 3>(r, row);
                d += y.transpose();
            }
        }
        propagate(&mut got, &blocks);
        for (a, b) in got.iter().zip(by_blocks.iter()) {
            assert_eq!(a.to_bits(), b.to_bits());
        }
        assert!(condition(&mut got, 0.0, f32::INFINITY));
        for i in 0..N {
            for j in 0..N {
                let tol = 1e-5 * dense[(i, j)].abs().max(1.0);
                assert!(
                    (f64::from(got[(i, j)]) - dense[(i, j)]).abs() < tol,
                    "({i}, {j})"
                );
                assert_eq!(got[(i, j)], got[(j, i)]);
            }
        }
    }
}
