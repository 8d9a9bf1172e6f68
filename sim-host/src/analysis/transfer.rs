//! Transfer functions of single-input single-output linear models.
//!
//! For `x_dot = A x + b u`, `y = c x` the transfer function is
//! `c (sI - A)^-1 b = [det(sI - A + b c) - det(sI - A)] / det(sI - A)`, so both numerator and
//! denominator come from characteristic polynomials, computed exactly (no root finding) by the
//! Faddeev-LeVerrier recursion.

use nalgebra::{Complex, DMatrix, DVector};
use serde::Serialize;

/// A rational transfer function, coefficients highest power first, denominator monic.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct TransferFunction {
    /// Numerator coefficients.
    pub num: Vec<f64>,
    /// Denominator coefficients (leading 1).
    pub den: Vec<f64>,
}

/// Characteristic polynomial `det(sI - A)`, highest power first (leading 1).
pub fn char_poly(a: &DMatrix<f64>) -> Vec<f64> {
    let n = a.nrows();
    let mut coeffs = vec![1.0; n + 1];
    let mut m = DMatrix::<f64>::zeros(n, n);
    let id = DMatrix::<f64>::identity(n, n);
    for k in 1..=n {
        m = a * &m + &id * coeffs[k - 1];
        coeffs[k] = -(a * &m).trace() / k as f64;
    }
    coeffs
}

impl TransferFunction {
    /// `c (sI - A)^-1 b` of a SISO model.
    pub fn from_state_space(a: &DMatrix<f64>, b: &DVector<f64>, c: &DVector<f64>) -> Self {
        let den = char_poly(a);
        let closed = char_poly(&(a - b * c.transpose()));
        let num: Vec<f64> = closed
            .iter()
            .zip(&den)
            .skip(1)
            .map(|(x, y)| x - y)
            .collect();
        Self { num, den }
    }

    /// Readable form `(n0 s^k + ...) / (s^n + ...)`.
    pub fn format(&self, digits: usize) -> String {
        format!(
            "({}) / ({})",
            poly_string(&self.num, digits),
            poly_string(&self.den, digits)
        )
    }

    /// Numerator with leading near-zero coefficients (below `tol` times the largest) removed.
    pub fn trimmed(&self, tol: f64) -> Self {
        let max = self.num.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let first = self
            .num
            .iter()
            .position(|x| x.abs() > tol * max)
            .unwrap_or(self.num.len().saturating_sub(1));
        Self {
            num: self.num[first..].to_vec(),
            den: self.den.clone(),
        }
    }
}

/// Polynomial product (coefficients highest power first).
pub fn poly_mul(a: &[f64], b: &[f64]) -> Vec<f64> {
    if a.is_empty() || b.is_empty() {
        return Vec::new();
    }
    let mut out = vec![0.0; a.len() + b.len() - 1];
    for (i, x) in a.iter().enumerate() {
        for (j, y) in b.iter().enumerate() {
            out[i + j] += x * y;
        }
    }
    out
}

/// Polynomial sum (coefficients highest power first).
pub fn poly_add(a: &[f64], b: &[f64]) -> Vec<f64> {
    let n = a.len().max(b.len());
    (0..n)
        .map(|k| {
            let ia = (k + a.len()).checked_sub(n).map_or(0.0, |i| a[i]);
            let ib = (k + b.len()).checked_sub(n).map_or(0.0, |i| b[i]);
            ia + ib
        })
        .collect()
}

/// The polynomial at a complex point (Horner).
pub fn poly_eval(p: &[f64], s: Complex<f64>) -> Complex<f64> {
    p.iter().fold(Complex::new(0.0, 0.0), |acc, &c| {
        acc * s + Complex::new(c, 0.0)
    })
}

/// Roots of a polynomial, as the eigenvalues of its companion matrix.
pub fn poly_roots(p: &[f64]) -> Vec<Complex<f64>> {
    let p = strip(p);
    let n = p.len().saturating_sub(1);
    if n == 0 {
        return Vec::new();
    }
    let a = DMatrix::from_fn(n, n, |i, j| {
        if i == n - 1 {
            -p[n - j] / p[0]
        } else if j == i + 1 {
            1.0
        } else {
            0.0
        }
    });
    super::lti::eigenvalues(&a)
}

fn strip(p: &[f64]) -> Vec<f64> {
    let first = p.iter().position(|x| *x != 0.0).unwrap_or(p.len());
    p[first..].to_vec()
}

impl TransferFunction {
    /// `num / den`, with leading zeros dropped and the denominator made monic.
    pub fn new(num: &[f64], den: &[f64]) -> Self {
        let den = strip(den);
        let lead = den.first().copied().unwrap_or(1.0);
        let num = strip(num);
        Self {
            num: if num.is_empty() {
                vec![0.0]
            } else {
                num.iter().map(|x| x / lead).collect()
            },
            den: den.iter().map(|x| x / lead).collect(),
        }
    }

    /// A pure gain.
    pub fn gain(k: f64) -> Self {
        Self::new(&[k], &[1.0])
    }

    /// `self * other`.
    pub fn series(&self, other: &Self) -> Self {
        Self::new(
            &poly_mul(&self.num, &other.num),
            &poly_mul(&self.den, &other.den),
        )
    }

    /// The closed loop `L / (1 + L)` of this loop transfer function under unity negative
    /// feedback.
    pub fn closed_loop(&self) -> Self {
        Self::new(&self.num, &poly_add(&self.den, &self.num))
    }

    /// Value at `s = j w`.
    pub fn eval(&self, w: f64) -> Complex<f64> {
        let s = Complex::new(0.0, w);
        poly_eval(&self.num, s) / poly_eval(&self.den, s)
    }

    /// Poles (roots of the denominator).
    pub fn poles(&self) -> Vec<Complex<f64>> {
        poly_roots(&self.den)
    }

    /// Unit-step response up to `t_end` at `dt` (RK4 on the controllable canonical form).
    /// The transfer function must be proper.
    pub fn step_response(&self, t_end: f64, dt: f64) -> (Vec<f64>, Vec<f64>) {
        let n = self.den.len() - 1;
        let mut b = vec![0.0; n + 1];
        let off = (n + 1).saturating_sub(self.num.len());
        for (i, x) in self.num.iter().enumerate() {
            if let Some(slot) = b.get_mut(off + i) {
                *slot = *x;
            }
        }
        let a_ = &self.den;
        let a = DMatrix::from_fn(n, n, |i, j| {
            if i == n - 1 {
                -a_[n - j]
            } else if j == i + 1 {
                1.0
            } else {
                0.0
            }
        });
        let bm = DMatrix::from_fn(n, 1, |i, _| if i == n - 1 { 1.0 } else { 0.0 });
        let c = DMatrix::from_fn(1, n, |_, j| b[n - j] - a_[n - j] * b[0]);
        let d = DMatrix::from_element(1, 1, b[0]);
        match super::lti::StateSpace::new(a, bm, c, d) {
            Ok(ss) => {
                let (t, y) = ss.step_response(0, t_end, dt);
                (t, y.iter().map(|v| v[0]).collect())
            }
            Err(_) => (Vec::new(), Vec::new()),
        }
    }
}

/// A polynomial as text, highest power first.
pub fn poly_string(c: &[f64], digits: usize) -> String {
    let n = c.len();
    let mut out = String::new();
    for (i, &x) in c.iter().enumerate() {
        let pow = n - 1 - i;
        let mag = format!("{:.*}", digits, x.abs());
        let term = match pow {
            0 => mag,
            1 if (x.abs() - 1.0).abs() < 1e-12 => "s".into(),
            1 => format!("{mag} s"),
            _ if (x.abs() - 1.0).abs() < 1e-12 => format!("s^{pow}"),
            _ => format!("{mag} s^{pow}"),
        };
        if i == 0 {
            if x < 0.0 {
                out.push('-');
            }
            out.push_str(&term);
        } else {
            out.push_str(if x < 0.0 { " - " } else { " + " });
            out.push_str(&term);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn second_order_by_hand() {
        // A = [[a11, a12], [a21, a22]], b = [b1, b2], y = x2:
        // num = b2 s + (a21 b1 - a11 b2), den = s^2 - (a11 + a22) s + (a11 a22 - a12 a21).
        let a = DMatrix::from_row_slice(2, 2, &[-7.56, 15.72, -7.405, -15.81]);
        let b = DVector::from_vec(vec![-2.703, -133.7]);
        let c = DVector::from_vec(vec![0.0, 1.0]);
        let tf = TransferFunction::from_state_space(&a, &b, &c);
        let d = |x: f64, y: f64| (x - y).abs() < 1e-9;
        assert!(d(tf.den[1], 7.56 + 15.81));
        assert!(d(tf.den[2], 7.56 * 15.81 + 15.72 * 7.405));
        assert!(d(tf.num[0], -133.7));
        assert!(d(tf.num[1], -7.405 * -2.703 - 7.56 * 133.7));
    }

    #[test]
    fn algebra_closed_loop_and_step() {
        // L = 4 / (s (s + 2)): closed loop 4 / (s^2 + 2 s + 4), wn 2, zeta 0.5.
        let l = TransferFunction::new(&[4.0], &[1.0, 2.0, 0.0]);
        let t = l.closed_loop();
        assert_eq!(t.den, vec![1.0, 2.0, 4.0]);
        let p = t.poles();
        assert!((p[0].re + 1.0).abs() < 1e-12 && (p[0].im.abs() - 3f64.sqrt()).abs() < 1e-12);
        let (_, y) = t.step_response(10.0, 0.001);
        let peak = y.iter().cloned().fold(0.0, f64::max);
        // Overshoot exp(-pi zeta / sqrt(1 - zeta^2)) = 16.3 %.
        assert!((peak - 1.163).abs() < 1e-3, "{peak}");
        assert!((t.eval(0.0).re - 1.0).abs() < 1e-12);
        let s =
            TransferFunction::new(&[1.0, 1.0], &[1.0, 3.0]).series(&TransferFunction::gain(2.0));
        assert_eq!(s.num, vec![2.0, 2.0]);
        assert_eq!(poly_add(&[1.0, 2.0], &[1.0, 0.0, 0.0]), vec![1.0, 1.0, 2.0]);
    }

    #[test]
    fn char_poly_of_a_companion_matrix() {
        // Companion matrix of s^3 + 2 s^2 + 3 s + 4.
        let a = DMatrix::from_row_slice(3, 3, &[0.0, 1.0, 0.0, 0.0, 0.0, 1.0, -4.0, -3.0, -2.0]);
        let p = char_poly(&a);
        for (x, y) in p.iter().zip([1.0, 2.0, 3.0, 4.0]) {
            assert!((x - y).abs() < 1e-12);
        }
    }
}

/// The three transfer functions the thesis prints, from a linearisation.
#[derive(Clone, Debug, Serialize)]
pub struct ThesisTransferFunctions {
    /// p / combined aileron, roll-only (one state p).
    pub p_over_da: TransferFunction,
    /// q / elevator, two-state short period (w, q).
    pub q_over_de: TransferFunction,
    /// r / rudder, four-state lateral model (v, p, r, phi).
    pub r_over_dr: TransferFunction,
}

/// Forms p/da, q/de and r/dr from the decoupled models.
pub fn thesis_transfer_functions(lin: &super::linearize::Linearization) -> ThesisTransferFunctions {
    let lat = &lin.lat;
    let lon = &lin.lon;
    // Lateral order v, p, r, phi, psi; inputs left, right aileron, rudder. Combined aileron
    // da moves the left surface by -da and the right by +da.
    let b_da = |i: usize| lat.b[(i, 1)] - lat.b[(i, 0)];
    let p_over_da = TransferFunction {
        num: vec![b_da(1)],
        den: vec![1.0, -lat.a[(1, 1)]],
    };
    // Longitudinal order u, w, q, theta, Ze, Omega; short period keeps w, q.
    let a_sp = DMatrix::from_fn(2, 2, |i, j| lon.a[(i + 1, j + 1)]);
    let b_sp = DVector::from_fn(2, |i, _| lon.b[(i + 1, 0)]);
    let q_over_de =
        TransferFunction::from_state_space(&a_sp, &b_sp, &DVector::from_vec(vec![0.0, 1.0]));
    let a4 = DMatrix::from_fn(4, 4, |i, j| lat.a[(i, j)]);
    let b4 = DVector::from_fn(4, |i, _| lat.b[(i, 2)]);
    let r_over_dr =
        TransferFunction::from_state_space(&a4, &b4, &DVector::from_vec(vec![0.0, 0.0, 1.0, 0.0]));
    ThesisTransferFunctions {
        p_over_da,
        q_over_de,
        r_over_dr,
    }
}
