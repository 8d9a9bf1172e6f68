//! The mission of each flight: the default mission, a mission file, or one generated from the
//! flight's draws; all laid out from the runway and turned with it about home.

use super::draws::Sampler;
use super::spec::MissionSpec;
use crate::flight::missions::{default_mission, MissionBuilder, Spot};
use common::math::geodetic::{ned_offset, offset_point, GeoPoint};
use mavlink::dialects::common::{MavCmd, MISSION_ITEM_INT_DATA};
use std::path::PathBuf;

/// Which mission a campaign flies.
#[derive(Clone, Debug, PartialEq)]
pub enum MissionChoice {
    /// [`default_mission`].
    Default,
    /// One generated per flight from its draws ([`GeneratedSpots`]).
    Generated,
    /// A QGroundControl `.plan` or `QGC WPL 110` file: its mission and geofence.
    File {
        /// The file as named on the command line.
        path: PathBuf,
        /// Mission items.
        mission: Vec<MISSION_ITEM_INT_DATA>,
        /// Geofence items.
        fence: Vec<MISSION_ITEM_INT_DATA>,
    },
}

impl MissionChoice {
    /// `default`, `generated`, or a file read and checked now.
    pub fn parse(arg: &str) -> anyhow::Result<Self> {
        match arg {
            "default" => Ok(Self::Default),
            "generated" => Ok(Self::Generated),
            path => {
                let file = crate::mission_file::read_mission_file(path.as_ref())?;
                anyhow::ensure!(
                    !file.mission.is_empty(),
                    "`{path}`: the mission has no items"
                );
                Ok(Self::File {
                    path: PathBuf::from(path),
                    mission: file.mission,
                    fence: file.fence,
                })
            }
        }
    }

    /// How the command line names it.
    pub fn name(&self) -> String {
        match self {
            Self::Default => "default".into(),
            Self::Generated => "generated".into(),
            Self::File { path, .. } => path.display().to_string(),
        }
    }
}

/// Where and which way the aircraft lands, from home, in the mission as flown.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Landing {
    /// The NAV_LAND point, north and east of home, m.
    pub point_ne: (f64, f64),
    /// Direction of the final approach, rad from north.
    pub direction_rad: f64,
}

/// A flight's mission: items, geofence and its landing.
#[derive(Clone, Debug)]
pub struct FlownMission {
    /// Mission items.
    pub items: Vec<MISSION_ITEM_INT_DATA>,
    /// Geofence items.
    pub fence: Vec<MISSION_ITEM_INT_DATA>,
    /// The landing, when the mission has one after a positioned item.
    pub landing: Option<Landing>,
}

/// Builds the flight's mission and turns it by the runway heading about home. The generated
/// mission's numbers are always drawn (recorded only when used), so the draws after them do
/// not depend on the mission kind; with the runway chosen `into_wind` it lands in its
/// take-off direction.
pub fn mission_for(
    s: &mut Sampler,
    choice: &MissionChoice,
    spec: &MissionSpec,
    home: GeoPoint,
    runway_heading_rad: f64,
    into_wind: bool,
) -> FlownMission {
    let generated = generated_spots(
        s,
        spec,
        into_wind,
        matches!(choice, MissionChoice::Generated),
    );
    let (items, fence) = match choice {
        MissionChoice::Default => (default_mission(home), Vec::new()),
        MissionChoice::Generated => (generated.build(home), Vec::new()),
        MissionChoice::File { mission, fence, .. } => (mission.clone(), fence.clone()),
    };
    let items = rotate_about_home(&items, home, runway_heading_rad);
    let fence = rotate_about_home(&fence, home, runway_heading_rad);
    let landing = landing_of(&items, home);
    FlownMission {
        items,
        fence,
        landing,
    }
}

/// Items with global positions turned by `angle` (clockwise seen from above, as a heading)
/// about `home`; frame-less items unchanged.
pub fn rotate_about_home(
    items: &[MISSION_ITEM_INT_DATA],
    home: GeoPoint,
    angle: f64,
) -> Vec<MISSION_ITEM_INT_DATA> {
    let (sin, cos) = angle.sin_cos();
    items
        .iter()
        .map(|i| {
            let mut i = i.clone();
            if is_positioned(&i) {
                let (n, e): (f64, f64) = ned_offset(home, point(&i));
                let p = offset_point(home, n * cos - e * sin, n * sin + e * cos);
                i.x = p.lat_e7;
                i.y = p.lon_e7;
            }
            i
        })
        .collect()
}

fn is_positioned(i: &MISSION_ITEM_INT_DATA) -> bool {
    crate::mission_file::item::is_global(i.frame)
}

fn point(i: &MISSION_ITEM_INT_DATA) -> GeoPoint {
    GeoPoint {
        lat_e7: i.x,
        lon_e7: i.y,
    }
}

/// The last NAV_LAND and the direction to it from the positioned item before it.
pub fn landing_of(items: &[MISSION_ITEM_INT_DATA], home: GeoPoint) -> Option<Landing> {
    let k = items
        .iter()
        .rposition(|i| i.command == MavCmd::MAV_CMD_NAV_LAND && is_positioned(i))?;
    let before = items[..k].iter().rev().find(|i| is_positioned(i))?;
    let (ln, le): (f64, f64) = ned_offset(home, point(&items[k]));
    let (bn, be): (f64, f64) = ned_offset(home, point(before));
    Some(Landing {
        point_ne: (ln, le),
        direction_rad: (le - be).atan2(ln - bn),
    })
}

/// The numbers of a generated mission, in the runway's frame (x along the runway, y to its
/// right, home at the origin).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GeneratedSpots {
    length_m: f64,
    width_m: f64,
    rotation_rad: f64,
    counter_clockwise: bool,
    loiter_corner: usize,
    loiter_radius_m: f64,
    loiter_turns: u32,
    loiter_counter_clockwise: bool,
    height_m: f64,
    /// Land against the take-off direction.
    reciprocal: bool,
    /// Side of the runway the downwind leg is flown on (+1 right).
    pattern_side: f64,
}

/// Height of the circuit before the approach, m (the default mission's).
const PATTERN_HEIGHT_M: f64 = 40.0;
/// Distance of the final approach's first point from the landing point, m (the default
/// mission's: 40 m on a 5 degree slope needs 457 m).
const FINAL_M: f64 = 450.0;
/// Distance of the downwind leg from the runway, m.
const PATTERN_OFFSET_M: f64 = 150.0;
/// Take-off point ahead of home, m.
const TAKEOFF_M: f64 = 300.0;

/// Draws a generated mission's numbers (recorded when `record`).
fn generated_spots(
    s: &mut Sampler,
    m: &MissionSpec,
    into_wind: bool,
    record: bool,
) -> GeneratedSpots {
    let keep = |s: &mut Sampler, name: &str, v: f64| {
        if record {
            s.record(name, v);
        }
        v
    };
    let lerp = |r: [f64; 2], u: f64| r[0] + (r[1] - r[0]) * u;
    let coin = |s: &mut Sampler| if s.unit_silent() < 0.5 { 0.0 } else { 1.0 };
    let u = s.unit_silent();
    let length_m = keep(s, "mission.length_m", lerp(m.length_m, u));
    let u = s.unit_silent();
    let width_m = keep(s, "mission.width_m", lerp(m.width_m, u));
    let u = s.unit_silent();
    let rotation_deg = keep(s, "mission.rotation_deg", lerp(m.rotation_deg, u));
    let c = coin(s);
    let counter_clockwise = keep(s, "mission.counter_clockwise", c) > 0.5;
    let u = s.unit_silent();
    let loiter_corner = keep(s, "mission.loiter_corner", (u * 4.0).floor().min(3.0)) as usize;
    let u = s.unit_silent();
    let loiter_radius_m = keep(s, "mission.loiter_radius_m", lerp(m.loiter_radius_m, u));
    let u = s.unit_silent();
    let span = f64::from(m.loiter_turns[1] - m.loiter_turns[0] + 1);
    let turns =
        (f64::from(m.loiter_turns[0]) + (u * span).floor()).min(f64::from(m.loiter_turns[1]));
    let loiter_turns = keep(s, "mission.loiter_turns", turns) as u32;
    let c = coin(s);
    let loiter_counter_clockwise = keep(s, "mission.loiter_counter_clockwise", c) > 0.5;
    let u = s.unit_silent();
    let height_m = keep(s, "mission.height_m", lerp(m.height_m, u));
    let c = if m.land_in_takeoff_direction || into_wind {
        s.unit_silent();
        0.0
    } else {
        coin(s)
    };
    let reciprocal = keep(s, "mission.land_reciprocal", c) > 0.5;
    let c = coin(s);
    let pattern_side = if keep(s, "mission.pattern_right", c) > 0.5 {
        1.0
    } else {
        -1.0
    };
    GeneratedSpots {
        length_m,
        width_m,
        rotation_rad: rotation_deg.to_radians(),
        counter_clockwise,
        loiter_corner,
        loiter_radius_m,
        loiter_turns,
        loiter_counter_clockwise,
        height_m,
        reciprocal,
        pattern_side,
    }
}

impl GeneratedSpots {
    /// The mission in the runway's frame, north along the runway (turned later): take-off
    /// 300 m ahead, the rectangle (its nearest corner first), back to that corner, a loiter at
    /// one corner, the downwind leg beside the runway, base, final and the landing at home.
    fn build(&self, home: GeoPoint) -> Vec<MISSION_ITEM_INT_DATA> {
        let h = self.height_m;
        let (sin, cos) = self.rotation_rad.sin_cos();
        // The rectangle's centre lies ahead of the take-off point by half its length, so the
        // climb-out heads into it whatever its rotation.
        let centre = (TAKEOFF_M + 0.5 * self.length_m, 0.0);
        let (hl, hw) = (0.5 * self.length_m, 0.5 * self.width_m);
        let mut corners: Vec<(f64, f64)> = [(-hl, -hw), (hl, -hw), (hl, hw), (-hl, hw)]
            .iter()
            .map(|&(x, y)| (centre.0 + x * cos - y * sin, centre.1 + x * sin + y * cos))
            .collect();
        // Corners in the order listed go round clockwise seen from above (x north, y east).
        if self.counter_clockwise {
            corners.reverse();
        }
        let d2 = |c: &(f64, f64)| (c.0 - TAKEOFF_M).powi(2) + c.1.powi(2);
        let first = (0..4)
            .min_by(|&a, &b| d2(&corners[a]).total_cmp(&d2(&corners[b])))
            .unwrap_or(0);
        corners.rotate_left(first);
        let mut b = MissionBuilder::new(home).item(
            MavCmd::MAV_CMD_NAV_TAKEOFF,
            [0.0; 4],
            Some(Spot {
                north_m: TAKEOFF_M,
                east_m: 0.0,
                height_m: h,
            }),
        );
        for c in corners.iter().chain(corners.first()) {
            b = b.waypoint(c.0, c.1, h);
        }
        let lc = corners[self.loiter_corner];
        let radius = if self.loiter_counter_clockwise {
            -self.loiter_radius_m
        } else {
            self.loiter_radius_m
        };
        b = b.item(
            MavCmd::MAV_CMD_NAV_LOITER_TURNS,
            [self.loiter_turns as f32, 0.0, radius as f32, 0.0],
            Some(Spot {
                north_m: lc.0,
                east_m: lc.1,
                height_m: h,
            }),
        );
        // The circuit: downwind leg beside the runway, base leg, final into the landing.
        let dir = if self.reciprocal { -1.0 } else { 1.0 };
        let side = self.pattern_side * PATTERN_OFFSET_M;
        let hp = PATTERN_HEIGHT_M;
        b.waypoint(dir * TAKEOFF_M, side, hp)
            .waypoint(-dir * FINAL_M, side, hp)
            .waypoint(-dir * FINAL_M, 0.0, hp)
            .land(0.0, 0.0)
            .build()
    }
}
