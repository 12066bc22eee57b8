//! Readers against the real measured data in ../shared/data (see its README).

use sinsmodel::io::readers::{gnss_imu, rtklib};
use std::path::PathBuf;

mod common;

fn data(rel: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/data")
        .join(rel)
}

#[test]
fn psins_lasergyro_log() {
    let log =
        sinsmodel::io::imu_stream::read_psins(&data("psins-lasergyro/lasergyro.imu")).unwrap();
    let imu = &log.imu;
    assert_eq!(imu.samples.len(), 184_718);
    assert!((imu.rate_hz() - 100.0).abs() < 1e-6);
    imu.check_time("lasergyro", 1.5).unwrap();
    let (f, w) = imu.mean_rates();
    let w_degh = w.norm().to_degrees() * 3600.0;
    eprintln!(
        "lasergyro: |mean f| = {:.4} m/s^2, |mean w| = {w_degh:.3} deg/h, f = {f:?}",
        f.norm()
    );
    assert!((f.norm() - 9.795).abs() < 0.005, "{}", f.norm());
    assert!((w_degh - 14.9).abs() < 0.1, "{w_degh}");
    // FRD: gravity reaction points up, i.e. along -z for a near-level vehicle
    assert!(f.z < -9.7);
    assert!((log.lat_deg - 34.246048).abs() < 1e-9);
    assert!(
        (log.euler_deg[2] - 90.6).abs() < 1e-9,
        "NED yaw from PSINS yaw -90.6"
    );
}

#[test]
fn gnss_imu_drive_on_gpst_with_rtk_aligned() {
    let log = gnss_imu::read(&data("gnss-imu-drive/imu_1934.csv")).unwrap();
    let imu = &log.imu;
    let n = imu.samples.len();
    eprintln!(
        "gnss_imu: {n} samples, skipped lines {:?}, GPST {:.3} .. {:.3}",
        log.skipped,
        imu.samples[0].t,
        imu.samples[n - 1].t
    );
    assert!((54_800..54_900).contains(&n), "{n}");
    assert!((imu.rate_hz() - 100.0).abs() < 1.0);
    let pos = rtklib::read(&data("gnss-imu-drive/gnss_1934_sf.pos")).unwrap();
    assert_eq!(pos.len(), 2197);
    let fixed = pos.iter().filter(|p| p.q == 1).count() as f64 / pos.len() as f64;
    assert!(fixed > 0.99);
    // both on GPST 2025-07-08 19:34 .. 19:43, overlapping by more than 540 s
    let (i0, i1) = (imu.samples[0].t, imu.samples[n - 1].t);
    let (p0, p1) = (pos[0].t, pos[pos.len() - 1].t);
    let day = rtklib::days_from_civil(2025, 7, 8) as f64 * 86400.0;
    assert!((p0 - (day + 19.0 * 3600.0 + 34.0 * 60.0 + 18.499)).abs() < 1e-6);
    let overlap = i1.min(p1) - i0.max(p0);
    assert!(overlap > 540.0, "overlap {overlap} s");
    // alignment: the car drives off in both records at the same time (within 0.5 s):
    // RTK speed first exceeds 1 m/s; IMU horizontal specific force (sensor x, y) first departs
    // from its static mean by 1 m/s² for 0.5 s.
    let t_rtk = pos
        .iter()
        .find(|p| p.v_ned.map(|v| v[0].hypot(v[1])).unwrap_or(0.0) > 1.0)
        .unwrap()
        .t;
    let dt = imu.interval();
    let static_n = 3000;
    let mean = imu.samples[..static_n]
        .iter()
        .map(|s| s.dv / dt)
        .sum::<nalgebra::Vector3<f64>>()
        / static_n as f64;
    let filt: Vec<(f64, f64)> = imu
        .samples
        .windows(50)
        .map(|w| {
            let m = w.iter().map(|s| s.dv / dt).sum::<nalgebra::Vector3<f64>>() / 50.0 - mean;
            (w[49].t, m.x.hypot(m.y))
        })
        .collect();
    let t_imu = filt
        .iter()
        .find(|x| x.0 > t_rtk - 30.0 && x.1 > 1.0)
        .map(|x| x.0)
        .unwrap();
    eprintln!(
        "drive-off: RTK speed > 1 m/s at {t_rtk:.2}, IMU horizontal accel > 1 m/s^2 at {t_imu:.2}"
    );
    assert!(
        t_imu < t_rtk + 0.5 && t_imu > t_rtk - 5.0,
        "IMU {t_imu} vs RTK {t_rtk}"
    );
}

/// A GNSS_IMU csv without its `.tag`: refused with the way out named; with `--clock-offset`
/// (here the offset the tag gives) the same samples as with the tag.
#[test]
fn gnss_imu_csv_without_tag_takes_a_clock_offset() {
    let with_tag = gnss_imu::read(&data("gnss-imu-drive/imu_1934.csv")).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let copy = dir.path().join("imu_1934.csv");
    std::fs::copy(data("gnss-imu-drive/imu_1934.csv"), &copy).unwrap();
    let e = gnss_imu::read(&copy).unwrap_err();
    assert!(format!("{e:#}").contains("--clock-offset"), "{e:#}");
    let given = gnss_imu::read_with(&copy, Some(with_tag.clock_offset)).unwrap();
    assert_eq!(given.imu.samples, with_tag.imu.samples);
    // through the command line: refused without, read with
    let bin = env!("CARGO_BIN_EXE_sinsmodel");
    let run = |extra: &[&str]| {
        let mut a = vec!["imu-check", "--imu", copy.to_str().unwrap(), "--tilted"];
        a.extend_from_slice(extra);
        std::process::Command::new(bin).args(&a).output().unwrap()
    };
    let out = run(&[]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--clock-offset"));
    let out = run(&["--clock-offset", "0"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        out.status.success() && err.contains("clock offset 0 s from --clock-offset"),
        "{err}"
    );
    // a text IMU file takes no clock offset
    let txt = dir.path().join("x.txt");
    std::fs::write(&txt, "0.01 0 0 0 0 0 -0.098\n0.02 0 0 0 0 0 -0.098\n").unwrap();
    let out = std::process::Command::new(bin)
        .args([
            "imu-check",
            "--imu",
            txt.to_str().unwrap(),
            "--clock-offset",
            "5",
        ])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
}

/// A PSINS user's MATLAB file: the drive scenario simulated by the project, its increments
/// turned into PSINS `[wm vm t]` (right-forward-up) and its truth into `avp`, written as a
/// level-5 `.mat`; `filter --imu FILE.mat:imu --truth FILE.mat:avp` gives the same navigation
/// solution, number for number, as the same data in the project's text files.
#[test]
fn matlab_file_reads_like_the_text_it_came_from() {
    use sinsmodel::io::readers::matlab;
    let dir = tempfile::tempdir().unwrap();
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let sim = dir.path().join("drive");
    let (ok, _, err) = common::sinsmodel(&[
        "simulate",
        root.join("scenarios/drive.toml").to_str().unwrap(),
        "--out",
        sim.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let imu = sinsmodel::io::imu_stream::read_text(&sim.join("imu.txt")).unwrap();
    let truth = sinsmodel::io::truth::read(&sim.join("truth.txt")).unwrap();
    let mut wm_vm_t = Vec::new();
    for s in &imu.samples {
        // FRD → PSINS X right, Y forward, Z up
        wm_vm_t.extend_from_slice(&[s.dtheta.y, s.dtheta.x, -s.dtheta.z]);
        wm_vm_t.extend_from_slice(&[s.dv.y, s.dv.x, -s.dv.z, s.t]);
    }
    let mut avp = Vec::new();
    for r in &truth {
        // [pitch roll yaw] with yaw west of north, [vE vN vU], [lat lon h], t
        avp.extend_from_slice(&[r.euler.y, r.euler.x, -r.euler.z, r.v.y, r.v.x, -r.v.z]);
        avp.extend_from_slice(&[r.lat, r.lon, r.h, r.t]);
    }
    let mat = dir.path().join("drive.mat");
    matlab::write(&mat, &[("imu", &wm_vm_t, 7), ("avp", &avp, 10)]).unwrap();
    let run = |imu: String, truth: String, out: &str| {
        let out = dir.path().join(out);
        let (ok, _, err) = common::sinsmodel(&[
            "filter",
            "--model",
            "P13",
            "--imu",
            &imu,
            "--truth",
            &truth,
            "--aid",
            sim.join("gnss.txt").to_str().unwrap(),
            "--nav-rate",
            "1",
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(ok, "{err}");
        let rows = |name: &str| -> Vec<String> {
            std::fs::read_to_string(out.join(name))
                .unwrap()
                .lines()
                .filter(|l| !l.starts_with('#'))
                .map(String::from)
                .collect()
        };
        (rows("nav.txt"), rows("states.txt"), err)
    };
    let m = mat.to_str().unwrap();
    let (nav_mat, states_mat, err) = run(format!("{m}:imu"), format!("{m}:avp"), "mat");
    assert!(
        err.contains("MATLAB variable") && err.contains("right-forward-up"),
        "{err}"
    );
    let (nav_txt, states_txt, _) = run(
        sim.join("imu.txt").to_str().unwrap().into(),
        sim.join("truth.txt").to_str().unwrap().into(),
        "txt",
    );
    assert!(nav_mat.len() > 100, "{}", nav_mat.len());
    assert_eq!(nav_mat, nav_txt);
    assert_eq!(states_mat, states_txt);
    // the variable can be left out when one array has the columns; a wrong one is named
    let (ok, _, err) = common::sinsmodel(&["imu-check", "--imu", m]);
    assert!(ok, "{err}");
    let (ok, _, err) = common::sinsmodel(&["imu-check", "--imu", &format!("{m}:wm")]);
    assert!(
        !ok && err.contains("no numeric array `wm`")
            && err.contains("imu (")
            && err.contains("avp ("),
        "{err}"
    );
    // an output is never written over the .mat it reads, nor under a name that reads as
    // FILE.mat:VARIABLE
    let imu_var = format!("{m}:imu");
    let navigate_to = |out: &str| {
        common::sinsmodel(&[
            "navigate", "--imu", &imu_var, "--lat", "30", "--lon", "114", "--att", "0,0,0",
            "--out", out,
        ])
    };
    let (ok, _, err) = navigate_to(m);
    assert!(!ok && err.contains("input"), "{err}");
    let named = format!("{}:imu", dir.path().join("out.mat").display());
    let (ok, _, err) = navigate_to(&named);
    assert!(!ok && err.contains("selects a MATLAB variable"), "{err}");
}

/// A solution written in UTC (or JST) is refused with the line and the leap seconds, not read as
/// GPST 18 s early; the GPST header of the shared drive is accepted.
#[test]
fn rtklib_times_in_utc_are_refused() {
    let src = data("gnss-imu-drive/gnss_1934_sf.pos");
    let text = std::fs::read_to_string(&src).unwrap();
    assert!(text.contains("%  GPST"), "the shared file states GPST");
    assert!(rtklib::read(&src).is_ok());
    let dir = std::env::temp_dir().join(format!("sinsmodel-utc-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for (sys, early) in [
        ("UTC", "18 s early"),
        ("JST", "9 h 18 s early"),
        ("utc", "18 s early"),
    ] {
        let p = dir.join(format!("{sys}.pos"));
        std::fs::write(&p, text.replacen("%  GPST", &format!("%  {sys} "), 1)).unwrap();
        let e = rtklib::read(&p).unwrap_err().to_string();
        let line = text.lines().position(|l| l.starts_with("%  GPST")).unwrap() + 1;
        assert!(e.contains(&format!("{sys}.pos:{line}:")), "{e}");
        assert!(e.contains(early) && e.contains("GPST = UTC + 18 s"), "{e}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// A time-tag file cut short is refused (its early records alone put the clock seconds late),
/// naming how much of the log it covers.
#[test]
fn a_truncated_time_tag_file_is_refused() {
    let dir = std::env::temp_dir().join(format!("sinsmodel-tag-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let csv = dir.join("imu_1934.csv");
    std::fs::copy(data("gnss-imu-drive/imu_1934.csv"), &csv).unwrap();
    let tag = std::fs::read(data("gnss-imu-drive/imu_1934.csv.tag")).unwrap();
    // the 76-byte header and the first half of the 8-byte records
    let half = 76 + (tag.len() - 76) / 16 * 8;
    std::fs::write(dir.join("imu_1934.csv.tag"), &tag[..half]).unwrap();
    let e = format!("{:#}", gnss_imu::read(&csv).unwrap_err());
    assert!(
        e.contains("truncated time-tag file") && e.contains("--clock-offset"),
        "{e}"
    );
    std::fs::write(dir.join("imu_1934.csv.tag"), &tag).unwrap();
    assert!(gnss_imu::read(&csv).is_ok());
    // zero padding after the records is no truncation
    let mut padded = tag.clone();
    padded.extend([0u8; 800]);
    std::fs::write(dir.join("imu_1934.csv.tag"), &padded).unwrap();
    assert!(gnss_imu::read(&csv).is_ok());
    std::fs::remove_dir_all(&dir).ok();
}

/// One corrupted record of the drive's `.tag` (a tick 5 s back, or a file position 777 bytes
/// on) had moved the IMU clock silently (by up to 5 s): refused naming the record.
#[test]
fn a_corrupted_time_tag_record_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let csv = data("gnss-imu-drive/imu_1934.csv");
    let tag = std::fs::read(data("gnss-imu-drive/imu_1934.csv.tag")).unwrap();
    for (name, field, delta) in [("tick", 0usize, -5000i64), ("pos", 4usize, 777i64)] {
        let d = dir.path().join(name);
        std::fs::create_dir(&d).unwrap();
        std::fs::copy(&csv, d.join("imu_1934.csv")).unwrap();
        let mut t = tag.clone();
        let at = 76 + 8 * 18_000 + field;
        let v = u32::from_le_bytes(t[at..at + 4].try_into().unwrap()) as i64 + delta;
        t[at..at + 4].copy_from_slice(&(v as u32).to_le_bytes());
        std::fs::write(d.join("imu_1934.csv.tag"), t).unwrap();
        let e = format!("{:#}", gnss_imu::read(&d.join("imu_1934.csv")).unwrap_err());
        assert!(
            e.contains("goes back from record") && e.contains("corrupted"),
            "{name}: {e}"
        );
    }
    // the intact one reads
    gnss_imu::read(&csv).unwrap();
}

/// A `.pos` without its column header is read as GPST with a warning that says so; an IMU
/// whose clock is 1000× slow (ms read as s: 0.1 Hz) is refused with that cause.
#[test]
fn a_pos_without_its_time_system_and_a_slow_clock_are_said() {
    let dir = tempfile::tempdir().unwrap();
    let pos = std::fs::read_to_string(data("gnss-imu-drive/gnss_1934_sf.pos")).unwrap();
    let bare: String = pos
        .lines()
        .filter(|l| !l.starts_with('%'))
        .map(|l| format!("{l}\n"))
        .collect();
    let p = dir.path().join("bare.pos");
    std::fs::write(&p, bare).unwrap();
    let imu = dir.path().join("imu.txt");
    let rows: String = (1..=2000)
        .map(|k| format!("{} 0 0 0 0 0 -0.0980665\n", k as f64 * 10.0))
        .collect();
    std::fs::write(&imu, rows).unwrap();
    let filter = |imu: &std::path::Path| {
        common::sinsmodel(&[
            "filter",
            "--model",
            "P13",
            "--grade",
            "mems",
            "--imu",
            imu.to_str().unwrap(),
            "--aid",
            p.to_str().unwrap(),
            "--init",
            "40.0966268,-105.1474483,1601.474,-178.19,6.687,178.97",
            "--out",
            dir.path().join("o").to_str().unwrap(),
        ])
    };
    let (_, _, err) = filter(&data("gnss-imu-drive/imu_1934.csv"));
    assert!(
        err.contains("bare.pos: no column header") && err.contains("read as GPST"),
        "{err}"
    );
    let (ok, _, err) = filter(&imu);
    assert!(!ok && err.contains("time in ms read as s"), "{err}");
}
