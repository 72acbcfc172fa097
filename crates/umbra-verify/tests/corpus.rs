//! The assimp corpus rendered and verified: every OBJ, PLY, STL, glTF
//! and GLB file of Debian's `assimp-testmodels` that loads with 1 to 200,000 triangles is
//! put over a ground plane, rendered at 64 x 64 with `cpu-silhouette` and compared with the
//! CPU ray-traced reference by `umbra_verify`: 0 mismatches outside the one-pixel band.
//! (Loading every file, broken ones included, is crates/umbra-geom/tests/corpus_assimp.rs.)
//!
//! `UMBRA_ASSIMP_MODELS` overrides `/usr/share/assimp/models`; skipped with a message when
//! absent. `UMBRA_CORPUS_VERIFY_TABLE=FILE` writes the per-file numbers as a Markdown table.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use umbra_geom::load::{self, Format, LoadOptions};
use umbra_geom::{scene, weld::weld};
use umbra_gl::{create_method, Camera, ContextOptions, FrameParams, GlApi, HeadlessContext, Renderer, SceneGpu};
use umbra_verify::{verify_method, view_reference};

const SIZE: u32 = 64;
const MAX_TRIANGLES: usize = 200_000;
const METHOD: &str = "cpu-silhouette";

fn corpus_dir() -> Option<PathBuf> {
    let dir = std::env::var_os("UMBRA_ASSIMP_MODELS")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from("/usr/share/assimp/models"));
    dir.is_dir().then_some(dir)
}

fn supported(path: &Path) -> bool {
    let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("").to_ascii_lowercase();
    let name = name.strip_suffix(".gz").unwrap_or(&name);
    Path::new(name).extension().and_then(|e| e.to_str()).and_then(Format::from_extension).is_some()
}

fn collect(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else { return };
    for entry in entries.flatten() {
        let path = entry.path();
        if path.is_dir() {
            collect(&path, out);
        } else if path.is_file() && supported(&path) {
            out.push(path);
        }
    }
}

/// Camera and point light framed from the bounds: looking down at the model from the front,
/// the light above and to the side, so the model shadows itself and the ground.
fn frame(bounds: umbra_geom::Aabb) -> FrameParams {
    let c = bounds.center().map(f64::from);
    let d = f64::from(bounds.diagonal()).max(1e-3);
    let camera = Camera {
        eye: [c[0] + 0.4 * d, c[1] + 0.9 * d, c[2] + 1.3 * d],
        target: c,
        up: [0.0, 1.0, 0.0],
        fov_y_degrees: 50.0,
        near: 0.01 * d,
        ..Camera::default()
    };
    let light = [(c[0] - 0.5 * d) as f32, (c[1] + 1.5 * d) as f32, (c[2] + 0.3 * d) as f32, 1.0];
    FrameParams { camera, width: SIZE, height: SIZE, lights: vec![light], ..FrameParams::default() }
}

#[test]
fn loaded_corpus_models_render_exactly() {
    let Some(dir) = corpus_dir() else {
        eprintln!("skipped: /usr/share/assimp/models is absent (apt-get install assimp-testmodels, or set UMBRA_ASSIMP_MODELS)");
        return;
    };
    let mut files = Vec::new();
    collect(&dir, &mut files);
    files.sort();
    let ctx = HeadlessContext::with_options(ContextOptions { api: GlApi::Gl45Core, debug: true })
        .unwrap_or_else(|e| panic!("no headless GL 4.5 context: {e}"));
    let gl = ctx.gl();
    let mut renderer = Renderer::new(gl).expect("renderer").with_error_log(ctx.error_log().cloned());
    let options = LoadOptions { max_input_bytes: 256 << 20 };
    let mut rows = Vec::new();
    let mut failures = Vec::new();
    let mut verified = 0;
    for path in &files {
        let rel = path.strip_prefix(&dir).unwrap_or(path).display().to_string();
        // files that fail to load are corpus_assimp.rs's business
        let Ok(loaded) = load::load_path_detailed(path, &options) else { continue };
        let mut mesh = loaded.mesh;
        let Some(bounds) = mesh.bounds() else { continue };
        if mesh.triangles.is_empty() || mesh.triangles.len() > MAX_TRIANGLES {
            continue;
        }
        scene::add_ground(&mut mesh);
        let welded = Arc::new(weld(&mesh));
        let params = frame(bounds);
        let scene = SceneGpu::upload(gl, welded).unwrap_or_else(|e| panic!("{rel}: upload: {e}"));
        let view =
            view_reference(gl, &mut renderer, &scene, &params).unwrap_or_else(|e| panic!("{rel}: reference: {e}"));
        let mut method = create_method(METHOD).expect("registered method");
        let report = verify_method(gl, &mut renderer, &scene, method.as_mut(), &params, &view);
        method.destroy(gl);
        scene.destroy(gl);
        let report = report.unwrap_or_else(|e| panic!("{rel}: verify: {e}"));
        let m = report.metrics;
        eprintln!(
            "{rel}: {} triangles, samples {} shadowed {} band {} outside-band mismatches {}",
            mesh.triangles.len(),
            m.samples,
            m.shadowed_reference,
            m.band_samples,
            m.mismatches_outside_band
        );
        rows.push(format!(
            "| `{rel}` | {} | {} | {} | {} | {} | {} |",
            mesh.triangles.len(),
            m.samples,
            m.shadowed_reference,
            m.band_samples,
            m.mismatches,
            m.mismatches_outside_band
        ));
        if m.mismatches_outside_band != 0 {
            failures.push(format!("{rel}: {} mismatches outside the band", m.mismatches_outside_band));
        }
        verified += 1;
    }
    renderer.destroy(gl);
    eprintln!("assimp corpus: {verified} models verified with {METHOD} at {SIZE}x{SIZE}");
    if let Some(out) = std::env::var_os("UMBRA_CORPUS_VERIFY_TABLE") {
        let mut text = String::from(
            "| file | triangles (+2 ground) | samples | shadowed (reference) | band samples | mismatches | outside band |\n| --- | ---: | ---: | ---: | ---: | ---: | ---: |\n",
        );
        for r in &rows {
            text.push_str(r);
            text.push('\n');
        }
        std::fs::write(&out, text).expect("write UMBRA_CORPUS_VERIFY_TABLE");
    }
    assert!(verified > 0, "no corpus model loaded with 1..={MAX_TRIANGLES} triangles");
    assert!(failures.is_empty(), "{} models not exact:\n{}", failures.len(), failures.join("\n"));
}
