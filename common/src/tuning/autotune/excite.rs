//! The inputs the vehicle flies to identify itself: where each axis's excitation starts and
//! ends in the autotune's timeline, and its shape.
//!
//! Roll and pitch take 3-2-1-1 sequences on the attitude command (pulses of 3, 2, 1 and 1
//! base widths, alternating in sign): one sequence spreads its energy over a decade of
//! frequency around the inner loops' bandwidth, and the closed attitude loops keep the
//! aircraft near its level attitude throughout (the stick flight of `sim-host fly
//! --stick-doublets` identified roll and pitch within 6 % this way). Three sequences an axis,
//! the second mirrored, leave the fit no one-sided bias. The throttle takes steps, up then
//! down: the airspeed answers a throttle step with its own slow pole.

/// One stretch of the timeline.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Stage {
    /// Wings level at the start altitude and airspeed: the loops settle, the level pitch and
    /// throttle are taken.
    Level,
    /// 3-2-1-1s on the roll command.
    Roll,
    /// 3-2-1-1s on the pitch command, throttle held.
    Pitch,
    /// Throttle steps, pitch held.
    Throttle,
    /// 3-2-1-1s on the rudder, wings held level: last, as the wind estimate takes a share of
    /// the sideslip for wind and gives it back over some seconds, and the other models read
    /// their angle of attack through it.
    Yaw,
}

/// Width of a 3-2-1-1's unit pulse, s: its energy sits between `1 / (6 T)` and `1 / (2 T)`
/// Hz, around the roll and pitch loops' 1-3 Hz.
pub const PULSE_S: f32 = 0.3;

/// Level flight after each 3-2-1-1, s.
const REST_S: f32 = 2.0;

/// A 3-2-1-1 lasts seven unit pulses; [`REST_S`] of level flight follow each.
const SEQUENCE_S: f32 = 7.0 * PULSE_S + REST_S;

/// Width of the rudder's 3-2-1-1 unit pulse, s: half the attitude stages'. The rudder yaws
/// the aircraft for as long as it is held, and its three-unit pulse at 0.3 s (0.9 s) of 10 deg
/// swung the 25e 30-40 deg off its heading and, in light turbulence, slowed it to 13 m/s;
/// the side force it is fitted on answers the rudder at once.
pub const YAW_PULSE_S: f32 = 0.5 * PULSE_S;

/// A rudder 3-2-1-1 and the level flight after it.
const YAW_SEQUENCE_S: f32 = 7.0 * YAW_PULSE_S + REST_S;

/// Sequences flown per axis.
const SEQUENCES: f32 = 3.0;

/// Throttle held at each step, s: a few of the airspeed's time constants (`1 / a_V1`, about
/// 4 s on the 25e) would reach its steady state; a share of one is what the fit needs and
/// what keeps the height and airspeed change small.
const THROTTLE_STEP_S: f32 = 4.0;

/// The timeline, stage by stage, with each stage's length in s.
pub const TIMELINE: [(Stage, f32); 9] = [
    (Stage::Level, 3.0),
    (Stage::Roll, SEQUENCES * SEQUENCE_S),
    (Stage::Level, 3.0),
    (Stage::Pitch, SEQUENCES * SEQUENCE_S),
    (Stage::Level, 3.0),
    (Stage::Throttle, 3.0 * THROTTLE_STEP_S),
    (Stage::Level, 3.0),
    (Stage::Yaw, SEQUENCES * YAW_SEQUENCE_S),
    (Stage::Level, 2.0),
];

/// The whole timeline's length, s.
pub fn timeline_s() -> f32 {
    TIMELINE.iter().map(|(_, d)| d).sum()
}

/// Where `t_s` into the timeline falls: the stage, the time into it and the share of the
/// timeline flown; `None` once it is over.
pub fn at(t_s: f32) -> Option<(Stage, f32, f32)> {
    let mut start = 0.0;
    for (stage, length) in TIMELINE {
        if t_s < start + length {
            return Some((stage, t_s - start, t_s / timeline_s()));
        }
        start += length;
    }
    None
}

/// A 3-2-1-1 of unit height on pulses of `pulse_s`, `t_s` into it (0 after its end).
fn sequence(t_s: f32, pulse_s: f32) -> f32 {
    let k = t_s / pulse_s;
    if k < 0.0 {
        0.0
    } else if k < 3.0 {
        1.0
    } else if k < 5.0 {
        -1.0
    } else if k < 6.0 {
        1.0
    } else if k < 7.0 {
        -1.0
    } else {
        0.0
    }
}

/// The roll or pitch stage's input, of unit height, `t_s` into the stage: three 3-2-1-1s, the
/// second mirrored.
pub fn doublets(t_s: f32) -> f32 {
    sequences(t_s, PULSE_S, SEQUENCE_S)
}

/// The yaw stage's input: the same on [`YAW_PULSE_S`].
pub fn yaw_doublets(t_s: f32) -> f32 {
    sequences(t_s, YAW_PULSE_S, YAW_SEQUENCE_S)
}

/// Three 3-2-1-1s on pulses of `pulse_s`, one every `every_s`, the second mirrored.
fn sequences(t_s: f32, pulse_s: f32, every_s: f32) -> f32 {
    let n = libm::floorf(t_s / every_s);
    let sign = if n == 1.0 { -1.0 } else { 1.0 };
    if !(0.0..SEQUENCES).contains(&n) {
        return 0.0;
    }
    sign * sequence(t_s - n * every_s, pulse_s)
}

/// The throttle stage's step, of unit height, `t_s` into the stage: up, down, then back.
pub fn steps(t_s: f32) -> f32 {
    if t_s < 0.0 {
        0.0
    } else if t_s < THROTTLE_STEP_S {
        1.0
    } else if t_s < 2.0 * THROTTLE_STEP_S {
        -1.0
    } else {
        0.0
    }
}
