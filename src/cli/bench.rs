//! `sinsmodel bench [--seconds S]`: throughput of navigation + filter jobs, generated sparse
//! kernels against a dense-nalgebra filter on the same data in the same process, and peak memory.

use anyhow::Result;
use clap::Args;
use sinsmodel::estimate::filter::{self, AidingEpoch, FilterConfig};
use sinsmodel::model::Model;
use sinsmodel::report::reproduce::{self, Priors};
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

fn peak_rss_mib() -> f64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("VmHWM:"))
                .map(|l| l.to_string())
        })
        .and_then(|l| {
            l.split_whitespace()
                .nth(1)
                .and_then(|k| k.parse::<f64>().ok())
        })
        .map(|kb| kb / 1024.0)
        .unwrap_or(f64::NAN)
}

/// Job 3: explain on `seconds` of the demo's 2 kHz vibration data, baseline P31, every library
/// candidate; against one plain P31 filter pass over the same data.
fn explain_job(seconds: f64) -> Result<()> {
    use sinsmodel::estimate::explain::{self, ExplainData, ExplainOptions};
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
        imu: &sim.imu,
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
    Ok(())
}

fn tempfile_dir() -> Result<std::path::PathBuf> {
    let d = std::env::temp_dir().join(format!("sinsmodel-bench-{}", std::process::id()));
    std::fs::create_dir_all(&d)?;
    Ok(d)
}
