//! sinsmodel: an error-model compiler and model-discovery tool for strapdown inertial
//! navigation systems. Frames: NED navigation, FRD body; SI units and radians inside.
//!
//! The data path: `model-spec/*.toml` → `codegen/` (build.rs) → [`model::generated`] →
//! [`model::Model`] → [`estimate::filter`] → [`explain`] → [`experiment`] / [`report`]. Modules are grouped by domain:
//!
//! - [`model`]: the compiled error models (catalogue, generated kernels, run-time composition,
//!   covariance propagation, Jacobians at a point).
//! - [`data`]: the data a run reads, opened by the library (options, aiding plan, outages,
//!   initial state, the filter set-up the options give).
//! - [`nav`]: Earth model, attitude, the linearisation point, the strapdown navigator.
//! - [`sim`]: scenarios, trajectories, the IMU simulator with error injection, seeded RNG.
//! - [`estimate`]: the error-state Kalman filter, alignment, Allan deviation, mounting.
//! - [`explain`]: what a model gets wrong on measured data and which term causes it (GLR
//!   signatures, innovation diagnostics, selection, words); returns data only.
//! - [`io`]: IMU, aiding and truth files, readers of other formats, units at the edges,
//!   atomic output files.
//! - [`experiment`]: the paper's reproduction, hidden-effect cases end to end, explain's
//!   evaluation campaign (built on `estimate`, never used by it).
//! - [`report`]: rendering: explain's words and Markdown, plots and progress bars.
//! - [`fuzzing`]: fuzz target bodies, shared by cargo-fuzz and the stable corpus test.

pub mod data;
pub mod estimate;
pub mod experiment;
pub mod explain;
pub mod fuzzing;
pub mod io;
pub mod model;
pub mod nav;
pub mod report;
pub mod sim;
