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
/// rate): the start row at `t0`, then a row at the first sample at or after each `t0 + k/rate`
/// (k = 1, 2, …), within half a sample interval. The grid is counted from `t0` itself, so an
/// absolute clock (GPS seconds) gives the same rows as a clock that starts at 0.
pub struct RowClock {
    t0: f64,
    period: f64,
    n: u64,
    tol: f64,
    /// The rate asked for [Hz] when it is above the IMU's sample rate (rows at every sample).
    capped_hz: Option<f64>,
    interval: f64,
}

impl RowClock {
    /// Rows at `rate_hz` from `t0` [s]; every sample when `rate_hz` is None; `interval` [s] is
    /// the median sample interval. A rate above the sample rate gives a row at every sample
    /// ([`RowClock::capped_note`] says so).
    pub fn new(t0: f64, rate_hz: Option<f64>, interval: f64) -> RowClock {
        let period = rate_hz.map(|r| 1.0 / r).unwrap_or(0.0);
        // a rate above the IMU's (beyond a jittered clock's slack) cannot be met
        let capped_hz = rate_hz.filter(|_| period > 0.0 && period < 0.99 * interval);
        RowClock {
            t0,
            period: if capped_hz.is_some() { 0.0 } else { period },
            n: 0,
            tol: 0.5 * interval,
            capped_hz,
            interval,
        }
    }

    /// Whether the sample at `t` [s] gets a row (the first call, at the start, always does).
    pub fn due(&mut self, t: f64) -> bool {
        if self.period == 0.0 {
            return true;
        }
        // counted from t0: an absolute clock's size must not widen the tolerance; a relative
        // 1e-9 of the elapsed time (and the rounding of t itself) so that a sample exactly at a
        // threshold counts on either rounding
        let rel = t - self.t0;
        let eps = 1e-9 * rel.abs().max(1.0) + 4.0 * f64::EPSILON * t.abs();
        let threshold = |n: u64| n as f64 * self.period - self.tol;
        if rel + eps < threshold(self.n) {
            return false;
        }
        while threshold(self.n) <= rel + eps {
            self.n += 1;
        }
        true
    }

    /// With a rate above the IMU's sample rate: the note that rows come at every sample
    /// instead (`option` names the rate's option).
    pub fn capped_note(&self, option: &str) -> Option<String> {
        self.capped_hz.map(|r| {
            format!(
                "{option} {}: above the IMU's sample rate ({} Hz); a row at every IMU sample instead",
                crate::io::units::shown_number(r),
                crate::io::units::sig3(1.0 / self.interval)
            )
        })
    }

    /// The row spacing in words, for file headers.
    pub fn words(&self) -> String {
        if self.period == 0.0 {
            "a row at the start and at every IMU sample".to_string()
        } else {
            format!(
                "a row at the start and every {} s after it (at the first IMU sample at or after each)",
                self.period
            )
        }
    }
}

/// `rate_hz` given to `option` (`--nav-rate`) checked: positive, finite, at most 1e5 Hz.
pub fn check_rate(option: &str, rate_hz: f64) -> Result<()> {
    let shown = crate::io::units::shown_number(rate_hz);
    if rate_hz.is_nan() || rate_hz <= 0.0 {
        bail!("{option} {shown}: must be positive (Hz)");
    }
    if !(rate_hz.is_finite() && rate_hz <= 1e5) {
        bail!("{option} {shown}: expected a rate in (0, 1e5] Hz");
    }
    Ok(())
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
    // the start row (the clock's first call is always due)
    if clock.due(t0) {
        row(&nav.state)?;
    }
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The rows' times at `rate` [Hz] over `secs` of samples at 100 Hz from `t0` [s].
    fn rows(t0: f64, rate: Option<f64>, secs: f64) -> Vec<f64> {
        let mut c = RowClock::new(t0, rate, 0.01);
        let n = (secs * 100.0).round() as u64;
        (0..=n)
            .map(|k| t0 + k as f64 * 0.01)
            .filter(|&t| c.due(t))
            .map(|t| t - t0)
            .collect()
    }

    /// The grid is anchored at the start on an absolute clock as on one from 0 (it was 98.25 s
    /// to the first row at 0.01 Hz on GPS seconds), and the start row is always written.
    #[test]
    fn rows_start_at_the_start_on_any_clock() {
        for t0 in [0.0, 1_436_000_000.0, 1_751_000_000.25] {
            let r = rows(t0, Some(0.01), 250.0);
            assert_eq!(r.len(), 3, "{t0}: {r:?}");
            for (k, t) in r.iter().enumerate() {
                assert!((t - 100.0 * k as f64).abs() < 1e-5, "{t0}: {r:?}");
            }
            let r = rows(t0, Some(3.0), 10.0);
            assert_eq!(r.len(), 31, "{t0}: start + 30 rows");
            assert!(
                r.windows(2)
                    .all(|w| (w[1] - w[0] - 1.0 / 3.0).abs() < 0.0101),
                "{r:?}"
            );
        }
        // longer than the run: the start row only
        assert_eq!(rows(1.7e9, Some(0.001), 60.0), vec![0.0]);
    }

    #[test]
    fn a_rate_above_the_imu_rate_is_capped_and_said() {
        let c = RowClock::new(0.0, Some(1000.0), 0.01);
        let note = c.capped_note("--nav-rate").unwrap();
        assert!(
            note.contains("--nav-rate 1000") && note.contains("100 Hz"),
            "{note}"
        );
        assert_eq!(rows(0.0, Some(1000.0), 1.0).len(), 101);
        assert!(RowClock::new(0.0, Some(100.0), 0.01)
            .capped_note("x")
            .is_none());
        assert!(RowClock::new(0.0, None, 0.01).capped_note("x").is_none());
        let e = check_rate("--nav-rate", -5.0).unwrap_err().to_string();
        assert_eq!(e, "--nav-rate -5: must be positive (Hz)");
        assert!(check_rate("--nav-rate", 2e5).is_err() && check_rate("--nav-rate", 1e5).is_ok());
    }
}
