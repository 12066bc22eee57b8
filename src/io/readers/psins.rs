//! PSINS `.imu` logs (PSINS toolbox, Yan Gongmin): `%` comment lines, three header rows
//! (`pitch0 roll0 yaw0 [deg] VE0 VN0 VU0 [m/s]`; `lat0 lon0 [deg] h0 [m] t0 [s] T [ms] g [m/s²]`;
//! `gyro scale [arcsec/count] ×3, accel scale [µg·s/count] ×3`), then integer counts of
//! increments `dθx dθy dθz dvx dvy dvz` in the PSINS body frame X-right, Y-forward, Z-up.
//!
//! Converted on reading: FRD body x = PSINS Y, y = PSINS X, z = −PSINS Z; header attitude from
//! PSINS (ENU, yaw positive west of north) to NED/FRD: roll and pitch kept, yaw = −yaw_PSINS;
//! velocity ENU → NED.

use crate::io::imu::{parse_numbers, parse_numbers_into, ImuData, ImuSample};
use crate::io::lines::Lines;
use crate::io::sample_source::SampleSource;
use anyhow::{bail, Result};
use nalgebra::Vector3;
use std::path::Path;

/// A PSINS log: the increments and its header, converted to NED/FRD and SI.
#[derive(Debug, Clone)]
pub struct PsinsLog {
    /// Increments, FRD body, starting at t0 + T.
    pub imu: ImuData,
    /// Header roll, pitch, yaw [deg] in NED/FRD (marked "maybe inaccurate" in the file).
    pub euler_deg: [f64; 3],
    /// Header velocity NED [m/s].
    pub v_ned: [f64; 3],
    /// Latitude, longitude [deg].
    pub lat_deg: f64,
    /// Longitude [deg].
    pub lon_deg: f64,
    /// Height [m].
    pub h_m: f64,
    /// Sample interval [s].
    pub interval: f64,
    /// Gravity used by the file for the accelerometer scale [m/s²].
    pub g: f64,
}

/// A PSINS log's samples, read one at a time after its header.
pub struct PsinsSource {
    lines: Lines<std::io::BufReader<std::fs::File>>,
    row: Vec<f64>,
    t0: f64,
    dt: f64,
    gscale: [f64; 3],
    ascale: [f64; 3],
    n: u64,
}

impl SampleSource for PsinsSource {
    fn next_sample(&mut self) -> Result<Option<(ImuSample, usize)>> {
        loop {
            let Some(line) = self.lines.next_line()? else {
                return Ok(None);
            };
            let l = line.text.trim();
            if l.is_empty() || l.starts_with('%') {
                continue;
            }
            let lineno = line.no;
            parse_numbers_into(l, 6, line.file, lineno, &mut self.row)?;
            let v = &self.row;
            let (g, a) = (&self.gscale, &self.ascale);
            self.n += 1;
            // PSINS body (X right, Y forward, Z up) → FRD (x forward, y right, z down)
            return Ok(Some((
                ImuSample {
                    t: self.t0 + self.n as f64 * self.dt,
                    dtheta: Vector3::new(v[1] * g[1], v[0] * g[0], -v[2] * g[2]),
                    dv: Vector3::new(v[4] * a[1], v[3] * a[0], -v[5] * a[2]),
                },
                lineno,
            )));
        }
    }
    fn fraction(&self) -> f64 {
        self.lines.fraction()
    }
}

/// Opens a PSINS `.imu` file: reads and checks its three header rows (interval, gravity, scales
/// positive and plausible, start position and attitude in range) and returns the header (with no
/// samples) and the source of its samples.
pub fn open(path: &Path) -> Result<(PsinsLog, PsinsSource)> {
    let mut lines = Lines::open(path, "PSINS log")?;
    let name = path.display().to_string();
    let mut header: Vec<(usize, Vec<f64>)> = Vec::new();
    while header.len() < 3 {
        let Some(line) = lines.next_line()? else {
            bail!("{name}: missing the three PSINS header rows");
        };
        let l = line.text.trim();
        if l.is_empty() || l.starts_with('%') {
            continue;
        }
        let lineno = line.no;
        header.push((lineno, parse_numbers(l, 6, path, lineno)?));
    }
    let (l0, h0) = (header[0].0, &header[0].1);
    let (l1, h1) = (header[1].0, &header[1].1);
    let (l2, h2) = (header[2].0, &header[2].1);
    let d2r = std::f64::consts::PI / 180.0;
    let (t0, dt, g) = (h1[3], h1[4] * 1e-3, h1[5]);
    if !(dt > 0.0 && dt <= 10.0) {
        bail!(
            "{name}:{l1}: header: sample interval T = {} ms is not an IMU's (0 < T <= 10000 ms)",
            h1[4]
        );
    }
    if !(g > 9.0 && g < 10.5) {
        bail!("{name}:{l1}: header: gravity g = {g} m/s^2 is not the Earth's (9 .. 10.5)");
    }
    if t0.abs() > 1e10 {
        bail!("{name}:{l1}: header: start time t0 = {t0} s is beyond ±1e10 s");
    }
    use crate::io::bounds;
    if let Some(p) = bounds::lat_deg(h1[0])
        .or_else(|| bounds::lon_deg(h1[1]))
        .or_else(|| bounds::height_m(h1[2]))
    {
        bail!("{name}:{l1}: header: {p}");
    }
    if let Some(p) = bounds::attitude_deg([h0[1], h0[0], h0[2]]) {
        bail!("{name}:{l0}: header: {p}");
    }
    if h0[3..6].iter().any(|v| v.abs() > 1e4) {
        bail!("{name}:{l0}: header: velocity beyond ±1e4 m/s");
    }
    let (mut gscale, mut ascale) = ([0.0; 3], [0.0; 3]);
    for k in 0..3 {
        // a count is at most a few degrees or a few g over one sample at any IMU rate
        if !(h2[k] >= 1e-9 && h2[k] <= 3600.0) {
            bail!(
                "{name}:{l2}: header: gyro scale {} arcsec/count (axis {}) must be within 1e-9 .. 3600",
                h2[k],
                k + 1
            );
        }
        if !(h2[3 + k] >= 1e-9 && h2[3 + k] <= 1e6) {
            bail!(
                "{name}:{l2}: header: accelerometer scale {} ug*s/count (axis {}) must be within 1e-9 .. 1e6",
                h2[3 + k],
                k + 1
            );
        }
        gscale[k] = h2[k] * d2r / 3600.0;
        ascale[k] = h2[3 + k] * 1e-6 * g;
    }
    let log = PsinsLog {
        imu: ImuData::default(),
        euler_deg: [h0[1], h0[0], -h0[2]],
        v_ned: [h0[4], h0[3], -h0[5]],
        lat_deg: h1[0],
        lon_deg: h1[1],
        h_m: h1[2],
        interval: dt,
        g,
    };
    Ok((
        log,
        PsinsSource {
            lines,
            row: Vec::with_capacity(6),
            t0,
            dt,
            gscale,
            ascale,
            n: 0,
        },
    ))
}
