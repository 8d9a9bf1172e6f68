//! Missions written as a planner would write them: MAVLink `MISSION_ITEM_INT`s with global
//! positions, built from offsets in metres from the simulator's home (the runway).

use super::config::{FlightConfig, RcSticks};
use super::script::{Action, Script, ScriptStep, PX4_POSCTL, PX4_STABILIZED};
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

/// A mission on another runway than the default's, laid out as an outside planner laid out
/// the missions this autopilot had never flown: the take-off item off the runway's heading,
/// rectangles turned from it, speed changes, loiter turns and a circuit to the runway from
/// either side.
#[derive(Clone, Debug)]
pub struct RunwayMission {
    /// A short name for tables.
    pub name: &'static str,
    /// What the mission flies, for the documents.
    pub what: &'static str,
    /// The runway's heading, the way the aircraft stands on it (and lands), rad from north.
    pub runway_rad: f64,
    /// The items.
    pub items: Vec<MISSION_ITEM_INT_DATA>,
}

/// Places points given along a runway and to its right (m) north and east of home.
struct RunwayFrame {
    sin: f64,
    cos: f64,
}

impl RunwayFrame {
    fn new(heading_rad: f64) -> Self {
        let (sin, cos) = heading_rad.sin_cos();
        Self { sin, cos }
    }

    /// A spot `along` the runway and `right` of it, `height_m` above home.
    fn spot(&self, along: f64, right: f64, height_m: f64) -> Spot {
        Spot {
            north_m: along * self.cos - right * self.sin,
            east_m: along * self.sin + right * self.cos,
            height_m,
        }
    }

    /// The corners of a `length` by `width` rectangle (m) about `centre` (along, right),
    /// its length turned `turn_rad` right of the runway, clockwise seen from above from the
    /// corner nearest the runway's start.
    fn rectangle(
        &self,
        centre: (f64, f64),
        length: f64,
        width: f64,
        turn_rad: f64,
    ) -> [(f64, f64); 4] {
        let (s, c) = turn_rad.sin_cos();
        let (hl, hw) = (0.5 * length, 0.5 * width);
        [(-hl, -hw), (hl, -hw), (hl, hw), (-hl, hw)]
            .map(|(x, y)| (centre.0 + x * c - y * s, centre.1 + x * s + y * c))
    }
}

/// Builds a mission in a runway's frame.
struct RunwayBuilder {
    frame: RunwayFrame,
    b: MissionBuilder,
}

impl RunwayBuilder {
    fn item(mut self, cmd: MavCmd, params: [f32; 4], at: Option<(f64, f64, f64)>) -> Self {
        let at = at.map(|(a, r, h)| self.frame.spot(a, r, h));
        self.b = self.b.item(cmd, params, at);
        self
    }

    fn waypoint(self, along: f64, right: f64, height_m: f64) -> Self {
        self.item(
            MavCmd::MAV_CMD_NAV_WAYPOINT,
            [0.0, 0.0, 0.0, f32::NAN],
            Some((along, right, height_m)),
        )
    }

    /// `DO_CHANGE_SPEED` to an airspeed of `mps`.
    fn speed(self, mps: f32) -> Self {
        self.item(MavCmd::MAV_CMD_DO_CHANGE_SPEED, [0.0, mps, -1.0, 0.0], None)
    }

    fn land_at_home(self) -> Vec<MISSION_ITEM_INT_DATA> {
        self.item(
            MavCmd::MAV_CMD_NAV_LAND,
            [0.0, 0.0, 0.0, f32::NAN],
            Some((0.0, 0.0, 0.0)),
        )
        .b
        .build()
    }
}

/// Two missions on other runways (120 and 250 deg), each landing at home on its runway:
/// - `runway 120`: the take-off item 300 m out 30 deg right of the runway at 50 m, three
///   sides of a 500 m x 300 m rectangle turned 30 deg right flown at 20 m/s
///   (`DO_CHANGE_SPEED`), 17 m/s again for a right-hand circuit (downwind 200 m right of the runway at 40 m) and a
///   450 m final;
/// - `runway 250`: the take-off item 300 m out 75 deg left at 60 m, three sides of a
///   500 m x 300 m rectangle turned 60 deg left flown anticlockwise, two anticlockwise turns
///   of 70 m round its fourth corner, a left-hand circuit 200 m off the runway at 45 m and a
///   350 m final.
pub fn other_runway_missions(home: GeoPoint) -> Vec<RunwayMission> {
    let build = |deg: f64| RunwayBuilder {
        frame: RunwayFrame::new(deg.to_radians()),
        b: MissionBuilder::new(home),
    };
    let takeoff = |off_deg: f64, h: f64| {
        let (s, c) = off_deg.to_radians().sin_cos();
        Some((300.0 * c, 300.0 * s, h))
    };
    let east = build(120.0);
    let r = east
        .frame
        .rectangle((750.0, 400.0), 500.0, 300.0, 30f64.to_radians());
    // The rectangle at 20 m/s, back to 17 for the circuit: its last corner, 135 deg and
    // downwind, needs a fillet wider than the 70 m default (`NAV_TURN_RAD`, laid out for
    // 22 m/s over ground), which the path manager lays out from the wind (91 m in 5 m/s);
    // on the 70 m fillet it was overshot by up to 58 m.
    let east = east
        .item(MavCmd::MAV_CMD_NAV_TAKEOFF, [0.0; 4], takeoff(30.0, 50.0))
        .speed(20.0)
        .waypoint(r[0].0, r[0].1, 50.0)
        .waypoint(r[1].0, r[1].1, 50.0)
        .waypoint(r[2].0, r[2].1, 50.0)
        .waypoint(r[3].0, r[3].1, 50.0)
        .speed(17.0)
        .waypoint(400.0, 200.0, 40.0)
        .waypoint(-450.0, 200.0, 40.0)
        .waypoint(-450.0, 0.0, 40.0)
        .land_at_home();
    let west = build(250.0);
    let r = west
        .frame
        .rectangle((700.0, -450.0), 500.0, 300.0, -60f64.to_radians());
    let mut b = west.item(MavCmd::MAV_CMD_NAV_TAKEOFF, [0.0; 4], takeoff(-75.0, 60.0));
    // Anticlockwise: the corners in reverse, the loiter at the last.
    for c in [r[0], r[3], r[2]] {
        b = b.waypoint(c.0, c.1, 60.0);
    }
    let west = b
        .item(
            MavCmd::MAV_CMD_NAV_LOITER_TURNS,
            [2.0, 0.0, -70.0, 0.0],
            Some((r[1].0, r[1].1, 60.0)),
        )
        .waypoint(400.0, -200.0, 45.0)
        .waypoint(-350.0, -200.0, 45.0)
        .waypoint(-350.0, 0.0, 45.0)
        .land_at_home();
    vec![
        RunwayMission {
            name: "runway 120",
            what: "take-off item 30 deg right of the runway, a rectangle turned 30 deg right flown clockwise at 20 m/s, right-hand circuit at 17 m/s",
            runway_rad: 120f64.to_radians(),
            items: east,
        },
        RunwayMission {
            name: "runway 250",
            what: "take-off item 75 deg left of the runway, three sides of a rectangle turned 60 deg left anticlockwise, two anticlockwise turns, left-hand circuit",
            runway_rad: 250f64.to_radians(),
            items: west,
        },
    ]
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

/// A 3-2-1-1 of `amp` from `from_s` on steps of `unit_s`, then centred: the stick positions a
/// pilot flies for a broad band with few reversals.
fn three_two_one_one(from_s: f64, unit_s: f64, amp: f32) -> [(f64, f32); 5] {
    [(0.0, amp), (3.0, -amp), (5.0, amp), (6.0, -amp), (7.0, 0.0)]
        .map(|(k, a)| (from_s + k * unit_s, a))
}

/// An identification flight as a pilot flies it with the simulator's radio (RC_CHANNELS):
/// Stabilized from the hand launch at `throttle`, 3-2-1-1s of 0.3 stick on 0.3 s steps in
/// roll, then in pitch, three times each, then full and idle power for 6 s each (the airspeed
/// model's excitation), then three 3-2-1-1s of 0.3 stick in yaw (the rudder over the yaw
/// damper: the sideslip model's), 105 s in all.
pub fn stick_doublets(throttle: f32) -> FlightConfig {
    let stick = |from_s, roll, pitch, throttle| RcSticks {
        from_s,
        roll,
        pitch,
        throttle,
        yaw: 0.0,
    };
    let yaw = |from_s, yaw| RcSticks {
        yaw,
        ..stick(from_s, 0.0, 0.0, throttle)
    };
    let mut sticks = vec![stick(0.0, 0.0, 0.0, throttle)];
    for k in 0..3 {
        let t0 = 10.0 + 20.0 * f64::from(k);
        for (from_s, roll) in three_two_one_one(t0, 0.3, 0.3) {
            sticks.push(stick(from_s, roll, 0.0, throttle));
        }
        for (from_s, pitch) in three_two_one_one(t0 + 10.0, 0.3, 0.3) {
            sticks.push(stick(from_s, 0.0, pitch, throttle));
        }
    }
    for (from_s, power) in [(72.0, 0.9), (78.0, 0.2), (84.0, throttle)] {
        sticks.push(stick(from_s, 0.0, 0.0, power));
    }
    for t0 in [90.0, 95.0, 100.0] {
        for (from_s, y) in three_two_one_one(t0, 0.3, 0.3) {
            sticks.push(yaw(from_s, y));
        }
    }
    FlightConfig {
        duration_s: 105.0,
        script: Script {
            steps: vec![ScriptStep {
                after_arm_s: 0.0,
                action: Action::Mode(PX4_STABILIZED),
            }],
            ..Script::thesis()
        },
        rc_sticks: sticks,
        ..FlightConfig::default()
    }
}

/// When the autotune flight's station presses autotune, s after arming: once the take-off
/// from the simulator's hand launch has settled into level flight.
pub const AUTOTUNE_AT_S: f64 = 10.0;

/// Time the autotune flight leaves the autotune before the thesis's script, s: its timeline
/// (60 s), the fit and the design, and some level flight.
pub const AUTOTUNE_FOR_S: f64 = 80.0;

/// The gains the design sets, which the autotune flight's station reads before the autotune
/// and after it, with the coefficients it identified (the `ATUN_A_*` parameters).
pub const AUTOTUNE_GAINS: [&str; 17] = [
    "RLL_KP",
    "RLL_KI",
    "RLL_RATE_KD",
    "CRS_KP",
    "CRS_KI",
    "SLIP_KP",
    "SLIP_KI",
    "PTCH_KP",
    "PTCH_KI",
    "PTCH_RATE_KD",
    "ALT_KP",
    "ALT_KI",
    "ASPD_PTCH_KP",
    "ASPD_PTCH_KI",
    "ASPD_THR_KP",
    "ASPD_THR_KI",
    "ASPD_SCL_REF",
];

/// What the vehicle's design ran on beside the identified coefficients, which the autotune
/// flight's station reads as well: the servo it fitted through and the feedback filter of the
/// outer loops (the host recomputes the design's margins from them).
pub const AUTOTUNE_DESIGN_INPUTS: [&str; 2] = ["SERVO_BW", "FB_LPF_POLE"];

/// What the autotune flight's station reads: [`AUTOTUNE_GAINS`], [`AUTOTUNE_DESIGN_INPUTS`],
/// then the identified coefficients' parameters as the vehicle declares them.
pub fn autotune_params() -> Vec<String> {
    let identified = common::tuning::autotune::params::IDENTIFIED.params.iter();
    AUTOTUNE_GAINS
        .iter()
        .chain(&AUTOTUNE_DESIGN_INPUTS)
        .copied()
        .chain(identified.map(|p| p.def.name))
        .map(String::from)
        .collect()
}

/// The station's autotune pressed at `at_s` after arming: [`autotune_params`] read a second
/// before, the autotune, and the same read a second before [`AUTOTUNE_FOR_S`] has passed.
fn autotune_steps(at_s: f64) -> [ScriptStep; 3] {
    let read = || Action::ReadParams(autotune_params());
    let at = |after_arm_s, action| ScriptStep {
        after_arm_s,
        action,
    };
    [
        at(at_s - 1.0, read()),
        at(at_s, Action::Autotune(true)),
        at(at_s + AUTOTUNE_FOR_S - 1.0, read()),
    ]
}

/// The thesis's script flown after an autotune, as a QGroundControl user flies it: Hold from
/// the hand launch, autotune ([`AUTOTUNE_AT_S`]), then the script [`AUTOTUNE_FOR_S`] later;
/// the station reads [`autotune_params`] before the autotune and before the script.
pub fn autotune_then_thesis() -> FlightConfig {
    let mut script = Script::thesis();
    for step in script.steps.iter_mut().skip(1) {
        step.after_arm_s += AUTOTUNE_AT_S + AUTOTUNE_FOR_S;
    }
    script.steps.splice(1..1, autotune_steps(AUTOTUNE_AT_S));
    FlightConfig {
        duration_s: script.length_s(),
        script,
        ..FlightConfig::default()
    }
}

/// When the autotune-then-mission flight's station switches to Hold, s after arming on the
/// runway: the take-off it started a second after arming has climbed to `NAV_RTL_ALT`
/// (60 m) some 21 s after arming, and circles there.
pub const HOLD_AFTER_ARM_S: f64 = 30.0;

/// When that station presses autotune, s after arming: 5 s of Hold after the circle, the
/// wings level.
pub const AUTOTUNE_AFTER_TAKEOFF_S: f64 = HOLD_AFTER_ARM_S + 5.0;

/// When that station starts the mission, s after arming: [`AUTOTUNE_FOR_S`] after the
/// autotune was pressed.
pub const MISSION_AFTER_AUTOTUNE_S: f64 = AUTOTUNE_AFTER_TAKEOFF_S + AUTOTUNE_FOR_S;

/// A mission flight (`runway_mission`'s, or a mission file's) flown after an autotune, as a
/// QGroundControl user flies it: the mission uploaded and the autopilot armed on the runway
/// as for the mission, then Takeoff (`MAV_CMD_NAV_TAKEOFF`, QGroundControl's Takeoff action)
/// a second after arming, Hold once in the air ([`HOLD_AFTER_ARM_S`]), autotune
/// ([`AUTOTUNE_AFTER_TAKEOFF_S`]; [`autotune_params`] read before it and once it is done),
/// then `MAV_CMD_MISSION_START` ([`MISSION_AFTER_AUTOTUNE_S`]): the whole mission, its
/// take-off item (already above its height) included, flown on the gains the autotune
/// applied, to the landing and the disarm. The mission's figures count from its start.
pub fn autotune_then_mission(mission: FlightConfig) -> FlightConfig {
    let at = |after_arm_s, action| ScriptStep {
        after_arm_s,
        action,
    };
    let mut steps = vec![
        at(1.0, Action::Takeoff),
        at(HOLD_AFTER_ARM_S, Action::Mode(PX4_POSCTL)),
    ];
    steps.extend(autotune_steps(AUTOTUNE_AFTER_TAKEOFF_S));
    steps.push(at(MISSION_AFTER_AUTOTUNE_S, Action::MissionStart));
    FlightConfig {
        duration_s: mission.duration_s + MISSION_AFTER_AUTOTUNE_S,
        script: Script {
            steps,
            ..mission.script
        },
        ..mission
    }
}
