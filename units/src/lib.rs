//! Physical quantities with units at the edges: `"0.01 deg/h"`, `"50 ug"`, `"-10 ppm"`,
//! `"5e-5 s^2/m"`, `"10 ug/g^2"`, `"0.01 deg/sqrt(h)"`, converted to SI (radians) inside.
//!
//! A unit expression is a product of factors separated by `*` or `/`; a factor is a unit name,
//! optionally raised to an integer power (`s^2`), or `sqrt(name)`. Dimensions are tracked as
//! exponents of metre, second and radian (radian is kept as a dimension so that an angle rate is
//! never confused with a plain rate); half-integer exponents come from `sqrt`.

use std::fmt;

/// Standard gravity used to convert `g`, `mg`, `ug` [m/s²].
pub const STANDARD_GRAVITY: f64 = 9.806_65;

/// Dimension exponents, doubled so that `sqrt` stays integral: [metre, second, radian].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Dim(pub [i32; 3]);

impl Dim {
    /// `self + sign·o`, exponent by exponent, in i64 (no wrap) and then bounded.
    fn add(self, o: Dim, sign: i32) -> Result<Dim, String> {
        let e = |i: usize| i64::from(self.0[i]) + i64::from(sign) * i64::from(o.0[i]);
        Dim::bounded([e(0), e(1), e(2)])
    }
    /// Every exponent times `k`, in i64 (no wrap) and then bounded.
    fn scale(self, k: i32) -> Result<Dim, String> {
        let e = |i: usize| i64::from(self.0[i]) * i64::from(k);
        Dim::bounded([e(0), e(1), e(2)])
    }
    /// Doubled exponents computed in i64 back to a `Dim`, or the one that is beyond
    /// [`MAX_DIM_EXPONENT`] named.
    fn bounded(e: [i64; 3]) -> Result<Dim, String> {
        let limit = 2 * i64::from(MAX_DIM_EXPONENT);
        for (name, &x) in ["m", "s", "rad"].iter().zip(e.iter()) {
            if x.abs() > limit {
                let power = if x % 2 == 0 {
                    format!("{}", x / 2)
                } else {
                    format!("({x}/2)")
                };
                return Err(format!(
                    "dimension {name}^{power} is out of range (|exponent| <= {MAX_DIM_EXPONENT} for each of m, s, rad)"
                ));
            }
        }
        // in range: each doubled exponent fits an i32 by far
        Ok(Dim(e.map(|x| x as i32)))
    }
    /// Dimension of a product; an error when an exponent would leave ±[`MAX_DIM_EXPONENT`].
    pub fn times(self, o: Dim) -> Result<Dim, String> {
        self.add(o, 1)
    }
    /// Dimension of a quotient; an error when an exponent would leave ±[`MAX_DIM_EXPONENT`].
    pub fn per(self, o: Dim) -> Result<Dim, String> {
        self.add(o, -1)
    }
    /// Dimension raised to an integer power; an error when |k| > [`MAX_POWER`] or an exponent
    /// would leave ±[`MAX_DIM_EXPONENT`].
    pub fn powi(self, k: i32) -> Result<Dim, String> {
        if k.unsigned_abs() > MAX_POWER.unsigned_abs() {
            return Err(format!(
                "power {k} is out of range (|power| <= {MAX_POWER})"
            ));
        }
        self.scale(k)
    }
    /// Square root; None when an exponent would become fractional beyond halves.
    pub fn sqrt(self) -> Option<Dim> {
        if self.0.iter().any(|e| e % 2 != 0) {
            return None;
        }
        Some(Dim([self.0[0] / 2, self.0[1] / 2, self.0[2] / 2]))
    }
    /// True for a dimensionless quantity (radians allowed: an angle is dimensionless in SI).
    pub fn is_dimensionless_or_angle(self) -> bool {
        self.0[0] == 0 && self.0[1] == 0
    }
}

/// Largest power a unit factor or a regressor's `powi` may use.
pub const MAX_POWER: i32 = 12;

/// Largest |exponent| of metre, second or radian in any dimension that a unit, a quantity or a
/// regressor reaches (an acceleration to the twelfth power, s^-24, is the largest a single
/// `powi` can make). Bounding it keeps the exponent arithmetic far from i32 overflow.
pub const MAX_DIM_EXPONENT: i32 = 24;

/// Deepest nesting of `sqrt(...)` in a unit (`ug/sqrt(Hz)` is depth 1).
pub const MAX_SQRT_DEPTH: usize = 4;

/// Dimension of a specific force, m/s².
pub const DIM_ACCEL: Dim = Dim([2, -4, 0]);
/// Dimension of an angular rate, rad/s.
pub const DIM_RATE: Dim = Dim([0, -2, 2]);
/// Dimension of an angular acceleration, rad/s².
pub const DIM_ANG_ACCEL: Dim = Dim([0, -4, 2]);
/// Dimension of a specific force's rate of change, m/s³.
pub const DIM_JERK: Dim = Dim([2, -6, 0]);
/// Dimensionless.
pub const DIM_ONE: Dim = ONE;

impl fmt::Display for Dim {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let names = ["m", "s", "rad"];
        let mut parts = Vec::new();
        for (n, &e) in names.iter().zip(self.0.iter()) {
            match e {
                0 => {}
                2 => parts.push(n.to_string()),
                e if e % 2 == 0 => parts.push(format!("{n}^{}", e / 2)),
                e => parts.push(format!("{n}^({e}/2)")),
            }
        }
        if parts.is_empty() {
            write!(f, "1")
        } else {
            write!(f, "{}", parts.join("*"))
        }
    }
}

/// A unit: the factor that converts a value in it to SI, and its dimension.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Unit {
    /// Multiply a value in this unit by `to_si` to get SI (radians for angles).
    pub to_si: f64,
    /// Dimension of the unit.
    pub dim: Dim,
}

/// Why a quantity or unit string could not be read.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct UnitError(pub String);

impl fmt::Display for UnitError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for UnitError {}

const M: Dim = Dim([2, 0, 0]);
const S: Dim = Dim([0, 2, 0]);
const RAD: Dim = Dim([0, 0, 2]);
const ONE: Dim = Dim([0, 0, 0]);

fn base(name: &str) -> Option<Unit> {
    let acc = DIM_ACCEL;
    let deg = std::f64::consts::PI / 180.0;
    let (to_si, dim) = match name {
        "1" => (1.0, ONE),
        "ppm" => (1e-6, ONE),
        "ppb" => (1e-9, ONE),
        "m" => (1.0, M),
        "mm" => (1e-3, M),
        "cm" => (1e-2, M),
        "km" => (1e3, M),
        "s" => (1.0, S),
        "ms" => (1e-3, S),
        "us" | "µs" => (1e-6, S),
        "ns" => (1e-9, S),
        "min" => (60.0, S),
        "h" => (3600.0, S),
        "Hz" => (1.0, Dim([0, -2, 0])),
        "rad" => (1.0, RAD),
        "mrad" => (1e-3, RAD),
        "urad" => (1e-6, RAD),
        "deg" => (deg, RAD),
        "arcmin" => (deg / 60.0, RAD),
        "arcsec" => (deg / 3600.0, RAD),
        "g" => (STANDARD_GRAVITY, acc),
        "mg" => (STANDARD_GRAVITY * 1e-3, acc),
        "ug" | "µg" => (STANDARD_GRAVITY * 1e-6, acc),
        "gal" => (1e-2, acc),
        _ => return None,
    };
    Some(Unit { to_si, dim })
}

/// Parses a unit expression such as `deg/h`, `s^2/m`, `ug/sqrt(Hz)`, `rad*s/m`.
///
/// Refused with a message: unknown names, a power beyond ±[`MAX_POWER`], a dimension exponent
/// beyond ±[`MAX_DIM_EXPONENT`], `sqrt` nested deeper than [`MAX_SQRT_DEPTH`], and a conversion
/// factor to SI that is not a normal f64 (it overflowed to infinity or underflowed to zero).
pub fn parse_unit(text: &str) -> Result<Unit, UnitError> {
    parse_unit_at(text, 0)
}

/// [`parse_unit`] inside `depth` enclosing `sqrt(...)`.
fn parse_unit_at(text: &str, depth: usize) -> Result<Unit, UnitError> {
    let t = text.trim();
    if t.is_empty() {
        return Err(UnitError("empty unit".into()));
    }
    let mut unit = Unit {
        to_si: 1.0,
        dim: ONE,
    };
    let mut rest = t;
    let mut sign = 1;
    loop {
        let end = next_operator(rest);
        let factor = rest[..end].trim();
        let f = parse_factor(factor, depth).map_err(|e| UnitError(format!("unit `{t}`: {e}")))?;
        unit.to_si = if sign > 0 {
            unit.to_si * f.to_si
        } else {
            unit.to_si / f.to_si
        };
        if !unit.to_si.is_normal() {
            return Err(UnitError(format!(
                "unit `{t}`: its factor to SI is out of the range of f64 (overflows or underflows)"
            )));
        }
        unit.dim = unit
            .dim
            .add(f.dim, sign)
            .map_err(|e| UnitError(format!("unit `{t}`: {e}")))?;
        if end == rest.len() {
            break;
        }
        sign = if rest.as_bytes()[end] == b'/' { -1 } else { 1 };
        rest = &rest[end + 1..];
    }
    Ok(unit)
}

/// Index of the next `*` or `/` outside parentheses, or the length of `s`.
fn next_operator(s: &str) -> usize {
    let mut depth = 0;
    for (i, c) in s.char_indices() {
        match c {
            '(' => depth += 1,
            ')' => depth -= 1,
            '*' | '/' if depth == 0 => return i,
            _ => {}
        }
    }
    s.len()
}

/// One factor: `name`, `name^n` or `sqrt(unit)`, inside `depth` enclosing `sqrt`.
fn parse_factor(f: &str, depth: usize) -> Result<Unit, String> {
    if let Some(inner) = f.strip_prefix("sqrt(").and_then(|x| x.strip_suffix(')')) {
        if depth >= MAX_SQRT_DEPTH {
            return Err(format!("`sqrt` nested deeper than {MAX_SQRT_DEPTH} levels"));
        }
        let u = parse_unit_at(inner, depth + 1).map_err(|e| e.0)?;
        let dim = u
            .dim
            .sqrt()
            .ok_or_else(|| format!("sqrt of `{inner}` would give a quarter power"))?;
        return Ok(Unit {
            to_si: u.to_si.sqrt(),
            dim,
        });
    }
    let (name, power) = match f.split_once('^') {
        Some((n, p)) => {
            // parsed wide, so that no written power can wrap before the range check
            let p: i64 = p
                .trim()
                .parse()
                .map_err(|_| format!("power `{p}` is not an integer"))?;
            if p.abs() > i64::from(MAX_POWER) {
                return Err(format!(
                    "power `{p}` is out of range (|power| <= {MAX_POWER})"
                ));
            }
            (n.trim(), p as i32)
        }
        None => (f, 1),
    };
    let u = base(name).ok_or_else(|| {
        format!(
            "unknown unit `{name}` (known: 1 ppm ppb m mm cm km s ms us ns min h Hz rad mrad urad deg \
             arcmin arcsec g mg ug gal, combined with * / ^n sqrt())"
        )
    })?;
    Ok(Unit {
        to_si: u.to_si.powi(power),
        dim: u.dim.powi(power)?,
    })
}

/// A value with its unit, as written: `"0.01 deg/h"`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Quantity {
    /// The value converted to SI.
    pub si: f64,
    /// Dimension of the value.
    pub dim: Dim,
}

/// Checks a value converted to SI: finite, and not a non-zero value that underflowed (to zero
/// or to a subnormal, where f64 has lost its precision). `what` is the quantity as written.
fn check_si(si: f64, written_nonzero: bool, what: &str) -> Result<f64, UnitError> {
    if !si.is_finite() {
        return Err(UnitError(format!(
            "`{what}` is too large: it overflows f64 in SI units"
        )));
    }
    if written_nonzero && !si.is_normal() {
        return Err(UnitError(format!(
            "`{what}` is too small: it underflows f64 in SI units (|value| < {:e})",
            f64::MIN_POSITIVE
        )));
    }
    Ok(si)
}

/// Length in bytes of the decimal number `s` starts with: sign, digits, a point, digits, and an
/// exponent only when digits follow it (`2e-3ms` → `2e-3`, `2em` → `2`).
fn numeric_prefix(s: &str) -> usize {
    let b = s.as_bytes();
    let digits = |mut i: usize| {
        while i < b.len() && b[i].is_ascii_digit() {
            i += 1;
        }
        i
    };
    let mut i = usize::from(matches!(b.first(), Some(b'+' | b'-')));
    let start = i;
    i = digits(i);
    if b.get(i) == Some(&b'.') {
        i = digits(i + 1);
    }
    if i == start {
        return 0;
    }
    if matches!(b.get(i), Some(b'e' | b'E')) {
        let j = i + 1 + usize::from(matches!(b.get(i + 1), Some(b'+' | b'-')));
        let k = digits(j);
        if k > j {
            i = k;
        }
    }
    i
}

/// Parses `"<number> <unit>"` (a bare number is dimensionless) into SI.
///
/// Refused with a message: a number that is not finite, a unit [`parse_unit`] refuses, and a
/// value that overflows f64 in SI or, when not written as zero, underflows (`1e-320 m`).
pub fn parse_quantity(text: &str) -> Result<Quantity, UnitError> {
    let t = text.trim();
    let split = t.find(|c: char| c.is_whitespace()).unwrap_or(t.len());
    let (num, unit) = t.split_at(split);
    let value: f64 = num.parse().map_err(|_| {
        // a unit glued to its number (`2ms`): the number and the unit need a space between
        let digits = numeric_prefix(num);
        if digits > 0 && num[..digits].parse::<f64>().is_ok() && parse_unit(&num[digits..]).is_ok()
        {
            UnitError(format!(
                "`{t}`: write a space between the number and its unit (`{} {}`)",
                &num[..digits],
                &num[digits..]
            ))
        } else {
            UnitError(format!("`{t}`: `{num}` is not a number"))
        }
    })?;
    if !value.is_finite() {
        return Err(UnitError(format!("`{t}`: value is not finite")));
    }
    let unit = if unit.trim().is_empty() {
        Unit {
            to_si: 1.0,
            dim: ONE,
        }
    } else {
        parse_unit(unit)?
    };
    Ok(Quantity {
        si: check_si(value * unit.to_si, value != 0.0, t)?,
        dim: unit.dim,
    })
}

/// Parses a quantity and checks that its dimension is that of `expected_unit`; returns the value
/// in `expected_unit` (SI when that unit is SI), finite, and normal unless written as zero.
pub fn parse_quantity_as(text: &str, expected_unit: &str) -> Result<f64, UnitError> {
    let q = parse_quantity(text)?;
    let u = parse_unit(expected_unit)?;
    if q.dim != u.dim {
        return Err(UnitError(format!(
            "`{text}` has dimension {} but {expected_unit} ({}) is expected",
            q.dim, u.dim
        )));
    }
    check_si(q.si / u.to_si, q.si != 0.0, text.trim())
}

/// The fuzz targets' properties on numbers and dimensions, shared by the runtime's
/// (`sinsmodel::fuzzing`) and the spec compiler's (`sinsmodel_codegen::fuzzing`) targets.
pub mod fuzz_property {
    use super::{Dim, MAX_DIM_EXPONENT};

    /// Panics naming `what` unless `v` is finite.
    pub fn finite(v: f64, what: &str) {
        assert!(v.is_finite(), "accepted {what} = {v} is not finite");
    }

    /// Panics unless every exponent of `d` is within the documented bound (no wrapped
    /// arithmetic).
    pub fn bounded(d: Dim, what: &str) {
        assert!(
            d.0.iter().all(|e| e.abs() <= 2 * MAX_DIM_EXPONENT),
            "accepted {what} has dimension exponents {:?} beyond ±{MAX_DIM_EXPONENT}",
            d.0
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_unit_glued_to_its_number_is_refused_asking_for_a_space() {
        let e = parse_quantity("2ms").unwrap_err().0;
        assert!(
            e.contains("write a space between the number and its unit (`2 ms`)"),
            "{e}"
        );
        let e = parse_quantity("1e-9mm").unwrap_err().0;
        assert!(e.contains("(`1e-9 mm`)"), "{e}");
        let e = parse_quantity("-0.5deg/h").unwrap_err().0;
        assert!(e.contains("(`-0.5 deg/h`)"), "{e}");
        // no number, or no unit after it: as before
        let e = parse_quantity("abc ms").unwrap_err().0;
        assert!(e.contains("`abc` is not a number"), "{e}");
        let e = parse_quantity("2xyz").unwrap_err().0;
        assert!(e.contains("`2xyz` is not a number"), "{e}");
        assert_eq!(numeric_prefix("2em"), 1);
        assert_eq!(numeric_prefix("+.5e+3x"), 6);
        assert_eq!(numeric_prefix("ms"), 0);
    }

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() <= 1e-12 * b.abs().max(1e-300)
    }

    #[test]
    fn converts_edge_units_to_si() {
        let deg_h = std::f64::consts::PI / 180.0 / 3600.0;
        assert!(close(
            parse_quantity_as("0.01 deg/h", "rad/s").unwrap(),
            0.01 * deg_h
        ));
        assert!(close(
            parse_quantity_as("50 ug", "m/s^2").unwrap(),
            50e-6 * STANDARD_GRAVITY
        ));
        assert!(close(parse_quantity_as("-10 ppm", "1").unwrap(), -1e-5));
        assert!(close(
            parse_quantity_as("5e-5 s^2/m", "s^2/m").unwrap(),
            5e-5
        ));
        assert!(close(
            parse_quantity_as("10 ug/g^2", "s^2/m").unwrap(),
            10e-6 / STANDARD_GRAVITY
        ));
        assert!(close(
            parse_quantity_as("0.01 deg/sqrt(h)", "rad/sqrt(s)").unwrap(),
            0.01 * std::f64::consts::PI / 180.0 / 60.0
        ));
        assert!(close(
            parse_quantity_as("10 ug/sqrt(Hz)", "m/s/sqrt(s)").unwrap(),
            10e-6 * STANDARD_GRAVITY
        ));
        assert!(close(parse_quantity_as("10 mm", "m").unwrap(), 0.01));
    }

    #[test]
    fn rejects_wrong_dimension_and_unknown_units() {
        let e = parse_quantity_as("0.01 m/s", "rad/s").unwrap_err();
        assert!(e.0.contains("dimension"), "{e}");
        let e = parse_quantity_as("3 furlong", "m").unwrap_err();
        assert!(e.0.contains("unknown unit `furlong`"), "{e}");
        assert!(parse_quantity_as("abc deg", "rad").is_err());
        assert!(parse_quantity_as("NaN deg", "rad").is_err());
        assert!(parse_quantity_as("1 s^x", "s").is_err());
    }

    #[test]
    fn exponents_are_bounded_not_wrapped() {
        // i32::MIN as a power: its absolute value used to wrap, and s^-2147483648 times the
        // doubled exponent of s wrapped to 0, so `rad*s^-2147483648` read as plain rad
        for text in [
            "1 rad*s^2147483647",
            "1 rad*s^-2147483648",
            "1 s^99999999999",
        ] {
            let e = parse_quantity_as(text, "rad").unwrap_err();
            assert!(
                e.0.contains("power") && e.0.contains("out of range"),
                "{text}: {e}"
            );
        }
        let e = parse_unit("s^13").unwrap_err();
        assert!(e.0.contains("power `13` is out of range"), "{e}");
        // each written power is in range, their product is not
        let e = parse_unit("s^12*s^12*s").unwrap_err();
        assert!(
            e.0.contains("dimension s^25 is out of range (|exponent| <= 24"),
            "{e}"
        );
        assert_eq!(parse_unit("s^12*s^12").unwrap().dim, Dim([0, 48, 0]));
        let e = parse_unit("1/s^12/s^12/s").unwrap_err();
        assert!(e.0.contains("dimension s^-25"), "{e}");
        // the same bound for regressor dimensions and powers
        assert!(DIM_ACCEL.powi(12).is_ok());
        assert!(DIM_ACCEL.powi(13).unwrap_err().contains("power 13"));
        assert!(DIM_ACCEL.powi(i32::MIN).is_err());
        let e = DIM_ACCEL.powi(12).unwrap().times(DIM_RATE).unwrap_err();
        assert!(e.contains("dimension s^-25"), "{e}");
    }

    #[test]
    fn sqrt_nesting_is_bounded() {
        assert!(parse_unit("sqrt(sqrt(sqrt(sqrt(1))))").is_ok());
        let e = parse_unit("sqrt(sqrt(sqrt(sqrt(sqrt(1)))))").unwrap_err();
        assert!(e.0.contains("`sqrt` nested deeper than 4 levels"), "{e}");
        let deep = format!("{}1{}", "sqrt(".repeat(100_000), ")".repeat(100_000));
        assert!(parse_unit(&deep).is_err());
    }

    #[test]
    fn non_finite_and_underflowing_values_are_refused() {
        let e = parse_quantity("1e308 g").unwrap_err();
        assert!(
            e.0.contains("`1e308 g` is too large: it overflows f64"),
            "{e}"
        );
        let e = parse_quantity_as("1e308 km", "m").unwrap_err();
        assert!(e.0.contains("too large"), "{e}");
        let e = parse_quantity("1e-320 m").unwrap_err();
        assert!(
            e.0.contains("`1e-320 m` is too small: it underflows f64"),
            "{e}"
        );
        let e = parse_quantity("1e-300 ppb").unwrap_err();
        assert!(e.0.contains("too small"), "{e}");
        // a value in range whose expected unit moves it out of range
        let e = parse_quantity_as("1e300 m", "ppb*mm^12").unwrap_err();
        assert!(
            e.0.contains("dimension") || e.0.contains("too large"),
            "{e}"
        );
        assert!(parse_quantity("1e999 m").is_err());
        assert!(parse_quantity("inf m").is_err());
        assert!(parse_quantity("-inf").is_err());
        // zero stays zero, of either sign
        assert_eq!(parse_quantity_as("0 deg/h", "rad/s").unwrap(), 0.0);
        assert_eq!(parse_quantity_as("-0 ug", "m/s^2").unwrap(), 0.0);
        // a unit whose factor to SI leaves f64 is refused whatever the value
        let e = parse_unit("ppb^12*ppb^12*ppb^12").unwrap_err();
        assert!(
            e.0.contains("factor to SI is out of the range of f64"),
            "{e}"
        );
        let e = parse_unit("km^12*km^12*km^12*km^12*km^12*km^12*km^12*km^12*km^12").unwrap_err();
        assert!(
            e.0.contains("factor to SI") || e.0.contains("dimension"),
            "{e}"
        );
        let e = parse_unit("1/ppb^12/ppb^12/ppb^12").unwrap_err();
        assert!(
            e.0.contains("factor to SI is out of the range of f64"),
            "{e}"
        );
    }
}
