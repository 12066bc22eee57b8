//! IMU logs described by a format file: the same motion written in five layouts, units and axis
//! conventions reads back to the same FRD increments; `imu-check` catches a wrong unit and a
//! flipped axis; bad descriptions get `file:line` errors.

mod common;
use common::sinsmodel;

use nalgebra::Vector3;
use sinsmodel::io::imu::{ImuData, ImuSample};
use sinsmodel::io::imu_format::ImuFormat;
use std::fmt::Write as _;
use std::path::Path;
use std::process::Command;

const G: f64 = 9.80665;
const D2R: f64 = std::f64::consts::PI / 180.0;

/// A manoeuvring IMU: 200 Hz, rates and forces varying in every axis (FRD).
fn motion() -> ImuData {
    let dt = 0.005;
    let samples = (1..=400)
        .map(|k| {
            let t = k as f64 * dt;
            let w = Vector3::new(
                0.3 * (1.1 * t).sin(),
                -0.2 * (0.7 * t).cos(),
                0.5 * (0.3 * t).sin(),
            );
            let f = Vector3::new(
                1.5 * (2.0 * t).sin(),
                0.8 * (1.3 * t).cos(),
                -G + 0.4 * (3.0 * t).sin(),
            );
            ImuSample {
                t,
                dtheta: w * dt,
                dv: f * dt,
            }
        })
        .collect();
    ImuData { samples }
}

/// FRD body vector → sensor axes for a mounting given as the body direction of each sensor axis.
fn to_sensor(v: &Vector3<f64>, axes: [&str; 3]) -> Vector3<f64> {
    let dir = |w: &str| match w {
        "forward" => Vector3::new(1.0, 0.0, 0.0),
        "back" => Vector3::new(-1.0, 0.0, 0.0),
        "right" => Vector3::new(0.0, 1.0, 0.0),
        "left" => Vector3::new(0.0, -1.0, 0.0),
        "down" => Vector3::new(0.0, 0.0, 1.0),
        "up" => Vector3::new(0.0, 0.0, -1.0),
        _ => unreachable!(),
    };
    Vector3::new(
        dir(axes[0]).dot(v),
        dir(axes[1]).dot(v),
        dir(axes[2]).dot(v),
    )
}

fn read(dir: &Path, name: &str, data: &str, format: &str) -> ImuData {
    let d = dir.join(name);
    let f = dir.join(format!("{name}.toml"));
    std::fs::write(&d, data).unwrap();
    std::fs::write(&f, format).unwrap();
    ImuFormat::load(&f)
        .unwrap_or_else(|e| panic!("{name}: {e:#}"))
        .read(&d)
        .unwrap_or_else(|e| panic!("{name}: {e:#}"))
}

fn assert_same(name: &str, got: &ImuData, want: &ImuData, tol_th: f64, tol_v: f64) {
    assert_eq!(
        got.samples.len(),
        want.samples.len(),
        "{name}: sample count"
    );
    for (a, b) in got.samples.iter().zip(&want.samples) {
        assert!((a.t - b.t).abs() < 1e-9, "{name}: t {} vs {}", a.t, b.t);
        assert!(
            (a.dtheta - b.dtheta).amax() <= tol_th,
            "{name} t={}: dtheta {:?} vs {:?}",
            a.t,
            a.dtheta,
            b.dtheta
        );
        assert!(
            (a.dv - b.dv).amax() <= tol_v,
            "{name} t={}: dv {:?} vs {:?}",
            a.t,
            a.dv,
            b.dv
        );
    }
}

#[test]
fn five_layouts_of_the_same_motion_read_back_to_the_same_increments() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let m = motion();
    let dt = 0.005;
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));

    // 1. the project's own text, through the shipped description
    let mut s = String::from("# t dtheta dv\n");
    for x in &m.samples {
        writeln!(
            s,
            "{:?} {:?} {:?} {:?} {:?} {:?} {:?}",
            x.t, x.dtheta.x, x.dtheta.y, x.dtheta.z, x.dv.x, x.dv.y, x.dv.z
        )
        .unwrap();
    }
    let fmt = std::fs::read_to_string(root.join("formats/sinsmodel-text.toml")).unwrap();
    assert_same("text", &read(dir, "text", &s, &fmt), &m, 0.0, 0.0);

    // 2. ROS CSV export: FLU, rad/s and m/s^2, time in ns, header row (shipped description,
    //    with the sample-and-hold rule so that rates × intervals give the increments back)
    let flu = ["forward", "left", "up"];
    let mut s = String::from("%time,field.header.seq,field.angular_velocity.x,field.angular_velocity.y,field.angular_velocity.z,field.linear_acceleration.x,field.linear_acceleration.y,field.linear_acceleration.z\n");
    // a first row at t0 starts the first interval
    for (k, x) in std::iter::once(&m.samples[0]).chain(&m.samples).enumerate() {
        let t_ns = if k == 0 {
            0
        } else {
            (x.t * 1e9).round() as i64
        };
        let w = to_sensor(&(x.dtheta / dt), flu);
        let f = to_sensor(&(x.dv / dt), flu);
        writeln!(
            s,
            "{t_ns},{k},{:?},{:?},{:?},{:?},{:?},{:?}",
            w.x, w.y, w.z, f.x, f.y, f.z
        )
        .unwrap();
    }
    let fmt = std::fs::read_to_string(root.join("formats/ros-imu.toml"))
        .unwrap()
        .replace("integration = \"trapezoid\"", "integration = \"hold\"");
    assert_same("ros", &read(dir, "ros", &s, &fmt), &m, 1e-15, 1e-14);

    // 3. whitespace, deg/s and g, time in ms, right-forward-up axes (PSINS-style)
    let rfu = ["right", "forward", "up"];
    let mut s = String::new();
    for (k, x) in std::iter::once(&m.samples[0]).chain(&m.samples).enumerate() {
        let t_ms = if k == 0 { 0.0 } else { x.t * 1e3 };
        let w = to_sensor(&(x.dtheta / dt), rfu) / D2R;
        let f = to_sensor(&(x.dv / dt), rfu) / G;
        writeln!(
            s,
            "{t_ms:?}   {:?} {:?} {:?}   {:?} {:?} {:?}",
            w.x, w.y, w.z, f.x, f.y, f.z
        )
        .unwrap();
    }
    let fmt = r#"
[file]
delimiter = "whitespace"
[time]
column = 1
unit = "ms"
[signals]
kind = "rate"
integration = "hold"
gyro = [2, 3, 4]
gyro_unit = "deg/s"
accel = [5, 6, 7]
accel_unit = "g"
[axes]
x = "right"
y = "forward"
z = "up"
"#;
    assert_same("rfu", &read(dir, "rfu", &s, fmt), &m, 1e-15, 1e-14);

    // 4. raw counts of increments (0.1 arcsec, 1e-5 m/s per count), time in us, sensor turned
    //    180° about z (x back, y left, z down); equal to within half a count
    let q_th = 0.1 / 3600.0 * D2R;
    let q_v = 1e-5;
    let bld = ["back", "left", "down"];
    let mut s = String::from("t_us gx gy gz ax ay az\n");
    for x in &m.samples {
        let w = to_sensor(&x.dtheta, bld) / q_th;
        let f = to_sensor(&x.dv, bld) / q_v;
        writeln!(
            s,
            "{} {} {} {} {} {} {}",
            (x.t * 1e6).round() as i64,
            w.x.round(),
            w.y.round(),
            w.z.round(),
            f.x.round(),
            f.y.round(),
            f.z.round()
        )
        .unwrap();
    }
    let fmt = r#"
[file]
header = true
[time]
column = "t_us"
unit = "us"
[signals]
kind = "increment"
gyro = ["gx", "gy", "gz"]
gyro_unit = "0.1 arcsec"
accel = ["ax", "ay", "az"]
accel_unit = "1e-5 m/s"
[axes]
x = "back"
y = "left"
z = "down"
"#;
    assert_same(
        "counts",
        &read(dir, "counts", &s, fmt),
        &m,
        0.5001 * q_th,
        0.5001 * q_v,
    );

    // 5. semicolons, columns by index in another order, comment lines, skipped preamble, mrad/s
    //    and mg, identity axes
    let mut s = String::from("logger v2\nserial 1234\n// columns: ax ay az t gz gy gx\n");
    for (k, x) in std::iter::once(&m.samples[0]).chain(&m.samples).enumerate() {
        let t = if k == 0 { 0.0 } else { x.t };
        let w = x.dtheta / dt * 1e3;
        let f = x.dv / dt / (G * 1e-3);
        writeln!(
            s,
            "{:?};{:?};{:?};{t:?};{:?};{:?};{:?}",
            f.x, f.y, f.z, w.z, w.y, w.x
        )
        .unwrap();
    }
    let fmt = r#"
[file]
delimiter = ";"
skip_lines = 2
comment = "//"
[time]
column = 4
[signals]
kind = "rate"
integration = "hold"
gyro = [7, 6, 5]
gyro_unit = "mrad/s"
accel = [1, 2, 3]
accel_unit = "mg"
"#;
    assert_same(
        "semicolon",
        &read(dir, "semicolon", &s, fmt),
        &m,
        1e-15,
        1e-14,
    );
}

#[test]
fn trapezoid_integrates_a_ramp_exactly_and_jitter_uses_each_interval() {
    let tmp = tempfile::tempdir().unwrap();
    // rate w(t) = 0.1 + 0.2 t on x, f(t) = -9.8 + 0.5 t on z, jittered clock
    let ts = [0.0, 0.004, 0.011, 0.015, 0.023, 0.030];
    let mut s = String::new();
    for t in ts {
        writeln!(s, "{t} {} 0 0 0 0 {}", 0.1 + 0.2 * t, -9.8 + 0.5 * t).unwrap();
    }
    let fmt = "[time]\ncolumn = 1\n[signals]\nkind = \"rate\"\ngyro = [2, 3, 4]\ngyro_unit = \"rad/s\"\naccel = [5, 6, 7]\naccel_unit = \"m/s^2\"\n";
    let d = read(tmp.path(), "ramp", &s, fmt);
    assert_eq!(d.samples.len(), ts.len() - 1);
    for (k, x) in d.samples.iter().enumerate() {
        let (a, b) = (ts[k], ts[k + 1]);
        let th = 0.1 * (b - a) + 0.1 * (b * b - a * a);
        let v = -9.8 * (b - a) + 0.25 * (b * b - a * a);
        assert!((x.dtheta.x - th).abs() < 1e-15, "{} vs {th}", x.dtheta.x);
        assert!((x.dv.z - v).abs() < 1e-14, "{} vs {v}", x.dv.z);
    }
}

/// A static, level, north-facing navigation-grade IMU at 30° N written as FLU rates in deg/s and
/// m/s^2, 100 Hz, 20 s.
fn static_flu_deg_s(path: &Path) {
    let lat = 30.0 * D2R;
    let g = sinsmodel::nav::earth::gravity(lat, 0.0);
    let om = sinsmodel::nav::earth::OMEGA;
    // FRD at rest, level, heading north: w = (Ω cos L, 0, −Ω sin L), f = (0, 0, −g)
    let w = to_sensor(
        &Vector3::new(om * lat.cos(), 0.0, -om * lat.sin()),
        ["forward", "left", "up"],
    );
    let f = to_sensor(&Vector3::new(0.0, 0.0, -g), ["forward", "left", "up"]);
    let mut s = String::from("t,wx,wy,wz,ax,ay,az\n");
    for k in 0..=2000 {
        let t = k as f64 * 0.01;
        let n = 1e-3 * ((k * 7919 % 1000) as f64 / 1000.0 - 0.5); // small deterministic noise
        writeln!(
            s,
            "{t:?},{:?},{:?},{:?},{:?},{:?},{:?}",
            w.x / D2R,
            w.y / D2R,
            w.z / D2R,
            f.x + n,
            f.y - n,
            f.z + 0.5 * n
        )
        .unwrap();
    }
    std::fs::write(path, s).unwrap();
}

const STATIC_FMT: &str = r#"[file]
delimiter = ","
header = true
[time]
column = "t"
[signals]
kind = "rate"
gyro = ["wx", "wy", "wz"]
gyro_unit = "deg/s"
accel = ["ax", "ay", "az"]
accel_unit = "m/s^2"
[axes]
x = "forward"
y = "left"
z = "up"
"#;

#[test]
fn imu_check_accepts_the_right_description_and_catches_a_wrong_unit_or_axis() {
    let tmp = tempfile::tempdir().unwrap();
    let data = tmp.path().join("static.csv");
    static_flu_deg_s(&data);
    let fmt = tmp.path().join("right.toml");
    std::fs::write(&fmt, STATIC_FMT).unwrap();
    let d = data.to_str().unwrap();
    let (ok, out, err) = sinsmodel(&[
        "imu-check",
        "--imu",
        d,
        "--imu-format",
        fmt.to_str().unwrap(),
        "--lat",
        "30",
    ]);
    assert!(ok, "{out}\n{err}");
    assert!(out.contains("plausible"), "{out}");
    assert!(out.contains("100.000 Hz"), "{out}");
    // level, heading north by gyrocompass
    let roll_ok = out.contains("roll 0.0") || out.contains("roll -0.0");
    assert!(
        roll_ok && (out.contains("heading 0.0°") || out.contains("heading 360.0°")),
        "{out}"
    );

    // deg/s read as rad/s
    let wrong_unit = tmp.path().join("unit.toml");
    std::fs::write(
        &wrong_unit,
        STATIC_FMT.replace("gyro_unit = \"deg/s\"", "gyro_unit = \"rad/s\""),
    )
    .unwrap();
    let (ok, out, err) = sinsmodel(&[
        "imu-check",
        "--imu",
        d,
        "--imu-format",
        wrong_unit.to_str().unwrap(),
        "--lat",
        "30",
    ]);
    assert!(!ok, "{out}");
    assert!(
        err.contains("gyro_unit") && err.contains("deg/s read as rad/s"),
        "{err}"
    );

    // g-valued description of m/s^2 data
    let wrong_acc = tmp.path().join("acc.toml");
    std::fs::write(
        &wrong_acc,
        STATIC_FMT.replace("accel_unit = \"m/s^2\"", "accel_unit = \"g\""),
    )
    .unwrap();
    let (ok, _, err) = sinsmodel(&[
        "imu-check",
        "--imu",
        d,
        "--imu-format",
        wrong_acc.to_str().unwrap(),
    ]);
    assert!(
        !ok && err.contains("accel_unit") && err.contains("m/s^2 described as g"),
        "{err}"
    );

    // the data are FLU, described as FRD: y and z flipped, the body looks upside down
    let flipped = tmp.path().join("flipped.toml");
    std::fs::write(
        &flipped,
        STATIC_FMT.replace("y = \"left\"\nz = \"up\"", "y = \"right\"\nz = \"down\""),
    )
    .unwrap();
    let (ok, _, err) = sinsmodel(&[
        "imu-check",
        "--imu",
        d,
        "--imu-format",
        flipped.to_str().unwrap(),
    ]);
    assert!(
        !ok && err.contains("[axes]") && err.contains("roll 180"),
        "{err}"
    );
    // a description beside the data is found and said
    std::fs::write(tmp.path().join("static.csv.format.toml"), STATIC_FMT).unwrap();
    let (ok, out, err) = sinsmodel(&["imu-check", "--imu", d]);
    assert!(ok && err.contains("found beside it"), "{out}\n{err}");
}

#[test]
fn bad_descriptions_get_file_and_line() {
    let cases: &[(&str, &str, usize, &str)] = &[
        (
            "kind = \"rate\"",
            "kind = \"rates\"",
            7,
            "expected \"rate\" or \"increment\"",
        ),
        (
            "gyro_unit = \"deg/s\"",
            "gyro_unit = \"m/s\"",
            9,
            "gyro_unit",
        ),
        (
            "accel_unit = \"m/s^2\"",
            "accel_unit = \"furlong\"",
            11,
            "unknown unit",
        ),
        ("z = \"up\"", "z = \"down\"", 13, "left-handed"),
        ("z = \"up\"", "z = \"forward\"", 13, "same way"),
        (
            "z = \"up\"",
            "z = \"sideways\"",
            15,
            "expected forward, back",
        ),
        (
            "delimiter = \",\"",
            "delimiter = \"ab\"",
            2,
            "[file] delimiter",
        ),
        (
            "header = true",
            "header = true\ncolour = 3",
            4,
            "unknown field",
        ),
        ("column = \"t\"", "column = 0", 5, "count from 1"),
        (
            "gyro = [\"wx\", \"wy\", \"wz\"]",
            "gyro = [\"wx\", \"wy\"]",
            8,
            "three columns",
        ),
    ];
    for (from, to, line, msg) in cases {
        assert!(STATIC_FMT.contains(from), "{from}");
        let text = STATIC_FMT.replacen(from, to, 1);
        let err = format!("{:#}", ImuFormat::parse(&text, "fmt.toml").unwrap_err());
        assert!(err.contains(msg), "{to}: {err}");
        // the line named is the line of the bad key (the axes frame checks name the [axes] x line)
        let l: usize = err
            .strip_prefix("fmt.toml:")
            .and_then(|r| r.split(':').next())
            .and_then(|n| n.parse().ok())
            .unwrap_or_else(|| panic!("{to}: no line in {err}"));
        let want_line = text
            .lines()
            .position(|x| x.contains(to.lines().last().unwrap()))
            .unwrap()
            + 1;
        let axes_x = text.lines().position(|x| x.starts_with("x = ")).unwrap() + 1;
        assert!(
            l == want_line || (*msg == "left-handed" || *msg == "same way") && l == axes_x,
            "{to}: line {l}, want {want_line} ({line}): {err}"
        );
    }
    // a column name the data's header lacks names the description and the data line
    let tmp = tempfile::tempdir().unwrap();
    let data = tmp.path().join("d.csv");
    std::fs::write(&data, "time,wx,wy,wz,ax,ay,az\n0,0,0,0,0,0,-9.8\n").unwrap();
    let err = format!(
        "{:#}",
        ImuFormat::parse(STATIC_FMT, "fmt.toml")
            .unwrap()
            .read(&data)
            .unwrap_err()
    );
    assert!(
        err.contains("column `t`") && err.contains("d.csv:1") && err.contains("time, wx"),
        "{err}"
    );
    // a non-number in the data names file, line and column
    std::fs::write(
        &data,
        "t,wx,wy,wz,ax,ay,az\n0,0,0,0,0,0,-9.8\n0.01,0,x,0,0,0,-9.8\n",
    )
    .unwrap();
    let err = format!(
        "{:#}",
        ImuFormat::parse(STATIC_FMT, "fmt.toml")
            .unwrap()
            .read(&data)
            .unwrap_err()
    );
    assert!(err.contains("d.csv:3: column 3"), "{err}");
}

#[test]
fn the_shipped_gnss_imu_description_reads_what_the_built_in_reader_reads() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let data = root.join("../shared/data/gnss-imu-drive/imu_1934.csv");
    let builtin = sinsmodel::io::readers::gnss_imu::read(&data).unwrap();
    let described = ImuFormat::load(&root.join("formats/gnss-imu-csv.toml"))
        .unwrap()
        .read(&data)
        .unwrap();
    // the built-in reader is on GPST (clock offset from the .tag); the description on the
    // logger's clock: same increments, times shifted by the offset
    assert_eq!(builtin.imu.samples.len(), described.samples.len());
    for (a, b) in builtin.imu.samples.iter().zip(&described.samples) {
        assert!(
            (a.t - b.t - builtin.clock_offset).abs() < 1e-6,
            "{} {}",
            a.t,
            b.t
        );
        // the built-in reader forms Δt from the millisecond counts, the description from the
        // times in seconds (t ≈ 262 s: a rounding of ~6e-14 s in a 0.01 s interval)
        let tol = |v: &Vector3<f64>| 1e-10 * v.amax() + 1e-18;
        assert!(
            (a.dtheta - b.dtheta).amax() <= tol(&a.dtheta),
            "{:?} {:?}",
            a.dtheta,
            b.dtheta
        );
        assert!((a.dv - b.dv).amax() <= tol(&a.dv), "{:?} {:?}", a.dv, b.dv);
    }
}

#[test]
fn axes_as_a_rotation_matrix_equal_axes_as_directions() {
    let words = STATIC_FMT.replace(
        "x = \"forward\"\ny = \"left\"\nz = \"up\"",
        "x = \"right\"\ny = \"forward\"\nz = \"up\"",
    );
    let matrix = STATIC_FMT.replace(
        "x = \"forward\"\ny = \"left\"\nz = \"up\"",
        "rotation = [[0, 1, 0], [1, 0, 0], [0, 0, -1]]",
    );
    let a = ImuFormat::parse(&words, "w.toml").unwrap().axes;
    let b = ImuFormat::parse(&matrix, "m.toml").unwrap().axes;
    assert_eq!(a, b);
    for (bad, msg) in [
        (
            "rotation = [[1, 0, 0], [0, 1, 0], [0, 0, -1]]",
            "rotation matrix",
        ),
        ("rotation = [[1, 0, 0], [0, 1, 0]]", "three rows"),
        (
            "x = \"forward\"\nrotation = [[1, 0, 0], [0, 1, 0], [0, 0, 1]]",
            "not a mix",
        ),
    ] {
        let text = STATIC_FMT.replace("x = \"forward\"\ny = \"left\"\nz = \"up\"", bad);
        let err = format!("{:#}", ImuFormat::parse(&text, "fmt.toml").unwrap_err());
        let axes_line = text.lines().position(|l| l == "[axes]").unwrap() + 2;
        assert!(
            err.contains(msg)
                && (err.starts_with(&format!("fmt.toml:{axes_line}:"))
                    || err.starts_with(&format!("fmt.toml:{}:", axes_line - 1))),
            "{bad}: {err}"
        );
    }
}

/// The ROS example and its description, copied into `dir`.
fn ros_copy(dir: &Path) -> (std::path::PathBuf, std::path::PathBuf) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let d = dir.join("ros.csv");
    let f = dir.join("ros.toml");
    std::fs::copy(root.join("examples/ros_imu.csv"), &d).unwrap();
    std::fs::copy(root.join("formats/ros-imu.toml"), &f).unwrap();
    (d, f)
}

#[test]
fn outputs_never_land_on_inputs_or_special_files() {
    let tmp = tempfile::tempdir().unwrap();
    let (d, f) = ros_copy(tmp.path());
    let before = std::fs::read(&d).unwrap();
    let (ds, fs) = (d.to_str().unwrap(), f.to_str().unwrap());
    let nav = |out: &str| {
        sinsmodel(&[
            "navigate",
            "--imu",
            ds,
            "--imu-format",
            fs,
            "--lat",
            "30",
            "--lon",
            "120",
            "--att",
            "1,-2,30",
            "--out",
            out,
        ])
    };
    for out in [ds, fs] {
        let (ok, _, err) = nav(out);
        assert!(
            !ok && err.contains("--out") && err.contains("input of this run"),
            "{err}"
        );
    }
    for cmd in ["align", "allan", "imu-check"] {
        let (ok, _, err) = sinsmodel(&[cmd, "--imu", ds, "--imu-format", fs, "--json", ds]);
        assert!(
            !ok && err.contains("--json") && err.contains("input"),
            "{cmd}: {err}"
        );
    }
    let dir = tmp.path().join("adir");
    std::fs::create_dir(&dir).unwrap();
    let (ok, _, err) = sinsmodel(&[
        "imu-check",
        "--imu",
        ds,
        "--imu-format",
        fs,
        "--json",
        dir.to_str().unwrap(),
    ]);
    assert!(!ok && err.contains("not a regular file"), "{err}");
    assert_eq!(std::fs::read(&d).unwrap(), before, "the input changed");
    // a device as input: refused at once, not read forever
    let (ok, _, err) = sinsmodel(&["imu-check", "--imu", "/dev/zero", "--imu-format", fs]);
    assert!(!ok && err.contains("not a regular file"), "{err}");
}

#[test]
fn absurd_values_units_and_clocks_are_refused_with_file_and_line() {
    let tmp = tempfile::tempdir().unwrap();
    let (d, f) = ros_copy(tmp.path());
    let text = std::fs::read_to_string(&d).unwrap();
    let fmt = std::fs::read_to_string(&f).unwrap();
    let run = |data: &str, fmt: &str| {
        let dd = tmp.path().join("x.csv");
        let ff = tmp.path().join("x.toml");
        std::fs::write(&dd, data).unwrap();
        std::fs::write(&ff, fmt).unwrap();
        sinsmodel(&[
            "navigate",
            "--imu",
            dd.to_str().unwrap(),
            "--imu-format",
            ff.to_str().unwrap(),
            "--lat",
            "30",
            "--lon",
            "120",
            "--att",
            "1,-2,30",
            "--out",
            tmp.path().join("nav.txt").to_str().unwrap(),
        ])
    };
    // a 1e20 m/s^2 value in row 10
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    let mut cells: Vec<String> = lines[10].split(',').map(String::from).collect();
    cells[7] = "1e20".into();
    lines[10] = cells.join(",");
    let (ok, _, err) = run(&(lines.join("\n") + "\n"), &fmt);
    assert!(
        !ok && err.contains("x.csv:11") && err.contains("beyond any IMU"),
        "{err}"
    );
    // ns stamps described as seconds
    let (ok, _, err) = run(&text, &fmt.replace("unit = \"ns\"", "unit = \"s\""));
    assert!(!ok && err.contains("[time] unit"), "{err}");
    // a decimal comma: one field too many
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    lines[20] = lines[20].replacen(".", ",", 1);
    let (ok, _, err) = run(&(lines.join("\n") + "\n"), &fmt);
    assert!(
        !ok && err.contains("x.csv:21") && err.contains("decimal comma"),
        "{err}"
    );
    // a column used by name and by index
    let (ok, _, err) = run(&text, &fmt.replace("\"field.angular_velocity.y\"", "5"));
    assert!(!ok && err.contains("used twice"), "{err}");
    // the wrong delimiter
    let (ok, _, err) = run(
        &text,
        &fmt.replace("delimiter = \",\"", "delimiter = \";\""),
    );
    assert!(!ok && err.contains("is [file] delimiter right"), "{err}");
    // per-count scale forgotten on a moving log: imu-check still stops
    let dd = tmp.path().join("x.csv");
    std::fs::write(&dd, &text).unwrap();
    let ff = tmp.path().join("y.toml");
    std::fs::write(
        &ff,
        fmt.replace("accel_unit = \"m/s^2\"", "accel_unit = \"100 m/s^2\""),
    )
    .unwrap();
    let (ok, _, err) = sinsmodel(&[
        "imu-check",
        "--imu",
        dd.to_str().unwrap(),
        "--imu-format",
        ff.to_str().unwrap(),
    ]);
    assert!(!ok && err.contains("accel"), "{err}");
    // messages for a float column index and a unit written as 1/s
    let e = format!(
        "{:#}",
        ImuFormat::parse(&fmt.replace("column = \"%time\"", "column = 1.0"), "f.toml").unwrap_err()
    );
    assert!(e.contains("1-based index (a whole number)"), "{e}");
    let e = format!(
        "{:#}",
        ImuFormat::parse(
            &fmt.replace("gyro_unit = \"rad/s\"", "gyro_unit = \"1/s\""),
            "f.toml"
        )
        .unwrap_err()
    );
    assert!(!e.contains("not a number"), "{e}");
}

#[test]
fn a_closed_pipe_ends_the_output_quietly() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let out = Command::new("bash")
        .args([
            "-c",
            &format!(
                "'{}' imu-check --imu '{}' --imu-format '{}' | true; '{}' model list | head -1 >/dev/null",
                env!("CARGO_BIN_EXE_sinsmodel"),
                root.join("examples/ros_imu.csv").display(),
                root.join("formats/ros-imu.toml").display(),
                env!("CARGO_BIN_EXE_sinsmodel")
            ),
        ])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!err.contains("panicked"), "{err}");
}

#[test]
fn scenarios_that_would_hang_or_exhaust_memory_are_refused_before_simulating() {
    let tmp = tempfile::tempdir().unwrap();
    let base = "name = \"x\"\nimu_rate_hz = 100.0\n[start]\nlat_deg = 30.0\nlon_deg = 110.0\nh_m = 0.0\neuler_deg = [0.0, 0.0, 0.0]\n[[segment]]\nkind = \"rest\"\nduration_s = 10.0\n[[vibration]]\nkind = \"sine\"\naxis = \"n\"\namplitude = \"1 g\"\nfreq_hz = 20.0\n";
    let cases: &[(&str, &str, &str)] = &[
        ("freq_hz = 20.0", "freq_hz = inf", "freq_hz"),
        ("freq_hz = 20.0", "freq_hz = 1e9", "freq_hz"),
        ("imu_rate_hz = 100.0", "imu_rate_hz = 1e9", "imu_rate_hz"),
        ("lat_deg = 30.0", "lat_deg = nan", "lat_deg"),
        (
            "amplitude = \"1 g\"",
            "amplitude = \"1e308 g\"",
            "amplitude",
        ),
        ("duration_s = 10.0", "duration_s = 1e15", "duration_s"),
        ("duration_s = 10.0", "duration_s = 1e7", "--force"),
    ];
    for (from, to, want) in cases {
        let f = tmp.path().join("s.toml");
        std::fs::write(&f, base.replace(from, to)).unwrap();
        let out = tmp.path().join("o");
        let t0 = std::time::Instant::now();
        let (ok, _, err) = sinsmodel(&[
            "simulate",
            f.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(
            !ok && err.contains(want) && !err.contains("panicked"),
            "{to}: {err}"
        );
        assert!(t0.elapsed().as_secs() < 10, "{to}: took {:?}", t0.elapsed());
        assert!(!out.exists(), "{to}: an output directory was left");
    }
    // a vibration above Nyquist is simulated, with a warning
    let f = tmp.path().join("s.toml");
    std::fs::write(&f, base.replace("freq_hz = 20.0", "freq_hz = 80.0")).unwrap();
    let out = tmp.path().join("o");
    let (ok, _, err) = sinsmodel(&[
        "simulate",
        f.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(ok && err.contains("Nyquist"), "{err}");
    // re-running into it replaces the run; a file the user added there stops it
    std::fs::write(out.join("notes.txt"), "mine").unwrap();
    let (ok, _, err) = sinsmodel(&[
        "simulate",
        f.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(!ok && err.contains("notes.txt"), "{err}");
    assert_eq!(
        std::fs::read_to_string(out.join("notes.txt")).unwrap(),
        "mine"
    );
}
