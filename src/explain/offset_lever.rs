//! An IMU–GNSS time offset against an antenna lever arm. On a vehicle mostly at one speed a
//! lever arm along the track moves the fixes as speed × an offset does, in turns as in a
//! straight line; they differ only where the speed changes. When the re-stamped runs name an
//! offset, the model they name is fitted again on the fixes as given with a horizontal lever
//! arm in the offset's place; when that fits the data as well, the offset is not named.

use super::findings::Explanation;
use super::rivals::{compare, occam, Comparison, BLOCKS};
use super::words::sig3;
use super::{model_with, run_pass, Context, ExplainData, ExplainOptions};
use crate::estimate::filter::FilterConfig;
use crate::model::generated::common;
use crate::model::Model;

/// One side of [`offset_or_lever_arm`]: the data on fixes re-stamped by `shift` [s] and the
/// filter configuration of a model there.
pub struct OnFixes<'a> {
    /// The data.
    pub data: &'a ExplainData<'a>,
    /// The filter configuration of a model on them.
    pub config_for: &'a dyn Fn(&Model) -> anyhow::Result<FilterConfig>,
    /// Their re-stamp [s].
    pub shift: f64,
}

/// The time offset `e` names after re-stamping (a cause) against the antenna lever arms along
/// the body's horizontal axes on the fixes as given. The model of `e`'s causes on the
/// re-stamped fixes (`stamped`) is fitted beside the same model on the fixes as given
/// (`given`), with a horizontal lever arm added, or as it is when it holds one. When one of
/// those fits the data as well (the re-stamp not better beyond chance,
/// [`Comparison::better_in_few_blocks`]) with a lever arm beyond 3σ, the offset is not named,
/// and the causes that move with it are judged ([`moved_with_the_offset`]).
pub fn offset_or_lever_arm(
    e: &mut Explanation,
    baseline: &Model,
    opts: &ExplainOptions,
    (given, stamped): (&OnFixes, &OnFixes),
    progress: &mut dyn FnMut(usize, f64),
) -> anyhow::Result<()> {
    let Some(k) = e.findings.iter().position(|f| f.term == "dt_gnss") else {
        return Ok(());
    };
    if e.restamp.is_none() || !e.findings[k].is_cause() {
        return Ok(());
    }
    // the run's widened baseline priors, as its passes had them
    let widened: Vec<(usize, f64)> = if e.baseline_priors_widened {
        e.baseline_priors_tight
            .iter()
            .map(|p| (p.index, p.suggested * common::TERMS[p.index].display_to_si))
            .collect()
    } else {
        Vec::new()
    };
    let causes: Vec<usize> = e
        .findings
        .iter()
        .filter(|f| f.is_cause() && f.term != "dt_gnss")
        .filter_map(|f| super::term_index(&f.term))
        .collect();
    let ctx_g = Context {
        baseline,
        data: given.data,
        config_for: given.config_for,
        opts,
    };
    let ctx_s = Context {
        data: stamped.data,
        config_for: stamped.config_for,
        ..ctx_g
    };
    let round = e.rounds + 1;
    let named = model_with(&baseline.name, causes.iter().copied())?;
    let cfg = ctx_s.extended_config(&named, &widened)?;
    let p_s = run_pass(&named, &[], stamped.data, &cfg, &mut |x| progress(round, x))?;
    let Some(end_s) = p_s.run.records.last() else {
        return Ok(());
    };
    let occam_s = occam(&ctx_s, &named, &cfg, &end_s.sigma);
    let levers: Vec<usize> = ["lever_x", "lever_y"]
        .iter()
        .filter_map(|n| super::term_index(n))
        .collect();
    // the rivals: the model as it is when it holds a lever arm, and with each one it lacks
    let mut rivals: Vec<Vec<usize>> = Vec::new();
    if causes.iter().any(|t| levers.contains(t)) {
        rivals.push(causes.clone());
    }
    for &l in levers.iter().filter(|l| !causes.contains(l)) {
        rivals.push(causes.iter().copied().chain([l]).collect());
    }
    for terms in rivals {
        let m = model_with(&baseline.name, terms.iter().copied())?;
        // (a configuration that refuses a lever arm has no antenna to put it on)
        let Ok(cfg_g) = ctx_g.extended_config(&m, &widened) else {
            continue;
        };
        let p_g = run_pass(&m, &[], given.data, &cfg_g, &mut |x| progress(round, x))?;
        let Some(end_g) = p_g.run.records.last() else {
            continue;
        };
        let occam_g = occam(&ctx_g, &m, &cfg_g, &end_g.sigma);
        let shift = stamped.shift - given.shift;
        // (the lever arm's run as the named one: the fit is the re-stamp's against it)
        let Some(fit) = compare(given.data, &p_g.run, &p_s.run, (shift, occam_s - occam_g)) else {
            continue;
        };
        if fit.better_in_few_blocks() {
            continue;
        }
        let fitted = |name: &str| m.index_of(name).map(|i| (end_g.x[i], end_g.sigma[i]));
        let Some(how) = lever_words(e, &levers, &fitted, &fit) else {
            continue;
        };
        moved_with_the_offset(e, &fitted, &how);
        super::not_named(&mut e.findings[k], super::Unnamed::OffsetOrLeverArm, how);
        let line = e.summary.first().cloned();
        e.summary = super::words::summary(e);
        if let Some(line) = line.filter(|l| l.starts_with("The GNSS fixes were re-stamped")) {
            e.summary.insert(0, line);
        }
        return Ok(());
    }
    Ok(())
}

/// Why the offset of `e` is not named when the lever arms among `levers` fitted on the fixes as
/// given (`fitted`: a term's value and σ, SI) fit as `fit` says: None when none is beyond 3σ.
fn lever_words(
    e: &Explanation,
    levers: &[usize],
    fitted: &dyn Fn(&str) -> Option<(f64, f64)>,
    fit: &Comparison,
) -> Option<String> {
    let held: Vec<String> = levers
        .iter()
        .filter_map(|&l| {
            let info = &common::TERMS[l];
            let (x, s) = fitted(info.name)?;
            (x.abs() > 3.0 * s).then(|| {
                let offered = e.candidates.iter().any(|c| c.term == info.name);
                format!(
                    "{} = {} ± {} {}{}",
                    info.name,
                    sig3(x / info.display_to_si),
                    sig3(s / info.display_to_si),
                    info.display,
                    if offered {
                        ""
                    } else {
                        ", not a candidate here"
                    }
                )
            })
        })
        .collect();
    if held.is_empty() {
        return None;
    }
    let by = fit.z.map_or(String::new(), |z| {
        format!(
            " (the re-stamp's gain {} of its σ over {BLOCKS} blocks of fixes, {} of the quiet blocks')",
            sig3(z),
            sig3(fit.z_quiet.unwrap_or(f64::NAN))
        )
    });
    Some(format!(
        "on the fixes as stamped, {} {} the data {}: a log-likelihood {} against {} for the re-stamped fixes{by}. On this motion an antenna lever arm along the track moves the fixes as speed × a time offset does, and the data do not tell them apart; a known lever arm (--lever-arm) or offset (--gnss-delay), or a run with more changes of speed, decides",
        held.join(" and "),
        if held.len() == 1 { "fits" } else { "fit" },
        if fit.loglik - fit.loglik_named + fit.occam > 0.0 {
            "as well"
        } else {
            "better"
        },
        sig3(fit.loglik_named),
        sig3(fit.loglik),
    ))
}

/// Each cause of `e` but the offset against its value on the fixes as given (`fitted`: value
/// and σ, SI): one that moves by more than 3σ is not named (its value is the offset's as much
/// as its own, `how`); one that moves by more than σ/2 is given the mean of the two, its σ
/// widened by half their difference (either fit may be the true one).
fn moved_with_the_offset(
    e: &mut Explanation,
    fitted: &dyn Fn(&str) -> Option<(f64, f64)>,
    how: &str,
) {
    for f in e
        .findings
        .iter_mut()
        .filter(|f| f.is_cause() && f.term != "dt_gnss")
    {
        let (Some((b, sb)), Some(t)) = (fitted(&f.term), super::term_index(&f.term)) else {
            continue;
        };
        let si = common::TERMS[t].display_to_si;
        let (a, s, b, sb) = (f.estimate, f.sigma, b / si, sb / si);
        let both = format!(
            "{} {} on the re-stamped fixes, {} ± {} {} on the fixes as stamped",
            sig3(a),
            f.unit,
            sig3(b),
            sig3(sb),
            f.unit
        );
        if (a - b).abs() > 3.0 * s {
            let why = format!("its value moves with the time offset: {both}, where {how}");
            super::not_named(f, super::Unnamed::OffsetOrLeverArm, why);
            continue;
        }
        if (a - b).abs() <= 0.5 * s {
            // (it does not move: its σ would grow by 3 % at most)
            continue;
        }
        let old = f.headline.clone();
        f.estimate = 0.5 * (a + b);
        f.sigma = (s * s + 0.25 * (a - b).powi(2)).sqrt();
        f.headline = old.replacen(
            &format!("= {} ± {} {}", sig3(a), sig3(s), f.unit),
            &format!("= {} ± {} {}", sig3(f.estimate), sig3(f.sigma), f.unit),
            1,
        );
        f.words = f.words.replacen(&old, &f.headline, 1);
        f.words.push_str(&format!(
            ". Its value moves with the time offset, which the data do not tell from a lever arm: {both}; the value above is the mean of the two, its σ widened by half their difference"
        ));
    }
}
