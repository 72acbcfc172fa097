//! cs-silhouette on wgpu: what the torture suite cannot see.
//! * the compute passes emit exactly the CPU silhouette's number of side quads and caps (read
//!   back from the indirect commands), for every light kind, many lights per frame (each light
//!   has its own outputs);
//! * the stencil equals cpu-silhouette's value for value, non-manifold edges with
//!   multiplicities far above 3 bits included (a 40-page book);
//! * an edge with 40,000 triangles is split into records (Mesa's gallivm ends shader loops at
//!   65,535 iterations) and still emits exactly the CPU's quads and stencil;
//! * the worst case Σ|m| = Σk fills the output buffer exactly.

mod common;

use std::sync::Arc;

use common::*;
use umbra_geom::scene::book;
use umbra_geom::silhouette::{extract, VolumeGeometry};
use umbra_geom::{weld::weld, EdgeAdjacency, Mesh, WeldedMesh};
use umbra_wgpu::methods::cs_silhouette::MAX_TRIANGLES_PER_RECORD;
use umbra_wgpu::{Camera, FrameParams, HeadlessGpu, Renderer, SceneGpu, StencilImage};

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

/// What the CPU extracts for `light`: (side vertices, cap vertices as cs-silhouette draws them).
fn cpu_counts(mesh: &WeldedMesh, light: [f32; 4], zpass: bool) -> (u32, u32) {
    let adj = EdgeAdjacency::build(mesh);
    let mut v = VolumeGeometry::default();
    extract(mesh, &adj, light, !zpass, &mut v);
    let per_cap = if light[3] == 0.0 { 1 } else { 2 };
    (v.sides.len() as u32, (v.light_caps.len() * per_cap) as u32)
}

struct Rendered {
    stencil: Vec<StencilImage>,
    /// Per light: (side vertices, cap vertices) read back from the indirect commands.
    counts: Vec<Option<(u32, u32)>>,
    gpu_bytes: u64,
}

/// One frame with `method`, z-fail or z-pass as `p` says (auto z-pass off: the caps are drawn),
/// volumes unculled: a cull keeps the visible samples' counts only, and these tests compare
/// every pixel's count with cpu-silhouette's whole volume.
fn render(gpu: &HeadlessGpu, mesh: &Arc<WeldedMesh>, method: &str, p: &FrameParams) -> Rendered {
    let p = &FrameParams { auto_zpass: false, volume_cull: false, ..p.clone() };
    let scene = SceneGpu::upload(&gpu.device, mesh.clone()).expect("upload");
    let mut renderer = Renderer::new(&gpu.device).expect("renderer");
    let mut volumes = renderer.volumes(&gpu.device, method).expect("method");
    let images = renderer.render(&gpu.device, &gpu.queue, &scene, &mut volumes, p).unwrap_or_else(|e| panic!("{e}"));
    let counts = (0..p.lights.len()).map(|i| volumes.gpu_counts(&gpu.device, &gpu.queue, i).expect("counts")).collect();
    Rendered { stencil: images.stencil.into_iter().map(|s| s.image).collect(), counts, gpu_bytes: volumes.gpu_bytes() }
}

fn assert_same_stencil(test: &str, expected: &StencilImage, actual: &StencilImage) {
    let differing = expected.pixels.iter().zip(&actual.pixels).filter(|(a, b)| a != b).count();
    assert_eq!(differing, 0, "{test}: {differing} stencil values differ from cpu-silhouette's");
}

#[test]
fn stencil_and_counts_equal_cpu_silhouette() {
    let Some(gpu) = gpu() else { return };
    let mesh = torture_mesh();
    let lights = [POINT_LIGHT, [3.4, 4.0, 0.4, 1.0], [-0.4, 1.0, 0.3, 0.0], [0.3, 0.9, -0.2, 0.0]];
    let cameras = [default_camera(), Camera { eye: [6.0, 3.0, -5.0], ..default_camera() }];
    for camera in cameras {
        for zpass in [false, true] {
            // All lights in one frame: every light keeps its own outputs until it is drawn.
            let mut p = params(camera, lights.to_vec(), 256, 192);
            p.zpass = zpass;
            let cpu = render(&gpu, &mesh, "cpu-silhouette", &p);
            let cs = render(&gpu, &mesh, "cs-silhouette", &p);
            assert_eq!(cs.stencil.len(), lights.len());
            assert!(cpu.counts.iter().all(Option::is_none), "cpu-silhouette has no GPU-side counts");
            for (i, (e, a)) in cpu.stencil.iter().zip(&cs.stencil).enumerate() {
                assert!(e.pixels.iter().any(|&v| v != 0), "light {i} casts a visible shadow");
                assert_same_stencil(&format!("light {i}, zpass {zpass}"), e, a);
                let (sides, caps) = cs.counts[i].expect("cs-silhouette counts on the GPU");
                let (cpu_sides, cpu_caps) = cpu_counts(&mesh, lights[i], zpass);
                assert_eq!(sides, cpu_sides, "side vertices of light {i}");
                assert_eq!(caps, if zpass { 0 } else { cpu_caps }, "cap vertices of light {i} (none under z-pass)");
            }
        }
    }
}

#[test]
fn book_spine_multiplicity_beyond_three_bits() {
    let Some(gpu) = gpu() else { return };
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
    let cpu = render(&gpu, &mesh, "cpu-silhouette", &p);
    let cs = render(&gpu, &mesh, "cs-silhouette", &p);
    assert_same_stencil("book spine", &cpu.stencil[0], &cs.stencil[0]);
    assert_eq!(cs.counts[0].expect("counts").0, cpu_counts(&mesh, light, false).0);
}

#[test]
fn worst_case_output_fills_the_buffer_exactly() {
    let Some(gpu) = gpu() else { return };
    // Disjoint triangles facing up: every edge has one opposite and |m| = 1, Σ|m| = Σk.
    let mut m = Mesh::default();
    for i in 0..12 {
        for j in 0..12 {
            let (x, z, y) = (i as f32 * 0.5 - 3.0, j as f32 * 0.5 - 3.0, 1.0 + 0.05 * ((i * 7 + j * 3) % 5) as f32);
            let b = m.positions.len() as u32;
            m.positions.extend_from_slice(&[[x, y, z], [x + 0.2, y, z + 0.3], [x + 0.3, y, z - 0.1]]);
            m.triangles.push([b, b + 1, b + 2]);
        }
    }
    let mesh = Arc::new(weld(&m));
    let adj = EdgeAdjacency::build(&mesh);
    let camera = Camera { eye: [0.0, 6.0, 6.0], target: [0.0, 0.0, 0.0], ..default_camera() };
    let p = params(camera, vec![[0.2, 8.0, 0.1, 1.0]], 256, 192);
    let cpu = render(&gpu, &mesh, "cpu-silhouette", &p);
    let cs = render(&gpu, &mesh, "cs-silhouette", &p);
    assert_same_stencil("worst case", &cpu.stencil[0], &cs.stencil[0]);
    let (sides, caps) = cs.counts[0].expect("counts");
    assert_eq!(sides as usize, 6 * adj.opposites.len(), "every opposite contributes a quad: Σ|m| = Σk");
    assert_eq!(caps as usize, 6 * mesh.triangles.len());
    // Records 16 e + slots 4 Σk + the cull's pieces 4 t and flags 4 (1 + pieces) (here every
    // triangle is a piece of its own), per light: orientation 4 t + quads 8 Σk + caps 12 t +
    // two 16-byte commands + the kept count (16) + clip positions 32 v (every buffer at least
    // 16 bytes).
    let expected = 16 * adj.len()
        + 4 * adj.opposites.len()
        + 4 * mesh.triangles.len()
        + 4 * (1 + mesh.triangles.len())
        + 16
        + 4 * mesh.triangles.len()
        + 8 * adj.opposites.len()
        + 12 * mesh.triangles.len()
        + 32
        + 32 * mesh.positions.len();
    assert_eq!(cs.gpu_bytes as usize, expected);
}

/// One spine edge with 40,000 triangles (|m| = 40,000 under a light from above): more than two
/// records of MAX_TRIANGLES_PER_RECORD; the GPU must emit exactly the CPU's quads and stencil.
#[test]
fn spine_split_into_records_counts_equal_cpu() {
    const PAGES: usize = 40_000;
    let Some(gpu) = gpu() else { return };
    assert!(PAGES as u32 > 2 * MAX_TRIANGLES_PER_RECORD);
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
    let camera = Camera { eye: [0.37, -1.0, 2.5], target: [0.45, -2.0, 0.0], ..default_camera() };
    let p = params(camera, vec![light], 64, 48);
    let cs = render(&gpu, &mesh, "cs-silhouette", &p);
    let (sides, caps) = cs.counts[0].expect("counts");
    let (cpu_sides, cpu_caps) = cpu_counts(&mesh, light, false);
    assert_eq!(sides, cpu_sides, "side vertices (gallivm ends a shader loop at 65,535 iterations)");
    assert_eq!(caps, cpu_caps, "cap vertices");
    let records =
        umbra_wgpu::methods::cs_silhouette::edge_records(&EdgeAdjacency::build(&mesh), MAX_TRIANGLES_PER_RECORD);
    assert_eq!(records.iter().filter(|r| r[0..2] == [0, 1] || r[0..2] == [1, 0]).count(), 3, "the spine is split");
    let cpu = render(&gpu, &mesh, "cpu-silhouette", &p);
    assert!(cpu.stencil[0].pixels.iter().any(|&v| v != 0), "the shadow is in view");
    assert_same_stencil("spine 40k", &cpu.stencil[0], &cs.stencil[0]);
}
