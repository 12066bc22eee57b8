//! Helpers shared by the tests that run the `sinsmodel` binary.

use std::process::Command;

#[allow(dead_code)]
/// Runs the binary built for these tests: (success, stdout, stderr).
pub fn sinsmodel(args: &[&str]) -> (bool, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_sinsmodel"))
        .args(args)
        .output()
        .expect("run sinsmodel");
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[allow(dead_code)]
/// Compares `actual` with `tests/golden/NAME.txt` (or writes it under `SINSMODEL_BLESS=1`).
pub fn check_golden(name: &str, actual: &str) {
    let root = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let path = root.join("tests/golden").join(format!("{name}.txt"));
    if std::env::var_os("SINSMODEL_BLESS").is_some() {
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(&path, actual).unwrap();
        return;
    }
    let expected = std::fs::read_to_string(&path).unwrap_or_else(|e| {
        panic!(
            "{}: {e} (SINSMODEL_BLESS=1 cargo test --test golden --test bad_corpus writes it)",
            path.display()
        )
    });
    if expected != actual {
        let (mut shown, mut n) = (String::new(), 0);
        for (i, (a, b)) in expected.lines().zip(actual.lines()).enumerate() {
            if a != b && n < 12 {
                shown.push_str(&format!("line {}:\n  golden: {a}\n  now:    {b}\n", i + 1));
                n += 1;
            }
        }
        panic!(
            "{name}: the output differs from {} ({} golden lines, {} now); first differences:\n{shown}",
            path.display(),
            expected.lines().count(),
            actual.lines().count()
        );
    }
}

#[allow(dead_code)]
/// The options `docs/explain.md` §2 gives explain on the shared MEMS drive after the files: the
/// start from the drive-off, closed loop, and the MEMS priors (the caller adds `--model`,
/// `--imu`, `--aid`, `--noise` and `--out`).
pub const MEMS_DRIVE_START_AND_PRIORS: [&str; 14] = [
    "--init",
    "40.0966268,-105.1474483,1601.476,-178.192,6.687,-181.028",
    "--mode",
    "closed",
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
];
