//! What both formats are read into, and the checks they share: the items with this autopilot's
//! fixed fields, coordinates scaled into their integer fields, command and frame numbers.

use mavlink::dialects::common::{MavCmd, MavFrame, MavMissionType, MISSION_ITEM_INT_DATA};
use num_traits::FromPrimitive;
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
pub(super) const DO_JUMP: MavCmd = MavCmd::MAV_CMD_DO_JUMP;

/// A MISSION_ITEM_INT with this autopilot's fixed fields filled in.
// One argument per field that varies between items: a builder would only rename them.
#[allow(clippy::too_many_arguments)]
pub(super) fn item(
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
pub fn is_global(frame: MavFrame) -> bool {
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
pub(super) enum Coord {
    Latitude,
    Longitude,
}

/// Collects errors with the file name.
pub(super) struct Ctx<'a> {
    /// The file, named in every error.
    pub(super) file: &'a Path,
}

impl Ctx<'_> {
    /// The error for `value` at `key`, rejected for `reason`.
    pub(super) fn bad(
        &self,
        key: &str,
        value: impl ToString,
        reason: impl ToString,
    ) -> MissionFileError {
        MissionFileError::Value {
            file: self.file.to_path_buf(),
            key: key.to_string(),
            value: value.to_string(),
            reason: reason.to_string(),
        }
    }

    /// `x`/`y` of a parameter (`None` = null) in `frame`.
    pub(super) fn coord(
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

    /// The `MAV_CMD` numbered `n`.
    pub(super) fn command(&self, n: f64, key: &str) -> Result<MavCmd, MissionFileError> {
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

    /// The `MAV_FRAME` numbered `n`.
    pub(super) fn frame(&self, n: f64, key: &str) -> Result<MavFrame, MissionFileError> {
        if n.fract() != 0.0 || !(0.0..=255.0).contains(&n) {
            return Err(self.bad(key, n, "a frame number is an integer 0..255"));
        }
        MavFrame::from_u32(n as u32).ok_or_else(|| self.bad(key, n, "unknown MAV_FRAME"))
    }
}
