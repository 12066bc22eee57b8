//! The data options as the command line takes them (the library's [`sinsmodel::data`], which
//! opens the data), and how the library's notes reach stderr.

use anyhow::Result;
pub use sinsmodel::data::{DataOptions as DataArgs, ImuSource};

/// Refuses `--force` on a command whose only use for it was replacing outputs (align,
/// imu-check): it now runs past data checks only, and `--overwrite` replaces.
pub fn refuse_force_for_outputs(force: bool) -> Result<()> {
    if force {
        anyhow::bail!(
            "--force replaces no file any more (it only runs past data checks): give --overwrite to replace --json"
        );
    }
    Ok(())
}

/// Prints a note of the library (what is read, what `--init auto` found, warnings) on stderr.
pub fn note(line: &str) {
    eprintln!("{line}");
    if let Some(w) = line.strip_prefix("warning: ") {
        sinsmodel::io::warnings::keep(w);
    }
}

/// Prints the sensor noise and grade the run assumes and the known GNSS values (once per run).
pub fn print_noise(data: &DataArgs) -> Result<()> {
    for line in data.noise_lines()? {
        eprintln!("{line}");
    }
    Ok(())
}
