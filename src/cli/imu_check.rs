//! `sinsmodel imu-check --imu FILE [--imu-format F] [--lat DEG] [--skip S] [--seconds S]
//! [--tilted] [--json OUT]`: what the log holds as read; exit 2 when it is implausible.

use anyhow::{bail, Result};
use clap::Args;
use sinsmodel::estimate::imu_check;
use sinsmodel::io::atomic_file::{self, Provenance};
use sinsmodel::report::imu_check as report;
use std::path::PathBuf;

/// Arguments of `imu-check`.
#[derive(Args)]
pub struct ImuCheckArgs {
    #[command(flatten)]
    src: super::data::ImuSource,
    /// Latitude [deg] for local gravity (default 45°, within 0.3 % of any latitude).
    #[arg(long, allow_hyphen_values = true)]
    lat: Option<f64>,
    /// Start of the static window after the first sample [s].
    #[arg(long, default_value_t = 0.0)]
    skip: f64,
    /// Length of the static window [s].
    #[arg(long, default_value_t = 10.0)]
    seconds: f64,
    /// The IMU is mounted far from level on purpose (no axis warning beyond 45° of tilt).
    #[arg(long)]
    tilted: bool,
    /// JSON output of everything checked.
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
pub fn run(args: &ImuCheckArgs) -> Result<()> {
    super::data::refuse_force_for_outputs(args.force)?;
    check_args(args)?;
    if let Some(j) = &args.json {
        args.src
            .check_output("--json", j, Provenance::Json("imu-check"), args.overwrite)?;
    }
    let data = args.src.read(&mut super::data::note)?;
    let c = imu_check::check(
        &data,
        args.lat.map(f64::to_radians),
        args.skip,
        args.seconds,
        args.tilted,
    );
    for line in report::lines(&c) {
        println!("{line}");
    }
    if let Some(j) = &args.json {
        atomic_file::write_text(
            j,
            &atomic_file::with_written_by(&serde_json::to_string_pretty(&c)?, "imu-check"),
        )?;
        eprintln!("wrote {}", j.display());
    }
    if !c.problems.is_empty() {
        bail!(
            "{}: implausible as read:\n  - {}",
            args.src.imu.display(),
            c.problems.join("\n  - ")
        );
    }
    println!("{}", report::verdict(&c));
    Ok(())
}

/// Refuses a latitude, skip or window length out of range.
fn check_args(args: &ImuCheckArgs) -> Result<()> {
    if let Some(l) = args.lat {
        if !(l.is_finite() && l.abs() < 90.0) {
            bail!("--lat {l}: expected a latitude in degrees within (-90, 90)");
        }
    }
    if !(args.skip.is_finite() && args.skip >= 0.0) {
        bail!("--skip {}: expected seconds >= 0", args.skip);
    }
    if !(args.seconds.is_finite() && args.seconds > 0.0) {
        bail!("--seconds {}: expected seconds > 0", args.seconds);
    }
    Ok(())
}
