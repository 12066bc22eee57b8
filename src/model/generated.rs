//! Code generated from `model-spec/` by `build.rs` (crate `sinsmodel-codegen`); the reviewed copy
//! of the same text is in `codegen/snapshots/`.

include!(concat!(env!("OUT_DIR"), "/models.rs"));
