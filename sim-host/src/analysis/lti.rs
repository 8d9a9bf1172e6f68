//! Linear time-invariant systems in state-space form: frequency response, poles, stability
//! margins and step responses, for designing and judging the loops from the linear model.

use nalgebra::{Complex, DMatrix, DVector};
use serde::Serialize;

/// `x' = A x + B u`, `y = C x + D u`.
#[derive(Clone, Debug, PartialEq)]
pub struct StateSpace {
    /// State matrix.
    pub a: DMatrix<f64>,
    /// Input matrix.
    pub b: DMatrix<f64>,
    /// Output matrix.
    pub c: DMatrix<f64>,
    /// Feed-through matrix.
    pub d: DMatrix<f64>,
}

impl StateSpace {
    /// Checks the dimensions agree.
    pub fn new(
        a: DMatrix<f64>,
        b: DMatrix<f64>,
        c: DMatrix<f64>,
        d: DMatrix<f64>,
    ) -> Result<Self, String> {
        let n = a.nrows();
        if a.ncols() != n
            || b.nrows() != n
            || c.ncols() != n
            || d.nrows() != c.nrows()
            || d.ncols() != b.ncols()
        {
            return Err(format!(
                "state-space dimensions disagree: A {}x{}, B {}x{}, C {}x{}, D {}x{}",
                a.nrows(),
                a.ncols(),
                b.nrows(),
                b.ncols(),
                c.nrows(),
                c.ncols(),
                d.nrows(),
                d.ncols()
            ));
        }
        Ok(Self { a, b, c, d })
    }

    /// Number of states.
    pub fn order(&self) -> usize {
        self.a.nrows()
    }

    /// `C (jw I - A)^-1 B + D`.
    pub fn freq_response(&self, w: f64) -> DMatrix<Complex<f64>> {
        let n = self.order();
        let jw = Complex::new(0.0, w);
        let m = DMatrix::<Complex<f64>>::from_fn(n, n, |i, j| {
            let a = Complex::new(-self.a[(i, j)], 0.0);
            if i == j {
                a + jw
            } else {
                a
            }
        });
        let bc = self.b.map(|x| Complex::new(x, 0.0));
        let x = m.lu().solve(&bc).unwrap_or_else(|| {
            DMatrix::from_element(n, self.b.ncols(), Complex::new(f64::NAN, f64::NAN))
        });
        self.c.map(|v| Complex::new(v, 0.0)) * x + self.d.map(|v| Complex::new(v, 0.0))
    }

    /// Eigenvalues of `A`, sorted by real part then imaginary part.
    pub fn poles(&self) -> Vec<Complex<f64>> {
        eigenvalues(&self.a)
    }

    /// Response of every output to a unit step on input `input`, by RK4 at `dt` up to `t_end`.
    pub fn step_response(
        &self,
        input: usize,
        t_end: f64,
        dt: f64,
    ) -> (Vec<f64>, Vec<DVector<f64>>) {
        let n = self.order();
        let mut u = DVector::zeros(self.b.ncols());
        if input < u.len() {
            u[input] = 1.0;
        }
        let bu = &self.b * &u;
        let f = |x: &DVector<f64>| &self.a * x + &bu;
        let mut x = DVector::zeros(n);
        let steps = (t_end / dt).ceil() as usize;
        let mut t = Vec::with_capacity(steps + 1);
        let mut y = Vec::with_capacity(steps + 1);
        for k in 0..=steps {
            t.push(k as f64 * dt);
            y.push(&self.c * &x + &self.d * &u);
            let k1 = f(&x);
            let k2 = f(&(&x + &k1 * (dt / 2.0)));
            let k3 = f(&(&x + &k2 * (dt / 2.0)));
            let k4 = f(&(&x + &k3 * dt));
            x += (k1 + k2 * 2.0 + k3 * 2.0 + k4) * (dt / 6.0);
        }
        (t, y)
    }
}

/// Eigenvalues of a real square matrix, sorted by real part then imaginary part.
pub fn eigenvalues(a: &DMatrix<f64>) -> Vec<Complex<f64>> {
    let mut v: Vec<Complex<f64>> = a.clone().complex_eigenvalues().iter().copied().collect();
    v.sort_by(|x, y| x.re.total_cmp(&y.re).then(x.im.total_cmp(&y.im)));
    v
}

/// Damping ratio and natural frequency (rad/s) of a pole.
pub fn damping_and_frequency(p: Complex<f64>) -> (f64, f64) {
    let wn = p.norm();
    if wn == 0.0 {
        (1.0, 0.0)
    } else {
        (-p.re / wn, wn)
    }
}

/// Classical stability margins of a loop transfer function `L(jw)` (closed loop `1/(1+L)`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Margins {
    /// Gain margin, dB (`None` if the phase never crosses -180 deg in the band).
    pub gain_margin_db: Option<f64>,
    /// Frequency where the phase crosses -180 deg, rad/s.
    pub phase_crossover_radps: Option<f64>,
    /// Phase margin, deg (`None` if |L| never crosses 1 in the band).
    pub phase_margin_deg: Option<f64>,
    /// Frequency where |L| = 1, rad/s.
    pub gain_crossover_radps: Option<f64>,
}

/// Margins of `l` over `w_min..w_max` (log-spaced sweep, crossings refined by bisection). At
/// several crossings the worst (smallest) margin is reported.
pub fn margins(l: impl Fn(f64) -> Complex<f64>, w_min: f64, w_max: f64) -> Margins {
    let n = 4000;
    let ws: Vec<f64> = (0..=n)
        .map(|k| w_min * (w_max / w_min).powf(k as f64 / n as f64))
        .collect();
    // Unwrapped phase along the sweep, deg.
    let mut phase = Vec::with_capacity(ws.len());
    let mut prev: Option<f64> = None;
    for &w in &ws {
        let p = l(w).arg().to_degrees();
        let p = match prev {
            Some(q) => q + ((p - q + 180.0).rem_euclid(360.0) - 180.0),
            // Where a loop's phase starts at low frequency (0 or -90 deg per integrator).
            None if p > 0.0 => p - 360.0,
            None => p,
        };
        phase.push(p);
        prev = Some(p);
    }
    let mag: Vec<f64> = ws.iter().map(|&w| l(w).norm()).collect();
    let mut out = Margins::default();
    for i in 0..n {
        if (mag[i] - 1.0) * (mag[i + 1] - 1.0) <= 0.0 && mag[i] != mag[i + 1] {
            let w = bisect(|w| l(w).norm() - 1.0, ws[i], ws[i + 1]);
            let ph = phase[i]
                + (phase[i + 1] - phase[i]) * ((w / ws[i]).ln() / (ws[i + 1] / ws[i]).ln());
            // Not wrapped: the phase as followed from low frequency (common's margins).
            let pm = ph + 180.0;
            if out.phase_margin_deg.is_none_or(|m| pm < m) {
                out.phase_margin_deg = Some(pm);
                out.gain_crossover_radps = Some(w);
            }
        }
        // Phase crossings of -180 deg (mod 360).
        let k0 = ((phase[i] + 180.0) / 360.0).floor();
        let k1 = ((phase[i + 1] + 180.0) / 360.0).floor();
        if k0 != k1 {
            let target = 360.0 * k0.max(k1) - 180.0;
            let w =
                ws[i] * (ws[i + 1] / ws[i]).powf((target - phase[i]) / (phase[i + 1] - phase[i]));
            let gm = -20.0 * l(w).norm().log10();
            if out.gain_margin_db.is_none_or(|m| gm < m) {
                out.gain_margin_db = Some(gm);
                out.phase_crossover_radps = Some(w);
            }
        }
    }
    out
}

fn bisect(f: impl Fn(f64) -> f64, mut lo: f64, mut hi: f64) -> f64 {
    let flo = f(lo);
    for _ in 0..60 {
        let mid = (lo * hi).sqrt();
        if (f(mid) > 0.0) == (flo > 0.0) {
            lo = mid
        } else {
            hi = mid
        }
    }
    (lo * hi).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn first_order_lag_frequency_response_and_step() {
        // 1/(s+2): |G(j2)| = 1/(2 sqrt 2), phase -45 deg; step settles at 0.5.
        let g = StateSpace::new(
            DMatrix::from_element(1, 1, -2.0),
            DMatrix::from_element(1, 1, 1.0),
            DMatrix::from_element(1, 1, 1.0),
            DMatrix::zeros(1, 1),
        )
        .unwrap();
        let h = g.freq_response(2.0)[(0, 0)];
        assert!((h.norm() - 1.0 / 8f64.sqrt()).abs() < 1e-12);
        assert!((h.arg().to_degrees() + 45.0).abs() < 1e-9);
        let (_, y) = g.step_response(0, 5.0, 0.001);
        assert!(
            (y.last().map(|v| v[0]).unwrap_or(0.0) - 0.5 * (1.0 - (-10f64).exp())).abs() < 1e-9
        );
        assert_eq!(g.poles(), vec![Complex::new(-2.0, 0.0)]);
    }

    #[test]
    fn margins_of_a_known_loop() {
        // L = K / (s (s+1)(s+2)) with K = 2: the phase crosses -180 deg at w = sqrt 2 where
        // |L| = 2 / (sqrt2 * sqrt3 * sqrt6) = 1/3: gain margin 20 log10 3 = 9.54 dB.
        let l = |w: f64| {
            let s = Complex::new(0.0, w);
            Complex::new(2.0, 0.0) / (s * (s + 1.0) * (s + 2.0))
        };
        let m = margins(l, 0.01, 100.0);
        assert!(
            (m.gain_margin_db.unwrap_or(0.0) - 9.5424).abs() < 0.01,
            "{m:?}"
        );
        assert!((m.phase_crossover_radps.unwrap_or(0.0) - 2f64.sqrt()).abs() < 1e-3);
        // Gain crossover: |L| = 1 at w = 0.7494, phase margin 32.6 deg.
        assert!(
            (m.phase_margin_deg.unwrap_or(0.0) - 32.6).abs() < 0.2,
            "{m:?}"
        );
        let (z, wn) = damping_and_frequency(Complex::new(-11.7, 10.0));
        assert!((z - 0.760).abs() < 1e-3 && (wn - 15.39).abs() < 0.01);
    }
}
