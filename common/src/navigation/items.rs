//! MAVLink mission items' command numbers, frames, positions and altitudes.

use super::plan::MissionItem;
use crate::estimator::Home;
use crate::math::geodetic::{flight_ned_offset, GeoPoint};
use mavlink::dialects::common::{MavCmd, MavFrame};
use nalgebra::Vector3;

/// `MAV_CMD_NAV_WAYPOINT`.
pub const NAV_WAYPOINT: u16 = MavCmd::MAV_CMD_NAV_WAYPOINT as u16;
/// `MAV_CMD_NAV_LOITER_UNLIM`.
pub const NAV_LOITER_UNLIM: u16 = MavCmd::MAV_CMD_NAV_LOITER_UNLIM as u16;
/// `MAV_CMD_NAV_LOITER_TURNS`.
pub const NAV_LOITER_TURNS: u16 = MavCmd::MAV_CMD_NAV_LOITER_TURNS as u16;
/// `MAV_CMD_NAV_LOITER_TIME`.
pub const NAV_LOITER_TIME: u16 = MavCmd::MAV_CMD_NAV_LOITER_TIME as u16;
/// `MAV_CMD_NAV_RETURN_TO_LAUNCH`.
pub const NAV_RETURN_TO_LAUNCH: u16 = MavCmd::MAV_CMD_NAV_RETURN_TO_LAUNCH as u16;
/// `MAV_CMD_NAV_LAND`.
pub const NAV_LAND: u16 = MavCmd::MAV_CMD_NAV_LAND as u16;
/// `MAV_CMD_NAV_TAKEOFF`.
pub const NAV_TAKEOFF: u16 = MavCmd::MAV_CMD_NAV_TAKEOFF as u16;
/// `MAV_CMD_NAV_LOITER_TO_ALT`.
pub const NAV_LOITER_TO_ALT: u16 = MavCmd::MAV_CMD_NAV_LOITER_TO_ALT as u16;
/// `MAV_CMD_DO_JUMP`.
pub const DO_JUMP: u16 = MavCmd::MAV_CMD_DO_JUMP as u16;
/// `MAV_CMD_DO_CHANGE_SPEED`.
pub const DO_CHANGE_SPEED: u16 = MavCmd::MAV_CMD_DO_CHANGE_SPEED as u16;
/// `MAV_CMD_DO_SET_HOME`.
pub const DO_SET_HOME: u16 = MavCmd::MAV_CMD_DO_SET_HOME as u16;
/// `MAV_CMD_NAV_FENCE_POLYGON_VERTEX_INCLUSION`.
pub const FENCE_POLYGON_INCLUSION: u16 = MavCmd::MAV_CMD_NAV_FENCE_POLYGON_VERTEX_INCLUSION as u16;
/// `MAV_CMD_NAV_FENCE_POLYGON_VERTEX_EXCLUSION`.
pub const FENCE_POLYGON_EXCLUSION: u16 = MavCmd::MAV_CMD_NAV_FENCE_POLYGON_VERTEX_EXCLUSION as u16;

// The *_INT frame numbers are deprecated synonyms, yet ground stations still send them.
#[allow(deprecated)]
const GLOBAL_ABS: [u8; 2] = [
    MavFrame::MAV_FRAME_GLOBAL as u8,
    MavFrame::MAV_FRAME_GLOBAL_INT as u8,
];
#[allow(deprecated)]
const GLOBAL_REL: [u8; 2] = [
    MavFrame::MAV_FRAME_GLOBAL_RELATIVE_ALT as u8,
    MavFrame::MAV_FRAME_GLOBAL_RELATIVE_ALT_INT as u8,
];

/// The navigation commands this navigator flies.
pub fn is_nav(command: u16) -> bool {
    matches!(
        command,
        NAV_WAYPOINT
            | NAV_LOITER_UNLIM
            | NAV_LOITER_TURNS
            | NAV_LOITER_TIME
            | NAV_RETURN_TO_LAUNCH
            | NAV_LAND
            | NAV_TAKEOFF
            | NAV_LOITER_TO_ALT
    )
}

/// The commands this navigator executes (navigation and the supported `DO_*`).
pub fn is_supported(command: u16) -> bool {
    is_nav(command) || matches!(command, DO_JUMP | DO_CHANGE_SPEED | DO_SET_HOME)
}

/// The item's frame is a global one (latitude, longitude, altitude).
pub fn is_global(item: &MissionItem) -> bool {
    GLOBAL_ABS.contains(&item.frame) || GLOBAL_REL.contains(&item.frame)
}

/// The item's altitude is relative to home (rather than above mean sea level).
pub fn is_relative(item: &MissionItem) -> bool {
    GLOBAL_REL.contains(&item.frame)
}

/// The item's horizontal position, when it names one: a global frame and not the 0/0 that
/// several commands use for "here".
pub fn point(item: &MissionItem) -> Option<GeoPoint> {
    let p = GeoPoint {
        lat_e7: item.x,
        lon_e7: item.y,
    };
    (is_global(item) && !(item.x == 0 && item.y == 0) && p.is_valid()).then_some(p)
}

/// An altitude with its datum.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Altitude {
    /// Height above home, m (the `*_RELATIVE_ALT` frames).
    AboveHome(f32),
    /// Above mean sea level, m (the plain global frames).
    Amsl(f32),
}

impl Altitude {
    /// As height above `home`, m.
    pub fn above_home_m(self, home: &Home) -> f32 {
        match self {
            Altitude::AboveHome(h) => h,
            Altitude::Amsl(a) => a - home.alt_amsl_m,
        }
    }

    /// Above mean sea level, m, by way of the height above `home` (so an AMSL altitude comes
    /// back rounded through home's datum, as the navigator has always flown it).
    pub fn amsl_m(self, home: &Home) -> f32 {
        self.above_home_m(home) + home.alt_amsl_m
    }
}

/// The item's altitude with its datum; `None` when it gives none (not a global frame, or a
/// non-finite `z`).
pub fn altitude(item: &MissionItem) -> Option<Altitude> {
    let z = item.z_m();
    if !z.is_finite() {
        None
    } else if is_relative(item) {
        Some(Altitude::AboveHome(z))
    } else if GLOBAL_ABS.contains(&item.frame) {
        Some(Altitude::Amsl(z))
    } else {
        None
    }
}

/// Where an item flies to: a point and an altitude, each absent when the item leaves it to
/// the aircraft's present one.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Place {
    /// The horizontal position, when the item names one ([`point`]).
    pub point: Option<GeoPoint>,
    /// The altitude, when the item gives one ([`altitude`]).
    pub alt: Option<Altitude>,
}

impl Place {
    /// The place `item` names.
    pub fn of(item: &MissionItem) -> Self {
        Self {
            point: point(item),
            alt: altitude(item),
        }
    }

    /// Height above `home`, m, when the place gives an altitude.
    pub fn height(&self, home: &Home) -> Option<f32> {
        self.alt.map(|a| a.above_home_m(home))
    }

    /// NED from `home`: the place's point (or `here`'s when it names none) at its height (or
    /// `here`'s when it gives none).
    pub fn ned(&self, home: &Home, here: &Vector3<f32>) -> Vector3<f32> {
        let (n, e) = match self.point {
            Some(p) => flight_ned_offset(home.point, p),
            None => (here.x, here.y),
        };
        let h = self.height(home).unwrap_or(-here.z);
        Vector3::new(n, e, -h)
    }
}

/// The item's altitude as height above home, m; `None` when it gives none (not a global frame,
/// or a non-finite `z`).
pub fn height(item: &MissionItem, home: &Home) -> Option<f32> {
    altitude(item).map(|a| a.above_home_m(home))
}

/// The item's altitude above mean sea level, m, when it gives one.
pub fn alt_amsl(item: &MissionItem, home: &Home) -> Option<f32> {
    altitude(item).map(|a| a.amsl_m(home))
}

/// The item's target NED from home: its position (or `here`'s when it names none) at its
/// height (or `here`'s when it gives none).
pub fn target_ned(item: &MissionItem, home: &Home, here: &Vector3<f32>) -> Vector3<f32> {
    Place::of(item).ned(home, here)
}
