//! `sim-host laws`: the two longitudinal laws side by side, the successive loop closure (the
//! flight defaults, `LON_LAW` = 0) and the total energy control (`LON_LAW` = 1, its designed
//! gains): the longitudinal chapter-4 scenarios on the nonlinear plant, and the default mission
//! flown by the firmware in calm air and in wind with light turbulence. Written as a section of
//! `docs/RESULTS.md`.

use super::fly::{fly_report, FlyOptions};
use super::navigation::WIND_NED;
use super::scenario::{fly, gain_set, level_trim, FLIGHT_TECS};
use crate::aircraft::Aircraft;
use crate::environment::wind::Turbulence;
use crate::flight::config::FlightConfig;
use crate::flight::measures::rms;
use crate::flight::missions::{default_mission, runway_mission};
use crate::flight::record::Sample as FlightSample;
use crate::flight::runner::FlightOutcome;
use crate::flight::summary::share_on_stop_pct;
use crate::plant::params::ModelParams;
use crate::report::{sig, sig_or_dash};
use crate::scenario::sim::{Run, SimConfig};
use crate::scenario::{Axis, Scenario, AIRSPEED_MPS};
use anyhow::Context;
use std::fmt::Write as _;

/// Name of the section `sim-host laws` writes into `docs/RESULTS.md`.
pub const SECTION: &str = "laws";

/// The longitudinal scenarios of chapter 4 both laws fly.
pub const SCENARIOS: [&str; 5] = [
    "altitude_step",
    "altitude_doublet",
    "climb",
    "altitude_step_small",
    "airspeed_step_small",
];

/// The two laws: the gain-set name a scenario flies, and the `LON_LAW` the firmware is given.
pub const LAWS: [(&str, &str, f32); 2] = [
    ("successive loop closure", "flight", 0.0),
    ("total energy control", FLIGHT_TECS, 1.0),
];

/// Throttle travel per second: the sum of the throttle's changes over the time, 1/s.
pub fn throttle_travel_per_s(throttle: &[f64], duration_s: f64) -> f64 {
    let travel: f64 = throttle.windows(2).map(|w| (w[1] - w[0]).abs()).sum();
    if duration_s > 0.0 {
        travel / duration_s
    } else {
        f64::NAN
    }
}

/// One scenario run's figures: the step's own and the coupling into the other quantity.
struct ScenarioRow {
    rise_s: Option<f64>,
    overshoot_pct: f64,
    settling_s: Option<f64>,
    /// Largest departure of the quantity not commanded: airspeed from 17 m/s in the altitude
    /// scenarios, altitude from its start in the airspeed one.
    coupling: f64,
    travel_per_s: f64,
    on_stop_pct: f64,
}

fn scenario_row(sc: &Scenario, run: &Run, m: &crate::scenario::metrics::RunMetrics) -> ScenarioRow {
    let s = &run.samples;
    let h0 = s.first().map_or(0.0, |x| x.alt_msl_m);
    let coupling = s
        .iter()
        .map(|x| match sc.axis {
            Axis::Airspeed => (x.alt_msl_m - h0).abs(),
            _ => (x.airspeed_mps - AIRSPEED_MPS).abs(),
        })
        .fold(0.0, f64::max);
    let thr: Vec<f64> = s.iter().map(|x| x.throttle).collect();
    ScenarioRow {
        rise_s: m.rise_time_s,
        overshoot_pct: m.overshoot_pct,
        settling_s: m.settling_time_s,
        coupling,
        travel_per_s: throttle_travel_per_s(&thr, sc.duration_s),
        on_stop_pct: share_on_stop_pct(&thr),
    }
}

/// The default mission from the runway, the firmware given `LON_LAW` = `law` by the scripted
/// ground station before arming, as a user would set it.
pub fn fly_mission(
    aircraft: &Aircraft,
    law: f32,
    wind_ned: [f64; 3],
    turbulence: Turbulence,
    seed: u64,
) -> anyhow::Result<FlightOutcome> {
    let mut cfg = FlightConfig {
        wind_ned,
        turbulence,
        seed,
        ..runway_mission(default_mission(ModelParams::new(aircraft).home))
    };
    cfg.script.params.push(("LON_LAW".into(), law));
    Ok(fly_report(aircraft, &cfg, &FlyOptions::default())?.outcome)
}

/// RMS of the altitude error (truth against the altitude guidance asked for) while banked
/// more than 10 deg, m: what the turns cost the height.
fn turn_alt_rms(samples: &[FlightSample]) -> f64 {
    let e: Vec<f64> = samples
        .iter()
        .filter(|x| x.armed && x.roll.abs() > 10f64.to_radians() && x.sp_alt.is_finite())
        .map(|x| x.alt - x.sp_alt)
        .collect();
    rms(&e)
}

/// The section: every figure with the command that produces it (`command`). `seeds`: the
/// windy flights' seeds.
pub fn laws_markdown(aircraft: &Aircraft, command: &str, seeds: &[u64]) -> anyhow::Result<String> {
    let mut md = String::new();
    let _ = writeln!(
        md,
        "## Longitudinal laws compared: successive loop closure and total energy control\n\n\
         Written by `{command}`. The same aircraft and lateral loops flown with the \
         longitudinal law of the flight defaults (`LON_LAW` = 0: the regimes of Figure 3-16, \
         altitude by pitch and airspeed by throttle in the band) and with the total energy \
         control (`LON_LAW` = 1, its designed gains, docs/PARAMETERS.md): throttle on the \
         total energy rate, pitch on its balance. Coupling is the largest departure of the \
         quantity not commanded (airspeed from 17 m/s while the altitude changes, altitude \
         while the airspeed does); throttle travel is the sum of its changes per second; on a \
         stop is the share of the time at 0 or 1 (within 1 %).\n\n\
         ### Chapter-4 scenarios (nonlinear plant, truth, no noise; `sim-host scenario NAME \
         --gains flight,{FLIGHT_TECS}`)\n\n\
         | scenario | law | rise 10-90 % (s) | overshoot (%) | settling 2 % (s) | coupling | throttle travel (1/s) | throttle on a stop (%) |\n\
         |---|---|---:|---:|---:|---:|---:|---:|"
    );
    let trim = level_trim(aircraft)?;
    let sets = LAWS
        .iter()
        .map(|(_, n, _)| Ok((n.to_string(), gain_set(aircraft, n)?)))
        .collect::<anyhow::Result<Vec<_>>>()?;
    for name in SCENARIOS {
        let sc = Scenario::by_name(name).map_err(|e| anyhow::anyhow!(e))?;
        let r = fly(aircraft, &trim, sc, &sets, &SimConfig::default())?;
        let unit = if sc.axis == Axis::Airspeed {
            "m"
        } else {
            "m/s"
        };
        for ((law, set, _), (run, m)) in LAWS.iter().zip(r.runs.iter().zip(&r.metrics)) {
            debug_assert_eq!(run.gains, *set);
            let row = scenario_row(sc, run, m);
            let _ = writeln!(
                md,
                "| `{name}` | {law} | {} | {} | {} | {} {unit} | {} | {} |",
                sig_or_dash(row.rise_s, 3),
                sig(row.overshoot_pct, 3),
                sig_or_dash(row.settling_s, 3),
                sig(row.coupling, 3),
                sig(row.travel_per_s, 3),
                sig(row.on_stop_pct, 3),
            );
        }
    }
    let _ = writeln!(
        md,
        "\n### The default mission (firmware in the loop, on its estimates; `sim-host fly \
         --mission default --param LON_LAW=N [--wind=-3,-4,0 --turbulence light --seed S]`)\n\n\
         Altitude and airspeed errors are the truth's against guidance over the flight; in \
         turns, the altitude error's RMS while banked more than 10 deg. Energy: what the motor \
         drew from the battery.\n\n\
         | air | law | items | altitude RMS (m) | altitude RMS in turns (m) | airspeed RMS (m/s) | throttle travel (1/s) | throttle on a stop in level cruise (%) | energy (Wh) | flight (s) | touchdown from the point (m), sink (m/s) |\n\
         |---|---|---|---:|---:|---:|---:|---:|---:|---:|---|"
    );
    let mut cases = vec![("calm".to_string(), [0.0; 3], Turbulence::None, 1)];
    for s in seeds {
        cases.push((
            format!(
                "wind ({}, {}, {}) m/s, light turbulence, seed {s}",
                WIND_NED[0], WIND_NED[1], WIND_NED[2]
            ),
            WIND_NED,
            Turbulence::Light,
            *s,
        ));
    }
    for (air, wind, turb, seed) in cases {
        for (law, _, value) in LAWS {
            let o = fly_mission(aircraft, value, wind, turb, seed)?;
            let m = o
                .summary
                .mission
                .clone()
                .context("the flight flew no mission")?;
            let armed: Vec<&FlightSample> = o.samples.iter().filter(|x| x.armed).collect();
            let thr: Vec<f64> = armed.iter().map(|x| x.throttle).collect();
            let span = match (armed.first(), armed.last()) {
                (Some(a), Some(b)) => b.t - a.t,
                _ => 0.0,
            };
            let td = m.touchdown.map_or("none".into(), |t| {
                format!("{:.1}, {:.2}", t.distance_m, t.sink_rate_mps)
            });
            let _ = writeln!(
                md,
                "| {air} | {law} | {}/{} | {} | {} | {} | {} | {} | {:.2} | {:.0} | {td} |",
                m.reached.len(),
                m.nav_items.len(),
                sig(m.alt_rms_m, 3),
                sig(turn_alt_rms(&o.samples), 3),
                sig(m.airspeed_rms_mps, 3),
                sig(throttle_travel_per_s(&thr, span), 3),
                sig(m.throttle_at_stops_pct, 3),
                m.energy_wh,
                m.flight_time_s,
            );
        }
    }
    Ok(md)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn throttle_travel_and_share_on_a_stop() {
        // 0.5 -> 0.7 -> 0.4 -> 1.0: travel 0.2 + 0.3 + 0.6 = 1.1 over 2 s.
        let t = [0.5, 0.7, 0.4, 1.0];
        assert!((throttle_travel_per_s(&t, 2.0) - 0.55).abs() < 1e-12);
        assert!(throttle_travel_per_s(&t, 0.0).is_nan());
        assert_eq!(share_on_stop_pct(&t), 25.0);
        assert_eq!(share_on_stop_pct(&[0.0, 0.005, 0.5, 0.995]), 75.0);
        assert!(share_on_stop_pct(&[]).is_nan());
    }
}
