//! Explain in words: regressor degree and signals, separation hints, findings, the summary.

use super::findings::{Explanation, Finding};
use super::G0;
pub use crate::io::units::sig3;
use crate::model::catalog::Sensor;
use crate::model::generated::common;
use crate::model::ImuSignals;
use nalgebra::Vector3;

/// Homogeneous degree of a regressor in the IMU signals (1 for f_x, |f_x|; 2 for f_x², f_x f_y,
/// ω², ω̇; 0 for a constant), found numerically (ω̇ scales as ω² does, ḟ as f ω: a faster
/// motion).
pub(super) fn regressor_degree(id: usize) -> i32 {
    let s = base_signals();
    let r1 = common::regressor_value(id, &s);
    let s2 = ImuSignals {
        f: s.f * 2.0,
        w: s.w * 2.0,
        dw: s.dw * 4.0,
        df: s.df * 4.0,
    };
    let r2 = common::regressor_value(id, &s2);
    if r1 == 0.0 || r2 == 0.0 {
        return 0;
    }
    (r2 / r1).abs().log2().round() as i32
}

/// A generic point of the IMU signals for probing regressors.
fn base_signals() -> ImuSignals {
    ImuSignals {
        f: Vector3::new(3.1, -2.3, 1.7),
        w: Vector3::new(0.7, -0.4, 0.9),
        dw: Vector3::new(0.3, 0.8, -0.6),
        df: Vector3::new(-1.1, 0.5, 2.2),
    }
}

/// Which body signals a regressor depends on (`f.x` … `w.z`, `dw.x` … `df.z`).
pub(super) fn regressor_signals(id: usize) -> Vec<&'static str> {
    let names = [
        "f.x", "f.y", "f.z", "w.x", "w.y", "w.z", "dw.x", "dw.y", "dw.z", "df.x", "df.y", "df.z",
    ];
    let base = base_signals();
    let r0 = common::regressor_value(id, &base);
    (0..12)
        .filter(|&k| {
            let mut s = base;
            let v = match k / 3 {
                0 => &mut s.f,
                1 => &mut s.w,
                2 => &mut s.dw,
                _ => &mut s.df,
            };
            v[k % 3] *= 1.37;
            (common::regressor_value(id, &s) - r0).abs() > 1e-12 * r0.abs().max(1.0)
        })
        .map(|k| names[k])
        .collect()
}

/// What excitation would separate two terms, from their sensors and regressors.
pub fn separation_hint(a: usize, b: usize) -> String {
    let (ta, tb) = (&common::TERMS[a], &common::TERMS[b]);
    let (da, db) = (
        regressor_degree(ta.regressor),
        regressor_degree(tb.regressor),
    );
    let (sa, sb) = (
        regressor_signals(ta.regressor),
        regressor_signals(tb.regressor),
    );
    let ra = common::REGRESSORS[ta.regressor];
    let rb = common::REGRESSORS[tb.regressor];
    if ta.sensor.enters_h() || tb.sensor.enters_h() {
        return format!(
            "{} and {} act on the aiding through the velocity, acceleration or attitude at each one: turns and speed changes in other directions, or a longer run with them, separate them",
            ta.name, tb.name
        );
    }
    if ta.sensor != tb.sensor {
        return format!(
            "a {} term and a {} term: a longer run or a re-orientation separates them (a gyro error grows the tilt ∝ t after onset, an accelerometer error the velocity)",
            sensor_word(ta.sensor),
            sensor_word(tb.sensor)
        );
    }
    if sa != sb {
        let only = |x: &[&str], y: &[&str]| -> Vec<String> {
            x.iter()
                .filter(|s| !y.contains(s))
                .map(|s| s.to_string())
                .collect()
        };
        let mut diff = only(&sa, &sb);
        diff.extend(only(&sb, &sa));
        return format!(
            "an excitation that changes {} while the other signals stay (a re-orientation, or vibration along that axis) separates {} ({ra}) from {} ({rb})",
            diff.join(" and "),
            ta.name,
            tb.name
        );
    }
    if da != db {
        return format!(
            "two vibration amplitudes separate {} (∝ A^{da}, regressor {ra}) from {} (∝ A^{db}, regressor {rb})",
            ta.name, tb.name
        );
    }
    if ta.axis != tb.axis {
        return format!(
            "a re-orientation (another attitude) separates the {} and {} axes",
            ["x", "y", "z"][ta.axis],
            ["x", "y", "z"][tb.axis]
        );
    }
    format!(
        "an excitation where {ra} and {rb} are not proportional (e.g. a sign change: attitude or vibration phase)"
    )
}

pub(super) fn sensor_word(s: Sensor) -> &'static str {
    match s {
        Sensor::Gyro => "gyro",
        Sensor::Accel => "accelerometer",
        Sensor::Gnss => "GNSS",
        Sensor::Reference => "velocity reference",
        Sensor::Attitude => "attitude reference",
    }
}

/// Mean regressor in natural units: g^k (accelerations) or (deg/s)^k (rates); with its unit.
pub(super) fn regressor_in_natural_units(id: usize, mean_si: f64) -> (f64, String) {
    let deg = regressor_degree(id);
    let sig = regressor_signals(id);
    if deg == 0 {
        return (mean_si, "1".into());
    }
    if sig.iter().all(|s| s.starts_with('f')) {
        (
            mean_si / G0.powi(deg),
            if deg == 1 {
                "g".into()
            } else {
                format!("g^{deg}")
            },
        )
    } else if sig.iter().all(|s| s.starts_with('w')) {
        let d = std::f64::consts::PI / 180.0;
        (
            mean_si / d.powi(deg),
            if deg == 1 {
                "deg/s".into()
            } else {
                format!("(deg/s)^{deg}")
            },
        )
    } else {
        (mean_si, "SI".into())
    }
}

/// A term finding in words: (its headline — what it is and its value —, the whole text, which
/// begins with the headline).
pub(super) fn finding_words(
    f: &Finding,
    info: &crate::model::catalog::TermInfo,
    prior_display: f64,
) -> (String, String) {
    if info.sensor.enters_h() {
        return gnss_finding_words(f, info);
    }
    let sensor = sensor_word(info.sensor);
    let axis = ["x", "y", "z"][info.axis];
    let reg = common::REGRESSORS[info.regressor];
    let group = info
        .group
        .trim_start_matches("accel ")
        .trim_start_matches("accelerometer ")
        .trim_start_matches("gyro ");
    let bias = if info.sensor == Sensor::Accel {
        "bias"
    } else {
        "drift"
    };
    let headline = format!(
        "{sensor} {axis} {group} {} = {} ± {} {}",
        f.term,
        sig3(f.estimate),
        sig3(f.sigma),
        f.unit,
    );
    let mut s = if crate::model::regressor_reads(info.regressor, &["dw", "df"]) {
        // a regressor of the signals' rates of change averages to nothing over a run: the term
        // acts while the motion changes, not as a constant
        format!(
            "{headline} (extended filter): it acts while the motion changes (regressor {reg}), not as a constant {bias}"
        )
    } else if f.excited_fraction < 0.9 && f.effect_excited.abs() > 1.5 * f.effect.abs() {
        // a regressor excited over part of the run: its effect there, not diluted by the rest
        format!(
            "{headline} (extended filter): where {reg} is excited ({} % of the run) it averages {} {}, and the term acts as a {} {} {bias} along {axis} there ({} {} over the whole run)",
            sig3(100.0 * f.excited_fraction),
            sig3(f.regressor_excited_mean),
            f.regressor_unit,
            sig3(f.effect_excited),
            f.effect_unit,
            sig3(f.effect),
            f.effect_unit,
        )
    } else {
        format!(
            "{headline} (extended filter): with the data's mean {reg} of {} {} it acts as a {} {} {bias} along {axis}",
            sig3(f.regressor_mean),
            f.regressor_unit,
            sig3(f.effect),
            f.effect_unit,
        )
    };
    if !f.equivalent.is_empty() {
        let others: Vec<String> = f
            .equivalent_estimates
            .iter()
            .map(|e| {
                format!(
                    "{} (would need {} ± {} {} by the signatures, {} prior σ)",
                    e.term,
                    sig3(e.estimate),
                    sig3(e.sigma),
                    e.unit,
                    sig3(e.prior_sigmas.abs())
                )
            })
            .collect();
        // an unattributed class names nothing: the priors that would choose do not fit
        let named = if f.not_attributed.is_some() {
            format!("none named; {} stands for the class", f.term)
        } else {
            "named: the one the spec's priors find most plausible".to_string()
        };
        s.push_str(&format!(
            "; the data cannot separate it from {} (equivalence class; {named}); {}",
            others.join(", "),
            f.separate_by.join("; ")
        ));
    }
    if f.prior_widened && f.stand_in.is_none() {
        s.push_str(&format!(
            "; at {} prior σ ({} {}) the extended filter starts it with σ {} {} (`--prior '{}={} {}'`)",
            sig3(f.estimate.abs() / prior_display),
            sig3(prior_display),
            f.unit,
            sig3(f.prior_sigma),
            f.unit,
            f.term,
            sig3(f.prior_sigma),
            f.unit
        ));
    }
    if let Some(b) = &f.confounded_with {
        s.push_str(&format!(
            "; on these data its regressor is proportional to that of the baseline term {b}, so part of it may be taken up there"
        ));
    }
    s.push_str(&share_and_stand_in(
        f,
        ": noise stated too small, an aiding error or a sensor effect outside the library fit sensor terms this way; do not read it as a property of the sensor",
    ));
    (headline, s)
}

/// The tail every term finding's words end with: the share of the misfit it explains and, for a
/// stand-in, why (then `what_else`).
fn share_and_stand_in(f: &Finding, what_else: &str) -> String {
    let mut s = String::new();
    if let Some(share) = f.misfit_share {
        s.push_str(&format!(
            "; it explains {} % of the baseline's excess misfit (2Δℓ {})",
            share_percent(share),
            sig3(f.two_delta_loglik)
        ));
    }
    if let (Some(why), Some([d, sd])) = (&f.stand_in, f.offset_in_place) {
        s.push_str(&format!(
            ". It probably stands in for an IMU–GNSS time offset of {} ± {} ms ({why}){what_else}",
            sig3(d),
            sig3(sd)
        ));
    } else if let Some(why) = &f.stand_in {
        s.push_str(&format!(
            ". It probably stands in for an effect the candidates do not describe ({why}){what_else}"
        ));
        if let Some(p) = f.suggested_prior {
            s.push_str(&format!(
                ". Yet it holds across the data and explains most of the misfit: if this sensor can have such a value, give --prior '{}={} {}' (a prior that holds it) and run again",
                f.term,
                sig3(p),
                f.unit
            ));
        }
    } else if let Some(why) = &f.not_attributed {
        s.push_str(&format!(
            ". No member of its class is named as the cause: {why}"
        ));
    }
    s
}

/// A GNSS term's finding in words: what it is, its value, and the shared tail (class, share
/// of the misfit, stand-in).
fn gnss_finding_words(f: &Finding, info: &crate::model::catalog::TermInfo) -> (String, String) {
    let headline = format!(
        "{} {} = {} ± {} {}",
        info.group,
        f.term,
        sig3(f.estimate),
        sig3(f.sigma),
        f.unit,
    );
    let mut s = format!("{headline} (extended filter; {})", info.doc);
    if info.sensor == Sensor::Reference && info.unit == "rad" {
        // the data cannot tell a reference turned by +m from one whose axis is written negated
        s.push_str(&format!(
            "; the angle of the reference's axes against the IMU's, both read as forward-right-down: a reference file whose {} column has the other sign gives the same data with the angle's sign reversed",
            match info.name {
                "mount_y" => "vz",
                "mount_z" => "vy",
                _ => "vy or vz",
            }
        ));
    }
    if info.sensor == Sensor::Attitude && info.unit == "rad" {
        s.push_str(
            "; the reference's axes are turned by this angle against the IMU's (on a level vehicle it reads its roll, pitch or yaw larger by it): rotate the reference's output back by it, or keep the term in the model",
        );
    }
    if !f.equivalent.is_empty() {
        let others: Vec<String> = f
            .equivalent_estimates
            .iter()
            .map(|e| {
                format!(
                    "{} (would need {} ± {} {})",
                    e.term,
                    sig3(e.estimate),
                    sig3(e.sigma),
                    e.unit
                )
            })
            .collect();
        s.push_str(&format!(
            "; the data cannot separate it from {}; {}",
            others.join(", "),
            f.separate_by.join("; ")
        ));
    }
    s.push_str(&share_and_stand_in(f, ""));
    (headline, s)
}

pub(super) fn channel_word(c: &str) -> String {
    match c {
        "vel_n" => "north velocity".into(),
        "vel_e" => "east velocity".into(),
        "pos_n" => "north position".into(),
        "pos_e" => "east position".into(),
        "pos_h" => "height".into(),
        "vel_bx" => "forward velocity (reference)".into(),
        "vel_by" => "right velocity (reference)".into(),
        "vel_bz" => "down velocity (reference)".into(),
        "att_n" => "north tilt (attitude reference)".into(),
        "att_e" => "east tilt (attitude reference)".into(),
        "att_d" => "heading (attitude reference)".into(),
        other => other.to_string(),
    }
}

/// The plain-words summary: what the baseline gets wrong, what was found, the gain.
pub(super) fn summary(e: &Explanation) -> Vec<String> {
    let mut out = Vec::new();
    tight_priors_words(e, &mut out);
    let t_ref = time_reference(e);
    baseline_consistency_words(e, t_ref, &mut out);
    findings_words(e, &mut out);
    left_over_words(e, t_ref, &mut out);
    not_named_words(e, &mut out);
    out
}

/// The summary's line on baseline priors the data find too tight (and whether they were widened).
fn tight_priors_words(e: &Explanation, out: &mut Vec<String>) {
    if !e.baseline_priors_tight.is_empty() {
        let w = &e.baseline_priors_tight;
        let values = w
            .iter()
            .map(tight_prior_words)
            .collect::<Vec<_>>()
            .join("; ");
        let options = format!(
            "{} (each 3× the estimate's magnitude, rounded up to one significant digit)",
            w.iter()
                .map(|p| format!("--prior '{}={} {}'", p.term, sig3(p.suggested), p.unit))
                .collect::<Vec<_>>()
                .join(" ")
        );
        let gain = sig3(e.baseline_priors_gain.unwrap_or(0.0));
        // the check runs on the model explain recommends: the baseline plus its causes
        let with = if e.findings.iter().any(|f| f.is_cause() && f.kind != "noise") {
            "even with the findings added"
        } else {
            "with no term added"
        };
        out.push(if e.baseline_priors_widened {
            format!(
                "The baseline's priors are too tight for these data: {with}, {values}. Either this sensor's errors are larger than its grade's priors (then give these priors, or the --grade of your sensor, yourself), or an effect the candidates do not describe acts through these terms (at rest a constant error of the specific force or rate looks like a bias); the data alone cannot tell which. A baseline held to priors the data reject is biased and its bias would be explained, so explain ran again with {options}: the baseline's log-likelihood rises by 2Δℓ {gain}, and what follows is that run; a term it finds beside these widened ones may be what they took up."
            )
        } else {
            format!(
                "{}{} {values}; but widening those priors ({options}) does not raise the baseline's likelihood enough (2Δℓ {gain}): the data do not ask for them, and what follows keeps the priors as given. Such values usually pair with a term fitted beside them (see the stand-ins below).",
                with[..1].to_uppercase(),
                &with[1..]
            )
        });
    }
}

/// One baseline prior the data find too tight: its estimate and how many of its prior σ that is.
pub(super) fn tight_prior_words(p: &super::findings::TightPrior) -> String {
    format!(
        "{} = {} ± {} {} is {}× its prior σ of {} {}",
        p.term,
        sig3(p.estimate),
        sig3(p.sigma),
        p.unit,
        sig3(p.prior_sigmas),
        sig3(p.prior),
        p.unit
    )
}

/// A mean NIS for the summary's comparisons with 1 and with each other: four significant
/// digits (1.012 → 1.004, where three would print 1.01 → 1.00).
pub(super) fn nis_text(v: f64) -> String {
    let a = v.abs();
    if !v.is_finite() || a == 0.0 || !(1e-3..1e5).contains(&a) {
        return if v.is_finite() && a != 0.0 {
            format!("{v:.3e}")
        } else {
            sig3(v)
        };
    }
    let decimals = (3 - a.log10().floor() as i32).max(0) as usize;
    format!("{v:.decimals$}")
}

/// A finding's share of the baseline's excess misfit in percent for the words: none (0) when
/// its round raised the misfit instead.
pub fn share_percent(share: f64) -> String {
    sig3(100.0 * share.max(0.0))
}

/// A finding's verdict as the summary opens its line: `Found`, `Fitted, but not a cause` (a
/// stand-in) or `Fitted, not attributed`.
pub fn verdict(f: &Finding) -> &'static str {
    if f.stand_in.is_some() {
        "Fitted, but not a cause"
    } else if f.not_attributed.is_some() {
        "Fitted, not attributed"
    } else {
        "Found"
    }
}

/// A finding's line in the summary: its verdict and its words.
pub fn finding_line(f: &Finding) -> String {
    format!("{}: {}.", verdict(f), f.words)
}

/// A p-value for the words: three significant digits, "< 1e-16" below double precision's
/// resolution of 1 − p (where it is 0 or a rounding residue).
fn p_text(p: f64) -> String {
    if p < 1e-16 {
        "< 1e-16".into()
    } else {
        sig3(p)
    }
}

/// The time [s] the summary counts data times from: the first update's whole second when the
/// times are large (GPS seconds on real data), else 0.
fn time_reference(e: &Explanation) -> f64 {
    // data times (GPS seconds on real data) are counted from the first update when large
    if e.baseline.t_start.abs() > 1e5 {
        e.baseline.t_start.floor()
    } else {
        0.0
    }
}

/// Channel `ch`'s Ljung–Box p after Bonferroni over `channels` channels, when it fails at 0.01.
fn correlated_p(ch: &super::diagnostics::ChannelStats, channels: usize) -> Option<f64> {
    ch.whiteness_p
        .map(|p| (p * channels as f64).min(1.0))
        .filter(|p| *p <= 0.01)
}

/// The summary's lines on where the baseline misfits the data (innovations too large, correlated
/// or too small), or that it is consistent; times from `t_ref` [s].
fn baseline_consistency_words(e: &Explanation, t_ref: f64, out: &mut Vec<String>) {
    let mut consistent = true;
    let first = out.len();
    for ch in &e.baseline.channels {
        let too_large = ch.nis_mean > ch.nis_band[1] * 1.5;
        let correlated = correlated_p(ch, e.baseline.channels.len());
        if !too_large && correlated.is_none() {
            continue;
        }
        consistent = false;
        let worst = ch
            .segments
            .iter()
            .max_by(|a, b| a.nis_mean.total_cmp(&b.nis_mean));
        let also = correlated
            .map(|p| {
                format!(
                    "; they are also correlated in time (Ljung–Box p {} after Bonferroni)",
                    p_text(p)
                )
            })
            .unwrap_or_default();
        let from = if t_ref != 0.0 {
            " from the first update"
        } else {
            ""
        };
        match (too_large, worst) {
            (true, Some(sg)) if sg.nis_mean > ch.nis_band[1] => out.push(format!(
                "{} innovations are {}× larger than the model predicts during {:.0}–{:.0} s{from} (mean NIS {}), biased by {:+.1}σ{also}; the model does not explain the data there.",
                channel_word(&ch.channel),
                sig3(sg.nis_mean.sqrt()),
                sg.t0 - t_ref,
                sg.t1 - t_ref,
                sig3(sg.nis_mean),
                sg.bias_sigma
            )),
            (true, _) => out.push(format!(
                "{} innovations are {}× larger than the model predicts over the run (mean NIS {}){also}.",
                channel_word(&ch.channel),
                sig3(ch.nis_mean.sqrt()),
                sig3(ch.nis_mean)
            )),
            // correlated and far too small: a filter given more noise than the data carry
            // corrects slowly, which alone correlates its innovations
            (false, _) if ch.nis_mean < 0.5 * ch.nis_band[0] => out.push(format!(
                "{} innovations are {}× smaller than the model predicts (mean NIS {}, 95 % band {}–{}) and correlated in time (Ljung–Box p {} after Bonferroni over the channels): its measurement or process noise is set too high for these data. A filter given more noise than the data carry corrects slowly, which alone correlates its innovations, so whether a slow effect is there too cannot be told until the noise is right (--noise, --grade, or the aiding's σ).",
                channel_word(&ch.channel),
                sig3((1.0 / ch.nis_mean.max(1e-12)).sqrt()),
                sig3(ch.nis_mean),
                sig3(ch.nis_band[0]),
                sig3(ch.nis_band[1]),
                correlated.map(p_text).unwrap_or_default(),
            )),
            // the whiteness test failed and the size is not too large: say where the size lies
            (false, _) => {
                let size = if ch.nis_mean < ch.nis_band[0] {
                    "their size is below what the model predicts"
                } else if ch.nis_mean > ch.nis_band[1] {
                    "their size is somewhat above what the model predicts"
                } else {
                    "their size is what the model predicts"
                };
                out.push(format!(
                    "{} innovations are correlated in time (Ljung–Box p {} after Bonferroni over the channels); {size} (mean NIS {}, 95 % band {}–{}): the model misses a slow effect.",
                    channel_word(&ch.channel),
                    correlated.map(p_text).unwrap_or_default(),
                    sig3(ch.nis_mean),
                    sig3(ch.nis_band[0]),
                    sig3(ch.nis_band[1])
                ))
            }
        }
    }
    for ch in &e.baseline.channels {
        // (a correlated one was said above, with why it is correlated)
        let said = correlated_p(ch, e.baseline.channels.len()).is_some();
        if ch.nis_mean < 0.5 * ch.nis_band[0] && !said {
            consistent = false;
            out.push(format!(
                "{} innovations are {}× smaller than the model predicts (mean NIS {}): its measurement or process noise is set too high for these data.",
                channel_word(&ch.channel),
                sig3((1.0 / ch.nis_mean.max(1e-12)).sqrt()),
                sig3(ch.nis_mean)
            ));
        }
    }
    // (each line is about the baseline's innovations, not the extended model's)
    for line in &mut out[first..] {
        *line = format!("Baseline {}: {line}", e.baseline_model);
    }
    if consistent {
        out.push(format!(
            "The baseline {} is consistent with the data: mean NIS {} and white innovations in every channel.",
            e.baseline_model,
            nis_text(e.baseline.nis_mean)
        ));
    }
}

/// The summary's lines on the findings: none significant, each one, and the extended model's gain.
fn findings_words(e: &Explanation, out: &mut Vec<String>) {
    if e.findings.is_empty() {
        let nameable = e
            .candidates
            .iter()
            .filter(|c| c.testable && c.confounded_with.is_none())
            .count();
        let masked = e
            .candidates
            .iter()
            .filter(|c| c.testable && c.confounded_with.is_some() && c.p_holm <= e.alpha)
            .count();
        let mut line = format!(
            "No candidate that could be named is significant at α = {} (Holm over the {} testable ones that are separable from the baseline)",
            e.alpha, nameable
        );
        if masked > 0 {
            line.push_str(&format!(
                "; {masked} significant alone are not separable from a baseline term (listed below)"
            ));
        }
        line.push('.');
        out.push(line);
    }
    for f in &e.findings {
        out.push(finding_line(f));
    }
    // no finding a cause (a term or a noise level): nothing is added
    if !e.findings.is_empty() && e.findings.iter().all(|f| !f.is_cause()) {
        out.push(format!(
            "No term is added: every term fitted is a stand-in or not attributed, so the model stays {}.",
            e.baseline_model
        ));
    } else if !e.findings.is_empty() {
        let mut s = format!(
            "Extended model {}: mean NIS {} → {}, log-likelihood {:+.1}",
            e.extended_model,
            nis_text(e.gain.nis_mean_before),
            nis_text(e.gain.nis_mean_after),
            e.gain.loglik
        );
        if let (Some(b), Some(a)) = (e.gain.model_error_rms_before, e.gain.model_error_rms_after) {
            s.push_str(&format!(
                "; model error (truth) {} → {} arcsec RMS ({})",
                sig3(b),
                sig3(a),
                if a <= b {
                    format!("{}× smaller", sig3(b / a))
                } else {
                    format!("{}× larger", sig3(a / b))
                }
            ));
        }
        s.push('.');
        out.push(s);
    }
}

/// The summary's lines on what the extension leaves: the unexplained share of the misfit and the
/// structure left in the innovations; times from `t_ref` [s].
fn left_over_words(e: &Explanation, t_ref: f64, out: &mut Vec<String>) {
    // said whenever the baseline had an excess to explain (a mean NIS of the extended model
    // below 1 leaves none of it: 0 %)
    if let Some(left) = e.misfit_unexplained {
        out.push(format!(
            "Left unexplained: {} % of the baseline's excess misfit (mean NIS {} against 1 for a consistent filter){}.",
            if left > 0.0 {
                sig3(100.0 * left)
            } else {
                "0".into()
            },
            nis_text(e.extended.nis_mean),
            if left > 0.5 {
                "; most of the misfit is something the candidates do not describe"
            } else {
                ""
            }
        ));
        // a stand-in takes up misfit without being its cause: said first
        let taken = e.misfit_taken_by_stand_ins();
        if let (true, Some(by_causes), Some(last)) = (
            taken >= 0.05,
            e.misfit_unexplained_by_causes(),
            out.last_mut(),
        ) {
            *last = if e.stand_ins_left_out {
                format!(
                    "Left unexplained by the causes found: {} % of the baseline's excess misfit (mean NIS {} against 1 for a consistent filter). Fits that are not causes (\"Fitted, but not a cause\" above) take up {}; they are left out of the extended model.",
                    sig3(100.0 * left.max(0.0)),
                    nis_text(e.extended.nis_mean),
                    shares_text(taken),
                )
            } else {
                format!(
                    "Left unexplained by the causes found: {} % of the baseline's excess misfit. Fits that are not causes (\"Fitted, but not a cause\" above) take up {}; with them the extended model leaves {} % (mean NIS {} against 1 for a consistent filter), which is no explanation.",
                    sig3(100.0 * by_causes),
                    shares_text(taken),
                    sig3(100.0 * left.max(0.0)),
                    nis_text(e.extended.nis_mean),
                )
            };
        }
    }
    // what the extended model leaves in the innovations (the baseline's was said above)
    let left = e.extended.structure();
    if e.findings.iter().any(|f| f.is_cause()) && !left.is_empty() {
        let said: Vec<String> = left
            .iter()
            .map(|r| {
                let mut parts = Vec::new();
                if r.correlated {
                    let p = r.whiteness_p.unwrap_or(0.0);
                    parts.push(format!(
                        "correlated in time (Ljung–Box p {})",
                        if p < 1e-300 {
                            "< 1e-300".to_string()
                        } else {
                            sig3(p)
                        }
                    ));
                }
                if let (true, Some([t0, t1])) = (r.biased, r.segment) {
                    parts.push(format!(
                        "biased by {:+.1}σ over {:.0}–{:.0} s",
                        r.segment_z,
                        t0 - t_ref,
                        t1 - t_ref
                    ));
                }
                format!(
                    "{} innovations {}",
                    channel_word(&r.channel),
                    parts.join(" and ")
                )
            })
            .collect();
        out.push(format!(
            "After the extension structure remains (a segment's bias is its mean normalised innovation × √count): {}. Something the extended model does not describe is still in the data; a finding may absorb part of it (its consistency splits say whether it holds across the data).",
            said.join("; ")
        ));
    }
}

/// The summary's lines on candidates not named: implausible, unconfirmed, not separable, not
/// testable.
fn not_named_words(e: &Explanation, out: &mut Vec<String>) {
    if !e.implausible.is_empty() {
        let list: Vec<String> = e
            .implausible
            .iter()
            .map(|i| {
                format!(
                    "{} (would need {} ± {} {}, {} prior σ)",
                    i.term,
                    sig3(i.estimate),
                    sig3(i.sigma),
                    i.unit,
                    sig3(i.prior_sigmas)
                )
            })
            .collect();
        out.push(format!(
            "Significant but not named, their values would be implausible (a weak signature fitting some other mismatch; if your sensor can have such errors, widen its prior with --prior): {}.",
            list.join(", ")
        ));
    }
    if !e.unconfirmed.is_empty() {
        let names: Vec<&str> = e.unconfirmed.iter().map(|u| u.0.as_str()).collect();
        let (g, p) = (e.unconfirmed[0].1, e.unconfirmed[0].2);
        out.push(format!(
            "The signatures pointed at {} but the filter with them did not confirm it (2Δ log-likelihood {} with the prior's Occam term added back, against {}, φ times the χ²_k quantile at α): not named; the misfit is something the candidates do not describe.",
            names.join(", "),
            sig3(g),
            sig3(p)
        ));
    }
    if !e.not_separable.is_empty() {
        let list: Vec<String> = e
            .not_separable
            .iter()
            .map(|(c, b)| format!("{c} (like {b})"))
            .collect();
        out.push(format!(
            "Not separable from a baseline term on these data (its regressor is proportional to that term's, whose state takes it up): {}.",
            list.join(", ")
        ));
    }
    if !e.not_testable.is_empty() {
        out.push(format!(
            "Not testable on these data (no information): {}.",
            e.not_testable.join(", ")
        ));
    }
}

/// The share `taken` (a fraction; the stand-ins' shares summed) of the misfit in words: above
/// all of it, the shares (each from the round that added its fit) overlap, and the words say so.
fn shares_text(taken: f64) -> String {
    // (above 100 % as said: 100.4 % reads as 100 %)
    if taken >= 1.005 {
        format!(
            "{} % of it (each share from the round that added the fit: they overlap, and together come to more than all of it)",
            sig3(100.0 * taken)
        )
    } else {
        format!("{} % of it", sig3(100.0 * taken))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_tight_prior_is_said_as_a_multiple_of_its_prior_sigma() {
        let p = super::super::findings::TightPrior {
            term: "nabla_x".into(),
            index: 0,
            estimate: 408.0,
            sigma: 12.0,
            prior: 100.0,
            prior_sigmas: 4.08,
            suggested: 2000.0,
            unit: "ug".into(),
        };
        assert_eq!(
            tight_prior_words(&p),
            "nabla_x = 408 ± 12.0 ug is 4.08× its prior σ of 100 ug"
        );
    }

    #[test]
    fn a_mean_nis_near_1_keeps_enough_digits_to_differ() {
        assert_eq!(nis_text(1.0123), "1.012");
        assert_eq!(nis_text(1.0041), "1.004");
        assert_eq!(nis_text(0.917), "0.9170");
        assert_eq!(nis_text(2324.4), "2324");
        assert_eq!(nis_text(21.53), "21.53");
        assert_eq!(nis_text(3.0e6), "3.000e6");
    }
}
