//! Spec terms kept out of the candidates that explain all a sensor finding does. The rounds can
//! only name the nearest candidate; when a term kept out takes the finding's place and the
//! priors find it the more plausible, it could equally be the cause, and the finding says so
//! instead of naming its own term.

use super::findings::{EquivalentTerm, Finding, Unnamed};
use super::words::sig3;
use super::{model_with, not_named, run_pass, selection, term_index, Context, Rounds};
use crate::model::catalog::{Sensor, StateRef};
use crate::model::generated::common;

/// Each IMU-term finding among `findings` that is no stand-in (a cause, or a class not
/// attributed, which the rounds' model may have dropped) is tried, in one more pass, against
/// the spec terms of its sensor that are not among the candidates `cands`: the model of the
/// rounds without those findings' terms, with the findings and the terms kept out as its
/// candidates. A term kept out that is significant alone and beside which the finding is no
/// longer significant, given the other findings (all it explains, that term explains too),
/// joins its `withheld_alike`. When the priors find such a term more plausible than the
/// finding's (fewer prior σ), or the values differ by 10× in prior σ with the finding's beyond
/// 3, the finding is not named, as the selection treats a class: the data cannot say the cause
/// is its term and not that one. Otherwise it stays named and its words list them. Nothing runs
/// when no term of such a sensor was kept out. (GNSS findings are tried against the GNSS terms
/// kept out in `rivals`, one filter pass each.)
pub(super) fn withheld_alike(
    ctx: &Context,
    r: &Rounds,
    findings: &mut [Finding],
    cands: &[usize],
    progress: &mut dyn FnMut(usize, f64),
) -> anyhow::Result<()> {
    let in_model = |t: usize| r.model.states.contains(&StateRef::Term(t));
    let judged: Vec<(usize, usize)> = findings
        .iter()
        .enumerate()
        .filter(|(_, f)| f.stand_in.is_none() && f.kind != "noise")
        .filter_map(|(k, f)| Some((k, term_index(&f.term)?)))
        .filter(|&(_, t)| !common::TERMS[t].sensor.enters_h())
        .collect();
    // a GNSS term only where the data hold fixes the baseline forms (a turntable's static
    // aiding refuses them)
    let fixes = |w: usize| {
        common::TERMS[w].sensor != Sensor::Gnss
            || model_with(&ctx.baseline.name, [w]).is_ok_and(|m| (ctx.config_for)(&m).is_ok())
    };
    let withheld: Vec<usize> = (0..common::TERM_COUNT)
        .filter(|&w| !cands.contains(&w) && !in_model(w))
        .filter(|&w| judged.iter().any(|&(_, t)| may_take(t, w)))
        .filter(|&w| fixes(w))
        .collect();
    if judged.is_empty() || withheld.is_empty() {
        return Ok(());
    }
    let terms: Vec<usize> = judged.iter().map(|x| x.1).collect();
    let kept = r.model.states.iter().filter_map(|s| match *s {
        StateRef::Term(t) if !ctx.baseline.states.contains(s) && !terms.contains(&t) => Some(t),
        _ => None,
    });
    let m = model_with(&ctx.baseline.name, kept)?;
    let pool: Vec<usize> = terms.iter().chain(&withheld).copied().collect();
    let cfg = ctx.extended_config(&m, &r.widened)?;
    let pass = run_pass(&m, &pool, ctx.data, &cfg, &mut |x| {
        progress(r.rounds + 1, x)
    })?;
    let named: Vec<usize> = (0..terms.len()).collect();
    let others: Vec<usize> = (terms.len()..pool.len()).collect();
    // the misfit left is the rounds' model's: without the findings this pass's own mean NIS
    // would scale every test down by the very misfit they explain (a 60-s demo's kaq_z_yz, 23σ
    // in the extended filter, was no longer significant here)
    let mut sig = pass.sig;
    sig.dispersion = r.pass.sig.dispersion;
    let tried = Tried {
        sig,
        judged,
        pool,
        named,
        others,
    };
    unname_pairs(&tried, findings, ctx.opts);
    unname_moved(&tried, findings, ctx.opts);
    name_taken(&tried, findings, ctx.opts);
    Ok(())
}

/// Whether kept-out term `w` may take the place of a finding of term `t`: a term of the same
/// sensor, or a GNSS term (an antenna lever arm moves the fixes in turns, a time offset by speed
/// × it; an IMU term, an accelerometer delay above all, takes either up: an antenna lever arm
/// kept out gave "Found: accelerometer y delay tau_y = 29.0 ± 6.63 ms" on a simulated drive,
/// helper-55).
fn may_take(t: usize, w: usize) -> bool {
    let (s, sw) = (common::TERMS[t].sensor, common::TERMS[w].sensor);
    s == sw || (sw == Sensor::Gnss && !s.enters_h())
}

/// The pass that tries the terms kept out: its signatures (scaled by the rounds' dispersion),
/// the findings tried ((finding index, term)), the pass's candidates (their terms then the ones
/// kept out), and the indices of each among them.
struct Tried {
    sig: super::signatures::Signatures,
    judged: Vec<(usize, usize)>,
    pool: Vec<usize>,
    named: Vec<usize>,
    others: Vec<usize>,
}

/// One term kept out that takes two findings' place together (each significant beside the
/// other, neither beside it) is the simpler answer for both: both are not named.
fn unname_pairs(tried: &Tried, findings: &mut [Finding], opts: &super::ExplainOptions) {
    let Tried {
        sig,
        judged,
        pool,
        named,
        others,
    } = tried;
    let sensor_of = |x: usize| common::TERMS[pool[x]].sensor;
    let mut pairs = Vec::new();
    for &x in named.iter() {
        // (per sensor: the findings of one, the terms kept out of the same)
        if named[..x].iter().any(|&y| sensor_of(y) == sensor_of(x)) {
            continue;
        }
        let of = |v: &[usize]| -> Vec<usize> {
            v.iter()
                .copied()
                .filter(|&y| sensor_of(y) == sensor_of(x))
                .collect()
        };
        let rivals: Vec<usize> = others
            .iter()
            .copied()
            .filter(|&y| may_take(pool[x], pool[y]))
            .collect();
        pairs.extend(selection::taken_together(
            sig,
            (named, &of(named)),
            &rivals,
            opts,
        ));
    }
    for (a, b, w, est, sd, prior) in pairs {
        if prior > opts.stand_in_prior_sigmas {
            continue;
        }
        let info = &common::TERMS[pool[w]];
        let other = |x: usize| common::TERMS[judged[x].1].name;
        for (x, y) in [(a, b), (b, a)] {
            let f = &mut findings[judged[x].0];
            if f.unnamed_because(Unnamed::WithheldTermFits) {
                continue;
            }
            let why = format!(
                "what it and {} explain together, {} (it would need {} ± {} {}, {} prior σ, by the signatures), which is not among the candidates, explains alone (beside it, neither is significant): one term outside the candidates is the simpler answer and could be the cause of both; offer it as a candidate and run again",
                other(y),
                info.name,
                sig3(est),
                sig3(sd),
                info.display,
                sig3(prior)
            );
            f.withheld_alike
                .push(EquivalentTerm::of(pool[w], (est, sd, prior)));
            not_named(f, Unnamed::WithheldTermFits, why);
        }
    }
}

/// A cause whose value leans on a term kept out (fitted beside it, significant there, the value
/// moves by more than 3σ) is no value of the sensor's: it is not named.
fn unname_moved(tried: &Tried, findings: &mut [Finding], opts: &super::ExplainOptions) {
    let (pool, judged) = (&tried.pool, &tried.judged);
    // (turntable with `!tau_z`: tau_y 3.81 ms for 2 hidden)
    let moved = selection::moved_by(&tried.sig, &tried.named, &tried.others, opts);
    for (&(k, t), moves) in judged.iter().zip(moved) {
        let f = &mut findings[k];
        let Some((w, beside, wv)) = moves.into_iter().find(|m| may_take(t, pool[m.0])) else {
            continue;
        };
        if !f.is_cause() {
            continue;
        }
        let info = &common::TERMS[pool[w]];
        let why = format!(
            "its value leans on {}, which is not among the candidates: fitted beside it ({} = {} ± {} {}, significant there), it would be {} ± {} {} in that pass, beyond 3σ of its value without it; offer {} as a candidate and run again",
            info.name,
            info.name,
            sig3(wv[0]),
            sig3(wv[1]),
            info.display,
            sig3(beside[0]),
            sig3(beside[1]),
            f.unit,
            info.name
        );
        not_named(f, Unnamed::LeansOnWithheldTerm, why);
    }
}

/// The terms kept out that explain all a finding does join its `withheld_alike`; the priors
/// decide whether it is still named (see [`withheld_alike`]).
fn name_taken(tried: &Tried, findings: &mut [Finding], opts: &super::ExplainOptions) {
    let (pool, judged) = (&tried.pool, &tried.judged);
    let taken = selection::taken_by(&tried.sig, &tried.named, &tried.others, opts);
    for (&(k, t), (own, members)) in judged.iter().zip(taken) {
        // (a withheld term of another IMU sensor is no rival of this one)
        let mut members: Vec<EquivalentTerm> = members
            .into_iter()
            .filter(|m| may_take(t, pool[m.0]))
            .map(|(a, estimate, sigma, prior_sigmas)| {
                EquivalentTerm::of(pool[a], (estimate, sigma, prior_sigmas))
            })
            .collect();
        let f = &mut findings[k];
        if members.is_empty() || !own.is_finite() || f.unnamed_because(Unnamed::WithheldTermFits) {
            continue;
        }
        members.sort_by(|a, b| a.prior_sigmas.total_cmp(&b.prior_sigmas));
        let listed: Vec<String> = members
            .iter()
            .map(|m| {
                format!(
                    "{} (it would need {} ± {} {}, {} prior σ, by the signatures)",
                    m.term,
                    sig3(m.estimate),
                    sig3(m.sigma),
                    m.unit,
                    sig3(m.prior_sigmas)
                )
            })
            .collect();
        let (each, which, offer) = if members.len() == 1 {
            ("", "which is", "it as a candidate")
        } else {
            ("each of ", "which are", "them as candidates")
        };
        let most = members[0].prior_sigmas;
        let widest = members
            .iter()
            .map(|m| m.prior_sigmas)
            .chain(f.equivalent_estimates.iter().map(|e| e.prior_sigmas.abs()))
            .fold(own, f64::max);
        let why = if most < own {
            // the selection would have named the withheld term: the priors prefer it
            Some(format!(
                "what it explains, {each}{}, {which} not among the candidates, explains as well (beside it, it is no longer significant), and the spec's priors find {} more plausible than it (its value in that pass needs {} prior σ): a term outside the candidates could equally be the cause; offer {offer} and run again",
                listed.join(", "),
                members[0].term,
                sig3(own)
            ))
        } else if own > 3.0 && widest / own >= selection::UNATTRIBUTED_RATIO {
            // as within a class: priors that do not fit this sensor would choose
            Some(format!(
                "what it explains, {each}{}, {which} not among the candidates, explains as well (beside it, it is no longer significant); its value in that pass needs {} prior σ, and the values would differ by {}× in prior σ: priors that do not fit this sensor would choose, not the data; offer {offer} and run again",
                listed.join(", "),
                sig3(own),
                sig3(widest / own)
            ))
        } else {
            None
        };
        match why {
            Some(why) => {
                f.withheld_alike = members;
                not_named(f, Unnamed::WithheldTermFits, why);
            }
            None => {
                // named by the priors, as the selection names a class's most plausible member
                f.words.push_str(&format!(
                    ". What it explains, {each}{}, {which} not among the candidates, explains as well; the spec's priors find {} (at {} prior σ in that pass) the most plausible",
                    listed.join(", "),
                    f.term,
                    sig3(own)
                ));
                f.withheld_alike = members;
            }
        }
    }
}
