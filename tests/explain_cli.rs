//! `sinsmodel explain` from the command line: the embedded demo end to end (JSON of DESIGN §9,
//! report, figures, extended preset), its refusals of bad input, and both measured data sets.

mod common;
use common::sinsmodel;

use std::path::{Path, PathBuf};

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!(
        "sinsmodel-explain-cli-{}-{name}",
        std::process::id()
    ));
    let _ = std::fs::remove_dir_all(&d);
    d
}

/// The JSON file at `path`; an explanation's findings are checked to record a rule for every
/// reason they are not attributed (and none for a cause).
fn json(path: &Path) -> serde_json::Value {
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    for f in v["findings"].as_array().into_iter().flatten() {
        let rules = f["not_attributed_because"].as_array().unwrap();
        assert_eq!(f["not_attributed"].is_null(), rules.is_empty(), "{f}");
    }
    v
}

#[test]
fn demo_finds_d_and_writes_the_design_contract() {
    let out = tmp("demo");
    let j = tmp("demo.json");
    let (ok, stdout, stderr) = sinsmodel(&[
        "explain",
        "--out",
        out.to_str().unwrap(),
        "--json",
        j.to_str().unwrap(),
    ]);
    assert!(ok, "{stderr}");
    assert!(stdout.contains("report.md"), "{stdout}");
    for f in [
        "report.md",
        "report.html",
        "explain.json",
        "extended.toml",
        "innovations_before.png",
        "innovations_after.png",
        "candidates.png",
        "estimates.png",
        "model_error.png",
    ] {
        assert!(out.join(f).exists(), "{f} missing");
    }
    let v = json(&out.join("explain.json"));
    assert_eq!(v, json(&j), "--json and the directory's copy agree");
    // DESIGN §9 names
    assert!(v["model"].as_array().unwrap().len() >= 28);
    for k in ["loglik", "nis_mean", "whiteness_p"] {
        assert!(v["baseline"][k].is_number(), "baseline.{k}");
        assert!(v["extended"][k].is_number(), "extended.{k}");
    }
    assert!(v["extended"]["terms"].as_array().unwrap().len() > 28);
    for k in ["loglik", "model_error_rms_before", "model_error_rms_after"] {
        assert!(v["gain"][k].is_number(), "gain.{k}");
    }
    let findings = v["findings"].as_array().unwrap();
    let named: Vec<&str> = findings
        .iter()
        .map(|f| f["term"].as_str().unwrap())
        .collect();
    // the hidden d (5e-5 s^2/m = 490 ug/g^2 on every axis), each named or in a named class
    for axis in ["d_x", "d_y", "d_z"] {
        let f = findings
            .iter()
            .find(|f| {
                f["term"] == axis
                    || f["equivalent"]
                        .as_array()
                        .unwrap()
                        .iter()
                        .any(|e| e == axis)
            })
            .unwrap_or_else(|| panic!("{axis} not found; named {named:?}"));
        for k in ["estimate", "sigma", "llr"] {
            assert!(f[k].is_number(), "finding.{k}");
        }
        assert!(f["unit"].is_string());
        if f["term"] == axis {
            let est = f["estimate"].as_f64().unwrap();
            assert!((est - 490.3).abs() < 49.0, "{axis} = {est} ug/g^2");
            // the vibration runs in windows: f² is excited over part of the run, where the
            // term's effect is several times its whole-run mean
            let frac = f["excited_fraction"].as_f64().unwrap();
            let (whole, there) = (
                f["effect"].as_f64().unwrap(),
                f["effect_excited"].as_f64().unwrap(),
            );
            assert!((0.1..0.8).contains(&frac), "{axis}: excited {frac}");
            assert!(
                there > 1.5 * whole && whole > 0.0,
                "{axis}: {there} mg there, {whole} mg in all"
            );
            assert!(
                f["words"].as_str().unwrap().contains("is excited ("),
                "{}",
                f["words"]
            );
        }
    }
    // each d a cause: d_z's value moves 7.9 of its σ beside the kao candidates it takes up, but
    // they fit the data worse, so it stands (until 2026-12-08 d_z was "not attributed" for it)
    for axis in ["d_x", "d_y", "d_z"] {
        let f = findings.iter().find(|f| f["term"] == axis).unwrap();
        assert!(
            f["stand_in"].is_null() && f["not_attributed"].is_null(),
            "{axis} not named a cause: {}",
            f["words"]
        );
        // d_z's z vibration lies in one half: no split tests it, and its words say so
        let untested = f["consistency"]
            .as_array()
            .unwrap()
            .iter()
            .all(|c| c["tested"] == false);
        assert_eq!(
            untested,
            f["words"]
                .as_str()
                .unwrap()
                .contains("Whether it holds across the data is not known"),
            "{axis}: {}",
            f["words"]
        );
    }
    let d_z = findings.iter().find(|f| f["term"] == "d_z").unwrap();
    assert!(
        d_z["words"].as_str().unwrap().contains("is not known"),
        "{}",
        d_z["words"]
    );
    // no cause but the hidden d: the simulation has nothing else (until 2026-12-08 the demo ran
    // open loop about a free navigation 8.4° off, whose neglected ½φ²·g read as an
    // accelerometer delay: "Found: tau_x = -0.105 ± 0.015 ms")
    for f in findings {
        let cause = f["stand_in"].is_null() && f["not_attributed"].is_null();
        let of_d = |t: &serde_json::Value| t.as_str().is_some_and(|t| t.starts_with("d_"));
        let with_d = of_d(&f["term"]) || f["equivalent"].as_array().unwrap().iter().any(of_d);
        assert!(!cause || with_d, "a wrong cause named: {}", f["words"]);
    }
    // the free navigation drifts beyond small angles: explain runs closed loop and says why
    assert_eq!(v["closed_loop_instead"], true, "{}", v["linearisation"]);
    let why = v["linearisation"].as_str().unwrap();
    assert!(
        why.starts_with("Closed loop instead of open loop:"),
        "{why}"
    );
    // (the open-loop pass ends where the drift passes the bound: the rest would be thrown away)
    assert!(why.contains("the open-loop pass stopped"), "{why}");
    assert_eq!(summary_first(&v), why, "the summary opens with it");
    assert!(v["data"]
        .as_str()
        .unwrap()
        .contains("closed loop (its open-loop"));
    // the baseline had an excess to explain: what the extension leaves is said, named or not
    let summary: Vec<&str> = v["summary"]
        .as_array()
        .unwrap()
        .iter()
        .map(|l| l.as_str().unwrap())
        .collect();
    assert!(v["gain"]["misfit_unexplained"].is_number());
    assert!(
        summary.iter().any(|l| l.starts_with("Left unexplained: ")),
        "{summary:#?}"
    );
    // the demo states every noise level as simulated (its heights too, since 2026-12-07: before,
    // they carried no noise under a stated σ and the height σ was named at its search bound):
    // no level is named as a cause
    for f in findings.iter().filter(|f| f["kind"] == "noise") {
        assert!(
            !(f["stand_in"].is_null() && f["not_attributed"].is_null()),
            "a noise level stated right named as a cause: {}",
            f["words"]
        );
    }
    let before = v["gain"]["model_error_rms_before"].as_f64().unwrap();
    let after = v["gain"]["model_error_rms_after"].as_f64().unwrap();
    assert!(after < 0.2 * before, "model error {before} -> {after}");
    let preset = std::fs::read_to_string(out.join("extended.toml")).unwrap();
    assert!(preset.contains("[[preset]]") && preset.contains("base = \"P28\""));
    for axis in ["d_x", "d_y", "d_z"] {
        assert!(
            preset.contains(&format!("\"{axis}\"")),
            "{axis} not in: {preset}"
        );
    }
    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    assert!(html.contains("data:image/png;base64,"), "figures embedded");
    assert!(
        !html.contains("src=\"innovations"),
        "no links to files beside it"
    );
    // a second run replaces the first one's directory (it holds the run marker)
    let (ok, _, stderr) = sinsmodel(&[
        "explain",
        "--out",
        out.to_str().unwrap(),
        "--demo-seconds",
        "120",
    ]);
    assert!(ok, "{stderr}");
    std::fs::remove_dir_all(&out).unwrap();
    std::fs::remove_file(&j).unwrap();
}

/// The first line of explain.json's summary.
fn summary_first(v: &serde_json::Value) -> &str {
    v["summary"][0].as_str().unwrap()
}

/// The demo's filter follows --mode and --step (until 2026-12-08 it ran open loop at 0.01 s
/// whatever they said); an explicit --mode open stays open loop about the drifting navigation,
/// with the warning that names --mode closed.
#[test]
fn the_demo_follows_mode_and_step() {
    // the 120-s demo writing into `out`, with `extra`
    fn demo_in(out: &Path, extra: &[&str]) -> (bool, String, String) {
        let mut args = vec!["explain", "--demo-seconds", "120"];
        args.extend(["--out", out.to_str().unwrap()]);
        args.extend(extra);
        sinsmodel(&args)
    }
    let run = |extra: &[&str], name: &str| {
        let out = tmp(name);
        let (ok, _, stderr) = demo_in(&out, extra);
        assert!(ok, "{stderr}");
        let v = json(&out.join("explain.json"));
        std::fs::remove_dir_all(&out).unwrap();
        v
    };
    let open = run(&["--mode", "open", "--step", "0.02"], "demo-open");
    assert_eq!(open["closed_loop_instead"], false);
    let why = open["linearisation"].as_str().unwrap();
    assert!(why.contains("Run with --mode closed"), "{why}");
    assert!(
        !why.contains("pass stopped"),
        "open loop runs to the end: {why}"
    );
    assert!(
        open["data"]
            .as_str()
            .unwrap()
            .contains("filter step 0.02 s"),
        "{}",
        open["data"]
    );
    let closed = run(&["--mode", "closed"], "demo-closed");
    assert!(
        closed["linearisation"].is_null(),
        "{}",
        closed["linearisation"]
    );
    assert_eq!(closed["closed_loop_instead"], false);
    assert!(closed["data"]
        .as_str()
        .unwrap()
        .contains("closed loop (--mode closed)"));
    for (bad, says) in [
        (["--mode", "sideways"], "--mode `sideways`"),
        (["--step", "10"], "milliseconds written as seconds"),
        (["--init-speed", "5"], "--init-speed belongs to --init auto"),
        (
            ["--step", "1e-7"],
            "shorter than the demo's 2000 Hz IMU sample interval",
        ),
        (["--zupt", "0.01"], "--zupt: a data option; it needs data"),
        // (1.4 samples: until 2026-12-08 it silently ran every 2 samples)
        (
            ["--step", "0.0007"],
            "would step every 2 samples (0.001 s, 43 % longer than asked); give --step 0.0005 or 0.001",
        ),
    ] {
        let out = tmp("demo-bad-mode");
        let (ok, _, stderr) = demo_in(&out, &bad);
        assert!(!ok && stderr.contains(says), "{bad:?}: {stderr}");
        assert!(!out.exists(), "{bad:?}: nothing written");
    }
}

#[test]
fn explain_refuses_bad_input_with_the_reason() {
    let rlg = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../shared/data/psins-lasergyro/lasergyro.imu"
    );
    let init = "34.246048,108.909664,380,0.3878,1.0026,90.603";
    let out = tmp("bad");
    let o = out.to_str().unwrap();
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (
            vec![
                "explain", "--model", "P28", "--imu", rlg, "--init", init, "--out", o,
            ],
            "no aiding",
        ),
        (
            vec![
                "explain",
                "--model",
                "P28",
                "--imu",
                rlg,
                "--static-aid",
                "34.2,108.9,380",
                "--init",
                init,
                "--candidates",
                "d_q",
                "--out",
                o,
            ],
            "unknown term `d_q`",
        ),
        (vec!["explain", "--alpha", "1.5", "--out", o], "--alpha 1.5"),
        (vec!["explain", "--alpha", "NaN", "--out", o], "--alpha NaN"),
        (
            vec![
                "explain",
                "--model",
                "P28",
                "--imu",
                rlg,
                "--static-aid",
                "34.2,108.9",
                "--init",
                init,
                "--out",
                o,
            ],
            "--static-aid takes LAT,LON,H",
        ),
        (
            vec![
                "explain",
                "--model",
                "P28",
                "--imu",
                rlg,
                "--static-aid",
                "34.2,108.9,380",
                "--init",
                init,
                "--prior",
                "epz_x=1 deg/h",
                "--out",
                o,
            ],
            "--prior `epz_x=1 deg/h`",
        ),
        (
            vec!["explain", "--aid", "x.txt", "--out", o],
            "--aid: a data option; it needs data (--imu FILE",
        ),
        (
            vec!["explain", "--imu", "x.txt", "--out", o],
            "--model BASELINE is required",
        ),
        (
            vec!["explain", "--demo-seconds", "inf", "--out", o],
            "--demo-seconds",
        ),
        (
            vec![
                "explain",
                "--model",
                "P28",
                "--imu",
                rlg,
                "--static-aid",
                "34.2,108.9,380",
                "--init",
                "nan,108.909664,380,0.3878,1.0026,90.603",
                "--out",
                o,
            ],
            "--init: lat = NaN",
        ),
        (
            vec![
                "explain",
                "--model",
                "P28",
                "--imu",
                rlg,
                "--static-aid",
                "34.2,108.9,380",
                "--init",
                init,
                "--candidates",
                ",",
                "--out",
                o,
            ],
            "the list is empty",
        ),
        (
            vec![
                "explain",
                "--model",
                "P28",
                "--imu",
                rlg,
                "--static-aid",
                "40.2,108.9,380",
                "--init",
                init,
                "--out",
                o,
            ],
            "km from the first aiding fix",
        ),
        (
            vec![
                "explain",
                "--model",
                "P28",
                "--imu",
                rlg,
                "--static-aid",
                "34.2,108.9,380",
                "--init",
                init,
                "--demo-seconds",
                "100",
                "--out",
                o,
            ],
            "belong to the embedded demo",
        ),
        (
            vec![
                "explain",
                "--model",
                "P31",
                "--imu",
                rlg,
                "--static-aid",
                "34.246048,108.909664,380",
                "--init",
                init,
                "--prior",
                "d_x=1e300 ug/g^2",
                "--out",
                o,
            ],
            "beyond the 1.00e6 ug/g^2 the term can physically have",
        ),
        (
            vec![
                "explain",
                "--model",
                "P13",
                "--imu",
                rlg,
                "--static-aid",
                "34.246048,108.909664,380",
                "--init",
                init,
                "--json",
                o,
                "--out",
                o,
            ],
            "the same path as --out",
        ),
        (
            vec![
                "explain",
                "--model",
                "P28",
                "--imu",
                rlg,
                "--static-aid",
                "34.246048,108.909664,380",
                "--init",
                init,
                "--prior",
                "eps_x=1e300 deg/s",
                "--out",
                o,
            ],
            "beyond the 72000 deg/h the term can physically have",
        ),
    ];
    for (args, expect) in cases {
        let (ok, _, stderr) = sinsmodel(&args);
        assert!(!ok, "{args:?} was accepted");
        assert!(stderr.contains(expect), "{args:?}: {stderr}");
        assert!(!out.exists(), "{args:?} left an output directory");
    }
    // an existing directory that sinsmodel did not write is never replaced
    let foreign = tmp("foreign");
    std::fs::create_dir_all(&foreign).unwrap();
    std::fs::write(foreign.join("notes.txt"), "mine").unwrap();
    let (ok, _, stderr) = sinsmodel(&[
        "explain",
        "--demo-seconds",
        "60",
        "--out",
        foreign.to_str().unwrap(),
    ]);
    assert!(
        !ok && stderr.contains("was not written by sinsmodel"),
        "{stderr}"
    );
    assert_eq!(
        std::fs::read_to_string(foreign.join("notes.txt")).unwrap(),
        "mine"
    );
    std::fs::remove_dir_all(&foreign).unwrap();
}

/// A prior beyond a term's physical limit (the spec's `limit`) is refused as a unit slip, before
/// any pass runs.
#[test]
fn a_prior_beyond_the_spec_limit_is_a_unit_slip() {
    // (and other --prior slips: a unit glued on, no name, no value, a prior that pins the term)
    let out = tmp("limit");
    for (prior, want) in [
        ("tau_x=5 s", "5000 ms is beyond the 100 ms"),
        // the library terms' limits: d in s²/m read for µg/g², a g²-sensitivity in deg/s
        ("d_z=0.5 s^2/m", "4.90e6 ug/g^2 is beyond the 1.00e6 ug/g^2"),
        (
            "kgq_x=100 deg/s/g^2",
            "3.60e5 deg/h/g^2 is beyond the 72000 deg/h/g^2",
        ),
        ("size_*=40 m", "40000 mm is beyond the 1000 mm"),
        // as many digits as it takes to differ from the limit
        ("tau_x=100.001 ms", "100.001 ms is beyond the 100 ms"),
        // so small a prior pins the terms at zero: refused, naming the spec's σ
        (
            "size_*=1e-9 mm",
            "1.00e-9 mm is more than 10^6 times below the spec's prior σ of 10.0 mm",
        ),
        (
            "tau_x=2ms",
            "write a space between the number and its unit (`2 ms`)",
        ),
        ("=2 ms", "the term name is missing before `=`"),
        ("tau_x=", "the quantity is missing after `=`"),
    ] {
        let mut args = rlg_static_explain(&out);
        args.extend(["--prior".to_string(), prior.to_string()]);
        let (ok, _, stderr) = sinsmodel(&args.iter().map(String::as_str).collect::<Vec<_>>());
        assert!(
            !ok && stderr.contains(want) && stderr.contains("--prior"),
            "{stderr}"
        );
    }
    assert!(!out.exists(), "nothing written");
}

/// Candidates the baseline already has are skipped with a note; "not testable" is listed.
#[test]
fn candidates_in_the_baseline_are_skipped_and_untestable_ones_listed() {
    let out = tmp("skip");
    let (ok, _, stderr) = sinsmodel(&[
        "explain",
        "--model",
        "P31",
        "--candidates",
        "d_x,size_*",
        "--demo-seconds",
        "120",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(ok, "{stderr}");
    assert!(
        stderr.contains("d_x is already in the baseline"),
        "{stderr}"
    );
    let v = json(&out.join("explain.json"));
    let nt: Vec<&str> = v["not_testable"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_str().unwrap())
        .collect();
    // no angular motion in the demo: the size effects (on-axis and off-axis) have no information
    assert_eq!(
        nt,
        vec![
            "size_x", "size_y", "size_z", "size_x_y", "size_x_z", "size_y_x", "size_y_z",
            "size_z_x", "size_z_y"
        ]
    );
    assert!(v["findings"].as_array().unwrap().is_empty());
    std::fs::remove_dir_all(&out).unwrap();
}

/// `explain` on the parked laser-gyro log with its static aid (docs/explain.md §1), P28.
fn rlg_static_explain(out: &std::path::Path) -> Vec<String> {
    let rlg = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../shared/data/psins-lasergyro/lasergyro.imu"
    );
    [
        "explain",
        "--model",
        "P28",
        "--imu",
        rlg,
        "--static-aid",
        "34.246048,108.909664,380",
        "--init",
        "34.246048,108.909664,380,0.3878,1.0026,90.603",
        "--out",
        out.to_str().unwrap(),
    ]
    .map(String::from)
    .to_vec()
}

/// explain on the shared MEMS drive as `docs/explain.md` §2 runs it, with `extra` options, into
/// `out`: (success, stdout, stderr).
fn mems_drive_explain(out: &std::path::Path, extra: &[&str]) -> (bool, String, String) {
    mems_drive_explain_in("closed", out, extra)
}

/// [`mems_drive_explain`] in filter mode `mode` (`open` or `closed`).
fn mems_drive_explain_in(
    mode: &str,
    out: &std::path::Path,
    extra: &[&str],
) -> (bool, String, String) {
    let d = concat!(env!("CARGO_MANIFEST_DIR"), "/../shared/data/gnss-imu-drive");
    let (imu, pos) = (format!("{d}/imu_1934.csv"), format!("{d}/gnss_1934_sf.pos"));
    let noise = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/docs/real-data/mems_static_allan.json"
    );
    let mut args = vec!["explain", "--model", "P28+vertical", "--imu", &imu];
    args.extend(["--aid", &pos, "--noise", noise]);
    // the drive's start and priors (option, value pairs), in the mode asked for
    for pair in common::MEMS_DRIVE_START_AND_PRIORS.chunks(2) {
        args.extend([pair[0], if pair[0] == "--mode" { mode } else { pair[1] }]);
    }
    args.extend(extra);
    args.extend(["--out", out.to_str().unwrap()]);
    sinsmodel(&args)
}

/// Open loop on the MEMS drive linearises about a free-inertial solution that tumbles: explain
/// says so (a warning, the report's words and explain.json), naming --mode closed.
#[test]
fn open_loop_about_a_drifting_navigation_is_said() {
    let out = tmp("mems-open");
    let (ok, _, stderr) = mems_drive_explain_in("open", &out, &[]);
    assert!(ok, "{stderr}");
    assert!(
        stderr.contains("Open loop about a drifting navigation")
            && stderr.contains("--mode closed"),
        "{stderr}"
    );
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(report.contains("Open loop about a drifting navigation"));
    let j: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("explain.json")).unwrap()).unwrap();
    assert!(j["linearisation"].as_str().unwrap().contains("deg"));
    std::fs::remove_dir_all(&out).unwrap();
}

/// Both measured sets (docs/explain.md): only what is stable is asserted.
#[test]
fn measured_data() {
    let out = tmp("rlg");
    let mut args = rlg_static_explain(&out);
    args.extend([
        "--noise".to_string(),
        concat!(env!("CARGO_MANIFEST_DIR"), "/docs/real-data/rlg_allan.json").to_string(),
    ]);
    let (ok, _, stderr) = sinsmodel(&args.iter().map(String::as_str).collect::<Vec<_>>());
    assert!(ok, "{stderr}");
    let v = json(&out.join("explain.json"));
    // a channel whose innovations are far too small and correlated gets one line, which says the
    // noise is set too high, not also that the model misses a slow effect
    for ch in ["north velocity", "east velocity", "north position"] {
        let lines: Vec<&str> = stderr
            .lines()
            .filter(|l| l.starts_with("Baseline ") && l.contains(&format!(": {ch} innovations")))
            .collect();
        assert_eq!(lines.len(), 1, "{ch}: {lines:#?}");
        assert!(
            lines[0].contains("set too high") && !lines[0].contains("misses a slow effect"),
            "{}",
            lines[0]
        );
    }
    // the parked car's motion is no error term: nothing is named as a cause (a term fitted to
    // it must be labelled a stand-in)
    for f in v["findings"].as_array().unwrap() {
        assert!(
            !f["stand_in"].is_null() || !f["not_attributed"].is_null(),
            "{} named as a cause: {stderr}",
            f["term"]
        );
    }
    std::fs::remove_dir_all(&out).unwrap();

    let out = tmp("mems");
    let (ok, _, stderr) = mems_drive_explain(&out, &[]);
    assert!(ok, "{stderr}");
    let v = json(&out.join("explain.json"));
    // the MEMS baseline does not explain the drive (NIS well above 1) and whatever explain
    // adds must lower it
    let before = v["baseline"]["nis_mean"].as_f64().unwrap();
    let after = v["extended"]["nis_mean"].as_f64().unwrap();
    assert!(before > 2.0, "baseline NIS {before}");
    assert!(after <= before, "NIS {before} -> {after}");
    assert!(v["gain"]["loglik"].as_f64().unwrap() >= 0.0);
    // the drive's largest misfit is an IMU–GNSS time offset (docs/explain.md §2): fitted as a
    // measurement finding, positive (the fixes describe the trajectory a little later than
    // their stamps), tens of milliseconds to a few tenths of a second, refitted on re-stamped
    // fixes; there the positions alone and the velocities alone want offsets apart, so it is
    // labelled a stand-in saying so, and the lever arm the first-order fit named beside it is
    // gone
    let findings = v["findings"].as_array().unwrap();
    let dt = findings
        .iter()
        .find(|f| f["term"] == "dt_gnss")
        .unwrap_or_else(|| panic!("no time offset fitted: {stderr}"));
    assert_eq!(dt["kind"], "measurement");
    let ms = dt["estimate"].as_f64().unwrap();
    assert!((30.0..300.0).contains(&ms), "dt_gnss {ms} ms");
    assert!(v["restamp"]["passes"].as_array().unwrap().len() >= 2);
    let why = dt["stand_in"].as_str().unwrap_or_else(|| panic!("{dt}"));
    assert!(why.contains("from the position fixes"), "{why}");
    assert!(!findings.iter().any(|f| f["term"] == "lever_x"));
    // dt_gnss's velocity rows take the mechanisation's acceleration, not the closed loop's
    // correction jumps: with them the accelerometer white noise fitted 19.8× the static Allan
    // value (above the raw increments' 5.7×) to take up the misfit; without, 1.9×
    if let Some(vrw) = findings.iter().find(|f| f["term"] == "accel_vrw") {
        let scale = vrw["scale"].as_f64().unwrap();
        assert!(scale < 5.7, "accelerometer white noise {scale}× the stated");
    }
    // the preset explain recommends holds error terms only: no noise level, no stand-in (and
    // with no cause there is no preset)
    let causes = findings
        .iter()
        .any(|f| f["stand_in"].is_null() && f["not_attributed"].is_null());
    match std::fs::read_to_string(out.join("extended.toml")) {
        Ok(preset) => {
            assert!(causes, "a preset without a cause: {preset}");
            let terms_line = preset.lines().find(|l| l.starts_with("terms = ")).unwrap();
            for f in findings {
                if f["kind"] == "noise" || !f["stand_in"].is_null() {
                    let quoted = format!("\"{}\"", f["term"].as_str().unwrap());
                    assert!(!terms_line.contains(&quoted), "{terms_line}");
                }
            }
        }
        Err(_) => assert!(!causes, "no preset beside a cause"),
    }
    // no size effect read as a cause: one that is named is labelled a stand-in, or is a few
    // centimetres at most
    for f in findings {
        if f["term"].as_str().unwrap().starts_with("size_") && f["stand_in"].is_null() {
            let mm = f["estimate"].as_f64().unwrap().abs();
            assert!(mm < 50.0, "{} = {mm} mm read as a cause", f["term"]);
        }
    }
    std::fs::remove_dir_all(&out).unwrap();
}

/// GNSS terms belong to a GNSS receiver: with a static aid they are no candidates, and the
/// known values are checked for units and physics.
#[test]
fn gnss_terms_need_gnss_aiding_and_plausible_known_values() {
    let shared = concat!(env!("CARGO_MANIFEST_DIR"), "/../shared/data");
    let out = tmp("gnss-static");
    let base = rlg_static_explain(&out);
    let run = |extra: [&str; 2]| {
        let mut a: Vec<&str> = base.iter().map(String::as_str).collect();
        a.extend(extra);
        sinsmodel(&a)
    };
    let (ok, _, stderr) = run(["--candidates", "dt_gnss,d_x"]);
    assert!(!ok);
    assert!(
        stderr.contains("dt_gnss is a GNSS term") && stderr.contains("without --aid"),
        "{stderr}"
    );
    let (ok, _, stderr) = run(["--lever-arm", "0.1,0,-1"]);
    assert!(!ok);
    assert!(stderr.contains("need --aid"), "{stderr}");
    let d = format!("{shared}/gnss-imu-drive");
    let drive = |extra: &[&str]| {
        let imu = format!("{d}/imu_1934.csv");
        let pos = format!("{d}/gnss_1934_sf.pos");
        let mut a = vec![
            "filter",
            "--model",
            "P28+vertical",
            "--imu",
            &imu,
            "--aid",
            &pos,
            "--init",
            "40.0966268,-105.1474483,1601.476,-178.192,6.687,-181.028",
            "--out",
            out.to_str().unwrap(),
        ]
        .into_iter()
        .map(String::from)
        .collect::<Vec<_>>();
        a.extend(extra.iter().map(|s| s.to_string()));
        let refs: Vec<&str> = a.iter().map(|s| s.as_str()).collect();
        sinsmodel(&refs)
    };
    for (extra, why) in [
        (&["--gnss-delay", "92"][..], "with its unit"),
        (&["--gnss-delay", "92 s"][..], "ms read as s?"),
        (&["--lever-arm", "0.1,0.2"][..], "got 2 values"),
        (&["--lever-arm", "600,0,0"][..], "mm read as m?"),
        (&["--gnss-delay", "0.179 ms"][..], "below 1 ms"),
        (&["--lever-arm", "NaN,0,0"][..], "is not a number"),
        (
            &["--lever-arm", "0,0,1e400"][..],
            "beyond the largest number",
        ),
        (&["--lever-arm", "0.3 furlongs,0,0"][..], "expected metres"),
    ] {
        let (ok, _, stderr) = drive(extra);
        assert!(!ok, "{extra:?} accepted");
        assert!(stderr.contains(why), "{extra:?}: {stderr}");
    }
    let _ = std::fs::remove_dir_all(&out);
}

/// On the shared drive with the time offset withheld (`--candidates 'lever_*'`), the antenna
/// lever arm that takes up speed × offset in the turns is not presented as a cause: a withheld
/// GNSS term tried in its place (dt_gnss) fits the data at least as well, and the finding says
/// so with the offset.
#[test]
fn a_lever_arm_standing_in_for_a_withheld_time_offset_says_so() {
    let out = tmp("mems-lever");
    let (ok, _, stderr) = mems_drive_explain(&out, &["--candidates", "lever_*"]);
    assert!(ok, "{stderr}");
    let v = json(&out.join("explain.json"));
    let findings = v["findings"].as_array().unwrap();
    let lever_x = findings
        .iter()
        .find(|f| f["term"] == "lever_x")
        .unwrap_or_else(|| panic!("lever_x not fitted: {stderr}"));
    let why = lever_x["stand_in"].as_str().unwrap_or_else(|| {
        panic!("lever_x presented as a cause: {lever_x}");
    });
    assert!(why.contains("dt_gnss") && why.contains(" ms "), "{why}");
    for f in findings.iter().filter(|f| f["kind"] != "noise") {
        assert!(
            !f["stand_in"].is_null(),
            "{} named as a cause: {stderr}",
            f["term"]
        );
    }
    std::fs::remove_dir_all(&out).unwrap();
}

/// The demo (d·f² on every axis, 60 s) with its cause kept out of the candidates. Under
/// vibration alike on the three axes f_x·f_z rectifies as f_z² does, so a cross-quadratic fits
/// an axis's misfit with a tight σ (`!d_*`), and with those withheld too an asymmetric scale
/// does (`!d_*,!kaq_*`; d explains all it does, and better). Each such fit must name the d of
/// its axis as explaining as well, at about the value hidden (490 µg/g²), and none may be
/// presented as a cause: before, the demo printed a class claim that left d out, and "Found:
/// kas_x = 2639 ppm". With d offered alone (`d_*`), the terms kept out explain what d does only
/// at ten and more of their prior σ, and d is still named, as the selection names a class's
/// most plausible member (helper-52's review).
#[test]
fn a_withheld_term_that_fits_as_well_is_named_and_nothing_is_claimed() {
    let run = |cands: &str, name: &str| -> (serde_json::Value, String) {
        let out = tmp(name);
        let (ok, _, stderr) = sinsmodel(&[
            "explain",
            "--demo-seconds",
            "60",
            "--candidates",
            cands,
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(ok, "{stderr}");
        let report = std::fs::read_to_string(out.join("report.md")).unwrap();
        assert!(
            // (the verdict lists every rule that un-named the finding, this one last)
            report.contains("a withheld term fits as well) |") || cands == "d_*",
            "{report}"
        );
        (json(&out.join("explain.json")), stderr)
    };
    for (cands, family) in [("!d_*", "kaq_"), ("!d_*,!kaq_*", "kas_")] {
        let (v, stderr) = run(
            cands,
            &format!("demo-withheld{}", family.trim_end_matches('_')),
        );
        let mut axes = Vec::new();
        for f in v["findings"].as_array().unwrap() {
            let term = f["term"].as_str().unwrap();
            if f["kind"] != "sensor" {
                continue;
            }
            assert!(
                !(f["stand_in"].is_null() && f["not_attributed"].is_null()),
                "{cands}: {term} presented as a cause: {stderr}"
            );
            let Some(alike) = f["withheld_alike"].as_array() else {
                continue;
            };
            // the most plausible term kept out is the d of its axis, near the value hidden
            let axis = &term[term.find('_').unwrap() + 1..][..1];
            let d = &alike[0];
            assert_eq!(
                d["term"],
                format!("d_{axis}").as_str(),
                "{cands}: {term}: {alike:?}"
            );
            let (est, sd) = (
                d["estimate"].as_f64().unwrap(),
                d["sigma"].as_f64().unwrap(),
            );
            assert!(
                (est - 490.0).abs() < 0.1 * 490.0 && (est - 490.0).abs() < 4.0 * sd.max(1.0),
                "{cands}: {term}: d_{axis} would need {est} ± {sd} ug/g^2, hidden 490"
            );
            assert!(because(f, "withheld_term_fits"), "{f}");
            let why = f["not_attributed"].as_str().unwrap();
            assert!(why.contains("not among the candidates"), "{f}");
            if term.starts_with(family) {
                axes.push(axis.to_string());
            }
        }
        // x and y at 60 s (z's cross-quadratic is weak there: ± 23.5 against ± 4.2)
        axes.sort();
        axes.dedup();
        assert!(
            axes.contains(&"x".to_string()) && axes.contains(&"y".to_string()),
            "{cands}: {axes:?}: {stderr}"
        );
        assert!(
            !stderr.contains("Found: accelerometer"),
            "{cands}: {stderr}"
        );
    }
    // d_z alone kept out (helper-53): the z cross-quadratic, 23σ in the extended filter, was
    // "Found" while the pass that tries d_z in its place scaled its test down by the misfit it
    // explains (that pass's own mean NIS); the rounds' model's is used now
    let (v, stderr) = run("!d_z", "demo-withheld-dz");
    let z: Vec<&serde_json::Value> = v["findings"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|f| f["kind"] == "sensor" && f["term"].as_str().unwrap().starts_with("kaq_z"))
        .collect();
    assert!(!z.is_empty(), "no z cross-quadratic fitted: {stderr}");
    for f in z {
        assert!(because(f, "withheld_term_fits"), "{f}");
        assert_eq!(f["withheld_alike"][0]["term"], "d_z", "{f}");
    }
    let (v, stderr) = run("d_*", "demo-d-offered");
    for axis in ["x", "y"] {
        let f = v["findings"]
            .as_array()
            .unwrap()
            .iter()
            .find(|f| f["term"] == format!("d_{axis}").as_str())
            .unwrap_or_else(|| panic!("d_{axis} not fitted: {stderr}"));
        assert!(
            f["stand_in"].is_null() && f["not_attributed"].is_null(),
            "d_{axis} not named: {f}"
        );
        // the terms kept out that explain it need ten and more of their prior σ
        let alike = f["withheld_alike"].as_array().unwrap();
        assert!(
            alike
                .iter()
                .all(|a| a["prior_sigmas"].as_f64().unwrap() > 9.0),
            "{alike:?}"
        );
        assert_eq!(f["not_attributed_because"], serde_json::json!([]), "{f}");
    }
}

/// The turntable of the README (`scenarios/turntable.toml`: a 40-mm off-axis lever arm size_x_y
/// and a common 2-ms delay) with size_x_y and the cross-quadratics kept out: the rounds name
/// size_y and d_y, each of which size_x_y explains together with the other; one term kept out
/// that explains two findings is the simpler answer (helper-53: both were "Found", size_y =
/// −37 mm and d_y = −1082 µg/g², with size_y = d_y = 0 in the scenario). The report's words
/// give that reason, not a class that cannot be told apart. And with one delay kept out, a
/// delay whose value leans on it is not named.
#[test]
fn one_term_kept_out_that_explains_two_findings_unnames_both() {
    let dir = tmp("turntable-withheld");
    let sim = dir.join("sim");
    let (ok, _, stderr) = sinsmodel(&[
        "simulate",
        "scenarios/turntable.toml",
        "--out",
        sim.to_str().unwrap(),
    ]);
    assert!(ok, "{stderr}");
    let (imu, truth) = (sim.join("imu.txt"), sim.join("truth.txt"));
    // explain on the turntable with the candidates `cands`, into `name`
    let explained = |cands: &str, name: &str| -> (PathBuf, String) {
        let out = dir.join(name);
        let (ok, _, stderr) = sinsmodel(&[
            "explain",
            "--model",
            "P28",
            "--imu",
            imu.to_str().unwrap(),
            "--static-aid",
            "30,114,20",
            "--truth",
            truth.to_str().unwrap(),
            "--candidates",
            cands,
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(ok, "{stderr}");
        (out, stderr)
    };
    let (out, stderr) = explained("!size_x_y,!kaq_*", "explain");
    let v = json(&out.join("explain.json"));
    let mut pointed = 0;
    for f in v["findings"].as_array().unwrap() {
        let term = f["term"].as_str().unwrap();
        if f["kind"] != "sensor" || term.starts_with("tau_") {
            continue;
        }
        // nothing but the delays is in the scenario
        assert!(
            !(f["stand_in"].is_null() && f["not_attributed"].is_null()),
            "{term} presented as a cause: {stderr}"
        );
        if let Some(w) = f["withheld_alike"]
            .as_array()
            .and_then(|a| a.iter().find(|w| w["term"] == "size_x_y"))
        {
            let est = w["estimate"].as_f64().unwrap();
            assert!(
                (est - 40.0).abs() < 8.0,
                "{term}: size_x_y would need {est} mm"
            );
            pointed += 1;
        }
    }
    assert!(pointed >= 2, "{stderr}");
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(
        report.contains("a term the candidates keep out explains it as well")
            && report.contains("fitted, not attributed (a withheld term fits as well)"),
        "{report}"
    );
    // one delay kept out (helper-54): tau_y took up tau_z's part, "Found: tau_y = 3.81 ±
    // 0.205 ms" for 2 hidden; fitted beside tau_z its value moves by more than 3σ
    let (out, stderr) = explained("!tau_z", "explain-tau");
    let v = json(&out.join("explain.json"));
    for f in v["findings"].as_array().unwrap() {
        let (term, est) = (f["term"].as_str().unwrap(), f["estimate"].as_f64().unwrap());
        if term.starts_with("tau_") && f["stand_in"].is_null() && f["not_attributed"].is_null() {
            assert!(
                (est - 2.0).abs() < 3.0 * f["sigma"].as_f64().unwrap(),
                "{f}"
            );
        }
    }
    let tau_y = v["findings"]
        .as_array()
        .unwrap()
        .iter()
        .find(|f| f["term"] == "tau_y")
        .unwrap_or_else(|| panic!("tau_y not fitted: {stderr}"));
    let why = tau_y["not_attributed"].as_str().unwrap_or("");
    assert!(why.contains("leans on tau_z"), "{tau_y}");
    assert!(because(tau_y, "leans_on_withheld_term"), "{tau_y}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The demo with its cause (d·f²) withheld from the candidates: the white-noise scales that
/// take up the vibration's misfit (hundreds of times the stated) are fitted but not named as a
/// cause (the accelerometer's is beyond what a grade mis-states, and tested quiet against
/// vibrating; until 2026-12-07, with the demo's heights noise-free, that split failed too), and
/// the summary says the causes found leave most of the misfit unexplained.
#[test]
fn demo_with_its_cause_withheld_names_no_noise_level() {
    let out = tmp("demo-withheld");
    let (ok, _, stderr) = sinsmodel(&[
        "explain",
        "--demo-seconds",
        "60",
        "--candidates",
        "lever_*",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(ok, "{stderr}");
    let v = json(&out.join("explain.json"));
    let findings = v["findings"].as_array().unwrap();
    let vrw = findings
        .iter()
        .find(|f| f["term"] == "accel_vrw")
        .unwrap_or_else(|| panic!("no accelerometer noise fitted: {stderr}"));
    assert!(vrw["scale"].as_f64().unwrap() > 30.0, "{vrw}");
    let why = vrw["stand_in"].as_str().unwrap_or("");
    assert!(why.contains("mis-stated within a grade"), "{vrw}");
    let split = vrw["consistency"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["split"] == "vibration")
        .unwrap_or_else(|| panic!("no vibration split: {vrw}"));
    assert_eq!(split["tested"], true, "{vrw}");
    for f in findings {
        let sensor_noise =
            f["kind"] == "noise" && !f["term"].as_str().unwrap().starts_with("sigma_");
        assert!(
            !(sensor_noise && f["stand_in"].is_null()),
            "{} named as a cause: {stderr}",
            f["term"]
        );
    }
    assert!(
        !stderr.contains("Found: the data show a gyro")
            && !stderr.contains("Found: the data show an accel"),
        "{stderr}"
    );
    let left = stderr
        .lines()
        .find(|l| l.starts_with("Left unexplained"))
        .unwrap_or_else(|| panic!("{stderr}"));
    let pct: f64 = left
        .split("Left unexplained by the causes found: ")
        .nth(1)
        .and_then(|t| t.split(' ').next())
        .and_then(|t| t.parse().ok())
        .unwrap_or_else(|| panic!("{left}"));
    assert!(pct > 50.0, "{left}");
    let by_causes = v["gain"]["misfit_unexplained_by_causes"].as_f64().unwrap();
    assert!((by_causes * 100.0 - pct).abs() < 0.1, "{by_causes} {left}");
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    // (until 2026-12-07 the demo's noise-free heights put the height σ at its search bound,
    // which the glance table wrote as "(a bound, no estimate)"; the words of a bound are tested
    // in explain::noise)
    assert!(
        report.contains("Left unexplained by the causes found:"),
        "the report's glance table"
    );
    std::fs::remove_dir_all(&out).unwrap();
}

/// A common accelerometer delay (2 ms on x, y and z) on a nine-rotation turntable: the rounds
/// fit tau_z at twice its size beside a cross-quadratic stand-in, and once the stand-in is
/// dropped tau_y is significant beside it. No delay may then be presented as a cause with a
/// value off the truth; tau_z says why it is not named and how to fit them together.
#[test]
fn a_common_accelerometer_delay_is_not_named_at_twice_its_size() {
    let (dir, out, stderr) = explained_turntable("common-delay", &NINE_MIXED, &[]);
    no_delay_named_off_its_value(&out, &stderr);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The nine rotations of the turntable the common-delay tests use (axis, degrees).
const NINE_MIXED: [(&str, i32); 9] = [
    ("x", 90),
    ("x", 90),
    ("y", 90),
    ("y", 90),
    ("z", 90),
    ("z", 90),
    ("x", -90),
    ("y", -90),
    ("z", -90),
];

/// A common accelerometer delay (2 ms on x, y and z) on nine rotations about x four times, y
/// four times, then z (the first nine of `scenarios/turntable.toml`): no single delay can be
/// told from the common one there, and tau_z alone fits about twice its value with no stand-in
/// beside it (3.80 ± 0.31 ms "Found" on three seeds in a review). Fitted beside the delays it
/// takes up, it moves by more than 3 of its σ: not named.
#[test]
fn a_common_delay_the_rotations_cannot_separate_is_not_named() {
    let seq = [
        ("x", 90),
        ("x", 90),
        ("x", 90),
        ("x", 90),
        ("y", 90),
        ("y", 90),
        ("y", 90),
        ("y", 90),
        ("z", 90),
    ];
    let (dir, out, stderr) = explained_turntable("delay-unseparated", &seq, &[]);
    no_delay_named_off_its_value(&out, &stderr);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// No accelerometer delay in `out`'s explain.json is a cause with a value more than 0.5 ms off
/// the simulated 2 ms; tau_z, fitted off it, says why it is not named.
fn no_delay_named_off_its_value(out: &std::path::Path, stderr: &str) {
    let v = json(&out.join("explain.json"));
    let findings = v["findings"].as_array().unwrap();
    for f in findings {
        let cause = f["stand_in"].is_null() && f["not_attributed"].is_null();
        let term = f["term"].as_str().unwrap();
        if cause && term.starts_with("tau_") {
            let est = f["estimate"].as_f64().unwrap();
            assert!(
                (est - 2.0).abs() < 0.5,
                "{term} = {est} ms named as a cause: {stderr}"
            );
        }
    }
    let tau_z = findings
        .iter()
        .find(|f| f["term"] == "tau_z")
        .unwrap_or_else(|| panic!("tau_z not fitted: {stderr}"));
    if (tau_z["estimate"].as_f64().unwrap() - 2.0).abs() >= 0.5 {
        let why = tau_z["not_attributed"].as_str().unwrap_or("");
        assert!(
            (why.contains("stand-ins") && why.contains("--candidates '!"))
                || why.contains("the data do not fix its value"),
            "{tau_z}"
        );
    }
}

/// explain on a truth whose heading contradicts the run's (--init at yaw 90°, the truth at 0°):
/// a warning on stderr and in the report, as `filter` says it (the model-error figures measure
/// against that truth).
#[test]
fn explain_says_when_the_truth_contradicts_the_run() {
    let (dir, out, stderr) = explained_turntable(
        "truth-heading",
        &NINE_MIXED,
        &["--init", "30,114,20,0,0,90"],
    );
    let warned = |text: &str| {
        text.matches("the truth's attitude differs from the filter's estimate in heading")
            .count()
    };
    let said: Vec<&str> = stderr
        .lines()
        .filter(|l| l.starts_with("warning: --truth"))
        .collect();
    assert_eq!(said.len(), 1, "{stderr}");
    assert!(warned(said[0]) == 1, "{stderr}");
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(warned(&report) >= 1, "not in the report");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The nine-rotation turntable simulated into a fresh directory `name`, and explain (P28,
/// static aid at the start, the truth given, `extra` options) run on it into its `explain`:
/// (the directory, the explain output, explain's stderr); explain must succeed.
fn explained_turntable(
    name: &str,
    seq: &[(&str, i32)],
    extra: &[&str],
) -> (PathBuf, PathBuf, String) {
    let dir = tmp(name);
    let sim = nine_rotation_turntable(&dir, seq);
    let out = dir.join("explain");
    let (imu, truth) = (sim.join("imu.txt"), sim.join("truth.txt"));
    let mut args = vec!["explain", "--model", "P28", "--imu", imu.to_str().unwrap()];
    args.extend([
        "--static-aid",
        "30,114,20",
        "--truth",
        truth.to_str().unwrap(),
    ]);
    args.extend(extra);
    args.extend(["--out", out.to_str().unwrap()]);
    let (ok, _, stderr) = sinsmodel(&args);
    assert!(ok, "{stderr}");
    (dir, out, stderr)
}

/// Simulates, into `dir`/sim, a nine-rotation turntable (90° in 5 s about x, x, y, y, z, z, −x,
/// −y, −z, 20 s at rest after each, 60 s before) at 200 Hz with a common accelerometer delay of
/// 2 ms; returns the simulation's directory.
fn nine_rotation_turntable(dir: &std::path::Path, seq: &[(&str, i32)]) -> PathBuf {
    std::fs::create_dir_all(dir).unwrap();
    let mut scen = String::from(
        "name = \"tt\"\nimu_rate_hz = 200.0\ntruth_rate_hz = 10.0\nseed = 3\n[start]\nlat_deg = 30.0\nlon_deg = 114.0\nh_m = 20.0\neuler_deg = [0.0, 0.0, 0.0]\n[[segment]]\nkind = \"rest\"\nduration_s = 60.0\n",
    );
    for (axis, angle) in seq {
        scen.push_str(&format!(
            "[[segment]]\nkind = \"rotate\"\naxis = \"{axis}\"\nangle_deg = {angle}.0\nduration_s = 5.0\n[[segment]]\nkind = \"rest\"\nduration_s = 20.0\n"
        ));
    }
    scen.push_str("[errors]\ntau_x = \"2 ms\"\ntau_y = \"2 ms\"\ntau_z = \"2 ms\"\n[noise]\narw = \"0.01 deg/sqrt(h)\"\nvrw = \"10 ug/sqrt(Hz)\"\n");
    simulated(dir, &scen)
}

/// `sinsmodel simulate` of the scenario text `scenario`, written to `dir`/scenario.toml, into
/// `dir`/sim; returns the simulation's directory.
fn simulated(dir: &Path, scenario: &str) -> PathBuf {
    let scen_path = dir.join("scenario.toml");
    std::fs::write(&scen_path, scenario).unwrap();
    let sim = dir.join("sim");
    let (ok, _, stderr) = sinsmodel(&[
        "simulate",
        scen_path.to_str().unwrap(),
        "--out",
        sim.to_str().unwrap(),
    ]);
    assert!(ok, "{stderr}");
    sim
}

/// explain keeps about what `filter` keeps per aiding epoch (it had held ~2.9 KB, then ~0.8 KB,
/// against the filter's ~0.4 KB: every pass's record of every epoch, and a string per
/// innovation): the growth of peak memory from 3000 to 15000 epochs (10 Hz fixes with
/// velocities, P13), per epoch, within 1.5× the filter's and under 1 KB.
#[test]
fn explain_keeps_about_what_filter_keeps_per_epoch() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let peak = |args: &[&str]| -> f64 {
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_sinsmodel"))
            .args(args)
            .env("SINSMODEL_REPORT_PEAK_RSS", "1")
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{err}");
        err.lines()
            .find_map(|l| l.strip_prefix("peak-rss-kib "))
            .expect("the peak is reported")
            .trim()
            .parse::<f64>()
            .unwrap()
            * 1024.0
    };
    let mut used = Vec::new();
    for seconds in [300, 1500] {
        let sc = d.join(format!("m{seconds}.toml"));
        std::fs::write(
            &sc,
            format!(
                "name = \"m\"\nimu_rate_hz = 50.0\nseed = 5\n[start]\nlat_deg = 40.0\nlon_deg = -105.0\nh_m = 1600.0\n\
                 [[segment]]\nkind = \"rest\"\nduration_s = 20.0\n[[segment]]\nkind = \"accelerate\"\nduration_s = 10.0\naccel_mps2 = 1.0\n\
                 [[segment]]\nkind = \"turn\"\nduration_s = {}\nyaw_rate_deg_s = 2.0\n\
                 [gnss]\nrate_hz = 10.0\nsigma_ne = \"0.05 m\"\nsigma_d = \"0.1 m\"\nsigma_v = \"0.02 m/s\"\n",
                seconds - 30
            ),
        )
        .unwrap();
        let sim = d.join(format!("sim{seconds}"));
        let (ok, _, err) = sinsmodel(&[
            "simulate",
            sc.to_str().unwrap(),
            "--out",
            sim.to_str().unwrap(),
        ]);
        assert!(ok, "{err}");
        let (imu, aid) = (sim.join("imu.txt"), sim.join("gnss.txt"));
        let common = [
            "--model",
            "P13",
            "--imu",
            imu.to_str().unwrap(),
            "--aid",
            aid.to_str().unwrap(),
            "--init",
            "40,-105,1600,0,0,0",
        ];
        let out_f = d.join(format!("f{seconds}"));
        let out_e = d.join(format!("e{seconds}"));
        let mut f = vec![
            "filter",
            "--nav-rate",
            "1",
            "--out",
            out_f.to_str().unwrap(),
        ];
        f.extend(common);
        let mut e = vec!["explain", "--out", out_e.to_str().unwrap()];
        e.extend(common);
        used.push((peak(&f), peak(&e)));
    }
    let epochs = 12_000.0;
    let per_filter = (used[1].0 - used[0].0) / epochs;
    let per_explain = (used[1].1 - used[0].1) / epochs;
    eprintln!("bytes per epoch: filter {per_filter:.0}, explain {per_explain:.0}");
    assert!(
        per_explain < 1.5 * per_filter.max(100.0) && per_explain < 1024.0,
        "explain {per_explain:.0} B per epoch, filter {per_filter:.0}"
    );
}

/// A simulated drive whose GNSS stamps run 0.2 s late (each fix re-stamped by hand, an exact
/// shift): the first-order dt_gnss fits about −180 ms and, before it was refitted on
/// re-stamped fixes, a lever arm along the track stood beside it as a cause. explain now
/// re-stamps the fixes by what it found and runs again: the offset comes out within its
/// interval of −200 ms, and no lever arm is named.
/// A simulated 520-s drive (rest, speed changes, turns both ways) in `dir` with GNSS fixes of
/// rate `rate_hz` (positions σ 0.1 m, velocities σ 0.02 m/s); returns the simulation's
/// directory (imu.txt, truth.txt, gnss.txt).
fn simulated_drive(dir: &Path, rate_hz: f64) -> PathBuf {
    simulated_drive_with(dir, rate_hz, "")
}

/// [`simulated_drive`] with the scenario's `[errors]` lines `errors` (e.g. `lever_x = "0.8 m"`).
fn simulated_drive_with(dir: &Path, rate_hz: f64, errors: &str) -> PathBuf {
    simulated_drive_shaped(dir, 7, (60.0, 60.0, [30.0, 30.0, 60.0]), rate_hz, errors)
}

/// [`simulated_drive_with`] with the scenario's `seed` and the legs' durations [s]: the rest at
/// each end, each of the three cruises, and the three turns (3°/s, −3°/s, 3°/s).
fn simulated_drive_shaped(
    dir: &Path,
    seed: u64,
    legs: (f64, f64, [f64; 3]),
    rate_hz: f64,
    errors: &str,
) -> PathBuf {
    std::fs::create_dir_all(dir).unwrap();
    simulated(dir, &drive_scenario(seed, legs, rate_hz, errors))
}

/// The scenario text of [`simulated_drive_shaped`]: 1.5 m/s² to and from cruise (15 m/s).
fn drive_scenario(
    seed: u64,
    (rest, cruise, turns): (f64, f64, [f64; 3]),
    rate_hz: f64,
    errors: &str,
) -> String {
    let mut sc = format!(
        "name = \"late\"\nimu_rate_hz = 100.0\ntruth_rate_hz = 10.0\nseed = {seed}\n\
         [start]\nlat_deg = 40.0966\nlon_deg = -105.1474\nh_m = 1601.0\neuler_deg = [0.0, 0.0, 30.0]\n\
         [[segment]]\nkind = \"rest\"\nduration_s = {rest:?}\n\
         [[segment]]\nkind = \"accelerate\"\nduration_s = 10.0\naccel_mps2 = 1.5\n",
    );
    for (turn, rate) in turns.into_iter().zip([3.0, -3.0, 3.0]) {
        sc.push_str(&format!(
            "[[segment]]\nkind = \"cruise\"\nduration_s = {cruise:?}\n[[segment]]\nkind = \"turn\"\nduration_s = {turn}\nyaw_rate_deg_s = {rate}\n"
        ));
    }
    sc.push_str(&format!(
        "[[segment]]\nkind = \"accelerate\"\nduration_s = 10.0\naccel_mps2 = -1.5\n\
         [[segment]]\nkind = \"rest\"\nduration_s = {rest:?}\n\
         [errors]\n{errors}\n\
         [noise]\narw = \"0.1 deg/sqrt(h)\"\nvrw = \"50 ug/sqrt(Hz)\"\n\
         [gnss]\nrate_hz = {rate_hz}\nsigma_ne = \"0.1 m\"\nsigma_d = \"0.2 m\"\nsigma_v = \"0.02 m/s\"\n"
    ));
    sc
}

/// The dt_gnss finding among `findings` (explain's `stderr` in the panic without one).
fn time_offset<'a>(findings: &'a [serde_json::Value], stderr: &str) -> &'a serde_json::Value {
    findings
        .iter()
        .find(|f| f["term"] == "dt_gnss")
        .unwrap_or_else(|| panic!("no time offset fitted: {stderr}"))
}

/// explain (P13, tactical grade, the drive's noise) on the simulated drive `sim` with the
/// aiding file `aid`, into `out`; returns explain.json and stderr.
fn explain_drive(
    sim: &Path,
    aid: &Path,
    out: &Path,
    extra: &[&str],
) -> (serde_json::Value, String) {
    let (imu, truth) = (sim.join("imu.txt"), sim.join("truth.txt"));
    let mut args = vec![
        "explain",
        "--model",
        "P13",
        "--grade",
        "tactical",
        "--noise",
        "arw=0.1 deg/sqrt(h), vrw=50 ug/sqrt(Hz)",
        "--imu",
        imu.to_str().unwrap(),
        "--aid",
        aid.to_str().unwrap(),
        "--truth",
        truth.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    let (ok, _, stderr) = sinsmodel(&args);
    assert!(ok, "{stderr}");
    let v = json(&out.join("explain.json"));
    // the findings at a glance give a stand-in's other reasons as well
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    for f in v["findings"].as_array().unwrap() {
        if !f["stand_in"].is_null() && !f["not_attributed"].is_null() {
            let row = format!("| {} |", f["term"].as_str().unwrap());
            let line = report.lines().find(|l| l.starts_with(&row)).unwrap();
            assert!(line.contains("(a stand-in; also "), "{line}");
        }
    }
    (v, stderr)
}

/// The simulation `sim`'s GNSS fixes stamped `late` [s] late (the fix stamped t is the
/// trajectory at t − late), written beside them; returns the file.
fn late_fixes(sim: &Path, late: f64) -> PathBuf {
    let gnss = std::fs::read_to_string(sim.join("gnss.txt")).unwrap();
    let shifted: String = gnss
        .lines()
        .map(|l| match l.split_once(' ') {
            Some((t, rest)) if !l.starts_with('#') => {
                format!("{:.4} {rest}\n", t.parse::<f64>().unwrap() + late)
            }
            _ => format!("{l}\n"),
        })
        .collect();
    let aid = sim.join(format!("late_{late}.txt"));
    std::fs::write(&aid, shifted).unwrap();
    aid
}

/// explain (`explain_drive`) on the simulated drive in a new directory `name` with its fixes
/// stamped `late` [s] late and the options `extra`, into its `explain`; returns the directory,
/// explain.json and stderr.
fn explained_late(name: &str, late: f64, extra: &[&str]) -> (PathBuf, serde_json::Value, String) {
    let dir = tmp(name);
    let sim = simulated_drive(&dir, 1.0);
    let (v, stderr) = explain_drive(&sim, &late_fixes(&sim, late), &dir.join("explain"), extra);
    (dir, v, stderr)
}

/// A finding's estimate and σ (display unit).
fn value(f: &serde_json::Value) -> (f64, f64) {
    (
        f["estimate"].as_f64().unwrap(),
        f["sigma"].as_f64().unwrap(),
    )
}

/// Whether finding `f` (explain.json) is named as a cause.
fn is_cause(f: &serde_json::Value) -> bool {
    f["stand_in"].is_null() && f["not_attributed"].is_null()
}

/// Asserts that no finding among `findings` but the term `but` is named a cause, the noise
/// levels too when `noise` (explain's `stderr` in the panic).
fn none_named_but(findings: &[serde_json::Value], but: &str, noise: bool, stderr: &str) {
    for f in findings.iter().filter(|f| noise || f["kind"] != "noise") {
        assert!(
            f["term"] == but || !is_cause(f),
            "{} named as a cause: {stderr}",
            f["term"]
        );
    }
}

/// Stamps 0.2 s late with the time offset withheld from the candidates: a lever arm along the
/// track (speed × offset in turns) with an accelerometer delay beside it (the offset's
/// along-track acceleration) fit the misfit, but neither is a cause: the offset, fitted to
/// every order on fixes re-stamped by it, fits as well in the lever arm's place, and the finding
/// says so with its value.
#[test]
fn a_lever_arm_is_no_cause_where_a_withheld_offset_fits_as_well() {
    let (dir, v, stderr) = explained_late("late-withheld", 0.2, &["--candidates", "!dt_gnss"]);
    let findings = v["findings"].as_array().unwrap();
    none_named_but(findings, "", false, &stderr);
    let lever = findings
        .iter()
        .find(|f| f["term"] == "lever_x")
        .unwrap_or_else(|| panic!("no lever arm fitted: {stderr}"));
    let [ms, sigma] = [0, 1].map(|k| lever["offset_in_place"][k].as_f64().unwrap());
    eprintln!(
        "lever_x {} m stands in for an offset of {ms} ± {sigma} ms",
        lever["estimate"]
    );
    assert!((ms + 200.0).abs() <= 4.0 * sigma, "{lever}");
    assert!(v["restamp"].is_null(), "re-stamped by a withheld term");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Stamps 50 ms late: the rounds name a lever arm along the track first and the offset beside it
/// comes out at nothing; the offset in the lever arm's place fits as well, so explain re-stamps
/// the fixes by it and names the offset, not the lever arm.
#[test]
fn an_offset_a_lever_arm_took_is_refitted_and_named() {
    let (dir, v, stderr) = explained_late("late-50ms", 0.05, &[]);
    let findings = v["findings"].as_array().unwrap();
    let dt = time_offset(findings, &stderr);
    let (ms, sigma) = value(dt);
    eprintln!(
        "stamps 50 ms late: dt_gnss {ms} ± {sigma} ms; runs {}",
        v["restamp"]
    );
    assert!(is_cause(dt), "{dt}");
    assert!(
        (ms + 50.0).abs() <= 3.0 * sigma,
        "dt_gnss {ms} ± {sigma} ms"
    );
    none_named_but(findings, "dt_gnss", false, &stderr);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Stamps 0.9 s early: to first order the offset is held only by the stated noise (a vel_ne σ
/// 4× the stated was named the cause); refitted on re-stamped fixes it is the offset, and the
/// noise level is no cause. Stamps 1.5 s late: the offset found is beyond the ±1 s explain
/// re-stamps by, and nothing is named a cause.
/// Stamps 50 ms late on a drive whose antenna sits 0.8 m ahead of the IMU: at the drive's one
/// speed the lever arm cancels most of the offset's move of the fixes (15 m/s × 50 ms), and
/// what is left is the offset's along-track acceleration, an accelerometer delay's signature
/// (the first run named tau_x −52 ms alone). Tried with the offset and the lever arms in its
/// place, the delay fits no better, so explain re-stamps by the offset and names it with the
/// lever arm, not the delay.
#[test]
fn an_offset_a_lever_arm_cancels_is_no_accelerometer_delay() {
    let dir = tmp("late-lever");
    let sim = simulated_drive_with(&dir, 1.0, "lever_x = \"0.8 m\"");
    let (v, stderr) = explain_drive(&sim, &late_fixes(&sim, 0.05), &dir.join("explain"), &[]);
    let findings = v["findings"].as_array().unwrap();
    let (ms, sigma) = value(time_offset(findings, &stderr));
    let lever = findings
        .iter()
        .find(|f| f["term"] == "lever_x" && is_cause(f))
        .unwrap_or_else(|| panic!("no lever arm named: {stderr}"));
    let (m, m_sigma) = value(lever);
    eprintln!("50 ms late, lever arm 0.8 m: dt_gnss {ms} ± {sigma} ms, lever_x {m} ± {m_sigma} m");
    assert!(
        (ms + 50.0).abs() <= 3.0 * sigma,
        "dt_gnss {ms} ± {sigma} ms"
    );
    assert!(
        (m - 0.8).abs() <= 3.0 * m_sigma,
        "lever_x {m} ± {m_sigma} m"
    );
    for f in findings.iter().filter(|f| f["term"] != "dt_gnss") {
        assert!(
            f["term"] == "lever_x" || f["term"] == "lever_y" || !is_cause(f),
            "{} named: {stderr}",
            f["term"]
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_large_offset_is_refitted_or_names_nothing() {
    let dir = tmp("early-900ms");
    let sim = simulated_drive(&dir, 1.0);
    let (v, stderr) = explain_drive(&sim, &late_fixes(&sim, -0.9), &dir.join("early"), &[]);
    let findings = v["findings"].as_array().unwrap();
    let dt = time_offset(findings, &stderr);
    let (ms, sigma) = value(dt);
    eprintln!("stamps 0.9 s early: dt_gnss {ms} ± {sigma} ms");
    assert!(is_cause(dt) && (ms - 900.0).abs() <= 3.0 * sigma, "{dt}");
    none_named_but(findings, "dt_gnss", true, &stderr);
    let (v, stderr) = explain_drive(&sim, &late_fixes(&sim, 1.5), &dir.join("late"), &[]);
    none_named_but(v["findings"].as_array().unwrap(), "", true, &stderr);
    assert!(stderr.contains("beyond ±1 s"), "{stderr}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_late_gnss_stamp_is_refitted_to_every_order() {
    // the receiver's stamps 0.2 s late: the fix stamped t is the trajectory at t − 0.2 s
    let (dir, v, stderr) = explained_late("late-stamps", 0.2, &[]);
    let out = dir.join("explain");
    let findings = v["findings"].as_array().unwrap();
    let dt = time_offset(findings, &stderr);
    let (ms, sigma) = value(dt);
    eprintln!(
        "stamps 200 ms late: dt_gnss {ms} ± {sigma} ms; runs {}",
        v["restamp"]
    );
    assert!(
        dt["stand_in"].is_null() && dt["not_attributed"].is_null(),
        "{dt}"
    );
    assert!(
        (ms + 200.0).abs() <= 3.0 * sigma,
        "dt_gnss {ms} ± {sigma} ms"
    );
    assert!(v["restamp"]["passes"].as_array().unwrap().len() >= 2);
    for f in findings {
        let is_cause = f["stand_in"].is_null() && f["not_attributed"].is_null();
        assert!(
            !(is_cause && f["term"].as_str().unwrap().starts_with("lever")),
            "a lever arm named beside the offset: {f}"
        );
    }
    let preset = std::fs::read_to_string(out.join("extended.toml")).unwrap();
    assert!(preset.contains("--gnss-delay"), "{preset}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A receiver whose positions are stamped 0.2 s late and whose velocities 0.3 s late (10-Hz
/// fixes, the velocity columns one row older): no one time offset fits both kinds of fix. The
/// first run names one (to first order); refitted on re-stamped fixes, the positions alone and
/// the velocities alone want offsets apart, and explain labels the offset a stand-in, saying so.
#[test]
fn a_velocity_latency_of_its_own_is_no_time_offset() {
    const LAG: usize = 1;
    let dir = tmp("velocity-latency");
    let sim = simulated_drive(&dir, 10.0);
    let gnss = std::fs::read_to_string(sim.join("gnss.txt")).unwrap();
    let rows: Vec<Vec<&str>> = gnss
        .lines()
        .filter(|l| !l.starts_with('#'))
        .map(|l| l.split_whitespace().collect())
        .collect();
    let mut text: String = gnss
        .lines()
        .filter(|l| l.starts_with('#'))
        .map(|l| format!("{l}\n"))
        .collect();
    for k in LAG..rows.len() {
        // stamped 0.2 s late, positions of row k and velocities of row k − LAG (older)
        let (p, v) = (&rows[k], &rows[k - LAG]);
        let t: f64 = p[0].parse().unwrap();
        text.push_str(&format!(
            "{:.4} {} {}\n",
            t + 0.2,
            p[1..7].join(" "),
            v[7..].join(" ")
        ));
    }
    let aid = dir.join("vel_late.txt");
    std::fs::write(&aid, text).unwrap();
    let out = dir.join("explain");
    let (v, stderr) = explain_drive(&sim, &aid, &out, &[]);
    let findings = v["findings"].as_array().unwrap();
    let dt = time_offset(findings, &stderr);
    let why = dt["stand_in"].as_str().unwrap_or_else(|| panic!("{dt}"));
    eprintln!("positions 0.2 s, velocities 0.3 s late: {why}");
    assert!(
        why.contains("from the position fixes") && why.contains("from the velocity fixes"),
        "{why}"
    );
    for f in findings {
        let is_cause = f["stand_in"].is_null() && f["not_attributed"].is_null();
        assert!(
            !(is_cause && f["term"].as_str().unwrap().starts_with("lever")),
            "a lever arm named for a velocity latency: {f}"
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A wrong known offset (`--gnss-delay '200 ms'` on fixes stamped right): the first run fits
/// −180 ms on top to first order (with a lever arm beside it); refitted on re-stamped fixes the
/// offset in all is none, and explain says the given one is not borne out, naming no cause.
#[test]
fn a_wrong_known_offset_is_not_borne_out() {
    let (dir, v, stderr) = explained_late("wrong-delay", 0.0, &["--gnss-delay", "200 ms"]);
    let findings = v["findings"].as_array().unwrap();
    let dt = time_offset(findings, &stderr);
    let why = dt["not_attributed"]
        .as_str()
        .unwrap_or_else(|| panic!("{dt}"));
    assert!(why.contains("not borne out"), "{why}");
    assert!(because(dt, "offset_not_borne_out"), "{dt}");
    let ms = dt["estimate"].as_f64().unwrap();
    assert!(ms.abs() <= 3.0 * dt["sigma"].as_f64().unwrap(), "{ms} ms");
    for f in findings {
        let is_cause = f["stand_in"].is_null() && f["not_attributed"].is_null();
        assert!(!is_cause, "a cause named on fixes stamped right: {f}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// True when `rule` is among the rules that un-named finding `f` (its `not_attributed_because`).
fn because(f: &serde_json::Value, rule: &str) -> bool {
    f["not_attributed_because"]
        .as_array()
        .is_some_and(|r| r.iter().any(|x| x == rule))
}

/// The drive with an antenna lever arm hidden and kept out of the candidates (`!lever_*`): an
/// accelerometer delay takes it up (helper-55: "Found: accelerometer y delay tau_y = 29.0 ±
/// 6.63 ms" on seed 5, hidden none). Now the IMU findings are tried against the GNSS terms kept
/// out too: nothing is named, and the delay names the lever arm it stands for, at the hidden
/// value within 3σ.
#[test]
fn an_antenna_lever_arm_kept_out_is_no_accelerometer_delay() {
    let dir = tmp("drive-lever-withheld");
    // (seed, lever arm [m]) as helper-55 drew them
    for (seed, lever) in [(5, [0.37, 0.48, -0.31]), (7, [-0.53, -0.70, -0.52])] {
        let errors = lever_errors(lever);
        // (helper-55's drives: 300 s)
        let legs = (60.0, 40.0 / 3.0, [30.0, 30.0, 60.0]);
        let d = dir.join(format!("seed_{seed}"));
        let sim = simulated_drive_shaped(&d, seed, legs, 1.0, &errors);
        let cands = ["--candidates", "!lever_*"];
        let (v, stderr) = explain_drive(&sim, &sim.join("gnss.txt"), &d.join("explain"), &cands);
        let findings = v["findings"].as_array().unwrap();
        for f in findings {
            assert!(
                f["kind"] == "noise" || !(f["stand_in"].is_null() && f["not_attributed"].is_null()),
                "seed {seed}: {} named with only a lever arm hidden: {stderr}",
                f["term"]
            );
        }
        let tau = findings
            .iter()
            .find(|f| f["term"] == "tau_y")
            .unwrap_or_else(|| panic!("seed {seed}: no accelerometer delay fitted: {stderr}"));
        assert!(because(tau, "withheld_term_fits"), "seed {seed}: {tau}");
        let lx = tau["withheld_alike"]
            .as_array()
            .unwrap()
            .iter()
            .find(|w| w["term"] == "lever_x")
            .unwrap_or_else(|| panic!("seed {seed}: {tau}"));
        let (est, sd) = (
            lx["estimate"].as_f64().unwrap(),
            lx["sigma"].as_f64().unwrap(),
        );
        assert!(
            (est - lever[0]).abs() < 3.0 * sd,
            "seed {seed}: lever_x would need {est} ± {sd} m, hidden {}",
            lever[0]
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The drive with its fixes stamped 10 ms late and nothing else hidden, every candidate
/// offered: an accelerometer x delay took the offset (helper-56: "Found: accelerometer x delay
/// tau_x = -11.5 ± 3.09 ms", dt_gnss dropped as taken up by it), because the offset tried in
/// its place had the lever arms beside it and fell under 3σ. Tried alone as well, the offset
/// is named at the hidden value and no delay is.
#[test]
fn a_small_time_offset_is_no_accelerometer_delay() {
    let dir = tmp("drive-small-offset");
    // (helper-56's drive: 300 s), its fixes stamped 10 ms late: dt_gnss = −10 ms
    let sim = simulated_drive_shaped(&dir, 11, (20.0, 44.0, [36.0; 3]), 1.0, "");
    let aid = late_fixes(&sim, 0.010);
    let (v, stderr) = explain_drive(&sim, &aid, &dir.join("explain"), &[]);
    let findings = v["findings"].as_array().unwrap();
    for f in findings {
        let named = f["stand_in"].is_null() && f["not_attributed"].is_null();
        assert!(
            !(named && f["term"].as_str().unwrap().starts_with("tau_")),
            "a delay named for a late fix: {stderr}"
        );
    }
    let dt = time_offset(findings, &stderr);
    assert!(
        dt["stand_in"].is_null() && dt["not_attributed"].is_null(),
        "{dt}"
    );
    let (ms, sd) = (
        dt["estimate"].as_f64().unwrap(),
        dt["sigma"].as_f64().unwrap(),
    );
    assert!(
        (ms + 10.0).abs() < 3.0 * sd,
        "dt_gnss {ms} ± {sd} ms, hidden -10"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A drive mostly at one speed with an antenna lever arm hidden and every candidate offered: a
/// lever arm along the track moves the fixes as speed × a time offset does, the rounds took
/// the offset first, and explain printed "Found: GNSS time offset dt_gnss = -11.2 ± 2.92 ms"
/// with no offset hidden (helper-55's lvo_7, seed 7), or an offset beside a lever arm 2.6σ
/// from the hidden one (seed 10). Tried against a lever arm on the fixes as given, or fitted
/// beside the lever arms it re-stamped for, the offset is not named, and each lever arm named
/// holds the hidden value within 2σ.
#[test]
fn a_lever_arm_is_no_time_offset_on_a_drive_at_one_speed() {
    let dir = tmp("drive-lever-offered");
    for (seed, lever) in [(7, [-0.53, -0.70, -0.52]), (10, [0.55, 0.48, -0.28])] {
        let errors = lever_errors(lever);
        let legs = (60.0, 40.0 / 3.0, [30.0, 30.0, 60.0]);
        let d = dir.join(format!("seed_{seed}"));
        let sim = simulated_drive_shaped(&d, seed, legs, 1.0, &errors);
        let (v, stderr) = explain_drive(&sim, &sim.join("gnss.txt"), &d.join("explain"), &[]);
        let findings = v["findings"].as_array().unwrap();
        let dt = time_offset(findings, &stderr);
        // (or, fitted beside the lever arms it re-stamped for, it is no offset in all)
        let rules = ["offset_or_lever_arm", "offset_not_borne_out"];
        assert!(rules.iter().any(|r| because(dt, r)), "seed {seed}: {dt}");
        for f in findings
            .iter()
            .filter(|f| is_cause(f) && f["kind"] != "noise")
        {
            let axis = ["lever_x", "lever_y", "lever_z"]
                .iter()
                .position(|t| f["term"] == *t);
            let Some(axis) = axis else {
                panic!("seed {seed}: {} named: {stderr}", f["term"]);
            };
            let (m, sd) = value(f);
            assert!(
                (m - lever[axis]).abs() <= 2.0 * sd,
                "seed {seed}: {} = {m} ± {sd} m, hidden {}",
                f["term"],
                lever[axis]
            );
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The scenario's `[errors]` lines of an antenna lever arm (x, y, z) [m].
fn lever_errors(lever: [f64; 3]) -> String {
    format!(
        "lever_x = \"{} m\"\nlever_y = \"{} m\"\nlever_z = \"{} m\"",
        lever[0], lever[1], lever[2]
    )
}

/// A uniform draw in [lo, hi) from `seed` and `k` (splitmix64): the campaign's lever arms.
fn draw(seed: u64, k: u64, lo: f64, hi: f64) -> f64 {
    let mut z = seed
        .wrapping_mul(0x9e37_79b9_7f4a_7c15)
        .wrapping_add(k.wrapping_mul(0xbf58_476d_1ce4_e5b9));
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^= z >> 31;
    lo + (hi - lo) * (z >> 11) as f64 / (1u64 << 53) as f64
}

/// The developer's campaign behind the offset-or-lever-arm numbers of docs/explain.md (about
/// 2.5 s per run): 300-s P13 drives (as `a_lever_arm_is_no_time_offset_on_a_drive_at_one_speed`),
/// an antenna lever arm drawn per seed (|x| 0.3–0.8 m, y ±0.8 m, z ±0.6 m), every candidate
/// offered, with the fixes as simulated, 15 ms late and 30 ms late, and 30 ms late without the
/// lever arm; prints per group how often dt_gnss is named and how often its value is beyond 3σ
/// of the hidden one. `SEEDS=1-40 cargo test --release --test explain_cli
/// offset_or_lever_arm_campaign -- --ignored --nocapture` (default 1-20).
#[test]
#[ignore]
fn offset_or_lever_arm_campaign() {
    let seeds = std::env::var("SEEDS").unwrap_or_else(|_| "1-20".into());
    let (a, b) = seeds.split_once('-').expect("SEEDS=FIRST-LAST");
    let (a, b): (u64, u64) = (a.parse().unwrap(), b.parse().unwrap());
    let dir = tmp("offset-lever-campaign");
    // (group, fixes late [s], with a lever arm)
    for (group, late, lever) in [
        ("lever arm, no offset", 0.0, true),
        ("lever arm, 15 ms late", 0.015, true),
        ("lever arm, 30 ms late", 0.030, true),
        ("no lever arm, 30 ms late", 0.030, false),
    ] {
        let (mut runs, mut named, mut off, mut taken) = (0, 0, 0, 0);
        for seed in a..=b {
            let sign = if draw(seed, 0, 0.0, 1.0) < 0.5 {
                -1.0
            } else {
                1.0
            };
            let arm = [
                sign * draw(seed, 1, 0.3, 0.8),
                draw(seed, 2, -0.8, 0.8),
                draw(seed, 3, -0.6, 0.6),
            ];
            let arm = arm.map(|x| (x * 1e3).round() / 1e3);
            let errors = if lever {
                lever_errors(arm)
            } else {
                String::new()
            };
            let d = dir.join(format!("{seed}-{late}-{lever}"));
            let legs = (60.0, 40.0 / 3.0, [30.0, 30.0, 60.0]);
            let sim = simulated_drive_shaped(&d, seed, legs, 1.0, &errors);
            let aid = if late > 0.0 {
                late_fixes(&sim, late)
            } else {
                sim.join("gnss.txt")
            };
            let (v, _) = explain_drive(&sim, &aid, &d.join("explain"), &[]);
            runs += 1;
            let dt = v["findings"]
                .as_array()
                .unwrap()
                .iter()
                .find(|f| f["term"] == "dt_gnss");
            // (un-named by the offset-or-lever-arm rule alone: named before it)
            let only = |f: &&serde_json::Value| {
                f["not_attributed_because"] == serde_json::json!(["offset_or_lever_arm"])
            };
            taken += dt.filter(only).map_or(0, |_| 1);
            if let Some(dt) = dt.filter(|f| is_cause(f)) {
                named += 1;
                let (ms, sd) = value(dt);
                if (ms + late * 1e3).abs() > 3.0 * sd {
                    off += 1;
                }
            }
            std::fs::remove_dir_all(&d).unwrap();
        }
        eprintln!("{group}: {runs} runs (seeds {a}-{b}), dt_gnss named in {named}, {off} of them beyond 3σ of the hidden offset; {taken} more un-named by offset_or_lever_arm alone");
    }
}

/// The drive at 25 m/s (2.5 m/s² to and from cruise) with an antenna lever arm hidden and its
/// fixes 20 ms late, every candidate offered (helper-57's v25_12): the first run's offset came
/// out −4.50 ± 3.62 ms beside a lever arm and an accelerometer delay, under the 5 ms that are
/// re-stamped, and all three were "Found" (lever_x −0.820 m for −0.529 m hidden, tau_x
/// −13.5 ms, none hidden). An offset within 2σ of zero is no cause; the lever arm then stands
/// in for it, the fixes are re-stamped, and the offset and the lever arms come out at the
/// hidden values with no delay named.
#[test]
fn a_fast_drive_names_the_offset_not_a_delay() {
    let dir = tmp("drive-25mps");
    let lever = [-0.529, -0.606, -0.551];
    let legs = (60.0, 40.0 / 3.0, [30.0, 30.0, 60.0]);
    let text = drive_scenario(12, legs, 1.0, &lever_errors(lever))
        .replace("accel_mps2 = 1.5", "accel_mps2 = 2.5")
        .replace("accel_mps2 = -1.5", "accel_mps2 = -2.5");
    std::fs::create_dir_all(&dir).unwrap();
    let sim = simulated(&dir, &text);
    let (v, stderr) = explain_drive(&sim, &late_fixes(&sim, 0.020), &dir.join("explain"), &[]);
    let findings = v["findings"].as_array().unwrap();
    let dt = time_offset(findings, &stderr);
    let (ms, sd) = value(dt);
    assert!(is_cause(dt) && (ms + 20.0).abs() <= 3.0 * sd, "{dt}");
    for f in findings
        .iter()
        .filter(|f| is_cause(f) && f["kind"] != "noise")
    {
        let Some(axis) = ["lever_x", "lever_y", "lever_z"]
            .iter()
            .position(|t| f["term"] == *t)
        else {
            assert_eq!(f["term"], "dt_gnss", "{stderr}");
            continue;
        };
        let (m, sd) = value(f);
        assert!(
            (m - lever[axis]).abs() <= 3.0 * sd,
            "{}: {m} ± {sd}",
            f["term"]
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
