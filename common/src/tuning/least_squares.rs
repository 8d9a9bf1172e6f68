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
        let (mut coef, mut std_err) = (SVector::<f32, N>::zeros(), SVector::<f32, N>::zeros());
        let mut inv = SMatrix::<f32, N, N>::zeros();
        let r2 = solve_into(
            self.r.as_slice(),
            self.z.as_slice(),
            [self.rss, self.y_sum, self.y_sq],
            self.rows,
            inv.as_mut_slice(),
            coef.as_mut_slice(),
            std_err.as_mut_slice(),
        )?;
        Some(Fit {
            coef,
            std_err,
            r2,
            rows: self.rows,
        })
    }
}

/// [`LeastSquares::solve`] on the factor's storage (`r` column-major, as many columns as `z` has
/// elements), with `inv` as room for `R^-1`: writes the coefficients and their standard errors,
/// returns R^2. Apart from the generic `solve` and not inlined, as [`rotate_in`]. The
/// operations are those of nalgebra's back substitution and products, in their order, so the
/// fits are the same to the bit.
#[inline(never)]
fn solve_into(
    r: &[f32],
    z: &[f32],
    [rss, y_sum, y_sq]: [f32; 3],
    rows: u32,
    inv: &mut [f32],
    coef: &mut [f32],
    std_err: &mut [f32],
) -> Option<f32> {
    let n = z.len();
    let diag = |i: usize| r.get(i * n + i).copied().unwrap_or(0.0);
    let scale = (0..n).map(|i| diag(i).abs()).fold(0.0, f32::max);
    if rows <= n as u32 || scale <= 0.0 {
        return None;
    }
    if (0..n).any(|i| diag(i).abs() <= 1e-6 * scale) {
        return None;
    }
    // R^-1 by back substitution, a column of the identity at a time: the coefficients are
    // R^-1 Q^T y, and (X^T X)^-1 = R^-1 R^-T gives each coefficient's variance as a row of
    // R^-1 squared.
    for (k, col) in inv.chunks_exact_mut(n).enumerate() {
        for (i, e) in col.iter_mut().enumerate() {
            *e = if i == k { 1.0 } else { 0.0 };
        }
        for (i, r_col) in r.chunks_exact(n).enumerate().rev() {
            let d = diag(i);
            if d == 0.0 {
                return None;
            }
            let coeff = col.get(i).copied().unwrap_or(0.0) / d;
            if let Some(e) = col.get_mut(i) {
                *e = coeff;
            }
            for (e, &rk) in col.iter_mut().zip(r_col).take(i) {
                *e += -coeff * rk;
            }
        }
    }
    // Row i of R^-1 times Q^T y, the products summed in column order from the first.
    for (i, c) in coef.iter_mut().enumerate() {
        let mut terms = inv
            .chunks_exact(n)
            .zip(z)
            .map(|(col, &zj)| col.get(i).copied().unwrap_or(0.0) * zj);
        if let Some(first) = terms.next() {
            *c = terms.fold(first, |acc, t| t + acc);
        }
    }
    let dof = (rows - n as u32) as f32;
    let sigma2 = rss / dof;
    for (i, se) in std_err.iter_mut().enumerate() {
        let row_sq = inv
            .chunks_exact(n)
            .map(|col| col.get(i).copied().unwrap_or(0.0))
            .fold(0.0, |acc: f32, v| acc + v * v);
        *se = libm::sqrtf(sigma2 * row_sq);
    }
    let total = y_sq - y_sum * y_sum / rows as f32;
    Some(if total > 0.0 { 1.0 - rss / total } else { 0.0 })
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
        let h = crate::math::elementary::hypot(a, b);
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
            assert_eq!(bits(ls.solve()), bits(solve_on_matrices(&ls)));
        }
        assert!(ls.solve().is_some());
    }

    /// The fit as `solve` took it from nalgebra before it moved out of line.
    fn solve_on_matrices<const N: usize>(ls: &LeastSquares<N>) -> Option<Fit<N>> {
        let scale = (0..N).map(|i| ls.r[(i, i)].abs()).fold(0.0, f32::max);
        if ls.rows <= N as u32 || scale <= 0.0 {
            return None;
        }
        if (0..N).any(|i| ls.r[(i, i)].abs() <= 1e-6 * scale) {
            return None;
        }
        let inv =
            ls.r.solve_upper_triangular(&SMatrix::<f32, N, N>::identity())?;
        let coef = inv * ls.z;
        let dof = (ls.rows - N as u32) as f32;
        let sigma2 = ls.rss / dof;
        let mut std_err = SVector::<f32, N>::zeros();
        for i in 0..N {
            std_err[i] = libm::sqrtf(sigma2 * inv.row(i).norm_squared());
        }
        let n = ls.rows as f32;
        let total = ls.y_sq - ls.y_sum * ls.y_sum / n;
        let r2 = if total > 0.0 {
            1.0 - ls.rss / total
        } else {
            0.0
        };
        Some(Fit {
            coef,
            std_err,
            r2,
            rows: ls.rows,
        })
    }

    fn bits<const N: usize>(f: Option<Fit<N>>) -> Option<([u32; N], [u32; N], u32)> {
        f.map(|f| {
            (
                core::array::from_fn(|i| f.coef[i].to_bits()),
                core::array::from_fn(|i| f.std_err[i].to_bits()),
                f.r2.to_bits(),
            )
        })
    }

    #[test]
    fn rows_rotated_out_of_line_give_the_factor_of_the_rotations_on_matrices_to_the_bit() {
        same_bits_as_on_matrices::<2>();
        same_bits_as_on_matrices::<5>();
        same_bits_as_on_matrices::<6>();
        same_bits_as_on_matrices::<8>();
    }
}
