//! Edge cases of the host API: a framebuffer without stencil, `add_light` before
//! `count_shadows`, an invalid light, no default framebuffer: each a typed error.

use crate::common::*;
use crate::gl_state::{assert_same_state, query_state};
use crate::host::{Host, H, W};
use crate::{view, DIRECTIONAL, POINT};
use umbra_gl::glow::{self, HasContext};
use umbra_gl::{create_method, DepthConvention, FrameTarget, GlError, Renderer, SceneGpu, ShadowMethod};

/// A framebuffer with depth but no stencil: a typed error, nothing drawn, state restored.
#[test]
fn framebuffer_without_stencil_is_an_error() {
    let ctx = context();
    let gl = ctx.gl();
    let scene = SceneGpu::upload(gl, sphere_over_ground()).expect("upload");
    let mut renderer = Renderer::new(gl).expect("renderer").with_error_log(ctx.error_log().cloned());
    let mut method = create_method("cpu-silhouette").expect("method");
    // SAFETY: object creation on the current context.
    let (fbo, rbs) = unsafe {
        let fbo = gl.create_framebuffer().expect("fbo");
        gl.bind_framebuffer(glow::FRAMEBUFFER, Some(fbo));
        let mut rbs = Vec::new();
        for (format, attachment) in
            [(glow::RGBA8, glow::COLOR_ATTACHMENT0), (glow::DEPTH_COMPONENT24, glow::DEPTH_ATTACHMENT)]
        {
            let rb = gl.create_renderbuffer().expect("rb");
            gl.bind_renderbuffer(glow::RENDERBUFFER, Some(rb));
            gl.renderbuffer_storage(glow::RENDERBUFFER, format, W as i32, H as i32);
            gl.framebuffer_renderbuffer(glow::FRAMEBUFFER, attachment, glow::RENDERBUFFER, Some(rb));
            rbs.push(rb);
        }
        gl.bind_framebuffer(glow::FRAMEBUFFER, None);
        (fbo, rbs)
    };
    let p = view(POINT, DepthConvention::Standard);
    let before = query_state(gl);
    let err = renderer
        .count_shadows(gl, &scene, method.as_mut(), &p, POINT, FrameTarget { framebuffer: Some(fbo) })
        .expect_err("no stencil");
    assert!(matches!(&err, GlError::InvalidParams(m) if m.contains("stencil bits")), "{err}");
    assert_same_state(&before, &query_state(gl), "failed count_shadows");
    assert!(ctx.take_gl_errors().is_empty(), "the check itself raises no GL error");
    // SAFETY: our own objects.
    unsafe {
        gl.delete_framebuffer(fbo);
        rbs.into_iter().for_each(|rb| gl.delete_renderbuffer(rb));
    }
    method.destroy(gl);
    renderer.destroy(gl);
    scene.destroy(gl);
}

/// add_light needs the method's volumes of this scene (count_shadows first); an invalid
/// light is refused before any GL call.
#[test]
fn add_light_before_count_shadows_and_bad_lights_are_errors() {
    let ctx = context();
    let gl = ctx.gl();
    let scene = SceneGpu::upload(gl, sphere_over_ground()).expect("upload");
    let mut renderer = Renderer::new(gl).expect("renderer").with_error_log(ctx.error_log().cloned());
    let mut method: Box<dyn ShadowMethod> = create_method("vs-silhouette").expect("method");
    let p = view(POINT, DepthConvention::Standard);
    let host = Host::new(gl, &scene, DepthConvention::Standard);
    let target = FrameTarget { framebuffer: Some(host.fbo) };
    let err = renderer.add_light(gl, &scene, method.as_mut(), &p, POINT, target).expect_err("not counted yet");
    assert!(err.to_string().contains("count_shadows first"), "{err}");
    for bad in [[0.0, 1.0, 0.0, 0.5], [0.0, 0.0, 0.0, 0.0], [f32::NAN, 1.0, 0.0, 1.0]] {
        let err = renderer.count_shadows(gl, &scene, method.as_mut(), &p, bad, target).expect_err("bad light");
        assert!(matches!(err, GlError::InvalidParams(_)), "{bad:?}: {err}");
    }
    assert!(ctx.take_gl_errors().is_empty());
    host.destroy(gl);
    method.destroy(gl);
    renderer.destroy(gl);
    scene.destroy(gl);
}

/// The surfaceless headless context has no default framebuffer: count_shadows into it is a
/// typed framebuffer error (GL_FRAMEBUFFER_UNDEFINED), not a GL error, state untouched.
#[test]
fn missing_default_framebuffer_is_a_framebuffer_error() {
    let ctx = context();
    let gl = ctx.gl();
    let scene = SceneGpu::upload(gl, sphere_over_ground()).expect("upload");
    let mut renderer = Renderer::new(gl).expect("renderer").with_error_log(ctx.error_log().cloned());
    let mut method = create_method("cpu-silhouette").expect("method");
    let p = view(DIRECTIONAL, DepthConvention::Standard);
    let before = query_state(gl);
    let err = renderer
        .count_shadows(gl, &scene, method.as_mut(), &p, DIRECTIONAL, FrameTarget { framebuffer: None })
        .expect_err("no default framebuffer");
    assert!(matches!(err, GlError::Framebuffer { status: glow::FRAMEBUFFER_UNDEFINED, .. }), "{err}");
    assert_same_state(&before, &query_state(gl), "failed count_shadows");
    assert!(ctx.take_gl_errors().is_empty());
    method.destroy(gl);
    renderer.destroy(gl);
    scene.destroy(gl);
}
