//! Linear least squares taken in one sample at a time: the upper-triangular factor `R` of a
//! QR factorisation of the regressors, updated by Givens rotations as each row arrives.
//!
//! The normal equations (`X^T X`, `X^T y`) would square the regressors' condition number, and
//! in `f32` a fit of a roll damping (regressors of a few rad/s beside a constant) would lose
//! half its digits; the rotations keep it as `X` itself is conditioned. Memory is fixed
//! (`N x N + N + 4` floats), a row costs `O(N^2)`, so a fit spreads over as many control
//! periods as it has samples, and none of it needs the heap.

// The matrices and vectors are fixed-size and indexed with loop indices below their
// dimension: no index comes from outside.
#![allow(clippy::indexing_slicing)]

use nalgebra::{SMatrix, SVector};

/// Least squares over `N` regressors.
#[derive(Clone, Debug)]
pub struct LeastSquares<const N: usize> {
    /// Upper-triangular factor of the regressors.
    r: SMatrix<f32, N, N>,
    /// `Q^T y`: the right-hand side rotated with `r`.
    z: SVector<f32, N>,
    /// Residual sum of squares left over by the rotations.
    rss: f32,
    /// Sum and sum of squares of the measured outputs, for the variance they had to explain.
    y_sum: f32,
    y_sq: f32,
    rows: u32,
}

/// A solved fit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fit<const N: usize> {
    /// Coefficients, in the order of the regressors.
    pub coef: SVector<f32, N>,
    /// Each coefficient's standard error (the residuals' variance through `(X^T X)^-1`).
    pub std_err: SVector<f32, N>,
    /// Share of the outputs' variance the fit explains (R^2, 1 for a perfect fit).
    pub r2: f32,
    /// Rows taken in.
    pub rows: u32,
}

impl<const N: usize> Default for LeastSquares<N> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const N: usize> LeastSquares<N> {
    /// No rows yet.
    pub fn new() -> Self {
        Self {
            r: SMatrix::zeros(),
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

    /// Takes in one row: regressors `x`, output `y`. A row with a value that is not finite is
    /// left out (`false`), so a bad sample costs that sample only.
    pub fn push(&mut self, x: &SVector<f32, N>, y: f32) -> bool {
        if !y.is_finite() || x.iter().any(|v| !v.is_finite()) {
            return false;
        }
        // `x` and `y` are rotated into the factor; what is left of `y` is the row's residual.
        let mut x = *x;
        let resid = rotate_in(
            self.r.as_mut_slice(),
            self.z.as_mut_slice(),
            x.as_mut_slice(),
            y,
        );
        self.rss += resid * resid;
        self.y_sum += y;
        self.y_sq += y * y;
        self.rows += 1;
        true
    }

    /// The fit, or `None` while some regressor has not varied independently of the others
    /// (a diagonal of `R` under `1e-6` of the largest: that regressor was not excited).
    pub fn solve(&self) -> Option<Fit<N>> {
        let scale = (0..N).map(|i| self.r[(i, i)].abs()).fold(0.0, f32::max);
        if self.rows <= N as u32 || scale <= 0.0 {
            return None;
        }
        if (0..N).any(|i| self.r[(i, i)].abs() <= 1e-6 * scale) {
            return None;
        }
        // R^-1 by nalgebra's back substitution: the coefficients are R^-1 Q^T y, and
        // (X^T X)^-1 = R^-1 R^-T gives each coefficient's variance as a row of R^-1 squared.
        let inv = self
            .r
            .solve_upper_triangular(&SMatrix::<f32, N, N>::identity())?;
        let coef = inv * self.z;
        let dof = (self.rows - N as u32) as f32;
        let sigma2 = self.rss / dof;
        let mut std_err = SVector::<f32, N>::zeros();
        for i in 0..N {
            std_err[i] = libm::sqrtf(sigma2 * inv.row(i).norm_squared());
        }
        let n = self.rows as f32;
        let total = self.y_sq - self.y_sum * self.y_sum / n;
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

/// The rotations of [`LeastSquares::push`]: the row `x`, `y` rotated into the factor `r`
/// (column-major, as many columns as `x` has elements) and its right-hand side `z`; what is
/// left of `y` is returned. Apart from the generic `push` and not inlined: one copy for every
/// size of fit (the MCU image had one inlined for each of the autotune's four sizes).
#[inline(never)]
fn rotate_in(r: &mut [f32], z: &mut [f32], x: &mut [f32], y: f32) -> f32 {
    let n = x.len();
    let mut resid = y;
    for i in 0..n {
        let diag = i * n + i;
        let (Some(&a), Some(&b)) = (r.get(diag), x.get(i)) else {
            break;
        };
        if b == 0.0 {
            continue;
        }
        let h = libm::hypotf(a, b);
        let (c, s) = (a / h, b / h);
        if let Some(d) = r.get_mut(diag) {
            *d = h;
        }
        if let Some(xi) = x.get_mut(i) {
            *xi = 0.0;
        }
        // Column j of the factor holds row i's element j at its index i.
        for (col, xj) in r.chunks_exact_mut(n).zip(x.iter_mut()).skip(i + 1) {
            if let Some(rij) = col.get_mut(i) {
                let (r0, x0) = (*rij, *xj);
                *rij = c * r0 + s * x0;
                *xj = c * x0 - s * r0;
            }
        }
        if let Some(zi) = z.get_mut(i) {
            let z0 = *zi;
            *zi = c * z0 + s * resid;
            resid = c * resid - s * z0;
        }
    }
    resid
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The rotations as `push` wrote them on nalgebra's matrices before they moved out of line.
    fn push_on_matrices<const N: usize>(
        r: &mut SMatrix<f32, N, N>,
        z: &mut SVector<f32, N>,
        x: &SVector<f32, N>,
        y: f32,
    ) -> f32 {
        let (mut x, mut resid) = (*x, y);
        for i in 0..N {
            let (a, b) = (r[(i, i)], x[i]);
            if b == 0.0 {
                continue;
            }
            let h = libm::hypotf(a, b);
            let (c, s) = (a / h, b / h);
            r[(i, i)] = h;
            x[i] = 0.0;
            for j in i + 1..N {
                let (rij, xj) = (r[(i, j)], x[j]);
                r[(i, j)] = c * rij + s * xj;
                x[j] = c * xj - s * rij;
            }
            let zi = z[i];
            z[i] = c * zi + s * resid;
            resid = c * resid - s * zi;
        }
        resid
    }

    fn same_bits_as_on_matrices<const N: usize>() {
        let mut state = 0x2545_F491_u32 ^ N as u32;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            // Some exact zeros among the regressors: the rotations skip them.
            if state.is_multiple_of(7) {
                0.0
            } else {
                (state >> 8) as f32 / (1 << 23) as f32 * 4.0 - 1.0
            }
        };
        let mut ls = LeastSquares::<N>::new();
        let (mut r, mut z, mut rss) = (SMatrix::<f32, N, N>::zeros(), SVector::zeros(), 0.0f32);
        for _ in 0..200 {
            let x = SVector::<f32, N>::from_fn(|_, _| next());
            let y = next();
            assert!(ls.push(&x, y));
            let resid = push_on_matrices(&mut r, &mut z, &x, y);
            rss += resid * resid;
            assert!(ls
                .r
                .iter()
                .zip(r.iter())
                .all(|(a, b)| a.to_bits() == b.to_bits()));
            assert!(ls
                .z
                .iter()
                .zip(z.iter())
                .all(|(a, b)| a.to_bits() == b.to_bits()));
            assert_eq!(ls.rss.to_bits(), rss.to_bits());
        }
    }

    #[test]
    fn rows_rotated_out_of_line_give_the_factor_of_the_rotations_on_matrices_to_the_bit() {
        same_bits_as_on_matrices::<2>();
        same_bits_as_on_matrices::<5>();
        same_bits_as_on_matrices::<6>();
        same_bits_as_on_matrices::<8>();
    }
}
