//! Static alignment: detection of a disturbed start, coarse analytic alignment from the mean
//! specific force (gravity reaction, "up") and the mean angular rate (Earth rate), latitude from
//! the angle between them, and fine alignment by the error-state Kalman filter (P13, closed loop)
//! with zero-velocity and known-position updates. NED/FRD, SI inside.

use crate::nav::attitude::dcm_from_euler;

use crate::estimate::filter::{self, AidingEpoch, FilterConfig, Mode};
use crate::io::imu::{mean_rates_of, ImuData, ImuSample};
use crate::model::Model;
use crate::nav::strapdown::{NavState, Vertical};
use nalgebra::{Rotation3, UnitQuaternion, Vector3};

/// Coarse alignment of one stretch of static data.
#[derive(Debug, Clone, Copy)]
pub struct Coarse {
    /// Roll, pitch, heading [rad].
    pub euler: Vector3<f64>,
    /// Latitude from the Earth-rate and gravity directions [rad].
    pub lat: f64,
    /// Mean specific force, FRD [m/s²].
    pub f_mean: Vector3<f64>,
    /// Mean angular rate, FRD [rad/s].
    pub w_mean: Vector3<f64>,
}

/// Analytic alignment from the mean specific force and rate of `samples`.
/// Each increment is divided by its own interval ([`mean_rates_of`]), so a jittered clock gives
/// the same means as a uniform one.
pub fn coarse(samples: &[ImuSample], dt: f64) -> Coarse {
    let (f, w) = mean_rates_of(samples, dt);
    let roll = (-f.y).atan2(-f.z);
    let pitch = f.x.atan2((f.y * f.y + f.z * f.z).sqrt());
    // rate in the levelled body frame (yaw 0): its horizontal part is Ω cos L (cos ψ, −sin ψ)
    let level = dcm_from_euler(roll, pitch, 0.0);
    let wl = level * w;
    let heading = (-wl.y).atan2(wl.x);
    // latitude: "up" is along f; the Earth rate's up component is Ω sin L
    let up = f.normalize();
    let w_up = w.dot(&up);
    let lat = w_up.atan2((w - w_up * up).norm());
    Coarse {
        euler: Vector3::new(roll, pitch, heading),
        lat,
        f_mean: f,
        w_mean: w,
    }
}

/// Disturbed windows (of `win_s` seconds): a parked vehicle being rocked shows up in the mean
/// angular rate of a window, so a window is disturbed when its mean rate differs from the median
/// window's by more than 5 robust standard deviations (1.4826 × median absolute deviation).
/// Returns the window length in samples and one flag per whole window.
pub fn disturbed_windows(data: &ImuData, win_s: f64) -> (usize, Vec<bool>) {
    let dt = data.interval();
    let w = ((win_s / dt).round() as usize).max(2);
    let means: Vec<Vector3<f64>> = data
        .samples
        .chunks(w)
        .filter(|c| c.len() == w)
        .map(|c| mean_rates_of(c, dt).1)
        .collect();
    let med = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v.get(v.len() / 2).copied().unwrap_or(0.0)
    };
    let center = Vector3::new(
        med(&mut means.iter().map(|m| m.x).collect()),
        med(&mut means.iter().map(|m| m.y).collect()),
        med(&mut means.iter().map(|m| m.z).collect()),
    );
    let dev: Vec<f64> = means.iter().map(|m| (m - center).norm()).collect();
    let mad = med(&mut dev.clone());
    (w, dev.iter().map(|d| *d > 5.0 * 1.4826 * mad).collect())
}

/// At rest, judged from absolute evidence: the RMS deviation of the 1-s mean specific forces of
/// a window from their mean [m/s²] stays below this (5 mg: engine vibration averages out within
/// a second, a vehicle that rolls, brakes or is carried does not).
pub const STATIC_F_SPREAD: f64 = 0.05;
/// At rest: the RMS deviation of the 1-s mean angular rates from their mean [rad/s] stays below
/// this (0.1 deg/s: about five times the 1-s noise of a consumer MEMS gyro; a gyro bias is
/// constant and does not count).
pub const STATIC_W_SPREAD: f64 = 0.1 * std::f64::consts::PI / 180.0;
/// At rest: the mean |f| is within this of local gravity [m/s²] (0.05 g: room for a MEMS
/// accelerometer's bias and scale).
pub const STATIC_G_ERROR: f64 = 0.05 * 9.80665;
/// At rest: a window's mean specific force stays within this of the first window's of the
/// same stretch [m/s²] (10 mg, a tilt of 0.6°: a constant acceleration passes the spread tests
/// inside each window but not this one).
pub const STATIC_F_STEP: f64 = 0.1;
/// Largest zero-velocity innovation the fine alignment accepts [m/s] (its updates are 1 s apart:
/// 0.3 m/s is a 1.7° tilt error's drift, which the coarse levelling is far below at rest).
pub const ZUPT_INNOVATION_MAX: f64 = 0.3;

/// What one window of data says about being at rest.
#[derive(Debug, Clone, Copy)]
pub struct RestEvidence {
    /// RMS deviation of the 1-s mean specific forces from the window mean [m/s²].
    pub f_spread: f64,
    /// RMS deviation of the 1-s mean angular rates from the window mean [rad/s].
    pub w_spread: f64,
    /// |mean f| − local gravity [m/s²].
    pub g_error: f64,
    /// Mean specific force of the window, body frame [m/s²].
    pub f_mean: Vector3<f64>,
    /// Mean angular rate of the window, body frame [rad/s].
    pub w_mean: Vector3<f64>,
}

impl RestEvidence {
    /// True when every measure is within its threshold.
    pub fn at_rest(&self) -> bool {
        self.f_spread <= STATIC_F_SPREAD
            && self.w_spread <= STATIC_W_SPREAD
            && self.g_error.abs() <= STATIC_G_ERROR
    }
}

/// Evidence of rest of each whole window of `win` samples (1-s sub-means), with `g` the local
/// gravity [m/s²].
pub fn rest_evidence(data: &ImuData, win: usize, g: f64) -> Vec<RestEvidence> {
    let dt = data.interval();
    let sub = ((1.0 / dt).round() as usize).clamp(2, win.max(2));
    data.samples
        .chunks(win)
        .filter(|c| c.len() == win)
        .map(|c| {
            let means: Vec<(Vector3<f64>, Vector3<f64>)> = c
                .chunks(sub)
                .filter(|s| s.len() == sub)
                .map(|s| mean_rates_of(s, dt))
                .collect();
            let k = means.len().max(1) as f64;
            let fm = means.iter().map(|m| m.0).sum::<Vector3<f64>>() / k;
            let wm = means.iter().map(|m| m.1).sum::<Vector3<f64>>() / k;
            let rms = |dev: Vec<f64>| (dev.iter().map(|d| d * d).sum::<f64>() / k).sqrt();
            RestEvidence {
                f_spread: rms(means.iter().map(|m| (m.0 - fm).norm()).collect()),
                w_spread: rms(means.iter().map(|m| (m.1 - wm).norm()).collect()),
                g_error: fm.norm() - g,
                f_mean: fm,
                w_mean: wm,
            }
        })
        .collect()
}

/// Largest angle [rad] between the measured mean specific force at rest and the one an
/// initial attitude predicts before the attitude is refused (5°).
pub const MAX_TILT_MISMATCH: f64 = 5.0 * std::f64::consts::PI / 180.0;

/// Checks an initial roll and pitch [rad] against gravity: when the first seconds of `head` are
/// at rest (by [`rest_evidence`] over up to 10 s), the mean specific force must point where the
/// attitude says "up" is, within [`MAX_TILT_MISMATCH`]; returns the problem in words, or None
/// (also when the start moves: then the data cannot judge).
pub fn attitude_contradicts_gravity(head: &ImuData, roll: f64, pitch: f64) -> Option<String> {
    let dt = head.interval();
    if dt.is_nan() || dt <= 0.0 || head.duration() < 2.0 {
        return None;
    }
    let win = ((head.duration().min(10.0) / dt) as usize).min(head.samples.len());
    let first = ImuData {
        samples: head.samples[..win].to_vec(),
    };
    let g = first.mean_rates().0.norm();
    let ev = rest_evidence(&first, win, g);
    if !ev
        .first()
        .is_some_and(|e| e.f_spread <= STATIC_F_SPREAD && e.w_spread <= STATIC_W_SPREAD)
    {
        return None;
    }
    let (f, _) = first.mean_rates();
    // at rest f^b = C_n^b (0, 0, −g): "up" in the body is −f
    let c = dcm_from_euler(roll, pitch, 0.0);
    let predicted = c.transpose() * Vector3::new(0.0, 0.0, -1.0);
    let angle = f.normalize().dot(&predicted).clamp(-1.0, 1.0).acos();
    (angle > MAX_TILT_MISMATCH).then(|| {
        let d = 180.0 / std::f64::consts::PI;
        format!(
            "the initial attitude contradicts gravity: roll {:.2} deg, pitch {:.2} deg put the specific force {:.1} deg away from \
             what the first {:.0} s at rest measure (roll {:.2} deg, pitch {:.2} deg); check roll and pitch (a sensor mounted \
             upside down has roll 180), or pass --force to run anyway",
            roll * d,
            pitch * d,
            angle * d,
            first.duration(),
            (-f.y).atan2(-f.z) * d,
            f.x.atan2((f.y * f.y + f.z * f.z).sqrt()) * d
        )
    })
}

/// Result of a static alignment.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Alignment {
    /// Roll [deg] (NED/FRD).
    pub roll_deg: f64,
    /// Pitch [deg].
    pub pitch_deg: f64,
    /// Heading [deg], 0..360; None when the gyros cannot find north (their bias, or its prior,
    /// hides the Earth rate): see `heading_note`.
    pub heading_deg: Option<f64>,
    /// 1-σ of the heading from the fine alignment [deg], including the gyro-bias prior.
    pub heading_sigma_deg: Option<f64>,
    /// Why there is no heading, or what widened its σ.
    pub heading_note: Option<String>,
    /// Gyro-bias 1-σ used in the fine alignment [deg/h]: the given prior, widened to the bias
    /// the data show at rest when that is larger.
    pub gyro_bias_sigma_used_deg_h: f64,
    /// Latitude: given, or estimated [deg]; None when the gyro bias hides the Earth rate (the
    /// latitude comes from its direction) and none was given.
    pub lat_deg: Option<f64>,
    /// 1-σ of the estimated latitude [deg]: the scatter of one-minute estimates and the gyro
    /// bias against the Earth rate (0 when given; None when the latitude is not determined).
    pub lat_sigma_deg: Option<f64>,
    /// Seconds from the first sample to the stretch used: skipped as disturbed or moving (and,
    /// with align's `--skip`, set by the caller from the first sample of the file).
    pub skipped_s: f64,
    /// Coarse heading per window of the used data [deg] (evidence of stability); empty when
    /// the gyros cannot find north.
    pub heading_windows_deg: Vec<f64>,
    /// Coarse latitude estimate [deg]; None when the gyros cannot see the Earth rate.
    pub coarse_lat_deg: Option<f64>,
    /// Estimated gyro biases after fine alignment [deg/h].
    pub gyro_bias_deg_h: [f64; 3],
    /// Their 1-σ from the fine alignment [deg/h].
    pub gyro_bias_sigma_deg_h: [f64; 3],
}

/// Aligns static data: skips a disturbed start, uses at most `seconds` of the rest; latitude
/// given in radians or estimated; longitude/height only matter through gravity and radii.
/// `gyro_bias_sigma` [rad/s] is the prior 1-σ of the gyro biases in the fine alignment; it
/// bounds the heading accuracy (σ_ψ ≈ σ_ε / (Ω cos L)).
pub fn align(
    data: &ImuData,
    lat: Option<f64>,
    seconds: Option<f64>,
    lon: f64,
    h: f64,
    gyro_bias_sigma: f64,
) -> anyhow::Result<Alignment> {
    let dt = data.interval();
    // the quiet-window logic works on 10 s windows of samples: at least 1 Hz data
    if !(dt > 0.0 && dt <= 1.0) {
        anyhow::bail!(
            "the IMU interval is {dt} s: alignment needs data at 1 Hz or faster (10 s windows of samples)"
        );
    }
    let (q0, used) = samples_at_rest(data, dt, lat, h, seconds)?;
    let (c, windows, lat_sigma) = coarse_on_quiet(&used, dt);
    if let Some(given) = lat {
        check_given_latitude(given, &c, lat_sigma, gyro_bias_sigma)?;
    }
    let lat_used = lat.unwrap_or(c.lat);
    let north = north_seen(&c, lat, lat_used, gyro_bias_sigma);
    let (bias_sigma, no_heading) = (north.bias_sigma, north.no_heading);
    let fine = fine_align(used, dt, &c, lat_used, lon, h, bias_sigma)?;
    let (e, eps, eps_sigma) = (fine.euler, fine.eps_deg_h, fine.eps_sigma_deg_h);
    let deg = 180.0 / std::f64::consts::PI;
    let deg_h = 180.0 / std::f64::consts::PI * 3600.0;
    Ok(Alignment {
        roll_deg: e.x * deg,
        pitch_deg: e.y * deg,
        heading_deg: (!no_heading).then(|| (e.z * deg).rem_euclid(360.0)),
        heading_sigma_deg: (!no_heading).then_some(fine.heading_sigma * deg),
        heading_note: north.note,
        gyro_bias_sigma_used_deg_h: bias_sigma * deg_h,
        lat_deg: (lat.is_some() || !no_heading).then_some(lat_used * deg),
        // the bias tilts the measured Earth rate by up to σ_b / Ω
        lat_sigma_deg: if lat.is_some() {
            Some(0.0)
        } else {
            (!no_heading).then(|| lat_sigma.hypot(bias_sigma / crate::nav::earth::OMEGA) * deg)
        },
        // from the sample times (a jittered clock makes q0·dt wrong), rounded to the microsecond
        skipped_s: ((data.samples[q0].t - data.samples[0].t) * 1e6).round() / 1e6,
        heading_windows_deg: if no_heading {
            Vec::new()
        } else {
            windows
                .iter()
                .map(|x| (x.euler.z * deg).rem_euclid(360.0))
                .collect()
        },
        coarse_lat_deg: (!no_heading).then_some(c.lat * deg),
        gyro_bias_deg_h: [eps[0], eps[1], eps[2]],
        // a horizontal gyro bias and the heading error are one unknown at rest (ε_E = Ω cos L
        // δψ): the x and y biases are no better known than the heading lets them be (with no
        // heading, up to the whole horizontal Earth rate)
        gyro_bias_sigma_deg_h: {
            let psi = if no_heading {
                1.0
            } else {
                fine.heading_sigma.min(1.0)
            };
            let coupled = crate::nav::earth::OMEGA * lat_used.cos() * psi.sin() * deg_h;
            [
                eps_sigma[0].hypot(coupled),
                eps_sigma[1].hypot(coupled),
                eps_sigma[2],
            ]
        },
    })
}

/// The first and end window index of the longest run of windows at rest whose mean specific
/// force stays within [`STATIC_F_STEP`] of the run's first window ((0, 0) when none).
fn longest_run(evidence: &[RestEvidence]) -> (usize, usize) {
    let (mut best, mut run_start): ((usize, usize), Option<usize>) = ((0, 0), None);
    for k in 0..=evidence.len() {
        let e = evidence.get(k);
        let continues = match (e, run_start) {
            (Some(e), Some(s0)) => {
                e.at_rest() && (e.f_mean - evidence[s0].f_mean).norm() <= STATIC_F_STEP
            }
            _ => false,
        };
        if continues {
            continue;
        }
        if let Some(s0) = run_start {
            if k - s0 > best.1 - best.0 {
                best = (s0, k);
            }
        }
        run_start = e.filter(|e| e.at_rest()).map(|_| k);
    }
    best
}

/// The samples to align on (sample period `dt` [s]): the longest stretch at rest (10 s windows at
/// rest by absolute evidence, gravity at latitude `lat` [rad] or 45° and height `h` [m]), less a
/// disturbed start, at most `seconds` [s] of it; with the index of its first sample. At least
/// 60 s are needed.
fn samples_at_rest(
    data: &ImuData,
    dt: f64,
    lat: Option<f64>,
    h: f64,
    seconds: Option<f64>,
) -> anyhow::Result<(usize, Vec<ImuSample>)> {
    // at rest by absolute evidence (10 s windows of 1-s means) and not disturbed relative to
    // the other windows; the longest run of such windows is used
    let g_local = crate::nav::earth::gravity(lat.unwrap_or(45f64.to_radians()), h);
    let (w10, disturbed) = disturbed_windows(data, 10.0);
    let evidence = rest_evidence(data, w10, g_local);
    let best = longest_run(&evidence);
    // from the sample times: on a jittered clock a window of w10 samples is not 10 s
    let rest_s = if best.1 > best.0 {
        let (a, b) = (best.0 * w10, (best.1 * w10).min(data.samples.len()) - 1);
        data.samples[b].t - data.samples[a].t + dt
    } else {
        0.0
    };
    if rest_s < 60.0 {
        let moving: Vec<&RestEvidence> = evidence.iter().filter(|e| !e.at_rest()).collect();
        let worst =
            |f: &dyn Fn(&RestEvidence) -> f64| moving.iter().map(|e| f(e)).fold(0.0, f64::max);
        anyhow::bail!(
            "the data are not at rest long enough to align: the longest stretch at rest is {rest_s:.0} s of {:.0} s, 60 s are needed. \
             In the {} of {} ten-second windows judged moving: specific-force spread up to {:.3} m/s^2 (at rest <= {STATIC_F_SPREAD}), \
             angular-rate spread up to {:.3} deg/s (at rest <= {:.2}), | |f| - g | up to {:.3} m/s^2 (at rest <= {:.2}); \
             and a stretch ends where a window's mean specific force moves more than {STATIC_F_STEP} m/s^2 from its first window's \
             (a constant acceleration, a drive-off, passes the tests inside each window): between windows it moved by up to {:.3} m/s^2. \
             Give the attitude instead: --init for filter, explain and navigate (or navigate's --att) (from a known mounting, or a GNSS course once moving)",
            data.duration(),
            moving.len(),
            evidence.len(),
            worst(&|e| e.f_spread),
            worst(&|e| e.w_spread).to_degrees(),
            STATIC_W_SPREAD.to_degrees(),
            worst(&|e| e.g_error.abs()),
            STATIC_G_ERROR,
            evidence
                .windows(2)
                .map(|w| (w[1].f_mean - w[0].f_mean).norm())
                .fold(0.0, f64::max)
        );
    }
    // inside it, a disturbed start (a touch, a door: at rest by the thresholds but unlike the
    // other windows) is skipped as before: after the last disturbed window of the first half
    let half = best.0 + (best.1 - best.0) / 2;
    let first = disturbed[best.0..half]
        .iter()
        .rposition(|d| *d)
        .map(|k| best.0 + k + 1)
        .unwrap_or(best.0);
    let q0 = first * w10;
    // a run that reaches the last whole window keeps the samples after it too
    let end = if best.1 == evidence.len() {
        data.samples.len()
    } else {
        best.1 * w10
    };
    let mut used: Vec<ImuSample> = data.samples[q0..end].to_vec();
    if let Some(s) = seconds {
        let n = ((s / dt).round() as usize).min(used.len());
        used.truncate(n);
    }
    if used.len() < (60.0 / dt) as usize {
        anyhow::bail!("fewer than 60 s of data at rest to align on (--seconds)");
    }
    Ok((q0, used))
}

/// Coarse alignment of `used` (sample period `dt` [s]) on its quiet 10 s windows, the coarse
/// alignments of its 60 s windows, and the 1-σ of the latitude from their scatter [rad].
fn coarse_on_quiet(used: &[ImuSample], dt: f64) -> (Coarse, Vec<Coarse>, f64) {
    // coarse alignment on the quiet windows only (later disturbances excluded from the means)
    let used_data = ImuData {
        samples: used.to_vec(),
    };
    let (w10, flags) = disturbed_windows(&used_data, 10.0);
    let quiet: Vec<ImuSample> = used
        .chunks(w10)
        .zip(flags.iter().chain(std::iter::repeat(&false)))
        .filter(|(_, f)| !**f)
        .flat_map(|(c, _)| c.iter().copied())
        .collect();
    let c = coarse(&quiet, dt);
    // latitude σ from the scatter of per-window estimates (60 s windows)
    let w = (60.0 / dt) as usize;
    let windows: Vec<Coarse> = quiet
        .chunks(w)
        .filter(|x| x.len() == w)
        .map(|x| coarse(x, dt))
        .collect();
    let k = windows.len() as f64;
    let lat_mean_w = windows.iter().map(|x| x.lat).sum::<f64>() / k;
    let lat_sigma = (windows
        .iter()
        .map(|x| (x.lat - lat_mean_w).powi(2))
        .sum::<f64>()
        / (k - 1.0).max(1.0))
    .sqrt()
        / k.sqrt();
    (c, windows, lat_sigma)
}

/// What the gyros can say about north.
struct North {
    /// Gyro-bias 1-σ for the fine alignment [rad/s]: the prior, widened to the bias seen.
    bias_sigma: f64,
    /// The bias hides the Earth rate: no heading (its σ would exceed 20°).
    no_heading: bool,
    /// Why there is no heading, or what widened the bias σ.
    note: Option<String>,
}

/// What the gyros can say about north at latitude `lat_used` [rad] (`lat`: given) from the
/// coarse alignment `c`, against the gyro-bias prior `gyro_bias_sigma` [rad/s].
/// Refuses a given latitude [rad] that the data at rest contradict: where the gyros see the
/// Earth rate's direction, the latitude they show (σ from the windows' scatter and the gyro
/// bias) must be within 5 σ + 1° of it (radians given as degrees, a hemisphere's sign lost).
fn check_given_latitude(
    given: f64,
    c: &Coarse,
    lat_sigma: f64,
    gyro_bias_sigma: f64,
) -> anyhow::Result<()> {
    let own = north_seen(c, None, c.lat, gyro_bias_sigma);
    if own.no_heading {
        return Ok(());
    }
    let sigma = lat_sigma.hypot(own.bias_sigma / crate::nav::earth::OMEGA);
    let off = (given - c.lat).abs();
    if off > 5.0 * sigma + 1f64.to_radians() {
        anyhow::bail!(
            "--lat {:.4} deg: the data at rest show a latitude of {:.4} ± {:.4} deg (the Earth-rate \
             and gravity directions), {:.0} σ away: radians given as degrees, or the hemisphere's \
             sign lost? (omit --lat to use the estimate)",
            given.to_degrees(),
            c.lat.to_degrees(),
            sigma.to_degrees(),
            off / sigma.max(f64::MIN_POSITIVE)
        );
    }
    Ok(())
}

fn north_seen(c: &Coarse, lat: Option<f64>, lat_used: f64, gyro_bias_sigma: f64) -> North {
    // what the gyros can say about north: the horizontal Earth rate against the gyro bias. At
    // rest |ω̄| = |Ω + b|: above 2 Ω the bias is at least |ω̄| − Ω (≥ Ω) and the prior is
    // widened to it (the heading σ must include the bias the data show); between 0.5 and 2 Ω a
    // scale error explains the difference as well as a bias, and the prior stands.
    let omega_h = crate::nav::earth::OMEGA * lat_used.cos();
    let ratio = c.w_mean.norm() / crate::nav::earth::OMEGA;
    let bias_seen = if ratio > 2.0 {
        c.w_mean.norm() - crate::nav::earth::OMEGA
    } else {
        0.0
    };
    let bias_sigma = gyro_bias_sigma.max(bias_seen);
    let deg_h = 180.0 / std::f64::consts::PI * 3600.0;
    let mut heading_note = (bias_sigma > gyro_bias_sigma).then(|| {
        format!(
            "gyro-bias prior widened from {:.3} to {:.3} deg/h: at rest the gyros read {:.3} deg/h against Earth rate {:.3} deg/h",
            gyro_bias_sigma * deg_h,
            bias_sigma * deg_h,
            c.w_mean.norm() * deg_h,
            crate::nav::earth::OMEGA * deg_h
        )
    });
    // σ_ψ ≈ σ_b / (Ω cos L): beyond ~20° the gyros do not find north
    let no_heading = bias_sigma / omega_h > 20f64.to_radians();
    if no_heading {
        // without a given latitude the estimated one is as hidden as north: compare with the
        // whole Earth rate (its horizontal part is at most that)
        let (rate, which) = match lat {
            Some(_) => (omega_h, "the horizontal Earth rate"),
            None => (crate::nav::earth::OMEGA, "the Earth rate"),
        };
        heading_note = Some(format!(
            "no heading: the gyro bias ({:.3} deg/h at rest{}) is {:.1}x {which} ({:.3} deg/h{}), \
             so gyrocompassing cannot find north (sigma would exceed 20 deg); give the heading with --init / --att, or align on a GNSS course once moving",
            bias_sigma * deg_h,
            if bias_sigma > gyro_bias_sigma { ", seen in the data" } else { ", the --gyro-bias-sigma prior" },
            bias_sigma / rate,
            rate * deg_h,
            if lat.is_some() { " at this latitude" } else { "; its horizontal part is smaller" }
        ));
    }
    North {
        bias_sigma,
        no_heading,
        note: heading_note,
    }
}

/// What the fine alignment gives.
struct Fine {
    /// Roll, pitch, heading [rad].
    euler: Vector3<f64>,
    /// 1-σ of the heading (phi_d) at the last update [rad].
    heading_sigma: f64,
    /// Estimated gyro biases [deg/h].
    eps_deg_h: Vec<f64>,
    /// Their 1-σ [deg/h].
    eps_sigma_deg_h: Vec<f64>,
}

/// Fine alignment of `used` (sample period `dt` [s]) from the coarse one `c`: P13, closed
/// loop, zero velocity and known position (latitude `lat_used` [rad], longitude `lon` [rad],
/// height `h` [m]) at 1 Hz, gyro-bias prior `bias_sigma` [rad/s].
fn fine_align(
    used: Vec<ImuSample>,
    dt: f64,
    c: &Coarse,
    lat_used: f64,
    lon: f64,
    h: f64,
    bias_sigma: f64,
) -> anyhow::Result<Fine> {
    // fine alignment: P13, closed loop, zero velocity and known position at 1 Hz
    let model = Model::parse("P13")?;
    let mut cfg = FilterConfig::new(&model);
    cfg.mode = Mode::ClosedLoop;
    cfg.vertical = Vertical::Fixed;
    cfg.set_prior(&model, "phi_n", 1e-3);
    cfg.set_prior(&model, "phi_e", 1e-3);
    cfg.set_prior(&model, "phi_d", 0.1);
    for n in ["eps_x", "eps_y", "eps_z"] {
        cfg.set_prior(&model, n, bias_sigma);
    }
    cfg.set_prior(&model, "nabla_x", 1e-3);
    cfg.set_prior(&model, "nabla_y", 1e-3);
    cfg.set_prior(&model, "nabla_z", 1e-3);
    let t0 = used[0].t - dt;
    let start = NavState {
        t: t0,
        lat: lat_used,
        lon,
        h,
        v: Vector3::zeros(),
        q: UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(dcm_from_euler(
            c.euler.x, c.euler.y, c.euler.z,
        ))),
    };
    let t_end = used[used.len() - 1].t;
    let aid: Vec<AidingEpoch> = (1..)
        .map(|i| t0 + i as f64)
        .take_while(|t| *t <= t_end)
        .map(|t| AidingEpoch {
            t,
            vel: Some((Vector3::zeros(), 0.01)),
            pos: Some((lat_used, lon, h, [0.1, 0.1, 0.1])),
            body_vel: None,
            att: None,
        })
        .collect();
    let imu = ImuData { samples: used };
    let run = filter::run(&model, &cfg, &imu, start, &aid, None, |_| {});
    // at rest the velocity cannot drift far in the second between updates: one that does
    // says the data move (a drive-off the rest tests let through)
    if let Some(nu) = run
        .innovations
        .iter()
        .filter(|i| i.meas.starts_with("vel"))
        .find(|i| i.nu.abs() > ZUPT_INNOVATION_MAX)
    {
        anyhow::bail!(
            "the data move during the stretch taken as at rest: the fine alignment's zero-velocity update at {:.1} s after its start \
             finds a velocity of {:.3} m/s (at rest <= {ZUPT_INNOVATION_MAX} m/s within 1 s); --skip and --seconds choose a stretch at rest",
            nu.t - t0,
            nu.nu.abs()
        );
    }
    let e = run.final_state.euler();
    let last = run
        .records
        .last()
        .ok_or_else(|| anyhow::anyhow!("no filter update"))?;
    let i_phid = model.index_of("phi_d").expect("P13 has phi_d");
    let deg = 180.0 / std::f64::consts::PI;
    let of = |v: &[f64]| -> Vec<f64> {
        ["eps_x", "eps_y", "eps_z"]
            .iter()
            .map(|n| v[model.index_of(n).expect("P13 eps")] * deg * 3600.0)
            .collect()
    };
    let (eps, eps_sigma) = (of(&last.x), of(&last.sigma));
    Ok(Fine {
        euler: e,
        heading_sigma: last.sigma[i_phid],
        eps_deg_h: eps,
        eps_sigma_deg_h: eps_sigma,
    })
}
