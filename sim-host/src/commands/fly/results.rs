//! `sim-host fly --report`'s document: the estimator's accuracy and the step figures of one
//! scripted flight flown on the estimate and on the truth.

use crate::flight::config::FlightConfig;
use crate::flight::runner::FlightOutcome;
use crate::report::sig;

/// `docs/RESULTS-SITL.md`: estimator accuracy of the flight and the step figures of the same
/// scripted flight flown on the estimate and on the truth (`SIM_USE_TRUTH`).
pub fn results_markdown(
    cfg: &FlightConfig,
    est: &FlightOutcome,
    truth: &FlightOutcome,
    command_line: &str,
) -> String {
    use std::fmt::Write;
    let s = &est.summary;
    let mut md = String::new();
    let _ = writeln!(md, "# Firmware in the loop: results\n");
    let _ = writeln!(
        md,
        "Produced by `{command_line}` (the firmware's `App` in-process, lock-step, seed {}, \
         {:.0} s simulated, wind ({}, {}, {}) m/s NED, {} turbulence). The flight starts \
         trimmed and level 100 m above home at 17 m/s; the simulator holds the trim until the \
         ground station has armed the autopilot (a hand launch with a safety pilot), then the \
         autopilot flies: Hold, the +100 m climb, four 90 deg right turns 30 s apart and a \
         +-10 m altitude doublet (`sim_host::flight::Script::thesis`). The script repeats no \
         command after its end; the rest of the flight is held level.\n",
        cfg.seed, s.sim_s, cfg.wind_ned[0], cfg.wind_ned[1], cfg.wind_ned[2], s.turbulence
    );
    let _ = writeln!(
        md,
        "## Estimator accuracy\n\nErrors of the firmware's estimate against the simulator's truth, \
         every frame (100 Hz). Two windows: from the first `converged` (the launch transient \
         included: arming follows within a second and the autopilot pulls the hand-launched \
         aircraft onto its course and into the +100 m climb), and from 30 s after it. Wind error \
         is horizontal, against the total wind at the aircraft (steady plus Dryden: the air mass \
         the wind triangle measures, and the target's reference) and, for comparison, against \
         the steady part alone. Targets: roll and pitch < 0.5 deg, heading < 2 deg, \
         altitude < 1 m, airspeed < 0.5 m/s, wind < 1 m/s.\n"
    );
    let _ = writeln!(
        md,
        "| quantity | RMS from convergence | max | RMS from 30 s after | max | target |\n|---|---|---|---|---|---|"
    );
    if let (Some(e), Some(l)) = (&s.estimator, &s.estimator_settled) {
        let _ = writeln!(
            md,
            "| window starts at (s) | {:.1} | | {:.1} | | |",
            e.from_s, l.from_s
        );
        let rows: [(&str, f64, f64, f64, f64, &str); 7] = [
            (
                "roll (deg)",
                e.roll_rms_deg,
                e.roll_max_deg,
                l.roll_rms_deg,
                l.roll_max_deg,
                "0.5",
            ),
            (
                "pitch (deg)",
                e.pitch_rms_deg,
                e.pitch_max_deg,
                l.pitch_rms_deg,
                l.pitch_max_deg,
                "0.5",
            ),
            (
                "heading (deg)",
                e.heading_rms_deg,
                e.heading_max_deg,
                l.heading_rms_deg,
                l.heading_max_deg,
                "2",
            ),
            (
                "altitude (m)",
                e.alt_rms_m,
                e.alt_max_m,
                l.alt_rms_m,
                l.alt_max_m,
                "1",
            ),
            (
                "airspeed (m/s)",
                e.airspeed_rms_mps,
                f64::NAN,
                l.airspeed_rms_mps,
                f64::NAN,
                "0.5",
            ),
            (
                "wind vs total (m/s)",
                e.wind_total_rms_mps,
                f64::NAN,
                l.wind_total_rms_mps,
                f64::NAN,
                "1",
            ),
            (
                "wind vs steady (m/s)",
                e.wind_rms_mps,
                f64::NAN,
                l.wind_rms_mps,
                f64::NAN,
                "",
            ),
        ];
        let m = |x: f64| if x.is_nan() { String::new() } else { sig(x, 3) };
        for (name, a, b, c, d, t) in rows {
            let _ = writeln!(
                md,
                "| {name} | {} | {} | {} | {} | {t} |",
                sig(a, 3),
                m(b),
                sig(c, 3),
                m(d)
            );
        }
        let _ = writeln!(md);
    }
    let _ = writeln!(
        md,
        "## Step figures: flown on the estimate vs on the truth\n\nThe same flight (same seed, \
         same turbulence) flown twice: on the autopilot's estimator, and with `SIM_USE_TRUTH` = 1 \
         on the simulator's HIL_STATE_QUATERNION. Figures of the true response, as chapter 4 reads \
         them (rise 10-90 %, overshoot, 2 % settling); the difference is (estimate - truth) / truth.\n"
    );
    let _ = writeln!(
        md,
        "| command | rise est. (s) | rise truth (s) | diff | overshoot est. (%) | overshoot truth (%) | settling est. (s) | settling truth (s) | diff | final error est. | final error truth |\n|---|---|---|---|---|---|---|---|---|---|---|"
    );
    let f = |x: Option<f64>| x.map_or("-".to_string(), |v| format!("{v:.1}"));
    let d = |a: Option<f64>, b: Option<f64>| match (a, b) {
        (Some(a), Some(b)) if b != 0.0 => format!("{:+.0} %", (a - b) / b * 100.0),
        _ => "-".into(),
    };
    for (a, b) in s.segments.iter().zip(&truth.summary.segments) {
        let unit = if a.signal == "altitude" { "m" } else { "deg" };
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} | {:.1} | {:.1} | {} | {} | {} | {:.2} {unit} | {:.2} {unit} |",
            a.what,
            f(a.metrics.rise_time_s),
            f(b.metrics.rise_time_s),
            d(a.metrics.rise_time_s, b.metrics.rise_time_s),
            a.metrics.overshoot_pct,
            b.metrics.overshoot_pct,
            f(a.metrics.settling_time_s),
            f(b.metrics.settling_time_s),
            d(a.metrics.settling_time_s, b.metrics.settling_time_s),
            a.final_error_max,
            b.final_error_max,
        );
    }
    if let Some(b) = &s.battery {
        let _ = writeln!(
            md,
            "\nBattery (the simulated 3S 3200 mAh pack, from full at power-up): {:.2} Wh and \
             {:.0} mAh drawn, lowest {:.2} V, {:.1} % left at the end (the autopilot's \
             estimate: {:.1} %).",
            b.energy_wh, b.charge_mah, b.min_voltage_v, b.final_remaining_pct, b.final_estimate_pct
        );
    }
    let _ = writeln!(
        md,
        "\nSpeed of this run: {:.1} s simulated in {:.2} s wall clock ({:.0}x real time, release build).",
        s.sim_s, s.wall_s, s.real_time_factor
    );
    md
}
