use sinsmodel::estimate::explain::{run_hidden_case, ExplainOptions};
use sinsmodel::sim::hidden::{generate, CaseKind, GROUPS};

#[test]
#[ignore]
fn probe() {
    let which = std::env::var("PROBE").unwrap_or_else(|_| "d".into());
    let kind = match which.as_str() {
        "null" => CaseKind::Null,
        "two" => CaseKind::Two,
        g => CaseKind::One(GROUPS.iter().find(|x| **x == g).unwrap()),
    };
    let seed: u64 = std::env::var("SEED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1);
    let case = generate(seed, kind, 600.0, 1.0);
    eprintln!("{}", case.description);
    let t = std::time::Instant::now();
    let out = run_hidden_case(&case, &ExplainOptions::default()).unwrap();
    eprintln!("took {:.1} s", t.elapsed().as_secs_f64());
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
    for (h, (x, s)) in case.hidden.iter().zip(&out.oracle_estimates) {
        eprintln!("  true {} {:.4e}, oracle {:.4e} ± {:.1e}", h.0, h.1, x, s);
    }
    eprintln!(
        "  found {:?} recovery {:?} oracle rms {:?} rounds {}",
        case.hidden
            .iter()
            .map(|h| out.found(&h.0))
            .collect::<Vec<_>>(),
        out.gain_recovery(),
        out.oracle_model_error_rms,
        e.rounds
    );
}
