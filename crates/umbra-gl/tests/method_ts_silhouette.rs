//! ts-silhouette and ts-silhouette-3edge (paper 001, tessellation shaders): what the torture
//! suite cannot see.
//! * the stencil equals cpu-silhouette's value for value (z-fail and z-pass, point and
//!   directional lights, several lights per frame), including a 40-page book whose spine is
//!   split over several patches (|m| up to 40 > the paper's limit of 32) — except for a few
//!   pixels on projected volume-face edges, where the tessellator's triangle vertex order
//!   rounds the interpolated depth differently;
//! * gpu_bytes is `patch_bytes` = 12 (V + K) + 4 (3 + K) P, recomputed here from the
//!   adjacency;
//! * the stages "sides" and "caps" are reported for every light;
//! * preparing for another scene replaces the patches; destroy + prepare works again.

mod common;

use std::sync::Arc;

use common::*;
use umbra_geom::{weld::weld, EdgeAdjacency, Mesh, WeldedMesh};
use umbra_gl::methods::ts_silhouette::{patch_bytes, TsSilhouette, NAME, NAME_3EDGE};
use umbra_gl::{
    Camera, FrameParams, HeadlessContext, Renderer, RgbaImage, SceneGpu, ShadowMethod, StageHook, StageMark,
    StencilCapture, StencilImage,
};

/// `pages` triangles sharing the spine (-1, 1.5, 0)-(1, 1.5, 0), fanned around it, windings
/// alternating (the torture suite's book).
fn book(pages: usize) -> Mesh {
    let mut m = Mesh { positions: vec![[-1.0, 1.5, 0.0], [1.0, 1.5, 0.0]], ..Default::default() };
    for k in 0..pages {
        let a = std::f32::consts::PI * (0.1 + 0.8 * k as f32 / pages.max(2) as f32 - 0.5) + std::f32::consts::PI;
        m.positions.push([0.3 * (k as f32 / pages as f32 - 0.5), 1.5 + a.sin(), a.cos()]);
        let o = 2 + k as u32;
        m.triangles.push(if k % 2 == 0 { [0, 1, o] } else { [1, 0, o] });
    }
    m
}

/// Sphere, 40-page book (all pages wound alike, so the spine's |m| reaches 40), a
/// non-manifold fin pair and the ground.
fn torture_mesh() -> Arc<WeldedMesh> {
    let mut m = umbra_geom::scene::uv_sphere([0.0, 2.0, 0.0], 1.0, 32, 16);
    let mut b = book(40);
    for (i, t) in b.triangles.iter_mut().enumerate() {
        if i % 2 == 1 {
            t.swap(0, 1); // same winding for every page: |m| = 40 for a light above
        }
    }
    for p in &mut b.positions {
        p[0] += 3.0;
    }
    m.append(&b);
    let mut fins = Mesh { positions: vec![[-3.0, 1.0, 0.0], [-3.0, 1.0, 1.0]], ..Default::default() };
    for (k, p) in [[-2.0, 1.2, 0.5], [-4.0, 1.3, 0.5], [-3.0, 2.0, 0.4]].into_iter().enumerate() {
        fins.positions.push(p);
        fins.triangles.push([0, 1, 2 + k as u32]);
    }
    m.append(&fins);
    m.append(&umbra_geom::scene::ground_plane([0.0, 0.0, 0.0], 10.0));
    Arc::new(weld(&m))
}

fn camera() -> Camera {
    Camera { eye: [1.0, 7.0, 9.0], target: [0.5, 0.5, 0.0], ..default_camera() }
}

const LIGHTS: [[f32; 4]; 3] = [[0.4, 7.0, 0.3, 1.0], [-0.5, 1.0, 0.2, 0.0], [4.5, 5.0, -1.0, 1.0]];

fn render_stencils(
    ctx: &HeadlessContext,
    mesh: &Arc<WeldedMesh>,
    method: &mut dyn ShadowMethod,
    zpass: bool,
) -> Vec<StencilImage> {
    let gl = ctx.gl();
    let scene = SceneGpu::upload(gl, mesh.clone()).expect("upload");
    let mut r = Renderer::new(gl).expect("renderer").with_error_log(ctx.error_log().cloned());
    let mut p = params(camera(), LIGHTS.to_vec(), 320, 240);
    p.zpass = zpass;
    // z-fail when asked for, not auto z-pass (auto_zpass.rs tests the choice).
    p.auto_zpass = false;
    // cpu-silhouette's unculled counts: its receiver cull keeps every decision, not every
    // pixel's count (docs/exactness.md).
    p.volume_cull = false;
    p.capture.stencil = StencilCapture::AllLights;
    let images =
        r.render(gl, &scene, method, &p, None).unwrap_or_else(|e| panic!("render with {}: {e}", method.name()));
    r.destroy(gl);
    scene.destroy(gl);
    images.stencil.into_iter().map(|s| s.image).collect()
}

fn grey(s: &StencilImage) -> RgbaImage {
    let mut img = RgbaImage::new(s.width, s.height, [0, 0, 0, 255]);
    for (d, &v) in img.pixels.iter_mut().zip(&s.pixels) {
        let g = v.saturating_mul(40);
        *d = [g, g, g, 255];
    }
    img
}

/// `actual` equals `expected` value for value, except at pixels where `expected` itself
/// changes value within one pixel (the projected edge of some volume face: there the
/// tessellator's triangles, the same quads cut into triangles with other vertex orders,
/// interpolate depth with other rounding than cpu-silhouette's), and those are rare. A
/// missing, extra or flipped quad changes whole regions and fails.
fn assert_stencil_agrees(ctx: &HeadlessContext, test: &str, expected: &StencilImage, actual: &StencilImage) {
    let (w, h) = (expected.width as i64, expected.height as i64);
    let at = |x: i64, y: i64| expected.pixels[(y * w + x) as usize];
    let on_edge = |x: i64, y: i64| {
        let v = at(x, y);
        (-1..=1).any(|dy| {
            (-1..=1).any(|dx| {
                let (nx, ny) = (x + dx, y + dy);
                nx >= 0 && ny >= 0 && nx < w && ny < h && at(nx, ny) != v
            })
        })
    };
    let mut differing = 0;
    let mut off_edge = 0;
    let mut diff = grey(expected);
    for y in 0..h {
        for x in 0..w {
            let i = (y * w + x) as usize;
            if expected.pixels[i] != actual.pixels[i] {
                differing += 1;
                let edge = on_edge(x, y);
                off_edge += usize::from(!edge);
                diff.pixels[i] = if edge { [255, 160, 0, 255] } else { [255, 0, 0, 255] };
            }
        }
    }
    let limit = expected.pixels.len() / 2000;
    if off_edge > 0 || differing > limit {
        let note = write_failure_images(ctx, test, &grey(actual), &diff);
        panic!(
            "{test}: {differing} stencil values differ ({off_edge} away from any edge, at most {limit} allowed on edges) on {}; {note}",
            ctx.renderer_string()
        );
    }
}

#[test]
fn stencil_equals_cpu_silhouette() {
    let ctx = context();
    let mesh = torture_mesh();
    for zpass in [false, true] {
        let mut cpu = umbra_gl::create_method("cpu-silhouette").unwrap();
        let expected = render_stencils(&ctx, &mesh, cpu.as_mut(), zpass);
        cpu.destroy(ctx.gl());
        assert!(expected.iter().all(|s| s.pixels.iter().any(|&v| v != 0)), "every light casts a visible shadow");
        // The book's spine counts 40 where its shadow is seen through all pages.
        assert!(expected[0].pixels.iter().any(|&v| v >= 33), "a stencil count beyond the paper's multiplicity 32");
        for mut method in [TsSilhouette::new(), TsSilhouette::new_three_edge()] {
            let actual = render_stencils(&ctx, &mesh, &mut method, zpass);
            let capacity = method.patch_capacity().expect("prepared");
            assert!(capacity < 40, "the spine must be split (K = {capacity})");
            method.destroy(ctx.gl());
            for (i, (e, a)) in expected.iter().zip(&actual).enumerate() {
                let test = format!("{}_light{i}_{}", method.name(), if zpass { "zpass" } else { "zfail" });
                assert_stencil_agrees(&ctx, &test, e, a);
            }
        }
    }
    assert!(ctx.take_gl_errors().is_empty());
}

/// 12 (V + K) + 4 (3 + K) P, with P = Σ ceil(n_e / K), straight from the adjacency.
fn expected_bytes(adj: &EdgeAdjacency, k: usize) -> usize {
    let v = adj.edges.iter().flatten().chain(&adj.opposites).map(|&i| i as usize + 1).max().unwrap_or(0);
    let p: usize = (0..adj.len()).map(|e| adj.opposites(e).len().div_ceil(k)).sum();
    12 * (v + k) + 4 * (3 + k) * p
}

#[test]
fn gpu_bytes_is_patch_bytes() {
    let ctx = context();
    let gl = ctx.gl();
    for mesh in [torture_mesh(), sphere_over_ground(), Arc::new(weld(&book(40)))] {
        let adj = EdgeAdjacency::build(&mesh);
        let scene = SceneGpu::upload(gl, mesh.clone()).expect("upload");
        let mut m = TsSilhouette::new();
        assert_eq!(m.gpu_bytes(), 0, "nothing before prepare");
        m.prepare(gl, &scene).expect("prepare");
        let k = m.patch_capacity().expect("prepared");
        assert!((1..=29).contains(&k));
        assert_eq!(m.gpu_bytes(), expected_bytes(&adj, k));
        assert_eq!(m.gpu_bytes(), patch_bytes(&adj));
        m.destroy(gl);
        assert_eq!(m.gpu_bytes(), 0, "nothing after destroy");
        scene.destroy(gl);
    }
    // A closed mesh: every edge has two opposites, so K = 2 and P = E.
    let sphere = Arc::new(weld(&umbra_geom::scene::uv_sphere([0.0; 3], 1.0, 16, 8)));
    let adj = EdgeAdjacency::build(&sphere);
    assert!((0..adj.len()).all(|e| adj.opposites(e).len() == 2));
    assert_eq!(patch_bytes(&adj), 12 * (sphere.positions.len() + 2) + 4 * 5 * adj.len());
}

#[derive(Default)]
struct Marks(Vec<StageMark>);

impl StageHook for Marks {
    fn mark(&mut self, _gl: &glow::Context, mark: StageMark) {
        self.0.push(mark);
    }
}

#[test]
fn reports_sides_and_caps_per_light_and_reprepares() {
    let ctx = context();
    let gl = ctx.gl();
    let a = SceneGpu::upload(gl, sphere_over_ground()).expect("upload");
    let b = SceneGpu::upload(gl, torture_mesh()).expect("upload");
    let mut r = Renderer::new(gl).expect("renderer").with_error_log(ctx.error_log().cloned());
    for name in [NAME, NAME_3EDGE] {
        let mut m = umbra_gl::create_method(name).expect("registered");
        assert_eq!(m.name(), name);
        assert_eq!(m.stages(), ["sides", "caps"]);
        let p =
            FrameParams { lights: LIGHTS.to_vec(), width: 64, height: 48, camera: camera(), ..FrameParams::default() };
        let mut marks = Marks::default();
        r.render(gl, &a, m.as_mut(), &p, Some(&mut marks)).expect("render");
        let ours: Vec<(&str, Option<usize>)> =
            marks.0.iter().filter(|k| k.source == name).map(|k| (k.label, k.light)).collect();
        let want: Vec<(&str, Option<usize>)> =
            (0..LIGHTS.len()).flat_map(|l| [("sides", Some(l)), ("caps", Some(l))]).collect();
        assert_eq!(ours, want);
        assert_eq!(m.prepared_scene(), Some(a.id()));
        let bytes_a = m.gpu_bytes();
        // Another scene: new patches.
        r.render(gl, &b, m.as_mut(), &p, None).expect("render");
        assert_eq!(m.prepared_scene(), Some(b.id()));
        assert_eq!(m.gpu_bytes(), patch_bytes(&EdgeAdjacency::build(b.mesh())));
        assert_ne!(m.gpu_bytes(), bytes_a);
        // Destroyed, then used again: prepared from scratch.
        m.destroy(gl);
        assert_eq!(m.prepared_scene(), None);
        r.render(gl, &a, m.as_mut(), &p, None).expect("render after destroy");
        assert_eq!(m.gpu_bytes(), bytes_a);
        m.destroy(gl);
    }
    r.destroy(gl);
    a.destroy(gl);
    b.destroy(gl);
    assert!(ctx.take_gl_errors().is_empty());
}

/// Not a test: ms per 1280x720 frame of Crytek Sponza (torture pose 0) for the silhouette
/// methods, warm (llvmpipe compiles shaders on the first draw), and per-stage times.
/// Run: `cargo test --release -p umbra-gl --test method_ts_silhouette -- --ignored --nocapture`.
#[test]
#[ignore]
fn sponza_frame_time() {
    let dir = std::env::var_os("UMBRA_SCENES")
        .map(std::path::PathBuf::from)
        .unwrap_or_else(|| std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/scenes"));
    let path = dir.join("crytek-sponza.obj.gz");
    if !path.is_file() {
        eprintln!("SKIPPED: {} not found (set UMBRA_SCENES)", path.display());
        return;
    }
    let mesh = umbra_geom::load::load_path(&path).expect("load sponza");
    let b = mesh.bounds().expect("non-empty");
    let at = |f: [f64; 3]| [0, 1, 2].map(|k| b.min[k] as f64 + f[k] * (b.max[k] - b.min[k]) as f64);
    let welded = Arc::new(weld(&mesh));
    let light = at([0.61, 0.7, 0.57]);
    let camera = Camera {
        eye: at([0.3, 0.45, 0.5]),
        target: at([0.7, 0.3, 0.5]),
        near: 1e-3 * b.diagonal() as f64,
        ..Camera::default()
    };
    let p = FrameParams {
        camera,
        lights: vec![[light[0] as f32, light[1] as f32, light[2] as f32, 1.0]],
        ..FrameParams::default()
    };
    let ctx = context();
    let gl = ctx.gl();
    let scene = SceneGpu::upload(gl, welded.clone()).expect("upload");
    let adj = scene.adjacency().clone();
    eprintln!(
        "sponza: {} welded triangles, {} edges, {} opposites, max {} per edge, patch_bytes {}",
        welded.triangles.len(),
        adj.len(),
        adj.opposites.len(),
        adj.max_opposites(),
        patch_bytes(&adj)
    );
    let mut r = Renderer::new(gl).expect("renderer");
    let names = ["cpu-silhouette", "ts-silhouette", "ts-silhouette-3edge", "gs-silhouette", "gs-silhouette-3edge"];
    let mut methods: Vec<Box<dyn ShadowMethod>> =
        names.iter().map(|n| umbra_gl::create_method(n).expect("registered")).collect();
    // Warm-up: prepare, shader compilation on first draw.
    for m in &mut methods {
        for _ in 0..2 {
            r.render(gl, &scene, m.as_mut(), &p, None).expect("render");
        }
    }
    // Round robin, so that a machine whose load changes affects every method alike; the
    // median frame per method.
    const ROUNDS: usize = 5;
    let mut frames = vec![Vec::new(); names.len()];
    for _ in 0..ROUNDS {
        for (m, f) in methods.iter_mut().zip(&mut frames) {
            let t = std::time::Instant::now();
            r.render(gl, &scene, m.as_mut(), &p, None).expect("render");
            f.push(t.elapsed().as_secs_f64() * 1e3);
        }
    }
    for ((name, m), f) in names.iter().zip(&mut methods).zip(&mut frames) {
        f.sort_by(f64::total_cmp);
        let mut hook = umbra_gl::TimestampHook::synchronous();
        r.render(gl, &scene, m.as_mut(), &p, Some(&mut hook)).expect("render");
        let stages: Vec<String> = hook
            .finish(gl)
            .iter()
            .filter(|s| s.mark.source == *name)
            .map(|s| format!("{} {:.0}", s.mark.label, s.gpu_ns as f64 / 1e6))
            .collect();
        hook.destroy(gl);
        eprintln!(
            "{name:<20} median {:7.1} ms/frame (min {:7.1}, max {:7.1}); gpu_bytes {:>9}; stages (ms, synchronous): {}",
            f[ROUNDS / 2],
            f[0],
            f[ROUNDS - 1],
            m.gpu_bytes(),
            stages.join(", ")
        );
        m.destroy(gl);
    }
    r.destroy(gl);
    scene.destroy(gl);
}
