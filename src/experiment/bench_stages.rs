//! `bench`'s stage costs on the KF-GINS-layout job: each stage of a filter run (parse the IMU
//! text, mechanise, propagate the covariance, update, format the navigation row) timed alone in
//! this process on the job's own data, per IMU sample, beside the floor its work allows where
//! one can be stated: bytes at this machine's read or copy speed, multiply-adds at its rate for
//! a vectorised loop on cached data. The gap between a stage and its floor is what is left.

use crate::estimate::filter::{self, joseph_update, FilterConfig};
use crate::experiment::reproduce;
use crate::io::imu_stream::ImuStream;
use crate::model::covariance::SparsePropagator;
use crate::model::{ImuSignals, Model};
use crate::nav::nav_point::NavPoint;
use crate::nav::strapdown::Navigator;
use crate::sim::simulator::SimOutput;
use anyhow::Result;
use nalgebra::Vector3;
use std::hint::black_box;
use std::path::Path;
use std::time::Instant;

/// The KF-GINS-layout job's scenario: `seconds` [s] at rest at 200 Hz, the paper's sensor errors
/// and noise, 1 Hz GNSS positions (0.5 m horizontal, 1 m vertical).
pub fn kf_gins_scenario(seconds: f64) -> String {
    format!(
        "name = \"bench-kf-gins\"\nimu_rate_hz = 200.0\ntruth_rate_hz = 1.0\nseed = 1\n[start]\nlat_deg = 28.22\nlon_deg = 112.99\n\
         [[segment]]\nkind = \"rest\"\nduration_s = {seconds}\n{}{}\n[gnss]\nrate_hz = 1.0\nsigma_ne = \"0.5 m\"\nsigma_d = \"1 m\"\n",
        reproduce::PAPER_ERRORS,
        reproduce::PAPER_NOISE
    )
}

/// One stage's cost and its floor [µs per IMU sample]; the floor is None where none is stated.
#[derive(Debug, Clone, Copy)]
pub struct Stage {
    /// The stage's name.
    pub name: &'static str,
    /// Measured cost [µs per sample], fastest of three.
    pub us: f64,
    /// The floor of its work [µs per sample].
    pub floor_us: Option<f64>,
    /// What the floor counts.
    pub floor_is: &'static str,
}

/// Per-sample costs of every stage, and of the whole in-process filter without output.
#[derive(Debug, Clone)]
pub struct Stages {
    /// IMU samples in the job.
    pub samples: usize,
    /// Parse, mechanise, propagate, update, write.
    pub stages: Vec<Stage>,
    /// The whole filter in this process on data in memory, no output [µs per sample].
    pub filter_us: f64,
}

/// Fastest of three runs of `f` [s].
fn fastest<F: FnMut()>(mut f: F) -> f64 {
    (0..3)
        .map(|_| {
            let t = Instant::now();
            f();
            t.elapsed().as_secs_f64()
        })
        .fold(f64::INFINITY, f64::min)
}

/// Multiply-adds per nanosecond of a vectorised loop on data in the L1 cache (32 running sums
/// of a·x over 256 doubles, repeated; the sums stay in registers): the arithmetic rate the
/// floors are counted at.
pub fn mul_add_rate() -> f64 {
    let x: Vec<f64> = (0..256).map(|i| 1.0 + i as f64 * 1e-3).collect();
    let reps = 40_000;
    let s = fastest(|| {
        let mut acc = [0.0f64; 32];
        for r in 0..reps {
            let a = black_box(1e-9 * (r % 7) as f64);
            for c in x.chunks_exact(32) {
                for (s, v) in acc.iter_mut().zip(c) {
                    *s += a * v;
                }
            }
        }
        black_box(acc);
    });
    (reps * 256) as f64 / (s * 1e9)
}

/// A stage's name, cost and floor as one report line.
pub fn report_line(s: &Stage) -> String {
    match s.floor_us {
        Some(f) => format!(
            "{:<26} {:>6.3} us   floor {:>6.3} us ({}): {:.1}x",
            s.name,
            s.us,
            f,
            s.floor_is,
            s.us / f
        ),
        None => format!("{:<26} {:>6.3} us   floor not stated", s.name, s.us),
    }
}

/// Measures every stage on `sim` (the job's data in memory, also written as the IMU text
/// `imu_text`) for `model` under `cfg`, whose step is one IMU sample.
pub fn stages(
    model: &Model,
    cfg: &FilterConfig,
    sim: &SimOutput,
    aid: &[filter::AidingEpoch],
    imu_text: &Path,
) -> Result<Stages> {
    let samples = sim.imu.samples.len();
    let per = |s: f64| s * 1e6 / samples as f64;
    let rate = mul_add_rate();
    let mut out = Vec::new();

    // parse: the streamed reader to the last sample; floor: the file's bytes read and scanned
    let mut parsed = 0;
    let t_parse = fastest(|| {
        parsed = 0;
        if let Ok(mut s) = ImuStream::text(imu_text) {
            while let Ok(Some(_)) = s.next() {
                parsed += 1;
            }
        }
    });
    anyhow::ensure!(
        parsed == samples,
        "bench: {} parsed {parsed} of {samples} samples",
        imu_text.display()
    );
    let t_read = fastest(|| {
        if let Ok(b) = std::fs::read(imu_text) {
            black_box(b.iter().filter(|&&c| c == b'\n').count());
        }
    });
    out.push(Stage {
        name: "parse IMU text",
        us: per(t_parse),
        floor_us: Some(per(t_read)),
        floor_is: "reading the file's bytes and finding its line ends",
    });

    // mechanise: the navigator alone
    let t_mech = fastest(|| {
        let mut nav = Navigator::new(sim.start, cfg.vertical);
        let mut t0 = sim.imu.samples[0].t - 1.0 / 200.0;
        for s in &sim.imu.samples {
            nav.step(&s.dtheta, &s.dv, s.t - t0);
            t0 = s.t;
        }
        black_box(nav.state);
    });
    out.push(Stage {
        name: "mechanise",
        us: per(t_mech),
        floor_us: None,
        floor_is: "",
    });

    // A(t): the navigation point and A's non-zeros, once per step
    let np0 = nav_point(sim);
    let n = model.n();
    let (mut a, mut acc) = (vec![0.0; n * n], model.accumulator());
    let t_fill = fastest(|| {
        let mut np = np0;
        for s in &sim.imu.samples {
            let f = s.dv * 200.0;
            np.update(
                sim.start.lat,
                sim.start.h,
                sim.start.v,
                &sim.start.dcm(),
                &f,
            );
            acc.reset();
            acc.add(&ImuSignals::new(f, s.dtheta * 200.0));
            model.fill_a(&np, &acc.mean(), &mut a);
        }
        black_box(&a);
    });
    out.push(Stage {
        name: "form A(t)",
        us: per(t_fill),
        floor_us: None,
        floor_is: "",
    });

    // propagate: one covariance step per sample, A at a navigation point of the job
    let (t_prop, mul_adds) = propagate_cost(model, cfg, sim, samples);
    out.push(Stage {
        name: "propagate P",
        us: per(t_prop),
        floor_us: mul_adds.map(|m| m as f64 / rate / 1e3),
        floor_is: "its multiply-adds at the vectorised rate",
    });

    out.push(update_stage(model, cfg, sim, aid)?);
    out.push(write_stage(sim));

    let t_filter = fastest(|| {
        black_box(filter::run(
            model,
            cfg,
            &sim.imu,
            sim.start,
            aid,
            None,
            |_| {},
        ));
    });
    Ok(Stages {
        samples,
        stages: out,
        filter_us: per(t_filter),
    })
}

/// Seconds for `steps` covariance steps of `model` (its own kernel: generated for a preset,
/// the run-time one otherwise) at the job's first navigation point, and the run-time kernel's
/// multiply-adds per step (None for a preset's generated kernel, which does not count them).
fn propagate_cost(
    model: &Model,
    cfg: &FilterConfig,
    sim: &SimOutput,
    steps: usize,
) -> (f64, Option<usize>) {
    let n = model.n();
    let s0 = &sim.imu.samples[0];
    let np = nav_point(sim);
    let mut acc = model.accumulator();
    acc.add(&ImuSignals::new(s0.dv * 200.0, s0.dtheta * 200.0));
    let mut a = vec![0.0; n * n];
    model.fill_a(&np, &acc.mean(), &mut a);
    let mut p0 = vec![0.0; n * n];
    for i in 0..n {
        p0[i * n + i] = cfg.prior_sigma[i].powi(2);
    }
    let (mut p, mut x) = (p0.clone(), vec![0.0; n]);
    let dt = 1.0 / 200.0;
    match model.preset {
        Some(k) => {
            let t = fastest(|| {
                p.copy_from_slice(&p0);
                for _ in 0..steps {
                    (k.propagate)(&a, dt, &cfg.q, &mut p, &mut x);
                }
                black_box(&p);
            });
            (t, None)
        }
        None => {
            let mut sp = SparsePropagator::new(n, model.a_pattern());
            let t = fastest(|| {
                p.copy_from_slice(&p0);
                for _ in 0..steps {
                    sp.propagate_with_state(&a, dt, &cfg.q, &mut p, Some(&mut x));
                }
                black_box(&p);
            });
            (t, Some(sp.mul_adds()))
        }
    }
}

/// The navigation point at the job's start (specific force from the first sample).
fn nav_point(sim: &SimOutput) -> NavPoint {
    let c = sim.start.dcm();
    let f = sim.imu.samples[0].dv * 200.0;
    NavPoint::new(sim.start.lat, sim.start.h, sim.start.v, &c, &f)
}

/// Three scalar position updates (the model's `pos_ne` and `pos_h` rows) per GNSS fix of `aid`,
/// per IMU sample of `sim`.
fn update_stage(
    model: &Model,
    cfg: &FilterConfig,
    sim: &SimOutput,
    aid: &[filter::AidingEpoch],
) -> Result<Stage> {
    let per = |s: f64| s * 1e6 / sim.imu.samples.len() as f64;
    let n = model.n();
    // update: three scalar position updates per GNSS epoch
    let mut p = vec![0.0; n * n];
    for i in 0..n {
        p[i * n + i] = cfg.prior_sigma[i].powi(2).max(1e-12);
    }
    let (mut u, mut k, mut x) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let np = nav_point(sim);
    let mut rows: Vec<Vec<f64>> = Vec::new();
    for meas in ["pos_ne", "pos_h"] {
        let mut h = vec![0.0; 3 * n];
        if let Ok(c) = model.fill_h(meas, &np, &mut h) {
            rows.extend(h.chunks(n).take(c).map(<[f64]>::to_vec));
        }
    }
    anyhow::ensure!(
        !rows.is_empty(),
        "bench: model {} has no position measurement",
        model.name
    );
    let r_pos = 0.25; // (0.5 m)²
    let p0 = p.clone();
    let t_upd = fastest(|| {
        p.copy_from_slice(&p0);
        for _ in aid {
            for h in &rows {
                black_box(joseph_update(
                    &mut x,
                    &mut p,
                    (h, 0.1, r_pos),
                    f64::INFINITY,
                    &mut u,
                    &mut k,
                ));
            }
        }
    });
    Ok(Stage {
        name: "update (position fix)",
        us: per(t_upd),
        floor_us: None,
        floor_is: "",
    })
}

/// Formatting a nav.txt row (ten fixed-point columns and nine σ) per IMU sample of `sim`, and
/// copying the same bytes (the floor).
fn write_stage(sim: &SimOutput) -> Stage {
    let per = |s: f64| s * 1e6 / sim.imu.samples.len() as f64;
    // write: a navigation row with nine σ columns; floor: copying the same bytes
    let mut buf = Vec::with_capacity(256 * 1024);
    let mut written = 0usize;
    let sig = [
        1.234e-7, 2.5e-7, 0.61, 1.2e-3, 1.1e-3, 2.2e-3, 3.3e-6, 3.1e-6, 8.9e-5,
    ];
    let t_write = fastest(|| {
        written = 0;
        for (i, s) in sim.imu.samples.iter().enumerate() {
            let row = crate::io::truth::TruthRow {
                t: s.t,
                lat: 0.4925 + i as f64 * 1e-12,
                lon: 1.972,
                h: 0.5,
                v: Vector3::new(1e-3, -2e-3, 5e-4),
                euler: Vector3::new(1e-4, -2e-4, 0.3),
            };
            // as filter's nav.txt thread appends them
            crate::io::truth::push_row_values(&mut buf, &row);
            for v in sig {
                buf.push(b' ');
                crate::io::fixed::push_sci(&mut buf, v * (1.0 + i as f64 * 1e-9), 4);
            }
            buf.push(b'\n');
            if buf.len() > 200 * 1024 {
                written += buf.len();
                black_box(&buf);
                buf.clear();
            }
        }
        written += buf.len();
        buf.clear();
    });
    let src = vec![7u8; 256 * 1024];
    let t_copy = fastest(|| {
        let mut left = written;
        while left > 0 {
            let c = left.min(src.len());
            buf.clear();
            buf.extend_from_slice(&src[..c]);
            black_box(&buf);
            left -= c;
        }
    });
    Stage {
        name: "format nav.txt row",
        us: per(t_write),
        floor_us: Some(per(t_copy)),
        floor_is: "copying the row's bytes",
    }
}
