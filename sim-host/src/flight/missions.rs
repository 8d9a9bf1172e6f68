//! Missions written as a planner would write them: MAVLink `MISSION_ITEM_INT`s with global
//! positions, built from offsets in metres from the simulator's home (the runway).

use super::config::FlightConfig;
use super::script::{Action, Script, ScriptStep};
use common::math::geodetic::{offset_point, GeoPoint};
use mavlink::dialects::common::{MavCmd, MavFrame, MavMissionType, MISSION_ITEM_INT_DATA};

/// A point of a mission: metres north and east of home, height above home.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Spot {
    /// North of home, m.
    pub north_m: f64,
    /// East of home, m.
    pub east_m: f64,
    /// Height above home, m.
    pub height_m: f64,
}

/// Builds items in sequence against one home.
pub struct MissionBuilder {
    home: GeoPoint,
    items: Vec<MISSION_ITEM_INT_DATA>,
}

impl MissionBuilder {
    /// An empty mission around `home`.
    pub fn new(home: GeoPoint) -> Self {
        Self {
            home,
            items: Vec::new(),
        }
    }

    /// Appends an item at `at` (or frame-less when `None`) with `params` 1-4.
    pub fn item(mut self, cmd: MavCmd, params: [f32; 4], at: Option<Spot>) -> Self {
        let seq = self.items.len() as u16;
        self.items.push(global_item(
            self.home,
            seq,
            cmd,
            params,
            at,
            MavMissionType::MAV_MISSION_TYPE_MISSION,
        ));
        self
    }

    /// A waypoint (default acceptance radius).
    pub fn waypoint(self, north_m: f64, east_m: f64, height_m: f64) -> Self {
        self.item(
            MavCmd::MAV_CMD_NAV_WAYPOINT,
            [0.0, 0.0, 0.0, f32::NAN],
            Some(Spot {
                north_m,
                east_m,
                height_m,
            }),
        )
    }

    /// A landing at `(north_m, east_m)` on the ground at home's height, along the line from
    /// the item before.
    pub fn land(self, north_m: f64, east_m: f64) -> Self {
        self.item(
            MavCmd::MAV_CMD_NAV_LAND,
            [0.0, 0.0, 0.0, f32::NAN],
            Some(Spot {
                north_m,
                east_m,
                height_m: 0.0,
            }),
        )
    }

    /// The items.
    pub fn build(self) -> Vec<MISSION_ITEM_INT_DATA> {
        self.items
    }
}

/// One item of any list: at `at` (global frame, altitude relative to home), or frame-less.
fn global_item(
    home: GeoPoint,
    seq: u16,
    cmd: MavCmd,
    params: [f32; 4],
    at: Option<Spot>,
    kind: MavMissionType,
) -> MISSION_ITEM_INT_DATA {
    let (frame, x, y, z) = match at {
        Some(s) => {
            let p = offset_point(home, s.north_m, s.east_m);
            (
                MavFrame::MAV_FRAME_GLOBAL_RELATIVE_ALT,
                p.lat_e7,
                p.lon_e7,
                s.height_m as f32,
            )
        }
        None => (MavFrame::MAV_FRAME_MISSION, 0, 0, 0.0),
    };
    MISSION_ITEM_INT_DATA {
        param1: params[0],
        param2: params[1],
        param3: params[2],
        param4: params[3],
        x,
        y,
        z,
        seq,
        command: cmd,
        target_system: 1,
        target_component: 1,
        frame,
        current: 0,
        autocontinue: 1,
        mission_type: kind,
    }
}

/// A geofence inclusion polygon through `corners` (north, east of home, m): one
/// `NAV_FENCE_POLYGON_VERTEX_INCLUSION` item per vertex, `param1` the vertex count.
pub fn fence_inclusion_polygon(
    home: GeoPoint,
    corners: &[(f64, f64)],
) -> Vec<MISSION_ITEM_INT_DATA> {
    corners
        .iter()
        .enumerate()
        .map(|(i, &(north_m, east_m))| {
            global_item(
                home,
                i as u16,
                MavCmd::MAV_CMD_NAV_FENCE_POLYGON_VERTEX_INCLUSION,
                [corners.len() as f32, 0.0, 0.0, 0.0],
                Some(Spot {
                    north_m,
                    east_m,
                    height_m: 0.0,
                }),
                MavMissionType::MAV_MISSION_TYPE_FENCE,
            )
        })
        .collect()
}

/// The default mission, flown by `cargo run --release -p sim-host`: take off from the runway
/// at home heading north, climb to 60 m, fly a 600 m x 400 m rectangle clockwise, circle its
/// north-west corner twice (radius 80 m), then come back past home to the south and land on
/// the runway heading north, touching down at home.
pub fn default_mission(home: GeoPoint) -> Vec<MISSION_ITEM_INT_DATA> {
    let h = 60.0;
    MissionBuilder::new(home)
        .item(
            MavCmd::MAV_CMD_NAV_TAKEOFF,
            [0.0, 0.0, 0.0, 0.0],
            Some(Spot {
                north_m: 300.0,
                east_m: 0.0,
                height_m: h,
            }),
        )
        .waypoint(600.0, 0.0, h)
        .waypoint(600.0, 400.0, h)
        .waypoint(0.0, 400.0, h)
        .waypoint(0.0, 0.0, h)
        .item(
            MavCmd::MAV_CMD_NAV_LOITER_TURNS,
            [2.0, 0.0, 80.0, 0.0],
            Some(Spot {
                north_m: 600.0,
                east_m: 0.0,
                height_m: h,
            }),
        )
        .waypoint(300.0, -150.0, 40.0)
        .waypoint(-450.0, -150.0, 40.0)
        .waypoint(-450.0, 0.0, 40.0)
        .land(0.0, 0.0)
        .build()
}

/// A flight of `mission` from the runway at home (heading north, engine off), as a pilot
/// with QGroundControl flies it: no parameter set (the firmware's defaults fly), the mission
/// uploaded, the autopilot armed once its estimator has converged, the mission started a second later; the flight
/// ends when the autopilot has landed and disarmed (or after 900 s).
pub fn runway_mission(mission: Vec<MISSION_ITEM_INT_DATA>) -> FlightConfig {
    FlightConfig {
        duration_s: 900.0,
        stop_when_landed: true,
        runway_heading: Some(0.0),
        script: Script {
            steps: vec![ScriptStep {
                after_arm_s: 1.0,
                action: Action::MissionStart,
            }],
            mission,
            ..Script::thesis()
        },
        ..FlightConfig::default()
    }
}
