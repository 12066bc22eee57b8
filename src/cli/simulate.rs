//! `sinsmodel simulate SCENARIO.toml --out DIR [--force] [--mat]`.

use anyhow::{bail, Result};
use clap::Args;
use sinsmodel::io::atomic_file::{self, OutputDir};
use sinsmodel::io::{aiding, imu, truth};
use sinsmodel::report::progress;
use sinsmodel::sim::budget::{self, Budget};
use sinsmodel::sim::scenario::Scenario;
use sinsmodel::sim::simulator::{simulate, SimOutput};
use std::path::PathBuf;

/// Arguments of `simulate`.
#[derive(Args)]
pub struct SimulateArgs {
    /// Scenario file (TOML; see scenarios/).
    scenario: PathBuf,
    /// Output DIRECTORY (not a file; navigate's --out is a file): imu.txt, gnss.txt (with
    /// [gnss]), truth.txt and a copy of the scenario; written complete or not at all, replacing
    /// only an earlier sinsmodel run's directory.
    #[arg(long)]
    out: PathBuf,
    /// Simulate even when the run would exceed the size limit (memory or output size).
    #[arg(long)]
    force: bool,
    /// Also write data.mat as PSINS users keep data: `imu` = [wm(3) vm(3) t] increments,
    /// right-forward-up, and `avp` = the truth (MATLAB level 5; read as --imu DIR/data.mat:imu).
    #[arg(long)]
    mat: bool,
}

/// Runs the command.
pub fn run(args: &SimulateArgs) -> Result<()> {
    let sc = Scenario::load(&args.scenario)?;
    for w in &sc.warnings {
        eprintln!("warning: {w}");
    }
    check_budget(args, &sc)?;
    let out = OutputDir::create(&args.out, &[args.scenario.as_path()], "simulate")?;
    let pb = progress::bar(1000, "simulate");
    let sim = simulate(&sc, |f| pb.set_position((f * 1000.0) as u64));
    pb.finish_and_clear();
    if let Some(p) = budget::unreadable(&sim) {
        bail!("{}: {p}", args.scenario.display());
    }
    let header = format!(
        "{} (scenario `{}`, seed {})",
        super::command_line(),
        sc.name.escape_debug(),
        sc.seed
    );
    imu::write_text(&out.file("imu.txt"), &sim.imu, &header)?;
    truth::write(&out.file("truth.txt"), &sim.truth, &header)?;
    if !sim.gnss.is_empty() {
        aiding::write_with_velocity(
            &out.file("gnss.txt"),
            &sim.gnss,
            sim.gnss_velocity.as_deref(),
            &header,
        )?;
    }
    if let Some(bv) = &sim.body_velocity {
        aiding::write_body_velocity(&out.file("reference.txt"), bv, &header)?;
    }
    if let Some(a) = &sim.attitude {
        aiding::write_attitude(&out.file("attitude.txt"), a, &header)?;
    }
    if args.mat {
        write_mat(&out, &sim)?;
    }
    atomic_file::write_text(&out.file("scenario.toml"), &sc.text)?;
    out.commit()?;
    print_summary(args, &sc, &sim);
    Ok(())
}

/// Refuses (unless --force) a run that would exceed the size limit (memory or output) or take
/// too long (vibration terms at every quadrature node of every sub-step).
fn check_budget(args: &SimulateArgs, sc: &Scenario) -> Result<()> {
    let b = Budget::of(sc);
    if b.too_large() && !args.force {
        bail!(
            "{}: {:.3e} IMU samples ({:.0} s at {} Hz) need about {:.1} GB of memory and write about {:.1} GB of text; \
             shorten the scenario or pass --force",
            args.scenario.display(),
            b.samples,
            sc.duration(),
            sc.imu_rate_hz,
            b.memory_bytes / 1e9,
            b.text_bytes / 1e9
        );
    }
    if b.too_long() && !args.force {
        bail!(
            "{}: {:.0} vibration terms evaluated at {:.0} sub-steps per IMU sample ({:.3e} evaluations, roughly {:.0} min on one core at {:.0e} per second); \
             fewer random components, a lower band edge or a higher imu_rate_hz shortens it; pass --force to run anyway",
            args.scenario.display(),
            b.terms,
            b.sub_steps,
            b.evaluations,
            b.minutes(),
            budget::EVALUATIONS_PER_S
        );
    }
    Ok(())
}

/// Writes data.mat as PSINS users keep data: `imu` = [wm(3) vm(3) t] increments,
/// right-forward-up, and `avp` = the truth (MATLAB level 5).
fn write_mat(out: &OutputDir, sim: &SimOutput) -> Result<()> {
    use sinsmodel::io::readers::matlab;
    let bytes =
        (sim.imu.samples.len() * matlab::IMU_COLUMNS + sim.truth.len() * matlab::AVP_COLUMNS) * 8;
    if bytes as u64 > matlab::MAX_MAT_BYTES || sim.imu.samples.len() > i32::MAX as usize {
        bail!("--mat: {bytes} bytes of arrays exceed the {} bytes a .mat is read with here; shorten the scenario", matlab::MAX_MAT_BYTES);
    }
    let imu_rows = matlab::psins_imu_rows(&sim.imu);
    let avp_rows = matlab::psins_avp_rows(&sim.truth);
    matlab::write(
        &out.file("data.mat"),
        &[
            ("imu", &imu_rows, matlab::IMU_COLUMNS),
            ("avp", &avp_rows, matlab::AVP_COLUMNS),
        ],
    )
}

/// Prints what was simulated and where it went.
fn print_summary(args: &SimulateArgs, sc: &Scenario, sim: &SimOutput) {
    eprintln!(
        "simulated {} IMU samples ({:.1} s at {} Hz{}), {} truth rows, {} GNSS fixes{}{} into {}{}",
        sim.imu.samples.len(),
        sim.imu.duration(),
        sc.imu_rate_hz,
        if sc.clock_jitter_periods > 1 {
            format!(
                ", a jittered clock: each sample spans 1 to {} periods",
                sc.clock_jitter_periods
            )
        } else {
            String::new()
        },
        sim.truth.len(),
        sim.gnss.len(),
        if sim.gnss_velocity.is_some() {
            " with velocities"
        } else {
            ""
        },
        sim.body_velocity
            .as_ref()
            .map(|b| format!(", {} body-velocity reference rows (reference.txt)", b.len()))
            .unwrap_or_default()
            + &sim
                .attitude
                .as_ref()
                .map(|a| format!(", {} attitude reference rows (attitude.txt)", a.len()))
                .unwrap_or_default(),
        args.out.display(),
        if args.mat {
            " (and data.mat: arrays imu and avp)"
        } else {
            ""
        }
    );
}
