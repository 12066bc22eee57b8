//! Initial attitude of an IMU whose axes are not documented, from the data: roll and pitch from
//! gravity in the static start, heading from the direction of the first acceleration when the
//! vehicle drives off, matched to the course of the reference (RTK) velocity.

use crate::io::imu::ImuData;
use crate::io::readers::rtklib::PosEpoch;
use crate::nav::attitude::dcm_from_euler;
use anyhow::{bail, Result};
use nalgebra::Vector3;

/// What was found.
#[derive(Debug, Clone, Copy)]
pub struct Mounting {
    /// Roll, pitch, yaw of the sensor axes in NED at the start [rad].
    pub euler: Vector3<f64>,
    /// Mean static specific force in sensor axes [m/s²].
    pub f_static: Vector3<f64>,
    /// Drive-off acceleration direction in sensor axes (unit, gravity removed).
    pub forward_sensor: Vector3<f64>,
    /// RTK course at drive-off [rad].
    pub course: f64,
    /// Drive-off time (RTK speed first above 1 m/s) [s].
    pub t_drive_off: f64,
}

/// Finds the sensor attitude at the start: `static_s` seconds of static data at the start;
/// the drive-off is where the reference speed first exceeds 1 m/s.
pub fn from_drive_off(imu: &ImuData, pos: &[PosEpoch], static_s: f64) -> Result<Mounting> {
    let dt = imu.interval();
    let t0 = imu.samples[0].t;
    let stat: Vec<_> = imu.samples.iter().filter(|s| s.t < t0 + static_s).collect();
    if stat.len() < 100 {
        bail!("fewer than 100 static samples");
    }
    let f_static = stat.iter().map(|s| s.dv).sum::<Vector3<f64>>() / (stat.len() as f64 * dt);
    let roll = (-f_static.y).atan2(-f_static.z);
    let pitch = f_static
        .x
        .atan2((f_static.y * f_static.y + f_static.z * f_static.z).sqrt());
    let speed = |p: &PosEpoch| p.v_ned.map(|v| v[0].hypot(v[1])).unwrap_or(0.0);
    let k = pos
        .iter()
        .position(|p| speed(p) > 1.0)
        .ok_or_else(|| anyhow::anyhow!("the reference never moves"))?;
    let t_drive_off = pos[k].t;
    // course from the reference velocity 2 s after drive-off
    let later = pos
        .iter()
        .find(|p| p.t >= t_drive_off + 2.0)
        .unwrap_or(&pos[k]);
    let v = later.v_ned.unwrap_or([1.0, 0.0, 0.0]);
    let course = v[1].atan2(v[0]);
    // mean acceleration over the 2 s from drive-off minus the static specific force, levelled
    let acc: Vec<_> = imu
        .samples
        .iter()
        .filter(|s| s.t >= t_drive_off - 0.5 && s.t < t_drive_off + 1.5)
        .collect();
    if acc.is_empty() {
        bail!("no IMU samples at the drive-off");
    }
    let a_sensor =
        acc.iter().map(|s| s.dv).sum::<Vector3<f64>>() / (acc.len() as f64 * dt) - f_static;
    let level = dcm_from_euler(roll, pitch, 0.0);
    let a_level = level * a_sensor;
    // in the levelled frame the forward direction is at angle atan2(y, x) from the sensor x axis;
    // the sensor's yaw is the course minus that angle
    let yaw = course - a_level.y.atan2(a_level.x);
    Ok(Mounting {
        euler: Vector3::new(roll, pitch, yaw),
        f_static,
        forward_sensor: a_sensor.normalize(),
        course,
        t_drive_off,
    })
}
