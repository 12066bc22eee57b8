//! What `filter` writes and prints: the files written as the epochs come (states.txt,
//! model_error.txt) and innovations.txt, outages.json, and the text tables of the summary (NIS
//! per channel, drift after each GNSS outage, the model-error RMS).

use crate::estimate::{filter, metrics};
use crate::io::atomic_file::{AtomicFile, OutputDir};
use crate::model::Model;
use anyhow::Result;
use std::io::Write;

/// The files written as the epochs come: states.txt, and model_error.txt with truth; and what
/// the summary needs of each epoch: t [s] and the model error e = φ̂ − φ (north, east) [rad].
pub struct EpochFiles {
    /// states.txt.
    pub states: AtomicFile,
    /// model_error.txt, with truth.
    pub model_error: Option<AtomicFile>,
    /// t [s] and e north, east [rad] (None where the truth has no row) of every epoch.
    pub errors: Vec<(f64, Option<[f64; 2]>)>,
    /// The model's indices of phi_n, phi_e, phi_d.
    phi: [Option<usize>; 3],
    /// Per axis (north, east, down): |e| [rad] and |e| / σ of every epoch with truth.
    disagreement: [Vec<(f64, f64)>; 3],
}

impl EpochFiles {
    /// Creates the files in `out` with their headers.
    pub fn create(
        out: &OutputDir,
        model: &Model,
        cfg: &filter::FilterConfig,
        provenance: &str,
        with_truth: bool,
    ) -> Result<EpochFiles> {
        let mut states = AtomicFile::create(&out.file("states.txt"))?;
        let w = states.writer();
        writeln!(w, "# {provenance}")?;
        writeln!(
            w,
            "# model {} ({} states), mode {}; estimate and 1-sigma of every state, SI units (rad, m/s, rad/s, m/s^2, 1, s^2/m …)",
            model.name,
            model.n(),
            cfg.mode.word()
        )?;
        write!(w, "# t")?;
        for (i, n) in model.names.iter().enumerate() {
            write!(w, " {n}[{}]", model.unit(i))?;
        }
        for n in &model.names {
            write!(w, " sigma_{n}")?;
        }
        writeln!(w)?;
        let model_error = match with_truth {
            true => {
                let mut f = AtomicFile::create(&out.file("model_error.txt"))?;
                let w = f.writer();
                writeln!(w, "# {provenance}")?;
                writeln!(
                    w,
                    "# t phi_true_n phi_true_e phi_true_d phi_est_n phi_est_e phi_est_d e_n e_e [arcsec]"
                )?;
                Some(f)
            }
            false => None,
        };
        Ok(EpochFiles {
            states,
            model_error,
            errors: Vec::new(),
            phi: ["phi_n", "phi_e", "phi_d"].map(|n| model.index_of(n)),
            disagreement: Default::default(),
        })
    }

    /// Writes one epoch's record.
    pub fn record(&mut self, r: &filter::Record) -> Result<()> {
        let arcsec = metrics::ARCSEC_PER_RAD;
        let w = self.states.writer();
        write!(w, "{:.4}", r.t)?;
        for v in r.x.iter().chain(&r.sigma) {
            write!(w, " {v:.6e}")?;
        }
        writeln!(w)?;
        let mut e_ne = None;
        if let (Some(f), Some(p)) = (self.model_error.as_mut(), r.phi_true) {
            let e = r.phi_est - p;
            e_ne = Some([e.x, e.y]);
            crate::estimate::metrics::add_attitude_disagreement(
                &mut self.disagreement,
                r,
                self.phi,
            );
            writeln!(
                f.writer(),
                "{:.4} {:.4} {:.4} {:.4} {:.4} {:.4} {:.4} {:.4} {:.4}",
                r.t,
                p.x * arcsec,
                p.y * arcsec,
                p.z * arcsec,
                r.phi_est.x * arcsec,
                r.phi_est.y * arcsec,
                r.phi_est.z * arcsec,
                e.x * arcsec,
                e.y * arcsec
            )?;
        }
        self.errors.push((r.t, e_ne));
        Ok(())
    }

    /// Where the truth contradicts the filter itself, in words (None when it does not): on
    /// an axis where the median model error over the epochs with truth exceeds 5° and 10 of
    /// its σ, the truth is not of this run's attitude (yaw in radians or with the opposite
    /// sign, another body frame).
    pub fn truth_disagreement(&self) -> Option<String> {
        crate::estimate::metrics::truth_disagreement(&self.disagreement, "model_error.txt measures")
    }

    /// Commits states.txt, innovations.txt (written now from `run`) and model_error.txt;
    /// returns the epochs' model errors.
    pub fn commit(
        self,
        out: &OutputDir,
        run: &filter::FilterRun,
        provenance: &str,
    ) -> Result<Vec<(f64, Option<[f64; 2]>)>> {
        self.states.commit()?;
        let mut f = AtomicFile::create(&out.file("innovations.txt"))?;
        let w = f.writer();
        writeln!(w, "# {provenance}")?;
        writeln!(w, "# t measurement component nu S (SI; nu = z - H x)")?;
        for i in &run.innovations {
            writeln!(
                w,
                "{:.4} {} {} {:.6e} {:.6e}",
                i.t, i.meas, i.component, i.nu, i.s
            )?;
        }
        if !run.gated.is_empty() {
            writeln!(
                w,
                "# rejected by the innovation gate (not applied, not above): t measurement component nu S"
            )?;
            for i in &run.gated {
                writeln!(
                    w,
                    "# {:.4} {} {} {:.6e} {:.6e}",
                    i.t, i.meas, i.component, i.nu, i.s
                )?;
            }
        }
        f.commit()?;
        if let Some(f) = self.model_error {
            f.commit()?;
        }
        Ok(self.errors)
    }
}

/// outages.json: the drift of the filter's solution at the first fix after each outage [m],
/// with the command line `provenance`.
pub fn outages_json(provenance: &str, rows: &[metrics::OutageDrift]) -> Result<String> {
    Ok(serde_json::to_string_pretty(&serde_json::json!({
        "command": provenance,
        "what": "GNSS outages: horizontal position drift of the filter's solution at the first aiding fix after each, against that fix (its pos_ne innovation), metres",
        "outages": rows,
    }))?)
}

/// The table of the drift at the end of each GNSS outage (empty without outages); times from
/// `t_first`, the first IMU sample [s].
pub fn outage_table(rows: &[metrics::OutageDrift], t_first: f64) -> String {
    if rows.is_empty() {
        return String::new();
    }
    let mut s = String::from(
        "GNSS outages: drift at the first fix after each (the filter's solution against that fix; times in seconds from the first IMU sample, as --outage counts)\n",
    );
    s.push_str(&format!(
        "  {:>10} {:>9} {:>10} {:>9} {:>9} {:>10}\n",
        "start[s]", "length[s]", "fix at[s]", "north[m]", "east[m]", "horiz.[m]"
    ));
    for r in rows {
        s.push_str(&format!(
            "  {:>10.1} {:>9.1} {:>10.1} {:>9.2} {:>9.2} {:>10.2}\n",
            r.start_s - t_first,
            r.end_s - r.start_s,
            r.fix_t_s - t_first,
            r.drift_n_m,
            r.drift_e_m,
            r.drift_horizontal_m
        ));
    }
    s
}

/// The model error RMS over the second half of the update epochs, in words (empty without
/// epochs).
pub fn model_error_line(errors: &[(f64, Option<[f64; 2]>)]) -> String {
    let Some(h) = metrics::second_half_rms(errors) else {
        return String::new();
    };
    match h.rms_arcsec {
        None => format!(
            "model error: no update epoch of the second half ({:.0}–{:.0} s) has a truth row: no RMS\n",
            h.mid, h.last
        ),
        Some(rms) => format!(
            "model error e = phi_hat - phi (truth), RMS over the second half ({:.0}–{:.0} s{}): north {:.2} arcsec, east {:.2} arcsec\n",
            h.mid,
            h.last,
            if h.with_truth < h.epochs {
                format!(", the {} of {} update epochs with a truth row", h.with_truth, h.epochs)
            } else {
                String::new()
            },
            rms[0],
            rms[1]
        ),
    }
}

/// The mean NIS of every channel against its 95 % band, with a word on each.
pub fn nis_table(run: &filter::FilterRun) -> String {
    let mut s = String::from(
        "innovations: mean NIS per channel (1 for a consistent filter; 95 % band for the count)\n",
    );
    for c in filter::nis_by_channel(run) {
        s.push_str(&format!(
            "  {:<6} {:>6} updates  mean NIS {:>9}  band {:.2}..{:.2}  {}\n",
            c.channel,
            c.count,
            crate::explain::sig3(c.mean),
            c.band[0],
            c.band[1],
            match c.verdict() {
                "too large" =>
                    "too large: the model misses an error or the noise/priors are too small",
                "too small" => "too small: the noise or the measurement sigma is pessimistic",
                v => v,
            }
        ));
    }
    s
}
