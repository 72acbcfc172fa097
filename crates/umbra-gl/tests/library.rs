//! Library-first behaviour: drawing into a caller's framebuffer, restoring the caller's GL
//! state, the method registry, and a method with its own "lit" test (Classification::Shader).

mod common;

use common::*;
use umbra_gl::glow::HasContext;
use umbra_gl::{
    create_method, glow, method_names, read_rgba8, read_stencil, Attachments, BlendState, Classification,
    DepthConvention, FrameParams, FrameTarget, GlError, GlExtra, GlState, LightCapture, RenderTarget, Renderer,
    SceneGpu, SceneId, ShadowMethod, StencilCapture, StencilFace, VolumeFrame, NO_TRIANGLE,
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
/// render() into the renderer's own target, and leaves the caller's state as it was —
/// including glClipControl and glDepthRange, which the reversed-Z frame changes.
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
    // Float depth, like the renderer's own reversed-Z target.
    let caller = RenderTarget::new(gl, p.width, p.height, Attachments { float_depth: true, ..Attachments::default() })
        .expect("caller fbo");
    let theirs = GlState {
        depth_test: true,
        depth_func: glow::GREATER,
        depth_write: false,
        depth_clamp: true,
        stencil_test: true,
        stencil_front: StencilFace {
            func: glow::NOTEQUAL,
            reference: 3,
            value_mask: 0x0F,
            write_mask: 0x70,
            ..StencilFace::KEEP
        },
        stencil_back: StencilFace {
            func: glow::LEQUAL,
            reference: 1,
            value_mask: 0xF0,
            write_mask: 0x07,
            depth_pass: glow::INVERT,
            ..StencilFace::KEEP
        },
        color_write: [true, false, true, false],
        cull_face: Some(glow::FRONT),
        front_face: glow::CW,
        blend: Some(BlendState {
            src_rgb: glow::SRC_ALPHA,
            dst_rgb: glow::ONE_MINUS_SRC_ALPHA,
            ..BlendState::ADDITIVE
        }),
        polygon_offset: Some((1.5, 2.0)),
    };
    // SAFETY: plain state setters on the current context.
    unsafe {
        // Bound first: GL clamps the queried stencil reference to the stencil bits of the
        // current draw framebuffer (the surfaceless default framebuffer has none).
        gl.bind_framebuffer(glow::FRAMEBUFFER, Some(caller.framebuffer()));
        gl.viewport(3, 4, 50, 60);
        gl.enable(glow::SCISSOR_TEST);
        gl.depth_range_f64(0.25, 0.75);
        assert!(ctx.extra().clip_control(glow::UPPER_LEFT, glow::NEGATIVE_ONE_TO_ONE), "glClipControl loaded");
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
        assert_eq!(gl.get_parameter_i32(glow::CLIP_ORIGIN) as u32, glow::UPPER_LEFT, "clip origin restored");
        assert_eq!(
            gl.get_parameter_i32(glow::CLIP_DEPTH_MODE) as u32,
            glow::NEGATIVE_ONE_TO_ONE,
            "clip depth mode restored"
        );
        let mut range = [0.0f32; 2];
        gl.get_parameter_f32_slice(glow::DEPTH_RANGE, &mut range);
        assert_eq!(range, [0.25, 0.75], "depth range restored");
        // Back to GL's defaults for the reads below.
        gl.depth_range_f64(0.0, 1.0);
        ctx.extra().clip_control(glow::LOWER_LEFT, glow::NEGATIVE_ONE_TO_ONE);
    }

    let theirs_rgba = read_rgba8(gl, Some(caller.framebuffer()), glow::COLOR_ATTACHMENT0, p.width, p.height);
    assert_same_image(&ctx, "caller_framebuffer", &own.rgba, &theirs_rgba);
    assert_eq!(stencils.len(), 1);
    assert_eq!(stencils[0].image, own.stencil[0].image, "stencil of light 0 through draw_frame");
    // Light 1 was drawn after light 0: the framebuffer's stencil now holds light 1's lighting
    // marks, not light 0's counts — read_stencil must still read it without error.
    let _ = read_stencil(gl, Some(caller.framebuffer()), p.width, p.height);

    // The standard convention into a DEPTH24_STENCIL8 framebuffer: the frame the renderer's own
    // standard target gives.
    let standard = FrameParams { depth_convention: DepthConvention::Standard, ..p.clone() };
    let own_standard = renderer.render(gl, &scene, method.as_mut(), &standard, None).expect("render standard");
    let caller24 = RenderTarget::new(gl, p.width, p.height, Attachments::default()).expect("caller fbo d24");
    let stencils = renderer
        .draw_frame(
            gl,
            &scene,
            method.as_mut(),
            &standard,
            FrameTarget { framebuffer: Some(caller24.framebuffer()) },
            None,
        )
        .expect("draw_frame standard");
    let theirs24 = read_rgba8(gl, Some(caller24.framebuffer()), glow::COLOR_ATTACHMENT0, p.width, p.height);
    assert_same_image(&ctx, "caller_framebuffer_standard", &own_standard.rgba, &theirs24);
    assert_eq!(stencils[0].image, own_standard.stencil[0].image, "standard stencil of light 0 through draw_frame");
    assert!(ctx.take_gl_errors().is_empty());
    caller24.destroy(gl);
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
    fn draw_volumes(
        &mut self,
        gl: &glow::Context,
        _scene: &SceneGpu,
        frame: &mut VolumeFrame<'_>,
    ) -> Result<(), GlError> {
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
    fn bind_lighting(
        &mut self,
        gl: &glow::Context,
        program: glow::Program,
        _frame: &VolumeFrame<'_>,
    ) -> Result<(), GlError> {
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
    // The split crosses the sphere, so lit-by-umbra_lit pixels facing away from the light exist.
    let mut method = HalfSpace { split: -0.5, prepared: None, volumes_called: 0 };
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
        let lit = x > f64::from(method.split);
        checks.check(px, py, (c[0].abs_diff(ambient) <= 1) != lit, || {
            format!("x = {x}: colour {c:?}, lit expected {lit}")
        });
    }
    checks.finish();

    // The lit mask of a Shader classification: umbra_lit AND the seen side faces the light.
    let mesh = scene.mesh().clone();
    let (wp, ids) = (img.world_pos.as_ref().expect("wp"), img.triangle_id.as_ref().expect("ids"));
    assert_eq!(img.lit_masks.len(), 2);
    for (li, &light) in p.lights.iter().enumerate() {
        let mask = &img.lit_masks[li].image;
        let mut checks = PixelChecks::new(&ctx, "half_space_lit_mask", &img.rgba);
        let (mut lit, mut split_off, mut facing_away) = (0, 0, 0);
        for y in 0..p.height {
            for x in 0..p.width {
                let (m, id) = (mask.get(x, y).expect("in"), ids.get(x, y).expect("in"));
                if id == NO_TRIANGLE {
                    checks.check(x, y, m == 0, || "background marked lit".into());
                    continue;
                }
                let w = wp.get(x, y).expect("in");
                let world = [w[0], w[1], w[2]].map(f64::from);
                let Some(faces) = seen_side_faces_light(&mesh, id, world, p.camera.eye, light) else { continue };
                if (w[0] - method.split).abs() < 1e-4 {
                    continue;
                }
                let expected = w[0] > method.split && faces;
                lit += usize::from(expected);
                split_off += usize::from(faces && w[0] <= method.split);
                facing_away += usize::from(!faces && w[0] > method.split);
                if u8::from(expected) != m {
                    checks.check(x, y, false, || {
                        format!("light {li}: mask {m}, x = {}, seen side faces light {faces}", w[0])
                    });
                }
            }
        }
        checks.finish();
        assert!(
            lit > 500 && split_off > 500 && facing_away > 50,
            "light {li}: {lit} lit, {split_off} x <= split, {facing_away} facing away"
        );
    }
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
        (
            "eye == target",
            umbra_gl::FrameParams { camera: umbra_gl::Camera::look_at([1.0; 3], [1.0; 3]), ..good.clone() },
        ),
        (
            "stencil of a missing light",
            umbra_gl::FrameParams {
                capture: umbra_gl::CaptureFlags { stencil: StencilCapture::Light(3), ..good.capture },
                ..good.clone()
            },
        ),
        (
            "lit mask of a missing light",
            umbra_gl::FrameParams {
                capture: umbra_gl::CaptureFlags { lit_mask: LightCapture::Light(1), ..good.capture },
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

    // Without glClipControl, reversed-Z is refused (typed error) and the standard convention
    // still works.
    let mut bare = Renderer::new(gl).expect("renderer").with_extra(GlExtra::default());
    assert!(!bare.supports(DepthConvention::ReversedZ) && bare.supports(DepthConvention::Standard));
    assert!(matches!(bare.render(gl, &scene, method.as_mut(), &good, None), Err(GlError::InvalidParams(_))));
    let standard = FrameParams { depth_convention: DepthConvention::Standard, ..good.clone() };
    bare.render(gl, &scene, method.as_mut(), &standard, None).expect("standard frame without glClipControl");
    assert!(renderer.supports(DepthConvention::ReversedZ), "Renderer::new finds glClipControl through EGL");
    bare.destroy(gl);
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

/// Probes the far plane of the frame's depth convention with one screen-covering triangle
/// drawn with the frame's counting state ([`VolumeFrame::shadow_volume_state`]), both faces
/// set to INCR on depth FAIL:
/// * `at_infinity == false`: clip-space vertices pushed to the far plane by the shared
///   `umbra_push_to_far` with `u_far_clip_z = frame.far_clip_z()` (how light caps are drawn);
/// * `at_infinity == true`: world-space directions (w = 0) through `clip_from_world` (how the
///   far ends of sides and dark caps are drawn).
///
/// Depth clamp is turned OFF for the probe, so a vertex a hair beyond the far plane would be
/// clipped and leave the stencil at 0: the far plane must come out EXACTLY (depth 1 standard,
/// 0 reversed-Z). A triangle exactly there fails the strict test at every sample, geometry and
/// background alike, so the stencil must be 1 everywhere.
struct FarPlaneProbe {
    at_infinity: bool,
    /// World-space directions (w = 0) covering the view, for `at_infinity`.
    directions: [[f32; 4]; 3],
    gpu: Option<(glow::Program, glow::VertexArray)>,
    prepared: Option<SceneId>,
    /// Per frame: the convention, far_clip_z and depth func the method was given.
    seen: Vec<(DepthConvention, f32, u32)>,
}

const PROBE_VERT: &str = "uniform vec4 u_pos[3];\nuniform mat4 u_m;\nuniform bool u_push;\n\
void main() { vec4 c = u_m * u_pos[gl_VertexID]; gl_Position = u_push ? umbra_push_to_far(c) : c; }\n";

impl ShadowMethod for FarPlaneProbe {
    fn name(&self) -> &'static str {
        "test-far-plane-probe"
    }
    fn stages(&self) -> &'static [&'static str] {
        &[]
    }
    fn prepare(&mut self, gl: &glow::Context, scene: &SceneGpu) -> Result<(), GlError> {
        if self.gpu.is_none() {
            let depth_glsl = include_str!("../src/methods/shared/depth.glsl");
            let vert = format!("#version 450 core\n{depth_glsl}\n{PROBE_VERT}");
            let program = umbra_gl::program::link_program(
                gl,
                "far plane probe",
                &[
                    umbra_gl::program::ShaderSource::vertex("probe.vert", &vert),
                    umbra_gl::program::ShaderSource::fragment("probe.frag", "#version 450 core\nvoid main() {}\n"),
                ],
                &[],
            )?;
            // SAFETY: creating an (empty) vertex array on the current context.
            let vao = unsafe { gl.create_vertex_array() }
                .map_err(|detail| GlError::Create { what: "vertex array", detail })?;
            self.gpu = Some((program, vao));
        }
        self.prepared = Some(scene.id());
        Ok(())
    }
    fn prepared_scene(&self) -> Option<SceneId> {
        self.prepared
    }
    fn draw_volumes(
        &mut self,
        gl: &glow::Context,
        _scene: &SceneGpu,
        frame: &mut VolumeFrame<'_>,
    ) -> Result<(), GlError> {
        let Some((program, vao)) = self.gpu else { return Err(GlError::InvalidParams("probe not prepared".into())) };
        let mut state = frame.shadow_volume_state();
        self.seen.push((frame.depth_convention(), frame.far_clip_z(), state.depth_func));
        let count = StencilFace { depth_fail: glow::INCR_WRAP, depth_pass: glow::KEEP, ..state.stencil_front };
        state.stencil_front = count;
        state.stencil_back = count;
        // Reason: see the struct doc — without clamping, only an exact far plane survives.
        state.depth_clamp = false;
        state.apply(gl);
        let (m, pos) = if self.at_infinity {
            (frame.clip_from_world_f32(), self.directions)
        } else {
            let identity = [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0];
            // A clip-space triangle covering the viewport, at an arbitrary depth before the push.
            (identity, [[-1.0, -1.0, 0.3, 1.0], [3.0, -1.0, 0.3, 1.0], [-1.0, 3.0, 0.3, 1.0]])
        };
        let flat: Vec<f32> = pos.iter().flatten().copied().collect();
        // SAFETY: our program and empty VAO; uniforms match PROBE_VERT and depth.glsl.
        unsafe {
            gl.use_program(Some(program));
            gl.bind_vertex_array(Some(vao));
            gl.uniform_4_f32_slice(gl.get_uniform_location(program, "u_pos").as_ref(), &flat);
            gl.uniform_matrix_4_f32_slice(gl.get_uniform_location(program, "u_m").as_ref(), false, &m);
            gl.uniform_1_i32(gl.get_uniform_location(program, "u_push").as_ref(), i32::from(!self.at_infinity));
            gl.uniform_1_f32(gl.get_uniform_location(program, "u_far_clip_z").as_ref(), frame.far_clip_z());
            gl.draw_arrays(glow::TRIANGLES, 0, 3);
        }
        Ok(())
    }
    fn gpu_bytes(&self) -> usize {
        0
    }
    fn destroy(&mut self, gl: &glow::Context) {
        if let Some((program, vao)) = self.gpu.take() {
            // SAFETY: our own objects, not used afterwards.
            unsafe {
                gl.delete_program(program);
                gl.delete_vertex_array(vao);
            }
        }
        self.prepared = None;
    }
}

#[test]
fn the_far_plane_is_exact_and_fails_the_counting_test_everywhere() {
    let ctx = context();
    let gl = ctx.gl();
    let scene = SceneGpu::upload(gl, sphere_over_ground()).expect("upload");
    let mut renderer = Renderer::new(gl).expect("renderer").with_error_log(ctx.error_log().cloned());
    let camera = default_camera();
    // View-space directions (w = 0) whose triangle covers the whole view, to world space.
    let world_from_view = camera.view_from_world().inverse();
    let directions = [[-4.0, -4.0, -1.0], [12.0, -4.0, -1.0], [-4.0, 12.0, -1.0]].map(|d| {
        let w = world_from_view * umbra_gl::glam::DVec4::new(d[0], d[1], d[2], 0.0);
        [w.x as f32, w.y as f32, w.z as f32, 0.0]
    });
    for at_infinity in [false, true] {
        let mut probe = FarPlaneProbe { at_infinity, directions, gpu: None, prepared: None, seen: Vec::new() };
        for convention in [DepthConvention::Standard, DepthConvention::ReversedZ] {
            let p = FrameParams { depth_convention: convention, ..params(camera, vec![POINT_LIGHT], 96, 64) };
            let img = renderer.render(gl, &scene, &mut probe, &p, None).expect("render");
            let ids = img.triangle_id.as_ref().expect("ids");
            let background = ids.pixels.iter().filter(|&&i| i == NO_TRIANGLE).count();
            assert!(background > 100 && background < ids.pixels.len() - 100, "the view shows geometry and background");
            let st = &img.stencil[0].image;
            let wrong = st.pixels.iter().filter(|&&s| s != 1).count();
            assert_eq!(wrong, 0, "{convention:?}, at infinity {at_infinity}: {wrong} pixels not counted exactly once");
            assert!(
                img.lit_masks[0].image.pixels.iter().all(|&m| m == 0),
                "{convention:?}: counted everywhere = lit nowhere"
            );
        }
        let (far_standard, far_reversed) = (1.0, 0.0);
        assert_eq!(
            probe.seen,
            vec![
                (DepthConvention::Standard, far_standard, glow::LESS),
                (DepthConvention::ReversedZ, far_reversed, glow::GREATER)
            ]
        );
        probe.destroy(gl);
    }
    assert!(ctx.take_gl_errors().is_empty());
    renderer.destroy(gl);
    scene.destroy(gl);
}
