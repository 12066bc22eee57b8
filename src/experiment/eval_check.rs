//! A stored case of explain's evaluation (an entry of `explain-eval`'s `cases.json`) checked like
//! any input before `--merge` uses it: what the campaign draws for its index (group, hidden term,
//! λ) is drawn again and compared, and the outcome must be one a run can produce (finite values,
//! σ > 0, a truth ≠ 0, flags that agree with what was named, names of the library). And the indices of merged
//! shards must leave no gap.

use crate::experiment::explain_eval::{draw, CaseResult, EvalSpec};
use crate::model::generated::common;
use crate::sim::hidden::all_groups;

/// Noise levels explain names, besides `sigma_<measurement>`.
const NOISE_LEVELS: [&str; 4] = ["gyro_arw", "accel_vrw", "gyro_bias_rw", "accel_bias_rw"];

/// Why the stored case `c` cannot be one the campaign `spec` produced (the field and what is
/// wrong with it), or Ok.
pub fn check_case(spec: &EvalSpec, c: &CaseResult) -> Result<(), String> {
    check_draw(spec, c)?;
    check_outcome(c)?;
    check_numbers(c)
}

/// Most wall time one case may take [s] (a day): beyond it a stored time is no measurement.
const MAX_CASE_SECONDS: f64 = 86_400.0;

/// The groups of `--groups`: `all`, or a list of known group names, each once. Err says which
/// entry is wrong and why.
pub fn parse_groups(given: &[String]) -> Result<Vec<String>, String> {
    let known = all_groups();
    if given.is_empty() {
        return Err("the list is empty".into());
    }
    if given.iter().any(|g| g == "all") {
        if given.len() > 1 {
            return Err(
                "`all` stands alone: it is every group; give it or a list of groups".into(),
            );
        }
        return Ok(known.iter().map(|s| s.to_string()).collect());
    }
    for (k, x) in given.iter().enumerate() {
        if x.is_empty() {
            return Err(format!(
                "entry {} of {} is empty (a doubled or trailing comma?)",
                k + 1,
                given.len()
            ));
        }
        if !known.contains(&x.as_str()) {
            let hint = if x.trim() != x {
                " (no spaces around the commas)"
            } else if known.contains(&x.to_ascii_lowercase().as_str()) {
                " (names are lower-case)"
            } else {
                ""
            };
            return Err(format!(
                "unknown group `{x}`{hint} (groups: {}; or `all`)",
                known.join(", ")
            ));
        }
        if given[..k].contains(x) {
            return Err(format!("`{x}` is given twice"));
        }
    }
    Ok(given.to_vec())
}

/// Why stored campaign settings `sp` cannot be ones explain-eval writes, or Ok.
pub fn check_spec(sp: &EvalSpec) -> Result<(), String> {
    let d = EvalSpec::default();
    if sp.seed > 1_000_000_000_000 {
        return Err(format!("seed {}: a run's seed is 0 to 1e12", sp.seed));
    }
    if !(sp.seconds.is_finite() && (300.0..=7200.0).contains(&sp.seconds)) {
        return Err(format!("seconds {}: a run takes 300 to 7200 s", sp.seconds));
    }
    if sp.null_fraction != d.null_fraction || sp.lambda != d.lambda {
        return Err(format!(
            "null_fraction {} and lambda {:?}: every run draws a fraction {} of null cases and λ over {:?}",
            sp.null_fraction, sp.lambda, d.null_fraction, d.lambda
        ));
    }
    if !(sp.alpha.is_finite() && (1e-12..=0.5).contains(&sp.alpha)) {
        return Err(format!("alpha {}: a run's α is in [1e-12, 0.5]", sp.alpha));
    }
    parse_groups(&sp.groups)
        .map(|_| ())
        .map_err(|e| format!("groups: {e}"))
}

/// Which settings of campaign `b` differ from `a`'s, with both values; None when none does.
pub fn spec_differs(a: &EvalSpec, b: &EvalSpec) -> Option<String> {
    let mut d = Vec::new();
    if a.seed != b.seed {
        d.push(format!("seed {} against {}", b.seed, a.seed));
    }
    if a.groups != b.groups {
        d.push(format!(
            "groups {} against {}",
            b.groups.join(","),
            a.groups.join(",")
        ));
    }
    if a.seconds != b.seconds {
        d.push(format!("seconds {} against {}", b.seconds, a.seconds));
    }
    if a.alpha != b.alpha {
        d.push(format!("alpha {} against {}", b.alpha, a.alpha));
    }
    if a.null_fraction != b.null_fraction || a.lambda != b.lambda {
        d.push("null fraction or λ range".into());
    }
    (!d.is_empty()).then(|| d.join(", "))
}

fn is_term(name: &str) -> bool {
    common::TERMS.iter().any(|t| t.name == name)
}

fn shown(term: Option<&str>) -> String {
    term.map(|t| format!("`{t}`"))
        .unwrap_or_else(|| "none (a null case)".into())
}

/// The group, term and λ against what the campaign draws for the case's index.
fn check_draw(spec: &EvalSpec, c: &CaseResult) -> Result<(), String> {
    // a run's cases start at --first ≤ 1e9 and number at most 100000
    if c.index >= 1_000_100_000 {
        return Err(format!(
            "index {}: a run's cases lie below 1000100000 (--first ≤ 1e9, --cases ≤ 100000)",
            c.index
        ));
    }
    if c.group != "null" && !spec.groups.contains(&c.group) {
        return Err(format!(
            "group `{}` is neither `null` nor one of the campaign's groups ({})",
            c.group,
            spec.groups.join(", ")
        ));
    }
    if let Some(t) = c.term.as_deref().filter(|t| !is_term(t)) {
        return Err(format!(
            "term `{t}` is not a term of the model spec's library"
        ));
    }
    let d = draw(spec, c.index).map_err(|e| e.to_string())?;
    let (i, seed) = (c.index, spec.seed);
    if c.group != d.case.group {
        return Err(format!(
            "group `{}`: case {i} of seed {seed} draws `{}`",
            c.group, d.case.group
        ));
    }
    let want = d.case.hidden.first().map(|h| h.0.as_str());
    if c.term.as_deref() != want {
        return Err(format!(
            "term {}: case {i} of seed {seed} hides {}",
            shown(c.term.as_deref()),
            shown(want)
        ));
    }
    let also: Vec<&str> = d.case.hidden.iter().skip(1).map(|h| h.0.as_str()).collect();
    if c.also_hidden != also {
        return Err(format!(
            "also_hidden [{}]: case {i} of seed {seed} hides [{}] beside its first term",
            c.also_hidden.join(", "),
            also.join(", ")
        ));
    }
    let misstated: Vec<&str> = d.case.noise_ratio.iter().map(|n| n.0.as_str()).collect();
    if c.noise_misstated != misstated {
        return Err(format!(
            "noise_misstated [{}]: case {i} of seed {seed} states [{}] wrongly",
            c.noise_misstated.join(", "),
            misstated.join(", ")
        ));
    }
    // the truth's size comes from the simulation (λ over the signature's information), its
    // sign from the draw
    if let (Some(v), Some((_, reference))) = (c.truth, d.case.hidden.first()) {
        if v != 0.0 && v.signum() != reference.signum() {
            return Err(format!(
                "truth {v}: case {i} of seed {seed} puts its term in with the {} sign",
                if *reference > 0.0 {
                    "positive"
                } else {
                    "negative"
                }
            ));
        }
    }
    let [lo, hi] = spec.lambda;
    match (c.lambda, d.lambda) {
        (None, None) => Ok(()),
        (Some(l), _) if !(l.is_finite() && l > 0.0) => Err(format!(
            "lambda {l}: a noncentrality λ = θ² I is finite and > 0"
        )),
        (Some(l), _) if l < lo * (1.0 - 1e-9) || l > hi * (1.0 + 1e-9) => Err(format!(
            "lambda {l}: outside the campaign's range [{lo}, {hi}] it is drawn from"
        )),
        (Some(l), Some(e)) if (l - e).abs() > 1e-9 * e => {
            Err(format!("lambda {l}: case {i} of seed {seed} draws λ = {e}"))
        }
        (Some(_), Some(_)) => Ok(()),
        (Some(l), None) => Err(format!("lambda {l}: a null case has none")),
        (None, Some(e)) => Err(format!(
            "lambda is missing: case {i} of seed {seed} hides its term at λ = {e}"
        )),
    }
}

/// The truth, estimate and σ, the names, and the flags against what was named.
fn check_outcome(c: &CaseResult) -> Result<(), String> {
    let null = c.term.is_none();
    match c.truth {
        Some(_) if null => return Err("truth: a null case hides nothing".into()),
        None if !null => return Err("truth is missing for a hidden term".into()),
        Some(v) if !v.is_finite() || v == 0.0 => {
            return Err(format!(
                "truth {v}: a hidden term is put in at λ > 0, so its true value is finite and never 0 (the coefficient error divides by it)"
            ))
        }
        _ => {}
    }
    match (c.estimate, c.sigma) {
        (None, None) => {}
        (Some(_), Some(_)) if null => {
            return Err("estimate: a null case has no hidden term to estimate".into())
        }
        (Some(e), Some(s)) => {
            if !e.is_finite() {
                return Err(format!("estimate {e}: not finite"));
            }
            if !(s.is_finite() && s > 0.0) {
                return Err(format!("sigma {s}: a standard deviation is finite and > 0"));
            }
        }
        _ => return Err("estimate and sigma: one is given without the other".into()),
    }
    if let Some((k, n)) = c
        .named
        .iter()
        .enumerate()
        .find(|(k, n)| c.named[..*k].contains(n))
    {
        return Err(format!(
            "named: `{n}` is there twice (entries {} and {}): a run names a term once",
            c.named[..k].iter().position(|x| x == n).unwrap_or(0) + 1,
            k + 1
        ));
    }
    if !c.named.is_empty() && c.candidates_tested == 0 {
        return Err(format!(
            "candidates_tested 0, yet named holds {}: a named term is a tested candidate",
            c.named.join(", ")
        ));
    }
    if let Some(n) = c.stand_ins.iter().find(|n| !is_term(n)) {
        return Err(format!(
            "stand_ins: `{n}` is not a term of the model spec's library"
        ));
    }
    if let Some(n) = c.stand_ins.iter().find(|n| c.named.contains(n)) {
        return Err(format!(
            "stand_ins: `{n}` is also among named (a finding is a claim or a stand-in, not both)"
        ));
    }
    for (field, list) in [
        ("stand_ins", &c.stand_ins),
        ("noise_named", &c.noise_named),
        ("noise_stand_ins", &c.noise_stand_ins),
        ("also_hidden", &c.also_hidden),
    ] {
        if let Some((k, n)) = list
            .iter()
            .enumerate()
            .find(|(k, n)| list[..*k].contains(n))
        {
            return Err(format!(
                "{field}: `{n}` is there twice (entry {}): a run lists it once",
                k + 1
            ));
        }
    }
    if let Some(n) = c.named.iter().find(|n| !is_term(n)) {
        return Err(format!(
            "named: `{n}` is not a term of the model spec's library"
        ));
    }
    let level = |n: &str| NOISE_LEVELS.contains(&n) || n.len() > 6 && n.starts_with("sigma_");
    if let Some(n) = c.noise_named.iter().find(|n| !level(n)) {
        return Err(format!(
            "noise_named: `{n}` is not a noise level explain names ({}, sigma_<measurement>)",
            NOISE_LEVELS.join(", ")
        ));
    }
    if let Some(n) = c
        .noise_stand_ins
        .iter()
        .find(|n| !c.noise_named.contains(n))
    {
        return Err(format!("noise_stand_ins: `{n}` is not among noise_named"));
    }
    check_flags(c)
}

/// `detected` and `wrong_term` against `named`, as a run sets them.
fn check_flags(c: &CaseResult) -> Result<(), String> {
    let (d, w, nothing) = (c.detected, c.wrong_term, c.named.is_empty());
    let named = c.named.join(", ");
    let hidden: Vec<&str> = c
        .term
        .iter()
        .chain(&c.also_hidden)
        .map(String::as_str)
        .collect();
    let why = match c.term.as_deref() {
        None if d => "detected = true in a null case (nothing is hidden)".to_string(),
        None if w == nothing => format!(
            "wrong_term = {w} in a null case that named {}: there every named term is a wrong one",
            if nothing { "nothing" } else { &named }
        ),
        _ if d && nothing => "detected = true, yet named is empty (nothing was named)".into(),
        _ if w && nothing => format!(
            "wrong_term = true with detected = {d}, yet named is empty: a wrong term is a named one"
        ),
        Some(t) if !d && hidden.iter().all(|h| c.named.iter().any(|n| n == h)) => {
            format!("detected = false, yet named holds the hidden term `{t}` and any beside it")
        }
        Some(t) if w && c.named.iter().all(|n| hidden.contains(&n.as_str())) => format!(
            "wrong_term = true, yet named holds only the hidden term `{t}` or those beside it: a wrong term is another one"
        ),
        Some(_) if !d && !w && !nothing && hidden.len() == 1 => format!(
            "detected = false and wrong_term = false, yet named holds {named}: a named term is the hidden one (detected) or not (a wrong term)"
        ),
        _ => return Ok(()),
    };
    Err(why)
}

/// Gain recovery, candidates tested and the case's time.
fn check_numbers(c: &CaseResult) -> Result<(), String> {
    // (a gain recovery has no bound but finiteness: the log-likelihood ratio over an oracle
    // gain just above 10 reaches 65 in real cases, and a worse fit makes either ratio negative)
    if let Some(g) = c.gain_recovery.filter(|g| !g.is_finite()) {
        return Err(format!("gain_recovery {g}: not finite"));
    }
    if c.candidates_tested > common::TERM_COUNT {
        return Err(format!(
            "candidates_tested {}: more than the {} terms of the library",
            c.candidates_tested,
            common::TERM_COUNT
        ));
    }
    for (field, v) in [
        ("seconds_taken", c.seconds_taken),
        ("seconds_taken_setup", c.seconds_taken_setup),
        ("seconds_taken_explain", c.seconds_taken_explain),
    ] {
        if !(v.is_finite() && (0.0..=MAX_CASE_SECONDS).contains(&v)) {
            return Err(format!(
                "{field} {v}: a case's time is finite, ≥ 0 and at most a day ({MAX_CASE_SECONDS} s)"
            ));
        }
    }
    if c.seconds_taken_setup + c.seconds_taken_explain > c.seconds_taken * (1.0 + 1e-9) + 1e-6 {
        return Err(format!(
            "seconds_taken_setup {} and seconds_taken_explain {} add up to more than seconds_taken {}",
            c.seconds_taken_setup, c.seconds_taken_explain, c.seconds_taken
        ));
    }
    Ok(())
}

/// The runs of indices missing between the smallest and the largest of `sorted` (ascending):
/// (first, last) of each gap.
pub fn missing_ranges(sorted: &[usize]) -> Vec<(usize, usize)> {
    sorted
        .windows(2)
        .filter(|w| w[1] > w[0] + 1)
        .map(|w| (w[0] + 1, w[1] - 1))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gaps_between_indices() {
        assert_eq!(missing_ranges(&[0, 1, 5, 6, 8]), vec![(2, 4), (7, 7)]);
        assert!(missing_ranges(&[100, 101, 102]).is_empty());
        assert!(missing_ranges(&[]).is_empty());
    }
}
