//! The simulator link into the application (`App::on_sim_bytes`): sensor, GPS, radio and
//! truth frames with any values and any timestamps, corrupted, cut and interleaved with
//! garbage, and the ground station arming and switching modes in between.
//!
//! Asserted: each intact `HIL_SENSOR` of our system gets exactly one `HIL_ACTUATOR_CONTROLS`
//! answer naming its time, and nothing else gets one; every control is finite and in range
//! (throttle zero while disarmed); the heartbeat comes at least once a second of vehicle time;
//! the vehicle's clock never goes back.

use arbitrary::Arbitrary;
use common::link::framing::{FrameParser, Sender};
use common::link::simlink::BITS_IMU;
use common::sensors::SensorFrame;
use firmware::app::App;
use mavlink::dialects::common::*;

use crate::frames::{calm_fix, calm_sensors, frame, raw_frame, Simulator, Wobble};
use crate::gcs::{Float, GcsMsg};
use crate::watch::{check_controls, drain, sim_answers, Heartbeat};

/// A timestamp: most often the next regular one, sometimes anything.
#[derive(Arbitrary, Clone, Copy, Debug)]
pub enum Time {
    Next,
    Step(u16),
    Back(u32),
    Jump(u64),
    Same,
}

/// What the simulator does next.
#[derive(Arbitrary, Clone, Debug)]
pub enum SimAction {
    /// Regular frames of an aircraft at rest, 10 ms apart, with a GPS fix every 10th.
    Calm { frames: u8, wobble: Wobble },
    /// One sensor frame with any values in any group.
    Sensor {
        time: Time,
        fields: u32,
        values: [Float; 12],
    },
    /// A GPS frame with any values.
    Gps {
        time: Time,
        fix_type: u8,
        lat: i32,
        lon: i32,
        alt: i32,
        vel: [i16; 3],
        eph: u16,
        sats: u8,
    },
    /// A plausible fix, offset from home.
    Fix { north: i16, east: i16, speed: u8 },
    /// The radio.
    Rc { chan: [u16; 4], count: u8, rssi: u8 },
    /// The simulator's truth.
    Truth {
        q: [Float; 4],
        rates: [Float; 3],
        v: [i16; 3],
        tas: u16,
        alt: i32,
    },
    /// A frame of any id the dialect knows, any payload.
    Raw { id: u16, payload: Vec<u8> },
    /// A sensor frame from another system.
    Foreign { sys: u8 },
    /// Bytes that are no frame.
    Garbage(Vec<u8>),
    /// The next regular sensor frame with one byte changed.
    Corrupt { at: u16, xor: u8 },
    /// The next regular sensor frame delivered in two reads.
    Split { at: u16 },
    /// The ground station (arming, modes, sticks, parameters).
    Ground(GcsMsg),
}

struct Harness {
    app: App,
    sim: Simulator,
    station: Sender,
    /// The last raw timestamp sent, for the next regular one.
    raw_us: u64,
    heartbeat: Heartbeat,
}

impl Harness {
    fn time(&mut self, t: Time) -> u64 {
        self.raw_us = match t {
            Time::Next => self.raw_us.wrapping_add(10_000),
            Time::Step(s) => self.raw_us.wrapping_add(u64::from(s) * 100),
            Time::Back(s) => self.raw_us.wrapping_sub(u64::from(s)),
            Time::Jump(t) => t,
            Time::Same => self.raw_us,
        };
        self.raw_us
    }

    /// Feeds the pieces, one read each. Every `HIL_SENSOR` of our system that a fresh parser
    /// finds in them is owed one answer naming its time (each action leaves the link's parser
    /// empty: garbage is followed by a frame's length of zeros).
    fn feed(&mut self, pieces: &[&[u8]]) {
        let mut expected = Vec::new();
        let mut reference = FrameParser::new();
        for p in pieces {
            reference.push(p, |f| {
                if let MavMessage::HIL_SENSOR(d) = f.message {
                    if f.header.system_id == u32::from(common::gcs::SYSTEM_ID) {
                        expected.push(d.time_usec);
                    }
                }
            });
        }
        let mut out = Vec::new();
        for p in pieces {
            self.app.on_sim_bytes(p, &mut |b| out.extend_from_slice(b));
        }
        let answers = sim_answers(&out);
        assert_eq!(
            answers.iter().map(|a| a.time_usec).collect::<Vec<_>>(),
            expected,
            "one answer per sensor frame, naming its time"
        );
        for a in &answers {
            check_controls(a, a.mode.contains(MavModeFlag::MAV_MODE_FLAG_SAFETY_ARMED));
        }
        if let Some(last) = answers.last() {
            let flag = last.mode.contains(MavModeFlag::MAV_MODE_FLAG_SAFETY_ARMED);
            assert_eq!(
                flag,
                self.app.armed(),
                "the answer says armed as the vehicle is"
            );
        }
        let sent = drain(&mut self.app);
        if !expected.is_empty() {
            let now = self.app.vehicle().time_us().unwrap_or(0);
            self.heartbeat.after_poll(now, &sent);
        }
    }

    fn sensor(&mut self, f: &SensorFrame) {
        let bytes = self.sim.sensors(f);
        self.feed(&[&bytes]);
    }

    fn step(&mut self, a: &SimAction) {
        match a {
            SimAction::Calm { frames, wobble } => {
                for k in 0..u32::from(*frames) {
                    let t = self.time(Time::Next);
                    if k % 10 == 0 {
                        let fix = self.sim.gps(t, &calm_fix((0, 0), wobble.airspeed));
                        self.feed(&[&fix]);
                    }
                    self.sensor(&calm_sensors(t, wobble));
                }
            }
            SimAction::Sensor {
                time,
                fields,
                values,
            } => {
                let t = self.time(*time);
                let v = values.map(Float::get);
                let d = HIL_SENSOR_DATA {
                    time_usec: t,
                    xacc: v[0],
                    yacc: v[1],
                    zacc: v[2],
                    xgyro: v[3],
                    ygyro: v[4],
                    zgyro: v[5],
                    xmag: v[6],
                    ymag: v[7],
                    zmag: v[8],
                    abs_pressure: v[9],
                    diff_pressure: v[10],
                    pressure_alt: 0.0,
                    temperature: v[11],
                    fields_updated: HilSensorUpdatedFlags::from_bits_retain(fields | BITS_IMU),
                    id: 0,
                };
                let bytes = frame(&mut self.sim.tx, &MavMessage::HIL_SENSOR(d));
                self.feed(&[&bytes]);
            }
            SimAction::Gps {
                time,
                fix_type,
                lat,
                lon,
                alt,
                vel,
                eph,
                sats,
            } => {
                let t = self.time(*time);
                let d = HIL_GPS_DATA {
                    time_usec: t,
                    lat: *lat,
                    lon: *lon,
                    alt: *alt,
                    eph: *eph,
                    epv: *eph,
                    vel: 0,
                    vn: vel[0],
                    ve: vel[1],
                    vd: vel[2],
                    cog: u16::MAX,
                    fix_type: *fix_type,
                    satellites_visible: *sats,
                    id: 0,
                    yaw: 0,
                };
                let bytes = frame(&mut self.sim.tx, &MavMessage::HIL_GPS(d));
                self.feed(&[&bytes]);
            }
            SimAction::Fix { north, east, speed } => {
                let bytes = self
                    .sim
                    .gps(self.raw_us, &calm_fix((*north, *east), *speed));
                self.feed(&[&bytes]);
            }
            SimAction::Rc { chan, count, rssi } => {
                let d = RC_CHANNELS_DATA {
                    chan1_raw: chan[0],
                    chan2_raw: chan[1],
                    chan3_raw: chan[2],
                    chan4_raw: chan[3],
                    chancount: *count,
                    rssi: *rssi,
                    ..RC_CHANNELS_DATA::DEFAULT
                };
                let bytes = frame(&mut self.sim.tx, &MavMessage::RC_CHANNELS(d));
                self.feed(&[&bytes]);
            }
            SimAction::Truth {
                q,
                rates,
                v,
                tas,
                alt,
            } => {
                let d = HIL_STATE_QUATERNION_DATA {
                    time_usec: self.raw_us,
                    attitude_quaternion: q.map(Float::get),
                    rollspeed: rates[0].get(),
                    pitchspeed: rates[1].get(),
                    yawspeed: rates[2].get(),
                    alt: *alt,
                    vx: v[0],
                    vy: v[1],
                    vz: v[2],
                    true_airspeed: *tas,
                    ..HIL_STATE_QUATERNION_DATA::DEFAULT
                };
                let bytes = frame(&mut self.sim.tx, &MavMessage::HIL_STATE_QUATERNION(d));
                self.feed(&[&bytes]);
            }
            SimAction::Raw { id, payload } => {
                // Mostly the messages the link reads, with any payload.
                let id = match *id {
                    i @ 0..=1023 => [107, 113, 115, 65, 0][usize::from(i) % 5],
                    i => u32::from(i),
                };
                if let Some(bytes) = raw_frame(&mut self.sim.tx, id, payload) {
                    self.feed(&[&bytes]);
                }
            }
            SimAction::Foreign { sys } => {
                let t = self.raw_us.wrapping_add(10_000);
                let mut other = Simulator {
                    tx: Sender::new(if *sys == 1 { 2 } else { *sys }, 51),
                };
                let bytes = other.sensors(&calm_sensors(t, &Wobble::default()));
                self.feed(&[&bytes]);
            }
            SimAction::Garbage(g) => {
                // Garbage may hold the start of a frame that swallows what follows; a frame
                // after it is owed nothing, so end it here with a whole frame's length of
                // zeros (a zero is never a start marker and fails any candidate's checksum).
                let mut bytes = g.clone();
                bytes.extend_from_slice(&[0u8; 300]);
                self.feed(&[&bytes]);
            }
            SimAction::Corrupt { at, xor } => {
                let t = self.time(Time::Next);
                let mut bytes = self.sim.sensors(&calm_sensors(t, &Wobble::default()));
                let i = usize::from(*at) % bytes.len();
                let xor = if *xor == 0 { 1 } else { *xor };
                bytes[i] ^= xor;
                bytes.extend_from_slice(&[0u8; 300]);
                self.feed(&[&bytes]);
            }
            SimAction::Split { at } => {
                let t = self.time(Time::Next);
                let bytes = self.sim.sensors(&calm_sensors(t, &Wobble::default()));
                let i = usize::from(*at) % bytes.len();
                let (a, b) = bytes.split_at(i);
                self.feed(&[a, b]);
            }
            SimAction::Ground(m) => {
                let mut bytes = Vec::new();
                match m.build(self.app.vehicle().params()) {
                    Some(crate::gcs::Built::Typed(msg)) => {
                        bytes = frame(&mut self.station, &msg);
                    }
                    Some(crate::gcs::Built::Raw(id, p)) => {
                        if let Some(f) = raw_frame(&mut self.station, id, &p) {
                            bytes = f;
                        }
                    }
                    None => {}
                }
                // Datagrams: a cut frame never holds back the simulator's next one.
                self.app.on_gcs_datagram(1, &bytes);
                // What it answered is checked as it is drained. The heartbeat is not asked of
                // it: a datagram that asks the vehicle nothing costs its framing only, and the
                // link's next run is the next sensor frame's, where the heartbeat is checked.
                let sent = drain(&mut self.app);
                let now = self.app.vehicle().time_us().unwrap_or(0);
                self.heartbeat.note(now, &sent);
            }
        }
    }
}

/// Runs one input.
pub fn run(data: &[u8]) {
    let mut h = Harness {
        app: App::new(),
        sim: Simulator::default(),
        station: Sender::new(255, 190),
        raw_us: 0,
        heartbeat: Heartbeat::default(),
    };
    crate::each_action(data, 400, |a: &SimAction| h.step(a));
}
