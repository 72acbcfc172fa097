//! cargo-fuzz target `stl`: feeds arbitrary bytes to `fuzz_stl` of fuzz/entry.rs
//! (docs/robustness.md, "Fuzzing"); replayed by crates/umbra-geom/tests/fuzz_replay.rs.
#![no_main]

include!("../entry.rs");

libfuzzer_sys::fuzz_target!(|data: &[u8]| fuzz_stl(data));
