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
    if let Some(u) = e.misfit_unexplained_by_causes() {
        gain["misfit_unexplained_by_causes"] = json!(u);
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
        "linearisation": e.linearisation,
        "closed_loop_instead": e.closed_loop_instead,
        "restamp": e.restamp,
        "unconfirmed": e.unconfirmed
            .iter()
            .map(|(t, g, p)| json!({"term": t, "two_delta_loglik_with_occam": g, "threshold": p}))
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
    let offset_cause = crate::explain::restamp::offset_cause(e).is_some();
    if let (Some(r), true) = (&e.restamp, offset_cause) {
        let shift = r.passes.last().map_or(0.0, |p| p.shift_ms);
        s.push_str(&format!(
            "# dt_gnss was fitted on the fixes re-stamped by {} ms (its first-order H falls short at\n\
             # this offset): run the model with --gnss-delay '{} ms'; its dt_gnss state holds what is left.\n",
            crate::explain::sig3(shift),
            crate::explain::sig3(shift)
        ));
    }
    for f in e.findings.iter().filter(|f| f.stand_in.is_some()) {
        s.push_str(&format!(
            "# {} is left out: it probably stands in for an effect the candidates do not describe.\n",
            f.term
        ));
    }
    for f in e.findings.iter().filter(|f| f.not_attributed.is_some()) {
        if !f.unnamed_because(crate::explain::Unnamed::ClassNotSeparable) {
            s.push_str(&format!(
                "# {} is left out: it is not attributed ({}).\n",
                f.term,
                f.not_attributed
                    .as_deref()
                    .unwrap_or_default()
                    .replace('\n', " ")
            ));
        } else {
            // (and the other rules that un-named it, in a few words each)
            let also: Vec<&str> = f
                .not_attributed_because
                .iter()
                .filter(|&&u| u != crate::explain::Unnamed::ClassNotSeparable)
                .map(|u| u.words().1)
                .collect();
            s.push_str(&format!(
                "# {} is left out: the data cannot tell it from {} and the priors would choose{}.\n",
                f.term,
                f.equivalent.join(", "),
                if also.is_empty() {
                    String::new()
                } else {
                    format!("; also, {}", also.join(", and "))
                }
            ));
        }
    }
    // (a noise level that stands in is left out above: no advice to state it)
    for f in e
        .findings
        .iter()
        .filter(|f| f.kind == "noise" && f.stand_in.is_none())
    {
        // a level at its search bound is no estimate: the bound, said as one
        let line = match f.scale_bound {
            Some(b) => format!(
                "# noise, not a term: {} {b} {} {} (at the search bound: the likelihood still rises beyond it; give a value there with --noise or the aiding's σ).\n",
                f.term,
                sig3(f.estimate),
                f.unit
            ),
            None => format!(
                "# noise, not a term: {} = {} {} ({}× the stated; give it with --noise or the aiding's σ).\n",
                f.term,
                sig3(f.estimate),
                f.unit,
                f.scale.map(sig3).unwrap_or_default()
            ),
        };
        s.push_str(&line);
    }
    // whether the extended pass explain reports held the terms left out above (it is run again
    // without them when a rule un-named one after the rounds)
    let parts: Vec<&str> = e.extended_model.split('+').collect();
    let left_out: Vec<&str> = e
        .findings
        .iter()
        .filter(|f| !f.is_cause() && f.kind != "noise")
        .map(|f| f.term.as_str())
        .collect();
    let held: Vec<&str> = left_out
        .iter()
        .copied()
        .filter(|t| parts.contains(t))
        .collect();
    if !held.is_empty() {
        s.push_str(&format!(
            "# the extended pass explain reports ({}) also held {}, left out here.\n",
            e.extended_model,
            held.join(", ")
        ));
    } else if !left_out.is_empty() {
        s.push_str(&format!(
            "# the extended pass explain reports ({}) holds none of the terms left out above: it was run again without them.\n",
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
        "# sinsmodel explain: {}\n\nData: {}\n\n",
        e.baseline_model,
        notation(data)
    ));
    s.push_str("## In words\n\n");
    for line in &e.summary {
        // a finding's line: its verdict and one sentence (the whole in section 3)
        let short = e
            .findings
            .iter()
            .find(|f| crate::explain::finding_line(f) == *line)
            .map(|f| format!("{}: {}", crate::explain::verdict(f), short_words(f)));
        s.push_str(&format!(
            "- {}\n",
            notation(short.as_deref().unwrap_or(line))
        ));
    }
    at_a_glance(e, &mut s);
    let mut placed = vec![false; figures.len()];
    // figures are numbered in the order the page shows them
    let mut number = 0;
    let mut place = |s: &mut String, files: &[&str]| {
        for (k, (file, caption)) in figures.iter().enumerate() {
            if !placed[k] && files.iter().any(|f| file == f) {
                placed[k] = true;
                number += 1;
                s.push_str(&figure(number, file, caption));
            }
        }
    };
    baseline_section(e, &mut s);
    place(&mut s, &["innovations_before.png"]);
    candidates_section(e, &mut s);
    place(&mut s, &["candidates.png"]);
    findings_section(e, &mut s);
    place(&mut s, &["estimates.png"]);
    gain_section(e, &mut s);
    place(
        &mut s,
        &[
            "innovations_after.png",
            "model_error.png",
            "model_error_after.png",
        ],
    );
    let rest: Vec<usize> = (0..figures.len()).filter(|&k| !placed[k]).collect();
    if !rest.is_empty() {
        s.push_str("\n## Further figures\n\n");
        for (i, k) in rest.into_iter().enumerate() {
            s.push_str(&figure(number + i + 1, &figures[k].0, &figures[k].1));
        }
    }
    notes_section(&mut s);
    s
}

/// A finding in one sentence for the report's summary: its headline (the rest is in section 3),
/// the share of the misfit it explains, and whether it is a stand-in.
fn short_words(f: &crate::explain::Finding) -> String {
    let mut s = f.headline.clone();
    if let Some(x) = f.misfit_share {
        s.push_str(&format!(
            "; explains {} % of the baseline's excess misfit",
            crate::explain::share_percent(x)
        ));
    }
    if f.stand_in.is_some() {
        s.push_str(
            " — probably a stand-in for an effect the candidates do not describe (section 3)",
        );
    } else if f.not_attributed.is_some() {
        s.push_str(&format!(" — {} (section 3)", not_attributed_because(f).1));
    }
    s.push('.');
    s
}

/// Why a finding is not attributed, short (the table's verdict) and as a clause: each rule
/// that un-named it (`not_attributed_because`), in the order they did.
fn not_attributed_because(f: &crate::explain::Finding) -> (String, String) {
    let (short, clause): (Vec<&str>, Vec<&str>) =
        f.not_attributed_because.iter().map(|u| u.words()).unzip();
    if short.is_empty() {
        // (every rule that un-names a finding records itself; this is a guard, not a verdict)
        return ("reason not recorded".into(), "see section 3".into());
    }
    (short.join("; "), clause.join(", and "))
}

/// A figure as an HTML block in the Markdown (rendered by Markdown viewers and embedded by the
/// HTML page): the image `file` with its numbered caption.
fn figure(n: usize, file: &str, caption: &str) -> String {
    let cap = super::html_text(caption);
    format!(
        "\n<figure>\n<img src=\"{file}\" alt=\"{cap}\">\n<figcaption>Figure {n}. {cap}</figcaption>\n</figure>\n\n"
    )
}

/// "≤" or "≥" for a noise level at its search bound (`scale_bound` at most or at least); None
/// for an estimate.
fn bound_sign(f: &crate::explain::Finding) -> Option<&'static str> {
    match f.scale_bound? {
        "at most" => Some("≤"),
        _ => Some("≥"),
    }
}

/// The findings at a glance: one row each with its value ± σ, its kind, the share of the
/// baseline's excess misfit it removes and whether it is named as a cause; nothing without
/// findings.
fn at_a_glance(e: &Explanation, s: &mut String) {
    if e.findings.is_empty() {
        return;
    }
    s.push_str(
        "\n## Findings at a glance\n\n| term | kind | value ± σ | explains of the excess misfit | verdict |\n|---|---|---|---|---|\n",
    );
    for f in &e.findings {
        let verdict = if f.stand_in.is_some() && f.not_attributed.is_some() {
            // (a stand-in that a rule un-named as well says both)
            &format!(
                "fitted, but not a cause (a stand-in; also {})",
                not_attributed_because(f).0
            )
        } else if f.stand_in.is_some() {
            "fitted, but not a cause (a stand-in)"
        } else if f.not_attributed.is_some() {
            &format!("fitted, not attributed ({})", not_attributed_because(f).0)
        } else if f.kind == "noise" {
            "**found: a noise level**"
        } else {
            "**found: a cause**"
        };
        let value = match (f.scale, bound_sign(f)) {
            (Some(k), Some(cmp)) if f.unit == "x stated" => {
                format!("{cmp} {}× the stated σ (a bound, no estimate)", sig3(k))
            }
            (Some(k), Some(cmp)) => format!(
                "{cmp} {} {} ({cmp} {}× the stated; a bound, no estimate)",
                num(f.estimate),
                notation(&f.unit),
                sig3(k)
            ),
            (Some(_), None) if f.unit == "x stated" => {
                format!("{} ± {} × the stated σ", num(f.estimate), num(f.sigma))
            }
            (Some(k), None) => format!(
                "{} ± {} {} ({}× the stated)",
                num(f.estimate),
                num(f.sigma),
                notation(&f.unit),
                sig3(k)
            ),
            (None, _) => format!(
                "{} ± {} {}",
                num(f.estimate),
                num(f.sigma),
                notation(&f.unit)
            ),
        };
        let share = f
            .misfit_share
            .map(|x| {
                format!(
                    "{} % (2Δℓ {})",
                    crate::explain::share_percent(x),
                    sig3(f.two_delta_loglik)
                )
            })
            .unwrap_or_else(|| format!("— (2Δℓ {})", sig3(f.two_delta_loglik)));
        s.push_str(&format!(
            "| {} | {} | {value} | {share} | {verdict} |\n",
            f.term, f.kind
        ));
    }
    if let (Some(u), Some(c)) = (e.misfit_unexplained, e.misfit_unexplained_by_causes()) {
        if c > u + 0.005 {
            s.push_str(&format!(
                "\nLeft unexplained by the causes found: {} % of the baseline's excess misfit (fits that are not causes take up {} %; with them the extended model leaves {} %).\n",
                sig3(100.0 * c),
                sig3(100.0 * e.misfit_taken_by_stand_ins()),
                sig3(100.0 * u)
            ));
        } else {
            s.push_str(&format!(
                "\nLeft unexplained by the model explain recommends: {} % of the baseline's excess misfit.\n",
                sig3(100.0 * u)
            ));
        }
    }
}

/// Text with the regressors and units in mathematical notation for a reader: `f.z.powi(2)` →
/// f_z², `f.x.abs()` → |f_x|, `w.y` → ω_y, `dw.x` → ω̇_x, `df.x` → ḟ_x, ` * ` between signals →
/// ·, `ug` → µg, `^2` → ², `sqrt(Hz)` → √Hz.
pub fn notation(text: &str) -> String {
    let b = text.as_bytes();
    let mut out = String::with_capacity(text.len());
    let mut i = 0;
    let boundary = |k: usize| k == 0 || !(b[k - 1].is_ascii_alphanumeric() || b[k - 1] == b'_');
    while i < b.len() {
        // a signal: (dw|df|w|f).(x|y|z), not inside a longer word
        let sig = [("dw.", "ω̇_"), ("df.", "ḟ_"), ("w.", "ω_"), ("f.", "f_")]
            .iter()
            .find(|(p, _)| {
                boundary(i)
                    && text[i..].starts_with(p)
                    && matches!(b.get(i + p.len()), Some(b'x' | b'y' | b'z'))
                    && !b
                        .get(i + p.len() + 1)
                        .is_some_and(|c| c.is_ascii_alphanumeric())
            });
        if let Some((p, q)) = sig {
            let axis = b[i + p.len()] as char;
            let mut j = i + p.len() + 1;
            let sym = format!("{q}{axis}");
            if text[j..].starts_with(".powi(2)") {
                out.push_str(&format!("{sym}²"));
                j += 8;
            } else if text[j..].starts_with(".powi(3)") {
                out.push_str(&format!("{sym}³"));
                j += 8;
            } else if text[j..].starts_with(".abs()") {
                out.push_str(&format!("|{sym}|"));
                j += 6;
            } else {
                out.push_str(&sym);
            }
            // a product of signals: ` * ` becomes a centred dot
            if text[j..].starts_with(" * ")
                && ["dw.", "df.", "w.", "f."]
                    .iter()
                    .any(|p| text[j + 3..].starts_with(p))
            {
                out.push('·');
                j += 3;
            }
            i = j;
            continue;
        }
        let units = [
            ("ug", "µg"),
            ("sqrt(Hz)", "√Hz"),
            ("sqrt(h)", "√h"),
            ("sqrt(s)", "√s"),
            ("^2", "²"),
            ("^3", "³"),
            (" x stated", " × stated"),
        ];
        if let Some((p, q)) = units.iter().find(|(p, _)| {
            text[i..].starts_with(p)
                && (!p.starts_with('u')
                    || (boundary(i)
                        && !b.get(i + p.len()).is_some_and(|c| c.is_ascii_alphabetic())))
        }) {
            out.push_str(q);
            i += p.len();
            continue;
        }
        let c = text[i..].chars().next().expect("in the text");
        out.push(c);
        i += c.len_utf8();
    }
    out
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
        let note = candidate_note(e, c);
        if c.testable {
            s.push_str(&format!(
                "| {} | {} | {:.1} | {} | {} | {} | {} | {} |\n",
                c.term,
                c.group,
                c.llr,
                num(c.p_holm),
                num(c.glr_estimate),
                num(c.glr_sigma),
                notation(&c.unit),
                note
            ));
        } else {
            s.push_str(&format!(
                "| {} | {} | — | — | — | — | {} | {} |\n",
                c.term,
                c.group,
                notation(&c.unit),
                note
            ));
        }
    }
}

/// The candidates table's note on `c`: why a candidate is not testable, not separable, or
/// significant alone yet not named (the later rounds' reason), or that it was named.
fn candidate_note(e: &Explanation, c: &crate::explain::CandidateTest) -> String {
    if !c.testable {
        return "not testable (no information)".into();
    }
    if let Some(b) = &c.confounded_with {
        return format!("not separable from {b}");
    }
    if let Some(f) = e.findings.iter().find(|f| f.term == c.term) {
        return if f.is_cause() {
            format!("named in round {} (section 3)", f.round)
        } else {
            format!(
                "fitted in round {}, not named as a cause (section 3)",
                f.round
            )
        };
    }
    if let Some(f) = e.findings.iter().find(|f| f.equivalent.contains(&c.term)) {
        return format!(
            "not separable from {} on these data (its equivalence class, section 3)",
            f.term
        );
    }
    if let Some(i) = e.implausible.iter().find(|i| i.term == c.term) {
        return format!(
            "significant, but it would need {} prior σ: implausible, not named",
            sig3(i.prior_sigmas)
        );
    }
    if let Some((_, gain, penalty)) = e.unconfirmed.iter().find(|u| u.0 == c.term) {
        return format!(
            "selected, but the extended filter did not confirm it (2Δℓ with the prior's Occam term {} below {}, φ times the χ²_k quantile at α)",
            sig3(*gain),
            sig3(*penalty)
        );
    }
    if c.p_holm <= e.alpha {
        return if e.findings.is_empty() {
            "significant alone, but not once tested with the others in the selection rounds".into()
        } else {
            let named: Vec<&str> = e.findings.iter().map(|f| f.term.as_str()).collect();
            format!(
                "significant alone, but not once {} fitted beside it: they take up its signature",
                if named.len() == 1 {
                    format!("{} is", named[0])
                } else {
                    format!("{} are", named.join(", "))
                }
            )
        };
    }
    String::new()
}

/// Section 3 of the Markdown report: the findings and the extended model.
fn findings_section(e: &Explanation, s: &mut String) {
    s.push_str("\n## 3. Findings and the extended model\n\n");
    if e.findings.is_empty() {
        s.push_str("Nothing is significant; the model stays as it is.\n");
    }
    for f in &e.findings {
        let verdict = if f.stand_in.is_some() {
            "fitted, but not a cause"
        } else if f.not_attributed.is_some() {
            "fitted, not attributed"
        } else {
            "found"
        };
        let share = f
            .misfit_share
            .map(|x| {
                format!(
                    "; explains {} % of the excess misfit",
                    crate::explain::share_percent(x)
                )
            })
            .unwrap_or_default();
        // a level at its search bound is a bound, not an estimate
        let value = match bound_sign(f) {
            Some(cmp) => format!("{cmp} {}", num(f.estimate)),
            None => format!("{} ± {}", num(f.estimate), num(f.sigma)),
        };
        // the llr when selected is conditional on the terms selected before it; section 2's
        // is the candidate's alone in the baseline pass
        let alone = e
            .candidates
            .iter()
            .find(|c| c.term == f.term)
            .map(|c| c.llr)
            .filter(|a| format!("{a:.1}") != format!("{:.1}", f.llr))
            .map(|a| format!(" beside the terms selected before it; {a:.1} alone, section 2"))
            .unwrap_or_default();
        s.push_str(&format!(
            "- **{}** = {}: {verdict}{share} (llr {:.1}{alone}; p {}; round {}).\n\n  <details><summary>In full</summary>{}</details>\n\n",
            f.term,
            notation(&format!("{value} {}", f.unit)),
            f.llr,
            num(f.p_value),
            f.round,
            super::html_text(&notation(&f.words))
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
         and the filter with it confirms the gain the signatures predicted: its 2Δ \
         log-likelihood, with the prior's Occam term ln det(I + S J S) added back (S the \
         terms' prior σ, J their information), above φ times the χ²_k quantile 1 − α for the k \
         terms added in the round.\n",
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
    s.push_str(
        "\n**Found** is a finding named as a cause: significant, plausible in its prior σ, \
         holding across the data in every split tested (its consistency in explain.json) and not \
         in a class whose members' values differ by an order of magnitude or more. **Fitted, but \
         not a cause** is significant but fails one of those, or a noise level's own rules: \
         implausible in its prior σ, a sensor's noise level more than 30× from the stated or above \
         what the raw increments show, a fix's σ its own innovations do not bear out, an interval \
         that holds the stated value, not one value across the data, or removing little of the \
         misfit; its words say which, and it is no property of the sensor: it probably stands in \
         for something the candidates lack. **Fitted, not attributed** is significant, but the \
         data do not say its term is the cause: its class holds members whose values differ by \
         an order of magnitude or more, its value moves when a candidate is fitted beside it and \
         the candidate fits the data better, its value in the extended filter lies within 2σ of \
         zero, or a term the candidates withhold fits the data as well; its words say which, and \
         none is named.\n",
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
