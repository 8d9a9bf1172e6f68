//! Figures of a run: step metrics of every step of the command, their worst case, peak
//! surface deflections, and the excursions used to tell a bounded flight from a divergent one.

use super::sim::Run;
use super::{Axis, Scenario};
use crate::analysis::metrics::{step_metrics, StepMetrics};
use serde::Serialize;

/// One step of the command and the response's figures over it (until the next step).
#[derive(Clone, Copy, Debug, Serialize)]
pub struct Segment {
    /// Time of the step, s.
    pub t_step_s: f64,
    /// Command before the step (deg or m).
    pub from: f64,
    /// Command after it.
    pub to: f64,
    /// Figures (rise 10-90 %, overshoot, settling 2 %, steady-state error over the last 10 %).
    pub metrics: StepMetrics,
}

/// Everything read off one run.
#[derive(Clone, Debug, Serialize)]
pub struct RunMetrics {
    /// Scenario.
    pub scenario: &'static str,
    /// Gain set.
    pub gains: String,
    /// Noise sigma the run was flown with.
    pub noise_sigma: f64,
    /// Unit of the commanded quantity.
    pub unit: &'static str,
    /// Per step of the command.
    pub segments: Vec<Segment>,
    /// Slowest 10-90 % rise time over the steps, s (`None` if some step never reached 90 %).
    pub rise_time_s: Option<f64>,
    /// Largest overshoot over the steps, %.
    pub overshoot_pct: f64,
    /// Slowest 2 % settling time over the steps, s (`None` if some step never settled).
    pub settling_time_s: Option<f64>,
    /// Largest |steady-state error| over the steps (deg or m).
    pub steady_state_error: f64,
    /// Peak |elevator|, deg.
    pub peak_elevator_deg: f64,
    /// Peak |aileron|, deg.
    pub peak_aileron_deg: f64,
    /// Peak |rudder|, deg.
    pub peak_rudder_deg: f64,
    /// Peak |roll|, deg.
    pub peak_roll_deg: f64,
    /// Peak |pitch|, deg.
    pub peak_pitch_deg: f64,
    /// Peak |pitch command|, deg (altitude modes; 0 when the pitch loop was never asked).
    pub peak_pitch_cmd_deg: f64,
    /// Lowest and highest altitude, m.
    pub alt_range_m: [f64; 2],
    /// Lowest and highest airspeed, m/s.
    pub airspeed_range_mps: [f64; 2],
    /// Altitude scenarios: time from the first step until the altitude first comes within 2 %
    /// of the first step of the command, s.
    pub time_to_2pct_s: Option<f64>,
    /// Ripple: RMS of the tracking error about its mean over the second half of every held
    /// segment (deg or m), where a settled loop shows only what noise and limit cycles leave
    /// (a steady offset is not ripple).
    pub ripple_rms: f64,
    /// Lowest and highest pitch in the climb regime, deg, over the second half of the time
    /// spent in it, less its last second (`None` if the run spends under 4 s in it): a settled
    /// climb shows a narrow range, a cycling airspeed-by-pitch loop a wide one.
    pub climb_regime_pitch_deg: Option<[f64; 2]>,
    /// Lowest and highest throttle over the second half of the run.
    pub throttle_range_tail: [f64; 2],
    /// Surface activity: mean |change| per second of the surface of the loop under test
    /// (aileron, rudder or elevator), deg/s.
    pub surface_activity_dps: f64,
    /// Ticks on which the autopilot refused an input.
    pub rejected_ticks: u32,
}

fn abs_max(it: impl Iterator<Item = f64>) -> f64 {
    it.fold(0.0, |a, v| if v.is_finite() { a.max(v.abs()) } else { a })
}

fn range(it: impl Iterator<Item = f64>) -> [f64; 2] {
    it.fold([f64::INFINITY, f64::NEG_INFINITY], |[lo, hi], v| {
        [lo.min(v), hi.max(v)]
    })
}

/// Reads the figures off a run of `scenario`.
pub fn run_metrics(scenario: &Scenario, run: &Run) -> RunMetrics {
    let s = &run.samples;
    let t: Vec<f64> = s.iter().map(|x| x.t).collect();
    let y: Vec<f64> = s.iter().map(|x| x.response).collect();
    let t_end = t.last().copied().unwrap_or(0.0) + run.config.dt_s;
    let cmd_at = |time: f64| s.iter().rev().find(|x| x.t <= time).map(|x| x.command);
    let initial = s.first().map_or(0.0, |x| x.command);
    let mut segments = Vec::new();
    let mut from = initial;
    for (i, (ts, _)) in scenario.steps.iter().enumerate() {
        let to = cmd_at(*ts).unwrap_or(from);
        let end = scenario.steps.get(i + 1).map_or(t_end, |n| n.0);
        segments.push(Segment {
            t_step_s: *ts,
            from,
            to,
            metrics: step_metrics(&t, &y, from, to, *ts, end),
        });
        from = to;
    }
    let rise_time_s = segments
        .iter()
        .map(|g| g.metrics.rise_time_s)
        .try_fold(0.0f64, |a, r| r.map(|r| a.max(r)));
    let settling_time_s = segments
        .iter()
        .map(|g| g.metrics.settling_time_s)
        .try_fold(0.0f64, |a, r| r.map(|r| a.max(r)));
    let overshoot_pct = segments
        .iter()
        .map(|g| g.metrics.overshoot_pct)
        .fold(0.0, f64::max);
    let steady_state_error = abs_max(segments.iter().map(|g| g.metrics.steady_state_error));
    let time_to_2pct_s = match (scenario.axis, segments.first()) {
        (Axis::Altitude, Some(g)) => {
            let band = 0.02 * (g.to - g.from).abs();
            s.iter()
                .find(|x| x.t >= g.t_step_s && (x.response - g.to).abs() <= band)
                .map(|x| x.t - g.t_step_s)
        }
        _ => None,
    };
    // Ripple over the second half of each held segment (also before the first step).
    let mut bounds: Vec<(f64, f64)> = Vec::new();
    let mut start = 0.0;
    for (ts, _) in scenario.steps {
        bounds.push((start, *ts));
        start = *ts;
    }
    bounds.push((start, t_end));
    let (mut sq, mut n) = (0.0, 0usize);
    for (a, b) in bounds {
        let mid = 0.5 * (a + b);
        let err: Vec<f64> = s
            .iter()
            .filter(|x| x.t >= mid && x.t < b)
            .map(|x| x.response - x.command)
            .collect();
        if err.is_empty() {
            continue;
        }
        let mean = err.iter().sum::<f64>() / err.len() as f64;
        sq += err.iter().map(|e| (e - mean).powi(2)).sum::<f64>();
        n += err.len();
    }
    let ripple_rms = if n > 0 { (sq / n as f64).sqrt() } else { 0.0 };
    let surface = |x: &super::sim::Sample| match scenario.axis {
        Axis::Roll | Axis::Heading => x.aileron_deg,
        Axis::Sideslip => x.rudder_deg,
        Axis::Pitch | Axis::Altitude | Axis::Airspeed => x.elevator_deg,
    };
    let travel: f64 = s
        .windows(2)
        .map(|w| (surface(&w[1]) - surface(&w[0])).abs())
        .sum();
    let duration = (t_end - run.config.dt_s).max(run.config.dt_s);
    let climb: Vec<&super::sim::Sample> = s.iter().filter(|x| x.regime == 1).collect();
    let climb_regime_pitch_deg = match (climb.first(), climb.last()) {
        (Some(a), Some(b)) if b.t - a.t > 4.0 => Some(range(
            climb
                .iter()
                .filter(|x| x.t >= 0.5 * (a.t + b.t) && x.t <= b.t - 1.0)
                .map(|x| x.pitch_deg),
        )),
        _ => None,
    };
    RunMetrics {
        climb_regime_pitch_deg,
        scenario: run.scenario,
        gains: run.gains.clone(),
        noise_sigma: run.config.noise_sigma,
        unit: scenario.axis.unit(),
        segments,
        rise_time_s,
        overshoot_pct,
        settling_time_s,
        steady_state_error,
        peak_elevator_deg: abs_max(s.iter().map(|x| x.elevator_deg)),
        peak_aileron_deg: abs_max(s.iter().map(|x| x.aileron_deg)),
        peak_rudder_deg: abs_max(s.iter().map(|x| x.rudder_deg)),
        peak_roll_deg: abs_max(s.iter().map(|x| x.roll_deg)),
        peak_pitch_deg: abs_max(s.iter().map(|x| x.pitch_deg)),
        peak_pitch_cmd_deg: abs_max(s.iter().map(|x| x.pitch_cmd_deg)),
        alt_range_m: range(s.iter().map(|x| x.alt_msl_m)),
        airspeed_range_mps: range(s.iter().map(|x| x.airspeed_mps)),
        time_to_2pct_s,
        ripple_rms,
        throttle_range_tail: range(s.iter().filter(|x| x.t >= 0.5 * t_end).map(|x| x.throttle)),
        surface_activity_dps: travel / duration,
        rejected_ticks: run.rejected_ticks,
    }
}
