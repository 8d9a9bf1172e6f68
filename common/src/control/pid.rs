//! The discrete PID building block every loop of the autopilot is made of.
//!
//! Form, per step of length `dt`:
//!
//! ```text
//! u = sat( ff + kp e + I + D + T )
//! I[k+1] = I[k] + ki e dt            (forward Euler, held by the anti-windup rule below)
//! D      = -kd * dy/dt               (on the measurement y, or on a measured rate)
//! T      = bumpless-transfer offset, decays as exp(-t / transfer_tc)
//! ```
//!
//! - **Derivative on the measurement** (`-kd * ydot`), never on the error: a setpoint step does
//!   not kick the output, and where a rate gyro measures `ydot` directly (roll rate `p` for the
//!   roll loop, `q` for pitch) it is used as is instead of differencing a noisy angle. This is the
//!   thesis's rate damper (`kd_p`, `kd_q` acting on `p`, `q`).
//! - **Anti-windup: conditional integration (clamping).** The integrator only moves while the
//!   output is inside its limits, or when moving it pulls the output back inside; when it would
//!   push the output past a limit it integrates just up to the limit and stops there. Chosen over
//!   back-calculation because it needs no extra tracking time constant (one less parameter to get
//!   wrong for each of the several gain sets this autopilot flies) and leaves the integrator at
//!   the value that holds the output at its limit, so recovery starts the moment the error changes
//!   sign.
//! - **Bumpless re-initialisation** ([`Pid::reset_to`]): on engagement, or when a loop's setpoint
//!   source changes, the next output is made equal to a given value (normally the output the
//!   actuator or the next loop was receiving), and the loop then moves away from it smoothly.
//!   [`Bumpless::Integrator`] (inner loops, whose previous output is the best guess of the
//!   equilibrium) sets the integrator to the share of the output that would hold at zero error,
//!   `u0 - ff - D`, and lets the proportional share fade in through the offset `T = -kp e`;
//!   [`Bumpless::Fade`] (outer loops and the throttle, whose previous output is not an
//!   equilibrium: a bank angle, full throttle) clears the integrator and lets the whole
//!   difference fade. A loop with `ki = 0` always fades. Putting the proportional share into the
//!   integrator instead (the textbook `I = u0 - kp e`) would make the output exactly continuous too,
//!   but a loop engaged with an error then acts on it only through a slow integrator.
//! - The integral term is stored in output units (`I`, not `integral of e`), so a change of `ki`
//!   does not make the output jump.

use crate::math::clamp;

/// Gains and output limits of one PID loop.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct PidGains {
    /// Proportional gain (output per unit error).
    pub kp: f32,
    /// Integral gain (output per unit error per second).
    pub ki: f32,
    /// Derivative gain on the measurement (output per unit measurement rate).
    pub kd: f32,
    /// Lowest output.
    pub out_min: f32,
    /// Highest output.
    pub out_max: f32,
}

impl PidGains {
    /// A PI(D) loop with symmetric output limits `+-limit`.
    pub const fn symmetric(kp: f32, ki: f32, kd: f32, limit: f32) -> Self {
        Self {
            kp,
            ki,
            kd,
            out_min: -limit,
            out_max: limit,
        }
    }

    fn is_finite(&self) -> bool {
        self.kp.is_finite()
            && self.ki.is_finite()
            && self.kd.is_finite()
            && self.out_min.is_finite()
            && self.out_max.is_finite()
            && self.out_min <= self.out_max
    }
}

/// What the derivative term acts on, this step.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Derivative {
    /// No derivative action.
    None,
    /// The measurement `y`: the PID differences it (backward difference; zero on the first step
    /// after a reset).
    Measurement(f32),
    /// The measured rate `dy/dt` (a gyro), used directly.
    Rate(f32),
}

/// Where a bumpless re-initialisation puts the difference between the wanted and the computed
/// output.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Bumpless {
    /// Into the integrator (up to its limits); into the fading offset when `ki = 0`.
    Integrator,
    /// Into the fading offset; the integrator is cleared.
    Fade,
}

/// The terms of the last output, for telemetry and tests.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct PidTerms {
    /// Proportional term.
    pub p: f32,
    /// Integral term.
    pub i: f32,
    /// Derivative term.
    pub d: f32,
    /// Bumpless-transfer offset.
    pub transfer: f32,
    /// Output after saturation.
    pub output: f32,
    /// The output sat on a limit.
    pub saturated: bool,
}

/// One discrete PID loop. Plain state, no allocation; every step takes its own `dt`.
#[derive(Clone, Copy, Debug)]
pub struct Pid {
    gains: PidGains,
    transfer_tc: f32,
    integ: f32,
    transfer: f32,
    prev_meas: Option<f32>,
    pending: Option<(f32, Bumpless)>,
    last: PidTerms,
}

impl Pid {
    /// A loop at rest (zero integrator, zero output). `transfer_tc` (s) is the time constant with
    /// which a bumpless-transfer offset fades.
    pub fn new(gains: PidGains, transfer_tc: f32) -> Self {
        Self {
            gains,
            transfer_tc,
            integ: 0.0,
            transfer: 0.0,
            prev_meas: None,
            pending: None,
            last: PidTerms::default(),
        }
    }

    /// The gains in use.
    pub fn gains(&self) -> PidGains {
        self.gains
    }

    /// Replaces the gains (and fade time constant). State is kept; callers that need the output
    /// continuous across the change follow with [`Pid::reset_to`].
    pub fn set_gains(&mut self, gains: PidGains, transfer_tc: f32) {
        self.gains = gains;
        self.transfer_tc = transfer_tc;
    }

    /// Back to rest: integrator, offset and derivative memory cleared, last output zero.
    pub fn reset(&mut self) {
        self.integ = 0.0;
        self.transfer = 0.0;
        self.prev_meas = None;
        self.pending = None;
        self.last = PidTerms::default();
    }

    /// Makes the next [`Pid::step`] output exactly `output` (clamped to the limits), whatever its
    /// error then is, by re-initialising the integrator and the fading offset (see [`Bumpless`]).
    /// The derivative memory is cleared, so a stale measurement does not kick either.
    /// A non-finite `output` is ignored (the loop then restarts from its own state).
    pub fn reset_to(&mut self, output: f32, how: Bumpless) {
        self.prev_meas = None;
        self.pending = if output.is_finite() {
            Some((output, how))
        } else {
            None
        };
    }

    /// Output of the last step.
    pub fn output(&self) -> f32 {
        self.last.output
    }

    /// Terms of the last step.
    pub fn terms(&self) -> PidTerms {
        self.last
    }

    /// One step: `error` = setpoint - measurement (already wrapped where the quantity is an
    /// angle), `deriv` the derivative source, `ff` a feed-forward (trim) added before saturation,
    /// `dt` the time since the last step, s.
    ///
    /// A non-finite input, a non-positive `dt` or non-finite gains leave the state untouched and
    /// return the last output: nothing non-finite ever comes out.
    pub fn step(&mut self, error: f32, deriv: Derivative, ff: f32, dt: f32) -> f32 {
        let deriv_ok = match deriv {
            Derivative::None => true,
            Derivative::Measurement(y) | Derivative::Rate(y) => y.is_finite(),
        };
        let inputs_ok = dt > 0.0
            && dt.is_finite()
            && error.is_finite()
            && ff.is_finite()
            && deriv_ok
            && self.gains.is_finite();
        if !inputs_ok {
            return self.last.output;
        }
        let g = self.gains;

        // The offset left by an earlier bumpless transfer fades out.
        if self.transfer != 0.0 {
            self.transfer *= if self.transfer_tc > 0.0 && self.transfer_tc.is_finite() {
                libm::expf(-dt / self.transfer_tc)
            } else {
                0.0
            };
            // Far below any servo resolution: stop paying for the exp().
            if libm::fabsf(self.transfer) < 1e-7 {
                self.transfer = 0.0;
            }
        }

        let p = g.kp * error;
        let d = match deriv {
            Derivative::None => 0.0,
            Derivative::Rate(rate) => -g.kd * rate,
            Derivative::Measurement(y) => {
                let d = match self.prev_meas {
                    Some(prev) => -g.kd * (y - prev) / dt,
                    None => 0.0,
                };
                self.prev_meas = Some(y);
                d
            }
        };

        if let Some((target, how)) = self.pending.take() {
            // Solve ff + p + I + d + T = target for I (and T).
            let target = clamp(target, g.out_min, g.out_max);
            let need = target - ff - p - d;
            if how == Bumpless::Integrator && g.ki != 0.0 {
                let span = g.out_max - g.out_min;
                self.integ = clamp(need + p, -span, span);
                self.transfer = need - self.integ;
            } else {
                self.integ = 0.0;
                self.transfer = need;
            }
        } else {
            // Conditional integration: move the integrator only as far as the output limits let
            // it, and never push further into a limit the output already sits on.
            let rest = ff + p + d + self.transfer;
            let candidate = self.integ + g.ki * error * dt;
            if candidate > self.integ {
                let room = g.out_max - rest;
                self.integ = self.integ.max(candidate.min(room));
            } else if candidate < self.integ {
                let room = g.out_min - rest;
                self.integ = self.integ.min(candidate.max(room));
            }
            let span = g.out_max - g.out_min;
            self.integ = clamp(self.integ, -span, span);
        }

        let raw = ff + p + self.integ + d + self.transfer;
        let output = clamp(raw, g.out_min, g.out_max);
        let output = if output.is_finite() {
            output
        } else {
            self.last.output
        };
        self.last = PidTerms {
            p,
            i: self.integ,
            d,
            transfer: self.transfer,
            output,
            saturated: raw > g.out_max || raw < g.out_min,
        };
        output
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const DT: f32 = 0.001;

    /// Double integrator y'' = u under u = kp e - kd y': closed loop s^2 + kd s + kp, so
    /// wn = sqrt(kp), zeta = kd / (2 wn): overshoot exp(-pi zeta / sqrt(1 - zeta^2)), peak time
    /// pi / (wn sqrt(1 - zeta^2)).
    #[test]
    fn pd_on_double_integrator_matches_second_order_prediction() {
        let (wn, zeta) = (2.0f32, 0.5f32);
        let mut pid = Pid::new(PidGains::symmetric(wn * wn, 0.0, 2.0 * zeta * wn, 1e6), 1.0);
        let (mut y, mut v) = (0.0f32, 0.0f32);
        let (mut peak, mut t_peak) = (0.0f32, 0.0f32);
        for k in 0..10_000 {
            let u = pid.step(1.0 - y, Derivative::Rate(v), 0.0, DT);
            // Exact ZOH update of the double integrator over one step.
            y += v * DT + 0.5 * u * DT * DT;
            v += u * DT;
            if y > peak {
                peak = y;
                t_peak = (k + 1) as f32 * DT;
            }
        }
        let os_expected =
            libm::expf(-core::f32::consts::PI * zeta / libm::sqrtf(1.0 - zeta * zeta));
        let tp_expected = core::f32::consts::PI / (wn * libm::sqrtf(1.0 - zeta * zeta));
        assert!(
            (peak - 1.0 - os_expected).abs() < 0.005,
            "overshoot {}",
            peak - 1.0
        );
        assert!((t_peak - tp_expected).abs() < 0.01, "peak time {t_peak}");
        assert!((y - 1.0).abs() < 1e-3);
    }

    /// First-order plant y' = -a y + b u with PI kp/ki = 1/a cancelling the pole: the closed loop
    /// is 1/(tau s + 1) with tau = 1/(b ki): 63.2 % at tau, no overshoot, no steady error.
    #[test]
    fn pi_on_first_order_plant_gives_predicted_time_constant() {
        let (a, b) = (2.0f32, 4.0f32);
        let tau = 0.25f32;
        let ki = a / (b * tau);
        let kp = ki / a;
        let mut pid = Pid::new(PidGains::symmetric(kp, ki, 0.0, 1e6), 1.0);
        let mut y = 0.0f32;
        let mut y_at_tau = 0.0;
        let mut max = 0.0f32;
        for k in 0..5000 {
            let u = pid.step(1.0 - y, Derivative::None, 0.0, DT);
            y += (-a * y + b * u) * DT;
            if k + 1 == 250 {
                y_at_tau = y;
            }
            max = max.max(y);
        }
        assert!((y_at_tau - 0.632).abs() < 0.01, "y(tau) = {y_at_tau}");
        assert!(max < 1.005, "overshoot {max}");
        assert!((y - 1.0).abs() < 1e-3);
    }

    #[test]
    fn output_saturates_and_reports_it() {
        let mut pid = Pid::new(PidGains::symmetric(10.0, 0.0, 0.0, 0.5), 1.0);
        assert_eq!(pid.step(1.0, Derivative::None, 0.0, 0.02), 0.5);
        assert!(pid.terms().saturated);
        assert_eq!(pid.step(-1.0, Derivative::None, 0.0, 0.02), -0.5);
        assert!((pid.step(0.01, Derivative::None, 0.0, 0.02) - 0.1).abs() < 1e-6);
        assert!(!pid.terms().saturated);
        // The feed-forward counts against the same limits.
        assert_eq!(pid.step(0.01, Derivative::None, 0.45, 0.02), 0.5);
        assert!(pid.terms().saturated);
    }

    /// A textbook PI without any anti-windup, the baseline the clamped loop is compared with.
    struct NaivePi {
        kp: f32,
        ki: f32,
        integ: f32,
        lim: f32,
    }
    impl NaivePi {
        fn step(&mut self, e: f32, dt: f32) -> f32 {
            self.integ += self.ki * e * dt;
            (self.kp * e + self.integ).clamp(-self.lim, self.lim)
        }
    }

    /// Plant y' = u with |u| <= 1; a setpoint the actuator cannot reach quickly keeps the loop
    /// saturated for seconds. Without anti-windup the integrator charges up and the response
    /// overshoots badly; with clamping the integrator stays bounded and the overshoot is small.
    #[test]
    fn anti_windup_bounds_integrator_and_speeds_recovery() {
        let (kp, ki, lim) = (2.0f32, 2.0f32, 1.0f32);
        let run = |clamped: bool| {
            let mut pid = Pid::new(PidGains::symmetric(kp, ki, 0.0, lim), 1.0);
            let mut naive = NaivePi {
                kp,
                ki,
                integ: 0.0,
                lim,
            };
            let mut y = 0.0f32;
            let mut max = 0.0f32;
            let mut max_integ = 0.0f32;
            let mut settle = 0.0f32;
            for k in 0..20_000 {
                let e = 5.0 - y;
                let u = if clamped {
                    let u = pid.step(e, Derivative::None, 0.0, DT);
                    max_integ = max_integ.max(pid.terms().i.abs());
                    u
                } else {
                    let u = naive.step(e, DT);
                    max_integ = max_integ.max(naive.integ.abs());
                    u
                };
                y += u * DT;
                max = max.max(y);
                if (y - 5.0).abs() > 0.05 {
                    settle = (k + 1) as f32 * DT;
                }
            }
            (max - 5.0, max_integ, settle)
        };
        let (os_clamped, integ_clamped, settle_clamped) = run(true);
        let (os_naive, integ_naive, settle_naive) = run(false);
        extern crate std;
        std::println!(
            "clamped: overshoot {os_clamped:.3} integ {integ_clamped:.3} settle {settle_clamped:.2} s; \
             naive: overshoot {os_naive:.3} integ {integ_naive:.3} settle {settle_naive:.2} s"
        );
        // While saturated the clamped integrator never exceeds the output span.
        assert!(integ_clamped <= lim + 1e-6, "integrator {integ_clamped}");
        assert!(
            integ_naive > 3.0 * lim,
            "naive integrator only {integ_naive}"
        );
        // Linear-region overshoot of this loop (zeta = 0.707 with a zero) is about 20 %
        // of the last, unsaturated part of the step; the naive loop overshoots by metres.
        assert!(os_clamped < 0.3, "clamped overshoot {os_clamped}");
        assert!(os_naive > 1.0, "naive overshoot {os_naive}");
        assert!(
            settle_clamped < 0.6 * settle_naive,
            "settling {settle_clamped} vs {settle_naive}"
        );
    }

    #[test]
    fn bumpless_reset_keeps_output_continuous() {
        // Integrator takes the zero-error share, the proportional share fades in.
        let tc = 0.5;
        let mut pid = Pid::new(PidGains::symmetric(-1.0, -0.5, -0.1, 0.4), tc);
        pid.reset_to(0.123, Bumpless::Integrator);
        let u = pid.step(0.2, Derivative::Rate(0.3), 0.01, 0.02);
        assert!((u - 0.123).abs() < 1e-6);
        let i0 = 0.123 - 0.01 - (-0.1 * -0.3);
        assert!((pid.terms().i - i0).abs() < 1e-6);
        assert!((pid.terms().transfer - 0.2).abs() < 1e-6, "-kp e");
        // A persisting error: after tc the proportional action is (1 - 1/e) in.
        let mut u = 0.0;
        for _ in 0..25 {
            u = pid.step(0.2, Derivative::Rate(0.3), 0.01, 0.02);
        }
        let integ = pid.terms().i;
        let expected = 0.01 - 0.2 + 0.2 * libm::expf(-1.0) + integ + 0.03;
        assert!((u - expected).abs() < 1e-4, "{u} vs {expected}");

        // Fade: integrator cleared, everything fades.
        let mut f = Pid::new(PidGains::symmetric(1.0, 1.0, 0.0, 10.0), tc);
        f.step(1.0, Derivative::None, 0.0, 0.02);
        f.reset_to(2.0, Bumpless::Fade);
        assert!((f.step(0.5, Derivative::None, 0.0, 0.02) - 2.0).abs() < 1e-6);
        assert_eq!(f.terms().i, 0.0);

        // Proportional-only loop: the difference fades with the transfer time constant.
        let tc = 0.5;
        let mut p_only = Pid::new(PidGains::symmetric(2.0, 0.0, 0.0, 10.0), tc);
        p_only.reset_to(1.0, Bumpless::Integrator);
        assert!((p_only.step(0.1, Derivative::None, 0.0, 0.02) - 1.0).abs() < 1e-6);
        let mut u = 0.0;
        for _ in 0..25 {
            u = p_only.step(0.1, Derivative::None, 0.0, 0.02);
        }
        // After 0.5 s = tc: offset 0.8 * e^-1 on top of kp e = 0.2.
        assert!((u - (0.2 + 0.8 * libm::expf(-1.0))).abs() < 1e-4, "{u}");
    }

    #[test]
    fn derivative_on_measurement_matches_supplied_rate() {
        let g = PidGains::symmetric(0.0, 0.0, 0.5, 10.0);
        let mut a = Pid::new(g, 1.0);
        let mut b = Pid::new(g, 1.0);
        // First step has no history: no kick.
        assert_eq!(a.step(0.0, Derivative::Measurement(1.0), 0.0, 0.02), 0.0);
        for k in 1..10 {
            let y = 1.0 + 0.3 * k as f32 * 0.02;
            let ua = a.step(0.0, Derivative::Measurement(y), 0.0, 0.02);
            let ub = b.step(0.0, Derivative::Rate(0.3), 0.0, 0.02);
            assert!((ua - ub).abs() < 1e-4);
            assert!((ub + 0.15).abs() < 1e-6);
        }
    }

    #[test]
    fn bad_inputs_hold_last_output() {
        let mut pid = Pid::new(PidGains::symmetric(1.0, 1.0, 0.0, 10.0), 1.0);
        let u = pid.step(1.0, Derivative::None, 0.0, 0.02);
        for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
            assert_eq!(pid.step(bad, Derivative::None, 0.0, 0.02), u);
            assert_eq!(pid.step(1.0, Derivative::Rate(bad), 0.0, 0.02), u);
            assert_eq!(pid.step(1.0, Derivative::None, bad, 0.02), u);
            assert_eq!(pid.step(1.0, Derivative::None, 0.0, bad), u);
        }
        assert_eq!(pid.step(1.0, Derivative::None, 0.0, 0.0), u);
        assert_eq!(pid.step(1.0, Derivative::None, 0.0, -0.02), u);
        assert_eq!(pid.terms().i, 0.02);
    }
}
