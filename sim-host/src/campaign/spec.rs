//! The campaign file: what is uncertain and by how much, as TOML. Every key is optional and
//! a missing one keeps its default ([`CampaignSpec::default`], written out by
//! [`DEFAULT_CAMPAIGN_TOML`]); an unknown key, a negative spread or an impossible range is
//! refused with the file, the dotted key and the value.
//!
//! Two shapes of dispersion: a *spread* `s` is a relative half-width, the quantity is
//! multiplied by `1 + U(-s, s)`; a *range* `[lo, hi]` draws `U(lo, hi)`. Uniform rather than
//! normal because the file states bounds (an identification's confidence, a datasheet's
//! tolerance), and a uniform draw gives the edges of the box as much weight as the middle.

use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The built-in campaign with every key at its default, as a file a user starts from.
pub const DEFAULT_CAMPAIGN_TOML: &str = include_str!("default_campaign.toml");

/// A rejected campaign file.
#[derive(Debug, thiserror::Error)]
pub enum SpecError {
    /// The file could not be read.
    #[error("cannot read campaign file `{file}`: {source}")]
    Read {
        /// The file.
        file: PathBuf,
        /// The operating-system error.
        source: std::io::Error,
    },
    /// Not valid TOML.
    #[error("campaign file `{file}` is not valid TOML: {message}")]
    Syntax {
        /// The file.
        file: PathBuf,
        /// The parser's message.
        message: String,
    },
    /// An unknown key, a mistyped value or one outside what can be flown.
    #[error("campaign file `{file}`: key `{key}` = {value}: {reason}")]
    Value {
        /// The file.
        file: PathBuf,
        /// Dotted key.
        key: String,
        /// The value as written.
        value: String,
        /// Why it is refused.
        reason: String,
    },
}

/// The aerodynamic model.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct AeroSpec {
    /// Spread of every coefficient of the aircraft file's `[aero.*]` tables, each drawn on
    /// its own.
    pub coefficient_spread: f64,
}

/// Mass properties.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct MassSpec {
    /// Spread of the mass.
    pub mass_spread: f64,
    /// Spread of each of Jx, Jy, Jz and Jxz.
    pub inertia_spread: f64,
    /// Largest shift of the centre of gravity along body x, y and z, m (each `U(-d, d)`).
    pub cg_shift_m: [f64; 3],
}

/// Motor and propeller.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct PropulsionSpec {
    /// Spread of the thrust (the propeller's thrust coefficient).
    pub thrust_spread: f64,
}

/// Surface servos (one draw for all of them: one make of servo).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ServoSpec {
    /// Spread of the bandwidth.
    pub bandwidth_spread: f64,
    /// Spread of the rate limit.
    pub rate_limit_spread: f64,
}

/// Sensor errors.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SensorSpec {
    /// Largest gyro turn-on bias per axis, rad/s (replaces the aircraft file's).
    pub gyro_bias_radps: f64,
    /// Largest accelerometer bias per axis, m/s^2 (replaces the aircraft file's).
    pub accel_bias_mps2: f64,
    /// Largest magnetometer hard-iron offset per axis, gauss.
    pub mag_offset_gauss: f64,
    /// Spread of the gyro scale factor, per axis.
    pub gyro_scale_spread: f64,
    /// Spread of the accelerometer scale factor, per axis.
    pub accel_scale_spread: f64,
    /// Spread of the differential-pressure scale factor.
    pub pitot_scale_spread: f64,
    /// Largest differential-pressure zero offset, Pa.
    #[serde(rename = "pitot_offset_Pa")]
    pub pitot_offset_pa: f64,
    /// Each sensor's noise (standard deviation) is multiplied by a factor drawn from this
    /// range, one draw per sensor (IMU, magnetometer, barometer, pitot, GPS).
    pub noise_factor: [f64; 2],
    /// GPS latency, s. The ground station still tells the autopilot the aircraft file's
    /// latency, as an operator sets the receiver's datasheet value.
    pub gps_latency_s: [f64; 2],
}

/// The estimator's initial errors. The estimator starts itself from its sensors, so these
/// are drawn as the GPS receiver's start-up error (the first fixes of a cold start are off
/// and converge): the home and initial position the autopilot takes are off by it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct EstimatorSpec {
    /// Horizontal start-up offset, m (magnitude; the direction is uniform).
    pub gps_startup_horizontal_m: [f64; 2],
    /// Largest vertical start-up offset, m (`U(-d, d)`).
    pub gps_startup_vertical_m: f64,
    /// Time constant of the receiver's convergence, s.
    pub gps_startup_tau_s: [f64; 2],
}

/// The air.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct WindSpec {
    /// Steady wind speed, m/s, from a direction uniform over the compass.
    pub speed_mps: [f64; 2],
    /// Turbulence severities drawn from, each equally likely (`none`, `light`,
    /// `moderate`, `severe`).
    pub turbulence: Vec<String>,
}

/// The runway.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RunwaySpec {
    /// Runway heading, deg from north; the whole mission turns with it about home.
    pub heading_deg: [f64; 2],
    /// Use the runway's end that faces the wind, as a pilot reads the windsock: take-off and
    /// landing with a headwind component (a generated mission then lands in its take-off
    /// direction). `false`: the drawn heading as it is, tailwinds included.
    pub into_wind: bool,
}

/// Missions generated per flight (`--mission generated`): take-off along the runway, a
/// rectangle, a loiter at one of its corners, an approach and a landing on the runway.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct MissionSpec {
    /// Rectangle length, m.
    pub length_m: [f64; 2],
    /// Rectangle width, m.
    pub width_m: [f64; 2],
    /// Rotation of the rectangle about its centre, deg from the runway's direction.
    pub rotation_deg: [f64; 2],
    /// Loiter radius, m.
    pub loiter_radius_m: [f64; 2],
    /// Loiter turns (whole turns, both ends included).
    pub loiter_turns: [u32; 2],
    /// Cruise height above home, m.
    pub height_m: [f64; 2],
    /// Land in the take-off direction only (`false`: either direction, equally likely, when
    /// the runway is not chosen into the wind).
    pub land_in_takeoff_direction: bool,
}

/// The downward rangefinder.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RangefinderSpec {
    /// Share of the flights whose aircraft carries one (the aircraft file's, or a LIDAR-Lite
    /// v3 where the file names none), drawn after everything else; 0 draws nothing.
    pub fitted_share: f64,
}

impl Default for RangefinderSpec {
    /// Half the aircraft, so that one campaign gives the pass rates with and without one.
    fn default() -> Self {
        Self { fitted_share: 0.5 }
    }
}

/// What the autopilot is told of the simulator's truth: experiments on the laws, not on the
/// aircraft.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields, default)]
pub struct OracleSpec {
    /// The landing's flare flies on the true height above home and vertical speed
    /// (`SIM_USE_TRUTH` = 2): the best any height sensor could give it.
    pub flare_on_truth: bool,
}

/// What the scripted ground station does besides the mission: what a user would do.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields, default)]
pub struct StationSpec {
    /// Each flight autotunes before its mission, as a QGroundControl user does it
    /// (`flight::missions::autotune_then_mission`): Takeoff a second after arming, Hold,
    /// `MAV_CMD_DO_AUTOTUNE_ENABLE`, then the mission on the gains it applied.
    pub autotune: bool,
}

/// Everything a campaign disperses.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields, default)]
pub struct CampaignSpec {
    /// Aerodynamics.
    pub aero: AeroSpec,
    /// Mass, inertia, centre of gravity.
    pub mass: MassSpec,
    /// Thrust.
    pub propulsion: PropulsionSpec,
    /// Servos.
    pub servos: ServoSpec,
    /// Sensors.
    pub sensors: SensorSpec,
    /// Initial estimator errors.
    pub estimator: EstimatorSpec,
    /// Wind and turbulence.
    pub wind: WindSpec,
    /// Runway heading.
    pub runway: RunwaySpec,
    /// Generated missions.
    pub mission: MissionSpec,
    /// The rangefinder.
    pub rangefinder: RangefinderSpec,
    /// Truth given to the autopilot.
    pub oracle: OracleSpec,
    /// The ground station's part.
    pub station: StationSpec,
}

impl Default for AeroSpec {
    fn default() -> Self {
        Self {
            coefficient_spread: 0.20,
        }
    }
}

impl Default for MassSpec {
    fn default() -> Self {
        Self {
            mass_spread: 0.10,
            inertia_spread: 0.15,
            // 15 mm is 6 % of the chord along x; a battery slid sideways or a payload on top.
            cg_shift_m: [0.015, 0.005, 0.01],
        }
    }
}

impl Default for PropulsionSpec {
    fn default() -> Self {
        Self {
            thrust_spread: 0.15,
        }
    }
}

impl Default for ServoSpec {
    fn default() -> Self {
        Self {
            bandwidth_spread: 0.25,
            rate_limit_spread: 0.25,
        }
    }
}

impl Default for SensorSpec {
    fn default() -> Self {
        Self {
            // 0.3 deg/s, 10 mg, 2 % of the field: a MEMS IMU and a calibrated compass.
            gyro_bias_radps: 0.005,
            accel_bias_mps2: 0.1,
            mag_offset_gauss: 0.01,
            gyro_scale_spread: 0.02,
            accel_scale_spread: 0.02,
            pitot_scale_spread: 0.10,
            pitot_offset_pa: 2.0,
            noise_factor: [1.0, 2.0],
            // The autopilot is told 0.12 s (the aircraft file's); a receiver delivers its fixes tens
            // of milliseconds either side of its datasheet figure.
            gps_latency_s: [0.07, 0.2],
        }
    }
}

impl Default for EstimatorSpec {
    fn default() -> Self {
        Self {
            gps_startup_horizontal_m: [0.0, 5.0],
            gps_startup_vertical_m: 5.0,
            gps_startup_tau_s: [30.0, 120.0],
        }
    }
}

impl Default for WindSpec {
    fn default() -> Self {
        Self {
            speed_mps: [0.0, 8.0],
            turbulence: vec!["light".into(), "moderate".into()],
        }
    }
}

impl Default for RunwaySpec {
    fn default() -> Self {
        Self {
            heading_deg: [0.0, 360.0],
            into_wind: true,
        }
    }
}

impl Default for MissionSpec {
    fn default() -> Self {
        Self {
            length_m: [400.0, 800.0],
            width_m: [250.0, 500.0],
            rotation_deg: [0.0, 360.0],
            loiter_radius_m: [60.0, 120.0],
            loiter_turns: [1, 3],
            height_m: [50.0, 80.0],
            land_in_takeoff_direction: false,
        }
    }
}

impl CampaignSpec {
    /// Reads and checks a campaign file.
    pub fn from_file(path: &Path) -> Result<Self, SpecError> {
        let text = std::fs::read_to_string(path).map_err(|source| SpecError::Read {
            file: path.to_path_buf(),
            source,
        })?;
        Self::from_toml_str(&text, path)
    }

    /// The file given, or the defaults.
    pub fn load(path: Option<&Path>) -> Result<Self, SpecError> {
        path.map_or_else(|| Ok(Self::default()), Self::from_file)
    }

    /// Parses and checks TOML text; `file` names it in errors.
    pub fn from_toml_str(text: &str, file: &Path) -> Result<Self, SpecError> {
        let table: toml::Table = toml::from_str(text).map_err(|e| SpecError::Syntax {
            file: file.to_path_buf(),
            message: e.message().to_string(),
        })?;
        // Unknown keys first, from the defaults' own keys: the error can then show the
        // value and the keys that table knows, which serde's message does not.
        let known = toml::Table::try_from(Self::default()).map_err(|e| SpecError::Syntax {
            file: file.to_path_buf(),
            message: e.to_string(),
        })?;
        unknown_keys(&table, &known, "", file)?;
        let spec: Self = serde_path_to_error::deserialize(toml::Value::Table(table.clone()))
            .map_err(|e| {
                let key = e.path().to_string();
                let value = lookup(&table, &key).map_or_else(|| "?".into(), |v| v.to_string());
                SpecError::Value {
                    file: file.to_path_buf(),
                    key,
                    value,
                    reason: e.into_inner().message().to_string(),
                }
            })?;
        spec.validate(file)?;
        Ok(spec)
    }

    /// Checks every spread and range.
    pub fn validate(&self, file: &Path) -> Result<(), SpecError> {
        let c = Check { file };
        // Spreads of quantities that must keep their sign stay below 1.
        c.spread("aero.coefficient_spread", self.aero.coefficient_spread, 0.9)?;
        c.spread("mass.mass_spread", self.mass.mass_spread, 0.5)?;
        c.spread("mass.inertia_spread", self.mass.inertia_spread, 0.5)?;
        // The main wheels stand 0.10 m ahead of the CG: a shift of that size would put the
        // aircraft on its tail.
        for (i, v) in self.mass.cg_shift_m.iter().enumerate() {
            c.spread(&format!("mass.cg_shift_m[{i}]"), *v, 0.05)?;
        }
        c.spread(
            "propulsion.thrust_spread",
            self.propulsion.thrust_spread,
            0.9,
        )?;
        c.spread("servos.bandwidth_spread", self.servos.bandwidth_spread, 0.9)?;
        c.spread(
            "servos.rate_limit_spread",
            self.servos.rate_limit_spread,
            0.9,
        )?;
        let s = &self.sensors;
        c.spread("sensors.gyro_bias_radps", s.gyro_bias_radps, 0.2)?;
        c.spread("sensors.accel_bias_mps2", s.accel_bias_mps2, 2.0)?;
        c.spread("sensors.mag_offset_gauss", s.mag_offset_gauss, 0.5)?;
        c.spread("sensors.gyro_scale_spread", s.gyro_scale_spread, 0.5)?;
        c.spread("sensors.accel_scale_spread", s.accel_scale_spread, 0.5)?;
        c.spread("sensors.pitot_scale_spread", s.pitot_scale_spread, 0.9)?;
        c.spread("sensors.pitot_offset_Pa", s.pitot_offset_pa, 50.0)?;
        c.range("sensors.noise_factor", s.noise_factor, 0.0, 10.0)?;
        c.range("sensors.gps_latency_s", s.gps_latency_s, 0.0, 1.0)?;
        let e = &self.estimator;
        c.range(
            "estimator.gps_startup_horizontal_m",
            e.gps_startup_horizontal_m,
            0.0,
            100.0,
        )?;
        c.spread(
            "estimator.gps_startup_vertical_m",
            e.gps_startup_vertical_m,
            100.0,
        )?;
        c.range(
            "estimator.gps_startup_tau_s",
            e.gps_startup_tau_s,
            1.0,
            3600.0,
        )?;
        // The simulator refuses winds of more than 15 m/s per component.
        c.range("wind.speed_mps", self.wind.speed_mps, 0.0, 15.0)?;
        if self.wind.turbulence.is_empty() {
            return Err(c.bad("wind.turbulence", "[]", "name at least one severity"));
        }
        for (i, t) in self.wind.turbulence.iter().enumerate() {
            crate::flight::parse_turbulence(t)
                .map_err(|e| c.bad(&format!("wind.turbulence[{i}]"), &format!("\"{t}\""), &e))?;
        }
        c.range("runway.heading_deg", self.runway.heading_deg, -360.0, 720.0)?;
        let m = &self.mission;
        c.range("mission.length_m", m.length_m, 250.0, 3000.0)?;
        c.range("mission.width_m", m.width_m, 250.0, 3000.0)?;
        c.range("mission.rotation_deg", m.rotation_deg, -360.0, 720.0)?;
        c.range("mission.loiter_radius_m", m.loiter_radius_m, 40.0, 500.0)?;
        c.range("mission.height_m", m.height_m, 30.0, 120.0)?;
        let t = m.loiter_turns;
        if t[0] > t[1] || t[1] > 20 {
            return Err(c.bad(
                "mission.loiter_turns",
                &format!("{t:?}"),
                "must be [min, max] with min <= max <= 20",
            ));
        }
        let share = self.rangefinder.fitted_share;
        if !(0.0..=1.0).contains(&share) {
            return Err(c.bad(
                "rangefinder.fitted_share",
                &share.to_string(),
                "a share of the flights, from 0 to 1",
            ));
        }
        Ok(())
    }
}

/// Rejects keys of `table` that `known` lacks; `path` is `table`'s own dotted key.
fn unknown_keys(
    table: &toml::Table,
    known: &toml::Table,
    path: &str,
    file: &Path,
) -> Result<(), SpecError> {
    for (k, v) in table {
        let key = if path.is_empty() {
            k.clone()
        } else {
            format!("{path}.{k}")
        };
        match (known.get(k), v) {
            (None, _) => {
                let names: Vec<&str> = known.keys().map(String::as_str).collect();
                return Err(SpecError::Value {
                    file: file.to_path_buf(),
                    key,
                    value: v.to_string(),
                    reason: format!("unknown key (known here: {})", names.join(", ")),
                });
            }
            (Some(toml::Value::Table(kt)), toml::Value::Table(t)) => {
                unknown_keys(t, kt, &key, file)?
            }
            _ => {}
        }
    }
    Ok(())
}

/// The value at a dotted key (`a.b[2]` style indices are cut off).
fn lookup<'a>(table: &'a toml::Table, key: &str) -> Option<&'a toml::Value> {
    let mut parts = key.split('.');
    let mut v = table.get(parts.next()?.split('[').next()?)?;
    for p in parts {
        v = v.as_table()?.get(p.split('[').next()?)?;
    }
    Some(v)
}

struct Check<'a> {
    file: &'a Path,
}

impl Check<'_> {
    fn bad(&self, key: &str, value: &str, reason: &str) -> SpecError {
        SpecError::Value {
            file: self.file.to_path_buf(),
            key: key.to_string(),
            value: value.to_string(),
            reason: reason.to_string(),
        }
    }

    fn spread(&self, key: &str, v: f64, max: f64) -> Result<(), SpecError> {
        if !v.is_finite() || v < 0.0 {
            return Err(self.bad(key, &v.to_string(), "a spread must not be negative"));
        }
        if v > max {
            return Err(self.bad(
                key,
                &v.to_string(),
                &format!("at most {max}: beyond it the quantity leaves what the model can fly"),
            ));
        }
        Ok(())
    }

    fn range(&self, key: &str, r: [f64; 2], min: f64, max: f64) -> Result<(), SpecError> {
        let value = format!("[{}, {}]", r[0], r[1]);
        if !(r[0].is_finite() && r[1].is_finite()) || r[0] > r[1] {
            return Err(self.bad(key, &value, "must be [low, high] with low <= high"));
        }
        if r[0] < min || r[1] > max {
            return Err(self.bad(key, &value, &format!("must lie within {min}..{max}")));
        }
        Ok(())
    }
}
