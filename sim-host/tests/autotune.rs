//! The autotune flown end to end: the scripted station presses autotune in the air
//! (`MAV_CMD_DO_AUTOTUNE_ENABLE`, as QGroundControl's button does), the firmware flies its
//! excitation on its own estimates, fits the reduced models on board and designs its gains;
//! the identified coefficients are checked against the aircraft file's linearisation (an
//! independent computation: the Jacobian of the plant about its trim), and every refusal and
//! abort against its reason, the aircraft flying on.

use sim_host::aircraft::Aircraft;
use sim_host::commands::fly::autotune::autotune_report;
use sim_host::commands::fly::{fly_report, FlyOptions};
use sim_host::commands::linearize::linearize_report_at;
use sim_host::flight::missions::{
    autotune_then_mission, autotune_then_thesis, default_mission, runway_mission, AUTOTUNE_AT_S,
    MISSION_AFTER_AUTOTUNE_S,
};
use sim_host::flight::summary::MissionSummary;
use sim_host::flight::{Action, Fault, FaultWindow, FlightConfig, FlightOutcome, ScriptStep};
use sim_host::plant::ModelParams;

fn aircraft() -> Aircraft {
    Aircraft::ultrastick25e().expect("built-in aircraft")
}

fn flown(cfg: &FlightConfig) -> FlightOutcome {
    fly_report(&aircraft(), cfg, &FlyOptions::default())
        .expect("flight")
        .outcome
}

/// The autotune flight of `sim-host fly --autotune`, changed by `tweak`.
fn autotune_flight(tweak: impl FnOnce(&mut FlightConfig)) -> FlightOutcome {
    let mut cfg = autotune_then_thesis();
    tweak(&mut cfg);
    flown(&cfg)
}

fn step(after_arm_s: f64, action: Action) -> ScriptStep {
    ScriptStep {
        after_arm_s,
        action,
    }
}

/// The texts that start with `prefix`, with their time.
fn texts<'a>(o: &'a FlightOutcome, prefix: &'a str) -> impl Iterator<Item = (f64, &'a str)> {
    o.summary
        .texts
        .iter()
        .filter(move |(_, t)| t.starts_with(prefix))
        .map(|(t, s)| (*t, s.as_str()))
}

/// The numbers of the autotune's text for `axis` ("Autotune: roll 16.8 -157.9 R2 0.97"): the
/// coefficients, then the R^2.
fn fitted(o: &FlightOutcome, axis: &str) -> Vec<f64> {
    let prefix = format!("Autotune: {axis} ");
    let (_, text) = texts(o, &prefix)
        .find(|(_, t)| t.contains(" R2 "))
        .unwrap_or_else(|| panic!("no {axis} model in {:?}", o.summary.texts));
    text[prefix.len()..]
        .split_whitespace()
        .filter_map(|w| w.parse().ok())
        .collect()
}

/// The commands' answers: what was sent and the result.
fn answers<'a>(o: &'a FlightOutcome, what: &'a str) -> Vec<&'a str> {
    o.summary
        .commands
        .iter()
        .filter(|c| c.what == what)
        .map(|c| c.result.as_str())
        .collect()
}

/// The lowest true altitude over `from_s..to_s`, m.
fn lowest(o: &FlightOutcome, from_s: f64, to_s: f64) -> f64 {
    o.samples
        .iter()
        .filter(|s| s.t >= from_s && s.t < to_s)
        .map(|s| s.alt)
        .fold(f64::INFINITY, f64::min)
}

/// From the firmware's default gains, in still air, the autotune identifies the 25e's roll,
/// sideslip and pitch from its own estimates and accelerometer: roll damping and aileron
/// power, the side force's sideslip term, and the pitch damping and elevator power within
/// 15 % of the linearisation at the same 17 m/s, the pitch stiffness within 20 % (the
/// estimator's vertical velocity, through the angle of attack it gives, is the cause,
/// docs/AUTOTUNE.md), the rudder's side force within 20 % (measured -14.7 %; over the seeds 1
/// to 6 of the sensors' noise it ranges from -16 % to +24 %, the sideslip term from -3.4 % to
/// -0.4 %: docs/AUTOTUNE.md);
/// every fit explains at least 70 % of what it fits; the gains are applied.
#[test]
fn the_autotune_identifies_the_25e_from_its_own_estimates_and_applies_its_gains() {
    let o = autotune_flight(|_| {});
    let armed = o.summary.armed_at_s.expect("armed");
    let start = armed + AUTOTUNE_AT_S;
    assert_eq!(answers(&o, "autotune"), ["MAV_RESULT_IN_PROGRESS"]);
    for stage in [
        "Autotune: started, level flight",
        "Autotune: roll doublets",
        "Autotune: pitch doublets",
        "Autotune: rudder doublets",
        "Autotune: throttle steps",
        "Autotune: gains applied",
    ] {
        assert!(
            texts(&o, stage).next().is_some(),
            "no `{stage}`: {:?}",
            o.summary.texts
        );
    }
    let lin = linearize_report_at(&aircraft(), "level", 17.0).expect("linearised");
    let reference = |name: &str| {
        lin.reduced
            .named()
            .iter()
            .find(|(n, _)| *n == name)
            .map(|(_, v)| *v)
            .expect("coefficient")
    };
    let within = |got: f64, name: &str, pct: f64| {
        let r = reference(name);
        let d = 100.0 * (got - r) / r;
        assert!(d.abs() <= pct, "{name} {got} against {r}: {d:+.1} %");
    };
    let roll = fitted(&o, "roll");
    within(roll[0], "a_phi1", 15.0);
    within(roll[1], "a_phi2", 15.0);
    assert!(roll[2] >= 0.7, "roll R2 {}", roll[2]);
    let sideslip = fitted(&o, "sideslip");
    within(sideslip[0], "a_beta1", 15.0);
    within(sideslip[1], "a_beta2", 20.0);
    assert!(sideslip[2] >= 0.7, "sideslip R2 {}", sideslip[2]);
    let pitch = fitted(&o, "pitch");
    within(pitch[0], "a_theta1", 15.0);
    within(pitch[1], "a_theta2", 20.0);
    within(pitch[2], "a_theta3", 15.0);
    assert!(pitch[3] >= 0.7, "pitch R2 {}", pitch[3]);
    // Never beyond its limits: 35 deg of bank, 30 m of height.
    let during = o
        .samples
        .iter()
        .filter(|s| s.t >= start && s.t < start + 60.0);
    let bank = during
        .map(|s| s.roll.abs().to_degrees())
        .fold(0.0, f64::max);
    assert!(bank < 35.0, "bank {bank} deg");
    let start_h = lowest(&o, start, start + 0.5);
    assert!(lowest(&o, start, start + 60.0) > start_h - 30.0);
}

/// Autotune asked on the runway before the take-off and again during the mission is refused
/// each time with its reason, and the mission flies on to its landing.
#[test]
fn autotune_on_the_ground_and_in_a_mission_is_refused_and_the_mission_lands() {
    let a = aircraft();
    let mut cfg = runway_mission(default_mission(ModelParams::new(&a).home));
    cfg.script
        .steps
        .insert(0, step(0.0, Action::Autotune(true)));
    cfg.script.steps.push(step(60.0, Action::Autotune(true)));
    let o = flown(&cfg);
    assert_eq!(
        answers(&o, "autotune"),
        ["MAV_RESULT_DENIED", "MAV_RESULT_DENIED"]
    );
    assert!(texts(&o, "Autotune refused: not in the air")
        .next()
        .is_some());
    assert!(
        texts(&o, "Autotune refused: fly Stabilized, Altitude or Hold")
            .next()
            .is_some()
    );
    assert!(texts(&o, "Autotune: started").next().is_none());
    assert!(o.summary.touchdown.is_some(), "the mission landed");
}

/// Pressed twice, the autotune runs once: the second press is answered with its progress.
#[test]
fn autotune_pressed_twice_runs_once_and_answers_the_second_with_its_progress() {
    let o = autotune_flight(|c| {
        c.script
            .steps
            .insert(3, step(AUTOTUNE_AT_S + 5.0, Action::Autotune(true)));
    });
    assert_eq!(
        answers(&o, "autotune"),
        ["MAV_RESULT_IN_PROGRESS", "MAV_RESULT_IN_PROGRESS"]
    );
    assert_eq!(texts(&o, "Autotune: started").count(), 1);
}

/// The GPS lost in the middle of the autotune aborts it with the reason, the gains kept, and
/// the aircraft flies on level; pressed with the airspeed sensor failed in flight, it is
/// refused.
#[test]
fn a_sensor_failing_aborts_the_autotune_and_a_failed_one_refuses_it() {
    let o = autotune_flight(|c| {
        let armed_guess = 9.0;
        let from_s = armed_guess + AUTOTUNE_AT_S + 20.0;
        c.faults.push(FaultWindow {
            fault: Fault::GpsLost,
            from_s,
            to_s: from_s + 30.0,
        });
        c.duration_s = 120.0;
    });
    let (t, _) = texts(&o, "Autotune aborted: GPS or airspeed sensor failed")
        .next()
        .unwrap_or_else(|| panic!("{:?}", o.summary.texts));
    assert!(texts(&o, "Autotune: gains applied").next().is_none());
    let h = lowest(&o, t - 1.0, t);
    assert!(lowest(&o, t, t + 30.0) > h - 15.0, "flies on level");
    let o = autotune_flight(|c| {
        // Failed in the air, after the arming it would refuse and before the press.
        c.faults.push(FaultWindow {
            fault: Fault::PitotFailed,
            from_s: 12.0,
            to_s: 1e9,
        });
        c.duration_s = 60.0;
    });
    assert_eq!(answers(&o, "autotune"), ["MAV_RESULT_DENIED"]);
    assert!(texts(&o, "Autotune refused: GPS or airspeed failed")
        .next()
        .is_some());
}

/// The station falling silent in the middle of the autotune raises the link-loss failsafe,
/// which aborts the autotune; the aircraft flies the failsafe's reaction, gains kept.
#[test]
fn the_station_lost_mid_autotune_aborts_it_for_the_failsafe() {
    let o = autotune_flight(|c| {
        c.script
            .steps
            .insert(3, step(AUTOTUNE_AT_S + 20.0, Action::Silence));
        c.duration_s = 120.0;
    });
    assert!(
        texts(&o, "Autotune aborted: failsafe").next().is_some(),
        "{:?}",
        o.summary.texts
    );
    assert!(texts(&o, "Autotune: gains applied").next().is_none());
}

/// With the servo set eight times slower than the aircraft's (1 Hz for its 8 Hz), the roll
/// model cannot explain what was flown: the autotune fails naming the axis and its fit
/// quality, and the gains stay as they were (a design that fails its margins is the unit test
/// `common::tuning::autotune::tests::a_model_whose_design_fails_its_margins_hands_over_no_gains`).
#[test]
fn a_poor_fit_fails_the_autotune_naming_the_axis_and_leaves_the_gains() {
    let o = autotune_flight(|c| {
        c.script.params.push(("SERVO_BW".into(), 1.0));
        c.duration_s = 120.0;
    });
    let failed: Vec<_> = texts(&o, "Autotune failed: ").collect();
    assert_eq!(failed.len(), 1, "{:?}", o.summary.texts);
    assert!(
        failed[0].1.starts_with("Autotune failed: roll fit R2 ")
            && failed[0].1.ends_with("too low"),
        "{failed:?}"
    );
    assert!(texts(&o, "Autotune: gains applied").next().is_none());
    let (before, after) = (&o.summary.params_read, "RLL_KP");
    let values: Vec<f32> = before
        .iter()
        .filter(|(_, n, _)| n == after)
        .map(|(_, _, v)| *v)
        .collect();
    assert_eq!(values.len(), 2, "read before and after");
    assert_eq!(values[0], values[1], "RLL_KP unchanged");
}

/// docs/NAVIGATION.md's targets in calm air, each checked on its own: `(what, met)`.
fn navigation_targets(m: &MissionSummary) -> Vec<(&'static str, bool)> {
    let td = m.touchdown.expect("touched down");
    vec![
        ("every waypoint reached", m.all_reached),
        (
            "straight-leg cross-track RMS under 0.5 m",
            m.xtrack_rms_m < 0.5,
        ),
        ("altitude error RMS under 1.5 m", m.alt_rms_m < 1.5),
        ("airspeed error RMS under 1 m/s", m.airspeed_rms_mps < 1.0),
        ("touchdown within 20 m", td.distance_m < 20.0),
        ("sink under 1.5 m/s", td.sink_rate_mps < 1.5),
    ]
}

/// `fly --autotune --mission default`, as a QGroundControl user flies it: Takeoff from the
/// runway, Hold, autotune, then the default mission on the gains it applied, beside the same
/// mission on the default gains. The default gains meet every calm-air target of
/// docs/NAVIGATION.md; after the autotune (the design's inputs `DesignInputs::AUTOTUNE`: the
/// outer loops at the flight-proven set's separations) the mission meets every one of them
/// too (straight legs 0.487 m RMS against 0.5, 0.436 on the default gains; 0.502 m before the
/// autotune fitted each model on its own stage of the excitation), and holds its altitude and
/// airspeed closer than the default gains do. Every loop, the sideslip's among them, keeps its
/// margins on the identified model, recomputed on the host from what the station read back,
/// with the gains the vehicle applied.
#[test]
fn after_the_autotune_the_default_mission_meets_every_navigation_target_and_holds_altitude_and_airspeed_closer(
) {
    let a = aircraft();
    let plain_cfg = runway_mission(default_mission(ModelParams::new(&a).home));
    let tuned = flown(&autotune_then_mission(plain_cfg.clone()));
    let plain = flown(&plain_cfg);
    for (what, answer) in [
        ("takeoff", "MAV_RESULT_ACCEPTED"),
        ("mode Hold", "MAV_RESULT_ACCEPTED"),
        ("autotune", "MAV_RESULT_IN_PROGRESS"),
        ("mission start", "MAV_RESULT_ACCEPTED"),
    ] {
        assert_eq!(answers(&tuned, what), [answer], "{what}");
    }
    assert!(
        texts(&tuned, "Autotune: gains applied").next().is_some(),
        "{:?}",
        tuned.summary.texts
    );
    let r = autotune_report(&a, &tuned, &plain).expect("report");
    let m = r.mission.as_ref().expect("a mission before and after");
    assert!(m.calm);
    for (what, met) in navigation_targets(&m.default_gains) {
        assert!(met, "default gains: {what}: {:?}", m.default_gains);
    }
    let (after, before) = (&m.after_autotune, &m.default_gains);
    for (what, met) in navigation_targets(after) {
        assert!(met, "after the autotune: {what}: {after:?}");
    }
    assert!(
        after.alt_rms_m <= before.alt_rms_m,
        "{after:?} against {before:?}"
    );
    assert!(
        after.airspeed_rms_mps <= before.airspeed_rms_mps,
        "{after:?} against {before:?}"
    );
    assert!(after.xtrack_rms_m < 2.0, "within the turbulent-air target");
    assert!(after.strikes.is_empty() && after.pass, "{after:?}");
    // The figures are the mission's: counted from its start, not from the arming.
    let frame_s = tuned.summary.sim_s / tuned.summary.frames as f64;
    let armed_s = tuned.summary.armed_frames as f64 * frame_s;
    assert!(
        after.flight_time_s <= armed_s - MISSION_AFTER_AUTOTUNE_S + 1.0,
        "mission {} s of {armed_s} s armed",
        after.flight_time_s
    );
    let margins = r.margins.as_ref().expect("margins");
    assert_eq!(margins.loops.len(), 7);
    for l in &margins.loops {
        let (gm, pm) = (
            l.gain_margin_db.unwrap_or(f64::INFINITY),
            l.phase_margin_deg.unwrap_or(f64::INFINITY),
        );
        let pm_min = if ["roll", "pitch"].contains(&l.name.as_str()) {
            45.0
        } else {
            30.0
        };
        assert!(gm >= 6.0 && pm >= pm_min, "{}: {gm} dB, {pm} deg", l.name);
    }
    let diff = margins.gains_diff_max_pct.expect("gains compared");
    assert!(diff < 0.01, "the host's design {diff} % from the vehicle's");
}
