//! The data options of the commands that read data, as a library value: the IMU file and how
//! to read it ([`ImuSource`]), and everything `filter` and `explain` share ([`DataOptions`]:
//! IMU, aiding, truth, initial state, priors, noise, mode, step, ZUPT, outages, known GNSS
//! values). With the `cli` feature they are also the command line's options, so a field's doc
//! comment is its `--help` text.

use crate::io::imu::ImuData;
use crate::io::imu_stream::ImuStream;
use anyhow::Result;
use std::path::{Path, PathBuf};

/// The files read beside an IMU file: its format description and a GNSS_IMU csv's clock file.
fn read_beside(imu: &Path) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = crate::io::imu_format::beside(imu).into_iter().collect();
    v.push(imu.with_extension("csv.tag"));
    v
}

/// The IMU file and how to read it: the options of `navigate`, `align`, `allan`, `imu-check`.
#[cfg_attr(feature = "cli", derive(clap::Args))]
#[derive(Clone, Debug)]
pub struct ImuSource {
    /// IMU file (text, PSINS .imu, FILE.mat:VARIABLE of PSINS [wm vm t], GNSS_IMU .csv, or any
    /// layout --imu-format describes).
    #[cfg_attr(feature = "cli", arg(long))]
    pub imu: PathBuf,
    /// IMU format description (TOML, docs/formats.md); default: FILE.format.toml beside the
    /// IMU file if there is one, else chosen by the file's extension.
    #[cfg_attr(feature = "cli", arg(long))]
    pub imu_format: Option<PathBuf>,
    /// GPST − IMU clock [s] for a GNSS_IMU .csv without its .tag file (0 keeps the IMU clock).
    #[cfg_attr(feature = "cli", arg(long, allow_hyphen_values = true))]
    pub clock_offset: Option<f64>,
}

impl ImuSource {
    /// Reads the IMU file; `note` hears which format was used.
    pub fn read(&self, note: &mut dyn FnMut(&str)) -> Result<ImuData> {
        self.open(note)?.collect()
    }

    /// Opens the IMU file as a stream of validated samples; `note` hears which format was used.
    pub fn open(&self, note: &mut dyn FnMut(&str)) -> Result<ImuStream> {
        open_imu(
            &self.imu,
            self.imu_format.as_deref(),
            self.clock_offset,
            note,
        )
    }

    /// The input files (so outputs never land on them).
    pub fn paths(&self) -> Vec<PathBuf> {
        let mut v = vec![crate::io::readers::matlab::file_of(&self.imu)];
        v.extend(self.imu_format.clone());
        v.extend(read_beside(&self.imu));
        v
    }

    /// Refuses an output file that is one of the inputs or not a regular file, and (unless
    /// `overwrite`) one that is another run's result or not provably this command's earlier output.
    pub fn check_output(
        &self,
        option: &str,
        path: &Path,
        provenance: crate::io::atomic_file::Provenance,
        overwrite: bool,
    ) -> Result<()> {
        let inputs = self.paths();
        let refs: Vec<&Path> = inputs.iter().map(|p| p.as_path()).collect();
        crate::io::atomic_file::check_output_file(option, path, &refs, provenance, overwrite)
    }
}

/// Opens an IMU file as a stream of validated samples; `note` hears "reading FILE as …".
pub fn open_imu(
    imu: &Path,
    format: Option<&Path>,
    clock_offset: Option<f64>,
    note: &mut dyn FnMut(&str),
) -> Result<ImuStream> {
    let (stream, how) = ImuStream::open_with(imu, format, clock_offset)?;
    note(&crate::io::lines::printable_message(&format!(
        "reading {} {how}",
        imu.display()
    )));
    Ok(stream)
}

/// The data options of `filter` and `explain`.
#[cfg_attr(feature = "cli", derive(clap::Args))]
#[derive(Clone, Debug)]
pub struct DataOptions {
    /// IMU file (text, PSINS .imu, FILE.mat:VARIABLE of PSINS [wm vm t], GNSS_IMU .csv, or any
    /// layout --imu-format describes).
    #[cfg_attr(feature = "cli", arg(long))]
    pub imu: Option<PathBuf>,
    /// IMU format description (TOML, docs/formats.md); default: FILE.format.toml beside the
    /// IMU file if there is one, else chosen by the file's extension.
    #[cfg_attr(feature = "cli", arg(long))]
    pub imu_format: Option<PathBuf>,
    /// GPST − IMU clock [s] for a GNSS_IMU .csv without its .tag file (0 keeps the IMU clock).
    #[cfg_attr(feature = "cli", arg(long, allow_hyphen_values = true))]
    pub clock_offset: Option<f64>,
    /// Position aiding file (t lat lon h sigma_n sigma_e sigma_d), or an RTKLIB `.pos` solution.
    #[cfg_attr(feature = "cli", arg(long))]
    pub aid: Option<PathBuf>,
    /// Which parts of the aiding file to use: pos, vel or pos,vel (default: all the file has; an
    /// RTKLIB .pos with vn ve vu, or an 11-column aiding file, has velocities).
    #[cfg_attr(feature = "cli", arg(long))]
    pub aid_use: Option<String>,
    /// A static vehicle at a known position: lat,lon [deg],h [m]; position updates (σ 0.1 m) and
    /// zero-velocity updates (σ from --zupt, default 0.01 m/s) at 1 Hz instead of --aid.
    #[cfg_attr(
        feature = "cli",
        arg(long, value_delimiter = ',', allow_hyphen_values = true)
    )]
    pub static_aid: Option<Vec<f64>>,
    /// Prior 1-σ of a state, NAME=QUANTITY with units (repeatable); a trailing `*` matches a
    /// prefix: `--prior 'eps_*=1 deg/s' --prior 'nabla_*=20 mg' --prior 'phi_d=5 deg'`. The most
    /// specific wins whatever the order (`eps_x=…` over `eps_*=…`, a longer prefix over a
    /// shorter); a name given twice is refused; attitude priors (phi_*) below 90 deg.
    #[cfg_attr(feature = "cli", arg(long))]
    pub prior: Vec<String>,
    /// Sensor white noise instead of the spec defaults: a `sinsmodel allan --json` file (the RMS
    /// over the three axes of the gyros' ARW, and of the accelerometers' VRW; `fit.*.white` in
    /// the units its `units` names, SI without them; a key twice is refused), or inline with units:
    /// `'arw=0.3 deg/sqrt(h), vrw=150 ug/sqrt(Hz)'`; inline may add a bias random walk (bias
    /// instability) `gyro_bias_rw=10 deg/h/sqrt(h), accel_bias_rw=30 ug/sqrt(s)`, which explain
    /// then tests as noise levels too.
    #[cfg_attr(feature = "cli", arg(long))]
    pub noise: Option<PathBuf>,
    /// Truth file (t lat lon h vn ve vd roll pitch yaw), or a PSINS reference FILE.mat:avp: adds
    /// the true φ and the model error.
    #[cfg_attr(feature = "cli", arg(long))]
    pub truth: Option<PathBuf>,
    /// Initial lat,lon [deg],h [m],roll,pitch,yaw [deg][,vn,ve,vd m/s], or `auto`: level from
    /// the first seconds at rest, heading by gyrocompassing (when the grade allows) or from the
    /// GNSS course of the drive-off, or from the course at a moving start (docs/real-data.md);
    /// default: the first truth row.
    #[cfg_attr(feature = "cli", arg(long, allow_hyphen_values = true))]
    pub init: Option<String>,
    /// With `--init auto`: the GNSS speed [m/s] above which the course gives the heading
    /// [default: 3].
    #[cfg_attr(feature = "cli", arg(long, allow_hyphen_values = true))]
    pub init_speed: Option<f64>,
    /// open (errors estimated only) or closed (fed back) [default: open; closed with
    /// --body-velocity or --attitude, whose rows open loop would linearise about the
    /// free-inertial solution].
    #[cfg_attr(feature = "cli", arg(long))]
    pub mode: Option<String>,
    /// Filter step [s] [default: 0.01, or the IMU's median interval when that is longer].
    #[cfg_attr(feature = "cli", arg(long, allow_hyphen_values = true))]
    pub step: Option<f64>,
    /// Zero-velocity updates with this σ [m/s] at every aiding epoch (vehicle at rest).
    #[cfg_attr(feature = "cli", arg(long, allow_hyphen_values = true))]
    pub zupt: Option<f64>,
    /// Run even when the initial roll and pitch contradict the measured gravity direction or the
    /// first seconds' magnitudes look like a unit slip; it never replaces an output file.
    #[cfg_attr(feature = "cli", arg(long))]
    pub force: bool,
    /// Sensor grade the priors and noise assume: navigation (the spec's defaults), tactical or
    /// mems; --prior and --noise override single values.
    #[cfg_attr(feature = "cli", arg(long))]
    pub grade: Option<String>,
    /// A GNSS outage: START,DURATION [s], START counted from the first IMU sample (not the
    /// data's clock, which may be absolute GPS seconds; `--init auto` prints its start both
    /// ways); the aiding epochs inside are dropped and the drift at its end is reported
    /// (repeatable).
    #[cfg_attr(feature = "cli", arg(long, allow_hyphen_values = true))]
    pub outage: Vec<String>,
    /// Known IMU–GNSS time offset with its unit (`92 ms`, `0.092 s`): a fix stamped t is the
    /// trajectory at t + OFFSET (the spec term dt_gnss), applied by re-stamping the fixes
    /// (exact, where the term's H is first order); needs --aid.
    #[cfg_attr(feature = "cli", arg(long, allow_hyphen_values = true))]
    pub gnss_delay: Option<String>,
    /// Known GNSS antenna lever arm, IMU to antenna in the body frame (FRD): X,Y,Z [m] (the spec
    /// terms lever_x lever_y lever_z), applied in the residuals; needs --aid.
    #[cfg_attr(
        feature = "cli",
        arg(long, value_delimiter = ',', allow_hyphen_values = true)
    )]
    pub lever_arm: Option<Vec<String>>,
    /// Body-frame velocity reference (odometer with the non-holonomic constraint, DVL): a file
    /// of `t vx vy vz sigma` (s on the IMU's clock; forward, right, down m/s; m/s), used as
    /// the `vel_body` measurement (needs a model with +vertical).
    #[cfg_attr(feature = "cli", arg(long))]
    pub body_velocity: Option<PathBuf>,
    /// Known mounting of the velocity reference against the IMU body frame: ROLL,PITCH,YAW
    /// [deg] (the spec terms mount_x mount_y mount_z; a unit may be given, `26 mrad`), applied
    /// in the residuals; needs --body-velocity.
    #[cfg_attr(
        feature = "cli",
        arg(long, value_delimiter = ',', allow_hyphen_values = true)
    )]
    pub mounting: Option<Vec<String>>,
    /// Attitude reference (a second INS, an AHRS): a file of `t roll pitch yaw sigma_tilt
    /// sigma_yaw` (s on the IMU's clock; z-y-x Euler angles of the reference frame's FRD axes
    /// against NED, deg, yaw -180..360; deg), used as the `att_ref` measurement.
    #[cfg_attr(feature = "cli", arg(long))]
    pub attitude: Option<PathBuf>,
}

impl DataOptions {
    /// Options with nothing given (the command line's defaults).
    pub fn none() -> DataOptions {
        DataOptions {
            imu: None,
            imu_format: None,
            clock_offset: None,
            aid: None,
            aid_use: None,
            static_aid: None,
            prior: Vec::new(),
            noise: None,
            truth: None,
            init: None,
            init_speed: None,
            mode: None,
            step: None,
            zupt: None,
            force: false,
            grade: None,
            outage: Vec::new(),
            gnss_delay: None,
            lever_arm: None,
            body_velocity: None,
            mounting: None,
            attitude: None,
        }
    }

    /// True when any data option was given (explain runs its embedded demo when none is).
    pub fn any_given(&self) -> bool {
        !self.given_names().is_empty()
    }

    /// The data options given, as spelled on the command line (`--mode`, `--step` and
    /// `--init-speed` are not among them: the demo reads the first two).
    pub fn given_names(&self) -> Vec<&'static str> {
        [
            (self.imu.is_some(), "--imu"),
            (self.imu_format.is_some(), "--imu-format"),
            (self.clock_offset.is_some(), "--clock-offset"),
            (self.aid.is_some(), "--aid"),
            (self.aid_use.is_some(), "--aid-use"),
            (self.static_aid.is_some(), "--static-aid"),
            (!self.prior.is_empty(), "--prior"),
            (self.noise.is_some(), "--noise"),
            (self.truth.is_some(), "--truth"),
            (self.init.is_some(), "--init"),
            (self.zupt.is_some(), "--zupt"),
            (self.force, "--force"),
            (self.grade.is_some(), "--grade"),
            (!self.outage.is_empty(), "--outage"),
            (self.gnss_delay.is_some(), "--gnss-delay"),
            (self.lever_arm.is_some(), "--lever-arm"),
            (self.body_velocity.is_some(), "--body-velocity"),
            (self.mounting.is_some(), "--mounting"),
            (self.attitude.is_some(), "--attitude"),
        ]
        .into_iter()
        .filter_map(|(given, name)| given.then_some(name))
        .collect()
    }

    /// True when the aiding comes from a GNSS file (`--aid`): GNSS terms (time offset, lever
    /// arm) mean something only then.
    pub fn has_gnss(&self) -> bool {
        self.aid.is_some()
    }

    /// The input files named by the options (so outputs never land on them).
    pub fn input_paths(&self) -> Vec<PathBuf> {
        [
            &self.imu,
            &self.imu_format,
            &self.aid,
            &self.noise,
            &self.truth,
            &self.body_velocity,
            &self.attitude,
        ]
        .into_iter()
        .flatten()
        .map(|p| crate::io::readers::matlab::file_of(p))
        .chain(self.imu.iter().flat_map(|i| read_beside(i)))
        .collect()
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
        if let Some(p) = &self.body_velocity {
            s.push_str(&format!(", body-velocity reference {}", p.display()));
        }
        if let Some(p) = &self.attitude {
            s.push_str(&format!(", attitude reference {}", p.display()));
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
        if let Some(m) = &self.mounting {
            s.push_str(&format!(
                ", known reference mounting {} (deg, roll pitch yaw)",
                m.join(",")
            ));
        }
        s
    }

    /// The IMU file, which every run on data needs.
    pub fn imu_path(&self) -> Result<&Path> {
        use anyhow::Context;
        self.imu.as_deref().context("--imu FILE is required")
    }
}
