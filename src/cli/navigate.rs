//! `sinsmodel navigate --imu FILE --lat --lon --h --att R,P,Y [--vel N,E,D] [--vertical] --out FILE`.

use anyhow::{bail, Result};
use clap::Args;
use sinsmodel::io::imu::ImuData;
use sinsmodel::io::imu_stream::ImuStream;
use sinsmodel::io::truth::{self, TruthRow};
use sinsmodel::nav::free_inertial::{self, RowClock};
use sinsmodel::nav::strapdown::{NavState, Vertical};
use sinsmodel::report::progress;
use std::path::PathBuf;

/// Arguments of `navigate`.
#[derive(Args)]
pub struct NavigateArgs {
    #[command(flatten)]
    src: super::data::ImuSource,
    /// Initial latitude [deg].
    #[arg(long, allow_hyphen_values = true)]
    lat: f64,
    /// Initial longitude [deg].
    #[arg(long, allow_hyphen_values = true)]
    lon: f64,
    /// Initial height [m].
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    h: f64,
    /// Initial roll,pitch,yaw [deg] (NED/FRD), e.g. from `sinsmodel align`.
    #[arg(
        long,
        value_delimiter = ',',
        allow_hyphen_values = true,
        required = true
    )]
    att: Vec<f64>,
    /// Initial NED velocity N,E,D [m/s].
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true)]
    vel: Option<Vec<f64>>,
    /// Vertical channel: fixed (default), damped, free.
    #[arg(long, default_value = "fixed")]
    vertical: Vertical,
    /// Output rate [Hz].
    #[arg(long, default_value_t = 10.0)]
    out_rate: f64,
    /// Output file (truth layout of DESIGN §9).
    #[arg(long)]
    out: PathBuf,
    /// Run even when --att's roll and pitch contradict the measured gravity direction, or the
    /// first seconds' magnitudes look like a unit slip.
    #[arg(long)]
    force: bool,
    /// Replace an --out file that is not provably an earlier `navigate` output.
    #[arg(long)]
    overwrite: bool,
    /// Read the whole IMU file before navigating (the pre-streaming path, kept as the baseline
    /// `sinsmodel bench` measures the stream against).
    #[arg(long, hide = true)]
    in_memory: bool,
}

/// Runs the command.
pub fn run(args: &NavigateArgs) -> Result<()> {
    check_args(args)?;
    let check_out = || {
        args.src.check_output(
            "--out",
            &args.out,
            sinsmodel::io::atomic_file::Provenance::Text("navigate"),
            args.overwrite,
        )
    };
    check_out()?;
    // streamed: memory does not grow with the file; the output is written as it goes and
    // appears only when complete
    let mut data = args.src.open(&mut super::data::note)?;
    if args.in_memory {
        data = data.into_memory()?;
    }
    check_start(args, &data)?;
    let v = args.vel.clone().unwrap_or_else(|| vec![0.0; 3]);
    let att = [args.att[0], args.att[1], args.att[2]];
    let t0 = data.start_time();
    let start = free_inertial::start_state(t0, args.lat, args.lon, args.h, att, [v[0], v[1], v[2]]);
    let mut clock = RowClock::new(t0, Some(args.out_rate), data.interval());
    let row = |s: &NavState| TruthRow {
        t: s.t,
        lat: s.lat,
        lon: s.lon,
        h: s.h,
        v: s.v,
        euler: s.euler(),
    };
    let mut out = truth::create(
        &args.out,
        &format!(
            "{} (vertical {})",
            super::command_line(),
            args.vertical.word()
        ),
    )?;
    let mut rows = 0u64;
    let pb = progress::bar(1000, "navigate");
    let end = free_inertial::run(
        &mut data,
        start,
        args.vertical,
        &mut clock,
        &args.src.imu.display().to_string(),
        &mut |s| {
            rows += 1;
            Ok(truth::write_row(out.writer(), &row(s))?)
        },
        &mut |f| pb.set_position((f * 1000.0) as u64),
    )?;
    pb.finish_and_clear();
    // checked again: the file may have been replaced while the run worked
    check_out()?;
    out.commit()?;
    print_summary(args, &data, rows, &start, &end);
    Ok(())
}

/// Refuses a latitude, attitude, velocity, longitude, height or output rate out of range.
fn check_args(args: &NavigateArgs) -> Result<()> {
    if args.lat.abs() >= 89.0 || !args.lat.is_finite() {
        bail!("--lat {} must be within ±89°", args.lat);
    }
    use sinsmodel::io::bounds;
    if args.att.len() != 3
        || bounds::attitude_deg([args.att[0], args.att[1], args.att[2]]).is_some()
    {
        bail!(
            "--att {}: expected roll,pitch,yaw in degrees (roll within ±180, pitch within ±90, yaw within ±360)",
            args.att.iter().map(|a| a.to_string()).collect::<Vec<_>>().join(",")
        );
    }
    if args
        .vel
        .as_ref()
        .is_some_and(|v| v.len() != 3 || v.iter().any(|x| !x.is_finite() || x.abs() > 1e4))
    {
        bail!("--vel: expected N,E,D in m/s (three finite comma-separated numbers within ±1e4)");
    }
    if let Some(p) = bounds::lon_deg(args.lon) {
        bail!("--lon: {p}");
    }
    if let Some(p) = bounds::height_m(args.h) {
        bail!("--h: {p}");
    }
    if !(args.out_rate.is_finite() && args.out_rate > 0.0 && args.out_rate <= 1e5) {
        bail!(
            "--out-rate {}: expected a rate in (0, 1e5] Hz",
            args.out_rate
        );
    }
    Ok(())
}

/// The plausibility imu-check applies, on the first 10 s: warns (a start that moves or a tilted
/// mounting are legitimate here); a unit, scale or clock slip, or an --att that contradicts the
/// measured gravity, stops the run unless --force.
fn check_start(args: &NavigateArgs, data: &ImuStream) -> Result<()> {
    let head = ImuData {
        samples: data.head().to_vec(),
    };
    let check = sinsmodel::estimate::imu_check::start_check(&head, args.lat.to_radians());
    for p in &check.warnings {
        eprintln!("warning: {p} (`sinsmodel imu-check` shows what was read)");
    }
    // a unit, scale or clock slip is refused: navigating on it gives hours of nonsense
    if let Some(p) = &check.unit_problem {
        if args.force {
            eprintln!("warning: {p} (--force given)");
        } else {
            bail!("--imu: {p} (in the first 10 s; `sinsmodel imu-check` shows what was read; --force runs anyway)");
        }
    }
    let d = std::f64::consts::PI / 180.0;
    if let Some(p) = sinsmodel::estimate::align::attitude_contradicts_gravity(
        &head,
        args.att[0] * d,
        args.att[1] * d,
    ) {
        if args.force {
            eprintln!("warning: {p} (--force given)");
        } else {
            bail!("--att: {p}");
        }
    }
    Ok(())
}

/// Prints what was navigated and written, and how far the end is from the start.
fn print_summary(args: &NavigateArgs, data: &ImuStream, rows: u64, s0: &NavState, s1: &NavState) {
    eprintln!(
        "navigated {} samples ({:.1} s), wrote {} rows to {}",
        data.count(),
        data.last_t() - data.first_t(),
        rows,
        args.out.display()
    );
    let [dn, de] = free_inertial::displacement_ne(s0, s1);
    eprintln!(
        "final position {:.3} km from the start ({:.3} km north, {:.3} km east): free-inertial \
         navigation, no aiding; its drift grows with the initial attitude and sensor errors (use \
         `sinsmodel align` for --att on a static start, `sinsmodel filter` to estimate the errors)",
        dn.hypot(de) / 1000.0,
        dn / 1000.0,
        de / 1000.0
    );
}
