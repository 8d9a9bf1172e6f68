//! The vehicle's clock. Its time comes from the sensor frames' timestamps, which come from
//! outside (the simulator, or a driver's timer): they are data, not truth.
//!
//! The clock follows them monotonically. A frame's step from the last accepted one is taken
//! when it is forward and at most [`MAX_STEP_US`]; a frame at the same time or a little
//! older is stale (its samples may still be used, but time does not move); any larger jump,
//! forward or back, is refused and counted. When [`RESYNC_FRAMES`] frames in a row follow each
//! other regularly in a new time base (a simulator that restarted, a driver timer that
//! wrapped), the clock adopts that base and carries on from where it was, so nothing that
//! runs on it ever sees time jump or go back. A frame flagged as a reset re-synchronises at
//! once. The clock itself starts at the first frame's time when that is plausible (under a
//! day), otherwise at zero; after that only bounded steps are ever added.

// Timestamps come from outside: no operation on them may wrap or panic.
#![cfg_attr(not(test), deny(clippy::arithmetic_side_effects))]

/// Largest step between two frames taken as time passing, us (sensor frames come every 10 ms;
/// a scheduling hiccup of a few hundred milliseconds is still a step).
pub const MAX_STEP_US: u64 = 500_000;
/// Regular frames in a new time base after which the clock adopts it.
pub const RESYNC_FRAMES: u8 = 5;
/// Largest first timestamp taken as the clock's start, us (one day).
pub const MAX_START_US: u64 = 86_400_000_000;

/// What one frame's timestamp did to the clock.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Step {
    /// The first frame: the clock starts.
    Started,
    /// Time moved forward by this many microseconds.
    Advanced(u64),
    /// The same time as the last frame, or a little older: time does not move.
    Stale,
    /// A jump beyond [`MAX_STEP_US`]: refused, the frame is not used.
    Refused,
    /// A new time base taken (after [`RESYNC_FRAMES`] regular frames, or a reset flag): time
    /// does not move on this frame.
    Resynced,
}

/// Counters of what the clock refused.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ClockStats {
    /// Frames at the same time or a little older than the last.
    pub stale: u32,
    /// Frames refused for a jump.
    pub refused: u32,
    /// New time bases taken.
    pub resyncs: u32,
}

/// The clock.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Clock {
    now_us: Option<u64>,
    /// The last accepted frame's own timestamp.
    last_raw: u64,
    /// A new time base seen lately: its last timestamp and how many regular frames it had.
    candidate: Option<(u64, u8)>,
    stats: ClockStats,
}

impl Clock {
    /// The vehicle's time, us; `None` before the first frame.
    pub fn now_us(&self) -> Option<u64> {
        self.now_us
    }

    /// What the clock refused so far.
    pub fn stats(&self) -> ClockStats {
        self.stats
    }

    /// A frame stamped `raw` (us, the source's own time base); `reset` when the source says
    /// it restarted.
    pub fn on_frame(&mut self, raw: u64, reset: bool) -> Step {
        let Some(now) = self.now_us else {
            self.now_us = Some(if raw <= MAX_START_US { raw } else { 0 });
            self.last_raw = raw;
            return Step::Started;
        };
        if reset {
            return self.resync(raw);
        }
        match raw.checked_sub(self.last_raw) {
            Some(dt) if dt > 0 && dt <= MAX_STEP_US => {
                self.now_us = Some(now.saturating_add(dt));
                self.last_raw = raw;
                self.candidate = None;
                Step::Advanced(dt)
            }
            Some(0) => self.stale(),
            None if self.last_raw.saturating_sub(raw) <= MAX_STEP_US => self.stale(),
            _ => self.jump(raw),
        }
    }

    fn stale(&mut self) -> Step {
        self.stats.stale = self.stats.stale.saturating_add(1);
        Step::Stale
    }

    fn jump(&mut self, raw: u64) -> Step {
        let regular = |last: u64| {
            raw.checked_sub(last)
                .is_some_and(|d| d > 0 && d <= MAX_STEP_US)
        };
        let count = match self.candidate {
            Some((last, n)) if regular(last) => n.saturating_add(1),
            _ => 1,
        };
        if count >= RESYNC_FRAMES {
            return self.resync(raw);
        }
        self.candidate = Some((raw, count));
        self.stats.refused = self.stats.refused.saturating_add(1);
        Step::Refused
    }

    fn resync(&mut self, raw: u64) -> Step {
        self.last_raw = raw;
        self.candidate = None;
        self.stats.resyncs = self.stats.resyncs.saturating_add(1);
        Step::Resynced
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(c: &mut Clock, raws: impl IntoIterator<Item = u64>) -> std::vec::Vec<Step> {
        raws.into_iter().map(|t| c.on_frame(t, false)).collect()
    }
    extern crate std;

    #[test]
    fn regular_frames_advance_the_clock_by_their_steps() {
        let mut c = Clock::default();
        assert_eq!(c.now_us(), None);
        let s = run(&mut c, [1_000, 11_000, 21_000]);
        assert_eq!(
            s,
            [
                Step::Started,
                Step::Advanced(10_000),
                Step::Advanced(10_000)
            ]
        );
        assert_eq!(c.now_us(), Some(21_000));
    }

    #[test]
    fn one_frame_from_the_far_future_is_refused_and_time_goes_on() {
        let mut c = Clock::default();
        run(&mut c, [0, 10_000]);
        assert_eq!(c.on_frame(1 << 62, false), Step::Refused);
        assert_eq!(c.on_frame(u64::MAX, false), Step::Refused);
        assert_eq!(c.on_frame(20_000, false), Step::Advanced(10_000));
        assert_eq!(c.now_us(), Some(20_000));
        assert_eq!(c.stats().refused, 2);
    }

    #[test]
    fn three_seconds_backwards_costs_five_frames_not_three_seconds() {
        let mut c = Clock::default();
        run(&mut c, (0..=400).map(|k| k * 10_000));
        let before = c.now_us().unwrap();
        // The source restarts 3 s earlier and carries on regularly from there.
        let back = run(&mut c, (0..6).map(|k| 1_000_000 + k * 10_000));
        assert_eq!(&back[..4], &[Step::Refused; 4]);
        assert_eq!(back[4], Step::Resynced);
        assert_eq!(back[5], Step::Advanced(10_000));
        // No time was lost or invented: only the adopted frame's step.
        assert_eq!(c.now_us(), Some(before + 10_000));
    }

    #[test]
    fn a_first_frame_beyond_a_day_starts_the_clock_at_zero() {
        let mut c = Clock::default();
        assert_eq!(c.on_frame(u64::MAX - 5, false), Step::Started);
        assert_eq!(c.now_us(), Some(0));
        // Its successors advance normally; the raw time never enters the clock's sum.
        assert_eq!(c.on_frame(u64::MAX, false), Step::Advanced(5));
        assert_eq!(c.now_us(), Some(5));
    }

    #[test]
    fn a_reset_flag_takes_the_new_base_at_once() {
        let mut c = Clock::default();
        run(&mut c, [5_000_000, 5_010_000]);
        assert_eq!(c.on_frame(0, true), Step::Resynced);
        assert_eq!(c.on_frame(10_000, false), Step::Advanced(10_000));
        assert_eq!(c.now_us(), Some(5_020_000));
    }

    #[test]
    fn a_repeated_or_slightly_older_frame_is_stale() {
        let mut c = Clock::default();
        run(&mut c, [0, 10_000]);
        assert_eq!(c.on_frame(10_000, false), Step::Stale);
        assert_eq!(c.on_frame(5_000, false), Step::Stale);
        assert_eq!(c.stats().stale, 2);
        assert_eq!(c.now_us(), Some(10_000));
    }
}
