//! `sinsmodel bench [--seconds S]`: throughput of navigation + filter jobs, generated sparse
//! kernels against a dense-nalgebra filter on the same data in the same process, and peak memory.

use anyhow::Result;
use clap::Args;
use sinsmodel::estimate::filter::{self, AidingEpoch, FilterConfig};
use sinsmodel::experiment::reproduce::{self, Priors};
use sinsmodel::model::Model;
use sinsmodel::sim::scenario::Scenario;
use sinsmodel::sim::simulator::{simulate, SimOutput};
use std::io::Write as _;
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
}

fn data(rate: f64, seconds: f64) -> Result<(SimOutput, Vec<AidingEpoch>)> {
    let text = format!(
        "name = \"bench\"\nimu_rate_hz = {rate}\ntruth_rate_hz = 1.0\nseed = 9\n[start]\nlat_deg = 28.22\nlon_deg = 112.99\n\
         [[segment]]\nkind = \"rest\"\nduration_s = {seconds}\n{}{}",
        reproduce::PAPER_ERRORS,
        reproduce::PAPER_NOISE
    );
    let sim = simulate(&Scenario::parse(&text, "bench")?, |_| {});
    let aid = reproduce::aiding_from_truth(&sim, &Priors::default(), false, 9)?;
    Ok((sim, aid))
}

/// This process's peak resident memory (VmHWM) [KiB].
pub fn peak_rss_kib() -> Option<u64> {
    std::fs::read_to_string("/proc/self/status")
        .ok()?
        .lines()
        .find(|l| l.starts_with("VmHWM:"))?
        .split_whitespace()
        .nth(1)?
        .parse()
        .ok()
}

fn peak_rss_mib() -> f64 {
    peak_rss_kib()
        .map(|k| k as f64 / 1024.0)
        .unwrap_or(f64::NAN)
}

/// Job 3: explain on `seconds` of the demo's 2 kHz vibration data, baseline P31, every library
/// candidate; against one plain P31 filter pass over the same data.
fn explain_job(seconds: f64) -> Result<()> {
    use sinsmodel::explain::{self, ExplainData, ExplainOptions};
    let case = reproduce::explain_demo(seconds, 3);
    let sim = simulate(&Scenario::parse(&case.scenario, "bench explain")?, |_| {});
    let priors = Priors::default();
    let aid = reproduce::aiding_from_truth(&sim, &priors, true, 3)?;
    let model = Model::parse("P31")?;
    let cands = explain::parse_candidates(None, &model).map_err(anyhow::Error::msg)?;
    let cfg = reproduce::config(&model, &priors)?;
    let t = Instant::now();
    let plain = filter::run(&model, &cfg, &sim.imu, sim.start, &aid, None, |_| {});
    let t_plain = t.elapsed().as_secs_f64();
    let data = ExplainData {
        imu: sinsmodel::explain::ImuInput::Memory(&sim.imu),
        aid: &aid,
        truth: None,
        start: sim.start,
    };
    let mut pass_start = Instant::now();
    let mut passes: Vec<f64> = Vec::new();
    let mut current = 0usize;
    let t = Instant::now();
    let e = explain::explain(
        &model,
        &cands,
        &data,
        &|m: &Model| reproduce::config(m, &priors),
        &ExplainOptions::default(),
        &mut |pass, _| {
            if pass != current {
                if current != 0 {
                    passes.push(pass_start.elapsed().as_secs_f64());
                }
                current = pass;
                pass_start = Instant::now();
            }
        },
    )?;
    passes.push(pass_start.elapsed().as_secs_f64());
    let t_explain = t.elapsed().as_secs_f64();
    println!(
        "job 3 (explain): {:.0} s of 2 kHz IMU ({} samples), baseline P31, {} candidates, {} filter passes",
        seconds,
        sim.imu.samples.len(),
        cands.len(),
        e.rounds
    );
    println!(
        "  explain: {:.2} s in all; passes {}; plain P31 filter pass: {:.2} s; ratio explain / plain pass {:.2}",
        t_explain,
        passes
            .iter()
            .map(|p| format!("{p:.2} s"))
            .collect::<Vec<_>>()
            .join(", "),
        t_plain,
        t_explain / t_plain
    );
    println!(
        "  the first pass carries the {} candidate signatures: {:.2} s against {:.2} s without ({:.2}x)",
        cands.len(),
        passes[0],
        t_plain,
        passes[0] / t_plain
    );
    drop(plain);
    Ok(())
}

/// Runs the command.
pub fn run(args: &BenchArgs) -> Result<()> {
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
    if args.explain_seconds > 0.0 && args.explain_seconds < 10.0 {
        anyhow::bail!(
            "--explain-seconds {}: expected 0 (skip) or 10 to 86400 s",
            args.explain_seconds
        );
    }
    let model = Model::parse("P31")?;
    let hours = args.seconds / 3600.0;

    // Job 1: 1 kHz IMU, 100 Hz filter step, 1 Hz position updates, navigation + P31.
    let (sim, aid) = data(1000.0, args.seconds)?;
    let mut cfg = reproduce::config(&model, &Priors::default())?;
    // fastest of three runs each (the machine is shared; the minimum is the least disturbed)
    let time_model = |model: &Model, cfg: &FilterConfig| {
        let mut best = (f64::INFINITY, 0);
        for _ in 0..3 {
            let t = Instant::now();
            let r = filter::run(model, cfg, &sim.imu, sim.start, &aid, None, |_| {});
            let el = t.elapsed().as_secs_f64();
            if el < best.0 {
                best = (el, r.records.len());
            }
        }
        best
    };
    let time = |cfg: &FilterConfig| time_model(&model, cfg);
    let (t_gen, n1) = time(&cfg);
    cfg.dense_reference = true;
    let (t_dense, n2) = time(&cfg);
    assert_eq!(n1, n2);
    println!(
        "job 1: {:.0} s of 1 kHz IMU, P31, 100 Hz step, 1 Hz updates",
        args.seconds
    );
    println!(
        "  generated sparse kernels: {:.3} s = {:.2} h of data per second ({:.0}x real time)",
        t_gen,
        hours / t_gen,
        args.seconds / t_gen
    );
    println!(
        "  dense nalgebra filter:    {:.3} s = {:.2} h of data per second",
        t_dense,
        hours / t_dense
    );
    println!("  ratio dense / generated:  {:.2}", t_dense / t_gen);

    // Composed models: the same 31 states written as P28+d_x+d_y+d_z. Parsed, it runs on P31's
    // generated kernels (same states, same order); forced onto the run-time composition path it
    // measures what a composition no preset matches costs.
    let composed = Model::parse("P28+d_x+d_y+d_z")?;
    cfg.dense_reference = false;
    let runtime = composed.runtime_only();
    // interleaved P31 / composed / run-time runs, fastest of five each, so that a slow spell of
    // the (shared) machine hits all three alike
    let run_once = |m: &Model| {
        let t = Instant::now();
        let r = filter::run(m, &cfg, &sim.imu, sim.start, &aid, None, |_| {});
        (t.elapsed().as_secs_f64(), r.records.len())
    };
    let (mut t_p31, mut t_comp, mut t_rt) = (f64::INFINITY, f64::INFINITY, f64::INFINITY);
    for _ in 0..5 {
        t_p31 = t_p31.min(run_once(&model).0);
        t_comp = t_comp.min(run_once(&composed).0);
        t_rt = t_rt.min(run_once(&runtime).0);
    }
    println!(
        "  P28+d_x+d_y+d_z (compiled as {}): {:.3} s against P31 {:.3} s (interleaved), ratio {:.2}",
        composed.compiled_as().unwrap_or("-"),
        t_comp,
        t_p31,
        t_comp / t_p31
    );
    println!(
        "  P28+d_x+d_y+d_z on the run-time composition path: {:.3} s, ratio to P31 {:.2}",
        t_rt,
        t_rt / t_p31
    );

    // Job 2 (the KF-GINS job): 200 Hz IMU, 1 Hz GNSS positions, covariance at every IMU epoch,
    // a navigation row written per epoch.
    let (sim, aid) = data(200.0, args.seconds)?;
    let mut cfg = reproduce::config(&model, &Priors::default())?;
    cfg.step_s = 1.0 / 200.0;
    let dir = tempfile_dir()?;
    let job2 = |cfg: &FilterConfig, name: &str| -> Result<f64> {
        let path = dir.join(name);
        let mut w = std::io::BufWriter::with_capacity(1 << 20, std::fs::File::create(&path)?);
        let t = Instant::now();
        let mut err = None;
        filter::run_with(
            &model,
            cfg,
            &sim.imu,
            sim.start,
            &aid,
            None,
            |_| {},
            &mut |s| {
                let row = sinsmodel::io::truth::TruthRow {
                    t: s.t,
                    lat: s.lat,
                    lon: s.lon,
                    h: s.h,
                    v: s.v,
                    euler: s.euler(),
                };
                if let Err(e2) = sinsmodel::io::truth::write_row(&mut w, &row) {
                    err = Some(e2);
                }
            },
        );
        w.flush()?;
        if let Some(e) = err {
            return Err(e.into());
        }
        let el = t.elapsed().as_secs_f64();
        std::fs::remove_file(&path)?;
        Ok(el)
    };
    let epochs = sim.imu.samples.len() as f64;
    let best3 = |cfg: &FilterConfig, name: &str| -> Result<f64> {
        Ok(job2(cfg, name)?.min(job2(cfg, name)?).min(job2(cfg, name)?))
    };
    let t2 = best3(&cfg, "nav_generated.txt")?;
    cfg.dense_reference = true;
    let t2d = best3(&cfg, "nav_dense.txt")?;
    println!("job 2 (KF-GINS layout): {:.0} s of 200 Hz IMU, P31 covariance every epoch, 1 Hz GNSS, a row written per epoch", args.seconds);
    println!(
        "  generated: {:.3} s = {:.0} epochs/s; dense: {:.3} s = {:.0} epochs/s; ratio {:.2}",
        t2,
        epochs / t2,
        t2d,
        epochs / t2d,
        t2d / t2
    );
    println!(
        "peak resident memory: {:.1} MiB (includes the simulated data held in memory)",
        peak_rss_mib()
    );
    let _ = std::fs::remove_dir(&dir);
    if args.explain_seconds > 0.0 {
        explain_job(args.explain_seconds)?;
    }
    if args.memory_seconds > 0.0 {
        memory_job(args.memory_seconds)?;
    }
    Ok(())
}

/// A child process's wall time [s] and peak resident memory [MiB] (its own VmHWM, which it
/// prints when `SINSMODEL_REPORT_PEAK_RSS` is set; a parent's rusage would count the parent's
/// pages at fork).
fn run_child(args: &[&std::ffi::OsStr]) -> Result<(f64, f64)> {
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

/// Job 4: navigate and filter on `seconds` of 2 kHz IMU text (the sine case), each as a child
/// process, streamed and reading the whole file first (the baseline), interleaved, fastest of
/// three; peak resident memory of each.
fn memory_job(seconds: f64) -> Result<()> {
    use std::ffi::OsStr;
    let dir = tempfile_dir()?.join("memory");
    // the README's sine case (scenarios/sine.toml): 6 g, 90 Hz on N, E, D at 2 kHz, the paper's
    // sensor errors, 1 Hz GNSS
    let vib: String = ["n", "e", "d"]
        .iter()
        .map(|a| {
            format!(
                "[[vibration]]\nkind = \"sine\"\naxis = \"{a}\"\namplitude = \"6 g\"\nfreq_hz = 90.0\n"
            )
        })
        .collect();
    let scenario = format!(
        "name = \"bench-memory\"\nimu_rate_hz = 2000.0\ntruth_rate_hz = 1.0\nseed = 1\n[start]\nlat_deg = 28.22\nlon_deg = 112.99\n\
         [[segment]]\nkind = \"rest\"\nduration_s = {seconds}\n{vib}{}{}\n[gnss]\nrate_hz = 1.0\nsigma_ne = \"0.5 m\"\nsigma_d = \"1 m\"\n",
        reproduce::PAPER_ERRORS,
        reproduce::PAPER_NOISE
    );
    std::fs::create_dir_all(&dir)?;
    let sc = dir.join("scenario.toml");
    std::fs::write(&sc, scenario)?;
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
    let nav_out = dir.join("nav.txt");
    let filt_out = dir.join("filter");
    let nav = |whole: bool| -> Result<(f64, f64)> {
        let mut a: Vec<&OsStr> = vec![
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
        ];
        if whole {
            a.push(OsStr::new("--in-memory"));
        }
        run_child(&a)
    };
    let aid = data.join("gnss.txt");
    let truth = data.join("truth.txt");
    let filt = |whole: bool| -> Result<(f64, f64)> {
        let mut a: Vec<&OsStr> = vec![
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
        ];
        if whole {
            a.push(OsStr::new("--in-memory"));
        }
        run_child(&a)
    };
    type Best = (f64, f64);
    let mut best: [Best; 4] = [(f64::INFINITY, 0.0); 4];
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

fn tempfile_dir() -> Result<std::path::PathBuf> {
    let d = std::env::temp_dir().join(format!("sinsmodel-bench-{}", std::process::id()));
    std::fs::create_dir_all(&d)?;
    Ok(d)
}
