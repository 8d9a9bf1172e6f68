//! The topics of the flight log: PX4's names and fields where PX4 has the topic, so
//! PlotJuggler's and Flight Review's layouts find them; the project's own where it has none
//! (the thesis's loops, the navigator's phase).
//!
//! Each topic is a plain struct (`ulog_topic!`): the format a reader is told and the bytes
//! written come from the same field list.

use crate::ulog_topic;

ulog_topic! {
    /// The attitude estimate.
    VehicleAttitude = "vehicle_attitude" {
        /// Body-to-NED quaternion, w x y z (Hamilton, as PX4).
        q: [f32; 4],
    }
}

ulog_topic! {
    /// Position and velocity in the local NED frame whose origin is `ref_lat`, `ref_lon`,
    /// `ref_alt`.
    VehicleLocalPosition = "vehicle_local_position" {
        /// Horizontal position valid (the filter has seen GPS).
        xy_valid: bool,
        /// Vertical position valid.
        z_valid: bool,
        /// Horizontal velocity valid.
        v_xy_valid: bool,
        /// Vertical velocity valid.
        v_z_valid: bool,
        /// North, m.
        x: f32,
        /// East, m.
        y: f32,
        /// Down, m.
        z: f32,
        /// North velocity, m/s.
        vx: f32,
        /// East velocity, m/s.
        vy: f32,
        /// Down velocity, m/s.
        vz: f32,
        /// Heading (yaw), rad.
        heading: f32,
        /// Origin's latitude, deg.
        ref_lat: f64,
        /// Origin's longitude, deg.
        ref_lon: f64,
        /// Origin's altitude above mean sea level, m.
        ref_alt: f32,
        /// Standard deviation of the horizontal position, m.
        eph: f32,
        /// Standard deviation of the vertical position, m.
        epv: f32,
    }
}

ulog_topic! {
    /// Position on the globe.
    VehicleGlobalPosition = "vehicle_global_position" {
        /// Latitude, deg.
        lat: f64,
        /// Longitude, deg.
        lon: f64,
        /// Altitude above mean sea level, m.
        alt: f32,
        /// Carried by dead reckoning (GPS lost).
        dead_reckoning: bool,
    }
}

ulog_topic! {
    /// The inertial sensors as received.
    SensorCombined = "sensor_combined" {
        /// Angular rate, body axes, rad/s.
        gyro_rad: [f32; 3],
        /// Specific force, body axes, m/s^2.
        accelerometer_m_s2: [f32; 3],
    }
}

ulog_topic! {
    /// The magnetometer as received.
    VehicleMagnetometer = "vehicle_magnetometer" {
        /// Field, body axes, gauss.
        magnetometer_ga: [f32; 3],
    }
}

ulog_topic! {
    /// The barometer as received, and the altitude it gives.
    VehicleAirData = "vehicle_air_data" {
        /// Pressure altitude, m.
        baro_alt_meter: f32,
        /// Static pressure, Pa.
        baro_pressure_pa: f32,
        /// Temperature, degC.
        baro_temp_celcius: f32,
    }
}

ulog_topic! {
    /// The pitot's differential pressure as received.
    DifferentialPressure = "differential_pressure" {
        /// Differential pressure, Pa.
        differential_pressure_pa: f32,
    }
}

ulog_topic! {
    /// The airspeed the autopilot flies on.
    AirspeedValidated = "airspeed_validated" {
        /// True airspeed, m/s.
        true_airspeed_m_s: f32,
        /// Ground speed minus the last wind estimate, the pitot having failed.
        airspeed_synthetic: bool,
    }
}

ulog_topic! {
    /// The GPS fix as received.
    VehicleGpsPosition = "vehicle_gps_position" {
        /// Latitude, 1e-7 deg.
        lat: i32,
        /// Longitude, 1e-7 deg.
        lon: i32,
        /// Altitude above mean sea level, mm.
        alt: i32,
        /// Horizontal dilution of precision.
        eph: f32,
        /// Vertical dilution of precision.
        epv: f32,
        /// North velocity, m/s.
        vel_n_m_s: f32,
        /// East velocity, m/s.
        vel_e_m_s: f32,
        /// Down velocity, m/s.
        vel_d_m_s: f32,
        /// Fix type (0-1 none, 2 2D, 3 3D).
        fix_type: u8,
        /// Satellites used.
        satellites_used: u8,
    }
}

ulog_topic! {
    /// The wind estimate.
    Wind = "wind" {
        /// North component (velocity of the air mass), m/s.
        windspeed_north: f32,
        /// East component, m/s.
        windspeed_east: f32,
    }
}

ulog_topic! {
    /// The navigation filter's states and the diagonal of its covariance (PX4's layout: the
    /// first `n_states` entries are used).
    EstimatorStates = "estimator_states" {
        /// States.
        states: [f32; 24],
        /// States used.
        n_states: u8,
        /// Variances of the states.
        covariances: [f32; 24],
    }
}

ulog_topic! {
    /// The attitude the outer loops ask for.
    VehicleAttitudeSetpoint = "vehicle_attitude_setpoint" {
        /// Roll, rad.
        roll_body: f32,
        /// Pitch, rad.
        pitch_body: f32,
        /// Course (the heading loop's setpoint), rad.
        yaw_body: f32,
    }
}

ulog_topic! {
    /// Every loop of the successive-loop-closure autopilot: setpoint, measurement and output.
    ControlLoops = "control_loops" {
        /// Course setpoint, rad.
        course_sp: f32,
        /// Course over ground, rad.
        course: f32,
        /// Roll setpoint (the course loop's output), rad.
        roll_sp: f32,
        /// Roll, rad.
        roll: f32,
        /// Aileron (the roll loop's output), rad, UMN sign.
        aileron: f32,
        /// Sideslip, rad.
        sideslip: f32,
        /// Rudder (the sideslip loop's output), rad, UMN sign.
        rudder: f32,
        /// Altitude setpoint above mean sea level, m.
        altitude_sp: f32,
        /// Altitude above mean sea level, m.
        altitude: f32,
        /// Pitch setpoint (the altitude or energy loop's output), rad.
        pitch_sp: f32,
        /// Pitch, rad.
        pitch: f32,
        /// Elevator (the pitch loop's output), rad, UMN sign.
        elevator: f32,
        /// Airspeed setpoint, m/s.
        airspeed_sp: f32,
        /// Airspeed, m/s.
        airspeed: f32,
        /// Throttle (the airspeed or energy loop's output), 0..1.
        throttle: f32,
    }
}

ulog_topic! {
    /// What the autopilot sends its actuators: HIL_ACTUATOR_CONTROLS's controls (PX4's
    /// normalised sense).
    ActuatorOutputs = "actuator_outputs" {
        /// Outputs used.
        noutputs: u32,
        /// Roll, pitch, yaw in -1..1, throttle in 0..1, the rest 0.
        output: [f32; 16],
    }
}

ulog_topic! {
    /// Arming and mode.
    VehicleStatus = "vehicle_status" {
        /// PX4's arming state: 1 disarmed, 2 armed.
        arming_state: u8,
        /// PX4's navigation state of the mode flown.
        nav_state: u8,
        /// A failsafe reaction is flying the aircraft.
        failsafe: bool,
        /// The heartbeat's `custom_mode` of the mode flown (PX4's main and sub mode).
        custom_mode: u32,
    }
}

ulog_topic! {
    /// The land detector.
    VehicleLandDetected = "vehicle_land_detected" {
        /// On the ground.
        landed: bool,
        /// MAVLink's MAV_LANDED_STATE.
        landed_state: u8,
    }
}

ulog_topic! {
    /// The downward rangefinder's readings as received (PX4's fields; written while readings
    /// arrive, none without a rangefinder).
    DistanceSensor = "distance_sensor" {
        /// Distance along the sensor's axis, m (at or over `max_distance`: no echo in range).
        current_distance: f32,
        /// Shortest distance the sensor measures, m.
        min_distance: f32,
        /// Longest distance the sensor measures, m.
        max_distance: f32,
        /// Signal quality: -1 unknown, 0 invalid, 1..100 poor to perfect (PX4's scale).
        signal_quality: i8,
        /// MAV_SENSOR_ORIENTATION: 25, pitch 270 (downward).
        orientation: u8,
    }
}

ulog_topic! {
    /// The flight pack.
    BatteryStatus = "battery_status" {
        /// Voltage, V.
        voltage_v: f32,
        /// Current, A.
        current_a: f32,
        /// Charge used, mAh.
        discharged_mah: f32,
        /// State of charge, 0..1.
        remaining: f32,
        /// Time left at the present draw, s.
        time_remaining_s: f32,
        /// Warning level (MAV_BATTERY_CHARGE_STATE less one: 0 none ... 3 emergency).
        warning: u8,
    }
}

ulog_topic! {
    /// The mission and the navigator.
    MissionResult = "mission_result" {
        /// The item flown to.
        seq_current: u16,
        /// The last item reached, or -1.
        seq_reached: i32,
        /// Items in the mission.
        seq_total: u16,
        /// The navigator's phase (the project's numbering: docs/LOGGING.md).
        phase: u8,
    }
}

ulog_topic! {
    /// The ground link.
    TelemetryStatus = "telemetry_status" {
        /// Frames received and accepted.
        rx_message_count: u32,
        /// Frames rejected (bad checksum, unknown, bad signature).
        rx_error_count: u32,
        /// Frames the link could not send (its buffer full).
        tx_dropped_count: u32,
        /// Time since the station was last heard, ms (u32::MAX: never).
        heartbeat_age_ms: u32,
    }
}
