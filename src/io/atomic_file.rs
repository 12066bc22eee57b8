//! Writing output files so that a reader never sees a half-finished file: write to a temporary
//! file beside the target, flush, then rename over it.

use anyhow::{Context, Result};
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard};

/// Tag in the name of every temporary this crate makes (`.NAME.sinsmodel-partial-PID-N`,
/// `.NAME.sinsmodel-staging-PID`, `.NAME.sinsmodel-old-PID`): the sweep of killed runs'
/// leftovers takes only names of exactly these forms, never a user's `nav.txt.old-2024`.
const TEMP_TAG: &str = "sinsmodel";

/// File inside every temporary's directory (`.NAME.sinsmodel-partial-PID-N/`, which holds it and
/// the file being written, `NAME`), written before the file: a killed run's temporary is swept
/// only when its directory holds this file with [`PARTIAL_TEXT`] and nothing but the file, so a
/// user's file or directory that merely has such a name is never taken.
const PARTIAL_MARKER: &str = ".sinsmodel-partial";
/// What [`PARTIAL_MARKER`] holds.
const PARTIAL_TEXT: &str = "sinsmodel temporary: removed when its file is written\n";

/// File inside every staging directory, written when it is created: a directory is swept as a
/// killed run's staging only when it holds this file with [`STAGING_TEXT`].
const STAGING_MARKER: &str = ".sinsmodel-staging";
/// What [`STAGING_MARKER`] holds.
const STAGING_TEXT: &str = "sinsmodel staging directory: removed when its run ends\n";

/// First line of every [`RUN_MARKER`]; the run's files follow, one per line.
const RUN_MARKER_HEADER: &str = "written by sinsmodel; its files:";

/// Temporaries and staging directories of this process not yet committed: what a SIGINT or
/// SIGTERM removes ([`remove_unfinished`]).
static UNFINISHED: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

fn unfinished() -> MutexGuard<'static, Vec<PathBuf>> {
    UNFINISHED.lock().unwrap_or_else(|e| e.into_inner())
}

fn register(p: &Path) {
    unfinished().push(p.to_path_buf());
}

fn unregister(list: &mut Vec<PathBuf>, p: &Path) {
    list.retain(|q| q != p);
}

/// Removes every unfinished output of this process (temporaries and staging directories) and
/// returns how many, with the registry still locked: while the guard lives no output can be
/// committed, so a caller that ends the process on a signal leaves either the earlier result
/// or the complete new one, and no hidden leftover.
pub fn remove_unfinished() -> (usize, MutexGuard<'static, Vec<PathBuf>>) {
    let mut list = unfinished();
    let mut n = 0;
    for p in list.drain(..) {
        if std::fs::remove_dir_all(&p)
            .or_else(|_| std::fs::remove_file(&p))
            .is_ok()
        {
            n += 1;
        }
    }
    (n, list)
}

/// A unique temporary for `target`: the path `NAME` (plus `ext` unless it already ends so)
/// inside a new directory `.NAME.sinsmodel-partial-PID-N` beside it (unique per process and
/// file, so concurrent runs never share one) that holds the [`PARTIAL_MARKER`]; the directory
/// is registered for removal on a signal, and [`forget_temporary`] removes it. The file itself
/// is not created.
pub fn temporary_beside(target: &Path, ext: &str) -> Result<PathBuf> {
    static SERIAL: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let k = SERIAL.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let (parent, name) = parent_and_name(target);
    let dir = parent.join(format!(
        ".{name}.{TEMP_TAG}-partial-{}-{k}",
        std::process::id()
    ));
    // registered first: a signal at any moment from here removes it
    register(&dir);
    // (the marker written directly: an atomic write would need a temporary of its own)
    let made = std::fs::create_dir(&dir)
        .and_then(|_| std::fs::write(dir.join(PARTIAL_MARKER), PARTIAL_TEXT));
    if let Err(e) = made {
        let _ = std::fs::remove_dir_all(&dir);
        unregister(&mut unfinished(), &dir);
        anyhow::bail!(
            "cannot create the temporary {} for {}: {e}",
            dir.display(),
            target.display()
        );
    }
    let file = if name.ends_with(ext) {
        name
    } else {
        format!("{name}{ext}")
    };
    Ok(dir.join(file))
}

/// The directory of a temporary made by this process's [`temporary_beside`], if `tmp` is one.
fn temporary_dir(tmp: &Path) -> Option<&Path> {
    let dir = tmp.parent()?;
    let own = format!(".{TEMP_TAG}-partial-{}-", std::process::id());
    let n = dir.file_name()?.to_string_lossy();
    (n.starts_with('.') && n.contains(&own)).then_some(dir)
}

/// Removes the temporary `tmp` (if still there), its marker and its directory, with the
/// registry `list` held.
fn discard_temporary(list: &mut Vec<PathBuf>, tmp: &Path) {
    let Some(dir) = temporary_dir(tmp) else {
        return;
    };
    let _ = std::fs::remove_file(tmp);
    let _ = std::fs::remove_file(dir.join(PARTIAL_MARKER));
    // (never recursive: anything else inside stays, with the directory)
    let _ = std::fs::remove_dir(dir);
    unregister(list, dir);
}

/// Ends a temporary made by [`temporary_beside`] (after it was moved into place, or to drop
/// it): removes the file if it is still there, its marker and its directory.
pub fn forget_temporary(tmp: &Path) {
    discard_temporary(&mut unfinished(), tmp);
}

/// A file being written; it appears at its final path only on [`AtomicFile::commit`].
pub struct AtomicFile {
    tmp: PathBuf,
    target: PathBuf,
    out: Option<NamedWriter>,
}

/// A buffered file writer whose errors name the file they happened in (a full disk while
/// writing says which output it was).
pub struct NamedWriter {
    inner: BufWriter<std::fs::File>,
    target: PathBuf,
}

impl NamedWriter {
    /// The file behind the buffer, for a writer that bypasses it (flush the buffer first) or
    /// hints to the operating system such as starting the write-back.
    pub fn file(&self) -> &std::fs::File {
        self.inner.get_ref()
    }

    fn named(&self, e: std::io::Error) -> std::io::Error {
        std::io::Error::new(
            e.kind(),
            format!("cannot write {}: {e}", self.target.display()),
        )
    }
}

impl Write for NamedWriter {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.inner.write(buf).map_err(|e| self.named(e))
    }
    fn write_all(&mut self, buf: &[u8]) -> std::io::Result<()> {
        self.inner.write_all(buf).map_err(|e| self.named(e))
    }
    fn flush(&mut self) -> std::io::Result<()> {
        self.inner.flush().map_err(|e| self.named(e))
    }
}

impl AtomicFile {
    /// Starts writing `target` (through `target.sinsmodel-partial-PID-N`, unique per process
    /// and file), creating its directory.
    pub fn create(target: &Path) -> Result<AtomicFile> {
        if let Ok(m) = std::fs::symlink_metadata(target) {
            if !m.is_file() && !std::fs::metadata(target).is_ok_and(|m| m.is_file()) {
                anyhow::bail!(
                    "{}: exists and is not a regular file (a directory, device or pipe); choose another output path",
                    target.display()
                );
            }
        }
        if let Some(parent) = target.parent().filter(|p| !p.as_os_str().is_empty()) {
            std::fs::create_dir_all(parent)
                .with_context(|| format!("cannot create {}", parent.display()))?;
        }
        if let (Some(dir), Some(name)) = (target.parent(), target.file_name()) {
            let dir = if dir.as_os_str().is_empty() {
                Path::new(".")
            } else {
                dir
            };
            remove_stale(dir, &name.to_string_lossy());
        }
        let tmp = temporary_beside(target, "")?;
        let f = std::fs::File::create(&tmp).with_context(|| {
            forget_temporary(&tmp);
            format!("cannot create {}", tmp.display())
        })?;
        Ok(AtomicFile {
            tmp,
            target: target.to_path_buf(),
            out: Some(NamedWriter {
                inner: BufWriter::with_capacity(1 << 20, f),
                target: target.to_path_buf(),
            }),
        })
    }

    /// The writer.
    pub fn writer(&mut self) -> &mut NamedWriter {
        self.out.as_mut().expect("not committed")
    }

    /// Flushes and renames into place.
    pub fn commit(mut self) -> Result<()> {
        let mut w = self.out.take().expect("not committed");
        if let Err(e) = w.inner.flush().and_then(|_| w.inner.get_ref().sync_all()) {
            drop(w);
            forget_temporary(&self.tmp);
            anyhow::bail!(
                "cannot write {} (for {}): {e}",
                self.tmp.display(),
                self.target.display()
            );
        }
        drop(w);
        // (under the registry's lock: a signal arriving now waits for the rename)
        let mut list = unfinished();
        let moved = std::fs::rename(&self.tmp, &self.target);
        discard_temporary(&mut list, &self.tmp);
        moved.map_err(|e| {
            anyhow::anyhow!(
                "cannot move {} to {}: {e}",
                self.tmp.display(),
                self.target.display()
            )
        })
    }
}

impl Drop for AtomicFile {
    fn drop(&mut self) {
        if self.out.is_some() {
            forget_temporary(&self.tmp);
        }
    }
}

/// Writes a whole text file atomically.
pub fn write_text(target: &Path, text: &str) -> Result<()> {
    let mut f = AtomicFile::create(target)?;
    f.writer().write_all(text.as_bytes())?;
    f.commit()
}

/// Name of the marker file in every directory an [`OutputDir`] writes.
pub const RUN_MARKER: &str = ".sinsmodel-run";

/// An output directory that holds one run's outputs, complete or none: files are written into
/// a staging directory beside the target, which replaces the target only on
/// [`OutputDir::commit`]. A target that exists is replaced only when a sinsmodel run wrote it
/// (it holds [`RUN_MARKER`]) or it is empty; anything else is refused, so no input is lost.
pub struct OutputDir {
    staging: PathBuf,
    target: PathBuf,
    command: String,
    committed: bool,
}

impl OutputDir {
    /// Checks `target` can be replaced by a run of `command` (`simulate`, `explain`, …) and that
    /// no `inputs` lie inside it, then creates the staging directory. An earlier run that a
    /// killed replacement left set aside (and no target) is restored first.
    pub fn create(target: &Path, inputs: &[&Path], command: &str) -> Result<OutputDir> {
        refuse_mat_variable_name("--out", target)?;
        if std::fs::symlink_metadata(target).is_ok_and(|m| m.file_type().is_symlink()) {
            anyhow::bail!(
                "--out {}: is a symbolic link; give the directory it points to (a run replaces the directory itself, not what a link points at)",
                target.display()
            );
        }
        let (parent, name) = parent_and_name(target);
        if !target.exists() {
            restore_set_aside(&parent, &name, target);
        }
        if target.exists() {
            check_replaceable(target, command)?;
            let canon = target.canonicalize()?;
            for inp in inputs {
                if let Ok(c) = inp.canonicalize() {
                    if c.starts_with(&canon) {
                        anyhow::bail!(
                            "--out {}: the input {} is inside it; choose another output directory",
                            target.display(),
                            inp.display()
                        );
                    }
                }
            }
        }
        std::fs::create_dir_all(&parent).with_context(|| {
            let why = if parent.ancestors().any(Path::is_file) {
                " (a file stands where a directory of that path would be)"
            } else {
                ""
            };
            format!(
                "--out {}: cannot create its directory {}{why}",
                target.display(),
                parent.display()
            )
        })?;
        remove_stale(&parent, &name);
        let staging = sibling(target, "staging");
        if std::fs::symlink_metadata(&staging).is_ok() {
            anyhow::bail!(
                "--out {}: {} exists (this process's staging name); remove it",
                target.display(),
                staging.display()
            );
        }
        // registered first: a signal at any moment from here removes it
        register(&staging);
        // (the staging directory is the run's own; the user gave --out)
        let made = std::fs::create_dir(&staging)
            .with_context(|| {
                format!(
                    "--out {}: cannot write in {} (a run writes a directory beside its output there first, then renames it)",
                    target.display(),
                    parent.display()
                )
            })
            .and_then(|_| write_text(&staging.join(STAGING_MARKER), STAGING_TEXT));
        if let Err(e) = made {
            let _ = std::fs::remove_dir_all(&staging);
            unregister(&mut unfinished(), &staging);
            return Err(e);
        }
        Ok(OutputDir {
            staging,
            target: target.to_path_buf(),
            command: command.to_string(),
            committed: false,
        })
    }

    /// Path of a file `name` inside the staging directory.
    pub fn file(&self, name: &str) -> PathBuf {
        self.staging.join(name)
    }

    /// Marks the run complete and moves it into place (replacing the previous run, if any).
    pub fn commit(mut self) -> Result<()> {
        let mut names: Vec<String> = std::fs::read_dir(&self.staging)
            .with_context(|| format!("cannot read {}", self.staging.display()))?
            .filter_map(|e| e.ok())
            .map(|e| e.file_name().to_string_lossy().into_owned())
            .collect();
        names.retain(|n| n != STAGING_MARKER);
        names.sort();
        // each file with its size and modification time: a file edited since is not the run's
        let lines: Vec<String> = names
            .iter()
            .map(|n| match stamp(&self.staging.join(n)) {
                Some((len, ns)) => format!("{n}\t{len}\t{ns}"),
                None => n.clone(),
            })
            .collect();
        write_text(
            &self.staging.join(RUN_MARKER),
            &format!("{}\n{}\n", marker_header(&self.command), lines.join("\n")),
        )?;
        // (a kill between the two leaves a staging directory the sweep still recognises)
        std::fs::remove_file(self.staging.join(STAGING_MARKER))
            .with_context(|| format!("cannot finish {}", self.staging.display()))?;
        // two renames, each atomic: the earlier run moves aside whole, the new one moves in
        // whole; a kill between them leaves no target (never a mixed or half-deleted one), and
        // the hidden leftovers are removed by the next run. Under the registry's lock: a
        // SIGINT or SIGTERM waits for both.
        let mut list = unfinished();
        // what the start checked may have changed while the run worked (a file added, the
        // directory replaced): checked again, and nothing moves in if it is not replaceable
        if self.target.exists() {
            check_replaceable(&self.target, &self.command).context(
                "the output directory changed while the run worked; the new result is not moved in",
            )?;
        }
        let old = sibling(&self.target, "old");
        if self.target.exists() {
            std::fs::rename(&self.target, &old)
                .with_context(|| format!("cannot replace {}", self.target.display()))?;
        }
        std::fs::rename(&self.staging, &self.target).with_context(|| {
            format!(
                "cannot move {} to {}",
                self.staging.display(),
                self.target.display()
            )
        })?;
        self.committed = true;
        unregister(&mut list, &self.staging);
        // (still under the lock: a signal waits, so no half-deleted set-aside run is left)
        let _ = std::fs::remove_dir_all(&old);
        drop(list);
        Ok(())
    }
}

impl Drop for OutputDir {
    fn drop(&mut self) {
        if !self.committed {
            let _ = std::fs::remove_dir_all(&self.staging);
            unregister(&mut unfinished(), &self.staging);
        }
    }
}

/// The first line of a run's marker: `written by sinsmodel COMMAND; its files:`.
fn marker_header(command: &str) -> String {
    format!("written by sinsmodel {command}; its files:")
}

/// Refuses to replace the existing directory `target` unless it provably holds only a
/// sinsmodel run's files: a valid marker listing them, of `command` (or of a release that did
/// not record the command), and nothing else beside them.
fn check_replaceable(target: &Path, command: &str) -> Result<()> {
    if !target.is_dir() {
        anyhow::bail!("--out {}: exists and is not a directory", target.display());
    }
    let mut present: Vec<String> = std::fs::read_dir(target)
        .with_context(|| format!("cannot read {}", target.display()))?
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    present.sort();
    if present.is_empty() {
        return Ok(());
    }
    let shown = |names: &[String]| {
        let mut s = names
            .iter()
            .take(20)
            .cloned()
            .collect::<Vec<_>>()
            .join(", ");
        if names.len() > 20 {
            s.push_str(&format!(" and {} more", names.len() - 20));
        }
        s
    };
    if !present.iter().any(|n| n == RUN_MARKER) {
        anyhow::bail!(
            "--out {}: the directory exists and was not written by sinsmodel (it holds {}); choose another (nothing is overwritten)",
            target.display(),
            shown(&present)
        );
    }
    // the marker must list the run's files: an empty, unreadable or foreign marker (or one of
    // an older release, which listed none) proves nothing
    let listed = run_listing(target).map_err(|why| {
        anyhow::anyhow!(
            "--out {}: cannot prove the directory holds only an earlier sinsmodel run's files ({why}); it holds {}. Nothing is overwritten: move what you want to keep and remove the directory, or choose another --out",
            target.display(),
            shown(&present)
        )
    })?;
    if let Some(other) = run_command(target).filter(|c| c != command) {
        anyhow::bail!(
            "--out {}: holds the result of `sinsmodel {other}`, not of `{command}`; choose another --out (nothing is overwritten)",
            target.display()
        );
    }
    // anything not listed, or listed but no longer a plain file, was put there since, and
    // replacing the directory would lose it
    let foreign: Vec<String> = present
        .iter()
        .filter(|n| *n != RUN_MARKER)
        .filter(|n| {
            !listed.contains(n)
                || !std::fs::symlink_metadata(target.join(n)).is_ok_and(|m| m.is_file())
        })
        .cloned()
        .collect();
    if !foreign.is_empty() {
        anyhow::bail!(
            "--out {}: holds files the earlier sinsmodel run did not write ({}); move them or choose another --out (nothing is overwritten)",
            target.display(),
            shown(&foreign)
        );
    }
    let edited = edited_since(target);
    if !edited.is_empty() {
        anyhow::bail!(
            "--out {}: {} changed since the earlier sinsmodel run wrote {} (size or modification time); copy what you want to keep elsewhere or choose another --out (nothing is overwritten)",
            target.display(),
            shown(&edited),
            if edited.len() == 1 { "it" } else { "them" }
        );
    }
    Ok(())
}

/// The command a run directory's marker names (`None` for a release that did not record it,
/// or no valid marker).
fn run_command(dir: &Path) -> Option<String> {
    let text = std::fs::read_to_string(dir.join(RUN_MARKER)).ok()?;
    let first = text.lines().next()?;
    let cmd = first
        .strip_prefix("written by sinsmodel ")?
        .strip_suffix("; its files:")?;
    Some(cmd.to_string())
}

/// A file's size [bytes] and modification time [ns since the epoch], as the marker records them.
fn stamp(p: &Path) -> Option<(u64, u128)> {
    let m = std::fs::symlink_metadata(p).ok()?;
    let t = m
        .modified()
        .ok()?
        .duration_since(std::time::UNIX_EPOCH)
        .ok()?;
    Some((m.len(), t.as_nanos()))
}

/// The files of run directory `dir` whose size or modification time differ from what its
/// marker recorded (edited since the run wrote them).
fn edited_since(dir: &Path) -> Vec<String> {
    let text = std::fs::read_to_string(dir.join(RUN_MARKER)).unwrap_or_default();
    text.lines()
        .skip(1)
        .filter_map(|l| {
            let mut f = l.split('\t');
            let (name, len, ns) = (f.next()?, f.next()?, f.next()?);
            let recorded = (len.parse::<u64>().ok()?, ns.parse::<u128>().ok()?);
            (stamp(&dir.join(name)) != Some(recorded)).then(|| name.to_string())
        })
        .collect()
}

/// True when `dir` holds a valid run marker and nothing but the files it lists.
fn fully_listed(dir: &Path) -> bool {
    let Ok(listed) = run_listing(dir) else {
        return false;
    };
    std::fs::read_dir(dir).is_ok_and(|entries| {
        entries.filter_map(|e| e.ok()).all(|e| {
            let n = e.file_name().to_string_lossy().into_owned();
            n == RUN_MARKER || (listed.contains(&n) && e.file_type().is_ok_and(|t| t.is_file()))
        })
    })
}

/// With no `target`, moves back the earlier run a killed replacement left set aside
/// (`.NAME.sinsmodel-old-PID` of a process that is gone, holding only its listed files).
fn restore_set_aside(parent: &Path, name: &str, target: &Path) {
    let Ok(entries) = std::fs::read_dir(parent) else {
        return;
    };
    let mut found: Vec<(std::time::SystemTime, PathBuf)> = entries
        .filter_map(|e| e.ok())
        .filter_map(|e| {
            let entry = e.file_name().to_string_lossy().into_owned();
            match leftover_kind(&entry, name) {
                Some(("old", pid)) if pid != std::process::id() && !pid_alive(pid) => {
                    let p = e.path();
                    let t = e.metadata().and_then(|m| m.modified()).ok()?;
                    (fully_listed(&p) && !e.file_type().ok()?.is_symlink()).then_some((t, p))
                }
                _ => None,
            }
        })
        .collect();
    found.sort();
    if let Some((_, p)) = found.pop() {
        if std::fs::rename(&p, target).is_ok() {
            eprintln!(
                "note: restored {} from {} (a run was killed while replacing it)",
                target.display(),
                p.display()
            );
        }
    }
}

/// The files a run directory's [`RUN_MARKER`] lists, or why it proves nothing: missing, not a
/// plain file, unreadable, not sinsmodel's header, or listing no file.
pub fn run_listing(dir: &Path) -> std::result::Result<Vec<String>, String> {
    let marker = dir.join(RUN_MARKER);
    let meta = std::fs::symlink_metadata(&marker).map_err(|_| format!("it has no {RUN_MARKER}"))?;
    if !meta.is_file() {
        return Err(format!("its {RUN_MARKER} is not a plain file"));
    }
    if meta.len() > 1 << 20 {
        return Err(format!(
            "its {RUN_MARKER} is larger than any sinsmodel writes"
        ));
    }
    let text = std::fs::read_to_string(&marker)
        .map_err(|e| format!("its {RUN_MARKER} cannot be read as text: {e}"))?;
    let mut lines = text.lines();
    let first = lines.next().unwrap_or("");
    let ours = first == RUN_MARKER_HEADER
        || first
            .strip_prefix("written by sinsmodel ")
            .and_then(|r| r.strip_suffix("; its files:"))
            .is_some_and(|c| {
                !c.is_empty() && c.bytes().all(|b| b.is_ascii_lowercase() || b == b'-')
            });
    if !ours {
        return Err(format!(
            "its {RUN_MARKER} does not start with sinsmodel's line \"{RUN_MARKER_HEADER}\""
        ));
    }
    let listed: Vec<String> = lines
        .filter(|l| !l.is_empty())
        .map(|l| l.split('\t').next().unwrap_or(l).to_string())
        .collect();
    if listed.is_empty() {
        return Err(format!(
            "its {RUN_MARKER} lists no files, as an older release wrote it"
        ));
    }
    Ok(listed)
}

/// `.NAME.sinsmodel-KIND-PID` beside `target`: this process's hidden staging or set-aside
/// directory.
fn sibling(target: &Path, kind: &str) -> PathBuf {
    let (parent, name) = parent_and_name(target);
    parent.join(format!(".{name}.{TEMP_TAG}-{kind}-{}", std::process::id()))
}

/// The directory `target` is in (`.` for a bare name) and its name.
fn parent_and_name(target: &Path) -> (PathBuf, String) {
    let parent = match target.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let name = target
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "out".into());
    (parent, name)
}

/// True unless the process `pid` is known to be gone (Linux: no /proc/PID).
fn pid_alive(pid: u32) -> bool {
    if !Path::new("/proc/self").exists() {
        return true;
    }
    Path::new(&format!("/proc/{pid}")).exists()
}

/// What a leftover name beside output `name` is, if it is exactly one of this crate's
/// temporaries: (kind, pid).
fn leftover_kind(entry: &str, name: &str) -> Option<(&'static str, u32)> {
    let digits = |s: &str| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit());
    let rest = entry
        .strip_prefix('.')?
        .strip_prefix(name)?
        .strip_prefix(&format!(".{TEMP_TAG}-"))?;
    // .NAME.sinsmodel-partial-PID-N (a file's temporary directory)
    if let Some((pid, k)) = rest
        .strip_prefix("partial-")
        .and_then(|r| r.split_once('-'))
    {
        if !(digits(pid) && digits(k)) {
            return None;
        }
        return pid.parse().ok().map(|p| ("partial", p));
    }
    // .NAME.sinsmodel-staging-PID or .NAME.sinsmodel-old-PID
    for kind in ["staging", "old"] {
        if let Some(pid) = rest.strip_prefix(kind).and_then(|r| r.strip_prefix('-')) {
            if digits(pid) {
                return pid.parse().ok().map(|p| (kind, p));
            }
        }
    }
    None
}

/// Removes leftovers of killed runs beside output `name` in `dir`: only entries whose name is
/// exactly one of this crate's temporaries, whose process is gone, and whose content proves it
/// (for a file's temporary a directory holding only its [`PARTIAL_MARKER`] and the file; a
/// directory holding the staging marker, or an earlier run's valid [`RUN_MARKER`], for a
/// staging or set-aside directory). Anything else is left.
fn remove_stale(dir: &Path, name: &str) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for e in entries.filter_map(|e| e.ok()) {
        let entry = e.file_name().to_string_lossy().into_owned();
        let Some((kind, pid)) = leftover_kind(&entry, name) else {
            continue;
        };
        if pid == std::process::id() || pid_alive(pid) {
            continue;
        }
        let p = e.path();
        let Ok(meta) = std::fs::symlink_metadata(&p) else {
            continue;
        };
        let ours = match kind {
            "partial" => meta.is_dir() && only_a_temporary(&p, name),
            "staging" => {
                meta.is_dir()
                    && (std::fs::read_to_string(p.join(STAGING_MARKER))
                        .is_ok_and(|t| t == STAGING_TEXT)
                        || run_listing(&p).is_ok())
            }
            _ => meta.is_dir() && fully_listed(&p),
        };
        if ours {
            let _ = if meta.is_dir() {
                std::fs::remove_dir_all(&p)
            } else {
                std::fs::remove_file(&p)
            };
        }
    }
}

/// True when `dir` holds the [`PARTIAL_MARKER`] with [`PARTIAL_TEXT`] and at most the file being
/// written for output `name` (`NAME`, or `NAME.png` for a plot): what a killed run's temporary
/// holds, and nothing a user put there.
fn only_a_temporary(dir: &Path, name: &str) -> bool {
    let marked = std::fs::read_to_string(dir.join(PARTIAL_MARKER)).is_ok_and(|t| t == PARTIAL_TEXT);
    let Ok(entries) = std::fs::read_dir(dir) else {
        return false;
    };
    let png = format!("{name}.png");
    marked
        && entries.filter_map(|e| e.ok()).all(|e| {
            let n = e.file_name().to_string_lossy().into_owned();
            n == PARTIAL_MARKER
                || ((n == name || n == png) && e.file_type().is_ok_and(|t| t.is_file()))
        })
}

/// Refuses an output named like `FILE.mat:VARIABLE`: inputs of that form select a variable of a
/// MATLAB file, and a file of that literal name would be read instead of it.
fn refuse_mat_variable_name(option: &str, path: &Path) -> Result<()> {
    let s = path.to_string_lossy().to_ascii_lowercase();
    if s.contains(".mat:") {
        anyhow::bail!(
            "{option} {}: a name like FILE.mat:VARIABLE selects a MATLAB variable where inputs are read; choose another name",
            crate::io::lines::shown(&path.to_string_lossy())
        );
    }
    Ok(())
}

/// What proves that an existing single-file output is this command's earlier result, so that a
/// run may replace it: anything else is refused without `--overwrite`.
#[derive(Debug, Clone, Copy)]
pub enum Provenance {
    /// A JSON object whose `written_by` is `sinsmodel COMMAND` (see [`with_written_by`]).
    Json(&'static str),
    /// A text file whose first line is the provenance header `# sinsmodel COMMAND …`.
    Text(&'static str),
    /// A PNG carrying the `Software` text chunk `sinsmodel` that every plot of this crate has.
    Png,
}

/// `text` (pretty JSON of an object) with `"written_by": "sinsmodel COMMAND"` as its first
/// field: how a JSON output proves it is this command's ([`Provenance::Json`]).
pub fn with_written_by(text: &str, command: &str) -> String {
    match text.strip_prefix('{') {
        Some(rest) if rest.trim_start().starts_with('"') => {
            format!("{{\n  \"written_by\": \"sinsmodel {command}\",{rest}")
        }
        Some(rest) => format!("{{\n  \"written_by\": \"sinsmodel {command}\"{rest}"),
        None => text.to_string(),
    }
}

impl Provenance {
    /// Why the file at `path` is not provably this command's output (`None`: it is).
    fn lacking(&self, path: &Path) -> Option<String> {
        use std::io::Read;
        match self {
            Provenance::Json(cmd) => {
                let mut text = String::new();
                let read = std::fs::File::open(path)
                    .and_then(|f| f.take(64 << 20).read_to_string(&mut text));
                let v: Option<serde_json::Value> =
                    read.ok().and_then(|_| serde_json::from_str(&text).ok());
                let want = format!("sinsmodel {cmd}");
                match v
                    .as_ref()
                    .and_then(|v| v.get("written_by"))
                    .and_then(|w| w.as_str())
                {
                    Some(w) if w == want => None,
                    Some(w) => Some(format!("its \"written_by\" is \"{w}\", not \"{want}\"")),
                    None => Some(format!(
                        "it is not a JSON object with \"written_by\": \"{want}\""
                    )),
                }
            }
            Provenance::Text(cmd) => {
                let mut head = vec![0u8; 4096];
                let n = std::fs::File::open(path)
                    .and_then(|mut f| f.read(&mut head))
                    .unwrap_or(0);
                let first = String::from_utf8_lossy(&head[..n]);
                let first = first.lines().next().unwrap_or("");
                let want = format!("# sinsmodel {cmd}");
                (first != want && !first.starts_with(&format!("{want} "))).then(|| {
                    format!("its first line is not the header \"{want} …\" this command writes")
                })
            }
            Provenance::Png => {
                let bytes = std::fs::read(path).unwrap_or_default();
                (png_text(&bytes, "Software").as_deref() != Some(PNG_SOFTWARE))
                    .then(|| format!("it is not a PNG marked \"Software: {PNG_SOFTWARE}\""))
            }
        }
    }
}

/// The `Software` text every plot of this crate carries.
pub const PNG_SOFTWARE: &str = "sinsmodel";

/// CRC-32 (ISO-HDLC, as PNG chunks use) of `data`.
fn crc32(data: &[u8]) -> u32 {
    let mut c = 0xffff_ffffu32;
    for &b in data {
        c ^= b as u32;
        for _ in 0..8 {
            c = if c & 1 != 0 {
                0xedb8_8320 ^ (c >> 1)
            } else {
                c >> 1
            };
        }
    }
    !c
}

/// The PNG's chunks as (type, data) up to IEND, or `None` if it is no PNG.
fn png_chunks(bytes: &[u8]) -> Option<Vec<([u8; 4], &[u8])>> {
    let mut rest = bytes.strip_prefix(b"\x89PNG\r\n\x1a\n")?;
    let mut out = Vec::new();
    while rest.len() >= 12 {
        let len = u32::from_be_bytes(rest[..4].try_into().ok()?) as usize;
        let kind: [u8; 4] = rest[4..8].try_into().ok()?;
        let data = rest.get(8..8 + len)?;
        rest = rest.get(12 + len..)?;
        out.push((kind, data));
        if &kind == b"IEND" {
            break;
        }
    }
    Some(out)
}

/// The text of the PNG's `tEXt` chunk `keyword`, if it has one.
pub fn png_text(bytes: &[u8], keyword: &str) -> Option<String> {
    png_chunks(bytes)?
        .into_iter()
        .filter(|(k, _)| k == b"tEXt")
        .find_map(|(_, d)| {
            let z = d.iter().position(|&b| b == 0)?;
            (&d[..z] == keyword.as_bytes())
                .then(|| String::from_utf8_lossy(&d[z + 1..]).into_owned())
        })
}

/// `bytes` (a PNG) with a `tEXt` chunk `keyword` = `text` after its header chunk; `None` if it
/// is no PNG.
pub fn png_with_text(bytes: &[u8], keyword: &str, text: &str) -> Option<Vec<u8>> {
    let chunks = png_chunks(bytes)?;
    let mut out = b"\x89PNG\r\n\x1a\n".to_vec();
    let mut push = |kind: &[u8], data: &[u8]| {
        out.extend_from_slice(&(data.len() as u32).to_be_bytes());
        let start = out.len();
        out.extend_from_slice(kind);
        out.extend_from_slice(data);
        let crc = crc32(&out[start..]);
        out.extend_from_slice(&crc.to_be_bytes());
    };
    for (k, (kind, data)) in chunks.iter().enumerate() {
        push(kind, data);
        if k == 0 {
            let mut t = keyword.as_bytes().to_vec();
            t.push(0);
            t.extend_from_slice(text.as_bytes());
            push(b"tEXt", &t);
        }
    }
    Some(out)
}

/// Refuses an output file `path` (named by `option` in the message) that is one of `inputs`
/// (also through a link) or exists as something other than a regular file; and, unless
/// `overwrite` (the `--overwrite` option),
/// one that a sinsmodel run directory's [`RUN_MARKER`] lists (another run's result) or that is
/// not provably this command's earlier output (`provenance`; an empty file holds nothing to
/// lose). Call it before the computation.
pub fn check_output_file(
    option: &str,
    path: &Path,
    inputs: &[&Path],
    provenance: Provenance,
    overwrite: bool,
) -> Result<()> {
    check_output_path(option, path, inputs)?;
    let Ok(meta) = std::fs::metadata(path) else {
        return Ok(());
    };
    if overwrite {
        return Ok(());
    }
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    if let (Ok(listed), Some(name)) = (run_listing(dir), path.file_name()) {
        if listed.iter().any(|l| std::ffi::OsStr::new(l) == name) {
            anyhow::bail!(
                "{option} {}: is a result of the sinsmodel run in {} (its {RUN_MARKER} lists it); replacing it would change that run's outputs. Choose another path, or give --overwrite to replace it",
                path.display(),
                dir.display()
            );
        }
    }
    if meta.len() > 0 {
        if let Some(why) = provenance.lacking(path) {
            anyhow::bail!(
                "{option} {}: exists and is not provably an earlier output of this command ({why}); nothing is overwritten: choose another path, or give --overwrite to replace it",
                path.display()
            );
        }
    }
    Ok(())
}

/// Refuses an output file `path` (named by `option` in the message) that is one of `inputs`
/// (also through a link) or exists as something other than a regular file.
fn check_output_path(option: &str, path: &Path, inputs: &[&Path]) -> Result<()> {
    refuse_mat_variable_name(option, path)?;
    // writable before minutes of work: create the directory and a probe file in it
    if let Some(parent) = path.parent().filter(|p| !p.as_os_str().is_empty()) {
        std::fs::create_dir_all(parent).with_context(|| {
            format!(
                "{option} {}: cannot create {}",
                path.display(),
                parent.display()
            )
        })?;
    }
    // (a fresh temporary of this crate's form, never truncating anything that exists)
    let made = temporary_beside(path, "").and_then(|probe| {
        let opened = std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&probe);
        forget_temporary(&probe);
        Ok(opened?)
    });
    made.with_context(|| format!("{option} {}: cannot write there", path.display()))?;
    if let Ok(m) = std::fs::metadata(path) {
        if !m.is_file() {
            anyhow::bail!(
                "{option} {}: exists and is not a regular file (a directory, device or pipe); choose another output path",
                path.display()
            );
        }
        let canon = path.canonicalize().ok();
        for inp in inputs {
            if canon.is_some() && inp.canonicalize().ok() == canon {
                anyhow::bail!(
                    "{option} {}: is an input of this run ({}); choose another output path",
                    path.display(),
                    inp.display()
                );
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn crc32_is_the_png_one() {
        assert_eq!(crc32(b"123456789"), 0xcbf4_3926);
        assert_eq!(crc32(b"IEND"), 0xae42_6082);
    }

    #[test]
    fn a_png_gets_and_keeps_its_text() {
        // the smallest PNG: signature, IHDR (1×1 grey), IDAT, IEND
        let mut png = b"\x89PNG\r\n\x1a\n".to_vec();
        let mut chunk = |kind: &[u8], data: &[u8]| {
            png.extend_from_slice(&(data.len() as u32).to_be_bytes());
            let mut body = kind.to_vec();
            body.extend_from_slice(data);
            png.extend_from_slice(&body);
            png.extend_from_slice(&crc32(&body).to_be_bytes());
        };
        chunk(b"IHDR", &[0, 0, 0, 1, 0, 0, 0, 1, 8, 0, 0, 0, 0]);
        chunk(b"IDAT", &[0x78, 0x9c, 0x63, 0x60, 0, 0, 0, 2, 0, 1]);
        chunk(b"IEND", &[]);
        assert_eq!(png_text(&png, "Software"), None);
        let marked = png_with_text(&png, "Software", "sinsmodel").unwrap();
        assert_eq!(png_text(&marked, "Software").as_deref(), Some("sinsmodel"));
        // every chunk's CRC checks, and the text sits right after IHDR
        let mut rest = &marked[8..];
        while rest.len() >= 12 {
            let len = u32::from_be_bytes(rest[..4].try_into().unwrap()) as usize;
            let crc = u32::from_be_bytes(rest[8 + len..12 + len].try_into().unwrap());
            assert_eq!(crc32(&rest[4..8 + len]), crc);
            rest = &rest[12 + len..];
        }
        let chunks = png_chunks(&marked).unwrap();
        assert_eq!(&chunks[1].0, b"tEXt");
        assert_eq!(chunks.len(), 4);
        assert_eq!(png_with_text(b"not a png", "Software", "x"), None);
    }

    #[test]
    fn written_by_comes_first_in_a_json_object() {
        let t = with_written_by("{\n  \"a\": 1\n}", "align");
        let v: serde_json::Value = serde_json::from_str(&t).unwrap();
        assert_eq!(v["written_by"], "sinsmodel align");
        assert_eq!(v["a"], 1);
        assert!(t.starts_with("{\n  \"written_by\""));
        let v: serde_json::Value = serde_json::from_str(&with_written_by("{}", "x")).unwrap();
        assert_eq!(v["written_by"], "sinsmodel x");
    }

    #[test]
    fn only_exact_temporary_names_are_leftovers() {
        assert_eq!(
            leftover_kind(".nav.txt.sinsmodel-partial-12-0", "nav.txt"),
            Some(("partial", 12))
        );
        assert_eq!(
            leftover_kind(".o.sinsmodel-staging-7", "o"),
            Some(("staging", 7))
        );
        assert_eq!(leftover_kind(".o.sinsmodel-old-7", "o"), Some(("old", 7)));
        for user in [
            // a plain file of the temporaries' former name form: a user's
            "nav.txt.sinsmodel-partial-12-0",
            "a_gyro.png.sinsmodel-partial-12-3.png",
            ".nav.txt.sinsmodel-partial-12",
            ".nav.txt.sinsmodel-partial-12-0x",
            "nav.txt.old-2024",
            "nav.txt.partial-12-0",
            "nav.txt.sinsmodel-partial-12",
            "nav.txt.sinsmodel-partial-12-0.bak",
            "nav.txt.sinsmodel-partial--0",
            ".o.old-7",
            ".o.sinsmodel-old-7x",
            ".oo.sinsmodel-old-7",
        ] {
            let name = match user {
                u if u.contains("nav") => "nav.txt",
                u if u.contains("gyro") => "a_gyro.png",
                _ => "o",
            };
            assert_eq!(leftover_kind(user, name), None, "{user}");
        }
    }
}
