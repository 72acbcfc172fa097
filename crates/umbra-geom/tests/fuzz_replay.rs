//! Replays the fuzz corpus and every pinned regression input through the same entry points
//! the cargo-fuzz targets run (fuzz/entry.rs, included below), so a parser regression is
//! caught by a plain `cargo test` on every change without nightly or cargo-fuzz (why CI does
//! it this way: docs/robustness.md).
//!
//! Inputs: `fuzz/corpus/<target>/*` (the minimised corpus the fuzzer grew) and
//! `fuzz/regressions/<target>/*` (inputs that must neither crash nor hang, named after the
//! failure each pins),
//! for the targets obj, ply, stl, gltf, gzip and geometry.

include!("../../../fuzz/entry.rs");

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

fn fuzz_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../fuzz")
}

type Entry = fn(&[u8]);

const TARGETS: [(&str, Entry); 6] = [
    ("obj", fuzz_obj),
    ("ply", fuzz_ply),
    ("stl", fuzz_stl),
    ("gltf", fuzz_gltf),
    ("gzip", fuzz_gzip),
    ("geometry", fuzz_geometry),
];

/// Runs every file of `dir` through `entry`; a panic is reported with the file name.
/// Returns how many files ran.
fn replay(dir: &Path, entry: Entry, failures: &mut Vec<String>) -> usize {
    let Ok(entries) = std::fs::read_dir(dir) else { return 0 };
    let mut files: Vec<PathBuf> = entries.flatten().map(|e| e.path()).filter(|p| p.is_file()).collect();
    files.sort();
    for file in &files {
        // a file the running fuzzer just replaced by a smaller one is gone: skip it
        let Ok(data) = std::fs::read(file) else { continue };
        // Speed is not judged here (the fuzzer's own -timeout reports slow inputs while it
        // runs); a slow file is only named.
        let start = Instant::now();
        let result = std::panic::catch_unwind(|| entry(&data));
        let took = start.elapsed();
        if result.is_err() {
            failures.push(format!("{}: panicked", file.display()));
        } else if took > Duration::from_secs(1) {
            eprintln!("note: {} took {took:?}", file.display());
        }
    }
    files.len()
}

#[test]
fn fuzz_corpus_and_regressions_replay_cleanly() {
    let root = fuzz_dir();
    let mut failures = Vec::new();
    let mut total = 0;
    for (target, entry) in TARGETS {
        let corpus = replay(&root.join("corpus").join(target), entry, &mut failures);
        let regressions = replay(&root.join("regressions").join(target), entry, &mut failures);
        eprintln!("{target}: {corpus} corpus inputs, {regressions} regression inputs");
        total += corpus + regressions;
    }
    assert!(total > 0, "no fuzz inputs under {}", root.display());
    assert!(failures.is_empty(), "{} inputs failed:\n{}", failures.len(), failures.join("\n"));
}

/// The entry points themselves catch what they should: an invariant break panics.
#[test]
fn entry_points_check_what_they_claim() {
    // a strict-order mesh: one edge shared by two triangles facing opposite ways
    let mut data = Vec::new();
    for c in [0.3f32, 0.2, 4.0, 1.0] {
        data.extend(c.to_le_bytes());
    }
    data.push(3); // 4 vertices
    for p in [[0.0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, -1.0, 0.5]] {
        for c in p {
            data.extend(c.to_le_bytes());
        }
    }
    data.extend([0, 1, 2, 1, 0, 3, 0, 0, 4]); // the last triangle is dropped by weld
    fuzz_geometry(&data);
    // the loaders' error checks accept typed errors with a place
    fuzz_obj(b"v 0 0 0\nf 1 2 3\n");
    fuzz_ply(b"ply\nformat ascii 1.0\nelement vertex 4000000000\nproperty float x\nend_header\n");
    fuzz_stl(&[0u8; 10]);
    fuzz_gltf(b"{\"asset\": {\"version\": \"2.0\"}, \"nodes\": [{\"mesh\": 7}]}");
    fuzz_gzip(b"\x1f\x8b\x08\x00garbage");
    // and a loaded mesh that broke the contract would be caught
    let bad = Mesh { positions: vec![[0.0; 3]], triangles: vec![[0, 0, 1]], normals: None };
    assert!(std::panic::catch_unwind(|| check_loaded(Ok(bad), "x.obj")).is_err());
}
