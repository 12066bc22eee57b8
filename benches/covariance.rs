//! P ← Φ P Φᵀ + Q for P31: the generated sparse kernel against dense nalgebra SMatrix<f64,31,31>
//! on the same input (Φ = I + A dt + A² dt²/2 formed in both), and the run-time sparse path.
//! Run: `cargo bench --bench covariance`; the ratio dense/generated is the figure of merit.

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use nalgebra::{SMatrix, Vector3};
use sinsmodel::model::covariance::SparsePropagator;
use sinsmodel::model::generated::p31;
use sinsmodel::nav::attitude::dcm_from_euler;
use sinsmodel::nav::nav_point::NavPoint;

type M31 = SMatrix<f64, 31, 31>;

fn inputs() -> ([[f64; 31]; 31], [[f64; 31]; 31], [f64; 31]) {
    let c = dcm_from_euler(0.01, -0.02, 0.3);
    let f = Vector3::new(0.1, -0.2, -9.79);
    let nav = NavPoint::new(0.4925, 50.0, Vector3::new(1.0, -2.0, 0.1), &c, &f);
    let mut acc = p31::Regressors::default();
    acc.add(&sinsmodel::model::ImuSignals::new(
        f,
        Vector3::new(1e-3, -2e-3, 5e-4),
    ));
    let mut a = [[0.0; 31]; 31];
    p31::fill_a(&nav, &acc.mean(), &mut a);
    let mut p = [[0.0; 31]; 31];
    for (i, row) in p.iter_mut().enumerate() {
        for (j, v) in row.iter_mut().enumerate() {
            *v = if i == j {
                1.0 + i as f64 * 0.1
            } else {
                0.01 / (1.0 + (i as f64 - j as f64).abs())
            };
        }
    }
    let q = [1e-6; 31];
    (a, p, q)
}

fn dense_propagate(a: &M31, p: &M31, q: &[f64; 31], dt: f64) -> M31 {
    let phi = M31::identity() + a * dt + (a * a) * (0.5 * dt * dt);
    let mut out = phi * p * phi.transpose();
    for i in 0..31 {
        out[(i, i)] += q[i] * dt;
    }
    out
}

fn bench(c: &mut Criterion) {
    let (a, p, q) = inputs();
    let dt = 0.01;
    let am = M31::from_fn(|i, j| a[i][j]);
    let pm = M31::from_fn(|i, j| p[i][j]);
    let mut g = c.benchmark_group("p31_covariance_propagation");
    g.bench_function("generated_sparse", |b| {
        b.iter(|| {
            let mut pp = p;
            p31::propagate_cov(black_box(&a), dt, &q, &mut pp);
            black_box(pp)
        })
    });
    g.bench_function("dense_nalgebra_smatrix", |b| {
        b.iter(|| black_box(dense_propagate(black_box(&am), &pm, &q, dt)))
    });
    g.bench_function("generated_fill_b_only", |b| {
        b.iter(|| {
            let mut bb = [[0.0; 31]; p31::ND];
            p31::fill_b(black_box(&a), dt, &mut bb);
            black_box(bb)
        })
    });
    let flat_a: Vec<f64> = a.iter().flatten().copied().collect();
    let flat_p: Vec<f64> = p.iter().flatten().copied().collect();
    let mut prop = SparsePropagator::new(31, &p31::A_PATTERN);
    g.bench_function("runtime_sparse", |b| {
        b.iter(|| {
            let mut pp = flat_p.clone();
            prop.propagate(black_box(&flat_a), dt, &q, &mut pp);
            black_box(pp)
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
