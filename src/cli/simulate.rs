//! `sinsmodel simulate SCENARIO.toml --out DIR [--force] [--mat]`.

use anyhow::{bail, Result};
use clap::Args;
use sinsmodel::io::atomic_file::{self, OutputDir};
use sinsmodel::io::{aiding, imu, truth};
use sinsmodel::report::progress;
use sinsmodel::sim::scenario::Scenario;
use sinsmodel::sim::simulator::simulate;
use std::path::PathBuf;

/// Arguments of `simulate`.
#[derive(Args)]
pub struct SimulateArgs {
    /// Scenario file (TOML; see scenarios/).
    scenario: PathBuf,
    /// Output directory: imu.txt, gnss.txt (with [gnss]), truth.txt and a copy of the scenario;
    /// written complete or not at all, replacing only an earlier sinsmodel run's directory.
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

/// Bytes of memory per IMU sample while simulating, and of text per sample in imu.txt
/// (measured: ~55 B and ~150 B).
const MEM_PER_SAMPLE: f64 = 60.0;
const TEXT_PER_SAMPLE: f64 = 160.0;
/// Above this many bytes of memory or output, `--force` is needed.
const LIMIT_BYTES: f64 = 4e9;
/// Vibration-term evaluations per second on one core (measured here: 4.7e8/s for 2000 random
/// components at 100 Hz with 320 sub-steps).
const EVALUATIONS_PER_S: f64 = 4e8;
/// Above this many vibration-term evaluations (about 10 min), `--force` is needed.
const LIMIT_EVALUATIONS: f64 = 2.4e11;

/// Runs the command.
pub fn run(args: &SimulateArgs) -> Result<()> {
    let sc = Scenario::load(&args.scenario)?;
    for w in &sc.warnings {
        eprintln!("warning: {w}");
    }
    let samples = sc.duration() * sc.imu_rate_hz;
    let (mem, text) = (samples * MEM_PER_SAMPLE, samples * TEXT_PER_SAMPLE);
    if (mem > LIMIT_BYTES || text > LIMIT_BYTES) && !args.force {
        bail!(
            "{}: {:.3e} IMU samples ({:.0} s at {} Hz) need about {:.1} GB of memory and write about {:.1} GB of text; \
             shorten the scenario or pass --force",
            args.scenario.display(),
            samples,
            sc.duration(),
            sc.imu_rate_hz,
            mem / 1e9,
            text / 1e9
        );
    }
    // the time it would take: vibration terms at every quadrature node of every sub-step
    let (terms, sub) = sc.vibration_work();
    let evaluations = samples * sub * 3.0 * terms.max(1.0);
    if evaluations > LIMIT_EVALUATIONS && !args.force {
        bail!(
            "{}: {:.0} vibration terms evaluated at {:.0} sub-steps per IMU sample ({:.3e} evaluations, roughly {:.0} min on one core at {:.0e} per second); \
             fewer random components, a lower band edge or a higher imu_rate_hz shortens it; pass --force to run anyway",
            args.scenario.display(),
            terms,
            sub,
            evaluations,
            evaluations / EVALUATIONS_PER_S / 60.0,
            EVALUATIONS_PER_S
        );
    }
    let out = OutputDir::create(&args.out, &[args.scenario.as_path()], "simulate")?;
    let pb = progress::bar(1000, "simulate");
    let sim = simulate(&sc, |f| pb.set_position((f * 1000.0) as u64));
    pb.finish_and_clear();
    check_output(&args.scenario, &sim)?;
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
    if args.mat {
        use sinsmodel::io::readers::matlab;
        let bytes = (sim.imu.samples.len() * matlab::IMU_COLUMNS
            + sim.truth.len() * matlab::AVP_COLUMNS)
            * 8;
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
        )?;
    }
    atomic_file::write_text(&out.file("scenario.toml"), &sc.text)?;
    out.commit()?;
    eprintln!(
        "simulated {} IMU samples ({:.1} s at {} Hz{}), {} truth rows, {} GNSS fixes{} into {}{}",
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
        args.out.display(),
        if args.mat {
            " (and data.mat: arrays imu and avp)"
        } else {
            ""
        }
    );
    Ok(())
}

/// What simulate writes must be what its readers accept: a trajectory that runs past a pole or
/// beyond 1e4 m/s, or increments beyond what any IMU measures, are refused with the time (a
/// scenario can ask for them within each of its own bounds).
fn check_output(
    scenario: &std::path::Path,
    sim: &sinsmodel::sim::simulator::SimOutput,
) -> Result<()> {
    use sinsmodel::io::bounds;
    use sinsmodel::io::imu_stream::{MAX_FORCE, MAX_RATE};
    let name = scenario.display();
    for r in &sim.truth {
        let d = 180.0 / std::f64::consts::PI;
        let problem = bounds::lat_deg(r.lat * d)
            .or_else(|| bounds::height_m(r.h))
            .or_else(|| {
                (r.v.norm() > 1e4).then(|| format!("speed {:.0} m/s beyond 1e4 m/s", r.v.norm()))
            });
        if let Some(p) = problem {
            bail!("{name}: the simulated trajectory is not one the readers accept at t = {:.3} s: {p} (a path across a pole, or an acceleration or vibration too large for its duration)", r.t);
        }
    }
    let mut prev = sim.start.t;
    for s in &sim.imu.samples {
        let dt = s.t - prev;
        prev = s.t;
        let (w, f) = (s.dtheta.norm() / dt, s.dv.norm() / dt);
        if !(w.is_finite() && f.is_finite()) || w > MAX_RATE || f > MAX_FORCE {
            bail!(
                "{name}: at t = {:.3} s the simulated IMU measures {w:.3e} rad/s and {f:.3e} m/s^2, beyond any IMU (<= {MAX_RATE} rad/s, <= 2000 g): an injected error or a motion too large",
                s.t
            );
        }
    }
    Ok(())
}
