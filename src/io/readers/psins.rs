//! PSINS `.imu` logs (PSINS toolbox, Yan Gongmin): `%` comment lines, three header rows
//! (`pitch0 roll0 yaw0 [deg] VE0 VN0 VU0 [m/s]`; `lat0 lon0 [deg] h0 [m] t0 [s] T [ms] g [m/s²]`;
//! `gyro scale [arcsec/count] ×3, accel scale [µg·s/count] ×3`), then integer counts of
//! increments `dθx dθy dθz dvx dvy dvz` in the PSINS body frame X-right, Y-forward, Z-up.
//!
//! Converted on reading: FRD body x = PSINS Y, y = PSINS X, z = −PSINS Z; header attitude from
//! PSINS (ENU, yaw positive west of north) to NED/FRD: roll and pitch kept, yaw = −yaw_PSINS;
//! velocity ENU → NED.

use crate::io::imu::{parse_numbers, ImuData, ImuSample};
use anyhow::{bail, Context, Result};
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

/// Reads a PSINS `.imu` file.
pub fn read(path: &Path) -> Result<PsinsLog> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("cannot read PSINS log {}", path.display()))?;
    let mut header: Vec<Vec<f64>> = Vec::new();
    let mut samples = Vec::new();
    let (mut t0, mut dt, mut gscale, mut ascale) = (0.0, 0.0, [0.0; 3], [0.0; 3]);
    let d2r = std::f64::consts::PI / 180.0;
    let mut g = 0.0;
    for (i, line) in text.lines().enumerate() {
        let l = line.trim();
        if l.is_empty() || l.starts_with('%') {
            continue;
        }
        let v = parse_numbers(l, 6, path, i + 1)?;
        if header.len() < 3 {
            header.push(v);
            if header.len() == 3 {
                t0 = header[1][3];
                dt = header[1][4] * 1e-3;
                g = header[1][5];
                if dt.is_nan() || dt <= 0.0 || g.is_nan() || g <= 9.0 || g >= 10.5 {
                    bail!(
                        "{}:{}: header: bad sample interval {} ms or g {}",
                        path.display(),
                        i,
                        header[1][4],
                        g
                    );
                }
                for k in 0..3 {
                    gscale[k] = header[2][k] * d2r / 3600.0;
                    ascale[k] = header[2][3 + k] * 1e-6 * g;
                }
            }
            continue;
        }
        let n = samples.len() as f64 + 1.0;
        // PSINS body (X right, Y forward, Z up) → FRD (x forward, y right, z down)
        let th = Vector3::new(v[1] * gscale[1], v[0] * gscale[0], -v[2] * gscale[2]);
        let dv = Vector3::new(v[4] * ascale[1], v[3] * ascale[0], -v[5] * ascale[2]);
        samples.push(ImuSample {
            t: t0 + n * dt,
            dtheta: th,
            dv,
        });
    }
    if header.len() < 3 {
        bail!("{}: missing the three PSINS header rows", path.display());
    }
    if samples.is_empty() {
        bail!("{}: no data rows", path.display());
    }
    let h0 = &header[0];
    Ok(PsinsLog {
        imu: ImuData { samples },
        euler_deg: [h0[1], h0[0], -h0[2]],
        v_ned: [h0[4], h0[3], -h0[5]],
        lat_deg: header[1][0],
        lon_deg: header[1][1],
        h_m: header[1][2],
        interval: dt,
        g,
    })
}
