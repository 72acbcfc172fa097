//! Library-first behaviour: drawing into a caller's framebuffer, restoring the caller's GL
//! state, the method registry, and a method with its own "lit" test (Classification::Shader).

mod common;

use common::*;
use umbra_gl::glow::HasContext;
use umbra_gl::{
    create_method, glow, method_names, read_rgba8, read_stencil, Attachments, BlendState, Classification, FrameTarget,
    GlError, GlState, RenderTarget, Renderer, SceneGpu, SceneId, ShadowMethod, StencilCapture, StencilFace, VolumeFrame,
};

#[test]
fn registry_lists_and_creates_every_method() {
    let names = method_names();
    assert!(names.contains(&"none") && names.contains(&"cpu-silhouette"), "{names:?}");
    for &n in names {
        assert_eq!(create_method(n).expect("registered").name(), n);
    }
    let err = create_method("shadow-magic").err().expect("unknown name");
    assert!(err.to_string().contains("cpu-silhouette"), "error lists the known methods: {err}");
}

/// draw_frame into a framebuffer the caller owns gives the same pixels and stencil as
/// render() into the renderer's own target, and leaves the caller's state as it was.
#[test]
fn caller_framebuffer_gets_the_same_frame_and_keeps_its_state() {
    let ctx = context();
    let gl = ctx.gl();
    let mesh = sphere_over_ground();
    let scene = SceneGpu::upload(gl, mesh.clone()).expect("upload");
    let mut renderer = Renderer::new(gl).expect("renderer").with_error_log(ctx.error_log().cloned());
    let mut method = create_method("cpu-silhouette").expect("method");
    let mut p = params(default_camera(), vec![POINT_LIGHT, [0.3, 1.0, 0.2, 0.0]], 160, 120);
    p.capture.world_pos = false;
    p.capture.triangle_id = false;
    p.capture.stencil = StencilCapture::Light(0);
    let own = renderer.render(gl, &scene, method.as_mut(), &p, None).expect("render");

    // The caller's framebuffer and some unusual state of theirs.
    let caller = RenderTarget::new(gl, p.width, p.height, Attachments::default()).expect("caller fbo");
    let theirs = GlState {
        depth_test: true,
        depth_func: glow::GREATER,
        depth_write: false,
        depth_clamp: true,
        stencil_test: true,
        stencil_front: StencilFace { func: glow::NOTEQUAL, reference: 3, value_mask: 0x0F, write_mask: 0x70, ..StencilFace::KEEP },
        stencil_back: StencilFace { func: glow::LEQUAL, reference: 1, value_mask: 0xF0, write_mask: 0x07, depth_pass: glow::INVERT, ..StencilFace::KEEP },
        color_write: [true, false, true, false],
        cull_face: Some(glow::FRONT),
        front_face: glow::CW,
        blend: Some(BlendState { src_rgb: glow::SRC_ALPHA, dst_rgb: glow::ONE_MINUS_SRC_ALPHA, ..BlendState::ADDITIVE }),
        polygon_offset: Some((1.5, 2.0)),
    };
    // SAFETY: plain state setters on the current context.
    unsafe {
        // Bound first: GL clamps the queried stencil reference to the stencil bits of the
        // current draw framebuffer (the surfaceless default framebuffer has none).
        gl.bind_framebuffer(glow::FRAMEBUFFER, Some(caller.framebuffer()));
        gl.viewport(3, 4, 50, 60);
        gl.enable(glow::SCISSOR_TEST);
    }
    theirs.apply(gl);
    let before = GlState::capture(gl);
    assert_eq!(before, theirs, "capture reads back what apply set");

    let stencils = renderer
        .draw_frame(gl, &scene, method.as_mut(), &p, FrameTarget { framebuffer: Some(caller.framebuffer()) }, None)
        .expect("draw_frame");

    assert_eq!(GlState::capture(gl), theirs, "GlState fields restored");
    // SAFETY: queries on the current context.
    unsafe {
        let mut vp = [0; 4];
        gl.get_parameter_i32_slice(glow::VIEWPORT, &mut vp);
        assert_eq!(vp, [3, 4, 50, 60], "viewport restored");
        assert!(gl.is_enabled(glow::SCISSOR_TEST), "scissor enable restored");
        assert_eq!(gl.get_parameter_i32(glow::READ_FRAMEBUFFER_BINDING) as u32, caller.framebuffer().0.get());
        assert_eq!(gl.get_parameter_i32(glow::DRAW_FRAMEBUFFER_BINDING) as u32, caller.framebuffer().0.get());
        assert_eq!(gl.get_parameter_i32(glow::CURRENT_PROGRAM), 0);
        assert_eq!(gl.get_parameter_i32(glow::VERTEX_ARRAY_BINDING), 0);
    }

    let theirs_rgba = read_rgba8(gl, Some(caller.framebuffer()), glow::COLOR_ATTACHMENT0, p.width, p.height);
    assert_same_image(&ctx, "caller_framebuffer", &own.rgba, &theirs_rgba);
    assert_eq!(stencils.len(), 1);
    assert_eq!(stencils[0].image, own.stencil[0].image, "stencil of light 0 through draw_frame");
    // Light 1 was drawn after light 0: the framebuffer's stencil now holds light 1's lighting
    // marks, not light 0's counts — read_stencil must still read it without error.
    let _ = read_stencil(gl, Some(caller.framebuffer()), p.width, p.height);
    assert!(ctx.take_gl_errors().is_empty());
    caller.destroy(gl);
    method.destroy(gl);
    renderer.destroy(gl);
    scene.destroy(gl);
}

/// A method that classifies in the lighting shader (as a shadow-map method would): lit
/// where world x > split. Checks the Classification::Shader path end to end.
struct HalfSpace {
    split: f32,
    prepared: Option<SceneId>,
    volumes_called: usize,
}

impl ShadowMethod for HalfSpace {
    fn name(&self) -> &'static str {
        "test-half-space"
    }
    fn stages(&self) -> &'static [&'static str] {
        &["nothing"]
    }
    fn prepare(&mut self, _gl: &glow::Context, scene: &SceneGpu) -> Result<(), GlError> {
        self.prepared = Some(scene.id());
        Ok(())
    }
    fn prepared_scene(&self) -> Option<SceneId> {
        self.prepared
    }
    fn draw_volumes(&mut self, gl: &glow::Context, _scene: &SceneGpu, frame: &mut VolumeFrame<'_>) -> Result<(), GlError> {
        frame.mark(gl, "nothing");
        self.volumes_called += 1;
        Ok(())
    }
    fn classification(&self) -> Classification {
        Classification::Shader
    }
    fn lighting_glsl(&self) -> Option<&'static str> {
        Some("uniform float u_split;\nbool umbra_lit(vec3 world_pos) { return world_pos.x > u_split; }\n")
    }
    fn bind_lighting(&mut self, gl: &glow::Context, program: glow::Program, _frame: &VolumeFrame<'_>) -> Result<(), GlError> {
        // SAFETY: the program is current (renderer contract); uniform set on it.
        unsafe {
            let loc = gl.get_uniform_location(program, "u_split");
            gl.uniform_1_f32(loc.as_ref(), self.split);
        }
        Ok(())
    }
    fn gpu_bytes(&self) -> usize {
        0
    }
    fn destroy(&mut self, _gl: &glow::Context) {
        self.prepared = None;
    }
}

#[test]
fn a_method_can_classify_in_the_lighting_shader() {
    let ctx = context();
    let gl = ctx.gl();
    let scene = SceneGpu::upload(gl, sphere_over_ground()).expect("upload");
    let mut renderer = Renderer::new(gl).expect("renderer").with_error_log(ctx.error_log().cloned());
    let mut method = HalfSpace { split: 1.0, prepared: None, volumes_called: 0 };
    let p = params(default_camera(), vec![POINT_LIGHT, [0.3, 1.0, 0.2, 0.0]], 200, 150);
    let mut hook = umbra_gl::TimestampHook::new();
    let img = renderer.render(gl, &scene, &mut method, &p, Some(&mut hook)).expect("render");
    assert_eq!(method.volumes_called, 2, "once per light");
    let timings = hook.finish(gl);
    let labels: Vec<_> = timings.iter().map(|t| (t.mark.source, t.mark.label, t.mark.light)).collect();
    assert_eq!(
        labels,
        vec![
            ("renderer", "depth", None),
            ("renderer", "volumes", Some(0)),
            ("test-half-space", "nothing", Some(0)),
            ("renderer", "lighting", Some(0)),
            ("renderer", "volumes", Some(1)),
            ("test-half-space", "nothing", Some(1)),
            ("renderer", "lighting", Some(1)),
        ]
    );
    let ambient = expected_ambient_u8(&p);
    let mut checks = PixelChecks::new(&ctx, "half_space", &img.rgba);
    for [x, z] in [[-3.0, 1.0], [-2.0, -1.0], [0.0, 3.5], [3.0, 0.0], [2.5, 2.5]] {
        let (px, py) = pixel_of(&p.camera, [x, 0.0, z], p.width, p.height);
        let c = img.rgba.get(px, py).expect("in image");
        let lit = x > 1.0;
        checks.check(px, py, (c[0].abs_diff(ambient) <= 1) != lit, || format!("x = {x}: colour {c:?}, lit expected {lit}"));
    }
    checks.finish();
    hook.destroy(gl);
    renderer.destroy(gl);
    scene.destroy(gl);
}

#[test]
fn bad_parameters_are_typed_errors_not_panics() {
    let ctx = context();
    let gl = ctx.gl();
    let scene = SceneGpu::upload(gl, sphere_over_ground()).expect("upload");
    let mut renderer = Renderer::new(gl).expect("renderer");
    let mut method = create_method("cpu-silhouette").expect("method");
    let good = params(default_camera(), vec![POINT_LIGHT], 32, 32);
    let cases = [
        ("zero width", umbra_gl::FrameParams { width: 0, ..good.clone() }),
        ("light w = 0.5", umbra_gl::FrameParams { lights: vec![[0.0, 1.0, 0.0, 0.5]], ..good.clone() }),
        ("zero direction", umbra_gl::FrameParams { lights: vec![[0.0, 0.0, 0.0, 0.0]], ..good.clone() }),
        ("NaN light", umbra_gl::FrameParams { lights: vec![[f32::NAN, 1.0, 0.0, 1.0]], ..good.clone() }),
        ("eye == target", umbra_gl::FrameParams { camera: umbra_gl::Camera::look_at([1.0; 3], [1.0; 3]), ..good.clone() }),
        (
            "stencil of a missing light",
            umbra_gl::FrameParams {
                capture: umbra_gl::CaptureFlags { stencil: StencilCapture::Light(3), ..good.capture },
                ..good.clone()
            },
        ),
    ];
    for (what, p) in cases {
        match renderer.render(gl, &scene, method.as_mut(), &p, None) {
            Err(GlError::InvalidParams(_)) => {}
            other => panic!("{what}: expected InvalidParams, got {:?}", other.map(|_| ())),
        }
    }
    // An out-of-range index is rejected at upload.
    let bad = std::sync::Arc::new(umbra_geom::WeldedMesh {
        positions: vec![[0.0; 3]; 3],
        triangles: vec![[0, 1, 7]],
        source_triangle: vec![0],
        degenerate_triangles: 0,
    });
    assert!(matches!(SceneGpu::upload(gl, bad), Err(GlError::InvalidParams(_))));
    // The good frame still works after all the rejected ones.
    renderer.render(gl, &scene, method.as_mut(), &good, None).expect("good frame");
}

/// An empty mesh renders just the background.
#[test]
fn empty_scene_renders_the_background() {
    let ctx = context();
    let mesh = std::sync::Arc::new(umbra_geom::WeldedMesh::default());
    let p = params(default_camera(), vec![POINT_LIGHT], 16, 8);
    for m in method_names() {
        let img = render_once(&ctx, &mesh, m, &p);
        let bg = p.background.map(|v| (v * 255.0).round() as u8);
        assert!(img.rgba.pixels.iter().all(|&c| c == bg), "{m}: {:?}", img.rgba.pixels[0]);
        assert!(img.triangle_id.expect("ids").pixels.iter().all(|&i| i == umbra_gl::NO_TRIANGLE));
    }
}
