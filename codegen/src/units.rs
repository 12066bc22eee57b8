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
    fn add(self, o: Dim, sign: i32) -> Dim {
        Dim([
            self.0[0] + sign * o.0[0],
            self.0[1] + sign * o.0[1],
            self.0[2] + sign * o.0[2],
        ])
    }
    fn scale(self, k: i32) -> Dim {
        Dim([self.0[0] * k, self.0[1] * k, self.0[2] * k])
    }
    /// Dimension of a product.
    pub fn times(self, o: Dim) -> Dim {
        self.add(o, 1)
    }
    /// Dimension of a quotient.
    pub fn per(self, o: Dim) -> Dim {
        self.add(o, -1)
    }
    /// Dimension raised to an integer power (|k| ≤ [`MAX_POWER`]).
    pub fn powi(self, k: i32) -> Dim {
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

/// Dimension of a specific force, m/s².
pub const DIM_ACCEL: Dim = Dim([2, -4, 0]);
/// Dimension of an angular rate, rad/s.
pub const DIM_RATE: Dim = Dim([0, -2, 2]);
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
    let acc = M.add(S, -2);
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
        "Hz" => (1.0, S.scale(-1)),
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
pub fn parse_unit(text: &str) -> Result<Unit, UnitError> {
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
        let f = parse_factor(factor).map_err(|e| UnitError(format!("unit `{t}`: {e}")))?;
        unit.to_si = if sign > 0 {
            unit.to_si * f.to_si
        } else {
            unit.to_si / f.to_si
        };
        unit.dim = unit.dim.add(f.dim, sign);
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

fn parse_factor(f: &str) -> Result<Unit, String> {
    if let Some(inner) = f.strip_prefix("sqrt(").and_then(|x| x.strip_suffix(')')) {
        let u = parse_unit(inner).map_err(|e| e.0)?;
        if u.dim.0.iter().any(|e| e % 2 != 0) {
            return Err(format!("sqrt of `{inner}` would give a quarter power"));
        }
        return Ok(Unit {
            to_si: u.to_si.sqrt(),
            dim: Dim([u.dim.0[0] / 2, u.dim.0[1] / 2, u.dim.0[2] / 2]),
        });
    }
    let (name, power) = match f.split_once('^') {
        Some((n, p)) => {
            let p: i32 = p
                .trim()
                .parse()
                .map_err(|_| format!("power `{p}` is not an integer"))?;
            if p.abs() > MAX_POWER {
                return Err(format!(
                    "power `{p}` is out of range (|power| <= {MAX_POWER})"
                ));
            }
            (n.trim(), p)
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
        dim: u.dim.scale(power),
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

/// Parses `"<number> <unit>"` (a bare number is dimensionless) into SI.
pub fn parse_quantity(text: &str) -> Result<Quantity, UnitError> {
    let t = text.trim();
    let split = t.find(|c: char| c.is_whitespace()).unwrap_or(t.len());
    let (num, unit) = t.split_at(split);
    let value: f64 = num
        .parse()
        .map_err(|_| UnitError(format!("`{t}`: `{num}` is not a number")))?;
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
        si: value * unit.to_si,
        dim: unit.dim,
    })
}

/// Parses a quantity and checks that its dimension is that of `expected_unit`; returns SI.
pub fn parse_quantity_as(text: &str, expected_unit: &str) -> Result<f64, UnitError> {
    let q = parse_quantity(text)?;
    let u = parse_unit(expected_unit)?;
    if q.dim != u.dim {
        return Err(UnitError(format!(
            "`{text}` has dimension {} but {expected_unit} ({}) is expected",
            q.dim, u.dim
        )));
    }
    Ok(q.si / u.to_si)
}

#[cfg(test)]
mod tests {
    use super::*;

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
}
