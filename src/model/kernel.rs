//! The sparse covariance kernel every generated preset shares: P ← Φ P Φᵀ + diag(q)·dt and
//! x ← Φ x with Φ = I + B, where B = Φ − I is non-zero only on the navigation rows.
//!
//! A preset's generated module supplies B's structure and its fill ([`PhiRows`]: the dynamic
//! rows, the columns of B's non-zeros and `fill_b`) and calls the functions here through one-line
//! wrappers. The arithmetic is written once, in one fixed order of operations, so every preset
//! computes exactly what its own copy of this code used to.

/// B = Φ − I of one preset (N states, ND dynamic rows), as its generated module defines it.
pub trait PhiRows<const N: usize, const ND: usize> {
    /// The rows of Φ that differ from the identity (the navigation rows).
    const DYN_ROWS: [usize; ND];
    /// Columns of the non-zeros of B in each dynamic row.
    const B_COLS: [&'static [usize]; ND];
    /// B = Φ − I = A·dt + A²·dt²/2 on the dynamic rows (dt in s).
    fn fill_b(a: &[[f64; N]; N], dt: f64, b: &mut [[f64; N]; ND]);
}

/// P ← Φ P Φᵀ + diag(q)·dt with Φ = I + B: P + BP + (BP)ᵀ + BPBᵀ on the pattern only.
/// `q` is the continuous white-noise density of each state (SI²/s). Uses AVX2 when the CPU
/// has it (same arithmetic, wider registers: results are identical).
pub fn propagate_cov<K: PhiRows<N, ND>, const N: usize, const ND: usize>(
    a: &[[f64; N]; N],
    dt: f64,
    q: &[f64; N],
    p: &mut [[f64; N]; N],
) {
    #[cfg(target_arch = "x86_64")]
    {
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU supports AVX2, checked just above.
            unsafe { propagate_avx2::<K, N, ND>(a, dt, q, p, None) };
            return;
        }
    }
    propagate_body::<K, N, ND>(a, dt, q, p, None)
}

/// `propagate_cov` plus the state: x ← Φ x with the same Φ.
pub fn propagate_cov_and_state<K: PhiRows<N, ND>, const N: usize, const ND: usize>(
    a: &[[f64; N]; N],
    dt: f64,
    q: &[f64; N],
    p: &mut [[f64; N]; N],
    x: &mut [f64; N],
) {
    #[cfg(target_arch = "x86_64")]
    {
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU supports AVX2, checked just above.
            unsafe { propagate_avx2::<K, N, ND>(a, dt, q, p, Some(x)) };
            return;
        }
    }
    propagate_body::<K, N, ND>(a, dt, q, p, Some(x))
}

/// [`propagate_body`] compiled for AVX2 (no FMA: the same roundings as without it).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn propagate_avx2<K: PhiRows<N, ND>, const N: usize, const ND: usize>(
    a: &[[f64; N]; N],
    dt: f64,
    q: &[f64; N],
    p: &mut [[f64; N]; N],
    x: Option<&mut [f64; N]>,
) {
    propagate_body::<K, N, ND>(a, dt, q, p, x)
}

/// B from A, then x ← Φ x (when given) and P ← P + BP + (BP)ᵀ + BPBᵀ + diag(q)·dt.
// The index loops are kept as written: the order of every floating-point sum is part of the
// results (the goldens compare them bit for bit).
#[allow(clippy::needless_range_loop)]
#[inline(always)]
fn propagate_body<K: PhiRows<N, ND>, const N: usize, const ND: usize>(
    a: &[[f64; N]; N],
    dt: f64,
    q: &[f64; N],
    p: &mut [[f64; N]; N],
    x: Option<&mut [f64; N]>,
) {
    let mut b = [[0.0; N]; ND];
    K::fill_b(a, dt, &mut b);
    if let Some(x) = x {
        propagate_state::<K, N, ND>(&b, x);
    }
    // M = B P, row by row as a sum of scaled rows of P (contiguous, vectorisable)
    let mut m = [[0.0; N]; ND];
    for r in 0..ND {
        let mut acc = [0.0; N];
        for &k in K::B_COLS[r] {
            let bk = b[r][k];
            let pk = &p[k];
            for j in 0..N {
                acc[j] += bk * pk[j];
            }
        }
        m[r] = acc;
    }
    for r in 0..ND {
        let i = K::DYN_ROWS[r];
        for s in 0..ND {
            // (M Bᵀ)[r][s] over all columns (B is zero off its pattern), in four
            // interleaved partial sums so the products vectorise
            let (mr, bs) = (&m[r], &b[s]);
            let mut lanes = [0.0; 4];
            for (mc, bc) in mr.chunks_exact(4).zip(bs.chunks_exact(4)) {
                for l in 0..4 {
                    lanes[l] += mc[l] * bc[l];
                }
            }
            let mut v = (lanes[0] + lanes[1]) + (lanes[2] + lanes[3]);
            for (mk, bk) in mr
                .chunks_exact(4)
                .remainder()
                .iter()
                .zip(bs.chunks_exact(4).remainder())
            {
                v += mk * bk;
            }
            p[i][K::DYN_ROWS[s]] += v;
        }
        for j in 0..N {
            p[i][j] += m[r][j];
            p[j][i] += m[r][j];
        }
    }
    for i in 0..N {
        p[i][i] += q[i] * dt;
    }
}

/// x ← Φ x with Φ = I + B (B from `fill_b`).
#[allow(clippy::needless_range_loop)] // the sums' order is part of the results
pub fn propagate_state<K: PhiRows<N, ND>, const N: usize, const ND: usize>(
    b: &[[f64; N]; ND],
    x: &mut [f64; N],
) {
    let mut dx = [0.0; ND];
    for r in 0..ND {
        for &k in K::B_COLS[r] {
            dx[r] += b[r][k] * x[k];
        }
    }
    for r in 0..ND {
        x[K::DYN_ROWS[r]] += dx[r];
    }
}

/// `propagate_cov` on slices: `a` and `p` are N×N row-major, `q` has N entries.
pub fn propagate_cov_dyn<K: PhiRows<N, ND>, const N: usize, const ND: usize>(
    a: &[f64],
    dt: f64,
    q: &[f64],
    p: &mut [f64],
) {
    let a: &[[f64; N]; N] = a.as_chunks::<N>().0.try_into().expect("A of N×N");
    let p: &mut [[f64; N]; N] = p.as_chunks_mut::<N>().0.try_into().expect("P of N×N");
    let q: &[f64; N] = q.try_into().expect("q of length N");
    propagate_cov::<K, N, ND>(a, dt, q, p);
}

/// `propagate_cov_and_state` on slices.
pub fn propagate_dyn<K: PhiRows<N, ND>, const N: usize, const ND: usize>(
    a: &[f64],
    dt: f64,
    q: &[f64],
    p: &mut [f64],
    x: &mut [f64],
) {
    let a: &[[f64; N]; N] = a.as_chunks::<N>().0.try_into().expect("A of N×N");
    let p: &mut [[f64; N]; N] = p.as_chunks_mut::<N>().0.try_into().expect("P of N×N");
    let q: &[f64; N] = q.try_into().expect("q of length N");
    let x: &mut [f64; N] = x.try_into().expect("x of length N");
    propagate_cov_and_state::<K, N, ND>(a, dt, q, p, x);
}
