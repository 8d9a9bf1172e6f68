//! The MCU image, on QEMU's emulated STM32F405, answers the simulator in lock-step over its
//! first UART: the same frames the host build answers.

use common::link::simlink::{encode_hil_sensor, SensorFrame};
use common::sensors::ImuSample;
use mavlink::dialects::common::MavMessage;
use nalgebra::Vector3;
use sim_host::link::lockstep::Lockstep;
use sim_host::link::transport::TcpServer;
use std::process::{Command, Stdio};
use std::time::Duration;
use system_tests::{build_mcu_firmware, spawn_qemu, tool_available, Kill};

#[test]
fn the_emulated_stm32f405_answers_every_sensor_frame() {
    if !tool_available("qemu-system-arm") {
        return;
    }
    let elf = build_mcu_firmware();
    // The second UART is the ground link: QEMU sends its bytes to `gcs` over UDP.
    // QEMU sends each UART byte as its own datagram, so the socket is read while the
    // simulation runs (a 1-byte datagram costs a full buffer slot).
    let gcs = std::net::UdpSocket::bind("127.0.0.1:0").expect("gcs socket");
    gcs.set_read_timeout(Some(Duration::from_millis(100)))
        .expect("timeout");
    let gcs_addr = gcs.local_addr().expect("gcs addr");
    let heartbeats = std::sync::Arc::new(std::sync::atomic::AtomicUsize::new(0));
    let done = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
    let reader = {
        let (heartbeats, done) = (heartbeats.clone(), done.clone());
        std::thread::spawn(move || {
            let mut parser = common::link::framing::FrameParser::new();
            let mut buf = [0u8; 4096];
            while !done.load(std::sync::atomic::Ordering::Relaxed) {
                if let Ok((n, _)) = gcs.recv_from(&mut buf) {
                    parser.push(&buf[..n], |f| {
                        if let MavMessage::HEARTBEAT(h) = f.message {
                            if h.mavtype == mavlink::dialects::common::MavType::MAV_TYPE_FIXED_WING
                            {
                                heartbeats.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                            }
                        }
                    });
                }
            }
        })
    };
    let qemu_port = std::net::UdpSocket::bind("127.0.0.1:0")
        .and_then(|s| s.local_addr())
        .expect("free port")
        .port();
    let mut qemu = None;
    let server = TcpServer::listen("127.0.0.1:0", Duration::from_secs(20), |addr| {
        let child = Command::new("qemu-system-arm")
            .args([
                "-cpu",
                "cortex-m4",
                "-machine",
                "netduinoplus2",
                "-nographic",
            ])
            .args(["-semihosting-config", "enable=on,target=native"])
            .args(["-monitor", "none"])
            .arg("-serial")
            .arg(format!("tcp:{addr},nodelay=on"))
            .arg("-serial")
            .arg(format!("udp:{gcs_addr}@:{qemu_port}"))
            .arg("-kernel")
            .arg(&elf)
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .expect("qemu starts");
        qemu = Some(Kill(child));
    })
    .expect("QEMU connects to the simulator");
    let mut link = Lockstep::new(server, Duration::from_secs(10));
    link.wait_for_autopilot(Duration::from_secs(20))
        .expect("the MCU announces itself once its UART is up");
    for k in 0..250u64 {
        let t = k * 20_000; // 50 Hz: 250 frames are 5 s of autopilot time
        let frame = SensorFrame {
            time_us: t,
            imu: Some(ImuSample {
                accel: Vector3::new(0.0, 0.0, -9.8),
                gyro: Vector3::zeros(),
            }),
            ..Default::default()
        };
        let msg = MavMessage::HIL_SENSOR(encode_hil_sensor(&frame, 0.0));
        let answer = link.exchange(t, &[msg]).expect("the MCU answers");
        assert_eq!(answer.time_us, t);
        assert!(!answer.armed, "a fresh autopilot is disarmed");
    }
    assert_eq!(link.stats().crc_errors, 0);

    // 5 s of autopilot time: heartbeats (1 Hz) of a fixed wing came down the ground UART.
    std::thread::sleep(Duration::from_millis(500));
    done.store(true, std::sync::atomic::Ordering::Relaxed);
    let _ = reader.join();
    let n = heartbeats.load(std::sync::atomic::Ordering::Relaxed);
    assert!(n >= 4, "{n} heartbeats on the ground UART");
    drop(qemu);
}

/// A ground station on the image's second UART, over TCP (QEMU connects to us).
struct Station {
    stream: std::net::TcpStream,
    parser: common::link::framing::FrameParser,
    sender: common::link::framing::Sender,
    inbox: Vec<MavMessage>,
}

impl Station {
    fn send(&mut self, msg: &MavMessage) {
        use std::io::Write;
        let frame = self.sender.encode(msg);
        self.stream
            .write_all(frame.raw_bytes())
            .expect("ground UART");
    }

    /// Reads until `pick` finds a message, for at most `secs`.
    fn wait<T>(&mut self, secs: f64, mut pick: impl FnMut(&MavMessage) -> Option<T>) -> Option<T> {
        use std::io::Read;
        let end = std::time::Instant::now() + Duration::from_secs_f64(secs);
        let mut buf = [0u8; 1024];
        loop {
            if let Some(i) = self.inbox.iter().position(|m| pick(m).is_some()) {
                let m = self.inbox.remove(i);
                return pick(&m);
            }
            if std::time::Instant::now() > end {
                return None;
            }
            if let Ok(n) = self.stream.read(&mut buf) {
                let inbox = &mut self.inbox;
                self.parser.push(&buf[..n], |f| inbox.push(f.message));
            }
        }
    }

    fn ack(
        &mut self,
        cmd: mavlink::dialects::common::MavCmd,
    ) -> Option<mavlink::dialects::common::MavResult> {
        self.wait(10.0, |m| match m {
            MavMessage::COMMAND_ACK(a) if a.command == cmd => Some(a.result),
            _ => None,
        })
    }

    /// A parameter read as QGroundControl does it: asked again when no answer comes within a
    /// few seconds (a request sent while the board is still booting can go unanswered).
    fn param(&mut self, name: &str) -> Option<f32> {
        use mavlink::dialects::common::PARAM_REQUEST_READ_DATA;
        (0..3).find_map(|_| {
            self.send(&MavMessage::PARAM_REQUEST_READ(PARAM_REQUEST_READ_DATA {
                param_index: -1,
                target_system: 1,
                target_component: 1,
                param_id: name.into(),
            }));
            self.wait(3.5, |m| match m {
                MavMessage::PARAM_VALUE(v) if v.param_id.to_str().ok() == Some(name) => {
                    Some(v.param_value)
                }
                _ => None,
            })
        })
    }
}

/// QEMU with USART1 and USART2 on TCP listeners of this test and the flash sectors in
/// `storage`; returns the process and the ground station.
fn boot_with_storage(
    elf: &std::path::Path,
    storage: &std::path::Path,
) -> (
    Kill,
    Station,
    std::thread::JoinHandle<()>,
    std::sync::Arc<std::sync::atomic::AtomicUsize>,
) {
    // The command line sim-host runs the image with, the storage file as its argument.
    let cfg = sim_host::link::qemu::QemuConfig {
        elf: elf.to_path_buf(),
        storage: Some(storage.to_path_buf()),
        ..Default::default()
    };
    let (qemu, sim, gcs) = spawn_qemu(|s, g| cfg.command(s, g));
    let (sim, _) = sim.accept().expect("QEMU connects USART1");
    // Nobody simulates: the simulator link only counts boots (a heartbeat at each).
    let boots = std::sync::Arc::new(std::sync::atomic::AtomicUsize::new(0));
    let counted = boots.clone();
    let drain = std::thread::spawn(move || {
        use std::io::Read;
        let mut sim = sim;
        let mut buf = [0u8; 256];
        let mut parser = common::link::framing::FrameParser::new();
        while let Ok(n) = sim.read(&mut buf) {
            if n == 0 {
                break;
            }
            parser.push(&buf[..n], |f| {
                if matches!(f.message, MavMessage::HEARTBEAT(_)) {
                    counted.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
                }
            });
        }
    });
    let (stream, _) = gcs.accept().expect("QEMU connects USART2");
    stream
        .set_read_timeout(Some(Duration::from_millis(50)))
        .unwrap();
    let station = Station {
        stream,
        parser: common::link::framing::FrameParser::new(),
        sender: common::link::framing::Sender::new(255, 190),
        inbox: Vec::new(),
    };
    (qemu, station, drain, boots)
}

fn upload(st: &mut Station, n: u16) -> Option<mavlink::dialects::common::MavMissionResult> {
    use mavlink::dialects::common::*;
    st.send(&MavMessage::MISSION_COUNT(MISSION_COUNT_DATA {
        count: n,
        target_system: 1,
        target_component: 1,
        ..Default::default()
    }));
    loop {
        let next = st.wait(10.0, |m| match m {
            MavMessage::MISSION_REQUEST_INT(r) => Some(Ok(r.seq)),
            MavMessage::MISSION_ACK(a) => Some(Err(a.mavtype)),
            _ => None,
        })?;
        let seq = match next {
            Ok(seq) => seq,
            Err(result) => return Some(result),
        };
        st.send(&MavMessage::MISSION_ITEM_INT(MISSION_ITEM_INT_DATA {
            param1: if seq == 0 { 15.0 } else { 0.0 },
            x: 449_727_000 + i32::from(seq) * 20_000,
            y: -932_350_000,
            z: 60.0,
            seq,
            command: if seq == 0 {
                MavCmd::MAV_CMD_NAV_TAKEOFF
            } else {
                MavCmd::MAV_CMD_NAV_WAYPOINT
            },
            target_system: 1,
            target_component: 1,
            frame: MavFrame::MAV_FRAME_GLOBAL_RELATIVE_ALT,
            autocontinue: 1,
            ..Default::default()
        }));
    }
}

fn mission_count(st: &mut Station) -> Option<u16> {
    use mavlink::dialects::common::*;
    st.send(&MavMessage::MISSION_REQUEST_LIST(
        MISSION_REQUEST_LIST_DATA {
            target_system: 1,
            target_component: 1,
            ..Default::default()
        },
    ));
    st.wait(10.0, |m| match m {
        MavMessage::MISSION_COUNT(c) => Some(c.count),
        _ => None,
    })
}

/// PREFLIGHT_STORAGE is answered IN_PROGRESS, then ACCEPTED once the record is in the host
/// file standing for the flash sectors; PREFLIGHT_REBOOT_SHUTDOWN resets the emulated board
/// (SCB system reset), which boots again with the parameter and the mission it saved.
#[test]
fn parameters_and_a_mission_survive_a_reset_of_the_emulated_board() {
    use mavlink::dialects::common::*;
    if !tool_available("qemu-system-arm") {
        return;
    }
    let elf = build_mcu_firmware();
    let dir = tempfile::tempdir().expect("tempdir");
    let storage = dir.path().join("flash.bin");
    let (qemu, mut st, drain, boots) = boot_with_storage(&elf, &storage);
    let default = common::params::ParamStore::new(common::vehicle::params::REGISTRY).get("RLL_KP");
    assert_ne!(default, Some(-0.5));
    assert_eq!(st.param("RLL_KP"), default, "the default at first boot");
    let booted = || boots.load(std::sync::atomic::Ordering::SeqCst);
    assert_eq!(booted(), 1);
    assert_eq!(mission_count(&mut st), Some(0));
    st.send(&MavMessage::PARAM_SET(PARAM_SET_DATA {
        param_value: -0.5,
        target_system: 1,
        target_component: 1,
        param_id: "RLL_KP".into(),
        param_type: MavParamType::MAV_PARAM_TYPE_REAL32,
    }));
    assert_eq!(
        upload(&mut st, 3),
        Some(MavMissionResult::MAV_MISSION_ACCEPTED)
    );
    let store = common::gcs::client::command_long(
        MavCmd::MAV_CMD_PREFLIGHT_STORAGE,
        [1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    );
    st.send(&store);
    let cmd = MavCmd::MAV_CMD_PREFLIGHT_STORAGE;
    assert_eq!(st.ack(cmd), Some(MavResult::MAV_RESULT_IN_PROGRESS));
    assert_eq!(st.ack(cmd), Some(MavResult::MAV_RESULT_ACCEPTED));
    // The board record's two sectors of 16 KiB, then the flight logs' six of 128 KiB
    // (firmware/src/mcu/flash.rs).
    assert_eq!(
        std::fs::metadata(&storage).unwrap().len(),
        32 * 1024 + 768 * 1024
    );

    st.send(&common::gcs::client::command_long(
        MavCmd::MAV_CMD_PREFLIGHT_REBOOT_SHUTDOWN,
        [1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    ));
    let cmd = MavCmd::MAV_CMD_PREFLIGHT_REBOOT_SHUTDOWN;
    assert_eq!(st.ack(cmd), Some(MavResult::MAV_RESULT_ACCEPTED));
    // The board resets: RAM is gone, the file stays.
    std::thread::sleep(Duration::from_millis(500));
    st.inbox.clear();
    assert_eq!(
        st.param("RLL_KP"),
        Some(-0.5),
        "the saved value after reset"
    );
    assert_eq!(booted(), 2, "booted again");
    assert_eq!(
        mission_count(&mut st),
        Some(3),
        "the saved mission after reset"
    );
    drop(qemu);
    let _ = drain.join();

    // And after QEMU itself ends: a new process reads the same file.
    let (qemu, mut st, drain, _) = boot_with_storage(&elf, &storage);
    assert_eq!(st.param("RLL_KP"), Some(-0.5));
    assert_eq!(mission_count(&mut st), Some(3));
    drop(qemu);
    let _ = drain.join();
}
