//! `sinsmodel model list` and `sinsmodel model show MODEL`.

use anyhow::Result;
use clap::Subcommand;
use sinsmodel::model::catalog::StateRef;
use sinsmodel::model::generated::{common, PRESETS};
use sinsmodel::model::Model;

/// Actions of `model`.
#[derive(Subcommand)]
pub enum ModelAction {
    /// Presets and every spec term (with units and default priors).
    List,
    /// One model: states in order with units, non-zero counts and the sparsity of A.
    Show {
        /// Model, e.g. P31, P28+kaq_x_xy+kgf_xz, P31+vertical.
        model: String,
    },
}

/// Runs the action.
pub fn run(action: ModelAction) -> Result<()> {
    match action {
        ModelAction::List => {
            print!("{}", list_text());
            Ok(())
        }
        ModelAction::Show { model } => {
            let m = Model::parse(&model)?;
            print!("{}", show_text(&m));
            Ok(())
        }
    }
}

fn list_text() -> String {
    let mut s = String::from("Presets (add `+vertical` for dv_d and dh, `+TERM` for any term):\n");
    for p in PRESETS.iter().filter(|p| !p.vertical) {
        s.push_str(&format!(
            "  {:<5} {:>2} states  {}\n",
            p.name,
            p.states.len(),
            p.doc
        ));
    }
    s.push_str("\nNavigation states:\n");
    for st in common::NAV_STATES.iter() {
        s.push_str(&format!(
            "  {:<8} [{}]{}  {}\n",
            st.name,
            st.unit,
            if st.vertical { " (+vertical)" } else { "" },
            st.doc
        ));
    }
    let mut group = "";
    s.push_str("\nTerms (name, sensor axis, regressor, SI unit, default prior sigma):\n");
    for t in common::TERMS.iter() {
        if t.group != group {
            group = t.group;
            s.push_str(&format!(
                "  -- {}{}\n",
                t.group,
                if t.library { " (library)" } else { "" }
            ));
        }
        let (sensor, axis, reg) = match t.sensor {
            sinsmodel::model::catalog::Sensor::Gyro => (
                "gyro",
                ["x", "y", "z"][t.axis],
                common::REGRESSORS[t.regressor],
            ),
            sinsmodel::model::catalog::Sensor::Accel => (
                "accel",
                ["x", "y", "z"][t.axis],
                common::REGRESSORS[t.regressor],
            ),
            sinsmodel::model::catalog::Sensor::Gnss => ("gnss", "-", "enters H"),
            sinsmodel::model::catalog::Sensor::Reference => ("reference", "-", "enters H"),
            sinsmodel::model::catalog::Sensor::Attitude => ("attitude", "-", "enters H"),
        };
        s.push_str(&format!(
            "  {:<9} {} {}  <{}>  [{}]  sigma {} {}\n",
            t.name,
            sensor,
            axis,
            reg,
            t.unit,
            format_sig(t.sigma / t.display_to_si),
            t.display
        ));
    }
    s
}

fn format_sig(v: f64) -> String {
    let t = format!("{v:.6}");
    let t = t.trim_end_matches('0').trim_end_matches('.');
    if t.is_empty() || t == "-" {
        format!("{v:e}")
    } else {
        t.to_string()
    }
}

/// The text of `model show`.
pub fn show_text(m: &Model) -> String {
    let n = m.n();
    let mut s = format!("Model {}: {} states\n\n", m.name, n);
    for (i, name) in m.names.iter().enumerate() {
        let kind = match m.states[i] {
            StateRef::Nav(k) => common::NAV_STATES[k].doc,
            StateRef::Term(k) => common::TERMS[k].doc,
        };
        s.push_str(&format!(
            "  {:>2} {:<9} {:<9} {}\n",
            i,
            name,
            format!("[{}]", m.unit(i)),
            kind
        ));
    }
    s.push_str(&format!(
        "\nA: {} structural non-zeros of {} ({:.1} %)\n",
        m.a_pattern().len(),
        n * n,
        100.0 * m.a_pattern().len() as f64 / (n * n) as f64
    ));
    let nav = generic_point();
    for meas in m.measurements() {
        let mut h = vec![0.0; meas.rows.len() * n];
        let nnz = match m.fill_h(meas.name, &nav, &mut h) {
            Ok(_) => h.iter().filter(|v| **v != 0.0).count(),
            Err(_) => 0,
        };
        s.push_str(&format!(
            "H {}: {} non-zeros ({} rows: {})\n",
            meas.name,
            nnz,
            meas.rows.len(),
            meas.rows
                .iter()
                .map(|r| r.name)
                .collect::<Vec<_>>()
                .join(" ")
        ));
    }
    s.push_str("\nSparsity of A (# = structural non-zero; columns in state order):\n");
    let w = m.names.iter().map(|n| n.chars().count()).max().unwrap_or(1);
    let mut header = " ".repeat(6 + w);
    for j in 0..n {
        header.push(char::from_digit((j % 10) as u32, 10).unwrap_or('?'));
    }
    s.push_str(&header);
    s.push('\n');
    for i in 0..n {
        let mut row = format!("  {:>2} {:<w$} ", i, m.names[i]);
        for j in 0..n {
            row.push(if m.a_pattern().binary_search(&(i, j)).is_ok() {
                '#'
            } else {
                '.'
            });
        }
        s.push_str(&row);
        s.push('\n');
    }
    s
}

/// A point where no structural non-zero of H vanishes by accident.
fn generic_point() -> sinsmodel::nav::nav_point::NavPoint {
    let c = sinsmodel::nav::attitude::dcm_from_euler(0.1, 0.2, 0.3);
    let mut np = sinsmodel::nav::nav_point::NavPoint::new(
        0.5,
        100.0,
        nalgebra::Vector3::new(1.0, 2.0, 0.5),
        &c,
        &nalgebra::Vector3::new(0.3, -0.2, -9.8),
    );
    np.set_rate(&nalgebra::Vector3::new(0.05, -0.03, 0.2));
    np
}
