//! Helpers shared by the tests that run the `sinsmodel` binary.

use std::process::Command;

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
