//! The telemetry scheduler: which messages stream at which interval.
//!
//! Defaults follow PX4's "normal" MAVLink mode on a ground-station link; `MAV_CMD_SET_MESSAGE_INTERVAL`
//! changes one stream (interval > 0), restores its default (0) or stops it (-1).

use mavlink::dialects::common::{
    ATTITUDE_DATA, BATTERY_STATUS_DATA, CURRENT_MODE_DATA, EXTENDED_SYS_STATE_DATA,
    GLOBAL_POSITION_INT_DATA, GPS_RAW_INT_DATA, HOME_POSITION_DATA, MISSION_CURRENT_DATA,
    NAV_CONTROLLER_OUTPUT_DATA, SERVO_OUTPUT_RAW_DATA, SYS_STATUS_DATA, VFR_HUD_DATA,
};
use mavlink::MessageData;

/// A message the link can stream.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Stream {
    /// `SYS_STATUS` (1).
    SysStatus,
    /// `GPS_RAW_INT` (24).
    GpsRawInt,
    /// `ATTITUDE` (30).
    Attitude,
    /// `GLOBAL_POSITION_INT` (33).
    GlobalPositionInt,
    /// `MISSION_CURRENT` (42).
    MissionCurrent,
    /// `NAV_CONTROLLER_OUTPUT` (62).
    NavControllerOutput,
    /// `VFR_HUD` (74).
    VfrHud,
    /// `BATTERY_STATUS` (147).
    BatteryStatus,
    /// `HOME_POSITION` (242).
    HomePosition,
    /// `EXTENDED_SYS_STATE` (245).
    ExtendedSysState,
    /// `CURRENT_MODE` (436).
    CurrentMode,
    /// `SERVO_OUTPUT_RAW` (36): the surfaces and the throttle flown, as PWM (what a station
    /// logs for identification from the ground link: `sim-host identify`).
    ServoOutputRaw,
}

/// Number of streams.
pub const STREAM_COUNT: usize = 12;

impl Stream {
    /// Every stream, in the order they are emitted when due together.
    pub const ALL: [Stream; STREAM_COUNT] = [
        Stream::SysStatus,
        Stream::GpsRawInt,
        Stream::Attitude,
        Stream::GlobalPositionInt,
        Stream::MissionCurrent,
        Stream::NavControllerOutput,
        Stream::VfrHud,
        Stream::BatteryStatus,
        Stream::HomePosition,
        Stream::ExtendedSysState,
        Stream::CurrentMode,
        Stream::ServoOutputRaw,
    ];

    /// MAVLink message id.
    pub const fn message_id(self) -> u32 {
        match self {
            Stream::SysStatus => SYS_STATUS_DATA::ID,
            Stream::GpsRawInt => GPS_RAW_INT_DATA::ID,
            Stream::Attitude => ATTITUDE_DATA::ID,
            Stream::GlobalPositionInt => GLOBAL_POSITION_INT_DATA::ID,
            Stream::MissionCurrent => MISSION_CURRENT_DATA::ID,
            Stream::NavControllerOutput => NAV_CONTROLLER_OUTPUT_DATA::ID,
            Stream::VfrHud => VFR_HUD_DATA::ID,
            Stream::BatteryStatus => BATTERY_STATUS_DATA::ID,
            Stream::HomePosition => HOME_POSITION_DATA::ID,
            Stream::ExtendedSysState => EXTENDED_SYS_STATE_DATA::ID,
            Stream::CurrentMode => CURRENT_MODE_DATA::ID,
            Stream::ServoOutputRaw => SERVO_OUTPUT_RAW_DATA::ID,
        }
    }

    /// The stream carrying message `id`.
    pub fn from_message_id(id: u32) -> Option<Self> {
        Self::ALL.iter().copied().find(|s| s.message_id() == id)
    }

    /// Default interval, µs (PX4 normal-mode rates: ATTITUDE 15 Hz, GLOBAL_POSITION_INT 5 Hz,
    /// VFR_HUD 4 Hz, SYS_STATUS/GPS_RAW_INT/NAV_CONTROLLER_OUTPUT/EXTENDED_SYS_STATE/
    /// MISSION_CURRENT/SERVO_OUTPUT_RAW 1 Hz, BATTERY_STATUS/HOME_POSITION/CURRENT_MODE 0.5 Hz).
    pub const fn default_interval_us(self) -> u32 {
        match self {
            Stream::Attitude => 66_667,
            Stream::GlobalPositionInt => 200_000,
            Stream::VfrHud => 250_000,
            Stream::SysStatus
            | Stream::GpsRawInt
            | Stream::NavControllerOutput
            | Stream::ExtendedSysState
            | Stream::MissionCurrent
            | Stream::ServoOutputRaw => 1_000_000,
            Stream::BatteryStatus | Stream::HomePosition | Stream::CurrentMode => 2_000_000,
        }
    }

    fn index(self) -> usize {
        self as usize
    }
}

/// Time between the first emissions of two streams, µs (see [`Scheduler::new`]): the twelve
/// places 90 ms apart lie within the first second, each in a 20 ms control period of its own.
pub const FIRST_DUE_STEP_US: u64 = 90_000;

/// Fastest interval a stream may be set to, µs (1 kHz): faster requests are clamped.
pub const MIN_INTERVAL_US: u32 = 1_000;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Slot {
    /// 0 = stopped.
    interval_us: u32,
    due_us: u64,
}

/// Interval and next due time of every stream.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Scheduler {
    slots: [Slot; STREAM_COUNT],
}

impl Default for Scheduler {
    fn default() -> Self {
        Self::new()
    }
}

impl Scheduler {
    /// All streams at their default interval. The fast ones (ATTITUDE, GLOBAL_POSITION_INT,
    /// VFR_HUD) are first due at time 0; the once-a-second and slower ones are spread over the
    /// first second ([`FIRST_DUE_STEP_US`] times their place in [`Stream::ALL`]), so that they
    /// do not all fall due in the same control period: due together with the fast ones and
    /// the heartbeat, their messages cost an MCU's control period some 70,000 instructions
    /// more than the others, once a second.
    pub fn new() -> Self {
        let mut slots = [Slot {
            interval_us: 0,
            due_us: 0,
        }; STREAM_COUNT];
        let mut first_due_us = 0;
        for s in Stream::ALL {
            if let Some(slot) = slots.get_mut(s.index()) {
                slot.interval_us = s.default_interval_us();
                if slot.interval_us >= 1_000_000 {
                    slot.due_us = first_due_us;
                }
            }
            first_due_us = first_due_us.saturating_add(FIRST_DUE_STEP_US);
        }
        Self { slots }
    }

    /// Current interval of a stream, µs; `None` when stopped.
    pub fn interval_us(&self, s: Stream) -> Option<u32> {
        self.slots
            .get(s.index())
            .map(|x| x.interval_us)
            .filter(|&i| i > 0)
    }

    /// Applies `SET_MESSAGE_INTERVAL`'s `interval_us` (-1 stop, 0 default, > 0 interval);
    /// `false`, changing nothing, for NaN.
    pub fn set_interval(&mut self, s: Stream, interval_us: f32, now_us: u64) -> bool {
        if interval_us.is_nan() {
            return false;
        }
        let new = if interval_us < -0.5 {
            0
        } else if interval_us < 0.5 {
            s.default_interval_us()
        } else if interval_us >= u32::MAX as f32 {
            u32::MAX
        } else {
            (interval_us as u32).max(MIN_INTERVAL_US)
        };
        if let Some(slot) = self.slots.get_mut(s.index()) {
            slot.interval_us = new;
            slot.due_us = now_us;
        }
        true
    }

    /// Calls `emit` for each stream due at `now_us` and schedules its next emission. A late
    /// poll emits once, not a burst of the missed ones.
    pub fn run(&mut self, now_us: u64, mut emit: impl FnMut(Stream)) {
        for s in Stream::ALL {
            let Some(slot) = self.slots.get_mut(s.index()) else {
                continue;
            };
            if slot.interval_us == 0 || now_us < slot.due_us {
                continue;
            }
            emit(s);
            slot.due_us = slot.due_us.saturating_add(u64::from(slot.interval_us));
            if slot.due_us <= now_us {
                slot.due_us = now_us.saturating_add(u64::from(slot.interval_us));
            }
        }
    }
}
