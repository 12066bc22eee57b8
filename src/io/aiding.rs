//! Position aiding files (DESIGN §9, KF-GINS GNSS layout):
//! `t [s]  lat lon [deg]  h [m]  sigma_n sigma_e sigma_d [m]`, optionally followed by a velocity
//! set `v_n v_e v_d [m/s]  sigma_v [m/s]` (11 columns; every row the same width).

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

/// A velocity fix: NED velocity and its 1-σ per component.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VelocityFix {
    /// NED velocity [m/s].
    pub v_ned: [f64; 3],
    /// 1-σ of each component [m/s].
    pub sigma: f64,
}

/// Writes fixes atomically.
pub fn write(path: &Path, rows: &[PositionFix], header: &str) -> Result<()> {
    write_with_velocity(path, rows, None, header)
}

/// Writes fixes atomically, with a velocity per fix (11 columns: `… v_n v_e v_d sigma_v`) when
/// `velocities` is given (one per fix).
pub fn write_with_velocity(
    path: &Path,
    rows: &[PositionFix],
    velocities: Option<&[VelocityFix]>,
    header: &str,
) -> Result<()> {
    if velocities.is_some_and(|v| v.len() != rows.len()) {
        anyhow::bail!("{}: one velocity per fix is needed", path.display());
    }
    let mut f = AtomicFile::create(path)?;
    let w = f.writer();
    for l in header.lines() {
        writeln!(w, "# {l}")?;
    }
    if velocities.is_some() {
        writeln!(
            w,
            "# t[s] lat lon [deg] h[m] sigma_n sigma_e sigma_d [m] v_n v_e v_d sigma_v [m/s]"
        )?;
    } else {
        writeln!(w, "# t[s] lat lon [deg] h[m] sigma_n sigma_e sigma_d [m]")?;
    }
    for (k, r) in rows.iter().enumerate() {
        // σ in shortest round-trip form: a σ of 1e-5 m must not be written as 0
        write!(
            w,
            "{:.4} {:.11} {:.11} {:.4} {} {} {}",
            r.t,
            r.lat.to_degrees(),
            // in [-180, 180): a crossing of 180° writes what the reader takes
            crate::io::bounds::written_lon_deg(r.lon.to_degrees()),
            r.h,
            r.sigma[0],
            r.sigma[1],
            r.sigma[2]
        )?;
        if let Some(v) = velocities.map(|v| &v[k]) {
            write!(
                w,
                " {:.6} {:.6} {:.6} {}",
                v.v_ned[0], v.v_ned[1], v.v_ned[2], v.sigma
            )?;
        }
        writeln!(w)?;
    }
    f.commit()
}

/// Reads a position aiding file; σ must be positive, time increasing.
pub fn read(path: &Path) -> Result<Vec<PositionFix>> {
    Ok(read_with_velocity(path)?.into_iter().map(|f| f.0).collect())
}

/// Reads an aiding file of 7 columns (positions) or 11 (positions and velocities), the width
/// taken from its first data row; σ positive, time increasing, ranges checked.
pub fn read_with_velocity(path: &Path) -> Result<Vec<(PositionFix, Option<VelocityFix>)>> {
    let mut lines = crate::io::lines::Lines::open(path, "aiding file")?;
    let mut width = 7;
    while let Some(l) = lines.next_line()? {
        let t = l.text.trim();
        if t.is_empty() || t.starts_with('#') {
            continue;
        }
        let n = t
            .split(|c: char| c.is_whitespace() || c == ',')
            .filter(|s| !s.is_empty())
            .count();
        if n == 11 {
            width = 11;
        }
        break;
    }
    let rows = read_table(path, width, "aiding file")?;
    if rows.is_empty() {
        bail!("{}: the aiding file has no data rows", path.display());
    }
    rows.into_iter()
        .map(|(line, v)| {
            if v[4..7].iter().any(|s| !(*s >= 1e-6 && *s <= 1e5)) {
                bail!(
                    "{}:{line}: sigma must be in [1e-6, 1e5] m (got {}, {}, {})",
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
            let vel = if width == 11 {
                if v[7..10].iter().any(|x| x.abs() > 1e4) {
                    bail!("{}:{line}: a velocity beyond ±1e4 m/s", path.display());
                }
                if !(v[10] >= 1e-6 && v[10] <= 1e3) {
                    bail!(
                        "{}:{line}: velocity sigma must be in [1e-6, 1e3] m/s (got {})",
                        path.display(),
                        v[10]
                    );
                }
                Some(VelocityFix {
                    v_ned: [v[7], v[8], v[9]],
                    sigma: v[10],
                })
            } else {
                None
            };
            Ok((
                PositionFix {
                    t: v[0],
                    lat: v[1].to_radians(),
                    lon: v[2].to_radians(),
                    h: v[3],
                    sigma: [v[4], v[5], v[6]],
                },
                vel,
            ))
        })
        .collect()
}

/// A GNSS outage window on the data's clock [s].
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct Outage {
    /// First second without aiding, on the data's clock [s].
    pub start_s: f64,
    /// End of the window [s].
    pub end_s: f64,
}

impl Outage {
    /// Whether time `t` [s] falls in the window [start, end).
    pub fn contains(&self, t: f64) -> bool {
        t >= self.start_s && t < self.end_s
    }

    /// The window in words, counted from the first IMU sample (`first_t` [s]) as `--outage`
    /// takes it, and on the data's clock when that is not the same.
    pub fn words(&self, first_t: f64) -> String {
        let rel = format!(
            "{:.3} .. {:.3} s from the first IMU sample",
            self.start_s - first_t,
            self.end_s - first_t
        );
        if first_t == 0.0 {
            rel
        } else {
            format!(
                "{rel} (t = {:.3} .. {:.3} s on the data's clock)",
                self.start_s, self.end_s
            )
        }
    }
}

/// A time `t` [s] on the data's clock in words: seconds from the first IMU sample (`first_t`),
/// as `--outage` counts, and on the data's clock (absolute GPS seconds, say) when that differs.
pub fn time_from_first_sample(t: f64, first_t: f64) -> String {
    let d = t - first_t;
    let rel = if d < -0.0005 {
        format!("{:.3} s before the first IMU sample", -d)
    } else {
        format!("{:.3} s from the first IMU sample", d.abs())
    };
    if first_t == 0.0 {
        rel
    } else {
        format!("t = {t:.3} s on the data's clock = {rel}")
    }
}

/// A body-frame velocity from a reference (odometer with the non-holonomic constraint, DVL):
/// FRD velocity in the reference's frame and its 1-σ per component.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodyVelocityFix {
    /// Time on the IMU's clock [s].
    pub t: f64,
    /// Forward, right, down velocity [m/s].
    pub v_frd: [f64; 3],
    /// 1-σ of each component [m/s].
    pub sigma: f64,
}

/// Header line of a body-velocity reference file.
const BODY_VELOCITY_COLUMNS: &str = "t[s] v_x v_y v_z (forward right down) [m/s] sigma [m/s]";

/// Writes body-frame velocities atomically: `t vx vy vz sigma` per row.
pub fn write_body_velocity(path: &Path, rows: &[BodyVelocityFix], header: &str) -> Result<()> {
    let mut f = AtomicFile::create(path)?;
    let w = f.writer();
    for l in header.lines() {
        writeln!(w, "# {l}")?;
    }
    writeln!(w, "# {BODY_VELOCITY_COLUMNS}")?;
    for r in rows {
        writeln!(
            w,
            "{:.4} {:.6} {:.6} {:.6} {}",
            r.t, r.v_frd[0], r.v_frd[1], r.v_frd[2], r.sigma
        )?;
    }
    f.commit()
}

/// Largest speed a reference row may give [m/s] (a vehicle or vessel; beyond it a unit slip).
const MAX_REFERENCE_SPEED: f64 = 300.0;

/// Reads a body-velocity reference file (`t vx vy vz sigma`: s, FRD m/s, m/s): time strictly
/// increasing, speeds within ±300 m/s, σ in [0.001, 2] m/s; each error names the line and the
/// likely slip.
pub fn read_body_velocity(path: &Path) -> Result<Vec<BodyVelocityFix>> {
    let rows = read_table(path, 5, "body-velocity reference file").map_err(|e| {
        // a GNSS aiding file given here is the likeliest slip
        if e.to_string().contains("found 6") {
            e.context(format!(
                "{}: 6 columns is the layout of an attitude reference (--attitude: t roll pitch yaw sigma_tilt sigma_yaw); --body-velocity takes `t vx vy vz sigma` in the body frame",
                path.display()
            ))
        } else if e.to_string().contains("found 7") || e.to_string().contains("found 11") {
            e.context(format!(
                "{}: 7 or 11 columns is the layout of a position aiding file (--aid); --body-velocity takes `t vx vy vz sigma` in the body frame",
                path.display()
            ))
        } else {
            e
        }
    })?;
    if rows.is_empty() {
        bail!(
            "{}: the body-velocity reference file has no data rows ({BODY_VELOCITY_COLUMNS})",
            path.display()
        );
    }
    let mut out: Vec<BodyVelocityFix> = Vec::with_capacity(rows.len());
    for (line, v) in rows {
        let at = format!("{}:{line}", path.display());
        check_after(&at, v[0], out.last().map(|r| r.t))?;
        if v[1..4].iter().any(|x| x.abs() > MAX_REFERENCE_SPEED) {
            bail!(
                "{at}: a velocity component beyond ±{MAX_REFERENCE_SPEED} m/s ({}, {}, {}): km/h or mm/s written as m/s?",
                v[1],
                v[2],
                v[3]
            );
        }
        if !(1e-3..=2.0).contains(&v[4]) {
            bail!(
                "{at}: sigma {} must be in [0.001, 2] m/s (an odometer or DVL is not better than 1 mm/s, and one worse than 2 m/s carries nothing; cm/s or mm/s written as m/s?)",
                v[4]
            );
        }
        out.push(BodyVelocityFix {
            t: v[0],
            v_frd: [v[1], v[2], v[3]],
            sigma: v[4],
        });
    }
    Ok(out)
}

/// A reference row's time `t` [s] must follow the previous row's `prev` (`at`: file and line).
fn check_after(at: &str, t: f64, prev: Option<f64>) -> Result<()> {
    match prev {
        Some(p) if t <= p => bail!(
            "{at}: time {t} s is not after the previous row's {p} s (rows must be in time order, each time once)"
        ),
        _ => Ok(()),
    }
}

/// An attitude from a reference (a second INS, an AHRS): the roll, pitch and yaw of its own
/// frame (FRD) against NED, and the 1-σ of its tilt and of its yaw.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AttitudeFix {
    /// Time on the IMU's clock [s].
    pub t: f64,
    /// Roll, pitch, yaw (z-y-x Euler angles of C_r^n) [rad].
    pub rpy: [f64; 3],
    /// 1-σ of roll and pitch [rad].
    pub sigma_tilt: f64,
    /// 1-σ of yaw [rad].
    pub sigma_yaw: f64,
}

/// Header line of an attitude reference file.
const ATTITUDE_COLUMNS: &str =
    "t[s] roll pitch yaw [deg] (the reference's FRD frame against NED) sigma_tilt sigma_yaw [deg]";

/// Writes reference attitudes atomically: `t roll pitch yaw sigma_tilt sigma_yaw` per row, angles
/// in degrees.
pub fn write_attitude(path: &Path, rows: &[AttitudeFix], header: &str) -> Result<()> {
    let mut f = AtomicFile::create(path)?;
    let w = f.writer();
    for l in header.lines() {
        writeln!(w, "# {l}")?;
    }
    writeln!(w, "# {ATTITUDE_COLUMNS}")?;
    for r in rows {
        let d = |x: f64| x.to_degrees();
        writeln!(
            w,
            "{:.4} {:.6} {:.6} {:.6} {} {}",
            r.t,
            d(r.rpy[0]),
            d(r.rpy[1]),
            d(r.rpy[2]),
            d(r.sigma_tilt),
            d(r.sigma_yaw)
        )?;
    }
    f.commit()
}

/// Reads an attitude reference file (`t roll pitch yaw sigma_tilt sigma_yaw`: s, then degrees):
/// time strictly increasing, roll within ±180°, pitch within ±90°, yaw within −180…360°, each σ
/// in [0.001, 10]°; each error names the line and the likely slip. Angles are returned in rad.
pub fn read_attitude(path: &Path) -> Result<Vec<AttitudeFix>> {
    let rows = read_table(path, 6, "attitude reference file").map_err(|e| {
        if e.to_string().contains("found 5") {
            e.context(format!(
                "{}: 5 columns is the layout of a body-velocity reference (--body-velocity); --attitude takes `t roll pitch yaw sigma_tilt sigma_yaw` in degrees",
                path.display()
            ))
        } else {
            e
        }
    })?;
    if rows.is_empty() {
        bail!(
            "{}: the attitude reference file has no data rows ({ATTITUDE_COLUMNS})",
            path.display()
        );
    }
    let mut out: Vec<AttitudeFix> = Vec::with_capacity(rows.len());
    for (line, v) in rows {
        let at = format!("{}:{line}", path.display());
        check_after(&at, v[0], out.last().map(|r| r.t))?;
        let (roll, pitch, yaw) = (v[1], v[2], v[3]);
        if roll.abs() > 180.0 || pitch.abs() > 90.0 || !(-180.0..=360.0).contains(&yaw) {
            bail!(
                "{at}: roll {roll}, pitch {pitch}, yaw {yaw} deg: roll must be within ±180, pitch within ±90, yaw within -180..360 (angles are degrees; a pitch beyond 90 is a roll and pitch swapped, or another Euler order)"
            );
        }
        for (name, s) in [("sigma_tilt", v[4]), ("sigma_yaw", v[5])] {
            if !(0.001..=10.0).contains(&s) {
                bail!(
                    "{at}: {name} {s} must be in [0.001, 10] deg (degrees, not radians; a reference worse than 10 deg carries nothing)"
                );
            }
        }
        out.push(AttitudeFix {
            t: v[0],
            rpy: [roll.to_radians(), pitch.to_radians(), yaw.to_radians()],
            sigma_tilt: v[4].to_radians(),
            sigma_yaw: v[5].to_radians(),
        });
    }
    Ok(out)
}
