//! Position aiding files (DESIGN §9, KF-GINS GNSS layout):
//! `t [s]  lat lon [deg]  h [m]  sigma_n sigma_e sigma_d [m]`.

use crate::atomic_file::AtomicFile;
use crate::imu::parse_numbers;
use anyhow::{bail, Context, Result};
use std::io::Write;
use std::path::Path;

/// A position fix with its 1-σ (angles in radians in memory).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PositionFix {
    /// Time [s].
    pub t: f64,
    /// Latitude [rad].
    pub lat: f64,
    /// Longitude [rad].
    pub lon: f64,
    /// Height [m].
    pub h: f64,
    /// 1-σ north, east, down [m].
    pub sigma: [f64; 3],
}

/// Writes fixes atomically.
pub fn write(path: &Path, rows: &[PositionFix], header: &str) -> Result<()> {
    let mut f = AtomicFile::create(path)?;
    let w = f.writer();
    for l in header.lines() {
        writeln!(w, "# {l}")?;
    }
    writeln!(w, "# t[s] lat lon [deg] h[m] sigma_n sigma_e sigma_d [m]")?;
    for r in rows {
        writeln!(
            w,
            "{:.4} {:.11} {:.11} {:.4} {:.4} {:.4} {:.4}",
            r.t,
            r.lat.to_degrees(),
            r.lon.to_degrees(),
            r.h,
            r.sigma[0],
            r.sigma[1],
            r.sigma[2]
        )?;
    }
    f.commit()
}

/// Reads a position aiding file; σ must be positive, time increasing.
pub fn read(path: &Path) -> Result<Vec<PositionFix>> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("cannot read aiding file {}", path.display()))?;
    let mut out: Vec<PositionFix> = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let l = line.trim();
        if l.is_empty() || l.starts_with('#') {
            continue;
        }
        let v = parse_numbers(l, 7, path, i + 1)?;
        if out.last().is_some_and(|p| v[0] <= p.t) {
            bail!(
                "{}:{}: time {} does not increase",
                path.display(),
                i + 1,
                v[0]
            );
        }
        if v[4] <= 0.0 || v[5] <= 0.0 || v[6] <= 0.0 {
            bail!("{}:{}: sigma must be positive", path.display(), i + 1);
        }
        if v[1].abs() > 90.0 {
            bail!(
                "{}:{}: latitude {} outside ±90°",
                path.display(),
                i + 1,
                v[1]
            );
        }
        out.push(PositionFix {
            t: v[0],
            lat: v[1].to_radians(),
            lon: v[2].to_radians(),
            h: v[3],
            sigma: [v[4], v[5], v[6]],
        });
    }
    Ok(out)
}
