//! The report's pictures: a histogram of every figure, the touchdowns in the approach's
//! frame, and the verdict's margin against the quantities that matter most. Drawn from the
//! records alone, deterministically (same records, same bytes).

use super::record::FlightRecord;
use super::report::{Report, FIGURES};
use super::stats::quantile;
use super::verdict::TOUCHDOWN_M;
use crate::report::plot::{ensure_font, FONT};
use anyhow::{anyhow, Context};
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use std::path::Path;

const PASS: RGBColor = RGBColor(30, 90, 200);
const FAIL: RGBColor = RGBColor(220, 30, 30);

fn e<E: std::fmt::Display>(x: E) -> anyhow::Error {
    anyhow!("{x}")
}

/// Range of values padded by 5 % (widened when flat).
fn span(v: impl Iterator<Item = f64>) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for x in v.filter(|x| x.is_finite()) {
        lo = lo.min(x);
        hi = hi.max(x);
    }
    if !lo.is_finite() {
        return (0.0, 1.0);
    }
    let pad = if hi > lo {
        0.05 * (hi - lo)
    } else {
        0.5 * hi.abs().max(1.0)
    };
    (lo - pad, hi + pad)
}

/// Points `(x, y, passed)`, the failing flights in red, the passing ones last, on top: they
/// are the fewer when a campaign goes badly.
fn dots<DB: DrawingBackend>(
    chart: &mut ChartContext<'_, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
    pts: &[(f64, f64, bool)],
    radius: i32,
) -> anyhow::Result<()> {
    for ok in [false, true] {
        let color = if ok { PASS } else { FAIL };
        chart
            .draw_series(
                pts.iter()
                    .filter(|p| p.2 == ok)
                    .map(|p| Circle::new((p.0, p.1), radius, color.filled())),
            )
            .map_err(e)?;
    }
    Ok(())
}

/// A grid of histograms, one per figure of [`FIGURES`], failing flights stacked in red.
pub fn histograms(records: &[FlightRecord], path: &Path) -> anyhow::Result<()> {
    ensure_font();
    let cols = 4;
    let rows = FIGURES.len().div_ceil(cols);
    let root = BitMapBackend::new(path, (1600, 300 * rows as u32 + 40)).into_drawing_area();
    root.fill(&WHITE).map_err(e)?;
    let root = root
        .titled(
            &format!(
                "{} flights: figures (failing flights in red)",
                records.len()
            ),
            (FONT, 22),
        )
        .map_err(e)?;
    for ((_, label, get), area) in FIGURES.iter().zip(root.split_evenly((rows, cols)).iter()) {
        let vals: Vec<(f64, bool)> = records
            .iter()
            .filter_map(|r| get(&r.figures).map(|v| (v, r.verdict.pass)))
            .collect();
        // The bins span the 1 % to 99 % quantiles: a few wild flights (a touchdown a
        // kilometre away) would otherwise crush everyone else into one bin. What lies
        // beyond is counted in the end bins.
        let mut sorted: Vec<f64> = vals.iter().map(|v| v.0).collect();
        sorted.sort_by(f64::total_cmp);
        let (lo, hi) = span([quantile(&sorted, 0.01), quantile(&sorted, 0.99)].into_iter());
        let bins = 30;
        let width = (hi - lo) / bins as f64;
        let mut pass = vec![0u32; bins];
        let mut fail = vec![0u32; bins];
        for (v, ok) in &vals {
            let b = (((v - lo) / width).max(0.0) as usize).min(bins - 1);
            if *ok {
                pass[b] += 1;
            } else {
                fail[b] += 1;
            }
        }
        let top = (0..bins)
            .map(|b| pass[b] + fail[b])
            .max()
            .unwrap_or(1)
            .max(1);
        let mut chart = ChartBuilder::on(area)
            .margin(8)
            .caption(*label, (FONT, 15))
            .x_label_area_size(28)
            .y_label_area_size(44)
            .build_cartesian_2d(lo..hi, 0u32..top + top / 10 + 1)
            .map_err(e)?;
        chart
            .configure_mesh()
            .label_style((FONT, 11))
            .x_labels(5)
            .y_labels(4)
            .draw()
            .map_err(e)?;
        let x = |b: usize| lo + width * b as f64;
        chart
            .draw_series(
                (0..bins).map(|b| {
                    Rectangle::new([(x(b), 0), (x(b + 1), pass[b])], PASS.mix(0.7).filled())
                }),
            )
            .map_err(e)?;
        chart
            .draw_series((0..bins).filter(|&b| fail[b] > 0).map(|b| {
                Rectangle::new(
                    [(x(b), pass[b]), (x(b + 1), pass[b] + fail[b])],
                    FAIL.filled(),
                )
            }))
            .map_err(e)?;
    }
    root.present()
        .with_context(|| format!("cannot write PNG file `{}`", path.display()))
}

/// Touchdowns along and across the approach, with the criterion's circle.
pub fn touchdowns(records: &[FlightRecord], path: &Path) -> anyhow::Result<()> {
    ensure_font();
    let pts: Vec<(f64, f64, bool)> = records
        .iter()
        .filter_map(|r| {
            let f = &r.figures;
            Some((f.touchdown_along_m?, f.touchdown_cross_m?, r.verdict.pass))
        })
        .collect();
    // Four times the criterion's radius around the point, equal scales on both axes (a
    // circle stays a circle); the touchdowns beyond are counted in the caption.
    let half = 4.0 * TOUCHDOWN_M;
    let (am, cm) = (0.0, 0.0);
    let outside = pts
        .iter()
        .filter(|p| p.0.abs() > half || p.1.abs() > half)
        .count();
    let root = BitMapBackend::new(path, (900, 900)).into_drawing_area();
    root.fill(&WHITE).map_err(e)?;
    let mut chart = ChartBuilder::on(&root)
        .margin(12)
        .caption(
            format!(
                "{} touchdowns, {outside} beyond this view (failing flights in red)",
                pts.len()
            ),
            (FONT, 20),
        )
        .x_label_area_size(40)
        .y_label_area_size(56)
        .build_cartesian_2d(cm - half..cm + half, am - half..am + half)
        .map_err(e)?;
    chart
        .configure_mesh()
        .x_desc("across the approach, right + (m)")
        .y_desc("along the approach, past the point + (m)")
        .label_style((FONT, 13))
        .axis_desc_style((FONT, 15))
        .draw()
        .map_err(e)?;
    let circle: Vec<(f64, f64)> = (0..=180)
        .map(|k| {
            let t = k as f64 / 180.0 * std::f64::consts::TAU;
            (TOUCHDOWN_M * t.cos(), TOUCHDOWN_M * t.sin())
        })
        .collect();
    chart
        .draw_series(LineSeries::new(circle, BLACK.stroke_width(1)))
        .map_err(e)?;
    let shown: Vec<(f64, f64, bool)> = pts
        .iter()
        .filter(|p| p.0.abs() <= half && p.1.abs() <= half)
        .map(|p| (p.1, p.0, p.2))
        .collect();
    dots(&mut chart, &shown, 3)?;
    root.present()
        .with_context(|| format!("cannot write PNG file `{}`", path.display()))
}

/// The verdict's margin against the six quantities most strongly related to it.
pub fn sensitivity(report: &Report, records: &[FlightRecord], path: &Path) -> anyhow::Result<()> {
    ensure_font();
    let top: Vec<&str> = report
        .sensitivity
        .iter()
        .take(6)
        .map(|s| s.quantity.as_str())
        .collect();
    let root = BitMapBackend::new(path, (1500, 840)).into_drawing_area();
    root.fill(&WHITE).map_err(e)?;
    let root = root
        .titled(
            "verdict margin against the quantities that matter most (failing flights in red)",
            (FONT, 20),
        )
        .map_err(e)?;
    for (q, area) in top.iter().zip(root.split_evenly((2, 3)).iter()) {
        let pts: Vec<(f64, f64, bool)> = records
            .iter()
            .filter_map(|r| Some((r.draws.get(q)?, r.verdict.margin, r.verdict.pass)))
            .collect();
        let (x0, x1) = span(pts.iter().map(|p| p.0));
        let (y0, y1) = span(pts.iter().map(|p| p.1.max(-1.0)));
        let mut chart = ChartBuilder::on(area)
            .margin(10)
            .caption(*q, (FONT, 15))
            .x_label_area_size(28)
            .y_label_area_size(44)
            .build_cartesian_2d(x0..x1, y0..y1)
            .map_err(e)?;
        chart
            .configure_mesh()
            .label_style((FONT, 11))
            .x_labels(5)
            .y_labels(5)
            .draw()
            .map_err(e)?;
        let clipped: Vec<(f64, f64, bool)> =
            pts.iter().map(|p| (p.0, p.1.max(-1.0), p.2)).collect();
        dots(&mut chart, &clipped, 2)?;
    }
    root.present()
        .with_context(|| format!("cannot write PNG file `{}`", path.display()))
}
