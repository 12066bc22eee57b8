//! `sinsmodel bench [--seconds S]`: throughput of navigation + filter jobs, generated sparse
//! kernels against a dense-nalgebra filter on the same data in the same process, and peak memory.

use anyhow::Result;
use clap::Args;
pub use sinsmodel::experiment::bench::peak_rss_kib;
use sinsmodel::experiment::bench::{self, data};
use sinsmodel::experiment::reproduce::{self, Priors};
use sinsmodel::model::Model;
use std::ffi::{OsStr, OsString};
use std::path::Path;
use std::time::Instant;

/// Arguments of `bench`.
#[derive(Args)]
pub struct BenchArgs {
    /// Seconds of simulated IMU data per job (results are scaled to hours of data per second).
    #[arg(long, default_value_t = 600.0)]
    seconds: f64,
    /// Seconds of 2 kHz IMU data for the explain job (the target: 7200 s in ≤ 30 s); 0 skips it.
    #[arg(long, default_value_t = 7200.0)]
    explain_seconds: f64,
    /// Seconds of 2 kHz IMU text for the streaming job (navigate and filter as child processes,
    /// peak memory and time, streamed against reading the whole file; the target: 7200 s, a
    /// 2.3 GB file, in at most 64 MiB); 0 skips it.
    #[arg(long, default_value_t = 600.0)]
    memory_seconds: f64,
    /// Seconds of 200 Hz static IMU text for issue 27's KF-GINS job (0 skips it; 10 to 86400 s):
    /// the 21-state model and P31+vertical as child processes, then each stage against its floor.
    #[arg(long, default_value_t = 3600.0)]
    kf_gins_seconds: f64,
}

/// The KF-GINS job's 21-state model: P13+vertical with the gyro and accelerometer scale factors.
pub const KF_GINS_MODEL: &str = "P13+vertical+kg_11+kg_22+kg_33+ka_11+ka_22+ka_33";

/// Job 3 (library: `experiment::bench::explain_job`), printed.
fn explain_job(seconds: f64) -> Result<()> {
    let j = bench::explain_job(seconds)?;
    println!(
        "job 3 (explain): {:.0} s of 2 kHz IMU ({} samples), baseline P31, {} candidates, {} filter passes",
        seconds, j.samples, j.candidates, j.rounds
    );
    println!(
        "  explain: {:.2} s in all; passes {}; plain P31 filter pass: {:.2} s; ratio explain / plain pass {:.2}",
        j.explain_s,
        j.passes_s
            .iter()
            .map(|p| format!("{p:.2} s"))
            .collect::<Vec<_>>()
            .join(", "),
        j.plain_s,
        j.explain_s / j.plain_s
    );
    println!(
        "  the first pass carries the {} candidate signatures: {:.2} s against {:.2} s without ({:.2}x)",
        j.candidates,
        j.passes_s[0],
        j.plain_s,
        j.passes_s[0] / j.plain_s
    );
    Ok(())
}

/// Runs the command; the scratch directory goes, whatever the jobs left in it.
pub fn run(args: &BenchArgs) -> Result<()> {
    check_args(args)?;
    let r = jobs(args);
    let _ = bench::scratch_dir().map(std::fs::remove_dir_all);
    r
}

/// Every job `args` asks for, printed.
fn jobs(args: &BenchArgs) -> Result<()> {
    let model = Model::parse("P31")?;
    kernels_job(args.seconds, &model)?;
    kf_gins_job(args.seconds, &model)?;
    println!(
        "peak resident memory: {:.1} MiB (includes the simulated data held in memory)",
        bench::peak_rss_mib()
    );
    if args.explain_seconds > 0.0 {
        explain_job(args.explain_seconds)?;
    }
    if args.memory_seconds > 0.0 {
        memory_job(args.memory_seconds)?;
    }
    if args.kf_gins_seconds > 0.0 {
        kf_gins_files_job(args.kf_gins_seconds)?;
    }
    Ok(())
}

/// Refuses lengths of data out of range.
fn check_args(args: &BenchArgs) -> Result<()> {
    if !(args.seconds.is_finite() && (10.0..=86_400.0).contains(&args.seconds)) {
        anyhow::bail!("--seconds {}: expected 10 to 86400 s", args.seconds);
    }
    if !(args.explain_seconds.is_finite() && (0.0..=86_400.0).contains(&args.explain_seconds)) {
        anyhow::bail!(
            "--explain-seconds {}: expected 0 to 86400 s",
            args.explain_seconds
        );
    }
    if !(args.memory_seconds.is_finite()
        && (args.memory_seconds == 0.0 || (10.0..=86_400.0).contains(&args.memory_seconds)))
    {
        anyhow::bail!(
            "--memory-seconds {}: expected 0 (skip) or 10 to 86400 s",
            args.memory_seconds
        );
    }
    if !(args.kf_gins_seconds.is_finite()
        && (args.kf_gins_seconds == 0.0 || (10.0..=86_400.0).contains(&args.kf_gins_seconds)))
    {
        anyhow::bail!(
            "--kf-gins-seconds {}: expected 0 (skip) or 10 to 86400 s",
            args.kf_gins_seconds
        );
    }
    if args.explain_seconds > 0.0 && args.explain_seconds < 10.0 {
        anyhow::bail!(
            "--explain-seconds {}: expected 0 (skip) or 10 to 86400 s",
            args.explain_seconds
        );
    }
    Ok(())
}

/// Job 1: `seconds` [s] of 1 kHz IMU, 100 Hz filter step, 1 Hz position updates, navigation +
/// `model` (P31): generated kernels against dense, then the composed models; printed.
fn kernels_job(seconds: f64, model: &Model) -> Result<()> {
    let hours = seconds / 3600.0;
    let (sim, aid) = data(1000.0, seconds)?;
    let cfg = reproduce::config(model, &Priors::default())?;
    let k = bench::kernels(model, &cfg, &sim, &aid);
    let (t_gen, t_dense) = (k.generated_s, k.dense_s);
    println!("job 1: {seconds:.0} s of 1 kHz IMU, P31, 100 Hz step, 1 Hz updates");
    println!(
        "  generated sparse kernels: {:.3} s = {:.2} h of data per second ({:.0}x real time)",
        t_gen,
        hours / t_gen,
        seconds / t_gen
    );
    println!(
        "  dense nalgebra filter:    {:.3} s = {:.2} h of data per second",
        t_dense,
        hours / t_dense
    );
    println!("  ratio dense / generated:  {:.2}", t_dense / t_gen);
    let c = bench::composition(model, &cfg, &sim, &aid)?;
    println!(
        "  P28+d_x+d_y+d_z (compiled as {}): {:.3} s against P31 {:.3} s (interleaved), ratio {:.2}",
        c.compiled_as.unwrap_or("-"),
        c.composed_s,
        c.p31_s,
        c.composed_s / c.p31_s
    );
    println!(
        "  P28+d_x+d_y+d_z on the run-time composition path: {:.3} s, ratio to P31 {:.2}",
        c.runtime_s,
        c.runtime_s / c.p31_s
    );
    Ok(())
}

/// Job 2 (the KF-GINS job): `seconds` [s] of 200 Hz IMU, 1 Hz GNSS positions, covariance at
/// every IMU epoch, a navigation row written per epoch; printed.
fn kf_gins_job(seconds: f64, model: &Model) -> Result<()> {
    let (sim, aid) = data(200.0, seconds)?;
    let mut cfg = reproduce::config(model, &Priors::default())?;
    cfg.step_s = 1.0 / 200.0;
    let dir = bench::scratch_dir()?;
    let epochs = sim.imu.samples.len() as f64;
    let t2 = bench::kf_gins(model, &cfg, &sim, &aid, &dir.join("nav_generated.txt"))?;
    cfg.dense_reference = true;
    let t2d = bench::kf_gins(model, &cfg, &sim, &aid, &dir.join("nav_dense.txt"))?;
    println!("job 2 (KF-GINS layout): {seconds:.0} s of 200 Hz IMU, P31 covariance every epoch, 1 Hz GNSS, a row written per epoch");
    println!(
        "  generated: {:.3} s = {:.0} epochs/s; dense: {:.3} s = {:.0} epochs/s; ratio {:.2}",
        t2,
        epochs / t2,
        t2d,
        epochs / t2d,
        t2d / t2
    );
    Ok(())
}

/// A child process's wall time [s] and peak resident memory [MiB] (its own VmHWM, which it
/// prints when `SINSMODEL_REPORT_PEAK_RSS` is set; a parent's rusage would count the parent's
/// pages at fork).
fn run_child<S: AsRef<OsStr> + std::fmt::Debug>(args: &[S]) -> Result<(f64, f64)> {
    let exe = std::env::current_exe()?;
    let t = Instant::now();
    let out = std::process::Command::new(&exe)
        .args(args)
        .env("SINSMODEL_REPORT_PEAK_RSS", "1")
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .output()?;
    let el = t.elapsed().as_secs_f64();
    let err = String::from_utf8_lossy(&out.stderr);
    if !out.status.success() {
        anyhow::bail!("bench: {:?} failed: {}", args, err.trim());
    }
    let kib: f64 = err
        .lines()
        .find_map(|l| l.strip_prefix("peak-rss-kib "))
        .and_then(|v| v.trim().parse().ok())
        .ok_or_else(|| anyhow::anyhow!("bench: {:?} did not report its peak memory", args))?;
    Ok((el, kib / 1024.0))
}

/// The arguments of a child: the words and paths given, then `--in-memory` when `whole`.
fn child_args(words: &[&OsStr], whole: bool) -> Vec<OsString> {
    let mut a: Vec<OsString> = words.iter().map(|w| w.to_os_string()).collect();
    if whole {
        a.push("--in-memory".into());
    }
    a
}

/// Job 4: navigate and filter on `seconds` [s] of 2 kHz IMU text (the sine case), each as a
/// child process, streamed and reading the whole file first (the baseline), interleaved,
/// fastest of three; peak resident memory of each.
fn memory_job(seconds: f64) -> Result<()> {
    let dir = bench::scratch_dir()?.join("memory");
    std::fs::create_dir_all(&dir)?;
    let sc = dir.join("scenario.toml");
    std::fs::write(&sc, bench::memory_scenario(seconds))?;
    let data = dir.join("sine");
    let t = Instant::now();
    run_child(&[
        OsStr::new("simulate"),
        sc.as_os_str(),
        OsStr::new("--out"),
        data.as_os_str(),
        OsStr::new("--force"),
    ])?;
    let t_sim = t.elapsed().as_secs_f64();
    let imu = data.join("imu.txt");
    let size_gb = std::fs::metadata(&imu)?.len() as f64 / 1e9;
    println!(
        "job 4 (streaming): {seconds:.0} s of 2 kHz IMU text ({:.0} samples, {size_gb:.2} GB, simulated in {t_sim:.0} s); navigate and P31 filter as child processes, streamed vs reading the whole file first (interleaved, fastest of 3)",
        seconds * 2000.0
    );
    let best = stream_against_whole(&dir, &data)?;
    for (name, s, w) in [
        ("navigate", best[0], best[1]),
        ("filter P31", best[2], best[3]),
    ] {
        println!(
            "  {name:<10} streamed: {:.2} s, peak RSS {:.1} MiB; whole file: {:.2} s, {:.1} MiB; time ratio whole / streamed {:.2}, memory ratio {:.1}",
            s.0,
            s.1,
            w.0,
            w.1,
            w.0 / s.0,
            w.1 / s.1
        );
    }
    std::fs::remove_dir_all(&dir)?;
    Ok(())
}

/// Navigate and filter on the simulated `data` directory (outputs in `dir`), streamed and whole
/// file, interleaved three times: per run kind the fastest time [s] and the largest peak [MiB].
fn stream_against_whole(dir: &Path, data: &Path) -> Result<[(f64, f64); 4]> {
    let (imu, aid, truth) = (
        data.join("imu.txt"),
        data.join("gnss.txt"),
        data.join("truth.txt"),
    );
    let (nav_out, filt_out) = (dir.join("nav.txt"), dir.join("filter"));
    let nav = |whole: bool| -> Result<(f64, f64)> {
        run_child(&child_args(
            &[
                OsStr::new("navigate"),
                OsStr::new("--imu"),
                imu.as_os_str(),
                OsStr::new("--lat"),
                OsStr::new("28.22"),
                OsStr::new("--lon"),
                OsStr::new("112.99"),
                OsStr::new("--att"),
                OsStr::new("0,0,0"),
                OsStr::new("--out"),
                nav_out.as_os_str(),
            ],
            whole,
        ))
    };
    let filt = |whole: bool| -> Result<(f64, f64)> {
        run_child(&child_args(
            &[
                OsStr::new("filter"),
                OsStr::new("--model"),
                OsStr::new("P31"),
                OsStr::new("--imu"),
                imu.as_os_str(),
                OsStr::new("--aid"),
                aid.as_os_str(),
                OsStr::new("--truth"),
                truth.as_os_str(),
                OsStr::new("--out"),
                filt_out.as_os_str(),
            ],
            whole,
        ))
    };
    let mut best: [(f64, f64); 4] = [(f64::INFINITY, 0.0); 4];
    for _ in 0..3 {
        for (k, r) in [nav(false)?, nav(true)?, filt(false)?, filt(true)?]
            .into_iter()
            .enumerate()
        {
            if r.0 < best[k].0 {
                best[k].0 = r.0;
            }
            best[k].1 = best[k].1.max(r.1);
        }
    }
    Ok(best)
}

/// Job 5: issue 27's KF-GINS job on files, `seconds` [s] of 200 Hz static IMU text and 1 Hz
/// GNSS: `filter` with the 21-state composed model and with P31+vertical as child processes
/// (alternating, three each: fastest, slowest, peak memory), then each stage per sample
/// against its floor (`experiment::bench_stages`); printed.
fn kf_gins_files_job(seconds: f64) -> Result<()> {
    use sinsmodel::experiment::bench_stages;
    let dir = bench::scratch_dir()?.join("kf-gins");
    std::fs::create_dir_all(&dir)?;
    let text = bench_stages::kf_gins_scenario(seconds);
    let sc = dir.join("scenario.toml");
    std::fs::write(&sc, &text)?;
    let data = dir.join("data");
    let words = |w: &str| w.split(' ').map(OsString::from).collect::<Vec<_>>();
    let mut sim_args = words("simulate");
    sim_args.extend([
        sc.clone().into(),
        "--out".into(),
        data.clone().into(),
        "--force".into(),
    ]);
    run_child(&sim_args)?;
    let job = |model: &str| -> Result<(f64, f64)> {
        let mut a = words("filter --model");
        a.push(model.into());
        a.extend([
            "--imu".into(),
            data.join("imu.txt").into(),
            "--aid".into(),
            data.join("gnss.txt").into(),
        ]);
        a.extend(words(
            "--init 28.22,112.99,0,0,0,0 --step 0.005 --mode closed --out",
        ));
        a.push(dir.join("out").into());
        run_child(&a)
    };
    let (mut t21, mut t33) = (Vec::new(), Vec::new());
    for _ in 0..3 {
        t21.push(job(KF_GINS_MODEL)?);
        t33.push(job("P31+vertical")?);
    }
    let samples = (seconds * 200.0).round();
    println!("job 5 (KF-GINS job on files): {seconds} s of 200 Hz static IMU text, 1 Hz GNSS, closed loop, covariance and a nav.txt row every sample");
    for (name, t) in [(KF_GINS_MODEL, &t21), ("P31+vertical (compiled)", &t33)] {
        let lo = t.iter().map(|r| r.0).fold(f64::INFINITY, f64::min);
        let hi = t.iter().map(|r| r.0).fold(0.0, f64::max);
        let mem = t.iter().map(|r| r.1).fold(0.0, f64::max);
        println!(
            "  filter --model {name}: {lo:.2}-{hi:.2} s (3 runs), {:.2} us per sample, peak {mem:.1} MiB",
            lo * 1e6 / samples
        );
    }
    let sim = sinsmodel::sim::simulator::simulate(
        &sinsmodel::sim::scenario::Scenario::parse(&text, "bench kf-gins")?,
        |_| {},
    );
    let model = Model::parse(KF_GINS_MODEL)?;
    let mut cfg = reproduce::config(&model, &Priors::default())?;
    cfg.step_s = 1.0 / 200.0;
    cfg.mode = sinsmodel::estimate::filter::Mode::ClosedLoop;
    let aid = reproduce::aiding_from_truth(&sim, &Priors::default(), false, 1)?;
    let st = bench_stages::stages(&model, &cfg, &sim, &aid, &data.join("imu.txt"))?;
    println!("  stages of {KF_GINS_MODEL}, each alone in this process (us per sample, fastest of 3; floor where one is stated):");
    for s in &st.stages {
        println!("    {}", bench_stages::report_line(s));
    }
    println!(
        "    whole filter in process    {:.3} us (data in memory, no output)",
        st.filter_us
    );
    std::fs::remove_dir_all(&dir)?;
    Ok(())
}
