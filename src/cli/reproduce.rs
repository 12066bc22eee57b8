//! `sinsmodel reproduce [--quick] [--priors-grid] [--consistency] --out DIR`: the paper's §3 and
//! Fig. 1 (DESIGN §6) with P28 and P31, figures, the priors study and the consistency check.

use anyhow::Result;
use clap::Args;
use sinsmodel::experiment::reproduce::{self, Case, GridPoint, Priors};
use sinsmodel::io::atomic_file::{self, OutputDir};
use sinsmodel::report::progress;
use sinsmodel::report::reproduce::{self as report, Results};
use sinsmodel::sim::simulator::SimOutput;
use std::path::PathBuf;

/// Arguments of `reproduce`.
#[derive(Args)]
pub struct ReproduceArgs {
    /// Shortened cases (10 min each) for CI.
    #[arg(long)]
    quick: bool,
    /// Also run the priors study (ratio over a grid of σ_d, σ_∇ and φ₀) on the sine case.
    #[arg(long)]
    priors_grid: bool,
    /// Run the 20-seed Monte Carlo consistency check (NEES, NIS) instead of the cases.
    #[arg(long)]
    consistency: bool,
    /// Seed.
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u64).range(0..=1_000_000_000_000))]
    seed: u64,
    /// Output DIRECTORY (not a file; navigate's --out is a file): results.json, results.md and
    /// the figures. The shipped full run in docs/reproduce/ is refreshed with `sinsmodel
    /// reproduce --priors-grid --out docs/reproduce`.
    #[arg(long, default_value = "out/reproduce")]
    out: PathBuf,
}

/// Runs the command.
pub fn run(args: &ReproduceArgs) -> Result<()> {
    // one run's outputs, complete or none; a directory sinsmodel did not write is left alone
    let dir = OutputDir::create(&args.out, &[], "reproduce")?;
    if args.consistency {
        return consistency(args, dir);
    }
    let priors = Priors::default();
    let mut results = Vec::new();
    let mut grid = Vec::new();
    eprintln!("{}", report::table_intro(args.quick));
    eprintln!("{}", report::table_header());
    for case in reproduce::cases(args.quick, args.seed) {
        let pb = progress::bar(1000, case.name);
        let (res, sim, runs) = reproduce::run_case(&case, &priors, args.seed, |_, f| {
            pb.set_position((f * 1000.0) as u64)
        })?;
        pb.finish_and_clear();
        eprintln!("{}", report::table_row(&res));
        report::case_figures(&dir, case.name, &runs)?;
        if args.priors_grid && case.name == "sine" {
            grid = priors_grid(&case, &sim, args.seed)?;
        }
        results.push(res);
    }
    let out = Results {
        cases: results,
        priors_grid: grid,
        notes: report::notes(&priors),
    };
    atomic_file::write_text(
        &dir.file("results.json"),
        &serde_json::to_string_pretty(&out)?,
    )?;
    atomic_file::write_text(&dir.file("results.md"), &report::markdown(&out, args.quick))?;
    dir.commit()?;
    if args.quick {
        eprintln!(
            "reference: the full run (2 h cases) is in docs/reproduce/results.md. Its ratios are \
             smaller: P28's error saturates within minutes at the tilt that absorbs the \
             unmodelled d f^2, while P31's residual error (the slowly observable part: gyro \
             biases, the remaining error of d) keeps growing over the hours."
        );
    }
    eprintln!(
        "wrote results.json, results.md and the figures (*_model_error_*.png{}) in {}",
        if out.cases.iter().any(|c| c.name == "fig1") {
            ", fig1_position_error.png"
        } else {
            ""
        },
        args.out.display()
    );
    Ok(())
}

/// The priors study on the sine `case` (library: `experiment::reproduce::priors_grid`), each
/// point printed as it comes.
fn priors_grid(case: &Case, sim: &SimOutput, seed: u64) -> Result<Vec<GridPoint>> {
    let pb = progress::bar(11, "priors");
    let grid = reproduce::priors_grid(case, sim, seed, |k, _, g| {
        pb.set_position(k as u64);
        pb.suspend(|| eprintln!("{}", report::grid_line(g)));
    })?;
    pb.finish_and_clear();
    Ok(grid)
}

/// The consistency Monte Carlo (library: `experiment::reproduce::consistency`), printed and plotted.
fn consistency(args: &ReproduceArgs, dir: OutputDir) -> Result<()> {
    let pb = progress::bar(20, "monte carlo");
    let out = reproduce::consistency(args.quick, |k, _| pb.set_position(k as u64))?;
    pb.finish_and_clear();
    for line in report::consistency_lines(&out) {
        eprintln!("{line}");
    }
    report::consistency_figure(&dir, &out)?;
    atomic_file::write_text(
        &dir.file("consistency.json"),
        &serde_json::to_string_pretty(&out)?,
    )?;
    dir.commit()?;
    eprintln!(
        "wrote consistency.json and consistency_nees.png in {}",
        args.out.display()
    );
    Ok(())
}
