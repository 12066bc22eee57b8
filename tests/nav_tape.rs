//! The navigation tape (`estimate::nav_tape`): passes replayed from one recorded open-loop pass
//! equal full passes bit for bit (preset and run-time composed models, what their observers
//! see); no tape where the navigation would differ; explain and its evaluation give the same
//! answers with and without it.

use sinsmodel::estimate::filter::{self, AidingEpoch, FilterConfig, Mode, Observer, StepSums};
use sinsmodel::estimate::nav_tape::{NavTape, TapeRecorder};
use sinsmodel::experiment::reproduce::{self, Priors};
use sinsmodel::model::generated::common;
use sinsmodel::model::{ImuSignals, Model};
use sinsmodel::nav::nav_point::NavPoint;
use sinsmodel::nav::strapdown::{NavState, Vertical};
use sinsmodel::sim::scenario::Scenario;
use sinsmodel::sim::simulator::{simulate, SimOutput};

fn data() -> (SimOutput, Vec<AidingEpoch>) {
    let case = &reproduce::cases(true, 5)[0];
    let sim = simulate(&Scenario::parse(&case.scenario, "static").unwrap(), |_| {});
    let aid = reproduce::aiding_from_truth(&sim, &Priors::default(), true, 5).unwrap();
    (sim, aid)
}

fn config(model: &Model) -> FilterConfig {
    reproduce::config(model, &Priors::default()).unwrap()
}

/// What an observer is shown, step by step, as text (Debug of f64 tells every bit apart).
#[derive(Default)]
struct Log {
    /// Regressor sums of the samples since the last step (a full pass).
    sums: Vec<f64>,
    count: u32,
    lines: Vec<String>,
    /// nav_sample calls: the last (time, x) shown before each step.
    shown: Option<(f64, Vec<f64>)>,
}

impl Observer for Log {
    fn sample(&mut self, sig: &ImuSignals) {
        let mut v = [0.0; common::REGRESSOR_COUNT];
        common::regressor_values(sig, &mut v);
        self.sums.resize(v.len(), 0.0);
        for (s, x) in self.sums.iter_mut().zip(&v) {
            *s += x;
        }
        self.count += 1;
    }
    fn step_sums(&mut self, sums: &StepSums<'_>) {
        self.sums = sums.regressors.to_vec();
        self.count = sums.count;
    }
    fn nav_sample(&mut self, s: &NavState, x: &[f64], _p: &[f64]) {
        // (a replay shows each step's x once, at its first sample; a full pass at every
        // sample: the first showing of each x is what both must agree on)
        if self.shown.as_ref().is_none_or(|(_, y)| y != x) {
            self.shown = Some((s.t, x.to_vec()));
            self.lines.push(format!("x at {:?}: {x:?}", s.t));
        }
    }
    fn step(&mut self, t: f64, dt: f64, np: &NavPoint, a: &[f64], pattern: &[(usize, usize)]) {
        let a: Vec<f64> = pattern.iter().map(|&(i, j)| a[i * np_n(a) + j]).collect();
        self.lines.push(format!(
            "step {t:?} {dt:?} {:?} {:?} {:?} {a:?} sums {:?} of {}",
            np.f_ned, np.v_ned, np.w_b, self.sums, self.count
        ));
        self.sums.clear();
        self.count = 0;
    }
    fn scalar_update(
        &mut self,
        t: f64,
        meas: &'static str,
        component: usize,
        _h: &[f64],
        k: &[f64],
        nu: f64,
        s: f64,
    ) {
        self.lines.push(format!(
            "update {t:?} {meas} {component} {k:?} {nu:?} {s:?}"
        ));
    }
}

/// n of an n×n row-major matrix.
fn np_n(a: &[f64]) -> usize {
    (a.len() as f64).sqrt().round() as usize
}

fn record(model: &Model, sim: &SimOutput, aid: &[AidingEpoch]) -> NavTape {
    let cfg = config(model);
    let mut rec = TapeRecorder::new(&cfg, &sim.start, aid).expect("open loop records");
    let run = filter::run_observed(
        model,
        &cfg,
        &sim.imu,
        sim.start,
        aid,
        Some(&sim.truth),
        |_| {},
        &mut |_| {},
        &mut rec,
    );
    rec.finish(&run).expect("a whole pass gives a tape")
}

#[test]
fn replayed_passes_equal_full_passes_bit_for_bit() {
    let (sim, aid) = data();
    let tape = record(&Model::parse("P31").unwrap(), &sim, &aid);
    assert!(
        tape.len() > 1000 && tape.bytes() > 100_000,
        "{}",
        tape.len()
    );
    // the recorded model, a run-time composition with terms P31 lacks, and another preset
    for name in ["P31", "P13+kas_x+d_y+kgf_zx", "P24"] {
        let model = Model::parse(name).unwrap();
        let cfg = config(&model);
        assert!(tape.fits(&cfg, &sim.start, &aid), "{name}");
        let mut seen_full = Log::default();
        let full = filter::run_observed(
            &model,
            &cfg,
            &sim.imu,
            sim.start,
            &aid,
            Some(&sim.truth),
            |_| {},
            &mut |_| {},
            &mut seen_full,
        );
        let mut seen_replay = Log::default();
        let mut truth = sinsmodel::io::truth::TruthSlice::new(&sim.truth);
        let replay = filter::run_replay(
            &model,
            &cfg,
            &tape,
            &aid,
            Some(&mut truth),
            |_| {},
            &mut seen_replay,
            true,
        )
        .unwrap();
        assert!(full.records.len() > 100 && full.innovations.len() > 100);
        assert_eq!(format!("{full:?}"), format!("{replay:?}"), "{name}");
        assert_eq!(seen_full.lines.len(), seen_replay.lines.len(), "{name}");
        for (a, b) in seen_full.lines.iter().zip(&seen_replay.lines) {
            assert_eq!(a, b, "{name}");
        }
    }
}

#[test]
fn no_tape_where_the_navigation_would_differ() {
    let (sim, aid) = data();
    let model = Model::parse("P31").unwrap();
    let cfg = config(&model);
    // closed loop: the navigation depends on the filter
    let mut closed = cfg.clone();
    closed.mode = Mode::ClosedLoop;
    assert!(TapeRecorder::new(&closed, &sim.start, &aid).is_none());
    let tape = record(&model, &sim, &aid);
    assert!(tape.fits(&cfg, &sim.start, &aid));
    assert!(!tape.fits(&closed, &sim.start, &aid));
    let mut other_step = cfg.clone();
    other_step.step_s *= 2.0;
    assert!(!tape.fits(&other_step, &sim.start, &aid));
    let mut other_vertical = cfg.clone();
    other_vertical.vertical = match cfg.vertical {
        Vertical::Damped => Vertical::Free,
        _ => Vertical::Damped,
    };
    assert!(!tape.fits(&other_vertical, &sim.start, &aid));
    // an epoch moved (a re-stamped GNSS) ends its steps elsewhere
    let mut moved = aid.clone();
    moved[3].t += 0.005;
    assert!(!tape.fits(&cfg, &sim.start, &moved));
    assert!(!tape.fits(&cfg, &sim.start, &aid[1..]));
    let mut start = sim.start;
    start.h += 1e-9;
    assert!(!tape.fits(&cfg, &start, &aid));
    // and a replay it does not fit is refused, not run
    let err = filter::run_replay(
        &model,
        &cfg,
        &tape,
        &moved,
        None,
        |_| {},
        &mut filter::NoObserver,
        false,
    )
    .unwrap_err();
    assert!(err.to_string().contains("not recorded for"), "{err}");
}

/// explain-eval's cases (explain's passes and the oracle's) give the same answers, to the bit,
/// with the passes sharing one navigation and with every pass navigating.
#[test]
fn explain_answers_the_same_with_and_without_the_tape() {
    use sinsmodel::experiment::explain_eval::{default_options, prepare, EvalSpec};
    use sinsmodel::experiment::hidden::run_hidden_on;
    let spec = EvalSpec {
        seed: 3,
        seconds: 300.0,
        groups: ["d", "kas", "size", "gnss_lever"]
            .iter()
            .map(|g| g.to_string())
            .collect(),
        ..EvalSpec::default()
    };
    let mut named = 0;
    for index in 0..4 {
        let (_, (case, sim, aid)) = prepare(&spec, index).unwrap();
        let mut opts = default_options();
        let shared = run_hidden_on(&case, &sim, &aid, &opts).unwrap();
        opts.share_navigation = false;
        let alone = run_hidden_on(&case, &sim, &aid, &opts).unwrap();
        let text = |o: &sinsmodel::experiment::hidden::HiddenOutcome| {
            format!(
                "{:?} {:?} {:?} {:?}",
                o.explanation, o.oracle_loglik, o.oracle_model_error_rms, o.oracle_estimates
            )
        };
        assert_eq!(text(&shared), text(&alone), "case {index}");
        named += shared.explanation.findings.len();
    }
    // (cases that name nothing would compare little)
    assert!(named > 0);
}
