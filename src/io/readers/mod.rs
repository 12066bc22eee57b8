//! Readers for measured data in other people's formats, producing the project's own types
//! (FRD body increments, NED, SI).

pub mod gnss_imu;
pub mod psins;
pub mod rtklib;

use crate::io::imu::ImuData;
use anyhow::Result;
use std::path::Path;

/// Reads an IMU file in any known format, chosen by extension: `.imu` PSINS, `.csv`
/// GNSS_IMU (with its `.tag` beside it for GPST), anything else the project's text format.
pub fn read_any_imu(path: &Path) -> Result<ImuData> {
    match path.extension().and_then(|e| e.to_str()) {
        Some("imu") => Ok(psins::read(path)?.imu),
        Some("csv") => Ok(gnss_imu::read(path)?.imu),
        _ => crate::io::imu::read_text(path),
    }
}
