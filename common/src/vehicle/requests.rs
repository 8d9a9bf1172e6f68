//! What a ground station may ask of the vehicle. The ground link checks each request against
//! the vehicle's snapshot and queues it; the vehicle takes the queue and acts on it.

use super::modes::FlightMode;
use crate::sensors::ManualInput;

/// An arming or disarming request the link accepted.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ArmRequest {
    /// `true` to arm, `false` to disarm.
    pub arm: bool,
    /// Forced (param2 = 21196): checks skipped, disarm even in the air.
    pub forced: bool,
}

/// What the ground station asked the vehicle to do, after the link's checks. The vehicle takes
/// these with [`crate::gcs::GroundLink::take_requests`] and acts on them.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct VehicleRequests {
    /// Arm or disarm.
    pub arm: Option<ArmRequest>,
    /// Switch to this mode.
    pub mode: Option<FlightMode>,
    /// Make this mission item the current one.
    pub mission_seq: Option<u16>,
    /// New altitude setpoint (`MAV_CMD_DO_CHANGE_ALTITUDE`).
    pub altitude: Option<AltitudeSetpoint>,
    /// New airspeed setpoint, m/s (`MAV_CMD_DO_CHANGE_SPEED`, airspeed type).
    pub airspeed: Option<f32>,
    /// New course setpoint, rad in [0, 2 pi) (`MAV_CMD_CONDITION_YAW`, absolute or relative).
    pub course: Option<CourseSetpoint>,
    /// The latest stick positions (`MANUAL_CONTROL`: QGC's virtual joystick or a gamepad).
    pub manual: Option<ManualInput>,
    /// Give up the landing being flown (`MAV_CMD_DO_GO_AROUND`).
    pub go_around: bool,
    /// Start (`true`) or stop an autotune, or put back the gains the last one replaced
    /// (`false`) (`MAV_CMD_DO_AUTOTUNE_ENABLE`).
    pub autotune: Option<bool>,
}

/// An altitude the ground station asked for.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct AltitudeSetpoint {
    /// Altitude, m.
    pub alt_m: f32,
    /// `true`: above home (`MAV_FRAME_GLOBAL_RELATIVE_ALT`); `false`: above mean sea level.
    pub relative_to_home: bool,
}

/// A course the ground station asked for.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct CourseSetpoint {
    /// Angle, rad.
    pub angle: f32,
    /// `true`: added to the current course (direction already applied); `false`: absolute.
    pub relative: bool,
}
