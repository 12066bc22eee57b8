//! Loading and validating the declarative model spec (`model-spec/*.toml`).
//!
//! Every problem is reported as one [`SpecError`] naming the file, the line, the item (state,
//! term, entry, preset or measurement) and what is wrong.

use crate::expr::{self, Expr, ExprKind};
use crate::grades::{self, Grade};
use crate::units;
use serde::Deserialize;
use std::collections::{BTreeSet, HashMap};
use std::fmt;
use std::path::{Path, PathBuf};
use toml::Spanned;

/// The spec files, in the order they are read.
pub const SPEC_FILES: [&str; 5] = [
    "navigation.toml",
    "terms.toml",
    "measurements.toml",
    "presets.toml",
    "grades.toml",
];

/// One problem in the spec: file, 1-based line, the item it concerns, and the message.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SpecError {
    /// Path of the spec file.
    pub file: PathBuf,
    /// 1-based line (0 when the problem concerns the whole file).
    pub line: usize,
    /// The item concerned, e.g. "term `eps_x`".
    pub item: String,
    /// What is wrong.
    pub message: String,
}

impl fmt::Display for SpecError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.line > 0 {
            write!(f, "{}:{}: ", self.file.display(), self.line)?;
        } else {
            write!(f, "{}: ", self.file.display())?;
        }
        if !self.item.is_empty() {
            write!(f, "{}: ", self.item)?;
        }
        f.write_str(&self.message)
    }
}

impl std::error::Error for SpecError {}

/// Which instrument a term corrupts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Sensor {
    /// Gyro: the term adds to the measured angular rate [rad/s].
    Gyro,
    /// Accelerometer: the term adds to the measured specific force [m/s²].
    Accel,
    /// GNSS aiding: the term enters the measurements (its H entries), not A — a time offset,
    /// an antenna lever arm.
    Gnss,
    /// A body-frame velocity reference (odometer, DVL): the term enters its measurement (its H
    /// entries), not A — a mounting misalignment.
    Reference,
    /// An attitude reference (a second INS, an AHRS): the term enters its measurement (its H
    /// entries), not A — a mounting misalignment.
    Attitude,
}

impl Sensor {
    /// The term enters the measurements (its `h` entries), not A.
    pub fn enters_h(self) -> bool {
        matches!(self, Sensor::Gnss | Sensor::Reference | Sensor::Attitude)
    }
}

/// A navigation error state (attitude, velocity, position).
#[derive(Debug, Clone)]
pub struct NavState {
    /// Canonical name, e.g. `phi_n`.
    pub name: String,
    /// SI unit of the state.
    pub unit: String,
    /// Unit used at the edges.
    pub display: String,
    /// Factor from display unit to SI.
    pub display_to_si: f64,
    /// Default prior 1-σ, SI.
    pub sigma: f64,
    /// Present only with `+vertical`.
    pub vertical: bool,
    /// Which white sensor noise drives the state (its process noise).
    pub white_noise: WhiteNoise,
    /// One-line description.
    pub doc: String,
}

/// The white sensor noise that drives a navigation state (`white_noise` in navigation.toml).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WhiteNoise {
    /// No white noise enters the state directly.
    None,
    /// Gyro angle random walk (attitude rows).
    GyroArw,
    /// Accelerometer velocity random walk (velocity rows).
    AccelVrw,
}

/// A non-zero entry of the navigation block of A(t).
#[derive(Debug, Clone)]
pub struct NavEntry {
    /// Row: index into [`Spec::nav_states`].
    pub row: usize,
    /// Column: index into [`Spec::nav_states`].
    pub col: usize,
    /// The validated expression.
    pub expr: Expr,
}

/// A regressor: the body-frame signal whose step mean multiplies a term's state.
#[derive(Debug, Clone)]
pub struct Regressor {
    /// The validated expression over `f.x .. w.z`.
    pub expr: Expr,
    /// True when the expression uses no IMU signal (e.g. `1`): it needs no accumulation.
    pub constant: bool,
}

/// An instrument error term (one state).
#[derive(Debug, Clone)]
pub struct Term {
    /// Canonical name, e.g. `kaq_x_xy`.
    pub name: String,
    /// Sensor corrupted.
    pub sensor: Sensor,
    /// Sensing axis, 0 = x, 1 = y, 2 = z (FRD body).
    pub axis: usize,
    /// Index into [`Spec::regressors`].
    pub regressor: usize,
    /// SI unit of the state.
    pub unit: String,
    /// Unit at the edges.
    pub display: String,
    /// Factor from display unit to SI.
    pub display_to_si: f64,
    /// Default prior 1-σ, SI.
    pub sigma: f64,
    /// Random-walk density of the state, SI per √s (0 = random constant).
    pub noise: f64,
    /// Largest physically plausible |value|, SI (`limit` in terms.toml; ∞ when not given): a
    /// prior or an injected value beyond it is refused as a unit mistake.
    pub limit: f64,
    /// Group label for listings.
    pub group: String,
    /// One-line description.
    pub doc: String,
    /// Candidate library term (in no preset by default).
    pub library: bool,
    /// Priors this term declares for named grades: (grade, 1-σ [SI], line in terms.toml).
    pub grade_sigma: Vec<(String, f64, usize)>,
    /// A GNSS term's H entries: (measurement row name, expression), merged into the rows.
    pub h: Vec<(String, Expr)>,
}

/// One H entry of a measurement row.
#[derive(Debug, Clone)]
pub struct HEntry {
    /// Global state name.
    pub state: String,
    /// Validated expression.
    pub expr: Expr,
}

/// One component of a measurement.
#[derive(Debug, Clone)]
pub struct MeasRow {
    /// Component name, e.g. `dp_n`.
    pub name: String,
    /// Unit of the component.
    pub unit: String,
    /// Non-zero H entries.
    pub h: Vec<HEntry>,
    /// The residual z = computed − aided, in `unit`, over the state and the aiding record.
    pub residual: Expr,
    /// The residual's 1-σ, from the aiding record.
    pub residual_sigma: Expr,
}

/// Which aiding record a measurement is formed from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Aiding {
    /// A position fix (`aid.lat`, `aid.lon`, `aid.h`, `aid.sigma_n|e|d`).
    Position,
    /// A velocity fix (`aid.vn`, `aid.ve`, `aid.vd`, `aid.sigma_v`).
    Velocity,
    /// A body-frame (FRD) velocity from a reference: odometer, DVL (`aid.vx`, `aid.vy`,
    /// `aid.vz`, `aid.sigma_b`).
    BodyVelocity,
    /// An attitude from a reference: a second INS, an AHRS (`aid.r11` … `aid.r33`, its frame's
    /// C_r^n; `aid.sigma_tilt`, `aid.sigma_yaw`).
    Attitude,
}

/// A measurement type (`vel_ne`, `pos_ne`, `pos_h`).
#[derive(Debug, Clone)]
pub struct Measurement {
    /// Canonical name.
    pub name: String,
    /// One-line description.
    pub doc: String,
    /// Default noise 1-σ per component, SI.
    pub sigma: f64,
    /// The aiding record it is formed from.
    pub aiding: Aiding,
    /// Components.
    pub rows: Vec<MeasRow>,
}

/// A named model.
#[derive(Debug, Clone)]
pub struct Preset {
    /// Name, e.g. `P31`.
    pub name: String,
    /// One-line description.
    pub doc: String,
    /// State names in order.
    pub states: Vec<String>,
}

/// The composition rule of DESIGN §4 for instrument columns.
#[derive(Debug, Clone)]
pub struct Compose {
    /// Rows (nav indices) filled by gyro terms, in body-axis-to-NED order (N, E, D).
    pub gyro_rows: Vec<usize>,
    /// Sign of the gyro column (−1: −C e_i r).
    pub gyro_sign: i32,
    /// Rows (nav indices) filled by accelerometer terms.
    pub accel_rows: Vec<usize>,
    /// Sign of the accelerometer column (+1: C e_i r).
    pub accel_sign: i32,
}

/// White sensor noise densities, SI.
#[derive(Debug, Clone, Copy)]
pub struct SensorNoise {
    /// Gyro angle random walk [rad/√s].
    pub gyro_arw: f64,
    /// Accelerometer velocity random walk [m/s/√s].
    pub accel_vrw: f64,
}

/// The whole validated spec.
#[derive(Debug, Clone)]
pub struct Spec {
    /// Directory the spec was read from.
    pub dir: PathBuf,
    /// Navigation states (including the vertical ones), in order.
    pub nav_states: Vec<NavState>,
    /// Non-zero entries of the full (vertical) navigation block.
    pub nav_entries: Vec<NavEntry>,
    /// Instrument column rule.
    pub compose: Compose,
    /// Instrument error terms.
    pub terms: Vec<Term>,
    /// Distinct regressors used by the terms.
    pub regressors: Vec<Regressor>,
    /// Measurement types.
    pub measurements: Vec<Measurement>,
    /// Presets, in file order.
    pub presets: Vec<Preset>,
    /// White sensor noise.
    pub sensor_noise: SensorNoise,
    /// Sensor grades for `--grade` (`grades.toml`): priors and white noise of other IMU classes.
    pub grades: Vec<Grade>,
}

// ---------------------------------------------------------------- raw TOML

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawNavigation {
    state: Vec<RawState>,
    a: Vec<RawEntry>,
    compose: RawCompose,
    sensor_noise: RawSensorNoise,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawState {
    name: Spanned<String>,
    unit: String,
    display: String,
    sigma: String,
    #[serde(default)]
    vertical: bool,
    #[serde(default)]
    white_noise: Option<Spanned<String>>,
    doc: String,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawEntry {
    row: Spanned<String>,
    col: Spanned<String>,
    expr: Spanned<String>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawCompose {
    gyro_rows: Spanned<Vec<String>>,
    gyro_sign: i32,
    accel_rows: Spanned<Vec<String>>,
    accel_sign: i32,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawSensorNoise {
    gyro_arw: Spanned<String>,
    accel_vrw: Spanned<String>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawTerms {
    term: Vec<RawTerm>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawTerm {
    name: Spanned<String>,
    sensor: Spanned<String>,
    #[serde(default)]
    axis: Option<Spanned<String>>,
    #[serde(default)]
    regressor: Option<Spanned<String>>,
    #[serde(default)]
    h: Vec<RawTermH>,
    unit: Spanned<String>,
    display: Spanned<String>,
    sigma: Spanned<String>,
    #[serde(default)]
    noise: Option<Spanned<String>>,
    #[serde(default)]
    limit: Option<Spanned<String>>,
    group: String,
    doc: String,
    #[serde(default)]
    library: bool,
    #[serde(default)]
    grade_sigma: std::collections::BTreeMap<String, Spanned<String>>,
}

/// One H entry of a GNSS term: the measurement row it enters and its value.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawTermH {
    row: Spanned<String>,
    expr: Spanned<String>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawMeasurements {
    measurement: Vec<RawMeasurement>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawMeasurement {
    name: Spanned<String>,
    doc: String,
    sigma: Spanned<String>,
    aiding: Spanned<String>,
    rows: Vec<RawMeasRow>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawMeasRow {
    name: String,
    unit: String,
    h: Vec<RawHEntry>,
    residual: Spanned<String>,
    residual_sigma: Spanned<String>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawHEntry {
    state: Spanned<String>,
    expr: Spanned<String>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawPresets {
    preset: Vec<RawPreset>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawPreset {
    name: Spanned<String>,
    doc: String,
    #[serde(default)]
    states: Option<Vec<String>>,
    #[serde(default)]
    base: Option<Spanned<String>>,
    #[serde(default)]
    terms: Vec<String>,
}

// ---------------------------------------------------------------- loading

/// Source text of one spec file, for turning byte spans into line numbers.
pub(crate) struct Source {
    pub(crate) path: PathBuf,
    text: String,
}

impl Source {
    pub(crate) fn read(dir: &Path, name: &str) -> Result<Source, SpecError> {
        let path = dir.join(name);
        let text = std::fs::read_to_string(&path).map_err(|e| SpecError {
            file: path.clone(),
            line: 0,
            item: String::new(),
            message: format!("cannot read spec file: {e}"),
        })?;
        Ok(Source { path, text })
    }

    pub(crate) fn new(dir: &Path, name: &str, text: &str) -> Source {
        Source {
            path: dir.join(name),
            text: text.to_string(),
        }
    }

    pub(crate) fn line_of(&self, offset: usize) -> usize {
        let end = offset.min(self.text.len());
        self.text[..end].bytes().filter(|&b| b == b'\n').count() + 1
    }

    pub(crate) fn error(
        &self,
        span: std::ops::Range<usize>,
        item: &str,
        message: impl Into<String>,
    ) -> SpecError {
        SpecError {
            file: self.path.clone(),
            line: self.line_of(span.start),
            item: item.to_string(),
            message: message.into(),
        }
    }

    pub(crate) fn parse<T: for<'de> Deserialize<'de>>(&self) -> Result<T, SpecError> {
        toml::from_str(&self.text).map_err(|e| {
            let line = e.span().map(|s| self.line_of(s.start)).unwrap_or(0);
            SpecError {
                file: self.path.clone(),
                line,
                item: String::new(),
                message: e.message().trim().to_string(),
            }
        })
    }
}

pub(crate) fn check_name(
    src: &Source,
    name: &Spanned<String>,
    what: &str,
) -> Result<(), SpecError> {
    let n = name.get_ref();
    let ok = !n.is_empty()
        && n.chars().next().is_some_and(|c| c.is_ascii_lowercase())
        && n.chars()
            .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_');
    if ok {
        Ok(())
    } else {
        Err(src.error(
            name.span(),
            &format!("{what} `{n}`"),
            "names must be lower-case letters, digits and `_`, starting with a letter",
        ))
    }
}

pub(crate) fn quantity(
    src: &Source,
    text: &Spanned<String>,
    unit: &str,
    item: &str,
    field: &str,
) -> Result<f64, SpecError> {
    units::parse_quantity_as(text.get_ref(), unit)
        .map_err(|e| src.error(text.span(), item, format!("{field}: {e}")))
}

impl Spec {
    /// Reads and validates the spec in `dir` (the files of [`SPEC_FILES`]), one file and one
    /// kind of item at a time; the first problem found is returned.
    pub fn load(dir: &Path) -> Result<Spec, SpecError> {
        let [nav, terms, meas, presets, grades] = SPEC_FILES.map(|f| Source::read(dir, f));
        Spec::from_sources(dir, [nav?, terms?, meas?, presets?, grades?])
    }

    /// Validates a spec given as the texts of its files, in [`SPEC_FILES`] order, as
    /// [`Spec::load`] does once it has read them; `dir` only names the files in messages.
    pub fn from_texts(dir: &Path, texts: [&str; SPEC_FILES.len()]) -> Result<Spec, SpecError> {
        let sources = std::array::from_fn(|i| Source::new(dir, SPEC_FILES[i], texts[i]));
        Spec::from_sources(dir, sources)
    }

    fn from_sources(dir: &Path, sources: [Source; SPEC_FILES.len()]) -> Result<Spec, SpecError> {
        let [nav_src, terms_src, meas_src, preset_src, grades_src] = sources;
        let raw_nav: RawNavigation = nav_src.parse()?;
        let raw_terms: RawTerms = terms_src.parse()?;
        let raw_meas: RawMeasurements = meas_src.parse()?;
        let raw_presets: RawPresets = preset_src.parse()?;

        let mut names: HashMap<String, String> = HashMap::new();
        let nav_states = load_nav_states(&nav_src, &raw_nav.state, &mut names)?;
        let nav_entries = load_nav_entries(&nav_src, &raw_nav.a, &nav_states)?;
        let compose = load_compose(&nav_src, &raw_nav.compose, &nav_states)?;
        let sensor_noise = load_sensor_noise(&nav_src, &raw_nav.sensor_noise)?;
        let (terms, regressors) = load_terms(&terms_src, &raw_terms.term, &mut names)?;
        let mut measurements = load_measurements(&meas_src, &raw_meas.measurement, &names)?;
        merge_term_h(&terms_src, &raw_terms.term, &terms, &mut measurements)?;
        let presets = load_presets(
            &preset_src,
            &raw_presets.preset,
            &nav_states,
            &terms,
            &names,
        )?;
        let grades = grades::load(&grades_src, &terms_src, &nav_states, &terms)?;
        Ok(Spec {
            dir: dir.to_path_buf(),
            nav_states,
            nav_entries,
            compose,
            terms,
            regressors,
            measurements,
            presets,
            sensor_noise,
            grades,
        })
    }

    /// Index of a term by name.
    pub fn term_index(&self, name: &str) -> Option<usize> {
        self.terms.iter().position(|t| t.name == name)
    }

    /// Index of a navigation state by name.
    pub fn nav_index(&self, name: &str) -> Option<usize> {
        self.nav_states.iter().position(|s| s.name == name)
    }
}

// ---------------------------------------------------------------- loading, step by step

/// Navigation states: names, units, priors and the white noise that drives each.
fn load_nav_states(
    src: &Source,
    raw: &[RawState],
    names: &mut HashMap<String, String>,
) -> Result<Vec<NavState>, SpecError> {
    let mut nav_states = Vec::new();
    for s in raw {
        let item = format!("state `{}`", s.name.get_ref());
        check_name(src, &s.name, "state")?;
        if names
            .insert(s.name.get_ref().clone(), "navigation.toml".into())
            .is_some()
        {
            return Err(src.error(s.name.span(), &item, "duplicate name"));
        }
        let unit = units::parse_unit(&s.unit)
            .map_err(|e| src.error(s.name.span(), &item, format!("unit: {e}")))?;
        let display = units::parse_unit(&s.display)
            .map_err(|e| src.error(s.name.span(), &item, format!("display: {e}")))?;
        if unit.dim != display.dim {
            return Err(src.error(
                s.name.span(),
                &item,
                format!(
                    "display unit `{}` does not match unit `{}`",
                    s.display, s.unit
                ),
            ));
        }
        let sigma = units::parse_quantity_as(&s.sigma, &s.unit)
            .map_err(|e| src.error(s.name.span(), &item, format!("sigma: {e}")))?;
        let white_noise = match s.white_noise.as_ref().map(|w| w.get_ref().as_str()) {
            None => WhiteNoise::None,
            Some("gyro_arw") => WhiteNoise::GyroArw,
            Some("accel_vrw") => WhiteNoise::AccelVrw,
            Some(other) => {
                let span = s.white_noise.as_ref().map(|w| w.span()).unwrap_or(0..0);
                return Err(src.error(
                    span,
                    &item,
                    format!("white_noise: unknown source `{other}` (expected `gyro_arw` or `accel_vrw`, keys of [sensor_noise])"),
                ));
            }
        };
        let expected_dim = match white_noise {
            WhiteNoise::None => None,
            WhiteNoise::GyroArw => Some(("rad", units::parse_unit("rad").map(|u| u.dim))),
            WhiteNoise::AccelVrw => Some(("m/s", units::parse_unit("m/s").map(|u| u.dim))),
        };
        if let Some((want, Ok(dim))) = expected_dim {
            if dim != unit.dim {
                return Err(src.error(
                    s.name.span(),
                    &item,
                    format!(
                        "white_noise: a state in `{}` cannot be driven by a density whose integral is in `{want}`",
                        s.unit
                    ),
                ));
            }
        }
        nav_states.push(NavState {
            name: s.name.get_ref().clone(),
            unit: s.unit.clone(),
            display: s.display.clone(),
            display_to_si: display.to_si / unit.to_si,
            sigma,
            vertical: s.vertical,
            white_noise,
            doc: s.doc.clone(),
        });
    }
    Ok(nav_states)
}

fn nav_index(nav_states: &[NavState], name: &str) -> Option<usize> {
    nav_states.iter().position(|s| s.name == name)
}

/// The navigation block of A(t): one validated expression per non-zero.
fn load_nav_entries(
    src: &Source,
    raw: &[RawEntry],
    nav_states: &[NavState],
) -> Result<Vec<NavEntry>, SpecError> {
    let mut nav_entries: Vec<NavEntry> = Vec::new();
    for e in raw {
        let item = format!("A entry ({}, {})", e.row.get_ref(), e.col.get_ref());
        let state = |s: &Spanned<String>| {
            nav_index(nav_states, s.get_ref()).ok_or_else(|| {
                src.error(s.span(), &item, format!("unknown state `{}`", s.get_ref()))
            })
        };
        let (row, col) = (state(&e.row)?, state(&e.col)?);
        if nav_entries.iter().any(|x| x.row == row && x.col == col) {
            return Err(src.error(e.row.span(), &item, "duplicate entry"));
        }
        let expr = expr::parse(e.expr.get_ref(), ExprKind::Navigation)
            .map_err(|m| src.error(e.expr.span(), &item, m))?;
        nav_entries.push(NavEntry { row, col, expr });
    }
    Ok(nav_entries)
}

/// The composition rule: which rows gyro and accelerometer columns fill, with which sign.
fn load_compose(
    src: &Source,
    raw: &RawCompose,
    nav_states: &[NavState],
) -> Result<Compose, SpecError> {
    let rows = |list: &Spanned<Vec<String>>, what: &str| -> Result<Vec<usize>, SpecError> {
        if list.get_ref().len() != 3 {
            return Err(src.error(
                list.span(),
                "compose",
                format!("{what} needs 3 rows (N, E, D)"),
            ));
        }
        list.get_ref()
            .iter()
            .map(|n| {
                nav_index(nav_states, n).ok_or_else(|| {
                    src.error(
                        list.span(),
                        "compose",
                        format!("{what}: unknown state `{n}`"),
                    )
                })
            })
            .collect()
    };
    let compose = Compose {
        gyro_rows: rows(&raw.gyro_rows, "gyro_rows")?,
        gyro_sign: raw.gyro_sign,
        accel_rows: rows(&raw.accel_rows, "accel_rows")?,
        accel_sign: raw.accel_sign,
    };
    for (sign, what) in [
        (compose.gyro_sign, "gyro_sign"),
        (compose.accel_sign, "accel_sign"),
    ] {
        if sign != 1 && sign != -1 {
            return Err(src.error(0..0, "compose", format!("{what} must be 1 or -1")));
        }
    }
    Ok(compose)
}

/// The white sensor noise densities.
fn load_sensor_noise(src: &Source, raw: &RawSensorNoise) -> Result<SensorNoise, SpecError> {
    Ok(SensorNoise {
        gyro_arw: quantity(
            src,
            &raw.gyro_arw,
            "rad/sqrt(s)",
            "sensor_noise",
            "gyro_arw",
        )?,
        accel_vrw: quantity(
            src,
            &raw.accel_vrw,
            "m/s/sqrt(s)",
            "sensor_noise",
            "accel_vrw",
        )?,
    })
}

/// Instrument error terms and the distinct regressors they use; each term's unit times its
/// regressor's dimension must be the sensor's (rad/s for gyros, m/s² for accelerometers).
fn load_terms(
    src: &Source,
    raw: &[RawTerm],
    names: &mut HashMap<String, String>,
) -> Result<(Vec<Term>, Vec<Regressor>), SpecError> {
    let mut terms = Vec::new();
    let mut regressors: Vec<Regressor> = Vec::new();
    for t in raw {
        terms.push(load_term(src, t, names, &mut regressors)?);
    }
    Ok((terms, regressors))
}

/// One term, checked field by field in file order; its regressor is added to `regressors`.
fn load_term(
    src: &Source,
    t: &RawTerm,
    names: &mut HashMap<String, String>,
    regressors: &mut Vec<Regressor>,
) -> Result<Term, SpecError> {
    let item = format!("term `{}`", t.name.get_ref());
    check_name(src, &t.name, "term")?;
    if let Some(prev) = names.insert(t.name.get_ref().clone(), "terms.toml".into()) {
        return Err(src.error(
            t.name.span(),
            &item,
            format!("duplicate name (already defined in {prev})"),
        ));
    }
    let sensor = term_sensor(src, t, &item)?;
    let unit = units::parse_unit(t.unit.get_ref())
        .map_err(|e| src.error(t.unit.span(), &item, format!("unit: {e}")))?;
    let axis = term_axis(src, t, &item, sensor)?;
    let (rexpr, h) = match sensor {
        Sensor::Gnss | Sensor::Reference | Sensor::Attitude => gnss_term_h(src, t, &item)?,
        _ => (
            sensor_term_regressor(src, t, &item, sensor, unit.dim)?,
            Vec::new(),
        ),
    };
    let regressor = intern_regressor(regressors, rexpr);
    let display = term_display(src, t, &item, &unit)?;
    let sigma = quantity(src, &t.sigma, t.unit.get_ref(), &item, "sigma")?;
    let noise = term_noise(src, t, &item)?;
    let limit = term_limit(src, t, &item, sigma)?;
    let grade_sigma = term_grade_sigma(src, t, &item)?;
    Ok(Term {
        name: t.name.get_ref().clone(),
        sensor,
        axis,
        regressor,
        unit: t.unit.get_ref().clone(),
        display: t.display.get_ref().clone(),
        display_to_si: display.to_si / unit.to_si,
        sigma,
        noise,
        limit,
        group: t.group.clone(),
        doc: t.doc.clone(),
        library: t.library,
        grade_sigma,
        h,
    })
}

/// The term's `sensor`: `gyro`, `accel` or `gnss`.
fn term_sensor(src: &Source, t: &RawTerm, item: &str) -> Result<Sensor, SpecError> {
    match t.sensor.get_ref().as_str() {
        "gyro" => Ok(Sensor::Gyro),
        "accel" => Ok(Sensor::Accel),
        "gnss" => Ok(Sensor::Gnss),
        "reference" => Ok(Sensor::Reference),
        "attitude" => Ok(Sensor::Attitude),
        other => Err(src.error(
            t.sensor.span(),
            item,
            format!("unknown sensor `{other}` (expected `gyro`, `accel`, `gnss`, `reference` or `attitude`)"),
        )),
    }
}

/// The term's sensing `axis` (0 = x, 1 = y, 2 = z); required except for a GNSS term (0).
fn term_axis(src: &Source, t: &RawTerm, item: &str, sensor: Sensor) -> Result<usize, SpecError> {
    match &t.axis {
        None if sensor.enters_h() => Ok(0),
        None => Err(src.error(
            t.name.span(),
            item,
            "missing `axis` (`x`, `y` or `z`: the sensing axis of the gyro or accelerometer)",
        )),
        Some(a) => match a.get_ref().as_str() {
            "x" => Ok(0),
            "y" => Ok(1),
            "z" => Ok(2),
            other => Err(src.error(
                a.span(),
                item,
                format!("unknown axis `{other}` (expected `x`, `y` or `z`)"),
            )),
        },
    }
}

/// A gyro or accelerometer term's regressor: required, no `h`, and of the right dimension.
fn sensor_term_regressor(
    src: &Source,
    t: &RawTerm,
    item: &str,
    sensor: Sensor,
    unit: units::Dim,
) -> Result<Expr, SpecError> {
    let Some(r) = &t.regressor else {
        return Err(src.error(
            t.name.span(),
            item,
            "missing `regressor` (the body-frame signal the error is proportional to, e.g. `f.x.powi(2)`, or `1` for a bias)",
        ));
    };
    if let Some(e) = t.h.first() {
        return Err(src.error(
            e.row.span(),
            item,
            "`h` belongs to `sensor = \"gnss\"` terms (a gyro or accelerometer term enters A through its regressor)",
        ));
    }
    let rexpr = expr::parse(r.get_ref(), ExprKind::Regressor)
        .map_err(|m| src.error(r.span(), item, format!("regressor: {m}")))?;
    check_term_dimension(src, t, r, item, sensor, &rexpr, unit)?;
    Ok(rexpr)
}

/// Index of `rexpr` in `regressors`, appending it when no equal regressor is there yet.
fn intern_regressor(regressors: &mut Vec<Regressor>, rexpr: Expr) -> usize {
    let key = rexpr.key();
    match regressors.iter().position(|r| r.expr.key() == key) {
        Some(i) => i,
        None => {
            let constant = rexpr.symbols().is_empty();
            regressors.push(Regressor {
                expr: rexpr,
                constant,
            });
            regressors.len() - 1
        }
    }
}

/// The term's `display` unit, which must measure what its `unit` measures.
fn term_display(
    src: &Source,
    t: &RawTerm,
    item: &str,
    unit: &units::Unit,
) -> Result<units::Unit, SpecError> {
    let display = units::parse_unit(t.display.get_ref())
        .map_err(|e| src.error(t.display.span(), item, format!("display: {e}")))?;
    if unit.dim != display.dim {
        return Err(src.error(
            t.display.span(),
            item,
            format!(
                "display unit `{}` does not match unit `{}`",
                t.display.get_ref(),
                t.unit.get_ref()
            ),
        ));
    }
    Ok(display)
}

/// The term's random-walk density `noise` in unit/√s (0 when not given: a random constant).
fn term_noise(src: &Source, t: &RawTerm, item: &str) -> Result<f64, SpecError> {
    match &t.noise {
        Some(n) => quantity(
            src,
            n,
            &format!("({})/sqrt(s)", t.unit.get_ref()).replace("(1)/", "1/"),
            item,
            "noise",
        ),
        None => Ok(0.0),
    }
}

/// The term's plausibility `limit` (∞ when not given), which must exceed its `sigma`.
fn term_limit(src: &Source, t: &RawTerm, item: &str, sigma: f64) -> Result<f64, SpecError> {
    let Some(l) = &t.limit else {
        return Ok(f64::INFINITY);
    };
    let v = quantity(src, l, t.unit.get_ref(), item, "limit")?;
    if v.partial_cmp(&sigma) != Some(std::cmp::Ordering::Greater) {
        return Err(src.error(
            l.span(),
            item,
            "limit must be larger than sigma (it bounds what is physically plausible)",
        ));
    }
    Ok(v)
}

/// The priors the term declares per grade: (grade, 1-σ [SI], line in terms.toml).
fn term_grade_sigma(
    src: &Source,
    t: &RawTerm,
    item: &str,
) -> Result<Vec<(String, f64, usize)>, SpecError> {
    t.grade_sigma
        .iter()
        .map(|(g, q)| {
            let si = quantity(src, q, t.unit.get_ref(), item, &format!("grade_sigma.{g}"))?;
            Ok((g.clone(), si, src.line_of(q.span().start)))
        })
        .collect()
}

/// A GNSS term: no regressor (it does not enter A; the constant `1` stands for it), and at
/// least one H entry, each a navigation expression over the rows of measurements.toml.
fn gnss_term_h(
    src: &Source,
    t: &RawTerm,
    item: &str,
) -> Result<(Expr, Vec<(String, Expr)>), SpecError> {
    if let Some(r) = &t.regressor {
        return Err(src.error(
            r.span(),
            item,
            "a `gnss` or `reference` term enters the measurements, not A: remove `regressor` and give its `h` entries",
        ));
    }
    if t.h.is_empty() {
        return Err(src.error(
            t.name.span(),
            item,
            "a `gnss` or `reference` term needs `h = [{ row = \"dp_n\", expr = \"...\" }, ...]`: the measurement rows it enters",
        ));
    }
    let mut h = Vec::new();
    for e in &t.h {
        let ex = expr::parse(e.expr.get_ref(), ExprKind::Navigation)
            .map_err(|m| src.error(e.expr.span(), item, format!("h[{}]: {m}", e.row.get_ref())))?;
        h.push((e.row.get_ref().clone(), ex));
    }
    let one = expr::parse("1", ExprKind::Regressor).expect("the constant regressor parses");
    Ok((one, h))
}

/// Merges every GNSS term's H entries into the measurement rows they name, checking that the
/// row exists, is entered once, and that the term's unit times the entry's dimension is the
/// row's unit.
fn merge_term_h(
    src: &Source,
    raw: &[RawTerm],
    terms: &[Term],
    measurements: &mut [Measurement],
) -> Result<(), SpecError> {
    for (t, rt) in terms.iter().zip(raw) {
        let item = format!("term `{}`", t.name);
        for ((row_name, e), re) in t.h.iter().zip(&rt.h) {
            let Some(row) = measurements
                .iter_mut()
                .flat_map(|m| m.rows.iter_mut())
                .find(|r| &r.name == row_name)
            else {
                let rows: Vec<&str> = measurements
                    .iter()
                    .flat_map(|m| m.rows.iter().map(|r| r.name.as_str()))
                    .collect();
                return Err(src.error(
                    re.row.span(),
                    &item,
                    format!(
                        "h: unknown measurement row `{row_name}` (rows: {})",
                        rows.join(" ")
                    ),
                ));
            };
            if row.h.iter().any(|x| x.state == t.name) {
                return Err(src.error(
                    re.row.span(),
                    &item,
                    format!("h: row `{row_name}` entered twice"),
                ));
            }
            let at = |m: String| src.error(re.expr.span(), &item, format!("h[{row_name}]: {m}"));
            let dim = e.dimension().map_err(at)?;
            let term_unit = units::parse_unit(&t.unit).map_err(|e| at(e.to_string()))?;
            let row_unit = units::parse_unit(&row.unit).map_err(|e| at(e.to_string()))?;
            let got = term_unit.dim.times(dim).map_err(at)?;
            if got.0[0] != row_unit.dim.0[0] || got.0[1] != row_unit.dim.0[1] {
                return Err(src.error(
                    re.expr.span(),
                    &item,
                    format!(
                        "h[{row_name}]: unit `{}` times `{}` [{dim}] is {got}, but the row is in {}",
                        t.unit, e.source, row.unit
                    ),
                ));
            }
            row.h.push(HEntry {
                state: t.name.clone(),
                expr: e.clone(),
            });
        }
    }
    Ok(())
}

/// Unit × regressor dimension = the sensor's dimension. Radians are compared loosely (an SI
/// radian is dimensionless: ω² times a lever arm in m is an acceleration).
fn check_term_dimension(
    src: &Source,
    t: &RawTerm,
    reg_text: &Spanned<String>,
    item: &str,
    sensor: Sensor,
    regressor: &Expr,
    unit: units::Dim,
) -> Result<(), SpecError> {
    let reg_dim = regressor
        .dimension()
        .map_err(|m| src.error(reg_text.span(), item, format!("regressor: {m}")))?;
    let (sensor_unit, sensor_name) = match sensor {
        Sensor::Gyro => ("rad/s", "a gyro error"),
        Sensor::Accel => ("m/s^2", "an accelerometer error"),
        Sensor::Gnss | Sensor::Reference | Sensor::Attitude => {
            unreachable!("a gnss term has no regressor")
        }
    };
    let want = units::parse_unit(sensor_unit)
        .expect("sensor unit parses")
        .dim;
    let got = unit
        .times(reg_dim)
        .map_err(|m| src.error(t.unit.span(), item, format!("unit times regressor: {m}")))?;
    if got.0[0] != want.0[0] || got.0[1] != want.0[1] {
        return Err(src.error(
            t.unit.span(),
            item,
            format!(
                "unit `{}` times regressor `{}` [{}] is {}, but {sensor_name} is in {sensor_unit}: the unit should be {} ",
                t.unit.get_ref(),
                reg_text.get_ref(),
                reg_dim,
                got,
                want.per(reg_dim).map_or_else(|e| format!("(none: {e})"), |d| d.to_string())
            )
            .trim_end()
            .to_string(),
        ));
    }
    Ok(())
}

/// Measurements: components with their H entries (states must exist) and default σ.
fn load_measurements(
    src: &Source,
    raw: &[RawMeasurement],
    names: &HashMap<String, String>,
) -> Result<Vec<Measurement>, SpecError> {
    let mut measurements: Vec<Measurement> = Vec::new();
    for m in raw {
        let item = format!("measurement `{}`", m.name.get_ref());
        check_name(src, &m.name, "measurement")?;
        if measurements.iter().any(|x| &x.name == m.name.get_ref()) {
            return Err(src.error(m.name.span(), &item, "duplicate name"));
        }
        let first_unit = m.rows.first().map(|r| r.unit.clone()).unwrap_or_default();
        let sigma = quantity(src, &m.sigma, &first_unit, &item, "sigma")?;
        if !(sigma > 0.0 && sigma.is_finite()) {
            return Err(src.error(m.sigma.span(), &item, "sigma must be positive and finite"));
        }
        let aiding = match m.aiding.get_ref().as_str() {
            "position" => Aiding::Position,
            "velocity" => Aiding::Velocity,
            "body_velocity" => Aiding::BodyVelocity,
            "attitude" => Aiding::Attitude,
            other => {
                return Err(src.error(
                    m.aiding.span(),
                    &item,
                    format!("aiding: unknown record `{other}` (expected `position`, `velocity`, `body_velocity` or `attitude`)"),
                ))
            }
        };
        let mut rows = Vec::new();
        for r in &m.rows {
            let residual = residual_expr(src, &r.residual, aiding, &item, "residual")?;
            let residual_sigma =
                residual_expr(src, &r.residual_sigma, aiding, &item, "residual_sigma")?;
            let mut h = Vec::new();
            for e in &r.h {
                if !names.contains_key(e.state.get_ref()) {
                    return Err(src.error(
                        e.state.span(),
                        &item,
                        format!("unknown state `{}`", e.state.get_ref()),
                    ));
                }
                let expr = expr::parse(e.expr.get_ref(), ExprKind::Navigation)
                    .map_err(|msg| src.error(e.expr.span(), &item, msg))?;
                h.push(HEntry {
                    state: e.state.get_ref().clone(),
                    expr,
                });
            }
            rows.push(MeasRow {
                name: r.name.clone(),
                unit: r.unit.clone(),
                h,
                residual,
                residual_sigma,
            });
        }
        measurements.push(Measurement {
            name: m.name.get_ref().clone(),
            doc: m.doc.clone(),
            sigma,
            aiding,
            rows,
        });
    }
    Ok(measurements)
}

/// A residual (or its 1-σ) expression of a measurement formed from `aiding`: it may use only that
/// record's fields.
fn residual_expr(
    src: &Source,
    text: &Spanned<String>,
    aiding: Aiding,
    item: &str,
    field: &str,
) -> Result<Expr, SpecError> {
    let e = expr::parse(text.get_ref(), ExprKind::Residual)
        .map_err(|msg| src.error(text.span(), item, format!("{field}: {msg}")))?;
    let (fields, record): (&[&str], &str) = match aiding {
        Aiding::Position => (&expr::AID_POSITION_FIELDS, "position"),
        Aiding::Velocity => (&expr::AID_VELOCITY_FIELDS, "velocity"),
        Aiding::BodyVelocity => (&expr::AID_BODY_VELOCITY_FIELDS, "body velocity"),
        Aiding::Attitude => (&expr::AID_ATTITUDE_FIELDS, "attitude"),
    };
    for sym in e.symbols() {
        if let Some(f) = sym.strip_prefix("aid.") {
            if !fields.contains(&f) {
                return Err(src.error(
                    text.span(),
                    item,
                    format!(
                        "{field}: `{sym}` is not in a {record} fix (it has aid.{})",
                        fields.join(" aid.")
                    ),
                ));
            }
        }
    }
    Ok(e)
}

/// Presets: `[[preset]]` entries with either the full `states` list or a `base` preset (defined
/// earlier in the file) plus `terms`; every name is checked, none listed twice.
fn load_presets(
    src: &Source,
    raw: &[RawPreset],
    nav_states: &[NavState],
    terms: &[Term],
    names: &HashMap<String, String>,
) -> Result<Vec<Preset>, SpecError> {
    let mut presets: Vec<Preset> = Vec::new();
    for raw in raw {
        let name = raw.name.get_ref();
        let item = format!("preset `{name}`");
        check_preset_name(src, raw, &item, &presets, terms)?;
        let states = preset_states(src, raw, &item, &presets)?;
        check_preset_states(src, raw, &item, &states, nav_states, names)?;
        presets.push(Preset {
            name: name.clone(),
            doc: raw.doc.clone(),
            states,
        });
    }
    Ok(presets)
}

/// A preset's name: letters, digits and `_`, not `vertical`, not an earlier preset's nor a term's.
fn check_preset_name(
    src: &Source,
    raw: &RawPreset,
    item: &str,
    earlier: &[Preset],
    terms: &[Term],
) -> Result<(), SpecError> {
    let name = raw.name.get_ref();
    let span = raw.name.span();
    let ok_name = name.chars().next().is_some_and(|c| c.is_ascii_alphabetic())
        && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_');
    if !ok_name || name.eq_ignore_ascii_case("vertical") {
        return Err(src.error(
            span,
            item,
            "preset names are letters, digits and `_`, starting with a letter (and not `vertical`)",
        ));
    }
    if earlier.iter().any(|p| p.name.eq_ignore_ascii_case(name)) {
        return Err(src.error(span, item, "duplicate preset (names are case-insensitive)"));
    }
    if terms.iter().any(|t| t.name.eq_ignore_ascii_case(name)) {
        return Err(src.error(span, item, "a preset cannot have the name of a term"));
    }
    Ok(())
}

/// A preset's state list: its `states`, or the states of its `base` (an earlier preset) followed
/// by its `terms`.
fn preset_states(
    src: &Source,
    raw: &RawPreset,
    item: &str,
    earlier: &[Preset],
) -> Result<Vec<String>, SpecError> {
    let span = raw.name.span();
    match (&raw.states, &raw.base) {
        (Some(s), None) => {
            if !raw.terms.is_empty() {
                return Err(src.error(span, item, "give either `states`, or `base` and `terms`"));
            }
            Ok(s.clone())
        }
        (None, Some(base)) => {
            let b = earlier
                .iter()
                .find(|p| p.name.eq_ignore_ascii_case(base.get_ref()))
                .ok_or_else(|| {
                    src.error(
                        base.span(),
                        item,
                        format!("base `{}` is not a preset defined above it", base.get_ref()),
                    )
                })?;
            let mut s = b.states.clone();
            s.extend(raw.terms.iter().cloned());
            Ok(s)
        }
        _ => Err(src.error(
            span,
            item,
            "give either `states` (the full list) or `base` (a preset above) and `terms`",
        )),
    }
}

/// A preset's states: each listed once, known, not vertical, and the horizontal navigation
/// states first, in order.
fn check_preset_states(
    src: &Source,
    raw: &RawPreset,
    item: &str,
    states: &[String],
    nav_states: &[NavState],
    names: &HashMap<String, String>,
) -> Result<(), SpecError> {
    let name = raw.name.get_ref();
    let span = raw.name.span();
    let mut seen = BTreeSet::new();
    for s in states {
        if !seen.insert(s.as_str()) {
            return Err(src.error(span.clone(), item, format!("state `{s}` listed twice")));
        }
        if !names.contains_key(s) {
            return Err(src.error(
                span.clone(),
                item,
                format!("names missing term `{s}` (not a state of navigation.toml nor a term of terms.toml)"),
            ));
        }
        if nav_states.iter().any(|n| &n.name == s && n.vertical) {
            return Err(src.error(
                span.clone(),
                item,
                format!(
                    "vertical state `{s}` cannot be listed; write the model as `{name}+vertical`"
                ),
            ));
        }
    }
    let horizontal: Vec<&str> = nav_states
        .iter()
        .filter(|s| !s.vertical)
        .map(|s| s.name.as_str())
        .collect();
    if states.len() < horizontal.len()
        || states[..horizontal.len()]
            .iter()
            .map(String::as_str)
            .ne(horizontal.iter().copied())
    {
        return Err(src.error(
            span,
            item,
            format!(
                "must start with the navigation states {}",
                horizontal.join(" ")
            ),
        ));
    }
    Ok(())
}
