//! Noise levels as findings: the gyro and accelerometer white noise and the aiding's stated
//! 1-σ (one scale per measurement), each estimated by maximum likelihood of the innovations and
//! tested against its stated value with a likelihood-ratio test (Holm over the levels, and the
//! BIC).
//!
//! Each level is a scale s of what the filter was given (the `--noise`/`--grade` density, the σ a
//! fix states). The log-likelihood is searched in log₂ s around the current value: passes at
//! half and twice, then successive parabolic interpolation (or steps of 4× while it keeps
//! rising), within 1/16 … 64 of the start. Two sweeps over the levels in turn (white noise
//! first, then the aiding σ), each given all the others; a level's 2Δℓ is then the drop when it
//! alone returns to its stated value, the others kept at their fits. The 95 % interval is
//! where the last parabola falls by χ²₁(0.95)/2. [`stage`] runs it after the terms and turns
//! the significant levels into findings.
//!
//! A finding is a claim about the sensor or the fixes, judged by rules beside the test: it holds
//! across the data (the splits), a white noise does not exceed what the raw increments show
//! (`raw_noise`; a level they rule out no longer shifts the others: [`Claims`]), and a fix's σ
//! is borne out by those fixes' own innovations ([`not_borne_out_by_own_fixes`]).
//!
//! In open loop these passes are replays of one recorded pass (`estimate::replay`): the
//! navigation, A(t), H and z do not depend on the noise there, so each costs well under 1 % of a
//! pass; in closed loop they are full passes.

use super::{
    baseline_excess, run_pass, run_pass_watched, sig3, Context, ExplainData, ExplainOptions,
    Finding, Pass, PassStats, Rounds, G0,
};
use crate::estimate::filter::{FilterConfig, Innovation};
use crate::estimate::replay::{Recorder, Tape};
use crate::estimate::stats;
use crate::model::generated::common;
use crate::model::Model;

/// Passes of one model under rescaled noise levels: replayed from a tape of one open-loop pass
/// (`estimate::replay`) where one could be recorded, else run in full.
struct Passes<'a, 'd> {
    model: &'a Model,
    data: &'a ExplainData<'d>,
    tape: Option<Tape>,
}

impl<'a, 'd> Passes<'a, 'd> {
    /// Runs the pass of `model` with `cfg`, recording a tape whose groups are the states each
    /// of `levels` scales; the tape is kept only when its replay of `cfg` gives the pass's
    /// innovations back (the same updates, log-likelihood within 1e-6 relative).
    fn record(
        model: &'a Model,
        data: &'a ExplainData<'d>,
        cfg: &FilterConfig,
        levels: &[Level],
        progress: &mut dyn FnMut(f64),
    ) -> anyhow::Result<Passes<'a, 'd>> {
        let groups: Vec<Vec<usize>> = levels
            .iter()
            .filter_map(|level| {
                let mut c = cfg.clone();
                level.apply(model, &mut c, 2.0);
                let g: Vec<usize> = (0..cfg.q.len()).filter(|&i| c.q[i] != cfg.q[i]).collect();
                (!g.is_empty()).then_some(g)
            })
            .collect();
        // (a state in two levels' groups cannot be scaled by either alone)
        let disjoint = groups.iter().enumerate().all(|(a, ga)| {
            groups[a + 1..]
                .iter()
                .all(|gb| ga.iter().all(|i| !gb.contains(i)))
        });
        let Some(mut rec) = Recorder::new(model.n(), cfg, &groups).filter(|_| disjoint) else {
            return Ok(Passes {
                model,
                data,
                tape: None,
            });
        };
        let pass = run_pass_watched(model, &[], data, cfg, progress, &mut rec)?;
        let tape = rec.finish().filter(|t| {
            t.innovations(cfg).is_some_and(|inn| {
                let l = super::diagnostics::loglik_sum(&inn);
                let l0 = pass.stats.loglik;
                inn.len() == pass.run.innovations.len()
                    && (l - l0).abs() <= 1e-6 * l0.abs().max(1.0)
            })
        });
        Ok(Passes { model, data, tape })
    }

    /// The applied innovations of the pass with configuration `cfg`.
    fn innovations(&self, cfg: &FilterConfig) -> anyhow::Result<Vec<Innovation>> {
        if let Some(inn) = self.tape.as_ref().and_then(|t| t.innovations(cfg)) {
            return Ok(inn);
        }
        Ok(run_pass(self.model, &[], self.data, cfg, &mut |_| {})?
            .run
            .innovations)
    }

    /// The innovation log-likelihood of the pass with configuration `cfg`.
    fn loglik(&self, cfg: &FilterConfig) -> anyhow::Result<f64> {
        Ok(super::diagnostics::loglik_sum(&self.innovations(cfg)?))
    }
}

/// A noise level explain can scale.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Level {
    /// Gyro white noise (angle random walk).
    GyroArw,
    /// Accelerometer white noise (velocity random walk).
    AccelVrw,
    /// Gyro bias random walk (bias instability), offered when one is stated.
    GyroBiasRw,
    /// Accelerometer bias random walk, offered when one is stated.
    AccelBiasRw,
    /// The aiding's stated 1-σ of one measurement.
    Sigma(&'static str),
}

impl Level {
    /// The name in findings: `gyro_arw`, `accel_vrw`, `sigma_<measurement>`.
    pub(super) fn name(&self) -> String {
        match self {
            Level::GyroArw => "gyro_arw".into(),
            Level::AccelVrw => "accel_vrw".into(),
            Level::GyroBiasRw => "gyro_bias_rw".into(),
            Level::AccelBiasRw => "accel_bias_rw".into(),
            Level::Sigma(m) => format!("sigma_{m}"),
        }
    }

    /// Applies scale `s` to `cfg` (on top of what it holds).
    pub(super) fn apply(&self, model: &Model, cfg: &mut FilterConfig, s: f64) {
        match self {
            Level::GyroArw => cfg.scale_sensor_noise(model, s, 1.0),
            Level::AccelVrw => cfg.scale_sensor_noise(model, 1.0, s),
            Level::GyroBiasRw => cfg.scale_bias_random_walk(model, s, 1.0),
            Level::AccelBiasRw => cfg.scale_bias_random_walk(model, 1.0, s),
            Level::Sigma(m) => match cfg.sigma_scale.iter_mut().find(|x| x.0 == *m) {
                Some(x) => x.1 *= s,
                None => cfg.sigma_scale.push((m, s)),
            },
        }
    }
}

/// One level's fit.
#[derive(Debug, Clone)]
pub(super) struct LevelFit {
    /// The level.
    pub(super) level: Level,
    /// Maximum-likelihood scale of the stated value.
    pub(super) scale: f64,
    /// Approximate 95 % interval of the scale.
    pub(super) interval: [f64; 2],
    /// −1 when the last search for the level ended at its lower bound with the likelihood still
    /// rising towards it (the scale is at most `scale`), +1 at its upper bound (at least), 0
    /// when the maximum was bracketed.
    pub(super) at_bound: i8,
    /// 2Δℓ of the fitted scale over the stated value, the other levels at their fitted scales.
    pub(super) two_delta_loglik: f64,
    /// Holm-adjusted p-value over the levels.
    pub(super) p_holm: f64,
    /// True when significant (Holm at α and 2Δℓ above the BIC penalty ln N).
    pub(super) significant: bool,
}

/// ML scales of every level on `model` with configuration `cfg`, whose pass has log-likelihood
/// and scalar innovation count `(loglik0, innovations)`; returns the fits and the configuration
/// with the significant scales applied.
fn fit(
    passes: &Passes,
    cfg: &FilterConfig,
    levels: &[Level],
    (loglik0, innovations): (f64, usize),
    opts: &ExplainOptions,
    progress: &mut dyn FnMut(f64),
) -> anyhow::Result<(Vec<LevelFit>, FilterConfig)> {
    let model = passes.model;
    let mut cur = cfg.clone();
    let mut l_cur = loglik0;
    let mut fits = Vec::new();
    let passes_per_level = MAX_EVALS as f64;
    let total = (2.0 * passes_per_level + 1.0) * levels.len() as f64;
    let mut done = 0.0;
    // two sweeps: the second refits each level given all the others
    let order: Vec<Level> = levels.iter().chain(levels.iter()).copied().collect();
    let mut scales = vec![1.0; levels.len()];
    let mut gains = vec![0.0; levels.len()];
    let mut curvs = vec![0.0; levels.len()];
    let mut bounds = vec![0i8; levels.len()];
    for (step, &level) in order.iter().enumerate() {
        let li = step % levels.len();
        let mut eval = |u: f64| -> anyhow::Result<f64> {
            let mut c = cur.clone();
            level.apply(model, &mut c, 2f64.powf(u));
            let l = passes.loglik(&c)?;
            done += 1.0;
            progress(done / total);
            Ok(l)
        };
        let (u, l, curv, edge) = search(&mut eval, l_cur)?;
        if l > l_cur {
            level.apply(model, &mut cur, 2f64.powf(u));
            scales[li] *= 2f64.powf(u);
            gains[li] += 2.0 * (l - l_cur);
            l_cur = l;
        }
        curvs[li] = curv;
        bounds[li] = edge;
    }
    // each level's evidence is the drop in ℓ when it alone goes back to its stated value, the
    // others kept at their fitted scales: a level that in the first sweep took up another's
    // misfit keeps no gain the second sweep gave back
    for (li, &level) in levels.iter().enumerate() {
        if scales[li] == 1.0 {
            gains[li] = 0.0;
            continue;
        }
        let mut c = cur.clone();
        level.apply(model, &mut c, 1.0 / scales[li]);
        let l = passes.loglik(&c)?;
        done += 1.0;
        progress(done / total);
        gains[li] = (2.0 * (l_cur - l)).max(0.0);
    }
    for (li, &level) in levels.iter().enumerate() {
        fits.push(LevelFit {
            level,
            scale: scales[li],
            interval: interval(scales[li], curvs[li]),
            at_bound: bounds[li],
            two_delta_loglik: gains[li],
            p_holm: stats::chi2_sf(gains[li], 1.0),
            significant: false,
        });
    }
    // Holm over the levels, and the BIC: a level is named only when the data need it
    let p: Vec<f64> = fits.iter().map(|f| f.p_holm).collect();
    let adj = stats::holm(&p);
    let bic = (innovations.max(2) as f64).ln();
    for (f, a) in fits.iter_mut().zip(adj) {
        f.p_holm = a;
        f.significant = a <= opts.alpha && f.two_delta_loglik > bic;
    }
    // refitted, a level's gain is tested again (it was measured beside the unnamed levels'
    // fits): one no longer significant is no claim, and the others are refitted without it
    let mut named: Vec<bool> = fits.iter().map(|f| f.significant).collect();
    let mut out = with_levels(model, cfg, &fits, &named);
    refit_and_retest(
        passes,
        cfg,
        &mut fits,
        &mut named,
        &mut out,
        (opts.alpha, bic),
        1,
    )?;
    Ok((fits, out))
}

/// `cfg` with the `named` levels of `fits` at their scales.
fn with_levels(
    model: &Model,
    cfg: &FilterConfig,
    fits: &[LevelFit],
    named: &[bool],
) -> FilterConfig {
    let mut out = cfg.clone();
    for (f, _) in fits.iter().zip(named).filter(|x| *x.1) {
        f.level.apply(model, &mut out, f.scale);
    }
    out
}

/// Refits the `named` levels of `fits` on `out` (= `cfg` with them; [`settle`], at most
/// `sweeps` times) and, when that moved them, tests them again ([`retest`]); while one is
/// dropped, the rest are refitted from `cfg` without it and tested again.
fn refit_and_retest(
    passes: &Passes,
    cfg: &FilterConfig,
    fits: &mut [LevelFit],
    named: &mut [bool],
    out: &mut FilterConfig,
    tests: (f64, f64),
    sweeps: usize,
) -> anyhow::Result<()> {
    let mut moved = settle(passes, fits, named, out, sweeps)?;
    while moved && retest(passes, fits, named, out, tests)? {
        *out = with_levels(passes.model, cfg, fits, named);
        moved = settle(passes, fits, named, out, sweeps)?;
    }
    Ok(())
}

/// Refits each `named` level once more on `out`, where the levels not named are back at their
/// stated values: a level the data do not need must not shift the value of one they do.
/// Updates the fits' scales and intervals and `out`; returns whether it refitted (some level
/// not named had moved from its stated value).
fn refit_named(
    passes: &Passes,
    fits: &mut [LevelFit],
    named: &[bool],
    out: &mut FilterConfig,
) -> anyhow::Result<bool> {
    let model = passes.model;
    let moved = fits.iter().zip(named).any(|(f, &n)| !n && f.scale != 1.0);
    if !moved || !named.contains(&true) {
        return Ok(false);
    }
    let mut l_out = passes.loglik(out)?;
    for (f, _) in fits.iter_mut().zip(named).filter(|x| *x.1) {
        let level = f.level;
        let base = out.clone();
        let mut eval = |u: f64| -> anyhow::Result<f64> {
            let mut c = base.clone();
            level.apply(model, &mut c, 2f64.powf(u));
            passes.loglik(&c)
        };
        let (u, l, curv, edge) = search(&mut eval, l_out)?;
        if l > l_out {
            level.apply(model, out, 2f64.powf(u));
            f.scale *= 2f64.powf(u);
            l_out = l;
        }
        f.at_bound = edge;
        if curv < 0.0 {
            f.interval = interval(f.scale, curv);
        }
    }
    Ok(true)
}

/// The 95 % interval of a scale fitted at `scale` where ℓ(log₂ s) has curvature `curv` (ℓ ≈
/// curv · u² + …): where the parabola falls by χ²₁(0.95)/2; unbounded without curvature.
fn interval(scale: f64, curv: f64) -> [f64; 2] {
    let half = if curv < 0.0 {
        (stats::chi2_isf(0.05, 1.0) / (-2.0 * curv)).sqrt()
    } else {
        f64::INFINITY
    };
    let u = scale.log2();
    [2f64.powf(u - half), 2f64.powf(u + half)]
}

/// Maximises ℓ(u) over u = log₂ s from u = 0 (where ℓ = `l0`) in at most [`MAX_EVALS`]
/// passes: ±1, then successive parabolic interpolation through the best point and its nearest
/// neighbours on either side (a step of 2 beyond the best point while it lies at an end),
/// within [−4, 6]. Returns (u, ℓ(u), the curvature a of the last parabola, ℓ ≈ a u² + …, and
/// −1 or +1 when the best point is the lowest or highest tried: the likelihood still rises
/// beyond it, so u is a bound of the maximum, not the maximum; else 0).
fn search(
    eval: &mut dyn FnMut(f64) -> anyhow::Result<f64>,
    l0: f64,
) -> anyhow::Result<(f64, f64, f64, i8)> {
    const LO: f64 = -4.0;
    const HI: f64 = 6.0;
    let mut pts: Vec<(f64, f64)> = vec![(0.0, l0), (-1.0, eval(-1.0)?), (1.0, eval(1.0)?)];
    let mut curv = 0.5 * (pts[1].1 + pts[2].1 - 2.0 * l0);
    for _ in 2..MAX_EVALS {
        pts.sort_by(|x, y| x.0.total_cmp(&y.0));
        let k = (0..pts.len())
            .max_by(|&i, &j| pts[i].1.total_cmp(&pts[j].1))
            .expect("points");
        let next = if k == 0 || k + 1 == pts.len() {
            // the best point is at an end: step on
            let dir: f64 = if k == 0 { -1.0 } else { 1.0 };
            (pts[k].0 + 2.0 * dir).clamp(LO, HI)
        } else {
            let ((x0, y0), (x1, y1), (x2, y2)) = (pts[k - 1], pts[k], pts[k + 1]);
            let a = ((y2 - y1) / (x2 - x1) - (y1 - y0) / (x1 - x0)) / (x2 - x0);
            curv = a;
            if a >= 0.0 {
                break;
            }
            let b = (y1 - y0) / (x1 - x0) - a * (x0 + x1);
            (-b / (2.0 * a)).clamp(x0, x2)
        };
        if pts.iter().any(|p| (p.0 - next).abs() < 0.02) {
            break;
        }
        pts.push((next, eval(next)?));
    }
    pts.sort_by(|x, y| x.0.total_cmp(&y.0));
    let k = (0..pts.len())
        .max_by(|&i, &j| pts[i].1.total_cmp(&pts[j].1))
        .expect("points");
    let edge = if k == 0 {
        -1
    } else if k + 1 == pts.len() {
        1
    } else {
        let ((x0, y0), (x1, y1), (x2, y2)) = (pts[k - 1], pts[k], pts[k + 1]);
        curv = ((y2 - y1) / (x2 - x1) - (y1 - y0) / (x1 - x0)) / (x2 - x0);
        0
    };
    Ok((pts[k].0, pts[k].1, curv, edge))
}

/// Most sweeps of the claimed levels' refits in [`Claims::new`].
const SETTLE_SWEEPS: usize = 4;

/// Most filter passes per noise level (the start point's pass not counted).
const MAX_EVALS: usize = 5;

/// The extended pass with the significant noise levels and the scales it applies to them.
pub(super) type NoisePass = (Pass, Vec<(Level, f64)>);

/// Noise levels as findings (after the terms): when the extended model's mean NIS lies outside
/// its 95 % band, the ML scale of each noise level is tested against 1; the significant ones
/// become findings of kind `noise` and a last pass with them is the extended one, returned with
/// the scales it applies.
pub(super) fn stage(
    ctx: &Context,
    r: &Rounds,
    base: &PassStats,
    stand_ins: &[usize],
    progress: &mut dyn FnMut(usize, f64),
) -> anyhow::Result<(Vec<Finding>, Option<NoisePass>)> {
    let st = &r.pass.stats;
    let n: usize = st.channels.iter().map(|c| c.count).sum();
    let band = stats::mean_chi2_band(1.0, n.max(1), 1.959_964);
    if !ctx.opts.noise_levels || (st.nis_mean >= band[0] && st.nis_mean <= band[1]) {
        return Ok((Vec::new(), None));
    }
    let mut levels = vec![Level::GyroArw, Level::AccelVrw];
    let cfg = ctx.extended_config(&r.model, &r.widened)?;
    // a bias random walk is a level only where one is stated (a scale of zero is zero)
    let (gyro_rw, accel_rw) = cfg.bias_random_walk(&r.model);
    if gyro_rw > 0.0 {
        levels.push(Level::GyroBiasRw);
    }
    if accel_rw > 0.0 {
        levels.push(Level::AccelBiasRw);
    }
    for i in &r.pass.run.innovations {
        if !levels.contains(&Level::Sigma(i.meas)) {
            levels.push(Level::Sigma(i.meas));
        }
    }
    let round = r.rounds + 1;
    let passes = Passes::record(&r.model, ctx.data, &cfg, &levels, &mut |f| {
        progress(round, 0.5 * f)
    })?;
    let (fits, cfg_noise) = fit(
        &passes,
        &cfg,
        &levels,
        (st.loglik, r.pass.run.innovations.len()),
        ctx.opts,
        &mut |f| progress(round, 0.5 + 0.5 * f),
    )?;
    if !fits.iter().any(|f| f.significant) {
        return Ok((Vec::new(), None));
    }
    let stated = Stated {
        white: cfg.sensor_noise(&r.model),
        bias_rw: cfg.bias_random_walk(&r.model),
    };
    let bic = (r.pass.run.innovations.len().max(2) as f64).ln();
    let mut raw = super::raw_noise::Reading::default();
    let motion = Motion::read(ctx.data, &mut raw)?;
    let raw = raw.finish();
    let claims = Claims::new(
        &passes,
        &cfg,
        &fits,
        &stated,
        raw.as_ref(),
        (ctx.opts.alpha, bic),
    )?;
    // the extended pass holds every level at its joint fit, the ones that stand in too (as it
    // holds the terms that do); the findings state the claims
    let applied: Vec<(Level, f64)> = fits
        .iter()
        .filter(|f| f.significant)
        .map(|f| (f.level, f.scale))
        .collect();
    let pass = run_pass(&r.model, &[], ctx.data, &cfg_noise, &mut |f| {
        progress(round + 1, f)
    })?;
    let excess = baseline_excess(base);
    let removed = st.nis_mean - pass.stats.nis_mean;
    // (the extended pass's reduction is shared by the joint fits' 2Δℓ)
    let total: f64 = fits
        .iter()
        .filter(|f| f.significant)
        .map(|f| f.two_delta_loglik)
        .sum();
    let judge = Judge {
        passes: &passes,
        motion: &motion,
        stated: &stated,
        raw: raw.as_ref(),
        bic,
    };
    let mut findings = Vec::new();
    for (k, f) in claims.fits.iter().enumerate().filter(|x| x.1.significant) {
        let w = fits[k].two_delta_loglik / total.max(f64::MIN_POSITIVE);
        let mut nf = noise_finding(
            f,
            &stated,
            excess.map(|e| removed * w / e),
            f.two_delta_loglik,
        );
        // a level the raw increments rule out is judged where it was fitted (beside the
        // others' joint fits), the rest where the claims were refitted without it
        let at = match (&claims.claimed, claims.contradicted[k]) {
            (Some((cfg, inn)), false) => (cfg, inn.as_slice()),
            _ => (&cfg_noise, pass.run.innovations.as_slice()),
        };
        judge.level(f, at, &mut nf)?;
        findings.push(nf);
    }
    taken_up_by_stand_ins(ctx, r, &claims.fits, stand_ins, &mut findings)?;
    Ok((findings, Some((pass, applied))))
}

/// The fits the findings state. A significant white-noise level the raw increments rule out
/// (see [`raw_reading`]) is still reported as fitted, but the other significant levels are
/// refitted with it back at its stated value: a level the data rule out must not shift the
/// value of one they allow (a velocity random walk fitted several times the sensor's takes up
/// part of the velocity fixes' own noise).
struct Claims {
    /// Every level's fit; the significant ones not ruled out refitted as above.
    fits: Vec<LevelFit>,
    /// Per fit: a significant level the raw increments rule out.
    contradicted: Vec<bool>,
    /// With a level ruled out: the configuration with the claimed levels at their scales (those
    /// ruled out at stated) and its applied innovations; None when none is (the claims are the
    /// joint fits, which the extended pass holds).
    claimed: Option<(FilterConfig, Vec<Innovation>)>,
}

impl Claims {
    /// The claims from the joint `fits` over the stated configuration `cfg`, given the raw
    /// reading `raw`; `(alpha, bic)` are the tests' level and the BIC penalty ln N. A claimed
    /// level is tested again after the refits (its 2Δℓ the drop when it alone returns to its
    /// stated value): one no longer significant is no claim, and the others are refitted
    /// without it.
    fn new(
        passes: &Passes,
        cfg: &FilterConfig,
        fits: &[LevelFit],
        stated: &Stated,
        raw: Option<&super::raw_noise::RawNoise>,
        (alpha, bic): (f64, f64),
    ) -> anyhow::Result<Claims> {
        let contradicted: Vec<bool> = fits
            .iter()
            .map(|f| f.significant && matches!(raw_reading(f, stated, raw), Some(Err(_))))
            .collect();
        let mut fits = fits.to_vec();
        if !contradicted.contains(&true) {
            return Ok(Claims {
                fits,
                contradicted,
                claimed: None,
            });
        }
        let mut named: Vec<bool> = fits
            .iter()
            .zip(&contradicted)
            .map(|(f, &c)| f.significant && !c)
            .collect();
        let mut out = with_levels(passes.model, cfg, &fits, &named);
        refit_and_retest(
            passes,
            cfg,
            &mut fits,
            &mut named,
            &mut out,
            (alpha, bic),
            SETTLE_SWEEPS,
        )?;
        let innovations = passes.innovations(&out)?;
        Ok(Claims {
            fits,
            contradicted,
            claimed: Some((out, innovations)),
        })
    }
}

/// Refits the `named` levels of `fits` on `out` in turn until their scales settle (one level
/// moved shifts the others' optimum), at most `sweeps` times; returns whether the first sweep
/// refitted ([`refit_named`]: some level not named had moved from its stated value).
fn settle(
    passes: &Passes,
    fits: &mut [LevelFit],
    named: &[bool],
    out: &mut FilterConfig,
    sweeps: usize,
) -> anyhow::Result<bool> {
    let mut refitted = false;
    for sweep in 0..sweeps {
        let before: Vec<f64> = fits.iter().map(|f| f.scale).collect();
        let ran = refit_named(passes, fits, named, out)?;
        refitted |= sweep == 0 && ran;
        let moved = fits
            .iter()
            .zip(&before)
            .any(|(f, b)| (f.scale / b).log2().abs() > 0.01);
        if !moved {
            break;
        }
    }
    Ok(refitted)
}

/// Tests the `named` levels of `fits` again on `out` (which holds them): each one's 2Δℓ is the
/// drop when it alone returns to its stated value; Holm over all levels (the others with their
/// first 2Δℓ) at `alpha` and above `bic`. A level no longer significant is un-named and marked
/// not significant; returns whether one was.
fn retest(
    passes: &Passes,
    fits: &mut [LevelFit],
    named: &mut [bool],
    out: &FilterConfig,
    (alpha, bic): (f64, f64),
) -> anyhow::Result<bool> {
    let l_out = passes.loglik(out)?;
    for (f, _) in fits.iter_mut().zip(named.iter()).filter(|x| *x.1) {
        let mut c = out.clone();
        f.level.apply(passes.model, &mut c, 1.0 / f.scale);
        f.two_delta_loglik = (2.0 * (l_out - passes.loglik(&c)?)).max(0.0);
    }
    let p: Vec<f64> = fits
        .iter()
        .map(|f| stats::chi2_sf(f.two_delta_loglik, 1.0))
        .collect();
    let mut dropped = false;
    for ((f, a), n) in fits.iter_mut().zip(stats::holm(&p)).zip(named.iter_mut()) {
        if *n {
            f.p_holm = a;
            if !(a <= alpha && f.two_delta_loglik > bic) {
                (f.significant, *n, dropped) = (false, false, true);
            }
        }
    }
    Ok(dropped)
}

/// What judges a fitted level as a claim about the sensor or the fixes.
struct Judge<'a, 'p, 'd> {
    passes: &'a Passes<'p, 'd>,
    motion: &'a Motion,
    stated: &'a Stated,
    raw: Option<&'a super::raw_noise::RawNoise>,
    /// The BIC penalty ln N.
    bic: f64,
}

impl Judge<'_, '_, '_> {
    /// Judges level `f` fitted at configuration and innovations `at`, adding to its finding `nf`
    /// the consistency splits and the words (and a stand-in reason) of every rule it fails.
    fn level(
        &self,
        f: &LevelFit,
        (cfg, inn): (&FilterConfig, &[Innovation]),
        nf: &mut Finding,
    ) -> anyhow::Result<()> {
        // a noise level is a constant of the sensor or the receiver: fitted on parts of the data
        // apart (while the body rotates or turns and otherwise; each half), it gives one scale
        let groups = self.motion.groups(inn);
        nf.consistency = split_scales(self.passes, cfg, f, inn, &groups)?;
        let why: Vec<String> = nf
            .consistency
            .iter()
            .filter_map(|c| c.disagreement("× stated"))
            .collect();
        if !why.is_empty() {
            let why = why.join("; ");
            // every group's scale on the same side of 1.5×: the stated value is off throughout,
            // by an amount that changes
            let failing = nf.consistency.iter().filter(|c| !c.holds);
            let (lo, hi) = failing
                .flat_map(|c| c.groups.iter().map(|g| g.estimate))
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
                    (a.min(x), b.max(x))
                });
            let tail = if lo > 1.5 {
                format!("the stated value is too small in every group ({}× to {}×) but no single level fits: the noise changes with the motion, or something the candidates do not describe adds to it; a filter that must be consistent everywhere needs the larger", sig3(lo), sig3(hi))
            } else if hi < 1.0 / 1.5 {
                format!("the stated value is too large in every group ({}× to {}×) but no single level fits: the noise changes with the motion, or something the candidates do not describe takes part of it", sig3(lo), sig3(hi))
            } else {
                "a noise level of the sensor or receiver is one constant; a missing term, an aiding error or noise that changes with the motion fits this way; do not read it as the stated noise being wrong".to_string()
            };
            nf.words.push_str(&format!(
                ". It is not one level across the data ({why}): {tail}"
            ));
            nf.stand_in = Some(why);
        }
        if let Some(why) = implausible_scale(f) {
            nf.words.push_str(&format!(". {why}"));
            nf.stand_in.get_or_insert(why);
        }
        if let Some(hint) = unit_slip(f) {
            nf.words.push_str(&format!(". {hint}"));
        }
        if let Some(why) = holds_the_stated_value(f) {
            nf.words.push_str(&format!(
                ". It is no finding that the stated value is wrong: {why}"
            ));
            nf.stand_in.get_or_insert(why);
        }
        if let Some(why) = not_borne_out_by_own_fixes(self.passes, cfg, f, inn, self.bic)? {
            nf.words.push_str(&format!(
                ". It is no finding about these fixes' σ: {why}; it takes up misfit of the other fixes that the model does not describe (a term outside the candidates, an aiding error such as a lever arm or a time offset, or correlated receiver errors), so do not read it as the stated σ being wrong"
            ));
            nf.stand_in.get_or_insert(why);
        }
        match raw_reading(f, self.stated, self.raw) {
            Some(Err(why)) => {
                nf.words.push_str(&format!(
                    ". It is not a finding about the sensor's noise: {why}; it stands in for something the model lacks: an effect that acts with the motion (vibration, a sensor term outside the candidates, a g-sensitivity, a scale error) or a correlated noise such as a bias instability"
                ));
                nf.stand_in.get_or_insert(why);
            }
            Some(Ok(reading)) => nf.words.push_str(&format!("; {reading}")),
            None => {}
        }
        Ok(())
    }
}

/// A noise finding that is significant only while the terms the rules called stand-ins
/// (`stand_ins`) are left out of the model is no claim about the noise either: with them fitted
/// beside it, each significant level of `fits` (not yet a stand-in in `findings`) is fitted
/// again from its stated value on the model with them, the others kept at their fits;
/// a level whose 2Δℓ then falls to max(ln N, χ²₁(α)) or below is marked a stand-in. A term the
/// prior rejects (a value many prior σ out) may still be a real effect of this unit: the noise
/// scale then only stands in for it.
fn taken_up_by_stand_ins(
    ctx: &Context,
    r: &Rounds,
    fits: &[LevelFit],
    stand_ins: &[usize],
    findings: &mut [Finding],
) -> anyhow::Result<()> {
    let open: Vec<(usize, &LevelFit)> = fits
        .iter()
        .filter(|f| f.significant)
        .enumerate()
        .filter(|(k, _)| findings[*k].stand_in.is_none())
        .collect();
    if stand_ins.is_empty() || open.is_empty() {
        return Ok(());
    }
    let model = super::model_with(&r.model.name, stand_ins.iter().copied())?;
    let mut cfg_plus = ctx.extended_config(&model, &r.widened)?;
    // the levels claimed so far beside them (one that stands in is back at its stated value)
    for (k, f) in fits.iter().filter(|f| f.significant).enumerate() {
        if findings[k].stand_in.is_none() {
            f.level.apply(&model, &mut cfg_plus, f.scale);
        }
    }
    let levels: Vec<Level> = open.iter().map(|(_, f)| f.level).collect();
    let passes = Passes::record(&model, ctx.data, &cfg_plus, &levels, &mut |_| {})?;
    let n = r.pass.run.innovations.len().max(2) as f64;
    let threshold = n.ln().max(stats::chi2_isf(ctx.opts.alpha, 1.0));
    let names: Vec<&str> = stand_ins.iter().map(|&t| common::TERMS[t].name).collect();
    for (k, f) in open {
        let mut stated = cfg_plus.clone();
        f.level.apply(&model, &mut stated, 1.0 / f.scale);
        let l1 = passes.loglik(&stated)?;
        let mut eval = |u: f64| -> anyhow::Result<f64> {
            let mut c = stated.clone();
            f.level.apply(&model, &mut c, 2f64.powf(u));
            passes.loglik(&c)
        };
        let (_, l, _, _) = search(&mut eval, l1)?;
        let gain = (2.0 * (l - l1)).max(0.0);
        if gain <= threshold {
            let why = format!(
                "fitted beside {} (called stand-ins above) it is no longer significant (2Δℓ {} → {}, against {})",
                names.join(", "),
                sig3(f.two_delta_loglik),
                sig3(gain),
                sig3(threshold)
            );
            let nf = &mut findings[k];
            nf.words.push_str(&format!(
                ". It is not a finding of its own: {why}; the misfit it takes up may be an effect of this unit the priors or the candidates do not admit, so do not read it as the stated noise being wrong"
            ));
            nf.stand_in = Some(why);
        }
    }
    Ok(())
}

/// Why aiding level `f` (a fix's stated σ, fitted on `cfg`, whose innovations are `inn`) is no
/// claim about those fixes, in words: from the stated σ to the fit (the others kept at their
/// fits), the log-likelihood of the fixes it scales rises by `threshold` (the BIC's ln N) or
/// less, and any gain comes from the other measurements' innovations. None when they bear it
/// out, and for the sensors' levels.
///
/// A fix's σ enters its own innovations' variance directly and the others' only through the
/// filter's covariance, so a mis-stated σ shows first in its own innovations; a scale the
/// others' innovations want instead takes up their misfit (a wider σ lets the filter's position
/// or velocity drift further between them). Under a correctly stated σ the own gain at any
/// scale is at most the largest one, χ²₁-distributed: such a stand-in goes unlabelled only when
/// that exceeds the threshold.
fn not_borne_out_by_own_fixes(
    passes: &Passes,
    cfg: &FilterConfig,
    f: &LevelFit,
    inn: &[Innovation],
    threshold: f64,
) -> anyhow::Result<Option<String>> {
    let Level::Sigma(meas) = f.level else {
        return Ok(None);
    };
    let mut stated = cfg.clone();
    f.level.apply(passes.model, &mut stated, 1.0 / f.scale);
    let at_stated = passes.innovations(&stated)?;
    if at_stated.len() != inn.len() {
        anyhow::bail!("the noise passes differ in their updates");
    }
    // 2Δℓ per measurement, in the order the measurements first appear
    let mut gains: Vec<(&'static str, f64)> = Vec::new();
    for (a, b) in inn.iter().zip(&at_stated) {
        let g = 2.0 * (super::diagnostics::loglik_of(a) - super::diagnostics::loglik_of(b));
        match gains.iter_mut().find(|x| x.0 == a.meas) {
            Some(x) => x.1 += g,
            None => gains.push((a.meas, g)),
        }
    }
    let own = gains.iter().find(|x| x.0 == meas).map_or(0.0, |x| x.1);
    if own > threshold {
        return Ok(None);
    }
    let others: Vec<String> = gains
        .iter()
        .filter(|x| x.0 != meas)
        .enumerate()
        .map(|(k, x)| {
            let verb = if k == 0 { " changes" } else { "" };
            format!("that of the {} innovations{verb} by {}", x.0, sig3(x.1))
        })
        .collect();
    let others = if others.is_empty() {
        String::new()
    } else {
        format!(", while {}", others.join(" and "))
    };
    Ok(Some(format!(
        "the {meas} fixes' own innovations do not bear it out: from the stated σ to the fit their log-likelihood changes by 2Δℓ {} (not above ln N = {}){others}",
        sig3(own),
        sig3(threshold)
    )))
}

/// The unit slip a fix's σ scale `f` looks like, in words: within 1.3× of 1/100 or 1/1000
/// (a σ column in cm or mm, cm/s or mm/s, read as m or m/s); None otherwise and for the
/// sensors' levels (their units are named by `--noise` and checked there).
fn unit_slip(f: &LevelFit) -> Option<String> {
    let Level::Sigma(meas) = f.level else {
        return None;
    };
    let (unit, per) = [("cm", 1e-2), ("mm", 1e-3)]
        .into_iter()
        .find(|&(_, k)| (f.scale / k).ln().abs() < 1.3f64.ln())?;
    let si = if meas.starts_with("vel") { "m/s" } else { "m" };
    Some(format!(
        "A scale this close to {} is what the fixes' σ in {unit}{} read as {si} gives: check the file's σ columns and their unit (the file's σ are SI)",
        sig3(per),
        if si == "m/s" { "/s" } else { "" }
    ))
}

/// Why level `f` is no finding though its test passed, in words: its 95 % interval holds the
/// stated value (scale 1). The test's 2Δℓ is the drop with the others at their fits, the
/// interval the curvature about the fit; where the likelihood is far from a parabola they can
/// disagree, and a claim whose own interval holds the stated value says nothing. None for a
/// level at its search bound (no interval) and an interval without 1.
fn holds_the_stated_value(f: &LevelFit) -> Option<String> {
    let [lo, hi] = f.interval;
    if f.at_bound != 0 || !(lo.is_finite() && hi.is_finite()) || !(lo <= 1.0 && 1.0 <= hi) {
        return None;
    }
    Some(format!(
        "its 95 % interval ({}–{}×) holds the stated value, so the data do not tell the two apart (its 2Δℓ {} is the drop with the other levels at their fits, where the likelihood is no parabola)",
        sig3(lo),
        sig3(hi),
        sig3(f.two_delta_loglik)
    ))
}

/// Most a sensor's noise level can be mis-stated by and still be read as that level: grades
/// differ by one or two orders of magnitude, and within a grade the data sheets' values differ
/// by a few times.
pub(super) const PLAUSIBLE_SCALE: f64 = 30.0;

/// Why sensor noise level `f`'s scale is no reading of the sensor's noise (more than
/// [`PLAUSIBLE_SCALE`] times the stated or less than its inverse), in words; None for a
/// plausible scale and for the aiding's σ (a receiver's σ may be stated for fixes with none).
fn implausible_scale(f: &LevelFit) -> Option<String> {
    if matches!(f.level, Level::Sigma(_))
        || (1.0 / PLAUSIBLE_SCALE..=PLAUSIBLE_SCALE).contains(&f.scale)
    {
        return None;
    }
    let way = if f.scale > 1.0 { "larger" } else { "smaller" };
    Some(format!(
        "A level {}× the stated is {way} than a noise level mis-stated within a grade ({}× at most): either the stated noise is not this sensor's (give --grade or --noise for it and run again) or the scale compensates for an effect the candidates do not describe",
        sig3(f.scale),
        PLAUSIBLE_SCALE
    ))
}

/// Where the body rotates or turns and where it vibrates [s], read from the IMU: the splits of
/// the noise levels ([`Motion::groups`]).
struct Motion {
    /// Spans while the rate averaged over 0.1 s is above [`super::signatures::ROTATING`].
    rotating: Vec<(f64, f64)>,
    /// Spans while the body vibrates (see [`vibrating_spans`]).
    shaking: Vec<(f64, f64)>,
}

impl Motion {
    /// Reads the spans in one pass over the IMU; every sample also goes to the raw white-noise
    /// `raw` reading (the same pass serves both).
    fn read(data: &ExplainData, raw: &mut super::raw_noise::Reading) -> anyhow::Result<Motion> {
        // rotating spans from the rate averaged over 0.1 s; vibration from the scatter of the
        // specific force about its mean over the same 0.1 s
        let mut spans: Vec<(f64, f64)> = Vec::new();
        let mut windows: Vec<(f64, f64, f64)> = Vec::new();
        let mut samples = data.imu.samples()?;
        let (mut t0, mut t_prev, mut acc) = (f64::NAN, f64::NAN, nalgebra::Vector3::zeros());
        let (mut f_sum, mut f_sq, mut count) = (nalgebra::Vector3::zeros(), 0.0, 0usize);
        let mut on = false;
        while let Some(smp) = samples.next_sample()? {
            raw.push(&smp);
            if t0.is_nan() {
                t0 = smp.t;
                t_prev = smp.t;
                continue;
            }
            acc += smp.dtheta;
            let dt = smp.t - t_prev;
            t_prev = smp.t;
            if dt > 0.0 {
                let f = smp.dv / dt;
                f_sum += f;
                f_sq += f.norm_squared();
                count += 1;
            }
            if smp.t - t0 >= 0.1 {
                let rate = acc.norm() / (smp.t - t0);
                if rate > super::signatures::ROTATING {
                    if !on {
                        spans.push((t0, smp.t));
                    }
                    on = true;
                    if let Some(last) = spans.last_mut() {
                        last.1 = smp.t;
                    }
                } else if rate < 0.5 * super::signatures::ROTATING {
                    on = false;
                }
                if count >= 2 {
                    let n = count as f64;
                    let scatter = (f_sq / n - (f_sum / n).norm_squared()).max(0.0).sqrt();
                    windows.push((t0, smp.t, scatter));
                }
                t0 = smp.t;
                acc = nalgebra::Vector3::zeros();
                (f_sum, f_sq, count) = (nalgebra::Vector3::zeros(), 0.0, 0);
            }
        }
        Ok(Motion {
            rotating: spans,
            shaking: vibrating_spans(&windows),
        })
    }

    /// Each innovation's group in the three splits of the noise levels: (0 at rest or moving
    /// straight, 1 while the body rotates or turns, to 2 s after), (0 first half, 1 second half
    /// of the updates) and (0 quiet, 1 while the body vibrates, to 2 s after; all 0 when the
    /// vibration level does not change across the data).
    fn groups(&self, inn: &[Innovation]) -> Vec<[usize; 3]> {
        let half = inn.len() / 2;
        let within = |sp: &[(f64, f64)], t: f64| sp.iter().any(|&(a, b)| t >= a && t <= b + 2.0);
        inn.iter()
            .enumerate()
            .map(|(k, i)| {
                [
                    usize::from(within(&self.rotating, i.t)),
                    usize::from(k >= half),
                    usize::from(within(&self.shaking, i.t)),
                ]
            })
            .collect()
    }
}

/// The spans [s] where the body vibrates, from 0.1-s windows (start, end, RMS scatter of the
/// specific force about its window mean [m/s²]): windows above the geometric mean of the
/// scatter's 10th and 90th percentiles, merged. None when those percentiles are within 3× of
/// each other or the 90th is under 0.1 m/s² (sensor noise alone): the vibration level does
/// not change enough across the data to tell a noise level from an effect of vibration.
fn vibrating_spans(windows: &[(f64, f64, f64)]) -> Vec<(f64, f64)> {
    if windows.len() < 10 {
        return Vec::new();
    }
    let mut v: Vec<f64> = windows.iter().map(|w| w.2).collect();
    v.sort_by(f64::total_cmp);
    let (p10, p90) = (v[v.len() / 10], v[v.len() * 9 / 10]);
    if p90 < 0.1 || p90 < 3.0 * p10 {
        return Vec::new();
    }
    let cut = (p10.max(1e-9) * p90).sqrt();
    let mut spans: Vec<(f64, f64)> = Vec::new();
    for &(a, b, _) in windows.iter().filter(|w| w.2 > cut) {
        match spans.last_mut() {
            Some(last) if a <= last.1 + 1e-9 => last.1 = b,
            _ => spans.push((a, b)),
        }
    }
    spans
}

/// Level `f`'s scale fitted on each group of each split apart: passes at half and twice the
/// fitted scale beside the innovations `inn` of `cfg` (which has it), a parabola in log₂ s through each group's
/// log-likelihood; σ from its curvature. Groups without curvature carry no information.
fn split_scales(
    passes: &Passes,
    cfg: &FilterConfig,
    f: &LevelFit,
    inn: &[Innovation],
    groups: &[[usize; 3]],
) -> anyhow::Result<Vec<super::Consistency>> {
    let loglik_by_group = |inn: &[Innovation]| -> [[f64; 2]; 3] {
        let mut l = [[0.0; 2]; 3];
        for (i, g) in inn.iter().zip(groups) {
            let li = super::diagnostics::loglik_of(i);
            for (split, &k) in g.iter().enumerate() {
                l[split][k] += li;
            }
        }
        l
    };
    let mut at = Vec::new();
    for u in [-1.0, 1.0] {
        let mut c = cfg.clone();
        f.level.apply(passes.model, &mut c, 2f64.powf(u));
        let inn = passes.innovations(&c)?;
        if inn.len() != groups.len() {
            anyhow::bail!("the noise passes differ in their updates");
        }
        at.push(loglik_by_group(&inn));
    }
    let mid = loglik_by_group(inn);
    let mut out = Vec::new();
    for (split, name, labels) in [
        (
            0,
            "rotation",
            ["at rest or moving straight", "while rotating or turning"],
        ),
        (1, "time", ["first half", "second half"]),
        (2, "vibration", ["quiet", "while vibrating"]),
    ] {
        let est: Vec<(f64, f64)> = (0..2)
            .map(|k| {
                let (ym, y0, yp) = (at[0][split][k], mid[split][k], at[1][split][k]);
                // ℓ(u) = a u² + b u + c through u = −1, 0, 1
                let a = 0.5 * (yp + ym) - y0;
                let b = 0.5 * (yp - ym);
                if a >= 0.0 || groups.iter().all(|g| g[split] != k) {
                    return (f64::NAN, f64::NAN);
                }
                // (beyond 8× of the passes the parabola is no guide: at least that far)
                let u = (-b / (2.0 * a)).clamp(-3.0, 3.0);
                let sigma_u = 1.0 / (-2.0 * a).sqrt();
                // a group that cannot place the scale within a factor 4 says nothing
                if sigma_u > 2.0 {
                    return (f64::NAN, f64::NAN);
                }
                (f.scale.log2() + u, sigma_u)
            })
            .collect();
        // tested in log₂ s (where the likelihood is near a parabola): the groups disagree when
        // χ² p < 0.0027 and their scales differ by more than 1.5×
        // (a group's information is judged above, by its σ in log₂ s)
        let mut c =
            super::Consistency::test_within(name, &|k| labels[k].to_string(), &est, f64::INFINITY);
        let spread = c
            .groups
            .iter()
            .map(|g| g.estimate)
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), u| {
                (lo.min(u), hi.max(u))
            });
        let wide = spread.1 - spread.0 > 1.5f64.log2();
        c.holds = !(c.p_value < super::findings::SPLIT_P && wide);
        if c.tested && c.p_value < super::findings::SPLIT_P {
            let ratio = sig3(2f64.powf(spread.1 - spread.0));
            c.why = if wide {
                format!(
                    "fails: χ² p {}, and the groups' scales differ by {ratio}×, more than 1.5×",
                    sig3(c.p_value)
                )
            } else {
                format!(
                    "holds: χ² p {}, but the groups' scales differ by only {ratio}×, not more than 1.5×",
                    sig3(c.p_value)
                )
            };
        }
        // said as scales of the stated value (σ by the delta method)
        for g in &mut c.groups {
            let scale = 2f64.powf(g.estimate);
            g.sigma *= scale * std::f64::consts::LN_2;
            g.estimate = scale;
        }
        out.push(c);
    }
    Ok(out)
}

/// The raw increments' reading `raw` of white-noise level `f` (see [`super::raw_noise`]):
/// Err(why) when the fit is more than they show, Ok(words) when they allow it; None for the
/// other levels.
fn raw_reading(
    f: &LevelFit,
    stated: &Stated,
    raw: Option<&super::raw_noise::RawNoise>,
) -> Option<Result<String, String>> {
    let (what, stated_si, to_unit, unit) = match f.level {
        Level::GyroArw => ("gyro", stated.white.0, DEG_RT_H, "deg/sqrt(h)"),
        Level::AccelVrw => ("accelerometer", stated.white.1, UG_RT_HZ, "ug/sqrt(Hz)"),
        _ => return None,
    };
    let Some(raw) = raw else {
        return Some(Ok(super::raw_noise::no_reading(what)));
    };
    let raw_si = if what == "gyro" { raw.gyro } else { raw.accel };
    // at a search bound the fit is a bound: at most its scale (no lower end) or at least it
    let interval = match f.at_bound {
        -1 => [0.0, f.scale],
        1 => [f.scale, f64::INFINITY],
        _ => f.interval,
    };
    super::raw_noise::judge(what, interval, stated_si, raw_si, to_unit, unit, raw.blocks)
}

/// rad/√s → deg/√h (white gyro noise).
const DEG_RT_H: f64 = 180.0 / std::f64::consts::PI * 60.0;
/// m/s/√s → µg/√Hz (white accelerometer noise).
const UG_RT_HZ: f64 = 1e6 / G0;

/// The noise levels the filter was given (SI).
struct Stated {
    /// White noise: ARW [rad/√s], VRW [m/s/√s].
    white: (f64, f64),
    /// Bias random walk: gyro [rad/s/√s], accelerometer [m/s²/√s].
    bias_rw: (f64, f64),
}

/// The finding of a significant noise level: the level the data show in the user's unit, its
/// scale of the stated value and the interval.
fn noise_finding(
    f: &LevelFit,
    stated: &Stated,
    misfit_share: Option<f64>,
    two_delta_loglik: f64,
) -> Finding {
    let (arw, vrw) = stated.white;
    let (grw, arw_bias) = stated.bias_rw;
    let (stated, unit, what) = match f.level {
        Level::GyroBiasRw => (
            // rad/s/√s → deg/h/√h
            grw * 180.0 / std::f64::consts::PI * 3600.0 * 60.0,
            "deg/h/sqrt(h)",
            "a gyro bias random walk (bias instability)".to_string(),
        ),
        Level::AccelBiasRw => (
            // m/s²/√s → µg/√s
            arw_bias * 1e6 / G0,
            "ug/sqrt(s)",
            "an accelerometer bias random walk (bias instability)".to_string(),
        ),
        Level::GyroArw => (
            arw * DEG_RT_H,
            "deg/sqrt(h)",
            "a gyro white noise (angle random walk)".to_string(),
        ),
        Level::AccelVrw => (
            vrw * UG_RT_HZ,
            "ug/sqrt(Hz)",
            "an accelerometer white noise (velocity random walk)".to_string(),
        ),
        Level::Sigma(m) => (1.0, "x stated", format!("a 1-σ of the {m} aiding")),
    };
    let estimate = stated * f.scale;
    let [lo, hi] = f.interval;
    // a scale the search stopped at with the likelihood still rising is a bound, not an
    // estimate: no interval (e.g. a σ stated for fixes that carry no noise at all)
    let bound = match f.at_bound {
        -1 => Some(("≤", "smaller", "at most")),
        1 => Some(("≥", "larger", "at least")),
        _ => None,
    };
    // a reference's rows (body velocity, attitude) are no fixes
    let states = match f.level {
        Level::Sigma(m) if from_reference(m) => "the σ the reference's rows state",
        _ => "the σ the fixes state",
    };
    let words = match (bound, f.level) {
        (Some((cmp, way, _)), Level::Sigma(_)) => format!(
            "the data show {what} at the search bound ({cmp} {}× {states}; the likelihood still rises towards {way} values, so no estimate or interval; 2Δℓ {})",
            sig3(f.scale),
            sig3(f.two_delta_loglik)
        ),
        (Some((cmp, way, _)), _) => format!(
            "the data show {what} at the search bound ({cmp} {} {unit}, {cmp} {}× the stated {}; the likelihood still rises towards {way} values, so no estimate or interval; 2Δℓ {})",
            sig3(estimate),
            sig3(f.scale),
            sig3(stated),
            sig3(f.two_delta_loglik)
        ),
        (None, Level::Sigma(_)) => format!(
            "the data show {what} {}× {states} (95 % interval {}–{}×; 2Δℓ {})",
            sig3(f.scale),
            sig3(lo),
            sig3(hi),
            sig3(f.two_delta_loglik)
        ),
        (None, _) => format!(
            "the data show {what} of {} {unit}, {}× the stated {} (95 % interval {}–{}×; 2Δℓ {})",
            sig3(estimate),
            sig3(f.scale),
            sig3(stated),
            sig3(lo),
            sig3(hi),
            sig3(f.two_delta_loglik)
        ),
    };
    // far below the σ the fixes state: the likely causes, as a unit check would name them
    let words = match f.level {
        Level::Sigma(m) if f.scale <= 0.01 => {
            let rows = if from_reference(m) { "rows" } else { "fixes" };
            format!(
                "{words}; the {rows} scatter by a hundredth or less of the σ they state, as a σ written in mm but read as m would, or {rows} that carry no noise (smoothed or simulated)"
            )
        }
        _ => words,
    };
    let headline = words.clone();
    let words = match misfit_share {
        Some(s) => format!(
            "{words}; it explains {} % of the baseline's excess misfit",
            super::share_percent(s)
        ),
        None => words,
    };
    Finding {
        term: f.level.name(),
        kind: "noise",
        estimate,
        sigma: if bound.is_some() {
            f64::NAN
        } else {
            stated * f.scale * (hi / lo).ln() / (2.0 * 1.959_964)
        },
        unit: unit.into(),
        llr: f.two_delta_loglik,
        p_value: f.p_holm,
        equivalent: Vec::new(),
        equivalent_estimates: Vec::new(),
        withheld_alike: Vec::new(),
        glr_estimate: estimate,
        glr_sigma: f64::NAN,
        round: 0,
        confounded_with: None,
        regressor_mean: 0.0,
        regressor_excited_mean: 0.0,
        excited_fraction: 0.0,
        effect_excited: 0.0,
        regressor_unit: String::new(),
        effect: estimate,
        effect_unit: unit.into(),
        separate_by: Vec::new(),
        prior_sigma: stated,
        prior_widened: false,
        words,
        headline,
        two_delta_loglik,
        misfit_share,
        prior_sigmas: 0.0,
        stand_in: None,
        suggested_prior: None,
        offset_in_place: None,
        not_attributed: None,
        not_attributed_because: Vec::new(),
        scale: Some(f.scale),
        scale_interval: bound.is_none().then_some(f.interval),
        scale_bound: bound.map(|b| b.2),
        halves: None,
        speed_halves: None,
        consistency: vec![],
    }
}

/// Measurement `m` is formed from a reference's rows (its spec `aiding` is a body velocity or an
/// attitude), not from GNSS fixes.
fn from_reference(m: &str) -> bool {
    use crate::model::catalog::Aiding;
    crate::model::generated::common::MEASUREMENTS
        .iter()
        .any(|x| x.name == m && matches!(x.aiding, Aiding::BodyVelocity | Aiding::Attitude))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_search_finds_the_maximum_of_a_parabola_in_log_scale() {
        // ℓ(u) = −3 (u − 1.7)², maximum at s = 2^1.7 = 3.25
        let f = |u: f64| -3.0 * (u - 1.7) * (u - 1.7);
        let mut calls = 0;
        let (u, l, a, edge) = search(
            &mut |u| {
                calls += 1;
                Ok(f(u))
            },
            f(0.0),
        )
        .unwrap();
        assert!((u - 1.7).abs() < 1e-9, "{u}");
        assert!(l.abs() < 1e-9);
        assert!((a + 3.0).abs() < 1e-9, "{a}");
        assert!(calls <= MAX_EVALS, "{calls}");
        assert_eq!(edge, 0);
    }

    #[test]
    fn vibration_spans_only_where_the_level_changes() {
        // 0.1-s windows: quiet (0.02 m/s²) but for 2–3 s and 5–5.5 s (3 m/s²)
        let w: Vec<(f64, f64, f64)> = (0..100)
            .map(|k| {
                let t = k as f64 * 0.1;
                let on = (2.0..3.0).contains(&t) || (5.0..5.5).contains(&t);
                (t, t + 0.1, if on { 3.0 } else { 0.02 })
            })
            .collect();
        let sp = vibrating_spans(&w);
        assert_eq!(sp.len(), 2, "{sp:?}");
        assert!(
            (sp[0].0 - 2.0).abs() < 1e-9 && (sp[0].1 - 3.0).abs() < 1e-9,
            "{sp:?}"
        );
        // the same level throughout (or only sensor noise): no split
        let flat: Vec<(f64, f64, f64)> = w.iter().map(|x| (x.0, x.1, 3.0)).collect();
        assert!(vibrating_spans(&flat).is_empty());
        let noise: Vec<(f64, f64, f64)> =
            w.iter().map(|x| (x.0, x.1, x.2.min(0.05) * 0.5)).collect();
        assert!(vibrating_spans(&noise).is_empty());
    }

    #[test]
    fn a_sensor_noise_scale_beyond_a_grade_is_no_reading_of_the_noise() {
        let fit = |level, scale| LevelFit {
            level,
            scale,
            interval: [scale / 1.2, scale * 1.2],
            at_bound: 0,
            two_delta_loglik: 100.0,
            p_holm: 0.0,
            significant: true,
        };
        assert!(implausible_scale(&fit(Level::AccelVrw, 10.0)).is_none());
        assert!(implausible_scale(&fit(Level::GyroArw, 0.1)).is_none());
        let why = implausible_scale(&fit(Level::AccelVrw, 335.0)).unwrap();
        assert!(
            why.contains("335× the stated") && why.contains("--grade"),
            "{why}"
        );
        assert!(implausible_scale(&fit(Level::GyroBiasRw, 0.01)).is_some());
        // an aiding σ may be stated for fixes that carry none
        assert!(implausible_scale(&fit(Level::Sigma("pos_h"), 0.001)).is_none());
    }

    #[test]
    fn a_fix_sigma_scale_of_a_unit_slip_is_said() {
        let fit = |level, scale: f64| LevelFit {
            level,
            scale,
            interval: [scale / 1.05, scale * 1.05],
            at_bound: 0,
            two_delta_loglik: 1e4,
            p_holm: 0.0,
            significant: true,
        };
        let w = unit_slip(&fit(Level::Sigma("pos_ne"), 0.00101)).unwrap();
        assert!(w.contains("0.001") && w.contains("in mm read as m "), "{w}");
        let w = unit_slip(&fit(Level::Sigma("vel_ne"), 0.0098)).unwrap();
        assert!(w.contains("in cm/s read as m/s"), "{w}");
        assert!(unit_slip(&fit(Level::Sigma("pos_ne"), 0.2)).is_none());
        assert!(unit_slip(&fit(Level::Sigma("pos_h"), 2.44e-4)).is_none());
        assert!(unit_slip(&fit(Level::AccelVrw, 0.001)).is_none());
    }

    #[test]
    fn a_level_whose_interval_holds_the_stated_value_is_no_finding() {
        let fit = |interval: [f64; 2], at_bound| LevelFit {
            level: Level::GyroArw,
            scale: (interval[0] * interval[1]).sqrt(),
            interval,
            at_bound,
            two_delta_loglik: 11.9,
            p_holm: 0.001,
            significant: true,
        };
        let why = holds_the_stated_value(&fit([0.609, 1.10], 0)).unwrap();
        assert!(why.contains("0.609–1.10×") && why.contains("11.9"), "{why}");
        assert!(holds_the_stated_value(&fit([0.25, 0.78], 0)).is_none());
        assert!(holds_the_stated_value(&fit([1.02, 1.3], 0)).is_none());
        // at a search bound there is no interval to judge
        assert!(holds_the_stated_value(&fit([0.5, 2.0], -1)).is_none());
        assert!(holds_the_stated_value(&fit([0.5, f64::INFINITY], 0)).is_none());
    }

    #[test]
    fn the_search_steps_on_when_the_likelihood_keeps_rising() {
        // rises up to u = 5 (s = 32): steps of 2 from 1
        let f = |u: f64| -((u - 5.0) * (u - 5.0)).sqrt();
        let (u, _, _, _) = search(&mut |u| Ok(f(u)), f(0.0)).unwrap();
        assert!(u >= 3.0, "{u}");
        // and stays at 1 when nothing is to gain
        let g = |u: f64| -u * u;
        let (u, _, a, edge) = search(&mut |u| Ok(g(u)), g(0.0)).unwrap();
        assert!(u.abs() < 1e-9 && (a + 1.0).abs() < 1e-9 && edge == 0);
    }

    #[test]
    fn a_scale_at_the_search_bound_is_said_as_a_bound_without_an_interval() {
        // a σ stated for noise-free fixes: the likelihood rises without end towards 0
        let (u, _, _, edge) = search(&mut |u| Ok(-u), 0.0).unwrap();
        assert!(u == -4.0 && edge == -1, "{u} {edge}");
        let (u, _, _, edge) = search(&mut |u| Ok(u), 0.0).unwrap();
        assert!(u == 6.0 && edge == 1, "{u} {edge}");
        let fit = |at_bound| LevelFit {
            level: Level::Sigma("pos_h"),
            scale: 2f64.powi(-12),
            interval: [1.71e-4, 3.49e-4],
            at_bound,
            two_delta_loglik: 900.0,
            p_holm: 0.0,
            significant: true,
        };
        let stated = Stated {
            white: (1e-4, 1e-3),
            bias_rw: (0.0, 0.0),
        };
        let f = noise_finding(&fit(-1), &stated, None, 900.0);
        assert!(
            f.words
                .contains("at the search bound (≤ 2.44e-4× the σ the fixes state")
                && !f.words.contains("interval 1.71e-4"),
            "{}",
            f.words
        );
        assert!(f.scale_interval.is_none() && f.sigma.is_nan());
        assert_eq!(f.scale_bound, Some("at most"));
        // a hundredth or less of the stated σ: the likely causes are named
        assert!(
            f.words.contains("as a σ written in mm but read as m would"),
            "{}",
            f.words
        );
        let mut g = fit(1);
        g.level = Level::GyroArw;
        g.scale = 64.0;
        let f = noise_finding(&g, &stated, None, 900.0);
        assert!(f.words.contains("at the search bound (≥"), "{}", f.words);
        assert!(!f.words.contains("read as m"), "{}", f.words);
        assert_eq!(f.scale_bound, Some("at least"));
        // bracketed: an estimate with its interval
        let f = noise_finding(&fit(0), &stated, None, 900.0);
        assert!(
            f.words.contains("95 % interval 1.71e-4–3.49e-4×"),
            "{}",
            f.words
        );
        assert!(f.scale_interval.is_some() && f.scale_bound.is_none());
    }
}
