//! Truth files (DESIGN §9): `t [s]  lat lon [deg]  h [m]  v_n v_e v_d [m/s]  roll pitch yaw [deg]`.

use crate::io::atomic_file::AtomicFile;
use crate::io::fixed::write_fixed;
use crate::io::imu::TableRows;
use anyhow::Result;
use nalgebra::Vector3;
use std::io::Write;
use std::path::Path;

pub use crate::io::truth_row::TruthRow;

/// Writes truth rows atomically.
pub fn write(path: &Path, rows: &[TruthRow], header: &str) -> Result<()> {
    let mut f = create(path, header)?;
    for r in rows {
        write_row(f.writer(), r)?;
    }
    f.commit()
}

/// Starts a truth-layout file (atomic, appears on commit) with its header lines; rows follow
/// with [`write_row`].
pub fn create(path: &Path, header: &str) -> Result<AtomicFile> {
    let mut f = AtomicFile::create(path)?;
    let w = f.writer();
    for l in header.lines() {
        writeln!(w, "# {l}")?;
    }
    writeln!(
        w,
        "# t[s] lat lon [deg] h[m] v_n v_e v_d [m/s] roll pitch yaw [deg] (NED, FRD)"
    )?;
    Ok(f)
}

/// Writes one row of the truth layout (`t lat lon h v_n v_e v_d roll pitch yaw`, degrees).
pub fn write_row<W: Write>(w: &mut W, r: &TruthRow) -> std::io::Result<()> {
    for (k, (v, dec)) in columns(r).iter().enumerate() {
        if k > 0 {
            w.write_all(b" ")?;
        }
        write_fixed(w, *v, *dec)?;
    }
    w.write_all(b"\n")
}

/// [`write_row`]'s values onto the end of `out`, without its line end (the caller adds more
/// columns): the same bytes without a call per number (nav.txt's rows at every IMU sample).
pub fn push_row_values(out: &mut Vec<u8>, r: &TruthRow) {
    for (k, (v, dec)) in columns(r).iter().enumerate() {
        if k > 0 {
            out.push(b' ');
        }
        crate::io::fixed::push_fixed(out, *v, *dec);
    }
}

/// A truth row's ten written values (degrees for angles) and the decimals each is written with.
fn columns(r: &TruthRow) -> [(f64, usize); 10] {
    let d = 180.0 / std::f64::consts::PI;
    // longitude in [-180, 180) and yaw within ±360 whatever the navigator accumulated
    let lon_deg = crate::io::bounds::written_lon_deg(r.lon * d);
    [
        (r.t, 4),
        (r.lat * d, 11),
        (lon_deg, 11),
        (r.h, 4),
        (r.v.x, 6),
        (r.v.y, 6),
        (r.v.z, 6),
        (r.euler.x * d, 9),
        (r.euler.y * d, 9),
        (crate::io::bounds::written_yaw_deg(r.euler.z * d), 9),
    ]
}

/// Checks one truth row's ranges and converts it (degrees → radians).
fn row_from(file: &str, line: usize, v: &[f64]) -> Result<TruthRow> {
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
        anyhow::bail!("{file}:{line}: {w}");
    }
    Ok(TruthRow {
        t: v[0],
        lat: v[1].to_radians(),
        lon: v[2].to_radians(),
        h: v[3],
        v: Vector3::new(v[4], v[5], v[6]),
        euler: Vector3::new(v[7].to_radians(), v[8].to_radians(), v[9].to_radians()),
    })
}

/// Looks up truth rows at increasing times (a file read as it goes, or rows in memory).
pub trait TruthLookup {
    /// The row nearest after or at `t − 1 µs` when it lies within `tol` [s] of `t`; calls come
    /// with non-decreasing `t`.
    fn at(&mut self, t: f64, tol: f64) -> Result<Option<TruthRow>>;
}

/// Rows in memory with a cursor.
pub struct TruthSlice<'a> {
    rows: &'a [TruthRow],
    i: usize,
}

impl<'a> TruthSlice<'a> {
    /// A cursor at the first row.
    pub fn new(rows: &'a [TruthRow]) -> Self {
        TruthSlice { rows, i: 0 }
    }
}

impl TruthLookup for TruthSlice<'_> {
    fn at(&mut self, t: f64, tol: f64) -> Result<Option<TruthRow>> {
        while self.i + 1 < self.rows.len() && self.rows[self.i].t < t - 1e-6 {
            self.i += 1;
        }
        Ok(self
            .rows
            .get(self.i)
            .filter(|r| (r.t - t).abs() < tol)
            .copied())
    }
}

/// A truth file read as the lookups advance: memory does not grow with the file.
pub struct TruthReader {
    rows: Option<TableRows<std::io::BufReader<std::fs::File>>>,
    /// Rows of a `.mat` reference array (read whole).
    mem: std::vec::IntoIter<TruthRow>,
    cur: Option<TruthRow>,
}

impl TruthReader {
    /// Opens a truth file; refuses one without data rows.
    pub fn open(path: &Path) -> Result<TruthReader> {
        let mut r = match crate::io::readers::matlab::split(path) {
            Some((file, var)) => TruthReader {
                rows: None,
                mem: crate::io::readers::matlab::read_avp(&file, var.as_deref())?.into_iter(),
                cur: None,
            },
            None => TruthReader {
                rows: Some(TableRows::open(path, 10, "truth file")?),
                mem: Vec::new().into_iter(),
                cur: None,
            },
        };
        r.cur = r.read_row()?;
        if r.cur.is_none() {
            anyhow::bail!("{}: the truth file has no data rows", path.display());
        }
        Ok(r)
    }

    fn read_row(&mut self) -> Result<Option<TruthRow>> {
        let Some(rows) = self.rows.as_mut() else {
            return Ok(self.mem.next());
        };
        let name = rows.name().to_string();
        match rows.next_row()? {
            Some((line, v)) => Ok(Some(row_from(&name, line, v)?)),
            None => Ok(None),
        }
    }
}

impl TruthReader {
    /// The next row in file order (and the reader moves past it).
    pub fn next_row(&mut self) -> Result<Option<TruthRow>> {
        let r = self.cur;
        if r.is_some() {
            self.cur = self.read_row()?;
        }
        Ok(r)
    }

    /// Reads the rest of the file, so that a bad row after the last lookup is still reported.
    pub fn finish(mut self) -> Result<()> {
        while self.read_row()?.is_some() {}
        Ok(())
    }
}

impl TruthLookup for TruthReader {
    fn at(&mut self, t: f64, tol: f64) -> Result<Option<TruthRow>> {
        while self.cur.is_some_and(|r| r.t < t - 1e-6) {
            match self.read_row()? {
                Some(r) => self.cur = Some(r),
                None => break,
            }
        }
        Ok(self.cur.filter(|r| (r.t - t).abs() < tol))
    }
}

/// Reads a truth file whole (errors name file and line; time must increase).
pub fn read(path: &Path) -> Result<Vec<TruthRow>> {
    if let Some((file, var)) = crate::io::readers::matlab::split(path) {
        return crate::io::readers::matlab::read_avp(&file, var.as_deref());
    }
    let mut t = TableRows::open(path, 10, "truth file")?;
    let name = t.name().to_string();
    let mut rows = Vec::new();
    while let Some((line, v)) = t.next_row()? {
        rows.push(row_from(&name, line, v)?);
    }
    if rows.is_empty() {
        anyhow::bail!("{}: the truth file has no data rows", path.display());
    }
    Ok(rows)
}
