//! The vehicle's flight log read back message by message: the sensors as they were received,
//! the state in PX4's numbers.

extern crate std;

use std::vec::Vec;

use nalgebra::Vector3;

use super::*;
use crate::logger::{Logged, SystemInfo, TOPICS};
use crate::sensors::{BaroSample, ImuSample, RangeSample};
use crate::ulog::topic::Topic;
use crate::vehicle::FromGround;

/// The data messages of `id` in a ULog stream, their payload after the id and timestamp.
fn samples(bytes: &[u8], id: u16) -> Vec<(u64, Vec<u8>)> {
    let mut out = Vec::new();
    let mut at = crate::ulog::HEADER_LEN;
    while at + 3 <= bytes.len() {
        let size = u16::from_le_bytes([bytes[at], bytes[at + 1]]) as usize;
        let p = &bytes[at + 3..at + 3 + size];
        if bytes[at + 2] == b'D' && u16::from_le_bytes([p[0], p[1]]) == id {
            out.push((
                u64::from_le_bytes(p[2..10].try_into().unwrap()),
                p[10..].to_vec(),
            ));
        }
        at += 3 + size;
    }
    out
}

fn f32_at(p: &[u8], i: usize) -> f32 {
    f32::from_le_bytes(p[i..i + 4].try_into().unwrap())
}

/// A logger started at time 0.
fn started_logger() -> Logger {
    let mut log = Logger::new(SystemInfo {
        sys_name: "test",
        ver_sw: "0",
        ver_hw: "host",
    });
    log.start(0);
    log
}

/// The vehicle's topics due after frame `f`, written and drained into `bytes`.
fn log_frame(v: &Vehicle, log: &mut Logger, f: &SensorFrame, bytes: &mut Vec<u8>) {
    log.step(f.time_us, v.params());
    v.write_log(log, f);
    while log.pending_len() > 0 {
        let n = log.pending().len();
        bytes.extend_from_slice(log.pending());
        log.consume(n);
    }
}

#[test]
fn a_vehicle_on_the_ground_logs_its_sensors_as_received_and_its_state_in_px4s_numbers() {
    let mut v = Vehicle::new();
    let mut log = started_logger();
    let imu = ImuSample {
        accel: Vector3::new(0.1, -0.2, -9.8),
        gyro: Vector3::new(0.01, 0.02, -0.03),
    };
    let baro = BaroSample {
        pressure_pa: 100_000.0,
        temperature_c: 15.0,
    };
    let mut bytes = Vec::new();
    for k in 0..300u64 {
        let f = SensorFrame {
            time_us: k * 10_000,
            imu: Some(imu),
            baro: Some(baro),
            ..Default::default()
        };
        v.on_sensors(&f, &FromGround::default());
        log_frame(&v, &mut log, &f, &mut bytes);
    }
    assert_eq!(log.stats().dropped, 0);

    let imu_log = samples(&bytes, SensorCombined::ID);
    // 25 Hz from the end of the definitions to 2.99 s.
    assert!(imu_log.len() >= 60, "{}", imu_log.len());
    let (_, p) = &imu_log[0];
    assert_eq!(p.len() + 8, SensorCombined::FORMAT.size());
    assert_eq!(
        [f32_at(p, 0), f32_at(p, 4), f32_at(p, 8)],
        [0.01, 0.02, -0.03]
    );
    assert_eq!(
        [f32_at(p, 12), f32_at(p, 16), f32_at(p, 20)],
        [0.1, -0.2, -9.8]
    );

    let air = samples(&bytes, VehicleAirData::ID);
    let (_, p) = air.last().unwrap();
    assert_eq!(f32_at(p, 4), 100_000.0);
    // ISA pressure altitude of 1000 hPa: 110.9 m.
    assert!((f32_at(p, 0) - 110.9).abs() < 0.5, "{}", f32_at(p, 0));

    let status = samples(&bytes, VehicleStatus::ID);
    let (t, p) = status.last().unwrap();
    assert!(*t <= 2_990_000);
    // PX4: disarmed is arming state 1; Manual is navigation state 0.
    assert_eq!(p[0], 1);
    assert_eq!(p[1], 0);

    let att = samples(&bytes, VehicleAttitude::ID);
    let (_, p) = att.last().unwrap();
    let q: Vec<f32> = (0..4).map(|i| f32_at(p, 4 * i)).collect();
    let norm = q.iter().map(|x| x * x).sum::<f32>().sqrt();
    assert!((norm - 1.0).abs() < 1e-5, "{q:?}");

    // Every topic the vehicle has data for is written at least once.
    for (i, (f, _)) in TOPICS.iter().enumerate() {
        let without_data = [
            "differential_pressure",
            "vehicle_magnetometer",
            "vehicle_gps_position",
            "telemetry_status",
            "distance_sensor",
        ];
        if !without_data.contains(&f.name) {
            assert!(!samples(&bytes, i as u16).is_empty(), "{}", f.name);
        }
    }
}

/// A rangefinder read at 20 Hz is logged as PX4's `distance_sensor` at its 10 Hz, each sample
/// as received (distance, limits, MAVLink's quality 80 as PX4's 80, orientation 25); once the
/// readings stop, half a second later, so does the topic.
#[test]
fn rangefinder_readings_are_logged_as_distance_sensor_while_they_arrive() {
    let mut v = Vehicle::new();
    let mut log = started_logger();
    let mut bytes = Vec::new();
    for k in 0..400u64 {
        let f = SensorFrame {
            time_us: k * 10_000,
            imu: Some(ImuSample {
                accel: Vector3::new(0.0, 0.0, -9.8),
                gyro: Vector3::zeros(),
            }),
            ..Default::default()
        };
        v.on_sensors(&f, &FromGround::default());
        // Readings at 20 Hz for the first 2 s.
        if k % 5 == 0 && k < 200 {
            v.on_range(&RangeSample {
                distance_m: 0.25 + 0.001 * k as f32,
                min_m: 0.05,
                max_m: 40.0,
                quality: 80,
            });
        }
        log_frame(&v, &mut log, &f, &mut bytes);
    }
    let range = samples(&bytes, DistanceSensor::ID);
    assert_eq!(range[0].1.len() + 8, DistanceSensor::FORMAT.size());
    // 10 Hz over the 2 s of readings and the half second after them, less the definitions'.
    assert!((18..=26).contains(&range.len()), "{} samples", range.len());
    let last = range.last().map_or(0, |(t, _)| *t);
    assert!((1_990_000..=2_500_000).contains(&last), "last at {last} us");
    for (t, p) in &range {
        let k = (*t / 50_000 * 5).min(195);
        assert!(
            (f32_at(p, 0) - (0.25 + 0.001 * k as f32)).abs() < 1e-6,
            "at {t} us"
        );
        assert_eq!([f32_at(p, 4), f32_at(p, 8)], [0.05, 40.0]);
        assert_eq!([p[12], p[13]], [80, 25]);
    }
}
