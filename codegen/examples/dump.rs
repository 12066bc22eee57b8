fn main() {
    let spec = sinsmodel_codegen::Spec::load(std::path::Path::new("model-spec")).unwrap_or_else(|e| { eprintln!("{e}"); std::process::exit(1) });
    for f in sinsmodel_codegen::generate(&spec) { std::fs::write(format!("/tmp/gen_{}.rs", f.module), f.text).unwrap(); }
}
