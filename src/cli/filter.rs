//! `sinsmodel filter --model MODEL --imu FILE --aid FILE [--truth FILE] [--init …] --out DIR`.

use super::data::DataArgs;
use super::nav_out::{NavWriter, RowClock};
use anyhow::Result;
use clap::Args;
use sinsmodel::data::Dataset;
use sinsmodel::estimate::filter::{self, FilterConfig, FilterRun};
use sinsmodel::estimate::metrics;
use sinsmodel::io::atomic_file::OutputDir;
use sinsmodel::model::Model;
use sinsmodel::report::filter::{
    model_error_line, nis_table, outage_table, outages_json, EpochFiles,
};
use sinsmodel::report::progress;
use std::path::PathBuf;

/// Arguments of `filter`.
#[derive(Args)]
pub struct FilterArgs {
    /// Model, e.g. P31, P28+kaq_x_xy, P31+vertical.
    #[arg(long)]
    model: String,
    #[command(flatten)]
    data: DataArgs,
    /// Output DIRECTORY (not a file; navigate's --out is a file): states.txt, innovations.txt,
    /// nav.txt (the navigation solution with 1-σ) and its plots, model_error.txt (with truth),
    /// outages.json (with --outage); written complete or not at all, replacing only an earlier
    /// sinsmodel run's directory.
    #[arg(long)]
    out: PathBuf,
    /// Rate of the navigation solution nav.txt [Hz] (default: every IMU sample); --out-rate,
    /// navigate's older name, is accepted too.
    #[arg(long, alias = "out-rate", allow_hyphen_values = true)]
    nav_rate: Option<f64>,
    /// Read the whole IMU file before filtering (the pre-streaming path, kept as the baseline
    /// `sinsmodel bench` measures the stream against).
    #[arg(long, hide = true)]
    in_memory: bool,
    /// Innovation gate: a scalar update whose innovation exceeds this many of its predicted σ
    /// (√S), e.g. 10, is not applied, and is counted in the summary and listed at the end of
    /// innovations.txt; after 5 epochs of a component rejected in a row the next is applied.
    /// `off` applies every update (single outlying fixes are dropped before the run all the same).
    #[arg(long, default_value = "off", allow_hyphen_values = true)]
    gate: String,
}

/// The `--gate` value: a number of σ in [3, 1e6], or None for `off`.
fn gate(text: &str) -> Result<Option<f64>> {
    if text.trim() == "off" {
        return Ok(None);
    }
    match text.trim().parse::<f64>() {
        Ok(g) if (3.0..=1e6).contains(&g) => Ok(Some(g)),
        Ok(_) => anyhow::bail!(
            "--gate {}: a gate is between 3 and 1e6 σ (below 3 it rejects good fixes: 0.3 % of honest innovations lie beyond 3 σ), or `off`",
            sinsmodel::io::lines::shown(text.trim())
        ),
        Err(_) => anyhow::bail!(
            "--gate `{text}`: expected a number of σ (e.g. 10) or `off`"
        ),
    }
}

/// Runs the command: one streamed pass (memory does not grow with the IMU or truth file);
/// states.txt and model_error.txt are written as the epochs come, innovations.txt at the end,
/// and the directory appears only when the run succeeded.
pub fn run(args: &FilterArgs) -> Result<()> {
    let model = Model::parse(&args.model)?;
    if let Some(r) = args.nav_rate {
        sinsmodel::nav::free_inertial::check_rate("--nav-rate", r)?;
    }
    let mut cfg = args.data.config(&model, false)?;
    cfg.gate = gate(&args.gate)?;
    let inputs = args.data.input_paths();
    let refs: Vec<&std::path::Path> = inputs.iter().map(|p| p.as_path()).collect();
    let out = OutputDir::create(&args.out, &refs, "filter")?;
    super::data::print_noise(&args.data)?;
    let mut inputs = args.data.open(&mut super::data::note)?;
    if args.in_memory {
        inputs.imu = inputs.imu.into_memory()?;
    }
    let start = inputs.start;
    sinsmodel::data::apply_opened(&mut cfg, &model, inputs.init_sigma, inputs.step_s);
    let provenance = super::command_line();
    let with_truth = inputs.truth.is_some();
    let mut files = EpochFiles::create(&out, &model, &cfg, &provenance, with_truth)?;
    let clock = RowClock::new(start.t, args.nav_rate, inputs.imu.interval());
    if let Some(n) = clock.capped_note("--nav-rate") {
        super::data::note(&format!("note: {n}"));
    }
    let mut nav = NavWriter::create(&out.file("nav.txt"), &model, clock, &provenance)?;
    let run = filter_pass(&model, &cfg, &mut inputs, &mut nav, &mut files)?;
    if let Some(tr) = inputs.truth.take() {
        tr.finish()?;
        check_truth_coverage(&files.errors, args.data.gnss_delay.as_deref())?;
    }
    let (t_first, t_last) = (inputs.imu.first_t(), inputs.imu.last_t());
    sinsmodel::data::check_inside(files.errors.len(), inputs.aid.len(), start.t, t_last)?;
    for (option, path, meas) in [
        ("--body-velocity", &args.data.body_velocity, "vel_body"),
        ("--attitude", &args.data.attitude, "att_ref"),
    ] {
        sinsmodel::data::dataset::check_reference_inside(
            option,
            path.as_deref(),
            run.innovations
                .iter()
                .filter(|i| i.meas == meas && i.component == 0)
                .count(),
            start.t,
            t_last,
        )?;
    }
    if let Some(w) = files.truth_disagreement() {
        super::data::note(&format!("warning: {w}"));
    }
    let errors = files.commit(&out, &run, &provenance)?;
    let nav_rows = nav.rows;
    // (said once nav.txt is known to be whole)
    nav.finish(&out.file("nav.png"))?;
    if let (Some(r), 1) = (args.nav_rate, nav_rows) {
        super::data::note(&format!(
            "note: --nav-rate {}: one row every {} s, longer than the {:.3} s filtered; nav.txt has only the start row",
            sinsmodel::io::units::shown_number(r),
            sinsmodel::io::units::shown_number(1.0 / r),
            t_last - start.t
        ));
    }
    let outage_rows = metrics::outage_drifts(&inputs.outages, &run, t_first, t_last)?;
    if !outage_rows.is_empty() {
        sinsmodel::io::atomic_file::write_text(
            &out.file("outages.json"),
            &outages_json(&provenance, &outage_rows)?,
        )?;
    }
    out.commit()?;
    print_summary(
        &inputs,
        &model,
        &cfg,
        &run,
        &outage_rows,
        with_truth.then_some(errors.as_slice()),
    );
    if let Some(w) = rest_claim_line(&args.data, &run) {
        eprintln!("{w}");
    }
    eprintln!(
        "wrote {} in {} (nav.txt: {nav_rows} rows)",
        written(with_truth, !inputs.outages.is_empty()).join(", "),
        args.out.display()
    );
    Ok(())
}

/// The streamed pass with a progress bar: `nav` and `files` hear every epoch; a run the filter
/// judges broken is an error.
fn filter_pass(
    model: &Model,
    cfg: &FilterConfig,
    inputs: &mut Dataset,
    nav: &mut NavWriter,
    files: &mut EpochFiles,
) -> Result<FilterRun> {
    let pb = progress::bar(1000, "filter");
    let mut epochs = sinsmodel::data::aid::with_rows(
        sinsmodel::data::aid::with_body_velocity(
            inputs.aid.epochs_outside(&inputs.outages),
            &inputs.body_velocity,
        ),
        &inputs.attitude,
    );
    let mut io = filter::StreamIo {
        samples: &mut inputs.imu,
        aiding: &mut epochs,
        truth: inputs
            .truth
            .as_mut()
            .map(|t| t as &mut dyn sinsmodel::io::truth::TruthLookup),
    };
    let run = filter::run_stream(
        model,
        cfg,
        inputs.start,
        &mut io,
        |f| pb.set_position((f * 1000.0) as u64),
        &mut |_| {},
        nav,
        &mut |r| files.record(r),
        false,
    )?;
    drop(epochs);
    pb.finish_and_clear();
    run.check().map_err(anyhow::Error::msg)?;
    Ok(run)
}

/// One update epoch's t [s] and model error e = φ̂ − φ north, east [rad] (None without a truth
/// row).
type EpochError = (f64, Option<[f64; 2]>);

/// Prints what was filtered, the NIS table, the outage table and, with truth, the model error of
/// the epochs (`errors`: t [s], e north, east [rad]).
fn print_summary(
    inputs: &Dataset,
    model: &Model,
    cfg: &FilterConfig,
    run: &FilterRun,
    outage_rows: &[metrics::OutageDrift],
    errors: Option<&[EpochError]>,
) {
    let (t_first, t_last) = (inputs.imu.first_t(), inputs.imu.last_t());
    let filtered_from = if inputs.skipped_samples > 0 {
        inputs.start.t
    } else {
        t_first
    };
    eprintln!(
        "filtered {} samples ({:.1} s) with {} ({} states, {} loop): {} scalar updates",
        inputs.imu.count() - inputs.skipped_samples,
        t_last - filtered_from,
        model.name,
        model.n(),
        cfg.mode.word(),
        run.innovations.len(),
    );
    eprint!("{}", nis_table(run));
    if let Some(w) = gated_line(run, cfg.gate) {
        eprintln!("{w}");
    }
    eprint!("{}", outage_table(outage_rows, t_first));
    if let Some(errors) = errors {
        eprint!("{}", model_error_line(errors));
    }
}

/// Mean NIS of a zero-velocity channel above which the vehicle may move (the parked laser-gyro
/// log, disturbed but parked, gives 3.19; a 0.15 m/s² creep 4127).
const REST_NIS_NOTE: f64 = 10.0;

/// Under `--static-aid` or `--zupt`, a line saying that velocity channels whose mean NIS is over
/// [`REST_NIS_NOTE`] also fit a vehicle that moves (a gentle creep or a turn on a curve passes
/// the IMU's rest checks); None otherwise.
fn rest_claim_line(data: &sinsmodel::data::DataOptions, run: &FilterRun) -> Option<String> {
    let claim = if data.static_aid.is_some() {
        "--static-aid"
    } else if data.zupt.is_some() {
        "--zupt"
    } else {
        return None;
    };
    let large: Vec<String> = filter::nis_by_channel(run)
        .iter()
        .filter(|c| c.channel.starts_with("vel_") && c.mean > REST_NIS_NOTE)
        .map(|c| format!("{} {}", c.channel, sinsmodel::explain::sig3(c.mean)))
        .collect();
    (!large.is_empty()).then(|| {
        format!(
            "note: {claim} says the vehicle stands still, and its zero-velocity updates' mean NIS ({}) is over {REST_NIS_NOTE}: \
             the vehicle may move (a creep under 0.3 m/s² or a steady turn passes the IMU's rest checks; \
             cut the files to the stretch at rest to tell), or the initial attitude is off (a heading 180° wrong)",
            large.join(", ")
        )
    })
}

/// The summary's line on the fixes the innovation gate `gate` [σ] rejected (None without a
/// gate), with a warning when they are more than 1 % of the updates: then the model or
/// the stated noise misses something, rather than the fixes being outliers.
fn gated_line(run: &FilterRun, gate: Option<f64>) -> Option<String> {
    let g = gate?;
    let k = run.gated.len();
    let all = k + run.innovations.len();
    let Some(first) = run.gated.first() else {
        return Some(format!(
            "gate: none of {all} scalar updates rejected (|nu| > {} sigma)",
            sinsmodel::io::units::shown_number(g)
        ));
    };
    let mut epochs: Vec<f64> = run.gated.iter().map(|i| i.t).collect();
    epochs.dedup();
    let mut line = format!(
        "gate: {k} of {all} scalar updates rejected (|nu| > {} sigma), at {} epoch{}, the first at t = {:.3} s ({} component {}); listed at the end of innovations.txt",
        sinsmodel::io::units::shown_number(g),
        epochs.len(),
        if epochs.len() == 1 { "" } else { "s" },
        first.t,
        first.meas,
        first.component
    );
    if run.gate_passed > 0 {
        line.push_str(&format!(
            "\nwarning: {} updates beyond the gate were applied all the same, each after {} epochs of its component rejected in a row: a longer run than outlier bursts have, so a step in the fixes that stays or a filter that is off there (the listed innovations show which)",
            run.gate_passed,
            sinsmodel::estimate::filter::GATE_RUN
        ));
    }
    if k * 100 > all {
        line.push_str(&format!(
            "\nwarning: the gate rejected {:.1} % of the updates: more than outliers do; the model or the stated noise misses something (the NIS above leaves them out: --gate off shows the filter that takes them)",
            100.0 * k as f64 / all as f64
        ));
    }
    Some(line)
}

/// The files of the output directory (model_error.txt `with_truth`, outages.json
/// `with_outages`).
fn written(with_truth: bool, with_outages: bool) -> Vec<&'static str> {
    let mut names = vec![
        "states.txt",
        "innovations.txt",
        "nav.txt",
        "nav_track.png",
        "nav_sigma.png",
    ];
    if with_truth {
        names.push("model_error.txt");
    }
    if with_outages {
        names.push("outages.json");
    }
    names
}

/// The truth must have a row at the update epochs: none is an error (another clock, or fixes
/// re-stamped by `delay`, `--gnss-delay`, between its rows?), some missing a warning.
fn check_truth_coverage(errors: &[(f64, Option<[f64; 2]>)], delay: Option<&str>) -> Result<()> {
    let covered = errors.iter().filter(|e| e.1.is_some()).count();
    if covered == 0 && !errors.is_empty() {
        let why = match delay {
            Some(d) => format!("--gnss-delay `{d}` re-stamps the fixes, and their epochs now fall between the truth's rows: give the truth at the IMU rate, or leave --truth out"),
            None => "is it on the IMU's and the aiding's clock?".to_string(),
        };
        anyhow::bail!(
            "--truth: the truth file has no row at any of the {} update epochs ({:.3} .. {:.3} s): {why}",
            errors.len(),
            errors[0].0,
            errors[errors.len() - 1].0
        );
    }
    if covered < errors.len() {
        eprintln!(
            "warning: the truth file has a row at only {covered} of the {} update epochs: model_error.txt and the model-error RMS cover those only",
            errors.len()
        );
    }
    Ok(())
}
