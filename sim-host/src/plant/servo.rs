//! Surface servos: first order at 8 Hz, rate limited to 150 deg/s, position limited to +-25 deg.
//! The throttle has no dynamics and is only saturated to 0..1.
//!
//! The flight software's command reaches the servos through a zero-order hold: it is held over
//! each plant step while the servos move, and every RK4 stage of the step sees the surfaces
//! where the servos are at that stage's time ([`ServoBank::rk4_held`]). Setting the surfaces at
//! their end-of-step position for the whole step instead would lead the true surface motion by
//! half a step: a phase lead of `w dt / 2`, 1.3 to 2 deg at 9 to 14 rad/s with 5 ms steps, all
//! of it optimistic margin.

use super::inputs::Controls;
use super::integrator::rk4_step;
use crate::aircraft::Actuators;
use nalgebra::SVector;

/// One servo.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Servo {
    /// Bandwidth, rad/s.
    pub bandwidth_radps: f64,
    /// Rate limit, rad/s.
    pub rate_limit_radps: f64,
    /// Position limits `[min, max]`, rad.
    pub limits_rad: [f64; 2],
    /// Current position, rad.
    pub position: f64,
}

impl Servo {
    /// A servo of the given parameters at `position`.
    pub fn new(params: &Actuators, position: f64) -> Self {
        Self {
            bandwidth_radps: 2.0 * std::f64::consts::PI * params.bandwidth_Hz,
            rate_limit_radps: params.rate_limit_radps,
            limits_rad: params.position_limit_rad,
            position: position.clamp(params.position_limit_rad[0], params.position_limit_rad[1]),
        }
    }

    /// Where the servo is `tau` s after its present position with `command` held since: the
    /// exact solution of `x' = sat_rate(w (command - x))`, stopped at the travel's ends.
    ///
    /// Far from the command the rate limit binds and the servo moves at the limit until the
    /// error is down to `rate / w`, then it closes the rest exponentially. The motion is
    /// monotonic towards the command, so clamping it to the travel is where the servo stops. Being
    /// exact, it holds at any step (where `w dt` is 1.005 at 8 Hz and 20 ms, forward Euler would
    /// overshoot) and at any RK4 stage time inside one. A command that is not finite holds the
    /// servo where it is.
    pub fn held(&self, command: f64, tau: f64) -> f64 {
        let error = command - self.position;
        // At rest on its command (flaps, a surface held), or at the step's start: no motion.
        if !error.is_finite() || error == 0.0 || tau <= 0.0 {
            return self.position;
        }
        let knee = self.rate_limit_radps / self.bandwidth_radps;
        let ramp_s = (error.abs() - knee).max(0.0) / self.rate_limit_radps;
        let position = if tau <= ramp_s {
            self.position + error.signum() * self.rate_limit_radps * tau
        } else {
            let left = error.clamp(-knee, knee);
            command - left * (-self.bandwidth_radps * (tau - ramp_s)).exp()
        };
        position.clamp(self.limits_rad[0], self.limits_rad[1])
    }

    /// Moves toward `command`, held for `dt` s, and returns the new position.
    pub fn step(&mut self, command: f64, dt: f64) -> f64 {
        self.position = self.held(command, dt);
        self.position
    }
}

/// The servos of every surface, plus the throttle saturation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ServoBank {
    /// Elevator servo.
    pub elevator: Servo,
    /// Left aileron servo.
    pub aileron_left: Servo,
    /// Right aileron servo.
    pub aileron_right: Servo,
    /// Rudder servo.
    pub rudder: Servo,
    /// Left flap servo.
    pub flap_left: Servo,
    /// Right flap servo.
    pub flap_right: Servo,
}

impl ServoBank {
    /// Servos resting at `initial` (e.g. the trim).
    pub fn new(params: &Actuators, initial: &Controls) -> Self {
        Self {
            elevator: Servo::new(params, initial.elevator),
            aileron_left: Servo::new(params, initial.aileron_left),
            aileron_right: Servo::new(params, initial.aileron_right),
            rudder: Servo::new(params, initial.rudder),
            flap_left: Servo::new(params, initial.flap_left),
            flap_right: Servo::new(params, initial.flap_right),
        }
    }

    /// The surfaces `tau` s into a step with `cmd` held since its start (see [`Servo::held`]),
    /// and the throttle saturated to 0..1.
    pub fn held(&self, cmd: &Controls, tau: f64) -> Controls {
        Controls {
            elevator: self.elevator.held(cmd.elevator, tau),
            aileron_left: self.aileron_left.held(cmd.aileron_left, tau),
            aileron_right: self.aileron_right.held(cmd.aileron_right, tau),
            rudder: self.rudder.held(cmd.rudder, tau),
            throttle: if cmd.throttle.is_finite() {
                cmd.throttle.clamp(0.0, 1.0)
            } else {
                0.0
            },
            flap_left: self.flap_left.held(cmd.flap_left, tau),
            flap_right: self.flap_right.held(cmd.flap_right, tau),
        }
    }

    /// Moves every servo toward its command, held for `dt` s; returns the surfaces at the end.
    pub fn step(&mut self, cmd: &Controls, dt: f64) -> Controls {
        let end = self.held(cmd, dt);
        self.settle_at(&end);
        end
    }

    /// The servos where `surfaces` are.
    fn settle_at(&mut self, surfaces: &Controls) {
        self.elevator.position = surfaces.elevator;
        self.aileron_left.position = surfaces.aileron_left;
        self.aileron_right.position = surfaces.aileron_right;
        self.rudder.position = surfaces.rudder;
        self.flap_left.position = surfaces.flap_left;
        self.flap_right.position = surfaces.flap_right;
    }

    /// One RK4 step of `x' = f(surfaces, x)` over `dt` with `cmd` held at the servos' inputs
    /// (zero-order hold): each stage evaluates `f` with the surfaces where the servos are at
    /// the stage's time, and the servos end the step where the surfaces are at its end, which
    /// it returns. The one definition of how commanded surfaces enter an integrated model.
    pub fn rk4_held<const N: usize>(
        &mut self,
        cmd: &Controls,
        x: &mut SVector<f64, N>,
        dt: f64,
        f: impl Fn(&Controls, &SVector<f64, N>) -> SVector<f64, N>,
    ) -> Controls {
        let start = *self;
        // RK4 asks for the surfaces at the step's start, twice at its middle and at its end:
        // each is computed once (the servos' exponentials are a large share of a flight's time).
        let (half, end) = (start.held(cmd, 0.5 * dt), start.held(cmd, dt));
        let at = |tau: f64| {
            if tau == 0.5 * dt {
                half
            } else if tau == dt {
                end
            } else {
                start.held(cmd, tau)
            }
        };
        rk4_step(|tau, x| f(&at(tau), x), x, dt);
        self.settle_at(&end);
        end
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::aircraft::Aircraft;

    fn servo() -> Servo {
        Servo::new(&Aircraft::ultrastick25e().unwrap().actuators, 0.0)
    }

    #[test]
    fn small_step_is_first_order_at_8_hz() {
        // 0.01 rad step: the rate limit (150 deg/s) is never reached; after one time constant
        // (1 / (2 pi 8) s) the servo is at 1 - 1/e of the step.
        let mut s = servo();
        let tau = 1.0 / (2.0 * std::f64::consts::PI * 8.0);
        let n = 100;
        for _ in 0..n {
            s.step(0.01, tau / n as f64);
        }
        assert!((s.position - 0.01 * (1.0 - (-1.0f64).exp())).abs() < 1e-9);
    }

    #[test]
    fn large_step_is_rate_limited_and_saturated() {
        let mut s = servo();
        // 0.1 s at 150 deg/s is at most 15 deg.
        for _ in 0..100 {
            s.step(1.0, 0.001);
        }
        assert!((s.position - 15f64.to_radians()).abs() < 1e-8);
        for _ in 0..1000 {
            s.step(1.0, 0.001);
        }
        assert!((s.position - 25f64.to_radians()).abs() < 1e-6);
        s.step(f64::NAN, 0.01);
        assert!(s.position.is_finite());
    }

    /// A bank at neutral, and the elevator's bandwidth, rad/s.
    fn bank() -> (ServoBank, f64) {
        let a = Aircraft::ultrastick25e().unwrap();
        let bank = ServoBank::new(&a.actuators, &Controls::default());
        (bank, 2.0 * std::f64::consts::PI * a.actuators.bandwidth_Hz)
    }

    #[test]
    fn a_held_step_is_one_minus_exp_at_each_stage_time_and_its_integral_is_rk4_accurate() {
        // A 1 deg elevator step (below the rate limit's knee, 150 / (2 pi 8) = 3.0 deg) held
        // over one 20 ms step: the stages see 1 - exp(-w tau) at tau = 0, dt/2, dt/2, dt, and
        // y' = elevator integrates to the exact A (dt - (1 - exp(-w dt)) / w) within Simpson's
        // error bound A w^4 dt^5 / 2880 (RK4 on an input alone is Simpson's rule).
        let (mut bank, w) = bank();
        let (amp, dt) = (1f64.to_radians(), 0.02);
        let cmd = Controls {
            elevator: amp,
            ..Controls::default()
        };
        let seen = std::cell::RefCell::new(Vec::new());
        let mut y = nalgebra::Vector1::new(0.0);
        let end = bank.rk4_held(&cmd, &mut y, dt, |c, _| {
            seen.borrow_mut().push(c.elevator);
            nalgebra::Vector1::new(c.elevator)
        });
        let step = |tau: f64| amp * (1.0 - (-w * tau).exp());
        let stages = [0.0, dt / 2.0, dt / 2.0, dt].map(step);
        for (got, want) in seen.borrow().iter().zip(stages) {
            assert!((got - want).abs() < 1e-15, "stage {got} against {want}");
        }
        assert_eq!(seen.borrow().len(), 4);
        assert_eq!(end.elevator, step(dt));
        assert_eq!(bank.elevator.position, step(dt));
        let exact = amp * (dt - (1.0 - (-w * dt).exp()) / w);
        let bound = amp * w.powi(4) * dt.powi(5) / 2880.0;
        assert!((y[0] - exact).abs() < bound, "{} against {exact}", y[0]);
    }

    #[test]
    fn a_large_held_step_ramps_at_the_rate_limit_inside_the_step_and_stops_at_the_travel() {
        // 10 deg commanded: 150 deg/s until the error is down to the knee (3.0 deg), so the
        // stages of a 20 ms step see 0, 1.5 and 3 deg; a 1 rad command stops at the travel's
        // end (25 deg) and goes no further at any stage.
        let (mut bank, _) = bank();
        let rate = bank.rudder.rate_limit_radps;
        let cmd = Controls {
            rudder: 10f64.to_radians(),
            ..Controls::default()
        };
        let seen = std::cell::RefCell::new(Vec::new());
        let mut y = nalgebra::Vector1::new(0.0);
        bank.rk4_held(&cmd, &mut y, 0.02, |c, _| {
            seen.borrow_mut().push(c.rudder);
            nalgebra::Vector1::new(c.rudder)
        });
        for (got, tau) in seen.borrow().iter().zip([0.0, 0.01, 0.01, 0.02]) {
            assert!((got - rate * tau).abs() < 1e-15, "{got} at {tau}");
        }
        let far = Controls {
            rudder: 1.0,
            ..Controls::default()
        };
        let stop = bank.rudder.limits_rad[1];
        for _ in 0..20 {
            bank.rk4_held(&far, &mut y, 0.02, |c, _| {
                assert!(c.rudder <= stop);
                nalgebra::Vector1::new(c.rudder)
            });
        }
        assert_eq!(bank.rudder.position, stop);
    }

    #[test]
    fn the_surface_lags_a_held_sine_by_the_servo_and_half_a_step() {
        // A sine sampled and held over 5 ms steps reaches the surface through a zero-order hold
        // (e^{-j w dt / 2}) and the servo (w_s / (j w + w_s)): at 2 Hz that is -14.04 - 1.80 =
        // -15.84 deg. The surface's mean over each step (what y' = elevator integrates), placed
        // at the step's middle, shows that phase against the command; surfaces held at their
        // end-of-step position would show the servo alone, 1.8 deg less lag.
        let (mut bank, ws) = bank();
        let (dt, f, amp) = (0.005, 2.0, 1f64.to_radians());
        let w = 2.0 * std::f64::consts::PI * f;
        let per_period = (1.0 / (f * dt)).round() as usize;
        let mut y = nalgebra::Vector1::new(0.0);
        let (mut re, mut im) = (0.0, 0.0);
        for k in 0..5 * per_period {
            let t = k as f64 * dt;
            let cmd = Controls {
                elevator: amp * (w * t).sin(),
                ..Controls::default()
            };
            let before = y[0];
            bank.rk4_held(&cmd, &mut y, dt, |c, _| nalgebra::Vector1::new(c.elevator));
            // After the servo's transient (its time constant is 20 ms), whole periods only.
            if k >= 3 * per_period {
                let mean = (y[0] - before) / dt;
                let mid = t + dt / 2.0;
                re += mean * (w * mid).sin();
                im += mean * (w * mid).cos();
            }
        }
        let phase = im.atan2(re).to_degrees();
        let expected = (-(w / ws).atan() - w * dt / 2.0).to_degrees();
        assert!(
            (phase - expected).abs() < 0.05,
            "{phase} against {expected} deg"
        );
    }
}
