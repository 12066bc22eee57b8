//! Model layouts (DESIGN §3), preset kernels against run-time composition, covariance kernels
//! against a dense reference, and the regressor accumulator.

use nalgebra::{DMatrix, Vector3};
use sinsmodel::model::covariance::{propagate_dense, SparsePropagator};
use sinsmodel::model::generated::PRESETS;
use sinsmodel::model::{ImuSignals, Model};
use sinsmodel::nav::attitude::dcm_from_euler;
use sinsmodel::nav::nav_point::NavPoint;

/// Small deterministic generator (xorshift) so the tests need no extra crate.
struct Rng(u64);
impl Rng {
    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        lo + (hi - lo) * ((self.0 >> 11) as f64 / (1u64 << 53) as f64)
    }
}

fn random_point(rng: &mut Rng) -> (NavPoint, Vector3<f64>, Vector3<f64>) {
    let c = dcm_from_euler(
        rng.uniform(-3.1, 3.1),
        rng.uniform(-1.5, 1.5),
        rng.uniform(-3.1, 3.1),
    );
    let f = Vector3::new(
        rng.uniform(-50.0, 50.0),
        rng.uniform(-50.0, 50.0),
        rng.uniform(-50.0, 50.0),
    );
    let w = Vector3::new(
        rng.uniform(-2.0, 2.0),
        rng.uniform(-2.0, 2.0),
        rng.uniform(-2.0, 2.0),
    );
    let v = Vector3::new(
        rng.uniform(-300.0, 300.0),
        rng.uniform(-300.0, 300.0),
        rng.uniform(-30.0, 30.0),
    );
    let nav = NavPoint::new(
        rng.uniform(-1.4, 1.4),
        rng.uniform(-100.0, 9000.0),
        v,
        &c,
        &f,
    );
    (nav, f, w)
}

const P13: [&str; 13] = [
    "phi_n", "phi_e", "phi_d", "dv_n", "dv_e", "dlat", "dlon", "eps_x", "eps_y", "eps_z",
    "nabla_x", "nabla_y", "nabla_z",
];
const KG: [&str; 6] = ["kg_11", "kg_21", "kg_31", "kg_22", "kg_32", "kg_33"];
const KA: [&str; 9] = [
    "ka_11", "ka_21", "ka_31", "ka_12", "ka_22", "ka_32", "ka_13", "ka_23", "ka_33",
];

#[test]
fn presets_have_the_design_state_lists() {
    let p13 = Model::parse("P13").unwrap();
    assert_eq!(p13.names, P13);
    let p28 = Model::parse("P28").unwrap();
    let want28: Vec<&str> = P13
        .iter()
        .chain(KG.iter())
        .chain(KA.iter())
        .copied()
        .collect();
    assert_eq!(p28.names, want28);
    let p31 = Model::parse("P31").unwrap();
    let want31: Vec<&str> = want28
        .iter()
        .copied()
        .chain(["d_x", "d_y", "d_z"])
        .collect();
    assert_eq!(p31.names, want31);
    let p24 = Model::parse("P24").unwrap();
    let want24: Vec<&str> = want28
        .iter()
        .copied()
        .filter(|s| !["nabla_z", "ka_31", "ka_32", "ka_33"].contains(s))
        .collect();
    assert_eq!(p24.names, want24);
    assert_eq!([p13.n(), p24.n(), p28.n(), p31.n()], [13, 24, 28, 31]);
    let v = Model::parse("P31+vertical").unwrap();
    assert_eq!(v.n(), 33);
    assert_eq!(
        &v.names[..9],
        ["phi_n", "phi_e", "phi_d", "dv_n", "dv_e", "dv_d", "dlat", "dlon", "dh"]
    );
}

#[test]
fn model_syntax_and_its_errors() {
    let m = Model::parse("P28+kaq_x_xy+kgf_xz").unwrap();
    assert_eq!(m.n(), 30);
    assert_eq!(&m.names[28..], ["kaq_x_xy", "kgf_xz"]);
    assert!(m.preset.is_none());
    assert!(Model::parse("P31").unwrap().preset.is_some());
    for (bad, needle) in [
        ("P99", "unknown preset `P99`"),
        ("P28+kaq_q_xy", "unknown term `kaq_q_xy`"),
        ("P31+d_x", "already in P31"),
        ("P28+kas_x+kas_x", "given twice"),
        ("P28+vertical+vertical", "given twice"),
    ] {
        let e = Model::parse(bad).unwrap_err().to_string();
        assert!(e.contains(needle), "{bad}: {e}");
    }
}

/// The generated preset kernels and run-time composition give identical A and H, bit for bit,
/// for every preset with and without the vertical channel.
#[test]
fn preset_path_equals_runtime_path() {
    let mut rng = Rng(0x9e3779b97f4a7c15);
    for k in PRESETS {
        let m = Model::parse(k.name).unwrap();
        assert!(m.preset.is_some(), "{} resolves to its kernels", k.name);
        let runtime_pattern: Vec<(usize, usize)> = m.a_pattern().to_vec();
        assert_eq!(runtime_pattern, k.a_pattern, "{} pattern", k.name);
        let n = m.n();
        for _ in 0..50 {
            let (nav, f, w) = random_point(&mut rng);
            let mut acc = m.accumulator();
            let sig = ImuSignals {
                f,
                w,
                dw: w.cross(&f) * 0.7,
                df: f.cross(&w) * -1.3,
            };
            acc.add(&sig);
            acc.add(&ImuSignals {
                f: f * 0.5,
                w: w * -0.3,
                dw: sig.dw * 1.9,
                df: sig.df * 0.4,
            });
            let r = acc.mean();
            let mut a1 = vec![0.0; n * n];
            let mut a2 = vec![0.0; n * n];
            m.fill_a(&nav, &r, &mut a1);
            m.fill_a_runtime(&nav, &r, &mut a2);
            assert_eq!(a1, a2, "{} A", k.name);
            for meas in m.measurements() {
                let rows = meas.rows.len();
                let mut h1 = vec![0.0; rows * n];
                let mut h2 = vec![0.0; rows * n];
                m.fill_h(meas.name, &nav, &mut h1).unwrap();
                m.fill_h_runtime(meas.name, &nav, &mut h2).unwrap();
                assert_eq!(h1, h2, "{} H {}", k.name, meas.name);
            }
        }
    }
}

/// The run-time composition writes every entry of A's pattern and nothing else, so the filter
/// leaves A unzeroed between steps on that path: over an A full of NaN the pattern comes out
/// as over a zeroed one, and every other entry is untouched.
#[test]
fn runtime_composition_writes_the_whole_pattern_and_nothing_else() {
    let mut rng = Rng(0x2545f4914f6cdd1d);
    for name in [
        "P13+vertical+kg_11+kg_22+kg_33+ka_11+ka_22+ka_33",
        "P28+kaq_x_xy+kgf_xz",
        "P31+vertical",
        "P13+dt_gnss+lever_x+lever_y+tau_x",
    ] {
        let m = Model::parse(name).unwrap().runtime_only();
        assert!(m.fill_a_writes_whole_pattern(), "{name}");
        let n = m.n();
        for _ in 0..20 {
            let (nav, f, w) = random_point(&mut rng);
            let mut acc = m.accumulator();
            acc.add(&ImuSignals {
                f,
                w,
                dw: w.cross(&f),
                df: f.cross(&w),
            });
            let r = acc.mean();
            let mut zeroed = vec![0.0; n * n];
            m.fill_a_runtime(&nav, &r, &mut zeroed);
            let mut over = vec![f64::NAN; n * n];
            m.fill_a_runtime(&nav, &r, &mut over);
            let pattern: std::collections::HashSet<usize> =
                m.a_pattern().iter().map(|&(i, j)| i * n + j).collect();
            for k in 0..n * n {
                if pattern.contains(&k) {
                    assert_eq!(over[k].to_bits(), zeroed[k].to_bits(), "{name} entry {k}");
                } else {
                    assert!(over[k].is_nan(), "{name}: entry {k} is off the pattern");
                }
            }
        }
    }
    // a preset's kernel gets a zeroed A
    assert!(!Model::parse("P31").unwrap().fill_a_writes_whole_pattern());
}

#[test]
fn measurement_support_follows_the_states() {
    let m = Model::parse("P31").unwrap();
    let names: Vec<_> = m.measurements().iter().map(|x| x.name).collect();
    // (an attitude reference's rows reference the attitude errors only)
    assert_eq!(names, ["vel_ne", "pos_ne", "att_ref"]);
    let mut h = vec![0.0; 33];
    let e = m
        .fill_h("pos_h", &random_point(&mut Rng(3)).0, &mut h)
        .unwrap_err();
    assert!(e.to_string().contains("needs state `dh`"), "{e}");
    // with the vertical channel: the height, and a body-frame velocity reference (its rows
    // reference dv_d)
    let v = Model::parse("P31+vertical").unwrap();
    let names: Vec<_> = v.measurements().iter().map(|x| x.name).collect();
    assert_eq!(names, ["vel_ne", "pos_ne", "pos_h", "vel_body", "att_ref"]);
}

/// Generated sparse kernel, run-time sparse propagation and dense Φ P Φᵀ + Q agree.
#[test]
fn covariance_kernels_match_dense_reference() {
    let mut rng = Rng(77);
    for name in [
        "P13",
        "P24",
        "P28",
        "P31",
        "P31+vertical",
        "P28+kaq_x_xy+kgf_xz+size_z",
    ] {
        let m = Model::parse(name).unwrap();
        let n = m.n();
        let (nav, f, w) = random_point(&mut rng);
        let mut acc = m.accumulator();
        acc.add(&ImuSignals::new(f, w));
        let mut a = vec![0.0; n * n];
        m.fill_a(&nav, &acc.mean(), &mut a);
        // a random symmetric positive definite P
        let l = DMatrix::from_fn(n, n, |_, _| rng.uniform(-1.0, 1.0));
        let p0 = &l * l.transpose() + DMatrix::identity(n, n);
        let q: Vec<f64> = (0..n).map(|_| rng.uniform(0.0, 1e-3)).collect();
        let dt = 0.01;
        let dense = propagate_dense(&DMatrix::from_row_slice(n, n, &a), dt, &q, &p0);
        let mut p_rt: Vec<f64> = p0.transpose().as_slice().to_vec();
        SparsePropagator::new(n, m.a_pattern()).propagate(&a, dt, &q, &mut p_rt);
        let scale = dense.amax();
        let check = |p: &[f64], what: &str| {
            let got = DMatrix::from_row_slice(n, n, p);
            let err = (&got - &dense).amax() / scale;
            assert!(err < 1e-13, "{name} {what}: relative error {err:e}");
        };
        check(&p_rt, "runtime");
        if let Some(k) = m.preset {
            let mut p_gen: Vec<f64> = p0.transpose().as_slice().to_vec();
            (k.propagate_cov)(&a, dt, &q, &mut p_gen);
            check(&p_gen, "generated");
            // the run-time path does the generated kernel's arithmetic: the same bits
            let bits = |p: &[f64]| p.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
            assert!(
                bits(&p_rt) == bits(&p_gen),
                "{name}: run-time P differs in bits"
            );
        }
    }
}

/// DESIGN §2: the step mean of f² is the mean of squares (≈ A²/2 under a sine), never the square
/// of the mean (≈ 0), which would silently turn P31 into P28.
#[test]
fn accumulator_uses_mean_of_squares() {
    let m = Model::parse("P31").unwrap();
    let k = m
        .regressor_ids
        .iter()
        .position(|&r| sinsmodel::model::generated::common::REGRESSORS[r] == "f.x.powi(2)")
        .unwrap();
    let kx = m
        .regressor_ids
        .iter()
        .position(|&r| sinsmodel::model::generated::common::REGRESSORS[r] == "f.x")
        .unwrap();
    let mut acc = m.accumulator();
    let amp = 6.0 * 9.80665;
    let samples = 2000;
    for i in 0..samples {
        let fx = amp * (2.0 * std::f64::consts::PI * i as f64 / 20.0).cos();
        acc.add(&ImuSignals::new(
            Vector3::new(fx, 0.0, -9.8),
            Vector3::zeros(),
        ));
    }
    let r = acc.mean();
    assert!(
        (r[k] - amp * amp / 2.0).abs() < 1e-9 * amp * amp,
        "<f_x^2> = {}",
        r[k]
    );
    assert!(r[kx].abs() < 1e-9 * amp, "<f_x> = {}", r[kx]);
}

/// The all-at-once regressor evaluation (run-time accumulators of many regressors) gives each
/// regressor's own value to the bit.
#[test]
fn every_regressor_at_once_equals_each_alone() {
    use sinsmodel::model::generated::common;
    let mut rng = Rng(91);
    for _ in 0..200 {
        let (_, f, w) = random_point(&mut rng);
        let mut s = ImuSignals::new(f, w);
        s.dw = w * rng.uniform(-3.0, 3.0);
        s.df = f * rng.uniform(-3.0, 3.0);
        let mut all = [0.0; common::REGRESSOR_COUNT];
        common::regressor_values(&s, &mut all);
        for (id, v) in all.iter().enumerate() {
            assert_eq!(
                v.to_bits(),
                common::regressor_value(id, &s).to_bits(),
                "{id}"
            );
        }
    }
}
