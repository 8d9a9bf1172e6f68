//! The scalar Kalman measurement update shared by the estimator's filters.
//!
//! Every measurement is fused one component at a time: no matrix inverse (nothing to be
//! singular), and each component can be gated on its own.

// The matrices and vectors are fixed-size and indexed with loop indices below their
// dimension: no index comes from outside.
#![allow(clippy::indexing_slicing)]

use crate::math::clamp;
use nalgebra::{SMatrix, SVector};

/// Why a measurement component was not fused.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Refused {
    /// The innovation was beyond the gate: an outlier, or the filter has lost track.
    Gated,
    /// The innovation variance was not a positive finite number.
    Degenerate,
}

impl core::fmt::Display for Refused {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(match self {
            Refused::Gated => "innovation beyond the gate",
            Refused::Degenerate => "innovation variance not positive and finite",
        })
    }
}

impl core::error::Error for Refused {}

/// The outcome of one fused component.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fused<const N: usize> {
    /// State correction.
    pub dx: SVector<f32, N>,
    /// Normalised innovation squared, `innov^2 / S`.
    pub nis: f32,
}

/// The gain of one scalar measurement: `P h`, the innovation variance and what the state moves
/// by.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Gain<const N: usize> {
    ph: SVector<f32, N>,
    s: f32,
    /// The outcome: the state correction and the normalised innovation.
    pub fused: Fused<N>,
}

/// The gain of one scalar measurement `z = h . x + noise(r)` given its innovation
/// `z - h . x_pred`, or why it is refused. `P h` reads only the columns where `h` is non-zero
/// (one to six of them in the estimator). `p` is not changed: see [`downdate`].
pub fn gain<const N: usize>(
    p: &SMatrix<f32, N, N>,
    h: &SVector<f32, N>,
    innov: f32,
    r: f32,
    gate_sigma: f32,
) -> Result<Gain<N>, Refused> {
    let mut ph = SVector::<f32, N>::zeros();
    let [acc] = &mut ph.data.0;
    for (col, &hj) in p.data.0.iter().zip(h.iter()) {
        if hj != 0.0 {
            for (a, &x) in acc.iter_mut().zip(col) {
                *a += x * hj;
            }
        }
    }
    let s = h.dot(&ph) + r;
    if !(s.is_finite() && s > 0.0 && innov.is_finite()) {
        return Err(Refused::Degenerate);
    }
    let nis = innov * innov / s;
    if nis > gate_sigma * gate_sigma {
        return Err(Refused::Gated);
    }
    Ok(Gain {
        ph,
        s,
        fused: Fused {
            dx: ph * (innov / s),
            nis,
        },
    })
}

/// The covariance after the measurement of `g`. With the optimal gain `k = P h / s`, the
/// Joseph form `(I - k h') P (I - k h')' + k r k'` equals `P - (P h)(P h)' / s`: a symmetric
/// rank-one downdate. Only its upper triangle is computed (91 products for 13 states instead
/// of two dense 13x13x13 products) and mirrored, so `p` stays exactly symmetric; the caller's
/// conditioning keeps its diagonal positive. Returns false, with `p` untouched, when the
/// result would hold a non-finite entry.
pub fn downdate<const N: usize>(p: &mut SMatrix<f32, N, N>, g: &Gain<N>) -> bool {
    let k = g.ph / g.s;
    let ([k], [ph]) = (&k.data.0, &g.ph.data.0);
    // `p` by columns: `p[(i, j)]` is `cols[j][i]`; the upper triangle is `i <= j`.
    let cols = &mut p.data.0;
    // Checked before anything is written: no copy of `p` is needed to keep it on refusal.
    let mut finite = 0.0;
    for (j, (col, &phj)) in cols.iter().zip(ph).enumerate() {
        for (&pij, &ki) in col.iter().zip(k).take(j + 1) {
            finite = finite_sum(finite, pij - ki * phj);
        }
    }
    if finite != 0.0 {
        return false;
    }
    for (j, (col, &phj)) in cols.iter_mut().zip(ph).enumerate() {
        for (pij, &ki) in col.iter_mut().zip(k).take(j + 1) {
            *pij -= ki * phj;
        }
    }
    mirror_upper(cols);
    true
}

/// `sum` plus `x * 0`: zero while every `x` given is finite, NaN from the first that is not
/// (`x * 0` is NaN for an infinity or a NaN, and a NaN stays). Two operations a value, no
/// branch.
#[inline(always)]
fn finite_sum(sum: f32, x: f32) -> f32 {
    sum + x * 0.0
}

/// Copies the upper triangle of the matrix whose columns are `cols` onto its lower one.
#[inline(always)]
fn mirror_upper<const N: usize>(cols: &mut [[f32; N]; N]) {
    for j in 1..N {
        let (left, right) = cols.split_at_mut(j);
        if let Some(col) = right.first() {
            for (left_col, &v) in left.iter_mut().zip(col) {
                if let Some(lower) = left_col.get_mut(j) {
                    *lower = v;
                }
            }
        }
    }
}

/// Fuses one scalar measurement: [`gain`] then [`downdate`]. Returns the correction to add to
/// the state, or why the measurement was refused (then `p` is untouched).
pub fn scalar_update<const N: usize>(
    p: &mut SMatrix<f32, N, N>,
    h: &SVector<f32, N>,
    innov: f32,
    r: f32,
    gate_sigma: f32,
) -> Result<Fused<N>, Refused> {
    let g = gain(p, h, innov, r, gate_sigma)?;
    if !downdate(p, &g) {
        return Err(Refused::Degenerate);
    }
    Ok(g.fused)
}

/// Keeps the diagonal of `p` between `min_var` and `max_var`: the conditioning of a
/// covariance already exactly symmetric and finite (as [`downdate`] leaves it).
pub fn clamp_diagonal<const N: usize>(p: &mut SMatrix<f32, N, N>, min_var: f32, max_var: f32) {
    for (j, col) in p.data.0.iter_mut().enumerate() {
        if let Some(d) = col.get_mut(j) {
            *d = clamp(*d, min_var, max_var);
        }
    }
}

/// Makes `p` exactly symmetric and keeps its diagonal between `min_var` and `max_var`, in
/// place (no temporary matrix).
///
/// Returns false when `p` holds a non-finite entry (the caller then resets the filter); `p`
/// is then left as it was.
pub fn condition<const N: usize>(p: &mut SMatrix<f32, N, N>, min_var: f32, max_var: f32) -> bool {
    let cols = &mut p.data.0;
    let finite = cols
        .iter()
        .flatten()
        .fold(0.0, |sum, &x| finite_sum(sum, x));
    if finite != 0.0 {
        return false;
    }
    // `p[(i, j)]` is `cols[j][i]`: each pair above and below the diagonal is met once, at its
    // column `j` and row `i < j`.
    for j in 1..N {
        let (left, right) = cols.split_at_mut(j);
        if let Some(col) = right.first_mut() {
            for (left_col, upper) in left.iter_mut().zip(col.iter_mut()) {
                if let Some(lower) = left_col.get_mut(j) {
                    let v = 0.5 * (*upper + *lower);
                    *upper = v;
                    *lower = v;
                }
            }
        }
    }
    clamp_diagonal(p, min_var, max_var);
    true
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix2, Vector2};

    #[test]
    fn scalar_update_matches_the_textbook_gain() {
        // One state, prior variance 4, measurement variance 1: K = 4/5, posterior 4/5.
        let mut p = SMatrix::<f32, 1, 1>::new(4.0);
        let f = scalar_update(&mut p, &SVector::<f32, 1>::new(1.0), 10.0, 1.0, 100.0).unwrap();
        assert!((f.dx[0] - 8.0).abs() < 1e-5);
        assert!((p[(0, 0)] - 0.8).abs() < 1e-6);
        assert!((f.nis - 20.0).abs() < 1e-4);
    }

    #[test]
    fn gate_and_degenerate_leave_p_alone() {
        let mut p = Matrix2::new(1.0, 0.0, 0.0, 1.0);
        let h = Vector2::new(1.0, 0.0);
        assert_eq!(
            scalar_update(&mut p, &h, 100.0, 1.0, 5.0),
            Err(Refused::Gated)
        );
        assert_eq!(
            scalar_update(&mut p, &h, f32::NAN, 1.0, 5.0),
            Err(Refused::Degenerate)
        );
        assert_eq!(
            scalar_update(&mut p, &h, 1.0, -2.0, 5.0),
            Err(Refused::Degenerate)
        );
        assert_eq!(p, Matrix2::identity());
        let mut bad = Matrix2::new(f32::NAN, 0.0, 0.0, 1.0);
        assert!(!condition(&mut bad, 1e-9, 1e9));
    }

    /// The indexed forms these functions had: the loops over columns must give the same
    /// bits (the host's flights do not change with them).
    fn reference(p: &mut SMatrix<f32, 13, 13>, h: &SVector<f32, 13>) -> bool {
        let mut ph = SVector::<f32, 13>::zeros();
        for (j, &hj) in h.iter().enumerate() {
            if hj != 0.0 {
                ph += p.column(j) * hj;
            }
        }
        let s = h.dot(&ph) + 0.1;
        let k = ph / s;
        let mut finite = true;
        for j in 0..13 {
            for i in 0..=j {
                finite &= (p[(i, j)] - k[i] * ph[j]).is_finite();
            }
        }
        if !finite {
            return false;
        }
        for j in 0..13 {
            for i in 0..=j {
                let v = p[(i, j)] - k[i] * ph[j];
                p[(i, j)] = v;
                p[(j, i)] = v;
            }
        }
        true
    }

    #[test]
    fn the_column_loops_equal_the_indexed_forms_to_the_bit() {
        // Entries with every bit of the mantissa in use: sines of integers.
        let entry = |k: usize| libm::sinf(k as f32);
        for case in 0..40 {
            let a = SMatrix::<f32, 13, 13>::from_fn(|i, j| entry(case * 997 + i * 13 + j));
            // Not exactly symmetric, as the prediction leaves it before conditioning.
            let skew =
                SMatrix::<f32, 13, 13>::from_fn(|i, j| entry(case * 991 + i * 17 + j) * 1e-3);
            let p0 = a * a.transpose() + skew;
            let mut h = SVector::<f32, 13>::zeros();
            for j in 0..13 {
                if (j + case) % 4 == 0 {
                    h[j] = entry(case * 89 + j);
                }
            }
            let mut want = p0;
            if case == 7 {
                want[(2, 5)] = f32::INFINITY;
            }
            let mut got = want;
            let kept = reference(&mut want, &h);
            let g = gain(&got, &h, 0.3, 0.1, f32::INFINITY);
            let done = g.map(|g| downdate(&mut got, &g));
            assert_eq!(done.is_ok_and(|d| d), kept, "{case}");
            for (x, y) in got.iter().zip(want.iter()) {
                assert_eq!(x.to_bits(), y.to_bits(), "{case}");
            }
            // The conditioning, against its indexed form.
            let mut want = p0;
            for j in 0..13 {
                for i in 0..j {
                    let v = 0.5 * (want[(i, j)] + want[(j, i)]);
                    want[(i, j)] = v;
                    want[(j, i)] = v;
                }
                want[(j, j)] = clamp(want[(j, j)], 0.05, 2.0);
            }
            let mut got = p0;
            assert!(condition(&mut got, 0.05, 2.0));
            for (x, y) in got.iter().zip(want.iter()) {
                assert_eq!(x.to_bits(), y.to_bits(), "{case}");
            }
        }
    }

    #[test]
    fn the_symmetric_downdate_equals_the_joseph_form() {
        // A full, positive definite 5x5 covariance and a measurement of two states at once:
        // the textbook Joseph form, in f64, is the reference.
        let a = SMatrix::<f64, 5, 5>::from_fn(|i, j| ((i * 7 + j * 3) % 5) as f64 * 0.3 - 0.5);
        let p64 = a * a.transpose() + SMatrix::<f64, 5, 5>::identity() * 0.7;
        let h64 = SVector::<f64, 5>::new(0.0, 1.0, 0.0, -1.0, 0.0);
        let r = 0.25;
        let ph = p64 * h64;
        let s = h64.dot(&ph) + r;
        let k = ph / s;
        let ikh = SMatrix::<f64, 5, 5>::identity() - k * h64.transpose();
        let joseph = ikh * p64 * ikh.transpose() + k * k.transpose() * r;
        let mut p = p64.cast::<f32>();
        let f = scalar_update(&mut p, &h64.cast::<f32>(), 0.5, r as f32, 100.0).unwrap();
        for i in 0..5 {
            assert!((f.dx[i] as f64 - k[i] * 0.5).abs() < 1e-6, "{i}");
            for j in 0..5 {
                assert!(
                    (p[(i, j)] as f64 - joseph[(i, j)]).abs() < 1e-5,
                    "({i}, {j})"
                );
                assert_eq!(p[(i, j)], p[(j, i)]);
            }
        }
    }
}
