//! The energy control against what its design predicts.

use super::*;
use crate::control::longitudinal::gains::FLIGHT;

const DT: f32 = 0.02;

/// An engaged control that has seen `h`, `v` steady for a second.
fn steady(t: &TecsGains, h: f32, v: f32) -> Tecs {
    let mut tecs = Tecs::new(t, &FLIGHT, 1.0);
    for _ in 0..50 {
        tecs.observe(h, v, DT);
    }
    tecs.engage(FLIGHT.trim_throttle, FLIGHT.trim_pitch);
    tecs
}

/// [`steady`], then ten seconds holding `h`, `v`: the engagement's offset has faded.
fn settled(t: &TecsGains, h: f32, v: f32) -> Tecs {
    let mut tecs = steady(t, h, v);
    for _ in 0..500 {
        tecs.observe(h, v, DT);
        tecs.step(&demand(h, v), &FLIGHT, DT);
    }
    tecs
}

fn demand(altitude: f32, airspeed: f32) -> TecsDemand {
    TecsDemand {
        altitude,
        airspeed,
        climb_rate: 0.0,
    }
}

#[test]
fn in_steady_level_flight_it_outputs_trim_throttle_and_trim_pitch() {
    let mut tecs = steady(&ENGAGED_FOR_TEST, 100.0, 17.0);
    let mut o = TecsOutput::default();
    for _ in 0..500 {
        tecs.observe(100.0, 17.0, DT);
        o = tecs.step(&demand(100.0, 17.0), &FLIGHT, DT).unwrap();
    }
    assert!((o.throttle - FLIGHT.trim_throttle).abs() < 1e-5, "{o:?}");
    assert!((o.pitch_cmd - FLIGHT.trim_pitch).abs() < 1e-5, "{o:?}");
    assert_eq!(o.underspeed, 0.0);
}

const ENGAGED_FOR_TEST: TecsGains = gains::ENGAGED;

/// A glide slope climbing at 1 m/s (the reference on it) asks for a flight-path angle of
/// 1/17 rad; with the rates still zero that is the whole energy-rate error, so the throttle
/// rises by the feed-forward `g (h_dot_d / V) / a_V2` = 0.108 plus the proportional part
/// `kp h_dot_d / V` = 0.018, and the pitch by the flight-path angle (the balance's height
/// weight is 1) plus its proportional part.
#[test]
fn a_climb_demand_raises_throttle_by_the_energy_rate_over_a_v2() {
    let t = ENGAGED_FOR_TEST;
    let mut tecs = settled(&t, 100.0, 17.0);
    tecs.observe(100.0, 17.0, DT);
    let glide = TecsDemand {
        climb_rate: 1.0,
        ..demand(100.0, 17.0)
    };
    let o = tecs.step(&glide, &FLIGHT, DT).unwrap();
    assert_eq!(o.climb_rate_demand, 1.0);
    let gamma = 1.0 / 17.0;
    let ff = gamma * GRAVITY / t.thr_accel;
    assert!((ff - 0.108).abs() < 1e-3);
    // One step of integration on top.
    let want = FLIGHT.trim_throttle + ff + t.thr_kp * gamma + t.thr_ki * gamma * DT;
    assert!((o.throttle - want).abs() < 1e-4, "{} vs {want}", o.throttle);
    let want_pitch = FLIGHT.trim_pitch + gamma + t.pitch_kp * gamma + t.pitch_ki * gamma * DT;
    assert!((o.pitch_cmd - want_pitch).abs() < 1e-4, "{}", o.pitch_cmd);
}

/// A 2 m step of the demand is filtered at `k_h`: the first climb-rate demand is `k_h` x 2 m
/// = 0.8 m/s (the reference moved k_h x 2 m x dt), not the 3 m/s climb limit a slew would ask.
#[test]
fn a_small_altitude_step_asks_for_k_h_times_the_step_not_the_climb_limit() {
    let t = ENGAGED_FOR_TEST;
    let mut tecs = settled(&t, 100.0, 17.0);
    tecs.observe(100.0, 17.0, DT);
    let o = tecs.step(&demand(102.0, 17.0), &FLIGHT, DT).unwrap();
    let moved = t.height_k * 2.0 * DT;
    let want = t.height_k * 2.0 + t.height_k * moved;
    assert!((want - 0.8).abs() < 0.01);
    assert!((o.climb_rate_demand - want).abs() < 1e-4, "{o:?}");
}

/// A demand moving at 1 m/s (a leg between waypoints 20 m apart in height, flown for 20 s)
/// is a ramp the aircraft can fly: the reference follows it without lag, so after a second
/// with the aircraft held at 100 m the climb-rate demand is the ramp's 1 m/s plus `k_h` x the
/// metre the reference has moved, 1.4 m/s (a first-order filter alone would lag 2.5 m).
#[test]
fn a_ramp_of_the_demand_is_followed_without_lag() {
    let t = ENGAGED_FOR_TEST;
    let mut tecs = settled(&t, 100.0, 17.0);
    let mut o = TecsOutput::default();
    for i in 1..=50 {
        tecs.observe(100.0, 17.0, DT);
        o = tecs
            .step(&demand(100.0 + i as f32 * DT, 17.0), &FLIGHT, DT)
            .unwrap();
    }
    assert!((o.climb_rate_demand - 1.4).abs() < 0.01, "{o:?}");
}

/// A far climb demand is limited to the climb limit and saturates the throttle; the
/// integrator stops there (conditional integration), so on reaching the altitude there is
/// nothing to unwind.
#[test]
fn a_far_climb_is_rate_limited_and_the_throttle_integrator_does_not_wind_up() {
    let t = ENGAGED_FOR_TEST;
    let mut tecs = settled(&t, 100.0, 17.0);
    let mut o = TecsOutput::default();
    // Ten seconds asking for +300 m while the aircraft does not move.
    for _ in 0..500 {
        tecs.observe(100.0, 17.0, DT);
        o = tecs.step(&demand(400.0, 17.0), &FLIGHT, DT).unwrap();
        assert!(o.climb_rate_demand <= t.climb_max);
    }
    assert_eq!(o.climb_rate_demand, t.climb_max);
    assert_eq!(o.throttle, FLIGHT.throttle_max);
    // The integrator holds just what brings the output to full, 1 - trim - ff - p = 0.054,
    // where a plain one would hold 0.18 rad * 2.75/s * 10 s = 4.9 of throttle to unwind.
    let gamma = t.climb_max / 17.0;
    let room = 1.0 - FLIGHT.trim_throttle - gamma * GRAVITY / t.thr_accel - t.thr_kp * gamma;
    let terms = tecs.thr.terms();
    assert!((room - 0.054).abs() < 1e-3, "{room}");
    assert!((terms.i - room).abs() < 1e-3, "{terms:?}");
}

/// The aircraft is 30 m too low and 4 m/s too slow (11 m/s, below the underspeed threshold by
/// half the band): the pitch command goes nose down to gain speed, where in-speed it would
/// climb, and the throttle is full.
#[test]
fn an_underspeed_takes_priority_over_height() {
    let t = ENGAGED_FOR_TEST;
    let run = |v: f32| {
        let mut tecs = steady(&t, 100.0, v);
        let mut o = TecsOutput::default();
        for _ in 0..50 {
            tecs.observe(100.0, v, DT);
            o = tecs.step(&demand(130.0, 17.0), &FLIGHT, DT).unwrap();
        }
        o
    };
    let slow = run(t.underspeed - 0.5 * UNDERSPEED_BAND_MPS);
    assert!((slow.underspeed - 0.5).abs() < 1e-6);
    // Half priority moves the balance weights from (1, 0.5) to (0.75, 1) on height and speed
    // and asks to accelerate: less nose up than in speed; full priority weighs speed alone,
    // so the height error no longer counts and the nose goes down.
    let fast = run(17.0);
    assert!(slow.pitch_cmd < fast.pitch_cmd - 0.02, "{slow:?} {fast:?}");
    assert!(slow.accel_demand > 0.0);
    let full = run(t.underspeed - UNDERSPEED_BAND_MPS - 1.0);
    assert_eq!(full.underspeed, 1.0);
    assert_eq!(full.throttle, FLIGHT.throttle_max);
    assert!(full.pitch_cmd < FLIGHT.trim_pitch, "nose down: {full:?}");
    assert!(fast.pitch_cmd > FLIGHT.trim_pitch, "nose up: {fast:?}");
}

#[test]
fn bad_inputs_hold_and_change_nothing() {
    let mut tecs = steady(&ENGAGED_FOR_TEST, 100.0, 17.0);
    tecs.observe(100.0, 17.0, DT);
    let good = tecs.step(&demand(110.0, 17.0), &FLIGHT, DT).unwrap();
    for dt in [0.0, -1.0, f32::NAN, f32::INFINITY] {
        assert_eq!(tecs.step(&demand(110.0, 17.0), &FLIGHT, dt), None);
    }
    assert_eq!(tecs.step(&demand(f32::NAN, 17.0), &FLIGHT, DT), None);
    assert_eq!(tecs.step(&demand(110.0, f32::INFINITY), &FLIGHT, DT), None);
    assert!(good.throttle.is_finite());
    // Bad samples leave the estimators as they were: it goes on as a twin that never saw them.
    let mut twin = tecs;
    tecs.observe(f32::NAN, f32::NEG_INFINITY, -1.0);
    tecs.observe(100.0, 17.0, DT);
    twin.observe(100.0, 17.0, DT);
    assert_eq!(
        tecs.step(&demand(110.0, 17.0), &FLIGHT, DT),
        twin.step(&demand(110.0, 17.0), &FLIGHT, DT)
    );
    // A bad glide rate loses only its feed-forward.
    let nan_rate = TecsDemand {
        climb_rate: f32::NAN,
        ..demand(110.0, 17.0)
    };
    assert!(tecs.step(&nan_rate, &FLIGHT, DT).is_some());
    // Never engaged, or never observed: nothing.
    let mut cold = Tecs::new(&ENGAGED_FOR_TEST, &FLIGHT, 1.0);
    cold.engage(0.5, 0.0);
    assert!(!cold.engaged());
    assert_eq!(cold.step(&demand(100.0, 17.0), &FLIGHT, DT), None);
}
