//! `sinsmodel explain-eval`: a small campaign's report has its structure and behaves (hidden terms
//! found, null cases quiet); the same checks fail with a deliberately broken selector; two
//! half-runs merged equal the whole run.

use std::path::{Path, PathBuf};
use std::process::Command;

fn sinsmodel(args: &[&str]) -> (bool, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_sinsmodel"))
        .args(args)
        .output()
        .expect("run sinsmodel");
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("sinsmodel-eval-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn eval(name: &str, extra: &[&str]) -> (PathBuf, serde_json::Value) {
    let out = tmp(name);
    let mut args = vec![
        "explain-eval",
        "--seed",
        "3",
        "--seconds",
        "300",
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    let (ok, stderr) = sinsmodel(&args);
    assert!(ok, "{stderr}");
    let v = json(&out.join("eval.json"));
    (out, v)
}

/// What a working explain must show on a small campaign; Err names what failed.
fn behaves(v: &serde_json::Value) -> Result<(), String> {
    let rate = |k: &str| v[k].as_f64();
    let det = rate("detection_rate").ok_or("no detection rate")?;
    if det < 0.8 {
        return Err(format!("detection {det}"));
    }
    if rate("detection_rate_lambda_50").is_some_and(|d| d < 1.0) {
        return Err(format!(
            "detection at λ ≥ 50: {}",
            v["detection_rate_lambda_50"]
        ));
    }
    if let Some(w) = rate("wrong_term_rate") {
        if w > 0.1 {
            return Err(format!("wrong term rate {w}"));
        }
    }
    if let Some(f) = rate("false_alarm_rate") {
        if f > 0.0 {
            return Err(format!("false alarms {f}"));
        }
    }
    let e = rate("coef_error_median").ok_or("no coefficient error")?;
    if e > 0.25 {
        return Err(format!("coefficient error median {e}"));
    }
    Ok(())
}

#[test]
fn small_campaign_structure_behaviour_broken_selector_and_merge() {
    let (whole, v) = eval("whole", &["--cases", "12"]);
    for k in [
        "cases",
        "seed",
        "detection_rate",
        "false_alarm_rate",
        "wrong_term_rate",
        "coef_error_median",
        "coef_error_p90",
        "calibration",
        "gain_recovery_median",
        "by_group",
        "power_curve",
    ] {
        assert!(v.get(k).is_some(), "eval.json lacks {k}");
    }
    assert_eq!(v["cases"], 12);
    assert!(
        v["null_cases"].as_u64().unwrap() >= 1,
        "the seed draws null cases"
    );
    for b in v["power_curve"].as_array().unwrap() {
        for k in ["lambda_lo", "lambda_hi", "cases", "detection_rate"] {
            assert!(b.get(k).is_some(), "power_curve bin lacks {k}");
        }
    }
    for g in ["d", "kaq", "kas", "kao", "kgf", "kgq", "size"] {
        assert!(v["by_group"][g]["cases"].is_number(), "by_group.{g}");
    }
    assert!(whole.join("power_curve.png").exists());
    behaves(&v).unwrap();

    // the same checks must catch a selector that names terms at random
    let (broken, vb) = eval("broken", &["--cases", "12", "--broken-selector"]);
    assert!(behaves(&vb).is_err(), "a broken selector passed: {vb}");

    // two half-runs (shards) merged equal the whole run
    let (h1, _) = eval("h1", &["--cases", "6"]);
    let (h2, _) = eval("h2", &["--cases", "6", "--first", "6", "--jobs", "1"]);
    let merged = tmp("merged");
    let (ok, stderr) = sinsmodel(&[
        "explain-eval",
        "--merge",
        h1.to_str().unwrap(),
        h2.to_str().unwrap(),
        "--out",
        merged.to_str().unwrap(),
    ]);
    assert!(ok, "{stderr}");
    let strip = |mut x: serde_json::Value| {
        for k in ["seconds_wall", "seconds_per_case"] {
            x.as_object_mut().unwrap().remove(k);
        }
        x
    };
    assert_eq!(strip(json(&merged.join("eval.json"))), strip(v.clone()));
    let cases = |p: &Path| {
        let mut c = json(&p.join("cases.json"));
        for x in c["cases"].as_array_mut().unwrap() {
            x.as_object_mut().unwrap().remove("seconds_taken");
        }
        c
    };
    assert_eq!(cases(&merged), cases(&whole));
    // a shard merged twice is refused
    let (ok, stderr) = sinsmodel(&[
        "explain-eval",
        "--merge",
        h1.to_str().unwrap(),
        h1.to_str().unwrap(),
        "--out",
        tmp("twice").to_str().unwrap(),
    ]);
    assert!(!ok && stderr.contains("appears twice"), "{stderr}");
    // a stored campaign with settings explain-eval never writes is refused
    let edited = tmp("edited");
    std::fs::create_dir_all(&edited).unwrap();
    let text = std::fs::read_to_string(h2.join("cases.json")).unwrap();
    let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
    v["spec"]["alpha"] = serde_json::json!(0.7);
    std::fs::write(edited.join("cases.json"), v.to_string()).unwrap();
    let (ok, stderr) = sinsmodel(&[
        "explain-eval",
        "--merge",
        edited.to_str().unwrap(),
        "--out",
        tmp("edited_out").to_str().unwrap(),
    ]);
    assert!(!ok && stderr.contains("campaign settings"), "{stderr}");
    std::fs::remove_dir_all(&edited).unwrap();
    for d in [whole, broken, h1, h2, merged] {
        std::fs::remove_dir_all(d).unwrap();
    }
}
