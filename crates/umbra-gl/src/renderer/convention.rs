//! The frame's depth convention on the context: glClipControl (found through EGL, or given
//! with [`Renderer::with_extra`]) and glDepthRange, and whether a convention can be drawn.

use std::sync::OnceLock;

use glow::HasContext;

use super::Renderer;
use crate::camera::{DepthConvention, DepthConventionGl};
use crate::error::GlError;
use crate::extra::GlExtra;

/// Entry points through EGL when the current context is an EGL context (then
/// eglGetProcAddress is valid for it); empty otherwise (no EGL, or another window system).
pub(super) fn extra_from_current_egl() -> GlExtra {
    use khronos_egl as egl;
    static EGL: OnceLock<Option<egl::DynamicInstance<egl::EGL1_4>>> = OnceLock::new();
    // SAFETY: loads the system's libEGL (the library the headless context uses too); its
    // initialisation has no preconditions.
    let instance = EGL.get_or_init(|| unsafe { egl::DynamicInstance::<egl::EGL1_4>::load_required() }.ok());
    match instance {
        Some(e) if e.get_current_context().is_some() => {
            GlExtra::load(|name| e.get_proc_address(name).map_or(std::ptr::null(), |f| f as *const std::ffi::c_void))
        }
        _ => GlExtra::default(),
    }
}

impl Renderer {
    /// Whether frames in `convention` can be drawn: Standard always, ReversedZ when
    /// glClipControl is loaded.
    pub fn supports(&self, convention: DepthConvention) -> bool {
        convention == DepthConvention::Standard || self.extra.has_clip_control()
    }

    /// Err unless frames in `convention` can be drawn ([`Renderer::supports`]).
    pub(super) fn check_convention(&self, convention: DepthConvention) -> Result<(), GlError> {
        if self.supports(convention) {
            return Ok(());
        }
        Err(GlError::InvalidParams(format!(
            "depth convention {convention:?} needs glClipControl (GL 4.5 / ARB_clip_control), which this renderer has \
             not loaded: give it one with Renderer::with_extra(GlExtra::load(..)) or use DepthConvention::Standard"
        )))
    }

    /// glClipControl and glDepthRange for `convention` (restored by SavedState).
    pub(super) fn set_depth_convention(&self, gl: &glow::Context, convention: DepthConvention) -> Result<(), GlError> {
        // Reason: LOWER_LEFT is GL's default origin (keeps glReadPixels rows and
        // gl_FrontFacing as everywhere else); the depth mode maps clip z to depth: ZERO_TO_ONE
        // makes depth = z_ndc exactly, so reversed-Z's n / d reaches the float depth buffer
        // without the z / 2 + 1 / 2 rounding that would cost it every bit below 2^-24 (it is
        // what makes reversed-Z precise); NEGATIVE_ONE_TO_ONE for Standard.
        // SAFETY: the context the entry point was loaded for is current (the renderer's
        // contract); the arguments are valid enums.
        let set = unsafe { self.extra.clip_control(glow::LOWER_LEFT, convention.clip_depth_mode()) };
        // SAFETY: plain queries and glDepthRange on the current context.
        unsafe {
            if !set {
                // No glClipControl: only fine if the context is already in the wanted mode.
                let origin = gl.get_parameter_i32(glow::CLIP_ORIGIN) as u32;
                let mode = gl.get_parameter_i32(glow::CLIP_DEPTH_MODE) as u32;
                if origin != glow::LOWER_LEFT || mode != convention.clip_depth_mode() {
                    return Err(GlError::InvalidParams(format!(
                        "clip control is (0x{origin:04X}, 0x{mode:04X}) and glClipControl is not loaded to set it for {convention:?}"
                    )));
                }
            }
            // Reason: the full [0, 1] depth range, so window depth = the convention's depth.
            gl.depth_range_f64(0.0, 1.0);
        }
        Ok(())
    }
}
