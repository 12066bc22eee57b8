//! Covariance propagation P ← Φ P Φᵀ + diag(q)·dt with Φ = I + A·dt + A²·dt²/2, for models
//! composed at run time (the presets use their generated kernels), and a dense reference.

use nalgebra::DMatrix;

/// Sparse propagation with a run-time pattern (row-major (i, j) list of A's non-zeros).
#[derive(Debug, Clone)]
pub struct SparsePropagator {
    n: usize,
    dyn_rows: Vec<usize>,
    b_cols: Vec<Vec<usize>>,
    /// Every structural non-zero of B: (dynamic row r, row i of A, column j, direct A entry,
    /// range into `ks` of the k with A[i][k]·A[k][j] structurally non-zero).
    b_entries: Vec<(usize, usize, usize, bool, std::ops::Range<usize>)>,
    ks: Vec<usize>,
    /// Scratch: B = Φ − I on the dynamic rows (nd × n), kept between steps (no allocation).
    b: Vec<f64>,
    /// Scratch: M = B P (nd × n).
    m: Vec<f64>,
    /// Scratch: B x (nd).
    dx: Vec<f64>,
}

impl SparsePropagator {
    /// Builds the structure of B = Φ − I from A's pattern.
    pub fn new(n: usize, a_pattern: &[(usize, usize)]) -> SparsePropagator {
        let mut a_rows = vec![Vec::new(); n];
        for &(i, j) in a_pattern {
            a_rows[i].push(j);
        }
        let dyn_rows: Vec<usize> = (0..n).filter(|&i| !a_rows[i].is_empty()).collect();
        let b_cols: Vec<Vec<usize>> = dyn_rows
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
        let nd = dyn_rows.len();
        let has = |i: usize, j: usize| a_rows[i].contains(&j);
        let mut b_entries = Vec::new();
        let mut ks = Vec::new();
        for (r, &i) in dyn_rows.iter().enumerate() {
            for &j in &b_cols[r] {
                let start = ks.len();
                ks.extend(a_rows[i].iter().copied().filter(|&k| has(k, j)));
                b_entries.push((r, i, j, has(i, j), start..ks.len()));
            }
        }
        SparsePropagator {
            n,
            dyn_rows,
            b_cols,
            b_entries,
            ks,
            b: vec![0.0; nd * n],
            m: vec![0.0; nd * n],
            dx: vec![0.0; nd],
        }
    }

    /// Number of structural non-zeros of B = Φ − I.
    pub fn b_nnz(&self) -> usize {
        self.b_cols.iter().map(Vec::len).sum()
    }

    /// P ← Φ P Φᵀ + diag(q)·dt; `a`, `p` n×n row-major, `q` [SI²/s], `dt` [s].
    pub fn propagate(&mut self, a: &[f64], dt: f64, q: &[f64], p: &mut [f64]) {
        self.propagate_with_state(a, dt, q, p, None)
    }

    /// [`SparsePropagator::propagate`] and, when given, x ← Φ x with the same Φ. Works in the
    /// propagator's own scratch buffers: no allocation per step. Uses AVX2 when the CPU has it
    /// (same arithmetic, wider registers), like the generated kernels.
    pub fn propagate_with_state(
        &mut self,
        a: &[f64],
        dt: f64,
        q: &[f64],
        p: &mut [f64],
        x: Option<&mut [f64]>,
    ) {
        #[cfg(target_arch = "x86_64")]
        {
            if std::arch::is_x86_feature_detected!("avx2") {
                // SAFETY: the CPU supports AVX2, checked just above.
                unsafe { self.propagate_avx2(a, dt, q, p, x) };
                return;
            }
        }
        self.propagate_body(a, dt, q, p, x)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn propagate_avx2(
        &mut self,
        a: &[f64],
        dt: f64,
        q: &[f64],
        p: &mut [f64],
        x: Option<&mut [f64]>,
    ) {
        self.propagate_body(a, dt, q, p, x)
    }

    #[inline(always)]
    fn propagate_body(
        &mut self,
        a: &[f64],
        dt: f64,
        q: &[f64],
        p: &mut [f64],
        x: Option<&mut [f64]>,
    ) {
        let n = self.n;
        self.fill_b(a, dt);
        if let Some(x) = x {
            let (b, dx) = (&self.b, &mut self.dx);
            for (r, d) in dx.iter_mut().enumerate() {
                *d = self.b_cols[r].iter().map(|&k| b[r * n + k] * x[k]).sum();
            }
            for (r, &i) in self.dyn_rows.iter().enumerate() {
                x[i] += dx[r];
            }
        }
        self.sandwich(p);
        for i in 0..n {
            p[i * n + i] += q[i] * dt;
        }
    }

    /// B = Φ − I = A·dt + A²·dt²/2 on the dynamic rows, into the scratch `b`.
    #[inline(always)]
    fn fill_b(&mut self, a: &[f64], dt: f64) {
        let n = self.n;
        let half_dt2 = 0.5 * dt * dt;
        let b = &mut self.b;
        for (r, i, j, direct, ks) in &self.b_entries {
            let (i, j) = (*i, *j);
            let mut second = 0.0;
            for &k in &self.ks[ks.clone()] {
                second += a[i * n + k] * a[k * n + j];
            }
            let first = if *direct { a[i * n + j] * dt } else { 0.0 };
            b[r * n + j] = first + half_dt2 * second;
        }
    }

    /// M = B P into the scratch `m` (P n×n row-major, B from [`Self::fill_b`]).
    #[inline(always)]
    fn b_times(&mut self, p: &[f64]) {
        let n = self.n;
        let (b, m) = (&self.b, &mut self.m);
        for (r, cols) in self.b_cols.iter().enumerate() {
            let mr = &mut m[r * n..(r + 1) * n];
            mr.iter_mut().for_each(|v| *v = 0.0);
            for &k in cols {
                let bk = b[r * n + k];
                for (mj, pj) in mr.iter_mut().zip(&p[k * n..(k + 1) * n]) {
                    *mj += bk * pj;
                }
            }
        }
    }

    /// P ← Φ P Φᵀ = P + B P + (B P)ᵀ + B P Bᵀ, with B from [`Self::fill_b`].
    #[inline(always)]
    fn sandwich(&mut self, p: &mut [f64]) {
        let n = self.n;
        self.b_times(p);
        let (b, m) = (&self.b, &self.m);
        for (r, &i) in self.dyn_rows.iter().enumerate() {
            let mr = &m[r * n..(r + 1) * n];
            for (s, &js) in self.dyn_rows.iter().enumerate() {
                // dense dot over the row (B is zero off its pattern) in four partial sums
                p[i * n + js] += dot4(mr, &b[s * n..(s + 1) * n]);
            }
            for (j, &mj) in mr.iter().enumerate() {
                p[i * n + j] += mj;
                p[j * n + i] += mj;
            }
        }
    }

    /// Rows of A that are not all zero (the rows Φ − I can change).
    pub fn dyn_rows(&self) -> &[usize] {
        &self.dyn_rows
    }

    /// One step of a replay interval (see `estimate::replay`): Ψ ← Φ Ψ and, for each noise
    /// group k, G_k ← Φ G_k Φᵀ + diag(q_k)·dt, with Φ = I + A·dt + A²·dt²/2 as in
    /// [`Self::propagate`]; every matrix n×n row-major, `a` [1/s], `dt` [s], `q_k` [SI²/s].
    pub fn accumulate(
        &mut self,
        a: &[f64],
        dt: f64,
        q: &[Vec<f64>],
        g: &mut [Vec<f64>],
        psi: &mut [f64],
    ) {
        #[cfg(target_arch = "x86_64")]
        {
            if std::arch::is_x86_feature_detected!("avx2") {
                // SAFETY: the CPU supports AVX2, checked just above.
                unsafe { self.accumulate_avx2(a, dt, q, g, psi) };
                return;
            }
        }
        self.accumulate_body(a, dt, q, g, psi)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn accumulate_avx2(
        &mut self,
        a: &[f64],
        dt: f64,
        q: &[Vec<f64>],
        g: &mut [Vec<f64>],
        psi: &mut [f64],
    ) {
        self.accumulate_body(a, dt, q, g, psi)
    }

    #[inline(always)]
    fn accumulate_body(
        &mut self,
        a: &[f64],
        dt: f64,
        q: &[Vec<f64>],
        g: &mut [Vec<f64>],
        psi: &mut [f64],
    ) {
        let n = self.n;
        self.fill_b(a, dt);
        for (gk, qk) in g.iter_mut().zip(q) {
            self.sandwich(gk);
            for i in 0..n {
                gk[i * n + i] += qk[i] * dt;
            }
        }
        // Ψ ← Ψ + B Ψ
        self.b_times(psi);
        for (r, &i) in self.dyn_rows.iter().enumerate() {
            for (pj, mj) in psi[i * n..(i + 1) * n].iter_mut().zip(&self.m[r * n..]) {
                *pj += mj;
            }
        }
    }
}

/// Dot product in four interleaved partial sums (vectorises).
#[inline]
fn dot4(a: &[f64], b: &[f64]) -> f64 {
    let mut lanes = [0.0; 4];
    let (ca, cb) = (a.chunks_exact(4), b.chunks_exact(4));
    let (ra, rb) = (ca.remainder(), cb.remainder());
    for (x, y) in ca.zip(cb) {
        for l in 0..4 {
            lanes[l] += x[l] * y[l];
        }
    }
    let mut v = (lanes[0] + lanes[1]) + (lanes[2] + lanes[3]);
    for (x, y) in ra.iter().zip(rb) {
        v += x * y;
    }
    v
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
