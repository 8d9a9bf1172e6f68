//! The few statistics a campaign report needs: a binomial confidence interval, quantiles and
//! a rank correlation.

/// z of the two-sided 95 % normal interval.
pub const Z95: f64 = 1.959_963_984_540_054;

/// A share as a percentage with one decimal, as the reports print it.
pub fn pct(x: f64) -> String {
    format!("{:.1} %", 100.0 * x)
}

/// The Wilson score interval of a proportion `k` of `n` at the normal quantile `z`. Chosen
/// over the normal (Wald) interval because pass rates sit near 1, where Wald's collapses to
/// zero width, and over Clopper-Pearson because its coverage is close to nominal without
/// being as conservative.
pub fn wilson(k: u64, n: u64, z: f64) -> (f64, f64) {
    if n == 0 {
        return (0.0, 1.0);
    }
    let n = n as f64;
    let p = k as f64 / n;
    let z2 = z * z;
    let denom = 1.0 + z2 / n;
    let centre = (p + z2 / (2.0 * n)) / denom;
    let half = z * (p * (1.0 - p) / n + z2 / (4.0 * n * n)).sqrt() / denom;
    ((centre - half).max(0.0), (centre + half).min(1.0))
}

/// The `q` quantile of sorted values, linearly interpolated between order statistics.
pub fn quantile(sorted: &[f64], q: f64) -> f64 {
    match sorted.len() {
        0 => f64::NAN,
        1 => sorted[0],
        n => {
            let pos = q.clamp(0.0, 1.0) * (n - 1) as f64;
            let (i, frac) = (pos.floor() as usize, pos - pos.floor());
            let j = (i + 1).min(n - 1);
            sorted[i] + frac * (sorted[j] - sorted[i])
        }
    }
}

/// Ranks from 1, ties sharing their mean rank.
fn ranks(v: &[f64]) -> Vec<f64> {
    let mut idx: Vec<usize> = (0..v.len()).collect();
    idx.sort_by(|&a, &b| v[a].total_cmp(&v[b]));
    let mut r = vec![0.0; v.len()];
    let mut i = 0;
    while i < idx.len() {
        let mut j = i;
        while j + 1 < idx.len() && v[idx[j + 1]] == v[idx[i]] {
            j += 1;
        }
        let mean = 0.5 * (i + j) as f64 + 1.0;
        for &k in &idx[i..=j] {
            r[k] = mean;
        }
        i = j + 1;
    }
    r
}

/// Spearman's rank correlation of paired values; `None` with fewer than three pairs or when
/// either side is constant. A rank correlation because the figures are skewed (a few long
/// landings) and their relation to a quantity need only be monotonic.
pub fn spearman(x: &[f64], y: &[f64]) -> Option<f64> {
    if x.len() != y.len() || x.len() < 3 {
        return None;
    }
    let (rx, ry) = (ranks(x), ranks(y));
    let n = rx.len() as f64;
    let (mx, my) = (rx.iter().sum::<f64>() / n, ry.iter().sum::<f64>() / n);
    let (mut sxy, mut sxx, mut syy) = (0.0, 0.0, 0.0);
    for (a, b) in rx.iter().zip(&ry) {
        sxy += (a - mx) * (b - my);
        sxx += (a - mx) * (a - mx);
        syy += (b - my) * (b - my);
    }
    (sxx > 0.0 && syy > 0.0).then(|| sxy / (sxx * syy).sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wilson_matches_the_textbook_interval_for_990_of_1000() {
        // p = 0.99, n = 1000: centre 0.98812, half-width 0.00643 (Wilson 1927).
        let (lo, hi) = wilson(990, 1000, Z95);
        assert!((lo - 0.98169).abs() < 1e-5, "{lo}");
        assert!((hi - 0.99456).abs() < 1e-5, "{hi}");
        let (lo, hi) = wilson(1000, 1000, Z95);
        assert!((lo - 0.99617).abs() < 2e-5 && hi == 1.0, "{lo} {hi}");
    }

    #[test]
    fn quantiles_interpolate_between_order_statistics() {
        let v = [1.0, 2.0, 3.0, 4.0];
        assert_eq!(quantile(&v, 0.5), 2.5);
        assert_eq!(quantile(&v, 0.0), 1.0);
        assert_eq!(quantile(&v, 1.0), 4.0);
    }

    #[test]
    fn spearman_is_one_for_any_increasing_relation_and_shares_tied_ranks() {
        let x = [1.0, 2.0, 3.0, 4.0, 5.0];
        let y: Vec<f64> = x.iter().map(|v: &f64| v.powi(3)).collect();
        assert!((spearman(&x, &y).unwrap() - 1.0).abs() < 1e-12);
        let z: Vec<f64> = y.iter().map(|v| -v).collect();
        assert!((spearman(&x, &z).unwrap() + 1.0).abs() < 1e-12);
        assert_eq!(ranks(&[3.0, 1.0, 3.0]), vec![2.5, 1.0, 2.5]);
        assert!(spearman(&x, &[2.0; 5]).is_none());
    }
}
