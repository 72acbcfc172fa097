//! `cs-silhouette`: silhouette shadow volumes found by compute shaders and drawn with indirect
//! draws, no CPU round trip.
//!
//! Paper 001 (Milet, Kobrtek, Zemčík), Section 2.2-2.3 and its future work (a compute-shader
//! silhouette): every edge's multiplicity with the reference edge (Alg. 3-4, the shared
//! `multiplicity.glsl`), sides extruded with Eq. 2, caps oriented by the same test; light caps
//! pushed to the far plane (paper 003, Eq. 6) with the infinite far plane.
//!
//! Once per mesh ([`ShadowMethod::prepare`]): per edge record `(A, B, first opposite, count)` and
//! the opposite-vertex list (CSR) in shader-storage buffers. An edge with more than
//! [`MAX_OPPOSITES_PER_RECORD`] opposites is split into several records over consecutive
//! ranges of its opposites: llvmpipe (Mesa gallivm, `LP_MAX_TGSI_LOOP_ITERATIONS`) silently
//! ends every shader loop after 65,535 iterations, so one invocation looping over a spine of
//! 100,000 pages counted only 65,535 of them. Each record's partial multiplicity `m_r` emits
//! `|m_r|` quads with its own sign; the stencil counts are additive, so the sides of all the
//! records of an edge count exactly `m = Σ m_r` (opposite-signed quads of the same edge cancel;
//! `Σ|m_r| <= Σk` keeps the worst-case sizing). Output buffers sized for the worst
//! case: one 8-byte quad record per opposite vertex (`|m| <= k`, so `Σ|m| <= Σk`) and one
//! 12-byte cap record per triangle; two 16-byte `DrawArraysIndirectCommand`s. The scene's own
//! position and index buffers are read as shader storage (not copied).
//!
//! Per light per frame (all on the GPU):
//! 1. `glMemoryBarrier(SHADER_STORAGE | BUFFER_UPDATE)`, then the two commands reset to
//!    `{count 0, 1 instance}` with glNamedBufferSubData (see [`CsSilhouette::draw_volumes`]
//!    for why each barrier bit is there);
//! 2. "silhouette": `sides.comp.glsl`, one invocation per edge record, writes `|m|` quad records
//!    `(X, Y)` (the quad `Y X X∞ Y∞`, X/Y = A/B swapped for `m < 0`) compacted with an atomic
//!    counter: the sides command's vertex count, one atomicAdd per record with m != 0;
//! 3. "cap-orientation" (z-fail only): `caps.comp.glsl`, one invocation per triangle, writes
//!    the cap's three vertex indices wound to face the light, compacted the same way;
//! 4. `glMemoryBarrier(COMMAND | SHADER_STORAGE)`;
//! 5. "sides", "caps": two `glDrawArraysIndirect` with the counting state; the vertex
//!    shaders pull records and positions from shader storage (`gl_VertexID`).
//!
//! With [`VolumeFrame::volume_cull`], the volume is culled on the GPU before step 2
//! (`gpu_cull/`, the twin of umbra-wgpu's): the visible samples scattered into the light's
//! receiver map, and every piece of the caster (triangles joined across shared edges) that no
//! visible sample lies behind marked unneeded; the silhouette pass skips the records of its
//! edges and the cap pass its triangles. Nothing is read back.
//!
//! Stages reported: "receivers" (the cull), "silhouette", "cap-orientation", "sides", "caps".

use glow::HasContext;

use crate::error::GlError;
use crate::gpu_buffer::{buffer_store, checked_size, BufferApi, BufferData};
use crate::methods::face_depth::{face_depth_fragment, DepthUniforms, SIDE_PLANE_GLSL};
use crate::methods::gpu_cull::{GpuCull, Pieces};
use crate::methods::method::{DrawnVolume, ShadowMethod, VolumeFrame};
use crate::program::{link_program, uniform, ShaderSource};
use crate::scene::{SceneGpu, SceneId};

/// Registry name.
pub const NAME: &str = "cs-silhouette";

const MULTIPLICITY: &str = include_str!("../shared/multiplicity.glsl");
const DEPTH: &str = include_str!("../shared/depth.glsl");
const SIDES_COMP: &str = include_str!("sides.comp.glsl");
const CAPS_COMP: &str = include_str!("caps.comp.glsl");
const SIDES_VERT: &str = include_str!("sides.vert.glsl");
const CAPS_VERT: &str = include_str!("caps.vert.glsl");
const FRAG: &str = include_str!("volume.frag.glsl");

/// Most opposites one compute invocation loops over (one edge record). The multiplicity loop
/// and the quad-writing loop together stay below llvmpipe's 65,535 iterations per shader
/// loop (even if the limit were shared by both loops of an invocation).
pub const MAX_OPPOSITES_PER_RECORD: u32 = 16_384;

/// `local_size_x` of both compute shaders.
const WORKGROUP: u32 = 256;

// Shader-storage binding points (the `binding =` of the shaders). Binding 0 is the renderer's
// normals ([`crate::scene::NORMALS_BINDING`]) and stays untouched.
const POSITIONS: u32 = 1;
const EDGES: u32 = 2;
const OPPOSITES: u32 = 3;
const SIDES_COMMAND: u32 = 4;
const QUADS: u32 = 5;
const INDICES: u32 = 2;
const CAPS_COMMAND: u32 = 3;
const CAPS: u32 = 4;
// The cull's: per edge record its piece (sides), per triangle its piece (caps), the flags.
const RECORD_PIECES: u32 = 6;
const SIDES_NEEDED: u32 = 7;
const TRIANGLE_PIECES: u32 = 5;
const CAPS_NEEDED: u32 = 6;

/// Bytes of one DrawArraysIndirectCommand (count, instanceCount, first, baseInstance).
const COMMAND_BYTES: usize = 16;
/// Bytes of one side-quad record (two vertex indices).
pub const QUAD_RECORD_BYTES: usize = 8;
/// Bytes of one cap record (three vertex indices).
pub const CAP_RECORD_BYTES: usize = 12;
/// Bytes per edge of the edge buffer (`uvec4`).
pub const EDGE_RECORD_BYTES: usize = 16;

/// Sizes of the GPU buffers the method owns.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Layout {
    /// Unique edges.
    pub edges: usize,
    /// Edge records: `edges` plus the extra records of edges split at
    /// [`MAX_OPPOSITES_PER_RECORD`] opposites.
    pub records: usize,
    /// Σk: opposite vertices over all edges = worst-case side quads.
    pub opposites: usize,
    /// Triangles (one cap record each).
    pub triangles: usize,
}

impl Layout {
    /// Bytes of the edge-record buffer.
    pub fn edge_bytes(&self) -> usize {
        EDGE_RECORD_BYTES * self.records
    }
    /// Bytes of the opposite-vertex buffer (one u32 each).
    pub fn opposite_bytes(&self) -> usize {
        4 * self.opposites
    }
    /// Worst case: every opposite vertex contributes one quad.
    pub fn quad_bytes(&self) -> usize {
        QUAD_RECORD_BYTES * self.opposites
    }
    /// Bytes of the cap buffer (worst case: every triangle).
    pub fn cap_bytes(&self) -> usize {
        CAP_RECORD_BYTES * self.triangles
    }
    /// Everything [`ShadowMethod::gpu_bytes`] reports: the four buffers above plus the two
    /// indirect commands.
    pub fn total_bytes(&self) -> usize {
        self.edge_bytes() + self.opposite_bytes() + self.quad_bytes() + self.cap_bytes() + 2 * COMMAND_BYTES
    }
}

struct Programs {
    sides_comp: glow::Program,
    caps_comp: glow::Program,
    sides_draw: glow::Program,
    caps_draw: glow::Program,
    /// The face-depth uniforms of the two draw programs (shared/side_plane.glsl), located at
    /// link time.
    sides_depth: DepthUniforms,
    caps_depth: DepthUniforms,
}

impl Programs {
    fn all(&self) -> [glow::Program; 4] {
        [self.sides_comp, self.caps_comp, self.sides_draw, self.caps_draw]
    }
}

struct Gpu {
    programs: Programs,
    /// Vertex array without attributes: the core profile needs one bound to draw.
    empty_vao: glow::VertexArray,
    edges: glow::Buffer,
    opposites: glow::Buffer,
    quads: glow::Buffer,
    caps: glow::Buffer,
    /// Sides command at offset 0, caps command at offset 16.
    commands: glow::Buffer,
    layout: Layout,
    max_groups: u32,
}

/// The GPU cull of the prepared scene (made on the first culled frame).
struct Cull {
    gpu: GpuCull,
    /// Per edge record, its piece.
    record_pieces: glow::Buffer,
    /// Per triangle, its piece.
    triangle_pieces: glow::Buffer,
}

/// See the module documentation.
#[derive(Default)]
pub struct CsSilhouette {
    prepared: Option<SceneId>,
    gpu: Option<Gpu>,
    cull: Option<Cull>,
    /// Whether the last frame's volume was culled, and what it drew (with `report`).
    last_culled: bool,
    triangles: usize,
}

/// The edge records of `adj`: `(edge, [A, B, first opposite, count])`, at least one per
/// edge, an edge split every [`MAX_OPPOSITES_PER_RECORD`] opposites.
fn edge_records(adj: &umbra_geom::EdgeAdjacency) -> Vec<(usize, [u32; 4])> {
    let mut records = Vec::with_capacity(adj.len());
    for (e, &[a, b]) in adj.edges.iter().enumerate() {
        let (mut start, end) = (adj.opposite_start[e], adj.opposite_start[e + 1]);
        // At least one record per edge (an edge without opposites contributes nothing).
        loop {
            let n = (end - start).min(MAX_OPPOSITES_PER_RECORD);
            records.push((e, [a, b, start, n]));
            start += n;
            if start >= end {
                break;
            }
        }
    }
    records
}

fn u32_bytes(v: &[u32]) -> &[u8] {
    // SAFETY: u32 has no padding; the slice covers exactly size_of_val(v) initialised bytes.
    unsafe { std::slice::from_raw_parts(v.as_ptr().cast::<u8>(), std::mem::size_of_val(v)) }
}

fn compute_source(body: &str) -> String {
    format!("#version 450 core\n{MULTIPLICITY}\n{body}")
}

impl CsSilhouette {
    /// Unprepared; programs and buffers are made by `prepare`.
    pub fn new() -> Self {
        Self::default()
    }

    /// Buffer sizes of the prepared scene.
    pub fn layout(&self) -> Option<Layout> {
        self.gpu.as_ref().map(|g| g.layout)
    }

    /// The two indirect commands as the GPU left them: `(side vertices, cap vertices)`
    /// (a readback, for tests and statistics; stalls the pipeline).
    pub fn last_counts(&self, gl: &glow::Context) -> Option<(u32, u32)> {
        let g = self.gpu.as_ref()?;
        let mut bytes = [0u8; 2 * COMMAND_BYTES];
        // SAFETY: reads 32 bytes of our own 32-byte command buffer; the barrier makes the
        // shader atomics visible to the read (BUFFER_UPDATE covers glGetBufferSubData).
        unsafe {
            gl.memory_barrier(glow::BUFFER_UPDATE_BARRIER_BIT);
            gl.bind_buffer(glow::COPY_READ_BUFFER, Some(g.commands));
            gl.get_buffer_sub_data(glow::COPY_READ_BUFFER, 0, &mut bytes);
            gl.bind_buffer(glow::COPY_READ_BUFFER, None);
        }
        let word = |i: usize| u32::from_le_bytes([bytes[4 * i], bytes[4 * i + 1], bytes[4 * i + 2], bytes[4 * i + 3]]);
        Some((word(0), word(4)))
    }

    /// The GPU cull of `scene` (prepared): its programs, pyramid and the pieces.
    fn make_cull(&self, gl: &glow::Context, scene: &SceneGpu) -> Result<Cull, GlError> {
        let max_groups = self.gpu.as_ref().map_or(1, |g| g.max_groups);
        let pieces = Pieces::new(scene)?;
        let per_record: Vec<u32> =
            edge_records(scene.adjacency()).into_iter().map(|(e, _)| pieces.per_edge[e]).collect();
        let buffers = crate::methods::hier::buffers::allocate_buffers(
            gl,
            &[4 * per_record.len().max(1), 4 * pieces.per_triangle.len().max(1)],
            &["cs-silhouette record pieces", "cs-silhouette triangle pieces"],
        )?;
        // SAFETY: uploads into our own buffers, sized above.
        unsafe {
            gl.named_buffer_sub_data_u8_slice(buffers[0], 0, u32_bytes(&per_record));
            gl.named_buffer_sub_data_u8_slice(buffers[1], 0, u32_bytes(&pieces.per_triangle));
        }
        match GpuCull::new(gl, &pieces, max_groups) {
            Ok(gpu) => Ok(Cull { gpu, record_pieces: buffers[0], triangle_pieces: buffers[1] }),
            Err(e) => {
                // SAFETY: our own buffers, never handed out.
                unsafe {
                    gl.delete_buffer(buffers[0]);
                    gl.delete_buffer(buffers[1]);
                }
                Err(e)
            }
        }
    }

    fn link_all(gl: &glow::Context) -> Result<Programs, GlError> {
        let frag = face_depth_fragment(FRAG);
        let mut done: Vec<glow::Program> = Vec::new();
        let sides_comp_src = compute_source(SIDES_COMP);
        let caps_comp_src = compute_source(CAPS_COMP);
        let sides_vert_src = format!("#version 450 core\n{MULTIPLICITY}\n{DEPTH}\n{SIDE_PLANE_GLSL}\n{SIDES_VERT}");
        let caps_vert_src = format!("#version 450 core\n{MULTIPLICITY}\n{DEPTH}\n{SIDE_PLANE_GLSL}\n{CAPS_VERT}");
        let specs: [(&str, Vec<ShaderSource<'_>>); 4] = [
            (
                "cs-silhouette sides compute",
                vec![ShaderSource {
                    stage: glow::COMPUTE_SHADER,
                    name: "cs_silhouette/sides.comp.glsl",
                    source: &sides_comp_src,
                }],
            ),
            (
                "cs-silhouette caps compute",
                vec![ShaderSource {
                    stage: glow::COMPUTE_SHADER,
                    name: "cs_silhouette/caps.comp.glsl",
                    source: &caps_comp_src,
                }],
            ),
            (
                "cs-silhouette sides",
                vec![
                    ShaderSource::vertex("cs_silhouette/sides.vert.glsl", &sides_vert_src),
                    ShaderSource::fragment("cs_silhouette/volume.frag.glsl", &frag),
                ],
            ),
            (
                "cs-silhouette caps",
                vec![
                    ShaderSource::vertex("cs_silhouette/caps.vert.glsl", &caps_vert_src),
                    ShaderSource::fragment("cs_silhouette/volume.frag.glsl", &frag),
                ],
            ),
        ];
        for (name, stages) in &specs {
            match link_program(gl, name, stages, &[]) {
                Ok(p) => done.push(p),
                Err(e) => {
                    // SAFETY: programs we created, not used afterwards.
                    unsafe {
                        for p in done {
                            gl.delete_program(p);
                        }
                    }
                    return Err(e);
                }
            }
        }
        Ok(Programs {
            sides_comp: done[0],
            caps_comp: done[1],
            sides_draw: done[2],
            caps_draw: done[3],
            sides_depth: DepthUniforms::locate(gl, done[2]),
            caps_depth: DepthUniforms::locate(gl, done[3]),
        })
    }

    /// Dispatches `count` invocations of the bound compute program in chunks of at most
    /// `max_groups` workgroups, telling the shader where each chunk starts.
    fn dispatch(gl: &glow::Context, program: glow::Program, first_name: &str, count: usize, max_groups: u32) {
        let first = uniform(gl, program, first_name);
        let per_dispatch = max_groups as usize * WORKGROUP as usize;
        let mut start = 0usize;
        while start < count {
            let n = (count - start).min(per_dispatch);
            // SAFETY: the program is current; n.div_ceil(WORKGROUP) <= max_groups.
            unsafe {
                gl.uniform_1_u32(first.as_ref(), start as u32);
                gl.dispatch_compute(n.div_ceil(WORKGROUP as usize) as u32, 1, 1);
            }
            start += n;
        }
    }
}

impl ShadowMethod for CsSilhouette {
    fn silhouette_sides(&self) -> bool {
        true
    }

    fn name(&self) -> &'static str {
        NAME
    }

    fn stages(&self) -> &'static [&'static str] {
        &["receivers", "silhouette", "cap-orientation", "sides", "caps"]
    }

    fn prepare(&mut self, gl: &glow::Context, scene: &SceneGpu) -> Result<(), GlError> {
        self.destroy(gl);
        let mesh = scene.mesh();
        let adj = scene.adjacency();
        // SAFETY: plain limit queries on the current context.
        let (vertex_blocks, max_groups) = unsafe {
            (
                gl.get_parameter_i32(glow::MAX_VERTEX_SHADER_STORAGE_BLOCKS),
                gl.get_parameter_indexed_i32(glow::MAX_COMPUTE_WORK_GROUP_COUNT, 0),
            )
        };
        if vertex_blocks < 2 {
            return Err(GlError::InvalidParams(format!(
                "cs-silhouette needs 2 shader storage blocks in the vertex shader, the driver offers {vertex_blocks}"
            )));
        }
        let max_groups = max_groups.clamp(1, i32::MAX) as u32;

        let edge_words: Vec<u32> = edge_records(adj).into_iter().flat_map(|(_, r)| r).collect();
        let layout = Layout {
            edges: adj.len(),
            records: edge_words.len() / 4,
            opposites: adj.opposites.len(),
            triangles: mesh.triangles.len(),
        };
        // 6 vertices per worst-case quad and per cap must fit one indirect draw's count.
        if u32::try_from(6 * layout.opposites.max(layout.triangles)).is_err() {
            return Err(GlError::InvalidParams(format!(
                "cs-silhouette: {} opposite vertices / {} triangles exceed one indirect draw",
                layout.opposites, layout.triangles
            )));
        }
        checked_size(layout.edge_bytes(), "cs-silhouette edge buffer")?;
        checked_size(layout.opposite_bytes(), "cs-silhouette opposite buffer")?;
        checked_size(layout.quad_bytes(), "cs-silhouette quad buffer")?;
        checked_size(layout.cap_bytes(), "cs-silhouette cap buffer")?;

        let programs = Self::link_all(gl)?;
        // SAFETY: DSA object creation and uploads on the current context; every object is
        // deleted on the error paths.
        unsafe {
            let mut buffers = Vec::new();
            let mut failure = None;
            for what in [
                "cs-silhouette edges",
                "cs-silhouette opposites",
                "cs-silhouette quads",
                "cs-silhouette caps",
                "cs-silhouette commands",
            ] {
                match gl.create_named_buffer() {
                    Ok(b) => buffers.push(b),
                    Err(detail) => {
                        failure = Some(GlError::Create { what, detail });
                        break;
                    }
                }
            }
            let vao = match failure {
                None => match gl.create_named_vertex_array() {
                    Ok(v) => Ok(v),
                    Err(detail) => Err(GlError::Create { what: "cs-silhouette vertex array", detail }),
                },
                Some(e) => Err(e),
            };
            let empty_vao = match vao {
                Ok(v) => v,
                Err(e) => {
                    for b in buffers {
                        gl.delete_buffer(b);
                    }
                    for p in programs.all() {
                        gl.delete_program(p);
                    }
                    return Err(e);
                }
            };
            let [edges, opposites, quads, caps, commands] =
                [buffers[0], buffers[1], buffers[2], buffers[3], buffers[4]];
            // Checked stores: a refused allocation (GL_OUT_OF_MEMORY) is this call's typed
            // error, never an empty buffer counted as ready.
            let stores = [
                // Read-only inputs: STATIC_DRAW (uploaded once, read by every frame).
                (edges, BufferData::Bytes(u32_bytes(&edge_words)), glow::STATIC_DRAW, "cs-silhouette edges"),
                (opposites, BufferData::Bytes(u32_bytes(&adj.opposites)), glow::STATIC_DRAW, "cs-silhouette opposites"),
                // Written and read by the GPU every frame: DYNAMIC_COPY.
                (quads, BufferData::Size(layout.quad_bytes()), glow::DYNAMIC_COPY, "cs-silhouette quads"),
                (caps, BufferData::Size(layout.cap_bytes()), glow::DYNAMIC_COPY, "cs-silhouette caps"),
                (commands, BufferData::Size(2 * COMMAND_BYTES), glow::DYNAMIC_COPY, "cs-silhouette commands"),
            ];
            let stored = stores
                .into_iter()
                .try_for_each(|(b, data, usage, what)| buffer_store(gl, b, BufferApi::Dsa, data, usage, what));
            if let Err(e) = stored {
                for b in buffers {
                    gl.delete_buffer(b);
                }
                gl.delete_vertex_array(empty_vao);
                for p in programs.all() {
                    gl.delete_program(p);
                }
                return Err(e);
            }
            self.gpu = Some(Gpu { programs, empty_vao, edges, opposites, quads, caps, commands, layout, max_groups });
        }
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
        frame.mark(gl, "receivers");
        self.triangles = scene.mesh().triangles.len();
        // The cull, where asked (an orthographic view draws every volume: its far ends cannot
        // lie at infinity, docs/exactness.md "Orthographic views", and this method has no
        // finite ones); a light it cannot cull exactly is drawn whole.
        self.last_culled = false;
        if let (true, false, Some(bounds)) = (frame.volume_cull, frame.is_orthographic(), scene.bounds()) {
            if self.cull.is_none() {
                self.cull = Some(self.make_cull(gl, scene)?);
            }
            let cull = self.cull.as_ref().expect("made above");
            self.last_culled = cull.gpu.run(gl, scene, frame, bounds)?;
        }
        let culled = self.last_culled;
        let cull = self.cull.as_ref();
        let g = self
            .gpu
            .as_ref()
            .ok_or_else(|| GlError::InvalidParams("cs-silhouette: draw_volumes before prepare".into()))?;
        let l = g.layout;
        let caps = !frame.zpass && l.triangles > 0;
        // A directional light's dark cap has zero area: light caps only.
        let vertices_per_cap: u32 = if frame.light[3] == 0.0 { 3 } else { 6 };
        let p = &g.programs;

        frame.mark(gl, "silhouette");
        // SAFETY: our own programs and buffers; the scene's position and index buffers are
        // only read. Dispatch sizes cover exactly the edges / triangles the shaders bound-check.
        unsafe {
            // Barrier 1 (before touching this frame's buffers):
            // - SHADER_STORAGE: the previous frame's vertex shaders READ the quad and cap
            //   records through shader storage; this frame's compute shaders overwrite them.
            //   glMemoryBarrier orders all shader memory transactions issued before it against
            //   those after it, so no record is overwritten while a draw may still read it.
            // - BUFFER_UPDATE: the previous frame's compute shaders WROTE the commands with
            //   atomics; the glNamedBufferSubData reset below must wait for those writes
            //   (otherwise a late atomic could land after the reset).
            gl.memory_barrier(glow::SHADER_STORAGE_BARRIER_BIT | glow::BUFFER_UPDATE_BARRIER_BIT);
            // Reset both commands: count 0, one instance, first 0, base instance 0. An API
            // write: visible to every later command without a barrier.
            let reset: [u32; 8] = [0, 1, 0, 0, 0, 1, 0, 0];
            gl.named_buffer_sub_data_u8_slice(g.commands, 0, u32_bytes(&reset));

            let light = frame.light;
            gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, POSITIONS, Some(scene.position_buffer()));
            if l.edges > 0 {
                // Compute stage: multiplicity per edge and compaction (sides.comp.glsl).
                gl.use_program(Some(p.sides_comp));
                gl.uniform_4_f32_slice(uniform(gl, p.sides_comp, "u_light").as_ref(), &light);
                gl.uniform_1_u32(uniform(gl, p.sides_comp, "u_edge_count").as_ref(), l.records as u32);
                gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, EDGES, Some(g.edges));
                gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, OPPOSITES, Some(g.opposites));
                gl.bind_buffer_range(
                    glow::SHADER_STORAGE_BUFFER,
                    SIDES_COMMAND,
                    Some(g.commands),
                    0,
                    COMMAND_BYTES as i32,
                );
                gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, QUADS, Some(g.quads));
                gl.uniform_1_u32(uniform(gl, p.sides_comp, "u_cull").as_ref(), u32::from(culled));
                if let (true, Some(c)) = (culled, cull) {
                    gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, RECORD_PIECES, Some(c.record_pieces));
                    gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, SIDES_NEEDED, Some(c.gpu.needed));
                }
                Self::dispatch(gl, p.sides_comp, "u_first_edge", l.records, g.max_groups);
            }
        }
        frame.mark(gl, "cap-orientation");
        // SAFETY: as above.
        unsafe {
            if caps {
                // Compute stage: cap orientation per triangle and compaction (caps.comp.glsl).
                gl.use_program(Some(p.caps_comp));
                gl.uniform_4_f32_slice(uniform(gl, p.caps_comp, "u_light").as_ref(), &frame.light);
                gl.uniform_1_u32(uniform(gl, p.caps_comp, "u_triangle_count").as_ref(), l.triangles as u32);
                gl.uniform_1_u32(uniform(gl, p.caps_comp, "u_vertices_per_cap").as_ref(), vertices_per_cap);
                gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, INDICES, Some(scene.index_buffer()));
                gl.bind_buffer_range(
                    glow::SHADER_STORAGE_BUFFER,
                    CAPS_COMMAND,
                    Some(g.commands),
                    COMMAND_BYTES as i32,
                    COMMAND_BYTES as i32,
                );
                gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, CAPS, Some(g.caps));
                gl.uniform_1_u32(uniform(gl, p.caps_comp, "u_cull").as_ref(), u32::from(culled));
                if let (true, Some(c)) = (culled, cull) {
                    gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, TRIANGLE_PIECES, Some(c.triangle_pieces));
                    gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, CAPS_NEEDED, Some(c.gpu.needed));
                }
                Self::dispatch(gl, p.caps_comp, "u_first_triangle", l.triangles, g.max_groups);
            }
            // Barrier 2 (compute results -> draws):
            // - COMMAND: glDrawArraysIndirect sources its vertex counts from the commands the
            //   compute shaders wrote with atomics;
            // - SHADER_STORAGE: the draws' vertex shaders read the quad and cap records the
            //   compute shaders wrote through shader storage.
            gl.memory_barrier(glow::COMMAND_BARRIER_BIT | glow::SHADER_STORAGE_BARRIER_BIT);
        }

        // Counting state: z-fail or z-pass two-sided stencil; reasons in GlState::shadow_volume.
        frame.shadow_volume_state().apply(gl);
        let clip = frame.clip_from_world_f32();
        frame.mark(gl, "sides");
        // SAFETY: our programs, empty vertex array and command buffer; the vertex counts were
        // written by the compute shaders and never exceed the records they wrote.
        unsafe {
            gl.bind_vertex_array(Some(g.empty_vao));
            gl.bind_buffer(glow::DRAW_INDIRECT_BUFFER, Some(g.commands));
            if l.edges > 0 {
                // Vertex stage: side quads from the records (sides.vert.glsl).
                gl.use_program(Some(p.sides_draw));
                gl.uniform_matrix_4_f32_slice(uniform(gl, p.sides_draw, "u_clip_from_world").as_ref(), false, &clip);
                gl.uniform_4_f32_slice(uniform(gl, p.sides_draw, "u_light").as_ref(), &frame.light);
                // The face depth functions every fragment's depth comes from (shared/side_plane.glsl).
                p.sides_depth.set(gl, frame);
                gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, QUADS, Some(g.quads));
                gl.draw_arrays_indirect_offset(glow::TRIANGLES, 0);
            }
        }
        frame.mark(gl, "caps");
        // SAFETY: as above.
        unsafe {
            if caps {
                // Vertex stage: light cap pushed to far + dark cap (caps.vert.glsl).
                gl.use_program(Some(p.caps_draw));
                gl.uniform_matrix_4_f32_slice(uniform(gl, p.caps_draw, "u_clip_from_world").as_ref(), false, &clip);
                gl.uniform_4_f32_slice(uniform(gl, p.caps_draw, "u_light").as_ref(), &frame.light);
                gl.uniform_1_f32(uniform(gl, p.caps_draw, "u_far_clip_z").as_ref(), frame.far_clip_z());
                gl.uniform_1_u32(uniform(gl, p.caps_draw, "u_vertices_per_cap").as_ref(), vertices_per_cap);
                // The face depth functions every fragment's depth comes from (shared/side_plane.glsl).
                p.caps_depth.set(gl, frame);
                gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, CAPS, Some(g.caps));
                gl.draw_arrays_indirect_offset(glow::TRIANGLES, COMMAND_BYTES as i32);
            }
            // Leave no binding of ours behind (the caller's indexed bindings 1-5 and the
            // indirect binding are not restored: the renderer does not use them).
            gl.bind_buffer(glow::DRAW_INDIRECT_BUFFER, None);
            for b in [POSITIONS, EDGES, OPPOSITES, SIDES_COMMAND, QUADS, RECORD_PIECES, SIDES_NEEDED] {
                gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, b, None);
            }
            gl.bind_vertex_array(None);
        }
        Ok(())
    }

    fn culls_volumes(&self) -> bool {
        true
    }

    fn read_drawn_volume(&self, gl: &glow::Context) -> Option<DrawnVolume> {
        let (sides, _) = self.last_counts(gl)?;
        let triangles = match (self.last_culled, &self.cull) {
            (true, Some(c)) => c.gpu.kept(gl) as u64,
            _ => self.triangles as u64,
        };
        // Six vertices per side quad, one quad per unit of |m|.
        Some(DrawnVolume { triangles, edges: u64::from(sides / 6), culled: self.last_culled, clamped: false })
    }

    fn gpu_bytes(&self) -> usize {
        self.gpu.as_ref().map_or(0, |g| g.layout.total_bytes())
            + self.cull.as_ref().map_or(0, |c| {
                c.gpu.gpu_bytes() + 4 * (self.gpu.as_ref().map_or(0, |g| g.layout.records + g.layout.triangles))
            })
    }

    fn destroy(&mut self, gl: &glow::Context) {
        if let Some(c) = self.cull.take() {
            c.gpu.destroy(gl);
            // SAFETY: our own buffers, not used afterwards.
            unsafe {
                gl.delete_buffer(c.record_pieces);
                gl.delete_buffer(c.triangle_pieces);
            }
        }
        if let Some(g) = self.gpu.take() {
            // SAFETY: our own objects, not used afterwards.
            unsafe {
                for p in g.programs.all() {
                    gl.delete_program(p);
                }
                gl.delete_vertex_array(g.empty_vao);
                for b in [g.edges, g.opposites, g.quads, g.caps, g.commands] {
                    gl.delete_buffer(b);
                }
            }
        }
        self.prepared = None;
    }
}
