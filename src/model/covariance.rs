//! Covariance propagation P ← Φ P Φᵀ + diag(q)·dt with Φ = I + A·dt + A²·dt²/2, for models
//! composed at run time (the presets use their generated kernels), and a dense reference.
//!
//! The run-time kernel is written once, generic over the row length: a model of up to 64
//! states (the widths `by_width!` lists) runs a copy compiled for its own width (loops of known length,
//! unrolled and vectorised like the generated kernels), a larger one the same code with the width
//! read at run time. Every copy performs the same floating-point operations in the same order,
//! so the results do not depend on which one ran.

use nalgebra::DMatrix;

/// Sparse propagation with a run-time pattern (row-major (i, j) list of A's non-zeros).
#[derive(Debug, Clone)]
pub struct SparsePropagator {
    n: usize,
    dyn_rows: Vec<usize>,
    b_cols: Vec<Vec<usize>>,
    /// B's structural non-zeros, grouped by their number of second-order products.
    fill: Vec<FillGroup>,
    /// Scratch: B = Φ − I on the dynamic rows (nd × n), kept between steps (no allocation).
    b: Vec<f64>,
    /// Scratch: M = B P (nd × n).
    m: Vec<f64>,
    /// Scratch: Bᵀ (n × nd rounded up to a multiple of 4; zero off B's pattern), filled with B.
    bt: Vec<f64>,
    /// Scratch: B x (nd).
    dx: Vec<f64>,
}

/// Calls `$self.$method::<W>($args…)` with W the model's width when a copy is compiled for it,
/// else W = 0 (the width read at run time).
macro_rules! by_width {
    ($self:ident . $method:ident ( $($arg:expr),* )) => {
        by_width!(@arms $self, $method, ($($arg),*);
            1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17 18 19 20 21 22 23 24 25 26 27 28 29 30 31
            32 33 34 35 36 37 38 39 40 41 42 43 44 45 46 47 48 49 50 51 52 53 54 55 56 57 58 59
            60 61 62 63 64)
    };
    (@arms $self:ident, $method:ident, $args:tt; $($w:literal)*) => {
        match $self.n {
            $( $w => by_width!(@call $self, $method, $w, $args), )*
            _ => by_width!(@call $self, $method, 0, $args),
        }
    };
    (@call $self:ident, $method:ident, $w:literal, ($($arg:expr),*)) => {
        $self.$method::<$w>($($arg),*)
    };
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
        let mut fill: Vec<FillGroup> = Vec::new();
        for (r, &i) in dyn_rows.iter().enumerate() {
            for &j in &b_cols[r] {
                let ks: Vec<usize> = a_rows[i].iter().copied().filter(|&k| has(k, j)).collect();
                let g = match fill.iter().position(|g| g.len == ks.len()) {
                    Some(g) => g,
                    None => {
                        fill.push(FillGroup {
                            len: ks.len(),
                            targets: Vec::new(),
                            pairs: Vec::new(),
                        });
                        fill.len() - 1
                    }
                };
                let direct = has(i, j).then_some(i * n + j);
                fill[g].targets.push((r * n + j, direct));
                fill[g]
                    .pairs
                    .extend(ks.iter().map(|&k| (i * n + k, k * n + j)));
            }
        }
        SparsePropagator {
            n,
            dyn_rows,
            b_cols,
            fill,
            b: vec![0.0; nd * n],
            m: vec![0.0; nd * n],
            bt: vec![0.0; n * nd.div_ceil(4) * 4],
            dx: vec![0.0; nd],
        }
    }

    /// Number of structural non-zeros of B = Φ − I.
    pub fn b_nnz(&self) -> usize {
        self.b_cols.iter().map(Vec::len).sum()
    }

    /// Multiply-adds of one [`Self::propagate`] (B's second-order products, M = B P, the four
    /// columns of B P Bᵀ at a time; the adds of P + M + Mᵀ not counted).
    pub fn mul_adds(&self) -> usize {
        let n = self.n;
        let products: usize = self.fill.iter().map(|g| g.pairs.len()).sum();
        let nd4 = self.dyn_rows.len().div_ceil(4) * 4;
        products + self.b_nnz() * n + self.dyn_rows.len() * nd4 * n
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
        let n = self.n;
        assert!(
            a.len() == n * n && p.len() == n * n && q.len() == n,
            "sizes of A, P, q"
        );
        by_width!(self.propagate_width(a, dt, q, p, x))
    }

    /// [`Self::propagate_with_state`] for rows of `W` states (0: `self.n`, read at run time).
    fn propagate_width<const W: usize>(
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
                unsafe { self.propagate_avx2::<W>(a, dt, q, p, x) };
                return;
            }
        }
        self.propagate_body::<W>(a, dt, q, p, x)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn propagate_avx2<const W: usize>(
        &mut self,
        a: &[f64],
        dt: f64,
        q: &[f64],
        p: &mut [f64],
        x: Option<&mut [f64]>,
    ) {
        self.propagate_body::<W>(a, dt, q, p, x)
    }

    /// The row length of this copy: `W`, or the model's when `W` is 0.
    #[inline(always)]
    fn width<const W: usize>(&self) -> usize {
        if W == 0 {
            self.n
        } else {
            W
        }
    }

    #[inline(always)]
    fn propagate_body<const W: usize>(
        &mut self,
        a: &[f64],
        dt: f64,
        q: &[f64],
        p: &mut [f64],
        x: Option<&mut [f64]>,
    ) {
        let n = self.width::<W>();
        self.fill_b(a, dt);
        // x = 0 (closed loop between updates) stays exactly +0 under Φ = I + B: skipped
        if let Some(x) = x.filter(|x| x.iter().any(|v| v.to_bits() != 0)) {
            let (b, dx) = (&self.b, &mut self.dx);
            for (r, d) in dx.iter_mut().enumerate() {
                let br = &b[r * n..(r + 1) * n];
                *d = self.b_cols[r].iter().map(|&k| br[k] * x[k]).sum();
            }
            for (r, &i) in self.dyn_rows.iter().enumerate() {
                x[i] += dx[r];
            }
        }
        self.sandwich::<W>(p);
        for i in 0..n {
            p[i * n + i] += q[i] * dt;
        }
    }

    /// B = Φ − I = A·dt + A²·dt²/2 on the dynamic rows, into the scratch `b`, and its
    /// transpose into `bt` (once per step, however many matrices the step then propagates).
    #[inline(always)]
    fn fill_b(&mut self, a: &[f64], dt: f64) {
        let half_dt2 = 0.5 * dt * dt;
        let b = &mut self.b;
        for g in &self.fill {
            match g.len {
                0 => g.fill(0, a, dt, half_dt2, b),
                1 => g.fill(1, a, dt, half_dt2, b),
                2 => g.fill(2, a, dt, half_dt2, b),
                3 => g.fill(3, a, dt, half_dt2, b),
                4 => g.fill(4, a, dt, half_dt2, b),
                5 => g.fill(5, a, dt, half_dt2, b),
                6 => g.fill(6, a, dt, half_dt2, b),
                l => g.fill(l, a, dt, half_dt2, b),
            }
        }
        let (n, ndp) = (self.n, self.bt.len() / self.n.max(1));
        for (r, cols) in self.b_cols.iter().enumerate() {
            for &j in cols {
                self.bt[j * ndp + r] = self.b[r * n + j];
            }
        }
    }

    /// M = B P into the scratch `m` (P n×n row-major, B from [`Self::fill_b`]).
    #[inline(always)]
    fn b_times<const W: usize>(&mut self, p: &[f64]) {
        let n = self.width::<W>();
        let (b, m) = (&self.b, &mut self.m);
        for (r, cols) in self.b_cols.iter().enumerate() {
            let mr = &mut m[r * n..(r + 1) * n];
            let br = &b[r * n..(r + 1) * n];
            if W > 0 {
                // the same sums, the row held in registers
                let mut acc = [0.0; W];
                for &k in cols {
                    let bk = br[k];
                    let pk: &[f64; W] = p[k * W..(k + 1) * W].try_into().expect("row");
                    for (aj, pj) in acc.iter_mut().zip(pk) {
                        *aj += bk * pj;
                    }
                }
                mr.copy_from_slice(&acc);
                continue;
            }
            mr.iter_mut().for_each(|v| *v = 0.0);
            for &k in cols {
                let bk = br[k];
                for (mj, pj) in mr.iter_mut().zip(&p[k * n..(k + 1) * n]) {
                    *mj += bk * pj;
                }
            }
        }
    }

    /// P ← Φ P Φᵀ = P + B P + (B P)ᵀ + B P Bᵀ, with B from [`Self::fill_b`].
    ///
    /// Each (B P Bᵀ)[r][s] is the dot product of row r of M = B P with row s of B over all n
    /// columns, summed as four interleaved partial sums (column j into sum j mod 4 while four
    /// columns remain, the sums added pairwise, then the last columns one by one), the order of
    /// the generated kernels. Four s are computed side by side from Bᵀ so that every operation
    /// is a vertical one on four values.
    #[inline(always)]
    fn sandwich<const W: usize>(&mut self, p: &mut [f64]) {
        let n = self.width::<W>();
        self.b_times::<W>(p);
        let nd = self.dyn_rows.len();
        let ndp = self.bt.len() / n;
        let (bt, m) = (&self.bt, &self.m);
        let n4 = n - n % 4;
        for (r, &i) in self.dyn_rows.iter().enumerate() {
            let mr = &m[r * n..(r + 1) * n];
            for s0 in (0..nd).step_by(4) {
                let col = |j: usize| -> &[f64; 4] {
                    bt[j * ndp + s0..j * ndp + s0 + 4].try_into().expect("4")
                };
                let mut lanes = [[0.0f64; 4]; 4];
                for (c, m4) in mr[..n4].chunks_exact(4).enumerate() {
                    for (q, lane) in lanes.iter_mut().enumerate() {
                        let bj = col(4 * c + q);
                        for l in 0..4 {
                            lane[l] += m4[q] * bj[l];
                        }
                    }
                }
                let mut v = [0.0f64; 4];
                for l in 0..4 {
                    v[l] = (lanes[0][l] + lanes[1][l]) + (lanes[2][l] + lanes[3][l]);
                }
                for (j, &mj) in mr.iter().enumerate().skip(n4) {
                    let bj = col(j);
                    for l in 0..4 {
                        v[l] += mj * bj[l];
                    }
                }
                for (l, &vl) in v.iter().enumerate().take(nd - s0) {
                    p[i * n + self.dyn_rows[s0 + l]] += vl;
                }
            }
            let pi = &mut p[i * n..(i + 1) * n];
            for (pj, &mj) in pi.iter_mut().zip(mr) {
                *pj += mj;
            }
            for (j, &mj) in mr.iter().enumerate() {
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
        by_width!(self.accumulate_width(a, dt, q, g, psi))
    }

    /// [`Self::accumulate`] for rows of `W` states (0: `self.n`, read at run time).
    fn accumulate_width<const W: usize>(
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
                unsafe { self.accumulate_avx2::<W>(a, dt, q, g, psi) };
                return;
            }
        }
        self.accumulate_body::<W>(a, dt, q, g, psi)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn accumulate_avx2<const W: usize>(
        &mut self,
        a: &[f64],
        dt: f64,
        q: &[Vec<f64>],
        g: &mut [Vec<f64>],
        psi: &mut [f64],
    ) {
        self.accumulate_body::<W>(a, dt, q, g, psi)
    }

    #[inline(always)]
    fn accumulate_body<const W: usize>(
        &mut self,
        a: &[f64],
        dt: f64,
        q: &[Vec<f64>],
        g: &mut [Vec<f64>],
        psi: &mut [f64],
    ) {
        let n = self.width::<W>();
        self.fill_b(a, dt);
        for (gk, qk) in g.iter_mut().zip(q) {
            self.sandwich::<W>(gk);
            for i in 0..n {
                gk[i * n + i] += qk[i] * dt;
            }
        }
        // Ψ ← Ψ + B Ψ
        self.b_times::<W>(psi);
        for (r, &i) in self.dyn_rows.iter().enumerate() {
            for (pj, mj) in psi[i * n..(i + 1) * n].iter_mut().zip(&self.m[r * n..]) {
                *pj += mj;
            }
        }
    }
}

/// Non-zeros of B = A·dt + A²·dt²/2 that have the same number `len` of second-order products,
/// as flat indices into the row-major A and B (one loop of known length per group: the
/// entries' sums overlap in the CPU instead of waiting on each other).
#[derive(Debug, Clone)]
struct FillGroup {
    len: usize,
    /// Per entry: its index in B, and A's index of the first-order term when A has it.
    targets: Vec<(usize, Option<usize>)>,
    /// `len` (i·n + k, k·n + j) pairs per entry: the products A[i][k]·A[k][j] in order of k.
    pairs: Vec<(usize, usize)>,
}

impl FillGroup {
    /// B[t] = A[d]·dt + dt²/2 · Σ A[u]·A[v] for every entry of the group, `l` = `self.len`
    /// products each (a constant where inlined with one: the loop is then unrolled).
    #[inline(always)]
    fn fill(&self, l: usize, a: &[f64], dt: f64, half_dt2: f64, b: &mut [f64]) {
        for (e, &(t, direct)) in self.targets.iter().enumerate() {
            let mut second = 0.0;
            for &(u, v) in &self.pairs[e * l..(e + 1) * l] {
                second += a[u] * a[v];
            }
            let first = direct.map_or(0.0, |d| a[d] * dt);
            b[t] = first + half_dt2 * second;
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A pattern, A, P and x (row-major).
    type Case = (Vec<(usize, usize)>, Vec<f64>, Vec<f64>, Vec<f64>);

    /// A random navigation-like pattern: `nd` dynamic rows reading any state, the rest constant.
    fn case(n: usize, nd: usize, seed: u64) -> Case {
        let mut rng = crate::sim::rng::Rng::new(seed);
        let mut pattern = Vec::new();
        let mut a = vec![0.0; n * n];
        for i in 0..nd {
            for j in 0..n {
                if rng.uniform() < 0.6 {
                    pattern.push((i, j));
                    a[i * n + j] = rng.uniform() - 0.5;
                }
            }
        }
        let l: Vec<f64> = (0..n * n).map(|_| rng.uniform() - 0.5).collect();
        let mut p = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..n {
                p[i * n + j] = (0..n).map(|k| l[i * n + k] * l[j * n + k]).sum::<f64>();
            }
        }
        let x: Vec<f64> = (0..n).map(|_| rng.uniform() - 0.5).collect();
        (pattern, a, p, x)
    }

    #[test]
    fn every_width_gives_the_same_bits() {
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        for (n, nd) in [(5, 3), (21, 9), (33, 12), (64, 20)] {
            let (pattern, a, p0, x0) = case(n, nd, n as u64);
            let q: Vec<f64> = (0..n).map(|i| 1e-4 * (i + 1) as f64).collect();
            let mut sp = SparsePropagator::new(n, &pattern);
            let (mut p_w, mut x_w) = (p0.clone(), x0.clone());
            sp.propagate_with_state(&a, 0.01, &q, &mut p_w, Some(&mut x_w));
            let (mut p_0, mut x_0) = (p0.clone(), x0.clone());
            sp.propagate_width::<0>(&a, 0.01, &q, &mut p_0, Some(&mut x_0));
            assert!(
                bits(&p_w) == bits(&p_0) && bits(&x_w) == bits(&x_0),
                "n = {n}"
            );
            // the replay's step: G_k and Ψ the same way
            let g0 = vec![p0.clone(), p0.clone()];
            let qs = vec![q.clone(), q.iter().map(|v| 2.0 * v).collect()];
            let eye: Vec<f64> = (0..n * n)
                .map(|k| f64::from(u8::from(k % (n + 1) == 0)))
                .collect();
            let (mut g_w, mut psi_w) = (g0.clone(), eye.clone());
            sp.accumulate(&a, 0.01, &qs, &mut g_w, &mut psi_w);
            let (mut g_0, mut psi_0) = (g0.clone(), eye.clone());
            sp.accumulate_width::<0>(&a, 0.01, &qs, &mut g_0, &mut psi_0);
            assert!(bits(&psi_w) == bits(&psi_0), "n = {n}");
            for (gw, g0) in g_w.iter().zip(&g_0) {
                assert!(bits(gw) == bits(g0), "n = {n}");
            }
            // and both agree with Φ P Φᵀ + Q formed densely
            let am = DMatrix::from_row_slice(n, n, &a);
            let pm = DMatrix::from_row_slice(n, n, &p0);
            let dense = propagate_dense(&am, 0.01, &q, &pm);
            let err = (DMatrix::from_row_slice(n, n, &p_w) - &dense).amax() / dense.amax();
            assert!(err < 1e-13, "n = {n}: relative error {err:e}");
        }
    }

    #[test]
    fn multiply_adds_are_counted_from_the_pattern() {
        // x0' = x1, x1' = x2: B = [[0, dt, dt²/2, 0], [0, 0, dt, 0]] on rows 0 and 1 of 4
        let sp = SparsePropagator::new(4, &[(0, 1), (1, 2)]);
        // one product A[0][1]·A[1][2]; M = B P: 3 non-zeros × 4; B P Bᵀ: 2 rows × 4 columns × 4
        assert_eq!(sp.mul_adds(), 1 + 3 * 4 + 2 * 4 * 4);
    }

    #[test]
    fn a_zero_state_stays_zero() {
        let (pattern, a, mut p, _) = case(21, 9, 4);
        let mut x = vec![0.0; 21];
        SparsePropagator::new(21, &pattern).propagate_with_state(
            &a,
            0.01,
            &[0.0; 21],
            &mut p,
            Some(&mut x),
        );
        assert!(x.iter().all(|v| v.to_bits() == 0));
    }
}
