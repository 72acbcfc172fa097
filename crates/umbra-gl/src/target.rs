//! The renderer's own framebuffer and readback helpers.
//!
//! Attachments (immutable textures, created with direct state access):
//! * COLOR_ATTACHMENT0: RGBA8 colour;
//! * COLOR_ATTACHMENT1 (optional): RGBA32F world position, `w = 1` on geometry, 0 on background;
//! * COLOR_ATTACHMENT2 (optional): R32UI triangle id, [`NO_TRIANGLE`] on background;
//! * COLOR_ATTACHMENT3 (optional): R8 lit mask, 1.0 where the lighting pass shaded the pixel for
//!   the captured light (the renderer's final lit decision), 0 elsewhere;
//! * DEPTH_STENCIL_ATTACHMENT: DEPTH24_STENCIL8, or DEPTH32F_STENCIL8 with
//!   [`Attachments::float_depth`] (reversed-Z, see [`crate::DepthConvention`]).
//!
//! Every texture's storage is checked when allocated: one the driver refuses is
//! [`GlError::OutOfMemory`] naming the attachment, nothing is left behind (no object, no
//! pending GL error) and the context stays usable (`tests/gl_failures.rs`).
//!
//! Fragment output location i goes to draw buffer i; [`TargetPass`] selects which attachments
//! a pass writes. Readbacks return TOP-row-first images (glReadPixels delivers the bottom row
//! first).

use glow::HasContext;

use crate::error::GlError;
use crate::image::{Image, LitMaskImage, RgbaImage, StencilImage, TriangleIdImage, WorldPosImage};

/// Triangle id of a pixel where no triangle was drawn.
pub use umbra_geom::image::NO_TRIANGLE;

/// Which optional attachments a [`RenderTarget`] has, and its depth format.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Attachments {
    /// RGBA32F world position at COLOR_ATTACHMENT1 (fragment output location 1).
    pub world_pos: bool,
    /// R32UI triangle id at COLOR_ATTACHMENT2 (fragment output location 2).
    pub triangle_id: bool,
    /// R8 lit mask at COLOR_ATTACHMENT3 (fragment output location 3).
    pub lit_mask: bool,
    /// DEPTH32F_STENCIL8 instead of DEPTH24_STENCIL8.
    pub float_depth: bool,
}

impl Attachments {
    /// Whether a target with `self` serves a frame that needs `wanted` (every wanted optional
    /// attachment present, same depth format).
    pub fn covers(&self, wanted: &Attachments) -> bool {
        (self.world_pos || !wanted.world_pos)
            && (self.triangle_id || !wanted.triangle_id)
            && (self.lit_mask || !wanted.lit_mask)
            && self.float_depth == wanted.float_depth
    }
}

/// Which attachments a pass writes (the framebuffer's draw-buffer list).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TargetPass {
    /// Pass 1: colour, and world position / triangle id when present (locations 0, 1, 2).
    Depth,
    /// Pass 3: colour only (location 0), plus the lit mask (location 3) when `lit_mask` and
    /// present. Locations 1 and 2 keep pass 1's values.
    Lighting {
        /// Also write the lit mask (location 3).
        lit_mask: bool,
    },
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
    lit_mask: Option<glow::Texture>,
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
            let fbo =
                gl.create_named_framebuffer().map_err(|detail| GlError::Create { what: "framebuffer", detail })?;
            // Every texture made so far, deleted (with the framebuffer) if a later one fails.
            let mut made = Vec::with_capacity(5);
            let mut all = || -> Result<_, GlError> {
                let mut tex = |format: u32, bytes_per_pixel: usize, name: &str| {
                    texture_storage(gl, &mut made, width, height, format, bytes_per_pixel, name)
                };
                let color = tex(glow::RGBA8, 4, "RGBA8 colour")?;
                // Reason for float depth: see crate::camera (reversed-Z keeps ~24 significant
                // bits of near / distance only in floating point). D32F_S8 takes 8 bytes per
                // pixel (32-bit depth, 8-bit stencil, 24 unused), D24S8 4.
                let depth_stencil = if attachments.float_depth {
                    tex(glow::DEPTH32F_STENCIL8, 8, "DEPTH32F_STENCIL8 depth-stencil")?
                } else {
                    tex(glow::DEPTH24_STENCIL8, 4, "DEPTH24_STENCIL8 depth-stencil")?
                };
                let world_pos =
                    if attachments.world_pos { Some(tex(glow::RGBA32F, 16, "RGBA32F world-position")?) } else { None };
                let triangle_id =
                    if attachments.triangle_id { Some(tex(glow::R32UI, 4, "R32UI triangle-id")?) } else { None };
                // R8 (normalized), not R8UI: the lighting pass blends additively into every
                // draw buffer, and on a normalized buffer min(1, dst + src) with src in {0, 1}
                // is a logical OR — so two fragments of one pixel (coplanar duplicates under
                // Classification::StencilTest) can only set the bit, never clear it.
                let lit_mask = if attachments.lit_mask { Some(tex(glow::R8, 1, "R8 lit-mask")?) } else { None };
                Ok((color, depth_stencil, world_pos, triangle_id, lit_mask))
            };
            let (color, depth_stencil, world_pos, triangle_id, lit_mask) = match all() {
                Ok(t) => t,
                Err(e) => {
                    for t in made {
                        gl.delete_texture(t);
                    }
                    gl.delete_framebuffer(fbo);
                    return Err(e);
                }
            };
            gl.named_framebuffer_texture(Some(fbo), glow::COLOR_ATTACHMENT0, Some(color), 0);
            gl.named_framebuffer_texture(Some(fbo), glow::DEPTH_STENCIL_ATTACHMENT, Some(depth_stencil), 0);
            if let Some(t) = world_pos {
                gl.named_framebuffer_texture(Some(fbo), glow::COLOR_ATTACHMENT1, Some(t), 0);
            }
            if let Some(t) = triangle_id {
                gl.named_framebuffer_texture(Some(fbo), glow::COLOR_ATTACHMENT2, Some(t), 0);
            }
            if let Some(t) = lit_mask {
                gl.named_framebuffer_texture(Some(fbo), glow::COLOR_ATTACHMENT3, Some(t), 0);
            }
            let target =
                Self { width, height, attachments, fbo, color, depth_stencil, world_pos, triangle_id, lit_mask };
            target.set_draw_buffers(gl, TargetPass::Depth);
            let status = gl.check_named_framebuffer_status(Some(fbo), glow::DRAW_FRAMEBUFFER);
            if status != glow::FRAMEBUFFER_COMPLETE {
                target.destroy(gl);
                return Err(GlError::Framebuffer {
                    status,
                    what: "RenderTarget (RGBA8 + D24S8/D32FS8 + optional RGBA32F/R32UI/R8)",
                });
            }
            Ok(target)
        }
    }

    /// Width in pixels.
    pub fn width(&self) -> u32 {
        self.width
    }
    /// Height in pixels.
    pub fn height(&self) -> u32 {
        self.height
    }
    /// Which attachments it has.
    pub fn attachments(&self) -> Attachments {
        self.attachments
    }
    /// The framebuffer object (e.g. for [`crate::FrameTarget`]).
    pub fn framebuffer(&self) -> glow::Framebuffer {
        self.fbo
    }

    /// Draw buffers of this framebuffer for `pass` (framebuffer-object state, not context
    /// state); a location without a draw buffer is discarded by GL, so a pass leaves the
    /// attachments it does not list intact.
    pub fn set_draw_buffers(&self, gl: &glow::Context, pass: TargetPass) {
        let a = self.attachments;
        let on = |yes: bool, att: u32| if yes { att } else { glow::NONE };
        let bufs = match pass {
            TargetPass::Depth => [
                glow::COLOR_ATTACHMENT0,
                on(a.world_pos, glow::COLOR_ATTACHMENT1),
                on(a.triangle_id, glow::COLOR_ATTACHMENT2),
                glow::NONE,
            ],
            TargetPass::Lighting { lit_mask } => {
                [glow::COLOR_ATTACHMENT0, glow::NONE, glow::NONE, on(lit_mask && a.lit_mask, glow::COLOR_ATTACHMENT3)]
            }
        };
        // SAFETY: valid attachment enums for our own framebuffer.
        unsafe { gl.named_framebuffer_draw_buffers(Some(self.fbo), &bufs) };
    }

    /// Clears colour to `background`, world position to 0, triangle id to [`NO_TRIANGLE`],
    /// the lit mask to 0, depth to `far_depth` ([`crate::DepthConvention::far_depth`]) and
    /// stencil to 0. The caller must have write masks on (see [`crate::GlState::default`]);
    /// clears obey them. Leaves the draw buffers at [`TargetPass::Depth`].
    pub fn clear(&self, gl: &glow::Context, background: [f32; 4], far_depth: f32) {
        self.clear_lit_mask(gl);
        self.set_draw_buffers(gl, TargetPass::Depth);
        // SAFETY: clears of our own framebuffer's draw buffers (indices match set_draw_buffers).
        unsafe {
            gl.clear_named_framebuffer_f32_slice(Some(self.fbo), glow::COLOR, 0, &background);
            if self.attachments.world_pos {
                gl.clear_named_framebuffer_f32_slice(Some(self.fbo), glow::COLOR, 1, &[0.0; 4]);
            }
            if self.attachments.triangle_id {
                gl.clear_named_framebuffer_u32_slice(Some(self.fbo), glow::COLOR, 2, &[NO_TRIANGLE, 0, 0, 0]);
            }
            gl.clear_named_framebuffer_depth_stencil(Some(self.fbo), glow::DEPTH_STENCIL, 0, far_depth, 0);
        }
    }

    /// Clears the lit mask (if present) to 0; leaves the draw buffers at
    /// `TargetPass::Lighting { lit_mask: true }`. Obeys the colour write mask of draw buffer 3.
    pub fn clear_lit_mask(&self, gl: &glow::Context) {
        if self.attachments.lit_mask {
            self.set_draw_buffers(gl, TargetPass::Lighting { lit_mask: true });
            // SAFETY: draw buffer 3 of our own framebuffer is the R8 lit mask (set just above).
            unsafe { gl.clear_named_framebuffer_f32_slice(Some(self.fbo), glow::COLOR, 3, &[0.0; 4]) };
        }
    }

    /// Reads the colour attachment (top row first).
    pub fn read_rgba(&self, gl: &glow::Context) -> RgbaImage {
        read_rgba8(gl, Some(self.fbo), glow::COLOR_ATTACHMENT0, self.width, self.height)
    }

    /// Reads the world positions; None without that attachment.
    pub fn read_world_pos(&self, gl: &glow::Context) -> Option<WorldPosImage> {
        self.attachments.world_pos.then(|| {
            let bytes = read_bytes(
                gl,
                Some(self.fbo),
                glow::COLOR_ATTACHMENT1,
                self.width,
                self.height,
                glow::RGBA,
                glow::FLOAT,
                16,
            );
            let px = bytes
                .chunks_exact(16)
                .map(|c| [0, 1, 2, 3].map(|i| f32::from_ne_bytes([c[4 * i], c[4 * i + 1], c[4 * i + 2], c[4 * i + 3]])))
                .collect();
            Image::from_bottom_up(self.width, self.height, px)
        })
    }

    /// Reads the triangle ids; None without that attachment.
    pub fn read_triangle_ids(&self, gl: &glow::Context) -> Option<TriangleIdImage> {
        self.attachments.triangle_id.then(|| {
            let bytes = read_bytes(
                gl,
                Some(self.fbo),
                glow::COLOR_ATTACHMENT2,
                self.width,
                self.height,
                glow::RED_INTEGER,
                glow::UNSIGNED_INT,
                4,
            );
            let px = bytes.chunks_exact(4).map(|c| u32::from_ne_bytes([c[0], c[1], c[2], c[3]])).collect();
            Image::from_bottom_up(self.width, self.height, px)
        })
    }

    /// The lit mask as 0 / 1 per pixel (the R8 value 1.0 reads back as 255).
    pub fn read_lit_mask(&self, gl: &glow::Context) -> Option<LitMaskImage> {
        self.attachments.lit_mask.then(|| {
            let bytes = read_bytes(
                gl,
                Some(self.fbo),
                glow::COLOR_ATTACHMENT3,
                self.width,
                self.height,
                glow::RED,
                glow::UNSIGNED_BYTE,
                1,
            );
            Image::from_bottom_up(self.width, self.height, bytes.into_iter().map(|v| u8::from(v != 0)).collect())
        })
    }

    /// Reads the stencil (top row first).
    pub fn read_stencil(&self, gl: &glow::Context) -> StencilImage {
        read_stencil(gl, Some(self.fbo), self.width, self.height)
    }

    /// Deletes the GL objects.
    pub fn destroy(self, gl: &glow::Context) {
        // SAFETY: objects owned by this target, not used afterwards.
        unsafe {
            gl.delete_framebuffer(self.fbo);
            for t in [Some(self.color), Some(self.depth_stencil), self.world_pos, self.triangle_id, self.lit_mask]
                .into_iter()
                .flatten()
            {
                gl.delete_texture(t);
            }
        }
    }
}

/// Creates a `width x height` texture of `format` (one level) into `made`, its storage
/// allocation checked ([`crate::gpu_buffer::checked_allocation`]): a refusal is
/// [`GlError::OutOfMemory`] naming the attachment, with the texture deleted and no GL error
/// left pending.
fn texture_storage(
    gl: &glow::Context,
    made: &mut Vec<glow::Texture>,
    width: u32,
    height: u32,
    format: u32,
    bytes_per_pixel: usize,
    name: &str,
) -> Result<glow::Texture, GlError> {
    // SAFETY: texture creation on the current context; stored in `made` (the caller deletes
    // it on a later failure) or deleted right here.
    let t = unsafe { gl.create_named_texture(glow::TEXTURE_2D) }
        .map_err(|detail| GlError::Create { what: "texture", detail })?;
    let bytes = width as usize * height as usize * bytes_per_pixel;
    let what = format!("the {width}x{height} {name} attachment of the render target");
    // SAFETY: immutable storage of our own new texture; width and height are within
    // GL_MAX_RENDERBUFFER_SIZE (checked by RenderTarget::new), so they fit an i32.
    let result = crate::gpu_buffer::checked_allocation(gl, &what, bytes, || unsafe {
        gl.texture_storage_2d(t, 1, format, width as i32, height as i32)
    });
    match result {
        Ok(()) => {
            made.push(t);
            Ok(t)
        }
        Err(e) => {
            // SAFETY: our own texture, never handed out.
            unsafe { gl.delete_texture(t) };
            Err(e)
        }
    }
}

/// Reads `width x height` RGBA8 pixels from `read_buffer` (e.g. COLOR_ATTACHMENT0, or BACK
/// for the default framebuffer) of `framebuffer` (None = default), top row first.
pub fn read_rgba8(
    gl: &glow::Context,
    framebuffer: Option<glow::Framebuffer>,
    read_buffer: u32,
    width: u32,
    height: u32,
) -> RgbaImage {
    let bytes = read_bytes(gl, framebuffer, read_buffer, width, height, glow::RGBA, glow::UNSIGNED_BYTE, 4);
    let px = bytes.chunks_exact(4).map(|c| [c[0], c[1], c[2], c[3]]).collect();
    Image::from_bottom_up(width, height, px)
}

/// Reads the stencil of `framebuffer` (None = default) with GL_STENCIL_INDEX, one u8 per
/// pixel, top row first. Works on any framebuffer with a stencil attachment.
pub fn read_stencil(
    gl: &glow::Context,
    framebuffer: Option<glow::Framebuffer>,
    width: u32,
    height: u32,
) -> StencilImage {
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
        gl.bind_buffer(glow::PIXEL_PACK_BUFFER, crate::gl_names::buffer(prev_pack_buffer));
        gl.bind_framebuffer(glow::READ_FRAMEBUFFER, crate::gl_names::framebuffer(prev_read_fb));
    }
    out
}
