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
            .args(["-serial", "null"])
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
    for k in 0..100u64 {
        let t = k * 20_000;
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
    drop(qemu);
}
