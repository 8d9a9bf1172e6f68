//! The two filters of the thesis's autopilot, discretised exactly (zero-order hold) for the `dt`
//! of each step.
//!
//! - [`LowPass`]: `a / (s + a)` on the altitude and airspeed feedback, pole `a = 2 rad/s`
//!   (Appendix E: `LP_filter = [0 0.0392; 1 -0.9608]` at 50 Hz).
//! - [`Washout`]: `s / (s + a)` on the yaw rate of the yaw damper, `a = 2 rad/s` (Appendix D:
//!   `zpk(0, -2, 0.065)` then `c2d(.., SampleTime)`, MATLAB's default zero-order hold).
//!
//! - [`RateEstimator`]: a value and its rate from samples of the value alone (the total energy
//!   control's climb rate and airspeed rate), not a thesis filter.
//!
//! Zero-order hold is what MATLAB's `c2d` did for the thesis, and it makes each filter's step
//! response equal to the continuous one at every sample. Both filters start from their first
//! input (the low-pass outputs it, the washout outputs zero), so engaging a loop in flight does
//! not produce a transient from an arbitrary initial state.

/// `(p, 1 - p)` with `p = exp(-pole * dt)`: the zero-order-hold coefficients of `pole / (s + pole)`,
/// `y[k+1] = p y[k] + (1 - p) u[k]`. At `pole = 2 rad/s`, `dt = 0.02 s`: `(0.9608, 0.0392)`.
pub fn low_pass_coefficients(pole: f32, dt: f32) -> (f32, f32) {
    let p = libm::expf(-pole * dt);
    (p, 1.0 - p)
}

fn valid(pole: f32, dt: f32, u: f32) -> bool {
    pole.is_finite() && pole > 0.0 && dt.is_finite() && dt > 0.0 && u.is_finite()
}

/// First-order low-pass `pole / (s + pole)`, zero-order hold: `y[k+1] = p y[k] + (1 - p) u[k]`.
///
/// [`LowPass::step`] returns `y[k]` (which depends on inputs up to `u[k-1]`, as the thesis's
/// strictly proper `0.0392 / (z - 0.9608)` does) and advances the state with `u[k]`.
#[derive(Clone, Copy, Debug)]
pub struct LowPass {
    pole: f32,
    coeff_dt: f32,
    p: f32,
    y: Option<f32>,
}

impl LowPass {
    /// A filter with its pole at `pole` rad/s, empty until its first input.
    pub fn new(pole: f32) -> Self {
        Self {
            pole,
            coeff_dt: f32::NAN,
            p: 0.0,
            y: None,
        }
    }

    /// Moves the pole (rad/s); the state is kept.
    pub fn set_pole(&mut self, pole: f32) {
        self.pole = pole;
        self.coeff_dt = f32::NAN;
    }

    /// Forgets the state; the next input initialises it.
    pub fn reset(&mut self) {
        self.y = None;
    }

    /// The current output `y[k]`, `None` before the first input.
    pub fn output(&self) -> Option<f32> {
        self.y
    }

    /// Feeds `u[k]`, returns `y[k]`. The first input initialises the filter to itself. A
    /// non-finite input, pole or `dt` leaves the state alone and returns the current output
    /// (`None` only if the filter has never had a good input).
    pub fn step(&mut self, u: f32, dt: f32) -> Option<f32> {
        if !valid(self.pole, dt, u) {
            return self.y;
        }
        // exp() once per distinct dt: the loop runs at a fixed rate, so this is nearly free.
        if dt != self.coeff_dt {
            self.p = low_pass_coefficients(self.pole, dt).0;
            self.coeff_dt = dt;
        }
        let y = self.y.unwrap_or(u);
        self.y = Some(self.p * y + (1.0 - self.p) * u);
        Some(y)
    }
}

/// Washout (high-pass) `s / (s + pole)`, zero-order hold: `G(z) = (z - 1) / (z - p)`,
/// `y[k] = p y[k-1] + u[k] - u[k-1]`, `p = exp(-pole dt)`. DC gain 0; a step passes with gain 1
/// at its first sample and then decays as `exp(-pole t)`.
#[derive(Clone, Copy, Debug)]
pub struct Washout {
    pole: f32,
    coeff_dt: f32,
    p: f32,
    prev_u: Option<f32>,
    y: f32,
}

impl Washout {
    /// A washout with its pole at `pole` rad/s.
    pub fn new(pole: f32) -> Self {
        Self {
            pole,
            coeff_dt: f32::NAN,
            p: 0.0,
            prev_u: None,
            y: 0.0,
        }
    }

    /// Moves the pole (rad/s); the state is kept.
    pub fn set_pole(&mut self, pole: f32) {
        self.pole = pole;
        self.coeff_dt = f32::NAN;
    }

    /// Forgets the state; the next input is taken as the steady value (output 0).
    pub fn reset(&mut self) {
        self.prev_u = None;
        self.y = 0.0;
    }

    /// Feeds `u[k]`, returns `y[k]`. A non-finite input, pole or `dt` leaves the state alone and
    /// returns the last output.
    pub fn step(&mut self, u: f32, dt: f32) -> f32 {
        if !valid(self.pole, dt, u) {
            return self.y;
        }
        if dt != self.coeff_dt {
            self.p = low_pass_coefficients(self.pole, dt).0;
            self.coeff_dt = dt;
        }
        let prev = self.prev_u.unwrap_or(u);
        self.y = self.p * self.y + u - prev;
        self.prev_u = Some(u);
        self.y
    }
}

/// A value and its rate of change from noisy samples of the value: the observer
/// `x' = r + 2 w (u - x)`, `r' = w^2 (u - x)` (both poles at `-w`), one Euler step per sample.
///
/// Why not a differenced low-pass: the observer's rate has no lag against a ramp in steady
/// state (a ramp is what a climb or an acceleration is), and its noise falls off as `1/s`
/// above `w` where a filtered difference only flattens. From the value alone, the rate's
/// transfer is `s w^2 / (s^2 + 2 w s + w^2)` (a differentiator with a critically damped
/// second-order roll-off): at `w / 3` it lags the true rate by 37 deg.
#[derive(Clone, Copy, Debug)]
pub struct RateEstimator {
    w: f32,
    state: Option<(f32, f32)>,
}

impl RateEstimator {
    /// An estimator with both poles at `w` rad/s, empty until its first sample.
    pub fn new(w: f32) -> Self {
        Self { w, state: None }
    }

    /// Moves the poles (rad/s); the state is kept.
    pub fn set_pole(&mut self, w: f32) {
        self.w = w;
    }

    /// Forgets the state; the next sample initialises it at rest.
    pub fn reset(&mut self) {
        self.state = None;
    }

    /// The present value and rate, `None` before the first good sample.
    pub fn output(&self) -> Option<(f32, f32)> {
        self.state
    }

    /// Feeds sample `u`, returns `(value, rate)`. The first sample initialises the value to
    /// itself with zero rate. A non-finite sample, pole or `dt`, or a `w dt` at which the Euler
    /// step would be unstable (above 1), leaves the state alone.
    pub fn step(&mut self, u: f32, dt: f32) -> Option<(f32, f32)> {
        if !valid(self.w, dt, u) || self.w * dt > 1.0 {
            return self.state;
        }
        let (mut x, mut r) = self.state.unwrap_or((u, 0.0));
        x += r * dt;
        let e = u - x;
        x += 2.0 * self.w * dt * e;
        r += self.w * self.w * dt * e;
        self.state = Some((x, r));
        self.state
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn thesis_coefficients_at_50_hz() {
        let (a, b) = low_pass_coefficients(2.0, 0.02);
        // Appendix E: LP_filter = [0 0.0392; 1 -0.9608].
        assert!((a - 0.9608).abs() < 5e-5, "{a}");
        assert!((b - 0.0392).abs() < 5e-5, "{b}");
        assert!((a + b - 1.0).abs() < 1e-7, "unity DC gain");
    }

    #[test]
    fn low_pass_matches_continuous_step_at_samples() {
        let mut f = LowPass::new(2.0);
        assert_eq!(f.step(0.0, 0.02), Some(0.0));
        for k in 1..200 {
            let y = f.step(1.0, 0.02).unwrap();
            let t = (k - 1) as f32 * 0.02;
            assert!(
                (y - (1.0 - libm::expf(-2.0 * t))).abs() < 1e-5,
                "k={k} y={y}"
            );
        }
        // First input initialises: no transient when engaged at 100 m.
        let mut g = LowPass::new(2.0);
        assert_eq!(g.step(100.0, 0.02), Some(100.0));
        assert_eq!(g.step(100.0, 0.02), Some(100.0));
        // Bad input: state kept.
        assert_eq!(g.step(f32::NAN, 0.02), Some(100.0));
        assert_eq!(LowPass::new(2.0).step(f32::INFINITY, 0.02), None);
    }

    #[test]
    fn washout_dc_gain_zero_high_frequency_gain_one() {
        let dt = 0.02;
        let p = libm::expf(-2.0 * dt);
        let mut w = Washout::new(2.0);
        assert_eq!(w.step(0.0, dt), 0.0);
        // Step: passes with gain 1 at once, then decays as exp(-2 t) (the continuous response).
        for k in 0..500 {
            let y = w.step(1.0, dt);
            let t = k as f32 * dt;
            assert!((y - libm::expf(-2.0 * t)).abs() < 1e-5, "k={k} y={y}");
        }
        // DC gain 0: after 10 s of a constant input nothing is left.
        assert!(w.step(1.0, dt).abs() < 1e-4);

        // Sinusoid well above the pole (20 rad/s, 10x): gain |jw/(jw+2)| = 0.995.
        let mut w = Washout::new(2.0);
        let mut amp = 0.0f32;
        for k in 0..2000 {
            let t = k as f32 * dt;
            let y = w.step(libm::sinf(20.0 * t), dt);
            if t > 30.0 {
                amp = amp.max(y.abs());
            }
        }
        // Exact gain of the discrete filter there, |(e^jwT - 1) / (e^jwT - p)|, which is within
        // 2 % of the continuous one (the ZOH form's known high-frequency warp).
        let wt = 20.0 * dt;
        let (c, s) = (libm::cosf(wt), libm::sinf(wt));
        let zoh = libm::sqrtf(((c - 1.0) * (c - 1.0) + s * s) / ((c - p) * (c - p) + s * s));
        assert!((amp - zoh).abs() < 0.005, "gain at 20 rad/s {amp} vs {zoh}");
        assert!((zoh - 0.995).abs() < 0.025);

        // Nyquist (alternating input): the ZOH form gives exactly 2 / (1 + p) = 1.02.
        let mut w = Washout::new(2.0);
        let mut last = 0.0;
        for k in 0..2000 {
            last = w.step(if k % 2 == 0 { 1.0 } else { -1.0 }, dt);
        }
        assert!((last.abs() - 2.0 / (1.0 + p)).abs() < 1e-4, "{last}");
    }

    #[test]
    fn washout_starts_at_zero_and_ignores_bad_input() {
        let mut w = Washout::new(2.0);
        // A steady turn rate at engagement produces no damper kick.
        assert_eq!(w.step(0.3, 0.02), 0.0);
        let y = w.step(0.4, 0.02);
        assert!((y - 0.1).abs() < 1e-6);
        assert_eq!(w.step(f32::NAN, 0.02), y);
        assert_eq!(w.step(0.4, f32::INFINITY), y);
    }

    /// On a ramp the observer's rate settles on the ramp's slope with no lag (a type-2 loop),
    /// and its value on the ramp itself; a step makes the rate rise and come back to zero.
    #[test]
    fn rate_estimator_follows_a_ramp_without_lag() {
        let mut f = RateEstimator::new(2.0);
        assert_eq!(f.step(100.0, 0.02), Some((100.0, 0.0)));
        let mut last = (0.0, 0.0);
        for k in 1..=1000 {
            last = f.step(100.0 + 1.5 * k as f32 * 0.02, 0.02).unwrap();
        }
        assert!((last.1 - 1.5).abs() < 1e-3, "{last:?}");
        assert!((last.0 - 130.0).abs() < 1e-3, "{last:?}");
        let mut g = RateEstimator::new(2.0);
        g.step(0.0, 0.02);
        let mut peak = 0.0f32;
        let mut r = 0.0;
        for _ in 0..1000 {
            r = g.step(1.0, 0.02).unwrap().1;
            peak = peak.max(r);
        }
        // Continuous response of s w^2/(s + w)^2 to a unit step: w^2 t e^(-w t), peak w/e.
        assert!((peak - 2.0 / core::f32::consts::E).abs() < 0.03, "{peak}");
        assert!(r.abs() < 1e-3);
        // Bad samples and steps leave the state alone.
        let held = g.output();
        assert_eq!(g.step(f32::NAN, 0.02), held);
        assert_eq!(g.step(1.0, -0.02), held);
        assert_eq!(g.step(1.0, 2.0), held);
        assert_eq!(RateEstimator::new(2.0).step(f32::INFINITY, 0.02), None);
    }
}
