//! Linear least squares taken in one sample at a time: the upper-triangular factor `R` of a
//! QR factorisation of the regressors, updated by Givens rotations as each row arrives.
//!
//! The normal equations (`X^T X`, `X^T y`) would square the regressors' condition number, and
//! in `f32` a fit of a roll damping (regressors of a few rad/s beside a constant) would lose
//! half its digits; the rotations keep it as `X` itself is conditioned. Memory is fixed
//! (`MAX x MAX + MAX + 4` floats), a row of `N` regressors costs `O(N^2)`, so a fit spreads over as many control
//! periods as it has samples, and none of it needs the heap.

// The matrices and vectors are fixed-size and indexed with loop indices below the fit's
// number of regressors, itself at most their dimension: no index comes from outside.
#![allow(clippy::indexing_slicing)]

use nalgebra::{SMatrix, SVector};

/// Most regressors a fit takes.
pub const MAX: usize = 8;

/// Least squares over up to [`MAX`] regressors, their number set at run time: one copy of
/// the code serves every model (a const-generic size per model put each size's unrolled
/// rotations in the MCU image, some 4 KB of its flash budget).
#[derive(Clone, Debug)]
pub struct LeastSquares {
    /// Regressors taken (1..=MAX).
    n: usize,
    /// Upper-triangular factor of the regressors; the identity beyond `n`, so that the
    /// solve of the whole block gives zeros there.
    r: SMatrix<f32, MAX, MAX>,
    /// `Q^T y`: the right-hand side rotated with `r`.
    z: SVector<f32, MAX>,
    /// Residual sum of squares left over by the rotations.
    rss: f32,
    /// Sum and sum of squares of the measured outputs, for the variance they had to explain.
    y_sum: f32,
    y_sq: f32,
    rows: u32,
}

/// A solved fit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fit {
    /// Coefficients, in the order of the regressors (0 beyond their number).
    pub coef: [f32; MAX],
    /// Each coefficient's standard error (the residuals' variance through `(X^T X)^-1`).
    pub std_err: [f32; MAX],
    /// Share of the outputs' variance the fit explains (R^2, 1 for a perfect fit).
    pub r2: f32,
    /// Rows taken in.
    pub rows: u32,
}

impl LeastSquares {
    /// No rows yet, over `n` regressors (at least 1, at most [`MAX`]).
    pub fn new(n: usize) -> Self {
        let n = n.clamp(1, MAX);
        let mut r = SMatrix::zeros();
        for i in n..MAX {
            r[(i, i)] = 1.0;
        }
        Self {
            n,
            r,
            z: SVector::zeros(),
            rss: 0.0,
            y_sum: 0.0,
            y_sq: 0.0,
            rows: 0,
        }
    }

    /// Rows taken in so far.
    pub fn rows(&self) -> u32 {
        self.rows
    }

    /// Takes in one row: regressors `x` (as many as the fit's), output `y`. A row with a value
    /// that is not finite, or of another length, is left out (`false`), so a bad sample costs
    /// that sample only.
    pub fn push(&mut self, x: &[f32], y: f32) -> bool {
        let n = self.n;
        if x.len() != n || !y.is_finite() || x.iter().any(|v| !v.is_finite()) {
            return false;
        }
        // `x` and `y` are rotated into the factor; what is left of `y` is the row's residual.
        let mut row = [0.0; MAX];
        for (d, v) in row.iter_mut().zip(x) {
            *d = *v;
        }
        let mut resid = y;
        for i in 0..n {
            let (a, b) = (self.r[(i, i)], row[i]);
            if b == 0.0 {
                continue;
            }
            let h = libm::hypotf(a, b);
            let (c, s) = (a / h, b / h);
            self.r[(i, i)] = h;
            row[i] = 0.0;
            // `j` indexes the factor's row and the regressors' together.
            #[allow(clippy::needless_range_loop)]
            for j in i + 1..n {
                let (rij, xj) = (self.r[(i, j)], row[j]);
                self.r[(i, j)] = c * rij + s * xj;
                row[j] = c * xj - s * rij;
            }
            let zi = self.z[i];
            self.z[i] = c * zi + s * resid;
            resid = c * resid - s * zi;
        }
        self.rss += resid * resid;
        self.y_sum += y;
        self.y_sq += y * y;
        self.rows += 1;
        true
    }

    /// The fit, or `None` while some regressor has not varied independently of the others
    /// (a diagonal of `R` under `1e-6` of the largest: that regressor was not excited).
    pub fn solve(&self) -> Option<Fit> {
        let n = self.n;
        let scale = (0..n).map(|i| self.r[(i, i)].abs()).fold(0.0, f32::max);
        if self.rows <= n as u32 || scale <= 0.0 {
            return None;
        }
        if (0..n).any(|i| self.r[(i, i)].abs() <= 1e-6 * scale) {
            return None;
        }
        // R^-1 by nalgebra's back substitution: the coefficients are R^-1 Q^T y, and
        // (X^T X)^-1 = R^-1 R^-T gives each coefficient's variance as a row of R^-1 squared.
        // Beyond `n` the factor is the identity and `z` zero: the inverse is block-diagonal,
        // those coefficients 0 and the rows of the first `n` untouched by them.
        let inv = self
            .r
            .solve_upper_triangular(&SMatrix::<f32, MAX, MAX>::identity())?;
        let coef_v = inv * self.z;
        let dof = (self.rows - n as u32) as f32;
        let sigma2 = self.rss / dof;
        let (mut coef, mut std_err) = ([0.0; MAX], [0.0; MAX]);
        for i in 0..n {
            coef[i] = coef_v[i];
            std_err[i] = libm::sqrtf(sigma2 * inv.row(i).norm_squared());
        }
        let total = self.y_sq - self.y_sum * self.y_sum / self.rows as f32;
        let r2 = if total > 0.0 {
            1.0 - self.rss / total
        } else {
            0.0
        };
        Some(Fit {
            coef,
            std_err,
            r2,
            rows: self.rows,
        })
    }
}
