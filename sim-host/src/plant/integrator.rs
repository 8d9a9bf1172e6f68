//! Fixed-step fourth-order Runge-Kutta.

use nalgebra::SVector;

/// One classical RK4 step of `x_dot = f(x)` over `dt`, in place, without allocation.
#[inline]
pub fn rk4_step<const N: usize>(
    f: impl Fn(&SVector<f64, N>) -> SVector<f64, N>,
    x: &mut SVector<f64, N>,
    dt: f64,
) {
    let k1 = f(x);
    let k2 = f(&(*x + k1 * (0.5 * dt)));
    let k3 = f(&(*x + k2 * (0.5 * dt)));
    let k4 = f(&(*x + k3 * dt));
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
                rk4_step(|s| Vector2::new(s[1], -s[0]), &mut x, dt);
            }
            (x - Vector2::new(1.0, 0.0)).norm()
        };
        let (e1, e2) = (run(50), run(100));
        assert!(e1 < 1e-4);
        // Halving the step divides the error by about 2^4 = 16.
        assert!((e1 / e2) > 14.0 && (e1 / e2) < 18.0, "ratio {}", e1 / e2);
    }
}
