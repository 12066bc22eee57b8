//! The `sinsmodel` binary: model listing, model show, jacobian output and its input errors.

mod common;
use common::sinsmodel;

#[test]
fn model_show_p31_lists_the_canonical_states_in_order() {
    let (ok, out, _) = sinsmodel(&["model", "show", "P31"]);
    assert!(ok);
    let names: Vec<&str> = out
        .lines()
        .filter_map(|l| {
            let mut it = l.split_whitespace();
            let idx = it.next()?.parse::<usize>().ok()?;
            let name = it.next()?;
            it.next()?.starts_with('[').then_some((idx, name))
        })
        .map(|(_, n)| n)
        .collect();
    let want = "phi_n phi_e phi_d dv_n dv_e dlat dlon eps_x eps_y eps_z nabla_x nabla_y nabla_z \
                kg_11 kg_21 kg_31 kg_22 kg_32 kg_33 ka_11 ka_21 ka_31 ka_12 ka_22 ka_32 ka_13 ka_23 ka_33 d_x d_y d_z";
    assert_eq!(names.join(" "), want);
    assert!(out.contains("Model P31: 31 states"));
    assert!(out.contains("A: 81 structural non-zeros"), "{out}");
    assert!(out.contains("H pos_ne: 2 non-zeros"));
}

#[test]
fn model_list_shows_presets_and_library_terms_with_units() {
    let (ok, out, _) = sinsmodel(&["model", "list"]);
    assert!(ok);
    for needle in [
        "P13", "P24", "P28", "P31", "kaq_x_xy", "kgf_zz", "size_z", "deg/h", "ug/g^2",
    ] {
        assert!(out.contains(needle), "missing {needle}");
    }
}

#[test]
fn jacobian_prints_dense_a_and_h() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("point.json");
    std::fs::write(
        &p,
        r#"{"lat_deg": 28.22, "h_m": 0, "v_ned": [0,0,0], "euler_deg": [0,0,0], "f_b": [0,0,-9.79], "w_b": [0,0,0]}"#,
    )
    .unwrap();
    let (ok, out, err) = sinsmodel(&[
        "jacobian",
        "--model",
        "P28+kaq_x_xy",
        "--at",
        p.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["states"].as_array().unwrap().len(), 29);
    assert_eq!(v["a"].as_array().unwrap().len(), 29);
    // level, at rest: dv_e/phi_n = f_D = -g
    assert!((v["a"][4][0].as_f64().unwrap() + 9.79).abs() < 1e-12);
    assert_eq!(v["h"]["vel_ne"][0][3].as_f64(), Some(1.0));
    let rm = v["h"]["pos_ne"][0][5].as_f64().unwrap();
    assert!(rm > 6.33e6 && rm < 6.40e6, "{rm}");
}

#[test]
fn jacobian_rejects_bad_input_with_a_clear_message() {
    let dir = tempfile::tempdir().unwrap();
    let cases = [
        ("missing.json", None, "cannot read"),
        ("bad.json", Some("{\"lat_deg\": 1,"), "not valid JSON"),
        (
            "field.json",
            Some(
                r#"{"lat_deg": 1, "h_m": 0, "v_ned": [0,0,0], "euler_deg": [0,0,0], "f_b": [0,0,-9.8]}"#,
            ),
            "missing field `w_b`",
        ),
        (
            "lat.json",
            Some(
                r#"{"lat_deg": 95, "h_m": 0, "v_ned": [0,0,0], "euler_deg": [0,0,0], "f_b": [0,0,-9.8], "w_b": [0,0,0]}"#,
            ),
            "outside",
        ),
    ];
    for (name, text, needle) in cases {
        let p = dir.path().join(name);
        if let Some(t) = text {
            std::fs::write(&p, t).unwrap();
        }
        let (ok, _, err) = sinsmodel(&["jacobian", "--model", "P31", "--at", p.to_str().unwrap()]);
        assert!(!ok, "{name} accepted");
        assert!(err.contains(needle) && err.contains(name), "{name}: {err}");
        assert!(!err.contains("panicked"), "{err}");
    }
    let (ok, _, err) = sinsmodel(&["model", "show", "P32"]);
    assert!(!ok && err.contains("unknown preset `P32`"), "{err}");
}

/// scenarios/drive.toml simulated into a temporary directory: (the directory, the run's folder).
fn simulated_drive() -> (tempfile::TempDir, std::path::PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let sim = dir.path().join("drive");
    let (ok, _, err) = sinsmodel(&[
        "simulate",
        root.join("scenarios/drive.toml").to_str().unwrap(),
        "--out",
        sim.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    (dir, sim)
}

/// `--outage START,DURATION`: the fixes inside are dropped and the drift at the first fix after
/// it is reported (terminal table and outages.json), finite and growing with the outage.
#[test]
fn filter_outages_drop_aiding_and_report_the_drift() {
    let (dir, sim) = simulated_drive();
    let s = |n: &str| sim.join(n).to_str().unwrap().to_string();
    let run = |outages: &[&str], out: &str| {
        let mut a = vec![
            "filter".to_string(),
            "--model".into(),
            "P28".into(),
            "--imu".into(),
            s("imu.txt"),
            "--aid".into(),
            s("gnss.txt"),
            "--truth".into(),
            s("truth.txt"),
            "--out".into(),
            dir.path().join(out).to_str().unwrap().to_string(),
        ];
        for o in outages {
            a.push("--outage".into());
            a.push(o.to_string());
        }
        let refs: Vec<&str> = a.iter().map(|x| x.as_str()).collect();
        sinsmodel(&refs)
    };
    let (ok, _, err) = run(&["80,10", "120,40"], "with");
    assert!(ok, "{err}");
    assert!(err.contains("GNSS outages: drift"), "{err}");
    let json: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(dir.path().join("with/outages.json")).unwrap(),
    )
    .unwrap();
    let rows = json["outages"].as_array().unwrap();
    assert_eq!(rows.len(), 2);
    let drift: Vec<f64> = rows
        .iter()
        .map(|r| r["drift_horizontal_m"].as_f64().unwrap())
        .collect();
    assert!(drift.iter().all(|d| d.is_finite() && *d > 0.0), "{drift:?}");
    assert!(
        drift[1] > drift[0],
        "a 40 s outage drifts more than a 10 s one: {drift:?}"
    );
    // the fixes inside the outages were not used: 50 fewer epochs of pos_ne (2 components)
    let count = |d: &str| {
        std::fs::read_to_string(dir.path().join(d).join("innovations.txt"))
            .unwrap()
            .lines()
            .filter(|l| l.contains(" pos_ne "))
            .count()
    };
    let (ok, _, err) = run(&[], "without");
    assert!(ok, "{err}");
    assert_eq!(count("without") - count("with"), 2 * 50);
    // an outage past the data has nothing to measure against
    let (ok, _, err) = run(&["5000,10"], "late");
    assert!(
        !ok && err.contains("--outage") && err.contains("no position fix after it"),
        "{err}"
    );
    // malformed
    let (ok, _, err) = run(&["nan,10"], "bad");
    assert!(!ok && err.contains("--outage `nan,10`"), "{err}");
}

/// filter's nav.txt: the navigator corrected by the estimate, at --nav-rate, in the truth
/// layout with 1-σ columns; far closer to the truth than the uncorrected navigator (open loop),
/// and as close in closed loop; plots written.
#[test]
fn filter_writes_a_navigation_solution_with_sigmas() {
    let (dir, sim) = simulated_drive();
    let s = |n: &str| sim.join(n).to_str().unwrap().to_string();
    let read = |p: &std::path::Path| -> Vec<Vec<f64>> {
        std::fs::read_to_string(p)
            .unwrap()
            .lines()
            .filter(|l| !l.starts_with('#'))
            .map(|l| l.split_whitespace().map(|v| v.parse().unwrap()).collect())
            .collect()
    };
    let truth = read(&sim.join("truth.txt"));
    // horizontal position error [m] of rows against truth at the same times
    let err_m = |rows: &[Vec<f64>]| -> Vec<f64> {
        rows.iter()
            .filter_map(|r| {
                let tr = truth.iter().find(|t| (t[0] - r[0]).abs() < 1e-6)?;
                let d = std::f64::consts::PI / 180.0 * 6.378e6;
                Some(((r[1] - tr[1]) * d).hypot((r[2] - tr[2]) * d * tr[1].to_radians().cos()))
            })
            .collect()
    };
    let rms = |v: &[f64]| (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt();
    for mode in ["open", "closed"] {
        let out = dir.path().join(mode);
        let (ok, _, err) = sinsmodel(&[
            "filter",
            "--model",
            "P28",
            "--imu",
            &s("imu.txt"),
            "--aid",
            &s("gnss.txt"),
            "--truth",
            &s("truth.txt"),
            "--mode",
            mode,
            "--nav-rate",
            "10",
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(ok, "{err}");
        let nav = read(&out.join("nav.txt"));
        assert_eq!(nav.len(), 2201, "the start row, then 220 s at 10 Hz");
        // truth layout + sigma_n sigma_e sigma_vn sigma_ve sigma_tilt_n/e/d (no vertical states)
        assert!(nav
            .iter()
            .all(|r| r.len() == 17 && r.iter().all(|v| v.is_finite())));
        assert!(nav.iter().all(|r| r[10..].iter().all(|s| *s > 0.0)));
        let e = err_m(&nav);
        assert!(e.len() > 200);
        eprintln!("{mode}: nav.txt horizontal error RMS {:.3} m", rms(&e));
        assert!(rms(&e) < 0.5, "{mode}: {}", rms(&e));
        assert!(out.join("nav_track.png").exists() && out.join("nav_sigma.png").exists());
    }
    // the uncorrected navigator drifts far more over the same 220 s
    let raw = dir.path().join("raw.txt");
    let (ok, _, err) = sinsmodel(&[
        "navigate",
        "--imu",
        &s("imu.txt"),
        "--lat",
        "40.0966",
        "--lon",
        "-105.1474",
        "--h",
        "1601",
        "--att",
        "0,0,30",
        "--out",
        raw.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let raw_rms = rms(&err_m(&read(&raw)));
    eprintln!("navigate alone: horizontal error RMS {raw_rms:.3} m");
    assert!(raw_rms > 5.0 * 0.5, "{raw_rms}");
}

/// GNSS velocity aiding: an 11-column aiding file (or an RTKLIB .pos with velocities) adds
/// vel_ne updates with its σ; `--aid-use` chooses; asking for velocities a file lacks is refused.
#[test]
fn filter_uses_gnss_velocities_when_the_file_has_them() {
    let (dir, sim) = simulated_drive();
    // velocities from the truth at the fix times, σ 0.05 m/s
    let truth: Vec<Vec<f64>> = std::fs::read_to_string(sim.join("truth.txt"))
        .unwrap()
        .lines()
        .filter(|l| !l.starts_with('#'))
        .map(|l| l.split_whitespace().map(|v| v.parse().unwrap()).collect())
        .collect();
    let mut text = String::from("# t lat lon h sn se sd vn ve vd sv\n");
    for l in std::fs::read_to_string(sim.join("gnss.txt"))
        .unwrap()
        .lines()
    {
        if l.starts_with('#') {
            continue;
        }
        let t: f64 = l.split_whitespace().next().unwrap().parse().unwrap();
        let tr = truth.iter().find(|r| (r[0] - t).abs() < 1e-6).unwrap();
        text.push_str(&format!("{l} {} {} {} 0.05\n", tr[4], tr[5], tr[6]));
    }
    let aid11 = dir.path().join("aid11.txt");
    std::fs::write(&aid11, text).unwrap();
    let s = |n: &str| sim.join(n).to_str().unwrap().to_string();
    let filter = |aid: &str, extra: &[&str], out: &str| {
        let o = dir.path().join(out);
        let imu = s("imu.txt");
        let mut a = vec![
            "filter",
            "--model",
            "P28",
            "--imu",
            &imu,
            "--init",
            "40.0966,-105.1474,1601,0,0,30",
            "--aid",
            aid,
            "--out",
            o.to_str().unwrap(),
        ];
        a.extend_from_slice(extra);
        let r = sinsmodel(&a);
        let inn = std::fs::read_to_string(o.join("innovations.txt")).unwrap_or_default();
        (
            r,
            inn.matches(" vel_ne ").count(),
            inn.matches(" pos_ne ").count(),
        )
    };
    let ((ok, _, err), vel, pos) = filter(aid11.to_str().unwrap(), &[], "both");
    assert!(ok, "{err}");
    assert_eq!((vel, pos), (2 * 220, 2 * 220), "{err}");
    let ((ok, _, err), vel, pos) = filter(aid11.to_str().unwrap(), &["--aid-use", "vel"], "vel");
    assert!(ok, "{err}");
    assert_eq!((vel, pos), (2 * 220, 0));
    let ((ok, _, _), vel, _) = filter(aid11.to_str().unwrap(), &["--aid-use", "pos"], "pos");
    assert!(ok && vel == 0);
    let ((ok, _, err), _, _) = filter(&s("gnss.txt"), &["--aid-use", "vel"], "none");
    assert!(!ok && err.contains("has no velocity columns"), "{err}");
    let ((ok, _, err), _, _) = filter(aid11.to_str().unwrap(), &["--zupt", "0.1"], "zupt");
    assert!(!ok && err.contains("--zupt and GNSS velocity"), "{err}");
    // the shared RTKLIB solution carries velocities and their sigma
    let pos = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/data/gnss-imu-drive/gnss_1934_sf.pos");
    let e = sinsmodel::io::readers::rtklib::read(&pos).unwrap();
    assert!(e
        .iter()
        .all(|p| p.v_ned.is_some() && p.sigma_v_ne.is_some()));
}

/// `--grade`: the priors and noise of a sensor grade for every state, said on stderr; --prior
/// overrides single values; without it the run says it assumes the spec's navigation grade.
#[test]
fn filter_grade_sets_every_prior_and_says_so() {
    let (dir, sim) = simulated_drive();
    let s = |n: &str| sim.join(n).to_str().unwrap().to_string();
    let run = |extra: &[&str], out: &str| {
        let o = dir.path().join(out);
        let (imu, aid, truth) = (s("imu.txt"), s("gnss.txt"), s("truth.txt"));
        let mut a = vec![
            "filter",
            "--model",
            "P28",
            "--imu",
            &imu,
            "--aid",
            &aid,
            "--truth",
            &truth,
            "--out",
            o.to_str().unwrap(),
        ];
        a.extend_from_slice(extra);
        let (ok, _, err) = sinsmodel(&a);
        let states = std::fs::read_to_string(o.join("states.txt")).unwrap_or_default();
        let header: Vec<String> = states
            .lines()
            .find(|l| l.starts_with("# t "))
            .map(|l| l[2..].split_whitespace().map(String::from).collect())
            .unwrap_or_default();
        let first: Vec<f64> = states
            .lines()
            .find(|l| !l.starts_with('#'))
            .map(|l| l.split_whitespace().map(|v| v.parse().unwrap()).collect())
            .unwrap_or_default();
        let sigma = move |name: &str| {
            let k = header
                .iter()
                .position(|h| h == &format!("sigma_{name}"))
                .unwrap();
            first[k]
        };
        (ok, err, sigma)
    };
    let (ok, err, sigma) = run(&[], "nav");
    assert!(ok && err.contains("navigation grade"), "{err}");
    let nav_kg = sigma("kg_11");
    let (ok, err, sigma) = run(&["--grade", "mems", "--prior", "nabla_x=20 mg"], "mems");
    assert!(ok && err.contains("--grade mems"), "{err}");
    // the first epoch, 1 s in: unobserved terms keep their prior
    assert!(
        (sigma("kg_11") / 1e-2 - 1.0).abs() < 0.05,
        "{}",
        sigma("kg_11")
    );
    assert!(sigma("kg_11") > 100.0 * nav_kg);
    let g = 9.80665;
    assert!(
        (sigma("nabla_x") / (20e-3 * g) - 1.0).abs() < 0.2,
        "{}",
        sigma("nabla_x")
    );
    assert!(
        (sigma("nabla_y") / (50e-3 * g) - 1.0).abs() < 0.2,
        "{}",
        sigma("nabla_y")
    );
    let (ok, err, _) = run(&["--grade", "consumer"], "bad");
    assert!(!ok && err.contains("--grade `consumer`"), "{err}");
}
