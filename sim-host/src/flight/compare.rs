//! Two flights' answers compared frame by frame: the HIL_ACTUATOR_CONTROLS of two `.tlog`s
//! (the MCU image in QEMU against the host build, for the same seed), bit for bit.

use crate::link::tlog::read_tlog;
use common::gcs::{COMPONENT_ID, SYSTEM_ID};
use common::link::framing::FrameParser;
use mavlink::dialects::common::MavMessage;
use serde::Serialize;

/// Controls compared: roll, pitch, yaw, throttle (the rest are unused).
pub const CONTROLS: usize = 4;

/// One HIL_ACTUATOR_CONTROLS of the autopilot.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Answer {
    /// The sensor frame it answers, us.
    pub time_us: u64,
    /// Roll, pitch, yaw (-1..1) and throttle (0..1), PX4's sense.
    pub controls: [f32; CONTROLS],
    /// MAV_MODE flags (128: armed).
    pub mode: u8,
    /// Flags (bit 0: lock-step).
    pub flags: u64,
}

/// The autopilot's answers in a `.tlog`, in order (frames of the autopilot's system and
/// component, [`SYSTEM_ID`] and [`COMPONENT_ID`]).
pub fn answers(tlog: &[u8]) -> Vec<Answer> {
    let mut parser = FrameParser::new();
    let mut out = Vec::new();
    for (_, frame) in read_tlog(tlog) {
        parser.push(&frame, |f| {
            if let MavMessage::HIL_ACTUATOR_CONTROLS(d) = f.message {
                if (f.header.system_id, f.header.component_id)
                    == (u32::from(SYSTEM_ID), COMPONENT_ID)
                {
                    let mut controls = [0.0; CONTROLS];
                    controls.copy_from_slice(&d.controls[..CONTROLS]);
                    out.push(Answer {
                        time_us: d.time_usec,
                        controls,
                        mode: d.mode.bits(),
                        flags: d.flags.bits(),
                    });
                }
            }
        });
    }
    out
}

/// Where two flights' answers first part.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct FirstDifference {
    /// Index of the answer (0: the first sensor frame).
    pub frame: usize,
    /// Its sensor frame's time, s.
    pub time_s: f64,
    /// The control that differs (0 roll, 1 pitch, 2 yaw, 3 throttle), `None` when the times,
    /// the mode or the flags differ.
    pub control: Option<usize>,
    /// Its value in the first flight.
    pub a: f32,
    /// Its value in the second.
    pub b: f32,
}

/// Two flights' answers compared.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct AnswerComparison {
    /// Answers in the first flight.
    pub frames_a: usize,
    /// Answers in the second.
    pub frames_b: usize,
    /// Answers compared (the shorter flight's).
    pub compared: usize,
    /// Answers equal bit for bit (time, mode, flags, the four controls) from the first on.
    pub identical_frames: usize,
    /// The first answer that differs.
    pub first_difference: Option<FirstDifference>,
    /// Largest |a - b| of each control over the compared answers.
    pub max_abs_diff: [f64; CONTROLS],
}

impl AnswerComparison {
    /// Bit for bit the same over every compared answer.
    pub fn identical(&self) -> bool {
        self.first_difference.is_none()
    }
}

/// Compares `a` with `b` answer by answer.
pub fn compare_answers(a: &[Answer], b: &[Answer]) -> AnswerComparison {
    let compared = a.len().min(b.len());
    let mut first_difference = None;
    let mut max_abs_diff = [0.0f64; CONTROLS];
    for (i, (x, y)) in a.iter().zip(b).enumerate() {
        for (c, m) in max_abs_diff.iter_mut().enumerate() {
            *m = m.max((f64::from(x.controls[c]) - f64::from(y.controls[c])).abs());
        }
        if first_difference.is_some() {
            continue;
        }
        let control = (0..CONTROLS).find(|&c| x.controls[c].to_bits() != y.controls[c].to_bits());
        let other = x.time_us != y.time_us || x.mode != y.mode || x.flags != y.flags;
        if control.is_some() || other {
            first_difference = Some(FirstDifference {
                frame: i,
                time_s: x.time_us as f64 * 1e-6,
                control,
                a: control.map_or(f32::NAN, |c| x.controls[c]),
                b: control.map_or(f32::NAN, |c| y.controls[c]),
            });
        }
    }
    AnswerComparison {
        frames_a: a.len(),
        frames_b: b.len(),
        compared,
        identical_frames: first_difference.map_or(compared, |d| d.frame),
        first_difference,
        max_abs_diff,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn answer(k: u64, roll: f32) -> Answer {
        Answer {
            time_us: k * 10_000,
            controls: [roll, 0.1, 0.0, 0.5],
            mode: 128,
            flags: 1,
        }
    }

    #[test]
    fn the_first_differing_bit_names_its_frame_and_control() {
        let a: Vec<Answer> = (0..10).map(|k| answer(k, 0.25)).collect();
        let mut b = a.clone();
        b[7].controls[0] = f32::from_bits(0.25f32.to_bits() + 1);
        b[8].controls[0] = 0.5;
        let c = compare_answers(&a, &b);
        assert_eq!(c.identical_frames, 7);
        let d = c.first_difference.expect("a difference");
        assert_eq!((d.frame, d.control), (7, Some(0)));
        assert!((d.time_s - 0.07).abs() < 1e-12);
        assert_eq!(c.max_abs_diff[0], 0.25);
        assert!(compare_answers(&a, &a).identical());
    }
}
