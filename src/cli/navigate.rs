//! `sinsmodel navigate --imu FILE --lat --lon --h --att R,P,Y [--vel N,E,D] [--vertical] --out FILE`.

use anyhow::{bail, Result};
use clap::Args;
use nalgebra::{Rotation3, UnitQuaternion, Vector3};
use sinsmodel::io::truth;
use sinsmodel::io::truth::TruthRow;
use sinsmodel::nav::attitude::dcm_from_euler;
use sinsmodel::nav::strapdown::{NavState, Navigator, Vertical};
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
    /// Run even when --att's roll and pitch contradict the measured gravity direction, and
    /// replace an --out file that is not provably an earlier `navigate` output.
    #[arg(long)]
    force: bool,
    /// Read the whole IMU file before navigating (the pre-streaming path, kept as the baseline
    /// `sinsmodel bench` measures the stream against).
    #[arg(long, hide = true)]
    in_memory: bool,
}

/// Runs the command.
pub fn run(args: &NavigateArgs) -> Result<()> {
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
    let check_out = || {
        args.src.check_output(
            "--out",
            &args.out,
            sinsmodel::io::atomic_file::Provenance::Text("navigate"),
            args.force,
        )
    };
    check_out()?;
    // streamed: memory does not grow with the file; the output is written as it goes and
    // appears only when complete
    let mut data = args.src.open(&mut super::data::note)?;
    if args.in_memory {
        data = data.into_memory()?;
    }
    // the same plausibility imu-check applies, on the first 10 s: warn, do not stop (a start
    // that moves or a tilted mounting are legitimate here)
    let head = sinsmodel::io::imu::ImuData {
        samples: data.head().to_vec(),
    };
    let check =
        sinsmodel::estimate::imu_check::check(&head, Some(args.lat.to_radians()), 0.0, 10.0, true);
    for p in check
        .problems
        .iter()
        .filter(|p| !check.unit_problems.contains(p))
        .map(|p| {
            if check.gyro_unit_problems.contains(p) {
                format!("{p} (or an uncalibrated MEMS gyro's bias)")
            } else {
                p.clone()
            }
        })
    {
        eprintln!("warning: {p} (`sinsmodel imu-check` shows what was read)");
    }
    // a unit, scale or clock slip is refused: navigating on it gives hours of nonsense
    if let Some(p) = check.unit_problems.first() {
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
    drop(head);
    let c = dcm_from_euler(args.att[0] * d, args.att[1] * d, args.att[2] * d);
    let v = args.vel.clone().unwrap_or_else(|| vec![0.0; 3]);
    let t0 = data.start_time();
    let start = NavState {
        t: t0,
        lat: args.lat * d,
        lon: args.lon * d,
        h: args.h,
        v: Vector3::new(v[0], v[1], v[2]),
        q: UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(c)),
    };
    let mut nav = Navigator::new(start, args.vertical);
    let mut clock = super::nav_out::RowClock::new(t0, Some(args.out_rate), data.interval());
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
    truth::write_row(out.writer(), &row(&nav.state))?;
    let mut rows = 1u64;
    let pb = progress::bar(1000, "navigate");
    let mut prev_t = t0;
    while let Some(s) = data.next()? {
        if s.t <= t0 {
            // a jittered clock starts at its first sample (`ImuStream::start_time`)
            continue;
        }
        let k = data.count() - 1;
        nav.step(&s.dtheta, &s.dv, s.t - prev_t);
        nav.state.t = s.t;
        let st = &nav.state;
        if ![st.lat, st.lon, st.h, st.v.x, st.v.y, st.v.z, st.q.w, st.q.i]
            .iter()
            .all(|v| v.is_finite())
            || st.h.abs() > 1e7
            || st.lat.abs() >= 89.9f64.to_radians()
            || st.v.norm() > 1e4
        {
            bail!(
                "{}: the navigation diverged at t = {:.3} s (sample {}): a non-finite state, a pole (the NED frame is undefined there) or a speed over 1e4 m/s; the increments are not physical there \
                 (check the IMU values, units and clock; `sinsmodel imu-check` shows what was read)",
                args.src.imu.display(),
                s.t,
                k + 1
            );
        }
        prev_t = s.t;
        if clock.due(s.t) {
            truth::write_row(out.writer(), &row(&nav.state))?;
            rows += 1;
        }
        if k % 100_000 == 0 {
            pb.set_position((data.fraction() * 1000.0) as u64);
        }
    }
    pb.finish_and_clear();
    // checked again: the file may have been replaced while the run worked
    check_out()?;
    out.commit()?;
    eprintln!(
        "navigated {} samples ({:.1} s), wrote {} rows to {}",
        data.count(),
        data.last_t() - data.first_t(),
        rows,
        args.out.display()
    );
    let (s0, s1) = (&start, &nav.state);
    let r = sinsmodel::nav::earth::A;
    let dn = (s1.lat - s0.lat) * r;
    let de = (s1.lon - s0.lon) * r * s0.lat.cos();
    eprintln!(
        "final position {:.3} km from the start ({:.3} km north, {:.3} km east): free-inertial \
         navigation, no aiding; its drift grows with the initial attitude and sensor errors (use \
         `sinsmodel align` for --att on a static start, `sinsmodel filter` to estimate the errors)",
        dn.hypot(de) / 1000.0,
        dn / 1000.0,
        de / 1000.0
    );
    Ok(())
}
