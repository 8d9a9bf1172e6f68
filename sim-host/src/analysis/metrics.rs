//! Step-response figures: rise time (10-90 %), overshoot, settling time (2 %) and
//! steady-state error, as the thesis's chapter 4 reads them off its plots.

use serde::Serialize;

/// Figures of one step (or one segment of a doublet or multi-step command).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct StepMetrics {
    /// Size of the commanded step, in the signal's unit.
    pub step: f64,
    /// Time from 10 % to 90 % of the step, s; `None` if 90 % is never reached.
    pub rise_time_s: Option<f64>,
    /// Largest excursion past the command, in % of the step (0 if none).
    pub overshoot_pct: f64,
    /// Time after the step until the response stays within 2 % of the step of the command, s;
    /// `None` if it has not settled by the end of the segment.
    pub settling_time_s: Option<f64>,
    /// Command minus the mean response over the last 10 % of the segment.
    pub steady_state_error: f64,
}

/// Figures of the response `y(t)` to a step from `y0` to `target` at `t_step`, over the
/// samples with `t_step <= t < t_end`.
pub fn step_metrics(
    t: &[f64],
    y: &[f64],
    y0: f64,
    target: f64,
    t_step: f64,
    t_end: f64,
) -> StepMetrics {
    let step = target - y0;
    let seg: Vec<(f64, f64)> = t
        .iter()
        .zip(y)
        .filter(|(ti, _)| **ti >= t_step && **ti < t_end)
        .map(|(a, b)| (*a, *b))
        .collect();
    if seg.is_empty() || step == 0.0 {
        return StepMetrics {
            step,
            ..Default::default()
        };
    }
    // Progress towards the target as a fraction of the step (sign-free).
    let frac = |v: f64| (v - y0) / step;
    let crossing = |level: f64| {
        seg.windows(2)
            .find_map(|w| {
                let (a, b) = (frac(w[0].1), frac(w[1].1));
                (a < level && b >= level)
                    .then(|| w[0].0 + (level - a) / (b - a) * (w[1].0 - w[0].0))
            })
            .or_else(|| (frac(seg[0].1) >= level).then_some(seg[0].0))
    };
    let rise_time_s = match (crossing(0.1), crossing(0.9)) {
        (Some(a), Some(b)) => Some(b - a),
        _ => None,
    };
    let peak = seg.iter().map(|(_, v)| frac(*v)).fold(f64::MIN, f64::max);
    let overshoot_pct = ((peak - 1.0) * 100.0).max(0.0);
    let band = 0.02;
    let last_out = seg.iter().rposition(|(_, v)| (frac(*v) - 1.0).abs() > band);
    let settling_time_s = match last_out {
        None => Some(0.0),
        Some(i) if i + 1 < seg.len() => Some(seg[i + 1].0 - t_step),
        Some(_) => None,
    };
    let tail_start = t_end - 0.1 * (t_end - t_step);
    let tail: Vec<f64> = seg
        .iter()
        .filter(|(ti, _)| *ti >= tail_start)
        .map(|(_, v)| *v)
        .collect();
    let mean_tail = if tail.is_empty() {
        seg[seg.len() - 1].1
    } else {
        tail.iter().sum::<f64>() / tail.len() as f64
    };
    StepMetrics {
        step,
        rise_time_s,
        overshoot_pct,
        settling_time_s,
        steady_state_error: target - mean_tail,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A second-order step response with known figures: wn = 2 rad/s, zeta = 0.5 gives
    /// overshoot exp(-pi zeta / sqrt(1 - zeta^2)) = 16.3 %, 10-90 % rise 0.82 s, 2 % settling
    /// 3.7 s (a numerical property of this exact response, checked by the crossings below).
    fn second_order(t: f64) -> f64 {
        let (wn, z) = (2.0_f64, 0.5_f64);
        let wd = wn * (1.0 - z * z).sqrt();
        let phi = (1.0 - z * z).sqrt().atan2(z);
        1.0 - (-z * wn * t).exp() / (1.0 - z * z).sqrt() * (wd * t + phi).sin()
    }

    #[test]
    fn second_order_figures() {
        let t: Vec<f64> = (0..20_000).map(|k| k as f64 * 0.001).collect();
        let y: Vec<f64> = t.iter().map(|&t| 10.0 + 5.0 * second_order(t)).collect();
        let m = step_metrics(&t, &y, 10.0, 15.0, 0.0, 20.0);
        assert!((m.overshoot_pct - 16.30).abs() < 0.05, "{m:?}");
        assert!(
            (m.rise_time_s.unwrap_or(0.0) - 0.8192).abs() < 0.01,
            "{m:?}"
        );
        let ts = m.settling_time_s.unwrap_or(0.0);
        assert!(ts > 3.0 && ts < 4.2, "{m:?}");
        assert!(m.steady_state_error.abs() < 1e-3);
        // The same response downwards gives the same figures.
        let y: Vec<f64> = t.iter().map(|&t| -5.0 * second_order(t)).collect();
        let d = step_metrics(&t, &y, 0.0, -5.0, 0.0, 20.0);
        assert!((d.overshoot_pct - m.overshoot_pct).abs() < 1e-9);
    }

    #[test]
    fn a_response_that_never_arrives() {
        let t: Vec<f64> = (0..100).map(|k| k as f64 * 0.1).collect();
        let y: Vec<f64> = t.iter().map(|_| 0.5).collect();
        let m = step_metrics(&t, &y, 0.0, 1.0, 0.0, 10.0);
        assert_eq!(m.rise_time_s, None);
        assert_eq!(m.settling_time_s, None);
        assert!((m.steady_state_error - 0.5).abs() < 1e-12);
    }
}
