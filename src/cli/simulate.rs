//! `sinsmodel simulate SCENARIO.toml --out DIR`.

use anyhow::{Context, Result};
use clap::Args;
use sinsmodel::io::{aiding, atomic_file, imu, truth};
use sinsmodel::report::progress;
use sinsmodel::sim::scenario::Scenario;
use sinsmodel::sim::simulator::simulate;
use std::path::PathBuf;

/// Arguments of `simulate`.
#[derive(Args)]
pub struct SimulateArgs {
    /// Scenario file (TOML; see scenarios/).
    scenario: PathBuf,
    /// Output directory: imu.txt, gnss.txt, truth.txt and a copy of the scenario.
    #[arg(long)]
    out: PathBuf,
}

/// Runs the command.
pub fn run(args: &SimulateArgs) -> Result<()> {
    let sc = Scenario::load(&args.scenario)?;
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("cannot create {}", args.out.display()))?;
    let pb = progress::bar(1000, "simulate");
    let sim = simulate(&sc, |f| pb.set_position((f * 1000.0) as u64));
    pb.finish_and_clear();
    let header = format!(
        "sinsmodel simulate {} (scenario `{}`, seed {})",
        args.scenario.display(),
        sc.name,
        sc.seed
    );
    imu::write_text(&args.out.join("imu.txt"), &sim.imu, &header)?;
    truth::write(&args.out.join("truth.txt"), &sim.truth, &header)?;
    if !sim.gnss.is_empty() {
        aiding::write(&args.out.join("gnss.txt"), &sim.gnss, &header)?;
    }
    atomic_file::write_text(&args.out.join("scenario.toml"), &sc.text)?;
    eprintln!(
        "simulated {} IMU samples ({:.1} s at {} Hz), {} truth rows, {} GNSS fixes into {}",
        sim.imu.samples.len(),
        sim.imu.duration(),
        sc.imu_rate_hz,
        sim.truth.len(),
        sim.gnss.len(),
        args.out.display()
    );
    Ok(())
}
