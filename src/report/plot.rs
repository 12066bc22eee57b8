//! PNG line plots (plotters, bitmap backend, the DejaVu Sans font embedded by the `dejavu` crate,
//! so nothing links to system font libraries). Files appear atomically.

use anyhow::{anyhow, Result};
use plotters::prelude::*;
use std::path::Path;
use std::sync::Once;

static FONT: Once = Once::new();

fn register_font() {
    FONT.call_once(|| {
        let _ = plotters::style::register_font(
            "sans-serif",
            FontStyle::Normal,
            dejavu::sans::regular(),
        );
    });
}

/// One curve: label and (x, y) points.
pub struct Series {
    /// Legend label.
    pub label: String,
    /// Points.
    pub points: Vec<(f64, f64)>,
}

/// Axis scaling.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Scale {
    /// Linear axes.
    Linear,
    /// Log-log axes (positive data only).
    LogLog,
    /// Logarithmic x, linear y (positive x only).
    LogX,
    /// Linear x, logarithmic y (positive y only).
    LogY,
}

/// Draws `series` into a 1000×600 PNG at `path`.
pub fn line_plot(
    path: &Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[Series],
    scale: Scale,
) -> Result<()> {
    register_font();
    let tmp = crate::io::atomic_file::temporary_beside(path, ".png");
    {
        let root = BitMapBackend::new(&tmp, (1000, 600)).into_drawing_area();
        root.fill(&WHITE)
            .map_err(|e| anyhow!("plot {}: {e}", path.display()))?;
        let pts = series.iter().flat_map(|s| s.points.iter());
        let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
        for &(x, y) in pts {
            let ok = match scale {
                Scale::Linear => true,
                Scale::LogLog => x > 0.0 && y > 0.0,
                Scale::LogX => x > 0.0,
                Scale::LogY => y > 0.0,
            };
            if x.is_finite() && y.is_finite() && ok {
                x0 = x0.min(x);
                x1 = x1.max(x);
                y0 = y0.min(y);
                y1 = y1.max(y);
            }
        }
        if x0 > x1 {
            (x0, x1, y0, y1) = (0.0, 1.0, 0.0, 1.0);
        }
        if y1 - y0 <= 0.0 {
            y1 = if scale == Scale::LogY || scale == Scale::LogLog {
                y0 * 10.0
            } else {
                y0 + 1.0
            };
        }
        let colors = [
            RGBColor(31, 119, 180),
            RGBColor(214, 39, 40),
            RGBColor(44, 160, 44),
            RGBColor(148, 103, 189),
            RGBColor(255, 127, 14),
            RGBColor(23, 190, 207),
        ];
        let mut builder = ChartBuilder::on(&root);
        builder
            .caption(title, ("sans-serif", 24))
            .margin(15)
            .x_label_area_size(45)
            .y_label_area_size(80);
        macro_rules! draw {
            ($chart:expr) => {{
                let mut chart = $chart;
                chart
                    .configure_mesh()
                    .x_desc(x_label)
                    .y_desc(y_label)
                    .label_style(("sans-serif", 15))
                    .draw()
                    .map_err(|e| anyhow!("plot {}: {e}", path.display()))?;
                for (k, s) in series.iter().enumerate() {
                    let c = colors[k % colors.len()];
                    chart
                        .draw_series(LineSeries::new(
                            s.points
                                .iter()
                                .copied()
                                .filter(|p| p.0.is_finite() && p.1.is_finite()),
                            c.stroke_width(2),
                        ))
                        .map_err(|e| anyhow!("plot {}: {e}", path.display()))?
                        .label(s.label.clone())
                        .legend(move |(x, y)| {
                            PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(2))
                        });
                }
                chart
                    .configure_series_labels()
                    .background_style(WHITE.mix(0.8))
                    .border_style(BLACK)
                    .label_font(("sans-serif", 15))
                    .draw()
                    .map_err(|e| anyhow!("plot {}: {e}", path.display()))?;
            }};
        }
        match scale {
            Scale::Linear => {
                let pad = 0.05 * (y1 - y0);
                draw!(builder
                    .build_cartesian_2d(x0..x1, (y0 - pad)..(y1 + pad))
                    .map_err(|e| anyhow!("plot {}: {e}", path.display()))?)
            }
            Scale::LogLog => draw!(builder
                .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())
                .map_err(|e| anyhow!("plot {}: {e}", path.display()))?),
            Scale::LogX => {
                let pad = 0.05 * (y1 - y0);
                draw!(builder
                    .build_cartesian_2d((x0..x1).log_scale(), (y0 - pad)..(y1 + pad))
                    .map_err(|e| anyhow!("plot {}: {e}", path.display()))?)
            }
            Scale::LogY => draw!(builder
                .build_cartesian_2d(x0..x1, (y0..y1).log_scale())
                .map_err(|e| anyhow!("plot {}: {e}", path.display()))?),
        }
        root.present()
            .map_err(|e| anyhow!("plot {}: {e}", path.display()))?;
    }
    finish(&tmp, path)
}

/// One bar: label, value and an optional ± error.
pub struct Bar {
    /// Category label (x axis).
    pub label: String,
    /// Height.
    pub value: f64,
    /// Half-length of the error bar, if any.
    pub err: Option<f64>,
}

/// Draws a horizontal bar chart (one row per bar, first at the top) into a 1000×600 PNG at
/// `path`, with an optional vertical threshold line.
pub fn bar_plot(
    path: &Path,
    title: &str,
    value_label: &str,
    bars: &[Bar],
    threshold: Option<(f64, &str)>,
) -> Result<()> {
    register_font();
    let tmp = crate::io::atomic_file::temporary_beside(path, ".png");
    {
        let err = |e: &dyn std::fmt::Display| anyhow!("plot {}: {e}", path.display());
        let root = BitMapBackend::new(&tmp, (1000, 600)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| err(&e))?;
        let mut lo: f64 = 0.0;
        let mut hi: f64 = threshold.map(|t| t.0).unwrap_or(0.0);
        for b in bars.iter().filter(|b| b.value.is_finite()) {
            let e = b.err.filter(|e| e.is_finite()).unwrap_or(0.0);
            lo = lo.min(b.value - e);
            hi = hi.max(b.value + e);
        }
        if hi - lo <= 0.0 {
            hi = lo + 1.0;
        }
        let pad = 0.05 * (hi - lo);
        let n = bars.len().max(1);
        // row k is drawn at y = n - 1 - k so the first bar is on top
        let row = |k: usize| (n - 1 - k) as f64;
        let labels: Vec<String> = bars.iter().map(|b| b.label.clone()).collect();
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 24))
            .margin(15)
            .x_label_area_size(45)
            .y_label_area_size(170)
            .build_cartesian_2d((lo - pad)..(hi + pad), -0.5..(n as f64 - 0.5))
            .map_err(|e| err(&e))?;
        chart
            .configure_mesh()
            .disable_y_mesh()
            .y_labels(n)
            .y_label_formatter(&|y| {
                let k = y.round();
                if (y - k).abs() < 1e-6 && k >= 0.0 && (k as usize) < n {
                    labels.get(n - 1 - k as usize).cloned().unwrap_or_default()
                } else {
                    String::new()
                }
            })
            .x_desc(value_label)
            .label_style(("sans-serif", 14))
            .draw()
            .map_err(|e| err(&e))?;
        let blue = RGBColor(31, 119, 180);
        chart
            .draw_series(
                bars.iter()
                    .enumerate()
                    .filter(|(_, b)| b.value.is_finite())
                    .map(|(k, b)| {
                        let y = row(k);
                        Rectangle::new([(0.0, y - 0.35), (b.value, y + 0.35)], blue.filled())
                    }),
            )
            .map_err(|e| err(&e))?;
        for (k, b) in bars.iter().enumerate() {
            if let Some(e) = b.err.filter(|e| e.is_finite() && b.value.is_finite()) {
                let y = row(k);
                chart
                    .draw_series(std::iter::once(PathElement::new(
                        vec![(b.value - e, y), (b.value + e, y)],
                        BLACK.stroke_width(2),
                    )))
                    .map_err(|e| err(&e))?;
            }
        }
        if let Some((t, label)) = threshold {
            let red = RGBColor(214, 39, 40);
            chart
                .draw_series(std::iter::once(PathElement::new(
                    vec![(t, -0.5), (t, n as f64 - 0.5)],
                    red.stroke_width(2),
                )))
                .map_err(|e| err(&e))?
                .label(label.to_string())
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], red.stroke_width(2))
                });
            chart
                .configure_series_labels()
                .position(SeriesLabelPosition::LowerRight)
                .background_style(WHITE.mix(0.8))
                .border_style(BLACK)
                .label_font(("sans-serif", 15))
                .draw()
                .map_err(|e| err(&e))?;
        }
        root.present().map_err(|e| err(&e))?;
    }
    finish(&tmp, path)
}

/// Moves the drawn temporary `tmp` to `path` (atomically), marked `Software: sinsmodel` so that
/// a later run can tell its own plot from a user's file.
fn finish(tmp: &Path, path: &Path) -> Result<()> {
    use crate::io::atomic_file;
    let bytes = std::fs::read(tmp);
    let _ = std::fs::remove_file(tmp);
    atomic_file::forget_temporary(tmp);
    let bytes = bytes.map_err(|e| anyhow!("plot {}: {e}", path.display()))?;
    let marked = atomic_file::png_with_text(&bytes, "Software", atomic_file::PNG_SOFTWARE)
        .ok_or_else(|| anyhow!("plot {}: the drawing is no PNG", path.display()))?;
    let mut f = atomic_file::AtomicFile::create(path)?;
    std::io::Write::write_all(f.writer(), &marked)?;
    f.commit()
}
