//! Snapshot to telemetry message conversions. Units change here, at the edge: degrees,
//! centidegrees, millimetres and centimetres per second as each MAVLink field asks.

use mavlink::dialects::common::*;
use num_traits::FromPrimitive;

use crate::battery::{Battery, Warning};
use crate::vehicle::modes::FlightMode;
use crate::vehicle::snapshot::{LandedState, MissionRunState, VehicleSnapshot};

use crate::math::RAD2DEG;

/// Angle in rad to degrees in [0, 360). `%` is the exact `fmodf` (the one `wrap_pi` uses
/// too), so the image carries one copy of it.
fn heading_deg(rad: f32) -> f32 {
    let d = (rad * RAD2DEG) % 360.0;
    if d < 0.0 {
        d + 360.0
    } else {
        d
    }
}

/// Heading in centidegrees 0..35999 (`as` saturates, NaN gives 0).
fn heading_cdeg(rad: f32) -> u16 {
    ((heading_deg(rad) * 100.0) as u16).min(35_999)
}

fn time_boot_ms(now_us: u64) -> u32 {
    (now_us / 1000) as u32
}

/// The heartbeat's `base_mode`, following PX4's choice of flags per mode.
pub fn base_mode(v: &VehicleSnapshot) -> MavModeFlag {
    let m = v.mode;
    let mut f = MavModeFlag::MAV_MODE_FLAG_CUSTOM_MODE_ENABLED;
    if v.armed {
        f |= MavModeFlag::MAV_MODE_FLAG_SAFETY_ARMED;
    }
    if v.hil {
        f |= MavModeFlag::MAV_MODE_FLAG_HIL_ENABLED;
    }
    if m.manual_input() {
        f |= MavModeFlag::MAV_MODE_FLAG_MANUAL_INPUT_ENABLED;
    }
    if m.stabilized() {
        f |= MavModeFlag::MAV_MODE_FLAG_STABILIZE_ENABLED;
    }
    if m.auto() || m == FlightMode::Hold {
        f |= MavModeFlag::MAV_MODE_FLAG_GUIDED_ENABLED;
    }
    if m.auto() {
        f |= MavModeFlag::MAV_MODE_FLAG_AUTO_ENABLED;
    }
    f
}

/// The heartbeat's `system_status`.
pub fn system_status(v: &VehicleSnapshot) -> MavState {
    if !v.boot_complete {
        MavState::MAV_STATE_BOOT
    } else if v.failsafe {
        MavState::MAV_STATE_CRITICAL
    } else if v.armed {
        MavState::MAV_STATE_ACTIVE
    } else {
        MavState::MAV_STATE_STANDBY
    }
}

/// `HEARTBEAT`.
pub fn heartbeat(v: &VehicleSnapshot) -> MavMessage {
    MavMessage::HEARTBEAT(HEARTBEAT_DATA {
        custom_mode: v.mode.custom_mode(),
        mavtype: MavType::MAV_TYPE_FIXED_WING,
        autopilot: MavAutopilot::MAV_AUTOPILOT_GENERIC,
        base_mode: base_mode(v),
        system_status: system_status(v),
        mavlink_version: 3,
    })
}

/// A pre-arm check that refuses arming.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum PrearmFailure {
    /// The gyros are silent or their samples refused.
    Gyro,
    /// The accelerometers are.
    Accelerometer,
    /// The magnetometer is.
    Magnetometer,
    /// The barometer is.
    Barometer,
    /// The airspeed sensor is.
    Airspeed,
    /// The battery is below its critical level.
    BatteryCritical,
    /// The attitude estimate has not converged yet.
    AttitudeConverging,
    /// No 3D GPS fix yet.
    NoGpsFix,
    /// The position estimate is not valid yet.
    PositionInvalid,
}

impl PrearmFailure {
    /// The reason, as "Arming denied: `reason`" says it.
    pub fn reason(self) -> &'static str {
        match self {
            PrearmFailure::Gyro => "gyro unhealthy",
            PrearmFailure::Accelerometer => "accelerometer unhealthy",
            PrearmFailure::Magnetometer => "magnetometer unhealthy",
            PrearmFailure::Barometer => "barometer unhealthy",
            PrearmFailure::Airspeed => "airspeed sensor unhealthy",
            PrearmFailure::BatteryCritical => "battery critical",
            PrearmFailure::AttitudeConverging => "attitude estimate not converged",
            PrearmFailure::NoGpsFix => "no 3D GPS fix",
            PrearmFailure::PositionInvalid => "position estimate invalid",
        }
    }

    /// Whether waiting mends it: the estimator converging, the GPS receiver acquiring its
    /// fix. A failed sensor or an empty pack waits for the operator.
    pub fn passes_with_time(self) -> bool {
        match self {
            PrearmFailure::AttitudeConverging
            | PrearmFailure::NoGpsFix
            | PrearmFailure::PositionInvalid => true,
            PrearmFailure::Gyro
            | PrearmFailure::Accelerometer
            | PrearmFailure::Magnetometer
            | PrearmFailure::Barometer
            | PrearmFailure::Airspeed
            | PrearmFailure::BatteryCritical => false,
        }
    }

    /// The arming command's result, in MAVLink's sense of each: TEMPORARILY_REJECTED for what
    /// passes with time ("retrying later should work", as a station that retries on it
    /// does), DENIED for what does not ("retrying the same command will not work").
    pub fn result(self) -> MavResult {
        if self.passes_with_time() {
            MavResult::MAV_RESULT_TEMPORARILY_REJECTED
        } else {
            MavResult::MAV_RESULT_DENIED
        }
    }
}

/// Why arming must be refused, `None` when every pre-arm check passes. The checks that do not
/// pass with time come first, so a station retrying a temporary refusal is not kept waiting
/// for one that will not pass.
pub fn prearm_failure(v: &VehicleSnapshot) -> Option<PrearmFailure> {
    let h = &v.health;
    let checks = [
        (h.gyro_ok, PrearmFailure::Gyro),
        (h.accel_ok, PrearmFailure::Accelerometer),
        (h.mag_ok, PrearmFailure::Magnetometer),
        (h.baro_ok, PrearmFailure::Barometer),
        (h.airspeed_ok, PrearmFailure::Airspeed),
        (
            !(v.battery.present && v.battery.warning >= Warning::Critical),
            PrearmFailure::BatteryCritical,
        ),
        (h.attitude_converged, PrearmFailure::AttitudeConverging),
        (h.gps_ok && v.gps.fix_type >= 3, PrearmFailure::NoGpsFix),
        (h.position_valid, PrearmFailure::PositionInvalid),
    ];
    checks.iter().find(|(ok, _)| !ok).map(|&(_, why)| why)
}

/// `SYS_STATUS`.
pub fn sys_status(v: &VehicleSnapshot, rx_errors: u16) -> MavMessage {
    type S = MavSysStatusSensor;
    let h = &v.health;
    let mut present = S::MAV_SYS_STATUS_SENSOR_3D_GYRO
        | S::MAV_SYS_STATUS_SENSOR_3D_ACCEL
        | S::MAV_SYS_STATUS_SENSOR_3D_MAG
        | S::MAV_SYS_STATUS_SENSOR_ABSOLUTE_PRESSURE
        | S::MAV_SYS_STATUS_SENSOR_DIFFERENTIAL_PRESSURE
        | S::MAV_SYS_STATUS_SENSOR_GPS
        | S::MAV_SYS_STATUS_AHRS
        | S::MAV_SYS_STATUS_SENSOR_ANGULAR_RATE_CONTROL
        | S::MAV_SYS_STATUS_SENSOR_ATTITUDE_STABILIZATION
        | S::MAV_SYS_STATUS_SENSOR_YAW_POSITION
        | S::MAV_SYS_STATUS_SENSOR_Z_ALTITUDE_CONTROL
        | S::MAV_SYS_STATUS_SENSOR_XY_POSITION_CONTROL
        | S::MAV_SYS_STATUS_SENSOR_MOTOR_OUTPUTS
        | S::MAV_SYS_STATUS_PREARM_CHECK;
    if v.battery.present {
        present |= S::MAV_SYS_STATUS_SENSOR_BATTERY;
    }
    let mut health = present;
    let checks = [
        (h.gyro_ok, S::MAV_SYS_STATUS_SENSOR_3D_GYRO),
        (h.accel_ok, S::MAV_SYS_STATUS_SENSOR_3D_ACCEL),
        (h.mag_ok, S::MAV_SYS_STATUS_SENSOR_3D_MAG),
        (h.baro_ok, S::MAV_SYS_STATUS_SENSOR_ABSOLUTE_PRESSURE),
        (
            h.airspeed_ok,
            S::MAV_SYS_STATUS_SENSOR_DIFFERENTIAL_PRESSURE,
        ),
        (
            h.gps_ok && v.gps.fix_type >= 3,
            S::MAV_SYS_STATUS_SENSOR_GPS,
        ),
        (h.attitude_converged, S::MAV_SYS_STATUS_AHRS),
        (prearm_failure(v).is_none(), S::MAV_SYS_STATUS_PREARM_CHECK),
        (
            !(v.battery.present && v.battery.warning >= Warning::Low),
            S::MAV_SYS_STATUS_SENSOR_BATTERY,
        ),
    ];
    for (ok, bit) in checks {
        if !ok {
            health.remove(bit);
        }
    }
    let b = &v.battery;
    MavMessage::SYS_STATUS(SYS_STATUS_DATA {
        onboard_control_sensors_present: present,
        onboard_control_sensors_enabled: present,
        onboard_control_sensors_health: health,
        load: (v.cpu_load * 1000.0) as u16,
        voltage_battery: battery_mv(b).unwrap_or(u16::MAX),
        current_battery: battery_ca(b),
        drop_rate_comm: 0,
        errors_comm: rx_errors,
        // Autopilot-specific counters: sensor frames refused for their time, and new time
        // bases the clock took (see common::vehicle::clock).
        errors_count1: u16::try_from(v.clock.refused).unwrap_or(u16::MAX),
        errors_count2: u16::try_from(v.clock.resyncs).unwrap_or(u16::MAX),
        errors_count3: 0,
        errors_count4: 0,
        battery_remaining: battery_percent(b),
        onboard_control_sensors_present_extended: MavSysStatusSensorExtended::empty(),
        onboard_control_sensors_enabled_extended: MavSysStatusSensorExtended::empty(),
        onboard_control_sensors_health_extended: MavSysStatusSensorExtended::empty(),
    })
}

/// `ATTITUDE`.
pub fn attitude(v: &VehicleSnapshot, now_us: u64) -> MavMessage {
    MavMessage::ATTITUDE(ATTITUDE_DATA {
        time_boot_ms: time_boot_ms(now_us),
        roll: v.roll,
        pitch: v.pitch,
        yaw: v.yaw,
        rollspeed: v.roll_rate,
        pitchspeed: v.pitch_rate,
        yawspeed: v.yaw_rate,
    })
}

/// `GLOBAL_POSITION_INT`.
pub fn global_position_int(v: &VehicleSnapshot, now_us: u64) -> MavMessage {
    MavMessage::GLOBAL_POSITION_INT(GLOBAL_POSITION_INT_DATA {
        time_boot_ms: time_boot_ms(now_us),
        lat: v.lat_e7,
        lon: v.lon_e7,
        alt: (v.alt_amsl_m * 1000.0) as i32,
        relative_alt: (v.alt_rel_home_m * 1000.0) as i32,
        vx: (v.vel_n * 100.0) as i16,
        vy: (v.vel_e * 100.0) as i16,
        vz: (v.vel_d * 100.0) as i16,
        hdg: heading_cdeg(v.yaw),
    })
}

/// `GPS_RAW_INT`.
pub fn gps_raw_int(v: &VehicleSnapshot) -> MavMessage {
    let g = &v.gps;
    let dop = |d: f32| {
        if d > 0.0 {
            (d * 100.0) as u16
        } else {
            u16::MAX
        }
    };
    MavMessage::GPS_RAW_INT(GPS_RAW_INT_DATA {
        time_usec: g.time_usec,
        lat: g.lat_e7,
        lon: g.lon_e7,
        alt: (g.alt_amsl_m * 1000.0) as i32,
        eph: dop(g.hdop),
        epv: dop(g.vdop),
        vel: (g.ground_speed_m_s * 100.0) as u16,
        cog: heading_cdeg(g.course),
        fix_type: GpsFixType::from_u8(g.fix_type).unwrap_or(GpsFixType::GPS_FIX_TYPE_NO_GPS),
        satellites_visible: g.satellites,
        alt_ellipsoid: 0,
        h_acc: 0,
        v_acc: 0,
        vel_acc: 0,
        hdg_acc: 0,
        yaw: 0,
    })
}

/// `VFR_HUD`.
pub fn vfr_hud(v: &VehicleSnapshot) -> MavMessage {
    MavMessage::VFR_HUD(VFR_HUD_DATA {
        airspeed: v.airspeed,
        groundspeed: v.ground_speed(),
        alt: v.alt_amsl_m,
        climb: -v.vel_d,
        heading: heading_deg(v.yaw) as i16,
        throttle: (v.outputs.throttle.clamp(0.0, 1.0) * 100.0) as u16,
    })
}

/// `SERVO_OUTPUT_RAW` of output port 0: aileron, elevator, rudder and throttle on servos 1-4
/// as [`crate::actuators::Surfaces::to_pwm_us`] maps them; `time_usec` the boot clock (µs,
/// wrapping with its 32 bits every 71 min, as the message has it).
pub fn servo_output_raw(v: &VehicleSnapshot, now_us: u64) -> MavMessage {
    let [servo1_raw, servo2_raw, servo3_raw, servo4_raw] = v.outputs.to_pwm_us();
    MavMessage::SERVO_OUTPUT_RAW(SERVO_OUTPUT_RAW_DATA {
        time_usec: now_us as u32,
        servo1_raw,
        servo2_raw,
        servo3_raw,
        servo4_raw,
        ..Default::default()
    })
}

/// `NAV_CONTROLLER_OUTPUT`.
pub fn nav_controller_output(v: &VehicleSnapshot) -> MavMessage {
    let n = &v.nav;
    MavMessage::NAV_CONTROLLER_OUTPUT(NAV_CONTROLLER_OUTPUT_DATA {
        nav_roll: n.roll_cmd * RAD2DEG,
        nav_pitch: n.pitch_cmd * RAD2DEG,
        alt_error: n.alt_error_m,
        aspd_error: n.airspeed_error_m_s,
        xtrack_error: n.xtrack_error_m,
        nav_bearing: heading_deg(n.course_cmd) as i16,
        target_bearing: heading_deg(n.target_bearing) as i16,
        wp_dist: n.wp_dist_m as u16,
    })
}

/// `HOME_POSITION`; `None` while home is not set.
pub fn home_position(v: &VehicleSnapshot, now_us: u64) -> Option<MavMessage> {
    let h = &v.home;
    if !h.valid {
        return None;
    }
    Some(MavMessage::HOME_POSITION(HOME_POSITION_DATA {
        latitude: h.lat_e7,
        longitude: h.lon_e7,
        altitude: (h.alt_amsl_m * 1000.0) as i32,
        // The local frame's origin is home.
        x: 0.0,
        y: 0.0,
        z: 0.0,
        q: [1.0, 0.0, 0.0, 0.0],
        approach_x: 0.0,
        approach_y: 0.0,
        approach_z: 0.0,
        time_usec: now_us,
    }))
}

/// `EXTENDED_SYS_STATE`.
pub fn extended_sys_state(v: &VehicleSnapshot) -> MavMessage {
    MavMessage::EXTENDED_SYS_STATE(EXTENDED_SYS_STATE_DATA {
        vtol_state: MavVtolState::MAV_VTOL_STATE_UNDEFINED,
        landed_state: match v.landed {
            LandedState::Undefined => MavLandedState::MAV_LANDED_STATE_UNDEFINED,
            LandedState::OnGround => MavLandedState::MAV_LANDED_STATE_ON_GROUND,
            LandedState::InAir => MavLandedState::MAV_LANDED_STATE_IN_AIR,
            LandedState::Takeoff => MavLandedState::MAV_LANDED_STATE_TAKEOFF,
            LandedState::Landing => MavLandedState::MAV_LANDED_STATE_LANDING,
        },
    })
}

/// Pack voltage in mV (UINT16_MAX - 1 at most: UINT16_MAX means unknown); `None` when no
/// battery is monitored.
fn battery_mv(b: &Battery) -> Option<u16> {
    b.present
        .then(|| libm::roundf(b.voltage_v * 1000.0).clamp(0.0, 65_534.0) as u16)
}

/// Current in cA, -1 when no battery is monitored.
fn battery_ca(b: &Battery) -> i16 {
    if b.present {
        libm::roundf(b.current_a * 100.0).clamp(-32_768.0, 32_767.0) as i16
    } else {
        -1
    }
}

/// Charge left in %, -1 when no battery is monitored.
fn battery_percent(b: &Battery) -> i8 {
    if b.present {
        libm::roundf(b.remaining * 100.0).clamp(0.0, 100.0) as i8
    } else {
        -1
    }
}

/// `BATTERY_STATUS`: the pack voltage in `voltages[0]` (cells are not reported one by one),
/// the current, the charge (mAh) and energy (hJ) used, the charge left, the time remaining
/// and the monitor's warning as the charge state; unknown values as MAVLink marks them.
pub fn battery_status(v: &VehicleSnapshot) -> MavMessage {
    let b = &v.battery;
    let mut voltages = [u16::MAX; 10];
    voltages[0] = battery_mv(b).unwrap_or(u16::MAX);
    let whole = |x: f32| libm::roundf(x).clamp(0.0, i32::MAX as f32) as i32;
    MavMessage::BATTERY_STATUS(BATTERY_STATUS_DATA {
        current_consumed: if b.present { whole(b.consumed_mah) } else { -1 },
        // 1 Wh = 3600 J = 36 hJ.
        energy_consumed: if b.present {
            whole(b.energy_wh * 36.0)
        } else {
            -1
        },
        temperature: i16::MAX,
        voltages,
        current_battery: battery_ca(b),
        id: 0,
        battery_function: MavBatteryFunction::MAV_BATTERY_FUNCTION_ALL,
        mavtype: MavBatteryType::MAV_BATTERY_TYPE_LIPO,
        battery_remaining: battery_percent(b),
        // 0: not estimated.
        time_remaining: if b.present && b.time_remaining_s > 0.0 {
            whole(b.time_remaining_s).max(1)
        } else {
            0
        },
        charge_state: match (b.present, b.warning) {
            (false, _) => MavBatteryChargeState::MAV_BATTERY_CHARGE_STATE_UNDEFINED,
            (true, Warning::None) => MavBatteryChargeState::MAV_BATTERY_CHARGE_STATE_OK,
            (true, Warning::Low) => MavBatteryChargeState::MAV_BATTERY_CHARGE_STATE_LOW,
            (true, Warning::Critical) => MavBatteryChargeState::MAV_BATTERY_CHARGE_STATE_CRITICAL,
            (true, Warning::Emergency) => MavBatteryChargeState::MAV_BATTERY_CHARGE_STATE_EMERGENCY,
        },
        voltages_ext: [0; 4],
        mode: MavBatteryMode::MAV_BATTERY_MODE_UNKNOWN,
        fault_bitmask: MavBatteryFault::empty(),
    })
}

/// `MISSION_CURRENT` for item `seq` of a mission of `total` items.
pub fn mission_current(
    v: &VehicleSnapshot,
    seq: u16,
    total: u16,
    ids: (u32, u32, u32),
) -> MavMessage {
    MavMessage::MISSION_CURRENT(MISSION_CURRENT_DATA {
        seq,
        // MAVLink: UINT16_MAX when no mission is stored.
        total: if total == 0 { u16::MAX } else { total },
        mission_state: if total == 0 {
            MissionState::MISSION_STATE_NO_MISSION
        } else {
            match v.mission_state {
                MissionRunState::NotStarted => MissionState::MISSION_STATE_NOT_STARTED,
                MissionRunState::Active => MissionState::MISSION_STATE_ACTIVE,
                MissionRunState::Paused => MissionState::MISSION_STATE_PAUSED,
                MissionRunState::Complete => MissionState::MISSION_STATE_COMPLETE,
            }
        },
        mission_mode: if v.mode == FlightMode::Mission { 1 } else { 2 },
        mission_id: ids.0,
        fence_id: ids.1,
        rally_points_id: ids.2,
    })
}

/// `CURRENT_MODE`.
pub fn current_mode(v: &VehicleSnapshot, intended: FlightMode) -> MavMessage {
    MavMessage::CURRENT_MODE(CURRENT_MODE_DATA {
        custom_mode: v.mode.custom_mode(),
        intended_custom_mode: intended.custom_mode(),
        standard_mode: v.mode.standard(),
    })
}

/// `AVAILABLE_MODES` entry for `mode`.
pub fn available_mode(index: usize, mode: FlightMode) -> MavMessage {
    MavMessage::AVAILABLE_MODES(AVAILABLE_MODES_DATA {
        custom_mode: mode.custom_mode(),
        properties: mode.properties(),
        number_modes: FlightMode::ALL.len() as u8,
        mode_index: index.saturating_add(1) as u8,
        standard_mode: mode.standard(),
        mode_name: mode.name().into(),
    })
}
