//! Hidden-effect cases end to end: simulate a case with terms hidden in it, aid from the truth,
//! run explain with the case's baseline and the oracle filter (the true model) for the gain it
//! can reach. Shared by the tests and `explain-eval`; kept out of `estimate/` so the estimator
//! never depends on the experiments built on it.

use crate::estimate::filter::{self, AidingEpoch, FilterConfig};
use crate::explain::{
    explain, innovation_loglik, parse_candidates, ExplainData, ExplainOptions, Explanation,
    ImuInput,
};
use crate::io::imu::ImuData;
use crate::model::catalog::Sensor;
use crate::model::generated::common;
use crate::model::Model;

/// Runs a hidden-effect case end to end: simulate, aid from the truth (1 Hz position and
/// velocity, σ 0.1 m and 0.01 m/s), explain with the case's baseline and the default
/// candidates, and the oracle filter (baseline + the hidden terms) for the gain it can reach.
/// Shared by the tests and `explain-eval`.
pub fn run_hidden_case(
    case: &crate::sim::hidden::HiddenCase,
    opts: &ExplainOptions,
) -> anyhow::Result<HiddenOutcome> {
    let (sim, aid) = simulate_case(case)?;
    run_hidden_on(case, &sim, &aid, opts)
}

/// Simulates a hidden-effect case and its aiding (1 Hz position σ 0.1 m and velocity σ 0.01 m/s
/// from the truth).
pub fn simulate_case(
    case: &crate::sim::hidden::HiddenCase,
) -> anyhow::Result<(crate::sim::simulator::SimOutput, Vec<AidingEpoch>)> {
    use crate::experiment::reproduce::{aiding_from_truth, Priors};
    let sc = crate::sim::scenario::Scenario::parse(&case.scenario, &format!("case {}", case.seed))?;
    let sim = crate::sim::simulator::simulate(&sc, |_| {});
    let priors = Priors {
        sigma_p: "0.1 m".into(),
        ..Priors::default()
    };
    let aid = aiding_from_truth(&sim, &priors, true, case.seed)?;
    Ok((sim, aid))
}

/// Runs explain and the oracle on already simulated data of `case` (the IMU may carry the
/// hidden terms injected after simulation, see `inject`).
pub fn run_hidden_on(
    case: &crate::sim::hidden::HiddenCase,
    sim: &crate::sim::simulator::SimOutput,
    aid: &[AidingEpoch],
    opts: &ExplainOptions,
) -> anyhow::Result<HiddenOutcome> {
    let aid = aid.to_vec();
    let baseline = Model::parse(&case.baseline)?;
    let mut cands = parse_candidates(None, &baseline).map_err(anyhow::Error::msg)?;
    cands.retain(|&t| !case.withheld.iter().any(|w| w == common::TERMS[t].name));
    if case.static_aid {
        cands.retain(|&t| common::TERMS[t].sensor != Sensor::Gnss);
    }
    // explain's passes and the oracle's share one navigation of the data where they can
    let imu = ImuInput::Memory(&sim.imu);
    let slot = crate::explain::TapeSlot::new(&imu);
    let data = ExplainData {
        imu,
        aid: &aid,
        truth: Some(&sim.truth),
        start: sim.start,
        tape: opts.share_navigation.then_some(&slot),
    };
    let stated = |m: &Model| stated_config(case, sim, m);
    let config_for = |m: &Model| -> anyhow::Result<FilterConfig> { Ok(stated(m)) };
    let mut opts = opts.clone();
    opts.noise_levels &= !case.static_aid;
    for (name, sigma) in &case.priors {
        if let Some(t) = common::TERMS.iter().position(|x| x.name == name) {
            opts.candidate_sigma.retain(|x| x.0 != t);
            opts.candidate_sigma.push((t, *sigma));
        }
    }
    let t_explain = std::time::Instant::now();
    let expl = explain(&baseline, &cands, &data, &config_for, &opts, &mut |_, _| {})?;
    let explain_seconds = t_explain.elapsed().as_secs_f64();
    let oracle = Model::parse(&case.oracle_model())?;
    // the oracle knows the terms and their size: a prior that holds the true value
    let mut oracle_cfg = stated(&oracle);
    // and the noise as simulated
    let ratio = |l: &str| crate::sim::hidden::ratio_of(&case.noise_ratio, l);
    oracle_cfg.scale_sensor_noise(&oracle, ratio("gyro_arw"), ratio("accel_vrw"));
    oracle_cfg.scale_bias_random_walk(&oracle, ratio("gyro_bias_rw"), ratio("accel_bias_rw"));
    for (name, v) in &case.hidden {
        if let Some(i) = oracle.index_of(name) {
            let declared = case.priors.iter().find(|p| &p.0 == name).map(|p| p.1);
            let sigma = declared.unwrap_or(oracle_cfg.prior_sigma[i]);
            oracle_cfg.prior_sigma[i] = sigma.max(3.0 * v.abs());
        }
    }
    let run = match slot.replay(&oracle, &oracle_cfg, &data)? {
        Some(run) => run,
        None => filter::run(
            &oracle,
            &oracle_cfg,
            &sim.imu,
            sim.start,
            &aid,
            Some(&sim.truth),
            |_| {},
        ),
    };
    let t_end = run.records.last().map(|r| r.t).unwrap_or(0.0);
    let t0 = run.records.first().map(|r| r.t).unwrap_or(0.0);
    let oracle_rms = filter::model_error_rms_arcsec(&run, 0.5 * (t0 + t_end), t_end + 1.0)
        .map(|e| e[0].hypot(e[1]));
    let oracle_estimates = case
        .hidden
        .iter()
        .map(|(name, _)| {
            let i = oracle.index_of(name).expect("oracle has the hidden term");
            let r = run.records.last().expect("records");
            (r.x[i], r.sigma[i])
        })
        .collect();
    Ok(HiddenOutcome {
        explanation: expl,
        explain_seconds,
        oracle_loglik: innovation_loglik(&run),
        oracle_model_error_rms: oracle_rms,
        oracle_estimates,
    })
}

/// The filter configuration of `model` on a case's data: the case's stated noise (a noise case
/// states one level wrongly), closed loop with a velocity reference, as the command line runs
/// it.
pub fn stated_config(
    case: &crate::sim::hidden::HiddenCase,
    sim: &crate::sim::simulator::SimOutput,
    m: &Model,
) -> FilterConfig {
    let mut c = match case.stated_noise {
        Some([arw, vrw, grw, arw_bias]) => FilterConfig::new(m)
            .with_sensor_noise(m, arw, vrw)
            .with_bias_random_walk(m, grw, arw_bias),
        None => FilterConfig::new(m),
    };
    if sim.body_velocity.is_some() {
        c.mode = crate::estimate::filter::Mode::ClosedLoop;
    }
    c
}

/// Adds term `term` with value `theta` (SI) to IMU increments: the sensor's output along its
/// axis gains θ · regressor · Δt, the regressor formed from each increment's mean signals
/// (their derivatives from consecutive increments).
/// A GNSS term changes nothing here (the simulator puts it into the aiding).
pub fn inject(imu: &mut ImuData, start_t: f64, term: usize, theta: f64) {
    let info = &common::TERMS[term];
    let mut prev = start_t;
    let mut rates = crate::model::SignalRates::default();
    for smp in &mut imu.samples {
        let dt = smp.t - prev;
        prev = smp.t;
        if dt <= 0.0 {
            continue;
        }
        let sig = rates.next(&(smp.dv / dt), &(smp.dtheta / dt), dt);
        let r = common::regressor_value(info.regressor, &sig);
        match info.sensor {
            Sensor::Accel => smp.dv[info.axis] += theta * r * dt,
            Sensor::Gyro => smp.dtheta[info.axis] += theta * r * dt,
            // a GNSS term is in the aiding, not in the IMU's increments
            Sensor::Gnss | Sensor::Reference | Sensor::Attitude => {}
        }
    }
}

/// What explain did on a hidden-effect case, with the oracle's reference.
#[derive(Debug, Clone)]
pub struct HiddenOutcome {
    /// Explain's result.
    pub explanation: Explanation,
    /// Wall time explain took [s].
    pub explain_seconds: f64,
    /// Model error RMS of the filter with the true model [arcsec] (second half).
    pub oracle_model_error_rms: Option<f64>,
    /// Innovation log-likelihood of the filter with the true model.
    pub oracle_loglik: f64,
    /// The oracle filter's final estimate and σ of each hidden term (SI).
    pub oracle_estimates: Vec<(f64, f64)>,
}

impl HiddenOutcome {
    /// True when the hidden term `name` was named, or is in a finding's equivalence class.
    pub fn found(&self, name: &str) -> bool {
        self.explanation
            .findings
            .iter()
            .any(|f| f.term == name || f.equivalent.iter().any(|e| e == name))
    }

    /// Fraction of the oracle's gain the extended model recovers, and which gain: the model
    /// error (truth) when knowing the true model lowers it by at least 10 %, else the
    /// innovation log-likelihood (terms that do not reach the attitude, e.g. vertical ones).
    /// None when the oracle gains nothing on either.
    pub fn gain_recovery(&self) -> Option<(f64, &'static str)> {
        let e = &self.explanation;
        let g = &e.gain;
        if let (Some(b), Some(a), Some(o)) = (
            g.model_error_rms_before,
            g.model_error_rms_after,
            self.oracle_model_error_rms,
        ) {
            if b - o >= 0.1 * b {
                return Some(((b - a) / (b - o), "model error"));
            }
        }
        let base = e.baseline.loglik;
        let oracle_gain = self.oracle_loglik - base;
        (oracle_gain > 10.0).then(|| (g.loglik / oracle_gain, "log-likelihood"))
    }
}
