//! Reports: the paper's reproduction and its statistics, PNG plots and progress bars (the
//! last two with the `cli` feature).

pub mod explain;
#[cfg(feature = "cli")]
pub mod plot;
#[cfg(feature = "cli")]
pub mod progress;
pub mod reproduce;
