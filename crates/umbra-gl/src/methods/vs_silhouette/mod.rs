//! `vs-silhouette`: silhouette shadow volumes evaluated in the vertex shader from precomputed
//! sides-data and caps-data.
//!
//! Paper 003 (Milet et al., "Fast robust and precise shadow algorithm for WebGL 1.0
//! platform"), Section 2: sides by Algorithm 1 (Eq. 1-5, Fig. 2-3), caps by Algorithm 2 with
//! the front cap shifted to infinity (Eq. 6, Fig. 4-5) and the infinite far plane, in the
//! compact instanced layout of Section 2.6 (sides-data `16 · (2 + maxMult) · e` bytes, Eq. 8;
//! caps-data `48 · t` bytes, Eq. 9; see [`umbra_geom::sides_data`]). Multiplicity and cap
//! orientation by paper 001's reference edge (Alg. 3-4), the shared `multiplicity.glsl`.
//!
//! Once per mesh ([`ShadowMethod::prepare`] / [`VsSilhouette::prepare_mesh`]): sides-data and
//! caps-data built on the CPU and uploaded to two static vertex buffers, one vertex array each
//! with every attribute advancing once per instance (divisor 1), two programs.
//! Per light per frame: uniforms and two instanced draws, nothing else:
//! * sides: `e` instances (edge records) of `6 · maxMult` vertices; the side index and the
//!   vertex of the side come from `gl_VertexID` (the paper had to emulate it in WebGL 1.0);
//! * caps (z-fail only): `t` instances (triangles) of 6 vertices (3 for a directional light,
//!   whose dark cap has zero area).
//!
//! `maxMult` is the scene's largest number of opposite vertices, capped
//! ([`umbra_geom::sides_data::choose_max_mult`], at most `MAX_VERTEX_ATTRIBS - 2` and 14):
//! edges with more opposites are split into several records whose sub-multiplicities add up
//! (quads of opposite sign over one edge are the same two triangles reversed, Eq. 4-5, and
//! cancel in the stencil). [`VsSilhouette::with_max_mult_cap`] forces a smaller cap (tests).
//!
//! The shaders are written in the common subset of GLSL 4.50 core and GLSL ES 3.00 (the basis
//! of a WebGL 2 build); [`ShaderDialect`] picks the prelude. The GL calls of this module are
//! the OpenGL ES 3.0 subset (no direct state access), so the same code runs on an ES 3
//! context (tested in `tests/method_vs_silhouette.rs`).
//!
//! Stages reported: "sides", "caps".

use glow::HasContext;
use umbra_geom::sides_data::{
    build_caps_data, build_sides_data, caps_data_bytes, choose_max_mult, record_count, sides_data_bytes, MAX_MULT_LIMIT,
};
use umbra_geom::{EdgeAdjacency, Light, WeldedMesh};

use crate::error::GlError;
use crate::methods::{ShadowMethod, VolumeFrame};
use crate::program::{link_program, uniform, ShaderSource};
use crate::scene::{SceneGpu, SceneId};
use crate::state::GlState;

pub const NAME: &str = "vs-silhouette";

const MULTIPLICITY: &str = include_str!("../shared/multiplicity.glsl");
const DEPTH: &str = include_str!("../shared/depth.glsl");
const SIDES_VERT: &str = include_str!("sides.vert.glsl");
const CAPS_VERT: &str = include_str!("caps.vert.glsl");
const FRAG: &str = include_str!("volume.frag.glsl");

/// Which GLSL the shader bodies are compiled as (they have no `#version` of their own).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ShaderDialect {
    /// `#version 450 core` (the OpenGL 4.5 renderer).
    Glsl450,
    /// `#version 300 es` with highp defaults (OpenGL ES 3.0 / WebGL 2).
    Essl300,
}

impl ShaderDialect {
    fn prelude(self) -> &'static str {
        match self {
            ShaderDialect::Glsl450 => "#version 450 core\n",
            // Reason: ES has no default float precision in fragment shaders, and the
            // multiplicity test needs full f32 in every stage (highp is f32 in ES 3.0).
            ShaderDialect::Essl300 => "#version 300 es\nprecision highp float;\nprecision highp int;\n",
        }
    }
}

/// Full source of the sides vertex shader for `max_mult` opposite slots per record.
pub fn sides_vertex_source(dialect: ShaderDialect, max_mult: usize) -> String {
    format!("{}#define UMBRA_MAX_MULT {max_mult}\n{MULTIPLICITY}\n{DEPTH}\n{SIDES_VERT}", dialect.prelude())
}

/// Full source of the caps vertex shader.
pub fn caps_vertex_source(dialect: ShaderDialect) -> String {
    format!("{}{MULTIPLICITY}\n{DEPTH}\n{CAPS_VERT}", dialect.prelude())
}

/// Full source of the (empty) fragment shader.
pub fn fragment_source(dialect: ShaderDialect) -> String {
    format!("{}{FRAG}", dialect.prelude())
}

/// Sizes of the uploaded shadow geometry.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Layout {
    /// Opposite-vertex slots per edge record (`maxMult` of Eq. 8).
    pub max_mult: usize,
    /// Edge records (`e` of Eq. 8; more than the edges when some were split).
    pub records: usize,
    /// Edges of the scene.
    pub edges: usize,
    /// Triangles (`t` of Eq. 9).
    pub triangles: usize,
    /// Eq. 8, `16 · (2 + maxMult) · e`.
    pub sides_bytes: usize,
    /// Eq. 9, `48 · t`.
    pub caps_bytes: usize,
}

/// The layout `prepare` uses for a mesh with adjacency `adj` and `triangles` triangles when
/// at most `max_mult_limit` opposite slots fit in a record (GL: `MAX_VERTEX_ATTRIBS - 2`; 14
/// on every OpenGL 4.5 / ES 3.0 implementation): no GL needed (e.g. for `umbra info`).
pub fn plan_layout(adj: &EdgeAdjacency, triangles: usize, max_mult_limit: usize) -> Layout {
    let max_mult = choose_max_mult(adj, max_mult_limit.min(MAX_MULT_LIMIT)).max(1);
    let records = record_count(adj, max_mult);
    Layout {
        max_mult,
        records,
        edges: adj.len(),
        triangles,
        sides_bytes: sides_data_bytes(records, max_mult),
        caps_bytes: caps_data_bytes(triangles),
    }
}

/// What one volume pass needs besides the prepared data (the fields of a [`VolumeFrame`]).
#[derive(Clone, Copy, Debug)]
pub struct VolumeDraw {
    /// Column-major clip-from-world matrix (infinite far plane).
    pub clip_from_world: [f32; 16],
    pub light: Light,
    /// z-pass: no caps.
    pub zpass: bool,
    /// [`VolumeFrame::far_clip_z`].
    pub far_clip_z: f32,
    /// The counting state, [`VolumeFrame::shadow_volume_state`].
    pub state: GlState,
}

struct Program {
    program: glow::Program,
    clip_from_world: Option<glow::UniformLocation>,
    light: Option<glow::UniformLocation>,
    far_clip_z: Option<glow::UniformLocation>,
}

impl Program {
    fn link(gl: &glow::Context, name: &str, vert_name: &str, vert: &str, frag: &str) -> Result<Self, GlError> {
        let program = link_program(
            gl,
            name,
            &[ShaderSource::vertex(vert_name, vert), ShaderSource::fragment("vs_silhouette/volume.frag.glsl", frag)],
            &[],
        )?;
        Ok(Self {
            clip_from_world: uniform(gl, program, "u_clip_from_world"),
            light: uniform(gl, program, "u_light"),
            far_clip_z: uniform(gl, program, "u_far_clip_z"),
            program,
        })
    }

    /// Binds the program and sets its uniforms for this pass.
    fn bind(&self, gl: &glow::Context, d: &VolumeDraw) {
        // SAFETY: our own linked program; uniform locations come from it.
        unsafe {
            gl.use_program(Some(self.program));
            gl.uniform_matrix_4_f32_slice(self.clip_from_world.as_ref(), false, &d.clip_from_world);
            gl.uniform_4_f32_slice(self.light.as_ref(), &d.light);
            gl.uniform_1_f32(self.far_clip_z.as_ref(), d.far_clip_z);
        }
    }
}

struct Gpu {
    sides: Program,
    caps: Program,
    sides_vao: glow::VertexArray,
    caps_vao: glow::VertexArray,
    sides_buffer: glow::Buffer,
    caps_buffer: glow::Buffer,
    layout: Layout,
}

/// See the module documentation.
#[derive(Default)]
pub struct VsSilhouette {
    prepared: Option<SceneId>,
    gpu: Option<Gpu>,
    /// Upper bound on maxMult forced by the caller (tests of the splitting).
    max_mult_cap: Option<usize>,
}

fn as_bytes(v: &[[f32; 4]]) -> &[u8] {
    // SAFETY: [f32; 4] has no padding and every byte is initialised.
    unsafe { std::slice::from_raw_parts(v.as_ptr().cast::<u8>(), std::mem::size_of_val(v)) }
}

/// A static vertex buffer holding `data`, and a vertex array reading `stride_vec4s`
/// consecutive vec4 attributes (locations 0..) from it once per instance.
///
/// ES 3.0 entry points only (bind-to-edit): binds the new vertex array and GL_ARRAY_BUFFER,
/// and unbinds both before returning.
fn instanced_vec4_buffer(
    gl: &glow::Context,
    what: &'static str,
    data: &[[f32; 4]],
    stride_vec4s: usize,
) -> Result<(glow::Buffer, glow::VertexArray), GlError> {
    let bytes = as_bytes(data);
    crate::scene::checked_size(bytes.len(), what)?;
    let stride =
        i32::try_from(16 * stride_vec4s).map_err(|_| GlError::InvalidParams(format!("{what}: stride too large")))?;
    // SAFETY: object creation and uploads on the current context; `bytes` outlives the call;
    // every attribute offset lies inside the stride.
    unsafe {
        let buffer = gl.create_buffer().map_err(|detail| GlError::Create { what, detail })?;
        let vao = match gl.create_vertex_array() {
            Ok(v) => v,
            Err(detail) => {
                gl.delete_buffer(buffer);
                return Err(GlError::Create { what, detail });
            }
        };
        gl.bind_buffer(glow::ARRAY_BUFFER, Some(buffer));
        // STATIC_DRAW: uploaded once per mesh, read by every frame.
        gl.buffer_data_u8_slice(glow::ARRAY_BUFFER, bytes, glow::STATIC_DRAW);
        gl.bind_vertex_array(Some(vao));
        for i in 0..stride_vec4s as u32 {
            gl.vertex_attrib_pointer_f32(i, 4, glow::FLOAT, false, stride, 16 * i as i32);
            gl.enable_vertex_attrib_array(i);
            // Divisor 1: one record per instance (paper 003 Section 2.6 instancing), the same
            // for all of the instance's vertices.
            gl.vertex_attrib_divisor(i, 1);
        }
        gl.bind_vertex_array(None);
        gl.bind_buffer(glow::ARRAY_BUFFER, None);
        Ok((buffer, vao))
    }
}

impl VsSilhouette {
    pub fn new() -> Self {
        Self::default()
    }

    /// Like [`VsSilhouette::new`], with maxMult at most `cap` (>= 1): edges with more opposite
    /// vertices are split into several records.
    pub fn with_max_mult_cap(cap: usize) -> Self {
        Self { max_mult_cap: Some(cap.max(1)), ..Self::default() }
    }

    /// Sizes of the prepared data (None before prepare).
    pub fn layout(&self) -> Option<Layout> {
        self.gpu.as_ref().map(|g| g.layout)
    }

    /// GL_BUFFER_SIZE of the sides-data and caps-data buffers as GL reports it.
    pub fn uploaded_buffer_bytes(&self, gl: &glow::Context) -> Option<(usize, usize)> {
        let g = self.gpu.as_ref()?;
        // SAFETY: queries on our own buffers; the ARRAY_BUFFER binding is restored to none.
        unsafe {
            let size = |b| {
                gl.bind_buffer(glow::ARRAY_BUFFER, Some(b));
                let s = gl.get_buffer_parameter_i32(glow::ARRAY_BUFFER, glow::BUFFER_SIZE);
                gl.bind_buffer(glow::ARRAY_BUFFER, None);
                s.max(0) as usize
            };
            Some((size(g.sides_buffer), size(g.caps_buffer)))
        }
    }

    /// Preprocessing for `mesh` with its adjacency on the current context (GL 4.5 core or
    /// ES 3.0, matching `dialect`): builds and uploads sides-data and caps-data, links the
    /// programs. Replaces what an earlier call prepared.
    pub fn prepare_mesh(
        &mut self,
        gl: &glow::Context,
        dialect: ShaderDialect,
        mesh: &WeldedMesh,
        adj: &EdgeAdjacency,
    ) -> Result<(), GlError> {
        self.destroy(gl);
        // SAFETY: plain query on the current context.
        let attribs = unsafe { gl.get_parameter_i32(glow::MAX_VERTEX_ATTRIBS) }.max(3) as usize;
        let limit = (attribs - 2).min(self.max_mult_cap.unwrap_or(MAX_MULT_LIMIT));
        let layout = plan_layout(adj, mesh.triangles.len(), limit);
        let sides = build_sides_data(mesh, adj, layout.max_mult).map_err(|e| GlError::InvalidParams(e.to_string()))?;
        let caps = build_caps_data(mesh).map_err(|e| GlError::InvalidParams(e.to_string()))?;
        debug_assert_eq!(sides.records(), layout.records);
        if i32::try_from(layout.records).is_err() || i32::try_from(layout.triangles).is_err() {
            return Err(GlError::InvalidParams(format!(
                "vs-silhouette: {} edge records / {} triangles exceed one instanced draw",
                layout.records, layout.triangles
            )));
        }

        let sides_prog = Program::link(
            gl,
            "vs-silhouette sides",
            "vs_silhouette/sides.vert.glsl",
            &sides_vertex_source(dialect, layout.max_mult),
            &fragment_source(dialect),
        )?;
        let caps_prog = match Program::link(
            gl,
            "vs-silhouette caps",
            "vs_silhouette/caps.vert.glsl",
            &caps_vertex_source(dialect),
            &fragment_source(dialect),
        ) {
            Ok(p) => p,
            Err(e) => {
                // SAFETY: our own program, not used afterwards.
                unsafe { gl.delete_program(sides_prog.program) };
                return Err(e);
            }
        };
        let delete_programs = || {
            // SAFETY: our own programs, not used afterwards.
            unsafe {
                gl.delete_program(sides_prog.program);
                gl.delete_program(caps_prog.program);
            }
        };
        let (sides_buffer, sides_vao) =
            match instanced_vec4_buffer(gl, "vs-silhouette sides-data", &sides.data, sides.stride()) {
                Ok(x) => x,
                Err(e) => {
                    delete_programs();
                    return Err(e);
                }
            };
        let (caps_buffer, caps_vao) = match instanced_vec4_buffer(gl, "vs-silhouette caps-data", &caps, 3) {
            Ok(x) => x,
            Err(e) => {
                delete_programs();
                // SAFETY: our own objects, not used afterwards.
                unsafe {
                    gl.delete_buffer(sides_buffer);
                    gl.delete_vertex_array(sides_vao);
                }
                return Err(e);
            }
        };
        self.gpu =
            Some(Gpu { sides: sides_prog, caps: caps_prog, sides_vao, caps_vao, sides_buffer, caps_buffer, layout });
        Ok(())
    }

    /// Draws the volume for one light into the current framebuffer's stencil with
    /// `d.state`; `mark(gl, label)` is called before each stage ("sides", "caps").
    pub fn draw_volume(
        &self,
        gl: &glow::Context,
        d: &VolumeDraw,
        mark: &mut dyn FnMut(&glow::Context, &'static str),
    ) -> Result<(), GlError> {
        let g = self.gpu.as_ref().ok_or_else(|| GlError::InvalidParams("vs-silhouette: draw before prepare".into()))?;
        let l = g.layout;
        // Counting state (z-fail or z-pass), reasons per field in GlState::shadow_volume.
        d.state.apply(gl);

        mark(gl, "sides");
        if l.records > 0 {
            g.sides.bind(gl, d);
            // SAFETY: our program and vertex array; every instance reads one whole record of
            // the sides-data buffer (records * stride vec4s were uploaded).
            unsafe {
                gl.bind_vertex_array(Some(g.sides_vao));
                // Vertex shader stage (sides.vert.glsl): Alg. 1 per vertex; 6 vertices per
                // potential side, maxMult potential sides per record.
                gl.draw_arrays_instanced(glow::TRIANGLES, 0, (6 * l.max_mult) as i32, l.records as i32);
            }
        }

        mark(gl, "caps");
        // z-pass counts only faces in front of the sample and needs no caps.
        if !d.zpass && l.triangles > 0 {
            g.caps.bind(gl, d);
            // A directional light's dark cap has zero area: draw only the light cap.
            let vertices = if d.light[3] == 0.0 { 3 } else { 6 };
            // SAFETY: our program and vertex array; one caps-data record per instance.
            unsafe {
                gl.bind_vertex_array(Some(g.caps_vao));
                // Vertex shader stage (caps.vert.glsl): Alg. 2 per vertex.
                gl.draw_arrays_instanced(glow::TRIANGLES, 0, vertices, l.triangles as i32);
            }
        }
        // SAFETY: unbinding leaves no dangling reference to our vertex array.
        unsafe { gl.bind_vertex_array(None) };
        Ok(())
    }
}

impl ShadowMethod for VsSilhouette {
    fn name(&self) -> &'static str {
        NAME
    }

    fn stages(&self) -> &'static [&'static str] {
        &["sides", "caps"]
    }

    fn prepare(&mut self, gl: &glow::Context, scene: &SceneGpu) -> Result<(), GlError> {
        self.prepare_mesh(gl, ShaderDialect::Glsl450, scene.mesh(), scene.adjacency())?;
        self.prepared = Some(scene.id());
        Ok(())
    }

    fn prepared_scene(&self) -> Option<SceneId> {
        self.prepared
    }

    fn draw_volumes(
        &mut self,
        gl: &glow::Context,
        _scene: &SceneGpu,
        frame: &mut VolumeFrame<'_>,
    ) -> Result<(), GlError> {
        let d = VolumeDraw {
            clip_from_world: frame.clip_from_world_f32(),
            light: frame.light,
            zpass: frame.zpass,
            far_clip_z: frame.far_clip_z(),
            state: frame.shadow_volume_state(),
        };
        self.draw_volume(gl, &d, &mut |gl, label| frame.mark(gl, label))
    }

    fn gpu_bytes(&self) -> usize {
        self.gpu.as_ref().map_or(0, |g| g.layout.sides_bytes + g.layout.caps_bytes)
    }

    fn destroy(&mut self, gl: &glow::Context) {
        if let Some(g) = self.gpu.take() {
            // SAFETY: our own objects, not used afterwards.
            unsafe {
                gl.delete_program(g.sides.program);
                gl.delete_program(g.caps.program);
                gl.delete_vertex_array(g.sides_vao);
                gl.delete_vertex_array(g.caps_vao);
                gl.delete_buffer(g.sides_buffer);
                gl.delete_buffer(g.caps_buffer);
            }
        }
        self.prepared = None;
    }
}
