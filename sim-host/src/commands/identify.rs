//! `sim-host identify LOG`: the reduced models of the design fitted from a flight's simulator
//! link log, by the same identifier the vehicle runs (`common::tuning::identify`), beside the
//! aircraft file's linearisation at the same airspeed.
//!
//! The log is a `.tlog` of the simulator link (`simlink.tlog` of `sim-host fly` and `sim-host
//! sim`, or any PX4-interface simulator's recorded the same way): the truth's attitude, rates,
//! velocity and airspeed (`HIL_STATE_QUATERNION`) and the autopilot's answer to each frame
//! (`HIL_ACTUATOR_CONTROLS`, the surface commands held until the next). Samples count while
//! the autopilot is armed and, in a flight armed standing on a runway, the aircraft is 5 m or
//! more above the lowest height of the armed flight (the runway): the ground's forces are not
//! the models'. The log holds no
//! wind: the flight's steady wind is read from it (the ground velocity less the airspeed
//! along the nose, averaged), and the angle of attack is the velocity's through it. Gusts are
//! not: in turbulence the angle of attack carries them as noise.
//!
//! Or the log is a ground link's `.tlog`, as a station records the autopilot's telemetry, with
//! `ATTITUDE`, `SERVO_OUTPUT_RAW`, `GLOBAL_POSITION_INT` and `VFR_HUD` asked for at 50 Hz: the
//! same samples from the autopilot's estimate, its surfaces from the servo pulses, without the
//! sideslip model (no accelerometer among those messages). At slower rates it is refused with
//! the messages named.
//!
//! Or the log is the autopilot's own flight log (a `.ulg`, as the board writes it and a station
//! downloads it), written with `SDLOG_PROFILE`'s system-identification bit (8) so that its
//! attitude, rates, accelerations, surfaces, velocity and airspeed come at every 100 Hz sensor
//! frame: the same samples from the autopilot's estimate instead of the truth, each taken at
//! an `actuator_outputs` sample with the latest of the other topics, fitted through the
//! pre-filters the vehicle fits its own sensors through. A flight log at the default
//! profile's 25 Hz is refused with the parameter to set: its 40 ms between samples do not
//! resolve the 25e's 60 ms roll mode.

use crate::aircraft::Aircraft;
use crate::commands::linearize::linearize_report_at;
use crate::report::sig;
use crate::report::table::Table;
use anyhow::{bail, Context};
use common::math::frames::{body_to_ned, ned_to_body, AirData};
use common::math::RAD2DEG;
use common::tuning::identify::{
    Axis, AxisError, Identifier, IdentifyConfig, Sample, AIRSPEED_FILTER_TAU_S,
    ATTITUDE_FILTER_TAU_S,
};
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// Height above the armed flight's lowest point from which a sample counts as flown, m.
const AIRBORNE_M: f64 = 5.0;

/// Airspeed under which an armed aircraft stands on the ground, m/s.
const STANDING_MPS: f32 = 3.0;

/// One coefficient: identified, and the linearisation's where it has one.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Coefficient {
    /// Beard and McLain's name (or the kinematic gain's).
    pub name: String,
    /// Identified value.
    pub value: f64,
    /// Its standard error.
    pub std_err: f64,
    /// The aircraft file's linearisation at the same airspeed (1 for the kinematic gains).
    pub reference: Option<f64>,
    /// `value` against `reference`, %.
    pub diff_pct: Option<f64>,
}

/// One axis: its fit, or why there is none.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct AxisReport {
    /// `roll`, `pitch`, `airspeed`, `course`, `altitude`.
    pub axis: String,
    /// The input the axis is excited by.
    pub input: String,
    /// Its standard deviation over the flight (deg of surface or bank, or throttle; `None`
    /// where the fit failed for another reason).
    pub input_sd: Option<f64>,
    /// Share of the state's rate the model explains.
    pub r2: Option<f64>,
    /// Sample pairs fitted.
    pub rows: u32,
    /// The coefficients (none when the axis has no fit).
    pub coefficients: Vec<Coefficient>,
    /// Why the axis has no fit.
    pub error: Option<String>,
}

/// What `sim-host identify` reports.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct IdentifyReport {
    /// The log read.
    pub log: String,
    /// Airspeed the coefficients are given at (the flown samples' mean), m/s.
    pub airspeed_ref_mps: f64,
    /// Servo time constant the surfaces are followed with (the aircraft file's bandwidth), s.
    pub servo_tau_s: f64,
    /// Samples flown (armed, off the ground).
    pub samples: usize,
    /// Their span, s.
    pub flown_s: f64,
    /// The steady wind read from the log (the angle of attack is taken through it), NED, m/s.
    pub wind_ned_mps: [f64; 3],
    /// Per axis, in the design's order.
    pub axes: Vec<AxisReport>,
    /// The printed tables.
    #[serde(skip)]
    pub tables: Vec<Table>,
}

impl IdentifyReport {
    /// The identified value of `axis`'s coefficient `name`: an error naming the axis when it
    /// has no model, or the coefficient when the axis lacks it.
    pub fn coefficient(&self, axis: &str, name: &str) -> Result<f64, String> {
        let a = self
            .axes
            .iter()
            .find(|a| a.axis == axis)
            .ok_or_else(|| format!("no `{axis}` axis"))?;
        if let Some(e) = &a.error {
            return Err(format!("the {axis} axis has no model ({e})"));
        }
        a.coefficients
            .iter()
            .find(|c| c.name == name && c.value.is_finite())
            .map(|c| c.value)
            .ok_or_else(|| format!("`{axis}.{name}` is missing or not a number"))
    }

    /// The axes without a fit that a design needs, with the reason. The sideslip's is not
    /// among them: without rudder doublets (a flight in Stabilized, whose rudder is the yaw
    /// damper's) the report says why it has none, and a design keeps the base set's sideslip
    /// gains.
    pub fn failures(&self) -> Vec<String> {
        self.axes
            .iter()
            .filter(|a| a.axis != Axis::Sideslip.name())
            .filter_map(|a| a.error.as_ref().map(|e| format!("{}: {e}", a.axis)))
            .collect()
    }
}

mod logs;
use logs::{ground_samples, samples, ulog_samples, Timed};

/// The flight's steady horizontal wind, NED, m/s: the mean of the ground velocity less the
/// airspeed along the body's nose. The log holds no wind, and the angle of attack is read from
/// the velocity through the air; the nose's direction leaves out the angle of attack's and
/// the sideslip's share of the airspeed (tenths of a m/s), and the wind's vertical part is
/// taken as none.
fn steady_wind(flown: &[&Timed]) -> Vector3<f64> {
    let n = flown.len().max(1) as f64;
    let sum = flown.iter().fold(Vector3::zeros(), |acc, t| {
        let air = body_to_ned(
            &t.attitude,
            &Vector3::new(f64::from(t.sample.airspeed), 0.0, 0.0),
        );
        acc + (t.v_ned - air)
    });
    let w = sum / n;
    Vector3::new(w.x, w.y, 0.0)
}

/// Fits the log at `path`; `airspeed` overrides the reference airspeed (the flown mean);
/// `window` keeps the samples between two times of the log's clock, s (the simulated time
/// of `sim-host fly`).
pub fn identify_log(
    path: &Path,
    aircraft: &Aircraft,
    airspeed: Option<f64>,
    window: Option<(f64, f64)>,
) -> anyhow::Result<IdentifyReport> {
    let bytes = std::fs::read(path).with_context(|| format!("reading {}", path.display()))?;
    let flight_log = bytes.starts_with(&common::ulog::MAGIC);
    let ground = if flight_log {
        None
    } else {
        ground_samples(path, &bytes)?
    };
    let ground_link = ground.is_some();
    let all = match ground {
        Some(g) => g,
        None if flight_log => ulog_samples(path, &bytes)?,
        None => samples(&bytes),
    };
    if all.is_empty() {
        bail!(
            "{}: no HIL_STATE_QUATERNION answered by an HIL_ACTUATOR_CONTROLS of the autopilot \
             (a simulator link's .tlog with the truth frames), nor a ground link's \
             SERVO_OUTPUT_RAW with its ATTITUDE, GLOBAL_POSITION_INT and VFR_HUD",
            path.display()
        );
    }
    // A flight armed at rest stood on a runway: its lowest height is the ground. One armed
    // already flying (the simulator's hand launch) never touched it.
    let on_runway = all
        .iter()
        .any(|s| s.armed && s.sample.airspeed < STANDING_MPS);
    let runway = if on_runway {
        all.iter()
            .filter(|s| s.armed)
            .map(|s| s.alt_m)
            .fold(f64::INFINITY, f64::min)
    } else {
        f64::NEG_INFINITY
    };
    let within = |t: &Timed| {
        window.is_none_or(|(from, to)| (from..=to).contains(&(t.time_us as f64 * 1e-6)))
    };
    let flown: Vec<&Timed> = all
        .iter()
        .filter(|s| s.armed && s.alt_m >= runway + AIRBORNE_M && within(s))
        .collect();
    if flown.len() < 50 {
        bail!(
            "{}: {} samples armed and {AIRBORNE_M} m above the runway: too few to fit",
            path.display(),
            flown.len()
        );
    }
    let wind = steady_wind(&flown);
    let flown: Vec<Timed> = flown
        .into_iter()
        .map(|t| {
            let air = AirData::from_body_velocity(&ned_to_body(&t.attitude, &(t.v_ned - wind)));
            // A ground link's roll model reads the sideslip's lateral force, as the vehicle's
            // autotune does.
            let ay = if ground_link {
                (air.beta * f64::from(t.sample.airspeed).powi(2)) as f32
            } else {
                t.sample.ay
            };
            Timed {
                sample: Sample {
                    alpha: air.alpha as f32,
                    beta: air.beta as f32,
                    air_speed: air.va as f32,
                    ay,
                    ..t.sample
                },
                ..*t
            }
        })
        .collect();
    let va_ref = airspeed.unwrap_or_else(|| {
        flown
            .iter()
            .map(|s| f64::from(s.sample.airspeed))
            .sum::<f64>()
            / flown.len() as f64
    });
    let servo_tau = 1.0 / (2.0 * std::f64::consts::PI * aircraft.actuators.bandwidth_Hz);
    // The autopilot's estimate carries its sensors' noise: fitted through the pre-filters the
    // vehicle fits its own through; the truth needs none.
    let (airspeed_filter_tau_s, attitude_filter_tau_s) = if flight_log || ground_link {
        (AIRSPEED_FILTER_TAU_S, ATTITUDE_FILTER_TAU_S)
    } else {
        (0.0, 0.0)
    };
    let mut id = Identifier::new(IdentifyConfig {
        airspeed_ref: va_ref as f32,
        servo_tau_s: servo_tau as f32,
        servo_rate_radps: aircraft.actuators.rate_limit_radps as f32,
        airspeed_filter_tau_s,
        attitude_filter_tau_s,
    });
    id.take_rows(!ground_link, true);
    let mut last: Option<u64> = None;
    for s in &flown {
        let dt = last.map_or(0.0, |l| s.time_us.saturating_sub(l) as f32 * 1e-6);
        id.push(dt, &s.sample);
        last = Some(s.time_us);
    }
    let span = flown.last().zip(flown.first()).map_or(0.0, |(b, a)| {
        b.time_us.saturating_sub(a.time_us) as f64 * 1e-6
    });
    let reference = linearize_report_at(aircraft, "level", va_ref)
        .ok()
        .map(|r| r.reduced);
    let expected = |name: &str| -> Option<f64> {
        let r = reference.as_ref();
        match name {
            "k_chi" | "k_h" => Some(1.0),
            _ => r.and_then(|r| r.named().iter().find(|(n, _)| *n == name).map(|(_, v)| *v)),
        }
    };
    let mut axes = Vec::new();
    for axis in Axis::ALL {
        // Angles are reported in degrees, the throttle as it is.
        let (input, _) = axis.input();
        let scale = if axis == Axis::Airspeed { 1.0 } else { RAD2DEG };
        let report = match id.fit(axis) {
            _ if ground_link && axis == Axis::Sideslip => AxisReport {
                axis: axis.name().into(),
                input: input.into(),
                input_sd: None,
                r2: None,
                rows: 0,
                coefficients: Vec::new(),
                error: Some("no accelerometer (the side force) in a ground link's messages".into()),
            },
            Ok(f) => AxisReport {
                axis: axis.name().into(),
                input: input.into(),
                input_sd: Some(f64::from(f.input_sd * scale)),
                r2: Some(f64::from(f.r2)),
                rows: f.rows,
                coefficients: axis
                    .coefficients()
                    .iter()
                    .zip(f.coef.iter().zip(f.std_err.iter()))
                    .map(|(name, (v, e))| {
                        let value = f64::from(*v);
                        let reference = expected(name);
                        Coefficient {
                            name: (*name).into(),
                            value,
                            std_err: f64::from(*e),
                            reference,
                            // Relative to the signed reference (not `report::pct`'s
                            // magnitude): -3 % is a coefficient 3 % smaller in size.
                            diff_pct: reference
                                .filter(|r| r.abs() > 1e-9)
                                .map(|r| 100.0 * (value - r) / r),
                        }
                    })
                    .collect(),
                error: None,
            },
            Err(e) => {
                let (sd, error) = match e {
                    AxisError::NotExcited { sd, needed, .. } => (
                        Some(f64::from(sd * scale)),
                        format!(
                            "not excited: the {input} varied {} (standard deviation), at least {} needed",
                            sig(f64::from(sd * scale), 2),
                            sig(f64::from(needed * scale), 2)
                        ),
                    ),
                    AxisError::Singular => (
                        None,
                        "its regressors never varied independently of each other".into(),
                    ),
                };
                AxisReport {
                    axis: axis.name().into(),
                    input: input.into(),
                    input_sd: sd,
                    r2: None,
                    rows: 0,
                    coefficients: Vec::new(),
                    error: Some(error),
                }
            }
        };
        axes.push(report);
    }
    let mut t = Table::new(
        format!(
            "Reduced models identified from {} ({} s flown, coefficients at {} m/s, steady wind N {} E {} m/s; servo time constant {} s), beside the aircraft file's linearisation at that airspeed",
            path.display(),
            sig(span, 3),
            sig(va_ref, 3),
            sig(wind.x, 2),
            sig(wind.y, 2),
            sig(servo_tau, 2)
        ),
        &["axis", "coefficient", "identified", "std. error", "linearised", "difference", "R^2", "excitation (sd)"],
    );
    for a in &axes {
        let unit = if a.input == "throttle" { "" } else { " deg" };
        let excitation = a
            .input_sd
            .map_or("-".into(), |sd| format!("{}{unit} {}", sig(sd, 2), a.input));
        if let Some(e) = &a.error {
            t.row([
                a.axis.clone(),
                "-".into(),
                e.clone(),
                String::new(),
                String::new(),
                String::new(),
                String::new(),
                excitation,
            ]);
            continue;
        }
        for c in &a.coefficients {
            t.row([
                a.axis.clone(),
                c.name.clone(),
                sig(c.value, 4),
                sig(c.std_err, 2),
                c.reference.map_or("-".into(), |r| sig(r, 4)),
                c.diff_pct.map_or("-".into(), |d| format!("{d:+.1} %")),
                a.r2.map_or("-".into(), |r| format!("{r:.3}")),
                excitation.clone(),
            ]);
        }
    }
    Ok(IdentifyReport {
        log: path.display().to_string(),
        airspeed_ref_mps: va_ref,
        servo_tau_s: servo_tau,
        samples: flown.len(),
        flown_s: span,
        wind_ned_mps: [wind.x, wind.y, wind.z],
        axes,
        tables: vec![t],
    })
}
