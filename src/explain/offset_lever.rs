//! An IMU–GNSS time offset against an antenna lever arm. On a vehicle mostly at one speed a
//! lever arm along the track moves the fixes as speed × an offset does, in turns as in a
//! straight line; they differ only where the speed changes. When the re-stamped runs name an
//! offset, the model they name is fitted again on the fixes as given with a horizontal lever
//! arm in the offset's place; when that fits the data as well, the offset is not named.

use super::findings::{EquivalentTerm, Explanation};
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

/// The time offset `e` names after re-stamping (a cause) against an antenna lever arm along
/// the track (body x) on the fixes as given; `lever_known`: the user gave the lever arm
/// (`--lever-arm`), and it is not tried. First the offset left on the re-stamped fixes is
/// fitted beside the GNSS causes that took it up ([`left_beside_its_takers`]). Then the model
/// of `e`'s causes on the re-stamped fixes (`stamped`) is fitted beside the same model with
/// lever_x added, or as it is when it holds it, on the fixes as given (`given`). When that fits
/// the data as well (the re-stamp not better beyond chance,
/// [`Comparison::better_in_few_blocks`]) with lever_x beyond 3σ, the offset is not named, and
/// the causes that move with it are judged ([`moved_with_the_offset`]).
pub fn offset_or_lever_arm(
    e: &mut Explanation,
    baseline: &Model,
    opts: &ExplainOptions,
    (given, stamped, lever_known): (&OnFixes, &OnFixes, bool),
    progress: &mut dyn FnMut(usize, f64),
) -> anyhow::Result<()> {
    let Some(k) = e.findings.iter().position(|f| f.term == "dt_gnss") else {
        return Ok(());
    };
    if e.restamp.is_none() || !e.findings[k].is_cause() {
        return Ok(());
    }
    // the run's widened baseline priors, as its passes had them
    let widened = if e.baseline_priors_widened {
        super::widened_priors(&e.baseline_priors_tight)
    } else {
        Vec::new()
    };
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
    left_beside_its_takers(e, &ctx_s, &widened, k, progress)?;
    let Some(lx) = super::term_index("lever_x").filter(|_| e.findings[k].is_cause()) else {
        return unattributed(e, &ctx_s, &widened, progress);
    };
    if lever_known {
        return Ok(());
    }
    let causes = causes_of(e);
    let round = e.rounds + 1;
    let named = model_with(&baseline.name, causes.iter().copied())?;
    let cfg = ctx_s.extended_config(&named, &widened)?;
    let p_s = run_pass(&named, &[], stamped.data, &cfg, &mut |x| progress(round, x))?;
    let Some(end_s) = p_s.run.records.last() else {
        return Ok(());
    };
    let occam_s = occam(&ctx_s, &named, &cfg, &end_s.sigma);
    // the rival: the model with the lever arm along the track (a lever arm across it, or a
    // term the re-stamped model lacks, would win by what the other misses)
    let m = model_with(
        &baseline.name,
        causes.iter().copied().filter(|&t| t != lx).chain([lx]),
    )?;
    // (a configuration that refuses a lever arm has no antenna to put it on)
    let Ok(cfg_g) = ctx_g.extended_config(&m, &widened) else {
        return Ok(());
    };
    let p_g = run_pass(&m, &[], given.data, &cfg_g, &mut |x| progress(round, x))?;
    let Some(end_g) = p_g.run.records.last() else {
        return Ok(());
    };
    let occam_g = occam(&ctx_g, &m, &cfg_g, &end_g.sigma);
    let shift = stamped.shift - given.shift;
    // (the lever arm's run as the named one: the fit is the re-stamp's against it)
    let Some(fit) = compare(given.data, &p_g.run, &p_s.run, (shift, occam_s - occam_g)) else {
        return Ok(());
    };
    if fit.better_in_few_blocks() {
        return Ok(());
    }
    let fitted = |name: &str| m.index_of(name).map(|i| (end_g.x[i], end_g.sigma[i]));
    let on = if given.shift == 0.0 {
        "on the fixes as stamped".to_string()
    } else {
        format!(
            "on the fixes as given (shifted by --gnss-delay {} ms)",
            sig3(given.shift * 1e3)
        )
    };
    let Some(how) = lever_words(e, lx, &fitted, &fit, (&on, given.shift != 0.0)) else {
        return Ok(());
    };
    moved_with_the_offset(e, &fitted, &how, &on);
    // the offset and the lever arm are one class the data do not tell apart
    let f = &mut e.findings[k];
    if let Some((x, s)) = fitted(common::TERMS[lx].name) {
        let si = common::TERMS[lx].display_to_si;
        let prior_sigmas = (x / super::prior_sigma(lx, opts)).abs();
        f.add_equivalent(EquivalentTerm::of(lx, (x / si, s / si, prior_sigmas)));
    }
    super::not_named(f, super::Unnamed::OffsetOrLeverArm, how);
    unattributed(e, &ctx_s, &widened, progress)
}

/// The terms of `e`'s causes but the time offset.
fn causes_of(e: &Explanation) -> Vec<usize> {
    e.findings
        .iter()
        .filter(|f| f.is_cause() && f.term != "dt_gnss")
        .filter_map(|f| super::term_index(&f.term))
        .collect()
}

/// `e` with its time offset not named: the summary opens with the re-stamp no offset was
/// named for, and when a term of the extended model is no cause now, that model is refitted
/// without it on the re-stamped fixes (`ctx`, the widened priors `widened`).
fn unattributed(
    e: &mut Explanation,
    ctx: &Context,
    widened: &[(usize, f64)],
    progress: &mut dyn FnMut(usize, f64),
) -> anyhow::Result<()> {
    let causes = causes_of(e);
    let m = model_with(&ctx.baseline.name, causes.iter().copied())?;
    if m.name != e.extended_model {
        let cfg = ctx.extended_config(&m, widened)?;
        let round = e.rounds + 1;
        let p = run_pass(&m, &[], ctx.data, &cfg, &mut |x| progress(round, x))?;
        let excess = super::baseline_excess(&e.baseline);
        e.extended_model = m.name.clone();
        e.gain = super::Gain::between(&e.baseline, &p.stats);
        e.misfit_unexplained = excess.map(|x| ((p.stats.nis_mean - 1.0) / x).max(0.0));
        e.innovations_after = super::normalised(&p.run);
        e.model_error_after = super::model_error_series(&p.run);
        e.extended = p.stats;
    }
    let Some(r) = &e.restamp else {
        return Ok(());
    };
    let line = super::restamp::restamp_line_unattributed(
        r.passes.last().map_or(0.0, |p| p.shift_ms),
        r.nis_as_stamped,
    );
    e.summary = super::words::summary(e);
    e.summary.insert(0, line);
    Ok(())
}

/// When the GNSS causes of `e`'s last re-stamped run took up what was left of the offset (its
/// candidate test alone then counted for nothing, and a lever arm beside an overshooting
/// re-stamp kept it: fixes 30 ms late came out −39.5 ± 2.87 ms beside lever_x), the offset
/// left is fitted beside them on the re-stamped fixes (`ctx`; the model of `e`'s causes, the
/// widened priors `widened`), and the offset in all (finding `k`) is the re-stamp plus that,
/// with its σ; not named when that is within 3σ of nothing. The causes take their values and
/// σ from that fit too.
fn left_beside_its_takers(
    e: &mut Explanation,
    ctx: &Context,
    widened: &[(usize, f64)],
    k: usize,
    progress: &mut dyn FnMut(usize, f64),
) -> anyhow::Result<()> {
    let Some(restamp) = &e.restamp else {
        return Ok(());
    };
    let Some(last) = restamp.passes.last().filter(|p| !p.taken_up_by.is_empty()) else {
        return Ok(());
    };
    let (shift, takers) = (last.shift_ms, last.taken_up_by.join(", "));
    let Some(w) = super::term_index("dt_gnss") else {
        return Ok(());
    };
    let m = model_with(&ctx.baseline.name, causes_of(e).into_iter().chain([w]))?;
    let cfg = ctx.extended_config(&m, widened)?;
    let round = e.rounds + 1;
    let p = run_pass(&m, &[], ctx.data, &cfg, &mut |x| progress(round, x))?;
    let (Some(i), Some(end)) = (m.index_of("dt_gnss"), p.run.records.last()) else {
        return Ok(());
    };
    let ms = 1.0 / common::TERMS[w].display_to_si;
    let (left, sigma) = (end.x[i] * ms, end.sigma[i] * ms);
    if !(left.is_finite() && sigma.is_finite()) {
        return Ok(());
    }
    let total = shift + left;
    let nis0 = restamp.nis_as_stamped;
    // the causes beside it as fitted with it: their σ holds what the offset left may take
    for g in e
        .findings
        .iter_mut()
        .filter(|g| g.is_cause() && g.term != "dt_gnss")
    {
        let (Some(j), Some(t)) = (m.index_of(&g.term), super::term_index(&g.term)) else {
            continue;
        };
        let si = common::TERMS[t].display_to_si;
        let (x, s) = (end.x[j] / si, end.sigma[j] / si);
        if (x - g.estimate).abs() > 0.5 * g.sigma || s > 1.03 * g.sigma {
            let before = format!("{} ± {} {}", sig3(g.estimate), sig3(g.sigma), g.unit);
            set_value(g, x, s);
            g.words.push_str(&format!(
                ". Its value is the fit beside the time offset left on the re-stamped fixes ({before} without it)"
            ));
        }
    }
    let f = &mut e.findings[k];
    set_value(f, total, sigma);
    f.words.push_str(&format!(
        ". Fitted beside {takers} on the re-stamped fixes, {} ± {} ms is left on top of the re-stamp by {} ms, so the offset in all is {} ± {} ms",
        sig3(left),
        sig3(sigma),
        sig3(shift),
        sig3(total),
        sig3(sigma)
    ));
    if total.abs() <= 3.0 * sigma {
        let why = format!(
            "beside {takers} the fixes want no offset in all ({} ± {} ms)",
            sig3(total),
            sig3(sigma)
        );
        super::not_named(f, super::Unnamed::OffsetNotBorneOut, why);
    }
    if let Some(r) = &mut e.restamp {
        (r.total_ms, r.sigma_ms) = (total, sigma);
    }
    e.summary = super::words::summary(e);
    e.summary
        .insert(0, super::restamp::restamp_line(shift, left, sigma, nis0));
    Ok(())
}

/// Sets finding `f`'s value and σ (display unit) and its headline's, in its words too.
fn set_value(f: &mut super::Finding, estimate: f64, sigma: f64) {
    let old = f.headline.clone();
    f.headline = old.replacen(
        &format!("= {} ± {} {}", sig3(f.estimate), sig3(f.sigma), f.unit),
        &format!("= {} ± {} {}", sig3(estimate), sig3(sigma), f.unit),
        1,
    );
    (f.estimate, f.sigma) = (estimate, sigma);
    f.words = f.words.replacen(&old, &f.headline, 1);
}

/// Why the offset of `e` is not named when lever_x (term `lx`) fitted on the fixes as given
/// (`fitted`: a term's value and σ, SI; `on`: those fixes in words; `delay_given`: the user
/// gave `--gnss-delay`) fits as `fit` says: None when it is not beyond 3σ.
fn lever_words(
    e: &Explanation,
    lx: usize,
    fitted: &dyn Fn(&str) -> Option<(f64, f64)>,
    fit: &Comparison,
    (on, delay_given): (&str, bool),
) -> Option<String> {
    let info = &common::TERMS[lx];
    let (x, s) = fitted(info.name).filter(|(x, s)| x.abs() > 3.0 * s)?;
    let offered = e.candidates.iter().any(|c| c.term == info.name);
    let by = fit.z.map_or(String::new(), |z| {
        format!(
            " (the re-stamp's difference {} of its σ over {BLOCKS} blocks of fixes, {} of the quiet blocks')",
            sig3(z),
            sig3(fit.z_quiet.unwrap_or(f64::NAN))
        )
    });
    let as_well = if fit.gain() > 0.0 {
        "almost as well (the re-stamp's advantage is within what the data leave to chance)"
    } else {
        "as well or better"
    };
    Some(format!(
        "{on}, {} = {} ± {} {}{} fits the data {as_well}: a log-likelihood {} against {} for the re-stamped fixes{by}. On this motion a lever arm along the track moves the fixes as speed × a time offset does, and the data do not tell them apart; a known lever arm (--lever-arm){}, or a run with more changes of speed, decides",
        info.name,
        sig3(x / info.display_to_si),
        sig3(s / info.display_to_si),
        info.display,
        if offered { "" } else { " (not a candidate here)" },
        sig3(fit.loglik_named),
        sig3(fit.loglik),
        if delay_given { "" } else { " or offset (--gnss-delay)" },
    ))
}

/// Each cause of `e` but the offset against its value on the fixes as given (`fitted`: value
/// and σ, SI; `on`: those fixes in words): one that moves by more than 3σ is not named (its
/// value is the offset's as much as its own, `how`); one that moves by more than σ/2 is given
/// the mean of the two, its σ widened by half their difference (either fit may be the true
/// one).
fn moved_with_the_offset(
    e: &mut Explanation,
    fitted: &dyn Fn(&str) -> Option<(f64, f64)>,
    how: &str,
    on: &str,
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
            "{} ± {} {} on the re-stamped fixes, {} ± {} {} {on}",
            sig3(a),
            sig3(s),
            f.unit,
            sig3(b),
            sig3(sb),
            f.unit
        );
        if (a - b).abs() > 3.0 * s {
            let why = format!(
                "its value moves with the time offset ({both}), which the data do not tell from a lever arm: {how}"
            );
            super::not_named(f, super::Unnamed::OffsetOrLeverArm, why);
            continue;
        }
        if (a - b).abs() <= 0.5 * s {
            // (it does not move: its σ would grow by 3 % at most)
            continue;
        }
        set_value(f, 0.5 * (a + b), (s * s + 0.25 * (a - b).powi(2)).sqrt());
        f.words.push_str(&format!(
            ". Its value moves with the time offset, which the data do not tell from a lever arm: {both}; the value above is the mean of the two, its σ widened by half their difference"
        ));
    }
}
