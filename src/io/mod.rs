//! Files in and out: IMU increments, aiding and truth files, readers of other formats (PSINS
//! `.imu`, GNSS_IMU csv, RTKLIB `.pos`), quantities with units at the edges, atomic outputs,
//! the warnings said about the data (kept for the report).

pub mod aiding;
pub mod atomic_file;
pub mod bounds;
pub mod fixed;
pub mod imu;
pub mod imu_format;
pub mod imu_stream;
pub mod json_unique;
pub mod lines;
pub mod readers;
pub mod sample_source;
pub mod truth;
pub mod truth_row;
pub mod units;
pub mod warnings;
