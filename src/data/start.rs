//! The initial navigation state of a run: `--init` values, the truth row at the IMU start, or
//! `--init auto` (level at rest, heading by gyrocompassing or the GNSS course: [`crate::estimate::init`]).

use super::aid::{AidPlan, Outage};
use super::DataOptions;
use crate::io::imu_stream::ImuStream;
use crate::io::truth::{self, TruthLookup, TruthRow};
use crate::model::Model;
use crate::nav::attitude::dcm_from_euler;
use crate::nav::strapdown::NavState;
use anyhow::{bail, Context, Result};
use nalgebra::{Rotation3, UnitQuaternion, Vector3};

/// The start of a run: the state, with `--init auto` the 1-σ of its tilt and heading [rad],
/// and the IMU samples skipped to reach it.
pub(crate) struct Start {
    /// Initial navigation state.
    pub state: NavState,
    /// With `--init auto`: 1-σ of the found tilt and heading [rad].
    pub sigma: Option<(f64, f64)>,
    /// IMU samples read before the start and not filtered.
    pub skipped: u64,
}

/// `--init` values: lat, lon [deg], h [m], roll, pitch, yaw [deg][, vn, ve, vd m/s], each
/// inside its physical range.
const INIT_RANGES: [(&str, f64, f64, &str); 9] = [
    ("lat", -90.0, 90.0, "deg"),
    ("lon", -360.0, 360.0, "deg"),
    ("h", -1000.0, 50_000.0, "m"),
    ("roll", -180.0, 180.0, "deg"),
    ("pitch", -90.0, 90.0, "deg"),
    ("yaw", -360.0, 360.0, "deg"),
    ("vn", -1000.0, 1000.0, "m/s"),
    ("ve", -1000.0, 1000.0, "m/s"),
    ("vd", -1000.0, 1000.0, "m/s"),
];

/// The numbers of an `--init` text `lat,lon,h,roll,pitch,yaw[,vn,ve,vd]` (deg, m, deg, m/s),
/// each inside its physical range and the latitude off the poles; `auto` is not numbers.
pub fn init_numbers(text: &str) -> Result<Vec<f64>> {
    let v: Vec<f64> = text
        .split(',')
        .map(|x| x.trim().parse::<f64>())
        .collect::<std::result::Result<_, _>>()
        .map_err(|_| {
            anyhow::anyhow!(
                "--init `{}`: expected auto or lat,lon,h,roll,pitch,yaw[,vn,ve,vd] (numbers, deg, m, m/s)",
                crate::io::lines::shown(text)
            )
        })?;
    if v.len() != 6 && v.len() != 9 {
        bail!(
            "--init takes lat,lon,h,roll,pitch,yaw[,vn,ve,vd] (6 or 9 numbers), got {}",
            v.len()
        );
    }
    if let Some(why) = init_value_problem(&v) {
        bail!("--init: {why}");
    }
    Ok(v)
}

/// What is wrong with initial-state numbers `v` (lat, lon [deg], h [m], roll, pitch, yaw
/// [deg][, vn, ve, vd m/s]) in words (`lat = 95 is outside [-90, 90] deg`), or None: each
/// inside its physical range and the latitude off the poles — the bounds of `--init`, which
/// navigate's --lat --lon --h --att --vel share.
pub fn init_value_problem(v: &[f64]) -> Option<String> {
    for (x, (name, lo, hi, unit)) in v.iter().zip(INIT_RANGES) {
        if !(x.is_finite() && (lo..=hi).contains(x)) {
            return Some(format!(
                "{name} = {} is outside [{lo}, {hi}] {unit}",
                crate::io::units::shown_number(*x)
            ));
        }
    }
    if v.first().is_some_and(|lat| lat.abs() >= 89.9) {
        return Some(format!(
            "lat = {} is at a pole (|lat| < 89.9 deg): the navigation frame is not defined there",
            v[0]
        ));
    }
    None
}

/// The navigation state of checked `--init` numbers `v` ([`init_numbers`]) at time `t0` [s].
fn state_from_values(v: &[f64], t0: f64) -> NavState {
    let d = std::f64::consts::PI / 180.0;
    let c = dcm_from_euler(v[3] * d, v[4] * d, v[5] * d);
    NavState {
        t: t0,
        lat: v[0] * d,
        lon: v[1] * d,
        h: v[2],
        v: if v.len() == 9 {
            Vector3::new(v[6], v[7], v[8])
        } else {
            Vector3::zeros()
        },
        q: UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(c)),
    }
}

/// The truth row at the start of the first sample's interval: t0 on a uniform clock; on a
/// jittered one the first sample may span other than the median interval, so the row closest
/// to t0 within 2.5 intervals before the first sample is taken (and the run starts at its time).
fn state_from_truth(
    tr: &mut truth::TruthReader,
    path: &std::path::Path,
    imu: &ImuStream,
    t0: f64,
) -> Result<NavState> {
    let r = match tr.at(t0, 1e-6)? {
        Some(r) => r,
        None => {
            let mut scan = truth::TruthReader::open(path)?;
            let (lo, first) = (imu.first_t() - 2.5 * imu.interval(), imu.first_t());
            let mut best: Option<TruthRow> = None;
            while let Some(r) = scan.next_row()? {
                if r.t >= first - 1e-9 {
                    break;
                }
                if r.t >= lo && best.is_none_or(|b| (r.t - t0).abs() < (b.t - t0).abs()) {
                    best = Some(r);
                }
            }
            let r = best.with_context(|| {
                format!(
                    "no truth row at the IMU start ({t0:.6} s, or within 2.5 sample intervals before the first sample at {first:.6} s); give --init"
                )
            })?;
            // the lookups of the run start from there
            tr.at(r.t, 1e-6)?;
            r
        }
    };
    let c = dcm_from_euler(r.euler.x, r.euler.y, r.euler.z);
    Ok(NavState {
        t: r.t,
        lat: r.lat,
        lon: r.lon,
        h: r.h,
        v: r.v,
        q: UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(c)),
    })
}

impl DataOptions {
    /// The numbers of `--init` (None for `auto` or none given), checked.
    fn init_values(&self) -> Result<Option<Vec<f64>>> {
        match self.init.as_deref() {
            None | Some("auto") => Ok(None),
            Some(text) => init_numbers(text).map(Some),
        }
    }

    /// True with `--init auto`.
    pub(crate) fn init_auto(&self) -> bool {
        self.init.as_deref() == Some("auto")
    }

    /// The start of the run on `imu` (at its start time unless `--init auto` finds a later one,
    /// up to which the stream is then advanced); `note` hears what `--init auto` found.
    pub(crate) fn start(
        &self,
        imu: &mut ImuStream,
        plan: &AidPlan,
        outages: &[Outage],
        truth_reader: Option<&mut truth::TruthReader>,
        note: &mut dyn FnMut(&str),
    ) -> Result<Start> {
        let t0 = imu.start_time();
        let init_values = self.init_values()?;
        let auto = self.init_auto();
        if self.init_speed.is_some() && !auto {
            bail!("--init-speed applies to --init auto");
        }
        if auto {
            let found = self.auto_init(plan, outages)?;
            for line in &found.report {
                note(&format!("init auto: {line}"));
            }
            // the run starts after the start's sample
            let first_t = imu.first_t();
            let skipped = imu.skip_through(found.state.t + 1e-9)?;
            // the data's clock may be absolute (GPS seconds) while --outage counts from the
            // first sample: the start said both ways
            note(&format!(
                "init auto: the run starts at {} (--outage START counts from that sample){}",
                crate::io::aiding::time_from_first_sample(found.state.t, first_t),
                if skipped > 0 {
                    format!("; the {skipped} IMU samples before it are skipped")
                } else {
                    String::new()
                }
            ));
            return Ok(Start {
                state: found.state,
                sigma: Some((found.sigma_tilt, found.sigma_yaw)),
                skipped,
            });
        }
        let state = match (&init_values, truth_reader) {
            (Some(v), _) => state_from_values(v, t0),
            (None, Some(tr)) => {
                let p = self.truth.as_ref().expect("a truth reader has a path");
                state_from_truth(tr, p, imu, t0)?
            }
            (None, None) => bail!("give --init or --truth for the initial state"),
        };
        Ok(Start {
            state,
            sigma: None,
            skipped: 0,
        })
    }

    /// `--init auto`: reads the IMU file from its start (a second pass, memory bounded by
    /// quarter-second means) until [`init::find`] decides.
    fn auto_init(
        &self,
        plan: &AidPlan,
        outages: &[Outage],
    ) -> Result<crate::estimate::init::AutoInit> {
        use crate::estimate::init::{self, Blocks, Fix, Found, Priors};
        let speed = self.init_speed.unwrap_or(init::DEFAULT_SPEED);
        if !(speed.is_finite() && (0.5..=100.0).contains(&speed)) {
            bail!(
                "--init-speed {}: expected a speed in [0.5, 100] m/s",
                crate::io::units::shown_number(speed)
            );
        }
        // the bias priors the run will use (grade, --prior)
        let m = Model::parse("P28")?;
        let cfg = self.config(&m, true)?;
        let prior = |name: &str| m.index_of(name).map(|i| cfg.prior_sigma[i]);
        let priors = Priors {
            gyro_bias: prior("eps_x").context("P28 has eps_x")?,
            accel_bias: prior("nabla_x").context("P28 has nabla_x")?,
            speed,
            gyro_scale: prior("kg_33").context("P28 has kg_33")?,
        };
        // fixes inside a --outage are not used to start either
        let outside = |t: f64| !outages.iter().any(|o| o.contains(t));
        let (mut fixes, static_pos, receiver) = match plan {
            AidPlan::Fixes(list, _, _) => {
                let kept: Vec<_> = list.iter().filter(|(p, _)| outside(p.t)).collect();
                (
                    kept.iter()
                        .map(|(p, v)| Fix::from_aiding(p, v.as_ref()))
                        .collect::<Vec<_>>(),
                    None,
                    kept.iter().map(|(_, v)| v.is_some()).collect::<Vec<_>>(),
                )
            }
            AidPlan::Static { fix, .. } => {
                (Vec::new(), Some([fix.lat, fix.lon, fix.h]), Vec::new())
            }
        };
        init::check_velocities(&fixes, &receiver)?;
        init::velocities_from_positions(&mut fixes);
        let imu_path = self.imu.as_ref().context("--imu FILE is required")?;
        let (mut stream, _) = crate::io::imu_stream::ImuStream::open_with(
            imu_path,
            self.imu_format.as_deref(),
            self.clock_offset,
        )?;
        let dt = stream.interval();
        let mut blocks = Blocks::default();
        let mut next_look = 10.0;
        loop {
            let s = stream.next()?;
            if let Some(s) = &s {
                blocks.push(s, dt);
                if blocks.seconds() < next_look {
                    continue;
                }
                next_look = blocks.seconds() + 10.0;
            }
            match init::find(&blocks.blocks, &fixes, static_pos, priors, s.is_none())? {
                Found::Done(a) => return Ok(*a),
                Found::NeedMore if s.is_none() => {
                    let imu_span = match (blocks.blocks.first(), blocks.blocks.last()) {
                        (Some(a), Some(b)) => format!("{:.3} .. {:.3} s", a.t_start, b.t_end),
                        _ => "none".to_string(),
                    };
                    let fix_span = match (fixes.first(), fixes.last()) {
                        (Some(a), Some(b)) => format!("{:.3} .. {:.3} s", a.t, b.t),
                        _ => "none".to_string(),
                    };
                    bail!(
                        "--init auto: the IMU data end before a start is found (IMU {imu_span}, GNSS fixes {fix_span}: on the same clock?)"
                    )
                }
                Found::NeedMore => {}
            }
        }
    }
}
