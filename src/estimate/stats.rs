//! Statistics of the filter's tests: χ² quantiles and tail probabilities, the normal
//! distribution, the Ljung–Box whiteness test, multiple-test corrections.

/// The median of `values` (the upper one of an even count; NaN-safe order), sorting them in
/// place; None when empty.
pub fn median(values: &mut [f64]) -> Option<f64> {
    values.sort_by(f64::total_cmp);
    values.get(values.len() / 2).copied()
}

/// Wilson–Hilferty approximation of the χ² quantile with `k` degrees of freedom at normal z.
pub fn chi2_quantile(k: f64, z: f64) -> f64 {
    let a = 2.0 / (9.0 * k);
    k * (1.0 - a + z * a.sqrt()).powi(3)
}

/// ln Γ(x) for x > 0 (Lanczos, g = 7, 9 terms; relative error below 1e-14).
pub fn ln_gamma(x: f64) -> f64 {
    const C: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    if x < 0.5 {
        // reflection
        let pi = std::f64::consts::PI;
        return (pi / (pi * x).sin()).ln() - ln_gamma(1.0 - x);
    }
    let x = x - 1.0;
    let mut a = C[0];
    let t = x + 7.5;
    for (i, c) in C.iter().enumerate().skip(1) {
        a += c / (x + i as f64);
    }
    0.5 * (2.0 * std::f64::consts::PI).ln() + (x + 0.5) * t.ln() - t + a.ln()
}

/// Regularised upper incomplete gamma Q(a, x) = Γ(a, x)/Γ(a) (series below a + 1, continued
/// fraction above; relative accuracy ~1e-13).
pub fn gamma_q(a: f64, x: f64) -> f64 {
    if x <= 0.0 {
        return 1.0;
    }
    let gln = ln_gamma(a);
    if x < a + 1.0 {
        let (mut sum, mut del, mut ap) = (1.0 / a, 1.0 / a, a);
        for _ in 0..10_000 {
            ap += 1.0;
            del *= x / ap;
            sum += del;
            if del.abs() < sum.abs() * 1e-16 {
                break;
            }
        }
        (1.0 - sum * (-x + a * x.ln() - gln).exp()).max(0.0)
    } else {
        let tiny = 1e-300;
        let mut b = x + 1.0 - a;
        let mut c = 1.0 / tiny;
        let mut d = 1.0 / b;
        let mut h = d;
        for i in 1..10_000 {
            let an = -(i as f64) * (i as f64 - a);
            b += 2.0;
            d = an * d + b;
            if d.abs() < tiny {
                d = tiny;
            }
            c = b + an / c;
            if c.abs() < tiny {
                c = tiny;
            }
            d = 1.0 / d;
            let del = d * c;
            h *= del;
            if (del - 1.0).abs() < 1e-16 {
                break;
            }
        }
        (-x + a * x.ln() - gln).exp() * h
    }
}

/// P(χ²_k > x): the p-value of a χ² statistic with `k` degrees of freedom.
pub fn chi2_sf(x: f64, k: f64) -> f64 {
    if !x.is_finite() {
        return if x > 0.0 { 0.0 } else { 1.0 };
    }
    gamma_q(0.5 * k, 0.5 * x.max(0.0))
}

/// The x with P(χ²_k > x) = p (bisection on [`chi2_sf`]; p in (0, 1)).
pub fn chi2_isf(p: f64, k: f64) -> f64 {
    let (mut lo, mut hi) = (0.0, k + 10.0);
    while chi2_sf(hi, k) > p {
        hi *= 2.0;
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if chi2_sf(mid, k) > p {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// Standard normal cumulative distribution Φ(z).
pub fn normal_cdf(z: f64) -> f64 {
    if z >= 0.0 {
        1.0 - 0.5 * chi2_sf(z * z, 1.0)
    } else {
        0.5 * chi2_sf(z * z, 1.0)
    }
}

/// Two-sided band [lo, hi] at normal z of the mean of χ²_k / k over `n` independent samples
/// (Wilson–Hilferty).
pub fn mean_chi2_band(k: f64, n: usize, z: f64) -> [f64; 2] {
    let dof = k * n as f64;
    [chi2_quantile(dof, -z) / dof, chi2_quantile(dof, z) / dof]
}

/// Ljung–Box test of whiteness of `x` over `lags` lags: (Q, p-value against χ²_lags).
/// None when the series is too short (fewer than lags + 2 values) or constant.
pub fn ljung_box(x: &[f64], lags: usize) -> Option<(f64, f64)> {
    let n = x.len();
    if lags == 0 || n < lags + 2 {
        return None;
    }
    let mean = x.iter().sum::<f64>() / n as f64;
    let c0: f64 = x.iter().map(|v| (v - mean).powi(2)).sum::<f64>();
    if c0.is_nan() || c0 <= 0.0 {
        return None;
    }
    let mut q = 0.0;
    for l in 1..=lags {
        let cl: f64 = (l..n).map(|i| (x[i] - mean) * (x[i - l] - mean)).sum();
        let r = cl / c0;
        q += r * r / (n - l) as f64;
    }
    q *= (n * (n + 2)) as f64;
    Some((q, chi2_sf(q, lags as f64)))
}

/// Holm's step-down adjustment of p-values (same order as given; each capped at 1).
pub fn holm(p: &[f64]) -> Vec<f64> {
    let m = p.len();
    let mut idx: Vec<usize> = (0..m).collect();
    idx.sort_by(|&a, &b| p[a].total_cmp(&p[b]));
    let mut out = vec![1.0; m];
    let mut running: f64 = 0.0;
    for (rank, &i) in idx.iter().enumerate() {
        let adj = ((m - rank) as f64 * p[i]).min(1.0);
        running = running.max(adj);
        out[i] = running;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chi2_tail_matches_known_values() {
        // scipy.stats.chi2.sf: (3.841458820694124, 1) = 0.05; (6.634896601021214, 1) = 0.01;
        // (18.307038053275146, 10) = 0.05; (100, 50) = 3.454931382984871e-5
        assert!((chi2_sf(3.841_458_820_694_124, 1.0) - 0.05).abs() < 1e-12);
        assert!((chi2_sf(6.634_896_601_021_214, 1.0) - 0.01).abs() < 1e-12);
        assert!((chi2_sf(18.307_038_053_275_146, 10.0) - 0.05).abs() < 1e-12);
        assert!((chi2_sf(100.0, 50.0) / 3.454_931_382_984_871e-5 - 1.0).abs() < 1e-10);
        assert!(chi2_sf(2000.0, 1.0) < 1e-300 && chi2_sf(2000.0, 1.0) >= 0.0);
        assert!((normal_cdf(1.959_963_984_540_054) - 0.975).abs() < 1e-12);
        assert!((chi2_isf(0.01, 1.0) - 6.634_896_601_021_214).abs() < 1e-9);
        assert!((ln_gamma(10.0) - 362_880f64.ln()).abs() < 1e-12);
    }

    #[test]
    fn ljung_box_accepts_white_and_rejects_correlated() {
        let mut rng = crate::sim::rng::Rng::new(5);
        let white: Vec<f64> = (0..2000).map(|_| rng.normal()).collect();
        let (_, p) = ljung_box(&white, 20).unwrap();
        assert!(p > 0.01, "white noise p {p}");
        let mut ar = vec![0.0; 2000];
        for i in 1..2000 {
            ar[i] = 0.5 * ar[i - 1] + white[i];
        }
        let (_, p) = ljung_box(&ar, 20).unwrap();
        assert!(p < 1e-10, "AR(1) p {p}");
    }

    #[test]
    fn holm_adjusts_step_down() {
        let adj = holm(&[0.01, 0.04, 0.03, 0.5]);
        assert_eq!(adj, vec![0.04, 0.09, 0.09, 0.5]);
    }
}
