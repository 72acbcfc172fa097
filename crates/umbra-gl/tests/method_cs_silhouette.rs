//! cs-silhouette (compute-shader silhouette, indirect draws): what the torture suite cannot see.
//! * the compute passes emit exactly cpu-silhouette's number of side quads and caps (read back
//!   from the indirect commands), for every light kind, many lights per frame (counter reset);
//! * the stencil equals cpu-silhouette's value for value, including non-manifold edges with
//!   multiplicities far above 3 bits (a 40-page book: |m| up to 40);
//! * an edge with 100,000 opposites (split into records: llvmpipe ends shader loops at 65,535
//!   iterations) emits exactly cpu-silhouette's quads and stencil;
//! * the worst case Σ|m| = Σk fills the output buffer exactly, without overflow;
//! * gpu_bytes is the documented formula.

mod common;

use std::sync::Arc;

use common::*;
use umbra_geom::scene::book;
use umbra_geom::silhouette::{extract, VolumeGeometry};
use umbra_geom::{weld::weld, EdgeAdjacency, Mesh, WeldedMesh};
use umbra_gl::methods::cs_silhouette::{CsSilhouette, MAX_OPPOSITES_PER_RECORD};
use umbra_gl::{
    Camera, FrameParams, HeadlessContext, Renderer, RgbaImage, SceneGpu, ShadowMethod, StencilCapture, StencilImage,
};

/// Sphere over ground plus a 40-page book.
fn torture_mesh() -> Arc<WeldedMesh> {
    let mut m = umbra_geom::scene::uv_sphere([0.0, 2.0, 0.0], 1.0, 48, 24);
    let mut b = book(40);
    for p in &mut b.positions {
        p[0] += 3.0;
    }
    m.append(&b);
    m.append(&umbra_geom::scene::ground_plane([0.0, 0.0, 0.0], 10.0));
    Arc::new(weld(&m))
}

/// Disjoint triangles facing up over a ground: every edge has one opposite and |m| = 1 (none
/// is edge-on to a light above), so the side quads reach the worst case Σ|m| = Σk.
fn scattered_triangles() -> Arc<WeldedMesh> {
    let mut m = Mesh::default();
    for i in 0..12 {
        for j in 0..12 {
            let (x, z, y) = (i as f32 * 0.5 - 3.0, j as f32 * 0.5 - 3.0, 1.0 + 0.05 * ((i * 7 + j * 3) % 5) as f32);
            let b = m.positions.len() as u32;
            m.positions.extend_from_slice(&[[x, y, z], [x + 0.2, y, z + 0.3], [x + 0.3, y, z - 0.1]]);
            m.triangles.push([b, b + 1, b + 2]);
        }
    }
    Arc::new(weld(&m))
}

struct Rendered {
    stencil: Vec<StencilImage>,
    /// cs-silhouette only: (side vertices, cap vertices) of the LAST light, read back from
    /// the indirect commands.
    counts: Option<(u32, u32)>,
    gpu_bytes: usize,
}

fn render_with(
    ctx: &HeadlessContext,
    mesh: &Arc<WeldedMesh>,
    method: &mut dyn ShadowMethod,
    p: &FrameParams,
) -> Rendered {
    let gl = ctx.gl();
    let scene = SceneGpu::upload(gl, mesh.clone()).expect("upload");
    let mut r = Renderer::new(gl).expect("renderer").with_error_log(ctx.error_log().cloned());
    let mut p = p.clone();
    p.capture.stencil = StencilCapture::AllLights;
    let images =
        r.render(gl, &scene, method, &p, None).unwrap_or_else(|e| panic!("render with {}: {e}", method.name()));
    let gpu_bytes = method.gpu_bytes();
    let out = Rendered { stencil: images.stencil.into_iter().map(|s| s.image).collect(), counts: None, gpu_bytes };
    r.destroy(gl);
    scene.destroy(gl);
    out
}

fn render_cs(ctx: &HeadlessContext, mesh: &Arc<WeldedMesh>, p: &FrameParams) -> Rendered {
    let gl = ctx.gl();
    let mut m = CsSilhouette::new();
    // z-fail, so the caps are drawn and counted (auto z-pass would skip them; auto_zpass.rs);
    // unculled, as cpu-silhouette's counts below: the GPU cull keeps every visible sample's
    // decision, not every pixel's count (docs/exactness.md).
    let p = &FrameParams { auto_zpass: false, volume_cull: false, ..p.clone() };
    let mut out = render_with(ctx, mesh, &mut m, p);
    out.counts = m.last_counts(gl);
    m.destroy(gl);
    assert_eq!(m.gpu_bytes(), 0);
    out
}

fn render_cpu(ctx: &HeadlessContext, mesh: &Arc<WeldedMesh>, p: &FrameParams) -> Rendered {
    let mut m = umbra_gl::create_method("cpu-silhouette").expect("registered");
    // The unculled counts: the receiver cull keeps every visible sample's decision, not every
    // pixel's count (docs/exactness.md).
    let p = &FrameParams { auto_zpass: false, volume_cull: false, ..p.clone() };
    let out = render_with(ctx, mesh, m.as_mut(), p);
    m.destroy(ctx.gl());
    out
}

fn grey(s: &StencilImage) -> RgbaImage {
    let mut img = RgbaImage::new(s.width, s.height, [0, 0, 0, 255]);
    for (d, &v) in img.pixels.iter_mut().zip(&s.pixels) {
        let g = v.saturating_mul(60);
        *d = [g, g, g, 255];
    }
    img
}

fn assert_same_stencil(ctx: &HeadlessContext, test: &str, expected: &StencilImage, actual: &StencilImage) {
    let differing = expected.pixels.iter().zip(&actual.pixels).filter(|(a, b)| a != b).count();
    if differing > 0 {
        let mut diff = grey(expected);
        for (d, (a, b)) in diff.pixels.iter_mut().zip(expected.pixels.iter().zip(&actual.pixels)) {
            if a != b {
                *d = [255, 0, 0, 255];
            }
        }
        let note = write_failure_images(ctx, test, &grey(actual), &diff);
        panic!("{test}: {differing} stencil values differ on {}; {note}", ctx.renderer_string());
    }
}

/// What cpu-silhouette extracts for `light`: (side vertices, cap vertices as cs draws them).
fn cpu_counts(mesh: &WeldedMesh, light: [f32; 4], zpass: bool) -> (u32, u32) {
    let adj = EdgeAdjacency::build(mesh);
    let mut v = VolumeGeometry::default();
    extract(mesh, &adj, light, !zpass, &mut v);
    let per_cap = if light[3] == 0.0 { 1 } else { 2 };
    (v.sides.len() as u32, (v.light_caps.len() * per_cap) as u32)
}

#[test]
fn stencil_and_counts_equal_cpu_silhouette() {
    let ctx = context();
    let mesh = torture_mesh();
    let lights = [POINT_LIGHT, [3.4, 4.0, 0.4, 1.0], [-0.4, 1.0, 0.3, 0.0], [0.3, 0.9, -0.2, 0.0]];
    let cameras = [default_camera(), Camera { eye: [6.0, 3.0, -5.0], ..default_camera() }];
    for camera in cameras {
        for zpass in [false, true] {
            // All lights in one frame: the commands are reset and the buffers reused per light.
            let mut p = params(camera, lights.to_vec(), 256, 192);
            p.zpass = zpass;
            // z-fail when asked for, not auto z-pass (auto_zpass.rs tests the choice).
            p.auto_zpass = false;
            let cpu = render_cpu(&ctx, &mesh, &p);
            let cs = render_cs(&ctx, &mesh, &p);
            assert_eq!(cs.stencil.len(), lights.len());
            for (i, (e, a)) in cpu.stencil.iter().zip(&cs.stencil).enumerate() {
                assert!(e.pixels.iter().any(|&v| v != 0), "light {i} casts a visible shadow");
                assert_same_stencil(&ctx, &format!("cs_light{i}_{}", if zpass { "zpass" } else { "zfail" }), e, a);
            }
            let last = lights[lights.len() - 1];
            let (sides, caps) = cs.counts.expect("prepared");
            let (cpu_sides, cpu_caps) = cpu_counts(&mesh, last, zpass);
            assert_eq!(sides, cpu_sides, "side vertices of the last light");
            if !zpass {
                assert_eq!(caps, cpu_caps, "cap vertices of the last light");
            } else {
                assert_eq!(caps, 0, "z-pass draws no caps");
            }
        }
    }
}

#[test]
fn book_spine_multiplicity_beyond_three_bits() {
    let ctx = context();
    let mut m = book(40);
    m.append(&umbra_geom::scene::ground_plane([0.0, 0.0, 0.0], 10.0));
    let mesh = Arc::new(weld(&m));
    let adj = EdgeAdjacency::build(&mesh);
    // A light low on the side: all pages face it the same way, the spine's |m| is 40.
    let light = [-6.0, 1.0, 0.5, 1.0];
    let spine = (0..adj.len()).find(|&e| adj.opposites(e).len() == 40).expect("spine");
    let m_spine =
        umbra_geom::multiplicity::edge_multiplicity(&mesh.positions, adj.edges[spine], adj.opposites(spine), light);
    assert!(m_spine.abs() > 7, "spine multiplicity {m_spine} needs more than 3 bits");
    let p = params(Camera { eye: [3.0, 4.0, 5.0], target: [0.0, 1.0, 0.0], ..default_camera() }, vec![light], 256, 192);
    let cpu = render_cpu(&ctx, &mesh, &p);
    let cs = render_cs(&ctx, &mesh, &p);
    assert_same_stencil(&ctx, "cs_book_spine", &cpu.stencil[0], &cs.stencil[0]);
    assert_eq!(cs.counts.expect("prepared").0, cpu_counts(&mesh, light, false).0);
}

#[test]
fn worst_case_output_fills_the_buffer_exactly() {
    let ctx = context();
    let mesh = scattered_triangles();
    let adj = EdgeAdjacency::build(&mesh);
    let p = params(
        Camera { eye: [0.0, 6.0, 6.0], target: [0.0, 0.0, 0.0], ..default_camera() },
        vec![[0.2, 8.0, 0.1, 1.0]],
        256,
        192,
    );
    let cpu = render_cpu(&ctx, &mesh, &p);
    let cs = render_cs(&ctx, &mesh, &p);
    assert_same_stencil(&ctx, "cs_worst_case", &cpu.stencil[0], &cs.stencil[0]);
    let (sides, caps) = cs.counts.expect("prepared");
    assert_eq!(sides as usize, 6 * adj.opposites.len(), "every opposite contributes a quad: Σ|m| = Σk");
    assert_eq!(caps as usize, 6 * mesh.triangles.len());
    // gpu_bytes: edges 16 e + opposites 4 Σk + quads 8 Σk + caps 12 t + two 16-byte commands.
    let expected = 16 * adj.len() + 12 * adj.opposites.len() + 12 * mesh.triangles.len() + 32;
    assert_eq!(cs.gpu_bytes, expected);
    assert_eq!(cpu.stencil.len(), 1);
}

/// The 100,000-page book of umbra-verify's stencil_wrap (one spine edge with 100,000
/// opposites, |m| = 100,000 under a light from above): the compute pass must emit exactly
/// cpu-silhouette's side quads and caps.
#[test]
fn spine_with_100k_opposites_counts_equal_cpu() {
    const PAGES: usize = 100_000;
    let ctx = context();
    let mut m = Mesh { positions: vec![[0.0, 0.0, -1.0], [0.0, 0.0, 1.0]], ..Mesh::default() };
    for i in 0..PAGES {
        let a = (-10.0 + 20.0 * (i as f64 + 0.5) / PAGES as f64).to_radians();
        let r = [1.0f64, 0.8, 0.6, 0.4][i % 4];
        m.positions.push([(r * a.cos()) as f32, (r * a.sin()) as f32, 0.0]);
        m.triangles.push([0, 1, 2 + i as u32]);
    }
    m.append(&umbra_geom::scene::ground_plane([0.0, -2.0, 0.0], 10.0));
    let mesh = Arc::new(weld(&m));
    let light = [0.0, 1.0, 0.0, 0.0];
    let p =
        params(Camera { eye: [0.37, -1.0, 2.5], target: [0.45, -2.0, 0.0], ..default_camera() }, vec![light], 64, 48);
    let cs = render_cs(&ctx, &mesh, &p);
    let (sides, caps) = cs.counts.expect("prepared");
    let (cpu_sides, cpu_caps) = cpu_counts(&mesh, light, false);
    assert_eq!(sides, cpu_sides, "side vertices (llvmpipe ends a shader loop at 65,535 iterations)");
    assert_eq!(caps, cpu_caps, "cap vertices");
    // The spine is split into ceil(100,000 / MAX_OPPOSITES_PER_RECORD) records: gpu_bytes
    // counts 16 bytes per record.
    let adj = EdgeAdjacency::build(&mesh);
    let extra = (PAGES as u32).div_ceil(MAX_OPPOSITES_PER_RECORD) as usize - 1;
    assert!(extra > 0, "the spine must be split");
    let expected = 16 * (adj.len() + extra) + 12 * adj.opposites.len() + 12 * mesh.triangles.len() + 32;
    assert_eq!(cs.gpu_bytes, expected);
    // And the stencil, value for value (both wrap the same way at 8 bits).
    let cpu = render_cpu(&ctx, &mesh, &p);
    assert!(cpu.stencil[0].pixels.iter().any(|&v| v != 0), "the shadow is in view");
    assert_same_stencil(&ctx, "cs_spine_100k", &cpu.stencil[0], &cs.stencil[0]);
}
