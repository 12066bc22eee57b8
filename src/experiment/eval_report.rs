//! What `explain-eval` prints and writes in words: the headline, the statement of the test the
//! theory curve belongs to, and the Markdown report (`eval.md`) with the power curve overall
//! and per group, each rate with its 95 % confidence interval.

use crate::experiment::explain_eval::{PowerBin, Summary};

/// A rate as a percentage (— when nothing was measured, never `inf %`).
pub fn pct(v: Option<f64>) -> String {
    // (merged cases are checked, and what slips past is said as such)
    match v {
        Some(x) if x.is_finite() => format!("{:.1} %", 100.0 * x),
        Some(x) => format!("not finite ({x})"),
        None => "—".into(),
    }
}

/// A 95 % confidence interval as percentages, in brackets after a space (empty when none).
pub fn ci(v: Option<[f64; 2]>) -> String {
    match v {
        Some([lo, hi]) => format!(" [{:.1}–{:.1} %]", 100.0 * lo, 100.0 * hi),
        None => String::new(),
    }
}

/// The summary's headline lines (stderr and the report).
pub fn headline(s: &Summary) -> Vec<String> {
    let mut v = vec![
        format!(
            "detection {} (λ ≥ 50: {}{}), false alarms {}{} of {} null cases, wrong term {}{}, a noise level named in {} of the cases, one stated right named as a cause in {}{}",
            pct(s.detection_rate),
            pct(s.detection_rate_lambda_50),
            ci(s.detection_lambda_50_ci),
            pct(s.false_alarm_rate),
            ci(s.false_alarm_ci),
            s.null_cases,
            pct(s.wrong_term_rate),
            ci(s.wrong_term_ci),
            pct(s.noise_finding_rate),
            pct(s.noise_false_alarm_rate),
            ci(s.noise_false_alarm_ci)
        ),
        format!(
            "coefficient error median {} (90 %: {}), calibration (truth within ±2σ) {}{}, gain recovery median {}",
            pct(s.coef_error_median),
            pct(s.coef_error_p90),
            pct(s.calibration),
            ci(s.calibration_ci),
            pct(s.gain_recovery_median)
        ),
    ];
    if s.noise_cases > 0 {
        v.push(format!(
            "misstated noise: {} cases; in {} of them every misstated level was named as noise; a term was named in {} of those that hide no term",
            s.noise_cases,
            pct(s.noise_called_rate),
            pct(s.noise_only_term_named_rate)
        ));
    }
    v
}

/// The test the theory curve is the power of, in words.
pub fn test_statement(s: &Summary) -> String {
    format!(
        "The theory is the power of the test explain's selection starts with: for each candidate, \
         the likelihood-ratio statistic 2Δℓ of its coefficient through the baseline filter (the \
         score test, χ²₁ under the null), divided by the baseline's dispersion φ = max(1, mean \
         NIS) (quasi-likelihood), must exceed Holm's first threshold, the χ²₁ quantile \
         1 − α/m over the m candidates tested (α = {}; m is each case's own count, median {}), \
         and ln N (BIC, N innovations). A candidate that passes is kept only if the filter \
         confirms the extended model (its 2Δℓ with the prior's Occam term ln det(I + SJS) added \
         back above the χ²_k quantile 1 − α, times φ, for k added terms), its estimate holds \
         across the consistency splits and it is not a stand-in; those gates lower detection \
         below this curve, while the forward selection's later steps (conditional tests, Holm \
         over the candidates left) can pass a candidate the first test missed. A case's λ is \
         the noncentrality θ²I of its hidden term's test through the baseline filter; a case \
         that hides several terms counts as found only when every one is named, so its λ is \
         the weakest term's θ_i²/(J⁻¹)_ii, its information beside the others. Each bin's \
         theory is the test's power averaged over the bin's cases (their λ and m); an empty \
         bin's, and the plotted curve, are the power at the median m.",
        s.alpha, s.candidates_tested_median
    )
}

fn bins_table(m: &mut String, bins: &[PowerBin]) {
    m.push_str("| λ bin | cases | detected | 95 % interval | theory |\n|---|---|---|---|---|\n");
    for b in bins {
        m.push_str(&format!(
            "| {:.0}–{:.0} | {} | {} |{} | {:.1} % |\n",
            b.lambda_lo,
            b.lambda_hi,
            b.cases,
            pct(b.detection_rate),
            ci(b.detection_ci),
            100.0 * b.theory
        ));
    }
}

/// The Markdown report of `n` cases of `seconds` each.
pub fn markdown(s: &Summary, n: usize, seconds: f64) -> String {
    let mut m = format!(
        "# explain-eval: {n} cases of {seconds} s, seed {}\n\n",
        s.seed
    );
    for l in headline(s) {
        m.push_str(&format!("- {l}\n"));
    }
    m.push_str(&format!("\n{}\n\n", test_statement(s)));
    bins_table(&mut m, &s.power_curve);
    m.push_str(
        "\nPer group, the cases that hide a term (a misstated-noise case that hides none is a null case, counted above):\n\n| group | cases | detected | detected, λ ≥ 50 | per λ bin (detected/cases: 10–20, 20–50, 50–100, 100–200, 200–500, 500–1000) |\n|---|---|---|---|---|\n",
    );
    for (g, st) in &s.by_group {
        let per_bin: Vec<String> = st
            .power_curve
            .iter()
            .map(|b| {
                let hits = b
                    .detection_rate
                    .map_or(0, |r| (r * b.cases as f64).round() as usize);
                format!("{hits}/{}", b.cases)
            })
            .collect();
        m.push_str(&format!(
            "| {g} | {} | {} | {} | {} |\n",
            st.cases,
            pct(st.detection_rate),
            pct(st.detection_rate_lambda_50),
            per_bin.join(", ")
        ));
    }
    m.push_str("\n![power curve](power_curve.png)\n\n![power per group](power_by_group.png)\n");
    m
}
