//! Navigation flown end to end: the default mission uploaded through the ground link by the
//! scripted ground station (MISSION_COUNT, MISSION_REQUEST_INT, MISSION_ITEM_INT, MISSION_ACK),
//! started with MAV_CMD_MISSION_START and flown by the firmware on its own estimates, from the
//! runway to the runway.

use sim_host::aircraft::Aircraft;
use sim_host::commands::navigation;
use sim_host::environment::wind::Turbulence;
use sim_host::flight::summary::MissionSummary;
use sim_host::flight::FlightOutcome;

/// The default mission from the runway, with the firmware's parameters and the ground
/// station's mission tuning, as `sim-host navigation` flies it.
fn fly_default(wind_ned: [f64; 3], turbulence: Turbulence, seed: u64) -> FlightOutcome {
    let a = Aircraft::ultrastick25e().expect("built-in aircraft");
    navigation::fly_default(&a, wind_ned, turbulence, seed).expect("flight")
}

/// What every landing of the default mission must show: every navigation item reached in
/// order, a touchdown within 20 m of the landing point at a sink rate a small aircraft's
/// landing gear takes (under 1.5 m/s, about half its 0.3 m drop test's 2.4 m/s), disarmed.
fn landed_as_planned(o: &FlightOutcome) -> MissionSummary {
    let m = o.summary.mission.clone().expect("a mission was flown");
    eprintln!("{m:#?}");
    assert_eq!(o.summary.upload_results(), ["MAV_MISSION_ACCEPTED"]);
    assert!(
        m.all_reached,
        "reached {:?} of {:?}",
        m.reached, m.nav_items
    );
    assert_eq!(m.reached, m.nav_items, "in order, each once");
    let td = m.touchdown.expect("touched down");
    assert!(
        td.distance_m < 20.0,
        "touchdown {:.1} m away",
        td.distance_m
    );
    assert!(
        td.sink_rate_mps < 1.5,
        "sink rate {:.2} m/s",
        td.sink_rate_mps
    );
    let last = o.samples.last().expect("samples");
    assert!(!last.armed, "disarmed after the landing");
    m
}

#[test]
fn the_default_mission_flies_from_runway_to_runway_in_calm_air() {
    let o = fly_default([0.0; 3], Turbulence::None, 1);
    let m = landed_as_planned(&o);
    assert!(m.xtrack_rms_m < 0.5, "cross-track {:.2} m", m.xtrack_rms_m);
    assert!(m.alt_rms_m < 1.5, "altitude {:.2} m", m.alt_rms_m);
    assert!(
        m.airspeed_rms_mps < 1.0,
        "airspeed {:.2} m/s",
        m.airspeed_rms_mps
    );
}

/// In a 5 m/s wind from the north-north-east (a headwind and crosswind on the landing) with
/// light Dryden turbulence, on estimates, on every one of the forty seeds of
/// `docs/NAVIGATION.md` (a landing in turbulence is judged on its spread, not on one gust):
/// every waypoint in order, straight legs within 2 m, altitude within 1.5 m and airspeed
/// within 1 m/s RMS, touchdown within 20 m of the point under 1.5 m/s, stopped and disarmed.
#[test]
fn the_default_mission_meets_every_target_in_wind_and_turbulence_on_forty_seeds() {
    for &seed in navigation::SEEDS.iter().chain(&navigation::CHECK_SEEDS) {
        eprintln!("seed {seed}");
        let o = fly_default(navigation::WIND_NED, Turbulence::Light, seed);
        let m = landed_as_planned(&o);
        assert!(
            m.xtrack_rms_m < 2.0,
            "seed {seed}: cross-track {:.2} m",
            m.xtrack_rms_m
        );
        assert!(
            m.alt_rms_m < 1.5,
            "seed {seed}: altitude {:.2} m",
            m.alt_rms_m
        );
        assert!(
            m.airspeed_rms_mps < 1.0,
            "seed {seed}: airspeed {:.2} m/s",
            m.airspeed_rms_mps
        );
    }
}
