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
