//! Attitude conventions: C = C_b^n (FRD body to NED), Euler angles roll φ, pitch θ, yaw ψ with
//! C = Rz(ψ)·Ry(θ)·Rx(φ), and the attitude error φ defined by C̃ = (I − [φ×]) C (DESIGN §1).

use nalgebra::{Matrix3, Vector3};

/// C_b^n from roll, pitch, yaw [rad] (C = Rz(yaw)·Ry(pitch)·Rx(roll)).
pub fn dcm_from_euler(roll: f64, pitch: f64, yaw: f64) -> Matrix3<f64> {
    let (sr, cr) = roll.sin_cos();
    let (sp, cp) = pitch.sin_cos();
    let (sy, cy) = yaw.sin_cos();
    let rz = Matrix3::new(cy, -sy, 0.0, sy, cy, 0.0, 0.0, 0.0, 1.0);
    let ry = Matrix3::new(cp, 0.0, sp, 0.0, 1.0, 0.0, -sp, 0.0, cp);
    let rx = Matrix3::new(1.0, 0.0, 0.0, 0.0, cr, -sr, 0.0, sr, cr);
    rz * ry * rx
}

/// Roll, pitch, yaw [rad] of C_b^n (inverse of [`dcm_from_euler`], pitch in [−π/2, π/2]).
pub fn euler_from_dcm(c: &Matrix3<f64>) -> Vector3<f64> {
    let pitch = (-c[(2, 0)]).clamp(-1.0, 1.0).asin();
    let roll = c[(2, 1)].atan2(c[(2, 2)]);
    let yaw = c[(1, 0)].atan2(c[(0, 0)]);
    Vector3::new(roll, pitch, yaw)
}

/// Skew-symmetric matrix [v×] such that [v×] u = v × u.
pub fn skew(v: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -v.z, v.y, v.z, 0.0, -v.x, -v.y, v.x, 0.0)
}

/// Attitude error φ [rad] of a computed DCM against the truth: E = C̃ Cᵀ,
/// φ = ½ [E₂₃ − E₃₂, E₃₁ − E₁₃, E₁₂ − E₂₁] (DESIGN §1).
pub fn attitude_error(c_computed: &Matrix3<f64>, c_true: &Matrix3<f64>) -> Vector3<f64> {
    let e = c_computed * c_true.transpose();
    0.5 * Vector3::new(
        e[(1, 2)] - e[(2, 1)],
        e[(2, 0)] - e[(0, 2)],
        e[(0, 1)] - e[(1, 0)],
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn euler_round_trip_and_error_sign() {
        let c = dcm_from_euler(0.1, -0.2, 2.5);
        let e = euler_from_dcm(&c);
        assert!((e - Vector3::new(0.1, -0.2, 2.5)).norm() < 1e-12);
        // Level IMU at yaw 0: phi = -(Euler error) (DESIGN §1).
        let truth = dcm_from_euler(0.0, 0.0, 0.0);
        let computed = dcm_from_euler(1e-4, 0.0, 0.0);
        let phi = attitude_error(&computed, &truth);
        assert!((phi.x + 1e-4).abs() < 1e-10, "{phi}");
        // C~ = (I - [phi x]) C reproduces phi.
        let phi0 = Vector3::new(1e-5, -2e-5, 3e-5);
        let c2 = (Matrix3::identity() - skew(&phi0)) * c;
        assert!((attitude_error(&c2, &c) - phi0).norm() < 1e-15);
    }
}
