//! The error-state filter: P24 = P28 horizontally for a level IMU (DESIGN §3), the paper's
//! experiments in their quick form with the done-when ratios, closed-loop feedback.

use sinsmodel::estimate::filter::{self, FilterConfig, Mode};
use sinsmodel::model::Model;
use sinsmodel::report::reproduce::{self, Priors};
use sinsmodel::sim::scenario::Scenario;
use sinsmodel::sim::simulator::simulate;

#[test]
fn p24_and_p28_give_the_same_horizontal_solution_for_a_level_imu() {
    let case = &reproduce::cases(true, 3)[0]; // static, level, paper errors
    let sim = simulate(&Scenario::parse(&case.scenario, "static").unwrap(), |_| {});
    let priors = Priors::default();
    let aid = reproduce::aiding_from_truth(&sim, &priors, true, 3).unwrap();
    let (_, runs) =
        reproduce::run_models(&sim, &aid, &["P24", "P28"], &priors, case.window, |_, _| {})
            .unwrap();
    let (a, b) = (&runs[0], &runs[1]);
    let mut worst: f64 = 0.0;
    for (ra, rb) in a.records.iter().zip(&b.records) {
        for i in 0..7 {
            // horizontal navigation states share names and indices 0..7
            let tol = 1e-6 * ra.sigma[i].max(rb.sigma[i]);
            worst = worst.max((ra.x[i] - rb.x[i]).abs() / ra.sigma[i]);
            assert!(
                (ra.x[i] - rb.x[i]).abs() <= tol,
                "{} at t = {}: {} vs {}",
                a.names[i],
                ra.t,
                ra.x[i],
                rb.x[i]
            );
        }
    }
    eprintln!("P24 vs P28: largest horizontal difference {worst:.2e} sigma");
}

#[test]
fn quick_reproduction_meets_the_done_when_ratios() {
    let priors = Priors::default();
    for case in reproduce::cases(true, 1) {
        let (r, _, _) = reproduce::run_case(&case, &priors, 1, |_, _| {}).unwrap();
        eprintln!(
            "{:<12} P28 {:?} P31 {:?} ratio {:.2}",
            r.name, r.model_error_rms_arcsec["P28"], r.model_error_rms_arcsec["P31"], r.ratio
        );
        match r.name.as_str() {
            "static" => assert!((0.8..=1.25).contains(&r.ratio), "static ratio {}", r.ratio),
            "sine" => assert!(r.ratio >= 5.0, "sine ratio {}", r.ratio),
            _ => assert!(r.ratio > 1.0, "{} ratio {}", r.name, r.ratio),
        }
    }
}

#[test]
fn closed_loop_feedback_keeps_the_navigator_on_the_truth() {
    let case = &reproduce::cases(true, 5)[0];
    let sim = simulate(&Scenario::parse(&case.scenario, "static").unwrap(), |_| {});
    let priors = Priors::default();
    let aid = reproduce::aiding_from_truth(&sim, &priors, true, 5).unwrap();
    let model = Model::parse("P31").unwrap();
    let mut cfg: FilterConfig = reproduce::config(&model, &priors).unwrap();
    let open = filter::run(
        &model,
        &cfg,
        &sim.imu,
        sim.start,
        &aid,
        Some(&sim.truth),
        |_| {},
    );
    cfg.mode = Mode::ClosedLoop;
    let closed = filter::run(
        &model,
        &cfg,
        &sim.imu,
        sim.start,
        &aid,
        Some(&sim.truth),
        |_| {},
    );
    let last = |r: &filter::FilterRun| {
        let p = r.records.last().unwrap().pos_err_ne.unwrap();
        p[0].hypot(p[1])
    };
    eprintln!(
        "final position error: open loop {:.1} m, closed loop {:.3} m",
        last(&open),
        last(&closed)
    );
    assert!(last(&open) > 20.0, "the free navigator drifts");
    assert!(last(&closed) < 2.0, "feedback keeps it on the truth");
    // the attitude is known equally well in both modes: same model-error RMS (second half)
    let eo = filter::model_error_rms_arcsec(&open, 300.0, 600.0).unwrap();
    let ec = filter::model_error_rms_arcsec(&closed, 300.0, 600.0).unwrap();
    eprintln!("model error RMS: open {eo:?} closed {ec:?} arcsec");
    for k in 0..2 {
        assert!((ec[k] / eo[k] - 1.0).abs() < 0.2, "{eo:?} vs {ec:?}");
    }
    // the accumulated closed-loop estimate of the x gyro bias agrees with open loop
    let i = model.index_of("eps_x").unwrap();
    let (eo, ec) = (
        open.records.last().unwrap().x[i],
        closed.records.last().unwrap().x[i],
    );
    let s = open.records.last().unwrap().sigma[i];
    assert!((eo - ec).abs() < s, "eps_x open {eo} closed {ec} sigma {s}");
}
