//! The filter set-up the data options give: grade priors and noise, `--prior` by pattern,
//! `--noise`, mode, step, the known GNSS values, explain's term priors.

use super::dataset::DEFAULT_STEP_S;
use super::DataOptions;
use crate::estimate::filter::{FilterConfig, Mode};
use crate::model::catalog::GradeInfo;
use crate::model::generated::common;
use crate::model::priors::{self, StatePattern};
use crate::model::Model;
use crate::nav::strapdown::Vertical;
use anyhow::{bail, Context, Result};

/// The grade `--grade` names (None for navigation, the spec's defaults): `model-spec/grades.toml`.
pub(crate) fn grade_table(grade: Option<&str>) -> Result<Option<&'static GradeInfo>> {
    priors::grade(grade).map_err(|_| {
        anyhow::anyhow!(
            "--grade `{}`: expected {}",
            crate::io::lines::shown(grade.unwrap_or_default()),
            priors::grade_names()
        )
    })
}

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

impl DataOptions {
    /// The known IMU–GNSS time offset of `--gnss-delay` [s], checked for syntax and physics:
    /// the fixes are re-stamped by it (a fix stamped t is taken at t + dt).
    pub fn gnss_delay_s(&self) -> Result<Option<f64>> {
        let Some(text) = &self.gnss_delay else {
            return Ok(None);
        };
        let dt = crate::io::units::parse_quantity_as(text, "s").with_context(|| {
            format!(
                "--gnss-delay `{text}`: expected a time with its unit, e.g. `92 ms` or `0.092 s`"
            )
        })?;
        if !dt.is_finite() || dt.abs() > 1.0 {
            bail!(
                "--gnss-delay `{text}`: {dt} s is beyond ±1 s; an IMU–GNSS time offset is milliseconds to a few hundred (ms read as s? a UTC–GPST leap-second or whole-second difference of the clocks belongs in the stamps: --clock-offset for a GNSS_IMU .csv, else the files' own time columns)"
            );
        }
        if !self.has_gnss() {
            bail!("--gnss-delay and --lever-arm describe a GNSS receiver: they need --aid (a GNSS file)");
        }
        if dt == 0.0 {
            // (none: `0 s` and `-0 s` leave the fixes as stamped)
            return Ok(None);
        }
        if dt.abs() < 1e-3 {
            bail!(
                "--gnss-delay `{text}`: {} ms is below 1 ms, far under an IMU sample period: it changes nothing measurable (s read as ms? `0.179 s` is 179 ms); leave the option out for none",
                crate::io::units::sig3(dt * 1e3)
            );
        }
        Ok(Some(dt))
    }

    /// The known aiding term values of `--gnss-delay`, `--lever-arm` and `--mounting`: (term
    /// index, SI), each checked for syntax and physics. The time offset is applied by
    /// re-stamping the fixes ([`DataOptions::gnss_delay_s`]), the others in the residuals
    /// ([`DataOptions::residual_known`]).
    pub fn known_gnss(&self) -> Result<Vec<(usize, f64)>> {
        let mut out = Vec::new();
        if let Some(dt) = self.gnss_delay_s()? {
            out.push((term("dt_gnss", "--gnss-delay")?, dt));
        }
        out.extend(self.residual_known()?);
        Ok(out)
    }

    /// The known aiding term values applied in the residuals (z − H θ): `--lever-arm` and
    /// `--mounting`, (term index, SI).
    pub fn residual_known(&self) -> Result<Vec<(usize, f64)>> {
        let mut out = Vec::new();
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
                    Err(_) => crate::io::units::parse_quantity_as(item, "m").with_context(|| {
                        format!("--lever-arm: {axis} = `{item}`: expected metres (`0.3`) or a length with its unit (`30 cm`)")
                    })?,
                };
                if !v.is_finite() {
                    bail!("--lever-arm: {axis} = `{item}` is {}", finite_words(v));
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
        if let Some(m) = &self.mounting {
            if self.body_velocity.is_none() {
                bail!("--mounting describes a velocity reference: it needs --body-velocity (the reference's file)");
            }
            out.extend(known_mounting(m)?);
        }
        Ok(out)
    }

    /// What the user set over the grade's priors and noise, in words (`eps_*, nabla_* set by
    /// --prior and the noise set by --noise`); None when nothing was.
    fn overridden(&self) -> Option<String> {
        let mut names: Vec<String> = Vec::new();
        for p in &self.prior {
            let name = p.split('=').next().unwrap_or("").trim();
            let name = crate::io::lines::shown(name);
            if !names.contains(&name) {
                names.push(name);
            }
        }
        let mut parts = Vec::new();
        if !names.is_empty() {
            parts.push(format!("{} set by --prior", names.join(", ")));
        }
        if self.noise.is_some() {
            parts.push("the noise set by --noise".to_string());
        }
        (!parts.is_empty()).then(|| parts.join(" and "))
    }

    /// What the run assumes of the sensor, one line each: the grade the priors assume, the known
    /// GNSS values applied, the noise `--noise` gives (said once per run).
    pub fn noise_lines(&self) -> Result<Vec<String>> {
        let mut lines = Vec::new();
        let overridden = self.overridden();
        match (grade_table(self.grade.as_deref())?, overridden) {
            (None, None) => lines.push(format!(
                "priors and noise: {} (the spec's defaults, a navigation-grade laser-gyro INS); --grade tactical|mems for other sensors",
                if self.grade.is_some() { "--grade navigation" } else { "navigation grade" },
            )),
            // a hand-tuned run is not the laser-gyro INS the defaults describe: say what is whose
            (None, Some(o)) => lines.push(format!(
                "priors and noise: the spec's navigation-grade defaults{}, with {o}; the other values stay those of a navigation-grade laser-gyro INS (--grade tactical|mems for other sensors)",
                if self.grade.is_some() { " (--grade navigation)" } else { "" },
            )),
            (Some(g), o) => lines.push(format!(
                "priors and noise: --grade {} (ARW {}, VRW {}; the priors of model-spec/grades.toml){}",
                g.name,
                g.gyro_arw_text,
                g.accel_vrw_text,
                o.map(|o| format!(", with {o}")).unwrap_or_default()
            )),
        }
        let reference = match (&self.body_velocity, &self.attitude) {
            (Some(_), _) => Some("--body-velocity"),
            (None, Some(_)) => Some("--attitude"),
            (None, None) => None,
        };
        match (reference, self.mode.as_deref()) {
            (Some(r), None) => lines.push(format!(
                "mode: closed loop, the default with {r} (its rows are linearised about the aided solution; --mode open would linearise them about the free-inertial one, which biases a mounting and couples it into gyro terms)"
            )),
            (Some(r), Some("open")) => lines.push(format!(
                "warning: --mode open with {r}: the reference's rows are linearised about the free-inertial solution, whose error grows through the run; a mounting comes out biased and gyro terms (kg_33, eps_z) may take part of it; --mode closed avoids this"
            )),
            _ => {}
        }
        for (t, v) in self.known_gnss()? {
            let info = &common::TERMS[t];
            let how = if info.name == "dt_gnss" {
                "the fixes re-stamped by it, exact to every order"
            } else {
                "applied in the residuals"
            };
            lines.push(format!(
                "known GNSS value, {how}: {} = {} {} ({}); a {} state in the model estimates what is left on top of it",
                info.name,
                v / info.display_to_si,
                info.display,
                info.doc,
                info.name
            ));
        }
        if let Some(path) = &self.noise {
            let NoiseGiven {
                arw,
                vrw,
                gyro_bias_rw: g,
                accel_bias_rw: a,
            } = noise_given(path)?;
            // rad/√s → deg/√h: × 180/π × 60; m/s/√s → µg/√Hz: ÷ g × 1e6
            lines.push(format!(
                "noise from {} (used{}): ARW {:.3e} rad/sqrt(s) = {:.3} deg/sqrt(h), VRW {:.3e} m/s/sqrt(s) = {:.0} ug/sqrt(Hz)",
                path.display(),
                if self.grade.is_some() { " instead of the grade's" } else { "" },
                arw,
                arw.to_degrees() * 60.0,
                vrw,
                vrw / crate::io::units::STANDARD_GRAVITY * 1e6
            ));
            if path.exists() && !states_units(path) {
                lines.push(format!(
                    "warning: --noise {}: no `units` entry: its white noises were read in SI (rad/sqrt(s), m/s/sqrt(s)), as `sinsmodel allan --json` writes them; a file in deg/sqrt(h) or ug/sqrt(Hz) must say so in `units` (the values above passed the plausibility range in SI)",
                    path.display()
                ));
            }
            // rad/s/√s → deg/h/√h: × 180/π × 3600 × 60; m/s²/√s → µg/√s: ÷ g × 1e6
            if g > 0.0 {
                lines.push(format!(
                    "gyro bias random walk from --noise: {g:.3e} rad/s/sqrt(s) = {:.3} deg/h/sqrt(h)",
                    g.to_degrees() * 3600.0 * 60.0
                ));
            }
            if a > 0.0 {
                lines.push(format!(
                    "accelerometer bias random walk from --noise: {a:.3e} m/s^2/sqrt(s) = {:.1} ug/sqrt(s)",
                    a / crate::io::units::STANDARD_GRAVITY * 1e6
                ));
            }
        }
        Ok(lines)
    }

    /// The `--prior` options that name spec terms (names or prefixes): (term index, σ in SI),
    /// for explain's candidates (the sensor class of the data).
    pub fn term_priors(&self) -> Result<Vec<(usize, f64)>> {
        use crate::model::generated::common;
        let mut out: Vec<(usize, f64)> = Vec::new();
        if let Some(g) = grade_table(self.grade.as_deref())? {
            out.extend(g.term_sigma.iter().copied().enumerate());
        }
        check_prior_repeats(&self.prior)?;
        for (t, info) in common::TERMS.iter().enumerate() {
            let Some((spec, value)) = prior_for(&self.prior, info.name)? else {
                continue;
            };
            let si = crate::io::units::parse_quantity_as(value, info.unit)
                .map_err(|e| anyhow::anyhow!("--prior `{spec}`: {e}"))?;
            if !(si.is_finite() && si > 0.0) {
                bail!("--prior `{spec}`: a prior σ must be positive and finite");
            }
            if let Some(why) = info.beyond_limit(si).or(info.prior_too_small(si)) {
                bail!("--prior `{spec}`: {}: {why}", info.name);
            }
            out.retain(|x| x.0 != t);
            out.push((t, si));
        }
        Ok(out)
    }

    /// Every `--prior` must name a state of `model` or a spec term (explain's candidates).
    pub fn check_prior_names(&self, model: &Model) -> Result<()> {
        use crate::model::generated::common;
        for spec in &self.prior {
            let (name, _) = prior_parts(spec)?;
            let hit = |n: &str| match name.strip_suffix('*') {
                Some(prefix) => n.starts_with(prefix),
                None => n == name,
            };
            if !model.names.iter().any(|n| hit(n)) && !common::TERMS.iter().any(|t| hit(t.name)) {
                bail!(
                    "--prior `{spec}`: no state `{name}` in {} and no spec term of that name{}",
                    model.name,
                    crate::model::did_you_mean(name.trim_end_matches('*'))
                );
            }
            // a term of an aiding the run does not have is no candidate: its prior would be
            // ignored without a word
            use crate::model::catalog::Sensor;
            if let Some(t) = common::TERMS.iter().find(|t| t.name == name) {
                let missing = match t.sensor {
                    Sensor::Gnss if !self.has_gnss() => Some("a GNSS term; without --aid"),
                    Sensor::Reference if self.body_velocity.is_none() => {
                        Some("a velocity reference's term; without --body-velocity")
                    }
                    Sensor::Attitude if self.attitude.is_none() => {
                        Some("an attitude reference's term; without --attitude")
                    }
                    _ => None,
                };
                if let (Some(m), false) = (missing, model.names.contains(&name)) {
                    bail!("--prior `{spec}`: {name} is {m} it is no candidate and the prior would be ignored");
                }
            }
        }
        Ok(())
    }

    /// `--mode` when given, checked: open or closed.
    pub fn mode_given(&self) -> Result<Option<Mode>> {
        match self.mode.as_deref() {
            None => Ok(None),
            Some("open") => Ok(Some(Mode::OpenLoop)),
            Some("closed") => Ok(Some(Mode::ClosedLoop)),
            Some(m) => bail!("--mode `{m}`: expected open or closed"),
        }
    }

    /// `--step` `s` [s] checked against the IMU's sample interval [s] (`whose`, e.g. "the
    /// IMU's median"): a step shorter than a sample would be the sample's, and one far from a
    /// whole number of samples would silently be the next whole number (the filter ends a step
    /// at the first sample at least `s` after its start: `--step 0.007` on 200 Hz ran 0.01 s).
    pub fn check_step_interval(s: f64, interval: f64, whose: &str) -> Result<()> {
        // (to the microsecond, as a step is given)
        let shown = |x: f64| {
            let t = format!("{x:.6}");
            t.trim_end_matches('0').trim_end_matches('.').to_string()
        };
        let us = shown(interval);
        if s < 0.999 * interval {
            bail!(
                "--step {} s is shorter than {whose} sample interval ({us} s); give --step {us} or more",
                crate::io::units::shown_number(s)
            );
        }
        let k = ((s - 1e-9) / interval).ceil().max(1.0);
        let run = k * interval;
        if run > 1.1 * s {
            bail!(
                "--step {} s is {} of {whose} sample intervals ({us} s): the filter ends a step at a whole sample, so it would step every {} samples ({} s, {} % longer than asked); give --step {} or {}",
                crate::io::units::shown_number(s),
                crate::io::units::shown_number((s / interval * 100.0).round() / 100.0),
                k,
                shown(run),
                ((run / s - 1.0) * 100.0).round(),
                shown((k - 1.0).max(1.0) * interval),
                shown(run)
            );
        }
        Ok(())
    }

    /// `--step` when given, checked: in (0, 1] s (a longer step integrates the error model over
    /// whole manoeuvres with a second-order Φ: milliseconds written as seconds).
    pub fn step_given(&self) -> Result<Option<f64>> {
        match self.step {
            Some(s) if !(s.is_finite() && s > 0.0 && s <= 1.0) => {
                let hint = if s.is_finite() && s > 1.0 {
                    format!(
                        "; a step of {} s spans whole manoeuvres: milliseconds written as seconds? ({} ms is --step {})",
                        crate::io::units::shown_number(s),
                        crate::io::units::shown_number(s),
                        crate::io::units::shown_number(s / 1000.0)
                    )
                } else {
                    String::new()
                };
                bail!(
                    "--step {}: expected a filter step in (0, 1] s{hint}",
                    crate::io::units::shown_number(s)
                )
            }
            s => Ok(s),
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
        cfg.mode = match args.mode_given()? {
            Some(m) => m,
            // a velocity reference's rows hold only to first order about the aided solution
            None if args.body_velocity.is_some() || args.attitude.is_some() => Mode::ClosedLoop,
            None => Mode::OpenLoop,
        };
        cfg.step_s = args.step_given()?.unwrap_or(DEFAULT_STEP_S);
        cfg.known_gnss = args.residual_known()?;
        if !args.has_gnss() {
            if let Some(t) = model.states.iter().find_map(|s| match *s {
                crate::model::catalog::StateRef::Term(k)
                    if common::TERMS[k].sensor == crate::model::catalog::Sensor::Gnss =>
                {
                    Some(common::TERMS[k].name)
                }
                _ => None,
            }) {
                bail!("--model {}: {t} is a GNSS term (it enters the fixes of a GNSS receiver); without --aid there is none", model.name);
            }
        }
        check_reference_terms(model, args)?;
        if !model.vertical {
            cfg.vertical = Vertical::Fixed;
        }
        check_prior_repeats(&args.prior)?;
        for spec in &args.prior {
            let (name, _) = prior_parts(spec)?;
            let pattern = StatePattern::new(name);
            if !lenient_priors && !model.names.iter().any(|n| pattern.matches(n)) {
                bail!(
                    "--prior `{spec}`: no state `{name}` in model {}",
                    model.name
                );
            }
        }
        for i in 0..model.n() {
            let Some((spec, value)) = prior_for(&args.prior, model.names[i])? else {
                continue;
            };
            let si = crate::io::units::parse_quantity_as(value, model.unit(i))
                .map_err(|e| anyhow::anyhow!("--prior `{spec}`: {e}"))?;
            if !(si.is_finite() && si > 0.0) {
                bail!("--prior `{spec}`: a prior σ must be positive and finite");
            }
            if let crate::model::catalog::StateRef::Term(t) = model.states[i] {
                let info = &crate::model::generated::common::TERMS[t];
                if let Some(why) = info.beyond_limit(si).or(info.prior_too_small(si)) {
                    bail!("--prior `{spec}`: {}: {why}", info.name);
                }
            }
            if model.names[i].starts_with("phi_") && si >= MAX_ATTITUDE_PRIOR_RAD {
                bail!(
                    "--prior `{spec}`: {}: a 1-σ of {:.1} deg is not a small attitude error; the error model is linear in small angles (sin φ ≈ φ) and means nothing at 90° or more: give the attitude in --init (`sinsmodel align`, or --init auto for the heading) and a prior below 90 deg",
                    model.names[i],
                    si.to_degrees()
                );
            }
            cfg.prior_sigma[i] = si;
        }
        if let Some(path) = &args.noise {
            let n = noise_given(path)?;
            cfg = cfg.with_sensor_noise(model, n.arw, n.vrw);
            if n.gyro_bias_rw > 0.0 || n.accel_bias_rw > 0.0 {
                cfg = cfg.with_bias_random_walk(model, n.gyro_bias_rw, n.accel_bias_rw);
            }
        }
        Ok(cfg)
    }
}

/// The noise `--noise` gives (SI).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NoiseGiven {
    /// Gyro white noise (angle random walk) [rad/√s].
    pub arw: f64,
    /// Accelerometer white noise (velocity random walk) [m/s/√s].
    pub vrw: f64,
    /// Gyro bias random walk (bias instability) [rad/s/√s]; 0 when not given (inline only).
    pub gyro_bias_rw: f64,
    /// Accelerometer bias random walk [m/s²/√s]; 0 when not given (inline only).
    pub accel_bias_rw: f64,
}

/// The noise `--noise` gives: inline `arw=Q, vrw=Q[, gyro_bias_rw=Q, accel_bias_rw=Q]` with
/// units, or an `allan --json` file (its white noise, the RMS over the three axes).
pub fn noise_given(path: &std::path::Path) -> Result<NoiseGiven> {
    let text = path.to_string_lossy();
    if text.contains('=') && !path.exists() {
        return noise_inline(&text);
    }
    let (arw, vrw) = white_noise_of_allan_json(path)?;
    Ok(NoiseGiven {
        arw,
        vrw,
        gyro_bias_rw: 0.0,
        accel_bias_rw: 0.0,
    })
}

/// True when the noise file at `path` (read and checked already) has a `units` entry.
fn states_units(path: &std::path::Path) -> bool {
    crate::io::lines::read_small_text(path, "--noise")
        .ok()
        .and_then(|t| serde_json::from_str::<serde_json::Value>(&t).ok())
        .is_some_and(|v| !v["units"].is_null())
}

/// Gyro ARW [rad/√s] and accelerometer VRW [m/s/√s] of an `allan --json` file (the RMS over
/// the three axes: √((x² + y² + z²)/3)), each checked for a plausible size.
fn white_noise_of_allan_json(path: &std::path::Path) -> Result<(f64, f64)> {
    let text = crate::io::lines::read_small_text(path, "--noise")
        .with_context(|| format!("--noise {}: cannot read the file", path.display()))?;
    let v: serde_json::Value = serde_json::from_str(&text).with_context(|| {
        format!(
            "--noise {}: not valid JSON (expected the output of `sinsmodel allan --json`)",
            path.display()
        )
    })?;
    crate::io::json_unique::check(&text)
        .map_err(|e| anyhow::anyhow!("--noise {}: {e}", path.display()))?;
    let white = |names: [&str; 3]| -> Result<f64> {
        let mut s = 0.0;
        for n in names {
            let field = &v["fit"][n]["white"];
            let w_given = field.as_f64().with_context(|| {
                format!(
                    "--noise {}: fit.{n}.white {} (expected a number: the output of `sinsmodel allan --json`)",
                    path.display(),
                    if field.is_null() { "is missing or null (the fit was not determined)".to_string() } else { format!("is {field}, not a number") }
                )
            })?;
            let gyro = n.starts_with("gyro");
            let w = w_given * white_unit_scale(path, &v, n, gyro)?;
            let (min, max) = noise_range(gyro);
            if !(w.is_finite() && w >= min && w <= max) {
                bail!(
                    "--noise {}: fit.{n}.white = {w_given} ({w:e} SI) is not a plausible noise density ({min:e} ≤ w ≤ {max} SI: rad/√s for gyros, m/s/√s for accelerometers)",
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

/// The factor to SI (rad/√s for a gyro, m/s/√s for an accelerometer) of channel `n`'s white
/// noise in an allan JSON `v`, from its `units` entry: allan's `rad/s (fit: white rad/sqrt(s),
/// …)`, the same with other units (`deg/h (fit: white deg/sqrt(h), …)`), or the white noise's
/// unit alone; 1 (SI, as allan writes) when the file has no `units`. A missing entry beside
/// others, or a unit that is not a noise density of the channel's kind, is refused, naming the
/// file and key.
fn white_unit_scale(
    path: &std::path::Path,
    v: &serde_json::Value,
    n: &str,
    gyro: bool,
) -> Result<f64> {
    let si = if gyro { "rad/sqrt(s)" } else { "m/s/sqrt(s)" };
    if v["units"].is_null() {
        return Ok(1.0);
    }
    let entry = &v["units"][n];
    if entry.is_null() {
        bail!(
            "--noise {}: units has no entry for {n} while it has some: give every channel's unit (as `sinsmodel allan --json` writes), or none for SI ({si})",
            path.display()
        );
    }
    let text = entry.as_str().with_context(|| {
        format!(
            "--noise {}: units.{n} is {entry}, not a unit (expected e.g. `{si}`)",
            path.display()
        )
    })?;
    // `… (fit: white UNIT, random_walk …)` or the unit alone
    let mut unit = match text.split_once("white") {
        Some((_, rest)) => rest.split(',').next().unwrap_or("").trim(),
        None => text.trim(),
    };
    // the `)` that closes `(fit: …` when white is its last entry
    while unit.matches(')').count() > unit.matches('(').count() {
        unit = unit[..unit.len() - 1].trim_end();
    }
    crate::io::units::parse_quantity_as(&format!("1 {unit}"), si).map_err(|e| {
        anyhow::anyhow!(
            "--noise {}: units.{n} `{}`: the white noise's unit `{}` is not a {} noise density like {si} ({})",
            path.display(),
            crate::io::lines::shown(text),
            crate::io::lines::shown(unit),
            if gyro { "gyro" } else { "accelerometer" },
            e.0
        )
    })
}

/// `arw=0.3 deg/sqrt(h), vrw=150 ug/sqrt(Hz)`: both required, each checked like the file's;
/// `gyro_bias_rw`, `accel_bias_rw` optional.
pub(crate) fn noise_inline(text: &str) -> Result<NoiseGiven> {
    let [arw, vrw, g, a] = noise_inline_all(text)?;
    match (arw, vrw) {
        (Some(arw), Some(vrw)) => Ok(NoiseGiven {
            arw,
            vrw,
            gyro_bias_rw: g.unwrap_or(0.0),
            accel_bias_rw: a.unwrap_or(0.0),
        }),
        _ => bail!("--noise `{text}`: give both arw and vrw, e.g. 'arw=0.3 deg/sqrt(h), vrw=150 ug/sqrt(Hz)'"),
    }
}

/// The inline `--noise` values (SI): arw, vrw, gyro_bias_rw, accel_bias_rw, each checked for
/// its unit and a plausible size.
fn noise_inline_all(text: &str) -> Result<[Option<f64>; 4]> {
    let (mut arw, mut vrw, mut grw, mut abrw) = (None, None, None, None);
    for part in text.split(',').map(str::trim).filter(|p| !p.is_empty()) {
        let (k, v) = part
            .split_once('=')
            .with_context(|| format!("--noise `{part}`: expected arw=QUANTITY or vrw=QUANTITY"))?;
        let (slot, unit, (min, max)) = match k.trim() {
            "arw" => (&mut arw, "rad/sqrt(s)", noise_range(true)),
            "vrw" => (&mut vrw, "m/s/sqrt(s)", noise_range(false)),
            // 1e-12 rad/s/√s (0.0002 deg/h/√h) ..= 1e-3 (200000 deg/h/√h)
            "gyro_bias_rw" => (&mut grw, "rad/s/sqrt(s)", (1e-12, 1e-3)),
            // 1e-9 m/s²/√s (0.1 µg/√s) ..= 0.1 (10 mg/√s)
            "accel_bias_rw" => (&mut abrw, "m/s^2/sqrt(s)", (1e-9, 0.1)),
            other => {
                bail!("--noise: unknown key `{other}` (arw, vrw, gyro_bias_rw, accel_bias_rw)")
            }
        };
        let q = crate::io::units::parse_quantity_as(v, unit)
            .map_err(|e| anyhow::anyhow!("--noise {}: {}", k.trim(), e.0))?;
        if !(q.is_finite() && q >= min && q <= max) {
            bail!(
                "--noise {}: {} is not a plausible noise density ({min:e} ..= {max} {unit})",
                k.trim(),
                v.trim()
            );
        }
        if slot.replace(q).is_some() {
            bail!("--noise: `{}` given twice", k.trim());
        }
    }
    Ok([arw, vrw, grw, abrw])
}

/// Plausible white-noise densities (SI): gyro ARW 1e-9 ..= 1 rad/√s (the best ring-laser gyros
/// are near 3e-7), accelerometer VRW 1e-7 ..= 100 m/s/√s (0.01 µg/√Hz upward).
fn noise_range(gyro: bool) -> (f64, f64) {
    // the worst MEMS parts: a few deg/√h, a few hundred µg/√Hz; the bounds are 100× beyond
    // (0.1 rad/√s = 344 deg/√h, 1 m/s/√s = 102 mg/√Hz), so a value in µg/√Hz or deg/√h read
    // as SI is refused
    if gyro {
        (1e-9, 0.1)
    } else {
        (1e-7, 1.0)
    }
}

/// A `--prior` option's name and quantity, trimmed: refused without `=`, without a name before
/// it or without a quantity after it.
fn prior_parts(spec: &str) -> Result<(&str, &str)> {
    let (name, value) = spec
        .split_once('=')
        .with_context(|| format!("--prior `{spec}`: expected NAME=QUANTITY"))?;
    let (name, value) = (name.trim(), value.trim());
    if name.is_empty() {
        bail!("--prior `{spec}`: the term name is missing before `=` (NAME=QUANTITY, e.g. `tau_x=2 ms`)");
    }
    if value.is_empty() {
        bail!("--prior `{spec}`: the quantity is missing after `=` (NAME=QUANTITY, e.g. `{name}=2 ms`)");
    }
    Ok((name, value))
}

/// Largest attitude prior 1-σ [rad] (90°): the error model is linear in small angles.
const MAX_ATTITUDE_PRIOR_RAD: f64 = std::f64::consts::FRAC_PI_2;

/// Refuses a `--prior` name (or prefix) given twice, naming both values: which one was meant
/// is not for the tool to guess.
fn check_prior_repeats(specs: &[String]) -> Result<()> {
    for (k, spec) in specs.iter().enumerate() {
        let (name, value) = prior_parts(spec)?;
        for earlier in &specs[..k] {
            let (n0, v0) = prior_parts(earlier)?;
            if n0 == name {
                bail!("--prior {name} given twice: `{v0}` and `{value}`; give it once");
            }
        }
    }
    Ok(())
}

/// The `--prior` (spec, quantity) that sets state `name`: the most specific that matches — the
/// exact name over any prefix, a longer prefix over a shorter (`eps_x=1 deg/h` wins over
/// `eps_*=10 deg/h` whatever their order). Names are unique ([`check_prior_repeats`]), so no
/// two matches are equally specific.
pub(super) fn prior_for<'a>(specs: &'a [String], name: &str) -> Result<Option<(&'a str, &'a str)>> {
    let mut best: Option<(usize, &str, &str)> = None;
    for spec in specs {
        let (pattern, value) = prior_parts(spec)?;
        if !StatePattern::new(pattern).matches(name) {
            continue;
        }
        let specificity = match pattern.strip_suffix('*') {
            Some(prefix) => prefix.len(),
            None => usize::MAX,
        };
        if best.is_none_or(|b| specificity > b.0) {
            best = Some((specificity, spec.as_str(), value));
        }
    }
    Ok(best.map(|(_, spec, value)| (spec, value)))
}

/// A model's velocity-reference terms (mounting) need `--body-velocity`, and a reference given
/// needs a model that forms its measurement (`vel_body` rows reference dv_d: `+vertical`).
fn check_reference_terms(model: &Model, args: &DataOptions) -> Result<()> {
    use crate::model::catalog::{Sensor, StateRef};
    let reference_term = model.states.iter().find_map(|s| match *s {
        StateRef::Term(k) if common::TERMS[k].sensor == Sensor::Reference => {
            Some(common::TERMS[k].name)
        }
        _ => None,
    });
    match (&args.body_velocity, reference_term) {
        (None, Some(t)) => bail!(
            "--model {}: {t} is a mounting of a velocity reference (it enters the body-frame velocity measurement); without --body-velocity there is none",
            model.name
        ),
        (Some(p), _) if !model.measurements().iter().any(|m| m.name == "vel_body") => bail!(
            "--body-velocity {}: model {} cannot use it: the body-frame velocity measurement needs the vertical channel (write the model with +vertical, e.g. P13+vertical)",
            p.display(),
            model.name
        ),
        _ => Ok::<(), anyhow::Error>(()),
    }?;
    let attitude_term = model.states.iter().find_map(|s| match *s {
        StateRef::Term(k) if common::TERMS[k].sensor == Sensor::Attitude => {
            Some(common::TERMS[k].name)
        }
        _ => None,
    });
    if let (None, Some(t)) = (&args.attitude, attitude_term) {
        bail!(
            "--model {}: {t} is a mounting of an attitude reference (it enters the attitude measurement); without --attitude there is none",
            model.name
        );
    }
    Ok(())
}

/// The `--mounting R,P,Y` values as (term, value [rad]): bare numbers are degrees, a unit may be
/// given (`10 mrad`); each within the terms' small-angle limit (10°).
fn known_mounting(m: &[String]) -> Result<Vec<(usize, f64)>> {
    if m.len() != 3 {
        bail!(
            "--mounting: expected ROLL,PITCH,YAW of the reference against the IMU body frame in degrees, got {} values",
            m.len()
        );
    }
    let mut out = Vec::new();
    for (item, name) in m.iter().zip(["mount_x", "mount_y", "mount_z"]) {
        let item = item.trim();
        let v = match item.parse::<f64>() {
            Ok(v) => v.to_radians(),
            Err(_) => crate::io::units::parse_quantity_as(item, "rad").with_context(|| {
                format!("--mounting: {name} = `{item}`: expected degrees (`1.5`) or an angle with its unit (`26 mrad`)")
            })?,
        };
        let k = term(name, "--mounting")?;
        if !v.is_finite() {
            bail!("--mounting: {name} = `{item}` is {}", finite_words(v));
        }
        if let Some(why) = common::TERMS[k].beyond_limit(v) {
            bail!("--mounting: {name} = `{item}`: {why}; a mounting this large is no small misalignment: rotate the reference's velocities into the IMU's axes first");
        }
        out.push((k, v));
    }
    Ok(out)
}

/// The index of spec term `name`, which `option` gives a value of.
fn term(name: &str, option: &str) -> Result<usize> {
    common::TERMS
        .iter()
        .position(|t| t.name == name)
        .with_context(|| format!("{option}: the spec has no term `{name}` (model-spec/terms.toml)"))
}

/// Why a value that is not finite is refused: NaN is no number, ±∞ (or a literal beyond
/// 1.8e308, which parses to ∞) no finite value.
fn finite_words(v: f64) -> &'static str {
    if v.is_nan() {
        "not a number"
    } else {
        "beyond the largest number (±1.8e308) or infinite"
    }
}
