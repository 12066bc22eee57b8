//! Consistency a user trips over (#25): time bases (`--init auto`'s start and `--outage` said from
//! the first IMU sample), one spelling per option across commands (`--init`, `--nav-rate`,
//! `--skip`), signed directions in words, the priors a hand-tuned run overrode, and `--out` a
//! file or a directory as each command's help says.

mod common;
use common::sinsmodel;
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn p(x: &Path) -> &str {
    x.to_str().unwrap()
}

/// The drive scenario (60 s at rest, then a drive-off at heading 30°) simulated into `dir/drive`.
fn simulate_drive(dir: &Path) -> PathBuf {
    let out = dir.join("drive");
    let (ok, _, err) = sinsmodel(&[
        "simulate",
        p(&root().join("scenarios/drive.toml")),
        "--out",
        p(&out),
    ]);
    assert!(ok, "{err}");
    out
}

/// The static scenario shortened to 200 s, simulated into `dir/static`.
fn simulate_short_static(dir: &Path) -> PathBuf {
    let text = std::fs::read_to_string(root().join("scenarios/static.toml")).unwrap();
    assert!(text.contains("duration_s = 7200.0"));
    let scen = dir.join("short.toml");
    std::fs::write(
        &scen,
        text.replace("duration_s = 7200.0", "duration_s = 200.0"),
    )
    .unwrap();
    let out = dir.join("static");
    let (ok, _, err) = sinsmodel(&["simulate", p(&scen), "--out", p(&out)]);
    assert!(ok, "{err}");
    out
}

/// `file` with `offset` [s] added to the time (first column) of every data row, written to `to`:
/// the data on an absolute clock, as GPS-stamped logs are.
fn shift_clock(file: &Path, to: &Path, offset: f64) {
    let text = std::fs::read_to_string(file).unwrap();
    let mut out = String::new();
    for line in text.lines() {
        if line.starts_with('#') || line.trim().is_empty() {
            out.push_str(line);
        } else {
            let (t, rest) = line.split_once(' ').unwrap();
            let t: f64 = t.parse().unwrap();
            out.push_str(&format!("{:.6} {rest}", t + offset));
        }
        out.push('\n');
    }
    std::fs::write(to, out).unwrap();
}

/// On a GPS-like clock (1e9 s), `--init auto` says where the run starts on the data's clock and
/// from the first sample; the outage table and the outage refusals count from the first sample,
/// as `--outage` does (its help says so).
#[test]
fn init_auto_and_outages_say_their_times_from_the_first_sample() {
    let dir = tempfile::tempdir().unwrap();
    let sim = simulate_drive(dir.path());
    let (imu, aid) = (dir.path().join("imu.txt"), dir.path().join("gnss.txt"));
    shift_clock(&sim.join("imu.txt"), &imu, 1e9);
    shift_clock(&sim.join("gnss.txt"), &aid, 1e9);
    let run = |outages: &[&str], out: &str| {
        let out = dir.path().join(out);
        let mut a = vec![
            "filter",
            "--model",
            "P13",
            "--grade",
            "tactical",
            "--imu",
            p(&imu),
            "--aid",
            p(&aid),
            "--init",
            "auto",
            "--out",
            p(&out),
        ];
        for o in outages {
            a.extend(["--outage", o]);
        }
        let (ok, _, err) = sinsmodel(&a);
        (ok, err)
    };
    let (ok, err) = run(&["100,20"], "f");
    assert!(ok, "{err}");
    // the first sample at 1e9 + 0.005 s; the run starts at the start of its interval
    assert!(
        err.contains(
            "init auto: the run starts at t = 1000000000.000 s on the data's clock = 0.005 s before the first IMU sample (--outage START counts from that sample)"
        ),
        "{err}"
    );
    assert!(
        err.contains("GNSS outages: drift at the first fix after each")
            && err.contains("times in seconds from the first IMU sample, as --outage counts"),
        "{err}"
    );
    let row = err
        .lines()
        .find(|l| l.trim_start().starts_with("100.0 "))
        .unwrap_or_else(|| panic!("no outage row starting at 100.0 s: {err}"));
    assert!(row.contains(" 20.0 "), "{row}");
    let (ok, err) = run(&["100,20", "110,20"], "g");
    assert!(!ok);
    assert!(
        err.contains("100.000 .. 120.000 s from the first IMU sample (t = 1000000100.005 .. 1000000120.005 s on the data's clock)"),
        "{err}"
    );
    // a START given on the data's clock: refused with the START that was probably meant
    let (ok, err) = run(&["1000000100.005,20"], "k");
    assert!(!ok);
    assert!(
        err.contains("looks like a time on that clock")
            && err.contains("START = 100.000 was probably meant"),
        "{err}"
    );
    let (ok, err) = run(&["200,20"], "h");
    assert!(!ok);
    assert!(
        err.contains("--outage 200.000 .. 220.000 s from the first IMU sample")
            && err.contains("219.995 s from the first IMU sample"),
        "{err}"
    );
    let (_, help, _) = sinsmodel(&["filter", "--help"]);
    assert!(
        help.contains("START counted from the first IMU sample (not the data's clock"),
        "{help}"
    );
}

/// navigate takes the initial state as `--init LAT,LON,H,ROLL,PITCH,YAW` as filter does (its
/// own `--lat --lon --h --att` still work, the two forms exclusive), and the rate as `--nav-rate`
/// as filter does (`--out-rate` still accepted): the same rows either way.
#[test]
fn navigate_takes_init_and_nav_rate_as_filter_does() {
    let dir = tempfile::tempdir().unwrap();
    let sim = simulate_drive(dir.path());
    let imu = sim.join("imu.txt");
    let rows = |args: &[&str], name: &str| {
        let out = dir.path().join(name);
        let mut a = vec!["navigate", "--imu", p(&imu), "--out", p(&out)];
        a.extend_from_slice(args);
        let (ok, _, err) = sinsmodel(&a);
        assert!(ok, "{args:?}: {err}");
        let text = std::fs::read_to_string(&out).unwrap();
        text.lines()
            .filter(|l| !l.starts_with('#'))
            .map(str::to_string)
            .collect::<Vec<_>>()
    };
    let old = rows(
        &[
            "--lat",
            "40.0966",
            "--lon",
            "-105.1474",
            "--h",
            "1601",
            "--att",
            "0,0,30",
            "--out-rate",
            "5",
        ],
        "old.txt",
    );
    let new = rows(
        &["--init", "40.0966,-105.1474,1601,0,0,30", "--nav-rate", "5"],
        "new.txt",
    );
    assert_eq!(old.len(), 1101, "5 Hz over 220 s");
    assert_eq!(old, new);
    // the 9-number form with a velocity, as filter takes it
    let with_vel = rows(
        &[
            "--init",
            "40.0966,-105.1474,1601,0,0,30,0,0,0",
            "--nav-rate",
            "5",
        ],
        "vel.txt",
    );
    assert_eq!(with_vel, new);
    let (ok, _, err) = sinsmodel(&[
        "navigate",
        "--imu",
        p(&imu),
        "--init",
        "40,-105,1601,0,0,30",
        "--att",
        "0,0,30",
        "--out",
        p(&dir.path().join("x.txt")),
    ]);
    assert!(!ok && err.contains("cannot be used with"), "{err}");
    let (ok, _, err) = sinsmodel(&[
        "navigate",
        "--imu",
        p(&imu),
        "--init",
        "auto",
        "--out",
        p(&dir.path().join("x.txt")),
    ]);
    assert!(
        !ok && err.contains("--init auto: navigate has no aiding"),
        "{err}"
    );
    let (ok, _, err) = sinsmodel(&[
        "navigate",
        "--imu",
        p(&imu),
        "--init",
        "40,-105,1601,0,95,30",
        "--out",
        p(&dir.path().join("x.txt")),
    ]);
    // the same check and words as filter's --init
    assert!(
        !ok && err.contains("--init: pitch = 95 is outside [-90, 90] deg"),
        "{err}"
    );
    let (ok, _, err) = sinsmodel(&[
        "navigate",
        "--imu",
        p(&imu),
        "--lat",
        "40",
        "--lon",
        "-105",
        "--att",
        "0,0,30",
        "--nav-rate",
        "0",
        "--out",
        p(&dir.path().join("x.txt")),
    ]);
    assert!(!ok && err.contains("--nav-rate 0"), "{err}");
    // filter takes navigate's old spelling too
    let (_, help, _) = sinsmodel(&["filter", "--help"]);
    assert!(help.contains("--out-rate"), "{help}");
}

/// A drift south and west is said so (not "-0.667 km north"), and the height change with a
/// vertical channel that moves, as up or down.
#[test]
fn navigate_says_south_and_west_not_negative_north() {
    let dir = tempfile::tempdir().unwrap();
    let sim = simulate_drive(dir.path());
    let out = dir.path().join("nav.txt");
    // headed 180° wrong, the drive goes south-west instead of north-east
    let (ok, _, err) = sinsmodel(&[
        "navigate",
        "--imu",
        p(&sim.join("imu.txt")),
        "--init",
        "40.0966,-105.1474,1601,0,0,210",
        "--vertical",
        "damped",
        "--out",
        p(&out),
    ]);
    assert!(ok, "{err}");
    let line = err
        .lines()
        .find(|l| l.starts_with("final position"))
        .unwrap_or_else(|| panic!("{err}"));
    let inside = &line[line.find('(').unwrap() + 1..line.find(')').unwrap()];
    assert!(
        inside.contains(" km south") && inside.contains(" km west"),
        "{line}"
    );
    assert!(
        inside.contains(" m up") || inside.contains(" m down"),
        "{line}"
    );
    assert!(!inside.contains('-'), "a signed distance: {line}");
    let (ok, _, err) = sinsmodel(&[
        "navigate",
        "--imu",
        p(&sim.join("imu.txt")),
        "--init",
        "40.0966,-105.1474,1601,0,0,30",
        "--out",
        p(&out),
        "--overwrite",
    ]);
    assert!(ok, "{err}");
    let line = err
        .lines()
        .find(|l| l.starts_with("final position"))
        .unwrap();
    assert!(
        line.contains(" km north,") && line.contains(" km east)"),
        "fixed vertical, no height: {line}"
    );
}

/// align takes --skip as allan and imu-check do: seconds after the first sample, the stretch at
/// rest searched after them, the printed start still counted from the first sample.
#[test]
fn align_skips_like_allan_and_imu_check() {
    let dir = tempfile::tempdir().unwrap();
    let sim = simulate_short_static(dir.path());
    let imu = sim.join("imu.txt");
    let align = |skip: &str, json: &str| {
        let j = dir.path().join(json);
        let (ok, out, err) = sinsmodel(&[
            "align",
            "--imu",
            p(&imu),
            "--lat",
            "28.22",
            "--skip",
            skip,
            "--json",
            p(&j),
        ]);
        assert!(ok, "{err}");
        let v: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&j).unwrap()).unwrap();
        (out, v["skipped_s"].as_f64().unwrap())
    };
    let (_, s0) = align("0", "a0.json");
    assert!(s0 < 1.0, "{s0}");
    let (out, s) = align("50", "a50.json");
    assert!((50.0..51.0).contains(&s), "skipped_s {s}");
    assert!(out.contains("at rest from 50 s after the start"), "{out}");
    for bad in ["--skip=-1", "--skip=nan"] {
        let (ok, _, err) = sinsmodel(&["align", "--imu", p(&imu), bad]);
        assert!(!ok && err.contains("--skip"), "{bad}: {err}");
    }
    // 150 s skipped leave 50 s, fewer than the 60 s alignment needs
    let (ok, _, err) = sinsmodel(&["align", "--imu", p(&imu), "--skip", "150"]);
    assert!(!ok && err.contains("not at rest long enough"), "{err}");
}

/// `--noise` with an allan file uses the RMS over the axes, and its help says so (it said "mean").
#[test]
fn noise_from_allan_is_the_rms_over_the_axes_as_the_help_says() {
    let dir = tempfile::tempdir().unwrap();
    let sim = simulate_drive(dir.path());
    // gyro whites 1, 2, 2 e-4: RMS 1.732e-4 (mean 1.667e-4); accels 1, 1, 4 e-3: RMS 2.449e-3
    let json = dir.path().join("allan.json");
    std::fs::write(
        &json,
        r#"{"fit": {"gyro_x": {"white": 1e-4}, "gyro_y": {"white": 2e-4}, "gyro_z": {"white": 2e-4},
        "accel_x": {"white": 1e-3}, "accel_y": {"white": 1e-3}, "accel_z": {"white": 4e-3}}}"#,
    )
    .unwrap();
    let (_, _, err) = sinsmodel(&[
        "filter",
        "--model",
        "P13",
        "--grade",
        "tactical",
        "--imu",
        p(&sim.join("imu.txt")),
        "--aid",
        p(&sim.join("gnss.txt")),
        "--init",
        "auto",
        "--noise",
        p(&json),
        "--out",
        p(&dir.path().join("f")),
    ]);
    assert!(
        err.contains("ARW 1.732e-4 rad/sqrt(s)") && err.contains("VRW 2.449e-3 m/s/sqrt(s)"),
        "{err}"
    );
    let (_, help, _) = sinsmodel(&["filter", "--help"]);
    assert!(
        help.contains("the RMS over the three axes") && !help.contains("mean ARW"),
        "{help}"
    );
}

/// A hand-tuned run says which priors the user set instead of calling itself the spec's
/// laser-gyro INS.
#[test]
fn priors_line_names_the_priors_the_user_set() {
    let dir = tempfile::tempdir().unwrap();
    let sim = simulate_drive(dir.path());
    let (imu, aid) = (sim.join("imu.txt"), sim.join("gnss.txt"));
    let base = [
        "filter",
        "--model",
        "P13",
        "--imu",
        p(&imu),
        "--aid",
        p(&aid),
        "--init",
        "auto",
    ];
    let priors_line = |extra: &[&str], out: &str| {
        let o = dir.path().join(out);
        let mut a = base.to_vec();
        a.extend_from_slice(extra);
        a.extend(["--out", p(&o)]);
        let (_, _, err) = sinsmodel(&a);
        err.lines()
            .find(|l| l.starts_with("priors and noise:"))
            .unwrap_or_else(|| panic!("{err}"))
            .to_string()
    };
    let plain = priors_line(&[], "a");
    assert!(
        plain.contains("navigation grade (the spec's defaults, a navigation-grade laser-gyro INS)"),
        "{plain}"
    );
    let tuned = priors_line(
        &[
            "--prior",
            "eps_*=0.5 deg/s",
            "--prior",
            "nabla_*=0.5 m/s^2",
            "--noise",
            "arw=0.5 deg/sqrt(h), vrw=150 ug/sqrt(Hz)",
        ],
        "b",
    );
    assert!(
        tuned.contains("the spec's navigation-grade defaults, with eps_*, nabla_* set by --prior and the noise set by --noise"),
        "{tuned}"
    );
    assert!(
        !tuned.contains("(the spec's defaults, a navigation-grade"),
        "{tuned}"
    );
    let graded = priors_line(&["--grade", "mems", "--prior", "phi_d=10 deg"], "c");
    assert!(
        graded.contains("--grade mems") && graded.contains("with phi_d set by --prior"),
        "{graded}"
    );
}

/// Each command's `--out` help says whether it is a file or a directory; reproduce writes to
/// out/reproduce unless told, and names how the shipped docs/reproduce is refreshed.
#[test]
fn out_is_a_file_or_a_directory_as_each_help_says() {
    for (cmd, what) in [
        ("navigate", "Output FILE"),
        ("filter", "Output DIRECTORY"),
        ("explain", "Output DIRECTORY"),
        ("simulate", "Output DIRECTORY"),
        ("reproduce", "Output DIRECTORY"),
        ("explain-eval", "Output DIRECTORY"),
    ] {
        let (ok, help, err) = sinsmodel(&[cmd, "--help"]);
        assert!(ok, "{err}");
        let out = help
            .lines()
            .skip_while(|l| !l.trim_start().starts_with("--out <"))
            .take(3)
            .collect::<Vec<_>>()
            .join(" ");
        assert!(out.contains(what), "{cmd}: {out}");
    }
    let (_, help, _) = sinsmodel(&["reproduce", "--help"]);
    assert!(
        help.contains("[default: out/reproduce]") && help.contains("--out docs/reproduce"),
        "{help}"
    );
}
