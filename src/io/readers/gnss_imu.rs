//! The rtklibexplorer GNSS_IMU logs: `imu_*.csv` with rows `acc_x acc_y acc_z [g]
//! gyro_x gyro_y gyro_z [deg/s] t [ms since power-up]`, and the RTKLIB time-tag file
//! `imu_*.csv.tag` (60-byte text header, u32 tick_f, u32 time [s], f64 sec — the GPST start,
//! seconds since 1970 — then records u32 tick [ms since start], u32 file position).
//!
//! Rates are turned into increments over each sample interval (rate × Δt). The IMU's body axes
//! are not documented: samples stay in the sensor's own axes (the mounting is found from the
//! data elsewhere). A malformed first or last line (partial write) is skipped with a warning; a
//! malformed line elsewhere is an error.

use crate::io::imu::{ImuData, ImuSample};
use crate::io::units::STANDARD_GRAVITY;
use anyhow::{bail, Context, Result};
use nalgebra::Vector3;
use std::path::Path;

/// A GNSS_IMU log on GPST.
#[derive(Debug, Clone)]
pub struct GnssImuLog {
    /// Increments in the sensor axes, times in GPST seconds since 1970.
    pub imu: ImuData,
    /// GPST − IMU clock [s], from the time-tag file.
    pub clock_offset: f64,
    /// Lines skipped with a warning (line numbers).
    pub skipped: Vec<usize>,
}

fn parse_row(l: &str) -> Option<[f64; 7]> {
    let f: Vec<&str> = l.split(',').map(str::trim).collect();
    if f.len() != 7 || f.iter().any(|x| x.is_empty()) {
        return None;
    }
    let mut out = [0.0; 7];
    for (o, s) in out.iter_mut().zip(&f) {
        *o = s.parse().ok().filter(|v: &f64| v.is_finite())?;
    }
    Some(out)
}

/// Reads `path` and, for GPST, `path` + `.tag`.
pub fn read(path: &Path) -> Result<GnssImuLog> {
    read_with(path, None)
}

/// Reads `path` with the clock offset [s] added to its times when given (`--clock-offset`: a
/// log without its `.tag`, or another clock), else from the `.tag` file beside it.
pub fn read_with(path: &Path, given_offset: Option<f64>) -> Result<GnssImuLog> {
    let meta = std::fs::metadata(path)
        .with_context(|| format!("cannot read IMU log {}", path.display()))?;
    if !meta.is_file() {
        bail!("{}: not a regular file", path.display());
    }
    let bytes =
        std::fs::read(path).with_context(|| format!("cannot read IMU log {}", path.display()))?;
    // the same text rules as every reader (crate::io::lines): NUL bytes, non-UTF-8 text and
    // over-long lines refused with file:line; a byte-order mark is kept in the byte count (the
    // tag counts it) but not in the first row
    let mut lineno = 0usize;
    for l in bytes.split(|&b| b == b'\n') {
        lineno += 1;
        let what = if l.len() > crate::io::lines::MAX_LINE_BYTES {
            "a line longer than 1 MiB"
        } else if l.contains(&0) {
            "NUL bytes in the line"
        } else if std::str::from_utf8(l).is_err() {
            "not UTF-8 text"
        } else {
            continue;
        };
        bail!(
            "{}:{lineno}: {what}: not a GNSS_IMU csv (binary data, or a truncated write)",
            path.display()
        );
    }
    let text = String::from_utf8_lossy(&bytes);
    let lines: Vec<&str> = text.split('\n').collect();
    let n_lines = lines
        .iter()
        .rposition(|l| !l.trim().is_empty())
        .map(|k| k + 1)
        .unwrap_or(0);
    // The tag's file positions count the bytes as logged; this file was stored with LF line ends
    // where the logger wrote CR LF when the last tag position lies beyond the file's end.
    let tag_path = path.with_extension("csv.tag");
    let clock = match given_offset {
        Some(o) => Clock::Given(o),
        None => Clock::Tag(read_tag(&tag_path).with_context(|| {
            "without its .tag file, give the clock offset with --clock-offset SECONDS (GPST - IMU clock; 0 keeps the IMU's own clock)"
        })?),
    };
    let last_pos = match &clock {
        Clock::Tag(t) => t.records.last().map(|r| r.1).unwrap_or(0),
        Clock::Given(_) => 0,
    };
    let line_end_bytes = if last_pos > bytes.len() { 2 } else { 1 };
    let mut rows: Vec<([f64; 7], usize)> = Vec::new(); // (row, byte offset of the line end)
    let mut skipped = Vec::new();
    let mut offset = 0usize;
    for (i, line) in lines.iter().enumerate().take(n_lines) {
        let line = line.trim_end_matches('\r');
        offset += line.len() + line_end_bytes;
        let l = line.trim().trim_start_matches('\u{feff}');
        match parse_row(l) {
            Some(r) => rows.push((r, offset)),
            None if i == 0 || i + 1 == n_lines => {
                eprintln!(
                    "warning: {}:{}: partial or malformed line skipped: `{}`",
                    path.display(),
                    i + 1,
                    crate::io::lines::shown(l)
                );
                skipped.push(i + 1);
            }
            None => bail!(
                "{}:{}: malformed row `{}` (expected 7 comma-separated numbers)",
                path.display(),
                i + 1,
                crate::io::lines::shown(l)
            ),
        }
    }
    if rows.len() < 2 {
        bail!("{}: fewer than two valid rows", path.display());
    }
    let clock_offset = match &clock {
        Clock::Given(o) => *o,
        Clock::Tag(tag) => clock_offset(tag, &tag_path, &rows)?,
    };
    let d2r = std::f64::consts::PI / 180.0;
    let mut samples = Vec::with_capacity(rows.len());
    for (k, w) in rows.windows(2).enumerate() {
        let (prev, cur) = (&w[0].0, &w[1].0);
        let dt = (cur[6] - prev[6]) * 1e-3;
        if dt <= 0.0 {
            bail!(
                "{}: row {}: time {} ms does not increase (previous {} ms)",
                path.display(),
                k + 2,
                cur[6],
                prev[6]
            );
        }
        samples.push(ImuSample {
            t: cur[6] * 1e-3 + clock_offset,
            dtheta: Vector3::new(cur[3], cur[4], cur[5]) * (d2r * dt),
            dv: Vector3::new(cur[0], cur[1], cur[2]) * (STANDARD_GRAVITY * dt),
        });
    }
    Ok(GnssImuLog {
        imu: ImuData { samples },
        clock_offset,
        skipped,
    })
}

/// Where the GPST − IMU clock offset comes from.
enum Clock {
    /// Given by the user [s].
    Given(f64),
    /// The RTKLIB time-tag file.
    Tag(Tag),
}

/// The parsed time-tag file: GPST start [s since 1970] and (tick [ms], file position) records.
struct Tag {
    start: f64,
    records: Vec<(f64, usize)>,
}

fn read_tag(tag: &Path) -> Result<Tag> {
    let b = std::fs::read(tag)
        .with_context(|| format!("cannot read time-tag file {}", tag.display()))?;
    if b.len() < 76 || !b.starts_with(b"TIMETAG") {
        bail!("{}: not an RTKLIB time-tag file", tag.display());
    }
    let time = u32::from_le_bytes(b[64..68].try_into().expect("4 bytes")) as f64;
    let sec = f64::from_le_bytes(b[68..76].try_into().expect("8 bytes"));
    let records = b[76..]
        .chunks_exact(8)
        .map(|r| {
            let tick = u32::from_le_bytes(r[0..4].try_into().expect("4 bytes")) as f64;
            let fpos = u32::from_le_bytes(r[4..8].try_into().expect("4 bytes")) as usize;
            (tick, fpos)
        })
        .collect::<Vec<(f64, usize)>>();
    // zero padding after the records is no record
    let mut records = records;
    while records.last().is_some_and(|r| r.0 == 0.0 && r.1 == 0) {
        records.pop();
    }
    // the logger appends: ticks and file positions never decrease; a record that does is
    // corrupt and would move the least-latency bound, i.e. the whole clock
    if let Some(k) = records
        .windows(2)
        .position(|w| w[1].0 < w[0].0 || w[1].1 < w[0].1)
    {
        let (a, b) = (records[k], records[k + 1]);
        bail!(
            "{}: record {} (byte {}) goes back from record {}: tick {} ms and file position {} after tick {} ms and position {} \
             (ticks and positions only grow as the log is written): a corrupted time-tag file, which would shift the IMU clock; \
             use an intact .tag, or give --clock-offset SECONDS (GPST - IMU clock)",
            tag.display(),
            k + 2,
            76 + 8 * (k + 1),
            k + 1,
            b.0,
            b.1,
            a.0,
            a.1
        );
    }
    Ok(Tag {
        start: time + sec,
        records,
    })
}

/// GPST − IMU clock: each tag record says the bytes up to its file position had arrived by
/// start + tick; a line ending before that position was sampled no later, so every record bounds
/// the offset from above and the smallest bound (least latency) is taken.
fn clock_offset(tag: &Tag, path: &Path, rows: &[([f64; 7], usize)]) -> Result<f64> {
    let mut best = f64::INFINITY;
    let mut bounds = Vec::with_capacity(tag.records.len());
    let mut k = 0usize;
    for &(tick, fpos) in &tag.records {
        while k + 1 < rows.len() && rows[k + 1].1 <= fpos {
            k += 1;
        }
        if rows[k].1 <= fpos {
            let bound = tag.start + tick * 1e-3 - rows[k].0[6] * 1e-3;
            best = best.min(bound);
            bounds.push(bound);
        }
    }
    if !best.is_finite() {
        bail!("{}: no record covers a complete IMU line", path.display());
    }
    // the least latency is shared by many records (on the shared drive the 10 smallest bounds
    // lie within 9 ms): a smallest bound far below the fifth smallest is one bad record
    if bounds.len() >= 5 {
        bounds.sort_by(f64::total_cmp);
        if bounds[4] - bounds[0] > 0.05 {
            bail!(
                "{}: the smallest clock bound of its records is {:.3} s below the fifth smallest (the least latency is shared by many \
                 records): a corrupted record would shift the IMU clock; use an intact .tag, or give --clock-offset SECONDS",
                path.display(),
                bounds[4] - bounds[0]
            );
        }
    }
    // the logger tags the file as it grows: records that stop well before the log's end are a
    // truncated tag file, whose least-latency bound comes from its early part only (a clock
    // seconds late)
    let (last_tagged, log_end) = (
        tag.records.iter().map(|r| r.1).max().unwrap_or(0),
        rows.last().map_or(0, |r| r.1),
    );
    if (last_tagged as f64) < 0.95 * log_end as f64 {
        bail!(
            "{}: its records end at byte {last_tagged} of the {log_end}-byte log ({:.0} %): a \
             truncated time-tag file gives a clock offset from the log's start only; use the whole \
             .tag, or give --clock-offset SECONDS (GPST - IMU clock)",
            path.display(),
            100.0 * last_tagged as f64 / log_end.max(1) as f64
        );
    }
    Ok(best)
}
