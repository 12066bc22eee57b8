//! The aiding clock against the IMU's, from the turns both see: the GNSS course change over
//! each interval between fixes is correlated with the gyros' turn about the measured vertical
//! over the same interval shifted by every lag within ±[`MAX_LAG_S`]. A best lag far from zero,
//! clearly better than zero, says the fixes describe other moments than their stamps say (UTC
//! read as GPST, a late or early aiding file, a wrong `--clock-offset`). The IMU is judged as it
//! streams: memory holds the fixes' intervals and a few seconds of the turn's integral.

use crate::io::aiding::{PositionFix, VelocityFix};
use crate::io::imu::ImuSample;
use nalgebra::Vector3;
use std::collections::VecDeque;

/// Largest clock offset looked for [s] (offsets of an hour or more are refused by the time-span
/// check of the aiding file).
pub const MAX_LAG_S: f64 = 600.0;
/// Step between the lags tried [s].
const LAG_STEP_S: f64 = 0.5;
/// Entry of lag zero.
const ZERO: usize = (MAX_LAG_S / LAG_STEP_S) as usize;
/// Grid of the IMU's turn integral [s].
const GRID_S: f64 = 0.05;
/// Slowest GNSS speed at which a course is taken [m/s] (slower, its noise and a car's
/// sideslip when manoeuvring dominate).
const MIN_COURSE_SPEED: f64 = 3.0;
/// Longest interval between fixes taken [s].
const MAX_INTERVAL_S: f64 = 5.0;
/// Fastest course change taken [rad/s] (faster is an outlier: 90 deg/s at 3 m/s is a 1.9 m
/// radius).
const MAX_COURSE_RATE: f64 = std::f64::consts::FRAC_PI_2;
/// Least course change [rad] (summed over the intervals) before a lag is judged: two 90° turns.
const MIN_TURNED_RAD: f64 = std::f64::consts::PI;
/// Least course change [rad] before an offset is said before the end of the IMU file: eight 90°
/// turns.
const EARLY_TURNED_RAD: f64 = 4.0 * std::f64::consts::PI;
/// Peaks of the correlation closer than this [s] are one.
const PEAK_APART_S: f64 = 3.0;
/// Correlation within which of the best another lag's peak is as good (turns that repeat).
const ALIKE: f64 = 0.05;
/// Least correlation at the best lag for an offset to be refused …
const BEYOND_DOUBT_BEST: f64 = 0.85;
/// … with the stamps' correlation under this.
const BEYOND_DOUBT_STAMPED: f64 = 0.5;
/// Least correlation at the best lag for an offset to be said.
const SAY_CORRELATION: f64 = 0.8;
/// Least margin of the best lag's correlation over the stamped one's for an offset to be said.
const SAY_MARGIN: f64 = 0.3;
/// Least offset said [s] (below it, the time offset is a model term's business, not a slip).
const MIN_OFFSET_S: f64 = 1.0;

/// A GNSS course change: from `t0` to `t1` [s] on the aiding clock the course turned by `dpsi`
/// [rad] (positive clockwise seen from above, as yaw in NED).
#[derive(Debug, Clone, Copy)]
pub struct CourseTurn {
    /// Start of the interval [s].
    pub t0: f64,
    /// End of the interval [s].
    pub t1: f64,
    /// Course change over it [rad].
    pub dpsi: f64,
}

/// Wraps an angle [rad] into (−π, π].
fn wrap(a: f64) -> f64 {
    let w = a.rem_euclid(std::f64::consts::TAU);
    if w > std::f64::consts::PI {
        w - std::f64::consts::TAU
    } else {
        w
    }
}

/// The course changes between consecutive fixes (sorted by time): from their velocities where
/// every fix has one, else from the tracks between neighbouring positions (the course of the
/// track from one fix to the next stands for the time between them). Intervals slower than
/// [`MIN_COURSE_SPEED`], longer than [`MAX_INTERVAL_S`] or turning implausibly fast are left out.
pub fn course_turns(fixes: &[(PositionFix, Option<VelocityFix>)]) -> Vec<CourseTurn> {
    let keep = |t0: f64, t1: f64, dpsi: f64| {
        let dt = t1 - t0;
        (dt > 0.0 && dt <= MAX_INTERVAL_S && dpsi.abs() <= MAX_COURSE_RATE * dt)
            .then_some(CourseTurn { t0, t1, dpsi })
    };
    if fixes.iter().all(|f| f.1.is_some()) {
        // (time, course) where the receiver's speed gives one
        let course = |f: &(PositionFix, Option<VelocityFix>)| {
            let v = f.1?;
            let speed = v.v_ned[0].hypot(v.v_ned[1]);
            (speed - 3.0 * v.sigma >= MIN_COURSE_SPEED).then(|| v.v_ned[1].atan2(v.v_ned[0]))
        };
        return fixes
            .windows(2)
            .filter_map(|w| {
                let (a, b) = (course(&w[0])?, course(&w[1])?);
                keep(w[0].0.t, w[1].0.t, wrap(b - a))
            })
            .collect();
    }
    // the track from fix k to k+1: (mid time, course) where it is long against the noise
    let track = |a: &PositionFix, b: &PositionFix| -> Option<(f64, f64)> {
        let dt = b.t - a.t;
        let dn = (b.lat - a.lat) * (crate::nav::earth::radius_meridian(a.lat) + a.h);
        let de = crate::nav::earth::lon_difference(b.lon, a.lon)
            * (crate::nav::earth::radius_transverse(a.lat) + a.h)
            * a.lat.cos();
        let noise = a.sigma[0].max(a.sigma[1]).hypot(b.sigma[0].max(b.sigma[1]));
        let d = dn.hypot(de);
        (dt > 0.0 && dt <= MAX_INTERVAL_S && d - 3.0 * noise >= MIN_COURSE_SPEED * dt)
            .then(|| (0.5 * (a.t + b.t), de.atan2(dn)))
    };
    let tracks: Vec<Option<(f64, f64)>> =
        fixes.windows(2).map(|w| track(&w[0].0, &w[1].0)).collect();
    tracks
        .windows(2)
        .filter_map(|w| {
            let ((t0, a), (t1, b)) = (w[0]?, w[1]?);
            keep(t0, t1, wrap(b - a))
        })
        .collect()
}

/// One lag's running sums over the intervals judged so far.
#[derive(Debug, Clone, Default)]
struct LagSums {
    /// Next interval to judge at this lag.
    next: usize,
    /// Σ GNSS course change × IMU turn [rad²].
    gy: f64,
    /// Σ GNSS course change² [rad²].
    gg: f64,
    /// Σ IMU turn² [rad²].
    yy: f64,
    /// Σ |GNSS course change| [rad].
    turned: f64,
}

/// An offset found: the lag [s] at which the fixes match the IMU best (a fix stamped t
/// describes the IMU's t + lag), the correlations there and at zero, and the course turned [rad].
#[derive(Debug, Clone)]
pub struct ClockOffset {
    /// Best lag [s].
    pub lag_s: f64,
    /// Correlation at the best lag.
    pub best: f64,
    /// Correlation as stamped (lag 0).
    pub stamped: f64,
    /// GNSS course turned over the intervals judged at the best lag [rad].
    pub turned: f64,
    /// Other lags [s] whose correlation peaks within [`ALIKE`] of the best (turns that repeat),
    /// by distance from zero; `lag_s` is the one nearest zero.
    pub alike: Vec<f64>,
}

impl ClockOffset {
    /// True when the offset is beyond doubt (a run on it would be nonsense): the best lag's
    /// correlation at least [`BEYOND_DOUBT_BEST`] and the stamped one's under
    /// [`BEYOND_DOUBT_STAMPED`].
    pub fn beyond_doubt(&self) -> bool {
        self.best >= BEYOND_DOUBT_BEST && self.stamped < BEYOND_DOUBT_STAMPED
    }

    /// Says the offset: an error when it is beyond doubt (unless `force`), else a warning kept
    /// for the report.
    pub fn say(&self, force: bool) -> anyhow::Result<()> {
        let p = self.words();
        if self.beyond_doubt() && !force {
            anyhow::bail!("--aid: {p} (--force runs anyway)");
        }
        crate::io::warnings::warn(&format!(
            "--aid: {p} ({})",
            if force {
                "--force given".to_string()
            } else {
                self.why_warned()
            }
        ));
        Ok(())
    }

    /// Why a found offset is only warned, in words.
    pub fn why_warned(&self) -> String {
        if self.stamped >= BEYOND_DOUBT_STAMPED {
            format!(
                "not refused: the fixes as stamped still match in part, correlation {:.2}",
                self.stamped
            )
        } else {
            format!(
                "not refused: the best lag's correlation {:.2} is under {BEYOND_DOUBT_BEST}",
                self.best
            )
        }
    }

    /// The finding in words, with its likely cause.
    pub fn words(&self) -> String {
        let l = self.lag_s;
        if !self.alike.is_empty() {
            let mut lags: Vec<String> = std::iter::once(l)
                .chain(self.alike.iter().copied())
                .take(4)
                .map(|x| format!("{x:+.1}"))
                .collect();
            let more = if self.alike.len() > 3 {
                format!(" (and {} more lags)", self.alike.len() - 3)
            } else {
                String::new()
            };
            let last = lags.pop().unwrap_or_default();
            let lags = if lags.is_empty() {
                last
            } else {
                format!("{} or {last}", lags.join(", "))
            };
            return format!(
                "the aiding's clock is likely off the IMU's, by an amount these data cannot pin down: the GNSS course turns {:.0}° in all, \
                 and its turns match the gyros' turns about the vertical about as well (correlation {:.2} at best, the others within \
                 {ALIKE}) with each fix taken {lags} s{more} from its stamp, against {:.2} as stamped — the drive's turns repeat; check the aiding \
                 file's time system and --clock-offset (add one of these to the aiding file's times)",
                self.turned.to_degrees(),
                self.best,
                if self.stamped.abs() < 0.005 { 0.0 } else { self.stamped },
            );
        }
        let cause = if (15.0..=19.0).contains(&l.abs()) {
            format!(
                "{:.0} s is about the GPS–UTC leap seconds (18 s since 2017): likely UTC times read as GPST",
                l.abs()
            )
        } else {
            "a late or early aiding file, another time system, or a wrong --clock-offset".into()
        };
        format!(
            "the aiding's clock is likely {:.1} s off the IMU's: the GNSS course turns {:.0}° in all, and its turns match the gyros' \
             turns about the vertical best (correlation {:.2}) with each fix taken {:.1} s {} its stamp, against {:.2} as stamped; {cause} \
             (add {l:+.1} s to the aiding file's times to put them on the IMU's clock)",
            l.abs(),
            self.turned.to_degrees(),
            self.best,
            l.abs(),
            if l < 0.0 { "before" } else { "after" },
            // (no "-0.00")
            if self.stamped.abs() < 0.005 { 0.0 } else { self.stamped },
        )
    }
}

/// The window check of the aiding clock against the fixes `fixes`, fed the stream's first
/// seconds `head` here and every later window by the stream (those `--init auto` reads through
/// to its start included); it says an offset found ([`ClockOffset::say`]). None where the
/// fixes show no turn.
pub fn window_check(
    fixes: &[(PositionFix, Option<VelocityFix>)],
    head: &[ImuSample],
    force: bool,
) -> Option<crate::io::imu_stream::WindowCheck> {
    let mut c = ClockCheck::new(course_turns(fixes))?;
    c.feed(head);
    Some(Box::new(move |w| {
        c.feed(w);
        match c.judge(w.is_empty()) {
            Some(off) => off.say(force),
            None => Ok(()),
        }
    }))
}

/// The streaming check: fed every IMU sample in order, it judges each GNSS interval at every
/// lag as soon as the IMU covers it.
#[derive(Debug, Clone)]
pub struct ClockCheck {
    /// The GNSS course changes, by time.
    turns: Vec<CourseTurn>,
    /// Per lag (from −[`MAX_LAG_S`] in steps of [`LAG_STEP_S`]).
    lags: Vec<LagSums>,
    /// The IMU's turn integral [rad] on the grid from `grid_t0` [s], step [`GRID_S`].
    grid: VecDeque<f64>,
    /// Time of `grid[0]` [s].
    grid_t0: f64,
    /// Time of the first sample [s] (the integral starts there).
    t_first: Option<f64>,
    /// Time [s] and integral [rad] at the last sample.
    last: (f64, f64),
    /// Low-passed specific force [m/s²] (its direction is the vertical).
    f_avg: Vector3<f64>,
    /// An offset has been found and said.
    said: bool,
}

impl ClockCheck {
    /// A check of the GNSS course changes `turns` (from [`course_turns`]); None when there are
    /// none.
    pub fn new(turns: Vec<CourseTurn>) -> Option<ClockCheck> {
        let n = (2.0 * MAX_LAG_S / LAG_STEP_S).round() as usize + 1;
        (!turns.is_empty()).then(|| ClockCheck {
            turns,
            lags: vec![LagSums::default(); n],
            grid: VecDeque::new(),
            grid_t0: 0.0,
            t_first: None,
            last: (0.0, 0.0),
            f_avg: Vector3::zeros(),
            said: false,
        })
    }

    /// The lag [s] of entry `k`.
    fn lag(k: usize) -> f64 {
        -MAX_LAG_S + k as f64 * LAG_STEP_S
    }

    /// The IMU's turn integral at `t` [s], interpolated on the grid; None outside it.
    fn turn_at(&self, t: f64) -> Option<f64> {
        let x = (t - self.grid_t0) / GRID_S;
        if x < 0.0 || self.grid.is_empty() {
            return None;
        }
        let i = x.floor() as usize;
        let a = *self.grid.get(i)?;
        if i + 1 == self.grid.len() {
            return (x - i as f64 <= 1e-9).then_some(a);
        }
        let b = self.grid[i + 1];
        Some(a + (b - a) * (x - i as f64))
    }

    /// Feeds consecutive IMU samples (FRD increments).
    pub fn feed(&mut self, samples: &[ImuSample]) {
        for s in samples {
            let Some(_) = self.t_first else {
                self.t_first = Some(s.t);
                self.grid_t0 = s.t;
                self.grid.push_back(0.0);
                self.last = (s.t, 0.0);
                continue;
            };
            let (t_prev, y_prev) = self.last;
            let dt = s.t - t_prev;
            if dt <= 0.0 {
                continue;
            }
            // the vertical from the specific force low-passed over about a second
            let f = s.dv / dt;
            if self.f_avg == Vector3::zeros() {
                self.f_avg = f;
            }
            self.f_avg += (f - self.f_avg) * dt.min(1.0);
            let down = -self.f_avg.try_normalize(1e-3).unwrap_or(-Vector3::z());
            let y = y_prev + s.dtheta.dot(&down);
            loop {
                let tg = self.grid_t0 + self.grid.len() as f64 * GRID_S;
                if tg > s.t {
                    break;
                }
                self.grid
                    .push_back(y_prev + (y - y_prev) * (tg - t_prev) / dt);
            }
            self.last = (s.t, y);
        }
    }

    /// Judges every interval the IMU now covers at every lag, forgets the part of the integral
    /// no lag needs any more, and returns an offset found (once): before the `end` of the IMU
    /// file only one beyond doubt on [`EARLY_TURNED_RAD`] of turns, at the end any.
    pub fn judge(&mut self, end: bool) -> Option<ClockOffset> {
        let t_first = self.t_first?;
        let t_end = self.grid_t0 + (self.grid.len().saturating_sub(1)) as f64 * GRID_S;
        for k in 0..self.lags.len() {
            let lag = Self::lag(k);
            while let Some(turn) = self.turns.get(self.lags[k].next).copied() {
                if turn.t1 + lag > t_end {
                    break;
                }
                self.lags[k].next += 1;
                if turn.t0 + lag < t_first {
                    continue;
                }
                let (Some(a), Some(b)) = (self.turn_at(turn.t0 + lag), self.turn_at(turn.t1 + lag))
                else {
                    continue;
                };
                let y = b - a;
                let s = &mut self.lags[k];
                s.gy += turn.dpsi * y;
                s.gg += turn.dpsi * turn.dpsi;
                s.yy += y * y;
                s.turned += turn.dpsi.abs();
            }
        }
        // the earliest time any lag still needs
        let need = (0..self.lags.len())
            .filter_map(|k| {
                self.turns
                    .get(self.lags[k].next)
                    .map(|t| t.t0 + Self::lag(k))
            })
            .fold(f64::INFINITY, f64::min);
        while self.grid.len() > 2 && self.grid_t0 + GRID_S < need {
            self.grid.pop_front();
            self.grid_t0 += GRID_S;
        }
        if self.said {
            return None;
        }
        let found = self.offset().filter(|f| {
            end || (f.beyond_doubt()
                && f.turned >= EARLY_TURNED_RAD
                && self.lags[ZERO].turned >= EARLY_TURNED_RAD)
        })?;
        self.said = true;
        Some(found)
    }

    /// The correlation at lag entry `k`, when its intervals have turned at least `turned` [rad]
    /// (the IMU's turns taken as at least a tenth of the GNSS's, RMS: where the IMU does not
    /// turn, noise gives no correlation).
    fn correlation(&self, k: usize, turned: f64) -> Option<f64> {
        let s = &self.lags[k];
        (s.turned >= turned && s.gg > 0.0).then(|| s.gy / (s.gg * s.yy.max(0.01 * s.gg)).sqrt())
    }

    /// The correlation as stamped (lag zero; judged on a quarter of the turns a lag needs: the
    /// end of the IMU file may cut the turns stamped after it) and the best lag's entry and
    /// correlation.
    fn stamped_and_best(&self) -> Option<(f64, usize, f64)> {
        let stamped = self.correlation(ZERO, 0.25 * MIN_TURNED_RAD)?;
        let (k, best) = (0..self.lags.len())
            .filter_map(|k| self.correlation(k, MIN_TURNED_RAD).map(|c| (k, c)))
            .max_by(|a, b| a.1.total_cmp(&b.1))?;
        Some((stamped, k, best))
    }

    /// The best lag when it is an offset worth saying.
    fn offset(&self) -> Option<ClockOffset> {
        let (stamped, k, best) = self.stamped_and_best()?;
        let lag_s = Self::lag(k);
        if !(lag_s.abs() >= MIN_OFFSET_S && best >= SAY_CORRELATION && best - stamped >= SAY_MARGIN)
        {
            return None;
        }
        // the peaks about as high as the best (a drive whose turns repeat), nearest zero first
        let c = |k: usize| {
            self.correlation(k, MIN_TURNED_RAD)
                .unwrap_or(f64::NEG_INFINITY)
        };
        let mut peaks: Vec<usize> = (0..self.lags.len())
            .filter(|&j| {
                let v = c(j);
                v >= best - ALIKE
                    && (j == 0 || v >= c(j - 1))
                    && (j + 1 == self.lags.len() || v > c(j + 1))
            })
            .collect();
        peaks.sort_by(|a, b| Self::lag(*a).abs().total_cmp(&Self::lag(*b).abs()));
        // ripples of one peak are one peak
        let mut kept: Vec<usize> = Vec::new();
        for j in peaks {
            if kept
                .iter()
                .all(|&q| (Self::lag(q) - Self::lag(j)).abs() > PEAK_APART_S)
            {
                kept.push(j);
            }
        }
        let peaks = kept;
        let first = peaks.first().copied().unwrap_or(k);
        Some(ClockOffset {
            lag_s: Self::lag(first),
            best,
            stamped,
            turned: self.lags[first].turned,
            alike: peaks[1.min(peaks.len())..]
                .iter()
                .map(|&j| Self::lag(j))
                .collect(),
        })
    }

    /// The correlation as stamped and the best lag's [s], when both have seen enough turns.
    #[cfg(test)]
    fn summary(&self) -> Option<(f64, f64, f64)> {
        let (stamped, k, best) = self.stamped_and_best()?;
        Some((stamped, Self::lag(k), best))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A drive of turns at `rate(t)` [rad/s] sampled at 100 Hz for `secs`, level, at 10 m/s.
    fn drive(secs: f64, rate: impl Fn(f64) -> f64) -> (Vec<ImuSample>, Vec<CourseTurn>) {
        let dt = 0.01;
        let n = (secs / dt) as usize;
        let samples: Vec<ImuSample> = (1..=n)
            .map(|i| {
                let t = i as f64 * dt;
                ImuSample {
                    t,
                    dtheta: Vector3::new(0.0, 0.0, rate(t - 0.5 * dt) * dt),
                    dv: Vector3::new(0.0, 0.0, -9.8 * dt),
                }
            })
            .collect();
        // GNSS course changes per second: the integral of the rate
        let turns = (0..secs as usize - 1)
            .map(|k| {
                let (t0, t1) = (k as f64, k as f64 + 1.0);
                let dpsi = (0..100)
                    .map(|j| rate(t0 + (j as f64 + 0.5) * 0.01) * 0.01)
                    .sum();
                CourseTurn { t0, t1, dpsi }
            })
            .collect();
        (samples, turns)
    }

    /// Turns of 90° left and right at irregular times.
    fn rate(t: f64) -> f64 {
        let turns = [
            (40.0, 1.0),
            (95.0, -1.0),
            (130.0, -1.0),
            (210.0, 1.0),
            (260.0, 1.0),
            (330.0, -1.0),
        ];
        turns
            .iter()
            .filter(|(at, _)| t >= *at && t < at + 9.0)
            .map(|(_, s)| s * 10f64.to_radians())
            .sum()
    }

    fn run(shift: f64) -> (Option<ClockOffset>, ClockCheck) {
        let (samples, mut turns) = drive(400.0, rate);
        for t in &mut turns {
            t.t0 += shift;
            t.t1 += shift;
        }
        let mut c = ClockCheck::new(turns).unwrap();
        let mut found = None;
        for w in samples.chunks(1000).chain([&[][..]]) {
            c.feed(w);
            found = found.or(c.judge(w.is_empty()));
        }
        (found, c)
    }

    #[test]
    fn one_clock_says_nothing() {
        let (found, c) = run(0.0);
        assert!(found.is_none(), "{found:?}");
        let (stamped, lag, best) = c.summary().unwrap();
        assert!(
            stamped > 0.99 && lag.abs() < 0.01 && best > 0.99,
            "{stamped} {lag} {best}"
        );
        // memory: only a few seconds of the integral are kept
        assert!(c.grid.len() < 400, "{}", c.grid.len());
    }

    #[test]
    fn a_late_or_early_file_is_found_with_its_offset() {
        for shift in [18.0, -30.0, 100.0, 3.0] {
            let (found, _) = run(shift);
            let f = found.unwrap_or_else(|| panic!("{shift}: none"));
            assert!((f.lag_s + shift).abs() <= 0.5, "{shift}: {f:?}");
            assert!(f.alike.is_empty(), "{shift}: {f:?}");
            // 3 s is a third of a 9-s turn: the stamped fixes still half match (warned only)
            assert_eq!(f.beyond_doubt(), shift.abs() > 9.0, "{shift}: {f:?}");
            let w = f.words();
            assert!(w.contains(&format!("add {:+.1} s", -shift)), "{w}");
            assert_eq!(w.contains("UTC times read as GPST"), shift == 18.0, "{w}");
        }
    }

    /// A slalom moving from the first sample, a left-right turn every 20 s: the turns repeat, so
    /// lags 20 s apart match about as well; the offset is said with the others that match,
    /// the one nearest zero first (for 15 s, −5 s matches as well as the true −15 s).
    #[test]
    fn repeating_turns_leave_the_offset_ambiguous_and_say_so() {
        let slalom = |t: f64| 15f64.to_radians() * (std::f64::consts::TAU * t / 20.0).sin();
        for shift in [-5.0, 5.0, 15.0] {
            let (samples, mut turns) = drive(400.0, slalom);
            for t in &mut turns {
                t.t0 += shift;
                t.t1 += shift;
            }
            let mut c = ClockCheck::new(turns).unwrap();
            c.feed(&samples);
            let f = c.judge(true).unwrap_or_else(|| panic!("{shift}: none"));
            // the true shift is among the lags said; the nearest zero first
            let said: Vec<f64> = std::iter::once(f.lag_s).chain(f.alike.clone()).collect();
            assert!(
                said.iter().any(|l| (l + shift).abs() <= 0.5),
                "{shift}: {f:?}"
            );
            assert!(
                said.windows(2).all(|w| w[0].abs() <= w[1].abs()),
                "{shift}: {f:?}"
            );
            let w = f.words();
            assert!(
                w.contains("cannot pin down") && w.contains("more lags)"),
                "{w}"
            );
            if shift.abs() < 10.0 {
                assert!(w.contains(&format!("{:+.1}, ", -shift)), "{w}");
            }
        }
    }

    #[test]
    fn straight_runs_are_not_judged() {
        let (samples, turns) = drive(200.0, |_| 0.0);
        let mut c = ClockCheck::new(turns).unwrap();
        c.feed(&samples);
        assert!(c.judge(true).is_none());
        assert!(c.summary().is_none());
    }
}
