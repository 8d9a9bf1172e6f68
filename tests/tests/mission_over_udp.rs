//! A ground station of its own (this test: a UDP socket, frames encoded and parsed by the
//! `mavlink` crate alone, none of the autopilot's framing code) flies the default mission
//! through the autopilot's ground link as an operator with QGroundControl would: upload with
//! the mission protocol, download and compare, arm (retried while the pre-arm checks refuse),
//! MISSION_START, then watch the progress messages until the aircraft has landed and disarmed.
//!
//! The firmware runs in the loop of the 6-DOF simulator, in this process, paced at `SPEED`
//! simulated seconds per wall second. Lock-step keeps the flight itself deterministic; only
//! the moments at which this station's frames arrive depend on the wall clock.
//!
//! The simulator's scripted ground station is present on the same link (it cannot be left
//! out of a flight): here it uploads nothing and commands nothing. It does send heartbeats,
//! which would hide a station that stopped sending its own, so once this station has armed
//! and started the mission the script falls silent (`Action::Silence`; its "arm" that
//! precedes it is a no-op on an armed vehicle). From then on only this station's heartbeats
//! keep the autopilot's link-loss failsafe (`FS_GCS_TOUT_S`, 5 s of the autopilot's time)
//! from returning the aircraft home: a station that fell silent would fail the test.

use common::math::geodetic::{ned_offset, GeoPoint};
use common::math::Euler;
use mavlink::dialects::common::*;
use nalgebra::Vector3;
use sim_host::aircraft::Aircraft;
use sim_host::commands::fly::{fly_report, FlyOptions};
use sim_host::flight::missions::default_mission;
use sim_host::flight::{Action, FlightConfig, FlightOutcome, Sample, Script, ScriptStep};
use sim_host::plant::{ground, ModelParams, State};
use std::net::{SocketAddr, UdpSocket};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};
use system_tests::station::{free_port, Station, ME, TARGET};

/// Simulated seconds per wall second: the ~350 s mission takes about 15 s.
const SPEED: f64 = 25.0;
/// Length of the mission flight, s of simulated time: the default mission is flown and the
/// aircraft stopped and disarmed by about 352 s, and the station must then hear a disarmed
/// heartbeat. `stop_when_landed` would end the flight at the very frame the autopilot
/// disarms, before that frame's telemetry reaches the UDP port and before the next 1 Hz
/// heartbeat, so a station on the link would never see the vehicle disarmed.
const FLIGHT_S: f64 = 380.0;
/// Simulated time at which the scripted station says its (no-op) "arm" and falls silent, s:
/// well after this station has armed (the estimator converges in about 10 s).
const SCRIPT_SILENT_AT_S: f64 = 40.0;
fn aircraft() -> Aircraft {
    Aircraft::ultrastick25e().expect("built-in aircraft")
}

/// The downloaded list is the uploaded one, field by field (floats bit for bit: the NaN
/// parameters of the default mission included). `current` is the autopilot's to set, and the
/// target is the station that asked.
fn assert_same_mission(got: &[MISSION_ITEM_INT_DATA], sent: &[MISSION_ITEM_INT_DATA]) {
    assert_eq!(got.len(), sent.len(), "item count");
    for (g, s) in got.iter().zip(sent) {
        let seq = s.seq;
        let floats = [
            ("param1", g.param1, s.param1),
            ("param2", g.param2, s.param2),
            ("param3", g.param3, s.param3),
            ("param4", g.param4, s.param4),
            ("z", g.z, s.z),
        ];
        for (name, a, b) in floats {
            assert_eq!(a.to_bits(), b.to_bits(), "item {seq} {name}: {a} vs {b}");
        }
        assert_eq!((g.x, g.y), (s.x, s.y), "item {seq} x, y");
        assert_eq!(g.seq, s.seq, "item {seq} seq");
        assert_eq!(g.command, s.command, "item {seq} command");
        assert_eq!(g.frame, s.frame, "item {seq} frame");
        assert_eq!(g.autocontinue, s.autocontinue, "item {seq} autocontinue");
        assert_eq!(g.mission_type, s.mission_type, "item {seq} mission_type");
        assert_eq!(
            (g.target_system, g.target_component),
            ME,
            "item {seq} addressed to the station"
        );
    }
}

/// A flight on the runway at home with the autopilot's ground link on a UDP port, the
/// scripted station uploading nothing and commanding nothing; `silent_at_s`: when it says
/// its no-op "arm" and stops its heartbeats (beyond the flight: never).
fn flight(
    autopilot_port: u16,
    station_port: u16,
    duration_s: f64,
    speed: f64,
    silent_at_s: f64,
) -> FlightConfig {
    FlightConfig {
        duration_s,
        realtime: true,
        speed,
        stop_when_landed: false,
        runway_heading: Some(0.0),
        ground_link: Some((
            format!("127.0.0.1:{autopilot_port}"),
            format!("127.0.0.1:{station_port}"),
        )),
        script: Script {
            first_arm_s: silent_at_s,
            steps: vec![ScriptStep {
                after_arm_s: 0.0,
                action: Action::Silence,
            }],
            mission: Vec::new(),
            ..Script::thesis()
        },
        ..FlightConfig::default()
    }
}

/// Starts the flight on its own thread, and a station on a fresh port to fly it.
fn start(duration_s: f64, speed: f64, silent_at_s: f64) -> (Station, JoinHandle<FlightOutcome>) {
    let socket = UdpSocket::bind("127.0.0.1:0").expect("station socket");
    let station_port = socket.local_addr().expect("station addr").port();
    let autopilot_port = free_port();
    let cfg = flight(autopilot_port, station_port, duration_s, speed, silent_at_s);
    let handle = std::thread::spawn(move || {
        fly_report(&aircraft(), &cfg, &FlyOptions::default())
            .expect("flight")
            .outcome
    });
    let to: SocketAddr = format!("127.0.0.1:{autopilot_port}")
        .parse()
        .expect("address");
    let mut station = Station::new(socket, to);
    station.fixed_wing_heartbeat(10.0);
    (station, handle)
}

/// Where the wheels first met the runway after the last flight of at least a second: the
/// first sample whose true attitude and position put some ground-contact point of the model
/// below the runway plane (the simulator's own contact geometry; to one 10 ms frame).
///
/// Read from the log because the flight's `summary.mission` (with the plant's touchdown) is
/// filled in only for a mission the scripted station uploaded, and here it uploads none.
fn touchdown(samples: &[Sample], params: &ModelParams) -> Option<(f64, f64, f64)> {
    let clearance = |s: &Sample| {
        let state = State {
            pos_ned: Vector3::new(s.north, s.east, params.home_alt_msl_m - s.alt),
            vel_body: Vector3::zeros(),
            attitude: Euler::new(s.roll, s.pitch, s.yaw).to_quaternion(),
            omega_body: Vector3::zeros(),
            engine_speed: 0.0,
        };
        ground::clearance_m(params, &state.to_vector())
    };
    let mut airborne_since = None;
    let mut found = None;
    for s in samples {
        if clearance(s) > 0.0 {
            airborne_since.get_or_insert(s.t);
        } else {
            if airborne_since.is_some_and(|t0| s.t - t0 >= 1.0) {
                found = Some((s.t, s.north, s.east));
            }
            airborne_since = None;
        }
    }
    found
}

#[test]
fn a_station_over_udp_uploads_the_mission_arms_starts_it_and_sees_it_flown_to_the_landing() {
    let wall = Instant::now();
    let params = ModelParams::new(&aircraft());
    let home = params.home;
    let mission = default_mission(home);
    let n = mission.len() as u16;
    let (mut gcs, flight) = start(FLIGHT_S, SPEED, SCRIPT_SILENT_AT_S);

    // Upload: each item asked for once, in order, then accepted.
    let (ack, requests) = gcs.upload(&mission);
    assert_eq!(ack.mavtype, MavMissionResult::MAV_MISSION_ACCEPTED);
    assert_eq!(requests, (0..n).collect::<Vec<_>>(), "requests");
    assert_ne!(ack.opaque_id, 0, "the ACK names the stored plan");
    let stored = gcs.download();
    assert_same_mission(&stored, &mission);

    // Arm: refused (with a reason) until the estimator has converged, then accepted; half a
    // second of the autopilot's time between tries.
    let (armed, refusals) = gcs.arm(Duration::from_secs(15), 0.5, SPEED);
    let start_result = gcs.command(MavCmd::MAV_CMD_MISSION_START, [0.0; 7]);
    assert_eq!(start_result, Some(MavResult::MAV_RESULT_ACCEPTED));
    let denied = gcs
        .log
        .texts
        .iter()
        .filter(|t| t.starts_with("Arming denied"))
        .count();
    eprintln!(
        "armed at {:?} ms of the autopilot's time after {refusals} refusals ({denied} texts, e.g. {:?})",
        armed,
        gcs.log.texts.iter().find(|t| t.starts_with("Arming denied"))
    );
    assert!(refusals == 0 || denied > 0, "each refusal says why");

    // Watch until the flight ends, `FLIGHT_S` after the start (landed, stopped, disarmed by
    // then).
    while !flight.is_finished() {
        gcs.pump();
        gcs.inbox.clear();
    }
    let outcome = flight.join().expect("flight thread");
    // What was sent in the last frames is on its way.
    let settle = Instant::now();
    while settle.elapsed() < Duration::from_millis(200) {
        gcs.pump();
        gcs.inbox.clear();
    }
    let log = &gcs.log;
    let wall_s = wall.elapsed().as_secs_f64();
    let sim_s = outcome.samples.last().map_or(0.0, |s| s.t);
    eprintln!(
        "flight: {sim_s:.1} s simulated in {wall_s:.1} s wall; {} heartbeats, {} MISSION_CURRENT, reached {:?}",
        log.heartbeats.len(),
        log.current.len(),
        log.reached
    );
    eprintln!("texts: {:?}", log.texts);

    // Every item reached, each once, in order.
    assert_eq!(
        log.reached,
        (0..n).collect::<Vec<_>>(),
        "MISSION_ITEM_REACHED"
    );
    // The current item went through the whole mission, one step at a time.
    let mut seqs: Vec<u16> = log
        .current
        .iter()
        .filter(|c| c.1 == n)
        .map(|c| c.0)
        .collect();
    seqs.dedup();
    assert_eq!(seqs, (0..n).collect::<Vec<_>>(), "MISSION_CURRENT seq");
    let last = log.current.last().expect("MISSION_CURRENT");
    assert_eq!(last.2, MissionState::MISSION_STATE_COMPLETE, "{last:?}");
    assert_eq!(
        last.3, ack.opaque_id,
        "the mission flown is the one uploaded"
    );
    // Armed, then disarmed once landed: the heartbeat's armed flag rose once and fell once.
    let mut flags: Vec<bool> = log.heartbeats.iter().map(|h| h.0).collect();
    flags.dedup();
    assert_eq!(flags, [false, true, false], "armed flag over the flight");
    assert!(
        !log.texts.iter().any(|t| t.contains("Failsafe")),
        "no failsafe: {:?}",
        log.texts
    );
    assert_eq!(log.foreign, 0, "only the autopilot speaks on its port");
    assert_eq!(log.unparsed, 0, "every frame parses");

    // The simulator's side of the same flight.
    let first_armed = outcome.samples.iter().find(|s| s.armed).expect("armed");
    assert!(
        first_armed.t < SCRIPT_SILENT_AT_S,
        "armed by this station at {:.1} s, before the script's no-op arm",
        first_armed.t
    );
    let last_sample = outcome.samples.last().expect("samples");
    let disarmed = outcome
        .samples
        .iter()
        .skip_while(|s| !s.armed)
        .find(|s| !s.armed)
        .expect("disarmed after the flight");
    assert!(!last_sample.armed, "disarmed at the end");
    let land = mission
        .iter()
        .rfind(|i| i.command == MavCmd::MAV_CMD_NAV_LAND)
        .expect("a NAV_LAND");
    let (ln, le): (f64, f64) = ned_offset(
        home,
        GeoPoint {
            lat_e7: land.x,
            lon_e7: land.y,
        },
    );
    let (t_td, n_td, e_td) = touchdown(&outcome.samples, &params).expect("touched down");
    let distance = (n_td - ln).hypot(e_td - le);
    eprintln!(
        "touchdown at {t_td:.2} s, {n_td:.1} m N {e_td:.1} m E: {distance:.1} m from the landing point; stopped at {:.1} m N {:.1} m E",
        last_sample.north, last_sample.east
    );
    assert!(
        distance < 20.0,
        "touchdown {distance:.1} m from the landing point"
    );
    eprintln!("disarmed at {:.1} s", disarmed.t);
    assert!(disarmed.t > t_td, "disarmed after the touchdown");
}

/// `mission` with `item` inserted at `at`, renumbered.
fn with_item(
    mission: &[MISSION_ITEM_INT_DATA],
    at: usize,
    item: MISSION_ITEM_INT_DATA,
) -> Vec<MISSION_ITEM_INT_DATA> {
    let mut m = mission.to_vec();
    m.insert(at, item);
    for (i, it) in m.iter_mut().enumerate() {
        it.seq = i as u16;
    }
    m
}

fn do_jump(target: f32, repeat: f32) -> MISSION_ITEM_INT_DATA {
    MISSION_ITEM_INT_DATA {
        param1: target,
        param2: repeat,
        command: MavCmd::MAV_CMD_DO_JUMP,
        frame: MavFrame::MAV_FRAME_MISSION,
        target_system: TARGET.0,
        target_component: TARGET.1,
        autocontinue: 1,
        mission_type: MavMissionType::MAV_MISSION_TYPE_MISSION,
        ..Default::default()
    }
}

#[test]
fn bad_uploads_over_udp_get_the_error_that_names_the_fault_and_keep_the_stored_mission() {
    let wall = Instant::now();
    let home = ModelParams::new(&aircraft()).home;
    let good = default_mission(home);
    // On the runway, never armed: 30 s of the autopilot's time at 5x, several times what
    // the station's session takes. The scripted station never arms, so never reaches its
    // steps: it sends heartbeats only.
    let (mut gcs, flight) = start(30.0, 5.0, f64::INFINITY);
    let (ack, _) = gcs.upload(&good);
    assert_eq!(ack.mavtype, MavMissionResult::MAV_MISSION_ACCEPTED);
    assert_same_mission(&gcs.download(), &good);

    // Latitude out of range (MAVLink: -90..90 deg): refused as the item arrives, naming x;
    // nothing after it is asked for.
    let mut bad_lat = good.clone();
    bad_lat[3].x = 910_000_000;
    let (ack, requests) = gcs.upload(&bad_lat);
    assert_eq!(ack.mavtype, MavMissionResult::MAV_MISSION_INVALID_PARAM5_X);
    assert_eq!(requests, [0, 1, 2, 3], "stops at the bad item");
    assert_same_mission(&gcs.download(), &good);

    // 450 m above home: over MIS_ALT_MAX (400 m by default), naming z (param 7).
    let mut too_high = good.clone();
    too_high[2].z = 450.0;
    let (ack, requests) = gcs.upload(&too_high);
    assert_eq!(ack.mavtype, MavMissionResult::MAV_MISSION_INVALID_PARAM7);
    assert_eq!(requests.len(), too_high.len(), "checked once complete");
    assert_same_mission(&gcs.download(), &good);

    // A jump to an item the mission does not have (11 items: 0..=10).
    let bad_jump = with_item(&good, 6, do_jump(20.0, 1.0));
    let (ack, _) = gcs.upload(&bad_jump);
    assert_eq!(ack.mavtype, MavMissionResult::MAV_MISSION_INVALID_SEQUENCE);
    assert_same_mission(&gcs.download(), &good);

    // The same jump to an item that exists is accepted and stored: the refusal above was
    // for its target.
    let jump = with_item(&good, 6, do_jump(1.0, 1.0));
    let (ack, _) = gcs.upload(&jump);
    assert_eq!(ack.mavtype, MavMissionResult::MAV_MISSION_ACCEPTED);
    assert_same_mission(&gcs.download(), &jump);
    // 400 m is still in range: the altitude limit is where the parameter puts it.
    let mut at_limit = good.clone();
    at_limit[2].z = 400.0;
    let (ack, _) = gcs.upload(&at_limit);
    assert_eq!(ack.mavtype, MavMissionResult::MAV_MISSION_ACCEPTED);
    assert_same_mission(&gcs.download(), &at_limit);

    assert!(
        !flight.is_finished(),
        "the station's session ended within the flight ({:.1} s)",
        wall.elapsed().as_secs_f64()
    );
    eprintln!("session: {:.1} s wall", wall.elapsed().as_secs_f64());
    let outcome = flight.join().expect("flight thread");
    assert!(outcome.samples.iter().all(|s| !s.armed), "never armed");
    eprintln!("whole test: {:.1} s wall", wall.elapsed().as_secs_f64());
}
