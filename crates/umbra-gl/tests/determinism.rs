//! Determinism and concurrency (the guide's "the same input gives the
//! same PNG bytes"):
//! * every method rendering the same frame twice — on one context, and on a second
//!   context — gives byte-identical PNG files (written by `RgbaImage::save_png`);
//! * the CPU preprocessing (weld, edge adjacency, CPU silhouettes) is parallel with rayon:
//!   a child process of this test binary limited to one rayon thread
//!   (`RAYON_NUM_THREADS=1`, read by rayon's global pool, which every umbra call uses)
//!   renders the same PNG bytes as this process with the default pool (one thread per
//!   core);
//! * several threads, each with its own `HeadlessContext`, rendering different scenes at
//!   the same time give the same PNG bytes as the same renders one after another.

mod common;

use common::*;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use umbra_geom::{scene, weld::weld, WeldedMesh};
use umbra_gl::{FrameParams, HeadlessContext};

/// Where the PNGs of this test go.
fn out_dir(sub: &str) -> PathBuf {
    let dir = output_dir().join("determinism").join(sub);
    std::fs::create_dir_all(&dir).expect("create the determinism output directory");
    dir
}

/// Renders and encodes one frame as PNG bytes (through a file, as users get them).
fn png_bytes(ctx: &HeadlessContext, mesh: &Arc<WeldedMesh>, method: &str, p: &FrameParams, path: &Path) -> Vec<u8> {
    let images = render_once(ctx, mesh, method, p);
    images.rgba.save_png(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// The frame every method renders: sphere over ground, a point light, 96 x 96.
fn frame() -> FrameParams {
    FrameParams { capture: Default::default(), ..params(default_camera(), vec![POINT_LIGHT], 96, 96) }
}

/// An image that is not trivially uniform: the frame shows ground, shadow and sphere.
fn distinct_colours(png: &[u8]) -> usize {
    let decoder = png::Decoder::new(std::io::Cursor::new(png));
    let mut reader = decoder.read_info().expect("our own PNG decodes");
    let mut buf = vec![0; reader.output_buffer_size().expect("sized PNG")];
    let info = reader.next_frame(&mut buf).expect("one frame");
    let mut colours: Vec<&[u8]> = buf[..info.buffer_size()].chunks_exact(4).collect();
    colours.sort_unstable();
    colours.dedup();
    colours.len()
}

#[test]
fn same_render_twice_gives_identical_png_bytes() {
    let mesh = sphere_over_ground();
    let p = frame();
    let dir = out_dir("twice");
    let first_ctx = context();
    let mut first = Vec::new();
    for method in shadow_methods() {
        let a = png_bytes(&first_ctx, &mesh, method, &p, &dir.join(format!("{method}-a.png")));
        let b = png_bytes(&first_ctx, &mesh, method, &p, &dir.join(format!("{method}-b.png")));
        assert!(distinct_colours(&a) > 3, "{method}: the frame is (nearly) uniform");
        assert!(a == b, "{method}: two renders on one context give different PNG bytes (see {})", dir.display());
        first.push((method, a));
    }
    drop(first_ctx);
    // a fresh context (new programs, buffers, render targets) renders the same bytes
    let second_ctx = context();
    for (method, a) in first {
        let c = png_bytes(&second_ctx, &mesh, method, &p, &dir.join(format!("{method}-c.png")));
        assert!(a == c, "{method}: a second context renders different PNG bytes (see {})", dir.display());
    }
}

/// The scene for the rayon comparison: a 6 x 6 grid of spheres over a plane (~30k
/// triangles), large enough that weld, adjacency and the CPU silhouette split their work
/// differently with one thread and with several.
fn rayon_scene() -> Arc<WeldedMesh> {
    let mut mesh = scene::load_scene("spheres:6:30000").expect("procedural scene");
    scene::add_ground(&mut mesh);
    Arc::new(weld(&mesh))
}

fn rayon_frame(mesh: &WeldedMesh) -> FrameParams {
    let b = mesh.positions.iter().fold(([f32::MAX; 3], [f32::MIN; 3]), |(lo, hi), p| {
        ([0, 1, 2].map(|k| lo[k].min(p[k])), [0, 1, 2].map(|k| hi[k].max(p[k])))
    });
    let c = [0, 1, 2].map(|k| 0.5 * (f64::from(b.0[k]) + f64::from(b.1[k])));
    let r = (0..3).map(|k| f64::from(b.1[k] - b.0[k])).fold(0.0, f64::max);
    let camera = umbra_gl::Camera {
        eye: [c[0] + 0.2 * r, c[1] + 0.8 * r, c[2] + 0.9 * r],
        target: c,
        up: [0.0, 1.0, 0.0],
        fov_y_degrees: 50.0,
        near: 0.01 * r,
        ..umbra_gl::Camera::default()
    };
    FrameParams {
        capture: Default::default(),
        ..params(camera, vec![[(c[0] + 0.3 * r) as f32, (c[1] + 0.7 * r) as f32, c[2] as f32, 1.0]], 96, 96)
    }
}

/// The methods compared across rayon pools: every registered shadow method.
fn render_rayon_set(dir: &Path) {
    let ctx = context();
    let mesh = rayon_scene();
    let p = rayon_frame(&mesh);
    for method in shadow_methods() {
        png_bytes(&ctx, &mesh, method, &p, &dir.join(format!("{method}.png")));
    }
}

/// Run by [`rayon_one_thread_matches_all_threads`] in a child process with one rayon thread;
/// does nothing when run directly.
#[test]
#[ignore = "helper: run by rayon_one_thread_matches_all_threads in a child process"]
fn rayon_child_render() {
    if let Some(dir) = std::env::var_os("UMBRA_DETERMINISM_CHILD_DIR") {
        render_rayon_set(Path::new(&dir));
    }
}

#[test]
fn rayon_one_thread_matches_all_threads() {
    let all = out_dir("rayon-all-threads");
    let one = out_dir("rayon-one-thread");
    for dir in [&all, &one] {
        for entry in std::fs::read_dir(dir).expect("list output").flatten() {
            let _ = std::fs::remove_file(entry.path());
        }
    }
    render_rayon_set(&all);
    let status = std::process::Command::new(std::env::current_exe().expect("test binary path"))
        .args(["--exact", "rayon_child_render", "--ignored", "--test-threads=1"])
        .env("RAYON_NUM_THREADS", "1")
        .env("UMBRA_DETERMINISM_CHILD_DIR", &one)
        .output()
        .expect("run the child test process");
    assert!(
        status.status.success(),
        "the one-thread child render failed: {}\n{}{}",
        status.status,
        String::from_utf8_lossy(&status.stdout),
        String::from_utf8_lossy(&status.stderr)
    );
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    eprintln!("rayon: default pool of {cores} thread(s) against 1 thread");
    let mut compared = 0;
    for method in shadow_methods() {
        let name = format!("{method}.png");
        let a = std::fs::read(all.join(&name)).expect("all-threads PNG");
        let b = std::fs::read(one.join(&name)).unwrap_or_else(|e| panic!("{method}: the child wrote no PNG: {e}"));
        assert!(distinct_colours(&a) > 3, "{method}: the frame is (nearly) uniform");
        assert!(
            a == b,
            "{method}: 1 rayon thread and {cores} give different PNG bytes ({} vs {})",
            all.display(),
            one.display()
        );
        compared += 1;
    }
    assert_eq!(compared, shadow_methods().len());
}

/// Different scenes for the concurrency test, each with its own method.
fn concurrent_jobs() -> Vec<(&'static str, &'static str)> {
    vec![
        ("sphere", "cpu-silhouette"),
        ("spheres:3", "ts-silhouette"),
        ("box", "vs-silhouette"),
        ("default", "gs-triangle"),
    ]
}

fn job_mesh(spec: &str) -> Arc<WeldedMesh> {
    if spec == "sphere" {
        return sphere_over_ground();
    }
    let mut mesh = scene::load_scene(spec).expect("procedural scene");
    scene::add_ground(&mut mesh);
    Arc::new(weld(&mesh))
}

/// One job on its own context: the PNG bytes.
fn run_job(spec: &str, method: &str, path: &Path) -> Vec<u8> {
    let ctx = context();
    let mesh = job_mesh(spec);
    let p = if spec == "sphere" { frame() } else { rayon_frame(&mesh) };
    png_bytes(&ctx, &mesh, method, &p, path)
}

#[test]
fn concurrent_contexts_match_sequential_renders() {
    let jobs = concurrent_jobs();
    for (_, method) in &jobs {
        assert!(umbra_gl::method_names().contains(method), "{method} is not a registered method");
    }
    let seq_dir = out_dir("sequential");
    let par_dir = out_dir("concurrent");
    let sequential: Vec<Vec<u8>> = jobs
        .iter()
        .enumerate()
        .map(|(i, (spec, method))| run_job(spec, method, &seq_dir.join(format!("{i}-{method}.png"))))
        .collect();
    // all at once: a barrier makes the threads render together
    let barrier = Arc::new(std::sync::Barrier::new(jobs.len()));
    let handles: Vec<_> = jobs
        .iter()
        .enumerate()
        .map(|(i, &(spec, method))| {
            let barrier = barrier.clone();
            let path = par_dir.join(format!("{i}-{method}.png"));
            std::thread::spawn(move || {
                barrier.wait();
                run_job(spec, method, &path)
            })
        })
        .collect();
    for (i, handle) in handles.into_iter().enumerate() {
        let concurrent = handle.join().unwrap_or_else(|_| panic!("job {i} {:?} panicked", jobs[i]));
        assert!(distinct_colours(&sequential[i]) > 3, "job {i} {:?}: the frame is (nearly) uniform", jobs[i]);
        assert!(
            concurrent == sequential[i],
            "job {i} {:?}: concurrent and sequential renders differ ({} vs {})",
            jobs[i],
            par_dir.display(),
            seq_dir.display()
        );
    }
}
