//! Reports: explain's words and Markdown, PNG plots and progress bars (the last two with the
//! `cli` feature). Rendering only; the experiments are in `experiment`.

pub mod align;
pub mod allan;
pub mod explain;
#[cfg(feature = "cli")]
pub mod explain_files;
pub mod explain_notes;
pub mod filter;
pub mod imu_check;
#[cfg(feature = "cli")]
pub mod plot;
#[cfg(feature = "cli")]
pub mod progress;
pub mod reproduce;
