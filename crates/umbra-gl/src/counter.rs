//! The shadow-volume counter: 8 stencil bits, or a wide f32 count resolved into the stencil.
//!
//! Counting (Heidmann 1991 z-pass; Everitt & Kilgard 2002 z-fail): every volume face in front
//! of (z-pass) or behind (z-fail) a visible sample adds +1 or -1; with consistently oriented
//! volumes the sum at sample `p` is `W(p)`, the number of triangles between `p` and the light,
//! and `p` is lit iff `W(p) = 0`. The classic counter is the 8-bit stencil with INCR_WRAP /
//! DECR_WRAP ([`crate::GlState::shadow_volume_for`]): exact modulo 256, so a sample with
//! `W = 256, 512, ...` reads 0 and is drawn LIT — silently wrong. A fan of 100,000 triangles
//! around one edge, or 300 stacked quads, reach such counts;
//! [`umbra_geom::winding_bound`] bounds `W` per mesh and light to tell when it can happen.
//!
//! [`Counter::Float32`] counts instead into an R32F colour texture of the counter's own
//! framebuffer (exact for `|W| < 2^24`): the volume fragment shaders of every counting method
//! write `o_count = gl_FrontFacing ? 1.0 : -1.0` at location 0 (ignored under
//! [`Counter::Stencil8`], whose colour write mask is off), and
//! [`crate::GlState::shadow_volume_float_for`] sums them with blending ONE, ONE (FUNC_ADD for
//! z-pass, FUNC_REVERSE_SUBTRACT for z-fail, the depth test on the stencil op's condition).
//! The depth test needs the frame's depth: [`FloatCounter::begin`] copies it with
//! glBlitFramebuffer into a depth texture of exactly the frame framebuffer's depth format
//! (queried, so a caller's framebuffer and the default framebuffer work alike; multisampled
//! ones are refused). After the methods drew, [`FloatCounter::resolve`] draws one full-screen
//! triangle into the frame's framebuffer that sets the stencil to 1 where the count is not 0
//! (it was cleared to 0): the lighting pass and its `StencilZero` test are unchanged.
//!
//! Methods whose stencil use is not the standard count (all-edges-invert, paper 002's INVERT
//! scheme) or that do not use the stencil (shadow maps) do not use the counter: the renderer
//! enables it only for [`crate::Classification::StencilZero`] methods.

use glow::HasContext;

use crate::camera::DepthConvention;
use crate::error::GlError;
use crate::program::{link_program, uniform, ShaderSource};
use crate::state::GlState;

pub use umbra_geom::frame::Counter;

/// What a [`Counter`] means in OpenGL terms.
pub trait CounterGl {
    /// The counting state of a volume pass with this counter.
    fn shadow_volume_state(self, zpass: bool, convention: DepthConvention) -> GlState;
}

impl CounterGl for Counter {
    fn shadow_volume_state(self, zpass: bool, convention: DepthConvention) -> GlState {
        match self {
            Counter::Stencil8 => GlState::shadow_volume_for(zpass, convention),
            Counter::Float32 => GlState::shadow_volume_float_for(zpass, convention),
        }
    }
}

const RESOLVE_VERT: &str = include_str!("shaders/fullscreen.vert.glsl");

const RESOLVE_FRAG: &str = "#version 450 core
// Counter resolve: the stencil test (ALWAYS, REPLACE with 1) marks the pixels whose count is
// not 0; a pixel with count 0 is discarded and keeps the cleared stencil 0.
uniform sampler2D u_count;
void main() {
    if (texelFetch(u_count, ivec2(gl_FragCoord.xy), 0).r == 0.0) {
        discard;
    }
}
";

/// Sized depth format matching a framebuffer's depth attachment (bits, float or not,
/// stencil present), so glBlitFramebuffer can copy the depth.
fn depth_format(depth_bits: i32, float: bool, stencil_bits: i32) -> Option<u32> {
    match (depth_bits, float, stencil_bits > 0) {
        (32, true, true) => Some(glow::DEPTH32F_STENCIL8),
        (32, true, false) => Some(glow::DEPTH_COMPONENT32F),
        (24, false, true) => Some(glow::DEPTH24_STENCIL8),
        (24, false, false) => Some(glow::DEPTH_COMPONENT24),
        (32, false, false) => Some(glow::DEPTH_COMPONENT32),
        (16, false, false) => Some(glow::DEPTH_COMPONENT16),
        _ => None,
    }
}

/// Where the counter's framebuffer gets the frame's depth from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum DepthSource {
    /// The frame's own depth texture (name, mip level), attached as is: nothing copied.
    Texture(glow::Texture, i32),
    /// The frame's own depth renderbuffer, attached as is.
    Renderbuffer(glow::Renderbuffer),
    /// A copy (glBlitFramebuffer) into a texture of this sized format: the default
    /// framebuffer, or an attachment that cannot be shared (layered, cube face).
    Copy(u32),
}

struct Attachments {
    width: u32,
    height: u32,
    fbo: glow::Framebuffer,
    count: glow::Texture,
    /// Our depth copy (format, texture), made when a [`DepthSource::Copy`] needs it.
    copy: Option<(u32, glow::Texture)>,
    /// What is attached at DEPTH_ATTACHMENT now.
    attached: Option<DepthSource>,
}

impl Attachments {
    fn destroy(&self, gl: &glow::Context) {
        // SAFETY: our own objects, not used afterwards.
        unsafe {
            gl.delete_framebuffer(self.fbo);
            gl.delete_texture(self.count);
            if let Some((_, t)) = self.copy {
                gl.delete_texture(t);
            }
        }
    }

    /// Attaches `source` as the depth (making the copy texture if needed); returns the
    /// framebuffer status.
    fn attach(&mut self, gl: &glow::Context, source: DepthSource) -> Result<u32, GlError> {
        // SAFETY: DSA attachment of objects that exist on the current context (the caller's,
        // queried from its framebuffer, or our own).
        unsafe {
            match source {
                DepthSource::Texture(t, level) => {
                    gl.named_framebuffer_texture(Some(self.fbo), glow::DEPTH_ATTACHMENT, Some(t), level)
                }
                DepthSource::Renderbuffer(r) => gl.named_framebuffer_renderbuffer(
                    Some(self.fbo),
                    glow::DEPTH_ATTACHMENT,
                    glow::RENDERBUFFER,
                    Some(r),
                ),
                DepthSource::Copy(format) => {
                    if self.copy.is_some_and(|(f, _)| f != format) {
                        if let Some((_, t)) = self.copy.take() {
                            gl.delete_texture(t);
                        }
                    }
                    let t = match self.copy {
                        Some((_, t)) => t,
                        None => {
                            let t = texture(gl, format, self.width, self.height)?;
                            self.copy = Some((format, t));
                            t
                        }
                    };
                    gl.named_framebuffer_texture(Some(self.fbo), glow::DEPTH_ATTACHMENT, Some(t), 0);
                }
            }
            self.attached = Some(source);
            Ok(gl.check_named_framebuffer_status(Some(self.fbo), glow::DRAW_FRAMEBUFFER))
        }
    }
}

/// A `width x height` single-level texture of `format`, nearest filtering.
fn texture(gl: &glow::Context, format: u32, width: u32, height: u32) -> Result<glow::Texture, GlError> {
    // SAFETY: DSA texture creation on the current context.
    unsafe {
        let t =
            gl.create_named_texture(glow::TEXTURE_2D).map_err(|detail| GlError::Create { what: "texture", detail })?;
        gl.texture_storage_2d(t, 1, format, width as i32, height as i32);
        // Reason: texelFetch ignores filtering, but completeness does not: a non-mipmap
        // minification filter keeps a single-level texture complete everywhere.
        gl.texture_parameter_i32(t, glow::TEXTURE_MIN_FILTER, glow::NEAREST as i32);
        gl.texture_parameter_i32(t, glow::TEXTURE_MAG_FILTER, glow::NEAREST as i32);
        Ok(t)
    }
}

/// GL resources of [`Counter::Float32`]: the resolve program, an empty vertex array and (made
/// on first use, remade when size or depth format change) the count framebuffer.
pub struct FloatCounter {
    program: glow::Program,
    u_count: Option<glow::UniformLocation>,
    vao: glow::VertexArray,
    attachments: Option<Attachments>,
}

impl FloatCounter {
    /// Compiles the resolve program (GL 4.5 core context current).
    pub fn new(gl: &glow::Context) -> Result<Self, GlError> {
        let program = link_program(
            gl,
            "counter resolve",
            &[
                ShaderSource::vertex("shaders/fullscreen.vert.glsl", RESOLVE_VERT),
                ShaderSource::fragment("counter.rs RESOLVE_FRAG", RESOLVE_FRAG),
            ],
            &[],
        )?;
        let u_count = uniform(gl, program, "u_count");
        // SAFETY: object creation on the current context; the program is deleted on failure.
        let vao = match unsafe { gl.create_vertex_array() } {
            Ok(v) => v,
            Err(detail) => {
                // SAFETY: our own program, not used afterwards.
                unsafe { gl.delete_program(program) };
                return Err(GlError::Create { what: "vertex array", detail });
            }
        };
        Ok(Self { program, u_count, vao, attachments: None })
    }

    /// Prepares one light's count: (re)creates the count framebuffer for `width x height`,
    /// gives it `frame`'s depth (None = default framebuffer) — the very depth texture or
    /// renderbuffer of a framebuffer object, attached as is, else a glBlitFramebuffer copy in
    /// the same format — clears the count to 0 and binds it as the draw framebuffer with the
    /// full viewport. Returns the framebuffer the volume pass must draw into.
    pub fn begin(
        &mut self,
        gl: &glow::Context,
        frame: Option<glow::Framebuffer>,
        width: u32,
        height: u32,
    ) -> Result<glow::Framebuffer, GlError> {
        let source = Self::frame_depth_source(gl, frame)?;
        if self.attachments.as_ref().is_none_or(|a| a.width != width || a.height != height) {
            if let Some(a) = self.attachments.take() {
                a.destroy(gl);
            }
            self.attachments = Some(Self::create(gl, width, height)?);
        }
        let a =
            self.attachments.as_mut().ok_or_else(|| GlError::InvalidParams("counter framebuffer missing".into()))?;
        let mut used = source;
        if a.attached != Some(source) {
            let mut status = a.attach(gl, source)?;
            if status != glow::FRAMEBUFFER_COMPLETE && source != DepthSource::Copy(Self::frame_depth_format(gl, frame)?)
            {
                // A shared attachment our framebuffer cannot take (e.g. another size): copy.
                used = DepthSource::Copy(Self::frame_depth_format(gl, frame)?);
                status = a.attach(gl, used)?;
            }
            if status != glow::FRAMEBUFFER_COMPLETE {
                a.attached = None;
                return Err(GlError::Framebuffer { status, what: "float32 counter (R32F + the frame's depth)" });
            }
        }
        let (w, h) = (width as i32, height as i32);
        // Reason: the clear of the count obeys the colour write mask; GL's default state has it
        // on (the depth mask does not matter: only the colour is cleared).
        GlState::default().apply(gl);
        // SAFETY: DSA blit and clear between framebuffers of the same size on the current
        // context; binding our framebuffer and setting the viewport.
        unsafe {
            if let DepthSource::Copy(_) = used {
                // Reason: the volume faces must be depth-tested against the frame's own depth;
                // the blit copies it (same format, same size, NEAREST).
                gl.blit_named_framebuffer(
                    frame,
                    Some(a.fbo),
                    0,
                    0,
                    w,
                    h,
                    0,
                    0,
                    w,
                    h,
                    glow::DEPTH_BUFFER_BIT,
                    glow::NEAREST,
                );
            }
            // Reason: every light starts from count 0.
            gl.clear_named_framebuffer_f32_slice(Some(a.fbo), glow::COLOR, 0, &[0.0, 0.0, 0.0, 0.0]);
            // Reason: the methods draw into the bound draw framebuffer, over all of it.
            gl.bind_framebuffer(glow::DRAW_FRAMEBUFFER, Some(a.fbo));
            gl.viewport(0, 0, w, h);
        }
        Ok(a.fbo)
    }

    /// Writes the stencil of `frame` (cleared to 0 before the volume pass): 1 where the count
    /// is not 0. Leaves `frame` bound as the draw framebuffer with the full viewport.
    pub fn resolve(
        &self,
        gl: &glow::Context,
        frame: Option<glow::Framebuffer>,
        width: u32,
        height: u32,
    ) -> Result<(), GlError> {
        let a =
            self.attachments.as_ref().ok_or_else(|| GlError::InvalidParams("counter resolve without begin".into()))?;
        GlState::stencil_mark_resolve().apply(gl);
        // SAFETY: our program, empty VAO and count texture; the texture binding of unit 0 and
        // the active unit are read first and restored after the draw.
        unsafe {
            // Reason: the resolve writes the frame's own stencil, every pixel of it.
            gl.bind_framebuffer(glow::DRAW_FRAMEBUFFER, frame);
            gl.viewport(0, 0, width as i32, height as i32);
            let active = gl.get_parameter_i32(glow::ACTIVE_TEXTURE) as u32;
            // Reason: the shader reads the count through sampler unit 0 (u_count = 0).
            gl.active_texture(glow::TEXTURE0);
            let previous = gl.get_parameter_i32(glow::TEXTURE_BINDING_2D) as u32;
            gl.bind_texture(glow::TEXTURE_2D, Some(a.count));
            // Reason: our resolve program; the renderer re-binds its own afterwards.
            gl.use_program(Some(self.program));
            gl.uniform_1_i32(self.u_count.as_ref(), 0);
            // Reason: core profile draws need a vertex array; ours is empty (gl_VertexID).
            gl.bind_vertex_array(Some(self.vao));
            gl.draw_arrays(glow::TRIANGLES, 0, 3);
            // Reason: give unit 0 and the active unit back as they were.
            gl.bind_texture(glow::TEXTURE_2D, std::num::NonZeroU32::new(previous).map(glow::NativeTexture));
            gl.active_texture(active);
        }
        Ok(())
    }

    /// Reads the count of every pixel (bottom row first, as GL stores it) of the last
    /// [`FloatCounter::begin`]; for tests and diagnostics.
    pub fn read_counts(&self, gl: &glow::Context) -> Option<Vec<f32>> {
        let a = self.attachments.as_ref()?;
        let mut out = vec![0.0f32; (a.width * a.height) as usize];
        // SAFETY: readback of our own R32F attachment into a buffer of exactly its size (rows
        // of 4 * width bytes meet any pack alignment); the read framebuffer binding is
        // restored.
        unsafe {
            let previous = gl.get_parameter_i32(glow::READ_FRAMEBUFFER_BINDING) as u32;
            // Reason: glReadPixels reads the bound read framebuffer (its draw buffer 0 is the
            // count); restored below.
            gl.bind_framebuffer(glow::READ_FRAMEBUFFER, Some(a.fbo));
            gl.read_pixels(
                0,
                0,
                a.width as i32,
                a.height as i32,
                glow::RED,
                glow::FLOAT,
                glow::PixelPackData::Slice(Some(bytes_of_f32(&mut out))),
            );
            gl.bind_framebuffer(
                glow::READ_FRAMEBUFFER,
                std::num::NonZeroU32::new(previous).map(glow::NativeFramebuffer),
            );
        }
        Some(out)
    }

    fn frame_depth_format(gl: &glow::Context, frame: Option<glow::Framebuffer>) -> Result<u32, GlError> {
        // The default framebuffer names its depth buffer DEPTH, a framebuffer object
        // DEPTH_ATTACHMENT.
        let attachment = if frame.is_some() { glow::DEPTH_ATTACHMENT } else { glow::DEPTH };
        // SAFETY: DSA queries of the frame framebuffer's attachment on the current context.
        let (depth, kind, stencil_attachment, samples) = unsafe {
            let q = |pname| gl.get_named_framebuffer_attachment_parameter_i32(frame, attachment, pname);
            let stencil_name = if frame.is_some() { glow::STENCIL_ATTACHMENT } else { glow::STENCIL };
            let stencil = gl.get_named_framebuffer_attachment_parameter_i32(
                frame,
                stencil_name,
                glow::FRAMEBUFFER_ATTACHMENT_STENCIL_SIZE,
            );
            (
                q(glow::FRAMEBUFFER_ATTACHMENT_DEPTH_SIZE),
                q(glow::FRAMEBUFFER_ATTACHMENT_COMPONENT_TYPE) as u32,
                stencil,
                gl.get_named_framebuffer_parameter_i32(frame, glow::SAMPLES),
            )
        };
        if samples > 0 {
            return Err(GlError::InvalidParams(format!(
                "the float32 counter needs a single-sampled framebuffer (it has {samples} samples)"
            )));
        }
        // A packed depth-stencil texture/renderbuffer is attached to both points; a separate
        // stencil is not part of the depth format.
        let packed = stencil_attachment > 0 && (depth == 32 && kind == glow::FLOAT || depth == 24);
        depth_format(depth, kind == glow::FLOAT, if packed { stencil_attachment } else { 0 }).ok_or_else(|| {
            GlError::InvalidParams(format!(
                "the float32 counter cannot copy a depth buffer of {depth} bits (component type 0x{kind:04X})"
            ))
        })
    }

    /// The frame's depth as a [`DepthSource`]: a framebuffer object's non-layered depth
    /// texture or renderbuffer is shared; anything else is copied.
    fn frame_depth_source(gl: &glow::Context, frame: Option<glow::Framebuffer>) -> Result<DepthSource, GlError> {
        if frame.is_some() {
            // SAFETY: DSA queries of the frame framebuffer's depth attachment.
            let (kind, name, level, layered, layer, face) = unsafe {
                let q = |pname| gl.get_named_framebuffer_attachment_parameter_i32(frame, glow::DEPTH_ATTACHMENT, pname);
                let kind = q(glow::FRAMEBUFFER_ATTACHMENT_OBJECT_TYPE) as u32;
                let name = q(glow::FRAMEBUFFER_ATTACHMENT_OBJECT_NAME) as u32;
                if kind == glow::TEXTURE {
                    (
                        kind,
                        name,
                        q(glow::FRAMEBUFFER_ATTACHMENT_TEXTURE_LEVEL),
                        q(glow::FRAMEBUFFER_ATTACHMENT_LAYERED),
                        q(glow::FRAMEBUFFER_ATTACHMENT_TEXTURE_LAYER),
                        q(glow::FRAMEBUFFER_ATTACHMENT_TEXTURE_CUBE_MAP_FACE),
                    )
                } else {
                    (kind, name, 0, 0, 0, 0)
                }
            };
            if let Some(n) = std::num::NonZeroU32::new(name) {
                if kind == glow::RENDERBUFFER {
                    return Ok(DepthSource::Renderbuffer(glow::NativeRenderbuffer(n)));
                }
                if kind == glow::TEXTURE && layered == 0 && layer == 0 && face == 0 {
                    return Ok(DepthSource::Texture(glow::NativeTexture(n), level));
                }
            }
        }
        Ok(DepthSource::Copy(Self::frame_depth_format(gl, frame)?))
    }

    fn create(gl: &glow::Context, width: u32, height: u32) -> Result<Attachments, GlError> {
        // SAFETY: DSA creation of a framebuffer and a texture on the current context; both are
        // deleted on the error path.
        unsafe {
            let fbo =
                gl.create_named_framebuffer().map_err(|detail| GlError::Create { what: "framebuffer", detail })?;
            let count = match texture(gl, glow::R32F, width, height) {
                Ok(t) => t,
                Err(e) => {
                    gl.delete_framebuffer(fbo);
                    return Err(e);
                }
            };
            gl.named_framebuffer_texture(Some(fbo), glow::COLOR_ATTACHMENT0, Some(count), 0);
            // Reason: fragment output location 0 (o_count) goes to the count texture.
            gl.named_framebuffer_draw_buffers(Some(fbo), &[glow::COLOR_ATTACHMENT0]);
            Ok(Attachments { width, height, fbo, count, copy: None, attached: None })
        }
    }

    /// Frees the GL objects (context current).
    pub fn destroy(mut self, gl: &glow::Context) {
        if let Some(a) = self.attachments.take() {
            a.destroy(gl);
        }
        // SAFETY: our own objects, not used afterwards.
        unsafe {
            gl.delete_program(self.program);
            gl.delete_vertex_array(self.vao);
        }
    }
}

fn bytes_of_f32(v: &mut [f32]) -> &mut [u8] {
    // SAFETY: f32 has no invalid bit patterns and u8 has alignment 1; the byte slice covers
    // exactly the same memory and borrows it mutably for its lifetime.
    unsafe { std::slice::from_raw_parts_mut(v.as_mut_ptr().cast::<u8>(), std::mem::size_of_val(v)) }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn depth_formats_match_what_the_frame_has() {
        assert_eq!(depth_format(32, true, 8), Some(glow::DEPTH32F_STENCIL8));
        assert_eq!(depth_format(24, false, 8), Some(glow::DEPTH24_STENCIL8));
        assert_eq!(depth_format(24, false, 0), Some(glow::DEPTH_COMPONENT24));
        assert_eq!(depth_format(32, true, 0), Some(glow::DEPTH_COMPONENT32F));
        assert_eq!(depth_format(16, false, 0), Some(glow::DEPTH_COMPONENT16));
        assert_eq!(depth_format(0, false, 0), None, "no depth buffer");
    }

    /// The float32 counter on a caller's framebuffer (the renderer's RenderTarget used as one,
    /// through draw_frame) marks exactly the pixels the 8-bit stencil marks when every count
    /// is small (the default scene), for D24S8 and D32FS8 depth and both conventions, and
    /// reports no GL error.
    #[test]
    fn float32_marks_what_stencil8_marks_on_a_callers_framebuffer() {
        use crate::renderer::{CaptureFlags, FrameParams, FrameTarget, LightCapture, Renderer};
        use crate::target::{Attachments, RenderTarget};
        let ctx = crate::HeadlessContext::new().unwrap_or_else(|e| panic!("no headless GL context: {e}"));
        let gl = ctx.gl();
        let mesh = umbra_geom::scene::load_scene("default").expect("default scene");
        let scene = crate::SceneGpu::upload(gl, std::sync::Arc::new(umbra_geom::weld::weld(&mesh))).expect("upload");
        let mut renderer = Renderer::new(gl).expect("renderer").with_error_log(ctx.error_log().cloned());
        let (w, h) = (160, 120);
        for (convention, float_depth) in
            [(DepthConvention::Standard, false), (DepthConvention::ReversedZ, true), (DepthConvention::Standard, true)]
        {
            let target =
                RenderTarget::new(gl, w, h, Attachments { float_depth, ..Attachments::default() }).expect("target");
            let mut masks = Vec::new();
            for counter in [Counter::Stencil8, Counter::Float32] {
                for method in ["cpu-silhouette", "gs-triangle"] {
                    let mut m = crate::create_method(method).expect("method");
                    let params = FrameParams {
                        camera: crate::Camera {
                            eye: [6.0, 5.0, 8.0],
                            target: [0.0, 0.5, 0.0],
                            ..crate::Camera::default()
                        },
                        width: w,
                        height: h,
                        lights: vec![[2.0, 6.0, 1.0, 1.0]],
                        depth_convention: convention,
                        counter,
                        capture: CaptureFlags { stencil: LightCapture::AllLights, ..CaptureFlags::default() },
                        ..FrameParams::default()
                    };
                    let stencil = renderer
                        .draw_frame(
                            gl,
                            &scene,
                            m.as_mut(),
                            &params,
                            FrameTarget { framebuffer: Some(target.framebuffer()) },
                            None,
                        )
                        .unwrap_or_else(|e| panic!("{method} {counter:?} {convention:?}: {e}"));
                    m.destroy(gl);
                    let shadowed: Vec<bool> = stencil[0].image.pixels.iter().map(|&s| s != 0).collect();
                    masks.push((method, counter, shadowed));
                }
            }
            target.destroy(gl);
            let (s8, f32s) = masks.split_at(2);
            for ((m, _, a), (_, _, b)) in s8.iter().zip(f32s) {
                let shadowed = a.iter().filter(|&&x| x).count();
                assert!(shadowed > 500, "{m} {convention:?}: a shadow in view ({shadowed})");
                let only8 = a.iter().zip(b).filter(|(x, y)| **x && !**y).count();
                let only32 = a.iter().zip(b).filter(|(x, y)| !**x && **y).count();
                assert!(a == b, "{m} {convention:?} float_depth {float_depth}: float32 marks other pixels than stencil8 ({only8} only stencil8, {only32} only float32, {shadowed} stencil8)");
            }
        }
        assert!(ctx.take_gl_errors().is_empty());
        renderer.destroy(gl);
        scene.destroy(gl);
    }

    #[test]
    fn counter_names_and_states() {
        assert_eq!(Counter::default(), Counter::Stencil8);
        assert_eq!(Counter::Stencil8.name(), "stencil8");
        assert_eq!(Counter::Float32.name(), "float32");
        let c = DepthConvention::ReversedZ;
        assert_eq!(Counter::Stencil8.shadow_volume_state(false, c), GlState::shadow_volume_for(false, c));
        assert_eq!(Counter::Float32.shadow_volume_state(true, c), GlState::shadow_volume_float_for(true, c));
    }
}
