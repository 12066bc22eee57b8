//! A body-frame velocity reference (odometer, DVL) end to end: the simulator writes it with a
//! mounting misalignment, the filter estimates the mounting, explain names it (and nothing of
//! the sensor), and bad reference input is refused with the likely slip.

mod common;
use common::sinsmodel;

use std::path::{Path, PathBuf};

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("sinsmodel-reference-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The shipped drive with a reference mounted (0.5°, 1.5°), `edit` applied to its text,
/// simulated into `dir`/sim; returns that directory.
fn simulated(dir: &Path, edit: impl Fn(String) -> String) -> PathBuf {
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/drive_reference.toml"),
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
    assert!(stderr.contains("body-velocity reference rows"), "{stderr}");
    sim
}

/// explain on the simulation in `sim` (baseline P13+vertical, tactical grade) with `extra`
/// options: its JSON.
fn explained(sim: &Path, out: &Path, extra: &[&str]) -> serde_json::Value {
    let p = |f: &str| sim.join(f).to_str().unwrap().to_string();
    let (imu, aid, reference, truth) = (
        p("imu.txt"),
        p("gnss.txt"),
        p("reference.txt"),
        p("truth.txt"),
    );
    let mut args = vec![
        "explain",
        "--model",
        "P13+vertical",
        "--grade",
        "tactical",
        "--imu",
        &imu,
        "--aid",
        &aid,
        "--body-velocity",
        &reference,
        "--truth",
        &truth,
        "--out",
    ];
    let out_s = out.to_str().unwrap();
    args.push(out_s);
    args.extend(extra);
    let (ok, _, stderr) = sinsmodel(&args);
    assert!(ok, "{stderr}");
    serde_json::from_str(&std::fs::read_to_string(out.join("explain.json")).unwrap()).unwrap()
}

fn is_cause(f: &serde_json::Value) -> bool {
    f["stand_in"].is_null() && f["not_attributed"].is_null()
}

/// The finding of `term` in explain's JSON `j`, named as a cause (else the test fails with the
/// summary), and its estimate (display unit).
fn named_cause(j: &serde_json::Value, term: &str) -> f64 {
    let f = j["findings"]
        .as_array()
        .unwrap()
        .iter()
        .find(|f| f["term"] == term)
        .unwrap_or_else(|| panic!("{term} not among the findings: {:#?}", j["summary"]));
    assert!(is_cause(f), "{term}: {}", f["words"]);
    f["estimate"].as_f64().unwrap()
}

/// No finding in `j` is a cause except those of `allowed` (`what`: the case, for the message).
fn no_other_cause(j: &serde_json::Value, allowed: &[&str], what: &str) {
    for f in j["findings"].as_array().unwrap() {
        let term = f["term"].as_str().unwrap();
        assert!(
            allowed.contains(&term) || !is_cause(f),
            "{what}: named {}",
            f["words"]
        );
    }
}

/// The mounting's pitch and yaw are named as causes within 10 % of the truth, with kind
/// `measurement`; no sensor term or noise level is named as a cause.
#[test]
fn explain_names_a_reference_mounting_and_no_sensor_term() {
    let dir = tmp("named");
    let sim = simulated(&dir, |t| t);
    let j = explained(&sim, &dir.join("explain"), &[]);
    for (name, truth) in [("mount_y", 0.5), ("mount_z", 1.5)] {
        let est = named_cause(&j, name);
        assert!(
            (est - truth).abs() < 0.1 * truth,
            "{name} = {est} deg for {truth}"
        );
    }
    for f in j["findings"].as_array().unwrap() {
        if f["term"].as_str().unwrap().starts_with("mount_") {
            assert_eq!(f["kind"], "measurement");
            assert_eq!(f["unit"], "deg");
        }
    }
    no_other_cause(&j, &["mount_y", "mount_z"], "beside the mounting");
}

/// The reference's rows stamped 0.1 s and 0.3 s late (a latency, as odometers on a vehicle bus
/// have): its time offset is named within 10 %, beside the mounting, and no sensor term, GNSS
/// term or noise level takes it (an accelerometer delay acts alike on the reference's rows; at
/// 0.2 s and beyond, groups holding under 1 % of the information used to demote it, and a GNSS
/// noise level was named in its place).
#[test]
fn explain_names_a_late_reference() {
    let dir = tmp("late");
    let sim = simulated(&dir, |t| t);
    for late_s in [0.1, 0.3] {
        let late = dir.join(format!("late_{late_s}.txt"));
        let text: String = std::fs::read_to_string(sim.join("reference.txt"))
            .unwrap()
            .lines()
            .map(|l| match l.split_once(' ') {
                Some((t, rest)) if !l.starts_with('#') => {
                    format!("{:.4} {rest}\n", t.parse::<f64>().unwrap() + late_s)
                }
                _ => format!("{l}\n"),
            })
            .collect();
        std::fs::write(&late, text).unwrap();
        let p = |f: &str| sim.join(f).to_str().unwrap().to_string();
        let out = dir.join(format!("explain_{late_s}"));
        let (ok, _, stderr) = sinsmodel(&[
            "explain",
            "--model",
            "P13+vertical",
            "--grade",
            "tactical",
            "--imu",
            &p("imu.txt"),
            "--aid",
            &p("gnss.txt"),
            "--body-velocity",
            late.to_str().unwrap(),
            "--truth",
            &p("truth.txt"),
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(ok, "{stderr}");
        let j: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("explain.json")).unwrap())
                .unwrap();
        let est = named_cause(&j, "dt_ref");
        let truth = -1e3 * late_s;
        assert!(
            (est - truth).abs() < 0.1 * truth.abs(),
            "dt_ref = {est} ms for {truth}"
        );
        no_other_cause(&j, &["dt_ref", "mount_y", "mount_z"], "beside the latency");
    }
}

/// A wheel odometer reading 2 % fast (`k_ref = 20000 ppm`, a worn or under-inflated tyre's
/// radius): its scale is named within 10 % beside the mounting, and nothing else.
#[test]
fn explain_names_an_odometer_scale() {
    let dir = tmp("scale");
    let sim = simulated(&dir, |t| {
        t.replace(
            "mount_z = \"1.5 deg\"\n",
            "mount_z = \"1.5 deg\"\nk_ref = \"20000 ppm\"\n",
        )
    });
    let j = explained(&sim, &dir.join("explain"), &[]);
    let est = named_cause(&j, "k_ref");
    assert!(
        (est - 20000.0).abs() < 2000.0,
        "k_ref = {est} ppm for 20000"
    );
    no_other_cause(&j, &["k_ref", "mount_y", "mount_z"], "beside the scale");
}

/// The mounting withheld from the candidates: what fits in its place is not named as a cause.
#[test]
fn a_withheld_mounting_gives_no_confident_finding() {
    let dir = tmp("withheld");
    let sim = simulated(&dir, |t| t);
    let j = explained(&sim, &dir.join("explain"), &["--candidates", "!mount_*"]);
    no_other_cause(&j, &[], "a stand-in for the withheld mounting");
}

/// A reference mounted true (no misalignment) and a consistent model: nothing is named.
#[test]
fn a_true_mounting_is_not_named() {
    let dir = tmp("null");
    let sim = simulated(&dir, |t| {
        t.replace("mount_y = \"0.5 deg\"\n", "")
            .replace("mount_z = \"1.5 deg\"\n", "")
    });
    let j = explained(&sim, &dir.join("explain"), &[]);
    no_other_cause(&j, &[], "a null case");
}

/// The mounting given as known (`--mounting 0,0.5,1.5`, degrees) is applied in the residuals:
/// explain then names nothing and says what it applied; an implausible or malformed mounting
/// is refused, as is one without a reference.
#[test]
fn a_known_mounting_is_applied_and_checked() {
    let dir = tmp("known");
    let sim = simulated(&dir, |t| t);
    let j = explained(&sim, &dir.join("explain"), &["--mounting", "0,0.5,1.5"]);
    no_other_cause(&j, &[], "beside the known mounting");
    let summary = j["summary"].to_string();
    assert!(
        summary.contains("mount_y = 0.500 deg") && summary.contains("mount_z = 1.50 deg"),
        "{summary}"
    );
    let p = |f: &str| sim.join(f).to_str().unwrap().to_string();
    for (value, with_reference, expect) in [
        ("0,0.5,30", true, "rotate the reference's velocities"),
        ("0,0.5", true, "got 2 values"),
        ("0,0.5,1.5 rad", true, "beyond"),
        ("0,x,1", true, "expected degrees"),
        ("0,0.5,1.5", false, "needs --body-velocity"),
    ] {
        let mut args = vec![
            "filter".to_string(),
            "--model".into(),
            "P13+vertical".into(),
            "--imu".into(),
            p("imu.txt"),
            "--aid".into(),
            p("gnss.txt"),
            "--truth".into(),
            p("truth.txt"),
            format!("--mounting={value}"),
            "--out".into(),
            dir.join("out").to_str().unwrap().into(),
        ];
        if with_reference {
            args.extend(["--body-velocity".into(), p("reference.txt")]);
        }
        let refs: Vec<&str> = args.iter().map(String::as_str).collect();
        let (ok, _, stderr) = sinsmodel(&refs);
        assert!(!ok, "accepted --mounting {value}");
        assert!(
            stderr.contains("--mounting") && stderr.contains(expect),
            "{value}: {stderr}"
        );
    }
}

/// The filter estimates the mounting given as states (closed loop), and reports the reference's
/// three channels consistent.
#[test]
fn filter_estimates_the_mounting() {
    let dir = tmp("filter");
    let sim = simulated(&dir, |t| t);
    let p = |f: &str| sim.join(f).to_str().unwrap().to_string();
    let out = dir.join("filter");
    let (ok, _, stderr) = sinsmodel(&[
        "filter",
        "--model",
        "P13+vertical+mount_y+mount_z",
        "--grade",
        "tactical",
        "--mode",
        "closed",
        "--imu",
        &p("imu.txt"),
        "--aid",
        &p("gnss.txt"),
        "--body-velocity",
        &p("reference.txt"),
        "--truth",
        &p("truth.txt"),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(ok, "{stderr}");
    for ch in ["vel_bx", "vel_by", "vel_bz"] {
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
    for (name, truth) in [("mount_y", 0.5f64), ("mount_z", 1.5)] {
        let i = header
            .iter()
            .position(|h| *h == format!("{name}[rad]"))
            .unwrap();
        let (est, sig) = (last[i].to_degrees(), last[i + n].to_degrees());
        assert!(
            (est - truth).abs() < 0.1 * truth && (est - truth).abs() < 4.0 * sig,
            "{name} = {est} ± {sig} deg for {truth}"
        );
    }
}

/// Bad reference input: speeds in km/h, a mounting state without a reference, a reference with
/// a model that cannot use it, a scenario mounting without a reference, and a σ in cm/s.
#[test]
fn bad_reference_input_is_refused_with_the_likely_slip() {
    let dir = tmp("bad");
    let sim = simulated(&dir, |t| t);
    let p = |f: &str| sim.join(f).to_str().unwrap().to_string();
    // km/h written as m/s: every velocity × 3.6
    let kmh = dir.join("kmh.txt");
    let text: String = std::fs::read_to_string(sim.join("reference.txt"))
        .unwrap()
        .lines()
        .map(|l| {
            if l.starts_with('#') {
                return format!("{l}\n");
            }
            let v: Vec<f64> = l.split_whitespace().map(|x| x.parse().unwrap()).collect();
            format!(
                "{} {} {} {} {}\n",
                v[0],
                v[1] * 3.6,
                v[2] * 3.6,
                v[3] * 3.6,
                v[4]
            )
        })
        .collect();
    std::fs::write(&kmh, text).unwrap();
    let run = |model: &str, reference: Option<&str>| {
        let mut args = vec![
            "filter".to_string(),
            "--model".into(),
            model.into(),
            "--imu".into(),
            p("imu.txt"),
            "--aid".into(),
            p("gnss.txt"),
            "--truth".into(),
            p("truth.txt"),
            "--out".into(),
            dir.join("out").to_str().unwrap().into(),
        ];
        if let Some(r) = reference {
            args.extend(["--body-velocity".into(), r.to_string()]);
        }
        let refs: Vec<&str> = args.iter().map(String::as_str).collect();
        let (ok, _, stderr) = sinsmodel(&refs);
        assert!(!ok, "accepted: {args:?}");
        stderr
    };
    let e = run("P13+vertical", Some(kmh.to_str().unwrap()));
    assert!(e.contains("3.6×: km/h written as m/s?"), "{e}");
    let e = run("P13+vertical+mount_z", None);
    assert!(
        e.contains("mount_z") && e.contains("--body-velocity"),
        "{e}"
    );
    // explain: a prior on a reference term without a reference would be ignored
    let (ok, _, e) = sinsmodel(&[
        "explain",
        "--model",
        "P13+vertical",
        "--imu",
        &p("imu.txt"),
        "--aid",
        &p("gnss.txt"),
        "--truth",
        &p("truth.txt"),
        "--prior",
        "mount_z=1 deg",
        "--out",
        dir.join("e").to_str().unwrap(),
    ]);
    assert!(
        !ok && e.contains("mount_z") && e.contains("would be ignored"),
        "{e}"
    );
    let e = run("P13", Some(&p("reference.txt")));
    assert!(e.contains("+vertical"), "{e}");
    // rows on another clock (GPS seconds), or in ms: they miss the GNSS fixes' times
    let rows = |f: &dyn Fn(f64) -> f64| -> String {
        std::fs::read_to_string(sim.join("reference.txt"))
            .unwrap()
            .lines()
            .filter(|l| !l.starts_with('#'))
            .map(|l| {
                let (t, rest) = l.split_once(' ').unwrap();
                format!("{} {rest}\n", f(t.parse().unwrap()))
            })
            .collect()
    };
    for (name, shift) in [
        ("gps.txt", &(|t: f64| t + 1.4e9) as &dyn Fn(f64) -> f64),
        ("ms.txt", &|t: f64| t * 1000.0),
    ] {
        let f = dir.join(name);
        std::fs::write(&f, rows(shift)).unwrap();
        let e = run("P13+vertical", Some(f.to_str().unwrap()));
        assert!(
            e.contains("GNSS fixes' times") && e.contains("another clock"),
            "{e}"
        );
    }
    // UTC stamps against GPST (18 s): inside the fixes' times, but its speeds line up with the
    // GNSS's only shifted back
    let f = dir.join("utc.txt");
    std::fs::write(&f, rows(&|t: f64| t + 18.0)).unwrap();
    let e = run("P13+vertical", Some(f.to_str().unwrap()));
    assert!(
        e.contains("when shifted by -18") && e.contains("its clock is not the IMU's"),
        "{e}"
    );
    // the position aiding file given as the reference
    let e = run("P13+vertical", Some(&p("gnss.txt")));
    assert!(e.contains("position aiding file"), "{e}");
    let cms = dir.join("cms.txt");
    std::fs::write(&cms, "0.1 10 0 0 5\n").unwrap();
    let e = run("P13+vertical", Some(cms.to_str().unwrap()));
    assert!(e.contains("cms.txt:1") && e.contains("cm/s"), "{e}");
    // a scenario mounting with nothing to mount
    let scen = dir.join("noref.toml");
    let text = std::fs::read_to_string(dir.join("drive.toml")).unwrap();
    let cut = text.find("[reference]").unwrap();
    std::fs::write(&scen, &text[..cut]).unwrap();
    let (ok, _, stderr) = sinsmodel(&[
        "simulate",
        scen.to_str().unwrap(),
        "--out",
        dir.join("s2").to_str().unwrap(),
    ]);
    assert!(!ok);
    assert!(
        stderr.contains("mount_y") && stderr.contains("[reference]"),
        "{stderr}"
    );
}
