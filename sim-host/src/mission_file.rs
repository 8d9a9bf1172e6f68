//! Mission files: QGroundControl's `.plan` (JSON) and the plain-text `QGC WPL 110` format, read
//! into the `MISSION_ITEM_INT` items the autopilot's mission protocol carries.
//!
//! Conventions of this autopilot that the reader applies:
//! - home is not item 0: the `.plan`'s `plannedHomePosition` and the WPL file's line 0 become
//!   [`MissionFile::home`], and item 0 is the first thing to fly;
//! - a DO_JUMP's target (`param1`) is the item's index in [`MissionFile::mission`]: in a `.plan`
//!   it is written as a `doJumpId`, in a WPL file as a line index counting home as 0, and both
//!   are translated;
//! - global frames carry latitude and longitude as degE7; `MAV_FRAME_MISSION` items carry
//!   `param5`/`param6` as plain integers; local frames as metres * 1e4 (the MAVLink
//!   `MISSION_ITEM_INT` field definitions);
//! - a `null` parameter (the `.plan`'s way of writing NaN, "no change") is NaN in
//!   `param1..4` and `z`; in `x`/`y`, which are integers, it is 0;
//! - every item has `current = 0` and targets system 1, component 1 (the autopilot).
//!
//! Every rejection names the file, the place (a JSON path such as `mission.items[3].params[4]`,
//! or `line 5, column 9`) and the value.

use common::math::geodetic::GeoPoint;
use mavlink::dialects::common::{MavCmd, MavFrame, MavMissionType, MISSION_ITEM_INT_DATA};
use num_traits::FromPrimitive;
use serde_json::Value;
use std::path::{Path, PathBuf};

/// What a mission file holds, ready for the mission protocol.
#[derive(Clone, Debug, PartialEq)]
pub struct MissionFile {
    /// Mission items, `seq` 0.. in order (`mission_type` MISSION).
    pub mission: Vec<MISSION_ITEM_INT_DATA>,
    /// Geofence items: polygon vertices (`param1` = vertex count) and circles (`param1` =
    /// radius, m), `mission_type` FENCE.
    pub fence: Vec<MISSION_ITEM_INT_DATA>,
    /// Rally points, `mission_type` RALLY, altitude relative to home.
    pub rally: Vec<MISSION_ITEM_INT_DATA>,
    /// Planned home: latitude and longitude in degrees, altitude above mean sea level in m.
    pub home: Option<(f64, f64, f64)>,
}

/// A rejected mission file.
#[derive(Debug, thiserror::Error)]
pub enum MissionFileError {
    /// The file could not be read.
    #[error("cannot read mission file `{file}`: {source}")]
    Read {
        /// The file asked for.
        file: PathBuf,
        /// The operating-system error.
        source: std::io::Error,
    },
    /// The file is not valid JSON (a `.plan`) or not a WPL file.
    #[error("mission file `{file}`: {at}: {message}")]
    Syntax {
        /// The file.
        file: PathBuf,
        /// Where (`line L, column C`).
        at: String,
        /// What is wrong.
        message: String,
    },
    /// A value is missing, malformed, out of range or not supported.
    #[error("mission file `{file}`: {key} = {value}: {reason}")]
    Value {
        /// The file.
        file: PathBuf,
        /// JSON path (`mission.items[3].params[4]`) or `line L, column C (name)`.
        key: String,
        /// The rejected value as written (`<missing>` when absent).
        value: String,
        /// Why it is rejected.
        reason: String,
    },
}

/// `MAV_CMD_DO_JUMP`.
const DO_JUMP: MavCmd = MavCmd::MAV_CMD_DO_JUMP;

/// Reads a mission file, `.plan` (JSON) or `QGC WPL 110` text, told apart by their content.
pub fn read_mission_file(path: &Path) -> Result<MissionFile, MissionFileError> {
    let text = std::fs::read_to_string(path).map_err(|source| MissionFileError::Read {
        file: path.to_path_buf(),
        source,
    })?;
    parse_mission_text(&text, path)
}

/// Parses mission text: a WPL file if its first line starts with `QGC WPL`, a `.plan`
/// otherwise; `file` names it in errors.
pub fn parse_mission_text(text: &str, file: &Path) -> Result<MissionFile, MissionFileError> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    if text.trim_start().starts_with("QGC WPL") {
        parse_wpl(text, file)
    } else {
        parse_plan(text, file)
    }
}

/// A MISSION_ITEM_INT with this autopilot's fixed fields filled in.
// One argument per field that varies between items: a builder would only rename them.
#[allow(clippy::too_many_arguments)]
fn item(
    seq: usize,
    command: MavCmd,
    frame: MavFrame,
    params: [f32; 4],
    x: i32,
    y: i32,
    z: f32,
    autocontinue: bool,
    mission_type: MavMissionType,
) -> MISSION_ITEM_INT_DATA {
    MISSION_ITEM_INT_DATA {
        param1: params[0],
        param2: params[1],
        param3: params[2],
        param4: params[3],
        x,
        y,
        z,
        // Plans beyond 65535 items are rejected before this is reached.
        seq: seq as u16,
        command,
        target_system: 1,
        target_component: 1,
        frame,
        current: 0,
        autocontinue: u8::from(autocontinue),
        mission_type,
    }
}

/// Whether `frame` carries latitude/longitude in x/y.
#[allow(deprecated)]
fn is_global(frame: MavFrame) -> bool {
    matches!(
        frame,
        MavFrame::MAV_FRAME_GLOBAL
            | MavFrame::MAV_FRAME_GLOBAL_RELATIVE_ALT
            | MavFrame::MAV_FRAME_GLOBAL_INT
            | MavFrame::MAV_FRAME_GLOBAL_RELATIVE_ALT_INT
            | MavFrame::MAV_FRAME_GLOBAL_TERRAIN_ALT
            | MavFrame::MAV_FRAME_GLOBAL_TERRAIN_ALT_INT
    )
}

/// Which of `param5`/`param6` a coordinate is (their ranges differ in global frames).
#[derive(Clone, Copy, PartialEq)]
enum Coord {
    Latitude,
    Longitude,
}

/// Collects errors with the file name.
struct Ctx<'a> {
    file: &'a Path,
}

impl Ctx<'_> {
    fn bad(&self, key: &str, value: impl ToString, reason: impl ToString) -> MissionFileError {
        MissionFileError::Value {
            file: self.file.to_path_buf(),
            key: key.to_string(),
            value: value.to_string(),
            reason: reason.to_string(),
        }
    }

    /// `x`/`y` of a parameter (`None` = null) in `frame`.
    fn coord(
        &self,
        v: Option<f64>,
        frame: MavFrame,
        which: Coord,
        key: &str,
    ) -> Result<i32, MissionFileError> {
        let Some(v) = v else { return Ok(0) };
        if !v.is_finite() {
            return Err(self.bad(key, v, "must be a finite number"));
        }
        let scaled = if is_global(frame) {
            let (limit, name) = match which {
                Coord::Latitude => (90.0, "latitude"),
                Coord::Longitude => (180.0, "longitude"),
            };
            if v.abs() > limit {
                return Err(self.bad(
                    key,
                    v,
                    format!("{name} must be within -{limit}..{limit} deg"),
                ));
            }
            (v * 1e7).round()
        } else if frame == MavFrame::MAV_FRAME_MISSION {
            v.round()
        } else {
            (v * 1e4).round()
        };
        if scaled < f64::from(i32::MIN) || scaled > f64::from(i32::MAX) {
            return Err(self.bad(key, v, "does not fit the item's 32-bit integer field"));
        }
        Ok(scaled as i32)
    }

    fn command(&self, n: f64, key: &str) -> Result<MavCmd, MissionFileError> {
        if n.fract() != 0.0 || !(0.0..=65535.0).contains(&n) {
            return Err(self.bad(key, n, "a command number is an integer 0..65535"));
        }
        MavCmd::from_u32(n as u32).ok_or_else(|| {
            self.bad(
                key,
                n,
                "unknown MAV_CMD (not in the MAVLink common dialect)",
            )
        })
    }

    fn frame(&self, n: f64, key: &str) -> Result<MavFrame, MissionFileError> {
        if n.fract() != 0.0 || !(0.0..=255.0).contains(&n) {
            return Err(self.bad(key, n, "a frame number is an integer 0..255"));
        }
        MavFrame::from_u32(n as u32).ok_or_else(|| self.bad(key, n, "unknown MAV_FRAME"))
    }
}

// ------------------------------------------------------------------------------------- .plan

/// Compact JSON text of a value for error messages.
fn show(v: &Value) -> String {
    let s = v.to_string();
    if s.len() > 60 {
        format!(
            "{}...",
            &s[..s.char_indices().nth(57).map_or(s.len(), |(i, _)| i)]
        )
    } else {
        s
    }
}

impl Ctx<'_> {
    fn field<'v>(
        &self,
        obj: &'v Value,
        key: &str,
        path: &str,
    ) -> Result<&'v Value, MissionFileError> {
        obj.get(key)
            .ok_or_else(|| self.bad(&join(path, key), "<missing>", "required"))
    }

    fn object<'v>(&self, v: &'v Value, path: &str) -> Result<&'v Value, MissionFileError> {
        if v.is_object() {
            Ok(v)
        } else {
            Err(self.bad(path, show(v), "must be an object"))
        }
    }

    fn array<'v>(&self, v: &'v Value, path: &str) -> Result<&'v Vec<Value>, MissionFileError> {
        v.as_array()
            .ok_or_else(|| self.bad(path, show(v), "must be an array"))
    }

    fn number(&self, v: &Value, path: &str) -> Result<f64, MissionFileError> {
        v.as_f64()
            .ok_or_else(|| self.bad(path, show(v), "must be a number"))
    }

    /// A number or `null` (`None`).
    fn nullable(&self, v: &Value, path: &str) -> Result<Option<f64>, MissionFileError> {
        if v.is_null() {
            Ok(None)
        } else {
            self.number(v, path).map(Some)
        }
    }

    fn boolean(&self, v: &Value, path: &str) -> Result<bool, MissionFileError> {
        v.as_bool()
            .ok_or_else(|| self.bad(path, show(v), "must be true or false"))
    }

    fn version(&self, obj: &Value, path: &str, want: i64) -> Result<(), MissionFileError> {
        let v = self.field(obj, "version", path)?;
        if v.as_i64() == Some(want) {
            Ok(())
        } else {
            Err(self.bad(
                &join(path, "version"),
                show(v),
                format!("only version {want} is supported"),
            ))
        }
    }

    /// `[lat, lon]` or `[lat, lon, alt]` in degrees.
    fn position(&self, v: &Value, path: &str, n: usize) -> Result<Vec<f64>, MissionFileError> {
        let a = self.array(v, path)?;
        if a.len() != n {
            return Err(self.bad(path, show(v), format!("must hold {n} numbers")));
        }
        let mut out = Vec::with_capacity(n);
        for (i, x) in a.iter().enumerate() {
            let key = format!("{path}[{i}]");
            let x = self.number(x, &key)?;
            let limit = if i == 0 { 90.0 } else { 180.0 };
            if i < 2 && x.abs() > limit {
                let name = if i == 0 { "latitude" } else { "longitude" };
                return Err(self.bad(
                    &key,
                    x,
                    format!("{name} must be within -{limit}..{limit} deg"),
                ));
            }
            out.push(x);
        }
        Ok(out)
    }
}

fn join(path: &str, key: &str) -> String {
    if path.is_empty() {
        key.to_string()
    } else {
        format!("{path}.{key}")
    }
}

/// Parses a QGroundControl `.plan` (file version 1, mission version 2, geofence and rally
/// version 2); `file` names it in errors.
pub fn parse_plan(text: &str, file: &Path) -> Result<MissionFile, MissionFileError> {
    let cx = Ctx { file };
    let root: Value = serde_json::from_str(text).map_err(|e| MissionFileError::Syntax {
        file: file.to_path_buf(),
        at: format!("line {}, column {}", e.line(), e.column()),
        message: format!("not valid JSON: {e}"),
    })?;
    cx.object(&root, "<top level>")?;
    let file_type = cx.field(&root, "fileType", "")?;
    if file_type.as_str() != Some("Plan") {
        return Err(cx.bad("fileType", show(file_type), "must be \"Plan\""));
    }
    cx.version(&root, "", 1)?;

    let mission = cx.object(cx.field(&root, "mission", "")?, "mission")?;
    cx.version(mission, "mission", 2)?;
    let home = match mission.get("plannedHomePosition") {
        None | Some(Value::Null) => None,
        Some(v) => {
            let p = cx.position(v, "mission.plannedHomePosition", 3)?;
            Some((p[0], p[1], p[2]))
        }
    };
    let items = cx.array(cx.field(mission, "items", "mission")?, "mission.items")?;
    let mut out = Vec::with_capacity(items.len());
    // (index in `out`, path of its param1) of each DO_JUMP, resolved once every doJumpId is known.
    let mut jumps = Vec::new();
    let mut jump_ids = std::collections::HashMap::new();
    for (i, it) in items.iter().enumerate() {
        let path = format!("mission.items[{i}]");
        cx.object(it, &path)?;
        let ty = cx.field(it, "type", &path)?;
        match ty.as_str() {
            Some("SimpleItem") => {}
            Some("ComplexItem") => {
                let kind = it
                    .get("complexItemType")
                    .map_or_else(|| "<no complexItemType>".to_string(), show);
                return Err(cx.bad(
                    &join(&path, "complexItemType"),
                    kind,
                    "complex items (survey, corridor scan, structure scan, landing patterns) are not supported: expand them into simple items in QGroundControl",
                ));
            }
            _ => {
                return Err(cx.bad(
                    &join(&path, "type"),
                    show(ty),
                    "must be \"SimpleItem\" or \"ComplexItem\"",
                ))
            }
        }
        let key = join(&path, "command");
        let command = cx.command(cx.number(cx.field(it, "command", &path)?, &key)?, &key)?;
        let key = join(&path, "frame");
        let frame = cx.frame(cx.number(cx.field(it, "frame", &path)?, &key)?, &key)?;
        let autocontinue = cx.boolean(
            cx.field(it, "autoContinue", &path)?,
            &join(&path, "autoContinue"),
        )?;
        let ppath = join(&path, "params");
        let params = cx.array(cx.field(it, "params", &path)?, &ppath)?;
        if params.len() != 7 {
            return Err(cx.bad(
                &ppath,
                format!("{} values", params.len()),
                "must hold 7 values (param1..param7)",
            ));
        }
        let mut p = [None; 7];
        for (k, v) in params.iter().enumerate() {
            p[k] = cx.nullable(v, &format!("{ppath}[{k}]"))?;
        }
        let f32_or_nan = |v: Option<f64>| v.map_or(f32::NAN, |x| x as f32);
        let x = cx.coord(p[4], frame, Coord::Latitude, &format!("{ppath}[4]"))?;
        let y = cx.coord(p[5], frame, Coord::Longitude, &format!("{ppath}[5]"))?;
        if let Some(id) = it.get("doJumpId") {
            let key = join(&path, "doJumpId");
            let n = cx.number(id, &key)?;
            if n.fract() != 0.0 || n < 0.0 {
                return Err(cx.bad(&key, show(id), "must be a non-negative integer"));
            }
            if jump_ids.insert(n as u64, out.len()).is_some() {
                return Err(cx.bad(&key, show(id), "used by an earlier item too"));
            }
        }
        if command == DO_JUMP {
            jumps.push((out.len(), format!("{ppath}[0]")));
        }
        out.push(item(
            out.len(),
            command,
            frame,
            [
                f32_or_nan(p[0]),
                f32_or_nan(p[1]),
                f32_or_nan(p[2]),
                f32_or_nan(p[3]),
            ],
            x,
            y,
            f32_or_nan(p[6]),
            autocontinue,
            MavMissionType::MAV_MISSION_TYPE_MISSION,
        ));
    }
    if out.len() > usize::from(u16::MAX) {
        return Err(cx.bad(
            "mission.items",
            format!("{} items", out.len()),
            "too many items",
        ));
    }
    for (idx, key) in jumps {
        let target = out[idx].param1;
        let seq = (target.fract() == 0.0 && target >= 0.0)
            .then(|| jump_ids.get(&(target as u64)))
            .flatten()
            .ok_or_else(|| {
                cx.bad(
                    &key,
                    target,
                    "DO_JUMP target is not the doJumpId of any item",
                )
            })?;
        out[idx].param1 = *seq as f32;
    }

    let mut fence = Vec::new();
    if let Some(gf) = root.get("geoFence") {
        cx.object(gf, "geoFence")?;
        cx.version(gf, "geoFence", 2)?;
        if let Some(polys) = gf.get("polygons") {
            for (i, poly) in cx.array(polys, "geoFence.polygons")?.iter().enumerate() {
                let path = format!("geoFence.polygons[{i}]");
                cx.object(poly, &path)?;
                let inclusion = match poly.get("inclusion") {
                    None => true,
                    Some(v) => cx.boolean(v, &join(&path, "inclusion"))?,
                };
                let vpath = join(&path, "polygon");
                let verts = cx.array(cx.field(poly, "polygon", &path)?, &vpath)?;
                if verts.len() < 3 {
                    return Err(cx.bad(
                        &vpath,
                        format!("{} vertices", verts.len()),
                        "a polygon needs at least 3 vertices",
                    ));
                }
                let command = if inclusion {
                    MavCmd::MAV_CMD_NAV_FENCE_POLYGON_VERTEX_INCLUSION
                } else {
                    MavCmd::MAV_CMD_NAV_FENCE_POLYGON_VERTEX_EXCLUSION
                };
                for (k, v) in verts.iter().enumerate() {
                    let p = cx.position(v, &format!("{vpath}[{k}]"), 2)?;
                    fence.push(fence_item(
                        fence.len(),
                        command,
                        verts.len() as f32,
                        p[0],
                        p[1],
                    ));
                }
            }
        }
        if let Some(circles) = gf.get("circles") {
            for (i, c) in cx.array(circles, "geoFence.circles")?.iter().enumerate() {
                let path = format!("geoFence.circles[{i}]");
                cx.object(c, &path)?;
                let inclusion =
                    cx.boolean(cx.field(c, "inclusion", &path)?, &join(&path, "inclusion"))?;
                let cpath = join(&path, "circle");
                let circle = cx.object(cx.field(c, "circle", &path)?, &cpath)?;
                let centre = cx.position(
                    cx.field(circle, "center", &cpath)?,
                    &join(&cpath, "center"),
                    2,
                )?;
                let rkey = join(&cpath, "radius");
                let radius = cx.number(cx.field(circle, "radius", &cpath)?, &rkey)?;
                if !(radius > 0.0 && radius.is_finite()) {
                    return Err(cx.bad(&rkey, radius, "must be a positive distance in m"));
                }
                let command = if inclusion {
                    MavCmd::MAV_CMD_NAV_FENCE_CIRCLE_INCLUSION
                } else {
                    MavCmd::MAV_CMD_NAV_FENCE_CIRCLE_EXCLUSION
                };
                fence.push(fence_item(
                    fence.len(),
                    command,
                    radius as f32,
                    centre[0],
                    centre[1],
                ));
            }
        }
    }

    let mut rally = Vec::new();
    if let Some(rp) = root.get("rallyPoints") {
        cx.object(rp, "rallyPoints")?;
        cx.version(rp, "rallyPoints", 2)?;
        if let Some(points) = rp.get("points") {
            for (i, v) in cx.array(points, "rallyPoints.points")?.iter().enumerate() {
                let p = cx.position(v, &format!("rallyPoints.points[{i}]"), 3)?;
                let g = GeoPoint::from_deg(p[0], p[1]);
                rally.push(item(
                    rally.len(),
                    MavCmd::MAV_CMD_NAV_RALLY_POINT,
                    MavFrame::MAV_FRAME_GLOBAL_RELATIVE_ALT,
                    [0.0; 4],
                    g.lat_e7,
                    g.lon_e7,
                    p[2] as f32,
                    true,
                    MavMissionType::MAV_MISSION_TYPE_RALLY,
                ));
            }
        }
    }

    Ok(MissionFile {
        mission: out,
        fence,
        rally,
        home,
    })
}

fn fence_item(
    seq: usize,
    command: MavCmd,
    param1: f32,
    lat: f64,
    lon: f64,
) -> MISSION_ITEM_INT_DATA {
    let g = GeoPoint::from_deg(lat, lon);
    item(
        seq,
        command,
        MavFrame::MAV_FRAME_GLOBAL,
        [param1, 0.0, 0.0, 0.0],
        g.lat_e7,
        g.lon_e7,
        0.0,
        true,
        MavMissionType::MAV_MISSION_TYPE_FENCE,
    )
}

// ---------------------------------------------------------------------------------- QGC WPL

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
