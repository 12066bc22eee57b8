//! The data options as the command line takes them (the library's [`sinsmodel::data`], which
//! opens the data), and how the library's notes reach stderr.

use anyhow::Result;
pub use sinsmodel::data::{DataOptions as DataArgs, ImuSource};

/// Prints a note of the library (what is read, what `--init auto` found, warnings) on stderr.
pub fn note(line: &str) {
    eprintln!("{line}");
}

/// Prints the sensor noise and grade the run assumes and the known GNSS values (once per run).
pub fn print_noise(data: &DataArgs) -> Result<()> {
    for line in data.noise_lines()? {
        eprintln!("{line}");
    }
    Ok(())
}
