//! `sinsmodel reproduce [--quick] [--priors-grid] [--consistency] --out DIR`: the paper's §3 and
//! Fig. 1 (DESIGN §6) with P28 and P31, figures, the priors study and the consistency check.

use anyhow::{Context, Result};
use clap::Args;
use serde::Serialize;
use sinsmodel::filter::{self, FilterRun};
use sinsmodel::model::Model;
use sinsmodel::plot::{line_plot, Scale, Series};
use sinsmodel::reproduce::{self, CaseResult, Priors};
use sinsmodel::scenario::Scenario;
use sinsmodel::simulator::simulate;
use sinsmodel::{atomic_file, progress};
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
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Output directory.
    #[arg(long, default_value = "out/reproduce")]
    out: PathBuf,
}

#[derive(Serialize)]
struct Results {
    cases: Vec<CaseResult>,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    priors_grid: Vec<GridPoint>,
    notes: Vec<String>,
}

#[derive(Serialize, Clone)]
struct GridPoint {
    sigma_d: String,
    sigma_nabla: String,
    phi0: String,
    p28_arcsec: [f64; 2],
    p31_arcsec: [f64; 2],
    ratio: f64,
}

const ARCSEC: f64 = 180.0 / std::f64::consts::PI * 3600.0;

fn model_error_series(run: &FilterRun, label: &str, comp: usize) -> Series {
    Series {
        label: label.to_string(),
        points: run
            .records
            .iter()
            .filter_map(|r| {
                r.phi_true
                    .map(|pt| (r.t / 3600.0, (r.phi_est[comp] - pt[comp]) * ARCSEC))
            })
            .collect(),
    }
}

/// Runs the command.
pub fn run(args: &ReproduceArgs) -> Result<()> {
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("cannot create {}", args.out.display()))?;
    if args.consistency {
        return consistency(args);
    }
    let priors = Priors::default();
    let mut results = Vec::new();
    let mut grid = Vec::new();
    for case in reproduce::cases(args.quick, args.seed) {
        let pb = progress::bar(1000, case.name);
        let (res, sim, runs) = reproduce::run_case(&case, &priors, args.seed, |_, f| {
            pb.set_position((f * 1000.0) as u64)
        })?;
        pb.finish_and_clear();
        eprintln!(
            "{:<12} P28 {:>9.2} {:>9.2}  P31 {:>8.2} {:>8.2} arcsec  ratio {:.2}",
            res.name,
            res.model_error_rms_arcsec["P28"][0],
            res.model_error_rms_arcsec["P28"][1],
            res.model_error_rms_arcsec["P31"][0],
            res.model_error_rms_arcsec["P31"][1],
            res.ratio
        );
        if case.name == "fig1" {
            let pos = |c: usize, l: &str| Series {
                label: l.into(),
                points: runs[1]
                    .records
                    .iter()
                    .filter_map(|r| r.pos_err_ne.map(|p| (r.t / 3600.0, p[c] / 1000.0)))
                    .collect(),
            };
            line_plot(
                &args.out.join("fig1_position_error.png"),
                "Fig. 1: free-inertial position error from d only (8 g, 90 Hz on N, E, D)",
                "time [h]",
                "position error [km]",
                &[pos(0, "north"), pos(1, "east")],
                Scale::Linear,
            )?;
        }
        for (comp, axis) in [(0, "north"), (1, "east")] {
            line_plot(
                &args
                    .out
                    .join(format!("{}_model_error_{axis}.png", case.name)),
                &format!(
                    "{}: model error e_{} = phi_hat - phi",
                    case.name,
                    &axis[..1].to_uppercase()
                ),
                "time [h]",
                "model error [arcsec]",
                &[
                    model_error_series(&runs[0], "P28", comp),
                    model_error_series(&runs[1], "P31", comp),
                ],
                Scale::Linear,
            )?;
        }
        if args.priors_grid && case.name == "sine" {
            grid = priors_grid(&case, &sim, args.seed)?;
        }
        results.push(res);
    }
    let notes = vec![
        format!(
            "priors (1-sigma): phi0 {}, nabla {}, d {}; measurements: sigma_v {}, sigma_p {} at 1 Hz (sine_random: position only)",
            priors.phi0, priors.nabla, priors.d, priors.sigma_v, priors.sigma_p
        ),
        "model error RMS over the second hour (fig1: hours 1-4; --quick: second half of 10 min)".into(),
        "vibration simulated at 2 kHz; regressor means from the increments (<f^2> attenuated by sinc^2 = 0.993 at 90 Hz, not corrected)".into(),
    ];
    let out = Results {
        cases: results,
        priors_grid: grid,
        notes,
    };
    atomic_file::write_text(
        &args.out.join("results.json"),
        &serde_json::to_string_pretty(&out)?,
    )?;
    atomic_file::write_text(&args.out.join("results.md"), &markdown(&out, args.quick))?;
    eprintln!("wrote {}", args.out.join("results.json").display());
    Ok(())
}

fn markdown(r: &Results, quick: bool) -> String {
    let mut s = format!(
        "# Reproduction of Yu et al. 2013 §3{}\n\nModel error e = φ̂ − φ (RMS, arcsec, north / east), open-loop filters on the same simulated data.\n\n\
         | case | P28 N | P28 E | P31 N | P31 E | P28/P31 |\n|---|---|---|---|---|---|\n",
        if quick { " (quick: 10-minute cases)" } else { "" }
    );
    for c in &r.cases {
        let (a, b) = (
            c.model_error_rms_arcsec["P28"],
            c.model_error_rms_arcsec["P31"],
        );
        s.push_str(&format!(
            "| {} | {:.2} | {:.2} | {:.2} | {:.2} | {:.2} |\n",
            c.name, a[0], a[1], b[0], b[1], c.ratio
        ));
    }
    s.push('\n');
    for n in &r.notes {
        s.push_str(&format!("- {n}\n"));
    }
    if !r.priors_grid.is_empty() {
        s.push_str("\n## Priors study (sine case)\n\n| σ_d | σ_∇ | φ₀ | P28 (N, E) | P31 (N, E) | ratio |\n|---|---|---|---|---|---|\n");
        for g in &r.priors_grid {
            s.push_str(&format!(
                "| {} | {} | {} | {:.1}, {:.1} | {:.1}, {:.1} | {:.2} |\n",
                g.sigma_d,
                g.sigma_nabla,
                g.phi0,
                g.p28_arcsec[0],
                g.p28_arcsec[1],
                g.p31_arcsec[0],
                g.p31_arcsec[1],
                g.ratio
            ));
        }
    }
    s
}

fn priors_grid(
    case: &reproduce::Case,
    sim: &sinsmodel::simulator::SimOutput,
    seed: u64,
) -> Result<Vec<GridPoint>> {
    let mut points = Vec::new();
    let mut settings = Vec::new();
    for d in ["10 ug/g^2", "100 ug/g^2", "1000 ug/g^2"] {
        for nabla in ["10 ug", "100 ug", "1000 ug"] {
            settings.push((d, nabla, "60 arcsec"));
        }
    }
    for phi0 in ["10 arcsec", "600 arcsec"] {
        settings.push(("100 ug/g^2", "100 ug", phi0));
    }
    let pb = progress::bar(settings.len() as u64, "priors");
    for (k, (d, nabla, phi0)) in settings.into_iter().enumerate() {
        let pr = Priors {
            d: d.into(),
            nabla: nabla.into(),
            phi0: phi0.into(),
            ..Priors::default()
        };
        let aid = reproduce::aiding_from_truth(sim, &pr, case.velocity_updates, seed)?;
        let mut e = Vec::new();
        for m in ["P28", "P31"] {
            let model = Model::parse(m)?;
            let cfg = reproduce::config(&model, &pr)?;
            let run = filter::run(
                &model,
                &cfg,
                &sim.imu,
                sim.start,
                &aid,
                Some(&sim.truth),
                |_| {},
            );
            e.push(
                filter::model_error_rms_arcsec(&run, case.window.0, case.window.1)
                    .unwrap_or([f64::NAN; 2]),
            );
        }
        let ratio = e[0][0].hypot(e[0][1]) / e[1][0].hypot(e[1][1]);
        eprintln!("  sigma_d {d:>11} sigma_nabla {nabla:>8} phi0 {phi0:>10}: ratio {ratio:.2}");
        points.push(GridPoint {
            sigma_d: d.into(),
            sigma_nabla: nabla.into(),
            phi0: phi0.into(),
            p28_arcsec: e[0],
            p31_arcsec: e[1],
            ratio,
        });
        pb.set_position(k as u64 + 1);
    }
    pb.finish_and_clear();
    Ok(points)
}

/// Wilson–Hilferty approximation of the χ² quantile with `k` degrees of freedom at normal z.
pub fn chi2_quantile(k: f64, z: f64) -> f64 {
    let a = 2.0 / (9.0 * k);
    k * (1.0 - a + z * a.sqrt()).powi(3)
}

#[derive(Serialize)]
struct Consistency {
    seeds: usize,
    model: String,
    nees_dim: usize,
    nees_mean: f64,
    nees_band: [f64; 2],
    nees_fraction_in_band: f64,
    nis_mean: f64,
    nis_band: [f64; 2],
    nis_fraction_in_band: f64,
}

/// 20-seed Monte Carlo with the true model: every seed draws the initial navigation errors and
/// all 24 instrument parameters of P31 from the filter's prior N(0, P0), injects them, and runs P31.
fn consistency(args: &ReproduceArgs) -> Result<()> {
    let seeds = 20usize;
    let secs = if args.quick { 600.0 } else { 3600.0 };
    let priors = Priors::default();
    let model = Model::parse("P31")?;
    let n = model.n();
    let cfg0 = reproduce::config(&model, &priors)?;
    let base = reproduce::cases(true, 0)[0]
        .scenario
        .replace("duration_s = 600", &format!("duration_s = {secs}"));
    let base = &base[..base.find("[errors]").context("errors table")?];
    let mut nees_sum: Vec<f64> = Vec::new();
    let mut nis_sum: Vec<f64> = Vec::new();
    let pb = progress::bar(seeds as u64, "monte carlo");
    for s in 0..seeds {
        let mut rng = sinsmodel::rng::Rng::new(1000 + s as u64);
        let x0: Vec<f64> = (0..n).map(|i| cfg0.prior_sigma[i] * rng.normal()).collect();
        let mut text = base.replace("seed = 0", &format!("seed = {}", 100 + s));
        text.push_str("[errors]\n");
        for (i, name) in model.names.iter().enumerate().skip(7) {
            text.push_str(&format!("{name} = \"{:e} {}\"\n", x0[i], model.unit(i)));
        }
        text.push_str(reproduce::PAPER_NOISE);
        let sc = Scenario::parse(&text, "consistency")?;
        let sim = simulate(&sc, |_| {});
        let aid = reproduce::aiding_from_truth(&sim, &priors, true, 100 + s as u64)?;
        let mut start = sim.start;
        start.q = nalgebra::UnitQuaternion::from_scaled_axis(-nalgebra::Vector3::new(
            x0[0], x0[1], x0[2],
        )) * start.q;
        start.v.x += x0[3];
        start.v.y += x0[4];
        start.lat += x0[5];
        start.lon += x0[6];
        let mut cfg = cfg0.clone();
        cfg.keep_covariance = true;
        let run = filter::run(
            &model,
            &cfg,
            &sim.imu,
            start,
            &aid,
            Some(&sim.truth),
            |_| {},
        );
        let mut k = 0;
        for r in &run.records {
            let (Some(phi), Some(cov)) = (r.phi_true, r.cov.as_ref()) else {
                continue;
            };
            let tr = sim
                .truth
                .iter()
                .find(|t| (t.t - r.t).abs() < 1e-6)
                .context("truth row")?;
            let mut xt = x0.clone();
            xt[0] = phi.x;
            xt[1] = phi.y;
            xt[2] = phi.z;
            xt[3] = r.nav.v.x - tr.v.x;
            xt[4] = r.nav.v.y - tr.v.y;
            xt[5] = r.nav.lat - tr.lat;
            xt[6] = r.nav.lon - tr.lon;
            let e: Vec<f64> = (0..n).map(|i| r.x[i] - xt[i]).collect();
            let p = nalgebra::DMatrix::from_row_slice(n, n, cov);
            let ev = nalgebra::DVector::from_vec(e);
            let nees = match p.cholesky() {
                Some(ch) => ev.dot(&ch.solve(&ev)),
                None => f64::NAN,
            };
            if nees_sum.len() <= k {
                nees_sum.push(0.0);
            }
            nees_sum[k] += nees;
            k += 1;
        }
        for (j, inn) in run.innovations.iter().enumerate() {
            if nis_sum.len() <= j {
                nis_sum.push(0.0);
            }
            nis_sum[j] += inn.nu * inn.nu / inn.s;
        }
        pb.set_position(s as u64 + 1);
    }
    pb.finish_and_clear();
    let m = seeds as f64;
    let band = |dof: f64| {
        [
            chi2_quantile(dof * m, -1.959_964) / m,
            chi2_quantile(dof * m, 1.959_964) / m,
        ]
    };
    let nees_avg: Vec<f64> = nees_sum.iter().map(|v| v / m).collect();
    let nis_avg: Vec<f64> = nis_sum.iter().map(|v| v / m).collect();
    let (nb, ib) = (band(n as f64), band(1.0));
    let frac = |v: &[f64], b: [f64; 2]| {
        v.iter().filter(|x| **x >= b[0] && **x <= b[1]).count() as f64 / v.len().max(1) as f64
    };
    let out = Consistency {
        seeds,
        model: model.name.clone(),
        nees_dim: n,
        nees_mean: nees_avg.iter().sum::<f64>() / nees_avg.len().max(1) as f64 / n as f64,
        nees_band: [nb[0] / n as f64, nb[1] / n as f64],
        nees_fraction_in_band: frac(&nees_avg, nb),
        nis_mean: nis_avg.iter().sum::<f64>() / nis_avg.len().max(1) as f64,
        nis_band: ib,
        nis_fraction_in_band: frac(&nis_avg, ib),
    };
    eprintln!(
        "consistency ({} seeds, {}): NEES/n mean {:.3} (95% band of the 20-run average {:.3}..{:.3}), {:.1}% of epochs in band; \
         NIS mean {:.3} (band {:.3}..{:.3}), {:.1}% in band",
        seeds,
        out.model,
        out.nees_mean,
        out.nees_band[0],
        out.nees_band[1],
        100.0 * out.nees_fraction_in_band,
        out.nis_mean,
        out.nis_band[0],
        out.nis_band[1],
        100.0 * out.nis_fraction_in_band
    );
    let series = |v: &[f64], scale: f64, l: &str| Series {
        label: l.into(),
        points: v
            .iter()
            .enumerate()
            .map(|(k, x)| (k as f64, x / scale))
            .collect(),
    };
    line_plot(
        &args.out.join("consistency_nees.png"),
        "Average NEES / n over 20 seeds (P31, true model)",
        "update epoch [s]",
        "NEES / n",
        &[
            series(&nees_avg, n as f64, "NEES/n"),
            Series {
                label: "95% band".into(),
                points: vec![
                    (0.0, out.nees_band[0]),
                    (nees_avg.len() as f64, out.nees_band[0]),
                ],
            },
            Series {
                label: "95% band".into(),
                points: vec![
                    (0.0, out.nees_band[1]),
                    (nees_avg.len() as f64, out.nees_band[1]),
                ],
            },
        ],
        Scale::Linear,
    )?;
    atomic_file::write_text(
        &args.out.join("consistency.json"),
        &serde_json::to_string_pretty(&out)?,
    )?;
    Ok(())
}
