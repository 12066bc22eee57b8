//! sinsmodel-codegen: compiles the declarative SINS error-model spec (`model-spec/*.toml`) into
//! Rust: sparse A(t) and H fill functions, regressor accumulators and the B = Φ − I of the sparse
//! covariance kernel (whose arithmetic the main crate holds once, in `src/model/kernel.rs`) for
//! every preset (with and without the vertical channel), plus per-term column functions for
//! models composed at run time.
//!
//! Called from the main crate's `build.rs` (prost-build style): output goes to `OUT_DIR`, files are
//! written only when their content changed, and the same text is kept as reviewed snapshots in
//! `codegen/snapshots/` (checked by the `snapshots` test).

pub mod emit;
pub mod expr;
pub mod fuzzing;
pub mod grades;
pub mod layout;
pub mod spec;
/// Units and quantities: the `sinsmodel-units` crate, shared with the runtime.
pub use sinsmodel_units as units;

pub use layout::{Layout, StateRef};
pub use spec::{Spec, SpecError};

use std::path::Path;

/// One generated file: its module name, a description, and its text.
#[derive(Debug, Clone)]
pub struct GeneratedFile {
    /// Module (and file stem) name, e.g. `p31_vertical`.
    pub module: String,
    /// What it holds, e.g. `P31+vertical`.
    pub what: String,
    /// Formatted Rust source with the generated header.
    pub text: String,
}

/// Module name of a preset layout: `P31` → `p31`, `P31+vertical` → `p31_vertical`.
pub fn module_name(layout_name: &str) -> String {
    layout_name.to_lowercase().replace('+', "_")
}

/// Generates all files for a spec: `common`, one module per preset and per preset+vertical,
/// and `models` (the root that includes them).
pub fn generate(spec: &Spec) -> Vec<GeneratedFile> {
    let mut files = vec![GeneratedFile {
        module: "common".into(),
        what: "the catalogue, navigation block and per-term columns".into(),
        text: emit::common_module(spec),
    }];
    for p in 0..spec.presets.len() {
        for vertical in [false, true] {
            let layout = Layout::preset(spec, p, vertical);
            files.push(GeneratedFile {
                module: module_name(&layout.name),
                what: layout.name.clone(),
                text: emit::preset_module(spec, &layout),
            });
        }
    }
    let mods: Vec<(String, String)> = files
        .iter()
        .map(|f| (f.module.clone(), f.what.clone()))
        .collect();
    files.push(GeneratedFile {
        module: "models".into(),
        what: "the root module".into(),
        text: emit::root_module(spec, &mods),
    });
    files
}

/// Writes `text` to `path` only when the file is missing or its content differs; returns whether
/// it wrote. Writes go through a temporary file and a rename, so a reader never sees half a file.
pub fn write_if_changed(path: &Path, text: &str) -> std::io::Result<bool> {
    if std::fs::read_to_string(path).is_ok_and(|old| old == text) {
        return Ok(false);
    }
    let tmp = path.with_extension("rs.tmp");
    std::fs::write(&tmp, text)?;
    std::fs::rename(&tmp, path)?;
    Ok(true)
}

/// Build-script entry point: loads the spec in `spec_dir`, generates, writes changed files into
/// `out_dir`, and returns the generated files.
pub fn build(spec_dir: &Path, out_dir: &Path) -> Result<Vec<GeneratedFile>, SpecError> {
    let spec = Spec::load(spec_dir)?;
    let files = generate(&spec);
    for f in &files {
        let path = out_dir.join(format!("{}.rs", f.module));
        write_if_changed(&path, &f.text).map_err(|e| SpecError {
            file: path.clone(),
            line: 0,
            item: String::new(),
            message: format!("cannot write generated file: {e}"),
        })?;
    }
    Ok(files)
}
