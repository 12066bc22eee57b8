//! A model's state layout and its symbolic A(t) and H: the composition rule of DESIGN §4
//! applied to a list of states.

use crate::spec::{Sensor, Spec};
use proc_macro2::TokenStream;
use quote::{format_ident, quote};
use std::collections::BTreeSet;

/// One state of a model: a navigation state or an instrument term (indices into the spec).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StateRef {
    /// Index into `Spec::nav_states`.
    Nav(usize),
    /// Index into `Spec::terms`.
    Term(usize),
}

/// The ordered states of a model.
#[derive(Debug, Clone)]
pub struct Layout {
    /// Model name as written, e.g. `P31+vertical`.
    pub name: String,
    /// True when the vertical channel is present.
    pub vertical: bool,
    /// States in order.
    pub states: Vec<StateRef>,
}

/// A structural non-zero of A or H with its generated value expression.
#[derive(Debug, Clone)]
pub struct SymEntry {
    /// Row (model state index for A, component index for H).
    pub row: usize,
    /// Column (model state index).
    pub col: usize,
    /// Human-readable symbolic expression for the comment above the line.
    pub comment: String,
    /// Rust expression computing the value (uses bound navigation symbols and `r`).
    pub value: TokenStream,
}

impl Layout {
    /// The layout of a preset, with or without the vertical channel: all navigation states in spec
    /// order, then the preset's terms in its order.
    pub fn preset(spec: &Spec, preset: usize, vertical: bool) -> Layout {
        let p = &spec.presets[preset];
        let mut states: Vec<StateRef> = spec
            .nav_states
            .iter()
            .enumerate()
            .filter(|(_, s)| vertical || !s.vertical)
            .map(|(i, _)| StateRef::Nav(i))
            .collect();
        for name in &p.states {
            if let Some(t) = spec.term_index(name) {
                states.push(StateRef::Term(t));
            }
        }
        Layout {
            name: if vertical {
                format!("{}+vertical", p.name)
            } else {
                p.name.clone()
            },
            vertical,
            states,
        }
    }

    /// Canonical name of state `i`.
    pub fn state_name<'a>(&self, spec: &'a Spec, i: usize) -> &'a str {
        match self.states[i] {
            StateRef::Nav(k) => &spec.nav_states[k].name,
            StateRef::Term(k) => &spec.terms[k].name,
        }
    }

    /// Model index of a state by name.
    pub fn index_of(&self, spec: &Spec, name: &str) -> Option<usize> {
        (0..self.states.len()).find(|&i| self.state_name(spec, i) == name)
    }

    fn nav_pos(&self, nav: usize) -> Option<usize> {
        self.states.iter().position(|s| *s == StateRef::Nav(nav))
    }

    /// Distinct non-constant regressors (spec indices) this model accumulates, in first-use order.
    pub fn regressors(&self, spec: &Spec) -> Vec<usize> {
        let mut out = Vec::new();
        for s in &self.states {
            if let StateRef::Term(t) = s {
                let r = spec.terms[*t].regressor;
                if !spec.regressors[r].constant && !out.contains(&r) {
                    out.push(r);
                }
            }
        }
        out
    }

    /// Symbolic non-zeros of A, row-major order; term columns read the step mean of their
    /// regressor from `r[k]` (k = position in [`Layout::regressors`]).
    pub fn a_entries(&self, spec: &Spec) -> Vec<SymEntry> {
        let regs = self.regressors(spec);
        let mut out = Vec::new();
        for e in &spec.nav_entries {
            if let (Some(row), Some(col)) = (self.nav_pos(e.row), self.nav_pos(e.col)) {
                let ast = &e.expr.ast;
                out.push(SymEntry {
                    row,
                    col,
                    comment: e.expr.source.clone(),
                    value: quote!(#ast),
                });
            }
        }
        for (col, s) in self.states.iter().enumerate() {
            if let StateRef::Term(t) = s {
                let r = spec.terms[*t].regressor;
                let rval = match regs.iter().position(|&x| x == r) {
                    Some(k) => quote!(r[#k]),
                    None => quote!(r),
                };
                for (nav_row, entry) in term_column(spec, *t, rval) {
                    if let Some(row) = self.nav_pos(nav_row) {
                        out.push(SymEntry {
                            row,
                            col,
                            comment: entry.comment,
                            value: entry.value,
                        });
                    }
                }
            }
        }
        out.sort_by_key(|e| (e.row, e.col));
        out
    }

    /// Symbolic non-zeros of H for measurement `m` (rows = components), or `None` when the
    /// measurement references a navigation state this model lacks. Entries of GNSS terms the
    /// model lacks are left out (the measurement exists without them).
    pub fn h_entries(&self, spec: &Spec, m: usize) -> Option<Vec<SymEntry>> {
        let meas = &spec.measurements[m];
        let mut out = Vec::new();
        for (row, r) in meas.rows.iter().enumerate() {
            for h in &r.h {
                let col = match self.index_of(spec, &h.state) {
                    Some(c) => c,
                    None if spec.term_index(&h.state).is_some() => continue,
                    None => return None,
                };
                let ast = &h.expr.ast;
                out.push(SymEntry {
                    row,
                    col,
                    comment: h.expr.source.clone(),
                    value: quote!(#ast),
                });
            }
        }
        Some(out)
    }

    /// Structural pattern of A as (row, col) pairs.
    pub fn a_pattern(&self, spec: &Spec) -> BTreeSet<(usize, usize)> {
        self.a_entries(spec)
            .iter()
            .map(|e| (e.row, e.col))
            .collect()
    }
}

/// The column of term `t` over navigation rows (spec nav indices): DESIGN §4's rule,
/// `sign · C[row, axis] · r`, where `rval` is the token for the regressor's step mean (ignored
/// when the regressor is the constant 1).
pub fn term_column(spec: &Spec, t: usize, rval: TokenStream) -> Vec<(usize, SymEntry)> {
    let term = &spec.terms[t];
    let reg = &spec.regressors[term.regressor];
    let (rows, sign) = match term.sensor {
        Sensor::Gyro => (&spec.compose.gyro_rows, spec.compose.gyro_sign),
        Sensor::Accel => (&spec.compose.accel_rows, spec.compose.accel_sign),
        // a GNSS term enters the measurements, not A
        Sensor::Gnss | Sensor::Reference | Sensor::Attitude => return Vec::new(),
    };
    let mut out = Vec::new();
    for (k, &nav_row) in rows.iter().enumerate() {
        let c = format_ident!("c{}{}", k + 1, term.axis + 1);
        let c_text = format!("C{}{}", k + 1, term.axis + 1);
        let signed = if sign < 0 { quote!(-#c) } else { quote!(#c) };
        let sign_text = if sign < 0 { "-" } else { "" };
        let (value, comment) = if reg.expr.is_one() {
            (signed, format!("{sign_text}{c_text}"))
        } else if reg.constant {
            let ast = &reg.expr.ast;
            (
                quote!(#signed * (#ast)),
                format!("{sign_text}{c_text} * ({})", reg.expr.source),
            )
        } else {
            (
                quote!(#signed * #rval),
                format!("{sign_text}{c_text} * <{}>", reg.expr.source),
            )
        };
        out.push((
            nav_row,
            SymEntry {
                row: nav_row,
                col: 0,
                comment,
                value,
            },
        ));
    }
    out
}
