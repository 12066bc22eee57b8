//! IMU increments in memory and the project's text format (DESIGN §9, KF-GINS compatible):
//! `t [s]  dtheta_x dtheta_y dtheta_z [rad]  dv_x dv_y dv_z [m/s]`, increments over (t_prev, t],
//! FRD body frame, whitespace or comma separated, `#` comment lines.

use crate::io::atomic_file::AtomicFile;
use crate::io::lines::{shown, Lines};
use anyhow::{bail, Result};
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

    /// Mean specific force [m/s²] and angular rate [rad/s] over all samples: Σ increments /
    /// Σ intervals, each sample over its own interval ([`mean_rates_of`]).
    pub fn mean_rates(&self) -> (Vector3<f64>, Vector3<f64>) {
        mean_rates_of(&self.samples, self.interval())
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

/// Mean specific force [m/s²] and angular rate [rad/s] of consecutive samples, each increment
/// over its own interval: the increments after the first, summed, over the time from the first
/// sample to the last (exact on a jittered clock, where dividing by a median interval is not);
/// a single sample is divided by `dt` [s].
pub fn mean_rates_of(samples: &[ImuSample], dt: f64) -> (Vector3<f64>, Vector3<f64>) {
    match samples {
        [] => (Vector3::zeros(), Vector3::zeros()),
        [one] => (one.dv / dt, one.dtheta / dt),
        [first, rest @ ..] => {
            let span = rest[rest.len() - 1].t - first.t;
            let f = rest.iter().map(|s| s.dv).sum::<Vector3<f64>>() / span;
            let w = rest.iter().map(|s| s.dtheta).sum::<Vector3<f64>>() / span;
            (f, w)
        }
    }
}

/// Splits a data line on whitespace and commas and parses `n` finite numbers into `out`
/// (cleared first).
pub fn parse_numbers_into(
    line: &str,
    n: usize,
    file: &str,
    lineno: usize,
    out: &mut Vec<f64>,
) -> Result<()> {
    out.clear();
    let mut count = 0usize;
    let mut field = |f: &[u8]| -> Result<()> {
        count += 1;
        if count > n {
            return Ok(());
        }
        // the correctly rounded value, as str::parse gives it (fast-float2 is the algorithm the
        // standard library adopted, without its per-call checks)
        let text = || shown(&String::from_utf8_lossy(f));
        let v: f64 = fast_float2::parse(f).map_err(|_| {
            anyhow::anyhow!(
                "{file}:{lineno}: column {count}: `{}` is not a number",
                text()
            )
        })?;
        if !v.is_finite() {
            bail!(
                "{file}:{lineno}: column {count}: `{}` is not finite",
                text()
            );
        }
        out.push(v);
        Ok(())
    };
    if line.is_ascii() {
        // every line of a numeric table: split byte by byte on the separators
        // `char::is_whitespace` gives for an ASCII byte (space, \t, \n, \x0B, \x0C, \r) and ','
        let sep = |b: &u8| matches!(b, b' ' | b'\t' | b'\n' | 0x0B | 0x0C | b'\r' | b',');
        for f in line.as_bytes().split(sep).filter(|f| !f.is_empty()) {
            field(f)?;
        }
    } else {
        // any other line by `char`, where Unicode white space separates too
        for f in line
            .split(|c: char| c.is_whitespace() || c == ',')
            .filter(|s| !s.is_empty())
        {
            field(f.as_bytes())?;
        }
    }
    if count != n {
        bail!("{file}:{lineno}: expected {n} columns, found {count}");
    }
    Ok(())
}

/// Splits a data line on whitespace and commas and parses `n` finite numbers.
pub fn parse_numbers(line: &str, n: usize, file: &Path, lineno: usize) -> Result<Vec<f64>> {
    let mut out = Vec::with_capacity(n);
    parse_numbers_into(line, n, &file.display().to_string(), lineno, &mut out)?;
    Ok(out)
}

/// A whitespace/comma separated numeric table with a fixed number of columns whose first column
/// is a strictly increasing time, read one row at a time; `#` comment and blank lines are
/// skipped; every problem names the file and line.
pub struct TableRows<R> {
    lines: Lines<R>,
    ncols: usize,
    prev_t: Option<f64>,
    row: Vec<f64>,
}

impl TableRows<std::io::BufReader<std::fs::File>> {
    /// Opens `path`; `what` names the kind of file in messages.
    pub fn open(path: &Path, ncols: usize, what: &str) -> Result<Self> {
        Ok(TableRows::new(Lines::open(path, what)?, ncols))
    }
}

impl<R: std::io::BufRead> TableRows<R> {
    /// Rows of `lines` with `ncols` columns.
    pub fn new(lines: Lines<R>, ncols: usize) -> Self {
        TableRows {
            lines,
            ncols,
            prev_t: None,
            row: Vec::with_capacity(ncols),
        }
    }

    /// The file's name as messages show it.
    pub fn name(&self) -> &str {
        self.lines.name()
    }

    /// Fraction of the file read so far.
    pub fn fraction(&self) -> f64 {
        self.lines.fraction()
    }

    /// The next row (line number, values), or None at the end of the file.
    pub fn next_row(&mut self) -> Result<Option<(usize, &[f64])>> {
        loop {
            let Some(line) = self.lines.next_line()? else {
                return Ok(None);
            };
            let l = line.text.trim();
            if l.is_empty() || l.starts_with('#') {
                continue;
            }
            let lineno = line.no;
            parse_numbers_into(l, self.ncols, line.file, lineno, &mut self.row)?;
            let t = self.row[0];
            if let Some(prev) = self.prev_t {
                if t <= prev {
                    bail!(
                        "{}:{lineno}: time {t} does not increase (previous {prev})",
                        line.file
                    );
                }
            }
            self.prev_t = Some(t);
            return Ok(Some((lineno, &self.row)));
        }
    }
}

/// Reads a whitespace/comma separated numeric table with `ncols` columns whose first column is a
/// strictly increasing time; `#` comment and blank lines are skipped. Returns (line, values) rows;
/// every problem names the file and line. `what` names the kind of file in messages.
pub fn read_table(path: &Path, ncols: usize, what: &str) -> Result<Vec<(usize, Vec<f64>)>> {
    let mut t = TableRows::open(path, ncols, what)?;
    let mut rows = Vec::new();
    while let Some((line, v)) = t.next_row()? {
        rows.push((line, v.to_vec()));
    }
    Ok(rows)
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

#[cfg(test)]
mod tests {
    use super::parse_numbers_into;

    /// The byte-wise split of an ASCII line and the `char` split of any other line find the
    /// same fields as `char::is_whitespace` and ',' always did.
    #[test]
    fn fields_split_on_the_same_separators_either_way() {
        let mut out = Vec::new();
        for (line, want) in [
            (
                "1 2\t3,4\u{0B}5\u{0C}6\r",
                vec![1.0, 2.0, 3.0, 4.0, 5.0, 6.0],
            ),
            ("  1,, 2e-3  -4.5 ", vec![1.0, 2e-3, -4.5]),
            // non-ASCII white space (no-break space, ideographic space) separates too
            ("1\u{A0}2\u{3000}3", vec![1.0, 2.0, 3.0]),
        ] {
            parse_numbers_into(line, want.len(), "f", 7, &mut out).unwrap();
            assert_eq!(out, want, "{line:?}");
        }
        // a non-ASCII field is named as it was written
        let e = parse_numbers_into("1 2µ 3", 3, "f", 7, &mut out).unwrap_err();
        assert!(e.to_string().contains("f:7: column 2: `2µ`"), "{e}");
        let e = parse_numbers_into("1 x 3", 3, "f", 7, &mut out).unwrap_err();
        assert!(
            e.to_string().contains("f:7: column 2: `x` is not a number"),
            "{e}"
        );
        let e = parse_numbers_into("1 2", 3, "f", 7, &mut out).unwrap_err();
        assert!(e.to_string().contains("expected 3 columns, found 2"), "{e}");
    }
}
