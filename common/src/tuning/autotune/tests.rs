//! The autotune's timeline, limits and reports, flown against a still estimate (the whole
//! loop, plant included, is flown by `sim-host/tests/autotune.rs`).

use super::excite::{self, Stage, TIMELINE};
use super::params::{self, AutotuneParams, UNIDENTIFIED};
use super::*;
use crate::control::lateral::RollMode;
use crate::control::longitudinal::LonMode;
use crate::estimator::Estimator;
use crate::math::DEG;
use crate::math::GRAVITY;

const DT: f32 = 0.02;

/// Level at 17 m/s, 360 m, every sensor healthy.
fn level() -> EstimatedState {
    let mut e = Estimator::default().state();
    e.alt_amsl_m = 360.0;
    e.airspeed = 17.0;
    e.ground_speed = 17.0;
    e.euler.theta = 2.0 * DEG;
    e.health.gps.healthy = true;
    e.health.pitot.healthy = true;
    e
}

fn calm() -> Situation {
    Situation {
        mode_kept: true,
        failsafe: false,
        flying: true,
        airspeed_range: (13.0, 23.0),
    }
}

fn p() -> AutotuneParams {
    (params::PARAMS.base)()
}

fn started() -> (Autotune, Surfaces) {
    let s = Surfaces {
        throttle: 0.5,
        ..Surfaces::default()
    };
    let mut a = Autotune::new();
    a.start(&level(), 17.0, &s, &p());
    (a, s)
}

#[test]
fn the_excitation_stays_within_two_fifths_of_the_abort_limits_on_every_tick() {
    let (mut a, s) = started();
    let (e, p) = (level(), p());
    let mut seen = [false; 3];
    for _ in 0..(excite::timeline_s() / DT) as usize {
        let t = a.step(DT, &e, &s, &calm(), &p, &GainSet::default());
        let c = t.commands.expect("the autotune flies while it runs");
        if let RollMode::Roll(r) = c.roll {
            assert!(r.abs() <= EXCITATION_SHARE * p.bank_max + 1e-6, "roll {r}");
            seen[0] |= r.abs() > 0.9 * EXCITATION_SHARE * p.bank_max;
        }
        if let LonMode::Pitch { pitch, throttle } = c.lon {
            let off = pitch - e.euler.theta;
            assert!(
                off.abs() <= EXCITATION_SHARE * p.pitch_max + 1e-4,
                "pitch {off}"
            );
            assert!((throttle - 0.5).abs() <= p.throttle_step + 1e-6);
            seen[1] |= off.abs() > 0.9 * EXCITATION_SHARE * p.pitch_max;
            seen[2] |= (throttle - 0.5).abs() > 0.9 * p.throttle_step;
        }
    }
    assert_eq!(seen, [true; 3], "every axis excited to its size");
}

#[test]
fn the_progress_runs_through_qgroundcontrols_bands_stage_by_stage() {
    let (mut a, s) = started();
    let (e, p) = (level(), p());
    let mut t_s = 0.0;
    let mut last = 0;
    while t_s < excite::timeline_s() {
        a.step(DT, &e, &s, &calm(), &p, &GainSet::default());
        let Status::Running(progress) = a.status() else {
            panic!("running through the timeline");
        };
        assert!(progress >= last, "progress went back at {t_s} s");
        last = progress;
        if let Some((stage, into, _)) = excite::at(t_s + DT) {
            // A tick into each stage, the band is the stage's.
            let band = match stage {
                Stage::Roll => 20..40,
                Stage::Pitch => 40..60,
                Stage::Throttle => 60..70,
                Stage::Yaw => 70..80,
                Stage::Level => 0..80,
            };
            if into > 0.1 {
                assert!(band.contains(&progress), "{stage:?} at {progress}");
            }
        }
        t_s += DT;
    }
}

#[test]
fn a_bank_beyond_the_limit_aborts_at_once_and_gives_the_aircraft_back() {
    let (mut a, s) = started();
    let mut e = level();
    e.euler.phi = 36.0 * DEG;
    let t = a.step(DT, &e, &s, &calm(), &p(), &GainSet::default());
    match t.report {
        Some(Report::Aborted(Abort::Bank(d))) => assert!((d - 36.0).abs() < 0.01),
        r => panic!("{r:?}"),
    }
    assert!(t.commands.is_none() && t.gains.is_none());
    assert!(!a.running());
    assert_eq!(a.status(), Status::Failed);
    // Nothing more from it until it is started again.
    let t = a.step(DT, &level(), &s, &calm(), &p(), &GainSet::default());
    assert_eq!(t, Tick::default());
}

#[test]
fn each_broken_condition_aborts_with_its_own_reason() {
    let s = Surfaces::default();
    let base = GainSet::default();
    type Spoil = fn(&mut EstimatedState, &mut Situation);
    let cases: [(Spoil, Abort); 7] = [
        (|e, _| e.euler.theta = 20.0 * DEG, Abort::Pitch(18.0)),
        (|e, _| e.alt_amsl_m = 320.0, Abort::HeightLoss(40.0)),
        (|e, _| e.airspeed = 11.0, Abort::Airspeed(11.0)),
        (|_, c| c.mode_kept = false, Abort::ModeChanged),
        (|_, c| c.failsafe = true, Abort::Failsafe),
        (|_, c| c.flying = false, Abort::Landed),
        (|e, _| e.health.gps.healthy = false, Abort::Sensors),
    ];
    for (spoil, why) in cases {
        let (mut a, _) = started();
        let (mut e, mut c) = (level(), calm());
        spoil(&mut e, &mut c);
        let t = a.step(DT, &e, &s, &c, &p(), &base);
        match (t.report, why) {
            (Some(Report::Aborted(got)), _) if got == why => {}
            (Some(Report::Aborted(Abort::Pitch(d))), Abort::Pitch(x))
            | (Some(Report::Aborted(Abort::HeightLoss(d))), Abort::HeightLoss(x))
            | (Some(Report::Aborted(Abort::Airspeed(d))), Abort::Airspeed(x)) => {
                assert!((d - x).abs() < 0.01, "{d} for {x}")
            }
            (r, _) => panic!("{why:?}: {r:?}"),
        }
    }
}

#[test]
fn a_station_stop_aborts_a_running_autotune_and_nothing_else() {
    let (mut a, _) = started();
    assert_eq!(
        a.abort(Abort::Station),
        Some(Report::Aborted(Abort::Station))
    );
    assert_eq!(a.abort(Abort::Station), None);
    assert_eq!(Autotune::new().abort(Abort::Station), None);
}

#[test]
fn a_flight_without_motion_fails_on_its_roll_model_and_hands_over_no_gains() {
    // The estimate never moves: the surfaces did not either, so roll is not excited.
    let (mut a, s) = started();
    let (e, p) = (level(), p());
    let mut last = None;
    for _ in 0..((excite::timeline_s() + 2.0) / DT) as usize {
        let t = a.step(DT, &e, &s, &calm(), &p, &GainSet::default());
        let f = Some(Vector3::new(0.0, 0.0, -GRAVITY));
        a.observe(DT, &sample(&e, &s, f, a.wind()));
        assert!(t.gains.is_none());
        last = t.report.or(last);
    }
    assert_eq!(last, Some(Report::Failed(Failure::NotExcited(Axis::Roll))));
    assert_eq!(a.status(), Status::Failed);
}

#[test]
fn the_timeline_lasts_under_65_s_and_ends_level() {
    assert!(excite::timeline_s() < 65.0, "{}", excite::timeline_s());
    assert_eq!(TIMELINE.last().map(|t| t.0), Some(Stage::Level));
    assert_eq!(excite::at(excite::timeline_s() + 0.01), None);
    // A 3-2-1-1 is 3, 2, 1, 1 pulses of alternating sign.
    let signs: [f32; 7] =
        core::array::from_fn(|k| excite::doublets((k as f32 + 0.5) * excite::PULSE_S));
    assert_eq!(signs, [1.0, 1.0, 1.0, -1.0, -1.0, 1.0, -1.0]);
}

/// A model whose roll diverges (`a_phi1` -5: the thesis's rules then leave the roll loop
/// 16 dB short of its gain margin) fails in the design, naming the roll loop; no gains.
#[test]
fn a_model_whose_design_fails_its_margins_hands_over_no_gains() {
    use crate::tuning::design::{Loop, Reason};
    let (mut a, s) = started();
    a.model = DesignModel {
        va: 17.0,
        a_phi1: -5.0,
        a_phi2: -156.5,
        a_theta1: 15.8,
        a_theta2: 126.7,
        a_theta3: -133.7,
        a_v1: 0.32,
        a_v2: 5.3,
        servo_bandwidth_hz: 8.0,
        ..UNIDENTIFIED
    };
    a.phase = Phase::Fitting {
        next: FITTED.len(),
        id: Identifier::new(IdentifyConfig {
            airspeed_ref: 17.0,
            servo_tau_s: 0.02,
            servo_rate_radps: 0.0,
            airspeed_filter_tau_s: 0.0,
            attitude_filter_tau_s: 0.0,
        }),
    };
    let (e, p) = (level(), p());
    let mut last = None;
    for _ in 0..400 {
        let t = a.step(DT, &e, &s, &calm(), &p, &GainSet::default());
        assert!(t.gains.is_none());
        last = t.report.or(last);
        if !a.running() {
            break;
        }
    }
    match last {
        Some(Report::Failed(Failure::Design(f))) => {
            assert_eq!(f.loop_, Some(Loop::Roll));
            assert!(
                matches!(f.reason, Reason::GainMargin(db) if db < 6.0),
                "{f:?}"
            );
        }
        r => panic!("{r:?}"),
    }
    assert_eq!(a.status(), Status::Failed);
}

/// A stage that leaves the aircraft 11 m low (the Aerosonde's throttle steps): the level
/// stages after it hold the height they found, not the start's, so no climb back (the
/// Aerosonde's took 17 deg of pitch and aborted the autotune); the height lost is still
/// counted from the start.
#[test]
fn a_level_stage_holds_the_height_it_began_at_and_the_height_lost_counts_from_the_start() {
    let (mut a, s) = started();
    let p = p();
    let g = GainSet::default();
    let mut t_s = 0.0;
    let mut held_after = 0;
    while t_s < excite::timeline_s() {
        let stage = excite::at(t_s).map(|x| x.0);
        let mut e = level();
        // From the throttle steps on: 11 m low.
        let past_throttle = TIMELINE
            .iter()
            .take_while(|(st, _)| *st != Stage::Throttle)
            .map(|(_, d)| d)
            .sum::<f32>();
        if t_s >= past_throttle {
            e.alt_amsl_m -= 11.0;
        }
        let t = a.step(DT, &e, &s, &calm(), &p, &g);
        if let (Some(Stage::Level), Some(c)) = (stage, t.commands) {
            if let LonMode::Altitude { altitude, .. } = c.lon {
                let after = t_s >= past_throttle;
                let want = if after { 349.0 } else { 360.0 };
                assert!((altitude - want).abs() < 1e-3, "{altitude} at {t_s} s");
                held_after += usize::from(after);
            }
        }
        t_s += DT;
    }
    assert!(matches!(a.status(), Status::Running(_)), "not aborted");
    assert!(held_after > 0);
    // 11 m below the start with 30 allowed: no abort; 31 m would be one.
    let mut low = level();
    low.alt_amsl_m -= 31.0;
    let t = a.step(DT, &low, &s, &calm(), &p, &g);
    assert_eq!(t.report, Some(Report::Aborted(Abort::HeightLoss(31.0))));
}
