//! The logger's parameters: when a flight log is written (PX4's `SDLOG_MODE`) and what it
//! takes in (PX4's `SDLOG_PROFILE`).

use crate::param;
use crate::params::{independent, Group, ParamDef};

/// When the board writes a log.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LogParams {
    /// `SDLOG_MODE`: -1 never, 0 from arming to disarming, 1 from boot to the first disarming
    /// (later flights from arming), PX4's numbers.
    pub mode: i8,
    /// `SDLOG_PROFILE`: PX4's bits; 3 (system identification) and 4 (high rate) log the
    /// identification's topics at every sensor frame.
    pub profile: u8,
}

/// `SDLOG_PROFILE`'s bits that ask for the identification's topics at every sensor frame:
/// PX4's 3 (system identification) and 4 (high rate).
pub const PROFILE_HIGH_RATE: u8 = 0b1_1000;

impl LogParams {
    /// Whether a log starts now: `armed`, or from boot when no log has started yet.
    pub fn starts(&self, armed: bool, logs_started: u32) -> bool {
        match self.mode {
            0 => armed,
            1 => armed || logs_started == 0,
            _ => false,
        }
    }
}

/// The logger's parameters.
pub const PARAMS: Group<LogParams> = Group {
    name: "Logger",
    params: &[
        param!(
            ParamDef::int(
                "SDLOG_MODE",
                0,
                -1,
                1,
                "",
                "When the flight log is written: -1 never, 0 from arming to disarming, 1 from boot until the first disarming (then each flight from arming)",
            ),
            LogParams => mode,
            count
        ),
        param!(
            ParamDef::int(
                "SDLOG_PROFILE",
                1,
                0,
                255,
                "",
                "What the flight log takes in, PX4's bits: 3 (system identification) or 4 (high rate) log the attitude, rates, accelerations, surfaces, velocity and airspeed at every sensor frame (100 Hz, under a board's own cap), what `sim-host identify` fits the aircraft's models from; the other bits change nothing here",
            ),
            LogParams => profile,
            count
        ),
    ],
    base: || LogParams {
        mode: 0,
        profile: 1,
    },
    check: independent,
};

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_mode_starts_a_log_when_px4s_does() {
        let at = |mode| LogParams { mode, profile: 1 };
        // Never.
        assert!(!at(-1).starts(true, 0));
        // Arming to disarming.
        assert!(!at(0).starts(false, 0) && at(0).starts(true, 3));
        // From boot (no log yet), then each arming.
        assert!(at(1).starts(false, 0) && !at(1).starts(false, 1) && at(1).starts(true, 1));
    }
}
