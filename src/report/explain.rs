//! What `explain` writes: the JSON of DESIGN §9 (with added fields), the Markdown report and
//! the `presets.toml` entry of the extended model. Figures and the HTML page are made by the
//! command line (they need the plotting backend).

use crate::explain::{sig3, Explanation};
use serde_json::{json, Value};

/// The explain JSON (DESIGN §9 names; fields are added, never renamed). Non-finite numbers
/// become `null`.
pub fn json(e: &Explanation, extended_names: &[String], data: &str) -> Value {
    let pass = |p: &crate::explain::PassStats| {
        json!({
            "model": p.model,
            "loglik": p.loglik,
            "nis_mean": p.nis_mean,
            "whiteness_p": p.whiteness_p,
            "channels": p.channels,
            "model_error_rms_arcsec": p.model_error_rms_arcsec,
            "truth_check": p.truth_check,
        })
    };
    let mut extended = pass(&e.extended);
    extended["terms"] = json!(extended_names);
    // what the extended model leaves: channels still correlated in time or biased somewhere
    extended["residual_structure"] = json!(e.extended.structure());
    let mut gain = json!({
        "loglik": e.gain.loglik,
        "nis_mean_before": e.gain.nis_mean_before,
        "nis_mean_after": e.gain.nis_mean_after,
    });
    if let (Some(b), Some(a)) = (e.gain.model_error_rms_before, e.gain.model_error_rms_after) {
        gain["model_error_rms_before"] = json!(b);
        gain["model_error_rms_after"] = json!(a);
        gain["model_error_unit"] = json!("arcsec");
    }
    if let Some(u) = e.misfit_unexplained {
        gain["misfit_unexplained"] = json!(u);
    }
    json!({
        "written_by": "sinsmodel explain",
        "data": data,
        "model": e.model,
        "baseline": pass(&e.baseline),
        "findings": e.findings,
        "extended": extended,
        "gain": gain,
        "candidates": e.candidates,
        "not_testable": e.not_testable,
        "implausible": e.implausible,
        "unconfirmed": e.unconfirmed
            .iter()
            .map(|(t, g, p)| json!({"term": t, "two_delta_loglik": g, "bic_penalty": p}))
            .collect::<Vec<_>>(),
        "not_separable": e.not_separable
            .iter()
            .map(|(c, b)| json!({"term": c, "like": b}))
            .collect::<Vec<_>>(),
        "baseline_priors_tight": e.baseline_priors_tight,
        "baseline_priors_widened": e.baseline_priors_widened,
        "baseline_priors_gain": e.baseline_priors_gain,
        "alpha": e.alpha,
        "rounds": e.rounds,
        "summary": e.summary,
    })
}

/// The `presets.toml` entry that makes the extended model a compiled preset (`None` when
/// nothing was found).
pub fn extended_preset(e: &Explanation) -> Option<String> {
    // a finding that probably stands in for something else is no term to compile in
    // nor is a noise level (it is a --noise value or an aiding σ, not a state)
    let causes: Vec<&crate::explain::Finding> = e
        .findings
        .iter()
        .filter(|f| f.is_cause() && f.kind != "noise")
        .collect();
    if causes.is_empty() {
        return None;
    }
    let mut parts = e.baseline_model.split('+');
    let base = parts.next().unwrap_or("P28");
    let mut vertical = false;
    let mut terms: Vec<String> = Vec::new();
    for p in parts {
        if p == "vertical" {
            vertical = true;
        } else {
            terms.push(p.to_string());
        }
    }
    terms.extend(causes.iter().map(|f| f.term.clone()));
    let list: Vec<String> = terms.iter().map(|t| format!("\"{t}\"")).collect();
    let mut s = format!(
        "# The extended model explain found, as a compiled preset: append to model-spec/presets.toml\n\
         # and rebuild; then `--model {base}_explained{}`.\n",
        if vertical { "+vertical" } else { "" }
    );
    for f in e.findings.iter().filter(|f| f.stand_in.is_some()) {
        s.push_str(&format!(
            "# {} is left out: it probably stands in for an effect the candidates do not describe.\n",
            f.term
        ));
    }
    for f in e.findings.iter().filter(|f| f.not_attributed.is_some()) {
        s.push_str(&format!(
            "# {} is left out: the data cannot tell it from {} and the priors would choose.\n",
            f.term,
            f.equivalent.join(", ")
        ));
    }
    for f in e.findings.iter().filter(|f| f.kind == "noise") {
        s.push_str(&format!(
            "# noise, not a term: {} = {} {} ({}× the stated; give it with --noise or the aiding's σ).\n",
            f.term,
            sig3(f.estimate),
            f.unit,
            f.scale.map(sig3).unwrap_or_default()
        ));
    }
    if e.findings
        .iter()
        .any(|f| !f.is_cause() || f.kind == "noise")
    {
        s.push_str(&format!(
            "# the extended pass explain reports ({}) also held the lines above.\n",
            e.extended_model
        ));
    }
    for f in causes.iter().filter(|f| f.prior_widened) {
        s.push_str(&format!(
            "# {} lies beyond its spec prior σ; run the filter with --prior '{}={} {}'.\n",
            f.term,
            f.term,
            sig3(f.prior_sigma),
            f.unit
        ));
    }
    s.push_str(&format!(
        "[[preset]]\nname = \"{base}_explained\"\ndoc = \"{} extended with {} (found by sinsmodel explain)\"\nbase = \"{base}\"\nterms = [{}]\n",
        e.baseline_model,
        causes
            .iter()
            .map(|f| f.term.as_str())
            .collect::<Vec<_>>()
            .join(", "),
        list.join(", ")
    ));
    Some(s)
}

fn num(v: f64) -> String {
    if v.is_finite() {
        sig3(v)
    } else {
        "—".into()
    }
}

/// The Markdown report; `figures` are (file name, caption) pairs beside it.
pub fn markdown(e: &Explanation, data: &str, figures: &[(String, String)]) -> String {
    let mut s = String::new();
    s.push_str(&format!(
        "# sinsmodel explain: {}\n\nData: {data}\n\n",
        e.baseline_model
    ));
    s.push_str("## In words\n\n");
    for line in &e.summary {
        s.push_str(&format!("- {line}\n"));
    }
    baseline_section(e, &mut s);
    candidates_section(e, &mut s);
    findings_section(e, &mut s);
    gain_section(e, &mut s);
    notes_section(&mut s);
    if !figures.is_empty() {
        s.push_str("\n## Figures\n\n");
        for (file, caption) in figures {
            s.push_str(&format!("![{caption}]({file})\n\n*{caption}*\n\n"));
        }
    }
    s
}

/// Section 1 of the Markdown report: the baseline's fit, channel by channel, and against truth.
fn baseline_section(e: &Explanation, s: &mut String) {
    s.push_str("\n## 1. What the baseline gets wrong\n\n");
    s.push_str(&format!(
        "Baseline {}: log-likelihood {}, mean NIS {} (1 when consistent), whiteness p {} \
         (smallest over channels, Bonferroni-corrected).\n\n",
        e.baseline.model,
        num(e.baseline.loglik),
        num(e.baseline.nis_mean),
        num(e.baseline.whiteness_p)
    ));
    s.push_str("| channel | innovations | mean NIS | 95 % band | outside 95 % | Ljung–Box p | worst segment |\n|---|---|---|---|---|---|---|\n");
    for c in &e.baseline.channels {
        let worst = c
            .segments
            .iter()
            .max_by(|a, b| a.nis_mean.total_cmp(&b.nis_mean))
            .map(|sg| {
                format!(
                    "{:.0}–{:.0} s: NIS {}, bias {:+.1}σ",
                    sg.t0,
                    sg.t1,
                    num(sg.nis_mean),
                    sg.bias_sigma
                )
            })
            .unwrap_or_default();
        s.push_str(&format!(
            "| {} | {} | {} | {}–{} | {:.1} % | {} | {} |\n",
            c.channel,
            c.count,
            num(c.nis_mean),
            num(c.nis_band[0]),
            num(c.nis_band[1]),
            100.0 * c.fraction_outside_95,
            c.whiteness_p.map(num).unwrap_or_else(|| "—".into()),
            worst
        ));
    }
    if !e.baseline.truth_check.is_empty() {
        s.push_str("\nWith truth, the filter's predicted σ against its actual error (RMS over the run):\n\n| state | predicted σ | actual error | unit |\n|---|---|---|---|\n");
        for t in &e.baseline.truth_check {
            s.push_str(&format!(
                "| {} | {} | {} | {} |\n",
                t.state,
                num(t.predicted_sigma_rms),
                num(t.actual_error_rms),
                t.unit
            ));
        }
    }
}

/// Section 2 of the Markdown report: the table of candidates, each tested alone.
fn candidates_section(e: &Explanation, s: &mut String) {
    s.push_str(&format!(
        "\n## 2. Candidates (baseline pass, each alone; α = {} family-wise, Holm)\n\n\
         | term | group | llr | p (Holm) | GLR estimate | σ | unit | note |\n|---|---|---|---|---|---|---|---|\n",
        e.alpha
    ));
    for c in &e.candidates {
        let note = if !c.testable {
            "not testable (no information)".to_string()
        } else if let Some(b) = &c.confounded_with {
            format!("not separable from {b}")
        } else {
            String::new()
        };
        if c.testable {
            s.push_str(&format!(
                "| {} | {} | {:.1} | {} | {} | {} | {} | {} |\n",
                c.term,
                c.group,
                c.llr,
                num(c.p_holm),
                num(c.glr_estimate),
                num(c.glr_sigma),
                c.unit,
                note
            ));
        } else {
            s.push_str(&format!(
                "| {} | {} | — | — | — | — | {} | {} |\n",
                c.term, c.group, c.unit, note
            ));
        }
    }
}

/// Section 3 of the Markdown report: the findings and the extended model.
fn findings_section(e: &Explanation, s: &mut String) {
    s.push_str("\n## 3. Findings and the extended model\n\n");
    if e.findings.is_empty() {
        s.push_str("Nothing is significant; the model stays as it is.\n");
    }
    for f in &e.findings {
        s.push_str(&format!(
            "- {}**{}** = {} ± {} {} (llr {:.1}, p {}; pass {}). {}\n",
            if f.stand_in.is_some() {
                "*fitted, not a cause:* "
            } else if f.not_attributed.is_some() {
                "*fitted, not attributed:* "
            } else {
                ""
            },
            f.term,
            num(f.estimate),
            num(f.sigma),
            f.unit,
            f.llr,
            num(f.p_value),
            f.round,
            f.words
        ));
    }
    s.push_str(&format!("\nExtended model: `{}`", e.extended_model));
    if extended_preset(e).is_some() {
        s.push_str(" (its `presets.toml` entry is in `extended.toml`)");
    }
    s.push_str(".\n");
}

/// Section 4 of the Markdown report: the gain of the extended model over the baseline.
fn gain_section(e: &Explanation, s: &mut String) {
    s.push_str("\n## 4. Gain\n\n| | baseline | extended |\n|---|---|---|\n");
    s.push_str(&format!(
        "| log-likelihood | {} | {} |\n| mean NIS | {} | {} |\n| whiteness p | {} | {} |\n",
        num(e.baseline.loglik),
        num(e.extended.loglik),
        num(e.baseline.nis_mean),
        num(e.extended.nis_mean),
        num(e.baseline.whiteness_p),
        num(e.extended.whiteness_p)
    ));
    if let (Some(b), Some(a)) = (e.gain.model_error_rms_before, e.gain.model_error_rms_after) {
        s.push_str(&format!(
            "| model error φ̂ − φ, RMS √(n² + e²) over the second half [arcsec] | {} | {} |\n",
            num(b),
            num(a)
        ));
    }
}

/// The Markdown report's notes on how to read the tests and the words it uses.
fn notes_section(s: &mut String) {
    s.push_str(
        "\nThe candidate tests are quasi-likelihood tests: when the baseline's innovations are \
         larger than predicted (mean NIS φ > 1), information and score are divided by φ. A term \
         is named only when its value is within 100 prior σ (`--prior` sets the sensor class) \
         and the filter with it confirms the gain the signatures predicted (2Δ log-likelihood \
         above the BIC penalty k ln N).\n",
    );
    s.push_str(
        "\n**Not testable** means the data carry no information on the term (its regressor is \
         zero or its signature never reaches the innovations): explain cannot say whether it is \
         there. **Not separable from a baseline term** means its regressor is proportional to \
         that term's on these data, so the baseline state already takes it up. An \
         **equivalence class** is a set of candidates the data cannot tell apart (signatures \
         correlated at |ρ| > 0.9 and likelihoods within the α-level margin); explain names the \
         member the spec's priors find most plausible and says which excitation would separate \
         them.\n",
    );
}

/// Standard base64 (RFC 4648, with padding), for figures embedded in the HTML report.
pub fn base64(bytes: &[u8]) -> String {
    const A: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for chunk in bytes.chunks(3) {
        let b = [
            chunk[0],
            *chunk.get(1).unwrap_or(&0),
            *chunk.get(2).unwrap_or(&0),
        ];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for k in 0..4 {
            if k <= chunk.len() {
                out.push(A[((n >> (18 - 6 * k)) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

fn html_escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

/// A self-contained HTML page of the Markdown report: the text preformatted (tables stay
/// legible), figures embedded as base64 PNGs (`figures`: caption and PNG bytes).
pub fn html(title: &str, markdown: &str, figures: &[(String, Vec<u8>)]) -> String {
    let mut s = format!(
        "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>{}</title>\
         <style>body{{font-family:sans-serif;max-width:1100px;margin:2em auto}}\
         pre{{white-space:pre-wrap;font-size:14px}}img{{max-width:100%}}</style></head><body>\n",
        html_escape(title)
    );
    let text: String = markdown
        .lines()
        .filter(|l| !l.starts_with("!["))
        .collect::<Vec<_>>()
        .join("\n");
    s.push_str(&format!("<pre>{}</pre>\n", html_escape(&text)));
    for (caption, png) in figures {
        s.push_str(&format!(
            "<figure><img alt=\"{0}\" src=\"data:image/png;base64,{1}\"><figcaption>{0}</figcaption></figure>\n",
            html_escape(caption),
            base64(png)
        ));
    }
    s.push_str("</body></html>\n");
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_matches_rfc4648_vectors() {
        let cases = [
            ("", ""),
            ("f", "Zg=="),
            ("fo", "Zm8="),
            ("foo", "Zm9v"),
            ("foob", "Zm9vYg=="),
            ("fooba", "Zm9vYmE="),
            ("foobar", "Zm9vYmFy"),
        ];
        for (i, o) in cases {
            assert_eq!(base64(i.as_bytes()), o);
        }
    }
}
