//! An IMU–GNSS time offset fitted to every order. dt_gnss's H is first order in the offset
//! (position rows −v dt, velocity rows −a dt with a lagged acceleration): at a few hundred ms
//! on a turning vehicle the fit falls short and other terms (an antenna lever arm along the
//! track, accelerometer delays) take up the rest as if they were causes. When the first pass
//! names a time offset, explain runs again on the fixes re-stamped by it (a fix stamped t taken
//! at t + dt: exact) and fits what is left, until nothing significant is.

use super::findings::{Consistency, Explanation, Finding};
use super::words::{sig3, summary};
use crate::estimate::filter::AidingEpoch;
use serde::Serialize;

pub use super::offset_lever::{offset_or_lever_arm, OnFixes};

/// Smallest time offset [s] a pass refits on re-stamped fixes: below, the first-order H's
/// error (of order a dt² / 2 in position) is under a millimetre on a car.
pub const RESTAMP_MIN_S: f64 = 0.005;

/// Most explain runs on re-stamped fixes after the first.
pub const MAX_RESTAMPS: usize = 4;

/// The largest total re-stamp [s] explain tries (`--gnss-delay`'s bound).
const MAX_SHIFT_S: f64 = 1.0;

/// One run on re-stamped fixes.
#[derive(Debug, Clone, Serialize)]
pub struct Pass {
    /// The shift the fixes carried [ms] (the user's `--gnss-delay` on the first run).
    pub shift_ms: f64,
    /// The offset the run fitted on top [ms]: its dt_gnss cause, else its candidate test alone.
    pub estimate_ms: f64,
    /// Its σ [ms].
    pub sigma_ms: f64,
    /// The run's other GNSS causes that take up the candidate test's offset (it is then no
    /// offset on top: the run's causes fit that misfit).
    pub taken_up_by: Vec<String>,
}

/// How a time offset was fitted by re-stamping the fixes.
#[derive(Debug, Clone, Serialize)]
pub struct Restamp {
    /// The runs, the first on the fixes as given.
    pub passes: Vec<Pass>,
    /// The offset in all [ms]: the last shift plus what the last run fitted on top (none when
    /// other causes take it up).
    pub total_ms: f64,
    /// Its σ [ms] (the last run's).
    pub sigma_ms: f64,
    /// Causes the first run (dt_gnss to first order) named that the re-stamped fixes do not
    /// bear out: (term, its first-run words).
    pub dropped: Vec<(String, String)>,
    /// Mean NIS of the baseline on the fixes as given (the first run's).
    pub nis_as_stamped: f64,
}

/// The time offset [ms] and its σ [ms] of `e`'s dt_gnss finding when it is a cause.
pub fn offset_cause(e: &Explanation) -> Option<(f64, f64)> {
    e.findings
        .iter()
        .find(|f| f.term == "dt_gnss" && f.is_cause())
        .map(|f| (f.estimate, f.sigma))
}

/// The time offset [ms] and its σ [ms] a GNSS finding of `e` probably stands in for, when the
/// offset was fitted there but named no cause (a lever arm along the track took its place, say):
/// the fixes are then re-stamped by it as by a cause.
fn offset_in_place(e: &Explanation) -> Option<(f64, f64)> {
    if !e.candidates.iter().any(|c| c.term == "dt_gnss") {
        return None;
    }
    e.findings
        .iter()
        .find_map(|f| f.offset_in_place)
        .map(|[d, s]| (d, s))
}

/// The time offset [ms] and its σ [ms] of `e`'s dt_gnss finding when it is no cause but beyond
/// 3σ: its verdict (a stand-in held by the stated noise, a split that fails) came from the
/// first-order fit, which at a large offset is itself wrong; the exact fit decides.
fn offset_fitted(e: &Explanation) -> Option<(f64, f64)> {
    e.findings
        .iter()
        .find(|f| f.term == "dt_gnss" && f.estimate.abs() > 3.0 * f.sigma)
        .map(|f| (f.estimate, f.sigma))
}

/// What run `e` (on fixes shifted by `shift_ms`) leaves of the offset: its dt_gnss cause, else
/// the offset a finding stands in for, else its candidate test alone, which the run's other
/// GNSS causes may take up.
fn left_by(e: &Explanation, shift_ms: f64) -> Pass {
    if let Some((d, s)) = offset_cause(e).or_else(|| offset_in_place(e)) {
        return Pass {
            shift_ms,
            estimate_ms: d,
            sigma_ms: s,
            taken_up_by: Vec::new(),
        };
    }
    let (d, s) = e
        .candidates
        .iter()
        .find(|c| c.term == "dt_gnss")
        .map_or((0.0, f64::NAN), |c| (c.glr_estimate, c.glr_sigma));
    let taken_up_by = e
        .findings
        .iter()
        .filter(|f| f.is_cause() && f.kind == "measurement" && f.term != "dt_gnss")
        .map(|f| f.term.clone())
        .collect();
    Pass {
        shift_ms,
        estimate_ms: d,
        sigma_ms: s,
        taken_up_by,
    }
}

/// explain with a time offset fitted to every order: `run(shift)` is explain on the fixes
/// re-stamped by `shift` [s] (`given` [s]: the user's `--gnss-delay`, 0 without), `by_fix(shift)`
/// the test of what is left there from each kind of fix alone. When the first run names
/// dt_gnss as a cause of at least [`RESTAMP_MIN_S`], the fixes are re-stamped by it and explain
/// runs again, up to [`MAX_RESTAMPS`] times, while what is left (the run's dt_gnss cause, else
/// its candidate test alone unless the run's other GNSS causes take it up) is at least that
/// and beyond 3σ; the last run is the answer, with dt_gnss in all as its first finding.
pub fn explain_restamped(
    given: f64,
    mut run: impl FnMut(f64) -> anyhow::Result<Explanation>,
    mut by_fix: impl FnMut(f64) -> anyhow::Result<Consistency>,
) -> anyhow::Result<Explanation> {
    let first = run(given)?;
    let start = offset_cause(&first)
        .or_else(|| offset_in_place(&first))
        .or_else(|| offset_fitted(&first));
    let Some((d, s)) = start else {
        return Ok(first);
    };
    if d.abs() * 1e-3 < RESTAMP_MIN_S {
        return Ok(first);
    }
    let mut shift = given + d * 1e-3;
    let mut passes = vec![Pass {
        shift_ms: given * 1e3,
        estimate_ms: d,
        sigma_ms: s,
        taken_up_by: Vec::new(),
    }];
    for _ in 0..MAX_RESTAMPS {
        if shift.abs() > MAX_SHIFT_S {
            let why = format!(
                "the offset found in all, {} ms, is beyond ±1 s, the most explain re-stamps the fixes by (the spec's limit of dt_gnss): check the clocks (a whole second between the IMU's and the receiver's?)",
                sig3(shift * 1e3)
            );
            return Ok(unsettled(first, &passes, &why));
        }
        let e = run(shift)?;
        let left = left_by(&e, shift * 1e3);
        let (d, s) = (left.estimate_ms, left.sigma_ms);
        let more =
            left.taken_up_by.is_empty() && d.abs() * 1e-3 >= RESTAMP_MIN_S && d.abs() > 3.0 * s;
        passes.push(left);
        if more {
            // still an offset to take out
            shift += d * 1e-3;
            continue;
        }
        if !s.is_finite() {
            return Ok(unsettled(
                first,
                &passes,
                "the last run gives no σ for what is left",
            ));
        }
        // one offset for every kind of fix: what is left on the re-stamped fixes, from the
        // positions alone and from the velocities alone
        let split = by_fix(shift)?;
        return Ok(fold(&first, e, passes, split, given * 1e3));
    }
    let why = format!(
        "{} runs on re-stamped fixes did not settle",
        passes.len() - 1
    );
    Ok(unsettled(first, &passes, &why))
}

/// The first run `e`, its summary opened by why the re-stamping of `passes` did not settle, with
/// none of its findings named a cause (each was fitted beside an offset the run could not fit).
fn unsettled(mut e: Explanation, passes: &[Pass], why: &str) -> Explanation {
    for f in e.findings.iter_mut().filter(|f| f.is_cause()) {
        super::not_named(
            f,
            super::Unnamed::OffsetUnsettled,
            format!(
                "it was fitted beside a time offset the re-stamped runs did not settle ({why})"
            ),
        );
    }
    let shifts: Vec<String> = passes.iter().skip(1).map(|p| sig3(p.shift_ms)).collect();
    let refitted = if shifts.is_empty() {
        format!("The time offset was not refitted on re-stamped fixes: {why}")
    } else {
        format!(
            "The time offset was refitted on re-stamped fixes (shifts {} ms), but {why}",
            shifts.join(", ")
        )
    };
    e.summary = summary(&e);
    e.summary.insert(
        0,
        format!(
            "{refitted}: nothing is named a cause: the findings below are the first run's, fitted with the offset to first order, and may stand in for its higher orders."
        ),
    );
    e
}

/// The last run `last` (on fixes re-stamped by its pass's shift) with dt_gnss in all as its
/// first finding: the first run's finding with the offset, σ, share and words of all passes;
/// a stand-in when the kinds of fix (`split`) want different offsets, and no cause when the
/// offset in all is none (`given_ms`: the user's `--gnss-delay`, then not borne out).
fn fold(
    first: &Explanation,
    mut last: Explanation,
    passes: Vec<Pass>,
    split: Consistency,
    given_ms: f64,
) -> Explanation {
    let end = passes.last().expect("at least two passes");
    let (shift, sigma) = (end.shift_ms, end.sigma_ms);
    let rest = if end.taken_up_by.is_empty() {
        end.estimate_ms
    } else {
        0.0
    };
    let total = shift + rest;
    let mut f = offset_finding(first);
    // (the first run's verdict on it, to first order, is replaced by the one below)
    (f.stand_in, f.not_attributed, f.offset_in_place) = (None, None, None);
    f.not_attributed_because.clear();
    let nis0 = first.baseline.nis_mean;
    f.estimate = total;
    f.sigma = sigma;
    f.misfit_share = (nis0 > 1.0).then(|| (nis0 - last.baseline.nis_mean) / (nis0 - 1.0));
    // the evidence of the re-stamp: the baseline's log-likelihood on the re-stamped fixes
    // against the fixes as given
    f.two_delta_loglik = 2.0 * (last.baseline.loglik - first.baseline.loglik);
    let dropped: Vec<(String, String)> = first
        .findings
        .iter()
        .filter(|g| g.is_cause() && g.term != "dt_gnss")
        .filter(|g| {
            !last
                .findings
                .iter()
                .any(|h| h.term == g.term && h.is_cause())
        })
        .map(|g| (g.term.clone(), g.headline.clone()))
        .collect();
    let steps: Vec<String> = passes
        .iter()
        .map(|p| {
            let on = if p.shift_ms == 0.0 {
                "on the fixes as stamped".to_string()
            } else {
                format!("on the fixes shifted by {} ms", sig3(p.shift_ms))
            };
            let taken = if p.taken_up_by.is_empty() {
                String::new()
            } else {
                format!(" alone, which {} there take up", p.taken_up_by.join(", "))
            };
            format!(
                "{} ± {} ms {on}{taken}",
                sig3(p.estimate_ms),
                sig3(p.sigma_ms)
            )
        })
        .collect();
    f.headline = format!(
        "GNSS time offset dt_gnss = {} ± {} {}",
        sig3(total),
        sig3(sigma),
        f.unit
    );
    f.words = format!(
        "{} (fitted to every order: the fixes re-stamped by what each run found and explain run again, {}; a fix stamped t is the trajectory at t + dt_gnss); re-stamping the fixes by {} ms takes the baseline's mean NIS from {} to {}, {} % of its excess misfit",
        f.headline,
        steps.join(", then "),
        sig3(shift),
        sig3(nis0),
        sig3(last.baseline.nis_mean),
        sig3(100.0 * f.misfit_share.unwrap_or(0.0).max(0.0))
    );
    if !dropped.is_empty() {
        f.words.push_str(&format!(
            ". The first run, with the offset to first order, also named {}: on the re-stamped fixes {} not, so {} stood in for the offset's higher orders",
            dropped
                .iter()
                .map(|(t, h)| format!("{t} ({h})"))
                .collect::<Vec<_>>()
                .join(", "),
            if dropped.len() == 1 { "it is" } else { "they are" },
            if dropped.len() == 1 { "it" } else { "they" },
        ));
    }
    judge(&mut f, (total, sigma, shift), given_ms, &split);
    f.consistency.retain(|c| c.split != split.split);
    f.consistency.push(split);
    last.findings.retain(|g| g.term != "dt_gnss");
    last.findings.insert(0, f);
    last.restamp = Some(Restamp {
        passes,
        total_ms: total,
        sigma_ms: sigma,
        dropped,
        nis_as_stamped: nis0,
    });
    last.summary = summary(&last);
    last.summary
        .insert(0, restamp_line(shift, rest, sigma, nis0));
    last
}

/// The summary's first line after a re-stamp by `shift` [ms] whose offset is not named;
/// `nis0` the baseline's mean NIS on the fixes as given.
pub(super) fn restamp_line_unattributed(shift: f64, nis0: f64) -> String {
    format!(
        "The GNSS fixes were re-stamped by {} ms, the time offset the runs fitted, but that offset is not named a cause (its finding below says why): the baseline pass, the candidates and every other finding below are on the re-stamped fixes; the baseline's mean NIS on the fixes as given was {}.",
        sig3(shift),
        sig3(nis0)
    )
}

/// The summary's first line after a re-stamp by `shift` [ms] with `rest` ± `sigma` [ms] left
/// on top; `nis0` the baseline's mean NIS on the fixes as given.
pub(super) fn restamp_line(shift: f64, rest: f64, sigma: f64, nis0: f64) -> String {
    format!(
        "The GNSS fixes were re-stamped by {} ms, the time offset the runs found (`--gnss-delay '{} ms'` does the same; {} ± {} ms more is left on top, in the offset's value below): the baseline pass, the candidates and every other finding below are on the re-stamped fixes; the baseline's mean NIS on the fixes as given was {}.",
        sig3(shift),
        sig3(shift),
        sig3(rest),
        sig3(sigma),
        sig3(nis0)
    )
}

/// The first run `e`'s dt_gnss finding, or, where it named none (a lever arm along the track
/// took the offset's place), one made from its candidate test and the finding that stands in
/// for it (the values are set by the caller).
fn offset_finding(e: &Explanation) -> Finding {
    if let Some(f) = e.findings.iter().find(|f| f.term == "dt_gnss") {
        return f.clone();
    }
    let g = e
        .findings
        .iter()
        .find(|f| f.offset_in_place.is_some())
        .expect("the first run named the offset, or a finding standing in for it");
    let info = super::term_index("dt_gnss")
        .map(|t| &crate::model::generated::common::TERMS[t])
        .expect("the spec declares dt_gnss");
    let test = e.candidates.iter().find(|c| c.term == "dt_gnss");
    let of = |x: fn(&super::findings::CandidateTest) -> f64| test.map_or(f64::NAN, x);
    let prior = info.sigma / info.display_to_si;
    let [d, _] = g.offset_in_place.unwrap_or_default();
    Finding {
        term: info.name.to_string(),
        kind: "measurement",
        unit: info.display.to_string(),
        llr: of(|c| c.llr),
        p_value: of(|c| c.p_holm),
        equivalent: Vec::new(),
        equivalent_estimates: Vec::new(),
        withheld_alike: Vec::new(),
        glr_estimate: of(|c| c.glr_estimate),
        glr_sigma: of(|c| c.glr_sigma),
        confounded_with: None,
        regressor_mean: 1.0,
        regressor_unit: "1".into(),
        regressor_excited_mean: 1.0,
        excited_fraction: 1.0,
        effect_excited: d,
        effect: d,
        effect_unit: info.display.to_string(),
        separate_by: Vec::new(),
        prior_sigma: prior,
        prior_widened: false,
        prior_sigmas: (d / prior).abs(),
        suggested_prior: None,
        halves: None,
        speed_halves: None,
        consistency: Vec::new(),
        ..g.clone()
    }
}

/// The verdict on the offset in all `f` ((total, σ, the last shift) [ms]): no cause when the
/// fixes want none in all (`given_ms`: the user's `--gnss-delay`, then not borne out), a
/// stand-in when the kinds of fix (`split`) want different ones.
fn judge(
    f: &mut Finding,
    (total, sigma, shift): (f64, f64, f64),
    given_ms: f64,
    split: &Consistency,
) {
    if total.abs() <= 3.0 * sigma {
        // the re-stamped fixes want no offset in all
        let why = if given_ms != 0.0 {
            format!(
                "in all the fixes want no offset ({} ± {} ms): the --gnss-delay given, {} ms, is not borne out, and the fixes as stamped are on the IMU's clock",
                sig3(total),
                sig3(sigma),
                sig3(given_ms)
            )
        } else {
            format!(
                "in all the fixes want no offset ({} ± {} ms): the first run's was the first-order fit's artefact",
                sig3(total),
                sig3(sigma)
            )
        };
        super::not_named(f, super::Unnamed::OffsetNotBorneOut, why);
    } else if !split.holds {
        // the kinds of fix want different offsets: no one time offset of the receiver
        let by: Vec<String> = split
            .groups
            .iter()
            .map(|g| {
                format!(
                    "{} ± {} ms {}",
                    sig3(shift + g.estimate),
                    sig3(g.sigma),
                    g.group
                )
            })
            .collect();
        let why = format!(
            "on the re-stamped fixes each kind alone wants its own offset, {} (χ² p {}): not one offset of the receiver; its velocities may carry a latency of their own (a filtered velocity) or its positions a lever arm, and one offset for both stands in for that; `--aid-use pos` or `--aid-use vel` fits each kind alone",
            by.join(", "),
            sig3(split.p_value)
        );
        f.words.push_str(&format!(
            ". It probably stands in for an effect the candidates do not describe ({why})"
        ));
        f.stand_in = Some(why);
    }
}

/// `aid` with its GNSS fixes (positions, velocities) re-stamped by `shift` [s] (the one stamped
/// t taken at t + shift, as `--gnss-delay` does), other aiding (body velocity, attitude) where it
/// was; epochs at or before `t0` [s] (the start) dropped.
pub(super) fn restamped_aid(aid: &[AidingEpoch], shift: f64, t0: f64) -> Vec<AidingEpoch> {
    let mut out = Vec::with_capacity(aid.len());
    for e in aid {
        if e.pos.is_some() || e.vel.is_some() {
            out.push(AidingEpoch {
                t: e.t + shift,
                pos: e.pos,
                vel: e.vel,
                body_vel: None,
                att: None,
            });
        }
        if e.body_vel.is_some() || e.att.is_some() {
            out.push(AidingEpoch {
                pos: None,
                vel: None,
                ..e.clone()
            });
        }
    }
    out.retain(|e| e.t > t0);
    // stable: a re-stamped fix keeps its place among epochs of one time
    out.sort_by(|a, b| a.t.total_cmp(&b.t));
    out
}

/// A time offset in a finding's place, fitted to every order.
pub(super) struct RivalOffset {
    /// The offset in all [s]: the re-stamp plus what the last pass fitted on top.
    pub(super) offset_s: f64,
    /// Its σ [s] (the last pass's).
    pub(super) sigma_s: f64,
    /// The re-stamp of the last pass's fixes [s] (0: the fixes as given).
    pub(super) shift_s: f64,
    /// The last pass (None: the first, on the fixes as given).
    pub(super) pass: Option<super::Pass>,
}

/// dt_gnss (state `i` of `m`, the rounds' model with it in a finding's place) fitted to every
/// order: `first` is `m`'s pass on the fixes as given (its dt_gnss first order); while what it
/// leaves is at least [`RESTAMP_MIN_S`] and beyond 3σ (at most [`MAX_RESTAMPS`] times, within
/// ±1 s in all), `m` runs again on the fixes re-stamped by the offset so far.
pub(super) fn rival_offset(
    data: &super::ExplainData,
    m: &crate::model::Model,
    i: usize,
    cfg: &crate::estimate::filter::FilterConfig,
    first: &super::Pass,
    progress: &mut dyn FnMut(f64),
) -> anyhow::Result<Option<RivalOffset>> {
    let fitted = |p: &super::Pass| p.run.records.last().map(|r| (r.x[i], r.sigma[i]));
    let Some((mut d, mut s)) = fitted(first) else {
        return Ok(None);
    };
    let mut shift = 0.0;
    let mut last = None;
    for _ in 0..MAX_RESTAMPS {
        if d.abs() < RESTAMP_MIN_S || d.abs() < 3.0 * s || (shift + d).abs() > MAX_SHIFT_S {
            break;
        }
        shift += d;
        let aid = restamped_aid(data.aid, shift, data.start.t);
        let moved = super::ExplainData { aid: &aid, ..*data };
        let p = super::run_pass(m, &[], &moved, cfg, progress)?;
        let Some(x) = fitted(&p) else {
            return Ok(None);
        };
        (d, s) = x;
        last = Some(p);
    }
    let shift_s = if last.is_some() { shift } else { 0.0 };
    Ok(Some(RivalOffset {
        offset_s: shift_s + d,
        sigma_s: s,
        shift_s,
        pass: last,
    }))
}
