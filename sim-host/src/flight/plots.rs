//! The flight's figures: altitude, course, attitude and the battery against time, and the
//! ground track, drawn from plain series so a simulated flight and a flight log draw the same.

use super::record::{csv_headers, csv_row, Sample, DEG};
use crate::report::csv_out::write_csv;
use crate::report::plot::{Figure, Panel, Series};
use common::math::wrap_pi;
use std::path::{Path, PathBuf};

/// What a flight's figures draw, each panel's lines as plain series against time (s), the
/// ground track's as east (x) and north (y), m: a simulated flight's ([`FlightSeries::of_samples`],
/// truth beside the autopilot's view) or a flight log's (`sim-host log`, the autopilot's view
/// alone). A line without a finite value is not drawn, nor a panel without a line.
#[derive(Clone, Debug, Default)]
pub struct FlightSeries {
    /// Altitude above mean sea level, m.
    pub altitude_m: Vec<Series>,
    /// Airspeed, m/s.
    pub airspeed_mps: Vec<Series>,
    /// Elevator (deg) and throttle (%).
    pub elevator_throttle: Vec<Series>,
    /// Course over ground, 0..360 deg.
    pub course_deg: Vec<Series>,
    /// Heading, 0..360 deg.
    pub heading_deg: Vec<Series>,
    /// Aileron and rudder, deg.
    pub aileron_rudder_deg: Vec<Series>,
    /// Roll, deg.
    pub roll_deg: Vec<Series>,
    /// Pitch, deg.
    pub pitch_deg: Vec<Series>,
    /// The heading estimate's error, deg (only where the truth is known).
    pub heading_error_deg: Vec<Series>,
    /// Battery voltage, V.
    pub voltage_v: Vec<Series>,
    /// Battery current, A.
    pub current_a: Vec<Series>,
    /// Charge left, %.
    pub charge_left_pct: Vec<Series>,
    /// The ground track: east as x, north as y, m.
    pub track_m: Vec<Series>,
}

/// An angle in radians as degrees in 0..360.
fn deg360(x: f64) -> f64 {
    (x * DEG).rem_euclid(360.0)
}

impl FlightSeries {
    /// A simulated flight's series: the truth, the estimate and the setpoints, at 10 Hz
    /// (enough for the eye, light for the encoder).
    pub fn of_samples(samples: &[Sample]) -> Self {
        let p: Vec<&Sample> = samples.iter().step_by(10).collect();
        let t: Vec<f64> = p.iter().map(|s| s.t).collect();
        let col = |f: &dyn Fn(&Sample) -> f64| p.iter().map(|s| f(s)).collect::<Vec<f64>>();
        let line = |label: &str, f: &dyn Fn(&Sample) -> f64| Series::new(label, t.clone(), col(f));
        // Only while the autopilot monitors a battery.
        let known: Vec<&&Sample> = p
            .iter()
            .filter(|s| s.est_bat_remaining.is_finite())
            .collect();
        Self {
            altitude_m: vec![
                line("truth", &|s| s.alt),
                line("estimate", &|s| s.est_alt),
                line("setpoint", &|s| s.sp_alt).dashed(),
            ],
            airspeed_mps: vec![
                line("truth", &|s| s.airspeed),
                line("estimate", &|s| s.est_airspeed),
                line("setpoint", &|s| s.sp_airspeed).dashed(),
            ],
            elevator_throttle: vec![
                line("elevator", &|s| s.elevator * DEG),
                line("throttle", &|s| s.throttle * 100.0),
            ],
            course_deg: vec![
                line("truth", &|s| deg360(s.course)),
                line("estimate", &|s| deg360(s.est_course)),
                line("setpoint", &|s| deg360(s.sp_course)).dashed(),
            ],
            heading_deg: vec![
                line("truth", &|s| deg360(s.yaw)),
                line("estimate", &|s| deg360(s.est_yaw)),
            ],
            aileron_rudder_deg: vec![
                line("aileron", &|s| s.aileron * DEG),
                line("rudder", &|s| s.rudder * DEG),
            ],
            roll_deg: vec![
                line("truth", &|s| s.roll * DEG),
                line("estimate", &|s| s.est_roll * DEG).dashed(),
            ],
            pitch_deg: vec![
                line("truth", &|s| s.pitch * DEG),
                line("estimate", &|s| s.est_pitch * DEG).dashed(),
            ],
            heading_error_deg: vec![line("estimate - truth", &|s| {
                wrap_pi(s.est_yaw - s.yaw) * DEG
            })],
            voltage_v: vec![line("truth", &|s| s.bat_voltage)],
            current_a: vec![line("truth", &|s| s.bat_current)],
            charge_left_pct: vec![
                line("truth", &|s| s.bat_soc * 100.0),
                Series::new(
                    "estimate",
                    known.iter().map(|s| s.t).collect(),
                    known.iter().map(|s| s.est_bat_remaining * 100.0).collect(),
                )
                .dashed(),
            ],
            track_m: track_series(samples),
        }
    }

    /// The figures, each with its file name: altitude, course, attitude, battery and the
    /// ground track.
    pub fn figures(&self) -> Vec<(&'static str, Figure)> {
        let truth = self
            .voltage_v
            .iter()
            .any(|s| s.label == "truth" && s.y.iter().any(|v| v.is_finite()));
        let attitude: Vec<&str> = self
            .roll_deg
            .iter()
            .chain(&self.pitch_deg)
            .filter(|s| s.y.iter().any(|v| v.is_finite()))
            .map(|s| s.label.as_str())
            .fold(Vec::new(), |mut seen, l| {
                if !seen.contains(&l) {
                    seen.push(l);
                }
                seen
            });
        let figure = |title: &str, panels: Vec<(&str, &Vec<Series>)>| {
            Figure::new(
                title,
                "t (s)",
                panels
                    .into_iter()
                    .map(|(label, series)| Panel::new(label, series.clone()))
                    .collect(),
            )
        };
        let wrapped = |series: &[Series]| series.iter().map(break_wraps).collect::<Vec<_>>();
        let (course, heading) = (wrapped(&self.course_deg), wrapped(&self.heading_deg));
        vec![
            (
                "altitude.png",
                figure(
                    "Altitude",
                    vec![
                        ("altitude AMSL (m)", &self.altitude_m),
                        ("airspeed (m/s)", &self.airspeed_mps),
                        ("elevator (deg), throttle (%)", &self.elevator_throttle),
                    ],
                ),
            ),
            (
                "course.png",
                figure(
                    "Course and heading",
                    vec![
                        ("course (deg)", &course),
                        ("heading (deg)", &heading),
                        ("aileron, rudder (deg)", &self.aileron_rudder_deg),
                    ],
                ),
            ),
            (
                "attitude.png",
                figure(
                    &format!("Attitude: {}", attitude.join(" and ")),
                    vec![
                        ("roll (deg)", &self.roll_deg),
                        ("pitch (deg)", &self.pitch_deg),
                        ("heading error (deg)", &self.heading_error_deg),
                    ],
                ),
            ),
            (
                "battery.png",
                figure(
                    if truth {
                        "Battery: the simulated pack and the autopilot's estimate"
                    } else {
                        "Battery: as the autopilot measured and estimated it"
                    },
                    vec![
                        ("voltage (V)", &self.voltage_v),
                        ("current (A)", &self.current_a),
                        ("charge left (%)", &self.charge_left_pct),
                    ],
                ),
            ),
            (
                "ground_track.png",
                ground_track_figure(self.track_m.clone(), "Ground track"),
            ),
        ]
    }

    /// Draws the figures into `dir`; returns the files written.
    pub fn write_figures(&self, dir: &Path) -> anyhow::Result<Vec<PathBuf>> {
        let mut files = Vec::new();
        for (name, mut f) in self.figures() {
            // An autopilot seen only through its links (QEMU, `sim-host sim`) leaves its
            // estimate and setpoints out of the simulator's log, and a flight log holds no
            // truth: no line for them, no panel when none is left, no figure without a panel
            // (a log cut before its first sample).
            for p in &mut f.panels {
                p.series.retain(|s| s.y.iter().any(|v| v.is_finite()));
            }
            f.panels.retain(|p| !p.series.is_empty());
            if f.panels.is_empty() {
                continue;
            }
            let path = dir.join(name);
            f.save_png(&path)?;
            files.push(path);
        }
        Ok(files)
    }
}

/// An angle series in 0..360 deg broken (a NaN put in) where it wraps: a line drawn across
/// the wrap would sweep the panel, and a thick line turning back on itself within a pixel
/// spikes out of it.
pub fn break_wraps(s: &Series) -> Series {
    let mut x = Vec::with_capacity(s.x.len());
    let mut y = Vec::with_capacity(s.y.len());
    for (i, (&xi, &yi)) in s.x.iter().zip(&s.y).enumerate() {
        if i > 0 && (yi - s.y[i - 1]).abs() > 180.0 {
            x.push(xi);
            y.push(f64::NAN);
        }
        x.push(xi);
        y.push(yi);
    }
    Series { x, y, ..s.clone() }
}

/// The ground track of a simulated flight, truth and estimate, at 10 Hz.
pub fn track_series(samples: &[Sample]) -> Vec<Series> {
    let p: Vec<&Sample> = samples.iter().step_by(10).collect();
    let truth = Series::new(
        "truth",
        p.iter().map(|s| s.east).collect(),
        p.iter().map(|s| s.north).collect(),
    );
    let valid: Vec<&&Sample> = p.iter().filter(|s| s.est_north.is_finite()).collect();
    let est = Series::new(
        "estimate",
        valid.iter().map(|s| s.est_east).collect(),
        valid.iter().map(|s| s.est_north).collect(),
    )
    .dashed();
    vec![truth, est]
}

/// A ground track (east as x, north as y) as a map, one metre as long on both axes.
pub fn ground_track_figure(track: Vec<Series>, title: &str) -> Figure {
    Figure::new(title, "east (m)", vec![Panel::new("north (m)", track)]).map()
}

/// Writes `flight.csv` and the PNG plots into `dir`; returns the files written.
pub fn write_log_and_plots(dir: &Path, samples: &[Sample]) -> anyhow::Result<Vec<PathBuf>> {
    let csv = dir.join("flight.csv");
    let rows: Vec<Vec<f64>> = samples.iter().map(csv_row).collect();
    write_csv(&csv, &csv_headers(), &rows)?;
    let mut files = vec![csv];
    files.extend(FlightSeries::of_samples(samples).write_figures(dir)?);
    Ok(files)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_angle_that_wraps_past_north_is_broken_there_and_nowhere_else() {
        let s = Series::new("c", vec![0.0, 1.0, 2.0, 3.0], vec![350.0, 359.0, 2.0, 10.0]);
        let b = break_wraps(&s);
        assert_eq!(b.x, vec![0.0, 1.0, 2.0, 2.0, 3.0]);
        assert_eq!(b.y[..2], [350.0, 359.0]);
        assert!(b.y[2].is_nan());
        assert_eq!(b.y[3..], [2.0, 10.0]);
    }
}
