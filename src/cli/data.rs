//! The data options shared by `filter` and `explain` (they mean exactly the same in both): IMU,
//! aiding, truth, initial state, priors, noise, mode, step, ZUPT; and the filter set-up they give.

use anyhow::{bail, Context, Result};
use clap::Args;
use nalgebra::{Rotation3, UnitQuaternion, Vector3};
use sinsmodel::estimate::filter::{AidingEpoch, FilterConfig, Mode};
use sinsmodel::io::imu::ImuData;
use sinsmodel::io::truth::{TruthLookup, TruthRow};
use sinsmodel::io::{aiding, truth};
use sinsmodel::model::catalog::GradeInfo;
use sinsmodel::model::generated::common;
use sinsmodel::model::priors::{self, StatePattern};
use sinsmodel::model::Model;
use sinsmodel::nav::attitude::dcm_from_euler;
use sinsmodel::nav::strapdown::{NavState, Vertical};
use std::path::PathBuf;

/// The IMU file and how to read it: the options of `navigate`, `align`, `allan`, `imu-check`.
#[derive(Args, Clone, Debug)]
pub struct ImuSource {
    /// IMU file (text, PSINS .imu, FILE.mat:VARIABLE of PSINS [wm vm t], GNSS_IMU .csv, or any
    /// layout --imu-format describes).
    #[arg(long)]
    pub imu: PathBuf,
    /// IMU format description (TOML, docs/formats.md); default: FILE.format.toml beside the
    /// IMU file if there is one, else chosen by the file's extension.
    #[arg(long)]
    pub imu_format: Option<PathBuf>,
    /// GPST − IMU clock [s] for a GNSS_IMU .csv without its .tag file (0 keeps the IMU clock).
    #[arg(long, allow_hyphen_values = true)]
    pub clock_offset: Option<f64>,
}

impl ImuSource {
    /// Reads the IMU file; says on stderr which format was used.
    pub fn read(&self) -> Result<ImuData> {
        self.open()?.collect()
    }

    /// Opens the IMU file as a stream of validated samples; says on stderr which format was used.
    pub fn open(&self) -> Result<sinsmodel::io::imu_stream::ImuStream> {
        let (stream, how) = sinsmodel::io::imu_stream::ImuStream::open_with(
            &self.imu,
            self.imu_format.as_deref(),
            self.clock_offset,
        )?;
        eprintln!(
            "{}",
            sinsmodel::io::lines::printable_message(&format!(
                "reading {} {how}",
                self.imu.display()
            ))
        );
        Ok(stream)
    }

    /// The input files (so outputs never land on them).
    pub fn paths(&self) -> Vec<PathBuf> {
        let mut v = vec![sinsmodel::io::readers::matlab::file_of(&self.imu)];
        v.extend(self.imu_format.clone());
        v.extend(sinsmodel::io::imu_format::beside(&self.imu));
        // a GNSS_IMU csv's clock file is read beside it
        v.push(self.imu.with_extension("csv.tag"));
        v
    }

    /// Refuses an output file that is one of the inputs or not a regular file, and (unless
    /// `force`) one that is another run's result or not provably this command's earlier output.
    pub fn check_output(
        &self,
        option: &str,
        path: &std::path::Path,
        provenance: sinsmodel::io::atomic_file::Provenance,
        force: bool,
    ) -> Result<()> {
        let inputs = self.paths();
        let refs: Vec<&std::path::Path> = inputs.iter().map(|p| p.as_path()).collect();
        sinsmodel::io::atomic_file::check_output_file(option, path, &refs, provenance, force)
    }
}

/// The data options of `filter` and `explain`.
#[derive(Args, Clone, Debug)]
pub struct DataArgs {
    /// IMU file (text, PSINS .imu, FILE.mat:VARIABLE of PSINS [wm vm t], GNSS_IMU .csv, or any
    /// layout --imu-format describes).
    #[arg(long)]
    imu: Option<PathBuf>,
    /// IMU format description (TOML, docs/formats.md); default: FILE.format.toml beside the
    /// IMU file if there is one, else chosen by the file's extension.
    #[arg(long)]
    imu_format: Option<PathBuf>,
    /// GPST − IMU clock [s] for a GNSS_IMU .csv without its .tag file (0 keeps the IMU clock).
    #[arg(long, allow_hyphen_values = true)]
    clock_offset: Option<f64>,
    /// Position aiding file (t lat lon h sigma_n sigma_e sigma_d), or an RTKLIB `.pos` solution.
    #[arg(long)]
    aid: Option<PathBuf>,
    /// Which parts of the aiding file to use: pos, vel or pos,vel (default: all the file has; an
    /// RTKLIB .pos with vn ve vu, or an 11-column aiding file, has velocities).
    #[arg(long)]
    aid_use: Option<String>,
    /// A static vehicle at a known position: lat,lon [deg],h [m]; position updates (σ 0.1 m) and
    /// zero-velocity updates (σ from --zupt, default 0.01 m/s) at 1 Hz instead of --aid.
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true)]
    static_aid: Option<Vec<f64>>,
    /// Prior 1-σ of a state, NAME=QUANTITY with units (repeatable); a trailing `*` matches a
    /// prefix: `--prior 'eps_*=1 deg/s' --prior 'nabla_*=20 mg' --prior 'phi_d=5 deg'`.
    #[arg(long)]
    prior: Vec<String>,
    /// Sensor white noise instead of the spec defaults: a `sinsmodel allan --json` file (mean
    /// ARW of the gyros, VRW of the accelerometers), or inline with units:
    /// `'arw=0.3 deg/sqrt(h), vrw=150 ug/sqrt(Hz)'`.
    #[arg(long)]
    noise: Option<PathBuf>,
    /// Truth file (t lat lon h vn ve vd roll pitch yaw), or a PSINS reference FILE.mat:avp: adds
    /// the true φ and the model error.
    #[arg(long)]
    truth: Option<PathBuf>,
    /// Initial lat,lon [deg],h [m],roll,pitch,yaw [deg][,vn,ve,vd m/s], or `auto`: level from
    /// the first seconds at rest, heading by gyrocompassing (when the grade allows) or from the
    /// GNSS course of the drive-off, or from the course at a moving start (docs/real-data.md);
    /// default: the first truth row.
    #[arg(long, allow_hyphen_values = true)]
    init: Option<String>,
    /// With `--init auto`: the GNSS speed [m/s] above which the course gives the heading
    /// [default: 3].
    #[arg(long)]
    init_speed: Option<f64>,
    /// open (errors estimated only) or closed (fed back).
    #[arg(long, default_value = "open")]
    mode: String,
    /// Filter step [s] [default: 0.01, or the IMU's median interval when that is longer].
    #[arg(long)]
    step: Option<f64>,
    /// Zero-velocity updates with this σ [m/s] at every aiding epoch (vehicle at rest).
    #[arg(long)]
    zupt: Option<f64>,
    /// Run even when the initial roll and pitch contradict the measured gravity direction; with
    /// explain, also replace a --json file that is not provably an earlier explain output.
    #[arg(long)]
    pub force: bool,
    /// Sensor grade the priors and noise assume: navigation (the spec's defaults), tactical or
    /// mems; --prior and --noise override single values.
    #[arg(long)]
    grade: Option<String>,
    /// A GNSS outage: START,DURATION [s], START counted from the first IMU sample; the aiding
    /// epochs inside are dropped and the drift at its end is reported (repeatable).
    #[arg(long, allow_hyphen_values = true)]
    outage: Vec<String>,
    /// Known IMU–GNSS time offset with its unit (`92 ms`, `0.092 s`): a fix stamped t is the
    /// trajectory at t + OFFSET (the spec term dt_gnss), applied in the residuals; needs --aid.
    #[arg(long, allow_hyphen_values = true)]
    gnss_delay: Option<String>,
    /// Known GNSS antenna lever arm, IMU to antenna in the body frame (FRD): X,Y,Z [m] (the spec
    /// terms lever_x lever_y lever_z), applied in the residuals; needs --aid.
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true)]
    lever_arm: Option<Vec<String>>,
}

/// A GNSS outage window on the data's clock [s].
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct Outage {
    /// First second without aiding, on the data's clock [s].
    pub start_s: f64,
    /// End of the window [s].
    pub end_s: f64,
}

impl Outage {
    /// Whether time `t` [s] falls in the window [start, end).
    pub fn contains(&self, t: f64) -> bool {
        t >= self.start_s && t < self.end_s
    }
}

/// The grade `--grade` names (None for navigation, the spec's defaults): `model-spec/grades.toml`.
fn grade_table(grade: Option<&str>) -> Result<Option<&'static GradeInfo>> {
    priors::grade(grade).map_err(|_| {
        anyhow::anyhow!(
            "--grade `{}`: expected {}",
            sinsmodel::io::lines::shown(grade.unwrap_or_default()),
            priors::grade_names()
        )
    })
}

/// Default filter step [s].
const DEFAULT_STEP_S: f64 = 0.01;

/// What opening the data decides for the filter set-up: the step [s] (the default raised to the
/// IMU's interval), and the attitude priors raised to what `--init auto` found — tilt 1-σ for
/// phi_n and phi_e, heading 1-σ for phi_d [rad] (a prior already wider is kept).
pub fn apply_opened(
    cfg: &mut FilterConfig,
    model: &Model,
    init_sigma: Option<(f64, f64)>,
    step_s: f64,
) {
    cfg.step_s = step_s;
    let Some((tilt, yaw)) = init_sigma else {
        return;
    };
    for (i, name) in model.names.iter().enumerate() {
        let s = match *name {
            "phi_n" | "phi_e" => tilt,
            "phi_d" => yaw,
            _ => continue,
        };
        cfg.prior_sigma[i] = cfg.prior_sigma[i].max(s);
    }
}

/// What the data options load for a command that passes over the data more than once: the IMU
/// file (read again on every pass), aiding epochs, truth, the initial state.
pub struct Inputs {
    /// The IMU file.
    pub imu: PathBuf,
    /// Its format description, when given.
    pub imu_format: Option<PathBuf>,
    /// `--clock-offset` [s], when given.
    pub clock_offset: Option<f64>,
    /// Aiding epochs after the start.
    pub aid: Vec<AidingEpoch>,
    /// Truth rows, when given.
    pub truth: Option<Vec<TruthRow>>,
    /// Initial navigation state.
    pub start: NavState,
    /// With `--init auto`: 1-σ of the found tilt and heading [rad].
    pub init_sigma: Option<(f64, f64)>,
    /// The filter step [s].
    pub step_s: f64,
}

/// The data options opened for one streamed pass.
pub struct Opened {
    /// IMU samples, validated as they are read.
    pub imu: sinsmodel::io::imu_stream::ImuStream,
    /// Aiding epochs after the start.
    pub aid: AidPlan,
    /// Truth, read as the run advances.
    pub truth: Option<truth::TruthReader>,
    /// Initial navigation state.
    pub start: NavState,
    /// GNSS outages (aiding dropped inside).
    pub outages: Vec<Outage>,
    /// With `--init auto`: 1-σ of the found tilt and heading [rad], for the attitude priors.
    pub init_sigma: Option<(f64, f64)>,
    /// IMU samples read before the start (`--init auto` at a later sample) and not filtered.
    pub skipped_samples: u64,
    /// The filter step [s]: `--step`, or the default raised to the IMU's interval.
    pub step_s: f64,
}

/// Where the aiding epochs come from.
pub enum AidPlan {
    /// Fixes from a file (with their velocities when the file has them and `--aid-use` takes
    /// them), with the ZUPT σ [m/s] to add to each and whether positions are used.
    Fixes(
        Vec<(aiding::PositionFix, Option<aiding::VelocityFix>)>,
        Option<f64>,
        bool,
    ),
    /// A static vehicle: this fix every whole second from `first_s`, with a ZUPT σ [m/s].
    Static {
        /// The position (its `t` unused).
        fix: aiding::PositionFix,
        /// Time of the first epoch [s].
        first_s: f64,
        /// Zero-velocity σ [m/s].
        zupt: Option<f64>,
    },
}

impl AidPlan {
    /// Only the epochs after `t0`.
    fn after(self, t0: f64) -> AidPlan {
        match self {
            AidPlan::Fixes(f, z, p) => {
                AidPlan::Fixes(f.into_iter().filter(|f| f.0.t > t0).collect(), z, p)
            }
            s => s,
        }
    }

    /// Number of epochs from a file (0 for the endless static plan).
    pub fn len(&self) -> usize {
        match self {
            AidPlan::Fixes(f, _, _) => f.len(),
            AidPlan::Static { .. } => 0,
        }
    }

    /// The epochs in time order without those inside any outage window.
    pub fn epochs_outside<'a>(
        &'a self,
        outages: &'a [Outage],
    ) -> Box<dyn Iterator<Item = AidingEpoch> + 'a> {
        Box::new(
            self.epochs()
                .filter(move |e| !outages.iter().any(|o| o.contains(e.t))),
        )
    }

    /// The epochs in time order (endless for a static vehicle: the run ends with the IMU data).
    pub fn epochs(&self) -> Box<dyn Iterator<Item = AidingEpoch> + '_> {
        let epoch = |f: &aiding::PositionFix, t: f64, zupt: Option<f64>| AidingEpoch {
            t,
            vel: zupt.map(|s| (Vector3::zeros(), s)),
            pos: Some((f.lat, f.lon, f.h, f.sigma)),
        };
        match self {
            AidPlan::Fixes(f, zupt, use_pos) => Box::new(f.iter().map(move |(p, v)| {
                let mut e = epoch(p, p.t, *zupt);
                if let Some(v) = v {
                    e.vel = Some((Vector3::from(v.v_ned), v.sigma));
                }
                if !*use_pos {
                    e.pos = None;
                }
                e
            })),
            AidPlan::Static { fix, first_s, zupt } => {
                Box::new((0u64..).map(move |k| epoch(fix, first_s + k as f64, *zupt)))
            }
        }
    }
}

/// At least 10 aiding epochs must have fallen inside the IMU data (t0, t_last]: `used` of
/// `total` (0: a static plan) did.
pub fn check_inside(used: usize, total: usize, t0: f64, t_last: f64) -> Result<()> {
    if used < 10 {
        bail!(
            "only {used}{} aiding epochs fall inside the IMU data ({t0:.3} to {t_last:.3} s); at least 10 are needed (the filter works on innovations)",
            if total > 0 { format!(" of {total}") } else { String::new() }
        );
    }
    Ok(())
}

impl DataArgs {
    /// True when any data option was given (explain runs its embedded demo when none is).
    pub fn any_given(&self) -> bool {
        self.imu.is_some()
            || self.imu_format.is_some()
            || self.clock_offset.is_some()
            || self.aid.is_some()
            || self.aid_use.is_some()
            || self.static_aid.is_some()
            || !self.prior.is_empty()
            || self.noise.is_some()
            || self.truth.is_some()
            || self.init.is_some()
            || self.zupt.is_some()
            || self.force
            || self.grade.is_some()
            || !self.outage.is_empty()
            || self.gnss_delay.is_some()
            || self.lever_arm.is_some()
    }

    /// True when the aiding comes from a GNSS file (`--aid`): GNSS terms (time offset, lever
    /// arm) mean something only then.
    pub fn has_gnss(&self) -> bool {
        self.aid.is_some()
    }

    /// The known GNSS term values of `--gnss-delay` and `--lever-arm`: (term index, SI), each
    /// checked for syntax and physics.
    pub fn known_gnss(&self) -> Result<Vec<(usize, f64)>> {
        let term = |name: &str, option: &str| -> Result<usize> {
            common::TERMS
                .iter()
                .position(|t| t.name == name)
                .with_context(|| {
                    format!("{option}: the spec has no term `{name}` (model-spec/terms.toml)")
                })
        };
        let mut out = Vec::new();
        if let Some(text) = &self.gnss_delay {
            let dt = sinsmodel::io::units::parse_quantity_as(text, "s").with_context(|| {
                format!("--gnss-delay `{text}`: expected a time with its unit, e.g. `92 ms` or `0.092 s`")
            })?;
            if !dt.is_finite() || dt.abs() > 1.0 {
                bail!(
                    "--gnss-delay `{text}`: {dt} s is beyond ±1 s; an IMU–GNSS time offset is milliseconds to a few hundred (ms read as s? a UTC–GPST leap-second difference belongs in --clock-offset)"
                );
            }
            if dt != 0.0 && dt.abs() < 1e-3 {
                bail!(
                    "--gnss-delay `{text}`: {} ms is below 1 ms, far under an IMU sample period: it changes nothing measurable (s read as ms? `0.179 s` is 179 ms); leave the option out for none",
                    dt * 1e3
                );
            }
            out.push((term("dt_gnss", "--gnss-delay")?, dt));
        }
        if let Some(l) = &self.lever_arm {
            if l.len() != 3 {
                bail!(
                    "--lever-arm: expected X,Y,Z in metres (body frame, FRD), got {} values",
                    l.len()
                );
            }
            for (k, (item, axis)) in l.iter().zip(["x", "y", "z"]).enumerate() {
                // bare numbers are metres; a unit may be given (`34 cm`)
                let item = item.trim();
                let v = match item.parse::<f64>() {
                    Ok(v) => v,
                    Err(_) => sinsmodel::io::units::parse_quantity_as(item, "m").with_context(|| {
                        format!("--lever-arm: {axis} = `{item}`: expected metres (`0.3`) or a length with its unit (`30 cm`)")
                    })?,
                };
                if !v.is_finite() {
                    bail!("--lever-arm: {axis} = `{item}` is not a number");
                }
                if v.abs() > 10.0 {
                    bail!(
                        "--lever-arm: {axis} = {v} m is beyond ±10 m; a vehicle's IMU-to-antenna arm is metres at most (mm read as m?)"
                    );
                }
                out.push((
                    term(["lever_x", "lever_y", "lever_z"][k], "--lever-arm")?,
                    v,
                ));
            }
        }
        if !out.is_empty() && !self.has_gnss() {
            bail!("--gnss-delay and --lever-arm describe a GNSS receiver: they need --aid (a GNSS file)");
        }
        Ok(out)
    }

    /// The input files named by the options (so outputs never land on them).
    pub fn input_paths(&self) -> Vec<PathBuf> {
        [
            &self.imu,
            &self.imu_format,
            &self.aid,
            &self.noise,
            &self.truth,
        ]
        .into_iter()
        .flatten()
        .map(|p| sinsmodel::io::readers::matlab::file_of(p))
        .chain(self.imu.iter().flat_map(|i| {
            // what is read beside the IMU file: its format description and a csv's clock file
            let mut v: Vec<PathBuf> = sinsmodel::io::imu_format::beside(i).into_iter().collect();
            v.push(i.with_extension("csv.tag"));
            v
        }))
        .collect()
    }

    /// Prints the sensor noise `--noise` gives, if any, and the grade the priors assume (once per
    /// run).
    pub fn print_noise(&self) -> Result<()> {
        match grade_table(self.grade.as_deref())? {
            None => eprintln!(
                "priors and noise: {} (the spec's defaults, a navigation-grade laser-gyro INS); --grade tactical|mems for other sensors{}",
                if self.grade.is_some() { "--grade navigation" } else { "navigation grade" },
                if self.prior.is_empty() && self.noise.is_none() { "" } else { "; --prior/--noise override single values" }
            ),
            Some(g) => eprintln!(
                "priors and noise: --grade {} (ARW {}, VRW {}; the priors of model-spec/grades.toml){}",
                g.name,
                g.gyro_arw_text,
                g.accel_vrw_text,
                if self.prior.is_empty() && self.noise.is_none() { "" } else { "; --prior/--noise override single values" }
            ),
        }
        for (t, v) in self.known_gnss()? {
            let info = &common::TERMS[t];
            eprintln!(
                "known GNSS value applied in the residuals: {} = {} {} ({}); a {} state in the model estimates what is left on top of it",
                info.name,
                v / info.display_to_si,
                info.display,
                info.doc,
                info.name
            );
        }
        if let Some(path) = &self.noise {
            let (arw, vrw) = noise_from_allan(path)?;
            // rad/√s → deg/√h: × 180/π × 60; m/s/√s → µg/√Hz: ÷ g × 1e6
            eprintln!(
                "noise from {} (used{}): ARW {:.3e} rad/sqrt(s) = {:.3} deg/sqrt(h), VRW {:.3e} m/s/sqrt(s) = {:.0} ug/sqrt(Hz)",
                path.display(),
                if self.grade.is_some() { " instead of the grade's" } else { "" },
                arw,
                arw.to_degrees() * 60.0,
                vrw,
                vrw / sinsmodel::io::units::STANDARD_GRAVITY * 1e6
            );
        }
        Ok(())
    }

    /// A description of the data for reports.
    pub fn describe(&self) -> String {
        let mut s = String::new();
        if let Some(p) = &self.imu {
            s.push_str(&format!("IMU {}", p.display()));
        }
        if let Some(p) = &self.aid {
            s.push_str(&format!(", aiding {}", p.display()));
        }
        if let Some(v) = &self.static_aid {
            s.push_str(&format!(", static at {v:?}"));
        }
        if let Some(p) = &self.truth {
            s.push_str(&format!(", truth {}", p.display()));
        }
        if let Some(d) = &self.gnss_delay {
            s.push_str(&format!(", known GNSS delay {d}"));
        }
        if let Some(l) = &self.lever_arm {
            s.push_str(&format!(", known lever arm {} (m, FRD)", l.join(",")));
        }
        s
    }

    /// The `--prior` options that name spec terms (names or prefixes): (term index, σ in SI),
    /// for explain's candidates (the sensor class of the data).
    pub fn term_priors(&self) -> Result<Vec<(usize, f64)>> {
        use sinsmodel::model::generated::common;
        let mut out: Vec<(usize, f64)> = Vec::new();
        if let Some(g) = grade_table(self.grade.as_deref())? {
            out.extend(g.term_sigma.iter().copied().enumerate());
        }
        for spec in &self.prior {
            let (name, value) = spec
                .split_once('=')
                .with_context(|| format!("--prior `{spec}`: expected NAME=QUANTITY"))?;
            let (name, value) = (name.trim(), value.trim());
            let pattern = StatePattern::new(name);
            for (t, info) in common::TERMS.iter().enumerate() {
                if pattern.matches(info.name) {
                    let si = sinsmodel::io::units::parse_quantity_as(value, info.unit)
                        .map_err(|e| anyhow::anyhow!("--prior `{spec}`: {e}"))?;
                    if !(si.is_finite() && si > 0.0) {
                        bail!("--prior `{spec}`: a prior σ must be positive and finite");
                    }
                    if let Some(why) = info.beyond_limit(si) {
                        bail!("--prior `{spec}`: {}: {why}", info.name);
                    }
                    out.retain(|x| x.0 != t);
                    out.push((t, si));
                }
            }
        }
        Ok(out)
    }

    /// Every `--prior` must name a state of `model` or a spec term (explain's candidates).
    pub fn check_prior_names(&self, model: &Model) -> Result<()> {
        use sinsmodel::model::generated::common;
        for spec in &self.prior {
            let name = spec.split_once('=').map(|x| x.0.trim()).unwrap_or(spec);
            let hit = |n: &str| match name.strip_suffix('*') {
                Some(prefix) => n.starts_with(prefix),
                None => n == name,
            };
            if !model.names.iter().any(|n| hit(n)) && !common::TERMS.iter().any(|t| hit(t.name)) {
                bail!(
                    "--prior `{spec}`: no state `{name}` in {} and no spec term of that name{}",
                    model.name,
                    sinsmodel::model::did_you_mean(name.trim_end_matches('*'))
                );
            }
        }
        Ok(())
    }

    /// For a command that passes over the IMU file more than once (explain): reads the file
    /// through once (every sample validated, its end found; memory does not grow with it), then
    /// the aiding epochs inside it, the truth and the initial state. Each pass reads the file
    /// again ([`sinsmodel::explain::ImuInput::File`]).
    pub fn load_for_passes(&self) -> Result<Inputs> {
        let mut opened = self.open()?;
        while opened.imu.next()?.is_some() {}
        let t_last = opened.imu.last_t();
        let truth = match &self.truth {
            Some(p) => Some(truth::read(p)?),
            None => None,
        };
        let start = opened.start;
        let aid: Vec<AidingEpoch> = opened
            .aid
            .epochs_outside(&opened.outages)
            .take_while(|e| e.t <= t_last + 1e-9)
            .collect();
        check_inside(aid.len(), opened.aid.len(), start.t, t_last)?;
        Ok(Inputs {
            init_sigma: opened.init_sigma,
            step_s: opened.step_s,
            imu: self.imu.clone().context("--imu FILE is required")?,
            imu_format: self.imu_format.clone(),
            clock_offset: self.clock_offset,
            aid,
            truth,
            start,
        })
    }

    /// Opens the IMU, aiding and truth files for one streamed pass and builds the initial
    /// state; everything that can be checked before the run is (the aiding epochs that fall
    /// inside the IMU data are counted after it: [`check_inside`]).
    pub fn open(&self) -> Result<Opened> {
        let args = self;
        let step = args.step_given()?;
        let imu_path = args.imu.as_ref().context("--imu FILE is required")?;
        let (mut imu, how) = sinsmodel::io::imu_stream::ImuStream::open_with(
            imu_path,
            args.imu_format.as_deref(),
            args.clock_offset,
        )?;
        eprintln!(
            "{}",
            sinsmodel::io::lines::printable_message(&format!(
                "reading {} {how}",
                imu_path.display()
            ))
        );
        if let Some(z) = args.zupt {
            if !(z.is_finite() && z > 0.0 && z < 100.0) {
                bail!("--zupt {z}: expected a velocity σ in (0, 100) m/s");
            }
        }
        let zupt = args.zupt.or(args
            .static_aid
            .as_ref()
            .map(|_| sinsmodel::model::measurement_sigma("vel_ne").unwrap_or(0.01)));
        let t0 = imu.start_time();
        let fixes: AidPlan = match (&args.aid, &args.static_aid) {
            (Some(p), None) => {
                let fixes: Vec<(aiding::PositionFix, Option<aiding::VelocityFix>)> =
                    if p.extension().is_some_and(|e| e == "pos") {
                        sinsmodel::io::readers::rtklib::read(p)?
                            .iter()
                            .map(|e| {
                                (
                                    aiding::PositionFix {
                                        t: e.t,
                                        lat: e.lat_deg.to_radians(),
                                        lon: e.lon_deg.to_radians(),
                                        h: e.h,
                                        sigma: [
                                            e.sigma_neu[0].max(0.02),
                                            e.sigma_neu[1].max(0.02),
                                            e.sigma_neu[2].max(0.05),
                                        ],
                                    },
                                    e.v_ned.map(|v| aiding::VelocityFix {
                                        v_ned: v,
                                        // RTKLIB's velocity σ, floored at 1 cm/s
                                        sigma: e
                                            .sigma_v_ne
                                            .map(|s| s[0].max(s[1]))
                                            .unwrap_or(0.1)
                                            .max(0.01),
                                    }),
                                )
                            })
                            .collect()
                    } else {
                        aiding::read_with_velocity(p)?
                    };
                let has_vel = fixes.iter().any(|f| f.1.is_some());
                let (use_pos, use_vel) = match args.aid_use.as_deref() {
                    None => (true, has_vel),
                    Some("pos") => (true, false),
                    Some("vel") => (false, true),
                    Some("pos,vel") | Some("vel,pos") => (true, true),
                    Some(o) => bail!(
                        "--aid-use `{}`: expected pos, vel or pos,vel",
                        sinsmodel::io::lines::shown(o)
                    ),
                };
                if use_vel && !has_vel {
                    bail!(
                        "--aid-use {}: {} has no velocity columns (an RTKLIB .pos with vn ve vu, or an aiding file of 11 columns: t lat lon h sigma_n sigma_e sigma_d v_n v_e v_d sigma_v)",
                        args.aid_use.as_deref().unwrap_or(""),
                        p.display()
                    );
                }
                if use_vel && args.zupt.is_some() {
                    bail!("--zupt and GNSS velocity aiding both give the velocity: choose one (--aid-use pos keeps --zupt)");
                }
                let fixes = fixes
                    .into_iter()
                    .map(|(p, v)| (p, if use_vel { v } else { None }))
                    .collect();
                AidPlan::Fixes(fixes, zupt, use_pos)
            }
            (None, Some(v)) if v.len() == 3 => {
                use sinsmodel::io::bounds;
                if let Some(p) = bounds::lat_deg(v[0])
                    .or_else(|| bounds::lon_deg(v[1]))
                    .or_else(|| bounds::height_m(v[2]))
                {
                    bail!("--static-aid: {p}");
                }
                AidPlan::Static {
                    fix: aiding::PositionFix {
                        t: 0.0,
                        lat: v[0].to_radians(),
                        lon: v[1].to_radians(),
                        h: v[2],
                        sigma: [0.1, 0.1, 0.1],
                    },
                    first_s: imu.first_t().floor() + 1.0,
                    zupt,
                }
            }
            (Some(_), Some(_)) => bail!("give --aid FILE or --static-aid LAT,LON,H, not both"),
            (None, Some(v)) => bail!(
                "--static-aid takes LAT,LON,H (3 numbers: deg, deg, m), got {}",
                v.len()
            ),
            (None, None) => bail!(
                "no aiding: give --aid FILE or --static-aid LAT,LON,H (the filter works on innovations)"
            ),
        };
        let mut truth_reader = match &args.truth {
            Some(p) => Some(truth::TruthReader::open(p)?),
            None => None,
        };
        let step_s = match step {
            Some(s) if s < 0.999 * imu.interval() => bail!(
                "--step {s} s is shorter than the IMU's median sample interval ({:.6} s); give --step {:.6} or more",
                imu.interval(),
                imu.interval()
            ),
            Some(s) => s,
            None => DEFAULT_STEP_S.max(imu.interval()),
        };
        let mut outages = Vec::new();
        for o in &args.outage {
            let v: Vec<f64> = o
                .split(',')
                .map(|x| x.trim().parse::<f64>())
                .collect::<std::result::Result<_, _>>()
                .map_err(|_| {
                    anyhow::anyhow!(
                        "--outage `{}`: expected START,DURATION in seconds",
                        sinsmodel::io::lines::shown(o)
                    )
                })?;
            if v.len() != 2
                || !v.iter().all(|x| x.is_finite())
                || v[0] < 0.0
                || v[1] <= 0.0
                || v[0] + v[1] > 1e7
            {
                bail!(
                    "--outage `{}`: expected START,DURATION in seconds (START >= 0 from the first IMU sample, DURATION > 0)",
                    sinsmodel::io::lines::shown(o)
                );
            }
            let start_s = imu.first_t() + v[0];
            outages.push(Outage {
                start_s,
                end_s: start_s + v[1],
            });
        }
        outages.sort_by(|a, b| a.start_s.total_cmp(&b.start_s));
        if let Some(w) = outages.windows(2).find(|w| w[1].start_s < w[0].end_s) {
            bail!(
                "--outage: the windows {:.3} .. {:.3} s and {:.3} .. {:.3} s overlap: give each outage once (one window from the first start to the last end)",
                w[0].start_s,
                w[0].end_s,
                w[1].start_s,
                w[1].end_s
            );
        }
        let d = std::f64::consts::PI / 180.0;
        let init_values: Option<Vec<f64>> = match args.init.as_deref() {
            None | Some("auto") => None,
            Some(text) => Some(
                text.split(',')
                    .map(|x| x.trim().parse::<f64>())
                    .collect::<std::result::Result<_, _>>()
                    .map_err(|_| {
                        anyhow::anyhow!(
                            "--init `{}`: expected auto or lat,lon,h,roll,pitch,yaw[,vn,ve,vd] (numbers, deg, m, m/s)",
                            sinsmodel::io::lines::shown(text)
                        )
                    })?,
            ),
        };
        let auto = args.init.as_deref() == Some("auto");
        if args.init_speed.is_some() && !auto {
            bail!("--init-speed applies to --init auto");
        }
        let mut init_sigma = None;
        let mut skipped = 0u64;
        let start = match (&init_values, &mut truth_reader) {
            _ if auto => {
                let found = self.auto_init(&fixes, &outages)?;
                for line in &found.report {
                    eprintln!("init auto: {line}");
                }
                init_sigma = Some((found.sigma_tilt, found.sigma_yaw));
                // the run starts after the start's sample
                skipped = imu.skip_through(found.state.t + 1e-9)?;
                if skipped > 0 {
                    eprintln!(
                        "init auto: {skipped} IMU samples before {:.3} s skipped",
                        found.state.t
                    );
                }
                found.state
            }
            (Some(v), _) => {
                if v.len() != 6 && v.len() != 9 {
                    bail!(
                        "--init takes lat,lon,h,roll,pitch,yaw[,vn,ve,vd] (6 or 9 numbers), got {}",
                        v.len()
                    );
                }
                let names = ["lat", "lon", "h", "roll", "pitch", "yaw", "vn", "ve", "vd"];
                let ranges = [
                    (-90.0, 90.0, "deg"),
                    (-360.0, 360.0, "deg"),
                    (-1000.0, 50_000.0, "m"),
                    (-180.0, 180.0, "deg"),
                    (-90.0, 90.0, "deg"),
                    (-360.0, 360.0, "deg"),
                    (-1000.0, 1000.0, "m/s"),
                    (-1000.0, 1000.0, "m/s"),
                    (-1000.0, 1000.0, "m/s"),
                ];
                for (k, x) in v.iter().enumerate() {
                    let (lo, hi, unit) = ranges[k];
                    if !(x.is_finite() && (lo..=hi).contains(x)) {
                        bail!("--init: {} = {x} is outside [{lo}, {hi}] {unit}", names[k]);
                    }
                }
                if v[0].abs() >= 89.9 {
                    bail!(
                        "--init: lat = {} is at a pole (|lat| < 89.9 deg): the navigation frame is not defined there",
                        v[0]
                    );
                }
                let c = dcm_from_euler(v[3] * d, v[4] * d, v[5] * d);
                NavState {
                    t: t0,
                    lat: v[0] * d,
                    lon: v[1] * d,
                    h: v[2],
                    v: if v.len() == 9 {
                        Vector3::new(v[6], v[7], v[8])
                    } else {
                        Vector3::zeros()
                    },
                    q: UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(c)),
                }
            }
            (None, Some(tr)) => {
                // the truth row at the start of the first sample's interval: t0 on a uniform
                // clock; on a jittered one the first sample may span other than the median
                // interval, so the row closest to t0 within 2.5 intervals before the first
                // sample is taken (and the run starts at its time)
                let r = match tr.at(t0, 1e-6)? {
                    Some(r) => r,
                    None => {
                        let p = args.truth.as_ref().expect("a truth reader has a path");
                        let mut scan = truth::TruthReader::open(p)?;
                        let (lo, first) = (imu.first_t() - 2.5 * imu.interval(), imu.first_t());
                        let mut best: Option<TruthRow> = None;
                        while let Some(r) = scan.next_row()? {
                            if r.t >= first - 1e-9 {
                                break;
                            }
                            if r.t >= lo && best.is_none_or(|b| (r.t - t0).abs() < (b.t - t0).abs())
                            {
                                best = Some(r);
                            }
                        }
                        let r = best.with_context(|| {
                            format!(
                                "no truth row at the IMU start ({t0:.6} s, or within 2.5 sample intervals before the first sample at {first:.6} s); give --init"
                            )
                        })?;
                        // the lookups of the run start from there
                        tr.at(r.t, 1e-6)?;
                        r
                    }
                };
                let c = dcm_from_euler(r.euler.x, r.euler.y, r.euler.z);
                NavState {
                    t: r.t,
                    lat: r.lat,
                    lon: r.lon,
                    h: r.h,
                    v: r.v,
                    q: UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(c)),
                }
            }
            (None, None) => bail!("give --init or --truth for the initial state"),
        };
        let t0 = start.t;
        if let Some(o) = outages.iter().find(|o| o.end_s <= t0 + 1e-9) {
            bail!(
                "--outage: the window {:.3} .. {:.3} s ends before the run starts ({t0:.3} s{}): there is no drift to measure",
                o.start_s,
                o.end_s,
                if auto { ", where --init auto found its start" } else { "" }
            );
        }
        let e = start.euler();
        let (roll, pitch) = (e.x, e.y);
        let head = sinsmodel::io::imu::ImuData {
            samples: imu.head().to_vec(),
        };
        // magnitudes before anything is run on them: a unit, scale or clock slip (deg/s as
        // rad/s, g as m/s², ms as s) gives plausible-looking nonsense downstream
        let check = sinsmodel::estimate::imu_check::check(&head, Some(start.lat), 0.0, 10.0, true);
        // a MEMS gyro's bias can reach what a unit slip gives: with --grade mems a warning
        let mems = args.grade.as_deref() == Some("mems");
        for p in check.gyro_unit_problems.iter().filter(|_| mems) {
            eprintln!(
                "warning: --imu {}: {p} (or a MEMS gyro's bias: --grade mems given)",
                imu_path.display()
            );
        }
        let slips: Vec<&String> = check
            .unit_problems
            .iter()
            .chain(check.gyro_unit_problems.iter().filter(|_| !mems))
            .collect();
        if let Some(p) = slips.first() {
            if args.force {
                eprintln!("warning: --imu {}: {p} (--force given)", imu_path.display());
            } else {
                bail!(
                    "--imu {}: {p} (in the first 10 s; `sinsmodel imu-check` shows what was read; --force runs anyway)",
                    imu_path.display()
                );
            }
        }
        if let Some(p) =
            sinsmodel::estimate::align::attitude_contradicts_gravity(&head, roll, pitch)
                .filter(|_| !auto)
        {
            if args.force {
                eprintln!("warning: {p} (--force given)");
            } else {
                bail!("{}{p}", if args.init.is_some() { "--init: " } else { "" });
            }
        }
        drop(head);
        if let AidPlan::Fixes(fixes, _, _) = &fixes {
            let fixes: Vec<&aiding::PositionFix> = fixes.iter().map(|f| &f.0).collect();
            let after = fixes.iter().filter(|f| f.t > t0).count();
            if after < 10 {
                bail!(
                    "only {after} of {} aiding epochs come after the IMU start ({t0:.3} s); at least 10 are needed (the filter works on innovations)",
                    fixes.len()
                );
            }
            // the initial position and the first aiding fix must describe the same place
            if let Some(f) = fixes.iter().find(|f| f.t > t0) {
                let dn = (f.lat - start.lat) * 6.371e6;
                let de = (f.lon - start.lon) * 6.371e6 * start.lat.cos();
                let dist = dn.hypot(de);
                if dist > 20_000.0 {
                    bail!(
                        "the initial position is {:.1} km from the first aiding fix (t = {:.3} s): check --init / --static-aid / --aid",
                        dist / 1000.0,
                        f.t
                    );
                }
            }
        }
        if let AidPlan::Static { fix, .. } = &fixes {
            let dn = (fix.lat - start.lat) * 6.371e6;
            let de = (fix.lon - start.lon) * 6.371e6 * start.lat.cos();
            if dn.hypot(de) > 20_000.0 {
                bail!(
                    "the initial position is {:.1} km from the first aiding fix (--static-aid): check --init / --static-aid",
                    dn.hypot(de) / 1000.0
                );
            }
        }
        Ok(Opened {
            imu,
            aid: fixes.after(t0),
            truth: truth_reader,
            start,
            outages,
            init_sigma,
            skipped_samples: skipped,
            step_s,
        })
    }

    /// `--step` when given, checked: in (0, 10] s.
    fn step_given(&self) -> Result<Option<f64>> {
        match self.step {
            Some(s) if !(s.is_finite() && s > 0.0 && s <= 10.0) => {
                bail!("--step {s}: expected a filter step in (0, 10] s")
            }
            s => Ok(s),
        }
    }

    /// `--init auto`: reads the IMU file from its start (a second pass, memory bounded by
    /// quarter-second means) until [`init::find`] decides.
    fn auto_init(
        &self,
        plan: &AidPlan,
        outages: &[Outage],
    ) -> Result<sinsmodel::estimate::init::AutoInit> {
        use sinsmodel::estimate::init::{self, Blocks, Fix, Found, Priors};
        let speed = self.init_speed.unwrap_or(init::DEFAULT_SPEED);
        if !(speed.is_finite() && (0.5..=100.0).contains(&speed)) {
            bail!("--init-speed {speed}: expected a speed in [0.5, 100] m/s");
        }
        // the bias priors the run will use (grade, --prior)
        let m = Model::parse("P28")?;
        let cfg = self.config(&m, true)?;
        let prior = |name: &str| m.index_of(name).map(|i| cfg.prior_sigma[i]);
        let priors = Priors {
            gyro_bias: prior("eps_x").context("P28 has eps_x")?,
            accel_bias: prior("nabla_x").context("P28 has nabla_x")?,
            speed,
            gyro_scale: prior("kg_33").context("P28 has kg_33")?,
        };
        // fixes inside a --outage are not used to start either
        let outside = |t: f64| !outages.iter().any(|o| o.contains(t));
        let (mut fixes, static_pos, receiver) = match plan {
            AidPlan::Fixes(list, _, _) => {
                let kept: Vec<_> = list.iter().filter(|(p, _)| outside(p.t)).collect();
                (
                    kept.iter()
                        .map(|(p, v)| Fix {
                            t: p.t,
                            pos: [p.lat, p.lon, p.h],
                            sigma_pos: p.sigma[0].max(p.sigma[1]),
                            v: v.map(|v| Vector3::from(v.v_ned)),
                            sigma_v: v.map(|v| v.sigma).unwrap_or(0.0),
                            derived: false,
                        })
                        .collect::<Vec<_>>(),
                    None,
                    kept.iter().map(|(_, v)| v.is_some()).collect::<Vec<_>>(),
                )
            }
            AidPlan::Static { fix, .. } => {
                (Vec::new(), Some([fix.lat, fix.lon, fix.h]), Vec::new())
            }
        };
        init::check_velocities(&fixes, &receiver)?;
        init::velocities_from_positions(&mut fixes);
        let imu_path = self.imu.as_ref().context("--imu FILE is required")?;
        let (mut stream, _) = sinsmodel::io::imu_stream::ImuStream::open_with(
            imu_path,
            self.imu_format.as_deref(),
            self.clock_offset,
        )?;
        let dt = stream.interval();
        let mut blocks = Blocks::default();
        let mut next_look = 10.0;
        loop {
            let s = stream.next()?;
            if let Some(s) = &s {
                blocks.push(s, dt);
                if blocks.seconds() < next_look {
                    continue;
                }
                next_look = blocks.seconds() + 10.0;
            }
            match init::find(&blocks.blocks, &fixes, static_pos, priors, s.is_none())? {
                Found::Done(a) => return Ok(*a),
                Found::NeedMore if s.is_none() => {
                    let imu_span = match (blocks.blocks.first(), blocks.blocks.last()) {
                        (Some(a), Some(b)) => format!("{:.3} .. {:.3} s", a.t_start, b.t_end),
                        _ => "none".to_string(),
                    };
                    let fix_span = match (fixes.first(), fixes.last()) {
                        (Some(a), Some(b)) => format!("{:.3} .. {:.3} s", a.t, b.t),
                        _ => "none".to_string(),
                    };
                    bail!(
                        "--init auto: the IMU data end before a start is found (IMU {imu_span}, GNSS fixes {fix_span}: on the same clock?)"
                    )
                }
                Found::NeedMore => {}
            }
        }
    }

    /// The filter configuration for `model`: mode, step, vertical channel, `--prior` and
    /// `--noise`. With `lenient_priors`, a `--prior` naming no state of this model is skipped
    /// (explain applies the same priors to the baseline and to extended models).
    pub fn config(&self, model: &Model, lenient_priors: bool) -> Result<FilterConfig> {
        let args = self;
        let mut cfg = FilterConfig::new(model);
        if let Some(g) = grade_table(args.grade.as_deref())? {
            priors::apply_grade(model, g, &mut cfg.prior_sigma);
            cfg = cfg.with_sensor_noise(model, g.gyro_arw, g.accel_vrw);
        }
        cfg.mode = match args.mode.as_str() {
            "open" => Mode::OpenLoop,
            "closed" => Mode::ClosedLoop,
            m => bail!("--mode `{m}`: expected open or closed"),
        };
        cfg.step_s = args.step_given()?.unwrap_or(DEFAULT_STEP_S);
        cfg.known_gnss = args.known_gnss()?;
        if !args.has_gnss() {
            if let Some(t) = model.states.iter().find_map(|s| match *s {
                sinsmodel::model::catalog::StateRef::Term(k)
                    if common::TERMS[k].sensor == sinsmodel::model::catalog::Sensor::Gnss =>
                {
                    Some(common::TERMS[k].name)
                }
                _ => None,
            }) {
                bail!("--model {}: {t} is a GNSS term (it enters the fixes of a GNSS receiver); without --aid there is none", model.name);
            }
        }
        if !model.vertical {
            cfg.vertical = Vertical::Fixed;
        }
        for spec in &args.prior {
            let (name, value) = spec
                .split_once('=')
                .with_context(|| format!("--prior `{spec}`: expected NAME=QUANTITY"))?;
            let (name, value) = (name.trim(), value.trim());
            let pattern = StatePattern::new(name);
            let matches: Vec<usize> = (0..model.n())
                .filter(|&i| pattern.matches(model.names[i]))
                .collect();
            if matches.is_empty() && !lenient_priors {
                bail!(
                    "--prior `{spec}`: no state `{name}` in model {}",
                    model.name
                );
            }
            for i in matches {
                let si = sinsmodel::io::units::parse_quantity_as(value, model.unit(i))
                    .map_err(|e| anyhow::anyhow!("--prior `{spec}`: {e}"))?;
                if !(si.is_finite() && si > 0.0) {
                    bail!("--prior `{spec}`: a prior σ must be positive and finite");
                }
                if let sinsmodel::model::catalog::StateRef::Term(t) = model.states[i] {
                    let info = &sinsmodel::model::generated::common::TERMS[t];
                    if let Some(why) = info.beyond_limit(si) {
                        bail!("--prior `{spec}`: {}: {why}", info.name);
                    }
                }
                cfg.prior_sigma[i] = si;
            }
        }
        if let Some(path) = &args.noise {
            let (arw, vrw) = noise_from_allan(path)?;
            cfg = cfg.with_sensor_noise(model, arw, vrw);
        }
        Ok(cfg)
    }
}

/// Gyro ARW [rad/√s] and accelerometer VRW [m/s/√s] from `--noise`: inline
/// `arw=Q, vrw=Q` with units, or an `allan --json` file (the mean over the three axes).
pub fn noise_from_allan(path: &std::path::Path) -> Result<(f64, f64)> {
    let text = path.to_string_lossy();
    if text.contains('=') && !path.exists() {
        return noise_inline(&text);
    }
    let text = sinsmodel::io::lines::read_small_text(path, "--noise")
        .with_context(|| format!("--noise {}: cannot read the file", path.display()))?;
    let v: serde_json::Value = serde_json::from_str(&text).with_context(|| {
        format!(
            "--noise {}: not valid JSON (expected the output of `sinsmodel allan --json`)",
            path.display()
        )
    })?;
    let white = |names: [&str; 3]| -> Result<f64> {
        let mut s = 0.0;
        for n in names {
            let field = &v["fit"][n]["white"];
            let w = field.as_f64().with_context(|| {
                format!(
                    "--noise {}: fit.{n}.white {} (expected a number: the output of `sinsmodel allan --json`)",
                    path.display(),
                    if field.is_null() { "is missing or null (the fit was not determined)".to_string() } else { format!("is {field}, not a number") }
                )
            })?;
            let (min, max) = noise_range(n.starts_with("gyro"));
            if !(w.is_finite() && w >= min && w <= max) {
                bail!(
                    "--noise {}: fit.{n}.white = {w} is not a plausible noise density ({min:e} ≤ w ≤ {max} SI: rad/√s for gyros, m/s/√s for accelerometers)",
                    path.display()
                );
            }
            s += w * w;
        }
        Ok((s / 3.0).sqrt())
    };
    Ok((
        white(["gyro_x", "gyro_y", "gyro_z"])?,
        white(["accel_x", "accel_y", "accel_z"])?,
    ))
}

/// `arw=0.3 deg/sqrt(h), vrw=150 ug/sqrt(Hz)`: both required, each checked like the file's.
fn noise_inline(text: &str) -> Result<(f64, f64)> {
    let (mut arw, mut vrw) = (None, None);
    for part in text.split(',').map(str::trim).filter(|p| !p.is_empty()) {
        let (k, v) = part
            .split_once('=')
            .with_context(|| format!("--noise `{part}`: expected arw=QUANTITY or vrw=QUANTITY"))?;
        let (slot, unit, (min, max)) = match k.trim() {
            "arw" => (&mut arw, "rad/sqrt(s)", noise_range(true)),
            "vrw" => (&mut vrw, "m/s/sqrt(s)", noise_range(false)),
            other => bail!("--noise: unknown key `{other}` (arw, vrw)"),
        };
        let q = sinsmodel::io::units::parse_quantity_as(v, unit)
            .map_err(|e| anyhow::anyhow!("--noise {}: {}", k.trim(), e.0))?;
        if !(q.is_finite() && q >= min && q <= max) {
            bail!(
                "--noise {}: {} is not a plausible noise density ({min:e} ..= {max} {unit})",
                k.trim(),
                v.trim()
            );
        }
        *slot = Some(q);
    }
    match (arw, vrw) {
        (Some(a), Some(v)) => Ok((a, v)),
        _ => bail!("--noise `{text}`: give both arw and vrw, e.g. 'arw=0.3 deg/sqrt(h), vrw=150 ug/sqrt(Hz)'"),
    }
}

/// Plausible white-noise densities (SI): gyro ARW 1e-9 ..= 1 rad/√s (the best ring-laser gyros
/// are near 3e-7), accelerometer VRW 1e-7 ..= 100 m/s/√s (0.01 µg/√Hz upward).
fn noise_range(gyro: bool) -> (f64, f64) {
    if gyro {
        (1e-9, 1.0)
    } else {
        (1e-7, 100.0)
    }
}
