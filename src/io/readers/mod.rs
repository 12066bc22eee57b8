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

/// Reads an IMU file as `format` describes it (`--imu-format`), else as the description beside
/// it (`FILE.format.toml`), else by extension; also returns the words saying which was used.
pub fn read_imu(path: &Path, format: Option<&Path>) -> Result<(ImuData, String)> {
    use crate::io::imu_format::{beside, ImuFormat};
    if !std::fs::metadata(path).is_ok_and(|m| m.is_file()) {
        anyhow::bail!(
            "--imu {}: cannot read IMU file (missing, or not a regular file: a directory, device or pipe)",
            path.display()
        );
    }
    if let Some(f) = format {
        let fmt = ImuFormat::load(f)?;
        return Ok((fmt.read(path)?, format!("as described by {}", f.display())));
    }
    if let Some(f) = beside(path) {
        let fmt = ImuFormat::load(&f)?;
        return Ok((
            fmt.read(path)?,
            format!("as described by {} (found beside it)", f.display()),
        ));
    }
    let how = match path.extension().and_then(|e| e.to_str()) {
        Some("imu") => "as a PSINS .imu log (by its extension)",
        Some("csv") => "as a GNSS_IMU csv on GPST with its .tag file (by its extension)",
        _ => "as sinsmodel IMU text (t dtheta_xyz [rad] dv_xyz [m/s], FRD)",
    };
    Ok((
        read_any_imu(path)?,
        format!("{how}; --imu-format describes any other layout"),
    ))
}
