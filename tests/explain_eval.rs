//! `sinsmodel explain-eval`: a small campaign's report has its structure and behaves (hidden terms
//! found, null cases quiet); the same checks fail with a deliberately broken selector; two
//! half-runs merged equal the whole run; merged cases are checked like any input.

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
        for k in [
            "seconds_wall",
            "seconds_per_case",
            "seconds_per_case_setup",
            "seconds_per_case_explain",
        ] {
            x.as_object_mut().unwrap().remove(k);
        }
        x
    };
    assert_eq!(strip(json(&merged.join("eval.json"))), strip(v.clone()));
    let cases = |p: &Path| {
        let mut c = json(&p.join("cases.json"));
        for x in c["cases"].as_array_mut().unwrap() {
            for k in [
                "seconds_taken",
                "seconds_taken_setup",
                "seconds_taken_explain",
            ] {
                x.as_object_mut().unwrap().remove(k);
            }
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
    assert!(!ok && stderr.contains("merge each shard once"), "{stderr}");
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

/// Every kind of cause in one small campaign: a two-term case (d and kas on one axis), a
/// misstated noise (a null case for terms, which explain must call noise), a GNSS lever arm, a
/// turntable's inner lever arm and accelerometer delay; the report states the test, gives the
/// rates' confidence intervals and a power curve per group.
#[test]
fn every_kind_of_cause_in_a_small_campaign() {
    let groups = "two_axis,noise_gyro,gnss_lever,inner_lever,accel_delay";
    let (dir, v) = eval("kinds", &["--cases", "10", "--groups", groups]);
    let cases = json(&dir.join("cases.json"));
    let cases = cases["cases"].as_array().unwrap();
    let of = |g: &'static str| cases.iter().filter(move |c| c["group"] == g);
    assert!(of("two_axis").count() >= 1, "seed 3 draws a two-term case");
    for c in of("two_axis") {
        let kas = c["term"].as_str().unwrap().replace("d_", "kas_");
        assert_eq!(c["also_hidden"], serde_json::json!([kas]), "{c}");
    }
    for c in of("noise_gyro") {
        assert_eq!(c["noise_misstated"], serde_json::json!(["gyro_arw"]));
        assert!(c["term"].is_null(), "a noise case hides no term: {c}");
    }
    for c in of("accel_delay") {
        assert_eq!(c["also_hidden"], serde_json::json!(["tau_y", "tau_z"]));
    }
    behaves(&v).unwrap();
    for k in [
        "false_alarm_ci",
        "wrong_term_ci",
        "detection_lambda_50_ci",
        "calibration_ci",
        "noise_cases",
    ] {
        assert!(v.get(k).is_some(), "eval.json lacks {k}");
    }
    if let Some([lo, hi]) = v["false_alarm_ci"]
        .as_array()
        .map(|a| [a[0].as_f64().unwrap(), a[1].as_f64().unwrap()])
    {
        assert!(lo <= v["false_alarm_rate"].as_f64().unwrap() && hi > 0.0);
    }
    for g in groups.split(',') {
        let bins = v["by_group"][g]["power_curve"].as_array().unwrap();
        assert_eq!(bins.len(), 6, "{g}: six λ bins");
    }
    let md = std::fs::read_to_string(dir.join("eval.md")).unwrap();
    for says in ["Holm's first threshold", "95 % interval", "per λ bin"] {
        assert!(md.contains(says), "eval.md does not say {says}:\n{md}");
    }
    assert!(dir.join("power_by_group.png").exists());
    // `all` stands alone; empty entries and settings beside --merge are refused, named
    for (args, says) in [
        (
            vec!["--cases", "1", "--groups", "all,d"],
            "`all` stands alone",
        ),
        (
            vec!["--cases", "1", "--groups", "d,,kas"],
            "entry 2 of 3 is empty",
        ),
        (vec!["--cases", "1", "--groups", "d, kas"], "no spaces"),
        (vec!["--cases", "1", "--seconds", "-1"], "--seconds -1"),
        (
            vec!["--merge", dir.to_str().unwrap(), "--seed", "9"],
            "not --seed",
        ),
    ] {
        let mut a = vec!["explain-eval"];
        a.extend(args.iter().copied());
        let out = tmp("refused");
        a.extend(["--out", out.to_str().unwrap()]);
        let (ok, err) = sinsmodel(&a);
        assert!(!ok && err.contains(says), "{args:?}: {err}");
        assert!(!out.exists(), "{args:?} wrote {}", out.display());
    }
    // an unknown group is refused naming the known ones
    let (ok, err) = sinsmodel(&[
        "explain-eval",
        "--cases",
        "1",
        "--groups",
        "d,nosuch",
        "--out",
        tmp("nosuch").to_str().unwrap(),
    ]);
    assert!(!ok && err.contains("unknown group `nosuch`") && err.contains("two_axis"));
}

/// `--merge` checks every stored case like any input: an edited field is refused naming the
/// shard's file, the case's index and the field (never an `inf %` from a truth of 0), and a
/// range of indices missing between shards is refused naming it.
/// The filter's confirmation at the selection's α (the prior's Occam term added back): a d_x
/// at λ 17.4 that passes the first test (2Δℓ 19.5) is named. Under the old k ln N bar the
/// extended filter's 2Δℓ of 5.2 undid it (sensor-600 campaign, seed 7, case 192).
#[test]
fn a_weak_term_that_passes_the_first_test_is_confirmed_at_alpha() {
    use sinsmodel::experiment::explain_eval::{default_options, run_case_explained, EvalSpec};
    let spec = EvalSpec {
        seed: 7,
        ..EvalSpec::default()
    };
    let (c, e) = run_case_explained(&spec, 192, &default_options()).expect("the case runs");
    assert_eq!(c.term.as_deref(), Some("d_x"));
    let lambda = c.lambda.unwrap();
    assert!((10.0..25.0).contains(&lambda), "λ {lambda}");
    assert!(
        c.detected && !c.wrong_term,
        "{c:?}\n{}",
        e.summary.join("\n")
    );
    assert!(e.unconfirmed.is_empty(), "{:?}", e.unconfirmed);
    let (est, sigma, truth) = (c.estimate.unwrap(), c.sigma.unwrap(), c.truth.unwrap());
    assert!(
        (est - truth).abs() < 3.0 * sigma,
        "{est} ± {sigma} vs {truth}"
    );
}

/// A noise level the stand-in terms take up is no finding: a 300-s case hides kgq_x at 9.1 of
/// the spec's (laser-grade) prior σ, which explain calls a stand-in (its prior objects more than
/// the data support it); the gyro white noise, stated right, fitted 2.77× without it and was
/// named until the noise finding was re-tested beside the stand-ins (sensor-300 campaign, seed
/// 8, case 26, run with the spec's prior: the campaign's kgq cases now declare a tactical
/// gyro's, under which the same case names kgq_x).
#[test]
fn a_noise_level_the_stand_ins_take_up_is_not_named() {
    use sinsmodel::experiment::explain_eval::{default_options, prepare, EvalSpec};
    use sinsmodel::experiment::hidden::run_hidden_on;
    let spec = EvalSpec {
        seed: 8,
        seconds: 300.0,
        ..EvalSpec::default()
    };
    let (_, (mut case, sim, aid)) = prepare(&spec, 26).expect("the case is put in");
    assert_eq!(case.hidden.len(), 1);
    assert_eq!(case.hidden[0].0, "kgq_x");
    assert!(case.noise_ratio.is_empty());
    let mut opts = default_options();
    opts.alpha = spec.alpha;
    let explain = |case: &sinsmodel::sim::hidden::HiddenCase| {
        run_hidden_on(case, &sim, &aid, &opts)
            .expect("the case runs")
            .explanation
    };
    // as the campaign runs it: the declared prior holds the value, and kgq_x is named
    let declared = explain(&case);
    let words = declared.summary.join("\n");
    assert!(
        declared
            .findings
            .iter()
            .any(|f| f.term == "kgq_x" && f.stand_in.is_none()),
        "{words}"
    );
    // with the spec's laser-grade prior
    case.priors.retain(|p| !p.0.starts_with("kgq_"));
    let e = explain(&case);
    let words = e.summary.join("\n");
    let terms: Vec<_> = e.findings.iter().filter(|f| f.kind != "noise").collect();
    assert!(
        terms
            .iter()
            .any(|f| f.term == "kgq_x" && f.stand_in.is_some()),
        "{words}"
    );
    // no claim: every term and every noise level it fitted is labelled a stand-in
    assert!(e.findings.iter().all(|f| f.stand_in.is_some()), "{words}");
}

/// Case `index` of the all-600 campaign (seed 11, every group), run and explained.
fn all_600_case(
    index: usize,
) -> (
    sinsmodel::experiment::explain_eval::CaseResult,
    sinsmodel::explain::Explanation,
) {
    all_600_case_with(
        index,
        &sinsmodel::experiment::explain_eval::default_options(),
    )
}

/// Case `index` of the all-600 campaign, explained with `opts`.
fn all_600_case_with(
    index: usize,
    opts: &sinsmodel::explain::ExplainOptions,
) -> (
    sinsmodel::experiment::explain_eval::CaseResult,
    sinsmodel::explain::Explanation,
) {
    use sinsmodel::experiment::explain_eval::{run_case_explained, EvalSpec};
    let spec = EvalSpec {
        seed: 11,
        groups: sinsmodel::sim::hidden::all_groups()
            .iter()
            .map(|g| g.to_string())
            .collect(),
        ..EvalSpec::default()
    };
    run_case_explained(&spec, index, opts).expect("the case runs")
}

/// A white-noise level the raw increments do not show is no finding about the noise: all-600's
/// case 28 (seed 11) states the gyro's white noise too small and nothing else; explain names
/// the gyro level, and also fitted the accelerometer's above its stated value (named until the
/// fit was read against the Allan deviation of the raw increments, which show the stated value).
/// Since 2026-12-08 the case runs closed loop by default (its free navigation drifts beyond
/// 2.56° with the gyro noise) and fits no accelerometer level there; the rule is tested in open loop,
/// where the level is fitted.
#[test]
fn a_white_noise_the_raw_increments_do_not_show_is_not_named() {
    let (c, _) = all_600_case(28);
    let named: Vec<&String> = c
        .noise_named
        .iter()
        .filter(|l| !c.noise_stand_ins.contains(l))
        .collect();
    assert_eq!(named, vec!["gyro_arw"], "closed loop: {c:?}");
    let open = sinsmodel::explain::ExplainOptions {
        closed_loop_on_drift: false,
        ..sinsmodel::experiment::explain_eval::default_options()
    };
    let (c, e) = all_600_case_with(28, &open);
    assert_eq!(c.noise_misstated, vec!["gyro_arw".to_string()], "{c:?}");
    let named: Vec<&String> = c
        .noise_named
        .iter()
        .filter(|l| !c.noise_stand_ins.contains(l))
        .collect();
    assert_eq!(named, vec!["gyro_arw"], "{c:?}\n{}", e.summary.join("\n"));
    assert!(
        c.noise_stand_ins.contains(&"accel_vrw".to_string()),
        "{c:?}"
    );
    let words = e.summary.join("\n");
    assert!(
        words.contains("raw accelerometer increments show"),
        "{words}"
    );
}

/// A lever arm and a time offset the data do not tell apart are one class: all-600's case 13
/// (seed 11) hides an antenna lever arm along x at λ 41 on a drive mostly at one speed; the
/// offset, a candidate, fits as well in its place (−0.7 of its σ). explain called the lever
/// arm a stand-in that "probably" stands in for the offset until 2026-12-08; now the lever arm
/// is not attributed, the offset its equivalent with the value it would need, and neither
/// goes into the extended model.
#[test]
fn a_lever_arm_an_offset_fits_as_well_is_a_class_with_it() {
    let (c, e) = all_600_case(13);
    let words = e.summary.join("\n");
    assert_eq!(c.term.as_deref(), Some("lever_x"), "{c:?}");
    let f = e
        .findings
        .iter()
        .find(|f| f.term == "lever_x")
        .unwrap_or_else(|| panic!("no lever arm fitted:\n{words}"));
    assert!(f.stand_in.is_none(), "a stand-in:\n{words}");
    assert!(f.not_attributed.is_some(), "named a cause:\n{words}");
    let dt = f
        .equivalent_estimates
        .iter()
        .find(|q| q.term == "dt_gnss")
        .unwrap_or_else(|| panic!("no offset in its class:\n{words}"));
    assert!(dt.estimate.abs() > 3.0 * dt.sigma, "{dt:?}");
    assert!(
        (f.estimate - c.truth.unwrap()).abs() <= 2.0 * f.sigma,
        "{c:?}"
    );
    assert!(c.detected && !c.wrong_term, "{c:?}");
    assert_eq!(e.extended_model, e.baseline_model, "{words}");
    assert!(
        words.contains("Fitted, not attributed: GNSS lever arm lever_x"),
        "{words}"
    );
}

#[test]
fn merged_cases_are_checked_like_any_input() {
    let (a, _) = eval("chk_a", &["--cases", "3"]);
    let (b, _) = eval("chk_b", &["--cases", "2", "--first", "5"]);
    let merge = |dirs: &[&Path]| {
        let out = tmp("chk_out");
        let mut args = vec!["explain-eval", "--merge"];
        args.extend(dirs.iter().map(|d| d.to_str().unwrap()));
        args.extend(["--out", out.to_str().unwrap()]);
        let r = sinsmodel(&args);
        let _ = std::fs::remove_dir_all(&out);
        r
    };
    // a gap between shards: cases 3–4 were never run
    let (ok, err) = merge(&[a.as_path(), b.as_path()]);
    assert!(!ok && err.contains("cases 3–4 are missing"), "{err}");
    assert!(err.contains("--first 3 --cases 2"), "{err}");
    // the first detected hidden term of shard a, edited one field at a time
    let stored = json(&a.join("cases.json"));
    let k = stored["cases"]
        .as_array()
        .unwrap()
        .iter()
        .position(|c| c["term"].is_string() && c["detected"] == true && c["sigma"].is_number())
        .expect("seed 3 finds a hidden term in its first three cases");
    let index = stored["cases"][k]["index"].as_u64().unwrap();
    let edited = tmp("chk_edit");
    let edits: [(&str, serde_json::Value, &str); 15] = [
        (
            "stand_ins",
            serde_json::json!(["size_z", "size_z"]),
            "`size_z` is there twice",
        ),
        ("seconds_taken", serde_json::json!(1e300), "at most a day"),
        (
            "also_hidden",
            serde_json::json!(["kas_x"]),
            "also_hidden [kas_x]",
        ),
        (
            "noise_misstated",
            serde_json::json!(["gyro_arw"]),
            "noise_misstated [gyro_arw]",
        ),
        ("lambda", serde_json::json!(-5.0), "lambda -5"),
        (
            "lambda",
            serde_json::json!(1e300),
            "outside the campaign's range",
        ),
        ("group", serde_json::json!("zzz"), "group `zzz`"),
        (
            "term",
            serde_json::json!("nosuch_term"),
            "term `nosuch_term`",
        ),
        ("sigma", serde_json::json!(0.0), "sigma 0"),
        ("sigma", serde_json::json!(-1.0), "sigma -1"),
        ("truth", serde_json::json!(0.0), "truth 0"),
        ("named", serde_json::json!(["no_such"]), "named: `no_such`"),
        ("named", serde_json::json!([]), "named is empty"),
        ("noise_named", serde_json::json!(["loud"]), "noise_named"),
        (
            "candidates_tested",
            serde_json::json!(100_000),
            "candidates_tested",
        ),
    ];
    for (field, value, says) in edits {
        let mut v = stored.clone();
        v["cases"][k][field] = value.clone();
        std::fs::create_dir_all(&edited).unwrap();
        std::fs::write(edited.join("cases.json"), v.to_string()).unwrap();
        let (ok, err) = merge(&[edited.as_path()]);
        assert!(!ok, "{field} = {value} was merged: {err}");
        for part in [
            "chk_edit/cases.json",
            &format!("case {index} (entry {} of 3)", k + 1),
            says,
        ] {
            assert!(
                err.contains(part),
                "{field} = {value}: lacks `{part}`: {err}"
            );
        }
        assert!(!err.contains("inf %"), "{err}");
    }
    // a field left out is refused, not read as empty or 0; so are settings no run writes
    for field in ["stand_ins", "gain_recovery", "estimate"] {
        let mut v = stored.clone();
        v["cases"][k].as_object_mut().unwrap().remove(field);
        std::fs::write(edited.join("cases.json"), v.to_string()).unwrap();
        let (ok, err) = merge(&[edited.as_path()]);
        assert!(
            !ok && err.contains(&format!("missing field `{field}`")),
            "{field}: {err}"
        );
    }
    for (field, value, says) in [
        (
            "groups",
            serde_json::json!(["d", "nosuch"]),
            "unknown group `nosuch`",
        ),
        ("seconds", serde_json::json!(10.0), "seconds 10"),
        ("null_fraction", serde_json::json!(0.5), "null_fraction 0.5"),
    ] {
        let mut v = stored.clone();
        v["spec"][field] = value;
        std::fs::write(edited.join("cases.json"), v.to_string()).unwrap();
        let (ok, err) = merge(&[edited.as_path()]);
        assert!(!ok && err.contains(says), "spec.{field}: {err}");
    }
    // contradictory flags: not detected, a wrong term, nothing named
    let mut v = stored.clone();
    v["cases"][k]["named"] = serde_json::json!([]);
    v["cases"][k]["detected"] = serde_json::json!(false);
    v["cases"][k]["wrong_term"] = serde_json::json!(true);
    std::fs::write(edited.join("cases.json"), v.to_string()).unwrap();
    let (ok, err) = merge(&[edited.as_path()]);
    assert!(!ok && err.contains("wrong_term = true"), "{err}");
    // a wrong term where only the hidden one was named
    let mut v = stored.clone();
    v["cases"][k]["named"] = serde_json::json!([stored["cases"][k]["term"].clone()]);
    v["cases"][k]["wrong_term"] = serde_json::json!(true);
    std::fs::write(edited.join("cases.json"), v.to_string()).unwrap();
    let (ok, err) = merge(&[edited.as_path()]);
    assert!(
        !ok && err.contains("named holds only the hidden term"),
        "{err}"
    );
    // the truth with the other sign than the draw puts the term in with
    let mut v = stored.clone();
    let truth = stored["cases"][k]["truth"].as_f64().unwrap();
    v["cases"][k]["truth"] = serde_json::json!(-truth);
    std::fs::write(edited.join("cases.json"), v.to_string()).unwrap();
    let (ok, err) = merge(&[edited.as_path()]);
    assert!(
        !ok && err.contains("puts its term in with the")
            && (err.contains("positive sign") || err.contains("negative sign")),
        "{err}"
    );
    // the same term named twice; a term named while no candidate was tested; a field no
    // release writes
    let term = stored["cases"][k]["term"].clone();
    for (field, value, says) in [
        ("named", serde_json::json!([term, term]), "is there twice"),
        (
            "candidates_tested",
            serde_json::json!(0),
            "candidates_tested 0",
        ),
        (
            "extra_field",
            serde_json::json!(1),
            "unknown field `extra_field`",
        ),
    ] {
        let mut v = stored.clone();
        v["cases"][k][field] = value;
        std::fs::write(edited.join("cases.json"), v.to_string()).unwrap();
        let (ok, err) = merge(&[edited.as_path()]);
        assert!(!ok && err.contains(says), "{field}: {err}");
    }
    // fields no release writes beside the cases: in the campaign settings, at the top
    for at in ["spec", ""] {
        let mut v = stored.clone();
        match at {
            "" => v["bogus_top"] = serde_json::json!(1),
            _ => v[at]["bogus"] = serde_json::json!(1),
        }
        std::fs::write(edited.join("cases.json"), v.to_string()).unwrap();
        let (ok, err) = merge(&[edited.as_path()]);
        assert!(!ok && err.contains("unknown field `bogus"), "{at}: {err}");
    }
    // the shards as written merge (with the missing ones run)
    let (c, _) = eval("chk_c", &["--cases", "2", "--first", "3"]);
    let (ok, err) = merge(&[a.as_path(), b.as_path(), c.as_path()]);
    assert!(ok, "{err}");
    for d in [a, b, c, edited] {
        std::fs::remove_dir_all(d).unwrap();
    }
}

/// Under an address-space limit (`ulimit -v` 150 MB) two jobs fit (one malloc arena; they
/// aborted on a failed allocation, leaving the staging directory), more jobs than fit are refused
/// before any work naming --jobs, and neither leaves anything beside --out.
#[test]
fn jobs_under_an_address_space_limit_fit_or_are_refused() {
    let dir = tmp("ulimit");
    std::fs::create_dir_all(&dir).unwrap();
    let run = |jobs: &str| {
        let out = Command::new("bash")
            .arg("-c")
            .arg(format!(
                "ulimit -v 150000 && exec \"$0\" explain-eval --cases 2 --seconds 300 --jobs {jobs} --out \"$1\""
            ))
            .arg(env!("CARGO_BIN_EXE_sinsmodel"))
            .arg(dir.join(format!("j{jobs}")))
            .output()
            .expect("run bash");
        (
            out.status.code(),
            String::from_utf8_lossy(&out.stderr).into_owned(),
        )
    };
    let (code, err) = run("2");
    assert_eq!(code, Some(0), "{err}");
    assert!(dir.join("j2/eval.json").exists());
    let (code, err) = run("8");
    assert_eq!(code, Some(2), "{err}");
    assert!(
        err.contains("--jobs 8") && err.contains("ulimit -v") && err.contains("room for"),
        "{err}"
    );
    let mut left: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    left.sort();
    assert_eq!(left, ["j2"], "left beside --out");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Developer probe: `EVAL_SEED=7 EVAL_INDEX=10 [EVAL_SECONDS=600] [EVAL_GROUPS=all] cargo test
/// --release --test explain_eval -- --ignored probe_case --nocapture` prints one campaign
/// case's result and explain's summary.
#[test]
#[ignore]
fn probe_case() {
    use sinsmodel::experiment::explain_eval::{default_options, run_case_explained, EvalSpec};
    let var = |k: &str| std::env::var(k).ok();
    let mut spec = EvalSpec {
        seed: var("EVAL_SEED").and_then(|s| s.parse().ok()).unwrap_or(7),
        seconds: var("EVAL_SECONDS")
            .and_then(|s| s.parse().ok())
            .unwrap_or(600.0),
        ..EvalSpec::default()
    };
    if let Some(g) = var("EVAL_GROUPS") {
        spec.groups = if g == "all" {
            sinsmodel::sim::hidden::all_groups()
                .iter()
                .map(|s| s.to_string())
                .collect()
        } else {
            g.split(',').map(str::to_string).collect()
        };
    }
    let index = var("EVAL_INDEX").and_then(|s| s.parse().ok()).unwrap_or(0);
    let (c, e) = run_case_explained(&spec, index, &default_options()).expect("the case runs");
    eprintln!("{}", serde_json::to_string_pretty(&c).unwrap());
    for s in &e.summary {
        eprintln!("  {s}");
    }
}

/// Where the power below λ = 50 goes: `EVAL_SEED=7 cargo test --release --test explain_eval --
/// --ignored probe_power --nocapture` runs the cases of a stored campaign (`EVAL_CASES`,
/// default docs/explain-eval/sensor-600/cases.json) with 10 ≤ λ < 50 and prints, for each, the
/// hidden term's first test (llr with the quasi-likelihood, Holm p, the number tested) beside
/// what explain named and what it left unconfirmed.
#[test]
#[ignore]
fn probe_power() {
    use sinsmodel::experiment::explain_eval::{default_options, run_case_explained, EvalSpec};
    let var = |k: &str| std::env::var(k).ok();
    let path = var("EVAL_CASES").unwrap_or_else(|| {
        concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/docs/explain-eval/sensor-600/cases.json"
        )
        .into()
    });
    let stored: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    let spec: EvalSpec = serde_json::from_value(stored["spec"].clone()).unwrap();
    let only: Option<Vec<usize>> =
        var("EVAL_INDICES").map(|s| s.split(',').map(|x| x.parse().unwrap()).collect());
    for c in stored["cases"].as_array().unwrap() {
        if only
            .as_ref()
            .is_some_and(|o| !o.contains(&(c["index"].as_u64().unwrap() as usize)))
        {
            continue;
        }
        let Some(lambda) = c["lambda"].as_f64() else {
            continue;
        };
        if !(10.0..50.0).contains(&lambda) {
            continue;
        }
        let index = c["index"].as_u64().unwrap() as usize;
        let (r, e) = run_case_explained(&spec, index, &default_options()).unwrap();
        let tested = e.candidates.iter().filter(|t| t.testable).count();
        // every hidden term's first test (the weakest sets the case's λ)
        let first: Vec<String> = r
            .term
            .iter()
            .chain(&r.also_hidden)
            .map(|term| {
                let t = e.candidates.iter().find(|t| &t.term == term);
                format!(
                    "{term} first llr {:.1} p_holm {:.3e}",
                    t.map_or(f64::NAN, |t| t.llr),
                    t.map_or(f64::NAN, |t| t.p_holm)
                )
            })
            .collect();
        eprintln!(
            "PROBE {index} λ {lambda:.1} {} m {tested} phi {:.3} | named {:?} stand_ins {:?} unconfirmed {:?} detected {}",
            first.join(", "),
            e.baseline.nis_mean,
            r.named,
            r.stand_ins,
            e.unconfirmed,
            r.detected
        );
    }
}

/// An aiding σ that other fixes' misfit takes up is no finding about those fixes: all-600's
/// case 73 (seed 11) states the gyro's white noise too small and nothing else; explain names the
/// gyro level and also fitted the velocity fixes' σ above the σ they state (true: as stated),
/// named until a fix's level had to be borne out by its own innovations.
#[test]
fn an_aiding_sigma_its_own_fixes_do_not_bear_out_is_not_named() {
    let (c, e) = all_600_case(73);
    assert_eq!(c.noise_misstated, vec!["gyro_arw".to_string()], "{c:?}");
    let words = e.summary.join("\n");
    let named: Vec<&String> = c
        .noise_named
        .iter()
        .filter(|l| !c.noise_stand_ins.contains(l))
        .collect();
    assert_eq!(named, vec!["gyro_arw"], "{c:?}\n{words}");
    assert_eq!(c.noise_stand_ins, vec!["sigma_vel_ne".to_string()], "{c:?}");
    assert!(
        words.contains("vel_ne fixes' own innovations do not bear it out"),
        "{words}"
    );
}

/// The rule above costs no power where a fix's σ is truly misstated: on a drive (P13, the
/// noise stated right) the velocity fixes' σ is stated half what they carry, or twice, or the
/// horizontal position fixes' half (with the velocity fixes, and without); explain names that
/// level within 10 % of the true scale, not as a stand-in, and no other level, and names no
/// level when every σ is stated right. (Measured over 16 seeds, `aiding_sigma_scan`: named in
/// 32 of 32, the 95 % interval holds the true 2× in 27 of 32: the velocity fixes' intervals
/// are too narrow when the accelerometer noise took part of their misfit in the joint fit.)
#[test]
fn a_misstated_aiding_sigma_is_named_near_its_scale() {
    use sinsmodel::experiment::hidden::{run_hidden_on, simulate_case};
    use sinsmodel::sim::hidden::{generate, CaseKind};
    let case = generate(5, CaseKind::One("noise_gyro"), 600.0, 0.0);
    let (sim, aid) = simulate_case(&case).expect("the case simulates");
    // (the last: position fixes only, whose σ is stated half; before a refitted level was
    // tested again, a level fitted beside it could keep the gain of the joint fit)
    let levels = [
        ("sigma_vel_ne", 0.5),
        ("sigma_vel_ne", 2.0),
        ("sigma_pos_ne", 0.5),
        ("none", 1.0),
        ("sigma_pos_ne only", 0.5),
    ];
    for (label, stated_over_true) in levels {
        let level = label.trim_end_matches(" only");
        let mut stated = aid.clone();
        for a in &mut stated {
            if label.ends_with(" only") {
                a.vel = None;
            }
            match level {
                "sigma_vel_ne" => a.vel.as_mut().expect("velocity fixes").1 *= stated_over_true,
                "sigma_pos_ne" => {
                    let s = &mut a.pos.as_mut().expect("position fixes").3;
                    s[0] *= stated_over_true;
                    s[1] *= stated_over_true;
                }
                _ => {}
            }
        }
        let opts = sinsmodel::explain::ExplainOptions::default();
        let out = run_hidden_on(&case, &sim, &stated, &opts).expect("explain runs");
        let e = &out.explanation;
        let words = e.summary.join("\n");
        // every noise level named as a cause (the sensors' are stated right)
        let named: Vec<&str> = e
            .findings
            .iter()
            .filter(|f| f.kind == "noise" && f.is_cause())
            .map(|f| f.term.as_str())
            .collect();
        if level == "none" {
            assert!(named.is_empty(), "{named:?} named:\n{words}");
            continue;
        }
        assert_eq!(
            named,
            vec![level],
            "{label} stated {stated_over_true}×:\n{words}"
        );
        let f = e.findings.iter().find(|f| f.term == level).expect("named");
        let truth = 1.0 / stated_over_true;
        let scale = f.scale.expect("a noise finding's scale");
        assert!(
            (scale / truth - 1.0).abs() < 0.1,
            "{level}: fitted {scale}× for a true {truth}×:\n{words}"
        );
    }
}

/// Measurement probe (the figures in docs/explain.md and the test above): seeds 1–16 of the
/// drive with the velocity or the horizontal position fixes' σ stated half what they carry;
/// counts the seeds where the level is named (not a stand-in) and where its 95 % interval holds
/// the true 2×. `cargo test --release --test explain_eval -- --ignored aiding_sigma_scan
/// --nocapture`
#[test]
#[ignore]
fn aiding_sigma_scan() {
    use sinsmodel::experiment::hidden::{run_hidden_on, simulate_case};
    use sinsmodel::sim::hidden::{generate, CaseKind};
    let opts = sinsmodel::explain::ExplainOptions::default();
    let (mut named, mut covered, mut runs) = (0, 0, 0);
    for seed in 1..=16 {
        let case = generate(seed, CaseKind::One("noise_gyro"), 600.0, 0.0);
        let (sim, aid) = simulate_case(&case).expect("the case simulates");
        for level in ["sigma_vel_ne", "sigma_pos_ne"] {
            let mut stated = aid.clone();
            for a in &mut stated {
                if level == "sigma_vel_ne" {
                    a.vel.as_mut().expect("velocity fixes").1 *= 0.5;
                } else {
                    let s = &mut a.pos.as_mut().expect("position fixes").3;
                    s[0] *= 0.5;
                    s[1] *= 0.5;
                }
            }
            let out = run_hidden_on(&case, &sim, &stated, &opts).expect("explain runs");
            runs += 1;
            let found = out
                .explanation
                .findings
                .iter()
                .find(|f| f.term == level && f.stand_in.is_none());
            let interval = found.and_then(|f| f.scale_interval);
            named += usize::from(found.is_some());
            covered += usize::from(interval.is_some_and(|[lo, hi]| lo <= 2.0 && 2.0 <= hi));
            eprintln!(
                "seed {seed} {level}: {:?} {interval:?}",
                found.and_then(|f| f.scale)
            );
        }
    }
    eprintln!("named {named} of {runs}; the 95 % interval holds the true 2× in {covered}");
}

/// How much of the put-in term the first test sees: `EVAL_CASES=…/cases.json [EVAL_GROUPS_ONLY=size,kas]
/// cargo test --release --test explain_eval -- --ignored probe_efficiency --nocapture` runs
/// each sensor case of a stored campaign twice, with the term put in and without (the same
/// noise), and prints the first test's GLR estimate of the hidden term on each: their
/// difference over the value put in is the share of the term the signature sees (1 when the
/// linearised per-step signature is the effect's), and ((difference)/σ)² the first test's own
/// noncentrality beside the λ drawn.
#[test]
#[ignore]
fn probe_efficiency() {
    use sinsmodel::experiment::explain_eval::{default_options, prepare, EvalSpec};
    use sinsmodel::experiment::hidden::{run_hidden_on, simulate_case};
    let var = |k: &str| std::env::var(k).ok();
    let path = var("EVAL_CASES").expect("EVAL_CASES: a stored campaign's cases.json");
    let stored: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    let spec: EvalSpec = serde_json::from_value(stored["spec"].clone()).unwrap();
    let only: Option<Vec<String>> =
        var("EVAL_GROUPS_ONLY").map(|s| s.split(',').map(str::to_string).collect());
    let mut opts = default_options();
    opts.alpha = spec.alpha;
    for c in stored["cases"].as_array().unwrap() {
        let group = c["group"].as_str().unwrap().to_string();
        if c["lambda"].is_null() || only.as_ref().is_some_and(|o| !o.contains(&group)) {
            continue;
        }
        let index = c["index"].as_u64().unwrap() as usize;
        let (drawn, (case, sim, aid)) = prepare(&spec, index).unwrap();
        let (name, theta) = case.hidden[0].clone();
        let glr = |sim: &sinsmodel::sim::simulator::SimOutput| {
            let e = run_hidden_on(&case, sim, &aid, &opts).unwrap().explanation;
            let t = e.candidates.iter().find(|t| t.term == name).cloned();
            t.map_or((f64::NAN, f64::NAN, f64::NAN), |t| {
                (t.glr_estimate, t.glr_sigma, t.llr)
            })
        };
        let (g1, s1, l1) = glr(&sim);
        let (sim0, _) = simulate_case(&case).unwrap();
        let (g0, _, l0) = glr(&sim0);
        let info = sinsmodel::model::generated::common::TERMS
            .iter()
            .find(|t| t.name == name)
            .unwrap();
        let truth = theta / info.display_to_si;
        eprintln!(
            "EFF {index} {group} {name} λ {:.1} share {:.3} λ_test {:.1} llr {l1:.1} (without {l0:.1}) truth {truth:.4} glr {g1:.4} without {g0:.4} σ {s1:.4}",
            drawn.lambda.unwrap(),
            (g1 - g0) / truth,
            ((g1 - g0) / s1).powi(2),
        );
    }
}
