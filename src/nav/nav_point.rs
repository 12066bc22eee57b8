//! The navigation quantities A(t) and H are evaluated at (DESIGN §4): position, velocity,
//! attitude and specific force, with the WGS-84 radii frozen at the point.

use crate::nav::earth;
use nalgebra::{Matrix3, Vector3};

/// A linearisation point: every symbol the spec's A and H expressions may use.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NavPoint {
    /// Geodetic latitude [rad].
    pub lat: f64,
    /// Height above the ellipsoid, up [m].
    pub h: f64,
    /// Velocity, NED [m/s].
    pub v_ned: [f64; 3],
    /// R_M + h [m].
    pub rm: f64,
    /// R_N + h [m].
    pub rn: f64,
    /// Earth rotation rate [rad/s].
    pub omega: f64,
    /// Specific force in NED, C f^b [m/s²].
    pub f_ned: [f64; 3],
    /// C_b^n, row-major.
    pub c: [[f64; 3]; 3],
    /// ∂γ/∂lat [m/s²/rad].
    pub dg_dlat: f64,
    /// ∂γ/∂h [1/s²].
    pub dg_dh: f64,
    /// Body angular rate w^b_ib, FRD [rad/s] (the step mean; zero until set with
    /// [`NavPoint::set_rate`]).
    pub w_b: [f64; 3],
    /// Acceleration of the navigation solution in NED, dv/dt over the last second [m/s²] (zero
    /// until set with [`NavPoint::set_acceleration`]): smooth where the specific force
    /// vibrates.
    pub a_ned: [f64; 3],
    /// Acceleration of the navigation solution in NED over the last filter step, dv/dt [m/s²]
    /// (zero until set with [`NavPoint::set_step_acceleration`]): prompt, not smoothed.
    pub a_step: [f64; 3],
}

impl NavPoint {
    /// Moves the point to a new navigation state, recomputing the radii and gravity derivatives
    /// only when latitude changed by more than 1e-9 rad (6 mm) or height by more than 1 mm
    /// (their change below that is under 1e-11 relative).
    pub fn update(
        &mut self,
        lat: f64,
        h: f64,
        v_ned: Vector3<f64>,
        c_bn: &Matrix3<f64>,
        f_b: &Vector3<f64>,
    ) {
        if (lat - self.lat).abs() > 1e-9 || (h - self.h).abs() > 1e-3 {
            let (w_b, a_ned, a_step) = (self.w_b, self.a_ned, self.a_step);
            *self = NavPoint::new(lat, h, v_ned, c_bn, f_b);
            (self.w_b, self.a_ned, self.a_step) = (w_b, a_ned, a_step);
            return;
        }
        let f_n = c_bn * f_b;
        self.v_ned = [v_ned.x, v_ned.y, v_ned.z];
        self.f_ned = [f_n.x, f_n.y, f_n.z];
        for (i, row) in self.c.iter_mut().enumerate() {
            for (j, v) in row.iter_mut().enumerate() {
                *v = c_bn[(i, j)];
            }
        }
    }

    /// Builds the point from latitude [rad], height [m], NED velocity [m/s], C_b^n and the
    /// body-frame specific force f^b [m/s²].
    pub fn new(
        lat: f64,
        h: f64,
        v_ned: Vector3<f64>,
        c_bn: &Matrix3<f64>,
        f_b: &Vector3<f64>,
    ) -> NavPoint {
        let f_n = c_bn * f_b;
        let mut c = [[0.0; 3]; 3];
        for (i, row) in c.iter_mut().enumerate() {
            for (j, v) in row.iter_mut().enumerate() {
                *v = c_bn[(i, j)];
            }
        }
        NavPoint {
            lat,
            h,
            v_ned: [v_ned.x, v_ned.y, v_ned.z],
            rm: earth::radius_meridian(lat) + h,
            rn: earth::radius_transverse(lat) + h,
            omega: earth::OMEGA,
            f_ned: [f_n.x, f_n.y, f_n.z],
            c,
            dg_dlat: earth::gravity_dlat(lat, h),
            dg_dh: earth::gravity_dh(lat, h),
            w_b: [0.0; 3],
            a_ned: [0.0; 3],
            a_step: [0.0; 3],
        }
    }

    /// Sets the navigation-frame acceleration a [m/s²] (NED, dv/dt over the last second) the
    /// point's H entries may use.
    pub fn set_acceleration(&mut self, a: &Vector3<f64>) {
        self.a_ned = [a.x, a.y, a.z];
    }

    /// Sets the navigation-frame acceleration over the last filter step [m/s²] (NED, dv/dt)
    /// the point's H entries may use.
    pub fn set_step_acceleration(&mut self, a: &Vector3<f64>) {
        self.a_step = [a.x, a.y, a.z];
    }

    /// Sets the body angular rate w^b_ib [rad/s] (FRD) the point's H entries may use.
    pub fn set_rate(&mut self, w_b: &Vector3<f64>) {
        self.w_b = [w_b.x, w_b.y, w_b.z];
    }
}

/// Velocities of the last second, for the acceleration dv/dt over it.
#[derive(Debug, Clone, Default)]
pub struct AccelWindow {
    /// (t [s], NED velocity [m/s]), oldest first.
    past: std::collections::VecDeque<(f64, Vector3<f64>)>,
}

impl AccelWindow {
    /// Width of the window [s].
    pub const SECONDS: f64 = 1.0;

    /// Adds the velocity `v` [m/s] at `t` [s]; returns dv/dt [m/s²] over the last
    /// [`AccelWindow::SECONDS`] (over what there is at the start; zero for a single sample).
    pub fn push(&mut self, t: f64, v: Vector3<f64>) -> Vector3<f64> {
        self.past.push_back((t, v));
        while self.past.len() > 2 && self.past[1].0 <= t - Self::SECONDS {
            self.past.pop_front();
        }
        let (t0, v0) = self.past[0];
        if t > t0 {
            (v - v0) / (t - t0)
        } else {
            Vector3::zeros()
        }
    }
}
