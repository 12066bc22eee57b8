//! Physical ranges of the quantities that enter from outside (options and file rows), in one
//! place: each function returns the problem in words, or None when the value is plausible.
//! Degrees at the edge, as the files and options write them.

/// Latitude [deg]: finite and inside (−90, 90) (the navigation frame is undefined at a pole).
pub fn lat_deg(v: f64) -> Option<String> {
    (v.is_nan() || v.abs() >= 90.0).then(|| format!("latitude {v} outside (-90, 90) deg"))
}

/// Longitude [deg]: finite, −180 ..= 360.
pub fn lon_deg(v: f64) -> Option<String> {
    (!(-180.0..=360.0).contains(&v)).then(|| format!("longitude {v} outside -180 .. 360 deg"))
}

/// `v` unchanged (to the last bit) when `keep` holds, else wrapped into [−half, half): how a
/// file writes an angle that a navigator or simulator accumulated (same unit as `half`).
fn wrapped(v: f64, half: f64, keep: bool) -> f64 {
    if keep || !v.is_finite() {
        v
    } else {
        (v + half).rem_euclid(2.0 * half) - half
    }
}

/// Longitude [deg] as files write it: unchanged inside [−180, 180), else wrapped into it
/// (a crossing of 180° either way must not write −180.0001 or 360.0001, which readers refuse).
pub fn written_lon_deg(v: f64) -> f64 {
    wrapped(v, 180.0, (-180.0..180.0).contains(&v))
}

/// Longitude [rad] as files write it: unchanged inside [−π, π), else wrapped into it.
pub fn written_lon_rad(v: f64) -> f64 {
    use std::f64::consts::PI;
    wrapped(v, PI, (-PI..PI).contains(&v))
}

/// Yaw [deg] as files write it: unchanged inside the readers' ±360, else wrapped into
/// [−180, 180).
pub fn written_yaw_deg(v: f64) -> f64 {
    wrapped(v, 180.0, v.abs() <= 360.0)
}

/// Yaw [rad] as files write it: unchanged inside ±2π, else wrapped into [−π, π).
pub fn written_yaw_rad(v: f64) -> f64 {
    use std::f64::consts::PI;
    wrapped(v, PI, v.abs() <= 2.0 * PI)
}

/// Height [m]: finite, within ±1e5.
pub fn height_m(v: f64) -> Option<String> {
    (v.is_nan() || v.abs() > 1e5).then(|| format!("height {v} beyond ±1e5 m"))
}

/// Roll, pitch, yaw [deg]: roll ±180, pitch ±90, yaw ±360.
pub fn attitude_deg(rpy: [f64; 3]) -> Option<String> {
    let ok = rpy[0].abs() <= 180.0 && rpy[1].abs() <= 90.0 && rpy[2].abs() <= 360.0;
    (!ok).then(|| format!("attitude {rpy:?} outside roll ±180, pitch ±90, yaw ±360 deg"))
}

/// Velocity components [m/s]: finite, each within ±1e4.
pub fn velocity_mps(v: [f64; 3]) -> Option<String> {
    (!v.iter().all(|x| x.abs() <= 1e4)).then(|| format!("velocity {v:?} beyond ±1e4 m/s"))
}

/// Specific force components [m/s²]: finite, each within ±1e4 (about 1000 g).
pub fn specific_force_mps2(f: [f64; 3]) -> Option<String> {
    (!f.iter().all(|x| x.abs() <= 1e4))
        .then(|| format!("specific force {f:?} beyond ±1e4 m/s^2 (about 1000 g)"))
}

/// Angular rate components [rad/s]: finite, each within ±1e3.
pub fn angular_rate_rps(w: [f64; 3]) -> Option<String> {
    (!w.iter().all(|x| x.abs() <= 1e3)).then(|| format!("angular rate {w:?} beyond ±1e3 rad/s"))
}

/// `None` when every angular acceleration component is within ±1e5 rad/s² (else why not).
pub fn angular_accel_rps2(dw: [f64; 3]) -> Option<String> {
    (!dw.iter().all(|x| x.abs() <= 1e5))
        .then(|| format!("angular acceleration {dw:?} beyond ±1e5 rad/s²"))
}

/// `None` when every component of a specific force's rate of change is within ±1e6 m/s³.
pub fn jerk_mps3(df: [f64; 3]) -> Option<String> {
    (!df.iter().all(|x| x.abs() <= 1e6))
        .then(|| format!("rate of change of the specific force {df:?} beyond ±1e6 m/s³"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn edges_and_non_finite_values() {
        assert!(lat_deg(89.9).is_none() && lat_deg(90.0).is_some() && lat_deg(f64::NAN).is_some());
        assert!(
            lon_deg(360.0).is_none() && lon_deg(-181.0).is_some() && lon_deg(f64::NAN).is_some()
        );
        assert!(height_m(-1e5).is_none() && height_m(f64::INFINITY).is_some());
        assert!(attitude_deg([180.0, -90.0, 360.0]).is_none());
        assert!(
            attitude_deg([0.0, 95.0, 0.0]).is_some()
                && attitude_deg([f64::NAN, 0.0, 0.0]).is_some()
        );
        assert!(velocity_mps([1e4, -1e4, 0.0]).is_none());
        assert!(velocity_mps([0.0, 1e308, 0.0]).is_some() && velocity_mps([f64::NAN; 3]).is_some());
        assert!(specific_force_mps2([0.0, 0.0, -9.8]).is_none());
        assert!(specific_force_mps2([0.0, 0.0, -1e308]).is_some());
        assert!(angular_rate_rps([1e3, 0.0, 0.0]).is_none());
        assert!(angular_rate_rps([0.0, f64::INFINITY, 0.0]).is_some());
    }

    #[test]
    fn written_angles_are_ones_the_readers_take() {
        // in range: the same bits
        assert_eq!(written_lon_deg(-179.999_999_9), -179.999_999_9);
        assert_eq!(written_yaw_deg(350.0), 350.0);
        // across 180° either way, and past 360°
        assert!((written_lon_deg(-180.000_08) - 179.999_92).abs() < 1e-9);
        assert!((written_lon_deg(360.0001) - 0.0001).abs() < 1e-9);
        assert!((written_lon_deg(180.0) + 180.0).abs() < 1e-12);
        assert!((written_yaw_deg(-450.0) + 90.0).abs() < 1e-12);
        let pi = std::f64::consts::PI;
        assert!((written_lon_rad(pi + 0.1) - (-pi + 0.1)).abs() < 1e-12);
        assert!((written_yaw_rad(-2.0 * pi - 0.1) + 0.1).abs() < 1e-12);
        for v in [-540.0, -180.000_08, 180.0, 359.9, 360.0001, 1e6] {
            assert!(lon_deg(written_lon_deg(v)).is_none(), "{v}");
            assert!(
                attitude_deg([0.0, 0.0, written_yaw_deg(v)]).is_none(),
                "{v}"
            );
        }
    }
}
