//! Estimation on IMU data: the error-state Kalman filter over any model, static alignment,
//! Allan deviation and noise identification, the initial state and IMU mounting from the data
//! (`--init auto`), IMU log plausibility.

pub mod align;
pub mod allan;
pub mod clock_check;
pub mod filter;
pub mod imu_check;
pub mod init;
pub mod metrics;
pub mod nav_tape;
pub mod replay;
pub mod stats;
