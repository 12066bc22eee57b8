//! An attitude reference (a second INS, an AHRS) end to end: the simulator writes it with a
//! mounting misalignment, the filter estimates the mounting, explain names it (and nothing of
//! the sensor), and bad attitude input is refused with the likely slip.

mod common;
use common::sinsmodel;

use std::path::{Path, PathBuf};

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("sinsmodel-attitude-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The shipped drive with an attitude reference mounted (roll 0.5°, yaw 1.0°), `edit` applied to
/// its text, simulated into `dir`/sim; returns that directory.
fn simulated(dir: &Path, edit: impl Fn(String) -> String) -> PathBuf {
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/drive_attitude.toml"),
    )
    .unwrap();
    let scen = dir.join("drive.toml");
    std::fs::write(&scen, edit(text)).unwrap();
    let sim = dir.join("sim");
    let (ok, _, stderr) = sinsmodel(&[
        "simulate",
        scen.to_str().unwrap(),
        "--out",
        sim.to_str().unwrap(),
    ]);
    assert!(ok, "{stderr}");
    assert!(stderr.contains("attitude reference rows"), "{stderr}");
    sim
}

/// explain on the simulation in `sim` (baseline P13, tactical grade) with the attitude file
/// `attitude` and `extra` options: its JSON.
fn explained(sim: &Path, attitude: &Path, out: &Path, extra: &[&str]) -> serde_json::Value {
    let p = |f: &str| sim.join(f).to_str().unwrap().to_string();
    let (imu, aid, truth) = (p("imu.txt"), p("gnss.txt"), p("truth.txt"));
    let mut args = vec![
        "explain",
        "--model",
        "P13",
        "--grade",
        "tactical",
        "--imu",
        &imu,
        "--aid",
        &aid,
        "--attitude",
        attitude.to_str().unwrap(),
        "--truth",
        &truth,
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend(extra);
    let (ok, _, stderr) = sinsmodel(&args);
    assert!(ok, "{stderr}");
    serde_json::from_str(&std::fs::read_to_string(out.join("explain.json")).unwrap()).unwrap()
}

fn is_cause(f: &serde_json::Value) -> bool {
    f["stand_in"].is_null() && f["not_attributed"].is_null()
}

/// The terms explain names as causes in `j`.
fn causes(j: &serde_json::Value) -> Vec<String> {
    j["findings"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|f| is_cause(f))
        .map(|f| f["term"].as_str().unwrap().to_string())
        .collect()
}

/// The mounting's roll and yaw are named as causes within 10 % of the truth, with kind
/// `measurement` and unit deg; nothing else is named as a cause.
#[test]
fn explain_names_an_attitude_reference_mounting_and_no_sensor_term() {
    let dir = tmp("named");
    let sim = simulated(&dir, |t| t);
    let j = explained(&sim, &sim.join("attitude.txt"), &dir.join("explain"), &[]);
    let mut named = causes(&j);
    named.sort();
    assert_eq!(named, ["att_mount_x", "att_mount_z"], "{:#?}", j["summary"]);
    for (name, truth) in [("att_mount_x", 0.5), ("att_mount_z", 1.0)] {
        let f = j["findings"]
            .as_array()
            .unwrap()
            .iter()
            .find(|f| f["term"] == name)
            .unwrap();
        let est = f["estimate"].as_f64().unwrap();
        assert!(
            (est - truth).abs() < 0.1 * truth,
            "{name} = {est} deg for {truth}"
        );
        assert_eq!(f["kind"], "measurement");
        assert_eq!(f["unit"], "deg");
    }
}

/// The attitude rows restamped 0.2 s late (a second INS's output latency): the time offset
/// dt_att is named, -200 ms within 10 %, beside the mounting, and nothing else (before it was a
/// candidate, an accelerometer white noise 21.5× the stated was named in its place).
#[test]
fn explain_names_a_late_attitude_reference() {
    let dir = tmp("late");
    let sim = simulated(&dir, |t| t);
    let good = std::fs::read_to_string(sim.join("attitude.txt")).unwrap();
    let late = dir.join("late.txt");
    std::fs::write(
        &late,
        rewritten(&good, |mut v| {
            v[0] += 0.2;
            v
        }),
    )
    .unwrap();
    let j = explained(&sim, &late, &dir.join("explain"), &[]);
    let mut named = causes(&j);
    named.sort();
    assert_eq!(
        named,
        ["att_mount_x", "att_mount_z", "dt_att"],
        "{:#?}",
        j["summary"]
    );
    let f = j["findings"]
        .as_array()
        .unwrap()
        .iter()
        .find(|f| f["term"] == "dt_att")
        .unwrap();
    let est = f["estimate"].as_f64().unwrap();
    assert!((est + 200.0).abs() < 20.0, "dt_att = {est} ms for -200");
    assert_eq!(f["unit"], "ms");
}

/// A reference mounted true (no mounting in the scenario) names nothing; with the mounting but
/// its terms withheld from the candidates, no sensor term or noise level is named in its place.
#[test]
fn a_true_or_withheld_mounting_names_no_cause() {
    let dir = tmp("null");
    let sim = simulated(&dir, |t| {
        t.replace("att_mount_x = \"0.5 deg\"\n", "")
            .replace("att_mount_z = \"1.0 deg\"\n", "")
    });
    let j = explained(&sim, &sim.join("attitude.txt"), &dir.join("explain"), &[]);
    assert!(causes(&j).is_empty(), "{:#?}", j["summary"]);
    std::fs::create_dir_all(dir.join("withheld")).unwrap();
    let sim = simulated(&dir.join("withheld"), |t| t);
    let j = explained(
        &sim,
        &sim.join("attitude.txt"),
        &dir.join("explain_withheld"),
        &["--candidates", "!att_mount_*"],
    );
    assert!(causes(&j).is_empty(), "{:#?}", j["summary"]);
}

/// The filter with the mounting in its model estimates it within 10 % and 4 σ of the truth, and
/// the attitude channels are consistent.
#[test]
fn filter_estimates_the_mounting() {
    let dir = tmp("filter");
    let sim = simulated(&dir, |t| t);
    let p = |f: &str| sim.join(f).to_str().unwrap().to_string();
    let out = dir.join("filter");
    let (ok, _, stderr) = sinsmodel(&[
        "filter",
        "--model",
        "P13+att_mount_x+att_mount_y+att_mount_z",
        "--grade",
        "tactical",
        "--imu",
        &p("imu.txt"),
        "--aid",
        &p("gnss.txt"),
        "--attitude",
        &p("attitude.txt"),
        "--truth",
        &p("truth.txt"),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(ok, "{stderr}");
    assert!(
        stderr.contains("closed loop, the default with --attitude"),
        "{stderr}"
    );
    for ch in ["att_n", "att_e", "att_d"] {
        let line = stderr
            .lines()
            .find(|l| l.trim_start().starts_with(ch))
            .unwrap();
        assert!(line.contains("consistent"), "{line}");
    }
    let text = std::fs::read_to_string(out.join("states.txt")).unwrap();
    let header: Vec<&str> = text
        .lines()
        .find(|l| l.starts_with("# t "))
        .unwrap()
        .split_whitespace()
        .skip(1)
        .collect();
    let last: Vec<f64> = text
        .lines()
        .rfind(|l| !l.starts_with('#') && !l.trim().is_empty())
        .unwrap()
        .split_whitespace()
        .map(|v| v.parse().unwrap())
        .collect();
    let n = (header.len() - 1) / 2;
    for (name, truth) in [
        ("att_mount_x", 0.5f64),
        ("att_mount_y", 0.0),
        ("att_mount_z", 1.0),
    ] {
        let i = header
            .iter()
            .position(|h| *h == format!("{name}[rad]"))
            .unwrap();
        let (est, sig) = (last[i].to_degrees(), last[i + n].to_degrees());
        assert!(
            (est - truth).abs() < (0.1 * truth).max(0.02) && (est - truth).abs() < 4.0 * sig,
            "{name} = {est} ± {sig} deg for {truth}"
        );
    }
}

/// `text` (an attitude file) with each data row's columns passed through `f`.
fn rewritten(text: &str, f: impl Fn(Vec<f64>) -> Vec<f64>) -> String {
    text.lines()
        .map(|l| {
            if l.starts_with('#') {
                format!("{l}\n")
            } else {
                let v: Vec<f64> = l.split_whitespace().map(|x| x.parse().unwrap()).collect();
                let w: Vec<String> = f(v).iter().map(|x| format!("{x}")).collect();
                format!("{}\n", w.join(" "))
            }
        })
        .collect()
}

/// Bad attitude input is refused with the file, line or option and the likely slip: angles in
/// radians, an ENU heading, σ in radians, a body-velocity file given here, another clock, and
/// a mounting term or prior without --attitude.
#[test]
fn bad_attitude_input_is_refused_with_the_likely_slip() {
    let dir = tmp("bad");
    let sim = simulated(&dir, |t| t);
    let good = std::fs::read_to_string(sim.join("attitude.txt")).unwrap();
    let p = |f: &str| sim.join(f).to_str().unwrap().to_string();
    let run = |name: &str, text: &str, extra: &[&str]| -> String {
        let file = dir.join(name);
        std::fs::write(&file, text).unwrap();
        let out = dir.join(format!("out_{name}"));
        let mut args = vec![
            "filter".to_string(),
            "--model".into(),
            "P13".into(),
            "--grade".into(),
            "tactical".into(),
            "--imu".into(),
            p("imu.txt"),
            "--aid".into(),
            p("gnss.txt"),
            "--truth".into(),
            p("truth.txt"),
            "--attitude".into(),
            file.to_str().unwrap().into(),
            "--out".into(),
            out.to_str().unwrap().into(),
        ];
        args.extend(extra.iter().map(|s| s.to_string()));
        let a: Vec<&str> = args.iter().map(String::as_str).collect();
        let (ok, _, stderr) = sinsmodel(&a);
        assert!(!ok, "{name} was accepted");
        assert!(!out.exists(), "{name}: an output was written");
        stderr
    };
    let cases: Vec<(&str, String, &str)> = vec![
        (
            "radians.txt",
            rewritten(&good, |mut v| {
                for a in &mut v[1..4] {
                    *a = a.to_radians();
                }
                v
            }),
            "radians written as degrees",
        ),
        (
            "enu.txt",
            rewritten(&good, |mut v| {
                v[3] = (90.0 - v[3]).rem_euclid(360.0);
                v
            }),
            "(ENU)",
        ),
        (
            "sigma_rad.txt",
            rewritten(&good, |mut v| {
                v[4] = 1e-4;
                v
            }),
            "must be in [0.001, 10] deg",
        ),
        (
            "five.txt",
            rewritten(&good, |v| v[..5].to_vec()),
            "layout of a body-velocity reference",
        ),
        (
            "clock.txt",
            rewritten(&good, |mut v| {
                v[0] += 1.0e5;
                v
            }),
            "another clock",
        ),
        (
            "other_run.txt",
            rewritten(&good, |mut v| {
                v[0] += 5.0;
                v
            }),
            "when shifted by -4.95 s",
        ),
    ];
    for (name, text, want) in &cases {
        let stderr = run(name, text, &[]);
        assert!(stderr.contains(want), "{name}: {stderr}");
        assert!(stderr.contains(name), "{name} not named: {stderr}");
    }
    // a mounting term without the reference's file
    let (ok, _, stderr) = sinsmodel(&[
        "filter",
        "--model",
        "P13+att_mount_z",
        "--imu",
        &p("imu.txt"),
        "--aid",
        &p("gnss.txt"),
        "--out",
        dir.join("out_noatt").to_str().unwrap(),
    ]);
    assert!(!ok && stderr.contains("without --attitude"), "{stderr}");
}
