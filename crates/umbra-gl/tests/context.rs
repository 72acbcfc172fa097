//! Headless contexts: several threads at once, GLES 3, extra entry points, GL errors.

mod common;

use common::*;
use umbra_gl::glow::HasContext;
use umbra_gl::{glow, ContextOptions, GlApi, GlError, HeadlessContext, Renderer, SceneGpu};

#[test]
fn gl45_core_context_reports_its_version_and_platform() {
    let ctx = context();
    let version = ctx.version_string();
    assert!(version.starts_with("4.5") || version.starts_with("4.6"), "GL_VERSION {version}");
    assert!(version.contains("Core"), "core profile expected: {version}");
    assert!(!ctx.renderer_string().is_empty());
    assert!(ctx.platform().contains("surfaceless") || ctx.platform().contains("device"), "{}", ctx.platform());
    // SAFETY: integer query on the context current on this thread; the debug flag was requested.
    let flags = unsafe { ctx.gl().get_parameter_i32(glow::CONTEXT_FLAGS) } as u32;
    assert_ne!(flags & glow::CONTEXT_FLAG_DEBUG_BIT, 0, "debug context expected");
    assert!(ctx.take_gl_errors().is_empty());
}

#[test]
fn gles3_context_can_be_created() {
    let ctx = HeadlessContext::new_gles3().unwrap_or_else(|e| panic!("GLES 3 context: {e}"));
    let version = ctx.version_string();
    assert!(version.starts_with("OpenGL ES 3."), "GL_VERSION {version}");
    assert_eq!(ctx.api(), GlApi::Gles3);
    // A trivial ES 3 shader compiles (the ES 3 paths build on this).
    let gl = ctx.gl();
    let src = "#version 300 es\nprecision highp float;\nout vec4 c;\nvoid main() { c = vec4(1.0); }\n";
    let p = umbra_gl::program::link_program(
        gl,
        "es3 test",
        &[
            umbra_gl::program::ShaderSource::vertex(
                "es3.vert",
                "#version 300 es\nvoid main() { gl_Position = vec4(0.0); }\n",
            ),
            umbra_gl::program::ShaderSource::fragment("es3.frag", src),
        ],
        &[],
    )
    .expect("ES 3 program links");
    // SAFETY: deleting the program just created on the current context.
    unsafe { gl.delete_program(p) };
    assert!(ctx.take_gl_errors().is_empty());
}

#[test]
fn missing_entry_points_are_loaded_into_gl_extra() {
    let ctx = context();
    let extra = ctx.extra();
    assert!(extra.has_clip_control(), "GL 4.5 has glClipControl");
    assert!(extra.has_multi_draw_indirect(), "GL 4.3 has glMultiDraw*Indirect");
    // Call glClipControl with the default values: must not raise an error.
    // SAFETY: the context is current on this thread.
    assert!(unsafe { extra.clip_control(glow::LOWER_LEFT, glow::NEGATIVE_ONE_TO_ONE) });
    assert!(ctx.take_gl_errors().is_empty());
}

/// A deliberate GL error is recorded by the synchronous debug callback, and a frame after it
/// returns Err (so a GL error fails any test that renders).
#[test]
fn gl_errors_are_reported_and_fail_the_frame() {
    let ctx = context();
    let gl = ctx.gl();
    // SAFETY: deliberately invalid enum; GL just records GL_INVALID_ENUM.
    unsafe { gl.enable(0xDEAD) };
    let log = ctx.error_log().expect("debug context has a log");
    let recorded = log.take();
    assert!(
        recorded.iter().any(|m| m.contains("0x824C")),
        "debug callback should have recorded a DEBUG_TYPE_ERROR (0x824C) message: {recorded:?}"
    );
    // glGetError still holds the code.
    let rest = ctx.take_gl_errors();
    assert!(rest.iter().any(|m| m.contains("GL_INVALID_ENUM")), "{rest:?}");

    let mesh = sphere_over_ground();
    let scene = SceneGpu::upload(gl, mesh).expect("upload");
    let mut renderer = Renderer::new(gl).expect("renderer").with_error_log(ctx.error_log().cloned());
    let mut method = umbra_gl::create_method("cpu-silhouette").expect("method");
    let p = params(default_camera(), vec![POINT_LIGHT], 64, 48);
    renderer.render(gl, &scene, method.as_mut(), &p, None).expect("clean frame");
    // SAFETY: as above.
    unsafe { gl.enable(0xDEAD) };
    match renderer.render(gl, &scene, method.as_mut(), &p, None) {
        Err(GlError::Gl { messages, .. }) => assert!(!messages.is_empty()),
        other => panic!("a frame after a GL error must fail, got {:?}", other.map(|_| ())),
    }
    // The error list is drained: the next frame is clean again.
    renderer.render(gl, &scene, method.as_mut(), &p, None).expect("clean frame after the failure");
}

/// Even without a debug context (no callback), glGetError makes frames fail.
#[test]
fn gl_errors_fail_the_frame_without_debug_output() {
    let ctx = HeadlessContext::with_options(ContextOptions { api: GlApi::Gl45Core, debug: false }).expect("context");
    assert!(ctx.error_log().is_none());
    let gl = ctx.gl();
    let scene = SceneGpu::upload(gl, sphere_over_ground()).expect("upload");
    let mut renderer = Renderer::new(gl).expect("renderer");
    let mut method = umbra_gl::create_method("none").expect("method");
    let p = params(default_camera(), vec![POINT_LIGHT], 32, 32);
    // SAFETY: deliberately invalid enum.
    unsafe { gl.enable(0xDEAD) };
    assert!(matches!(renderer.render(gl, &scene, method.as_mut(), &p, None), Err(GlError::Gl { .. })));
}

/// Three threads, each with its own context, render the same frame at the same time; all
/// images are identical (and equal to this thread's).
#[test]
fn contexts_on_three_threads_render_identical_images() {
    let mesh = sphere_over_ground();
    let p = params(default_camera(), vec![POINT_LIGHT, [0.3, 1.0, 0.2, 0.0]], 160, 120);
    let barrier = std::sync::Arc::new(std::sync::Barrier::new(3));
    let handles: Vec<_> = (0..3)
        .map(|_| {
            let (mesh, p, barrier) = (mesh.clone(), p.clone(), barrier.clone());
            std::thread::spawn(move || {
                let ctx = context();
                barrier.wait();
                let mut images = Vec::new();
                for _ in 0..3 {
                    images.push(render_once(&ctx, &mesh, "cpu-silhouette", &p).rgba);
                }
                images
            })
        })
        .collect();
    let results: Vec<Vec<umbra_gl::RgbaImage>> =
        handles.into_iter().map(|h| h.join().expect("render thread")).collect();
    let ctx = context();
    let here = render_once(&ctx, &mesh, "cpu-silhouette", &p).rgba;
    for img in results.iter().flatten() {
        assert_same_image(&ctx, "threads", &here, img);
    }
}

/// Two contexts on one thread: the newer one is current; the older one can be made current
/// again and still renders.
#[test]
fn two_contexts_on_one_thread_switch_with_make_current() {
    let a = context();
    let b = context();
    let mesh = sphere_over_ground();
    let p = params(default_camera(), vec![POINT_LIGHT], 64, 48);
    let from_b = render_once(&b, &mesh, "cpu-silhouette", &p).rgba;
    a.make_current().expect("make a current");
    let from_a = render_once(&a, &mesh, "cpu-silhouette", &p).rgba;
    assert_same_image(&a, "two_contexts", &from_a, &from_b);
    drop(b);
    // Dropping b (not current) must leave a current and working.
    let again = render_once(&a, &mesh, "cpu-silhouette", &p).rgba;
    assert_same_image(&a, "two_contexts_after_drop", &from_a, &again);
}
