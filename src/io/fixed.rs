//! Fast decimal formatting for large text outputs (a navigation row per IMU epoch), byte for
//! byte what `std`'s `{:.d$}` and `{:.d$e}` write: `value` scaled by an exact power of ten and
//! rounded through integer arithmetic; a value whose digits that cannot settle for certain (out
//! of range, not finite, within rounding error of a tie) is handed to `std` itself.

use std::io::{self, Write};

/// Writes `value` with `decimals` (≤ 12) digits after the point; falls back to `{:.d$}` when the
/// scaled value does not fit exactly in an integer or is not finite. Unlike `std`, −0.0 is
/// written without its sign (a value that rounds to zero from below keeps its `-`, as in `std`).
pub fn write_fixed<W: Write>(w: &mut W, value: f64, decimals: usize) -> io::Result<()> {
    match fixed_bytes(value, decimals) {
        Some((buf, len)) => w.write_all(&buf[..len]),
        None => write!(w, "{value:.decimals$}"),
    }
}

/// [`write_fixed`] onto the end of `out` (one copy of a fixed size per number instead of a
/// call per number: the nav.txt rows).
pub fn push_fixed(out: &mut Vec<u8>, value: f64, decimals: usize) {
    match fixed_bytes(value, decimals) {
        Some((buf, len)) => push_bytes(out, &buf, len),
        // (writing into a Vec cannot fail)
        None => drop(write!(out, "{value:.decimals$}")),
    }
}

/// Appends the first `len` bytes of `buf`: all of it is copied (a copy the compiler knows the
/// size of), then the rest is cut off again.
fn push_bytes(out: &mut Vec<u8>, buf: &[u8; NUMBER_BYTES], len: usize) {
    let start = out.len();
    out.extend_from_slice(buf);
    out.truncate(start + len);
}

/// Room for one formatted number (sign, 16 integer digits, point and 12 decimals; a scientific
/// one is shorter).
const NUMBER_BYTES: usize = 48;

/// The bytes of `{value:.decimals$}` and their count, when integer arithmetic settles them.
fn fixed_bytes(value: f64, decimals: usize) -> Option<([u8; NUMBER_BYTES], usize)> {
    let scale = *EXACT_POW10[..=12].get(decimals)?;
    let v = value * scale;
    // not finite or too large
    if v.is_nan() || v.abs() >= 9.0e15 {
        return None;
    }
    // rounded half away from zero, as f64::round, in integers: the truncation and the
    // fraction it leaves are exact below 2⁵³; a tie is left to std
    let t = v as i64;
    let f = v - t as f64;
    if f.abs() == 0.5 {
        return None;
    }
    // (|v| < 9·10¹⁵ < 2⁵³, where doubles are at most 1 apart: |scaled| < 9·10¹⁵ too)
    let scaled = t + i64::from(f > 0.5) - i64::from(f < -0.5);
    let neg = scaled < 0 || (scaled == 0 && value.is_sign_negative() && value != 0.0);
    let n = scaled.unsigned_abs();
    let unit = scale as u64;
    let (int, frac) = (n / unit, n % unit);
    // (int < 9·10¹⁵: at most 16 digits)
    let int_digits = 1 + POW10_U64[1..].iter().take_while(|&&p| int >= p).count();
    let len = usize::from(neg) + int_digits + if decimals > 0 { 1 + decimals } else { 0 };
    // written from the last digit back
    let mut buf = [0u8; NUMBER_BYTES];
    let mut k = len;
    if decimals > 0 {
        k = put_digits(&mut buf, k, frac, decimals) - 1;
        buf[k] = b'.';
    }
    k = put_digits(&mut buf, k, int, int_digits);
    if neg {
        buf[k - 1] = b'-';
    }
    Some((buf, len))
}

/// 10⁰ … 10¹⁶ as integers.
const POW10_U64: [u64; 17] = {
    let mut p = [1u64; 17];
    let mut i = 1;
    while i < 17 {
        p[i] = p[i - 1] * 10;
        i += 1;
    }
    p
};

/// "00", "01", … "99": two decimal digits at a time.
const DIGIT_PAIRS: [[u8; 2]; 100] = {
    let mut t = [[0u8; 2]; 100];
    let mut i = 0;
    while i < 100 {
        t[i] = [b'0' + (i / 10) as u8, b'0' + (i % 10) as u8];
        i += 1;
    }
    t
};

/// Writes the last `count` decimal digits of `v` (leading zeros included) to end at
/// `buf[end - 1]`, two at a time; returns where they start.
fn put_digits(buf: &mut [u8], end: usize, mut v: u64, count: usize) -> usize {
    let mut k = end;
    for _ in 0..count / 2 {
        k -= 2;
        buf[k..k + 2].copy_from_slice(&DIGIT_PAIRS[(v % 100) as usize]);
        v /= 100;
    }
    if count % 2 == 1 {
        k -= 1;
        buf[k] = b'0' + (v % 10) as u8;
    }
    k
}

/// Exact powers of ten 10⁰ … 10²² (every one is a double).
const EXACT_POW10: [f64; 23] = [
    1.0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
    1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
];

/// |value| · 10^k with one rounding (k within ±22), None beyond.
fn scaled_by_pow10(a: f64, k: i32) -> Option<f64> {
    let p = *EXACT_POW10.get(k.unsigned_abs() as usize)?;
    Some(if k >= 0 { a * p } else { a / p })
}

/// Writes `value` in scientific notation with `decimals` (≤ 12) digits after the point, the
/// bytes of `{:.decimals$e}` (`-1.2346e-5`, `0.0000e0`); digits that cannot be settled exactly
/// here are left to `std`.
pub fn write_sci<W: Write>(w: &mut W, value: f64, decimals: usize) -> io::Result<()> {
    match sci_bytes(value, decimals) {
        Some((buf, len)) => w.write_all(&buf[..len]),
        None => write!(w, "{value:.decimals$e}"),
    }
}

/// [`write_sci`] onto the end of `out` (as [`push_fixed`]).
pub fn push_sci(out: &mut Vec<u8>, value: f64, decimals: usize) {
    match sci_bytes(value, decimals) {
        Some((buf, len)) => push_bytes(out, &buf, len),
        // (writing into a Vec cannot fail)
        None => drop(write!(out, "{value:.decimals$e}")),
    }
}

/// The bytes of `{value:.decimals$e}` and their count, when [`sci_digits`] settles them.
fn sci_bytes(value: f64, decimals: usize) -> Option<([u8; NUMBER_BYTES], usize)> {
    let (digits, exp) = sci_digits(value, decimals)?;
    let mut buf = [0u8; NUMBER_BYTES];
    let mut k = 0;
    if value.is_sign_negative() {
        buf[k] = b'-';
        k += 1;
    }
    let mut d = [0u8; 13];
    let mut rest = digits;
    for slot in d[..=decimals].iter_mut().rev() {
        *slot = b'0' + (rest % 10) as u8;
        rest /= 10;
    }
    buf[k] = d[0];
    k += 1;
    if decimals > 0 {
        buf[k] = b'.';
        buf[k + 1..k + 1 + decimals].copy_from_slice(&d[1..=decimals]);
        k += 1 + decimals;
    }
    buf[k] = b'e';
    k += 1;
    if exp < 0 {
        buf[k] = b'-';
        k += 1;
    }
    let mut e = [0u8; 4];
    let mut ne = 0;
    let mut x = exp.unsigned_abs();
    loop {
        e[ne] = b'0' + (x % 10) as u8;
        ne += 1;
        x /= 10;
        if x == 0 {
            break;
        }
    }
    for c in e[..ne].iter().rev() {
        buf[k] = *c;
        k += 1;
    }
    Some((buf, k))
}

/// The `decimals + 1` significant digits of |value| as an integer and its decimal exponent, when
/// they are certain: finite non-zero value, exponent within reach of exact powers of ten, and
/// the scaled value farther from a rounding tie than 10⁻¹⁵ of its size (its one rounding is
/// within 1.2·10⁻¹⁶ of it).
fn sci_digits(value: f64, decimals: usize) -> Option<(u64, i32)> {
    if decimals > 12 || !value.is_finite() || value == 0.0 {
        return None;
    }
    let a = value.abs();
    let (lo, hi) = (EXACT_POW10[decimals], EXACT_POW10[decimals + 1]);
    // decimal exponent from the binary one (within one), then settled by the scaled value
    let e2 = ((a.to_bits() >> 52) & 0x7ff) as i32 - 1023;
    let mut exp = (f64::from(e2) * std::f64::consts::LOG10_2).floor() as i32;
    let mut scaled = scaled_by_pow10(a, decimals as i32 - exp)?;
    for _ in 0..2 {
        if scaled < lo - 1.0 {
            exp -= 1;
        } else if scaled >= hi + 1.0 {
            exp += 1;
        } else {
            break;
        }
        scaled = scaled_by_pow10(a, decimals as i32 - exp)?;
    }
    // [lo − 1, lo) and [hi − 1, hi + 1): which exponent is right is not certain here
    if scaled < lo || scaled >= hi - 1.0 {
        return None;
    }
    // integer part and fraction exactly (scaled < 10¹³ < 2⁵³), rounded to nearest
    let int = scaled as u64;
    let frac = scaled - int as f64;
    if (frac - 0.5).abs() < hi * 1e-15 {
        return None;
    }
    Some((int + u64::from(frac > 0.5), exp))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_std_formatting() {
        let mut rng = crate::sim::rng::Rng::new(3);
        let special = [
            0.0,
            1e-300,
            -1e-300,
            0.5,
            -0.5,
            2.5,
            f64::NAN,
            f64::INFINITY,
            9.1e15,
            -1e20,
        ];
        for k in 0..20000 + special.len() {
            let v = special
                .get(k.wrapping_sub(20000))
                .copied()
                .unwrap_or_else(|| (rng.uniform() - 0.5) * 10f64.powf(rng.uniform() * 8.0 - 3.0));
            // nav.txt's columns take 4, 6, 9 and 11 decimals; 13 is left to std
            for d in [0, 3, 4, 6, 9, 11, 12, 13] {
                let mut a = Vec::new();
                write_fixed(&mut a, v, d).unwrap();
                let b = format!("{v:.d$}");
                assert_eq!(String::from_utf8(a).unwrap(), b, "{v} {d}");
                let mut c = b"x ".to_vec();
                push_fixed(&mut c, v, d);
                assert_eq!(c, format!("x {b}").into_bytes(), "{v} {d}");
            }
        }
    }

    #[test]
    fn negative_zero_is_written_without_its_sign() {
        // (as every output written so far has it; std writes "-0.0000")
        let mut a = Vec::new();
        write_fixed(&mut a, -0.0, 4).unwrap();
        let mut b = Vec::new();
        push_fixed(&mut b, -0.0, 4);
        assert_eq!(
            (a.as_slice(), b.as_slice()),
            (&b"0.0000"[..], &b"0.0000"[..])
        );
    }

    #[test]
    fn scientific_matches_std_formatting() {
        let mut rng = crate::sim::rng::Rng::new(5);
        let check = |v: f64| {
            for d in [0, 1, 3, 4, 6, 9, 12] {
                let mut a = Vec::new();
                write_sci(&mut a, v, d).unwrap();
                let b = format!("{v:.d$e}");
                assert_eq!(String::from_utf8(a).unwrap(), b, "{v:e} {d}");
                let mut c = b"x ".to_vec();
                push_sci(&mut c, v, d);
                assert_eq!(c, format!("x {b}").into_bytes(), "{v:e} {d}");
            }
        };
        for _ in 0..200_000 {
            let u = rng.uniform();
            let v = (rng.uniform() - 0.5) * 10f64.powf(u * 60.0 - 30.0);
            check(v);
            // next to the powers of ten and to ties at four decimals
            let k = (u * 40.0 - 20.0).round() as i32;
            let p = 10f64.powi(k);
            check(p);
            check(f64::from_bits(p.to_bits() + 1));
            check(f64::from_bits(p.to_bits() - 1));
            check(9.99995 * p);
            check(1.00005 * p);
            check((rng.uniform() * 1e5).round() / 1e5 * p);
        }
        // the fast path, not std, writes nearly every value in the navigation rows' range
        let mut rng = crate::sim::rng::Rng::new(6);
        let fast = (0..100_000)
            .filter(|_| sci_digits(10f64.powf(rng.uniform() * 24.0 - 12.0), 4).is_some())
            .count();
        assert!(fast > 99_900, "{fast} of 100000 on the fast path");
        for v in [
            0.0,
            -0.0,
            f64::NAN,
            f64::INFINITY,
            -f64::INFINITY,
            f64::MIN_POSITIVE,
            5e-324,
            f64::MAX,
            1.0,
            -1.0,
        ] {
            check(v);
        }
    }
}
