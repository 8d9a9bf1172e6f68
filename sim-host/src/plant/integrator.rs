//! Fixed-step fourth-order Runge-Kutta.

use nalgebra::SVector;

/// One classical RK4 step of `x_dot = f(tau, x)` over `dt`, in place, without allocation;
/// `tau` is the time since the start of the step (0, `dt / 2`, `dt / 2`, `dt` at the four
/// stages), so inputs that move inside the step are seen where they are at each stage.
#[inline]
pub fn rk4_step<const N: usize>(
    f: impl Fn(f64, &SVector<f64, N>) -> SVector<f64, N>,
    x: &mut SVector<f64, N>,
    dt: f64,
) {
    let half = 0.5 * dt;
    let k1 = f(0.0, x);
    let k2 = f(half, &(*x + k1 * half));
    let k3 = f(half, &(*x + k2 * half));
    let k4 = f(dt, &(*x + k3 * dt));
    *x += (k1 + (k2 + k3) * 2.0 + k4) * (dt / 6.0);
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector2;

    #[test]
    fn fourth_order_on_a_harmonic_oscillator() {
        // x'' = -x from (1, 0): after 2 pi the exact answer is (1, 0); RK4's error ~ dt^4.
        let run = |n: usize| {
            let dt = 2.0 * std::f64::consts::PI / n as f64;
            let mut x = Vector2::new(1.0, 0.0);
            for _ in 0..n {
                rk4_step(|_, s| Vector2::new(s[1], -s[0]), &mut x, dt);
            }
            (x - Vector2::new(1.0, 0.0)).norm()
        };
        let (e1, e2) = (run(50), run(100));
        assert!(e1 < 1e-4);
        // Halving the step divides the error by about 2^4 = 16.
        assert!((e1 / e2) > 14.0 && (e1 / e2) < 18.0, "ratio {}", e1 / e2);
    }

    #[test]
    fn stage_times_make_a_cubic_in_time_exact() {
        // With `x' = tau^3` the step is Simpson's rule on the stage times, exact for cubics:
        // dt^4 / 4. Stages seen at other times would miss it by a fraction of that.
        let dt = 0.3;
        let mut x = nalgebra::Vector1::new(0.0);
        rk4_step(|tau, _| nalgebra::Vector1::new(tau.powi(3)), &mut x, dt);
        assert!((x[0] - dt.powi(4) / 4.0).abs() < 1e-15, "{}", x[0]);
    }
}
