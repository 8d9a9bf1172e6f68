//! Frames as a simulator or a ground station sends them: well-formed MAVLink 2 frames of
//! typed messages, frames of any message id with any payload (their checksum right, so the
//! autopilot's decoder and not its framing meets them), and the realistic sensor frames that
//! let the estimator converge so the fuzzer reaches armed flight in every mode.

use arbitrary::Arbitrary;
use common::link::framing::Sender;
use common::link::simlink::{encode_hil_gps, encode_hil_sensor};
use common::math::geodetic::GeoPoint;
use common::sensors::{BaroSample, GpsFix, ImuSample, MagSample, PitotSample, SensorFrame};
use mavlink::dialects::common::MavMessage;
use mavlink::Message;
use nalgebra::Vector3;

/// Where the realistic frames put the aircraft (any field will do; this one is flat).
pub const HOME: GeoPoint = GeoPoint {
    lat_e7: 473_977_420,
    lon_e7: 85_455_940,
};
/// Its altitude above mean sea level, m.
pub const HOME_ALT_M: f32 = 488.0;

/// One MAVLink 2 frame of `msg` from `tx`.
pub fn frame(tx: &mut Sender, msg: &MavMessage) -> Vec<u8> {
    tx.encode(msg).raw_bytes().to_vec()
}

/// A MAVLink 2 frame of message `id` with this payload and a valid checksum, whatever the
/// payload holds (the dialect may not decode it: an unknown enum value, a command id it has
/// no name for). `None` for an id the dialect does not know (no checksum seed).
pub fn raw_frame(tx: &mut Sender, id: u32, payload: &[u8]) -> Option<Vec<u8>> {
    let extra = MavMessage::extra_crc(id);
    MavMessage::default_message_from_id(id)?;
    let payload = payload.get(..payload.len().min(255)).unwrap_or(&[]);
    let h = tx.next_header();
    let mut f = vec![
        0xFD,
        payload.len() as u8,
        0,
        0,
        h.sequence,
        h.system_id as u8,
        h.component_id,
    ];
    f.extend_from_slice(&id.to_le_bytes()[..3]);
    f.extend_from_slice(payload);
    let mut crc = X25::new();
    crc.digest(&f[1..]);
    crc.digest(&[extra]);
    f.extend_from_slice(&crc.get().to_le_bytes());
    Some(f)
}

/// MAVLink's checksum (CRC-16/MCRF4XX).
struct X25(u16);

impl X25 {
    fn new() -> Self {
        Self(0xFFFF)
    }
    fn digest(&mut self, bytes: &[u8]) {
        for &b in bytes {
            let mut t = b ^ (self.0 & 0xFF) as u8;
            t ^= t << 4;
            self.0 =
                (self.0 >> 8) ^ (u16::from(t) << 8) ^ (u16::from(t) << 3) ^ (u16::from(t) >> 4);
        }
    }
    fn get(&self) -> u16 {
        self.0
    }
}

/// Small deviations of a realistic frame from rest: a few tenths of the unit each, so the
/// estimator sees a plausible aircraft but not always the same one.
#[derive(Arbitrary, Clone, Copy, Debug, Default)]
pub struct Wobble {
    pub accel: [i8; 3],
    pub gyro: [i8; 3],
    pub baro: i8,
    pub airspeed: u8,
}

/// A sensor frame of an aircraft at rest (or flying straight and level at `wobble.airspeed`)
/// over [`HOME`], heading north.
pub fn calm_sensors(time_us: u64, w: &Wobble) -> SensorFrame {
    let small = |v: i8, scale: f32| f32::from(v) * scale;
    let airspeed = f32::from(w.airspeed) * 0.15;
    SensorFrame {
        time_us,
        imu: Some(ImuSample {
            accel: Vector3::new(
                small(w.accel[0], 0.01),
                small(w.accel[1], 0.01),
                -9.806_65 + small(w.accel[2], 0.01),
            ),
            gyro: Vector3::new(
                small(w.gyro[0], 1e-4),
                small(w.gyro[1], 1e-4),
                small(w.gyro[2], 1e-4),
            ),
        }),
        mag: Some(MagSample {
            field: Vector3::new(0.216, 0.0, 0.424),
        }),
        baro: Some(BaroSample {
            pressure_pa: 95_600.0 + small(w.baro, 1.0),
            temperature_c: 15.0,
        }),
        pitot: Some(PitotSample {
            diff_pressure_pa: 0.5 * 1.13 * airspeed * airspeed,
        }),
        reset: false,
    }
}

/// A 3D fix over [`HOME`], `offset` metres north and east, flying north at `speed` m/s.
pub fn calm_fix(offset: (i16, i16), speed: u8) -> GpsFix {
    let deg_per_m = 1.0 / 111_320.0;
    GpsFix {
        position: GeoPoint {
            lat_e7: HOME.lat_e7 + (f64::from(offset.0) * deg_per_m * 1e7) as i32,
            lon_e7: HOME.lon_e7 + (f64::from(offset.1) * deg_per_m * 1.5 * 1e7) as i32,
        },
        alt_amsl_m: HOME_ALT_M,
        vel_ned: Vector3::new(f32::from(speed) * 0.15, 0.0, 0.0),
        fix_type: 3,
        satellites: 12,
        hdop: 0.8,
    }
}

/// The simulator's frames, from the autopilot's system (1), as a simulator sends them.
pub struct Simulator {
    pub tx: Sender,
}

impl Default for Simulator {
    fn default() -> Self {
        Self {
            tx: Sender::new(common::gcs::SYSTEM_ID, 51),
        }
    }
}

impl Simulator {
    /// `HIL_SENSOR` of `f`.
    pub fn sensors(&mut self, f: &SensorFrame) -> Vec<u8> {
        frame(
            &mut self.tx,
            &MavMessage::HIL_SENSOR(encode_hil_sensor(f, 0.0)),
        )
    }

    /// `HIL_GPS` of `fix` at `time_us`.
    pub fn gps(&mut self, time_us: u64, fix: &GpsFix) -> Vec<u8> {
        frame(
            &mut self.tx,
            &MavMessage::HIL_GPS(encode_hil_gps(time_us, fix)),
        )
    }
}
