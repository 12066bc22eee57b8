//! Spec terms withheld from the candidates that a sensor finding cannot be told from on these
//! data. The rounds can only name the nearest candidate; when a withheld term has the same
//! signature, it could equally be the cause, and the finding says so instead of naming its term.

use super::findings::{EquivalentTerm, Finding};
use super::words::sig3;
use super::{model_with, not_named, run_pass, selection, term_index, Context, Rounds};
use crate::model::catalog::StateRef;
use crate::model::generated::common;

/// Each IMU-term finding among `findings` that is no stand-in (a cause, or a class not
/// attributed, which the rounds' model may have dropped) is tested, in one more pass, against
/// the spec terms of its sensor withheld from the candidates `cands`: the model of the rounds
/// without those findings' terms, with the findings and the withheld terms as its candidates. A withheld term in a finding's
/// equivalence class given the other findings (the selection's test) joins its
/// `withheld_alike`, and the finding is not named: the data cannot say the cause is its term
/// and not that one. Nothing runs when no term of such a sensor was withheld. (GNSS findings
/// are tried against the withheld GNSS terms in `rivals`, one filter pass each.)
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
    let withheld: Vec<usize> = (0..common::TERM_COUNT)
        .filter(|&w| !cands.contains(&w) && !in_model(w))
        .filter(|&w| {
            judged
                .iter()
                .any(|&(_, t)| common::TERMS[t].sensor == common::TERMS[w].sensor)
        })
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
    let taken = selection::taken_by(&pass.sig, &named, &others, ctx.opts);
    for (&(k, t), (own, members)) in judged.iter().zip(taken) {
        // (a withheld term of another sensor is no rival of this one)
        let sensor = common::TERMS[t].sensor;
        let mut members: Vec<EquivalentTerm> = members
            .into_iter()
            .filter(|m| common::TERMS[pool[m.0]].sensor == sensor)
            .map(|(a, estimate, sigma, prior_sigmas)| {
                let info = &common::TERMS[pool[a]];
                EquivalentTerm {
                    term: info.name.to_string(),
                    estimate,
                    sigma,
                    unit: info.display.to_string(),
                    prior_sigmas,
                }
            })
            .collect();
        if members.is_empty() || !own.is_finite() {
            continue;
        }
        members.sort_by(|a, b| a.prior_sigmas.total_cmp(&b.prior_sigmas));
        let f = &mut findings[k];
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
        let (which, offer) = if members.len() == 1 {
            ("which is", "it as a candidate")
        } else {
            ("which are", "them as candidates")
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
                "what it explains, {}, {which} not among the candidates, explains as well (beside it, it is no longer significant), and the spec's priors find {} more plausible than its {} prior σ: a term outside the candidates could equally be the cause; offer {offer} and run again",
                listed.join(", "),
                members[0].term,
                sig3(own)
            ))
        } else if own > 3.0 && widest / own >= selection::UNATTRIBUTED_RATIO {
            // as within a class: priors that do not fit this sensor would choose
            Some(format!(
                "what it explains, {}, {which} not among the candidates, explains as well (beside it, it is no longer significant); it needs {} prior σ, and the values would differ by {}× in prior σ: priors that do not fit this sensor would choose, not the data; offer {offer} and run again",
                listed.join(", "),
                sig3(own),
                sig3(widest / own)
            ))
        } else {
            None
        };
        match why {
            Some(why) => {
                f.withheld_named = true;
                f.withheld_alike = members;
                not_named(f, why);
            }
            None => {
                // named by the priors, as the selection names a class's most plausible member
                f.words.push_str(&format!(
                    ". What it explains, {}, {which} not among the candidates, explains as well; the spec's priors find {} (at {} prior σ) the most plausible",
                    listed.join(", "),
                    f.term,
                    sig3(own)
                ));
                f.withheld_alike = members;
            }
        }
    }
    Ok(())
}
