//! The plain-text `QGC WPL 110` format: one tab-separated line per item, line 0 the home
//! position.

use super::item::{item, Coord, Ctx, MissionFile, MissionFileError, DO_JUMP};
use mavlink::dialects::common::MavMissionType;
use std::path::Path;

/// Names of the WPL columns, for errors.
const WPL_COLUMNS: [&str; 12] = [
    "index",
    "current",
    "frame",
    "command",
    "param1",
    "param2",
    "param3",
    "param4",
    "x/latitude",
    "y/longitude",
    "z/altitude",
    "autocontinue",
];

/// Parses a `QGC WPL 110` file: tab-separated `index current frame command p1 p2 p3 p4 x y z
/// autocontinue`, line 0 the home position; `file` names it in errors.
pub fn parse_wpl(text: &str, file: &Path) -> Result<MissionFile, MissionFileError> {
    let cx = Ctx { file };
    let mut lines = text.lines().enumerate();
    let header = lines.next().map_or("", |(_, l)| l.trim());
    if header != "QGC WPL 110" {
        return Err(cx.bad(
            "line 1",
            format!("{header:?}"),
            "the first line must be \"QGC WPL 110\"",
        ));
    }
    let mut home = None;
    let mut mission = Vec::new();
    let mut jumps = Vec::new();
    let mut expected_index = 0u64;
    for (n, line) in lines {
        let line_no = n + 1;
        if line.trim().is_empty() {
            continue;
        }
        // The format separates with tabs; files edited by hand often use spaces.
        let cols: Vec<&str> = if line.contains('\t') {
            line.split('\t').map(str::trim).collect()
        } else {
            line.split_whitespace().collect()
        };
        if cols.len() != 12 {
            return Err(cx.bad(
                &format!("line {line_no}"),
                format!("{} columns", cols.len()),
                "a WPL line has 12 columns: index current frame command p1 p2 p3 p4 x y z autocontinue",
            ));
        }
        let key = |c: usize| format!("line {line_no}, column {} ({})", c + 1, WPL_COLUMNS[c]);
        let mut v = [0.0f64; 12];
        for (c, s) in cols.iter().enumerate() {
            v[c] = s
                .parse::<f64>()
                .map_err(|_| cx.bad(&key(c), format!("{s:?}"), "not a number"))?;
            // The item's fields are 32-bit floats: a larger number would become an infinity.
            if v[c].is_finite() && v[c].abs() > f64::from(f32::MAX) {
                return Err(cx.bad(&key(c), s, "too large for a 32-bit float"));
            }
        }
        if v[0] != expected_index as f64 {
            return Err(cx.bad(
                &key(0),
                cols[0],
                format!("indices count up from 0: expected {expected_index}"),
            ));
        }
        expected_index += 1;
        let autocontinue = match cols[11] {
            "0" => false,
            "1" => true,
            s => return Err(cx.bad(&key(11), s, "must be 0 or 1")),
        };
        let frame = cx.frame(v[2], &key(2))?;
        let command = cx.command(v[3], &key(3))?;
        if v[0] == 0.0 {
            // Home: never a mission item on this autopilot.
            for (c, name) in [(8, "latitude"), (9, "longitude")] {
                let limit = if c == 8 { 90.0 } else { 180.0 };
                if !v[c].is_finite() || v[c].abs() > limit {
                    return Err(cx.bad(
                        &key(c),
                        cols[c],
                        format!("{name} must be within -{limit}..{limit} deg"),
                    ));
                }
            }
            home = Some((v[8], v[9], v[10]));
            continue;
        }
        let x = cx.coord(Some(v[8]), frame, Coord::Latitude, &key(8))?;
        let y = cx.coord(Some(v[9]), frame, Coord::Longitude, &key(9))?;
        if command == DO_JUMP {
            jumps.push((mission.len(), key(4)));
        }
        mission.push(item(
            mission.len(),
            command,
            frame,
            [v[4] as f32, v[5] as f32, v[6] as f32, v[7] as f32],
            x,
            y,
            v[10] as f32,
            autocontinue,
            MavMissionType::MAV_MISSION_TYPE_MISSION,
        ));
    }
    if mission.len() > usize::from(u16::MAX) {
        return Err(cx.bad(
            "<file>",
            format!("{} items", mission.len()),
            "too many items",
        ));
    }
    // WPL jump targets count home as line index 0.
    let count = mission.len();
    for (idx, key) in jumps {
        let target = mission[idx].param1;
        if target.fract() != 0.0 || target < 1.0 || target as usize > count {
            return Err(cx.bad(
                &key,
                target,
                format!("DO_JUMP target must be the index of a mission line, 1..{count}"),
            ));
        }
        mission[idx].param1 = target - 1.0;
    }
    Ok(MissionFile {
        mission,
        fence: Vec::new(),
        rally: Vec::new(),
        home,
    })
}
