//! Models as users write them (`P31`, `P28+kaq_x_xy+kgf_xz`, `P31+vertical`): parsing, the
//! state layout, and A(t)/H filling, either through a preset's generated kernels or composed at
//! run time from the generated navigation block and per-term columns.

pub mod catalog;
pub mod covariance;
pub mod generated;
pub mod jacobian;
pub mod kernel;
pub mod priors;

use crate::model::catalog::{MeasurementInfo, PresetKernels, StateRef};
use crate::model::generated::{common, PRESETS};
use crate::nav::nav_point::NavPoint;
use nalgebra::Vector3;
use std::fmt;

/// Why a model string could not be used.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ModelError(pub String);

impl fmt::Display for ModelError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for ModelError {}

/// A resolved model: ordered states and the means to fill A and H.
#[derive(Debug, Clone)]
pub struct Model {
    /// Canonical text, e.g. `P28+vertical+kaq_x_xy`.
    pub name: String,
    /// Vertical channel present.
    pub vertical: bool,
    /// States in order (catalogue references).
    pub states: Vec<StateRef>,
    /// State names in order.
    pub names: Vec<&'static str>,
    /// Accumulated (non-constant) regressors, indices into `common::REGRESSORS`.
    pub regressor_ids: Vec<usize>,
    /// The preset's generated kernels when the model is exactly a preset (optionally +vertical).
    pub preset: Option<&'static PresetKernels>,
    a_pattern: Vec<(usize, usize)>,
    /// Run-time composition plan: (index in the flat navigation block, index in the flat n×n
    /// A) of each navigation entry the model has.
    nav_map: Vec<(u32, u32)>,
    /// Run-time composition plan: each term column.
    term_cols: Vec<TermColumn>,
}

/// A term's column of A in a run-time composition: the term, the position of its regressor's
/// mean, and (navigation row, index in the flat n×n A) of each of its rows the model has.
type TermColumn = (usize, Option<usize>, Vec<(usize, usize)>);

/// Default noise 1-σ (SI, per component) of spec measurement `name`.
pub fn measurement_sigma(name: &str) -> Option<f64> {
    common::MEASUREMENTS
        .iter()
        .find(|m| m.name == name)
        .map(|m| m.sigma)
}

/// Levenshtein distance between two names (byte-wise; names are ASCII).
pub fn edit_distance(a: &str, b: &str) -> usize {
    let (a, b) = (a.as_bytes(), b.as_bytes());
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.iter().enumerate() {
        let mut cur = vec![i + 1; b.len() + 1];
        for (j, cb) in b.iter().enumerate() {
            let sub = prev[j] + usize::from(ca != cb);
            cur[j + 1] = sub.min(prev[j + 1] + 1).min(cur[j] + 1);
        }
        prev = cur;
    }
    prev[b.len()]
}

/// Spec term names nearest to `name` (at most 3, within edit distance 3).
pub fn nearest_terms(name: &str) -> Vec<&'static str> {
    let mut v: Vec<(usize, &'static str)> = common::TERMS
        .iter()
        .map(|t| (edit_distance(name, t.name), t.name))
        .filter(|(d, _)| *d <= 3)
        .collect();
    v.sort();
    v.into_iter().take(3).map(|(_, n)| n).collect()
}

/// `; did you mean a, b?` for an unknown term name, or nothing when no name is near.
pub fn did_you_mean(name: &str) -> String {
    let near = nearest_terms(name);
    if near.is_empty() {
        String::new()
    } else {
        format!("; did you mean {}?", near.join(", "))
    }
}

fn preset_names() -> String {
    PRESETS
        .iter()
        .filter(|p| !p.vertical)
        .map(|p| p.name)
        .collect::<Vec<_>>()
        .join(", ")
}

impl Model {
    /// Parses `PRESET[+vertical][+term…]`; added terms go after the preset's, in the order given.
    pub fn parse(text: &str) -> Result<Model, ModelError> {
        // what messages show of the model text and its parts: short and printable
        let shown_text = crate::io::lines::shown(text);
        let mut parts = text.split('+').map(str::trim);
        let base = parts.next().unwrap_or("");
        let mut vertical = false;
        let mut extra: Vec<usize> = Vec::new();
        for p in parts {
            if p.eq_ignore_ascii_case("vertical") {
                if vertical {
                    return Err(ModelError(format!(
                        "model `{shown_text}`: `vertical` given twice"
                    )));
                }
                vertical = true;
                continue;
            }
            let t = common::TERMS
                .iter()
                .position(|t| t.name == p)
                .ok_or_else(|| {
                    ModelError(format!(
                        "model `{shown_text}`: unknown term `{}`{} (see `sinsmodel model list`)",
                        crate::io::lines::shown(p),
                        did_you_mean(p)
                    ))
                })?;
            if extra.contains(&t) {
                return Err(ModelError(format!(
                    "model `{shown_text}`: term `{}` given twice",
                    crate::io::lines::shown(p)
                )));
            }
            extra.push(t);
        }
        let preset = PRESETS
            .iter()
            .find(|k| k.name.eq_ignore_ascii_case(base) && !k.vertical)
            .ok_or_else(|| {
                ModelError(format!(
                    "model `{shown_text}`: unknown preset `{}` (presets: {}); write a model as PRESET[+vertical][+term…]",
                    crate::io::lines::shown(base),
                    preset_names()
                ))
            })?;
        let kernels = PRESETS
            .iter()
            .find(|k| {
                k.name == format!("{}{}", preset.name, if vertical { "+vertical" } else { "" })
            })
            .expect("every preset has a +vertical twin");
        let mut states: Vec<StateRef> = kernels.state_refs.to_vec();
        for &t in &extra {
            if states.contains(&StateRef::Term(t)) {
                return Err(ModelError(format!(
                    "model `{shown_text}`: term `{}` is already in {}",
                    common::TERMS[t].name,
                    preset.name
                )));
            }
            states.push(StateRef::Term(t));
        }
        let mut name = kernels.name.to_string();
        for &t in &extra {
            name.push('+');
            name.push_str(common::TERMS[t].name);
        }
        // a composed model whose states are exactly a compiled preset's (same order, e.g.
        // P28+d_x+d_y+d_z = P31, or a user's [[preset]]) runs on that preset's generated kernels
        let compiled = PRESETS
            .iter()
            .find(|k| k.vertical == vertical && k.state_refs == states.as_slice());
        Ok(Model::from_states(name, vertical, states, compiled))
    }

    fn from_states(
        name: String,
        vertical: bool,
        states: Vec<StateRef>,
        preset: Option<&'static PresetKernels>,
    ) -> Model {
        let names = states
            .iter()
            .map(|s| match *s {
                StateRef::Nav(k) => common::NAV_STATES[k].name,
                StateRef::Term(k) => common::TERMS[k].name,
            })
            .collect();
        let mut nav_pos = [None; common::NAV_COUNT];
        for (i, s) in states.iter().enumerate() {
            if let StateRef::Nav(k) = *s {
                nav_pos[k] = Some(i);
            }
        }
        let mut regressor_ids = Vec::new();
        for s in &states {
            if let StateRef::Term(t) = *s {
                let r = common::TERMS[t].regressor;
                if !common::REGRESSOR_CONSTANT[r] && !regressor_ids.contains(&r) {
                    regressor_ids.push(r);
                }
            }
        }
        let mut a_pattern = Vec::new();
        for &(r, c) in common::NAV_PATTERN.iter() {
            if let (Some(i), Some(j)) = (nav_pos[r], nav_pos[c]) {
                a_pattern.push((i, j));
            }
        }
        for (j, s) in states.iter().enumerate() {
            if let StateRef::Term(t) = *s {
                for &r in common::TERM_ROWS[t] {
                    if let Some(i) = nav_pos[r] {
                        a_pattern.push((i, j));
                    }
                }
            }
        }
        a_pattern.sort_unstable();
        let n = states.len();
        let nav_map = common::NAV_PATTERN
            .iter()
            .filter_map(|&(r, c)| {
                let flat = |x: usize| u32::try_from(x).expect("a model of under 65536 states");
                Some((
                    flat(r * common::NAV_COUNT + c),
                    flat(nav_pos[r]? * n + nav_pos[c]?),
                ))
            })
            .collect();
        let term_cols = states
            .iter()
            .enumerate()
            .filter_map(|(j, s)| match *s {
                StateRef::Term(t) => {
                    let reg = common::TERMS[t].regressor;
                    let rows = common::TERM_ROWS[t]
                        .iter()
                        .filter_map(|&row| Some((row, nav_pos[row]? * n + j)))
                        .collect();
                    Some((t, regressor_ids.iter().position(|&x| x == reg), rows))
                }
                StateRef::Nav(_) => None,
            })
            .collect();
        Model {
            name,
            vertical,
            states,
            names,
            regressor_ids,
            preset,
            a_pattern,
            nav_map,
            term_cols,
        }
    }

    /// Number of states.
    pub fn n(&self) -> usize {
        self.states.len()
    }

    /// Index of a state by canonical name.
    pub fn index_of(&self, name: &str) -> Option<usize> {
        self.names.iter().position(|n| *n == name)
    }

    /// Structural non-zeros of A, row-major.
    pub fn a_pattern(&self) -> &[(usize, usize)] {
        &self.a_pattern
    }

    /// SI unit of state `i`.
    pub fn unit(&self, i: usize) -> &'static str {
        match self.states[i] {
            StateRef::Nav(k) => common::NAV_STATES[k].unit,
            StateRef::Term(k) => common::TERMS[k].unit,
        }
    }

    /// Default prior 1-σ of state `i`, SI.
    pub fn prior_sigma(&self, i: usize) -> f64 {
        match self.states[i] {
            StateRef::Nav(k) => common::NAV_STATES[k].sigma,
            StateRef::Term(k) => common::TERMS[k].sigma,
        }
    }

    /// Measurements whose states are all in this model.
    pub fn measurements(&self) -> Vec<&'static MeasurementInfo> {
        common::MEASUREMENTS
            .iter()
            .filter(|m| m.states.iter().all(|s| self.index_of(s).is_some()))
            .collect()
    }

    /// Step means of this model's regressors over IMU samples (f [m/s²], w [rad/s], FRD).
    pub fn accumulator(&self) -> RegressorAccumulator {
        RegressorAccumulator {
            ids: self.regressor_ids.clone(),
            sum: vec![0.0; self.regressor_ids.len()],
            count: 0,
            generated: self.preset.map(|k| k.accumulate),
        }
    }

    /// The same model without its generated kernels (run-time composition only): the
    /// benchmark's and the tests' reference for the composed path.
    pub fn runtime_only(&self) -> Model {
        let mut m = self.clone();
        m.preset = None;
        m
    }

    /// Name of the compiled preset whose kernels this model runs on, if any.
    pub fn compiled_as(&self) -> Option<&'static str> {
        self.preset.map(|k| k.name)
    }

    /// Fills A (n×n row-major, zeroed by the caller) through the preset kernel when there is
    /// one, else by run-time composition.
    pub fn fill_a(&self, nav: &NavPoint, r: &[f64], a: &mut [f64]) {
        match self.preset {
            Some(k) => (k.fill_a)(nav, r, a),
            None => self.fill_a_runtime(nav, r, a),
        }
    }

    /// Whether [`Model::fill_a`] writes every entry of [`Model::a_pattern`] (the run-time
    /// composition does, each once), so that A needs no zeroing between two calls.
    pub fn fill_a_writes_whole_pattern(&self) -> bool {
        self.preset.is_none()
    }

    /// Fills A by run-time composition: the generated navigation block and per-term columns;
    /// every entry of the pattern is written (a zero too), nothing else.
    pub fn fill_a_runtime(&self, nav: &NavPoint, r: &[f64], a: &mut [f64]) {
        let n = self.n();
        let mut block = [[0.0; common::NAV_COUNT]; common::NAV_COUNT];
        common::fill_nav_block(nav, &mut block);
        let block = block.as_flattened();
        let a = &mut a[..n * n];
        for &(from, to) in &self.nav_map {
            a[to as usize] = block[from as usize];
        }
        for (t, k, rows) in &self.term_cols {
            let rv = k.map(|k| r[k]).unwrap_or(0.0);
            let mut col = [0.0; common::NAV_COUNT];
            common::term_column(*t, nav, rv, &mut col);
            for &(row, to) in rows {
                a[to] = col[row];
            }
        }
    }

    /// Fills H (components × n, row-major, zeroed by the caller) for measurement `meas`;
    /// returns the number of components.
    pub fn fill_h(&self, meas: &str, nav: &NavPoint, h: &mut [f64]) -> Result<usize, ModelError> {
        let rows = self.measurement(meas)?.rows.len();
        if let Some(k) = self.preset {
            if (k.fill_h)(meas, nav, h) {
                return Ok(rows);
            }
        }
        self.fill_h_runtime(meas, nav, h)
    }

    fn measurement(&self, meas: &str) -> Result<&'static MeasurementInfo, ModelError> {
        let m = common::MEASUREMENTS
            .iter()
            .find(|m| m.name == meas)
            .ok_or_else(|| ModelError(format!("unknown measurement `{meas}`")))?;
        if let Some(s) = m.states.iter().find(|s| self.index_of(s).is_none()) {
            return Err(ModelError(format!(
                "measurement `{meas}` needs state `{s}`, which model {} lacks",
                self.name
            )));
        }
        Ok(m)
    }

    /// Fills H by run-time composition from the generated measurement entries.
    pub fn fill_h_runtime(
        &self,
        meas: &str,
        nav: &NavPoint,
        h: &mut [f64],
    ) -> Result<usize, ModelError> {
        let m = self.measurement(meas)?;
        let idx = common::MEASUREMENTS
            .iter()
            .position(|x| x.name == meas)
            .expect("found above");
        let n = self.n();
        let mut missing = None;
        common::measurement_entries(idx, nav, &mut |row, state, v| match self.index_of(state) {
            Some(j) => h[row * n + j] = v,
            // a GNSS term's entry applies only when the term is in the model
            None if common::TERMS.iter().any(|t| t.name == state) => {}
            None => missing = Some(state),
        });
        match missing {
            Some(s) => Err(ModelError(format!(
                "measurement `{meas}` needs state `{s}`"
            ))),
            None => Ok(m.rows.len()),
        }
    }
}

/// Running sums of a model's regressors over the IMU samples of one filter step.
#[derive(Debug, Clone)]
pub struct RegressorAccumulator {
    ids: Vec<usize>,
    sum: Vec<f64>,
    count: u32,
    generated: Option<AccumulateFn>,
}

/// True when regressor `id` (an index into `common::REGRESSORS`) reads one of the IMU signals
/// `names` (`f`, `w`, `dw`, `df`).
pub fn regressor_reads(id: usize, names: &[&str]) -> bool {
    common::REGRESSOR_SIGNALS[id]
        .iter()
        .any(|s| names.contains(s))
}

/// A generated regressor accumulator: adds one sample's signals to running sums.
pub type AccumulateFn = fn(&mut [f64], &ImuSignals);

/// The body-frame (FRD) signals of one IMU sample that regressors read.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ImuSignals {
    /// Specific force f [m/s²] (the sample's mean).
    pub f: Vector3<f64>,
    /// Angular rate w [rad/s] (the sample's mean).
    pub w: Vector3<f64>,
    /// Angular acceleration dw [rad/s²] ([`SignalRates`]).
    pub dw: Vector3<f64>,
    /// Rate of change of the specific force df [m/s³] ([`SignalRates`]).
    pub df: Vector3<f64>,
}

impl ImuSignals {
    /// A sample's f [m/s²] and w [rad/s] with zero derivatives.
    pub fn new(f: Vector3<f64>, w: Vector3<f64>) -> ImuSignals {
        ImuSignals {
            f,
            w,
            ..Default::default()
        }
    }
}

/// The derivatives of the IMU signals from consecutive samples: each sample's mean rate and
/// specific force minus the previous sample's, over the time between their midpoints (zero for
/// the first sample). Summed over a filter step they telescope to the step's change.
#[derive(Debug, Clone, Default)]
pub struct SignalRates {
    prev: Option<(Vector3<f64>, Vector3<f64>, f64)>,
}

impl SignalRates {
    /// The signals of a sample of mean specific force `f` [m/s²] and rate `w` [rad/s] spanning
    /// `dt` [s], with dw and df from the previous sample.
    pub fn next(&mut self, f: &Vector3<f64>, w: &Vector3<f64>, dt: f64) -> ImuSignals {
        let (dw, df) = match self.prev {
            Some((fp, wp, dtp)) if dt + dtp > 0.0 => {
                let k = 1.0 / (0.5 * (dt + dtp));
                ((w - wp) * k, (f - fp) * k)
            }
            _ => (Vector3::zeros(), Vector3::zeros()),
        };
        self.prev = Some((*f, *w, dt));
        ImuSignals {
            f: *f,
            w: *w,
            dw,
            df,
        }
    }
}

/// Above this many regressors a run-time accumulator evaluates all of them at once per sample.
const MANY_REGRESSORS: usize = 6;

impl RegressorAccumulator {
    /// An accumulator of the given regressors (indices into `common::REGRESSORS`).
    pub fn new(ids: Vec<usize>) -> RegressorAccumulator {
        RegressorAccumulator {
            sum: vec![0.0; ids.len()],
            ids,
            count: 0,
            generated: None,
        }
    }

    /// Adds one sample's signals (FRD body frame).
    pub fn add(&mut self, sig: &ImuSignals) {
        match self.generated {
            Some(acc) => acc(&mut self.sum, sig),
            // many regressors: each value once, in straight-line code
            None if self.ids.len() > MANY_REGRESSORS => {
                let mut v = [0.0; common::REGRESSOR_COUNT];
                common::regressor_values(sig, &mut v);
                for (s, &id) in self.sum.iter_mut().zip(&self.ids) {
                    *s += v[id];
                }
            }
            None => {
                for (s, &id) in self.sum.iter_mut().zip(&self.ids) {
                    *s += common::regressor_value(id, sig);
                }
            }
        }
        self.count += 1;
    }

    /// Means (mean of squares, never square of means); zeros when empty.
    pub fn mean(&self) -> Vec<f64> {
        let mut out = vec![0.0; self.sum.len()];
        self.mean_into(&mut out);
        out
    }

    /// [`RegressorAccumulator::mean`] into a caller's buffer (no allocation per filter step).
    pub fn mean_into(&self, out: &mut [f64]) {
        let k = if self.count > 0 {
            1.0 / self.count as f64
        } else {
            0.0
        };
        for (o, s) in out.iter_mut().zip(&self.sum) {
            *o = s * k;
        }
    }

    /// Sets the step's sums from `all` (every spec regressor's sum, indexed as
    /// `common::REGRESSORS`, added in the samples' order as [`RegressorAccumulator::add`] adds)
    /// over `count` samples: a replayed step ([`crate::estimate::nav_tape`]).
    pub fn set_sums(&mut self, all: &[f64], count: u32) {
        for (s, &id) in self.sum.iter_mut().zip(&self.ids) {
            *s = all[id];
        }
        self.count = count;
    }

    /// Starts a new step.
    pub fn reset(&mut self) {
        self.sum.iter_mut().for_each(|s| *s = 0.0);
        self.count = 0;
    }
}
