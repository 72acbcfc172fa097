//! The three shared real scenes load with exactly the published triangle and vertex counts
//! (after fan triangulation, before welding). Skipped with a message when the scenes
//! directory is absent. Load times are printed (run with `--nocapture` to see them).

use std::path::PathBuf;
use std::time::Instant;
use umbra_geom::load;

fn scenes_dir() -> Option<PathBuf> {
    let dir = match std::env::var_os("UMBRA_SCENES") {
        Some(d) => PathBuf::from(d),
        None => PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/scenes"),
    };
    if dir.is_dir() {
        Some(dir)
    } else {
        eprintln!("SKIPPED: scenes directory {} not found (set UMBRA_SCENES)", dir.display());
        None
    }
}

fn check(name: &str, triangles: usize, vertices: usize) {
    let Some(dir) = scenes_dir() else { return };
    let path = dir.join(name);
    if !path.is_file() {
        eprintln!("SKIPPED: {} not found", path.display());
        return;
    }
    let start = Instant::now();
    let loaded = load::load_path_detailed(&path, &load::LoadOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    let seconds = start.elapsed().as_secs_f64();
    println!(
        "{name}: {} triangles, {} vertices, loaded in {:.3} s ({} profile)",
        loaded.mesh.triangles.len(),
        loaded.mesh.positions.len(),
        seconds,
        if cfg!(debug_assertions) { "debug" } else { "release" }
    );
    // Load speed is measured by benchmarks (docs/benchmarks.md), never asserted here.
    assert_eq!(loaded.mesh.triangles.len(), triangles, "{name} triangles");
    assert_eq!(loaded.mesh.positions.len(), vertices, "{name} vertices");
    assert!(loaded.mesh.normals.is_none(), "the shared scenes have no normals");
    assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
    let n = loaded.mesh.positions.len() as u32;
    assert!(loaded.mesh.triangles.iter().flatten().all(|&i| i < n));
    assert!(loaded.mesh.positions.iter().flatten().all(|c| c.is_finite()));
}

#[test]
fn crytek_sponza_counts() {
    check("crytek-sponza.obj.gz", 262_267, 192_870);
}

#[test]
fn conference_counts() {
    check("conference.obj.gz", 331_179, 194_399);
}

#[test]
fn sibenik_counts() {
    check("sibenik.obj.gz", 75_284, 40_981);
}
