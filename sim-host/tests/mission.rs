//! Navigation flown end to end: the default mission uploaded through the ground link by the
//! scripted ground station (MISSION_COUNT, MISSION_REQUEST_INT, MISSION_ITEM_INT, MISSION_ACK),
//! started with MAV_CMD_MISSION_START and flown by the firmware on its own estimates, from the
//! runway to the runway.

use sim_host::aircraft::Aircraft;
use sim_host::commands::navigation;
use sim_host::environment::wind::Turbulence;
use sim_host::flight::landed::landed_state_honest;
use sim_host::flight::summary::MissionSummary;
use sim_host::flight::FlightOutcome;

/// The default mission from the runway, with the firmware's parameters (the ground station
/// sets none), as `sim-host navigation` flies it.
fn fly_default(wind_ned: [f64; 3], turbulence: Turbulence, seed: u64) -> FlightOutcome {
    let a = Aircraft::ultrastick25e().expect("built-in aircraft");
    navigation::fly_default(&a, wind_ned, turbulence, seed).expect("flight")
}

/// What every flight of the default mission must show: every navigation item reached in
/// order, a touchdown, disarmed after it. Returns the figures.
fn flown_as_planned(o: &FlightOutcome) -> MissionSummary {
    let m = o.summary.mission.clone().expect("a mission was flown");
    eprintln!("{m:#?}");
    assert_eq!(o.summary.upload_results(), ["MAV_MISSION_ACCEPTED"]);
    assert!(
        m.all_reached,
        "reached {:?} of {:?}",
        m.reached, m.nav_items
    );
    assert_eq!(m.reached, m.nav_items, "in order, each once");
    assert!(m.touchdown.is_some(), "touched down");
    assert!(m.strikes.is_empty(), "strikes {:?}", m.strikes);
    assert!(m.pass, "failed {:?}", m.failed);
    let last = o.samples.last().expect("samples");
    assert!(!last.armed, "disarmed after the landing");
    m
}

/// The landing's targets: within 20 m of the landing point at a sink rate a small aircraft's
/// landing gear takes (under 1.5 m/s, about half its 0.3 m drop test's 2.4 m/s).
fn on_target(m: &MissionSummary) -> bool {
    m.touchdown
        .as_ref()
        .is_some_and(|td| td.distance_m < 20.0 && td.sink_rate_mps < 1.5)
}

#[test]
fn the_default_mission_flies_from_runway_to_runway_in_calm_air() {
    let o = fly_default([0.0; 3], Turbulence::None, 1);
    let m = flown_as_planned(&o);
    // Disarmed after the landing, the surfaces rest where they rested before arming (trim)
    // from the next 20 ms control period on, even while the aircraft still rolls.
    let rest = o.samples.first().expect("samples");
    let armed = o.samples.iter().position(|s| s.armed).expect("armed");
    let disarmed = armed
        + o.samples[armed..]
            .iter()
            .position(|s| !s.armed)
            .expect("disarmed after the flight");
    let t_disarmed = o.samples[disarmed].t;
    for s in o.samples[disarmed..]
        .iter()
        .filter(|s| s.t >= t_disarmed + 0.02 - 1e-6)
    {
        let off = [
            s.elevator - rest.elevator,
            s.aileron - rest.aileron,
            s.rudder - rest.rudder,
        ];
        assert!(
            off.iter().all(|d| d.abs() < 1e-3),
            "surfaces {off:?} rad from rest at {:.2} s",
            s.t
        );
    }
    assert!(on_target(&m), "touchdown {:?}", m.touchdown);
    assert!(m.xtrack_rms_m < 0.5, "cross-track {:.2} m", m.xtrack_rms_m);
    assert!(m.alt_rms_m < 1.5, "altitude {:.2} m", m.alt_rms_m);
    assert!(
        m.airspeed_rms_mps < 1.0,
        "airspeed {:.2} m/s",
        m.airspeed_rms_mps
    );
}

/// In a 5 m/s wind from the north-north-east (a headwind and crosswind on the landing) with
/// light Dryden turbulence, on estimates, on the forty seeds of `docs/NAVIGATION.md`: every
/// waypoint in order, straight legs within 2 m, altitude within 1.5 m and airspeed within
/// 1 m/s RMS, stopped and disarmed, on every seed. A landing in turbulence is judged on its
/// spread, not on one gust: the touchdown is on target (within 20 m, under 1.5 m/s) on at
/// least 37 of the 40 (92.5 %: 193 of the 200 seeds 1-200 are, 96.5 %, and 38 of these 40),
/// and on none beyond 30 m or at the landing gear's 2.4 m/s drop test (`docs/NAVIGATION.md`
/// gives the spread and why it is not every landing).
#[test]
fn the_default_mission_meets_every_target_in_wind_and_turbulence_on_forty_seeds() {
    let mut on = 0;
    for &seed in navigation::SEEDS.iter().chain(&navigation::CHECK_SEEDS) {
        eprintln!("seed {seed}");
        let o = fly_default(navigation::WIND_NED, Turbulence::Light, seed);
        let m = flown_as_planned(&o);
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
        let td = m.touchdown.as_ref().expect("touched down");
        assert!(
            td.distance_m < 30.0 && td.sink_rate_mps < 2.4,
            "seed {seed}: touchdown {:.1} m away at {:.2} m/s",
            td.distance_m,
            td.sink_rate_mps
        );
        on += usize::from(on_target(&m));
    }
    assert!(on >= 37, "{on} of 40 touchdowns on target");
}

/// The slowest and fastest cruise airspeeds a mission may set (`NAV_ASPD_MIN` 13 m/s and
/// `NAV_ASPD_MAX` 23 m/s; level flight ends at 23.6 m/s at full throttle), with the surface and
/// altitude loops scaled by airspeed (`ASPD_SCL_REF`, docs/GAIN-DESIGN.md): the same targets
/// as at the 17 m/s the gains were designed at.
#[test]
fn the_default_mission_flies_at_the_slowest_and_fastest_cruise_airspeeds() {
    let a = Aircraft::ultrastick25e().expect("built-in aircraft");
    for va in [13.0, 23.0] {
        let o = navigation::fly_default_at_airspeed(&a, va).expect("flight");
        let m = flown_as_planned(&o);
        assert!(on_target(&m), "{va} m/s: touchdown {:?}", m.touchdown);
        assert!(
            m.xtrack_rms_m < 1.0,
            "{va} m/s: cross-track {:.2} m",
            m.xtrack_rms_m
        );
        assert!(m.alt_rms_m < 1.5, "{va} m/s: altitude {:.2} m", m.alt_rms_m);
        assert!(
            m.airspeed_rms_mps < 1.0,
            "{va} m/s: airspeed {:.2} m/s",
            m.airspeed_rms_mps
        );
    }
}

/// A mission that reached every item, whose log has the right wing tip on the runway while
/// armed (rolled 20 deg on the wheels: the tip reaches the ground at 14.6 deg), fails its
/// summary on `no_strike` alone, with the strike as an event in the JSON and the printed
/// table; a smaller roll, or the same roll while disarmed, passes.
#[test]
fn a_wing_tip_on_the_runway_while_armed_fails_the_mission_summary_on_no_strike() {
    use sim_host::commands::fly::mission_table;
    use sim_host::flight::strikes::{propeller_hub_m, strike_points, survey};
    use sim_host::flight::Sample;
    use sim_host::plant::Plant;

    let a = Aircraft::ultrastick25e().expect("built-in aircraft");
    let rest = Plant::at_rest_on_ground(&a, 0.0, 0.0, 0.0);
    let e = rest.euler();
    let home = a.environment.home_alt_msl_m;
    let log = |rolls: &[f64], armed: bool| -> Vec<Sample> {
        rolls
            .iter()
            .enumerate()
            .map(|(k, r)| Sample {
                t: k as f64,
                armed,
                alt: rest.alt_msl_m(),
                roll: r.to_radians(),
                pitch: e.theta,
                yaw: e.psi,
                ..Sample::default()
            })
            .collect()
    };
    let points = strike_points(&a, propeller_hub_m(&a, [0.0; 3]));
    let judged = |samples: &[Sample]| {
        let mut m = MissionSummary {
            all_reached: true,
            ..MissionSummary::default()
        };
        m.judge(survey(samples, &points, home));
        m
    };

    let struck = judged(&log(&[0.0, 20.0, 0.0], true));
    assert!(!struck.pass);
    assert_eq!(struck.failed, ["no_strike"]);
    assert_eq!(struck.strikes.len(), 1);
    assert!(struck.strikes[0].point.starts_with("right wing tip"));
    assert_eq!(struck.strikes[0].t_s, 1.0);
    assert!(struck.min_clearance_m.is_some_and(|c| c < 0.0));
    let json = serde_json::to_value(&struck).expect("json");
    assert_eq!(json["failed"][0], "no_strike");
    assert_eq!(json["strikes"][0]["t_s"], 1.0);
    let text = mission_table(&struck).render_text();
    assert!(text.contains("right wing tip at 1.0 s"), "{text}");
    assert!(text.contains("fail: no_strike"), "{text}");

    // Rolled 10 deg the tip stays clear; rolled 20 deg while disarmed (the hands of the crew
    // before the flight) is no strike of the flight.
    let tilted = judged(&log(&[0.0, 10.0, 0.0], true));
    assert!(
        tilted.pass && tilted.strikes.is_empty(),
        "{:?}",
        tilted.failed
    );
    let mut handled = log(&[0.0, 20.0, 0.0], true);
    handled[1].armed = false;
    let handled = judged(&handled);
    assert!(
        handled.pass && handled.strikes.is_empty(),
        "{:?}",
        handled.failed
    );
}

/// Missions from other runways, laid out as an outside planner laid them out (the take-off
/// item 30 and 75 deg off the runway, turned rectangles, a speed change to 20 m/s, loiter
/// turns, circuits from either side), flown with the firmware's defaults by a station that
/// sets none: in calm air and in the default case's wind turned with each runway, with light
/// turbulence, every navigation target is met, nothing but the wheels touches the ground, the
/// throttle is on a stop in under 10 % of level cruise and the landed state the station read
/// is honest from the start to the stop.
#[test]
fn missions_from_other_runways_fly_well_in_calm_air_and_in_wind() {
    let aircraft = Aircraft::ultrastick25e().expect("built-in aircraft");
    let home = sim_host::plant::ModelParams::new(&aircraft).home;
    let opts = sim_host::commands::fly::FlyOptions::default();
    for mission in sim_host::flight::missions::other_runway_missions(home) {
        for (turbulence, calm) in [(Turbulence::None, true), (Turbulence::Light, false)] {
            let o = navigation::fly_runway_mission(&aircraft, &mission, turbulence, 1, &opts)
                .expect("flight");
            if let Err(e) = navigation::flies_well(&o, calm) {
                panic!("{} ({turbulence:?}): {e}", mission.name);
            }
        }
    }
}

/// A tailwind and a crosswind from the left on the take-off roll (5 m/s towards north and
/// towards east, light turbulence): parked and rolling slowly, the aircraft sees its air from
/// behind or from the side, far outside the Minnesota model's linear envelope. The plant's
/// flat-plate aerodynamics there (`sim_host::plant::aero`) lift and roll it no more than a
/// plate would, so nothing but the wheels touches the ground and every item is reached; with
/// the linear coefficients carried to 180 deg, seed 1 put the right wing tip on the runway in
/// both. The same wind is then a tailwind or a crosswind on the roll-out, 18 m/s over the
/// ground at the touchdown in the tailwind: the station reads ON_GROUND within 15 s of it
/// (`landed_state_honest`), since ground speed is no evidence of flight in the navigator's
/// roll-out (the land detector waited 20 s for the wheels to slow it under `LND_VXY_MAX`).
/// Both flights meet every target of docs/NAVIGATION.md besides (`navigation::flies_well`):
/// the tailwind's lands 16.9 m past the point, near the 20 m target's edge (it moved between
/// -2.7 and +20.3 m with changes far from the flare, docs/NAVIGATION.md).
#[test]
fn a_tailwind_or_a_crosswind_strikes_no_wing_tip_and_the_roll_out_reads_on_ground_within_15_s() {
    let a = Aircraft::ultrastick25e().expect("built-in aircraft");
    for towards in [0, 90] {
        let o = navigation::fly_default(&a, navigation::rose_wind(towards), Turbulence::Light, 1)
            .expect("flight");
        eprintln!("wind towards {towards} deg");
        let m = flown_as_planned(&o);
        let td = m.touchdown.as_ref().expect("touched down");
        if let Err(e) = landed_state_honest(&o.summary.landed_states, td.time_s, &o.samples) {
            panic!("wind towards {towards} deg: {e}");
        }
        if let Err(e) = navigation::flies_well(&o, false) {
            panic!("wind towards {towards} deg: {e}");
        }
    }
}
