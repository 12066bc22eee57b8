//! libFuzzer target `gnss_imu_csv`: the body is `sinsmodel::fuzzing::gnss_imu_csv`, shared with the stable
//! corpus test (`tests/fuzz_corpus.rs`).
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| sinsmodel::fuzzing::gnss_imu_csv(data));
