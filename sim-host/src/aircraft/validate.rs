//! The physical sense of an aircraft file's values: positive masses and stiffnesses, a positive
//! definite inertia, ordered limits, one propeller and one motor model, a taildragger's or a
//! tricycle's gear below the CG.

use super::{Aircraft, AircraftError, GearLayout, MAX_BELLY_POINTS};
use std::path::Path;

impl Aircraft {
    /// Checks the physical sense of every value.
    pub fn validate(&self, file: &Path) -> Result<(), AircraftError> {
        let bad = |key: &str, value: String, reason: &str| AircraftError::Value {
            file: file.to_path_buf(),
            key: key.to_string(),
            value,
            reason: reason.to_string(),
        };
        let positive = |key: &str, v: f64| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(bad(key, v.to_string(), "must be positive"))
            }
        };
        let non_negative = |key: &str, v: f64| {
            if v.is_finite() && v >= 0.0 {
                Ok(())
            } else {
                Err(bad(key, v.to_string(), "must not be negative"))
            }
        };
        let ordered = |key: &str, v: [f64; 2]| {
            if v[0] < v[1] {
                Ok(())
            } else {
                Err(bad(
                    key,
                    format!("{v:?}"),
                    "must be [min, max] with min < max",
                ))
            }
        };
        let m = &self.mass;
        positive("mass.mass_kg", m.mass_kg)?;
        positive("mass.Jx_kgm2", m.Jx_kgm2)?;
        positive("mass.Jy_kgm2", m.Jy_kgm2)?;
        positive("mass.Jz_kgm2", m.Jz_kgm2)?;
        if m.Jx_kgm2 * m.Jz_kgm2 - m.Jxz_kgm2 * m.Jxz_kgm2 <= 0.0 {
            return Err(bad(
                "mass.Jxz_kgm2",
                m.Jxz_kgm2.to_string(),
                &format!(
                    "inertia not positive definite: Jx*Jz - Jxz^2 = {:.6} <= 0",
                    m.Jx_kgm2 * m.Jz_kgm2 - m.Jxz_kgm2 * m.Jxz_kgm2
                ),
            ));
        }
        let g = &self.geometry;
        positive("geometry.b_m", g.b_m)?;
        positive("geometry.S_m2", g.S_m2)?;
        positive("geometry.c_m", g.c_m)?;
        positive("aero.drag.oswald_e", self.aero.drag.oswald_e)?;
        non_negative("aero.drag.CD_min", self.aero.drag.CD_min)?;
        let p = &self.propulsion;
        positive("propulsion.prop_radius_m", p.prop_radius_m)?;
        positive("propulsion.Jmp_kgm2", p.Jmp_kgm2)?;
        ordered("propulsion.J_clamp", p.J_clamp)?;
        non_negative("propulsion.J_clamp", p.J_clamp[0])?;
        let missing = |key: &str, reason: &str| AircraftError::Shape {
            file: file.to_path_buf(),
            key: key.to_string(),
            message: reason.to_string(),
        };
        match (&p.CP_poly_J, &p.CQ_poly_J) {
            (Some(_), None) | (None, Some(_)) => {}
            (Some(cq), Some(_)) => {
                return Err(bad(
                    "propulsion.CQ_poly_J",
                    format!("{cq:?}"),
                    "give CP_poly_J or CQ_poly_J, not both",
                ))
            }
            (None, None) => {
                return Err(missing(
                    "propulsion.CP_poly_J",
                    "missing: the propeller's torque needs CP_poly_J (power coefficient) or CQ_poly_J (torque coefficient)",
                ))
            }
        }
        match (&p.motor_power_poly_throttle_W, &p.motor_power_clamp_W, &p.dc_motor) {
            (Some(_), Some(clamp), None) => {
                ordered("propulsion.motor_power_clamp_W", *clamp)?;
            }
            (None, None, Some(m)) => {
                positive("propulsion.dc_motor.KV_rpm_per_V", m.KV_rpm_per_V)?;
                positive("propulsion.dc_motor.resistance_ohm", m.resistance_ohm)?;
                non_negative("propulsion.dc_motor.no_load_current_A", m.no_load_current_A)?;
                positive("propulsion.dc_motor.max_voltage_V", m.max_voltage_V)?;
            }
            (Some(_), None, None) => {
                return Err(missing(
                    "propulsion.motor_power_clamp_W",
                    "missing: the power curve needs its clamp",
                ))
            }
            (None, Some(_), None) => {
                return Err(missing(
                    "propulsion.motor_power_poly_throttle_W",
                    "missing: the clamp needs its power curve",
                ))
            }
            (_, _, Some(_)) => {
                return Err(missing(
                    "propulsion.dc_motor",
                    "give either the power curve (motor_power_poly_throttle_W, motor_power_clamp_W) or [propulsion.dc_motor], not both",
                ))
            }
            (None, None, None) => {
                return Err(missing(
                    "propulsion.motor_power_poly_throttle_W",
                    "missing: the motor needs a power curve (motor_power_poly_throttle_W, motor_power_clamp_W) or a [propulsion.dc_motor] table",
                ))
            }
        }
        ordered("propulsion.omega_limits_radps", p.omega_limits_radps)?;
        // Qm = P / Omega: the lower engine-speed limit keeps the division finite.
        positive("propulsion.omega_limits_radps", p.omega_limits_radps[0])?;
        let b = &self.battery;
        if !(1..=14).contains(&b.cells) {
            return Err(bad(
                "battery.cells",
                b.cells.to_string(),
                "must be within 1..14 cells",
            ));
        }
        positive("battery.capacity_mAh", b.capacity_mAh)?;
        non_negative("battery.internal_resistance_ohm", b.internal_resistance_ohm)?;
        non_negative("battery.avionics_power_W", b.avionics_power_W)?;
        if !(b.motor_esc_efficiency > 0.0 && b.motor_esc_efficiency <= 1.0) {
            return Err(bad(
                "battery.motor_esc_efficiency",
                b.motor_esc_efficiency.to_string(),
                "must be within 0 (excluded) and 1",
            ));
        }
        if !(0.0..=1.0).contains(&b.initial_soc) {
            return Err(bad(
                "battery.initial_soc",
                b.initial_soc.to_string(),
                "must be within 0..1",
            ));
        }
        let a = &self.actuators;
        positive("actuators.bandwidth_Hz", a.bandwidth_Hz)?;
        positive("actuators.rate_limit_radps", a.rate_limit_radps)?;
        ordered("actuators.position_limit_rad", a.position_limit_rad)?;
        if let Err((key, value, reason)) = self.sensors.validate() {
            return Err(bad(&key, value, reason));
        }
        let e = &self.environment;
        positive("environment.g_mps2", e.g_mps2)?;
        if !(-90.0..=90.0).contains(&e.home_lat_deg) {
            return Err(bad(
                "environment.home_lat_deg",
                e.home_lat_deg.to_string(),
                "must be within -90..90 deg",
            ));
        }
        if !(-180.0..=180.0).contains(&e.home_lon_deg) {
            return Err(bad(
                "environment.home_lon_deg",
                e.home_lon_deg.to_string(),
                "must be within -180..180 deg",
            ));
        }
        if let Some(perf) = &self.performance {
            positive("performance.cruise_airspeed_mps", perf.cruise_airspeed_mps)?;
        }
        self.validate_ground(file)
    }

    /// Checks the `[ground]` table: a taildragger's or a tricycle's gear standing below the CG.
    fn validate_ground(&self, file: &Path) -> Result<(), AircraftError> {
        let bad = |key: &str, value: String, reason: &str| AircraftError::Value {
            file: file.to_path_buf(),
            key: format!("ground.{key}"),
            value,
            reason: reason.to_string(),
        };
        let gr = &self.ground;
        let has_tail = gr.tail_wheel_m.is_some()
            || gr.tail_stiffness_Npm.is_some()
            || gr.tail_damping_Nspm.is_some()
            || gr.tail_steer_per_rudder.is_some();
        let has_nose = gr.nose_wheel_m.is_some()
            || gr.nose_stiffness_Npm.is_some()
            || gr.nose_damping_Nspm.is_some()
            || gr.nose_steer_per_rudder.is_some();
        let shape = |key: &str, message: &str| AircraftError::Shape {
            file: file.to_path_buf(),
            key: format!("ground.{key}"),
            message: message.to_string(),
        };
        if has_tail && has_nose {
            return Err(shape(
                "nose_wheel_m",
                "a [ground] table gives the tail_* keys (a taildragger) or the nose_* keys (tricycle gear), not both",
            ));
        }
        let prefix = if has_nose { "nose" } else { "tail" };
        for (name, given) in [
            (
                "wheel_m",
                [gr.tail_wheel_m.is_some(), gr.nose_wheel_m.is_some()],
            ),
            (
                "stiffness_Npm",
                [
                    gr.tail_stiffness_Npm.is_some(),
                    gr.nose_stiffness_Npm.is_some(),
                ],
            ),
            (
                "damping_Nspm",
                [
                    gr.tail_damping_Nspm.is_some(),
                    gr.nose_damping_Nspm.is_some(),
                ],
            ),
            (
                "steer_per_rudder",
                [
                    gr.tail_steer_per_rudder.is_some(),
                    gr.nose_steer_per_rudder.is_some(),
                ],
            ),
        ] {
            if !given[usize::from(has_nose)] {
                return Err(shape(
                    &format!("{prefix}_{name}"),
                    "missing: the gear's third wheel needs its position, stiffness, damping and steering (tail_* for a taildragger, nose_* for tricycle gear)",
                ));
            }
        }
        let Some(third) = gr.third_wheel() else {
            return Err(shape("tail_wheel_m", "missing"));
        };
        for (key, v) in [
            ("main_stiffness_Npm".to_string(), gr.main_stiffness_Npm),
            (format!("{prefix}_stiffness_Npm"), third.stiffness_Npm),
            ("belly_stiffness_Npm".to_string(), gr.belly_stiffness_Npm),
            ("slip_speed_mps".to_string(), gr.slip_speed_mps),
        ] {
            if v.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
                return Err(bad(&key, v.to_string(), "must be positive"));
            }
        }
        for (key, v) in [
            ("main_damping_Nspm".to_string(), gr.main_damping_Nspm),
            (format!("{prefix}_damping_Nspm"), third.damping_Nspm),
            ("belly_damping_Nspm".to_string(), gr.belly_damping_Nspm),
        ] {
            if v.partial_cmp(&0.0) == Some(std::cmp::Ordering::Less) || !v.is_finite() {
                return Err(bad(&key, v.to_string(), "must not be negative"));
            }
        }
        for (key, v) in [
            ("mu_roll", gr.mu_roll),
            ("mu_side", gr.mu_side),
            ("mu_belly", gr.mu_belly),
        ] {
            if !(0.0..=2.0).contains(&v) {
                return Err(bad(key, v.to_string(), "must be within 0..2"));
            }
        }
        if !(-2.0..=2.0).contains(&third.steer_per_rudder) {
            return Err(bad(
                &format!("{prefix}_steer_per_rudder"),
                third.steer_per_rudder.to_string(),
                "must be within -2..2",
            ));
        }
        let point = |key: &str, v: [f64; 3], ok: bool, reason: &str| {
            if ok {
                Ok(())
            } else {
                Err(bad(key, format!("{v:?}"), reason))
            }
        };
        let (l, r, t) = (gr.main_wheel_left_m, gr.main_wheel_right_m, third.pos_m);
        match third.layout {
            GearLayout::Taildragger => {
                point(
                    "main_wheel_left_m",
                    l,
                    l[0] > 0.0 && l[1] < 0.0 && l[2] > 0.0,
                    "a taildragger's left main wheel is ahead of (x > 0), left of (y < 0) and below (z > 0) the CG",
                )?;
                point(
                    "main_wheel_right_m",
                    r,
                    r[0] > 0.0 && r[1] > 0.0 && r[2] > 0.0,
                    "a taildragger's right main wheel is ahead of (x > 0), right of (y > 0) and below (z > 0) the CG",
                )?;
                point(
                    "tail_wheel_m",
                    t,
                    t[0] < 0.0 && t[2] > 0.0,
                    "the tail wheel is behind (x < 0) and below (z > 0) the CG",
                )?;
            }
            GearLayout::Tricycle => {
                point(
                    "main_wheel_left_m",
                    l,
                    l[0] < 0.0 && l[1] < 0.0 && l[2] > 0.0,
                    "a tricycle's left main wheel is behind (x < 0), left of (y < 0) and below (z > 0) the CG",
                )?;
                point(
                    "main_wheel_right_m",
                    r,
                    r[0] < 0.0 && r[1] > 0.0 && r[2] > 0.0,
                    "a tricycle's right main wheel is behind (x < 0), right of (y > 0) and below (z > 0) the CG",
                )?;
                point(
                    "nose_wheel_m",
                    t,
                    t[0] > 0.0 && t[2] > 0.0,
                    "the nose wheel is ahead of (x > 0) and below (z > 0) the CG",
                )?;
            }
        }
        let max_belly = MAX_BELLY_POINTS;
        if gr.belly_points_m.len() > max_belly {
            return Err(bad(
                "belly_points_m",
                format!("{} points", gr.belly_points_m.len()),
                &format!("at most {max_belly} belly points"),
            ));
        }
        for (i, p) in gr.belly_points_m.iter().enumerate() {
            if p.iter().any(|c| c.abs() > 10.0) {
                return Err(bad(
                    &format!("belly_points_m[{i}]"),
                    format!("{p:?}"),
                    "must be within 10 m of the CG",
                ));
            }
        }
        Ok(())
    }
}
