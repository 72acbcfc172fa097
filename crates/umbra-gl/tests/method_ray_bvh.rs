//! ray-bvh (one shadow ray per view sample through a CPU-built BVH, compute shaders): what the
//! torture suite cannot see. Exactness against the reference is the torture suite's and
//! crates/umbra-verify/tests/ray_bvh.rs's job; here:
//! * an empty scene and an all-background frame: nothing shadowed, no GL error;
//! * the stencil equals cpu-silhouette's "shadowed" decision on the sphere over the ground, for
//!   point and directional lights, several lights in one frame (the samples are made once per
//!   frame and reused), and again with walks of one step a pass (every walk parked and resumed);
//! * gpu_bytes is the BVH's bytes plus the frame's formula, and the BVH's figures are reported.

mod common;

use std::sync::Arc;

use common::*;
use umbra_geom::{weld::weld, Mesh};
use umbra_gl::methods::ray_bvh::{frame_bytes, RayBvhMethod};
use umbra_gl::{create_method, Camera, Renderer, SceneGpu, ShadowMethod};

#[test]
fn empty_scene_and_all_background_frame_shadow_nothing() {
    let ctx = context();
    let empty = Arc::new(weld(&Mesh::default()));
    let s =
        volume_stencils(&ctx, &empty, &mut RayBvhMethod::new(), &method_frame(vec![POINT_LIGHT, [1.0, 2.0, 0.5, 0.0]]));
    assert_eq!(s.len(), 2);
    assert!(s.iter().all(|img| img.pixels.iter().all(|&v| v == 0)), "an empty scene cast a shadow");
    let mesh = sphere_over_ground();
    let mut p = method_frame(vec![POINT_LIGHT]);
    p.camera = Camera { eye: [0.0, 20.0, 0.0], target: [0.0, 40.0, 0.0], up: [1.0, 0.0, 0.0], ..Camera::default() };
    let images = render_once(&ctx, &mesh, "ray-bvh", &params(p.camera, p.lights.clone(), METHOD_W, METHOD_H));
    let ids = images.triangle_id.expect("ids");
    assert!(ids.pixels.iter().all(|&t| t == umbra_gl::NO_TRIANGLE), "the frame is meant to show no surface");
    assert!(images.stencil[0].image.pixels.iter().all(|&v| v == 0));
    assert!(ctx.take_gl_errors().is_empty());
}

/// The sphere over the ground seen from above: cpu-silhouette's stencil decides like the
/// reference there (the torture suite); ray-bvh must decide the same on every pixel whose seen
/// side faces the light (elsewhere the stencil does not matter), with its default step budget
/// and with one step a pass.
#[test]
fn same_decision_as_cpu_silhouette_for_several_lights_and_resumed_walks() {
    let ctx = context();
    let mesh = sphere_over_ground();
    let p = method_frame(vec![POINT_LIGHT, [0.4, 1.0, 0.3, 0.0], [3.0, 4.0, -2.0, 1.0]]);
    let mut cpu = create_method("cpu-silhouette").expect("registered");
    let theirs = volume_stencils(&ctx, &mesh, cpu.as_mut(), &p);
    let lit = render_once(&ctx, &mesh, "none", &params(p.camera, p.lights.clone(), METHOD_W, METHOD_H)).lit_masks;
    for budget in [umbra_gl::methods::ray_bvh::DEFAULT_BUDGET, 1] {
        let ours = volume_stencils(&ctx, &mesh, &mut RayBvhMethod::with_budget(budget), &p);
        for (i, (a, b)) in ours.iter().zip(&theirs).enumerate() {
            let (a, b) = (stencil_shadowed(a), stencil_shadowed(b));
            let facing = &lit[i].image.pixels;
            let differ = (0..a.len()).filter(|&k| facing[k] != 0 && a[k] != b[k]).count();
            let shadows = (0..a.len()).filter(|&k| facing[k] != 0 && a[k]).count();
            assert!(shadows > 100, "light {i}, budget {budget}: only {shadows} shadowed samples");
            // Pixels where the two differ can only be rounding at shadow boundaries; the
            // torture suite holds both to the reference's band. Here: a handful at most.
            assert!(differ <= 4, "light {i}, budget {budget}: {differ} pixels differ from cpu-silhouette");
        }
    }
}

#[test]
fn gpu_bytes_are_the_bvh_and_the_frame_and_the_figures_say_so() {
    let ctx = context();
    let gl = ctx.gl();
    let mesh = sphere_over_ground();
    let scene = SceneGpu::upload(gl, mesh.clone()).expect("upload");
    let mut r = Renderer::new(gl).expect("renderer");
    let mut m = RayBvhMethod::new();
    r.render(gl, &scene, &mut m, &method_frame(vec![POINT_LIGHT]), None).expect("render");
    let bvh = umbra_geom::ray_bvh::build(&mesh.positions, &mesh.triangles);
    assert_eq!(m.scene_bytes(), bvh.bytes());
    assert_eq!(m.gpu_bytes(), bvh.bytes() + frame_bytes(METHOD_W, METHOD_H));
    let figures = m.scene_figures();
    let get = |k: &str| figures.iter().find(|(n, _)| *n == k).map(|&(_, v)| v);
    assert_eq!(get("bvh_bytes"), Some(bvh.bytes() as f64));
    assert_eq!(get("bvh_nodes"), Some(bvh.node_count() as f64));
    assert!(get("bvh_build_ms").is_some_and(|ms| ms >= 0.0));
    m.destroy(gl);
    assert_eq!(m.gpu_bytes(), 0);
    r.destroy(gl);
    scene.destroy(gl);
}
