//! Simulation scenarios (TOML): start state, motion segments, vibration, injected sensor errors,
//! noise and GNSS aiding. See `scenarios/*.toml` for documented examples.

use crate::io::units;
use crate::model::generated::common;
use anyhow::{anyhow, bail, Context, Result};
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::Path;

/// Start of the trajectory.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Start {
    /// Latitude [deg].
    pub lat_deg: f64,
    /// Longitude [deg].
    pub lon_deg: f64,
    /// Height [m].
    #[serde(default)]
    pub h_m: f64,
    /// Roll, pitch, yaw [deg] (C_b^n = Rz(yaw) Ry(pitch) Rx(roll)).
    #[serde(default)]
    pub euler_deg: [f64; 3],
    /// Initial speed along the heading [m/s].
    #[serde(default)]
    pub speed_mps: f64,
}

/// One motion segment.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Segment {
    /// `rest` (speed must be 0), `cruise` (constant speed), `accelerate`, `turn`, `rotate` (a
    /// turntable rotation about a body axis, at rest).
    pub kind: String,
    /// Duration [s].
    pub duration_s: f64,
    /// Along-track acceleration for `accelerate` [m/s²].
    #[serde(default)]
    pub accel_mps2: f64,
    /// Yaw rate for `turn` [deg/s].
    #[serde(default)]
    pub yaw_rate_deg_s: f64,
    /// Body axis of a `rotate` segment: `x`, `y` or `z` (FRD).
    #[serde(default)]
    pub axis: Option<String>,
    /// Angle of a `rotate` segment [deg], positive right-handed about `axis`.
    #[serde(default)]
    pub angle_deg: Option<f64>,
}

/// Checks a `rotate` segment: a body axis, a finite non-zero angle within ±3600°, a rate
/// within ±1e4 °/s, no `accel_mps2` or `yaw_rate_deg_s`, and at least [`MIN_ROTATE_SAMPLES`]
/// IMU periods (its rate ramps are integrated sample by sample). An angle that is π/4, π/2, π,
/// 3π/2 or 2π is pushed to `warnings` (radians written as degrees?).
fn check_rotate(
    s: &Segment,
    where_: &str,
    imu_rate_hz: f64,
    warnings: &mut Vec<String>,
) -> Result<()> {
    match s.axis.as_deref() {
        Some("x" | "y" | "z") => {}
        Some(a) => bail!("{where_}: axis = \"{a}\" must be a body axis: x, y or z"),
        None => bail!("{where_}: a rotate segment needs `axis` (x, y or z) and `angle_deg`"),
    }
    let Some(angle) = s.angle_deg else {
        bail!(
            "{where_}: a rotate segment needs `angle_deg` (degrees, right-handed about its axis)"
        );
    };
    if !(angle.is_finite() && angle.abs() <= 3600.0) {
        bail!("{where_}: angle_deg = {angle} must be within ±3600 deg");
    }
    if angle == 0.0 {
        bail!("{where_}: angle_deg = 0: a rotation of nothing (use a `rest` segment)");
    }
    if s.accel_mps2 != 0.0 || s.yaw_rate_deg_s != 0.0 {
        bail!("{where_}: `accel_mps2` and `yaw_rate_deg_s` do not apply to a rotate segment (its rate follows from angle_deg and duration_s)");
    }
    let min = MIN_ROTATE_SAMPLES / imu_rate_hz;
    if s.duration_s < min {
        bail!(
            "{where_}: duration_s = {} is under {MIN_ROTATE_SAMPLES} IMU periods ({min} s at {imu_rate_hz} Hz): its rate ramps would not be resolved (ms read as s?)",
            s.duration_s
        );
    }
    let rate = angle / (s.duration_s - rotate_ramp(s.duration_s));
    if rate.abs() > 1e4 {
        bail!("{where_}: angle_deg / duration_s needs a peak rate of {rate:.0} deg/s (after the rate ramps), beyond ±1e4 deg/s (rad given as deg? or ms as s?)");
    }
    let pi = std::f64::consts::PI;
    if [0.25, 0.5, 1.0, 1.5, 2.0]
        .iter()
        .any(|k| (angle.abs() - k * pi).abs() < 1e-3)
    {
        warnings.push(format!(
            "{where_}: angle_deg = {angle} is a multiple of π/4 in radians: radians written as degrees? (a rotation of {angle}°)"
        ));
    }
    Ok(())
}

/// Fewest IMU periods a `rotate` segment may last.
pub const MIN_ROTATE_SAMPLES: f64 = 20.0;

/// The rate ramp [s] of a `rotate` segment lasting `duration_s`.
pub fn rotate_ramp(duration_s: f64) -> f64 {
    ROTATE_RAMP_S.min(0.25 * duration_s)
}

/// Length [s] of the raised-cosine rate ramps at each end of a `rotate` segment (a quarter of
/// the segment when that is shorter).
pub const ROTATE_RAMP_S: f64 = 0.5;

/// A vibration source.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Vibration {
    /// `sine` (linear), `random` (linear, band-limited), `angular` (sinusoidal Euler angle).
    pub kind: String,
    /// `n` `e` `d` (NED) or `x` `y` `z` (FRD body) for linear; `roll` `pitch` `yaw` for angular.
    pub axis: String,
    /// Sine: peak acceleration (e.g. "6 g"); angular: peak angle (e.g. "1 deg").
    #[serde(default)]
    pub amplitude: Option<String>,
    /// Frequency [Hz] (sine, angular).
    #[serde(default)]
    pub freq_hz: f64,
    /// Phase [deg] (sine, angular).
    #[serde(default)]
    pub phase_deg: f64,
    /// Random: acceleration PSD (e.g. "0.01 g^2/Hz"), flat over `band_hz`.
    #[serde(default)]
    pub psd: Option<String>,
    /// Random: [low, high] band edges [Hz].
    #[serde(default)]
    pub band_hz: Option<[f64; 2]>,
    /// Random: number of sinusoids synthesising the band (default 200).
    #[serde(default)]
    pub components: Option<usize>,
    /// Windows [start_s, end_s, amplitude scale]; default: always on at scale 1.
    #[serde(default)]
    pub schedule: Option<Vec<[f64; 3]>>,
}

/// GNSS position aiding written by the simulator.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GnssSpec {
    /// Rate [Hz].
    pub rate_hz: f64,
    /// Horizontal 1-σ (e.g. "0.5 m").
    #[serde(default = "default_sigma_ne")]
    pub sigma_ne: String,
    /// Vertical 1-σ (e.g. "1 m").
    #[serde(default = "default_sigma_d")]
    pub sigma_d: String,
    /// Add Gaussian noise with those σ (default true).
    #[serde(default = "yes")]
    pub noisy: bool,
    /// 1-σ of a GNSS velocity written with each fix (e.g. "0.05 m/s"); none by default.
    #[serde(default)]
    pub sigma_v: Option<String>,
}

/// A body-frame velocity reference (odometer, DVL) written by the simulator: the true body
/// velocity turned by the scenario's mounting terms (`mount_x` … in `[errors]`).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ReferenceSpec {
    /// Rate [Hz].
    pub rate_hz: f64,
    /// 1-σ of each body-frame component (e.g. "0.05 m/s").
    #[serde(default = "default_sigma_reference")]
    pub sigma: String,
    /// Add Gaussian noise with that σ (default true).
    #[serde(default = "yes")]
    pub noisy: bool,
}

/// An attitude reference (a second INS, an AHRS) written by the simulator: the true attitude
/// turned by the scenario's mounting terms (`att_mount_x` … in `[errors]`).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AttitudeReferenceSpec {
    /// Rate [Hz].
    pub rate_hz: f64,
    /// 1-σ of roll and pitch (e.g. "0.05 deg").
    #[serde(default = "default_sigma_tilt")]
    pub sigma_tilt: String,
    /// 1-σ of yaw (e.g. "0.2 deg").
    #[serde(default = "default_sigma_yaw")]
    pub sigma_yaw: String,
    /// Add Gaussian noise with those σ (default true).
    #[serde(default = "yes")]
    pub noisy: bool,
}

fn default_sigma_tilt() -> String {
    "0.05 deg".into()
}
fn default_sigma_yaw() -> String {
    "0.2 deg".into()
}

fn default_sigma_reference() -> String {
    "0.05 m/s".into()
}

fn default_sigma_ne() -> String {
    "0.5 m".into()
}
fn default_sigma_d() -> String {
    "1 m".into()
}
fn yes() -> bool {
    true
}

/// Sensor noise.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NoiseSpec {
    /// Angle random walk (e.g. "0.01 deg/sqrt(h)").
    pub arw: Option<String>,
    /// Velocity random walk (e.g. "10 ug/sqrt(Hz)").
    pub vrw: Option<String>,
    /// Gyro bias random walk (e.g. "0.001 deg/h/sqrt(h)").
    pub gyro_bias_rw: Option<String>,
    /// Accelerometer bias random walk (e.g. "1 ug/sqrt(h)").
    pub accel_bias_rw: Option<String>,
    /// Gyro quantum (e.g. "0.1 arcsec").
    pub gyro_quantum: Option<String>,
    /// Accelerometer quantum (e.g. "1e-4 m/s").
    pub accel_quantum: Option<String>,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawScenario {
    name: String,
    #[serde(default)]
    imu_rate_hz: Option<f64>,
    #[serde(default = "default_truth_rate")]
    truth_rate_hz: f64,
    #[serde(default)]
    seed: u64,
    start: Start,
    segment: Vec<Segment>,
    #[serde(default)]
    vibration: Vec<Vibration>,
    #[serde(default)]
    errors: BTreeMap<String, String>,
    #[serde(default)]
    noise: NoiseSpec,
    #[serde(default)]
    gnss: Option<GnssSpec>,
    #[serde(default)]
    reference: Option<ReferenceSpec>,
    attitude_reference: Option<AttitudeReferenceSpec>,
    #[serde(default)]
    clock_jitter_periods: Option<u32>,
}

fn default_truth_rate() -> f64 {
    10.0
}

/// A validated scenario, SI units.
#[derive(Debug, Clone)]
pub struct Scenario {
    /// Name.
    pub name: String,
    /// IMU rate [Hz].
    pub imu_rate_hz: f64,
    /// Truth output rate [Hz].
    pub truth_rate_hz: f64,
    /// Seed of every random draw.
    pub seed: u64,
    /// Start.
    pub start: Start,
    /// Segments.
    pub segments: Vec<Segment>,
    /// Vibration sources.
    pub vibration: Vec<Vibration>,
    /// Injected errors: (term index in `common::TERMS`, SI value).
    pub errors: Vec<(usize, f64)>,
    /// ARW [rad/√s], VRW [m/s/√s], gyro/accel bias RW [rad/s/√s, m/s²/√s], quanta [rad, m/s].
    pub noise: NoiseSi,
    /// GNSS aiding (rate [Hz], σ_ne [m], σ_d [m], noisy).
    pub gnss: Option<(f64, f64, f64, bool)>,
    /// GNSS velocity 1-σ [m/s] when the fixes carry a velocity.
    pub gnss_sigma_v: Option<f64>,
    /// A body-frame velocity reference (rate [Hz], 1-σ [m/s], noisy).
    pub reference: Option<(f64, f64, bool)>,
    /// An attitude reference (rate [Hz], 1-σ tilt and yaw [rad], noisy).
    pub attitude_reference: Option<(f64, f64, f64, bool)>,
    /// A jittered IMU clock: each output sample spans 1 to this many periods of `imu_rate_hz`
    /// at random (1: a uniform clock).
    pub clock_jitter_periods: u32,
    /// Remarks that are not errors (vibration above the IMU's Nyquist frequency).
    pub warnings: Vec<String>,
    /// The scenario text, for provenance.
    pub text: String,
}

/// Noise parameters in SI.
#[derive(Debug, Clone, Copy, Default)]
pub struct NoiseSi {
    /// Angle random walk [rad/√s].
    pub arw: f64,
    /// Velocity random walk [m/s/√s].
    pub vrw: f64,
    /// Gyro bias random walk [rad/s/√s].
    pub gyro_bias_rw: f64,
    /// Accelerometer bias random walk [m/s²/√s].
    pub accel_bias_rw: f64,
    /// Gyro quantum [rad] (0 = none).
    pub gyro_quantum: f64,
    /// Accelerometer quantum [m/s] (0 = none).
    pub accel_quantum: f64,
}

/// Bounds on scenario quantities (a simulation must end and fit in memory).
const MAX_RATE_HZ: f64 = 1e5;
/// Longest segment [s].
const MAX_DURATION_S: f64 = 1e7;
/// Highest vibration frequency [Hz].
const MAX_VIB_HZ: f64 = 1e5;
/// Most sinusoids in a random vibration.
const MAX_COMPONENTS: usize = 10_000;

/// Line (1-based) of the first line that starts with `needle` as a whole key (`rate_hz` does not
/// match `imu_rate_hz`, `d_x` not `d_xy`); 0 when none does.
fn line_of(text: &str, needle: &str) -> usize {
    let needle = needle.trim_end();
    let ident = |c: char| c.is_alphanumeric() || c == '_';
    text.lines()
        .position(|l| {
            let l = l.trim_start();
            l.starts_with(needle)
                && (needle.ends_with(|c: char| !ident(c)) || !l[needle.len()..].starts_with(ident))
        })
        .map(|i| i + 1)
        .unwrap_or(0)
}

impl Scenario {
    /// Total duration [s].
    /// Vibration terms evaluated per quadrature node, and the sub-steps per IMU sample the
    /// simulator takes (16 per period of the fastest vibration): the work the simulation does is
    /// about samples × sub-steps × terms × 3 nodes.
    pub fn vibration_work(&self) -> (f64, f64) {
        let mut terms = 0.0;
        let mut max_f: f64 = 0.0;
        for v in &self.vibration {
            match v.kind.as_str() {
                "random" => {
                    terms += v.components.unwrap_or(200).max(1) as f64;
                    max_f = max_f.max(v.band_hz.map(|b| b[1]).unwrap_or(0.0));
                }
                _ => {
                    terms += 1.0;
                    max_f = max_f.max(v.freq_hz);
                }
            }
        }
        let sub = (16.0 * max_f / self.imu_rate_hz).ceil().max(1.0);
        (terms, sub)
    }

    /// Duration of all segments [s].
    pub fn duration(&self) -> f64 {
        self.segments.iter().map(|s| s.duration_s).sum()
    }

    /// Reads and validates a scenario file.
    pub fn load(path: &Path) -> Result<Scenario> {
        let text = crate::io::lines::read_small_text(path, "scenario")
            .with_context(|| format!("cannot read scenario {}", path.display()))?;
        Scenario::parse(&text, &path.display().to_string())
    }

    /// Parses scenario text; `origin` names it in messages.
    pub fn parse(text: &str, origin: &str) -> Result<Scenario> {
        let raw: RawScenario = toml::from_str(text).map_err(|e| {
            let line = e
                .span()
                .map(|s| crate::io::lines::line_at(text, s.start))
                .unwrap_or(0);
            anyhow!("{origin}:{line}: {}", e.message().trim())
        })?;
        let src = Src { text, origin };
        // default IMU rate: 2 kHz with vibration (DESIGN §2: increments attenuate <f^2>), else 100 Hz

        let imu_rate_hz = raw.imu_rate_hz.unwrap_or(if raw.vibration.is_empty() {
            100.0
        } else {
            2000.0
        });
        check_rates_and_start(&raw, &src, imu_rate_hz)?;
        let mut warnings = Vec::new();
        check_segments(&raw, origin, imu_rate_hz, &mut warnings)?;
        for v in &raw.vibration {
            check_vibration(v, &src, imu_rate_hz, &mut warnings)?;
        }
        let errors = parse_errors(&raw.errors, &src)?;
        let noise = parse_noise(&raw.noise, &src)?;
        let gnss = parse_gnss(raw.gnss.as_ref(), &src, imu_rate_hz)?;
        let gnss_sigma_v = parse_gnss_sigma_v(raw.gnss.as_ref(), &src)?;
        let reference = parse_reference(raw.reference.as_ref(), &src, imu_rate_hz)?;
        if reference.is_none() {
            if let Some(&(k, _)) = errors
                .iter()
                .find(|(k, _)| common::TERMS[*k].sensor == crate::model::catalog::Sensor::Reference)
            {
                bail!(
                    "{}: {} is a mounting of a velocity reference; the scenario has no [reference] section to write one",
                    src.at(common::TERMS[k].name),
                    common::TERMS[k].name
                );
            }
        }
        let attitude_reference =
            parse_attitude_reference(raw.attitude_reference.as_ref(), &src, imu_rate_hz)?;
        if attitude_reference.is_none() {
            if let Some(&(k, _)) = errors
                .iter()
                .find(|(k, _)| common::TERMS[*k].sensor == crate::model::catalog::Sensor::Attitude)
            {
                bail!(
                    "{}: {} is a mounting of an attitude reference; the scenario has no [attitude_reference] section to write one",
                    src.at(common::TERMS[k].name),
                    common::TERMS[k].name
                );
            }
        }
        let clock_jitter_periods = raw.clock_jitter_periods.unwrap_or(1);
        if !(1..=4).contains(&clock_jitter_periods) {
            bail!(
                "{}: clock_jitter_periods = {clock_jitter_periods} must be 1 (a uniform clock) to 4 (samples spanning 1 to 4 periods; the readers refuse gaps over 5 median intervals)",
                src.at("clock_jitter_periods")
            );
        }
        Ok(Scenario {
            name: raw.name,
            imu_rate_hz,
            truth_rate_hz: raw.truth_rate_hz,
            seed: raw.seed,
            start: raw.start,
            segments: raw.segment,
            vibration: raw.vibration,
            errors,
            noise,
            gnss,
            gnss_sigma_v,
            reference,
            attitude_reference,
            clock_jitter_periods,
            text: text.to_string(),
            warnings,
        })
    }
}

/// The scenario text and its name, to say where in it a message points.
struct Src<'a> {
    /// The scenario text.
    text: &'a str,
    /// Its name in messages.
    origin: &'a str,
}

impl Src<'_> {
    /// `origin:line` of the first line starting with key `needle` (line 0 when none does).
    fn at(&self, needle: &str) -> String {
        format!("{}:{}", self.origin, line_of(self.text, needle))
    }
}

/// Checks the IMU rate `imu_rate_hz` [Hz] (at most 1e5 Hz), the truth rate and the start.
fn check_rates_and_start(raw: &RawScenario, src: &Src, imu_rate_hz: f64) -> Result<()> {
    if !(imu_rate_hz > 0.0 && imu_rate_hz <= MAX_RATE_HZ) {
        bail!(
            "{}: imu_rate_hz = {imu_rate_hz} must be in (0, {MAX_RATE_HZ}] Hz",
            src.at("imu_rate_hz")
        );
    }
    if !(raw.truth_rate_hz > 0.0 && raw.truth_rate_hz <= imu_rate_hz) {
        bail!(
            "{}: truth_rate_hz must be in (0, imu_rate_hz]",
            src.at("truth_rate_hz")
        );
    }
    let st = &raw.start;
    if st.lat_deg.is_nan() || st.lat_deg.abs() >= 89.0 {
        bail!(
            "{}: lat_deg = {} must be within ±89°",
            src.at("lat_deg"),
            st.lat_deg
        );
    }
    use crate::io::bounds;
    if let Some(p) = bounds::lon_deg(st.lon_deg) {
        bail!("{}: lon_deg: {p}", src.at("lon_deg"));
    }
    if let Some(p) = bounds::height_m(st.h_m) {
        bail!("{}: h_m: {p}", src.at("h_m"));
    }
    if let Some(p) = bounds::attitude_deg(st.euler_deg) {
        bail!("{}: euler_deg: {p}", src.at("euler_deg"));
    }
    if !(0.0..=1e4).contains(&st.speed_mps) {
        bail!(
            "{}: speed_mps = {} must be in 0 .. 1e4 m/s",
            src.at("speed_mps"),
            st.speed_mps
        );
    }
    Ok(())
}

/// Checks the motion segments (durations, rates, kinds, the speed they lead to within 0 to
/// 1e4 m/s, `rotate` only at rest) at an IMU rate of `imu_rate_hz` [Hz].
fn check_segments(
    raw: &RawScenario,
    origin: &str,
    imu_rate_hz: f64,
    warnings: &mut Vec<String>,
) -> Result<()> {
    if raw.segment.is_empty() {
        bail!("{origin}: at least one [[segment]] is needed");
    }
    let mut speed = raw.start.speed_mps;
    for (k, s) in raw.segment.iter().enumerate() {
        let where_ = format!("{origin}: segment {} (`{}`)", k + 1, s.kind);
        if !(s.duration_s > 0.0 && s.duration_s <= MAX_DURATION_S) {
            bail!(
                "{where_}: duration_s = {} must be in (0, {MAX_DURATION_S}] s",
                s.duration_s
            );
        }
        if !(s.accel_mps2.abs() <= 1e3 && s.yaw_rate_deg_s.abs() <= 1e4) {
            bail!(
                "{where_}: accel_mps2 = {} (|a| <= 1000 m/s^2) or yaw_rate_deg_s = {} (|r| <= 1e4 deg/s) out of range",
                s.accel_mps2,
                s.yaw_rate_deg_s
            );
        }
        if s.kind != "rotate" && (s.axis.is_some() || s.angle_deg.is_some()) {
            bail!("{where_}: `axis` and `angle_deg` belong to `rotate` segments");
        }
        match s.kind.as_str() {
            "rest" if speed != 0.0 => {
                bail!("{where_}: rest needs zero speed (speed is {speed} m/s)")
            }
            "rest" | "cruise" | "turn" => {}
            "accelerate" => speed += s.accel_mps2 * s.duration_s,
            "rotate" => check_rotate(s, &where_, imu_rate_hz, warnings)?,
            other => {
                bail!("{where_}: unknown kind `{other}` (rest, cruise, accelerate, turn, rotate)")
            }
        }
        if speed < 0.0 {
            bail!("{where_}: speed would become negative");
        }
        if speed > 1e4 {
            bail!("{where_}: speed would exceed 1e4 m/s");
        }
    }
    if raw.segment.iter().any(|s| s.kind == "rotate") {
        if raw.start.speed_mps != 0.0
            || raw
                .segment
                .iter()
                .any(|s| !matches!(s.kind.as_str(), "rest" | "rotate"))
        {
            bail!(
                "{origin}: a `rotate` segment is a turntable rotation at rest: the scenario may then hold only `rest` and `rotate` segments, from speed_mps = 0"
            );
        }
        if raw.vibration.iter().any(|v| v.kind == "angular") {
            bail!(
                "{origin}: angular vibration and `rotate` segments cannot be combined (the turntable sets the attitude)"
            );
        }
    }
    Ok(())
}

/// Checks one vibration source at an IMU rate of `imu_rate_hz` [Hz]; one above the Nyquist
/// frequency is pushed to `warnings`.
fn check_vibration(
    v: &Vibration,
    src: &Src,
    imu_rate_hz: f64,
    warnings: &mut Vec<String>,
) -> Result<()> {
    let where_ = format!(
        "{}: vibration `{}` on `{}`",
        src.at(&format!("axis = \"{}\"", v.axis)),
        v.kind,
        v.axis
    );
    check_vibration_keys(v, &where_)?;
    check_vibration_level(v, &where_, imu_rate_hz, warnings)?;
    if v.kind != "random" {
        if !(v.freq_hz > 0.0 && v.freq_hz <= MAX_VIB_HZ) {
            bail!(
                "{where_}: freq_hz = {} must be in (0, {MAX_VIB_HZ}] Hz",
                v.freq_hz
            );
        }
        if v.freq_hz > 0.5 * imu_rate_hz {
            warnings.push(format!(
                "{where_}: freq_hz = {} is above the Nyquist frequency of the {imu_rate_hz} Hz IMU: the increments average it away",
                v.freq_hz
            ));
        }
    }
    if !v.phase_deg.is_finite() {
        bail!("{where_}: phase_deg must be finite");
    }
    for w in v.schedule.iter().flatten() {
        if !(w.iter().all(|x| x.is_finite()) && w[1] > w[0] && w[2].abs() <= 1e3) {
            bail!("{where_}: schedule window {w:?} must be finite with end > start and |scale| <= 1000");
        }
    }
    Ok(())
}

/// Checks a vibration source's kind, its axis, and that it sets no key of another kind.
fn check_vibration_keys(v: &Vibration, where_: &str) -> Result<()> {
    let linear_axes = ["n", "e", "d", "x", "y", "z"];
    match v.kind.as_str() {
        "sine" | "random" if !linear_axes.contains(&v.axis.as_str()) => {
            bail!("{where_}: axis must be one of n e d x y z")
        }
        "angular" if !["roll", "pitch", "yaw"].contains(&v.axis.as_str()) => {
            bail!("{where_}: axis must be roll, pitch or yaw")
        }
        "sine" | "random" | "angular" => {}
        other => bail!("{where_}: unknown kind `{other}` (sine, random, angular)"),
    }
    // a key of another kind would be ignored without a word (and went unchecked: a
    // random source took `freq_hz = nan`)
    let foreign = if v.kind == "random" {
        [
            (v.amplitude.is_some(), "amplitude"),
            (v.freq_hz != 0.0, "freq_hz"),
            (v.phase_deg != 0.0, "phase_deg"),
        ]
    } else {
        [
            (v.psd.is_some(), "psd"),
            (v.band_hz.is_some(), "band_hz"),
            (v.components.is_some(), "components"),
        ]
    };
    if let Some((_, key)) = foreign.iter().find(|(set, _)| *set) {
        let uses = if v.kind == "random" {
            "psd, band_hz, components"
        } else {
            "amplitude, freq_hz, phase_deg"
        };
        bail!(
            "{where_}: `{key}` does not apply to a `{}` vibration (it takes {uses}, schedule)",
            v.kind
        );
    }
    Ok(())
}

/// Checks a vibration source's level: a sine's amplitude (within ±1000 g), an angular one's
/// (within ±180°), a random one's PSD (0 to 100 g²/Hz), band [Hz] and components.
fn check_vibration_level(
    v: &Vibration,
    where_: &str,
    imu_rate_hz: f64,
    warnings: &mut Vec<String>,
) -> Result<()> {
    match v.kind.as_str() {
        "sine" => {
            let a = v
                .amplitude
                .as_deref()
                .ok_or_else(|| anyhow!("{where_}: amplitude missing"))?;
            let a = units::parse_quantity_as(a, "m/s^2")
                .map_err(|e| anyhow!("{where_}: amplitude: {e}"))?;
            if a.is_nan() || a.abs() > 1000.0 * units::STANDARD_GRAVITY {
                bail!("{where_}: amplitude must be within ±1000 g");
            }
        }
        "angular" => {
            let a = v
                .amplitude
                .as_deref()
                .ok_or_else(|| anyhow!("{where_}: amplitude missing"))?;
            let a = units::parse_quantity_as(a, "rad")
                .map_err(|e| anyhow!("{where_}: amplitude: {e}"))?;
            if a.is_nan() || a.abs() > std::f64::consts::PI {
                bail!("{where_}: amplitude must be within ±180 deg");
            }
        }
        _ => {
            let p = v
                .psd
                .as_deref()
                .ok_or_else(|| anyhow!("{where_}: psd missing"))?;
            let p = units::parse_quantity_as(p, "m^2/s^4/Hz")
                .map_err(|e| anyhow!("{where_}: psd: {e}"))?;
            let g2 = units::STANDARD_GRAVITY.powi(2);
            if !(0.0..=100.0 * g2).contains(&p) {
                bail!("{where_}: psd must be in 0 .. 100 g^2/Hz");
            }
            let b = v
                .band_hz
                .ok_or_else(|| anyhow!("{where_}: band_hz missing"))?;
            if !(b[0] > 0.0 && b[1] > b[0] && b[1] <= MAX_VIB_HZ) {
                bail!(
                    "{where_}: band_hz must be [low, high] with 0 < low < high <= {MAX_VIB_HZ} Hz"
                );
            }
            if b[1] > 0.5 * imu_rate_hz {
                warnings.push(format!(
                    "{where_}: band_hz reaches {} Hz, above the Nyquist frequency of the {imu_rate_hz} Hz IMU: the increments average it away",
                    b[1]
                ));
            }
            if let Some(c) = v.components {
                if !(1..=MAX_COMPONENTS).contains(&c) {
                    bail!("{where_}: components = {c} must be in 1 ..= {MAX_COMPONENTS}");
                }
            }
        }
    }
    Ok(())
}

/// The injected errors of `[errors]`: (term index in `common::TERMS`, SI value).
fn parse_errors(raw: &BTreeMap<String, String>, src: &Src) -> Result<Vec<(usize, f64)>> {
    let mut errors = Vec::new();
    for (name, value) in raw {
        let at_e = src.at(&format!("{name} "));
        let k = common::TERMS
            .iter()
            .position(|t| t.name == name)
            .ok_or_else(|| {
                anyhow!("{at_e}: [errors]: unknown term `{name}` (see `sinsmodel model list`)")
            })?;
        let si = units::parse_quantity_as(value, common::TERMS[k].unit).map_err(|e| {
            anyhow!(
                "{at_e}: [errors] {name}: {e} (unit of {name}: {})",
                common::TERMS[k].unit
            )
        })?;
        if !si.is_finite() {
            bail!("{at_e}: [errors] {name} = {value} is not finite in SI units");
        }
        if let Some(why) = common::TERMS[k].beyond_limit(si) {
            bail!("{at_e}: [errors] {name} = {value}: {why}");
        }
        errors.push((k, si));
    }
    Ok(errors)
}

/// The `[noise]` levels in SI (an absent one 0).
fn parse_noise(n: &NoiseSpec, src: &Src) -> Result<NoiseSi> {
    let q = |v: &Option<String>, unit: &str, key: &str| -> Result<f64> {
        match v {
            Some(s) => {
                let x = units::parse_quantity_as(s, unit)
                    .map_err(|e| anyhow!("{}: [noise] {key}: {e}", src.at(key)))?;
                if !(x.is_finite() && x >= 0.0) {
                    bail!(
                        "{}: [noise] {key} = {s} must be finite and >= 0",
                        src.at(key)
                    );
                }
                Ok(x)
            }
            None => Ok(0.0),
        }
    };
    Ok(NoiseSi {
        arw: q(&n.arw, "rad/sqrt(s)", "arw")?,
        vrw: q(&n.vrw, "m/s/sqrt(s)", "vrw")?,
        gyro_bias_rw: q(&n.gyro_bias_rw, "rad/s/sqrt(s)", "gyro_bias_rw")?,
        accel_bias_rw: q(&n.accel_bias_rw, "m/s^2/sqrt(s)", "accel_bias_rw")?,
        gyro_quantum: q(&n.gyro_quantum, "rad", "gyro_quantum")?,
        accel_quantum: q(&n.accel_quantum, "m/s", "accel_quantum")?,
    })
}

/// GNSS aiding as (rate [Hz], σ_ne [m], σ_d [m], noisy), its rate at most `imu_rate_hz` [Hz].
fn parse_gnss(
    g: Option<&GnssSpec>,
    src: &Src,
    imu_rate_hz: f64,
) -> Result<Option<(f64, f64, f64, bool)>> {
    Ok(match g {
        Some(g) => {
            if !(g.rate_hz > 0.0 && g.rate_hz <= imu_rate_hz) {
                bail!(
                    "{}: [gnss] rate_hz must be in (0, imu_rate_hz]",
                    src.at("rate_hz")
                );
            }
            let sne = units::parse_quantity_as(&g.sigma_ne, "m")
                .map_err(|e| anyhow!("{}: [gnss] sigma_ne: {e}", src.at("sigma_ne")))?;
            let sd = units::parse_quantity_as(&g.sigma_d, "m")
                .map_err(|e| anyhow!("{}: [gnss] sigma_d: {e}", src.at("sigma_d")))?;
            // gnss.txt holds heights to 0.1 mm: a σ must be well above that
            if !((1e-3..=1e4).contains(&sne) && (1e-3..=1e4).contains(&sd)) {
                bail!(
                    "{}: [gnss] sigma_ne and sigma_d must be in [1e-3, 1e4] m (gnss.txt holds positions to 0.1 mm)",
                    src.at("sigma_ne")
                );
            }
            Some((g.rate_hz, sne, sd, g.noisy))
        }
        None => None,
    })
}

/// A body-frame velocity reference as (rate [Hz], 1-σ [m/s], noisy): a rate in (0,
/// imu_rate_hz] [Hz], a σ in [1e-4, 100] m/s.
fn parse_reference(
    r: Option<&ReferenceSpec>,
    src: &Src,
    imu_rate_hz: f64,
) -> Result<Option<(f64, f64, bool)>> {
    let Some(r) = r else { return Ok(None) };
    if !(r.rate_hz > 0.0 && r.rate_hz <= imu_rate_hz) {
        bail!(
            "{}: [reference] rate_hz must be in (0, imu_rate_hz]",
            src.at("rate_hz")
        );
    }
    let s = units::parse_quantity_as(&r.sigma, "m/s")
        .map_err(|e| anyhow!("{}: [reference] sigma: {e}", src.at("sigma")))?;
    if !(1e-4..=100.0).contains(&s) {
        bail!(
            "{}: [reference] sigma must be in [1e-4, 100] m/s (reference.txt holds velocities to 1 um/s)",
            src.at("sigma")
        );
    }
    Ok(Some((r.rate_hz, s, r.noisy)))
}

/// An attitude reference as (rate [Hz], 1-σ tilt and yaw [rad], noisy): a rate in (0,
/// imu_rate_hz] [Hz], each σ in [0.001, 10] deg.
fn parse_attitude_reference(
    r: Option<&AttitudeReferenceSpec>,
    src: &Src,
    imu_rate_hz: f64,
) -> Result<Option<(f64, f64, f64, bool)>> {
    let Some(r) = r else { return Ok(None) };
    if !(r.rate_hz > 0.0 && r.rate_hz <= imu_rate_hz) {
        bail!(
            "{}: [attitude_reference] rate_hz must be in (0, imu_rate_hz]",
            src.at("rate_hz")
        );
    }
    let mut sig = [0.0; 2];
    for (k, (name, text)) in [("sigma_tilt", &r.sigma_tilt), ("sigma_yaw", &r.sigma_yaw)]
        .into_iter()
        .enumerate()
    {
        let s = units::parse_quantity_as(text, "rad")
            .map_err(|e| anyhow!("{}: [attitude_reference] {name}: {e}", src.at(name)))?;
        if !(0.001f64.to_radians()..=10f64.to_radians()).contains(&s) {
            bail!(
                "{}: [attitude_reference] {name} must be in [0.001, 10] deg (attitude.txt holds angles to 1e-6 deg)",
                src.at(name)
            );
        }
        sig[k] = s;
    }
    Ok(Some((r.rate_hz, sig[0], sig[1], r.noisy)))
}

/// The 1-σ [m/s] of the GNSS velocity written with each fix, if any (1e-4 to 100 m/s).
fn parse_gnss_sigma_v(g: Option<&GnssSpec>, src: &Src) -> Result<Option<f64>> {
    Ok(match g.and_then(|g| g.sigma_v.as_ref()) {
        Some(v) => {
            let sv = units::parse_quantity_as(v, "m/s")
                .map_err(|e| anyhow!("{}: [gnss] sigma_v: {e}", src.at("sigma_v")))?;
            if !(1e-4..=100.0).contains(&sv) {
                bail!(
                    "{}: [gnss] sigma_v must be in [1e-4, 100] m/s (gnss.txt holds velocities to 1 um/s)",
                    src.at("sigma_v")
                );
            }
            Some(sv)
        }
        None => None,
    })
}
