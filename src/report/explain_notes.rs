//! The lines `explain` adds to its summary and prints around a run: candidates already in the
//! baseline, the known GNSS values applied, and the embedded demo's description and its
//! estimates against the hidden truth.

use crate::explain::{sig3, Explanation};
use crate::model::generated::common;

/// Puts a line first in `e`'s summary for each candidate in `skipped` the baseline already
/// holds (the last named first, as each goes before the others).
pub fn note_skipped(e: &mut Explanation, skipped: &[String]) {
    for s in skipped {
        e.summary.insert(
            0,
            format!(
                "Candidate {s} is already in the baseline {}; skipped.",
                e.baseline_model
            ),
        );
    }
}

/// The summary line on the known GNSS values (`--gnss-delay`, `--lever-arm`) applied in every
/// pass, from (term index, value in SI units); None without any.
pub fn known_gnss(known: &[(usize, f64)]) -> Option<String> {
    if known.is_empty() {
        return None;
    }
    let known: Vec<String> = known
        .iter()
        .map(|&(t, v)| {
            let info = &common::TERMS[t];
            format!(
                "{} = {} {}",
                info.name,
                sig3(v / info.display_to_si),
                info.display
            )
        })
        .collect();
    // a time offset is refitted in all (the fixes re-stamped), so its finding is said in all
    let offset = if known.iter().any(|k| k.starts_with("dt_gnss ")) {
        " (a time offset refitted on re-stamped fixes is said in all, the given one included)"
    } else {
        ""
    };
    Some(format!(
        "Known aiding values applied in every pass (--gnss-delay, --lever-arm, --mounting): {}; a GNSS or reference finding is what the data show on top of them{offset}.",
        known.join(", ")
    ))
}

/// The demo's d estimates against the hidden 490 ug/g² [%], with their 1-σ [%]: what the demo
/// prints after its run.
pub fn demo_against_truth(e: &Explanation) -> String {
    // a d value (ug/g^2) and its σ against the hidden 490, in percent
    let held = |term: &str, estimate: f64, sigma: f64| {
        format!(
            "{term} {:+.2} % (± {:.2} %)",
            (estimate / 490.0 - 1.0) * 100.0,
            sigma / 490.0 * 100.0
        )
    };
    let against: Vec<String> = e
        .findings
        .iter()
        .filter(|f| f.term.starts_with("d_") && f.unit == "ug/g^2" && f.estimate.is_finite())
        .map(|f| held(&f.term, f.estimate, f.sigma))
        .collect();
    if against.is_empty() {
        // withheld, a d term may still be named as what a finding's term stands for
        let mut alike: Vec<String> = Vec::new();
        for w in e.findings.iter().flat_map(|f| &f.withheld_alike) {
            let line = held(&w.term, w.estimate, w.sigma);
            if w.term.starts_with("d_") && w.unit == "ug/g^2" && !alike.contains(&line) {
                alike.push(line);
            }
        }
        if !alike.is_empty() {
            return format!(
                "(hidden truth: d = 490 ug/g^2 on every axis; no d_ term was a finding, but the findings name d terms outside the candidates that would explain as well, at {} against it)",
                alike.join(", ")
            );
        }
        return "(hidden truth: d = 490 ug/g^2 on every axis; no d_ term was found, so there is no estimate to hold against it)".to_string();
    }
    format!(
        "(hidden truth: d = 490 ug/g^2 on every axis; the estimates read {} against it; 0.7 % of that is expected: the regressor f^2 is formed from 2 kHz increments, which average the 90 Hz sine, sinc^2 = 0.993)",
        against.join(", ")
    )
}

/// The demo's data in the report's words: `seconds` [s] simulated with `seed`.
pub fn demo_description(seconds: f64, seed: u64) -> String {
    format!(
        "embedded demo: {:.0} s simulated, the paper's 6 g / 3 g 90 Hz vibration on N, E, D (on/off windows), 2 kHz, \
         d_x = d_y = d_z = 5e-5 s^2/m (490 ug/g^2) hidden, seed {}",
        seconds, seed
    )
}
