//! Quantities with units at the edges (`"0.01 deg/h"`, `"50 ug"`, `"10 ppm"`), converted to SI;
//! the same parser the spec compiler uses.

pub use sinsmodel_units::{
    parse_quantity, parse_quantity_as, parse_unit, Quantity, Unit, UnitError, STANDARD_GRAVITY,
};

/// A number with three significant digits, plain (no exponent) where that reads well.
pub fn sig3(v: f64) -> String {
    if !v.is_finite() {
        return "not determined".into();
    }
    let a = v.abs();
    if a != 0.0 && !(1e-3..1e5).contains(&a) {
        format!("{v:.2e}")
    } else if a >= 100.0 {
        format!("{v:.0}")
    } else if a >= 10.0 {
        format!("{v:.1}")
    } else if a >= 1.0 {
        format!("{v:.2}")
    } else {
        format!("{v:.3}")
    }
}

/// A number from an option or file in a bounded form for messages: as written when that is
/// short (`0.01`, `-5`, `1e300`), else seven significant digits in exponent form (a 300-digit
/// `--alpha` is not echoed in full).
pub fn shown_number(v: f64) -> String {
    let plain = format!("{v}");
    if plain.len() <= 16 {
        return plain;
    }
    let r: f64 = format!("{v:.6e}").parse().unwrap_or(v);
    format!("{r:e}")
}

/// `a` and `b` each with three significant digits ([`sig3`]), or with as many more as it takes
/// for their magnitudes to read differently (100.001 against 100, not 100 against 100; −100.001
/// against 100 likewise).
pub fn sig_distinct(a: f64, b: f64) -> (String, String) {
    let signed = |v: f64, text: String| {
        if v < 0.0 {
            format!("-{text}")
        } else {
            text
        }
    };
    let (x, y) = (sig3(a.abs()), sig3(b.abs()));
    if x != y || a.abs() == b.abs() || !(a.is_finite() && b.is_finite()) {
        return (sig3(a), sig3(b));
    }
    // rounded to `digits` significant digits, then printed in the shortest form that reads back
    let round = |v: f64, digits: usize| -> String {
        let r: f64 = format!("{v:.prec$e}", prec = digits - 1)
            .parse()
            .unwrap_or(v);
        format!("{r}")
    };
    for digits in 4..=17 {
        let (x, y) = (round(a.abs(), digits), round(b.abs(), digits));
        if x != y {
            return (signed(a, x), signed(b, y));
        }
    }
    (format!("{a:e}"), format!("{b:e}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shown_numbers_are_bounded() {
        assert_eq!(shown_number(-5.0), "-5");
        assert_eq!(shown_number(0.01), "0.01");
        assert_eq!(shown_number(1e300), "1e300");
        assert_eq!(shown_number(1.0 / 3.0), "3.333333e-1");
        assert_eq!(shown_number(f64::INFINITY), "inf");
        assert!(shown_number(-1.234_567_890_123e200).len() <= 16);
    }

    #[test]
    fn two_values_read_differently_when_they_differ() {
        assert_eq!(
            sig_distinct(100.001, 100.0),
            ("100.001".into(), "100".into())
        );
        assert_eq!(sig_distinct(5000.0, 100.0), ("5000".into(), "100".into()));
        assert_eq!(
            sig_distinct(1000.5, 1000.0),
            ("1000.5".into(), "1000".into())
        );
        assert_eq!(
            sig_distinct(-100.001, 100.0),
            ("-100.001".into(), "100".into())
        );
    }
}
