//! `doublet --airspeed` and `scenario --airspeed`: both start from the level trim at the
//! airspeed asked for, or at the aircraft file's cruise airspeed, as `trim`, `linearize` and
//! `design` do.

use sim_host::aircraft::Aircraft;
use sim_host::analysis::doublet::DoubletConfig;
use sim_host::commands::doublet::doublet_report_at;
use sim_host::commands::scenario::{scenario_report, ScenarioOptions};
use std::path::{Path, PathBuf};
use std::process::Output;
use support::{col, csv, sim_host};

mod support;

fn aerosonde_file() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("aircraft/aerosonde.toml")
}

/// The JSON a successful run printed.
fn json_of(out: &Output) -> serde_json::Value {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

/// The trim of `doublet --json [--airspeed VA]` on the built-in aircraft.
fn doublet_trim(airspeed: Option<&str>) -> serde_json::Value {
    let mut args = vec!["doublet", "--json"];
    if let Some(va) = airspeed {
        args.extend(["--airspeed", va]);
    }
    let (out, _dir) = sim_host(&args);
    let report = json_of(&out);
    report["trim"].clone()
}

#[test]
fn doublet_at_20_mps_starts_from_a_trimmed_state_flying_20_mps_that_stays_there_until_the_doublet()
{
    let a = Aircraft::ultrastick25e().unwrap();
    let cfg = DoubletConfig::default();
    let r = doublet_report_at(&a, &cfg, 20.0, None).unwrap();
    // Still air: the airspeed is the speed of the trimmed state's velocity.
    let va = r.trim.state.vel_body.norm();
    assert!((va - 20.0).abs() < 0.01, "trimmed state flies {va} m/s");
    // A trim is steady: the nonlinear plant holds 20 m/s until the surface moves.
    for run in &r.runs {
        for s in run.samples.iter().filter(|s| s.t < cfg.start_s) {
            assert!(
                (s.nonlinear.va - 20.0).abs() < 0.01,
                "{:?} run at {} s: {} m/s",
                run.surface,
                s.t,
                s.nonlinear.va
            );
        }
    }
}

#[test]
fn doublet_airspeed_20_trims_with_more_throttle_and_less_angle_of_attack_than_the_default_17() {
    let at_20 = doublet_trim(Some("20"));
    let default = doublet_trim(None);
    let f = |v: &serde_json::Value, k: &str| v[k].as_f64().unwrap();
    // The built-in 25e has no cruise airspeed in its file: the default is the thesis's 17 m/s.
    assert_eq!(f(&default["target"], "va_mps"), 17.0);
    assert_eq!(f(&at_20["target"], "va_mps"), 20.0);
    // Above its minimum-power speed the 25e needs more thrust to fly faster, and the same
    // weight lifted at a higher dynamic pressure needs a smaller angle of attack.
    assert!(
        f(&at_20, "throttle") > f(&default, "throttle"),
        "throttle {} at 20 m/s, {} at 17 m/s",
        f(&at_20, "throttle"),
        f(&default, "throttle")
    );
    assert!(f(&at_20, "alpha") < f(&default, "alpha"));
}

#[test]
fn scenario_on_the_aerosonde_file_starts_at_its_25_mps_cruise_and_steps_the_airspeed_to_26() {
    let file = aerosonde_file();
    let (out, dir) = sim_host(&[
        "--aircraft",
        file.to_str().unwrap(),
        "scenario",
        "airspeed_step_small",
        "--gains",
        "flight",
        "--json",
    ]);
    let report = json_of(&out);
    // aerosonde.toml: `[performance] cruise_airspeed_mps = 25.0`.
    assert_eq!(report["trim_airspeed_mps"].as_f64(), Some(25.0));
    // What the plant flew: 25 m/s at the start, and the +1 m/s step taken from there.
    let (header, rows) = csv(&dir.path().join("airspeed_step_small.csv"));
    let flown: Vec<f64> = rows
        .iter()
        .map(|r| r[col(&header, "flight_airspeed_m/s")])
        .collect();
    let (first, last) = (flown[0], flown[flown.len() - 1]);
    assert!((first - 25.0).abs() < 0.01, "starts at {first} m/s");
    assert!((last - 26.0).abs() < 0.05, "settles at {last} m/s");
}

#[test]
fn the_aerosondes_altitude_step_holds_its_25_mps_trim_airspeed_not_the_thesiss_17() {
    let a = Aircraft::from_file(&aerosonde_file()).unwrap();
    let opts = ScenarioOptions {
        gains: vec!["computed".into()],
        ..ScenarioOptions::default()
    };
    let r = scenario_report(&a, "altitude_step_small", &opts, None).unwrap();
    assert_eq!(r.trim_airspeed_mps, 25.0);
    let run = r.results[0].run_of("computed").unwrap();
    let worst = run
        .samples
        .iter()
        .map(|s| (s.airspeed_mps - 25.0).abs())
        .fold(0.0, f64::max);
    // The 2 m climb trades a little speed for height; a loop holding 17 m/s would shed 8.
    assert!(worst < 1.0, "airspeed strays {worst} m/s from 25");
    let last = run.samples.last().unwrap();
    assert!(
        (last.airspeed_mps - 25.0).abs() < 0.1,
        "{} m/s",
        last.airspeed_mps
    );
    assert!((last.alt_msl_m - 102.0).abs() < 0.2, "{} m", last.alt_msl_m);
}

#[test]
fn an_airspeed_that_is_not_positive_or_cannot_be_trimmed_is_an_error_naming_it() {
    for command in [&["doublet"][..], &["scenario", "airspeed_step_small"][..]] {
        let (out, _) = sim_host(&[command, &["--airspeed", "-3"]].concat());
        assert_eq!(out.status.code(), Some(2), "{command:?}: a usage error");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            err.contains("--airspeed") && err.contains("`-3`") && err.contains("positive"),
            "{command:?}: {err}"
        );
        let (out, _) = sim_host(&[command, &["--airspeed", "200"]].concat());
        assert_eq!(out.status.code(), Some(1), "{command:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            err.contains("cannot be trimmed")
                && err.contains("200 m/s")
                && !err.contains("panicked"),
            "{command:?}: {err}"
        );
    }
}
