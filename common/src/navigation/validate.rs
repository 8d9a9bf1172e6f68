//! Mission checks at upload time: the first item that cannot be flown is refused with the
//! `MAV_MISSION_RESULT` that names its fault; what can be flown but may surprise is a warning.

use super::items::{self, *};
use super::navigator::params::NavParams;
use super::plan::MissionItem;
use crate::estimator::Home;
use crate::math::geodetic::flight_ned_offset;
use crate::param;
use crate::params::{Group, ParamDef};
use mavlink::dialects::common::MavMissionResult;

/// Parameters of the mission checks.
pub const PARAMS: Group<MissionLimits> = Group {
    name: "Mission checks",
    params: &[
        param!(
            ParamDef::real(
                "MIS_ALT_MIN",
                -20.0,
                -1000.0,
                0.0,
                "m",
                "Lowest item altitude accepted, height above home",
            ),
            MissionLimits => alt_min
        ),
        param!(
            ParamDef::real(
                "MIS_ALT_MAX",
                400.0,
                10.0,
                10000.0,
                "m",
                "Highest item altitude accepted, height above home",
            ),
            MissionLimits => alt_max
        ),
    ],
    base: || MissionLimits {
        alt_min: 0.0,
        alt_max: 0.0,
    },
    check: |l| {
        if l.alt_min < l.alt_max {
            Ok(())
        } else {
            Err("MIS_ALT_MIN")
        }
    },
};

/// Altitude range accepted for items, heights above home, m.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct MissionLimits {
    /// Lowest, m.
    pub alt_min: f32,
    /// Highest, m.
    pub alt_max: f32,
}

impl Default for MissionLimits {
    fn default() -> Self {
        PARAMS.defaults()
    }
}

/// What a finished upload is checked against before it replaces the stored list: the
/// navigator's limits and the present home (the vehicle hands them to the link).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PlanRules {
    /// Home, once known (absolute altitudes are checked against it).
    pub home: Option<Home>,
    /// Altitude range of mission items.
    pub limits: MissionLimits,
    /// The navigator's parameters (approach checks).
    pub nav: NavParams,
}

/// Why an item is refused.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rejection {
    /// The first item at fault.
    pub seq: u16,
    /// The result to send in `MISSION_ACK`.
    pub result: MavMissionResult,
}

impl core::fmt::Display for Rejection {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "mission item {} refused: {:?}", self.seq, self.result)
    }
}

impl core::error::Error for Rejection {}

/// Something that will be flown differently from what a reader might expect.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ValidationWarning {
    /// The mission has no `NAV_LAND`.
    NoLanding,
    /// This item's command is not executed here; it will be skipped.
    WillSkip {
        /// Its sequence number.
        seq: u16,
        /// Its `MAV_CMD`.
        command: u16,
    },
    /// The waypoint before this landing is too close for the glide slope from its height: the
    /// aircraft will arrive high.
    ApproachTooShort {
        /// The landing's sequence number.
        seq: u16,
    },
}

/// The text the ground station shows (one STATUSTEXT, 50 characters even for the largest
/// sequence numbers and commands).
impl core::fmt::Display for ValidationWarning {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            ValidationWarning::NoLanding => f.write_str("Mission has no landing: it ends circling"),
            ValidationWarning::WillSkip { seq, command } => {
                write!(f, "Item {seq}: command {command} unsupported, skipped")
            }
            ValidationWarning::ApproachTooShort { seq } => {
                write!(f, "Item {seq}: approach too short, arrives high")
            }
        }
    }
}

/// The outcome of a check.
#[derive(Clone, Debug, PartialEq)]
pub struct Validation {
    /// `Err` with the first refused item, or `Ok`.
    pub result: Result<(), Rejection>,
    /// Warnings (the first eight).
    pub warnings: heapless::Vec<ValidationWarning, 8>,
}

fn reject(seq: usize, result: MavMissionResult) -> Result<(), Rejection> {
    Err(Rejection {
        seq: u16::try_from(seq).unwrap_or(u16::MAX),
        result,
    })
}

/// Checks a mission before it replaces the stored one. `home` (when known) lets absolute
/// altitudes be checked against the limits; without it only relative ones are.
pub fn validate_mission(
    items: &[MissionItem],
    home: Option<&Home>,
    limits: &MissionLimits,
    nav: &NavParams,
) -> Validation {
    let mut out = Validation {
        result: Ok(()),
        warnings: heapless::Vec::new(),
    };
    let mut warn = |w| {
        let _ = out.warnings.push(w);
    };
    let mut result = Ok(());
    let mut prev_nav: Option<&MissionItem> = None;
    let some_home = home.copied().unwrap_or_default();
    for (seq, it) in items.iter().enumerate() {
        let s16 = u16::try_from(seq).unwrap_or(u16::MAX);
        if let Err(e) = check_item(seq, it, items.len(), home, limits) {
            result = Err(e);
            break;
        }
        if !is_supported(it.command) {
            warn(ValidationWarning::WillSkip {
                seq: s16,
                command: it.command,
            });
        }
        if it.command == NAV_LAND {
            let short = prev_nav
                .filter(|p| p.command == NAV_WAYPOINT)
                .and_then(|p| {
                    let (a, b) = (items::point(p)?, items::point(it)?);
                    let (n, e) = flight_ned_offset(a, b);
                    let drop = items::height(p, &some_home)? - items::height(it, &some_home)?;
                    Some(
                        crate::math::elementary::hypot(n, e)
                            * crate::math::elementary::tan(nav.glide_slope)
                            < drop - nav.alt_accept,
                    )
                });
            if short == Some(true) {
                warn(ValidationWarning::ApproachTooShort { seq: s16 });
            }
        }
        if is_nav(it.command) {
            prev_nav = Some(it);
        }
    }
    if !items.iter().any(|i| i.command == NAV_LAND) {
        warn(ValidationWarning::NoLanding);
    }
    out.result = result;
    out
}

fn check_item(
    seq: usize,
    it: &MissionItem,
    len: usize,
    home: Option<&Home>,
    limits: &MissionLimits,
) -> Result<(), Rejection> {
    use MavMissionResult::*;
    let global = items::is_global(it);
    if is_nav(it.command) && global {
        if it.x.unsigned_abs() > 900_000_000 {
            return reject(seq, MAV_MISSION_INVALID_PARAM5_X);
        }
        if it.y.unsigned_abs() > 1_800_000_000 {
            return reject(seq, MAV_MISSION_INVALID_PARAM6_Y);
        }
        let z = it.z_m();
        if z.is_infinite() {
            return reject(seq, MAV_MISSION_INVALID_PARAM7);
        }
        let h = if items::is_relative(it) {
            Some(z)
        } else {
            home.and_then(|h| items::height(it, h))
        };
        if h.is_some_and(|h| h < limits.alt_min || h > limits.alt_max) {
            return reject(seq, MAV_MISSION_INVALID_PARAM7);
        }
    }
    match it.command {
        // A waypoint is a place: it needs a global frame.
        NAV_WAYPOINT if !global => reject(seq, MAV_MISSION_UNSUPPORTED_FRAME),
        NAV_WAYPOINT if it.param(1) < 0.0 => reject(seq, MAV_MISSION_INVALID_PARAM2),
        NAV_LOITER_TURNS | NAV_LOITER_TIME if it.param(0).is_nan() || it.param(0) < 0.0 => {
            reject(seq, MAV_MISSION_INVALID_PARAM1)
        }
        DO_JUMP => {
            let t = it.param(0);
            let whole = t.is_finite() && libm::truncf(t) == t;
            if !whole || t < 0.0 || t >= len as f32 || t as usize == seq {
                return reject(seq, MAV_MISSION_INVALID_SEQUENCE);
            }
            let r = it.param(1);
            if r != -1.0 && !(r.is_finite() && r >= 0.0 && libm::truncf(r) == r) {
                return reject(seq, MAV_MISSION_INVALID_PARAM2);
            }
            Ok(())
        }
        _ => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every warning fits one STATUSTEXT whole, with the largest numbers it can carry.
    #[test]
    fn warnings_fit_one_statustext() {
        use core::fmt::Write as _;
        for w in [
            ValidationWarning::NoLanding,
            ValidationWarning::WillSkip {
                seq: u16::MAX,
                command: u16::MAX,
            },
            ValidationWarning::ApproachTooShort { seq: u16::MAX },
        ] {
            let mut s: heapless::String<{ crate::gcs::STATUSTEXT_LEN }> = heapless::String::new();
            assert!(write!(s, "{w}").is_ok(), "{w:?} does not fit: {s}");
        }
    }
    use crate::params::{validate_defs, ParamError};

    use crate::navigation::tests::{home, item};

    fn wp(n: f32, e: f32, h: f32) -> MissionItem {
        item(NAV_WAYPOINT, [0.0; 4], n, e, h)
    }

    fn check(items: &[MissionItem]) -> Validation {
        validate_mission(
            items,
            Some(&home()),
            &MissionLimits::default(),
            &NavParams::default(),
        )
    }

    fn rejected(items: &[MissionItem]) -> Option<(u16, MavMissionResult)> {
        check(items).result.err().map(|r| (r.seq, r.result))
    }

    #[test]
    fn params_well_formed() {
        assert_eq!(validate_defs(PARAMS.defs()), Ok(()));
        let mut l = MissionLimits::default();
        let g = PARAMS;
        assert_eq!(
            g.set(&mut l, "MIS_ALT_MAX", 5.0),
            Err(ParamError::OutOfBounds)
        );
        assert_eq!(g.set(&mut l, "MIS_ALT_MAX", 150.0), Ok(()));
        assert_eq!(l.alt_max, 150.0);
    }

    #[test]
    fn a_good_mission_passes_with_its_warnings() {
        let items = [
            wp(300.0, 0.0, 80.0),
            item(183, [0.0; 4], 0.0, 0.0, 0.0),
            wp(1000.0, 0.0, 60.0),
            item(NAV_LAND, [0.0; 4], 0.0, 0.0, 0.0),
        ];
        let v = check(&items);
        assert_eq!(v.result, Ok(()));
        assert_eq!(
            v.warnings[..],
            [ValidationWarning::WillSkip {
                seq: 1,
                command: 183
            }]
        );
        let v = check(&items[..3]);
        assert_eq!(v.result, Ok(()));
        assert!(v.warnings.contains(&ValidationWarning::NoLanding));
    }

    #[test]
    fn bad_latitude_longitude_and_altitude() {
        let mut bad_lat = wp(0.0, 0.0, 80.0);
        bad_lat.x = 910_000_000;
        assert_eq!(
            rejected(&[wp(1.0, 0.0, 50.0), bad_lat]),
            Some((1, MavMissionResult::MAV_MISSION_INVALID_PARAM5_X))
        );
        let mut bad_lon = wp(0.0, 0.0, 80.0);
        bad_lon.y = -1_800_000_001;
        assert_eq!(
            rejected(&[bad_lon]),
            Some((0, MavMissionResult::MAV_MISSION_INVALID_PARAM6_Y))
        );
        // 500 m above home: over MIS_ALT_MAX (400 m).
        assert_eq!(
            rejected(&[wp(100.0, 0.0, 80.0), wp(0.0, 0.0, 500.0)]),
            Some((1, MavMissionResult::MAV_MISSION_INVALID_PARAM7))
        );
        // Absolute frame: 700 m AMSL is 450 m above the 250 m home.
        let mut amsl = wp(0.0, 0.0, 700.0);
        amsl.frame = 5;
        assert_eq!(
            rejected(&[amsl]),
            Some((0, MavMissionResult::MAV_MISSION_INVALID_PARAM7))
        );
        amsl.z = 600f32.to_bits();
        assert_eq!(rejected(&[amsl]), None);
        let mut local = wp(0.0, 0.0, 50.0);
        local.frame = 2;
        assert_eq!(
            rejected(&[local]),
            Some((0, MavMissionResult::MAV_MISSION_UNSUPPORTED_FRAME))
        );
    }

    #[test]
    fn bad_jumps() {
        let jump = |t: f32, r: f32| item(DO_JUMP, [t, r, 0.0, 0.0], 0.0, 0.0, 0.0);
        let base = wp(100.0, 0.0, 50.0);
        assert_eq!(rejected(&[base, jump(0.0, 3.0)]), None);
        assert_eq!(rejected(&[base, jump(0.0, -1.0)]), None);
        for t in [5.0, 2.0, -1.0, 0.5, f32::NAN, 1.0] {
            assert_eq!(
                rejected(&[base, jump(t, 1.0)]),
                Some((1, MavMissionResult::MAV_MISSION_INVALID_SEQUENCE)),
                "target {t}"
            );
        }
        assert_eq!(
            rejected(&[base, jump(0.0, -3.0)]),
            Some((1, MavMissionResult::MAV_MISSION_INVALID_PARAM2))
        );
        let turns = item(NAV_LOITER_TURNS, [-1.0, 0.0, 50.0, 0.0], 0.0, 0.0, 50.0);
        assert_eq!(
            rejected(&[turns]),
            Some((0, MavMissionResult::MAV_MISSION_INVALID_PARAM1))
        );
    }

    /// 60 m of height to lose over 300 m: a 6-degree slope needs 571 m.
    #[test]
    fn short_approach_is_a_warning() {
        let items = [
            wp(300.0, 0.0, 60.0),
            item(NAV_LAND, [0.0; 4], 0.0, 0.0, 0.0),
        ];
        let v = check(&items);
        assert_eq!(v.result, Ok(()));
        assert_eq!(
            v.warnings[..],
            [ValidationWarning::ApproachTooShort { seq: 1 }]
        );
        let items = [
            wp(700.0, 0.0, 60.0),
            item(NAV_LAND, [0.0; 4], 0.0, 0.0, 0.0),
        ];
        assert!(check(&items).warnings.is_empty());
    }
}
