//! The flight log: what the autopilot records of each flight, at what rate, as ULog.
//!
//! The logger never writes storage itself. Each control period it encodes what is due into a
//! RAM ring ([`RING_LEN`] bytes), whole messages only; the board drains the ring into its
//! storage (a file in SITL, a flash region on the MCU) outside the control period, at its own
//! pace. A sample that finds the ring full is dropped, counted, and the gap is written as a
//! ULog dropout once there is room again, so a slow storage costs log data, never a control
//! period.
//!
//! A log starts with its definitions (header, flag bits, information, every parameter, the
//! formats and subscriptions). They go out a few messages a period as the ring has room,
//! before the first sample; a flight's samples start once they are out, a few periods
//! after arming.

pub mod params;
pub mod ring;
pub mod topics;

use crate::params::ParamStore;
use crate::ulog::topic::{Format, Topic};
use crate::ulog::{self, Level, TooLong};
use ring::ByteRing;
use topics::*;

/// Bytes of the ring between the logger and the storage.
pub const RING_LEN: usize = 4096;
/// The longest message the logger encodes (a format's text is the longest).
pub const MESSAGE_MAX: usize = 512;
/// Every how many microseconds a sync message is written.
pub const SYNC_PERIOD_US: u64 = 1_000_000;
/// Bytes of definitions encoded a control period at most: the log's opening (about 10 KB of
/// formats and parameters) spread over half a second, so no period pays for much of it (the
/// MCU's budget is per period).
pub const DEFINITIONS_PER_STEP: usize = 512;
/// The first samples of the topics, one topic a period after the definitions, µs apart: no
/// period encodes every topic at once.
pub const FIRST_SAMPLE_STAGGER_US: u64 = 20_000;

/// A topic of this log: its message id is its place in [`TOPICS`].
pub trait Logged: Topic {
    /// Its message id.
    const ID: u16;
}

macro_rules! logged {
    ($($t:ident => $rate:literal),* $(,)?) => {
        /// Every topic of the log with its rate in Hz, in message-id order.
        pub const TOPICS: &[(Format, u16)] = &[$(($t::FORMAT, $rate)),*];
        logged!(@ids 0u16, $($t),*);
    };
    (@ids $n:expr, $t:ident $(, $rest:ident)*) => {
        impl Logged for $t {
            const ID: u16 = $n;
        }
        logged!(@ids $n + 1, $($rest),*);
    };
    (@ids $n:expr,) => {};
}

// Rates: the estimate and the loops fast enough to see a 1-2 Hz oscillation of the attitude
// loops sharply, the slow states at a few Hz: 8.1 KB a second in all as flown (1.13 MB over
// the default mission's first 140 s in SITL; docs/LOGGING.md).
logged! {
    VehicleAttitude => 25,
    SensorCombined => 25,
    ControlLoops => 25,
    ActuatorOutputs => 25,
    VehicleAttitudeSetpoint => 10,
    VehicleLocalPosition => 10,
    AirspeedValidated => 10,
    VehicleAirData => 5,
    DifferentialPressure => 5,
    VehicleMagnetometer => 5,
    VehicleGlobalPosition => 5,
    VehicleGpsPosition => 5,
    Wind => 2,
    EstimatorStates => 2,
    VehicleStatus => 2,
    VehicleLandDetected => 2,
    BatteryStatus => 1,
    MissionResult => 1,
    TelemetryStatus => 1,
    DistanceSensor => 10,
}

/// What identifies the log's system (ULog information messages).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SystemInfo {
    /// `sys_name`: the autopilot.
    pub sys_name: &'static str,
    /// `ver_sw`: the software version.
    pub ver_sw: &'static str,
    /// `ver_hw`: the board.
    pub ver_hw: &'static str,
}

/// Where the log's definitions stand.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Stage {
    Header,
    Flags,
    Info(u8),
    Param(u16),
    Format(u16),
    Subscribe(u16),
    Data,
}

/// Counters of what the log lost.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LogStats {
    /// Samples and texts dropped for want of room in the ring.
    pub dropped: u32,
    /// Bytes taken into the ring.
    pub bytes: u32,
}

/// The logger of one flight at a time.
pub struct Logger {
    ring: ByteRing<RING_LEN>,
    stage: Option<Stage>,
    start_us: u64,
    next_due_us: [u64; TOPICS.len()],
    next_sync_us: u64,
    dropout_since_us: Option<u64>,
    stats: LogStats,
    info: SystemInfo,
    /// No topic faster than this, Hz (0: each at its own rate).
    rate_cap_hz: u16,
    /// The identification's topics at every sensor frame (`SDLOG_PROFILE`).
    high_rate: bool,
}

/// The topics a model of the aircraft is fitted from (`sim-host identify`), and their rate
/// when `SDLOG_PROFILE` asks for them: every 100 Hz sensor frame (at the control ticks' 50 Hz
/// the 25e's roll damping came out 14 % short from its stick doublets, at 100 Hz 10 %).
const IDENTIFICATION: [u16; 5] = [
    VehicleAttitude::ID,
    SensorCombined::ID,
    ActuatorOutputs::ID,
    VehicleLocalPosition::ID,
    AirspeedValidated::ID,
];
const IDENTIFICATION_HZ: u16 = 100;

impl Logger {
    /// A logger recording nothing yet.
    pub fn new(info: SystemInfo) -> Self {
        Self {
            ring: ByteRing::new(),
            stage: None,
            start_us: 0,
            next_due_us: [0; TOPICS.len()],
            next_sync_us: 0,
            dropout_since_us: None,
            stats: LogStats::default(),
            info,
            rate_cap_hz: 0,
            high_rate: false,
        }
    }

    /// Caps every topic's rate at `hz` (0: each at its own rate): a board whose storage is
    /// small or slow (the MCU's flash) logs the same topics less often.
    pub fn set_rate_cap(&mut self, hz: u16) {
        self.rate_cap_hz = hz;
    }

    /// Logs the identification's topics at every sensor frame (`SDLOG_PROFILE`'s bits 3 and
    /// 4), or each at its own rate.
    pub fn set_high_rate(&mut self, on: bool) {
        self.high_rate = on;
    }

    /// The rate topic `id` is written at, Hz: its own (the sensor frames' for the
    /// identification's topics when asked), or the cap when lower.
    pub fn rate_hz(&self, id: u16) -> Option<u16> {
        let (_, rate) = TOPICS.get(usize::from(id))?;
        let rate = if self.high_rate && IDENTIFICATION.contains(&id) {
            IDENTIFICATION_HZ
        } else {
            *rate
        };
        Some(match self.rate_cap_hz {
            0 => rate,
            cap => rate.min(cap),
        })
    }

    /// Whether a log is being recorded.
    pub fn recording(&self) -> bool {
        self.stage.is_some()
    }

    /// Whether the log is past its definitions: samples and texts are written now.
    pub fn writes_samples(&self) -> bool {
        self.stage == Some(Stage::Data)
    }

    /// What this log lost and took.
    pub fn stats(&self) -> LogStats {
        self.stats
    }

    /// Starts a new log at `now_us` (what is still in the ring of the last one stays ahead
    /// of it: drain it into the last log's storage first).
    pub fn start(&mut self, now_us: u64) {
        self.stage = Some(Stage::Header);
        self.start_us = now_us;
        self.next_due_us = [now_us; TOPICS.len()];
        self.next_sync_us = now_us.saturating_add(SYNC_PERIOD_US);
        self.dropout_since_us = None;
        self.stats = LogStats::default();
    }

    /// Ends the log: nothing more is taken; what is in the ring is still to be drained.
    pub fn stop(&mut self) {
        self.stage = None;
    }

    /// Moves the definitions on as far as the ring has room, then writes a sync marker when
    /// one is due. Call once a control period, before the samples.
    pub fn step(&mut self, now_us: u64, params: &ParamStore) {
        let mut budget = DEFINITIONS_PER_STEP;
        while let Some(stage) = self.stage.filter(|s| *s != Stage::Data) {
            if budget == 0 {
                return;
            }
            let mut b = [0u8; MESSAGE_MAX];
            let Some((n, next)) = self.definition(stage, params, &mut b) else {
                // An oversized definition is skipped, not allowed to stall the log.
                self.stage = Some(self.after(stage));
                continue;
            };
            if !self.ring.push(b.get(..n).unwrap_or(&[])) {
                return;
            }
            self.stats.bytes = self.stats.bytes.saturating_add(n as u32);
            budget = budget.saturating_sub(n);
            self.stage = Some(next);
            if next == Stage::Data {
                // The samples start now, one topic a period.
                for (k, due) in self.next_due_us.iter_mut().enumerate() {
                    *due =
                        now_us.saturating_add((k as u64).saturating_mul(FIRST_SAMPLE_STAGGER_US));
                }
            }
        }
        if self.stage == Some(Stage::Data) && now_us >= self.next_sync_us {
            let mut b = [0u8; 16];
            if let Ok(n) = ulog::sync(&mut b) {
                if self.ring.push(b.get(..n).unwrap_or(&[])) {
                    self.next_sync_us = now_us.saturating_add(SYNC_PERIOD_US);
                }
            }
        }
    }

    /// Whether any topic is due at `now_us` (the caller gathers nothing otherwise).
    pub fn any_due(&self, now_us: u64) -> bool {
        self.stage == Some(Stage::Data) && self.next_due_us.iter().any(|&t| now_us >= t)
    }

    /// Whether topic `T` is due at `now_us` (the caller builds the sample only then).
    pub fn due<T: Logged>(&self, now_us: u64) -> bool {
        self.stage == Some(Stage::Data)
            && self
                .next_due_us
                .get(usize::from(T::ID))
                .is_some_and(|&t| now_us >= t)
    }

    /// Writes one sample of `T` stamped `now_us`, and schedules the next at its rate.
    pub fn write<T: Logged>(&mut self, now_us: u64, sample: &T) {
        if self.stage != Some(Stage::Data) {
            return;
        }
        // The fields where the message will hold them, the rest in `write_encoded`: inlined
        // here, the encoding of a sample is its fields' stores at known places.
        let mut b = [0u8; MESSAGE_MAX];
        let fields = ulog::data_fields(&mut b, |c| sample.encode(c));
        self.write_encoded(now_us, T::ID, fields, &mut b);
    }

    /// The part of [`Logger::write`] that is the same for every topic: the next sample's time,
    /// the data message's header in front of the fields and the push into the ring. Not
    /// inlined: it would be copied into each of the twenty topics' callers (some 3 KB of the
    /// MCU image).
    #[inline(never)]
    fn write_encoded(
        &mut self,
        now_us: u64,
        id: u16,
        fields: Result<usize, TooLong>,
        b: &mut [u8; MESSAGE_MAX],
    ) {
        let rate = self.rate_hz(id);
        if let (Some(due), Some(rate)) = (self.next_due_us.get_mut(usize::from(id)), rate) {
            let period = 1_000_000 / u64::from(rate.max(1));
            // Keep the phase while on time; after a gap, start again from now.
            let next = due.saturating_add(period);
            *due = if next > now_us {
                next
            } else {
                now_us.saturating_add(period)
            };
        }
        let n = ulog::data_in_place(b, id, now_us, fields);
        self.push_or_drop(now_us, n, b);
    }

    /// Writes a text (a status text, a failsafe or land-detector event) stamped `now_us`.
    pub fn text(&mut self, now_us: u64, level: Level, text: &str) {
        if self.stage != Some(Stage::Data) {
            return;
        }
        let mut b = [0u8; MESSAGE_MAX];
        let n = ulog::logging(&mut b, level, now_us, text);
        self.push_or_drop(now_us, n, &b);
    }

    /// The oldest bytes waiting for the storage (a contiguous run; more may follow).
    pub fn pending(&self) -> &[u8] {
        self.ring.front()
    }

    /// Bytes waiting for the storage in all.
    pub fn pending_len(&self) -> usize {
        self.ring.len()
    }

    /// The storage took the first `n` bytes of [`Logger::pending`].
    pub fn consume(&mut self, n: usize) {
        self.ring.consume(n);
    }

    fn push_or_drop(&mut self, now_us: u64, n: Result<usize, TooLong>, b: &[u8]) {
        if let Some(since) = self.dropout_since_us {
            let mut d = [0u8; 8];
            let ms = now_us.saturating_sub(since) / 1000;
            let room = n.map_or(0, |n| n).saturating_add(5);
            match ulog::dropout(&mut d, u32::try_from(ms).unwrap_or(u32::MAX)) {
                Ok(k) if self.ring.free() >= room => {
                    self.ring.push(d.get(..k).unwrap_or(&[]));
                    self.dropout_since_us = None;
                }
                _ => {}
            }
        }
        let pushed = match n {
            Ok(n) if self.dropout_since_us.is_none() => self.ring.push(b.get(..n).unwrap_or(&[])),
            _ => false,
        };
        match (pushed, n) {
            (true, Ok(n)) => self.stats.bytes = self.stats.bytes.saturating_add(n as u32),
            _ => {
                self.stats.dropped = self.stats.dropped.saturating_add(1);
                self.dropout_since_us.get_or_insert(now_us);
            }
        }
    }

    /// The message of definition `stage`, and the stage after it; `None` if it cannot be
    /// encoded.
    fn definition(
        &self,
        stage: Stage,
        params: &ParamStore,
        b: &mut [u8],
    ) -> Option<(usize, Stage)> {
        let next = self.after(stage);
        let n = match stage {
            Stage::Header => ulog::header(b, self.start_us),
            Stage::Flags => ulog::flag_bits(b),
            Stage::Info(0) => ulog::info_str(b, "sys_name", self.info.sys_name),
            Stage::Info(1) => ulog::info_str(b, "ver_sw", self.info.ver_sw),
            Stage::Info(_) => ulog::info_str(b, "ver_hw", self.info.ver_hw),
            Stage::Param(i) => {
                let i = usize::from(i);
                let (Some(def), Some(v)) = (params.def(i), params.value(i)) else {
                    // Past the last parameter: on to the formats.
                    return Some((0, Stage::Format(0)));
                };
                if def.kind.is_integer() {
                    ulog::parameter_i32(b, def.name, v as i32)
                } else {
                    ulog::parameter_f32(b, def.name, v)
                }
            }
            Stage::Format(i) => ulog::format(b, &TOPICS.get(usize::from(i))?.0),
            Stage::Subscribe(i) => {
                let name = TOPICS.get(usize::from(i))?.0.name;
                ulog::add_logged(b, 0, i, name)
            }
            Stage::Data => return None,
        };
        n.ok().map(|n| (n, next))
    }

    fn after(&self, stage: Stage) -> Stage {
        let topics = TOPICS.len() as u16;
        match stage {
            Stage::Header => Stage::Flags,
            Stage::Flags => Stage::Info(0),
            Stage::Info(i) if i < 2 => Stage::Info(i + 1),
            Stage::Info(_) => Stage::Param(0),
            Stage::Param(i) => Stage::Param(i.saturating_add(1)),
            Stage::Format(i) if i.saturating_add(1) < topics => Stage::Format(i + 1),
            Stage::Format(_) => Stage::Subscribe(0),
            Stage::Subscribe(i) if i.saturating_add(1) < topics => Stage::Subscribe(i + 1),
            Stage::Subscribe(_) | Stage::Data => Stage::Data,
        }
    }
}

#[cfg(test)]
mod tests;
