//! The papers' own scenes, as a user sees them: `umbra verify` on Crytek Sponza, Conference
//! and Sibenik at 1280 x 720 from the default camera and light (every
//! shadow-volume method exact on the shared scenes). The torture suite covers three other
//! poses per scene at 240 x 180; this is the full-size default view, where the rarer
//! precision cases (edge-on side faces, depth-limited creases) occur.
//!
//! Scenes come from UMBRA_SCENES (default ../shared/scenes beside the workspace); a missing
//! scene is skipped with a message. The default test runs one method per family, each
//! the one with a pinned case here; `--ignored` runs every method:
//! `cargo test --release -p umbra-cli --test shared_scenes -- --ignored`. The whole exactness grid
//! (every exact method, default views and fly-through keyframes, four sizes, point
//! and directional lights) is `scripts/exactness_grid.py` (hours).

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

/// Runs `umbra verify --json` on `file` with `methods` at 1280x720 from the default camera;
/// see [`verify_view`].
fn verify_default_view(file: &str, methods: &str) -> usize {
    verify_view(file, methods, (1280, 720), &[])
}

/// Runs `umbra verify --json` on `file` with `methods` at `size` with the extra `args`; asserts
/// every exact method has no mismatch outside the band and band mismatches under 0.5 % of the
/// band, and that the exit status says the same. Returns the number of
/// methods checked.
fn verify_view(file: &str, methods: &str, size: (u32, u32), args: &[&str]) -> usize {
    let path = scenes_dir().join(file);
    if !path.is_file() {
        eprintln!("SKIPPED: {} not found (set UMBRA_SCENES)", path.display());
        return 0;
    }
    let size_arg = format!("{}x{}", size.0, size.1);
    let out = Command::new(env!("CARGO_BIN_EXE_umbra"))
        .args([
            "verify",
            "--scene",
            path.to_str().expect("utf-8 path"),
            "--method",
            methods,
            "--size",
            &size_arg,
            "--json",
            "--explain",
            "5",
        ])
        .args(args)
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
        let pixels = u64::from(size.0 * size.1) * (args.iter().filter(|&&a| a == "--light").count().max(1) as u64);
        assert!(samples > pixels / 10 && samples <= pixels, "{file} {method}: {samples} samples at {size_arg}");
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
    assert!(failures.is_empty(), "{file} at {size_arg} {args:?}: {}\n{stderr}", failures.join("; "));
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

/// The fly-through's first keyframe (bench/sponza.flythrough) at 1920x1080: along the
/// curtains' edges, side faces of their double-layer edges (multiplicity 2) seen 7e-4 rad from
/// edge-on pass within 1e-6 pixel of the curtain samples, which llvmpipe's plane equations
/// order differently for gs-silhouette's vertex order than for cpu-silhouette's (runs of false
/// light without the band). The envelope's side-face part makes them band
/// (docs/exactness.md); every other sample must be exact, for the default point light and a
/// directional one.
#[test]
fn crytek_sponza_flythrough_first_keyframe_at_1920x1080_is_exact() {
    let n = verify_view(
        "crytek-sponza.obj.gz",
        "gs-silhouette,cpu-silhouette",
        (1920, 1080),
        &["--eye", "-8.5,1.5,-0.3", "--target", "4.0,2.5,0.0", "--light", "default", "--light", "0.3,1,0.2,0"],
    );
    assert!(n == 0 || n == 2, "{n} methods checked");
}

/// Conference's default view at 640x360 with its default point light, pixel (114, 64):
/// every rasterizing method counts the face of a pillar's top edge there (a false shadow
/// without the band) although the face passes hundreds of units from the sample. The eye lies 0.0064
/// units from the face's plane: its projection is a sliver 0.0009 pixel from the pixel
/// centre, which llvmpipe's snapped coverage takes in, and the plane equation gives it a depth
/// in front of the sample (umbra_oracle::edge_on): band; every other sample exact.
#[test]
fn conference_default_view_at_640x360_is_exact() {
    let n = verify_view("conference.obj.gz", "cpu-silhouette,gs-triangle", (640, 360), &[]);
    assert!(n == 0 || n == 2, "{n} methods checked");
}

/// The fly-through's keyframe 6 (bench/sponza.flythrough) at 1280x720, pixel (532, 533):
/// ts-triangle's face seen edge-on there (band, as on Conference above).
#[test]
fn crytek_sponza_flythrough_keyframe_6_at_1280x720_is_exact() {
    let n = verify_view(
        "crytek-sponza.obj.gz",
        "ts-triangle",
        (1280, 720),
        &["--eye=-5.0,3.6,-0.2", "--target", "4.3,2.1,-0.2"],
    );
    assert!(n == 0 || n == 1, "{n} methods checked");
}

#[test]
#[ignore = "every method on every shared scene at 1280x720: minutes; run with --ignored"]
fn every_method_on_every_shared_scene_default_view_is_exact() {
    for file in ["crytek-sponza.obj.gz", "conference.obj.gz", "sibenik.obj.gz"] {
        verify_default_view(file, "all");
    }
}
