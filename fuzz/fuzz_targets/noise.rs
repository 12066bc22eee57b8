//! libFuzzer target `noise`: the body is `sinsmodel::fuzzing::noise`, shared with the stable
//! corpus test (`tests/fuzz_corpus.rs`).
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| sinsmodel::fuzzing::noise(data));
