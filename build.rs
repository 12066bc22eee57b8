//! Compiles `model-spec/*.toml` into Rust in OUT_DIR (see the `sinsmodel-codegen` crate).

use std::path::PathBuf;

fn main() {
    let root = PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").expect("CARGO_MANIFEST_DIR"));
    let spec_dir = root.join("model-spec");
    let out_dir = PathBuf::from(std::env::var("OUT_DIR").expect("OUT_DIR"));
    println!("cargo:rerun-if-changed=model-spec");
    for f in sinsmodel_codegen::spec::SPEC_FILES {
        println!("cargo:rerun-if-changed=model-spec/{f}");
    }
    if let Err(e) = sinsmodel_codegen::build(&spec_dir, &out_dir) {
        // One line naming file, line, item and problem; no backtrace.
        eprintln!("error: model spec: {e}");
        println!("cargo:warning=model spec: {e}");
        std::process::exit(1);
    }
}
