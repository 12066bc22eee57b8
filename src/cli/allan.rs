//! `sinsmodel allan --imu FILE [--json OUT] [--plot PREFIX]`: overlapping Allan deviation of the
//! six channels (rates Δθ/T [rad/s], Δv/T [m/s²], FRD body) with uncertainties, the noise fit, and
//! log-log plots.

use anyhow::Result;
use clap::Args;
use serde::Serialize;
use sinsmodel::estimate::allan::{fit, oadev, AllanCurve, NoiseFit};
use sinsmodel::io::atomic_file::{self, Provenance};
use sinsmodel::io::imu::ImuData;
use sinsmodel::report::plot::{line_plot, Scale, Series};
use std::collections::BTreeMap;
use std::path::PathBuf;

/// Arguments of `allan`.
#[derive(Args)]
pub struct AllanArgs {
    #[command(flatten)]
    src: super::data::ImuSource,
    /// Skip this many seconds at the start (e.g. a disturbed start).
    #[arg(long, default_value_t = 0.0)]
    skip: f64,
    /// Use at most this many seconds after --skip (e.g. the static part of a drive).
    #[arg(long)]
    seconds: Option<f64>,
    /// JSON output.
    #[arg(long)]
    json: Option<PathBuf>,
    /// Plot prefix: writes PREFIX_gyro.png and PREFIX_accel.png (default: next to --json).
    #[arg(long)]
    plot: Option<PathBuf>,
    /// Replace an existing output file that is not provably this command's earlier output (or
    /// that a sinsmodel run directory lists as its result).
    #[arg(long)]
    force: bool,
}

#[derive(Serialize)]
struct Out {
    rate_hz: f64,
    tau_s: Vec<f64>,
    adev: BTreeMap<String, Vec<f64>>,
    adev_err: BTreeMap<String, Vec<f64>>,
    fit: BTreeMap<String, NoiseFit>,
    units: BTreeMap<String, &'static str>,
}

const NAMES: [&str; 6] = [
    "gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y", "accel_z",
];

/// Runs the command.
pub fn run(args: &AllanArgs) -> Result<()> {
    if let Some(j) = &args.json {
        args.src
            .check_output("--json", j, Provenance::Json("allan"), args.force)?;
    }
    if let Some(p) = prefix_shown(args) {
        // the prefix names files in a directory: not a device or a special path
        let dir = p
            .parent()
            .filter(|d| !d.as_os_str().is_empty())
            .unwrap_or(std::path::Path::new("."));
        if dir.starts_with("/dev") || dir.starts_with("/proc") || dir.starts_with("/sys") {
            anyhow::bail!(
                "--plot {}: the plots would go into {}, not a place for files",
                p.display(),
                dir.display()
            );
        }
        for suffix in ["gyro", "accel"] {
            let png = PathBuf::from(format!("{}_{suffix}.png", p.display()));
            args.src
                .check_output("--plot", &png, Provenance::Png, args.force)?;
        }
    }
    let data = args.src.read(&mut super::data::note)?;
    let dt = data.interval();
    if !(args.skip.is_finite() && args.skip >= 0.0) {
        anyhow::bail!("--skip {}: expected seconds >= 0", args.skip);
    }
    if let Some(s) = args.seconds {
        if !(s.is_finite() && s > 0.0) {
            anyhow::bail!("--seconds {s}: expected a positive number of seconds");
        }
    }
    let t0 = data.samples[0].t + args.skip;
    let t1 = args.seconds.map(|s| t0 + s).unwrap_or(f64::INFINITY);
    let span = ImuData {
        samples: data
            .samples
            .iter()
            .filter(|s| s.t >= t0 && s.t < t1)
            .copied()
            .collect(),
    };
    let samples = &span.samples;
    if samples.len() < 16 {
        anyhow::bail!(
            "{}: fewer than 16 samples in the chosen span",
            args.src.imu.display()
        );
    }
    // Allan deviation describes a sensor at rest: say so when the span moves (10-s windows by
    // the absolute tests of `align`)
    let win = ((10.0 / dt).round() as usize).max(2);
    let g = span.mean_rates().0.norm();
    let evidence = sinsmodel::estimate::align::rest_evidence(&span, win, g);
    let moving = evidence.iter().filter(|e| !e.at_rest()).count();
    if moving > 0 {
        eprintln!(
            "warning: {moving} of the {} ten-second windows of the chosen span are not at rest (specific-force spread > {} m/s^2 or angular-rate spread > {:.2} deg/s): \
             the Allan deviation of moving data measures the motion, not the sensor; choose a stretch at rest with --skip / --seconds (`sinsmodel align` finds one)",
            evidence.len(),
            sinsmodel::estimate::align::STATIC_F_SPREAD,
            sinsmodel::estimate::align::STATIC_W_SPREAD.to_degrees()
        );
    }
    // a jittered clock: each increment keeps its own interval (cumulative integral resampled
    // to a uniform grid); dividing by one interval would turn the jitter times the mean (gravity
    // on an accelerometer) into noise
    let times: Vec<f64> = samples.iter().map(|s| s.t).collect();
    let jitter = span.jitter_rms() / dt;
    let resample = jitter > 1e-6;
    if resample {
        eprintln!(
            "note: the clock jitters ({:.2} % RMS of the {dt:.6} s interval): the increments are integrated in time and resampled to a uniform {dt:.6} s grid",
            100.0 * jitter
        );
    }
    let channel = |c: usize| -> Vec<f64> {
        samples
            .iter()
            .map(|s| if c < 3 { s.dtheta[c] } else { s.dv[c - 3] })
            .collect()
    };
    let curves: Vec<AllanCurve> = (0..6)
        .map(|c| {
            let inc = channel(c);
            if resample {
                let (y, t) = sinsmodel::estimate::allan::uniform_rates(&times, &inc);
                oadev(&y, t)
            } else {
                let y: Vec<f64> = inc.iter().map(|v| v / dt).collect();
                oadev(&y, dt)
            }
        })
        .collect();
    let mut out = Out {
        rate_hz: 1.0 / dt,
        tau_s: curves[0].tau_s.clone(),
        adev: BTreeMap::new(),
        adev_err: BTreeMap::new(),
        fit: BTreeMap::new(),
        units: BTreeMap::new(),
    };
    let r2dh = 180.0 / std::f64::consts::PI * 3600.0;
    for (k, c) in curves.iter().enumerate() {
        let f = fit(c);
        out.adev.insert(NAMES[k].into(), c.adev.clone());
        out.adev_err.insert(NAMES[k].into(), c.adev_err.clone());
        out.fit.insert(NAMES[k].into(), f);
        out.units.insert(
            NAMES[k].into(),
            if k < 3 {
                "rad/s (fit: white rad/sqrt(s), random_walk rad/s/sqrt(s))"
            } else {
                "m/s^2 (fit: white m/s/sqrt(s), random_walk m/s^2/sqrt(s))"
            },
        );
        println!("{}", fit_line(NAMES[k], &f));
    }
    println!(
        "(fits use tau <= {:.3e} s, a ninth of the {:.1} s of data: at least 9 independent clusters)",
        curves[0].span_s / 9.0,
        curves[0].span_s
    );
    if let Some(j) = &args.json {
        atomic_file::write_text(
            j,
            &atomic_file::with_written_by(&serde_json::to_string_pretty(&out)?, "allan"),
        )?;
    }
    if let Some(p) = prefix_shown(args) {
        let series = |range: std::ops::Range<usize>, scale: f64| -> Vec<Series> {
            range
                .map(|k| Series {
                    label: NAMES[k].into(),
                    points: curves[k]
                        .tau_s
                        .iter()
                        .zip(&curves[k].adev)
                        .map(|(t, a)| (*t, a * scale))
                        .collect(),
                })
                .collect()
        };
        let png = |suffix: &str| PathBuf::from(format!("{}_{suffix}.png", p.display()));
        line_plot(
            &png("gyro"),
            "Allan deviation, gyros",
            "tau [s]",
            "ADEV [deg/h]",
            &series(0..3, r2dh),
            Scale::LogLog,
        )?;
        line_plot(
            &png("accel"),
            "Allan deviation, accelerometers",
            "tau [s]",
            "ADEV [ug]",
            &series(3..6, 1e6 / sinsmodel::io::units::STANDARD_GRAVITY),
            Scale::LogLog,
        )?;
    }
    match (&args.json, &prefix_shown(args)) {
        (Some(j), Some(p)) => eprintln!(
            "wrote {}, {}_gyro.png and {}_accel.png",
            j.display(),
            p.display(),
            p.display()
        ),
        (None, Some(p)) => eprintln!(
            "wrote {}_gyro.png and {}_accel.png",
            p.display(),
            p.display()
        ),
        (Some(j), None) => eprintln!("wrote {}", j.display()),
        (None, None) => {
            eprintln!("(no files written: --json or --plot writes the curves and plots)")
        }
    }
    Ok(())
}

fn prefix_shown(args: &AllanArgs) -> Option<PathBuf> {
    args.plot
        .clone()
        .or_else(|| args.json.as_ref().map(|j| j.with_extension("")))
}

/// One channel's noise terms in display units, saying where the data do not support a value.
fn fit_line(name: &str, f: &NoiseFit) -> String {
    let gyro = name.starts_with("gyro");
    let r2dh = 180.0 / std::f64::consts::PI * 3600.0;
    let ug = 1e6 / sinsmodel::io::units::STANDARD_GRAVITY;
    let (white, bi, rw) = if gyro {
        (
            format!("ARW {} deg/sqrt(h)", num(f.white * r2dh / 60.0)),
            format!("{} deg/h", num(f.bias_instability * r2dh)),
            format!("RRW {} deg/h/sqrt(h)", num(f.random_walk * r2dh * 60.0)),
        )
    } else {
        (
            format!("VRW {} ug/sqrt(Hz)", num(f.white * ug)),
            format!("{} ug", num(f.bias_instability * ug)),
            format!("RRW {} ug/sqrt(s)", num(f.random_walk * ug)),
        )
    };
    let white = if f.white.is_finite() {
        white
    } else {
        "white noise not determined (no -1/2 slope)".into()
    };
    let bi = if !f.bias_instability.is_finite() {
        "bias instability not determined (too little data)".to_string()
    } else if f.bias_instability_upper_bound {
        format!("bias instability <= {bi} (curve still falling: an upper bound)")
    } else {
        format!("bias instability {bi}")
    };
    let rw = if f.random_walk.is_finite() {
        rw
    } else {
        "RRW not resolved by these data (no +1/2 slope within the supported tau)".into()
    };
    format!("{name:<8} {white}  {bi}  {rw}")
}

fn num(v: f64) -> String {
    sinsmodel::explain::sig3(v)
}
