//! Error-state Kalman filter over any model (`P31`, `P28+kaq_x_xy`, …) running beside the
//! strapdown navigator.
//!
//! - Propagation every filter step (default 0.01 s): A(t) from the model at the navigation state
//!   with the step means of the model's regressors (accumulated from the measured increments:
//!   mean of squares, never square of means); Φ = I + A dt + A² dt²/2 (second-order series);
//!   P ← Φ P Φᵀ + diag(q) dt through the preset's generated sparse kernel (or the run-time sparse
//!   propagator for composed models); q: gyro ARW² on the attitude rows, accelerometer VRW² on
//!   the velocity rows, each term's random-walk density² on its row.
//! - Updates at the aiding epochs (at the first step end at or after the epoch): sequential
//!   scalar updates in Joseph form for `vel_ne` (and `pos_ne`, `pos_h`), innovations and their
//!   variance recorded.
//! - Open loop: errors estimated, never fed back (the paper's comparison). Closed loop: after each
//!   update attitude, velocity and position are corrected and every instrument term's estimate is
//!   moved into a correction applied to all later increments (per sample, with its regressor).

use crate::nav::attitude::{attitude_error, dcm_from_euler};
use crate::model::catalog::{Sensor, StateRef};
use crate::model::covariance::SparsePropagator;
use crate::nav::earth;
use crate::model::generated::common;
use crate::io::imu::ImuData;
use crate::model::Model;
use crate::nav::nav_point::NavPoint;
use crate::nav::strapdown::{NavState, Navigator, Vertical};
use crate::io::truth::TruthRow;
use nalgebra::{UnitQuaternion, Vector3};

/// Feedback mode.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    /// Estimate only.
    OpenLoop,
    /// Feed estimates back into the navigator and the sensor corrections.
    ClosedLoop,
}

/// Filter settings (SI units).
#[derive(Debug, Clone)]
pub struct FilterConfig {
    /// Filter step [s] (default 0.01).
    pub step_s: f64,
    /// Feedback mode.
    pub mode: Mode,
    /// Prior 1-σ of every state (defaults: the spec's priors).
    pub prior_sigma: Vec<f64>,
    /// Continuous process-noise density per state [SI²/s].
    pub q: Vec<f64>,
    /// Navigator vertical channel.
    pub vertical: Vertical,
    /// Keep the full covariance in every record (for NEES).
    pub keep_covariance: bool,
    /// Propagate P with dense nalgebra matrices instead of the sparse kernels (benchmark baseline).
    pub dense_reference: bool,
}

impl FilterConfig {
    /// Defaults for a model: 0.01 s step, open loop, the spec's priors, the spec's ARW/VRW and
    /// term random walks.
    pub fn new(model: &Model) -> FilterConfig {
        let n = model.n();
        let mut q = vec![0.0; n];
        for (i, s) in model.states.iter().enumerate() {
            q[i] = match *s {
                StateRef::Nav(k) if common::NAV_STATES[k].name.starts_with("phi_") => {
                    common::GYRO_ARW.powi(2)
                }
                StateRef::Nav(k) if common::NAV_STATES[k].name.starts_with("dv_") => {
                    common::ACCEL_VRW.powi(2)
                }
                StateRef::Nav(_) => 0.0,
                StateRef::Term(k) => common::TERMS[k].noise.powi(2),
            };
        }
        FilterConfig {
            step_s: 0.01,
            mode: Mode::OpenLoop,
            prior_sigma: (0..n).map(|i| model.prior_sigma(i)).collect(),
            q,
            vertical: if model.vertical {
                Vertical::Free
            } else {
                Vertical::Fixed
            },
            keep_covariance: false,
            dense_reference: false,
        }
    }

    /// Sets the white sensor noise used in q: ARW [rad/√s] and VRW [m/s/√s].
    pub fn with_sensor_noise(mut self, model: &Model, arw: f64, vrw: f64) -> FilterConfig {
        for (i, name) in model.names.iter().enumerate() {
            if name.starts_with("phi_") {
                self.q[i] = arw * arw;
            } else if name.starts_with("dv_") {
                self.q[i] = vrw * vrw;
            }
        }
        self
    }

    /// Overrides the prior σ of a state by name; false when the model lacks it.
    pub fn set_prior(&mut self, model: &Model, name: &str, sigma: f64) -> bool {
        match model.index_of(name) {
            Some(i) => {
                self.prior_sigma[i] = sigma;
                true
            }
            None => false,
        }
    }
}

/// One aiding epoch: velocity and/or position with their 1-σ.
#[derive(Debug, Clone, Copy)]
pub struct AidingEpoch {
    /// Time [s].
    pub t: f64,
    /// NED velocity [m/s] and its 1-σ per component.
    pub vel: Option<(Vector3<f64>, f64)>,
    /// Latitude [rad], longitude [rad], height [m] and 1-σ north, east, down [m].
    pub pos: Option<(f64, f64, f64, [f64; 3])>,
}

/// An innovation of one scalar measurement component.
#[derive(Debug, Clone, Copy)]
pub struct Innovation {
    /// Time [s].
    pub t: f64,
    /// Measurement name (`vel_ne`, `pos_ne`, `pos_h`).
    pub meas: &'static str,
    /// Component index within the measurement.
    pub component: usize,
    /// Innovation ν = z − H x⁻ (SI).
    pub nu: f64,
    /// Its predicted variance S = H P⁻ Hᵀ + R.
    pub s: f64,
}

/// The filter state after one update.
#[derive(Debug, Clone)]
pub struct Record {
    /// Time [s].
    pub t: f64,
    /// Estimated error state (open loop) or the total estimate incl. fed-back corrections of the
    /// instrument terms (closed loop), SI.
    pub x: Vec<f64>,
    /// 1-σ of each state.
    pub sigma: Vec<f64>,
    /// True attitude error of the navigator φ [rad] (with truth).
    pub phi_true: Option<Vector3<f64>>,
    /// Estimated φ̂ (open loop: the state; closed loop: 0 after feedback).
    pub phi_est: Vector3<f64>,
    /// Navigator position error north, east [m] (with truth).
    pub pos_err_ne: Option<[f64; 2]>,
    /// Navigation state at the epoch (before any feedback).
    pub nav: NavState,
    /// Full covariance (row-major) when `FilterConfig::keep_covariance`.
    pub cov: Option<Vec<f64>>,
}

/// What a filter run produces.
#[derive(Debug, Clone)]
pub struct FilterRun {
    /// State names.
    pub names: Vec<&'static str>,
    /// One record per update epoch.
    pub records: Vec<Record>,
    /// All innovations.
    pub innovations: Vec<Innovation>,
    /// Final navigation state.
    pub final_state: NavState,
}

enum Kernel {
    Preset(crate::model::catalog::PropagateFn),
    Runtime(SparsePropagator),
    Dense,
}

/// Runs navigator + filter over `imu` from `start`, updating at `aiding` epochs; `truth` (same
/// clock) gives the true attitude error in the records.
pub fn run(
    model: &Model,
    cfg: &FilterConfig,
    imu: &ImuData,
    start: NavState,
    aiding: &[AidingEpoch],
    truth: Option<&[TruthRow]>,
    progress: impl FnMut(f64),
) -> FilterRun {
    run_with(model, cfg, imu, start, aiding, truth, progress, &mut |_| {})
}

/// [`run`] with a callback after every IMU sample (e.g. to write a navigation row per epoch).
#[allow(clippy::too_many_arguments)]
pub fn run_with(
    model: &Model,
    cfg: &FilterConfig,
    imu: &ImuData,
    start: NavState,
    aiding: &[AidingEpoch],
    truth: Option<&[TruthRow]>,
    mut progress: impl FnMut(f64),
    on_sample: &mut dyn FnMut(&NavState),
) -> FilterRun {
    let n = model.n();
    let mut nav = Navigator::new(start, cfg.vertical);
    let mut x = vec![0.0; n];
    let mut p = vec![0.0; n * n];
    for i in 0..n {
        p[i * n + i] = cfg.prior_sigma[i].powi(2);
    }
    let kernel = match model.preset {
        _ if cfg.dense_reference => Kernel::Dense,
        Some(k) => Kernel::Preset(k.propagate),
        None => Kernel::Runtime(SparsePropagator::new(n, model.a_pattern())),
    };
    let pattern = model.a_pattern().to_vec();
    let mut a = vec![0.0; n * n];
    let mut acc = model.accumulator();
    let mut r_mean = vec![0.0; model.regressor_ids.len()];
    let mut f_sum = Vector3::zeros();
    let mut in_step = 0usize;
    let mut step_t0 = start.t;
    // closed-loop corrections per term (SI), and per-term regressor/sensor info
    let terms: Vec<(usize, usize)> = model
        .states
        .iter()
        .enumerate()
        .filter_map(|(i, s)| match *s {
            StateRef::Term(k) => Some((i, k)),
            StateRef::Nav(_) => None,
        })
        .collect();
    let mut correction = vec![0.0; n];
    let mut next_aid = 0usize;
    let mut records = Vec::new();
    let mut innovations = Vec::new();
    let mut truth_i = 0usize;
    let report = (imu.samples.len() / 200).max(1);
    let mut prev_t = start.t;
    let idx = |name: &str| model.index_of(name);
    let (i_phi, i_dv) = (
        [idx("phi_n"), idx("phi_e"), idx("phi_d")],
        [idx("dv_n"), idx("dv_e"), idx("dv_d")],
    );
    let (i_lat, i_lon, i_h) = (idx("dlat"), idx("dlon"), idx("dh"));
    let mut h_row = vec![0.0; n];
    let mut np = NavPoint::new(start.lat, start.h, start.v, &start.dcm(), &Vector3::zeros());
    let mut u = vec![0.0; n];
    for (k, smp) in imu.samples.iter().enumerate() {
        let dt = smp.t - prev_t;
        prev_t = smp.t;
        let (mut dth, mut dvel) = (smp.dtheta, smp.dv);
        if cfg.mode == Mode::ClosedLoop {
            let f_meas = dvel / dt;
            let w_meas = dth / dt;
            for &(i, t) in &terms {
                if correction[i] != 0.0 {
                    let info = &common::TERMS[t];
                    let r = common::regressor_value(info.regressor, &f_meas, &w_meas);
                    match info.sensor {
                        Sensor::Gyro => dth[info.axis] -= correction[i] * r * dt,
                        Sensor::Accel => dvel[info.axis] -= correction[i] * r * dt,
                    }
                }
            }
        }
        nav.step(&dth, &dvel, dt);
        nav.state.t = smp.t;
        on_sample(&nav.state);
        let inv_dt = 1.0 / dt;
        let (f_c, w_c) = (dvel * inv_dt, dth * inv_dt);
        acc.add(&f_c, &w_c);
        f_sum += f_c;
        in_step += 1;
        let step_dt = smp.t - step_t0;
        let aid_due = next_aid < aiding.len() && aiding[next_aid].t <= smp.t + 1e-9;
        if step_dt + 1e-9 < cfg.step_s && !aid_due && k + 1 < imu.samples.len() {
            continue;
        }
        // ---- propagation over the step
        let s = nav.state;
        let f_mean = f_sum / in_step as f64;
        np.update(s.lat, s.h, s.v, &s.dcm(), &f_mean);
        for &(i, j) in &pattern {
            a[i * n + j] = 0.0;
        }
        acc.mean_into(&mut r_mean);
        model.fill_a(&np, &r_mean, &mut a);
        match &kernel {
            Kernel::Preset(f) => f(&a, step_dt, &cfg.q, &mut p, &mut x),
            Kernel::Runtime(sp) => {
                sp.propagate_with_state(&a, step_dt, &cfg.q, &mut p, Some(&mut x))
            }
            Kernel::Dense => {
                // the whole step with dense matrices: Φ, Φ P Φᵀ + Q and Φ x
                let am = nalgebra::DMatrix::from_row_slice(n, n, &a);
                let pm = nalgebra::DMatrix::from_row_slice(n, n, &p);
                let out = crate::model::covariance::propagate_dense_with_state(
                    &am,
                    step_dt,
                    &cfg.q,
                    &pm,
                    Some(&mut x),
                );
                p.copy_from_slice(out.transpose().as_slice());
            }
        }
        acc.reset();
        f_sum = Vector3::zeros();
        in_step = 0;
        step_t0 = smp.t;
        // ---- updates
        while next_aid < aiding.len() && aiding[next_aid].t <= smp.t + 1e-9 {
            let ep = aiding[next_aid];
            next_aid += 1;
            let s = nav.state;
            let mut scalar =
                |meas: &'static str, comp: usize, z: f64, r: f64, hrow: &[(usize, f64)]| {
                    h_row.iter_mut().for_each(|v| *v = 0.0);
                    for &(j, v) in hrow {
                        h_row[j] = v;
                    }
                    if let Some((nu, sv)) = joseph_update(&mut x, &mut p, &h_row, z, r, &mut u) {
                        innovations.push(Innovation {
                            t: ep.t,
                            meas,
                            component: comp,
                            nu,
                            s: sv,
                        });
                    }
                };
            if let Some((v, sig)) = ep.vel {
                for c in 0..2 {
                    if let Some(j) = i_dv[c] {
                        scalar("vel_ne", c, s.v[c] - v[c], sig * sig, &[(j, 1.0)]);
                    }
                }
            }
            if let Some((lat, lon, h, sig)) = ep.pos {
                let rm = earth::radius_meridian(s.lat) + s.h;
                let rn = earth::radius_transverse(s.lat) + s.h;
                if let (Some(jl), Some(jo)) = (i_lat, i_lon) {
                    scalar("pos_ne", 0, (s.lat - lat) * rm, sig[0].powi(2), &[(jl, rm)]);
                    scalar(
                        "pos_ne",
                        1,
                        (s.lon - lon) * rn * s.lat.cos(),
                        sig[1].powi(2),
                        &[(jo, rn * s.lat.cos())],
                    );
                }
                if let Some(jh) = i_h {
                    scalar("pos_h", 0, s.h - h, sig[2].powi(2), &[(jh, 1.0)]);
                }
            }
            let truth_row = truth.and_then(|tr| {
                while truth_i + 1 < tr.len() && tr[truth_i].t < ep.t - 1e-6 {
                    truth_i += 1;
                }
                let row = tr[truth_i];
                ((row.t - ep.t).abs() < 0.5 * cfg.step_s).then_some(row)
            });
            let phi_true = truth_row.map(|row| {
                let c_true = dcm_from_euler(row.euler.x, row.euler.y, row.euler.z);
                attitude_error(&nav.state.dcm(), &c_true)
            });
            let pos_err_ne = truth_row.map(|row| {
                let s = nav.state;
                [
                    (s.lat - row.lat) * (earth::radius_meridian(row.lat) + row.h),
                    (s.lon - row.lon) * (earth::radius_transverse(row.lat) + row.h) * row.lat.cos(),
                ]
            });
            let phi_est = Vector3::new(
                i_phi[0].map(|j| x[j]).unwrap_or(0.0),
                i_phi[1].map(|j| x[j]).unwrap_or(0.0),
                i_phi[2].map(|j| x[j]).unwrap_or(0.0),
            );
            let mut xr = x.clone();
            for &(i, _) in &terms {
                xr[i] += correction[i];
            }
            records.push(Record {
                t: ep.t,
                x: xr,
                sigma: (0..n).map(|i| p[i * n + i].max(0.0).sqrt()).collect(),
                phi_true,
                phi_est,
                pos_err_ne,
                nav: nav.state,
                cov: cfg.keep_covariance.then(|| p.clone()),
            });
            if cfg.mode == Mode::ClosedLoop {
                feedback(
                    &mut nav,
                    &mut x,
                    &mut correction,
                    &terms,
                    i_phi,
                    i_dv,
                    i_lat,
                    i_lon,
                    i_h,
                );
            }
        }
        if k % report == 0 {
            progress(k as f64 / imu.samples.len() as f64);
        }
    }
    progress(1.0);
    FilterRun {
        names: model.names.clone(),
        records,
        innovations,
        final_state: nav.state,
    }
}

/// Scalar update in Joseph form: P ← (I − K h) P (I − K h)ᵀ + K r Kᵀ, expanded for a row h;
/// returns (ν, S), or None when S is not positive.
fn joseph_update(
    x: &mut [f64],
    p: &mut [f64],
    h: &[f64],
    z: f64,
    r: f64,
    u: &mut [f64],
) -> Option<(f64, f64)> {
    let n = x.len();
    let nz: Vec<usize> = (0..n).filter(|&j| h[j] != 0.0).collect();
    for i in 0..n {
        u[i] = nz.iter().map(|&j| p[i * n + j] * h[j]).sum();
    }
    let hph: f64 = nz.iter().map(|&j| h[j] * u[j]).sum();
    let s = hph + r;
    if s.is_nan() || s <= 0.0 {
        return None;
    }
    let nu = z - nz.iter().map(|&j| h[j] * x[j]).sum::<f64>();
    let k: Vec<f64> = u.iter().map(|v| v / s).collect();
    for i in 0..n {
        x[i] += k[i] * nu;
    }
    // (I − K h) P (I − K h)ᵀ + r K Kᵀ = P − K uᵀ − u Kᵀ + (h P hᵀ + r) K Kᵀ
    for i in 0..n {
        for j in 0..n {
            p[i * n + j] += -k[i] * u[j] - u[i] * k[j] + s * k[i] * k[j];
        }
    }
    for i in 0..n {
        for j in 0..i {
            let m = 0.5 * (p[i * n + j] + p[j * n + i]);
            p[i * n + j] = m;
            p[j * n + i] = m;
        }
    }
    Some((nu, s))
}

#[allow(clippy::too_many_arguments)]
fn feedback(
    nav: &mut Navigator,
    x: &mut [f64],
    correction: &mut [f64],
    terms: &[(usize, usize)],
    i_phi: [Option<usize>; 3],
    i_dv: [Option<usize>; 3],
    i_lat: Option<usize>,
    i_lon: Option<usize>,
    i_h: Option<usize>,
) {
    let take = |x: &mut [f64], i: Option<usize>| {
        i.map(|j| std::mem::replace(&mut x[j], 0.0)).unwrap_or(0.0)
    };
    let phi = Vector3::new(take(x, i_phi[0]), take(x, i_phi[1]), take(x, i_phi[2]));
    let s = &mut nav.state;
    // C~ = (I − [φ×]) C  ⇒  C = exp([φ×]) C~
    s.q = UnitQuaternion::from_scaled_axis(phi) * s.q;
    for (c, &i) in i_dv.iter().enumerate() {
        s.v[c] -= take(x, i);
    }
    s.lat -= take(x, i_lat);
    s.lon -= take(x, i_lon);
    s.h -= take(x, i_h);
    for &(i, _) in terms {
        correction[i] += x[i];
        x[i] = 0.0;
    }
}

/// Root-mean-square of the model error e = φ̂ − φ (north, east) over records with t in [t0, t1],
/// in arcseconds (the paper's metric, DESIGN §5).
pub fn model_error_rms_arcsec(run: &FilterRun, t0: f64, t1: f64) -> Option<[f64; 2]> {
    let mut sum = [0.0; 2];
    let mut k = 0usize;
    for r in run.records.iter().filter(|r| r.t >= t0 && r.t <= t1) {
        let pt = r.phi_true?;
        for c in 0..2 {
            sum[c] += (r.phi_est[c] - pt[c]).powi(2);
        }
        k += 1;
    }
    if k == 0 {
        return None;
    }
    let arcsec = 180.0 / std::f64::consts::PI * 3600.0;
    Some([
        (sum[0] / k as f64).sqrt() * arcsec,
        (sum[1] / k as f64).sqrt() * arcsec,
    ])
}
