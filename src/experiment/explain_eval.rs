//! How well `explain` finds hidden effects: seeded cases from the hidden-effect generator
//! ([`crate::sim::hidden`]) with magnitudes drawn by their noncentrality λ = θ² I (log-uniform),
//! detection, false alarms, coefficient error, calibration and gain, and the power curve
//! against theory. Each case depends only on (seed, index), so any split of the indices over
//! threads or machines gives the same cases; [`summarize`] of merged case lists equals one run.

use crate::estimate::filter::FilterConfig;
use crate::estimate::stats;
use crate::experiment::hidden::{inject, run_hidden_on, simulate_case};
use crate::explain::{self, signature_information, ExplainData, ExplainOptions};
use crate::model::generated::common;
use crate::model::Model;
use crate::sim::hidden::{clear_effect, generate, CaseKind, GROUPS};
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

/// One case's outcome.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct CaseResult {
    /// Index of the case in the campaign.
    pub index: usize,
    /// `null` or the library group.
    pub group: String,
    /// Hidden term (None for a null case).
    pub term: Option<String>,
    /// True value (display unit of the term).
    pub truth: Option<f64>,
    /// Noncentrality λ = θ² I of the hidden term's test through the baseline filter.
    pub lambda: Option<f64>,
    /// Terms explain named (sensor and measurement findings).
    pub named: Vec<String>,
    /// Noise levels explain named (noise findings: a claim about the data's noise, not a term).
    #[serde(default)]
    pub noise_named: Vec<String>,
    /// Of those, the ones it labelled "not one level across the data" (stand-ins).
    #[serde(default)]
    pub noise_stand_ins: Vec<String>,
    /// The hidden term was named or is in a named class.
    pub detected: bool,
    /// A named term is neither the hidden one nor in a class with it (or anything in a null case).
    pub wrong_term: bool,
    /// Estimate of the hidden term (display unit) and its σ, when detected.
    pub estimate: Option<f64>,
    /// σ of the estimate.
    pub sigma: Option<f64>,
    /// Fraction of the oracle's gain the extended model recovers, when defined.
    pub gain_recovery: Option<f64>,
    /// Number of candidates tested (testable and separable) in the baseline pass.
    pub candidates_tested: usize,
    /// Wall time of the case [s] (not part of the comparison of runs).
    #[serde(default)]
    pub seconds_taken: f64,
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
        let g = GROUPS
            .iter()
            .find(|g| **g == spec.groups[k])
            .ok_or_else(|| anyhow::anyhow!("unknown group `{}`", spec.groups[k]))?;
        CaseKind::One(g)
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
    let t_start = std::time::Instant::now();
    let Drawn {
        case: drawn,
        lambda: drawn_lambda,
    } = draw(spec, index)?;
    // simulate without the hidden term, then put it in at the drawn λ
    let mut case = drawn.scaled(0.0);
    let (mut sim, aid) = simulate_case(&case)?;
    let mut opts = opts.clone();
    opts.alpha = spec.alpha;
    let (mut lambda, mut truth_si, mut term) = (None, None, None);
    if let Some((name, reference)) = drawn.hidden.first() {
        let t = common::TERMS
            .iter()
            .position(|x| x.name == name)
            .ok_or_else(|| anyhow::anyhow!("hidden term `{name}` is not a spec term"))?;
        let baseline = Model::parse(&case.baseline)?;
        let data = ExplainData {
            imu: crate::explain::ImuInput::Memory(&sim.imu),
            aid: &aid,
            truth: Some(&sim.truth),
            start: sim.start,
        };
        let info = signature_information(&baseline, t, &data, &FilterConfig::new(&baseline))?;
        let lam = drawn_lambda
            .ok_or_else(|| anyhow::anyhow!("case {index}: a hidden term drawn without its λ"))?;
        let theta = reference.signum() * (lam / info.max(f64::MIN_POSITIVE)).sqrt();
        inject(&mut sim.imu, sim.start.t, t, theta);
        case.hidden = vec![(name.clone(), theta)];
        lambda = Some(lam);
        truth_si = Some(theta);
        term = Some(t);
    }
    let out = run_hidden_on(&case, &sim, &aid, &opts)?;
    let e = &out.explanation;
    let named: Vec<String> = e
        .findings
        .iter()
        .filter(|f| f.kind != "noise")
        .map(|f| f.term.clone())
        .collect();
    let noise_named: Vec<String> = e
        .findings
        .iter()
        .filter(|f| f.kind == "noise")
        .map(|f| f.term.clone())
        .collect();
    let noise_stand_ins: Vec<String> = e
        .findings
        .iter()
        .filter(|f| f.kind == "noise" && f.stand_in.is_some())
        .map(|f| f.term.clone())
        .collect();
    let (mut detected, mut estimate, mut sigma) = (false, None, None);
    if let Some(t) = term {
        let name = common::TERMS[t].name;
        detected = out.found(name);
        for f in &e.findings {
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
    let wrong_term = e
        .findings
        .iter()
        .filter(|f| f.kind != "noise")
        .any(|f| match hidden_name {
            Some(h) => f.term != h && !f.equivalent.iter().any(|q| q == h),
            None => true,
        });
    Ok(CaseResult {
        index,
        group: drawn.group.clone(),
        term: hidden_name.map(str::to_string),
        truth: term
            .zip(truth_si)
            .map(|(t, v)| v / common::TERMS[t].display_to_si),
        lambda,
        named,
        noise_named,
        noise_stand_ins,
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
    })
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
    /// Theoretical detection at the bin's geometric centre: a χ²₁(λ) test at Holm's first
    /// threshold over the median number of candidates tested.
    pub theory: f64,
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
    /// Cases in which a noise level was named (the simulations state their noise correctly,
    /// except the heights of the truth-formed aiding, which carry none).
    #[serde(default)]
    pub noise_finding_rate: Option<f64>,
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
    /// Median candidates tested per case (the Holm count the theory uses).
    pub candidates_tested_median: f64,
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
    let c_thr = stats::chi2_isf(spec.alpha / m_med, 1.0);
    let edges = [10.0, 20.0, 50.0, 100.0, 200.0, 500.0, 1000.0];
    let power_curve = edges
        .windows(2)
        .map(|w| {
            let in_bin: Vec<&&CaseResult> = non_null
                .iter()
                .filter(|c| c.lambda.is_some_and(|l| l >= w[0] && l < w[1]))
                .collect();
            PowerBin {
                lambda_lo: w[0],
                lambda_hi: w[1],
                cases: in_bin.len(),
                detection_rate: rate(in_bin.iter().filter(|c| c.detected).count(), in_bin.len()),
                theory: power((w[0] * w[1]).sqrt(), c_thr),
            }
        })
        .collect();
    let mut by_group = std::collections::BTreeMap::new();
    for g in &spec.groups {
        let of: Vec<&&CaseResult> = non_null.iter().filter(|c| &c.group == g).collect();
        let of_hi: Vec<&&&CaseResult> = of
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
            },
        );
    }
    Summary {
        cases: cases.len(),
        seed: spec.seed,
        null_cases: nulls,
        detection_rate: rate(det, non_null.len()),
        detection_rate_lambda_50: rate(hi.iter().filter(|c| c.detected).count(), hi.len()),
        false_alarm_rate: rate(
            cases
                .iter()
                .filter(|c| c.term.is_none() && !c.named.is_empty())
                .count(),
            nulls,
        ),
        wrong_term_rate: rate(
            non_null.iter().filter(|c| c.wrong_term).count(),
            non_null.len(),
        ),
        noise_finding_rate: rate(
            cases.iter().filter(|c| !c.noise_named.is_empty()).count(),
            cases.len(),
        ),
        coef_error_median: quantile(&mut errs, 0.5),
        coef_error_p90: quantile(&mut errs, 0.9),
        calibration: rate(calib.iter().filter(|&&b| b).count(), calib.len()),
        gain_recovery_median: quantile(&mut gains, 0.5),
        by_group,
        power_curve,
        candidates_tested_median: m_med,
        alpha: spec.alpha,
    }
}

/// Re-exported for the command line: the default explain options.
pub fn default_options() -> ExplainOptions {
    explain::ExplainOptions::default()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn power_is_alpha_at_zero_and_grows() {
        let c = stats::chi2_isf(0.01, 1.0);
        assert!((power(0.0, c) - 0.01).abs() < 1e-9);
        assert!(power(10.0, c) < power(50.0, c));
        assert!(power(100.0, c) > 0.99);
    }
}
