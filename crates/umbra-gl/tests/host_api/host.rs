//! The host renderer: its own framebuffer (colour, a lit-mask attachment, a depth-stencil
//! renderbuffer in the convention's format), geometry and invariant shader, its depth and
//! ambient pass, and unusual GL state set before umbra is called.

use umbra_gl::glow::{self, HasContext};
use umbra_gl::program::{link_program, uniform, ShaderSource};
use umbra_gl::{
    camera::to_f32_cols, read_rgba8, DepthConvention, DepthConventionGl, FrameParams, HeadlessContext, Image, SceneGpu,
};

/// The host framebuffer's size.
pub(crate) const W: u32 = 200;
pub(crate) const H: u32 = 150;

/// The host's vertex shader: the position expression of umbra's scene shader, `invariant`
/// (count_shadows' invariance requirement).
pub(crate) const HOST_VERT: &str = "#version 450 core
layout(location = 0) in vec3 a_pos;
uniform mat4 u_clip_from_world;
invariant gl_Position;
void main() { gl_Position = u_clip_from_world * vec4(a_pos, 1.0); }
";

/// The host's depth + ambient pass: umbra's ambient colour, so that after `add_light` the
/// host's frame must equal umbra's own byte for byte; 0 into the lit-mask attachment (an
/// enabled draw buffer without a shader output would receive undefined values).
pub(crate) const HOST_FRAG: &str = "#version 450 core
uniform vec3 u_ambient;
layout(location = 0) out vec4 o_color;
layout(location = 3) out vec4 o_lit;
void main() { o_color = vec4(u_ambient, 1.0); o_lit = vec4(0.0); }
";

/// The host's GL objects: framebuffer (RGBA8 colour 0, R8 colour 3 for umbra's lit-mask
/// output, a depth-stencil renderbuffer in the convention's format), geometry, program.
pub(crate) struct Host {
    pub(crate) fbo: glow::Framebuffer,
    pub(crate) renderbuffers: Vec<glow::Renderbuffer>,
    pub(crate) vao: glow::VertexArray,
    pub(crate) buffers: Vec<glow::Buffer>,
    pub(crate) texture: glow::Texture,
    pub(crate) program: glow::Program,
    pub(crate) index_count: i32,
}

pub(crate) fn as_bytes<T: Copy>(v: &[T]) -> &[u8] {
    // SAFETY: plain f32/u32 arrays: no padding, every byte initialised.
    unsafe { std::slice::from_raw_parts(v.as_ptr().cast(), std::mem::size_of_val(v)) }
}

impl Host {
    pub(crate) fn new(gl: &glow::Context, scene: &SceneGpu, convention: DepthConvention) -> Host {
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
    pub(crate) fn draw_scene(&self, ctx: &HeadlessContext, p: &FrameParams) {
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
    pub(crate) fn set_unusual_state(&self, ctx: &HeadlessContext) {
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
    pub(crate) fn plain_state(&self, ctx: &HeadlessContext) {
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

    pub(crate) fn read_depth(&self, gl: &glow::Context) -> Vec<u8> {
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

    pub(crate) fn read_lit(&self, gl: &glow::Context) -> Image<u8> {
        let bits = read_rgba8(gl, Some(self.fbo), glow::COLOR_ATTACHMENT3, W, H);
        Image { width: W, height: H, pixels: bits.pixels.iter().map(|c| u8::from(c[0] != 0)).collect() }
    }

    pub(crate) fn destroy(self, gl: &glow::Context) {
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
