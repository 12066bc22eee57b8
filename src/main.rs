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
        // past a file-size limit (`ulimit -f`) a write fails with an error naming the file,
        // instead of the process dying without a word
        libc::signal(libc::SIGXFSZ, libc::SIG_IGN);
    }
    // under an address-space limit, one malloc arena (before the signal thread makes a second)
    #[cfg(unix)]
    cli::address_space::one_arena_under_a_limit();
    #[cfg(unix)]
    interrupts::remove_unfinished_outputs_on_signal();
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

/// SIGINT, SIGTERM and SIGHUP end the run without leaving its unfinished outputs behind.
#[cfg(unix)]
mod interrupts {
    use std::sync::atomic::{AtomicI32, Ordering};

    /// Write end of the pipe the handler signals through.
    static PIPE: AtomicI32 = AtomicI32::new(-1);

    extern "C" fn on_signal(sig: libc::c_int) {
        let b = sig as u8;
        // SAFETY: write(2) is async-signal-safe; the fd is a pipe this process owns.
        unsafe {
            libc::write(PIPE.load(Ordering::Relaxed), (&b as *const u8).cast(), 1);
        }
    }

    /// Installs the handlers: the signal's number goes down a pipe to a thread that removes
    /// the temporaries and staging directories (never a committed output, nor the earlier run
    /// a commit is replacing: the registry's lock waits for it), says so and exits 128 + signal.
    pub fn remove_unfinished_outputs_on_signal() {
        let mut fds = [0 as libc::c_int; 2];
        // SAFETY: pipe(2) fills the two descriptors; checked below.
        if unsafe { libc::pipe(fds.as_mut_ptr()) } != 0 {
            return;
        }
        PIPE.store(fds[1], Ordering::Relaxed);
        let read_end = fds[0];
        std::thread::spawn(move || {
            let mut b = 0u8;
            // SAFETY: reads one byte into `b` from the pipe's read end.
            while unsafe { libc::read(read_end, (&mut b as *mut u8).cast(), 1) } != 1 {}
            let (n, _held) = sinsmodel::io::atomic_file::remove_unfinished();
            let name = match b as libc::c_int {
                libc::SIGINT => "SIGINT",
                libc::SIGTERM => "SIGTERM",
                _ => "SIGHUP",
            };
            let _ = std::io::Write::write_all(
                &mut std::io::stderr(),
                format!(
                    "interrupted ({name}): {n} unfinished output{} removed; earlier results are left as they were\n",
                    if n == 1 { "" } else { "s" }
                )
                .as_bytes(),
            );
            std::process::exit(128 + b as i32);
        });
        for sig in [libc::SIGINT, libc::SIGTERM, libc::SIGHUP] {
            // SAFETY: installs a handler that only calls write(2); sa_mask empty, SA_RESTART so
            // interrupted reads and writes resume.
            unsafe {
                let mut sa: libc::sigaction = std::mem::zeroed();
                sa.sa_sigaction = on_signal as *const () as usize;
                sa.sa_flags = libc::SA_RESTART;
                libc::sigemptyset(&mut sa.sa_mask);
                libc::sigaction(sig, &sa, std::ptr::null_mut());
            }
        }
    }
}
