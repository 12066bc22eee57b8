//! The leaf every IMU reader stands on: the [`SampleSource`] trait (samples in file order) and
//! the limits of what any IMU measures. Readers build sources; [`crate::io::imu_stream`] wraps
//! a source into a validated stream and dispatches a file to its reader, never the other way.

use crate::io::imu::ImuSample;
use crate::io::units::STANDARD_GRAVITY;
use anyhow::Result;

/// Largest angular rate any IMU measures [rad/s].
pub const MAX_RATE: f64 = 100.0;
/// Largest specific force any IMU measures [m/s²] (2000 g).
pub const MAX_FORCE: f64 = 2000.0 * STANDARD_GRAVITY;
/// A reader of one IMU format that hands out samples in file order.
pub trait SampleSource {
    /// The next sample and the file line it came from (0 when it has no line of its own), or
    /// None at the end.
    fn next_sample(&mut self) -> Result<Option<(ImuSample, usize)>>;
    /// Fraction of the input read so far (for progress; 0 when unknown).
    fn fraction(&self) -> f64;
}
