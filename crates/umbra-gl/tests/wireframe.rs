//! The shadow-volume wireframe ([`Renderer::draw_volume_wireframe`], the viewer's
//! toggle) on the default scene (sphere over ground, point light):
//! * drawn over a frame, it changes some pixels but far fewer than all (lines, not fills),
//!   and only darkens them (`dst * tint` with a tint < 1);
//! * the frame rendered after it is byte-identical to the frame rendered before it (every
//!   state it changes, polygon mode and blend colour included, is restored);
//! * a method without volumes (a shadow map) gives a typed error and changes nothing;
//! * every counting method's wireframe restores the state (how much of it shows differs per
//!   method, printed).

mod common;

use common::*;
use umbra_gl::glow::{self, HasContext};
use umbra_gl::{create_method, FrameParams, FrameTarget, GlError, Renderer, RgbaImage, SceneGpu};

const W: u32 = 160;
const H: u32 = 120;
const TINT: [f32; 3] = [1.0, 0.25, 0.25];

fn frame() -> FrameParams {
    FrameParams { capture: Default::default(), ..params(default_camera(), vec![POINT_LIGHT], W, H) }
}

/// Frame before, frame with the wireframe over it, frame after (a fresh render).
fn before_wire_after(method: &str) -> (RgbaImage, RgbaImage, RgbaImage) {
    let ctx = context();
    let gl = ctx.gl();
    let scene = SceneGpu::upload(gl, sphere_over_ground()).expect("upload");
    let mut m = create_method(method).expect("registered method");
    let mut r = Renderer::new(gl).expect("renderer").with_error_log(ctx.error_log().cloned());
    let p = frame();
    let before = r.render(gl, &scene, m.as_mut(), &p, None).expect("frame before").rgba;
    let fb = r.target().expect("own target").framebuffer();
    r.draw_volume_wireframe(gl, &scene, m.as_mut(), &p, p.lights[0], FrameTarget { framebuffer: Some(fb) }, TINT)
        .unwrap_or_else(|e| panic!("{method}: wireframe: {e}"));
    let wired = r.target().expect("own target").read_rgba(gl);
    // SAFETY: a query on the current context: the wireframe must have restored FILL.
    let mut mode = [0i32; 2];
    unsafe { gl.get_parameter_i32_slice(glow::POLYGON_MODE, &mut mode) };
    assert_eq!(mode[0] as u32, glow::FILL, "{method}: polygon mode restored");
    let after = r.render(gl, &scene, m.as_mut(), &p, None).expect("frame after").rgba;
    m.destroy(gl);
    r.destroy(gl);
    scene.destroy(gl);
    (before, wired, after)
}

fn check_method(method: &str) {
    let (before, wired, after) = before_wire_after(method);
    let ctx = context();
    assert_same_image(&ctx, &format!("wireframe_{method}_state_restored"), &before, &after);
    let total = (W * H) as usize;
    let mut changed = 0;
    for (a, b) in before.pixels.iter().zip(&wired.pixels) {
        if a != b {
            changed += 1;
            // Only darkened (tint <= 1 per channel), alpha untouched.
            assert!(b[0] <= a[0] && b[1] <= a[1] && b[2] <= a[2] && b[3] == a[3], "{method}: {a:?} -> {b:?}");
        }
    }
    eprintln!("{method}: wireframe changed {changed} of {total} pixels");
    assert!(changed > 50, "{method}: the wireframe changed only {changed} pixels");
    assert!(changed < total / 3, "{method}: the wireframe changed {changed} of {total} pixels: not lines");
}

#[test]
fn cpu_silhouette_wireframe_draws_lines_and_restores_state() {
    check_method("cpu-silhouette");
}

#[test]
fn vs_silhouette_wireframe_draws_lines_and_restores_state() {
    check_method("vs-silhouette");
}

#[test]
fn cs_silhouette_wireframe_draws_lines_and_restores_state() {
    check_method("cs-silhouette");
}

#[test]
fn shadow_map_has_no_volumes_typed_error() {
    let ctx = context();
    let gl = ctx.gl();
    let scene = SceneGpu::upload(gl, sphere_over_ground()).expect("upload");
    let mut m = create_method("shadow-map-cube:1024").expect("registered method");
    let mut r = Renderer::new(gl).expect("renderer").with_error_log(ctx.error_log().cloned());
    let p = frame();
    let before = r.render(gl, &scene, m.as_mut(), &p, None).expect("frame").rgba;
    let fb = r.target().expect("own target").framebuffer();
    let e =
        r.draw_volume_wireframe(gl, &scene, m.as_mut(), &p, p.lights[0], FrameTarget { framebuffer: Some(fb) }, TINT);
    assert!(matches!(e, Err(GlError::Unsupported { .. })), "{e:?}");
    assert_eq!(r.target().expect("own target").read_rgba(gl), before, "nothing drawn");
    m.destroy(gl);
    r.destroy(gl);
    scene.destroy(gl);
}

#[test]
fn non_finite_tint_is_invalid_params() {
    let ctx = context();
    let gl = ctx.gl();
    let scene = SceneGpu::upload(gl, sphere_over_ground()).expect("upload");
    let mut m = create_method("cpu-silhouette").expect("registered method");
    let mut r = Renderer::new(gl).expect("renderer").with_error_log(ctx.error_log().cloned());
    let p = frame();
    let e =
        r.draw_volume_wireframe(gl, &scene, m.as_mut(), &p, p.lights[0], FrameTarget::default(), [f32::NAN, 1.0, 1.0]);
    assert!(matches!(e, Err(GlError::InvalidParams(_))), "{e:?}");
    m.destroy(gl);
    r.destroy(gl);
    scene.destroy(gl);
}

/// Every method that draws volumes: the wireframe draws without a GL error, only darkens,
/// and the state is restored (the next frame is byte-identical). How much shows differs per
/// method (printed; see `Renderer::draw_volume_wireframe`): the per-triangle methods draw
/// every triangle's volume (dense), methods that set their counting state after their last
/// stage mark draw those parts invisibly (gs-silhouette shows nothing on llvmpipe).
#[test]
fn every_volume_method_wireframe_restores_state() {
    for method in counting_methods() {
        let (before, wired, after) = before_wire_after(method);
        let ctx = context();
        assert_same_image(&ctx, &format!("wireframe_all_{method}_state_restored"), &before, &after);
        let changed = before.pixels.iter().zip(&wired.pixels).filter(|(a, b)| a != b).count();
        for (a, b) in before.pixels.iter().zip(&wired.pixels) {
            assert!(b[0] <= a[0] && b[1] <= a[1] && b[2] <= a[2] && b[3] == a[3], "{method}: {a:?} -> {b:?}");
        }
        eprintln!("{method}: wireframe changed {changed} of {} pixels", W * H);
    }
}
