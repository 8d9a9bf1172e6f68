//! The tables printed after a flight: the run, the estimator's errors, the scripted commands'
//! responses, the mission and the battery.

use crate::flight::runner::FlightOutcome;
use crate::flight::strikes::kind;
use crate::flight::summary::{BatterySummary, MissionSummary};
use crate::report::sig;
use crate::report::table::Table;

/// The short summary printed after a flight.
pub fn summary_tables(r: &FlightOutcome) -> Vec<Table> {
    let s = &r.summary;
    let mut run = Table::new("Flight", &["quantity", "value"]);
    run.row(["simulated".to_string(), format!("{:.1} s", s.sim_s)]);
    run.row(["wall clock".to_string(), format!("{:.2} s", s.wall_s)]);
    run.row([
        "real-time factor".to_string(),
        if s.real_time_factor < 10.0 {
            format!("{:.2}x", s.real_time_factor)
        } else {
            format!("{:.0}x", s.real_time_factor)
        },
    ]);
    run.row(["frames".to_string(), s.frames.to_string()]);
    run.row(["ended".to_string(), s.ended.describe().to_string()]);
    run.row([
        "armed at".to_string(),
        s.armed_at_s.map_or("never".into(), |t| format!("{t:.1} s")),
    ]);
    if let (None, Some(td)) = (&s.mission, &s.touchdown) {
        // No mission known here (`sim-host sim`): where and how the wheels met the runway.
        run.row([
            "touchdown".to_string(),
            format!(
                "at {:.1} s, {:.1} m N {:.1} m E of home, sink {:.2} m/s, {:.1} m/s over ground, {} bounce(s)",
                td.time_s, td.north_m, td.east_m, td.sink_rate_mps, td.ground_speed_mps, td.bounces
            ),
        ]);
    }
    if let Some(td) = &s.lifted_after_disarm {
        run.row([
            "lifted after the disarm".to_string(),
            format!(
                "the wind lifted the aircraft off the runway; down again at {:.1} s, {:.1} m N {:.1} m E of home (not the landing)",
                td.time_s, td.north_m, td.east_m
            ),
        ]);
    }
    run.row([
        "wind, turbulence".to_string(),
        format!(
            "({}, {}, {}) m/s NED, {}",
            s.wind_ned[0], s.wind_ned[1], s.wind_ned[2], s.turbulence
        ),
    ]);
    let mut tables = vec![run];
    for (e, when) in [
        (&s.estimator, "convergence"),
        (&s.estimator_settled, "30 s after convergence"),
    ] {
        let Some(e) = e else { continue };
        let mut t = Table::new(
            format!("Estimator error from {when} ({:.1} s) to the end", e.from_s),
            &["quantity", "RMS", "max"],
        );
        t.row([
            "roll (deg)".into(),
            sig(e.roll_rms_deg, 3),
            sig(e.roll_max_deg, 3),
        ]);
        t.row([
            "pitch (deg)".into(),
            sig(e.pitch_rms_deg, 3),
            sig(e.pitch_max_deg, 3),
        ]);
        t.row([
            "heading (deg)".into(),
            sig(e.heading_rms_deg, 3),
            sig(e.heading_max_deg, 3),
        ]);
        t.row([
            "altitude in home's datum (m)".into(),
            sig(e.alt_rms_m, 3),
            sig(e.alt_max_m, 3),
        ]);
        t.row([
            "home's altitude, set at arming (m)".into(),
            sig(e.home_alt_error_m, 3),
            "".into(),
        ]);
        t.row([
            "airspeed (m/s)".into(),
            sig(e.airspeed_rms_mps, 3),
            "".into(),
        ]);
        t.row([
            "wind, steady (m/s)".into(),
            sig(e.wind_rms_mps, 3),
            "".into(),
        ]);
        t.row([
            "wind, with turbulence (m/s)".into(),
            sig(e.wind_total_rms_mps, 3),
            "".into(),
        ]);
        tables.push(t);
    }
    let mut seg = Table::new(
        "Scripted commands: true response",
        &[
            "t (s)",
            "command",
            "rise (s)",
            "overshoot (%)",
            "settling (s)",
            "final error",
            "alt. held in turn (m)",
        ],
    );
    for g in &s.segments {
        let unit = if g.signal == "altitude" { "m" } else { "deg" };
        seg.row([
            format!("{:.1}", g.t_s),
            g.what.clone(),
            g.metrics
                .rise_time_s
                .map_or("-".into(), |x| format!("{x:.1}")),
            format!("{:.1}", g.metrics.overshoot_pct),
            g.metrics
                .settling_time_s
                .map_or("-".into(), |x| format!("{x:.1}")),
            format!("{:.2} {unit}", g.final_error_max),
            if g.signal == "course" {
                format!("{:.2}", g.alt_hold_error_max_m)
            } else {
                "-".into()
            },
        ]);
    }
    if !s.segments.is_empty() {
        tables.push(seg);
    }
    if let Some(m) = &s.mission {
        tables.push(mission_table(m));
    }
    if let Some(b) = &s.battery {
        tables.push(battery_table(b));
    }
    tables
}

/// A figure to three significant digits, or "n/a" where it was not measured (the errors
/// against guidance of an autopilot seen only through its links).
fn known(x: f64, digits: usize) -> String {
    if x.is_nan() {
        "n/a".into()
    } else {
        sig(x, digits)
    }
}

/// What the flight took from the battery.
pub fn battery_table(b: &BatterySummary) -> Table {
    let mut t = Table::new("Battery", &["quantity", "value"]);
    t.row([
        "energy used (Wh)".to_string(),
        format!("{:.2}", b.energy_wh),
    ]);
    t.row([
        "charge used (mAh)".to_string(),
        format!("{:.0}", b.charge_mah),
    ]);
    t.row([
        "lowest voltage (V)".to_string(),
        format!("{:.2}", b.min_voltage_v),
    ]);
    t.row([
        "remaining at the end (%)".to_string(),
        if b.final_estimate_pct.is_finite() {
            format!(
                "{:.1} (the autopilot's estimate: {:.1})",
                b.final_remaining_pct, b.final_estimate_pct
            )
        } else {
            format!("{:.1}", b.final_remaining_pct)
        },
    ]);
    t
}

/// The figures of a mission flight.
pub fn mission_table(m: &MissionSummary) -> Table {
    let mut t = Table::new("Mission", &["quantity", "value"]);
    let mut row = |q: &str, v: String| {
        t.row([q.to_string(), v]);
    };
    row(
        "items reached",
        format!(
            "{} of {} navigation items{}",
            m.reached.len(),
            m.nav_items.len(),
            if m.all_reached { ", all" } else { "" }
        ),
    );
    row(
        "cross-track, straight legs (m)",
        format!(
            "{} RMS, {} max",
            known(m.xtrack_rms_m, 3),
            known(m.xtrack_max_m, 3)
        ),
    );
    row(
        "cross-track, on loiter circles (m)",
        format!("{} RMS", known(m.orbit_xtrack_rms_m, 3)),
    );
    row(
        "altitude error (m)",
        format!("{} RMS", known(m.alt_rms_m, 3)),
    );
    row(
        "airspeed error (m/s)",
        format!("{} RMS", known(m.airspeed_rms_mps, 3)),
    );
    row(
        "throttle on a stop in level cruise (%)",
        known(m.throttle_at_stops_pct, 3),
    );
    row("flight time (s)", format!("{:.1}", m.flight_time_s));
    row("motor energy (Wh)", format!("{:.2}", m.energy_wh));
    match &m.touchdown {
        Some(td) => {
            row(
                "touchdown",
                format!(
                    "{:.1} m from the landing point ({:+.1} m along), sink {:.2} m/s, {:.1} m/s over ground, {} bounce(s)",
                    td.distance_m, td.along_m, td.sink_rate_mps, td.ground_speed_mps, td.bounces
                ),
            );
        }
        None => row("touchdown", "none".into()),
    }
    let strikes: Vec<String> = m
        .strikes
        .iter()
        .map(|s| {
            format!(
                "{} at {:.1} s in {}, {:.1} cm deep",
                kind(&s.point),
                s.t_s,
                s.phase,
                s.depth_m * 100.0
            )
        })
        .collect();
    row(
        "strikes",
        if strikes.is_empty() {
            "none".into()
        } else {
            strikes.join("; ")
        },
    );
    row(
        "verdict",
        if m.pass {
            "pass".into()
        } else {
            format!("fail: {}", m.failed.join(", "))
        },
    );
    t
}
