//! What a set of mission flights shows, as table cells and summaries: the targets each
//! flight is held to, and the spread of a set of windy flights. Shared by the tables of
//! `sim-host navigation` and its wind rose.

use crate::flight::summary::{MissionSummary, TouchdownSummary};
use crate::report::sig;

/// A figure under `limit`; one that was not measured (NaN: the errors against guidance of an
/// autopilot seen only through its links, the MCU image) is not held against the flight.
pub(super) fn under(figure: f64, limit: f64) -> bool {
    figure.is_nan() || figure < limit
}

/// The targets one flight is held to, each on its own (`calm`: the calm-air cross-track).
pub(super) struct TargetsMet {
    reached: bool,
    xtrack: bool,
    altitude: bool,
    airspeed: bool,
    touchdown: bool,
    sink: bool,
}

impl TargetsMet {
    pub(super) fn of(m: &MissionSummary, calm: bool) -> Self {
        let xt = if calm { 0.5 } else { 2.0 };
        Self {
            reached: m.all_reached,
            xtrack: under(m.xtrack_rms_m, xt),
            altitude: under(m.alt_rms_m, 1.5),
            airspeed: under(m.airspeed_rms_mps, 1.0),
            touchdown: m.touchdown.is_some_and(|t| t.distance_m < 20.0),
            sink: m.touchdown.is_some_and(|t| t.sink_rate_mps < 1.5),
        }
    }

    pub(super) fn all(&self) -> bool {
        self.reached && self.xtrack && self.altitude && self.airspeed && self.touchdown && self.sink
    }
}

/// Whether a flight meets the targets (`calm`: the calm-air cross-track target).
pub fn meets_targets(m: &MissionSummary, calm: bool) -> bool {
    TargetsMet::of(m, calm).all()
}

/// What a set of windy flights shows: how many meet each target, the worst figures and the
/// touchdowns' spread.
pub(super) struct Spread {
    n: usize,
    met: usize,
    reached: usize,
    xtrack: usize,
    altitude: usize,
    airspeed: usize,
    touchdown: usize,
    sink: usize,
    xtrack_max: f64,
    alt_max: f64,
    airspeed_max: f64,
    /// Touchdowns along the runway from the point, m, smallest first.
    along: Vec<f64>,
    /// Sink rates at touchdown, m/s, smallest first.
    sinks: Vec<f64>,
}

impl Spread {
    pub(super) fn of(flights: &[MissionSummary]) -> Self {
        let met: Vec<TargetsMet> = flights.iter().map(|m| TargetsMet::of(m, false)).collect();
        let count = |f: fn(&TargetsMet) -> bool| met.iter().filter(|t| f(t)).count();
        let max = |f: fn(&MissionSummary) -> f64| flights.iter().map(f).fold(f64::NAN, f64::max);
        let sorted = |f: fn(&TouchdownSummary) -> f64| {
            let mut v: Vec<f64> = flights
                .iter()
                .filter_map(|m| m.touchdown.as_ref().map(f))
                .collect();
            v.sort_by(f64::total_cmp);
            v
        };
        Self {
            n: flights.len(),
            met: count(TargetsMet::all),
            reached: count(|t| t.reached),
            xtrack: count(|t| t.xtrack),
            altitude: count(|t| t.altitude),
            airspeed: count(|t| t.airspeed),
            touchdown: count(|t| t.touchdown),
            sink: count(|t| t.sink),
            xtrack_max: max(|m| m.xtrack_rms_m),
            alt_max: max(|m| m.alt_rms_m),
            airspeed_max: max(|m| m.airspeed_rms_mps),
            along: sorted(|t| t.along_m),
            sinks: sorted(|t| t.sink_rate_mps),
        }
    }
}

/// The middle value of sorted figures (NaN for none).
pub(super) fn median(v: &[f64]) -> f64 {
    v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
}

/// A flight's touchdown as table cells: distance from the point (along the runway), and the
/// sink rate.
pub(super) fn touchdown_cells(m: &MissionSummary) -> (String, String) {
    m.touchdown.map_or(("none".into(), "-".into()), |t| {
        (
            format!("{:.1} ({:+.1})", t.distance_m, t.along_m),
            format!("{:.2}", t.sink_rate_mps),
        )
    })
}

/// A flight's verdict as a table cell: "yes", or "**no**" and what failed.
pub(super) fn verdict_cell(verdict: &Result<(), String>) -> String {
    verdict
        .as_ref()
        .map_or_else(|e| format!("**no**: {e}"), |()| "yes".into())
}

/// "first-last" of a run of seeds.
pub(super) fn seed_span(seeds: &[u64]) -> String {
    match (seeds.first(), seeds.last()) {
        (Some(a), Some(b)) => format!("{a}-{b}"),
        _ => "none".into(),
    }
}

/// One row of the results table: the worst figure of the flights and how many meet each
/// target.
pub(super) fn windy_row(label: &str, flights: &[MissionSummary]) -> String {
    let s = Spread::of(flights);
    let n = s.n;
    format!(
        "| {label} | all on {} of {n} | {} at most; under 2 on {} | {} at most | {} at most | \
         {:+.1} to {:+.1} m along; within 20 m on {} | {:.2} at most; under 1.5 on {} | on {} of {n} |",
        s.reached,
        sig(s.xtrack_max, 3),
        s.xtrack,
        sig(s.alt_max, 3),
        sig(s.airspeed_max, 3),
        s.along.first().copied().unwrap_or(f64::NAN),
        s.along.last().copied().unwrap_or(f64::NAN),
        s.touchdown,
        s.sinks.last().copied().unwrap_or(f64::NAN),
        s.sink,
        s.met,
    )
}

/// How many of the windy flights meet each target, and the spread of their touchdowns.
pub(super) fn spread_summary(flights: &[MissionSummary]) -> String {
    let s = Spread::of(flights);
    let n = s.n;
    let f = |x: Option<&f64>| x.map_or("-".to_string(), |x| format!("{x:+.1}"));
    format!(
        "Targets met on **{} of {n}** seeds. Per target: every waypoint {}/{n}, straight-leg \
         cross-track under 2 m {}/{n}, altitude under 1.5 m {}/{n}, airspeed under 1 m/s \
         {}/{n}, touchdown within 20 m {}/{n}, sink under 1.5 m/s {}/{n}. Touchdown along the \
         runway from the point: {} to {} m (median {:+.1}); sink rate median {:.2} m/s, \
         largest {}.\n",
        s.met,
        s.reached,
        s.xtrack,
        s.altitude,
        s.airspeed,
        s.touchdown,
        s.sink,
        f(s.along.first()),
        f(s.along.last()),
        median(&s.along),
        median(&s.sinks),
        s.sinks
            .last()
            .map_or("-".to_string(), |x| format!("{x:.2} m/s")),
    )
}
