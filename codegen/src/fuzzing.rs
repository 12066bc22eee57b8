//! The spec compiler's fuzz target body, shared by cargo-fuzz (`fuzz/fuzz_targets/spec.rs`) and
//! the main crate's stable corpus test (`tests/fuzz_corpus.rs`). The property is the runtime's
//! (`sinsmodel::fuzzing`): no panic, no hang, no NaN or infinity in anything accepted.

use crate::spec::SPEC_FILES;
use crate::units::fuzz_property::{bounded, finite};
use crate::{Layout, Spec};
use std::path::Path;

/// The real spec files, in [`SPEC_FILES`] order, held fixed while one of them is fuzzed.
const REAL_SPEC: [&str; SPEC_FILES.len()] = [
    include_str!("../../model-spec/navigation.toml"),
    include_str!("../../model-spec/terms.toml"),
    include_str!("../../model-spec/measurements.toml"),
    include_str!("../../model-spec/presets.toml"),
    include_str!("../../model-spec/grades.toml"),
];

/// The model-spec compiler's front end (TOML, units, expressions, presets).
///
/// The first byte picks the file to replace (`byte % 5`, in [`SPEC_FILES`] order: `0`
/// navigation, `1` terms, `2` measurements, `3` presets, `4` grades as ASCII digits); the rest of the input
/// is its text, the other files are the real ones. Property: an accepted spec has finite
/// numbers everywhere (priors, noise densities, display factors, expression literals) and its
/// presets lay out without panicking.
pub fn spec(data: &[u8]) {
    let Some((&which, text)) = data.split_first() else {
        return;
    };
    let Ok(text) = std::str::from_utf8(text) else {
        return;
    };
    let mut texts = REAL_SPEC;
    texts[usize::from(which) % SPEC_FILES.len()] = text;
    let Ok(spec) = Spec::from_texts(Path::new("model-spec"), texts) else {
        return;
    };
    for s in &spec.nav_states {
        finite(s.sigma, &format!("state `{}` sigma", s.name));
        finite(
            s.display_to_si,
            &format!("state `{}` display factor", s.name),
        );
    }
    for e in &spec.nav_entries {
        for v in e.expr.literals() {
            finite(v, &format!("literal of `{}`", e.expr.source));
        }
    }
    for t in &spec.terms {
        finite(t.sigma, &format!("term `{}` sigma", t.name));
        finite(t.noise, &format!("term `{}` noise", t.name));
        finite(
            t.display_to_si,
            &format!("term `{}` display factor", t.name),
        );
    }
    for r in &spec.regressors {
        for v in r.expr.literals() {
            finite(v, &format!("literal of regressor `{}`", r.expr.source));
        }
        if let Ok(d) = r.expr.dimension() {
            bounded(d, &format!("regressor `{}`", r.expr.source));
        }
    }
    for m in &spec.measurements {
        finite(m.sigma, &format!("measurement `{}` sigma", m.name));
        for e in m.rows.iter().flat_map(|r| &r.h) {
            for v in e.expr.literals() {
                finite(v, &format!("literal of `{}`", e.expr.source));
            }
        }
    }
    for g in &spec.grades {
        finite(g.gyro_arw, &format!("grade `{}` gyro_arw", g.name));
        finite(g.accel_vrw, &format!("grade `{}` accel_vrw", g.name));
        for (v, t) in g.term_sigma.iter().zip(&spec.terms) {
            finite(*v, &format!("grade `{}` prior of `{}`", g.name, t.name));
        }
        for v in g.nav_sigma.iter().flatten() {
            finite(*v, &format!("grade `{}` state prior", g.name));
        }
    }
    finite(spec.sensor_noise.gyro_arw, "gyro_arw");
    finite(spec.sensor_noise.accel_vrw, "accel_vrw");
    for p in 0..spec.presets.len() {
        for vertical in [false, true] {
            let _ = Layout::preset(&spec, p, vertical);
        }
    }
}
