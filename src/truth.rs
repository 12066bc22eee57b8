//! Truth files (DESIGN §9): `t [s]  lat lon [deg]  h [m]  v_n v_e v_d [m/s]  roll pitch yaw [deg]`.

use crate::atomic_file::AtomicFile;
use crate::imu::read_table;
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
        writeln!(
            w,
            "{:.4} {:.11} {:.11} {:.4} {:.6} {:.6} {:.6} {:.9} {:.9} {:.9}",
            r.t,
            r.lat.to_degrees(),
            r.lon.to_degrees(),
            r.h,
            r.v.x,
            r.v.y,
            r.v.z,
            r.euler.x.to_degrees(),
            r.euler.y.to_degrees(),
            r.euler.z.to_degrees()
        )?;
    }
    f.commit()
}

/// Reads a truth file (errors name file and line; time must increase).
pub fn read(path: &Path) -> Result<Vec<TruthRow>> {
    Ok(read_table(path, 10, "truth file")?
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
