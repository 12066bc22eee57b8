//! What `reproduce` prints and writes: the table of the cases' model error, results.json's
//! layout and notes, results.md, the consistency lines, and the figures (model error per case,
//! Fig. 1's position error, the consistency NEES; with the `cli` feature).

use crate::experiment::reproduce::{CaseResult, Consistency, GridPoint, Priors};
use serde::Serialize;

/// results.json: the cases, the priors study (when run) and the notes.
#[derive(Serialize)]
pub struct Results {
    /// One result per case.
    pub cases: Vec<CaseResult>,
    /// The priors study on the sine case (empty when not run).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub priors_grid: Vec<GridPoint>,
    /// Settings in words.
    pub notes: Vec<String>,
}

/// What the table of model errors shows (`quick`: 10-minute cases), two lines.
pub fn table_intro(quick: bool) -> String {
    format!(
        "model error e = phi_hat - phi of the open-loop P28 and P31 filters on the same data, RMS \
         over {} [arcsec], north and east;\nratio = |P28 (N, E)| / |P31 (N, E)| (how much better \
         the 31-state model knows the attitude)",
        if quick {
            "the second half of each 10-minute case"
        } else {
            "the second hour (fig1: hours 1-4)"
        }
    )
}

/// The table's header line.
pub fn table_header() -> String {
    format!(
        "{:<12} {:>9} {:>9}  {:>8} {:>8}  P28/P31",
        "case", "P28 N", "P28 E", "P31 N", "P31 E"
    )
}

/// One case's row of the table [arcsec].
pub fn table_row(res: &CaseResult) -> String {
    format!(
        "{:<12} {:>9.2} {:>9.2}  {:>8.2} {:>8.2}  {:.2}",
        res.name,
        res.model_error_rms_arcsec["P28"][0],
        res.model_error_rms_arcsec["P28"][1],
        res.model_error_rms_arcsec["P31"][0],
        res.model_error_rms_arcsec["P31"][1],
        res.ratio
    )
}

/// One point of the priors study, as printed while it runs.
pub fn grid_line(g: &GridPoint) -> String {
    format!(
        "  sigma_d {:>11} sigma_nabla {:>8} phi0 {:>10}: ratio {:.2}",
        g.sigma_d, g.sigma_nabla, g.phi0, g.ratio
    )
}

/// The notes of results.json and results.md: the priors, the RMS window, the simulation.
pub fn notes(priors: &Priors) -> Vec<String> {
    vec![
        format!(
            "priors (1-sigma): phi0 {}, nabla {}, d {}; measurements: sigma_v {}, sigma_p {} at 1 Hz (sine_random: position only)",
            priors.phi0, priors.nabla, priors.d, priors.sigma_v, priors.sigma_p
        ),
        "model error RMS over the second hour (fig1: hours 1-4; --quick: second half of 10 min)".into(),
        "vibration simulated at 2 kHz; regressor means from the increments (<f^2> attenuated by sinc^2 = 0.993 at 90 Hz, not corrected)".into(),
    ]
}

/// results.md (`quick`: 10-minute cases).
pub fn markdown(r: &Results, quick: bool) -> String {
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

/// The consistency Monte Carlo in two lines: the numbers against their bands, and the verdict.
pub fn consistency_lines(out: &Consistency) -> [String; 2] {
    [
        format!(
            "consistency ({} seeds, {}): NEES/n mean {:.3} (95% band of the 20-run average {:.3}..{:.3}), {:.1}% of epochs in band; \
             NIS mean {:.3} (band {:.3}..{:.3}), {:.1}% in band",
            out.seeds,
            out.model,
            out.nees_mean,
            out.nees_band[0],
            out.nees_band[1],
            100.0 * out.nees_fraction_in_band,
            out.nis_mean,
            out.nis_band[0],
            out.nis_band[1],
            100.0 * out.nis_fraction_in_band
        ),
        format!("verdict: {}", out.verdict),
    ]
}

#[cfg(feature = "cli")]
pub use figures::{case_figures, consistency_figure};

/// The PNG figures (plotting backend).
#[cfg(feature = "cli")]
mod figures {
    use crate::estimate::filter::FilterRun;
    use crate::experiment::reproduce::Consistency;
    use crate::io::atomic_file::OutputDir;
    use crate::report::plot::{line_plot, Scale, Series};
    use anyhow::Result;

    /// Arcseconds per radian.
    const ARCSEC: f64 = 180.0 / std::f64::consts::PI * 3600.0;

    /// The model error e = φ̂ − φ of `run`'s component `comp` (0 north, 1 east) [arcsec] against
    /// time [h], where the run has truth.
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

    /// A case's figures in `dir`: for fig1 the free-inertial position error [km] of the P31 run,
    /// then the model error north and east of both runs (`runs`: P28, P31).
    pub fn case_figures(dir: &OutputDir, name: &str, runs: &[FilterRun]) -> Result<()> {
        if name == "fig1" {
            let pos = |c: usize, l: &str| Series {
                label: l.into(),
                points: runs[1]
                    .records
                    .iter()
                    .filter_map(|r| r.pos_err_ne.map(|p| (r.t / 3600.0, p[c] / 1000.0)))
                    .collect(),
            };
            line_plot(
                &dir.file("fig1_position_error.png"),
                "Fig. 1: free-inertial position error from d only (8 g, 90 Hz on N, E, D)",
                "time [h]",
                "position error [km]",
                &[pos(0, "north"), pos(1, "east")],
                Scale::Linear,
            )?;
        }
        for (comp, axis) in [(0, "north"), (1, "east")] {
            line_plot(
                &dir.file(&format!("{name}_model_error_{axis}.png")),
                &format!(
                    "{name}: model error e_{} = phi_hat - phi",
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
        Ok(())
    }

    /// consistency_nees.png in `dir`: the seed-averaged NEES / n per update epoch and its 95 %
    /// band.
    pub fn consistency_figure(dir: &OutputDir, out: &Consistency) -> Result<()> {
        let (nees_avg, n) = (&out.nees_avg, out.nees_dim);
        let series = |v: &[f64], scale: f64, l: &str| Series {
            label: l.into(),
            points: v
                .iter()
                .enumerate()
                .map(|(k, x)| (k as f64, x / scale))
                .collect(),
        };
        line_plot(
            &dir.file("consistency_nees.png"),
            "Average NEES / n over 20 seeds (P31, true model)",
            "update epoch [s]",
            "NEES / n",
            &[
                series(nees_avg, n as f64, "NEES/n"),
                Series {
                    label: "95% band of the 20-run average".into(),
                    points: vec![
                        (0.0, out.nees_band[0]),
                        (nees_avg.len() as f64, out.nees_band[0]),
                        (nees_avg.len() as f64, out.nees_band[1]),
                        (0.0, out.nees_band[1]),
                    ],
                },
            ],
            Scale::Linear,
        )
    }
}
