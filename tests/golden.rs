//! Golden outputs: the commands whose numbers the project publishes, run on a seeded simulated
//! case and on both shared logs, compared bit for bit with `tests/golden/*.txt`.
//!
//! A refactoring must leave every one of these unchanged. Each golden file holds the exit status,
//! stdout and stderr as printed (wall-clock times masked), every text output of up to 64 KiB in
//! full, and the size and FNV-1a 64 hash of every output file (PNG plots and `nav.txt` included),
//! so a change anywhere in a result shows, and the diff shows where.
//!
//! When a change of the numbers is intended, regenerate with
//! `SINSMODEL_BLESS=1 cargo test --test golden` and say why in the commit.
//!
//! The commands run from the repository root with relative paths, so no absolute path enters an
//! output; the outputs go under `target/golden/`.

mod common;

use common::check_golden as check;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;

/// The repository root.
fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// FNV-1a 64 of `bytes` (stable across Rust releases, unlike the std hasher).
fn fnv1a(bytes: &[u8]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for &b in bytes {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0100_0000_01b3);
    }
    h
}

/// Masks what changes from run to run: the lines that carry wall-clock durations (explain-eval's
/// `seconds_taken`, wall time and time per case).
fn mask(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for line in text.lines() {
        let lower = line.to_ascii_lowercase();
        if lower.contains("seconds_taken")
            || lower.contains("seconds_per_case")
            || lower.contains("wall")
            || lower.contains("per case")
        {
            out.push_str("<timing line masked>\n");
        } else {
            out.push_str(line);
            out.push('\n');
        }
    }
    out
}

/// Every file below `dir`, sorted, as paths relative to it.
fn files_below(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        let Ok(rd) = std::fs::read_dir(&d) else {
            continue;
        };
        for e in rd {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else {
                out.push(p.strip_prefix(dir).unwrap().to_path_buf());
            }
        }
    }
    out.sort();
    out
}

/// Whether an output's text is shown in full in the golden file.
fn shown_in_full(name: &Path, bytes: &[u8]) -> bool {
    let ext = name.extension().and_then(|e| e.to_str()).unwrap_or("");
    matches!(ext, "json" | "md" | "txt" | "toml")
        && bytes.len() <= 64 * 1024
        && std::str::from_utf8(bytes).is_ok()
}

/// Runs `args` from the repository root and renders what it printed and wrote (`outputs`: the
/// output files or directories it names, relative to the root).
fn render(args: &[&str], outputs: &[&str]) -> String {
    for o in outputs {
        let p = root().join(o);
        let _ = std::fs::remove_dir_all(&p);
        let _ = std::fs::remove_file(&p);
    }
    let out = Command::new(env!("CARGO_BIN_EXE_sinsmodel"))
        .current_dir(root())
        .args(args)
        .output()
        .expect("run sinsmodel");
    let mut s = String::new();
    writeln!(s, "$ sinsmodel {}", args.join(" ")).unwrap();
    writeln!(s, "exit: {:?}", out.status.code()).unwrap();
    writeln!(s, "--- stdout").unwrap();
    s.push_str(&mask(&String::from_utf8_lossy(&out.stdout)));
    writeln!(s, "--- stderr").unwrap();
    s.push_str(&mask(&String::from_utf8_lossy(&out.stderr)));
    for o in outputs {
        let p = root().join(o);
        let files = if p.is_dir() {
            files_below(&p)
        } else if p.exists() {
            vec![PathBuf::new()]
        } else {
            writeln!(s, "--- {o}: not written").unwrap();
            continue;
        };
        for f in files {
            let path = if f.as_os_str().is_empty() {
                p.clone()
            } else {
                p.join(&f)
            };
            let mut bytes = std::fs::read(&path).unwrap();
            let shown = path.strip_prefix(root()).unwrap().display().to_string();
            // a run marker records each file's modification time: compared by its names
            if path.file_name().is_some_and(|n| n == ".sinsmodel-run") {
                let names: String = String::from_utf8_lossy(&bytes)
                    .lines()
                    .map(|l| l.split('\t').next().unwrap_or(l).to_string() + "\n")
                    .collect();
                bytes = names.into_bytes();
            }
            // a text shown in full is hashed as masked (explain-eval's times)
            let full =
                shown_in_full(&path, &bytes).then(|| mask(std::str::from_utf8(&bytes).unwrap()));
            let hash = fnv1a(full.as_ref().map_or(&bytes[..], |t| t.as_bytes()));
            let len = full.as_ref().map_or(bytes.len(), String::len);
            writeln!(s, "--- {shown}: {len} bytes, fnv1a64 {hash:016x}").unwrap();
            if let Some(t) = full {
                s.push_str(&t);
            }
        }
    }
    s
}

const RLG: &str = "../shared/data/psins-lasergyro/lasergyro.imu";
const MEMS_IMU: &str = "../shared/data/gnss-imu-drive/imu_1934.csv";
const MEMS_POS: &str = "../shared/data/gnss-imu-drive/gnss_1934_sf.pos";

#[test]
fn demo_explain() {
    let s = render(
        &["explain", "--out", "target/golden/demo"],
        &["target/golden/demo"],
    );
    check("demo_explain", &s);
}

#[test]
fn simulated_drive_filter_and_explain() {
    let mut s = render(
        &[
            "simulate",
            "scenarios/drive.toml",
            "--out",
            "target/golden/drive",
        ],
        &["target/golden/drive"],
    );
    s += &render(
        &[
            "filter",
            "--model",
            "P28+vertical",
            "--imu",
            "target/golden/drive/imu.txt",
            "--aid",
            "target/golden/drive/gnss.txt",
            "--truth",
            "target/golden/drive/truth.txt",
            "--outage",
            "100,20",
            "--out",
            "target/golden/drive_filter",
        ],
        &["target/golden/drive_filter"],
    );
    s += &render(
        &[
            "explain",
            "--model",
            "P13+vertical",
            "--imu",
            "target/golden/drive/imu.txt",
            "--aid",
            "target/golden/drive/gnss.txt",
            "--truth",
            "target/golden/drive/truth.txt",
            "--grade",
            "tactical",
            "--out",
            "target/golden/drive_explain",
        ],
        &["target/golden/drive_explain"],
    );
    check("simulated_drive", &s);
}

#[test]
fn laser_gyro_filter_and_explain() {
    let mut s = render(
        &[
            "filter",
            "--model",
            "P13",
            "--imu",
            RLG,
            "--static-aid",
            "34.246048,108.909664,380",
            "--init",
            "34.246048,108.909664,380,0.3878,1.0026,90.603",
            "--out",
            "target/golden/rlg_filter",
        ],
        &["target/golden/rlg_filter"],
    );
    s += &render(
        &[
            "explain",
            "--model",
            "P28",
            "--imu",
            RLG,
            "--static-aid",
            "34.246048,108.909664,380",
            "--init",
            "34.246048,108.909664,380,0.3878,1.0026,90.603",
            "--noise",
            "docs/real-data/rlg_allan.json",
            "--out",
            "target/golden/rlg_explain",
        ],
        &["target/golden/rlg_explain"],
    );
    check("laser_gyro", &s);
}

#[test]
fn mems_drive_filter_and_explain() {
    let mut s = render(
        &[
            "filter",
            "--model",
            "P13+vertical",
            "--imu",
            MEMS_IMU,
            "--aid",
            MEMS_POS,
            "--init",
            "auto",
            "--grade",
            "mems",
            "--mode",
            "closed",
            "--noise",
            "docs/real-data/mems_static_allan.json",
            "--outage",
            "200,30",
            "--outage",
            "400,30",
            "--out",
            "target/golden/mems_filter",
        ],
        &["target/golden/mems_filter"],
    );
    s += &render(
        &[
            "explain",
            "--model",
            "P28+vertical",
            "--imu",
            MEMS_IMU,
            "--aid",
            MEMS_POS,
            "--init",
            "40.0966268,-105.1474483,1601.476,-178.192,6.687,-181.028",
            "--mode",
            "closed",
            "--noise",
            "docs/real-data/mems_static_allan.json",
            "--prior",
            "eps_*=0.5 deg/s",
            "--prior",
            "nabla_*=0.5 m/s^2",
            "--prior",
            "phi_n=2 deg",
            "--prior",
            "phi_e=2 deg",
            "--prior",
            "phi_d=10 deg",
            "--out",
            "target/golden/mems_explain",
        ],
        &["target/golden/mems_explain"],
    );
    s += &render(
        &[
            "explain",
            "--model",
            "P13+vertical",
            "--imu",
            MEMS_IMU,
            "--aid",
            MEMS_POS,
            "--init",
            "auto",
            "--grade",
            "mems",
            "--mode",
            "closed",
            "--out",
            "target/golden/mems_explain_grade",
        ],
        &["target/golden/mems_explain_grade"],
    );
    check("mems_drive", &s);
}

#[test]
fn reproduce_and_eval_quick() {
    let mut s = render(
        &["reproduce", "--quick", "--out", "target/golden/reproduce"],
        &["target/golden/reproduce"],
    );
    s += &render(
        &[
            "explain-eval",
            "--cases",
            "4",
            "--seed",
            "11",
            "--seconds",
            "300",
            "--jobs",
            "2",
            "--out",
            "target/golden/eval",
        ],
        &["target/golden/eval"],
    );
    check("reproduce_eval", &s);
}

#[test]
fn model_listing_and_jacobian() {
    let mut s = render(&["model", "list"], &[]);
    s += &render(&["model", "show", "P28+kaq_x_xy+kgf_xz"], &[]);
    s += &render(
        &["jacobian", "--model", "P31", "--at", "examples/point.json"],
        &[],
    );
    s += &render(
        &[
            "jacobian",
            "--model",
            "P24+vertical+size_x",
            "--runtime",
            "--at",
            "examples/point.json",
        ],
        &[],
    );
    check("model_jacobian", &s);
}
