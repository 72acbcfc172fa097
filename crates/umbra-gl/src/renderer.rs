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
//! Depth convention ([`DepthConvention`], [`FrameParams::depth_convention`]): reversed-Z by
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
//! `umbra_lit` into the stencil), add_light `lighting_pass` alone. Files: `renderer/params.rs`
//! ([`FrameParams`]), `renderer/validate.rs` (the checks before drawing), `renderer/depth.rs`
//! (`depth_pass`), `renderer/volumes.rs` (`volume_pass`), `renderer/lighting.rs`
//! (`lighting_pass`), `renderer/wireframe.rs`.

use std::collections::HashMap;
use std::sync::OnceLock;

use glam::DMat4;
use glow::HasContext;
use umbra_geom::Light;

mod depth;
mod lighting;
mod params;
mod validate;
mod volumes;
mod wireframe;

pub use params::FrameParams;
use validate::{check_stencil_target, validate, validate_shading, validate_view};

use depth::DepthProgram;
use lighting::{LightingProgram, LitPass};

use crate::camera::{to_f32_cols, DepthConvention, DepthConventionGl};
use crate::counter::{Counter, FloatCounter};
use crate::error::{drain_get_error, GlError, GlErrorLog};
use crate::extra::GlExtra;
use crate::image::StencilImage;
use crate::methods::{Classification, ShadowMethod, StageHook, StageMark, VolumeFrame};
use crate::saved::{MethodBindings, SavedState};
use crate::scene::SceneGpu;
use crate::state::GlState;
use crate::target::{read_stencil, Attachments, RenderTarget, TargetPass};
use umbra_geom::camera::near_pyramid_points;

pub(crate) const SCENE_VERT: &str = include_str!("shaders/scene.vert.glsl");

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

/// What the passes of one frame share, derived once from its [`FrameParams`] and target.
struct PassView {
    /// Camera clip space from world space in the frame's depth convention.
    clip_from_world: DMat4,
    /// The same, as f32 columns for the shaders.
    clip_f32: [f32; 16],
    /// Its inverse (the near-plane corners, the scene clip planes in clip space).
    world_from_clip: DMat4,
    /// The eye and the near-plane corners the auto z-pass test uses (per frame, any light).
    near_pyramid: Vec<[f64; 3]>,
    eye: [f64; 3],
    convention: DepthConvention,
    /// The framebuffer drawn into (None = default framebuffer).
    fb: Option<glow::Framebuffer>,
    width: i32,
    height: i32,
    /// [`VolumeFrame::view_serial`]: new whenever the depth may have changed.
    serial: u64,
}

impl PassView {
    /// The [`VolumeFrame`] a method gets for `light` in this view: drawn into the view's
    /// framebuffer, 8-bit stencil counting, no state override, no hook (the volume pass sets
    /// those it needs).
    fn volume_frame(
        &self,
        params: &FrameParams,
        light: Light,
        light_index: usize,
        source: &'static str,
    ) -> VolumeFrame<'static> {
        VolumeFrame {
            clip_from_world: self.clip_from_world,
            eye: self.eye,
            light,
            light_index,
            zpass: params.zpass,
            width: params.width,
            height: params.height,
            target_framebuffer: self.fb,
            depth_convention: self.convention,
            counter: Counter::Stencil8,
            state_override: None,
            view_serial: self.serial,
            source,
            hook: None,
        }
    }

    fn new(params: &FrameParams, fb: Option<glow::Framebuffer>, serial: u64) -> Self {
        let convention = params.depth_convention;
        let aspect = params.width as f64 / params.height as f64;
        let clip_from_world = params.camera.clip_from_world_in(aspect, convention);
        let world_from_clip = clip_from_world.inverse();
        Self {
            clip_f32: to_f32_cols(&clip_from_world),
            near_pyramid: near_pyramid_points(&world_from_clip, params.camera.eye, convention),
            world_from_clip,
            clip_from_world,
            eye: params.camera.eye,
            convention,
            fb,
            width: params.width as i32,
            height: params.height as i32,
            serial,
        }
    }

    /// Binds the frame's framebuffer for drawing and sets the viewport to the whole frame.
    fn bind_target(&self, gl: &glow::Context) {
        // SAFETY: binding the frame's framebuffer and setting the viewport.
        unsafe {
            gl.bind_framebuffer(glow::DRAW_FRAMEBUFFER, self.fb);
            gl.viewport(0, 0, self.width, self.height);
        }
    }
}

/// The shadow-volume renderer. Holds programs and (for [`Renderer::render`]) an offscreen
/// target; delete with [`Renderer::destroy`].
pub struct Renderer {
    depth: DepthProgram,
    /// Key: ("", Shade) for the stencil-classified program, else the method name and pass.
    lighting: HashMap<(&'static str, LitPass), LightingProgram>,
    target: Option<RenderTarget>,
    error_log: Option<GlErrorLog>,
    /// glClipControl (for [`DepthConvention::ReversedZ`]).
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
}

/// Binding point of the uniform block `UmbraSceneClip` (methods/shared/depth.glsl).
pub const SCENE_CLIP_BINDING: u32 = 14;

/// Entry points through EGL when the current context is an EGL context (then
/// eglGetProcAddress is valid for it); empty otherwise (no EGL, or another window system).
fn extra_from_current_egl() -> GlExtra {
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

fn mark(hook: &mut Option<&mut dyn StageHook>, gl: &glow::Context, label: &'static str, light: Option<usize>) {
    if let Some(h) = hook.as_deref_mut() {
        h.mark(gl, StageMark { source: "renderer", label, light });
    }
}

impl Renderer {
    /// Compiles the depth/ambient and lighting programs (GL 4.5 core context current).
    ///
    /// glClipControl (needed for [`DepthConvention::ReversedZ`], the default) is loaded
    /// through EGL when the current context is an EGL context, as with
    /// [`crate::HeadlessContext`]; on other hosts pass it with [`Renderer::with_extra`] (or
    /// draw with [`DepthConvention::Standard`]).
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
        })
    }

    /// Uses these entry points (glClipControl) instead of the ones found at [`Renderer::new`],
    /// e.g. `GlExtra::load(loader)` with your window system's loader, or
    /// [`crate::HeadlessContext::extra`].
    pub fn with_extra(mut self, extra: GlExtra) -> Self {
        self.extra = extra;
        self
    }

    /// Whether frames in `convention` can be drawn: Standard always, ReversedZ when
    /// glClipControl is loaded.
    pub fn supports(&self, convention: DepthConvention) -> bool {
        convention == DepthConvention::Standard || self.extra.has_clip_control()
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

    /// Counts `light`'s shadow volumes into the stencil of a caller's framebuffer whose depth
    /// already holds the caller's scene — umbra inside someone else's renderer (issue 9 §1):
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
    /// rendered with glClipControl(LOWER_LEFT, [`DepthConvention::clip_depth_mode`]) and
    /// glDepthRange(0, 1), and the depth cleared to [`DepthConvention::far_depth`]. Other
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
    /// **GL state**: saved before and restored after, exactly: every [`GlState`] field
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
    fn begin_on_target(
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

    /// Err unless frames in `convention` can be drawn ([`Renderer::supports`]).
    fn check_convention(&self, convention: DepthConvention) -> Result<(), GlError> {
        if self.supports(convention) {
            return Ok(());
        }
        Err(GlError::InvalidParams(format!(
            "depth convention {convention:?} needs glClipControl (GL 4.5 / ARB_clip_control), which this renderer has \
             not loaded: give it one with Renderer::with_extra(GlExtra::load(..)) or use DepthConvention::Standard"
        )))
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

    /// glClipControl and glDepthRange for `convention` (restored by SavedState).
    fn set_depth_convention(&self, gl: &glow::Context, convention: DepthConvention) -> Result<(), GlError> {
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
    }

    /// Per light of the last frame (or [`Renderer::count_shadows`] call: one entry), whether
    /// its volumes were counted z-pass (forced by [`FrameParams::zpass`], or chosen by
    /// [`FrameParams::auto_zpass`]) rather than z-fail.
    pub fn last_zpass(&self) -> &[bool] {
        &self.last_zpass
    }
}
