//! The aiding a run uses: GNSS fixes from a file (RTKLIB `.pos` or the aiding format) or a
//! static vehicle, the `--aid-use` choice, ZUPTs, and the GNSS outage windows.

use super::DataOptions;
use crate::estimate::filter::AidingEpoch;
use crate::io::aiding::{self, AttitudeFix, BodyVelocityFix, PositionFix, VelocityFix};
use anyhow::{bail, Result};
use nalgebra::Vector3;
use std::path::Path;

pub use crate::io::aiding::Outage;

/// Where the aiding epochs come from.
#[derive(Debug)]
pub enum AidPlan {
    /// Fixes from a file (with their velocities when the file has them and `--aid-use` takes
    /// them), with the ZUPT σ [m/s] to add to each and whether positions are used.
    Fixes(Vec<(PositionFix, Option<VelocityFix>)>, Option<f64>, bool),
    /// A static vehicle: this fix every whole second from `first_s`, with a ZUPT σ [m/s].
    Static {
        /// The position (its `t` unused).
        fix: PositionFix,
        /// Time of the first epoch [s].
        first_s: f64,
        /// Zero-velocity σ [m/s].
        zupt: Option<f64>,
    },
}

impl AidPlan {
    /// Only the epochs after `t0`.
    pub(crate) fn after(self, t0: f64) -> AidPlan {
        match self {
            AidPlan::Fixes(f, z, p) => {
                AidPlan::Fixes(f.into_iter().filter(|f| f.0.t > t0).collect(), z, p)
            }
            s => s,
        }
    }

    /// True when no epoch comes from a file (a static plan, or a file's epochs all before the
    /// start).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Number of epochs from a file (0 for the endless static plan).
    pub fn len(&self) -> usize {
        match self {
            AidPlan::Fixes(f, _, _) => f.len(),
            AidPlan::Static { .. } => 0,
        }
    }

    /// The epochs in time order without those inside any outage window.
    pub fn epochs_outside<'a>(
        &'a self,
        outages: &'a [Outage],
    ) -> Box<dyn Iterator<Item = AidingEpoch> + 'a> {
        Box::new(
            self.epochs()
                .filter(move |e| !outages.iter().any(|o| o.contains(e.t))),
        )
    }

    /// The epochs in time order (endless for a static vehicle: the run ends with the IMU data).
    pub fn epochs(&self) -> Box<dyn Iterator<Item = AidingEpoch> + '_> {
        let epoch = |f: &PositionFix, t: f64, zupt: Option<f64>| AidingEpoch {
            t,
            vel: zupt.map(|s| (Vector3::zeros(), s)),
            pos: Some((f.lat, f.lon, f.h, f.sigma)),
            body_vel: None,
            att: None,
        };
        match self {
            AidPlan::Fixes(f, zupt, use_pos) => Box::new(f.iter().map(move |(p, v)| {
                let mut e = epoch(p, p.t, *zupt);
                if let Some(v) = v {
                    e.vel = Some((Vector3::from(v.v_ned), v.sigma));
                }
                if !*use_pos {
                    e.pos = None;
                }
                e
            })),
            AidPlan::Static { fix, first_s, zupt } => {
                Box::new((0u64..).map(move |k| epoch(fix, first_s + k as f64, *zupt)))
            }
        }
    }
}

/// At least 10 aiding epochs must have fallen inside the IMU data (t0, t_last]: `used` of
/// `total` (0: a static plan) did.
pub fn check_inside(used: usize, total: usize, t0: f64, t_last: f64) -> Result<()> {
    if used < 10 {
        bail!(
            "only {used}{} aiding epochs fall inside the IMU data ({t0:.3} to {t_last:.3} s); at least 10 are needed (the filter works on innovations)",
            if total > 0 { format!(" of {total}") } else { String::new() }
        );
    }
    Ok(())
}

/// RTKLIB's σ floors: north and east 2 cm, down 5 cm [m]; velocity 1 cm/s [m/s] (0.1 m/s when
/// the file gives none).
const RTKLIB_FLOOR_NED_M: [f64; 3] = [0.02, 0.02, 0.05];

/// The fixes of an RTKLIB `.pos` solution: positions in radians with RTKLIB's σ floored, and
/// velocities when the file has them.
fn fixes_from_rtklib(path: &Path) -> Result<Vec<(PositionFix, Option<VelocityFix>)>> {
    Ok(crate::io::readers::rtklib::read(path)?
        .iter()
        .map(|e| {
            (
                PositionFix {
                    t: e.t,
                    lat: e.lat_deg.to_radians(),
                    lon: e.lon_deg.to_radians(),
                    h: e.h,
                    sigma: [
                        e.sigma_neu[0].max(RTKLIB_FLOOR_NED_M[0]),
                        e.sigma_neu[1].max(RTKLIB_FLOOR_NED_M[1]),
                        e.sigma_neu[2].max(RTKLIB_FLOOR_NED_M[2]),
                    ],
                },
                e.v_ned.map(|v| VelocityFix {
                    v_ned: v,
                    // RTKLIB's velocity σ, floored at 1 cm/s
                    sigma: e
                        .sigma_v_ne
                        .map(|s| s[0].max(s[1]))
                        .unwrap_or(0.1)
                        .max(0.01),
                }),
            )
        })
        .collect())
}

impl DataOptions {
    /// The ZUPT σ [m/s]: `--zupt` (checked), or the spec's velocity σ for a static vehicle.
    fn zupt_sigma(&self) -> Result<Option<f64>> {
        if let Some(z) = self.zupt {
            if !(z.is_finite() && z > 0.0 && z < 100.0) {
                bail!(
                    "--zupt {}: expected a velocity σ in (0, 100) m/s",
                    crate::io::units::shown_number(z)
                );
            }
        }
        Ok(self.zupt.or(self
            .static_aid
            .as_ref()
            .map(|_| crate::model::measurement_sigma("vel_ne").unwrap_or(0.01))))
    }

    /// The fixes of the `--aid` file `p` as `--aid-use` takes them, with the ZUPT σ.
    fn file_plan(&self, p: &Path, zupt: Option<f64>) -> Result<AidPlan> {
        let fixes = if p.extension().is_some_and(|e| e == "pos") {
            fixes_from_rtklib(p)?
        } else {
            aiding::read_with_velocity(p)?
        };
        let has_vel = fixes.iter().any(|f| f.1.is_some());
        let (use_pos, use_vel) = match self.aid_use.as_deref() {
            None => (true, has_vel),
            Some("pos") => (true, false),
            Some("vel") => (false, true),
            Some("pos,vel") | Some("vel,pos") => (true, true),
            Some(o) => bail!(
                "--aid-use `{}`: expected pos, vel or pos,vel",
                crate::io::lines::shown(o)
            ),
        };
        if use_vel && !has_vel {
            bail!(
                "--aid-use {}: {} has no velocity columns (an RTKLIB .pos with vn ve vu, or an aiding file of 11 columns: t lat lon h sigma_n sigma_e sigma_d v_n v_e v_d sigma_v)",
                self.aid_use.as_deref().unwrap_or(""),
                p.display()
            );
        }
        if use_vel && self.zupt.is_some() {
            bail!("--zupt and GNSS velocity aiding both give the velocity: choose one (--aid-use pos keeps --zupt)");
        }
        // a known time offset re-stamps the fixes: the one stamped t is the trajectory at t + dt,
        // so the filter takes it there (exact to every order, where the H of dt_gnss is first
        // order in dt)
        let shift = self.gnss_delay_s()?.unwrap_or(0.0);
        let fixes = fixes
            .into_iter()
            .map(|(mut p, v)| {
                p.t += shift;
                (p, if use_vel { v } else { None })
            })
            .collect();
        Ok(AidPlan::Fixes(fixes, zupt, use_pos))
    }

    /// The aiding plan of `--aid` or `--static-aid` (a static plan's epochs start at the first
    /// whole second after `first_t` [s], the first IMU sample).
    pub fn aid_plan(&self, first_t: f64) -> Result<AidPlan> {
        let zupt = self.zupt_sigma()?;
        Ok(match (&self.aid, &self.static_aid) {
            (Some(p), None) => self.file_plan(p, zupt)?,
            (None, Some(v)) if v.len() == 3 => {
                use crate::io::bounds;
                if let Some(p) = bounds::lat_deg(v[0])
                    .or_else(|| bounds::lon_deg(v[1]))
                    .or_else(|| bounds::height_m(v[2]))
                {
                    bail!("--static-aid: {p}");
                }
                AidPlan::Static {
                    fix: PositionFix {
                        t: 0.0,
                        lat: v[0].to_radians(),
                        lon: v[1].to_radians(),
                        h: v[2],
                        sigma: [0.1, 0.1, 0.1],
                    },
                    first_s: first_t.floor() + 1.0,
                    zupt,
                }
            }
            (Some(_), Some(_)) => bail!("give --aid FILE or --static-aid LAT,LON,H, not both"),
            (None, Some(v)) => bail!(
                "--static-aid takes LAT,LON,H (3 numbers: deg, deg, m), got {}",
                v.len()
            ),
            (None, None) => bail!(
                "no aiding: give --aid FILE or --static-aid LAT,LON,H (the filter works on innovations)"
            ),
        })
    }

    /// The `--outage` windows on the data's clock (START counted from `first_t` [s], the first
    /// IMU sample), sorted; overlapping windows are refused.
    pub fn outages(&self, first_t: f64) -> Result<Vec<Outage>> {
        let mut outages = Vec::new();
        for o in &self.outage {
            let v: Vec<f64> = o
                .split(',')
                .map(|x| x.trim().parse::<f64>())
                .collect::<std::result::Result<_, _>>()
                .map_err(|_| {
                    anyhow::anyhow!(
                        "--outage `{}`: expected START,DURATION in seconds",
                        crate::io::lines::shown(o)
                    )
                })?;
            // a START on the data's clock (GPS seconds) where seconds from the first sample are meant
            if v.len() == 2 && first_t.abs() > 1e5 && (v[0] - first_t).abs() < 1e6 {
                bail!(
                    "--outage `{}`: START counts from the first IMU sample, not on the data's clock; {} looks like a time on that clock (the first sample is at {:.3} s), so START = {:.3} was probably meant",
                    crate::io::lines::shown(o),
                    v[0],
                    first_t,
                    v[0] - first_t
                );
            }
            if v.len() != 2
                || !v.iter().all(|x| x.is_finite())
                || v[0] < 0.0
                || v[1] <= 0.0
                || v[0] + v[1] > 1e7
            {
                bail!(
                    "--outage `{}`: expected START,DURATION in seconds (START >= 0 from the first IMU sample, DURATION > 0)",
                    crate::io::lines::shown(o)
                );
            }
            let start_s = first_t + v[0];
            outages.push(Outage {
                start_s,
                end_s: start_s + v[1],
            });
        }
        outages.sort_by(|a, b| a.start_s.total_cmp(&b.start_s));
        if let Some(w) = outages.windows(2).find(|w| w[1].start_s < w[0].end_s) {
            bail!(
                "--outage: the windows {} and {} overlap: give each outage once (one window from the first start to the last end)",
                w[0].words(first_t),
                w[1].words(first_t)
            );
        }
        Ok(outages)
    }
}

/// A reference's row that joins the aiding epochs: its time [s] and how it sets an epoch's field.
pub trait ReferenceRow {
    /// Time on the IMU's clock [s].
    fn t(&self) -> f64;
    /// Sets this row's field of epoch `e`.
    fn set(&self, e: &mut AidingEpoch);
}

impl ReferenceRow for BodyVelocityFix {
    fn t(&self) -> f64 {
        self.t
    }
    fn set(&self, e: &mut AidingEpoch) {
        e.body_vel = Some(Box::new((Vector3::from(self.v_frd), self.sigma)));
    }
}

impl ReferenceRow for AttitudeFix {
    fn t(&self) -> f64 {
        self.t
    }
    fn set(&self, e: &mut AidingEpoch) {
        e.att = Some(Box::new(*self));
    }
}

/// Aiding epochs in time order merged with a reference's rows (time order): a row at an epoch's
/// time (within 1 µs) joins that epoch, the others are epochs of their own.
pub struct WithRows<'a, I: Iterator<Item = AidingEpoch>, R: ReferenceRow> {
    epochs: std::iter::Peekable<I>,
    rows: &'a [R],
}

/// `epochs` (time order) with the body-velocity reference's rows `body` merged in ([`WithRows`]).
pub fn with_body_velocity<I: Iterator<Item = AidingEpoch>>(
    epochs: I,
    body: &[BodyVelocityFix],
) -> WithRows<'_, I, BodyVelocityFix> {
    with_rows(epochs, body)
}

/// `epochs` (time order) with a reference's rows merged in ([`WithRows`]).
pub fn with_rows<I: Iterator<Item = AidingEpoch>, R: ReferenceRow>(
    epochs: I,
    rows: &[R],
) -> WithRows<'_, I, R> {
    WithRows {
        epochs: epochs.peekable(),
        rows,
    }
}

/// Times closer than this are one epoch [s].
const SAME_EPOCH_S: f64 = 1e-6;

impl<I: Iterator<Item = AidingEpoch>, R: ReferenceRow> Iterator for WithRows<'_, I, R> {
    type Item = AidingEpoch;
    fn next(&mut self) -> Option<AidingEpoch> {
        match (self.epochs.peek().map(|e| e.t), self.rows.first()) {
            (None, None) => None,
            (Some(_), None) => self.epochs.next(),
            (Some(t), Some(b)) if t < b.t() - SAME_EPOCH_S => self.epochs.next(),
            (Some(t), Some(b)) if t <= b.t() + SAME_EPOCH_S => {
                let mut e = self.epochs.next()?;
                b.set(&mut e);
                self.rows = &self.rows[1..];
                Some(e)
            }
            (_, Some(b)) => {
                self.rows = &self.rows[1..];
                let mut e = AidingEpoch {
                    t: b.t(),
                    vel: None,
                    pos: None,
                    body_vel: None,
                    att: None,
                };
                b.set(&mut e);
                Some(e)
            }
        }
    }
}
