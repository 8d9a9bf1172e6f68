//! The flight's figures: altitude, course, attitude and the battery against time, and the
//! ground track.

use super::record::{csv_headers, csv_row, Sample, DEG};
use crate::report::csv_out::write_csv;
use crate::report::plot::{Figure, Panel, Series};
use common::math::wrap_pi;
use std::path::{Path, PathBuf};

/// The ground track, truth and estimate, as a map (one metre as long on both axes), at 10 Hz.
pub fn ground_track_figure(samples: &[Sample], title: &str) -> Figure {
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
    Figure::new(
        title,
        "east (m)",
        vec![Panel::new("north (m)", vec![truth, est])],
    )
    .map()
}

/// Writes `flight.csv` and the PNG plots into `dir`; returns the files written.
pub fn write_log_and_plots(dir: &Path, samples: &[Sample]) -> anyhow::Result<Vec<PathBuf>> {
    let mut files = Vec::new();
    let csv = dir.join("flight.csv");
    let rows: Vec<Vec<f64>> = samples.iter().map(csv_row).collect();
    write_csv(&csv, &csv_headers(), &rows)?;
    files.push(csv);

    // Plots at 10 Hz: enough for the eye, light for the encoder.
    let p: Vec<&Sample> = samples.iter().step_by(10).collect();
    let t: Vec<f64> = p.iter().map(|s| s.t).collect();
    let col = |f: &dyn Fn(&Sample) -> f64| p.iter().map(|s| f(s)).collect::<Vec<f64>>();
    let fig = |name: &str, mut f: Figure| -> anyhow::Result<PathBuf> {
        // An autopilot seen only through its links (QEMU, `sim-host sim`) leaves its estimate
        // and setpoints out of the log: no line for them.
        for p in &mut f.panels {
            p.series.retain(|s| s.y.iter().any(|v| v.is_finite()));
        }
        let path = dir.join(name);
        f.save_png(&path)?;
        Ok(path)
    };
    files.push(fig(
        "altitude.png",
        Figure::new(
            "Altitude",
            "t (s)",
            vec![
                Panel::new(
                    "altitude AMSL (m)",
                    vec![
                        Series::new("truth", t.clone(), col(&|s| s.alt)),
                        Series::new("estimate", t.clone(), col(&|s| s.est_alt)),
                        Series::new("setpoint", t.clone(), col(&|s| s.sp_alt)).dashed(),
                    ],
                ),
                Panel::new(
                    "airspeed (m/s)",
                    vec![
                        Series::new("truth", t.clone(), col(&|s| s.airspeed)),
                        Series::new("estimate", t.clone(), col(&|s| s.est_airspeed)),
                        Series::new("setpoint", t.clone(), col(&|s| s.sp_airspeed)).dashed(),
                    ],
                ),
                Panel::new(
                    "elevator (deg), throttle (%)",
                    vec![
                        Series::new("elevator", t.clone(), col(&|s| s.elevator * DEG)),
                        Series::new("throttle", t.clone(), col(&|s| s.throttle * 100.0)),
                    ],
                ),
            ],
        ),
    )?);
    let wrap360 = |x: f64| (x * DEG).rem_euclid(360.0);
    files.push(fig(
        "course.png",
        Figure::new(
            "Course and heading",
            "t (s)",
            vec![
                Panel::new(
                    "course (deg)",
                    vec![
                        Series::new("truth", t.clone(), col(&|s| wrap360(s.course))),
                        Series::new("estimate", t.clone(), col(&|s| wrap360(s.est_course))),
                        Series::new("setpoint", t.clone(), col(&|s| wrap360(s.sp_course))).dashed(),
                    ],
                ),
                Panel::new(
                    "heading (deg)",
                    vec![
                        Series::new("truth", t.clone(), col(&|s| wrap360(s.yaw))),
                        Series::new("estimate", t.clone(), col(&|s| wrap360(s.est_yaw))),
                    ],
                ),
                Panel::new(
                    "aileron, rudder (deg)",
                    vec![
                        Series::new("aileron", t.clone(), col(&|s| s.aileron * DEG)),
                        Series::new("rudder", t.clone(), col(&|s| s.rudder * DEG)),
                    ],
                ),
            ],
        ),
    )?);
    files.push(fig(
        "attitude.png",
        Figure::new(
            "Attitude: truth and estimate",
            "t (s)",
            vec![
                Panel::new(
                    "roll (deg)",
                    vec![
                        Series::new("truth", t.clone(), col(&|s| s.roll * DEG)),
                        Series::new("estimate", t.clone(), col(&|s| s.est_roll * DEG)).dashed(),
                    ],
                ),
                Panel::new(
                    "pitch (deg)",
                    vec![
                        Series::new("truth", t.clone(), col(&|s| s.pitch * DEG)),
                        Series::new("estimate", t.clone(), col(&|s| s.est_pitch * DEG)).dashed(),
                    ],
                ),
                Panel::new(
                    "heading error (deg)",
                    vec![Series::new(
                        "estimate - truth",
                        t.clone(),
                        col(&|s| wrap_pi(s.est_yaw - s.yaw) * DEG),
                    )],
                ),
            ],
        ),
    )?);
    let known: Vec<&&Sample> = p
        .iter()
        .filter(|s| s.est_bat_remaining.is_finite())
        .collect();
    files.push(fig(
        "battery.png",
        Figure::new(
            "Battery: the simulated pack and the autopilot's estimate",
            "t (s)",
            vec![
                Panel::new(
                    "voltage (V)",
                    vec![Series::new("truth", t.clone(), col(&|s| s.bat_voltage))],
                ),
                Panel::new(
                    "current (A)",
                    vec![Series::new("truth", t.clone(), col(&|s| s.bat_current))],
                ),
                Panel::new(
                    "charge left (%)",
                    vec![
                        Series::new("truth", t.clone(), col(&|s| s.bat_soc * 100.0)),
                        // Only while the autopilot monitors a battery.
                        Series::new(
                            "estimate",
                            known.iter().map(|s| s.t).collect(),
                            known.iter().map(|s| s.est_bat_remaining * 100.0).collect(),
                        )
                        .dashed(),
                    ],
                ),
            ],
        ),
    )?);
    files.push(fig(
        "ground_track.png",
        ground_track_figure(samples, "Ground track"),
    )?);
    Ok(files)
}
