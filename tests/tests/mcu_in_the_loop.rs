//! The MCU image, on QEMU's emulated STM32F405, answers the simulator in lock-step over its
//! first UART: the same frames the host build answers.

use common::link::simlink::{encode_hil_sensor, SensorFrame};
use common::sensors::ImuSample;
use mavlink::dialects::common::MavMessage;
use nalgebra::Vector3;
use sim_host::link::lockstep::Lockstep;
use sim_host::link::transport::TcpServer;
use std::process::{Child, Command, Stdio};
use std::time::Duration;
use system_tests::{build_mcu_firmware, tool_available};

struct Kill(Child);
impl Drop for Kill {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

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
