//! RTKLIB `.pos` solutions: `%` header lines, then `YYYY/MM/DD HH:MM:SS.sss lat lon h Q ns
//! sdn sde sdu sdne sdeu sdun age ratio [vn ve vu sdvn sdve sdvu sdvne sdveu sdvun]` in GPST.

use crate::io::lines::{shown, Lines};
use anyhow::{bail, Result};
use std::path::Path;

/// One RTKLIB epoch.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PosEpoch {
    /// GPST, seconds since 1970-01-01 (GPST calendar, no leap seconds applied).
    pub t: f64,
    /// Latitude [deg].
    pub lat_deg: f64,
    /// Longitude [deg].
    pub lon_deg: f64,
    /// Ellipsoidal height [m].
    pub h: f64,
    /// Quality flag (1 fix, 2 float, …).
    pub q: u8,
    /// 1-σ north, east, up [m].
    pub sigma_neu: [f64; 3],
    /// NED velocity [m/s] when the file has it.
    pub v_ned: Option<[f64; 3]>,
    /// 1-σ of the north and east velocity [m/s] when the file has them.
    pub sigma_v_ne: Option<[f64; 2]>,
}

/// Days since 1970-01-01 of a proleptic Gregorian date.
pub fn days_from_civil(y: i64, m: i64, d: i64) -> i64 {
    let y = if m <= 2 { y - 1 } else { y };
    let era = if y >= 0 { y } else { y - 399 } / 400;
    let yoe = y - era * 400;
    let doy = (153 * (m + if m > 2 { -3 } else { 9 }) + 2) / 5 + d - 1;
    let doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
    era * 146_097 + doe - 719_468
}

/// Reads a `.pos` file.
pub fn read(path: &Path) -> Result<Vec<PosEpoch>> {
    let mut lines = Lines::open(path, "RTKLIB solution")?;
    let mut out: Vec<PosEpoch> = Vec::new();
    while let Some(line) = lines.next_line()? {
        let l = line.text.trim();
        if l.is_empty() || l.starts_with('%') {
            continue;
        }
        let (file, no) = (line.file, line.no);
        let at = || format!("{file}:{no}");
        let f: Vec<&str> = l.split_whitespace().collect();
        if f.len() < 14 {
            bail!("{}: expected at least 14 columns, found {}", at(), f.len());
        }
        let date: Vec<i64> = f[0].split('/').filter_map(|x| x.parse().ok()).collect();
        let time: Vec<f64> = f[1].split(':').filter_map(|x| x.parse().ok()).collect();
        if date.len() != 3
            || time.len() != 3
            || !(1980..=2200).contains(&date[0])
            || !(1..=12).contains(&date[1])
            || !(1..=31).contains(&date[2])
            || !(0.0..24.0).contains(&time[0])
            || !(0.0..60.0).contains(&time[1])
            || !(0.0..61.0).contains(&time[2])
        {
            bail!(
                "{}: bad GPST date/time `{} {}` (expected YYYY/MM/DD HH:MM:SS.SSS, year 1980 to 2200)",
                at(),
                shown(f[0]),
                shown(f[1])
            );
        }
        let num = |k: usize| -> Result<f64> {
            f[k].parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| {
                    anyhow::anyhow!(
                        "{}: column {}: `{}` is not a finite number",
                        at(),
                        k + 1,
                        shown(f[k])
                    )
                })
        };
        let t = days_from_civil(date[0], date[1], date[2]) as f64 * 86400.0
            + time[0] * 3600.0
            + time[1] * 60.0
            + time[2];
        if let Some(prev) = out.last() {
            if t <= prev.t {
                bail!("{}: time does not increase", at());
            }
        }
        let v_ned = if f.len() >= 18 {
            Some([num(15)?, num(16)?, -num(17)?])
        } else {
            None
        };
        let sigma_v_ne = if f.len() >= 21 {
            Some([num(18)?, num(19)?])
        } else {
            None
        };
        let e = PosEpoch {
            sigma_v_ne,
            t,
            lat_deg: num(2)?,
            lon_deg: num(3)?,
            h: num(4)?,
            q: num(5)? as u8,
            sigma_neu: [num(7)?, num(8)?, num(9)?],
            v_ned,
        };
        use crate::io::bounds;
        let bad = bounds::lat_deg(e.lat_deg)
            .or_else(|| bounds::lon_deg(e.lon_deg))
            .or_else(|| bounds::height_m(e.h))
            .or_else(|| {
                e.sigma_neu
                    .iter()
                    .any(|s| !(0.0..=1e5).contains(s))
                    .then(|| "a position sigma outside 0 .. 1e5 m".to_string())
            })
            .or_else(|| {
                e.v_ned
                    .is_some_and(|v| v.iter().any(|x| x.abs() > 1e4))
                    .then(|| "a velocity beyond ±1e4 m/s".to_string())
            })
            .or_else(|| {
                e.sigma_v_ne
                    .is_some_and(|s| s.iter().any(|x| !(0.0..=1e3).contains(x)))
                    .then(|| "a velocity sigma outside 0 .. 1e3 m/s".to_string())
            });
        if let Some(b) = bad {
            bail!("{}: {b}", at());
        }
        out.push(e);
    }
    if out.is_empty() {
        bail!("{}: no solution epochs", path.display());
    }
    Ok(out)
}
