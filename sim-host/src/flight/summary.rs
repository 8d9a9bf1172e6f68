//! Figures of a flight: estimator errors against the truth, the chapter-4 step figures of
//! each scripted command, how a mission was flown ([`super::mission_summary`]), the link
//! counters and the speed of the loop.

use super::config::{turbulence_name, FlightConfig};
use super::record::{Sample, DEG};
use super::script::{Action, CommandRecord, GroundStation};
use crate::analysis::metrics::{step_metrics, StepMetrics};
use common::link::framing::LinkStats;
use common::math::wrap_pi;
use firmware::app::SimLinkHealth;
use serde::Serialize;

/// Time after the estimator first reports `converged` from which the "settled" errors count,
/// s: the autopilot has taken over (arming follows convergence within a second) and pulled
/// the aircraft onto its course and altitude.
pub const SETTLE_S: f64 = 30.0;

/// Root-mean-square and largest estimation errors, from convergence to the end.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct EstimatorErrors {
    /// Time the estimator first reported itself converged, s.
    pub from_s: f64,
    /// Samples counted.
    pub samples: usize,
    /// Roll RMS error, deg.
    pub roll_rms_deg: f64,
    /// Pitch RMS error, deg.
    pub pitch_rms_deg: f64,
    /// Heading RMS error, deg.
    pub heading_rms_deg: f64,
    /// Altitude RMS error in home's datum (see [`HomeDatum`]), m.
    pub alt_rms_m: f64,
    /// Error of home's altitude above sea level as set at arming, m (0 before arming).
    pub home_alt_error_m: f64,
    /// Airspeed RMS error, m/s.
    pub airspeed_rms_mps: f64,
    /// Horizontal wind RMS error against the steady wind, m/s.
    pub wind_rms_mps: f64,
    /// Horizontal wind RMS error against the total wind (turbulence included), m/s.
    pub wind_total_rms_mps: f64,
    /// Largest roll error, deg.
    pub roll_max_deg: f64,
    /// Largest pitch error, deg.
    pub pitch_max_deg: f64,
    /// Largest heading error, deg.
    pub heading_max_deg: f64,
    /// Largest altitude error, m.
    pub alt_max_m: f64,
}

/// Figures of one scripted command.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Segment {
    /// What was commanded.
    pub what: String,
    /// `altitude` (m) or `course` (deg).
    pub signal: &'static str,
    /// Time of the command, s.
    pub t_s: f64,
    /// End of the segment (next command or end of flight), s.
    pub t_end_s: f64,
    /// Commanded value (m AMSL or deg, course unwrapped from the start value).
    pub command: f64,
    /// Chapter-4 step figures of the true response (unit as `signal`).
    pub metrics: StepMetrics,
    /// Largest |command - truth| over the last 5 s of the segment.
    pub final_error_max: f64,
    /// Largest |altitude setpoint - true altitude| over the segment after 15 s (m): how well
    /// altitude is held through the turns.
    pub alt_hold_error_max_m: f64,
}

/// Why a flight ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Ending {
    /// Its duration was flown.
    Duration,
    /// The autopilot landed and disarmed (`stop_when_landed`).
    Landed,
    /// The autopilot closed the simulator link (`until_link_closes`).
    LinkClosed,
    /// The user stopped it (Ctrl-C).
    Stopped,
    /// The simulator link failed; the flight is returned inside the error.
    LinkFailed,
}

impl Ending {
    /// In words, for the printed summary.
    pub fn describe(self) -> &'static str {
        match self {
            Ending::Duration => "its duration was flown",
            Ending::Landed => "landed and disarmed",
            Ending::LinkClosed => "the autopilot closed the simulator link",
            Ending::Stopped => "stopped (Ctrl-C)",
            Ending::LinkFailed => "the simulator link failed",
        }
    }
}

/// Figures of a flight.
#[derive(Clone, Debug, Serialize)]
pub struct FlightSummary {
    /// Why the flight ended.
    pub ended: Ending,
    /// Sensor frames exchanged.
    pub frames: u64,
    /// Frames the autopilot flew (armed).
    pub armed_frames: u64,
    /// Simulated time, s.
    pub sim_s: f64,
    /// Wall-clock time of the loop, s.
    pub wall_s: f64,
    /// Simulated seconds per wall second.
    pub real_time_factor: f64,
    /// Seed.
    pub seed: u64,
    /// Turbulence.
    pub turbulence: &'static str,
    /// Steady wind, NED, m/s.
    pub wind_ned: [f64; 3],
    /// Arming accepted at, s (without a scripted station: the first armed answer).
    pub armed_at_s: Option<f64>,
    /// Estimator errors from the first `converged` to the end.
    pub estimator: Option<EstimatorErrors>,
    /// Estimator errors from 30 s after the first `converged` ([`SETTLE_S`]) to the end: the
    /// launch transient flown out.
    pub estimator_settled: Option<EstimatorErrors>,
    /// One entry per altitude or course command.
    pub segments: Vec<Segment>,
    /// Every ground-station command and its answer.
    pub commands: Vec<CommandRecord>,
    /// The autopilot's STATUSTEXT messages.
    pub texts: Vec<(f64, String)>,
    /// Parameters the script read: time, name, value.
    pub params_read: Vec<(f64, String, f32)>,
    /// The landed state the station read in EXTENDED_SYS_STATE, each time it changed: time,
    /// state (`ON_GROUND`, `TAKEOFF`, `IN_AIR`, `LANDING`, `UNDEFINED`).
    pub landed_states: Vec<(f64, String)>,
    /// Framing counters of the autopilot's answers (simulator side).
    pub sim_rx: LinkStatsJson,
    /// The autopilot's counters of what it received (`None`: an autopilot outside this
    /// process keeps them to itself).
    pub autopilot_rx: Option<AutopilotRx>,
    /// The first contact of the last landing flown armed (of the last landing, when the flight
    /// was never armed), wherever it was (a mission's figures measure it from its landing
    /// point).
    pub touchdown: Option<TouchdownSummary>,
    /// The first contact after an airborne phase of at least a second that began once the
    /// autopilot had disarmed: the wind lifted the aircraft left on the runway (its
    /// three-point attitude's C_L of about 0.8 carries the weight from about 11 m/s of
    /// airspeed). Not the autopilot's landing; reported so that it is seen.
    pub lifted_after_disarm: Option<TouchdownSummary>,
    /// Mission and geofence uploads: what, when, the MISSION_ACK result.
    pub uploads: Vec<(String, f64, String)>,
    /// How the mission went, when one was uploaded.
    pub mission: Option<MissionSummary>,
    /// What the flight took from the battery.
    pub battery: Option<BatterySummary>,
}

impl FlightSummary {
    /// The MISSION_ACK result of each upload, in order (`"MAV_MISSION_ACCEPTED"`, ...).
    pub fn upload_results(&self) -> Vec<&str> {
        self.uploads.iter().map(|u| u.2.as_str()).collect()
    }
}

use super::measures::max_abs;
use super::measures::{rms, HomeDatum};
pub use super::mission_summary::{
    mission_summary, share_on_stop_pct, touchdown_summary, MissionSummary, TouchdownSummary,
};

/// [`LinkStats`] for JSON.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct LinkStatsJson {
    /// Frames decoded.
    pub frames_ok: u32,
    /// CRC errors.
    pub crc_errors: u32,
    /// Unknown message ids.
    pub unknown_ids: u32,
    /// Undecodable payloads.
    pub parse_errors: u32,
    /// Bytes skipped.
    pub bytes_skipped: u32,
    /// Sequence gaps.
    pub seq_gaps: u32,
}

impl From<LinkStats> for LinkStatsJson {
    fn from(s: LinkStats) -> Self {
        Self {
            frames_ok: s.frames_ok,
            crc_errors: s.crc_errors,
            unknown_ids: s.unknown_ids,
            parse_errors: s.parse_errors,
            bytes_skipped: s.bytes_skipped,
            seq_gaps: s.seq_gaps,
        }
    }
}

/// What the autopilot counted on its simulator link.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct AutopilotRx {
    /// Framing counters.
    pub framing: LinkStatsJson,
    /// Sensor frames accepted.
    pub sensor_frames: u32,
    /// GPS frames accepted.
    pub gps_frames: u32,
    /// Frames from other systems.
    pub foreign_frames: u32,
    /// Frames of messages the sim link does not carry.
    pub ignored_frames: u32,
    /// Sensor groups rejected (IMU, mag, baro, pitot) and GPS frames rejected.
    pub rejected: [u32; 5],
    /// Stale sensor frames.
    pub stale_frames: u32,
}

/// Estimator errors over the samples from `delay_s` after the first `converged` on.
pub fn estimator_errors(samples: &[Sample], delay_s: f64) -> Option<EstimatorErrors> {
    let datum = HomeDatum::of(samples);
    let t0 = samples.iter().find(|s| s.converged)?.t + delay_s;
    let first = samples.iter().position(|s| s.t >= t0)?;
    let s = &samples[first..];
    let col = |f: &dyn Fn(&Sample) -> f64| s.iter().map(f).collect::<Vec<f64>>();
    let roll = col(&|x| wrap_pi(x.est_roll - x.roll) * DEG);
    let pitch = col(&|x| wrap_pi(x.est_pitch - x.pitch) * DEG);
    let yaw = col(&|x| wrap_pi(x.est_yaw - x.yaw) * DEG);
    let alt = col(&|x| x.est_alt - datum.truth_alt(x));
    let va = col(&|x| x.est_airspeed - x.airspeed);
    let wind = col(&|x| (x.est_wind[0] - x.wind_steady[0]).hypot(x.est_wind[1] - x.wind_steady[1]));
    let wind_t = col(&|x| (x.est_wind[0] - x.wind[0]).hypot(x.est_wind[1] - x.wind[1]));
    Some(EstimatorErrors {
        from_s: s[0].t,
        samples: s.len(),
        roll_rms_deg: rms(&roll),
        pitch_rms_deg: rms(&pitch),
        heading_rms_deg: rms(&yaw),
        alt_rms_m: rms(&alt),
        home_alt_error_m: datum.error_m,
        airspeed_rms_mps: rms(&va),
        wind_rms_mps: rms(&wind),
        wind_total_rms_mps: rms(&wind_t),
        roll_max_deg: max_abs(&roll),
        pitch_max_deg: max_abs(&pitch),
        heading_max_deg: max_abs(&yaw),
        alt_max_m: max_abs(&alt),
    })
}

/// Step figures of each scripted altitude and course command.
fn segments(samples: &[Sample], gcs: &GroundStation, home_alt: f64) -> Vec<Segment> {
    let Some(t0) = gcs.armed_at_s() else {
        return Vec::new();
    };
    let datum = HomeDatum::of(samples);
    let end = samples.last().map_or(0.0, |s| s.t);
    let steps = &gcs.script().steps;
    let t: Vec<f64> = samples.iter().map(|s| s.t).collect();
    let mut out = Vec::new();
    for (i, step) in steps.iter().enumerate() {
        // The command goes out at the first frame at or after its time.
        let Some(k0) = samples.iter().position(|s| s.t >= t0 + step.after_arm_s) else {
            break;
        };
        let ts = samples[k0].t;
        let te = steps
            .get(i + 1)
            .map_or(end + 1e-9, |n| t0 + n.after_arm_s)
            .min(end + 1e-9);
        let idx: Vec<usize> = (k0..samples.len()).filter(|&k| samples[k].t < te).collect();
        let last5: Vec<usize> = idx
            .iter()
            .copied()
            .filter(|&k| samples[k].t >= te - 5.0)
            .collect();
        let alt_hold_error_max_m = idx
            .iter()
            .filter(|&&k| samples[k].t >= ts + 15.0)
            .map(|&k| (samples[k].sp_alt - datum.truth_alt(&samples[k])).abs())
            .fold(0.0, f64::max);
        let (signal, command, y, y0) = match step.action {
            Action::AltitudeAboveHome(h) => {
                let y: Vec<f64> = samples.iter().map(|s| s.alt).collect();
                ("altitude", home_alt + f64::from(h), y, samples[k0].alt)
            }
            Action::Turn(_) => {
                // Unwrap the course about its value at the command, and read the new
                // setpoint the autopilot adopted one frame later.
                let c0 = samples[k0].course;
                let y: Vec<f64> = samples
                    .iter()
                    .map(|s| (c0 + wrap_pi(s.course - c0)) * DEG)
                    .collect();
                let sp = samples
                    .get(k0 + 1)
                    .map_or(samples[k0].sp_course, |s| s.sp_course);
                let target = (c0 + wrap_pi(sp - c0)) * DEG;
                // A 90 deg turn passes +-180 from the start value only past the target.
                ("course", target, y, c0 * DEG)
            }
            _ => continue,
        };
        let metrics = step_metrics(&t, &y, y0, command, ts, te);
        let final_error_max = last5
            .iter()
            .map(|&k| (command - y[k]).abs())
            .fold(0.0, f64::max);
        out.push(Segment {
            what: gcs
                .commands
                .iter()
                .find(|c| (c.t_s - ts).abs() < 1e-9)
                .map_or_else(|| format!("{:?}", step.action), |c| c.what.clone()),
            signal,
            t_s: ts,
            t_end_s: te,
            command,
            metrics,
            final_error_max,
            alt_hold_error_max_m,
        });
    }
    out
}

/// What the flight loop hands [`summarise`] beside the log.
pub(crate) struct FlightFacts<'a> {
    /// The scripted station, when there was one.
    pub gcs: Option<&'a GroundStation>,
    /// Frames exchanged.
    pub frames: u64,
    /// Sensor frame period, s.
    pub frame_s: f64,
    /// Frames the autopilot flew.
    pub armed_frames: u64,
    /// Wall-clock time, s.
    pub wall_s: f64,
    /// Framing counters of the autopilot's answers.
    pub sim_rx: LinkStats,
    /// The autopilot's own counters, when it can be looked into.
    pub health: Option<(SimLinkHealth, LinkStats)>,
    /// Field elevation, m AMSL.
    pub home_alt: f64,
    /// Why the flight ended.
    pub ended: Ending,
}

/// Builds the summary of a flight.
pub(crate) fn summarise(cfg: &FlightConfig, samples: &[Sample], f: &FlightFacts) -> FlightSummary {
    let sim_s = f.frames as f64 * f.frame_s;
    FlightSummary {
        ended: f.ended,
        uploads: f.gcs.map(|g| g.uploads.clone()).unwrap_or_default(),
        mission: None,
        touchdown: None,
        lifted_after_disarm: None,
        battery: battery_summary(samples),
        frames: f.frames,
        armed_frames: f.armed_frames,
        sim_s,
        wall_s: f.wall_s,
        real_time_factor: if f.wall_s > 0.0 {
            sim_s / f.wall_s
        } else {
            0.0
        },
        seed: cfg.seed,
        turbulence: turbulence_name(cfg.turbulence),
        wind_ned: cfg.wind_ned,
        // When the station's arming was accepted; without a station, the first armed answer.
        armed_at_s: match f.gcs {
            Some(g) => g.armed_at_s(),
            None => samples.iter().find(|s| s.armed).map(|s| s.t),
        },
        estimator: estimator_errors(samples, 0.0),
        estimator_settled: estimator_errors(samples, SETTLE_S),
        segments: f
            .gcs
            .map(|g| segments(samples, g, f.home_alt))
            .unwrap_or_default(),
        commands: f.gcs.map(|g| g.commands.clone()).unwrap_or_default(),
        texts: f.gcs.map(|g| g.texts.clone()).unwrap_or_default(),
        params_read: f.gcs.map(|g| g.params_read.clone()).unwrap_or_default(),
        landed_states: f
            .gcs
            .map(|g| {
                g.landed_states
                    .iter()
                    .map(|&(t, l)| {
                        let name = format!("{l:?}");
                        let short = name.trim_start_matches("MAV_LANDED_STATE_").to_string();
                        (t, short)
                    })
                    .collect()
            })
            .unwrap_or_default(),
        sim_rx: f.sim_rx.into(),
        autopilot_rx: f.health.map(|(health, ap_stats)| AutopilotRx {
            framing: ap_stats.into(),
            sensor_frames: health.sensor_frames,
            gps_frames: health.gps_frames,
            foreign_frames: health.foreign_frames,
            ignored_frames: health.ignored_frames,
            rejected: [
                health.rejected_imu,
                health.rejected_mag,
                health.rejected_baro,
                health.rejected_pitot,
                health.rejected_gps,
            ],
            stale_frames: health.stale_frames,
        }),
    }
}

/// What a flight took from the battery: the simulated pack's truth, and the autopilot's
/// estimate of the charge left at the end.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct BatterySummary {
    /// Energy drawn from the pack, Wh.
    pub energy_wh: f64,
    /// Charge drawn from the pack, mAh.
    pub charge_mah: f64,
    /// Lowest terminal voltage, V.
    pub min_voltage_v: f64,
    /// Charge left at the end, %.
    pub final_remaining_pct: f64,
    /// The autopilot's estimate of the charge left at the end, % (NaN: no battery monitored).
    pub final_estimate_pct: f64,
}

/// The battery's figures of a flight's log (`None` for an empty log).
pub fn battery_summary(samples: &[Sample]) -> Option<BatterySummary> {
    let last = samples.last()?;
    Some(BatterySummary {
        energy_wh: last.bat_energy_wh,
        charge_mah: last.bat_drawn_mah,
        min_voltage_v: samples
            .iter()
            .map(|s| s.bat_voltage)
            .fold(f64::INFINITY, f64::min),
        final_remaining_pct: last.bat_soc * 100.0,
        final_estimate_pct: last.est_bat_remaining * 100.0,
    })
}
