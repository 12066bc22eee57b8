//! Whether an IMU–GNSS time offset of a given size is what dt_gnss's H describes. Its position
//! rows move a fix by v·dt, v the navigation's velocity at the fix. That is the body's motion
//! only where the navigation's velocity is (in open loop it carries the free navigation's drift,
//! which on a vehicle at rest is all of it), and it is the displacement over the offset only
//! while the velocity holds over it (not where the fixes sample a faster motion, such as a
//! vibration's velocity at one phase). Beyond either, a fitted "offset" stands in for whatever
//! else its signature takes up.

use crate::estimate::filter::Observer;
use crate::model::Model;
use crate::nav::nav_point::NavPoint;
use crate::nav::strapdown::NavState;
use std::collections::VecDeque;

/// Offsets [s] the velocity is compared at: its mean over each, before the fix.
const SPANS_S: [f64; 8] = [0.005, 0.01, 0.02, 0.05, 0.1, 0.2, 0.5, 1.0];

/// The relative error of v·dt beyond which the first-order offset is no description of the
/// motion: the velocity at the fixes differs from its mean over the offset by half its size.
pub(super) const MAX_RELATIVE_ERROR: f64 = 0.5;

/// The share of the navigation's velocity at the fixes (RMS) that its own error may be before
/// dt_gnss's H, built on that velocity, no longer follows the body's motion.
pub(super) const MAX_DRIFT_SHARE: f64 = 0.5;

/// Watches a pass: at every position fix, the navigation's velocity there, its error estimate,
/// and the corrected velocity against its mean over each of [`SPANS_S`] before the fix (from the
/// velocity at the end of each filter step).
#[derive(Debug, Clone, Default)]
pub(super) struct OffsetOrder {
    /// The model's velocity-error states dv_n, dv_e, dv_d (none: not in the model).
    dv: [Option<usize>; 3],
    /// The latest velocity-error estimate [m/s] (computed − true).
    dv_hat: [f64; 3],
    /// The last second of step ends: (time [s], corrected NED velocity [m/s]).
    recent: VecDeque<(f64, [f64; 3])>,
    /// The navigation's velocity at the last step end [m/s].
    v_nav: [f64; 3],
    /// Σ |v_nav|² and Σ |dv̂|² over the fixes [m²/s²].
    drift: (f64, f64),
    /// Per span: Σ |v − v̄|² over the fixes [m²/s²].
    error: [f64; SPANS_S.len()],
    /// Per span: Σ |v|² over the same fixes [m²/s²].
    size: [f64; SPANS_S.len()],
    /// Per span: the fixes compared.
    fixes: [usize; SPANS_S.len()],
}

impl Observer for OffsetOrder {
    fn nav_sample(&mut self, _s: &NavState, x: &[f64], _p: &[f64]) {
        for (d, i) in self.dv_hat.iter_mut().zip(self.dv) {
            *d = i.map_or(0.0, |i| x[i]);
        }
    }

    fn step(&mut self, t: f64, _dt: f64, np: &NavPoint, _a: &[f64], _p: &[(usize, usize)]) {
        self.v_nav = np.v_ned;
        let v = [0, 1, 2].map(|j| np.v_ned[j] - self.dv_hat[j]);
        self.recent.push_back((t, v));
        let oldest = t - SPANS_S[SPANS_S.len() - 1] - 0.05;
        while self.recent.front().is_some_and(|&(s, _)| s < oldest) {
            self.recent.pop_front();
        }
    }

    fn scalar_update(
        &mut self,
        _t: f64,
        meas: &'static str,
        component: usize,
        _h: &[f64],
        _k: &[f64],
        _nu: f64,
        _s: f64,
    ) {
        // once per position fix (its first component), at the step that ends at the fix
        if meas != "pos_ne" || component != 0 {
            return;
        }
        let Some(&(t, v)) = self.recent.back() else {
            return;
        };
        self.drift.0 += self.v_nav.iter().map(|x| x * x).sum::<f64>();
        self.drift.1 += self.dv_hat.iter().map(|x| x * x).sum::<f64>();
        let first = self.recent.front().map_or(t, |x| x.0);
        let size = v.iter().map(|x| x * x).sum::<f64>();
        // one walk back through the history, the spans shortest first: a span's mean is complete
        // once the walk passes its start (a span the history does not reach back over is left out)
        let (mut sum, mut n) = ([0.0; 3], 0usize);
        let mut walk = self.recent.iter().rev().peekable();
        for (k, &span) in SPANS_S.iter().enumerate() {
            while let Some((_, u)) = walk.next_if(|x| x.0 >= t - span - 1e-9) {
                for j in 0..3 {
                    sum[j] += u[j];
                }
                n += 1;
            }
            if t - first < span - 1e-9 {
                break;
            }
            let m = n.max(1) as f64;
            self.error[k] += (0..3).map(|j| (v[j] - sum[j] / m).powi(2)).sum::<f64>();
            self.size[k] += size;
            self.fixes[k] += 1;
        }
    }
}

impl OffsetOrder {
    /// A watcher for a pass of `model`.
    pub(super) fn new(model: &Model) -> OffsetOrder {
        OffsetOrder {
            dv: ["dv_n", "dv_e", "dv_d"].map(|n| model.index_of(n)),
            ..Default::default()
        }
    }

    /// The RMS of the navigation's velocity-error estimate at the fixes relative to the RMS of
    /// its velocity there; None without fixes or velocity.
    pub(super) fn drift_share(&self) -> Option<f64> {
        (self.drift.0 > 0.0).then(|| (self.drift.1 / self.drift.0).sqrt())
    }

    /// The RMS of the velocity at the fixes less its mean over `dt` [s] before them, relative to
    /// the RMS of the velocity (interpolated between the spans compared, linearly in the
    /// logarithm of the span; the shortest span's below it); None without fixes or motion, or
    /// when `dt` is beyond the longest span compared.
    pub(super) fn relative_error(&self, dt: f64) -> Option<f64> {
        let at = |k: usize| {
            (self.fixes[k] > 0 && self.size[k] > 0.0).then(|| (self.error[k] / self.size[k]).sqrt())
        };
        let dt = dt.abs();
        let hi = SPANS_S.iter().position(|&s| s >= dt)?;
        if hi == 0 {
            return at(0);
        }
        let (a, b) = (at(hi - 1)?, at(hi)?);
        let w = (dt.ln() - SPANS_S[hi - 1].ln()) / (SPANS_S[hi].ln() - SPANS_S[hi - 1].ln());
        Some(a + w * (b - a))
    }

    /// Why a fitted time offset of `dt` [s] is no offset the data show: the navigation's
    /// velocity at the fixes is mostly its own error, or the first-order model does not hold at
    /// the offset's size; None when both hold or cannot be judged.
    pub(super) fn stand_in_words(&self, dt: f64) -> Option<String> {
        if let Some(d) = self.drift_share().filter(|&d| d > MAX_DRIFT_SHARE) {
            return Some(format!(
                "the navigation's velocity at the fixes is mostly its own error (the filter's velocity-error estimate is {} % of it, RMS): dt_gnss's H (a fix moved by v·dt, v the navigation's velocity) follows the free navigation's drift, not the body's motion, and the fit stands in for the drift's misfit (in closed loop, --mode closed, the velocity is corrected at every fix)",
                super::words::sig3(100.0 * d)
            ));
        }
        let e = self.relative_error(dt)?;
        (e > MAX_RELATIVE_ERROR).then(|| {
            format!(
                "at {} ms the velocity at the fixes is no motion over the offset: it differs from its own mean over those {} ms by {} % RMS (the fixes sample a motion faster than the offset, such as a vibration), so dt_gnss's first-order H (a fix moved by v·dt) does not describe an offset of this size and the fit stands in for something else",
                super::words::sig3(dt * 1e3),
                super::words::sig3(dt.abs() * 1e3),
                super::words::sig3(100.0 * e)
            )
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn np(v: [f64; 3]) -> NavPoint {
        let mut p = NavPoint::new(
            0.6,
            100.0,
            nalgebra::Vector3::from(v),
            &nalgebra::Matrix3::identity(),
            &nalgebra::Vector3::zeros(),
        );
        p.v_ned = v;
        p
    }

    /// 100-Hz steps, a position fix every second; `v(t)` the velocity at the step ends.
    fn watch(v: &dyn Fn(f64) -> [f64; 3]) -> OffsetOrder {
        let mut o = OffsetOrder::default();
        for k in 1..=6000 {
            let t = k as f64 * 0.01;
            o.step(t, 0.01, &np(v(t)), &[], &[]);
            if k % 100 == 0 {
                o.scalar_update(t, "pos_ne", 0, &[], &[], 0.0, 1.0);
                o.scalar_update(t, "pos_ne", 1, &[], &[], 0.0, 1.0);
                o.scalar_update(t, "vel_ne", 0, &[], &[], 0.0, 1.0);
            }
        }
        o
    }

    #[test]
    fn a_vehicle_holds_its_velocity_over_an_offset_and_a_vibration_does_not() {
        // a car at 15 m/s accelerating by ±2 m/s² and turning: v·dt holds up to a second
        let car = watch(&|t: f64| {
            let s = 15.0 + 2.0 * (t / 10.0).sin() * 5.0;
            let yaw = 0.1 * t;
            [s * yaw.cos(), s * yaw.sin(), 0.0]
        });
        for dt in [0.005, 0.05, 0.2, 1.0] {
            let e = car.relative_error(dt).unwrap();
            assert!(e < 0.1, "{dt}: {e}");
            assert!(car.stand_in_words(dt).is_none());
        }
        // at rest on a table vibrating at 31 Hz along z (0.3 m/s velocity amplitude): the
        // fixes see its velocity at one phase; over 5 ms it holds, over 100 ms it is noise
        let table = watch(&|t: f64| {
            [
                0.0,
                0.0,
                0.3 * (2.0 * std::f64::consts::PI * 31.0 * t + 0.7).sin(),
            ]
        });
        assert!(table.relative_error(0.1).unwrap() > 0.9);
        let words = table.stand_in_words(-0.199).expect("a stand-in at 199 ms");
        assert!(words.starts_with("at -199 ms the velocity"), "{words}");
        // beyond the longest span, or without fixes: no judgement
        assert!(table.relative_error(2.0).is_none());
        assert!(OffsetOrder::default().relative_error(0.1).is_none());
        assert!(OffsetOrder::default().drift_share().is_none());
    }

    #[test]
    fn an_offset_fitted_to_the_free_navigations_drift_is_a_stand_in() {
        // at rest in open loop: the navigation drifts to 1.5 m/s down and the filter's
        // velocity-error estimate holds nearly all of it
        let model = Model::parse("P13+vertical").unwrap();
        let i = model.index_of("dv_d").unwrap();
        let mut o = OffsetOrder::new(&model);
        let mut x = vec![0.0; model.n()];
        let s = NavState {
            t: 0.0,
            lat: 0.6,
            lon: 0.1,
            h: 0.0,
            v: nalgebra::Vector3::zeros(),
            q: nalgebra::UnitQuaternion::identity(),
        };
        for k in 1..=6000 {
            let t = k as f64 * 0.01;
            let drift = 1.5 * t / 60.0;
            x[i] = 0.97 * drift;
            o.nav_sample(&s, &x, &[]);
            o.step(t, 0.01, &np([0.0, 0.0, drift]), &[], &[]);
            if k % 100 == 0 {
                o.scalar_update(t, "pos_ne", 0, &[], &[], 0.0, 1.0);
            }
        }
        assert!((o.drift_share().unwrap() - 0.97).abs() < 1e-9);
        let words = o.stand_in_words(-0.2).expect("a stand-in");
        assert!(words.contains("mostly its own error"), "{words}");
        // the same drift beside a car's 15 m/s: the motion dominates
        let mut car = OffsetOrder::new(&model);
        for k in 1..=6000 {
            let t = k as f64 * 0.01;
            x[i] = 0.97 * 1.5 * t / 60.0;
            car.nav_sample(&s, &x, &[]);
            car.step(t, 0.01, &np([15.0, 0.0, 1.5 * t / 60.0]), &[], &[]);
            if k % 100 == 0 {
                car.scalar_update(t, "pos_ne", 0, &[], &[], 0.0, 1.0);
            }
        }
        assert!(car.drift_share().unwrap() < 0.1);
        assert!(car.stand_in_words(-0.2).is_none());
    }
}
