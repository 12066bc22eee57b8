//! What explain returns: candidate tests, findings, the gain, the whole explanation.

use super::diagnostics::PassStats;
use serde::Serialize;

/// One candidate's test in one pass.
#[derive(Debug, Clone, Serialize)]
pub struct CandidateTest {
    /// Term name.
    pub term: String,
    /// Group (spec).
    pub group: String,
    /// Information J·σ_prior² (the llr a 1-σ-prior effect would produce).
    pub information_prior_scaled: f64,
    /// GLR estimate θ̂ (display unit) and its σ, alone (not conditioned on other candidates).
    pub glr_estimate: f64,
    /// σ of the GLR estimate (display unit).
    pub glr_sigma: f64,
    /// Log-likelihood ratio b²/J, alone.
    pub llr: f64,
    /// χ²₁ p-value of the llr (uncorrected).
    pub p_value: f64,
    /// Holm-adjusted p-value over the testable candidates of this pass.
    pub p_holm: f64,
    /// False when the data carry no information on the term.
    pub testable: bool,
    /// Baseline term whose regressor sequence is proportional to this one's (|cos| > `confound_cos`).
    pub confounded_with: Option<String>,
    /// Display unit.
    pub unit: String,
}

/// A term explain adds to the model.
#[derive(Debug, Clone, Serialize)]
pub struct Finding {
    /// Canonical term name.
    pub term: String,
    /// What kind of cause: `sensor` (a term of the IMU's error model), `measurement` (a term
    /// of the aiding: time offset, lever arm) or `noise` (a white-noise or bias-instability
    /// level).
    pub kind: &'static str,
    /// Estimate from the extended filter (display unit).
    pub estimate: f64,
    /// Its 1-σ (display unit).
    pub sigma: f64,
    /// Display unit.
    pub unit: String,
    /// Conditional log-likelihood ratio when it was selected.
    pub llr: f64,
    /// Holm-corrected p-value when it was selected.
    pub p_value: f64,
    /// Candidates it cannot be told from on these data (its equivalence class, itself excluded).
    pub equivalent: Vec<String>,
    /// What each equivalent term would have to be to explain the same data.
    pub equivalent_estimates: Vec<EquivalentTerm>,
    /// Spec terms not among the candidates that explain all it explains (beside each it is no
    /// longer significant), with the value each would need (absent when none does, or every
    /// term was a candidate).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub withheld_alike: Vec<EquivalentTerm>,
    /// GLR estimate when selected (display unit).
    pub glr_estimate: f64,
    /// Its σ (display unit).
    pub glr_sigma: f64,
    /// Filter pass (1 = baseline) in which it was selected.
    pub round: usize,
    /// Baseline term it is not separable from at the regressor level, if any.
    pub confounded_with: Option<String>,
    /// Mean regressor over the run, in g- or deg/s-units (`regressor_unit`).
    pub regressor_mean: f64,
    /// Unit of `regressor_mean`, e.g. `g^2`.
    pub regressor_unit: String,
    /// Mean regressor over the samples where it is excited (|regressor| at least a tenth of its
    /// 99.9th percentile), in `regressor_unit`.
    pub regressor_excited_mean: f64,
    /// Fraction of the samples where the regressor is excited (0–1).
    pub excited_fraction: f64,
    /// What the term does where its regressor is excited: estimate × `regressor_excited_mean`,
    /// in `effect_unit`.
    pub effect_excited: f64,
    /// What the term does on these data: estimate × mean regressor, in `effect_unit`.
    pub effect: f64,
    /// `mg` (accelerometer) or `deg/h` (gyro).
    pub effect_unit: String,
    /// Which excitation would separate it from its equivalents.
    pub separate_by: Vec<String>,
    /// Prior σ the extended filter used (display unit): the spec's (or `--prior`), widened to
    /// 3 (|θ̂| + σ̂) when the GLR estimate θ̂ lies beyond 2 spec prior σ.
    pub prior_sigma: f64,
    /// True when the spec's prior σ was too small for what the data say.
    pub prior_widened: bool,
    /// The finding in words.
    pub words: String,
    /// Its first clause: what it is and its value (how `words` begins), for a one-line summary.
    pub headline: String,
    /// 2Δℓ the extended filter gained in the round that added it, its share when several
    /// terms were added in one round (weighted by their conditional llr).
    pub two_delta_loglik: f64,
    /// Fraction of the baseline's excess mean NIS (mean NIS − 1) its round removed (same
    /// weighting); absent when the baseline's mean NIS is within its 95 % band.
    pub misfit_share: Option<f64>,
    /// |estimate| in units of its prior σ (the spec's, or `--prior`), before any widening.
    pub prior_sigmas: f64,
    /// Why it probably stands in for an effect the candidates do not describe (it needs
    /// ≫ its prior, or it explains little of the misfit); absent for a finding read as a cause.
    pub stand_in: Option<String>,
    /// For a stand-in only because it needs more than `ExplainOptions::stand_in_prior_sigmas` (30) of its prior
    /// (every consistency split that was tested holds, at least one was, and it explains more
    /// than half of the baseline's excess misfit): a prior σ that holds it (display unit; 3×
    /// the estimate's magnitude rounded up to one significant digit, at most the term's
    /// `limit`), to give with `--prior` if the sensor can have such a value. Null otherwise.
    pub suggested_prior: Option<f64>,
    /// For a GNSS finding that probably stands in for an IMU–GNSS time offset (the offset,
    /// fitted to every order on the fixes re-stamped by it, fits the data as well in its
    /// place): that offset and its σ [ms]; absent otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub offset_in_place: Option<[f64; 2]>,
    /// Why no member of its equivalence class is named as the cause: the values they would need
    /// differ by 10× or more in prior σ and even the most plausible lies beyond 3 prior σ (the
    /// priors, which do not fit this sensor, would choose, not the data); the finding then
    /// stands for its class and is kept out of `extended.toml`.
    pub not_attributed: Option<String>,
    /// Which rules un-named it, in the order they did (empty for a cause; a stand-in may carry
    /// some too); `not_attributed` gives each one's words.
    pub not_attributed_because: Vec<Unnamed>,
    /// A noise finding's maximum-likelihood scale of the stated value (white noise density, or
    /// the aiding's stated 1-σ).
    pub scale: Option<f64>,
    /// Its approximate 95 % interval; null when the scale is at the search bound.
    pub scale_interval: Option<[f64; 2]>,
    /// `at most` when the search for the scale stopped at its lower bound with the likelihood
    /// still rising towards smaller values (`scale` is then a bound, not an estimate, and
    /// `sigma` and `scale_interval` are null), `at least` at its upper bound; absent otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub scale_bound: Option<&'static str>,
    /// A term finding's GLR estimate and σ (display unit) from the first and from the second
    /// half of the aiding epochs alone: `[[estimate, σ], [estimate, σ]]` (null without
    /// information in a half). A constant of the sensor or the aiding holds across both.
    pub halves: Option<[[f64; 2]; 2]>,
    /// The same from the updates below and at or above the median aided speed (a constant
    /// holds at any speed; a term standing in for an effect that grows with speed does not);
    /// null when the run is not split by speed (a median aided speed below 0.5 m/s).
    pub speed_halves: Option<[[f64; 2]; 2]>,
    /// A term finding's tests that it holds across the data: per split of the updates (time,
    /// speed, motion), its estimate from each group alone and whether they agree.
    pub consistency: Vec<Consistency>,
}

impl Finding {
    /// True when the finding is read as a cause: neither a stand-in nor an unattributed class.
    pub fn is_cause(&self) -> bool {
        self.stand_in.is_none() && self.not_attributed.is_none()
    }

    /// True when rule `why` is among those that un-named it.
    pub fn unnamed_because(&self, why: Unnamed) -> bool {
        self.not_attributed_because.contains(&why)
    }

    /// Puts `eq` in the finding's class, unless it is there already.
    pub(super) fn add_equivalent(&mut self, eq: EquivalentTerm) {
        if !self.equivalent.contains(&eq.term) {
            self.equivalent.push(eq.term.clone());
            self.equivalent_estimates.push(eq);
        }
    }
}

/// Why a fitted finding is not named as a cause: the rule that un-named it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Unnamed {
    /// The data cannot tell its equivalence class apart, and only priors that do not fit this
    /// sensor (≥ 10× apart, the most plausible beyond 3 prior σ) would choose.
    ClassNotSeparable,
    /// A spec term kept out of the candidates explains what it explains (alone, or for it and
    /// another finding together), and the priors do not prefer the finding.
    WithheldTermFits,
    /// Its value leans on a spec term kept out of the candidates (it moves > 3σ beside it).
    LeansOnWithheldTerm,
    /// The candidates it takes up, fitted beside it, move its value by more than 3σ.
    ValueMoves,
    /// Its value in the extended filter is within 2σ of zero.
    ValueNearZero,
    /// Its value was fitted beside a stand-in and changes once the stand-in is dropped or a
    /// rival takes its place.
    LeansOnStandIn,
    /// An aiding term and a sensor term whose estimates correlate beyond ±0.9.
    AidingSensorConfound,
    /// Fitted beside an IMU–GNSS time offset the re-stamped runs did not settle.
    OffsetUnsettled,
    /// An IMU–GNSS time offset the re-stamped fixes do not bear out.
    OffsetNotBorneOut,
    /// A noise level fitted beside a time offset the model does not hold.
    NoiseBesideOffset,
    /// An IMU–GNSS time offset an antenna lever arm fits as well on the fixes as stamped, or a
    /// GNSS term whose value moves with that offset.
    OffsetOrLeverArm,
}

impl Unnamed {
    /// The reason in a few words (the report's verdict column) and as a clause (its summary).
    pub fn words(self) -> (&'static str, &'static str) {
        match self {
            Self::ClassNotSeparable => (
                "class not separable",
                "its class cannot be told apart on these data",
            ),
            Self::WithheldTermFits => (
                "a withheld term fits as well",
                "a term the candidates keep out explains it as well",
            ),
            Self::LeansOnWithheldTerm => (
                "leans on a withheld term",
                "its value moves beside a term the candidates keep out",
            ),
            Self::ValueMoves => (
                "value moves beside other terms",
                "its value moves beside the candidates it takes up",
            ),
            Self::ValueNearZero => (
                "value within 2σ of zero",
                "the extended filter leaves its value within 2σ of zero",
            ),
            Self::LeansOnStandIn => (
                "leans on a stand-in",
                "its value was fitted beside a stand-in and changes without it",
            ),
            Self::AidingSensorConfound => (
                "confounded with an aiding term",
                "the data cannot separate an aiding term from a sensor term here",
            ),
            Self::OffsetUnsettled => (
                "time offset unsettled",
                "it was fitted beside a time offset the re-stamped runs did not settle",
            ),
            Self::OffsetNotBorneOut => (
                "offset not borne out",
                "the re-stamped fixes want no offset",
            ),
            Self::NoiseBesideOffset => (
                "fitted beside a missing offset",
                "it was fitted while a stand-in took the place of a time offset",
            ),
            Self::OffsetOrLeverArm => (
                "offset or lever arm, not told apart",
                "the data cannot tell an IMU–GNSS time offset from an antenna lever arm here",
            ),
        }
    }
}

/// A finding's test that it holds across the data: its estimate from each group of one split
/// of the updates alone, and whether they describe one constant.
#[derive(Debug, Clone, Serialize)]
pub struct Consistency {
    /// The split: `time` (halves of the aiding epochs), `speed` (below and from the median
    /// aided speed), `motion` (by the body axis of the most recent rotation), `manoeuvre`,
    /// `measurement` (by the kind of fix, for the aiding's own terms); for noise levels
    /// `rotation` (rotating or turning, or not), `time` and `vibration` (vibrating or quiet).
    pub split: String,
    /// The groups with information, each with its estimate and σ (display unit); a group
    /// whose σ is infinite, NaN or more than 100× the best group's carries none and is left out.
    pub groups: Vec<GroupEstimate>,
    /// Groups with a finite σ more than 100× the best group's: left out of `groups`, but in
    /// χ² and its degrees of freedom (where they add nothing but a degree of freedom each).
    pub uninformative_groups: usize,
    /// χ² of the group estimates (those in `groups` and the uninformative ones) about their
    /// information-weighted mean.
    pub chi2: f64,
    /// Its degrees of freedom (groups with a finite σ − 1).
    pub dof: usize,
    /// Its p-value; null when the split is not tested.
    pub p_value: f64,
    /// False when the groups disagree: χ² p < 0.0027 (3σ) and two groups more than 3σ and
    /// more than a quarter of the larger apart. True also when the split is not tested (see
    /// `tested`): nothing speaks against the term there, but nothing for it either.
    pub holds: bool,
    /// False when fewer than two groups carry information: no test was made.
    pub tested: bool,
    /// Why the split holds, fails or was not tested, in words.
    pub why: String,
}

/// A finding's estimate from one group of the updates alone.
#[derive(Debug, Clone, Serialize)]
pub struct GroupEstimate {
    /// The group, in words (e.g. `after rotating about z`).
    pub group: String,
    /// Estimate (display unit).
    pub estimate: f64,
    /// Its σ (display unit).
    pub sigma: f64,
}

/// A baseline term whose prior σ the data show to be too tight for this sensor.
#[derive(Debug, Clone, Serialize)]
pub struct TightPrior {
    /// Term name.
    pub term: String,
    /// Term index in the spec.
    #[serde(skip)]
    pub index: usize,
    /// Its estimate at the end of the first run's extended pass (display unit).
    pub estimate: f64,
    /// Its σ there (display unit).
    pub sigma: f64,
    /// The prior σ it had (display unit).
    pub prior: f64,
    /// |estimate| in units of that prior σ.
    pub prior_sigmas: f64,
    /// A prior σ that holds the data's value (display unit): 3 |estimate|, rounded up to one
    /// significant digit (3 × 408 µg = 1224 µg → 2000 µg).
    pub suggested: f64,
    /// Display unit.
    pub unit: String,
}

/// A term the data cannot tell from a finding, and the value it would need.
#[derive(Debug, Clone, Serialize)]
pub struct EquivalentTerm {
    /// Term name.
    pub term: String,
    /// GLR estimate in the finding's pass (display unit).
    pub estimate: f64,
    /// Its σ (display unit).
    pub sigma: f64,
    /// Display unit.
    pub unit: String,
    /// The estimate in units of the spec's prior σ (how plausible it is a priori).
    pub prior_sigmas: f64,
}

impl EquivalentTerm {
    /// Spec term `t` with the value it would need and its σ (display unit) and its prior-σ
    /// count.
    pub(super) fn of(t: usize, (estimate, sigma, prior_sigmas): (f64, f64, f64)) -> EquivalentTerm {
        let info = &crate::model::generated::common::TERMS[t];
        EquivalentTerm {
            term: info.name.to_string(),
            estimate,
            sigma,
            unit: info.display.to_string(),
            prior_sigmas,
        }
    }
}

/// Before/after gain of the extended model.
#[derive(Debug, Clone, Serialize)]
pub struct Gain {
    /// Log-likelihood after − before.
    pub loglik: f64,
    /// Mean NIS before and after.
    pub nis_mean_before: f64,
    /// Mean NIS after.
    pub nis_mean_after: f64,
    /// Model error RMS (north, east combined as √(n²+e²)) before [arcsec] (with truth).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub model_error_rms_before: Option<f64>,
    /// Same, after.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub model_error_rms_after: Option<f64>,
}

/// Everything explain found.
#[derive(Debug, Clone, Serialize)]
pub struct Explanation {
    /// Baseline model states.
    pub model: Vec<String>,
    /// Baseline model string.
    pub baseline_model: String,
    /// Baseline pass.
    pub baseline: PassStats,
    /// Candidate tests of the baseline pass, best first.
    pub candidates: Vec<CandidateTest>,
    /// Terms added, in order.
    pub findings: Vec<Finding>,
    /// Candidates not testable on these data.
    pub not_testable: Vec<String>,
    /// Significant candidates not named because their value would be implausible.
    pub implausible: Vec<Implausible>,
    /// Terms the signatures selected but the extended filter did not confirm: (term, 2Δℓ of
    /// the round plus the prior's Occam term ln det(I + SJS), S the prior σ, the χ²_k quantile 1 − α it had to
    /// pass, times the dispersion φ when above 1).
    pub unconfirmed: Vec<(String, f64, f64)>,
    /// Candidates whose regressor is proportional on these data to a baseline term's on the
    /// same sensor axis: (candidate, baseline term). Never named; the baseline term takes it up.
    pub not_separable: Vec<(String, String)>,
    /// Extended model string (baseline when nothing was found).
    pub extended_model: String,
    /// Extended model pass.
    pub extended: PassStats,
    /// Gain.
    pub gain: Gain,
    /// Filter passes made.
    pub rounds: usize,
    /// Options used.
    pub alpha: f64,
    /// Sentences for the terminal and the report.
    pub summary: Vec<String>,
    /// Fraction of the baseline's excess mean NIS the extended model leaves; absent when the
    /// baseline's mean NIS is within its 95 % band.
    pub misfit_unexplained: Option<f64>,
    /// The extended model holds only the causes: the stand-ins found last (a small share beside
    /// a misfit the causes leave) were taken out of it and its pass run again.
    pub stand_ins_left_out: bool,
    /// Baseline terms whose prior looks too tight for these data: in the extended model (the
    /// findings added) their estimate still lies beyond 3 prior σ and 3 own σ. Explain then
    /// ran again from the baseline with each prior widened to `suggested`.
    pub baseline_priors_tight: Vec<TightPrior>,
    /// True when this explanation is that second run: the widened priors raised the
    /// baseline's innovation log-likelihood (the data's evidence for them) by more than their
    /// BIC penalty.
    pub baseline_priors_widened: bool,
    /// 2Δ log-likelihood of the baseline with the widened priors over the priors as given.
    pub baseline_priors_gain: Option<f64>,
    /// Open loop about a navigation whose attitude error estimate passed
    /// [`super::MAX_OPEN_LOOP_TILT`]: why the linear error model may not hold, in words (None
    /// in closed loop or within small angles).
    pub linearisation: Option<String>,
    /// True when explain ran closed loop because the open-loop baseline pass drifted beyond
    /// small angles (`linearisation` says how far).
    pub closed_loop_instead: bool,
    /// The time offset fitted to every order by re-stamping the fixes (explain run again on
    /// them); None when no offset was found or it was too small to refit.
    pub restamp: Option<super::restamp::Restamp>,
    /// Normalised innovations of the baseline and extended passes, for plots.
    #[serde(skip)]
    pub innovations_before: Vec<Normalised>,
    /// Same for the extended pass.
    #[serde(skip)]
    pub innovations_after: Vec<Normalised>,
    /// Model error series (t [s], e_n, e_e [arcsec]) before and after (with truth).
    #[serde(skip)]
    pub model_error_before: Vec<(f64, f64, f64)>,
    /// Same, after.
    #[serde(skip)]
    pub model_error_after: Vec<(f64, f64, f64)>,
}

impl Explanation {
    /// Fraction of the baseline's excess misfit taken up only by fits that are not causes
    /// (stand-ins): the sum of their shares, 0 without any.
    pub fn misfit_taken_by_stand_ins(&self) -> f64 {
        self.findings
            .iter()
            .filter(|f| f.stand_in.is_some())
            .filter_map(|f| f.misfit_share)
            .map(|x| x.max(0.0))
            .sum()
    }

    /// Fraction of the baseline's excess misfit the causes found leave: what the extended model
    /// leaves plus what only stand-ins take up (at most 1); absent like `misfit_unexplained`.
    pub fn misfit_unexplained_by_causes(&self) -> Option<f64> {
        self.misfit_unexplained
            .map(|u| (u.max(0.0) + self.misfit_taken_by_stand_ins()).min(1.0))
    }
}

/// A significant candidate explain does not name: its value would be implausibly large.
#[derive(Debug, Clone, Serialize)]
pub struct Implausible {
    /// Term name.
    pub term: String,
    /// The value it would need (display unit).
    pub estimate: f64,
    /// σ of that value (display unit).
    pub sigma: f64,
    /// Display unit.
    pub unit: String,
    /// |estimate| in prior σ.
    pub prior_sigmas: f64,
    /// Conditional log-likelihood ratio.
    pub llr: f64,
}

/// χ² p-value below which a split's groups disagree (the two-sided 3σ level).
pub(super) const SPLIT_P: f64 = 0.0027;

/// A group carries information when its σ is within this many times the best group's (1 % of
/// its information). A group with less cannot contradict the best: its estimate is dominated by
/// what the linearised signatures leave out (measured: a velocity reference 0.2 s late, the
/// extended filter holding -198 ± 4 ms, has groups at 0.2 % and 0.05 % of the best's
/// information giving +236 ± 122 and +369 ± 148 ms; at 0.1 s late they give +109 and +275).
const INFORMATIVE: f64 = 10.0;

impl Consistency {
    /// The test over `split`'s groups (group k named `label(k)`), given each group's estimate
    /// and σ in the finding's display unit (groups without information, σ = ∞ or NaN, are left
    /// out).
    pub(super) fn test(
        split: &str,
        label: &dyn Fn(usize) -> String,
        est: &[(f64, f64)],
    ) -> Consistency {
        Self::test_within(split, label, est, INFORMATIVE)
    }

    /// [`Consistency::test`] with groups whose σ is more than `informative` × the best group's
    /// counted as carrying no information (∞: every group with a finite σ carries some).
    pub(super) fn test_within(
        split: &str,
        label: &dyn Fn(usize) -> String,
        est: &[(f64, f64)],
        informative: f64,
    ) -> Consistency {
        let finite = |e: f64, s: f64| e.is_finite() && s.is_finite() && s > 0.0;
        // every group with a finite σ enters χ² (where one far less informed than the best adds
        // nothing but a degree of freedom); such a group (e.g. −4.2e12 ± 4.2e14 beside ± 0.02)
        // is left out of `groups`: its estimate is whatever the numerics give
        let groups: Vec<GroupEstimate> = est
            .iter()
            .enumerate()
            .filter(|(_, (e, s))| finite(*e, *s))
            .map(|(k, &(estimate, sigma))| GroupEstimate {
                group: label(k),
                estimate,
                sigma,
            })
            .collect();
        let w: f64 = groups.iter().map(|g| g.sigma.powi(-2)).sum();
        let mean = groups
            .iter()
            .map(|g| g.estimate * g.sigma.powi(-2))
            .sum::<f64>()
            / w;
        let chi2: f64 = groups
            .iter()
            .map(|g| ((g.estimate - mean) / g.sigma).powi(2))
            .sum();
        let best = groups.iter().map(|g| g.sigma).fold(f64::INFINITY, f64::min);
        let is_informative = |g: &GroupEstimate| g.sigma <= informative * best;
        let n_informative = groups.iter().filter(|g| is_informative(g)).count();
        let dof = groups.len().saturating_sub(1);
        let tested = n_informative >= 2;
        let p_value = if tested {
            crate::estimate::stats::chi2_sf(chi2, dof as f64)
        } else {
            f64::NAN
        };
        // two groups far apart on both counts: beyond their noise, and by more than a quarter
        let pairs = || {
            groups.iter().enumerate().flat_map(|(i, a)| {
                groups[i + 1..].iter().map(move |b| {
                    let d = (a.estimate - b.estimate).abs();
                    (
                        a,
                        b,
                        d > 3.0 * a.sigma.hypot(b.sigma),
                        d > 0.25 * a.estimate.abs().max(b.estimate.abs()),
                    )
                })
            })
        };
        let apart = pairs().find(|p| p.2 && p.3);
        let holds = !(p_value < SPLIT_P && apart.is_some());
        let p = super::words::sig3(p_value);
        let why = if !tested {
            format!(
                "not tested: {} of the {} groups carries information, two are needed",
                n_informative,
                est.len()
            )
        } else if p_value >= SPLIT_P {
            format!("holds: the groups agree within their σ (χ² p {p}, not below {SPLIT_P})")
        } else if let (false, Some((a, b, _, _))) = (holds, apart) {
            format!(
                "fails: χ² p {p}, and {} ({}) and {} ({}) differ by more than 3 σ and more than a quarter",
                a.group,
                super::words::sig3(a.estimate),
                b.group,
                super::words::sig3(b.estimate)
            )
        } else if pairs().any(|p| p.2) {
            format!("holds: χ² p {p}, but no two groups that differ by more than 3 σ differ by more than a quarter")
        } else {
            format!("holds: χ² p {p}, but no two groups differ by more than 3 σ")
        };
        let uninformative_groups = groups.len() - n_informative;
        let groups = groups
            .iter()
            .filter(|g| is_informative(g))
            .cloned()
            .collect();
        Consistency {
            split: split.to_string(),
            groups,
            uninformative_groups,
            chi2: if dof > 0 { chi2 } else { 0.0 },
            dof,
            p_value,
            holds,
            tested,
            why,
        }
    }

    /// Why the groups show the term is not one constant, in words, when they do (`unit`: the
    /// finding's display unit).
    pub(super) fn disagreement(&self, unit: &str) -> Option<String> {
        use super::words::sig3;
        if self.holds {
            return None;
        }
        let g = &self.groups;
        let pair = |which: &str| {
            format!(
                "{which} give {} ± {} and {} ± {} {unit}: it does not hold across the data",
                sig3(g[0].estimate),
                sig3(g[0].sigma),
                sig3(g[1].estimate),
                sig3(g[1].sigma)
            )
        };
        Some(match self.split.as_str() {
            "time" if g.len() == 2 => pair("the first and the second half of the data"),
            "speed" if g.len() == 2 => pair("the slower and the faster half of the updates"),
            _ => {
                // the words name the groups that carry information (σ within 100× the best
                // group's) and, of many, the four farthest from the weighted mean; the JSON
                // keeps every group
                let best = g.iter().map(|x| x.sigma).fold(f64::INFINITY, f64::min);
                let informative: Vec<&GroupEstimate> =
                    g.iter().filter(|x| x.sigma <= 100.0 * best).collect();
                let (sw, swe) = informative.iter().fold((0.0, 0.0), |(a, b), x| {
                    let w = 1.0 / (x.sigma * x.sigma);
                    (a + w, b + w * x.estimate)
                });
                let mean = swe / sw;
                let mut shown: Vec<usize> = (0..informative.len()).collect();
                if shown.len() > 5 {
                    let off = |k: usize| {
                        let x = informative[k];
                        (x.estimate - mean).abs() / x.sigma
                    };
                    shown.sort_by(|&a, &b| off(b).total_cmp(&off(a)));
                    shown.truncate(4);
                    shown.sort_unstable();
                }
                let mut list = shown
                    .iter()
                    .map(|&k| {
                        let x = informative[k];
                        format!("{} ± {} {}", sig3(x.estimate), sig3(x.sigma), x.group)
                    })
                    .collect::<Vec<_>>()
                    .join(", ");
                list.push_str(&format!(" {unit}"));
                if shown.len() < informative.len() {
                    list.push_str(&format!(
                        " (the {} farthest from their weighted mean {} of {} groups)",
                        shown.len(),
                        sig3(mean),
                        informative.len()
                    ));
                }
                let left_out = g.len() - informative.len() + self.uninformative_groups;
                if left_out > 0 {
                    list.push_str(&format!(
                        "; {} group{} without information left out",
                        left_out,
                        if left_out == 1 { "" } else { "s" }
                    ));
                }
                format!(
                    "grouped by {}, the updates give {list} (χ² {} on {} degrees of freedom): it does not hold across the data",
                    match self.split.as_str() {
                        "motion" => "the last rotation's axis",
                        "measurement" => "the kind of fix",
                        other => other,
                    },
                    sig3(self.chi2),
                    self.dof
                )
            }
        })
    }
}

/// One normalised innovation kept for a plot: time, ν/√S and its channel (an index, not a
/// name: a run keeps one per scalar update).
#[derive(Debug, Clone, Copy)]
pub struct Normalised {
    /// Time [s].
    pub t: f64,
    /// ν/√S (1 = as predicted).
    pub nu: f64,
    /// Index into [`crate::estimate::filter::channels`].
    channel: u16,
}

impl Normalised {
    /// The normalised innovation of measurement `meas`'s `component` at `t` [s].
    pub fn new(t: f64, meas: &'static str, component: usize, nu: f64) -> Normalised {
        Normalised {
            t,
            nu,
            channel: crate::estimate::filter::channel_id(meas, component),
        }
    }

    /// Its channel: `vel_n`, `pos_e`, `vel_bx`, ….
    pub fn channel(&self) -> &'static str {
        crate::estimate::filter::channels()[self.channel as usize]
    }
}
