//! Covariance propagation P ← Φ P Φᵀ + diag(q)·dt with Φ = I + A·dt + A²·dt²/2, for models
//! composed at run time (the presets use their generated kernels), and a dense reference.

use nalgebra::DMatrix;

/// Sparse propagation with a run-time pattern (row-major (i, j) list of A's non-zeros).
#[derive(Debug, Clone)]
pub struct SparsePropagator {
    n: usize,
    dyn_rows: Vec<usize>,
    a_rows: Vec<Vec<usize>>,
    b_cols: Vec<Vec<usize>>,
}

impl SparsePropagator {
    /// Builds the structure of B = Φ − I from A's pattern.
    pub fn new(n: usize, a_pattern: &[(usize, usize)]) -> SparsePropagator {
        let mut a_rows = vec![Vec::new(); n];
        for &(i, j) in a_pattern {
            a_rows[i].push(j);
        }
        let dyn_rows: Vec<usize> = (0..n).filter(|&i| !a_rows[i].is_empty()).collect();
        let b_cols = dyn_rows
            .iter()
            .map(|&i| {
                let mut cols: Vec<usize> = a_rows[i].clone();
                for &k in &a_rows[i] {
                    cols.extend(a_rows[k].iter().copied());
                }
                cols.sort_unstable();
                cols.dedup();
                cols
            })
            .collect();
        SparsePropagator {
            n,
            dyn_rows,
            a_rows,
            b_cols,
        }
    }

    /// Number of structural non-zeros of B = Φ − I.
    pub fn b_nnz(&self) -> usize {
        self.b_cols.iter().map(Vec::len).sum()
    }

    /// P ← Φ P Φᵀ + diag(q)·dt; `a`, `p` n×n row-major, `q` [SI²/s], `dt` [s].
    pub fn propagate(&self, a: &[f64], dt: f64, q: &[f64], p: &mut [f64]) {
        self.propagate_with_state(a, dt, q, p, None)
    }

    /// [`SparsePropagator::propagate`] and, when given, x ← Φ x with the same Φ.
    pub fn propagate_with_state(
        &self,
        a: &[f64],
        dt: f64,
        q: &[f64],
        p: &mut [f64],
        x: Option<&mut [f64]>,
    ) {
        let n = self.n;
        let nd = self.dyn_rows.len();
        let half_dt2 = 0.5 * dt * dt;
        let mut b = vec![0.0; nd * n];
        for (r, &i) in self.dyn_rows.iter().enumerate() {
            for &j in &self.b_cols[r] {
                let mut second = 0.0;
                for &k in &self.a_rows[i] {
                    second += a[i * n + k] * a[k * n + j];
                }
                b[r * n + j] = a[i * n + j] * dt + half_dt2 * second;
            }
        }
        if let Some(x) = x {
            let dx: Vec<f64> = (0..nd)
                .map(|r| self.b_cols[r].iter().map(|&k| b[r * n + k] * x[k]).sum())
                .collect();
            for (r, &i) in self.dyn_rows.iter().enumerate() {
                x[i] += dx[r];
            }
        }
        let mut m = vec![0.0; nd * n];
        for r in 0..nd {
            let mr = &mut m[r * n..(r + 1) * n];
            for &k in &self.b_cols[r] {
                let bk = b[r * n + k];
                for (mj, pj) in mr.iter_mut().zip(&p[k * n..(k + 1) * n]) {
                    *mj += bk * pj;
                }
            }
        }
        for r in 0..nd {
            let i = self.dyn_rows[r];
            for s in 0..nd {
                let mut v = 0.0;
                for &k in &self.b_cols[s] {
                    v += m[r * n + k] * b[s * n + k];
                }
                p[i * n + self.dyn_rows[s]] += v;
            }
            for j in 0..n {
                p[i * n + j] += m[r * n + j];
                p[j * n + i] += m[r * n + j];
            }
        }
        for i in 0..n {
            p[i * n + i] += q[i] * dt;
        }
    }
}

/// Dense Φ = I + A dt + A² dt²/2.
pub fn dense_phi(a: &DMatrix<f64>, dt: f64) -> DMatrix<f64> {
    let n = a.nrows();
    DMatrix::<f64>::identity(n, n) + a * dt + (a * a) * (0.5 * dt * dt)
}

/// Dense reference: Φ = I + A dt + A² dt²/2, P ← Φ P Φᵀ + diag(q)·dt.
pub fn propagate_dense(a: &DMatrix<f64>, dt: f64, q: &[f64], p: &DMatrix<f64>) -> DMatrix<f64> {
    propagate_dense_with_state(a, dt, q, p, None)
}

/// [`propagate_dense`] and, when given, x ← Φ x with the same dense Φ.
pub fn propagate_dense_with_state(
    a: &DMatrix<f64>,
    dt: f64,
    q: &[f64],
    p: &DMatrix<f64>,
    x: Option<&mut [f64]>,
) -> DMatrix<f64> {
    let phi = dense_phi(a, dt);
    if let Some(x) = x {
        let xv = &phi * nalgebra::DVector::from_column_slice(x);
        x.copy_from_slice(xv.as_slice());
    }
    let mut out = &phi * p * phi.transpose();
    for i in 0..a.nrows() {
        out[(i, i)] += q[i] * dt;
    }
    out
}
