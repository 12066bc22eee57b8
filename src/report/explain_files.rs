//! The files of an `explain` run in its output directory: explain.json, extended.toml (when a
//! term was found), the figures (normalised innovations before and after, candidate ranking,
//! estimates, model error), report.md and report.html with the figures embedded. Needs the
//! plotting backend (the `cli` feature).

use super::explain as words;
use super::plot::{self, Bar, Scale, Series};
use crate::explain::Explanation;
use crate::io::atomic_file::{self, OutputDir};
use crate::model::Model;
use anyhow::{Context, Result};

/// Writes every file of the run into `out` (not committed), `data` describing the data; returns
/// the explain JSON text (for `--json`).
pub fn write(out: &OutputDir, e: &Explanation, data: &str) -> Result<String> {
    let extended = Model::parse(&e.extended_model)?;
    let names: Vec<String> = extended.names.iter().map(|s| s.to_string()).collect();
    let json = words::json(e, &names, data);
    let text = serde_json::to_string_pretty(&json)?;
    atomic_file::write_text(&out.file("explain.json"), &text)?;
    if let Some(preset) = words::extended_preset(e) {
        atomic_file::write_text(&out.file("extended.toml"), &preset)?;
    }
    let figures = figures(out, e)?;
    let md = words::markdown(e, data, &figures);
    atomic_file::write_text(&out.file("report.md"), &md)?;
    let mut embedded = Vec::new();
    for (file, _) in &figures {
        let bytes = std::fs::read(out.file(file))
            .with_context(|| format!("cannot read the figure {file}"))?;
        embedded.push(super::html::Embedded {
            file: file.clone(),
            mime: if file.ends_with(".svg") {
                "image/svg+xml"
            } else {
                "image/png"
            },
            bytes,
        });
    }
    let html = super::html::page(
        &format!("sinsmodel explain: {}", e.baseline_model),
        &md,
        &embedded,
    );
    atomic_file::write_text(&out.file("report.html"), &html)?;
    Ok(text)
}

/// The figures written into `out`, as (file, caption): normalised innovations before/after,
/// candidate ranking, estimates, model error. Times count from the first update when the data
/// carry large (GPS) times.
pub fn figures(out: &OutputDir, e: &Explanation) -> Result<Vec<(String, String)>> {
    let mut figs = Vec::new();
    let t_ref = if e.baseline.t_start.abs() > 1e5 {
        e.baseline.t_start.floor()
    } else {
        0.0
    };
    let t_label = if t_ref != 0.0 {
        format!("t − {t_ref:.0} [s]")
    } else {
        "t [s]".to_string()
    };
    innovations(out, e, t_ref, &t_label, &mut figs)?;
    candidates(out, e, &mut figs)?;
    estimates(out, e, &mut figs)?;
    if !e.model_error_before.is_empty() {
        model_error(out, e, t_ref, &t_label, &mut figs)?;
    }
    Ok(figs)
}

/// The normalised innovations of the baseline and the extended model, one curve per channel;
/// times [s] from `t_ref`.
fn innovations(
    out: &OutputDir,
    e: &Explanation,
    t_ref: f64,
    t_label: &str,
    figs: &mut Vec<(String, String)>,
) -> Result<()> {
    for (file, title, series) in [
        (
            "innovations_before.png",
            format!("Normalised innovations, baseline {}", e.baseline_model),
            &e.innovations_before,
        ),
        (
            "innovations_after.png",
            format!("Normalised innovations, extended {}", e.extended_model),
            &e.innovations_after,
        ),
    ] {
        let mut channels: Vec<&str> = Vec::new();
        for n in series.iter() {
            let c = n.channel();
            if !channels.contains(&c) {
                channels.push(c);
            }
        }
        let curves: Vec<Series> = channels
            .iter()
            .map(|c| Series {
                label: c.to_string(),
                points: series
                    .iter()
                    .filter(|n| n.channel() == *c)
                    .map(|n| (n.t - t_ref, n.nu))
                    .collect(),
            })
            .collect();
        plot::line_plot(
            &out.file(file),
            &title,
            t_label,
            "ν / √S (1 = as predicted)",
            &curves,
            Scale::Linear,
        )?;
        figs.push((file.to_string(), title));
    }
    Ok(())
}

/// The ranking of the testable candidates (at most 30) by their log-likelihood ratio alone,
/// with Holm's first threshold; nothing when none is testable.
fn candidates(out: &OutputDir, e: &Explanation, figs: &mut Vec<(String, String)>) -> Result<()> {
    let testable: Vec<_> = e.candidates.iter().filter(|c| c.testable).collect();
    if testable.is_empty() {
        return Ok(());
    }
    let bars: Vec<Bar> = testable
        .iter()
        .take(30)
        .map(|c| Bar {
            label: c.term.clone(),
            value: (1.0 + c.llr).log10(),
            err: None,
        })
        .collect();
    // the single-candidate threshold: Holm's first step at α over the testable ones
    let thr = crate::estimate::stats::chi2_isf(e.alpha / testable.len() as f64, 1.0);
    plot::bar_plot(
        &out.file("candidates.png"),
        "Candidates in the baseline pass (each alone)",
        "log10(1 + llr)",
        &bars,
        Some(((1.0 + thr).log10(), "Holm threshold (first step)")),
    )?;
    figs.push((
        "candidates.png".into(),
        "Candidate ranking: log-likelihood ratio of each candidate alone, with the threshold"
            .into(),
    ));
    Ok(())
}

/// The estimates of the terms found, each as its distance from 0 (a noise level: from its stated
/// value) in units of its own σ, so terms in different units share one axis, with ±2 (its 95 %
/// interval), labelled with the value in its unit; nothing without findings.
fn estimates(out: &OutputDir, e: &Explanation, figs: &mut Vec<(String, String)>) -> Result<()> {
    if e.findings.is_empty() {
        return Ok(());
    }
    let bars: Vec<Bar> = e
        .findings
        .iter()
        .map(|f| Bar {
            label: format!(
                "{} = {} ± {} {}",
                f.term,
                crate::io::units::sig3(f.estimate),
                crate::io::units::sig3(f.sigma),
                words::notation(&f.unit)
            ),
            // a term against 0, a noise level against its stated value
            value: if f.sigma > 0.0 {
                let reference = f.scale.map(|k| f.estimate / k).unwrap_or(0.0);
                (f.estimate - reference) / f.sigma
            } else {
                f64::NAN
            },
            err: Some(2.0),
        })
        .collect();
    plot::bar_plot(
        &out.file("estimates.png"),
        "Estimates of the terms found (extended filter), in units of their σ, ±2",
        "(estimate − reference) / σ; reference 0, a noise level's the stated value",
        &bars,
        None,
    )?;
    figs.push((
        "estimates.png".into(),
        "Estimates of the terms found, each as its distance from 0 (a noise level: from its stated value) in its own σ, with ±2 (its 95 % interval; beyond ±2 the data distinguish it); the values in their units label the bars".into(),
    ));
    Ok(())
}

/// The model error e = φ̂ − φ (north, east) [arcsec] of the baseline and the extended model,
/// and the extended model's alone when the baseline's (over 5× larger) would flatten it; times
/// [s] from `t_ref`.
fn model_error(
    out: &OutputDir,
    e: &Explanation,
    t_ref: f64,
    t_label: &str,
    figs: &mut Vec<(String, String)>,
) -> Result<()> {
    let pick = |v: &[(f64, f64, f64)], k: usize| -> Vec<(f64, f64)> {
        v.iter()
            .map(|r| (r.0 - t_ref, if k == 0 { r.1 } else { r.2 }))
            .collect()
    };
    let curves = vec![
        Series {
            label: format!("e_n baseline {}", e.baseline_model),
            points: pick(&e.model_error_before, 0),
        },
        Series {
            label: format!("e_e baseline {}", e.baseline_model),
            points: pick(&e.model_error_before, 1),
        },
        Series {
            label: "e_n extended".to_string(),
            points: pick(&e.model_error_after, 0),
        },
        Series {
            label: "e_e extended".to_string(),
            points: pick(&e.model_error_after, 1),
        },
    ];
    plot::line_plot(
        &out.file("model_error.png"),
        "Model error e = phi_est − phi before and after",
        t_label,
        "arcsec",
        &curves,
        Scale::Linear,
    )?;
    figs.push((
        "model_error.png".into(),
        "Model error e = phi_est − phi (north, east) of the baseline and the extended model".into(),
    ));
    // the extended model alone, when the baseline's error would flatten it
    if let (Some(b), Some(a)) = (e.gain.model_error_rms_before, e.gain.model_error_rms_after) {
        if b > 5.0 * a {
            plot::line_plot(
                &out.file("model_error_after.png"),
                &format!("Model error of the extended model {}", e.extended_model),
                t_label,
                "arcsec",
                &curves[2..],
                Scale::Linear,
            )?;
            figs.push((
                "model_error_after.png".into(),
                "Model error of the extended model alone (its scale)".into(),
            ));
        }
    }
    Ok(())
}
