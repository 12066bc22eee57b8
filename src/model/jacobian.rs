//! The `jacobian` command: A and H of a model at one linearisation point given as JSON, for the
//! independent CasADi check (`tools/verify-jacobians`).

use crate::model::Model;
use crate::nav::attitude::dcm_from_euler;
use crate::nav::nav_point::NavPoint;
use anyhow::{bail, Context, Result};
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// A linearisation point as written in POINT.json (degrees only for angles at this edge).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PointSpec {
    /// Geodetic latitude [deg].
    pub lat_deg: f64,
    /// Height [m].
    pub h_m: f64,
    /// NED velocity [m/s].
    pub v_ned: [f64; 3],
    /// Roll, pitch, yaw [deg]; C_b^n = Rz(yaw)·Ry(pitch)·Rx(roll).
    pub euler_deg: [f64; 3],
    /// Specific force, FRD body [m/s²].
    pub f_b: [f64; 3],
    /// Angular rate, FRD body [rad/s].
    pub w_b: [f64; 3],
    /// Angular acceleration, FRD body [rad/s²] (regressors with `dw`; zero when absent).
    #[serde(default)]
    pub dw_b: [f64; 3],
    /// Rate of change of the specific force, FRD body [m/s³] (regressors with `df`; zero when
    /// absent).
    #[serde(default)]
    pub df_b: [f64; 3],
}

/// The JSON printed by `sinsmodel jacobian`.
#[derive(Debug, Clone, Serialize)]
pub struct JacobianOut {
    /// Model name.
    pub model: String,
    /// State names in order.
    pub states: Vec<&'static str>,
    /// Dense A, row-major rows.
    pub a: Vec<Vec<f64>>,
    /// Structural non-zeros of A as [row, col].
    pub pattern: Vec<[usize; 2]>,
    /// H of each measurement the model supports.
    pub h: BTreeMap<&'static str, Vec<Vec<f64>>>,
}

/// The points of a POINT.json text, as `sinsmodel jacobian --at` reads it.
#[derive(Debug, Clone)]
pub enum Points {
    /// A single JSON object: one point (the output is one object).
    One(PointSpec),
    /// A JSON array of objects (the output is an array).
    Many(Vec<PointSpec>),
}

/// Most linearisation points in one `--at` file.
pub const MAX_POINTS: usize = 10_000;

/// Reads POINT.json text: one point object, or an array of at most [`MAX_POINTS`]; errors name
/// the point.
pub fn parse_points(text: &str) -> Result<Points> {
    let value: serde_json::Value = serde_json::from_str(text).context("not valid JSON")?;
    Ok(match value {
        serde_json::Value::Array(items) if items.len() > MAX_POINTS => anyhow::bail!(
            "{} points, more than the {MAX_POINTS} one run takes (its output would be about {} MB): split the file",
            items.len(),
            items.len() / 120
        ),
        serde_json::Value::Array(items) => Points::Many(
            items
                .into_iter()
                .enumerate()
                .map(|(k, v)| serde_json::from_value(v).with_context(|| format!("point {k}")))
                .collect::<Result<_>>()?,
        ),
        v => Points::One(serde_json::from_value(v)?),
    })
}

impl PointSpec {
    /// Checks that every number is finite and within the physical ranges of [`crate::io::bounds`]
    /// (latitude inside ±90°, height ±1e5 m, attitude, velocity ±1e4 m/s, specific force
    /// ±1e4 m/s², angular rate ±1e3 rad/s), so that A and H are finite.
    pub fn validate(&self) -> Result<()> {
        let all = [self.lat_deg, self.h_m]
            .into_iter()
            .chain(self.v_ned)
            .chain(self.euler_deg)
            .chain(self.f_b)
            .chain(self.w_b)
            .chain(self.dw_b)
            .chain(self.df_b);
        if all.into_iter().any(|v| !v.is_finite()) {
            bail!("point has a non-finite number");
        }
        if self.lat_deg.abs() >= 90.0 {
            bail!("lat_deg = {} is outside (-90, 90)", self.lat_deg);
        }
        use crate::io::bounds;
        let problems = [
            bounds::height_m(self.h_m).map(|p| format!("h_m: {p}")),
            bounds::attitude_deg(self.euler_deg).map(|p| format!("euler_deg: {p}")),
            bounds::velocity_mps(self.v_ned).map(|p| format!("v_ned: {p}")),
            bounds::specific_force_mps2(self.f_b).map(|p| format!("f_b: {p}")),
            bounds::angular_rate_rps(self.w_b).map(|p| format!("w_b: {p}")),
            bounds::angular_accel_rps2(self.dw_b).map(|p| format!("dw_b: {p}")),
            bounds::jerk_mps3(self.df_b).map(|p| format!("df_b: {p}")),
        ];
        if let Some(p) = problems.into_iter().flatten().next() {
            bail!("point: {p}");
        }
        Ok(())
    }

    /// The navigation point (radii frozen at this latitude and height).
    pub fn nav_point(&self) -> NavPoint {
        let d = std::f64::consts::PI / 180.0;
        let c = dcm_from_euler(
            self.euler_deg[0] * d,
            self.euler_deg[1] * d,
            self.euler_deg[2] * d,
        );
        let mut np = NavPoint::new(
            self.lat_deg * d,
            self.h_m,
            Vector3::from(self.v_ned),
            &c,
            &Vector3::from(self.f_b),
        );
        np.set_rate(&Vector3::from(self.w_b));
        // dv/dt of the navigation equations at the point: C f + g − (2 ω_ie + ω_en) × v
        let (lat, h, v) = (self.lat_deg * d, self.h_m, Vector3::from(self.v_ned));
        let w_ie = crate::nav::earth::OMEGA * Vector3::new(lat.cos(), 0.0, -lat.sin());
        let w_en = Vector3::new(v.y / np.rn, -v.x / np.rm, -v.y * lat.tan() / np.rn);
        let g = Vector3::new(0.0, 0.0, crate::nav::earth::gravity(lat, h));
        let a = c * Vector3::from(self.f_b) + g - (2.0 * w_ie + w_en).cross(&v);
        np.set_acceleration(&a);
        np.set_step_acceleration(&a);
        np
    }
}

/// A and H of `model` at `point`, regressors evaluated at the single sample (f_b, w_b, dw_b, df_b).
pub fn jacobian(model: &Model, point: &PointSpec, runtime: bool) -> Result<JacobianOut> {
    point.validate()?;
    let nav = point.nav_point();
    let mut acc = model.accumulator();
    acc.add(&crate::model::ImuSignals {
        f: Vector3::from(point.f_b),
        w: Vector3::from(point.w_b),
        dw: Vector3::from(point.dw_b),
        df: Vector3::from(point.df_b),
    });
    let r = acc.mean();
    let n = model.n();
    let mut a = vec![0.0; n * n];
    if runtime {
        model.fill_a_runtime(&nav, &r, &mut a);
    } else {
        model.fill_a(&nav, &r, &mut a);
    }
    let mut h = BTreeMap::new();
    for m in model.measurements() {
        let mut hm = vec![0.0; m.rows.len() * n];
        let rows = if runtime {
            model.fill_h_runtime(m.name, &nav, &mut hm)
        } else {
            model.fill_h(m.name, &nav, &mut hm)
        }
        .with_context(|| format!("measurement {}", m.name))?;
        h.insert(
            m.name,
            hm.chunks(n).take(rows).map(<[f64]>::to_vec).collect(),
        );
    }
    Ok(JacobianOut {
        model: model.name.clone(),
        states: model.names.clone(),
        a: a.chunks(n).map(<[f64]>::to_vec).collect(),
        pattern: model.a_pattern().iter().map(|&(i, j)| [i, j]).collect(),
        h,
    })
}
