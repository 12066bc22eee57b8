//! Position aiding files (DESIGN §9, KF-GINS GNSS layout):
//! `t [s]  lat lon [deg]  h [m]  sigma_n sigma_e sigma_d [m]`.

use crate::io::atomic_file::AtomicFile;
use crate::io::imu::read_table;
use anyhow::{bail, Result};
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
    let rows = read_table(path, 7, "aiding file")?;
    if rows.is_empty() {
        bail!("{}: the aiding file has no data rows", path.display());
    }
    rows.into_iter()
        .map(|(line, v)| {
            if v[4..7].iter().any(|s| !(*s > 0.0 && *s <= 1e5)) {
                bail!(
                    "{}:{line}: sigma must be in (0, 1e5] m (got {}, {}, {})",
                    path.display(),
                    v[4],
                    v[5],
                    v[6]
                );
            }
            use crate::io::bounds;
            if let Some(p) = bounds::lat_deg(v[1])
                .or_else(|| bounds::lon_deg(v[2]))
                .or_else(|| bounds::height_m(v[3]))
            {
                bail!("{}:{line}: {p}", path.display());
            }
            Ok(PositionFix {
                t: v[0],
                lat: v[1].to_radians(),
                lon: v[2].to_radians(),
                h: v[3],
                sigma: [v[4], v[5], v[6]],
            })
        })
        .collect()
}
