//! `--init auto`: the initial navigation state found in the data, NED/FRD, SI.
//!
//! The IMU is reduced to quarter-second means of specific force and angular rate (each
//! increment over its own interval, so a jittered clock gives the uniform clock's means). Then:
//!
//! - **Quiet start**: the first stretch at rest by the tests of [`crate::estimate::align`]
//!   (angular-rate spread, |f| against gravity), its 1-s means steady, its mean rate no more
//!   than the Earth rate and the gyro-bias prior allow (a steady turn is not rest), and GNSS
//!   fixes inside it showing no motion (a steady straight drive passes every IMU test). Roll
//!   and pitch from its first 10 s; the run starts there, at rest. Yaw by gyrocompassing when
//!   the bias prior and the scatter of the rates give 1° over at least 60 s; else from the
//!   drive-off: the IMU's own velocity since the rest (specific force levelled, turned by the
//!   heading change the gyros see, the force at rest taken off) matched to the GNSS course at
//!   the first fast fix within 10 s of the motion. No assumption on how the IMU sits in the
//!   vehicle, which may turn while it drives off: the direction of travel from the IMU's x
//!   axis (the mounting yaw) comes out too. The IMU's and the GNSS's speeds must agree.
//! - **Moving start** (no confirmed rest before the GNSS shows motion): the run starts at the
//!   first GNSS fix that is fast beyond its noise, confirmed by the next, with fixes about 1 s
//!   either side over which the vehicle drives straight; yaw is the GNSS course (this assumes
//!   the IMU's x axis along the direction of travel, and says so), roll and pitch from the
//!   specific force over that span less the GNSS acceleration over the same span.
//!
//! Each found angle comes with a 1-σ the filter starts from.

use crate::estimate::align::{STATIC_F_SPREAD, STATIC_G_ERROR, STATIC_W_SPREAD};
use crate::io::imu::ImuSample;
use crate::nav::attitude::{dcm_from_euler, euler_from_dcm};
use crate::nav::earth;
use crate::nav::strapdown::NavState;
use anyhow::{bail, Result};
use nalgebra::{Matrix3, Rotation3, UnitQuaternion, Vector3};

/// Length of one block of IMU means [s].
pub const BLOCK_S: f64 = 0.25;
/// Shortest quiet stretch that levels the IMU [s].
pub const MIN_QUIET_S: f64 = 3.0;
/// Shortest quiet stretch for gyrocompassing [s].
pub const GYROCOMPASS_S: f64 = 60.0;
/// Largest heading 1-σ gyrocompassing may give before the drive-off is used instead [rad] (1°).
pub const GYROCOMPASS_MAX_SIGMA: f64 = std::f64::consts::PI / 180.0;
/// Default GNSS speed above which the course gives the heading [m/s].
pub const DEFAULT_SPEED: f64 = 3.0;
/// Largest horizontal GNSS acceleration of a calm span for a moving start [m/s²].
const CALM_ACCEL: f64 = 0.3;
/// Seconds of IMU data searched for a start before giving up [s].
pub const SEARCH_S: f64 = 1800.0;
/// Heading 1-σ allowed for the vehicle turning during a drive-off, or for a course that is not
/// the IMU's x axis (side slip) at a moving start [rad] (2°).
const COURSE_SLACK: f64 = 2.0 * std::f64::consts::PI / 180.0;

/// Mean specific force and angular rate over one block, FRD.
#[derive(Debug, Clone, Copy)]
pub struct Block {
    /// Time of the block's first increment's start [s].
    pub t_start: f64,
    /// Time of its last increment's end [s] (a sample time).
    pub t_end: f64,
    /// Mean specific force [m/s²].
    pub f: Vector3<f64>,
    /// Mean angular rate [rad/s].
    pub w: Vector3<f64>,
}

/// Builds [`Block`]s from samples as they come.
#[derive(Debug, Default)]
pub struct Blocks {
    /// The finished blocks.
    pub blocks: Vec<Block>,
    prev_t: Option<f64>,
    start: f64,
    sum_dv: Vector3<f64>,
    sum_dth: Vector3<f64>,
}

impl Blocks {
    /// Adds one sample; `first_interval` [s] is taken as the first sample's interval.
    pub fn push(&mut self, s: &ImuSample, first_interval: f64) {
        if self.prev_t.is_none() {
            self.start = s.t - first_interval;
        }
        self.sum_dv += s.dv;
        self.sum_dth += s.dtheta;
        self.prev_t = Some(s.t);
        let span = s.t - self.start;
        if span >= BLOCK_S * (1.0 - 1e-9) {
            self.blocks.push(Block {
                t_start: self.start,
                t_end: s.t,
                f: self.sum_dv / span,
                w: self.sum_dth / span,
            });
            self.start = s.t;
            self.sum_dv = Vector3::zeros();
            self.sum_dth = Vector3::zeros();
        }
    }

    /// Seconds covered by the finished blocks.
    pub fn seconds(&self) -> f64 {
        match (self.blocks.first(), self.blocks.last()) {
            (Some(a), Some(b)) => b.t_end - a.t_start,
            _ => 0.0,
        }
    }
}

/// One GNSS fix as `--init auto` uses it.
#[derive(Debug, Clone, Copy)]
pub struct Fix {
    /// Time [s].
    pub t: f64,
    /// Latitude, longitude [rad], height [m].
    pub pos: [f64; 3],
    /// Horizontal position 1-σ [m] (the larger of north and east).
    pub sigma_pos: f64,
    /// NED velocity [m/s]: the receiver's, or from the neighbouring positions.
    pub v: Option<Vector3<f64>>,
    /// 1-σ of each velocity component [m/s].
    pub sigma_v: f64,
    /// The velocity was derived from the neighbouring positions (not the receiver's).
    pub derived: bool,
}

impl Fix {
    /// A fix from an aiding file's position `p` and its receiver velocity `v`, when it has one.
    pub fn from_aiding(
        p: &crate::io::aiding::PositionFix,
        v: Option<&crate::io::aiding::VelocityFix>,
    ) -> Fix {
        Fix {
            t: p.t,
            pos: [p.lat, p.lon, p.h],
            sigma_pos: p.sigma[0].max(p.sigma[1]),
            v: v.map(|v| Vector3::from(v.v_ned)),
            sigma_v: v.map(|v| v.sigma).unwrap_or(0.0),
            derived: false,
        }
    }

    fn speed(&self) -> f64 {
        self.v.map(|v| v.x.hypot(v.y)).unwrap_or(0.0)
    }

    /// Moving beyond doubt: horizontal speed above 0.5 m/s and above 4 σ of its noise (a
    /// speed from noisy positions at rest exceeds 3 σ at one fix in a hundred).
    fn moving(&self) -> bool {
        self.v.is_some() && self.speed() > 0.5_f64.max(4.0 * self.sigma_v)
    }
}

/// The neighbours of fix `k` for a central difference: the nearest fix at least 0.5 s before
/// and after it (the ends themselves when there is none), at most 5 s apart; None otherwise.
fn neighbours(fixes: &[Fix], k: usize) -> Option<(usize, usize)> {
    let t = fixes[k].t;
    let a = (0..k).rev().find(|&j| t - fixes[j].t >= 0.5).unwrap_or(k);
    let b = (k + 1..fixes.len())
        .find(|&j| fixes[j].t - t >= 0.5)
        .unwrap_or(k);
    let dt = fixes[b].t - fixes[a].t;
    (a != b && dt > 0.0 && dt <= 5.0).then_some((a, b))
}

/// The NED velocity between fixes `a` and `b` from their positions, and its 1-σ [m/s].
fn velocity_between(fixes: &[Fix], a: usize, b: usize) -> (Vector3<f64>, f64) {
    let (pa, pb) = (fixes[a].pos, fixes[b].pos);
    let dt = fixes[b].t - fixes[a].t;
    let lat = pa[0];
    let rm = earth::radius_meridian(lat) + pa[2];
    let rn = earth::radius_transverse(lat) + pa[2];
    let v = Vector3::new(
        (pb[0] - pa[0]) * rm / dt,
        (pb[1] - pa[1]) * rn * lat.cos() / dt,
        -(pb[2] - pa[2]) / dt,
    );
    (v, fixes[a].sigma_pos.hypot(fixes[b].sigma_pos) / dt)
}

/// Fills the velocity of fixes that have none from the neighbouring positions (central
/// differences over 1 to 5 s, [`neighbours`]; σ from the positions' σ).
pub fn velocities_from_positions(fixes: &mut [Fix]) {
    for k in 0..fixes.len() {
        if fixes[k].v.is_some() {
            continue;
        }
        if let Some((a, b)) = neighbours(fixes, k) {
            let (v, sigma) = velocity_between(fixes, a, b);
            fixes[k].v = Some(v);
            fixes[k].sigma_v = sigma;
            fixes[k].derived = true;
        }
    }
}

/// Checks the receiver's velocities against the positions: where a central difference of
/// positions exists, the two must agree within 5 σ plus 1 m/s (the acceleration over the
/// difference's span); more than a tenth of them disagreeing (swapped or negated columns, a
/// wrong unit) is refused naming the first.
pub fn check_velocities(fixes: &[Fix], receiver: &[bool]) -> Result<()> {
    let (mut checked, mut bad) = (0usize, Vec::new());
    // the height rate from the positions against the receiver's down velocity: Σ u r, Σ u², Σ r²,
    // Σ σ_v²
    let mut vertical = [0.0f64; 4];
    for k in 0..fixes.len() {
        let (true, Some(v)) = (receiver[k], fixes[k].v) else {
            continue;
        };
        let Some((a, b)) = neighbours(fixes, k) else {
            continue;
        };
        let (vp, sp) = velocity_between(fixes, a, b);
        vertical[0] += v.z * vp.z;
        vertical[1] += v.z * v.z;
        vertical[2] += vp.z * vp.z;
        vertical[3] += fixes[k].sigma_v * fixes[k].sigma_v;
        checked += 1;
        let d = ((v - vp).x).hypot((v - vp).y);
        if d > 5.0 * fixes[k].sigma_v.hypot(sp) + 1.0 {
            bad.push((k, v, vp));
        }
    }
    if checked > 0 && bad.len() * 10 > checked {
        let (k, v, vp) = bad[0];
        bail!(
            "--aid: the aiding file's velocities disagree with its positions at {} of {checked} fixes (first at t = {:.3} s: v_n, v_e = {:.2}, {:.2} m/s given, {:.2}, {:.2} m/s from the positions): swapped, negated or mis-scaled velocity columns? (--aid-use pos leaves them out)",
            bad.len(),
            fixes[k].t,
            v.x,
            v.y,
            vp.x,
            vp.y
        );
    }
    check_vertical_scale(vertical, checked)
}

/// The heights against the receiver's vertical velocities over `n` fixes, from the sums `s`
/// (Σ v_d·ṽ_d, Σ v_d², Σ ṽ_d² [m²/s²], ṽ_d from the height differences): the least-squares
/// scale of the height rate on the velocity is 1 for one unit and sign; feet give 3.28, an up
/// velocity read as down −1, heights that do not move (in km, or a constant) 0. Noise in the
/// velocities shrinks the scale towards 0 (it adds to Σ v_d² alone), so a scale under 0.3 is
/// judged only where the velocities' RMS is over 3 times their stated σ (`s[3]` = Σ σ_v²);
/// judged where that RMS is 0.1 m/s or more over 20 fixes or more, and refused when the scale
/// is over 1.3 or under 0.3 (−0.3 where the velocities' noise could explain it), beyond 5 σ of
/// its fit.
fn check_vertical_scale(s: [f64; 4], n: usize) -> Result<()> {
    if n < 20 || s[1] < n as f64 * 0.01 {
        return Ok(());
    }
    let k = s[0] / s[1];
    // residual Σ (ṽ − k v)² = Σṽ² − k Σ v ṽ
    let sigma = ((s[2] - k * s[0]).max(0.0) / (n - 1) as f64 / s[1]).sqrt();
    let beyond = |bound: f64| (k - bound).abs() > 5.0 * sigma;
    let low = if s[1] > 9.0 * s[3] { 0.3 } else { -0.3 };
    if !((k > 1.3 && beyond(1.3)) || (k < low && beyond(low))) {
        return Ok(());
    }
    const FEET_PER_METRE: f64 = 1.0 / 0.3048;
    let cause = if (k / FEET_PER_METRE - 1.0).abs() < 0.1 {
        "heights in feet (3.28 per metre)?"
    } else if (k + 1.0).abs() < 0.3 {
        "a vertical velocity up read as down (or heights as depths)?"
    } else if k.abs() < 0.3 {
        "heights that hardly move (in km, or held constant)?"
    } else {
        "heights or vertical velocities mis-scaled?"
    };
    bail!(
        "--aid: the aiding file's heights change {k:.2} ± {sigma:.2} times as fast as its vertical velocities say (over {n} fixes, \
         vertical speed {:.2} m/s RMS): {cause} (--aid-use pos leaves the velocities out)",
        (s[1] / n as f64).sqrt()
    )
}

/// Priors that decide how the heading can be found.
#[derive(Debug, Clone, Copy)]
pub struct Priors {
    /// Gyro bias 1-σ [rad/s].
    pub gyro_bias: f64,
    /// Accelerometer bias 1-σ [m/s²].
    pub accel_bias: f64,
    /// GNSS speed above which the course is used [m/s].
    pub speed: f64,
    /// Gyro scale-factor 1-σ [1] (a heading change the gyros measure is off by this fraction).
    pub gyro_scale: f64,
}

/// What `--init auto` found.
#[derive(Debug, Clone)]
pub struct AutoInit {
    /// The initial state (its time a sample time; the run starts after it).
    pub state: NavState,
    /// 1-σ of roll/pitch (tilt about north and east) [rad].
    pub sigma_tilt: f64,
    /// 1-σ of the heading [rad].
    pub sigma_yaw: f64,
    /// How each part was found, one line each, for the terminal.
    pub report: Vec<String>,
    /// Direction of travel from the IMU's x axis, positive to the right [rad], when a drive-off
    /// showed it (the mounting yaw).
    pub travel_from_x: Option<f64>,
}

/// The outcome of looking at the data read so far.
#[derive(Debug)]
pub enum Found {
    /// A start was found.
    Done(Box<AutoInit>),
    /// More data are needed to decide.
    NeedMore,
}

fn tilt_from(f: Vector3<f64>) -> (f64, f64) {
    (
        (-f.y).atan2(-f.z),
        f.x.atan2((f.y * f.y + f.z * f.z).sqrt()),
    )
}

fn mean_of(blocks: &[Block]) -> (Vector3<f64>, Vector3<f64>) {
    let mut span = 0.0;
    let (mut f, mut w) = (Vector3::zeros(), Vector3::zeros());
    for b in blocks {
        let d = b.t_end - b.t_start;
        f += b.f * d;
        w += b.w * d;
        span += d;
    }
    (f / span, w / span)
}

/// One whole second (4 blocks): its span, mean specific force and rate, and whether it passes
/// the tests of rest (angular-rate spread, |f| against gravity).
struct Second {
    t_start: f64,
    t_end: f64,
    f: Vector3<f64>,
    w: Vector3<f64>,
    ok: bool,
}

fn seconds(blocks: &[Block], g: f64) -> Vec<Second> {
    let per = (1.0 / BLOCK_S).round() as usize;
    blocks
        .chunks(per)
        .filter(|c| c.len() == per)
        .map(|c| {
            let (fm, wm) = mean_of(c);
            let k = c.len() as f64;
            let ws = (c.iter().map(|b| (b.w - wm).norm_squared()).sum::<f64>() / k).sqrt();
            Second {
                t_start: c[0].t_start,
                t_end: c[per - 1].t_end,
                f: fm,
                w: wm,
                // the specific force's spread is left out: vibration of a parked vehicle with
                // its engine on spreads quarter-second means without moving it
                ok: ws <= STATIC_W_SPREAD && (fm.norm() - g).abs() <= STATIC_G_ERROR,
            }
        })
        .collect()
}

/// The first stretch at rest: from the first second that passes the tests of rest (and the
/// next one too), on while the seconds pass them (one failing second between two passing ones
/// is a bump, not motion), their mean force and rate stay within twice the rest spreads of the
/// stretch's mean (a smooth drive-off changes the mean, not the spread), and the GNSS shows no
/// motion. Returns (first second, end second, ended) with `ended` false while more data could
/// extend it.
fn quiet_stretch(
    secs: &[Second],
    motion_t: Option<f64>,
    at_end: bool,
    min_s: usize,
) -> Option<(usize, usize, bool)> {
    let n = secs.len();
    let before_motion = |k: usize| motion_t.is_none_or(|tm| secs[k].t_end <= tm - 0.5);
    let mut k = 0;
    while k < n {
        if !(secs[k].ok && before_motion(k)) {
            if !before_motion(k) {
                return None;
            }
            k += 1;
            continue;
        }
        let (mut fsum, mut wsum) = (secs[k].f, secs[k].w);
        let mut e = k + 1;
        let mut ended = false;
        while e < n {
            let m = (e - k) as f64;
            let (fbar, wbar) = (fsum / m, wsum / m);
            let s = &secs[e];
            let bump = !s.ok && e + 1 < n && secs[e + 1].ok;
            let undecided = !s.ok && e + 1 == n && !at_end;
            if undecided {
                break;
            }
            let steady = (s.f - fbar).norm() <= 2.0 * STATIC_F_SPREAD
                && (s.w - wbar).norm() <= 2.0 * STATIC_W_SPREAD;
            if !((s.ok || bump) && steady && before_motion(e)) {
                ended = true;
                break;
            }
            fsum += s.f;
            wsum += s.w;
            e += 1;
        }
        if e == n && (at_end || !before_motion(n - 1)) {
            ended = true;
        }
        if e - k >= min_s || !ended {
            return Some((k, e, ended));
        }
        k = e;
    }
    None
}

fn deg(x: f64) -> f64 {
    x.to_degrees()
}

/// Attitude quaternion (body to NED) from roll, pitch and yaw [rad].
fn attitude(roll: f64, pitch: f64, yaw: f64) -> UnitQuaternion<f64> {
    UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(dcm_from_euler(
        roll, pitch, yaw,
    )))
}

/// Looks for a start in the blocks read so far and the GNSS fixes (`at_end`: no more IMU data
/// will come); `static_pos` is a known position of a static vehicle (no course then).
pub fn find(
    blocks: &[Block],
    fixes: &[Fix],
    static_pos: Option<[f64; 3]>,
    priors: Priors,
    at_end: bool,
) -> Result<Found> {
    let Some(first) = blocks.first() else {
        return if at_end {
            bail!("--init auto: the IMU file is shorter than {BLOCK_S} s")
        } else {
            Ok(Found::NeedMore)
        };
    };
    let cx = Search::new(blocks, fixes, static_pos, priors, at_end, first.t_start)?;
    let Some((quiet, unconfirmed)) = cx.confirmed_quiet() else {
        return Ok(Found::NeedMore);
    };
    match quiet {
        Some((k, e, closed)) if e - k >= cx.min_q || !closed => {
            if e - k < cx.min_q {
                return Ok(Found::NeedMore);
            }
            cx.quiet_start(k, e, closed)
        }
        _ => cx.moving_start(unconfirmed),
    }
}

/// A quiet stretch: its first second, its end second, and whether it has ended.
type Stretch = (usize, usize, bool);

/// A moving start's span: the fast fix, the fixes before and after it, the blocks between.
type Span = (usize, usize, usize, Vec<Block>);

/// What every phase of [`find`] shares: the data read so far, the priors, and what follows
/// from them before a quiet or a moving start is decided on.
struct Search<'a> {
    /// The blocks read so far.
    blocks: &'a [Block],
    /// The GNSS fixes.
    fixes: &'a [Fix],
    /// A known position of a static vehicle: latitude, longitude [rad], height [m].
    static_pos: Option<[f64; 3]>,
    /// The priors.
    priors: Priors,
    /// No more IMU data will come.
    at_end: bool,
    /// Start of the first block [s].
    t0: f64,
    /// End of the last block read [s].
    t_read: f64,
    /// The position searched at: latitude, longitude [rad], height [m].
    pos0: [f64; 3],
    /// Gravity there [m/s²].
    g: f64,
    /// The blocks' whole seconds.
    secs: Vec<Second>,
    /// Time of the first GNSS fix that shows motion, confirmed by the next [s].
    first_motion: Option<f64>,
    /// Shortest quiet stretch that levels the IMU [whole seconds].
    min_q: usize,
    /// Tilt 1-σ from the accelerometer-bias prior (at least 0.01°) [rad].
    sigma_tilt: f64,
}

/// What a quiet stretch gives before the heading: its blocks, level and scatter.
struct Rest {
    /// The stretch's blocks.
    q: Vec<Block>,
    /// Mean angular rate over the stretch [rad/s].
    w: Vector3<f64>,
    /// Start of the stretch, where the run starts [s].
    t_q: f64,
    /// Length of the stretch [s].
    q_s: f64,
    /// Roll from the stretch's first seconds [rad].
    roll: f64,
    /// Pitch from the stretch's first seconds [rad].
    pitch: f64,
    /// How each part was found so far, one line each.
    report: Vec<String>,
    /// Number of whole seconds at rest.
    nsec: f64,
    /// Scatter of the 1-s means of specific force [m/s²].
    f_scatter: f64,
    /// Scatter of the 1-s means of angular rate [rad/s].
    w_scatter: f64,
    /// Tilt 1-σ: the accelerometer-bias prior and the scatter [rad].
    sigma_tilt: f64,
    /// Heading 1-σ of gyrocompassing from the gyro-bias prior alone [rad].
    gc_bias: f64,
    /// Heading 1-σ of gyrocompassing: the bias prior and the noise of the mean rate [rad].
    gc_sigma: f64,
}

/// A drive-off matched to the GNSS: the level at the end of the rest and the course chord.
struct DriveOff {
    /// End of the rest [s].
    t_b: f64,
    /// Levelling rotation from the last 5 s at rest.
    level_last: Matrix3<f64>,
    /// Levelled specific force at rest [m/s²].
    f_rest_l: Vector3<f64>,
    /// Number of blocks in the last 5 s at rest.
    n_last: usize,
    /// Fix at the chord's start.
    ka: usize,
    /// Fix at the chord's end.
    kb: usize,
    /// Heading change the gyros see over the chord [rad].
    chord_turn: f64,
}

impl<'a> Search<'a> {
    /// The shared context of the data read so far; `t0` is the first block's start [s].
    fn new(
        blocks: &'a [Block],
        fixes: &'a [Fix],
        static_pos: Option<[f64; 3]>,
        priors: Priors,
        at_end: bool,
        t0: f64,
    ) -> Result<Self> {
        let t_read = blocks.last().map(|b| b.t_end).unwrap_or(t0);
        let pos0 = match (static_pos, fixes.iter().find(|f| f.t >= t0 - 1.0)) {
            (Some(p), _) => p,
            (None, Some(f)) => f.pos,
            (None, None) => bail!("--init auto: no GNSS fix at or after the IMU start ({t0:.3} s) to take the position from"),
        };
        let g = earth::gravity(pos0[0], pos0[2]);
        let secs = seconds(blocks, g);
        // the first GNSS fix that shows motion beyond its noise, confirmed by the next one
        let first_motion = (0..fixes.len().saturating_sub(1))
            .find(|&k| {
                fixes[k].t >= t0
                    && fixes[k].moving()
                    && fixes[k + 1].moving()
                    && fixes[k + 1].t - fixes[k].t <= 5.0
            })
            .map(|k| fixes[k].t);
        let d = std::f64::consts::PI / 180.0;
        Ok(Search {
            blocks,
            fixes,
            static_pos,
            priors,
            at_end,
            t0,
            t_read,
            pos0,
            g,
            secs,
            first_motion,
            min_q: MIN_QUIET_S.round() as usize,
            sigma_tilt: (priors.accel_bias / g).max(0.01 * d),
        })
    }

    /// The first quiet stretch that the GNSS and the gyros let stand as rest, and why one was
    /// turned down; None while more data are needed to decide.
    fn confirmed_quiet(&self) -> Option<(Option<Stretch>, Option<String>)> {
        let secs = &self.secs;
        let mut quiet = quiet_stretch(secs, self.first_motion, self.at_end, self.min_q);
        let mut unconfirmed: Option<String> = None;
        // the IMU alone cannot tell rest from a steady straight drive: the GNSS (or --static-aid)
        // must confirm it, with at least one fix with a velocity inside the stretch and none moving
        if let (Some((k, e, closed)), None) = (quiet, self.static_pos) {
            let (t_a, t_b) = (secs[k].t_start, secs[e - 1].t_end);
            let inside: Vec<&Fix> = self
                .fixes
                .iter()
                .filter(|f| f.t >= t_a && f.t <= t_b && f.v.is_some())
                .collect();
            if inside.is_empty() || inside.iter().any(|f| f.moving()) {
                if !closed && !self.at_end && inside.is_empty() {
                    return None;
                }
                unconfirmed = Some(format!(
                    "the IMU looks still from {t_a:.3} to {t_b:.3} s, but no GNSS fix with a velocity confirms rest there, and a steady straight drive looks the same"
                ));
                quiet = None;
            }
        }
        if let Some((k, e, _)) = quiet {
            if let Some(why) = self.steady_turn(k, e) {
                unconfirmed = Some(why);
                quiet = None;
            }
        }
        Some((quiet, unconfirmed))
    }

    /// Why seconds `k..e` are a steady turn, not rest, when their mean rate exceeds what the
    /// Earth rate and the gyro-bias prior allow; None when it does not.
    fn steady_turn(&self, k: usize, e: usize) -> Option<String> {
        // at rest the gyros measure the Earth rate and their bias: a mean rate beyond that is a
        // steady turn (a vehicle turning in place, a slow swing), not rest
        let r = &self.secs[k..e];
        let n = r.len() as f64;
        let w_mean = r.iter().map(|x| x.w).sum::<Vector3<f64>>() / n;
        let w_scatter = (r.iter().map(|x| (x.w - w_mean).norm_squared()).sum::<f64>()
            / (n - 1.0).max(1.0))
        .sqrt();
        let allowed = earth::OMEGA
            + 3.0 * (3.0 * self.priors.gyro_bias.powi(2) + w_scatter.powi(2) / n).sqrt();
        (w_mean.norm() > allowed).then(|| {
            format!(
                "the IMU turns steadily at {:.4} deg/s from {:.3} to {:.3} s, more than the Earth rate and the gyro-bias prior allow ({:.4} deg/s): not at rest",
                w_mean.norm().to_degrees(),
                r[0].t_start,
                r[r.len() - 1].t_end,
                allowed.to_degrees()
            )
        })
    }

    /// A start at rest in seconds `k..e` (`closed`: the stretch has ended): the heading by
    /// gyrocompassing, else from the drive-off.
    fn quiet_start(&self, k: usize, e: usize, closed: bool) -> Result<Found> {
        let rest = self.rest(k, e);
        let gc_possible = rest.gc_bias <= GYROCOMPASS_MAX_SIGMA;
        if (gc_possible || self.static_pos.is_some()) && !closed {
            // a longer rest may still bring the noise down (a static vehicle: wait for all
            // of it, to say how long it was)
            return Ok(Found::NeedMore);
        }
        if gc_possible && rest.q_s >= GYROCOMPASS_S && rest.gc_sigma <= GYROCOMPASS_MAX_SIGMA {
            return Ok(self.gyrocompass(rest));
        }
        self.drive_off(rest, gc_possible)
    }

    /// The level, the scatter of the 1-s means and the gyrocompass 1-σ of seconds `k..e`.
    fn rest(&self, k: usize, e: usize) -> Rest {
        let (secs, g) = (&self.secs, self.g);
        let (t_a, t_b) = (secs[k].t_start, secs[e - 1].t_end);
        let q: Vec<Block> = self
            .blocks
            .iter()
            .filter(|b| b.t_start >= t_a - 1e-9 && b.t_end <= t_b + 1e-9)
            .copied()
            .collect();
        let (f, w) = mean_of(&q);
        let t_q = q[0].t_start;
        let q_s = q.last().unwrap().t_end - t_q;
        // the run starts at the stretch's start: level from its first seconds (at most 10 s;
        // an attitude that creeps while standing is not averaged into the start)
        let first: Vec<Block> = q
            .iter()
            .filter(|b| b.t_end <= t_q + 10.0 + 1e-9)
            .copied()
            .collect();
        let (f_first, _) = mean_of(&first);
        let (roll, pitch) = tilt_from(f_first);
        let report = vec![format!(
            "level: roll {:.3} deg, pitch {:.3} deg from the first {:.1} s of {:.1} s at rest from t = {:.3} s",
            deg(roll),
            deg(pitch),
            first.last().map(|b| b.t_end - t_q).unwrap_or(0.0),
            q_s,
            t_q
        )];
        // the scatter of the 1-s means at rest: noise and vibration, as the data show them
        let rest_secs = &secs[k..e];
        let nsec = rest_secs.len() as f64;
        let scatter = |v: &dyn Fn(&Second) -> Vector3<f64>, mean: Vector3<f64>| {
            (rest_secs
                .iter()
                .map(|x| (v(x) - mean).norm_squared())
                .sum::<f64>()
                / (nsec - 1.0).max(1.0))
            .sqrt()
        };
        let f_scatter = scatter(&|x| x.f, f);
        let w_scatter = scatter(&|x| x.w, w);
        // the tilt's 1-σ: the accelerometer bias prior and how much the 1-s means wander
        let sigma_tilt = self.sigma_tilt.hypot(f_scatter / g);
        let horiz_rate = earth::OMEGA * self.pos0[0].cos();
        // heading 1-σ of gyrocompassing: the bias prior and the noise of the mean rate
        let gc_bias = self.priors.gyro_bias / horiz_rate;
        let gc_sigma = self.priors.gyro_bias.hypot(w_scatter / nsec.sqrt()) / horiz_rate;
        Rest {
            q,
            w,
            t_q,
            q_s,
            roll,
            pitch,
            report,
            nsec,
            f_scatter,
            w_scatter,
            sigma_tilt,
            gc_bias,
            gc_sigma,
        }
    }

    /// The state at the start of the rest: standing, levelled, heading `yaw` [rad].
    fn rest_state(&self, rest: &Rest, yaw: f64) -> NavState {
        NavState {
            t: rest.t_q,
            lat: self.pos0[0],
            lon: self.pos0[1],
            h: self.pos0[2],
            v: Vector3::zeros(),
            q: attitude(rest.roll, rest.pitch, yaw),
        }
    }

    /// The start at rest headed by gyrocompassing: the Earth rate's direction, levelled.
    fn gyrocompass(&self, mut rest: Rest) -> Found {
        let wl = dcm_from_euler(rest.roll, rest.pitch, 0.0) * rest.w;
        let yaw = (-wl.y).atan2(wl.x);
        rest.report.push(format!(
            "heading: {:.3} deg by gyrocompassing {:.1} s at rest (1-sigma {:.3} deg: gyro bias prior {:.4} deg/h and the scatter of the mean rate, against the Earth rate)",
            deg(yaw.rem_euclid(2.0 * std::f64::consts::PI)),
            rest.q_s,
            deg(rest.gc_sigma),
            self.priors.gyro_bias.to_degrees() * 3600.0
        ));
        Found::Done(Box::new(AutoInit {
            state: self.rest_state(&rest, yaw),
            sigma_tilt: rest.sigma_tilt,
            sigma_yaw: rest.gc_sigma,
            report: rest.report,
            travel_from_x: None,
        }))
    }

    /// The drive-off after the rest (`gc_ok`: gyrocompassing was possible, for the message):
    /// the first fast GNSS fix close after it, the level at the rest's end, the course chord.
    fn drive_off(&self, rest: Rest, gc_ok: bool) -> Result<Found> {
        let (fixes, priors) = (self.fixes, self.priors);
        // the drive-off after the quiet stretch
        let t_b = rest.q.last().unwrap().t_end;
        let fast = |f: &Fix| f.moving() && f.speed() > priors.speed;
        let Some(fx) = fixes.iter().find(|f| f.t > t_b && fast(f)) else {
            return self.no_drive_off(&rest, t_b, gc_ok);
        };
        if self.t_read < fx.t {
            return Ok(Found::NeedMore);
        }
        // the course fix must follow the drive-off closely
        let t_m = self.first_motion.unwrap_or(t_b).max(t_b);
        if fx.t - t_m > 10.0 {
            bail!(
                "--init auto: the first GNSS fix faster than {} m/s comes {:.1} s after the drive-off begins ({t_m:.3} s): by then the course no longer shows the heading at rest (a fix has a velocity from the file's columns, or from positions at most 5 s apart); denser GNSS fixes, or --init",
                priors.speed,
                fx.t - t_m
            );
        }
        // the IMU's own velocity since the rest, in the levelled frame of the heading at
        // rest: each block's specific force levelled, turned by the heading change the
        // gyros saw since the rest (their mean at rest taken off), less the force at rest
        let last: Vec<Block> = rest
            .q
            .iter()
            .filter(|b| b.t_start >= t_b - 5.0 - 1e-9)
            .copied()
            .collect();
        let (f_last, _) = mean_of(&last);
        let (roll_l, pitch_l) = tilt_from(f_last);
        let level_last = dcm_from_euler(roll_l, pitch_l, 0.0);
        let f_rest_l = level_last * f_last;
        let Some((ka, kb, chord_turn)) = self.chord(fx, t_m, &level_last, rest.w)? else {
            return Ok(Found::NeedMore);
        };
        let leg = DriveOff {
            t_b,
            level_last,
            f_rest_l,
            n_last: last.len(),
            ka,
            kb,
            chord_turn,
        };
        self.drive_off_heading(rest, &leg)
    }

    /// Why no heading comes after the rest ending at `t_b` [s] when no fast GNSS fix follows
    /// it (`gc_ok`: gyrocompassing was possible): an error at the end, else more data.
    fn no_drive_off(&self, rest: &Rest, t_b: f64, gc_ok: bool) -> Result<Found> {
        let (fixes, priors, q_s, gc_sigma) = (self.fixes, self.priors, rest.q_s, rest.gc_sigma);
        if self.at_end || self.static_pos.is_some() {
            let with_v: Vec<&Fix> = fixes
                .iter()
                .filter(|f| f.t > t_b && f.v.is_some())
                .collect();
            let gnss = if self.static_pos.is_some() {
                "the vehicle is static (--static-aid): no course".to_string()
            } else if with_v.is_empty() {
                format!(
                    "no GNSS fix after the rest has a velocity ({} fixes; velocities come from the file's columns or from positions at most 5 s apart)",
                    fixes.iter().filter(|f| f.t > t_b).count()
                )
            } else {
                format!(
                    "the GNSS speed never exceeds {} m/s (and 4 sigma of its noise) after it: {} fixes with a velocity, the fastest {:.2} m/s",
                    priors.speed,
                    with_v.len(),
                    with_v.iter().map(|f| f.speed()).fold(0.0, f64::max)
                )
            };
            bail!(
                "--init auto: no heading after the {:.1} s at rest: {}, and {gnss} (to take the course of a drive-off); give the heading with --init LAT,LON,H,ROLL,PITCH,YAW",
                q_s,
                if gc_ok {
                    format!(
                        "gyrocompassing the {q_s:.0} s at rest gives a heading 1-sigma of {:.2} deg (used at 1 deg or better, over at least {GYROCOMPASS_S:.0} s)",
                        deg(gc_sigma)
                    )
                } else {
                    format!(
                        "the gyros cannot find north (their bias prior {:.3} deg/h gives a gyrocompass heading 1-sigma of {:.1} deg)",
                        priors.gyro_bias.to_degrees() * 3600.0,
                        deg(gc_sigma)
                    )
                }
            );
        }
        if self.t_read - t_b > SEARCH_S {
            bail!("--init auto: no heading within {SEARCH_S:.0} s of the end of the stretch at rest: the GNSS speed never exceeds {} m/s", priors.speed);
        }
        Ok(Found::NeedMore)
    }

    /// The course chord of a drive-off: the fixes about 1 s either side of a fast fix from
    /// `fx` on, within 10 s of the motion at `t_m` [s], and the heading change [rad] the gyros
    /// see over it (rate `w` [rad/s] at rest taken off); None while more data are needed.
    fn chord(
        &self,
        fx: &Fix,
        t_m: f64,
        level_last: &Matrix3<f64>,
        w: Vector3<f64>,
    ) -> Result<Option<(usize, usize, f64)>> {
        let (blocks, fixes, priors) = (self.blocks, self.fixes, self.priors);
        // the GNSS side: the chord between the fixes about 1 s either side of the fast fix
        // (the velocity there, as a mean over the same span the IMU's is taken over, so a
        // turn in between is seen alike by both)
        // Of the fast fixes within 10 s of the motion, the first whose chord the gyros see
        // straight: in a turn a clock offset between IMU and GNSS turns the comparison by
        // the turn rate times the offset
        let turn_over = |a: f64, b: f64| -> f64 {
            blocks
                .iter()
                .filter(|x| x.t_start >= a - 1e-9 && x.t_end <= b + 1e-9)
                .map(|x| (level_last * (x.w - w)).z * (x.t_end - x.t_start))
                .sum()
        };
        let k0 = fixes.iter().position(|f| f.t == fx.t).unwrap_or(0);
        let mut pick: Option<(usize, usize, f64)> = None;
        for k in k0..fixes.len() {
            if fixes[k].t > t_m + 10.0 {
                break;
            }
            let Some((a, b)) = neighbours(fixes, k) else {
                continue;
            };
            if !(fixes[k].moving() && fixes[k].speed() > priors.speed) {
                continue;
            }
            if self.t_read < fixes[b].t {
                if self.at_end {
                    break;
                }
                return Ok(None);
            }
            let turn = turn_over(fixes[a].t, fixes[b].t);
            if pick.is_none() {
                pick = Some((a, b, turn));
            }
            if turn.abs() <= COURSE_SLACK {
                pick = Some((a, b, turn));
                break;
            }
        }
        if pick.is_none() {
            bail!(
                "--init auto: no GNSS fixes around the fix at {:.3} s (within the IMU data) for the course",
                fx.t
            );
        }
        Ok(pick)
    }

    /// The IMU's track since the rest up to `tb` [s], block by block: (time [s], displacement
    /// in the levelled frame of the heading at rest [m], heading change [rad]).
    fn imu_track(&self, leg: &DriveOff, tb: f64, w: Vector3<f64>) -> Vec<(f64, Vector3<f64>, f64)> {
        let (t_b, level_last, f_rest_l) = (leg.t_b, leg.level_last, leg.f_rest_l);
        // the IMU side: velocity and displacement since the rest, block by block
        let (mut psi, mut v_imu, mut disp) =
            (0.0f64, Vector3::<f64>::zeros(), Vector3::<f64>::zeros());
        let mut track: Vec<(f64, Vector3<f64>, f64)> = vec![(t_b, disp, psi)];
        for x in self
            .blocks
            .iter()
            .filter(|x| x.t_start >= t_b - 1e-9 && x.t_end <= tb + 1e-9)
        {
            let dt = x.t_end - x.t_start;
            let rate = (level_last * (x.w - w)).z;
            let mid = psi + 0.5 * rate * dt;
            let v0 = v_imu;
            v_imu += (dcm_from_euler(0.0, 0.0, mid) * (level_last * x.f) - f_rest_l) * dt;
            disp += 0.5 * (v0 + v_imu) * dt;
            psi += rate * dt;
            track.push((x.t_end, disp, psi));
        }
        track
    }

    /// The start at rest headed from the drive-off: the IMU's own track over the chord
    /// matched to the GNSS course, the mounting yaw, and their 1-σ.
    fn drive_off_heading(&self, mut rest: Rest, leg: &DriveOff) -> Result<Found> {
        let (fixes, priors) = (self.fixes, self.priors);
        let (t_b, ka, kb, chord_turn) = (leg.t_b, leg.ka, leg.kb, leg.chord_turn);
        let (ta, tb) = (fixes[ka].t, fixes[kb].t);
        // a turn over the chord: 0.2 s of IMU/GNSS clock offset is allowed for in the σ
        let sigma_clock = chord_turn.abs() / (tb - ta) * 0.2;
        let (v_chord, sigma_chord) = velocity_between(fixes, ka, kb);
        let track = self.imu_track(leg, tb, rest.w);
        let psi = track.last().unwrap().2;
        let at = |t: f64| {
            *track
                .iter()
                .min_by(|p, q| (p.0 - t).abs().total_cmp(&(q.0 - t).abs()))
                .unwrap()
        };
        let (a_imu, b_imu) = (at(ta), at(tb));
        let d_imu = (b_imu.1 - a_imu.1) / (b_imu.0 - a_imu.0).max(BLOCK_S);
        let speed_imu = d_imu.x.hypot(d_imu.y);
        let speed_gnss = v_chord.x.hypot(v_chord.y);
        // the GNSS and the IMU must agree on how fast the vehicle goes there
        if !(speed_imu > 0.5 * speed_gnss && speed_imu < 2.0 * speed_gnss) {
            bail!(
                "--init auto: from {ta:.3} to {tb:.3} s the IMU's integrated speed is {speed_imu:.2} m/s, the GNSS positions give {speed_gnss:.2} m/s: a clock offset between IMU and GNSS (UTC read as GPST is 18 s), or wrong IMU units? (give the start with --init: a run then measures the clock offset from the turns IMU and GNSS both see)"
            );
        }
        let course = v_chord.y.atan2(v_chord.x);
        // direction of the IMU's travel from the heading at rest
        let alpha = d_imu.y.atan2(d_imu.x);
        let yaw = course - alpha;
        // the direction of travel seen from the IMU's axes (their heading mid-span)
        let psi_mid = 0.5 * (a_imu.2 + b_imu.2);
        let travel = (alpha - psi_mid + std::f64::consts::PI)
            .rem_euclid(2.0 * std::f64::consts::PI)
            - std::f64::consts::PI;
        // 1-σ: the accelerometer noise integrated (1-s means scattering by f_scatter) and
        // the force at rest subtracted over the span, the course noise, the gyros' noise
        // over the span, and 2° for what the integration leaves out (pitching, a tilt change)
        let (f_scatter, w_scatter, nsec) = (rest.f_scatter, rest.w_scatter, rest.nsec);
        let span = tb - t_b;
        let sigma_v_imu = (f_scatter.powi(2) * span.max(1.0)
            + (f_scatter / (leg.n_last as f64 * BLOCK_S).max(1.0).sqrt() * span).powi(2))
        .sqrt();
        // the gyros' noise over the span, and their scale error on the heading change
        let sigma_turn = (w_scatter / nsec.sqrt() * span).hypot(priors.gyro_scale * psi_mid.abs());
        let sigma_yaw = ((sigma_v_imu / speed_imu).powi(2)
            + (sigma_chord / speed_gnss).powi(2)
            + sigma_turn.powi(2)
            + sigma_clock.powi(2)
            + COURSE_SLACK.powi(2))
        .sqrt();
        rest.report.push(format!(
            "heading: {:.3} deg from the drive-off: from {:.3} to {:.3} s the IMU's own track since the rest at {:.3} s (specific force levelled and turned by the gyros, {:.1} deg by the end; {:.2} m/s) runs {:.1} deg from the heading at rest, the GNSS positions {:.2} deg ({:.2} m/s); 1-sigma {:.2} deg (accelerometer noise, course noise, gyro noise and scale, 0.2 s of clock offset times the turn rate, {:.0} deg for what the integration leaves out)",
            deg(yaw.rem_euclid(2.0 * std::f64::consts::PI)),
            ta,
            tb,
            t_b,
            deg(psi),
            speed_imu,
            deg(alpha),
            deg(course.rem_euclid(2.0 * std::f64::consts::PI)),
            speed_gnss,
            deg(sigma_yaw),
            deg(COURSE_SLACK)
        ));
        rest.report.push(format!(
            "mounting: the direction of travel is {:.1} deg {} of the IMU x axis (roll {:.2} deg, pitch {:.2} deg of the IMU at rest)",
            deg(travel.abs()),
            if travel >= 0.0 { "right" } else { "left" },
            deg(rest.roll),
            deg(rest.pitch)
        ));
        Ok(Found::Done(Box::new(AutoInit {
            state: self.rest_state(&rest, yaw),
            sigma_tilt: rest.sigma_tilt,
            sigma_yaw,
            report: rest.report,
            travel_from_x: Some(travel),
        })))
    }

    /// A start on the move (no quiet stretch before the motion): the GNSS course gives the
    /// heading, the specific force less the GNSS acceleration the level.
    fn moving_start(&self, unconfirmed: Option<String>) -> Result<Found> {
        // no quiet stretch before the motion: a moving start
        if self.first_motion.is_none() {
            if self.at_end || self.static_pos.is_some() {
                bail!(
                    "--init auto: the IMU is never at rest for {MIN_QUIET_S:.0} s (by the absolute tests of `align`) and the GNSS never shows motion: nothing to level or head by; give --init LAT,LON,H,ROLL,PITCH,YAW"
                );
            }
            if self.t_read - self.t0 > SEARCH_S {
                bail!("--init auto: neither rest nor GNSS motion in the first {SEARCH_S:.0} s");
            }
            return Ok(Found::NeedMore);
        }
        let Some((k, ka, kb, around)) = self.moving_span()? else {
            return Ok(Found::NeedMore);
        };
        Ok(self.moving_fix(unconfirmed, k, ka, kb, &around))
    }

    /// The GNSS acceleration over fixes `ka` to `kb` around fix `k` [m/s²] and its 1-σ [m/s²].
    fn gnss_accel(&self, ka: usize, k: usize, kb: usize) -> (Vector3<f64>, f64) {
        // the GNSS acceleration over a span: from the receiver's velocities, or from the
        // positions' second difference (velocities derived at the span's ends are means
        // over other spans and would bias it)
        let fixes = self.fixes;
        let dt_a = fixes[kb].t - fixes[ka].t;
        if fixes[ka].derived || fixes[kb].derived {
            let (v1, s1) = velocity_between(fixes, ka, k);
            let (v2, s2) = velocity_between(fixes, k, kb);
            (2.0 * (v2 - v1) / dt_a, 2.0 * s1.hypot(s2) / dt_a)
        } else {
            let (va, vb) = (fixes[ka].v.unwrap(), fixes[kb].v.unwrap());
            (
                (vb - va) / dt_a,
                fixes[ka].sigma_v.hypot(fixes[kb].sigma_v) / dt_a,
            )
        }
    }

    /// The span of a moving start: the first fast fix with fixes about 1 s either side over
    /// which the vehicle drives straight, a calm one (GNSS acceleration under 0.3 m/s²)
    /// preferred for up to 60 s; None while more data are needed.
    fn moving_span(&self) -> Result<Option<Span>> {
        let (blocks, fixes, priors) = (self.blocks, self.fixes, self.priors);
        // the first fast fix with neighbours for the acceleration and IMU data around it
        // the first fast fix (beyond its noise, confirmed by the next) with velocities about
        // 1 s before and after it for the acceleration, where the vehicle does not turn
        // (the specific force is averaged in the body frame, the GNSS acceleration in NED:
        // in a turn they differ)
        // a calm span (the GNSS acceleration under CALM_ACCEL) is preferred for up to 60 s
        // after the first candidate: the level's correction by the GNSS acceleration
        // assumes the IMU's x axis along travel
        let mut chosen: Option<Span> = None;
        let mut fallback: Option<Span> = None;
        let mut turning: Option<(f64, f64)> = None;
        for k in 0..fixes.len().saturating_sub(1) {
            if let Some((kf, _, _, _)) = &fallback {
                if fixes[k].t > fixes[*kf].t + 60.0 {
                    break;
                }
            }
            let f = &fixes[k];
            let ok = f.t >= self.t0 + 0.5
                && f.moving()
                && f.speed() > priors.speed
                && fixes[k + 1].moving()
                && fixes[k + 1].t - f.t <= 5.0;
            let Some((a, b)) = neighbours(fixes, k) else {
                continue;
            };
            if !(ok && a < k && k < b && fixes[a].v.is_some() && fixes[b].v.is_some()) {
                continue;
            }
            if self.t_read < fixes[b].t {
                if self.at_end {
                    break;
                }
                return Ok(None);
            }
            let win: Vec<Block> = blocks
                .iter()
                .filter(|x| x.t_start >= fixes[a].t - 1e-9 && x.t_end <= fixes[b].t + 1e-9)
                .copied()
                .collect();
            if win.is_empty() {
                continue;
            }
            let (fw, _) = mean_of(&win);
            let (r0, p0) = tilt_from(fw);
            let lev = dcm_from_euler(r0, p0, 0.0);
            let turn: f64 = win
                .iter()
                .map(|x| (lev * x.w).z * (x.t_end - x.t_start))
                .sum();
            if turn.abs() > COURSE_SLACK {
                turning.get_or_insert((f.t, turn));
                continue;
            }
            let (an, _) = self.gnss_accel(a, k, b);
            if an.x.hypot(an.y) <= CALM_ACCEL {
                chosen = Some((k, a, b, win));
                break;
            }
            if fallback.is_none() {
                fallback = Some((k, a, b, win));
            }
        }
        if let (None, Some((kf, _, _, _))) = (&chosen, &fallback) {
            let waited = self.t_read - fixes[*kf].t;
            if !self.at_end && waited <= 60.0 {
                return Ok(None);
            }
            chosen = fallback;
        }
        if chosen.is_none() && self.at_end {
            bail!(
                "--init auto: the data start moving, and no GNSS fix faster than {} m/s (and 4 sigma of its noise, confirmed by the next fix) has fixes about 1 s before and after it{}; give --init LAT,LON,H,ROLL,PITCH,YAW",
                priors.speed,
                match turning {
                    Some((t, turn)) => format!(
                        " while the vehicle drives straight (the first candidate, at {t:.3} s, turns {:.1} deg in its window)",
                        deg(turn)
                    ),
                    None => String::new(),
                }
            );
        }
        Ok(chosen)
    }

    /// The moving start at fast fix `k` with the blocks `around` it between fixes `ka` and
    /// `kb`: heading the GNSS course, level the specific force less the GNSS acceleration.
    fn moving_fix(
        &self,
        unconfirmed: Option<String>,
        k: usize,
        ka: usize,
        kb: usize,
        around: &[Block],
    ) -> Found {
        let (fixes, g) = (self.fixes, self.g);
        let fx = fixes[k];
        // the specific force over the same span as the GNSS acceleration
        let (f, _) = mean_of(around);
        let (a_n, sigma_a) = self.gnss_accel(ka, k, kb);
        let v = fx.v.unwrap();
        let yaw = v.y.atan2(v.x);
        // f_b = C_n^b (a_n − g_n): the tilt that turns f_b into a_n − g_n, the heading the course
        let (r0, p0) = tilt_from(f);
        let u = dcm_from_euler(0.0, 0.0, yaw).transpose() * (a_n - Vector3::new(0.0, 0.0, g));
        let level_f = dcm_from_euler(r0, p0, 0.0) * f;
        let tilt = Rotation3::rotation_between(&level_f, &u).unwrap_or_else(Rotation3::identity);
        let e = euler_from_dcm(&(tilt.matrix() * dcm_from_euler(r0, p0, 0.0)));
        let (roll, pitch) = (e.x, e.y);
        // the start: the last block end at or before the fix, position moved back to it
        let t_s = self
            .blocks
            .iter()
            .map(|b| b.t_end)
            .filter(|t| *t <= fx.t + 1e-9)
            .fold(self.t0, f64::max);
        let back = fx.t - t_s;
        let rm = earth::radius_meridian(fx.pos[0]) + fx.pos[2];
        let rn = earth::radius_transverse(fx.pos[0]) + fx.pos[2];
        let pos = [
            fx.pos[0] - v.x * back / rm,
            fx.pos[1] - v.y * back / (rn * fx.pos[0].cos()),
            fx.pos[2] + v.z * back,
        ];
        let v_s = v - a_n * back;
        // the bias prior, the noise of the GNSS acceleration, 0.05 m/s² for the acceleration
        // changing within the second
        // the correction by the GNSS acceleration assumes the IMU's x axis along travel: a
        // mounting turned from that moves it, so its own size counts in the σ too
        let a_h = a_n.x.hypot(a_n.y);
        let sigma_tilt = (self.sigma_tilt.powi(2)
            + (sigma_a / g).powi(2)
            + (0.05 / g).powi(2)
            + (a_h / g).powi(2))
        .sqrt();
        let sigma_yaw = ((fx.sigma_v / fx.speed()).powi(2) + COURSE_SLACK.powi(2)).sqrt();
        let report = vec![
            format!(
                "the data start moving ({} before the GNSS shows motion at {:.3} s): the run starts at {:.3} s, at the first GNSS fix faster than {} m/s (confirmed by the next fix) with fixes around it for the acceleration and 0.5 s of IMU data before it",
                unconfirmed.unwrap_or_else(|| format!("no {MIN_QUIET_S:.0} s at rest")),
                self.first_motion.unwrap(),
                t_s,
                self.priors.speed
            ),
            format!(
                "heading: {:.3} deg = the GNSS course at {:.3} s ({:.1} m/s; this assumes the IMU x axis points along the direction of travel); 1-sigma {:.2} deg",
                deg(yaw.rem_euclid(2.0 * std::f64::consts::PI)),
                fx.t,
                fx.speed(),
                deg(sigma_yaw)
            ),
            format!(
                "level: roll {:.3} deg, pitch {:.3} deg from the specific force from {:.3} to {:.3} s less the GNSS acceleration over the same span ({:.2} m/s^2); 1-sigma {:.3} deg",
                deg(roll),
                deg(pitch),
                fixes[ka].t,
                fixes[kb].t,
                a_n.norm(),
                deg(sigma_tilt)
            ),
        ];
        Found::Done(Box::new(AutoInit {
            state: NavState {
                t: t_s,
                lat: pos[0],
                lon: pos[1],
                h: pos[2],
                v: v_s,
                q: attitude(roll, pitch, yaw),
            },
            sigma_tilt,
            sigma_yaw,
            report,
            travel_from_x: None,
        }))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(t: f64, dt: f64, f: Vector3<f64>, w: Vector3<f64>) -> ImuSample {
        ImuSample {
            t,
            dtheta: w * dt,
            dv: f * dt,
        }
    }

    /// Quarter-second means weight each increment by its own interval: a clock whose samples
    /// span 1 or 2 periods gives the uniform clock's means.
    #[test]
    fn blocks_of_a_jittered_clock_match_the_uniform_ones() {
        let f = |t: f64| Vector3::new(0.1 * t.sin(), 0.2, -9.8);
        let w = |t: f64| Vector3::new(1e-4, -2e-4 * t.cos(), 5e-5);
        let dt = 0.005;
        let (mut uni, mut jit) = (Blocks::default(), Blocks::default());
        let mut pending: Option<(Vector3<f64>, Vector3<f64>)> = None;
        for k in 1..=2000 {
            let t = k as f64 * dt;
            let (fk, wk) = (f(t - dt / 2.0), w(t - dt / 2.0));
            uni.push(&sample(t, dt, fk, wk), dt);
            // merge every 3rd and 4th sample of each four
            match (k % 4, pending.take()) {
                (3, _) => pending = Some((fk * dt, wk * dt)),
                (0, Some((dv, dth))) => {
                    jit.push(
                        &ImuSample {
                            t,
                            dtheta: dth + wk * dt,
                            dv: dv + fk * dt,
                        },
                        dt,
                    );
                }
                _ => jit.push(&sample(t, dt, fk, wk), dt),
            }
        }
        assert_eq!(uni.blocks.len(), jit.blocks.len());
        for (a, b) in uni.blocks.iter().zip(&jit.blocks) {
            assert!((a.t_end - b.t_end).abs() < 1e-12);
            assert!(
                (a.f - b.f).norm() < 1e-9 && (a.w - b.w).norm() < 1e-12,
                "{a:?} {b:?}"
            );
        }
    }

    /// Velocities from positions: central differences, east scaled by cos(lat).
    #[test]
    fn velocities_from_positions_are_central_differences() {
        let lat = 0.5f64;
        let rm = earth::radius_meridian(lat) + 100.0;
        let rn = earth::radius_transverse(lat) + 100.0;
        let mut fixes: Vec<Fix> = (0..3)
            .map(|k| Fix {
                t: k as f64,
                pos: [
                    lat + 3.0 * k as f64 / rm,
                    1.0 + 4.0 * k as f64 / (rn * lat.cos()),
                    100.0 - k as f64,
                ],
                sigma_pos: 0.1,
                v: None,
                sigma_v: 0.0,
                derived: false,
            })
            .collect();
        velocities_from_positions(&mut fixes);
        let v = fixes[1].v.unwrap();
        assert!((v - Vector3::new(3.0, 4.0, 1.0)).norm() < 1e-3, "{v}");
        assert!((fixes[1].sigma_v - 0.1 * std::f64::consts::SQRT_2 / 2.0).abs() < 1e-12);
    }
}
