//! cargo-fuzz target `gzip`: feeds arbitrary bytes to `fuzz_gzip` of fuzz/entry.rs
//! (docs/robustness.md, "Fuzzing"); replayed by crates/umbra-geom/tests/fuzz_replay.rs.
#![no_main]

include!("../entry.rs");

libfuzzer_sys::fuzz_target!(|data: &[u8]| fuzz_gzip(data));
