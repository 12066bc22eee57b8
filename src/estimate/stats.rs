//! Statistics of the filter's tests: χ² quantiles.

/// Wilson–Hilferty approximation of the χ² quantile with `k` degrees of freedom at normal z.
pub fn chi2_quantile(k: f64, z: f64) -> f64 {
    let a = 2.0 / (9.0 * k);
    k * (1.0 - a + z * a.sqrt()).powi(3)
}
