//! Each sensor's health as the estimator judges it: samples accepted, rejected by the
//! innovation gates, and silence.

/// Health and bookkeeping of one sensor.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SensorStatus {
    /// A good sample arrived within the timeout and fewer than `EST_MAX_REJECT` in a row were
    /// rejected.
    pub healthy: bool,
    /// Samples refused as non-finite or out of range.
    pub rejected: u32,
    /// Samples (or components) refused by the filters' innovation gates.
    pub gated: u32,
    /// Times the filter part this sensor corrects was restarted after a lock-out.
    pub resets: u32,
    consecutive: u32,
    gated_streak: u32,
    last_ok_us: Option<u64>,
}

impl SensorStatus {
    pub(super) fn reject(&mut self) {
        self.rejected = self.rejected.saturating_add(1);
        self.consecutive = self.consecutive.saturating_add(1);
    }

    pub(super) fn accept(&mut self, t_us: u64) {
        self.consecutive = 0;
        self.last_ok_us = Some(t_us);
    }

    /// Books `gated` refused components of a sample; `all` when none was fused. Returns true
    /// when the sensor has been locked out for `limit` samples in a row (and starts over).
    pub(super) fn gate(&mut self, gated: u8, all: bool, limit: u32) -> bool {
        self.gated = self.gated.saturating_add(u32::from(gated));
        if !all {
            self.gated_streak = 0;
            return false;
        }
        self.gated_streak = self.gated_streak.saturating_add(1);
        if self.gated_streak >= limit {
            self.gated_streak = 0;
            self.resets = self.resets.saturating_add(1);
            return true;
        }
        false
    }

    /// Judges the sensor at time `t_us` (µs): healthy while its last good sample is at most
    /// `timeout` s old and fewer than `max_rejections` in a row were refused.
    pub(super) fn evaluate(&mut self, t_us: u64, timeout: f32, max_rejections: u32) {
        self.healthy = match self.last_ok_us {
            // Compared in µs (exact up to 16.7 s; an infinite timeout stays infinite).
            Some(last) => {
                micros_f32(t_us.saturating_sub(last)) <= timeout * 1e6
                    && self.consecutive < max_rejections
            }
            None => false,
        };
    }
}

/// Health of every sensor.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SensorHealth {
    /// Accelerometer and gyro.
    pub imu: SensorStatus,
    /// Magnetometer.
    pub mag: SensorStatus,
    /// Static pressure (and temperature).
    pub baro: SensorStatus,
    /// Differential pressure.
    pub pitot: SensorStatus,
    /// GPS (a 3D fix counts as a good sample).
    pub gps: SensorStatus,
}

/// A duration in microseconds as an `f32` count of them, saturating at 71 minutes (beyond any
/// timeout): through `u32`, so that the conversion is the FPU's, not a software u64 one.
pub(super) fn micros_f32(us: u64) -> f32 {
    u32::try_from(us).unwrap_or(u32::MAX) as f32
}
