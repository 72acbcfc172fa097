//! The renderer's own framebuffer and readback helpers.
//!
//! Attachments (immutable textures, created with direct state access):
//! * COLOR_ATTACHMENT0: RGBA8 colour;
//! * COLOR_ATTACHMENT1 (optional): RGBA32F world position, `w = 1` on geometry, 0 on background;
//! * COLOR_ATTACHMENT2 (optional): R32UI triangle id, [`NO_TRIANGLE`] on background;
//! * DEPTH_STENCIL_ATTACHMENT: DEPTH24_STENCIL8.
//!
//! Readbacks return TOP-row-first images (glReadPixels delivers the bottom row first).

use glow::HasContext;

use crate::error::GlError;
use crate::image::{Image, RgbaImage, StencilImage, TriangleIdImage, WorldPosImage};

/// Triangle id of a pixel where no triangle was drawn.
pub const NO_TRIANGLE: u32 = u32::MAX;

/// Which optional attachments a [`RenderTarget`] has.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Attachments {
    pub world_pos: bool,
    pub triangle_id: bool,
}

/// An offscreen framebuffer of fixed size.
pub struct RenderTarget {
    width: u32,
    height: u32,
    attachments: Attachments,
    fbo: glow::Framebuffer,
    color: glow::Texture,
    depth_stencil: glow::Texture,
    world_pos: Option<glow::Texture>,
    triangle_id: Option<glow::Texture>,
}

impl RenderTarget {
    /// Creates the framebuffer; checks completeness. No bindings change (DSA).
    pub fn new(gl: &glow::Context, width: u32, height: u32, attachments: Attachments) -> Result<Self, GlError> {
        // SAFETY: query of an implementation limit on the current context.
        let max = unsafe { gl.get_parameter_i32(glow::MAX_RENDERBUFFER_SIZE) }.max(0) as u32;
        if width == 0 || height == 0 || width > max || height > max {
            return Err(GlError::InvalidParams(format!("render target {width}x{height} (limit {max}x{max}, > 0)")));
        }
        // SAFETY: DSA creation of textures and a framebuffer on the current context; every
        // object is either stored in the result or deleted on the error path.
        unsafe {
            let tex = |format: u32| -> Result<glow::Texture, GlError> {
                let t = gl
                    .create_named_texture(glow::TEXTURE_2D)
                    .map_err(|detail| GlError::Create { what: "texture", detail })?;
                gl.texture_storage_2d(t, 1, format, width as i32, height as i32);
                Ok(t)
            };
            let fbo = gl
                .create_named_framebuffer()
                .map_err(|detail| GlError::Create { what: "framebuffer", detail })?;
            let color = tex(glow::RGBA8)?;
            let depth_stencil = tex(glow::DEPTH24_STENCIL8)?;
            let world_pos = if attachments.world_pos { Some(tex(glow::RGBA32F)?) } else { None };
            let triangle_id = if attachments.triangle_id { Some(tex(glow::R32UI)?) } else { None };
            gl.named_framebuffer_texture(Some(fbo), glow::COLOR_ATTACHMENT0, Some(color), 0);
            gl.named_framebuffer_texture(Some(fbo), glow::DEPTH_STENCIL_ATTACHMENT, Some(depth_stencil), 0);
            if let Some(t) = world_pos {
                gl.named_framebuffer_texture(Some(fbo), glow::COLOR_ATTACHMENT1, Some(t), 0);
            }
            if let Some(t) = triangle_id {
                gl.named_framebuffer_texture(Some(fbo), glow::COLOR_ATTACHMENT2, Some(t), 0);
            }
            let target = Self { width, height, attachments, fbo, color, depth_stencil, world_pos, triangle_id };
            target.set_draw_buffers(gl, true);
            let status = gl.check_named_framebuffer_status(Some(fbo), glow::DRAW_FRAMEBUFFER);
            if status != glow::FRAMEBUFFER_COMPLETE {
                target.destroy(gl);
                return Err(GlError::Framebuffer { status, what: "RenderTarget (RGBA8 + D24S8 + optional RGBA32F/R32UI)" });
            }
            Ok(target)
        }
    }

    pub fn width(&self) -> u32 {
        self.width
    }
    pub fn height(&self) -> u32 {
        self.height
    }
    pub fn attachments(&self) -> Attachments {
        self.attachments
    }
    pub fn framebuffer(&self) -> glow::Framebuffer {
        self.fbo
    }

    /// Draw buffers of this framebuffer (framebuffer-object state, not context state):
    /// `all` = colour plus the present optional attachments at locations 1 and 2;
    /// otherwise colour only, so a pass writing only location 0 leaves the others intact.
    pub fn set_draw_buffers(&self, gl: &glow::Context, all: bool) {
        let one = |present: bool, att: u32| if all && present { att } else { glow::NONE };
        let bufs = [
            glow::COLOR_ATTACHMENT0,
            one(self.attachments.world_pos, glow::COLOR_ATTACHMENT1),
            one(self.attachments.triangle_id, glow::COLOR_ATTACHMENT2),
        ];
        // SAFETY: valid attachment enums for our own framebuffer.
        unsafe { gl.named_framebuffer_draw_buffers(Some(self.fbo), &bufs) };
    }

    /// Clears colour to `background`, world position to 0, triangle id to [`NO_TRIANGLE`],
    /// depth to 1 and stencil to 0. The caller must have write masks on (see
    /// [`crate::GlState::default`]); clears obey them.
    pub fn clear(&self, gl: &glow::Context, background: [f32; 4]) {
        self.set_draw_buffers(gl, true);
        // SAFETY: clears of our own framebuffer's draw buffers (indices match set_draw_buffers).
        unsafe {
            gl.clear_named_framebuffer_f32_slice(Some(self.fbo), glow::COLOR, 0, &background);
            if self.attachments.world_pos {
                gl.clear_named_framebuffer_f32_slice(Some(self.fbo), glow::COLOR, 1, &[0.0; 4]);
            }
            if self.attachments.triangle_id {
                gl.clear_named_framebuffer_u32_slice(Some(self.fbo), glow::COLOR, 2, &[NO_TRIANGLE, 0, 0, 0]);
            }
            gl.clear_named_framebuffer_depth_stencil(Some(self.fbo), glow::DEPTH_STENCIL, 0, 1.0, 0);
        }
    }

    pub fn read_rgba(&self, gl: &glow::Context) -> RgbaImage {
        read_rgba8(gl, Some(self.fbo), glow::COLOR_ATTACHMENT0, self.width, self.height)
    }

    pub fn read_world_pos(&self, gl: &glow::Context) -> Option<WorldPosImage> {
        self.attachments.world_pos.then(|| {
            let bytes = read_bytes(gl, Some(self.fbo), glow::COLOR_ATTACHMENT1, self.width, self.height, glow::RGBA, glow::FLOAT, 16);
            let px = bytes
                .chunks_exact(16)
                .map(|c| [0, 1, 2, 3].map(|i| f32::from_ne_bytes([c[4 * i], c[4 * i + 1], c[4 * i + 2], c[4 * i + 3]])))
                .collect();
            Image::from_bottom_up(self.width, self.height, px)
        })
    }

    pub fn read_triangle_ids(&self, gl: &glow::Context) -> Option<TriangleIdImage> {
        self.attachments.triangle_id.then(|| {
            let bytes =
                read_bytes(gl, Some(self.fbo), glow::COLOR_ATTACHMENT2, self.width, self.height, glow::RED_INTEGER, glow::UNSIGNED_INT, 4);
            let px = bytes.chunks_exact(4).map(|c| u32::from_ne_bytes([c[0], c[1], c[2], c[3]])).collect();
            Image::from_bottom_up(self.width, self.height, px)
        })
    }

    pub fn read_stencil(&self, gl: &glow::Context) -> StencilImage {
        read_stencil(gl, Some(self.fbo), self.width, self.height)
    }

    /// Deletes the GL objects.
    pub fn destroy(self, gl: &glow::Context) {
        // SAFETY: objects owned by this target, not used afterwards.
        unsafe {
            gl.delete_framebuffer(self.fbo);
            for t in [Some(self.color), Some(self.depth_stencil), self.world_pos, self.triangle_id].into_iter().flatten() {
                gl.delete_texture(t);
            }
        }
    }
}

/// Reads `width x height` RGBA8 pixels from `read_buffer` (e.g. COLOR_ATTACHMENT0, or BACK
/// for the default framebuffer) of `framebuffer` (None = default), top row first.
pub fn read_rgba8(gl: &glow::Context, framebuffer: Option<glow::Framebuffer>, read_buffer: u32, width: u32, height: u32) -> RgbaImage {
    let bytes = read_bytes(gl, framebuffer, read_buffer, width, height, glow::RGBA, glow::UNSIGNED_BYTE, 4);
    let px = bytes.chunks_exact(4).map(|c| [c[0], c[1], c[2], c[3]]).collect();
    Image::from_bottom_up(width, height, px)
}

/// Reads the stencil of `framebuffer` (None = default) with GL_STENCIL_INDEX, one u8 per
/// pixel, top row first. Works on any framebuffer with a stencil attachment.
pub fn read_stencil(gl: &glow::Context, framebuffer: Option<glow::Framebuffer>, width: u32, height: u32) -> StencilImage {
    let bytes = read_bytes(gl, framebuffer, glow::NONE, width, height, glow::STENCIL_INDEX, glow::UNSIGNED_BYTE, 1);
    Image::from_bottom_up(width, height, bytes)
}

/// glReadPixels of the rectangle (0, 0, width, height), bottom row first.
///
/// GL state touched and restored: READ_FRAMEBUFFER binding, PACK_ALIGNMENT (set to 1),
/// PIXEL_PACK_BUFFER binding (unbound so the data comes to client memory). The framebuffer's
/// read buffer is set to `read_buffer` (framebuffer-object state; skipped for NONE).
#[allow(clippy::too_many_arguments)]
fn read_bytes(
    gl: &glow::Context,
    framebuffer: Option<glow::Framebuffer>,
    read_buffer: u32,
    width: u32,
    height: u32,
    format: u32,
    ty: u32,
    bytes_per_pixel: usize,
) -> Vec<u8> {
    let mut out = vec![0u8; width as usize * height as usize * bytes_per_pixel];
    // SAFETY: the out slice holds width*height*bytes_per_pixel bytes, exactly what glReadPixels
    // writes with PACK_ALIGNMENT 1 and no pack buffer; previous bindings are restored.
    unsafe {
        let prev_read_fb = gl.get_parameter_i32(glow::READ_FRAMEBUFFER_BINDING) as u32;
        let prev_align = gl.get_parameter_i32(glow::PACK_ALIGNMENT);
        let prev_pack_buffer = gl.get_parameter_i32(glow::PIXEL_PACK_BUFFER_BINDING) as u32;
        gl.bind_framebuffer(glow::READ_FRAMEBUFFER, framebuffer);
        if read_buffer != glow::NONE {
            gl.read_buffer(read_buffer);
        }
        gl.bind_buffer(glow::PIXEL_PACK_BUFFER, None);
        gl.pixel_store_i32(glow::PACK_ALIGNMENT, 1);
        gl.read_pixels(0, 0, width as i32, height as i32, format, ty, glow::PixelPackData::Slice(Some(&mut out)));
        gl.pixel_store_i32(glow::PACK_ALIGNMENT, prev_align);
        gl.bind_buffer(glow::PIXEL_PACK_BUFFER, crate::saved::buffer(prev_pack_buffer));
        gl.bind_framebuffer(glow::READ_FRAMEBUFFER, crate::saved::framebuffer(prev_read_fb));
    }
    out
}
