//! `sim-host log FILE`: a flight log's summary (what flew, how long, in which modes, how
//! high, how fast, how far, on how much of the battery, and what the log lost) and the
//! figures a simulated flight draws, from the log alone.
//!
//! Times are seconds from the log's start (its header's timestamp: arming, for this
//! autopilot). The topics read are PX4's where PX4 has them (`vehicle_status`,
//! `vehicle_attitude`, `vehicle_local_position`, ...), so a PX4 log gives the same summary;
//! the setpoints and surfaces come from this autopilot's own `control_loops`.

use crate::flight::plots::FlightSeries;
use crate::flight::record::DEG;
use crate::report::plot::Series;
use crate::report::sig;
use crate::report::table::Table;
use crate::ulog_read::{read_file, Dataset, Ulog};
use anyhow::Context;
use common::math::Euler;
use nalgebra::{Quaternion, UnitQuaternion};
use serde::Serialize;
use std::path::{Path, PathBuf};

/// A stretch of the flight in one mode.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ModeSpan {
    /// The mode's name (the project's, by PX4's navigation state).
    pub mode: String,
    /// PX4's navigation state (`vehicle_status.nav_state`).
    pub nav_state: u8,
    /// From, s after the log's start.
    pub from_s: f64,
    /// To, s after the log's start.
    pub to_s: f64,
}

/// The least, the greatest and the mean of a quantity.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Range {
    /// Least.
    pub min: f64,
    /// Greatest.
    pub max: f64,
    /// Mean over the samples.
    pub mean: f64,
}

impl Range {
    /// The range of the finite values, if any.
    pub fn of(values: &[f64]) -> Option<Self> {
        let v: Vec<f64> = values.iter().copied().filter(|x| x.is_finite()).collect();
        (!v.is_empty()).then(|| Self {
            min: v.iter().copied().fold(f64::INFINITY, f64::min),
            max: v.iter().copied().fold(f64::NEG_INFINITY, f64::max),
            mean: v.iter().sum::<f64>() / v.len() as f64,
        })
    }
}

/// Roll and pitch over the log, from the attitude estimate.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct AttitudeStats {
    /// Greatest bank either way, deg.
    pub roll_max_abs_deg: f64,
    /// RMS roll, deg.
    pub roll_rms_deg: f64,
    /// Least pitch (the steepest dive), deg.
    pub pitch_min_deg: f64,
    /// Greatest pitch, deg.
    pub pitch_max_deg: f64,
    /// RMS pitch, deg.
    pub pitch_rms_deg: f64,
}

/// What the battery gave over the log, as the autopilot measured it.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct BatteryUse {
    /// Charge drawn between the first and the last sample, mAh.
    pub used_mah: f64,
    /// Voltage at the first sample, V.
    pub voltage_start_v: f64,
    /// Lowest voltage, V.
    pub voltage_min_v: f64,
    /// Charge left at the first sample, %.
    pub remaining_start_pct: f64,
    /// Charge left at the last sample, %.
    pub remaining_end_pct: f64,
}

/// A text the autopilot logged.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TextLine {
    /// When, s after the log's start.
    pub t_s: f64,
    /// Its level (`info`, `warning`, ...).
    pub level: String,
    /// The text.
    pub text: String,
}

/// One topic of the log: its samples and their rate.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TopicRate {
    /// Topic name.
    pub name: String,
    /// Its instance.
    pub multi_id: u8,
    /// Samples read.
    pub samples: usize,
    /// Samples per second between its first and last sample, Hz.
    pub rate_hz: f64,
}

/// A flight log's summary.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LogSummary {
    /// The file read.
    pub file: String,
    /// Its bytes.
    pub bytes: usize,
    /// Bytes read: the end of its last whole message.
    pub bytes_read: usize,
    /// `sys_name`.
    pub sys_name: Option<String>,
    /// `ver_sw`.
    pub ver_sw: Option<String>,
    /// `ver_hw`.
    pub ver_hw: Option<String>,
    /// When the log started, s on the autopilot's clock.
    pub start_s: f64,
    /// From the log's start to its last sample or text, s.
    pub duration_s: f64,
    /// The modes flown, in order (from `vehicle_status.nav_state`).
    pub modes: Vec<ModeSpan>,
    /// Roll and pitch.
    pub attitude: Option<AttitudeStats>,
    /// Altitude above mean sea level, m (`vehicle_global_position`).
    pub altitude_amsl_m: Option<Range>,
    /// Height above home, m (`vehicle_local_position`).
    pub height_m: Option<Range>,
    /// Airspeed, m/s (`airspeed_validated`).
    pub airspeed_mps: Option<Range>,
    /// Horizontal distance flown over the ground, m (`vehicle_local_position`).
    pub distance_m: Option<f64>,
    /// What the battery gave.
    pub battery: Option<BatteryUse>,
    /// Dropouts: times the writer lost data.
    pub dropouts: usize,
    /// Data lost in all, ms.
    pub dropout_ms: u64,
    /// Sync markers.
    pub syncs: usize,
    /// The texts, in order.
    pub texts: Vec<TextLine>,
    /// Parameters at the start.
    pub parameters: usize,
    /// Parameter changes during the log.
    pub parameter_changes: usize,
    /// Every topic.
    pub topics: Vec<TopicRate>,
    /// What the reader skipped, and where the log ends short of the file.
    pub warnings: Vec<String>,
}

/// What `sim-host log` produced.
pub struct LogReport {
    /// The summary.
    pub summary: LogSummary,
    /// The figures written.
    pub files: Vec<PathBuf>,
}

/// Reads the log in `path`, summarises it and draws its figures into `out`.
pub fn log_report(path: &Path, out: &Path) -> anyhow::Result<LogReport> {
    let log = read_file(path)?;
    let summary = summarize(&path.display().to_string(), &log);
    std::fs::create_dir_all(out).with_context(|| format!("cannot create `{}`", out.display()))?;
    let files = flight_series(&log).write_figures(out)?;
    Ok(LogReport { summary, files })
}

/// Seconds from the log's start of each sample of `d`.
fn times_s(log: &Ulog, d: &Dataset) -> Vec<f64> {
    d.timestamps_us()
        .iter()
        .map(|&t| (t as f64 - log.start_us as f64) * 1e-6)
        .collect()
}

/// Field `field` of topic `topic`, with its times: empty when the log has neither.
fn column(log: &Ulog, topic: &str, field: &str) -> (Vec<f64>, Vec<f64>) {
    log.dataset(topic)
        .and_then(|d| Some((times_s(log, d), d.field(field)?)))
        .unwrap_or_default()
}

/// Roll, pitch and yaw (rad) of every `vehicle_attitude` sample, with their times.
fn euler(log: &Ulog) -> (Vec<f64>, Vec<Euler<f64>>) {
    let (t, w) = column(log, "vehicle_attitude", "q[0]");
    let q: Vec<Vec<f64>> = (1..4)
        .map(|i| column(log, "vehicle_attitude", &format!("q[{i}]")).1)
        .collect();
    let e = (0..w.len().min(q.iter().map(Vec::len).min().unwrap_or(0)))
        .map(|i| {
            let q = Quaternion::new(w[i], q[0][i], q[1][i], q[2][i]);
            Euler::from_quaternion(&UnitQuaternion::from_quaternion(q))
        })
        .collect::<Vec<_>>();
    (t[..e.len()].to_vec(), e)
}

fn rms(v: &[f64]) -> f64 {
    (v.iter().map(|x| x * x).sum::<f64>() / v.len().max(1) as f64).sqrt()
}

/// The mode spans of `vehicle_status`, the last one to the log's end.
fn modes(log: &Ulog, end_s: f64) -> Vec<ModeSpan> {
    let (t, nav) = column(log, "vehicle_status", "nav_state");
    let mut spans: Vec<ModeSpan> = Vec::new();
    for (&t, &n) in t.iter().zip(&nav) {
        let n = n as u8;
        if spans.last().is_some_and(|s| s.nav_state == n) {
            continue;
        }
        if let Some(last) = spans.last_mut() {
            last.to_s = t;
        }
        let mode = common::vehicle::modes::MODES
            .iter()
            .find(|m| m.px4_nav_state == n)
            .map_or_else(|| format!("nav_state {n}"), |m| m.name.to_string());
        spans.push(ModeSpan {
            mode,
            nav_state: n,
            from_s: t,
            to_s: end_s,
        });
    }
    spans
}

/// The horizontal path length of the valid local positions.
fn distance(log: &Ulog) -> Option<f64> {
    let d = log.dataset("vehicle_local_position")?;
    let (x, y) = (d.field("x")?, d.field("y")?);
    let valid = d.field("xy_valid").unwrap_or_else(|| vec![1.0; x.len()]);
    let pts: Vec<(f64, f64)> = x
        .iter()
        .zip(&y)
        .zip(&valid)
        .filter(|(_, &v)| v != 0.0)
        .map(|((&x, &y), _)| (x, y))
        .collect();
    (pts.len() > 1).then(|| {
        pts.windows(2)
            .map(|w| (w[1].0 - w[0].0).hypot(w[1].1 - w[0].1))
            .sum()
    })
}

fn battery(log: &Ulog) -> Option<BatteryUse> {
    let d = log.dataset("battery_status").filter(|d| !d.is_empty())?;
    let (v, mah, rem) = (
        d.field("voltage_v")?,
        d.field("discharged_mah")?,
        d.field("remaining")?,
    );
    Some(BatteryUse {
        used_mah: mah.last()? - mah.first()?,
        voltage_start_v: *v.first()?,
        voltage_min_v: v.iter().copied().fold(f64::INFINITY, f64::min),
        remaining_start_pct: rem.first()? * 100.0,
        remaining_end_pct: rem.last()? * 100.0,
    })
}

/// The summary of `log`, read from `file`.
pub fn summarize(file: &str, log: &Ulog) -> LogSummary {
    let duration_s = (log.last_us().saturating_sub(log.start_us)) as f64 * 1e-6;
    let (_, att) = euler(log);
    let roll: Vec<f64> = att.iter().map(|e| e.phi * DEG).collect();
    let pitch: Vec<f64> = att.iter().map(|e| e.theta * DEG).collect();
    let attitude = (!att.is_empty()).then(|| AttitudeStats {
        roll_max_abs_deg: roll.iter().fold(0.0, |m: f64, r| m.max(r.abs())),
        roll_rms_deg: rms(&roll),
        pitch_min_deg: pitch.iter().copied().fold(f64::INFINITY, f64::min),
        pitch_max_deg: pitch.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        pitch_rms_deg: rms(&pitch),
    });
    let height: Vec<f64> = column(log, "vehicle_local_position", "z")
        .1
        .iter()
        .map(|z| -z)
        .collect();
    let info = |k: &str| log.info_text(k);
    LogSummary {
        file: file.to_string(),
        bytes: log.file_len,
        bytes_read: log.bytes_read,
        sys_name: info("sys_name"),
        ver_sw: info("ver_sw"),
        ver_hw: info("ver_hw"),
        start_s: log.start_us as f64 * 1e-6,
        duration_s,
        modes: modes(log, duration_s),
        attitude,
        altitude_amsl_m: Range::of(&column(log, "vehicle_global_position", "alt").1),
        height_m: Range::of(&height),
        airspeed_mps: Range::of(&column(log, "airspeed_validated", "true_airspeed_m_s").1),
        distance_m: distance(log),
        battery: battery(log),
        dropouts: log.dropouts.len(),
        dropout_ms: log.dropouts.iter().map(|d| u64::from(d.duration_ms)).sum(),
        syncs: log.syncs,
        texts: log
            .texts
            .iter()
            .map(|t| TextLine {
                t_s: (t.timestamp_us as f64 - log.start_us as f64) * 1e-6,
                level: t.level_name().to_string(),
                text: t.text.clone(),
            })
            .collect(),
        parameters: log.params.len(),
        parameter_changes: log.param_changes.len(),
        topics: log
            .datasets
            .iter()
            .map(|d| {
                let t = d.timestamps_us();
                let span_s = match (t.first(), t.last()) {
                    (Some(a), Some(b)) => b.saturating_sub(*a) as f64 * 1e-6,
                    _ => 0.0,
                };
                TopicRate {
                    name: d.name.clone(),
                    multi_id: d.multi_id,
                    samples: d.len(),
                    rate_hz: if span_s > 0.0 {
                        (d.len() - 1) as f64 / span_s
                    } else {
                        0.0
                    },
                }
            })
            .collect(),
        warnings: log.warnings.iter().map(|w| w.to_string()).collect(),
    }
}

/// The figures' series from the log: the autopilot's estimate and setpoints (a log holds no
/// truth).
pub fn flight_series(log: &Ulog) -> FlightSeries {
    let line = |label: &str, topic: &str, field: &str, scale: f64| {
        let (t, y) = column(log, topic, field);
        Series::new(label, t, y.iter().map(|v| v * scale).collect())
    };
    let deg360 = |s: Series| Series {
        y: s.y.iter().map(|v| v.rem_euclid(360.0)).collect(),
        ..s
    };
    let (ta, att) = euler(log);
    let attitude = |label: &str, f: &dyn Fn(&Euler<f64>) -> f64| {
        Series::new(label, ta.clone(), att.iter().map(f).collect())
    };
    // Course over ground from the estimated velocity.
    let course = log
        .dataset("vehicle_local_position")
        .and_then(|d| {
            let (vx, vy) = (d.field("vx")?, d.field("vy")?);
            Some(Series::new(
                "estimate",
                times_s(log, d),
                vx.iter().zip(&vy).map(|(n, e)| e.atan2(*n) * DEG).collect(),
            ))
        })
        .unwrap_or_else(|| Series::new("estimate", Vec::new(), Vec::new()));
    let (tp, x) = column(log, "vehicle_local_position", "x");
    let (_, y) = column(log, "vehicle_local_position", "y");
    let n = tp.len().min(x.len()).min(y.len());
    FlightSeries {
        altitude_m: vec![
            line("estimate", "vehicle_global_position", "alt", 1.0),
            line("setpoint", "control_loops", "altitude_sp", 1.0).dashed(),
        ],
        airspeed_mps: vec![
            line("estimate", "airspeed_validated", "true_airspeed_m_s", 1.0),
            line("setpoint", "control_loops", "airspeed_sp", 1.0).dashed(),
        ],
        elevator_throttle: vec![
            line("elevator", "control_loops", "elevator", DEG),
            line("throttle", "control_loops", "throttle", 100.0),
        ],
        course_deg: vec![
            deg360(course),
            deg360(line("setpoint", "control_loops", "course_sp", DEG)).dashed(),
        ],
        heading_deg: vec![deg360(attitude("estimate", &|e| e.psi * DEG))],
        aileron_rudder_deg: vec![
            line("aileron", "control_loops", "aileron", DEG),
            line("rudder", "control_loops", "rudder", DEG),
        ],
        roll_deg: vec![
            attitude("estimate", &|e| e.phi * DEG),
            line("setpoint", "vehicle_attitude_setpoint", "roll_body", DEG).dashed(),
        ],
        pitch_deg: vec![
            attitude("estimate", &|e| e.theta * DEG),
            line("setpoint", "vehicle_attitude_setpoint", "pitch_body", DEG).dashed(),
        ],
        heading_error_deg: Vec::new(),
        voltage_v: vec![line("measured", "battery_status", "voltage_v", 1.0)],
        current_a: vec![line("measured", "battery_status", "current_a", 1.0)],
        charge_left_pct: vec![line("estimate", "battery_status", "remaining", 100.0)],
        track_m: vec![Series::new("estimate", y[..n].to_vec(), x[..n].to_vec())],
    }
}

/// The summary as tables.
pub fn summary_tables(s: &LogSummary) -> Vec<Table> {
    let mut log = Table::new("Flight log", &["quantity", "value"]);
    let mut row = |k: &str, v: String| {
        log.row([k.to_string(), v]);
    };
    row("file", format!("{} ({} bytes)", s.file, s.bytes));
    if s.bytes_read < s.bytes {
        row(
            "read",
            format!("{} bytes (the rest is cut or corrupt)", s.bytes_read),
        );
    }
    let or_dash = |v: &Option<String>| v.clone().unwrap_or_else(|| "-".into());
    row(
        "system",
        format!(
            "{} {} ({})",
            or_dash(&s.sys_name),
            or_dash(&s.ver_sw),
            or_dash(&s.ver_hw)
        ),
    );
    row(
        "started",
        format!("{:.1} s on the autopilot's clock", s.start_s),
    );
    row("duration", format!("{:.1} s", s.duration_s));
    row(
        "parameters",
        format!(
            "{} ({} changed in flight)",
            s.parameters, s.parameter_changes
        ),
    );
    row(
        "dropouts",
        if s.dropouts == 0 {
            "none".into()
        } else {
            format!("{}, {} ms in all", s.dropouts, s.dropout_ms)
        },
    );
    row("sync markers", s.syncs.to_string());
    row("texts", s.texts.len().to_string());
    row("warnings", s.warnings.len().to_string());
    let mut tables = vec![log];

    if !s.modes.is_empty() {
        let mut modes = Table::new("Modes", &["mode", "from (s)", "to (s)", "for (s)"]);
        for m in &s.modes {
            modes.row([
                m.mode.clone(),
                format!("{:.1}", m.from_s),
                format!("{:.1}", m.to_s),
                format!("{:.1}", m.to_s - m.from_s),
            ]);
        }
        tables.push(modes);
    }

    let mut flight = Table::new("Flight", &["quantity", "min", "max", "mean or RMS"]);
    if let Some(a) = &s.attitude {
        flight.row([
            "roll (deg)".into(),
            String::new(),
            format!("{:.1} either way", a.roll_max_abs_deg),
            format!("{} RMS", sig(a.roll_rms_deg, 3)),
        ]);
        flight.row([
            "pitch (deg)".into(),
            format!("{:.1}", a.pitch_min_deg),
            format!("{:.1}", a.pitch_max_deg),
            format!("{} RMS", sig(a.pitch_rms_deg, 3)),
        ]);
    }
    for (name, r) in [
        ("altitude AMSL (m)", &s.altitude_amsl_m),
        ("height above home (m)", &s.height_m),
        ("airspeed (m/s)", &s.airspeed_mps),
    ] {
        if let Some(r) = r {
            flight.row([
                name.to_string(),
                format!("{:.1}", r.min),
                format!("{:.1}", r.max),
                format!("{:.1} mean", r.mean),
            ]);
        }
    }
    if let Some(d) = s.distance_m {
        flight.row([
            "distance flown (m)".into(),
            String::new(),
            String::new(),
            format!("{d:.0}"),
        ]);
    }
    if !flight.rows.is_empty() {
        tables.push(flight);
    }

    if let Some(b) = &s.battery {
        let mut bat = Table::new("Battery", &["quantity", "value"]);
        bat.row(["charge used (mAh)".into(), format!("{:.0}", b.used_mah)]);
        bat.row([
            "voltage (V)".into(),
            format!(
                "{:.2} at the start, {:.2} lowest",
                b.voltage_start_v, b.voltage_min_v
            ),
        ]);
        bat.row([
            "charge left (%)".into(),
            format!(
                "{:.1} at the start, {:.1} at the end",
                b.remaining_start_pct, b.remaining_end_pct
            ),
        ]);
        tables.push(bat);
    }

    if !s.texts.is_empty() {
        let mut texts = Table::new("Texts", &["t (s)", "level", "text"]);
        for t in &s.texts {
            texts.row([format!("{:.1}", t.t_s), t.level.clone(), t.text.clone()]);
        }
        tables.push(texts);
    }

    let mut topics = Table::new("Topics", &["topic", "instance", "samples", "rate (Hz)"]);
    for t in &s.topics {
        topics.row([
            t.name.clone(),
            t.multi_id.to_string(),
            t.samples.to_string(),
            format!("{:.2}", t.rate_hz),
        ]);
    }
    tables.push(topics);
    tables
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ulog_read::tests::Encoded;
    use common::logger::topics::VehicleStatus;
    use common::ulog::topic::Topic;
    use common::ulog::{self as enc, Level};

    /// A log of `vehicle_status` samples (time in us, nav_state), a text and two dropouts,
    /// written with the project's encoder.
    fn log(states: &[(u64, u8)]) -> Ulog {
        let mut b = Encoded::default();
        b.put(|x| enc::header(x, 2_000_000));
        b.put(enc::flag_bits);
        b.put(|x| enc::format(x, &VehicleStatus::FORMAT));
        b.put(|x| enc::add_logged(x, 0, 0, "vehicle_status"));
        for &(t, nav_state) in states {
            let s = VehicleStatus {
                arming_state: 2,
                nav_state,
                ..Default::default()
            };
            b.put(|x| enc::data(x, 0, t, |c| s.encode(c)));
        }
        b.put(|x| enc::dropout(x, 120));
        b.put(|x| enc::logging(x, Level::Critical, 3_500_000, "geofence breached"));
        b.put(|x| enc::dropout(x, 30));
        crate::ulog_read::parse(&b.0).unwrap()
    }

    #[test]
    fn modes_are_named_by_px4_navigation_state_and_last_to_the_logs_end() {
        let l = log(&[
            (2_000_000, 0),
            (2_500_000, 3),
            (3_000_000, 3),
            (3_500_000, 5),
            (4_000_000, 99),
        ]);
        let s = summarize("t.ulg", &l);
        let modes: Vec<(&str, f64, f64)> = s
            .modes
            .iter()
            .map(|m| (m.mode.as_str(), m.from_s, m.to_s))
            .collect();
        assert_eq!(
            modes,
            [
                ("Manual", 0.0, 0.5),
                ("Mission", 0.5, 1.5),
                ("Return", 1.5, 2.0),
                ("nav_state 99", 2.0, 2.0)
            ]
        );
        assert_eq!(s.duration_s, 2.0);
        assert_eq!((s.dropouts, s.dropout_ms), (2, 150));
        assert_eq!(
            s.texts,
            vec![TextLine {
                t_s: 1.5,
                level: "critical".into(),
                text: "geofence breached".into()
            }]
        );
        assert_eq!(s.topics[0].rate_hz, 2.0);
        // Topics this log lacks give no figure, not a wrong one.
        assert!(s.attitude.is_none() && s.battery.is_none() && s.distance_m.is_none());
        let tables = summary_tables(&s);
        let text = crate::commands::render(&tables, crate::commands::Format::Text);
        assert!(text.contains("2, 150 ms in all"), "{text}");
        assert!(text.contains("geofence breached"), "{text}");
        assert!(!text.contains("Flight\n"), "no figure to show: {text}");
        let dir = tempfile::tempdir().unwrap();
        assert_eq!(
            flight_series(&l).write_figures(dir.path()).unwrap(),
            Vec::<PathBuf>::new(),
            "no figure without a line to draw"
        );
    }
}
