//! `sinsmodel explain [--model BASELINE --imu FILE (--aid FILE | --static-aid LAT,LON,H) …]
//! [--candidates LIST] [--alpha A] [--out DIR] [--json FILE]`: what the model gets wrong on the
//! data, the missing error term, the extended model and its gain. Without data options it runs
//! the embedded demo: the paper's vibration case with the d terms hidden, baseline P28.

use super::data::DataArgs;
use anyhow::{bail, Context, Result};
use clap::Args;
use sinsmodel::estimate::filter::FilterConfig;
use sinsmodel::experiment::reproduce;
use sinsmodel::explain::{self, ExplainData, ExplainOptions, Explanation};
use sinsmodel::io::atomic_file::{self, OutputDir};
use sinsmodel::model::catalog::Sensor;
use sinsmodel::model::generated::common;
use sinsmodel::model::Model;
use sinsmodel::report::plot::{self, Bar, Scale, Series};
use sinsmodel::report::{explain as report, progress};
use std::path::{Path, PathBuf};

/// Arguments of `explain`.
#[derive(Args)]
pub struct ExplainArgs {
    /// Baseline model, e.g. P28, P31, P31+vertical (the demo: P28+vertical).
    #[arg(long)]
    model: Option<String>,
    #[command(flatten)]
    data: DataArgs,
    /// Candidate terms: names and prefix groups (`kaq_*,kas_y,d_*`); default every spec term
    /// the baseline lacks. `!name` or `!prefix*` withholds (`!size_*,!tau_*`: every term but
    /// those).
    #[arg(long)]
    candidates: Option<String>,
    /// Family-wise false-alarm level of the candidate tests (Holm-corrected), in (0, 0.5].
    #[arg(long, default_value_t = 0.01)]
    alpha: f64,
    /// Output directory: report.md, report.html, explain.json, extended.toml, figures.
    #[arg(long, default_value = "out/explain")]
    out: PathBuf,
    /// Also write the explain JSON (DESIGN §9) here.
    #[arg(long)]
    json: Option<PathBuf>,
    /// Demo only: length of the simulated run [s] (60 to 14400; default 600).
    #[arg(long)]
    demo_seconds: Option<f64>,
    /// Demo only: seed of the simulation (default 1; 0 to 1e12).
    #[arg(long, value_parser = clap::value_parser!(u64).range(0..=1_000_000_000_000))]
    demo_seed: Option<u64>,
}

/// Runs the command.
pub fn run(args: &ExplainArgs) -> Result<()> {
    if !(args.alpha.is_finite() && args.alpha > 0.0 && args.alpha <= 0.5) {
        bail!("--alpha {}: expected a level in (0, 0.5]", args.alpha);
    }
    let opts = ExplainOptions {
        alpha: args.alpha,
        ..ExplainOptions::default()
    };
    if let Some(j) = &args.json {
        if j.is_dir() {
            bail!("--json {}: is a directory; give a file name", j.display());
        }
        // inside --out it would be a file the run's directory did not list (explain.json is
        // there already)
        let inside = |dir: &Path| {
            let parent = j
                .parent()
                .filter(|p| !p.as_os_str().is_empty())
                .unwrap_or(Path::new("."));
            same_file(parent, dir)
        };
        if inside(&args.out) {
            bail!(
                "--json {}: inside --out {} (which holds explain.json already); give a path outside it",
                j.display(),
                args.out.display()
            );
        }
        for inp in args.data.input_paths() {
            if same_file(j, &inp) {
                bail!(
                    "--json {}: that is an input file; choose another",
                    j.display()
                );
            }
        }
        check_json(j, args.data.force)?;
    }
    if args.data.any_given() {
        if args.demo_seconds.is_some() || args.demo_seed.is_some() {
            bail!(
                "--demo-seconds and --demo-seed belong to the embedded demo, not to a run on data"
            );
        }
        let model_text = args
            .model
            .as_deref()
            .context("--model BASELINE is required with data (e.g. --model P31)")?;
        let baseline = Model::parse(model_text)?;
        let mut cands = explain::parse_candidates(args.candidates.as_deref(), &baseline)
            .map_err(anyhow::Error::msg)?;
        if !args.data.has_gnss() {
            // a static aid or ZUPTs have no antenna and no receiver clock
            let gnss: Vec<&str> = cands
                .iter()
                .filter(|&&t| common::TERMS[t].sensor == Sensor::Gnss)
                .map(|&t| common::TERMS[t].name)
                .collect();
            // (named by the user: a list of withholdings only starts from every term)
            let named = args.candidates.as_deref().is_some_and(|c| {
                c.split(',')
                    .map(str::trim)
                    .any(|i| !i.is_empty() && !i.starts_with('!'))
            });
            if named && !gnss.is_empty() {
                bail!(
                    "--candidates: {} {} GNSS term{} (entering the fixes of a GNSS receiver); without --aid there is none",
                    gnss.join(", "),
                    if gnss.len() == 1 { "is a" } else { "are" },
                    if gnss.len() == 1 { "" } else { "s" }
                );
            }
            cands.retain(|&t| common::TERMS[t].sensor != Sensor::Gnss);
        }
        if cands.is_empty() {
            bail!(
                "--candidates: no candidate is left to test (the baseline {} holds every term named, or only GNSS terms were named and there is no --aid)",
                baseline.name
            );
        }
        let skipped = already_in_baseline(args.candidates.as_deref(), &baseline);
        // every option is checked before the (long) run
        args.data.check_prior_names(&baseline)?;
        args.data.config(&baseline, true)?;
        let mut opts = opts.clone();
        opts.candidate_sigma = args.data.term_priors()?;
        // a static aid's or a ZUPT's σ is a tuning choice, not a receiver's: noise levels are
        // tested with GNSS aiding only
        opts.noise_levels = args.data.has_gnss();
        let inputs = args.data.input_paths();
        let refs: Vec<&std::path::Path> = inputs.iter().map(|p| p.as_path()).collect();
        let out = OutputDir::create(&args.out, &refs, "explain")?;
        super::data::print_noise(&args.data)?;
        let inputs = args.data.load_for_passes(&mut super::data::note)?;
        let data = ExplainData {
            imu: sinsmodel::explain::ImuInput::File {
                path: &inputs.imu,
                format: inputs.imu_format.as_deref(),
                clock_offset: inputs.clock_offset,
                skip_through: inputs.start.t + 1e-9,
                identity: Some(sinsmodel::explain::FileIdentity::of(&inputs.imu)?),
            },
            aid: &inputs.aid,
            truth: inputs.truth.as_deref(),
            start: inputs.start,
        };
        let config_for = |m: &Model| {
            let mut c = args.data.config(m, true)?;
            sinsmodel::data::apply_opened(&mut c, m, inputs.init_sigma, inputs.step_s);
            Ok(c)
        };
        let mut e = run_explain(&baseline, &cands, &data, &config_for, &opts)?;
        let known: Vec<String> = args
            .data
            .known_gnss()?
            .iter()
            .map(|&(t, v)| {
                let info = &common::TERMS[t];
                format!(
                    "{} = {} {}",
                    info.name,
                    explain::sig3(v / info.display_to_si),
                    info.display
                )
            })
            .collect();
        if !known.is_empty() {
            e.summary.insert(
                0,
                format!(
                    "Known GNSS values applied in every pass (--gnss-delay, --lever-arm): {}; a GNSS finding is what the data show on top of them.",
                    known.join(", ")
                ),
            );
        }
        finish(args, out, &e, &args.data.describe(), &skipped)
    } else {
        demo(args, &opts)
    }
}

fn same_file(a: &Path, b: &Path) -> bool {
    match (a.canonicalize(), b.canonicalize()) {
        (Ok(x), Ok(y)) => x == y,
        _ => a == b,
    }
}

/// Candidates the user named that the baseline already has (skipped, with a note).
/// Refuses a `--json` file that is not provably an earlier explain output (unless `force`).
fn check_json(j: &Path, force: bool) -> Result<()> {
    atomic_file::check_output_file(
        "--json",
        j,
        &[],
        atomic_file::Provenance::Json("explain"),
        force,
    )
}

fn already_in_baseline(spec: Option<&str>, baseline: &Model) -> Vec<String> {
    let Some(spec) = spec else {
        return Vec::new();
    };
    spec.split(',')
        .map(str::trim)
        .filter(|s| !s.ends_with('*') && baseline.index_of(s).is_some())
        .map(str::to_string)
        .collect()
}

fn run_explain(
    baseline: &Model,
    cands: &[usize],
    data: &ExplainData,
    config_for: &dyn Fn(&Model) -> Result<FilterConfig>,
    opts: &ExplainOptions,
) -> Result<Explanation> {
    let pb = progress::bar(1000, "explain");
    let e = explain::explain(baseline, cands, data, config_for, opts, &mut |pass, f| {
        pb.set_message(format!("pass {pass}"));
        pb.set_position((f * 1000.0) as u64);
    })?;
    pb.finish_and_clear();
    Ok(e)
}

/// The embedded demo: the paper's 6 g, 90 Hz N/E/D vibration at 2 kHz (on/off windows, 6 g
/// then 3 g) with the paper's sensor errors including d = 5e-5 s²/m on every axis, baseline P28.
fn demo(args: &ExplainArgs, opts: &ExplainOptions) -> Result<()> {
    let seconds = args.demo_seconds.unwrap_or(600.0);
    let seed = args.demo_seed.unwrap_or(1);
    if !(seconds.is_finite() && (60.0..=14_400.0).contains(&seconds)) {
        bail!("--demo-seconds {seconds}: expected 60 to 14400 s");
    }
    // P28 with its vertical channel: at the paper's level attitude d_z acts along the vertical,
    // which a fixed-height P28 cannot see (`--model P28` shows that)
    let model_text = args.model.as_deref().unwrap_or("P28+vertical");
    let baseline = Model::parse(model_text)?;
    let cands = explain::parse_candidates(args.candidates.as_deref(), &baseline)
        .map_err(anyhow::Error::msg)?;
    let out = OutputDir::create(&args.out, &[], "explain")?;
    let case = reproduce::explain_demo(seconds, seed);
    eprintln!(
        "demo: simulating {:.0} s of the paper's vibration case (6 g / 3 g at 90 Hz on N, E, D; 2 kHz) with d_x d_y d_z = 5e-5 s^2/m hidden; baseline {}",
        seconds, baseline.name
    );
    let sc = sinsmodel::sim::scenario::Scenario::parse(&case.scenario, "embedded demo")?;
    let pb = progress::bar(1000, "simulate");
    let sim = sinsmodel::sim::simulator::simulate(&sc, |f| pb.set_position((f * 1000.0) as u64));
    pb.finish_and_clear();
    let priors = reproduce::Priors::default();
    let aid = reproduce::aiding_from_truth(&sim, &priors, case.velocity_updates, seed)?;
    let data = ExplainData {
        imu: sinsmodel::explain::ImuInput::Memory(&sim.imu),
        aid: &aid,
        truth: Some(&sim.truth),
        start: sim.start,
    };
    let config_for = |m: &Model| reproduce::config(m, &priors);
    let e = run_explain(&baseline, &cands, &data, &config_for, opts)?;
    // the estimates against the hidden value, measured on this run
    let against: Vec<String> = e
        .findings
        .iter()
        .filter(|f| f.term.starts_with("d_") && f.unit == "ug/g^2" && f.estimate.is_finite())
        .map(|f| {
            format!(
                "{} {:+.2} % (± {:.2} %)",
                f.term,
                (f.estimate / 490.0 - 1.0) * 100.0,
                f.sigma / 490.0 * 100.0
            )
        })
        .collect();
    eprintln!(
        "(hidden truth: d = 490 ug/g^2 on every axis; the estimates read {} against it; 0.7 % of that is expected: the regressor f^2 is formed from 2 kHz increments, which average the 90 Hz sine, sinc^2 = 0.993)",
        if against.is_empty() { "nothing (no d_ term found)".to_string() } else { against.join(", ") }
    );
    let what = format!(
        "embedded demo: {:.0} s simulated, the paper's 6 g / 3 g 90 Hz vibration on N, E, D (on/off windows), 2 kHz, \
         d_x = d_y = d_z = 5e-5 s^2/m (490 ug/g^2) hidden, seed {}",
        seconds, seed
    );
    let skipped = already_in_baseline(args.candidates.as_deref(), &baseline);
    finish(args, out, &e, &what, &skipped)
}

/// Writes the report, figures, JSON and extended preset; prints the summary.
fn finish(
    args: &ExplainArgs,
    out: OutputDir,
    e: &Explanation,
    data: &str,
    skipped: &[String],
) -> Result<()> {
    let mut e = e.clone();
    for s in skipped {
        e.summary.insert(
            0,
            format!(
                "Candidate {s} is already in the baseline {}; skipped.",
                e.baseline_model
            ),
        );
    }
    let extended = Model::parse(&e.extended_model)?;
    let names: Vec<String> = extended.names.iter().map(|s| s.to_string()).collect();
    let json = report::json(&e, &names, data);
    let text = serde_json::to_string_pretty(&json)?;
    atomic_file::write_text(&out.file("explain.json"), &text)?;
    if let Some(preset) = report::extended_preset(&e) {
        atomic_file::write_text(&out.file("extended.toml"), &preset)?;
    }
    let figures = figures(&out, &e)?;
    let md = report::markdown(&e, data, &figures);
    atomic_file::write_text(&out.file("report.md"), &md)?;
    let mut embedded = Vec::new();
    for (file, caption) in &figures {
        let bytes = std::fs::read(out.file(file))
            .with_context(|| format!("cannot read the figure {file}"))?;
        embedded.push((caption.clone(), bytes));
    }
    let html = report::html(
        &format!("sinsmodel explain: {}", e.baseline_model),
        &md,
        &embedded,
    );
    atomic_file::write_text(&out.file("report.html"), &html)?;
    out.commit()?;
    if let Some(j) = &args.json {
        // checked again: the file may have been replaced while the run worked
        check_json(j, args.data.force)?;
        atomic_file::write_text(j, &text)?;
    }
    for line in &e.summary {
        eprintln!("{line}");
    }
    println!(
        "report: {} (and report.html, explain.json{} there)",
        args.out.join("report.md").display(),
        if report::extended_preset(&e).is_none() {
            ""
        } else {
            ", extended.toml"
        }
    );
    Ok(())
}

/// Figures: normalised innovations before/after, candidate ranking, estimates, model error.
/// Times count from the first update when the data carry large (GPS) times.
fn figures(out: &OutputDir, e: &Explanation) -> Result<Vec<(String, String)>> {
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
        let mut channels: Vec<String> = Vec::new();
        for (_, c, _) in series.iter() {
            if !channels.contains(c) {
                channels.push(c.clone());
            }
        }
        let curves: Vec<Series> = channels
            .iter()
            .map(|c| Series {
                label: c.clone(),
                points: series
                    .iter()
                    .filter(|(_, ch, _)| ch == c)
                    .map(|(t, _, v)| (*t - t_ref, *v))
                    .collect(),
            })
            .collect();
        plot::line_plot(
            &out.file(file),
            &title,
            &t_label,
            "ν / √S (1 = as predicted)",
            &curves,
            Scale::Linear,
        )?;
        figs.push((file.to_string(), title));
    }
    let testable: Vec<_> = e.candidates.iter().filter(|c| c.testable).collect();
    if !testable.is_empty() {
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
        let thr = sinsmodel::estimate::stats::chi2_isf(e.alpha / testable.len() as f64, 1.0);
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
    }
    if !e.findings.is_empty() {
        let bars: Vec<Bar> = e
            .findings
            .iter()
            .map(|f| Bar {
                label: format!("{} [{}]", f.term, f.unit),
                value: f.estimate,
                err: Some(2.0 * f.sigma),
            })
            .collect();
        plot::bar_plot(
            &out.file("estimates.png"),
            "Estimates of the terms found (extended filter), ±2σ",
            "estimate (each in its own unit)",
            &bars,
            None,
        )?;
        figs.push((
            "estimates.png".into(),
            "Estimates of the terms found, with ±2σ".into(),
        ));
    }
    if !e.model_error_before.is_empty() {
        let pick = |v: &[(f64, f64, f64)], k: usize| -> Vec<(f64, f64)> {
            v.iter()
                .map(|r| (r.0 - t_ref, if k == 0 { r.1 } else { r.2 }))
                .collect()
        };
        let curves = vec![
            Series {
                label: format!("e_n {}", e.baseline_model),
                points: pick(&e.model_error_before, 0),
            },
            Series {
                label: format!("e_e {}", e.baseline_model),
                points: pick(&e.model_error_before, 1),
            },
            Series {
                label: format!("e_n {}", e.extended_model),
                points: pick(&e.model_error_after, 0),
            },
            Series {
                label: format!("e_e {}", e.extended_model),
                points: pick(&e.model_error_after, 1),
            },
        ];
        plot::line_plot(
            &out.file("model_error.png"),
            "Model error e = phi_est − phi before and after",
            &t_label,
            "arcsec",
            &curves,
            Scale::Linear,
        )?;
        figs.push((
            "model_error.png".into(),
            "Model error e = phi_est − phi (north, east) of the baseline and the extended model"
                .into(),
        ));
        // the extended model alone, when the baseline's error would flatten it
        if let (Some(b), Some(a)) = (e.gain.model_error_rms_before, e.gain.model_error_rms_after) {
            if b > 5.0 * a {
                plot::line_plot(
                    &out.file("model_error_after.png"),
                    &format!("Model error of the extended model {}", e.extended_model),
                    &t_label,
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
    }
    Ok(figs)
}
