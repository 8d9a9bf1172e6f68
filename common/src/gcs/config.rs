//! Who the link is and what it works with: its MAVLink identity, its settings, and the
//! vehicle's stores it borrows for each message.

use super::ftp;
use crate::navigation::plan::MissionStore;
use crate::navigation::validate::PlanRules;
use crate::params::store::ParamStore;

/// Our MAVLink system id.
pub const SYSTEM_ID: u8 = 1;
/// Our MAVLink component id (`MAV_COMP_ID_AUTOPILOT1`).
pub const COMPONENT_ID: u8 = 1;
/// Heartbeat interval, µs (1 Hz; QGC drops a vehicle after 3.5 s of silence).
pub const HEARTBEAT_INTERVAL_US: u64 = 1_000_000;

/// Settings of a link.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LinkConfig {
    /// Our system id.
    pub system_id: u8,
    /// Our component id.
    pub component_id: u8,
    /// `PARAM_VALUE`s sent per poll of the link while streaming the list: paces a full
    /// download to the link's bandwidth (a 50 Hz loop with 4 per poll sends 200 per second).
    pub params_per_poll: u8,
    /// Hardware unique id reported in `AUTOPILOT_VERSION` (0 when unknown).
    pub uid: u64,
    /// The files served over MAVLink FTP; with a `general.json` among them, the link answers
    /// requests for `COMPONENT_METADATA` with its URI.
    pub files: &'static [ftp::File],
}

impl Default for LinkConfig {
    fn default() -> Self {
        Self {
            system_id: SYSTEM_ID,
            component_id: COMPONENT_ID,
            params_per_poll: 4,
            uid: 0,
            files: &[],
        }
    }
}

/// What the link reads and writes besides the vehicle's snapshot: the parameter values, the
/// stored plan, and what a finished upload is checked against.
pub struct Stores<'a> {
    /// Every parameter of the vehicle.
    pub params: &'a mut ParamStore,
    /// The mission, geofence and rally lists.
    pub plan: &'a mut MissionStore,
    /// Home and the navigator's limits, for the upload checks.
    pub rules: PlanRules,
}
