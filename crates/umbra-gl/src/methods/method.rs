//! The shadow-method trait of the GL backend ([`ShadowMethod`]), what a method sees of one
//! light's frame ([`VolumeFrame`]), how the lighting pass reads its result
//! ([`Classification`]) and the stage marks it reports ([`StageHook`]). Apart from the
//! registry (`methods/mod.rs`), so that each method imports these without importing the list
//! of every method.

use glam::DMat4;
use umbra_geom::Light;

use crate::camera::DepthConvention;
use crate::counter::{Counter, CounterGl};
use crate::error::GlError;
use crate::methods::work_counts::WorkCounts;
use crate::scene::{SceneGpu, SceneId};

/// How the lighting pass decides that a pixel is lit for the current light.
///
/// Whatever the classification, the renderer's final decision for a pixel and light ("lit":
/// it receives that light's diffuse and specular) is: the classification passes AND the side
/// of the triangle the camera sees faces the light (two-sided lighting, `gl_FrontFacing` and
/// the flat triangle normal). That decision is what the image shows and what
/// [`crate::CaptureFlags::lit_mask`] reads back; the verifier compares it with the
/// ray-traced reference. The stencil alone is not that decision: where the seen side faces
/// away from the light, the stencil value does not matter.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Classification {
    /// Lit where the stencil is 0 (counting methods; glStencilFunc(EQUAL, 0, 0xFF)).
    StencilZero,
    /// Lit where `glStencilFunc(func, reference, value_mask)` passes.
    StencilTest {
        /// glStencilFunc's comparison (`glow::EQUAL`, ...).
        func: u32,
        /// glStencilFunc's reference value.
        reference: i32,
        /// glStencilFunc's mask.
        value_mask: u32,
    },
    /// Lit where the method's GLSL `bool umbra_lit(vec3 world_pos)` returns true
    /// ([`ShadowMethod::lighting_glsl`]); resources bound in [`ShadowMethod::bind_lighting`].
    Shader,
}

/// Label and light of a stage boundary: "stage `label` starts here".
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StageMark {
    /// Name of the method (or "renderer" for the renderer's own passes).
    pub source: &'static str,
    /// The stage that starts ("depth", "volumes", "lighting", a method's own stage, "end").
    pub label: &'static str,
    /// Light index, `None` for per-frame stages.
    pub light: Option<usize>,
}

/// Receives stage boundaries (e.g. to issue glQueryCounter(GL_TIMESTAMP)).
pub trait StageHook {
    /// Called at every stage boundary, on the frame's context.
    fn mark(&mut self, gl: &glow::Context, mark: StageMark);
}

/// What a method gets for one light of one frame.
///
/// The frame's depth convention ([`VolumeFrame::depth_convention`]) is already applied: the
/// renderer has set glClipControl for it, `clip_from_world` is built in it, and
/// [`VolumeFrame::far_clip_z`] / [`VolumeFrame::shadow_volume_state`] follow it. A method that
/// uses those two (never literals for the far plane or the depth function) works under every
/// convention without knowing which one is active.
pub struct VolumeFrame<'a> {
    /// Camera clip space from world space, infinite far plane, in the frame's depth
    /// convention (f64; upload as f32).
    pub clip_from_world: DMat4,
    /// Eye position in world space.
    pub eye: [f64; 3],
    /// The light (w = 1 point, w = 0 directional).
    pub light: Light,
    /// Index of the light in the frame (0 for [`crate::Renderer::count_shadows`]).
    pub light_index: usize,
    /// z-pass counting instead of z-fail (no caps needed).
    pub zpass: bool,
    /// Cull and clamp the volumes against the light's receivers, for the methods that can
    /// ([`ShadowMethod::culls_volumes`]); from [`umbra_geom::FrameParams::volume_cull`].
    pub volume_cull: bool,
    /// Which faces the depth pass showed ([`umbra_geom::FrameParams::receivers`]): a pass that
    /// re-draws the scene's surfaces with depth EQUAL culls as it did
    /// ([`crate::GlState::visible_samples`]).
    pub receivers: crate::Receivers,
    /// Size of the render target in pixels.
    pub width: u32,
    /// Height of the render target in pixels.
    pub height: u32,
    /// The framebuffer the frame renders into (None = default framebuffer): a method that
    /// renders elsewhere (shadow maps) must bind this one back before drawing to the stencil.
    pub target_framebuffer: Option<glow::Framebuffer>,
    pub(crate) depth_convention: DepthConvention,
    /// The counter of this volume pass ([`crate::counter`]): [`Counter::Float32`] only for
    /// [`Classification::StencilZero`] methods when the frame asks for it; then
    /// `target_framebuffer` is the counter's framebuffer.
    pub(crate) counter: Counter,
    /// Replaces the counting state for every draw of the pass (the renderer's volume wireframe:
    /// lines, colour, no stencil), `None` normally.
    pub(crate) state_override: Option<crate::GlState>,
    /// See [`VolumeFrame::view_serial`].
    pub(crate) view_serial: u64,
    pub(crate) source: &'static str,
    pub(crate) hook: Option<&'a mut dyn StageHook>,
}

impl VolumeFrame<'_> {
    /// Reports that stage `label` of this method starts now (no-op without a hook).
    pub fn mark(&mut self, gl: &glow::Context, label: &'static str) {
        let mark = StageMark { source: self.source, label, light: Some(self.light_index) };
        if let Some(h) = self.hook.as_deref_mut() {
            h.mark(gl, mark);
        }
    }

    /// The frame's depth convention (Standard or reversed-Z). Methods rarely need it: use
    /// [`VolumeFrame::far_clip_z`] and [`VolumeFrame::shadow_volume_state`]. A method that
    /// renders its own depth (shadow maps) into its own target may change glClipControl for
    /// that pass but must set it back for this convention before drawing to the frame's target.
    pub fn depth_convention(&self) -> DepthConvention {
        self.depth_convention
    }

    /// Whether `clip_from_world` is orthographic: its last row is exactly (0, 0, 0, 1) (clip w
    /// = 1 at every finite point), which no perspective matrix has.
    pub fn is_orthographic(&self) -> bool {
        self.clip_from_world.row(3) == glam::DVec4::new(0.0, 0.0, 0.0, 1.0)
    }

    /// The clip-space z, as a multiple of clip w, of the far plane: light caps are pushed there
    /// (paper 003, Eq. 6: `z = far_clip_z * w`). Shaders get it as the uniform `u_far_clip_z`
    /// (see methods/shared/depth.glsl): 1 under [`DepthConvention::Standard`] (depth 1), 0
    /// under [`DepthConvention::ReversedZ`] (depth exactly 0). Always use this, never a literal.
    pub fn far_clip_z(&self) -> f32 {
        self.depth_convention.far_clip_z()
    }

    /// The GL state of a counting pass (z-fail or z-pass per [`VolumeFrame::zpass`]) for this
    /// frame's depth convention and counter. [`Counter::Stencil8`]:
    /// [`crate::GlState::shadow_volume_for`] (depth func LESS under Standard, GREATER under
    /// ReversedZ, INCR_WRAP / DECR_WRAP); [`Counter::Float32`]:
    /// [`crate::GlState::shadow_volume_float_for`] (the fragment shader's `o_count` blended
    /// into the counter's R32F buffer). Counting methods apply exactly this, and their volume
    /// fragment shaders write `layout(location = 0) out float o_count = gl_FrontFacing ? 1.0 :
    /// -1.0`.
    pub fn shadow_volume_state(&self) -> crate::GlState {
        if let Some(state) = self.state_override {
            return state;
        }
        self.counter.shadow_volume_state(self.zpass, self.depth_convention)
    }

    /// Identifies the frame's visible samples (the depth buffer the method is called on): the
    /// renderer hands out a new value whenever that depth may have changed since its previous
    /// call — each frame of [`crate::Renderer::render`] / [`crate::Renderer::draw_frame`] (one
    /// depth pass for all its lights), each [`crate::Renderer::count_shadows`] call (the
    /// caller's depth). A method that derives data from the visible samples (hier-triangle's
    /// sample hierarchy) may reuse it for every light with the same serial.
    pub fn view_serial(&self) -> u64 {
        self.view_serial
    }

    /// The counter of this volume pass.
    pub fn counter(&self) -> Counter {
        self.counter
    }

    /// `clip_from_world` as column-major f32 for glUniformMatrix4fv.
    pub fn clip_from_world_f32(&self) -> [f32; 16] {
        crate::camera::to_f32_cols(&self.clip_from_world)
    }
}

/// One way of classifying pixels as shadowed for one light.
///
/// GL objects are created in [`ShadowMethod::prepare`] (the constructor touches no GL, so the
/// registry can build a method before a context exists) and freed in
/// [`ShadowMethod::destroy`].
pub trait ShadowMethod {
    /// Registry name (e.g. "cpu-silhouette").
    fn name(&self) -> &'static str;

    /// Stage labels this method reports through [`VolumeFrame::mark`], in order.
    fn stages(&self) -> &'static [&'static str];

    /// Once per mesh: preprocessing (adjacency, GPU buffers, programs). The renderer calls it
    /// whenever [`ShadowMethod::prepared_scene`] differs from the scene being drawn.
    fn prepare(&mut self, gl: &glow::Context, scene: &SceneGpu) -> Result<(), GlError>;

    /// The scene the last successful `prepare` was for.
    fn prepared_scene(&self) -> Option<SceneId>;

    /// Marks the stencil (or its own resources) for one light; see the module doc.
    fn draw_volumes(
        &mut self,
        gl: &glow::Context,
        scene: &SceneGpu,
        frame: &mut VolumeFrame<'_>,
    ) -> Result<(), GlError>;

    /// True when the method draws side faces only for edges of nonzero multiplicity (the
    /// silhouette methods): the auto z-pass test may then let edges of multiplicity 0 cross the
    /// eye's near pyramid ([`umbra_geom::clearance`]). Per-triangle volumes draw two coincident
    /// opposite faces there, which cancel in exact arithmetic but not after clipping near the eye
    /// (tests/auto_zpass.rs pins the wrong pixel ts-triangle gives under the loose test), so they keep the strict test.
    fn silhouette_sides(&self) -> bool {
        false
    }

    /// True (the default) when the method rasterizes shadow volumes into the stencil (counting,
    /// or its own stencil test): the renderer then chooses z-pass or z-fail (and the stencil's
    /// start value `W0`), the wide counter and the clip planes for it. False for a method that
    /// decides per sample some other way and writes its [`Classification::StencilZero`]
    /// decision into the stencil itself (hier-triangle, hier-silhouette): the stencil is
    /// cleared to 0 and no counting state, counter or clip plane is set up for it; it has no
    /// volumes to show as a wireframe either.
    fn fills_volumes(&self) -> bool {
        true
    }

    /// Whether the method draws orthographic views ([`umbra_geom::camera::Projection`]): false
    /// by default, and the renderer refuses such a frame with an error naming the method. A
    /// point at infinity has clip w = 0 under an orthographic matrix, so volumes that run to
    /// infinity (the far plane at infinity of paper 003) cannot be drawn; a method that
    /// answers true closes its volumes at a finite distance ([`VolumeFrame::is_orthographic`],
    /// docs/exactness.md "Orthographic views") or draws no volumes.
    fn orthographic(&self) -> bool {
        false
    }

    /// How the lighting pass tests "lit".
    fn classification(&self) -> Classification {
        Classification::StencilZero
    }

    /// For [`Classification::Shader`]: GLSL 4.50 source (no `#version`) defining
    /// `bool umbra_lit(vec3 world_pos)`; appended to the lighting fragment shader.
    fn lighting_glsl(&self) -> Option<&'static str> {
        None
    }

    /// For [`Classification::Shader`]: binds what `umbra_lit` reads (uniforms on `program`,
    /// which is current, textures, buffers) before the lighting draw.
    fn bind_lighting(
        &mut self,
        _gl: &glow::Context,
        _program: glow::Program,
        _frame: &VolumeFrame<'_>,
    ) -> Result<(), GlError> {
        Ok(())
    }

    /// Whether the method culls and clamps its volumes against the light's receivers when
    /// [`VolumeFrame::volume_cull`] asks (docs/exactness.md, "Volumes clamped to their
    /// receivers"); false by default.
    fn culls_volumes(&self) -> bool {
        false
    }
    /// What the last [`ShadowMethod::draw_volumes`] drew (one light); `None` for methods that
    /// do not report it.
    fn drawn_volume(&self) -> Option<DrawnVolume> {
        None
    }
    /// [`ShadowMethod::drawn_volume`], or where only the GPU knows it, read back (a stall: the
    /// renderer asks only when it counts fragments).
    fn read_drawn_volume(&self, _gl: &glow::Context) -> Option<DrawnVolume> {
        self.drawn_volume()
    }
    /// Bytes of GPU memory the method holds (buffers, textures).
    fn gpu_bytes(&self) -> usize;

    /// Switches work counting on (the counts start from 0) or off. Methods without work counts
    /// ignore it (the default).
    fn set_count_work(&mut self, _on: bool) {}

    /// The work counted since counting was switched on (read back from the GPU: a stall, for
    /// benchmarks and tests); `None` for a method that does not count work.
    fn work_counts(&mut self, _gl: &glow::Context) -> Option<WorkCounts> {
        None
    }

    /// Figures of the method's per-scene preprocessing, `(key, value)`, that `umbra bench
    /// --json` adds to its rows (ray-bvh: `bvh_build_ms`, `bvh_bytes`, ...); none by default.
    fn scene_figures(&self) -> Vec<(&'static str, f64)> {
        Vec::new()
    }

    /// Frees the GL objects (context current); the method can be prepared again afterwards.
    fn destroy(&mut self, gl: &glow::Context);
}

/// What one light's volume pass drew ([`ShadowMethod::drawn_volume`]).
pub use umbra_geom::silhouette::DrawnVolume;
