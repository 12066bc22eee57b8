//! IMU increments in memory and the project's text format (DESIGN §9, KF-GINS compatible):
//! `t [s]  dtheta_x dtheta_y dtheta_z [rad]  dv_x dv_y dv_z [m/s]`, increments over (t_prev, t],
//! FRD body frame, whitespace or comma separated, `#` comment lines.

use crate::io::atomic_file::AtomicFile;
use anyhow::{bail, Context, Result};
use nalgebra::Vector3;
use std::io::Write;
use std::path::Path;

/// One IMU sample: increments over (t_prev, t] in the FRD body frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImuSample {
    /// End of the interval [s].
    pub t: f64,
    /// Angle increment ∫ω dt [rad].
    pub dtheta: Vector3<f64>,
    /// Velocity increment ∫f dt [m/s].
    pub dv: Vector3<f64>,
}

/// A sequence of IMU samples with strictly increasing time.
#[derive(Debug, Clone, Default)]
pub struct ImuData {
    /// The samples.
    pub samples: Vec<ImuSample>,
}

impl ImuData {
    /// Median sample interval [s] (0 with fewer than two samples).
    pub fn interval(&self) -> f64 {
        let mut d: Vec<f64> = self.samples.windows(2).map(|w| w[1].t - w[0].t).collect();
        if d.is_empty() {
            return 0.0;
        }
        d.sort_by(f64::total_cmp);
        d[d.len() / 2]
    }

    /// RMS deviation of the sample intervals from their median [s] (0 on a uniform clock).
    pub fn jitter_rms(&self) -> f64 {
        let median = self.interval();
        let n = self.samples.len().saturating_sub(1);
        if n == 0 {
            return 0.0;
        }
        let ss: f64 = self
            .samples
            .windows(2)
            .map(|w| (w[1].t - w[0].t - median).powi(2))
            .sum();
        (ss / n as f64).sqrt()
    }

    /// Sample rate [Hz] from the median interval.
    pub fn rate_hz(&self) -> f64 {
        1.0 / self.interval()
    }

    /// Duration from the first to the last sample time [s].
    pub fn duration(&self) -> f64 {
        match (self.samples.first(), self.samples.last()) {
            (Some(a), Some(b)) => b.t - a.t,
            _ => 0.0,
        }
    }

    /// Mean specific force and angular rate over all samples (Σ increments / Σ intervals).
    pub fn mean_rates(&self) -> (Vector3<f64>, Vector3<f64>) {
        let dt = self.interval();
        let n = self.samples.len() as f64;
        let f = self.samples.iter().map(|s| s.dv).sum::<Vector3<f64>>() / (n * dt);
        let w = self.samples.iter().map(|s| s.dtheta).sum::<Vector3<f64>>() / (n * dt);
        (f, w)
    }

    /// Checks time order and gaps; `what` names the source in messages.
    pub fn check_time(&self, what: &str, max_gap_intervals: f64) -> Result<()> {
        let dt = self.interval();
        for (k, w) in self.samples.windows(2).enumerate() {
            let d = w[1].t - w[0].t;
            if d <= 0.0 {
                bail!(
                    "{what}: sample {}: time does not increase ({} after {})",
                    k + 2,
                    w[1].t,
                    w[0].t
                );
            }
            if d > max_gap_intervals * dt {
                bail!("{what}: sample {}: gap of {d:.4} s (more than {max_gap_intervals} intervals of {dt:.4} s)", k + 2);
            }
        }
        Ok(())
    }
}

/// Splits a data line on whitespace and commas and parses `n` finite numbers.
pub fn parse_numbers(line: &str, n: usize, file: &Path, lineno: usize) -> Result<Vec<f64>> {
    let fields: Vec<&str> = line
        .split(|c: char| c.is_whitespace() || c == ',')
        .filter(|s| !s.is_empty())
        .collect();
    if fields.len() != n {
        bail!(
            "{}:{lineno}: expected {n} columns, found {}",
            file.display(),
            fields.len()
        );
    }
    fields
        .iter()
        .enumerate()
        .map(|(k, f)| {
            let v: f64 = f.parse().map_err(|_| {
                anyhow::anyhow!(
                    "{}:{lineno}: column {}: `{f}` is not a number",
                    file.display(),
                    k + 1
                )
            })?;
            if !v.is_finite() {
                bail!(
                    "{}:{lineno}: column {}: `{f}` is not finite",
                    file.display(),
                    k + 1
                );
            }
            Ok(v)
        })
        .collect()
}

/// Reads a whitespace/comma separated numeric table with `ncols` columns whose first column is a
/// strictly increasing time; `#` comment and blank lines are skipped. Returns (line, values) rows;
/// every problem names the file and line. `what` names the kind of file in messages.
pub fn read_table(path: &Path, ncols: usize, what: &str) -> Result<Vec<(usize, Vec<f64>)>> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("cannot read {what} {}", path.display()))?;
    let mut rows: Vec<(usize, Vec<f64>)> = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let l = line.trim();
        if l.is_empty() || l.starts_with('#') {
            continue;
        }
        let v = parse_numbers(l, ncols, path, i + 1)?;
        if let Some((_, prev)) = rows.last() {
            if v[0] <= prev[0] {
                bail!(
                    "{}:{}: time {} does not increase (previous {})",
                    path.display(),
                    i + 1,
                    v[0],
                    prev[0]
                );
            }
        }
        rows.push((i + 1, v));
    }
    Ok(rows)
}

/// Reads the text IMU format; any malformed row, NaN, non-increasing time or gap longer than 5
/// intervals is an error naming the file and line.
pub fn read_text(path: &Path) -> Result<ImuData> {
    let rows = read_table(path, 7, "IMU file")?;
    let lines_of: Vec<usize> = rows.iter().map(|r| r.0).collect();
    let samples: Vec<ImuSample> = rows
        .iter()
        .map(|(_, v)| ImuSample {
            t: v[0],
            dtheta: Vector3::new(v[1], v[2], v[3]),
            dv: Vector3::new(v[4], v[5], v[6]),
        })
        .collect();
    if samples.len() < 2 {
        bail!("{}: fewer than two IMU samples", path.display());
    }
    let data = ImuData { samples };
    let dt = data.interval();
    for (k, w) in data.samples.windows(2).enumerate() {
        if w[1].t - w[0].t > 5.0 * dt {
            bail!(
                "{}:{}: gap of {:.4} s after t = {} (more than 5 sample intervals of {dt:.4} s)",
                path.display(),
                lines_of[k + 1],
                w[1].t - w[0].t,
                w[0].t
            );
        }
    }
    Ok(data)
}

/// Writes the text IMU format atomically (shortest round-trip decimal for every number).
pub fn write_text(path: &Path, data: &ImuData, header: &str) -> Result<()> {
    let mut f = AtomicFile::create(path)?;
    let w = f.writer();
    for line in header.lines() {
        writeln!(w, "# {line}")?;
    }
    writeln!(w, "# t[s] dtheta_x dtheta_y dtheta_z [rad] dv_x dv_y dv_z [m/s], FRD body, increments over (t_prev, t]")?;
    for s in &data.samples {
        writeln!(
            w,
            "{} {} {} {} {} {} {}",
            s.t, s.dtheta.x, s.dtheta.y, s.dtheta.z, s.dv.x, s.dv.y, s.dv.z
        )?;
    }
    f.commit()
}
