//! Height above the ground from a downward rangefinder, for the landing's flare.
//!
//! A rangefinder sees the ground the barometer cannot, but its failures are the ones that
//! flared landings early or not at all (PX4 issues 6456 and 9843, ArduPilot 26932): readings
//! stuck at one value, short false echoes, dropouts reported as zero or as out of range. A
//! reading is used only through every gate below, else the landing flies on the height above
//! home as without a rangefinder:
//! - in range (strictly between the sensor's limits) and of usable signal quality;
//! - the tilt (angle between the body's z axis and the vertical) under `EKF_RNG_TILT`; the
//!   slant range times cos(roll) cos(pitch) is the height on flat ground;
//! - the median of the ground's height above home by the last [`WINDOW`] consecutive usable
//!   readings (the height above home less the range's height), so a spike of up to two
//!   readings never shows, and the median does not lag a descent as a median of ranges would;
//! - that median within `EKF_RNG_GATE` of the height above home (the runway is at home's
//!   altitude): a short echo at 20 m is rejected there;
//! - not stuck: each time the height above home has moved [`STUCK_DH_M`], the range must have
//!   moved at least [`STUCK_SHARE`] of that, or the sensor is failed until it does again;
//! - fresh: the last reading through the gates within `EKF_RNG_TOUT`.
//!
//! Between readings (20 Hz) and while a reading is held through a dropout, the height above
//! ground follows the height above home: what is kept is the ground's height the last good
//! reading saw, not the range, so a held value sinks with the aircraft (a range held for
//! half a second while a gust dropped the aircraft 2 m kept the flare from starting).

use crate::param;
use crate::params::{independent, Group, ParamDef};
use crate::sensors::RangeSample;

/// Readings the median is taken over: up to `(WINDOW - 1) / 2` wild ones are outvoted.
pub const WINDOW: usize = 5;
/// Change of the height above home over which the stuck detector judges the range, m: under
/// half a second of the approach's sink, and ten times a lidar's noise (2.5 cm). A reading that
/// freezes within one such step is judged at the end of the next: failed within a metre.
pub const STUCK_DH_M: f32 = 0.5;
/// Least share of that change the range must follow to count as alive.
pub const STUCK_SHARE: f32 = 0.3;

/// Settings of the height-above-ground stage.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RangeParams {
    /// Largest tilt at which a reading is used, rad.
    pub tilt_max: f32,
    /// Largest difference from the height above home of a reading used, m.
    pub gate_m: f32,
    /// Time after the last good reading the height above ground stays valid, s.
    pub timeout_s: f32,
    /// Least signal quality used (MAVLink's 1-100; 0, unknown, is accepted).
    pub quality_min: u8,
    /// The rangefinder's height reading with the aircraft on its wheels, m: heights above
    /// ground count from there, as heights above home count from where the aircraft stood.
    pub ground_clearance_m: f32,
}

/// The rangefinder's parameters.
pub const PARAMS: Group<RangeParams> = Group {
    name: "Rangefinder",
    params: &[
        param!(
            ParamDef::real("EKF_RNG_TILT", 30.0, 0.0, 60.0, "deg", "Largest tilt of a range used"),
            RangeParams => tilt_max, unit crate::math::DEG
        ),
        param!(
            ParamDef::real("EKF_RNG_GATE", 3.0, 0.5, 50.0, "m", "Largest range-baro height difference used"),
            RangeParams => gate_m
        ),
        param!(
            ParamDef::real("EKF_RNG_TOUT", 0.5, 0.05, 5.0, "s", "Range height valid this long after a good reading"),
            RangeParams => timeout_s
        ),
        param!(
            ParamDef::int("EKF_RNG_QMIN", 10, 0, 100, "%", "Least range signal quality used"),
            RangeParams => quality_min, count
        ),
        param!(
            ParamDef::real("EKF_RNG_GND", 0.1, 0.0, 2.0, "m", "Range height reading on the wheels (as ArduPilot's RNGFND1_GNDCLEAR)"),
            RangeParams => ground_clearance_m
        ),
    ],
    base: || RangeParams {
        tilt_max: 0.0,
        gate_m: 0.0,
        timeout_s: 0.0,
        quality_min: 0,
        ground_clearance_m: 0.0,
    },
    check: independent,
};

impl Default for RangeParams {
    fn default() -> Self {
        PARAMS.defaults()
    }
}

/// The height-above-ground stage.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Hagl {
    cfg: RangeParams,
    /// The ground's height above home by each of the last readings, m.
    window: [f32; WINDOW],
    /// Consecutive usable readings in the window (at most [`WINDOW`]).
    filled: u8,
    next: u8,
    /// The height above home of the ground the last good median saw, m.
    ground_m: f32,
    last_good_us: Option<u64>,
    /// When the last reading in range came, us.
    last_usable_us: Option<u64>,
    /// The stuck detector's start: the range and the height above home then, m.
    anchor: Option<(f32, f32)>,
    stuck: bool,
    rejected: u32,
}

impl Hagl {
    /// Replaces the settings.
    pub fn set_config(&mut self, cfg: RangeParams) {
        self.cfg = cfg;
    }

    /// One reading at `t_us`, with the cosine of the tilt and the height above home (m) then.
    pub fn update(&mut self, t_us: u64, s: &RangeSample, cos_tilt: f32, height_m: f32) {
        let c = &self.cfg;
        let quality_ok = s.quality == 0 || (s.quality > 1 && s.quality >= c.quality_min);
        let usable = quality_ok
            && s.distance_m > s.min_m
            && s.distance_m < s.max_m
            && cos_tilt >= crate::math::elementary::cos(c.tilt_max)
            && height_m.is_finite();
        if !usable {
            // Not a measurement of the ground: the window starts again, so no median ever
            // mixes readings from either side of a dropout.
            self.filled = 0;
            self.anchor = None;
            return;
        }
        // After a silence longer than the timeout the window starts again too: its old readings
        // are of another height.
        let gap_s = self
            .last_usable_us
            .map_or(0.0, |t| t_us.saturating_sub(t) as f32 * 1e-6);
        if gap_s > c.timeout_s {
            self.filled = 0;
            self.anchor = None;
        }
        self.last_usable_us = Some(t_us);
        // Counted from the reading on the wheels, as the height above home is.
        let h = s.distance_m * cos_tilt - c.ground_clearance_m;
        // The window holds the ground's height above home each reading saw, not the ranges:
        // its median is then as fresh as the last reading on a descent (a median of ranges
        // lags two readings, 0.1 s at 20 Hz, and the flare started that late).
        if let Some(slot) = self.window.get_mut(usize::from(self.next)) {
            *slot = height_m - h;
        }
        self.next = (self.next + 1) % WINDOW as u8;
        self.filled = (self.filled + 1).min(WINDOW as u8);
        match self.anchor {
            Some((h0, home0)) if libm::fabsf(height_m - home0) >= STUCK_DH_M => {
                self.stuck = libm::fabsf(h - h0) < STUCK_SHARE * libm::fabsf(height_m - home0);
                self.anchor = Some((h, height_m));
            }
            Some(_) => {}
            None => self.anchor = Some((h, height_m)),
        }
        if usize::from(self.filled) < WINDOW {
            return;
        }
        let ground = median(self.window);
        // Written so that a NaN median fails the gate: the runway is at home's height.
        let consistent = libm::fabsf(ground) <= c.gate_m;
        if self.stuck || !consistent {
            self.rejected = self.rejected.saturating_add(1);
            return;
        }
        self.ground_m = ground;
        self.last_good_us = Some(t_us);
    }

    /// The height above ground at `t_us`, m, with the aircraft `height_m` above home then,
    /// while the readings pass the gates.
    pub fn value(&self, t_us: u64, height_m: f32) -> Option<f32> {
        let fresh = self
            .last_good_us
            .is_some_and(|t| t_us.saturating_sub(t) as f32 * 1e-6 <= self.cfg.timeout_s);
        Some(height_m - self.ground_m).filter(|v| fresh && !self.stuck && v.is_finite())
    }

    /// The stuck detector has failed the sensor.
    pub fn stuck(&self) -> bool {
        self.stuck
    }

    /// Readings in range that the gates (consistency, stuck) rejected.
    pub fn rejected(&self) -> u32 {
        self.rejected
    }
}

/// The median of the window: the reading with fewer than half below it and at least half at or
/// below it (no sorting, no indexing; NaN, which never enters, would fail the gate).
fn median(w: [f32; WINDOW]) -> f32 {
    let half = WINDOW / 2;
    for x in w {
        let below = w.iter().filter(|y| **y < x).count();
        let at_or_below = w.iter().filter(|y| **y <= x).count();
        if below <= half && at_or_below > half {
            return x;
        }
    }
    f32::NAN
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use std::vec::Vec;

    const PERIOD_US: u64 = 50_000;

    fn reading(d: f32) -> RangeSample {
        RangeSample {
            distance_m: d,
            min_m: 0.1,
            max_m: 40.0,
            quality: 0,
        }
    }

    /// The stage with the default gates, heights counted from the sensor itself.
    fn stage() -> Hagl {
        let mut h = Hagl::default();
        h.set_config(RangeParams {
            ground_clearance_m: 0.0,
            ..RangeParams::default()
        });
        h
    }

    /// With `EKF_RNG_GND` at its 0.1 m, the aircraft on its wheels (the sensor 0.1 m over the
    /// runway, home's height 0) is 0 m above the ground, and 0.1 m lower than the sensor
    /// anywhere else.
    #[test]
    fn heights_above_ground_count_from_the_reading_on_the_wheels() {
        let mut h = Hagl::default();
        h.set_config(RangeParams::default());
        let on_wheels = feed(&mut h, 0, 5, |_| 0.1 + 1e-3, |_| 0.0);
        let v = on_wheels[4].expect("valid");
        assert!(libm::fabsf(v - 1e-3) < 1e-6, "{v}");
        let up = feed(&mut h, 5, 5, |_| 10.1, |_| 10.0);
        let v = up[4].expect("valid");
        assert!(libm::fabsf(v - 10.0) < 1e-5, "{v}");
    }

    /// Feeds `n` readings at 20 Hz from `k0`: the range from `range(k)`, the height above home
    /// from `home(k)`, level.
    fn feed(
        h: &mut Hagl,
        k0: u64,
        n: u64,
        range: impl Fn(u64) -> f32,
        home: impl Fn(u64) -> f32,
    ) -> Vec<Option<f32>> {
        (k0..k0 + n)
            .map(|k| {
                h.update(k * PERIOD_US, &reading(range(k)), 1.0, home(k));
                h.value(k * PERIOD_US, home(k))
            })
            .collect()
    }

    #[test]
    fn a_healthy_reading_validates_after_five_and_is_tilt_compensated() {
        let mut h = stage();
        let out = feed(&mut h, 0, 5, |_| 10.0, |_| 10.5);
        assert_eq!(&out[..4], &[None; 4]);
        assert_eq!(out[4], Some(10.0));
        // 20 deg of bank and 10 deg of pitch: the slant range is h / (cos phi cos theta).
        let c = libm::cosf(20f32.to_radians()) * libm::cosf(10f32.to_radians());
        for k in 5..10 {
            h.update(k * PERIOD_US, &reading(8.0 / c), c, 8.0);
        }
        let v = h.value(9 * PERIOD_US, 8.0).unwrap();
        assert!((v - 8.0).abs() < 1e-4, "{v}");
        // 40 deg of bank is beyond the 30 deg limit: the reading is not used.
        let c40 = libm::cosf(40f32.to_radians());
        h.update(10 * PERIOD_US, &reading(8.0 / c40), c40, 8.0);
        assert_eq!(
            h.value(21 * PERIOD_US, 8.0),
            None,
            "times out 0.5 s after the last good reading"
        );
    }

    /// Sinking at 1.5 m/s from 6 m with exact readings at 20 Hz, the height above ground is
    /// the true height at every reading once valid: a median of the ranges themselves would
    /// read two readings (0.15 m) high.
    #[test]
    fn on_a_descent_the_height_above_ground_does_not_lag() {
        let mut h = stage();
        let height = |k: u64| 6.0 - 1.5 * k as f32 * 0.05;
        let out = feed(&mut h, 0, 30, height, height);
        for (k, v) in out.iter().enumerate().skip(4) {
            let v = v.expect("valid");
            let truth = height(k as u64);
            assert!(
                libm::fabsf(v - truth) < 1e-4,
                "reading {k}: {v} for {truth}"
            );
        }
    }

    #[test]
    fn a_spike_of_two_frames_is_rejected() {
        let mut h = stage();
        feed(&mut h, 0, 10, |_| 10.0, |_| 10.0);
        let out = feed(&mut h, 10, 5, |k| if k < 12 { 1.0 } else { 10.0 }, |_| 10.0);
        assert!(out.iter().all(|v| *v == Some(10.0)), "{out:?}");
    }

    #[test]
    fn a_short_false_reading_at_20_m_does_not_validate() {
        let mut h = stage();
        // A steady 1 m echo (grass, rain, a reflection) at 20 m above home, level flight.
        let out = feed(&mut h, 0, 100, |k| 1.0 + 0.01 * (k % 3) as f32, |_| 20.0);
        assert!(out.iter().all(Option::is_none));
        assert!(h.rejected() >= 90, "{}", h.rejected());
    }

    #[test]
    fn a_stuck_reading_is_failed_within_a_metre_of_descent_and_recovers_when_it_follows() {
        let mut h = stage();
        // Descending at 1.2 m/s from 6 m with a good sensor.
        let home = |k: u64| 6.0 - 1.2 * k as f32 * 0.05;
        let out = feed(&mut h, 0, 10, home, home);
        assert!(out[9].is_some());
        // Frozen at 5.4 m from reading 10 on: within the 3 m gate for another 2.5 s.
        let out = feed(&mut h, 10, 40, |_| 5.4, home);
        let failed_at = out.iter().position(Option::is_none).expect("failed");
        // Frozen 0.06 m into a half-metre step, it is judged at the end of the next one: 0.54 m
        // of descent at 1.2 m/s, 0.45 s, 9 readings at 20 Hz (at worst a metre, 17 readings).
        assert_eq!(failed_at, 8, "failed after {} readings", failed_at + 1);
        assert!(h.stuck());
        assert!(out[failed_at..].iter().all(Option::is_none));
        // Alive again: following the height over the next metre clears it.
        let out = feed(
            &mut h,
            50,
            20,
            |k| 6.0 - 0.06 * (k - 50) as f32,
            |k| 6.0 - 0.06 * (k - 50) as f32,
        );
        assert!(!h.stuck() && out[19].is_some(), "{out:?}");
    }

    #[test]
    fn dropouts_time_out_and_zero_or_out_of_range_readings_are_not_used() {
        let mut h = stage();
        feed(&mut h, 0, 10, |_| 3.0, |_| 3.0);
        assert_eq!(h.value(9 * PERIOD_US, 3.0), Some(3.0));
        // Silence: valid for EKF_RNG_TOUT (0.5 s), then not; held meanwhile as the ground's
        // height, so it follows the height above home (2 m lower: 1 m over the ground).
        assert_eq!(h.value(19 * PERIOD_US, 1.0), Some(1.0));
        assert_eq!(h.value(20 * PERIOD_US + 1, 3.0), None);
        // Readings at the minimum (a lost echo some drivers report as 0) and above the maximum
        // (PX4's max + 1 cm) never validate, nor do readings of invalid quality.
        let mut h = stage();
        let out = feed(
            &mut h,
            0,
            20,
            |k| if k % 2 == 0 { 0.1 } else { 40.01 },
            |_| 0.5,
        );
        assert!(out.iter().all(Option::is_none));
        for k in 0..10 {
            let s = RangeSample {
                quality: 1,
                ..reading(3.0)
            };
            h.update(k * PERIOD_US, &s, 1.0, 3.0);
        }
        assert_eq!(h.value(9 * PERIOD_US, 3.0), None);
        // Non-finite inputs are not used either.
        h.update(0, &reading(f32::NAN), 1.0, 3.0);
        h.update(0, &reading(3.0), f32::NAN, 3.0);
        h.update(0, &reading(3.0), 1.0, f32::NAN);
        assert_eq!(h.value(0, 3.0), None);
        assert_eq!(h.value(9 * PERIOD_US, f32::NAN), None);
    }
}
