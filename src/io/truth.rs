//! Truth files (DESIGN §9): `t [s]  lat lon [deg]  h [m]  v_n v_e v_d [m/s]  roll pitch yaw [deg]`.

use crate::io::atomic_file::AtomicFile;
use crate::io::fixed::write_fixed;
use crate::io::imu::read_table;
use anyhow::Result;
use nalgebra::Vector3;
use std::io::Write;
use std::path::Path;

/// A truth record (angles in radians in memory).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TruthRow {
    /// Time [s].
    pub t: f64,
    /// Latitude [rad].
    pub lat: f64,
    /// Longitude [rad].
    pub lon: f64,
    /// Height [m].
    pub h: f64,
    /// NED velocity [m/s].
    pub v: Vector3<f64>,
    /// Roll, pitch, yaw [rad].
    pub euler: Vector3<f64>,
}

/// Writes truth rows atomically.
pub fn write(path: &Path, rows: &[TruthRow], header: &str) -> Result<()> {
    let mut f = AtomicFile::create(path)?;
    let w = f.writer();
    for l in header.lines() {
        writeln!(w, "# {l}")?;
    }
    writeln!(
        w,
        "# t[s] lat lon [deg] h[m] v_n v_e v_d [m/s] roll pitch yaw [deg] (NED, FRD)"
    )?;
    for r in rows {
        write_row(w, r)?;
    }
    f.commit()
}

/// Writes one row of the truth layout (`t lat lon h v_n v_e v_d roll pitch yaw`, degrees).
pub fn write_row<W: Write>(w: &mut W, r: &TruthRow) -> std::io::Result<()> {
    let d = 180.0 / std::f64::consts::PI;
    let cols: [(f64, usize); 10] = [
        (r.t, 4),
        (r.lat * d, 11),
        (r.lon * d, 11),
        (r.h, 4),
        (r.v.x, 6),
        (r.v.y, 6),
        (r.v.z, 6),
        (r.euler.x * d, 9),
        (r.euler.y * d, 9),
        (r.euler.z * d, 9),
    ];
    for (k, (v, dec)) in cols.iter().enumerate() {
        if k > 0 {
            w.write_all(b" ")?;
        }
        write_fixed(w, *v, *dec)?;
    }
    w.write_all(b"\n")
}

/// Reads a truth file (errors name file and line; time must increase).
pub fn read(path: &Path) -> Result<Vec<TruthRow>> {
    let rows = read_table(path, 10, "truth file")?;
    if rows.is_empty() {
        anyhow::bail!("{}: the truth file has no data rows", path.display());
    }
    for (line, v) in &rows {
        use crate::io::bounds;
        let what = bounds::lat_deg(v[1])
            .or_else(|| bounds::lon_deg(v[2]))
            .or_else(|| bounds::height_m(v[3]))
            .or_else(|| {
                v[4..7]
                    .iter()
                    .any(|x| x.abs() > 1e4)
                    .then(|| "velocity beyond ±1e4 m/s".to_string())
            })
            .or_else(|| bounds::attitude_deg([v[7], v[8], v[9]]));
        if let Some(w) = what {
            anyhow::bail!("{}:{line}: {w}", path.display());
        }
    }
    Ok(rows
        .into_iter()
        .map(|(_, v)| TruthRow {
            t: v[0],
            lat: v[1].to_radians(),
            lon: v[2].to_radians(),
            h: v[3],
            v: Vector3::new(v[4], v[5], v[6]),
            euler: Vector3::new(v[7].to_radians(), v[8].to_radians(), v[9].to_radians()),
        })
        .collect())
}
