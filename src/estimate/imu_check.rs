//! What an IMU log says about itself, to catch a wrong unit, axis or clock before any
//! navigation: sampling (rate, jitter, gaps), and on a static stretch the mean specific force
//! against local gravity, the mean angular rate against Earth rate, and the attitude that
//! follows. FRD body frame, SI inside; the report carries display units.

use crate::io::imu::ImuData;
use crate::nav::earth;
use nalgebra::Vector3;
use serde::Serialize;

/// The result of checking one IMU log.
#[derive(Debug, Clone, Serialize)]
pub struct ImuCheck {
    /// Number of samples.
    pub samples: usize,
    /// First to last sample [s].
    pub duration_s: f64,
    /// Rate from the median interval [Hz].
    pub rate_hz: f64,
    /// Shortest and longest interval [s].
    pub interval_min_s: f64,
    /// Longest interval [s].
    pub interval_max_s: f64,
    /// RMS deviation of the intervals from their median [s].
    pub jitter_rms_s: f64,
    /// Intervals longer than twice the median.
    pub gaps: usize,
    /// Start and end of the window the static checks used [s].
    pub window_s: [f64; 2],
    /// RMS of the specific force about its mean over the window [m/s²].
    pub f_spread_mps2: f64,
    /// The window looks static (specific-force spread below 0.5 m/s²).
    pub is_static: bool,
    /// Mean specific force over the window, FRD [m/s²] (Σ Δv / Σ Δt with each sample's own interval).
    pub f_mean_mps2: [f64; 3],
    /// Mean angular rate, FRD [rad/s].
    pub w_mean_radps: [f64; 3],
    /// |mean f| / local normal gravity.
    pub gravity_ratio: f64,
    /// Local normal gravity used [m/s²].
    pub gravity_mps2: f64,
    /// |mean ω| / Earth rate.
    pub earth_rate_ratio: f64,
    /// Roll and pitch from the mean specific force [deg].
    pub roll_deg: f64,
    /// Pitch [deg].
    pub pitch_deg: f64,
    /// Heading by gyrocompassing [deg], when the gyros resolve Earth rate (|ω| within 0.5–2×
    /// Earth rate on a static window); None otherwise.
    pub heading_deg: Option<f64>,
    /// Angle between the mean specific force and the body's up axis [deg].
    pub tilt_deg: f64,
    /// What is wrong, each with what to check; empty when the log is plausible.
    pub problems: Vec<String>,
    /// The subset of `problems` that only a unit, scale or clock slip explains (|f| far from
    /// gravity): `filter`, `explain` and `navigate` refuse to start on them without `--force`.
    pub unit_problems: Vec<String>,
    /// The gyro problems a unit slip likely explains (the mean rate at rest 57.3× or over 1000×
    /// Earth rate), which an uncalibrated MEMS gyro's bias can also give: refused unless the
    /// sensor is said to be MEMS grade.
    pub gyro_unit_problems: Vec<String>,
    /// Remarks that are not errors.
    pub notes: Vec<String>,
}

/// Checks `imu` on the window [first + skip_s, first + skip_s + window_s]; `lat` [rad] gives
/// local gravity (45° when None, which is within 0.3 % of every latitude); `tilted_ok` accepts a
/// mounting far from level.
pub fn check(
    imu: &ImuData,
    lat: Option<f64>,
    skip_s: f64,
    window_s: f64,
    tilted_ok: bool,
) -> ImuCheck {
    check_with(imu, lat, skip_s, window_s, tilted_ok, false)
}

/// [`check`] of the first 10 s, which something beside the IMU (GNSS fixes standing still)
/// says are at rest although their specific force spreads (engine vibration): the means are
/// judged as at rest — |ω̄| against Earth rate and the grade's biases, |f̄| against gravity.
pub fn check_at_witnessed_rest(imu: &ImuData, lat: Option<f64>) -> ImuCheck {
    check_with(imu, lat, 0.0, 10.0, true, true)
}

fn check_with(
    imu: &ImuData,
    lat: Option<f64>,
    skip_s: f64,
    window_s: f64,
    tilted_ok: bool,
    witnessed_rest: bool,
) -> ImuCheck {
    let s = &imu.samples;
    let mut intervals: Vec<f64> = s.windows(2).map(|w| w[1].t - w[0].t).collect();
    let median = imu.interval();
    let jitter = imu.jitter_rms();
    let gaps = intervals.iter().filter(|d| **d > 2.0 * median).count();
    intervals.sort_by(f64::total_cmp);
    let t_first = s.first().map(|x| x.t).unwrap_or(0.0);
    let mut m = Seen::of(imu, lat, t_first + skip_s, window_s);
    m.is_static |= witnessed_rest;
    let (w0, w1, f, w) = (m.w0, m.w1, m.f, m.w);
    let mut out = Said::default();
    let deg = 180.0 / std::f64::consts::PI;
    let mut heading = None;

    if m.count < 10 {
        out.problems.push(format!(
            "only {} samples between {:.3} s and {:.3} s: give --skip and --seconds inside the data ({:.3} .. {:.3} s)",
            m.count,
            w0,
            w1,
            t_first,
            s.last().map(|x| x.t).unwrap_or(0.0)
        ));
    } else if !m.is_static {
        out.moving(&m);
    } else {
        heading = out.at_rest(&m, tilted_ok);
    }
    out.clock(jitter, median, &intervals, gaps);
    ImuCheck {
        samples: s.len(),
        duration_s: imu.duration(),
        rate_hz: 1.0 / median,
        interval_min_s: intervals.first().copied().unwrap_or(0.0),
        interval_max_s: intervals.last().copied().unwrap_or(0.0),
        jitter_rms_s: jitter,
        gaps,
        window_s: [w0, w1],
        f_spread_mps2: m.spread,
        is_static: m.is_static,
        f_mean_mps2: [f.x, f.y, f.z],
        w_mean_radps: [w.x, w.y, w.z],
        gravity_ratio: m.gravity_ratio,
        gravity_mps2: m.g,
        earth_rate_ratio: m.earth_rate_ratio,
        roll_deg: m.roll * deg,
        pitch_deg: m.pitch * deg,
        heading_deg: heading,
        tilt_deg: m.tilt * deg,
        problems: out.problems,
        unit_problems: out.unit_problems,
        gyro_unit_problems: out.gyro_unit_problems,
        notes: out.notes,
    }
}

/// What the check window's samples show: their means, against gravity and Earth rate, and the
/// attitude that follows.
struct Seen {
    /// Start of the window [s].
    w0: f64,
    /// End of the window [s].
    w1: f64,
    /// Samples in the window (each with its own interval).
    count: usize,
    /// Mean specific force, FRD [m/s²].
    f: Vector3<f64>,
    /// Mean angular rate, FRD [rad/s].
    w: Vector3<f64>,
    /// RMS of the specific force about its mean [m/s²].
    spread: f64,
    /// At least ten samples and a spread below 0.5 m/s².
    is_static: bool,
    /// Local normal gravity [m/s²].
    g: f64,
    /// |mean f| / local gravity.
    gravity_ratio: f64,
    /// |mean ω| / Earth rate.
    earth_rate_ratio: f64,
    /// Roll from the mean specific force [rad].
    roll: f64,
    /// Pitch from the mean specific force [rad].
    pitch: f64,
    /// Angle between the mean specific force and the body's up axis [rad].
    tilt: f64,
}

impl Seen {
    /// The samples of `imu` from `w0` [s] over `window_s` [s] (at least ten intervals), with
    /// gravity at latitude `lat` [rad] (45° when None).
    fn of(imu: &ImuData, lat: Option<f64>, w0: f64, window_s: f64) -> Seen {
        let s = &imu.samples;
        // the window holds at least ten intervals (a clock read 1000× slow leaves one in 10 s)
        let tenth = s
            .iter()
            .skip_while(|x| x.t <= w0)
            .nth(10)
            .map(|x| x.t)
            .unwrap_or(f64::NEG_INFINITY);
        let w1 = (w0 + window_s).max(tenth);
        // means with each sample's own interval (the first sample's interval is unknown: skipped)
        let (mut sdv, mut sdth, mut sdt) = (Vector3::zeros(), Vector3::zeros(), 0.0);
        let mut rates: Vec<Vector3<f64>> = Vec::new();
        // |f| of 1-s means: vibration averages out inside one, and a body that turns over (a
        // turntable tumbling about a level axis) keeps |f| = g in each, where the window's mean
        // vector shrinks towards zero
        let (mut bdv, mut bdt, mut blocks) = (Vector3::zeros(), 0.0, Vec::new());
        for w in s.windows(2) {
            let (a, b) = (&w[0], &w[1]);
            if b.t <= w0 || b.t > w1 {
                continue;
            }
            let dt = b.t - a.t;
            sdv += b.dv;
            sdth += b.dtheta;
            sdt += dt;
            rates.push(b.dv / dt);
            bdv += b.dv;
            bdt += dt;
            if bdt >= 1.0 {
                blocks.push(bdv.norm() / bdt);
                (bdv, bdt) = (Vector3::zeros(), 0.0);
            }
        }
        if blocks.is_empty() && bdt > 0.0 {
            blocks.push(bdv.norm() / bdt);
        }
        let g = earth::gravity(lat.unwrap_or(std::f64::consts::FRAC_PI_4), 0.0);
        let omega = earth::OMEGA;
        let (f, w) = if sdt > 0.0 {
            (sdv / sdt, sdth / sdt)
        } else {
            (Vector3::zeros(), Vector3::zeros())
        };
        let spread = if rates.is_empty() {
            f64::NAN
        } else {
            (rates.iter().map(|r| (r - f).norm_squared()).sum::<f64>() / rates.len() as f64).sqrt()
        };
        let tilt = if f.norm() > 0.0 {
            (-f.z / f.norm()).clamp(-1.0, 1.0).acos()
        } else {
            f64::NAN
        };
        Seen {
            w0,
            w1,
            count: rates.len(),
            f,
            w,
            spread,
            is_static: rates.len() >= 10 && spread < 0.5,
            g,
            gravity_ratio: if blocks.is_empty() {
                f.norm() / g
            } else {
                blocks.iter().sum::<f64>() / blocks.len() as f64 / g
            },
            earth_rate_ratio: w.norm() / omega,
            roll: (-f.y).atan2(-f.z),
            pitch: f.x.atan2(f.y.hypot(f.z)),
            tilt,
        }
    }
}

/// What the check says: problems (and those a unit slip explains), and notes.
#[derive(Default)]
struct Said {
    /// What is wrong.
    problems: Vec<String>,
    /// The problems only a unit, scale or clock slip explains.
    unit_problems: Vec<String>,
    /// The gyro problems a unit slip likely explains.
    gyro_unit_problems: Vec<String>,
    /// Remarks that are not errors.
    notes: Vec<String>,
}

impl Said {
    /// On a window that is not static: only a specific force far from gravity (0.5 to 2 g) says
    /// something.
    fn moving(&mut self, m: &Seen) {
        let (w0, w1, g, gravity_ratio, spread) = (m.w0, m.w1, m.g, m.gravity_ratio, m.spread);
        // no vehicle averages 0.5 g or 2 g of specific force over seconds: a unit error shows
        // even while moving
        if !(0.5..2.0).contains(&gravity_ratio) {
            let p = format!(
                "mean specific force |f| (of 1-s means) = {} m/s² over {w0:.1}–{w1:.1} s is {}× local gravity ({g:.4} m/s²), \
                 which no vehicle averages over seconds, at rest or moving: the accelerometer unit or scale (accel_unit, per-count scale) or the clock is wrong{}",
                crate::io::units::sig3(gravity_ratio * g),
                crate::io::units::sig3(gravity_ratio),
                unit_hint(1.0 / gravity_ratio)
            );
            self.problems.push(p.clone());
            self.unit_problems.push(p);
        }
        self.notes.push(format!(
            "the window {w0:.1}–{w1:.1} s is not static (specific force varies by {spread:.2} m/s² RMS): \
             the gravity, Earth-rate and attitude checks need a static stretch (--skip, --seconds)"
        ));
    }

    /// On a static window: the specific force against gravity, the rate against Earth rate, the
    /// tilt (unless `tilted_ok`); returns the gyrocompass heading [deg] when the gyros resolve
    /// Earth rate.
    fn at_rest(&mut self, m: &Seen, tilted_ok: bool) -> Option<f64> {
        let (f, g, gravity_ratio) = (m.f, m.g, m.gravity_ratio);
        if (gravity_ratio - 1.0).abs() > 0.05 {
            let p = format!(
                "mean specific force |f| = {:.4} m/s² on a static stretch is {:.3}× local gravity ({g:.4} m/s²): \
                 the accelerometer unit (or scale, or the clock) is wrong — check accel_unit and [time] unit{}",
                f.norm(),
                gravity_ratio,
                unit_hint(g / f.norm())
            );
            // beyond 20 % no calibration error explains it
            if !(0.8..1.25).contains(&gravity_ratio) {
                self.unit_problems.push(p.clone());
            }
            self.problems.push(p);
        }
        self.earth_rate(m);
        let deg = 180.0 / std::f64::consts::PI;
        let (roll, pitch, tilt) = (m.roll, m.pitch, m.tilt);
        if tilt * deg > 45.0 && !tilted_ok {
            self.problems.push(format!(
                "the static specific force points {:.1}° away from the body's up axis (roll {:.1}°, pitch {:.1}°): \
                 if the vehicle stands level, [axes] is wrong (a flipped z gives roll 180°, swapped x and z \
                 pitch ±90°); --tilted accepts a tilted mounting",
                tilt * deg,
                roll * deg,
                pitch * deg
            ));
        }
        let earth_rate_ratio = m.earth_rate_ratio;
        if (0.5..2.0).contains(&earth_rate_ratio) {
            // level the mean rate with roll and pitch; its horizontal part points north
            let c = crate::nav::attitude::dcm_from_euler(roll, pitch, 0.0);
            let wl = c * m.w;
            let h = (-wl.y).atan2(wl.x).to_degrees().rem_euclid(360.0);
            // no "-0.0" and no "360.0" for north
            Some(if h.abs() < 1e-9 || h > 360.0 - 1e-9 {
                0.0
            } else {
                h
            })
        } else {
            self.notes.push(format!(
                "heading cannot be found from these gyros: |ω| is {earth_rate_ratio:.1}× Earth rate, so the \
                 gyro bias hides the Earth-rate direction; use --init or a GNSS course"
            ));
            None
        }
    }

    /// On a static window: the mean angular rate against Earth rate (57.3×, over 1000×, under
    /// 0.2× point at gyro_unit).
    fn earth_rate(&mut self, m: &Seen) {
        let (w, earth_rate_ratio) = (m.w, m.earth_rate_ratio);
        let deg = 180.0 / std::f64::consts::PI;
        let r2d = 180.0 / std::f64::consts::PI;
        if (earth_rate_ratio / r2d - 1.0).abs() < 0.05 {
            let p = format!(
                "mean angular rate on a static stretch is {earth_rate_ratio:.2}× Earth rate, within 5 % of 57.3 (degrees per radian): the gyro values look like deg/s read as rad/s — check gyro_unit"
            );
            self.problems.push(p.clone());
            self.gyro_unit_problems.push(p);
        } else if earth_rate_ratio > 1000.0 {
            let p = format!(
                "mean angular rate {:.4} deg/s on a static stretch is {:.0}× Earth rate (even MEMS gyro \
                 biases stay below ~100×): check gyro_unit (deg/s read as rad/s gives 57.3×)",
                w.norm() * deg,
                earth_rate_ratio
            );
            self.problems.push(p.clone());
            self.gyro_unit_problems.push(p);
        } else if earth_rate_ratio < 0.2 {
            self.problems.push(format!(
                "mean angular rate {:.3e} deg/h on a static stretch is {:.3}× Earth rate (15.04 deg/h), which \
                 any gyro at rest measures: check gyro_unit (rad/s read as deg/s gives 1/57.3)",
                w.norm() * deg * 3600.0,
                earth_rate_ratio
            ));
        }
    }

    /// Notes on the clock: jitter above 1 % of the `median` interval [s], and `gaps` (intervals
    /// over twice the median; `intervals` [s] sorted).
    fn clock(&mut self, jitter: f64, median: f64, intervals: &[f64], gaps: usize) {
        if jitter > 0.01 * median {
            self.notes.push(format!(
                "the clock jitters: intervals {:.6}–{:.6} s, RMS {:.2e} s about the median {median:.6} s \
                 (each sample's own interval is used)",
                intervals.first().copied().unwrap_or(0.0),
                intervals.last().copied().unwrap_or(0.0),
                jitter
            ));
        }
        if gaps > 0 {
            self.notes.push(format!(
                "{gaps} intervals longer than twice the median (the longest {:.4} s)",
                intervals.last().copied().unwrap_or(0.0)
            ));
        }
    }
}

/// What the first seconds of a log say before free-inertial navigation (`navigate`): warnings,
/// and the unit, scale or clock slip that stops it.
#[derive(Debug, Clone)]
pub struct StartCheck {
    /// The problems that are only warnings here (a start that moves or a tilted mounting are
    /// legitimate), a gyro unit problem with the MEMS-bias alternative said.
    pub warnings: Vec<String>,
    /// The first problem only a unit, scale or clock slip explains.
    pub unit_problem: Option<String>,
    /// The whole check of the first seconds.
    pub head: ImuCheck,
}

/// Checks the first 10 s `head` as `imu-check` does (a tilted mounting accepted), `lat` [rad]
/// giving local gravity.
pub fn start_check(head: &ImuData, lat: f64) -> StartCheck {
    let check = check(head, Some(lat), 0.0, 10.0, true);
    let warnings = check
        .problems
        .iter()
        .filter(|p| !check.unit_problems.contains(p))
        .map(|p| {
            if check.gyro_unit_problems.contains(p) {
                format!("{p} (or an uncalibrated MEMS gyro's bias)")
            } else {
                p.clone()
            }
        })
        .collect();
    StartCheck {
        warnings,
        unit_problem: check.unit_problems.first().cloned(),
        head: check,
    }
}

/// The likely slip behind a specific force `k` times too small (`k` = gravity / |f|), when it
/// is one of the usual factors.
fn unit_hint(k: f64) -> String {
    [
        (
            crate::io::units::STANDARD_GRAVITY,
            "the values look like g read as m/s²: accel_unit = \"g\" (or \"g*s\" for increments)",
        ),
        (
            crate::io::units::STANDARD_GRAVITY * 1e-3,
            "the values look like mg: accel_unit = \"mg\"",
        ),
        (
            1.0 / crate::io::units::STANDARD_GRAVITY,
            "the values look like m/s^2 described as g: accel_unit = \"m/s^2\"",
        ),
        (
            1e3,
            "a factor 1000 off: time in ms read as s ([time] unit) divides the increments by a 1000× longer interval, or mm/s read as m/s",
        ),
        (
            1e-3,
            "a factor 1000 off: time in s read as ms ([time] unit), or m/s read as mm/s",
        ),
    ]
    .iter()
    .find(|(r, _)| k.is_finite() && (k / r - 1.0).abs() < 0.05)
    .map(|(_, h)| format!("; {h}"))
    .unwrap_or_default()
}

/// Judges the IMU's data after its first seconds, a window of [`crate::io::imu_stream::HEAD_SECONDS`]
/// at a time as the stream hands them out, for the slips the first seconds could not show: a
/// mean specific force no vehicle averages (0.5–2 g, any window), and — when the first seconds
/// were not at rest — the first window at rest against gravity and Earth rate.
#[derive(Debug, Clone)]
pub struct WindowJudge {
    /// Latitude for local gravity [rad].
    lat: f64,
    /// A window at rest has been judged already (the first seconds, or a later one).
    rest_judged: bool,
    /// Gyro unit problems are warnings (a MEMS gyro's bias can give them).
    gyro_warn_only: bool,
    /// What `--zupt` or `--static-aid` holds the windows to.
    rest_claim: Option<RestClaim>,
    /// Time of the run's first sample [s] (times are said from it).
    t_first: f64,
    /// What says the vehicle is at rest, beside the IMU (whose steady turn on a smooth curve
    /// looks like rest): None, nothing (the gyros of later windows are not judged).
    rest_witness: Option<RestWitness>,
}

/// What says, beside the IMU, that the vehicle stands still in a stretch.
#[derive(Debug, Clone)]
pub enum RestWitness {
    /// A static vehicle is given (`--static-aid`).
    Static,
    /// GNSS speeds: (t [s], horizontal speed [m/s]) of every fix.
    Speeds(Vec<(f64, f64)>),
}

/// Fastest a GNSS fix may show in a stretch taken as at rest [m/s].
pub const REST_SPEED_MAX: f64 = 0.3;

impl RestWitness {
    /// True when the witness says the vehicle stands still from `t0` to `t1` [s] (static, or
    /// at least one GNSS fix there and none faster than [`REST_SPEED_MAX`]).
    pub fn at_rest(&self, t0: f64, t1: f64) -> bool {
        match self {
            RestWitness::Static => true,
            RestWitness::Speeds(v) => {
                let mut inside = v.iter().filter(|x| x.0 >= t0 && x.0 <= t1).peekable();
                inside.peek().is_some() && inside.all(|x| x.1 <= REST_SPEED_MAX)
            }
        }
    }

    /// True when the witness says the vehicle moves from `t0` to `t1` [s] (a GNSS fix there
    /// faster than 1 m/s).
    pub fn moving(&self, t0: f64, t1: f64) -> bool {
        match self {
            RestWitness::Static => false,
            RestWitness::Speeds(v) => v.iter().any(|x| x.0 >= t0 && x.0 <= t1 && x.1 > 1.0),
        }
    }
}

/// The stretch `t0`–`t1` [s] of a run whose first sample is at `t_first` [s], in words: on the
/// data's clock when that starts near 0, else from the first sample and on the data's clock.
pub fn span_words(t0: f64, t1: f64, t_first: f64) -> String {
    if t_first.abs() < 1.0 {
        format!("{t0:.1}–{t1:.1} s")
    } else {
        format!(
            "{:.1}–{:.1} s from the first IMU sample (t = {t0:.1} s on the data's clock)",
            t0 - t_first,
            t1 - t_first
        )
    }
}

/// A run said to be at rest (no translation: `--zupt`, `--static-aid`; it may turn in place,
/// as on a turntable) moves where, in a window that does not turn, its 1-s mean specific forces
/// spread by more than this [m/s²] (30 mg: far above engine vibration's, which 1-s means
/// average out) …
pub const MOVING_F_SPREAD: f64 = 0.3;
/// … or its mean specific force moves this far from the last still window's with no turn
/// between [m/s²] (a constant acceleration begun or ended).
pub const MOVING_F_STEP: f64 = 0.3;
/// A window turns when its 1-s mean angular rates spread by more than this, or its mean rate
/// differs by more than this from the first window's [rad/s] (0.2 deg/s: a slow turntable
/// tilt turns; a gyro's bias, in both, cancels).
pub const TURNING_RATE: f64 = 0.2 * std::f64::consts::PI / 180.0;

/// What a claim of rest holds a run to, window by window: translation shows in the specific
/// force of windows that do not turn (turning in place is allowed).
#[derive(Debug, Clone)]
pub struct RestClaim {
    /// The option that makes the claim (`--zupt`, `--static-aid`).
    option: &'static str,
    /// Mean specific force of the last window that did not turn, FRD [m/s²]; None after a turn.
    reference: Option<Vector3<f64>>,
    /// Mean angular rate of the first window, FRD [rad/s] (the gyro bias, at rest).
    w_first: Option<Vector3<f64>>,
}

impl RestClaim {
    /// Judges the window `data` (consecutive samples, FRD increments; times said from the run's
    /// first sample at `t_first` [s]): the claim and the motion that contradicts it, in words.
    fn judge(&mut self, data: &ImuData, t_first: f64) -> Option<String> {
        let window = &data.samples;
        if window.len() < 12 {
            return None;
        }
        let e = crate::estimate::align::rest_evidence(data, window.len(), earth::gravity(0.0, 0.0))
            .first()
            .copied()?;
        // turning: against the first window's mean rate (a MEMS gyro's bias cancels)
        let w0 = *self.w_first.get_or_insert(e.w_mean);
        if e.w_spread > TURNING_RATE || (e.w_mean - w0).norm() > TURNING_RATE {
            self.reference = None;
            return None;
        }
        let step = self.reference.map(|r| (e.f_mean - r).norm()).unwrap_or(0.0);
        self.reference = Some(e.f_mean);
        let (t0, t1) = (window[0].t, window[window.len() - 1].t);
        (e.f_spread > MOVING_F_SPREAD || step > MOVING_F_STEP).then(|| {
            format!(
                "{} says the vehicle does not move for the whole run, but the IMU accelerates at {} without turning: \
                 its 1-s mean specific forces spread by {:.3} m/s² RMS (at rest <= {MOVING_F_SPREAD}) and its mean moved by \
                 {step:.3} m/s² from the last still window's (<= {MOVING_F_STEP}): {}",
                self.option,
                span_words(t0, t1, t_first),
                e.f_spread,
                if self.option == "--zupt" {
                    "leave out --zupt (it adds a zero-velocity update at every aiding epoch), or cut the IMU file to the stretch at rest"
                } else {
                    "aid a moving run with GNSS fixes (--aid), or cut the IMU file to the stretch at rest"
                }
            )
        })
    }
}

impl WindowJudge {
    /// A judge for a run at latitude `lat` [rad] whose first seconds were `head` (their check);
    /// `gyro_warn_only` with a MEMS grade.
    pub fn new(lat: f64, head: &ImuCheck, gyro_warn_only: bool) -> WindowJudge {
        WindowJudge {
            lat,
            rest_judged: head.is_static,
            gyro_warn_only,
            rest_claim: None,
            t_first: head.window_s[0],
            rest_witness: None,
        }
    }

    /// Lets the gyros of the first later window at rest be judged where `witness` confirms
    /// the rest (without one only the specific force of later windows is judged: a steady turn
    /// on a smooth curve looks like rest to the IMU and reads like a gyro bias or a unit slip).
    pub fn witness_rest(&mut self, witness: RestWitness) {
        self.rest_witness = Some(witness);
    }

    /// Holds every window to `option`'s claim that the vehicle does not move for the whole
    /// run (`--zupt`, `--static-aid`; turning in place allowed), the first seconds `head`
    /// first; the words of the motion found there.
    pub fn claim_rest(
        &mut self,
        option: &'static str,
        head: &[crate::io::imu::ImuSample],
    ) -> Option<String> {
        let mut claim = RestClaim {
            option,
            reference: None,
            w_first: None,
        };
        let head = ImuData {
            samples: head.to_vec(),
        };
        let found = claim.judge(&head, self.t_first);
        self.rest_claim = Some(claim);
        found
    }

    /// The unit, scale or clock slip `window` (consecutive samples, FRD increments) shows, in
    /// words that begin with its time span ("at 20.0–30.0 s: …"), and whether it is only a
    /// warning; None when it shows none.
    pub fn judge(&mut self, window: &[crate::io::imu::ImuSample]) -> Option<(String, bool)> {
        if window.len() < 12 {
            return None;
        }
        let data = ImuData {
            samples: window.to_vec(),
        };
        if let Some(claim) = self.rest_claim.as_mut() {
            if let Some(p) = claim.judge(&data, self.t_first) {
                return Some((p, false));
            }
        }
        let (t0, t1) = (window[0].t, window[window.len() - 1].t);
        let m = Seen::of(&data, Some(self.lat), t0, t1 - t0);
        let mut said = Said::default();
        if !m.is_static {
            said.moving(&m);
        } else if !self.rest_judged
            && self
                .rest_witness
                .as_ref()
                .is_some_and(|w| w.at_rest(t0, t1))
        {
            self.rest_judged = true;
            said.at_rest(&m, true);
        } else if !(0.5..2.0).contains(&m.gravity_ratio) {
            // at rest again: only what no calibration error explains
            said.moving(&m);
        }
        let at = |p: &String| format!("at {}: {p}", span_words(t0, t1, self.t_first));
        if let Some(p) = said.unit_problems.first() {
            return Some((at(p), false));
        }
        said.gyro_unit_problems
            .first()
            .map(|p| (at(p), self.gyro_warn_only))
            .or_else(|| self.turns_while_gnss_stands(window).map(|p| (p, true)))
    }
}

impl WindowJudge {
    /// The aiding's clock against the IMU's, in words, when the window (consecutive samples)
    /// turns at over [`CLOCK_TURN_RATE`] on average while every GNSS fix in it stands still: a
    /// fix then describes another moment than its stamp says (a late or early aiding file,
    /// another time system). A warning only: a vehicle can turn in place.
    fn turns_while_gnss_stands(&self, window: &[crate::io::imu::ImuSample]) -> Option<String> {
        let Some(RestWitness::Speeds(_)) = &self.rest_witness else {
            return None;
        };
        let (t0, t1) = (window[0].t, window[window.len() - 1].t);
        let span = t1 - t0 + (t1 - t0) / (window.len() - 1) as f64;
        let turned: Vector3<f64> = window.iter().map(|s| s.dtheta).sum();
        let rate = turned.norm() / span;
        (rate > CLOCK_TURN_RATE && self.rest_witness.as_ref()?.at_rest(t0, t1)).then(|| {
            format!(
                "at {}: the IMU turns {:.0}° at {:.1} deg/s on average while every GNSS fix there stands still (under {REST_SPEED_MAX} m/s): \
                 the aiding's clock is likely off against the IMU's (a late or early aiding file, another time system or --clock-offset), \
                 unless the vehicle turns in place",
                span_words(t0, t1, self.t_first),
                turned.norm().to_degrees(),
                rate.to_degrees()
            )
        })
    }
}

/// A window whose mean angular rate is over this [rad/s] (10 deg/s: 100° in a 10-s window) turns,
/// whatever a gyro bias adds (a MEMS gyro's is a few deg/s at most), faster than a car can at
/// the speed of a GNSS fix taken as at rest ([`REST_SPEED_MAX`] plus 3 σ of its noise: 0.6 m/s
/// on a 5-m radius is 6.9 deg/s).
pub const CLOCK_TURN_RATE: f64 = 10.0 * std::f64::consts::PI / 180.0;

/// The stream's check of each window after the head with `judge`: a slip ends the run with an
/// error naming the IMU file `name` and the window, unless `force` (then, like a warning-only
/// gyro problem, it is said once on stderr, `why_warn` telling why it is only a warning).
pub fn window_check(
    mut judge: WindowJudge,
    name: String,
    force: bool,
    why_warn: &'static str,
) -> crate::io::imu_stream::WindowCheck {
    let mut warned = false;
    Box::new(move |w| {
        let Some((p, warn_only)) = judge.judge(w) else {
            return Ok(());
        };
        if !(warn_only || force) {
            anyhow::bail!(
                "--imu {name}: {p} (after the first 10 s: `sinsmodel imu-check --skip S` shows that stretch; --force runs anyway)"
            );
        }
        if !warned {
            warned = true;
            let why = if force {
                "--force given"
            } else if p.contains("the aiding's clock") {
                "not refused"
            } else {
                why_warn
            };
            crate::io::warnings::warn(&format!("--imu {name}: {p} ({why})"));
        }
        Ok(())
    })
}

/// The smallest gyro bias [deg/h] the static window of `check` shows (|ω̄| − Earth rate); None
/// when the window is not at rest.
pub fn least_gyro_bias_deg_h(check: &ImuCheck) -> Option<f64> {
    check
        .is_static
        .then(|| (check.earth_rate_ratio - 1.0).max(0.0) * earth::OMEGA.to_degrees() * 3600.0)
}

/// A gyro bias at rest beyond what the sensor grade `grade` (None: navigation) has, or on an
/// axis five σ of the gyro-bias prior given for it (`prior_deg_h`, x y z) when that is more, in
/// words with its likely cause (deg/s read as rad/s), for the first seconds' check `check`; None
/// within it, or with a MEMS grade (whose biases reach what a unit slip gives). Each axis's
/// least bias is its mean rate less Earth's whole rate. The limits are far above the grades'
/// priors: 10 s "at rest" by the specific force can still rock (the parked RLG log's first
/// seconds turn at 55 deg/h).
pub fn gyro_bias_beyond_grade(
    check: &ImuCheck,
    grade: Option<&str>,
    prior_deg_h: [Option<f64>; 3],
) -> Option<String> {
    let (grade_limit, grade_words) = match grade {
        None => (
            150.0,
            "a navigation-grade gyro's (the default grade; prior 0.02 deg/h",
        ),
        Some("tactical") => (300.0, "a tactical-grade gyro's (prior 1 deg/h"),
        _ => return None,
    };
    least_gyro_bias_deg_h(check)?;
    let deg_h = 180.0 / std::f64::consts::PI * 3600.0;
    let earth_deg_h = earth::OMEGA * deg_h;
    (0..3).find_map(|i| {
        let b = (check.w_mean_radps[i].abs() * deg_h - earth_deg_h).max(0.0);
        // a gyro-bias prior given says what bias is plausible: five of its σ, not below the grade's
        let (limit, words) = match prior_deg_h[i] {
            Some(p) if 5.0 * p > grade_limit => (
                5.0 * p,
                format!(
                    "five σ of the gyro-bias prior given for {} (--prior: {} deg/h",
                    ["x", "y", "z"][i],
                    crate::io::units::sig3(p)
                ),
            ),
            _ => (grade_limit, grade_words.to_string()),
        };
        (b > limit).then(|| {
            format!(
                "at rest the gyros read {} deg/h ({}× Earth rate): on {} a bias of at least {} deg/h, beyond {words}, \
                 at most {limit} deg/h accepted); the gyro values may be deg/s read as rad/s (57.3× the true rate: check gyro_unit), or the \
                 sensor is of a lower grade (--grade tactical or mems, or --prior 'eps_*=…')",
                crate::io::units::sig3(check.earth_rate_ratio * earth_deg_h),
                crate::io::units::sig3(check.earth_rate_ratio),
                ["x", "y", "z"][i],
                crate::io::units::sig3(b)
            )
        })
    })
}
