//! Hidden-effect tests of `explain`: a seeded generator hides a library term in simulated data
//! (a scenario that excites it, a baseline model that lacks it); explain must name it (or a
//! class containing it), estimate it within 10 % and recover ≥ 80 % of the gain of a filter
//! that knows the true model. Null cases must name nothing. The fast set: every library group
//! once, two null cases, one case that needs two terms.

use sinsmodel::experiment::hidden::{run_hidden_case, HiddenOutcome};
use sinsmodel::explain::ExplainOptions;
use sinsmodel::model::generated::common;
use sinsmodel::sim::hidden::{clear_effect, generate, CaseKind, HiddenCase};

/// Case length [s].
const SECONDS: f64 = 600.0;

fn run(kind: CaseKind, seed: u64) -> (HiddenCase, HiddenOutcome) {
    let case = generate(seed, kind, SECONDS, clear_effect(kind));
    let out = run_hidden_case(&case, &ExplainOptions::default()).expect("explain runs");
    (case, out)
}

/// The estimate explain gives for `name` (display unit): its finding's, or the value it would
/// need as a member of a finding's equivalence class.
fn estimate_of(out: &HiddenOutcome, name: &str) -> Option<f64> {
    for f in &out.explanation.findings {
        if f.term == name {
            return Some(f.estimate);
        }
        if let Some(e) = f.equivalent_estimates.iter().find(|e| e.term == name) {
            return Some(e.estimate);
        }
    }
    None
}

fn check_found(kind: CaseKind, seed: u64) {
    let (case, out) = run(kind, seed);
    let e = &out.explanation;
    let named: Vec<&str> = e.findings.iter().map(|f| f.term.as_str()).collect();
    for (name, truth_si) in &case.hidden {
        assert!(
            out.found(name),
            "{}: {name} not named (named {named:?}); summary: {:#?}",
            case.description,
            e.summary
        );
        let info = common::TERMS.iter().find(|t| t.name == name).unwrap();
        let truth = truth_si / info.display_to_si;
        let est = estimate_of(&out, name).unwrap();
        let rel = (est - truth).abs() / truth.abs();
        // a time offset within 10 % or 5 ms
        let close = rel < 0.10 || (name.starts_with("dt_") && (est - truth).abs() < 5.0);
        assert!(
            close,
            "{}: {name} estimated {est} {}, true {truth} ({:.1} % off)",
            case.description,
            info.display,
            rel * 100.0
        );
    }
    // nothing named that is neither hidden nor in a class with a hidden term, and no noise level
    // (every level is stated as simulated; until 2026-12-07 the simulated heights were
    // noise-free under a stated σ, and the height σ was named as stated too large)
    for f in e.findings.iter().filter(|f| f.kind == "noise") {
        assert!(
            f.stand_in.is_some(),
            "{}: noise finding {}: {}",
            case.description,
            f.term,
            f.words
        );
    }
    for f in e.findings.iter().filter(|f| f.kind != "noise") {
        let related = case
            .hidden
            .iter()
            .any(|(h, _)| &f.term == h || f.equivalent.iter().any(|x| x == h));
        // a fit the words do not attribute ("Fitted, not attributed": its value is not fixed
        // by the data) is no claim; anything else unrelated is a wrong name
        let unattributed = f.not_attributed.is_some() && f.stand_in.is_none();
        assert!(
            related || unattributed,
            "{}: named {} too",
            case.description,
            f.term
        );
        // a hidden library term is a cause, never reported as a stand-in for something else
        assert!(
            f.stand_in.is_none(),
            "{}: {} called a stand-in: {:?}",
            case.description,
            f.term,
            f.stand_in
        );
    }
    let (recovery, what) = out
        .gain_recovery()
        .unwrap_or_else(|| panic!("{}: the true model gains nothing", case.description));
    assert!(
        recovery >= 0.8,
        "{}: the extended model recovers {:.0} % of the true model's {what} gain",
        case.description,
        recovery * 100.0
    );
}

/// A noise case: the misstated white noise is named as a noise finding whose scale (the data's
/// level over the stated one) is within 10 % of the simulated ratio, with the true ratio inside
/// its 95 % interval; a term hidden beside it is found within 10 %; the other sensor's noise and
/// any other term are not named.
fn check_noise(group: &'static str, seed: u64) {
    let (case, out) = run(CaseKind::One(group), seed);
    let e = &out.explanation;
    let (level, ratio) = &case.noise_ratio[0];
    let shown: Vec<String> = e
        .findings
        .iter()
        .map(|f| format!("{} {:?}: {}", f.term, f.scale, f.words))
        .collect();
    let f = e
        .findings
        .iter()
        .find(|f| f.kind == "noise" && &f.term == level)
        .unwrap_or_else(|| panic!("{}: {level} not named; named {shown:#?}", case.description));
    let scale = f.scale.expect("a noise finding carries its scale");
    assert!(
        (scale / ratio - 1.0).abs() < 0.10,
        "{}: {level} scale {scale:.3}, simulated {ratio:.3}",
        case.description
    );
    let [lo, hi] = f
        .scale_interval
        .expect("a noise finding carries its interval");
    assert!(
        lo <= *ratio && *ratio <= hi,
        "{}: {level} simulated {ratio:.3} outside the 95 % interval {lo:.3}–{hi:.3}",
        case.description
    );
    assert!(
        false_causes(&case, &out).is_empty(),
        "{}: named {:?} as causes too",
        case.description,
        false_causes(&case, &out)
    );
    for (name, truth_si) in &case.hidden {
        assert!(
            out.found(name),
            "{}: {name} not named; {shown:#?}",
            case.description
        );
        let info = common::TERMS.iter().find(|t| t.name == name).unwrap();
        let truth = truth_si / info.display_to_si;
        let est = estimate_of(&out, name).unwrap();
        assert!(
            ((est - truth) / truth).abs() < 0.10,
            "{}: {name} estimated {est}, true {truth}",
            case.description
        );
    }
}

/// Findings presented as causes that are neither hidden (nor in a hidden term's class) nor the
/// misstated noise level; a finding marked as a stand-in ("fitted, but not a cause") is not a
/// cause.
fn false_causes(case: &HiddenCase, out: &HiddenOutcome) -> Vec<String> {
    out.explanation
        .findings
        .iter()
        .filter(|f| f.stand_in.is_none())
        .filter(|f| {
            if f.kind == "noise" {
                !case.noise_ratio.iter().any(|(l, _)| l == &f.term)
            } else {
                !case
                    .hidden
                    .iter()
                    .any(|(h, _)| &f.term == h || f.equivalent.iter().any(|x| x == h))
            }
        })
        .map(|f| format!("{} {:?}", f.term, f.scale))
        .collect()
}

/// Seeds 1–5 of each noise group (a case takes about a second): how often the misstated level
/// is named, with its scale within 10 % of the simulated ratio and the ratio inside its 95 %
/// interval, and how often anything else is named as a cause. A white noise stated too small
/// (2–10×) is named in at least 4 of 5 (measured 2026-11-24: gyro 5/5, accelerometer 4/5, the
/// fifth fitted but called a stand-in); an accelerometer noise stated too large is invisible
/// behind 0.01 m/s velocity fixes (the innovations stay consistent) and nothing may be named.
#[test]
fn noise_levels_across_seeds() {
    use sinsmodel::sim::hidden::NOISE_GROUPS;
    let mut table = String::new();
    for group in NOISE_GROUPS {
        let (mut named, mut close, mut covered, mut wrong) = (0, 0, 0, Vec::new());
        for seed in 1..=5 {
            let (case, out) = run(CaseKind::One(group), seed);
            let (level, ratio) = &case.noise_ratio[0];
            let f = out
                .explanation
                .findings
                .iter()
                .find(|f| f.kind == "noise" && &f.term == level && f.stand_in.is_none());
            if let Some(f) = f {
                named += 1;
                let scale = f.scale.unwrap();
                assert_eq!(
                    scale > 1.0,
                    *ratio > 1.0,
                    "{}: scale {scale}",
                    case.description
                );
                close += usize::from((scale / ratio - 1.0).abs() < 0.10);
                let [lo, hi] = f.scale_interval.unwrap();
                covered += usize::from(lo <= *ratio && *ratio <= hi);
            }
            let w = false_causes(&case, &out);
            if !w.is_empty() {
                wrong.push(format!("seed {seed}: {w:?}"));
            }
        }
        table.push_str(&format!(
            "{group}: named {named}/5, within 10 % {close}/5, ratio in the 95 % interval {covered}/5, false causes {wrong:?}\n"
        ));
        match group {
            "noise_gyro" | "noise_accel" | "noise_accel_kgf" => {
                assert!(named >= 4 && close >= 3 && covered >= 3, "{table}");
                assert!(wrong.len() <= 1, "{table}");
            }
            "noise_gyro_large" => assert!(named >= 3 && wrong.is_empty(), "{table}"),
            "noise_gyro_bias" | "noise_accel_bias" => assert!(named >= 3, "{table}"),
            _ => assert!(wrong.is_empty(), "{table}"),
        }
    }
    eprint!("{table}");
}

/// Seeds 1–5 of each velocity-reference group (about 8 s a case; run with `--ignored`): how
/// often every hidden term is named as a cause within 10 % (a time offset: or 5 ms), and what
/// else is named as a cause.
#[test]
#[ignore]
fn reference_groups_across_seeds() {
    use sinsmodel::sim::hidden::REFERENCE_GROUPS;
    let mut table = String::new();
    for group in REFERENCE_GROUPS {
        let (mut all_close, mut wrong, mut unattributed) = (0, Vec::new(), Vec::new());
        for seed in 1..=5 {
            let (case, out) = run(CaseKind::One(group), seed);
            let close = case.hidden.iter().all(|(name, truth_si)| {
                let info = common::TERMS.iter().find(|t| t.name == name).unwrap();
                let truth = truth_si / info.display_to_si;
                out.found(name)
                    && estimate_of(&out, name).is_some_and(|est| {
                        (est - truth).abs() < 0.1 * truth.abs()
                            || (name.starts_with("dt_") && (est - truth).abs() < 5.0)
                    })
            });
            all_close += usize::from(close);
            // unrelated fits: named as causes (wrong), or fitted and not attributed (no claim)
            let unrelated: Vec<&sinsmodel::explain::Finding> = out
                .explanation
                .findings
                .iter()
                .filter(|f| f.stand_in.is_none() && f.kind != "noise")
                .filter(|f| !case.hidden.iter().any(|(h, _)| &f.term == h))
                .collect();
            for f in unrelated {
                let what = format!("seed {seed}: {}", f.term);
                if f.not_attributed.is_none() {
                    wrong.push(what);
                } else {
                    unattributed.push(what);
                }
            }
            let w = false_causes(&case, &out)
                .into_iter()
                .filter(|w| {
                    w.starts_with("sigma_") || w.starts_with("gyro_") || w.starts_with("accel_")
                })
                .collect::<Vec<_>>();
            if !w.is_empty() {
                wrong.push(format!("seed {seed}: noise {w:?}"));
            }
        }
        table.push_str(&format!(
            "{group}: every hidden term named within 10 % in {all_close}/5, other causes named {wrong:?}, fits not attributed {unattributed:?}\n"
        ));
    }
    eprint!("{table}");
}

#[test]
fn finds_gyro_noise_stated_too_small() {
    check_noise("noise_gyro", 1);
}

#[test]
fn finds_accelerometer_noise_stated_too_small() {
    check_noise("noise_accel", 1);
}

/// A gyro white noise stated 8× too small on a 300-s drive, nothing else hidden: the noise is
/// called and no term is put forward as a cause (lever_y = −0.34 ± 0.03 m had been "Found": it
/// is significant only under the stated noise, and with the gyro level found it no longer
/// improves the fit), and the extended model's figures keep the noise level.
#[test]
fn a_misstated_noise_alone_names_no_term() {
    let kind = CaseKind::One("noise_gyro");
    let case = generate(3_000_003, kind, 300.0, clear_effect(kind));
    let out = run_hidden_case(&case, &ExplainOptions::default()).expect("explain runs");
    let e = &out.explanation;
    let causes: Vec<&str> = e
        .findings
        .iter()
        .filter(|f| f.kind != "noise" && f.is_cause())
        .map(|f| f.term.as_str())
        .collect();
    assert!(causes.is_empty(), "{}: named {causes:?}", case.description);
    assert!(e
        .findings
        .iter()
        .any(|f| f.kind == "noise" && f.term == "gyro_arw" && f.is_cause()));
    assert!(
        e.extended.nis_mean < 1.2,
        "the extended figures lost the noise level: mean NIS {}",
        e.extended.nis_mean
    );
}

#[test]
fn finds_a_noise_level_and_a_sensor_term_together() {
    check_noise("noise_accel_kgf", 1);
}

fn check_null(seed: u64) {
    let (case, out) = run(CaseKind::Null, seed);
    let named: Vec<&str> = out
        .explanation
        .findings
        .iter()
        .map(|f| f.term.as_str())
        .collect();
    assert!(named.is_empty(), "{}: named {named:?}", case.description);
    assert_eq!(
        out.explanation.extended_model,
        out.explanation.baseline_model
    );
}

#[test]
fn finds_hidden_d() {
    check_found(CaseKind::One("d"), 1);
}

#[test]
fn finds_hidden_kaq() {
    check_found(CaseKind::One("kaq"), 1);
}

#[test]
fn finds_hidden_kas() {
    check_found(CaseKind::One("kas"), 1);
}

#[test]
fn finds_hidden_kao() {
    check_found(CaseKind::One("kao"), 1);
}

#[test]
fn finds_hidden_kgf() {
    check_found(CaseKind::One("kgf"), 1);
}

#[test]
fn finds_hidden_kgq() {
    check_found(CaseKind::One("kgq"), 1);
}

#[test]
fn finds_hidden_size() {
    check_found(CaseKind::One("size"), 1);
}

#[test]
fn finds_a_hidden_gnss_time_offset() {
    check_found(CaseKind::One("gnss_time"), 1);
}

#[test]
fn finds_a_time_offset_and_a_sensor_term_together() {
    check_found(CaseKind::One("gnss_time_kgf"), 1);
}

#[test]
fn finds_a_hidden_antenna_lever_arm() {
    check_found(CaseKind::One("gnss_lever"), 1);
}

/// A velocity reference mounted pitched and yawed (0.2–2° each): both named within 10 %, no
/// sensor term named.
#[test]
fn finds_a_hidden_reference_mounting() {
    check_found(CaseKind::One("reference_mount"), 1);
}

/// An attitude reference's (a second INS, an AHRS) roll and yaw mounting (0.2–2° each): both
/// named within 10 %, no sensor term named.
#[test]
fn finds_a_hidden_attitude_reference_mounting() {
    check_found(CaseKind::One("attitude_mount"), 1);
}

/// A velocity reference's time offset (20–300 ms) and its yaw mounting: both named within 10 %
/// (or 5 ms), no sensor term named.
#[test]
fn finds_a_hidden_reference_time_offset() {
    check_found(CaseKind::One("reference_time"), 1);
}

/// The mounting and a gyro g-sensitivity beside it: all three named.
#[test]
fn finds_a_reference_mounting_beside_a_sensor_term() {
    check_found(CaseKind::One("reference_mount_kgf"), 1);
}

#[test]
fn finds_an_off_axis_inner_lever_arm_on_a_turntable() {
    check_found(CaseKind::One("inner_lever"), 1);
}

/// The same turntable with the off-axis lever arm withheld from the candidates (the hidden
/// effect is outside what explain may name), over seeds 1–10: whatever explain fits must be
/// labelled as standing in for something else, never presented as a cause (README, "Fitted, but
/// not a cause").
#[test]
fn a_withheld_inner_lever_arm_gives_no_confident_finding() {
    check_withheld("inner_lever", &["size_"], false);
}

/// The same with the turntable's position fixes treated like a receiver's, so the noise levels
/// are candidates too (and the GNSS terms withheld): no noise level stands in for the lever arm
/// as a cause either (3 of 10 seeds named a gyro white noise before the split test of levels).
#[test]
fn a_withheld_inner_lever_arm_gives_no_confident_noise_level() {
    check_withheld("inner_lever", &["size_", "dt_", "lever_"], true);
}

/// A drive with a time offset of the fixes and a gyro g-sensitivity (kgf_yx) hidden, the
/// offset withheld from the candidates, seeds 1–6: an antenna lever arm along the track takes
/// the offset up, the g-sensitivities fitted beside it lean on it (with the offset, re-stamped,
/// in its place they move by many σ), and a velocity σ takes up what is left; none is presented
/// as a cause (before, seed 4 named lever_x 0.96 m, kgf_yx at an eighth of its value and a
/// kgf_xy that is not there, and seed 6 a velocity σ 3×).
#[test]
fn a_withheld_time_offset_gives_no_confident_finding() {
    check_withheld_on("gnss_time_kgf", &["dt_"], false, 1..=6);
}

/// Hides `group` with the candidates starting with `prefixes` withheld, for seeds 1–10: nothing
/// fitted is presented as a cause, and on some seed something is fitted (the guard is exercised).
/// `noise`: the aiding is treated as a receiver's, so the noise levels are tested as well.
fn check_withheld(group: &'static str, prefixes: &[&str], noise: bool) {
    check_withheld_on(group, prefixes, noise, 1..=10);
}

/// [`check_withheld`] on the seeds `seeds`.
fn check_withheld_on(
    group: &'static str,
    prefixes: &[&str],
    noise: bool,
    seeds: std::ops::RangeInclusive<u64>,
) {
    let mut fitted = 0;
    for seed in seeds {
        let mut case = generate(seed, CaseKind::One(group), SECONDS, 1.0).withholding(prefixes);
        case.static_aid = !noise && case.static_aid;
        let out = run_hidden_case(&case, &ExplainOptions::default()).expect("explain runs");
        let e = &out.explanation;
        fitted += e.findings.len();
        for f in &e.findings {
            assert!(
                !f.is_cause(),
                "seed {seed}, {}: {} = {} {} presented as a cause: {}",
                case.description,
                f.term,
                f.estimate,
                f.unit,
                f.words
            );
        }
    }
    assert!(fitted > 0, "{group}: nothing fitted on any seed");
}

/// A vibration term withheld: d·f² hidden on one vibrating axis with every d withheld. A
/// rectifying term of the same axis may fit its misfit; none may be presented as a cause while
/// the withheld d fits as well (seeds 1–4 fit kas on its axis and a gyro noise level, all
/// judged stand-ins). The demo's vibration, alike on three axes, where a cross-quadratic is the
/// withheld d's equal, is `explain_cli::a_withheld_term_that_fits_as_well_is_named_…`.
#[test]
fn a_withheld_vibration_term_gives_no_confident_finding() {
    check_withheld_on("d", &["d_"], false, 1..=4);
}

/// Both sensor-side effects withheld at once (lever arm and asynchrony on one turntable).
#[test]
fn withheld_lever_arm_and_asynchrony_give_no_confident_finding() {
    check_withheld("inner_lever_delay", &["size_", "tau_"], false);
}

/// The off-axis lever arm named as a cause (not a stand-in) on every seed 1–10, its value within
/// 3 of its σ of the truth (seed 1 is held to 10 % above; over seeds 1–10, 9 are within 10 % and
/// seed 4 is 12.6 % off, as far as a filter that knows the true model: 2.4 σ), and the recovered
/// gain at least 80 % of that filter's.
#[test]
fn finds_the_off_axis_lever_arm_on_every_seed() {
    for seed in 1..=10 {
        let (case, out) = run(CaseKind::One("inner_lever"), seed);
        let (name, truth_si) = &case.hidden[0];
        let f = out
            .explanation
            .findings
            .iter()
            .find(|f| &f.term == name)
            .unwrap_or_else(|| panic!("seed {seed}: {name} not named"));
        assert!(f.is_cause(), "seed {seed}: {name} not a cause: {}", f.words);
        let truth = truth_si * 1e3; // m → mm
        assert!(
            (f.estimate - truth).abs() < 3.0 * f.sigma,
            "seed {seed}: {name} = {} ± {} mm, true {truth}",
            f.estimate,
            f.sigma
        );
        let (recovery, _) = out.gain_recovery().expect("a recovery");
        assert!(recovery >= 0.8, "seed {seed}: recovery {recovery}");
    }
}

/// A baseline term 10× beyond its prior (an accelerometer bias of 1 mg and a scale factor of
/// 1000 ppm held to the navigation-grade 100 µg and 100 ppm) on a turntable: explain says the
/// priors are too tight, with the data's values and a prior that holds them, runs again with
/// those and names nothing (with the tight priors alone the biased baseline made kao_y look
/// significant).
#[test]
fn a_baseline_prior_too_tight_is_said() {
    let mut case = generate(1, CaseKind::One("inner_lever"), SECONDS, 1.0).scaled(0.0);
    case.scenario = case.scenario.replace(
        "[errors]\n",
        "[errors]\nnabla_y = \"1000 ug\"\nka_22 = \"1000 ppm\"\n",
    );
    // the generator's own values for them go (a scenario key given twice is refused)
    let keep: Vec<&str> = case
        .scenario
        .lines()
        .filter(|l| {
            !(l.starts_with("nabla_y = \"") || l.starts_with("ka_22 = \"")) || l.contains("1000")
        })
        .collect();
    case.scenario = keep.join("\n") + "\n";
    case.baseline = "P31+vertical".into();
    let out = run_hidden_case(&case, &ExplainOptions::default()).expect("explain runs");
    let e = &out.explanation;
    let w: Vec<(&str, f64, f64)> = e
        .baseline_priors_tight
        .iter()
        .map(|p| (p.term.as_str(), p.estimate, p.suggested))
        .collect();
    let find = |name: &str| w.iter().find(|x| x.0 == name).copied();
    let (_, nabla, to) = find("nabla_y").unwrap_or_else(|| panic!("nabla_y not flagged: {w:?}"));
    assert!((nabla - 1000.0).abs() < 100.0 && to >= 3000.0, "{w:?}");
    // the scale factor stays biased by its tight prior (short static spans): beyond 3 prior σ,
    // and the suggested prior holds the true value
    let (_, ka, to) = find("ka_22").unwrap_or_else(|| panic!("ka_22 not flagged: {w:?}"));
    assert!(ka > 300.0 && to >= 1000.0, "{w:?}");
    assert_eq!(w.len(), 2, "only the two: {w:?}");
    assert!(e.summary[0].contains("too tight"), "{:?}", e.summary);
    assert!(
        e.findings.is_empty(),
        "named {:?}",
        e.findings.iter().map(|f| &f.term).collect::<Vec<_>>()
    );
}

/// A gyro–accelerometer asynchrony (the three accelerometers 1–3 ms behind the gyros) on the
/// turntable: the three delays are named, each within 10 %, none a stand-in.
#[test]
fn finds_a_gyro_accelerometer_asynchrony_on_a_turntable() {
    check_found(CaseKind::One("accel_delay"), 1);
}

/// Both on one turntable (an off-axis lever arm and the asynchrony, beside the baseline's
/// biases and scale factors): all four named with their values, nothing else.
#[test]
fn finds_an_inner_lever_arm_and_an_asynchrony_together() {
    check_found(CaseKind::One("inner_lever_delay"), 1);
}

/// The asynchrony withheld from the candidates: whatever explain fits instead is labelled a
/// stand-in, on every seed 1–10.
#[test]
fn a_withheld_asynchrony_gives_no_confident_finding() {
    check_withheld("accel_delay", &["tau_"], false);
}

/// The turntable with nothing hidden (the lever arm scaled to zero) names nothing.
#[test]
fn names_nothing_on_a_clean_turntable() {
    let case = generate(1, CaseKind::One("inner_lever"), SECONDS, 1.0).scaled(0.0);
    let out = run_hidden_case(&case, &ExplainOptions::default()).expect("explain runs");
    let named: Vec<&str> = out
        .explanation
        .findings
        .iter()
        .map(|f| f.term.as_str())
        .collect();
    assert!(named.is_empty(), "{}: named {named:?}", case.description);
}

#[test]
fn finds_two_hidden_terms_by_forward_selection() {
    check_found(CaseKind::Two, 1);
}

#[test]
fn names_nothing_when_nothing_is_hidden() {
    check_null(1);
    check_null(2);
}

/// A weaker effect (0.1 mg) is still found, but explain must not claim more precision than it has:
/// the reported σ covers the error (|error| < 4σ) at a tenth of the clear magnitude.
#[test]
fn sigma_covers_the_error_of_a_weak_effect() {
    let kind = CaseKind::One("d");
    let case = generate(3, kind, SECONDS, 0.1 * clear_effect(kind));
    let out = run_hidden_case(&case, &ExplainOptions::default()).unwrap();
    let (name, truth_si) = &case.hidden[0];
    let f = out
        .explanation
        .findings
        .iter()
        .find(|f| &f.term == name)
        .unwrap_or_else(|| panic!("{name} at 0.1 mg not named"));
    let info = common::TERMS.iter().find(|t| t.name == name).unwrap();
    let truth = truth_si / info.display_to_si;
    assert!(
        (f.estimate - truth).abs() < 4.0 * f.sigma,
        "{name}: {} ± {} vs true {truth}",
        f.estimate,
        f.sigma
    );
}

/// Developer probe: `PROBE=kgf SEED=3 cargo test --release --test explain -- --ignored probe
/// --nocapture` prints one case's summary and top candidates.
#[test]
#[ignore]
fn probe() {
    let which = std::env::var("PROBE").unwrap_or_else(|_| "d".into());
    let kind = match which.as_str() {
        "null" => CaseKind::Null,
        "two" => CaseKind::Two,
        g => CaseKind::One(
            sinsmodel::sim::hidden::all_groups()
                .into_iter()
                .find(|x| *x == g)
                .expect("a group, null or two"),
        ),
    };
    let seed = std::env::var("SEED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1);
    // CASE_SECONDS=300: a shorter case (explain-eval's --seconds)
    let seconds = std::env::var("CASE_SECONDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(SECONDS);
    let mut case = generate(seed, kind, seconds, clear_effect(kind));
    if let Ok(w) = std::env::var("WITHHOLD") {
        case = case.withholding(&w.split(',').collect::<Vec<_>>());
    }
    // NOISE=1: a turntable case's aiding treated like a receiver's (noise levels tested)
    if std::env::var("NOISE").is_ok() {
        case.static_aid = false;
    }
    let out = run_hidden_case(&case, &ExplainOptions::default()).expect("explain runs");
    eprintln!("{}", case.description);
    if std::env::var("SCEN").is_ok() {
        eprintln!("{}", case.scenario);
    }
    let e = &out.explanation;
    for s in &e.summary {
        eprintln!("  {s}");
    }
    for c in e.candidates.iter().take(6) {
        eprintln!(
            "  cand {} llr {:.1} p_holm {:.2e} glr {:.3e}±{:.1e} {} conf {:?}",
            c.term, c.llr, c.p_holm, c.glr_estimate, c.glr_sigma, c.unit, c.confounded_with
        );
    }
    for f in &e.findings {
        eprintln!(
            "  finding {} {:.4} ± {:.2} {} 2dl {:.1} prior σ {:.1} share {:?} stand-in {} splits failing {:?}",
            f.term,
            f.estimate,
            f.sigma,
            f.unit,
            f.two_delta_loglik,
            f.prior_sigmas,
            f.misfit_share,
            f.stand_in.is_some(),
            f.consistency
                .iter()
                .filter(|c| !c.holds)
                .map(|c| format!("{} χ² {:.1}/{}", c.split, c.chi2, c.dof))
                .collect::<Vec<_>>()
        );
    }
    if std::env::var("SHOW_GROUPS").is_ok() {
        for f in &e.findings {
            for c in &f.consistency {
                eprintln!(
                    "  {} {}: χ² {:.1}/{} holds {} {:?}",
                    f.term,
                    c.split,
                    c.chi2,
                    c.dof,
                    c.holds,
                    c.groups
                        .iter()
                        .map(|g| format!("{} {:.3}±{:.3}", g.group, g.estimate, g.sigma))
                        .collect::<Vec<_>>()
                );
            }
        }
    }
    for f in e.findings.iter().filter(|f| f.kind == "noise") {
        eprintln!("  noise {} scale {:?}", f.term, f.scale);
    }
    for (l, r) in &case.noise_ratio {
        eprintln!("  true {l} ratio {r:.3}");
    }
    for (h, (x, s)) in case.hidden.iter().zip(&out.oracle_estimates) {
        eprintln!("  true {} {:.4e}, oracle {:.4e} ± {:.1e}", h.0, h.1, x, s);
    }
    eprintln!(
        "  found {:?} recovery {:?} rounds {}",
        case.hidden
            .iter()
            .map(|h| out.found(&h.0))
            .collect::<Vec<_>>(),
        out.gain_recovery(),
        e.rounds
    );
}

/// A known time offset and lever arm (`--gnss-delay`, `--lever-arm`: `FilterConfig::known_gnss`)
/// applied in the residuals make the filter consistent again on data that carry them, and a
/// wrong one does not.
#[test]
fn known_gnss_values_are_applied_in_the_residuals() {
    use sinsmodel::estimate::filter;
    use sinsmodel::experiment::reproduce::{config, Priors};
    use sinsmodel::model::Model;
    for group in ["gnss_time", "gnss_lever"] {
        let case = generate(1, CaseKind::One(group), SECONDS, 1.0);
        let (sim, aid) = sinsmodel::experiment::hidden::simulate_case(&case).unwrap();
        let model = Model::parse(&case.baseline).unwrap();
        let (name, value) = &case.hidden[0];
        let t = common::TERMS.iter().position(|x| x.name == name).unwrap();
        let nis = |known: Vec<(usize, f64)>| {
            let mut cfg = config(&model, &Priors::default()).unwrap();
            cfg.known_gnss = known;
            let run = filter::run(&model, &cfg, &sim.imu, sim.start, &aid, None, |_| {});
            let n = run.innovations.len() as f64;
            run.innovations
                .iter()
                .map(|i| i.nu * i.nu / i.s)
                .sum::<f64>()
                / n
        };
        let (none, right, half) = (
            nis(vec![]),
            nis(vec![(t, *value)]),
            nis(vec![(t, 0.5 * value)]),
        );
        assert!(
            right < 1.2,
            "{group}: known {name} = {value}: mean NIS {right}"
        );
        assert!(
            none > 2.0 * right,
            "{group}: without it {none}, with it {right}"
        );
        assert!(
            half > 1.5 * right,
            "{group}: half of it {half}, all of it {right}"
        );
    }
}

/// Noise as a finding: the fixes state a position σ four times smaller than their real noise;
/// explain names that scale (within 10 %) and no error term.
#[test]
fn finds_an_aiding_sigma_stated_too_small() {
    use sinsmodel::experiment::hidden::{run_hidden_on, simulate_case};
    let case = generate(11, CaseKind::Null, SECONDS, 1.0);
    let (sim, mut aid) = simulate_case(&case).unwrap();
    for ep in &mut aid {
        if let Some(p) = &mut ep.pos {
            for s in &mut p.3 {
                *s /= 4.0;
            }
        }
    }
    let out = run_hidden_on(&case, &sim, &aid, &ExplainOptions::default()).unwrap();
    let e = &out.explanation;
    let kinds: Vec<(&str, &str)> = e
        .findings
        .iter()
        .map(|f| (f.term.as_str(), f.kind))
        .collect();
    assert!(
        e.findings.iter().all(|f| f.kind == "noise"),
        "an error term named: {kinds:?}"
    );
    let f = e
        .findings
        .iter()
        .find(|f| f.term == "sigma_pos_ne")
        .unwrap_or_else(|| panic!("no position sigma finding: {kinds:?}; {:#?}", e.summary));
    let scale = f.scale.unwrap();
    assert!((scale / 4.0 - 1.0).abs() < 0.10, "scale {scale}");
    let [lo, hi] = f.scale_interval.unwrap();
    assert!(lo < scale && scale < hi);
    assert!(
        e.extended.nis_mean < 1.2,
        "NIS after {}",
        e.extended.nis_mean
    );
}
