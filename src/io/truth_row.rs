//! The truth record, a leaf the truth file and the readers of other formats both produce.

use nalgebra::Vector3;

/// A truth record (angles in radians in memory).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TruthRow {
    /// Time [s].
    pub t: f64,
    /// Latitude [rad].
    pub lat: f64,
    /// Longitude [rad].
    pub lon: f64,
    /// Height [m].
    pub h: f64,
    /// NED velocity [m/s].
    pub v: Vector3<f64>,
    /// Roll, pitch, yaw [rad].
    pub euler: Vector3<f64>,
}
