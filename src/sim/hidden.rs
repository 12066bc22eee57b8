//! Seeded cases with an error term hidden in simulated data, for testing and evaluating
//! `explain`: a library term (or none, or two), a scenario that excites it (DESIGN §7), a
//! magnitude, and a baseline model that lacks it.

use crate::model::generated::common;
use crate::sim::rng::Rng;

/// Library groups a case can hide a term from.
pub const GROUPS: [&str; 7] = ["d", "kaq", "kas", "kao", "kgf", "kgq", "size"];

/// Groups of GNSS (measurement) terms a case can hide, on a drive with turns and speed
/// changes: the IMU–GNSS time offset (20–300 ms times `effect`), the same with a gyro
/// g-sensitivity kgf_yx beside it (3 deg/h/(m/s²) times `effect`, MEMS class), and the antenna
/// lever arm (0.1–2 m times `effect`). No vibration: the time offset's velocity rows use the
/// step's specific force, which vibration faster than the offset would not average.
pub const GNSS_GROUPS: [&str; 3] = ["gnss_time", "gnss_time_kgf", "gnss_lever"];

/// Groups of a body-frame velocity reference's mounting (an odometer or DVL at 10 Hz, σ 0.05
/// m/s) on the drive of the GNSS cases: its pitch and yaw against the IMU (`mount_y`,
/// `mount_z`, each 0.2–2° times `effect`, either sign), alone (`reference_mount`) or with a
/// gyro g-sensitivity kgf_yx beside it (`reference_mount_kgf`, as in `gnss_time_kgf`); and the
/// reference's time offset (`dt_ref`, 20–300 ms times `effect`, either sign) with its yaw
/// mounting (`reference_time`); and an attitude reference's mounting (a second INS or an AHRS at
/// 10 Hz, σ 0.05° tilt and 0.1° yaw): its roll and yaw, 0.2–2° each times `effect`, either sign
/// (`attitude_mount`). The baseline has the vertical channel (the velocity reference's rows
/// need it).
pub const REFERENCE_GROUPS: [&str; 4] = [
    "reference_mount",
    "reference_mount_kgf",
    "reference_time",
    "attitude_mount",
];

/// Groups hiding two terms (besides `gnss_time_kgf`, `reference_mount_kgf` and
/// `noise_accel_kgf`, which put a gyro g-sensitivity beside a GNSS, reference or noise cause):
/// d_x and d_y on different windows (`two`), and d and kas on one axis (`two_axis`).
pub const TWO_GROUPS: [&str; 2] = ["two", "two_axis"];

/// Every group a case can be drawn from: the sensor terms, the GNSS, reference and turntable
/// groups, the two-term groups and the misstated noise.
pub fn all_groups() -> Vec<&'static str> {
    GROUPS
        .iter()
        .chain(&GNSS_GROUPS)
        .chain(&REFERENCE_GROUPS)
        .chain(&TURNTABLE_GROUPS)
        .chain(&TWO_GROUPS)
        .chain(&NOISE_GROUPS)
        .copied()
        .collect()
}

/// Groups hidden on a turntable (a multi-position rotation sequence at rest, static aiding): an
/// accelerometer's off-axis inner lever arm (`size_i_j`, 20–60 mm times `effect`), seen in
/// the tangential kicks as a rotation starts and stops and in the centripetal terms.
/// And a gyro–accelerometer asynchrony: all three accelerometers' delay behind the gyros
/// (`tau_x tau_y tau_z`, one value of 1–3 ms times `effect`); and both together
/// (`inner_lever_delay`: what a real unit's calibration sequence holds).
pub const TURNTABLE_GROUPS: [&str; 3] = ["inner_lever", "accel_delay", "inner_lever_delay"];

/// Groups in which one sensor's white noise is stated wrongly, on a drive with turns and speed
/// changes aided by position and velocity fixes: the filter is told a MEMS grade's noise
/// (0.5 deg/√h, 150 µg/√Hz) while the gyro's (`noise_gyro`) or the accelerometer's
/// (`noise_accel`, and `noise_accel_kgf` with a gyro g-sensitivity kgf_yx beside it) is
/// k = 1 + `effect` · (1 … 9) times larger, or 1/k of it (`*_large`: stated too large). In
/// `noise_gyro_bias` and `noise_accel_bias` the filter is also told a bias random walk (bias
/// instability: 30 deg/h/√h, 30 µg/√s) and the gyro's or accelerometer's is k times larger.
pub const NOISE_GROUPS: [&str; 7] = [
    "noise_gyro",
    "noise_accel",
    "noise_accel_kgf",
    "noise_gyro_large",
    "noise_accel_large",
    "noise_gyro_bias",
    "noise_accel_bias",
];

/// The noise a noise group's filter is told: the MEMS grade's white noise 0.5 deg/√h [rad/√s]
/// and 150 µg/√Hz [m/s/√s] (grades.toml), and in the bias groups a bias random walk of
/// 30 deg/h/√h [rad/s/√s] and 30 µg/√s [m/s²/√s] (none in the others).
pub fn stated_noise(group: &str) -> [f64; 4] {
    let d2r = std::f64::consts::PI / 180.0;
    let bias = group.ends_with("_bias");
    [
        0.5 * d2r / 60.0,
        150e-6 * G0,
        if bias {
            30.0 * d2r / 3600.0 / 60.0
        } else {
            0.0
        },
        if bias { 30e-6 * G0 } else { 0.0 },
    ]
}

/// A system-level calibration sequence: 60 s at rest, then 18 rotations of ±90° in 5 s
/// (about 20 deg/s) about x, y and z — four about each axis, then x, y, z, −z, −y, −x — with
/// 20 s at rest after each.
pub fn turntable_segments() -> String {
    let mut s = String::from("[[segment]]\nkind = \"rest\"\nduration_s = 60.0\n");
    let seq = ["x", "x", "x", "x", "y", "y", "y", "y", "z", "z", "z", "z"]
        .iter()
        .map(|a| (*a, 90.0))
        .chain([
            ("x", 90.0),
            ("y", 90.0),
            ("z", 90.0),
            ("z", -90.0),
            ("y", -90.0),
            ("x", -90.0),
        ]);
    for (axis, angle) in seq {
        s.push_str(&format!(
            "[[segment]]\nkind = \"rotate\"\naxis = \"{axis}\"\nangle_deg = {angle:.1}\nduration_s = 5.0\n[[segment]]\nkind = \"rest\"\nduration_s = 20.0\n"
        ));
    }
    s
}

/// A drive for the GNSS cases: 60 s at rest, a start to 20 m/s, then minute-long cycles of a
/// turn (±6 deg/s for 15 s), a speed change (±1 m/s² for 10 s) and straight driving.
fn drive_segments(seconds: f64) -> String {
    let n = ((seconds - 70.0) / 60.0).floor().max(1.0) as usize;
    let mut s = String::from(
        "[[segment]]\nkind = \"rest\"\nduration_s = 60.0\n[[segment]]\nkind = \"accelerate\"\nduration_s = 10.0\naccel_mps2 = 2.0\n",
    );
    for i in 0..n {
        let r = if i % 2 == 0 { 6.0 } else { -6.0 };
        let a = if (i / 2) % 2 == 0 { 1.0 } else { -1.0 };
        s.push_str(&format!(
            "[[segment]]\nkind = \"turn\"\nduration_s = 15.0\nyaw_rate_deg_s = {r}\n[[segment]]\nkind = \"cruise\"\nduration_s = 20.0\n[[segment]]\nkind = \"accelerate\"\nduration_s = 10.0\naccel_mps2 = {a}\n[[segment]]\nkind = \"cruise\"\nduration_s = 15.0\n"
        ));
    }
    s
}

/// Standard gravity [m/s²].
const G0: f64 = 9.806_65;

/// What kind of case to draw.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CaseKind {
    /// Nothing hidden beyond the baseline's own errors.
    Null,
    /// One term of a group.
    One(&'static str),
    /// Two terms (d_x and d_y on different windows) that need forward selection.
    Two,
}

/// A hidden-effect case.
#[derive(Debug, Clone)]
pub struct HiddenCase {
    /// Seed of the draw (also the simulation's).
    pub seed: u64,
    /// Group (`null` and `two` for those kinds).
    pub group: String,
    /// Hidden terms and their true values, SI.
    pub hidden: Vec<(String, f64)>,
    /// Baseline model that lacks them.
    pub baseline: String,
    /// Scenario text (scenario file format).
    pub scenario: String,
    /// One line describing the case.
    pub description: String,
    /// Effect size used to size the magnitude (mg for accelerometer, deg/h for gyro terms).
    pub effect: f64,
    /// Prior σ (SI) the case declares for candidate terms, replacing the spec's RLG-grade ones
    /// where the hidden magnitude belongs to another sensor class (as `--prior` would).
    pub priors: Vec<(String, f64)>,
    /// Candidate terms withheld from explain (a compromise case: the hidden effect is outside
    /// the candidates explain may name; see [`HiddenCase::withholding`]).
    pub withheld: Vec<String>,
    /// The aiding is static (a turntable): explain runs as with `--static-aid`, without GNSS
    /// candidates (no antenna, no receiver clock) or noise levels (the aiding σ is a tuning
    /// choice).
    pub static_aid: bool,
    /// The noise the filter is told: white noise, gyro [rad/√s] and accelerometer [m/s/√s],
    /// and bias random walk, gyro [rad/s/√s] and accelerometer [m/s²/√s]; None: the spec's, as
    /// simulated.
    pub stated_noise: Option<[f64; 4]>,
    /// Noise levels stated wrongly (`gyro_arw`, `accel_vrw`, `gyro_bias_rw`, `accel_bias_rw`)
    /// and the ratio of the simulated level to the stated one.
    pub noise_ratio: Vec<(String, f64)>,
}

impl HiddenCase {
    /// The model a filter that knows the truth would use: baseline + hidden terms.
    pub fn oracle_model(&self) -> String {
        let mut m = self.baseline.clone();
        for (t, _) in &self.hidden {
            m.push('+');
            m.push_str(t);
        }
        m
    }

    /// The same case with the candidates whose names start with one of `prefixes` withheld from
    /// explain: the hidden effect is then outside what explain may name, and whatever it fits
    /// stands in for it.
    pub fn withholding(&self, prefixes: &[&str]) -> HiddenCase {
        let mut c = self.clone();
        c.withheld.extend(
            common::TERMS
                .iter()
                .filter(|t| prefixes.iter().any(|p| t.name.starts_with(p)))
                .map(|t| t.name.to_string()),
        );
        c.description = format!(
            "{} (candidates {}* withheld)",
            c.description,
            prefixes.join("*, ")
        );
        c
    }

    /// The same case with every hidden value multiplied by `k` (the scenario is rewritten).
    pub fn scaled(&self, k: f64) -> HiddenCase {
        let mut c = self.clone();
        for (name, v) in &mut c.hidden {
            let old = format!("{name} = \"{:e} {}\"", *v, unit_of(name));
            *v *= k;
            let new = format!("{name} = \"{:e} {}\"", *v, unit_of(name));
            c.scenario = c.scenario.replace(&old, &new);
        }
        c.effect *= k;
        c
    }
}

/// The ratio simulated/stated of noise `level` in `noise_ratio` (1 when it is stated right).
pub fn ratio_of(noise_ratio: &[(String, f64)], level: &str) -> f64 {
    noise_ratio
        .iter()
        .find(|x| x.0 == level)
        .map_or(1.0, |x| x.1)
}

fn unit_of(name: &str) -> &'static str {
    common::TERMS
        .iter()
        .find(|t| t.name == name)
        .map(|t| t.unit)
        .unwrap_or("1")
}

fn pick<'a, T>(rng: &mut Rng, v: &'a [T]) -> &'a T {
    let k = ((rng.uniform() * v.len() as f64) as usize).min(v.len() - 1);
    &v[k]
}

fn sine(axis: &str, amp_g: f64, freq: f64, schedule: &str) -> String {
    format!(
        "[[vibration]]\nkind = \"sine\"\naxis = \"{axis}\"\namplitude = \"{amp_g} g\"\nfreq_hz = {freq}\nschedule = {schedule}\n"
    )
}

fn angular(axis: &str, amp_deg: f64, freq: f64, schedule: &str) -> String {
    format!(
        "[[vibration]]\nkind = \"angular\"\naxis = \"{axis}\"\namplitude = \"{amp_deg} deg\"\nfreq_hz = {freq}\nschedule = {schedule}\n"
    )
}

/// Magnitude (the `effect` of [`generate`]) at which a 600 s case of `kind` determines the
/// hidden term to a few percent: 1 mg for accelerometer groups, 3 deg/h for the gyro groups
/// (their excitation is weaker: 0.2 g manoeuvres, or a tilt that must build up).
pub fn clear_effect(kind: CaseKind) -> f64 {
    match kind {
        CaseKind::One("kgf") | CaseKind::One("kgq") => 3.0,
        _ => 1.0,
    }
}

/// The baseline's own instrument errors (paper-like magnitudes, seeded signs), without `skip`.
fn baseline_errors(rng: &mut Rng, with_d: bool, skip: &[String]) -> String {
    let mut s = String::from("[errors]\n");
    let add = |name: &str, v: &str, s: &mut String| {
        if !skip.iter().any(|x| x == name) {
            s.push_str(&format!("{name} = \"{v}\"\n"));
        }
    };
    for ax in ["x", "y", "z"] {
        let sgn = if rng.uniform() < 0.5 { -1.0 } else { 1.0 };
        add(
            &format!("eps_{ax}"),
            &format!("{} deg/h", 0.01 * sgn),
            &mut s,
        );
        let sgn = if rng.uniform() < 0.5 { -1.0 } else { 1.0 };
        add(
            &format!("nabla_{ax}"),
            &format!("{} ug", 50.0 * sgn),
            &mut s,
        );
        if with_d {
            add(&format!("d_{ax}"), "5e-6 s^2/m", &mut s);
        }
    }
    for k in ["kg_11", "kg_22", "kg_33", "ka_11", "ka_22", "ka_33"] {
        add(k, "20 ppm", &mut s);
    }
    s
}

/// What every group's draw shares: the case's length, windows, vibration and effect sizes.
struct Draw {
    /// Length of the case [s].
    seconds: f64,
    /// Vibration frequency [Hz].
    freq: f64,
    /// Length of one of the six windows [s].
    w: f64,
    /// First window on (start, end) [s].
    on1: (f64, f64),
    /// Second window on (start, end) [s].
    on2: (f64, f64),
    /// Schedule: the first window at scale 1, the second at 0.5.
    steps: String,
    /// Vibration amplitude [g].
    amp: f64,
    /// The effect at the strongest excitation (mg or deg/h).
    effect: f64,
    /// The effect as an acceleration [m/s²].
    effect_si_acc: f64,
    /// The effect as an angular rate [rad/s].
    effect_si_gyro: f64,
    /// Vibration amplitude [m/s²].
    a_si: f64,
}

/// The parts of a case a group's draw sets: scenario pieces, hidden terms, baseline.
struct Parts {
    /// The `[[segment]]`s.
    segments: String,
    /// The `[[vibration]]`s.
    vib: String,
    /// Hidden terms and their true values, SI.
    hidden: Vec<(String, f64)>,
    /// Baseline model that lacks them.
    baseline: String,
    /// The baseline has its own d_x, d_y, d_z errors.
    with_d: bool,
    /// Noise levels stated wrongly and the ratio simulated/stated (stated: [`stated_noise`]).
    noise_ratio: Vec<(String, f64)>,
}

/// Draws a case of `kind` from `seed`. Cases last `seconds` (≥ 300) of 2 kHz IMU data at rest
/// (or a short drive for the g-sensitivity group), with windows of excitation that switch on
/// and off or step in amplitude, so that the hidden term is separable from the baseline's bias
/// and tilt. `effect` sizes the term: the mg (accelerometer) or deg/h (gyro) it produces at the
/// strongest excitation.
pub fn generate(seed: u64, kind: CaseKind, seconds: f64, effect: f64) -> HiddenCase {
    let mut rng = Rng::new(seed.wrapping_mul(0x9e37_79b9).wrapping_add(17));
    let seconds = seconds.max(300.0);
    let lat = 20.0 + 30.0 * rng.uniform();
    let freq = (30.0 + 30.0 * rng.uniform()).round();
    let w = seconds / 6.0; // six windows
    let win = |a: f64, b: f64| (a * w, b * w);
    let (on1, on2) = (win(1.0, 2.0), win(3.0, 4.0));
    let steps = format!(
        "[[{:.1}, {:.1}, 1.0], [{:.1}, {:.1}, 0.5]]",
        on1.0, on1.1, on2.0, on2.1
    );
    let amp = (4.0 + 4.0 * rng.uniform()).round(); // g
    let d = Draw {
        seconds,
        freq,
        w,
        on1,
        on2,
        steps,
        amp,
        effect,
        effect_si_acc: effect * 1e-3 * G0,
        effect_si_gyro: effect * std::f64::consts::PI / 180.0 / 3600.0,
        a_si: amp * G0,
    };
    let mut p = Parts {
        segments: format!("[[segment]]\nkind = \"rest\"\nduration_s = {seconds}\n"),
        vib: String::new(),
        hidden: Vec::new(),
        baseline: "P31".to_string(),
        with_d: true,
        noise_ratio: Vec::new(),
    };
    let (group, description): (String, String) = match kind {
        CaseKind::Null => ("null".into(), draw_null(&mut rng, &d, &mut p)),
        CaseKind::Two => ("two".into(), draw_two(&d, &mut p)),
        CaseKind::One("two_axis") => ("two_axis".into(), draw_two_axis(&mut rng, &d, &mut p)),
        CaseKind::One(g) => {
            draw_one(g, &mut rng, &d, &mut p);
            let text = if NOISE_GROUPS.contains(&g) {
                noise_description(&p)
            } else {
                one_description(g, &p, effect)
            };
            (g.into(), text)
        }
    };
    assemble(seed, group, description, lat, effect, &mut rng, p)
}

/// A null case: nothing hidden, a stepped sine vibration on x or y; returns the description.
fn draw_null(rng: &mut Rng, d: &Draw, p: &mut Parts) -> String {
    let amp = d.amp;
    let axes = ["x", "y", "z"];
    let ax = *pick(rng, &axes[..2]);
    p.vib = sine(ax, amp, d.freq, &d.steps);
    format!(
        "nothing hidden; {amp} g / {} g vibration on {ax}",
        amp / 2.0
    )
}

/// A case hiding d_x and d_y on different windows; returns the description.
fn draw_two(d: &Draw, p: &mut Parts) -> String {
    let (amp, freq, w, a_si) = (d.amp, d.freq, d.w, d.a_si);
    p.baseline = "P28".into();
    p.with_d = false;
    // x alone, y alone, then both at half amplitude: two amplitudes per axis separate
    // the quadratic terms from the asymmetric scale factors
    let both = (5.0 * w, 5.5 * w);
    let sched = |on: (f64, f64)| {
        format!(
            "[[{:.1}, {:.1}, 1.0], [{:.1}, {:.1}, 0.5]]",
            on.0, on.1, both.0, both.1
        )
    };
    p.vib = sine("x", amp, freq, &sched(d.on1)) + &sine("y", amp, freq + 7.0, &sched(d.on2));
    let dd = d.effect_si_acc / (a_si * a_si / 2.0);
    p.hidden.push(("d_x".into(), dd));
    p.hidden.push(("d_y".into(), -0.7 * dd));
    format!(
        "d_x and d_y hidden; {amp} g vibration on x, then y, then both at {} g",
        amp / 2.0
    )
}

/// A case hiding two sensor terms on one axis (x or y): the quadratic term d and the
/// asymmetric scale factor kas, under a sine vibration on that axis at two amplitudes (the
/// mean of f² goes with the amplitude squared, the mean of |f| with the amplitude, so the two
/// amplitudes separate them); kas at 0.7 of the effect, either sign. Returns the description.
fn draw_two_axis(rng: &mut Rng, d: &Draw, p: &mut Parts) -> String {
    p.baseline = "P28".into();
    p.with_d = false;
    let ax = *pick(rng, &["x", "y"]);
    p.vib = sine(ax, d.amp, d.freq, &d.steps);
    let dv = d.effect_si_acc / (d.a_si * d.a_si / 2.0);
    let sgn = if rng.uniform() < 0.5 { -1.0 } else { 1.0 };
    let kv = sgn * 0.7 * d.effect_si_acc / (d.a_si * 2.0 / std::f64::consts::PI);
    p.hidden.push((format!("d_{ax}"), dv));
    p.hidden.push((format!("kas_{ax}"), kv));
    format!(
        "d_{ax} and kas_{ax} hidden on one axis; {} g / {} g vibration on {ax}, baseline P28",
        d.amp,
        d.amp / 2.0
    )
}

/// Draws the hidden term(s) of group `g` and the scenario pieces that excite them.
fn draw_one(g: &str, rng: &mut Rng, d: &Draw, p: &mut Parts) {
    match g {
        "d" | "kaq" | "kas" | "kao" | "kgq" | "size" => draw_vibrated(g, rng, d, p),
        "kgf" => draw_kgf(rng, d, p),
        "gnss_time" | "gnss_time_kgf" | "gnss_lever" => draw_gnss(g, rng, d, p),
        "reference_mount" | "reference_mount_kgf" | "reference_time" | "attitude_mount" => {
            draw_reference(g, rng, d, p)
        }
        "inner_lever" | "accel_delay" | "inner_lever_delay" => draw_turntable(g, rng, d, p),
        g if NOISE_GROUPS.contains(&g) => draw_noise(g, rng, d, p),
        other => panic!("unknown group {other}"),
    }
}

/// A term of group `g` excited by vibration at rest (d, kaq, kas, kao, kgq, size).
fn draw_vibrated(g: &str, rng: &mut Rng, d: &Draw, p: &mut Parts) {
    let (amp, freq, w, on1, on2, steps) = (d.amp, d.freq, d.w, d.on1, d.on2, &d.steps);
    let (effect_si_acc, effect_si_gyro, a_si) = (d.effect_si_acc, d.effect_si_gyro, d.a_si);
    let axes = ["x", "y", "z"];
    match g {
        "d" => {
            p.baseline = "P28".into();
            p.with_d = false;
            let ax = *pick(rng, &axes[..2]);
            p.vib = sine(ax, amp, freq, steps);
            let v = effect_si_acc / (a_si * a_si / 2.0);
            p.hidden.push((format!("d_{ax}"), v));
        }
        "kaq" => {
            let (name, j, k) = *pick(rng, &[("kaq_x_xy", "x", "y"), ("kaq_y_xy", "x", "y")]);
            // single-axis windows, then both in phase
            let s_j = format!(
                "[[{:.1}, {:.1}, 1.0], [{:.1}, {:.1}, 1.0]]",
                on1.0, on1.1, on2.0, on2.1
            );
            let s_k = format!(
                "[[{:.1}, {:.1}, 1.0], [{:.1}, {:.1}, 1.0]]",
                2.0 * w,
                2.5 * w,
                on2.0,
                on2.1
            );
            p.vib = sine(j, amp, freq, &s_j) + &sine(k, amp, freq, &s_k);
            let v = effect_si_acc / (a_si * a_si / 2.0);
            p.hidden.push((name.into(), v));
        }
        "kas" => {
            let ax = *pick(rng, &axes[..2]);
            p.vib = sine(ax, amp, freq, steps);
            let v = effect_si_acc / (a_si * 2.0 / std::f64::consts::PI);
            p.hidden.push((format!("kas_{ax}"), v));
        }
        "kao" => {
            // gravity along z plus vibration beyond 1 g along z; the vertical channel shows it
            p.baseline = "P31+vertical".into();
            p.vib = sine("z", amp, freq, steps);
            let v = effect_si_acc / (a_si * a_si / 2.0);
            p.hidden.push(("kao_z".into(), v));
        }
        "kgq" => {
            let (name, j, k) = *pick(rng, &[("kgq_x", "y", "z"), ("kgq_y", "x", "z")]);
            let s_j = format!(
                "[[{:.1}, {:.1}, 1.0], [{:.1}, {:.1}, 1.0]]",
                on1.0, on1.1, on2.0, on2.1
            );
            let s_k = format!("[[{:.1}, {:.1}, 1.0]]", on2.0, on2.1);
            p.vib = sine(j, amp, freq, &s_j) + &sine(k, amp, freq, &s_k);
            let v = effect_si_gyro / (a_si * a_si / 2.0);
            p.hidden.push((name.into(), v));
        }
        "size" => {
            let (name, ax) = *pick(
                rng,
                &[("size_x", "yaw"), ("size_y", "yaw"), ("size_x", "pitch")],
            );
            let amp_deg = 0.5;
            let f_ang = 10.0;
            p.vib = angular(ax, amp_deg, f_ang, steps);
            let om = 2.0 * std::f64::consts::PI * f_ang * amp_deg.to_radians();
            let v = effect_si_acc / (om * om / 2.0);
            p.hidden.push((name.into(), v));
        }
        other => panic!("unknown group {other}"),
    }
}

/// A gyro g-sensitivity kgf_* excited by a short drive (accelerations along x, or turns).
fn draw_kgf(rng: &mut Rng, d: &Draw, p: &mut Parts) {
    let seconds = d.seconds;
    // a short drive: accelerations along x, turns (centripetal f_y)
    let (name, fj) = *pick(
        rng,
        &[("kgf_xx", 0), ("kgf_yx", 1), ("kgf_xy", 2), ("kgf_yy", 3)],
    );
    let n = ((seconds - 60.0) / 60.0).floor().max(1.0) as usize;
    let segments = &mut p.segments;
    *segments = String::from("[[segment]]\nkind = \"rest\"\nduration_s = 60.0\n");
    for i in 0..n {
        if fj < 2 {
            let a = if i % 2 == 0 { 2.0 } else { -2.0 };
            segments.push_str(&format!("[[segment]]\nkind = \"accelerate\"\nduration_s = 10.0\naccel_mps2 = {a}\n[[segment]]\nkind = \"cruise\"\nduration_s = 50.0\n"));
        } else {
            let r = if i % 2 == 0 { 6.0 } else { -6.0 };
            if i == 0 {
                segments.push_str(
                    "[[segment]]\nkind = \"accelerate\"\nduration_s = 10.0\naccel_mps2 = 2.0\n",
                );
            }
            segments.push_str(&format!("[[segment]]\nkind = \"turn\"\nduration_s = 15.0\nyaw_rate_deg_s = {r}\n[[segment]]\nkind = \"cruise\"\nduration_s = 35.0\n"));
        }
    }
    let g_exc = if fj < 2 {
        2.0
    } else {
        20.0 * 6.0f64.to_radians()
    };
    let v = d.effect_si_gyro / g_exc;
    p.hidden.push((name.into(), v));
}

/// A GNSS term of group `g` on a drive: the time offset (and kgf_yx beside it) or a lever arm.
fn draw_gnss(g: &str, rng: &mut Rng, d: &Draw, p: &mut Parts) {
    let effect = d.effect;
    p.segments = drive_segments(d.seconds);
    if g == "gnss_lever" {
        let name = *pick(rng, &["lever_x", "lever_y"]);
        let sgn = if rng.uniform() < 0.5 { -1.0 } else { 1.0 };
        // 0.1–2 m
        p.hidden
            .push((name.into(), sgn * effect * (0.1 + 1.9 * rng.uniform())));
        return;
    }
    let sgn = if rng.uniform() < 0.5 { -1.0 } else { 1.0 };
    // 20–300 ms
    let dt = sgn * effect * (0.02 + 0.28 * rng.uniform());
    p.hidden.push(("dt_gnss".into(), dt));
    if g == "gnss_time_kgf" {
        // and a sensor term beside it: a MEMS-class gyro g-sensitivity, excited
        // by the drive's speed changes (±1 m/s²) and turns
        p.hidden.push(("kgf_yx".into(), 3.0 * d.effect_si_gyro));
    }
}

/// A velocity reference's mounting of group `g` on a drive: pitch and yaw (and kgf_yx beside
/// them in `reference_mount_kgf`).
fn draw_reference(g: &str, rng: &mut Rng, d: &Draw, p: &mut Parts) {
    p.segments = drive_segments(d.seconds);
    p.baseline = "P31+vertical".into();
    if g == "reference_time" {
        let sgn = if rng.uniform() < 0.5 { -1.0 } else { 1.0 };
        // 20–300 ms
        p.hidden.push((
            "dt_ref".into(),
            sgn * d.effect * (0.02 + 0.28 * rng.uniform()),
        ));
    }
    let mounts: &[&str] = match g {
        "reference_time" => &["mount_z"],
        "attitude_mount" => &["att_mount_x", "att_mount_z"],
        _ => &["mount_y", "mount_z"],
    };
    for &name in mounts {
        let sgn = if rng.uniform() < 0.5 { -1.0 } else { 1.0 };
        // 0.2–2°
        let deg = sgn * d.effect * (0.2 + 1.8 * rng.uniform());
        p.hidden.push((name.into(), deg.to_radians()));
    }
    if g == "reference_mount_kgf" {
        p.hidden.push(("kgf_yx".into(), 3.0 * d.effect_si_gyro));
    }
}

/// A noise level of group `g` (white noise or bias random walk) stated wrongly on a drive (and
/// kgf_yx beside it in `noise_accel_kgf`).
fn draw_noise(g: &str, rng: &mut Rng, d: &Draw, p: &mut Parts) {
    p.segments = drive_segments(d.seconds);
    p.baseline = "P13".into();
    // 2–10 at effect 1; 1 (nothing misstated) at effect 0
    let k = 1.0 + d.effect * (1.0 + 8.0 * rng.uniform());
    let ratio = if g.ends_with("_large") { 1.0 / k } else { k };
    let level = match (g.starts_with("noise_gyro"), g.ends_with("_bias")) {
        (true, false) => "gyro_arw",
        (false, false) => "accel_vrw",
        (true, true) => "gyro_bias_rw",
        (false, true) => "accel_bias_rw",
    };
    p.noise_ratio.push((level.into(), ratio));
    if g == "noise_accel_kgf" {
        // a MEMS gyro's g-sensitivity (30 deg/h per m/s², 294 deg/h/g), visible beside
        // the MEMS gyro noise
        p.hidden.push(("kgf_yx".into(), 30.0 * d.effect_si_gyro));
    }
}

/// An inner lever arm (20–60 mm times the effect) and/or an accelerometer delay (1–3 ms times
/// the effect) of group `g`, on a turntable.
fn draw_turntable(g: &str, rng: &mut Rng, d: &Draw, p: &mut Parts) {
    let effect = d.effect;
    p.segments = turntable_segments();
    if g != "accel_delay" {
        let name = *pick(
            rng,
            &[
                "size_x_y", "size_x_z", "size_y_x", "size_y_z", "size_z_x", "size_z_y",
            ],
        );
        let sgn = if rng.uniform() < 0.5 { -1.0 } else { 1.0 };
        // 20–60 mm
        p.hidden
            .push((name.into(), sgn * effect * (0.02 + 0.04 * rng.uniform())));
    }
    if g != "inner_lever" {
        let sgn = if rng.uniform() < 0.5 { -1.0 } else { 1.0 };
        // 1–3 ms, the same for the three accelerometers
        let tau = sgn * effect * (1e-3 + 2e-3 * rng.uniform());
        for a in ["x", "y", "z"] {
            p.hidden.push((format!("tau_{a}"), tau));
        }
    }
}

/// The description of a one-group case: the first hidden term and its size (`effect` in deg/h
/// or mg, or the term's own value for a GNSS or turntable term).
fn one_description(g: &str, p: &Parts, effect: f64) -> String {
    let hidden = &p.hidden;
    let info = common::TERMS.iter().find(|t| t.name == hidden[0].0);
    let size = match info.map(|t| t.sensor) {
        Some(crate::model::catalog::Sensor::Gyro) => format!("{effect} deg/h"),
        // a GNSS term or a lever arm: its value
        Some(_) if TURNTABLE_GROUPS.contains(&g) => {
            let t = info.expect("matched");
            format!("{:.1} {}", hidden[0].1 / t.display_to_si, t.display)
        }
        Some(crate::model::catalog::Sensor::Gnss | crate::model::catalog::Sensor::Reference) => {
            let t = info.expect("matched");
            format!("{:.3} {}", hidden[0].1 / t.display_to_si, t.display)
        }
        _ => format!("{effect} mg"),
    };
    format!("{} hidden ({size}), baseline {}", hidden[0].0, p.baseline)
}

/// The description of a noise case: the level misstated, its ratio, and any term beside it.
fn noise_description(p: &Parts) -> String {
    let (level, r) = &p.noise_ratio[0];
    let mut s = format!(
        "{level} stated {} (simulated {r:.2}x the stated), baseline {}",
        if *r > 1.0 { "too small" } else { "too large" },
        p.baseline
    );
    for (name, _) in &p.hidden {
        s.push_str(&format!("; {name} hidden beside it"));
    }
    s
}

/// The case from its drawn parts: the baseline's errors (drawn last), the scenario text at
/// latitude `lat` [deg], the priors it declares.
fn assemble(
    seed: u64,
    group: String,
    description: String,
    lat: f64,
    effect: f64,
    rng: &mut Rng,
    p: Parts,
) -> HiddenCase {
    let Parts {
        segments,
        vib,
        hidden,
        baseline,
        with_d,
        noise_ratio,
    } = p;
    let skip: Vec<String> = hidden.iter().map(|h| h.0.clone()).collect();
    let mut errors = baseline_errors(rng, with_d, &skip);
    for (name, v) in &hidden {
        errors.push_str(&format!("{name} = \"{v:e} {}\"\n", unit_of(name)));
    }
    // a turntable has no vibration to sample: 200 Hz resolves its rate ramps; its aiding
    // (from the truth rows) at 10 Hz sees the kicks of each rotation
    let (imu_rate, truth_rate) = if TURNTABLE_GROUPS.contains(&group.as_str()) {
        ("200.0", "10.0")
    } else if NOISE_GROUPS.contains(&group.as_str()) || REFERENCE_GROUPS.contains(&group.as_str()) {
        // a drive without vibration: 200 Hz samples its manoeuvres
        ("200.0", "1.0")
    } else {
        ("2000.0", "1.0")
    };
    let stated_noise = (!noise_ratio.is_empty()).then(|| stated_noise(&group));
    let noise = match stated_noise {
        None => "[noise]\narw = \"0.01 deg/sqrt(h)\"\nvrw = \"10 ug/sqrt(Hz)\"\n".to_string(),
        Some(stated) => {
            let ratio = |l: &str| ratio_of(&noise_ratio, l);
            format!(
                "[noise]\narw = \"{:e} rad/sqrt(s)\"\nvrw = \"{:e} m/s/sqrt(s)\"\n\
                 gyro_bias_rw = \"{:e} rad/s/sqrt(s)\"\naccel_bias_rw = \"{:e} m/s^2/sqrt(s)\"\n",
                stated[0] * ratio("gyro_arw"),
                stated[1] * ratio("accel_vrw"),
                stated[2] * ratio("gyro_bias_rw"),
                stated[3] * ratio("accel_bias_rw")
            )
        }
    };
    let reference = if group == "attitude_mount" {
        "[attitude_reference]\nrate_hz = 10.0\nsigma_tilt = \"0.05 deg\"\nsigma_yaw = \"0.1 deg\"\n"
    } else if REFERENCE_GROUPS.contains(&group.as_str()) {
        "[reference]\nrate_hz = 10.0\nsigma = \"0.05 m/s\"\n"
    } else {
        ""
    };
    let scenario = format!(
        "name = \"hidden-{group}-{seed}\"\nimu_rate_hz = {imu_rate}\ntruth_rate_hz = {truth_rate}\nseed = {seed}\n\
         [start]\nlat_deg = {lat:.3}\nlon_deg = 112.0\n{segments}{vib}{errors}{noise}{reference}"
    );
    // g-sensitivities of several deg/h/g belong to a MEMS-class gyro, not to the spec's laser
    // gyro (0.01 deg/h/g): the case declares that class, as a user would with --prior
    let priors = if [
        "kgf",
        "gnss_time_kgf",
        "noise_accel_kgf",
        "reference_mount_kgf",
    ]
    .contains(&group.as_str())
    {
        // 10 deg/h/g; a MEMS gyro's 200 deg/h/g beside MEMS noise
        let dhg = if group == "noise_accel_kgf" {
            200.0
        } else {
            10.0
        };
        let sigma = dhg * std::f64::consts::PI / 180.0 / 3600.0 / G0;
        common::TERMS
            .iter()
            .filter(|t| t.name.starts_with("kgf_"))
            .map(|t| (t.name.to_string(), sigma))
            .collect()
    } else if group == "kgq" {
        // likewise g²-sensitivities: the λ draw puts a 300-s case's kgq at up to 17 of the
        // spec's laser-grade 0.01 deg/h/g², a tactical-grade gyro's size: the case declares
        // 0.1 deg/h/g² (widened to hold the value put in, `hold_in_declared_prior`)
        let sigma = 0.1 * std::f64::consts::PI / 180.0 / 3600.0 / (G0 * G0);
        common::TERMS
            .iter()
            .filter(|t| t.name.starts_with("kgq_"))
            .map(|t| (t.name.to_string(), sigma))
            .collect()
    } else {
        Vec::new()
    };
    let static_aid = TURNTABLE_GROUPS.contains(&group.as_str());
    HiddenCase {
        seed,
        group,
        hidden,
        baseline,
        scenario,
        description,
        effect,
        priors,
        withheld: Vec::new(),
        static_aid,
        stated_noise,
        noise_ratio,
    }
}
