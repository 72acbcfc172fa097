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
//! caps-data built on the CPU and uploaded to two static vertex buffers of exactly Eq. 8 and
//! Eq. 9 bytes, vertex arrays whose attributes advance once per instance (divisor 1), two
//! programs. Per light per frame: uniforms and instanced draws, nothing else:
//! * sides: `6 · maxMult` vertices per edge record; the record, the potential side `s` and the
//!   vertex `v` of the side come from `gl_VertexID` (the paper had to emulate it in WebGL 1.0);
//! * caps (z-fail only): 6 vertices per triangle (3 for a directional light, whose dark cap
//!   has zero area).
//!
//! Each instance reads `R` consecutive records through `R` attribute sets over the same buffer
//! (`R = MAX_VERTEX_ATTRIBS / (2 + maxMult)`, at most 8; 5 triangles for the caps with 16
//! attributes): the paper's layout and bytes, fewer instances (llvmpipe runs its vertex
//! pipeline once per instance; `R = 1` is the paper's one edge per instance,
//! [`VsSilhouette::with_records_per_instance_cap`]). The last `records % R` records are drawn
//! by one more instance whose missing attribute sets are disabled and read an all-zero
//! generic value: an empty record.
//!
//! `maxMult` is the scene's largest number of opposite vertices, capped
//! ([`umbra_geom::sides_data::choose_max_mult`]: at most `MAX_VERTEX_ATTRIBS - 2` and 14, and
//! the count that covers 99.9 % of the edges): edges with more opposites are split into
//! several records whose sub-multiplicities add up; quads of opposite sign over one split edge
//! are the same two triangles with the last two vertices swapped (Eq. 4-5 tables, see
//! `sides.vert.glsl`) and cancel in the stencil. [`VsSilhouette::with_max_mult_cap`] forces a
//! smaller cap (tests).
//!
//! The shaders are written in the common subset of GLSL 4.50 core and GLSL ES 3.00 (the basis
//! of a WebGL 2 build); [`ShaderDialect`] picks the prelude. The GL calls of this module are
//! the OpenGL ES 3.0 subset (no direct state access), so the same code runs on an ES 3
//! context (tested in `tests/method_vs_silhouette.rs`).
//!
//! Stages reported: "sides", "caps".

use glow::HasContext;
use umbra_geom::export_buffers::PORTABLE_VERTEX_ATTRIBS;
use umbra_geom::sides_data::{
    build_caps_data, build_sides_data, caps_data_bytes, max_mult_for_attribs, record_count, sides_data_bytes,
    MAX_MULT_LIMIT,
};
use umbra_geom::{EdgeAdjacency, Light, WeldedMesh};

use crate::camera::DepthConvention;
use crate::error::GlError;
use crate::gpu_buffer::{buffer_with_data, BufferApi, BufferData};
use crate::methods::face_depth::{DepthUniforms, FACE_DEPTH_FRAG_GLSL, SIDE_PLANE_GLSL};
use crate::methods::method::{ShadowMethod, VolumeFrame};
use crate::program::{link_program, uniform, ShaderSource};
use crate::scene::{SceneGpu, SceneId};
use crate::state::GlState;

/// Registry name.
pub const NAME: &str = "vs-silhouette";

const MULTIPLICITY: &str = include_str!("../shared/multiplicity.glsl");
const DEPTH: &str = include_str!("../shared/depth.glsl");
const SIDES_VERT: &str = include_str!("sides.vert.glsl");
const CAPS_VERT: &str = include_str!("caps.vert.glsl");
const FRAG: &str = include_str!("volume.frag.glsl");

/// Where the vertex shaders put a useless vertex (paper 003 Alg. 1 line 7 / Alg. 2 line 3 use
/// (0,0,0,0)): beyond the right and top clip planes (x = y = 2w), so every triangle made of
/// such vertices is rejected by the clip test before any setup (an all-zero vertex passes
/// every clip test with equality and reaches triangle setup with 0/0 coordinates).
macro_rules! culled {
    () => {
        "#define UMBRA_CULLED vec4(2.0, 2.0, 0.0, 1.0)\n"
    };
}

/// Which GLSL the shader bodies are compiled as (they have no `#version` of their own).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ShaderDialect {
    /// `#version 450 core` (the OpenGL 4.5 renderer).
    Glsl450,
    /// `#version 300 es` with highp defaults (OpenGL ES 3.0 / WebGL 2).
    Essl300,
}

impl ShaderDialect {
    /// The face depth functions of every fragment's depth (shared/side_plane.glsl,
    /// shared/face_depth.frag.glsl): GLSL 4.50 only. They need doubles, which GLSL
    /// ES 3.00 lacks; the ES build keeps the rasterized depth (the bodies test GL_ES).
    fn face_depth(self, stage: &'static str) -> &'static str {
        match self {
            ShaderDialect::Glsl450 => stage,
            ShaderDialect::Essl300 => "",
        }
    }

    fn prelude(self) -> &'static str {
        match self {
            ShaderDialect::Glsl450 => concat!("#version 450 core\n", culled!()),
            // Reason: ES has no default float precision in fragment shaders, and the
            // multiplicity test needs full f32 in every stage (highp is f32 in ES 3.0).
            ShaderDialect::Essl300 => {
                concat!("#version 300 es\nprecision highp float;\nprecision highp int;\n", culled!())
            }
        }
    }
}

/// Generated GLSL (both dialects): `records` sets of `fields.len()` vec4 attributes at
/// locations `0..records * fields.len()` (`a_r<record>_<field>`), a struct with the named
/// fields (`struct_body`) and `function(int r)` returning set `r`.
fn record_access(struct_name: &str, struct_body: &str, function: &str, fields: &[String], records: usize) -> String {
    let mut g = format!("#define UMBRA_RECORDS {records}\nstruct {struct_name} {{ {struct_body} }};\n");
    for r in 0..records {
        for f in 0..fields.len() {
            g += &format!("layout(location = {}) in vec4 a_r{r}_{f};\n", r * fields.len() + f);
        }
    }
    g += &format!("{struct_name} {function}(int r) {{\n    {struct_name} rec;\n");
    for r in 0..records {
        let assign: String = fields.iter().enumerate().map(|(f, name)| format!(" rec.{name} = a_r{r}_{f};")).collect();
        let guard = if r + 1 == records { "    {".to_string() } else { format!("    if (r == {r}) {{") };
        g += &format!("{guard}{assign} }}{}\n", if r + 1 == records { "" } else { " else" });
    }
    g += "    return rec;\n}\n";
    g
}

/// Full source of the sides vertex shader for `max_mult` opposite slots per record and
/// `records` edge records per instance.
pub fn sides_vertex_source(dialect: ShaderDialect, max_mult: usize, records: usize) -> String {
    let mut fields = vec!["a".to_string(), "b".to_string()];
    fields.extend((0..max_mult).map(|i| format!("o[{i}]")));
    let access = record_access(
        "UmbraEdgeRecord",
        "vec4 a; vec4 b; vec4 o[UMBRA_MAX_MULT];",
        "umbra_edge_record",
        &fields,
        records,
    );
    format!(
        "{}#define UMBRA_MAX_MULT {max_mult}\n{MULTIPLICITY}\n{DEPTH}\n{}\n{access}\n{SIDES_VERT}",
        dialect.prelude(),
        dialect.face_depth(SIDE_PLANE_GLSL)
    )
}

/// Full source of the caps vertex shader for `records` triangles per instance.
pub fn caps_vertex_source(dialect: ShaderDialect, records: usize) -> String {
    let fields = ["p0", "p1", "p2"].map(String::from);
    let access =
        record_access("UmbraTriangleRecord", "vec4 p0; vec4 p1; vec4 p2;", "umbra_triangle_record", &fields, records);
    format!(
        "{}{MULTIPLICITY}\n{DEPTH}\n{}\n{access}\n{CAPS_VERT}",
        dialect.prelude(),
        dialect.face_depth(SIDE_PLANE_GLSL)
    )
}

/// Full source of the fragment shader (GLSL 4.50: with the face depths).
pub fn fragment_source(dialect: ShaderDialect) -> String {
    format!("{}{}\n{FRAG}", dialect.prelude(), dialect.face_depth(FACE_DEPTH_FRAG_GLSL))
}

/// Records of `vec4s` vec4 each that fit one instance with `attribs` vertex attributes
/// (at most 8: beyond that the selection in the shader costs more than the instances save).
pub fn records_per_instance(vec4s: usize, attribs: usize) -> usize {
    (attribs / vec4s.max(1)).clamp(1, 8)
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
    /// Edge records drawn per instance (the same buffer read by several attribute sets).
    pub sides_records_per_instance: usize,
    /// Triangles drawn per instance.
    pub caps_records_per_instance: usize,
}

/// The layout `prepare` uses for a mesh with adjacency `adj` and `triangles` triangles with
/// `attribs` vertex attributes (GL_MAX_VERTEX_ATTRIBS, at least 16 on every OpenGL 4.5 /
/// ES 3.0 implementation) and at most `max_mult_limit` opposite slots per record: no GL
/// needed (e.g. for `umbra info`, with 16 and [`MAX_MULT_LIMIT`]).
pub fn plan_layout(adj: &EdgeAdjacency, triangles: usize, attribs: usize, max_mult_limit: usize) -> Layout {
    let max_mult = max_mult_for_attribs(adj, attribs, max_mult_limit);
    let records = record_count(adj, max_mult);
    Layout {
        max_mult,
        records,
        edges: adj.len(),
        triangles,
        sides_bytes: sides_data_bytes(records, max_mult),
        caps_bytes: caps_data_bytes(triangles),
        sides_records_per_instance: records_per_instance(2 + max_mult, attribs),
        caps_records_per_instance: records_per_instance(3, attribs),
    }
}

/// GL_MAX_VERTEX_ATTRIBS guaranteed by OpenGL 4.5 and OpenGL ES 3.0 (llvmpipe reports it too):
/// the export buffers' [`PORTABLE_VERTEX_ATTRIBS`].
pub const MIN_VERTEX_ATTRIBS: usize = PORTABLE_VERTEX_ATTRIBS;

/// The layout `prepare` uses on any implementation with the guaranteed minimum of vertex
/// attributes and no tighter cap: [`plan_layout`] with [`MIN_VERTEX_ATTRIBS`] and
/// [`MAX_MULT_LIMIT`], no GL needed (`umbra info`, `umbra export`).
pub fn plan_portable_layout(adj: &EdgeAdjacency, triangles: usize) -> Layout {
    plan_layout(adj, triangles, MIN_VERTEX_ATTRIBS, MAX_MULT_LIMIT)
}

/// What one volume pass needs besides the prepared data (the fields of a [`VolumeFrame`]).
#[derive(Clone, Copy, Debug)]
pub struct VolumeDraw {
    /// Column-major clip-from-world matrix (infinite far plane).
    pub clip_from_world: [f32; 16],
    /// The light (w = 1 point, w = 0 directional).
    pub light: Light,
    /// z-pass: no caps.
    pub zpass: bool,
    /// The viewport's width and height in pixels ([`VolumeFrame::width`], `height`): the
    /// window-space face depths of every fragment (GLSL 4.50 only).
    pub viewport_size: [u32; 2],
    /// [`VolumeFrame::depth_convention`]: the far plane's clip z (where light caps go) and the
    /// face depths.
    pub depth_convention: DepthConvention,
    /// The counting state, [`VolumeFrame::shadow_volume_state`].
    pub state: GlState,
}

struct Program {
    program: glow::Program,
    clip_from_world: Option<glow::UniformLocation>,
    light: Option<glow::UniformLocation>,
    far_clip_z: Option<glow::UniformLocation>,
    cap_vertices: Option<glow::UniformLocation>,
    depth: DepthUniforms,
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
            cap_vertices: uniform(gl, program, "u_cap_vertices"),
            depth: DepthUniforms::locate(gl, program),
            program,
        })
    }

    /// Binds the program and sets its uniforms for this pass.
    fn bind(&self, gl: &glow::Context, d: &VolumeDraw, cap_vertices: i32) {
        // SAFETY: our own linked program; uniform locations come from it (None: unused).
        unsafe {
            gl.use_program(Some(self.program));
            gl.uniform_matrix_4_f32_slice(self.clip_from_world.as_ref(), false, &d.clip_from_world);
            gl.uniform_4_f32_slice(self.light.as_ref(), &d.light);
            gl.uniform_1_f32(self.far_clip_z.as_ref(), d.depth_convention.far_clip_z());
            gl.uniform_1_i32(self.cap_vertices.as_ref(), cap_vertices);
        }
        // The face depth functions every fragment's depth comes from (GLSL 4.50; absent
        // uniforms under ES are None).
        self.depth.set_for(gl, d.viewport_size, d.depth_convention, d.zpass);
    }
}

/// One static buffer of records (`vec4s` vec4 each, `records` of them: exactly the bytes of
/// Eq. 8 or Eq. 9) and the vertex arrays that feed `per_instance` records to each instance.
struct RecordArrays {
    buffer: glow::Buffer,
    /// All `per_instance` attribute sets, instance i reads records `per_instance * i + j`.
    main_vao: glow::VertexArray,
    main_instances: usize,
    /// The last `records % per_instance` records: one instance whose missing sets are
    /// disabled (they read the generic attribute value, set to 0 = an empty record).
    remainder: Option<(glow::VertexArray, usize)>,
    vec4s: usize,
    per_instance: usize,
}

impl RecordArrays {
    /// ES 3.0 entry points only (bind-to-edit): binds new vertex arrays and GL_ARRAY_BUFFER,
    /// unbinds both before returning.
    fn new(
        gl: &glow::Context,
        what: &'static str,
        data: &[[f32; 4]],
        vec4s: usize,
        per_instance: usize,
    ) -> Result<Self, GlError> {
        let bytes = as_bytes(data);
        crate::gpu_buffer::checked_size(bytes.len(), what)?;
        let records = data.len() / vec4s.max(1);
        let record_bytes = 16 * vec4s;
        let stride = i32::try_from(record_bytes * per_instance)
            .map_err(|_| GlError::InvalidParams(format!("{what}: stride too large")))?;
        let (main_instances, rest) = (records / per_instance, records % per_instance);
        // SAFETY: object creation and uploads on the current context; `bytes` outlives the
        // call; every attribute of instance i reads inside record per_instance * i + j <
        // records (main) or inside the last `rest` records (remainder).
        unsafe {
            // STATIC_DRAW: uploaded once per mesh, read by every frame. Left bound to
            // GL_ARRAY_BUFFER, which the vertex_attrib_pointer calls below read; a store the
            // driver refuses is GlError::OutOfMemory and leaves no buffer behind.
            let buffer = buffer_with_data(
                gl,
                BufferApi::Bind(glow::ARRAY_BUFFER),
                BufferData::Bytes(bytes),
                glow::STATIC_DRAW,
                what,
            )?;
            let vao_for = |sets: usize, base: usize| -> Result<glow::VertexArray, GlError> {
                let vao = gl.create_vertex_array().map_err(|detail| GlError::Create { what, detail })?;
                gl.bind_vertex_array(Some(vao));
                for j in 0..sets {
                    for f in 0..vec4s {
                        let location = (j * vec4s + f) as u32;
                        let offset = (base + (j * vec4s + f) * 16) as i32;
                        gl.vertex_attrib_pointer_f32(location, 4, glow::FLOAT, false, stride, offset);
                        gl.enable_vertex_attrib_array(location);
                        // Divisor 1: the record is the same for all of the instance's vertices
                        // (paper 003 Section 2.6 instancing).
                        gl.vertex_attrib_divisor(location, 1);
                    }
                }
                Ok(vao)
            };
            let main = vao_for(per_instance, 0);
            let remainder = match (&main, rest) {
                (Ok(_), 1..) => Some(vao_for(rest, main_instances * per_instance * record_bytes)),
                _ => None,
            };
            gl.bind_vertex_array(None);
            gl.bind_buffer(glow::ARRAY_BUFFER, None);
            match (main, remainder) {
                (Ok(main_vao), None) => {
                    Ok(Self { buffer, main_vao, main_instances, remainder: None, vec4s, per_instance })
                }
                (Ok(main_vao), Some(Ok(r))) => {
                    Ok(Self { buffer, main_vao, main_instances, remainder: Some((r, rest)), vec4s, per_instance })
                }
                (Ok(main_vao), Some(Err(e))) => {
                    gl.delete_vertex_array(main_vao);
                    gl.delete_buffer(buffer);
                    Err(e)
                }
                (Err(e), _) => {
                    gl.delete_buffer(buffer);
                    Err(e)
                }
            }
        }
    }

    /// Draws every record: `vertices` vertices per record.
    fn draw(&self, gl: &glow::Context, vertices: usize) {
        let per_instance = (vertices * self.per_instance) as i32;
        // SAFETY: our vertex arrays over our buffer (see `new`); the program is bound.
        unsafe {
            if self.main_instances > 0 {
                gl.bind_vertex_array(Some(self.main_vao));
                gl.draw_arrays_instanced(glow::TRIANGLES, 0, per_instance, self.main_instances as i32);
            }
            if let Some((vao, rest)) = self.remainder {
                // The sets beyond `rest` are disabled: they read the generic attribute value,
                // which must be an empty record (count 0 / a degenerate triangle): all zero.
                for location in (rest * self.vec4s)..(self.per_instance * self.vec4s) {
                    gl.vertex_attrib_4_f32(location as u32, 0.0, 0.0, 0.0, 0.0);
                }
                gl.bind_vertex_array(Some(vao));
                gl.draw_arrays_instanced(glow::TRIANGLES, 0, per_instance, 1);
                // Back to GL's initial generic value (0, 0, 0, 1).
                for location in (rest * self.vec4s)..(self.per_instance * self.vec4s) {
                    gl.vertex_attrib_4_f32(location as u32, 0.0, 0.0, 0.0, 1.0);
                }
            }
        }
    }

    fn buffer_bytes(&self, gl: &glow::Context) -> usize {
        // SAFETY: query on our own buffer; the ARRAY_BUFFER binding is restored to none.
        unsafe {
            gl.bind_buffer(glow::ARRAY_BUFFER, Some(self.buffer));
            let s = gl.get_buffer_parameter_i32(glow::ARRAY_BUFFER, glow::BUFFER_SIZE);
            gl.bind_buffer(glow::ARRAY_BUFFER, None);
            s.max(0) as usize
        }
    }

    fn destroy(&self, gl: &glow::Context) {
        // SAFETY: our own objects, not used afterwards.
        unsafe {
            gl.delete_buffer(self.buffer);
            gl.delete_vertex_array(self.main_vao);
            if let Some((vao, _)) = self.remainder {
                gl.delete_vertex_array(vao);
            }
        }
    }
}

struct Gpu {
    sides: Program,
    caps: Program,
    sides_data: RecordArrays,
    caps_data: RecordArrays,
    layout: Layout,
}

/// See the module documentation.
#[derive(Default)]
pub struct VsSilhouette {
    prepared: Option<SceneId>,
    gpu: Option<Gpu>,
    /// Upper bound on maxMult forced by the caller (tests of the splitting).
    max_mult_cap: Option<usize>,
    /// Upper bound on the records per instance forced by the caller (tests).
    records_per_instance_cap: Option<usize>,
}

fn as_bytes(v: &[[f32; 4]]) -> &[u8] {
    // SAFETY: [f32; 4] has no padding and every byte is initialised.
    unsafe { std::slice::from_raw_parts(v.as_ptr().cast::<u8>(), std::mem::size_of_val(v)) }
}

impl VsSilhouette {
    /// Unprepared; programs and buffers are made by `prepare`.
    pub fn new() -> Self {
        Self::default()
    }

    /// Like [`VsSilhouette::new`], with maxMult at most `cap` (>= 1): edges with more opposite
    /// vertices are split into several records.
    pub fn with_max_mult_cap(cap: usize) -> Self {
        Self { max_mult_cap: Some(cap.max(1)), ..Self::default() }
    }

    /// At most `n` (>= 1) records per instance (1 = the paper's one edge per instance).
    pub fn with_records_per_instance_cap(mut self, n: usize) -> Self {
        self.records_per_instance_cap = Some(n.max(1));
        self
    }

    /// Sizes of the prepared data (None before prepare).
    pub fn layout(&self) -> Option<Layout> {
        self.gpu.as_ref().map(|g| g.layout)
    }

    /// GL_BUFFER_SIZE of the sides-data and caps-data buffers as GL reports it.
    pub fn uploaded_buffer_bytes(&self, gl: &glow::Context) -> Option<(usize, usize)> {
        let g = self.gpu.as_ref()?;
        Some((g.sides_data.buffer_bytes(gl), g.caps_data.buffer_bytes(gl)))
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
        let mut layout = plan_layout(adj, mesh.triangles.len(), attribs, self.max_mult_cap.unwrap_or(MAX_MULT_LIMIT));
        if let Some(n) = self.records_per_instance_cap {
            layout.sides_records_per_instance = layout.sides_records_per_instance.min(n);
            layout.caps_records_per_instance = layout.caps_records_per_instance.min(n);
        }
        let sides = build_sides_data(mesh, adj, layout.max_mult).map_err(|e| GlError::InvalidParams(e.to_string()))?;
        let caps = build_caps_data(mesh).map_err(|e| GlError::InvalidParams(e.to_string()))?;
        debug_assert_eq!(sides.records(), layout.records);
        let vertices = [6 * layout.max_mult * layout.sides_records_per_instance, 6 * layout.caps_records_per_instance];
        if i32::try_from(layout.records).is_err()
            || i32::try_from(layout.triangles).is_err()
            || vertices.iter().any(|&v| v > 1 << 20)
        {
            return Err(GlError::InvalidParams(format!(
                "vs-silhouette: {} edge records / {} triangles exceed one instanced draw",
                layout.records, layout.triangles
            )));
        }

        let frag = fragment_source(dialect);
        let sides_prog = Program::link(
            gl,
            "vs-silhouette sides",
            "vs_silhouette/sides.vert.glsl",
            &sides_vertex_source(dialect, layout.max_mult, layout.sides_records_per_instance),
            &frag,
        )?;
        let caps_src = caps_vertex_source(dialect, layout.caps_records_per_instance);
        let caps_prog = match Program::link(gl, "vs-silhouette caps", "vs_silhouette/caps.vert.glsl", &caps_src, &frag)
        {
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
        let sides_data = match RecordArrays::new(
            gl,
            "vs-silhouette sides-data",
            &sides.data,
            sides.stride(),
            layout.sides_records_per_instance,
        ) {
            Ok(x) => x,
            Err(e) => {
                delete_programs();
                return Err(e);
            }
        };
        let caps_data =
            match RecordArrays::new(gl, "vs-silhouette caps-data", &caps, 3, layout.caps_records_per_instance) {
                Ok(x) => x,
                Err(e) => {
                    delete_programs();
                    sides_data.destroy(gl);
                    return Err(e);
                }
            };
        self.gpu = Some(Gpu { sides: sides_prog, caps: caps_prog, sides_data, caps_data, layout });
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
            g.sides.bind(gl, d, 0);
            // Vertex shader stage (sides.vert.glsl): Alg. 1 per vertex; 6 vertices per
            // potential side, maxMult potential sides per record.
            g.sides_data.draw(gl, 6 * l.max_mult);
        }

        mark(gl, "caps");
        // z-pass counts only faces in front of the sample and needs no caps.
        if !d.zpass && l.triangles > 0 {
            // A directional light's dark cap has zero area: draw only the light cap.
            let vertices = if d.light[3] == 0.0 { 3 } else { 6 };
            g.caps.bind(gl, d, vertices as i32);
            // Vertex shader stage (caps.vert.glsl): Alg. 2 per vertex.
            g.caps_data.draw(gl, vertices);
        }
        // SAFETY: unbinding leaves no dangling reference to our vertex arrays.
        unsafe { gl.bind_vertex_array(None) };
        Ok(())
    }
}

impl ShadowMethod for VsSilhouette {
    fn silhouette_sides(&self) -> bool {
        true
    }

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
            viewport_size: [frame.width, frame.height],
            depth_convention: frame.depth_convention(),
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
            }
            g.sides_data.destroy(gl);
            g.caps_data.destroy(gl);
        }
        self.prepared = None;
    }
}
