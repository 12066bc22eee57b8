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
    let tmp = path.with_extension("partial.png");
    {
        let root = BitMapBackend::new(&tmp, (1000, 600)).into_drawing_area();
        root.fill(&WHITE)
            .map_err(|e| anyhow!("plot {}: {e}", path.display()))?;
        let pts = series.iter().flat_map(|s| s.points.iter());
        let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
        for &(x, y) in pts {
            if x.is_finite() && y.is_finite() && (scale == Scale::Linear || (x > 0.0 && y > 0.0)) {
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
            y1 = y0 + 1.0;
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
        }
        root.present()
            .map_err(|e| anyhow!("plot {}: {e}", path.display()))?;
    }
    std::fs::rename(&tmp, path)
        .map_err(|e| anyhow!("cannot move {} into place: {e}", path.display()))?;
    Ok(())
}
