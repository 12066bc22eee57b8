//! The replay of a recorded open-loop pass (`estimate::replay`) against full passes: the same
//! innovations under rescaled process noise and fix σ, for a preset and a run-time composed
//! model; and no tape where a replay cannot be exact.

use sinsmodel::estimate::filter::{self, FilterConfig, Mode};
use sinsmodel::estimate::replay::Recorder;
use sinsmodel::experiment::reproduce::{self, Priors};
use sinsmodel::model::Model;
use sinsmodel::sim::scenario::Scenario;
use sinsmodel::sim::simulator::simulate;

/// The states whose q `f` changes when it scales a copy of `cfg` by 2.
fn group(cfg: &FilterConfig, f: impl Fn(&mut FilterConfig)) -> Vec<usize> {
    let mut c = cfg.clone();
    f(&mut c);
    (0..cfg.q.len()).filter(|&i| c.q[i] != cfg.q[i]).collect()
}

fn check(model_name: &str) {
    let case = &reproduce::cases(true, 5)[0];
    let sim = simulate(&Scenario::parse(&case.scenario, "static").unwrap(), |_| {});
    let priors = Priors::default();
    let aid = reproduce::aiding_from_truth(&sim, &priors, true, 5).unwrap();
    let model = Model::parse(model_name).unwrap();
    let cfg: FilterConfig = reproduce::config(&model, &priors).unwrap();
    let arw = group(&cfg, |c| c.scale_sensor_noise(&model, 2.0, 1.0));
    let vrw = group(&cfg, |c| c.scale_sensor_noise(&model, 1.0, 2.0));
    assert!(!arw.is_empty() && !vrw.is_empty());
    let mut rec = Recorder::new(model.n(), &cfg, &[arw, vrw]).expect("open loop records");
    let full = filter::run_observed(
        &model,
        &cfg,
        &sim.imu,
        sim.start,
        &aid,
        None,
        |_| {},
        &mut |_| {},
        &mut rec,
    );
    let tape = rec.finish().expect("a tape");
    assert!(tape.bytes() > 0);
    let meas = full.innovations[0].meas;
    // the recorded configuration, then gyro noise ×3, accelerometer noise ×0.2 and the
    // first measurement's σ ×0.5 together
    let mut scaled = cfg.clone();
    scaled.scale_sensor_noise(&model, 3.0, 0.2);
    scaled.sigma_scale.push((meas, 0.5));
    let rescaled = filter::run(&model, &scaled, &sim.imu, sim.start, &aid, None, |_| {});
    // (the rescaling changes every variance: the comparison below can fail)
    let moved = full
        .innovations
        .iter()
        .zip(&rescaled.innovations)
        .filter(|(a, b)| (a.s / b.s - 1.0).abs() > 1e-3)
        .count();
    assert!(moved * 2 > full.innovations.len(), "{moved}");
    for (c, reference) in [
        (&cfg, full.innovations.clone()),
        (&scaled, rescaled.innovations),
    ] {
        let replayed = tape.innovations(c).expect("a rescaling replays");
        assert_eq!(replayed.len(), reference.len());
        for (a, b) in replayed.iter().zip(&reference) {
            assert_eq!((a.t, a.meas, a.component), (b.t, b.meas, b.component));
            assert!((a.s / b.s - 1.0).abs() < 1e-9, "S {} vs {}", a.s, b.s);
            assert!(
                (a.nu - b.nu).abs() < 1e-9 * b.s.sqrt().max(b.nu.abs()),
                "ν {} vs {} (√S {})",
                a.nu,
                b.nu,
                b.s.sqrt()
            );
        }
    }
    // what a replay cannot give: another step, another prior, a scale within a group that
    // is not one factor
    let mut other = cfg.clone();
    other.step_s *= 2.0;
    assert!(tape.innovations(&other).is_none());
    let mut other = cfg.clone();
    other.prior_sigma[0] *= 2.0;
    assert!(tape.innovations(&other).is_none());
    let mut other = cfg.clone();
    let i = (0..other.q.len()).find(|&i| other.q[i] > 0.0).unwrap();
    other.q[i] *= 2.0;
    assert!(tape.innovations(&other).is_none());
}

#[test]
fn a_replay_gives_a_full_pass_innovations_for_a_preset() {
    check("P31");
}

#[test]
fn a_replay_gives_a_full_pass_innovations_for_a_composed_model() {
    check("P28+vertical+d_x+kas_y");
}

#[test]
fn closed_loop_is_not_recorded() {
    let model = Model::parse("P13").unwrap();
    let mut cfg = FilterConfig::new(&model);
    cfg.mode = Mode::ClosedLoop;
    assert!(Recorder::new(model.n(), &cfg, &[]).is_none());
}
