//! `bench`'s measurements: throughput of navigation + filter jobs on simulated data, the
//! generated sparse kernels against a dense-nalgebra filter in the same process, composed models
//! on the preset's kernels and on the run-time path, explain's passes against a plain filter
//! pass, and peak memory. Times are wall-clock seconds; the minimum of repeated runs is kept
//! (the machine may be shared; the minimum is the least disturbed).

use crate::estimate::filter::{self, AidingEpoch, FilterConfig};
use crate::experiment::reproduce::{self, Priors};
use crate::model::Model;
use crate::sim::scenario::Scenario;
use crate::sim::simulator::{simulate, SimOutput};
use anyhow::Result;
use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// The bench's data: `seconds` [s] at rest, IMU at `rate` [Hz] with the paper's sensor errors
/// and noise, and 1 Hz aiding from the truth.
pub fn data(rate: f64, seconds: f64) -> Result<(SimOutput, Vec<AidingEpoch>)> {
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

/// This process's peak resident memory [MiB] (NaN where unknown).
pub fn peak_rss_mib() -> f64 {
    peak_rss_kib()
        .map(|k| k as f64 / 1024.0)
        .unwrap_or(f64::NAN)
}

/// A scratch directory of this process under the system's temporary directory (created).
pub fn scratch_dir() -> Result<PathBuf> {
    let d = std::env::temp_dir().join(format!("sinsmodel-bench-{}", std::process::id()));
    std::fs::create_dir_all(&d)?;
    Ok(d)
}

/// Job 1's times [s]: one filter run with the generated sparse kernels and with the dense
/// nalgebra reference, fastest of three each.
#[derive(Debug, Clone, Copy)]
pub struct Kernels {
    /// Generated sparse kernels [s].
    pub generated_s: f64,
    /// Dense nalgebra filter [s].
    pub dense_s: f64,
}

/// Times `model` under `cfg` on `sim` with `aid`, generated kernels then dense reference,
/// fastest of three runs each (the two produce the same number of records).
pub fn kernels(model: &Model, cfg: &FilterConfig, sim: &SimOutput, aid: &[AidingEpoch]) -> Kernels {
    let time = |cfg: &FilterConfig| {
        let mut best = (f64::INFINITY, 0);
        for _ in 0..3 {
            let t = Instant::now();
            let r = filter::run(model, cfg, &sim.imu, sim.start, aid, None, |_| {});
            let el = t.elapsed().as_secs_f64();
            if el < best.0 {
                best = (el, r.records.len());
            }
        }
        best
    };
    let (generated_s, n1) = time(cfg);
    let mut dense = cfg.clone();
    dense.dense_reference = true;
    let (dense_s, n2) = time(&dense);
    assert_eq!(n1, n2);
    Kernels {
        generated_s,
        dense_s,
    }
}

/// The same 31 states written as P28+d_x+d_y+d_z, timed against P31 [s].
#[derive(Debug, Clone)]
pub struct Composition {
    /// The preset the composition was compiled as, if any.
    pub compiled_as: Option<&'static str>,
    /// P31 [s].
    pub p31_s: f64,
    /// The composition as parsed (on the preset's kernels when it matches one) [s].
    pub composed_s: f64,
    /// The composition forced onto the run-time composition path [s].
    pub runtime_s: f64,
}

/// Times P28+d_x+d_y+d_z as parsed (P31's generated kernels: same states, same order) and forced
/// onto the run-time composition path (what a composition no preset matches costs) against
/// `p31`; interleaved runs, fastest of five each, so that a slow spell of the machine hits all
/// three alike.
pub fn composition(
    p31: &Model,
    cfg: &FilterConfig,
    sim: &SimOutput,
    aid: &[AidingEpoch],
) -> Result<Composition> {
    let composed = Model::parse("P28+d_x+d_y+d_z")?;
    let runtime = composed.runtime_only();
    let run_once = |m: &Model| {
        let t = Instant::now();
        let r = filter::run(m, cfg, &sim.imu, sim.start, aid, None, |_| {});
        (t.elapsed().as_secs_f64(), r.records.len())
    };
    let (mut t_p31, mut t_comp, mut t_rt) = (f64::INFINITY, f64::INFINITY, f64::INFINITY);
    for _ in 0..5 {
        t_p31 = t_p31.min(run_once(p31).0);
        t_comp = t_comp.min(run_once(&composed).0);
        t_rt = t_rt.min(run_once(&runtime).0);
    }
    Ok(Composition {
        compiled_as: composed.compiled_as(),
        p31_s: t_p31,
        composed_s: t_comp,
        runtime_s: t_rt,
    })
}

/// One KF-GINS-layout run [s]: the filter over `sim` with a navigation row written to `path` at
/// every IMU epoch (the file is removed afterwards).
pub fn kf_gins_once(
    model: &Model,
    cfg: &FilterConfig,
    sim: &SimOutput,
    aid: &[AidingEpoch],
    path: &Path,
) -> Result<f64> {
    let mut w = std::io::BufWriter::with_capacity(1 << 20, std::fs::File::create(path)?);
    let t = Instant::now();
    let mut err = None;
    filter::run_with(
        model,
        cfg,
        &sim.imu,
        sim.start,
        aid,
        None,
        |_| {},
        &mut |s| {
            let row = crate::io::truth::TruthRow {
                t: s.t,
                lat: s.lat,
                lon: s.lon,
                h: s.h,
                v: s.v,
                euler: s.euler(),
            };
            if let Err(e2) = crate::io::truth::write_row(&mut w, &row) {
                err = Some(e2);
            }
        },
    );
    w.flush()?;
    if let Some(e) = err {
        return Err(e.into());
    }
    let el = t.elapsed().as_secs_f64();
    std::fs::remove_file(path)?;
    Ok(el)
}

/// The fastest of three [`kf_gins_once`] runs [s].
pub fn kf_gins(
    model: &Model,
    cfg: &FilterConfig,
    sim: &SimOutput,
    aid: &[AidingEpoch],
    path: &Path,
) -> Result<f64> {
    let once = || kf_gins_once(model, cfg, sim, aid, path);
    Ok(once()?.min(once()?).min(once()?))
}

/// Job 3's measurements: explain on the demo's 2 kHz vibration data against one plain filter
/// pass over the same data.
#[derive(Debug, Clone)]
pub struct ExplainTiming {
    /// IMU samples.
    pub samples: usize,
    /// Candidates tested.
    pub candidates: usize,
    /// Filter passes explain made.
    pub rounds: usize,
    /// explain in all [s].
    pub explain_s: f64,
    /// Each pass [s], in order.
    pub passes_s: Vec<f64>,
    /// One plain P31 filter pass [s].
    pub plain_s: f64,
}

/// Job 3: explain on `seconds` [s] of the demo's 2 kHz vibration data, baseline P31, every
/// library candidate; against one plain P31 filter pass over the same data.
pub fn explain_job(seconds: f64) -> Result<ExplainTiming> {
    use crate::explain::{self, ExplainData, ExplainOptions};
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
        imu: explain::ImuInput::Memory(&sim.imu),
        aid: &aid,
        truth: None,
        start: sim.start,
        tape: None,
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
    drop(plain);
    Ok(ExplainTiming {
        samples: sim.imu.samples.len(),
        candidates: cands.len(),
        rounds: e.rounds,
        explain_s: t_explain,
        passes_s: passes,
        plain_s: t_plain,
    })
}

/// Job 4's scenario: the README's sine case (scenarios/sine.toml) for `seconds` [s]: 6 g, 90 Hz
/// on N, E, D at 2 kHz, the paper's sensor errors, 1 Hz GNSS.
pub fn memory_scenario(seconds: f64) -> String {
    let vib: String = ["n", "e", "d"]
        .iter()
        .map(|a| {
            format!(
                "[[vibration]]\nkind = \"sine\"\naxis = \"{a}\"\namplitude = \"6 g\"\nfreq_hz = 90.0\n"
            )
        })
        .collect();
    format!(
        "name = \"bench-memory\"\nimu_rate_hz = 2000.0\ntruth_rate_hz = 1.0\nseed = 1\n[start]\nlat_deg = 28.22\nlon_deg = 112.99\n\
         [[segment]]\nkind = \"rest\"\nduration_s = {seconds}\n{vib}{}{}\n[gnss]\nrate_hz = 1.0\nsigma_ne = \"0.5 m\"\nsigma_d = \"1 m\"\n",
        reproduce::PAPER_ERRORS,
        reproduce::PAPER_NOISE
    )
}
