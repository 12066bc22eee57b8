//! The `sinsmodel` command line.

use clap::{Parser, Subcommand};
use std::process::ExitCode;

mod cli;

/// Error-model compiler and model-discovery tool for strapdown inertial navigation systems.
#[derive(Parser)]
#[command(name = "sinsmodel", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Inspect the compiled models: list presets and terms, show one model.
    Model {
        #[command(subcommand)]
        action: cli::model::ModelAction,
    },
    /// Print A(t) and H of a model at one point (JSON), for the CasADi check.
    Jacobian(cli::jacobian::JacobianArgs),
    /// Simulate a scenario: IMU increments with injected errors, GNSS fixes and truth.
    Simulate(cli::simulate::SimulateArgs),
    /// Run the strapdown navigator on an IMU file.
    Navigate(cli::navigate::NavigateArgs),
    /// Run navigator + error-state Kalman filter with any model on IMU and position aiding files.
    Filter(cli::filter::FilterArgs),
    /// Static alignment: roll, pitch, heading with σ, latitude when not given.
    Align(cli::align::AlignArgs),
    /// What an IMU log holds as read (rate, jitter, gaps, gravity and Earth rate, attitude):
    /// catches a wrong unit, axis or clock in a format description.
    #[command(name = "imu-check")]
    ImuCheck(cli::imu_check::ImuCheckArgs),
    /// Overlapping Allan deviation of the six IMU channels, noise fit and plots.
    Allan(cli::allan::AllanArgs),
    /// Throughput of navigation + filter jobs (generated kernels vs dense), peak memory.
    Bench(cli::bench::BenchArgs),
    /// What the model gets wrong on the data, the missing error term, the extended model and
    /// its gain; without data options, the embedded demo (the paper's case with d hidden).
    Explain(cli::explain::ExplainArgs),
    /// How well explain finds hidden effects: seeded cases in parallel, power curve, false alarms.
    #[command(name = "explain-eval")]
    ExplainEval(cli::explain_eval::EvalArgs),
    /// Reproduce the paper's experiments (P28 vs P31), with figures, priors study, consistency.
    Reproduce(cli::reproduce::ReproduceArgs),
}

fn main() -> ExitCode {
    // Rust ignores SIGPIPE, so a closed pipe (`sinsmodel … | head`) would make println! panic;
    // restore the default: the process ends quietly when its reader goes away.
    #[cfg(unix)]
    // SAFETY: called first in main, before any thread exists; only resets a signal disposition.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    // A full disk or a closed file behind stdout/stderr makes println!/eprintln! panic: end with
    // status 2 and one line (when stderr still takes it), not a panic message.
    let default_hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        let msg = info
            .payload()
            .downcast_ref::<String>()
            .map(String::as_str)
            .or_else(|| info.payload().downcast_ref::<&str>().copied())
            .unwrap_or("");
        if msg.starts_with("failed printing to") {
            use std::io::Write;
            let _ = writeln!(std::io::stderr(), "error: cannot write the output: {msg}");
            std::process::exit(2);
        }
        default_hook(info);
    }));
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Model { action } => cli::model::run(action),
        Command::Jacobian(args) => cli::jacobian::run(&args),
        Command::Simulate(args) => cli::simulate::run(&args),
        Command::Navigate(args) => cli::navigate::run(&args),
        Command::Reproduce(args) => cli::reproduce::run(&args),
        Command::Filter(args) => cli::filter::run(&args),
        Command::Explain(args) => cli::explain::run(&args),
        Command::ExplainEval(args) => cli::explain_eval::run(&args),
        Command::Bench(args) => cli::bench::run(&args),
        Command::Allan(args) => cli::allan::run(&args),
        Command::ImuCheck(args) => cli::imu_check::run(&args),
        Command::Align(args) => cli::align::run(&args),
    };
    // `sinsmodel bench` measures its child processes' peak memory this way: a parent's rusage
    // counts the parent's own pages at fork and exec, the child's VmHWM does not
    if std::env::var_os("SINSMODEL_REPORT_PEAK_RSS").is_some() {
        if let Some(kib) = cli::bench::peak_rss_kib() {
            eprintln!("peak-rss-kib {kib}");
        }
    }
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            use std::io::Write;
            let _ = writeln!(
                std::io::stderr(),
                "error: {}",
                sinsmodel::io::lines::printable_message(&format!("{e:#}"))
            );
            ExitCode::from(2)
        }
    }
}
