//! The checked-in snapshots in `codegen/snapshots/` must equal what the spec generates now, so
//! reviewers see every change of the generated code. Refresh them with
//! `UPDATE_SNAPSHOTS=1 cargo test -p sinsmodel-codegen --test snapshots`.

use std::path::PathBuf;

#[test]
fn snapshots_are_fresh() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let spec = sinsmodel_codegen::Spec::load(&root.join("../model-spec"))
        .unwrap_or_else(|e| panic!("{e}"));
    let files = sinsmodel_codegen::generate(&spec);
    let dir = root.join("snapshots");
    let update = std::env::var_os("UPDATE_SNAPSHOTS").is_some();
    let mut stale = Vec::new();
    for f in &files {
        let path = dir.join(format!("{}.rs", f.module));
        let old = std::fs::read_to_string(&path).unwrap_or_default();
        if old != f.text {
            if update {
                std::fs::create_dir_all(&dir).unwrap();
                std::fs::write(&path, &f.text).unwrap();
            }
            stale.push(path.display().to_string());
        }
    }
    // snapshots of modules the spec no longer generates are stale too
    for entry in std::fs::read_dir(&dir).into_iter().flatten().flatten() {
        let stem = entry
            .path()
            .file_stem()
            .map(|s| s.to_string_lossy().to_string())
            .unwrap_or_default();
        if !files.iter().any(|f| f.module == stem) {
            if update {
                std::fs::remove_file(entry.path()).unwrap();
            }
            stale.push(format!("{} (no longer generated)", entry.path().display()));
        }
    }
    assert!(
        stale.is_empty() || update,
        "generated code differs from the snapshots: {stale:?}\n\
         run `UPDATE_SNAPSHOTS=1 cargo test -p sinsmodel-codegen --test snapshots` and review the diff"
    );
}
