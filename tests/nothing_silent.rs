//! "Nothing lost, nothing silent": options that were resolved silently, and inputs whose error
//! named the wrong cause, now say what happened. Data from `sinsmodel simulate`.

mod common;

use common::sinsmodel;
use std::path::{Path, PathBuf};

fn p(x: &Path) -> &str {
    x.to_str().unwrap()
}

/// 60 s at rest at 100 Hz with 1 Hz fixes, simulated into `dir/sim`; with `offset` [s] added to
/// every time of imu.txt, gnss.txt and truth.txt (an absolute clock such as GPS seconds).
fn simulated(dir: &Path, offset: f64) -> PathBuf {
    let sc = dir.join("s.toml");
    std::fs::write(
        &sc,
        "name = \"ns\"\nimu_rate_hz = 100.0\n[start]\nlat_deg = 30.0\nlon_deg = 110.0\n[[segment]]\nkind = \"rest\"\nduration_s = 60.0\n[gnss]\nrate_hz = 1.0\n",
    )
    .unwrap();
    let sim = dir.join("sim");
    let (ok, _, err) = sinsmodel(&["simulate", p(&sc), "--out", p(&sim)]);
    assert!(ok, "{err}");
    if offset != 0.0 {
        for f in ["imu.txt", "gnss.txt", "truth.txt"] {
            let text = std::fs::read_to_string(sim.join(f)).unwrap();
            let shifted: String = text
                .lines()
                .map(|l| match l.split_once(' ') {
                    Some((t, rest)) if !l.starts_with('#') => {
                        format!("{:.6} {rest}\n", t.parse::<f64>().unwrap() + offset)
                    }
                    _ => format!("{l}\n"),
                })
                .collect();
            std::fs::write(sim.join(f), shifted).unwrap();
        }
    }
    sim
}

fn filter(sim: &Path, out: &Path, extra: &[&str]) -> (bool, String) {
    let (imu, aid, truth) = (
        sim.join("imu.txt"),
        sim.join("gnss.txt"),
        sim.join("truth.txt"),
    );
    let mut a = vec![
        "filter",
        "--model",
        "P13",
        "--imu",
        p(&imu),
        "--aid",
        p(&aid),
        "--truth",
        p(&truth),
        "--out",
        p(out),
    ];
    a.extend_from_slice(extra);
    let (ok, _, err) = sinsmodel(&a);
    (ok, err)
}

/// The times of the rows of a nav.txt (or navigate output).
fn row_times(path: &Path) -> Vec<f64> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .filter(|l| !l.starts_with('#'))
        .map(|l| l.split_whitespace().next().unwrap().parse().unwrap())
        .collect()
}

/// Rows at t0 + k/rate from the run's start on an absolute clock, the start row always
/// written, and a rate above the IMU's said on stderr.
#[test]
fn the_nav_rate_grid_is_anchored_at_the_start() {
    let dir = tempfile::tempdir().unwrap();
    let t_abs = 1_751_000_000.0;
    let sim = simulated(dir.path(), t_abs);
    let nav = dir.path().join("nav.txt");
    let (ok, _, err) = sinsmodel(&[
        "navigate",
        "--imu",
        p(&sim.join("imu.txt")),
        "--init",
        "30,110,0,0,0,0",
        "--nav-rate",
        "0.1",
        "--out",
        p(&nav),
    ]);
    assert!(ok, "{err}");
    // the run starts at the first sample and lasts 59.99 s
    let t = row_times(&nav);
    assert_eq!(t.len(), 6, "the start and 10 .. 50 s: {t:?}");
    for (k, ti) in t.iter().enumerate() {
        assert!((ti - t[0] - 10.0 * k as f64).abs() < 1e-3, "{t:?}");
    }
    // filter: the start row too, on the same grid
    let out = dir.path().join("f3");
    let (ok, err) = filter(&sim, &out, &["--nav-rate", "3"]);
    assert!(ok, "{err}");
    let t = row_times(&out.join("nav.txt"));
    assert!(
        (t[0] - t_abs).abs() < 0.011,
        "the start row: {}",
        t[0] - t_abs
    );
    assert!(
        t.windows(2)
            .all(|w| (w[1] - w[0] - 1.0 / 3.0).abs() < 0.0101),
        "every interval 1/3 s within a sample: {:?}",
        &t[..4]
    );
    assert!(t.len() >= 180, "{}", t.len());
    // a rate longer than the run: only the start row, and said
    let out = dir.path().join("f001");
    let (ok, err) = filter(&sim, &out, &["--nav-rate", "0.01"]);
    assert!(ok, "{err}");
    assert_eq!(row_times(&out.join("nav.txt")).len(), 1);
    assert!(err.contains("only the start row"), "{err}");
    // above the IMU's rate: every sample, and said
    let out = dir.path().join("f1000");
    let (ok, err) = filter(&sim, &out, &["--nav-rate", "1000"]);
    assert!(ok, "{err}");
    assert!(
        err.contains("--nav-rate 1000: above the IMU's sample rate (100 Hz)"),
        "{err}"
    );
    assert_eq!(row_times(&out.join("nav.txt")).len(), 6001);
}

/// An --outage that drops no fix is refused naming the window, not reported as a drift.
#[test]
fn an_outage_without_a_fix_inside_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let sim = simulated(dir.path(), 0.0);
    let out = dir.path().join("o");
    // the second window is checked too when the first drops fixes
    let (ok, err) = filter(&sim, &out, &["--outage", "10,5", "--outage", "50.2,0.5"]);
    assert!(!ok, "accepted");
    assert!(
        err.contains("no aiding fix falls inside the window 50.200 .. 50.700 s")
            && err.contains("50.000")
            && err.contains("51.000"),
        "{err}"
    );
    assert!(!out.exists());
    let (ok, err) = filter(&sim, &out, &["--outage", "49.5,1"]);
    assert!(ok, "{err}");
    assert!(out.join("outages.json").exists());
}

/// Negative numbers reach the option's own check (not clap's "unexpected argument"), and a
/// number is echoed in a bounded form.
#[test]
fn negative_and_huge_numbers_get_the_options_own_words() {
    let dir = tempfile::tempdir().unwrap();
    let sim = simulated(dir.path(), 0.0);
    let imu = sim.join("imu.txt");
    let nav = dir.path().join("nav.txt");
    let (ok, _, err) = sinsmodel(&[
        "navigate",
        "--imu",
        p(&imu),
        "--init",
        "30,110,0,0,0,0",
        "--nav-rate",
        "-5",
        "--out",
        p(&nav),
    ]);
    assert!(
        !ok && err.contains("--nav-rate -5: must be positive (Hz)"),
        "{err}"
    );
    let out = dir.path().join("f");
    for (opt, val, words) in [
        ("--nav-rate", "-5", "--nav-rate -5: must be positive (Hz)"),
        ("--step", "-1", "--step -1: expected a filter step"),
        (
            "--step",
            "10",
            "milliseconds written as seconds? (10 ms is --step 0.01)",
        ),
        ("--zupt", "-0.1", "--zupt -0.1: expected a velocity σ"),
        ("--init-speed", "-3", "--init-speed"),
    ] {
        let (ok, err) = filter(&sim, &out, &[opt, val]);
        assert!(!ok && err.contains(words), "{opt} {val}: {err}");
        assert!(!err.contains("unexpected argument"), "{err}");
    }
    let huge = format!("1{}", "0".repeat(299));
    for (opt, val, words) in [
        ("--alpha", "-0.01", "--alpha -0.01: expected a level"),
        ("--alpha", huge.as_str(), "--alpha 1e299: expected a level"),
        (
            "--demo-seconds",
            "-60",
            "--demo-seconds -60: expected 60 to 14400 s",
        ),
    ] {
        let (ok, _, err) = sinsmodel(&["explain", opt, val]);
        assert!(!ok && err.contains(words), "{opt}: {err}");
        assert!(err.len() < 300, "bounded: {err}");
    }
}

/// navigate takes the initial state within filter's bounds, in filter's words: latitude 89 is
/// accepted by both, 89.95 refused by both as at a pole.
#[test]
fn navigate_and_filter_bound_the_start_alike() {
    let dir = tempfile::tempdir().unwrap();
    let sim = simulated(dir.path(), 0.0);
    let imu = sim.join("imu.txt");
    let nav = dir.path().join("nav.txt");
    let navigate = |extra: &[&str]| {
        let mut a = vec!["navigate", "--imu", p(&imu), "--out", p(&nav), "--force"];
        a.extend_from_slice(extra);
        sinsmodel(&a)
    };
    let (ok, _, err) = navigate(&["--lat", "89", "--lon", "110", "--att", "0,0,0"]);
    assert!(ok, "{err}");
    let (ok, _, err) = navigate(&["--init", "89,110,0,0,0,0", "--overwrite"]);
    assert!(ok, "{err}");
    let (ok, _, err) = navigate(&["--lat", "89.95", "--lon", "110", "--att", "0,0,0"]);
    assert!(
        !ok && err.contains("--lat: lat = 89.95 is at a pole"),
        "{err}"
    );
    let (ok, _, err) = navigate(&["--init", "89.95,110,0,0,0,0"]);
    assert!(
        !ok && err.contains("--init: lat = 89.95 is at a pole"),
        "{err}"
    );
    let (ok, err) = filter(
        &sim,
        &dir.path().join("f"),
        &["--init", "89.95,110,0,0,0,0"],
    );
    assert!(
        !ok && err.contains("--init: lat = 89.95 is at a pole"),
        "{err}"
    );
    let (ok, _, err) = navigate(&[
        "--lat", "30", "--lon", "110", "--att", "0,0,0", "--vel", "2000,0,0",
    ]);
    assert!(
        !ok && err.contains("--vel: vn = 2000 is outside [-1000, 1000] m/s"),
        "{err}"
    );
}

/// A comment prefix that can begin a number would drop data rows: refused when the description
/// is loaded, naming the file and line.
#[test]
fn a_comment_prefix_that_begins_a_number_is_refused() {
    let desc = |c: &str| {
        format!("[file]\ndelimiter = \",\"\ncomment = \"{c}\"\n[time]\ncolumn = 1\n[signals]\nkind = \"increment\"\ngyro = [2, 3, 4]\ngyro_unit = \"rad\"\naccel = [5, 6, 7]\naccel_unit = \"m/s\"\n")
    };
    use sinsmodel::io::imu_format::ImuFormat;
    for c in ["0", "1", "-", "+", ".", "9x"] {
        let e = ImuFormat::parse(&desc(c), "f.toml")
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("f.toml:3:") && e.contains("can begin a number"),
            "{c}: {e}"
        );
    }
    for c in ["#", "//", "%", ""] {
        assert!(ImuFormat::parse(&desc(c), "f.toml").is_ok(), "{c}");
    }
}

/// An ECEF or a degrees-minutes-seconds RTKLIB solution is named as such (with or without its
/// column header), not read as latitudes of -1277000 or as a vehicle that never moves.
#[test]
fn ecef_and_dms_pos_files_are_named() {
    let dir = tempfile::tempdir().unwrap();
    let read = |name: &str, text: &str| {
        let f = dir.path().join(name);
        std::fs::write(&f, text).unwrap();
        sinsmodel::io::readers::rtklib::read(&f)
            .unwrap_err()
            .to_string()
    };
    let ecef_row = "2025/07/08 19:34:18.499  -1277000.0747  -4717237.0937   4087230.1273 1 21 0.0100 0.0100 0.0100 0.0000 0.0000 0.0000 0.00 0.0\n";
    let ecef_head = "%  GPST                  x-ecef(m)      y-ecef(m)      z-ecef(m)   Q  ns   sdx(m)   sdy(m)   sdz(m)  sdxy(m)  sdyz(m)  sdzx(m) age(s)  ratio\n";
    let dms_row = "2025/07/08 19:34:18.499 40 05 47.85648 -105 08 50.81388 1601.4740000 1 21 0.0098995 0.0098995 0.0100000 0.0 0.0 0.0 0.00 0.0\n";
    let dms_head = "%  GPST                   latitude(d'\")   longitude(d'\")  height(m)   Q  ns   sdn(m)   sde(m)   sdu(m)  sdne(m)  sdeu(m)  sdun(m) age(s)  ratio\n";
    for (name, text, line, words) in [
        (
            "ecef.pos",
            format!("{ecef_head}{ecef_row}"),
            ":1:",
            "ECEF coordinates: output the solution in lat/lon/height",
        ),
        (
            "ecef_nh.pos",
            ecef_row.to_string(),
            ":1:",
            "ECEF coordinates",
        ),
        (
            "dms.pos",
            format!("{dms_head}{dms_row}"),
            ":1:",
            "degrees, minutes and seconds",
        ),
        (
            "dms_nh.pos",
            format!("% x\n{dms_row}"),
            ":2:",
            "output them in decimal degrees",
        ),
    ] {
        let e = read(name, &text);
        assert!(
            e.contains(&format!("{name}{line}")) && e.contains(words),
            "{name}: {e}"
        );
    }
    // decimal degrees still read
    let f = dir.path().join("ok.pos");
    std::fs::write(
        &f,
        "2025/07/08 19:34:18.499 40.0966 -105.1474 1601.474 1 21 0.01 0.01 0.01 0 0 0 0 0\n",
    )
    .unwrap();
    assert_eq!(sinsmodel::io::readers::rtklib::read(&f).unwrap().len(), 1);
}

/// The aiding file is checked against itself on every run (it was only under `--init auto`):
/// swapped velocity columns refused, heights in feet refused against the initial height, a
/// single 100 m outlier dropped with a warning that counts it (and the run then matches the
/// clean file's), the clean file passes without a word.
/// A 50-s drive (rest, 1.5 m/s² acceleration, a 90° turn) at 100 Hz with 1 Hz fixes and
/// velocities, simulated into `d/sim`.
fn drive(d: &Path) -> PathBuf {
    simulated_from(
        d,
        "name = \"drive\"\nimu_rate_hz = 100.0\nseed = 7\n[start]\nlat_deg = 40.0966\nlon_deg = -105.1474\nh_m = 1601.0\n\
         euler_deg = [0.0, 0.0, 30.0]\n[[segment]]\nkind = \"rest\"\nduration_s = 10.0\n[[segment]]\nkind = \"accelerate\"\n\
         duration_s = 10.0\naccel_mps2 = 1.5\n[[segment]]\nkind = \"turn\"\nduration_s = 30.0\nyaw_rate_deg_s = 3.0\n\
         [gnss]\nrate_hz = 1.0\nsigma_ne = \"0.05 m\"\nsigma_d = \"0.1 m\"\nsigma_v = \"0.02 m/s\"\n",
    )
}

#[test]
fn the_aiding_file_is_checked_against_itself_on_every_run() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let sim = drive(d);
    let text = std::fs::read_to_string(sim.join("gnss.txt")).unwrap();
    let rewrite = |name: &str, f: &dyn Fn(usize, &mut Vec<f64>)| {
        let mut out = String::new();
        for (k, l) in text.lines().enumerate() {
            if l.starts_with('#') {
                out.push_str(l);
            } else {
                let mut v: Vec<f64> = l.split_whitespace().map(|x| x.parse().unwrap()).collect();
                f(k, &mut v);
                let w: Vec<String> = v.iter().map(|x| format!("{x:.11}")).collect();
                out.push_str(&w.join(" "));
            }
            out.push('\n');
        }
        let path = d.join(name);
        std::fs::write(&path, out).unwrap();
        path
    };
    let imu = sim.join("imu.txt");
    let run_with = |aid: &Path, out: &str, extra: &[&str]| {
        let out = d.join(out);
        let (ok, err) = filter_p13(&imu, aid, "40.0966,-105.1474,1601,0,0,30", &out, extra);
        (ok, err, out)
    };
    let run = |aid: &Path, out: &str| run_with(aid, out, &[]);
    let (ok, err, clean) = run(&sim.join("gnss.txt"), "clean");
    assert!(ok && !err.contains("warning"), "{err}");
    let swapped = rewrite("swapped.txt", &|_, v| v.swap(7, 8));
    let (ok, err, _) = run(&swapped, "sw");
    assert!(
        !ok && err.contains("velocities disagree with its positions"),
        "{err}"
    );
    let feet = rewrite("feet.txt", &|_, v| v[3] *= 3.2808);
    let (ok, err, _) = run(&feet, "ft");
    assert!(!ok && err.contains("in feet?"), "{err}");
    // fix 30 (t = 30 s, in the turn) 100 m north
    let outlier = rewrite("outlier.txt", &|k, v| {
        if k == 31 {
            v[1] += 100.0 / 6.37e6 * 180.0 / std::f64::consts::PI;
        }
    });
    let (ok, err, out) = run(&outlier, "ol");
    assert!(
        ok && err.contains("1 of") && err.contains("dropped as outliers"),
        "{err}"
    );
    let epochs = |dir: &Path| {
        let t = std::fs::read_to_string(dir.join("innovations.txt")).unwrap();
        let mut times: Vec<String> = t
            .lines()
            .filter(|l| !l.starts_with('#'))
            .filter_map(|l| l.split_whitespace().next().map(str::to_string))
            .collect();
        times.dedup();
        times.len()
    };
    // the outlier's epoch is gone, every other is there
    assert_eq!(epochs(&out) + 1, epochs(&clean), "one epoch dropped");
    // a burst (fixes 30–32 s 100 m north) passes the neighbours' check in part; the filter's
    // innovation gate rejects what is left, counts it and lists it; without the gate the NIS
    // explodes
    let burst = rewrite("burst.txt", &|k, v| {
        if (31..=33).contains(&k) {
            v[1] += 100.0 / 6.37e6 * 180.0 / std::f64::consts::PI;
        }
    });
    let (ok, err, out) = run_with(&burst, "burst", &["--gate", "10"]);
    assert!(
        ok && err.contains("scalar updates rejected (|nu| > 10 sigma)"),
        "{err}"
    );
    let listed = std::fs::read_to_string(out.join("innovations.txt")).unwrap();
    assert!(
        listed.contains("# rejected by the innovation gate"),
        "{listed}"
    );
    let mean_nis = |dir: &Path, meas: &str| {
        let t = std::fs::read_to_string(dir.join("innovations.txt")).unwrap();
        let v: Vec<f64> = t
            .lines()
            .filter(|l| !l.starts_with('#'))
            .map(|l| l.split_whitespace().collect::<Vec<_>>())
            .filter(|w| w[1] == meas && w[2] == "0")
            .map(|w| w[3].parse::<f64>().unwrap().powi(2) / w[4].parse::<f64>().unwrap())
            .collect();
        v.iter().sum::<f64>() / v.len() as f64
    };
    let (gated, clean_nis) = (mean_nis(&out, "pos_ne"), mean_nis(&clean, "pos_ne"));
    assert!(
        gated < 3.0 * clean_nis.max(1.0),
        "gated {gated}, clean {clean_nis}"
    );
    let (ok, err, off) = run_with(&burst, "off", &[]);
    assert!(
        ok && !err.contains("rejected"),
        "the gate is off by default: {err}"
    );
    assert!(
        mean_nis(&off, "pos_ne") > 100.0 * gated,
        "without the gate the burst enters"
    );
    let (ok, err, _) = run_with(&burst, "g2", &["--gate", "2"]);
    assert!(
        !ok && err.contains("--gate 2: a gate is between 3 and 1e6"),
        "{err}"
    );
    // a step that stays (every fix from 30 s on 100 m north) is no outlier burst: after 5
    // rejected epochs in a row the gate takes the fixes again and says so, instead of keeping
    // the filter off them for good
    let step = rewrite("step.txt", &|k, v| {
        if k >= 31 {
            v[1] += 100.0 / 6.37e6 * 180.0 / std::f64::consts::PI;
        }
    });
    let (ok, err, out) = run_with(&step, "step", &["--gate", "10"]);
    assert!(
        ok && err.contains("were applied all the same, each after 5 epochs"),
        "{err}"
    );
    let listed = std::fs::read_to_string(out.join("innovations.txt")).unwrap();
    // fixes 30–34 s rejected (line 31 of the file is the fix at 30 s), the sixth (35 s) applied
    for t in 30..=34 {
        assert!(
            listed.contains(&format!("# {t}.0000 pos_ne 0")),
            "{t} s:\n{listed}"
        );
    }
    assert!(!listed.contains("# 35.0000 pos_ne 0"), "{listed}");
}

/// A truth file whose yaw is in radians, or counted the other way, contradicts the filter's own
/// estimate by hundreds of σ: said with the likely causes (it had been used silently as the
/// reference of model_error.txt); the right truth gives no word.
#[test]
fn a_truth_that_contradicts_the_filter_is_said() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let sim = drive(d);
    let text = std::fs::read_to_string(sim.join("truth.txt")).unwrap();
    // t lat lon h v_n v_e v_d roll pitch yaw: yaw is the last column
    let yaw_col = 9;
    let rewrite =
        |name: &str, f: &dyn Fn(f64) -> f64| with_column(&text, '#', yaw_col, 6, f, &d.join(name));
    let run = |truth: &Path, out: &str| {
        let (ok, _, err) = sinsmodel(&[
            "filter",
            "--model",
            "P13",
            "--imu",
            p(&sim.join("imu.txt")),
            "--aid",
            p(&sim.join("gnss.txt")),
            "--truth",
            p(truth),
            "--init",
            "40.0966,-105.1474,1601,0,0,30",
            "--out",
            p(&d.join(out)),
        ]);
        assert!(ok, "{err}");
        err
    };
    let err = run(&sim.join("truth.txt"), "ok");
    assert!(!err.contains("--truth:"), "{err}");
    for (name, f) in [
        ("rad.txt", &(|y: f64| y.to_radians()) as &dyn Fn(f64) -> f64),
        ("neg.txt", &|y: f64| -y),
    ] {
        let err = run(&rewrite(name, f), &format!("out-{name}"));
        assert!(
            err.contains("--truth: the truth's attitude differs")
                && err.contains("heading by a median"),
            "{name}: {err}"
        );
    }
}

/// Aiding fixes a day or 9 h away from the IMU's clock (a wrong date, JST read as GPST) had made
/// `--init auto` blame "the data start moving": refused naming the offset and its likely cause.
#[test]
fn aiding_on_another_day_or_clock_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let sim = simulated(dir.path(), 0.0);
    let text = std::fs::read_to_string(sim.join("gnss.txt")).unwrap();
    for (shift, cause) in [(86400.0, "1 day(s) off"), (32400.0, "9 h off")] {
        let shifted: String = text
            .lines()
            .map(|l| match l.split_once(' ') {
                Some((t, rest)) if !l.starts_with('#') => {
                    format!("{:.6} {rest}\n", t.parse::<f64>().unwrap() + shift)
                }
                _ => format!("{l}\n"),
            })
            .collect();
        let aid = dir.path().join("late.txt");
        std::fs::write(&aid, shifted).unwrap();
        for init in ["auto", "30,110,0,0,0,0"] {
            let (ok, _, err) = sinsmodel(&[
                "filter",
                "--model",
                "P13",
                "--imu",
                p(&sim.join("imu.txt")),
                "--aid",
                p(&aid),
                "--init",
                init,
                "--out",
                p(&dir.path().join("o")),
            ]);
            assert!(
                !ok && err.contains("--aid: the aiding fixes run from") && err.contains(cause),
                "{init}: {err}"
            );
        }
    }
}

/// An aiding file whose clock is 30 s late against the IMU's: the GNSS course turns match the
/// gyros' 30 s before their stamps (refused, the offset named; with --force warned), and while
/// the IMU turns at 12 deg/s the fixes stamped then still stand (they describe the rest 30 s
/// before; a warning: a vehicle can turn in place); the same data on one clock say nothing.
#[test]
fn a_late_aiding_clock_is_said_where_the_imu_turns_and_the_fixes_stand() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let sim = simulated_from(
        d,
        "name = \"clk\"\nimu_rate_hz = 100.0\nseed = 3\n[start]\nlat_deg = 40.0966\nlon_deg = -105.1474\nh_m = 1601.0\n\
         [[segment]]\nkind = \"rest\"\nduration_s = 40.0\n[[segment]]\nkind = \"accelerate\"\nduration_s = 2.0\naccel_mps2 = 3.0\n\
         [[segment]]\nkind = \"turn\"\nduration_s = 20.0\nyaw_rate_deg_s = 15.0\n[[segment]]\nkind = \"cruise\"\nduration_s = 20.0\n\
         [gnss]\nrate_hz = 1.0\nsigma_ne = \"0.05 m\"\nsigma_d = \"0.1 m\"\nsigma_v = \"0.02 m/s\"\n",
    );
    let late: String = std::fs::read_to_string(sim.join("gnss.txt"))
        .unwrap()
        .lines()
        .map(|l| match l.split_once(' ') {
            Some((t, rest)) if !l.starts_with('#') => {
                format!("{:.4} {rest}\n", t.parse::<f64>().unwrap() + 30.0)
            }
            _ => format!("{l}\n"),
        })
        .collect();
    std::fs::write(d.join("late.txt"), late).unwrap();
    let imu = sim.join("imu.txt");
    let run = |aid: &Path, out: &str, force: bool| {
        let extra: &[&str] = if force { &["--force"] } else { &[] };
        filter_p13(
            &imu,
            aid,
            "40.0966,-105.1474,1601,0,0,0",
            &d.join(out),
            extra,
        )
    };
    let (ok, err) = run(&sim.join("gnss.txt"), "clean", false);
    assert!(ok && !err.contains("warning"), "{err}");
    // the GNSS course turns 300° 30 s after the gyros: refused at the end of the IMU file
    let (ok, err) = run(&d.join("late.txt"), "late", false);
    assert!(
        !ok && err.contains("--aid: the aiding's clock is likely 30.0 s off the IMU's")
            && err.contains("add -30.0 s to the aiding file's times")
            && !d.join("late").exists(),
        "{err}"
    );
    let (ok, err) = run(&d.join("late.txt"), "late", true);
    assert!(
        ok && err.contains("at 40.1–50.1 s: the IMU turns")
            && err.contains("the aiding's clock is likely off against the IMU's")
            && err.contains("likely 30.0 s off the IMU's")
            && err.contains("(--force given)"),
        "{err}"
    );
}

/// Heights at a low site: fixes in feet (100 m read as 328) are refused naming feet, though the
/// heights differ by less than the 1000 m that had been the only bound; a height 80 m off is
/// warned as two datums (ellipsoidal against mean sea level); the clean run says neither.
#[test]
fn heights_in_feet_or_on_another_datum_are_named_at_a_low_site() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let sim = simulated_from(
        d,
        "name = \"low\"\nimu_rate_hz = 100.0\n[start]\nlat_deg = 30.0\nlon_deg = 110.0\nh_m = 100.0\n[[segment]]\nkind = \"rest\"\nduration_s = 40.0\n[gnss]\nrate_hz = 1.0\n",
    );
    let text = std::fs::read_to_string(sim.join("gnss.txt")).unwrap();
    let heights =
        |name: &str, f: &dyn Fn(f64) -> f64| with_column(&text, '#', 3, 4, f, &d.join(name));
    let run_from = |aid: &Path, out: &str, init: &str| {
        filter_p13(&sim.join("imu.txt"), aid, init, &d.join(out), &[])
    };
    let run = |aid: &Path, out: &str| run_from(aid, out, "30,110,100,0,0,0");
    let (ok, err) = run(&sim.join("gnss.txt"), "clean");
    assert!(ok && !err.contains("warning"), "{err}");
    let (ok, err) = run(&heights("feet.txt", &|h| h * 3.2808), "feet");
    assert!(!ok && err.contains("one of them in feet?"), "{err}");
    let (ok, err) = run(&heights("datum.txt", &|h| h + 80.0), "datum");
    assert!(ok && err.contains("heights on two datums?"), "{err}");
    // a sea-level start of 20 m under ellipsoidal fixes at 66.5 m (northern Germany's geoid) is
    // no feet, though 3.3× apart: it runs (it had been refused)
    let geoid = heights("geoid.txt", &|h| h - 33.5);
    let (ok, err) = run_from(&geoid, "geoid", "30,110,20,0,0,0");
    assert!(ok && !err.contains("feet"), "{err}");
    // 600 m off is beyond any datum: warned as such, not as two datums
    let (ok, err) = run(&heights("far.txt", &|h| h + 600.0), "far");
    assert!(
        ok && err.contains("more than two height datums differ by"),
        "{err}"
    );
}

/// A turntable that tumbles a full turn about a level axis in one 10-s window: the window's mean
/// specific-force vector nearly cancels, but |f| is 1 g throughout (the check takes |f| of 1-s
/// means); it had been refused as "0.050× local gravity … g read as m/s²".
#[test]
fn a_tumble_about_a_level_axis_is_no_unit_slip() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let sim = simulated_from(
        d,
        "name = \"tt\"\nimu_rate_hz = 100.0\n[start]\nlat_deg = 40.0\nlon_deg = -105.0\nh_m = 1600.0\n\
         [[segment]]\nkind = \"rest\"\nduration_s = 30.0\n[[segment]]\nkind = \"rotate\"\naxis = \"x\"\nangle_deg = 360.0\nduration_s = 10.0\n\
         [[segment]]\nkind = \"rest\"\nduration_s = 20.0\n",
    );
    let (ok, _, err) = sinsmodel(&[
        "filter",
        "--model",
        "P13",
        "--imu",
        p(&sim.join("imu.txt")),
        "--static-aid",
        "40,-105,1600",
        "--init",
        "40,-105,1600,0,0,0",
        "--out",
        p(&d.join("f")),
    ]);
    assert!(ok && !err.contains("local gravity"), "{err}");
}

/// `--zupt` beside GNSS fixes that move (a drive-off too gentle for the IMU's window test) is
/// refused by the fixes' own speeds; at rest the same option runs.
#[test]
fn zupt_is_held_to_the_fixes_speeds() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let moving = drive(d);
    let (ok, err) = filter(
        &moving,
        &d.join("m"),
        &[
            "--init",
            "40.0966,-105.1474,1601,0,0,30",
            "--zupt",
            "0.01",
            "--aid-use",
            "pos",
        ],
    );
    assert!(
        !ok && err.contains("--zupt says the vehicle does not move, but the aiding fixes move"),
        "{err}"
    );
    let rest_dir = d.join("rest");
    std::fs::create_dir_all(&rest_dir).unwrap();
    let still = simulated(&rest_dir, 0.0);
    let (ok, err) = filter(&still, &d.join("s"), &["--zupt", "0.01"]);
    assert!(ok, "{err}");
}

/// An outage's drift is the first fix's residual before any of its updates: the same whether the
/// innovation gate rejects that fix's north component or not (the east one had been taken after
/// the north update, so the gate changed it: −0.39 against −0.43 m).
#[test]
fn the_outage_drift_does_not_depend_on_the_gate() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let sim = d.join("sim");
    let (ok, _, err) = sinsmodel(&[
        "simulate",
        p(&root.join("scenarios/drive.toml")),
        "--out",
        p(&sim),
    ]);
    assert!(ok, "{err}");
    let drift = |gate: &str| {
        let out = d.join(format!("g{gate}"));
        let (ok, _, err) = sinsmodel(&[
            "filter",
            "--model",
            "P28",
            "--imu",
            p(&sim.join("imu.txt")),
            "--aid",
            p(&sim.join("gnss.txt")),
            "--truth",
            p(&sim.join("truth.txt")),
            "--outage",
            "80,20",
            "--gate",
            gate,
            "--out",
            p(&out),
        ]);
        assert!(ok, "{err}");
        let v: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("outages.json")).unwrap())
                .unwrap();
        (err, v["outages"][0].clone())
    };
    let (_, off) = drift("off");
    let (err, gated) = drift("10");
    assert!(
        err.contains("gate: 1 of"),
        "the gate rejects the fix after the outage: {err}"
    );
    assert_eq!(off, gated);
}

/// The shared MEMS drive with its RTK file moved on the clock: 60 s late is refused (the GNSS
/// course turns match the gyros' 60 s before their stamps), 2 s late is warned (its turns still
/// match in part as stamped, and explain's report opens with it); as recorded, nothing is said
/// of the clock.
#[test]
fn the_real_drive_on_a_moved_clock_is_said_with_its_offset() {
    let shared = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data/gnss-imu-drive");
    let pos = std::fs::read_to_string(shared.join("gnss_1934_sf.pos")).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // moves every epoch by `shift` seconds (within the day: the drive is at 19:34 GPST)
    let moved = |shift: f64| -> PathBuf {
        let text: String = pos
            .lines()
            .map(|l| {
                if l.starts_with('%') {
                    return format!("{l}\n");
                }
                let (date, rest) = l.split_once(' ').unwrap();
                let (time, rest) = rest.trim_start().split_once(' ').unwrap();
                let hms: Vec<f64> = time.split(':').map(|x| x.parse().unwrap()).collect();
                let s = hms[0] * 3600.0 + hms[1] * 60.0 + hms[2] + shift;
                let (h, m) = ((s / 3600.0).floor(), ((s % 3600.0) / 60.0).floor());
                format!(
                    "{date} {h:02}:{m:02}:{:06.3} {rest}\n",
                    s - h * 3600.0 - m * 60.0
                )
            })
            .collect();
        let path = d.join(format!("moved{shift}.pos"));
        std::fs::write(&path, text).unwrap();
        path
    };
    let run = |aid: &Path| mems_drive_filter(aid, &d.join("o"));
    let (ok, err) = run(&moved(0.0));
    assert!(ok && !err.contains("clock is likely"), "{err}");
    let (ok, err) = run(&moved(2.0));
    assert!(
        ok && err.contains("warning: --aid: the aiding's clock is likely 2.0 s off the IMU's")
            && err.contains("add -2.0 s"),
        "{err}"
    );
    // explain's report (what people read, not stderr) opens with the warning
    let out = d.join("explain2");
    let (ok, _, err) = sinsmodel(&[
        "explain",
        "--model",
        "P13",
        "--imu",
        p(&shared.join("imu_1934.csv")),
        "--aid",
        p(&moved(2.0)),
        "--init",
        "auto",
        "--grade",
        "mems",
        "--out",
        p(&out),
    ]);
    assert!(ok, "{err}");
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    let words = report.split("## In words").nth(1).unwrap();
    assert!(
        words
            .trim_start()
            .starts_with("- Warning about the data: --aid: the aiding's clock is likely 2.0 s off"),
        "{report}"
    );
    // 300 s late: the turns that match lie in the 360 s --init auto reads through to its start
    let (ok, err) = run(&moved(300.0));
    assert!(
        !ok && err.contains("the aiding's clock is likely 300.0 s off the IMU's"),
        "{err}"
    );
    let (ok, err) = run(&moved(60.0));
    assert!(
        !ok && err.contains("error: --aid: the aiding's clock is likely 60.0 s off the IMU's")
            && err.contains("add -60.0 s")
            && err.contains("(--force runs anyway)"),
        "{err}"
    );
}

/// The shared MEMS drive's RTK heights in feet (the velocities in m/s): with `--init auto` the
/// start takes the first fix's height, so no start height disagrees; the heights change 3.28×
/// as fast as the vertical velocities say and that is refused naming feet. An up velocity read
/// as down is named too; the file as recorded passes (scale 0.98), and so does one with 0.2 m/s
/// of noise added to its vertical velocities (a scale shrunk towards 0).
#[test]
fn the_real_drive_with_heights_in_feet_is_refused_under_init_auto() {
    let shared = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data/gnss-imu-drive");
    let pos = std::fs::read_to_string(shared.join("gnss_1934_sf.pos")).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // column `col` (0-based, after splitting on blanks) through `f`
    let changed = |name: &str, col: usize, f: &dyn Fn(f64) -> f64| {
        with_column(&pos, '%', col, 4, f, &d.join(name))
    };
    let run = |aid: &Path| mems_drive_filter(aid, &d.join("o"));
    let (ok, err) = run(&changed("same.pos", 4, &|h| h));
    assert!(ok && !err.contains("vertical velocities"), "{err}");
    let (ok, err) = run(&changed("feet.pos", 4, &|h| h / 0.3048));
    assert!(
        !ok && err.contains("--aid: the aiding file's heights change 3.")
            && err.contains("heights in feet"),
        "{err}"
    );
    // 0.2 m/s of noise on the vertical velocities (their stated σ kept): the scale shrinks
    // towards 0 (noise adds to Σ v² only), which says nothing of the units
    let state = std::cell::Cell::new(12345u64);
    let uniform = || {
        let x = state
            .get()
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        state.set(x);
        (x >> 11) as f64 / (1u64 << 53) as f64
    };
    let (ok, err) = run(&changed("noisy.pos", 17, &|vu| {
        vu + 0.2 * 3f64.sqrt() * (2.0 * uniform() - 1.0)
    }));
    assert!(ok && !err.contains("vertical velocities say"), "{err}");
    // heights in km: they hardly move while the velocities (0.27 m/s RMS, stated σ 0.06) say
    // they do
    let (ok, err) = run(&changed("km.pos", 4, &|h| h / 1000.0));
    assert!(
        !ok && err.contains("heights that hardly move (in km, or held constant)"),
        "{err}"
    );
    let (ok, err) = run(&changed("up.pos", 17, &|vu| -vu));
    assert!(
        !ok && err.contains("a vertical velocity up read as down"),
        "{err}"
    );
}

/// `--static-aid` on a run that creeps off at 0.15 m/s² after 60 s at rest (under the 0.3 m/s²
/// step the IMU's rest checks take as motion): the filter runs, and its summary says that the
/// zero-velocity updates' large NIS may be a vehicle that moves; the same run at rest says
/// nothing of it.
#[test]
fn static_aid_on_a_gentle_creep_says_the_vehicle_may_move() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    for (accel, says) in [(0.15, true), (0.0, false)] {
        let sc = d.join(format!("c{accel}.toml"));
        std::fs::write(
            &sc,
            format!(
                "name = \"creep\"\nimu_rate_hz = 100.0\nseed = 4\n[start]\nlat_deg = 30.0\nlon_deg = 110.0\nh_m = 100.0\n\
                 [[segment]]\nkind = \"rest\"\nduration_s = 60.0\n[[segment]]\nkind = \"accelerate\"\nduration_s = 30.0\n\
                 accel_mps2 = {accel}\n[gnss]\nrate_hz = 1.0\n"
            ),
        )
        .unwrap();
        let sim = d.join(format!("sim{accel}"));
        let (ok, _, err) = sinsmodel(&["simulate", p(&sc), "--out", p(&sim)]);
        assert!(ok, "{err}");
        let out = d.join(format!("o{accel}"));
        let (ok, _, err) = sinsmodel(&[
            "filter",
            "--model",
            "P13",
            "--imu",
            p(&sim.join("imu.txt")),
            "--static-aid",
            "30,110,100",
            "--init",
            "30,110,100,0,0,0",
            "--out",
            p(&out),
        ]);
        assert!(ok, "{err}");
        assert_eq!(
            err.contains("note: --static-aid says the vehicle stands still")
                && err.contains("the vehicle may move"),
            says,
            "{accel}: {err}"
        );
    }
}

/// `filter` (P13, `--init auto`, `--grade mems`) on the shared MEMS drive's IMU with the aiding
/// file `aid`, into `out`: whether it ran, and its stderr.
fn mems_drive_filter(aid: &Path, out: &Path) -> (bool, String) {
    let imu =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data/gnss-imu-drive/imu_1934.csv");
    filter_p13(&imu, aid, "auto", out, &["--grade", "mems"])
}

/// `filter --model P13 --imu IMU --aid AID --init INIT --out OUT EXTRA…`: whether it ran, and
/// its stderr.
fn filter_p13(imu: &Path, aid: &Path, init: &str, out: &Path, extra: &[&str]) -> (bool, String) {
    let mut a = vec![
        "filter",
        "--model",
        "P13",
        "--imu",
        p(imu),
        "--aid",
        p(aid),
        "--init",
        init,
        "--out",
        p(out),
    ];
    a.extend_from_slice(extra);
    let (ok, _, err) = sinsmodel(&a);
    (ok, err)
}

/// Writes `text` to `path` with column `col` (0-based, blank-separated) of every data row put
/// through `f` and written with `decimals` digits; rows starting with `comment` kept as they are.
fn with_column(
    text: &str,
    comment: char,
    col: usize,
    decimals: usize,
    f: &dyn Fn(f64) -> f64,
    path: &Path,
) -> PathBuf {
    let out: String = text
        .lines()
        .map(|l| {
            if l.starts_with(comment) {
                return format!("{l}\n");
            }
            let mut v: Vec<String> = l.split_whitespace().map(str::to_string).collect();
            v[col] = format!("{:.*}", decimals, f(v[col].parse().unwrap()));
            format!("{}\n", v.join(" "))
        })
        .collect();
    std::fs::write(path, out).unwrap();
    path.to_path_buf()
}

/// `simulate` of the scenario `toml` (written to `d/scenario.toml`) into `d/sim`; that directory.
fn simulated_from(d: &Path, toml: &str) -> PathBuf {
    let (sc, sim) = (d.join("scenario.toml"), d.join("sim"));
    std::fs::write(&sc, toml).unwrap();
    let (ok, _, err) = sinsmodel(&["simulate", p(&sc), "--out", p(&sim)]);
    assert!(ok, "{err}");
    sim
}
