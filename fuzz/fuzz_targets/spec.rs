//! libFuzzer target `spec`: the body is `sinsmodel_codegen::fuzzing::spec`, shared with the stable
//! corpus test (`tests/fuzz_corpus.rs`).
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| sinsmodel_codegen::fuzzing::spec(data));
