//! `sinsmodel imu-check --imu FILE [--imu-format F] [--lat DEG] [--skip S] [--seconds S]
//! [--tilted] [--json OUT]`: what the log holds as read; exit 2 when it is implausible.

use anyhow::{bail, Result};
use clap::Args;
use sinsmodel::estimate::imu_check;
use sinsmodel::io::atomic_file::{self, Provenance};
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
    force: bool,
}

/// Runs the command.
pub fn run(args: &ImuCheckArgs) -> Result<()> {
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
    if let Some(j) = &args.json {
        args.src
            .check_output("--json", j, Provenance::Json("imu-check"), args.force)?;
    }
    let data = args.src.read(&mut super::data::note)?;
    let c = imu_check::check(
        &data,
        args.lat.map(f64::to_radians),
        args.skip,
        args.seconds,
        args.tilted,
    );
    println!(
        "{} samples over {:.3} s: {:.3} Hz (median interval {:.6} s; shortest {:.6} s, longest {:.6} s; jitter RMS {:.2e} s; {} gaps)",
        c.samples,
        c.duration_s,
        c.rate_hz,
        1.0 / c.rate_hz,
        c.interval_min_s,
        c.interval_max_s,
        c.jitter_rms_s,
        c.gaps
    );
    if c.f_spread_mps2.is_finite() {
        println!(
            "window {:.3}–{:.3} s: specific force FRD ({:.4}, {:.4}, {:.4}) m/s² (spread {:.3} m/s² RMS{}), |f| = {}× local gravity {:.4} m/s²",
            c.window_s[0],
            c.window_s[1],
            c.f_mean_mps2[0],
            c.f_mean_mps2[1],
            c.f_mean_mps2[2],
            c.f_spread_mps2,
            if c.is_static { ", static" } else { ", moving" },
            sinsmodel::explain::sig3(c.gravity_ratio),
            c.gravity_mps2
        );
        let d = 180.0 / std::f64::consts::PI;
        println!(
            "angular rate FRD ({:.3e}, {:.3e}, {:.3e}) deg/h, |ω| = {}× Earth rate",
            c.w_mean_radps[0] * d * 3600.0,
            c.w_mean_radps[1] * d * 3600.0,
            c.w_mean_radps[2] * d * 3600.0,
            sinsmodel::explain::sig3(c.earth_rate_ratio)
        );
    } else {
        println!(
            "window {:.3}–{:.3} s: no samples in it",
            c.window_s[0], c.window_s[1]
        );
    }
    if c.is_static {
        println!(
            "static attitude: roll {:.3}°, pitch {:.3}°, heading {}",
            c.roll_deg,
            c.pitch_deg,
            match c.heading_deg {
                Some(h) => format!("{h:.1}° (gyrocompass, coarse)"),
                None => "not resolved by these gyros".into(),
            }
        );
    }
    for n in &c.notes {
        println!("note: {n}");
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
    if c.is_static {
        println!(
            "plausible: gravity and attitude as expected for a static IMU with these units and axes; {}",
            if (0.5..2.0).contains(&c.earth_rate_ratio) {
                "Earth rate as expected".to_string()
            } else {
                format!(
                    "Earth rate not resolved (the gyro bias makes |ω| {}× Earth rate: gyro units checked only for gross errors)",
                    sinsmodel::explain::sig3(c.earth_rate_ratio)
                )
            }
        );
    } else {
        println!("sampling read; units and axes not checked (no static stretch in the window)");
    }
    Ok(())
}
