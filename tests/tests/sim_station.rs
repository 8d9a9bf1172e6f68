//! `sim-host sim` flown by an outside ground station, as a user flies it from QGroundControl:
//! three programs (here three threads of this test, or QEMU beside them), the simulator
//! serving whatever autopilot connects, the autopilot's ground link on UDP, and a station of
//! the tests' own (`system_tests::station`: the mavlink crate alone) that sets the GPS latency
//! the simulator advises, uploads the default mission, arms, starts it and watches it flown.
//!
//! - The host build: the firmware's SITL loop (`firmware::sitl`, what
//!   `cargo run -p firmware -- --sim tcp:...` runs) connects to the simulator's TCP port; the
//!   flight is paced at [`SPEED`] so that this station, which lives in wall time, keeps its
//!   1 Hz heartbeat of the autopilot's clock. The whole mission, to the landing.
//! - The MCU image: `sim-host sim --link qemu` boots it, and the station speaks to its ground
//!   bridge. The image answers at about the pace of real time, so the flight is not paced;
//!   the station watches the take-off and the first leg, then stops the simulator as Ctrl-C
//!   would.

use common::math::geodetic::ned_offset;
use mavlink::dialects::common::*;
use sim_host::aircraft::Aircraft;
use sim_host::commands::fly::{FlyReport, LinkKind};
use sim_host::commands::sim::{sim_report, Ready, SimOptions};
use sim_host::flight::missions::default_mission;
use sim_host::flight::summary::Ending;
use sim_host::flight::FlightConfig;
use sim_host::link::qemu::QemuConfig;
use sim_host::plant::ModelParams;
use std::net::{SocketAddr, UdpSocket};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;
use std::thread::JoinHandle;
use std::time::Duration;
use system_tests::station::Station;
use system_tests::{build_mcu_firmware, tool_available};

/// Simulated seconds per wall second of the host build's flight.
const SPEED: f64 = 25.0;
/// The host build's flight, s: the mission is flown, landed and disarmed by about 352 s and
/// the station then hears a disarmed heartbeat.
const HOST_FLIGHT_S: f64 = 380.0;

fn aircraft() -> Aircraft {
    Aircraft::ultrastick25e().expect("built-in aircraft")
}

/// The simulator on its own thread; returns where it waits and the thread.
fn start_sim(
    cfg: FlightConfig,
    opts: SimOptions,
) -> (Ready, JoinHandle<anyhow::Result<FlyReport>>) {
    let (tx, rx) = mpsc::channel();
    let sim = std::thread::spawn(move || {
        sim_report(&aircraft(), &cfg, &opts, |ready| {
            let _ = tx.send(ready.clone());
        })
    });
    let ready = rx
        .recv_timeout(Duration::from_secs(30))
        .expect("the simulator is waiting");
    (ready, sim)
}

/// The first part of a flight, as a user flies it: the GPS latency the simulator prints, the
/// mission uploaded, armed once the estimator has converged, MISSION_START. Returns the
/// mission's length.
fn upload_arm_and_start(gcs: &mut Station, speed: f64) -> u16 {
    let params = ModelParams::new(&aircraft());
    gcs.fixed_wing_heartbeat(20.0);
    let delay = aircraft().sensors.gps.latency_s as f32;
    assert!(gcs.set_param("EKF_GPS_DELAY", delay), "EKF_GPS_DELAY set");
    let mission = default_mission(params.home);
    let (ack, _) = gcs.upload(&mission);
    assert_eq!(ack.mavtype, MavMissionResult::MAV_MISSION_ACCEPTED);
    let (armed_ms, refusals) = gcs.arm(Duration::from_secs(60), 0.5, speed);
    eprintln!("armed at {armed_ms:?} ms of the autopilot's clock after {refusals} refusals");
    assert_eq!(
        gcs.command(MavCmd::MAV_CMD_MISSION_START, [0.0; 7]),
        Some(MavResult::MAV_RESULT_ACCEPTED)
    );
    mission.len() as u16
}

#[test]
fn a_station_flies_the_default_mission_through_sim_host_sim_and_the_host_build() {
    let out = tempfile::tempdir().expect("tempdir");
    let cfg = FlightConfig {
        duration_s: HOST_FLIGHT_S,
        realtime: true,
        speed: SPEED,
        runway_heading: Some(0.0),
        scripted_station: false,
        until_link_closes: true,
        ..FlightConfig::default()
    };
    let opts = SimOptions {
        link: LinkKind::Tcp,
        bind: "127.0.0.1:0".into(),
        wait: Some(Duration::from_secs(20)),
        out: Some(out.path().to_path_buf()),
        plots: false,
        ..SimOptions::default()
    };
    let (ready, sim) = start_sim(cfg, opts);
    let sim_addr = ready
        .sim_link
        .strip_prefix("tcp ")
        .expect("a tcp address")
        .to_string();

    // The autopilot: the host build's SITL loop, its ground link on a UDP port of its own.
    let mut ground = firmware::sitl::GcsUdp::open("127.0.0.1:0", None).expect("ground link");
    let ground_addr = ground.local_addr().expect("ground address");
    let autopilot = std::thread::spawn(move || {
        let endpoint = firmware::sitl::SimEndpoint::Tcp(sim_addr);
        let mut link =
            firmware::sitl::connect(&endpoint, Duration::from_secs(10)).expect("connects");
        let mut app = firmware::app::App::new();
        firmware::sitl::run_with(
            link.as_mut(),
            &mut app,
            Duration::from_secs(5),
            Some(&mut ground),
            None,
            None,
        )
    });

    let socket = UdpSocket::bind("127.0.0.1:0").expect("station socket");
    let mut gcs = Station::new(socket, ground_addr);
    let n = upload_arm_and_start(&mut gcs, SPEED);
    while !sim.is_finished() {
        gcs.pump();
        gcs.inbox.clear();
    }
    let r = sim.join().expect("sim thread").expect("the flight");
    // The simulator closed its end at the duration: the autopilot saw the link close.
    let ended = autopilot.join().expect("autopilot thread");
    assert!(
        matches!(&ended, Err(e) if e.kind() == std::io::ErrorKind::UnexpectedEof),
        "{ended:?}"
    );

    let log = &gcs.log;
    eprintln!("reached {:?}; texts {:?}", log.reached, log.texts);
    // Home, set by arming on the runway, is held in the datum it was set in for the whole
    // flight, and the aircraft's altitude is given in that datum (within a millimetre of
    // rounding), while the estimator learns its barometer's offset from GPS.
    let first = log
        .armed_homes
        .first()
        .copied()
        .expect("HOME_POSITION while armed");
    let moved = log
        .armed_homes
        .iter()
        .map(|h| (h.2 - first.2).abs())
        .max()
        .unwrap_or(0);
    assert!(
        log.armed_homes.len() > 50
            && log
                .armed_homes
                .iter()
                .all(|h| h.0 == first.0 && h.1 == first.1),
        "{} homes",
        log.armed_homes.len()
    );
    assert_eq!(
        moved, 0,
        "home's altitude moved by up to {moved} mm in flight"
    );
    let off = log
        .armed_datums
        .iter()
        .map(|d| (d - first.2).abs())
        .max()
        .unwrap_or(i32::MAX);
    assert!(
        off <= 1,
        "altitude less height above home is {off} mm off home's"
    );
    assert_eq!(
        log.reached,
        (0..n).collect::<Vec<_>>(),
        "every item reached"
    );
    let mut flags: Vec<bool> = log.heartbeats.iter().map(|h| h.0).collect();
    flags.dedup();
    assert_eq!(
        flags,
        [false, true, false],
        "armed, then disarmed once landed"
    );
    assert!(
        !log.texts.iter().any(|t| t.contains("Failsafe")),
        "{:?}",
        log.texts
    );

    // The simulator's side: the flight to its duration, a touchdown at home, every file.
    let s = &r.outcome.summary;
    assert_eq!(s.ended, Ending::Duration);
    assert!(s.autopilot_rx.is_none() && s.mission.is_none());
    let td = s.touchdown.expect("a touchdown");
    let home = ModelParams::new(&aircraft()).home;
    let mission = default_mission(home);
    let l = mission
        .iter()
        .rfind(|i| i.command == MavCmd::MAV_CMD_NAV_LAND)
        .expect("a NAV_LAND");
    let land = ned_offset::<f64>(
        home,
        common::math::geodetic::GeoPoint {
            lat_e7: l.x,
            lon_e7: l.y,
        },
    );
    let distance = (td.north_m - land.0).hypot(td.east_m - land.1);
    eprintln!(
        "touchdown {distance:.1} m from the landing point, sink {:.2} m/s",
        td.sink_rate_mps
    );
    assert!(distance < 20.0 && td.sink_rate_mps < 1.5, "{td:?}");
    assert!(!r.outcome.samples.last().expect("samples").armed);
    for f in ["simlink.tlog", "flight.csv", "summary.json"] {
        assert!(out.path().join(f).is_file(), "{f} written");
    }
}

#[test]
fn a_station_flies_the_mcu_image_through_sim_host_sim_over_its_ground_bridge() {
    if !tool_available("qemu-system-arm") {
        return;
    }
    let elf = build_mcu_firmware();
    let out = tempfile::tempdir().expect("tempdir");
    // Ctrl-C, as the user would press it once the first leg is flown.
    let stop: &'static AtomicBool = Box::leak(Box::new(AtomicBool::new(false)));
    let cfg = FlightConfig {
        // A bound should the station fail; it stops the flight well before.
        duration_s: 150.0,
        runway_heading: Some(0.0),
        scripted_station: false,
        until_link_closes: true,
        stop: Some(stop),
        ..FlightConfig::default()
    };
    let opts = SimOptions {
        link: LinkKind::Qemu,
        qemu: QemuConfig {
            elf,
            ..QemuConfig::default()
        },
        gcs_bind: "127.0.0.1:0".into(),
        gcs_remote: None,
        out: Some(out.path().to_path_buf()),
        plots: false,
        ..SimOptions::default()
    };
    let (ready, sim) = start_sim(cfg, opts);
    let ground: SocketAddr = ready.ground.expect("the image's ground link");

    let socket = UdpSocket::bind("127.0.0.1:0").expect("station socket");
    let mut gcs = Station::new(socket, ground);
    upload_arm_and_start(&mut gcs, 1.0);
    // The take-off (item 0) and the first leg (item 1).
    while !gcs.log.reached.contains(&1) {
        assert!(
            !sim.is_finished(),
            "the flight ended early: {:?}",
            gcs.log.texts
        );
        gcs.pump();
        gcs.inbox.clear();
    }
    stop.store(true, Ordering::Relaxed);
    let r = sim.join().expect("sim thread").expect("the flight");
    assert_eq!(gcs.log.reached, [0, 1]);
    assert!(gcs.log.heartbeats.iter().any(|h| h.0), "armed");
    let s = &r.outcome.summary;
    assert_eq!(s.ended, Ending::Stopped);
    let last = r.outcome.samples.last().expect("samples");
    eprintln!(
        "stopped at {:.1} s ({:.2}x real time), {:.1} m up",
        last.t, s.real_time_factor, last.alt
    );
    assert!(last.armed && last.alt > 40.0, "{last:?}");
    assert_eq!(s.sim_rx.crc_errors, 0);
    for f in ["simlink.tlog", "flight.csv", "summary.json", "mcu.defmt"] {
        assert!(out.path().join(f).is_file(), "{f} written");
    }
}

/// The MCU image's flight log, listed and downloaded over its ground bridge by pymavlink the way
/// MAVProxy's `log` module does, armed and then disarmed on the runway, and erased: the bytes
/// are the log in the image's flash sectors (QEMU's storage file, read by the script's own
/// reader of the block layout), and pyulog reads the download without a warning.
#[test]
fn pymavlink_downloads_the_mcu_images_flight_log_from_its_flash_byte_for_byte() {
    if !tool_available("qemu-system-arm") || !tool_available("python3") {
        return;
    }
    let elf = build_mcu_firmware();
    let out = tempfile::tempdir().expect("tempdir");
    let storage = out.path().join("storage.bin");
    let stop: &'static AtomicBool = Box::leak(Box::new(AtomicBool::new(false)));
    let cfg = FlightConfig {
        duration_s: 240.0,
        runway_heading: Some(0.0),
        scripted_station: false,
        until_link_closes: true,
        stop: Some(stop),
        ..FlightConfig::default()
    };
    let opts = SimOptions {
        link: LinkKind::Qemu,
        qemu: QemuConfig {
            elf,
            storage: Some(storage.clone()),
            ..QemuConfig::default()
        },
        gcs_bind: "127.0.0.1:0".into(),
        gcs_remote: None,
        out: Some(out.path().to_path_buf()),
        plots: false,
        ..SimOptions::default()
    };
    let (ready, sim) = start_sim(cfg, opts);
    let ground: SocketAddr = ready.ground.expect("the image's ground link");
    let downloaded = out.path().join("downloaded.ulg");
    let script = system_tests::workspace_root().join("tests/interop/pymavlink_logs.py");
    let run = std::process::Command::new("python3")
        .arg(script)
        .arg(ground.port().to_string())
        .arg(format!("image:{}", storage.display()))
        .arg(&downloaded)
        .output()
        .expect("python3 runs");
    stop.store(true, Ordering::Relaxed);
    let _ = sim.join();
    let text = String::from_utf8_lossy(&run.stdout);
    eprintln!("{text}{}", String::from_utf8_lossy(&run.stderr));
    assert!(run.status.success(), "pymavlink checks:\n{text}");
    // PX4's reader, as the SITL log's test reads it (sim-host/tests/flight_log.rs).
    let info = std::process::Command::new("ulog_info")
        .arg(&downloaded)
        .output()
        .expect("ulog_info runs");
    let said = format!(
        "{}{}",
        String::from_utf8_lossy(&info.stdout),
        String::from_utf8_lossy(&info.stderr)
    );
    assert!(info.status.success(), "{said}");
    assert!(!said.to_lowercase().contains("warning"), "{said}");
    assert!(said.contains("No Dropouts"), "{said}");
    for topic in ["vehicle_attitude", "control_loops", "vehicle_status"] {
        assert!(said.contains(topic), "{topic} in the log: {said}");
    }
}
