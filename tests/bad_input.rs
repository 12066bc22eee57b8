//! Bad input gets a clear error naming the file, line and problem; outputs are never left
//! half-written.

mod common;

use std::path::Path;

fn run(args: &[&str]) -> (bool, String) {
    let (ok, _, err) = common::sinsmodel(args);
    (ok, err)
}

fn navigate(imu: &Path, out: &Path) -> (bool, String) {
    run(&[
        "navigate",
        "--imu",
        imu.to_str().unwrap(),
        "--lat",
        "30",
        "--lon",
        "110",
        "--att",
        "0,0,0",
        "--out",
        out.to_str().unwrap(),
    ])
}

/// Simulates the scenario `toml` into `d/o` (its text in `d/s.toml`); returns `d/o`.
fn simulated(d: &Path, toml: &str) -> std::path::PathBuf {
    let sc = d.join("s.toml");
    std::fs::write(&sc, toml).unwrap();
    let o = d.join("o");
    let (ok, err) = run(&[
        "simulate",
        sc.to_str().unwrap(),
        "--out",
        o.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    o
}

/// Writes the IMU text `text` to `path` with `f` applied to each data row's values (its index
/// among the lines, the values t dθ dv), comments kept.
fn rewrite_imu(text: &str, path: &Path, f: &dyn Fn(usize, &mut Vec<f64>)) {
    let mut out = String::new();
    for (k, l) in text.lines().enumerate() {
        if l.starts_with('#') {
            out.push_str(l);
        } else {
            let mut v: Vec<f64> = l.split_whitespace().map(|x| x.parse().unwrap()).collect();
            f(k, &mut v);
            let w: Vec<String> = v.iter().map(|x| format!("{x:.15e}")).collect();
            out.push_str(&w.join(" "));
        }
        out.push('\n');
    }
    std::fs::write(path, out).unwrap();
}

const GOOD: &str = "# t dth dv\n0.01 0 0 0 0 0 -0.098\n0.02 0 0 0 0 0 -0.098\n0.03 0 0 0 0 0 -0.098\n0.04 0 0 0 0 0 -0.098\n";

#[test]
fn imu_text_errors_name_file_line_and_problem() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("nav.txt");
    let cases = [
        (
            "short.txt",
            GOOD.replace("0.02 0 0 0 0 0 -0.098", "0.02 0 0 0 0 -0.098"),
            ":3:",
            "expected 7 columns",
        ),
        (
            "nan.txt",
            GOOD.replace("0.03 0 0 0 0 0 -0.098", "0.03 0 NaN 0 0 0 -0.098"),
            ":4:",
            "not finite",
        ),
        (
            "word.txt",
            GOOD.replace("0.03 0 0 0 0 0 -0.098", "0.03 0 x 0 0 0 -0.098"),
            ":4:",
            "`x` is not a number",
        ),
        (
            "back.txt",
            GOOD.replace("0.03 0", "0.015 0"),
            ":4:",
            "does not increase",
        ),
        ("gap.txt", GOOD.replace("0.04 0", "0.40 0"), ":5:", "gap"),
    ];
    for (name, text, line, problem) in cases {
        let p = dir.path().join(name);
        std::fs::write(&p, text).unwrap();
        let (ok, err) = navigate(&p, &out);
        assert!(!ok, "{name} accepted");
        assert!(
            err.contains(name) && err.contains(line) && err.contains(problem),
            "{name}: {err}"
        );
        assert!(!out.exists(), "no output written for {name}");
    }
    let (ok, err) = navigate(&dir.path().join("missing.txt"), &out);
    assert!(
        !ok && err.contains("cannot read IMU file") && err.contains("missing.txt"),
        "{err}"
    );
    // a good file navigates and the output appears whole (no temporary left behind)
    let p = dir.path().join("good.txt");
    std::fs::write(&p, GOOD).unwrap();
    let (ok, err) = navigate(&p, &out);
    assert!(ok, "{err}");
    assert!(out.exists());
    let leftovers: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| {
            e.file_name()
                .to_string_lossy()
                .contains("sinsmodel-partial")
        })
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
}

#[test]
fn scenario_errors_name_file_line_and_problem() {
    let dir = tempfile::tempdir().unwrap();
    let base = "name = \"x\"\nimu_rate_hz = 100.0\n[start]\nlat_deg = 30.0\nlon_deg = 110.0\n[[segment]]\nkind = \"rest\"\nduration_s = 1.0\n";
    let cases = [
        (
            "term.toml",
            format!("{base}[errors]\nkaq_q_xy = \"1 ug/g^2\"\n"),
            ":10:",
            "unknown term `kaq_q_xy`",
        ),
        (
            "unit.toml",
            format!("{base}[errors]\neps_x = \"0.01 m/s\"\n"),
            ":10:",
            "dimension",
        ),
        (
            "unit2.toml",
            format!("{base}[errors]\neps_x = \"0.01 furlong/h\"\n"),
            ":10:",
            "unknown unit `furlong`",
        ),
        // a scale factor of 10 written for 10 ppm, a bias in rad/s for deg/h, in m/s² for µg
        (
            "scale.toml",
            format!("{base}[errors]\nkg_11 = \"10\"\n"),
            ":10:",
            "1.00e7 ppm is beyond the 2.00e5 ppm the term can physically have",
        ),
        (
            "bias.toml",
            format!("{base}[errors]\neps_x = \"10 rad/s\"\n"),
            ":10:",
            "is beyond the 72000 deg/h",
        ),
        (
            "accel.toml",
            format!("{base}[errors]\nnabla_x = \"50 m/s^2\"\n"),
            ":10:",
            "is beyond the 1.00e6 ug",
        ),
        ("syntax.toml", format!("{base}[errors\n"), ":9", "invalid"),
        (
            "kind.toml",
            base.replace("\"rest\"", "\"hover\""),
            "segment 1",
            "unknown kind `hover`",
        ),
    ];
    for (name, text, line, problem) in cases {
        let p = dir.path().join(name);
        std::fs::write(&p, text).unwrap();
        let out = dir.path().join(format!("out_{name}"));
        let (ok, err) = run(&[
            "simulate",
            p.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(!ok, "{name} accepted");
        assert!(
            err.contains(name)
                && err.contains(line)
                && err.to_lowercase().contains(&problem.to_lowercase()),
            "{name}: {err}"
        );
        assert!(!out.join("imu.txt").exists());
    }
}

#[test]
fn simulate_then_navigate_round_trip_through_text() {
    let dir = tempfile::tempdir().unwrap();
    let sc = dir.path().join("s.toml");
    std::fs::write(
        &sc,
        "name = \"rt\"\nimu_rate_hz = 100.0\n[start]\nlat_deg = 30.0\nlon_deg = 110.0\n[[segment]]\nkind = \"rest\"\nduration_s = 60.0\n[gnss]\nrate_hz = 1.0\n",
    )
    .unwrap();
    let out = dir.path().join("sim");
    let (ok, err) = run(&[
        "simulate",
        sc.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    for f in ["imu.txt", "truth.txt", "gnss.txt", "scenario.toml"] {
        assert!(out.join(f).exists(), "{f}");
    }
    let imu = sinsmodel::io::imu_stream::read_text(&out.join("imu.txt")).unwrap();
    assert_eq!(imu.samples.len(), 6000);
    let fixes = sinsmodel::io::aiding::read(&out.join("gnss.txt")).unwrap();
    assert_eq!(fixes.len(), 60);
    let nav = dir.path().join("nav.txt");
    let (ok, err) = navigate(&out.join("imu.txt"), &nav);
    assert!(ok, "{err}");
    let rows = sinsmodel::io::truth::read(&nav).unwrap();
    let truth = sinsmodel::io::truth::read(&out.join("truth.txt")).unwrap();
    let (a, b) = (rows.last().unwrap(), truth.last().unwrap());
    assert!((a.t - b.t).abs() < 1e-9);
    assert!(
        (a.lat - b.lat).abs() * 6.4e6 < 0.01,
        "navigated through the text files to the truth"
    );
}

#[test]
fn out_of_range_edges_are_refused_by_option_or_file_line() {
    let dir = tempfile::tempdir().unwrap();
    let p = |n: &str| dir.path().join(n).to_str().unwrap().to_string();
    // a short static IMU log and good aiding
    let mut imu = String::from("# t dth dv\n");
    for k in 1..=300 {
        imu.push_str(&format!("{} 0 0 0 0 0 -0.0979\n", k as f64 * 0.01));
    }
    std::fs::write(p("imu.txt"), imu).unwrap();
    let aid_ok = "1 30 110 0 1 1 1\n2 30 110 0 1 1 1\n";
    std::fs::write(p("aid.txt"), aid_ok).unwrap();
    let filter = |extra: &[&str]| {
        let mut a = vec![
            "filter".to_string(),
            "--model".into(),
            "P13".into(),
            "--imu".into(),
            p("imu.txt"),
            "--out".into(),
            p("out"),
        ];
        a.extend(extra.iter().map(|s| s.to_string()));
        let refs: Vec<&str> = a.iter().map(|s| s.as_str()).collect();
        run(&refs)
    };
    let aid = p("aid.txt");
    let (ok, err) = filter(&["--aid", &aid, "--init", "90,110,0,0,0,0"]);
    assert!(
        !ok && err.contains("--init") && err.contains("pole"),
        "{err}"
    );
    std::fs::write(p("empty.txt"), "").unwrap();
    let empty = p("empty.txt");
    let (ok, err) = filter(&["--aid", &aid, "--init", "30,110,0,0,0,0", "--truth", &empty]);
    assert!(
        !ok && err.contains("empty.txt") && err.contains("no data rows"),
        "{err}"
    );
    for (name, text, want) in [
        ("lat.txt", "1 200 110 0 1 1 1\n", "aid_lat.txt:1: latitude"),
        ("sig.txt", "1 30 110 0 0 1 1\n", "aid_sig.txt:1: sigma"),
        ("lon.txt", "1 30 1e9 0 1 1 1\n", "aid_lon.txt:1: longitude"),
    ] {
        let f = p(&format!("aid_{name}"));
        std::fs::write(&f, text).unwrap();
        let (ok, err) = filter(&["--aid", &f, "--init", "30,110,0,0,0,0"]);
        assert!(!ok && err.contains(want), "{name}: {err}");
    }
    let head = "% GPST latitude(deg) longitude(deg) height(m) Q ns sdn(m) sde(m) sdu(m) sdne(m) sdeu(m) sdun(m) age(s) ratio\n";
    for (name, row, want) in [
        (
            "lat.pos",
            "2025/07/08 00:00:01.000 200.0 110.0 0.0 1 20 0.01 0.01 0.01 0 0 0 0 0\n",
            ":2: latitude",
        ),
        (
            "month.pos",
            "2025/13/08 00:00:01.000 30.0 110.0 0.0 1 20 0.01 0.01 0.01 0 0 0 0 0\n",
            ":2: bad GPST",
        ),
        (
            "sig.pos",
            "2025/07/08 00:00:01.000 30.0 110.0 0.0 1 20 -1 0.01 0.01 0 0 0 0 0\n",
            ":2: a position sigma",
        ),
    ] {
        let f = p(name);
        std::fs::write(&f, format!("{head}{row}")).unwrap();
        let (ok, err) = filter(&["--aid", &f, "--init", "30,110,0,0,0,0"]);
        assert!(!ok && err.contains(want), "{name}: {err}");
    }
    let truth = p("truth.txt");
    std::fs::write(&truth, "0 200 110 0 0 0 0 0 0 0\n").unwrap();
    let (ok, err) = filter(&["--aid", &aid, "--truth", &truth]);
    assert!(!ok && err.contains("truth.txt:1: latitude"), "{err}");
    let imu_p = p("imu.txt");
    for (opt, val) in [
        ("--gyro-bias-sigma", "nan"),
        ("--lon", "nan"),
        ("--h", "inf"),
        ("--lat", "nan"),
    ] {
        let (ok, err) = run(&["align", "--imu", &imu_p, opt, val]);
        assert!(!ok && err.contains(opt), "{opt} {val}: {err}");
    }
    assert!(
        !Path::new(&p("out")).exists(),
        "a refused run left its output directory"
    );
}

#[test]
fn scenario_keys_are_found_by_whole_name_and_slow_data_does_not_panic_align() {
    let dir = tempfile::tempdir().unwrap();
    let scen = "name = \"x\"\nimu_rate_hz = 100.0\n[start]\nlat_deg = 30.0\nlon_deg = 110.0\nh_m = 0.0\neuler_deg = [0.0, 0.0, 0.0]\n[[segment]]\nkind = \"rest\"\nduration_s = 10.0\n[errors]\nd_xq=\"5e-5 s^2/m\"\n[gnss]\nrate_hz = 1000.0\n";
    let f = dir.path().join("g.toml");
    std::fs::write(&f, scen).unwrap();
    let out = dir.path().join("o");
    let (ok, err) = run(&[
        "simulate",
        f.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(
        !ok && err.contains("g.toml:12:") && err.contains("d_xq"),
        "{err}"
    );
    std::fs::write(&f, scen.replace("d_xq", "d_x")).unwrap();
    let (ok, err) = run(&[
        "simulate",
        f.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(
        !ok && err.contains("g.toml:14:") && err.contains("rate_hz"),
        "{err}"
    );
    let slow = dir.path().join("slow.txt");
    std::fs::write(
        &slow,
        "100 0 0 0 0 0 -980\n200 0 0 0 0 0 -980\n300 0 0 0 0 0 -980\n",
    )
    .unwrap();
    let (ok, err) = run(&["align", "--imu", slow.to_str().unwrap()]);
    // refused where the samples are read (the interval is no IMU's), before align's own check
    assert!(
        !ok && err.contains("median sample interval") && !err.contains("panicked"),
        "{err}"
    );
}

/// A start attitude that contradicts gravity (a sensor upside down given roll 0) stops
/// navigate and filter with the attitude the data measure; `--force` runs anyway.
#[test]
fn an_initial_attitude_against_gravity_is_refused_unless_forced() {
    let dir = tempfile::tempdir().unwrap();
    let sc = dir.path().join("flip.toml");
    std::fs::write(
        &sc,
        "name = \"flip\"\nimu_rate_hz = 100.0\ntruth_rate_hz = 1.0\nseed = 2\n[start]\nlat_deg = 30.0\nlon_deg = 110.0\n\
         euler_deg = [180.0, 0.0, 20.0]\n[[segment]]\nkind = \"rest\"\nduration_s = 30.0\n\
         [noise]\narw = \"0.01 deg/sqrt(h)\"\nvrw = \"10 ug/sqrt(Hz)\"\n\
         [gnss]\nrate_hz = 1.0\nsigma_ne = \"0.5 m\"\nsigma_d = \"1 m\"\n",
    )
    .unwrap();
    let sim = dir.path().join("sim");
    let (ok, err) = run(&[
        "simulate",
        sc.to_str().unwrap(),
        "--out",
        sim.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let imu = sim.join("imu.txt");
    let aid = sim.join("gnss.txt");
    let out = dir.path().join("nav.txt");
    let (ok, err) = navigate(&imu, &out);
    assert!(
        !ok && err.contains("--att: the initial attitude contradicts gravity")
            && err.contains("roll 180.00")
            || !ok && err.contains("roll -180.00"),
        "{err}"
    );
    assert!(!out.exists());
    let nav_forced = |extra: &[&str]| {
        let mut a = vec![
            "navigate",
            "--imu",
            imu.to_str().unwrap(),
            "--lat",
            "30",
            "--lon",
            "110",
            "--att",
            "0,0,0",
            "--out",
            out.to_str().unwrap(),
        ];
        a.extend_from_slice(extra);
        run(&a)
    };
    let (ok, err) = nav_forced(&["--force"]);
    assert!(
        ok && err.contains("warning: the initial attitude contradicts gravity"),
        "{err}"
    );
    let od = dir.path().join("f");
    let filter = |init: &str| {
        run(&[
            "filter",
            "--model",
            "P13",
            "--imu",
            imu.to_str().unwrap(),
            "--aid",
            aid.to_str().unwrap(),
            "--init",
            init,
            "--out",
            od.to_str().unwrap(),
        ])
    };
    let (ok, err) = filter("30,110,0,0,0,20");
    assert!(
        !ok && err.contains("--init: the initial attitude contradicts gravity"),
        "{err}"
    );
    let (ok, err) = filter("30,110,0,180,0,20");
    assert!(ok, "the right attitude runs: {err}");
}

/// Leftovers of a killed run (a staging directory, a set-aside directory, a temporary file,
/// named with a process that is gone) are removed by the next run into the same place, and a
/// re-run replaces the earlier run's directory whole.
#[test]
fn leftovers_of_killed_runs_are_cleaned_and_reruns_replace_whole() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let imu = d.join("imu.txt");
    std::fs::write(&imu, GOOD).unwrap();
    // pid 4194304 is above Linux's pid_max: never a live process (tests/output_guard.rs has
    // the names that are left alone)
    std::fs::create_dir(d.join(".o.sinsmodel-staging-4194304")).unwrap();
    std::fs::write(
        d.join(".o.sinsmodel-staging-4194304/.sinsmodel-staging"),
        "sinsmodel staging directory: removed when its run ends\n",
    )
    .unwrap();
    std::fs::write(d.join(".o.sinsmodel-staging-4194304/states.txt"), "half").unwrap();
    // a file's temporary: a marked directory holding the half-written file
    let partial = d.join(".nav.txt.sinsmodel-partial-4194304-0");
    std::fs::create_dir(&partial).unwrap();
    std::fs::write(
        partial.join(".sinsmodel-partial"),
        "sinsmodel temporary: removed when its file is written\n",
    )
    .unwrap();
    std::fs::write(partial.join("nav.txt"), "half").unwrap();
    let (ok, err) = navigate(&imu, &d.join("nav.txt"));
    assert!(ok, "{err}");
    assert!(!partial.exists());
    let sc = d.join("s.toml");
    std::fs::write(
        &sc,
        "name = \"s\"\nimu_rate_hz = 100.0\n[start]\nlat_deg = 30.0\nlon_deg = 110.0\n[[segment]]\nkind = \"rest\"\nduration_s = 20.0\n[gnss]\nrate_hz = 1.0\nsigma_ne = \"0.5 m\"\nsigma_d = \"1 m\"\n",
    )
    .unwrap();
    let o = d.join("o");
    for _ in 0..2 {
        let (ok, err) = run(&[
            "simulate",
            sc.to_str().unwrap(),
            "--out",
            o.to_str().unwrap(),
        ]);
        assert!(ok, "{err}");
    }
    assert!(!d.join(".o.sinsmodel-staging-4194304").exists());
    let left: Vec<String> = std::fs::read_dir(d)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.contains("sinsmodel-"))
        .collect();
    assert!(left.is_empty(), "{left:?}");
    assert!(o.join("imu.txt").exists() && o.join("gnss.txt").exists());
}

/// reproduce writes its directory like every other command: one holding a user's files is
/// refused before any work, and the files are untouched.
#[test]
fn reproduce_refuses_a_directory_it_did_not_write() {
    let dir = tempfile::tempdir().unwrap();
    let o = dir.path().join("mine");
    std::fs::create_dir(&o).unwrap();
    std::fs::write(o.join("results.md"), "my notes").unwrap();
    for extra in [&[][..], &["--consistency"][..]] {
        let mut a = vec!["reproduce", "--quick", "--out", o.to_str().unwrap()];
        a.extend_from_slice(extra);
        let (ok, err) = run(&a);
        assert!(!ok && err.contains("was not written by sinsmodel"), "{err}");
    }
    assert_eq!(
        std::fs::read_to_string(o.join("results.md")).unwrap(),
        "my notes"
    );
    assert_eq!(std::fs::read_dir(&o).unwrap().count(), 1);
}

/// A scenario within every bound whose vibration would take hours to simulate (10 000 random
/// components up to 1e5 Hz at a 100 Hz IMU) is refused at once with the estimate; --force runs it.
#[test]
fn a_scenario_that_would_take_hours_is_refused_with_its_estimate() {
    let dir = tempfile::tempdir().unwrap();
    let sc = dir.path().join("slow.toml");
    std::fs::write(
        &sc,
        "name = \"slow\"\nimu_rate_hz = 100.0\n[start]\nlat_deg = 30.0\nlon_deg = 110.0\n[[segment]]\nkind = \"rest\"\nduration_s = 60.0\n\
         [[vibration]]\nkind = \"random\"\naxis = \"z\"\npsd = \"1e-4 g^2/Hz\"\nband_hz = [20.0, 1e5]\ncomponents = 10000\n",
    )
    .unwrap();
    let t = std::time::Instant::now();
    let (ok, err) = run(&[
        "simulate",
        sc.to_str().unwrap(),
        "--out",
        dir.path().join("o").to_str().unwrap(),
    ]);
    assert!(
        !ok && err.contains("evaluations") && err.contains("--force"),
        "{err}"
    );
    assert!(t.elapsed().as_secs() < 30, "refused before any work");
    assert!(!dir.path().join("o").exists());
}

/// A unit, scale or clock slip in the IMU file (accelerometers in g read as m/s², gyros in deg/s
/// read as rad/s, a time in ms read as s) is refused by `filter`, `explain` and `navigate`
/// before the run, with the likely cause named; `--force` runs anyway.
#[test]
fn imu_unit_and_clock_slips_are_refused_with_their_cause() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let o = simulated(d, "name = \"s\"\nimu_rate_hz = 100.0\n[start]\nlat_deg = 30.0\nlon_deg = 110.0\n[[segment]]\nkind = \"rest\"\nduration_s = 30.0\n[gnss]\nrate_hz = 1.0\nsigma_ne = \"0.5 m\"\nsigma_d = \"1 m\"\n");
    let text = std::fs::read_to_string(o.join("imu.txt")).unwrap();
    let rewrite = |name: &str, f: &dyn Fn(&[f64]) -> Vec<f64>| {
        let p = d.join(name);
        rewrite_imu(&text, &p, &|_, v| *v = f(v));
        p
    };
    let g = 9.80665;
    let deg = 180.0 / std::f64::consts::PI;
    let cases = [
        (
            rewrite("g.txt", &|v| {
                vec![v[0], v[1], v[2], v[3], v[4] / g, v[5] / g, v[6] / g]
            }),
            "look like g read as m/s²",
        ),
        (
            rewrite("ms.txt", &|v| {
                vec![v[0] * 1000.0, v[1], v[2], v[3], v[4], v[5], v[6]]
            }),
            "time in ms read as s",
        ),
        (
            rewrite("dps.txt", &|v| {
                vec![v[0], v[1] * deg, v[2] * deg, v[3] * deg, v[4], v[5], v[6]]
            }),
            "deg/s read as rad/s",
        ),
    ];
    let gnss = o.join("gnss.txt");
    for (imu, cause) in &cases {
        let imu_s = imu.to_str().unwrap();
        let filter = |force: bool| {
            let out = d.join("f");
            let mut a = vec![
                "filter",
                "--model",
                "P28",
                "--imu",
                imu_s,
                "--aid",
                gnss.to_str().unwrap(),
                "--init",
                "30,110,0,0,0,0",
                "--out",
                out.to_str().unwrap(),
            ];
            if force {
                a.push("--force");
            }
            run(&a)
        };
        let (ok, err) = filter(false);
        assert!(
            !ok && err.contains(cause) && err.contains("--imu"),
            "{cause}: {err}"
        );
        let (ok, err) = run(&[
            "explain",
            "--model",
            "P28",
            "--imu",
            imu_s,
            "--aid",
            gnss.to_str().unwrap(),
            "--init",
            "30,110,0,0,0,0",
            "--out",
            d.join("e").to_str().unwrap(),
        ]);
        assert!(!ok && err.contains(cause), "explain, {cause}: {err}");
        let (ok, err) = navigate(imu, &d.join("nav.txt"));
        if cause.contains("deg/s") {
            // a MEMS gyro's bias can look the same: navigate (no grade) warns
            assert!(
                ok && err.contains(cause) && err.contains("MEMS"),
                "navigate: {err}"
            );
        } else {
            assert!(!ok && err.contains(cause), "navigate, {cause}: {err}");
        }
        let (ok, err) = filter(true);
        if cause.contains("ms read as s") {
            // a median interval of 10 s is no strapdown IMU's: refused whatever --force says
            assert!(!ok && err.contains("not a strapdown IMU's"), "{err}");
        } else {
            assert!(
                ok && err.contains("(--force given)"),
                "{cause}, --force: {err}"
            );
        }
    }
    // with --grade mems the gyro one is a warning
    let (ok, err) = run(&[
        "filter",
        "--model",
        "P28",
        "--grade",
        "mems",
        "--imu",
        cases[2].0.to_str().unwrap(),
        "--aid",
        gnss.to_str().unwrap(),
        "--init",
        "30,110,0,0,0,0",
        "--out",
        d.join("f2").to_str().unwrap(),
    ]);
    assert!(ok && err.contains("--grade mems given"), "{err}");
    // the data as written run without a word about units
    let (ok, err) = navigate(&o.join("imu.txt"), &d.join("nav.txt"));
    assert!(ok && !err.contains("warning"), "{err}");
}

/// A slip the first 10 s cannot show by the IMU alone (they are disturbed, not at rest) is
/// found there where GNSS fixes stand through them, else where the data first come to rest as
/// the GNSS speeds confirm (filter, explain), and a specific force no
/// vehicle averages anywhere in the run: the run stops naming the stretch; navigate, without
/// GNSS, judges only the specific force there; the disturbed data in the right units run.
#[test]
fn imu_slips_after_the_first_seconds_are_found_where_the_data_show_them() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let o = simulated(d, "name = \"s\"\nimu_rate_hz = 100.0\n[start]\nlat_deg = 30.0\nlon_deg = 110.0\n[[segment]]\nkind = \"rest\"\nduration_s = 40.0\n[gnss]\nrate_hz = 1.0\nsigma_ne = \"0.5 m\"\nsigma_d = \"1 m\"\n");
    let text = std::fs::read_to_string(o.join("imu.txt")).unwrap();
    // the first 20 s shaken (±2 m/s² alternating on x: the mean stays, the spread is 2 m/s²)
    let rewrite = |name: &str, f: &dyn Fn(&mut [f64])| {
        let p = d.join(name);
        rewrite_imu(&text, &p, &|k, v| {
            if v[0] < 20.0 {
                v[4] += if k % 2 == 0 { 0.02 } else { -0.02 };
            }
            f(v)
        });
        p
    };
    let deg = 180.0 / std::f64::consts::PI;
    let shaken = rewrite("shaken.txt", &|_| {});
    let dps = rewrite("dps.txt", &|v| v[1..4].iter_mut().for_each(|x| *x *= deg));
    let g_late = rewrite("g_late.txt", &|v| {
        if v[0] > 15.0 {
            v[4..7].iter_mut().for_each(|x| *x /= 9.80665);
        }
    });
    let gnss = o.join("gnss.txt");
    let filter = |imu: &Path, out: &str| {
        run(&[
            "filter",
            "--model",
            "P13",
            "--imu",
            imu.to_str().unwrap(),
            "--aid",
            gnss.to_str().unwrap(),
            "--init",
            "30,110,0,0,0,0",
            "--out",
            d.join(out).to_str().unwrap(),
        ])
    };
    let (ok, err) = filter(&shaken, "f0");
    assert!(ok && !err.contains("warning"), "{err}");
    let (ok, err) = navigate(&shaken, &d.join("nav0.txt"));
    assert!(ok && !err.contains("warning"), "{err}");

    // GNSS fixes that stand through the shaken first seconds say they are at rest: the mean
    // rate is judged there (57.3× Earth rate)
    let (ok, err) = filter(&dps, "f1");
    assert!(
        !ok && err.contains("deg/s read as rad/s")
            && err.contains("in the first 10 s")
            && err.contains("dps.txt"),
        "{err}"
    );
    assert!(!d.join("f1").exists(), "a refused run left its output");
    // without fixes in the first 10 s nothing says they are at rest: the slip is found where
    // the data come to rest as the fixes confirm
    let late_fixes = d.join("gnss_from_10s.txt");
    std::fs::write(
        &late_fixes,
        std::fs::read_to_string(&gnss)
            .unwrap()
            .lines()
            .filter(|l| {
                l.starts_with('#') || l.split(' ').next().unwrap().parse::<f64>().unwrap() > 10.5
            })
            .map(|l| format!("{l}\n"))
            .collect::<String>(),
    )
    .unwrap();
    let (ok, err) = run(&[
        "filter",
        "--model",
        "P13",
        "--imu",
        dps.to_str().unwrap(),
        "--aid",
        late_fixes.to_str().unwrap(),
        "--init",
        "30,110,0,0,0,0",
        "--out",
        d.join("f1b").to_str().unwrap(),
    ]);
    assert!(
        !ok && err.contains("deg/s read as rad/s")
            && err.contains("after the first 10 s")
            && err.contains("dps.txt"),
        "{err}"
    );
    // navigate has no GNSS to confirm that a later still stretch is at rest (a steady turn on
    // a smooth curve looks the same to the IMU): its gyros are not judged there
    let (ok, err) = navigate(&dps, &d.join("nav1.txt"));
    assert!(ok && !err.contains("deg/s read as rad/s"), "{err}");

    let (ok, err) = filter(&g_late, "f2");
    assert!(
        !ok && err.contains("look like g read as m/s²") && err.contains("after the first 10 s"),
        "{err}"
    );
    let (ok, err) = navigate(&g_late, &d.join("nav2.txt"));
    assert!(!ok && err.contains("g read as m/s²"), "{err}");
    assert!(
        !d.join("nav2.txt").exists(),
        "a refused navigate wrote its output"
    );
}

/// `--zupt` and `--static-aid` say the whole run is at rest: on data that drive off they are
/// refused where the IMU first moves (the filter had run with NIS of 1e5 and blamed the model);
/// on data at rest they run.
#[test]
fn a_claim_of_rest_on_data_that_move_is_refused_where_they_move() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let o = simulated(d, "name = \"s\"\nimu_rate_hz = 100.0\n[start]\nlat_deg = 30.0\nlon_deg = 110.0\n[[segment]]\nkind = \"rest\"\nduration_s = 25.0\n\
         [[segment]]\nkind = \"accelerate\"\nduration_s = 20.0\naccel_mps2 = 1.0\n[gnss]\nrate_hz = 1.0\nsigma_ne = \"0.5 m\"\nsigma_d = \"1 m\"\n");
    let imu = o.join("imu.txt");
    let filter = |extra: &[&str], out: &str| {
        let out = d.join(out);
        let mut a = vec![
            "filter",
            "--model",
            "P13",
            "--imu",
            imu.to_str().unwrap(),
            "--init",
            "30,110,0,0,0,0",
            "--out",
            out.to_str().unwrap(),
        ];
        a.extend_from_slice(extra);
        run(&a)
    };
    let gnss = o.join("gnss.txt");
    let (ok, err) = filter(
        &[
            "--aid",
            gnss.to_str().unwrap(),
            "--aid-use",
            "pos",
            "--zupt",
            "0.01",
        ],
        "z",
    );
    // (the fixes beside --zupt move: their speed says it first, at 28 s)
    assert!(
        !ok && err.contains("--zupt says the vehicle does not move")
            && err.contains("the aiding fixes move")
            && err.contains("t = 28.000 s"),
        "{err}"
    );
    let (ok, err) = filter(&["--static-aid", "30,110,0"], "s");
    assert!(
        !ok && err.contains("--static-aid says the vehicle does not move"),
        "{err}"
    );
    // the GNSS fixes alone run
    let (ok, err) = filter(&["--aid", gnss.to_str().unwrap()], "g");
    assert!(ok, "{err}");
}

/// Gyros in deg/s read as rad/s on a unit with a bias (|ω| at rest 33× Earth rate, outside the
/// 57.3× band): a navigation- or tactical-grade run is refused with the slip named (also with a
/// tight gyro-bias prior given), a MEMS one runs (such a bias is a MEMS gyro's), as does one
/// whose prior allows it, and imu-check says which grade the rate allows.
#[test]
fn a_gyro_rate_at_rest_beyond_the_grade_names_the_unit_slip() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let o = simulated(d, "name = \"s\"\nimu_rate_hz = 100.0\n[start]\nlat_deg = 40.0\nlon_deg = -105.0\neuler_deg = [0.0, 0.0, 30.0]\n\
         [[segment]]\nkind = \"rest\"\nduration_s = 30.0\n[errors]\neps_z = \"10 deg/h\"\n[gnss]\nrate_hz = 1.0\nsigma_ne = \"0.5 m\"\nsigma_d = \"1 m\"\n");
    let deg = 180.0 / std::f64::consts::PI;
    let text = std::fs::read_to_string(o.join("imu.txt")).unwrap();
    let imu = d.join("dps.txt");
    rewrite_imu(&text, &imu, &|_, v| {
        v[1..4].iter_mut().for_each(|x| *x *= deg)
    });
    let gnss = o.join("gnss.txt");
    let filter_with = |grade: Option<&str>, out: &str, extra: &[&str]| {
        let out = d.join(out);
        let mut a = vec![
            "filter",
            "--model",
            "P13",
            "--imu",
            imu.to_str().unwrap(),
            "--aid",
            gnss.to_str().unwrap(),
            "--init",
            "40,-105,0,0,0,30",
            "--out",
            out.to_str().unwrap(),
        ];
        if let Some(g) = grade {
            a.extend_from_slice(&["--grade", g]);
        }
        a.extend_from_slice(extra);
        run(&a)
    };
    let filter = |grade: Option<&str>, out: &str| filter_with(grade, out, &[]);
    for grade in [None, Some("tactical")] {
        let (ok, err) = filter(grade, "f");
        assert!(
            !ok && err.contains("deg/s read as rad/s") && err.contains("a bias of at least"),
            "{grade:?}: {err}"
        );
    }
    let (ok, err) = filter(Some("mems"), "m");
    assert!(ok, "{err}");
    // a gyro-bias prior says what bias is plausible on its axis: a tight one keeps the refusal
    // (it had turned the check off), so does a wide one on one axis only (it had lifted the
    // limit for all three), a MEMS-sized one on every axis (0.5 deg/s) allows the 573 deg/h
    for (prior, out) in [("eps_z=10 deg/h", "p1"), ("eps_x=200 deg/h", "p3")] {
        let (ok, err) = filter_with(None, out, &["--prior", prior]);
        assert!(!ok && err.contains("deg/s read as rad/s"), "{prior}: {err}");
    }
    let (ok, err) = filter_with(None, "p2", &["--prior", "eps_*=0.5 deg/s"]);
    assert!(ok, "{err}");
    let (ok, said, err) =
        common::sinsmodel(&["imu-check", "--imu", imu.to_str().unwrap(), "--lat", "40"]);
    assert!(ok, "{err}");
    assert!(
        said.contains("a MEMS gyro's") && said.contains("deg/s read as rad/s likely"),
        "{said}"
    );
}

/// A run that starts moving and then turns steadily (6 deg/s, or 0.1 deg/s on a smooth curve)
/// looks at rest to the IMU's specific force: its gyros must not be judged against Earth rate
/// there (they had been refused as "1435× Earth rate" and as a bias beyond the grade). Runs.
#[test]
fn a_steady_turn_on_a_moving_start_is_not_taken_for_rest() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    for (name, rate) in [("circ", 6.0), ("curve", 0.1)] {
        let sc = d.join(format!("{name}.toml"));
        std::fs::write(
            &sc,
            format!(
                "name = \"{name}\"\nimu_rate_hz = 100.0\nseed = 5\n[start]\nlat_deg = 40.0\nlon_deg = -105.0\nh_m = 1600.0\n\
                 euler_deg = [0.0, 0.0, 10.0]\nspeed_mps = 20.0\n[[segment]]\nkind = \"turn\"\nduration_s = 50.0\n\
                 yaw_rate_deg_s = {rate}\n[gnss]\nrate_hz = 1.0\nsigma_ne = \"0.05 m\"\nsigma_d = \"0.1 m\"\n"
            ),
        )
        .unwrap();
        let o = d.join(name);
        let (ok, err) = run(&[
            "simulate",
            sc.to_str().unwrap(),
            "--out",
            o.to_str().unwrap(),
        ]);
        assert!(ok, "{err}");
        let (ok, err) = run(&[
            "filter",
            "--model",
            "P13",
            "--imu",
            o.join("imu.txt").to_str().unwrap(),
            "--aid",
            o.join("gnss.txt").to_str().unwrap(),
            "--truth",
            o.join("truth.txt").to_str().unwrap(),
            "--out",
            d.join(format!("f-{name}")).to_str().unwrap(),
        ]);
        assert!(
            ok && !err.contains("Earth rate") && !err.contains("warning"),
            "{name}: {err}"
        );
    }
}
