//! Types describing what the model spec declares (states, terms, measurements, presets); the
//! values themselves are generated from `model-spec/` into [`crate::model::generated`].

use crate::nav::nav_point::NavPoint;

/// Which instrument a term corrupts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Sensor {
    /// Gyro: adds to the measured angular rate [rad/s].
    Gyro,
    /// Accelerometer: adds to the measured specific force [m/s²].
    Accel,
    /// GNSS aiding: enters the measurements (H), not A — a time offset, an antenna lever arm.
    Gnss,
    /// A body-frame velocity reference (odometer, DVL): enters its measurement (H), not A — a
    /// mounting misalignment.
    Reference,
    /// An attitude reference (a second INS, an AHRS): enters its measurement (H), not A — a
    /// mounting misalignment.
    Attitude,
}

impl Sensor {
    /// The term enters the measurements (H), not A: its closed-loop correction applies to the
    /// residuals, and it describes the aiding, not the IMU.
    pub fn enters_h(self) -> bool {
        matches!(self, Sensor::Gnss | Sensor::Reference | Sensor::Attitude)
    }
}

/// A navigation error state as declared in `model-spec/navigation.toml`.
#[derive(Debug, Clone, Copy)]
pub struct NavStateInfo {
    /// Canonical name, e.g. `phi_n`.
    pub name: &'static str,
    /// SI unit of the state.
    pub unit: &'static str,
    /// Unit at the edges (reports, CLI).
    pub display: &'static str,
    /// Factor from the display unit to SI.
    pub display_to_si: f64,
    /// Default prior 1-σ, SI.
    pub sigma: f64,
    /// Present only with `+vertical`.
    pub vertical: bool,
    /// The white sensor noise that drives the state (its process noise).
    pub white_noise: WhiteNoise,
    /// One-line description.
    pub doc: &'static str,
}

/// Which white sensor noise drives a navigation state (`white_noise` in navigation.toml).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WhiteNoise {
    /// None enters the state directly.
    None,
    /// Gyro angle random walk [rad/√s] (attitude rows).
    GyroArw,
    /// Accelerometer velocity random walk [m/s/√s] (velocity rows).
    AccelVrw,
}

/// An instrument error term as declared in `model-spec/terms.toml`.
#[derive(Debug, Clone, Copy)]
pub struct TermInfo {
    /// Canonical name, e.g. `kaq_x_xy`.
    pub name: &'static str,
    /// Sensor corrupted.
    pub sensor: Sensor,
    /// Body (FRD) sensing axis: 0 = x, 1 = y, 2 = z.
    pub axis: usize,
    /// Index into `generated::common::REGRESSORS`.
    pub regressor: usize,
    /// SI unit of the state.
    pub unit: &'static str,
    /// Unit at the edges.
    pub display: &'static str,
    /// Factor from the display unit to SI.
    pub display_to_si: f64,
    /// Default prior 1-σ, SI.
    pub sigma: f64,
    /// Random-walk density of the state [SI/√s]; 0 for a random constant.
    pub noise: f64,
    /// Largest physically plausible |value|, SI (∞ when the spec gives none): a prior or an
    /// injected value beyond it is refused as a unit mistake.
    pub limit: f64,
    /// Group label.
    pub group: &'static str,
    /// One-line description.
    pub doc: &'static str,
    /// Candidate library term (DESIGN §7).
    pub library: bool,
}

impl TermInfo {
    /// Why `value` [SI] (a prior σ or an injected value) is no physically plausible value of
    /// this term, if it is not: beyond the spec's `limit` (a unit slip, s for ms or m for mm).
    pub fn beyond_limit(&self, value: f64) -> Option<String> {
        (value.abs() > self.limit).then(|| {
            let k = 1.0 / self.display_to_si;
            let (v, l) = crate::io::units::sig_distinct(value * k, self.limit * k);
            format!(
                "{v} {} is beyond the {l} {} the term can physically have (its `limit` in model-spec/terms.toml): a larger unit written where {} was meant?",
                self.display,
                self.display,
                self.display
            )
        })
    }
}

impl TermInfo {
    /// Why `sigma` [SI], a prior σ given for this term, is refused when it is more than
    /// [`PRIOR_BELOW_SPEC`] times below the spec's prior σ: the term is then pinned at zero, and
    /// explain would call it "not testable (no information)", which it is not.
    pub fn prior_too_small(&self, sigma: f64) -> Option<String> {
        (self.sigma > 0.0 && sigma < self.sigma / PRIOR_BELOW_SPEC).then(|| {
            let k = 1.0 / self.display_to_si;
            format!(
                "{} {} is more than 10^6 times below the spec's prior σ of {} {}: it pins the term at zero (the data could tell nothing about it); give a prior σ within 10^6 of the spec's, or withhold the term (`--candidates '!{}'`, or a model without it)",
                crate::io::units::sig3(sigma * k),
                self.display,
                crate::io::units::sig3(self.sigma * k),
                self.display,
                self.name
            )
        })
    }
}

/// How far below the spec's prior σ a `--prior` may go ([`TermInfo::prior_too_small`]).
pub const PRIOR_BELOW_SPEC: f64 = 1e6;

/// A sensor grade as declared in `model-spec/grades.toml`: white noise and the prior of every
/// state (navigation states in `NAV_STATES` order, terms in `TERMS` order; SI).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GradeInfo {
    /// Name as given to `--grade`.
    pub name: &'static str,
    /// What IMUs it describes.
    pub doc: &'static str,
    /// Gyro angle random walk [rad/√s].
    pub gyro_arw: f64,
    /// The angle random walk as written in the spec.
    pub gyro_arw_text: &'static str,
    /// Accelerometer velocity random walk [m/s/√s].
    pub accel_vrw: f64,
    /// The velocity random walk as written in the spec.
    pub accel_vrw_text: &'static str,
    /// Prior 1-σ of each navigation state [SI]; `None` keeps the spec's default.
    pub nav_sigma: [Option<f64>; crate::model::generated::common::NAV_COUNT],
    /// Prior 1-σ of each term [SI] (where it comes from, term, group or the unlisted rule, is
    /// the spec compiler's business: `sinsmodel_codegen::grades`).
    pub term_sigma: [f64; crate::model::generated::common::TERM_COUNT],
}

/// Which aiding record a measurement is formed from (`aiding` in measurements.toml).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Aiding {
    /// A position fix.
    Position,
    /// A velocity fix.
    Velocity,
    /// A body-frame (FRD) velocity from a reference (odometer, DVL).
    BodyVelocity,
    /// An attitude from a reference (a second INS, an AHRS).
    Attitude,
}

/// The filter's navigation state at a fix, as a measurement residual sees it (SI units).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ResidualState {
    /// Geodetic latitude [rad].
    pub lat: f64,
    /// Longitude [rad].
    pub lon: f64,
    /// Height, up [m].
    pub h: f64,
    /// North velocity [m/s].
    pub vn: f64,
    /// East velocity [m/s].
    pub ve: f64,
    /// Down velocity [m/s].
    pub vd: f64,
    /// R_M + h at the state [m].
    pub rm: f64,
    /// R_N + h at the state [m].
    pub rn: f64,
    /// C_b^n at the state, row by row (`c11` … `c33`).
    pub c11: f64,
    /// C_b^n (1, 2).
    pub c12: f64,
    /// C_b^n (1, 3).
    pub c13: f64,
    /// C_b^n (2, 1).
    pub c21: f64,
    /// C_b^n (2, 2).
    pub c22: f64,
    /// C_b^n (2, 3).
    pub c23: f64,
    /// C_b^n (3, 1).
    pub c31: f64,
    /// C_b^n (3, 2).
    pub c32: f64,
    /// C_b^n (3, 3).
    pub c33: f64,
}

/// One aiding record as a residual reads it (`aid.lat`, …): the fields of the record the
/// measurement names; the others are NaN, and the spec compiler refuses a residual that uses them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AidRecord {
    /// Latitude of a position fix [rad].
    pub lat: f64,
    /// Longitude [rad].
    pub lon: f64,
    /// Height, up [m].
    pub h: f64,
    /// 1-σ north [m].
    pub sigma_n: f64,
    /// 1-σ east [m].
    pub sigma_e: f64,
    /// 1-σ down [m].
    pub sigma_d: f64,
    /// North velocity of a velocity fix [m/s].
    pub vn: f64,
    /// East velocity [m/s].
    pub ve: f64,
    /// Down velocity [m/s].
    pub vd: f64,
    /// 1-σ of each velocity component [m/s].
    pub sigma_v: f64,
    /// Body-frame (FRD) velocity of a reference, forward [m/s].
    pub vx: f64,
    /// Right [m/s].
    pub vy: f64,
    /// Down [m/s].
    pub vz: f64,
    /// 1-σ of each body-frame component [m/s].
    pub sigma_b: f64,
    /// C_r^n of an attitude reference's frame, row by row (`r11` … `r33`).
    pub r11: f64,
    /// C_r^n (1, 2).
    pub r12: f64,
    /// C_r^n (1, 3).
    pub r13: f64,
    /// C_r^n (2, 1).
    pub r21: f64,
    /// C_r^n (2, 2).
    pub r22: f64,
    /// C_r^n (2, 3).
    pub r23: f64,
    /// C_r^n (3, 1).
    pub r31: f64,
    /// C_r^n (3, 2).
    pub r32: f64,
    /// C_r^n (3, 3).
    pub r33: f64,
    /// 1-σ of the reference's tilt (roll, pitch) [rad].
    pub sigma_tilt: f64,
    /// 1-σ of its yaw [rad].
    pub sigma_yaw: f64,
}

impl AidRecord {
    /// A record with no field set (all NaN), to be filled from one fix.
    pub const UNSET: AidRecord = AidRecord {
        lat: f64::NAN,
        lon: f64::NAN,
        h: f64::NAN,
        sigma_n: f64::NAN,
        sigma_e: f64::NAN,
        sigma_d: f64::NAN,
        vn: f64::NAN,
        ve: f64::NAN,
        vd: f64::NAN,
        sigma_v: f64::NAN,
        vx: f64::NAN,
        vy: f64::NAN,
        vz: f64::NAN,
        sigma_b: f64::NAN,
        r11: f64::NAN,
        r12: f64::NAN,
        r13: f64::NAN,
        r21: f64::NAN,
        r22: f64::NAN,
        r23: f64::NAN,
        r31: f64::NAN,
        r32: f64::NAN,
        r33: f64::NAN,
        sigma_tilt: f64::NAN,
        sigma_yaw: f64::NAN,
    };
}

/// One component of a measurement.
#[derive(Debug, Clone, Copy)]
pub struct MeasRowInfo {
    /// Component name, e.g. `dp_n`.
    pub name: &'static str,
    /// Unit of the component.
    pub unit: &'static str,
}

/// A measurement type as declared in `model-spec/measurements.toml`.
#[derive(Debug, Clone, Copy)]
pub struct MeasurementInfo {
    /// Canonical name: `vel_ne`, `pos_ne`, `pos_h`.
    pub name: &'static str,
    /// One-line description.
    pub doc: &'static str,
    /// Default noise 1-σ per component, SI.
    pub sigma: f64,
    /// The aiding record it is formed from.
    pub aiding: Aiding,
    /// Components.
    pub rows: &'static [MeasRowInfo],
    /// States the measurement references (all must be in a model for it to apply).
    pub states: &'static [&'static str],
}

/// What a model state is: a navigation state or an instrument term (catalogue indices).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StateRef {
    /// Index into `generated::common::NAV_STATES`.
    Nav(usize),
    /// Index into `generated::common::TERMS`.
    Term(usize),
}

/// A generated step kernel: (A, dt, q, P, x) with A and P N×N row-major; P ← Φ P Φᵀ + diag(q)·dt
/// and x ← Φ x.
pub type PropagateFn = fn(&[f64], f64, &[f64], &mut [f64], &mut [f64]);

/// The generated kernels of one preset, reachable by name at run time.
#[derive(Debug, Clone, Copy)]
pub struct PresetKernels {
    /// Name, e.g. `P31+vertical`.
    pub name: &'static str,
    /// One-line description.
    pub doc: &'static str,
    /// Vertical channel present.
    pub vertical: bool,
    /// State names in order.
    pub states: &'static [&'static str],
    /// Catalogue reference of each state.
    pub state_refs: &'static [StateRef],
    /// Structural non-zeros of A.
    pub a_pattern: &'static [(usize, usize)],
    /// Accumulated regressors (indices into `generated::common::REGRESSORS`).
    pub regressor_ids: &'static [usize],
    /// Supported measurements.
    pub measurements: &'static [&'static str],
    /// Fills A (N×N row-major) from regressor means.
    pub fill_a: fn(&NavPoint, &[f64], &mut [f64]),
    /// Fills H of a measurement (rows×N row-major); false if unsupported.
    pub fill_h: fn(&str, &NavPoint, &mut [f64]) -> bool,
    /// P ← Φ P Φᵀ + diag(q)·dt (N×N row-major).
    pub propagate_cov: fn(&[f64], f64, &[f64], &mut [f64]),
    /// P ← Φ P Φᵀ + diag(q)·dt and x ← Φ x (N×N row-major, N).
    pub propagate: PropagateFn,
    /// Adds one sample's regressors (f [m/s²], w [rad/s]) to running sums.
    pub accumulate: crate::model::AccumulateFn,
}
