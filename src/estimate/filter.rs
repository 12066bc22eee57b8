//! Error-state Kalman filter over any model (`P31`, `P28+kaq_x_xy`, …) running beside the
//! strapdown navigator.
//!
//! - Propagation every filter step (default 0.01 s): A(t) from the model at the navigation state
//!   with the step means of the model's regressors (accumulated from the measured increments:
//!   mean of squares, never square of means); Φ = I + A dt + A² dt²/2 (second-order series);
//!   P ← Φ P Φᵀ + diag(q) dt through the preset's generated sparse kernel (or the run-time sparse
//!   propagator for composed models); q: gyro ARW² on the attitude rows, accelerometer VRW² on
//!   the velocity rows, each term's random-walk density² on its row.
//! - Updates at the aiding epochs (at the first step end at or after the epoch): for every
//!   measurement of `model-spec/measurements.toml` that the model supports and the epoch carries,
//!   the residual z (computed minus aiding, in the measurement's components) and the generated H
//!   at the navigation point ([`Model::fill_h`]); sequential scalar updates in Joseph form,
//!   innovations and their variance recorded.
//! - Open loop: errors estimated, never fed back (the paper's comparison). Closed loop: after each
//!   update attitude, velocity and position are corrected and every instrument term's estimate is
//!   moved into a correction applied to all later increments (per sample, with its regressor).

pub use super::nav_tape::{NavTape, StepSums};
use crate::io::imu::{ImuData, ImuSample};
use crate::io::truth::{TruthLookup, TruthRow, TruthSlice};
use crate::model::catalog::{AidRecord, Aiding, ResidualState, Sensor, StateRef, WhiteNoise};
use crate::model::covariance::SparsePropagator;
use crate::model::generated::common;
use crate::model::Model;
use crate::nav::attitude::{attitude_error, dcm_from_euler};
use crate::nav::earth;
use crate::nav::nav_point::NavPoint;
use crate::nav::strapdown::{NavState, Navigator, Vertical};
use nalgebra::{UnitQuaternion, Vector3};

/// Feedback mode.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    /// Estimate only.
    OpenLoop,
    /// Feed estimates back into the navigator and the sensor corrections.
    ClosedLoop,
}

impl Mode {
    /// The command line's word for the mode (`open`, `closed`).
    pub fn word(self) -> &'static str {
        match self {
            Mode::OpenLoop => "open",
            Mode::ClosedLoop => "closed",
        }
    }
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
    /// Known values of GNSS terms, applied in the residuals (z − H θ): (term index, value SI),
    /// e.g. the antenna lever arm [m] and the IMU–GNSS time offset [s] given on the command line.
    /// A term that is also a state of the model then estimates what is left.
    pub known_gnss: Vec<(usize, f64)>,
    /// Scales of the aiding's stated 1-σ per measurement (name, factor): the σ a fix states
    /// times the factor enters R (1 when absent).
    pub sigma_scale: Vec<(&'static str, f64)>,
    /// Innovation gate [number of √S]: a scalar update whose |ν| exceeds it is not applied and
    /// is kept in [`FilterRun::gated`] (None: every update applied; explain's passes take all,
    /// since a misfit is what they analyse).
    pub gate: Option<f64>,
}

impl FilterConfig {
    /// Defaults for a model: 0.01 s step, open loop, the spec's priors, the spec's ARW/VRW and
    /// term random walks.
    pub fn new(model: &Model) -> FilterConfig {
        let n = model.n();
        let mut q = vec![0.0; n];
        for (i, s) in model.states.iter().enumerate() {
            q[i] = match *s {
                StateRef::Nav(k) => match common::NAV_STATES[k].white_noise {
                    WhiteNoise::GyroArw => common::GYRO_ARW.powi(2),
                    WhiteNoise::AccelVrw => common::ACCEL_VRW.powi(2),
                    WhiteNoise::None => 0.0,
                },
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
            known_gnss: Vec::new(),
            sigma_scale: Vec::new(),
            gate: None,
        }
    }

    /// Multiplies the white sensor noise in q by `arw_scale` (gyro) and `vrw_scale`
    /// (accelerometer): the densities scale, q by their squares.
    pub fn scale_sensor_noise(&mut self, model: &Model, arw_scale: f64, vrw_scale: f64) {
        for (i, w) in white_noise_states(model) {
            self.q[i] *= match w {
                WhiteNoise::GyroArw => arw_scale * arw_scale,
                _ => vrw_scale * vrw_scale,
            };
        }
    }

    /// White sensor noise densities in q: (ARW [rad/√s], VRW [m/s/√s]) of the first attitude and
    /// velocity state (0 when the model has none).
    pub fn sensor_noise(&self, model: &Model) -> (f64, f64) {
        let first = |kind: WhiteNoise| {
            white_noise_states(model)
                .find(|&(_, w)| w == kind)
                .map_or(0.0, |(i, _)| self.q[i].sqrt())
        };
        (first(WhiteNoise::GyroArw), first(WhiteNoise::AccelVrw))
    }

    /// Bias random-walk densities in q: gyro [rad/s/√s] and accelerometer [m/s²/√s] of the
    /// first gyro and accelerometer bias state (0 when the model has none or states none).
    pub fn bias_random_walk(&self, model: &Model) -> (f64, f64) {
        let first = |gyro: bool| {
            bias_states(model)
                .find(|&(_, g)| g == gyro)
                .map_or(0.0, |(i, _)| self.q[i].sqrt())
        };
        (first(true), first(false))
    }

    /// Sets the bias random walk (bias instability) of the gyro [rad/s/√s] and accelerometer
    /// [m/s²/√s] constant-bias states in q.
    pub fn with_bias_random_walk(mut self, model: &Model, gyro: f64, accel: f64) -> FilterConfig {
        for (i, g) in bias_states(model) {
            self.q[i] = if g { gyro * gyro } else { accel * accel };
        }
        self
    }

    /// Multiplies the bias random-walk densities in q by `gyro_scale` and `accel_scale`.
    pub fn scale_bias_random_walk(&mut self, model: &Model, gyro_scale: f64, accel_scale: f64) {
        for (i, g) in bias_states(model) {
            let s = if g { gyro_scale } else { accel_scale };
            self.q[i] *= s * s;
        }
    }

    /// Sets the white sensor noise used in q: ARW [rad/√s] and VRW [m/s/√s].
    /// (which states each drives is the spec's `white_noise`).
    pub fn with_sensor_noise(mut self, model: &Model, arw: f64, vrw: f64) -> FilterConfig {
        for (i, w) in white_noise_states(model) {
            self.q[i] = match w {
                WhiteNoise::GyroArw => arw * arw,
                _ => vrw * vrw,
            };
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

/// The constant-bias states of `model` (the spec's `gyro bias` and `accel bias` groups) with
/// true for a gyro bias: the states a bias random walk (bias instability) drives.
fn bias_states(model: &Model) -> impl Iterator<Item = (usize, bool)> + '_ {
    model
        .states
        .iter()
        .enumerate()
        .filter_map(|(i, s)| match *s {
            StateRef::Term(k) => match common::TERMS[k].group {
                "gyro bias" => Some((i, true)),
                "accel bias" => Some((i, false)),
                _ => None,
            },
            StateRef::Nav(_) => None,
        })
}

/// The model's states driven by white sensor noise (spec `white_noise`): (model index, kind),
/// `WhiteNoise::None` left out.
fn white_noise_states(model: &Model) -> impl Iterator<Item = (usize, WhiteNoise)> + '_ {
    model
        .states
        .iter()
        .enumerate()
        .filter_map(|(i, s)| match *s {
            StateRef::Nav(k) => Some((i, common::NAV_STATES[k].white_noise)),
            StateRef::Term(_) => None,
        })
        .filter(|&(_, w)| w != WhiteNoise::None)
}

/// One aiding epoch: velocity and/or position with their 1-σ.
#[derive(Debug, Clone)]
pub struct AidingEpoch {
    /// Time [s].
    pub t: f64,
    /// NED velocity [m/s] and its 1-σ per component.
    pub vel: Option<(Vector3<f64>, f64)>,
    /// Latitude [rad], longitude [rad], height [m] and 1-σ north, east, down [m].
    pub pos: Option<(f64, f64, f64, [f64; 3])>,
    /// Body-frame (FRD) velocity from a reference (odometer, DVL) [m/s] and its 1-σ per
    /// component (boxed: most epochs of a run held in memory have none).
    pub body_vel: Option<Box<(Vector3<f64>, f64)>>,
    /// Attitude from a reference (a second INS, an AHRS), boxed as `body_vel` is.
    pub att: Option<Box<crate::io::aiding::AttitudeFix>>,
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
    /// Scalar updates whose innovation or its variance was not finite (skipped), and the time
    /// of the first: the filter diverged or was fed non-physical numbers.
    pub nonfinite_updates: usize,
    /// Time of the first non-finite update [s].
    pub first_nonfinite_t: Option<f64>,
    /// Why the run stopped early: the filter diverged (time, state, likely cause).
    pub diverged: Option<String>,
    /// Scalar updates the innovation gate ([`FilterConfig::gate`]) rejected: not applied, not in
    /// `innovations`.
    pub gated: Vec<Innovation>,
    /// Updates beyond the gate that were applied all the same, because the gate had rejected
    /// [`GATE_RUN`] epochs of that component in a row (a step in the fixes that stays, or a
    /// filter that is off: either way no outlier burst).
    pub gate_passed: usize,
    /// Each position epoch's horizontal residual z − H x⁻ before any of its components is
    /// applied: (t [s], [north, east] [m]) (an outage's drift against the first fix after it).
    pub pos_ne_prior: Vec<(f64, [f64; 2])>,
}

/// Epochs in a row the innovation gate rejects of one measurement component before it lets the
/// next through: outliers come alone or in short bursts (a 6-fix burst keeps 4 after the fix
/// check drops its ends); a longer run is a step that stays or a filter that is off, and a gate
/// would keep it off (on the shared MEMS drive a 10-σ gate without this limit rejected 20 % of
/// the updates, where 0.3 % lie beyond 10 σ without a gate).
pub const GATE_RUN: u32 = 5;

impl FilterRun {
    /// An error when the run cannot support an answer: non-finite updates or states, or no
    /// innovations at all.
    pub fn check(&self) -> Result<(), String> {
        if let Some(d) = &self.diverged {
            return Err(d.clone());
        }
        if self.nonfinite_updates > 0 {
            return Err(format!(
                "the filter diverged: {} of {} scalar updates were not finite (first at t = {:.3} s); check --init, --prior, --noise and the IMU values",
                self.nonfinite_updates,
                self.nonfinite_updates + self.innovations.len(),
                self.first_nonfinite_t.unwrap_or(f64::NAN)
            ));
        }
        if let Some(r) = self
            .records
            .iter()
            .find(|r| r.x.iter().chain(&r.sigma).any(|v| !v.is_finite()))
        {
            return Err(format!(
                "the filter diverged: non-finite state estimates or a negative variance at t = {:.3} s; check --init, --prior, --noise and the IMU values",
                r.t
            ));
        }
        if self.innovations.is_empty() {
            return Err("no aiding update fell inside the IMU data: nothing to test".into());
        }
        Ok(())
    }
}

/// Watches a filter run from inside: every IMU sample, every propagation step and every scalar
/// update with its gain. `explain` propagates candidate-term signatures through it.
pub trait Observer {
    /// One IMU sample as the filter uses it: specific force f [m/s²] and rate w [rad/s], FRD.
    fn sample(&mut self, _sig: &crate::model::ImuSignals) {}
    /// After the propagation over a step of `dt` [s] ending at `t`: the navigation point and the
    /// model's A (n×n row-major; non-zeros at `pattern`) used for it.
    fn step(&mut self, _t: f64, _dt: f64, _np: &NavPoint, _a: &[f64], _pattern: &[(usize, usize)]) {
    }
    /// At the start and after every IMU sample: the navigation state, and the error estimate x
    /// and covariance P (n×n row-major) as of the last propagation step or update.
    fn nav_sample(&mut self, _s: &NavState, _x: &[f64], _p: &[f64]) {}
    /// After every filter step of a pass over the samples ([`run_stream`]): why the pass should
    /// end here, if it should (it then ends as a diverged one does, with that reason: the run
    /// is cut short, and [`FilterRun::check`] says so). Replays are not stopped.
    fn stop(&self) -> Option<String> {
        None
    }
    /// In a replay ([`run_replay`]), instead of every `sample`: the sums over the step's samples,
    /// before the step's propagation.
    fn step_sums(&mut self, _sums: &StepSums<'_>) {}
    /// Every scalar measurement before the update takes it (applied, gated or not finite): its
    /// row `h`, residual z (computed − aiding, after the known GNSS terms) and 1-σ (after the
    /// configuration's σ scale), in the measurement's SI units.
    #[allow(clippy::too_many_arguments)]
    fn residual(
        &mut self,
        _t: f64,
        _meas: &'static str,
        _component: usize,
        _h: &[f64],
        _z: f64,
        _sigma: f64,
    ) {
    }
    /// Before a scalar update is applied: its row `h`, gain `k` = P⁻hᵀ/S, innovation ν and
    /// variance S, and which measurement component it is.
    #[allow(clippy::too_many_arguments)]
    fn scalar_update(
        &mut self,
        _t: f64,
        _meas: &'static str,
        _component: usize,
        _h: &[f64],
        _k: &[f64],
        _nu: f64,
        _s: f64,
    ) {
    }
}

/// An observer that watches nothing.
pub struct NoObserver;
impl Observer for NoObserver {}

/// Two observers watching one run, the first called first.
pub struct Tee<'a>(pub &'a mut dyn Observer, pub &'a mut dyn Observer);
impl Observer for Tee<'_> {
    fn sample(&mut self, sig: &crate::model::ImuSignals) {
        self.0.sample(sig);
        self.1.sample(sig);
    }
    fn step(&mut self, t: f64, dt: f64, np: &NavPoint, a: &[f64], pattern: &[(usize, usize)]) {
        self.0.step(t, dt, np, a, pattern);
        self.1.step(t, dt, np, a, pattern);
    }
    fn nav_sample(&mut self, s: &NavState, x: &[f64], p: &[f64]) {
        self.0.nav_sample(s, x, p);
        self.1.nav_sample(s, x, p);
    }
    fn stop(&self) -> Option<String> {
        self.0.stop().or_else(|| self.1.stop())
    }
    fn step_sums(&mut self, sums: &StepSums<'_>) {
        self.0.step_sums(sums);
        self.1.step_sums(sums);
    }
    fn residual(&mut self, t: f64, meas: &'static str, comp: usize, h: &[f64], z: f64, sigma: f64) {
        self.0.residual(t, meas, comp, h, z, sigma);
        self.1.residual(t, meas, comp, h, z, sigma);
    }
    fn scalar_update(
        &mut self,
        t: f64,
        meas: &'static str,
        comp: usize,
        h: &[f64],
        k: &[f64],
        nu: f64,
        s: f64,
    ) {
        self.0.scalar_update(t, meas, comp, h, k, nu, s);
        self.1.scalar_update(t, meas, comp, h, k, nu, s);
    }
}

enum Kernel {
    Preset(crate::model::catalog::PropagateFn),
    Runtime(Box<SparsePropagator>),
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

/// The residual z = computed − aiding of spec measurement `meas` at an epoch, in the
/// measurement's components and units, with each component's 1-σ; None when the epoch does not
/// carry the record that measurement is formed from. Both z and H come from the spec
/// (`residual` and `h` of each row in measurements.toml: `common::residual`, [`Model::fill_h`]);
/// `residual_matches_generated_h` (tests/filter.rs) checks that they agree to first order.
pub fn residual(meas: &str, s: &NavState, ep: &AidingEpoch) -> Option<(Vec<f64>, Vec<f64>)> {
    let m = common::MEASUREMENTS.iter().position(|x| x.name == meas)?;
    let info = &common::MEASUREMENTS[m];
    let mut aid = AidRecord::UNSET;
    match info.aiding {
        Aiding::Position => {
            let (lat, lon, h, sig) = ep.pos?;
            // the fix's longitude as the turn nearest the state's (across the antimeridian a
            // fix at −179.9° is 0.2° from a state at 179.9°, not 359.8°)
            // (a fix within half a turn is taken as it is, to the last bit)
            let lon = if (s.lon - lon).abs() <= std::f64::consts::PI {
                lon
            } else {
                s.lon - earth::lon_difference(s.lon, lon)
            };
            (aid.lat, aid.lon, aid.h) = (lat, lon, h);
            (aid.sigma_n, aid.sigma_e, aid.sigma_d) = (sig[0], sig[1], sig[2]);
        }
        Aiding::Velocity => {
            let (v, sig) = ep.vel?;
            (aid.vn, aid.ve, aid.vd, aid.sigma_v) = (v.x, v.y, v.z, sig);
        }
        Aiding::BodyVelocity => {
            let (v, sig) = **ep.body_vel.as_ref()?;
            (aid.vx, aid.vy, aid.vz, aid.sigma_b) = (v.x, v.y, v.z, sig);
        }
        Aiding::Attitude => {
            let a = ep.att.as_ref()?;
            let r = crate::nav::attitude::dcm_from_euler(a.rpy[0], a.rpy[1], a.rpy[2]);
            (aid.r11, aid.r12, aid.r13) = (r[(0, 0)], r[(0, 1)], r[(0, 2)]);
            (aid.r21, aid.r22, aid.r23) = (r[(1, 0)], r[(1, 1)], r[(1, 2)]);
            (aid.r31, aid.r32, aid.r33) = (r[(2, 0)], r[(2, 1)], r[(2, 2)]);
            (aid.sigma_tilt, aid.sigma_yaw) = (a.sigma_tilt, a.sigma_yaw);
        }
    }
    let c = s.dcm();
    let state = ResidualState {
        lat: s.lat,
        lon: s.lon,
        h: s.h,
        vn: s.v.x,
        ve: s.v.y,
        vd: s.v.z,
        rm: earth::radius_meridian(s.lat) + s.h,
        rn: earth::radius_transverse(s.lat) + s.h,
        c11: c[(0, 0)],
        c12: c[(0, 1)],
        c13: c[(0, 2)],
        c21: c[(1, 0)],
        c22: c[(1, 1)],
        c23: c[(1, 2)],
        c31: c[(2, 0)],
        c32: c[(2, 1)],
        c33: c[(2, 2)],
    };
    let k = info.rows.len();
    let (mut z, mut sigma) = (vec![0.0; k], vec![0.0; k]);
    common::residual(m, &state, &aid, &mut z, &mut sigma);
    Some((z, sigma))
}

/// The running filter: navigator, error state, covariance and the per-step buffers.
struct Engine<'a> {
    nonfinite: usize,
    first_nonfinite_t: Option<f64>,
    gated: Vec<Innovation>,
    /// Epochs in a row the gate rejected, per (measurement, component).
    gate_runs: Vec<(&'static str, usize, u32)>,
    /// (t [s], north and east pos_ne residual [m] before the epoch's updates).
    pos_ne_prior: Vec<(f64, [f64; 2])>,
    /// −10⁻⁹ σ₀² of each state: a variance below it is negative beyond round-off.
    neg_tol: Vec<f64>,
    /// Updates beyond the gate applied because the gate had rejected GATE_RUN epochs in a row.
    gate_passed: usize,
    model: &'a Model,
    cfg: &'a FilterConfig,
    n: usize,
    nav: Navigator,
    x: Vec<f64>,
    p: Vec<f64>,
    kernel: Kernel,
    a: Vec<f64>,
    acc: crate::model::RegressorAccumulator,
    /// Derivatives of the measured signals (regressors with `dw`, `df`).
    rates: crate::model::SignalRates,
    r_mean: Vec<f64>,
    f_sum: Vector3<f64>,
    /// Σ of the step's body rates [rad/s] (its mean is the point's w_b).
    w_sum: Vector3<f64>,
    /// The mechanisation's velocity over the last second, for the point's acceleration a_ned.
    accel: crate::nav::nav_point::AccelWindow,
    /// The velocity the mechanisation alone gives [m/s]: the start's plus every step's change,
    /// without the updates' corrections (whose jumps are not the vehicle's acceleration).
    mech_v: Vector3<f64>,
    in_step: usize,
    step_t0: f64,
    /// The solution's velocity at the start of the step [m/s] (for the step's acceleration).
    step_v0: Vector3<f64>,
    /// (model index, term index) of every instrument term.
    terms: Vec<(usize, usize)>,
    /// Model indices of the GNSS terms (they enter H; their closed-loop corrections apply to
    /// the residuals).
    gnss_terms: Vec<usize>,
    /// Closed-loop corrections per state (SI), applied to later increments.
    correction: Vec<f64>,
    np: NavPoint,
    /// Spec measurements this model supports: (name, number of components).
    meas: Vec<(&'static str, usize)>,
    h: Vec<f64>,
    u: Vec<f64>,
    k: Vec<f64>,
    i_phi: [Option<usize>; 3],
    i_dv: [Option<usize>; 3],
    i_pos: [Option<usize>; 3],
    innovations: Vec<Innovation>,
}

impl<'a> Engine<'a> {
    fn new(model: &'a Model, cfg: &'a FilterConfig, start: NavState) -> Engine<'a> {
        let n = model.n();
        let mut p = vec![0.0; n * n];
        for i in 0..n {
            p[i * n + i] = cfg.prior_sigma[i].powi(2);
        }
        let kernel = match model.preset {
            _ if cfg.dense_reference => Kernel::Dense,
            Some(k) => Kernel::Preset(k.propagate),
            None => Kernel::Runtime(Box::new(SparsePropagator::new(n, model.a_pattern()))),
        };
        let terms = model
            .states
            .iter()
            .enumerate()
            .filter_map(|(i, s)| match *s {
                StateRef::Term(k) => Some((i, k)),
                StateRef::Nav(_) => None,
            })
            .collect();
        let gnss_terms = model
            .states
            .iter()
            .enumerate()
            .filter_map(|(i, s)| match *s {
                StateRef::Term(k) if common::TERMS[k].sensor.enters_h() => Some(i),
                _ => None,
            })
            .collect();
        let meas: Vec<(&'static str, usize)> = model
            .measurements()
            .iter()
            .map(|m| (m.name, m.rows.len()))
            .collect();
        let max_rows = meas.iter().map(|m| m.1).max().unwrap_or(0);
        let idx = |name: &str| model.index_of(name);
        Engine {
            model,
            cfg,
            n,
            nav: Navigator::new(start, cfg.vertical),
            x: vec![0.0; n],
            p,
            kernel,
            a: vec![0.0; n * n],
            acc: model.accumulator(),
            rates: crate::model::SignalRates::default(),
            r_mean: vec![0.0; model.regressor_ids.len()],
            f_sum: Vector3::zeros(),
            w_sum: Vector3::zeros(),
            accel: crate::nav::nav_point::AccelWindow::default(),
            mech_v: start.v,
            in_step: 0,
            step_t0: start.t,
            step_v0: start.v,
            terms,
            gnss_terms,
            correction: vec![0.0; n],
            np: NavPoint::new(start.lat, start.h, start.v, &start.dcm(), &Vector3::zeros()),
            meas,
            h: vec![0.0; max_rows * n],
            u: vec![0.0; n],
            k: vec![0.0; n],
            i_phi: [idx("phi_n"), idx("phi_e"), idx("phi_d")],
            i_dv: [idx("dv_n"), idx("dv_e"), idx("dv_d")],
            i_pos: [idx("dlat"), idx("dlon"), idx("dh")],
            innovations: Vec::new(),
            nonfinite: 0,
            first_nonfinite_t: None,
            gated: Vec::new(),
            gate_runs: Vec::new(),
            pos_ne_prior: Vec::new(),
            gate_passed: 0,
            neg_tol: cfg.prior_sigma.iter().map(|s| -1e-9 * s.powi(2)).collect(),
        }
    }

    /// One IMU sample: closed-loop sensor corrections, strapdown step, regressor sums.
    fn navigate(&mut self, smp: &crate::io::imu::ImuSample, dt: f64, obs: &mut dyn Observer) {
        let (mut dth, mut dvel) = (smp.dtheta, smp.dv);
        let measured = self.rates.next(&(dvel / dt), &(dth / dt), dt);
        if self.cfg.mode == Mode::ClosedLoop {
            for &(i, t) in &self.terms {
                if self.correction[i] != 0.0 {
                    let info = &common::TERMS[t];
                    let r = common::regressor_value(info.regressor, &measured);
                    match info.sensor {
                        Sensor::Gyro => dth[info.axis] -= self.correction[i] * r * dt,
                        Sensor::Accel => dvel[info.axis] -= self.correction[i] * r * dt,
                        // a GNSS term's correction applies to the residuals (`update`)
                        Sensor::Gnss | Sensor::Reference | Sensor::Attitude => {}
                    }
                }
            }
        }
        self.nav.step(&dth, &dvel, dt);
        self.nav.state.t = smp.t;
        let inv_dt = 1.0 / dt;
        let (f_c, w_c) = (dvel * inv_dt, dth * inv_dt);
        // the corrected signals, with the measured ones' derivatives (a correction is a step's
        // constant; its change between samples is negligible beside the signals')
        let sig = crate::model::ImuSignals {
            f: f_c,
            w: w_c,
            ..measured
        };
        self.acc.add(&sig);
        obs.sample(&sig);
        self.f_sum += f_c;
        self.w_sum += w_c;
        self.in_step += 1;
    }

    /// The end of a step at `t` [s] (a sample's time): propagation, the divergence check, then
    /// every aiding epoch due, each updated, recorded and (closed loop) fed back. Returns why
    /// the run must stop, if it must.
    fn end_step<'t, I: Iterator<Item = AidingEpoch>>(
        &mut self,
        t: f64,
        aiding: &mut std::iter::Peekable<I>,
        mut truth: Option<&mut (dyn TruthLookup + 't)>,
        obs: &mut dyn Observer,
        out: &mut Records<'_>,
    ) -> anyhow::Result<Option<String>> {
        self.propagate(t, obs);
        if let Some(d) = self.step_divergence(t) {
            return Ok(Some(d));
        }
        while let Some(ep) = aiding.next_if(|a| a.t <= t + 1e-9) {
            self.update(&ep, obs);
            let rec = self.record(&ep, truth.as_deref_mut())?;
            if let Some(d) = self.divergence(&rec) {
                return Ok(Some(d));
            }
            (out.on_record)(&rec)?;
            if out.keep {
                out.all.push(rec);
            } else {
                *out.last = Some(rec);
            }
            if self.cfg.mode == Mode::ClosedLoop {
                self.feedback();
            }
        }
        Ok(None)
    }

    /// The run's result from its kept records and why it stopped early, if it did.
    fn finish(self, records: Vec<Record>, diverged: Option<String>) -> FilterRun {
        FilterRun {
            names: self.model.names.clone(),
            records,
            innovations: self.innovations,
            final_state: self.nav.state,
            nonfinite_updates: self.nonfinite,
            first_nonfinite_t: self.first_nonfinite_t,
            diverged,
            gated: self.gated,
            gate_passed: self.gate_passed,
            pos_ne_prior: self.pos_ne_prior,
        }
    }

    /// Propagates x and P over the step that ends now: A(t) at the navigation point with the
    /// step's regressor means, through the preset kernel, the run-time propagator or dense.
    fn propagate(&mut self, t: f64, obs: &mut dyn Observer) {
        let (n, s) = (self.n, self.nav.state);
        let step_dt = t - self.step_t0;
        let f_mean = self.f_sum / self.in_step as f64;
        self.np.update(s.lat, s.h, s.v, &s.dcm(), &f_mean);
        self.np.set_rate(&(self.w_sum / self.in_step as f64));
        self.mech_v += s.v - self.step_v0;
        self.np.set_acceleration(&self.accel.push(t, self.mech_v));
        if step_dt > 0.0 {
            self.np
                .set_step_acceleration(&((s.v - self.step_v0) / step_dt));
        }
        // (the run-time composition writes every entry of the pattern: nothing left to zero)
        if !self.model.fill_a_writes_whole_pattern() {
            for &(i, j) in self.model.a_pattern() {
                self.a[i * n + j] = 0.0;
            }
        }
        self.acc.mean_into(&mut self.r_mean);
        self.model.fill_a(&self.np, &self.r_mean, &mut self.a);
        let q = &self.cfg.q;
        match &mut self.kernel {
            Kernel::Preset(f) => f(&self.a, step_dt, q, &mut self.p, &mut self.x),
            Kernel::Runtime(sp) => {
                sp.propagate_with_state(&self.a, step_dt, q, &mut self.p, Some(&mut self.x))
            }
            Kernel::Dense => {
                // the whole step with dense matrices: Φ, Φ P Φᵀ + Q and Φ x
                let am = nalgebra::DMatrix::from_row_slice(n, n, &self.a);
                let pm = nalgebra::DMatrix::from_row_slice(n, n, &self.p);
                let out = crate::model::covariance::propagate_dense_with_state(
                    &am,
                    step_dt,
                    q,
                    &pm,
                    Some(&mut self.x),
                );
                self.p.copy_from_slice(out.transpose().as_slice());
            }
        }
        obs.step(t, step_dt, &self.np, &self.a, self.model.a_pattern());
        self.acc.reset();
        self.f_sum = Vector3::zeros();
        self.w_sum = Vector3::zeros();
        self.in_step = 0;
        self.step_t0 = t;
        self.step_v0 = s.v;
    }

    /// Sequential scalar updates for every spec measurement the epoch carries, with the
    /// generated H at the current navigation point.
    fn update(&mut self, ep: &AidingEpoch, obs: &mut dyn Observer) {
        let (n, s) = (self.n, self.nav.state);
        let f_ned = Vector3::from(self.np.f_ned);
        let c = s.dcm();
        let mut np = NavPoint::new(s.lat, s.h, s.v, &c, &(c.transpose() * f_ned));
        (np.w_b, np.a_ned, np.a_step) = (self.np.w_b, self.np.a_ned, self.np.a_step);
        // the epoch is applied at the first sample at or after its time: the navigation state
        // is taken back to the fix time (a GNSS fix between two IMU samples, a jittered clock)
        let s_fix = state_at(&s, ep.t, &f_ned);
        for &(name, rows) in &self.meas {
            let Some((mut z, mut sigma)) = residual(name, &s_fix, ep) else {
                continue;
            };
            if let Some(&(_, k)) = self.cfg.sigma_scale.iter().find(|x| x.0 == name) {
                sigma.iter_mut().for_each(|v| *v *= k);
            }
            // known GNSS terms (lever arm, time offset): z − H θ_known
            if !self.cfg.known_gnss.is_empty() {
                let mi = common::MEASUREMENTS
                    .iter()
                    .position(|x| x.name == name)
                    .expect("a spec measurement");
                let known = &self.cfg.known_gnss;
                common::measurement_entries(mi, &np, &mut |comp, state, v| {
                    for &(t, theta) in known {
                        if common::TERMS[t].name == state {
                            z[comp] -= v * theta;
                        }
                    }
                });
            }
            let h = &mut self.h[..rows * n];
            h.iter_mut().for_each(|v| *v = 0.0);
            self.model
                .fill_h(name, &np, h)
                .expect("the model supports the measurements it lists");
            // GNSS terms fed back (closed loop) are known values: z − H θ_fed
            for (comp, zc) in z.iter_mut().enumerate() {
                let h_row = &self.h[comp * n..(comp + 1) * n];
                *zc -= self
                    .gnss_terms
                    .iter()
                    .map(|&i| h_row[i] * self.correction[i])
                    .sum::<f64>();
            }
            // the horizontal position residual before any of its components is applied (an
            // outage's drift; the sequential update changes the east one after the north)
            if name == "pos_ne" && rows == 2 {
                let prior = |c: usize| {
                    let h_row = &self.h[c * n..(c + 1) * n];
                    z[c] - h_row.iter().zip(&self.x).map(|(h, x)| h * x).sum::<f64>()
                };
                self.pos_ne_prior.push((ep.t, [prior(0), prior(1)]));
            }
            for (comp, (&zc, &sc)) in z.iter().zip(&sigma).enumerate() {
                let h_row = &self.h[comp * n..(comp + 1) * n];
                obs.residual(ep.t, name, comp, h_row, zc, sc);
                if !(zc.is_finite() && sc.is_finite()) {
                    self.nonfinite += 1;
                    self.first_nonfinite_t.get_or_insert(ep.t);
                    continue;
                }
                let run = gate_run(&mut self.gate_runs, name, comp);
                let gate = match self.cfg.gate {
                    Some(g) if self.gate_runs[run].2 < GATE_RUN => g,
                    _ => f64::INFINITY,
                };
                let upd = joseph_update(
                    &mut self.x,
                    &mut self.p,
                    (h_row, zc, sc * sc),
                    gate,
                    &mut self.u,
                    &mut self.k,
                );
                let innovation = |nu, s| Innovation {
                    t: ep.t,
                    meas: name,
                    component: comp,
                    nu,
                    s,
                };
                match upd {
                    Scalar::Applied(nu, sv) => {
                        let g = self.cfg.gate.unwrap_or(f64::INFINITY);
                        if self.gate_runs[run].2 >= GATE_RUN && nu * nu > g * g * sv {
                            self.gate_passed += 1;
                        }
                        self.gate_runs[run].2 = 0;
                        obs.scalar_update(ep.t, name, comp, h_row, &self.k, nu, sv);
                        self.innovations.push(innovation(nu, sv));
                    }
                    Scalar::Gated(nu, sv) => {
                        self.gated.push(innovation(nu, sv));
                        self.gate_runs[run].2 += 1;
                    }
                    Scalar::NotFinite => {
                        self.nonfinite += 1;
                        self.first_nonfinite_t.get_or_insert(ep.t);
                    }
                }
            }
        }
    }

    /// The record of an update epoch: estimates, σ, and with truth the true φ and position error.
    fn record<'t>(
        &mut self,
        ep: &AidingEpoch,
        truth: Option<&mut (dyn TruthLookup + 't)>,
    ) -> anyhow::Result<Record> {
        let n = self.n;
        let truth_row = match truth {
            Some(tr) => tr.at(ep.t, 0.5 * self.cfg.step_s)?,
            None => None,
        };
        let s = self.nav.state;
        let phi_true = truth_row.map(|row| {
            let c_true = dcm_from_euler(row.euler.x, row.euler.y, row.euler.z);
            attitude_error(&s.dcm(), &c_true)
        });
        let pos_err_ne = truth_row.map(|row| {
            [
                (s.lat - row.lat) * (earth::radius_meridian(row.lat) + row.h),
                earth::lon_difference(s.lon, row.lon)
                    * (earth::radius_transverse(row.lat) + row.h)
                    * row.lat.cos(),
            ]
        });
        let x = &self.x;
        let phi_est = Vector3::new(
            self.i_phi[0].map(|j| x[j]).unwrap_or(0.0),
            self.i_phi[1].map(|j| x[j]).unwrap_or(0.0),
            self.i_phi[2].map(|j| x[j]).unwrap_or(0.0),
        );
        let mut xr = x.clone();
        for &(i, _) in &self.terms {
            xr[i] += self.correction[i];
        }
        Ok(Record {
            t: ep.t,
            x: xr,
            // a NaN variance, or one negative beyond round-off, is kept as NaN (never shown as
            // σ = 0): `FilterRun::check` then stops the run with the time it happened
            sigma: (0..n)
                .map(|i| {
                    let v = self.p[i * n + i];
                    let tol = 1e-9 * self.cfg.prior_sigma[i].powi(2);
                    if v.is_nan() || v < -tol {
                        f64::NAN
                    } else {
                        v.max(0.0).sqrt()
                    }
                })
                .collect(),
            phi_true,
            phi_est,
            pos_err_ne,
            nav: s,
            cov: self.cfg.keep_covariance.then(|| self.p.clone()),
        })
    }

    /// Why the filter cannot go on after the propagation step ending at `t`, if it cannot: a
    /// non-finite estimate or variance, or a variance negative beyond round-off (checked every
    /// step, so the time named is the step where it happened).
    fn step_divergence(&self, t: f64) -> Option<String> {
        let n = self.n;
        // a finite estimate and a finite variance not negative beyond round-off (a NaN fails
        // `>=`), tested for every state without a branch each; which one failed only then
        let good = |i: usize| {
            let v = self.p[i * n + i];
            self.x[i].is_finite() & (v < f64::INFINITY) & (v >= self.neg_tol[i])
        };
        if (0..n).fold(true, |ok, i| ok & good(i)) {
            return None;
        }
        let bad = (0..n).find(|&i| !good(i))?;
        let s = &self.nav.state;
        let nav_finite = [s.lat, s.lon, s.h, s.v.x, s.v.y, s.v.z]
            .iter()
            .all(|v| v.is_finite());
        Some(format!(
            "the filter diverged at t = {t:.3} s (propagation): the estimate or variance of state {} is not finite or negative beyond round-off (navigation state lat {:.6} deg, lon {:.6} deg, h {:.1} m, speed {:.3} m/s); likely cause: {}; check --init, --prior, --noise and the IMU values",
            self.model.names[bad],
            s.lat.to_degrees(),
            s.lon.to_degrees(),
            s.h,
            s.v.norm(),
            if nav_finite {
                "A(t) or the process noise out of scale (IMU values beyond the model's range, priors or --noise far too large)"
            } else {
                "the navigation itself diverged: IMU values, units or the initial state are not physical"
            }
        ))
    }

    /// Why the filter cannot go on after this epoch's updates, if it cannot: a scalar update
    /// whose innovation or variance S was not finite or S ≤ 0, or a non-finite estimate or
    /// variance (or one negative beyond round-off) in the record. Names the time, the navigation
    /// state and the likely cause.
    fn divergence(&self, rec: &Record) -> Option<String> {
        let s = &self.nav.state;
        let state = format!(
            "navigation state lat {:.6} deg, lon {:.6} deg, h {:.1} m, speed {:.3} m/s",
            s.lat.to_degrees(),
            s.lon.to_degrees(),
            s.h,
            s.v.norm()
        );
        let nav_finite = [s.lat, s.lon, s.h, s.v.x, s.v.y, s.v.z]
            .iter()
            .all(|v| v.is_finite());
        if self.nonfinite > 0 {
            let cause = if !nav_finite {
                "the navigation itself diverged: IMU values, units or the initial state are not physical"
            } else {
                "an innovation variance S = HPH' + R that is not positive and finite: a covariance that lost positive definiteness (priors or --noise out of scale for the data) or a measurement sigma of zero"
            };
            return Some(format!(
                "the filter diverged at t = {:.3} s: a scalar update was not finite or had S <= 0 ({state}); likely cause: {cause}; check --init, --prior, --noise and the IMU values",
                rec.t
            ));
        }
        let bad_x = rec.x.iter().position(|v| !v.is_finite());
        let bad_p = rec.sigma.iter().position(|v| !v.is_finite());
        if let Some(i) = bad_x.or(bad_p) {
            return Some(format!(
                "the filter diverged at t = {:.3} s: {} of state {} is {} ({state}); likely cause: {}; check --init, --prior, --noise and the IMU values",
                rec.t,
                if bad_x.is_some() { "the estimate" } else { "the variance" },
                self.model.names[i],
                if bad_x.is_some() { "not finite" } else { "not finite or negative beyond round-off" },
                if nav_finite {
                    "A(t) or the process noise out of scale (IMU values beyond the model's range, priors or --noise far too large)"
                } else {
                    "the navigation itself diverged: IMU values, units or the initial state are not physical"
                }
            ));
        }
        None
    }

    /// Closed loop: moves the navigation error estimates into the navigator and the instrument
    /// estimates into the sensor corrections; the error state restarts at zero.
    fn feedback(&mut self) {
        let x = &mut self.x;
        let mut take =
            |i: Option<usize>| i.map(|j| std::mem::replace(&mut x[j], 0.0)).unwrap_or(0.0);
        let phi = Vector3::new(
            take(self.i_phi[0]),
            take(self.i_phi[1]),
            take(self.i_phi[2]),
        );
        let dv = [take(self.i_dv[0]), take(self.i_dv[1]), take(self.i_dv[2])];
        let dpos = [
            take(self.i_pos[0]),
            take(self.i_pos[1]),
            take(self.i_pos[2]),
        ];
        let s = &mut self.nav.state;
        // C~ = (I − [φ×]) C  ⇒  C = exp([φ×]) C~
        s.q = UnitQuaternion::from_scaled_axis(phi) * s.q;
        s.v -= Vector3::from(dv);
        // (the step's acceleration is the navigation's, not the correction's jump)
        self.step_v0 -= Vector3::from(dv);
        s.lat -= dpos[0];
        s.lon -= dpos[1];
        s.h -= dpos[2];
        for &(i, _) in &self.terms {
            self.correction[i] += self.x[i];
            self.x[i] = 0.0;
        }
    }
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
    progress: impl FnMut(f64),
    on_sample: &mut dyn FnMut(&NavState),
) -> FilterRun {
    run_observed(
        model,
        cfg,
        imu,
        start,
        aiding,
        truth,
        progress,
        on_sample,
        &mut NoObserver,
    )
}

/// [`run_with`] with an [`Observer`] that sees every sample, step and scalar update.
#[allow(clippy::too_many_arguments)]
pub fn run_observed(
    model: &Model,
    cfg: &FilterConfig,
    imu: &ImuData,
    start: NavState,
    aiding: &[AidingEpoch],
    truth: Option<&[TruthRow]>,
    progress: impl FnMut(f64),
    on_sample: &mut dyn FnMut(&NavState),
    obs: &mut dyn Observer,
) -> FilterRun {
    let mut samples = SliceSamples {
        samples: &imu.samples,
        next: 0,
    };
    let mut truth = truth.map(TruthSlice::new);
    let mut stream = StreamIo {
        samples: &mut samples,
        aiding: &mut aiding.iter().cloned(),
        truth: truth.as_mut().map(|t| t as &mut dyn TruthLookup),
    };
    match run_stream(
        model,
        cfg,
        start,
        &mut stream,
        progress,
        on_sample,
        obs,
        &mut |_| Ok(()),
        true,
    ) {
        Ok(run) => run,
        // in-memory samples and truth rows are read without I/O: nothing can fail
        Err(e) => unreachable!("in-memory filter input failed: {e}"),
    }
}

/// IMU samples handed to the filter one at a time.
pub trait Samples {
    /// The next sample, or None at the end.
    fn next_sample(&mut self) -> anyhow::Result<Option<ImuSample>>;
    /// Fraction of the input read so far.
    fn fraction(&self) -> f64;
}

/// Samples in memory handed out one at a time.
pub struct SliceSamples<'a> {
    samples: &'a [ImuSample],
    next: usize,
}

impl<'a> SliceSamples<'a> {
    /// From the first sample.
    pub fn new(samples: &'a [ImuSample]) -> Self {
        SliceSamples { samples, next: 0 }
    }
}

impl Samples for SliceSamples<'_> {
    fn next_sample(&mut self) -> anyhow::Result<Option<ImuSample>> {
        let s = self.samples.get(self.next).copied();
        self.next += 1;
        Ok(s)
    }
    fn fraction(&self) -> f64 {
        self.next as f64 / self.samples.len().max(1) as f64
    }
}

impl Samples for crate::io::imu_stream::ImuStream {
    fn next_sample(&mut self) -> anyhow::Result<Option<ImuSample>> {
        self.next()
    }
    fn fraction(&self) -> f64 {
        crate::io::imu_stream::ImuStream::fraction(self)
    }
}

/// What a streamed filter run reads: samples, aiding epochs in time order, and truth.
pub struct StreamIo<'a> {
    /// IMU samples.
    pub samples: &'a mut dyn Samples,
    /// Aiding epochs in increasing time (may be endless: the run ends with the samples).
    pub aiding: &'a mut dyn Iterator<Item = AidingEpoch>,
    /// Truth rows for the records, when given.
    pub truth: Option<&'a mut dyn TruthLookup>,
}

/// The filter over streamed input: every record goes to `on_record` as it is made (and is kept in
/// the returned run only with `keep_records`; without, the last one only), so memory does not
/// grow with the input; a read
/// error of the input, or of `on_record`, ends the run with that error.
#[allow(clippy::too_many_arguments)]
pub fn run_stream(
    model: &Model,
    cfg: &FilterConfig,
    start: NavState,
    io: &mut StreamIo<'_>,
    mut progress: impl FnMut(f64),
    on_sample: &mut dyn FnMut(&NavState),
    obs: &mut dyn Observer,
    on_record: &mut dyn FnMut(&Record) -> anyhow::Result<()>,
    keep_records: bool,
) -> anyhow::Result<FilterRun> {
    let mut e = Engine::new(model, cfg, start);
    let mut aiding = io.aiding.peekable();
    let mut records = Vec::new();
    let mut last = None;
    let mut prev_t = start.t;
    let mut k = 0u64;
    let mut next = io.samples.next_sample()?;
    // a run that starts after the first samples (`--init auto`) skips them
    while next.is_some_and(|s| s.t <= start.t + 1e-9) {
        next = io.samples.next_sample()?;
    }
    let mut diverged = None;
    let mut out = Records {
        keep: keep_records,
        all: &mut records,
        last: &mut last,
        on_record,
    };
    // the start state: the first row of a navigation output
    obs.nav_sample(&e.nav.state, &e.x, &e.p);
    while let Some(smp) = next {
        next = io.samples.next_sample()?;
        let dt = smp.t - prev_t;
        prev_t = smp.t;
        e.navigate(&smp, dt, obs);
        on_sample(&e.nav.state);
        obs.nav_sample(&e.nav.state, &e.x, &e.p);
        if k.is_multiple_of(2000) {
            progress(io.samples.fraction());
        }
        k += 1;
        let aid_due = aiding.peek().is_some_and(|a| a.t <= smp.t + 1e-9);
        let step_done = smp.t - e.step_t0 + 1e-9 >= cfg.step_s;
        if !step_done && !aid_due && next.is_some() {
            continue;
        }
        diverged = e.end_step(smp.t, &mut aiding, io.truth.as_deref_mut(), obs, &mut out)?;
        if diverged.is_none() {
            diverged = obs.stop();
        }
        if diverged.is_some() {
            break;
        }
    }
    progress(1.0);
    records.extend(last);
    Ok(e.finish(records, diverged))
}

/// Where a run's records go: each to `on_record`, then kept (all, or the last only).
struct Records<'r> {
    keep: bool,
    all: &'r mut Vec<Record>,
    last: &'r mut Option<Record>,
    on_record: &'r mut dyn FnMut(&Record) -> anyhow::Result<()>,
}

/// An open-loop filter pass from a [`NavTape`] recorded over the same data: the propagations,
/// updates and records of [`run_stream`] from the recorded navigation, bit-identical to a full
/// pass over the samples, without them. The observers are told every step's sums
/// ([`Observer::step_sums`]) instead of every sample, and `nav_sample` once per step (after its
/// first sample, as a full pass first shows them the step's x): only observers that need no
/// more may watch a replay. The caller checks [`NavTape::fits`] (else this is an error).
#[allow(clippy::too_many_arguments)]
pub fn run_replay(
    model: &Model,
    cfg: &FilterConfig,
    tape: &NavTape,
    aid: &[AidingEpoch],
    truth: Option<&mut (dyn TruthLookup + '_)>,
    mut progress: impl FnMut(f64),
    obs: &mut dyn Observer,
    keep_records: bool,
) -> anyhow::Result<FilterRun> {
    let start = tape.start();
    if !tape.fits(cfg, &start, aid) {
        anyhow::bail!("internal: a navigation tape replayed for a pass it was not recorded for");
    }
    let mut e = Engine::new(model, cfg, start);
    let mut aiding = aid.iter().cloned().peekable();
    let mut truth = truth;
    let (mut records, mut last) = (Vec::new(), None);
    let mut diverged = None;
    let mut out = Records {
        keep: keep_records,
        all: &mut records,
        last: &mut last,
        on_record: &mut |_| Ok(()),
    };
    obs.nav_sample(&e.nav.state, &e.x, &e.p);
    let steps = tape.len();
    for k in 0..steps {
        let (first, end, sums) = tape.step(k);
        obs.nav_sample(first, &e.x, &e.p);
        obs.step_sums(&sums);
        e.nav.state = *end;
        e.acc.set_sums(sums.regressors, sums.count);
        (e.f_sum, e.w_sum, e.in_step) = (sums.f, sums.w, sums.count as usize);
        if k.is_multiple_of(200) {
            progress(k as f64 / steps.max(1) as f64);
        }
        diverged = e.end_step(end.t, &mut aiding, truth.as_deref_mut(), obs, &mut out)?;
        if diverged.is_some() {
            break;
        }
    }
    progress(1.0);
    records.extend(last);
    Ok(e.finish(records, diverged))
}

/// The navigation state `s` taken back (or forward) to time `t` [s] along its velocity and
/// acceleration (specific force `f_ned` [m/s²] plus gravity), to first order; `s` itself when
/// `t` is its time.
fn state_at(s: &NavState, t: f64, f_ned: &Vector3<f64>) -> NavState {
    let dt = t - s.t;
    if dt == 0.0 || !dt.is_finite() {
        return *s;
    }
    let rm = earth::radius_meridian(s.lat) + s.h;
    let rn = earth::radius_transverse(s.lat) + s.h;
    let a = f_ned + Vector3::new(0.0, 0.0, earth::gravity(s.lat, s.h));
    NavState {
        t,
        lat: s.lat + s.v.x * dt / rm,
        lon: s.lon + s.v.y * dt / (rn * s.lat.cos()),
        h: s.h - s.v.z * dt,
        v: s.v + a * dt,
        q: s.q,
    }
}

/// The index in `runs` (epochs in a row the gate rejected, per measurement and component) of
/// component `comp` of measurement `name`, added at 0 when new.
pub(crate) fn gate_run(
    runs: &mut Vec<(&'static str, usize, u32)>,
    name: &'static str,
    comp: usize,
) -> usize {
    runs.iter()
        .position(|r| r.0 == name && r.1 == comp)
        .unwrap_or_else(|| {
            runs.push((name, comp, 0));
            runs.len() - 1
        })
}

/// What became of one scalar update.
pub(crate) enum Scalar {
    /// Applied, with its innovation ν and its variance S (SI).
    Applied(f64, f64),
    /// Not applied: |ν| beyond the gate's √S (ν, S).
    Gated(f64, f64),
    /// Not applied: ν or S not finite, or S <= 0.
    NotFinite,
}

/// Scalar update of measurement row h, value z and variance r in Joseph form:
/// P ← (I − K h) P (I − K h)ᵀ + K r Kᵀ, expanded for a row h, unless |ν| > `gate` √S.
pub(crate) fn joseph_update(
    x: &mut [f64],
    p: &mut [f64],
    (h, z, r): (&[f64], f64, f64),
    gate: f64,
    u: &mut [f64],
    k: &mut [f64],
) -> Scalar {
    let n = x.len();
    let nz: Vec<usize> = (0..n).filter(|&j| h[j] != 0.0).collect();
    for i in 0..n {
        u[i] = nz.iter().map(|&j| p[i * n + j] * h[j]).sum();
    }
    let hph: f64 = nz.iter().map(|&j| h[j] * u[j]).sum();
    let s = hph + r;
    if !s.is_finite() || s <= 0.0 {
        return Scalar::NotFinite;
    }
    let nu = z - nz.iter().map(|&j| h[j] * x[j]).sum::<f64>();
    if !nu.is_finite() {
        return Scalar::NotFinite;
    }
    if nu * nu > gate * gate * s {
        return Scalar::Gated(nu, s);
    }
    for (ki, ui) in k.iter_mut().zip(u.iter()) {
        *ki = ui / s;
    }
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
    if nu.is_finite() && s.is_finite() {
        Scalar::Applied(nu, s)
    } else {
        Scalar::NotFinite
    }
}

pub use super::metrics::{
    channel_id, channel_name, channel_str, channels, model_error_rms_arcsec, nis_by_channel,
    ChannelNis,
};
