//! The topics' formats against what their encoders write.

extern crate std;

use super::topics::*;
use crate::ulog::topic::Topic;
use crate::ulog::{self, Cursor};

fn encoded_len<T: Topic + Default>() -> usize {
    let mut b = [0u8; 512];
    let mut c = Cursor::new(&mut b);
    T::default().encode(&mut c);
    c.finish().unwrap()
}

macro_rules! check_all {
    ($($t:ty),*) => {{
        let mut names = std::vec::Vec::new();
        $(
            // The timestamp (8 bytes) comes from the data message, the rest from the encoder.
            assert_eq!(encoded_len::<$t>() + 8, <$t>::FORMAT.size(), "{}", <$t>::FORMAT.name);
            let mut b = [0u8; 1024];
            assert!(ulog::format(&mut b, &<$t>::FORMAT).is_ok());
            names.push(<$t>::FORMAT.name);
        )*
        names
    }};
}

#[test]
fn every_topic_writes_exactly_the_bytes_its_format_declares() {
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
        TelemetryStatus
    );
    let n = names.len();
    names.sort_unstable();
    names.dedup();
    assert_eq!(names.len(), n, "topic names are unique");
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
