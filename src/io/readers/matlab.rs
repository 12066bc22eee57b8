//! MATLAB `.mat` files (level 5, as `save -v7` or `-v6` writes them) as PSINS users keep them:
//! an IMU array `[wm(3) vm(3) t]` of increments (rad, m/s) in the PSINS body frame X-right,
//! Y-forward, Z-up, and a reference array `avp = [pitch roll yaw (rad) vE vN vU (m/s) lat lon
//! (rad) h (m) t (s)]`, yaw positive west of north. Selected as `FILE.mat:VARIABLE`.
//!
//! Converted on reading like the `.imu` reader: FRD body x = PSINS Y, y = PSINS X,
//! z = −PSINS Z; attitude roll and pitch kept, yaw = −yaw_PSINS; velocity ENU → NED.

use crate::io::imu::{ImuData, ImuSample};
use crate::io::truth_row::TruthRow;
use anyhow::{bail, Result};
use nalgebra::Vector3;
use std::path::{Path, PathBuf};

/// Largest `.mat` file read [bytes] (the file is read whole: 1 GiB holds 19 M samples of 7 doubles).
pub const MAX_MAT_BYTES: u64 = 1 << 30;

/// Columns of a PSINS IMU array `[wm(3) vm(3) t]`.
pub const IMU_COLUMNS: usize = 7;
/// Columns of a PSINS reference array `[att(3) vn(3) pos(3) t]`.
pub const AVP_COLUMNS: usize = 10;

/// Splits `FILE.mat:VARIABLE` into the file and the variable; `FILE.mat` alone gives no
/// variable; None when the argument does not name a `.mat` file (a path that exists as given
/// is taken as it is, colon or not).
pub fn split(arg: &Path) -> Option<(PathBuf, Option<String>)> {
    let is_mat = |p: &Path| {
        p.extension()
            .and_then(|e| e.to_str())
            .is_some_and(|e| e.eq_ignore_ascii_case("mat"))
    };
    if arg.exists() {
        return is_mat(arg).then(|| (arg.to_path_buf(), None));
    }
    let s = arg.to_str()?;
    let (file, var) = s.rsplit_once(':')?;
    let file = PathBuf::from(file);
    is_mat(&file).then(|| (file, Some(var.to_string())))
}

/// The file an argument names: the `.mat` file of `FILE.mat:VARIABLE`, else the argument.
pub fn file_of(arg: &Path) -> PathBuf {
    split(arg)
        .map(|(f, _)| f)
        .unwrap_or_else(|| arg.to_path_buf())
}

/// One array of a `.mat` file: its rows (row-major), row and column counts.
pub struct Table {
    /// Values, row after row.
    pub rows: Vec<f64>,
    /// Number of rows.
    pub n_rows: usize,
    /// Number of columns.
    pub n_cols: usize,
    /// `FILE.mat:VARIABLE`, for messages.
    pub name: String,
}

impl Table {
    /// Row `i` (0-based).
    pub fn row(&self, i: usize) -> &[f64] {
        &self.rows[i * self.n_cols..(i + 1) * self.n_cols]
    }
}

/// Reads the real numeric array `var` (or, when `var` is None, the only array with `n_cols`
/// columns) with exactly `n_cols` columns from a `.mat` file; `what` names it in messages.
pub fn read_array(path: &Path, var: Option<&str>, n_cols: usize, what: &str) -> Result<Table> {
    let file = path.display().to_string();
    let meta = std::fs::metadata(path)
        .map_err(|e| anyhow::anyhow!("{file}: cannot read {what} .mat file: {e}"))?;
    if !meta.is_file() {
        bail!("{file}: not a regular file (a directory, device or pipe)");
    }
    if meta.len() > MAX_MAT_BYTES {
        bail!(
            "{file}: {} bytes; .mat files are read whole and at most {MAX_MAT_BYTES} bytes are (save a shorter span, or write the data as text)",
            meta.len()
        );
    }
    let bytes = std::fs::read(path).map_err(|e| anyhow::anyhow!("{file}: {e}"))?;
    if bytes.len() < 128 {
        bail!(
            "{file}: {} bytes: too short for a MATLAB level-5 .mat file (128-byte header)",
            bytes.len()
        );
    }
    let text = String::from_utf8_lossy(&bytes[..116]);
    if text.starts_with("MATLAB 7.3") {
        bail!("{file}: a MATLAB 7.3 (HDF5) file; save it with `save(FILE, VAR, '-v7')` (or -v6) to read it here");
    }
    if !text.starts_with("MATLAB 5.0") {
        bail!("{file}: not a MATLAB level-5 .mat file (its header does not start with `MATLAB 5.0 MAT-file`; a MATLAB 4 file can be re-saved with -v6)");
    }
    prescan(&bytes, &file)?;
    let mat = parse_quietly(&bytes).map_err(|e| {
        anyhow::anyhow!(
            "{file}: a MATLAB level-5 file whose contents cannot be read ({e}): corrupt, or holding arrays of a kind not read here"
        )
    })?;
    let listing = || {
        let v: Vec<String> = mat
            .arrays()
            .iter()
            .map(|a| {
                let dims: Vec<String> = a.size().iter().map(|d| d.to_string()).collect();
                format!("{} ({})", crate::io::lines::shown(a.name()), dims.join("x"))
            })
            .collect();
        if v.is_empty() {
            "no numeric arrays".to_string()
        } else {
            format!("numeric arrays: {}", v.join(", "))
        }
    };
    let array = match var {
        Some(v) => mat.find_by_name(v).ok_or_else(|| {
            anyhow::anyhow!(
                "{file}: no numeric array `{}` ({})",
                crate::io::lines::shown(v),
                listing()
            )
        })?,
        None => {
            let fits: Vec<_> = mat
                .arrays()
                .iter()
                .filter(|a| a.size().len() == 2 && a.size()[1] == n_cols)
                .collect();
            match fits.as_slice() {
                [one] => *one,
                _ => bail!(
                    "{file}: name the {what} array as {file}:VARIABLE ({} with {n_cols} columns; {})",
                    if fits.is_empty() { "none" } else { "several" },
                    listing()
                ),
            }
        }
    };
    let name = format!("{file}:{}", crate::io::lines::shown(array.name()));
    let size = array.size();
    if size.len() != 2 || size[1] != n_cols {
        let dims: Vec<String> = size.iter().map(|d| d.to_string()).collect();
        let transposed = if size.len() == 2 && size[0] == n_cols {
            format!(
                " (it looks transposed: store it as {}x{n_cols}, one row per sample)",
                size[1]
            )
        } else {
            String::new()
        };
        bail!(
            "{name}: {} array is {}; expected N x {n_cols} ({}){transposed}",
            what,
            dims.join("x"),
            if n_cols == IMU_COLUMNS {
                "wm(3) [rad] vm(3) [m/s] t [s]"
            } else {
                "pitch roll yaw [rad] vE vN vU [m/s] lat lon [rad] h [m] t [s]"
            }
        );
    }
    let n_rows = size[0];
    if n_rows == 0 {
        bail!("{name}: the {what} array has no rows");
    }
    use matfile::NumericData as D;
    // doubles are read in place (a file can hold 1 GiB of them); singles are widened
    let widened: Vec<f64>;
    let col_major: &[f64] = match array.data() {
        D::Double { imag: Some(_), .. } | D::Single { imag: Some(_), .. } => {
            bail!("{name}: the {what} array is complex; expected real numbers")
        }
        D::Double { real, .. } => real,
        D::Single { real, .. } => {
            widened = real.iter().map(|&x| x as f64).collect();
            &widened
        }
        _ => bail!("{name}: the {what} array holds integers; expected double or single (PSINS arrays are double)"),
    };
    if Some(col_major.len()) != n_rows.checked_mul(n_cols) {
        bail!("{name}: the array's data do not match its size {n_rows}x{n_cols}");
    }
    let mut rows = vec![0.0; n_rows * n_cols];
    for c in 0..n_cols {
        for r in 0..n_rows {
            let x = col_major[c * n_rows + r];
            if !x.is_finite() {
                bail!(
                    "{name}: row {}, column {}: {} is not a finite number",
                    r + 1,
                    c + 1,
                    if x.is_nan() { "NaN" } else { "an infinity" }
                );
            }
            rows[r * n_cols + c] = x;
        }
    }
    Ok(Table {
        rows,
        n_rows,
        n_cols,
        name,
    })
}

/// Largest total size of a file's compressed elements once inflated [bytes].
pub const MAX_INFLATED_BYTES: u64 = MAX_MAT_BYTES;

/// Walks the top-level elements of a level-5 file before the `matfile` crate reads it: each
/// must be a matrix (14) or a compressed matrix (15) lying wholly inside the file, and the
/// compressed ones must inflate (checksum included) to at most [`MAX_INFLATED_BYTES`] in all,
/// counted without keeping them. A truncated file, a corrupt stream or a small file that
/// inflates without bound is refused here, with what was found.
fn prescan(bytes: &[u8], file: &str) -> Result<()> {
    prescan_within(bytes, file, MAX_INFLATED_BYTES)
}

/// [`prescan`] with an inflation budget [bytes].
fn prescan_within(bytes: &[u8], file: &str, max_inflated: u64) -> Result<()> {
    let little = match &bytes[126..128] {
        b"IM" => true,
        b"MI" => false,
        _ => bail!("{file}: the header's byte-order mark is neither IM nor MI: not a MATLAB level-5 file, or corrupt"),
    };
    let u32_at = |o: usize| u32_in(&bytes[o..o + 4], little);
    let (mut o, mut k, mut inflated) = (128usize, 0usize, 0u64);
    while o < bytes.len() {
        k += 1;
        if o + 8 > bytes.len() {
            bail!(
                "{file}: truncated: element {k} at byte {o} has no complete tag ({} bytes left): an interrupted copy or download?",
                bytes.len() - o
            );
        }
        let (ty, n) = (u32_at(o), u32_at(o + 4) as usize);
        let end = o + 8 + n;
        if end > bytes.len() {
            bail!(
                "{file}: truncated: element {k} at byte {o} declares {n} bytes, {} remain: an interrupted copy or download?",
                bytes.len() - o - 8
            );
        }
        match ty {
            14 => {}
            15 => {
                use std::io::Read;
                let budget = max_inflated - inflated;
                let corrupt = |e: std::io::Error| {
                    anyhow::anyhow!("{file}: compressed element {k} at byte {o} is corrupt ({e})")
                };
                let mut dec = libflate::zlib::Decoder::new(&bytes[o + 8..end]).map_err(corrupt)?;
                // what it holds must be one matrix (MATLAB never nests compression)
                let mut tag = [0u8; 8];
                dec.read_exact(&mut tag).map_err(corrupt)?;
                let (inner_ty, inner_n) = (u32_in(&tag[..4], little), u32_in(&tag[4..], little) as u64);
                if inner_ty != 14 {
                    bail!(
                        "{file}: compressed element {k} at byte {o} holds data type {inner_ty}, not a matrix (14): corrupt, or written by something other than MATLAB"
                    );
                }
                let got = 8 + std::io::copy(&mut dec.take(budget.saturating_sub(8) + 1), &mut std::io::sink())
                    .map_err(corrupt)?;
                if got <= budget && inner_n + 8 > got {
                    bail!(
                        "{file}: compressed element {k} at byte {o} holds a matrix declaring {inner_n} bytes, but only {} inflate: corrupt",
                        got - 8
                    );
                }
                if got > budget {
                    bail!(
                        "{file}: compressed element {k} inflates beyond {max_inflated} bytes (with the elements before it): refused, a .mat is read whole here"
                    );
                }
                inflated += got;
            }
            _ => bail!(
                "{file}: element {k} at byte {o} has data type {ty}, not a matrix (14) or a compressed matrix (15): corrupt, or not a MATLAB data file"
            ),
        }
        o = end;
        // some writers pad a compressed element to 8 bytes; trailing zeros end the file
        let aligned = (o + 7) & !7;
        if aligned <= bytes.len() && bytes[o..aligned].iter().all(|b| *b == 0) {
            o = aligned;
        }
        if bytes[o..].iter().all(|b| *b == 0) {
            break;
        }
    }
    Ok(())
}

/// The u32 in the first four bytes of `b`, in the file's byte order.
fn u32_in(b: &[u8], little: bool) -> u32 {
    let b = [b[0], b[1], b[2], b[3]];
    if little {
        u32::from_le_bytes(b)
    } else {
        u32::from_be_bytes(b)
    }
}

/// Parses a `.mat` file with the `matfile` crate, a panic inside it (an arithmetic overflow on
/// a corrupt dimension, found by the fuzz test) turned into an error, its message not printed.
fn parse_quietly(bytes: &[u8]) -> std::result::Result<matfile::MatFile, String> {
    let hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(|_| {}));
    let r = std::panic::catch_unwind(|| matfile::MatFile::parse(bytes));
    std::panic::set_hook(hook);
    match r {
        Ok(Ok(m)) => Ok(m),
        Ok(Err(e)) => Err(e.to_string()),
        Err(_) => Err("its structure is corrupt".to_string()),
    }
}

/// Reads a PSINS IMU array `[wm(3) vm(3) t]` (RFU increments) as FRD samples; the stream that
/// takes them checks time, gaps, rates and forces.
pub fn read_imu(path: &Path, var: Option<&str>) -> Result<(ImuData, String)> {
    let t = read_array(path, var, IMU_COLUMNS, "IMU")?;
    let samples = (0..t.n_rows)
        .map(|i| {
            let v = t.row(i);
            // PSINS body (X right, Y forward, Z up) → FRD (x forward, y right, z down)
            ImuSample {
                t: v[6],
                dtheta: Vector3::new(v[1], v[0], -v[2]),
                dv: Vector3::new(v[4], v[3], -v[5]),
            }
        })
        .collect();
    Ok((ImuData { samples }, t.name))
}

/// Reads a PSINS reference array `avp` as truth rows (NED, FRD attitude, radians); refuses
/// values out of range (degrees where radians are expected, among others) naming row and column.
pub fn read_avp(path: &Path, var: Option<&str>) -> Result<Vec<TruthRow>> {
    let t = read_array(path, var, AVP_COLUMNS, "reference (avp)")?;
    let mut out: Vec<TruthRow> = Vec::with_capacity(t.n_rows);
    use std::f64::consts::{FRAC_PI_2, PI};
    for i in 0..t.n_rows {
        let v = t.row(i);
        let at = |c: usize| format!("{}: row {}, column {}", t.name, i + 1, c + 1);
        for (c, lim, what) in [
            (0, FRAC_PI_2, "pitch"),
            (1, PI, "roll"),
            (2, 2.0 * PI, "yaw"),
            (6, FRAC_PI_2, "latitude"),
            (7, 2.0 * PI, "longitude"),
        ] {
            if v[c].abs() > lim {
                bail!(
                    "{}: {what} {} is beyond ±{lim:.4} rad (avp angles are in radians; degrees?)",
                    at(c),
                    v[c]
                );
            }
        }
        for (c, x) in v.iter().enumerate().take(6).skip(3) {
            if x.abs() > 1e4 {
                bail!("{}: velocity {x} m/s is beyond ±1e4 m/s", at(c));
            }
        }
        if let Some(p) = crate::io::bounds::height_m(v[8]) {
            bail!("{}: {p}", at(8));
        }
        if let Some(prev) = out.last() {
            if v[9] <= prev.t {
                bail!(
                    "{}: time {} does not increase (previous {})",
                    at(9),
                    v[9],
                    prev.t
                );
            }
        }
        out.push(TruthRow {
            t: v[9],
            lat: v[6],
            lon: v[7],
            h: v[8],
            v: Vector3::new(v[4], v[3], -v[5]),
            euler: Vector3::new(v[1], v[0], -v[2]),
        });
    }
    Ok(out)
}

/// IMU samples (FRD) as the rows of a PSINS `[wm(3) vm(3) t]` array (right-forward-up).
pub fn psins_imu_rows(imu: &ImuData) -> Vec<f64> {
    let mut rows = Vec::with_capacity(imu.samples.len() * IMU_COLUMNS);
    for s in &imu.samples {
        rows.extend_from_slice(&[s.dtheta.y, s.dtheta.x, -s.dtheta.z]);
        rows.extend_from_slice(&[s.dv.y, s.dv.x, -s.dv.z, s.t]);
    }
    rows
}

/// Truth rows (NED/FRD) as the rows of a PSINS `avp` array
/// `[pitch roll yaw (yaw west of north) vE vN vU lat lon h t]`, radians.
pub fn psins_avp_rows(truth: &[TruthRow]) -> Vec<f64> {
    let mut rows = Vec::with_capacity(truth.len() * AVP_COLUMNS);
    for r in truth {
        // longitude and yaw within what read_avp takes, whatever the simulator accumulated
        let yaw = crate::io::bounds::written_yaw_rad(-r.euler.z);
        rows.extend_from_slice(&[r.euler.y, r.euler.x, yaw, r.v.y, r.v.x, -r.v.z]);
        let lon = crate::io::bounds::written_lon_rad(r.lon);
        rows.extend_from_slice(&[r.lat, lon, r.h, r.t]);
    }
    rows
}

/// Writes arrays as a MATLAB level-5 `.mat` file (uncompressed, little-endian doubles): what the
/// tests and `simulate --mat` use to make files PSINS users would have. Each array is given row
/// after row with its column count.
pub fn write(path: &Path, arrays: &[(&str, &[f64], usize)]) -> Result<()> {
    let mut out: Vec<u8> = Vec::new();
    let mut header = format!(
        "MATLAB 5.0 MAT-file, Platform: sinsmodel, Created by: sinsmodel {}",
        env!("CARGO_PKG_VERSION")
    )
    .into_bytes();
    header.resize(116, b' ');
    out.extend_from_slice(&header);
    out.extend_from_slice(&[0u8; 8]); // subsystem data offset
    out.extend_from_slice(&0x0100u16.to_le_bytes());
    out.extend_from_slice(b"IM");
    let pad8 = |v: &mut Vec<u8>| {
        while !v.len().is_multiple_of(8) {
            v.push(0);
        }
    };
    for (name, rows, n_cols) in arrays {
        let n_cols = *n_cols;
        if n_cols == 0 || rows.len() % n_cols != 0 {
            bail!(
                "{}: array {name}: {} values do not fill {n_cols} columns",
                path.display(),
                rows.len()
            );
        }
        let n_rows = rows.len() / n_cols;
        let mut body: Vec<u8> = Vec::new();
        // array flags: miUINT32, 8 bytes, class mxDOUBLE_CLASS (6)
        body.extend_from_slice(&6u32.to_le_bytes());
        body.extend_from_slice(&8u32.to_le_bytes());
        body.extend_from_slice(&6u32.to_le_bytes());
        body.extend_from_slice(&0u32.to_le_bytes());
        // dimensions: miINT32
        body.extend_from_slice(&5u32.to_le_bytes());
        body.extend_from_slice(&8u32.to_le_bytes());
        body.extend_from_slice(&(n_rows as i32).to_le_bytes());
        body.extend_from_slice(&(n_cols as i32).to_le_bytes());
        // name: miINT8
        body.extend_from_slice(&1u32.to_le_bytes());
        body.extend_from_slice(&(name.len() as u32).to_le_bytes());
        body.extend_from_slice(name.as_bytes());
        pad8(&mut body);
        // real part: miDOUBLE, column after column
        body.extend_from_slice(&9u32.to_le_bytes());
        body.extend_from_slice(&((rows.len() * 8) as u32).to_le_bytes());
        for c in 0..n_cols {
            for r in 0..n_rows {
                body.extend_from_slice(&rows[r * n_cols + c].to_le_bytes());
            }
        }
        pad8(&mut body);
        // miMATRIX element
        out.extend_from_slice(&14u32.to_le_bytes());
        out.extend_from_slice(&(body.len() as u32).to_le_bytes());
        out.extend_from_slice(&body);
    }
    let mut f = crate::io::atomic_file::AtomicFile::create(path)?;
    use std::io::Write;
    f.writer().write_all(&out)?;
    f.commit()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_and_conversion() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("log.mat");
        // two samples: PSINS right/forward/up increments, then t
        let imu = [
            0.1e-4, 0.2e-4, 0.3e-4, 0.01, 0.02, 0.098, 0.01, 0.1e-4, 0.2e-4, 0.3e-4, 0.01, 0.02,
            0.098, 0.02,
        ];
        let avp = [0.01, 0.02, 0.5, 1.0, 2.0, 3.0, 0.6, 2.0, 100.0, 0.01];
        write(&p, &[("imu", &imu, 7), ("avp", &avp, 10)]).unwrap();
        let (data, name) = read_imu(&p, Some("imu")).unwrap();
        assert!(name.ends_with("log.mat:imu"));
        assert_eq!(data.samples.len(), 2);
        let s = data.samples[1];
        assert_eq!(s.t, 0.02);
        assert_eq!(
            [s.dtheta.x, s.dtheta.y, s.dtheta.z],
            [0.2e-4, 0.1e-4, -0.3e-4]
        );
        assert_eq!([s.dv.x, s.dv.y, s.dv.z], [0.02, 0.01, -0.098]);
        // the only 7-column array is found without a name
        assert_eq!(read_imu(&p, None).unwrap().0.samples.len(), 2);
        let t = read_avp(&p, Some("avp")).unwrap();
        assert_eq!(t[0].euler, Vector3::new(0.02, 0.01, -0.5));
        assert_eq!(t[0].v, Vector3::new(2.0, 1.0, -3.0));
        assert_eq!(
            (t[0].lat, t[0].lon, t[0].h, t[0].t),
            (0.6, 2.0, 100.0, 0.01)
        );
        let e = read_imu(&p, Some("nav")).unwrap_err().to_string();
        assert!(
            e.contains("no numeric array `nav`") && e.contains("imu (2x7)"),
            "{e}"
        );
        let e = read_avp(&p, Some("imu")).unwrap_err().to_string();
        assert!(e.contains("2x7") && e.contains("N x 10"), "{e}");
    }

    /// A compressed element (as `save -v7` writes) reads like the plain one; truncation, a
    /// foreign element type, a corrupt stream and an inflation beyond the budget are refused
    /// by the pre-scan with what was found.
    #[test]
    fn compressed_elements_and_the_prescan() {
        use std::io::Write;
        let dir = tempfile::tempdir().unwrap();
        let plain = dir.path().join("plain.mat");
        let imu: Vec<f64> = (1..=20)
            .flat_map(|k| [1e-6, 2e-6, 7e-7, 1e-3, 2e-3, 0.098, k as f64 * 0.01])
            .collect();
        write(&plain, &[("imu", &imu, 7)]).unwrap();
        let bytes = std::fs::read(&plain).unwrap();
        // the same miMATRIX element, zlib-compressed into a miCOMPRESSED element
        let mut enc = libflate::zlib::Encoder::new(Vec::new()).unwrap();
        enc.write_all(&bytes[128..]).unwrap();
        let z = enc.finish().into_result().unwrap();
        let mut comp = bytes[..128].to_vec();
        comp.extend_from_slice(&15u32.to_le_bytes());
        comp.extend_from_slice(&(z.len() as u32).to_le_bytes());
        comp.extend_from_slice(&z);
        let cp = dir.path().join("comp.mat");
        std::fs::write(&cp, &comp).unwrap();
        let (a, b) = (
            read_imu(&plain, None).unwrap().0,
            read_imu(&cp, None).unwrap().0,
        );
        assert_eq!(a.samples.len(), 20);
        assert!(a
            .samples
            .iter()
            .zip(&b.samples)
            .all(|(x, y)| x.t == y.t && x.dv == y.dv));
        // inflation budget
        let e = prescan_within(&comp, "c.mat", 100).unwrap_err().to_string();
        assert!(e.contains("inflates beyond 100 bytes"), "{e}");
        assert!(prescan_within(&comp, "c.mat", 1 << 20).is_ok());
        // truncated
        let e = prescan(&comp[..comp.len() - 5], "t.mat")
            .unwrap_err()
            .to_string();
        assert!(e.contains("truncated: element 1"), "{e}");
        // corrupt stream (a flipped byte in the deflate data)
        let mut bad = comp.clone();
        let mid = 136 + z.len() / 2;
        bad[mid] ^= 0x55;
        let e = prescan(&bad, "b.mat").unwrap_err().to_string();
        assert!(e.contains("corrupt") || e.contains("truncated"), "{e}");
        // compression nested in compression (MATLAB never writes it; the inner layer would
        // escape the budget)
        let mut enc = libflate::zlib::Encoder::new(Vec::new()).unwrap();
        enc.write_all(&comp[128..]).unwrap();
        let z2 = enc.finish().into_result().unwrap();
        let mut nested = bytes[..128].to_vec();
        nested.extend_from_slice(&15u32.to_le_bytes());
        nested.extend_from_slice(&(z2.len() as u32).to_le_bytes());
        nested.extend_from_slice(&z2);
        let e = prescan(&nested, "n.mat").unwrap_err().to_string();
        assert!(e.contains("holds data type 15"), "{e}");
        // a foreign element type
        let mut foreign = bytes.clone();
        foreign[128] = 13;
        let e = prescan(&foreign, "f.mat").unwrap_err().to_string();
        assert!(e.contains("data type 13"), "{e}");
    }

    #[test]
    fn refusals() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("bad.mat");
        let mut avp = [0.01, 0.02, 0.5, 1.0, 2.0, 3.0, 34.0, 2.0, 100.0, 0.01];
        write(&p, &[("avp", &avp, 10)]).unwrap();
        let e = read_avp(&p, None).unwrap_err().to_string();
        assert!(
            e.contains("row 1, column 7") && e.contains("degrees?"),
            "{e}"
        );
        avp[6] = f64::NAN;
        write(&p, &[("avp", &avp, 10)]).unwrap();
        let e = read_avp(&p, None).unwrap_err().to_string();
        assert!(e.contains("NaN") && e.contains("column 7"), "{e}");
        let imu_t = [0.0; 14];
        write(&p, &[("imu", &imu_t, 2)]).unwrap();
        let e = read_imu(&p, Some("imu")).unwrap_err().to_string();
        assert!(e.contains("transposed"), "{e}");
        std::fs::write(&p, b"hello, this is text").unwrap();
        let e = read_imu(&p, None).unwrap_err().to_string();
        assert!(e.contains("too short"), "{e}");
        let mut hdf = b"MATLAB 7.3 MAT-file".to_vec();
        hdf.resize(512, b' ');
        std::fs::write(&p, &hdf).unwrap();
        let e = read_imu(&p, None).unwrap_err().to_string();
        assert!(e.contains("-v7"), "{e}");
        assert_eq!(
            split(Path::new("/nonexistent/x.mat:imu")),
            Some((PathBuf::from("/nonexistent/x.mat"), Some("imu".to_string())))
        );
        assert_eq!(split(Path::new("/nonexistent/x.txt:imu")), None);
    }
}
