//! The topics' formats against what their encoders write, and the logger's stream walked
//! message by message as a ULog reader walks it.

extern crate std;

use std::vec::Vec;

use super::*;
use crate::ulog::topic::Topic;
use crate::ulog::{self, Cursor};
use crate::vehicle::params::REGISTRY;

fn encoded_len<T: Topic + Default>() -> usize {
    let mut b = [0u8; 512];
    let mut c = Cursor::new(&mut b);
    T::default().encode(&mut c);
    c.finish().unwrap()
}

macro_rules! check_all {
    ($($t:ty),*) => {{
        let mut names = Vec::new();
        $(
            // The timestamp (8 bytes) comes from the data message, the rest from the encoder.
            assert_eq!(encoded_len::<$t>() + 8, <$t>::FORMAT.size(), "{}", <$t>::FORMAT.name);
            assert_eq!(TOPICS[<$t as Logged>::ID as usize].0.name, <$t>::FORMAT.name);
            names.push(<$t>::FORMAT.name);
        )*
        names
    }};
}

#[test]
fn every_topic_writes_exactly_the_bytes_its_format_declares_under_its_own_id() {
    let mut names = check_all!(
        VehicleAttitude,
        VehicleLocalPosition,
        VehicleGlobalPosition,
        SensorCombined,
        VehicleMagnetometer,
        VehicleAirData,
        DifferentialPressure,
        AirspeedValidated,
        VehicleGpsPosition,
        Wind,
        EstimatorStates,
        VehicleAttitudeSetpoint,
        ControlLoops,
        ActuatorOutputs,
        VehicleStatus,
        VehicleLandDetected,
        BatteryStatus,
        MissionResult,
        TelemetryStatus,
        DistanceSensor
    );
    assert_eq!(names.len(), TOPICS.len());
    names.sort_unstable();
    names.dedup();
    assert_eq!(names.len(), TOPICS.len(), "topic names are unique");
}

#[test]
fn a_topics_format_text_is_px4s_for_the_same_fields() {
    let mut b = [0u8; 256];
    let n = ulog::format(&mut b, &VehicleAttitude::FORMAT).unwrap();
    assert_eq!(&b[3..n], b"vehicle_attitude:uint64_t timestamp;float[4] q;");
    let n = ulog::format(&mut b, &Wind::FORMAT).unwrap();
    assert_eq!(
        &b[3..n],
        b"wind:uint64_t timestamp;float windspeed_north;float windspeed_east;"
    );
}

#[test]
fn fields_are_written_in_order_little_endian_without_padding() {
    let s = VehicleGpsPosition {
        lat: -1,
        alt: 0x0102_0304,
        fix_type: 3,
        satellites_used: 9,
        ..Default::default()
    };
    let mut b = [0u8; 64];
    let mut c = Cursor::new(&mut b);
    s.encode(&mut c);
    let n = c.finish().unwrap();
    assert_eq!(n, 4 * 3 + 4 * 5 + 2);
    assert_eq!(b[..4], [0xff; 4]);
    assert_eq!(b[8..12], [4, 3, 2, 1]);
    assert_eq!(b[n - 2..n], [3, 9]);
}

const INFO: SystemInfo = SystemInfo {
    sys_name: "test",
    ver_sw: "0.1.0",
    ver_hw: "host",
};

/// One message of the stream: its type and payload.
fn messages(bytes: &[u8]) -> Vec<(u8, Vec<u8>)> {
    assert_eq!(&bytes[..7], &ulog::MAGIC);
    let mut out = Vec::new();
    let mut at = ulog::HEADER_LEN;
    while at + 3 <= bytes.len() {
        let size = u16::from_le_bytes([bytes[at], bytes[at + 1]]) as usize;
        out.push((bytes[at + 2], bytes[at + 3..at + 3 + size].to_vec()));
        at += 3 + size;
    }
    assert_eq!(at, bytes.len(), "the stream ends on a message boundary");
    out
}

/// Flies the logger for `periods` control periods of 20 ms from t = 0, writing every topic
/// when due, and draining `drain` bytes a period (all with `None`).
fn fly(periods: u64, drain: Option<usize>) -> (Vec<u8>, LogStats) {
    let params = crate::params::ParamStore::new(REGISTRY);
    let mut log = Logger::new(INFO);
    log.start(0);
    let mut out = Vec::new();
    for k in 0..periods {
        let t = k * 20_000;
        log.step(t, &params);
        if log.due::<VehicleAttitude>(t) {
            log.write(
                t,
                &VehicleAttitude {
                    q: [1.0, 0.0, 0.0, 0.0],
                },
            );
        }
        if log.due::<BatteryStatus>(t) {
            log.write(
                t,
                &BatteryStatus {
                    voltage_v: 12.0,
                    ..Default::default()
                },
            );
        }
        if log.due::<EstimatorStates>(t) {
            log.write(t, &EstimatorStates::default());
        }
        if k == 300 {
            log.text(t, Level::Warning, "geofence breached");
        }
        let mut left = drain.unwrap_or(usize::MAX);
        while left > 0 && log.pending_len() > 0 {
            let n = log.pending().len().min(left);
            out.extend_from_slice(&log.pending()[..n]);
            log.consume(n);
            left -= n;
        }
    }
    // What is still in the ring reaches the storage after the flight.
    while log.pending_len() > 0 {
        let n = log.pending().len();
        out.extend_from_slice(log.pending());
        log.consume(n);
    }
    (out, log.stats())
}

#[test]
fn a_log_opens_with_its_definitions_in_the_order_ulog_requires() {
    let (bytes, stats) = fly(100, None);
    assert_eq!(stats.dropped, 0);
    let m = messages(&bytes);
    let params = crate::params::ParamStore::new(REGISTRY).len();
    let kinds: Vec<u8> = m.iter().map(|(k, _)| *k).collect();
    assert_eq!(kinds[0], b'B');
    assert_eq!(&kinds[1..4], b"III");
    assert!(kinds[4..4 + params].iter().all(|&k| k == b'P'));
    let f = 4 + params;
    assert!(kinds[f..f + TOPICS.len()].iter().all(|&k| k == b'F'));
    let a = f + TOPICS.len();
    assert!(kinds[a..a + TOPICS.len()].iter().all(|&k| k == b'A'));
    assert!(kinds[a + TOPICS.len()..]
        .iter()
        .all(|&k| matches!(k, b'D' | b'S')));
    // Each subscription names its format, with its place as the message id.
    for (i, (_, p)) in m[a..a + TOPICS.len()].iter().enumerate() {
        assert_eq!(u16::from_le_bytes([p[1], p[2]]) as usize, i);
        assert_eq!(&p[3..], TOPICS[i].0.name.as_bytes());
    }
}

#[test]
fn each_topic_is_written_at_its_rate() {
    let (bytes, _) = fly(500, None); // 10 s
    let m = messages(&bytes);
    let count = |id: u16| {
        m.iter()
            .filter(|(k, p)| *k == b'D' && u16::from_le_bytes([p[0], p[1]]) == id)
            .count()
    };
    // The definitions (header, information, every parameter, every topic's format and
    // subscription) take the first dozen periods, a period more for every few parameters or
    // topics the registry gains; every rate is met from then on.
    let att = count(VehicleAttitude::ID);
    assert!((238..=250).contains(&att), "{att}");
    let bat = count(BatteryStatus::ID);
    assert!((9..=10).contains(&bat), "{bat}");
    let est = count(EstimatorStates::ID);
    assert!((19..=20).contains(&est), "{est}");
    let syncs = m.iter().filter(|(k, _)| *k == b'S').count();
    assert!((9..=10).contains(&syncs), "{syncs}");
    let text = m.iter().find(|(k, _)| *k == b'L').unwrap();
    assert_eq!(text.1[0], b'4');
    assert_eq!(
        u64::from_le_bytes(text.1[1..9].try_into().unwrap()),
        6_000_000
    );
    assert_eq!(&text.1[9..], b"geofence breached");
}

#[test]
fn a_storage_too_slow_costs_samples_and_the_log_says_for_how_long() {
    // 20 bytes a period is less than the three topics flown here need (about 28: 1.4 KB/s).
    let (bytes, stats) = fly(500, Some(20));
    assert!(stats.dropped > 0);
    let m = messages(&bytes);
    let dropouts: Vec<u16> = m
        .iter()
        .filter(|(k, _)| *k == b'O')
        .map(|(_, p)| u16::from_le_bytes([p[0], p[1]]))
        .collect();
    assert!(!dropouts.is_empty());
    // A dropout that a smaller sample of the same period ends (there was room for it) lasted
    // 0 ms; together they span the periods the storage fell behind.
    assert!(dropouts.iter().all(|&ms| ms < 10_000), "{dropouts:?}");
    assert!(
        dropouts.iter().map(|&ms| u32::from(ms)).sum::<u32>() > 0,
        "{dropouts:?}"
    );
}

#[test]
fn nothing_is_taken_before_the_start_or_after_the_stop() {
    let params = crate::params::ParamStore::new(REGISTRY);
    let mut log = Logger::new(INFO);
    log.step(0, &params);
    assert!(!log.due::<VehicleAttitude>(0));
    log.write(0, &VehicleAttitude::default());
    assert_eq!(log.pending_len(), 0);
    log.start(0);
    log.step(0, &params);
    assert!(log.pending_len() > 0);
    log.stop();
    let n = log.pending_len();
    log.step(20_000, &params);
    log.text(20_000, Level::Info, "x");
    assert_eq!(log.pending_len(), n);
    assert!(!log.recording());
}

/// `SDLOG_PROFILE`'s identification bits put the identification's topics at every 100 Hz
/// frame and leave the others at their own rates; a board's cap still bounds them all.
#[test]
fn the_identification_profile_logs_its_topics_every_frame_under_the_boards_cap() {
    let mut log = Logger::new(INFO);
    assert_eq!(log.rate_hz(VehicleAttitude::ID), Some(25));
    log.set_high_rate(true);
    for id in [VehicleAttitude::ID, SensorCombined::ID, ActuatorOutputs::ID] {
        assert_eq!(log.rate_hz(id), Some(100));
    }
    assert_eq!(log.rate_hz(VehicleLocalPosition::ID), Some(100));
    assert_eq!(log.rate_hz(AirspeedValidated::ID), Some(100));
    assert_eq!(log.rate_hz(BatteryStatus::ID), Some(1));
    log.set_rate_cap(4);
    assert_eq!(log.rate_hz(VehicleAttitude::ID), Some(4));
    assert_eq!(log.rate_hz(BatteryStatus::ID), Some(1));
}
