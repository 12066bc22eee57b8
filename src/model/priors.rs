//! Prior sets: the spec's defaults, then a sensor grade (`model-spec/grades.toml`), then the
//! user's overrides by state pattern. The grade's priors are generated from the spec, so a term
//! added to the spec has a prior under every grade with no code naming it.

use crate::model::catalog::{GradeInfo, StateRef};
use crate::model::generated::common;
use crate::model::Model;

/// A state or term named exactly (`ka_11`) or by prefix (`kaq_*`), as `--prior` and
/// `--candidates` take them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StatePattern<'a> {
    /// The name, or the prefix without its `*`.
    text: &'a str,
    /// Whether `text` is a prefix.
    prefix: bool,
}

impl<'a> StatePattern<'a> {
    /// Reads `name` or `prefix*`.
    pub fn new(pattern: &'a str) -> Self {
        match pattern.strip_suffix('*') {
            Some(text) => StatePattern { text, prefix: true },
            None => StatePattern {
                text: pattern,
                prefix: false,
            },
        }
    }

    /// Whether `name` matches.
    pub fn matches(&self, name: &str) -> bool {
        if self.prefix {
            name.starts_with(self.text)
        } else {
            name == self.text
        }
    }
}

/// The sensor grades of the spec, by name (`navigation` is the spec's own defaults, not listed).
pub fn grades() -> &'static [GradeInfo] {
    &common::GRADES
}

/// The names `--grade` takes, as a message lists them: `navigation, tactical or mems`.
pub fn grade_names() -> String {
    let names: Vec<&str> = std::iter::once("navigation")
        .chain(grades().iter().map(|g| g.name))
        .collect();
    match names.split_last() {
        Some((last, rest)) if !rest.is_empty() => format!("{} or {last}", rest.join(", ")),
        _ => "navigation".to_string(),
    }
}

/// The grade of a name: `None` for `navigation` (the spec's defaults) or no grade given.
pub fn grade(name: Option<&str>) -> Result<Option<&'static GradeInfo>, UnknownGrade> {
    match name {
        None | Some("navigation") => Ok(None),
        Some(g) => grades()
            .iter()
            .find(|x| x.name == g)
            .map(Some)
            .ok_or(UnknownGrade),
    }
}

/// A grade name that is not in `model-spec/grades.toml`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct UnknownGrade;

/// The prior 1-σ [SI] that `grade` gives state `s`; `None` where the spec's default is kept.
pub fn grade_prior(grade: &GradeInfo, s: StateRef) -> Option<f64> {
    match s {
        StateRef::Nav(i) => grade.nav_sigma[i],
        StateRef::Term(t) => Some(grade.term_sigma[t]),
    }
}

/// Writes the priors `grade` gives over `prior_sigma` (one 1-σ per state of `model`, SI); the
/// states the grade does not list keep theirs.
pub fn apply_grade(model: &Model, grade: &GradeInfo, prior_sigma: &mut [f64]) {
    for (i, s) in model.states.iter().enumerate() {
        if let Some(v) = grade_prior(grade, *s) {
            prior_sigma[i] = v;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn patterns_match_names_and_prefixes() {
        assert!(StatePattern::new("kaq_*").matches("kaq_x_xy"));
        assert!(!StatePattern::new("kaq_*").matches("ka_11"));
        assert!(StatePattern::new("ka_11").matches("ka_11"));
        assert!(!StatePattern::new("ka_1").matches("ka_11"));
        assert!(StatePattern::new("*").matches("anything"));
    }

    #[test]
    fn every_term_has_a_prior_under_every_grade() {
        assert!(!grades().is_empty());
        for g in grades() {
            for (t, info) in common::TERMS.iter().enumerate() {
                let v = g.term_sigma[t];
                assert!(v.is_finite() && v > 0.0, "{} {}", g.name, info.name);
            }
        }
        assert_eq!(grade(Some("navigation")), Ok(None));
        assert_eq!(grade(None), Ok(None));
        assert_eq!(grade(Some("consumer")), Err(UnknownGrade));
        assert_eq!(grade_names(), "navigation, tactical or mems");
    }

    #[test]
    fn grade_priors_are_the_spec_table() {
        // values as grades.toml writes them, parsed here independently of codegen
        let mems = grade(Some("mems")).unwrap().unwrap();
        let t = |n: &str| common::TERMS.iter().position(|x| x.name == n).unwrap();
        let q = |s: &str, u: &str| crate::io::units::parse_quantity_as(s, u).unwrap();
        assert_eq!(mems.term_sigma[t("eps_z")], q("0.5 deg/s", "rad/s"));
        assert_eq!(mems.term_sigma[t("kaq_x_xy")], q("5000 ug/g^2", "s^2/m"));
        assert_eq!(mems.gyro_arw, q("0.5 deg/sqrt(h)", "rad/sqrt(s)"));
        assert_eq!(mems.nav_sigma[common::PHI_D], Some(q("10 deg", "rad")));
        assert_eq!(mems.nav_sigma[common::DV_N], None);
        let tactical = grade(Some("tactical")).unwrap().unwrap();
        assert_eq!(tactical.term_sigma[t("ka_22")], q("500 ppm", "1"));
    }
}
