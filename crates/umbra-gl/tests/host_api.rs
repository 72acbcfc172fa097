//! umbra inside a stranger's renderer (issue 9 §1): the host draws its scene's depth with its
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

mod common;

use common::*;
use umbra_gl::glow::{self, HasContext};
use umbra_gl::program::{link_program, uniform, ShaderSource};
use umbra_gl::{
    camera::to_f32_cols, create_method, read_rgba8, read_stencil, CaptureFlags, Classification, DepthConvention,
    DepthConventionGl, FrameParams, FrameTarget, GlError, HeadlessContext, Image, LightCapture, Renderer, SceneGpu,
    ShadowMethod, NO_TRIANGLE,
};

/// The host's vertex shader: the position expression of umbra's scene shader, `invariant`
/// (count_shadows' invariance requirement).
const HOST_VERT: &str = "#version 450 core
layout(location = 0) in vec3 a_pos;
uniform mat4 u_clip_from_world;
invariant gl_Position;
void main() { gl_Position = u_clip_from_world * vec4(a_pos, 1.0); }
";
/// The host's depth + ambient pass: umbra's ambient colour, so that after `add_light` the
/// host's frame must equal umbra's own byte for byte; 0 into the lit-mask attachment (an
/// enabled draw buffer without a shader output would receive undefined values).
const HOST_FRAG: &str = "#version 450 core
uniform vec3 u_ambient;
layout(location = 0) out vec4 o_color;
layout(location = 3) out vec4 o_lit;
void main() { o_color = vec4(u_ambient, 1.0); o_lit = vec4(0.0); }
";

const W: u32 = 200;
const H: u32 = 150;
const DIRECTIONAL: [f32; 4] = [-0.4, 1.0, 0.3, 0.0];
const POINT: [f32; 4] = [1.5, 6.0, 0.5, 1.0];

/// The host's GL objects: framebuffer (RGBA8 colour 0, R8 colour 3 for umbra's lit-mask
/// output, a depth-stencil renderbuffer in the convention's format), geometry, program.
struct Host {
    fbo: glow::Framebuffer,
    renderbuffers: Vec<glow::Renderbuffer>,
    vao: glow::VertexArray,
    buffers: Vec<glow::Buffer>,
    texture: glow::Texture,
    program: glow::Program,
    index_count: i32,
}

fn as_bytes<T: Copy>(v: &[T]) -> &[u8] {
    // SAFETY: plain f32/u32 arrays: no padding, every byte initialised.
    unsafe { std::slice::from_raw_parts(v.as_ptr().cast(), std::mem::size_of_val(v)) }
}

impl Host {
    fn new(gl: &glow::Context, scene: &SceneGpu, convention: DepthConvention) -> Host {
        let mesh = scene.mesh();
        let program = link_program(
            gl,
            "host",
            &[ShaderSource::vertex("host.vert", HOST_VERT), ShaderSource::fragment("host.frag", HOST_FRAG)],
            &[],
        )
        .expect("host program");
        // SAFETY: object creation and uploads on the current context; slices outlive calls.
        unsafe {
            let vao = gl.create_vertex_array().expect("vao");
            let vbo = gl.create_buffer().expect("vbo");
            let ibo = gl.create_buffer().expect("ibo");
            gl.bind_vertex_array(Some(vao));
            gl.bind_buffer(glow::ARRAY_BUFFER, Some(vbo));
            gl.buffer_data_u8_slice(glow::ARRAY_BUFFER, as_bytes(&mesh.positions), glow::STATIC_DRAW);
            gl.vertex_attrib_pointer_f32(0, 3, glow::FLOAT, false, 12, 0);
            gl.enable_vertex_attrib_array(0);
            gl.bind_buffer(glow::ELEMENT_ARRAY_BUFFER, Some(ibo));
            gl.buffer_data_u8_slice(glow::ELEMENT_ARRAY_BUFFER, as_bytes(&mesh.triangles), glow::STATIC_DRAW);
            gl.bind_vertex_array(None);
            // A buffer and a texture of the host's, bound where umbra's methods bind theirs.
            let extra = gl.create_buffer().expect("ssbo");
            gl.bind_buffer(glow::SHADER_STORAGE_BUFFER, Some(extra));
            gl.buffer_data_size(glow::SHADER_STORAGE_BUFFER, 256, glow::STATIC_DRAW);
            gl.bind_buffer(glow::SHADER_STORAGE_BUFFER, None);
            let texture = gl.create_texture().expect("texture");
            gl.bind_texture(glow::TEXTURE_2D, Some(texture));
            gl.tex_storage_2d(glow::TEXTURE_2D, 1, glow::RGBA8, 4, 4);
            gl.bind_texture(glow::TEXTURE_2D, None);

            let fbo = gl.create_framebuffer().expect("fbo");
            gl.bind_framebuffer(glow::FRAMEBUFFER, Some(fbo));
            let mut renderbuffers = Vec::new();
            for (format, attachment) in [
                (glow::RGBA8, glow::COLOR_ATTACHMENT0),
                (glow::R8, glow::COLOR_ATTACHMENT3),
                (convention.depth_format(), glow::DEPTH_STENCIL_ATTACHMENT),
            ] {
                let rb = gl.create_renderbuffer().expect("renderbuffer");
                gl.bind_renderbuffer(glow::RENDERBUFFER, Some(rb));
                gl.renderbuffer_storage(glow::RENDERBUFFER, format, W as i32, H as i32);
                gl.framebuffer_renderbuffer(glow::FRAMEBUFFER, attachment, glow::RENDERBUFFER, Some(rb));
                renderbuffers.push(rb);
            }
            // Location 0 -> colour, location 3 (umbra's lit-mask output) -> the R8 buffer.
            gl.draw_buffers(&[glow::COLOR_ATTACHMENT0, glow::NONE, glow::NONE, glow::COLOR_ATTACHMENT3]);
            assert_eq!(gl.check_framebuffer_status(glow::FRAMEBUFFER), glow::FRAMEBUFFER_COMPLETE);
            gl.bind_framebuffer(glow::FRAMEBUFFER, None);
            Host {
                fbo,
                renderbuffers,
                vao,
                buffers: vec![vbo, ibo, extra],
                texture,
                program,
                index_count: mesh.triangles.len() as i32 * 3,
            }
        }
    }

    /// The host's own pass: clear, depth + ambient with its own shader, in `p`'s convention.
    fn draw_scene(&self, ctx: &HeadlessContext, p: &FrameParams) {
        let gl = ctx.gl();
        let convention = p.depth_convention;
        let clip = to_f32_cols(&p.camera.clip_from_world_in(p.width as f64 / p.height as f64, convention));
        // SAFETY: the host's own objects; state setters, clears and one draw.
        unsafe {
            gl.bind_framebuffer(glow::FRAMEBUFFER, Some(self.fbo));
            gl.viewport(0, 0, W as i32, H as i32);
            // The host's clip control: the convention's depth mode (count_shadows' contract).
            assert!(ctx.extra().clip_control(glow::LOWER_LEFT, convention.clip_depth_mode()), "glClipControl");
            gl.depth_range_f64(0.0, 1.0);
            umbra_gl::GlState::default().apply(gl);
            gl.clear_buffer_f32_slice(glow::COLOR, 0, &p.background);
            gl.clear_buffer_f32_slice(glow::COLOR, 3, &[0.0; 4]);
            gl.clear_buffer_depth_stencil(glow::DEPTH_STENCIL, 0, convention.far_depth(), 0);
            umbra_gl::GlState { depth_test: true, depth_func: convention.nearer(), ..umbra_gl::GlState::default() }
                .apply(gl);
            gl.use_program(Some(self.program));
            gl.uniform_matrix_4_f32_slice(uniform(gl, self.program, "u_clip_from_world").as_ref(), false, &clip);
            gl.uniform_3_f32_slice(uniform(gl, self.program, "u_ambient").as_ref(), &p.albedo.map(|a| a * p.ambient));
            gl.bind_vertex_array(Some(self.vao));
            gl.draw_elements(glow::TRIANGLES, self.index_count, glow::UNSIGNED_INT, 0);
        }
    }

    /// Unusual host state everywhere umbra could leave a trace.
    fn set_unusual_state(&self, ctx: &HeadlessContext) {
        let gl = ctx.gl();
        umbra_gl::GlState {
            depth_test: true,
            depth_func: glow::LEQUAL,
            depth_write: false,
            depth_clamp: true,
            stencil_test: true,
            stencil_front: umbra_gl::StencilFace {
                func: glow::GREATER,
                reference: 3,
                value_mask: 0x0F,
                write_mask: 0xF0,
                stencil_fail: glow::INVERT,
                depth_fail: glow::INCR,
                depth_pass: glow::DECR,
            },
            stencil_back: umbra_gl::StencilFace {
                func: glow::NOTEQUAL,
                reference: 5,
                value_mask: 0x3C,
                write_mask: 0x0F,
                stencil_fail: glow::ZERO,
                depth_fail: glow::REPLACE,
                depth_pass: glow::INCR_WRAP,
            },
            color_write: [true, false, true, false],
            cull_face: Some(glow::FRONT),
            front_face: glow::CW,
            blend: Some(umbra_gl::BlendState {
                src_rgb: glow::SRC_ALPHA,
                dst_rgb: glow::ONE_MINUS_SRC_ALPHA,
                src_alpha: glow::ZERO,
                dst_alpha: glow::DST_COLOR,
                equation_rgb: glow::MAX,
                equation_alpha: glow::FUNC_REVERSE_SUBTRACT,
            }),
            polygon_offset: Some((1.5, 2.0)),
        }
        .apply(gl);
        // SAFETY: state setters on the current context with the host's live objects.
        unsafe {
            // Bound first: GL clamps the queried stencil reference to the stencil bits of the
            // bound draw framebuffer.
            gl.bind_framebuffer(glow::FRAMEBUFFER, Some(self.fbo));
            gl.use_program(Some(self.program));
            gl.bind_vertex_array(Some(self.vao));
            gl.viewport(3, 4, 50, 60);
            gl.enable(glow::SCISSOR_TEST);
            gl.scissor(5, 6, 20, 10);
            gl.enable(glow::RASTERIZER_DISCARD);
            gl.depth_range_f64(0.25, 0.75);
            assert!(ctx.extra().clip_control(glow::UPPER_LEFT, glow::NEGATIVE_ONE_TO_ONE), "glClipControl");
            gl.patch_parameter_i32(glow::PATCH_VERTICES, 7);
            let extra = self.buffers[2];
            for binding in 0..8 {
                gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, binding, Some(extra));
            }
            gl.bind_buffer_range(glow::SHADER_STORAGE_BUFFER, 2, Some(extra), 64, 128);
            gl.bind_buffer(glow::SHADER_STORAGE_BUFFER, Some(self.buffers[0]));
            gl.bind_buffer(glow::ARRAY_BUFFER, Some(self.buffers[1]));
            gl.bind_buffer(glow::DRAW_INDIRECT_BUFFER, Some(extra));
            gl.bind_buffer(glow::DISPATCH_INDIRECT_BUFFER, Some(self.buffers[1]));
            gl.bind_buffer(glow::COPY_READ_BUFFER, Some(self.buffers[0]));
            // The z-pass scene box: uniform block binding 14 and clip distances 1..7.
            gl.bind_buffer_range(glow::UNIFORM_BUFFER, 14, Some(extra), 0, 128);
            gl.bind_buffer(glow::UNIFORM_BUFFER, Some(self.buffers[1]));
            gl.enable(glow::CLIP_DISTANCE3);
            gl.enable(glow::CLIP_DISTANCE7);
            gl.active_texture(glow::TEXTURE0);
            gl.bind_texture(glow::TEXTURE_2D, Some(self.texture));
            gl.active_texture(glow::TEXTURE3);
        }
    }

    /// Back to plain state before the host reads its buffers.
    fn plain_state(&self, ctx: &HeadlessContext) {
        let gl = ctx.gl();
        umbra_gl::GlState::default().apply(gl);
        // SAFETY: state setters on the current context.
        unsafe {
            gl.disable(glow::SCISSOR_TEST);
            gl.disable(glow::RASTERIZER_DISCARD);
            gl.disable(glow::CLIP_DISTANCE3);
            gl.disable(glow::CLIP_DISTANCE7);
            gl.depth_range_f64(0.0, 1.0);
            ctx.extra().clip_control(glow::LOWER_LEFT, glow::NEGATIVE_ONE_TO_ONE);
        }
    }

    fn read_depth(&self, gl: &glow::Context) -> Vec<u8> {
        let mut out = vec![0u8; W as usize * H as usize * 4];
        // SAFETY: `out` holds W * H floats, what glReadPixels writes with the default pack
        // alignment (4) and no pack buffer.
        unsafe {
            gl.bind_framebuffer(glow::READ_FRAMEBUFFER, Some(self.fbo));
            gl.read_pixels(
                0,
                0,
                W as i32,
                H as i32,
                glow::DEPTH_COMPONENT,
                glow::FLOAT,
                glow::PixelPackData::Slice(Some(&mut out)),
            );
        }
        out
    }

    fn read_lit(&self, gl: &glow::Context) -> Image<u8> {
        let bits = read_rgba8(gl, Some(self.fbo), glow::COLOR_ATTACHMENT3, W, H);
        Image { width: W, height: H, pixels: bits.pixels.iter().map(|c| u8::from(c[0] != 0)).collect() }
    }

    fn destroy(self, gl: &glow::Context) {
        // SAFETY: the host's own objects, unbound first.
        unsafe {
            gl.bind_framebuffer(glow::FRAMEBUFFER, None);
            gl.bind_vertex_array(None);
            gl.use_program(None);
            gl.delete_framebuffer(self.fbo);
            self.renderbuffers.into_iter().for_each(|rb| gl.delete_renderbuffer(rb));
            self.buffers.into_iter().for_each(|b| gl.delete_buffer(b));
            gl.delete_texture(self.texture);
            gl.delete_vertex_array(self.vao);
            gl.delete_program(self.program);
        }
    }
}

/// The GL state a host cares about, queried independently of umbra's own save/restore.
fn query_state(gl: &glow::Context) -> Vec<(String, Vec<i64>)> {
    let mut out = Vec::new();
    // SAFETY: glGet* queries of core state on the current context.
    unsafe {
        let ints = [
            ("BLEND", glow::BLEND, 1),
            ("BLEND_SRC_RGB", glow::BLEND_SRC_RGB, 1),
            ("BLEND_DST_RGB", glow::BLEND_DST_RGB, 1),
            ("BLEND_SRC_ALPHA", glow::BLEND_SRC_ALPHA, 1),
            ("BLEND_DST_ALPHA", glow::BLEND_DST_ALPHA, 1),
            ("BLEND_EQUATION_RGB", glow::BLEND_EQUATION_RGB, 1),
            ("BLEND_EQUATION_ALPHA", glow::BLEND_EQUATION_ALPHA, 1),
            ("DEPTH_TEST", glow::DEPTH_TEST, 1),
            ("DEPTH_FUNC", glow::DEPTH_FUNC, 1),
            ("DEPTH_WRITEMASK", glow::DEPTH_WRITEMASK, 1),
            ("DEPTH_CLAMP", glow::DEPTH_CLAMP, 1),
            ("STENCIL_TEST", glow::STENCIL_TEST, 1),
            ("STENCIL_FUNC", glow::STENCIL_FUNC, 1),
            ("STENCIL_REF", glow::STENCIL_REF, 1),
            ("STENCIL_VALUE_MASK", glow::STENCIL_VALUE_MASK, 1),
            ("STENCIL_WRITEMASK", glow::STENCIL_WRITEMASK, 1),
            ("STENCIL_FAIL", glow::STENCIL_FAIL, 1),
            ("STENCIL_PASS_DEPTH_FAIL", glow::STENCIL_PASS_DEPTH_FAIL, 1),
            ("STENCIL_PASS_DEPTH_PASS", glow::STENCIL_PASS_DEPTH_PASS, 1),
            ("STENCIL_BACK_FUNC", glow::STENCIL_BACK_FUNC, 1),
            ("STENCIL_BACK_REF", glow::STENCIL_BACK_REF, 1),
            ("STENCIL_BACK_VALUE_MASK", glow::STENCIL_BACK_VALUE_MASK, 1),
            ("STENCIL_BACK_WRITEMASK", glow::STENCIL_BACK_WRITEMASK, 1),
            ("STENCIL_BACK_FAIL", glow::STENCIL_BACK_FAIL, 1),
            ("STENCIL_BACK_PASS_DEPTH_FAIL", glow::STENCIL_BACK_PASS_DEPTH_FAIL, 1),
            ("STENCIL_BACK_PASS_DEPTH_PASS", glow::STENCIL_BACK_PASS_DEPTH_PASS, 1),
            ("CULL_FACE", glow::CULL_FACE, 1),
            ("CULL_FACE_MODE", glow::CULL_FACE_MODE, 1),
            ("FRONT_FACE", glow::FRONT_FACE, 1),
            ("CLIP_ORIGIN", glow::CLIP_ORIGIN, 1),
            ("CLIP_DEPTH_MODE", glow::CLIP_DEPTH_MODE, 1),
            ("CURRENT_PROGRAM", glow::CURRENT_PROGRAM, 1),
            ("VERTEX_ARRAY_BINDING", glow::VERTEX_ARRAY_BINDING, 1),
            ("DRAW_FRAMEBUFFER_BINDING", glow::DRAW_FRAMEBUFFER_BINDING, 1),
            ("READ_FRAMEBUFFER_BINDING", glow::READ_FRAMEBUFFER_BINDING, 1),
            ("VIEWPORT", glow::VIEWPORT, 4),
            ("COLOR_WRITEMASK", glow::COLOR_WRITEMASK, 4),
            ("SCISSOR_TEST", glow::SCISSOR_TEST, 1),
            ("SCISSOR_BOX", glow::SCISSOR_BOX, 4),
            ("RASTERIZER_DISCARD", glow::RASTERIZER_DISCARD, 1),
            ("POLYGON_OFFSET_FILL", glow::POLYGON_OFFSET_FILL, 1),
            ("PATCH_VERTICES", glow::PATCH_VERTICES, 1),
            ("ACTIVE_TEXTURE", glow::ACTIVE_TEXTURE, 1),
            ("ARRAY_BUFFER_BINDING", glow::ARRAY_BUFFER_BINDING, 1),
            ("DRAW_INDIRECT_BUFFER_BINDING", glow::DRAW_INDIRECT_BUFFER_BINDING, 1),
            ("DISPATCH_INDIRECT_BUFFER_BINDING", glow::DISPATCH_INDIRECT_BUFFER_BINDING, 1),
            ("COPY_READ_BUFFER_BINDING", glow::COPY_READ_BUFFER_BINDING, 1),
            ("SHADER_STORAGE_BUFFER_BINDING", glow::SHADER_STORAGE_BUFFER_BINDING, 1),
            ("UNIFORM_BUFFER_BINDING", glow::UNIFORM_BUFFER_BINDING, 1),
            ("DRAW_BUFFER0", glow::DRAW_BUFFER0, 1),
            ("DRAW_BUFFER3", glow::DRAW_BUFFER3, 1),
        ];
        for (name, pname, n) in ints {
            let mut v = vec![0i32; n];
            gl.get_parameter_i32_slice(pname, &mut v);
            out.push((name.to_string(), v.into_iter().map(i64::from).collect()));
        }
        let mut range = [0.0f32; 2];
        gl.get_parameter_f32_slice(glow::DEPTH_RANGE, &mut range);
        out.push(("DEPTH_RANGE".into(), range.iter().map(|f| i64::from(f.to_bits())).collect()));
        let offset = [glow::POLYGON_OFFSET_FACTOR, glow::POLYGON_OFFSET_UNITS].map(|p| gl.get_parameter_f32(p));
        out.push(("POLYGON_OFFSET".into(), offset.iter().map(|f| i64::from(f.to_bits())).collect()));
        for i in 0..8 {
            out.push((
                format!("SHADER_STORAGE_BUFFER_BINDING[{i}]"),
                vec![
                    i64::from(gl.get_parameter_indexed_i32(glow::SHADER_STORAGE_BUFFER_BINDING, i)),
                    gl.get_parameter_indexed_i64(glow::SHADER_STORAGE_BUFFER_START, i),
                    gl.get_parameter_indexed_i64(glow::SHADER_STORAGE_BUFFER_SIZE, i),
                ],
            ));
        }
        out.push((
            "UNIFORM_BUFFER_BINDING[14]".into(),
            vec![
                i64::from(gl.get_parameter_indexed_i32(glow::UNIFORM_BUFFER_BINDING, 14)),
                gl.get_parameter_indexed_i64(glow::UNIFORM_BUFFER_START, 14),
                gl.get_parameter_indexed_i64(glow::UNIFORM_BUFFER_SIZE, 14),
            ],
        ));
        for i in 0..8 {
            out.push((format!("CLIP_DISTANCE{i}"), vec![i64::from(gl.is_enabled(glow::CLIP_DISTANCE0 + i))]));
        }
        // Unit 0's textures (the shadow map's unit), queried through the active unit.
        let active = gl.get_parameter_i32(glow::ACTIVE_TEXTURE) as u32;
        gl.active_texture(glow::TEXTURE0);
        for (name, pname) in [
            ("TEXTURE_BINDING_2D[0]", glow::TEXTURE_BINDING_2D),
            ("TEXTURE_BINDING_CUBE_MAP[0]", glow::TEXTURE_BINDING_CUBE_MAP),
        ] {
            out.push((name.into(), vec![i64::from(gl.get_parameter_i32(pname))]));
        }
        gl.active_texture(active);
    }
    out
}

fn assert_same_state(before: &[(String, Vec<i64>)], after: &[(String, Vec<i64>)], what: &str) {
    let changed: Vec<String> = before
        .iter()
        .zip(after)
        .filter(|(b, a)| b != a)
        .map(|(b, a)| format!("{}: {:?} -> {:?}", b.0, b.1, a.1))
        .collect();
    assert!(changed.is_empty(), "{what} changed the host's GL state: {changed:#?}");
}

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

#[test]
fn stencil_test_method_returns_its_own_classification() {
    run_methods(&["all-edges-invert"], &[DepthConvention::Standard]);
}

#[test]
fn shadow_map_is_resolved_into_the_hosts_stencil() {
    run_methods(&["shadow-map-cube:1024"], &[DepthConvention::Standard, DepthConvention::ReversedZ]);
}

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

/// Math types at the boundary: a host's mint vectors and matrices work where umbra takes
/// plain arrays (camera, light), and give the same stencil as the arrays.
#[test]
fn mint_types_convert_at_the_boundary() {
    let eye = mint::Point3 { x: 0.0, y: 5.0, z: 8.0 };
    let target = mint::Point3 { x: 0.0, y: 0.5, z: 0.0 };
    let camera = umbra_gl::Camera::look_at(eye, target).with_up(mint::Vector3 { x: 0.0, y: 1.0, z: 0.0 });
    let arrays = umbra_gl::Camera::look_at([0.0, 5.0, 8.0], [0.0, 0.5, 0.0]);
    assert_eq!(camera, arrays);
    let clip: mint::ColumnMatrix4<f64> =
        camera.clip_from_world_cols(W as f64 / H as f64, DepthConvention::Standard).into();
    let cols = to_f32_cols(&camera.clip_from_world_in(W as f64 / H as f64, DepthConvention::Standard));
    assert_eq!(
        [clip.x.x as f32, clip.y.x as f32, clip.w.z as f32, clip.w.w as f32],
        [cols[0], cols[4], cols[14], cols[15]]
    );

    let ctx = context();
    let gl = ctx.gl();
    let scene = SceneGpu::upload(gl, sphere_over_ground()).expect("upload");
    let mut renderer = Renderer::new(gl).expect("renderer").with_error_log(ctx.error_log().cloned());
    let mut method = create_method("vs-silhouette").expect("method");
    let p = FrameParams { camera, ..view(POINT, DepthConvention::Standard) };
    let host = Host::new(gl, &scene, DepthConvention::Standard);
    let target = FrameTarget { framebuffer: Some(host.fbo) };
    let mut stencils = Vec::new();
    let mint_light = mint::Vector4 { x: POINT[0], y: POINT[1], z: POINT[2], w: POINT[3] };
    for light in [mint_light, POINT.into()] {
        host.draw_scene(&ctx, &p);
        renderer.count_shadows(gl, &scene, method.as_mut(), &p, light, target).expect("count_shadows");
        host.plain_state(&ctx);
        stencils.push(read_stencil(gl, Some(host.fbo), W, H));
    }
    assert_eq!(stencils[0], stencils[1], "mint light and array light count the same");
    assert!(stencils[0].pixels.iter().any(|&s| s != 0), "the sphere casts a shadow");
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
