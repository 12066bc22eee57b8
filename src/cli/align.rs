//! `sinsmodel align --imu FILE [--lat DEG] [--skip S] [--seconds N] [--json OUT]`.

use anyhow::Result;
use clap::Args;
use sinsmodel::estimate::align;
use sinsmodel::io::atomic_file::{self, Provenance};
use sinsmodel::report::align as report;
use std::path::PathBuf;

/// Arguments of `align`.
#[derive(Args)]
pub struct AlignArgs {
    #[command(flatten)]
    src: super::data::ImuSource,
    /// Latitude [deg]; estimated from the Earth-rate and gravity directions when omitted.
    #[arg(long, allow_hyphen_values = true)]
    lat: Option<f64>,
    /// Longitude [deg] (for the known-position updates).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    lon: f64,
    /// Height [m].
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    h: f64,
    /// Prior 1-σ of the gyro biases in the fine alignment [deg/h] (bounds the heading σ).
    #[arg(long, default_value_t = 0.2)]
    gyro_bias_sigma: f64,
    /// Skip this many seconds after the first sample (e.g. a disturbed start), as allan and
    /// imu-check do; the stretch at rest is searched in what follows, and the times printed
    /// still count from the first sample.
    #[arg(long, default_value_t = 0.0)]
    skip: f64,
    /// Use at most this many seconds of the stretch at rest.
    #[arg(long)]
    seconds: Option<f64>,
    /// JSON output {roll_deg, pitch_deg, heading_deg, heading_sigma_deg, lat_deg, lat_sigma_deg, …}.
    #[arg(long)]
    json: Option<PathBuf>,
    /// Replace an existing output file that is not provably this command's earlier output (or
    /// that a sinsmodel run directory lists as its result).
    #[arg(long)]
    overwrite: bool,
    /// The old name of --overwrite, refused: --force runs past data checks and replaces no file.
    #[arg(long, hide = true)]
    force: bool,
}

/// Runs the command.
pub fn run(args: &AlignArgs) -> Result<()> {
    super::data::refuse_force_for_outputs(args.force)?;
    check_args(args)?;
    if let Some(j) = &args.json {
        args.src
            .check_output("--json", j, Provenance::Json("align"), args.overwrite)?;
    }
    let whole = args.src.read(&mut super::data::note)?;
    // the samples from --skip on (as allan takes them); the rest is searched there
    let data = sinsmodel::estimate::allan::span(&whole, args.skip, None);
    if data.samples.is_empty() {
        anyhow::bail!(
            "--skip {}: the data last only {:.3} s",
            args.skip,
            whole.samples.last().map(|s| s.t).unwrap_or(0.0) - whole.samples[0].t
        );
    }
    let d = std::f64::consts::PI / 180.0;
    let mut a = align::align(
        &data,
        args.lat.map(|l| l * d),
        args.seconds,
        args.lon * d,
        args.h,
        args.gyro_bias_sigma * d / 3600.0,
    )?;
    // the start of the rest from the first sample of the file, not of the span after --skip
    a.skipped_s = ((a.skipped_s + data.samples[0].t - whole.samples[0].t) * 1e6).round() / 1e6;
    for line in report::lines(&a, args.lat.is_some()) {
        println!("{line}");
    }
    if let Some(j) = &args.json {
        atomic_file::write_text(
            j,
            &atomic_file::with_written_by(&serde_json::to_string_pretty(&a)?, "align"),
        )?;
        eprintln!("wrote {}", j.display());
    }
    Ok(())
}

/// Refuses a latitude, longitude, height, gyro-bias σ, skip or length out of range.
fn check_args(args: &AlignArgs) -> Result<()> {
    if let Some(l) = args.lat {
        if !(l.is_finite() && (-89.0..=89.0).contains(&l)) {
            anyhow::bail!("--lat {l} must be within ±89°");
        }
    }
    use sinsmodel::io::bounds;
    if let Some(p) = bounds::lon_deg(args.lon) {
        anyhow::bail!("--lon: {p}");
    }
    if let Some(p) = bounds::height_m(args.h) {
        anyhow::bail!("--h: {p}");
    }
    if !(args.gyro_bias_sigma.is_finite()
        && args.gyro_bias_sigma > 0.0
        && args.gyro_bias_sigma <= 3.6e6)
    {
        anyhow::bail!(
            "--gyro-bias-sigma {}: expected a positive gyro-bias sigma in deg/h (at most 3.6e6, i.e. 1000 deg/s)",
            args.gyro_bias_sigma
        );
    }
    if !(args.skip.is_finite() && args.skip >= 0.0) {
        anyhow::bail!("--skip {}: expected seconds >= 0", args.skip);
    }
    if let Some(s) = args.seconds {
        if !(s.is_finite() && s > 0.0) {
            anyhow::bail!("--seconds {s}: expected a positive number of seconds");
        }
    }
    Ok(())
}
