//! What a newcomer reads in the terminal and in the output files: channels named with their
//! expected NIS, provenance headers in the CLI's words, options named in errors, full state
//! names, fits the data do not support said as such.

mod common;
use common::sinsmodel;

use std::path::Path;

fn p(path: &Path) -> &str {
    path.to_str().unwrap()
}

/// A 2-minute static scenario with GNSS, simulated into `dir/sim`.
fn simulate_short_static(dir: &Path) -> std::path::PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(root.join("scenarios/static.toml")).unwrap();
    assert!(text.contains("duration_s = 7200.0"));
    let scen = dir.join("short.toml");
    std::fs::write(
        &scen,
        text.replace("duration_s = 7200.0", "duration_s = 120.0"),
    )
    .unwrap();
    let sim = dir.join("sim");
    let (ok, _, err) = sinsmodel(&["simulate", p(&scen), "--out", p(&sim)]);
    assert!(ok, "{err}");
    sim
}

#[test]
fn filter_reports_nis_per_channel_and_writes_provenance_headers() {
    let tmp = tempfile::tempdir().unwrap();
    let sim = simulate_short_static(tmp.path());
    let out = tmp.path().join("f");
    let (ok, _, err) = sinsmodel(&[
        "filter",
        "--model",
        "P13",
        "--imu",
        p(&sim.join("imu.txt")),
        "--aid",
        p(&sim.join("gnss.txt")),
        "--truth",
        p(&sim.join("truth.txt")),
        "--mode",
        "closed",
        "--out",
        p(&out),
    ]);
    assert!(ok, "{err}");
    // one line per channel with its count, mean NIS, band and a verdict
    for ch in ["pos_n", "pos_e"] {
        let line = err
            .lines()
            .find(|l| l.trim_start().starts_with(ch))
            .unwrap_or_else(|| panic!("no {ch} line in:\n{err}"));
        assert!(line.contains("mean NIS") && line.contains("band"), "{line}");
        assert!(
            ["consistent", "too large", "too small"]
                .iter()
                .any(|v| line.contains(v)),
            "{line}"
        );
    }
    assert!(err.contains("1 for a consistent filter"), "{err}");
    assert!(
        err.contains("model_error.txt") && err.contains(p(&out)),
        "{err}"
    );
    for f in ["states.txt", "innovations.txt", "model_error.txt"] {
        let text = std::fs::read_to_string(out.join(f)).unwrap();
        let first = text.lines().next().unwrap();
        assert!(
            first.starts_with("# sinsmodel filter --model P13") && first.contains("--mode closed"),
            "{f}: {first}"
        );
        let header: String = text.lines().take_while(|l| l.starts_with('#')).collect();
        for debug_name in ["ClosedLoop", "OpenLoop", "Fixed", "Gyro", "Accel"] {
            assert!(!header.contains(debug_name), "{f}: {header}");
        }
        assert!(!text.contains("NaN") && !text.contains("inf"), "{f}");
    }
    let states = std::fs::read_to_string(out.join("states.txt")).unwrap();
    assert!(states.lines().nth(1).unwrap().contains("mode closed"));
}

#[test]
fn navigate_names_its_inputs_and_reports_the_drift() {
    let tmp = tempfile::tempdir().unwrap();
    let sim = simulate_short_static(tmp.path());
    let imu = sim.join("imu.txt");
    let out = tmp.path().join("nav.txt");
    // without --att: the missing option is named
    let (ok, _, err) = sinsmodel(&[
        "navigate",
        "--imu",
        p(&imu),
        "--lat",
        "28.22",
        "--lon",
        "112.99",
        "--out",
        p(&out),
    ]);
    assert!(!ok && err.contains("--att"), "{err}");
    let (ok, _, err) = sinsmodel(&[
        "navigate",
        "--imu",
        p(&imu),
        "--lat",
        "28.22",
        "--lon",
        "112.99",
        "--att",
        "nan,0,0",
        "--out",
        p(&out),
    ]);
    assert!(!ok && err.contains("--att"), "{err}");
    for (opt, bad) in [("--att", "0,95,0"), ("--lon", "nan"), ("--h", "inf")] {
        let mut a = vec![
            "navigate",
            "--imu",
            p(&imu),
            "--lat",
            "28.22",
            "--lon",
            "112.99",
            "--att",
            "0,0,0",
            "--out",
            p(&out),
        ];
        match a.iter().position(|x| *x == opt) {
            Some(k) => a[k + 1] = bad,
            None => a.extend([opt, bad]),
        }
        let (ok, _, err) = sinsmodel(&a);
        assert!(!ok && err.contains(opt), "{opt} {bad}: {err}");
    }
    let (ok, _, err) = sinsmodel(&[
        "navigate",
        "--imu",
        p(&imu),
        "--lat",
        "28.22",
        "--lon",
        "112.99",
        "--att",
        "0,0,0",
        "--out",
        p(&out),
    ]);
    assert!(ok, "{err}");
    assert!(
        err.contains("from the start") && err.contains("free-inertial"),
        "{err}"
    );
    let first = std::fs::read_to_string(&out).unwrap();
    assert!(first.contains("vertical fixed"), "{first}");
    assert!(!first.contains("Fixed"));
}

#[test]
fn noise_file_errors_name_the_option() {
    let tmp = tempfile::tempdir().unwrap();
    let sim = simulate_short_static(tmp.path());
    let missing = tmp.path().join("missing.json");
    let (ok, _, err) = sinsmodel(&[
        "filter",
        "--model",
        "P13",
        "--imu",
        p(&sim.join("imu.txt")),
        "--aid",
        p(&sim.join("gnss.txt")),
        "--truth",
        p(&sim.join("truth.txt")),
        "--noise",
        p(&missing),
        "--out",
        p(&tmp.path().join("f")),
    ]);
    assert!(!ok, "{err}");
    assert!(
        err.contains("--noise") && err.contains("missing.json"),
        "{err}"
    );
}

#[test]
fn model_show_keeps_long_state_names_in_the_sparsity_picture() {
    let (ok, out, _) = sinsmodel(&["model", "show", "P28+kaq_x_xy+kgf_xz"]);
    assert!(ok);
    let pic = &out[out.find("Sparsity of A").unwrap()..];
    for name in ["kaq_x_xy", "kgf_xz", "nabla_x"] {
        assert!(
            pic.lines()
                .any(|l| l.split_whitespace().nth(1) == Some(name)),
            "{name} missing in:\n{pic}"
        );
    }
    let (ok, out, _) = sinsmodel(&["model", "list"]);
    assert!(
        ok && out.contains(" gyro ") && !out.contains("Gyro"),
        "{out}"
    );
}
