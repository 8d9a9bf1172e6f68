//! Flight modes as the link encodes them.
//!
//! Ground stations decode the heartbeat's `custom_mode` of any non-ArduPilot vehicle with
//! PX4's layout: `custom_mode = (main_mode << 16) | (sub_mode << 24)`. The standard-modes
//! microservice (`AVAILABLE_MODES`, `CURRENT_MODE`, `MAV_CMD_DO_SET_STANDARD_MODE`) adds an
//! autopilot-neutral number for the modes that have one. Both numbers are columns of the
//! vehicle's table of mode facts ([`crate::vehicle::modes::MODES`]); what is left here is the
//! parsing of `MAV_CMD_DO_SET_MODE`'s parameters, which only the link meets.

pub use crate::vehicle::modes::{px4_auto, px4_main, FlightMode, ModeSet};

impl FlightMode {
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
}

#[cfg(test)]
mod tests {
    use super::*;
    use mavlink::dialects::common::MavStandardMode;

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
