//! Surface servos: first order at 8 Hz, rate limited to 150 deg/s, position limited to +-25 deg.
//! The throttle has no dynamics and is only saturated to 0..1.

use super::inputs::Controls;
use crate::aircraft::Actuators;

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

    /// Moves toward `command` for `dt` s and returns the new position.
    ///
    /// The linear part is integrated exactly (`1 - exp(-w dt)`), so a 0.02 s step (where
    /// `w dt` is 1.005 at 8 Hz and forward Euler would overshoot) still behaves as a first-order
    /// lag; the change is then limited to `rate * dt` and the position to the travel.
    pub fn step(&mut self, command: f64, dt: f64) -> f64 {
        let command = if command.is_finite() {
            command
        } else {
            self.position
        };
        let linear = (command - self.position) * (1.0 - (-self.bandwidth_radps * dt).exp());
        let max_change = self.rate_limit_radps * dt;
        self.position = (self.position + linear.clamp(-max_change, max_change))
            .clamp(self.limits_rad[0], self.limits_rad[1]);
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

    /// Moves every servo toward its command for `dt` s; returns what the plant sees.
    pub fn step(&mut self, cmd: &Controls, dt: f64) -> Controls {
        Controls {
            elevator: self.elevator.step(cmd.elevator, dt),
            aileron_left: self.aileron_left.step(cmd.aileron_left, dt),
            aileron_right: self.aileron_right.step(cmd.aileron_right, dt),
            rudder: self.rudder.step(cmd.rudder, dt),
            throttle: if cmd.throttle.is_finite() {
                cmd.throttle.clamp(0.0, 1.0)
            } else {
                0.0
            },
            flap_left: self.flap_left.step(cmd.flap_left, dt),
            flap_right: self.flap_right.step(cmd.flap_right, dt),
        }
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
}
