//! The papers' own scenes, as a user sees them: `umbra verify` on Crytek Sponza, Conference
//! and Sibenik at 1280 x 720 from the default camera and light (issues 3-5: every
//! shadow-volume method exact on the shared scenes). The torture suite covers three other
//! poses per scene at 240 x 180; this is the full-size default view, where the rarer
//! precision cases (edge-on side faces, depth-limited creases) first showed up.
//!
//! Scenes come from UMBRA_SCENES (default ../shared/scenes beside the workspace); a missing
//! scene is skipped with a message. The default test runs the methods that once failed here
//! (one per family); `--ignored` runs every method:
//! `cargo test --release -p umbra-cli --test shared_scenes -- --ignored`.

use std::path::{Path, PathBuf};
use std::process::Command;

use serde_json::Value;

fn scenes_dir() -> PathBuf {
    std::env::var("UMBRA_SCENES")
        .map(PathBuf::from)
        .unwrap_or_else(|_| Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/scenes"))
}

/// Methods held to exactness (the others are measured only: docs/exactness.md).
fn must_be_exact(method: &str) -> bool {
    !(method == "none" || method.starts_with("shadow-map") || method == "all-edges-invert")
}

/// Runs `umbra verify --json` on `file` with `methods`; asserts every exact method has no
/// mismatch outside the band and band mismatches under 0.5 % of the band (issue 3's goal),
/// and that the exit status says the same. Returns the number of methods checked.
fn verify_default_view(file: &str, methods: &str) -> usize {
    let path = scenes_dir().join(file);
    if !path.is_file() {
        eprintln!("SKIPPED: {} not found (set UMBRA_SCENES)", path.display());
        return 0;
    }
    let out = Command::new(env!("CARGO_BIN_EXE_umbra"))
        .args([
            "verify",
            "--scene",
            path.to_str().expect("utf-8 path"),
            "--method",
            methods,
            "--json",
            "--explain",
            "5",
        ])
        .output()
        .expect("run umbra");
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    let reports: Vec<Value> =
        serde_json::from_str(&stdout).unwrap_or_else(|e| panic!("{file}: no JSON ({e}); stderr:\n{stderr}"));
    let mut failures = Vec::new();
    let mut checked = 0;
    for r in &reports {
        let method = r["method"].as_str().expect("method");
        let outside = r["mismatches_outside_band"].as_u64().expect("mismatches_outside_band");
        let band = r["band_samples"].as_u64().expect("band_samples");
        let band_mismatches = r["band_mismatches"].as_u64().expect("band_mismatches");
        eprintln!("{file} {method}: outside band {outside}, band mismatches {band_mismatches} / {band}");
        let samples = r["samples"].as_u64().expect("samples");
        assert!(samples > 100_000 && samples <= 1280 * 720, "{file} {method}: {samples} samples at 1280x720");
        if !must_be_exact(method) {
            continue;
        }
        checked += 1;
        if outside != 0 {
            failures.push(format!("{method}: {outside} mismatches outside the band"));
        }
        if band_mismatches * 200 >= band.max(1) {
            failures.push(format!("{method}: {band_mismatches} band mismatches of {band} band samples (>= 0.5 %)"));
        }
    }
    assert!(failures.is_empty(), "{file} at 1280x720, default view: {}\n{stderr}", failures.join("; "));
    assert_eq!(out.status.code(), Some(0), "{file}: exit status with every exact method passing\n{stderr}");
    checked
}

/// The methods that once had samples outside the band at this view (one silhouette method per
/// evaluation stage family and the per-triangle ones), before the depth-limited and edge-on
/// band classes existed.
const ONCE_FAILED: &str = "cpu-silhouette,vs-silhouette,gs-triangle,vs-triangle,ts-triangle";

#[test]
fn crytek_sponza_default_view_is_exact() {
    let n = verify_default_view("crytek-sponza.obj.gz", ONCE_FAILED);
    assert!(n == 0 || n == 5, "{n} methods checked");
}

#[test]
fn conference_default_view_is_exact() {
    let n = verify_default_view("conference.obj.gz", ONCE_FAILED);
    assert!(n == 0 || n == 5, "{n} methods checked");
}

#[test]
fn sibenik_default_view_is_exact() {
    let n = verify_default_view("sibenik.obj.gz", ONCE_FAILED);
    assert!(n == 0 || n == 5, "{n} methods checked");
}

#[test]
#[ignore = "every method on every shared scene at 1280x720: minutes; run with --ignored"]
fn every_method_on_every_shared_scene_default_view_is_exact() {
    for file in ["crytek-sponza.obj.gz", "conference.obj.gz", "sibenik.obj.gz"] {
        verify_default_view(file, "all");
    }
}
