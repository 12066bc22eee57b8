//! Writing output files so that a reader never sees a half-finished file: write to a temporary
//! file beside the target, flush, then rename over it.

use anyhow::{Context, Result};
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

/// A file being written; it appears at its final path only on [`AtomicFile::commit`].
pub struct AtomicFile {
    tmp: PathBuf,
    target: PathBuf,
    out: Option<BufWriter<std::fs::File>>,
}

impl AtomicFile {
    /// Starts writing `target` (through `target` + `.partial`).
    pub fn create(target: &Path) -> Result<AtomicFile> {
        let mut tmp = target.as_os_str().to_owned();
        tmp.push(".partial");
        let tmp = PathBuf::from(tmp);
        let f = std::fs::File::create(&tmp)
            .with_context(|| format!("cannot create {}", tmp.display()))?;
        Ok(AtomicFile {
            tmp,
            target: target.to_path_buf(),
            out: Some(BufWriter::with_capacity(1 << 20, f)),
        })
    }

    /// The writer.
    pub fn writer(&mut self) -> &mut BufWriter<std::fs::File> {
        self.out.as_mut().expect("not committed")
    }

    /// Flushes and renames into place.
    pub fn commit(mut self) -> Result<()> {
        let mut w = self.out.take().expect("not committed");
        w.flush()
            .with_context(|| format!("cannot write {}", self.tmp.display()))?;
        drop(w);
        std::fs::rename(&self.tmp, &self.target).with_context(|| {
            format!(
                "cannot move {} to {}",
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
