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

/// A tick label: at most four significant decimals, trailing zeros dropped, exponent form
/// outside 1e-3..1e5.
pub fn tick(v: f64) -> String {
    let a = v.abs();
    if a == 0.0 || !v.is_finite() {
        return "0".into();
    }
    if !(1e-3..1e5).contains(&a) {
        return format!("{v:.1e}");
    }
    let decimals = (3 - a.log10().floor() as i32).clamp(0, 6) as usize;
    let s = format!("{v:.decimals$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// Tick values for a log axis over `lo..hi` (both > 0): 1, 2 and 5 times each power of ten
/// inside; every integer multiple when that gives fewer than four.
fn log_ticks(lo: f64, hi: f64) -> Vec<f64> {
    let pick = |mult: &[f64]| -> Vec<f64> {
        let (k0, k1) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
        (k0..=k1)
            .flat_map(|k| mult.iter().map(move |m| m * 10f64.powi(k)))
            .filter(|v| *v >= lo * (1.0 - 1e-9) && *v <= hi * (1.0 + 1e-9))
            .collect()
    };
    let t = pick(&[1.0, 2.0, 5.0]);
    if t.len() >= 4 {
        t
    } else {
        pick(&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0])
    }
}

/// The plot's palette (matplotlib's first six), one colour per series in turn.
const COLORS: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(255, 127, 14),
    RGBColor(23, 190, 207),
];

/// The data's ranges (x0, x1, y0, y1) over the points `shown` accepts, widened to a unit span
/// (a decade on a log axis) where the data have none.
fn data_ranges(
    series: &[Series],
    scale: Scale,
    shown: &dyn Fn(&(f64, f64)) -> bool,
) -> (f64, f64, f64, f64) {
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for &(x, y) in series
        .iter()
        .flat_map(|s| s.points.iter())
        .filter(|p| shown(p))
    {
        x0 = x0.min(x);
        x1 = x1.max(x);
        y0 = y0.min(y);
        y1 = y1.max(y);
    }
    if x0 > x1 {
        (x0, x1, y0, y1) = (0.0, 1.0, 0.0, 1.0);
        if matches!(scale, Scale::LogLog | Scale::LogX) {
            (x0, x1) = (1.0, 10.0);
        }
        if matches!(scale, Scale::LogLog | Scale::LogY) {
            (y0, y1) = (1.0, 10.0);
        }
    }
    if x1 - x0 <= 0.0 {
        x1 = if matches!(scale, Scale::LogLog | Scale::LogX) {
            x0 * 10.0
        } else {
            x0 + 1.0
        };
    }
    if y1 - y0 <= 0.0 {
        y1 = if matches!(scale, Scale::LogLog | Scale::LogY) {
            y0 * 10.0
        } else {
            y0 + 1.0
        };
    }
    // a log y axis gets the margin a linear one gets from its pad: curves clear of the frame
    if matches!(scale, Scale::LogLog | Scale::LogY) {
        let r = (y1 / y0).powf(0.04);
        (y0, y1) = (y0 / r, y1 * r);
    }
    (x0, x1, y0, y1)
}

/// Draws the legend of `series` into `area` (a strip beside the axes), one line and label each.
fn draw_legend(
    area: &DrawingArea<BitMapBackend, plotters::coord::Shift>,
    series: &[Series],
) -> Result<()> {
    for (k, s) in series.iter().enumerate() {
        let c = COLORS[k % COLORS.len()];
        let y = 70 + 26 * k as i32;
        area.draw(&PathElement::new(vec![(6, y), (32, y)], c.stroke_width(3)))
            .map_err(|e| anyhow!("legend: {e}"))?;
        area.draw(&Text::new(
            s.label.clone(),
            (38, y - 9),
            ("sans-serif", 15).into_font().color(&BLACK),
        ))
        .map_err(|e| anyhow!("legend: {e}"))?;
    }
    Ok(())
}

/// Draws `series` into a 1000×600 PNG at `path`: the legend in a strip right of the axes (it
/// never covers data), points the scale cannot show (non-finite, ≤ 0 on a log axis) breaking
/// the line, ticks labelled by [`tick`]. An x axis of large values over a short span (absolute
/// GPS times) is drawn from its whole-number start, which the axis label then names.
pub fn line_plot(
    path: &Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[Series],
    scale: Scale,
) -> Result<()> {
    register_font();
    let err = |e: &dyn std::fmt::Display| anyhow!("plot {}: {e}", path.display());
    let shown = |&(x, y): &(f64, f64)| {
        x.is_finite()
            && y.is_finite()
            && match scale {
                Scale::Linear => true,
                Scale::LogLog => x > 0.0 && y > 0.0,
                Scale::LogX => x > 0.0,
                Scale::LogY => y > 0.0,
            }
    };
    let (x0, x1, y0, y1) = data_ranges(series, scale, &shown);
    // absolute times (GPS seconds) over a short span: counted from their whole-second start
    let x_off = if matches!(scale, Scale::Linear | Scale::LogY)
        && x0.abs() >= 1e5
        && x0.abs() > 100.0 * (x1 - x0)
    {
        x0.floor()
    } else {
        0.0
    };
    let x_desc = if x_off != 0.0 {
        format!("{x_label}, from {x_off:.0}")
    } else {
        x_label.to_string()
    };
    let (x0, x1) = (x0 - x_off, x1 - x_off);
    let labelled = series.iter().any(|s| !s.label.is_empty());
    let legend_w: u32 = if labelled {
        let chars = series
            .iter()
            .map(|s| s.label.chars().count())
            .max()
            .unwrap_or(0);
        (44 + 9 * chars as u32).clamp(120, 330)
    } else {
        0
    };
    let tmp = crate::io::atomic_file::temporary_beside(path, ".png")?;
    {
        let root = BitMapBackend::new(&tmp, (1000, 600)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| err(&e))?;
        let (area, legend) = root.split_horizontally(1000 - legend_w);
        let mut builder = ChartBuilder::on(&area);
        builder
            .caption(title, ("sans-serif", 22))
            .margin(15)
            .margin_right(30)
            .x_label_area_size(50)
            .y_label_area_size(85);
        // a tick a rounding residue away from 0 (-2.2e-16) reads 0
        let snap = |v: f64, span: f64| if v.abs() < 1e-9 * span { 0.0 } else { v };
        let x_fmt = |v: &f64| tick(snap(*v, x1 - x0));
        let y_fmt = |v: &f64| tick(snap(*v, y1 - y0));
        macro_rules! draw {
            ($chart:expr) => {{
                let mut chart = $chart;
                chart
                    .configure_mesh()
                    .x_desc(x_desc.as_str())
                    .y_desc(y_label)
                    .x_labels(9)
                    .y_labels(9)
                    .x_label_formatter(&x_fmt)
                    .y_label_formatter(&y_fmt)
                    .label_style(("sans-serif", 15))
                    .draw()
                    .map_err(|e| err(&e))?;
                for (k, s) in series.iter().enumerate() {
                    let c = COLORS[k % COLORS.len()];
                    // earlier series wider, so one a later series overlaps still shows
                    let width = if k == 0 && series.len() > 1 { 3 } else { 2 };
                    // each run of points the scale can show is one line
                    let mut run: Vec<(f64, f64)> = Vec::new();
                    let mut runs: Vec<Vec<(f64, f64)>> = Vec::new();
                    for p in &s.points {
                        if shown(p) {
                            run.push((p.0 - x_off, p.1));
                        } else if !run.is_empty() {
                            runs.push(std::mem::take(&mut run));
                        }
                    }
                    runs.push(run);
                    // segment by segment: a wide polyline's mitred joins at the sharp turns
                    // of a dense envelope would spike far outside the axes
                    for r in runs.into_iter().filter(|r| !r.is_empty()) {
                        if r.len() == 1 {
                            chart
                                .draw_series(std::iter::once(Circle::new(r[0], 2, c.filled())))
                                .map_err(|e| err(&e))?;
                            continue;
                        }
                        chart
                            .draw_series(
                                r.windows(2).map(|w| {
                                    PathElement::new(vec![w[0], w[1]], c.stroke_width(width))
                                }),
                            )
                            .map_err(|e| err(&e))?;
                    }
                }
            }};
        }
        let ypad = |lo: f64, hi: f64| 0.05 * (hi - lo);
        match scale {
            Scale::Linear => {
                let pad = ypad(y0, y1);
                draw!(builder
                    .build_cartesian_2d(x0..x1, (y0 - pad)..(y1 + pad))
                    .map_err(|e| err(&e))?)
            }
            Scale::LogLog => draw!(builder
                .build_cartesian_2d(
                    (x0..x1).log_scale().with_key_points(log_ticks(x0, x1)),
                    (y0..y1).log_scale().with_key_points(log_ticks(y0, y1))
                )
                .map_err(|e| err(&e))?),
            Scale::LogX => {
                let pad = ypad(y0, y1);
                draw!(builder
                    .build_cartesian_2d(
                        (x0..x1).log_scale().with_key_points(log_ticks(x0, x1)),
                        (y0 - pad)..(y1 + pad)
                    )
                    .map_err(|e| err(&e))?)
            }
            Scale::LogY => draw!(builder
                .build_cartesian_2d(
                    x0..x1,
                    (y0..y1).log_scale().with_key_points(log_ticks(y0, y1))
                )
                .map_err(|e| err(&e))?),
        }
        if labelled {
            draw_legend(&legend, series).map_err(|e| err(&e))?;
        }
        root.present().map_err(|e| err(&e))?;
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
    let tmp = crate::io::atomic_file::temporary_beside(path, ".png")?;
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
        // room for the longest label (about 8 px a character at 14 px)
        let label_w = (20 + 8 * labels.iter().map(|l| l.chars().count()).max().unwrap_or(0) as u32)
            .clamp(120, 450);
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 22))
            .margin(15)
            .margin_right(30)
            .x_label_area_size(50)
            .y_label_area_size(label_w)
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
            .x_label_formatter(&|v| tick(*v))
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
                .background_style(WHITE.mix(0.0))
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
    atomic_file::forget_temporary(tmp);
    let bytes = bytes.map_err(|e| anyhow!("plot {}: {e}", path.display()))?;
    let marked = atomic_file::png_with_text(&bytes, "Software", atomic_file::PNG_SOFTWARE)
        .ok_or_else(|| anyhow!("plot {}: the drawing is no PNG", path.display()))?;
    let mut f = atomic_file::AtomicFile::create(path)?;
    std::io::Write::write_all(f.writer(), &marked)?;
    f.commit()
}
