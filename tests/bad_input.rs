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
    // a good file navigates and the output appears whole (no .partial left behind)
    let p = dir.path().join("good.txt");
    std::fs::write(&p, GOOD).unwrap();
    let (ok, err) = navigate(&p, &out);
    assert!(ok, "{err}");
    assert!(out.exists());
    assert!(!dir.path().join("nav.txt.partial").exists());
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
    let imu = sinsmodel::io::imu::read_text(&out.join("imu.txt")).unwrap();
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
