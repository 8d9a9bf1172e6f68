//! Transfer functions of single-input single-output linear models.
//!
//! For `x_dot = A x + b u`, `y = c x` the transfer function is
//! `c (sI - A)^-1 b = [det(sI - A + b c) - det(sI - A)] / det(sI - A)`, so both numerator and
//! denominator come from characteristic polynomials, computed exactly (no root finding) by the
//! Faddeev-LeVerrier recursion.

use nalgebra::{DMatrix, DVector};
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
