//! Flight modes as the link encodes them.
//!
//! Ground stations decode the heartbeat's `custom_mode` of any non-ArduPilot vehicle with
//! PX4's layout: `custom_mode = (main_mode << 16) | (sub_mode << 24)`. The standard-modes
//! microservice (`AVAILABLE_MODES`, `CURRENT_MODE`, `MAV_CMD_DO_SET_STANDARD_MODE`) adds an
//! autopilot-neutral number for the modes that have one.

pub use crate::vehicle::modes::{FlightMode, ModeSet};
use mavlink::dialects::common::{MavModeProperty, MavStandardMode};

/// PX4 main mode numbers (`custom_mode` bits 16..23).
pub mod px4_main {
    /// Manual pass-through.
    pub const MANUAL: u8 = 1;
    /// Altitude control.
    pub const ALTCTL: u8 = 2;
    /// Position control.
    pub const POSCTL: u8 = 3;
    /// Automatic; the sub mode says which.
    pub const AUTO: u8 = 4;
    /// Rate control (not flown by this autopilot).
    pub const ACRO: u8 = 5;
    /// Offboard setpoints (not flown by this autopilot).
    pub const OFFBOARD: u8 = 6;
    /// Attitude stabilised.
    pub const STABILIZED: u8 = 7;
}

/// PX4 AUTO sub mode numbers (`custom_mode` bits 24..31).
pub mod px4_auto {
    /// Armed on the ground, waiting.
    pub const READY: u8 = 1;
    /// Take-off.
    pub const TAKEOFF: u8 = 2;
    /// Loiter (hold) around the current point.
    pub const LOITER: u8 = 3;
    /// Fly the mission.
    pub const MISSION: u8 = 4;
    /// Return to launch.
    pub const RTL: u8 = 5;
    /// Land.
    pub const LAND: u8 = 6;
}

impl FlightMode {
    /// PX4 (main, sub) mode numbers.
    pub const fn px4(self) -> (u8, u8) {
        match self {
            FlightMode::Manual => (px4_main::MANUAL, 0),
            FlightMode::Stabilized => (px4_main::STABILIZED, 0),
            FlightMode::Altitude => (px4_main::ALTCTL, 0),
            FlightMode::Hold => (px4_main::POSCTL, 0),
            FlightMode::Mission => (px4_main::AUTO, px4_auto::MISSION),
            FlightMode::Loiter => (px4_main::AUTO, px4_auto::LOITER),
            FlightMode::Return => (px4_main::AUTO, px4_auto::RTL),
            FlightMode::Takeoff => (px4_main::AUTO, px4_auto::TAKEOFF),
            FlightMode::Land => (px4_main::AUTO, px4_auto::LAND),
        }
    }

    /// The heartbeat's `custom_mode` in PX4's encoding.
    pub const fn custom_mode(self) -> u32 {
        let (main, sub) = self.px4();
        ((main as u32) << 16) | ((sub as u32) << 24)
    }

    /// The mode a PX4 (main, sub) pair names, if this autopilot flies it.
    pub fn from_px4(main: u8, sub: u8) -> Option<Self> {
        match (main, sub) {
            (px4_main::MANUAL, 0) => Some(FlightMode::Manual),
            (px4_main::STABILIZED, 0) => Some(FlightMode::Stabilized),
            (px4_main::ALTCTL, 0) => Some(FlightMode::Altitude),
            (px4_main::POSCTL, 0) => Some(FlightMode::Hold),
            (px4_main::AUTO, px4_auto::MISSION) => Some(FlightMode::Mission),
            (px4_main::AUTO, px4_auto::LOITER) => Some(FlightMode::Loiter),
            (px4_main::AUTO, px4_auto::RTL) => Some(FlightMode::Return),
            (px4_main::AUTO, px4_auto::TAKEOFF) => Some(FlightMode::Takeoff),
            (px4_main::AUTO, px4_auto::LAND) => Some(FlightMode::Land),
            _ => None,
        }
    }

    /// The mode a `custom_mode` word names (PX4 encoding), if this autopilot flies it. The
    /// low 16 bits are unused by the encoding and must be zero.
    pub fn from_custom_mode(custom_mode: u32) -> Option<Self> {
        if custom_mode & 0xffff != 0 {
            return None;
        }
        let main = ((custom_mode >> 16) & 0xff) as u8;
        let sub = ((custom_mode >> 24) & 0xff) as u8;
        Self::from_px4(main, sub)
    }

    /// The standard-modes number, `NON_STANDARD` for modes the standard does not name.
    pub const fn standard(self) -> MavStandardMode {
        match self {
            FlightMode::Manual | FlightMode::Stabilized => {
                MavStandardMode::MAV_STANDARD_MODE_NON_STANDARD
            }
            FlightMode::Altitude => MavStandardMode::MAV_STANDARD_MODE_ALTITUDE_HOLD,
            // The standard reserves POSITION_HOLD for vehicles that can stop; a fixed wing
            // holding its track and altitude is CRUISE.
            FlightMode::Hold => MavStandardMode::MAV_STANDARD_MODE_CRUISE,
            // The standard's ORBIT is a manual, stick-adjusted orbit, and QGroundControl never
            // offers it in its mode menu; PX4 reports its fixed-wing Hold (this Loiter) as
            // non-standard too and takes ORBIT only as an alias (`from_standard`).
            FlightMode::Loiter => MavStandardMode::MAV_STANDARD_MODE_NON_STANDARD,
            FlightMode::Return => MavStandardMode::MAV_STANDARD_MODE_SAFE_RECOVERY,
            FlightMode::Mission => MavStandardMode::MAV_STANDARD_MODE_MISSION,
            FlightMode::Land => MavStandardMode::MAV_STANDARD_MODE_LAND,
            FlightMode::Takeoff => MavStandardMode::MAV_STANDARD_MODE_TAKEOFF,
        }
    }

    /// The mode a standard-mode number names, if this autopilot flies it. ORBIT, which
    /// no mode advertises, is taken as Loiter, as PX4 takes it for its fixed-wing Hold.
    pub fn from_standard(mode: MavStandardMode) -> Option<Self> {
        match mode {
            MavStandardMode::MAV_STANDARD_MODE_NON_STANDARD => None,
            MavStandardMode::MAV_STANDARD_MODE_ORBIT => Some(FlightMode::Loiter),
            _ => Self::ALL.iter().copied().find(|m| m.standard() == mode),
        }
    }

    /// The mode `MAV_CMD_DO_SET_MODE`'s `param2` and `param3` name. Two forms arrive: PX4's,
    /// main mode in `param2` and sub mode in `param3` (MAVSDK, PX4's tools), and the whole
    /// `custom_mode` word in `param2` with `param3` zero (QGroundControl's APM-style command,
    /// pymavlink and MAVProxy with a custom mode map). They cannot be confused: a main mode
    /// is below 256 and a whole word of this encoding is at least 65536. `Err` carries the
    /// word asked for, for the refusal; values that are not whole numbers in range are
    /// refused as word 0.
    pub fn from_set_mode_params(param2: f32, param3: f32) -> Result<Self, u32> {
        let whole = |x: f32, max: f32| {
            (x.is_finite() && x >= 0.0 && x <= max && libm::truncf(x) == x).then_some(x as u32)
        };
        let word = match (whole(param2, u32::MAX as f32), whole(param3, 255.0)) {
            (Some(w), Some(0)) if w >= 1 << 16 => w,
            (Some(main), Some(sub)) if main < 256 => (main << 16) | (sub << 24),
            _ => return Err(0),
        };
        Self::from_custom_mode(word).ok_or(word)
    }

    /// `AVAILABLE_MODES.properties`.
    pub fn properties(self) -> MavModeProperty {
        match self {
            FlightMode::Manual | FlightMode::Stabilized | FlightMode::Altitude => {
                MavModeProperty::empty()
            }
            FlightMode::Hold => MavModeProperty::empty(),
            _ => MavModeProperty::MAV_MODE_PROPERTY_AUTO_MODE,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn px4_encoding_matches_px4_numbers() {
        // Values a PX4 vehicle puts in its heartbeat (main << 16 | sub << 24).
        assert_eq!(FlightMode::Manual.custom_mode(), 0x0001_0000);
        assert_eq!(FlightMode::Altitude.custom_mode(), 0x0002_0000);
        assert_eq!(FlightMode::Hold.custom_mode(), 0x0003_0000);
        assert_eq!(FlightMode::Stabilized.custom_mode(), 0x0007_0000);
        assert_eq!(FlightMode::Takeoff.custom_mode(), 0x0204_0000);
        assert_eq!(FlightMode::Loiter.custom_mode(), 0x0304_0000);
        assert_eq!(FlightMode::Mission.custom_mode(), 0x0404_0000);
        assert_eq!(FlightMode::Return.custom_mode(), 0x0504_0000);
        assert_eq!(FlightMode::Land.custom_mode(), 0x0604_0000);
        for m in FlightMode::ALL {
            assert_eq!(FlightMode::from_custom_mode(m.custom_mode()), Some(m));
        }
        assert_eq!(FlightMode::from_px4(px4_main::ACRO, 0), None);
        assert_eq!(FlightMode::from_px4(px4_main::AUTO, px4_auto::READY), None);
    }

    #[test]
    fn standard_modes_round_trip() {
        for m in FlightMode::ALL {
            if m.standard() != MavStandardMode::MAV_STANDARD_MODE_NON_STANDARD {
                assert_eq!(FlightMode::from_standard(m.standard()), Some(m));
            }
        }
        // Loiter is advertised as non-standard, ORBIT still reaches it.
        assert_eq!(
            FlightMode::Loiter.standard(),
            MavStandardMode::MAV_STANDARD_MODE_NON_STANDARD
        );
        assert_eq!(
            FlightMode::from_standard(MavStandardMode::MAV_STANDARD_MODE_ORBIT),
            Some(FlightMode::Loiter)
        );
        assert_eq!(
            FlightMode::from_standard(MavStandardMode::MAV_STANDARD_MODE_POSITION_HOLD),
            None
        );
        assert!(ModeSet::ALL.contains(FlightMode::Land));
    }

    #[test]
    fn set_mode_takes_px4_pairs_and_whole_words_and_refuses_the_rest() {
        for m in FlightMode::ALL {
            let (main, sub) = m.px4();
            assert_eq!(
                FlightMode::from_set_mode_params(f32::from(main), f32::from(sub)),
                Ok(m)
            );
            // Every word of this encoding is exact in an f32 (at most 8 significant bits).
            assert_eq!(
                FlightMode::from_set_mode_params(m.custom_mode() as f32, 0.0),
                Ok(m)
            );
        }
        // AUTO without a sub mode, ACRO, a word with low bits, a fraction, NaN, negatives.
        assert_eq!(FlightMode::from_set_mode_params(4.0, 0.0), Err(0x0004_0000));
        assert_eq!(FlightMode::from_set_mode_params(5.0, 0.0), Err(0x0005_0000));
        assert_eq!(FlightMode::from_set_mode_params(65537.0, 0.0), Err(65537));
        assert_eq!(FlightMode::from_set_mode_params(1.5, 0.0), Err(0));
        assert_eq!(FlightMode::from_set_mode_params(f32::NAN, 0.0), Err(0));
        assert_eq!(FlightMode::from_set_mode_params(-1.0, 0.0), Err(0));
        assert_eq!(FlightMode::from_set_mode_params(4.0, 256.0), Err(0));
        // ArduPlane numbers sent by pymavlink without a mode map are PX4 pairs, taken as such:
        // LOITER (12) names no PX4 main mode.
        assert_eq!(
            FlightMode::from_set_mode_params(12.0, 0.0),
            Err(0x000c_0000)
        );
        assert!(!ModeSet::WITHOUT_POSITION.contains(FlightMode::Mission));
    }
}
