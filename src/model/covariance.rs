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
    /// Columns of A's non-zeros in each dynamic row (the k of the products A[i][k]·A[k][j]).
    a_cols: Vec<Vec<usize>>,
    /// Products A[i][k]·A[k][j] with both factors on A's pattern.
    a2_products: usize,
    /// Scratch: B = Φ − I on the dynamic rows (nd × n, zero off B's pattern, then zero rows up
    /// to a multiple of four), kept between steps (no allocation).
    b: Vec<f64>,
    /// Scratch: B's last n mod 4 columns, transposed (each padded to a multiple of four rows).
    b_tail: Vec<f64>,
    /// Scratch: M = B P (nd × n).
    m: Vec<f64>,
    /// Scratch: B P Bᵀ (nd × nd rounded up to a multiple of four).
    v: Vec<f64>,
    /// Whether this CPU has AVX2 (B P Bᵀ four dot products at a time).
    avx2: bool,
    /// Whether this CPU has AVX-512 (A² and B P three rows at a time, eight columns a vector),
    /// used for models of up to 64 states.
    avx512: bool,
    /// The dynamic rows three at a time for A² (k: A's non-zeros in any of the three rows).
    a2_groups: Vec<RowGroup>,
    /// The dynamic rows three at a time for M = B P (k: B's non-zeros in any of the three).
    m_groups: Vec<RowGroup>,
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
        let a_cols: Vec<Vec<usize>> = dyn_rows.iter().map(|&i| a_rows[i].clone()).collect();
        let a2_products = a_cols.iter().flatten().map(|&k| a_rows[k].len()).sum();
        let group = |cols: &[Vec<usize>], coef: &dyn Fn(usize) -> usize| -> Vec<RowGroup> {
            (0..nd)
                .step_by(3)
                .map(|r0| {
                    let rows = r0..(r0 + 3).min(nd);
                    let mut ks: Vec<usize> = rows.flat_map(|r| cols[r].clone()).collect();
                    ks.sort_unstable();
                    ks.dedup();
                    let at = |q: usize| (r0 + q < nd).then(|| (coef(r0 + q), (r0 + q) * n));
                    RowGroup {
                        ks,
                        rows: [at(0), at(1), at(2)],
                    }
                })
                .collect()
        };
        let a2_groups = group(&a_cols, &|r| dyn_rows[r] * n);
        let m_groups = group(&b_cols, &|r| r * n);
        SparsePropagator {
            n,
            dyn_rows,
            b_cols,
            a_cols,
            a2_products,
            b: vec![0.0; nd.div_ceil(4) * 4 * n],
            b_tail: vec![0.0; (n % 4) * nd.div_ceil(4) * 4],
            m: vec![0.0; nd * n],
            v: vec![0.0; nd * nd.div_ceil(4) * 4],
            avx2: has_avx2(),
            avx512: has_avx512() && n <= 64,
            a2_groups,
            m_groups,
            dx: vec![0.0; nd],
        }
    }

    /// Number of structural non-zeros of B = Φ − I.
    pub fn b_nnz(&self) -> usize {
        self.b_cols.iter().map(Vec::len).sum()
    }

    /// Multiply-adds one [`Self::propagate`] needs on the pattern: the products of A² that A's
    /// non-zeros give, M = B P over B's non-zeros, and B P Bᵀ = M Bᵀ over B's non-zeros (the
    /// kernel itself also multiplies some zeros, four columns to a vector; the adds of
    /// P + M + Mᵀ not counted).
    pub fn mul_adds(&self) -> usize {
        self.a2_products + self.b_nnz() * self.n + self.dyn_rows.len() * self.b_nnz()
    }

    /// P ← Φ P Φᵀ + diag(q)·dt; `a`, `p` n×n row-major, `q` [SI²/s], `dt` [s]. `a` must be
    /// zero off the pattern given to [`Self::new`]: the kernel multiplies some of those zeros
    /// (whole rows at a time), which leaves the sums of finite values as the sparse order has them.
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
            if self.avx2 {
                // SAFETY: `avx2` is set only where the CPU has AVX2 (detected once, in `new`).
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
        self.fill_b::<W>(a, dt);
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

    /// B = Φ − I = A·dt + A²·dt²/2 on the dynamic rows, into the scratch `b` (once per step,
    /// however many matrices the step then propagates).
    ///
    /// Row i of A² is Σ A[i][k]·(row k of A) over A's non-zeros in row i, in order of k, a whole
    /// row at a time. A is zero off its pattern, so the products that a sum over the pattern
    /// alone would leave out are ±0 and leave the sums' bits as they are.
    #[inline(always)]
    fn fill_b<const W: usize>(&mut self, a: &[f64], dt: f64) {
        let n = self.width::<W>();
        let half_dt2 = 0.5 * dt * dt;
        #[cfg(target_arch = "x86_64")]
        if self.avx512 {
            // SAFETY: `avx512` is set only where the CPU has AVX-512F.
            unsafe {
                rows_avx512::<W>(n, &self.a2_groups, a, a, &mut self.b, Some((dt, half_dt2)));
            }
            self.fill_b_tail(n);
            return;
        }
        for (r, &i) in self.dyn_rows.iter().enumerate() {
            let ai = &a[i * n..(i + 1) * n];
            let br = &mut self.b[r * n..(r + 1) * n];
            if W > 0 {
                let mut acc = [0.0; W];
                for &k in &self.a_cols[r] {
                    let aik = ai[k];
                    let ak: &[f64; W] = a[k * W..(k + 1) * W].try_into().expect("row");
                    for (s, akj) in acc.iter_mut().zip(ak) {
                        *s += aik * akj;
                    }
                }
                for ((bj, aij), s) in br.iter_mut().zip(ai).zip(&acc) {
                    *bj = aij * dt + half_dt2 * s;
                }
                continue;
            }
            br.iter_mut().for_each(|v| *v = 0.0);
            for &k in &self.a_cols[r] {
                let aik = ai[k];
                for (s, akj) in br.iter_mut().zip(&a[k * n..(k + 1) * n]) {
                    *s += aik * akj;
                }
            }
            for (bj, aij) in br.iter_mut().zip(ai) {
                *bj = aij * dt + half_dt2 * *bj;
            }
        }
        self.fill_b_tail(n);
    }

    /// B's last n mod 4 columns into `b_tail`, transposed.
    #[inline(always)]
    fn fill_b_tail(&mut self, n: usize) {
        let (n4, ndp) = (n - n % 4, self.v.len() / self.dyn_rows.len().max(1));
        for (t, col) in self.b_tail.chunks_exact_mut(ndp).enumerate() {
            for (r, c) in col.iter_mut().enumerate().take(self.dyn_rows.len()) {
                *c = self.b[r * n + n4 + t];
            }
        }
    }

    /// M = B P into the scratch `m` (P n×n row-major, B from [`Self::fill_b`]).
    #[inline(always)]
    fn b_times<const W: usize>(&mut self, p: &[f64]) {
        let n = self.width::<W>();
        #[cfg(target_arch = "x86_64")]
        if self.avx512 {
            // SAFETY: `avx512` is set only where the CPU has AVX-512F.
            unsafe { rows_avx512::<W>(n, &self.m_groups, &self.b, p, &mut self.m, None) };
            return;
        }
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
    /// columns remain, the sums added pairwise, then the last columns one by one): the order of
    /// the generated kernels, four columns a vector.
    #[inline(always)]
    fn sandwich<const W: usize>(&mut self, p: &mut [f64]) {
        let n = self.width::<W>();
        self.b_times::<W>(p);
        self.dots::<W>();
        let (m, v, nd) = (&self.m, &self.v, self.dyn_rows.len());
        let ndp = v.len() / nd.max(1);
        for (r, &i) in self.dyn_rows.iter().enumerate() {
            let mr = &m[r * n..(r + 1) * n];
            for (&js, &vs) in self.dyn_rows.iter().zip(&v[r * ndp..r * ndp + nd]) {
                p[i * n + js] += vs;
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

    /// (B P Bᵀ)[r][s] = row r of M · row s of B into the scratch `v`, each summed as four
    /// interleaved partial sums (column j into sum j mod 4 while four columns remain, the sums
    /// added pairwise, then the last columns one by one): the generated kernels' order.
    #[inline(always)]
    fn dots<const W: usize>(&mut self) {
        let n = self.width::<W>();
        #[cfg(target_arch = "x86_64")]
        {
            if self.avx2 {
                // SAFETY: `avx2` is set only where the CPU has AVX2.
                unsafe {
                    dots_avx2::<W>(
                        n,
                        self.dyn_rows.len(),
                        &self.m,
                        &self.b,
                        &self.b_tail,
                        &mut self.v,
                    )
                };
                return;
            }
        }
        let (nd, n4) = (self.dyn_rows.len(), n - n % 4);
        let ndp = self.v.len() / nd.max(1);
        for r in 0..nd {
            let mr = &self.m[r * n..(r + 1) * n];
            for s in 0..nd {
                let bs = &self.b[s * n..(s + 1) * n];
                let mut lanes = [0.0f64; 4];
                for (m4, b4) in mr[..n4].chunks_exact(4).zip(bs[..n4].chunks_exact(4)) {
                    for l in 0..4 {
                        lanes[l] += m4[l] * b4[l];
                    }
                }
                let mut v = (lanes[0] + lanes[1]) + (lanes[2] + lanes[3]);
                for (mj, bj) in mr[n4..].iter().zip(&bs[n4..]) {
                    v += mj * bj;
                }
                self.v[r * ndp + s] = v;
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
            if self.avx2 {
                // SAFETY: `avx2` is set only where the CPU has AVX2 (detected once, in `new`).
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
        self.fill_b::<W>(a, dt);
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

/// Whether this CPU has AVX2.
fn has_avx2() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("avx2")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// Whether this CPU has AVX-512F.
pub(crate) fn has_avx512() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("avx512f")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// Up to three rows of a product out = C · S computed together: the k they sum over (the
/// union of their non-zeros, in order), and per row its offsets in C and in `out` (None past
/// the last row).
#[derive(Debug, Clone)]
struct RowGroup {
    ks: Vec<usize>,
    rows: [Option<(usize, usize)>; 3],
}

/// out[row] = Σ_k C[row][k] · S[k] (rows of n, k in each group's order) for every row of
/// `groups`, with AVX-512: three rows at a time, so three times as many independent sums as
/// one row has. A k outside a row's own non-zeros multiplies a zero of C and adds ±0, which
/// leaves the sum's bits as they are: every row is the one-row sum. With `fill` = (dt,
/// dt²/2), out[row] = C[row]·dt + dt²/2 · Σ instead (B from A: C = S = A). n ≤ 64.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
fn rows_avx512<const W: usize>(
    n: usize,
    groups: &[RowGroup],
    c: &[f64],
    s: &[f64],
    out: &mut [f64],
    fill: Option<(f64, f64)>,
) {
    use std::arch::x86_64::{
        __m512d, __mmask8, _mm512_add_pd, _mm512_mask_storeu_pd, _mm512_maskz_loadu_pd,
        _mm512_mul_pd, _mm512_set1_pd, _mm512_setzero_pd,
    };
    let n = if W == 0 { n } else { W };
    assert!(n <= 64, "rows of at most 64");
    let chunks = n.div_ceil(8);
    let mask = |q: usize| -> __mmask8 {
        let left = n - 8 * q;
        if left >= 8 {
            0xff
        } else {
            (1u8 << left) - 1
        }
    };
    let load = |row: &[f64], q: usize| -> __m512d {
        let row = &row[..n];
        // SAFETY: the lanes the mask loads are within `row` (8q < n, checked by the slice).
        unsafe { _mm512_maskz_loadu_pd(mask(q), row[8 * q..].as_ptr()) }
    };
    for g in groups {
        let mut acc = [[_mm512_setzero_pd(); 8]; 3];
        for &k in &g.ks {
            let sk = &s[k * n..(k + 1) * n];
            let mut row = [_mm512_setzero_pd(); 8];
            for (q, v) in row.iter_mut().enumerate().take(chunks) {
                *v = load(sk, q);
            }
            for (a, rows) in acc.iter_mut().zip(&g.rows) {
                let Some((ci, _)) = *rows else { continue };
                let x = _mm512_set1_pd(c[ci + k]);
                for (aq, rq) in a.iter_mut().zip(&row).take(chunks) {
                    *aq = _mm512_add_pd(*aq, _mm512_mul_pd(x, *rq));
                }
            }
        }
        for (a, rows) in acc.iter().zip(&g.rows) {
            let Some((ci, oi)) = *rows else { continue };
            let dst = &mut out[oi..oi + n];
            for (q, &aq) in a.iter().enumerate().take(chunks) {
                let v = match fill {
                    Some((dt, half_dt2)) => _mm512_add_pd(
                        _mm512_mul_pd(load(&c[ci..], q), _mm512_set1_pd(dt)),
                        _mm512_mul_pd(_mm512_set1_pd(half_dt2), aq),
                    ),
                    None => aq,
                };
                // SAFETY: the lanes the mask stores are within `dst` (8q < n = dst.len()).
                unsafe { _mm512_mask_storeu_pd(dst[8 * q..].as_mut_ptr(), mask(q), v) };
            }
        }
    }
}

/// [`SparsePropagator::dots`] with AVX2: four dot products (four rows of B) at a time, one
/// vector of four partial sums each, added pairwise across the four by two horizontal adds.
/// Every sum is the scalar order's, so the bits are the same. `m` is nd × n, `b` padded to
/// whole blocks of four rows, `b_tail` B's last n mod 4 columns transposed, `v` nd × ndp.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn dots_avx2<const W: usize>(
    n: usize,
    nd: usize,
    m: &[f64],
    b: &[f64],
    b_tail: &[f64],
    v: &mut [f64],
) {
    use std::arch::x86_64::{
        _mm256_add_pd, _mm256_hadd_pd, _mm256_loadu_pd, _mm256_mul_pd, _mm256_permute2f128_pd,
        _mm256_set1_pd, _mm256_setzero_pd, _mm256_storeu_pd,
    };
    let n = if W == 0 { n } else { W };
    let n4 = n - n % 4;
    let ndp = v.len() / nd.max(1);
    let load = |x: &[f64]| -> std::arch::x86_64::__m256d {
        let x: &[f64; 4] = x[..4].try_into().expect("four");
        // SAFETY: four f64 in bounds (checked just above); unaligned load.
        unsafe { _mm256_loadu_pd(x.as_ptr()) }
    };
    for r in 0..nd {
        let mr = &m[r * n..(r + 1) * n];
        for s0 in (0..ndp).step_by(4) {
            let mut acc = [_mm256_setzero_pd(); 4];
            for c in (0..n4).step_by(4) {
                let mc = load(&mr[c..]);
                for (l, al) in acc.iter_mut().enumerate() {
                    *al = _mm256_add_pd(*al, _mm256_mul_pd(mc, load(&b[(s0 + l) * n + c..])));
                }
            }
            // [s0: L0+L1, s1: L0+L1, s0: L2+L3, s1: L2+L3] and the same for s2, s3
            let h01 = _mm256_hadd_pd(acc[0], acc[1]);
            let h23 = _mm256_hadd_pd(acc[2], acc[3]);
            let mut v4 = _mm256_add_pd(
                _mm256_permute2f128_pd::<0x20>(h01, h23),
                _mm256_permute2f128_pd::<0x31>(h01, h23),
            );
            for (t, &mj) in mr[n4..].iter().enumerate() {
                let bj = load(&b_tail[t * ndp + s0..]);
                v4 = _mm256_add_pd(v4, _mm256_mul_pd(_mm256_set1_pd(mj), bj));
            }
            let out: &mut [f64; 4] = (&mut v[r * ndp + s0..r * ndp + s0 + 4])
                .try_into()
                .expect("four");
            // SAFETY: four f64 in bounds (checked just above); unaligned store.
            unsafe { _mm256_storeu_pd(out.as_mut_ptr(), v4) };
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
    fn the_vector_paths_give_the_scalar_bits() {
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        for (n, nd) in [(5, 3), (8, 4), (21, 9), (33, 12), (70, 21)] {
            let (pattern, a, p0, x0) = case(n, nd, 100 + n as u64);
            let q: Vec<f64> = (0..n).map(|i| 1e-4 * (i + 1) as f64).collect();
            let fast = SparsePropagator::new(n, &pattern);
            let mut avx2 = fast.clone();
            avx2.avx512 = false;
            let mut scalar = avx2.clone();
            scalar.avx2 = false;
            let run = |mut sp: SparsePropagator| {
                let (mut p, mut x) = (p0.clone(), x0.clone());
                for _ in 0..3 {
                    sp.propagate_with_state(&a, 0.01, &q, &mut p, Some(&mut x));
                }
                (bits(&p), bits(&x))
            };
            let want = run(scalar);
            assert!(run(avx2) == want, "n = {n}: AVX2");
            assert!(run(fast) == want, "n = {n}: AVX-512");
        }
    }

    #[test]
    fn multiply_adds_are_counted_from_the_pattern() {
        // x0' = x1, x1' = x2: B = [[0, dt, dt²/2, 0], [0, 0, dt, 0]] on rows 0 and 1 of 4
        let sp = SparsePropagator::new(4, &[(0, 1), (1, 2)]);
        // one product A[0][1]·A[1][2]; M = B P: 3 non-zeros × 4 columns; B P Bᵀ: 2 rows of M
        // times B's 3 non-zeros
        assert_eq!(sp.mul_adds(), 1 + 3 * 4 + 2 * 3);
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
