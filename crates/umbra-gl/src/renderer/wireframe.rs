//! The renderer's volume wireframe (a debugging view): a method's shadow volumes
//! drawn as tinted lines over a finished frame.

use glow::HasContext;
use umbra_geom::Light;

use umbra_geom::FrameParams;

use super::validate::validate_view;
use super::{FrameTarget, Renderer};
use crate::counter::Counter;
use crate::error::GlError;
use crate::methods::{Classification, ShadowMethod, StageHook, StageMark};
use crate::saved::{MethodBindings, SavedState};
use crate::scene::SceneGpu;
use crate::state::{BlendState, GlState};

impl Renderer {
    /// Draws `method`'s shadow volumes for `light` as a tinted wireframe over a frame already
    /// in the caller's framebuffer (`target`, None = the default framebuffer) — a debugging
    /// view (`umbra view`'s wireframe toggle). Call it after
    /// [`Renderer::draw_frame`] (or [`Renderer::render`], on [`Renderer::target`]'s
    /// framebuffer) with the same `params`: the volumes are tested against the frame's depth.
    ///
    /// What is drawn: every volume triangle the method draws for its counting (sides, light and
    /// dark caps) rasterized as lines (glPolygonMode LINE), where the line lies strictly nearer
    /// than the frame's depth (the counting pass's own depth test: the lines a viewer can see in
    /// front of the surfaces; light caps pushed to the far plane never show). Colour =
    /// `dst * tint` (glBlendFunc(ZERO, CONSTANT_COLOR), glBlendColor(tint)): the volume shaders
    /// write only a single-channel count, so the blend ignores it; alpha is not written.
    ///
    /// **Framebuffer contents touched**: the colour of every enabled draw buffer (tinted where
    /// a line passes; use a framebuffer with a single draw buffer, as for draw_frame) and the
    /// stencil (cleared to 0; nothing is counted into it). Depth is not written. Always
    /// counted with [`Counter::Stencil8`]'s geometry (the wide counter draws the same volumes
    /// into its own target, which is not what is shown).
    ///
    /// **GL state**: as [`Renderer::count_shadows`], all restored, plus glPolygonMode and
    /// glBlendColor.
    ///
    /// Methods without volumes ([`Classification::Shader`], the shadow maps, and those that
    /// fill none, [`ShadowMethod::fills_volumes`]: hier-triangle) give
    /// [`GlError::Unsupported`] and draw nothing. The wireframe state is applied at each of
    /// the method's stage marks ([`crate::VolumeFrame::mark`]), after the method set its counting
    /// state: a method that applies its counting state after its last mark before a draw
    /// draws that part invisibly (colour writes off). Measured on the sphere-over-ground
    /// frame (tests/wireframe.rs): cpu-, vs- and cs-silhouette show sides and caps;
    /// ts-silhouette sides only (the shared silhouette caps set their state after the "caps"
    /// mark); gs-silhouette nothing on llvmpipe (its sides, emitted by a geometry shader,
    /// are not drawn in line mode there; cause not found); the per-triangle methods draw
    /// every triangle's volume (dense).
    #[allow(clippy::too_many_arguments)]
    pub fn draw_volume_wireframe(
        &mut self,
        gl: &glow::Context,
        scene: &SceneGpu,
        method: &mut dyn ShadowMethod,
        params: &FrameParams,
        light: impl Into<Light>,
        target: FrameTarget,
        tint: [f32; 3],
    ) -> Result<(), GlError> {
        let light = light.into();
        validate_view(params, &light)?;
        if tint.iter().any(|v| !v.is_finite()) {
            return Err(GlError::InvalidParams(format!("wireframe tint {tint:?} is not finite")));
        }
        if method.classification() == Classification::Shader {
            return Err(GlError::Unsupported {
                method: method.name(),
                reason: "classifies in a shader (shadow map): it has no shadow volumes to draw as a wireframe".into(),
            });
        }
        if !method.fills_volumes() {
            return Err(GlError::Unsupported {
                method: method.name(),
                reason: "decides per sample without rasterizing shadow volumes: it has none to draw as a wireframe"
                    .into(),
            });
        }
        self.check_convention(params.depth_convention)?;
        let saved = SavedState::capture(gl);
        let bindings = MethodBindings::capture(gl);
        let result = self.wireframe_on(gl, scene, method, params, light, target.framebuffer, tint);
        bindings.restore(gl);
        saved.restore(gl, &self.extra);
        let checked = self.check_errors(gl, "draw_volume_wireframe");
        result.and(checked)
    }

    /// The body of [`Renderer::draw_volume_wireframe`] (state saved by the caller).
    #[allow(clippy::too_many_arguments)]
    fn wireframe_on(
        &mut self,
        gl: &glow::Context,
        scene: &SceneGpu,
        method: &mut dyn ShadowMethod,
        params: &FrameParams,
        light: Light,
        fb: Option<glow::Framebuffer>,
        tint: [f32; 3],
    ) -> Result<(), GlError> {
        // Reason: the wide counter would send the volumes into its own target; the geometry
        // is the same with the stencil counter, and only the geometry is shown.
        let params = FrameParams { counter: Counter::Stencil8, ..params.clone() };
        let view = self.begin_on_target(gl, scene, method, &params, fb)?;
        // SAFETY: plain state calls on the current context (restored by the caller's
        // SavedState).
        unsafe {
            // Reason: the wireframe itself: volume triangles as their edges. No method sets
            // the polygon mode, so it holds through the method's draws.
            gl.polygon_mode(glow::FRONT_AND_BACK, glow::LINE);
            // Reason: the blend below multiplies the frame by this tint (the volume shaders
            // write no colour to blend with).
            gl.blend_color(tint[0], tint[1], tint[2], 1.0);
        }
        let mut state = GlState::shadow_volume_for(false, view.convention);
        // Reason: draw lines, do not count (the stencil holds nothing the frame still needs).
        state.stencil_test = false;
        // Reason: tint RGB; alpha keeps the frame's coverage.
        state.color_write = [true, true, true, false];
        // Reason: dst * tint, independent of the shader's single-channel count output.
        state.blend = Some(BlendState {
            src_rgb: glow::ZERO,
            dst_rgb: glow::CONSTANT_COLOR,
            src_alpha: glow::ZERO,
            dst_alpha: glow::ONE,
            equation_rgb: glow::FUNC_ADD,
            equation_alpha: glow::FUNC_ADD,
        });
        // The depth test stays the counting state's (strictly nearer than the frame's depth,
        // depth clamp on, no depth writes): only lines in front of the visible surfaces show.
        // Every draw of the method takes this state (VolumeFrame::shadow_volume_state), as
        // does the hook at each stage mark for a method that applies its own state after one.
        self.volume_state_override = Some(state);
        let mut wire = WireframeHook { state };
        let mut hook: Option<&mut dyn StageHook> = Some(&mut wire);
        let drawn = self.volume_pass(gl, scene, method, &params, &view, light, 0, &mut hook);
        self.volume_state_override = None;
        drawn
    }
}

/// Applies the wireframe state at every stage mark of a method (after the method applied its
/// counting state, before its draws); the renderer's own marks are left alone.
struct WireframeHook {
    state: GlState,
}

impl StageHook for WireframeHook {
    fn mark(&mut self, gl: &glow::Context, mark: StageMark) {
        if mark.source != "renderer" {
            self.state.apply(gl);
        }
    }
}
