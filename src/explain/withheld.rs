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
    let alike = selection::alike_beside(&pass.sig, &named, &others, ctx.opts);
    for (&(k, t), members) in judged.iter().zip(alike) {
        // (a withheld term of another sensor is no rival of this one)
        let sensor = common::TERMS[t].sensor;
        let members: Vec<EquivalentTerm> = members
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
        if members.is_empty() {
            continue;
        }
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
        let why = format!(
            "the data cannot tell it from {}, which {} not among the candidates: a term outside the candidates fits these data as well and could equally be the cause; offer {} as a candidate and run again",
            listed.join(", "),
            if members.len() == 1 { "is" } else { "are" },
            if members.len() == 1 { "it" } else { "them" }
        );
        f.withheld_alike = members;
        not_named(f, why);
    }
    Ok(())
}
