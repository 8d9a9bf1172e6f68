//! What the vehicle records in the flight log: each topic of [`crate::logger::topics`] filled
//! from the stages' state when the logger says it is due.
//!
//! The board calls [`Vehicle::write_log`] after each sensor frame, with that frame: the
//! sensors are logged as received, the rest as the vehicle holds it after the frame's tick.

use super::snapshot::LandedState;
use super::Vehicle;
use crate::logger::topics::*;
use crate::logger::Logger;
use crate::math::atmosphere::pressure_altitude;
use crate::math::geodetic::GeoPoint;
use crate::sensors::SensorFrame;

fn lat_lon(p: GeoPoint) -> (f64, f64) {
    (p.lat_deg(), p.lon_deg())
}

impl Vehicle {
    /// Writes every topic due at the vehicle's time; `frame` is the sensor frame just taken.
    pub fn write_log(&self, log: &mut Logger, frame: &SensorFrame) {
        // Before its first frame the vehicle has no time, and nothing to log.
        let Some(now) = self.clock.now_us().filter(|&t| log.any_due(t)) else {
            return;
        };
        // Three frames in four have nothing due at the fastest rate: the estimate is formed
        // only when something is.
        let e = self.estimator.state();
        let (states, variances, eph, epv) = self.estimator.filter_states();
        if log.due::<VehicleAttitude>(now) {
            let q = e.attitude.quaternion();
            log.write(
                now,
                &VehicleAttitude {
                    q: [q.w, q.i, q.j, q.k],
                },
            );
        }
        if let Some(imu) = frame.imu.filter(|_| log.due::<SensorCombined>(now)) {
            log.write(
                now,
                &SensorCombined {
                    gyro_rad: imu.gyro.into(),
                    accelerometer_m_s2: imu.accel.into(),
                },
            );
        }
        let sp = self.setpoints();
        if log.due::<ControlLoops>(now) {
            let s = self.surfaces;
            log.write(
                now,
                &ControlLoops {
                    course_sp: sp.course,
                    course: e.course,
                    roll_sp: self.loops.roll_cmd,
                    roll: e.euler.phi,
                    aileron: s.aileron,
                    sideslip: e.sideslip,
                    rudder: s.rudder,
                    altitude_sp: sp.alt_amsl_m,
                    altitude: e.alt_amsl_m,
                    pitch_sp: self.loops.pitch_cmd,
                    pitch: e.euler.theta,
                    elevator: s.elevator,
                    airspeed_sp: sp.airspeed,
                    airspeed: e.airspeed,
                    throttle: s.throttle,
                },
            );
        }
        if log.due::<ActuatorOutputs>(now) {
            let c = self.surfaces.to_px4_controls();
            let mut output = [0.0; 16];
            output[..4].copy_from_slice(&c);
            log.write(
                now,
                &ActuatorOutputs {
                    noutputs: 4,
                    output,
                },
            );
        }
        if log.due::<VehicleAttitudeSetpoint>(now) {
            log.write(
                now,
                &VehicleAttitudeSetpoint {
                    roll_body: self.loops.roll_cmd,
                    pitch_body: self.loops.pitch_cmd,
                    yaw_body: sp.course,
                },
            );
        }
        if log.due::<VehicleLocalPosition>(now) {
            let (ref_lat, ref_lon, ref_alt) = match e.home {
                Some(h) => {
                    let (lat, lon) = lat_lon(h.point);
                    (lat, lon, h.alt_amsl_m)
                }
                None => (f64::NAN, f64::NAN, f32::NAN),
            };
            log.write(
                now,
                &VehicleLocalPosition {
                    xy_valid: e.position_valid,
                    z_valid: e.home.is_some(),
                    v_xy_valid: e.position_valid,
                    v_z_valid: e.position_valid,
                    x: e.pos_ned.x,
                    y: e.pos_ned.y,
                    z: e.pos_ned.z,
                    vx: e.vel_ned.x,
                    vy: e.vel_ned.y,
                    vz: e.vel_ned.z,
                    heading: e.euler.psi,
                    ref_lat,
                    ref_lon,
                    ref_alt,
                    eph,
                    epv,
                },
            );
        }
        if log.due::<AirspeedValidated>(now) {
            log.write(
                now,
                &AirspeedValidated {
                    true_airspeed_m_s: e.airspeed,
                    airspeed_synthetic: e.airspeed_synthetic,
                },
            );
        }
        if let Some(b) = frame.baro.filter(|_| log.due::<VehicleAirData>(now)) {
            log.write(
                now,
                &VehicleAirData {
                    baro_alt_meter: pressure_altitude(b.pressure_pa).unwrap_or(f32::NAN),
                    baro_pressure_pa: b.pressure_pa,
                    baro_temp_celcius: b.temperature_c,
                },
            );
        }
        if let Some(p) = frame.pitot.filter(|_| log.due::<DifferentialPressure>(now)) {
            log.write(
                now,
                &DifferentialPressure {
                    differential_pressure_pa: p.diff_pressure_pa,
                },
            );
        }
        if let Some(m) = frame.mag.filter(|_| log.due::<VehicleMagnetometer>(now)) {
            log.write(
                now,
                &VehicleMagnetometer {
                    magnetometer_ga: m.field.into(),
                },
            );
        }
        if log.due::<VehicleGlobalPosition>(now) {
            let (lat, lon) = lat_lon(e.position);
            log.write(
                now,
                &VehicleGlobalPosition {
                    lat,
                    lon,
                    alt: e.alt_amsl_m,
                    dead_reckoning: e.dead_reckoning,
                },
            );
        }
        if let Some(g) = self.last_gps.filter(|_| log.due::<VehicleGpsPosition>(now)) {
            log.write(
                now,
                &VehicleGpsPosition {
                    lat: g.position.lat_e7,
                    lon: g.position.lon_e7,
                    alt: (g.alt_amsl_m * 1000.0) as i32,
                    eph: g.hdop,
                    epv: g.hdop,
                    vel_n_m_s: g.vel_ned.x,
                    vel_e_m_s: g.vel_ned.y,
                    vel_d_m_s: g.vel_ned.z,
                    fix_type: g.fix_type,
                    satellites_used: g.satellites,
                },
            );
        }
        if log.due::<Wind>(now) {
            log.write(
                now,
                &Wind {
                    windspeed_north: e.wind_ned.x,
                    windspeed_east: e.wind_ned.y,
                },
            );
        }
        if log.due::<EstimatorStates>(now) {
            let mut t = EstimatorStates {
                n_states: states.len() as u8,
                ..Default::default()
            };
            for (d, s) in t.states.iter_mut().zip(states) {
                *d = s;
            }
            for (d, s) in t.covariances.iter_mut().zip(variances) {
                *d = s;
            }
            log.write(now, &t);
        }
        let c = &self.commander;
        if log.due::<VehicleStatus>(now) {
            let mode = c.flown_mode();
            log.write(
                now,
                &VehicleStatus {
                    arming_state: if c.armed() { 2 } else { 1 },
                    nav_state: mode.px4_nav_state(),
                    failsafe: c.failsafe_active(),
                    custom_mode: mode.custom_mode(),
                },
            );
        }
        if log.due::<VehicleLandDetected>(now) {
            let state = c.landed_state();
            log.write(
                now,
                &VehicleLandDetected {
                    landed: state == LandedState::OnGround,
                    landed_state: state as u8,
                },
            );
        }
        // A reading within the last half second (a rangefinder reads at 10-50 Hz): none once
        // it has gone quiet.
        let range = self
            .last_range
            .filter(|&(t, _)| now.saturating_sub(t) <= 500_000 && log.due::<DistanceSensor>(now));
        if let Some((_, r)) = range {
            log.write(
                now,
                &DistanceSensor {
                    current_distance: r.distance_m,
                    min_distance: r.min_m,
                    max_distance: r.max_m,
                    // MAVLink's 0 (unknown) and 1 (invalid) are PX4's -1 and 0.
                    signal_quality: match r.quality {
                        0 => -1,
                        1 => 0,
                        q => i8::try_from(q.min(100)).unwrap_or(100),
                    },
                    orientation: 25,
                },
            );
        }
        if log.due::<BatteryStatus>(now) {
            let b = self.battery.report(Some(now));
            log.write(
                now,
                &BatteryStatus {
                    voltage_v: b.voltage_v,
                    current_a: b.current_a,
                    discharged_mah: b.consumed_mah,
                    remaining: b.remaining,
                    time_remaining_s: b.time_remaining_s,
                    warning: b.warning as u8,
                },
            );
        }
        if log.due::<MissionResult>(now) {
            let out = c.navigation();
            let (seq, _) = c.mission();
            log.write(
                now,
                &MissionResult {
                    seq_current: seq,
                    seq_reached: out.reached.map_or(-1, i32::from),
                    seq_total: self.plan.mission.len() as u16,
                    phase: out.phase as u8,
                },
            );
        }
    }
}

#[cfg(test)]
mod tests;
