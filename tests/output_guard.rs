//! No output path removes or replaces a file the run cannot prove it wrote: run directories
//! need a marker that lists their files, the sweep of killed runs' leftovers takes only this
//! crate's temporaries, single-file outputs replace only their own command's earlier output
//! (else `--overwrite`), and a SIGINT/SIGTERM or a file-size limit leaves no half-written output.

mod common;

use std::path::Path;
use std::process::Command;

fn run(args: &[&str]) -> (bool, String) {
    let (ok, _, err) = common::sinsmodel(args);
    (ok, err)
}

const SCENARIO: &str = "name = \"s\"\nimu_rate_hz = 100.0\n[start]\nlat_deg = 30.0\nlon_deg = 110.0\n[[segment]]\nkind = \"rest\"\nduration_s = 20.0\n[gnss]\nrate_hz = 1.0\nsigma_ne = \"0.5 m\"\nsigma_d = \"1 m\"\n";

/// A simulated run in `d/o` (imu.txt, gnss.txt, truth.txt, scenario.toml and the marker).
fn simulate(d: &Path) -> std::path::PathBuf {
    let sc = d.join("s.toml");
    std::fs::write(&sc, SCENARIO).unwrap();
    let o = d.join("o");
    let (ok, err) = run(&[
        "simulate",
        sc.to_str().unwrap(),
        "--out",
        o.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    o
}

fn simulate_into(d: &Path, o: &Path) -> (bool, String) {
    run(&[
        "simulate",
        d.join("s.toml").to_str().unwrap(),
        "--out",
        o.to_str().unwrap(),
    ])
}

/// `navigate` on `imu` into `out` from a level start at 30° N 110° E.
fn navigate(imu: &str, out: &Path, force: bool) -> (bool, String) {
    let mut a = vec![
        "navigate", "--imu", imu, "--lat", "30", "--lon", "110", "--att", "0,0,0", "--out",
    ];
    let out = out.to_str().unwrap();
    a.push(out);
    if force {
        a.push("--overwrite");
    }
    run(&a)
}

/// Waits (up to a minute) until a staging directory for output `name` appears in `d`.
fn wait_for_staging(d: &Path, name: &str) {
    let t0 = std::time::Instant::now();
    let prefix = format!(".{name}.sinsmodel-staging-");
    while !names(d).iter().any(|n| n.starts_with(&prefix)) {
        assert!(t0.elapsed().as_secs() < 60, "no staging directory appeared");
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
}

fn names(d: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(d)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

/// A marker that lists no files (as older releases wrote it), an empty or foreign one, or a
/// directory of that name proves nothing: the re-run is refused, the files named, nothing lost.
#[test]
fn a_run_directory_needs_a_marker_that_lists_its_files() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let o = simulate(d);
    let marker = o.join(".sinsmodel-run");
    let listing = std::fs::read_to_string(&marker).unwrap();
    assert!(listing.starts_with("written by sinsmodel simulate; its files:\n"));
    // a re-run over its own complete output replaces it
    let (ok, err) = simulate_into(d, &o);
    assert!(ok, "{err}");
    std::fs::write(o.join("notes.txt"), "my notes").unwrap();
    for (what, bad, why) in [
        (
            "one line",
            Some("written by sinsmodel\n"),
            "does not start with",
        ),
        (
            "header only",
            Some("written by sinsmodel; its files:\n"),
            "lists no files",
        ),
        ("empty", Some(""), "does not start with"),
        ("garbage", Some("\u{0}\u{1}xyz"), "does not start with"),
        ("a directory", None, "not a plain file"),
    ] {
        let _ = std::fs::remove_file(&marker);
        let _ = std::fs::remove_dir(&marker);
        match bad {
            Some(text) => std::fs::write(&marker, text).unwrap(),
            None => std::fs::create_dir(&marker).unwrap(),
        }
        let (ok, err) = simulate_into(d, &o);
        assert!(
            !ok && err.contains("cannot prove") && err.contains(why) && err.contains("notes.txt"),
            "{what}: {err}"
        );
        assert_eq!(
            std::fs::read_to_string(o.join("notes.txt")).unwrap(),
            "my notes",
            "{what}"
        );
    }
    // a valid marker with a file it does not list: refused, naming the file
    let _ = std::fs::remove_dir(&marker);
    std::fs::write(&marker, listing).unwrap();
    let (ok, err) = simulate_into(d, &o);
    assert!(!ok && err.contains("did not write (notes.txt)"), "{err}");
    // a listed name that is now a directory is not the run's file either
    std::fs::remove_file(o.join("notes.txt")).unwrap();
    std::fs::remove_file(o.join("gnss.txt")).unwrap();
    std::fs::create_dir(o.join("gnss.txt")).unwrap();
    std::fs::write(o.join("gnss.txt/mine"), "x").unwrap();
    let (ok, err) = simulate_into(d, &o);
    assert!(!ok && err.contains("did not write (gnss.txt)"), "{err}");
    assert!(o.join("gnss.txt/mine").exists());
}

/// The sweep before a run removes only this crate's temporaries of dead processes whose
/// content proves them: users' `nav.txt.old-2024`, `.o.old-N` directories and old-style names
/// are left alone.
#[test]
fn the_sweep_of_leftovers_never_takes_a_users_file() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let o = simulate(d);
    // pid 4194304 is above Linux's pid_max: never a live process
    let theirs = [
        ".nav.txt.sinsmodel-partial-4194304-0",
        ".o.sinsmodel-staging-4194304",
        ".o.sinsmodel-old-4194304",
    ];
    std::fs::create_dir(d.join(theirs[0])).unwrap();
    std::fs::write(d.join(theirs[0]).join(".sinsmodel-partial"), PARTIAL_TEXT).unwrap();
    std::fs::write(d.join(theirs[0]).join("nav.txt"), "half").unwrap();
    std::fs::create_dir(d.join(theirs[1])).unwrap();
    std::fs::write(
        d.join(theirs[1]).join(".sinsmodel-staging"),
        "sinsmodel staging directory: removed when its run ends\n",
    )
    .unwrap();
    std::fs::write(d.join(theirs[1]).join("imu.txt"), "half").unwrap();
    std::fs::create_dir(d.join(theirs[2])).unwrap();
    std::fs::copy(
        o.join(".sinsmodel-run"),
        d.join(theirs[2]).join(".sinsmodel-run"),
    )
    .unwrap();
    let users = [
        "nav.txt.old-2024",
        "nav.txt.partial-4194304-0",
        ".o.old-4194304",
        ".o.partial-4194304",
        // our form of name, but nothing inside proves it
        ".o.sinsmodel-staging-4194305",
        ".o.sinsmodel-old-4194305",
        "nav.txt.sinsmodel-partial-4194304-x",
        ".nav.txt.sinsmodel-partial-4194305-0",
        // a plain file of exactly a temporary's former name
        "nav.txt.sinsmodel-partial-4194304-0",
    ];
    for u in &users {
        if u.starts_with('.') {
            std::fs::create_dir(d.join(u)).unwrap();
            std::fs::write(d.join(u).join("backup"), "keep").unwrap();
        } else {
            std::fs::write(d.join(u), "keep").unwrap();
        }
    }
    // a temporary's marked directory that also holds something else is a user's
    let mixed = ".nav.txt.sinsmodel-partial-4194304-1";
    std::fs::create_dir(d.join(mixed)).unwrap();
    std::fs::write(d.join(mixed).join(".sinsmodel-partial"), PARTIAL_TEXT).unwrap();
    std::fs::write(d.join(mixed).join("notes.txt"), "keep").unwrap();
    let imu = o.join("imu.txt");
    let (ok, err) = navigate(imu.to_str().unwrap(), &d.join("nav.txt"), false);
    assert!(ok, "{err}");
    assert!(d.join(mixed).join("notes.txt").exists());
    let (ok, err) = simulate_into(d, &o);
    assert!(ok, "{err}");
    let left = names(d);
    for t in &theirs {
        assert!(!left.contains(&t.to_string()), "{t} left: {left:?}");
    }
    for u in &users {
        assert!(left.contains(&u.to_string()), "{u} removed: {left:?}");
    }
}

/// What the marker inside a file's temporary directory holds.
const PARTIAL_TEXT: &str = "sinsmodel temporary: removed when its file is written\n";

/// A run killed (SIGKILL: no handler runs) while writing `nav.txt` leaves its temporary, which
/// the next run into the same place sweeps; a user's plain file named exactly like a temporary
/// (`nav.txt.sinsmodel-partial-999999-1`) survives that run.
#[test]
fn a_killed_runs_temporary_is_swept_and_a_users_file_of_its_name_form_is_not() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let nav = d.join("nav.txt");
    let users = "nav.txt.sinsmodel-partial-999999-1";
    std::fs::write(d.join(users), "my notes").unwrap();
    // a file being written: a temporary directory that holds nav.txt
    let writing = |d: &Path| {
        names(d).into_iter().find(|n| {
            n.starts_with(".nav.txt.sinsmodel-partial-") && d.join(n).join("nav.txt").exists()
        })
    };
    let mut left = None;
    // (navigate is fast: a longer log until the kill lands while it writes)
    for hours in [2, 8, 32] {
        let imu = d.join("imu.txt");
        let rows: String = (1..=hours * 360_000)
            .map(|i| format!("{:.2} 0 0 0 0 0 -0.0979\n", i as f64 * 0.01))
            .collect();
        std::fs::write(&imu, rows).unwrap();
        let mut child = Command::new(env!("CARGO_BIN_EXE_sinsmodel"))
            .args(["navigate", "--imu", imu.to_str().unwrap()])
            .args(["--lat", "30", "--lon", "110", "--att", "0,0,0", "--out"])
            .arg(&nav)
            .stderr(std::process::Stdio::null())
            .spawn()
            .unwrap();
        // rows being written: the temporary's nav.txt has bytes (an empty one is the moment
        // before, or a run already removing it, where a kill leaves no nav.txt behind)
        let rows_going = |d: &Path| {
            writing(d).is_some_and(|n| {
                std::fs::metadata(d.join(n).join("nav.txt")).is_ok_and(|m| m.len() > 0)
            })
        };
        let t0 = std::time::Instant::now();
        while !rows_going(d) && child.try_wait().unwrap().is_none() {
            assert!(
                t0.elapsed().as_secs() < 60,
                "navigate neither wrote nor ended"
            );
        }
        child.kill().unwrap_or(()); // SIGKILL
        let status = child.wait().unwrap();
        if !status.success() {
            left = writing(d);
            if left.is_some() {
                break;
            }
        }
        let _ = std::fs::remove_file(&nav);
    }
    let left = left.expect("no run was killed while it wrote nav.txt");
    assert_eq!(
        std::fs::read_to_string(d.join(&left).join(".sinsmodel-partial")).unwrap(),
        PARTIAL_TEXT
    );
    assert!(!nav.exists(), "the killed run's output appeared");
    // the next run sweeps the killed run's temporary and leaves the user's file alone
    std::fs::write(
        d.join("imu.txt"),
        "0.01 0 0 0 0 0 -0.0979\n0.02 0 0 0 0 0 -0.0979\n",
    )
    .unwrap();
    let (ok, err) = navigate(d.join("imu.txt").to_str().unwrap(), &nav, false);
    assert!(ok, "{err}");
    let now = names(d);
    assert!(!now.contains(&left), "{left} not swept: {now:?}");
    assert_eq!(std::fs::read_to_string(d.join(users)).unwrap(), "my notes");
    assert!(nav.exists());
}

/// Single-file outputs: another run's listed result or a file not provably this command's
/// earlier output is refused (nothing changed); the command's own earlier output is replaced;
/// --overwrite replaces anything.
#[test]
fn single_file_outputs_replace_only_their_own_earlier_output() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let o = simulate(d);
    let imu = o.join("imu.txt");
    let imu = imu.to_str().unwrap();
    let truth_before = std::fs::read(o.join("truth.txt")).unwrap();
    let nav = |out: &Path, force: bool| navigate(imu, out, force);
    // onto a simulation's truth.txt (listed in its marker)
    let (ok, err) = nav(&o.join("truth.txt"), false);
    assert!(
        !ok && err.contains("is a result of the sinsmodel run in"),
        "{err}"
    );
    assert_eq!(std::fs::read(o.join("truth.txt")).unwrap(), truth_before);
    // onto a user's file; then its own earlier output; then --overwrite
    let mine = d.join("nav.txt");
    std::fs::write(&mine, "my trajectory\n").unwrap();
    let (ok, err) = nav(&mine, false);
    assert!(
        !ok && err.contains("not provably an earlier output"),
        "{err}"
    );
    assert_eq!(std::fs::read_to_string(&mine).unwrap(), "my trajectory\n");
    // --force runs past the data checks only: it replaces no file
    let out = mine.to_str().unwrap();
    let (ok, err) = run(&[
        "navigate", "--imu", imu, "--lat", "30", "--lon", "110", "--att", "0,0,0", "--out", out,
        "--force",
    ]);
    assert!(!ok && err.contains("give --overwrite"), "{err}");
    assert_eq!(std::fs::read_to_string(&mine).unwrap(), "my trajectory\n");
    // align's and imu-check's --force used to mean --overwrite: refused, naming it
    let j0 = d.join("user.json");
    std::fs::write(&j0, "{\"mine\": 0}").unwrap();
    for cmd in ["align", "imu-check"] {
        let (ok, err) = run(&[cmd, "--imu", imu, "--json", j0.to_str().unwrap(), "--force"]);
        assert!(!ok && err.contains("give --overwrite"), "{cmd}: {err}");
        assert_eq!(std::fs::read_to_string(&j0).unwrap(), "{\"mine\": 0}");
    }
    let (ok, err) = nav(&mine, true);
    assert!(ok, "{err}");
    let (ok, err) = nav(&mine, false);
    assert!(ok, "its own earlier output: {err}");
    // JSON outputs: a user's JSON, another command's JSON, an empty file, its own
    let j = d.join("check.json");
    std::fs::write(&j, "{\"mine\": 1}").unwrap();
    for (cmd, extra) in [
        ("imu-check", &[][..]),
        ("align", &["--lat", "30"][..]),
        ("allan", &[][..]),
    ] {
        let mut a = vec![cmd, "--imu", imu, "--json", j.to_str().unwrap()];
        a.extend_from_slice(extra);
        let (ok, err) = run(&a);
        assert!(
            !ok && err.contains("not provably an earlier output"),
            "{cmd}: {err}"
        );
        assert_eq!(std::fs::read_to_string(&j).unwrap(), "{\"mine\": 1}");
    }
    let ic = d.join("ic.json");
    std::fs::write(&ic, "").unwrap();
    let (ok, err) = run(&["imu-check", "--imu", imu, "--json", ic.to_str().unwrap()]);
    assert!(ok, "an empty file holds nothing to lose: {err}");
    let (ok, err) = run(&["imu-check", "--imu", imu, "--json", ic.to_str().unwrap()]);
    assert!(ok, "its own earlier output: {err}");
    let (ok, err) = run(&[
        "align",
        "--imu",
        imu,
        "--lat",
        "30",
        "--json",
        ic.to_str().unwrap(),
    ]);
    assert!(
        !ok && err.contains("\"sinsmodel imu-check\", not \"sinsmodel align\""),
        "{err}"
    );
    // plots: a user's PNG is refused, allan's own replaced
    let prefix = d.join("a");
    let a_json = d.join("a.json");
    let allan = |force: bool| {
        let mut a = vec![
            "allan",
            "--imu",
            imu,
            "--json",
            a_json.to_str().unwrap(),
            "--plot",
            prefix.to_str().unwrap(),
        ];
        if force {
            a.push("--overwrite");
        }
        run(&a)
    };
    let (ok, err) = allan(false);
    assert!(ok, "{err}");
    let (ok, err) = allan(false);
    assert!(ok, "its own plots: {err}");
    std::fs::write(d.join("a_gyro.png"), b"\x89PNG\r\n\x1a\nmine").unwrap();
    let (ok, err) = allan(false);
    assert!(!ok && err.contains("not a PNG marked"), "{err}");
    let (ok, err) = allan(true);
    assert!(ok, "{err}");
}

/// SIGINT or SIGTERM during a run removes its staging directory at once (not at the next run),
/// exits 128 + signal, and leaves the earlier run's directory whole.
#[test]
fn an_interrupted_run_leaves_no_staging_and_the_earlier_result_whole() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let o = simulate(d);
    let before = names(&o);
    let ex = d.join("ex");
    for (sig, code) in [(libc_sig::SIGINT, 130), (libc_sig::SIGTERM, 143)] {
        // the embedded demo into the simulation's directory would be refused; into its own
        let child = Command::new(env!("CARGO_BIN_EXE_sinsmodel"))
            .args(["explain", "--out", ex.to_str().unwrap()])
            .stderr(std::process::Stdio::piped())
            .stdout(std::process::Stdio::null())
            .spawn()
            .unwrap();
        // wait for the staging directory to appear
        wait_for_staging(d, "ex");
        Command::new("kill")
            .args([format!("-{sig}"), child.id().to_string()])
            .status()
            .unwrap();
        let out = child.wait_with_output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(code), "{err}");
        assert!(err.contains("unfinished output"), "{err}");
        let left: Vec<String> = names(d)
            .into_iter()
            .filter(|n| n.contains("sinsmodel-"))
            .collect();
        assert!(left.is_empty(), "left behind: {left:?}");
        assert!(!ex.exists());
    }
    assert_eq!(names(&o), before);
}

/// Signal numbers (Linux and the BSDs agree on these two).
mod libc_sig {
    pub const SIGINT: i32 = 2;
    pub const SIGTERM: i32 = 15;
}

/// `sinsmodel ARGS` under a file-size limit of 20 blocks (`ulimit -f`): it must fail with exit
/// code 2 and an error naming `file` as too large (no SIGXFSZ death, no message-less exit), and
/// leave nothing in `d` whose name `leftover` picks.
fn fails_past_a_file_size_limit(d: &Path, args: &str, file: &str, leftover: fn(&str) -> bool) {
    let script = format!(
        "ulimit -f 20; exec '{}' {args}",
        env!("CARGO_BIN_EXE_sinsmodel")
    );
    let out = Command::new("sh").args(["-c", &script]).output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("cannot write") && err.contains(file) && err.contains("too large"),
        "{err}"
    );
    let left: Vec<String> = names(d).into_iter().filter(|n| leftover(n)).collect();
    assert!(left.is_empty(), "{left:?}");
}

/// Past a file-size limit a write fails with an error naming the file and no temporary is left.
#[test]
fn a_file_size_limit_is_an_error_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let o = simulate(d);
    let args = format!(
        "navigate --imu '{}' --lat 30 --lon 110 --att 0,0,0 --out-rate 100 --out '{}'",
        o.join("imu.txt").display(),
        d.join("big.txt").display()
    );
    fails_past_a_file_size_limit(d, &args, "big.txt", |n| n.contains("big"));
}

/// The same for filter's nav.txt, which a thread of its own formats and writes straight to the
/// file: the error names nav.txt, and no run directory or temporary is left.
#[test]
fn a_file_size_limit_on_filter_nav_txt_is_an_error_naming_it() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let o = simulate(d);
    let args = format!(
        "filter --model P13 --imu '{}' --aid '{}' --init 30,110,0,0,0,0 --out '{}'",
        o.join("imu.txt").display(),
        o.join("gnss.txt").display(),
        d.join("f").display()
    );
    fails_past_a_file_size_limit(d, &args, "nav.txt", |n| n == "f" || n.contains(".f."));
}

/// A run killed between its two renames leaves the earlier result only in its set-aside
/// directory: the next run into the same place restores it (even one that then fails) instead
/// of sweeping it away; a set-aside directory holding anything unlisted is never swept.
#[test]
fn a_set_aside_earlier_run_is_restored_not_swept() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let o = simulate(d);
    let before = names(&o);
    // the state a SIGKILL between the renames leaves: no target, the earlier run aside
    let aside = d.join(".o.sinsmodel-old-4194304");
    std::fs::rename(&o, &aside).unwrap();
    // a run that fails on its input still restores the earlier result first
    let bad = d.join("bad.txt");
    std::fs::write(&bad, "garbage\n").unwrap();
    let (ok, _) = run(&[
        "filter",
        "--imu",
        bad.to_str().unwrap(),
        "--aid",
        o.join("gnss.txt").to_str().unwrap(),
        "--init",
        "30,110,0,0,0,0",
        "--out",
        o.to_str().unwrap(),
    ]);
    assert!(!ok);
    let (ok, err) = simulate_into(d, &o);
    assert!(ok, "{err}");
    assert_eq!(names(&o), before);
    assert!(!aside.exists());
    // a set-aside directory with a file its marker does not list is the user's now: kept
    std::fs::create_dir(&aside).unwrap();
    std::fs::copy(o.join(".sinsmodel-run"), aside.join(".sinsmodel-run")).unwrap();
    std::fs::write(aside.join("notes.txt"), "mine").unwrap();
    let (ok, err) = simulate_into(d, &o);
    assert!(ok, "{err}");
    assert_eq!(
        std::fs::read_to_string(aside.join("notes.txt")).unwrap(),
        "mine"
    );
}

/// A directory is replaced only by the command that wrote it, never through a symbolic link,
/// and not when a file appeared in it while the run worked.
#[test]
fn a_run_directory_is_replaced_only_by_its_own_command_and_as_it_was() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let o = simulate(d);
    let (ok, err) = run(&[
        "explain",
        "--demo-seconds",
        "60",
        "--out",
        o.to_str().unwrap(),
    ]);
    assert!(
        !ok && err.contains("holds the result of `sinsmodel simulate`, not of `explain`"),
        "{err}"
    );
    assert!(o.join("imu.txt").exists());
    let link = d.join("link");
    std::os::unix::fs::symlink(&o, &link).unwrap();
    let (ok, err) = simulate_into(d, &link);
    assert!(!ok && err.contains("is a symbolic link"), "{err}");
    // a file added during the run: the new result is not moved in, the file stays
    let ex = d.join("ex");
    let demo = |out: &Path| {
        Command::new(env!("CARGO_BIN_EXE_sinsmodel"))
            .args([
                "explain",
                "--demo-seconds",
                "60",
                "--out",
                out.to_str().unwrap(),
            ])
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap()
    };
    let out = demo(&ex).wait_with_output().unwrap();
    assert!(out.status.success());
    let child = demo(&ex);
    wait_for_staging(d, "ex");
    std::fs::write(ex.join("my_notes.txt"), "notes").unwrap();
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && err.contains("changed while the run worked"),
        "{err}"
    );
    assert_eq!(
        std::fs::read_to_string(ex.join("my_notes.txt")).unwrap(),
        "notes"
    );
    assert!(!names(d).iter().any(|n| n.contains("sinsmodel-")));
}

/// What a reader opens beside the IMU file (a GNSS_IMU csv's `.tag`) is an input: no output
/// replaces it, not even with --overwrite.
#[test]
fn the_clock_file_beside_a_csv_is_an_input() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data/gnss-imu-drive");
    if !src.join("imu_1934.csv").exists() {
        eprintln!("skipped: ../shared/data/gnss-imu-drive is missing");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    for f in ["imu_1934.csv", "imu_1934.csv.tag"] {
        std::fs::copy(src.join(f), d.join(f)).unwrap();
        let mut p = std::fs::metadata(d.join(f)).unwrap().permissions();
        #[allow(clippy::permissions_set_readonly_false)]
        p.set_readonly(false);
        std::fs::set_permissions(d.join(f), p).unwrap();
    }
    let tag = d.join("imu_1934.csv.tag");
    let before = std::fs::read(&tag).unwrap();
    let (ok, err) = run(&[
        "imu-check",
        "--imu",
        d.join("imu_1934.csv").to_str().unwrap(),
        "--json",
        tag.to_str().unwrap(),
        "--overwrite",
    ]);
    assert!(!ok && err.contains("is an input of this run"), "{err}");
    assert_eq!(std::fs::read(&tag).unwrap(), before);
}

/// A file of a run directory edited since the run wrote it (another size or modification time
/// than its marker records) is not replaced.
#[test]
fn a_hand_edited_result_is_not_replaced() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let o = simulate(d);
    let marker = std::fs::read_to_string(o.join(".sinsmodel-run")).unwrap();
    assert!(
        marker.lines().nth(1).unwrap().split('\t').count() == 3,
        "{marker}"
    );
    let mut text = std::fs::read_to_string(o.join("scenario.toml")).unwrap();
    text.push_str("# my note\n");
    std::fs::write(o.join("scenario.toml"), &text).unwrap();
    let (ok, err) = simulate_into(d, &o);
    assert!(
        !ok && err.contains("scenario.toml changed since the earlier sinsmodel run"),
        "{err}"
    );
    assert_eq!(
        std::fs::read_to_string(o.join("scenario.toml")).unwrap(),
        text
    );
}
