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

pub mod item;
pub mod plan;
pub mod wpl;

use std::path::Path;

pub use item::{MissionFile, MissionFileError};
pub use plan::parse_plan;
pub use wpl::parse_wpl;

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
