//! Expressions of the spec: Rust syntax parsed with `syn`, restricted to arithmetic over named
//! symbols and a few float methods, so that generated code is plain, total and readable.

use quote::ToTokens;
use std::collections::BTreeSet;

/// Navigation quantities an A or H expression may use, with what they are (SI units).
/// The generated code binds each one from `NavPoint` (see `nav_accessor`).
pub const NAV_SYMBOLS: [(&str, &str); 31] = [
    ("lat", "geodetic latitude [rad]"),
    ("h", "height above the ellipsoid, up [m]"),
    ("vn", "north velocity [m/s]"),
    ("ve", "east velocity [m/s]"),
    ("vd", "down velocity [m/s]"),
    (
        "rm",
        "meridian radius of curvature plus height, R_M + h [m]",
    ),
    (
        "rn",
        "transverse radius of curvature plus height, R_N + h [m]",
    ),
    ("omega", "Earth rotation rate [rad/s]"),
    ("f_n", "north specific force, (C f^b)_N [m/s^2]"),
    ("f_e", "east specific force [m/s^2]"),
    ("f_d", "down specific force [m/s^2]"),
    ("c11", "C_b^n element (1,1)"),
    ("c12", "C_b^n element (1,2)"),
    ("c13", "C_b^n element (1,3)"),
    ("c21", "C_b^n element (2,1)"),
    ("c22", "C_b^n element (2,2)"),
    ("c23", "C_b^n element (2,3)"),
    ("c31", "C_b^n element (3,1)"),
    ("c32", "C_b^n element (3,2)"),
    ("c33", "C_b^n element (3,3)"),
    (
        "dg_dlat",
        "normal gravity derivative by latitude [m/s^2/rad]",
    ),
    ("dg_dh", "normal gravity derivative by height [1/s^2]"),
    (
        "w_x",
        "body angular rate about x, the step mean of w^b_ib [rad/s]",
    ),
    ("w_y", "body angular rate about y [rad/s]"),
    ("w_z", "body angular rate about z [rad/s]"),
    (
        "a_n",
        "north acceleration of the solution, dv/dt over the last second [m/s^2]",
    ),
    (
        "a_e",
        "east acceleration, dv/dt over the last second [m/s^2]",
    ),
    (
        "a_d",
        "down acceleration, dv/dt over the last second [m/s^2]",
    ),
    (
        "ai_n",
        "north acceleration of the solution over the last filter step, dv/dt [m/s^2]",
    ),
    (
        "ai_e",
        "east acceleration over the last filter step [m/s^2]",
    ),
    (
        "ai_d",
        "down acceleration over the last filter step [m/s^2]",
    ),
];

/// Dimension of a navigation symbol (an H entry's unit is checked with it), doubled exponents
/// of [m, s, rad] as in [`crate::units::Dim`].
fn nav_symbol_dim(name: &str) -> Option<crate::units::Dim> {
    use crate::units::Dim;
    Some(match name {
        "lat" => Dim([0, 0, 2]),
        "h" | "rm" | "rn" => Dim([2, 0, 0]),
        "vn" | "ve" | "vd" => Dim([2, -2, 0]),
        "omega" | "w_x" | "w_y" | "w_z" => crate::units::DIM_RATE,
        "f_n" | "f_e" | "f_d" | "a_n" | "a_e" | "a_d" | "ai_n" | "ai_e" | "ai_d" => {
            crate::units::DIM_ACCEL
        }
        "dg_dlat" => Dim([2, -4, -2]),
        "dg_dh" => Dim([0, -4, 0]),
        c if c.len() == 3 && c.starts_with('c') => crate::units::DIM_ONE,
        _ => return None,
    })
}

/// Navigation-state quantities a measurement residual may use: the filter's state at the fix
/// time (SI units), with the WGS-84 radii at that state.
pub const RESIDUAL_STATE_SYMBOLS: [(&str, &str); 17] = [
    ("lat", "geodetic latitude [rad]"),
    ("lon", "longitude [rad]"),
    ("h", "height above the ellipsoid, up [m]"),
    ("vn", "north velocity [m/s]"),
    ("ve", "east velocity [m/s]"),
    ("vd", "down velocity [m/s]"),
    ("rm", "R_M + h at the state [m]"),
    ("rn", "R_N + h at the state [m]"),
    ("c11", "C_b^n element (1, 1) at the state"),
    ("c12", "C_b^n element (1, 2)"),
    ("c13", "C_b^n element (1, 3)"),
    ("c21", "C_b^n element (2, 1)"),
    ("c22", "C_b^n element (2, 2)"),
    ("c23", "C_b^n element (2, 3)"),
    ("c31", "C_b^n element (3, 1)"),
    ("c32", "C_b^n element (3, 2)"),
    ("c33", "C_b^n element (3, 3)"),
];

/// Fields of the aiding record a residual may use (`aid.lat`, …): what a position fix gives and
/// what a velocity fix gives.
pub const AID_POSITION_FIELDS: [&str; 6] = ["lat", "lon", "h", "sigma_n", "sigma_e", "sigma_d"];
/// Fields of a velocity fix (`aid.vn`, …; one 1-σ for every component).
pub const AID_VELOCITY_FIELDS: [&str; 4] = ["vn", "ve", "vd", "sigma_v"];
/// Fields of a body-frame velocity fix from a reference (odometer, DVL; `aid.vx`, …; one 1-σ
/// for every component).
pub const AID_BODY_VELOCITY_FIELDS: [&str; 4] = ["vx", "vy", "vz", "sigma_b"];
/// Fields of an attitude from a reference (a second INS, an AHRS): its frame's C_r^n row by row
/// (`aid.r11` … `aid.r33`) and the 1-σ of its tilt and of its yaw [rad].
pub const AID_ATTITUDE_FIELDS: [&str; 11] = [
    "r11",
    "r12",
    "r13",
    "r21",
    "r22",
    "r23",
    "r31",
    "r32",
    "r33",
    "sigma_tilt",
    "sigma_yaw",
];

/// Body-frame IMU signals a regressor may use: `f.x f.y f.z` [m/s²], `w.x w.y w.z` [rad/s],
/// `dw.x dw.y dw.z` [rad/s²] (angular acceleration) and `df.x df.y df.z` [m/s³] (the specific
/// force's rate of change), each derivative the change from the previous sample.
pub const IMU_SIGNALS: [&str; 4] = ["f", "w", "dw", "df"];

/// Float methods an expression may call.
pub const METHODS: [&str; 6] = ["sin", "cos", "tan", "abs", "sqrt", "powi"];

/// Where an expression is used, which decides the symbols it may reference.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ExprKind {
    /// An entry of A or H: navigation symbols only.
    Navigation,
    /// A term's regressor: IMU signals only.
    Regressor,
    /// A measurement's residual or its 1-σ: the state's quantities and the aiding record's
    /// fields (`aid.lat`, `aid.sigma_n`, …).
    Residual,
}

/// A validated expression.
#[derive(Debug, Clone)]
pub struct Expr {
    /// The expression as written in the spec (trimmed).
    pub source: String,
    /// Parsed form.
    pub ast: syn::Expr,
}

impl Expr {
    /// Canonical text (token stream), used to identify equal regressors.
    pub fn key(&self) -> String {
        self.ast.to_token_stream().to_string()
    }

    /// Symbols used: navigation names, or `f.x`-style signal names.
    pub fn symbols(&self) -> BTreeSet<String> {
        let mut out = BTreeSet::new();
        collect(&self.ast, &mut out);
        out
    }

    /// Physical dimension of a regressor expression (f in m/s², w in rad/s) or of a navigation
    /// expression (each symbol's SI unit); errors name a sum
    /// of unlike dimensions, a fractional power or a trigonometric function of a dimensioned value.
    pub fn dimension(&self) -> Result<crate::units::Dim, String> {
        dimension(&self.ast)
    }

    /// Values of the numeric literals, in source order (`powi`'s exponent included).
    pub fn literals(&self) -> Vec<f64> {
        let mut out = Vec::new();
        literals(&self.ast, &mut out);
        out
    }

    /// True when the expression is the literal `1` or `1.0`.
    pub fn is_one(&self) -> bool {
        matches!(self.source.as_str(), "1" | "1.0")
    }
}

fn collect(e: &syn::Expr, out: &mut BTreeSet<String>) {
    match e {
        syn::Expr::Path(p) => {
            if let Some(id) = p.path.get_ident() {
                out.insert(id.to_string());
            }
        }
        syn::Expr::Field(f) => {
            out.insert(f.to_token_stream().to_string().replace(' ', ""));
        }
        syn::Expr::Binary(b) => {
            collect(&b.left, out);
            collect(&b.right, out);
        }
        syn::Expr::Unary(u) => collect(&u.expr, out),
        syn::Expr::Paren(p) => collect(&p.expr, out),
        syn::Expr::MethodCall(m) => {
            collect(&m.receiver, out);
            for a in &m.args {
                collect(a, out);
            }
        }
        _ => {}
    }
}

fn literals(e: &syn::Expr, out: &mut Vec<f64>) {
    match e {
        syn::Expr::Lit(l) => match &l.lit {
            syn::Lit::Float(f) => out.extend(f.base10_parse::<f64>().ok()),
            syn::Lit::Int(i) => out.extend(i.base10_parse::<f64>().ok()),
            _ => {}
        },
        syn::Expr::Binary(b) => {
            literals(&b.left, out);
            literals(&b.right, out);
        }
        syn::Expr::Unary(u) => literals(&u.expr, out),
        syn::Expr::Paren(p) => literals(&p.expr, out),
        syn::Expr::MethodCall(m) => {
            literals(&m.receiver, out);
            for a in &m.args {
                literals(a, out);
            }
        }
        _ => {}
    }
}

fn dimension(e: &syn::Expr) -> Result<crate::units::Dim, String> {
    use crate::units::{DIM_ACCEL, DIM_ANG_ACCEL, DIM_JERK, DIM_ONE, DIM_RATE};
    match e {
        syn::Expr::Lit(_) => Ok(DIM_ONE),
        syn::Expr::Field(f) => match &*f.base {
            syn::Expr::Path(p) if p.path.is_ident("f") => Ok(DIM_ACCEL),
            syn::Expr::Path(p) if p.path.is_ident("w") => Ok(DIM_RATE),
            syn::Expr::Path(p) if p.path.is_ident("dw") => Ok(DIM_ANG_ACCEL),
            syn::Expr::Path(p) if p.path.is_ident("df") => Ok(DIM_JERK),
            _ => Err(format!("no dimension for `{}`", f.to_token_stream())),
        },
        syn::Expr::Path(p) => p
            .path
            .get_ident()
            .and_then(|i| nav_symbol_dim(&i.to_string()))
            .ok_or_else(|| format!("no dimension for `{}`", p.to_token_stream())),
        syn::Expr::Binary(b) => {
            let (l, r) = (dimension(&b.left)?, dimension(&b.right)?);
            let in_range = |d: Result<crate::units::Dim, String>| {
                d.map_err(|m| format!("`{}`: {m}", b.to_token_stream()))
            };
            match b.op {
                syn::BinOp::Mul(_) => in_range(l.times(r)),
                syn::BinOp::Div(_) => in_range(l.per(r)),
                // radians are compared loosely (an SI radian is dimensionless: omega [rad/s]
                // and v/R [1/s] add)
                _ if l.0[0] == r.0[0] && l.0[1] == r.0[1] => Ok(l),
                _ => Err(format!(
                    "`{}` adds or subtracts unlike dimensions [{l}] and [{r}]",
                    b.to_token_stream()
                )),
            }
        }
        syn::Expr::Unary(u) => dimension(&u.expr),
        syn::Expr::Paren(p) => dimension(&p.expr),
        syn::Expr::MethodCall(m) => {
            let d = dimension(&m.receiver)?;
            match m.method.to_string().as_str() {
                "abs" => Ok(d),
                "sqrt" => d
                    .sqrt()
                    .ok_or_else(|| format!("`sqrt` of [{d}] has a fractional dimension")),
                "powi" => {
                    let k = match m.args.first() {
                        Some(syn::Expr::Lit(syn::ExprLit {
                            lit: syn::Lit::Int(i),
                            ..
                        })) => i.base10_parse::<i32>().map_err(|e| e.to_string())?,
                        _ => return Err("`powi` takes one integer literal".into()),
                    };
                    d.powi(k)
                        .map_err(|e| format!("`{}`: {e}", m.to_token_stream()))
                }
                name if d.is_dimensionless_or_angle() => {
                    let _ = name;
                    Ok(DIM_ONE)
                }
                name => Err(format!("`{name}` of a dimensioned value [{d}]")),
            }
        }
        other => Err(format!("no dimension for `{}`", other.to_token_stream())),
    }
}

fn is_nav_symbol(name: &str) -> bool {
    NAV_SYMBOLS.iter().any(|(n, _)| *n == name)
}

fn nav_symbol_list() -> String {
    let v: Vec<&str> = NAV_SYMBOLS.iter().map(|(n, _)| *n).collect();
    v.join(" ")
}

/// Parses and validates an expression; the error message names the offending piece.
pub fn parse(source: &str, kind: ExprKind) -> Result<Expr, String> {
    let source = source.trim();
    let ast: syn::Expr = syn::parse_str(source)
        .map_err(|e| format!("syntax error in expression `{source}`: {e}"))?;
    check(&ast, kind).map_err(|m| format!("{m} in expression `{source}`"))?;
    let mut ast = ast;
    floatify(&mut ast);
    Ok(Expr {
        source: source.to_string(),
        ast,
    })
}

/// Turns integer literals into float literals (`2` → `2.0`) except `powi`'s exponent, so that
/// generated code is well-typed f64 arithmetic.
fn floatify(e: &mut syn::Expr) {
    match e {
        syn::Expr::Lit(l) => {
            if let syn::Lit::Int(i) = &l.lit {
                let text = format!("{}.0", i.base10_digits());
                l.lit = syn::Lit::Float(syn::LitFloat::new(&text, i.span()));
            }
        }
        syn::Expr::Binary(b) => {
            floatify(&mut b.left);
            floatify(&mut b.right);
        }
        syn::Expr::Unary(u) => floatify(&mut u.expr),
        syn::Expr::Paren(p) => floatify(&mut p.expr),
        syn::Expr::MethodCall(m) => floatify(&mut m.receiver),
        _ => {}
    }
}

/// Checks that `e` uses only what an expression of `kind` may: literals, symbols, arithmetic and
/// the allowed methods.
fn check(e: &syn::Expr, kind: ExprKind) -> Result<(), String> {
    match e {
        syn::Expr::Lit(l) => check_literal(&l.lit),
        syn::Expr::Path(p) => check_symbol(p, kind),
        syn::Expr::Field(f) => check_field(f, kind),
        syn::Expr::Binary(b) => {
            use syn::BinOp::*;
            match b.op {
                Add(_) | Sub(_) | Mul(_) | Div(_) => {}
                _ => {
                    return Err(format!(
                        "operator `{}` is not allowed",
                        b.op.to_token_stream()
                    ))
                }
            }
            check(&b.left, kind)?;
            check(&b.right, kind)
        }
        syn::Expr::Unary(u) => match u.op {
            syn::UnOp::Neg(_) => check(&u.expr, kind),
            _ => Err(format!(
                "operator `{}` is not allowed",
                u.op.to_token_stream()
            )),
        },
        syn::Expr::Paren(p) => check(&p.expr, kind),
        syn::Expr::MethodCall(m) => check_method_call(m, kind),
        other => Err(format!(
            "`{}` is not allowed (arithmetic, literals, symbols and {} only)",
            other.to_token_stream(),
            METHODS.join(" ")
        )),
    }
}

/// A literal: a plain number (no type suffix) whose value is a finite f64.
fn check_literal(lit: &syn::Lit) -> Result<(), String> {
    match lit {
        // a suffix (`1.5f32`, `2u8`) would change the generated code's types
        syn::Lit::Float(f) if !f.suffix().is_empty() => Err(format!(
            "literal `{}` has a type suffix (write plain numbers)",
            f.token()
        )),
        syn::Lit::Int(i) if !i.suffix().is_empty() => Err(format!(
            "literal `{}` has a type suffix (write plain numbers)",
            i.token()
        )),
        // the generated code writes the value as an f64 literal: it must be one
        syn::Lit::Float(f) if !f.base10_parse::<f64>().is_ok_and(f64::is_finite) => Err(format!(
            "literal `{}` is beyond the range of f64",
            f.token()
        )),
        syn::Lit::Int(i) if !i.base10_parse::<f64>().is_ok_and(f64::is_finite) => Err(format!(
            "literal `{}` is beyond the range of f64",
            i.token()
        )),
        syn::Lit::Float(_) | syn::Lit::Int(_) => Ok(()),
        _ => Err("only numeric literals are allowed".into()),
    }
}

/// A bare symbol (`lat`, `rn`): one of the symbols an expression of `kind` may use.
fn check_symbol(p: &syn::ExprPath, kind: ExprKind) -> Result<(), String> {
    let name = p
        .path
        .get_ident()
        .map(|i| i.to_string())
        .ok_or_else(|| format!("unknown symbol `{}`", p.to_token_stream()))?;
    match kind {
        ExprKind::Residual if RESIDUAL_STATE_SYMBOLS.iter().any(|(n, _)| *n == name) => Ok(()),
        ExprKind::Residual => Err(format!(
            "unknown symbol `{name}` (a residual uses {} and aid.FIELD)",
            RESIDUAL_STATE_SYMBOLS
                .iter()
                .map(|(n, _)| *n)
                .collect::<Vec<_>>()
                .join(" ")
        )),
        ExprKind::Navigation if is_nav_symbol(&name) => Ok(()),
        ExprKind::Navigation => Err(format!(
            "unknown symbol `{name}` (navigation symbols: {})",
            nav_symbol_list()
        )),
        ExprKind::Regressor => Err(format!(
            "unknown symbol `{name}` (a regressor uses f.x f.y f.z [m/s^2], w.x w.y w.z [rad/s], dw.x dw.y dw.z [rad/s^2] and df.x df.y df.z [m/s^3])"
        )),
    }
}

/// A field (`f.x`, `aid.lat`): an IMU signal's axis in a regressor, an aiding field in a
/// residual, never in a navigation expression.
fn check_field(f: &syn::ExprField, kind: ExprKind) -> Result<(), String> {
    let base = match &*f.base {
        syn::Expr::Path(p) => p.path.get_ident().map(|i| i.to_string()),
        _ => None,
    };
    let member = match &f.member {
        syn::Member::Named(i) => i.to_string(),
        syn::Member::Unnamed(_) => String::new(),
    };
    let ok_member = matches!(member.as_str(), "x" | "y" | "z");
    let aid_field = AID_POSITION_FIELDS.contains(&member.as_str())
        || AID_VELOCITY_FIELDS.contains(&member.as_str())
        || AID_BODY_VELOCITY_FIELDS.contains(&member.as_str())
        || AID_ATTITUDE_FIELDS.contains(&member.as_str());
    match (kind, base.as_deref()) {
        (ExprKind::Residual, Some("aid")) if aid_field => Ok(()),
        (ExprKind::Residual, _) => Err(format!(
            "unknown field `{}` (the aiding record has aid.{}, aid.{}, aid.{} and aid.{})",
            f.to_token_stream().to_string().replace(' ', ""),
            AID_POSITION_FIELDS.join(" aid."),
            AID_VELOCITY_FIELDS.join(" aid."),
            AID_BODY_VELOCITY_FIELDS.join(" aid."),
            AID_ATTITUDE_FIELDS.join(" aid.")
        )),
        (ExprKind::Regressor, Some(b)) if IMU_SIGNALS.contains(&b) && ok_member => Ok(()),
        (ExprKind::Regressor, _) => Err(format!(
            "unknown signal `{}` (use f.x f.y f.z, w.x w.y w.z, dw.x dw.y dw.z or df.x df.y df.z)",
            f.to_token_stream().to_string().replace(' ', "")
        )),
        (ExprKind::Navigation, _) => Err(format!(
            "unknown symbol `{}` (IMU signals belong in a term's regressor)",
            f.to_token_stream().to_string().replace(' ', "")
        )),
    }
}

/// A method call: an allowed method; `powi` with one integer literal in range, others with none.
fn check_method_call(m: &syn::ExprMethodCall, kind: ExprKind) -> Result<(), String> {
    let name = m.method.to_string();
    if !METHODS.contains(&name.as_str()) {
        return Err(format!(
            "unknown method `{name}` (allowed: {})",
            METHODS.join(" ")
        ));
    }
    if name == "powi" {
        check_powi_args(m, kind)?;
    } else if !m.args.is_empty() {
        return Err(format!("`{name}` takes no arguments"));
    }
    check(&m.receiver, kind)
}

/// `powi`'s argument: exactly one integer literal, at most `units::MAX_POWER` in magnitude.
fn check_powi_args(m: &syn::ExprMethodCall, kind: ExprKind) -> Result<(), String> {
    let ok = m.args.len() == 1
        && matches!(
            m.args.first(),
            Some(syn::Expr::Lit(syn::ExprLit {
                lit: syn::Lit::Int(_),
                ..
            }))
        );
    if !ok {
        return Err("`powi` takes one integer literal".into());
    }
    for a in &m.args {
        check(a, kind)?;
    }
    let k = match m.args.first() {
        Some(syn::Expr::Lit(syn::ExprLit {
            lit: syn::Lit::Int(i),
            ..
        })) => i.base10_parse::<i32>().ok(),
        _ => None,
    };
    if k.is_none_or(|k| k.unsigned_abs() > crate::units::MAX_POWER.unsigned_abs()) {
        return Err(format!(
            "`powi` exponent out of range (|n| <= {})",
            crate::units::MAX_POWER
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn accepts_navigation_and_regressor_expressions() {
        let e = parse(
            "-omega * lat.sin() - ve * lat.tan() / rn",
            ExprKind::Navigation,
        )
        .unwrap();
        let s = e.symbols();
        assert!(s.contains("omega") && s.contains("lat") && s.contains("rn"));
        let r = parse("-(w.y.powi(2) + w.z.powi(2))", ExprKind::Regressor).unwrap();
        assert_eq!(
            r.symbols().into_iter().collect::<Vec<_>>(),
            vec!["w.y".to_string(), "w.z".to_string()]
        );
        assert!(parse("1", ExprKind::Regressor)
            .unwrap()
            .symbols()
            .is_empty());
    }

    #[test]
    fn rejects_unknown_symbols_methods_and_syntax() {
        let e = parse("omeag * 2.0", ExprKind::Navigation).unwrap_err();
        assert!(e.contains("unknown symbol `omeag`"), "{e}");
        let e = parse("f.q", ExprKind::Regressor).unwrap_err();
        assert!(e.contains("unknown signal `f.q`"), "{e}");
        let e = parse("f.x", ExprKind::Navigation).unwrap_err();
        assert!(e.contains("unknown symbol"), "{e}");
        let e = parse("lat.exp()", ExprKind::Navigation).unwrap_err();
        assert!(e.contains("unknown method `exp`"), "{e}");
        let e = parse("lat *", ExprKind::Navigation).unwrap_err();
        assert!(e.contains("syntax error"), "{e}");
        let e = parse("lat.powi(h)", ExprKind::Navigation).unwrap_err();
        assert!(e.contains("powi"), "{e}");
        assert!(parse("vn % 2", ExprKind::Navigation).is_err());
        let e = parse("vn * 1.5f32", ExprKind::Navigation).unwrap_err();
        assert!(e.contains("literal `1.5f32` has a type suffix"), "{e}");
        // found by fuzzing: `1.01e999` was accepted and would have been written as `inf`
        let e = parse("vn * 1.01e999", ExprKind::Navigation).unwrap_err();
        assert!(
            e.contains("literal `1.01e999` is beyond the range of f64"),
            "{e}"
        );
        let big = format!("1{}", "0".repeat(400));
        let e = parse(&format!("vn * {big}"), ExprKind::Navigation).unwrap_err();
        assert!(e.contains("is beyond the range of f64"), "{e}");
        assert!(parse("vn * 1e308", ExprKind::Navigation).is_ok());
        let e = parse("w.x.powi(2u8)", ExprKind::Regressor).unwrap_err();
        assert!(e.contains("literal `2u8` has a type suffix"), "{e}");
        assert_eq!(
            parse("2 * vn.powi(3) / 0.5", ExprKind::Navigation)
                .unwrap()
                .literals(),
            [2.0, 3.0, 0.5]
        );
    }

    #[test]
    fn residual_expressions_use_the_state_and_the_aiding_record() {
        let e = parse("(lon - aid.lon) * rn * lat.cos()", ExprKind::Residual).unwrap();
        let s = e.symbols();
        assert!(s.contains("aid.lon") && s.contains("rn") && s.contains("lat"));
        let e = parse("lat - aid.latitude", ExprKind::Residual).unwrap_err();
        assert!(e.contains("unknown field `aid.latitude`"), "{e}");
        let e = parse("omega * aid.h", ExprKind::Residual).unwrap_err();
        assert!(e.contains("unknown symbol `omega`"), "{e}");
        let e = parse("f.x - aid.vn", ExprKind::Residual).unwrap_err();
        assert!(e.contains("unknown field `f.x`"), "{e}");
    }

    #[test]
    fn regressor_dimensions_are_bounded_not_wrapped() {
        // each powi is in range; nested, their dimension (s^-4 to the 12^9) used to wrap i32
        let nested = format!("w.x{}", ".powi(12)".repeat(9));
        let r = parse(&nested, ExprKind::Regressor).unwrap();
        let e = r.dimension().unwrap_err();
        assert!(e.contains("is out of range (|exponent| <= 24"), "{e}");
        let e = parse("f.x.powi(12) * f.y", ExprKind::Regressor)
            .unwrap()
            .dimension()
            .unwrap_err();
        assert!(e.contains("dimension s^-26"), "{e}");
        let r = parse("f.x.powi(6) * f.y.powi(6)", ExprKind::Regressor).unwrap();
        assert_eq!(r.dimension().unwrap().0, [24, -48, 0]);
    }
}
