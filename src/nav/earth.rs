//! WGS-84 Earth model: radii of curvature, Earth rate, normal gravity (Somigliana with the
//! WGS-84 free-air correction) and its derivatives. SI units, radians, NED frame.

/// WGS-84 semi-major axis [m].
pub const A: f64 = 6_378_137.0;
/// WGS-84 flattening [-].
pub const F: f64 = 1.0 / 298.257_223_563;
/// First eccentricity squared [-].
pub const E2: f64 = F * (2.0 - F);
/// Earth rotation rate [rad/s].
pub const OMEGA: f64 = 7.292_115e-5;
/// Geocentric gravitational constant [m³/s²].
pub const GM: f64 = 3.986_004_418e14;
/// Normal gravity at the equator [m/s²].
pub const GAMMA_E: f64 = 9.780_325_335_9;
/// Normal gravity at the poles [m/s²].
pub const GAMMA_P: f64 = 9.832_184_937_8;

/// Meridian radius of curvature R_M at latitude `lat` [rad] → [m].
pub fn radius_meridian(lat: f64) -> f64 {
    let s2 = lat.sin().powi(2);
    A * (1.0 - E2) / (1.0 - E2 * s2).powf(1.5)
}

/// Transverse (prime-vertical) radius of curvature R_N at latitude `lat` [rad] → [m].
pub fn radius_transverse(lat: f64) -> f64 {
    let s2 = lat.sin().powi(2);
    A / (1.0 - E2 * s2).sqrt()
}

const B: f64 = A * (1.0 - F);
const K_SOMIGLIANA: f64 = (B * GAMMA_P - A * GAMMA_E) / (A * GAMMA_E);
const M_RATIO: f64 = OMEGA * OMEGA * A * A * B / GM;

fn free_air(lat: f64, h: f64) -> f64 {
    let s2 = lat.sin().powi(2);
    1.0 - 2.0 / A * (1.0 + F + M_RATIO - 2.0 * F * s2) * h + 3.0 * h * h / (A * A)
}

fn gamma0(lat: f64) -> f64 {
    let s2 = lat.sin().powi(2);
    GAMMA_E * (1.0 + K_SOMIGLIANA * s2) / (1.0 - E2 * s2).sqrt()
}

/// Longitude difference `a − b` [rad] as the shorter way round, in (−π, π]: across the
/// antimeridian 179.9° − (−179.9°) is −0.2°, not 359.8°. Unchanged to the last bit when it
/// is already within ±π.
pub fn lon_difference(a: f64, b: f64) -> f64 {
    let d = a - b;
    if d.abs() <= std::f64::consts::PI {
        d
    } else {
        let two_pi = 2.0 * std::f64::consts::PI;
        -((-d + std::f64::consts::PI).rem_euclid(two_pi) - std::f64::consts::PI)
    }
}

/// Normal gravity magnitude γ(lat, h) [m/s²], pointing down in NED.
pub fn gravity(lat: f64, h: f64) -> f64 {
    gamma0(lat) * free_air(lat, h)
}

/// ∂γ/∂lat [m/s²/rad].
pub fn gravity_dlat(lat: f64, h: f64) -> f64 {
    let (s, c) = lat.sin_cos();
    let s2 = s * s;
    let w = 1.0 - E2 * s2;
    let dg0 = GAMMA_E
        * (2.0 * K_SOMIGLIANA * s * c / w.sqrt()
            + (1.0 + K_SOMIGLIANA * s2) * E2 * s * c / w.powf(1.5));
    let dfree = 8.0 * F * s * c * h / A;
    dg0 * free_air(lat, h) + gamma0(lat) * dfree
}

/// ∂γ/∂h [1/s²] (negative: the unstable vertical loop).
pub fn gravity_dh(lat: f64, h: f64) -> f64 {
    let s2 = lat.sin().powi(2);
    gamma0(lat) * (-2.0 / A * (1.0 + F + M_RATIO - 2.0 * F * s2) + 6.0 * h / (A * A))
}

/// Earth rate in NED at latitude `lat` [rad] → [rad/s].
pub fn omega_ie_ned(lat: f64) -> nalgebra::Vector3<f64> {
    nalgebra::Vector3::new(OMEGA * lat.cos(), 0.0, -OMEGA * lat.sin())
}

/// Normal gravity vector in NED [m/s²] (down positive).
pub fn gravity_ned(lat: f64, h: f64) -> nalgebra::Vector3<f64> {
    nalgebra::Vector3::new(0.0, 0.0, gravity(lat, h))
}

/// Earth quantities at one latitude [rad] and height [m], for loops that step through many
/// nearby positions: radii plus height, tan and cos of latitude, Earth rate and gravity (NED).
#[derive(Debug, Clone, Copy)]
pub struct LocalEarth {
    /// Latitude [rad].
    pub lat: f64,
    /// Height [m].
    pub h: f64,
    /// R_M + h [m].
    pub rm: f64,
    /// R_N + h [m].
    pub rn: f64,
    /// tan(lat).
    pub tan: f64,
    /// cos(lat).
    pub cos: f64,
    /// 1 / (R_M + h) [1/m].
    pub inv_rm: f64,
    /// 1 / (R_N + h) [1/m].
    pub inv_rn: f64,
    /// 1 / ((R_N + h) cos(lat)) [1/m].
    pub inv_rn_cos: f64,
    /// Earth rate, NED [rad/s].
    pub w_ie: nalgebra::Vector3<f64>,
    /// Gravity, NED [m/s²].
    pub g: nalgebra::Vector3<f64>,
}

impl LocalEarth {
    /// The quantities at (lat, h).
    pub fn new(lat: f64, h: f64) -> LocalEarth {
        let rm = radius_meridian(lat) + h;
        let rn = radius_transverse(lat) + h;
        LocalEarth {
            lat,
            h,
            rm,
            rn,
            tan: lat.tan(),
            cos: lat.cos(),
            inv_rm: 1.0 / rm,
            inv_rn: 1.0 / rn,
            inv_rn_cos: 1.0 / (rn * lat.cos()),
            w_ie: omega_ie_ned(lat),
            g: gravity_ned(lat, h),
        }
    }

    /// Refreshes when latitude moved by more than 1e-9 rad (6 mm) or height by more than 1 mm;
    /// below that the quantities change by less than 1e-11 relative.
    pub fn follow(&mut self, lat: f64, h: f64) {
        if (lat - self.lat).abs() > 1e-9 || (h - self.h).abs() > 1e-3 {
            *self = LocalEarth::new(lat, h);
        }
    }

    /// Transport rate ω_en, NED [rad/s], for NED velocity `v` [m/s].
    pub fn omega_en(&self, v: &nalgebra::Vector3<f64>) -> nalgebra::Vector3<f64> {
        nalgebra::Vector3::new(
            v.y * self.inv_rn,
            -v.x * self.inv_rm,
            -v.y * self.tan * self.inv_rn,
        )
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn lon_difference_is_the_shorter_way_round() {
        let d = std::f64::consts::PI / 180.0;
        assert!((super::lon_difference(179.9 * d, -179.9 * d) + 0.2 * d).abs() < 1e-12);
        assert!((super::lon_difference(-179.9 * d, 179.9 * d) - 0.2 * d).abs() < 1e-12);
        // within half a turn: the plain difference, to the last bit
        let (a, b) = (1.234_567_891, -0.987_654_321);
        assert_eq!(super::lon_difference(a, b).to_bits(), (a - b).to_bits());
    }

    use super::*;

    #[test]
    fn known_values() {
        // Normal gravity at the equator and the pole, sea level.
        assert!((gravity(0.0, 0.0) - GAMMA_E).abs() < 1e-12);
        assert!((gravity(std::f64::consts::FRAC_PI_2, 0.0) - GAMMA_P).abs() < 1e-9);
        // Free-air gradient ≈ -3.086e-6 /s² at mid latitude.
        assert!((gravity_dh(0.78, 0.0) + 3.086e-6).abs() < 1e-8);
        // Radii at the equator: R_N = a, R_M = a (1 - e²).
        assert!((radius_transverse(0.0) - A).abs() < 1e-6);
        assert!((radius_meridian(0.0) - A * (1.0 - E2)).abs() < 1e-6);
    }

    #[test]
    fn derivatives_match_finite_differences() {
        for &(lat, h) in &[(0.3, 100.0), (-1.1, 5000.0), (0.9, -50.0)] {
            let d = 1e-6;
            let fd_lat = (gravity(lat + d, h) - gravity(lat - d, h)) / (2.0 * d);
            assert!(
                (fd_lat - gravity_dlat(lat, h)).abs() < 1e-8,
                "{fd_lat} {}",
                gravity_dlat(lat, h)
            );
            let fd_h = (gravity(lat, h + 1.0) - gravity(lat, h - 1.0)) / 2.0;
            assert!((fd_h - gravity_dh(lat, h)).abs() < 1e-12);
        }
    }
}
