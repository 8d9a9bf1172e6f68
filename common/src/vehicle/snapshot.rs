//! What the vehicle tells the link each tick: the state telemetry reports and the facts the
//! link needs to accept or refuse commands.

use super::modes::{FlightMode, ModeSet};

/// Where the vehicle is in its life cycle; the heartbeat's `system_status` follows from it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum LandedState {
    /// Not known (yet).
    #[default]
    Undefined,
    /// On the ground.
    OnGround,
    /// Flying.
    InAir,
    /// Taking off.
    Takeoff,
    /// Landing.
    Landing,
}

/// How far the vehicle has come through the current mission.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum MissionRunState {
    /// Mission loaded, not flown yet.
    #[default]
    NotStarted,
    /// Being flown.
    Active,
    /// Interrupted (mode changed away from Mission).
    Paused,
    /// Last item reached.
    Complete,
}

/// Health of each sensor and of the estimator. `true` means present and working.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SensorHealthReport {
    /// Rate gyros.
    pub gyro_ok: bool,
    /// Accelerometers.
    pub accel_ok: bool,
    /// Magnetometer.
    pub mag_ok: bool,
    /// Static-pressure sensor (barometer).
    pub baro_ok: bool,
    /// Differential-pressure sensor (airspeed).
    pub airspeed_ok: bool,
    /// GPS receiver delivering data (a fix is judged by [`GpsRaw::fix_type`]).
    pub gps_ok: bool,
    /// Attitude estimate converged.
    pub attitude_converged: bool,
    /// Position and velocity estimate valid (needs GPS).
    pub position_valid: bool,
}

/// The home position as reported (`HOME_POSITION`, the altitude above home).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct HomeReport {
    /// Whether home has been set.
    pub valid: bool,
    /// Latitude, degrees * 1e7.
    pub lat_e7: i32,
    /// Longitude, degrees * 1e7.
    pub lon_e7: i32,
    /// Altitude above mean sea level, m.
    pub alt_amsl_m: f32,
}

/// The GPS receiver's own solution, reported as is (`GPS_RAW_INT`).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct GpsRaw {
    /// Time of the fix, microseconds (the autopilot clock or UNIX time).
    pub time_usec: u64,
    /// MAVLink `GPS_FIX_TYPE`: 0 no GPS, 1 no fix, 2 2D, 3 3D, 4 DGPS, 5/6 RTK.
    pub fix_type: u8,
    /// Latitude, degrees * 1e7.
    pub lat_e7: i32,
    /// Longitude, degrees * 1e7.
    pub lon_e7: i32,
    /// Altitude above mean sea level, m.
    pub alt_amsl_m: f32,
    /// Horizontal dilution of precision (dimensionless); 0 when unknown.
    pub hdop: f32,
    /// Vertical dilution of precision (dimensionless); 0 when unknown.
    pub vdop: f32,
    /// Ground speed, m/s.
    pub ground_speed_m_s: f32,
    /// Course over ground, rad (0 north, clockwise).
    pub course: f32,
    /// Satellites used.
    pub satellites: u8,
}

/// Battery state: the battery monitor's report.
pub use crate::battery::Battery;

/// What the navigator and guidance are doing (`NAV_CONTROLLER_OUTPUT`).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct NavReport {
    /// Commanded roll, rad.
    pub roll_cmd: f32,
    /// Commanded pitch, rad.
    pub pitch_cmd: f32,
    /// Current desired course, rad (0 north, clockwise).
    pub course_cmd: f32,
    /// Bearing to the active waypoint, rad.
    pub target_bearing: f32,
    /// Distance to the active waypoint, m.
    pub wp_dist_m: f32,
    /// Altitude error (set point minus actual), m.
    pub alt_error_m: f32,
    /// Airspeed error (set point minus actual), m/s.
    pub airspeed_error_m_s: f32,
    /// Cross-track error, m.
    pub xtrack_error_m: f32,
}

/// Everything the link reports and checks, filled by the vehicle each tick. SI units and
/// radians unless a name says otherwise; angles of attitude are ZYX Euler angles of the body
/// frame relative to NED.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct VehicleSnapshot {
    /// Start-up finished (sensors initialised, parameters loaded). Before that the heartbeat
    /// says BOOT and arming is refused for now.
    pub boot_complete: bool,
    /// Flying against a simulator (heartbeat HIL flag).
    pub hil: bool,
    /// Motors and surfaces live.
    pub armed: bool,
    /// A failsafe is active (heartbeat CRITICAL when armed).
    pub failsafe: bool,
    /// Mode being flown.
    pub mode: FlightMode,
    /// Modes the vehicle can switch to now (mode changes to others are refused).
    pub modes_available: ModeSet,
    /// On the ground, in the air, ...
    pub landed: LandedState,
    /// Sensor and estimator health.
    pub health: SensorHealthReport,
    /// Roll, rad.
    pub roll: f32,
    /// Pitch, rad.
    pub pitch: f32,
    /// Yaw (heading), rad, 0 north, clockwise.
    pub yaw: f32,
    /// Body roll rate p, rad/s.
    pub roll_rate: f32,
    /// Body pitch rate q, rad/s.
    pub pitch_rate: f32,
    /// Body yaw rate r, rad/s.
    pub yaw_rate: f32,
    /// Estimated latitude, degrees * 1e7.
    pub lat_e7: i32,
    /// Estimated longitude, degrees * 1e7.
    pub lon_e7: i32,
    /// Estimated altitude above mean sea level, m.
    pub alt_amsl_m: f32,
    /// Estimated altitude above home, m.
    pub alt_rel_home_m: f32,
    /// Velocity north, m/s.
    pub vel_n: f32,
    /// Velocity east, m/s.
    pub vel_e: f32,
    /// Velocity down, m/s.
    pub vel_d: f32,
    /// Indicated airspeed, m/s.
    pub airspeed: f32,
    /// Airspeeds the vehicle may be asked to hold, m/s (`NAV_ASPD_MIN`, `NAV_ASPD_MAX`).
    pub airspeed_range_m_s: (f32, f32),
    /// The surfaces and throttle commanded (the throttle 0 while disarmed).
    pub outputs: crate::actuators::Surfaces,
    /// Home position.
    pub home: HomeReport,
    /// GPS receiver solution.
    pub gps: GpsRaw,
    /// Battery.
    pub battery: Battery,
    /// Navigator and guidance outputs.
    pub nav: NavReport,
    /// Index of the mission item being flown (or next to fly).
    pub mission_seq: u16,
    /// Progress through the mission.
    pub mission_state: MissionRunState,
    /// Share of the loop period used, 0..1.
    pub cpu_load: f32,
    /// What the vehicle's clock refused of the sensor frames' timestamps.
    pub clock: super::clock::ClockStats,
    /// Where the autotune stands.
    pub autotune: crate::tuning::autotune::Status,
}

impl VehicleSnapshot {
    /// Ground speed from the NED velocity, m/s.
    pub fn ground_speed(&self) -> f32 {
        libm::sqrtf(self.vel_n * self.vel_n + self.vel_e * self.vel_e)
    }
}
