//! How well `explain` finds hidden effects: seeded cases from the hidden-effect generator
//! ([`crate::sim::hidden`]) with magnitudes drawn by their noncentrality λ = θ² I (log-uniform),
//! detection, false alarms, coefficient error, calibration and gain, and the power curve
//! against theory. Each case depends only on (seed, index), so any split of the indices over
//! threads or machines gives the same cases; [`summarize`] of merged case lists equals one run.

use crate::estimate::stats;
use crate::experiment::hidden::{inject, run_hidden_on, simulate_case, stated_config};
use crate::explain::{self, ExplainData, ExplainOptions};
use crate::model::generated::common;
use crate::model::Model;
use crate::sim::hidden::{all_groups, clear_effect, generate, CaseKind, GROUPS};
use crate::sim::rng::Rng;
use serde::{Deserialize, Serialize};

/// What an evaluation draws.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EvalSpec {
    /// Seed of the campaign.
    pub seed: u64,
    /// Library groups hidden terms are drawn from.
    pub groups: Vec<String>,
    /// Simulated seconds per case.
    pub seconds: f64,
    /// Fraction of null cases (nothing hidden).
    pub null_fraction: f64,
    /// Range of the noncentrality λ = θ² I, drawn log-uniform.
    pub lambda: [f64; 2],
    /// Family-wise α of explain.
    pub alpha: f64,
}

impl Default for EvalSpec {
    fn default() -> Self {
        EvalSpec {
            seed: 1,
            groups: GROUPS.iter().map(|g| g.to_string()).collect(),
            seconds: 600.0,
            null_fraction: 0.2,
            lambda: [10.0, 1000.0],
            alpha: 0.01,
        }
    }
}

/// One case's outcome. Every field must be present in a stored case (a null stays `null`):
/// a field left out of a hand-edited shard is refused, never read as empty.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct CaseResult {
    /// Index of the case in the campaign.
    pub index: usize,
    /// `null` or the library group.
    pub group: String,
    /// Hidden term (None for a null case; the first of a two-term case).
    #[serde(deserialize_with = "Option::deserialize")]
    pub term: Option<String>,
    /// The other hidden terms of a case that hides more than one (a two-term case, a mounting's
    /// two axes, a turntable's three delays).
    pub also_hidden: Vec<String>,
    /// Noise levels the case states wrongly to the filter (a noise case); explain should name
    /// them as noise, not a term.
    pub noise_misstated: Vec<String>,
    /// True value (display unit of the term).
    #[serde(deserialize_with = "Option::deserialize")]
    pub truth: Option<f64>,
    /// Noncentrality λ = θ² I of the hidden term's test through the baseline filter (of the
    /// weakest hidden term, when there are more than one).
    #[serde(deserialize_with = "Option::deserialize")]
    pub lambda: Option<f64>,
    /// Terms explain named (sensor and measurement findings that are no stand-ins: causes, and
    /// classes the data cannot attribute to one member).
    pub named: Vec<String>,
    /// Noise levels explain named (noise findings: a claim about the data's noise, not a term).
    pub noise_named: Vec<String>,
    /// Of those, the ones it labelled "not one level across the data" (stand-ins).
    pub noise_stand_ins: Vec<String>,
    /// Terms explain fitted but labelled stand-ins ("Fitted, but not a cause"): no claim, so
    /// neither a detection nor a wrong term.
    pub stand_ins: Vec<String>,
    /// Every hidden term was named or is in a named class.
    pub detected: bool,
    /// A named term is neither a hidden one nor in a class with one (or anything in a null case).
    pub wrong_term: bool,
    /// Estimate of the hidden term (display unit) and its σ, when detected.
    #[serde(deserialize_with = "Option::deserialize")]
    pub estimate: Option<f64>,
    /// σ of the estimate.
    #[serde(deserialize_with = "Option::deserialize")]
    pub sigma: Option<f64>,
    /// Fraction of the oracle's gain the extended model recovers, when defined.
    #[serde(deserialize_with = "Option::deserialize")]
    pub gain_recovery: Option<f64>,
    /// Number of candidates tested (testable and separable) in the baseline pass.
    pub candidates_tested: usize,
    /// Wall time of the case [s] (not part of the comparison of runs).
    pub seconds_taken: f64,
    /// Of it, simulating the case and the pilot passes that size its hidden terms [s].
    pub seconds_taken_setup: f64,
    /// Of it, explain itself [s] (the rest: the oracle filter and the scoring).
    pub seconds_taken_explain: f64,
}

fn case_rng(seed: u64, index: usize) -> Rng {
    Rng::new(
        seed.wrapping_mul(0x9E37_79B9_7F4A_7C15)
            .wrapping_add((index as u64).wrapping_mul(0xD1B5_4A32_D192_ED03))
            .wrapping_add(1),
    )
}

/// What case `index` of campaign `spec` draws before anything is simulated: the hidden case
/// and, when it hides a term, its noncentrality λ = θ² I.
pub struct Drawn {
    /// The hidden-effect case (group, hidden term, scenario, baseline).
    pub case: crate::sim::hidden::HiddenCase,
    /// The λ the hidden term is put in at (None for a null case).
    pub lambda: Option<f64>,
}

/// Draws case `index` of the campaign `spec` (cheap: no simulation); [`run_case`] runs what
/// this draws, and a stored case is checked against it ([`check_case`]).
pub fn draw(spec: &EvalSpec, index: usize) -> anyhow::Result<Drawn> {
    let mut rng = case_rng(spec.seed, index);
    let null = rng.uniform() < spec.null_fraction;
    let kind = if null {
        CaseKind::Null
    } else {
        let k = ((rng.uniform() * spec.groups.len() as f64) as usize).min(spec.groups.len() - 1);
        let g = all_groups()
            .into_iter()
            .find(|g| *g == spec.groups[k])
            .ok_or_else(|| anyhow::anyhow!("unknown group `{}`", spec.groups[k]))?;
        if g == "two" {
            CaseKind::Two
        } else {
            CaseKind::One(g)
        }
    };
    let case_seed = spec
        .seed
        .wrapping_mul(1_000_003)
        .wrapping_add(index as u64 + 1);
    let case = generate(case_seed, kind, spec.seconds, clear_effect(kind));
    let lambda = case.hidden.first().map(|_| {
        let (lo, hi) = (spec.lambda[0].ln(), spec.lambda[1].ln());
        (lo + (hi - lo) * rng.uniform()).exp()
    });
    Ok(Drawn { case, lambda })
}

/// Runs case `index` of the campaign `spec`.
pub fn run_case(
    spec: &EvalSpec,
    index: usize,
    opts: &ExplainOptions,
) -> anyhow::Result<CaseResult> {
    run_case_explained(spec, index, opts).map(|x| x.0)
}

/// Runs case `index` of the campaign `spec`; returns its result and explain's whole answer
/// (for a developer's look at one case).
pub fn run_case_explained(
    spec: &EvalSpec,
    index: usize,
    opts: &ExplainOptions,
) -> anyhow::Result<(CaseResult, crate::explain::Explanation)> {
    let t_start = std::time::Instant::now();
    let mut opts = opts.clone();
    opts.alpha = spec.alpha;
    let t_setup = std::time::Instant::now();
    let (
        Drawn {
            case: drawn,
            lambda: drawn_lambda,
        },
        (case, sim, aid),
    ) = prepare(spec, index)?;
    let seconds_taken_setup = t_setup.elapsed().as_secs_f64();
    // (a case hides a term exactly when its draw gave a λ)
    let lambda = drawn_lambda.filter(|_| !case.hidden.is_empty());
    let truth_si = case.hidden.first().map(|h| h.1);
    let term = match case.hidden.first() {
        Some(h) => Some(term_index(&h.0)?),
        None => None,
    };
    let out = run_hidden_on(&case, &sim, &aid, &opts)?;
    let e = &out.explanation;
    // a claim: a term finding that is no stand-in (a cause, or a class the data cannot
    // attribute to one member); a stand-in ("Fitted, but not a cause: it probably stands in for
    // …") claims nothing about the sensor and is neither a detection nor a wrong term
    let claims: Vec<&crate::explain::Finding> = e
        .findings
        .iter()
        .filter(|f| f.kind != "noise" && f.stand_in.is_none())
        .collect();
    let names = |keep: &dyn Fn(&crate::explain::Finding) -> bool| -> Vec<String> {
        e.findings
            .iter()
            .filter(|f| keep(f))
            .map(|f| f.term.clone())
            .collect()
    };
    let named = names(&|f| f.kind != "noise" && f.stand_in.is_none());
    let stand_ins = names(&|f| f.kind != "noise" && f.stand_in.is_some());
    let noise_named = names(&|f| f.kind == "noise");
    let noise_stand_ins = names(&|f| f.kind == "noise" && f.stand_in.is_some());
    let hidden: Vec<&str> = case.hidden.iter().map(|h| h.0.as_str()).collect();
    // a claim covers hidden term h when it names h or h is in its class
    let covers =
        |f: &crate::explain::Finding, h: &str| f.term == h || f.equivalent.iter().any(|q| q == h);
    let (mut detected, mut estimate, mut sigma) = (false, None, None);
    if let Some(t) = term {
        let name = common::TERMS[t].name;
        detected = hidden.iter().all(|h| claims.iter().any(|f| covers(f, h)));
        for f in &claims {
            if f.term == name {
                estimate = Some(f.estimate);
                sigma = Some(f.sigma);
            } else if let Some(q) = f.equivalent_estimates.iter().find(|q| q.term == name) {
                estimate = Some(q.estimate);
                sigma = Some(q.sigma);
            }
        }
    }
    let hidden_name = term.map(|t| common::TERMS[t].name);
    let wrong_term = claims.iter().any(|f| !hidden.iter().any(|h| covers(f, h)));
    let result = CaseResult {
        index,
        group: drawn.group.clone(),
        term: hidden_name.map(str::to_string),
        also_hidden: hidden.iter().skip(1).map(|h| h.to_string()).collect(),
        noise_misstated: case.noise_ratio.iter().map(|n| n.0.clone()).collect(),
        truth: term
            .zip(truth_si)
            .map(|(t, v)| v / common::TERMS[t].display_to_si),
        lambda,
        named,
        noise_named,
        noise_stand_ins,
        stand_ins,
        detected,
        wrong_term,
        estimate,
        sigma,
        gain_recovery: out.gain_recovery().map(|g| g.0),
        candidates_tested: e
            .candidates
            .iter()
            .filter(|c| c.testable && c.confounded_with.is_none())
            .count(),
        seconds_taken: t_start.elapsed().as_secs_f64(),
        seconds_taken_setup,
        seconds_taken_explain: out.explain_seconds,
    };
    Ok((result, out.explanation))
}

/// Draws case `index` of campaign `spec` and puts its hidden terms in at the drawn λ: what
/// [`run_case`] explains (a test may change the case, e.g. its declared priors, and run it with
/// [`crate::experiment::hidden::run_hidden_on`]).
pub fn prepare(spec: &EvalSpec, index: usize) -> anyhow::Result<(Drawn, Put)> {
    let drawn = draw(spec, index)?;
    let put = if GROUPS.contains(&drawn.case.group.as_str()) {
        put_in_increments(&drawn.case, drawn.lambda, index)?
    } else {
        put_in_simulation(&drawn.case, drawn.lambda, index)?
    };
    Ok((drawn, put))
}

/// A case with its hidden terms put in at the drawn λ (its hidden values the ones put in), its
/// simulated IMU and truth, and its aiding.
pub type Put = (
    crate::sim::hidden::HiddenCase,
    crate::sim::simulator::SimOutput,
    Vec<crate::estimate::filter::AidingEpoch>,
);

/// The information I of term `name`'s signature through `case`'s baseline filter (its stated
/// noise) on simulated data `sim` and `aid`: λ = θ² I.
fn information(
    case: &crate::sim::hidden::HiddenCase,
    sim: &crate::sim::simulator::SimOutput,
    aid: &[crate::estimate::filter::AidingEpoch],
    name: &str,
) -> anyhow::Result<f64> {
    Ok(conditional_information(case, sim, aid, &[name])?[0])
}

/// For each of the terms `names`, the information of its signature through `case`'s baseline
/// filter with the other terms estimated beside it, 1 / (J⁻¹)_ii of their joint information J
/// (one pass): λ_i = θ_i² / (J⁻¹)_ii is the noncentrality of the test that names term i beside
/// the others (for one term, I itself).
fn conditional_information(
    case: &crate::sim::hidden::HiddenCase,
    sim: &crate::sim::simulator::SimOutput,
    aid: &[crate::estimate::filter::AidingEpoch],
    names: &[&str],
) -> anyhow::Result<Vec<f64>> {
    let baseline = Model::parse(&case.baseline)?;
    let data = ExplainData {
        imu: crate::explain::ImuInput::Memory(&sim.imu),
        aid,
        truth: Some(&sim.truth),
        start: sim.start,
        tape: None,
    };
    let cfg = stated_config(case, sim, &baseline);
    let terms = names
        .iter()
        .map(|n| term_index(n))
        .collect::<anyhow::Result<Vec<usize>>>()?;
    let j = explain::signature_information_matrix(&baseline, &terms, &data, &cfg)?;
    if terms.len() == 1 {
        return Ok(j);
    }
    let m = terms.len();
    let inv = nalgebra::DMatrix::from_row_slice(m, m, &j).try_inverse();
    Ok((0..m)
        .map(|i| match &inv {
            Some(inv) if inv[(i, i)] > 0.0 && inv[(i, i)].is_finite() => 1.0 / inv[(i, i)],
            // the terms cannot be told apart on these data: none can be named beside the others
            _ => 0.0,
        })
        .collect())
}

/// A sensor group's term: simulated without it, then put into the IMU's increments at the drawn
/// λ (θ · regressor · Δt along the sensor axis; I from a pilot pass on the same data).
fn put_in_increments(
    drawn: &crate::sim::hidden::HiddenCase,
    drawn_lambda: Option<f64>,
    index: usize,
) -> anyhow::Result<Put> {
    let mut case = drawn.scaled(0.0);
    let (mut sim, aid) = simulate_case(&case)?;
    if let Some((name, reference)) = drawn.hidden.first() {
        // (a sensor group states no noise and has no velocity reference: its stated
        // configuration is the spec's)
        let info = information(&case, &sim, &aid, name)?;
        let lam = drawn_lambda
            .ok_or_else(|| anyhow::anyhow!("case {index}: a hidden term drawn without its λ"))?;
        let theta = reference.signum() * (lam / info.max(f64::MIN_POSITIVE)).sqrt();
        inject(&mut sim.imu, sim.start.t, term_index(name)?, theta);
        case.hidden = vec![(name.clone(), theta)];
        hold_in_declared_prior(&mut case);
    }
    Ok((case, sim, aid))
}

/// Any other group (GNSS, reference, turntable, two-term, noise): the hidden terms go in
/// through the simulator (a GNSS or reference term lives in the aiding, not in the increments).
/// A pilot simulation without them gives each term's information I_i through the case's
/// baseline filter; every hidden value is then scaled by one factor k so that the weakest term's
/// λ_i = (k θ_i)² I_i is the drawn λ, and the case is simulated again (the same noise).
fn put_in_simulation(
    drawn: &crate::sim::hidden::HiddenCase,
    drawn_lambda: Option<f64>,
    index: usize,
) -> anyhow::Result<Put> {
    if drawn.hidden.is_empty() {
        let (sim, aid) = simulate_case(drawn)?;
        return Ok((drawn.clone(), sim, aid));
    }
    let lam = drawn_lambda
        .ok_or_else(|| anyhow::anyhow!("case {index}: a hidden term drawn without its λ"))?;
    let pilot = drawn.scaled(0.0);
    let (sim0, aid0) = simulate_case(&pilot)?;
    // with several terms hidden, each one's information beside the others': a case is found
    // when every term is named, and the weakest term is named only beside the others
    let names: Vec<&str> = drawn.hidden.iter().map(|h| h.0.as_str()).collect();
    let info = conditional_information(&pilot, &sim0, &aid0, &names)?;
    let mut weakest = f64::INFINITY;
    for ((_, v), i) in drawn.hidden.iter().zip(&info) {
        weakest = weakest.min(v * v * i);
    }
    if !(weakest.is_finite() && weakest > 0.0) {
        anyhow::bail!(
            "case {index}: the baseline filter holds no information on {} beside the other hidden terms (λ per unit {weakest})",
            drawn.oracle_model()
        );
    }
    drop((sim0, aid0));
    let mut case = drawn.scaled((lam / weakest).sqrt());
    hold_in_declared_prior(&mut case);
    let (sim, aid) = simulate_case(&case)?;
    Ok((case, sim, aid))
}

/// Where a case declares a prior for a family of terms (a MEMS-class gyro's kgf_*, as a user
/// would with `--prior kgf_*=…`), the family's σ is widened to hold each hidden value within
/// 1σ: the λ draw can put a weak signature's term at many of the declared σ (kgf_yy at 17σ),
/// which explain rightly calls a stand-in for that prior — a sensor class the case did not
/// declare. The whole family is widened alike, so no prior points at the hidden member.
fn hold_in_declared_prior(case: &mut crate::sim::hidden::HiddenCase) {
    let family = |n: &str| n.split('_').next().unwrap_or(n).to_string();
    for (name, v) in case.hidden.clone() {
        for p in case
            .priors
            .iter_mut()
            .filter(|p| family(&p.0) == family(&name))
        {
            p.1 = p.1.max(v.abs());
        }
    }
}

fn term_index(name: &str) -> anyhow::Result<usize> {
    common::TERMS
        .iter()
        .position(|x| x.name == name)
        .ok_or_else(|| anyhow::anyhow!("hidden term `{name}` is not a spec term"))
}

/// Detection in one λ bin, measured and in theory.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct PowerBin {
    /// Lower edge of the λ bin.
    pub lambda_lo: f64,
    /// Upper edge.
    pub lambda_hi: f64,
    /// Non-null cases in the bin.
    pub cases: usize,
    /// Fraction detected (null when the bin is empty).
    pub detection_rate: Option<f64>,
    /// Theoretical detection of the test explain's selection starts with, averaged over the
    /// bin's cases: a χ²₁(λ_i) test at Holm's first threshold χ²₁ quantile 1 − α/m_i over the
    /// case's own m_i candidates tested (at the bin's geometric centre and the median m when the
    /// bin is empty).
    pub theory: f64,
    /// 95 % confidence interval of the detection rate (Wilson score).
    #[serde(default)]
    pub detection_ci: Option<[f64; 2]>,
}

/// Per-group detection.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct GroupStats {
    /// Non-null cases of the group.
    pub cases: usize,
    /// Fraction detected.
    pub detection_rate: Option<f64>,
    /// Fraction detected among the cases with λ ≥ 50.
    pub detection_rate_lambda_50: Option<f64>,
    /// The group's detection against λ, with theory.
    #[serde(default)]
    pub power_curve: Vec<PowerBin>,
}

/// The evaluation's numbers (DESIGN-style field names of the issue; rates are fractions 0–1,
/// null where nothing was measured).
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct Summary {
    /// Cases in all.
    pub cases: usize,
    /// Campaign seed.
    pub seed: u64,
    /// Null cases.
    pub null_cases: usize,
    /// Detection over all non-null cases.
    pub detection_rate: Option<f64>,
    /// Detection over the non-null cases with λ ≥ 50 (target ≥ 0.95).
    pub detection_rate_lambda_50: Option<f64>,
    /// Null cases in which something was named (target ≤ 0.05).
    pub false_alarm_rate: Option<f64>,
    /// Non-null cases in which a wrong term was named.
    pub wrong_term_rate: Option<f64>,
    /// Cases in which a noise level was named (as a cause or as a stand-in).
    #[serde(default)]
    pub noise_finding_rate: Option<f64>,
    /// Cases in which a noise level the case states right was named as a cause (not as a
    /// stand-in): a false alarm about the noise (target ≤ 0.05, as for terms).
    #[serde(default)]
    pub noise_false_alarm_rate: Option<f64>,
    /// 95 % confidence interval of the same.
    #[serde(default)]
    pub noise_false_alarm_ci: Option<[f64; 2]>,
    /// Median of |θ̂ − θ|/|θ| over the detected cases (target ≤ 0.10).
    pub coef_error_median: Option<f64>,
    /// 90th percentile of the same.
    pub coef_error_p90: Option<f64>,
    /// Fraction of detected cases with the truth inside θ̂ ± 2σ (target 0.90–0.98).
    pub calibration: Option<f64>,
    /// Median gain recovery over the detected cases where it is defined (target ≥ 0.8).
    pub gain_recovery_median: Option<f64>,
    /// Per group.
    pub by_group: std::collections::BTreeMap<String, GroupStats>,
    /// Detection against λ, with theory.
    pub power_curve: Vec<PowerBin>,
    /// Median candidates tested per case (the Holm count of the theory of an empty bin).
    pub candidates_tested_median: f64,
    /// 95 % confidence interval (Wilson score) of the detection rate at λ ≥ 50.
    #[serde(default)]
    pub detection_lambda_50_ci: Option<[f64; 2]>,
    /// 95 % confidence interval of the false-alarm rate.
    #[serde(default)]
    pub false_alarm_ci: Option<[f64; 2]>,
    /// 95 % confidence interval of the wrong-term rate.
    #[serde(default)]
    pub wrong_term_ci: Option<[f64; 2]>,
    /// 95 % confidence interval of the calibration.
    #[serde(default)]
    pub calibration_ci: Option<[f64; 2]>,
    /// Cases that state a noise level wrongly to the filter (with or without a term beside it).
    #[serde(default)]
    pub noise_cases: usize,
    /// Of those, the fraction in which explain named every misstated level as noise.
    #[serde(default)]
    pub noise_called_rate: Option<f64>,
    /// Cases that state a noise level wrongly and hide no term: the fraction in which explain
    /// named a term (a false alarm; these cases are among the null cases).
    #[serde(default)]
    pub noise_only_term_named_rate: Option<f64>,
    /// α used.
    pub alpha: f64,
}

fn rate(hits: usize, n: usize) -> Option<f64> {
    (n > 0).then(|| hits as f64 / n as f64)
}

fn quantile(v: &mut [f64], q: f64) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    let k = ((v.len() - 1) as f64 * q).round() as usize;
    Some(v[k])
}

/// 95 % confidence interval of a rate `hits`/`n` (Wilson score; None for n = 0).
pub fn wilson(hits: usize, n: usize) -> Option<[f64; 2]> {
    if n == 0 {
        return None;
    }
    let z = 1.959_963_984_540_054_f64;
    let (nf, p) = (n as f64, hits as f64 / n as f64);
    let den = 1.0 + z * z / nf;
    let centre = (p + z * z / (2.0 * nf)) / den;
    let half = z * (p * (1.0 - p) / nf + z * z / (4.0 * nf * nf)).sqrt() / den;
    Some([(centre - half).max(0.0), (centre + half).min(1.0)])
}

/// Holm's first threshold over `m` candidates at family-wise `alpha`: the χ²₁ quantile 1 − α/m.
pub fn first_threshold(alpha: f64, m: usize) -> f64 {
    stats::chi2_isf(alpha / m.max(1) as f64, 1.0)
}

/// λ bin edges of the power curve.
const EDGES: [f64; 7] = [10.0, 20.0, 50.0, 100.0, 200.0, 500.0, 1000.0];

/// Detection per λ bin of `non_null` cases against the stated test's theory.
fn power_bins(non_null: &[&CaseResult], alpha: f64, m_med: f64) -> Vec<PowerBin> {
    EDGES
        .windows(2)
        .map(|w| {
            let in_bin: Vec<&&CaseResult> = non_null
                .iter()
                .filter(|c| c.lambda.is_some_and(|l| l >= w[0] && l < w[1]))
                .collect();
            let hits = in_bin.iter().filter(|c| c.detected).count();
            let theory = if in_bin.is_empty() {
                power((w[0] * w[1]).sqrt(), first_threshold(alpha, m_med as usize))
            } else {
                in_bin
                    .iter()
                    .map(|c| {
                        let l = c.lambda.unwrap_or(w[0]);
                        power(l, first_threshold(alpha, c.candidates_tested))
                    })
                    .sum::<f64>()
                    / in_bin.len() as f64
            };
            PowerBin {
                lambda_lo: w[0],
                lambda_hi: w[1],
                cases: in_bin.len(),
                detection_rate: rate(hits, in_bin.len()),
                theory,
                detection_ci: wilson(hits, in_bin.len()),
            }
        })
        .collect()
}

/// Theoretical detection probability of a single χ²₁ test with noncentrality λ at threshold c.
pub fn power(lambda: f64, c: f64) -> f64 {
    let (a, s) = (c.sqrt(), lambda.sqrt());
    stats::normal_cdf(-a - s) + 1.0 - stats::normal_cdf(a - s)
}

/// The numbers of a set of cases (in index order).
pub fn summarize(spec: &EvalSpec, cases: &[CaseResult]) -> Summary {
    let non_null: Vec<&CaseResult> = cases.iter().filter(|c| c.term.is_some()).collect();
    let nulls = cases.len() - non_null.len();
    let det = non_null.iter().filter(|c| c.detected).count();
    let hi: Vec<&&CaseResult> = non_null
        .iter()
        .filter(|c| c.lambda.is_some_and(|l| l >= 50.0))
        .collect();
    let mut errs: Vec<f64> = non_null
        .iter()
        .filter_map(|c| Some((c.estimate? - c.truth?).abs() / c.truth?.abs()))
        .collect();
    let calib: Vec<bool> = non_null
        .iter()
        .filter_map(|c| Some((c.estimate? - c.truth?).abs() <= 2.0 * c.sigma?))
        .collect();
    let mut gains: Vec<f64> = non_null
        .iter()
        .filter(|c| c.detected)
        .filter_map(|c| c.gain_recovery)
        .collect();
    let mut m: Vec<f64> = cases.iter().map(|c| c.candidates_tested as f64).collect();
    let m_med = quantile(&mut m, 0.5).unwrap_or(27.0).max(1.0);
    let power_curve = power_bins(&non_null, spec.alpha, m_med);
    let mut by_group = std::collections::BTreeMap::new();
    for g in &spec.groups {
        let of: Vec<&CaseResult> = non_null.iter().filter(|c| &c.group == g).copied().collect();
        let of_hi: Vec<&&CaseResult> = of
            .iter()
            .filter(|c| c.lambda.is_some_and(|l| l >= 50.0))
            .collect();
        by_group.insert(
            g.clone(),
            GroupStats {
                cases: of.len(),
                detection_rate: rate(of.iter().filter(|c| c.detected).count(), of.len()),
                detection_rate_lambda_50: rate(
                    of_hi.iter().filter(|c| c.detected).count(),
                    of_hi.len(),
                ),
                power_curve: power_bins(&of, spec.alpha, m_med),
            },
        );
    }
    let hi_hits = hi.iter().filter(|c| c.detected).count();
    let false_alarms = cases
        .iter()
        .filter(|c| c.term.is_none() && !c.named.is_empty())
        .count();
    let wrong = non_null.iter().filter(|c| c.wrong_term).count();
    let calibrated = calib.iter().filter(|&&b| b).count();
    let noise: Vec<&CaseResult> = cases
        .iter()
        .filter(|c| !c.noise_misstated.is_empty())
        .collect();
    let called = noise
        .iter()
        .filter(|c| c.noise_misstated.iter().all(|l| c.noise_named.contains(l)))
        .count();
    let noise_only: Vec<&&CaseResult> = noise.iter().filter(|c| c.term.is_none()).collect();
    let noise_false = cases.iter().filter(|c| noise_false_alarm(c)).count();
    Summary {
        cases: cases.len(),
        seed: spec.seed,
        null_cases: nulls,
        detection_rate: rate(det, non_null.len()),
        detection_rate_lambda_50: rate(hi_hits, hi.len()),
        false_alarm_rate: rate(false_alarms, nulls),
        wrong_term_rate: rate(wrong, non_null.len()),
        noise_finding_rate: rate(
            cases.iter().filter(|c| !c.noise_named.is_empty()).count(),
            cases.len(),
        ),
        noise_false_alarm_rate: rate(noise_false, cases.len()),
        noise_false_alarm_ci: wilson(noise_false, cases.len()),
        coef_error_median: quantile(&mut errs, 0.5),
        coef_error_p90: quantile(&mut errs, 0.9),
        calibration: rate(calibrated, calib.len()),
        gain_recovery_median: quantile(&mut gains, 0.5),
        by_group,
        power_curve,
        candidates_tested_median: m_med,
        alpha: spec.alpha,
        detection_lambda_50_ci: wilson(hi_hits, hi.len()),
        false_alarm_ci: wilson(false_alarms, nulls),
        wrong_term_ci: wilson(wrong, non_null.len()),
        calibration_ci: wilson(calibrated, calib.len()),
        noise_cases: noise.len(),
        noise_called_rate: rate(called, noise.len()),
        noise_only_term_named_rate: rate(
            noise_only.iter().filter(|c| !c.named.is_empty()).count(),
            noise_only.len(),
        ),
    }
}

/// Whether explain named, as a cause, a noise level that case `c` states right.
pub fn noise_false_alarm(c: &CaseResult) -> bool {
    c.noise_named
        .iter()
        .any(|l| !c.noise_stand_ins.contains(l) && !c.noise_misstated.contains(l))
}

/// Re-exported for the command line: the default explain options.
pub fn default_options() -> ExplainOptions {
    explain::ExplainOptions::default()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wilson_interval_holds_the_rate_and_stays_in_0_1() {
        let [lo, hi] = wilson(0, 32).expect("n > 0");
        assert_eq!(lo, 0.0);
        // the rule of three's neighbourhood: 0 of 32 leaves up to ~11 %
        assert!(hi > 0.09 && hi < 0.12, "{hi}");
        let [lo, hi] = wilson(18, 32).expect("n > 0");
        assert!(lo < 18.0 / 32.0 && hi > 18.0 / 32.0 && hi - lo > 0.3 && hi - lo < 0.35);
        assert!(wilson(5, 0).is_none());
    }

    #[test]
    fn power_is_alpha_at_zero_and_grows() {
        let c = stats::chi2_isf(0.01, 1.0);
        assert!((power(0.0, c) - 0.01).abs() < 1e-9);
        assert!(power(10.0, c) < power(50.0, c));
        assert!(power(100.0, c) > 0.99);
    }
}
