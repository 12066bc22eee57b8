//! One open-loop pass's navigation, kept so that later passes over the same data skip it.
//!
//! In open loop the navigator never sees the filter: every pass over the same IMU samples, start
//! state, vertical channel, filter step and aiding times navigates the same way, whatever its
//! model. A [`TapeRecorder`] watches one such pass (it is an [`Observer`]) and keeps, for each
//! filter step, the navigation state at the step's end and after its first sample, and the sums
//! over the step's samples of the signals and of every spec regressor, added in the samples'
//! order as the filter's own accumulators add them. [`super::filter::run_replay`] then runs
//! another model's pass from the tape: the same propagations and updates from the same numbers,
//! so its results are bit-identical to a full pass, without reading, navigating or summing a
//! sample. A tape holds about 0.44 kB per filter step (44 kB per second at the default 0.01 s).

use super::filter::{AidingEpoch, FilterConfig, Mode, Observer};
use crate::model::generated::common;
use crate::model::ImuSignals;
use crate::nav::strapdown::{NavState, Vertical};
use nalgebra::Vector3;

/// A tape larger than this [bytes] is not kept (the passes then run in full).
pub const MAX_BYTES: usize = 256 << 20;

/// Bytes a tape holds per filter step.
pub const STEP_BYTES: usize = std::mem::size_of::<Step>() + 8 * common::REGRESSOR_COUNT;

/// The most filter steps a tape holds ([`MAX_BYTES`]).
pub fn max_steps() -> usize {
    MAX_BYTES / STEP_BYTES
}

/// The sums over one filter step's samples, in the samples' order (what a replay hands its
/// observers in place of every sample, [`Observer::step_sums`]).
#[derive(Debug, Clone, Copy)]
pub struct StepSums<'a> {
    /// Σ of every spec regressor (indexed as `common::REGRESSORS`) over the step's samples.
    pub regressors: &'a [f64],
    /// Σ f [m/s²] (FRD).
    pub f: Vector3<f64>,
    /// Σ w [rad/s] (FRD).
    pub w: Vector3<f64>,
    /// Σ |f|² [m²/s⁴].
    pub f2: f64,
    /// Samples in the step.
    pub count: u32,
}

/// One filter step as the navigator left it.
#[derive(Debug, Clone, Copy)]
struct Step {
    /// The state after the step's first sample (what observers saw first with the step's x).
    first: NavState,
    /// The state at the step's end (its time is the step's).
    end: NavState,
    /// Σ |f|² [m²/s⁴] (Σ f and Σ w are regressors' sums, [`signal_ids`]).
    f2: f64,
    count: u32,
}

/// Where Σ w and Σ f sit among a step's regressor sums: the indices in `common::REGRESSORS` of
/// w.x, w.y, w.z, f.x, f.y, f.z (each the same additions as the filter's own Σ f and Σ w).
fn signal_ids() -> [usize; 6] {
    static IDS: std::sync::OnceLock<[usize; 6]> = std::sync::OnceLock::new();
    *IDS.get_or_init(|| {
        ["w.x", "w.y", "w.z", "f.x", "f.y", "f.z"].map(|name| {
            common::REGRESSORS
                .iter()
                .position(|r| *r == name)
                .expect("the spec's regressors include the IMU signals")
        })
    })
}

/// The bits of a navigation state's numbers (equal bits: the same state).
fn state_bits(s: &NavState) -> [u64; 11] {
    let q = &s.q.coords;
    [
        s.t, s.lat, s.lon, s.h, s.v.x, s.v.y, s.v.z, q[0], q[1], q[2], q[3],
    ]
    .map(f64::to_bits)
}

/// What a pass must share with the recorded one for the tape to stand for its navigation.
#[derive(Debug, Clone)]
struct Key {
    start: NavState,
    vertical: Vertical,
    step_s: f64,
    /// Every aiding epoch's time [s] (they end steps).
    aid_t: Vec<f64>,
}

impl Key {
    fn of(cfg: &FilterConfig, start: &NavState, aid: &[AidingEpoch]) -> Option<Key> {
        (cfg.mode == Mode::OpenLoop).then(|| Key {
            start: *start,
            vertical: cfg.vertical,
            step_s: cfg.step_s,
            aid_t: aid.iter().map(|a| a.t).collect(),
        })
    }

    /// True when a pass with `cfg` from `start` with aiding `aid` has this key, bit for bit.
    fn matches(&self, cfg: &FilterConfig, start: &NavState, aid: &[AidingEpoch]) -> bool {
        cfg.mode == Mode::OpenLoop
            && state_bits(&self.start) == state_bits(start)
            && self.vertical == cfg.vertical
            && self.step_s.to_bits() == cfg.step_s.to_bits()
            && self.aid_t.len() == aid.len()
            && self
                .aid_t
                .iter()
                .zip(aid)
                .all(|(t, a)| t.to_bits() == a.t.to_bits())
    }
}

/// A recorded open-loop pass's navigation (see the module's note).
#[derive(Debug, Clone)]
pub struct NavTape {
    key: Key,
    steps: Vec<Step>,
    /// Every step's regressor sums, `REGRESSOR_COUNT` per step.
    regressors: Vec<f64>,
}

impl NavTape {
    /// True when a pass with configuration `cfg` from `start` with aiding `aid` over the recorded
    /// samples navigates as the recorded pass did (open loop, the same start, vertical channel,
    /// step and aiding times).
    pub fn fits(&self, cfg: &FilterConfig, start: &NavState, aid: &[AidingEpoch]) -> bool {
        self.key.matches(cfg, start, aid)
    }

    /// The recorded start state.
    pub fn start(&self) -> NavState {
        self.key.start
    }

    /// Number of filter steps.
    pub fn len(&self) -> usize {
        self.steps.len()
    }

    /// True when no step was recorded.
    pub fn is_empty(&self) -> bool {
        self.steps.is_empty()
    }

    /// Step `k`: the state after its first sample, the state at its end, and its sums.
    pub fn step(&self, k: usize) -> (&NavState, &NavState, StepSums<'_>) {
        let s = &self.steps[k];
        let r = common::REGRESSOR_COUNT;
        let regressors = &self.regressors[k * r..(k + 1) * r];
        let [wx, wy, wz, fx, fy, fz] = signal_ids();
        let sums = StepSums {
            regressors,
            f: Vector3::new(regressors[fx], regressors[fy], regressors[fz]),
            w: Vector3::new(regressors[wx], regressors[wy], regressors[wz]),
            f2: s.f2,
            count: s.count,
        };
        (&s.first, &s.end, sums)
    }

    /// Bytes the tape holds.
    pub fn bytes(&self) -> usize {
        self.steps.len() * STEP_BYTES
    }
}

/// Watches an open-loop pass and records its navigation (see the module's note).
pub struct TapeRecorder {
    key: Key,
    steps: Vec<Step>,
    regressors: Vec<f64>,
    sums: [f64; common::REGRESSOR_COUNT],
    f2: f64,
    count: u32,
    first: Option<NavState>,
    last: NavState,
    started: bool,
    too_large: bool,
}

impl TapeRecorder {
    /// A recorder for a pass with configuration `cfg` from `start` with aiding `aid`; None in
    /// closed loop, where the navigation depends on the filter.
    pub fn new(cfg: &FilterConfig, start: &NavState, aid: &[AidingEpoch]) -> Option<TapeRecorder> {
        Some(TapeRecorder {
            key: Key::of(cfg, start, aid)?,
            steps: Vec::new(),
            regressors: Vec::new(),
            sums: [0.0; common::REGRESSOR_COUNT],
            f2: 0.0,
            count: 0,
            first: None,
            last: *start,
            started: false,
            too_large: false,
        })
    }

    /// Room for `steps` filter steps at once (the tape then grows by no doubling up to them).
    pub fn reserve(&mut self, steps: usize) {
        let steps = steps.min(max_steps() + 1);
        self.steps.reserve_exact(steps);
        self.regressors
            .reserve_exact(steps * common::REGRESSOR_COUNT);
    }

    /// The tape of `run`, the pass watched, or None when it outgrew [`MAX_BYTES`] or the pass
    /// ended early (diverged: its later steps are missing).
    pub fn finish(self, run: &super::filter::FilterRun) -> Option<NavTape> {
        if self.too_large || self.count > 0 || run.diverged.is_some() {
            return None;
        }
        Some(NavTape {
            key: self.key,
            steps: self.steps,
            regressors: self.regressors,
        })
    }
}

impl Observer for TapeRecorder {
    fn sample(&mut self, sig: &ImuSignals) {
        if self.too_large {
            return;
        }
        let mut v = [0.0; common::REGRESSOR_COUNT];
        common::regressor_values(sig, &mut v);
        for (s, x) in self.sums.iter_mut().zip(&v) {
            *s += x;
        }
        self.f2 += sig.f.norm_squared();
        self.count += 1;
    }

    fn nav_sample(&mut self, s: &NavState, _x: &[f64], _p: &[f64]) {
        // (the first call is the start state, before any sample)
        if !self.started {
            self.started = true;
            return;
        }
        if self.first.is_none() {
            self.first = Some(*s);
        }
        self.last = *s;
    }

    fn step(
        &mut self,
        _t: f64,
        _dt: f64,
        _np: &crate::nav::nav_point::NavPoint,
        _a: &[f64],
        _pattern: &[(usize, usize)],
    ) {
        if self.too_large {
            return;
        }
        self.steps.push(Step {
            first: self.first.take().unwrap_or(self.last),
            end: self.last,
            f2: self.f2,
            count: self.count,
        });
        self.regressors.extend_from_slice(&self.sums);
        self.sums = [0.0; common::REGRESSOR_COUNT];
        (self.f2, self.count) = (0.0, 0);
        if self.steps.len() > max_steps() {
            self.too_large = true;
            self.steps = Vec::new();
            self.regressors = Vec::new();
        }
    }
}
