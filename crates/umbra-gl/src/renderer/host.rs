//! umbra inside a caller's renderer, light by light: [`Renderer::count_shadows`] counts one
//! light's volumes into the stencil of the caller's framebuffer, on the caller's depth;
//! [`Renderer::add_light`] adds that light with umbra's lighting shader.

use glow::HasContext;
use umbra_geom::{FrameParams, Light};

use super::validate::{check_projection, check_stencil_target, validate_shading, validate_view};
use super::view::PassView;
use super::{FrameTarget, Renderer};
use crate::error::GlError;
use crate::methods::{Classification, ShadowMethod};
use crate::saved::{MethodBindings, SavedState};
use crate::scene::SceneGpu;

impl Renderer {
    /// Counts `light`'s shadow volumes into the stencil of a caller's framebuffer whose depth
    /// already holds the caller's scene — umbra inside someone else's renderer:
    /// no clear of colour or depth, no depth pass of umbra's own.
    ///
    /// Returns what "lit" means in the stencil afterwards, for the caller's lighting pass:
    /// [`Classification::StencilZero`] (lit where the stencil is 0) or
    /// [`Classification::StencilTest`] (lit where that `glStencilFunc` passes). Methods that
    /// classify in a shader ([`Classification::Shader`], the shadow maps) are resolved into the
    /// stencil here — 0 where the method's `umbra_lit` holds on the caller's visible surface,
    /// 1 elsewhere (also where no surface was drawn) — and report `StencilZero`. Either way,
    /// "lit" here is the classification only: like umbra's own lighting, the caller's shader
    /// must also require that the side of the triangle it sees faces the light (a surface
    /// seen from the side turned away from the light is unlit whatever the stencil holds;
    /// the volumes decide only for the lit side).
    ///
    /// Uses from `params`: `camera`, `width`, `height`, `zpass`, `depth_convention` (and the
    /// stencil counter choice); not `lights`, colours, `capture`. `light` is homogeneous
    /// (w = 1 point, w = 0 directional, coming from xyz): a `[f32; 4]`, or anything that
    /// converts into one (`mint::Vector4<f32>`, glam's `Vec4`).
    ///
    /// **Invariance requirement.** z-fail counting compares the volumes, whose caps are the
    /// scene's own triangles, with the depth buffer; the caller's depth must therefore be
    /// bit-identical to what umbra would draw: the same positions as `scene`, transformed by
    /// exactly `params.camera.clip_from_world_in(width / height, depth_convention)` converted
    /// with [`crate::camera::to_f32_cols`] (or [`crate::camera::Camera::clip_from_world_cols`] rounded to
    /// f32), in a vertex shader computing
    /// `gl_Position = u_clip_from_world * vec4(position, 1.0)` with `invariant gl_Position`,
    /// rendered with glClipControl(LOWER_LEFT, [`DepthConvention::clip_depth_mode`](crate::camera::DepthConventionGl::clip_depth_mode)) and
    /// glDepthRange(0, 1), and the depth cleared to [`DepthConvention::far_depth`](crate::camera::DepthConvention::far_depth). Other
    /// transforms give wrong counts along every silhouette and cap.
    ///
    /// **Framebuffer** (`target`, None = default framebuffer): `params.width x height`, with
    /// a stencil attachment of at least 8 bits (checked: [`GlError::InvalidParams`]); complete
    /// (checked: [`GlError::Framebuffer`]).
    ///
    /// **Framebuffer contents touched**: the stencil only — cleared to 0 and counted (its
    /// whole area: scissor is off during the call). Depth and every colour attachment are
    /// left as they were (the volumes draw with depth writes and colour writes off; a shadow
    /// map renders into its own texture). With `params.counter` wide counting, umbra's own
    /// counting target is drawn and the stencil written by its resolve.
    ///
    /// **GL state**: saved before and restored after, exactly: every [`GlState`](crate::GlState) field
    /// (depth test/func/write/clamp, stencil test, both stencil faces' func/ref/masks/ops,
    /// colour mask, cull enable/face, front face, blend enable/func/equation, polygon
    /// offset), the current program, the vertex array, the draw and read framebuffers, the
    /// viewport, SCISSOR_TEST and RASTERIZER_DISCARD, glClipControl's origin and depth mode,
    /// glDepthRange, the generic SHADER_STORAGE_BUFFER binding and the indexed bindings
    /// 0-7 (buffer, offset, size), the ARRAY_BUFFER, COPY_READ_BUFFER, DRAW_INDIRECT_BUFFER and
    /// DISPATCH_INDIRECT_BUFFER bindings, PATCH_VERTICES, the active texture unit and unit 0's 2D and cube-map
    /// textures. Not restored (nothing of the caller's is involved): objects the method owns
    /// and what is bound inside them.
    pub fn count_shadows(
        &mut self,
        gl: &glow::Context,
        scene: &SceneGpu,
        method: &mut dyn ShadowMethod,
        params: &FrameParams,
        light: impl Into<Light>,
        target: FrameTarget,
    ) -> Result<Classification, GlError> {
        let light = light.into();
        validate_view(params, &light)?;
        self.check_convention(params.depth_convention)?;
        check_projection(params, method)?;
        let saved = SavedState::capture(gl);
        let bindings = MethodBindings::capture(gl);
        let result = self.count_on(gl, scene, method, params, light, target.framebuffer);
        bindings.restore(gl);
        saved.restore(gl, &self.extra);
        let checked = self.check_errors(gl, "count_shadows");
        let classification = result?;
        checked.map(|()| classification)
    }

    /// Adds `light`'s diffuse + specular to draw buffer 0 of a caller's framebuffer with
    /// umbra's own lighting shader, where [`Renderer::count_shadows`] (called just before,
    /// for the same light, method, scene and view) left "lit" — for hosts that do not want
    /// to write their own lighting pass. Two-sided Lambert + Blinn-Phong with
    /// `params.light_color`, `albedo`, `specular`, `shininess`; depth func EQUAL against the
    /// caller's depth (the invariance requirement of `count_shadows` holds here too), no
    /// depth writes, additive blending (ONE, ONE), alpha not written.
    ///
    /// **Framebuffer contents touched**: draw buffer 0 (colour added), draw buffer 3 if the
    /// framebuffer has one (umbra's lit-mask output, 1 or 0 where shaded), and for
    /// [`Classification::StencilZero`] / shader-classified methods the stencil (incremented
    /// where shaded, so a coplanar duplicate triangle cannot add the light twice). Depth is
    /// not written. **GL state**: as [`Renderer::count_shadows`], all restored.
    pub fn add_light(
        &mut self,
        gl: &glow::Context,
        scene: &SceneGpu,
        method: &mut dyn ShadowMethod,
        params: &FrameParams,
        light: impl Into<Light>,
        target: FrameTarget,
    ) -> Result<(), GlError> {
        let light = light.into();
        validate_view(params, &light)?;
        validate_shading(params)?;
        self.check_convention(params.depth_convention)?;
        if method.prepared_scene() != Some(scene.id()) {
            return Err(GlError::InvalidParams(format!(
                "add_light: method {} has not counted this scene's shadows: call count_shadows first",
                method.name()
            )));
        }
        let saved = SavedState::capture(gl);
        let bindings = MethodBindings::capture(gl);
        let result = self.light_on(gl, scene, method, params, light, target.framebuffer);
        bindings.restore(gl);
        saved.restore(gl, &self.extra);
        let checked = self.check_errors(gl, "add_light");
        result.and(checked)
    }

    /// The common start of the passes on a caller's framebuffer (count_shadows,
    /// draw_volume_wireframe): binds it (checked to have a stencil), prepares `method` for
    /// `scene`, lets the passes cover the whole frame and sets the depth convention.
    pub(super) fn begin_on_target(
        &mut self,
        gl: &glow::Context,
        scene: &SceneGpu,
        method: &mut dyn ShadowMethod,
        params: &FrameParams,
        fb: Option<glow::Framebuffer>,
    ) -> Result<PassView, GlError> {
        let view = PassView::new(params, fb, self.next_view_serial());
        view.bind_target(gl);
        check_stencil_target(gl, fb)?;
        if method.prepared_scene() != Some(scene.id()) {
            method.prepare(gl, scene)?;
        }
        // SAFETY: plain enables (restored by the caller's SavedState).
        unsafe {
            // Reason: the stencil clear and the counting must cover the whole frame (a clear
            // obeys the scissor box), and nothing may be discarded before rasterization.
            gl.disable(glow::SCISSOR_TEST);
            gl.disable(glow::RASTERIZER_DISCARD);
        }
        self.set_depth_convention(gl, view.convention)?;
        Ok(view)
    }

    /// The body of [`Renderer::count_shadows`] (state saved by the caller).
    fn count_on(
        &mut self,
        gl: &glow::Context,
        scene: &SceneGpu,
        method: &mut dyn ShadowMethod,
        params: &FrameParams,
        light: Light,
        fb: Option<glow::Framebuffer>,
    ) -> Result<Classification, GlError> {
        let view = self.begin_on_target(gl, scene, method, params, fb)?;
        let mut hook = None;
        self.volume_pass(gl, scene, method, params, &view, light, 0, &mut hook)?;
        match method.classification() {
            Classification::Shader => {
                self.shader_lit_to_stencil(gl, scene, method, params, &view, light)?;
                Ok(Classification::StencilZero)
            }
            other => Ok(other),
        }
    }

    /// The body of [`Renderer::add_light`] (state saved by the caller).
    fn light_on(
        &mut self,
        gl: &glow::Context,
        scene: &SceneGpu,
        method: &mut dyn ShadowMethod,
        params: &FrameParams,
        light: Light,
        fb: Option<glow::Framebuffer>,
    ) -> Result<(), GlError> {
        let view = PassView::new(params, fb, self.next_view_serial());
        view.bind_target(gl);
        check_stencil_target(gl, fb)?;
        // SAFETY: plain enables (restored by the caller's SavedState).
        unsafe {
            // Reason: light the whole frame, as count_shadows counted it.
            gl.disable(glow::SCISSOR_TEST);
            gl.disable(glow::RASTERIZER_DISCARD);
        }
        self.set_depth_convention(gl, view.convention)?;
        let mut hook = None;
        self.lighting_pass(gl, scene, method, params, &view, None, None, light, 0, &mut hook)?;
        Ok(())
    }
}
