//! `sinsmodel filter --model MODEL --imu FILE --aid FILE [--truth FILE] [--init …] --out DIR`.

use super::data::DataArgs;
use anyhow::Result;
use clap::Args;
use sinsmodel::estimate::{filter, metrics};
use sinsmodel::io::atomic_file::{AtomicFile, OutputDir};
use sinsmodel::model::Model;
use sinsmodel::report::progress;
use std::io::Write;
use std::path::PathBuf;

/// Arguments of `filter`.
#[derive(Args)]
pub struct FilterArgs {
    /// Model, e.g. P31, P28+kaq_x_xy, P31+vertical.
    #[arg(long)]
    model: String,
    #[command(flatten)]
    data: DataArgs,
    /// Output directory: states.txt, innovations.txt, nav.txt (the navigation solution with
    /// 1-σ) and its plots, model_error.txt (with truth), outages.json (with --outage); written
    /// complete or not at all, replacing only an earlier sinsmodel run's directory.
    #[arg(long)]
    out: PathBuf,
    /// Rate of the navigation solution nav.txt [Hz] (default: every IMU sample).
    #[arg(long)]
    nav_rate: Option<f64>,
    /// Read the whole IMU file before filtering (the pre-streaming path, kept as the baseline
    /// `sinsmodel bench` measures the stream against).
    #[arg(long, hide = true)]
    in_memory: bool,
}

/// Runs the command: one streamed pass (memory does not grow with the IMU or truth file);
/// states.txt and model_error.txt are written as the epochs come, innovations.txt at the end,
/// and the directory appears only when the run succeeded.
pub fn run(args: &FilterArgs) -> Result<()> {
    let model = Model::parse(&args.model)?;
    let mut cfg = args.data.config(&model, false)?;
    let inputs = args.data.input_paths();
    let refs: Vec<&std::path::Path> = inputs.iter().map(|p| p.as_path()).collect();
    let out = OutputDir::create(&args.out, &refs, "filter")?;
    super::data::print_noise(&args.data)?;
    let mut inputs = args.data.open(&mut super::data::note)?;
    if args.in_memory {
        inputs.imu = inputs.imu.into_memory()?;
    }
    let start = inputs.start;
    sinsmodel::data::apply_opened(&mut cfg, &model, inputs.init_sigma, inputs.step_s);
    let provenance = super::command_line();
    let with_truth = inputs.truth.is_some();
    let mut files = EpochFiles::create(&out, &model, &cfg, &provenance, with_truth)?;
    if let Some(r) = args.nav_rate {
        if !(r.is_finite() && r > 0.0 && r <= 1e5) {
            anyhow::bail!("--nav-rate {r}: expected a rate in (0, 1e5] Hz");
        }
    }
    let clock = super::nav_out::RowClock::new(start.t, args.nav_rate, inputs.imu.interval());
    let mut nav =
        super::nav_out::NavWriter::create(&out.file("nav.txt"), &model, clock, &provenance)?;
    let pb = progress::bar(1000, "filter");
    let mut epochs = inputs.aid.epochs_outside(&inputs.outages);
    let mut io = filter::StreamIo {
        samples: &mut inputs.imu,
        aiding: &mut epochs,
        truth: inputs
            .truth
            .as_mut()
            .map(|t| t as &mut dyn sinsmodel::io::truth::TruthLookup),
    };
    let run = filter::run_stream(
        &model,
        &cfg,
        start,
        &mut io,
        |f| pb.set_position((f * 1000.0) as u64),
        &mut |_| {},
        &mut nav,
        &mut |r| files.record(r),
        false,
    )?;
    drop(epochs);
    pb.finish_and_clear();
    run.check().map_err(anyhow::Error::msg)?;
    if let Some(tr) = inputs.truth.take() {
        tr.finish()?;
        check_truth_coverage(&files.errors)?;
    }
    let (t_first, t_last) = (inputs.imu.first_t(), inputs.imu.last_t());
    sinsmodel::data::check_inside(files.errors.len(), inputs.aid.len(), start.t, t_last)?;
    let errors = files.commit(&out, &run, &provenance)?;
    let nav_rows = nav.rows;
    if nav_rows == 0 {
        anyhow::bail!(
            "--nav-rate {}: not one row of nav.txt within the data ({:.3} s of filtering): choose a higher rate",
            args.nav_rate.unwrap_or(0.0),
            t_last - start.t
        );
    }
    nav.finish(&out.file("nav.png"))?;
    let outage_rows = metrics::outage_drifts(&inputs.outages, &run, t_first, t_last)?;
    if !outage_rows.is_empty() {
        sinsmodel::io::atomic_file::write_text(
            &out.file("outages.json"),
            &serde_json::to_string_pretty(&serde_json::json!({
                "command": provenance,
                "what": "GNSS outages: horizontal position drift of the filter's solution at the first aiding fix after each, against that fix (its pos_ne innovation), metres",
                "outages": outage_rows,
            }))?,
        )?;
    }
    out.commit()?;
    let filtered_from = if inputs.skipped_samples > 0 {
        start.t
    } else {
        t_first
    };
    eprintln!(
        "filtered {} samples ({:.1} s) with {} ({} states, {} loop): {} scalar updates",
        inputs.imu.count() - inputs.skipped_samples,
        t_last - filtered_from,
        model.name,
        model.n(),
        cfg.mode.word(),
        run.innovations.len(),
    );
    eprint!("{}", nis_table(&run));
    eprint!("{}", outage_table(&outage_rows, t_first));
    if with_truth {
        eprint!("{}", model_error_line(&errors));
    }
    let mut names = vec![
        "states.txt",
        "innovations.txt",
        "nav.txt",
        "nav_track.png",
        "nav_sigma.png",
    ];
    if with_truth {
        names.push("model_error.txt");
    }
    if !inputs.outages.is_empty() {
        names.push("outages.json");
    }
    eprintln!(
        "wrote {} in {} (nav.txt: {nav_rows} rows)",
        names.join(", "),
        args.out.display()
    );
    Ok(())
}

/// The files written as the epochs come: states.txt, and model_error.txt with truth; and what
/// the summary needs of each epoch: t [s] and the model error e = φ̂ − φ (north, east) [rad].
struct EpochFiles {
    /// states.txt.
    states: AtomicFile,
    /// model_error.txt, with truth.
    model_error: Option<AtomicFile>,
    /// t [s] and e north, east [rad] (None where the truth has no row) of every epoch.
    errors: Vec<(f64, Option<[f64; 2]>)>,
}

impl EpochFiles {
    /// Creates the files in `out` with their headers.
    fn create(
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
        })
    }

    /// Writes one epoch's record.
    fn record(&mut self, r: &filter::Record) -> Result<()> {
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

    /// Commits states.txt, innovations.txt (written now from `run`) and model_error.txt;
    /// returns the epochs' model errors.
    fn commit(
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
        f.commit()?;
        if let Some(f) = self.model_error {
            f.commit()?;
        }
        Ok(self.errors)
    }
}

/// The truth must have a row at the update epochs: none is an error (another clock?), some
/// missing a warning.
fn check_truth_coverage(errors: &[(f64, Option<[f64; 2]>)]) -> Result<()> {
    let covered = errors.iter().filter(|e| e.1.is_some()).count();
    if covered == 0 && !errors.is_empty() {
        anyhow::bail!(
            "--truth: the truth file has no row at any of the {} update epochs ({:.3} .. {:.3} s): is it on the IMU's and the aiding's clock?",
            errors.len(),
            errors[0].0,
            errors[errors.len() - 1].0
        );
    }
    if covered < errors.len() {
        eprintln!(
            "warning: the truth file has a row at only {covered} of the {} update epochs: model_error.txt and the model-error RMS cover those only",
            errors.len()
        );
    }
    Ok(())
}

/// The table of the drift at the end of each GNSS outage (empty without outages); times from
/// `t_first`, the first IMU sample [s].
fn outage_table(rows: &[metrics::OutageDrift], t_first: f64) -> String {
    if rows.is_empty() {
        return String::new();
    }
    let mut s = String::from(
        "GNSS outages: drift at the first fix after each (the filter's solution against that fix)\n",
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
fn model_error_line(errors: &[(f64, Option<[f64; 2]>)]) -> String {
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
fn nis_table(run: &filter::FilterRun) -> String {
    let mut s = String::from(
        "innovations: mean NIS per channel (1 for a consistent filter; 95 % band for the count)\n",
    );
    for c in filter::nis_by_channel(run) {
        s.push_str(&format!(
            "  {:<6} {:>6} updates  mean NIS {:>9}  band {:.2}..{:.2}  {}\n",
            c.channel,
            c.count,
            sinsmodel::explain::sig3(c.mean),
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
