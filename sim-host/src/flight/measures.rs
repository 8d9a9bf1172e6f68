//! Measures over a flight's samples that its figures share: the RMS and largest magnitude of
//! a series, and home's altitude datum that altitude errors are counted in.

use super::record::Sample;

/// Root mean square of `v`; NaN when empty.
pub fn rms(v: &[f64]) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt()
}

/// Largest magnitude in `v`; 0 when empty.
pub fn max_abs(v: &[f64]) -> f64 {
    v.iter().fold(0.0, |m, x| m.max(x.abs()))
}

/// Home's altitude as the autopilot holds it. Home is set at arming to the altitude above sea
/// level the estimator has then, and held in that datum: from then on its altitudes above sea
/// level (the estimate, the set points) differ from the truth's by that constant error, while
/// the heights above home it flies by do not. Altitude errors are counted in home's datum: the
/// truth shifted by the error home was set with.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HomeDatum {
    /// Arming time, s (infinite when never armed).
    pub set_at_s: f64,
    /// Estimated minus true altitude above sea level at arming, m.
    pub error_m: f64,
}

impl HomeDatum {
    /// The datum of a flight's samples.
    pub fn of(samples: &[Sample]) -> Self {
        samples.iter().find(|s| s.armed).map_or(
            Self {
                set_at_s: f64::INFINITY,
                error_m: 0.0,
            },
            |s| Self {
                set_at_s: s.t,
                error_m: s.est_alt - s.alt,
            },
        )
    }

    /// The true altitude of a sample in home's datum, m.
    pub fn truth_alt(&self, s: &Sample) -> f64 {
        if s.t >= self.set_at_s {
            s.alt + self.error_m
        } else {
            s.alt
        }
    }
}
