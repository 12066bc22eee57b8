//! libFuzzer target `imu_text`: the body is `sinsmodel::fuzzing::imu_text`, shared with the stable
//! corpus test (`tests/fuzz_corpus.rs`).
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| sinsmodel::fuzzing::imu_text(data));
