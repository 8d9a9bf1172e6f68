//! What the vehicle reports: its [`VehicleSnapshot`], built from the estimate and the
//! commander's state, which the ground link turns into telemetry and checks commands against.

use super::commander::Commander;
use super::modes::{ModeSet, Needs, MODES};
use super::snapshot::{GpsRaw, HomeReport, NavReport, SensorHealthReport, VehicleSnapshot};
use crate::battery::Battery;
use crate::estimator::EstimatedState;
use crate::math::{course_and_speed, wrap_two_pi};
use crate::sensors::GpsFix;

/// Everything besides the estimate and the commander that the snapshot reports.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Extras {
    /// The vehicle's clock (the time of the last sensor frame), us; `None` before the first.
    pub time_us: Option<u64>,
    /// The last accepted GPS fix.
    pub gps: Option<GpsFix>,
    /// The surfaces and throttle commanded.
    pub outputs: crate::actuators::Surfaces,
    /// The clock's counters.
    pub clock: super::clock::ClockStats,
    /// The battery monitor's report.
    pub battery: Battery,
    /// Airspeeds the vehicle may be asked to hold, m/s (the navigator's settings).
    pub airspeed_range_m_s: (f32, f32),
    /// Where the autotune stands.
    pub autotune: crate::tuning::autotune::Status,
}

/// The modes the vehicle can fly with this estimate: each mode's [`Needs`] from the table of
/// mode facts (attitude for the altitude hold, a position for Hold, a position and a home
/// for the navigator's modes).
pub fn available_modes(e: &EstimatedState) -> ModeSet {
    let mut modes = ModeSet::EMPTY;
    for f in &MODES {
        let met = match f.needs {
            Needs::Nothing => true,
            Needs::Attitude => e.converged || e.attitude_valid,
            Needs::Position => e.position_valid,
            Needs::PositionAndHome => e.position_valid && e.home.is_some(),
        };
        if met {
            modes = modes.with(f.mode);
        }
    }
    modes
}

/// The snapshot of a vehicle.
pub fn snapshot(e: &EstimatedState, c: &Commander, x: &Extras) -> VehicleSnapshot {
    let h = &e.health;
    let health = SensorHealthReport {
        gyro_ok: h.imu.healthy,
        accel_ok: h.imu.healthy,
        mag_ok: h.mag.healthy,
        baro_ok: h.baro.healthy,
        airspeed_ok: h.pitot.healthy,
        gps_ok: h.gps.healthy,
        attitude_converged: e.converged,
        position_valid: e.position_valid,
    };
    let home = e.home.map_or(HomeReport::default(), |h| HomeReport {
        valid: true,
        lat_e7: h.point.lat_e7,
        lon_e7: h.point.lon_e7,
        alt_amsl_m: h.alt_amsl_m,
    });
    let gps = x.gps.map_or(GpsRaw::default(), |g| {
        let (course, speed) = course_and_speed(&g.vel_ned);
        GpsRaw {
            time_usec: x.time_us.unwrap_or(0),
            fix_type: g.fix_type,
            lat_e7: g.position.lat_e7,
            lon_e7: g.position.lon_e7,
            alt_amsl_m: g.alt_amsl_m,
            hdop: g.hdop,
            vdop: g.hdop * 1.5,
            ground_speed_m_s: speed,
            course: wrap_two_pi(course),
            satellites: g.satellites,
        }
    });
    let (mission_seq, mission_state) = c.mission();
    VehicleSnapshot {
        boot_complete: x.time_us.is_some(),
        hil: true,
        armed: c.armed(),
        failsafe: c.failsafe_active(),
        mode: c.flown_mode(),
        modes_available: available_modes(e),
        landed: c.landed_state(),
        health,
        roll: e.euler.phi,
        pitch: e.euler.theta,
        yaw: e.euler.psi,
        roll_rate: e.body_rates.x,
        pitch_rate: e.body_rates.y,
        yaw_rate: e.body_rates.z,
        lat_e7: e.position.lat_e7,
        lon_e7: e.position.lon_e7,
        alt_amsl_m: e.alt_amsl_m,
        alt_rel_home_m: e.alt_amsl_m - home.alt_amsl_m,
        vel_n: e.vel_ned.x,
        vel_e: e.vel_ned.y,
        vel_d: e.vel_ned.z,
        airspeed: e.airspeed,
        airspeed_range_m_s: x.airspeed_range_m_s,
        outputs: crate::actuators::Surfaces {
            throttle: if c.armed() { x.outputs.throttle } else { 0.0 },
            ..x.outputs
        },
        home,
        gps,
        battery: x.battery,
        nav: nav_telemetry(e, c),
        mission_seq,
        mission_state,
        cpu_load: 0.0,
        clock: x.clock,
        autotune: x.autotune,
    }
}

/// NAV_CONTROLLER_OUTPUT from the navigator's last step (zeros outside navigation modes).
fn nav_telemetry(e: &EstimatedState, c: &Commander) -> NavReport {
    if !c.flown_mode().needs_navigator() {
        return NavReport::default();
    }
    let finite = |x: f32| if x.is_finite() { x } else { 0.0 };
    let nav = c.navigation();
    let g = nav.guidance;
    NavReport {
        roll_cmd: 0.0,
        pitch_cmd: 0.0,
        course_cmd: g.map_or(0.0, |g| wrap_two_pi(g.course)),
        target_bearing: finite(wrap_two_pi(nav.target_bearing)),
        wp_dist_m: finite(nav.wp_dist_m),
        alt_error_m: g.map_or(0.0, |g| finite(g.altitude + e.pos_ned.z)),
        airspeed_error_m_s: g.map_or(0.0, |g| finite(g.airspeed - e.airspeed)),
        xtrack_error_m: g.map_or(0.0, |g| finite(g.cross_track)),
    }
}
