//! Quantities with units at the edges (`"0.01 deg/h"`, `"50 ug"`, `"10 ppm"`), converted to SI;
//! the same parser the spec compiler uses.

pub use sinsmodel_units::{
    parse_quantity, parse_quantity_as, parse_unit, Quantity, Unit, UnitError, STANDARD_GRAVITY,
};
