//! `imu-check`'s words: what the log holds as read (sampling, the static window's specific
//! force, angular rate and attitude, notes) and the verdict of a plausible log.

use crate::estimate::imu_check::ImuCheck;
use crate::explain::sig3;

/// The lines of what was read: sampling, the window's specific force and angular rate (or that
/// it is empty), the static attitude, the notes.
pub fn lines(c: &ImuCheck) -> Vec<String> {
    let mut v = vec![format!(
        "{} samples over {:.3} s: {:.3} Hz (median interval {:.6} s; shortest {:.6} s, longest {:.6} s; jitter RMS {:.2e} s; {} gaps)",
        c.samples,
        c.duration_s,
        c.rate_hz,
        1.0 / c.rate_hz,
        c.interval_min_s,
        c.interval_max_s,
        c.jitter_rms_s,
        c.gaps
    )];
    if c.f_spread_mps2.is_finite() {
        v.push(format!(
            "window {:.3}–{:.3} s: specific force FRD ({:.4}, {:.4}, {:.4}) m/s² (spread {:.3} m/s² RMS{}), |f| = {}× local gravity {:.4} m/s²",
            c.window_s[0],
            c.window_s[1],
            c.f_mean_mps2[0],
            c.f_mean_mps2[1],
            c.f_mean_mps2[2],
            c.f_spread_mps2,
            if c.is_static { ", static" } else { ", moving" },
            sig3(c.gravity_ratio),
            c.gravity_mps2
        ));
        let d = 180.0 / std::f64::consts::PI;
        v.push(format!(
            "angular rate FRD ({:.3e}, {:.3e}, {:.3e}) deg/h, |ω| = {}× Earth rate",
            c.w_mean_radps[0] * d * 3600.0,
            c.w_mean_radps[1] * d * 3600.0,
            c.w_mean_radps[2] * d * 3600.0,
            sig3(c.earth_rate_ratio)
        ));
    } else {
        v.push(format!(
            "window {:.3}–{:.3} s: no samples in it",
            c.window_s[0], c.window_s[1]
        ));
    }
    if c.is_static {
        v.push(format!(
            "static attitude: roll {:.3}°, pitch {:.3}°, heading {}",
            c.roll_deg,
            c.pitch_deg,
            match c.heading_deg {
                Some(h) => format!("{h:.1}° (gyrocompass, coarse)"),
                None => "not resolved by these gyros".into(),
            }
        ));
    }
    for n in &c.notes {
        v.push(format!("note: {n}"));
    }
    v
}

/// The verdict of a log without problems: what a static window confirmed, or that units and
/// axes were not checked.
pub fn verdict(c: &ImuCheck) -> String {
    if c.is_static {
        format!(
            "plausible: gravity and attitude as expected for a static IMU with these units and axes; {}",
            if (0.5..2.0).contains(&c.earth_rate_ratio) {
                "Earth rate as expected".to_string()
            } else {
                format!(
                    "Earth rate not resolved (the gyro bias makes |ω| {}× Earth rate, a bias of at least {} deg/h: a MEMS gyro's; \
                     for a navigation- or tactical-grade unit that is no bias but a unit slip, deg/s read as rad/s likely: check gyro_unit)",
                    sig3(c.earth_rate_ratio),
                    sig3(crate::estimate::imu_check::least_gyro_bias_deg_h(c).unwrap_or(0.0))
                )
            }
        )
    } else {
        "sampling read; units and axes not checked (no static stretch in the window)".to_string()
    }
}
