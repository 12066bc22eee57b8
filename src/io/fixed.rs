//! Fast fixed-point decimal formatting for large text outputs (a navigation row per IMU epoch):
//! `value` rounded to `decimals` places through integer arithmetic, identical to `{:.d$}` for
//! |value| · 10^d < 2^53.

use std::io::{self, Write};

const POW10: [f64; 13] = [
    1.0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12,
];

/// Writes `value` with `decimals` (≤ 12) digits after the point; falls back to `{:.d$}` when the
/// scaled value does not fit exactly in an integer or is not finite.
pub fn write_fixed<W: Write>(w: &mut W, value: f64, decimals: usize) -> io::Result<()> {
    let scale = POW10[decimals.min(12)];
    let scaled = (value * scale).round();
    if !scaled.is_finite() || scaled.abs() >= 9.0e15 || (value * scale - scaled).abs() == 0.5 {
        return write!(w, "{value:.decimals$}");
    }
    let neg = scaled < 0.0 || (scaled == 0.0 && value.is_sign_negative() && value != 0.0);
    let n = scaled.abs() as u64;
    let unit = scale as u64;
    let (int, frac) = (n / unit, n % unit);
    let mut buf = [0u8; 40];
    let mut k = buf.len();
    if decimals > 0 {
        let mut f = frac;
        for _ in 0..decimals {
            k -= 1;
            buf[k] = b'0' + (f % 10) as u8;
            f /= 10;
        }
        k -= 1;
        buf[k] = b'.';
    }
    let mut i = int;
    loop {
        k -= 1;
        buf[k] = b'0' + (i % 10) as u8;
        i /= 10;
        if i == 0 {
            break;
        }
    }
    if neg {
        k -= 1;
        buf[k] = b'-';
    }
    w.write_all(&buf[k..])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_std_formatting() {
        let mut rng = crate::sim::rng::Rng::new(3);
        for _ in 0..20000 {
            let v = (rng.uniform() - 0.5) * 10f64.powf(rng.uniform() * 8.0 - 3.0);
            for d in [0, 3, 4, 9] {
                let mut a = Vec::new();
                write_fixed(&mut a, v, d).unwrap();
                let b = format!("{v:.d$}");
                assert_eq!(String::from_utf8(a).unwrap(), b, "{v} {d}");
            }
        }
    }
}
