//! Strapdown navigator on IMU increments (Δθ, Δv) at the IMU rate, NED frame, WGS-84.
//!
//! Algorithm (Savage's two-speed structure reduced to one speed, as in PSINS and KF-GINS):
//! - attitude: rotation vector φ = Δθ_k + (1/12) Δθ_{k−1} × Δθ_k (two-sample coning correction
//!   using the previous sample), quaternion update q_k = q(−ζ) ⊗ q_{k−1} ⊗ q(φ) with
//!   ζ = ω_in^n T the navigation-frame rotation, renormalised every step;
//! - velocity: Δv + ½ Δθ × Δv (rotation) + (1/12)(Δθ_{k−1} × Δv_k + Δv_{k−1} × Δθ_k) (sculling),
//!   rotated by (I − ½[ζ×]) C_{k−1}, plus (g − (2ω_ie + ω_en) × v) T;
//! - position: trapezoidal integration of latitude, longitude and height;
//! - ω_ie, ω_en, g at the mid-interval, extrapolated from the last two steps.
//!
//! The vertical channel is `fixed` by default (height held, v_D = 0, as in the paper's model),
//! `free` (pure inertial, unstable with time constant √(R/2g) ≈ 9.5 min), or `damped` (a
//! second-order loop pulling height to the initial height with 100 s time constant).

use crate::nav::attitude::euler_from_dcm;
use crate::nav::earth;
use nalgebra::{Matrix3, UnitQuaternion, Vector3};

/// How the navigator treats height.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Vertical {
    /// Height held at its initial value, v_D = 0.
    Fixed,
    /// Height pulled to the initial height by a second-order loop (τ = 100 s).
    Damped,
    /// Pure inertial (unstable).
    Free,
}

impl Vertical {
    /// The command line's word for the mode (`fixed`, `damped`, `free`).
    pub fn word(self) -> &'static str {
        match self {
            Vertical::Fixed => "fixed",
            Vertical::Damped => "damped",
            Vertical::Free => "free",
        }
    }
}

impl std::str::FromStr for Vertical {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "fixed" => Ok(Vertical::Fixed),
            "damped" => Ok(Vertical::Damped),
            "free" => Ok(Vertical::Free),
            _ => Err(format!("unknown vertical mode `{s}` (fixed, damped, free)")),
        }
    }
}

/// Navigation state.
#[derive(Debug, Clone, Copy)]
pub struct NavState {
    /// Time [s].
    pub t: f64,
    /// Latitude [rad].
    pub lat: f64,
    /// Longitude [rad].
    pub lon: f64,
    /// Height [m].
    pub h: f64,
    /// NED velocity [m/s].
    pub v: Vector3<f64>,
    /// C_b^n as a unit quaternion.
    pub q: UnitQuaternion<f64>,
}

impl NavState {
    /// C_b^n.
    pub fn dcm(&self) -> Matrix3<f64> {
        *self.q.to_rotation_matrix().matrix()
    }

    /// Roll, pitch, yaw [rad].
    pub fn euler(&self) -> Vector3<f64> {
        euler_from_dcm(&self.dcm())
    }
}

/// The strapdown navigator.
#[derive(Debug, Clone)]
pub struct Navigator {
    /// Current state.
    pub state: NavState,
    vertical: Vertical,
    h_ref: f64,
    prev_dtheta: Vector3<f64>,
    prev_dv: Vector3<f64>,
    prev_v: Vector3<f64>,
    prev_lat: f64,
    prev_h: f64,
    damp_int: f64,
    earth: earth::LocalEarth,
}

const DAMP_TAU: f64 = 100.0;

impl Navigator {
    /// Starts at a state; the first step has no previous increments (zero coning/sculling terms).
    pub fn new(state: NavState, vertical: Vertical) -> Navigator {
        Navigator {
            state,
            vertical,
            h_ref: state.h,
            prev_dtheta: Vector3::zeros(),
            prev_dv: Vector3::zeros(),
            prev_v: state.v,
            prev_lat: state.lat,
            prev_h: state.h,
            damp_int: 0.0,
            earth: earth::LocalEarth::new(state.lat, state.h),
        }
    }

    /// Advances by one IMU sample with increments Δθ [rad], Δv [m/s] over `dt` [s].
    pub fn step(&mut self, dtheta: &Vector3<f64>, dv: &Vector3<f64>, dt: f64) {
        let s = self.state;
        let lat_mid = s.lat + 0.5 * (s.lat - self.prev_lat);
        let h_mid = s.h + 0.5 * (s.h - self.prev_h);
        let v_mid = s.v + 0.5 * (s.v - self.prev_v);
        self.earth.follow(lat_mid, h_mid);
        let e = self.earth;
        let w_ie = e.w_ie;
        let w_en = e.omega_en(&v_mid);
        let zeta = (w_ie + w_en) * dt;
        let g = e.g;

        // velocity
        let dv_rot = 0.5 * dtheta.cross(dv);
        let dv_scul = (self.prev_dtheta.cross(dv) + self.prev_dv.cross(dtheta)) / 12.0;
        // (I − ½[ζ×]) C_{k−1} (Δv + rotation + sculling), with the skew product as a cross product
        let u = s.q * (dv + dv_rot + dv_scul);
        let dv_sf = u - 0.5 * zeta.cross(&u);
        let dv_gcor = (g - (2.0 * w_ie + w_en).cross(&v_mid)) * dt;
        let mut v_new = s.v + dv_sf + dv_gcor;

        // vertical channel
        let mut h_new = s.h;
        match self.vertical {
            Vertical::Fixed => v_new.z = 0.0,
            Vertical::Free => h_new = s.h - 0.5 * (s.v.z + v_new.z) * dt,
            Vertical::Damped => {
                let err = s.h - self.h_ref;
                self.damp_int += err * dt;
                v_new.z += (3.0 / (DAMP_TAU * DAMP_TAU)) * err * dt
                    + (1.0 / DAMP_TAU.powi(3)) * self.damp_int * dt;
                h_new = s.h - 0.5 * (s.v.z + v_new.z) * dt - (3.0 / DAMP_TAU) * err * dt;
            }
        }

        // position (trapezoid, radii at mid-interval)
        let v_avg = 0.5 * (s.v + v_new);
        let lat_new = s.lat + v_avg.x * e.inv_rm * dt;
        let lon_new = s.lon + v_avg.y * e.inv_rn_cos * dt;

        // attitude
        let phi = dtheta + self.prev_dtheta.cross(dtheta) / 12.0;
        let mut q = rotation_quaternion(&-zeta) * s.q * rotation_quaternion(&phi);
        q.renormalize();

        self.prev_dtheta = *dtheta;
        self.prev_dv = *dv;
        self.prev_v = s.v;
        self.prev_lat = s.lat;
        self.prev_h = s.h;
        self.state = NavState {
            t: s.t + dt,
            lat: lat_new,
            lon: lon_new,
            h: h_new,
            v: v_new,
            q,
        };
    }
}

/// Unit quaternion of a rotation vector; for |φ| < 0.01 rad (every IMU-rate increment) the
/// half-angle sine and cosine come from their series to φ⁴ (truncation error < 2e-17).
pub fn rotation_quaternion(phi: &Vector3<f64>) -> UnitQuaternion<f64> {
    let x2 = phi.norm_squared();
    if x2 < 1e-4 {
        let c = 1.0 - x2 / 8.0 + x2 * x2 / 384.0;
        let s = 0.5 - x2 / 48.0 + x2 * x2 / 3840.0;
        UnitQuaternion::new_unchecked(nalgebra::Quaternion::new(
            c,
            s * phi.x,
            s * phi.y,
            s * phi.z,
        ))
    } else {
        UnitQuaternion::from_scaled_axis(*phi)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rotation_quaternion_series_matches_the_exact_formula() {
        for &a in &[1e-9, 1e-6, 1e-3, 9.9e-3, 0.02, 0.5] {
            let phi = Vector3::new(0.3, -0.5, 0.81).normalize() * a;
            let q = rotation_quaternion(&phi);
            let e = UnitQuaternion::from_scaled_axis(phi);
            assert!(
                (q.coords - e.coords).norm() < 3e-16, // series truncation < 2e-17; plus 1-ulp rounding of either formula
                "{a}: {}",
                (q.coords - e.coords).norm()
            );
        }
    }
}
