//! `sinsmodel filter --model MODEL --imu FILE --aid FILE [--truth FILE] [--init …] --out DIR`.

use super::data::DataArgs;
use anyhow::Result;
use clap::Args;
use sinsmodel::estimate::filter;
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
    /// Output directory: states.txt, innovations.txt, model_error.txt (with truth); written
    /// complete or not at all, replacing only an earlier sinsmodel run's directory.
    #[arg(long)]
    out: PathBuf,
}

/// Runs the command.
pub fn run(args: &FilterArgs) -> Result<()> {
    let model = Model::parse(&args.model)?;
    let cfg = args.data.config(&model, false)?;
    let out = OutputDir::create(&args.out, &args.data.input_paths())?;
    args.data.print_noise()?;
    let inputs = args.data.load()?;
    let (imu, aid, truth_rows, start) = (&inputs.imu, &inputs.aid, &inputs.truth, inputs.start);
    let pb = progress::bar(1000, "filter");
    let run = filter::run(&model, &cfg, imu, start, aid, truth_rows.as_deref(), |f| {
        pb.set_position((f * 1000.0) as u64)
    });
    pb.finish_and_clear();
    run.check().map_err(anyhow::Error::msg)?;

    let mut f = AtomicFile::create(&out.file("states.txt"))?;
    let w = f.writer();
    let provenance = super::command_line();
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
    for r in &run.records {
        write!(w, "{:.4}", r.t)?;
        for v in r.x.iter().chain(&r.sigma) {
            write!(w, " {v:.6e}")?;
        }
        writeln!(w)?;
    }
    f.commit()?;

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

    if truth_rows.is_some() {
        let mut f = AtomicFile::create(&out.file("model_error.txt"))?;
        let w = f.writer();
        let arcsec = 180.0 / std::f64::consts::PI * 3600.0;
        writeln!(w, "# {provenance}")?;
        writeln!(
            w,
            "# t phi_true_n phi_true_e phi_true_d phi_est_n phi_est_e phi_est_d e_n e_e [arcsec]"
        )?;
        for r in &run.records {
            if let Some(p) = r.phi_true {
                let e = r.phi_est - p;
                writeln!(
                    w,
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
        }
        f.commit()?;
    }
    out.commit()?;
    eprintln!(
        "filtered {} samples ({:.1} s) with {} ({} states, {} loop): {} scalar updates",
        imu.samples.len(),
        imu.duration(),
        model.name,
        model.n(),
        cfg.mode.word(),
        run.innovations.len(),
    );
    eprint!("{}", nis_table(&run));
    if let (Some(first), Some(last)) = (run.records.first(), run.records.last()) {
        let mid = 0.5 * (first.t + last.t);
        if let Some([n, e]) = filter::model_error_rms_arcsec(&run, mid, last.t) {
            eprintln!(
                "model error e = phi_hat - phi (truth), RMS over the second half ({mid:.0}–{:.0} s): north {n:.2} arcsec, east {e:.2} arcsec",
                last.t
            );
        }
    }
    let mut files = vec!["states.txt", "innovations.txt"];
    if truth_rows.is_some() {
        files.push("model_error.txt");
    }
    eprintln!("wrote {} in {}", files.join(", "), args.out.display());
    Ok(())
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
            sinsmodel::estimate::explain::sig3(c.mean),
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
