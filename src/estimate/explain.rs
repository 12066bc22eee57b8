//! What a model gets wrong on measured data, which missing error term causes it, the extended
//! model and its gain (DESIGN §8).
//!
//! 1. **Innovations.** The baseline filter's innovations per channel (`vel_n`, `vel_e`, `pos_n`,
//!    `pos_e`, `pos_h`): mean NIS against its χ² band, the fraction outside the 95 % band,
//!    Ljung–Box whiteness, mean normalised innovation and NIS per segment (segments where the
//!    excitation level changes, else fixed windows), and with truth the predicted σ against the
//!    actual estimation error.
//! 2. **Signatures (Willsky–Jones GLR).** A constant parameter θ of a candidate term enters the
//!    error dynamics as x_{k+1} = Φ_k x_k + Γ_k θ, Γ_k = dt (I + dt/2 A) a_θ with a_θ the term's
//!    column of A at the step's regressor mean (the same second-order discretisation as Φ). Its
//!    effect on the baseline filter's estimation error, D_{k+1} = Φ_k (I − K_k H_k) D_k + Γ_k,
//!    reaches the innovations as G_k = H_k D_k (sequentially per scalar update, with the
//!    filter's own gains), so ν_k = ν_k⁰ + G_k θ. All candidates ride along one filter pass
//!    (two sparse A-products per candidate and step). Information J = Σ Gᵀ S⁻¹ G and score
//!    b = Σ Gᵀ S⁻¹ ν give θ̂ = b/J, σ = J^−½, llr = b²/J ~ χ²₁ under H0.
//! 3. **Selection.** Forward selection on the joint J and b (conditional llr by Schur
//!    complements), each step tested against α / (candidates left) (Holm); candidates whose
//!    conditional signatures correlate at |ρ| > 0.9 with the chosen one form its equivalence
//!    class and leave the pool. The chosen terms are added and the filter is re-run with them
//!    (the signatures are linearisations: re-testing the rest through the extended filter keeps
//!    a large first finding from masking or inventing a second). Stops when nothing passes.
//!    A candidate whose information is zero on these data is "not testable"; one whose regressor
//!    sequence is proportional (|cos| > 0.999) to a baseline term's on the same sensor axis is
//!    flagged as not separable from it.
//! 4. **Gain.** The extended model's innovations (NIS, whiteness, log-likelihood) and, with
//!    truth, the paper's model error e = φ̂ − φ before and after.

use crate::estimate::filter::{self, channel_name, AidingEpoch, FilterConfig, FilterRun, Observer};
use crate::estimate::stats;
use crate::io::imu::ImuData;
use crate::io::truth::TruthRow;
use crate::model::catalog::{Sensor, StateRef};
use crate::model::generated::common;
use crate::model::{did_you_mean, Model, RegressorAccumulator};
use crate::nav::earth;
use crate::nav::nav_point::NavPoint;
use crate::nav::strapdown::NavState;
use nalgebra::{DMatrix, Vector3};
use serde::Serialize;

/// Standard gravity [m/s²] for expressing regressors in g.
const G0: f64 = 9.806_65;
const ARCSEC: f64 = 180.0 / std::f64::consts::PI * 3600.0;

/// Settings of a run of explain.
#[derive(Debug, Clone)]
pub struct ExplainOptions {
    /// Family-wise false-alarm level of the candidate tests (Holm-corrected).
    pub alpha: f64,
    /// |ρ| above which two signatures form an equivalence class.
    pub rho_equivalent: f64,
    /// Most filter passes (baseline + re-tests after each addition).
    pub max_rounds: usize,
    /// Prior-scaled information J·σ² below which a candidate is "not testable".
    pub min_information: f64,
    /// |cos| between a candidate's and a same-axis baseline term's regressor sequences above
    /// which the candidate is not separable from that term (0.999: within 2.6°).
    pub confound_cos: f64,
    /// A candidate whose estimate would exceed this many prior σ is not named but reported as
    /// implausible (a weakly observable signature fitting some other mismatch).
    pub max_prior_sigmas: f64,
    /// Prior σ of candidate terms that replace the spec's (term index, σ in SI): the sensor
    /// class of the data (`--prior` on the command line).
    pub candidate_sigma: Vec<(usize, f64)>,
    /// Test only: when a candidate passes, name a pseudo-random one of the pool instead of the
    /// best, unconfirmed (a selector naming terms at random, which the evaluation must catch).
    pub broken_selector: bool,
}

impl Default for ExplainOptions {
    fn default() -> Self {
        ExplainOptions {
            alpha: 0.01,
            rho_equivalent: 0.9,
            max_rounds: 4,
            min_information: 1e-6,
            confound_cos: 0.999,
            max_prior_sigmas: 100.0,
            candidate_sigma: Vec::new(),
            broken_selector: false,
        }
    }
}

/// Where explain's IMU samples come from: memory (simulations), or a file read again on every
/// pass, so that memory does not grow with the file.
#[derive(Clone, Copy)]
pub enum ImuInput<'a> {
    /// Samples in memory.
    Memory(&'a ImuData),
    /// A file and its format description (`--imu`, `--imu-format`).
    File {
        /// The IMU file.
        path: &'a std::path::Path,
        /// Its format description, when given.
        format: Option<&'a std::path::Path>,
        /// GPST − IMU clock offset [s] (`--clock-offset`), when given.
        clock_offset: Option<f64>,
        /// Samples at or before this time [s] are skipped (a run that starts later than the
        /// file, `--init auto`).
        skip_through: f64,
    },
}

impl ImuInput<'_> {
    /// A fresh pass over the samples.
    pub fn samples(&self) -> anyhow::Result<Box<dyn filter::Samples + '_>> {
        Ok(match *self {
            ImuInput::Memory(d) => Box::new(filter::SliceSamples::new(&d.samples)),
            ImuInput::File {
                path,
                format,
                clock_offset,
                skip_through,
            } => {
                let mut s =
                    crate::io::imu_stream::ImuStream::open_with(path, format, clock_offset)?.0;
                s.skip_through(skip_through)?;
                Box::new(s)
            }
        })
    }
}

/// The data explain works on (the same as the filter's).
#[derive(Clone, Copy)]
pub struct ExplainData<'a> {
    /// IMU increments, FRD.
    pub imu: ImuInput<'a>,
    /// Aiding epochs.
    pub aid: &'a [AidingEpoch],
    /// Truth, when known (simulations).
    pub truth: Option<&'a [TruthRow]>,
    /// Initial navigation state.
    pub start: NavState,
}

/// Parses a candidate list: names and prefix groups (`kaq_*,kas_y,d_*`), or `None` for the
/// default: every spec term the baseline lacks. Unknown names are an error listing the nearest.
pub fn parse_candidates(spec: Option<&str>, baseline: &Model) -> Result<Vec<usize>, String> {
    let in_base = |t: usize| baseline.states.contains(&StateRef::Term(t));
    let Some(spec) = spec else {
        return Ok((0..common::TERM_COUNT).filter(|&t| !in_base(t)).collect());
    };
    let mut out = Vec::new();
    if spec.split(',').all(|s| s.trim().is_empty()) {
        return Err(
            "--candidates: the list is empty (give names or prefix groups, e.g. `kaq_*,d_x`, or leave the option out for every term)"
                .into(),
        );
    }
    for item in spec.split(',').map(str::trim).filter(|s| !s.is_empty()) {
        let matched: Vec<usize> = match item.strip_suffix('*') {
            Some(prefix) => (0..common::TERM_COUNT)
                .filter(|&t| common::TERMS[t].name.starts_with(prefix))
                .collect(),
            None => (0..common::TERM_COUNT)
                .filter(|&t| common::TERMS[t].name == item)
                .collect(),
        };
        if matched.is_empty() {
            return Err(format!(
                "--candidates: unknown term `{item}`{}",
                did_you_mean(item.trim_end_matches('*'))
            ));
        }
        for t in matched {
            if !out.contains(&t) {
                out.push(t);
            }
        }
    }
    Ok(out)
}

// ---------------------------------------------------------------- signatures

/// Candidate signatures riding along one filter pass.
struct Signatures {
    n: usize,
    /// Candidate term indices.
    cands: Vec<usize>,
    /// Baseline instrument terms: (model index, term index).
    base_terms: Vec<(usize, usize)>,
    /// Accumulator of the candidates' and baseline terms' regressors (ids below).
    acc: RegressorAccumulator,
    r_mean: Vec<f64>,
    /// D, state-major: D[i·m + c] is state i of candidate c's signature (the inner loops run
    /// over the candidates, so one A entry serves all of them).
    d: Vec<f64>,
    w: Vec<f64>,
    aw: Vec<f64>,
    g: Vec<f64>,
    /// Position in `r_mean` of each candidate's and each baseline term's regressor.
    cand_r: Vec<usize>,
    base_r_idx: Vec<usize>,
    /// Baseline terms' regressor means of the current step.
    base_r: Vec<f64>,
    /// For each candidate, (model index, row of its term column) of the rows it reaches.
    cand_rows: Vec<Vec<(usize, usize)>>,
    /// Mean NIS of the pass (the dispersion φ of the quasi-likelihood; 1 when consistent).
    dispersion: f64,
    /// Information J (m × m) and score b (m).
    info: Vec<f64>,
    score: Vec<f64>,
    /// Σ over steps of each candidate's regressor mean, and steps counted.
    reg_sum: Vec<f64>,
    steps: usize,
    /// Σ r_c r_b, Σ r_c², Σ r_b² over steps for candidates vs same-axis baseline terms.
    cross: Vec<f64>,
    cand_sq: Vec<f64>,
    base_sq: Vec<f64>,
    /// Excitation level per step: (t [s], rms of the specific force about its step mean [m/s²]).
    level: Vec<(f64, f64)>,
    f_sum: Vector3<f64>,
    f2_sum: f64,
    count: usize,
}

fn reg_id(t: usize) -> usize {
    common::TERMS[t].regressor
}

impl Signatures {
    fn new(model: &Model, cands: &[usize]) -> Signatures {
        let n = model.n();
        let base_terms: Vec<(usize, usize)> = model
            .states
            .iter()
            .enumerate()
            .filter_map(|(i, s)| match *s {
                StateRef::Term(t) => Some((i, t)),
                StateRef::Nav(_) => None,
            })
            .collect();
        let mut r_ids = Vec::new();
        for t in cands.iter().copied().chain(base_terms.iter().map(|b| b.1)) {
            if !r_ids.contains(&reg_id(t)) {
                r_ids.push(reg_id(t));
            }
        }
        let mut nav_pos = [None; common::NAV_COUNT];
        for (i, s) in model.states.iter().enumerate() {
            if let StateRef::Nav(k) = *s {
                nav_pos[k] = Some(i);
            }
        }
        let m = cands.len();
        let nb = base_terms.len();
        let pos = |t: usize| r_ids.iter().position(|&x| x == reg_id(t)).unwrap_or(0);
        let cand_r = cands.iter().map(|&t| pos(t)).collect();
        let base_r_idx = base_terms.iter().map(|b| pos(b.1)).collect();
        let cand_rows = cands
            .iter()
            .map(|&t| {
                common::TERM_ROWS[t]
                    .iter()
                    .filter_map(|&row| nav_pos[row].map(|i| (i, row)))
                    .collect()
            })
            .collect();
        Signatures {
            n,
            cands: cands.to_vec(),
            base_terms,
            acc: RegressorAccumulator::new(r_ids.clone()),
            r_mean: vec![0.0; r_ids.len()],
            d: vec![0.0; m * n],
            w: vec![0.0; m * n],
            aw: vec![0.0; m * n],
            g: vec![0.0; m],
            cand_r,
            base_r_idx,
            base_r: vec![0.0; nb],
            cand_rows,
            dispersion: 1.0,
            info: vec![0.0; m * m],
            score: vec![0.0; m],
            reg_sum: vec![0.0; m],
            steps: 0,
            cross: vec![0.0; m * nb],
            cand_sq: vec![0.0; m],
            base_sq: vec![0.0; nb],
            level: Vec::new(),
            f_sum: Vector3::zeros(),
            f2_sum: 0.0,
            count: 0,
        }
    }
}

/// out = A · v for m column vectors stored state-major (v[j·m + c]), over A's pattern.
fn sparse_mul_block(
    a: &[f64],
    n: usize,
    m: usize,
    pattern: &[(usize, usize)],
    v: &[f64],
    out: &mut [f64],
) {
    out.iter_mut().for_each(|x| *x = 0.0);
    for &(i, j) in pattern {
        let aij = a[i * n + j];
        let (src, dst) = (&v[j * m..(j + 1) * m], &mut out[i * m..(i + 1) * m]);
        for (o, x) in dst.iter_mut().zip(src) {
            *o += aij * x;
        }
    }
}

impl Observer for Signatures {
    fn sample(&mut self, f: &Vector3<f64>, w: &Vector3<f64>) {
        self.acc.add(f, w);
        self.f_sum += f;
        self.f2_sum += f.norm_squared();
        self.count += 1;
    }

    fn step(&mut self, t: f64, dt: f64, np: &NavPoint, a: &[f64], pattern: &[(usize, usize)]) {
        let (n, m) = (self.n, self.cands.len());
        self.acc.mean_into(&mut self.r_mean);
        self.acc.reset();
        if self.count > 0 {
            let c = self.count as f64;
            let mean = self.f_sum / c;
            let var = (self.f2_sum / c - mean.norm_squared()).max(0.0);
            self.level.push((t, var.sqrt()));
        }
        self.f_sum = Vector3::zeros();
        self.f2_sum = 0.0;
        self.count = 0;
        self.steps += 1;
        let nb = self.base_terms.len();
        for k in 0..nb {
            let r = self.r_mean[self.base_r_idx[k]];
            self.base_r[k] = r;
            self.base_sq[k] += r * r;
        }
        if m == 0 {
            return;
        }
        // W = A D + [a_c], then D ← D + dt (W + dt/2 A W)
        sparse_mul_block(a, n, m, pattern, &self.d, &mut self.w);
        for c in 0..m {
            let t_c = self.cands[c];
            let rv = self.r_mean[self.cand_r[c]];
            self.reg_sum[c] += rv;
            self.cand_sq[c] += rv * rv;
            let info = &common::TERMS[t_c];
            for (k, &(_, bt)) in self.base_terms.iter().enumerate() {
                let bi = &common::TERMS[bt];
                if bi.sensor == info.sensor && bi.axis == info.axis {
                    self.cross[c * nb + k] += rv * self.base_r[k];
                }
            }
            let mut col = [0.0; common::NAV_COUNT];
            common::term_column(t_c, np, rv, &mut col);
            for &(i, row) in &self.cand_rows[c] {
                self.w[i * m + c] += col[row];
            }
        }
        sparse_mul_block(a, n, m, pattern, &self.w, &mut self.aw);
        let h = 0.5 * dt;
        for ((di, wi), awi) in self.d.iter_mut().zip(&self.w).zip(&self.aw) {
            *di += dt * (wi + h * awi);
        }
    }

    fn scalar_update(
        &mut self,
        _t: f64,
        _meas: &'static str,
        _component: usize,
        h: &[f64],
        k: &[f64],
        nu: f64,
        s: f64,
    ) {
        let (n, m) = (self.n, self.cands.len());
        if m == 0 {
            return;
        }
        // G = H D (per candidate), then D ← D − K G
        self.g.iter_mut().for_each(|x| *x = 0.0);
        for (j, &hj) in h.iter().enumerate().take(n) {
            if hj != 0.0 {
                for (g, d) in self.g.iter_mut().zip(&self.d[j * m..(j + 1) * m]) {
                    *g += hj * d;
                }
            }
        }
        for (i, &ki) in k.iter().enumerate().take(n) {
            if ki != 0.0 {
                for (d, g) in self.d[i * m..(i + 1) * m].iter_mut().zip(&self.g) {
                    *d -= ki * g;
                }
            }
        }
        let inv_s = 1.0 / s;
        for a in 0..m {
            let ga = self.g[a] * inv_s;
            if ga == 0.0 {
                continue;
            }
            self.score[a] += ga * nu;
            for b in 0..m {
                self.info[a * m + b] += ga * self.g[b];
            }
        }
    }
}

// ---------------------------------------------------------------- innovation analysis

/// One segment of the run and what the innovations of one channel did in it.
#[derive(Debug, Clone, Serialize)]
pub struct SegmentStats {
    /// Start and end [s].
    pub t0: f64,
    /// End [s].
    pub t1: f64,
    /// Excitation level (rms specific force about its mean) [g].
    pub level_g: f64,
    /// Innovations in the segment.
    pub count: usize,
    /// Mean NIS.
    pub nis_mean: f64,
    /// Mean normalised innovation ν/√S (bias in σ units).
    pub bias_sigma: f64,
}

/// What the innovations of one channel say.
#[derive(Debug, Clone, Serialize)]
pub struct ChannelStats {
    /// `vel_n`, `vel_e`, `pos_n`, `pos_e`, `pos_h`.
    pub channel: String,
    /// Number of innovations.
    pub count: usize,
    /// Mean NIS (1 for a consistent filter).
    pub nis_mean: f64,
    /// 95 % band of the mean NIS for this count.
    pub nis_band: [f64; 2],
    /// Fraction of innovations outside the single-epoch 95 % band (0.05 expected).
    pub fraction_outside_95: f64,
    /// Ljung–Box Q and its p-value (whiteness of the normalised innovations), when computable.
    pub ljung_box_q: Option<f64>,
    /// Ljung–Box p-value.
    pub whiteness_p: Option<f64>,
    /// Per-segment statistics.
    pub segments: Vec<SegmentStats>,
}

/// With truth: the filter's predicted σ against its actual estimation error.
#[derive(Debug, Clone, Serialize)]
pub struct TruthCheck {
    /// State (`phi_n`, `phi_e`, `dlat`, `dlon`, …).
    pub state: String,
    /// RMS of the predicted 1-σ (display unit).
    pub predicted_sigma_rms: f64,
    /// RMS of the actual error of the estimate (display unit).
    pub actual_error_rms: f64,
    /// Display unit.
    pub unit: String,
}

/// What one filter pass says about its model.
#[derive(Debug, Clone, Serialize)]
pub struct PassStats {
    /// Model as a string.
    pub model: String,
    /// Time of the first innovation [s] (data time; the words count from here).
    pub t_start: f64,
    /// Total log-likelihood of the innovations, Σ −½(ν²/S + ln 2πS).
    pub loglik: f64,
    /// Mean NIS over all scalar innovations.
    pub nis_mean: f64,
    /// Smallest per-channel whiteness p, Bonferroni-corrected over the channels (capped at 1).
    pub whiteness_p: f64,
    /// Per channel.
    pub channels: Vec<ChannelStats>,
    /// Model error e = φ̂ − φ RMS north, east [arcsec] over the second half (with truth).
    pub model_error_rms_arcsec: Option<[f64; 2]>,
    /// Predicted σ against actual error (with truth).
    pub truth_check: Vec<TruthCheck>,
}

/// Segments of constant excitation: 1-s bins of the level merged while within 30 % (and
/// 0.05 g); runs shorter than 10 s join their neighbour; with one segment, ten fixed windows.
fn segments(level: &[(f64, f64)], t_start: f64, t_end: f64) -> Vec<(f64, f64, f64)> {
    let mut bins: Vec<(f64, f64, f64)> = Vec::new(); // (t0, t1, level)
    let mut k = 0;
    while k < level.len() {
        let t0 = level[k].0;
        let (mut s, mut c) = (0.0, 0usize);
        while k < level.len() && level[k].0 < t0 + 1.0 {
            s += level[k].1;
            c += 1;
            k += 1;
        }
        let t1 = level.get(k).map(|l| l.0).unwrap_or(t_end);
        bins.push((t0, t1, s / c.max(1) as f64));
    }
    let mut segs: Vec<(f64, f64, f64, usize)> = Vec::new(); // t0 t1 sum count
    for (t0, t1, l) in bins {
        if let Some(last) = segs.last_mut() {
            let mean = last.2 / last.3 as f64;
            if (l - mean).abs() <= (0.3 * mean).max(0.05 * G0) {
                last.1 = t1;
                last.2 += l;
                last.3 += 1;
                continue;
            }
        }
        segs.push((t0, t1, l, 1));
    }
    let mut merged: Vec<(f64, f64, f64, usize)> = Vec::new();
    for s in segs {
        match merged.last_mut() {
            Some(last) if s.1 - s.0 < 10.0 => {
                last.1 = s.1;
                last.2 += s.2;
                last.3 += s.3;
            }
            _ => merged.push(s),
        }
    }
    let mut out: Vec<(f64, f64, f64)> = merged
        .into_iter()
        .map(|(t0, t1, s, c)| (t0, t1, s / c as f64))
        .collect();
    if let Some(first) = out.first_mut() {
        first.0 = t_start;
    }
    if out.len() <= 1 && t_end - t_start > 60.0 {
        let lvl = out.first().map(|s| s.2).unwrap_or(0.0);
        let w = (t_end - t_start) / 10.0;
        out = (0..10)
            .map(|i| (t_start + i as f64 * w, t_start + (i + 1) as f64 * w, lvl))
            .collect();
    }
    out
}

/// Total log-likelihood of a run's innovations, Σ −½(ν²/S + ln 2πS).
pub fn innovation_loglik(run: &FilterRun) -> f64 {
    run.innovations
        .iter()
        .map(|i| -0.5 * (i.nu * i.nu / i.s + (2.0 * std::f64::consts::PI * i.s).ln()))
        .sum()
}

fn pass_stats(
    model: &Model,
    run: &FilterRun,
    level: &[(f64, f64)],
    truth: Option<&[TruthRow]>,
) -> PassStats {
    let t_start = run.innovations.first().map(|i| i.t).unwrap_or(0.0);
    let t_end = run.innovations.last().map(|i| i.t).unwrap_or(0.0);
    let segs = segments(level, t_start, t_end + 1e-9);
    let mut names: Vec<String> = Vec::new();
    for i in &run.innovations {
        let c = channel_name(i.meas, i.component);
        if !names.contains(&c) {
            names.push(c);
        }
    }
    let single = [
        stats::chi2_quantile(1.0, -1.959_964).max(0.0),
        3.841_458_820_694_124,
    ];
    let mut channels = Vec::new();
    let loglik = innovation_loglik(run);
    let (mut nis_all, mut n_all) = (0.0, 0usize);
    for i in &run.innovations {
        nis_all += i.nu * i.nu / i.s;
        n_all += 1;
    }
    let mut min_p: f64 = 1.0;
    for name in &names {
        let inn: Vec<_> = run
            .innovations
            .iter()
            .filter(|i| &channel_name(i.meas, i.component) == name)
            .collect();
        let normed: Vec<f64> = inn.iter().map(|i| i.nu / i.s.sqrt()).collect();
        let nis: Vec<f64> = normed.iter().map(|v| v * v).collect();
        let count = nis.len();
        let nis_mean = nis.iter().sum::<f64>() / count.max(1) as f64;
        let outside = nis.iter().filter(|&&v| v > single[1]).count() as f64 / count.max(1) as f64;
        let lags = (count / 5).clamp(1, 20);
        let lb = stats::ljung_box(&normed, lags);
        if let Some((_, p)) = lb {
            min_p = min_p.min(p);
        }
        let segments = segs
            .iter()
            .map(|&(t0, t1, lvl)| {
                let vals: Vec<f64> = inn
                    .iter()
                    .zip(&normed)
                    .filter(|(i, _)| i.t >= t0 && i.t < t1)
                    .map(|(_, v)| *v)
                    .collect();
                let c = vals.len().max(1) as f64;
                SegmentStats {
                    t0,
                    t1,
                    level_g: lvl / G0,
                    count: vals.len(),
                    nis_mean: vals.iter().map(|v| v * v).sum::<f64>() / c,
                    bias_sigma: vals.iter().sum::<f64>() / c,
                }
            })
            .filter(|s| s.count > 0)
            .collect();
        channels.push(ChannelStats {
            channel: name.clone(),
            count,
            nis_mean,
            nis_band: stats::mean_chi2_band(1.0, count.max(1), 1.959_964),
            fraction_outside_95: outside,
            ljung_box_q: lb.map(|x| x.0),
            whiteness_p: lb.map(|x| x.1),
            segments,
        });
    }
    let whiteness_p = (min_p * names.len().max(1) as f64).min(1.0);
    let half = 0.5 * (t_start + t_end);
    let model_error_rms_arcsec = filter::model_error_rms_arcsec(run, half, t_end + 1.0);
    let truth_check = truth.map(|_| truth_check(model, run)).unwrap_or_default();
    PassStats {
        model: model.name.clone(),
        t_start,
        loglik,
        nis_mean: nis_all / n_all.max(1) as f64,
        whiteness_p,
        channels,
        model_error_rms_arcsec,
        truth_check,
    }
}

fn truth_check(model: &Model, run: &FilterRun) -> Vec<TruthCheck> {
    let mut out = Vec::new();
    for (c, name) in ["phi_n", "phi_e"].iter().enumerate() {
        let Some(i) = model.index_of(name) else {
            continue;
        };
        let (mut se, mut ss, mut k) = (0.0, 0.0, 0usize);
        for r in &run.records {
            if let Some(pt) = r.phi_true {
                se += (r.phi_est[c] - pt[c]).powi(2);
                ss += r.sigma[i].powi(2);
                k += 1;
            }
        }
        if k > 0 {
            out.push(TruthCheck {
                state: name.to_string(),
                predicted_sigma_rms: (ss / k as f64).sqrt() * ARCSEC,
                actual_error_rms: (se / k as f64).sqrt() * ARCSEC,
                unit: "arcsec".into(),
            });
        }
    }
    for (c, name) in ["dlat", "dlon"].iter().enumerate() {
        let Some(i) = model.index_of(name) else {
            continue;
        };
        let (mut se, mut ss, mut k) = (0.0, 0.0, 0usize);
        for r in &run.records {
            if let Some(pe) = r.pos_err_ne {
                let scale = if c == 0 {
                    earth::radius_meridian(r.nav.lat) + r.nav.h
                } else {
                    (earth::radius_transverse(r.nav.lat) + r.nav.h) * r.nav.lat.cos()
                };
                se += (r.x[i] * scale - pe[c]).powi(2);
                ss += (r.sigma[i] * scale).powi(2);
                k += 1;
            }
        }
        if k > 0 {
            out.push(TruthCheck {
                state: ["pos_n", "pos_e"][c].to_string(),
                predicted_sigma_rms: (ss / k as f64).sqrt(),
                actual_error_rms: (se / k as f64).sqrt(),
                unit: "m".into(),
            });
        }
    }
    out
}

// ---------------------------------------------------------------- candidates and selection

/// One candidate's test in one pass.
#[derive(Debug, Clone, Serialize)]
pub struct CandidateTest {
    /// Term name.
    pub term: String,
    /// Group (spec).
    pub group: String,
    /// Information J·σ_prior² (the llr a 1-σ-prior effect would produce).
    pub information_prior_scaled: f64,
    /// GLR estimate θ̂ (display unit) and its σ, alone (not conditioned on other candidates).
    pub glr_estimate: f64,
    /// σ of the GLR estimate (display unit).
    pub glr_sigma: f64,
    /// Log-likelihood ratio b²/J, alone.
    pub llr: f64,
    /// χ²₁ p-value of the llr (uncorrected).
    pub p_value: f64,
    /// Holm-adjusted p-value over the testable candidates of this pass.
    pub p_holm: f64,
    /// False when the data carry no information on the term.
    pub testable: bool,
    /// Baseline term whose regressor sequence is proportional to this one's (|cos| > `confound_cos`).
    pub confounded_with: Option<String>,
    /// Display unit.
    pub unit: String,
}

/// A term explain adds to the model.
#[derive(Debug, Clone, Serialize)]
pub struct Finding {
    /// Canonical term name.
    pub term: String,
    /// Estimate from the extended filter (display unit).
    pub estimate: f64,
    /// Its 1-σ (display unit).
    pub sigma: f64,
    /// Display unit.
    pub unit: String,
    /// Conditional log-likelihood ratio when it was selected.
    pub llr: f64,
    /// Holm-corrected p-value when it was selected.
    pub p_value: f64,
    /// Candidates it cannot be told from on these data (its equivalence class, itself excluded).
    pub equivalent: Vec<String>,
    /// What each equivalent term would have to be to explain the same data.
    pub equivalent_estimates: Vec<EquivalentTerm>,
    /// GLR estimate when selected (display unit).
    pub glr_estimate: f64,
    /// Its σ (display unit).
    pub glr_sigma: f64,
    /// Filter pass (1 = baseline) in which it was selected.
    pub round: usize,
    /// Baseline term it is not separable from at the regressor level, if any.
    pub confounded_with: Option<String>,
    /// Mean regressor over the run, in g- or deg/s-units (`regressor_unit`).
    pub regressor_mean: f64,
    /// Unit of `regressor_mean`, e.g. `g^2`.
    pub regressor_unit: String,
    /// What the term does on these data: estimate × mean regressor, in `effect_unit`.
    pub effect: f64,
    /// `mg` (accelerometer) or `deg/h` (gyro).
    pub effect_unit: String,
    /// Which excitation would separate it from its equivalents.
    pub separate_by: Vec<String>,
    /// Prior σ the extended filter used (display unit): the spec's (or `--prior`), widened to
    /// 3 (|θ̂| + σ̂) when the GLR estimate θ̂ lies beyond 2 spec prior σ.
    pub prior_sigma: f64,
    /// True when the spec's prior σ was too small for what the data say.
    pub prior_widened: bool,
    /// The finding in words.
    pub words: String,
}

/// A term the data cannot tell from a finding, and the value it would need.
#[derive(Debug, Clone, Serialize)]
pub struct EquivalentTerm {
    /// Term name.
    pub term: String,
    /// GLR estimate in the finding's pass (display unit).
    pub estimate: f64,
    /// Its σ (display unit).
    pub sigma: f64,
    /// Display unit.
    pub unit: String,
    /// The estimate in units of the spec's prior σ (how plausible it is a priori).
    pub prior_sigmas: f64,
}

/// Before/after gain of the extended model.
#[derive(Debug, Clone, Serialize)]
pub struct Gain {
    /// Log-likelihood after − before.
    pub loglik: f64,
    /// Mean NIS before and after.
    pub nis_mean_before: f64,
    /// Mean NIS after.
    pub nis_mean_after: f64,
    /// Model error RMS (north, east combined as √(n²+e²)) before [arcsec] (with truth).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub model_error_rms_before: Option<f64>,
    /// Same, after.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub model_error_rms_after: Option<f64>,
}

/// Everything explain found.
#[derive(Debug, Clone, Serialize)]
pub struct Explanation {
    /// Baseline model states.
    pub model: Vec<String>,
    /// Baseline model string.
    pub baseline_model: String,
    /// Baseline pass.
    pub baseline: PassStats,
    /// Candidate tests of the baseline pass, best first.
    pub candidates: Vec<CandidateTest>,
    /// Terms added, in order.
    pub findings: Vec<Finding>,
    /// Candidates not testable on these data.
    pub not_testable: Vec<String>,
    /// Significant candidates not named because their value would be implausible.
    pub implausible: Vec<Implausible>,
    /// Terms the signatures selected but the extended filter did not confirm: (term, 2Δℓ of
    /// the round, its BIC penalty k ln N).
    pub unconfirmed: Vec<(String, f64, f64)>,
    /// Candidates whose regressor is proportional on these data to a baseline term's on the
    /// same sensor axis: (candidate, baseline term). Never named; the baseline term takes it up.
    pub not_separable: Vec<(String, String)>,
    /// Extended model string (baseline when nothing was found).
    pub extended_model: String,
    /// Extended model pass.
    pub extended: PassStats,
    /// Gain.
    pub gain: Gain,
    /// Filter passes made.
    pub rounds: usize,
    /// Options used.
    pub alpha: f64,
    /// Sentences for the terminal and the report.
    pub summary: Vec<String>,
    /// Normalised innovations (t, channel, ν/√S) of the baseline and extended passes, for plots.
    #[serde(skip)]
    pub innovations_before: Vec<(f64, String, f64)>,
    /// Same for the extended pass.
    #[serde(skip)]
    pub innovations_after: Vec<(f64, String, f64)>,
    /// Model error series (t [s], e_n, e_e [arcsec]) before and after (with truth).
    #[serde(skip)]
    pub model_error_before: Vec<(f64, f64, f64)>,
    /// Same, after.
    #[serde(skip)]
    pub model_error_after: Vec<(f64, f64, f64)>,
}

struct Pass {
    run: FilterRun,
    sig: Signatures,
    stats: PassStats,
}

fn run_pass(
    model: &Model,
    cands: &[usize],
    data: &ExplainData,
    cfg: &FilterConfig,
    progress: &mut dyn FnMut(f64),
) -> anyhow::Result<Pass> {
    let mut sig = Signatures::new(model, cands);
    let mut samples = data.imu.samples()?;
    let mut truth = data.truth.map(crate::io::truth::TruthSlice::new);
    let mut io = filter::StreamIo {
        samples: &mut *samples,
        aiding: &mut data.aid.iter().copied(),
        truth: truth
            .as_mut()
            .map(|t| t as &mut dyn crate::io::truth::TruthLookup),
    };
    let run = filter::run_stream(
        model,
        cfg,
        data.start,
        &mut io,
        progress,
        &mut |_| {},
        &mut sig,
        &mut |_| Ok(()),
        true,
    )?;
    run.check()
        .map_err(|e| anyhow::anyhow!("{} pass: {e}", model.name))?;
    let stats = pass_stats(model, &run, &sig.level, data.truth);
    sig.dispersion = stats.nis_mean;
    Ok(Pass { run, sig, stats })
}

/// Prior-scaled quantities of a pass: J' = D J D, b' = D b with D = diag(σ_prior).
fn scaled(sig: &Signatures, opts: &ExplainOptions) -> (DMatrix<f64>, Vec<f64>, Vec<f64>) {
    let m = sig.cands.len();
    let sd: Vec<f64> = sig
        .cands
        .iter()
        .map(|&t| prior_sigma(t, opts).max(f64::MIN_POSITIVE))
        .collect();
    // quasi-likelihood: innovations φ times larger than S predicts scale the information and
    // score by 1/φ, so an inconsistent baseline does not make every candidate significant
    let phi = sig.dispersion.max(1.0);
    let j = DMatrix::from_fn(m, m, |a, b| sig.info[a * m + b] * sd[a] * sd[b] / phi);
    let b = (0..m).map(|a| sig.score[a] * sd[a] / phi).collect();
    (j, b, sd)
}

/// Prior σ of term `t` (SI): the override in `opts`, else the spec's.
pub fn prior_sigma(t: usize, opts: &ExplainOptions) -> f64 {
    opts.candidate_sigma
        .iter()
        .find(|x| x.0 == t)
        .map(|x| x.1)
        .unwrap_or(common::TERMS[t].sigma)
}

/// Conditional information, score and correlation of candidate `c` given the set `s`.
fn conditional(j: &DMatrix<f64>, b: &[f64], s: &[usize], c: usize) -> (f64, f64) {
    if s.is_empty() {
        return (j[(c, c)], b[c]);
    }
    let jss = DMatrix::from_fn(s.len(), s.len(), |x, y| j[(s[x], s[y])]);
    let Some(inv) = jss.clone().try_inverse() else {
        return (0.0, 0.0);
    };
    let jcs = DMatrix::from_fn(1, s.len(), |_, y| j[(c, s[y])]);
    let bs = DMatrix::from_fn(s.len(), 1, |x, _| b[s[x]]);
    let i_c = j[(c, c)] - (&jcs * &inv * jcs.transpose())[(0, 0)];
    let b_c = b[c] - (&jcs * &inv * bs)[(0, 0)];
    (i_c, b_c)
}

fn conditional_rho(j: &DMatrix<f64>, s: &[usize], a: usize, c: usize) -> f64 {
    let cross = if s.is_empty() {
        j[(a, c)]
    } else {
        let jss = DMatrix::from_fn(s.len(), s.len(), |x, y| j[(s[x], s[y])]);
        match jss.try_inverse() {
            Some(inv) => {
                let ja = DMatrix::from_fn(1, s.len(), |_, y| j[(a, s[y])]);
                let jc = DMatrix::from_fn(s.len(), 1, |x, _| j[(s[x], c)]);
                j[(a, c)] - (&ja * &inv * &jc)[(0, 0)]
            }
            None => return 0.0,
        }
    };
    let (ia, _) = conditional(j, &vec![0.0; j.nrows()], s, a);
    let (ic, _) = conditional(j, &vec![0.0; j.nrows()], s, c);
    if ia <= 0.0 || ic <= 0.0 {
        return 0.0;
    }
    cross / (ia * ic).sqrt()
}

/// A candidate the selection names, with its equivalence class.
struct Selected {
    idx: usize,
    llr: f64,
    p: f64,
    glr: f64,
    glr_sigma: f64,
    /// The other members: (candidate index, conditional GLR estimate, σ, display unit).
    class: Vec<(usize, f64, f64)>,
}

/// Forward selection on one pass's joint information (prior-scaled) over the `eligible`
/// candidates, with `innovations` scalar innovations in the pass.
///
/// Each step takes the candidate with the largest conditional llr; it must pass Holm's test at
/// α over the candidates left *and* lower the BIC (llr > ln N). Candidates join its equivalence
/// class when their conditional signatures correlate at |ρ| > `rho_equivalent` *and* the data
/// do not prefer the best one by more than the α-level χ²₁ quantile (with much information,
/// |ρ| = 0.97 can still separate two terms). Within a class the data cannot choose, so the
/// member the spec's priors find most plausible (fewest prior σ) is named and the rest listed
/// with the value each would need.
fn forward_select(
    sig: &Signatures,
    eligible: &[bool],
    innovations: usize,
    opts: &ExplainOptions,
) -> (Vec<Selected>, Vec<Implausible>) {
    let (j, b, sd) = scaled(sig, opts);
    let m = sig.cands.len();
    let margin = stats::chi2_isf(opts.alpha, 1.0);
    let bic = (innovations.max(2) as f64).ln();
    let mut pool: Vec<usize> = (0..m).filter(|&c| eligible[c]).collect();
    let mut chosen: Vec<usize> = Vec::new();
    let mut out = Vec::new();
    let mut implausible = Vec::new();
    while !pool.is_empty() {
        // (llr, information, score) of c given the chosen set
        let cond = |c: usize, chosen: &[usize]| -> Option<(f64, f64, f64)> {
            let (ic, bc) = conditional(&j, &b, chosen, c);
            (ic > 1e-12 * j[(c, c)].max(f64::MIN_POSITIVE)).then(|| (bc * bc / ic, ic, bc))
        };
        let mut best: Option<(usize, f64)> = None;
        for &c in &pool {
            if let Some((llr, _, _)) = cond(c, &chosen) {
                if best.is_none_or(|x| llr > x.1) {
                    best = Some((c, llr));
                }
            }
        }
        let Some((c, llr)) = best else {
            break;
        };
        let p = stats::chi2_sf(llr, 1.0);
        if p * pool.len() as f64 > opts.alpha || llr <= bic {
            break;
        }
        let (c, llr) = if opts.broken_selector {
            let k = (chosen.len() * 7 + pool.len() * 13 + 5) % pool.len();
            (pool[k], cond(pool[k], &chosen).map(|x| x.0).unwrap_or(llr))
        } else {
            (c, llr)
        };
        let mut members: Vec<(usize, f64, f64)> = vec![]; // (cand, θ' prior-scaled, info)
        for &a in &pool {
            let equivalent = a == c
                || (conditional_rho(&j, &chosen, a, c).abs() > opts.rho_equivalent
                    && cond(a, &chosen).is_some_and(|(la, _, _)| llr - la < margin));
            if equivalent {
                if let Some((_, ia, ba)) = cond(a, &chosen) {
                    members.push((a, ba / ia, ia));
                }
            }
        }
        // name the most plausible member: the fewest prior σ
        members.sort_by(|x, y| x.1.abs().total_cmp(&y.1.abs()));
        let (named, theta, info) = members[0];
        let display = |a: usize, th: f64, ia: f64| {
            let to_display = sd[a] / common::TERMS[sig.cands[a]].display_to_si;
            (th * to_display, to_display / ia.sqrt())
        };
        let (glr, glr_sigma) = display(named, theta, info);
        let named_llr = cond(named, &chosen).map(|x| x.0).unwrap_or(llr);
        if theta.abs() > opts.max_prior_sigmas {
            // even the most plausible member would need an implausible value: not named
            for &(a, th, ia) in &members {
                let (e, s) = display(a, th, ia);
                implausible.push(Implausible {
                    term: common::TERMS[sig.cands[a]].name.to_string(),
                    estimate: e,
                    sigma: s,
                    unit: common::TERMS[sig.cands[a]].display.to_string(),
                    prior_sigmas: th.abs(),
                    llr: cond(a, &chosen).map(|x| x.0).unwrap_or(0.0),
                });
            }
            pool.retain(|a| !members.iter().any(|m| m.0 == *a));
            continue;
        }
        out.push(Selected {
            idx: named,
            llr: named_llr,
            p: (stats::chi2_sf(named_llr, 1.0) * pool.len() as f64).min(1.0),
            glr,
            glr_sigma,
            class: members[1..]
                .iter()
                .map(|&(a, th, ia)| {
                    let (e, s) = display(a, th, ia);
                    (a, e, s)
                })
                .collect(),
        });
        chosen.push(named);
        pool.retain(|a| !members.iter().any(|m| m.0 == *a));
    }
    (out, implausible)
}

/// A significant candidate explain does not name: its value would be implausibly large.
#[derive(Debug, Clone, Serialize)]
pub struct Implausible {
    /// Term name.
    pub term: String,
    /// The value it would need (display unit).
    pub estimate: f64,
    /// σ of that value (display unit).
    pub sigma: f64,
    /// Display unit.
    pub unit: String,
    /// |estimate| in prior σ.
    pub prior_sigmas: f64,
    /// Conditional log-likelihood ratio.
    pub llr: f64,
}

/// Every candidate's test alone in this pass, and which may be named: testable and not
/// proportional at the regressor level to a baseline term of the same sensor axis (that term's
/// state already absorbs it; what is left of its signature is the filter's transient).
fn candidate_tests(sig: &Signatures, opts: &ExplainOptions) -> (Vec<CandidateTest>, Vec<bool>) {
    let (j, b, sd) = scaled(sig, opts);
    let m = sig.cands.len();
    let nb = sig.base_terms.len();
    // testability is a property of the data's excitation, not of the dispersion
    let phi = sig.dispersion.max(1.0);
    let testable: Vec<bool> = (0..m)
        .map(|c| j[(c, c)] * phi > opts.min_information)
        .collect();
    let p: Vec<f64> = (0..m)
        .map(|c| {
            if testable[c] {
                stats::chi2_sf(b[c] * b[c] / j[(c, c)], 1.0)
            } else {
                1.0
            }
        })
        .collect();
    let tp: Vec<f64> = (0..m).filter(|&c| testable[c]).map(|c| p[c]).collect();
    let adj = stats::holm(&tp);
    let mut k = 0;
    let mut tests = Vec::new();
    for c in 0..m {
        let term = &common::TERMS[sig.cands[c]];
        let to_display = 1.0 / term.display_to_si;
        let p_holm = if testable[c] {
            k += 1;
            adj[k - 1]
        } else {
            1.0
        };
        let confounded_with = (0..nb)
            .filter(|&q| sig.cross[c * nb + q] != 0.0)
            .map(|q| {
                let cos = sig.cross[c * nb + q] / (sig.cand_sq[c] * sig.base_sq[q]).sqrt();
                (q, cos)
            })
            .filter(|(_, cos)| cos.abs() > opts.confound_cos)
            .max_by(|x, y| x.1.abs().total_cmp(&y.1.abs()))
            .map(|(q, _)| common::TERMS[sig.base_terms[q].1].name.to_string());
        let jcc = j[(c, c)];
        tests.push(CandidateTest {
            term: term.name.to_string(),
            group: term.group.to_string(),
            information_prior_scaled: jcc,
            glr_estimate: if testable[c] {
                b[c] / jcc * sd[c] * to_display
            } else {
                0.0
            },
            glr_sigma: if testable[c] {
                sd[c] / jcc.sqrt() * to_display
            } else {
                f64::INFINITY
            },
            llr: if testable[c] { b[c] * b[c] / jcc } else { 0.0 },
            p_value: p[c],
            p_holm,
            testable: testable[c],
            confounded_with,
            unit: term.display.to_string(),
        });
    }
    let eligible = tests
        .iter()
        .map(|t| t.testable && t.confounded_with.is_none())
        .collect();
    (tests, eligible)
}

/// Homogeneous degree of a regressor in the IMU signals (1 for f_x, |f_x|; 2 for f_x², f_x f_y,
/// ω²; 0 for a constant), found numerically.
fn regressor_degree(id: usize) -> i32 {
    let f = Vector3::new(3.1, -2.3, 1.7);
    let w = Vector3::new(0.7, -0.4, 0.9);
    let r1 = common::regressor_value(id, &f, &w);
    let r2 = common::regressor_value(id, &(f * 2.0), &(w * 2.0));
    if r1 == 0.0 || r2 == 0.0 {
        return 0;
    }
    (r2 / r1).abs().log2().round() as i32
}

/// Which body signals a regressor depends on (`f.x` … `w.z`).
fn regressor_signals(id: usize) -> Vec<&'static str> {
    let names = ["f.x", "f.y", "f.z", "w.x", "w.y", "w.z"];
    let base_f = Vector3::new(3.1, -2.3, 1.7);
    let base_w = Vector3::new(0.7, -0.4, 0.9);
    let r0 = common::regressor_value(id, &base_f, &base_w);
    (0..6)
        .filter(|&k| {
            let (mut f, mut w) = (base_f, base_w);
            if k < 3 {
                f[k] *= 1.37;
            } else {
                w[k - 3] *= 1.37;
            }
            (common::regressor_value(id, &f, &w) - r0).abs() > 1e-12 * r0.abs().max(1.0)
        })
        .map(|k| names[k])
        .collect()
}

/// What excitation would separate two terms, from their sensors and regressors.
pub fn separation_hint(a: usize, b: usize) -> String {
    let (ta, tb) = (&common::TERMS[a], &common::TERMS[b]);
    let (da, db) = (
        regressor_degree(ta.regressor),
        regressor_degree(tb.regressor),
    );
    let (sa, sb) = (
        regressor_signals(ta.regressor),
        regressor_signals(tb.regressor),
    );
    let ra = common::REGRESSORS[ta.regressor];
    let rb = common::REGRESSORS[tb.regressor];
    if ta.sensor != tb.sensor {
        return format!(
            "a {} term and a {} term: a longer run or a re-orientation separates them (a gyro error grows the tilt ∝ t after onset, an accelerometer error the velocity)",
            sensor_word(ta.sensor),
            sensor_word(tb.sensor)
        );
    }
    if sa != sb {
        let only = |x: &[&str], y: &[&str]| -> Vec<String> {
            x.iter()
                .filter(|s| !y.contains(s))
                .map(|s| s.to_string())
                .collect()
        };
        let mut diff = only(&sa, &sb);
        diff.extend(only(&sb, &sa));
        return format!(
            "an excitation that changes {} while the other signals stay (a re-orientation, or vibration along that axis) separates {} ({ra}) from {} ({rb})",
            diff.join(" and "),
            ta.name,
            tb.name
        );
    }
    if da != db {
        return format!(
            "two vibration amplitudes separate {} (∝ A^{da}, regressor {ra}) from {} (∝ A^{db}, regressor {rb})",
            ta.name, tb.name
        );
    }
    if ta.axis != tb.axis {
        return format!(
            "a re-orientation (another attitude) separates the {} and {} axes",
            ["x", "y", "z"][ta.axis],
            ["x", "y", "z"][tb.axis]
        );
    }
    format!(
        "an excitation where {ra} and {rb} are not proportional (e.g. a sign change: attitude or vibration phase)"
    )
}

fn sensor_word(s: Sensor) -> &'static str {
    match s {
        Sensor::Gyro => "gyro",
        Sensor::Accel => "accelerometer",
    }
}

/// Mean regressor in natural units: g^k (accelerations) or (deg/s)^k (rates); with its unit.
fn regressor_in_natural_units(id: usize, mean_si: f64) -> (f64, String) {
    let deg = regressor_degree(id);
    let sig = regressor_signals(id);
    if deg == 0 {
        return (mean_si, "1".into());
    }
    if sig.iter().all(|s| s.starts_with('f')) {
        (
            mean_si / G0.powi(deg),
            if deg == 1 {
                "g".into()
            } else {
                format!("g^{deg}")
            },
        )
    } else if sig.iter().all(|s| s.starts_with('w')) {
        let d = std::f64::consts::PI / 180.0;
        (
            mean_si / d.powi(deg),
            if deg == 1 {
                "deg/s".into()
            } else {
                format!("(deg/s)^{deg}")
            },
        )
    } else {
        (mean_si, "SI".into())
    }
}

/// Runs explain: baseline pass, selection, re-tests, extended pass, gain. `config_for` gives the
/// filter configuration of a model (the same data options for all passes); `progress(pass,
/// fraction)` reports each pass.
pub fn explain(
    baseline: &Model,
    cands: &[usize],
    data: &ExplainData,
    config_for: &dyn Fn(&Model) -> anyhow::Result<FilterConfig>,
    opts: &ExplainOptions,
    progress: &mut dyn FnMut(usize, f64),
) -> anyhow::Result<Explanation> {
    let cands: Vec<usize> = cands
        .iter()
        .copied()
        .filter(|&t| !baseline.states.contains(&StateRef::Term(t)))
        .collect();
    let cfg = config_for(baseline)?;
    let base = run_pass(baseline, &cands, data, &cfg, &mut |f| progress(1, f))?;
    let base_pass_stats = base.stats.clone();
    let innovations_before = normalised(&base.run);
    let model_error_before = model_error_series(&base.run);
    let (tests, eligible) = candidate_tests(&base.sig, opts);
    let not_testable: Vec<String> = tests
        .iter()
        .filter(|t| !t.testable)
        .map(|t| t.term.clone())
        .collect();
    let not_separable: Vec<(String, String)> = tests
        .iter()
        .filter(|t| t.testable)
        .filter_map(|t| Some((t.term.clone(), t.confounded_with.clone()?)))
        .collect();
    let mut findings: Vec<Finding> = Vec::new();
    let mut excluded: Vec<usize> = Vec::new(); // term indices in a class or added
    let mut model = baseline.clone();
    let mut pass = base;
    let mut implausible: Vec<Implausible> = Vec::new();
    let (mut selected_now, imp) =
        forward_select(&pass.sig, &eligible, pass.run.innovations.len(), opts);
    implausible.extend(imp);
    let mut rounds = 1;
    let mut pool_terms: Vec<usize> = cands.clone();
    let mut widened: Vec<(usize, f64)> = Vec::new(); // (term, least prior σ, SI)
    let mut unconfirmed: Vec<(String, f64, f64)> = Vec::new(); // (term, 2Δℓ, penalty)
    let config_ext = |m: &Model, widened: &[(usize, f64)]| -> anyhow::Result<FilterConfig> {
        let mut cfg = config_for(m)?;
        // an added term starts from its candidate prior (the data's sensor class) …
        for &(t, sigma) in &opts.candidate_sigma {
            if !baseline.states.contains(&StateRef::Term(t)) {
                if let Some(i) = m.index_of(common::TERMS[t].name) {
                    cfg.prior_sigma[i] = sigma;
                }
            }
        }
        // … widened where the data put it beyond
        for &(t, sigma) in widened {
            if let Some(i) = m.index_of(common::TERMS[t].name) {
                cfg.prior_sigma[i] = cfg.prior_sigma[i].max(sigma);
            }
        }
        Ok(cfg)
    };
    loop {
        if selected_now.is_empty() {
            break;
        }
        let mut added = Vec::new();
        let (findings_before, widened_before) = (findings.len(), widened.len());
        for s in &selected_now {
            let t = pass.sig.cands[s.idx];
            let class: Vec<usize> = s.class.iter().map(|c| pass.sig.cands[c.0]).collect();
            excluded.push(t);
            excluded.extend(&class);
            let tests_now = candidate_tests(&pass.sig, opts).0;
            findings.push(Finding {
                term: common::TERMS[t].name.to_string(),
                estimate: 0.0,
                sigma: 0.0,
                unit: common::TERMS[t].display.to_string(),
                llr: s.llr,
                p_value: s.p,
                equivalent: class
                    .iter()
                    .map(|&c| common::TERMS[c].name.to_string())
                    .collect(),
                equivalent_estimates: s
                    .class
                    .iter()
                    .map(|&(c, estimate, sigma)| {
                        let tc = pass.sig.cands[c];
                        let info = &common::TERMS[tc];
                        EquivalentTerm {
                            term: info.name.to_string(),
                            estimate,
                            sigma,
                            unit: info.display.to_string(),
                            prior_sigmas: estimate * info.display_to_si / prior_sigma(tc, opts),
                        }
                    })
                    .collect(),
                glr_estimate: s.glr,
                glr_sigma: s.glr_sigma,
                round: rounds,
                confounded_with: tests_now[s.idx].confounded_with.clone(),
                regressor_mean: 0.0,
                regressor_unit: String::new(),
                effect: 0.0,
                effect_unit: String::new(),
                separate_by: class.iter().map(|&c| separation_hint(t, c)).collect(),
                prior_sigma: 0.0,
                prior_widened: false,
                words: String::new(),
            });
            // the extended filter's prior must hold what the data say: a GLR estimate beyond
            // 2 prior σ widens it to 3 (|θ̂| + σ̂)
            let info_t = &common::TERMS[t];
            if s.glr.abs() * info_t.display_to_si > 2.0 * prior_sigma(t, opts) {
                widened.push((t, 3.0 * (s.glr.abs() + s.glr_sigma) * info_t.display_to_si));
            }
            added.push(t);
        }
        let mut text = model.name.clone();
        for &t in &added {
            text.push('+');
            text.push_str(common::TERMS[t].name);
        }
        let next_model = Model::parse(&text)?;
        pool_terms.retain(|t| !excluded.contains(t));
        let last_round = rounds >= opts.max_rounds;
        let cfg = config_ext(&next_model, &widened)?;
        let next_pass = run_pass(
            &next_model,
            if last_round { &[] } else { &pool_terms },
            data,
            &cfg,
            &mut |f| progress(rounds + 1, f),
        )?;
        rounds += 1;
        // the filter must confirm what the signatures predicted: the added terms must raise the
        // log-likelihood by more than their BIC penalty (k ln N); else the linearisation did not
        // hold (or the misfit is something else) and the round is undone
        let gain = next_pass.stats.loglik - pass.stats.loglik;
        let penalty = added.len() as f64 * (next_pass.run.innovations.len().max(2) as f64).ln();
        if 2.0 * gain <= penalty && !opts.broken_selector {
            unconfirmed.extend(
                added
                    .iter()
                    .map(|&t| (common::TERMS[t].name.to_string(), 2.0 * gain, penalty)),
            );
            findings.truncate(findings_before);
            widened.truncate(widened_before);
            break;
        }
        model = next_model;
        pass = next_pass;
        if last_round {
            break;
        }
        let (_, eligible_now) = candidate_tests(&pass.sig, opts);
        let (sel, imp) = forward_select(&pass.sig, &eligible_now, pass.run.innovations.len(), opts);
        selected_now = sel;
        for i in imp {
            if !implausible.iter().any(|x| x.term == i.term) {
                implausible.push(i);
            }
        }
    }
    implausible.retain(|i| !findings.iter().any(|f| f.term == i.term));
    // the extended pass is the last one run (the baseline itself when nothing was found)
    let extended_stats = pass.stats.clone();
    let last = pass.run.records.last();
    let finding_terms: Vec<usize> = findings
        .iter()
        .map(|f| {
            common::TERMS
                .iter()
                .position(|x| x.name == f.term)
                .expect("finding is a spec term")
        })
        .collect();
    let means = if finding_terms.is_empty() {
        Vec::new()
    } else {
        regressor_means(data, &finding_terms)?
    };
    for (k, f) in findings.iter_mut().enumerate() {
        let t = finding_terms[k];
        let info = &common::TERMS[t];
        let to_display = 1.0 / info.display_to_si;
        if let (Some(i), Some(r)) = (model.index_of(info.name), last) {
            f.estimate = r.x[i] * to_display;
            f.sigma = r.sigma[i] * to_display;
            let used = config_ext(&model, &widened)?.prior_sigma[i];
            f.prior_sigma = used * to_display;
            f.prior_widened = used > prior_sigma(t, opts);
        }
        let c = means[k];
        let (rm, ru) = regressor_in_natural_units(info.regressor, c);
        f.regressor_mean = rm;
        f.regressor_unit = ru;
        let effect_si = f.estimate / to_display * c;
        let (effect, eu) = match info.sensor {
            Sensor::Accel => (effect_si / G0 * 1e3, "mg"),
            Sensor::Gyro => (effect_si * 180.0 / std::f64::consts::PI * 3600.0, "deg/h"),
        };
        f.effect = effect;
        f.effect_unit = eu.into();
        f.words = finding_words(f, info, prior_sigma(t, opts) / info.display_to_si);
    }
    let gain = Gain {
        loglik: extended_stats.loglik - base_pass_stats.loglik,
        nis_mean_before: base_pass_stats.nis_mean,
        nis_mean_after: extended_stats.nis_mean,
        model_error_rms_before: base_pass_stats
            .model_error_rms_arcsec
            .map(|e| e[0].hypot(e[1])),
        model_error_rms_after: extended_stats
            .model_error_rms_arcsec
            .map(|e| e[0].hypot(e[1])),
    };
    let mut ranked = tests;
    ranked.sort_by(|a, b| b.llr.total_cmp(&a.llr));
    let mut expl = Explanation {
        model: baseline.names.iter().map(|s| s.to_string()).collect(),
        baseline_model: baseline.name.clone(),
        baseline: base_pass_stats,
        candidates: ranked,
        findings,
        not_testable,
        implausible,
        unconfirmed,
        not_separable,
        extended_model: model.name.clone(),
        extended: extended_stats,
        gain,
        rounds,
        alpha: opts.alpha,
        summary: Vec::new(),
        innovations_before,
        innovations_after: normalised(&pass.run),
        model_error_before,
        model_error_after: model_error_series(&pass.run),
    };
    expl.summary = summary(&expl);
    Ok(expl)
}

/// Mean over the run of each term's regressor (SI), in one pass over the IMU samples (the
/// extended pass has no candidates, so it is computed from the samples directly).
fn regressor_means(data: &ExplainData, terms: &[usize]) -> anyhow::Result<Vec<f64>> {
    let mut prev = data.start.t;
    let mut sums = vec![0.0; terms.len()];
    let mut c = 0usize;
    let mut samples = data.imu.samples()?;
    while let Some(smp) = samples.next_sample()? {
        let dt = smp.t - prev;
        prev = smp.t;
        if dt > 0.0 {
            let (f, w) = (smp.dv / dt, smp.dtheta / dt);
            for (sum, &t) in sums.iter_mut().zip(terms) {
                *sum += common::regressor_value(common::TERMS[t].regressor, &f, &w);
            }
            c += 1;
        }
    }
    Ok(sums.into_iter().map(|s| s / c.max(1) as f64).collect())
}

fn normalised(run: &FilterRun) -> Vec<(f64, String, f64)> {
    run.innovations
        .iter()
        .map(|i| (i.t, channel_name(i.meas, i.component), i.nu / i.s.sqrt()))
        .collect()
}

fn model_error_series(run: &FilterRun) -> Vec<(f64, f64, f64)> {
    run.records
        .iter()
        .filter_map(|r| {
            r.phi_true.map(|pt| {
                (
                    r.t,
                    (r.phi_est.x - pt.x) * ARCSEC,
                    (r.phi_est.y - pt.y) * ARCSEC,
                )
            })
        })
        .collect()
}

fn finding_words(
    f: &Finding,
    info: &crate::model::catalog::TermInfo,
    prior_display: f64,
) -> String {
    let sensor = sensor_word(info.sensor);
    let axis = ["x", "y", "z"][info.axis];
    let reg = common::REGRESSORS[info.regressor];
    let group = info
        .group
        .trim_start_matches("accel ")
        .trim_start_matches("gyro ");
    let mut s = format!(
        "{sensor} {axis} {group} {} = {} ± {} {} (extended filter): with the data's mean {reg} of {} {} it acts as a {} {} {} along {axis}",
        f.term,
        sig3(f.estimate),
        sig3(f.sigma),
        f.unit,
        sig3(f.regressor_mean),
        f.regressor_unit,
        sig3(f.effect),
        f.effect_unit,
        if info.sensor == Sensor::Accel { "bias" } else { "drift" },
    );
    if !f.equivalent.is_empty() {
        let others: Vec<String> = f
            .equivalent_estimates
            .iter()
            .map(|e| {
                format!(
                    "{} (would need {} ± {} {} by the signatures, {} prior σ)",
                    e.term,
                    sig3(e.estimate),
                    sig3(e.sigma),
                    e.unit,
                    sig3(e.prior_sigmas.abs())
                )
            })
            .collect();
        s.push_str(&format!(
            "; the data cannot separate it from {} (equivalence class; named: the one the spec's priors find most plausible); {}",
            others.join(", "),
            f.separate_by.join("; ")
        ));
    }
    if f.prior_widened {
        s.push_str(&format!(
            "; at {} prior σ ({} {}) the extended filter starts it with σ {} {} (`--prior '{}={} {}'`)",
            sig3(f.estimate.abs() / prior_display),
            sig3(prior_display),
            f.unit,
            sig3(f.prior_sigma),
            f.unit,
            f.term,
            sig3(f.prior_sigma),
            f.unit
        ));
    }
    if let Some(b) = &f.confounded_with {
        s.push_str(&format!(
            "; on these data its regressor is proportional to that of the baseline term {b}, so part of it may be taken up there"
        ));
    }
    s
}

/// A number with three significant digits, plain (no exponent) where that reads well.
pub fn sig3(v: f64) -> String {
    if !v.is_finite() {
        return "not determined".into();
    }
    let a = v.abs();
    if a != 0.0 && !(1e-3..1e5).contains(&a) {
        format!("{v:.2e}")
    } else if a >= 100.0 {
        format!("{v:.0}")
    } else if a >= 10.0 {
        format!("{v:.1}")
    } else if a >= 1.0 {
        format!("{v:.2}")
    } else {
        format!("{v:.3}")
    }
}

fn channel_word(c: &str) -> String {
    match c {
        "vel_n" => "north velocity".into(),
        "vel_e" => "east velocity".into(),
        "pos_n" => "north position".into(),
        "pos_e" => "east position".into(),
        "pos_h" => "height".into(),
        other => other.to_string(),
    }
}

/// The plain-words summary: what the baseline gets wrong, what was found, the gain.
fn summary(e: &Explanation) -> Vec<String> {
    let mut out = Vec::new();
    // data times (GPS seconds on real data) are counted from the first update when large
    let t_ref = if e.baseline.t_start.abs() > 1e5 {
        e.baseline.t_start.floor()
    } else {
        0.0
    };
    let mut consistent = true;
    for ch in &e.baseline.channels {
        let inconsistent = ch.nis_mean > ch.nis_band[1] * 1.5
            || ch
                .whiteness_p
                .is_some_and(|p| p * e.baseline.channels.len() as f64 <= 0.01);
        if !inconsistent {
            continue;
        }
        consistent = false;
        let worst = ch
            .segments
            .iter()
            .max_by(|a, b| a.nis_mean.total_cmp(&b.nis_mean));
        match worst {
            Some(sg) if sg.nis_mean > ch.nis_band[1] => out.push(format!(
                "{} innovations are {}× larger than the model predicts during {:.0}–{:.0} s{} (mean NIS {}), biased by {:+.1}σ; the model does not explain the data there.",
                channel_word(&ch.channel),
                sig3(sg.nis_mean.sqrt()),
                sg.t0 - t_ref,
                sg.t1 - t_ref,
                if t_ref != 0.0 { " from the first update" } else { "" },
                sig3(sg.nis_mean),
                sg.bias_sigma
            )),
            _ => out.push(format!(
                "{} innovations are correlated in time (Ljung–Box p {}): the model misses a slow effect.",
                channel_word(&ch.channel),
                ch.whiteness_p.map(sig3).unwrap_or_default()
            )),
        }
    }
    for ch in &e.baseline.channels {
        if ch.nis_mean < 0.5 * ch.nis_band[0] {
            consistent = false;
            out.push(format!(
                "{} innovations are {}× smaller than the model predicts (mean NIS {}): its measurement or process noise is set too high for these data.",
                channel_word(&ch.channel),
                sig3((1.0 / ch.nis_mean.max(1e-12)).sqrt()),
                sig3(ch.nis_mean)
            ));
        }
    }
    if consistent {
        out.push(format!(
            "The baseline {} is consistent with the data: mean NIS {} and white innovations in every channel.",
            e.baseline_model,
            sig3(e.baseline.nis_mean)
        ));
    }
    if e.findings.is_empty() {
        let nameable = e
            .candidates
            .iter()
            .filter(|c| c.testable && c.confounded_with.is_none())
            .count();
        let masked = e
            .candidates
            .iter()
            .filter(|c| c.testable && c.confounded_with.is_some() && c.p_holm <= e.alpha)
            .count();
        let mut line = format!(
            "No candidate that could be named is significant at α = {} (Holm over the {} testable ones that are separable from the baseline)",
            e.alpha, nameable
        );
        if masked > 0 {
            line.push_str(&format!(
                "; {masked} significant alone are not separable from a baseline term (listed below)"
            ));
        }
        line.push('.');
        out.push(line);
    }
    for f in &e.findings {
        out.push(format!("Found: {}.", f.words));
    }
    if !e.findings.is_empty() {
        let mut s = format!(
            "Extended model {}: mean NIS {} → {}, log-likelihood {:+.1}",
            e.extended_model,
            sig3(e.gain.nis_mean_before),
            sig3(e.gain.nis_mean_after),
            e.gain.loglik
        );
        if let (Some(b), Some(a)) = (e.gain.model_error_rms_before, e.gain.model_error_rms_after) {
            s.push_str(&format!(
                "; model error (truth) {} → {} arcsec RMS ({}× smaller)",
                sig3(b),
                sig3(a),
                sig3(b / a)
            ));
        }
        s.push('.');
        out.push(s);
    }
    if !e.implausible.is_empty() {
        let list: Vec<String> = e
            .implausible
            .iter()
            .map(|i| {
                format!(
                    "{} (would need {} ± {} {}, {} prior σ)",
                    i.term,
                    sig3(i.estimate),
                    sig3(i.sigma),
                    i.unit,
                    sig3(i.prior_sigmas)
                )
            })
            .collect();
        out.push(format!(
            "Significant but not named, their values would be implausible (a weak signature fitting some other mismatch; if your sensor can have such errors, widen its prior with --prior): {}.",
            list.join(", ")
        ));
    }
    if !e.unconfirmed.is_empty() {
        let names: Vec<&str> = e.unconfirmed.iter().map(|u| u.0.as_str()).collect();
        let (g, p) = (e.unconfirmed[0].1, e.unconfirmed[0].2);
        out.push(format!(
            "The signatures pointed at {} but the filter with them did not confirm it (2Δ log-likelihood {} against a BIC penalty of {}): not named; the misfit is something the candidates do not describe.",
            names.join(", "),
            sig3(g),
            sig3(p)
        ));
    }
    if !e.not_separable.is_empty() {
        let list: Vec<String> = e
            .not_separable
            .iter()
            .map(|(c, b)| format!("{c} (like {b})"))
            .collect();
        out.push(format!(
            "Not separable from a baseline term on these data (its regressor is proportional to that term's, whose state takes it up): {}.",
            list.join(", ")
        ));
    }
    if !e.not_testable.is_empty() {
        out.push(format!(
            "Not testable on these data (no information): {}.",
            e.not_testable.join(", ")
        ));
    }
    out
}

/// Information (SI, 1/θ²) the signature of term `term` carries through `model`'s filter on
/// these data: λ = θ² I is the noncentrality of its test (independent of θ and of the data's
/// values, so it can be computed before the term is put into the data).
pub fn signature_information(
    model: &Model,
    term: usize,
    data: &ExplainData,
    cfg: &FilterConfig,
) -> anyhow::Result<f64> {
    let pass = run_pass(model, &[term], data, cfg, &mut |_| {})?;
    Ok(pass.sig.info[0])
}
