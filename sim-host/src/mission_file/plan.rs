//! QGroundControl's `.plan` (JSON): mission, geofence and rally points.

use super::item::{item, Coord, Ctx, MissionFile, MissionFileError, DO_JUMP};
use common::math::geodetic::GeoPoint;
use mavlink::dialects::common::{MavCmd, MavFrame, MavMissionType, MISSION_ITEM_INT_DATA};
use serde_json::Value;
use std::path::Path;

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
            // The item's fields are 32-bit floats: a larger number would become an infinity.
            if let Some(x) = p[k].filter(|x| x.abs() > f64::from(f32::MAX)) {
                return Err(cx.bad(&format!("{ppath}[{k}]"), x, "too large for a 32-bit float"));
            }
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
                if !(radius > 0.0 && radius <= f64::from(f32::MAX)) {
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
                if p[2].abs() > f64::from(f32::MAX) {
                    let key = format!("rallyPoints.points[{i}][2]");
                    return Err(cx.bad(&key, p[2], "too large for a 32-bit float"));
                }
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
