//! Rivals of a GNSS finding: the aiding terms withheld from the candidates, and an IMU–GNSS
//! time offset that is no cause, each tried in the finding's place. A lever arm along the track
//! moves the fixes in turns as speed × an offset does; when a rival fits the data as well, the
//! finding may stand in for it and says so.

use super::diagnostics::loglik_of;
use super::findings::{EquivalentTerm, Finding};
use super::restamp;
use super::words::{finding_words, sig3};
use super::{model_with, prior_sigma, run_pass, Context, Rounds};
use crate::estimate::filter::{FilterConfig, FilterRun};
use crate::model::catalog::StateRef;
use crate::model::generated::common;
use crate::model::Model;

/// Each GNSS cause among `findings` (final, of the rounds `r`) beside which the time offset is
/// no cause (not named, its value not fixed, or no candidate) is tried with the offset in its
/// place, fitted to every order on the fixes re-stamped by it: a lever arm along the track
/// moves the fixes as speed × an offset does, and the rounds may name it first. So is each
/// accelerometer delay, with the offset and the horizontal lever arms in its place: where a
/// forward lever arm cancels the offset's position (a car at one speed), what is left of the
/// offset is its along-track acceleration, an accelerometer delay's signature. When the rival
/// fits the data as well, the finding stands in for it. Returns those rivals.
pub(super) fn offset_stand_ins(
    ctx: &Context,
    r: &Rounds,
    findings: &mut [Finding],
    cands: &[usize],
    progress: &mut dyn FnMut(usize, f64),
) -> anyhow::Result<Vec<Option<Rival>>> {
    let term = super::term_index;
    let Some(w) = term("dt_gnss") else {
        return Ok(Vec::new());
    };
    if findings.iter().any(|f| f.term == "dt_gnss" && f.is_cause()) {
        return Ok(Vec::new());
    }
    // no receiver, no offset (a turntable's static aiding): the run refuses GNSS terms
    if (ctx.config_for)(&model_with(&ctx.baseline.name, [w])?).is_err() {
        return Ok(Vec::new());
    }
    // the rival's model drops the stand-ins and the classes not attributed; a finding un-named
    // only because a term kept out may take its place stays, as it was when the rounds fitted
    // the aiding term (dropping it left a drive's hidden g-sensitivity out of the offset's fit,
    // and a lever arm standing in for the offset was named)
    let kept_out_only = |f: &Finding| {
        f.stand_in.is_none()
            && f.not_attributed_because.iter().all(|u| {
                matches!(
                    u,
                    super::Unnamed::WithheldTermFits | super::Unnamed::LeansOnWithheldTerm
                )
            })
    };
    let others: Vec<usize> = findings
        .iter()
        .filter(|f| !f.is_cause() && !kept_out_only(f) && f.term != "dt_gnss")
        .filter_map(|f| term(&f.term))
        .collect();
    let levers: Vec<usize> = ["lever_x", "lever_y"]
        .iter()
        .filter_map(|n| term(n))
        .collect();
    let mut out = Vec::new();
    for f in findings.iter_mut().filter(|f| f.is_cause()) {
        let Some(t) = term(&f.term).filter(|&t| t != w) else {
            continue;
        };
        let with = match common::TERMS[t] {
            // (the receiver's terms: a reference's time offset or mounting is no GNSS term)
            info if info.sensor == common::TERMS[w].sensor => &[][..],
            info if info.group == "accelerometer delay" => &levers[..],
            _ => continue,
        };
        // an accelerometer delay is tried with the offset alone as well: with the lever arms
        // beside it a small offset may fall under 3σ (fixes 10 ms late gave "Found:
        // accelerometer x delay tau_x = -11.5 ± 3.09 ms", helper-56)
        let mut rival = offset_in_place(ctx, r, t, (w, with), &others, cands, progress)?;
        if rival.is_none() && !with.is_empty() {
            rival = offset_in_place(ctx, r, t, (w, &[]), &others, cands, progress)?;
        }
        let Some(rival) = rival else {
            continue;
        };
        rival.put_on(f);
        f.suggested_prior = None;
        let info = &common::TERMS[t];
        (f.headline, f.words) =
            finding_words(f, info, prior_sigma(t, ctx.opts) / info.display_to_si);
        out.push(Some(rival));
    }
    Ok(out)
}

/// For each GNSS finding among `judged` (one per named term of `r`; a cause or a stand-in, not
/// an unattributed class), the GNSS library terms withheld from the candidates `cands` are
/// tried in its place, one filter pass each, and so is a time offset that is no cause here:
/// when one fits the data as well ([`Comparison::as_well`]) at a value beyond 3σ, the finding
/// may stand in for it (a body-x lever arm moves the fixes in turns as speed × a time offset
/// does, an accelerometer delay beside it takes the rest): its stand-in reason says which, with
/// the value. Returns the rival of each finding (None where none fits).
pub(super) fn withheld_rivals(
    ctx: &Context,
    r: &Rounds,
    judged: &mut [Finding],
    cands: &[usize],
    progress: &mut dyn FnMut(usize, f64),
) -> anyhow::Result<Vec<Option<Rival>>> {
    let offset = super::term_index("dt_gnss");
    let offset_is_cause = judged.iter().any(|f| f.term == "dt_gnss" && f.is_cause());
    let stand_ins: Vec<usize> = judged
        .iter()
        .zip(&r.named)
        .filter(|(f, _)| f.stand_in.is_some())
        .map(|(_, n)| n.term)
        .collect();
    let mut out = vec![None; judged.len()];
    for (k, (f, n)) in judged.iter().zip(&r.named).enumerate() {
        let info = &common::TERMS[n.term];
        // (a stand-in too: its words should name the rival that may take its place)
        if f.not_attributed.is_some() || !info.sensor.enters_h() {
            continue;
        }
        let rivals = (0..common::TERMS.len()).filter(|&w| {
            let withheld = !cands.contains(&w) && !r.model.states.contains(&StateRef::Term(w));
            common::TERMS[w].sensor == info.sensor
                && w != n.term
                && (withheld || (Some(w) == offset && !offset_is_cause))
        });
        for w in rivals {
            let rival = if Some(w) == offset {
                offset_in_place(ctx, r, n.term, (w, &[]), &stand_ins, cands, progress)?
            } else {
                term_in_place(ctx, r, n.term, w, progress)?.map(|why| Rival {
                    why,
                    offset: None,
                    beside: Vec::new(),
                    tie: None,
                })
            };
            if rival.is_some() {
                out[k] = rival;
                break;
            }
        }
    }
    for (f, rival) in judged.iter_mut().zip(&out) {
        if let Some(rival) = rival {
            rival.put_on(f);
        }
    }
    Ok(out)
}

/// Why the finding of term `t` may stand in for `w` (a GNSS term withheld from the candidates)
/// when the rounds' model with `w` in its place fits the data as well, else None.
fn term_in_place(
    ctx: &Context,
    r: &Rounds,
    t: usize,
    w: usize,
    progress: &mut dyn FnMut(usize, f64),
) -> anyhow::Result<Option<String>> {
    let rival = &common::TERMS[w];
    // the rounds' terms beyond the baseline, the finding's replaced by the rival
    let terms = extra_terms(ctx, r).map(|x| if x == t { w } else { x });
    let m = model_with(&ctx.baseline.name, terms)?;
    let cfg = ctx.extended_config(&m, &r.widened)?;
    let p = run_pass(&m, &[], ctx.data, &cfg, &mut |x| progress(r.rounds + 1, x))?;
    let (Some(i), Some(last)) = (m.index_of(rival.name), p.run.records.last()) else {
        return Ok(None);
    };
    let occam = occam(ctx, &m, &cfg, &last.sigma) - named_occam(ctx, r)?;
    let fit = compare(ctx.data, &r.pass.run, &p.run, (0.0, occam));
    let (value, sigma) = (last.x[i], last.sigma[i]);
    Ok(fit.and_then(|fit| rival_words(rival, true, (value, sigma), "", &fit)))
}

/// Why the finding of term `t` may stand in for a time offset (term `w`, no cause here; with the
/// terms `with` beside it) when the offset fits the data as well in its place, fitted to every
/// order on the fixes re-stamped by it: first with the rounds' other terms but the stand-ins
/// `stand_ins` (an accelerometer delay takes the along-track part of an offset), then, when that
/// falls short and other terms are left, alone (a delay named a cause beside the lever arm
/// takes that part too); else None.
fn offset_in_place(
    ctx: &Context,
    r: &Rounds,
    t: usize,
    (w, with): (usize, &[usize]),
    stand_ins: &[usize],
    cands: &[usize],
    progress: &mut dyn FnMut(usize, f64),
) -> anyhow::Result<Option<Rival>> {
    let rival = &common::TERMS[w];
    let others: Vec<usize> = extra_terms(ctx, r)
        .filter(|x| *x != t && *x != w && !stand_ins.contains(x))
        .collect();
    let dropped: Vec<&str> = extra_terms(ctx, r)
        .filter(|x| *x != t && *x != w && stand_ins.contains(x))
        .map(|x| common::TERMS[x].name)
        .collect();
    let all: Vec<&str> = extra_terms(ctx, r)
        .filter(|x| *x != t && *x != w)
        .map(|x| common::TERMS[x].name)
        .collect();
    let with_names: Vec<&str> = with.iter().map(|x| common::TERMS[*x].name).collect();
    let tries = [
        (&others[..], dropped),
        (&[][..], if others.is_empty() { vec![] } else { all }),
    ];
    for (k, (keep, without)) in tries.into_iter().enumerate() {
        if k == 1 && without.is_empty() {
            break;
        }
        let added = with
            .iter()
            .copied()
            .filter(|x| *x != t && !keep.contains(x));
        let m = model_with(
            &ctx.baseline.name,
            keep.iter().copied().chain(added).chain([w]),
        )?;
        let cfg = ctx.extended_config(&m, &r.widened)?;
        let p = run_pass(&m, &[], ctx.data, &cfg, &mut |x| progress(r.rounds + 1, x))?;
        let Some(i) = m.index_of(rival.name) else {
            return Ok(None);
        };
        let Some(o) = restamp::rival_offset(ctx.data, &m, i, &cfg, &p, &mut |x| {
            progress(r.rounds + 1, x)
        })?
        else {
            return Ok(None);
        };
        let last = o.pass.as_ref().unwrap_or(&p);
        let Some(end) = last.run.records.last() else {
            return Ok(None);
        };
        let occam = occam(ctx, &m, &cfg, &end.sigma) - named_occam(ctx, r)?;
        let Some(fit) = compare(ctx.data, &r.pass.run, &last.run, (o.shift_s, occam)) else {
            return Ok(None);
        };
        let how = format!(
            " (± {} {}, fitted to every order on the fixes re-stamped by it{}; log-likelihoods over the fixes both runs take)",
            sig3(o.sigma_s / rival.display_to_si),
            rival.display,
            [("with", with_names.clone()), ("without", without)]
                .iter()
                .filter(|(_, n)| !n.is_empty())
                .map(|(w, n)| format!(", {w} {}", n.join(", ")))
                .collect::<String>()
        );
        let withheld = !cands.contains(&w);
        let unit = 1.0 / rival.display_to_si;
        let words = rival_words(rival, withheld, (o.offset_s, o.sigma_s), &how, &fit);
        // a candidate offset alone in a GNSS term's place that fits as well, but not better
        // beyond chance (not even in a few blocks, where a vehicle's speed changes): the two
        // are one class, neither probably the other's stand-in
        let tie = (!withheld
            && with.is_empty()
            && common::TERMS[t].sensor.enters_h()
            && !fit.better_in_few_blocks())
        .then(|| {
            let prior_sigmas = (o.offset_s / prior_sigma(w, ctx.opts)).abs();
            EquivalentTerm::of(w, (o.offset_s * unit, o.sigma_s * unit, prior_sigmas))
        });
        if let Some(why) = words {
            let beside = keep
                .iter()
                .filter_map(|&x| {
                    let j = m.index_of(common::TERMS[x].name)?;
                    Some((x, end.x[j], end.sigma[j]))
                })
                .collect();
            return Ok(Some(Rival {
                why,
                offset: Some([o.offset_s * unit, o.sigma_s * unit]),
                beside,
                tie,
            }));
        }
    }
    Ok(None)
}

/// A term that fits the data as well in a finding's place.
#[derive(Clone)]
pub(super) struct Rival {
    /// Why the finding may stand in for it.
    pub(super) why: String,
    /// For a time offset: its value and σ (display unit, ms).
    pub(super) offset: Option<[f64; 2]>,
    /// The rounds' other terms as fitted with the rival in the finding's place: (term, value,
    /// σ; SI).
    pub(super) beside: Vec<(usize, f64, f64)>,
    /// A candidate time offset alone in a GNSS finding's place that fits as well but not
    /// better beyond chance: its value there (display unit). The finding and the offset are
    /// then one class the data do not tell apart, not a stand-in and what it stands for.
    pub(super) tie: Option<EquivalentTerm>,
}

impl Rival {
    /// Puts the rival on finding `f`: a tie makes `f` a class with the offset (not attributed,
    /// the offset its equivalent), else `f` stands in for the rival.
    fn put_on(&self, f: &mut Finding) {
        f.offset_in_place = self.offset;
        match &self.tie {
            Some(eq) if f.stand_in.is_none() => {
                f.add_equivalent(eq.clone());
                f.separate_by.push(
                    "a known lever arm (--lever-arm) or offset (--gnss-delay), or a run with more changes of speed".into(),
                );
                super::not_named(f, super::Unnamed::OffsetOrLeverArm, self.why.clone());
            }
            _ => f.stand_in = super::joined(f.stand_in.take(), Some(self.why.clone())),
        }
    }
}

/// Each noise level among `findings` named a cause while a finding stands in for a time offset
/// (`rivals`: those that took the stand-ins' places) is not named: the model it was fitted in
/// leaves the offset to the stand-in (or, without it, to nothing), and a white-noise level or an
/// aiding σ takes up part of what the offset does.
pub(super) fn noise_beside_an_offset<'a>(
    findings: &mut [Finding],
    rivals: impl Iterator<Item = &'a Option<Rival>>,
) {
    let Some([d, sd]) = rivals.flatten().find_map(|r| r.offset) else {
        return;
    };
    for f in findings
        .iter_mut()
        .filter(|f| f.kind == "noise" && f.is_cause())
    {
        let why = format!(
            "it was fitted while a finding stands in for an IMU–GNSS time offset of {} ± {} ms the model does not hold, and a noise level fitted beside an effect left out takes part of it: fit the offset (offer dt_gnss as a candidate, or give --gnss-delay) and run again",
            sig3(d),
            sig3(sd)
        );
        super::not_named(f, super::Unnamed::NoiseBesideOffset, why);
    }
}

/// Each cause among `findings` whose value moves when a rival takes a stand-in's place
/// (`rivals`, one per named term of the rounds): fitted with the rival, it differs from the
/// finding's by more than 3σ of the two, or is no longer beyond 3σ. Its value leaned on the
/// stand-in (the causes beside a lever arm that stands in for a withheld time offset took part
/// of the offset), so it is not named. Returns whether any was unnamed.
pub(super) fn leaning_on_stand_ins(findings: &mut [Finding], rivals: &[Option<Rival>]) -> bool {
    let mut any = false;
    for rival in rivals.iter().flatten() {
        for &(t, v, sd) in &rival.beside {
            let info = &common::TERMS[t];
            let Some(f) = findings
                .iter_mut()
                .find(|f| f.term == info.name && f.is_cause())
            else {
                continue;
            };
            let (v, sd) = (v / info.display_to_si, sd / info.display_to_si);
            let moved = (f.estimate - v).abs() > 3.0 * f.sigma.hypot(sd);
            if !(moved || v.abs() <= 3.0 * sd) {
                continue;
            }
            let stand_in = rival.why.split(" (").next().unwrap_or_default();
            let why = format!(
                "with {stand_in} in a stand-in's place it comes out {} ± {} {}: its value here leans on the stand-in",
                sig3(v),
                sig3(sd),
                f.unit
            );
            super::not_named(f, super::Unnamed::LeansOnStandIn, why);
            any = true;
        }
    }
    any
}

/// The terms of the rounds' model beyond the baseline.
fn extra_terms<'a>(ctx: &'a Context, r: &'a Rounds) -> impl Iterator<Item = usize> + 'a {
    r.model.states.iter().filter_map(|s| match *s {
        StateRef::Term(t) if !ctx.baseline.states.contains(s) => Some(t),
        _ => None,
    })
}

/// The words of a rival that fits the data as well as the finding (`fit`) at a value beyond 3σ
/// (`value`, σ: SI; `how`: how it was fitted), else None (a rival at nothing fits as well only
/// where the finding barely fits at all); `withheld`: it was no candidate.
fn rival_words(
    rival: &crate::model::catalog::TermInfo,
    withheld: bool,
    (value, sigma): (f64, f64),
    how: &str,
    fit: &Comparison,
) -> Option<String> {
    (fit.as_well() && value.abs() > 3.0 * sigma).then(|| {
        let by = fit.z.map_or(String::new(), |z| {
            format!(" (the difference {} of its σ over {BLOCKS} blocks of fixes)", sig3(z))
        });
        format!(
            "{} ({}; {}) in its place fits the data {}: {} = {} {}{} gives a log-likelihood {} against {}{by}; {}",
            rival.name,
            rival.doc,
            if withheld { "not a candidate here" } else { "a candidate that was not named" },
            if fit.better() { "better" } else { "as well" },
            rival.name,
            sig3(value / rival.display_to_si),
            rival.display,
            how,
            sig3(fit.loglik),
            sig3(fit.loglik_named),
            if withheld {
                "offer it as a candidate to tell them apart"
            } else {
                "the data do not tell them apart"
            }
        )
    })
}

/// Blocks of consecutive fixes the log-likelihood difference of two fits is summed over: their
/// spread gives the difference's σ with the innovations' correlation in time inside a block.
pub(super) const BLOCKS: usize = 20;
/// Fewest fixes for the block test (two per block); below, two fits are told apart by a
/// log-likelihood of 2.
const MIN_FIXES: usize = 2 * BLOCKS;
/// Student's t at 0.975 on `BLOCKS` − 1 = 19 degrees of freedom.
const T_19: f64 = 2.093;
/// The bar of [`Comparison::better_in_few_blocks`] on the difference in the quiet blocks' σ:
/// on simulated drives a lever arm's rival time offset reached 3.4, a 30-ms offset 6.8 to 27.
const QUIET_Z: f64 = 5.0;

/// A rival's fit against the named model's over the fixes both runs take.
#[derive(Debug, Clone, Copy)]
pub(super) struct Comparison {
    /// The rival's log-likelihood.
    pub(super) loglik: f64,
    /// The named model's.
    pub(super) loglik_named: f64,
    /// The rival's Occam factor less the named model's ([`occam`]), added to the difference:
    /// the filter's log-likelihood is a marginal one, lower by it for each fitted term.
    pub(super) occam: f64,
    /// Their difference (with `occam`) in its σ (from the spread of [`BLOCKS`] blocks of consecutive fixes);
    /// `None` with fewer than [`MIN_FIXES`] fixes.
    pub(super) z: Option<f64>,
    /// The difference in its σ from the quiet blocks alone: the blocks' spread taken as
    /// 1.4826 × their median absolute deviation, which a few blocks that hold the whole
    /// difference (a vehicle's speed changes) do not inflate; `None` as `z`.
    pub(super) z_quiet: Option<f64>,
    /// The fixes compared.
    pub(super) fixes: usize,
}

impl Comparison {
    /// The rival's log-likelihood less the named model's, with the Occam factors.
    pub(super) fn gain(&self) -> f64 {
        self.loglik - self.loglik_named + self.occam
    }

    /// The rival fits the data as well: not worse beyond chance (t < −2.09 on 19 degrees of
    /// freedom; a log-likelihood within 2 without the block test).
    fn as_well(&self) -> bool {
        let diff = self.gain();
        self.z.map_or(diff >= -2.0, |z| z >= -T_19)
    }

    /// The rival fits better beyond chance.
    fn better(&self) -> bool {
        let diff = self.gain();
        self.z.map_or(diff > 2.0, |z| z > T_19)
    }

    /// The rival fits better beyond chance where the difference lies in a few blocks: against
    /// the quiet blocks' spread by more than [`QUIET_Z`] and by more than ln N in all (N the
    /// fixes compared; explain's bar for a term). The spread of all blocks holds the difference
    /// itself when a few hold it all (a time offset shows in a vehicle's speed changes, two of
    /// them on a drive), and their t-test stays near 2 at any size of it.
    pub(super) fn better_in_few_blocks(&self) -> bool {
        self.better()
            || (self.z_quiet.is_some_and(|z| z > QUIET_Z)
                && self.gain() > (self.fixes.max(2) as f64).ln())
    }
}

/// How run `rival` (its GNSS fixes re-stamped by `shift` [s]) fits against `named` (the fixes as
/// given) over the fixes both take: stamps inside the given ones by the re-stamp on either side,
/// paired by stamp; None without fixes.
pub(super) fn compare(
    data: &super::ExplainData,
    named: &FilterRun,
    rival: &FilterRun,
    (shift, occam): (f64, f64),
) -> Option<Comparison> {
    let stamps = || {
        data.aid
            .iter()
            .filter(|e| e.pos.is_some() || e.vel.is_some())
    };
    let (lo, hi) = (stamps().next()?, stamps().next_back()?);
    let (lo, hi) = (lo.t.max(data.start.t) + shift.abs(), hi.t - shift.abs());
    // a fix's stamp (the GNSS measurements moved by the re-stamp, the references did not), in µs
    let per_fix = |run: &FilterRun, by: f64| {
        let mut m = std::collections::BTreeMap::<i64, f64>::new();
        for n in &run.innovations {
            let t = match n.meas {
                "vel_body" | "att_ref" => n.t,
                _ => n.t - by,
            };
            if t > lo && t <= hi {
                *m.entry((t * 1e6).round() as i64).or_default() += loglik_of(n);
            }
        }
        m
    };
    let (a, b) = (per_fix(rival, shift), per_fix(named, 0.0));
    let pairs: Vec<(f64, f64)> = a
        .iter()
        .filter_map(|(k, x)| b.get(k).map(|y| (*x, *y)))
        .collect();
    let loglik: f64 = pairs.iter().map(|p| p.0).sum();
    let loglik_named: f64 = pairs.iter().map(|p| p.1).sum();
    let sums: Vec<f64> = (0..BLOCKS)
        .map(|k| {
            let (i, j) = (k * pairs.len() / BLOCKS, (k + 1) * pairs.len() / BLOCKS);
            pairs[i..j].iter().map(|p| p.0 - p.1).sum()
        })
        .collect();
    let enough = pairs.len() >= MIN_FIXES;
    let diff = loglik - loglik_named + occam;
    let z_quiet = enough.then(|| {
        let median = |mut v: Vec<f64>| {
            v.sort_by(f64::total_cmp);
            0.5 * (v[(v.len() - 1) / 2] + v[v.len() / 2])
        };
        let m = median(sums.clone());
        let mad = median(sums.iter().map(|s| (s - m).abs()).collect());
        in_sigmas(diff, (BLOCKS as f64).sqrt() * 1.4826 * mad)
    });
    let z = enough.then(|| {
        let mean = sums.iter().sum::<f64>() / BLOCKS as f64;
        let var = sums.iter().map(|s| (s - mean).powi(2)).sum::<f64>() / (BLOCKS - 1) as f64;
        // the total's σ: √(blocks × the blocks' variance)
        in_sigmas(diff, (BLOCKS as f64 * var).sqrt())
    });
    Some(Comparison {
        loglik,
        loglik_named,
        occam,
        z,
        z_quiet,
        fixes: pairs.len(),
    })
}

/// `diff` in units of `sd`: a difference of nothing is 0σ, any other over no spread ±∞.
fn in_sigmas(diff: f64, sd: f64) -> f64 {
    if sd > 0.0 {
        diff / sd
    } else if diff == 0.0 {
        0.0
    } else {
        diff.signum() * f64::INFINITY
    }
}

/// The Occam factor of `model`'s terms beyond the baseline, fitted with the priors of `cfg` to
/// the final σ `sigma` (SI): Σ ln(prior / σ). A filter's log-likelihood is the data's marginal
/// likelihood, lower by about this than the best fit's (Laplace's approximation), so two models
/// with different numbers of terms are compared with it taken out.
pub(super) fn occam(ctx: &Context, model: &Model, cfg: &FilterConfig, sigma: &[f64]) -> f64 {
    model
        .states
        .iter()
        .enumerate()
        .filter(|(_, s)| matches!(s, StateRef::Term(_)) && !ctx.baseline.states.contains(s))
        .filter_map(|(i, _)| {
            let (prior, post) = (cfg.prior_sigma[i], *sigma.get(i)?);
            (post > 0.0 && prior > post).then(|| (prior / post).ln())
        })
        .sum()
}

/// [`occam`] of the rounds' model `r` (its pass's final σ).
fn named_occam(ctx: &Context, r: &Rounds) -> anyhow::Result<f64> {
    let cfg = ctx.extended_config(&r.model, &r.widened)?;
    Ok(r.pass
        .run
        .records
        .last()
        .map_or(0.0, |last| occam(ctx, &r.model, &cfg, &last.sigma)))
}
