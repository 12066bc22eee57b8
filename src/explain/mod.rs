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

mod diagnostics;
mod findings;
mod noise;
mod offset_lever;
mod offset_order;
mod raw_noise;
pub mod restamp;
mod rivals;
mod selection;
mod signatures;
mod withheld;
mod words;

pub use diagnostics::{
    innovation_loglik, ChannelStats, PassStats, ResidualStructure, SegmentStats, TruthCheck,
};
pub use findings::{
    CandidateTest, Consistency, EquivalentTerm, Explanation, Finding, Gain, GroupEstimate,
    Implausible, Normalised, TightPrior, Unnamed,
};
pub use selection::prior_sigma;
pub use words::{finding_line, separation_hint, share_percent, sig3, verdict};

use crate::estimate::filter::{self, AidingEpoch, FilterConfig, FilterRun};
use crate::estimate::nav_tape::{self, NavTape, TapeRecorder};
use crate::estimate::stats;
use crate::io::imu::ImuData;
use crate::io::truth::TruthRow;
use crate::io::warnings::warn;
use crate::model::catalog::{Sensor, StateRef};
use crate::model::generated::common;
use crate::model::{did_you_mean, Model};
use crate::nav::strapdown::NavState;
use diagnostics::pass_stats;
use selection::{candidate_tests, forward_select, Selected};
use signatures::{Signatures, Split};

/// Median aided speed [m/s] below which the updates are not split by speed (a static or
/// walking run's speeds are the fixes' noise).
const MIN_SPLIT_SPEED: f64 = 0.5;
use words::{finding_words, regressor_in_natural_units, summary};

/// Standard gravity [m/s²] for expressing regressors in g.
pub(crate) const G0: f64 = 9.806_65;
/// Arcseconds per radian.
pub(crate) use crate::estimate::metrics::ARCSEC_PER_RAD as ARCSEC;

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
    /// A finding whose estimate exceeds this many prior σ is reported as probably standing in
    /// for an effect the candidates do not describe.
    pub stand_in_prior_sigmas: f64,
    /// A finding that removes less than this fraction of the baseline's excess mean NIS, while
    /// more than half of it is left, is reported as probably standing in (same reason).
    pub stand_in_share: f64,
    /// Test the noise levels (white noise, aiding σ) when the extended model is inconsistent.
    pub noise_levels: bool,
    /// Replay the first open-loop pass's navigation in the later passes that navigate alike
    /// (samples in memory only; [`TapeSlot`]). Bit-identical either way: false is the
    /// comparison that shows it.
    pub share_navigation: bool,
    /// When an open-loop baseline pass drifts beyond small angles (the filter's attitude error
    /// estimate past [`MAX_OPEN_LOOP_TILT`]), run closed loop instead (false: keep open loop and
    /// warn; the command line's explicit `--mode open`).
    pub closed_loop_on_drift: bool,
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
            stand_in_prior_sigmas: 30.0,
            stand_in_share: 0.2,
            noise_levels: true,
            candidate_sigma: Vec::new(),
            share_navigation: true,
            closed_loop_on_drift: true,
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
        /// The file as it was when the run began: every pass checks it still is.
        identity: Option<FileIdentity>,
    },
}

/// What identifies a file's content cheaply: size, modification time and a hash of its first
/// 64 KiB.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FileIdentity {
    len: u64,
    modified: Option<std::time::SystemTime>,
    head_hash: u64,
}

impl FileIdentity {
    /// The identity of the file at `path` now.
    pub fn of(path: &std::path::Path) -> anyhow::Result<FileIdentity> {
        use std::io::Read;
        let meta = std::fs::metadata(path)
            .map_err(|e| anyhow::anyhow!("{}: cannot read: {e}", path.display()))?;
        let mut head = Vec::new();
        std::fs::File::open(path)
            .and_then(|f| f.take(64 << 10).read_to_end(&mut head))
            .map_err(|e| anyhow::anyhow!("{}: cannot read: {e}", path.display()))?;
        // FNV-1a
        let head_hash = head.iter().fold(0xcbf2_9ce4_8422_2325u64, |h, &b| {
            (h ^ b as u64).wrapping_mul(0x0100_0000_01b3)
        });
        Ok(FileIdentity {
            len: meta.len(),
            modified: meta.modified().ok(),
            head_hash,
        })
    }
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
                identity,
            } => {
                // explain reads the file once per pass: a file replaced meanwhile would give a
                // report built from two data sets
                if let Some(id) = identity {
                    if FileIdentity::of(path)? != id {
                        anyhow::bail!(
                            "--imu {}: the file changed while explain was running (its size, modification time or first 64 KiB differ from when the run began); a report from two data sets would be wrong: run again on a file that stays put",
                            path.display()
                        );
                    }
                }
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
    /// Where the passes keep and find the data's navigation (None: every pass navigates).
    pub tape: Option<&'a TapeSlot>,
}

/// The navigation of explain's first open-loop pass over samples in memory, replayed by the
/// later passes that navigate alike ([`crate::estimate::nav_tape`]): one per explain run. A
/// file's samples get none: explain reads a file again on every pass so that its memory does
/// not grow with the input, and a tape would (about 44 kB per second of data).
pub struct TapeSlot {
    /// Which samples the tape is of (None: a file, no tape).
    source: Option<(usize, usize, u64)>,
    /// Set by the first open-loop pass: its tape, or None when it could not be kept.
    tape: std::sync::OnceLock<Option<NavTape>>,
}

impl TapeSlot {
    /// An empty slot for the samples of `imu`.
    pub fn new(imu: &ImuInput) -> TapeSlot {
        TapeSlot {
            source: source_id(imu),
            tape: std::sync::OnceLock::new(),
        }
    }

    /// The slot's tape when it is of `data`'s samples and a pass with `cfg` over them fits it.
    fn tape_for(&self, cfg: &FilterConfig, data: &ExplainData) -> Option<&NavTape> {
        self.tape
            .get()
            .and_then(|t| t.as_ref())
            .filter(|t| self.holds(data) && t.fits(cfg, &data.start, data.aid))
    }

    /// True when the slot is for `data`'s samples (and they are in memory).
    fn holds(&self, data: &ExplainData) -> bool {
        self.source.is_some() && self.source == source_id(&data.imu)
    }

    /// The pass of `model` with `cfg` over `data` (every record kept, no observer) replayed
    /// from this slot's tape, or None when the slot holds no tape of these samples that the
    /// pass fits (the caller then runs it in full).
    pub fn replay(
        &self,
        model: &Model,
        cfg: &FilterConfig,
        data: &ExplainData,
    ) -> anyhow::Result<Option<FilterRun>> {
        self.replay_watched(model, cfg, data, &mut |_| {}, &mut filter::NoObserver, true)
    }

    /// [`TapeSlot::replay`] watched by `obs`, reporting `progress`, keeping every record or
    /// only the last.
    fn replay_watched(
        &self,
        model: &Model,
        cfg: &FilterConfig,
        data: &ExplainData,
        progress: &mut dyn FnMut(f64),
        obs: &mut dyn filter::Observer,
        keep_records: bool,
    ) -> anyhow::Result<Option<FilterRun>> {
        let Some(tape) = self.tape_for(cfg, data) else {
            return Ok(None);
        };
        let mut truth = data.truth.map(crate::io::truth::TruthSlice::new);
        let truth = truth
            .as_mut()
            .map(|t| t as &mut dyn crate::io::truth::TruthLookup);
        filter::run_replay(
            model,
            cfg,
            tape,
            data.aid,
            truth,
            progress,
            obs,
            keep_records,
        )
        .map(Some)
    }
}

/// What identifies samples in memory: their address, number and last time's bits (None for a
/// file).
fn source_id(imu: &ImuInput) -> Option<(usize, usize, u64)> {
    match imu {
        ImuInput::Memory(d) => Some((
            d.samples.as_ptr() as usize,
            d.samples.len(),
            d.samples.last().map_or(0, |s| s.t.to_bits()),
        )),
        ImuInput::File { .. } => None,
    }
}

impl<'a> ExplainData<'a> {
    /// The same data with passes sharing their navigation through the slot given with the data,
    /// else `slot` (`share`), or with none (not `share`).
    fn sharing(&self, slot: &'a TapeSlot, share: bool) -> ExplainData<'a> {
        ExplainData {
            tape: match self.tape {
                _ if !share => None,
                Some(given) => Some(given),
                None => Some(slot),
            },
            ..*self
        }
    }
}

/// About how many filter steps of `step_s` [s] a pass over `data` takes (the tape's room).
fn expected_steps(data: &ExplainData, step_s: f64) -> usize {
    let end = match data.imu {
        ImuInput::Memory(d) => d.samples.last().map(|s| s.t),
        ImuInput::File { .. } => data.aid.last().map(|a| a.t),
    };
    let span = end.map_or(0.0, |t| (t - data.start.t).max(0.0));
    (span / step_s).ceil() as usize + data.aid.len() + 2
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
    let items: Vec<&str> = spec
        .split(',')
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .collect();
    // `!name` or `!prefix*` withholds: from the given terms, or from every term when only
    // withholdings are given (`!size_*,!tau_*`)
    let (withheld, given): (Vec<&str>, Vec<&str>) = items.iter().partition(|i| i.starts_with('!'));
    if given.is_empty() {
        out = (0..common::TERM_COUNT).filter(|&t| !in_base(t)).collect();
    }
    // each item's terms, to say which named ones a withholding takes back
    let mut sets: Vec<(bool, &str, Vec<usize>)> = Vec::new();
    for item in given.iter().chain(&withheld) {
        let (drop, item) = match item.strip_prefix('!') {
            Some(rest) => (true, rest.trim()),
            None => (false, *item),
        };
        if item.is_empty() {
            return Err(
                "--candidates: `!` needs a term or a family after it (`!size_*`, `!tau_x`)".into(),
            );
        }
        if drop && item.starts_with('!') {
            return Err(format!(
                "--candidates: `!{item}` has a doubled `!`; one withholds (`!{}`)",
                item.trim_start_matches('!')
            ));
        }
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
        sets.push((drop, item, matched.clone()));
        if drop {
            // a withholding that takes nothing back is a mistake, not a no-op to pass over
            if !matched.iter().any(|t| out.contains(t)) {
                let names: Vec<&str> = matched.iter().map(|&t| common::TERMS[t].name).collect();
                let is = if names.len() == 1 { "is" } else { "are" };
                let earlier: Vec<String> = sets
                    .iter()
                    .filter(|(d, _, w)| *d && w.iter().any(|t| matched.contains(t)))
                    .filter(|(_, name, _)| *name != item)
                    .map(|(_, name, _)| format!("`!{name}`"))
                    .collect();
                let why = if !earlier.is_empty() {
                    format!(
                        "{} {is} already withheld by {}",
                        names.join(", "),
                        earlier.join(", ")
                    )
                } else if matched.iter().all(|&t| in_base(t)) {
                    format!(
                        "{} {is} in the baseline model {}, so no candidate; to fit without it, give a model without it",
                        names.join(", "),
                        baseline.name
                    )
                } else {
                    format!(
                        "{} {is} not among the terms named before it (a withholding takes terms back from the names given, or from every term when only withholdings are given)",
                        names.join(", ")
                    )
                };
                return Err(format!(
                    "--candidates {spec}: `!{item}` withholds nothing: {why}"
                ));
            }
            out.retain(|t| !matched.contains(t));
            continue;
        }
        for t in matched {
            if !out.contains(&t) {
                out.push(t);
            }
        }
    }
    // a name (or family) every term of which is withheld again contradicts itself
    for (_, name, terms) in sets.iter().filter(|s| !s.0) {
        if terms.iter().all(|t| !out.contains(t)) {
            let by: Vec<String> = sets
                .iter()
                .filter(|(drop, _, w)| *drop && w.iter().any(|t| terms.contains(t)))
                .map(|(_, w, _)| format!("`!{w}`"))
                .collect();
            return Err(format!(
                "--candidates {spec}: `{name}` is both named and withheld ({}); name it or withhold it",
                by.join(", ")
            ));
        }
    }
    if out.is_empty() {
        return Err(format!(
            "--candidates {spec}: withholds every candidate; nothing is left to test"
        ));
    }
    if out.iter().all(|&t| in_base(t)) {
        let names: Vec<&str> = out.iter().map(|&t| common::TERMS[t].name).collect();
        return Err(format!(
            "--candidates {spec}: every term it names ({}) is already in the baseline model {}; nothing is left to test (name terms the model lacks, or leave the option out for all of them)",
            names.join(", "),
            baseline.name
        ));
    }
    Ok(out)
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
    run_pass_watched(model, cands, data, cfg, progress, &mut filter::NoObserver)
}

/// [`run_pass`] with one more observer `watch` of the run (after the signatures).
fn run_pass_watched(
    model: &Model,
    cands: &[usize],
    data: &ExplainData,
    cfg: &FilterConfig,
    progress: &mut dyn FnMut(f64),
    watch: &mut dyn filter::Observer,
) -> anyhow::Result<Pass> {
    // the median aiding time splits the updates into halves
    let t_half = data
        .aid
        .get(data.aid.len() / 2)
        .map_or(f64::INFINITY, |a| a.t);
    // … and the median aided speed by speed (none without velocity aiding)
    let mut speeds: Vec<f64> = data
        .aid
        .iter()
        .filter_map(|a| a.vel.map(|v| v.0.norm()))
        .collect();
    speeds.sort_by(f64::total_cmp);
    let speed_half = speeds
        .get(speeds.len() / 2)
        .copied()
        .unwrap_or(f64::INFINITY);
    let mut splits = vec![Split::Time(t_half)];
    // below a walking pace the aided speed is the fixes' noise: no split by it
    if speed_half.is_finite() && speed_half >= MIN_SPLIT_SPEED {
        splits.push(Split::Speed(speed_half));
    }
    splits.push(Split::Motion);
    splits.push(Split::Manoeuvre);
    splits.push(Split::Measurement);
    let mut sig = Signatures::new(model, cands, &splits);
    let run = filter_pass(
        model,
        cfg,
        data,
        progress,
        &mut filter::Tee(&mut sig, watch),
    )?;
    run.check()
        .map_err(|e| anyhow::anyhow!("{} pass: {e}", model.name))?;
    let stats = pass_stats(model, &run, &sig.level, data.truth);
    sig.dispersion = stats.nis_mean;
    Ok(Pass { run, sig, stats })
}

/// One filter pass of `model` with `cfg` over `data`, watched by `obs`: replayed from the data's
/// navigation tape when an earlier pass recorded one it fits, else run over the samples (the
/// first open-loop pass over samples in memory recording the tape).
fn filter_pass(
    model: &Model,
    cfg: &FilterConfig,
    data: &ExplainData,
    progress: &mut dyn FnMut(f64),
    obs: &mut dyn filter::Observer,
) -> anyhow::Result<FilterRun> {
    // every epoch's record only for the truth's checks; else the last (the estimates)
    let keep_records = data.truth.is_some();
    // the data's navigation, when an earlier open-loop pass of this run recorded it
    let slot = data.tape.filter(|s| s.holds(data));
    if let Some(s) = slot {
        if let Some(run) = s.replay_watched(model, cfg, data, progress, obs, keep_records)? {
            return Ok(run);
        }
    }
    // the first open-loop pass records it (when it will fit)
    let steps = expected_steps(data, cfg.step_s);
    let mut rec = slot
        .filter(|s| s.tape.get().is_none() && steps <= nav_tape::max_steps())
        .and_then(|_| TapeRecorder::new(cfg, &data.start, data.aid));
    if let Some(r) = rec.as_mut() {
        r.reserve(steps);
    }
    let mut none = filter::NoObserver;
    let recorder: &mut dyn filter::Observer = match rec.as_mut() {
        Some(r) => r,
        None => &mut none,
    };
    let mut truth = data.truth.map(crate::io::truth::TruthSlice::new);
    let mut samples = data.imu.samples()?;
    let mut io = filter::StreamIo {
        samples: &mut *samples,
        aiding: &mut data.aid.iter().cloned(),
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
        &mut filter::Tee(obs, recorder),
        &mut |_| Ok(()),
        keep_records,
    )?;
    if let (Some(s), Some(r)) = (slot, rec) {
        // (a tape too large or of a pass that ended early: the later passes run in full)
        let _ = s.tape.set(r.finish(&run));
    }
    Ok(run)
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
    let given = cands;
    let cands = candidates_here(baseline, cands, data);
    let as_given = data;
    // the passes share one navigation of the data where they navigate alike
    let slot = TapeSlot::new(&data.imu);
    let data = &data.sharing(&slot, opts.share_navigation);
    let first = Context {
        baseline,
        data,
        config_for,
        opts,
    };
    let stage = match baseline_and_select(&first, &cands, progress)? {
        Ok(stage) => stage,
        Err(drift) => {
            let again = (baseline, given, as_given);
            return explain_closed_loop(again, config_for, opts, progress, &drift);
        }
    };
    // a baseline term beyond a few prior σ even with the findings added: its prior is too tight
    // for this sensor and the baseline biased (before the findings it may only absorb what a
    // missing term does); explain runs again with priors that hold the data's values
    let tight = tight_priors(
        baseline,
        &stage.r.model,
        &stage.r.pass.run,
        &config_for(&stage.r.model)?,
    );
    let widen = widened_priors(&tight);
    let config_widened = |m: &Model| -> anyhow::Result<FilterConfig> {
        let mut c = config_for(m)?;
        widen_priors(&mut c, m, &widen);
        Ok(c)
    };
    let widened = Context {
        config_for: &config_widened,
        ..first
    };
    // the priors are hyperparameters: the baseline's innovation log-likelihood is the data's
    // evidence for them, so the run with the widened priors is kept only when its baseline
    // gains more than their BIC penalty
    let (stage, prior_gain, widened_kept) =
        prefer_widened(&widened, &cands, stage, widen.len(), progress)?;
    let ctx = if widened_kept { &widened } else { &first };
    let Stage {
        truth_warning,
        linearisation,
        base_stats,
        innovations_before,
        model_error_before,
        tests,
        not_testable,
        not_separable,
        r,
    } = stage;
    truth_warning.iter().for_each(|w| warn(w));
    linearisation.iter().for_each(|w| warn(w));
    let excess = baseline_excess(&base_stats);
    // which findings are causes, judged on the rounds' extended pass; the causes' values then
    // come from the model they recommend, without the stand-ins (a stand-in beside a cause
    // takes part of its value)
    let mut judged = complete_findings(ctx, &r, excess, None)?;
    // a term the rounds' extended filter leaves within 2σ of zero fixes no value: beside the
    // causes it only widens their σ (the demo in closed loop: kaq_z_xz −48 ± 137 µg/g² beside
    // d_z took it to 540 ± 138)
    value_not_fixed(&mut judged);
    // a GNSS cause that a GNSS term withheld from the candidates fits as well may stand in for it
    let rivals = rivals::withheld_rivals(ctx, &r, &mut judged, &cands, progress)?;
    let r = without_stand_ins(ctx, r, &judged, progress)?;
    let passed_over = passed_over(ctx, &r, &judged, &cands, progress)?;
    let stand_ins = judged_stand_ins(&r, &judged);
    // a noise level the terms judged stand-ins take up is no finding either
    let stand_in_terms = judged_stand_in_terms(&r, &judged);
    let (noise, noise_stage) = noise::stage(ctx, &r, &base_stats, &stand_in_terms, progress)?;
    let noise_pass = noise_stage.as_ref().map(|x| &x.0);
    // the extended pass is the last one run (the baseline itself when nothing was found)
    let last_pass = noise_pass.unwrap_or(&r.pass);
    // the share of the baseline's excess the extended model leaves
    let misfit_unexplained = excess.map(|e| (last_pass.stats.nis_mean - 1.0) / e);
    let mut findings = complete_findings(ctx, &r, excess, misfit_unexplained)?;
    keep_stand_ins(ctx, &r, &mut findings, judged, &rivals, misfit_unexplained);
    let kept_out = (&cands[..], given, &stand_ins[..], &passed_over[..]);
    judge_kept_out(ctx, &r, &mut findings, kept_out, progress)?;
    let judged_now = (&mut findings, noise);
    let in_place = judge_final(ctx, &r, &tests, judged_now, (&cands, &rivals), progress)?;
    let held_by_noise = match &noise_stage {
        Some(noise) => held_only_by_the_stated_noise(ctx, &r, noise, &mut findings, progress)?,
        None => false,
    };
    // a term these rules unname leaves the extended model: its pass is run again without it
    let unnamed = small_beside_the_unexplained(&mut findings, opts) | held_by_noise;
    let (model_name, rerun) = if unnamed | in_place {
        let applied = noise_stage.as_ref().map_or(&[][..], |x| &x.1[..]);
        causes_only_pass(ctx, &r, &findings, applied, progress)?
    } else {
        (r.model.name.clone(), None)
    };
    let last_pass = rerun.as_ref().unwrap_or(last_pass);
    let mut implausible = r.implausible;
    implausible.retain(|i| !findings.iter().any(|f| f.term == i.term));
    let extended_stats = last_pass.stats.clone();
    let gain = Gain::between(&base_stats, &extended_stats);
    let mut ranked = tests;
    ranked.sort_by(|a, b| b.llr.total_cmp(&a.llr));
    let mut expl = Explanation {
        model: baseline.names.iter().map(|s| s.to_string()).collect(),
        baseline_model: baseline.name.clone(),
        baseline: base_stats,
        candidates: ranked,
        findings,
        not_testable,
        implausible,
        unconfirmed: r.unconfirmed,
        not_separable,
        extended_model: model_name,
        extended: extended_stats,
        gain,
        rounds: r.rounds,
        alpha: opts.alpha,
        summary: Vec::new(),
        misfit_unexplained: match &rerun {
            Some(p) => excess.map(|e| ((p.stats.nis_mean - 1.0) / e).max(0.0)),
            None => misfit_unexplained.map(|u| u.max(0.0)),
        },
        stand_ins_left_out: rerun.is_some(),
        restamp: None,
        baseline_priors_tight: tight,
        baseline_priors_widened: widened_kept,
        baseline_priors_gain: prior_gain,
        linearisation,
        closed_loop_instead: false,
        innovations_before,
        innovations_after: normalised(&last_pass.run),
        model_error_before,
        model_error_after: model_error_series(&last_pass.run),
    };
    say_untested(&mut expl.findings);
    expl.summary = summary(&expl);
    Ok(expl)
}

/// The stage with `k` widened priors (`widened`) when the data's evidence for them, its
/// baseline's innovation log-likelihood over `stage`'s, beats their BIC penalty k ln N: (the
/// stage kept, that 2Δℓ, whether the widened one was kept). A drift the widened priors bring is
/// not followed: the run as given stays.
fn prefer_widened(
    widened: &Context,
    cands: &[usize],
    stage: Stage,
    k: usize,
    progress: &mut dyn FnMut(usize, f64),
) -> anyhow::Result<(Stage, Option<f64>, bool)> {
    if k == 0 {
        return Ok((stage, None, false));
    }
    let Ok(again) = baseline_and_select(widened, cands, progress)? else {
        return Ok((stage, None, false));
    };
    let gain = 2.0 * (again.base_stats.loglik - stage.base_stats.loglik);
    let n = again.r.pass.run.innovations.len().max(2) as f64;
    Ok(if gain > k as f64 * n.ln() {
        (again, Some(gain), true)
    } else {
        (stage, Some(gain), false)
    })
}

/// explain run again closed loop on `(baseline, candidates, data)` after its open-loop baseline
/// pass drifted beyond small angles (`drift`): the free navigation the errors were linearised
/// about left the linear error model, whose neglected terms would read as sensor or aiding
/// terms; the navigation corrected at every fix keeps the errors small. The summary opens with
/// why.
fn explain_closed_loop(
    (baseline, cands, data): (&Model, &[usize], &ExplainData),
    config_for: &dyn Fn(&Model) -> anyhow::Result<FilterConfig>,
    opts: &ExplainOptions,
    progress: &mut dyn FnMut(usize, f64),
    drift: &AttitudeDrift,
) -> anyhow::Result<Explanation> {
    let closed = |m: &Model| -> anyhow::Result<FilterConfig> {
        let mut c = config_for(m)?;
        c.mode = filter::Mode::ClosedLoop;
        Ok(c)
    };
    let mut e = explain(baseline, cands, data, &closed, opts, progress)?;
    let words = format!(
        "Closed loop instead of open loop: {} explain therefore ran closed loop (the navigation corrected at every fix); --mode open keeps open loop, with a warning.",
        drift.words(data.start.t)
    );
    e.summary.insert(0, words.clone());
    e.linearisation = Some(words);
    e.closed_loop_instead = true;
    Ok(e)
}

/// What [`judge_kept_out`] reads: the candidates here, the candidates as given, the stand-ins
/// (with their classes) and the candidates passed over ((term, GLR estimate, σ)).
type KeptOut<'a> = (
    &'a [usize],
    &'a [usize],
    &'a [String],
    &'a [(usize, f64, f64)],
);

/// The findings tried against the terms the candidates keep out ([`withheld::withheld_alike`]),
/// then the causes a passed-over candidate un-names ([`mark_passed_over`]): first, so that the
/// re-run those suggest offers what a finding names (`cands`: the candidates here; `given`: as
/// given, whose withholdings the suggestion keeps).
fn judge_kept_out(
    ctx: &Context,
    r: &Rounds,
    findings: &mut [Finding],
    (cands, given, stand_ins, passed_over): KeptOut,
    progress: &mut dyn FnMut(usize, f64),
) -> anyhow::Result<()> {
    withheld::withheld_alike(ctx, r, findings, cands, progress)?;
    let offered: Vec<usize> = findings
        .iter()
        .filter(|f| f.unnamed_because(Unnamed::WithheldTermFits))
        .flat_map(|f| f.withheld_alike.iter().filter_map(|w| term_index(&w.term)))
        .chain(given.iter().copied())
        .collect();
    let kept_out = withheld_by_the_user(ctx.baseline, &offered);
    mark_passed_over(findings, (stand_ins, &kept_out), passed_over);
    Ok(())
}

/// Candidates the rounds passed over that are significant beside the causes once the
/// stand-ins are dropped (a stand-in took their part of the misfit while they were judged):
/// (term index, GLR estimate, σ in the display unit), from one pass with the candidates not
/// named on `r`'s model; none when every finding in `judged` is a cause.
fn passed_over(
    ctx: &Context,
    r: &Rounds,
    judged: &[Finding],
    cands: &[usize],
    progress: &mut dyn FnMut(usize, f64),
) -> anyhow::Result<Vec<(usize, f64, f64)>> {
    if judged.iter().all(Finding::is_cause) {
        return Ok(Vec::new());
    }
    let named = |t: usize| {
        let name = common::TERMS[t].name;
        r.named.iter().any(|n| n.term == t)
            || judged
                .iter()
                .any(|f| f.equivalent.iter().any(|e| e == name))
            || r.model.states.contains(&StateRef::Term(t))
    };
    let pool: Vec<usize> = cands.iter().copied().filter(|&t| !named(t)).collect();
    if pool.is_empty() {
        return Ok(Vec::new());
    }
    let cfg = ctx.extended_config(&r.model, &r.widened)?;
    let round = r.rounds + 1;
    let pass = run_pass(&r.model, &pool, ctx.data, &cfg, &mut |f| progress(round, f))?;
    let (_, eligible) = candidate_tests(&pass.sig, ctx.opts);
    let (sel, _) = forward_select(&pass.sig, &eligible, pass.run.innovations.len(), ctx.opts);
    Ok(sel
        .iter()
        .map(|s| (pass.sig.cands[s.idx], s.glr, s.glr_sigma))
        .collect())
}

/// Most candidates fitted beside the causes in [`companions_move`] (one pass).
const MAX_COMPANIONS: usize = 6;

/// Candidates significant alone that the causes take up (not named, not in a class, not
/// implausible, not unconfirmed) are fitted beside them in one more pass: a cause of the same
/// sensor whose value then moves by more than 3 of its σ, where the companions fit the data
/// better (2Δℓ > 0: the filters' marginal log-likelihoods, priors included, favour them), is
/// "not attributed": the data do not fix its value on this excitation (a delay on z fits what a
/// common delay on x, y and z does on a turntable that never separates them), and its words say
/// so with both values. Where they do not fit better, the value stands and the words say how
/// far they moved it.
fn companions_move(
    ctx: &Context,
    r: &Rounds,
    tests: &[CandidateTest],
    findings: &mut [Finding],
    progress: &mut dyn FnMut(usize, f64),
) -> anyhow::Result<()> {
    let causes: Vec<usize> = (0..findings.len())
        .filter(|&k| findings[k].is_cause())
        .collect();
    let known = |name: &str| {
        findings
            .iter()
            .any(|f| f.term == name || f.equivalent.iter().any(|e| e == name))
            || r.implausible.iter().any(|i| i.term == name)
            || r.unconfirmed.iter().any(|u| u.0 == name)
    };
    let mut taken: Vec<usize> = tests
        .iter()
        .filter(|c| c.testable && c.confounded_with.is_none() && c.p_holm <= ctx.opts.alpha)
        .filter(|c| !known(&c.term))
        .filter_map(|c| term_index(&c.term))
        .filter(|&t| !r.model.states.contains(&StateRef::Term(t)))
        .filter(|&t| {
            causes
                .iter()
                .any(|&k| term_sensor(&findings[k].term) == Some(common::TERMS[t].sensor))
        })
        .collect();
    taken.truncate(MAX_COMPANIONS);
    if causes.is_empty() || taken.is_empty() {
        return Ok(());
    }
    let terms = r
        .model
        .states
        .iter()
        .filter_map(|s| match *s {
            StateRef::Term(t) if !ctx.baseline.states.contains(s) => Some(t),
            _ => None,
        })
        .chain(taken.iter().copied());
    let model = model_with(&ctx.baseline.name, terms)?;
    let cfg = ctx.extended_config(&model, &r.widened)?;
    let round = r.rounds + 1;
    let pass = run_pass(&model, &[], ctx.data, &cfg, &mut |f| progress(round, f))?;
    let Some(last) = pass.run.records.last() else {
        return Ok(());
    };
    let gain = 2.0 * (pass.stats.loglik - r.pass.stats.loglik);
    let value = |name: &str| {
        let t = term_index(name)?;
        let i = model.index_of(name)?;
        let k = 1.0 / common::TERMS[t].display_to_si;
        Some((last.x[i] * k, last.sigma[i] * k))
    };
    // (a companion the data leave at its prior σ moves nothing: named apart, without a value)
    let mut at_prior = Vec::new();
    let mut beside: Vec<String> = taken
        .iter()
        .filter_map(|&t| {
            let info = &common::TERMS[t];
            let (x, sd) = value(info.name)?;
            if sd >= 0.9 * prior_sigma(t, ctx.opts) / info.display_to_si {
                at_prior.push(info.name);
                return None;
            }
            Some(format!(
                "{} {} ± {} {}",
                info.name,
                sig3(x),
                sig3(sd),
                info.display
            ))
        })
        .collect();
    if !at_prior.is_empty() {
        beside.push(format!(
            "with {} left at {} prior σ",
            at_prior.join(" and "),
            if at_prior.len() == 1 { "its" } else { "their" }
        ));
    }
    for k in causes {
        let f = &mut findings[k];
        let Some((x, sd)) = value(&f.term) else {
            continue;
        };
        let moved = (x - f.estimate).abs() / f.sigma;
        if !(f.sigma > 0.0 && moved > 3.0) {
            continue;
        }
        let (with, to) = (
            beside.join(", "),
            format!(
                "{} ± {} {}, {} of its σ",
                sig3(x),
                sig3(sd),
                f.unit,
                sig3(moved)
            ),
        );
        if gain <= 0.0 {
            // the data's evidence (the filters' marginal log-likelihoods) is against the
            // companions: the freedom they add moves the value, the data do not
            f.words.push_str(&format!(
                ". Fitted beside the candidates significant alone that it takes up ({with}), it moves to {to}, but they do not fit the data better (2Δℓ {}): its value stands",
                sig3(gain)
            ));
            continue;
        }
        let why = format!(
            "the candidates significant alone that it takes up, fitted beside it ({with}), move it to {to} from this value (the fit changes by 2Δℓ {}): the data do not fix its value on this excitation; one that excites these terms apart decides",
            sig3(gain)
        );
        not_named(f, Unnamed::ValueMoves, why);
    }
    Ok(())
}

/// The candidates `cands` that are not in `baseline` and that these data can show: a velocity
/// or attitude reference's terms only where the data hold that reference and the baseline forms
/// its measurement (else they would be listed as untestable).
fn candidates_here(baseline: &Model, cands: &[usize], data: &ExplainData) -> Vec<usize> {
    let forms = |m: &str| baseline.measurements().iter().any(|x| x.name == m);
    let reference = data.aid.iter().any(|e| e.body_vel.is_some()) && forms("vel_body");
    let attitude = data.aid.iter().any(|e| e.att.is_some()) && forms("att_ref");
    cands
        .iter()
        .copied()
        .filter(|&t| !baseline.states.contains(&StateRef::Term(t)))
        .filter(|&t| match common::TERMS[t].sensor {
            Sensor::Reference => reference,
            Sensor::Attitude => attitude,
            _ => true,
        })
        .collect()
}

/// A term cause none of whose consistency splits could be tested (each leaves its information
/// in one group: a vibration on one axis in one half of the run) keeps its name, but its words
/// say that whether it holds across the data is not known (the demo's d_z: its z vibration lies
/// in the second half).
fn say_untested(findings: &mut [Finding]) {
    for f in findings.iter_mut().filter(|f| {
        f.is_cause()
            && f.kind != "noise"
            && !f.consistency.is_empty()
            && f.consistency.iter().all(|c| !c.tested)
    }) {
        let splits: Vec<&str> = f.consistency.iter().map(|c| c.split.as_str()).collect();
        f.words.push_str(&format!(
            ". Whether it holds across the data is not known: no split of these data ({}) leaves information on it in two groups",
            splits.join(", ")
        ));
    }
}

/// A term cause whose value the extended filter leaves within 2σ of zero is no longer named:
/// the likelihood it added in its round came while the other terms settled (a state with a
/// wide prior absorbs their transients), or before the terms beside it took its part, not from
/// a value the data fix (a time offset of −4.50 ± 3.62 ms beside a lever arm and an
/// accelerometer delay was "Found" on a drive whose fixes were 20 ms late, helper-57).
fn value_not_fixed(findings: &mut [Finding]) {
    for f in findings
        .iter_mut()
        .filter(|f| f.is_cause() && f.kind != "noise")
    {
        if f.sigma > 0.0 && f.estimate.abs() < 2.0 * f.sigma {
            let why = format!(
                "its value in the extended filter, {} ± {} {}, is within 2σ of zero: the likelihood it added (2Δℓ {}) came while the other terms settled, not from a value the data fix",
                sig3(f.estimate),
                sig3(f.sigma),
                f.unit,
                sig3(f.two_delta_loglik)
            );
            not_named(f, Unnamed::ValueNearZero, why);
        }
    }
}

/// The rules that judge the findings of the rounds `r` once their values are final (`tests`:
/// the candidates' tests; `cands`: the candidates; `rivals`: the rivals that took the judged
/// stand-ins' places): a companion that moves, an aiding term confounded with a sensor term, a
/// value not fixed, a GNSS cause beside an offset that is none, a value that leans on a
/// stand-in; then the noise findings `noise` join, none named beside an offset left to a
/// stand-in. Returns whether the last two unnamed a cause (its term then leaves the extended
/// model).
fn judge_final(
    ctx: &Context,
    r: &Rounds,
    tests: &[CandidateTest],
    (findings, noise): (&mut Vec<Finding>, Vec<Finding>),
    (cands, rivals): (&[usize], &[Option<rivals::Rival>]),
    progress: &mut dyn FnMut(usize, f64),
) -> anyhow::Result<bool> {
    companions_move(ctx, r, tests, findings, progress)?;
    aiding_and_sensor_confounded(ctx, r, findings, progress)?;
    value_not_fixed(findings);
    let late = rivals::offset_stand_ins(ctx, r, findings, cands, progress)?;
    let leaning = rivals::leaning_on_stand_ins(findings, rivals)
        | rivals::leaning_on_stand_ins(findings, &late);
    findings.extend(noise);
    rivals::noise_beside_an_offset(findings, rivals.iter().chain(&late));
    Ok(!late.is_empty() | leaning)
}

/// Each finding that was judged no cause (`judged`, one per named term of `r`, in order) keeps
/// the value it was fitted with; its words say what is left now (`unexplained`), with the
/// withheld GNSS term it may stand in for (`rivals`).
fn keep_stand_ins(
    ctx: &Context,
    r: &Rounds,
    findings: &mut [Finding],
    judged: Vec<Finding>,
    rivals: &[Option<rivals::Rival>],
    unexplained: Option<f64>,
) {
    for (((f, j), n), rival) in findings.iter_mut().zip(judged).zip(&r.named).zip(rivals) {
        if j.is_cause() {
            continue;
        }
        *f = j;
        // (a stand-in for a withheld GNSS term is no value to hold with a prior)
        f.suggested_prior = rival
            .is_none()
            .then(|| suggested_prior(f, ctx.opts))
            .flatten();
        f.stand_in = f.stand_in.as_ref().and(joined(
            stand_in_reason(f, unexplained, ctx.opts, Some(&r.offset_order)),
            rival.as_ref().map(|r| r.why.clone()),
        ));
        let info = &common::TERMS[n.term];
        (f.headline, f.words) =
            finding_words(f, info, prior_sigma(n.term, ctx.opts) / info.display_to_si);
    }
}

/// The name of the model of the causes among `findings` (the baseline and the named terms of `r`
/// that are causes) and its pass, with the noise levels found (`applied`) applied.
fn causes_only_pass(
    ctx: &Context,
    r: &Rounds,
    findings: &[Finding],
    applied: &[(noise::Level, f64)],
    progress: &mut dyn FnMut(usize, f64),
) -> anyhow::Result<(String, Option<Pass>)> {
    let causes = r
        .named
        .iter()
        .map(|n| n.term)
        .filter(|&t| {
            findings
                .iter()
                .any(|f| f.term == common::TERMS[t].name && f.is_cause())
        })
        .collect::<Vec<_>>();
    let model = model_with(&ctx.baseline.name, causes)?;
    // with the noise levels found, as the extended pass it replaces
    let cfg = config_with_levels(ctx, r, &model, applied)?;
    let round = r.rounds + 1;
    let pass = run_pass(&model, &[], ctx.data, &cfg, &mut |f| progress(round, f))?;
    Ok((model.name.clone(), Some(pass)))
}

/// `r`'s extended configuration of `model` with the noise `levels` scaled.
fn config_with_levels(
    ctx: &Context,
    r: &Rounds,
    model: &Model,
    levels: &[(noise::Level, f64)],
) -> anyhow::Result<FilterConfig> {
    let mut cfg = ctx.extended_config(model, &r.widened)?;
    for (level, scale) in levels {
        level.apply(model, &mut cfg, *scale);
    }
    Ok(cfg)
}

/// Finding `f` of term `t` becomes a stand-in for `why`; its headline and words say so.
fn mark_stand_in(f: &mut Finding, t: usize, why: String, opts: &ExplainOptions) {
    f.stand_in = Some(why);
    let info = &common::TERMS[t];
    (f.headline, f.words) = finding_words(f, info, prior_sigma(t, opts) / info.display_to_si);
}

/// A term cause whose gain does not survive the noise levels found as causes (each one level
/// across the data): with them applied, the model without the term loses less than the BIC's
/// ln N (and the α-level χ²₁ quantile) of 2Δℓ. Its significance came from the stated noise
/// being wrong (measured: a gyro white noise stated 8× too small on a drive gave "Found:
/// lever_y = −0.34 ± 0.03 m" beside the noise level). Noise fits that are not causes are not
/// applied: a level that does not hold across the data is no sensor's noise, and inflating it
/// can take up a real cause (on the MEMS drive, with every noise fit applied, the model
/// without dt_gnss fitted better). One pass per term cause, and one with them all unless every
/// level of `noise` (the extended pass and the scales it applies) is a cause.
/// Returns whether it unnamed a term.
fn held_only_by_the_stated_noise(
    ctx: &Context,
    r: &Rounds,
    noise: &noise::NoisePass,
    findings: &mut [Finding],
    progress: &mut dyn FnMut(usize, f64),
) -> anyhow::Result<bool> {
    let (noise_pass, applied) = noise;
    // (at the scales the findings state: refitted without the levels the raw increments rule
    // out, where the extended pass holds the joint fits)
    let causes: Vec<(noise::Level, f64)> = applied
        .iter()
        .filter_map(|&(level, joint)| {
            let name = level.name();
            findings
                .iter()
                .find(|f| f.kind == "noise" && f.term == name && f.is_cause())
                .map(|f| (level, f.scale.unwrap_or(joint)))
        })
        .collect();
    let terms: Vec<usize> = findings
        .iter()
        .filter(|f| f.is_cause() && f.kind != "noise")
        .filter_map(|f| term_index(&f.term))
        .filter(|t| r.named.iter().any(|x| x.term == *t))
        .collect();
    if causes.is_empty() || terms.is_empty() {
        return Ok(false);
    }
    let round = r.rounds + 2;
    let mut pass_of = |model: &Model| -> anyhow::Result<Pass> {
        let cfg = config_with_levels(ctx, r, model, &causes)?;
        run_pass(model, &[], ctx.data, &cfg, &mut |x| progress(round, x))
    };
    // every level found is a cause: the extended pass is the one with the term
    let fresh;
    let with = if causes == *applied {
        noise_pass
    } else {
        fresh = pass_of(&r.model)?;
        &fresh
    };
    let n = with.run.innovations.len().max(2) as f64;
    let threshold = n.ln().max(stats::chi2_isf(ctx.opts.alpha, 1.0));
    let mut unnamed = false;
    for t in terms {
        let others = r.named.iter().map(|x| x.term).filter(|&x| x != t);
        let pass = pass_of(&model_with(&ctx.baseline.name, others)?)?;
        let gain = 2.0 * (with.stats.loglik - pass.stats.loglik);
        if gain >= threshold {
            continue;
        }
        if let Some(f) = findings
            .iter_mut()
            .find(|f| f.term == common::TERMS[t].name)
        {
            unnamed = true;
            mark_stand_in(f, t, format!(
                "with the noise levels found applied it no longer improves the fit beyond chance (2Δℓ {} against {}): it is significant only while the noise is stated wrongly, and stands in for the noise",
                sig3(gain),
                sig3(threshold)
            ), ctx.opts);
        }
    }
    Ok(unnamed)
}

/// Prior σ beyond which a term cause that removes a small share of the misfit, while the causes
/// together leave most of it, is a stand-in (the prior itself objects to it at 3 σ).
const UNEXPLAINED_PRIOR_SIGMAS: f64 = 3.0;

/// A term cause removing less than `stand_in_share` of the baseline's excess misfit, at more than
/// [`UNEXPLAINED_PRIOR_SIGMAS`] of its prior, while the causes found (terms and noise levels)
/// together remove less than half of it, probably stands in for what leaves the rest: the
/// small-share rule spares a well-supported small share as one cause among several, but here the
/// others are not causes (measured: an attitude reference's mounting withheld from the
/// candidates gave "Found: lever_y = -5.32 ± 0.19 m", 7 % of the misfit, the rest fitted only
/// by noise levels that hold nowhere).
/// Returns whether it unnamed a term.
fn small_beside_the_unexplained(findings: &mut [Finding], opts: &ExplainOptions) -> bool {
    let explained: f64 = findings
        .iter()
        .filter(|f| f.is_cause())
        .filter_map(|f| f.misfit_share)
        .sum();
    if explained >= 0.5 {
        return false;
    }
    let mut unnamed = false;
    for f in findings.iter_mut().filter(|f| {
        f.is_cause()
            && f.kind != "noise"
            && f.prior_sigmas.abs() > UNEXPLAINED_PRIOR_SIGMAS
            && f.misfit_share.is_some_and(|s| s < opts.stand_in_share)
    }) {
        unnamed = true;
        let Some(t) = common::TERMS.iter().position(|t| t.name == f.term) else {
            continue;
        };
        let why = format!(
            "it needs {} prior σ and removes {} % of the baseline's excess misfit, while the causes found together remove {} %: most of the misfit is something the candidates do not describe, and a term this far from its prior fitted beside it probably stands in for part of it",
            sig3(f.prior_sigmas.abs()),
            sig3(100.0 * f.misfit_share.unwrap_or(0.0)),
            sig3(100.0 * explained.max(0.0))
        );
        mark_stand_in(f, t, why, opts);
    }
    unnamed
}

/// Largest |correlation| of two causes' estimates in the extended filter at which both stay
/// named: beyond it the data fix only a combination of the two.
const MAX_CAUSE_CORRELATION: f64 = 0.9;

/// A cause of the aiding (a time offset, a lever arm, a mounting: it enters H) and a sensor cause
/// whose estimates the extended model (`r`, one more pass keeping its covariance) correlates
/// beyond ±0.9 are both no longer named: on this motion an aiding's timing and an
/// accelerometer's delay (or a lever arm and a sensor term) look alike, and the data fix only
/// their combination; the words say so with the correlation.
fn aiding_and_sensor_confounded(
    ctx: &Context,
    r: &Rounds,
    findings: &mut [Finding],
    progress: &mut dyn FnMut(usize, f64),
) -> anyhow::Result<()> {
    let causes: Vec<(usize, usize)> = (0..findings.len())
        .filter(|&k| findings[k].is_cause())
        .filter_map(|k| Some((k, r.model.index_of(&findings[k].term)?)))
        .collect();
    let aids = |k: usize| term_sensor(&findings[k].term).is_some_and(|s| s.enters_h());
    let mixed = causes.iter().any(|&(k, _)| aids(k)) && causes.iter().any(|&(k, _)| !aids(k));
    if !mixed {
        return Ok(());
    }
    let mut cfg = ctx.extended_config(&r.model, &r.widened)?;
    cfg.keep_covariance = true;
    let round = r.rounds + 1;
    let pass = run_pass(&r.model, &[], ctx.data, &cfg, &mut |f| progress(round, f))?;
    let Some(p) = pass.run.records.last().and_then(|l| l.cov.clone()) else {
        return Ok(());
    };
    let n = r.model.n();
    let mut why: Vec<(usize, String)> = Vec::new();
    for &(a, i) in causes.iter().filter(|&&(k, _)| aids(k)) {
        for &(b, j) in causes.iter().filter(|&&(k, _)| !aids(k)) {
            let rho = p[i * n + j] / (p[i * n + i] * p[j * n + j]).sqrt();
            if rho.is_nan() || rho.abs() <= MAX_CAUSE_CORRELATION {
                continue;
            }
            for (k, other) in [(a, b), (b, a)] {
                why.push((
                    k,
                    format!(
                        "the data cannot separate it from {} (their estimates correlate {} in the extended filter): an aiding's timing, lever arm or mounting and a sensor term act alike on this motion, and either may take the whole effect; a known value of the aiding's (--gnss-delay, --lever-arm, --mounting) or a run that excites them apart decides",
                        findings[other].term,
                        sig3(rho)
                    ),
                ));
            }
        }
    }
    for (k, w) in why {
        not_named(&mut findings[k], Unnamed::AidingSensorConfound, w);
    }
    Ok(())
}

/// The index in `common::TERMS` of the term `name`, if it is one.
fn term_index(name: &str) -> Option<usize> {
    common::TERMS.iter().position(|t| t.name == name)
}

/// The sensor of the library term `name`, if it is one.
fn term_sensor(name: &str) -> Option<Sensor> {
    term_index(name).map(|t| common::TERMS[t].sensor)
}

/// Cause `f` is no longer named by rule `rule`: `why` joins its reasons and ends its words.
fn not_named(f: &mut Finding, rule: Unnamed, why: String) {
    f.words.push_str(&format!(". Not named as a cause: {why}"));
    f.not_attributed = joined(f.not_attributed.take(), Some(why));
    if !f.unnamed_because(rule) {
        f.not_attributed_because.push(rule);
    }
}

/// The term indices of the stand-ins among `judged` (one finding per named term of `r`).
fn judged_stand_in_terms(r: &Rounds, judged: &[Finding]) -> Vec<usize> {
    r.named
        .iter()
        .zip(judged)
        .filter(|(_, f)| !f.is_cause())
        .map(|(n, _)| n.term)
        .collect()
}

/// The names of the stand-ins among `judged` (one finding per named term of `r`) and of the
/// members of their classes (which would take their place were they withheld alone).
fn judged_stand_ins(r: &Rounds, judged: &[Finding]) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    for (n, f) in r.named.iter().zip(judged).filter(|(_, f)| !f.is_cause()) {
        for name in std::iter::once(common::TERMS[n.term].name.to_string())
            .chain(f.equivalent.iter().cloned())
        {
            if !out.contains(&name) {
                out.push(name);
            }
        }
    }
    out
}

/// The family of a spec term's name: its prefix up to and with its first `_` (`kaq_`, `d_`).
fn family(name: &str) -> &str {
    &name[..name.find('_').map_or(name.len(), |k| k + 1)]
}

/// Notes on the prefix items of a `--candidates` list that match terms of more than one
/// family (`!d*` withholds d_x, d_y, d_z and dt_gnss): what each matched.
pub fn prefix_reach(spec: Option<&str>) -> Vec<String> {
    let Some(spec) = spec else {
        return Vec::new();
    };
    let mut out = Vec::new();
    for item in spec.split(',').map(str::trim) {
        let Some(prefix) = item.trim_start_matches('!').strip_suffix('*') else {
            continue;
        };
        let names: Vec<&str> = common::TERMS
            .iter()
            .map(|t| t.name)
            .filter(|n| n.starts_with(prefix))
            .collect();
        let mut families: Vec<&str> = Vec::new();
        for n in &names {
            if !families.contains(&family(n)) {
                families.push(family(n));
            }
        }
        if families.len() > 1 {
            out.push(format!(
                "--candidates item `{item}` matches the terms {} ({} families: {}); give `{}*` for one family alone.",
                names.join(", "),
                families.len(),
                families.join(", "),
                families[0]
            ));
        }
    }
    out
}

/// The spec terms outside `baseline` that are not among the candidates `given` as
/// `--candidates` withholdings: `!family_*` where every term of a family is out (a family: the
/// names' common prefix up to its first `_`), else `!name`; none when every term is a candidate.
/// Sensors none of whose terms is given (GNSS terms on static aiding) are left out.
fn withheld_by_the_user(baseline: &Model, given: &[usize]) -> Vec<String> {
    // (a sensor none of whose terms is given is one the data hold no measurement of)
    let tested = |t: usize| {
        given
            .iter()
            .any(|&g| common::TERMS[g].sensor == common::TERMS[t].sensor)
    };
    let out = |t: usize| {
        !given.contains(&t) && !baseline.states.contains(&StateRef::Term(t)) && tested(t)
    };
    let mut items: Vec<String> = Vec::new();
    for t in (0..common::TERM_COUNT).filter(|&t| out(t)) {
        let fam = family(common::TERMS[t].name);
        // a family all of whose terms are out (or in the baseline) is withheld by its prefix
        let whole = (0..common::TERM_COUNT)
            .filter(|&u| common::TERMS[u].name.starts_with(fam))
            .all(|u| out(u) || baseline.states.contains(&StateRef::Term(u)));
        let item = if whole && fam.ends_with('_') {
            format!("!{fam}*")
        } else {
            format!("!{}", common::TERMS[t].name)
        };
        if !items.contains(&item) {
            items.push(item);
        }
    }
    items
}

/// Every cause of the sensor of a candidate in `passed_over` is no longer named: its value was
/// fitted while the stand-ins (`stand_ins`, with their classes) took part of the misfit that
/// candidate explains beside it; its words say so and how to fit them together, the run's own
/// withholdings (`kept_out`) kept.
fn mark_passed_over(
    findings: &mut [Finding],
    (stand_ins, kept_out): (&[String], &[String]),
    passed_over: &[(usize, f64, f64)],
) {
    for f in findings.iter_mut().filter(|f| f.is_cause()) {
        let Some(sensor) = term_sensor(&f.term) else {
            continue;
        };
        let beside: Vec<String> = passed_over
            .iter()
            .filter(|p| common::TERMS[p.0].sensor == sensor)
            .map(|&(c, glr, sd)| {
                let info = &common::TERMS[c];
                format!(
                    "{} ({} ± {} {})",
                    info.name,
                    sig3(glr),
                    sig3(sd),
                    info.display
                )
            })
            .collect();
        if beside.is_empty() {
            continue;
        }
        // (what the run's own --candidates kept out stays out)
        let withheld: Vec<String> = kept_out
            .iter()
            .cloned()
            .chain(stand_ins.iter().map(|n| format!("!{n}")))
            .collect();
        let why = format!(
            "once the stand-ins ({}) are dropped, {} {} significant beside it: its value was fitted while a stand-in took part of their misfit and is not final; run again with --candidates '{}' to fit them together",
            stand_ins.join(", "),
            beside.join(", "),
            if beside.len() == 1 { "becomes" } else { "become" },
            withheld.join(",")
        );
        not_named(f, Unnamed::LeansOnStandIn, why);
    }
}

impl Gain {
    /// What the extended pass (`after`) gains over the baseline's (`before`).
    fn between(before: &PassStats, after: &PassStats) -> Gain {
        Gain {
            loglik: after.loglik - before.loglik,
            nis_mean_before: before.nis_mean,
            nis_mean_after: after.nis_mean,
            model_error_rms_before: before.model_error_rms_arcsec.map(|e| e[0].hypot(e[1])),
            model_error_rms_after: after.model_error_rms_arcsec.map(|e| e[0].hypot(e[1])),
        }
    }
}

/// Two optional reasons as one (joined by "; ").
fn joined(a: Option<String>, b: Option<String>) -> Option<String> {
    match (a, b) {
        (Some(a), Some(b)) => Some(format!("{a}; {b}")),
        (a, b) => a.or(b),
    }
}

/// The instrument terms of `baseline` whose final estimate in `run` (a pass of `model`, the
/// baseline or its extension) lies beyond [`TIGHT_PRIOR_SIGMAS`] of their prior σ (in `cfg`)
/// and beyond 3 of their own σ: the data determine a value the prior calls implausible.
fn tight_priors(
    baseline: &Model,
    model: &Model,
    run: &FilterRun,
    cfg: &FilterConfig,
) -> Vec<TightPrior> {
    let Some(last) = run.records.last() else {
        return Vec::new();
    };
    let mut out = Vec::new();
    for (i, s) in model.states.iter().enumerate() {
        let StateRef::Term(t) = *s else { continue };
        if !baseline.states.contains(s) {
            continue;
        }
        let info = &common::TERMS[t];
        let (x, sd, prior) = (last.x[i], last.sigma[i], cfg.prior_sigma[i]);
        if !(prior > 0.0 && x.abs() > TIGHT_PRIOR_SIGMAS * prior && x.abs() > 3.0 * sd) {
            continue;
        }
        let k = 1.0 / info.display_to_si;
        out.push(TightPrior {
            term: info.name.to_string(),
            index: t,
            estimate: x * k,
            sigma: sd * k,
            prior: prior * k,
            prior_sigmas: x.abs() / prior,
            suggested: round_up_1(3.0 * x.abs() * k),
            unit: info.display.to_string(),
        });
    }
    out
}

/// `v` > 0 rounded up to one significant digit (0.0123 → 0.02, 340 → 400).
fn round_up_1(v: f64) -> f64 {
    let p = 10f64.powf(v.log10().floor());
    (v / p).ceil() * p
}

/// Prior σ beyond which a finding that removes little of the misfit is read as a stand-in (a
/// value within a few prior σ that explains little is a small effect beside larger ones: an
/// off-axis lever arm of 36 mm, 3.6 of the spec's 10 mm, beside a gyro–accelerometer
/// asynchrony that explains most).
const SMALL_SHARE_PRIOR_SIGMAS: f64 = 5.0;
/// The small-share rule spares a finding whose extended-filter support 2Δℓ is at least this many
/// times the prior's objection z² (z = its value in prior σ).
const SMALL_SHARE_SUPPORT: f64 = 4.0;

/// Attitude error estimate [rad] beyond which an open-loop pass is linearised about a navigation
/// too far from the truth: 2.56°, where the small-angle model's neglected second-order terms,
/// ½φ²·g on the specific force, reach 1 mg (a third of the bias the embedded demo's hidden d
/// makes over its run, ten navigation-grade accelerometer biases of 100 µg) and its couplings are
/// off by 1 − cos φ = 0.1 %. Measured: the demo's free navigation reaches 5.5° in its first
/// 104 s and 8.4° in 600 s, where the open-loop explain named an accelerometer delay tau_x the
/// simulation does not have ("Found", −0.105 ± 0.015 ms); closed loop names d alone.
pub const MAX_OPEN_LOOP_TILT: f64 = 0.044_72;

/// The largest attitude error estimate |φ̂| [rad] of a pass and its time [s]: in open loop, how
/// far in attitude the free navigation the errors are linearised about drifts.
struct AttitudeDrift {
    /// Indices of φ_n, φ_e, φ_d in the model.
    phi: [Option<usize>; 3],
    /// Largest |φ̂| so far [rad].
    max: f64,
    /// Its time [s].
    t: f64,
    /// Asks the pass to end once |φ̂| passes [`MAX_OPEN_LOOP_TILT`] (explain then runs closed
    /// loop: the rest of the open-loop pass would be thrown away).
    stop_beyond: bool,
}

impl filter::Observer for AttitudeDrift {
    fn stop(&self) -> Option<String> {
        (self.stop_beyond && self.max > MAX_OPEN_LOOP_TILT).then(|| {
            format!(
                "the open-loop pass stopped at an attitude error estimate of {} deg",
                sig3(self.max.to_degrees())
            )
        })
    }
    fn nav_sample(&mut self, s: &NavState, x: &[f64], _p: &[f64]) {
        let v = self
            .phi
            .iter()
            .map(|i| i.map_or(0.0, |i| x[i] * x[i]))
            .sum::<f64>()
            .sqrt();
        if v > self.max {
            self.max = v;
            self.t = s.t;
        }
    }
}

impl AttitudeDrift {
    /// What the drift means for an open-loop explain, in words (times from `t0` [s]): for a
    /// pass stopped at the bound (explain then runs closed loop), where it passed it; for one
    /// that ran on in open loop, how far it drifted, with the advice to run closed loop.
    fn words(&self, t0: f64) -> String {
        let phi = self.max.min(std::f64::consts::PI);
        let off = 100.0 * (1.0 - phi.cos());
        let neglected_mg = 0.5 * phi * phi * 1e3;
        let (opening, advice) = if self.stop_beyond {
            ("", "")
        } else {
            (
                "Open loop about a drifting navigation: ",
                " Run with --mode closed (the navigation corrected at every fix) before reading the findings below as properties of the sensor.",
            )
        };
        // a stopped pass saw the drift only up to the small angles' bound
        let (when, growing) = if self.stop_beyond {
            (
                format!(
                    "passes {} deg, the small angles' bound (½φ²·g = 1 mg), {:.1} s after the start (the filter's estimate, {} deg there; the open-loop pass stopped)",
                    sig3(MAX_OPEN_LOOP_TILT.to_degrees()),
                    self.t - t0,
                    sig3(self.max.to_degrees())
                ),
                ", and growing with the drift",
            )
        } else {
            (
                format!(
                    "reaches {} deg (the filter's estimate, {:.1} s after the start)",
                    sig3(self.max.to_degrees()),
                    self.t - t0
                ),
                "",
            )
        };
        format!(
            "{opening}the attitude error of the free-inertial solution the open-loop error model is linearised about {when}, where the small-angle model's couplings are off by 1 − cos φ = {} % and the terms it neglects, ½φ²·g = {} mg on the specific force{growing}, can read as sensor or aiding terms.{advice}",
            sig3(off),
            sig3(neglected_mg),
        )
    }
}

/// Prior σ beyond which a baseline term's estimate says its prior is too tight.
const TIGHT_PRIOR_SIGMAS: f64 = 3.0;

/// The baseline pass and the selection rounds on it.
struct Stage {
    /// What `--truth` contradicts in the baseline's estimate, in words.
    truth_warning: Option<String>,
    /// Open loop about a navigation that drifts beyond small angles, in words.
    linearisation: Option<String>,
    base_stats: PassStats,
    innovations_before: Vec<Normalised>,
    model_error_before: Vec<(f64, f64, f64)>,
    tests: Vec<CandidateTest>,
    not_testable: Vec<String>,
    not_separable: Vec<(String, String)>,
    r: Rounds,
}

/// Runs the baseline pass with the candidates' signatures, tests every candidate and selects
/// and re-tests terms in rounds; `Err` with the drift, without the rounds, when an open-loop
/// pass drifts beyond [`MAX_OPEN_LOOP_TILT`] and the options say to run closed loop then.
fn baseline_and_select(
    ctx: &Context,
    cands: &[usize],
    progress: &mut dyn FnMut(usize, f64),
) -> anyhow::Result<Result<Stage, AttitudeDrift>> {
    let cfg = (ctx.config_for)(ctx.baseline)?;
    let open_loop = cfg.mode == filter::Mode::OpenLoop;
    let mut drift = AttitudeDrift {
        phi: ["phi_n", "phi_e", "phi_d"].map(|n| ctx.baseline.index_of(n)),
        max: 0.0,
        t: f64::NAN,
        stop_beyond: open_loop && ctx.opts.closed_loop_on_drift,
    };
    let mut order = offset_order::OffsetOrder::new(ctx.baseline);
    let base = run_pass_watched(
        ctx.baseline,
        cands,
        ctx.data,
        &cfg,
        &mut |f| progress(1, f),
        &mut filter::Tee(&mut drift, &mut order),
    );
    // (the pass stopped where the drift passed small angles: its run is cut short)
    let drifted = open_loop && drift.max > MAX_OPEN_LOOP_TILT;
    if drift.stop_beyond && drifted {
        return Ok(Err(drift));
    }
    let base = base?;
    let linearisation = drifted.then(|| drift.words(ctx.data.start.t));
    let base_stats = base.stats.clone();
    let innovations_before = normalised(&base.run);
    // a truth not of this run's attitude (or time) makes every model-error figure meaningless
    let phi = ["phi_n", "phi_e", "phi_d"].map(|n| ctx.baseline.index_of(n));
    let off = crate::estimate::metrics::attitude_disagreement(&base.run, phi);
    let truth_warning = crate::estimate::metrics::truth_disagreement(
        &off,
        "the model error (truth) figures measure",
    );
    let model_error_before = model_error_series(&base.run);
    let (tests, eligible) = candidate_tests(&base.sig, ctx.opts);
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
    let r = select_and_retest(ctx, cands.to_vec(), (base, order), &eligible, progress)?;
    Ok(Ok(Stage {
        truth_warning,
        linearisation,
        base_stats,
        innovations_before,
        model_error_before,
        tests,
        not_testable,
        not_separable,
        r,
    }))
}

/// What every phase of one explain run shares: the baseline, the data, the filter set-up of a
/// model and the options.
struct Context<'a> {
    baseline: &'a Model,
    data: &'a ExplainData<'a>,
    config_for: &'a dyn Fn(&Model) -> anyhow::Result<FilterConfig>,
    opts: &'a ExplainOptions,
}

impl Context<'_> {
    /// Filter configuration of an extended model: an added term starts from its candidate prior
    /// (the data's sensor class), widened where the data put it beyond.
    fn extended_config(&self, m: &Model, widened: &[(usize, f64)]) -> anyhow::Result<FilterConfig> {
        let mut cfg = (self.config_for)(m)?;
        for &(t, sigma) in &self.opts.candidate_sigma {
            if !self.baseline.states.contains(&StateRef::Term(t)) {
                if let Some(i) = m.index_of(common::TERMS[t].name) {
                    cfg.prior_sigma[i] = sigma;
                }
            }
        }
        widen_priors(&mut cfg, m, widened);
        Ok(cfg)
    }
}

/// The priors explain widens for baseline terms whose priors are too tight: (term, the
/// suggested σ, SI).
fn widened_priors(tight: &[TightPrior]) -> Vec<(usize, f64)> {
    tight
        .iter()
        .map(|p| (p.index, p.suggested * common::TERMS[p.index].display_to_si))
        .collect()
}

/// Widens the prior σ of each term in `widened` ((term, least σ, SI)) that `m` holds.
fn widen_priors(cfg: &mut FilterConfig, m: &Model, widened: &[(usize, f64)]) {
    for &(t, sigma) in widened {
        if let Some(i) = m.index_of(common::TERMS[t].name) {
            cfg.prior_sigma[i] = cfg.prior_sigma[i].max(sigma);
        }
    }
}

/// The model `base` with the spec terms `terms` added.
fn model_with(base: &str, terms: impl IntoIterator<Item = usize>) -> anyhow::Result<Model> {
    let mut text = base.to_string();
    for t in terms {
        text.push('+');
        text.push_str(common::TERMS[t].name);
    }
    Ok(Model::parse(&text)?)
}

/// A term the selection named in a round, before the extended filter has estimated it.
struct Named {
    /// Term index.
    term: usize,
    /// Conditional llr and Holm p-value when selected.
    llr: f64,
    p_value: f64,
    /// Its equivalence class with the value each member would need.
    equivalent_estimates: Vec<EquivalentTerm>,
    /// GLR estimate and σ when selected (display unit).
    glr_estimate: f64,
    glr_sigma: f64,
    /// Filter pass (1 = baseline) in which it was selected.
    round: usize,
    /// Baseline term it is not separable from at the regressor level, if any.
    confounded_with: Option<String>,
    /// Which excitation separates it from each equivalent term.
    separate_by: Vec<String>,
    /// Its GLR estimate and σ from each group of each split of the updates alone (display unit).
    splits: Vec<(Split, Vec<(f64, f64)>)>,
    /// Largest over smallest prior-σ count in its class (≥ 10: not attributed).
    prior_ratio: f64,
    /// Its share of its round's gain: 2Δℓ, and the mean NIS removed.
    two_delta_loglik: f64,
    nis_removed: f64,
}

impl Named {
    /// The record of selection `s` of a pass with signatures `sig` and candidate tests `tests`.
    fn new(
        s: &Selected,
        sig: &Signatures,
        tests: &[CandidateTest],
        round: usize,
        opts: &ExplainOptions,
    ) -> Named {
        let t = sig.cands[s.idx];
        Named {
            term: t,
            llr: s.llr,
            p_value: s.p,
            equivalent_estimates: s
                .class
                .iter()
                .map(|&(c, estimate, sigma)| {
                    let tc = sig.cands[c];
                    let in_prior =
                        estimate * common::TERMS[tc].display_to_si / prior_sigma(tc, opts);
                    EquivalentTerm::of(tc, (estimate, sigma, in_prior))
                })
                .collect(),
            glr_estimate: s.glr,
            glr_sigma: s.glr_sigma,
            round,
            confounded_with: tests[s.idx].confounded_with.clone(),
            separate_by: s
                .class
                .iter()
                .map(|c| separation_hint(t, sig.cands[c.0]))
                .collect(),
            splits: s.splits.clone(),
            prior_ratio: s.prior_ratio,
            two_delta_loglik: 0.0,
            nis_removed: 0.0,
        }
    }
}

/// The outcome of the rounds of selection and re-test.
struct Rounds {
    /// The last model the filter confirmed (the baseline when nothing was).
    model: Model,
    /// Its pass.
    pass: Pass,
    /// Terms named, in order.
    named: Vec<Named>,
    /// Terms whose extended-filter prior was widened: (term, least prior σ, SI).
    widened: Vec<(usize, f64)>,
    /// Terms the filter did not confirm: (term, 2Δℓ, penalty).
    unconfirmed: Vec<(String, f64, f64)>,
    /// Significant candidates with implausible values.
    implausible: Vec<Implausible>,
    /// Filter passes made.
    rounds: usize,
    /// Each pass that named a term: its round, candidates (term indices) and prior-scaled
    /// information per group, for the terms' consistency splits.
    split_passes: Vec<(usize, Vec<usize>, selection::Scaled)>,
    /// The velocity at the baseline pass's position fixes against its mean over spans before
    /// them: whether a time offset's first-order H describes an offset of a given size.
    offset_order: offset_order::OffsetOrder,
}

/// The Occam term ln det(I + S J S) of terms `added` (J their information through the pass of
/// `sig`, S the diagonal of their prior σ in the extended configuration `cfg` of `model`): what the filter's
/// 2Δℓ pays for giving the terms a prior instead of fitting them freely. In a linear Gaussian
/// model 2Δℓ + ln(1 + J σ²) = GLR · Jσ²/(1 + Jσ²): the GLR where the data outweigh the prior.
fn occam(sig: &Signatures, added: &[usize], model: &Model, cfg: &FilterConfig) -> f64 {
    let m = sig.cands.len();
    let at: Vec<(usize, f64)> = added
        .iter()
        .filter_map(|&t| {
            let c = sig.cands.iter().position(|&x| x == t)?;
            let i = model.index_of(common::TERMS[t].name)?;
            Some((c, cfg.prior_sigma[i]))
        })
        .collect();
    if at.is_empty() {
        return 0.0;
    }
    let j = sig.info();
    let k = at.len();
    let a = nalgebra::DMatrix::from_fn(k, k, |x, y| {
        let ((cx, sx), (cy, sy)) = (at[x], at[y]);
        f64::from(u8::from(x == y)) + sx * sy * j[cx * m + cy]
    });
    // (I + D J D is positive definite for a J that is; a J that is not gives no credit)
    match a.cholesky() {
        Some(c) => 2.0 * c.l().diagonal().iter().map(|d| d.ln()).sum::<f64>(),
        None => 0.0,
    }
}

/// The rounds with the model that holds only the causes among `findings` (no stand-in, no
/// unattributed class) and its pass, when that differs from the rounds' model; else as given.
fn without_stand_ins(
    ctx: &Context,
    mut r: Rounds,
    findings: &[Finding],
    progress: &mut dyn FnMut(usize, f64),
) -> anyhow::Result<Rounds> {
    if findings.iter().all(Finding::is_cause) {
        return Ok(r);
    }
    let causes = r
        .named
        .iter()
        .zip(findings)
        .filter(|(_, f)| f.is_cause())
        .map(|(n, _)| n.term);
    let model = model_with(&ctx.baseline.name, causes)?;
    let cfg = ctx.extended_config(&model, &r.widened)?;
    let round = r.rounds + 1;
    r.pass = run_pass(&model, &[], ctx.data, &cfg, &mut |f| progress(round, f))?;
    r.model = model;
    r.rounds = round;
    Ok(r)
}

/// Selection on the baseline pass, then rounds of adding the selected terms, re-running the
/// filter (which must confirm them at the selection's α, see [`occam`]) and selecting again; the
/// rounds keep what the baseline pass's [`offset_order::OffsetOrder`] watched.
fn select_and_retest(
    ctx: &Context,
    cands: Vec<usize>,
    (base, offset_order): (Pass, offset_order::OffsetOrder),
    eligible: &[bool],
    progress: &mut dyn FnMut(usize, f64),
) -> anyhow::Result<Rounds> {
    let opts = ctx.opts;
    let (mut selected_now, implausible) =
        forward_select(&base.sig, eligible, base.run.innovations.len(), opts);
    let mut r = Rounds {
        model: ctx.baseline.clone(),
        pass: base,
        named: Vec::new(),
        widened: Vec::new(),
        unconfirmed: Vec::new(),
        implausible,
        rounds: 1,
        split_passes: Vec::new(),
        offset_order,
    };
    let mut excluded: Vec<usize> = Vec::new(); // term indices in a class or added
    let mut pool_terms = cands;
    while !selected_now.is_empty() {
        let mut added = Vec::new();
        let (named_before, widened_before) = (r.named.len(), r.widened.len());
        let tests_now = candidate_tests(&r.pass.sig, opts).0;
        r.split_passes.push((
            r.rounds,
            r.pass.sig.cands.clone(),
            selection::scaled(&r.pass.sig, opts),
        ));
        for s in &selected_now {
            let named = Named::new(s, &r.pass.sig, &tests_now, r.rounds, opts);
            let t = named.term;
            excluded.push(t);
            excluded.extend(s.class.iter().map(|c| r.pass.sig.cands[c.0]));
            // the extended filter's prior must hold what the data say: a GLR estimate beyond
            // 2 prior σ widens it to 3 (|θ̂| + σ̂)
            let info_t = &common::TERMS[t];
            // (never past the σ the term can physically have: its spec `limit`)
            if s.glr.abs() * info_t.display_to_si > 2.0 * prior_sigma(t, opts) {
                let wide = 3.0 * (s.glr.abs() + s.glr_sigma) * info_t.display_to_si;
                r.widened
                    .push((t, wide.min(info_t.limit).max(prior_sigma(t, opts))));
            }
            r.named.push(named);
            added.push(t);
        }
        let next_model = model_with(&r.model.name, added.iter().copied())?;
        pool_terms.retain(|t| !excluded.contains(t));
        let last_round = r.rounds >= opts.max_rounds;
        let cfg = ctx.extended_config(&next_model, &r.widened)?;
        let round = r.rounds + 1;
        let next_pass = run_pass(
            &next_model,
            if last_round { &[] } else { &pool_terms },
            ctx.data,
            &cfg,
            &mut |f| progress(round, f),
        )?;
        r.rounds = round;
        // the filter must confirm what the signatures predicted, at the selection's α: its
        // 2Δℓ, with the prior's Occam term added back, must pass the χ²_k quantile 1 − α
        // (times φ, as the selection's quasi-likelihood); else the linearisation did not hold
        // (or the misfit is something else) and the round is undone
        let gain = next_pass.stats.loglik - r.pass.stats.loglik;
        let statistic = 2.0 * gain + occam(&r.pass.sig, &added, &next_model, &cfg);
        let threshold =
            r.pass.sig.dispersion.max(1.0) * stats::chi2_isf(opts.alpha, added.len() as f64);
        if statistic <= threshold && !opts.broken_selector {
            r.unconfirmed.extend(
                added
                    .iter()
                    .map(|&t| (common::TERMS[t].name.to_string(), statistic, threshold)),
            );
            r.named.truncate(named_before);
            r.widened.truncate(widened_before);
            break;
        }
        // the round's gain, shared among its terms by their conditional llr
        let llr_sum: f64 = r.named[named_before..].iter().map(|n| n.llr).sum();
        let nis_removed = r.pass.stats.nis_mean - next_pass.stats.nis_mean;
        for n in &mut r.named[named_before..] {
            let w = if llr_sum > 0.0 {
                n.llr / llr_sum
            } else {
                1.0 / added.len() as f64
            };
            n.two_delta_loglik = 2.0 * gain * w;
            n.nis_removed = nis_removed * w;
        }
        r.model = next_model;
        r.pass = next_pass;
        if last_round {
            break;
        }
        let (_, eligible_now) = candidate_tests(&r.pass.sig, opts);
        let (sel, imp) = forward_select(
            &r.pass.sig,
            &eligible_now,
            r.pass.run.innovations.len(),
            opts,
        );
        selected_now = sel;
        for i in imp {
            if !r.implausible.iter().any(|x| x.term == i.term) {
                r.implausible.push(i);
            }
        }
    }
    resplit(&mut r);
    Ok(r)
}

/// Each named term's group estimates again from the pass that named it, with every other term
/// named in the end free there too (terms named in later rounds were candidates of that pass;
/// left out, a later term's effect would bias the groups of an earlier one and fail its
/// consistency test, though the extended filter holds both).
fn resplit(r: &mut Rounds) {
    let all: Vec<usize> = r.named.iter().map(|n| n.term).collect();
    for n in &mut r.named {
        let Some((_, cands, sc)) = r.split_passes.iter().find(|p| p.0 == n.round) else {
            continue;
        };
        let Some(me) = cands.iter().position(|&c| c == n.term) else {
            continue;
        };
        let others: Vec<usize> = all
            .iter()
            .filter(|&&t| t != n.term)
            .filter_map(|&t| cands.iter().position(|&c| c == t))
            .collect();
        n.splits = selection::split_estimates(sc, cands, me, &others);
    }
    r.split_passes.clear();
}

/// The findings of the rounds: each named term with the extended filter's estimate, its prior,
/// its mean regressor and effect on these data, and the words; `excess` is the baseline's
/// excess mean NIS and `unexplained` the share of it the extended model leaves.
fn complete_findings(
    ctx: &Context,
    r: &Rounds,
    excess: Option<f64>,
    unexplained: Option<f64>,
) -> anyhow::Result<Vec<Finding>> {
    let terms: Vec<usize> = r.named.iter().map(|n| n.term).collect();
    let means = if terms.is_empty() {
        Vec::new()
    } else {
        regressor_stats(ctx.data, &terms)?
    };
    let last = r.pass.run.records.last();
    let used_priors = ctx.extended_config(&r.model, &r.widened)?.prior_sigma;
    let mut out = Vec::new();
    for (n, &c) in r.named.iter().zip(&means) {
        let t = n.term;
        let info = &common::TERMS[t];
        let to_display = 1.0 / info.display_to_si;
        let (mut estimate, mut sigma, mut prior, mut widened) = (0.0, 0.0, 0.0, false);
        if let (Some(i), Some(rec)) = (r.model.index_of(info.name), last) {
            estimate = rec.x[i] * to_display;
            sigma = rec.sigma[i] * to_display;
            prior = used_priors[i] * to_display;
            widened = used_priors[i] > prior_sigma(t, ctx.opts);
        }
        let (regressor_mean, regressor_unit) = regressor_in_natural_units(info.regressor, c.mean);
        let (regressor_excited_mean, _) =
            regressor_in_natural_units(info.regressor, c.excited_mean);
        let effect_of = |r: f64| {
            let effect_si = estimate / to_display * r;
            match info.sensor {
                Sensor::Accel => (effect_si / G0 * 1e3, "mg"),
                Sensor::Gyro => (effect_si * 180.0 / std::f64::consts::PI * 3600.0, "deg/h"),
                // a GNSS term acts on the aiding as itself
                Sensor::Gnss | Sensor::Reference | Sensor::Attitude => (estimate, info.display),
            }
        };
        let (effect, effect_unit) = effect_of(c.mean);
        let (effect_excited, _) = effect_of(c.excited_mean);
        let mut f = Finding {
            term: info.name.to_string(),
            kind: if info.sensor.enters_h() {
                "measurement"
            } else {
                "sensor"
            },
            estimate,
            sigma,
            unit: info.display.to_string(),
            llr: n.llr,
            p_value: n.p_value,
            equivalent: n
                .equivalent_estimates
                .iter()
                .map(|e| e.term.clone())
                .collect(),
            equivalent_estimates: n.equivalent_estimates.clone(),
            withheld_alike: Vec::new(),
            glr_estimate: n.glr_estimate,
            glr_sigma: n.glr_sigma,
            round: n.round,
            confounded_with: n.confounded_with.clone(),
            regressor_mean,
            regressor_unit,
            regressor_excited_mean,
            excited_fraction: c.excited_fraction,
            effect_excited,
            effect,
            effect_unit: effect_unit.into(),
            separate_by: n.separate_by.clone(),
            prior_sigma: prior,
            prior_widened: widened,
            words: String::new(),
            headline: String::new(),
            two_delta_loglik: n.two_delta_loglik,
            misfit_share: excess.map(|e| n.nis_removed / e),
            prior_sigmas: (estimate / to_display).abs() / prior_sigma(t, ctx.opts),
            stand_in: None,
            suggested_prior: None,
            offset_in_place: None,
            // the priors choose within a class when they differ by an order of magnitude; they
            // are credible for that only while the chosen member sits within 3 of its prior σ
            not_attributed: (n.prior_ratio >= selection::UNATTRIBUTED_RATIO
                && !n.equivalent_estimates.is_empty()
                && (estimate / to_display).abs() > 3.0 * prior_sigma(t, ctx.opts))
            .then(|| {
                format!(
                    "the data cannot tell {} from {}, the values they would need differ by {}× in prior σ ({}), and even the most plausible is beyond 3 prior σ: priors that do not fit this sensor would choose, not the data; an excitation that separates them decides",
                    info.name,
                    n.equivalent_estimates
                        .iter()
                        .map(|e| e.term.as_str())
                        .collect::<Vec<_>>()
                        .join(", "),
                    sig3(n.prior_ratio),
                    std::iter::once(format!(
                        "{} {}",
                        info.name,
                        sig3((estimate / to_display).abs() / prior_sigma(t, ctx.opts))
                    ))
                    .chain(
                        n.equivalent_estimates
                            .iter()
                            .map(|e| format!("{} {}", e.term, sig3(e.prior_sigmas.abs())))
                    )
                    .collect::<Vec<_>>()
                    .join(", ")
                )
            }),
            not_attributed_because: Vec::new(),
            scale: None,
            scale_interval: None,
            scale_bound: None,
            halves: split_halves(&n.splits, "time"),
            speed_halves: split_halves(&n.splits, "speed"),
            // the kinds of fix test the aiding's own terms (a sensor term's information from
            // positions and from velocities is one signature seen twice)
            consistency: n
                .splits
                .iter()
                .filter(|(split, _)| *split != Split::Measurement || info.sensor.enters_h())
                .map(|(split, est)| {
                    Consistency::test(split.name(), &|k| split.group_label(k), est)
                })
                .collect(),
        };
        if f.not_attributed.is_some() {
            f.not_attributed_because.push(Unnamed::ClassNotSeparable);
        }
        f.stand_in = stand_in_reason(&f, unexplained, ctx.opts, Some(&r.offset_order));
        f.suggested_prior = suggested_prior(&f, ctx.opts);
        (f.headline, f.words) =
            finding_words(&f, info, prior_sigma(t, ctx.opts) / info.display_to_si);
        out.push(f);
    }
    Ok(out)
}

/// A two-group split's estimates as `[[estimate, σ], [estimate, σ]]` (the JSON's `halves` and
/// `speed_halves`), when the run has that split.
fn split_halves(splits: &[(Split, Vec<(f64, f64)>)], name: &str) -> Option<[[f64; 2]; 2]> {
    splits
        .iter()
        .find(|(s, g)| s.name() == name && g.len() == 2)
        .map(|(_, g)| [[g[0].0, g[0].1], [g[1].0, g[1].1]])
}

/// The baseline's excess mean NIS (mean NIS − 1) when it lies above the 95 % band of its count
/// (an excess to explain), else `None`.
fn baseline_excess(base: &PassStats) -> Option<f64> {
    let n: usize = base.channels.iter().map(|c| c.count).sum();
    let band = stats::mean_chi2_band(1.0, n.max(1), 1.959_964);
    (base.nis_mean > band[1]).then_some(base.nis_mean - 1.0)
}

/// Why finding `f` probably stands in for something the candidates do not describe, if it
/// does: it needs more than `stand_in_prior_sigmas` of its prior, or, beyond
/// [`SMALL_SHARE_PRIOR_SIGMAS`] prior σ, the extended filter's gain for it (2Δℓ) is below the
/// prior's objection z² to a value at z prior σ, or, beyond that many prior σ and with a support
/// below [`SMALL_SHARE_SUPPORT`] z², its round removed less than `stand_in_share` of the baseline's
/// excess misfit (`unexplained`, the share the extended model leaves, is said with it).
fn stand_in_reason(
    f: &Finding,
    unexplained: Option<f64>,
    opts: &ExplainOptions,
    order: Option<&offset_order::OffsetOrder>,
) -> Option<String> {
    let mut why: Vec<String> = f
        .consistency
        .iter()
        .filter_map(|c| c.disagreement(&f.unit))
        .collect();
    if let Some(info) = common::TERMS.iter().find(|t| t.name == f.term) {
        let value_si = f.estimate * info.display_to_si;
        // an IMU–GNSS time offset its H (v·dt) does not describe on the pass's motion
        if info.name == "dt_gnss" {
            why.extend(order.and_then(|o| o.stand_in_words(value_si)));
        }
        // a value the term cannot physically have is no property of the sensor
        if value_si.abs() > info.limit {
            let (v, l) =
                crate::io::units::sig_distinct(f.estimate, info.limit / info.display_to_si);
            why.push(format!(
                "{v} {} is beyond the {l} {} the term can physically have (its `limit` in model-spec/terms.toml)",
                f.unit, f.unit
            ));
        }
    }
    let z = f.prior_sigmas;
    // the posterior prefers the fitted value to none only when the data's support (2Δℓ)
    // outweighs the prior's objection to a value at z prior σ (z²)
    let unsupported = z > SMALL_SHARE_PRIOR_SIGMAS && f.two_delta_loglik < z * z;
    // a value within a few prior σ that explains little is a small effect beside larger ones,
    // not a stand-in; nor is one whose support exceeds the prior's objection several times over
    // (where several causes share the misfit, each removes a small part of it)
    let small_share = f.misfit_share.filter(|&share| {
        share < opts.stand_in_share
            && z > SMALL_SHARE_PRIOR_SIGMAS
            && f.two_delta_loglik < SMALL_SHARE_SUPPORT * z * z
    });
    let mut clauses = Vec::new();
    if z > opts.stand_in_prior_sigmas {
        clauses.push(format!("it needs {} prior σ", sig3(z)));
    } else if unsupported {
        clauses.push(format!(
            "at {} prior σ the sensor's prior objects to it by z² = {}, more than the data support it (2Δℓ {}): as a property of this sensor it is less credible than none, unless the prior is too tight for this unit",
            sig3(z),
            sig3(z * z),
            sig3(f.two_delta_loglik)
        ));
    }
    if let Some(share) = small_share {
        // (its prior σ said once: the clause before may have given them)
        clauses.push(format!(
            "{} removes only {} % of the baseline's excess misfit{}",
            if clauses.is_empty() {
                format!("it needs {} prior σ yet", sig3(z))
            } else if z > opts.stand_in_prior_sigmas {
                "and it".into()
            } else {
                "it".into()
            },
            sig3(100.0 * share.max(0.0)),
            unexplained
                .filter(|l| *l >= 0.01)
                .map(|l| format!(" (the extended model leaves {} % of it)", sig3(100.0 * l)))
                .unwrap_or_default()
        ));
    }
    why.extend(clauses);
    (!why.is_empty()).then(|| why.join("; "))
}

/// A prior σ (display unit) that would hold stand-in `f`'s value, when it is a stand-in only
/// because it needs more than `stand_in_prior_sigmas` of its prior: within the term's `limit`,
/// every consistency split tested holds (at least one was tested) and it explains more than
/// half of the baseline's excess misfit. 3× its magnitude rounded up to one significant digit,
/// at most the `limit`.
fn suggested_prior(f: &Finding, opts: &ExplainOptions) -> Option<f64> {
    let info = common::TERMS.iter().find(|t| t.name == f.term)?;
    let limit = info.limit / info.display_to_si;
    let holds = f.consistency.iter().any(|c| c.tested) && f.consistency.iter().all(|c| c.holds);
    (f.stand_in.is_some()
        && f.prior_sigmas > opts.stand_in_prior_sigmas
        && holds
        && f.misfit_share.is_some_and(|s| s > 0.5)
        && f.estimate.abs() <= limit)
        .then(|| round_up_1(3.0 * f.estimate.abs()).min(limit))
}

/// A regressor's statistics over the run (SI): its mean, and its mean and share of the samples
/// where it is excited.
#[derive(Debug, Clone, Copy, Default)]
struct RegressorStats {
    /// Mean over every sample.
    mean: f64,
    /// Mean over the samples where |r| is at least a tenth of its 99.9th percentile.
    excited_mean: f64,
    /// Share of the samples where it is excited.
    excited_fraction: f64,
}

/// Each term's regressor statistics (SI), in one pass over the IMU samples (the extended pass
/// has no candidates, so they are computed from the samples directly). |r| is binned on a log
/// scale (20 bins per decade over 1e-15..1e10, sums kept per bin), so the percentile and the
/// excited mean need no second pass and no memory per sample.
fn regressor_stats(data: &ExplainData, terms: &[usize]) -> anyhow::Result<Vec<RegressorStats>> {
    const PER_DECADE: f64 = 20.0;
    const LO: f64 = -15.0;
    const BINS: usize = 500;
    let bin = |a: f64| -> Option<usize> {
        (a > 0.0).then(|| (((a.log10() - LO) * PER_DECADE).floor().max(0.0) as usize).min(BINS - 1))
    };
    let mut prev = data.start.t;
    let mut sums = vec![0.0; terms.len()];
    let mut hist = vec![vec![(0u64, 0.0f64); BINS]; terms.len()];
    let mut c = 0usize;
    let mut samples = data.imu.samples()?;
    let mut rates = crate::model::SignalRates::default();
    while let Some(smp) = samples.next_sample()? {
        let dt = smp.t - prev;
        prev = smp.t;
        if dt > 0.0 {
            let sig = rates.next(&(smp.dv / dt), &(smp.dtheta / dt), dt);
            for (k, &t) in terms.iter().enumerate() {
                let r = common::regressor_value(common::TERMS[t].regressor, &sig);
                sums[k] += r;
                if let Some(b) = bin(r.abs()) {
                    hist[k][b].0 += 1;
                    hist[k][b].1 += r;
                }
            }
            c += 1;
        }
    }
    let n = c.max(1) as f64;
    Ok(sums
        .iter()
        .zip(&hist)
        .map(|(&sum, h)| {
            // the 99.9th percentile of |r| (lower edge of its bin), then the bins from a tenth of it
            let mut above = 0u64;
            let mut top = 0;
            for b in (0..BINS).rev() {
                above += h[b].0;
                if above as f64 >= 0.001 * n {
                    top = b;
                    break;
                }
            }
            let from = top.saturating_sub(PER_DECADE as usize);
            let (cnt, s) = h[from..]
                .iter()
                .fold((0u64, 0.0), |(a, b), x| (a + x.0, b + x.1));
            RegressorStats {
                mean: sum / n,
                excited_mean: if cnt > 0 { s / cnt as f64 } else { 0.0 },
                excited_fraction: cnt as f64 / n,
            }
        })
        .collect())
}

fn normalised(run: &FilterRun) -> Vec<Normalised> {
    run.innovations
        .iter()
        .map(|i| Normalised::new(i.t, i.meas, i.component, i.nu / i.s.sqrt()))
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

/// Term `term`'s estimates (display unit) from each kind of fix alone (positions, velocities,
/// attitudes) through `model`'s filter on these data, each with the others' information left
/// out, and whether they describe one value (the findings' split test): a time offset of the
/// fixes must be one value for the receiver's positions and its velocities.
pub fn measurement_consistency(
    model: &Model,
    term: usize,
    data: &ExplainData,
    cfg: &FilterConfig,
    opts: &ExplainOptions,
) -> anyhow::Result<Consistency> {
    let pass = run_pass(model, &[term], data, cfg, &mut |_| {})?;
    let sc = selection::scaled(&pass.sig, opts);
    let (split, est) = selection::split_estimates(&sc, &[term], 0, &[])
        .into_iter()
        .find(|(s, _)| *s == Split::Measurement)
        .expect("the pass keeps the split by measurement");
    Ok(Consistency::test(
        split.name(),
        &|k| split.group_label(k),
        &est,
    ))
}

/// Joint information J (m × m, row-major, SI) of the signatures of `terms` through `model`'s
/// filter on these data, from one pass: θ_i² / (J⁻¹)_ii is the noncentrality of term i's test
/// with the others estimated beside it (for one term, θ² J); J does not depend on θ or on the
/// data's values, so it can be computed before the terms are put into the data.
pub fn signature_information_matrix(
    model: &Model,
    terms: &[usize],
    data: &ExplainData,
    cfg: &FilterConfig,
) -> anyhow::Result<Vec<f64>> {
    let pass = run_pass(model, terms, data, cfg, &mut |_| {})?;
    Ok(pass.sig.info())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_rule_that_unnames_a_finding_is_recorded_once_in_order() {
        let mut f = finding(5.0, Some(0.8));
        assert!(f.is_cause() && f.not_attributed_because.is_empty());
        not_named(&mut f, Unnamed::ValueMoves, "a".into());
        not_named(&mut f, Unnamed::LeansOnStandIn, "b".into());
        not_named(&mut f, Unnamed::ValueMoves, "c".into());
        assert!(!f.is_cause());
        assert_eq!(
            f.not_attributed_because,
            [Unnamed::ValueMoves, Unnamed::LeansOnStandIn]
        );
        assert_eq!(f.not_attributed.as_deref(), Some("a; b; c"));
        assert!(
            f.words.ends_with(". Not named as a cause: c"),
            "{}",
            f.words
        );
        // each rule says something of its own, in the report and in the JSON
        let all = [
            Unnamed::ClassNotSeparable,
            Unnamed::WithheldTermFits,
            Unnamed::LeansOnWithheldTerm,
            Unnamed::ValueMoves,
            Unnamed::ValueNearZero,
            Unnamed::LeansOnStandIn,
            Unnamed::AidingSensorConfound,
            Unnamed::OffsetUnsettled,
            Unnamed::OffsetNotBorneOut,
            Unnamed::NoiseBesideOffset,
            Unnamed::OffsetOrLeverArm,
        ];
        let distinct = |x: Vec<String>| x.iter().collect::<std::collections::HashSet<_>>().len();
        assert_eq!(
            distinct(all.iter().map(|u| u.words().0.into()).collect()),
            all.len()
        );
        assert_eq!(
            distinct(all.iter().map(|u| u.words().1.into()).collect()),
            all.len()
        );
        let json = |u: &Unnamed| serde_json::to_string(u).unwrap();
        assert_eq!(distinct(all.iter().map(json).collect()), all.len());
        assert_eq!(json(&Unnamed::WithheldTermFits), "\"withheld_term_fits\"");
        // the README lists every rule by its JSON name
        let readme = include_str!("../../README.md");
        for u in &all {
            let name = format!("`{}`", json(u).trim_matches('"'));
            assert!(readme.contains(&name), "README.md does not list {name}");
        }
    }

    fn finding(prior_sigmas: f64, misfit_share: Option<f64>) -> Finding {
        Finding {
            term: "size_x".into(),
            kind: "sensor",
            estimate: 0.0,
            sigma: 0.0,
            unit: "mm".into(),
            llr: 0.0,
            p_value: 0.0,
            equivalent: vec![],
            equivalent_estimates: vec![],
            withheld_alike: Vec::new(),
            glr_estimate: 0.0,
            glr_sigma: 0.0,
            round: 1,
            confounded_with: None,
            regressor_mean: 0.0,
            regressor_excited_mean: 0.0,
            excited_fraction: 0.0,
            effect_excited: 0.0,
            regressor_unit: String::new(),
            effect: 0.0,
            effect_unit: String::new(),
            separate_by: vec![],
            prior_sigma: 0.0,
            prior_widened: false,
            words: String::new(),
            headline: String::new(),
            two_delta_loglik: 0.0,
            misfit_share,
            prior_sigmas,
            stand_in: None,
            suggested_prior: None,
            offset_in_place: None,
            not_attributed: None,
            not_attributed_because: Vec::new(),
            scale: None,
            scale_interval: None,
            scale_bound: None,
            halves: None,
            speed_halves: None,
            consistency: vec![],
        }
    }

    #[test]
    fn a_finding_far_beyond_its_prior_or_explaining_little_is_a_stand_in() {
        let o = ExplainOptions::default();
        // within its prior and explaining most of the misfit: a cause
        assert!(stand_in_reason(&finding(3.0, Some(0.9)), Some(0.05), &o, None).is_none());
        // the baseline was consistent (no excess to share): judged by its prior alone
        assert!(stand_in_reason(&finding(3.0, None), None, &o, None).is_none());
        let far = stand_in_reason(&finding(91.0, Some(0.9)), Some(0.05), &o, None).unwrap();
        assert!(far.contains("91.0 prior σ"), "{far}");
        let little = stand_in_reason(&finding(6.0, Some(0.08)), Some(0.9), &o, None).unwrap();
        assert!(
            little.contains("8.00 %") && little.contains("leaves 90.0 %"),
            "{little}"
        );
        // explaining little counts beyond 5 prior σ (within them: a small effect beside larger
        // ones, e.g. a 3.6 σ lever arm beside an asynchrony), whatever is left
        assert!(stand_in_reason(&finding(6.0, Some(0.08)), Some(0.0), &o, None).is_some());
        assert!(stand_in_reason(&finding(3.6, Some(0.08)), Some(0.0), &o, None).is_none());
        assert!(stand_in_reason(&finding(0.6, Some(0.06)), Some(0.53), &o, None).is_none());
        assert!(stand_in_reason(&finding(5.0, Some(0.5)), Some(0.0), &o, None).is_none());
    }

    #[test]
    fn a_finding_the_data_support_less_than_its_prior_objects_is_a_stand_in() {
        let o = ExplainOptions::default();
        let with = |z: f64, share: Option<f64>, two_dl: f64| {
            let mut f = finding(z, share);
            f.two_delta_loglik = two_dl;
            stand_in_reason(&f, Some(0.0), &o, None)
        };
        // 19 prior σ (z² 361) on a consistent baseline, supported by 2Δℓ 15.8: a stand-in
        let w = with(19.0, None, 15.8).unwrap();
        assert!(w.contains("z² = 361") && w.contains("2Δℓ 15.8"), "{w}");
        // the same value with overwhelming support: the prior is too tight, not the value wrong
        assert!(with(19.0, None, 400.0).is_none());
        // within 5 prior σ the prior's objection is not decisive
        assert!(with(4.9, None, 1.0).is_none());
        // a small share beside other causes is spared when the support is 4× the objection…
        assert!(with(6.2, Some(0.09), 432.0).is_none());
        // …and not below that
        let w = with(8.2, Some(0.0016), 78.7).unwrap();
        assert!(w.contains("it needs 8.20 prior σ yet removes only"), "{w}");
    }

    #[test]
    fn a_term_whose_groups_disagree_does_not_hold_across_the_data() {
        let halves = |k| Split::Time(0.0).group_label(k);
        let test = |e: &[(f64, f64)]| Consistency::test("time", &halves, e);
        // one constant: the halves agree within their σ
        assert!(test(&[(-0.34, 0.02), (-0.36, 0.02)]).holds);
        // many σ apart but within a quarter: a constant the model describes a little unevenly
        assert!(test(&[(179.0, 1.0), (190.0, 1.0)]).holds);
        // far apart on both counts
        let c = test(&[(-1.6, 0.02), (-0.4, 0.02)]);
        assert!(!c.holds && c.dof == 1 && c.p_value < 1e-6);
        assert!(
            c.tested && c.why.starts_with("fails: χ² p") && c.why.contains("(-1.60)"),
            "{}",
            c.why
        );
        let w = c.disagreement("m").unwrap();
        assert!(w.contains("-1.60 ± 0.020 and -0.400 ± 0.020 m"), "{w}");
        let c = test(&[(179.0, 1.0), (190.0, 1.0)]);
        assert!(
            c.tested
                && c.why.starts_with("holds: χ² p")
                && c.why.contains("differ by more than a quarter"),
            "{}",
            c.why
        );
        // a half without information says nothing: no test, not a passed one
        let c = test(&[(1.0, f64::INFINITY), (5.0, 0.1)]);
        assert!(c.holds && c.dof == 0 && c.groups.len() == 1);
        assert!(!c.tested && c.why.starts_with("not tested: 1 of the 2 groups"));
        let j = serde_json::to_value(&c).unwrap();
        assert!(j["p_value"].is_null() && j["tested"] == false, "{j}");
        // nor does one whose σ is absurd beside the others'
        let c = test(&[(-4.2e12, 4.2e14), (5.0, 0.1)]);
        assert!(!c.tested && c.groups.len() == 1 && c.groups[0].estimate == 5.0);
        assert!(c.p_value.is_nan() && c.holds && c.uninformative_groups == 1);
        let c = Consistency::test(
            "motion",
            &|k| Split::Motion.group_label(k),
            &[(-4.2e12, 4.2e14), (5.0, 0.1), (5.1, 0.1)],
        );
        assert!(
            c.tested && c.groups.len() == 2 && c.uninformative_groups == 1 && c.dof == 2,
            "{c:?}"
        );
        assert!(c.why.starts_with("holds: the groups agree"), "{}", c.why);
        // four groups: three agree, one is far off; the words name every group
        let motion = |k| Split::Motion.group_label(k);
        let c = Consistency::test(
            "motion",
            &motion,
            &[(10.0, 1.0), (11.0, 1.0), (9.5, 1.0), (40.0, 2.0)],
        );
        assert!(!c.holds && c.dof == 3, "{c:?}");
        let w = c.disagreement("mm").unwrap();
        assert!(w.contains("40.0 ± 2.00 after rotating about z"), "{w}");
        // four groups within noise
        let c = Consistency::test(
            "motion",
            &motion,
            &[(10.0, 1.0), (11.0, 1.0), (9.5, 1.0), (12.0, 2.0)],
        );
        assert!(c.holds, "{c:?}");
        let mut f = finding(0.9, Some(0.3));
        f.consistency = vec![Consistency::test(
            "speed",
            &|k| Split::Speed(1.0).group_label(k),
            &[(-1.6, 0.02), (-0.4, 0.02)],
        )];
        let why = stand_in_reason(&f, Some(0.0), &ExplainOptions::default(), None).unwrap();
        assert!(why.contains("slower and the faster"), "{why}");
    }

    #[test]
    fn a_stand_in_only_for_its_prior_says_which_prior_would_hold_it() {
        let o = ExplainOptions::default();
        let t = common::TERMS
            .iter()
            .position(|t| t.name == "tau_x")
            .unwrap();
        let info = &common::TERMS[t];
        let holds =
            |e: &[(f64, f64)]| Consistency::test("time", &|k| Split::Time(0.0).group_label(k), e);
        // the review's case: tau_x = 40.0 ± 0.293 ms, 40 prior σ, explaining 104 %
        let mut f = finding(40.0, Some(1.04));
        f.term = "tau_x".into();
        f.unit = info.display.into();
        f.estimate = 40.0;
        f.sigma = 0.293;
        f.consistency = vec![holds(&[(40.1, 0.4), (39.9, 0.4)])];
        f.stand_in = stand_in_reason(&f, Some(0.0), &o, None);
        assert!(f.stand_in.is_some());
        // 3 × 40 = 120 → 200 ms, beyond the 100 ms tau_x can have: the limit
        f.suggested_prior = suggested_prior(&f, &o);
        assert_eq!(f.suggested_prior, Some(100.0));
        let (_, w) = finding_words(&f, info, 1.0);
        assert!(
            w.contains("give --prior 'tau_x=100 ms' (a prior that holds it) and run again"),
            "{w}"
        );
        // 10 ms: 30 → 30 ms
        let mut g = f.clone();
        g.estimate = 10.0;
        assert_eq!(suggested_prior(&g, &o), Some(30.0));
        // not when a split fails, none was tested, it explains little, or it is within 30 σ
        let mut g = f.clone();
        g.consistency = vec![holds(&[(40.0, 0.4), (10.0, 0.4)])];
        assert_eq!(suggested_prior(&g, &o), None);
        g.consistency = vec![holds(&[(40.0, 0.4), (10.0, f64::INFINITY)])];
        assert_eq!(suggested_prior(&g, &o), None);
        let mut g = f.clone();
        g.misfit_share = Some(0.3);
        assert_eq!(suggested_prior(&g, &o), None);
        let mut g = f.clone();
        g.prior_sigmas = 20.0;
        assert_eq!(suggested_prior(&g, &o), None);
        let mut g = f.clone();
        g.stand_in = None;
        assert_eq!(suggested_prior(&g, &o), None);
        assert!(!finding_words(&g, info, 1.0).1.contains("--prior"));
    }

    #[test]
    fn a_suggested_prior_is_3x_the_estimate_rounded_up_to_one_digit() {
        // 3 × 408 µg = 1224 µg → 2000 µg; 3 × 0.0041 = 0.0123 → 0.02
        assert_eq!(round_up_1(3.0 * 408.0), 2000.0);
        assert!((round_up_1(3.0 * 0.0041) - 0.02).abs() < 1e-15);
        assert_eq!(round_up_1(300.0), 300.0);
    }

    #[test]
    fn an_unattributed_class_names_no_member_in_its_words() {
        let t = common::TERMS
            .iter()
            .position(|t| t.name == "kas_x")
            .unwrap();
        let info = &common::TERMS[t];
        let mut f = finding(40.0, Some(0.9));
        f.term = "kas_x".into();
        f.unit = info.display.into();
        f.equivalent = vec!["kao_x".into()];
        f.equivalent_estimates = vec![EquivalentTerm {
            term: "kao_x".into(),
            estimate: 5.0,
            sigma: 0.1,
            unit: "ppm".into(),
            prior_sigmas: 900.0,
        }];
        f.separate_by = vec!["two vibration amplitudes separate them".into()];
        let (_, named) = finding_words(&f, info, 1.0);
        assert!(
            named.contains("named: the one the spec's priors"),
            "{named}"
        );
        f.not_attributed = Some("the priors would choose".into());
        let (headline, w) = finding_words(&f, info, 1.0);
        assert!(
            !w.contains("named: the one") && w.contains("none named; kas_x stands for the class"),
            "{w}"
        );
        // the headline is what the finding is and its value, and the words begin with it
        assert!(
            w.starts_with(&headline) && headline.contains("kas_x = ") && !headline.contains(';'),
            "{headline} / {w}"
        );
    }

    #[test]
    fn the_excess_to_explain_needs_a_mean_nis_above_its_band() {
        let pass = |nis: f64, count: usize| PassStats {
            model: "P28".into(),
            t_start: 0.0,
            loglik: 0.0,
            nis_mean: nis,
            whiteness_p: 1.0,
            channels: vec![ChannelStats {
                channel: "vel_n".into(),
                count,
                nis_mean: nis,
                nis_band: [0.0, 0.0],
                fraction_outside_95: 0.0,
                ljung_box_q: None,
                whiteness_p: None,
                segments: vec![],
            }],
            model_error_rms_arcsec: None,
            truth_check: vec![],
        };
        assert_eq!(baseline_excess(&pass(1.02, 1000)), None);
        let e = baseline_excess(&pass(5.59, 1000)).unwrap();
        assert!((e - 4.59).abs() < 1e-12);
        // with 10 innovations a mean NIS of 1.5 is within the band
        assert_eq!(baseline_excess(&pass(1.5, 10)), None);
    }

    #[test]
    fn a_file_replaced_between_passes_is_refused() {
        let dir = std::env::temp_dir().join(format!("sinsmodel-identity-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("imu.txt");
        let rows = |n: usize| -> String {
            let mut s = String::from("# t dth dv\n");
            for k in 1..=n {
                s.push_str(&format!("{:.2} 0 0 0 0 0 -0.098\n", k as f64 * 0.01));
            }
            s
        };
        std::fs::write(&p, rows(50)).unwrap();
        let input = ImuInput::File {
            path: &p,
            format: None,
            clock_offset: None,
            skip_through: 0.0,
            identity: Some(FileIdentity::of(&p).unwrap()),
        };
        assert!(input.samples().is_ok());
        std::fs::write(&p, rows(60)).unwrap();
        let e = input.samples().err().unwrap().to_string();
        assert!(e.contains("changed while explain was running"), "{e}");
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn candidates_can_be_withheld_by_name_or_family() {
        let base = Model::parse("P28").unwrap();
        let name =
            |v: &[usize]| -> Vec<&str> { v.iter().map(|&t| common::TERMS[t].name).collect() };
        let all = parse_candidates(None, &base).unwrap();
        let no_size = parse_candidates(Some("!size_*"), &base).unwrap();
        assert!(name(&no_size).iter().all(|n| !n.starts_with("size_")));
        let sizes = name(&all).iter().filter(|n| n.starts_with("size_")).count();
        assert!(sizes >= 9 && no_size.len() == all.len() - sizes);
        let v = parse_candidates(Some("kaq_*, !kaq_x_xy ,d_x"), &base).unwrap();
        assert!(name(&v).contains(&"d_x") && !name(&v).contains(&"kaq_x_xy"));
        assert!(name(&v).contains(&"kaq_y_xy"));
        let e = parse_candidates(Some("!nope_*"), &base).unwrap_err();
        assert!(e.contains("unknown term `nope_*`"), "{e}");
        let e = parse_candidates(Some("d_x,!d_*"), &base).unwrap_err();
        assert!(
            e.contains("`d_x` is both named and withheld (`!d_*`)"),
            "{e}"
        );
        let e = parse_candidates(Some("size_x,!size_x"), &base).unwrap_err();
        assert!(
            e.contains("`size_x` is both named and withheld (`!size_x`)"),
            "{e}"
        );
        // a family of which one member is withheld is no contradiction
        assert!(parse_candidates(Some("size_*,!size_x"), &base).is_ok());
    }

    #[test]
    fn a_candidate_list_that_does_nothing_it_says_is_refused() {
        let base = Model::parse("P28").unwrap();
        let err = |spec: &str| parse_candidates(Some(spec), &base).unwrap_err();
        let e = err("!!d_x");
        assert!(e.contains("doubled `!`") && e.contains("(`!d_x`)"), "{e}");
        // a withholding of a term that was never named takes nothing back
        let e = err("d_x,!kas_x");
        assert!(
            e.contains("`!kas_x` withholds nothing") && e.contains("not among"),
            "{e}"
        );
        // a baseline term is no candidate to withhold, nor to name alone
        let e = err("!d_*,!d_x");
        assert!(e.contains("already withheld by `!d_*`"), "{e}");
        let e = err("!nabla_x");
        assert!(e.contains("in the baseline model P28"), "{e}");
        let e = err("nabla_x");
        assert!(
            e.contains("already in the baseline model P28") && e.contains("nothing is left"),
            "{e}"
        );
        // one baseline term beside a candidate is skipped (the CLI notes it)
        assert!(parse_candidates(Some("nabla_x,d_x"), &base).is_ok());
    }

    #[test]
    fn the_users_withholdings_are_kept_as_families_where_whole() {
        let base = Model::parse("P28").unwrap();
        let given = parse_candidates(Some("!d_*,!kaq_x_xy"), &base).unwrap();
        assert_eq!(withheld_by_the_user(&base, &given), ["!d_*", "!kaq_x_xy"]);
        // a prefix across families is said (d_ and dt_), one within a family is not
        let notes = prefix_reach(Some("!d*,kaq_*"));
        assert_eq!(notes.len(), 1, "{notes:?}");
        assert!(
            notes[0].contains("dt_gnss") && notes[0].contains("`d_*`"),
            "{notes:?}"
        );
        let all = parse_candidates(None, &base).unwrap();
        assert!(withheld_by_the_user(&base, &all).is_empty());
    }

    #[test]
    fn structure_left_is_time_correlation_or_a_biased_segment() {
        let channel = |p: Option<f64>, bias: f64, count: usize| ChannelStats {
            channel: "vel_n".into(),
            count,
            nis_mean: 1.0,
            nis_band: [0.9, 1.1],
            fraction_outside_95: 0.05,
            ljung_box_q: None,
            whiteness_p: p,
            segments: vec![SegmentStats {
                t0: 10.0,
                t1: 20.0,
                level_g: 0.0,
                count,
                nis_mean: 1.0,
                bias_sigma: bias,
            }],
        };
        let pass = |channels: Vec<ChannelStats>| PassStats {
            model: "P28".into(),
            t_start: 0.0,
            loglik: 0.0,
            nis_mean: 1.0,
            whiteness_p: 1.0,
            channels,
            model_error_rms_arcsec: None,
            truth_check: vec![],
        };
        // white and unbiased: nothing left
        assert!(pass(vec![channel(Some(0.5), 0.01, 100)])
            .structure()
            .is_empty());
        // a mean of 0.3σ over 100 innovations is a 3σ bias: not yet
        assert!(pass(vec![channel(Some(0.5), 0.3, 100)])
            .structure()
            .is_empty());
        // 0.5σ over 100 is 5σ: biased, with its segment
        let s = pass(vec![channel(Some(0.5), -0.5, 100)]).structure();
        assert!(s[0].biased && !s[0].correlated && s[0].segment == Some([10.0, 20.0]));
        assert!((s[0].segment_z + 5.0).abs() < 1e-12);
        // p 0.004 on one of three channels is 0.012 after Bonferroni: white; 0.003 is not
        let three = |p| {
            pass(vec![
                channel(Some(p), 0.0, 100),
                channel(None, 0.0, 100),
                channel(None, 0.0, 100),
            ])
        };
        assert!(three(0.004).structure().is_empty());
        assert!(three(0.003).structure()[0].correlated);
        // innovations far below their stated σ are the filter's smooth error: not structure
        let mut quiet = channel(Some(1e-300), 0.0, 100);
        quiet.nis_mean = 0.003;
        assert!(pass(vec![quiet]).structure().is_empty());
    }
}
