//! The README's shell commands, run verbatim and in order, as a new user would from a fresh
//! clone with `../shared` beside it.
//!
//! Every ```` ```sh ```` block of `README.md` is split into commands (`\` continuations joined,
//! trailing `# comments` dropped). Each runs under `bash` in a scratch copy of the checkout's
//! layout (`scenarios/`, `examples/` and `formats/` linked read-only, `../shared` linked, everything the
//! commands write lands in the scratch directory), with `sinsmodel` on the PATH being the binary
//! this test suite built. Three kinds of command are treated specially, each listed below with
//! its reason, and each entry must match a README command (so the lists cannot go stale):
//! - `cargo run --release -- ARGS` runs as `sinsmodel ARGS` (the same program; the suite does
//!   not build the release profile a second time);
//! - long commands run in a quick variant (`QUICK`);
//! - commands that would act on the machine or the checkout rather than on data are not run
//!   (`NOT_RUN`).
//!
//! A command the test does not know (not `sinsmodel …` and not in a list) fails the test, as
//! does any command exiting non-zero or printing a panic. The `reproduce` commands, which read
//! nothing the others write, run in order on a second thread in their own scratch directory.

use std::path::{Path, PathBuf};
use std::process::Command;

/// README command (exact) → the quick variant the test runs instead, and why.
const QUICK: &[(&str, &str, &str)] = &[
    (
        "sinsmodel reproduce --out out/reproduce --priors-grid",
        "sinsmodel reproduce --quick --out out/reproduce --priors-grid",
        "the full run takes ~10 min; --quick runs the same cases for 10 minutes each",
    ),
    (
        "sinsmodel reproduce --consistency --out out/mc",
        "sinsmodel reproduce --consistency --quick --out out/mc",
        "20 seeds of 1 h; --quick runs 20 seeds of 10 min",
    ),
    (
        "sinsmodel bench",
        "sinsmodel bench --seconds 20 --explain-seconds 20 --memory-seconds 20 --kf-gins-seconds 20",
        "the benchmark runs minutes of data per job by design",
    ),
    (
        "sinsmodel explain-eval --cases 200 --seed 7 --out out/explain-eval",
        "sinsmodel explain-eval --cases 4 --seed 7 --out out/explain-eval",
        "200 cases take ~5 min on two cores",
    ),
];

/// README commands (prefix) the test does not run, and why.
const NOT_RUN: &[(&str, &str)] = &[
    ("tools/test", "it is the test suite this test is part of"),
    (
        "cargo build --release",
        "the suite builds the same binary in its test profile and puts it on the PATH",
    ),
    (
        "export PATH=",
        "the test puts the binary it built on the PATH itself",
    ),
    (
        "UPDATE_SNAPSHOTS=1 cargo test",
        "it rewrites the checked-in snapshots; the suite runs the same test in check mode",
    ),
    (
        "cargo bench",
        "criterion runs for minutes; the benches are compiled by clippy --all-targets",
    ),
    (
        "tools/bench-table",
        "it runs the benchmarks for minutes and rewrites the README's table",
    ),
    (
        "tools/kf-gins-compare",
        "it needs a KF-GINS binary built from KF-GINS's own checkout; tools/test_kf_gins_compare.py runs it with a stand-in",
    ),
];

/// The commands of every ```sh block, continuations joined, comments dropped.
fn readme_commands(text: &str) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    let mut in_sh = false;
    let mut pending: Option<(usize, String)> = None;
    for (k, line) in text.lines().enumerate() {
        let trimmed = line.trim();
        if trimmed.starts_with("```") {
            in_sh = !in_sh && trimmed == "```sh";
            continue;
        }
        if !in_sh {
            continue;
        }
        let code = strip_comment(line);
        let (cont, body) = match code.trim_end().strip_suffix('\\') {
            Some(b) => (true, b.trim().to_string()),
            None => (false, code.trim().to_string()),
        };
        let cmd = match pending.take() {
            Some((l, mut s)) => {
                s.push(' ');
                s.push_str(&body);
                (l, s)
            }
            None => (k + 1, body),
        };
        if cont {
            pending = Some(cmd);
        } else if !cmd.1.is_empty() {
            out.push(cmd);
        }
    }
    out
}

/// The line without a `#` comment (a `#` at the start or after whitespace, outside quotes).
fn strip_comment(line: &str) -> &str {
    let (mut single, mut double) = (false, false);
    let mut prev_space = true;
    for (i, c) in line.char_indices() {
        match c {
            '\'' if !double => single = !single,
            '"' if !single => double = !double,
            '#' if !single && !double && prev_space => return &line[..i],
            _ => {}
        }
        prev_space = c.is_whitespace();
    }
    line
}

/// The shell line the test runs for a README command, or why it does not run it.
fn plan(cmd: &str, used: &mut [bool]) -> Result<String, String> {
    for (prefix, why) in NOT_RUN {
        if cmd.starts_with(prefix) {
            return Err(why.to_string());
        }
    }
    let cmd = match cmd.strip_prefix("cargo run --release --") {
        Some(rest) => format!("sinsmodel{rest}"),
        None => cmd.to_string(),
    };
    for (k, (from, to, _)) in QUICK.iter().enumerate() {
        if cmd == *from {
            used[k] = true;
            return Ok(to.to_string());
        }
    }
    if cmd.starts_with("sinsmodel ") || cmd == "sinsmodel" {
        return Ok(cmd);
    }
    panic!("README command the test does not know how to run (add it to QUICK or NOT_RUN with a reason): {cmd}");
}

fn link(from: &Path, to: &Path) {
    std::os::unix::fs::symlink(from, to)
        .unwrap_or_else(|e| panic!("cannot link {} to {}: {e}", to.display(), from.display()));
}

#[test]
fn readme_commands_run_verbatim_in_order() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let shared = root.join("../shared");
    assert!(
        shared.join("data").is_dir(),
        "the README's real-data commands need ../shared beside the checkout ({} is missing)",
        shared.display()
    );
    let text = std::fs::read_to_string(root.join("README.md")).expect("README.md");
    let commands = readme_commands(&text);
    assert!(
        commands.len() >= 20,
        "only {} commands found",
        commands.len()
    );

    // scratch layout: <tmp>/main (the commands' working directory) and <tmp>/shared
    let tmp = tempfile::tempdir().expect("tempdir");
    let work = tmp.path().join("main");
    std::fs::create_dir(&work).unwrap();
    link(&shared.canonicalize().unwrap(), &tmp.path().join("shared"));
    for dir in ["scenarios", "examples", "formats"] {
        link(&root.join(dir), &work.join(dir));
    }
    let bin_dir = tmp.path().join("bin");
    std::fs::create_dir(&bin_dir).unwrap();
    link(
        Path::new(env!("CARGO_BIN_EXE_sinsmodel")),
        &bin_dir.join("sinsmodel"),
    );
    let path = format!(
        "{}:{}",
        bin_dir.display(),
        std::env::var("PATH").unwrap_or_default()
    );

    // Plan every command first; `sinsmodel reproduce` simulates its own data and reads nothing
    // the other commands write, so those run in order on a second thread in a scratch
    // directory of their own, beside the main sequence (the suite has two cores).
    let mut used = vec![false; QUICK.len()];
    let mut main_seq: Vec<(usize, String)> = Vec::new();
    let mut side_seq: Vec<(usize, String)> = Vec::new();
    for (line, cmd) in &commands {
        match plan(cmd, &mut used) {
            Ok(shell) if shell.starts_with("sinsmodel reproduce ") => side_seq.push((*line, shell)),
            Ok(shell) => main_seq.push((*line, shell)),
            Err(why) => eprintln!("README.md:{line}: not run: {cmd}  ({why})"),
        }
    }
    let side_work = tmp.path().join("side");
    std::fs::create_dir(&side_work).unwrap();
    let side = {
        let path = path.clone();
        std::thread::spawn(move || run_all(&side_seq, &side_work, &path))
    };
    let ran = run_all(&main_seq, &work, &path) + side.join().expect("reproduce commands");
    for (k, (from, _, why)) in QUICK.iter().enumerate() {
        assert!(
            used[k],
            "QUICK entry `{from}` ({why}) matches no README command: update the list"
        );
    }
    for (prefix, _) in NOT_RUN {
        assert!(
            commands.iter().any(|(_, c)| c.starts_with(prefix)),
            "NOT_RUN entry `{prefix}` matches no README command: update the list"
        );
    }
    eprintln!(
        "{ran} README commands ran, {} not run",
        commands.len() - ran
    );
}

/// Runs shell lines in order in `dir` with `path`, failing on the first that fails; returns
/// how many ran.
fn run_all(seq: &[(usize, String)], dir: &Path, path: &str) -> usize {
    for (line, shell) in seq {
        let t0 = std::time::Instant::now();
        let out = Command::new("bash")
            .args(["-c", &format!("set -euo pipefail; {shell}")])
            .current_dir(dir)
            .env("PATH", path)
            .output()
            .expect("bash");
        let stderr = String::from_utf8_lossy(&out.stderr);
        eprintln!(
            "README.md:{line}: {shell}  ({:.1} s)",
            t0.elapsed().as_secs_f64()
        );
        assert!(
            out.status.success() && !stderr.contains("panicked"),
            "README.md:{line}: `{shell}` failed ({}):\n{}\n{stderr}",
            out.status,
            String::from_utf8_lossy(&out.stdout)
        );
    }
    seq.len()
}

#[test]
fn comments_and_continuations_are_parsed() {
    let text = "x\n```sh\nsinsmodel a --p 'b # c' \\\n    --d e   # note\n# only a comment\n```\n```\nsinsmodel not-sh\n```\n";
    let c = readme_commands(text);
    assert_eq!(c, vec![(3, "sinsmodel a --p 'b # c' --d e".to_string())]);
}

/// Run verbatim, no README command writes into the shipped `docs/` (the full `reproduce` once
/// wrote `docs/reproduce/`, replacing the results the README shows); refreshing them is named in
/// prose, not given as a command to copy (#25).
#[test]
fn readme_commands_write_nothing_into_docs() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(root.join("README.md")).expect("README.md");
    for (line, cmd) in readme_commands(&text) {
        let words: Vec<&str> = cmd.split_whitespace().collect();
        for w in words.windows(2) {
            let output = matches!(w[0], "--out" | "--json" | "--plot");
            assert!(
                !(output && w[1].trim_matches(['\'', '"']).starts_with("docs/")),
                "README.md line {}: `{cmd}` writes into the shipped docs/",
                line + 1
            );
        }
    }
}
