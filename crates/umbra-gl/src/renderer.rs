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
//! Runs on a caller's `glow::Context` ([`Renderer::draw_frame`] into any framebuffer with a
//! depth-stencil attachment with 8 stencil bits) or into the renderer's own [`RenderTarget`]
//! with readback ([`Renderer::render`]). In both cases the state listed in [`crate::saved`]
//! (every [`GlState`] field, program, vertex array, framebuffer bindings, viewport, scissor and
//! rasterizer-discard enables, SSBO binding 0, clip control, depth range) is restored after the
//! frame. Not restored: what a shadow method binds besides program/vertex array (its own
//! buffer or texture bindings; cpu-silhouette uses direct state access and binds none); the
//! draw/read buffer selection of the framebuffer drawn into.

use std::collections::HashMap;
use std::sync::OnceLock;

use glow::HasContext;
use umbra_geom::Light;

use crate::camera::{to_f32_cols, Camera, DepthConvention};
use crate::error::{drain_get_error, GlError, GlErrorLog};
use crate::extra::GlExtra;
use crate::image::{LitMaskImage, RgbaImage, StencilImage, TriangleIdImage, WorldPosImage};
use crate::methods::{Classification, ShadowMethod, StageHook, StageMark, VolumeFrame};
use crate::program::{link_program, uniform, ShaderSource};
use crate::saved::SavedState;
use crate::scene::{SceneGpu, NORMALS_BINDING};
use crate::state::{BlendState, GlState, StencilFace};
use crate::target::{read_stencil, Attachments, RenderTarget, TargetPass};

const SCENE_VERT: &str = include_str!("shaders/scene.vert.glsl");
const DEPTH_FRAG: &str = include_str!("shaders/depth_ambient.frag.glsl");
const LIGHTING_FRAG: &str = include_str!("shaders/lighting.frag.glsl");

/// For which lights a per-light image is read back.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LightCapture {
    #[default]
    None,
    Light(usize),
    AllLights,
}

impl LightCapture {
    /// Whether light `light` is captured.
    pub fn includes(self, light: usize) -> bool {
        match self {
            LightCapture::None => false,
            LightCapture::Light(i) => i == light,
            LightCapture::AllLights => true,
        }
    }
}

/// Which per-light stencil masks to read back (after the method's volume pass, before
/// lighting).
pub type StencilCapture = LightCapture;
/// Which per-light lit masks to read back (after that light's lighting pass).
pub type LitMaskCapture = LightCapture;

/// Extra images [`Renderer::render`] reads back.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CaptureFlags {
    pub world_pos: bool,
    pub triangle_id: bool,
    pub stencil: StencilCapture,
    /// The renderer's final per-pixel decision "lit by this light" ([`LitMask`]): what the
    /// image shows, for every [`Classification`]. Own target only ([`Renderer::render`]).
    pub lit_mask: LitMaskCapture,
}

/// Everything that defines one frame.
#[derive(Clone, Debug, PartialEq)]
pub struct FrameParams {
    pub camera: Camera,
    pub width: u32,
    pub height: u32,
    /// Homogeneous lights: w = 1 point, w = 0 directional (light comes FROM xyz).
    pub lights: Vec<Light>,
    /// Colour (and intensity) of every light.
    pub light_color: [f32; 3],
    /// z-pass counting instead of z-fail (wrong when the camera is inside a shadow volume).
    pub zpass: bool,
    /// Ambient factor: pass 1 writes `albedo * ambient`.
    pub ambient: f32,
    /// Surface colour (all surfaces).
    pub albedo: [f32; 3],
    /// Blinn-Phong specular strength and exponent.
    pub specular: f32,
    pub shininess: f32,
    /// Clear colour (RGBA, 0..1).
    pub background: [f32; 4],
    pub capture: CaptureFlags,
    /// Depth convention of the frame (default [`DepthConvention::ReversedZ`]). It also picks
    /// the depth format of the renderer's own target; with [`Renderer::draw_frame`] the
    /// caller's framebuffer is drawn in it (reversed-Z is correct with any depth format but
    /// gains its precision only with a float one).
    pub depth_convention: DepthConvention,
}

impl Default for FrameParams {
    /// 1280x720, default camera, no lights, z-fail, light grey surfaces, ambient 0.15, white
    /// light, dark blue-grey background, reversed-Z.
    fn default() -> Self {
        Self {
            camera: Camera::default(),
            width: 1280,
            height: 720,
            lights: Vec::new(),
            light_color: [1.0; 3],
            zpass: false,
            ambient: 0.15,
            albedo: [0.8; 3],
            specular: 0.25,
            shininess: 32.0,
            background: [0.10, 0.12, 0.16, 1.0],
            capture: CaptureFlags::default(),
            depth_convention: DepthConvention::default(),
        }
    }
}

/// Per-light stencil mask after the volume pass.
#[derive(Clone, Debug, PartialEq)]
pub struct StencilMask {
    pub light: usize,
    pub image: StencilImage,
}

/// Per-light lit mask after that light's lighting pass: 1 where the pixel received the
/// light's diffuse and specular term (the classification passed AND the seen side of the
/// triangle faces the light), 0 elsewhere (shadowed, facing away, background).
#[derive(Clone, Debug, PartialEq)]
pub struct LitMask {
    pub light: usize,
    pub image: LitMaskImage,
}

/// What [`Renderer::render`] reads back; all images top row first.
#[derive(Clone, Debug, PartialEq)]
pub struct FrameImages {
    pub rgba: RgbaImage,
    pub world_pos: Option<WorldPosImage>,
    pub triangle_id: Option<TriangleIdImage>,
    /// In light order, one per captured light.
    pub stencil: Vec<StencilMask>,
    /// In light order, one per captured light.
    pub lit_masks: Vec<LitMask>,
}

/// Per-light images read during a frame.
#[derive(Default)]
struct Captured {
    stencil: Vec<StencilMask>,
    lit_masks: Vec<LitMask>,
}

struct DepthProgram {
    program: glow::Program,
    u_clip_from_world: Option<glow::UniformLocation>,
    u_ambient_color: Option<glow::UniformLocation>,
}

struct LightingProgram {
    program: glow::Program,
    u_clip_from_world: Option<glow::UniformLocation>,
    u_light: Option<glow::UniformLocation>,
    u_light_color: Option<glow::UniformLocation>,
    u_eye: Option<glow::UniformLocation>,
    u_albedo: Option<glow::UniformLocation>,
    u_specular: Option<glow::UniformLocation>,
    u_shininess: Option<glow::UniformLocation>,
}

impl LightingProgram {
    fn new(gl: &glow::Context, custom: Option<(&str, &str)>) -> Result<Self, GlError> {
        let (frag, defines, name) = match custom {
            Some((method, glsl)) => (format!("{LIGHTING_FRAG}\n{glsl}\n"), vec!["UMBRA_CUSTOM_LIT"], format!("lighting+{method}")),
            None => (LIGHTING_FRAG.to_string(), vec![], "lighting".to_string()),
        };
        let program = link_program(
            gl,
            &name,
            &[ShaderSource::vertex("shaders/scene.vert.glsl", SCENE_VERT), ShaderSource::fragment("shaders/lighting.frag.glsl", &frag)],
            &defines,
        )?;
        let u = |n| uniform(gl, program, n);
        Ok(Self {
            u_clip_from_world: u("u_clip_from_world"),
            u_light: u("u_light"),
            u_light_color: u("u_light_color"),
            u_eye: u("u_eye"),
            u_albedo: u("u_albedo"),
            u_specular: u("u_specular"),
            u_shininess: u("u_shininess"),
            program,
        })
    }
}

/// Where [`Renderer::draw_frame`] draws: a caller's framebuffer (None = default framebuffer)
/// of `FrameParams::width x height` with a depth-stencil attachment (8 stencil bits). Its
/// depth convention is [`FrameParams::depth_convention`].
#[derive(Clone, Copy, Debug, Default)]
pub struct FrameTarget {
    pub framebuffer: Option<glow::Framebuffer>,
}

/// The shadow-volume renderer. Holds programs and (for [`Renderer::render`]) an offscreen
/// target; delete with [`Renderer::destroy`].
pub struct Renderer {
    depth: DepthProgram,
    /// Key: "" for the stencil-classified program, else the method name.
    lighting: HashMap<&'static str, LightingProgram>,
    target: Option<RenderTarget>,
    error_log: Option<GlErrorLog>,
    /// glClipControl (for [`DepthConvention::ReversedZ`]).
    extra: GlExtra,
}

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

/// Checks parameters before any GL call.
fn validate(params: &FrameParams) -> Result<(), GlError> {
    params.camera.validate()?;
    if params.width == 0 || params.height == 0 {
        return Err(GlError::InvalidParams(format!("frame size {}x{}", params.width, params.height)));
    }
    for (i, l) in params.lights.iter().enumerate() {
        if l.iter().any(|v| !v.is_finite()) || !(l[3] == 0.0 || l[3] == 1.0) {
            return Err(GlError::InvalidParams(format!("light {i} = {l:?}: expected finite xyz and w = 0 or 1")));
        }
        if l[3] == 0.0 && l[0] == 0.0 && l[1] == 0.0 && l[2] == 0.0 {
            return Err(GlError::InvalidParams(format!("light {i} is directional with a zero direction")));
        }
    }
    for (what, capture) in [("stencil", params.capture.stencil), ("lit mask", params.capture.lit_mask)] {
        if let LightCapture::Light(i) = capture {
            if i >= params.lights.len() {
                return Err(GlError::InvalidParams(format!("{what} capture of light {i}, but {} light(s)", params.lights.len())));
            }
        }
    }
    let scalars = [params.ambient, params.specular, params.shininess];
    if scalars.iter().chain(&params.albedo).chain(&params.light_color).chain(&params.background).any(|v| !v.is_finite()) {
        return Err(GlError::InvalidParams("non-finite colour or shading parameter".into()));
    }
    Ok(())
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
        let program = link_program(
            gl,
            "depth+ambient",
            &[
                ShaderSource::vertex("shaders/scene.vert.glsl", SCENE_VERT),
                ShaderSource::fragment("shaders/depth_ambient.frag.glsl", DEPTH_FRAG),
            ],
            &[],
        )?;
        let depth = DepthProgram {
            u_clip_from_world: uniform(gl, program, "u_clip_from_world"),
            u_ambient_color: uniform(gl, program, "u_ambient_color"),
            program,
        };
        let mut lighting = HashMap::new();
        lighting.insert("", LightingProgram::new(gl, None)?);
        Ok(Self { depth, lighting, target: None, error_log: None, extra: extra_from_current_egl() })
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
        let reuse = self
            .target
            .as_ref()
            .is_some_and(|t| t.width() == params.width && t.height() == params.height && t.attachments().covers(&wanted));
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
        let result = self.frame_on(gl, scene, method, params, Some(target.framebuffer()), Some(&target), hook, &mut captured);
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
    /// which reads the caller's stencil (returned per captured light).
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
        if !self.supports(params.depth_convention) {
            return Err(GlError::InvalidParams(format!(
                "depth convention {:?} needs glClipControl (GL 4.5 / ARB_clip_control), which this renderer has not \
                 loaded: give it one with Renderer::with_extra(GlExtra::load(..)) or use DepthConvention::Standard",
                params.depth_convention
            )));
        }
        let saved = SavedState::capture(gl);
        let result = self.passes(gl, scene, method, params, fb, own, hook, captured);
        saved.restore(gl, &self.extra);
        // A GL error is a failure even if the passes returned Ok.
        let checked = self.check_errors(gl, "frame");
        result.and(checked)
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

    fn lighting_program(&mut self, gl: &glow::Context, method: &dyn ShadowMethod) -> Result<&LightingProgram, GlError> {
        let key = match method.classification() {
            Classification::Shader => method.name(),
            _ => "",
        };
        if !self.lighting.contains_key(key) {
            let glsl = method.lighting_glsl().ok_or_else(|| GlError::Unsupported {
                method: method.name(),
                reason: "Classification::Shader without lighting_glsl()".into(),
            })?;
            let p = LightingProgram::new(gl, Some((method.name(), glsl)))?;
            self.lighting.insert(key, p);
        }
        self.lighting
            .get(key)
            .ok_or_else(|| GlError::InvalidParams("lighting program missing".into()))
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
        let convention = params.depth_convention;
        self.set_depth_convention(gl, convention)?;
        let aspect = params.width as f64 / params.height as f64;
        let clip_from_world = params.camera.clip_from_world_in(aspect, convention);
        let clip_f32 = to_f32_cols(&clip_from_world);
        let eye = params.camera.eye;
        let (w, h) = (params.width as i32, params.height as i32);
        let bind_target = |gl: &glow::Context| {
            // SAFETY: binding the frame's framebuffer and setting the viewport.
            unsafe {
                gl.bind_framebuffer(glow::DRAW_FRAMEBUFFER, fb);
                gl.viewport(0, 0, w, h);
            }
        };

        mark(&mut hook, gl, "depth", None);
        // Reason: glClear* obeys the colour/depth/stencil write masks; GL's default state has
        // all of them on (and blending/tests do not affect clears).
        GlState::default().apply(gl);
        bind_target(gl);
        // SAFETY: disabling enables that would restrict clears and draws (restored by the
        // caller's SavedState), then clearing the bound framebuffer.
        unsafe {
            gl.disable(glow::SCISSOR_TEST);
            gl.disable(glow::RASTERIZER_DISCARD);
            // Reason: depth cleared to the far plane's depth (1 Standard, 0 reversed-Z), which is
            // also where light caps are pushed (so they fail the strict test there too).
            let far = convention.far_depth();
            match own {
                Some(t) => t.clear(gl, params.background, far),
                None => {
                    gl.clear_buffer_f32_slice(glow::COLOR, 0, &params.background);
                    gl.clear_buffer_depth_stencil(glow::DEPTH_STENCIL, 0, far, 0);
                }
            }
        }

        // ---- Pass 1: depth + ambient (+ world position, triangle id).
        if let Some(t) = own {
            t.set_draw_buffers(gl, TargetPass::Depth);
        }
        GlState {
            // Reason: nearest surface wins: strictly nearer (LESS Standard, GREATER reversed-Z,
            // where depth = near / distance grows towards the eye); ties keep the first triangle
            // drawn (strict, not LEQUAL / GEQUAL), the same one the lighting pass selects.
            depth_test: true,
            depth_func: convention.nearer(),
            depth_write: true,
            // Reason: the scene uses normal near clipping; only volumes need clamping.
            depth_clamp: false,
            // Reason: the stencil belongs to the per-light volume passes.
            stencil_test: false,
            stencil_front: StencilFace::KEEP,
            stencil_back: StencilFace::KEEP,
            color_write: [true; 4],
            // Reason: triangle soups are two-sided; every triangle is visible from both sides.
            cull_face: None,
            front_face: glow::CCW,
            // Reason: opaque ambient base colour.
            blend: None,
            // Reason: depths must match the lighting pass and the volumes exactly.
            polygon_offset: None,
        }
        .apply(gl);
        let ambient = params.albedo.map(|a| a * params.ambient);
        // SAFETY: our program and the scene's VAO; uniforms match the shader declarations.
        unsafe {
            gl.use_program(Some(self.depth.program));
            gl.uniform_matrix_4_f32_slice(self.depth.u_clip_from_world.as_ref(), false, &clip_f32);
            gl.uniform_3_f32_slice(self.depth.u_ambient_color.as_ref(), &ambient);
            gl.bind_vertex_array(Some(scene.vertex_array()));
        }
        scene.draw_triangles(gl);

        for (light_index, &light) in params.lights.iter().enumerate() {
            // ---- Pass 2: shadow volumes into a cleared stencil.
            mark(&mut hook, gl, "volumes", Some(light_index));
            // Reason: the stencil clear obeys the stencil write mask; default = all bits.
            GlState::default().apply(gl);
            bind_target(gl);
            // SAFETY: clears the stencil of the bound draw framebuffer.
            unsafe { gl.clear_buffer_i32_slice(glow::STENCIL, 0, &[0]) };
            {
                let mut frame = VolumeFrame {
                    clip_from_world,
                    eye,
                    light,
                    light_index,
                    zpass: params.zpass,
                    width: params.width,
                    height: params.height,
                    target_framebuffer: fb,
                    depth_convention: convention,
                    source: method.name(),
                    // Re-borrow with a shorter trait-object lifetime (an Option blocks the
                    // automatic coercion).
                    hook: match hook.as_mut() {
                        Some(h) => Some(&mut **h as &mut dyn StageHook),
                        None => None,
                    },
                };
                method.draw_volumes(gl, scene, &mut frame)?;
            }
            // The method may have bound other framebuffers (shadow maps) or changed the clip
            // control for its own depth pass: re-bind ours, re-set the convention.
            bind_target(gl);
            self.set_depth_convention(gl, convention)?;
            if params.capture.stencil.includes(light_index) {
                captured
                    .stencil
                    .push(StencilMask { light: light_index, image: read_stencil(gl, fb, params.width, params.height) });
            }
            // Lit mask of this light: own target only, cleared right before its lighting pass.
            let lit_mask = own.filter(|t| t.attachments().lit_mask && params.capture.lit_mask.includes(light_index));
            if let Some(t) = lit_mask {
                // Reason: the clear obeys the colour write mask, which the method may have
                // turned off; GL's default state has it on.
                GlState::default().apply(gl);
                t.clear_lit_mask(gl);
            }

            // ---- Pass 3: lighting where lit.
            mark(&mut hook, gl, "lighting", Some(light_index));
            let classification = method.classification();
            let one_per_pixel = StencilFace {
                // Reason: lit where the count is 0 (or, for Shader classification, where no
                // fragment of this light has been shaded yet: the method leaves the cleared 0).
                func: glow::EQUAL,
                reference: 0,
                value_mask: 0xFF,
                write_mask: 0xFF,
                stencil_fail: glow::KEEP,
                depth_fail: glow::KEEP,
                // Reason: the first fragment shaded at a pixel bumps the stencil to 1, so a
                // coplanar duplicate triangle at the same depth (common in soups) cannot add
                // this light a second time. The stencil is cleared before the next light.
                depth_pass: glow::INCR_WRAP,
            };
            let stencil_face = match classification {
                Classification::StencilZero | Classification::Shader => one_per_pixel,
                Classification::StencilTest { func, reference, value_mask } => StencilFace {
                    // Reason: the method's own "lit" test; its stencil encoding is unknown to
                    // us, so nothing is written (coplanar duplicates may add light twice).
                    func,
                    reference,
                    value_mask,
                    write_mask: 0,
                    stencil_fail: glow::KEEP,
                    depth_fail: glow::KEEP,
                    depth_pass: glow::KEEP,
                },
            };
            if let Some(t) = own {
                // Colour (and the lit mask when captured): pass 3 must not touch world
                // position / triangle id.
                t.set_draw_buffers(gl, TargetPass::Lighting { lit_mask: lit_mask.is_some() });
            }
            GlState {
                // Reason: shade exactly the surface pass 1 left visible: the same invariant
                // vertex shader gives bit-identical depths, EQUAL selects them (in either depth
                // convention).
                depth_test: true,
                depth_func: glow::EQUAL,
                // Reason: depth is final after pass 1.
                depth_write: false,
                // Reason: same clipping as pass 1, or depths could differ near the near plane.
                depth_clamp: false,
                stencil_test: true,
                stencil_front: stencil_face,
                stencil_back: stencil_face,
                // Reason: alpha keeps pass 1's coverage value 1.
                color_write: [true, true, true, false],
                // Reason: two-sided surfaces, as in pass 1.
                cull_face: None,
                front_face: glow::CCW,
                // Reason: each light adds its diffuse + specular onto ambient + earlier lights.
                // On the R8 lit mask (draw buffer 3) the same blend is min(1, dst + src) with
                // src in {0, 1}: an OR, so a second fragment of a pixel cannot clear the bit.
                blend: Some(BlendState::ADDITIVE),
                polygon_offset: None,
            }
            .apply(gl);
            let p = self.lighting_program(gl, method)?;
            // SAFETY: our program, the scene's VAO and normal SSBO; uniforms match the shader.
            unsafe {
                gl.use_program(Some(p.program));
                gl.uniform_matrix_4_f32_slice(p.u_clip_from_world.as_ref(), false, &clip_f32);
                gl.uniform_4_f32_slice(p.u_light.as_ref(), &light);
                gl.uniform_3_f32_slice(p.u_light_color.as_ref(), &params.light_color);
                gl.uniform_3_f32_slice(p.u_eye.as_ref(), &eye.map(|v| v as f32));
                gl.uniform_3_f32_slice(p.u_albedo.as_ref(), &params.albedo);
                gl.uniform_1_f32(p.u_specular.as_ref(), params.specular);
                gl.uniform_1_f32(p.u_shininess.as_ref(), params.shininess);
                gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, NORMALS_BINDING, Some(scene.normal_buffer()));
                gl.bind_vertex_array(Some(scene.vertex_array()));
            }
            if classification == Classification::Shader {
                let program = p.program;
                let frame = VolumeFrame {
                    clip_from_world,
                    eye,
                    light,
                    light_index,
                    zpass: params.zpass,
                    width: params.width,
                    height: params.height,
                    target_framebuffer: fb,
                    depth_convention: convention,
                    source: method.name(),
                    hook: None,
                };
                method.bind_lighting(gl, program, &frame)?;
            }
            scene.draw_triangles(gl);
            if let Some(t) = lit_mask {
                if let Some(image) = t.read_lit_mask(gl) {
                    captured.lit_masks.push(LitMask { light: light_index, image });
                }
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
    }
}
