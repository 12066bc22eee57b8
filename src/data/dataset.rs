//! A data set opened for a run: the IMU stream, the aiding plan, truth, the outages and the
//! start, everything checked that can be before the run ([`DataOptions::open`]); and the same
//! loaded once for a command that passes over the data several times ([`DataOptions::load_for_passes`]).

use super::aid::{AidPlan, Outage};
use super::DataOptions;
use crate::estimate::filter::AidingEpoch;
use crate::io::aiding::{AttitudeFix, BodyVelocityFix, PositionFix};
use crate::io::imu_stream::ImuStream;
use crate::io::truth::{self, TruthRow};
use crate::nav::earth;
use crate::nav::strapdown::NavState;
use anyhow::{bail, Result};
use std::path::PathBuf;

/// Default filter step [s].
pub const DEFAULT_STEP_S: f64 = 0.01;

/// The data options opened for one streamed pass.
pub struct Dataset {
    /// IMU samples, validated as they are read.
    pub imu: ImuStream,
    /// Aiding epochs after the start.
    pub aid: AidPlan,
    /// Rows of the body-velocity reference after the start (`--body-velocity`), time order.
    pub body_velocity: Vec<BodyVelocityFix>,
    /// Rows of the attitude reference after the start (`--attitude`), time order.
    pub attitude: Vec<AttitudeFix>,
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

/// What the data options load for a command that passes over the data more than once: the IMU
/// file (read again on every pass), aiding epochs, truth, the initial state.
pub struct PassInputs {
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

/// With a reference file (`path`, given as `option`: `--body-velocity`, `--attitude`), at least
/// 10 of its rows must have been used inside the IMU data (t0, t_last] [s]: `used` were.
pub fn check_reference_inside(
    option: &str,
    path: Option<&std::path::Path>,
    used: usize,
    t0: f64,
    t_last: f64,
) -> Result<()> {
    if let Some(p) = path {
        if used < 10 {
            bail!(
                "{option} {}: only {used} of its rows fall inside the IMU data ({t0:.3} to {t_last:.3} s); at least 10 are needed (its times must be on the IMU's clock: GPS seconds against the IMU's, or ms for s?)",
                p.display()
            );
        }
    }
    Ok(())
}

/// Horizontal distance [m] between two positions (lat, lon in rad) on the WGS-84 ellipsoid at
/// the first one's latitude and height `h` [m] (a local flat approximation: enough to tell the
/// same place from another town).
fn horizontal_distance_m(lat: f64, lon: f64, h: f64, lat2: f64, lon2: f64) -> f64 {
    let dn = (lat2 - lat) * (earth::radius_meridian(lat) + h);
    let de = earth::lon_difference(lon2, lon) * (earth::radius_transverse(lat) + h) * lat.cos();
    dn.hypot(de)
}

/// The GNSS motion between two consecutive fixes at most 2 s apart: the interval [s] and the
/// displacement north, east (flat, at the first fix) and up [m].
struct FixStep {
    /// First fix's time [s].
    t0: f64,
    /// Second fix's time [s].
    t1: f64,
    /// North displacement [m].
    dn: f64,
    /// East displacement [m].
    de: f64,
    /// Up displacement [m].
    du: f64,
}

impl FixStep {
    /// Mid time [s].
    fn t_mid(&self) -> f64 {
        0.5 * (self.t0 + self.t1)
    }
    /// Horizontal speed [m/s].
    fn horizontal_speed(&self) -> f64 {
        self.dn.hypot(self.de) / (self.t1 - self.t0)
    }
    /// Speed, with the vertical [m/s].
    fn speed(&self) -> f64 {
        self.dn.hypot(self.de).hypot(self.du) / (self.t1 - self.t0)
    }
    /// Course over ground, clockwise from north [rad].
    fn course(&self) -> f64 {
        self.de.atan2(self.dn)
    }
}

/// Each pair of consecutive fixes at most 2 s apart as a [`FixStep`].
fn fix_steps(fixes: &[(PositionFix, Option<crate::io::aiding::VelocityFix>)]) -> Vec<FixStep> {
    fixes
        .windows(2)
        .filter_map(|w| {
            let (a, b) = (&w[0].0, &w[1].0);
            let dt = b.t - a.t;
            (dt > 0.0 && dt <= 2.0).then(|| FixStep {
                t0: a.t,
                t1: b.t,
                dn: (b.lat - a.lat) * (earth::radius_meridian(a.lat) + a.h),
                de: earth::lon_difference(b.lon, a.lon)
                    * (earth::radius_transverse(a.lat) + a.h)
                    * a.lat.cos(),
                du: b.h - a.h,
            })
        })
        .collect()
}

/// The rows of a reference file (`option` `path`, `first`..`last` its time span [s]) after the
/// run's start `t0` [s]: at least 10 must be.
fn rows_after<R: super::aid::ReferenceRow>(
    option: &str,
    path: &std::path::Path,
    rows: Vec<R>,
    t0: f64,
) -> Result<Vec<R>> {
    let (first, last) = (rows[0].t(), rows[rows.len() - 1].t());
    let after: Vec<R> = rows.into_iter().filter(|r| r.t() > t0).collect();
    if after.len() < 10 {
        bail!(
            "{option} {}: {} of its rows (t = {first:.3} to {last:.3} s) fall after the run's start at t = {t0:.3} s; at least 10 are needed (its times must be on the IMU's clock: UTC for GPST, or ms for s?)",
            path.display(),
            after.len()
        );
    }
    Ok(after)
}

/// Most of a reference's rows (`option` `path`, times `times` [s], in order) must fall within
/// the GNSS fixes' times (±1 s), else another clock.
fn check_within_fixes(
    option: &str,
    path: &std::path::Path,
    times: &[f64],
    fixes: &[(PositionFix, Option<crate::io::aiding::VelocityFix>)],
) -> Result<()> {
    let (Some((p0, _)), Some((p1, _)), Some(&first), Some(&last)) =
        (fixes.first(), fixes.last(), times.first(), times.last())
    else {
        return Ok(());
    };
    let (f0, f1) = (p0.t, p1.t);
    let inside = times
        .iter()
        .filter(|&&t| t >= f0 - 1.0 && t <= f1 + 1.0)
        .count();
    if 2 * inside < times.len() {
        bail!(
            "{option} {}: {inside} of its {} rows after the start fall within the GNSS fixes' times (t = {f0:.3} to {f1:.3} s); its rows run t = {first:.3} to {last:.3} s: another clock (GPS seconds against the IMU's, UTC against GPST: 18 s) or ms written as s?",
            path.display(),
            times.len()
        );
    }
    Ok(())
}

impl DataOptions {
    /// Opens the IMU, aiding and truth files for one streamed pass and builds the initial
    /// state; everything that can be checked before the run is (the aiding epochs that fall
    /// inside the IMU data are counted after it: [`check_inside`]). `note` hears what is read
    /// and what `--init auto` found, and the warnings.
    pub fn open(&self, note: &mut dyn FnMut(&str)) -> Result<Dataset> {
        let step = self.step_given()?;
        let imu_path = self.imu_path()?;
        let mut imu = super::options::open_imu(
            imu_path,
            self.imu_format.as_deref(),
            self.clock_offset,
            note,
        )?;
        let mut plan = self.aid_plan(imu.first_t())?;
        check_fix_times(&plan, imu.first_t())?;
        let mut truth_reader = match &self.truth {
            Some(p) => Some(truth::TruthReader::open(p)?),
            None => None,
        };
        let step_s = match step {
            Some(s) => {
                DataOptions::check_step_interval(s, imu.interval(), "the IMU's median")?;
                s
            }
            None => DEFAULT_STEP_S.max(imu.interval()),
        };
        let outages = self.outages(imu.first_t())?;
        // the aiding clock is judged on every sample, those --init auto reads through included
        if let AidPlan::Fixes(list, _, _) = &plan {
            if let Some(c) =
                crate::estimate::clock_check::window_check(list, imu.head(), self.force)
            {
                imu.judge_windows(c);
            }
        }
        let start = self.start(&mut imu, &plan, &outages, truth_reader.as_mut(), note)?;
        let t0 = start.state.t;
        if let Some(o) = outages.iter().find(|o| o.end_s <= t0 + 1e-9) {
            bail!(
                "--outage: the window {} ends before the run starts ({}{}): there is no drift to measure",
                o.words(imu.first_t()),
                crate::io::aiding::time_from_first_sample(t0, imu.first_t()),
                if self.init_auto() { ", where --init auto found its start" } else { "" }
            );
        }
        self.check_head(&mut imu, &start.state, &plan, note)?;
        check_plan_at_start(&plan, &start.state, note)?;
        check_fixes(&mut plan, imu.first_t(), note)?;
        let aid = plan.after(t0);
        check_outages_drop_fixes(&aid, &outages, imu.first_t())?;
        let body_velocity = self.body_velocity_after(t0, &aid, note)?;
        let attitude = self.attitude_after(t0, &aid, note)?;
        Ok(Dataset {
            imu,
            aid,
            body_velocity,
            attitude,
            truth: truth_reader,
            start: start.state,
            outages,
            init_sigma: start.sigma,
            skipped_samples: start.skipped,
            step_s,
        })
    }

    /// Checks the first seconds of the IMU against the start: magnitudes before anything is run
    /// on them (a unit, scale or clock slip — deg/s as rad/s, g as m/s², ms as s — gives
    /// plausible-looking nonsense downstream), and the start's roll and pitch against gravity.
    fn check_head(
        &self,
        imu: &mut ImuStream,
        start: &NavState,
        plan: &AidPlan,
        note: &mut dyn FnMut(&str),
    ) -> Result<()> {
        let imu_path = self.imu_path()?;
        let witness = rest_witness(plan);
        let e = start.euler();
        let (roll, pitch) = (e.x, e.y);
        let head = crate::io::imu::ImuData {
            samples: imu.head().to_vec(),
        };
        let (check, moving) = head_seen(&head, start, witness.as_ref());
        // a MEMS gyro's bias can reach what a unit slip gives: with --grade mems a warning
        let mems = self.grade.as_deref() == Some("mems");
        for p in check.gyro_unit_problems.iter().filter(|_| mems) {
            note(&format!(
                "warning: --imu {}: {p} (or a MEMS gyro's bias: --grade mems given)",
                imu_path.display()
            ));
        }
        // a gyro bias at rest beyond the stated grade's (unless --prior sets the gyro biases)
        // the gyro-bias prior given for each axis [deg/h] (the most specific --prior, as where
        // they are applied; one that does not parse is left to that check)
        let eps_prior = ["eps_x", "eps_y", "eps_z"].map(|state| {
            super::setup::prior_for(&self.prior, state)
                .ok()
                .flatten()
                .and_then(|(_, q)| crate::io::units::parse_quantity_as(q, "deg/h").ok())
        });
        let beyond = crate::estimate::imu_check::gyro_bias_beyond_grade(
            &check,
            self.grade.as_deref(),
            eps_prior,
        );
        let slips: Vec<&String> = check
            .unit_problems
            .iter()
            .chain(check.gyro_unit_problems.iter().filter(|_| !mems))
            .chain(beyond.iter())
            .collect();
        if let Some(p) = slips.first() {
            if self.force {
                note(&format!(
                    "warning: --imu {}: {p} (--force given)",
                    imu_path.display()
                ));
            } else {
                bail!(
                    "--imu {}: {p} (in the first 10 s; `sinsmodel imu-check` shows what was read; --force runs anyway)",
                    imu_path.display()
                );
            }
        }
        // (a moving start's specific force holds its accelerations: a turn tilts it)
        if let Some(p) = crate::estimate::align::attitude_contradicts_gravity(&head, roll, pitch)
            .filter(|_| !self.init_auto() && !moving)
        {
            if self.force {
                note(&format!("warning: {p} (--force given)"));
            } else {
                bail!("{}{p}", if self.init.is_some() { "--init: " } else { "" });
            }
        }
        // the rest of the run, a window at a time as it is read
        use crate::estimate::imu_check::{window_check, WindowJudge};
        let mut judge = WindowJudge::new(start.lat, &check, mems);
        let claim = if self.static_aid.is_some() {
            Some("--static-aid")
        } else {
            self.zupt.map(|_| "--zupt")
        };
        if let (Some(o), true) = (claim, start.v.norm() > 1.0) {
            bail!(
                "{o} says the vehicle does not move, but the initial state moves at {:.2} m/s (--init or the truth's first row): {}",
                start.v.norm(),
                if o == "--zupt" {
                    "leave out --zupt (it adds a zero-velocity update at every aiding epoch)"
                } else {
                    "aid a moving run with GNSS fixes (--aid)"
                }
            );
        }
        // the GNSS fixes beside --zupt say whether the vehicle stands (speed less 3σ)
        if let (Some("--zupt"), Some(crate::estimate::imu_check::RestWitness::Speeds(v))) =
            (claim, witness.as_ref())
        {
            if let Some((t, sp)) = v.iter().find(|x| x.0 > start.t && x.1 > 1.0) {
                bail!(
                    "--zupt says the vehicle does not move, but the aiding fixes move: {:.2} m/s (less 3 σ of its noise) at {}: \
                     leave out --zupt (it adds a zero-velocity update at every aiding epoch), or cut the files to the stretch at rest",
                    sp,
                    crate::io::aiding::time_from_first_sample(*t, imu.first_t())
                );
            }
        }
        if let Some(w) = witness {
            judge.witness_rest(w);
        }
        if let Some(p) = claim.and_then(|o| judge.claim_rest(o, imu.head())) {
            if self.force {
                note(&format!(
                    "warning: --imu {}: {p} (--force given)",
                    imu_path.display()
                ));
            } else {
                bail!("--imu {}: {p} (--force runs anyway)", imu_path.display());
            }
        }
        imu.judge_windows(window_check(
            judge,
            imu_path.display().to_string(),
            self.force,
            "or a MEMS gyro's bias: --grade mems given",
        ));
        Ok(())
    }

    /// For a command that passes over the IMU file more than once (explain): reads the file
    /// through once (every sample validated, its end found; memory does not grow with it), then
    /// the aiding epochs inside it, the truth and the initial state. Each pass reads the file
    /// again (explain's `ImuInput::File`).
    pub fn load_for_passes(&self, note: &mut dyn FnMut(&str)) -> Result<PassInputs> {
        let mut opened = self.open(note)?;
        while opened.imu.next()?.is_some() {}
        let t_last = opened.imu.last_t();
        let truth = match &self.truth {
            Some(p) => Some(truth::read(p)?),
            None => None,
        };
        let start = opened.start;
        let aid: Vec<AidingEpoch> = super::aid::with_rows(
            super::aid::with_body_velocity(
                opened.aid.epochs_outside(&opened.outages),
                &opened.body_velocity,
            ),
            &opened.attitude,
        )
        .take_while(|e| e.t <= t_last + 1e-9)
        .collect();
        check_inside(aid.len(), opened.aid.len(), start.t, t_last)?;
        check_reference_inside(
            "--body-velocity",
            self.body_velocity.as_deref(),
            aid.iter().filter(|e| e.body_vel.is_some()).count(),
            start.t,
            t_last,
        )?;
        check_reference_inside(
            "--attitude",
            self.attitude.as_deref(),
            aid.iter().filter(|e| e.att.is_some()).count(),
            start.t,
            t_last,
        )?;
        Ok(PassInputs {
            init_sigma: opened.init_sigma,
            step_s: opened.step_s,
            imu: self.imu_path()?.to_path_buf(),
            imu_format: self.imu_format.clone(),
            clock_offset: self.clock_offset,
            aid,
            truth,
            start,
        })
    }
}

/// The aiding must go on after the start (at least 10 epochs) and begin where the start is
/// (within 20 km of it; a height 3.28× the other's beyond what the geoid and 10 s of climbing
/// allow refused as feet, or over 1000 m off; over 60 m off warned as two datums, over 150 m as
/// more than that).
fn check_plan_at_start(plan: &AidPlan, start: &NavState, note: &mut dyn FnMut(&str)) -> Result<()> {
    let t0 = start.t;
    let far = |lat: f64, lon: f64| {
        let d = horizontal_distance_m(start.lat, start.lon, start.h, lat, lon);
        (d > 20_000.0).then_some(d)
    };
    match plan {
        AidPlan::Fixes(fixes, _, _) => {
            let after = fixes.iter().filter(|f| f.0.t > t0).count();
            if after < 10 {
                let of = if after == fixes.len() {
                    format!("the file has only {after} aiding epochs")
                } else {
                    format!(
                        "only {after} of {} aiding epochs come after the IMU start ({t0:.3} s)",
                        fixes.len()
                    )
                };
                bail!("{of}; at least 10 are needed (the filter works on innovations)");
            }
            // the initial position and the first aiding fix must describe the same place
            if let Some(f) = fixes.iter().map(|f| &f.0).find(|f| f.t > t0) {
                let dh = f.h - start.h;
                let feet = (f.h / start.h / 3.2808 - 1.0).abs() < 0.05
                    || (start.h / f.h / 3.2808 - 1.0).abs() < 0.05;
                // beyond what the geoid (±100 m between ellipsoidal and sea-level heights), 10 s
                // of climbing (10 m/s) and the fix's noise allow
                let climb = 5.0 * f.sigma[2] + 10.0 * (f.t - t0).max(0.0);
                let beyond_datum = dh.abs() > 150.0 + climb;
                if dh.abs() > 1000.0 || (feet && beyond_datum) {
                    bail!(
                        "the initial height {:.1} m is {:.1} m from the first aiding fix's {:.1} m (t = {:.3} s){}: check --init / --aid",
                        start.h,
                        dh.abs(),
                        f.h,
                        f.t,
                        if feet { ", 3.28×: one of them in feet?" } else { "" }
                    );
                }
                if dh.abs() > 60.0 + climb {
                    let why = if beyond_datum {
                        "more than two height datums differ by (ellipsoidal and mean-sea-level heights differ by the geoid's \
                         undulation, within ±100 m): a wrong initial height, or fixes from elsewhere?"
                            .to_string()
                    } else {
                        format!(
                            "heights on two datums? (ellipsoidal heights, as GNSS gives them, and heights above mean sea level \
                             differ by the geoid's undulation, up to ±100 m){}",
                            if feet { ", or one of them in feet (3.28×)" } else { "" }
                        )
                    };
                    note(&format!(
                        "warning: the initial height {:.1} m is {:.1} m from the first aiding fix's {:.1} m (t = {:.3} s, σ {:.2} m): {why}; check --init / --aid",
                        start.h,
                        dh.abs(),
                        f.h,
                        f.t,
                        f.sigma[2]
                    ));
                }
                if let Some(dist) = far(f.lat, f.lon) {
                    bail!(
                        "the initial position is {:.1} km from the first aiding fix (t = {:.3} s): check --init / --static-aid / --aid",
                        dist / 1000.0,
                        f.t
                    );
                }
            }
        }
        AidPlan::Static { fix, .. } => {
            if let Some(dist) = far(fix.lat, fix.lon) {
                bail!(
                    "the initial position is {:.1} km from the first aiding fix (--static-aid): check --init / --static-aid",
                    dist / 1000.0
                );
            }
        }
    }
    Ok(())
}

/// The distance the start check uses, for the module's tests.
#[cfg(test)]
pub(crate) fn tests_distance(lat: f64, lon: f64, h: f64, lat2: f64, lon2: f64) -> f64 {
    horizontal_distance_m(lat, lon, h, lat2, lon2)
}

/// Refuses an `--outage` window that no aiding epoch of `aid` falls inside: nothing is dropped,
/// so the "drift" at its end would be an ordinary innovation. Names the window and the epochs
/// around it (`first_t` [s]: the first IMU sample, as --outage counts).
fn check_outages_drop_fixes(aid: &AidPlan, outages: &[Outage], first_t: f64) -> Result<()> {
    use crate::io::aiding::time_from_first_sample;
    'windows: for o in outages {
        let mut before = None;
        let mut after = None;
        for e in aid.epochs() {
            if e.t >= o.end_s {
                after = Some(e.t);
                break;
            }
            if e.t >= o.start_s {
                continue 'windows;
            }
            before = Some(e.t);
        }
        // no fix after it either: the drift check says so (no position fix after it)
        let Some(after) = after else { continue };
        let before = match before {
            Some(t) => format!(
                "the last fix before it at {}",
                time_from_first_sample(t, first_t)
            ),
            None => "no fix before it".into(),
        };
        bail!(
            "--outage: no aiding fix falls inside the window {} ({}; the next at {}): it drops nothing, so there is no outage drift to measure; widen it to cover a fix",
            o.words(first_t),
            before,
            time_from_first_sample(after, first_t)
        );
    }
    Ok(())
}

/// Largest acceleration a vehicle's fix-to-fix track may show [m/s²] (1 g) when fixes are
/// tested against their neighbours.
pub const FIX_ACCEL_MAX: f64 = 9.80665;

/// The aiding file against itself, for every run (`--init auto` checked the velocities only
/// for its own use): the receiver's velocities against the position differences (swapped,
/// negated or mis-scaled columns refused), and single fixes (or pairs) far off the line through
/// their neighbours and off the tracks of the two fixes before and the two after (beyond 10 σ
/// plus what 1 g can do in between: an outlier) dropped with a warning that counts them
/// (`first_t` [s]: the first IMU sample, for the times said).
fn check_fixes(plan: &mut AidPlan, first_t: f64, note: &mut dyn FnMut(&str)) -> Result<()> {
    let AidPlan::Fixes(list, _, _) = plan else {
        return Ok(());
    };
    use crate::estimate::init::{self, Fix};
    let fixes: Vec<Fix> = list
        .iter()
        .map(|(p, v)| Fix::from_aiding(p, v.as_ref()))
        .collect();
    let receiver: Vec<bool> = list.iter().map(|(_, v)| v.is_some()).collect();
    init::check_velocities(&fixes, &receiver)?;
    // how far fix p is from the line through fixes a and b at its time [m] (interpolated
    // between them or extrapolated beyond), when beyond 10 σ plus what 1 g allows
    let off = |p: &PositionFix, a: &PositionFix, b: &PositionFix| -> Option<f64> {
        let (ta, tb) = (p.t - a.t, p.t - b.t);
        let span = b.t - a.t;
        if !(span > 0.0 && ta.abs().max(tb.abs()) <= 10.0) {
            return None;
        }
        let w = ta / span;
        let (rm, rn) = (
            earth::radius_meridian(p.lat) + p.h,
            earth::radius_transverse(p.lat) + p.h,
        );
        let d = [
            (p.lat - (a.lat + w * (b.lat - a.lat))) * rm,
            earth::lon_difference(p.lon, a.lon + w * earth::lon_difference(b.lon, a.lon))
                * rn
                * p.lat.cos(),
            -(p.h - (a.h + w * (b.h - a.h))),
        ];
        let room = 0.5 * FIX_ACCEL_MAX * (ta * tb).abs();
        (0..3)
            .any(|i| {
                let s = p.sigma[i].hypot(a.sigma[i].max(b.sigma[i]));
                d[i].abs() > 10.0 * s + room
            })
            .then(|| d[0].hypot(d[1]).hypot(d[2]))
    };
    // an outlier is off the line through its neighbours, and off the tracks its two
    // predecessors and its two successors make (where it has them): a clean fix beside an
    // outlier is off the first line but on one of the tracks, and a burst of shifted fixes
    // lies on its own track (left to the filter's innovations and --gate)
    let n = list.len();
    let outliers: Vec<(usize, f64)> = (1..n.saturating_sub(1))
        .filter_map(|k| {
            let f = |i: usize| &list[i].0;
            let d = off(f(k), f(k - 1), f(k + 1))?;
            let before = k < 2 || off(f(k), f(k - 2), f(k - 1)).is_some();
            let after = k + 2 >= n || off(f(k), f(k + 1), f(k + 2)).is_some();
            (before && after).then_some((k, d))
        })
        .collect();
    let Some(&(k0, d0)) = outliers.first() else {
        return Ok(());
    };
    // many are no single outliers: said, kept, left to the filter's innovations to show
    if outliers.len() * 20 > list.len() {
        note(&format!(
            "warning: --aid: {} of {} fixes are off the line through their neighbours by more than 10 σ plus what 1 g allows \
             (the first {} m off, {}): a rough track or σ stated too small; kept",
            outliers.len(),
            list.len(),
            crate::io::units::sig3(d0),
            crate::io::aiding::time_from_first_sample(list[k0].0.t, first_t)
        ));
        return Ok(());
    }
    note(&format!(
        "warning: --aid: {} of {} fixes dropped as outliers, each off the line through its neighbours and off the tracks of the two \
         fixes before it and the two after it, by more than 10 σ plus what 1 g allows (the first {} off, {}); a longer burst of shifted \
         fixes is kept (its own track): --gate takes it out in the filter",
        outliers.len(),
        list.len(),
        crate::io::units::sig3(d0) + " m",
        crate::io::aiding::time_from_first_sample(list[k0].0.t, first_t)
    ));
    let drop: std::collections::HashSet<usize> = outliers.iter().map(|o| o.0).collect();
    let mut k = 0;
    list.retain(|_| {
        k += 1;
        !drop.contains(&(k - 1))
    });
    Ok(())
}

/// Refuses aiding fixes that all come before the IMU's first sample `first_t` [s], or whose
/// first comes more than an hour after it: another clock or date, with the likely one named
/// from the offset (a day, JST's 9 h, UTC's 18 leap seconds, ms read as s). Checked before
/// `--init auto`, which otherwise saw no fix while moving and blamed the start.
fn check_fix_times(plan: &AidPlan, first_t: f64) -> Result<()> {
    let AidPlan::Fixes(list, _, _) = plan else {
        return Ok(());
    };
    let (Some(a), Some(b)) = (list.first(), list.last()) else {
        return Ok(());
    };
    let (t_a, t_b) = (a.0.t, b.0.t);
    if t_b > first_t && t_a < first_t + 3600.0 {
        return Ok(());
    }
    let off = t_a - first_t;
    let near = |x: f64, tol: f64| (off.abs() - x).abs() <= tol;
    let days = (off.abs() / 86400.0).round();
    let hint = if days >= 1.0 && near(days * 86400.0, 120.0) {
        format!("{days:.0} day(s) off: a wrong date in the aiding file, or its week/day rollover?")
    } else if near(32400.0, 120.0) || near(32418.0, 2.0) {
        "9 h off: a solution in JST (UTC + 9 h) read as GPST?".to_string()
    } else if near(18.0, 2.0) {
        "18 s off: UTC read as GPST?".to_string()
    } else if t_a.abs() > 0.0 && (first_t / t_a - 1000.0).abs() < 50.0 {
        "the IMU's clock is about 1000× the aiding's: one of them in ms read as s?".to_string()
    } else {
        "the two files are on different clocks (GPS seconds against seconds since power-up?): --clock-offset for a GNSS_IMU csv, or [time] offset in an --imu-format description".to_string()
    };
    bail!(
        "--aid: the aiding fixes run from t = {t_a:.3} to {t_b:.3} s, {} the IMU's first sample (t = {first_t:.3} s): \
         they {} — {hint}",
        if off >= 0.0 {
            format!("starting {} s after", crate::io::units::sig3(off))
        } else {
            format!("starting {} s before", crate::io::units::sig3(-off))
        },
        if t_b <= first_t {
            "all end before the IMU starts"
        } else {
            "begin more than an hour after the IMU starts"
        }
    )
}

/// The check of the first seconds `head` and whether the start moves (its velocity, or a GNSS
/// fix over 1 m/s there: it may turn steadily on a smooth curve, which looks like rest to the
/// IMU, so its gyros are not judged). Where the specific force spreads (engine vibration) while
/// three or more GNSS fixes stand, the means are judged as at rest (a gyro unit slip shows in
/// |ω̄|).
fn head_seen(
    head: &crate::io::imu::ImuData,
    start: &NavState,
    witness: Option<&crate::estimate::imu_check::RestWitness>,
) -> (crate::estimate::imu_check::ImuCheck, bool) {
    use crate::estimate::imu_check::{check, check_at_witnessed_rest, RestWitness};
    let mut seen = check(head, Some(start.lat), 0.0, 10.0, true);
    let (h0, h1) = (
        head.samples.first().map_or(0.0, |x| x.t),
        head.samples.last().map_or(0.0, |x| x.t),
    );
    let moving = start.v.norm() > 1.0 || witness.is_some_and(|w| w.moving(h0, h1));
    if moving {
        seen.gyro_unit_problems.clear();
        seen.is_static = false;
    } else if !seen.is_static
        && matches!(witness, Some(RestWitness::Speeds(v))
            if v.iter().filter(|x| x.0 >= h0 && x.0 <= h1).count() >= 3)
        && witness.is_some_and(|w| w.at_rest(h0, h1))
    {
        seen = check_at_witnessed_rest(head, Some(start.lat));
    }
    (seen, moving)
}

/// What says, beside the IMU, whether the vehicle stands still: a static vehicle, or the GNSS
/// fixes' horizontal speeds (the receiver's, else from the neighbouring positions).
fn rest_witness(plan: &AidPlan) -> Option<crate::estimate::imu_check::RestWitness> {
    use crate::estimate::imu_check::RestWitness;
    match plan {
        AidPlan::Static { .. } => Some(RestWitness::Static),
        AidPlan::Fixes(list, _, _) => {
            // the speed less three σ of its noise (a speed from positions carries theirs)
            let speed = |k: usize| -> Option<f64> {
                if let Some(v) = list[k].1 {
                    return Some((v.v_ned[0].hypot(v.v_ned[1]) - 3.0 * v.sigma).max(0.0));
                }
                let (a, b) = (&list[k.checked_sub(1)?].0, &list.get(k + 1)?.0);
                let dt = b.t - a.t;
                let noise = a.sigma[0].max(a.sigma[1]).hypot(b.sigma[0].max(b.sigma[1])) / dt;
                (dt > 0.0 && dt <= 5.0).then(|| {
                    (horizontal_distance_m(a.lat, a.lon, a.h, b.lat, b.lon) / dt - 3.0 * noise)
                        .max(0.0)
                })
            };
            Some(RestWitness::Speeds(
                (0..list.len())
                    .filter_map(|k| speed(k).map(|s| (list[k].0.t, s)))
                    .collect(),
            ))
        }
    }
}

impl DataOptions {
    /// The `--body-velocity` rows after the start `t0` [s], checked against the data: some fall
    /// after the start, and their speeds agree with the GNSS fixes' (`aid`) where both move.
    fn body_velocity_after(
        &self,
        t0: f64,
        aid: &AidPlan,
        note: &mut dyn FnMut(&str),
    ) -> Result<Vec<BodyVelocityFix>> {
        let Some(path) = &self.body_velocity else {
            return Ok(Vec::new());
        };
        let rows = crate::io::aiding::read_body_velocity(path)?;
        let after = rows_after("--body-velocity", path, rows, t0)?;
        check_reference_times(path, &after, aid)?;
        if let Some(w) = sideways_reference(&after) {
            note(&format!("warning: --body-velocity {}: {w}", path.display()));
        }
        if let AidPlan::Fixes(fixes, _, _) = aid {
            match reference_speed_ratio(fixes, &after) {
                Some(r) if !(0.8..=1.25).contains(&r) => bail!(
                    "--body-velocity {}: its speeds are {r:.2}× those of the GNSS fixes in {} over the same times ({}); the columns must be m/s on the IMU's clock",
                    path.display(),
                    self.aid.as_deref().map_or("--aid".into(), |p| p.display().to_string()),
                    speed_slip(r)
                ),
                Some(r) => note(&format!(
                    "body-velocity reference: {} rows after the start; speed {r:.3}× the GNSS fixes' (median over moving fixes)",
                    after.len()
                )),
                None => note(&format!(
                    "body-velocity reference: {} rows after the start; its speeds not compared with the GNSS (fewer than 10 fix pairs moving faster than 1 m/s)",
                    after.len()
                )),
            }
            if let Some(lag) = reference_clock_lag(fixes, &after) {
                bail!(
                    "--body-velocity {}: its speeds follow the GNSS fixes' {} when shifted by {:+.2} s (mean square difference {:.3} (m/s)² there, {:.3} as stamped): its clock is not the IMU's (UTC against GPST: 18 s; another time base; ms for s?); a latency under 1 s is estimated by explain as dt_ref",
                    path.display(),
                    self.aid.as_deref().map_or("--aid".into(), |p| p.display().to_string()),
                    lag.shift_s,
                    lag.msd_best,
                    lag.msd_zero
                );
            }
        }
        Ok(after)
    }
}

/// A reference's speeds matching the GNSS's far better shifted in time than as stamped.
struct ClockLag {
    /// The shift that fits best [s] (a row stamped t is the speed at t + shift_s).
    shift_s: f64,
    /// Mean square difference (about its mean) at that shift [(m/s)², deg²].
    msd_best: f64,
    /// ... and as stamped.
    msd_zero: f64,
}

/// Largest shift searched between a reference's clock and the GNSS's [s].
const MAX_CLOCK_SHIFT_S: f64 = 60.0;

/// The rows (time-ordered) either side of `t` at most 2 s apart and the weight of the later one,
/// for interpolating a reference at `t`; None outside the rows or across a gap.
fn bracket<R: super::aid::ReferenceRow>(rows: &[R], t: f64) -> Option<(&R, &R, f64)> {
    let k = rows.partition_point(|r| r.t() < t);
    if k == 0 || k >= rows.len() {
        return None;
    }
    let (a, b) = (&rows[k - 1], &rows[k]);
    if b.t() - a.t() > 2.0 {
        return None;
    }
    Some((a, b, (t - a.t()) / (b.t() - a.t())))
}

/// The shift of the velocity reference's clock against the GNSS fixes' when it is one the data
/// show ([`best_shift`] of the GNSS speed from consecutive fixes at most 2 s apart against the
/// reference's speed interpolated there).
fn reference_clock_lag(
    fixes: &[(PositionFix, Option<crate::io::aiding::VelocityFix>)],
    body: &[BodyVelocityFix],
) -> Option<ClockLag> {
    let gnss: Vec<(f64, f64)> = fix_steps(fixes)
        .iter()
        .map(|s| (s.t_mid(), s.speed()))
        .collect();
    let speed = |t: f64| -> Option<f64> {
        let (a, b, w) = bracket(body, t)?;
        let n = |r: &BodyVelocityFix| nalgebra::Vector3::from(r.v_frd).norm();
        Some(n(a) + w * (n(b) - n(a)))
    };
    best_shift(&gnss, &speed, &|r, v| r - v)
}

/// The shift of a reference's clock against the GNSS's that the data show ([`ClockLag`]): the
/// shift s (−60…60 s in 0.05 s steps) minimising the mean square of `diff(reference at t − s,
/// GNSS value at t)` over the GNSS series `gnss` ((t, value)) about its mean, kept when beyond
/// 1 s (a latency within it is the reference's time-offset term's) and when the spread as
/// stamped exceeds that at the shift by more than half of it and beyond chance (n (m₀ − m)/m
/// above 100 over the n values compared, an F-like ratio; a steady motion shows no shift: flat).
fn best_shift(
    gnss: &[(f64, f64)],
    value_at: &dyn Fn(f64) -> Option<f64>,
    diff: &dyn Fn(f64, f64) -> f64,
) -> Option<ClockLag> {
    let msd = |shift: f64| -> Option<f64> {
        let (mut n, mut sum, mut sum2) = (0usize, 0.0, 0.0);
        for d in gnss
            .iter()
            .filter_map(|&(t, v)| value_at(t - shift).map(|r| diff(r, v)))
        {
            n += 1;
            sum += d;
            sum2 += d * d;
        }
        // at least half the pairs compared, and 10
        if n < 10 || 2 * n < gnss.len() {
            return None;
        }
        let mean = sum / n as f64;
        Some((sum2 / n as f64 - mean * mean).max(0.0))
    };
    let msd_zero = msd(0.0)?;
    let steps = (MAX_CLOCK_SHIFT_S / 0.05).round() as i64;
    let (shift_s, msd_best) = (-steps..=steps)
        .filter_map(|k| {
            let s = k as f64 * 0.05;
            msd(s).map(|m| (s, m))
        })
        .min_by(|a, b| a.1.total_cmp(&b.1))?;
    let n = gnss.len() as f64;
    let gain = n * (msd_zero - msd_best) / msd_best.max(f64::MIN_POSITIVE);
    (shift_s.abs() > 1.0 && msd_zero > 1.5 * msd_best && gain > 100.0).then_some(ClockLag {
        shift_s,
        msd_best,
        msd_zero,
    })
}

impl DataOptions {
    /// The `--attitude` rows after the start `t0` [s], checked against the data: at least 10
    /// after the start, most within the GNSS fixes' times, and their yaw along the GNSS course
    /// where the fixes move.
    fn attitude_after(
        &self,
        t0: f64,
        aid: &AidPlan,
        note: &mut dyn FnMut(&str),
    ) -> Result<Vec<AttitudeFix>> {
        let Some(path) = &self.attitude else {
            return Ok(Vec::new());
        };
        let rows = crate::io::aiding::read_attitude(path)?;
        let after = rows_after("--attitude", path, rows, t0)?;
        if let AidPlan::Fixes(fixes, _, _) = aid {
            let times: Vec<f64> = after.iter().map(|r| r.t).collect();
            check_within_fixes("--attitude", path, &times, fixes)?;
            let yaw = |r: &AttitudeFix| r.rpy[2];
            match heading_offset(fixes, &after, &yaw) {
                Some((d, spread)) if !follows_course(d, spread) => {
                    let slip = yaw_slip(fixes, &after, d);
                    bail!(
                        "--attitude {}: its yaw is {d:.1} deg from the GNSS course (median over moving fixes; the middle 80 % of the differences span {spread:.1} deg); a vehicle heads along its course, within a slip and a mounting: {slip}",
                        path.display()
                    );
                }
                Some((d, _)) => note(&format!(
                    "attitude reference: {} rows after the start; yaw {d:.2} deg from the GNSS course (median over moving fixes)",
                    after.len()
                )),
                None => note(&format!(
                    "attitude reference: {} rows after the start; its yaw not compared with the GNSS course (fewer than 10 fix pairs moving faster than 3 m/s)",
                    after.len()
                )),
            }
            if let Some(lag) = attitude_clock_lag(fixes, &after) {
                bail!(
                    "--attitude {}: its yaw follows the GNSS course of {} when shifted by {:+.2} s (mean square difference about its mean {:.3} deg² there, {:.3} as stamped): its clock is not the IMU's (UTC against GPST: 18 s; another run's file; another time base?)",
                    path.display(),
                    self.aid.as_deref().map_or("--aid".into(), |p| p.display().to_string()),
                    lag.shift_s,
                    lag.msd_best,
                    lag.msd_zero
                );
            }
        }
        Ok(after)
    }
}

/// An angle difference wrapped to ±180 [deg].
fn wrap_deg(d: f64) -> f64 {
    (d + 180.0).rem_euclid(360.0) - 180.0
}

/// The shift of the attitude reference's clock against the GNSS fixes' when it is one the data
/// show ([`best_shift`] of the GNSS course from consecutive fixes at most 2 s apart moving
/// faster than 3 m/s against the reference's yaw interpolated there, both deg).
fn attitude_clock_lag(
    fixes: &[(PositionFix, Option<crate::io::aiding::VelocityFix>)],
    rows: &[AttitudeFix],
) -> Option<ClockLag> {
    let course: Vec<(f64, f64)> = fix_steps(fixes)
        .iter()
        .filter(|s| s.horizontal_speed() >= 3.0)
        .map(|s| (s.t_mid(), s.course().to_degrees()))
        .collect();
    let yaw = |t: f64| -> Option<f64> {
        let (a, b, w) = bracket(rows, t)?;
        let (ya, yb) = (a.rpy[2].to_degrees(), b.rpy[2].to_degrees());
        Some(ya + w * wrap_deg(yb - ya))
    };
    best_shift(&course, &yaw, &|r, v| wrap_deg(r - v))
}

/// A reading of an attitude row's yaw [rad] under a hypothesis about its file.
type YawReading = fn(&AttitudeFix) -> f64;

/// The likely slip behind a reference yaw `d` degrees (median) from the GNSS course: the first
/// reading of the rows that brings it within [`MAX_COURSE_OFFSET_DEG`], else a guess from `d`.
fn yaw_slip(
    fixes: &[(PositionFix, Option<crate::io::aiding::VelocityFix>)],
    rows: &[AttitudeFix],
    d: f64,
) -> String {
    let slips: [(&str, YawReading); 3] = [
        ("radians written as degrees", |r| r.rpy[2].to_degrees()),
        (
            "a heading counter-clockwise from east (ENU) where NED's clockwise from north is meant",
            |r| std::f64::consts::FRAC_PI_2 - r.rpy[2],
        ),
        ("the yaw's sign reversed", |r| -r.rpy[2]),
    ];
    match slips.into_iter().find(|(_, f)| {
        heading_offset(fixes, rows, &|r| f(r)).is_some_and(|(d, spread)| follows_course(d, spread))
    }) {
        Some((s, _)) => format!("{s}?"),
        None if (d.abs() - 180.0).abs() < MAX_COURSE_OFFSET_DEG => {
            "the reference faces backwards, or its axes are not FRD?".into()
        }
        None => "another vehicle's file, another clock, or its axes are not FRD?".into(),
    }
}

/// Largest median difference between a reference's yaw and the GNSS course, and largest spread
/// of the differences (10th to 90th percentile) [deg]: a vehicle's slip and a mounting are
/// degrees and stay through its turns; beyond these the file's angles are not what they say (a
/// yaw in radians read as degrees stays near zero while the course turns).
const MAX_COURSE_OFFSET_DEG: f64 = 45.0;

/// A yaw `d` degrees from the course (median) with the differences spreading `spread` degrees
/// follows the course ([`MAX_COURSE_OFFSET_DEG`]).
fn follows_course(d: f64, spread: f64) -> bool {
    d.abs() <= MAX_COURSE_OFFSET_DEG && spread <= MAX_COURSE_OFFSET_DEG
}

/// The median of `yaw` (rad) minus the GNSS course [deg, wrapped to ±180] over the rows between
/// consecutive fixes at most 2 s apart that move faster than 3 m/s, and the spread of those
/// differences (10th to 90th percentile, deg); None with fewer than 10 such rows.
fn heading_offset(
    fixes: &[(PositionFix, Option<crate::io::aiding::VelocityFix>)],
    rows: &[AttitudeFix],
    yaw: &dyn Fn(&AttitudeFix) -> f64,
) -> Option<(f64, f64)> {
    let mut diffs = Vec::new();
    let mut j = 0;
    for step in fix_steps(fixes) {
        if step.horizontal_speed() < 3.0 {
            continue;
        }
        let course = step.course();
        while j < rows.len() && rows[j].t < step.t0 {
            j += 1;
        }
        for r in rows[j..].iter().take_while(|r| r.t <= step.t1) {
            diffs.push(wrap_deg((yaw(r) - course).to_degrees()));
        }
    }
    if diffs.len() < 10 {
        return None;
    }
    diffs.sort_by(f64::total_cmp);
    let at = |q: f64| diffs[((diffs.len() - 1) as f64 * q).round() as usize];
    Some((at(0.5), at(0.9) - at(0.1)))
}

/// The median ratio of the reference's speed to the GNSS speed (from consecutive fixes at most 2 s
/// apart, both moving faster than 1 m/s) over the fix pairs a reference row falls between; None
/// with fewer than 10 such pairs.
fn reference_speed_ratio(
    fixes: &[(PositionFix, Option<crate::io::aiding::VelocityFix>)],
    body: &[BodyVelocityFix],
) -> Option<f64> {
    let mut ratios = Vec::new();
    let mut j = 0;
    for step in fix_steps(fixes) {
        let gnss_speed = step.speed();
        while j < body.len() && body[j].t < step.t0 {
            j += 1;
        }
        let inside: Vec<f64> = body[j..]
            .iter()
            .take_while(|r| r.t <= step.t1)
            .map(|r| nalgebra::Vector3::from(r.v_frd).norm())
            .collect();
        if inside.is_empty() || gnss_speed < 1.0 {
            continue;
        }
        let ref_speed = inside.iter().sum::<f64>() / inside.len() as f64;
        if ref_speed > 1.0 {
            ratios.push(ref_speed / gnss_speed);
        }
    }
    if ratios.len() < 10 {
        return None;
    }
    crate::estimate::stats::median(&mut ratios)
}

/// The likely slip behind a reference speed `r` times the GNSS speed.
fn speed_slip(r: f64) -> &'static str {
    let near = |x: f64| (r / x - 1.0).abs() < 0.1;
    if near(3.6) {
        "3.6×: km/h written as m/s?"
    } else if near(1.0 / 3.6) {
        "1/3.6: m/s converted to km/h twice, or km/h divided where m/s was given?"
    } else if near(2.237) {
        "2.24×: mph written as m/s?"
    } else if near(1.944) {
        "1.94×: knots written as m/s?"
    } else {
        "a scale, a clock (UTC for GPST) or another vehicle's file?"
    }
}

/// The reference's rows against the other aiding: most must fall within the GNSS fixes' times
/// (else another clock), and under a static aid the reference must not move.
fn check_reference_times(
    path: &std::path::Path,
    rows: &[BodyVelocityFix],
    aid: &AidPlan,
) -> Result<()> {
    match aid {
        AidPlan::Fixes(fixes, _, _) => {
            let times: Vec<f64> = rows.iter().map(|r| r.t).collect();
            check_within_fixes("--body-velocity", path, &times, fixes)?;
        }
        AidPlan::Static { .. } => {
            let mut speeds: Vec<f64> = rows
                .iter()
                .map(|r| nalgebra::Vector3::from(r.v_frd).norm())
                .collect();
            let median = crate::estimate::stats::median(&mut speeds).unwrap_or(0.0);
            let sigma = rows[rows.len() / 2].sigma;
            if median > 3.0 * sigma + 0.05 {
                bail!(
                    "--body-velocity {}: the reference moves (median speed {median:.3} m/s against its σ {sigma} m/s) while --static-aid says the vehicle stands still",
                    path.display()
                );
            }
        }
    }
    Ok(())
}

/// A reference whose forward component is not the larger part of its speed where it moves
/// faster than 1 m/s (median |vx| / speed under 0.7): a vehicle moves forward, so its axes are
/// likely swapped or its velocities NED, not body; the words, or None.
fn sideways_reference(rows: &[BodyVelocityFix]) -> Option<String> {
    let mut share: Vec<f64> = rows
        .iter()
        .filter_map(|r| {
            let v = nalgebra::Vector3::from(r.v_frd);
            (v.norm() > 1.0).then(|| r.v_frd[0].abs() / v.norm())
        })
        .collect();
    if share.len() < 10 {
        return None;
    }
    let median = crate::estimate::stats::median(&mut share)?;
    (median < 0.7).then(|| {
        format!(
            "where it moves, its forward component vx is a median {:.0} % of its speed: a vehicle moves forward, so its columns may be swapped or its velocities NED instead of body (forward, right, down); a mounting found on it would be the axes' slip",
            median * 100.0
        )
    })
}
