//! Readers for measured data in other people's formats, producing the project's own types
//! (FRD body increments, NED, SI).

pub mod gnss_imu;
pub mod matlab;
pub mod psins;
pub mod rtklib;

use crate::io::imu::ImuData;
use anyhow::Result;
use std::path::Path;

/// Reads an IMU file as `format` describes it (`--imu-format`), else as the description beside
/// it (`FILE.format.toml`), else by extension; also returns the words saying which was used.
/// Every sample is validated ([`crate::io::imu_stream::ImuStream`]).
pub fn read_imu(path: &Path, format: Option<&Path>) -> Result<(ImuData, String)> {
    let (stream, how) = crate::io::imu_stream::ImuStream::open(path, format)?;
    Ok((stream.collect()?, how))
}
