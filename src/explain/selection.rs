//! Selection on a pass's joint information: conditional llr (Schur complements), Holm, equivalence classes.

use super::findings::{CandidateTest, Implausible};
use super::signatures::{Signatures, Split};
use super::ExplainOptions;
use crate::estimate::stats;
use crate::model::generated::common;
use crate::model::regressor_reads;
use nalgebra::DMatrix;

/// A pass's information and score, prior-scaled: J' = D J D, b' = D b with D = diag(σ_prior),
/// over the whole pass and per group of each split of its updates.
pub(super) struct Scaled {
    /// J' over the whole pass.
    pub(super) j: DMatrix<f64>,
    /// b' over the whole pass.
    pub(super) b: Vec<f64>,
    /// Prior σ of each candidate (SI).
    pub(super) sd: Vec<f64>,
    /// (J', b') of each group of each split of the updates.
    pub(super) splits: Vec<(Split, Vec<InfoScore>)>,
}

/// Specific-force spread within a filter step [m/s², rms about the step mean] above which the
/// run counts as vibrating (a car's ride is ~0.5; a sensor at rest shows its noise, < 0.05).
const MIN_VIBRATION: f64 = 0.1;

/// A prior-scaled information matrix J' and score b'.
pub(super) type InfoScore = (DMatrix<f64>, Vec<f64>);

/// The prior-scaled quantities of a pass.
pub(super) fn scaled(sig: &Signatures, opts: &ExplainOptions) -> Scaled {
    let m = sig.cands.len();
    let sd: Vec<f64> = sig
        .cands
        .iter()
        .map(|&t| prior_sigma(t, opts).max(f64::MIN_POSITIVE))
        .collect();
    // quasi-likelihood: innovations φ times larger than S predicts scale the information and
    // score by 1/φ, so an inconsistent baseline does not make every candidate significant
    let phi = sig.dispersion.max(1.0);
    let scale = |info: &[f64], score: &[f64]| {
        (
            DMatrix::from_fn(m, m, |a, b| info[a * m + b] * sd[a] * sd[b] / phi),
            (0..m).map(|a| score[a] * sd[a] / phi).collect::<Vec<f64>>(),
        )
    };
    let (j, b) = scale(&sig.info(), &sig.score());
    let splits = sig
        .splits
        .iter()
        .map(|acc| {
            let groups = acc
                .info
                .iter()
                .zip(&acc.score)
                .map(|(i, b)| scale(i, b))
                .collect();
            (acc.split, groups)
        })
        .collect();
    Scaled { j, b, sd, splits }
}

/// Prior σ of term `t` (SI): the override in `opts`, else the spec's.
pub fn prior_sigma(t: usize, opts: &ExplainOptions) -> f64 {
    opts.candidate_sigma
        .iter()
        .find(|x| x.0 == t)
        .map(|x| x.1)
        .unwrap_or(common::TERMS[t].sigma)
}

/// Conditional information, score and correlation of candidate `c` given the set `s`.
pub(super) fn conditional(j: &DMatrix<f64>, b: &[f64], s: &[usize], c: usize) -> (f64, f64) {
    if s.is_empty() {
        return (j[(c, c)], b[c]);
    }
    let jss = DMatrix::from_fn(s.len(), s.len(), |x, y| j[(s[x], s[y])]);
    let Some(inv) = jss.clone().try_inverse() else {
        return (0.0, 0.0);
    };
    let jcs = DMatrix::from_fn(1, s.len(), |_, y| j[(c, s[y])]);
    let bs = DMatrix::from_fn(s.len(), 1, |x, _| b[s[x]]);
    let i_c = j[(c, c)] - (&jcs * &inv * jcs.transpose())[(0, 0)];
    let b_c = b[c] - (&jcs * &inv * bs)[(0, 0)];
    (i_c, b_c)
}

pub(super) fn conditional_rho(j: &DMatrix<f64>, s: &[usize], a: usize, c: usize) -> f64 {
    let cross = if s.is_empty() {
        j[(a, c)]
    } else {
        let jss = DMatrix::from_fn(s.len(), s.len(), |x, y| j[(s[x], s[y])]);
        match jss.try_inverse() {
            Some(inv) => {
                let ja = DMatrix::from_fn(1, s.len(), |_, y| j[(a, s[y])]);
                let jc = DMatrix::from_fn(s.len(), 1, |x, _| j[(s[x], c)]);
                j[(a, c)] - (&ja * &inv * &jc)[(0, 0)]
            }
            None => return 0.0,
        }
    };
    let (ia, _) = conditional(j, &vec![0.0; j.nrows()], s, a);
    let (ic, _) = conditional(j, &vec![0.0; j.nrows()], s, c);
    if ia <= 0.0 || ic <= 0.0 {
        return 0.0;
    }
    cross / (ia * ic).sqrt()
}

/// A candidate the selection names, with its equivalence class.
pub(super) struct Selected {
    pub(super) idx: usize,
    /// Its GLR estimate and σ (display unit) from each group of each split of the updates
    /// alone, given the terms chosen before it (NaN, ∞ without information there).
    pub(super) splits: Vec<(Split, Vec<(f64, f64)>)>,
    pub(super) llr: f64,
    pub(super) p: f64,
    pub(super) glr: f64,
    pub(super) glr_sigma: f64,
    /// The other members: (candidate index, conditional GLR estimate, σ, display unit).
    pub(super) class: Vec<(usize, f64, f64)>,
    /// The values the members would need differ by [`UNATTRIBUTED_RATIO`] or more in prior σ:
    /// the priors, not the data, chose the named one (largest over smallest).
    pub(super) prior_ratio: f64,
}

/// Ratio of the prior-σ counts within an equivalence class at which the priors, not the data,
/// would choose its member: the class is reported, no member named as a cause.
pub(super) const UNATTRIBUTED_RATIO: f64 = 10.0;

/// Forward selection on one pass's joint information (prior-scaled) over the `eligible`
/// candidates, with `innovations` scalar innovations in the pass.
///
/// Each step takes the candidate with the largest conditional llr; it must pass Holm's test at
/// α over the candidates left *and* lower the BIC (llr > ln N). Candidates join its equivalence
/// class when their conditional signatures correlate at |ρ| > `rho_equivalent`, the data do not
/// prefer the best one by more than the α-level χ²₁ quantile, *and* beside the best one they
/// are no longer significant at that quantile (with much information, |ρ| = 0.97 can still
/// separate two terms, and two terms present together are then both kept in the pool). Within a class the data cannot choose, so the
/// member the spec's priors find most plausible (fewest prior σ) is named and the rest listed
/// with the value each would need.
pub(super) fn forward_select(
    sig: &Signatures,
    eligible: &[bool],
    innovations: usize,
    opts: &ExplainOptions,
) -> (Vec<Selected>, Vec<Implausible>) {
    select(&scaled(sig, opts), &sig.cands, eligible, innovations, opts)
}

/// [`forward_select`] on the prior-scaled quantities `sc` of the candidate terms `cands` (term
/// indices).
fn select(
    sc: &Scaled,
    cands: &[usize],
    eligible: &[bool],
    innovations: usize,
    opts: &ExplainOptions,
) -> (Vec<Selected>, Vec<Implausible>) {
    let (j, b, sd) = (&sc.j, &sc.b[..], &sc.sd[..]);
    let m = cands.len();
    let margin = stats::chi2_isf(opts.alpha, 1.0);
    let bic = (innovations.max(2) as f64).ln();
    let mut pool: Vec<usize> = (0..m).filter(|&c| eligible[c]).collect();
    let mut chosen: Vec<usize> = Vec::new();
    let mut out = Vec::new();
    let mut implausible = Vec::new();
    while !pool.is_empty() {
        let cond = |c: usize, chosen: &[usize]| cond_llr(j, b, chosen, c);
        let mut best: Option<(usize, f64)> = None;
        for &c in &pool {
            if let Some((llr, _, _)) = cond(c, &chosen) {
                if best.is_none_or(|x| llr > x.1) {
                    best = Some((c, llr));
                }
            }
        }
        let Some((c, llr)) = best else {
            break;
        };
        let p = stats::chi2_sf(llr, 1.0);
        if p * pool.len() as f64 > opts.alpha || llr <= bic {
            break;
        }
        let (c, llr) = if opts.broken_selector {
            let k = (chosen.len() * 7 + pool.len() * 13 + 5) % pool.len();
            (pool[k], cond(pool[k], &chosen).map(|x| x.0).unwrap_or(llr))
        } else {
            (c, llr)
        };
        let mut members: Vec<(usize, f64, f64)> = vec![]; // (cand, θ' prior-scaled, info)
        let with_c: Vec<usize> = chosen.iter().copied().chain([c]).collect();
        for &a in &pool {
            if a == c || equivalent((j, b), (&chosen, &with_c), (a, c, llr), (margin, opts)) {
                if let Some((_, ia, ba)) = cond(a, &chosen) {
                    members.push((a, ba / ia, ia));
                }
            }
        }
        // name the most plausible member: the fewest prior σ
        members.sort_by(|x, y| x.1.abs().total_cmp(&y.1.abs()));
        let (named, theta, info) = members[0];
        let display = |a: usize, th: f64, ia: f64| {
            let to_display = sd[a] / common::TERMS[cands[a]].display_to_si;
            (th * to_display, to_display / ia.sqrt())
        };
        let (glr, glr_sigma) = display(named, theta, info);
        let named_llr = cond(named, &chosen).map(|x| x.0).unwrap_or(llr);
        if theta.abs() > opts.max_prior_sigmas {
            // even the most plausible member would need an implausible value: not named
            for &(a, th, ia) in &members {
                let (e, s) = display(a, th, ia);
                implausible.push(Implausible {
                    term: common::TERMS[cands[a]].name.to_string(),
                    estimate: e,
                    sigma: s,
                    unit: common::TERMS[cands[a]].display.to_string(),
                    prior_sigmas: th.abs(),
                    llr: cond(a, &chosen).map(|x| x.0).unwrap_or(0.0),
                });
            }
            pool.retain(|a| !members.iter().any(|m| m.0 == *a));
            continue;
        }
        out.push(Selected {
            idx: named,
            splits: Vec::new(),
            llr: named_llr,
            p: (stats::chi2_sf(named_llr, 1.0) * pool.len() as f64).min(1.0),
            glr,
            glr_sigma,
            prior_ratio: members.last().map_or(1.0, |l| l.1.abs())
                / theta.abs().max(f64::MIN_POSITIVE),
            class: members[1..]
                .iter()
                .map(|&(a, th, ia)| {
                    let (e, s) = display(a, th, ia);
                    (a, e, s)
                })
                .collect(),
        });
        chosen.push(named);
        pool.retain(|a| !members.iter().any(|m| m.0 == *a));
    }
    // each named term's estimate from each group of the data alone, the other named terms free
    // there too (given only those named before it, a term selected first would carry what the
    // later ones describe, and its groups would disagree)
    for sel in &mut out {
        let others: Vec<usize> = chosen.iter().copied().filter(|&c| c != sel.idx).collect();
        sel.splits = split_estimates(sc, cands, sel.idx, &others);
    }
    (out, implausible)
}

/// (llr, information, score) of candidate `c` given the set `chosen`; None without information
/// beside it.
fn cond_llr(j: &DMatrix<f64>, b: &[f64], chosen: &[usize], c: usize) -> Option<(f64, f64, f64)> {
    let (ic, bc) = conditional(j, b, chosen, c);
    (ic > 1e-12 * j[(c, c)].max(f64::MIN_POSITIVE)).then(|| (bc * bc / ic, ic, bc))
}

/// Whether candidate `a` is in the equivalence class of `c` (conditional llr `llr_c`) given the
/// set `chosen` (`with_c`: it and `c`), on the prior-scaled (J', b'): their conditional
/// signatures correlate at |ρ| > `rho_equivalent`, the data do not prefer `c` by more than
/// `margin` (the α-level χ²₁ quantile), and beside `c` the term `a` is no longer significant at
/// that quantile (a term still significant beside c is not c's equivalent: the data separate
/// them and hold both, as d and kas hidden on one axis, which correlate at |ρ| > 0.97).
fn equivalent(
    (j, b): (&DMatrix<f64>, &[f64]),
    (chosen, with_c): (&[usize], &[usize]),
    (a, c, llr_c): (usize, usize, f64),
    (margin, opts): (f64, &ExplainOptions),
) -> bool {
    let separable = || cond_llr(j, b, with_c, a).is_some_and(|(l, _, _)| l >= margin);
    conditional_rho(j, chosen, a, c).abs() > opts.rho_equivalent
        && cond_llr(j, b, chosen, a).is_some_and(|(la, _, _)| llr_c - la < margin)
        && !separable()
}

/// Candidate `x`'s GLR estimate and σ in its display unit, and |estimate| in prior σ, from its
/// conditional information `ix` and score `bx` on the prior-scaled `sc` (candidates `cands`).
fn shown(sc: &Scaled, cands: &[usize], x: usize, (ix, bx): (f64, f64)) -> (f64, f64, f64) {
    let to_display = sc.sd[x] / common::TERMS[cands[x]].display_to_si;
    let theta = bx / ix;
    (theta * to_display, to_display / ix.sqrt(), theta.abs())
}

/// The log-likelihood ratio b_Sᵀ J_SS⁻¹ b_S of the candidates `set` together, given `chosen`
/// (their joint conditional test, χ²_|set| under the null); 0 where the information is singular.
fn joint_llr(j: &DMatrix<f64>, b: &[f64], chosen: &[usize], set: &[usize]) -> f64 {
    let fit = |idx: &[usize]| -> Option<f64> {
        if idx.is_empty() {
            return Some(0.0);
        }
        let jj = DMatrix::from_fn(idx.len(), idx.len(), |x, y| j[(idx[x], idx[y])]);
        let bb = nalgebra::DVector::from_fn(idx.len(), |x, _| b[idx[x]]);
        let sol = jj.cholesky()?.solve(&bb);
        Some(bb.dot(&sol))
    };
    let all: Vec<usize> = chosen.iter().chain(set).copied().collect();
    match (fit(&all), fit(chosen)) {
        (Some(a), Some(c)) => (a - c).max(0.0),
        _ => 0.0,
    }
}

/// Pairs of the candidates `pairs_of` (indices into `sig.cands`, among `named`) that one
/// candidate among `others` takes the place of together, given the rest of `named`: the pair
/// is significant together (at the α-level χ²₂ quantile) and each beside the other (χ²₁), the
/// other is significant alone, and beside it the pair is no longer significant, together or
/// each beside the other. Each as (a, b, that candidate, its GLR estimate, σ, display
/// unit; |estimate| in prior σ), given the rest.
pub(super) fn taken_together(
    sig: &Signatures,
    (named, pairs_of): (&[usize], &[usize]),
    others: &[usize],
    opts: &ExplainOptions,
) -> Vec<(usize, usize, usize, f64, f64, f64)> {
    let sc = scaled(sig, opts);
    let (j, b) = (&sc.j, &sc.b[..]);
    let (m1, m2) = (
        stats::chi2_isf(opts.alpha, 1.0),
        stats::chi2_isf(opts.alpha, 2.0),
    );
    let mut out = Vec::new();
    for (x, &a) in pairs_of.iter().enumerate() {
        for &c in &pairs_of[x + 1..] {
            let rest: Vec<usize> = named
                .iter()
                .copied()
                .filter(|&n| n != a && n != c)
                .collect();
            // each significant beside the other (both are findings here, not one and noise)
            let beside = |x: usize, extra: &[usize]| {
                let s: Vec<usize> = rest.iter().chain(extra).copied().collect();
                cond_llr(j, b, &s, x).map_or(0.0, |v| v.0)
            };
            if joint_llr(j, b, &rest, &[a, c]) < m2 || beside(a, &[c]) < m1 || beside(c, &[a]) < m1
            {
                continue;
            }
            for &w in others {
                let Some((_, iw, bw)) = cond_llr(j, b, &rest, w).filter(|x| x.0 >= m1) else {
                    continue;
                };
                let with_w: Vec<usize> = rest.iter().copied().chain([w]).collect();
                // beside it neither is significant, together or each beside the other
                if joint_llr(j, b, &with_w, &[a, c]) < m2
                    && beside(a, &[c, w]) < m1
                    && beside(c, &[a, w]) < m1
                {
                    let (est, sd, prior) = shown(&sc, &sig.cands, w, (iw, bw));
                    out.push((a, c, w, est, sd, prior));
                    break;
                }
            }
        }
    }
    out
}

/// A candidate that moves a named one's value: (candidate, the named one's estimate beside it
/// and its σ, the candidate's estimate and σ; display units).
pub(super) type MovedBy = (usize, [f64; 2], [f64; 2]);

/// For each of the candidates `named` (indices into `sig.cands`), given the rest of `named`:
/// the candidates among `others` that move its value, each as (candidate, the named one's
/// estimate beside it and its σ, the other's estimate and σ; display units). One moves it when
/// it is significant beside it (α-level χ²₁ quantile) and the named one's estimate beside it
/// differs from its estimate without it by more than 3 of its σ beside it: the named one's
/// value leans on that term's absence.
pub(super) fn moved_by(
    sig: &Signatures,
    named: &[usize],
    others: &[usize],
    opts: &ExplainOptions,
) -> Vec<Vec<MovedBy>> {
    let sc = scaled(sig, opts);
    let (j, b) = (&sc.j, &sc.b[..]);
    let margin = stats::chi2_isf(opts.alpha, 1.0);
    let display = |x: usize, info_score: (f64, f64)| {
        let (est, sd, _) = shown(&sc, &sig.cands, x, info_score);
        [est, sd]
    };
    named
        .iter()
        .map(|&c| {
            let rest: Vec<usize> = named.iter().copied().filter(|&x| x != c).collect();
            let Some((_, ic, bc)) = cond_llr(j, b, &rest, c) else {
                return Vec::new();
            };
            let alone = display(c, (ic, bc));
            let with_c: Vec<usize> = rest.iter().copied().chain([c]).collect();
            others
                .iter()
                .filter_map(|&w| {
                    cond_llr(j, b, &with_c, w).filter(|x| x.0 >= margin)?;
                    let with_w: Vec<usize> = rest.iter().copied().chain([w]).collect();
                    let (_, icw, bcw) = cond_llr(j, b, &with_w, c)?;
                    let beside = display(c, (icw, bcw));
                    let (_, iw, bw) = cond_llr(j, b, &with_c, w)?;
                    ((beside[0] - alone[0]).abs() > 3.0 * beside[1])
                        .then(|| (w, beside, display(w, (iw, bw))))
                })
                .collect()
        })
        .collect()
}

/// A candidate that takes a named one's place: (candidate index, GLR estimate, σ, display
/// unit; |estimate| in prior σ).
pub(super) type TakenBy = (usize, f64, f64, f64);

/// For each of the candidates `named` (indices into `sig.cands`), given the rest of `named`:
/// its own |GLR estimate| in prior σ (NaN when it is not significant here), and the candidates
/// among `others` that take its place: significant alone, and beside one of them it is no
/// longer significant at the α-level χ²₁ quantile (all it explains, that one explains too; a
/// term of the same signature, or a wider one that fits better), each
/// as (candidate index, GLR estimate, σ, display unit; |estimate| in prior σ), given the rest.
pub(super) fn taken_by(
    sig: &Signatures,
    named: &[usize],
    others: &[usize],
    opts: &ExplainOptions,
) -> Vec<(f64, Vec<TakenBy>)> {
    let sc = scaled(sig, opts);
    let (j, b) = (&sc.j, &sc.b[..]);
    let margin = stats::chi2_isf(opts.alpha, 1.0);
    named
        .iter()
        .map(|&c| {
            let rest: Vec<usize> = named.iter().copied().filter(|&x| x != c).collect();
            // (a finding not significant in this pass gives nothing to take)
            let Some((_, ic, bc)) = cond_llr(j, b, &rest, c).filter(|x| x.0 >= margin) else {
                return (f64::NAN, Vec::new());
            };
            let taken = others
                .iter()
                .filter_map(|&w| {
                    // (a term that explains nothing here takes nothing's place)
                    let (_, iw, bw) = cond_llr(j, b, &rest, w).filter(|x| x.0 >= margin)?;
                    let with_w: Vec<usize> = rest.iter().copied().chain([w]).collect();
                    let c_beside = cond_llr(j, b, &with_w, c).map_or(0.0, |x| x.0);
                    (c_beside < margin).then(|| {
                        let (est, sd, prior) = shown(&sc, &sig.cands, w, (iw, bw));
                        (w, est, sd, prior)
                    })
                })
                .collect();
            ((bc / ic).abs(), taken)
        })
        .collect()
}

/// Candidate `named`'s estimate and σ (display unit) from each group of each split of the
/// updates in `sc` alone, the candidates `others` free there too (indices into `cands`).
pub(super) fn split_estimates(
    sc: &Scaled,
    cands: &[usize],
    named: usize,
    others: &[usize],
) -> Vec<(Split, Vec<(f64, f64)>)> {
    let to_display = sc.sd[named] / common::TERMS[cands[named]].display_to_si;
    sc.splits
        .iter()
        .map(|(split, groups)| {
            let est = groups
                .iter()
                .map(|(jh, bh)| {
                    let (ih, bch) = conditional(jh, bh, others, named);
                    if ih > 1e-12 * jh[(named, named)].max(f64::MIN_POSITIVE) {
                        (bch / ih * to_display, to_display / ih.sqrt())
                    } else {
                        (f64::NAN, f64::INFINITY)
                    }
                })
                .collect();
            (*split, est)
        })
        .collect()
}

/// Every candidate's test alone in this pass, and which may be named: testable and not
/// proportional at the regressor level to a baseline term of the same sensor axis (that term's
/// state already absorbs it; what is left of its signature is the filter's transient).
pub(super) fn candidate_tests(
    sig: &Signatures,
    opts: &ExplainOptions,
) -> (Vec<CandidateTest>, Vec<bool>) {
    let Scaled { j, b, sd, .. } = scaled(sig, opts);
    let m = sig.cands.len();
    let nb = sig.base_terms.len();
    // testability is a property of the data's excitation, not of the dispersion; a regressor
    // of the body rate needs a rotation (without one its step means are the gyros' noise,
    // which the signatures would take for excitation)
    let phi = sig.dispersion.max(1.0);
    // (likewise a regressor of the specific force's rate of change needs a rotation or a
    // vibration: at rest its step means are the accelerometers' noise)
    let rotated = sig.last_axis > 0;
    let vibrated = sig.level.iter().any(|l| l.1 > MIN_VIBRATION);
    let testable: Vec<bool> = (0..m)
        .map(|c| {
            let reg = super::signatures::reg_id(sig.cands[c]);
            let excited = (rotated || !regressor_reads(reg, &["w", "dw"]))
                && (rotated || vibrated || !regressor_reads(reg, &["df"]));
            j[(c, c)] * phi > opts.min_information && excited
        })
        .collect();
    let p: Vec<f64> = (0..m)
        .map(|c| {
            if testable[c] {
                stats::chi2_sf(b[c] * b[c] / j[(c, c)], 1.0)
            } else {
                1.0
            }
        })
        .collect();
    let tp: Vec<f64> = (0..m).filter(|&c| testable[c]).map(|c| p[c]).collect();
    let adj = stats::holm(&tp);
    let mut k = 0;
    let mut tests = Vec::new();
    for c in 0..m {
        let term = &common::TERMS[sig.cands[c]];
        let to_display = 1.0 / term.display_to_si;
        let p_holm = if testable[c] {
            k += 1;
            adj[k - 1]
        } else {
            1.0
        };
        let confounded_with = (0..nb)
            .filter(|&q| sig.cross[c * nb + q] != 0.0)
            .map(|q| {
                let cos = sig.cross[c * nb + q] / (sig.cand_sq[c] * sig.base_sq[q]).sqrt();
                (q, cos)
            })
            .filter(|(_, cos)| cos.abs() > opts.confound_cos)
            .max_by(|x, y| x.1.abs().total_cmp(&y.1.abs()))
            .map(|(q, _)| common::TERMS[sig.base_terms[q].1].name.to_string());
        let jcc = j[(c, c)];
        tests.push(CandidateTest {
            term: term.name.to_string(),
            group: term.group.to_string(),
            information_prior_scaled: jcc,
            glr_estimate: if testable[c] {
                b[c] / jcc * sd[c] * to_display
            } else {
                0.0
            },
            glr_sigma: if testable[c] {
                sd[c] / jcc.sqrt() * to_display
            } else {
                f64::INFINITY
            },
            llr: if testable[c] { b[c] * b[c] / jcc } else { 0.0 },
            p_value: p[c],
            p_holm,
            testable: testable[c],
            confounded_with,
            unit: term.display.to_string(),
        });
    }
    let eligible = tests
        .iter()
        .map(|t| t.testable && t.confounded_with.is_none())
        .collect();
    (tests, eligible)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// llr of the joint fit over the set `s`: bᵀ J⁻¹ b restricted to `s`.
    fn joint_llr(j: &DMatrix<f64>, b: &[f64], s: &[usize]) -> f64 {
        if s.is_empty() {
            return 0.0;
        }
        let jss = DMatrix::from_fn(s.len(), s.len(), |x, y| j[(s[x], s[y])]);
        let bs = DMatrix::from_fn(s.len(), 1, |x, _| b[s[x]]);
        (bs.transpose() * jss.try_inverse().unwrap() * &bs)[(0, 0)]
    }

    fn spd(m: usize, seed: u64) -> DMatrix<f64> {
        let mut x = seed;
        let mut next = || {
            x = x
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((x >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        };
        let a = DMatrix::from_fn(m, m + 2, |_, _| next());
        &a * a.transpose() + DMatrix::identity(m, m) * 0.1
    }

    #[test]
    fn conditional_llr_is_the_joint_fits_increase() {
        let j = spd(5, 7);
        let b = [1.3, -0.4, 2.2, 0.7, -1.9];
        for (s, c) in [
            (vec![], 2),
            (vec![0], 2),
            (vec![1, 3], 4),
            (vec![0, 2, 4], 1),
        ] {
            let (ic, bc) = conditional(&j, &b, &s, c);
            let mut sc = s.clone();
            sc.push(c);
            let gain = joint_llr(&j, &b, &sc) - joint_llr(&j, &b, &s);
            assert!(
                (bc * bc / ic - gain).abs() < 1e-9 * gain.abs().max(1.0),
                "{s:?} {c}"
            );
        }
    }

    #[test]
    fn conditional_rho_of_a_candidate_with_itself_is_one() {
        let j = spd(4, 3);
        assert!((conditional_rho(&j, &[1], 2, 2) - 1.0).abs() < 1e-12);
        let r = conditional_rho(&j, &[0], 2, 3);
        assert!(r.abs() < 1.0);
    }

    fn opts() -> ExplainOptions {
        ExplainOptions::default()
    }

    /// The run's totals, each half holding half of them.
    fn sc(j: DMatrix<f64>, b: &[f64]) -> Scaled {
        let half = (&j * 0.5, b.iter().map(|x| 0.5 * x).collect::<Vec<f64>>());
        Scaled {
            sd: vec![1.0; b.len()],
            b: b.to_vec(),
            j,
            splits: vec![(Split::Time(0.0), vec![half.clone(), half])],
        }
    }

    #[test]
    fn a_strong_candidate_is_named_and_weak_independent_ones_are_not() {
        let j = DMatrix::identity(3, 3) * 100.0;
        // θ' = b/J: 0.5 prior σ (llr 25), 0.01 (llr 0.01), 0.02 (llr 0.04)
        let b = [50.0, 1.0, 2.0];
        let (sel, imp) = select(&sc(j.clone(), &b), &[0, 1, 2], &[true; 3], 1000, &opts());
        assert!(imp.is_empty());
        assert_eq!(sel.len(), 1);
        assert_eq!(sel[0].idx, 0);
        assert!((sel[0].llr - 25.0).abs() < 1e-9);
        assert!(sel[0].class.is_empty());
        // Holm: p × (candidates in the pool)
        assert!((sel[0].p - 3.0 * stats::chi2_sf(25.0, 1.0)).abs() < 1e-15);
    }

    #[test]
    fn holm_and_bic_stop_the_selection() {
        let j = DMatrix::identity(4, 4);
        // llr 9: p = 0.0027 < α = 0.01 alone, but × 4 candidates = 0.0108 > α
        let b = [3.0, 0.0, 0.0, 0.0];
        let (sel, _) = select(&sc(j.clone(), &b), &[0, 1, 2, 3], &[true; 4], 10, &opts());
        assert!(sel.is_empty());
        let (sel, _) = select(
            &sc(j.clone(), &b),
            &[0, 1, 2, 3],
            &[true, false, false, false],
            10,
            &opts(),
        );
        assert_eq!(sel.len(), 1, "alone it passes α");
        // with 10⁵ innovations the BIC asks llr > ln N = 11.5
        let (sel, _) = select(
            &sc(j.clone(), &b),
            &[0, 1, 2, 3],
            &[true, false, false, false],
            100_000,
            &opts(),
        );
        assert!(sel.is_empty());
    }

    #[test]
    fn equivalent_candidates_form_a_class_named_by_the_fewest_prior_sigmas() {
        // two signatures at ρ = 0.999; the second needs twice the prior σ of the first
        let rho: f64 = 0.999;
        let (i0, i1): (f64, f64) = (400.0, 100.0);
        let j = DMatrix::from_row_slice(
            2,
            2,
            &[i0, rho * (i0 * i1).sqrt(), rho * (i0 * i1).sqrt(), i1],
        );
        let theta0 = 0.5;
        let b = [i0 * theta0, rho * (i0 * i1).sqrt() * theta0];
        let (sel, _) = select(&sc(j.clone(), &b), &[0, 1], &[true; 2], 1000, &opts());
        assert_eq!(sel.len(), 1);
        assert_eq!(sel[0].idx, 0);
        assert_eq!(sel[0].class.len(), 1);
        assert_eq!(sel[0].class[0].0, 1);
        assert!(sel[0].class[0].1.abs() > sel[0].glr.abs());
        // the second needs 2ρ× the prior σ of the first: the data and the priors agree enough
        assert!(
            (sel[0].prior_ratio - 2.0 * rho).abs() < 1e-9,
            "{}",
            sel[0].prior_ratio
        );
        // the second's information 400× smaller: it would need 20× the prior σ, an order of
        // magnitude; the priors, not the data, choose
        let (i0, i1): (f64, f64) = (400.0, 1.0);
        let j = DMatrix::from_row_slice(
            2,
            2,
            &[i0, rho * (i0 * i1).sqrt(), rho * (i0 * i1).sqrt(), i1],
        );
        let b = [i0 * theta0, rho * (i0 * i1).sqrt() * theta0];
        let (sel, _) = select(&sc(j, &b), &[0, 1], &[true; 2], 1000, &opts());
        assert_eq!(sel[0].class.len(), 1);
        assert!(
            sel[0].prior_ratio >= UNATTRIBUTED_RATIO,
            "{}",
            sel[0].prior_ratio
        );
    }

    #[test]
    fn two_correlated_terms_both_present_are_not_one_class() {
        // signatures at ρ = 0.98 with much information (d and kas on one axis): the data hold
        // both (θ' = 0.5 and 0.4 prior σ), so each is significant beside the other
        let rho: f64 = 0.98;
        let (i0, i1): (f64, f64) = (4e4, 4e4);
        let c = rho * (i0 * i1).sqrt();
        let j = DMatrix::from_row_slice(2, 2, &[i0, c, c, i1]);
        let theta = [0.45, 0.45];
        let b = [i0 * theta[0] + c * theta[1], c * theta[0] + i1 * theta[1]];
        // what made them one class before: ρ above the bar and llrs within the α-quantile
        assert!(rho > opts().rho_equivalent && (b[0] * b[0] / i0 - b[1] * b[1] / i1).abs() < 6.6);
        let (sel, _) = select(&sc(j, &b), &[0, 1], &[true; 2], 1000, &opts());
        assert_eq!(sel.len(), 2, "both selected, not one class");
        assert!(sel.iter().all(|x| x.class.is_empty()));
    }

    #[test]
    fn a_value_beyond_the_plausible_prior_sigmas_is_not_named() {
        let j = DMatrix::identity(1, 1) * 1e-2;
        let b = [10.0]; // θ' = 1000 prior σ, llr 10⁴
        let (sel, imp) = select(&sc(j.clone(), &b), &[0], &[true], 1000, &opts());
        assert!(sel.is_empty());
        assert_eq!(imp.len(), 1);
        assert!((imp[0].prior_sigmas - 1000.0).abs() < 1e-9);
    }
}
