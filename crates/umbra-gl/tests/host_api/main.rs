//! umbra inside a stranger's renderer: the host draws its scene's depth with its
//! own shader into its own framebuffer, then [`Renderer::count_shadows`] counts one light's
//! volumes into the host's stencil and [`Renderer::add_light`] adds umbra's lighting.
//!
//! Checked per method, light (point w = 1, directional w = 0) and depth convention:
//! * the stencil after `count_shadows` equals, pixel by pixel, the stencil
//!   [`Renderer::render_stencil`] gives for the same view (counting and stencil-test methods);
//!   for a shadow map (classified in its shader, resolved into the stencil by
//!   `count_shadows`): 0 exactly where umbra's own frame lights a surface facing the light;
//! * the host's depth bytes and colour bytes are unchanged by `count_shadows`;
//! * a list of GL states (blend, depth, stencil, cull, clip control, program, VAO,
//!   framebuffers, viewport, colour mask, scissor, polygon offset, depth range, patch size,
//!   buffer and texture bindings, draw buffers) is the same before and after both calls;
//! * after `add_light` the host's colour equals umbra's own frame byte for byte and its
//!   lit-mask attachment equals umbra's lit mask.
//!
//! Edge cases named as tests: a framebuffer without stencil, `add_light` before
//! `count_shadows`, an invalid light.

#[path = "../common/mod.rs"]
mod common;
mod edge_cases;
mod gl_state;
mod host;
mod mint;

use common::*;
use gl_state::{assert_same_state, query_state};
use host::{Host, H, W};
use umbra_gl::glow;
use umbra_gl::{
    create_method, read_rgba8, read_stencil, CaptureFlags, Classification, DepthConvention, FrameParams, FrameTarget,
    HeadlessContext, Image, LightCapture, Renderer, SceneGpu, NO_TRIANGLE,
};

const DIRECTIONAL: [f32; 4] = [-0.4, 1.0, 0.3, 0.0];
const POINT: [f32; 4] = [1.5, 6.0, 0.5, 1.0];

/// The view of every case: the sphere over the ground, one light.
fn view(light: [f32; 4], convention: DepthConvention) -> FrameParams {
    FrameParams {
        camera: default_camera(),
        width: W,
        height: H,
        lights: vec![light],
        light_color: [0.7; 3],
        depth_convention: convention,
        ..FrameParams::default()
    }
}

/// One method, light and convention through the host API, checked against umbra's own frame.
fn check_case(
    ctx: &HeadlessContext,
    scene: &SceneGpu,
    method_name: &str,
    light: [f32; 4],
    convention: DepthConvention,
) {
    let gl = ctx.gl();
    let case = format!("{method_name}, light {light:?}, {convention:?}");
    let p = view(light, convention);
    let mut renderer = Renderer::new(gl).expect("renderer").with_error_log(ctx.error_log().cloned());
    let mut method = create_method(method_name).expect("method");

    // umbra's own frame of the same view: its stencil after the volume pass, lit mask, colour.
    let reference_stencil = renderer.render_stencil(gl, scene, method.as_mut(), &p, 0).expect("render_stencil");
    let own = FrameParams {
        capture: CaptureFlags { lit_mask: LightCapture::Light(0), triangle_id: true, ..CaptureFlags::default() },
        ..p.clone()
    };
    let frame = renderer.render(gl, scene, method.as_mut(), &own, None).expect("render");
    let lit = &frame.lit_masks[0].image;

    let host = Host::new(gl, scene, convention);
    host.draw_scene(ctx, &p);
    host.plain_state(ctx);
    let depth_before = host.read_depth(gl);
    let color_before = read_rgba8(gl, Some(host.fbo), glow::COLOR_ATTACHMENT0, W, H);
    let lit_before = host.read_lit(gl);

    // ---- count_shadows under unusual host state.
    host.set_unusual_state(ctx);
    let state_before = query_state(gl);
    let target = FrameTarget { framebuffer: Some(host.fbo) };
    let classification =
        renderer.count_shadows(gl, scene, method.as_mut(), &p, light, target).unwrap_or_else(|e| panic!("{case}: {e}"));
    assert_same_state(&state_before, &query_state(gl), &format!("{case}: count_shadows"));
    host.plain_state(ctx);
    assert!(host.read_depth(gl) == depth_before, "{case}: count_shadows changed the host's depth");
    assert_eq!(read_rgba8(gl, Some(host.fbo), glow::COLOR_ATTACHMENT0, W, H), color_before, "{case}: colour changed");
    assert_eq!(host.read_lit(gl), lit_before, "{case}: colour attachment 3 changed");
    let stencil = read_stencil(gl, Some(host.fbo), W, H);

    match method.classification() {
        Classification::Shader => {
            assert_eq!(classification, Classification::StencilZero, "{case}: resolved into the stencil");
            // 0 where umbra's own frame lit a surface; where it did not, a surface facing the
            // light (lit by `none`) is 1 and so is the background; facing away is free.
            let facing = none_lit_mask(ctx, scene, &p);
            let ids = frame.triangle_id.as_ref().expect("triangle ids");
            let mut wrong = 0;
            for i in 0..stencil.pixels.len() {
                let expected = match (lit.pixels[i], facing.pixels[i], ids.pixels[i] == NO_TRIANGLE) {
                    (1, _, _) => Some(0),
                    (_, _, true) => Some(1),
                    (0, 1, false) => Some(1),
                    _ => None,
                };
                wrong += usize::from(expected.is_some_and(|e| e != stencil.pixels[i]));
            }
            assert_eq!(wrong, 0, "{case}: resolved stencil differs from umbra's own lit decision at {wrong} pixels");
            assert!(stencil.pixels.iter().filter(|&&s| s == 0).count() > 1000, "{case}: lit pixels exist");
            assert!(stencil.pixels.iter().filter(|&&s| s == 1).count() > 1000, "{case}: shadowed pixels exist");
        }
        c => {
            assert_eq!(classification, c, "{case}: the method's own classification");
            let differ = stencil.pixels.iter().zip(&reference_stencil.pixels).filter(|(a, b)| a != b).count();
            assert_eq!(differ, 0, "{case}: host stencil differs from render_stencil at {differ} pixels");
            assert!(stencil.pixels.iter().any(|&s| s != 0), "{case}: some pixel is in shadow");
        }
    }

    // ---- add_light under the same unusual host state.
    host.set_unusual_state(ctx);
    let state_before = query_state(gl);
    renderer
        .add_light(gl, scene, method.as_mut(), &p, light, target)
        .unwrap_or_else(|e| panic!("{case}: add_light: {e}"));
    assert_same_state(&state_before, &query_state(gl), &format!("{case}: add_light"));
    host.plain_state(ctx);
    assert!(host.read_depth(gl) == depth_before, "{case}: add_light changed the host's depth");
    let color = read_rgba8(gl, Some(host.fbo), glow::COLOR_ATTACHMENT0, W, H);
    let differ = color.pixels.iter().zip(&frame.rgba.pixels).filter(|(a, b)| a != b).count();
    assert_eq!(differ, 0, "{case}: host colour after add_light differs from umbra's frame at {differ} pixels");
    let host_lit = host.read_lit(gl);
    let differ = host_lit.pixels.iter().zip(&lit.pixels).filter(|(a, b)| a != b).count();
    assert_eq!(differ, 0, "{case}: host lit mask differs from umbra's at {differ} pixels");
    let lit_count = lit.pixels.iter().filter(|&&l| l == 1).count();
    assert!(lit_count > 1000 && lit_count < lit.pixels.len() - 1000, "{case}: lit and unlit pixels ({lit_count})");

    host.destroy(gl);
    method.destroy(gl);
    renderer.destroy(gl);
    assert!(ctx.take_gl_errors().is_empty(), "{case}: no GL errors");
}

/// umbra's lit mask with the `none` method: every surface whose seen side faces the light.
fn none_lit_mask(ctx: &HeadlessContext, scene: &SceneGpu, p: &FrameParams) -> Image<u8> {
    let gl = ctx.gl();
    let mut renderer = Renderer::new(gl).expect("renderer");
    let mut none = create_method("none").expect("none");
    let q = FrameParams {
        capture: CaptureFlags { lit_mask: LightCapture::Light(0), ..CaptureFlags::default() },
        ..p.clone()
    };
    let f = renderer.render(gl, scene, none.as_mut(), &q, None).expect("none render");
    none.destroy(gl);
    renderer.destroy(gl);
    f.lit_masks[0].image.clone()
}

fn run_methods(methods: &[&str], conventions: &[DepthConvention]) {
    let ctx = context();
    let scene = SceneGpu::upload(ctx.gl(), sphere_over_ground()).expect("upload");
    for &m in methods {
        for &convention in conventions {
            for light in [POINT, DIRECTIONAL] {
                check_case(&ctx, &scene, m, light, convention);
            }
        }
    }
    scene.destroy(ctx.gl());
}

#[test]
fn silhouette_methods_count_into_the_hosts_stencil_like_their_own_frame() {
    run_methods(
        &["cpu-silhouette", "vs-silhouette", "ts-silhouette", "cs-silhouette", "gs-silhouette"],
        &[DepthConvention::Standard, DepthConvention::ReversedZ],
    );
}

/// hier-triangle extracts its samples from the host's depth (depth func EQUAL) and writes its
/// decision into the host's stencil: the same as in its own frame.
#[test]
fn hier_triangle_decides_into_the_hosts_stencil_like_its_own_frame() {
    run_methods(&["hier-triangle"], &[DepthConvention::Standard, DepthConvention::ReversedZ]);
}

/// hier-silhouette, the same way (its samples from the host's depth, its decision into the
/// host's stencil).
#[test]
fn hier_silhouette_decides_into_the_hosts_stencil_like_its_own_frame() {
    run_methods(&["hier-silhouette"], &[DepthConvention::Standard, DepthConvention::ReversedZ]);
}

/// ray-bvh, the same way (its samples from the host's depth, one shadow ray each, its decision
/// into the host's stencil).
#[test]
fn ray_bvh_decides_into_the_hosts_stencil_like_its_own_frame() {
    run_methods(&["ray-bvh"], &[DepthConvention::Standard, DepthConvention::ReversedZ]);
}

#[test]
fn stencil_test_method_returns_its_own_classification() {
    run_methods(&["all-edges-invert"], &[DepthConvention::Standard]);
}

#[test]
fn shadow_map_is_resolved_into_the_hosts_stencil() {
    run_methods(&["shadow-map-cube:1024"], &[DepthConvention::Standard, DepthConvention::ReversedZ]);
}
