//! The multi-pass stencil shadow-volume frame (Heidmann 1991; Everitt & Kilgard 2002 §2):
//!
//! 1. once per frame: clear, then depth + ambient (+ world position and triangle id when
//!    captured) with normal clipping;
//! 2. per light: clear the stencil to 0, let the [`ShadowMethod`] mark it (z-fail volumes by
//!    default, z-pass on request);
//! 3. per light: add diffuse + specular where the method's classification says "lit" AND the
//!    side of the triangle the camera sees faces the light, depth func EQUAL, no depth writes,
//!    additive blending; when asked, the same shader writes that decision into the lit mask.
//!
//! Depth convention ([`DepthConvention`](crate::camera::DepthConvention), [`FrameParams::depth_convention`]): reversed-Z by
//! default — glClipControl(LOWER_LEFT, ZERO_TO_ONE) for the frame, infinite reversed
//! projection (depth = near / distance, exactly 0 at infinity), depth cleared to 0, nearer =
//! GREATER, and a DEPTH32F_STENCIL8 buffer in the renderer's own target. The numbers behind it
//! are in [`crate::camera`]: a volume side meeting a surface at a shallow angle compares
//! against that surface's depth correctly only as far as depth resolves distance, ~d * 2^-24
//! with float reversed-Z against d^2 / (n * 2^24) with 24-bit standard depth. The standard
//! convention stays available (and needs no glClipControl).
//!
//! Runs on a caller's `glow::Context`, three ways:
//! * [`Renderer::render`]: the whole frame into the renderer's own [`RenderTarget`], with
//!   readback;
//! * [`Renderer::draw_frame`]: the whole frame (umbra's own depth pass included) into a
//!   caller's framebuffer with a depth-stencil attachment with 8 stencil bits;
//! * inside a caller's renderer, light by light: [`Renderer::count_shadows`] counts one light's
//!   volumes into the stencil of a framebuffer whose depth the caller drew (depth and colour
//!   untouched) and returns what "lit" means there; the caller's lighting pass tests it, or
//!   [`Renderer::add_light`] runs umbra's.
//!
//! Every entry point restores the state listed in `saved.rs` (every [`GlState`] field,
//! program, vertex array, framebuffer bindings, viewport, scissor and rasterizer-discard
//! enables, SSBO binding 0, clip control, depth range) and what a shadow method may bind on
//! top (SSBO bindings 1-7, ARRAY / COPY_READ / DRAW_INDIRECT / DISPATCH_INDIRECT buffer bindings, PATCH_VERTICES,
//! the active texture unit and unit 0's 2D and cube-map textures). Not restored: the
//! draw/read buffer selection of a framebuffer [`Renderer::render`] or
//! [`Renderer::draw_frame`] draws into (count_shadows and add_light never change it).
//!
//! Code layout: [`Renderer::render`] / [`Renderer::draw_frame`] run `passes`, which calls
//! `depth_pass` once and `volume_pass` + `lighting_pass` per light; count_shadows runs
//! `volume_pass` alone (plus, for shader-classified methods, a resolve of the method's
//! `umbra_lit` into the stencil), add_light `lighting_pass` alone. Files: `renderer/view.rs`
//! (what the passes of a frame share), `renderer/validate.rs` (the checks before drawing),
//! `renderer/convention.rs` (glClipControl and glDepthRange), `renderer/depth.rs`
//! (`depth_pass`), `renderer/volumes.rs` (`volume_pass`), `renderer/lighting.rs`
//! (`lighting_pass`), `renderer/host.rs` (count_shadows, add_light), `renderer/wireframe.rs`.
//! The frame's parameters are [`FrameParams`], umbra-geom's, shared with umbra-wgpu.

use std::collections::HashMap;

use glow::HasContext;

mod convention;
mod depth;
mod fragments;
mod host;
mod lighting;
mod validate;
mod view;
mod volumes;
mod wireframe;

use convention::extra_from_current_egl;
use depth::DepthProgram;
use lighting::{LightingProgram, LitPass};
use validate::validate;
use view::{mark, PassView};

use crate::camera::DepthConventionGl;
use crate::counter::FloatCounter;
use crate::error::{drain_get_error, GlError, GlErrorLog};
use crate::extra::GlExtra;
use crate::image::StencilImage;
use crate::methods::DrawnVolume;
use crate::methods::{ShadowMethod, StageHook};
use crate::saved::{MethodBindings, SavedState};
use crate::scene::SceneGpu;
use crate::state::GlState;
use crate::target::{read_stencil, Attachments, RenderTarget, TargetPass};

pub use crate::scene::SCENE_CLIP_BINDING;
pub use fragments::VolumeFragmentQuery;
pub use umbra_geom::frame::{FrameParams, Receivers};
pub use umbra_geom::frame_images::{CaptureFlags, FrameImages, LightCapture, LitMask, StencilMask};

/// Which per-light stencil masks to read back (after the method's volume pass, before
/// lighting).
pub type StencilCapture = LightCapture;
/// Which per-light lit masks to read back (after that light's lighting pass).
pub type LitMaskCapture = LightCapture;

/// Per-light images read during a frame.
#[derive(Default)]
struct Captured {
    stencil: Vec<StencilMask>,
    lit_masks: Vec<LitMask>,
}

/// Where [`Renderer::draw_frame`] draws: a caller's framebuffer (None = default framebuffer)
/// of `FrameParams::width x height` with a depth-stencil attachment (8 stencil bits). Its
/// depth convention is [`FrameParams::depth_convention`].
#[derive(Clone, Copy, Debug, Default)]
pub struct FrameTarget {
    /// The caller's framebuffer; None = the default framebuffer.
    pub framebuffer: Option<glow::Framebuffer>,
}

/// The shadow-volume renderer. Holds programs and (for [`Renderer::render`]) an offscreen
/// target; delete with [`Renderer::destroy`].
pub struct Renderer {
    depth: DepthProgram,
    /// Key: ("", Shade) for the stencil-classified program, else the method name and pass.
    lighting: HashMap<(&'static str, LitPass), LightingProgram>,
    target: Option<RenderTarget>,
    error_log: Option<GlErrorLog>,
    /// glClipControl (for [`DepthConvention::ReversedZ`](crate::camera::DepthConvention::ReversedZ)).
    extra: GlExtra,
    /// The wide counter's resources, made on the first [`Counter::Float32`] frame.
    counter: Option<FloatCounter>,
    /// Set only during [`Renderer::draw_volume_wireframe`]: the state every volume draw takes.
    volume_state_override: Option<GlState>,
    /// The uniform block `UmbraSceneClip` (methods/shared/depth.glsl): six clip-space planes.
    scene_clip: Option<glow::Buffer>,
    /// Per light of the last volume passes: counted z-pass ([`Renderer::last_zpass`]).
    last_zpass: Vec<bool>,
    /// The last [`VolumeFrame::view_serial`] handed out.
    view_serial: u64,
    /// Per light of the last volume passes: what the method drew ([`Renderer::last_drawn`]).
    last_drawn: Vec<Option<DrawnVolume>>,
    /// Count the fragments of every volume pass ([`Renderer::set_count_volume_fragments`]).
    count_volume_fragments: bool,
    /// The query object those counts use (made on first use).
    fragment_query: Option<glow::Query>,
    /// Its kind, chosen at the first counted pass ([`Renderer::volume_fragment_query`]).
    fragment_query_kind: Option<VolumeFragmentQuery>,
    /// Per light of the last volume passes: their fragment counts.
    last_volume_fragments: Vec<Option<u64>>,
}

impl Renderer {
    /// Compiles the depth/ambient and lighting programs (GL 4.5 core context current).
    ///
    /// glClipControl (needed for [`DepthConvention::ReversedZ`](crate::camera::DepthConvention::ReversedZ), the default) is loaded
    /// through EGL when the current context is an EGL context, as with
    /// [`crate::HeadlessContext`]; on other hosts pass it with [`Renderer::with_extra`] (or
    /// draw with [`DepthConvention::Standard`](crate::camera::DepthConvention::Standard)).
    pub fn new(gl: &glow::Context) -> Result<Self, GlError> {
        let depth = DepthProgram::new(gl)?;
        let mut lighting = HashMap::new();
        lighting.insert(("", LitPass::Shade), LightingProgram::new(gl, None, LitPass::Shade)?);
        Ok(Self {
            depth,
            lighting,
            target: None,
            error_log: None,
            extra: extra_from_current_egl(),
            counter: None,
            volume_state_override: None,
            scene_clip: None,
            last_zpass: Vec::new(),
            view_serial: 0,
            last_drawn: Vec::new(),
            count_volume_fragments: false,
            fragment_query: None,
            fragment_query_kind: None,
            last_volume_fragments: Vec::new(),
        })
    }

    /// Uses these entry points (glClipControl) instead of the ones found at [`Renderer::new`],
    /// e.g. `GlExtra::load(loader)` with your window system's loader, or
    /// [`crate::HeadlessContext::extra`].
    pub fn with_extra(mut self, extra: GlExtra) -> Self {
        self.extra = extra;
        self
    }

    /// Also fail frames on messages recorded by a KHR_debug callback
    /// ([`crate::HeadlessContext::error_log`] or your own [`GlErrorLog::install`]).
    /// Without it, frames still fail on `glGetError` codes.
    pub fn with_error_log(mut self, log: Option<GlErrorLog>) -> Self {
        self.error_log = log;
        self
    }

    /// The offscreen target of the last [`Renderer::render`].
    pub fn target(&self) -> Option<&RenderTarget> {
        self.target.as_ref()
    }

    /// Renders into the renderer's own target (recreated when the size or attachments
    /// change) and reads back colour and whatever `params.capture` asks for.
    pub fn render(
        &mut self,
        gl: &glow::Context,
        scene: &SceneGpu,
        method: &mut dyn ShadowMethod,
        params: &FrameParams,
        hook: Option<&mut dyn StageHook>,
    ) -> Result<FrameImages, GlError> {
        validate(params)?;
        let wanted = Attachments {
            world_pos: params.capture.world_pos,
            triangle_id: params.capture.triangle_id,
            lit_mask: params.capture.lit_mask != LightCapture::None,
            float_depth: params.depth_convention.depth_format() == glow::DEPTH32F_STENCIL8,
        };
        let reuse = self.target.as_ref().is_some_and(|t| {
            t.width() == params.width && t.height() == params.height && t.attachments().covers(&wanted)
        });
        if !reuse {
            if let Some(old) = self.target.take() {
                old.destroy(gl);
            }
            self.target = Some(RenderTarget::new(gl, params.width, params.height, wanted)?);
        }
        let Some(target) = self.target.take() else {
            return Err(GlError::InvalidParams("render target missing".into()));
        };
        let mut captured = Captured::default();
        let result =
            self.frame_on(gl, scene, method, params, Some(target.framebuffer()), Some(&target), hook, &mut captured);
        let images = result.map(|()| FrameImages {
            rgba: target.read_rgba(gl),
            world_pos: if params.capture.world_pos { target.read_world_pos(gl) } else { None },
            triangle_id: if params.capture.triangle_id { target.read_triangle_ids(gl) } else { None },
            stencil: captured.stencil,
            lit_masks: captured.lit_masks,
        });
        self.target = Some(target);
        // Readback errors (if any) count too.
        self.check_errors(gl, "readback")?;
        images
    }

    /// Convenience: renders and returns only light `light`'s stencil mask after its volume
    /// pass (depth pass + that light's volumes; the other lights are drawn as usual).
    pub fn render_stencil(
        &mut self,
        gl: &glow::Context,
        scene: &SceneGpu,
        method: &mut dyn ShadowMethod,
        params: &FrameParams,
        light: usize,
    ) -> Result<StencilImage, GlError> {
        let mut p = params.clone();
        p.capture.stencil = StencilCapture::Light(light);
        let mut images = self.render(gl, scene, method, &p, None)?;
        images
            .stencil
            .pop()
            .map(|m| m.image)
            .ok_or_else(|| GlError::InvalidParams(format!("no stencil captured for light {light}")))
    }

    /// Draws one frame into a caller's framebuffer (None = the default framebuffer). It must
    /// be `params.width x params.height` with a depth-stencil attachment with 8 stencil bits
    /// (DEPTH32F_STENCIL8 for reversed-Z precision; DEPTH24_STENCIL8 works in either
    /// convention) and should have a single draw buffer: draw buffer 0 receives the colour;
    /// further draw buffers would receive pass-1 outputs 1 (world position) and 2 (triangle
    /// id) and the lit-mask output 3, and are undefined after the lighting passes. Clears draw
    /// buffer 0, depth (to the convention's far value) and stencil, and leaves the depth
    /// buffer in `params.depth_convention`. glClipControl and glDepthRange are set for the
    /// frame and restored afterwards. `params.capture` is ignored except the stencil capture,
    /// which reads the caller's stencil (returned per captured light). A renderer that draws
    /// its own depth and lighting uses [`Renderer::count_shadows`] instead.
    pub fn draw_frame(
        &mut self,
        gl: &glow::Context,
        scene: &SceneGpu,
        method: &mut dyn ShadowMethod,
        params: &FrameParams,
        target: FrameTarget,
        hook: Option<&mut dyn StageHook>,
    ) -> Result<Vec<StencilMask>, GlError> {
        validate(params)?;
        let mut captured = Captured::default();
        self.frame_on(gl, scene, method, params, target.framebuffer, None, hook, &mut captured)?;
        Ok(captured.stencil)
    }

    /// Saves the caller's state, draws, restores, then fails on recorded GL errors.
    #[allow(clippy::too_many_arguments)]
    fn frame_on(
        &mut self,
        gl: &glow::Context,
        scene: &SceneGpu,
        method: &mut dyn ShadowMethod,
        params: &FrameParams,
        fb: Option<glow::Framebuffer>,
        own: Option<&RenderTarget>,
        hook: Option<&mut dyn StageHook>,
        captured: &mut Captured,
    ) -> Result<(), GlError> {
        self.check_convention(params.depth_convention)?;
        validate::check_projection(params, method)?;
        let saved = SavedState::capture(gl);
        let bindings = MethodBindings::capture(gl);
        let result = self.passes(gl, scene, method, params, fb, own, hook, captured);
        bindings.restore(gl);
        saved.restore(gl, &self.extra);
        // A GL error is a failure even if the passes returned Ok.
        let checked = self.check_errors(gl, "frame");
        result.and(checked)
    }

    /// A new [`VolumeFrame::view_serial`]: called once per depth buffer a method may see (each
    /// frame's depth pass, each call on a caller's depth). Unique in the process, so a method
    /// used by two renderers never mistakes one's samples for the other's.
    fn next_view_serial(&mut self) -> u64 {
        static SERIAL: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(1);
        self.view_serial = SERIAL.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        self.view_serial
    }

    /// Drains the debug log and glGetError; Err if anything was recorded.
    fn check_errors(&self, gl: &glow::Context, during: &'static str) -> Result<(), GlError> {
        let mut messages = self.error_log.as_ref().map(GlErrorLog::take).unwrap_or_default();
        messages.extend(drain_get_error(gl));
        if messages.is_empty() {
            Ok(())
        } else {
            Err(GlError::Gl { during, messages })
        }
    }

    /// The whole frame: depth + ambient once, then per light volumes and lighting.
    #[allow(clippy::too_many_arguments)]
    fn passes(
        &mut self,
        gl: &glow::Context,
        scene: &SceneGpu,
        method: &mut dyn ShadowMethod,
        params: &FrameParams,
        fb: Option<glow::Framebuffer>,
        own: Option<&RenderTarget>,
        mut hook: Option<&mut dyn StageHook>,
        captured: &mut Captured,
    ) -> Result<(), GlError> {
        if method.prepared_scene() != Some(scene.id()) {
            method.prepare(gl, scene)?;
        }
        self.set_depth_convention(gl, params.depth_convention)?;
        let view = PassView::new(params, fb, self.next_view_serial());
        self.depth_pass(gl, scene, params, &view, own, &mut hook);
        for (light_index, &light) in params.lights.iter().enumerate() {
            self.volume_pass(gl, scene, method, params, &view, light, light_index, &mut hook)?;
            if params.capture.stencil.includes(light_index) {
                captured
                    .stencil
                    .push(StencilMask { light: light_index, image: read_stencil(gl, fb, params.width, params.height) });
            }
            // Lit mask of this light: own target only, cleared right before its lighting pass.
            let lit_mask = own.filter(|t| t.attachments().lit_mask && params.capture.lit_mask.includes(light_index));
            let image =
                self.lighting_pass(gl, scene, method, params, &view, own, lit_mask, light, light_index, &mut hook)?;
            if let Some(image) = image {
                captured.lit_masks.push(LitMask { light: light_index, image });
            }
        }
        if let Some(t) = own {
            t.set_draw_buffers(gl, TargetPass::Depth);
        }
        mark(&mut hook, gl, "end", None);
        Ok(())
    }

    /// Deletes programs and the offscreen target.
    pub fn destroy(mut self, gl: &glow::Context) {
        // SAFETY: our own objects, not used afterwards.
        unsafe {
            gl.delete_program(self.depth.program);
            for (_, p) in self.lighting.drain() {
                gl.delete_program(p.program);
            }
        }
        if let Some(t) = self.target.take() {
            t.destroy(gl);
        }
        if let Some(c) = self.counter.take() {
            c.destroy(gl);
        }
        if let Some(b) = self.scene_clip.take() {
            // SAFETY: our own buffer.
            unsafe { gl.delete_buffer(b) };
        }
        if let Some(q) = self.fragment_query.take() {
            // SAFETY: our own query, not active.
            unsafe { gl.delete_query(q) };
        }
    }

    /// Per light of the last frame (or [`Renderer::count_shadows`] call: one entry), whether
    /// its volumes were counted z-pass (forced by [`FrameParams::zpass`], or chosen by
    /// [`FrameParams::auto_zpass`]) rather than z-fail.
    pub fn last_zpass(&self) -> &[bool] {
        &self.last_zpass
    }

    /// Per light of the last frame (or [`Renderer::count_shadows`] call), what the method
    /// drew ([`ShadowMethod::drawn_volume`]; `None` for methods that do not report it).
    pub fn last_drawn(&self) -> &[Option<DrawnVolume>] {
        &self.last_drawn
    }

    /// Counts the fragments every light's volume pass rasterizes from now on (or stops): one
    /// query around the method's [`ShadowMethod::draw_volumes`], of the kind
    /// [`Renderer::volume_fragment_query`] names: `GL_FRAGMENT_SHADER_INVOCATIONS`
    /// (ARB_pipeline_statistics_query) where offered — every volume fragment runs the fragment
    /// shader (the volume shaders write gl_FragDepth) — else `GL_SAMPLES_PASSED` (the samples
    /// that pass the depth and stencil tests: a lower bound). Reading the count waits for the
    /// pass: a stall, for benchmarks and tests. Not counted (`None`): methods that fill no
    /// volumes, the volume wireframe, OpenGL ES, and passes begun while a host's own query
    /// holds the target.
    pub fn set_count_volume_fragments(&mut self, on: bool) {
        self.count_volume_fragments = on;
    }

    /// Per light of the last frame, the fragments its volume pass rasterized, when counted
    /// ([`Renderer::set_count_volume_fragments`], methods that fill volumes only).
    pub fn last_volume_fragments(&self) -> &[Option<u64>] {
        &self.last_volume_fragments
    }
}
