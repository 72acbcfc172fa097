//! A minimal renderer of the caller's own that asks umbra for exact shadows of two lights —
//! the integration pattern for an existing engine (the stencil shadow-volume
//! frame of Heidmann 1991 / Everitt & Kilgard 2002 §2, with umbra's silhouettes, paper 001).
//!
//! The host owns everything: its GL context, its framebuffer (RGBA8 colour, an R8 "lit bits"
//! attachment for checking, DEPTH24_STENCIL8), its vertex buffers and its shaders. Per frame:
//! 1. host pass: its own shader draws the scene's depth and ambient colour;
//! 2. per light, umbra counts that light's shadow volumes into the host's stencil with
//!    [`Renderer::count_shadows`]: it clears and writes the stencil only — the host's depth
//!    and colour stay as the host drew them, and every GL state umbra changes is restored.
//!    The host's vertex shader is the same invariant expression as umbra's on the same
//!    positions and matrix, so the depths the volumes are tested against are the ones umbra
//!    would have drawn (count_shadows' invariance requirement);
//! 3. the host's own lighting pass adds the light where the stencil says "lit" (the
//!    [`Classification`] count_shadows returns) and the seen side faces the light, and sets
//!    the light's bit.
//!
//! The standard depth convention keeps the host free of glClipControl; reversed-Z works the
//! same way with a DEPTH32F_STENCIL8 buffer and the host drawing with glClipControl(LOWER_LEFT,
//! ZERO_TO_ONE) and `Camera::clip_from_world_in(.., ReversedZ)`.
//!
//! `cargo run --release -p umbra-gl --example host_renderer -- [OUT.png] [METHOD]`

use std::path::Path;
use std::sync::Arc;

use umbra_geom::scene::{ground_plane, uv_sphere};
use umbra_geom::WeldedMesh;
use umbra_gl::glow::{self, HasContext};
use umbra_gl::program::{link_program, uniform, ShaderSource};
use umbra_gl::scene::flat_normal;
use umbra_gl::{
    create_method, read_rgba8, BlendState, Camera, Classification, DepthConvention, FrameParams, FrameTarget, GlState,
    HeadlessContext, Image, Renderer, RgbaImage, SceneGpu, StencilFace,
};

type Error = Box<dyn std::error::Error>;

/// The host's vertex shader, shared by both host passes and identical to umbra's scene
/// shader's position expression (`invariant` + the same expression => the same depths).
const HOST_VERT: &str = "#version 450 core
layout(location = 0) in vec3 a_pos;
uniform mat4 u_clip_from_world;
out vec3 v_pos;
invariant gl_Position;
void main() { v_pos = a_pos; gl_Position = u_clip_from_world * vec4(a_pos, 1.0); }
";
const HOST_AMBIENT_FRAG: &str = "#version 450 core
uniform vec3 u_ambient;
layout(location = 0) out vec4 o_color;
layout(location = 1) out vec4 o_lit;
void main() { o_color = vec4(u_ambient, 1.0); o_lit = vec4(0.0); }
";
/// Two-sided Lambert; `o_lit` adds this light's bit (R8: k / 255 is stored exactly as k).
const HOST_LIGHT_FRAG: &str = "#version 450 core
in vec3 v_pos;
layout(std430, binding = 0) readonly buffer Normals { vec4 normals[]; };
uniform vec4 u_light;
uniform vec3 u_light_color;
uniform float u_light_bit;
layout(location = 0) out vec4 o_color;
layout(location = 1) out vec4 o_lit;
void main() {
    vec3 n = normals[gl_PrimitiveID].xyz;
    if (!gl_FrontFacing) n = -n;
    float d = dot(n, normalize(u_light.xyz - v_pos * u_light.w));
    if (d <= 0.0) discard; // the side the camera sees faces away from the light
    o_color = vec4(u_light_color * d, 0.0);
    o_lit = vec4(u_light_bit / 255.0);
}
";

/// What the host produced: its colour image, per-pixel light bits (bit i = lit by light i),
/// and the frame it drew (camera, size, lights, convention).
pub struct HostFrame {
    pub rgba: RgbaImage,
    pub lit_bits: Image<u8>,
    pub params: FrameParams,
}

/// The host's scene: a sphere over a ground plane.
pub fn host_scene() -> Arc<WeldedMesh> {
    let mut mesh = uv_sphere([0.0, 2.0, 0.0], 1.0, 48, 24);
    mesh.append(&ground_plane([0.0, 0.0, 0.0], 6.0));
    Arc::new(umbra_geom::weld::weld(&mesh))
}

/// The host's view: two lights, a point light (w = 1) and a directional one (w = 0).
pub fn host_params() -> FrameParams {
    FrameParams {
        camera: Camera::look_at([5.0, 5.0, 7.0], [0.0, 0.5, 0.0]),
        width: 480,
        height: 320,
        lights: vec![[1.5, 6.0, 0.5, 1.0], [-0.4, 1.0, 0.3, 0.0]],
        light_color: [0.45; 3],
        depth_convention: DepthConvention::Standard,
        ..FrameParams::default()
    }
}

fn as_bytes<T: Copy>(v: &[T]) -> &[u8] {
    // SAFETY: plain f32/u32 arrays: no padding, every byte initialised.
    unsafe { std::slice::from_raw_parts(v.as_ptr().cast(), std::mem::size_of_val(v)) }
}

/// Draws one host frame on the current context `gl` with umbra method `method_name`.
pub fn draw_host_frame(gl: &glow::Context, method_name: &str) -> Result<HostFrame, Error> {
    let p = host_params();
    let mesh = host_scene();
    let (w, h) = (p.width as i32, p.height as i32);
    let clip = Camera::clip_from_world_in(&p.camera, w as f64 / h as f64, p.depth_convention);
    let clip = umbra_gl::camera::to_f32_cols(&clip);
    let normals: Vec<[f32; 4]> =
        mesh.triangles.iter().map(|&t| flat_normal(&mesh.positions, t)).map(|[x, y, z]| [x, y, z, 0.0]).collect();

    // umbra's copy of the geometry (for its volumes) and its renderer.
    let scene = SceneGpu::upload(gl, mesh.clone())?;
    let mut renderer = Renderer::new(gl)?;
    let mut method = create_method(method_name)?;
    let ambient_prog = link_program(
        gl,
        "host ambient",
        &[ShaderSource::vertex("host.vert", HOST_VERT), ShaderSource::fragment("host_ambient.frag", HOST_AMBIENT_FRAG)],
        &[],
    )?;
    let light_prog = link_program(
        gl,
        "host light",
        &[ShaderSource::vertex("host.vert", HOST_VERT), ShaderSource::fragment("host_light.frag", HOST_LIGHT_FRAG)],
        &[],
    )?;
    // SAFETY: object creation, uploads, binds and draws on the current context; every slice
    // outlives its call; the index buffer holds valid indices (welded mesh).
    let result = unsafe {
        // The host's own geometry buffers.
        let vao = gl.create_vertex_array()?;
        let vbo = gl.create_buffer()?;
        let ibo = gl.create_buffer()?;
        let nbo = gl.create_buffer()?;
        // Reason: the host's VAO stays bound for all its draws (count_shadows restores it).
        gl.bind_vertex_array(Some(vao));
        gl.bind_buffer(glow::ARRAY_BUFFER, Some(vbo));
        gl.buffer_data_u8_slice(glow::ARRAY_BUFFER, as_bytes(&mesh.positions), glow::STATIC_DRAW);
        gl.vertex_attrib_pointer_f32(0, 3, glow::FLOAT, false, 12, 0);
        gl.enable_vertex_attrib_array(0);
        gl.bind_buffer(glow::ELEMENT_ARRAY_BUFFER, Some(ibo));
        gl.buffer_data_u8_slice(glow::ELEMENT_ARRAY_BUFFER, as_bytes(&mesh.triangles), glow::STATIC_DRAW);
        gl.bind_buffer(glow::SHADER_STORAGE_BUFFER, Some(nbo));
        gl.buffer_data_u8_slice(glow::SHADER_STORAGE_BUFFER, as_bytes(&normals), glow::STATIC_DRAW);
        // Reason: binding 0 is the lighting shader's `Normals` block.
        gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, 0, Some(nbo));
        let count = mesh.triangles.len() as i32 * 3;

        // The host's framebuffer: colour, lit bits, depth + 8 stencil bits.
        let fbo = gl.create_framebuffer()?;
        gl.bind_framebuffer(glow::FRAMEBUFFER, Some(fbo));
        let mut rbos = Vec::new();
        for (format, attachment) in [
            (glow::RGBA8, glow::COLOR_ATTACHMENT0),
            (glow::R8, glow::COLOR_ATTACHMENT1),
            (glow::DEPTH24_STENCIL8, glow::DEPTH_STENCIL_ATTACHMENT),
        ] {
            let rb = gl.create_renderbuffer()?;
            gl.bind_renderbuffer(glow::RENDERBUFFER, Some(rb));
            gl.renderbuffer_storage(glow::RENDERBUFFER, format, w, h);
            gl.framebuffer_renderbuffer(glow::FRAMEBUFFER, attachment, glow::RENDERBUFFER, Some(rb));
            rbos.push(rb);
        }
        let both = [glow::COLOR_ATTACHMENT0, glow::COLOR_ATTACHMENT1];
        // Reason: pass 1 writes the colour (0) and zero lit bits (1), over the whole target.
        gl.draw_buffers(&both);
        gl.viewport(0, 0, w, h);

        // 1. Host pass: clear, then depth + ambient (nearest surface wins, two-sided).
        GlState::default().apply(gl); // clears obey the write masks: all on
        gl.clear_buffer_f32_slice(glow::COLOR, 0, &p.background);
        gl.clear_buffer_f32_slice(glow::COLOR, 1, &[0.0; 4]);
        gl.clear_buffer_depth_stencil(glow::DEPTH_STENCIL, 0, 1.0, 0);
        // Reason: nearest surface wins (standard depth); no culling: the soup is two-sided.
        GlState { depth_test: true, depth_func: glow::LESS, ..GlState::default() }.apply(gl);
        gl.use_program(Some(ambient_prog));
        gl.uniform_matrix_4_f32_slice(uniform(gl, ambient_prog, "u_clip_from_world").as_ref(), false, &clip);
        gl.uniform_3_f32_slice(uniform(gl, ambient_prog, "u_ambient").as_ref(), &p.albedo.map(|a| a * p.ambient));
        gl.draw_elements(glow::TRIANGLES, count, glow::UNSIGNED_INT, 0);

        let mut result: Result<(), Error> = Ok(());
        for (i, &light) in p.lights.iter().enumerate() {
            // 2. umbra: this light's stencil count on the host's framebuffer (stencil only).
            let target = FrameTarget { framebuffer: Some(fbo) };
            let classification = match renderer.count_shadows(gl, &scene, method.as_mut(), &p, light, target) {
                Ok(c) => c,
                Err(e) => {
                    result = Err(e.into());
                    break;
                }
            };
            let light_test = match classification {
                // Lit where the count is 0; the first lit fragment bumps it to 1, so a coplanar
                // duplicate triangle (common in soups) cannot add the light twice.
                Classification::StencilZero => StencilFace {
                    func: glow::EQUAL,
                    reference: 0,
                    value_mask: 0xFF,
                    write_mask: 0xFF,
                    depth_pass: glow::INCR_WRAP,
                    ..StencilFace::KEEP
                },
                // The method's own stencil encoding: test it, write nothing.
                Classification::StencilTest { func, reference, value_mask } => {
                    StencilFace { func, reference, value_mask, write_mask: 0, ..StencilFace::KEEP }
                }
                // count_shadows resolves shader-classified methods (shadow maps) into the
                // stencil and reports StencilZero for them; Shader is never returned.
                Classification::Shader => {
                    result = Err("count_shadows returned Classification::Shader".into());
                    break;
                }
            };
            // 3. Host lighting where lit: the surface pass 1 left (EQUAL, no depth writes),
            // the method's stencil test, added onto what is there (alpha kept).
            GlState {
                depth_test: true,
                depth_func: glow::EQUAL,
                depth_write: false,
                stencil_test: true,
                stencil_front: light_test,
                stencil_back: light_test,
                color_write: [true, true, true, false],
                blend: Some(BlendState::ADDITIVE),
                ..GlState::default()
            }
            .apply(gl);
            // count_shadows restored the host's bindings (program, VAO, framebuffer, viewport,
            // draw buffers untouched).
            gl.use_program(Some(light_prog));
            gl.uniform_matrix_4_f32_slice(uniform(gl, light_prog, "u_clip_from_world").as_ref(), false, &clip);
            gl.uniform_4_f32_slice(uniform(gl, light_prog, "u_light").as_ref(), &light);
            gl.uniform_3_f32_slice(uniform(gl, light_prog, "u_light_color").as_ref(), &p.light_color);
            gl.uniform_1_f32(uniform(gl, light_prog, "u_light_bit").as_ref(), (1u32 << i) as f32);
            gl.draw_elements(glow::TRIANGLES, count, glow::UNSIGNED_INT, 0);
        }
        let images = result.map(|()| {
            let rgba = read_rgba8(gl, Some(fbo), glow::COLOR_ATTACHMENT0, p.width, p.height);
            let bits = read_rgba8(gl, Some(fbo), glow::COLOR_ATTACHMENT1, p.width, p.height);
            let lit_bits =
                Image { width: bits.width, height: bits.height, pixels: bits.pixels.iter().map(|c| c[0]).collect() };
            (rgba, lit_bits)
        });

        // Reason: hand the context back in GL's default state.
        GlState::default().apply(gl);
        gl.bind_framebuffer(glow::FRAMEBUFFER, None);
        gl.bind_vertex_array(None);
        gl.use_program(None);
        gl.delete_framebuffer(fbo);
        rbos.into_iter().for_each(|rb| gl.delete_renderbuffer(rb));
        [vbo, ibo, nbo].into_iter().for_each(|b| gl.delete_buffer(b));
        gl.delete_vertex_array(vao);
        gl.delete_program(ambient_prog);
        gl.delete_program(light_prog);
        images
    };
    method.destroy(gl);
    renderer.destroy(gl);
    scene.destroy(gl);
    let (rgba, lit_bits) = result?;
    Ok(HostFrame { rgba, lit_bits, params: p })
}

#[allow(dead_code)] // also compiled into tests/examples.rs, which calls draw_host_frame
fn main() -> Result<(), Error> {
    let out = std::env::args().nth(1).unwrap_or_else(|| "host_renderer.png".to_string());
    let method = std::env::args().nth(2).unwrap_or_else(|| "cpu-silhouette".to_string());
    // The host's context; in an application this is the window's.
    let ctx = HeadlessContext::new()?;
    let frame = draw_host_frame(ctx.gl(), &method)?;
    frame.rgba.save_png(Path::new(&out))?;
    println!("wrote {out}");
    Ok(())
}
