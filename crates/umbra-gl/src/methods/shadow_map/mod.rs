//! `shadow-map-cube:RES`: the shadow-mapping baseline the papers measure shadow volumes against
//! (Williams 1978). Paper 003, Section 3.1, Tables 1-2: omnidirectional (cube) shadow maps of
//! 1K, 2K, 4K and 8K texels per face ("SM1" ... "SM8") against the vertex-shader silhouettes;
//! paper 001, Tables 6 and 8: "classic 8K shadow mapping".
//!
//! * Point light (w = 1): a `RES x RES x 6` GL_DEPTH_COMPONENT32F cube map centred on the light,
//!   one 90° face per major axis, stored as a 6-layer 2D array texture in GL's face order with
//!   GL's face selection (GL 4.5 §8.13, Table 8.19) done in the lookup shader (lit.glsl says
//!   why: one sampler type for both light kinds, one texture lookup per pixel on llvmpipe).
//!   Rendered either in ONE layered pass (an instanced
//!   geometry shader sends each triangle to the faces whose frustum it touches, `gl_Layer`) or
//!   in six passes, one per face ([`FacePasses`]; layered is the default, see `docs/benchmarks.md`
//!   for the measurement).
//! * Directional light (w = 0): one `RES x RES` depth map (a 1-layer 2D array), an orthographic
//!   projection along the light direction fitted to the scene's bounds ("one face's worth").
//!
//! Depth convention: REVERSED (larger = closer to the light) so a float depth buffer keeps
//! relative precision everywhere: cube faces store `n / d` (`d` = distance along the face's
//! axis, infinite far plane, near `n` = 1e-3 of the scene diagonal); the directional map stores
//! `(h - h_min) / (h_max - h_min)`, `h` = position along the direction towards the light. The
//! projection matrices produce exactly these window depths under the frame's glClipControl
//! depth mode ([`VolumeFrame::depth_convention`]: ZERO_TO_ONE under reversed-Z, where `n / d`
//! keeps full float precision; NEGATIVE_ONE_TO_ONE under the standard convention, where GL's
//! `(z / w + 1) / 2` rounds it to ~2^-24 absolute), and the pass sets glDepthRange(0, 1) and
//! restores the caller's range.
//!
//! Bias: constant + slope-scaled, applied while rendering the map with glPolygonOffset
//! (`-bias_slope`, `-bias_constant`: negative because reversed depth moves away from the light
//! towards 0). Lookup: hardware depth comparison (GL_COMPARE_REF_TO_TEXTURE, GL_GEQUAL) with
//! NEAREST filtering = a hard test; optional 3 x 3 PCF as a majority vote (lit.glsl), a
//! compile-time variant named `shadow-map-cube:RES+pcf` (the renderer caches one lighting
//! program per method name).
//!
//! Classification: [`Classification::Shader`]: `umbra_lit(world_pos)` in `lit.glsl`; the
//! stencil is not used. Not exact (aliasing, bias): `umbra_verify::must_be_exact` is false for
//! every name starting with "shadow-map".
//!
//! Names: `shadow-map-cube:RES[+pcf]` with RES texels per side (any positive integer; a RES above
//! GL_MAX_CUBE_MAP_TEXTURE_SIZE / GL_MAX_TEXTURE_SIZE fails in `prepare` with a clear
//! [`GlError::Unsupported`], and GL_OUT_OF_MEMORY while allocating is caught and reported as
//! [`GlError::OutOfMemory`] — llvmpipe refuses a texture above its size limit, e.g. a 16384 cube —
//! leaving nothing behind: the context stays usable, `tests/gl_failures.rs`). [`ShadowMapConfig`] carries bias and PCF options.
//!
//! Once per mesh: programs, scene bounds. Textures and framebuffers are allocated on first use
//! per light kind and kept. Per light per frame: clear + depth render (stage "shadow-map");
//! the comparison runs in the renderer's lighting pass.

use std::sync::Mutex;

use glam::{DMat4, DVec3};
use glow::HasContext;
use umbra_geom::{Aabb, Light};

use crate::camera::DepthConventionGl;
use crate::error::{drain_get_error, GlError};
use crate::methods::method::{Classification, ShadowMethod, VolumeFrame};
use crate::program::{link_program, uniform, ShaderSource};
use crate::scene::{SceneGpu, SceneId};
use crate::state::{GlState, StencilFace};

/// Name prefix of the family; a full name is `shadow-map-cube:RES`.
pub const PREFIX: &str = "shadow-map-cube";
/// The registered (listed) members: 1K and 2K per face.
pub const NAME_1024: &str = "shadow-map-cube:1024";
/// 2048 texels per face.
pub const NAME_2048: &str = "shadow-map-cube:2048";

/// Texture unit of the map in the lighting pass (`layout(binding = 0)` in lit.glsl).
pub const MAP_UNIT: u32 = 0;

use umbra_geom::shadow_map::map_clip_from_world;
/// The cube-map and directional-map math (pure, shared with umbra-wgpu), moved to umbra-geom;
/// re-exported under its old paths.
pub use umbra_geom::shadow_map::{face_clip_from_world, face_rows, map_from_world, parse_name, NEAR_FRACTION};

const DEPTH_VERT: &str = include_str!("depth.vert.glsl");
const DEPTH_GEOM: &str = include_str!("depth.geom.glsl");
const LIT_GLSL: &str = include_str!("lit.glsl");
const LIT_PCF_GLSL: &str = concat!("#define UMBRA_SM_PCF\n", include_str!("lit.glsl"));

/// How the six cube faces are rendered.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FacePasses {
    /// One draw: an instanced geometry shader (6 invocations) picks the faces, `gl_Layer`.
    Layered,
    /// Six draws, one per face, vertex shader only.
    SixPasses,
}

/// Everything that defines a shadow-map method.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadowMapConfig {
    /// Texels per side of each cube face (and of the directional map).
    pub resolution: u32,
    /// glPolygonOffset units (multiples of the depth buffer's smallest resolvable difference
    /// at the primitive's depth), pushing stored depths away from the light.
    pub bias_constant: f32,
    /// glPolygonOffset factor (multiple of the primitive's maximum depth slope per texel).
    pub bias_slope: f32,
    /// 3 x 3 percentage-closer filtering, majority vote.
    pub pcf: bool,
    /// Layered (one draw) or six passes.
    pub faces: FacePasses,
}

/// Default constant bias (polygon-offset units); see [`ShadowMapConfig::bias_constant`].
pub const DEFAULT_BIAS_CONSTANT: f32 = 4.0;
/// Default slope-scaled bias (polygon-offset factor).
pub const DEFAULT_BIAS_SLOPE: f32 = 1.5;

impl ShadowMapConfig {
    /// Default bias, no PCF, layered rendering.
    pub fn new(resolution: u32) -> Self {
        Self {
            resolution,
            bias_constant: DEFAULT_BIAS_CONSTANT,
            bias_slope: DEFAULT_BIAS_SLOPE,
            pcf: false,
            faces: FacePasses::Layered,
        }
    }

    /// Parses `shadow-map-cube:RES[+pcf]` (RES a positive decimal integer, optional `k` suffix =
    /// x1024, so `shadow-map-cube:8k` is 8192). `None` for any other name.
    pub fn from_name(name: &str) -> Option<Self> {
        let (resolution, pcf) = parse_name(name)?;
        Some(Self { pcf, ..Self::new(resolution) })
    }

    /// The registry name, `shadow-map-cube:RES`, or `shadow-map-cube:RES+pcf` with PCF (a
    /// different lighting shader, so a different name: the renderer caches one lighting
    /// program per name). Bias and face passes do not change the name.
    pub fn name(&self) -> &'static str {
        intern(format!("{PREFIX}:{}{}", self.resolution, if self.pcf { "+pcf" } else { "" }))
    }

    /// Bytes of a cube map (6 faces of 4-byte texels).
    pub fn cube_bytes(&self) -> usize {
        6 * self.map2d_bytes()
    }

    /// Bytes of the directional 2D map.
    pub fn map2d_bytes(&self) -> usize {
        4 * (self.resolution as usize) * (self.resolution as usize)
    }
}

/// Names must be `&'static str` ([`ShadowMethod::name`]); each distinct resolution's name is
/// leaked once and reused.
fn intern(name: String) -> &'static str {
    static NAMES: Mutex<Vec<&'static str>> = Mutex::new(Vec::new());
    let mut names = NAMES.lock().unwrap_or_else(|e| e.into_inner());
    if let Some(n) = names.iter().find(|n| **n == name) {
        return n;
    }
    let leaked: &'static str = Box::leak(name.into_boxed_str());
    names.push(leaked);
    leaked
}

fn f32_cols(m: &DMat4) -> [f32; 16] {
    m.to_cols_array().map(|v| v as f32)
}

struct Programs {
    layered: glow::Program,
    u_faces: Option<glow::UniformLocation>,
    single: glow::Program,
    u_single: Option<glow::UniformLocation>,
}

/// A depth texture and the framebuffers that render into it.
struct DepthMap {
    texture: glow::Texture,
    /// Cube: [layered, +X, -X, +Y, -Y, +Z, -Z]; 2D: [the map].
    framebuffers: Vec<glow::Framebuffer>,
    bytes: usize,
}

impl DepthMap {
    fn destroy(self, gl: &glow::Context) {
        // SAFETY: our own objects, not used afterwards.
        unsafe {
            for f in self.framebuffers {
                gl.delete_framebuffer(f);
            }
            gl.delete_texture(self.texture);
        }
    }
}

/// What the lighting pass needs about the map of the current light.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Lookup {
    Cube { light: [f32; 3], near: f32 },
    Directional { map_from_world: [f32; 16] },
}

struct LitUniforms {
    program: glow::Program,
    kind: Option<glow::UniformLocation>,
    light_pos: Option<glow::UniformLocation>,
    near: Option<glow::UniformLocation>,
    map_from_world: Option<glow::UniformLocation>,
    resolution: Option<glow::UniformLocation>,
}

/// See the module documentation.
pub struct ShadowMapCube {
    config: ShadowMapConfig,
    name: &'static str,
    prepared: Option<SceneId>,
    bounds: Aabb,
    programs: Option<Programs>,
    cube: Option<DepthMap>,
    map2d: Option<DepthMap>,
    lookup: Option<Lookup>,
    lit_uniforms: Option<LitUniforms>,
}

impl ShadowMapCube {
    /// Builds the method (no GL calls). `config.resolution` must be positive.
    pub fn new(config: ShadowMapConfig) -> Self {
        Self {
            name: config.name(),
            config,
            prepared: None,
            bounds: Aabb { min: [-1.0; 3], max: [1.0; 3] },
            programs: None,
            cube: None,
            map2d: None,
            lookup: None,
            lit_uniforms: None,
        }
    }

    /// `shadow-map-cube:RES` with default options; `None` for other names or a bad RES.
    pub fn from_name(name: &str) -> Option<Self> {
        ShadowMapConfig::from_name(name).map(Self::new)
    }

    /// The configuration it was made with.
    pub fn config(&self) -> &ShadowMapConfig {
        &self.config
    }

    /// Allocates `RES x RES` depth32F storage (6 faces for a cube) and its framebuffers;
    /// GL_OUT_OF_MEMORY becomes [`GlError::OutOfMemory`] and leaves nothing behind.
    fn allocate(&self, gl: &glow::Context, cube: bool) -> Result<DepthMap, GlError> {
        let res = i32::try_from(self.config.resolution)
            .map_err(|_| GlError::InvalidParams(format!("{}: resolution too large", self.name)))?;
        let bytes = if cube { self.config.cube_bytes() } else { self.config.map2d_bytes() };
        // SAFETY: DSA object creation, storage allocation and parameters on the current
        // context; every object is deleted on every error path.
        unsafe {
            // Errors recorded before this allocation are not ours: report them as they are
            // rather than mistaking them for an allocation failure.
            let earlier = drain_get_error(gl);
            if !earlier.is_empty() {
                return Err(GlError::Gl { during: "before shadow-map allocation", messages: earlier });
            }
            // A 2D array for both kinds (6 layers = cube faces, 1 layer = directional map).
            let texture = gl
                .create_named_texture(glow::TEXTURE_2D_ARRAY)
                .map_err(|detail| GlError::Create { what: "shadow-map texture", detail })?;
            // One level: the map is sampled with NEAREST at texel resolution, no mipmaps.
            gl.texture_storage_3d(texture, 1, glow::DEPTH_COMPONENT32F, res, res, if cube { 6 } else { 1 });
            let errors = drain_get_error(gl);
            if !errors.is_empty() {
                gl.delete_texture(texture);
                let what = if cube { format!("6 x {res}^2") } else { format!("{res}^2") };
                if errors.iter().any(|e| e.contains("OUT_OF_MEMORY")) {
                    return Err(GlError::OutOfMemory {
                        what: format!("the {what} depth32F shadow map of {}", self.name),
                        bytes,
                        messages: errors,
                    });
                }
                return Err(GlError::Unsupported {
                    method: self.name,
                    reason: format!(
                        "GL error allocating a {what} depth32F shadow map ({:.0} MiB): {}",
                        bytes as f64 / (1024.0 * 1024.0),
                        errors.join("; ")
                    ),
                });
            }
            // Reason: a hard test; NEAREST so exactly one texel decides (PCF is explicit).
            gl.texture_parameter_i32(texture, glow::TEXTURE_MIN_FILTER, glow::NEAREST as i32);
            gl.texture_parameter_i32(texture, glow::TEXTURE_MAG_FILTER, glow::NEAREST as i32);
            // Reason: lookups a rounding error outside a face/the map reuse the edge texel.
            for wrap in [glow::TEXTURE_WRAP_S, glow::TEXTURE_WRAP_T] {
                gl.texture_parameter_i32(texture, wrap, glow::CLAMP_TO_EDGE as i32);
            }
            // Reason: the shadow sampler compares in hardware: 1 (lit) when ref >= stored, the
            // reversed-depth "not farther than the closest occluder".
            gl.texture_parameter_i32(texture, glow::TEXTURE_COMPARE_MODE, glow::COMPARE_REF_TO_TEXTURE as i32);
            gl.texture_parameter_i32(texture, glow::TEXTURE_COMPARE_FUNC, glow::GEQUAL as i32);

            let mut framebuffers = Vec::new();
            let attachments: Vec<Option<i32>> =
                if cube { vec![None, Some(0), Some(1), Some(2), Some(3), Some(4), Some(5)] } else { vec![Some(0)] };
            let mut failure = None;
            for layer in attachments {
                let fb = match gl.create_named_framebuffer() {
                    Ok(f) => f,
                    Err(detail) => {
                        failure = Some(GlError::Create { what: "shadow-map framebuffer", detail });
                        break;
                    }
                };
                framebuffers.push(fb);
                match layer {
                    // Whole texture: layered, gl_Layer picks the face.
                    None => gl.named_framebuffer_texture(Some(fb), glow::DEPTH_ATTACHMENT, Some(texture), 0),
                    Some(face) => {
                        gl.named_framebuffer_texture_layer(Some(fb), glow::DEPTH_ATTACHMENT, Some(texture), 0, face)
                    }
                }
                // Depth only: no colour buffer to draw to or read from.
                gl.named_framebuffer_draw_buffer(Some(fb), glow::NONE);
                gl.named_framebuffer_read_buffer(Some(fb), glow::NONE);
                let status = gl.check_named_framebuffer_status(Some(fb), glow::DRAW_FRAMEBUFFER);
                if status != glow::FRAMEBUFFER_COMPLETE {
                    failure = Some(GlError::Framebuffer { status, what: "shadow-map depth framebuffer" });
                    break;
                }
            }
            let map = DepthMap { texture, framebuffers, bytes };
            match failure {
                Some(e) => {
                    map.destroy(gl);
                    Err(e)
                }
                None => Ok(map),
            }
        }
    }

    /// GL state of the depth pass; a reason for every field.
    fn depth_state(&self) -> GlState {
        GlState {
            // Reason: keep the occluder closest to the light per texel.
            depth_test: true,
            // Reason: reversed depth, larger = closer to the light.
            depth_func: glow::GREATER,
            depth_write: true,
            // Reason: an occluder nearer to the light than the near distance still occludes
            // everything behind it: clamped to depth 1 instead of being clipped away.
            depth_clamp: true,
            // Reason: no stencil in the map's framebuffer; the method does not use it.
            stencil_test: false,
            stencil_front: StencilFace::KEEP,
            stencil_back: StencilFace::KEEP,
            // Reason: depth-only framebuffer.
            color_write: [false; 4],
            // Reason: triangle soups are two-sided; either side of a triangle occludes.
            cull_face: None,
            // Reason: irrelevant without culling; GL's default.
            front_face: glow::CCW,
            // Reason: no colour written.
            blend: None,
            // Reason: the constant + slope-scaled bias against self-shadowing ("acne"),
            // negated because reversed depth moves AWAY from the light towards 0.
            polygon_offset: Some((-self.config.bias_slope, -self.config.bias_constant)),
        }
    }
}

impl ShadowMethod for ShadowMapCube {
    fn name(&self) -> &'static str {
        self.name
    }

    fn orthographic(&self) -> bool {
        // The maps are drawn from the light and looked up at each sample's world position:
        // the camera's projection takes no part.
        true
    }

    fn stages(&self) -> &'static [&'static str] {
        &["shadow-map"]
    }

    fn prepare(&mut self, gl: &glow::Context, scene: &SceneGpu) -> Result<(), GlError> {
        // SAFETY: integer queries on the current context.
        let (max_cube, max_2d) = unsafe {
            (gl.get_parameter_i32(glow::MAX_CUBE_MAP_TEXTURE_SIZE), gl.get_parameter_i32(glow::MAX_TEXTURE_SIZE))
        };
        let res = self.config.resolution;
        if i64::from(res) > i64::from(max_cube) || i64::from(res) > i64::from(max_2d) {
            return Err(GlError::Unsupported {
                method: self.name,
                reason: format!(
                    "resolution {res} exceeds GL_MAX_CUBE_MAP_TEXTURE_SIZE = {max_cube} / GL_MAX_TEXTURE_SIZE = {max_2d} of this GL"
                ),
            });
        }
        if self.programs.is_none() {
            let vert_layered = format!("#version 450 core\n#define UMBRA_SM_LAYERED\n{DEPTH_VERT}");
            let geom = format!("#version 450 core\n{DEPTH_GEOM}");
            let vert_single = format!("#version 450 core\n{DEPTH_VERT}");
            // No fragment shader: depth-only passes (GL 4.5 §15.2: without one, fragments keep
            // their rasterised depth and write nothing else).
            let layered = link_program(
                gl,
                "shadow-map layered depth",
                &[
                    ShaderSource::vertex("shadow_map/depth.vert.glsl", &vert_layered),
                    ShaderSource { stage: glow::GEOMETRY_SHADER, name: "shadow_map/depth.geom.glsl", source: &geom },
                ],
                &[],
            )?;
            let single = match link_program(
                gl,
                "shadow-map depth",
                &[ShaderSource::vertex("shadow_map/depth.vert.glsl", &vert_single)],
                &[],
            ) {
                Ok(p) => p,
                Err(e) => {
                    // SAFETY: our program, not used afterwards.
                    unsafe { gl.delete_program(layered) };
                    return Err(e);
                }
            };
            self.programs = Some(Programs {
                u_faces: uniform(gl, layered, "u_face_clip_from_world"),
                layered,
                u_single: uniform(gl, single, "u_light_clip_from_world"),
                single,
            });
        }
        self.bounds = scene.bounds().unwrap_or(Aabb { min: [-1.0; 3], max: [1.0; 3] });
        self.prepared = Some(scene.id());
        Ok(())
    }

    fn prepared_scene(&self) -> Option<SceneId> {
        self.prepared
    }

    fn draw_volumes(
        &mut self,
        gl: &glow::Context,
        scene: &SceneGpu,
        frame: &mut VolumeFrame<'_>,
    ) -> Result<(), GlError> {
        frame.mark(gl, "shadow-map");
        let light: Light = frame.light;
        let point = light[3] != 0.0;
        let missing = if point { self.cube.is_none() } else { self.map2d.is_none() };
        if missing {
            let map = self.allocate(gl, point)?;
            if point {
                self.cube = Some(map)
            } else {
                self.map2d = Some(map)
            }
        }
        let programs = self
            .programs
            .as_ref()
            .ok_or_else(|| GlError::InvalidParams(format!("{}: draw before prepare", self.name)))?;
        let map = if point { self.cube.as_ref() } else { self.map2d.as_ref() }
            .ok_or_else(|| GlError::InvalidParams("shadow map missing".into()))?;
        // The frame's glClipControl depth mode is in force for this pass too (we leave it as
        // it is); the matrices produce the same window depths under either mode.
        let zero_to_one = frame.depth_convention().clip_depth_mode() == glow::ZERO_TO_ONE;
        let res = self.config.resolution as i32;
        let mut saved_range = [0.0f32; 2];
        // SAFETY: query of the depth range on the current context.
        unsafe { gl.get_parameter_f32_slice(glow::DEPTH_RANGE, &mut saved_range) };
        self.depth_state().apply(gl);
        // SAFETY: our programs, framebuffers and the scene's VAO; uniforms match the shaders;
        // the draw covers the scene's index buffer exactly (3 indices per triangle).
        unsafe {
            // Reason: the window depths of the matrices assume the full [0, 1] range.
            gl.depth_range(0.0, 1.0);
            gl.viewport(0, 0, res, res);
            gl.bind_vertex_array(Some(scene.vertex_array()));
            let count = (scene.triangle_count() * 3) as i32;
            if point {
                let l = DVec3::new(f64::from(light[0]), f64::from(light[1]), f64::from(light[2]));
                let b = &self.bounds;
                let diagonal = f64::from(b.diagonal()).max(1e-6);
                let near = NEAR_FRACTION * diagonal;
                let faces: Vec<DMat4> = (0..6).map(|f| face_clip_from_world(f, l, near, zero_to_one)).collect();
                match self.config.faces {
                    FacePasses::Layered => {
                        let fb = map.framebuffers[0];
                        gl.bind_framebuffer(glow::DRAW_FRAMEBUFFER, Some(fb));
                        // Clear all six layers to 0 = infinitely far (reversed depth).
                        gl.clear_named_framebuffer_f32_slice(Some(fb), glow::DEPTH, 0, &[0.0]);
                        let flat: Vec<f32> = faces.iter().flat_map(f32_cols).collect();
                        gl.use_program(Some(programs.layered));
                        gl.uniform_matrix_4_f32_slice(programs.u_faces.as_ref(), false, &flat);
                        if count > 0 {
                            gl.draw_elements(glow::TRIANGLES, count, glow::UNSIGNED_INT, 0);
                        }
                    }
                    FacePasses::SixPasses => {
                        gl.use_program(Some(programs.single));
                        for (f, m) in faces.iter().enumerate() {
                            let fb = map.framebuffers[1 + f];
                            gl.bind_framebuffer(glow::DRAW_FRAMEBUFFER, Some(fb));
                            gl.clear_named_framebuffer_f32_slice(Some(fb), glow::DEPTH, 0, &[0.0]);
                            gl.uniform_matrix_4_f32_slice(programs.u_single.as_ref(), false, &f32_cols(m));
                            if count > 0 {
                                gl.draw_elements(glow::TRIANGLES, count, glow::UNSIGNED_INT, 0);
                            }
                        }
                    }
                }
                self.lookup = Some(Lookup::Cube { light: [light[0], light[1], light[2]], near: near as f32 });
            } else {
                let dir = DVec3::new(f64::from(light[0]), f64::from(light[1]), f64::from(light[2]));
                let m = map_from_world(dir, &self.bounds);
                let fb = map.framebuffers[0];
                gl.bind_framebuffer(glow::DRAW_FRAMEBUFFER, Some(fb));
                gl.clear_named_framebuffer_f32_slice(Some(fb), glow::DEPTH, 0, &[0.0]);
                gl.use_program(Some(programs.single));
                gl.uniform_matrix_4_f32_slice(
                    programs.u_single.as_ref(),
                    false,
                    &f32_cols(&map_clip_from_world(&m, zero_to_one)),
                );
                if count > 0 {
                    gl.draw_elements(glow::TRIANGLES, count, glow::UNSIGNED_INT, 0);
                }
                self.lookup = Some(Lookup::Directional { map_from_world: f32_cols(&m) });
            }
            gl.depth_range(f64::from(saved_range[0]), f64::from(saved_range[1]));
            // Back to the frame's target (the renderer re-binds it too).
            gl.bind_framebuffer(glow::DRAW_FRAMEBUFFER, frame.target_framebuffer);
            gl.viewport(0, 0, frame.width as i32, frame.height as i32);
        }
        Ok(())
    }

    fn classification(&self) -> Classification {
        Classification::Shader
    }

    fn lighting_glsl(&self) -> Option<&'static str> {
        Some(if self.config.pcf { LIT_PCF_GLSL } else { LIT_GLSL })
    }

    fn bind_lighting(
        &mut self,
        gl: &glow::Context,
        program: glow::Program,
        _frame: &VolumeFrame<'_>,
    ) -> Result<(), GlError> {
        let lookup = self
            .lookup
            .ok_or_else(|| GlError::InvalidParams(format!("{}: lighting before draw_volumes", self.name)))?;
        if self.lit_uniforms.as_ref().map(|u| u.program) != Some(program) {
            let u = |n| uniform(gl, program, n);
            self.lit_uniforms = Some(LitUniforms {
                program,
                kind: u("u_sm_kind"),
                light_pos: u("u_sm_light_pos"),
                near: u("u_sm_near"),
                map_from_world: u("u_sm_map_from_world"),
                resolution: u("u_sm_resolution"),
            });
        }
        let Some(u) = self.lit_uniforms.as_ref() else { return Ok(()) };
        // SAFETY: `program` is current (renderer contract); our textures; uniforms match lit.glsl.
        unsafe {
            gl.uniform_1_f32(u.resolution.as_ref(), self.config.resolution as f32);
            match lookup {
                Lookup::Cube { light, near } => {
                    gl.uniform_1_i32(u.kind.as_ref(), 0);
                    gl.uniform_3_f32_slice(u.light_pos.as_ref(), &light);
                    gl.uniform_1_f32(u.near.as_ref(), near);
                    gl.bind_texture_unit(MAP_UNIT, self.cube.as_ref().map(|m| m.texture));
                }
                Lookup::Directional { map_from_world } => {
                    gl.uniform_1_i32(u.kind.as_ref(), 1);
                    gl.uniform_matrix_4_f32_slice(u.map_from_world.as_ref(), false, &map_from_world);
                    gl.bind_texture_unit(MAP_UNIT, self.map2d.as_ref().map(|m| m.texture));
                }
            }
        }
        Ok(())
    }

    fn gpu_bytes(&self) -> usize {
        self.cube.as_ref().map_or(0, |m| m.bytes) + self.map2d.as_ref().map_or(0, |m| m.bytes)
    }

    fn destroy(&mut self, gl: &glow::Context) {
        if let Some(p) = self.programs.take() {
            // SAFETY: our own programs, not used afterwards.
            unsafe {
                gl.delete_program(p.layered);
                gl.delete_program(p.single);
            }
        }
        for m in [self.cube.take(), self.map2d.take()].into_iter().flatten() {
            m.destroy(gl);
        }
        self.lit_uniforms = None;
        self.lookup = None;
        self.prepared = None;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_parse_with_resolution() {
        assert_eq!(ShadowMapConfig::from_name("shadow-map-cube:2048").map(|c| c.resolution), Some(2048));
        assert_eq!(ShadowMapConfig::from_name("shadow-map-cube:8k").map(|c| c.resolution), Some(8192));
        for bad in [
            "shadow-map-cube",
            "shadow-map-cube:",
            "shadow-map-cube:0",
            "shadow-map-cube:-1",
            "shadow-map-cube:1.5",
            "shadow-map-cube:99999999999",
            "cpu-silhouette",
        ] {
            assert!(ShadowMapConfig::from_name(bad).is_none(), "{bad}");
        }
        assert_eq!(ShadowMapConfig::new(1024).name(), NAME_1024);
        let pcf = ShadowMapConfig::from_name("shadow-map-cube:512+pcf").expect("pcf variant");
        assert!(pcf.pcf && pcf.resolution == 512 && pcf.name() == "shadow-map-cube:512+pcf");
        assert!(ShadowMapConfig::from_name("shadow-map-cube:+pcf").is_none());
        assert!(std::ptr::eq(ShadowMapConfig::new(77).name(), ShadowMapConfig::new(77).name()), "interned once");
        assert_eq!(ShadowMapConfig::new(8192).cube_bytes(), 6 * 8192 * 8192 * 4);
    }
}
