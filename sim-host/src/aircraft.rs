//! The aircraft file: the Ultra Stick 25e model parameters, read from TOML and validated.
//!
//! The file's keys mirror the Minnesota configuration script one to one (hence names such as
//! `CL_alpha`), so every value can be checked against its source comment. Loading goes in four
//! steps, each failing with the file, the dotted key and the value it rejects:
//! TOML syntax, non-finite numbers (TOML accepts `nan` and `inf`), shape (unknown, missing or
//! mistyped keys, through `deny_unknown_fields`), then physical sense (positive mass, a positive
//! definite inertia, ordered limits, ...).
#![allow(non_snake_case)]

use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The aircraft file shipped with the simulator, compiled in so the binary runs from any directory.
pub const DEFAULT_AIRCRAFT_TOML: &str = include_str!("../aircraft/ultrastick25e.toml");
/// The name under which errors in the built-in file are reported.
pub const DEFAULT_AIRCRAFT_NAME: &str = "<built-in>/sim-host/aircraft/ultrastick25e.toml";

/// A rejected aircraft file.
#[derive(Debug, thiserror::Error)]
pub enum AircraftError {
    /// The file could not be read.
    #[error("cannot read aircraft file `{file}`: {source}")]
    Read {
        /// The file asked for.
        file: PathBuf,
        /// The operating-system error.
        source: std::io::Error,
    },
    /// The file is not valid TOML.
    #[error("aircraft file `{file}` is not valid TOML: {message}")]
    Syntax {
        /// The file.
        file: PathBuf,
        /// The parser's message (with line and column).
        message: String,
    },
    /// A key is unknown, missing or of the wrong type.
    #[error("aircraft file `{file}`: key `{key}`: {message}")]
    Shape {
        /// The file.
        file: PathBuf,
        /// Dotted path of the offending key (`.` for the top level).
        key: String,
        /// What is wrong.
        message: String,
    },
    /// A value is out of its physical range.
    #[error("aircraft file `{file}`: key `{key}` = {value}: {reason}")]
    Value {
        /// The file.
        file: PathBuf,
        /// Dotted path of the offending key.
        key: String,
        /// The rejected value as written.
        value: String,
        /// Why it is rejected.
        reason: String,
    },
}

/// Mass and inertia. The inertia matrix is `[[Jx,0,-Jxz],[0,Jy,0],[-Jxz,0,Jz]]`.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Mass {
    /// Mass, kg.
    pub mass_kg: f64,
    /// Roll moment of inertia, kg m^2.
    pub Jx_kgm2: f64,
    /// Pitch moment of inertia, kg m^2.
    pub Jy_kgm2: f64,
    /// Yaw moment of inertia, kg m^2.
    pub Jz_kgm2: f64,
    /// Product of inertia, kg m^2 (enters the matrix as `-Jxz`).
    pub Jxz_kgm2: f64,
}

/// Reference geometry and force application points.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Geometry {
    /// Wing span, m.
    pub b_m: f64,
    /// Wing area, m^2.
    pub S_m2: f64,
    /// Mean aerodynamic chord, m.
    pub c_m: f64,
    /// Point where the aerodynamic force acts, from the CG, body axes, m.
    pub aero_arm_from_cg_m: [f64; 3],
    /// Point where the thrust acts, from the CG, body axes, m.
    pub prop_arm_from_cg_m: [f64; 3],
}

/// Lift coefficient derivatives (wind axes).
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Lift {
    /// Lift at zero angle of attack.
    pub CL0: f64,
    /// Per rad of angle of attack.
    pub CL_alpha: f64,
    /// Per unit `q c / (2 Va)`.
    pub CL_q: f64,
    /// Per rad of elevator.
    pub CL_de: f64,
    /// Per rad of aileron, half per side, symmetric.
    pub CL_da: f64,
    /// Per rad of flap, half per side, symmetric.
    pub CL_df: f64,
}

/// Drag polar and control drag (wind axes).
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Drag {
    /// Minimum drag.
    pub CD_min: f64,
    /// Lift coefficient at minimum drag.
    pub CL_at_CD_min: f64,
    /// Oswald efficiency.
    pub oswald_e: f64,
    /// Elevator drag, `|CD_de de|`.
    pub CD_de: f64,
    /// Aileron drag, half per side, `|CD_da/2 d|`.
    pub CD_da: f64,
    /// Rudder drag, `|CD_dr dr|`.
    pub CD_dr: f64,
    /// Flap drag, half per side.
    pub CD_df: f64,
}

/// Side-force derivatives (wind axes).
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Side {
    /// Per rad of sideslip.
    pub CY_beta: f64,
    /// Per unit `p b / (2 Va)`.
    pub CY_p: f64,
    /// Per unit `r b / (2 Va)`.
    pub CY_r: f64,
    /// Per rad of rudder.
    pub CY_dr: f64,
    /// Per rad of aileron, half per side, antisymmetric.
    pub CY_da: f64,
}

/// Rolling-moment derivatives (body axes).
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Roll {
    /// Per rad of sideslip.
    pub Cl_beta: f64,
    /// Per unit `p b / (2 Va)`.
    pub Cl_p: f64,
    /// Per unit `r b / (2 Va)`.
    pub Cl_r: f64,
    /// Per rad of combined aileron.
    pub Cl_da: f64,
    /// Per rad of rudder.
    pub Cl_dr: f64,
    /// Per rad of differential flap.
    pub Cl_df: f64,
}

/// Pitching-moment derivatives (body axes).
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Pitch {
    /// Pitching moment at zero angle of attack.
    pub Cm0: f64,
    /// Per rad of angle of attack.
    pub Cm_alpha: f64,
    /// Per unit `q c / (2 Va)`.
    pub Cm_q: f64,
    /// Per rad of elevator.
    pub Cm_de: f64,
    /// Per rad of aileron, half per side, symmetric.
    pub Cm_da: f64,
    /// Per rad of flap, half per side, symmetric.
    pub Cm_df: f64,
}

/// Yawing-moment derivatives (body axes).
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Yaw {
    /// Per rad of sideslip.
    pub Cn_beta: f64,
    /// Per unit `p b / (2 Va)`.
    pub Cn_p: f64,
    /// Per unit `r b / (2 Va)`.
    pub Cn_r: f64,
    /// Per rad of combined aileron.
    pub Cn_da: f64,
    /// Per rad of rudder.
    pub Cn_dr: f64,
    /// Per rad of differential flap.
    pub Cn_df: f64,
}

/// The aerodynamic derivative set.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Aero {
    /// Lift.
    pub lift: Lift,
    /// Drag.
    pub drag: Drag,
    /// Side force.
    pub side: Side,
    /// Rolling moment.
    pub roll: Roll,
    /// Pitching moment.
    pub pitch: Pitch,
    /// Yawing moment.
    pub yaw: Yaw,
}

/// Electric motor and propeller.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Propulsion {
    /// Propeller radius, m.
    pub prop_radius_m: f64,
    /// Thrust coefficient polynomial in the advance ratio, highest power first.
    pub CT_poly_J: [f64; 5],
    /// Power coefficient polynomial in the advance ratio, highest power first.
    pub CP_poly_J: [f64; 5],
    /// Range the advance ratio is clamped to.
    pub J_clamp: [f64; 2],
    /// Motor shaft power in throttle, W, highest power first.
    pub motor_power_poly_throttle_W: [f64; 3],
    /// Range the motor power is clamped to, W.
    pub motor_power_clamp_W: [f64; 2],
    /// Motor plus propeller inertia, kg m^2.
    pub Jmp_kgm2: f64,
    /// Range of the engine speed, rad/s.
    pub omega_limits_radps: [f64; 2],
}

/// Servo model parameters (all surfaces alike).
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Actuators {
    /// First-order bandwidth, Hz.
    pub bandwidth_Hz: f64,
    /// Rate limit, rad/s.
    pub rate_limit_radps: f64,
    /// Position limits `[min, max]`, rad.
    pub position_limit_rad: [f64; 2],
}

/// Gravity and the home point.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Environment {
    /// Gravitational acceleration, m/s^2 (flat earth, constant).
    pub g_mps2: f64,
    /// Home latitude, deg.
    pub home_lat_deg: f64,
    /// Home longitude, deg.
    pub home_lon_deg: f64,
    /// Altitude above mean sea level of the NED origin, m.
    pub home_alt_msl_m: f64,
}

/// Landing gear and belly contact with the ground (a taildragger: two main wheels ahead of the
/// CG, a tail wheel steered by the rudder).
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Ground {
    /// Left main wheel's ground contact point from the CG, body axes, m.
    pub main_wheel_left_m: [f64; 3],
    /// Right main wheel's ground contact point from the CG, body axes, m.
    pub main_wheel_right_m: [f64; 3],
    /// Tail wheel's ground contact point from the CG, body axes, m.
    pub tail_wheel_m: [f64; 3],
    /// Points of the fuselage and wings that touch in a belly or wing-tip landing, body axes, m.
    pub belly_points_m: Vec<[f64; 3]>,
    /// Stiffness of each main wheel's leg and tyre, N/m.
    pub main_stiffness_Npm: f64,
    /// Damping of each main wheel, N s/m.
    pub main_damping_Nspm: f64,
    /// Stiffness of the tail wheel's spring, N/m.
    pub tail_stiffness_Npm: f64,
    /// Damping of the tail wheel, N s/m.
    pub tail_damping_Nspm: f64,
    /// Stiffness of a belly point, N/m.
    pub belly_stiffness_Npm: f64,
    /// Damping of a belly point, N s/m.
    pub belly_damping_Nspm: f64,
    /// Rolling friction coefficient of the wheels (no brakes).
    pub mu_roll: f64,
    /// Side friction coefficient of the wheels.
    pub mu_side: f64,
    /// Sliding friction coefficient of the belly points.
    pub mu_belly: f64,
    /// Slip speed below which friction grows smoothly from zero, m/s.
    pub slip_speed_mps: f64,
    /// Tail-wheel heading per rudder deflection (the wheel turns with the rudder).
    pub tail_steer_per_rudder: f64,
}

/// Most belly points a `[ground]` table may list: the contact model keeps its points in
/// fixed-size arrays, after the three wheels.
pub const MAX_BELLY_POINTS: usize = 9;

/// The whole aircraft file.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Aircraft {
    /// Mass and inertia.
    pub mass: Mass,
    /// Geometry.
    pub geometry: Geometry,
    /// Aerodynamic derivatives.
    pub aero: Aero,
    /// Propulsion.
    pub propulsion: Propulsion,
    /// Servos.
    pub actuators: Actuators,
    /// Sensor rates, noise, biases and the GPS receiver.
    pub sensors: crate::sensors::SensorConfig,
    /// Environment.
    pub environment: Environment,
    /// Landing gear and belly contact.
    pub ground: Ground,
}

impl Aircraft {
    /// The built-in Ultra Stick 25e.
    pub fn ultrastick25e() -> Result<Self, AircraftError> {
        Self::from_toml_str(DEFAULT_AIRCRAFT_TOML, Path::new(DEFAULT_AIRCRAFT_NAME))
    }

    /// Reads and validates an aircraft file.
    pub fn from_file(path: &Path) -> Result<Self, AircraftError> {
        let text = std::fs::read_to_string(path).map_err(|source| AircraftError::Read {
            file: path.to_path_buf(),
            source,
        })?;
        Self::from_toml_str(&text, path)
    }

    /// The file given, or the built-in one when `None`.
    pub fn load(path: Option<&Path>) -> Result<Self, AircraftError> {
        match path {
            Some(p) => Self::from_file(p),
            None => Self::ultrastick25e(),
        }
    }

    /// Parses and validates TOML text; `file` names it in errors.
    pub fn from_toml_str(text: &str, file: &Path) -> Result<Self, AircraftError> {
        let file_buf = file.to_path_buf();
        let table: toml::Table = toml::from_str(text).map_err(|e| AircraftError::Syntax {
            file: file_buf.clone(),
            message: e.message().to_string() + &location(text, e.span()),
        })?;
        check_finite(&toml::Value::Table(table), "", file)?;
        let de = toml::Deserializer::parse(text).map_err(|e| AircraftError::Syntax {
            file: file_buf.clone(),
            message: e.message().to_string(),
        })?;
        let aircraft: Aircraft = serde_path_to_error::deserialize(de).map_err(|e| {
            let key = e.path().to_string();
            let inner = e.into_inner();
            AircraftError::Shape {
                file: file_buf.clone(),
                key,
                message: inner.message().to_string() + &location(text, inner.span()),
            }
        })?;
        aircraft.validate(file)?;
        Ok(aircraft)
    }

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
        ordered("propulsion.motor_power_clamp_W", p.motor_power_clamp_W)?;
        ordered("propulsion.omega_limits_radps", p.omega_limits_radps)?;
        // Qm = P / Omega: the lower engine-speed limit keeps the division finite.
        positive("propulsion.omega_limits_radps", p.omega_limits_radps[0])?;
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
        self.validate_ground(file)
    }

    /// Checks the `[ground]` table: a taildragger whose gear stands below the CG.
    fn validate_ground(&self, file: &Path) -> Result<(), AircraftError> {
        let bad = |key: &str, value: String, reason: &str| AircraftError::Value {
            file: file.to_path_buf(),
            key: format!("ground.{key}"),
            value,
            reason: reason.to_string(),
        };
        let gr = &self.ground;
        for (key, v) in [
            ("main_stiffness_Npm", gr.main_stiffness_Npm),
            ("tail_stiffness_Npm", gr.tail_stiffness_Npm),
            ("belly_stiffness_Npm", gr.belly_stiffness_Npm),
            ("slip_speed_mps", gr.slip_speed_mps),
        ] {
            if v.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
                return Err(bad(key, v.to_string(), "must be positive"));
            }
        }
        for (key, v) in [
            ("main_damping_Nspm", gr.main_damping_Nspm),
            ("tail_damping_Nspm", gr.tail_damping_Nspm),
            ("belly_damping_Nspm", gr.belly_damping_Nspm),
        ] {
            if v.partial_cmp(&0.0) == Some(std::cmp::Ordering::Less) || !v.is_finite() {
                return Err(bad(key, v.to_string(), "must not be negative"));
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
        if !(-2.0..=2.0).contains(&gr.tail_steer_per_rudder) {
            return Err(bad(
                "tail_steer_per_rudder",
                gr.tail_steer_per_rudder.to_string(),
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
        let (l, r, t) = (gr.main_wheel_left_m, gr.main_wheel_right_m, gr.tail_wheel_m);
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

/// " (line L, column C)" of a byte span, or nothing.
fn location(text: &str, span: Option<std::ops::Range<usize>>) -> String {
    match span {
        Some(r) if r.start <= text.len() => {
            let before = &text[..r.start];
            let line = before.matches('\n').count() + 1;
            let col = before.len() - before.rfind('\n').map_or(0, |i| i + 1) + 1;
            format!(" (line {line}, column {col})")
        }
        _ => String::new(),
    }
}

fn check_finite(v: &toml::Value, path: &str, file: &Path) -> Result<(), AircraftError> {
    match v {
        toml::Value::Float(x) if !x.is_finite() => Err(AircraftError::Value {
            file: file.to_path_buf(),
            key: path.to_string(),
            value: x.to_string(),
            reason: "must be a finite number".into(),
        }),
        toml::Value::Table(t) => {
            for (k, v) in t {
                let p = if path.is_empty() {
                    k.clone()
                } else {
                    format!("{path}.{k}")
                };
                check_finite(v, &p, file)?;
            }
            Ok(())
        }
        toml::Value::Array(a) => {
            for (i, v) in a.iter().enumerate() {
                check_finite(v, &format!("{path}[{i}]"), file)?;
            }
            Ok(())
        }
        _ => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn built_in_file_loads() {
        let a = Aircraft::ultrastick25e().unwrap();
        assert_eq!(a.mass.mass_kg, 1.959);
        assert_eq!(a.mass.Jxz_kgm2, 0.014);
        assert_eq!(a.environment.g_mps2, 9.8056);
    }
}
