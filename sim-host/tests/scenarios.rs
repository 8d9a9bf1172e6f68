//! The closed-loop tests of thesis chapter 4 on the nonlinear plant: design requirements,
//! boundedness of every gain set in every scenario, reproducible noise, and bad input.

use sim_host::aircraft::Aircraft;
use sim_host::analysis::trim::TrimResult;
use sim_host::commands::scenario::{
    fly, gain_set, gain_set_names, level_trim, scenario_report, write_result, ScenarioOptions,
    ScenarioResult,
};
use sim_host::scenario::metrics::RunMetrics;
use sim_host::scenario::sim::SimConfig;
use sim_host::scenario::{Scenario, SCENARIOS};
use std::sync::OnceLock;

mod support;

fn aircraft() -> &'static Aircraft {
    static A: OnceLock<Aircraft> = OnceLock::new();
    A.get_or_init(|| Aircraft::ultrastick25e().unwrap())
}

fn trim() -> &'static TrimResult {
    static T: OnceLock<TrimResult> = OnceLock::new();
    T.get_or_init(|| level_trim(aircraft()).unwrap())
}

fn fly_sets(name: &str, sets: &[&str], cfg: &SimConfig) -> ScenarioResult {
    let a = aircraft();
    let sets: Vec<_> = sets
        .iter()
        .map(|n| (n.to_string(), gain_set(a, n).unwrap()))
        .collect();
    fly(a, trim(), Scenario::by_name(name).unwrap(), &sets, cfg).unwrap()
}

fn of<'a>(r: &'a ScenarioResult, set: &str) -> &'a RunMetrics {
    r.metrics_of(set).unwrap()
}

/// The requirements of thesis section 3.3 on the nonlinear plant, with servos and the two-sample
/// delay, for the computed set (the one that meets all of them; see docs/RESULTS.md for the
/// others). Inner loops: 10-90 % rise under 1 s. Outer loops (heading, altitude): overshoot
/// under 5 %. Pitch: overshoot up to 7 %, read on the first step, from trim. The return step of
/// the pitch doublet starts from an unsettled, faster-than-trim state and overshoots more for
/// every set (RESULTS.md gives the numbers).
#[test]
fn design_requirements_hold_for_the_computed_set() {
    let cfg = SimConfig::default();
    let set = "computed";
    let roll = fly_sets("roll_doublet", &[set], &cfg);
    for seg in &of(&roll, set).segments {
        let rise = seg.metrics.rise_time_s.unwrap();
        assert!(rise < 1.0, "roll rise {rise} s");
    }
    let pitch = fly_sets("pitch_doublet", &[set], &cfg);
    let m = of(&pitch, set);
    for seg in &m.segments {
        let rise = seg.metrics.rise_time_s.unwrap();
        assert!(rise < 1.0, "pitch rise {rise} s");
    }
    let first = m.segments[0].metrics;
    assert!(first.overshoot_pct <= 7.0, "pitch overshoot {first:?}");

    let heading = fly_sets("heading_doublet", &[set], &cfg);
    let m = of(&heading, set);
    assert!(
        m.overshoot_pct < 5.0,
        "heading overshoot {}",
        m.overshoot_pct
    );
    assert!(m.settling_time_s.unwrap() < 10.0);
    let rect = fly_sets("heading_rectangle", &[set], &cfg);
    assert!(of(&rect, set).overshoot_pct < 5.0);

    let alt = fly_sets("altitude_step", &[set], &cfg);
    let m = of(&alt, set);
    assert!(
        m.overshoot_pct < 5.0,
        "altitude overshoot {}",
        m.overshoot_pct
    );
    // The computed altitude integrator is slow on purpose (its zero sits well below the
    // loop's bandwidth to keep the overshoot down): after the 40 s run the error is within 5 %
    // of the 5 m step.
    assert!(m.rise_time_s.is_some_and(|r| r < 15.0), "{m:?}");
    assert!(m.steady_state_error.abs() < 0.25, "{m:?}");

    // Climb of 100 m: "about 20 s" (thesis section 4.3.2, read off Figure 4-15). Taken as
    // 15 to 25 s to within 2 % (2 m): 15 s is below what the pitch limit allows (100 m at
    // 17 m/s and 20 deg takes 100 / (17 sin 20 deg) = 17.2 s), 25 s is 25 % over the thesis.
    let climb = fly_sets("climb", &[set], &cfg);
    let m = of(&climb, set);
    let t = m.time_to_2pct_s.unwrap();
    assert!((15.0..=25.0).contains(&t), "climb took {t} s");
    assert!(m.overshoot_pct < 5.0, "climb overshoot {}", m.overshoot_pct);
    let limit = 20.0 + 1e-3;
    assert!(m.peak_pitch_cmd_deg <= limit, "{}", m.peak_pitch_cmd_deg);
    // The commanded pitch does use the limit (the climb is limit-bound, not gain-bound).
    assert!(m.peak_pitch_cmd_deg > 19.9);
    assert!(m.alt_range_m[1] < 202.0);
}

/// Inner-loop rise time also holds for the designed and computed sets, which are faster than
/// Minnesota's on roll (the thesis's claim for Figure 4-1).
#[test]
fn inner_loops_of_designed_and_computed_rise_within_1_s() {
    let cfg = SimConfig::default();
    let roll = fly_sets("roll_doublet", &["designed", "computed", "minnesota"], &cfg);
    let pitch = fly_sets("pitch_doublet", &["designed", "computed"], &cfg);
    for set in ["designed", "computed"] {
        let r = of(&roll, set).rise_time_s.unwrap();
        assert!(r < 1.0 && r < of(&roll, "minnesota").rise_time_s.unwrap());
        assert!(of(&pitch, set).segments[0].metrics.rise_time_s.unwrap() < 1.0);
    }
}

fn bounded(m: &RunMetrics) -> bool {
    m.peak_roll_deg < 60.0
        && m.peak_pitch_deg < 30.0
        && m.alt_range_m[0] > 50.0
        && m.alt_range_m[1] < 250.0
        && m.airspeed_range_mps[0] > 10.0
        && m.airspeed_range_mps[1] < 30.0
        && m.rejected_ticks == 0
}

/// Every set flies every scenario with bounded attitude, altitude and airspeed, and follows the
/// command to within a sane error — except the thesis's designed sideslip loop (Table 3.5,
/// |kp| 3, |ki| 0.8; shared by `designed`, `designed_t310` and `designed_appe`), which is
/// unstable on this plant: wherever it is engaged the rudder hits both stops and the sideslip
/// error stays far above the command. The test asserts that divergence as it is.
#[test]
fn every_set_flies_every_scenario() {
    let cfg = SimConfig::default();
    let sets = gain_set_names();
    let thesis_slip = ["designed", "designed_t310", "designed_appe"];
    for s in SCENARIOS {
        let r = fly_sets(s.name, &sets, &cfg);
        for m in &r.metrics {
            let unstable_slip = s.slip_hold && thesis_slip.contains(&m.gains.as_str());
            if unstable_slip {
                assert!(
                    m.peak_rudder_deg > 24.9 && m.ripple_rms > 5.0,
                    "{} {}: expected the designed sideslip loop to oscillate: {m:?}",
                    s.name,
                    m.gains
                );
                continue;
            }
            assert!(bounded(m), "{} {}: {m:?}", s.name, m.gains);
            // Minnesota has no sideslip loop (yaw damper only): its sideslip stays at 0
            // whatever the command, an error of the full 5 deg.
            let sane = match s.axis {
                sim_host::scenario::Axis::Altitude => 5.0,
                _ => 5.5,
            };
            assert!(
                m.steady_state_error.abs() < sane,
                "{} {}: {m:?}",
                s.name,
                m.gains
            );
        }
    }
}

#[test]
fn noise_runs_are_reproducible_from_the_seed() {
    let dir = tempfile::tempdir().unwrap();
    let mut csv = Vec::new();
    for (k, seed) in [7u64, 7, 8].into_iter().enumerate() {
        let cfg = SimConfig {
            noise_sigma: 1e-3,
            seed,
            ..SimConfig::default()
        };
        let r = fly_sets("roll_doublet", &["designed", "minnesota"], &cfg);
        let sub = dir.path().join(k.to_string());
        std::fs::create_dir_all(&sub).unwrap();
        write_result(&r, &sub).unwrap();
        csv.push(std::fs::read(sub.join("roll_doublet_noise.csv")).unwrap());
    }
    assert_eq!(csv[0], csv[1], "same seed, different CSV");
    assert_ne!(csv[0], csv[2], "another seed gave the same noise");
    // Without noise the run differs from the noisy one (the noise reaches the loops).
    let quiet = fly_sets("roll_doublet", &["designed"], &SimConfig::default());
    let noisy = fly_sets(
        "roll_doublet",
        &["designed"],
        &SimConfig {
            noise_sigma: 1e-3,
            ..SimConfig::default()
        },
    );
    let (a, b) = (&quiet.runs[0].samples, &noisy.runs[0].samples);
    assert!(a.iter().zip(b).any(|(x, y)| x.aileron_deg != y.aileron_deg));
}

#[test]
fn unknown_scenario_and_gain_set_name_the_valid_ones() {
    let err = scenario_report(aircraft(), "loop", &ScenarioOptions::default(), None)
        .unwrap_err()
        .to_string();
    assert!(err.contains("unknown scenario `loop`"), "{err}");
    for s in SCENARIOS {
        assert!(err.contains(s.name), "{err}");
    }
    let opts = ScenarioOptions {
        gains: vec!["designed".into(), "classic".into()],
        ..ScenarioOptions::default()
    };
    let err = scenario_report(aircraft(), "roll_doublet", &opts, None)
        .unwrap_err()
        .to_string();
    assert!(err.contains("unknown gain set `classic`"), "{err}");
    for n in gain_set_names() {
        assert!(err.contains(n), "{err}");
    }
}

fn cli(args: &[&str]) -> (bool, String) {
    let (out, _dir) = support::sim_host(args);
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn cli_refuses_bad_names_and_noise() {
    let (ok, err) = cli(&["scenario", "barrel_roll"]);
    assert!(!ok);
    assert!(
        err.contains("barrel_roll") && err.contains("roll_doublet") && err.contains("climb"),
        "{err}"
    );
    let (ok, err) = cli(&["scenario", "climb", "--gains", "designed,bogus"]);
    assert!(!ok);
    assert!(
        err.contains("bogus") && err.contains("minnesota") && err.contains("computed"),
        "{err}"
    );
    for bad in ["-0.5", "NaN", "inf"] {
        let (ok, err) = cli(&["scenario", "roll_doublet", "--noise", bad]);
        assert!(!ok, "{bad}");
        assert!(err.contains("--noise") && err.contains("finite"), "{err}");
    }
}

/// The designed sideslip loop's divergence is not an artefact of the input delay: without it
/// the rudder still runs between its stops.
#[test]
fn designed_sideslip_loop_diverges_without_the_delay_too() {
    let cfg = SimConfig {
        delay_samples: 0,
        ..SimConfig::default()
    };
    let r = fly_sets("sideslip_doublet", &["designed", "computed"], &cfg);
    let d = of(&r, "designed");
    assert!(d.peak_rudder_deg > 24.9 && d.ripple_rms > 5.0, "{d:?}");
    // The computed set's sideslip loop tracks the same doublet.
    let c = of(&r, "computed");
    assert!(
        c.peak_rudder_deg < 20.0 && c.steady_state_error.abs() < 0.5,
        "{c:?}"
    );
}

/// The altitude loop flies about the trim pitch (its design is about the trim): even without
/// an integrator it settles on the command. Without the trim feed-forward it would settle
/// trim pitch / kp below (2.6 m for this set).
#[test]
fn p_only_altitude_loop_settles_on_the_command() {
    let r = fly_sets("altitude_step", &["designed_appe"], &SimConfig::default());
    let g = gain_set(aircraft(), "designed_appe").unwrap();
    assert_eq!(g.longitudinal.alt_ki, 0.0);
    let without_feed_forward = trim().theta / f64::from(g.longitudinal.alt_kp);
    let flown = of(&r, "designed_appe").steady_state_error;
    assert!(without_feed_forward > 2.0);
    assert!(flown.abs() < 0.1, "flown {flown} m");
}

/// The total energy control's height reference approaches a demand at `TECS_H_K` (0.4 1/s),
/// the height loop's own rate, so a step that reaches no climb or sink limit is a first-order
/// lag of time constant 1 / 0.4 = 2.5 s: 10-90 % rise ln 9 x 2.5 = 5.49 s, no overshoot. The
/// 2 m step asks for 0.8 m/s at most (the limit is 3). Flown on the nonlinear plant with the
/// servos and the delay, the rise is within 10 % of that and the overshoot under 2 %.
#[test]
fn the_energy_controls_small_altitude_step_is_the_first_order_lag_of_its_height_gain() {
    use sim_host::commands::scenario::FLIGHT_TECS;
    let g = gain_set(aircraft(), FLIGHT_TECS).unwrap();
    let k = f64::from(g.tecs.height_k);
    let predicted = 9f64.ln() / k;
    assert!((predicted - 5.49).abs() < 0.01, "{predicted}");
    let r = fly_sets("altitude_step_small", &[FLIGHT_TECS], &SimConfig::default());
    let m = of(&r, FLIGHT_TECS).segments[0].metrics;
    let rise = m.rise_time_s.unwrap();
    assert!(
        (rise / predicted - 1.0).abs() < 0.1,
        "rise {rise} s, predicted {predicted} s"
    );
    let overshoot = m.overshoot_pct;
    assert!(overshoot < 2.0, "overshoot {overshoot} %");
}

/// A gain file is checked gain by gain: a missing or non-finite gain is refused with its name.
#[test]
fn gain_files_name_the_missing_or_bad_gain() {
    let dir = tempfile::tempdir().unwrap();
    let g = sim_host::analysis::design::computed_gain_set(aircraft()).unwrap();
    let text = toml::to_string(&g).unwrap();
    let good = dir.path().join("computed.toml");
    std::fs::write(&good, &text).unwrap();
    let back = sim_host::commands::scenario::gain_file(&good).unwrap();
    assert_eq!(back, g);
    // The same file flies as a gain set.
    let by_name = gain_set(aircraft(), good.to_str().unwrap()).unwrap();
    assert_eq!(by_name, g);

    let missing = dir.path().join("missing.toml");
    let without: String = text
        .lines()
        .filter(|l| !l.starts_with("roll_kp"))
        .collect::<Vec<_>>()
        .join("\n");
    std::fs::write(&missing, without).unwrap();
    let e = format!(
        "{:#}",
        sim_host::commands::scenario::gain_file(&missing).unwrap_err()
    );
    assert!(e.contains("missing.toml") && e.contains("roll_kp"), "{e}");

    let nan = dir.path().join("nan.toml");
    let with_nan: String = text
        .lines()
        .map(|l| {
            if l.starts_with("pitch_kp") {
                "pitch_kp = nan".to_string()
            } else {
                l.to_string()
            }
        })
        .collect::<Vec<_>>()
        .join("\n");
    std::fs::write(&nan, with_nan).unwrap();
    let e = format!(
        "{:#}",
        sim_host::commands::scenario::gain_file(&nan).unwrap_err()
    );
    assert!(e.contains("nan.toml") && e.contains("PTCH_KP"), "{e}");
}
