//! `sinsmodel allan --imu FILE [--json OUT] [--plot PREFIX]`: overlapping Allan deviation of the
//! six channels (rates Δθ/T [rad/s], Δv/T [m/s²], FRD body) with uncertainties, the noise fit, and
//! log-log plots.

use anyhow::Result;
use clap::Args;
use sinsmodel::estimate::allan::{self, SpanCheck, CHANNELS};
use sinsmodel::io::atomic_file::{self, Provenance};
use sinsmodel::report::allan::{fit_line, fit_span_note, plot_path, plots};
use std::path::PathBuf;

/// Arguments of `allan`.
#[derive(Args)]
pub struct AllanArgs {
    #[command(flatten)]
    src: super::data::ImuSource,
    /// Skip this many seconds at the start (e.g. a disturbed start).
    #[arg(long, default_value_t = 0.0)]
    skip: f64,
    /// Use at most this many seconds after --skip (e.g. the static part of a drive).
    #[arg(long)]
    seconds: Option<f64>,
    /// JSON output.
    #[arg(long)]
    json: Option<PathBuf>,
    /// Plot prefix: writes PREFIX_gyro.png and PREFIX_accel.png (default: next to --json).
    #[arg(long)]
    plot: Option<PathBuf>,
    /// Replace an existing output file that is not provably this command's earlier output (or
    /// that a sinsmodel run directory lists as its result).
    #[arg(long)]
    overwrite: bool,
    /// Run even when the span's mean specific force is not near 1 g (a unit or clock slip).
    #[arg(long)]
    force: bool,
}

/// Runs the command.
pub fn run(args: &AllanArgs) -> Result<()> {
    check_outputs(args)?;
    let data = args.src.read(&mut super::data::note)?;
    let dt = data.interval();
    if !(args.skip.is_finite() && args.skip >= 0.0) {
        anyhow::bail!("--skip {}: expected seconds >= 0", args.skip);
    }
    if let Some(s) = args.seconds {
        if !(s.is_finite() && s > 0.0) {
            anyhow::bail!("--seconds {s}: expected a positive number of seconds");
        }
    }
    let span = allan::span(&data, args.skip, args.seconds);
    if span.samples.len() < 16 {
        anyhow::bail!(
            "{}: fewer than 16 samples in the chosen span",
            args.src.imu.display()
        );
    }
    let f_g = allan::mean_specific_force_g(&span);
    if let Some(p) = f_g.and_then(allan::gravity_problem) {
        if !args.force {
            anyhow::bail!(
                "--imu {}: {p}; `sinsmodel imu-check` shows what was read; --force runs anyway",
                args.src.imu.display()
            );
        }
        eprintln!(
            "warning: --imu {}: {p} (--force given)",
            args.src.imu.display()
        );
    }
    let seen = allan::check_span(&span, dt);
    if let Some(w) = f_g.and_then(|f| allan::scale_off_at_rest(f, seen.moving == 0)) {
        eprintln!("warning: --imu {}: {w}", args.src.imu.display());
    }
    print_span_check(&seen, dt);
    let curves = allan::six_channels(&span, dt, seen.resamples());
    let out = allan::report(&curves, dt);
    for name in CHANNELS {
        println!("{}", fit_line(name, &out.fit[name]));
    }
    println!("{}", fit_span_note(&curves[0]));
    if let Some(j) = &args.json {
        atomic_file::write_text(
            j,
            &atomic_file::with_written_by(&serde_json::to_string_pretty(&out)?, "allan"),
        )?;
    }
    if let Some(p) = prefix_shown(args) {
        plots(&p, &curves)?;
    }
    print_written(args);
    Ok(())
}

/// Refuses outputs (--json, the plots) that are not this command's earlier ones, and a plot
/// prefix in a device or special directory.
fn check_outputs(args: &AllanArgs) -> Result<()> {
    if let Some(j) = &args.json {
        args.src
            .check_output("--json", j, Provenance::Json("allan"), args.overwrite)?;
    }
    if let Some(p) = prefix_shown(args) {
        // the prefix names files in a directory: not a device or a special path
        let dir = p
            .parent()
            .filter(|d| !d.as_os_str().is_empty())
            .unwrap_or(std::path::Path::new("."));
        if dir.starts_with("/dev") || dir.starts_with("/proc") || dir.starts_with("/sys") {
            anyhow::bail!(
                "--plot {}: the plots would go into {}, not a place for files",
                p.display(),
                dir.display()
            );
        }
        for suffix in ["gyro", "accel"] {
            let png = plot_path(&p, suffix);
            args.src
                .check_output("--plot", &png, Provenance::Png, args.overwrite)?;
        }
    }
    Ok(())
}

/// Warns when the span moves and notes a jittered clock's resampling (`dt` [s]: the interval).
fn print_span_check(seen: &SpanCheck, dt: f64) {
    if seen.moving > 0 {
        eprintln!(
            "warning: {} of the {} ten-second windows of the chosen span are not at rest (specific-force spread > {} m/s^2 or angular-rate spread > {:.2} deg/s): \
             the Allan deviation of moving data measures the motion, not the sensor; choose a stretch at rest with --skip / --seconds (`sinsmodel align` finds one)",
            seen.moving,
            seen.windows,
            sinsmodel::estimate::align::STATIC_F_SPREAD,
            sinsmodel::estimate::align::STATIC_W_SPREAD.to_degrees()
        );
    }
    if seen.resamples() {
        eprintln!(
            "note: the clock jitters ({:.2} % RMS of the {dt:.6} s interval): the increments are integrated in time and resampled to a uniform {dt:.6} s grid",
            100.0 * seen.jitter
        );
    }
}

/// Says which files were written.
fn print_written(args: &AllanArgs) {
    match (&args.json, &prefix_shown(args)) {
        (Some(j), Some(p)) => eprintln!(
            "wrote {}, {}_gyro.png and {}_accel.png",
            j.display(),
            p.display(),
            p.display()
        ),
        (None, Some(p)) => eprintln!(
            "wrote {}_gyro.png and {}_accel.png",
            p.display(),
            p.display()
        ),
        (Some(j), None) => eprintln!("wrote {}", j.display()),
        (None, None) => {
            eprintln!("(no files written: --json or --plot writes the curves and plots)")
        }
    }
}

/// The plot prefix: --plot, else the --json file without its extension.
fn prefix_shown(args: &AllanArgs) -> Option<PathBuf> {
    args.plot
        .clone()
        .or_else(|| args.json.as_ref().map(|j| j.with_extension("")))
}
