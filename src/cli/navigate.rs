//! `sinsmodel navigate --imu FILE (--init LAT,LON,H,R,P,Y[,VN,VE,VD] | --lat --lon --h --att R,P,Y
//! [--vel N,E,D]) [--vertical] [--nav-rate HZ] --out FILE`.

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
    /// Initial state as filter and explain take it: lat,lon [deg],h [m],roll,pitch,yaw
    /// [deg][,vn,ve,vd m/s] (NED/FRD); instead of --lat --lon --h --att --vel, which stay as
    /// its parts.
    #[arg(long, allow_hyphen_values = true, conflicts_with_all = ["lat", "lon", "h", "att", "vel"])]
    init: Option<String>,
    /// Initial latitude [deg] (or give --init).
    #[arg(long, allow_hyphen_values = true, required_unless_present = "init")]
    lat: Option<f64>,
    /// Initial longitude [deg] (or give --init).
    #[arg(long, allow_hyphen_values = true, required_unless_present = "init")]
    lon: Option<f64>,
    /// Initial height [m] [default: 0].
    #[arg(long, allow_hyphen_values = true)]
    h: Option<f64>,
    /// Initial roll,pitch,yaw [deg] (NED/FRD), e.g. from `sinsmodel align`: the attitude part
    /// of --init (filter and explain take the whole initial state as --init).
    #[arg(
        long,
        value_delimiter = ',',
        allow_hyphen_values = true,
        required_unless_present = "init"
    )]
    att: Option<Vec<f64>>,
    /// Initial NED velocity N,E,D [m/s] [default: 0,0,0].
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true)]
    vel: Option<Vec<f64>>,
    /// Vertical channel: fixed (default), damped, free.
    #[arg(long, default_value = "fixed")]
    vertical: Vertical,
    /// Rate of the navigation solution written to --out [Hz] (the name filter uses for its
    /// nav.txt; --out-rate, the older name, is still accepted).
    #[arg(
        long,
        alias = "out-rate",
        default_value_t = 10.0,
        allow_hyphen_values = true
    )]
    nav_rate: f64,
    /// Output FILE (a single file, not a directory, unlike the --out of filter, explain,
    /// simulate and reproduce): the navigation solution in the truth layout of DESIGN §9.
    #[arg(long)]
    out: PathBuf,
    /// Run even when the initial roll and pitch contradict the measured gravity direction, or the
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
    let init = initial(args)?;
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
    check_start(args, &init, &mut data)?;
    let t0 = data.start_time();
    let start = free_inertial::start_state(t0, init.lat, init.lon, init.h, init.att, init.vel);
    let mut clock = RowClock::new(t0, Some(args.nav_rate), data.interval());
    if let Some(n) = clock.capped_note("--nav-rate") {
        super::data::note(&format!("note: {n}"));
    }
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
    let vertical_moves = !matches!(args.vertical, Vertical::Fixed);
    print_summary(args, &data, rows, &start, &end, vertical_moves);
    Ok(())
}

/// The initial state of the run, from --init or from --lat --lon --h --att --vel (deg, m, m/s).
struct Initial {
    lat: f64,
    lon: f64,
    h: f64,
    att: [f64; 3],
    vel: [f64; 3],
    /// The option the attitude came from (`--init` or `--att`), for messages.
    att_option: &'static str,
}

/// The initial state the options give, each value checked; the output rate checked too.
fn initial(args: &NavigateArgs) -> Result<Initial> {
    let init = match &args.init {
        Some(text) => from_init(text)?,
        None => {
            // clap requires these without --init
            let (Some(lat), Some(lon), Some(att)) = (args.lat, args.lon, &args.att) else {
                bail!("give --init LAT,LON,H,ROLL,PITCH,YAW, or --lat, --lon and --att");
            };
            if att.len() != 3 {
                bail!("--att: expected roll,pitch,yaw in degrees (three numbers)");
            }
            let v = args.vel.clone().unwrap_or_else(|| vec![0.0; 3]);
            if v.len() != 3 {
                bail!("--vel: expected N,E,D in m/s (three finite comma-separated numbers within ±1000)");
            }
            Initial {
                lat,
                lon,
                h: args.h.unwrap_or(0.0),
                att: [att[0], att[1], att[2]],
                vel: [v[0], v[1], v[2]],
                att_option: "--att",
            }
        }
    };
    check_initial(&init)?;
    free_inertial::check_rate("--nav-rate", args.nav_rate)?;
    Ok(init)
}

/// `--init LAT,LON,H,ROLL,PITCH,YAW[,VN,VE,VD]` as filter and explain take it (no `auto`:
/// navigate has no GNSS to head by).
fn from_init(text: &str) -> Result<Initial> {
    if text.trim() == "auto" {
        bail!("--init auto: navigate has no aiding to start from; expected lat,lon,h,roll,pitch,yaw[,vn,ve,vd] (numbers, deg, m, deg, m/s), e.g. the attitude from `sinsmodel align`");
    }
    let v = sinsmodel::data::init_numbers(text)?;
    Ok(Initial {
        lat: v[0],
        lon: v[1],
        h: v[2],
        att: [v[3], v[4], v[5]],
        vel: if v.len() == 9 {
            [v[6], v[7], v[8]]
        } else {
            [0.0; 3]
        },
        att_option: "--init",
    })
}

/// Refuses a latitude, longitude, height, attitude or velocity out of the range filter's
/// --init takes ([`sinsmodel::data::init_value_problem`]), with the same words, after the
/// option it came from.
fn check_initial(i: &Initial) -> Result<()> {
    let mut v = vec![i.lat, i.lon, i.h];
    v.extend(i.att);
    v.extend(i.vel);
    if let Some(why) = sinsmodel::data::init_value_problem(&v) {
        let option = if i.att_option == "--init" {
            "--init"
        } else {
            match why.split(' ').next().unwrap_or("") {
                "lat" => "--lat",
                "lon" => "--lon",
                "h" => "--h",
                "roll" | "pitch" | "yaw" => "--att",
                _ => "--vel",
            }
        };
        bail!("{option}: {why}");
    }
    Ok(())
}

/// The plausibility imu-check applies, on the first 10 s: warns (a start that moves or a tilted
/// mounting are legitimate here); a unit, scale or clock slip, or an --att that contradicts the
/// measured gravity, stops the run unless --force.
fn check_start(args: &NavigateArgs, init: &Initial, data: &mut ImuStream) -> Result<()> {
    let head = ImuData {
        samples: data.head().to_vec(),
    };
    let check = sinsmodel::estimate::imu_check::start_check(&head, init.lat.to_radians());
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
        init.att[0] * d,
        init.att[1] * d,
    ) {
        if args.force {
            eprintln!("warning: {p} (--force given)");
        } else {
            bail!("{}: {p}", init.att_option);
        }
    }
    // the rest of the run, a window at a time as it is read (gyro slips are warnings, as above)
    use sinsmodel::estimate::imu_check::{window_check, WindowJudge};
    data.judge_windows(window_check(
        WindowJudge::new(init.lat.to_radians(), &check.head, true),
        data.name().to_string(),
        args.force,
        "or an uncalibrated MEMS gyro's bias",
    ));
    Ok(())
}

/// Prints what was navigated and written, and how far the end is from the start (the height
/// change too when `vertical_moves`).
fn print_summary(
    args: &NavigateArgs,
    data: &ImuStream,
    rows: u64,
    s0: &NavState,
    s1: &NavState,
    vertical_moves: bool,
) {
    eprintln!(
        "navigated {} samples ({:.1} s), wrote {} rows to {}",
        data.count(),
        data.last_t() - data.first_t(),
        rows,
        args.out.display()
    );
    let [dn, de] = free_inertial::displacement_ne(s0, s1);
    let mut parts = vec![
        towards(dn / 1000.0, "km", "north", "south"),
        towards(de / 1000.0, "km", "east", "west"),
    ];
    if vertical_moves {
        parts.push(towards(s1.h - s0.h, "m", "up", "down"));
    }
    eprintln!(
        "final position {:.3} km from the start ({}): free-inertial navigation, no aiding; its \
         drift grows with the initial attitude and sensor errors (use `sinsmodel align` for the \
         attitude of --init or --att on a static start, `sinsmodel filter` to estimate the errors)",
        dn.hypot(de) / 1000.0,
        parts.join(", ")
    );
}

/// A signed displacement `x` in words: its size toward `positive` or `negative`
/// (`-39.155 km` north is `39.155 km south`).
fn towards(x: f64, unit: &str, positive: &str, negative: &str) -> String {
    let rounded = (x * 1000.0).round() / 1000.0;
    if rounded < 0.0 {
        format!("{:.3} {unit} {negative}", -x)
    } else {
        format!("{:.3} {unit} {positive}", x.abs())
    }
}
