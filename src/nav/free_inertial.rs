//! Free-inertial navigation of an IMU stream (`navigate`): the start state from the
//! command line's degrees, the strapdown navigator over the samples with a divergence check,
//! rows at a rate on the samples' own times ([`RowClock`]), and the displacement at the end.
//! No aiding: the drift grows with the initial attitude and sensor errors.

use crate::io::imu_stream::ImuStream;
use crate::nav::attitude::dcm_from_euler;
use crate::nav::earth;
use crate::nav::strapdown::{NavState, Navigator, Vertical};
use anyhow::{bail, Result};
use nalgebra::{Rotation3, UnitQuaternion, Vector3};

/// When output rows are due at a rate, on the samples' own times (so a jittered clock keeps the
/// rate): a row at the first sample at or after each multiple of the period from `t0`, within
/// half a sample interval.
pub struct RowClock {
    t0: f64,
    period: f64,
    n: u64,
    tol: f64,
}

impl RowClock {
    /// Rows at `rate_hz` from `t0` [s]; every sample when `rate_hz` is None; `interval` [s] is
    /// the median sample interval.
    pub fn new(t0: f64, rate_hz: Option<f64>, interval: f64) -> RowClock {
        RowClock {
            t0,
            period: rate_hz.map(|r| 1.0 / r).unwrap_or(0.0),
            n: 1,
            tol: 0.5 * interval,
        }
    }

    /// Whether the sample at `t` [s] gets a row.
    pub fn due(&mut self, t: f64) -> bool {
        if self.period == 0.0 {
            return true;
        }
        // a relative 1e-9 so that a sample exactly at a threshold counts on either rounding
        let eps = 1e-9 * t.abs().max(1.0);
        if t + eps < self.t0 + self.n as f64 * self.period - self.tol {
            return false;
        }
        while self.t0 + self.n as f64 * self.period - self.tol <= t + eps {
            self.n += 1;
        }
        true
    }

    /// The row spacing in words, for file headers.
    pub fn words(&self) -> String {
        if self.period == 0.0 {
            "a row at every IMU sample".to_string()
        } else {
            format!(
                "a row every {} s (at the first IMU sample at or after each)",
                self.period
            )
        }
    }
}

/// The start state at `t0` [s]: latitude and longitude [deg], height `h` [m], roll, pitch, yaw
/// `att_deg` [deg] (NED/FRD) and NED velocity `vel` [m/s].
pub fn start_state(
    t0: f64,
    lat_deg: f64,
    lon_deg: f64,
    h: f64,
    att_deg: [f64; 3],
    vel: [f64; 3],
) -> NavState {
    let d = std::f64::consts::PI / 180.0;
    let c = dcm_from_euler(att_deg[0] * d, att_deg[1] * d, att_deg[2] * d);
    NavState {
        t: t0,
        lat: lat_deg * d,
        lon: lon_deg * d,
        h,
        v: Vector3::new(vel[0], vel[1], vel[2]),
        q: UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(c)),
    }
}

/// True when the state is no longer navigation: a non-finite value, a height beyond 1e7 m, a
/// pole (within 0.1° of it; the NED frame is undefined there) or a speed over 1e4 m/s.
pub fn diverged(st: &NavState) -> bool {
    ![st.lat, st.lon, st.h, st.v.x, st.v.y, st.v.z, st.q.w, st.q.i]
        .iter()
        .all(|v| v.is_finite())
        || st.h.abs() > 1e7
        || st.lat.abs() >= 89.9f64.to_radians()
        || st.v.norm() > 1e4
}

/// Navigates the samples of `data` after `start.t` from `start`: `row` hears the start state and
/// every state `clock` makes due, `progress` the fraction of the input read (every 100000
/// samples); `name` is the IMU file in messages. Returns the final state; a divergence is an
/// error naming the time and sample.
pub fn run(
    data: &mut ImuStream,
    start: NavState,
    vertical: Vertical,
    clock: &mut RowClock,
    name: &str,
    row: &mut dyn FnMut(&NavState) -> Result<()>,
    progress: &mut dyn FnMut(f64),
) -> Result<NavState> {
    let t0 = start.t;
    let mut nav = Navigator::new(start, vertical);
    row(&nav.state)?;
    let mut prev_t = t0;
    while let Some(s) = data.next()? {
        if s.t <= t0 {
            // a jittered clock starts at its first sample (`ImuStream::start_time`)
            continue;
        }
        let k = data.count() - 1;
        nav.step(&s.dtheta, &s.dv, s.t - prev_t);
        nav.state.t = s.t;
        if diverged(&nav.state) {
            bail!(
                "{}: the navigation diverged at t = {:.3} s (sample {}): a non-finite state, a pole (the NED frame is undefined there) or a speed over 1e4 m/s; the increments are not physical there \
                 (check the IMU values, units and clock; `sinsmodel imu-check` shows what was read)",
                name,
                s.t,
                k + 1
            );
        }
        prev_t = s.t;
        if clock.due(s.t) {
            row(&nav.state)?;
        }
        if k.is_multiple_of(100_000) {
            progress(data.fraction());
        }
    }
    Ok(nav.state)
}

/// North and east displacement [m] from `s0` to `s1` (on a sphere of the equatorial radius).
pub fn displacement_ne(s0: &NavState, s1: &NavState) -> [f64; 2] {
    let r = earth::A;
    let dn = (s1.lat - s0.lat) * r;
    let de = (s1.lon - s0.lon) * r * s0.lat.cos();
    [dn, de]
}
