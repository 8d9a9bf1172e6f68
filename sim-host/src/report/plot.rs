//! Time-series figures: several panels stacked vertically, several series per panel, drawn
//! with plotters' bitmap backend and the bundled DejaVu Sans font (no system fonts needed).

use anyhow::{anyhow, Context};
use plotters::prelude::*;
use plotters::style::{register_font, FontStyle};
use std::path::Path;
use std::sync::Once;

/// The family name the bundled font is registered under.
pub(crate) const FONT: &str = "sans-serif";
static FONT_BYTES: &[u8] = include_bytes!("../../assets/DejaVuSans.ttf");
static REGISTER: Once = Once::new();

/// Registers the bundled font once, before any text is drawn.
pub(crate) fn ensure_font() {
    REGISTER.call_once(|| {
        // The font is compiled in and known to be valid; a failure would only cost the labels.
        let _ = register_font(FONT, FontStyle::Normal, FONT_BYTES);
    });
}

/// One line: label and samples.
#[derive(Clone, Debug, Default)]
pub struct Series {
    /// Legend text.
    pub label: String,
    /// Abscissae (usually time, s).
    pub x: Vec<f64>,
    /// Ordinates.
    pub y: Vec<f64>,
    /// Draw dashed (e.g. for the reference or linear model).
    pub dashed: bool,
}

impl Series {
    /// A solid series.
    pub fn new(label: impl Into<String>, x: Vec<f64>, y: Vec<f64>) -> Self {
        Self {
            label: label.into(),
            x,
            y,
            dashed: false,
        }
    }

    /// The same series drawn dashed.
    pub fn dashed(mut self) -> Self {
        self.dashed = true;
        self
    }
}

/// One panel: shared x axis, its own y axis label (with units) and series.
#[derive(Clone, Debug, Default)]
pub struct Panel {
    /// Y-axis label, with units, e.g. `"q (deg/s)"`.
    pub y_label: String,
    /// Lines drawn in this panel.
    pub series: Vec<Series>,
}

impl Panel {
    /// A panel with a label and series.
    pub fn new(y_label: impl Into<String>, series: Vec<Series>) -> Self {
        Self {
            y_label: y_label.into(),
            series,
        }
    }
}

/// A figure of stacked panels.
#[derive(Clone, Debug)]
pub struct Figure {
    /// Caption at the top.
    pub title: String,
    /// X-axis label with units, e.g. `"time (s)"`.
    pub x_label: String,
    /// Panels from top to bottom.
    pub panels: Vec<Panel>,
    /// Width in pixels.
    pub width: u32,
    /// Height of one panel in pixels.
    pub panel_height: u32,
    /// One metre is as long on both axes (a map).
    pub equal_aspect: bool,
}

impl Figure {
    /// A figure with default size.
    pub fn new(title: impl Into<String>, x_label: impl Into<String>, panels: Vec<Panel>) -> Self {
        Self {
            title: title.into(),
            x_label: x_label.into(),
            panels,
            width: 1000,
            panel_height: 220,
            equal_aspect: false,
        }
    }

    /// A map: square, one unit as long on both axes (ground tracks).
    pub fn map(mut self) -> Self {
        self.equal_aspect = true;
        self.width = 900;
        self.panel_height = 860;
        self
    }

    /// Renders the figure to a PNG file.
    pub fn save_png(&self, path: &Path) -> anyhow::Result<()> {
        ensure_font();
        let n = self.panels.len().max(1);
        let height = 40 + self.panel_height * n as u32;
        let root = BitMapBackend::new(path, (self.width, height)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| anyhow!("{e}"))?;
        let root = root
            .titled(&self.title, (FONT, 22))
            .map_err(|e| anyhow!("{e}"))?;
        let areas = root.split_evenly((n, 1));
        let palette = [BLUE, RED, RGBColor(0, 140, 0), MAGENTA, CYAN, BLACK];
        for (pi, (panel, area)) in self.panels.iter().zip(areas.iter()).enumerate() {
            let (mut x0, mut x1) = range(panel.series.iter().flat_map(|s| s.x.iter().copied()));
            let (mut y0, mut y1) = range(panel.series.iter().flat_map(|s| s.y.iter().copied()));
            if self.equal_aspect {
                // The plotting area, less the label areas and margins.
                let w = f64::from(self.width.saturating_sub(96).max(1));
                let h = f64::from(self.panel_height.saturating_sub(56).max(1));
                let scale = ((x1 - x0) / w).max((y1 - y0) / h);
                let (cx, cy) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));
                (x0, x1) = (cx - 0.5 * scale * w, cx + 0.5 * scale * w);
                (y0, y1) = (cy - 0.5 * scale * h, cy + 0.5 * scale * h);
            }
            let mut chart = ChartBuilder::on(area)
                .margin(8)
                .x_label_area_size(if pi + 1 == n { 40 } else { 22 })
                .y_label_area_size(80)
                .build_cartesian_2d(x0..x1, y0..y1)
                .map_err(|e| anyhow!("{e}"))?;
            let mut mesh = chart.configure_mesh();
            mesh.y_desc(panel.y_label.as_str())
                .label_style((FONT, 13))
                .axis_desc_style((FONT, 15));
            if pi + 1 == n {
                mesh.x_desc(self.x_label.as_str());
            }
            mesh.draw().map_err(|e| anyhow!("{e}"))?;
            for (si, s) in panel.series.iter().enumerate() {
                let color = palette[si % palette.len()];
                let style = ShapeStyle::from(&color).stroke_width(2);
                // A missing value (NaN) breaks the line: drawn through, it would land at the
                // drawing area's edge and streak across the panels.
                for (ri, pts) in finite_runs(s).into_iter().enumerate() {
                    let drawn = if s.dashed {
                        chart.draw_series(DashedLineSeries::new(pts, 8, 5, style))
                    } else {
                        chart.draw_series(LineSeries::new(pts, style))
                    }
                    .map_err(|e| anyhow!("{e}"))?;
                    if ri == 0 {
                        drawn.label(s.label.as_str()).legend(move |(x, y)| {
                            PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2))
                        });
                    }
                }
            }
            chart
                .configure_series_labels()
                .background_style(WHITE.mix(0.8))
                .border_style(BLACK)
                .label_font((FONT, 13))
                .position(SeriesLabelPosition::UpperRight)
                .draw()
                .map_err(|e| anyhow!("{e}"))?;
        }
        root.present()
            .with_context(|| format!("cannot write PNG file `{}`", path.display()))?;
        Ok(())
    }
}

/// The series' points in runs of finite ones.
fn finite_runs(s: &Series) -> Vec<Vec<(f64, f64)>> {
    let mut runs: Vec<Vec<(f64, f64)>> = Vec::new();
    let mut run = Vec::new();
    for (x, y) in s.x.iter().copied().zip(s.y.iter().copied()) {
        if x.is_finite() && y.is_finite() {
            run.push((x, y));
        } else if !run.is_empty() {
            runs.push(std::mem::take(&mut run));
        }
    }
    if !run.is_empty() {
        runs.push(run);
    }
    runs
}

/// Data range padded by 5 % (and widened when flat) so every line is visible.
fn range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.filter(|v| v.is_finite()) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if !lo.is_finite() {
        return (0.0, 1.0);
    }
    let span = hi - lo;
    let pad = if span > 1e-12 * hi.abs().max(1.0) {
        0.05 * span
    } else {
        0.5 * hi.abs().max(1e-3)
    };
    (lo - pad, hi + pad)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn draws_a_png() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("f.png");
        let t: Vec<f64> = (0..50).map(|i| i as f64 * 0.1).collect();
        let y: Vec<f64> = t.iter().map(|x| x.sin()).collect();
        let fig = Figure::new(
            "test",
            "time (s)",
            vec![
                Panel::new(
                    "y (m)",
                    vec![
                        Series::new("a", t.clone(), y.clone()),
                        Series::new("b", t.clone(), y.iter().map(|v| v * 0.5).collect()).dashed(),
                    ],
                ),
                Panel::new(
                    "flat (deg)",
                    vec![Series::new("c", t.clone(), vec![1.0; 50])],
                ),
            ],
        );
        fig.save_png(&path).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        assert_eq!(&bytes[1..4], b"PNG");
        assert!(bytes.len() > 5000);
    }

    #[test]
    fn a_missing_value_breaks_a_line_in_two() {
        let s = Series::new(
            "a",
            vec![0.0, 1.0, 2.0, 3.0, 4.0, f64::NAN],
            vec![1.0, f64::NAN, 2.0, 3.0, f64::INFINITY, 5.0],
        );
        assert_eq!(
            finite_runs(&s),
            vec![vec![(0.0, 1.0)], vec![(2.0, 2.0), (3.0, 3.0)]]
        );
    }
}
