//! The renderer's checks before any drawing: the frame's parameters (no GL call) and a
//! caller's target framebuffer.

use glow::HasContext;
use umbra_geom::{FrameParams, Light};

use crate::error::GlError;
use crate::methods::ShadowMethod;

/// Checks parameters before any GL call ([`FrameParams::check`]).
pub(super) fn validate(params: &FrameParams) -> Result<(), GlError> {
    Ok(params.check()?)
}

/// Camera, frame size and one light (for the host API, which takes the light apart).
pub(super) fn validate_view(params: &FrameParams, light: &Light) -> Result<(), GlError> {
    params.check_view()?;
    umbra_geom::check_light(0, light).map_err(|e| GlError::InvalidParams(e.to_string()))
}

/// An orthographic camera only with a method that draws it ([`ShadowMethod::orthographic`]).
pub(super) fn check_projection(params: &FrameParams, method: &dyn ShadowMethod) -> Result<(), GlError> {
    if params.camera.is_orthographic() && !method.orthographic() {
        return Err(GlError::InvalidParams(format!(
            "method {} cannot draw an orthographic view (its shadow volumes run to infinity, where an \
             orthographic camera has no far plane); cpu-silhouette, none and the shadow maps can",
            method.name()
        )));
    }
    Ok(())
}

/// Colours and shading parameters are finite.
pub(super) fn validate_shading(params: &FrameParams) -> Result<(), GlError> {
    Ok(params.check_shading()?)
}

/// The bound draw framebuffer (`fb`, as the error names it) is complete and has a stencil
/// buffer of at least 8 bits.
pub(super) fn check_stencil_target(gl: &glow::Context, fb: Option<glow::Framebuffer>) -> Result<(), GlError> {
    // The default framebuffer names its stencil buffer STENCIL, a framebuffer object
    // STENCIL_ATTACHMENT (a DEPTH_STENCIL attachment answers for both).
    let attachment = if fb.is_some() { glow::STENCIL_ATTACHMENT } else { glow::STENCIL };
    // SAFETY: queries of the bound draw framebuffer; the size is only queried when an image
    // is attached (otherwise the query is an error).
    let (status, kind, bits) = unsafe {
        let status = gl.check_framebuffer_status(glow::DRAW_FRAMEBUFFER);
        let kind = gl.get_framebuffer_attachment_parameter_i32(
            glow::DRAW_FRAMEBUFFER,
            attachment,
            glow::FRAMEBUFFER_ATTACHMENT_OBJECT_TYPE,
        ) as u32;
        let bits = if status == glow::FRAMEBUFFER_COMPLETE && kind != glow::NONE {
            gl.get_framebuffer_attachment_parameter_i32(
                glow::DRAW_FRAMEBUFFER,
                attachment,
                glow::FRAMEBUFFER_ATTACHMENT_STENCIL_SIZE,
            )
        } else {
            0
        };
        (status, kind, bits)
    };
    if status != glow::FRAMEBUFFER_COMPLETE {
        return Err(GlError::Framebuffer { status, what: "the caller's framebuffer (FrameTarget)" });
    }
    if kind == glow::NONE || bits < 8 {
        return Err(GlError::InvalidParams(format!(
            "the target framebuffer ({}) has {bits} stencil bits; shadow volumes need at least 8",
            if fb.is_some() { "a framebuffer object" } else { "the default framebuffer" }
        )));
    }
    Ok(())
}
