//! Every command on a corpus of bad files: each case must end with exit status 2 and a short,
//! printable `error:` message that names the file (or option), never a panic, never an output
//! left behind; and the corpus's valid look-alikes (a byte-order mark, CR LF line ends) are read.
//!
//! The corpus is made here from a small simulated run (static, 100 Hz, 40 s) by breaking one
//! thing at a time, for every reader: IMU text, PSINS `.imu`, GNSS_IMU `.csv`, format
//! descriptions, aiding, truth, RTKLIB `.pos`, scenarios, Jacobian points, noise files.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::Mutex;

/// Every refusal's message, in order, for the golden comparison (`tests/golden/bad_corpus.txt`).
static MESSAGES: Mutex<Vec<String>> = Mutex::new(Vec::new());

/// Exit status, stderr.
fn run(args: &[&str]) -> (Option<i32>, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_sinsmodel"))
        .args(args)
        .output()
        .expect("run sinsmodel");
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// What every refused case must look like; a failure is recorded (all are reported at the end).
fn refused(case: &str, args: &[&str], must_name: &str, out: Option<&Path>) -> Result<(), String> {
    let (code, err) = run(args);
    MESSAGES
        .lock()
        .unwrap()
        .push(format!("{case} (exit {code:?}):\n{err}"));
    let fail = |what: &str| Err(format!("{case}: {what}\n{err}"));
    if err.contains("panicked") || err.contains("RUST_BACKTRACE") {
        return fail("panic");
    }
    if code != Some(2) {
        return fail(&format!("exit status {code:?}"));
    }
    if !err.contains("error:") {
        return fail("no error line");
    }
    if !err.contains(must_name) {
        return fail(&format!("the message does not name `{must_name}`"));
    }
    if err.contains('\u{1b}') || err.contains('\0') || err.contains('\u{feff}') {
        return fail("raw control characters echoed");
    }
    if err.len() >= 3000 {
        return Err(format!(
            "{case}: {} bytes of message (an input echoed in full?)",
            err.len()
        ));
    }
    if let Some(o) = out {
        if o.exists() {
            return fail(&format!("output {} left behind", o.display()));
        }
    }
    Ok(())
}

fn check(failures: &mut Vec<String>, r: Result<(), String>) {
    if let Err(e) = r {
        failures.push(e);
    }
}

struct Corpus {
    dir: tempfile::TempDir,
}

impl Corpus {
    fn path(&self, name: &str) -> PathBuf {
        self.dir.path().join(name)
    }
    fn write(&self, name: &str, bytes: impl AsRef<[u8]>) -> String {
        let p = self.path(name);
        std::fs::write(&p, bytes).unwrap();
        p.to_str().unwrap().to_string()
    }
}

/// Pseudo-random bytes (a fixed linear congruential sequence).
fn noise(n: usize, seed: u64) -> Vec<u8> {
    let mut x = seed;
    (0..n)
        .map(|_| {
            x = x
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (x >> 33) as u8
        })
        .collect()
}

/// Replaces the `k`-th data line (0-based, comments skipped) of `text` by `f(line)`.
fn edit_row(text: &str, k: usize, f: impl Fn(&str) -> String) -> String {
    let mut seen = 0usize;
    let mut out = String::new();
    for l in text.lines() {
        if !l.starts_with('#') && !l.trim().is_empty() {
            if seen == k {
                out.push_str(&f(l));
                out.push('\n');
                seen += 1;
                continue;
            }
            seen += 1;
        }
        out.push_str(l);
        out.push('\n');
    }
    out
}

/// Replaces field `c` (0-based) of a whitespace-separated line.
fn field(l: &str, c: usize, v: &str) -> String {
    let mut f: Vec<&str> = l.split_whitespace().collect();
    f[c] = v;
    f.join(" ")
}

/// Bad variants of a whitespace table with a time column: (name, content).
fn table_variants(good: &str, ncols_note: &str) -> Vec<(String, Vec<u8>)> {
    let long = "9".repeat(100_000);
    let mut v: Vec<(String, Vec<u8>)> = vec![
        ("empty".into(), Vec::new()),
        ("comments_only".into(), b"# nothing here\n".to_vec()),
        (
            "nan".into(),
            edit_row(good, 5, |l| field(l, 1, "nan")).into(),
        ),
        (
            "inf".into(),
            edit_row(good, 5, |l| field(l, 2, "-inf")).into(),
        ),
        (
            "huge".into(),
            edit_row(good, 5, |l| field(l, 1, "1e308")).into(),
        ),
        (
            "word".into(),
            edit_row(good, 5, |l| field(l, 3, "abc")).into(),
        ),
        (
            "escape".into(),
            edit_row(good, 5, |l| field(l, 2, "\u{1b}[31mred\u{1b}[0m")).into(),
        ),
        (
            "long_field".into(),
            edit_row(good, 5, |l| field(l, 2, &long)).into(),
        ),
        (
            "time_back".into(),
            edit_row(good, 5, |l| field(l, 0, "0.001")).into(),
        ),
        (
            "few_cols".into(),
            edit_row(good, 5, |l| {
                let f: Vec<&str> = l.split_whitespace().collect();
                f[..f.len() - 1].join(" ")
            })
            .into(),
        ),
        (
            "many_cols".into(),
            edit_row(good, 5, |l| format!("{l} 7")).into(),
        ),
        ("nul".into(), {
            let mut b = good.as_bytes().to_vec();
            let k = b.len() / 2;
            b[k] = 0;
            b
        }),
        ("non_utf8".into(), {
            let mut b = good.as_bytes().to_vec();
            let k = b.len() / 3;
            b[k] = 0xff;
            b
        }),
        ("binary".into(), noise(4096, 7)),
        ("one_long_line".into(), vec![b'1'; 3 << 20]),
    ];
    for (n, _) in v.iter_mut() {
        n.push_str(ncols_note);
    }
    v
}

fn simulated(c: &Corpus) -> (String, String, String) {
    let scenario = "name = \"corpus\"\nimu_rate_hz = 100.0\ntruth_rate_hz = 1.0\nseed = 3\n\
        [start]\nlat_deg = 30.0\nlon_deg = 110.0\n[[segment]]\nkind = \"rest\"\nduration_s = 40.0\n\
        [noise]\narw = \"0.01 deg/sqrt(h)\"\nvrw = \"10 ug/sqrt(Hz)\"\n\
        [gnss]\nrate_hz = 1.0\nsigma_ne = \"0.5 m\"\nsigma_d = \"1 m\"\n";
    let sc = c.write("scenario.toml", scenario);
    let sim = c.path("sim");
    let (code, err) = run(&["simulate", &sc, "--out", sim.to_str().unwrap()]);
    assert_eq!(code, Some(0), "{err}");
    let s = |n: &str| sim.join(n).to_str().unwrap().to_string();
    (s("imu.txt"), s("gnss.txt"), s("truth.txt"))
}

const INIT: &str = "30,110,0,0,0,0";

#[test]
fn every_command_refuses_every_bad_file_with_exit_2_and_a_clear_message() {
    let c = Corpus {
        dir: tempfile::tempdir().unwrap(),
    };
    let (imu, aid, truth) = simulated(&c);
    let good_imu = std::fs::read_to_string(&imu).unwrap();
    let good_aid = std::fs::read_to_string(&aid).unwrap();
    let good_truth = std::fs::read_to_string(&truth).unwrap();
    let out_file = c.path("out.txt");
    let out_dir = c.path("out_dir");
    let o = out_file.to_str().unwrap();
    let od = out_dir.to_str().unwrap();
    let mut cases = 0usize;
    let mut failures: Vec<String> = Vec::new();

    // IMU text through every command that reads an IMU file
    let mut imu_variants = table_variants(&good_imu, "");
    imu_variants.push((
        "gap".into(),
        good_imu
            .lines()
            .enumerate()
            .map(|(k, l)| {
                if k > 300 && !l.starts_with('#') {
                    let t: f64 = l.split_whitespace().next().unwrap().parse().unwrap();
                    field(l, 0, &format!("{}", t + 5.0))
                } else {
                    l.to_string()
                }
            })
            .collect::<Vec<_>>()
            .join("\n")
            .into(),
    ));
    imu_variants.push((
        "rate_units".into(),
        edit_row(&good_imu, 1000, |l| field(l, 1, "5")).into(),
    ));
    imu_variants.push((
        "one_sample".into(),
        edit_row(&good_imu, 0, |l| l.into())
            .lines()
            .filter(|l| l.starts_with('#'))
            .chain(good_imu.lines().filter(|l| !l.starts_with('#')).take(1))
            .collect::<Vec<_>>()
            .join("\n")
            .into(),
    ));
    for (name, bytes) in &imu_variants {
        let p = c.write(&format!("imu_{name}.txt"), bytes);
        let runs: Vec<(&str, Vec<&str>, Option<&Path>)> = vec![
            (
                "navigate",
                vec![
                    "navigate", "--imu", &p, "--lat", "30", "--lon", "110", "--att", "0,0,0",
                    "--out", o,
                ],
                Some(out_file.as_path()),
            ),
            (
                "filter",
                vec![
                    "filter", "--model", "P13", "--imu", &p, "--aid", &aid, "--init", INIT,
                    "--out", od,
                ],
                Some(out_dir.as_path()),
            ),
            (
                "explain",
                vec![
                    "explain", "--model", "P13", "--imu", &p, "--aid", &aid, "--init", INIT,
                    "--out", od,
                ],
                Some(out_dir.as_path()),
            ),
            ("imu-check", vec!["imu-check", "--imu", &p], None),
            (
                "allan",
                vec!["allan", "--imu", &p, "--json", o],
                Some(out_file.as_path()),
            ),
            ("align", vec!["align", "--imu", &p, "--lat", "30"], None),
        ];
        for (cmd, args, out) in runs {
            check(
                &mut failures,
                refused(
                    &format!("{cmd} on IMU {name}"),
                    &args,
                    &format!("imu_{name}.txt"),
                    out,
                ),
            );
            cases += 1;
        }
    }

    // aiding and truth files, through filter
    for (name, bytes) in table_variants(&good_aid, "") {
        let p = c.write(&format!("aid_{name}.txt"), &bytes);
        let args = [
            "filter", "--model", "P13", "--imu", &imu, "--aid", &p, "--init", INIT, "--out", od,
        ];
        check(
            &mut failures,
            refused(
                &format!("filter on aiding {name}"),
                &args,
                &format!("aid_{name}.txt"),
                Some(&out_dir),
            ),
        );
        cases += 1;
    }
    let sigma0 = edit_row(&good_aid, 5, |l| field(l, 4, "0"));
    let p = c.write("aid_sigma0.txt", sigma0);
    let args = [
        "filter", "--model", "P13", "--imu", &imu, "--aid", &p, "--init", INIT, "--out", od,
    ];
    check(
        &mut failures,
        refused(
            "filter on aiding sigma 0",
            &args,
            "aid_sigma0.txt",
            Some(&out_dir),
        ),
    );
    for (name, bytes) in table_variants(&good_truth, "") {
        let p = c.write(&format!("truth_{name}.txt"), &bytes);
        let args = [
            "filter", "--model", "P13", "--imu", &imu, "--aid", &aid, "--truth", &p, "--init",
            INIT, "--out", od,
        ];
        check(
            &mut failures,
            refused(
                &format!("filter on truth {name}"),
                &args,
                &format!("truth_{name}.txt"),
                Some(&out_dir),
            ),
        );
        cases += 1;
    }
    let lat95 = edit_row(&good_truth, 3, |l| field(l, 1, "95"));
    let p = c.write("truth_lat95.txt", lat95);
    let args = [
        "filter", "--model", "P13", "--imu", &imu, "--aid", &aid, "--truth", &p, "--out", od,
    ];
    check(
        &mut failures,
        refused(
            "filter on truth lat 95",
            &args,
            "truth_lat95.txt",
            Some(&out_dir),
        ),
    );

    // PSINS .imu
    let psins_good = "% psins\n0 0 90 0 0 0\n30 110 0 0 10 9.8\n0.1 0.1 0.1 1 1 1\n1 2 3 4 5 6\n1 2 3 4 5 6\n1 2 3 4 5 6\n";
    let psins_bad: Vec<(&str, String)> = vec![
        (
            "scale0",
            psins_good.replace("0.1 0.1 0.1 1 1 1", "0 0.1 0.1 1 1 1"),
        ),
        (
            "scale_neg",
            psins_good.replace("0.1 0.1 0.1 1 1 1", "0.1 0.1 0.1 1 -1 1"),
        ),
        (
            "interval0",
            psins_good.replace("30 110 0 0 10 9.8", "30 110 0 0 0 9.8"),
        ),
        (
            "gravity0",
            psins_good.replace("30 110 0 0 10 9.8", "30 110 0 0 10 0"),
        ),
        (
            "lat95",
            psins_good.replace("30 110 0 0 10 9.8", "95 110 0 0 10 9.8"),
        ),
        (
            "nan",
            psins_good.replacen("1 2 3 4 5 6", "1 nan 3 4 5 6", 1),
        ),
        (
            "huge",
            psins_good.replacen("1 2 3 4 5 6", "1 1e308 3 4 5 6", 1),
        ),
        ("no_header", "% psins\n1 2 3 4 5 6\n".to_string()),
        (
            "binary",
            String::from_utf8_lossy(&noise(2000, 3)).into_owned(),
        ),
    ];
    for (name, text) in psins_bad {
        let p = c.write(&format!("log_{name}.imu"), text);
        let args = [
            "navigate", "--imu", &p, "--lat", "30", "--lon", "110", "--att", "0,0,0", "--out", o,
        ];
        check(
            &mut failures,
            refused(
                &format!("navigate on PSINS {name}"),
                &args,
                &format!("log_{name}.imu"),
                Some(&out_file),
            ),
        );
        cases += 1;
    }

    // GNSS_IMU csv without its .tag: the assumed format is named, with the way to choose another
    let p = c.write(
        "log.csv",
        "0.0,0.0,1.0,0.1,0.1,0.1,1000\n0.0,0.0,1.0,0.1,0.1,0.1,1010\n",
    );
    let args = ["imu-check", "--imu", &p];
    check(
        &mut failures,
        refused(
            "imu-check on a csv without .tag",
            &args,
            "--imu-format",
            None,
        ),
    );
    let p = c.write("bin.csv", noise(3000, 5));
    check(
        &mut failures,
        refused(
            "imu-check on a binary csv",
            &["imu-check", "--imu", &p],
            "bin.csv",
            None,
        ),
    );
    cases += 2;

    // format descriptions
    for (name, bytes) in [
        ("empty", Vec::new()),
        ("garbage", b"[file\ndelimiter = ".to_vec()),
        ("binary", noise(500, 11)),
        ("bad_unit", b"[time]\ncolumn = 1\nunit = \"s\"\n[signals]\nkind = \"increment\"\ngyro = [2, 3, 4]\ngyro_unit = \"rad*s^2147483647\"\naccel = [5, 6, 7]\naccel_unit = \"m/s\"\n".to_vec()),
    ] {
        let f = c.write(&format!("fmt_{name}.toml"), bytes);
        let args = ["imu-check", "--imu", &imu, "--imu-format", &f];
        check(&mut failures, refused(&format!("imu-check with format {name}"), &args, &format!("fmt_{name}.toml"), None));
        cases += 1;
    }

    // RTKLIB .pos aiding
    let pos_good = "% GPST latitude(deg) longitude(deg) height(m) Q ns sdn(m) sde(m) sdu(m) sdne(m) sdeu(m) sdun(m) age(s) ratio\n";
    for (name, row) in [
        (
            "year",
            "99999999999/01/01 00:00:01.000 30.0 110.0 10.0 1 8 0.01 0.01 0.02 0 0 0 0.0 10.0",
        ),
        (
            "month",
            "2020/13/01 00:00:01.000 30.0 110.0 10.0 1 8 0.01 0.01 0.02 0 0 0 0.0 10.0",
        ),
        (
            "nan",
            "2020/01/01 00:00:01.000 nan 110.0 10.0 1 8 0.01 0.01 0.02 0 0 0 0.0 10.0",
        ),
        (
            "escape",
            "2020/01/01 00:00:01.000 \u{1b}[2J 110.0 10.0 1 8 0.01 0.01 0.02 0 0 0 0.0 10.0",
        ),
        ("short", "2020/01/01 00:00:01.000 30.0 110.0"),
    ] {
        let p = c.write(&format!("sol_{name}.pos"), format!("{pos_good}{row}\n"));
        let args = [
            "filter", "--model", "P13", "--imu", &imu, "--aid", &p, "--init", INIT, "--out", od,
        ];
        check(
            &mut failures,
            refused(
                &format!("filter on .pos {name}"),
                &args,
                &format!("sol_{name}.pos:2"),
                Some(&out_dir),
            ),
        );
        cases += 1;
    }

    // scenarios
    for (name, text) in [
        ("empty", String::new()),
        ("binary", String::from_utf8_lossy(&noise(1000, 13)).into_owned()),
        ("nan_lat", "name = \"x\"\nimu_rate_hz = 100.0\n[start]\nlat_deg = nan\nlon_deg = 1.0\n[[segment]]\nkind = \"rest\"\nduration_s = 10.0\n".into()),
        ("huge_g", "name = \"x\"\nimu_rate_hz = 100.0\n[start]\nlat_deg = 1.0\nlon_deg = 1.0\n[[segment]]\nkind = \"rest\"\nduration_s = 10.0\n[errors]\nnabla_x = \"1e308 g\"\n".into()),
        ("inf_freq", "name = \"x\"\nimu_rate_hz = 100.0\n[start]\nlat_deg = 1.0\nlon_deg = 1.0\n[[segment]]\nkind = \"rest\"\nduration_s = 10.0\n[[vibration]]\nkind = \"sine\"\naxis = \"n\"\namplitude = \"1 g\"\nfreq_hz = inf\n".into()),
    ] {
        let p = c.write(&format!("sc_{name}.toml"), text);
        let args = ["simulate", &p, "--out", od];
        check(&mut failures, refused(&format!("simulate {name}"), &args, &format!("sc_{name}.toml"), Some(&out_dir)));
        cases += 1;
    }

    // Jacobian points and noise files
    for (name, text) in [
        ("empty", ""),
        ("null", "null"),
        ("huge_f", "{\"lat_deg\": 30, \"h_m\": 0, \"v_ned\": [0,0,0], \"euler_deg\": [0,0,0], \"f_b\": [1e200,0,-9.8], \"w_b\": [0,0,0]}"),
        ("lat95", "{\"lat_deg\": 95, \"h_m\": 0, \"v_ned\": [0,0,0], \"euler_deg\": [0,0,0], \"f_b\": [0,0,-9.8], \"w_b\": [0,0,0]}"),
        ("overflow", "{\"lat_deg\": 1e400, \"h_m\": 0, \"v_ned\": [0,0,0], \"euler_deg\": [0,0,0], \"f_b\": [0,0,-9.8], \"w_b\": [0,0,0]}"),
    ] {
        let p = c.write(&format!("pt_{name}.json"), text);
        check(&mut failures, refused(&format!("jacobian {name}"), &["jacobian", "--model", "P31", "--at", &p], &format!("pt_{name}.json"), None));
        cases += 1;
    }
    for (name, bytes) in [("binary", noise(700, 17)), ("empty_obj", b"{}".to_vec())] {
        let p = c.write(&format!("noise_{name}.json"), bytes);
        let args = [
            "filter", "--model", "P13", "--imu", &imu, "--aid", &aid, "--init", INIT, "--noise",
            &p, "--out", od,
        ];
        check(
            &mut failures,
            refused(
                &format!("filter with noise {name}"),
                &args,
                &format!("noise_{name}.json"),
                Some(&out_dir),
            ),
        );
        cases += 1;
    }
    // a 100 kB model name is not echoed in full
    let long_model = format!("P31+{}", "x".repeat(100_000));
    check(
        &mut failures,
        refused(
            "model show with a 100 kB name",
            &["model", "show", &long_model],
            "x",
            None,
        ),
    );
    cases += 1;
    assert!(cases > 150, "{cases} cases");
    assert!(
        failures.is_empty(),
        "{} of {cases} bad-input cases failed:\n\n{}",
        failures.len(),
        failures.join("\n\n")
    );
    // and every message is the one it was (a refactoring changes none)
    let corpus = c.dir.path().to_str().unwrap().to_string();
    let log = MESSAGES
        .lock()
        .unwrap()
        .join("\n")
        .replace(&corpus, "<corpus>");
    common::check_golden("bad_corpus", &log);

    // the valid look-alikes are read: a byte-order mark and CR LF line ends
    let bom = c.write(
        "imu_bom.txt",
        format!("\u{feff}{}", good_imu.replace('\n', "\r\n")),
    );
    let (code, err) = run(&["imu-check", "--imu", &bom]);
    assert_eq!(code, Some(0), "BOM + CR LF: {err}");
}
