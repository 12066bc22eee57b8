//! Writing output files so that a reader never sees a half-finished file: write to a temporary
//! file beside the target, flush, then rename over it.

use anyhow::{Context, Result};
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

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
    /// Starts writing `target` (through `target.partial-PID-N`, unique per process and file),
    /// creating its directory.
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
            remove_stale(dir, &format!("{}.", name.to_string_lossy()));
        }
        // unique per process and file: concurrent runs never share a temporary
        static SERIAL: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
        let k = SERIAL.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let mut tmp = target.as_os_str().to_owned();
        tmp.push(format!(".partial-{}-{k}", std::process::id()));
        let tmp = PathBuf::from(tmp);
        let f = std::fs::File::create(&tmp)
            .with_context(|| format!("cannot create {}", tmp.display()))?;
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
            let _ = std::fs::remove_file(&self.tmp);
            anyhow::bail!(
                "cannot write {} (for {}): {e}",
                self.tmp.display(),
                self.target.display()
            );
        }
        drop(w);
        std::fs::rename(&self.tmp, &self.target).map_err(|e| {
            let _ = std::fs::remove_file(&self.tmp);
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
            let _ = std::fs::remove_file(&self.tmp);
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
    committed: bool,
}

impl OutputDir {
    /// Checks `target` can be replaced and that no `inputs` lie inside it, then creates the
    /// staging directory.
    pub fn create(target: &Path, inputs: &[&Path]) -> Result<OutputDir> {
        refuse_mat_variable_name("--out", target)?;
        if target.exists() {
            if !target.is_dir() {
                anyhow::bail!("--out {}: exists and is not a directory", target.display());
            }
            let empty = std::fs::read_dir(target)
                .with_context(|| format!("cannot read {}", target.display()))?
                .next()
                .is_none();
            if !empty && !target.join(RUN_MARKER).exists() {
                anyhow::bail!(
                    "--out {}: the directory exists and was not written by sinsmodel; choose another (nothing is overwritten)",
                    target.display()
                );
            }
            if !empty {
                // the marker lists the run's files (one per line after the first): anything
                // else was put there since, and replacing the directory would lose it
                let marker = std::fs::read_to_string(target.join(RUN_MARKER)).unwrap_or_default();
                let listed: Vec<&str> = marker.lines().skip(1).collect();
                if !listed.is_empty() {
                    let mut foreign: Vec<String> = std::fs::read_dir(target)
                        .with_context(|| format!("cannot read {}", target.display()))?
                        .filter_map(|e| e.ok())
                        .map(|e| e.file_name().to_string_lossy().into_owned())
                        .filter(|n| n != RUN_MARKER && !listed.contains(&n.as_str()))
                        .collect();
                    if !foreign.is_empty() {
                        foreign.sort();
                        anyhow::bail!(
                            "--out {}: holds files the earlier sinsmodel run did not write ({}); move them or choose another --out (nothing is overwritten)",
                            target.display(),
                            foreign.join(", ")
                        );
                    }
                }
            }
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
        let parent = match target.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        std::fs::create_dir_all(&parent)
            .with_context(|| format!("cannot create {}", parent.display()))?;
        let name = target
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_else(|| "out".into());
        remove_stale(&parent, &format!(".{name}."));
        let staging = sibling(target, "partial");
        let _ = std::fs::remove_dir_all(&staging);
        std::fs::create_dir(&staging)
            .with_context(|| format!("cannot create {}", staging.display()))?;
        Ok(OutputDir {
            staging,
            target: target.to_path_buf(),
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
        names.sort();
        write_text(
            &self.staging.join(RUN_MARKER),
            &format!("written by sinsmodel; its files:\n{}\n", names.join("\n")),
        )?;
        // two renames, each atomic: the earlier run moves aside whole, the new one moves in
        // whole; a kill between them leaves no target (never a mixed or half-deleted one), and
        // the hidden leftovers are removed by the next run
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
        let _ = std::fs::remove_dir_all(&old);
        Ok(())
    }
}

impl Drop for OutputDir {
    fn drop(&mut self) {
        if !self.committed {
            let _ = std::fs::remove_dir_all(&self.staging);
        }
    }
}

/// `.NAME.KIND-PID` beside `target`: this process's hidden staging or set-aside directory.
fn sibling(target: &Path, kind: &str) -> PathBuf {
    let parent = match target.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let name = target
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "out".into());
    parent.join(format!(".{name}.{kind}-{}", std::process::id()))
}

/// True unless the process `pid` is known to be gone (Linux: no /proc/PID).
fn pid_alive(pid: u32) -> bool {
    if !Path::new("/proc/self").exists() {
        return true;
    }
    Path::new(&format!("/proc/{pid}")).exists()
}

/// Removes leftovers of killed runs in `dir`: entries named `PREFIX…-PID` or `PREFIX…-PID-N`
/// (temporaries, staging and set-aside directories) whose process is gone.
fn remove_stale(dir: &Path, prefix: &str) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for e in entries.filter_map(|e| e.ok()) {
        let name = e.file_name().to_string_lossy().into_owned();
        let Some(rest) = name.strip_prefix(prefix) else {
            continue;
        };
        // KIND-PID or KIND-PID-N, KIND one of partial, old
        let mut parts = rest.rsplit('-');
        let (Some(a), Some(b)) = (parts.next(), parts.next()) else {
            continue;
        };
        let kind_ok = |k: &str| k.ends_with("partial") || k.ends_with("old");
        let pid = match (a.parse::<u32>(), b.parse::<u32>()) {
            (Ok(_), Ok(pid)) if parts.next().is_some_and(kind_ok) => pid,
            (Ok(pid), _) if kind_ok(b) => pid,
            _ => continue,
        };
        if pid != std::process::id() && !pid_alive(pid) {
            let p = e.path();
            let _ = std::fs::remove_dir_all(&p).or_else(|_| std::fs::remove_file(&p));
        }
    }
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

/// Refuses an output file `path` (named by `option` in the message) that is one of `inputs`
/// (also through a link) or exists as something other than a regular file; call it before the
/// computation.
pub fn check_output_file(option: &str, path: &Path, inputs: &[&Path]) -> Result<()> {
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
    let mut probe = path.as_os_str().to_owned();
    probe.push(format!(".probe-{}", std::process::id()));
    let probe = PathBuf::from(probe);
    std::fs::File::create(&probe)
        .with_context(|| format!("{option} {}: cannot write there", path.display()))?;
    let _ = std::fs::remove_file(&probe);
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
