//! PX4's simulator interface: `HIL_SENSOR`, `HIL_GPS`, `BATTERY_STATUS` and a downward
//! rangefinder's `DISTANCE_SENSOR` from the simulator,
//! `HIL_ACTUATOR_CONTROLS` back.
//!
//! Both sides of the link use these functions, so units and flag bits are defined once:
//! `HIL_SENSOR` carries specific force in m/s^2 (level flight z = -g), rates in rad/s, field in
//! gauss, pressures in hPa and temperature in deg C, with `fields_updated` bits saying which
//! groups are new (a barometer update sets bits 9, 11 and 12 together). `HIL_GPS` carries
//! 1e-7 deg, mm and cm/s; `BATTERY_STATUS` the pack voltage in mV (`voltages[0]`, the other
//! cells UINT16_MAX: not measured one by one) and the current in cA. The autopilot answers every sensor frame with
//! `HIL_ACTUATOR_CONTROLS`: roll, pitch, yaw in -1..1 and throttle 0..1, `mode` bit 128 when
//! armed and `flags` bit 0 (lock-step).
//!
//! The decoders are the autopilot's first line of defence: a group whose values are not
//! finite or not physically plausible is dropped and counted, never passed on.

use crate::actuators::Surfaces;
use crate::math::geodetic::GeoPoint;
use crate::sensors::{
    limits, BaroSample, BatterySample, GpsFix, ImuSample, MagSample, ManualInput, PitotSample,
    RangeSample,
};

/// The frame `HIL_SENSOR` decodes into.
pub use crate::sensors::SensorFrame;
use mavlink::dialects::common::{
    HilActuatorControlsFlags, HilSensorUpdatedFlags, MavBatteryFunction, MavBatteryType,
    MavDistanceSensor, MavModeFlag, MavSensorOrientation, BATTERY_STATUS_DATA,
    DISTANCE_SENSOR_DATA, HIL_ACTUATOR_CONTROLS_DATA, HIL_GPS_DATA, HIL_SENSOR_DATA,
    RC_CHANNELS_DATA,
};
use nalgebra::Vector3;

const PA_PER_HPA: f32 = 100.0;

/// `fields_updated` bits of one complete IMU update (accelerometer and gyro, all axes).
pub const BITS_IMU: u32 = 0x3F;
/// `fields_updated` bits of one magnetometer update.
pub const BITS_MAG: u32 = 0x1C0;
/// `fields_updated` bits of one barometer update: absolute pressure, pressure altitude,
/// temperature.
pub const BITS_BARO: u32 = (1 << 9) | (1 << 11) | (1 << 12);
/// `fields_updated` bit of a differential-pressure update.
pub const BITS_DIFF_PRESSURE: u32 = 1 << 10;

/// Which groups of one frame were dropped as implausible or incomplete.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Rejected {
    /// IMU values missing an axis, non-finite or beyond range.
    pub imu: bool,
    /// Magnetometer.
    pub mag: bool,
    /// Barometer.
    pub baro: bool,
    /// Differential pressure.
    pub pitot: bool,
}

impl Rejected {
    /// True when nothing was dropped.
    pub fn none(&self) -> bool {
        !(self.imu || self.mag || self.baro || self.pitot)
    }
}

/// Encodes a sensor frame (simulator side).
pub fn encode_hil_sensor(f: &SensorFrame, pressure_alt_m: f32) -> HIL_SENSOR_DATA {
    let mut d = HIL_SENSOR_DATA {
        time_usec: f.time_us,
        ..Default::default()
    };
    let mut bits = 0u32;
    if let Some(imu) = f.imu {
        (d.xacc, d.yacc, d.zacc) = (imu.accel.x, imu.accel.y, imu.accel.z);
        (d.xgyro, d.ygyro, d.zgyro) = (imu.gyro.x, imu.gyro.y, imu.gyro.z);
        bits |= BITS_IMU;
    }
    if let Some(mag) = f.mag {
        (d.xmag, d.ymag, d.zmag) = (mag.field.x, mag.field.y, mag.field.z);
        bits |= BITS_MAG;
    }
    if let Some(b) = f.baro {
        d.abs_pressure = b.pressure_pa / PA_PER_HPA;
        d.temperature = b.temperature_c;
        d.pressure_alt = pressure_alt_m;
        bits |= BITS_BARO;
    }
    if let Some(p) = f.pitot {
        d.diff_pressure = p.diff_pressure_pa / PA_PER_HPA;
        bits |= BITS_DIFF_PRESSURE;
    }
    if f.reset {
        bits |= 1 << 31;
    }
    d.fields_updated = HilSensorUpdatedFlags::from_bits_truncate(bits);
    d
}

/// Decodes a `HIL_SENSOR` frame (autopilot side), dropping implausible groups.
pub fn decode_hil_sensor(d: &HIL_SENSOR_DATA) -> (SensorFrame, Rejected) {
    let bits = d.fields_updated.bits();
    let mut f = SensorFrame {
        time_us: d.time_usec,
        reset: bits & (1 << 31) != 0,
        ..Default::default()
    };
    let mut r = Rejected::default();
    let group = |mask: u32| bits & mask;
    match group(BITS_IMU) {
        0 => {}
        BITS_IMU => {
            let a = [d.xacc, d.yacc, d.zacc];
            let g = [d.xgyro, d.ygyro, d.zgyro];
            let imu = ImuSample {
                accel: Vector3::from(a),
                gyro: Vector3::from(g),
            };
            if imu.plausible() {
                f.imu = Some(imu);
            } else {
                r.imu = true;
            }
        }
        _ => r.imu = true,
    }
    match group(BITS_MAG) {
        0 => {}
        BITS_MAG => {
            let m = [d.xmag, d.ymag, d.zmag];
            let mag = MagSample {
                field: Vector3::from(m),
            };
            if mag.plausible() {
                f.mag = Some(mag);
            } else {
                r.mag = true;
            }
        }
        _ => r.mag = true,
    }
    // Pressure is what matters; a frame may carry it without altitude or temperature.
    if group(1 << 9) != 0 {
        let baro = BaroSample {
            pressure_pa: d.abs_pressure * PA_PER_HPA,
            temperature_c: if group(1 << 12) != 0 {
                d.temperature
            } else {
                15.0
            },
        };
        if baro.plausible() {
            f.baro = Some(baro);
        } else {
            r.baro = true;
        }
    }
    if group(BITS_DIFF_PRESSURE) != 0 {
        let pitot = PitotSample {
            diff_pressure_pa: d.diff_pressure * PA_PER_HPA,
        };
        if pitot.plausible() {
            f.pitot = Some(pitot);
        } else {
            r.pitot = true;
        }
    }
    (f, r)
}

fn clamp_i16(x: f32) -> i16 {
    if x.is_finite() {
        x.clamp(i16::MIN as f32, i16::MAX as f32) as i16
    } else {
        0
    }
}

/// Encodes a GPS fix (simulator side). `time_us` is the time the fix is valid for.
pub fn encode_hil_gps(time_us: u64, fix: &GpsFix) -> HIL_GPS_DATA {
    let (course, speed) = crate::math::course_and_speed(&fix.vel_ned);
    let cog_cdeg = crate::math::wrap_two_pi(course).to_degrees() * 100.0;
    HIL_GPS_DATA {
        time_usec: time_us,
        fix_type: fix.fix_type,
        lat: fix.position.lat_e7,
        lon: fix.position.lon_e7,
        alt: (fix.alt_amsl_m * 1000.0) as i32,
        eph: (fix.hdop * 100.0).clamp(0.0, 65534.0) as u16,
        epv: (fix.hdop * 150.0).clamp(0.0, 65534.0) as u16,
        vel: (speed * 100.0).clamp(0.0, 65534.0) as u16,
        vn: clamp_i16(fix.vel_ned.x * 100.0),
        ve: clamp_i16(fix.vel_ned.y * 100.0),
        vd: clamp_i16(fix.vel_ned.z * 100.0),
        cog: if speed > 0.5 {
            (cog_cdeg as u16).min(35999)
        } else {
            u16::MAX
        },
        satellites_visible: fix.satellites,
        id: 0,
        yaw: 0,
    }
}

/// Pulse widths a radio channel may take, us: outside them the receiver sends no signal or its
/// failsafe values.
pub const RC_PWM_RANGE_US: (u16, u16) = (800, 2200);

fn pwm_to_unit(pwm: u16, centre: f32) -> f32 {
    ((f32::from(pwm) - centre) / 500.0).clamp(-1.0, 1.0)
}

/// The sticks from `RC_CHANNELS` (the simulator's radio, or a receiver), PX4's default channel
/// order: 1 roll (2000 us full right), 2 pitch (2000 us full back, nose up), 3 throttle
/// (1000 us idle, 2000 us full), 4 yaw (2000 us full right); 1500 us centre. `None` with fewer
/// than four channels, a pulse outside [`RC_PWM_RANGE_US`] (0 and UINT16_MAX mark a channel not
/// sent), or an RSSI of 0 (no signal; 255 means unknown and is accepted).
pub fn decode_rc_channels(d: &RC_CHANNELS_DATA, time_us: u64) -> Option<ManualInput> {
    let ch = [d.chan1_raw, d.chan2_raw, d.chan3_raw, d.chan4_raw];
    let ok = d.chancount >= 4
        && d.rssi != 0
        && ch
            .iter()
            .all(|c| (RC_PWM_RANGE_US.0..=RC_PWM_RANGE_US.1).contains(c));
    ok.then(|| ManualInput {
        roll: pwm_to_unit(ch[0], 1500.0),
        pitch: pwm_to_unit(ch[1], 1500.0),
        throttle: ((f32::from(ch[2]) - 1000.0) / 1000.0).clamp(0.0, 1.0),
        yaw: pwm_to_unit(ch[3], 1500.0),
        time_us,
    })
}

/// `RC_CHANNELS` for stick positions (simulator side): roll, pitch, yaw in -1..1 (right, back,
/// right positive), throttle 0..1; the inverse of [`decode_rc_channels`].
pub fn encode_rc_channels(
    time_us: u64,
    roll: f32,
    pitch: f32,
    throttle: f32,
    yaw: f32,
) -> RC_CHANNELS_DATA {
    let pwm = |v: f32, centre: f32| libm::roundf(centre + 500.0 * v).clamp(1000.0, 2000.0) as u16;
    RC_CHANNELS_DATA {
        time_boot_ms: (time_us / 1000) as u32,
        chan1_raw: pwm(roll.clamp(-1.0, 1.0), 1500.0),
        chan2_raw: pwm(pitch.clamp(-1.0, 1.0), 1500.0),
        chan3_raw: pwm(2.0 * throttle.clamp(0.0, 1.0), 1000.0),
        chan4_raw: pwm(yaw.clamp(-1.0, 1.0), 1500.0),
        chancount: 4,
        rssi: 255,
        ..RC_CHANNELS_DATA::DEFAULT
    }
}

/// Decodes a `HIL_GPS` frame (autopilot side); `None` for an implausible fix.
pub fn decode_hil_gps(d: &HIL_GPS_DATA) -> Option<GpsFix> {
    let position = GeoPoint {
        lat_e7: d.lat,
        lon_e7: d.lon,
    };
    let alt_amsl_m = d.alt as f32 / 1000.0;
    if d.fix_type >= 2 && (!position.is_valid() || !limits::in_range(alt_amsl_m, limits::GPS_ALT_M))
    {
        return None;
    }
    Some(GpsFix {
        position,
        alt_amsl_m,
        vel_ned: Vector3::new(
            f32::from(d.vn) / 100.0,
            f32::from(d.ve) / 100.0,
            f32::from(d.vd) / 100.0,
        ),
        fix_type: d.fix_type,
        satellites: d.satellites_visible,
        hdop: if d.eph == u16::MAX {
            99.99
        } else {
            f32::from(d.eph) / 100.0
        },
    })
}

/// `BATTERY_STATUS` of a power monitor (simulator side): the pack voltage in `voltages[0]` in
/// mV with the other cells UINT16_MAX, as MAVLink asks when cells are not measured one by one;
/// the current in cA; the charge left -1 (the autopilot estimates it itself).
pub fn encode_battery_status(s: &BatterySample) -> BATTERY_STATUS_DATA {
    let mut voltages = [u16::MAX; 10];
    // UINT16_MAX means "not measured": a pack voltage above 65.534 V would continue in the
    // second cell, which the 60 V limit never needs.
    voltages[0] = libm::roundf(s.voltage_v * 1000.0).clamp(0.0, 65_534.0) as u16;
    BATTERY_STATUS_DATA {
        voltages,
        current_battery: libm::roundf(s.current_a * 100.0).clamp(-32_767.0, 32_767.0) as i16,
        current_consumed: -1,
        energy_consumed: -1,
        temperature: i16::MAX,
        battery_remaining: -1,
        battery_function: MavBatteryFunction::MAV_BATTERY_FUNCTION_ALL,
        mavtype: MavBatteryType::MAV_BATTERY_TYPE_LIPO,
        ..BATTERY_STATUS_DATA::DEFAULT
    }
}

/// Decodes a power monitor's `BATTERY_STATUS` (autopilot side): the pack voltage is the sum
/// of the cells reported (`voltages`, then `voltages_ext`; UINT16_MAX and, in the extension,
/// 0 mark a cell not reported), the current `current_battery`. `None` without a voltage,
/// without a current (-1: not measured; the monitor counts charge) or outside the
/// plausibility limits.
pub fn decode_battery_status(d: &BATTERY_STATUS_DATA) -> Option<BatterySample> {
    let cells = d.voltages.iter().filter(|&&mv| mv != u16::MAX);
    let ext = d
        .voltages_ext
        .iter()
        .filter(|&&mv| mv != 0 && mv != u16::MAX);
    let (mut mv, mut reported) = (0u32, false);
    for &c in cells.chain(ext) {
        mv = mv.saturating_add(u32::from(c));
        reported = true;
    }
    if !reported || d.current_battery == -1 {
        return None;
    }
    let sample = BatterySample {
        voltage_v: mv as f32 / 1000.0,
        current_a: f32::from(d.current_battery) / 100.0,
    };
    sample.plausible().then_some(sample)
}

/// `DISTANCE_SENSOR` of a downward rangefinder (simulator side), as PX4's simulator API sends
/// it: orientation `MAV_SENSOR_ROTATION_PITCH_270`, distances in cm, the variance in cm^2
/// (255: unknown), the field of view in rad.
pub fn encode_distance_sensor(
    time_us: u64,
    s: &RangeSample,
    sigma_m: f32,
    fov_rad: f32,
) -> DISTANCE_SENSOR_DATA {
    let cm = |m: f32| libm::roundf(m * 100.0).clamp(0.0, 65_535.0) as u16;
    let var_cm2 = sigma_m * sigma_m * 1e4;
    DISTANCE_SENSOR_DATA {
        time_boot_ms: (time_us / 1000) as u32,
        min_distance: cm(s.min_m),
        max_distance: cm(s.max_m),
        current_distance: cm(s.distance_m),
        mavtype: MavDistanceSensor::MAV_DISTANCE_SENSOR_LASER,
        id: 0,
        orientation: MavSensorOrientation::MAV_SENSOR_ROTATION_PITCH_270,
        covariance: if var_cm2.is_finite() {
            libm::roundf(var_cm2).clamp(0.0, 254.0) as u8
        } else {
            255
        },
        horizontal_fov: fov_rad,
        vertical_fov: fov_rad,
        quaternion: [0.0; 4],
        signal_quality: s.quality,
    }
}

/// Decodes `DISTANCE_SENSOR` (autopilot side): `None` for a sensor not looking down, or whose
/// range limits make no sense (no longer range than its shortest, or beyond 650 m). An
/// out-of-range distance is passed on as it came: it says the ground is not within reach.
pub fn decode_distance_sensor(d: &DISTANCE_SENSOR_DATA) -> Option<RangeSample> {
    let down = d.orientation == MavSensorOrientation::MAV_SENSOR_ROTATION_PITCH_270;
    (down && d.min_distance < d.max_distance && d.max_distance < u16::MAX).then(|| RangeSample {
        distance_m: f32::from(d.current_distance) / 100.0,
        min_m: f32::from(d.min_distance) / 100.0,
        max_m: f32::from(d.max_distance) / 100.0,
        quality: d.signal_quality.min(100),
    })
}

/// What the autopilot commands for one sensor frame.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ActuatorFrame {
    /// Time of the sensor frame this answers, us.
    pub time_us: u64,
    /// Surface and throttle commands.
    pub surfaces: Surfaces,
    /// Armed (throttle live).
    pub armed: bool,
}

/// Encodes the autopilot's answer.
pub fn encode_actuators(a: &ActuatorFrame) -> HIL_ACTUATOR_CONTROLS_DATA {
    let mut controls = [0.0_f32; 16];
    let c = a.surfaces.to_px4_controls();
    controls[..4].copy_from_slice(&c);
    if !a.armed {
        controls[3] = 0.0;
    }
    let mut mode = MavModeFlag::empty();
    if a.armed {
        mode |= MavModeFlag::MAV_MODE_FLAG_SAFETY_ARMED;
    }
    HIL_ACTUATOR_CONTROLS_DATA {
        time_usec: a.time_us,
        flags: HilActuatorControlsFlags::HIL_ACTUATOR_CONTROLS_FLAGS_LOCKSTEP,
        controls,
        mode,
    }
}

/// Decodes the autopilot's answer (simulator side). Out-of-range or non-finite controls are
/// clamped or neutralised; throttle is zero unless armed.
pub fn decode_actuators(d: &HIL_ACTUATOR_CONTROLS_DATA) -> ActuatorFrame {
    let armed = d.mode.contains(MavModeFlag::MAV_MODE_FLAG_SAFETY_ARMED);
    let mut surfaces =
        Surfaces::from_px4_controls([d.controls[0], d.controls[1], d.controls[2], d.controls[3]]);
    if !armed {
        surfaces.throttle = 0.0;
    }
    ActuatorFrame {
        time_us: d.time_usec,
        surfaces,
        armed,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame() -> SensorFrame {
        SensorFrame {
            time_us: 123_456,
            imu: Some(ImuSample {
                accel: Vector3::new(0.54, 0.017, -9.79),
                gyro: Vector3::new(0.01, -0.02, 0.03),
            }),
            mag: Some(MagSample {
                field: Vector3::new(0.18, -0.01, 0.52),
            }),
            baro: Some(BaroSample {
                pressure_pa: 100_129.4,
                temperature_c: 14.35,
            }),
            pitot: Some(PitotSample {
                diff_pressure_pa: 175.3,
            }),
            reset: false,
        }
    }

    #[test]
    fn sensor_round_trip_and_bits() {
        let d = encode_hil_sensor(&frame(), 100.0);
        // DESIGN.md: a barometer update sets bits 9, 11 and 12 together.
        assert_eq!(d.fields_updated.bits() & BITS_BARO, BITS_BARO);
        assert_eq!(d.fields_updated.bits(), 0x1FFF);
        assert!((d.abs_pressure - 1001.294).abs() < 1e-3, "hPa on the wire");
        let (back, rej) = decode_hil_sensor(&d);
        assert!(rej.none());
        let b = back.baro.map(|b| b.pressure_pa).unwrap_or(0.0);
        assert!((b - 100_129.4).abs() < 0.01);
        assert_eq!(back.imu, frame().imu);
        assert_eq!(back.mag, frame().mag);
    }

    #[test]
    fn implausible_groups_are_dropped_and_flagged() {
        let mut d = encode_hil_sensor(&frame(), 100.0);
        d.xgyro = f32::NAN;
        d.abs_pressure = 5000.0;
        d.diff_pressure = f32::INFINITY;
        let (f, r) = decode_hil_sensor(&d);
        assert!(f.imu.is_none() && r.imu);
        assert!(f.baro.is_none() && r.baro);
        assert!(f.pitot.is_none() && r.pitot);
        assert!(f.mag.is_some() && !r.mag);
        // Half an IMU update is no update.
        let mut d = encode_hil_sensor(&frame(), 100.0);
        d.fields_updated = HilSensorUpdatedFlags::from_bits_truncate(0x7);
        let (f, r) = decode_hil_sensor(&d);
        assert!(f.imu.is_none() && r.imu);
    }

    #[test]
    fn gps_round_trip_in_wire_units() {
        let fix = GpsFix {
            position: GeoPoint::from_deg(44.7258357, -93.07501316),
            alt_amsl_m: 100.25,
            vel_ned: Vector3::new(-15.0, 8.0, 0.5),
            fix_type: 3,
            satellites: 12,
            hdop: 0.9,
        };
        let d = encode_hil_gps(5_000, &fix);
        assert_eq!(d.alt, 100_250);
        assert_eq!((d.vn, d.ve, d.vd), (-1500, 800, 50));
        assert_eq!(d.vel, 1700);
        // Course of (-15, 8): 151.93 deg.
        assert_eq!(d.cog / 100, 151);
        let back = decode_hil_gps(&d).unwrap_or_default();
        assert_eq!(back.position, fix.position);
        assert!((back.vel_ned - fix.vel_ned).norm() < 1e-6);
        let mut bad = d;
        bad.lat = 950_000_000;
        assert!(decode_hil_gps(&bad).is_none());
    }

    #[test]
    fn battery_status_round_trips_in_mv_and_ca_and_refuses_what_is_not_measured() {
        let pack = BatterySample {
            voltage_v: 11.1,
            current_a: 8.25,
        };
        let d = encode_battery_status(&pack);
        // 11.1 V is 11099.999 mV in f32: rounded, not truncated.
        assert_eq!((d.voltages[0], d.current_battery), (11_100, 825));
        assert!(d.voltages[1..].iter().all(|&v| v == u16::MAX));
        assert_eq!(d.battery_remaining, -1);
        assert_eq!(decode_battery_status(&d), Some(pack));
        // Cells reported one by one add up to the pack.
        let mut cells = d.clone();
        cells.voltages[..3].copy_from_slice(&[3700, 3700, 3700]);
        let v = decode_battery_status(&cells).map(|s| s.voltage_v);
        assert!(v.is_some_and(|v| (v - 11.1).abs() < 1e-4), "{v:?}");
        // No voltage, no current, or 65 V: refused.
        let mut none = d.clone();
        none.voltages[0] = u16::MAX;
        assert_eq!(decode_battery_status(&none), None);
        let mut no_current = d.clone();
        no_current.current_battery = -1;
        assert_eq!(decode_battery_status(&no_current), None);
        let mut high = d.clone();
        high.voltages[0] = 65_000;
        assert_eq!(decode_battery_status(&high), None);
    }

    #[test]
    fn actuators_carry_armed_and_lockstep_bits() {
        let a = ActuatorFrame {
            time_us: 42,
            surfaces: Surfaces {
                elevator: -0.0972,
                aileron: 0.01,
                rudder: 0.003,
                throttle: 0.57,
            },
            armed: true,
        };
        let d = encode_actuators(&a);
        assert_eq!(d.mode.bits() & 128, 128);
        assert_eq!(d.flags.bits() & 1, 1);
        // Negative elevator (trailing edge up) is nose-up: positive PX4 pitch.
        assert!(d.controls[1] > 0.0);
        let back = decode_actuators(&d);
        assert!((back.surfaces.elevator - a.surfaces.elevator).abs() < 1e-6);
        let mut disarmed = d;
        disarmed.mode = MavModeFlag::empty();
        assert_eq!(decode_actuators(&disarmed).surfaces.throttle, 0.0);
    }
}

#[cfg(test)]
mod rc_tests {
    use super::*;

    #[test]
    fn rc_channels_round_trip_and_refuse_a_lost_signal() {
        let d = encode_rc_channels(2_000_000, 0.5, -0.25, 0.75, -1.0);
        // PX4's default order and pulse widths.
        assert_eq!(
            [d.chan1_raw, d.chan2_raw, d.chan3_raw, d.chan4_raw],
            [1750, 1375, 1750, 1000]
        );
        let m = decode_rc_channels(&d, 7).expect("valid");
        assert_eq!(
            (m.roll, m.pitch, m.throttle, m.yaw, m.time_us),
            (0.5, -0.25, 0.75, -1.0, 7)
        );
        let mut lost = d.clone();
        lost.rssi = 0;
        assert_eq!(decode_rc_channels(&lost, 7), None);
        let mut unsent = d.clone();
        unsent.chan3_raw = u16::MAX;
        assert_eq!(decode_rc_channels(&unsent, 7), None);
        let mut few = d.clone();
        few.chancount = 3;
        assert_eq!(decode_rc_channels(&few, 7), None);
    }
}

#[cfg(test)]
mod range_tests {
    use super::*;

    #[test]
    fn distance_sensor_round_trips_in_cm_looking_down_and_refuses_other_orientations() {
        let s = RangeSample {
            distance_m: 12.34,
            min_m: 0.1,
            max_m: 40.0,
            quality: 90,
        };
        let d = encode_distance_sensor(3_000_000, &s, 0.025, 0.008);
        assert_eq!(
            (d.current_distance, d.min_distance, d.max_distance),
            (1234, 10, 4000)
        );
        assert_eq!(
            d.orientation,
            MavSensorOrientation::MAV_SENSOR_ROTATION_PITCH_270
        );
        // 2.5 cm of noise: 6.25 cm^2 of variance.
        assert_eq!((d.covariance, d.time_boot_ms), (6, 3000));
        assert_eq!(decode_distance_sensor(&d), Some(s));
        // PX4's out-of-range reading, max + 1 cm, is passed on for the estimator to judge.
        let far = RangeSample {
            distance_m: 40.01,
            ..s
        };
        let got = decode_distance_sensor(&encode_distance_sensor(0, &far, 0.025, 0.008));
        assert_eq!(got.map(|r| r.distance_m > r.max_m), Some(true));
        let mut forward = d.clone();
        forward.orientation = MavSensorOrientation::MAV_SENSOR_ROTATION_NONE;
        assert_eq!(decode_distance_sensor(&forward), None);
        let mut absurd = d.clone();
        absurd.min_distance = 5000;
        assert_eq!(decode_distance_sensor(&absurd), None);
    }
}
