//! libFuzzer target `eval_case`: the body is `sinsmodel::fuzzing::eval_case`, shared with the stable
//! corpus test (`tests/fuzz_corpus.rs`).
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| sinsmodel::fuzzing::eval_case(data));
