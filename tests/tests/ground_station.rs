//! A ground station (this test, speaking MAVLink 2 over UDP) against the SITL autopilot, which
//! is fed by a simulator over TCP in lock-step: the autopilot's clock is the simulator's, paced
//! here at a few times real time; message rates are counted in that clock.
//!
//! The simulated airplane sits on the ground at home, at rest: the estimator converges there
//! (as before a real flight), which is what the pre-arm checks wait for.

use common::battery::cell_ocv;
use common::gcs::client::{command_long, gcs_heartbeat};
use common::link::framing::{Frame, FrameParser, Sender};
use common::link::simlink::{
    encode_battery_status, encode_hil_gps, encode_hil_sensor, SensorFrame,
};
use common::math::atmosphere::standard_atmosphere;
use common::math::geodetic::GeoPoint;
use common::sensors::{BaroSample, BatterySample, GpsFix, ImuSample, MagSample, PitotSample};
use firmware::app::App;
use firmware::sitl::{self, FileStorage, GcsUdp, SimEndpoint};
use mavlink::dialects::common::*;
use mavlink::Message;
use nalgebra::Vector3;
use sim_host::link::lockstep::Lockstep;
use sim_host::link::transport::TcpServer;
use std::net::{SocketAddr, UdpSocket};
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

const HOME_ALT_M: f32 = 250.0;
/// Simulated seconds per wall second.
const SPEEDUP: u64 = 1;

/// The flight pack on the ground: a 3S LiPo at 80 % (3 x 4.02 V at rest), the avionics
/// drawing 0.35 A through the pack's 24 mOhm (`BAT_R_INTERNAL`), read at 10 Hz.
const PACK_SOC: f32 = 0.8;
const PACK_CURRENT_A: f32 = 0.35;

fn pack() -> BatterySample {
    BatterySample {
        voltage_v: 3.0 * cell_ocv(PACK_SOC) - PACK_CURRENT_A * 0.024,
        current_a: PACK_CURRENT_A,
    }
}

/// Sensor frames of an airplane at rest on the ground at home, heading north, and its power
/// monitor's BATTERY_STATUS.
fn at_rest(k: u64, gps: bool) -> (u64, Vec<MavMessage>) {
    let t = k * 10_000;
    let air = standard_atmosphere(HOME_ALT_M);
    let frame = SensorFrame {
        time_us: t,
        imu: Some(ImuSample {
            accel: Vector3::new(0.0, 0.0, -9.8056),
            gyro: Vector3::zeros(),
        }),
        mag: k.is_multiple_of(2).then_some(MagSample {
            field: Vector3::new(0.18, -0.002, 0.52),
        }),
        baro: k.is_multiple_of(2).then_some(BaroSample {
            pressure_pa: air.pressure_pa,
            temperature_c: air.temperature_k - 273.15,
        }),
        pitot: k.is_multiple_of(2).then_some(PitotSample {
            diff_pressure_pa: 0.0,
        }),
        reset: false,
    };
    let mut m = vec![MavMessage::HIL_SENSOR(encode_hil_sensor(
        &frame, HOME_ALT_M,
    ))];
    if gps && k.is_multiple_of(20) {
        let fix = GpsFix {
            position: GeoPoint::from_deg(44.7258357, -93.07501316),
            alt_amsl_m: HOME_ALT_M,
            vel_ned: Vector3::zeros(),
            fix_type: 3,
            satellites: 12,
            hdop: 0.8,
        };
        m.push(MavMessage::HIL_GPS(encode_hil_gps(t, &fix)));
    }
    if k.is_multiple_of(10) {
        m.push(MavMessage::BATTERY_STATUS(encode_battery_status(&pack())));
    }
    (t, m)
}

/// One SITL autopilot with its simulator, until dropped.
struct Sitl {
    gcs_addr: SocketAddr,
    stop: Arc<AtomicBool>,
    threads: Vec<std::thread::JoinHandle<()>>,
}

impl Sitl {
    fn start(storage: Option<PathBuf>, gps: Arc<AtomicBool>) -> Self {
        Self::start_with_logs(storage, gps, None)
    }

    /// [`Sitl::start`] with its flight logs in `logs`.
    fn start_with_logs(
        storage: Option<PathBuf>,
        gps: Arc<AtomicBool>,
        logs: Option<PathBuf>,
    ) -> Self {
        let stop = Arc::new(AtomicBool::new(false));
        let gcs = GcsUdp::open("127.0.0.1:0", None).expect("gcs socket");
        let gcs_addr = gcs.local_addr().expect("gcs addr");
        let (tx, rx) = std::sync::mpsc::channel();
        let sim_stop = stop.clone();
        let sim = std::thread::spawn(move || {
            let server = TcpServer::listen("127.0.0.1:0", Duration::from_secs(10), |addr| {
                let _ = tx.send(addr);
            })
            .expect("autopilot connects");
            let mut link = Lockstep::new(server, Duration::from_secs(5));
            link.wait_for_autopilot(Duration::from_secs(10))
                .expect("autopilot announces itself");
            let start = Instant::now();
            let mut k = 0u64;
            while !sim_stop.load(Ordering::Relaxed) {
                let (t, msgs) = at_rest(k, gps.load(Ordering::Relaxed));
                // Paced at a few times real time: the autopilot's clock is this one, and the
                // rates below are counted in it.
                let due = Duration::from_micros(t / SPEEDUP);
                if let Some(wait) = due.checked_sub(start.elapsed()) {
                    std::thread::sleep(wait);
                }
                if link.exchange(t, &msgs).is_err() {
                    break;
                }
                k += 1;
            }
        });
        let addr = rx.recv().expect("simulator listening");
        let fw_stop = stop.clone();
        let fw = std::thread::spawn(move || {
            let mut link =
                sitl::connect(&SimEndpoint::Tcp(addr.to_string()), Duration::from_secs(5))
                    .expect("connect");
            let mut app = App::new();
            let mut storage = FileStorage::open(storage);
            storage.load_into(&mut app);
            let mut gcs = gcs;
            let mut logs = logs.map(|dir| sitl::LogFiles::new(dir, &mut app));
            let _ = sitl::run_with(
                link.as_mut(),
                &mut app,
                Duration::from_secs(1),
                Some(&mut gcs),
                Some(&mut storage),
                logs.as_mut(),
            );
            drop(fw_stop);
        });
        Self {
            gcs_addr,
            stop,
            threads: vec![sim, fw],
        }
    }
}

impl Drop for Sitl {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        for t in self.threads.drain(..) {
            let _ = t.join();
        }
    }
}

/// A ground station: system 255, component 190, as QGroundControl.
struct Gcs {
    socket: UdpSocket,
    to: SocketAddr,
    parser: FrameParser,
    sender: Sender,
    inbox: Vec<Frame>,
}

impl Gcs {
    fn new(to: SocketAddr) -> Self {
        let socket = UdpSocket::bind("127.0.0.1:0").expect("bind");
        socket.set_nonblocking(true).expect("non-blocking");
        let mut g = Self {
            socket,
            to,
            parser: FrameParser::new(),
            sender: Sender::new(255, 190),
            inbox: Vec::new(),
        };
        g.send(&gcs_heartbeat());
        g
    }

    fn send(&mut self, m: &MavMessage) {
        let raw = self.sender.encode(m);
        self.socket.send_to(raw.raw_bytes(), self.to).expect("send");
    }

    fn send_raw(&mut self, bytes: &[u8]) {
        self.socket.send_to(bytes, self.to).expect("send");
    }

    /// Takes what has arrived so far (the autopilot streams without pause, so this must not
    /// wait for a quiet moment).
    fn pump(&mut self) {
        let mut buf = [0u8; 9000];
        while let Ok((n, _)) = self.socket.recv_from(&mut buf) {
            let inbox = &mut self.inbox;
            self.parser.push(&buf[..n], |f| inbox.push(f));
        }
        std::thread::sleep(Duration::from_millis(2));
    }

    /// Waits for the first message `pick` accepts.
    fn wait<T>(&mut self, secs: f64, mut pick: impl FnMut(&MavMessage) -> Option<T>) -> Option<T> {
        let end = Instant::now() + Duration::from_secs_f64(secs);
        while Instant::now() < end {
            self.pump();
            if let Some(i) = self.inbox.iter().position(|f| pick(&f.message).is_some()) {
                let f = self.inbox.remove(i);
                return pick(&f.message);
            }
            self.inbox.clear();
        }
        None
    }

    fn command(&mut self, cmd: MavCmd, p: [f32; 7]) -> Option<MavResult> {
        self.send(&command_long(cmd, p));
        self.wait(2.0, |m| match m {
            MavMessage::COMMAND_ACK(a) if a.command == cmd => Some(a.result),
            _ => None,
        })
    }

    fn param_set(&mut self, name: &str, value: f32) -> Option<f32> {
        self.send(&MavMessage::PARAM_SET(PARAM_SET_DATA {
            param_value: value,
            target_system: 1,
            target_component: 1,
            param_id: name.into(),
            param_type: MavParamType::MAV_PARAM_TYPE_REAL32,
        }));
        let name = name.to_string();
        self.wait(2.0, move |m| match m {
            MavMessage::PARAM_VALUE(v) if v.param_id.to_str().ok() == Some(name.as_str()) => {
                Some(v.param_value)
            }
            _ => None,
        })
    }

    fn param_read(&mut self, name: &str) -> Option<f32> {
        self.send(&MavMessage::PARAM_REQUEST_READ(PARAM_REQUEST_READ_DATA {
            param_index: -1,
            target_system: 1,
            target_component: 1,
            param_id: name.into(),
        }));
        let name = name.to_string();
        self.wait(2.0, move |m| match m {
            MavMessage::PARAM_VALUE(v) if v.param_id.to_str().ok() == Some(name.as_str()) => {
                Some(v.param_value)
            }
            _ => None,
        })
    }
}

fn heartbeat_of(m: &MavMessage) -> Option<HEARTBEAT_DATA> {
    match m {
        MavMessage::HEARTBEAT(h) => Some(h.clone()),
        _ => None,
    }
}

#[test]
fn parameters_download_set_refuse_and_persist_across_a_reboot() {
    let dir = tempfile::tempdir().expect("tempdir");
    let storage = dir.path().join("sitl-storage.bin");
    let gps = Arc::new(AtomicBool::new(true));
    let sitl = Sitl::start(Some(storage.clone()), gps.clone());
    let mut gcs = Gcs::new(sitl.gcs_addr);
    let hb = gcs.wait(5.0, heartbeat_of).expect("heartbeat");
    assert_eq!(hb.mavtype, MavType::MAV_TYPE_FIXED_WING);
    assert_eq!(hb.autopilot, MavAutopilot::MAV_AUTOPILOT_GENERIC);

    // Full download: every index once, one stable count.
    gcs.send(&MavMessage::PARAM_REQUEST_LIST(PARAM_REQUEST_LIST_DATA {
        target_system: 1,
        target_component: 1,
    }));
    let mut seen = std::collections::BTreeMap::new();
    let mut count = None;
    let end = Instant::now() + Duration::from_secs(10);
    while Instant::now() < end && count.is_none_or(|c| seen.len() < c) {
        gcs.pump();
        for f in gcs.inbox.drain(..) {
            if let MavMessage::PARAM_VALUE(v) = f.message {
                let c = usize::from(v.param_count);
                assert_eq!(*count.get_or_insert(c), c, "param_count changed");
                let name = v.param_id.to_str().unwrap_or("").to_string();
                let prev = seen.insert(v.param_index, name.clone());
                assert!(prev.is_none(), "index {} sent twice", v.param_index);
            }
        }
    }
    let count = count.expect("PARAM_VALUEs");
    assert_eq!(seen.len(), count, "every index");
    assert!(seen.values().any(|n| n == "RLL_KP") && seen.values().any(|n| n == "EKF_GYR_NOISE"));

    // Set and read back; refuse NaN and out-of-bounds with the unchanged value echoed.
    assert_eq!(gcs.param_set("RLL_KP", -0.8), Some(-0.8));
    assert_eq!(gcs.param_read("RLL_KP"), Some(-0.8));
    assert_eq!(gcs.param_set("RLL_KP", f32::NAN), Some(-0.8));
    assert_eq!(
        gcs.param_set("RLL_KP", 5.0),
        Some(-0.8),
        "positive roll gain is out of bounds"
    );

    // Garbage and truncated frames on the link do not stop the heartbeat.
    let mut junk = vec![0xFD, 0x40, 0x00, 0x00];
    junk.extend((0..500).map(|i| (i * 37 % 251) as u8));
    gcs.send_raw(&junk);
    let raw = gcs
        .sender
        .encode(&MavMessage::PARAM_REQUEST_LIST(PARAM_REQUEST_LIST_DATA {
            target_system: 1,
            target_component: 1,
        }));
    let truncated = raw.raw_bytes()[..raw.raw_bytes().len() - 3].to_vec();
    gcs.send_raw(&truncated);
    gcs.inbox.clear();
    assert!(
        gcs.wait(3.0, heartbeat_of).is_some(),
        "heartbeat after garbage"
    );

    // Reboot: a new autopilot on the same storage file has the value.
    drop(gcs);
    drop(sitl);
    let sitl = Sitl::start(Some(storage), gps);
    let mut gcs = Gcs::new(sitl.gcs_addr);
    assert_eq!(
        gcs.param_read("RLL_KP"),
        Some(-0.8),
        "persisted across the reboot"
    );
}

#[test]
fn a_mission_round_trips_bit_for_bit_with_nan_fields() {
    let gps = Arc::new(AtomicBool::new(true));
    let sitl = Sitl::start(None, gps);
    let mut gcs = Gcs::new(sitl.gcs_addr);
    assert!(gcs.wait(5.0, heartbeat_of).is_some());
    let items: Vec<MISSION_ITEM_INT_DATA> = (0..5u16)
        .map(|seq| MISSION_ITEM_INT_DATA {
            param1: if seq == 2 { f32::NAN } else { seq as f32 },
            param2: 5.0,
            param3: 0.0,
            param4: f32::NAN,
            x: 447_258_357 + i32::from(seq) * 1000,
            y: -930_750_131,
            z: 100.0 + f32::from(seq),
            seq,
            command: MavCmd::MAV_CMD_NAV_WAYPOINT,
            target_system: 1,
            target_component: 1,
            frame: MavFrame::MAV_FRAME_GLOBAL_RELATIVE_ALT,
            current: 0,
            autocontinue: 1,
            mission_type: MavMissionType::MAV_MISSION_TYPE_MISSION,
        })
        .collect();
    gcs.send(&MavMessage::MISSION_COUNT(MISSION_COUNT_DATA {
        count: items.len() as u16,
        target_system: 1,
        target_component: 1,
        mission_type: MavMissionType::MAV_MISSION_TYPE_MISSION,
        opaque_id: 0,
    }));
    let mut acked = None;
    let end = Instant::now() + Duration::from_secs(10);
    while acked.is_none() && Instant::now() < end {
        gcs.pump();
        let inbox: Vec<Frame> = gcs.inbox.drain(..).collect();
        for f in inbox {
            match f.message {
                MavMessage::MISSION_REQUEST_INT(r) => {
                    let item = items[usize::from(r.seq)].clone();
                    gcs.send(&MavMessage::MISSION_ITEM_INT(item));
                }
                MavMessage::MISSION_ACK(a) => acked = Some(a.mavtype),
                _ => {}
            }
        }
    }
    assert_eq!(acked, Some(MavMissionResult::MAV_MISSION_ACCEPTED));

    gcs.send(&MavMessage::MISSION_REQUEST_LIST(
        MISSION_REQUEST_LIST_DATA {
            target_system: 1,
            target_component: 1,
            mission_type: MavMissionType::MAV_MISSION_TYPE_MISSION,
        },
    ));
    let n = gcs
        .wait(3.0, |m| match m {
            MavMessage::MISSION_COUNT(c) => Some(c.count),
            _ => None,
        })
        .expect("count");
    assert_eq!(usize::from(n), items.len());
    for (seq, sent) in items.iter().enumerate() {
        gcs.send(&MavMessage::MISSION_REQUEST_INT(MISSION_REQUEST_INT_DATA {
            seq: seq as u16,
            target_system: 1,
            target_component: 1,
            mission_type: MavMissionType::MAV_MISSION_TYPE_MISSION,
        }));
        let got = gcs
            .wait(3.0, |m| match m {
                MavMessage::MISSION_ITEM_INT(i) if usize::from(i.seq) == seq => Some(i.clone()),
                _ => None,
            })
            .expect("item");
        for (a, b) in [
            (got.param1, sent.param1),
            (got.param2, sent.param2),
            (got.param4, sent.param4),
            (got.z, sent.z),
        ] {
            assert_eq!(a.to_bits(), b.to_bits(), "item {seq} bit-exact");
        }
        assert_eq!((got.x, got.y, got.command), (sent.x, sent.y, sent.command));
    }
    gcs.send(&MavMessage::MISSION_ACK(MISSION_ACK_DATA {
        target_system: 1,
        target_component: 1,
        mavtype: MavMissionResult::MAV_MISSION_ACCEPTED,
        mission_type: MavMissionType::MAV_MISSION_TYPE_MISSION,
        opaque_id: 0,
    }));
}

#[test]
fn arming_waits_for_the_pre_arm_checks_and_streams_follow_their_interval() {
    let gps = Arc::new(AtomicBool::new(false));
    let sitl = Sitl::start(None, gps.clone());
    let mut gcs = Gcs::new(sitl.gcs_addr);
    assert!(gcs.wait(5.0, heartbeat_of).is_some());
    // No GPS: the checks refuse, and say why.
    std::thread::sleep(Duration::from_secs(2));
    let r = gcs.command(
        MavCmd::MAV_CMD_COMPONENT_ARM_DISARM,
        [1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    );
    assert!(
        matches!(
            r,
            Some(MavResult::MAV_RESULT_DENIED | MavResult::MAV_RESULT_TEMPORARILY_REJECTED)
        ),
        "{r:?}"
    );
    // With GPS the estimator converges and the same command is accepted.
    gps.store(true, Ordering::Relaxed);
    let end = Instant::now() + Duration::from_secs(30);
    let mut armed = false;
    while !armed && Instant::now() < end {
        std::thread::sleep(Duration::from_millis(500));
        armed = gcs.command(
            MavCmd::MAV_CMD_COMPONENT_ARM_DISARM,
            [1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        ) == Some(MavResult::MAV_RESULT_ACCEPTED);
    }
    assert!(armed, "arming accepted once converged");
    let hb = gcs
        .wait(3.0, |m| {
            heartbeat_of(m).filter(|h| h.base_mode.bits() & 128 != 0)
        })
        .expect("armed heartbeat");
    assert_eq!(hb.system_status, MavState::MAV_STATE_ACTIVE);

    // Every telemetry stream at 10 Hz: count each over 2 s of (real-time) simulation.
    let streams: [(u32, &str); 10] = [
        (1, "SYS_STATUS"),
        (24, "GPS_RAW_INT"),
        (30, "ATTITUDE"),
        (33, "GLOBAL_POSITION_INT"),
        (42, "MISSION_CURRENT"),
        (62, "NAV_CONTROLLER_OUTPUT"),
        (74, "VFR_HUD"),
        (147, "BATTERY_STATUS"),
        (242, "HOME_POSITION"),
        (245, "EXTENDED_SYS_STATE"),
    ];
    for (id, name) in streams {
        let r = gcs.command(
            MavCmd::MAV_CMD_SET_MESSAGE_INTERVAL,
            [id as f32, 100_000.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        );
        assert_eq!(r, Some(MavResult::MAV_RESULT_ACCEPTED), "{name}");
    }
    // Count in the autopilot's own time: the ATTITUDE timestamps bound a window of simulated
    // time, whatever the delivery latency of this test's socket.
    std::thread::sleep(Duration::from_millis(300));
    gcs.pump();
    gcs.inbox.clear();
    let start = Instant::now();
    let mut arrived: Vec<(u32, Option<u32>)> = Vec::new();
    while start.elapsed() < Duration::from_secs(3) {
        gcs.pump();
        for f in gcs.inbox.drain(..) {
            let t = match &f.message {
                MavMessage::ATTITUDE(a) => Some(a.time_boot_ms),
                _ => None,
            };
            arrived.push((f.message.message_id(), t));
        }
    }
    let stamps: Vec<(usize, u32)> = arrived
        .iter()
        .enumerate()
        .filter_map(|(i, (_, t))| t.map(|t| (i, t)))
        .collect();
    let (&(i0, t0), &(i1, t1)) = (
        stamps.first().expect("ATTITUDE"),
        stamps.last().expect("ATTITUDE"),
    );
    let window_s = f64::from(t1 - t0) / 1000.0;
    assert!(window_s > 1.5, "window {window_s} s");
    let mut counts = std::collections::BTreeMap::new();
    for (id, _) in &arrived[i0..i1] {
        *counts.entry(*id).or_insert(0u32) += 1;
    }
    for (id, name) in streams {
        let n = counts.get(&id).copied().unwrap_or(0);
        let rate = f64::from(n) / window_s;
        assert!(
            (rate - 10.0).abs() <= 1.5,
            "{name}: {rate:.2} Hz, asked for 10 Hz ({counts:?} over {window_s} s)"
        );
    }
}

#[test]
fn a_dozen_stations_in_turn_each_get_their_answers() {
    // More stations than the SITL link keeps at once (eight besides the fixed one): the one
    // heard longest ago makes room, so the newest always gets its answer.
    let gps = Arc::new(AtomicBool::new(true));
    let sitl = Sitl::start(None, gps);
    let mut stations: Vec<Gcs> = (0..12).map(|_| Gcs::new(sitl.gcs_addr)).collect();
    for (i, g) in stations.iter_mut().enumerate() {
        assert_eq!(g.param_read("NAV_ASPD"), Some(17.0), "station {i} answered");
    }
}

#[test]
fn a_request_behind_a_corrupt_length_in_its_datagram_is_answered_at_once() {
    let gps = Arc::new(AtomicBool::new(true));
    let sitl = Sitl::start(None, gps);
    let mut gcs = Gcs::new(sitl.gcs_addr);
    gcs.wait(5.0, heartbeat_of).expect("heartbeat");
    // One datagram: a heartbeat whose length byte was hit (claiming 200 bytes), then a read.
    let mut bad = gcs.sender.encode(&gcs_heartbeat()).raw_bytes().to_vec();
    bad[1] = 200;
    let read = gcs
        .sender
        .encode(&MavMessage::PARAM_REQUEST_READ(PARAM_REQUEST_READ_DATA {
            param_index: -1,
            target_system: 1,
            target_component: 1,
            param_id: "NAV_ASPD".into(),
        }));
    bad.extend_from_slice(read.raw_bytes());
    gcs.send_raw(&bad);
    let value = gcs.wait(1.0, |m| match m {
        MavMessage::PARAM_VALUE(v) if v.param_id.to_str().ok() == Some("NAV_ASPD") => {
            Some(v.param_value)
        }
        _ => None,
    });
    assert_eq!(value, Some(17.0), "answered within a second, not held");
}

/// Runs one of `tests/interop/`'s pymavlink scripts against a fresh SITL vehicle; false when
/// pymavlink is missing outside CI (skipped), a failed assertion when a check fails.
fn pymavlink_script(name: &str) -> bool {
    pymavlink_script_with(name, None).is_some()
}

/// [`pymavlink_script`] with the vehicle's logs in `logs`, passed as the script's second
/// argument; what it printed, `None` when skipped.
fn pymavlink_script_with(name: &str, logs: Option<&std::path::Path>) -> Option<String> {
    if !system_tests::pymavlink_available() {
        return None;
    }
    let gps = Arc::new(AtomicBool::new(true));
    let sitl = Sitl::start_with_logs(None, gps, logs.map(|p| p.to_path_buf()));
    let script = system_tests::workspace_root()
        .join("tests/interop")
        .join(name);
    let out = std::process::Command::new("python3")
        .arg(script)
        .arg(sitl.gcs_addr.port().to_string())
        .args(logs)
        .output()
        .expect("python3 runs");
    let text = String::from_utf8_lossy(&out.stdout);
    eprintln!("{text}{}", String::from_utf8_lossy(&out.stderr));
    assert!(out.status.success(), "pymavlink checks of {name}:\n{text}");
    Some(text.into_owned())
}

#[test]
fn pymavlink_lists_downloads_byte_for_byte_and_erases_the_flight_logs_armed_and_on_the_ground() {
    let dir = tempfile::tempdir().expect("tempdir");
    let logs = dir.path().join("logs");
    let Some(text) = pymavlink_script_with("pymavlink_logs.py", Some(&logs)) else {
        return;
    };
    // docs/LOGGING.md quotes these rates.
    for line in text.lines().filter(|l| l.starts_with("rate ")) {
        eprintln!("{line}");
    }
}

#[test]
fn signing_interoperates_with_pymavlink_and_refuses_unsigned_and_replayed_writes() {
    // pymavlink signs and verifies on its own (its signing is independent of this project's).
    pymavlink_script("pymavlink_signing.py");
}

#[test]
fn pymavlink_gets_protocol_version_chunked_texts_param_errors_and_metadata_over_ftp() {
    // What QGroundControl asks at connection, asked by pymavlink (its FTP client and its
    // decoding are independent of this project's): see the script's docstring for the checks.
    pymavlink_script("pymavlink_parity.py");
}

#[test]
fn the_shipped_pymavlink_mode_map_names_every_mode_by_its_word() {
    // docs/pymavlink/custom_mode_map.json is what a pymavlink or MAVProxy user copies to
    // ~/.pymavlink/: MAV_TYPE 1 (fixed wing), each heartbeat word to the mode's name.
    let path = system_tests::workspace_root().join("docs/pymavlink/custom_mode_map.json");
    let text = std::fs::read_to_string(&path).expect("the map is in the repository");
    let map: std::collections::BTreeMap<String, std::collections::BTreeMap<String, String>> =
        serde_json::from_str(&text).expect("the map is JSON of pymavlink's shape");
    let fixed_wing = &map["1"];
    assert_eq!(fixed_wing.len(), common::gcs::modes::FlightMode::ALL.len());
    for m in common::gcs::modes::FlightMode::ALL {
        assert_eq!(
            fixed_wing.get(&m.custom_mode().to_string()),
            Some(&m.name().to_uppercase()),
            "{m:?}"
        );
    }
}

#[test]
fn pymavlink_names_and_sets_every_mode_with_the_shipped_mode_map() {
    // pymavlink's own heartbeat decoding and set_mode (see the script's docstring).
    pymavlink_script("pymavlink_modes.py");
}

#[test]
fn home_set_by_arming_at_rest_is_reported_and_heights_are_in_its_datum() {
    // pymavlink reads HOME_POSITION and GLOBAL_POSITION_INT (see the script's docstring).
    pymavlink_script("pymavlink_home.py");
}

#[test]
fn pymavlink_sees_the_pack_s_voltage_current_and_charge_in_sys_status_and_battery_status() {
    // The simulator sends a 3S pack resting at 80 % (12.05 V, 0.35 A); the script checks
    // what pymavlink decodes against those figures: see its docstring.
    let p = pack();
    assert!((p.voltage_v - 12.0516).abs() < 1e-3, "{p:?}");
    pymavlink_script("pymavlink_battery.py");
}

#[test]
fn pymavlink_reads_the_flights_tlog_as_a_ground_stations_log_of_both_directions() {
    // A short scripted flight writes out/…/flight.tlog; pymavlink's own log reader checks it
    // (see the script's docstring).
    if !system_tests::pymavlink_available() {
        return;
    }
    let dir = tempfile::tempdir().expect("temporary directory");
    let cfg = sim_host::flight::FlightConfig {
        duration_s: 40.0,
        ..sim_host::flight::FlightConfig::default()
    };
    let opts = sim_host::commands::fly::FlyOptions {
        out: Some(dir.path().to_path_buf()),
        plots: false,
        ..sim_host::commands::fly::FlyOptions::default()
    };
    let aircraft = sim_host::aircraft::Aircraft::ultrastick25e().expect("built-in aircraft");
    sim_host::commands::fly::fly_report(&aircraft, &cfg, &opts).expect("flight");
    let script = system_tests::workspace_root().join("tests/interop/pymavlink_tlog.py");
    let out = std::process::Command::new("python3")
        .arg(script)
        .arg(dir.path().join("flight.tlog"))
        .output()
        .expect("python3 runs");
    let text = String::from_utf8_lossy(&out.stdout);
    eprintln!("{text}{}", String::from_utf8_lossy(&out.stderr));
    assert!(out.status.success(), "pymavlink reads the tlog:\n{text}");
}
