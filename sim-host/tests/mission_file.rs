//! Mission files: every field of a `.plan` and a WPL file lands in the MAVLink items, and each
//! kind of bad input names the file, the key and the value.

use mavlink::dialects::common::{MavCmd, MavFrame, MavMissionType, MISSION_ITEM_INT_DATA};
use sim_host::mission_file::{read_mission_file, MissionFileError};
use std::path::PathBuf;

fn write(dir: &tempfile::TempDir, name: &str, text: &str) -> PathBuf {
    let p = dir.path().join(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// A plan as QGroundControl writes it: takeoff, two waypoints (one with a null yaw), a loiter,
/// a DO_JUMP back to the first waypoint (by doJumpId), a landing; an inclusion polygon, an
/// exclusion circle, two rally points.
const PLAN: &str = r#"{
    "fileType": "Plan",
    "geoFence": {
        "circles": [
            { "circle": { "center": [44.7262, -93.0745], "radius": 25.5 }, "inclusion": false, "version": 1 }
        ],
        "polygons": [
            { "inclusion": true, "polygon": [[44.730, -93.080], [44.730, -93.070], [44.721, -93.070], [44.721, -93.080]], "version": 1 }
        ],
        "version": 2
    },
    "groundStation": "QGroundControl",
    "mission": {
        "cruiseSpeed": 17,
        "firmwareType": 12,
        "globalPlanAltitudeMode": 1,
        "hoverSpeed": 5,
        "items": [
            { "autoContinue": true, "command": 22, "doJumpId": 1, "frame": 3,
              "params": [15, 0, 0, null, 44.7260, -93.0750, 30], "type": "SimpleItem" },
            { "AMSLAltAboveTerrain": null, "Altitude": 50, "AltitudeMode": 1,
              "autoContinue": true, "command": 16, "doJumpId": 2, "frame": 3,
              "params": [0, 20, 0, null, 44.7280, -93.0760, 50], "type": "SimpleItem" },
            { "autoContinue": false, "command": 16, "doJumpId": 3, "frame": 3,
              "params": [2.5, 0, 0, 90, 44.7285, -93.0720, 60.5], "type": "SimpleItem" },
            { "autoContinue": true, "command": 19, "doJumpId": 4, "frame": 3,
              "params": [30, 0, -80, 0, -44.7240, 93.0725, 55], "type": "SimpleItem" },
            { "autoContinue": true, "command": 177, "doJumpId": 5, "frame": 2,
              "params": [2, 3, 0, 0, 0, 0, 0], "type": "SimpleItem" },
            { "autoContinue": true, "command": 21, "doJumpId": 6, "frame": 3,
              "params": [0, 0, 0, null, 44.72584, -93.07501, 0], "type": "SimpleItem" }
        ],
        "plannedHomePosition": [44.7258357, -93.07501316, 287.5],
        "vehicleType": 1,
        "version": 2
    },
    "rallyPoints": {
        "points": [[44.7270, -93.0740, 40], [44.7250, -93.0760, 45.5]],
        "version": 2
    },
    "version": 1
}"#;

fn check(
    it: &MISSION_ITEM_INT_DATA,
    seq: u16,
    (command, frame): (MavCmd, MavFrame),
    params: [f32; 4],
    xyz: (i32, i32, f32),
    autocontinue: u8,
    kind: MavMissionType,
) {
    assert_eq!(it.seq, seq, "{it:?}");
    assert_eq!(it.command, command, "{it:?}");
    assert_eq!(it.frame, frame, "{it:?}");
    for (got, want) in [it.param1, it.param2, it.param3, it.param4]
        .iter()
        .zip(params)
    {
        assert!(
            got.to_bits() == want.to_bits() || (got.is_nan() && want.is_nan()),
            "{it:?}: params {params:?}"
        );
    }
    assert_eq!((it.x, it.y), (xyz.0, xyz.1), "{it:?}");
    assert_eq!(it.z.to_bits(), xyz.2.to_bits(), "{it:?}");
    assert_eq!(it.autocontinue, autocontinue, "{it:?}");
    assert_eq!(it.mission_type, kind, "{it:?}");
    assert_eq!(it.current, 0);
    assert_eq!((it.target_system, it.target_component), (1, 1));
}

#[test]
fn plan_file_every_field() {
    let dir = tempfile::tempdir().unwrap();
    let f = read_mission_file(&write(&dir, "m.plan", PLAN)).unwrap();
    use MavCmd::*;
    use MavFrame::*;
    const M: MavMissionType = MavMissionType::MAV_MISSION_TYPE_MISSION;
    let rel = MAV_FRAME_GLOBAL_RELATIVE_ALT;
    let nan = f32::NAN;
    assert_eq!(f.home, Some((44.7258357, -93.07501316, 287.5)));
    assert_eq!(f.mission.len(), 6);
    let m = &f.mission;
    check(
        &m[0],
        0,
        (MAV_CMD_NAV_TAKEOFF, rel),
        [15.0, 0.0, 0.0, nan],
        (447_260_000, -930_750_000, 30.0),
        1,
        M,
    );
    check(
        &m[1],
        1,
        (MAV_CMD_NAV_WAYPOINT, rel),
        [0.0, 20.0, 0.0, nan],
        (447_280_000, -930_760_000, 50.0),
        1,
        M,
    );
    check(
        &m[2],
        2,
        (MAV_CMD_NAV_WAYPOINT, rel),
        [2.5, 0.0, 0.0, 90.0],
        (447_285_000, -930_720_000, 60.5),
        0,
        M,
    );
    check(
        &m[3],
        3,
        (MAV_CMD_NAV_LOITER_TIME, rel),
        [30.0, 0.0, -80.0, 0.0],
        (-447_240_000, 930_725_000, 55.0),
        1,
        M,
    );
    // doJumpId 2 is the item at index 1; the repeat count is kept; frame MISSION keeps x/y plain.
    check(
        &m[4],
        4,
        (MAV_CMD_DO_JUMP, MAV_FRAME_MISSION),
        [1.0, 3.0, 0.0, 0.0],
        (0, 0, 0.0),
        1,
        M,
    );
    check(
        &m[5],
        5,
        (MAV_CMD_NAV_LAND, rel),
        [0.0, 0.0, 0.0, nan],
        (447_258_400, -930_750_100, 0.0),
        1,
        M,
    );

    const F: MavMissionType = MavMissionType::MAV_MISSION_TYPE_FENCE;
    assert_eq!(f.fence.len(), 5);
    let vert = MAV_CMD_NAV_FENCE_POLYGON_VERTEX_INCLUSION;
    let corners = [
        (447_300_000, -930_800_000),
        (447_300_000, -930_700_000),
        (447_210_000, -930_700_000),
        (447_210_000, -930_800_000),
    ];
    for (i, (x, y)) in corners.iter().enumerate() {
        check(
            &f.fence[i],
            i as u16,
            (vert, MAV_FRAME_GLOBAL),
            [4.0, 0.0, 0.0, 0.0],
            (*x, *y, 0.0),
            1,
            F,
        );
    }
    check(
        &f.fence[4],
        4,
        (MAV_CMD_NAV_FENCE_CIRCLE_EXCLUSION, MAV_FRAME_GLOBAL),
        [25.5, 0.0, 0.0, 0.0],
        (447_262_000, -930_745_000, 0.0),
        1,
        F,
    );

    const R: MavMissionType = MavMissionType::MAV_MISSION_TYPE_RALLY;
    assert_eq!(f.rally.len(), 2);
    check(
        &f.rally[0],
        0,
        (MAV_CMD_NAV_RALLY_POINT, rel),
        [0.0; 4],
        (447_270_000, -930_740_000, 40.0),
        1,
        R,
    );
    check(
        &f.rally[1],
        1,
        (MAV_CMD_NAV_RALLY_POINT, rel),
        [0.0; 4],
        (447_250_000, -930_760_000, 45.5),
        1,
        R,
    );
}

const WPL: &str = "QGC WPL 110\n\
0\t1\t0\t16\t0\t0\t0\t0\t44.7258357\t-93.07501316\t287.5\t1\n\
1\t0\t3\t22\t15\t0\t0\t0\t44.726\t-93.075\t30\t1\n\
2\t0\t3\t16\t0\t20\t0\t0\t44.728\t-93.076\t50\t1\n\
3\t0\t3\t16\t2.5\t0\t0\t90\t-44.7285\t93.072\t60.5\t0\n\
4\t0\t2\t177\t2\t3\t0\t0\t0\t0\t0\t1\n\
5\t0\t3\t21\t0\t0\t0\t0\t44.72584\t-93.07501\t0\t1\n";

#[test]
fn wpl_file_every_field() {
    let dir = tempfile::tempdir().unwrap();
    let f = read_mission_file(&write(&dir, "m.waypoints", WPL)).unwrap();
    use MavCmd::*;
    use MavFrame::*;
    const M: MavMissionType = MavMissionType::MAV_MISSION_TYPE_MISSION;
    let rel = MAV_FRAME_GLOBAL_RELATIVE_ALT;
    // Line 0 is home, not an item.
    assert_eq!(f.home, Some((44.7258357, -93.07501316, 287.5)));
    assert!(f.fence.is_empty() && f.rally.is_empty());
    let m = &f.mission;
    assert_eq!(m.len(), 5);
    check(
        &m[0],
        0,
        (MAV_CMD_NAV_TAKEOFF, rel),
        [15.0, 0.0, 0.0, 0.0],
        (447_260_000, -930_750_000, 30.0),
        1,
        M,
    );
    check(
        &m[1],
        1,
        (MAV_CMD_NAV_WAYPOINT, rel),
        [0.0, 20.0, 0.0, 0.0],
        (447_280_000, -930_760_000, 50.0),
        1,
        M,
    );
    check(
        &m[2],
        2,
        (MAV_CMD_NAV_WAYPOINT, rel),
        [2.5, 0.0, 0.0, 90.0],
        (-447_285_000, 930_720_000, 60.5),
        0,
        M,
    );
    // Line index 2 (home counted as 0) is item 1.
    check(
        &m[3],
        3,
        (MAV_CMD_DO_JUMP, MAV_FRAME_MISSION),
        [1.0, 3.0, 0.0, 0.0],
        (0, 0, 0.0),
        1,
        M,
    );
    check(
        &m[4],
        4,
        (MAV_CMD_NAV_LAND, rel),
        [0.0; 4],
        (447_258_400, -930_750_100, 0.0),
        1,
        M,
    );
    // Spaces instead of tabs read the same.
    let spaced = WPL.replace('\t', "  ");
    let g = read_mission_file(&write(&dir, "s.waypoints", &spaced)).unwrap();
    assert_eq!(g.mission.len(), 5);
    assert_eq!(g.mission[2].x, m[2].x);
}

/// The error's text names the file, the key and the value.
fn rejects(name: &str, text: &str, key: &str, value: &str) -> MissionFileError {
    let dir = tempfile::tempdir().unwrap();
    let p = write(&dir, name, text);
    let e = read_mission_file(&p).unwrap_err();
    let msg = e.to_string();
    assert!(msg.contains(name), "file not named: {msg}");
    assert!(msg.contains(key), "key {key} not named: {msg}");
    assert!(msg.contains(value), "value {value} not named: {msg}");
    e
}

#[test]
fn bad_plan_files_are_named_by_key_and_value() {
    // Not JSON at all.
    let e = rejects(
        "a.plan",
        "{\"fileType\": \"Plan\",\n  \"version\": 1,,}",
        "line 2",
        "JSON",
    );
    assert!(matches!(e, MissionFileError::Syntax { .. }));
    // Wrong file type and versions.
    rejects(
        "b.plan",
        &PLAN.replace("\"fileType\": \"Plan\"", "\"fileType\": \"Mission\""),
        "fileType",
        "\"Mission\"",
    );
    rejects(
        "c.plan",
        &PLAN.replace("    \"version\": 1\n}", "    \"version\": 3\n}"),
        "version",
        "3",
    );
    rejects(
        "d.plan",
        &PLAN.replace(
            "\"vehicleType\": 1,\n        \"version\": 2",
            "\"vehicleType\": 1,\n        \"version\": 1",
        ),
        "mission.version",
        "1",
    );
    // An unknown command number.
    rejects(
        "e.plan",
        &PLAN.replace("\"command\": 19,", "\"command\": 12345,"),
        "mission.items[3].command",
        "12345",
    );
    // A latitude out of range.
    rejects(
        "f.plan",
        &PLAN.replace("44.7285, -93.0720", "94.7285, -93.0720"),
        "mission.items[2].params[4]",
        "94.7285",
    );
    // A malformed number.
    rejects(
        "g.plan",
        &PLAN.replace("[2.5, 0, 0, 90,", "[\"2.5\", 0, 0, 90,"),
        "mission.items[2].params[0]",
        "\"2.5\"",
    );
    // Six parameters.
    rejects(
        "h.plan",
        &PLAN.replace("[2, 3, 0, 0, 0, 0, 0]", "[2, 3, 0, 0, 0, 0]"),
        "mission.items[4].params",
        "6 values",
    );
    // A jump to a doJumpId nobody has.
    rejects(
        "i.plan",
        &PLAN.replace("[2, 3, 0, 0, 0, 0, 0]", "[9, 3, 0, 0, 0, 0, 0]"),
        "mission.items[4].params[0]",
        "9",
    );
    // A complex item.
    let survey = PLAN.replace(
        "{ \"autoContinue\": true, \"command\": 21,",
        "{ \"type\": \"ComplexItem\", \"complexItemType\": \"survey\", \"version\": 5 },\n            { \"autoContinue\": true, \"command\": 21,",
    );
    let e = rejects(
        "j.plan",
        &survey,
        "mission.items[5].complexItemType",
        "\"survey\"",
    );
    assert!(e.to_string().contains("not supported"), "{e}");
    // A missing key.
    rejects(
        "k.plan",
        &PLAN.replace("\"autoContinue\": false, ", ""),
        "mission.items[2].autoContinue",
        "<missing>",
    );
    // A fence polygon with two vertices, a rally point out of range, an unknown frame.
    rejects(
        "l.plan",
        &PLAN.replace(
            "[[44.730, -93.080], [44.730, -93.070], [44.721, -93.070], [44.721, -93.080]]",
            "[[44.730, -93.080], [44.730, -93.070]]",
        ),
        "geoFence.polygons[0].polygon",
        "2 vertices",
    );
    rejects(
        "m.plan",
        &PLAN.replace("[44.7250, -93.0760, 45.5]", "[44.7250, -193.0760, 45.5]"),
        "rallyPoints.points[1][1]",
        "-193.076",
    );
    rejects(
        "n.plan",
        &PLAN.replace(
            "\"doJumpId\": 6, \"frame\": 3",
            "\"doJumpId\": 6, \"frame\": 99",
        ),
        "mission.items[5].frame",
        "99",
    );
    rejects(
        "o.plan",
        &PLAN.replace(
            "\"plannedHomePosition\": [44.7258357, -93.07501316, 287.5]",
            "\"plannedHomePosition\": [44.7258357, -93.07501316]",
        ),
        "mission.plannedHomePosition",
        "[44.7258357,-93.07501316]",
    );
}

#[test]
fn bad_wpl_files_are_named_by_line_column_and_value() {
    rejects(
        "a.txt",
        &WPL.replace("QGC WPL 110", "QGC WPL 120"),
        "line 1",
        "QGC WPL 120",
    );
    // Line 5 of the file (header, home, then items) is index 3; its latitude is column 9.
    rejects(
        "b.txt",
        &WPL.replace("-44.7285", "-144.7285"),
        "line 5, column 9",
        "-144.7285",
    );
    rejects(
        "c.txt",
        &WPL.replace("\t50\t1\n", "\t5O\t1\n"),
        "line 4, column 11",
        "\"5O\"",
    );
    rejects(
        "d.txt",
        &WPL.replace("3\t16\t0\t20", "3\t16016\t0\t20"),
        "line 4, column 4",
        "16016",
    );
    rejects(
        "e.txt",
        &WPL.replace("4\t0\t2\t177\t2", "4\t0\t2\t177\t7"),
        "line 6, column 5",
        "7",
    );
    rejects(
        "f.txt",
        &WPL.replace("5\t0\t3\t21", "6\t0\t3\t21"),
        "line 7, column 1",
        "6",
    );
    rejects(
        "g.txt",
        &WPL.replace("\t0\t0\t0\t1\n", "\t0\t0\t1\n"),
        "line 6",
        "11 columns",
    );
    rejects(
        "h.txt",
        &WPL.replace("\t60.5\t0\n", "\t60.5\t2\n"),
        "line 5, column 12",
        "2",
    );
}

#[test]
fn missing_file_is_named() {
    let e = read_mission_file(std::path::Path::new("/nonexistent/m.plan")).unwrap_err();
    assert!(matches!(e, MissionFileError::Read { .. }));
    assert!(e.to_string().contains("/nonexistent/m.plan"));
}
