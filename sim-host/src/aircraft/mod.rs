//! The aircraft file: an airframe's model parameters (the Ultra Stick 25e's built in), read
//! from TOML and validated.
//!
//! The file's keys mirror the Minnesota configuration script one to one (hence names such as
//! `CL_alpha`), so every value can be checked against its source comment. Loading goes in four
//! steps, each failing with the file, the dotted key and the value it rejects:
//! TOML syntax, non-finite numbers (TOML accepts `nan` and `inf`), shape (unknown, missing or
//! mistyped keys, through `deny_unknown_fields`), then physical sense (positive mass, a positive
//! definite inertia, ordered limits, ...). [`load`] takes the first three steps, [`validate`]
//! the last.
#![allow(non_snake_case)]

pub mod load;
pub mod validate;

use serde::{Deserialize, Serialize};
use std::path::PathBuf;

/// The aircraft file shipped with the simulator, compiled in so the binary runs from any directory.
pub const DEFAULT_AIRCRAFT_TOML: &str = include_str!("../../aircraft/ultrastick25e.toml");
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
    /// Per unit `q c / (2 Va)` (absent: none, as in the Minnesota model).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub CD_q: f64,
    /// Which lift the induced drag squares and how the elevator's drag enters (absent: the
    /// Minnesota form).
    #[serde(default, skip_serializing_if = "is_default")]
    pub polar: DragPolar,
}

/// The form of the drag polar.
#[derive(Clone, Copy, Debug, Default, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum DragPolar {
    /// The Minnesota model: the induced drag squares the whole lift coefficient (rates and
    /// surfaces included) less `CL_at_CD_min`, and the elevator drag is `|CD_de de|`.
    #[default]
    TotalLift,
    /// Beard and McLain's (*Small Unmanned Aircraft*, eq. 4.11, as their `mavsim` computes
    /// it): the induced drag squares the lift of the angle of attack alone,
    /// `CL0 + CL_alpha alpha` (less `CL_at_CD_min`), and the elevator drag is signed,
    /// `CD_de de`.
    AngleOfAttackLift,
}

fn is_zero(x: &f64) -> bool {
    *x == 0.0
}

fn is_default<T: Default + PartialEq>(x: &T) -> bool {
    *x == T::default()
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
///
/// The propeller's torque comes from either a power-coefficient polynomial (`CP_poly_J`, the
/// Minnesota form) or a torque-coefficient polynomial (`CQ_poly_J`, Beard and McLain's); the
/// motor is either a shaft-power curve in throttle (`motor_power_poly_throttle_W` with
/// `motor_power_clamp_W`, the Minnesota form) or a DC motor (`[propulsion.dc_motor]`, Beard and
/// McLain's). Exactly one of each pair: [`Aircraft::validate`] checks it.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Propulsion {
    /// Propeller radius, m.
    pub prop_radius_m: f64,
    /// Thrust coefficient polynomial in the advance ratio, highest power first:
    /// `T = CT rho n^2 D^4` with `n` in rev/s.
    pub CT_poly_J: [f64; 5],
    /// Power coefficient polynomial in the advance ratio, highest power first:
    /// `Qp = CP rho n^3 D^5 / Omega`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub CP_poly_J: Option<[f64; 5]>,
    /// Torque coefficient polynomial in the advance ratio, highest power first:
    /// `Qp = CQ rho n^2 D^5`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub CQ_poly_J: Option<[f64; 5]>,
    /// Range the advance ratio is clamped to.
    pub J_clamp: [f64; 2],
    /// Motor shaft power in throttle, W, highest power first.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub motor_power_poly_throttle_W: Option<[f64; 3]>,
    /// Range the motor power is clamped to, W.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub motor_power_clamp_W: Option<[f64; 2]>,
    /// A DC motor fed `throttle * max_voltage_V` instead of the power curve.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dc_motor: Option<DcMotor>,
    /// Motor plus propeller inertia, kg m^2.
    pub Jmp_kgm2: f64,
    /// Range of the engine speed, rad/s.
    pub omega_limits_radps: [f64; 2],
    /// Which way the propeller turns (absent: the Minnesota wiring).
    #[serde(default, skip_serializing_if = "is_default")]
    pub spin: PropSpin,
}

/// A brushless DC motor as Beard and McLain model it (the propulsion addendum of *Small
/// Unmanned Aircraft*): torque `KQ ((V - KQ Omega) / R - i0)` at `V = throttle * V_max`, with
/// `KQ = 60 / (2 pi KV)` (the back-EMF constant in V s/rad equals the torque constant in N m/A).
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct DcMotor {
    /// Speed constant, rpm per volt.
    pub KV_rpm_per_V: f64,
    /// Winding resistance, ohm.
    pub resistance_ohm: f64,
    /// No-load current, A.
    pub no_load_current_A: f64,
    /// Voltage at full throttle, V.
    pub max_voltage_V: f64,
}

impl DcMotor {
    /// Torque constant `KQ`, N m/A (equal to the back-EMF constant in V s/rad).
    pub fn kq_nm_per_a(&self) -> f64 {
        60.0 / (2.0 * std::f64::consts::PI * self.KV_rpm_per_V)
    }
}

/// Which way the propeller turns, which sets the sign of its torque and gyroscopic moment on
/// the airframe.
#[derive(Clone, Copy, Debug, Default, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum PropSpin {
    /// The Minnesota wiring: roll moment `+(2 Qm - Qp)`, gyroscopic moment
    /// `omega_body x [Jmp Omega, 0, 0]`.
    #[default]
    Minnesota,
    /// Clockwise seen from behind (right-handed about body x): the mirror image of the
    /// Minnesota wiring, whose steady roll moment is Beard and McLain's `-Qp`.
    RightHand,
}

/// The flight battery (not part of the Minnesota model): a LiPo pack as an equivalent circuit,
/// see [`crate::plant::battery`].
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Battery {
    /// Cells in series.
    pub cells: u8,
    /// Capacity, mAh.
    pub capacity_mAh: f64,
    /// Internal resistance of the whole pack, ohm.
    pub internal_resistance_ohm: f64,
    /// Shaft power over electrical power of motor and ESC, 0..1.
    pub motor_esc_efficiency: f64,
    /// Constant draw of the avionics and servos, W.
    pub avionics_power_W: f64,
    /// State of charge at power-up, 0..1.
    pub initial_soc: f64,
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

/// Landing gear and belly contact with the ground: two main wheels and a third, steered by
/// the rudder, that is either a tail wheel (a taildragger: mains ahead of the CG) or a nose
/// wheel (tricycle gear: mains behind the CG). The file gives the `tail_*` keys or the `nose_*`
/// keys, not both ([`Ground::third_wheel`]).
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Ground {
    /// Left main wheel's ground contact point from the CG, body axes, m.
    pub main_wheel_left_m: [f64; 3],
    /// Right main wheel's ground contact point from the CG, body axes, m.
    pub main_wheel_right_m: [f64; 3],
    /// Tail wheel's ground contact point from the CG, body axes, m (a taildragger).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tail_wheel_m: Option<[f64; 3]>,
    /// Nose wheel's ground contact point from the CG, body axes, m (tricycle gear).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub nose_wheel_m: Option<[f64; 3]>,
    /// Points of the fuselage and wings that touch in a belly or wing-tip landing, body axes, m.
    pub belly_points_m: Vec<[f64; 3]>,
    /// Stiffness of each main wheel's leg and tyre, N/m.
    pub main_stiffness_Npm: f64,
    /// Damping of each main wheel, N s/m.
    pub main_damping_Nspm: f64,
    /// Stiffness of the tail wheel's spring, N/m.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tail_stiffness_Npm: Option<f64>,
    /// Damping of the tail wheel, N s/m.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tail_damping_Nspm: Option<f64>,
    /// Stiffness of the nose wheel's leg, N/m.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub nose_stiffness_Npm: Option<f64>,
    /// Damping of the nose wheel, N s/m.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub nose_damping_Nspm: Option<f64>,
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
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tail_steer_per_rudder: Option<f64>,
    /// Nose-wheel heading per rudder deflection: negative, so that a positive rudder turns the
    /// wheel's front, and the nose, to the left as it yaws the aircraft in the air.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub nose_steer_per_rudder: Option<f64>,
}

/// Where the third wheel is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GearLayout {
    /// Two mains ahead of the CG, a tail wheel.
    Taildragger,
    /// A nose wheel ahead of the CG, two mains behind it.
    Tricycle,
}

/// The wheel besides the mains, from whichever keys the file gives.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThirdWheel {
    /// Tail wheel or nose wheel.
    pub layout: GearLayout,
    /// Contact point from the CG, body axes, m.
    pub pos_m: [f64; 3],
    /// Stiffness, N/m.
    pub stiffness_Npm: f64,
    /// Damping, N s/m.
    pub damping_Nspm: f64,
    /// Wheel heading per rudder deflection.
    pub steer_per_rudder: f64,
}

impl Ground {
    /// The tail wheel, or else the nose wheel. `None` when neither set of keys is complete,
    /// which [`Aircraft::validate`] rejects.
    pub fn third_wheel(&self) -> Option<ThirdWheel> {
        let tail = (
            self.tail_wheel_m,
            self.tail_stiffness_Npm,
            self.tail_damping_Nspm,
            self.tail_steer_per_rudder,
        );
        let nose = (
            self.nose_wheel_m,
            self.nose_stiffness_Npm,
            self.nose_damping_Nspm,
            self.nose_steer_per_rudder,
        );
        let wheel =
            |layout, (p, k, c, s): (Option<[f64; 3]>, Option<f64>, Option<f64>, Option<f64>)| {
                Some(ThirdWheel {
                    layout,
                    pos_m: p?,
                    stiffness_Npm: k?,
                    damping_Nspm: c?,
                    steer_per_rudder: s?,
                })
            };
        wheel(GearLayout::Taildragger, tail).or_else(|| wheel(GearLayout::Tricycle, nose))
    }

    /// Moves every point by `d` (body axes, m).
    pub fn translate(&mut self, d: [f64; 3]) {
        let mv = |p: &mut [f64; 3]| {
            for i in 0..3 {
                p[i] += d[i];
            }
        };
        mv(&mut self.main_wheel_left_m);
        mv(&mut self.main_wheel_right_m);
        self.tail_wheel_m.iter_mut().for_each(mv);
        self.nose_wheel_m.iter_mut().for_each(mv);
        self.belly_points_m.iter_mut().for_each(mv);
    }
}

/// What a flight is trimmed for when nothing else is asked.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Performance {
    /// Airspeed the analysis commands trim at by default, m/s.
    pub cruise_airspeed_mps: f64,
}

/// Airspeed the analysis commands trim at when the aircraft file has no `[performance]`
/// table: the thesis's Table 2.3 for the Ultra Stick 25e, m/s.
pub const DEFAULT_TRIM_AIRSPEED_MPS: f64 = 17.0;

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
    /// Flight battery.
    pub battery: Battery,
    /// Servos.
    pub actuators: Actuators,
    /// Sensor rates, noise, biases and the GPS receiver.
    pub sensors: crate::sensors::config::SensorConfig,
    /// Environment.
    pub environment: Environment,
    /// Landing gear and belly contact.
    pub ground: Ground,
    /// The cruise airspeed (absent: [`DEFAULT_TRIM_AIRSPEED_MPS`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub performance: Option<Performance>,
}

impl Aircraft {
    /// The airspeed to trim at when none is asked for, m/s.
    pub fn cruise_airspeed_mps(&self) -> f64 {
        self.performance
            .as_ref()
            .map_or(DEFAULT_TRIM_AIRSPEED_MPS, |p| p.cruise_airspeed_mps)
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
