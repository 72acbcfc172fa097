//! `all-edges-invert` (paper 002): where it is exact, where it is not, and when it is fast.
//!
//! * Convex casters over a plane, camera outside every volume: the shadow mask (stencil ==
//!   1100b) equals cpu-silhouette's (stencil != 0) at every sample outside cpu-silhouette's
//!   one-pixel shadow boundary, for point and directional lights; the same on a concave "tree"
//!   of disconnected leaves whose volumes overlap many times over; on a finely tessellated
//!   sphere up to rare ties next to interior edges (bounded).
//! * Camera inside a shadow volume: the documented failure mode, many samples wrong.
//! * Timing (ignored by default): a procedural tree of many small random triangles, against
//!   cpu-silhouette, at several sizes; `cargo test --release -p umbra-gl --test
//!   method_all_edges_invert -- --ignored --nocapture`.

mod common;

use std::sync::Arc;
use std::time::Instant;

use umbra_geom::scene::{cuboid, ground_plane, tetrahedron, uv_sphere};
use umbra_geom::{weld::weld, Light, Mesh, WeldedMesh};
use umbra_gl::methods::all_edges_invert::{self, AllEdgesInvert};
use umbra_gl::{
    create_method, Camera, Classification, FrameParams, HeadlessContext, Renderer, SceneGpu, ShadowMethod, StencilImage,
};

fn stencil_of(ctx: &HeadlessContext, scene: &SceneGpu, method: &mut dyn ShadowMethod, p: &FrameParams) -> StencilImage {
    let gl = ctx.gl();
    let mut r = Renderer::new(gl).expect("renderer").with_error_log(ctx.error_log().cloned());
    let s = r.render_stencil(gl, scene, method, p, 0).unwrap_or_else(|e| panic!("{}: {e}", method.name()));
    r.destroy(gl);
    s
}

fn params(eye: [f64; 3], target: [f64; 3], light: Light, size: (u32, u32)) -> FrameParams {
    FrameParams {
        camera: Camera { eye, target, near: 0.01, ..Camera::default() },
        width: size.0,
        height: size.1,
        lights: vec![light],
        ..FrameParams::default()
    }
}

/// Shadow masks of cpu-silhouette and all-edges-invert for one view.
fn masks(ctx: &HeadlessContext, mesh: &Arc<WeldedMesh>, p: &FrameParams) -> (Vec<bool>, Vec<bool>) {
    let gl = ctx.gl();
    let scene = SceneGpu::upload(gl, mesh.clone()).expect("upload");
    let mut cpu = create_method("cpu-silhouette").expect("registered");
    let reference: Vec<bool> = stencil_of(ctx, &scene, cpu.as_mut(), p).pixels.iter().map(|&s| s != 0).collect();
    cpu.destroy(gl);
    let mut m = AllEdgesInvert::new();
    assert_eq!(
        m.classification(),
        Classification::StencilTest { func: umbra_gl::glow::NOTEQUAL, reference: 0b1100, value_mask: 0b1101 }
    );
    let got: Vec<bool> =
        stencil_of(ctx, &scene, &mut m, p).pixels.iter().map(|&s| s == all_edges_invert::SHADOW_VALUE as u8).collect();
    assert_eq!(m.gpu_bytes(), 0);
    m.destroy(gl);
    scene.destroy(gl);
    assert!(ctx.take_gl_errors().is_empty());
    (reference, got)
}

/// Samples whose 3x3 neighbourhood in `mask` is not uniform: the shadow boundary band.
fn boundary_band(mask: &[bool], w: usize, h: usize) -> Vec<bool> {
    let mut band = vec![false; mask.len()];
    for y in 0..h {
        for x in 0..w {
            let c = mask[y * w + x];
            let mut edge = false;
            for (dx, dy) in [(-1i64, -1i64), (0, -1), (1, -1), (-1, 0), (1, 0), (-1, 1), (0, 1), (1, 1)] {
                let (nx, ny) = (x as i64 + dx, y as i64 + dy);
                if nx >= 0
                    && ny >= 0
                    && (nx as usize) < w
                    && (ny as usize) < h
                    && mask[ny as usize * w + nx as usize] != c
                {
                    edge = true;
                }
            }
            band[y * w + x] = edge;
        }
    }
    band
}

/// (samples that differ outside the band, samples that differ in it, shadowed samples).
fn compare(reference: &[bool], got: &[bool], w: usize, h: usize) -> (usize, usize, usize) {
    let band = boundary_band(reference, w, h);
    let outside = (0..reference.len()).filter(|&i| !band[i] && reference[i] != got[i]).count();
    let inside = (0..reference.len()).filter(|&i| band[i] && reference[i] != got[i]).count();
    (outside, inside, reference.iter().filter(|&&s| s).count())
}

fn sphere_over_ground() -> Arc<WeldedMesh> {
    let mut m = uv_sphere([0.0, 2.0, 0.0], 1.0, 48, 24);
    m.append(&ground_plane([0.0, 0.0, 0.0], 10.0));
    Arc::new(weld(&m))
}

/// Tiny deterministic generator (xorshift64*), so the trees are the same on every run.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f32 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        ((self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 40) as f32) / (1u64 << 24) as f32
    }
    fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.next()
    }
}

/// A procedural "tree": a trunk (an open 8-sided tube) and `leaves` small random triangles,
/// each with its own three vertices (nothing shared: every edge is open, every leaf a
/// silhouette of its own), scattered in a ball of radius 1.5 around (0, 3, 0); plus a ground.
fn tree(leaves: usize, seed: u64) -> Mesh {
    let mut m = Mesh::default();
    let mut rng = Rng(seed.max(1));
    for _ in 0..leaves {
        // Rejection-sample the leaf centre in the ball.
        let c = loop {
            let p = [rng.range(-1.0, 1.0), rng.range(-1.0, 1.0), rng.range(-1.0, 1.0)];
            if p[0] * p[0] + p[1] * p[1] + p[2] * p[2] <= 1.0 {
                break [1.5 * p[0], 3.0 + 1.5 * p[1], 1.5 * p[2]];
            }
        };
        let b = m.positions.len() as u32;
        for _ in 0..3 {
            m.positions.push([
                c[0] + rng.range(-0.08, 0.08),
                c[1] + rng.range(-0.08, 0.08),
                c[2] + rng.range(-0.08, 0.08),
            ]);
        }
        m.triangles.push([b, b + 1, b + 2]);
    }
    let sides = 8u32;
    let b = m.positions.len() as u32;
    for k in 0..sides {
        let a = k as f32 * std::f32::consts::TAU / sides as f32;
        m.positions.push([0.15 * a.cos(), 0.0, 0.15 * a.sin()]);
        m.positions.push([0.1 * a.cos(), 2.5, 0.1 * a.sin()]);
    }
    for k in 0..sides {
        let (i0, i1) = (b + 2 * k, b + 2 * ((k + 1) % sides));
        m.triangles.push([i0, i0 + 1, i1 + 1]);
        m.triangles.push([i0, i1 + 1, i1]);
    }
    m.append(&ground_plane([0.0, 0.0, 0.0], 10.0));
    m
}

/// A box and a tetrahedron (convex, closed, few edges) over a plane, camera outside every
/// volume: the same shadow as cpu-silhouette at every sample off its boundary.
#[test]
fn exact_for_convex_casters_over_a_plane() {
    let ctx = common::context();
    let mut m = cuboid([-0.8, 1.5, 0.0], [0.5, 0.4, 0.6]);
    m.append(&tetrahedron([1.2, 1.8, 0.3], 0.7));
    m.append(&ground_plane([0.0, 0.0, 0.0], 10.0));
    let mesh = Arc::new(weld(&m));
    let (w, h) = (240usize, 180usize);
    for light in [[0.3, 6.0, 0.2, 1.0], [0.4, 1.0, 0.3, 0.0], [-2.0, 4.0, 1.0, 1.0]] {
        let p = params([5.0, 4.0, 6.0], [0.0, 0.5, 0.0], light, (w as u32, h as u32));
        let (reference, got) = masks(&ctx, &mesh, &p);
        let (outside, inside, shadowed) = compare(&reference, &got, w, h);
        println!(
            "box + tetrahedron, light {light:?}: {shadowed} shadowed; differ outside band {outside}, in band {inside}"
        );
        assert!(shadowed > 300, "the casters must cast a visible shadow ({shadowed})");
        assert_eq!(
            outside, 0,
            "light {light:?}: {outside} samples differ from cpu-silhouette outside the boundary band"
        );
    }
}

/// A finely tessellated sphere: still exact in its shadow, but on its lit surface a sample right
/// next to an interior edge sees the two neighbours' volumes meet in a side through that edge;
/// counting methods cancel the two copies, paper 002 judges each volume on its own, so a depth
/// tie between that side and the surface can read as PASS + ZFAIL of one volume (1100b). Such
/// samples are rare; they are counted here and bounded (0.05 % of the samples).
#[test]
fn nearly_exact_for_a_fine_sphere() {
    let ctx = common::context();
    let mesh = sphere_over_ground();
    let (w, h) = (240usize, 180usize);
    for light in [[0.3, 6.0, 0.2, 1.0], [0.4, 1.0, 0.3, 0.0], [-2.0, 4.0, 1.0, 1.0]] {
        let p = params([5.0, 4.0, 6.0], [0.0, 0.5, 0.0], light, (w as u32, h as u32));
        let (reference, got) = masks(&ctx, &mesh, &p);
        let (outside, inside, shadowed) = compare(&reference, &got, w, h);
        println!("sphere 48x24, light {light:?}: {shadowed} shadowed; differ outside band {outside}, in band {inside}");
        assert!(shadowed > 300, "the sphere must cast a visible shadow ({shadowed})");
        assert!(
            outside * 2000 <= w * h,
            "light {light:?}: {outside} samples differ from cpu-silhouette outside the boundary band"
        );
    }
}

#[test]
fn exact_for_overlapping_volumes_of_a_tree() {
    // Hundreds of disconnected leaves whose volumes overlap many times: exact as long as each
    // volume is drawn whole before the next (camera outside every volume).
    let ctx = common::context();
    let mesh = Arc::new(weld(&tree(3000, 7)));
    let (w, h) = (240usize, 180usize);
    let p = params([6.0, 7.0, 8.0], [0.0, 1.5, 0.0], [0.5, 9.0, 0.3, 1.0], (w as u32, h as u32));
    let (reference, got) = masks(&ctx, &mesh, &p);
    let (outside, inside, shadowed) = compare(&reference, &got, w, h);
    println!("tree of 3000 leaves: {shadowed} shadowed; differ outside band {outside}, in band {inside}");
    assert!(shadowed > 1000, "the tree must cast a visible shadow ({shadowed})");
    assert_eq!(outside, 0, "{outside} samples differ from cpu-silhouette outside the boundary band");
}

#[test]
fn camera_inside_a_shadow_volume_is_wrong() {
    // The eye on the ground in the sphere's umbra: paper 002's parity scheme sees only the
    // exit faces of the volumes around the eye (see the module documentation).
    let ctx = common::context();
    let mesh = sphere_over_ground();
    let (w, h) = (240usize, 180usize);
    let p = params([0.1, 0.3, 0.1], [4.0, 0.0, 3.0], [0.3, 6.0, 0.2, 1.0], (w as u32, h as u32));
    let (reference, got) = masks(&ctx, &mesh, &p);
    let (outside, inside, shadowed) = compare(&reference, &got, w, h);
    println!("camera in shadow: {shadowed} shadowed; differ outside band {outside}, in band {inside}");
    assert!(outside > 1000, "expected the documented failure, got only {outside} wrong samples");
}

// ---------------------------------------------------------------------------------------
// Timing (ignored by default).

fn time_frames(
    ctx: &HeadlessContext,
    scene: &SceneGpu,
    method: &mut dyn ShadowMethod,
    p: &FrameParams,
    frames: usize,
) -> f64 {
    let gl = ctx.gl();
    let mut r = Renderer::new(gl).expect("renderer").with_error_log(ctx.error_log().cloned());
    r.render(gl, scene, method, p, None).unwrap_or_else(|e| panic!("{}: {e}", method.name()));
    let mut ms: Vec<f64> = (0..frames)
        .map(|_| {
            let t = Instant::now();
            r.render(gl, scene, method, p, None).expect("render");
            t.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    r.destroy(gl);
    ms.sort_by(f64::total_cmp);
    ms[ms.len() / 2]
}

/// Trees of growing leaf counts at 1280x720, all-edges-invert against cpu-silhouette (and the
/// per-triangle vs-triangle, which draws the same amount of geometry with counting).
#[test]
#[ignore = "timing; run with --ignored --nocapture"]
fn tree_frame_times() {
    let frames: usize = std::env::var("UMBRA_FRAMES").ok().and_then(|s| s.parse().ok()).unwrap_or(5);
    let ctx = common::context();
    let gl = ctx.gl();
    println!("procedural tree, 1280x720, {}", ctx.renderer_string());
    for leaves in [1_000usize, 10_000, 100_000, 300_000] {
        let mesh = Arc::new(weld(&tree(leaves, 11)));
        let scene = SceneGpu::upload(gl, mesh.clone()).expect("upload");
        let p = params([6.0, 7.0, 8.0], [0.0, 1.5, 0.0], [0.5, 9.0, 0.3, 1.0], (1280, 720));
        let mut line = format!("  {leaves:>7} leaves ({:>7} triangles):", mesh.triangles.len());
        for name in ["none", "cpu-silhouette", "all-edges-invert", "vs-triangle"] {
            let mut m = create_method(name).expect("registered");
            let ms = time_frames(&ctx, &scene, m.as_mut(), &p, frames);
            m.destroy(gl);
            line += &format!("  {name} {ms:8.1} ms");
        }
        println!("{line}");
        scene.destroy(gl);
    }
}
