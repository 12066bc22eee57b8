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

/// Days in month `m` (1–12) of year `y` (Gregorian; 0 for a month out of range).
pub fn days_in_month(y: i64, m: i64) -> i64 {
    let leap = (y % 4 == 0 && y % 100 != 0) || y % 400 == 0;
    match m {
        1 | 3 | 5 | 7 | 8 | 10 | 12 => 31,
        4 | 6 | 9 | 11 => 30,
        2 if leap => 29,
        2 => 28,
        _ => 0,
    }
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

/// Refuses a `.pos` whose column header (`%  UTC  latitude(deg) …`) says its times are not
/// GPST: RTKLIB writes UTC or JST (UTC+9) when its time-format option asks for them, and read
/// as GPST they would put every fix 18 s (or 9 h) early against the IMU. True when `header`
/// is the column header (it names GPST).
fn check_time_system(header: &str, file: &str, no: usize) -> Result<bool> {
    let mut words = header.split_whitespace();
    let (Some(first), rest) = (words.next(), words.collect::<Vec<_>>().join(" ")) else {
        return Ok(false);
    };
    if !(rest.contains("latitude") || rest.contains("ecef") || rest.contains("week")) {
        return Ok(false);
    }
    let upper = first.to_ascii_uppercase();
    let first = upper.as_str();
    match first {
        "GPST" => Ok(true),
        "UTC" | "JST" => bail!(
            "{file}:{no}: the solution's times are {first} (its column header), sinsmodel reads GPST: \
             read as GPST every fix would sit {} against the IMU. Write the solution in GPST \
             (RTKLIB's time system option; no `-u` in rnx2rtkp) or convert it (GPST = UTC + 18 s \
             since 2017-01-01{})",
            if first == "UTC" { "18 s early" } else { "9 h 18 s early" },
            if first == "JST" { "; JST = UTC + 9 h" } else { "" }
        ),
        other if other.chars().all(|c| c.is_ascii_alphabetic()) && other.len() <= 5 => bail!(
            "{file}:{no}: unknown time system `{other}` in the column header (expected GPST)"
        ),
        _ => Ok(false),
    }
}

/// What RTKLIB must be told to write latitude and longitude in degrees.
const ECEF_FIX: &str = "ECEF coordinates: output the solution in lat/lon/height (RTKLIB 'Solution format: Lat/Lon/Height', out-solformat=llh)";
/// What RTKLIB must be told to write decimal degrees.
const DMS_FIX: &str = "latitude and longitude in degrees, minutes and seconds (`40 05 47.856`): output them in decimal degrees (RTKLIB 'Lat/Lon format: ddd.ddddddd', out-degform=deg)";

/// Refuses a `.pos` whose column header says its positions are ECEF x/y/z or d-m-s latitude
/// and longitude: sinsmodel reads latitude and longitude in decimal degrees.
fn check_coordinates(header: &str, file: &str, no: usize) -> Result<()> {
    if header.contains("x-ecef") || header.contains("y-ecef") {
        bail!("{file}:{no}: {ECEF_FIX}");
    }
    if header.contains("latitude(d'\")") || header.contains("latitude(dms)") {
        bail!("{file}:{no}: {DMS_FIX}");
    }
    Ok(())
}

/// The same as [`check_coordinates`] from the values of a row `f` (a file without its header):
/// x, y, z of Earth's size (|r| 6300 to 6450 km), or whole degrees and minutes before the
/// seconds of latitude and of longitude.
fn not_lat_lon_deg(f: &[&str]) -> Option<&'static str> {
    let num = |k: usize| f.get(k).and_then(|x| x.parse::<f64>().ok());
    if let (Some(x), Some(y), Some(z)) = (num(2), num(3), num(4)) {
        let r = (x * x + y * y + z * z).sqrt();
        if (6.3e6..6.45e6).contains(&r) {
            return Some(ECEF_FIX);
        }
    }
    let whole = |k: usize, max: f64| {
        f.get(k).is_some_and(|x| {
            !x.contains(['.', 'e', 'E']) && x.parse::<f64>().is_ok_and(|v| v.abs() <= max)
        })
    };
    let seconds = |k: usize| num(k).is_some_and(|v| (0.0..60.0).contains(&v));
    (f.len() >= 17
        && whole(2, 90.0)
        && whole(3, 59.0)
        && seconds(4)
        && whole(5, 360.0)
        && whole(6, 59.0)
        && seconds(7))
    .then_some(DMS_FIX)
}

/// Reads a `.pos` file.
pub fn read(path: &Path) -> Result<Vec<PosEpoch>> {
    let mut lines = Lines::open(path, "RTKLIB solution")?;
    let mut out: Vec<PosEpoch> = Vec::new();
    let mut gpst_said = false;
    while let Some(line) = lines.next_line()? {
        let l = line.text.trim();
        if let Some(header) = l.strip_prefix('%') {
            gpst_said |= check_time_system(header, line.file, line.no)?;
            check_coordinates(header, line.file, line.no)?;
            continue;
        }
        if l.is_empty() {
            continue;
        }
        if out.is_empty() && !gpst_said {
            eprintln!(
                "warning: {}: no column header (`%  GPST  latitude(deg) …`) says the time system before the first fix (line {}): \
                 read as GPST; a UTC solution would put every fix 18 s early against the IMU (RTKLIB writes the header unless told not to)",
                line.file, line.no
            );
        }
        let (file, no) = (line.file, line.no);
        let at = || format!("{file}:{no}");
        let f: Vec<&str> = l.split_whitespace().collect();
        if f.len() < 14 {
            bail!("{}: expected at least 14 columns, found {}", at(), f.len());
        }
        if let Some(why) = not_lat_lon_deg(&f) {
            bail!("{}: {why}", at());
        }
        let date: Vec<i64> = f[0].split('/').filter_map(|x| x.parse().ok()).collect();
        let time: Vec<f64> = f[1].split(':').filter_map(|x| x.parse().ok()).collect();
        if date.len() != 3
            || time.len() != 3
            || !(1980..=2200).contains(&date[0])
            || date[2] > days_in_month(date[0], date[1])
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
