//! `sinsmodel explain [--model BASELINE --imu FILE (--aid FILE | --static-aid LAT,LON,H) …]
//! [--candidates LIST] [--alpha A] [--out DIR] [--json FILE]`: what the model gets wrong on the
//! data, the missing error term, the extended model and its gain. Without data options it runs
//! the embedded demo: the paper's vibration case with the d terms hidden, baseline P28.

use super::data::DataArgs;
use anyhow::{bail, Context, Result};
use clap::Args;
use sinsmodel::estimate::filter::FilterConfig;
use sinsmodel::experiment::{explain_data, reproduce};
use sinsmodel::explain::{self, ExplainData, ExplainOptions, Explanation};
use sinsmodel::io::atomic_file::{self, OutputDir};
use sinsmodel::model::Model;
use sinsmodel::report::{explain as report, explain_files, explain_notes, progress};
use std::path::{Path, PathBuf};

/// Arguments of `explain`.
#[derive(Args)]
pub struct ExplainArgs {
    /// Baseline model, e.g. P28, P31, P31+vertical (the demo: P28+vertical).
    #[arg(long)]
    model: Option<String>,
    #[command(flatten)]
    data: DataArgs,
    /// Replace a --json file that is not provably an earlier explain output.
    #[arg(long)]
    overwrite: bool,
    /// Candidate terms: names and prefix groups (`kaq_*,kas_y,d_*`); default every spec term
    /// the baseline lacks. `!name` or `!prefix*` withholds (`!size_*,!tau_*`: every term but
    /// those).
    #[arg(long)]
    candidates: Option<String>,
    /// Family-wise false-alarm level of the candidate tests (Holm-corrected), in (0, 0.5].
    #[arg(long, default_value_t = 0.01, allow_hyphen_values = true)]
    alpha: f64,
    /// Output DIRECTORY (not a file; navigate's --out is a file): report.md, report.html,
    /// explain.json, extended.toml, figures.
    #[arg(long, default_value = "out/explain")]
    out: PathBuf,
    /// Also write the explain JSON (DESIGN §9) here.
    #[arg(long)]
    json: Option<PathBuf>,
    /// Demo only: length of the simulated run [s] (60 to 14400; default 600).
    #[arg(long, allow_hyphen_values = true)]
    demo_seconds: Option<f64>,
    /// Demo only: seed of the simulation (default 1; 0 to 1e12).
    #[arg(long, allow_hyphen_values = true, value_parser = clap::value_parser!(u64).range(0..=1_000_000_000_000))]
    demo_seed: Option<u64>,
}

/// Runs the command.
pub fn run(args: &ExplainArgs) -> Result<()> {
    if !(args.alpha.is_finite() && args.alpha > 0.0 && args.alpha <= 0.5) {
        bail!(
            "--alpha {}: expected a level in (0, 0.5]",
            sinsmodel::io::units::shown_number(args.alpha)
        );
    }
    let opts = ExplainOptions {
        alpha: args.alpha,
        // an explicit --mode is kept; by default a drifting open loop runs closed instead
        closed_loop_on_drift: args.data.mode.is_none(),
        ..ExplainOptions::default()
    };
    if let Some(j) = &args.json {
        check_json_option(args, j)?;
    }
    if args.data.any_given() {
        on_data(args, &opts)
    } else {
        demo(args, &opts)
    }
}

/// Refuses a `--json` file that is a directory, inside `--out`, an input, or not provably an
/// earlier explain output.
fn check_json_option(args: &ExplainArgs, j: &Path) -> Result<()> {
    if j.is_dir() {
        bail!("--json {}: is a directory; give a file name", j.display());
    }
    // the run makes --out a directory: as --json too the run would end refusing its own output
    if same_file(j, &args.out) {
        bail!(
            "--json {}: the same path as --out (the run's directory); give the JSON file another name",
            j.display()
        );
    }
    // inside --out it would be a file the run's directory did not list (explain.json is
    // there already)
    let parent = j
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    if same_file(parent, &args.out) {
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
    check_json(j, args.overwrite)
}

/// explain on the data the options name: the candidates checked against the aiding, every
/// option checked before the (long) run.
fn on_data(args: &ExplainArgs, opts: &ExplainOptions) -> Result<()> {
    // a data option without the data: the demo runs only when none is given
    if args.data.imu.is_none() {
        bail!(
            "{}: a data option; it needs data (--imu FILE with --aid or --static-aid, and --model). Without data options explain runs its embedded demo, which cannot use it (the demo takes --model, --candidates, --alpha, --mode, --step, --demo-seconds, --demo-seed, --out, --json)",
            args.data.given_names().join(", ")
        );
    }
    if args.demo_seconds.is_some() || args.demo_seed.is_some() {
        bail!("--demo-seconds and --demo-seed belong to the embedded demo, not to a run on data");
    }
    let model_text = args
        .model
        .as_deref()
        .context("--model BASELINE is required with data (e.g. --model P31)")?;
    let baseline = Model::parse(model_text)?;
    let cands = data_candidates(args, &baseline)?;
    let skipped = already_in_baseline(args.candidates.as_deref(), &baseline);
    // every option is checked before the (long) run
    args.data.check_prior_names(&baseline)?;
    args.data.config(&baseline, true)?;
    let opts = explain_data::options(&args.data, opts)?;
    let inputs = args.data.input_paths();
    let refs: Vec<&std::path::Path> = inputs.iter().map(|p| p.as_path()).collect();
    let out = OutputDir::create(&args.out, &refs, "explain")?;
    super::data::print_noise(&args.data)?;
    // a time offset found is refitted on fixes re-stamped by it (explain::restamp), then tried
    // against a lever arm on the fixes as given
    let pb = progress::bar(1000, "explain");
    let mut e = explain_data::explain_restamped(
        &args.data,
        (&baseline, &cands, &opts),
        &mut super::data::note,
        &mut |pass, f| {
            pb.set_message(format!("pass {pass}"));
            pb.set_position((f * 1000.0) as u64);
        },
    )?;
    pb.finish_and_clear();
    if let Some(line) = explain_notes::known_gnss(&args.data.known_gnss()?) {
        e.summary.insert(0, line);
    }
    finish(args, out, &e, &args.data.describe(), &skipped)
}

/// The candidates of a run on data: without GNSS aiding (a static aid or ZUPTs have no antenna
/// and no receiver clock) the GNSS terms are dropped, without a velocity reference its mounting
/// terms; either is refused when named.
fn data_candidates(args: &ExplainArgs, baseline: &Model) -> Result<Vec<usize>> {
    use sinsmodel::model::catalog::Sensor;
    let mut cands = explain::parse_candidates(args.candidates.as_deref(), baseline)
        .map_err(anyhow::Error::msg)?;
    // (named by the user: a list of withholdings only starts from every term)
    let named = args.candidates.as_deref().is_some_and(|c| {
        c.split(',')
            .map(str::trim)
            .any(|i| !i.is_empty() && !i.starts_with('!'))
    });
    let reference = args.data.body_velocity.is_some()
        && baseline.measurements().iter().any(|m| m.name == "vel_body");
    for (sensor, present, one, many, without) in [
        (
            Sensor::Gnss,
            args.data.has_gnss(),
            "is a GNSS term",
            "are GNSS terms",
            " (entering the fixes of a GNSS receiver); without --aid there is none",
        ),
        (
            Sensor::Reference,
            reference,
            "is a mounting of a velocity reference",
            "are mountings of a velocity reference",
            "; without --body-velocity (and a +vertical baseline) there is none",
        ),
        (
            Sensor::Attitude,
            args.data.attitude.is_some(),
            "is a mounting of an attitude reference",
            "are mountings of an attitude reference",
            "; without --attitude there is none",
        ),
    ] {
        let absent = explain_data::terms_of(&cands, sensor);
        if present || absent.is_empty() {
            continue;
        }
        if named {
            let verb = if absent.len() == 1 { one } else { many };
            bail!("--candidates: {} {verb}{without}", absent.join(", "));
        }
        explain_data::drop_sensor(&mut cands, sensor);
    }
    if cands.is_empty() {
        bail!(
            "--candidates: no candidate is left to test (the baseline {} holds every term named, or only GNSS or reference terms were named without their aiding)",
            baseline.name
        );
    }
    Ok(cands)
}

/// Whether `a` and `b` are the same file (by their canonical paths, else as given).
fn same_file(a: &Path, b: &Path) -> bool {
    match (a.canonicalize(), b.canonicalize()) {
        (Ok(x), Ok(y)) => x == y,
        _ => a == b,
    }
}

/// Refuses a `--json` file that is not provably an earlier explain output (unless `overwrite`).
fn check_json(j: &Path, overwrite: bool) -> Result<()> {
    atomic_file::check_output_file(
        "--json",
        j,
        &[],
        atomic_file::Provenance::Json("explain"),
        overwrite,
    )
}

/// Candidates the user named that the baseline already has (skipped, with a note).
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

/// explain with a progress bar.
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
        bail!(
            "--demo-seconds {}: expected 60 to 14400 s",
            sinsmodel::io::units::shown_number(seconds)
        );
    }
    // P28 with its vertical channel: at the paper's level attitude d_z acts along the vertical,
    // which a fixed-height P28 cannot see (`--model P28` shows that)
    let model_text = args.model.as_deref().unwrap_or("P28+vertical");
    let baseline = Model::parse(model_text)?;
    let cands = explain::parse_candidates(args.candidates.as_deref(), &baseline)
        .map_err(anyhow::Error::msg)?;
    // the demo's filter follows --mode and --step (open loop and 0.01 s without them);
    // --init-speed means something only with --init auto on data
    let (mode, step) = (args.data.mode_given()?, args.data.step_given()?);
    if args.data.init_speed.is_some() {
        bail!(
            "--init-speed belongs to --init auto on data; the embedded demo starts from its truth"
        );
    }
    let case = reproduce::explain_demo(seconds, seed);
    let sc = sinsmodel::sim::scenario::Scenario::parse(&case.scenario, "embedded demo")?;
    if let Some(s) = step {
        let whose = format!(
            "the demo's {} Hz IMU",
            sinsmodel::io::units::shown_number(sc.imu_rate_hz)
        );
        sinsmodel::data::DataOptions::check_step_interval(s, 1.0 / sc.imu_rate_hz, &whose)?;
    }
    let out = OutputDir::create(&args.out, &[], "explain")?;
    eprintln!(
        "demo: simulating {:.0} s of the paper's vibration case (6 g / 3 g at 90 Hz on N, E, D; 2 kHz) with d_x d_y d_z = 5e-5 s^2/m hidden; baseline {}",
        seconds, baseline.name
    );
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
        tape: None,
    };
    let config_for = |m: &Model| {
        let mut c = reproduce::config(m, &priors)?;
        c.mode = mode.unwrap_or(c.mode);
        c.step_s = step.unwrap_or(c.step_s);
        Ok(c)
    };
    let e = run_explain(&baseline, &cands, &data, &config_for, opts)?;
    // the estimates against the hidden value, measured on this run
    eprintln!("{}", explain_notes::demo_against_truth(&e));
    let mut what = explain_notes::demo_description(seconds, seed);
    if mode == Some(sinsmodel::estimate::filter::Mode::ClosedLoop) {
        what.push_str("; closed loop (--mode closed)");
    }
    if let Some(s) = step {
        what.push_str(&format!(
            "; filter step {} s (--step)",
            sinsmodel::io::units::shown_number(s)
        ));
    }
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
    explain_notes::note_skipped(&mut e, skipped);
    // a prefix that reaches across families (`!d*`: d_x … and dt_gnss) is said, not assumed
    for note in explain::prefix_reach(args.candidates.as_deref()) {
        e.summary.insert(0, note);
    }
    // what was said about the data goes first: a finding on data with a slip stands on it
    for (k, w) in sinsmodel::io::warnings::take().into_iter().enumerate() {
        e.summary.insert(k, format!("Warning about the data: {w}"));
    }
    // the mode explain chose is part of what the data went through
    let data = if e.closed_loop_instead {
        format!("{data}; closed loop (its open-loop baseline pass drifted beyond small angles)")
    } else {
        data.to_string()
    };
    let text = explain_files::write(&out, &e, &data)?;
    out.commit()?;
    if let Some(j) = &args.json {
        // checked again: the file may have been replaced while the run worked
        check_json(j, args.overwrite)?;
        atomic_file::write_text(j, &text)?;
    }
    // the terminal reads like the report: f_z², µg/g² (the JSON keeps the spec's spelling)
    for line in &e.summary {
        eprintln!("{}", report::notation(line));
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
