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
            (px4_main::MANUAL, _) => Some(FlightMode::Manual),
            (px4_main::STABILIZED, _) => Some(FlightMode::Stabilized),
            (px4_main::ALTCTL, _) => Some(FlightMode::Altitude),
            (px4_main::POSCTL, _) => Some(FlightMode::Hold),
            (px4_main::AUTO, px4_auto::MISSION) => Some(FlightMode::Mission),
            (px4_main::AUTO, px4_auto::LOITER) => Some(FlightMode::Loiter),
            (px4_main::AUTO, px4_auto::RTL) => Some(FlightMode::Return),
            (px4_main::AUTO, px4_auto::TAKEOFF) => Some(FlightMode::Takeoff),
            (px4_main::AUTO, px4_auto::LAND) => Some(FlightMode::Land),
            _ => None,
        }
    }

    /// The mode a `custom_mode` word names (PX4 encoding), if this autopilot flies it.
    pub fn from_custom_mode(custom_mode: u32) -> Option<Self> {
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
            FlightMode::Loiter => MavStandardMode::MAV_STANDARD_MODE_ORBIT,
            FlightMode::Return => MavStandardMode::MAV_STANDARD_MODE_SAFE_RECOVERY,
            FlightMode::Mission => MavStandardMode::MAV_STANDARD_MODE_MISSION,
            FlightMode::Land => MavStandardMode::MAV_STANDARD_MODE_LAND,
            FlightMode::Takeoff => MavStandardMode::MAV_STANDARD_MODE_TAKEOFF,
        }
    }

    /// The mode a standard-mode number names, if this autopilot flies it.
    pub fn from_standard(mode: MavStandardMode) -> Option<Self> {
        if mode == MavStandardMode::MAV_STANDARD_MODE_NON_STANDARD {
            return None;
        }
        Self::ALL.iter().copied().find(|m| m.standard() == mode)
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
        assert_eq!(
            FlightMode::from_standard(MavStandardMode::MAV_STANDARD_MODE_POSITION_HOLD),
            None
        );
        assert!(ModeSet::ALL.contains(FlightMode::Land));
        assert!(!ModeSet::WITHOUT_POSITION.contains(FlightMode::Mission));
    }
}
