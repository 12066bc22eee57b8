//! Sensor grades (`model-spec/grades.toml`): the prior 1-σ of every state and the white sensor
//! noise that `--grade tactical|mems` selects. A term's prior under a grade comes from the term
//! (`grade_sigma` in terms.toml), else its group's entry in the grade, else the grade's rule for
//! unlisted groups (the term's navigation-grade prior times a factor per sensor), so every term,
//! a new one included, has a prior under every grade without a line of code.

use crate::spec::{quantity, NavState, Sensor, Source, SpecError, Term};
use serde::Deserialize;
use std::collections::BTreeMap;
use toml::Spanned;

/// Where a term's prior under a grade comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GradeRule {
    /// The term's own `grade_sigma` entry (terms.toml).
    Term,
    /// The grade's entry for the term's group.
    Group,
    /// The grade's factor for unlisted groups times the term's navigation-grade prior.
    Unlisted,
}

/// One sensor grade: its white noise and the prior of every state.
#[derive(Debug, Clone)]
pub struct Grade {
    /// Name as given to `--grade` (`tactical`, `mems`).
    pub name: String,
    /// What IMUs it describes.
    pub doc: String,
    /// Gyro angle random walk [rad/√s].
    pub gyro_arw: f64,
    /// The angle random walk as written in grades.toml (for messages).
    pub gyro_arw_text: String,
    /// Accelerometer velocity random walk [m/s/√s].
    pub accel_vrw: f64,
    /// The velocity random walk as written in grades.toml (for messages).
    pub accel_vrw_text: String,
    /// Prior 1-σ of each navigation state [SI], `None` where the spec's default is kept.
    pub nav_sigma: Vec<Option<f64>>,
    /// Prior 1-σ of each term [SI], in the order of the spec's terms.
    pub term_sigma: Vec<f64>,
    /// Where each term's prior comes from.
    pub term_rule: Vec<GradeRule>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawGrades {
    grade: Vec<RawGrade>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawGrade {
    name: Spanned<String>,
    doc: String,
    gyro_arw: Spanned<String>,
    accel_vrw: Spanned<String>,
    unlisted: RawUnlisted,
    #[serde(default)]
    states: BTreeMap<String, Spanned<String>>,
    #[serde(default)]
    groups: BTreeMap<String, Spanned<String>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawUnlisted {
    gyro: Spanned<f64>,
    accel: Spanned<f64>,
}

/// Reads and validates `grades.toml` against the loaded states and terms.
pub(crate) fn load(
    src: &Source,
    terms_src: &Source,
    nav_states: &[NavState],
    terms: &[Term],
) -> Result<Vec<Grade>, SpecError> {
    let raw: RawGrades = src.parse()?;
    let mut grades: Vec<Grade> = Vec::new();
    for g in &raw.grade {
        let grade = load_grade(src, g, &grades, nav_states, terms)?;
        grades.push(grade);
    }
    check_term_grades(terms_src, terms, &grades)?;
    Ok(grades)
}

/// One grade: a new name, positive factors for unlisted groups, its state and term priors.
fn load_grade(
    src: &Source,
    g: &RawGrade,
    earlier: &[Grade],
    nav_states: &[NavState],
    terms: &[Term],
) -> Result<Grade, SpecError> {
    let name = g.name.get_ref();
    let item = format!("grade `{name}`");
    crate::spec::check_name(src, &g.name, "grade")?;
    if name == "navigation" || earlier.iter().any(|x| &x.name == name) {
        return Err(src.error(
            g.name.span(),
            &item,
            "duplicate grade (`navigation` is the spec's own defaults and is not listed)",
        ));
    }
    for (sensor, f) in [("gyro", &g.unlisted.gyro), ("accel", &g.unlisted.accel)] {
        let v = *f.get_ref();
        if !(v.is_finite() && v > 0.0) {
            return Err(src.error(
                f.span(),
                &item,
                format!("unlisted.{sensor}: the factor must be positive and finite, got {v}"),
            ));
        }
    }
    let nav_sigma = grade_nav_sigma(src, g, &item, nav_states)?;
    let (term_sigma, term_rule) = grade_term_sigma(src, g, &item, terms)?;
    Ok(Grade {
        name: name.clone(),
        doc: g.doc.clone(),
        gyro_arw: quantity(src, &g.gyro_arw, "rad/sqrt(s)", &item, "gyro_arw")?,
        gyro_arw_text: g.gyro_arw.get_ref().clone(),
        accel_vrw: quantity(src, &g.accel_vrw, "m/s/sqrt(s)", &item, "accel_vrw")?,
        accel_vrw_text: g.accel_vrw.get_ref().clone(),
        nav_sigma,
        term_sigma,
        term_rule,
    })
}

/// The grade's navigation-state priors (`states`), `None` for each state it does not list.
fn grade_nav_sigma(
    src: &Source,
    g: &RawGrade,
    item: &str,
    nav_states: &[NavState],
) -> Result<Vec<Option<f64>>, SpecError> {
    let mut nav_sigma = vec![None; nav_states.len()];
    for (state, q) in &g.states {
        let Some(i) = nav_states.iter().position(|s| &s.name == state) else {
            return Err(src.error(
                q.span(),
                item,
                format!("states: no navigation state `{state}` (navigation.toml)"),
            ));
        };
        let si = quantity(
            src,
            q,
            &nav_states[i].unit,
            item,
            &format!("states.{state}"),
        )?;
        nav_sigma[i] = Some(positive(src, q, si, item, &format!("states.{state}"))?);
    }
    Ok(nav_sigma)
}

/// Every term's prior under the grade and where it comes from (term, group or unlisted rule);
/// each group the grade lists must be some term's.
fn grade_term_sigma(
    src: &Source,
    g: &RawGrade,
    item: &str,
    terms: &[Term],
) -> Result<(Vec<f64>, Vec<GradeRule>), SpecError> {
    for (group, q) in &g.groups {
        if !terms.iter().any(|t| &t.group == group) {
            return Err(src.error(
                q.span(),
                item,
                format!("groups: no term has group `{group}` (terms.toml)"),
            ));
        }
    }
    let name = g.name.get_ref();
    let mut term_sigma = Vec::with_capacity(terms.len());
    let mut term_rule = Vec::with_capacity(terms.len());
    for t in terms {
        let (si, rule) = if let Some((_, si, _)) = t.grade_sigma.iter().find(|x| &x.0 == name) {
            (*si, GradeRule::Term)
        } else if let Some(q) = g.groups.get(&t.group) {
            let field = format!("groups.\"{}\" for term `{}`", t.group, t.name);
            let si = quantity(src, q, &t.unit, item, &field)?;
            (positive(src, q, si, item, &field)?, GradeRule::Group)
        } else {
            let k = match t.sensor {
                Sensor::Gyro => *g.unlisted.gyro.get_ref(),
                Sensor::Accel => *g.unlisted.accel.get_ref(),
                // the IMU's grade says nothing about the aiding: its own prior
                Sensor::Gnss | Sensor::Reference | Sensor::Attitude => 1.0,
            };
            (t.sigma * k, GradeRule::Unlisted)
        };
        term_sigma.push(si);
        term_rule.push(rule);
    }
    Ok((term_sigma, term_rule))
}

/// A term's own `grade_sigma` entries must name grades of grades.toml.
fn check_term_grades(
    terms_src: &Source,
    terms: &[Term],
    grades: &[Grade],
) -> Result<(), SpecError> {
    for t in terms {
        for (g, _, line) in &t.grade_sigma {
            if !grades.iter().any(|x| &x.name == g) {
                return Err(SpecError {
                    file: terms_src.path.clone(),
                    line: *line,
                    item: format!("term `{}`", t.name),
                    message: format!(
                        "grade_sigma: no grade `{g}` in grades.toml (expected one of: {})",
                        grades
                            .iter()
                            .map(|x| x.name.as_str())
                            .collect::<Vec<_>>()
                            .join(", ")
                    ),
                });
            }
        }
    }
    Ok(())
}

/// `si` if it is a positive, finite prior; else an error at `q`.
fn positive(
    src: &Source,
    q: &Spanned<String>,
    si: f64,
    item: &str,
    field: &str,
) -> Result<f64, SpecError> {
    if si.is_finite() && si > 0.0 {
        Ok(si)
    } else {
        Err(src.error(
            q.span(),
            item,
            format!("{field}: a prior must be positive, got `{}`", q.get_ref()),
        ))
    }
}
