//! The GPU cull of `cs-silhouette`: per light and frame, which pieces of the caster (triangles
//! joined across shared edges, [`caster_pieces`]) may shadow a visible sample, found without a
//! read-back. The frame's visible samples are scattered into the light's receiver map
//! (`receivers/`, as `cpu-silhouette`'s cull does, but into this module's buffer), then
//! `cull.comp.glsl` raises the eye's near pyramid under z-pass, builds the map's max pyramid,
//! and marks the pieces a triangle of which has a cell beyond it in its frustum; the
//! silhouette and cap passes skip the other pieces' edges and triangles.
//!
//! CC shadow volumes (Lloyd, Wendt, Govindaraju, Manocha, EGSR 2004, Section 4.1), culling
//! only: the volumes kept are drawn whole, to infinity. The twin of umbra-wgpu's
//! `methods/gpu_cull.rs`; the proof: docs/exactness.md, "Volumes culled on the GPU".

use glow::HasContext;
use umbra_geom::camera::zpass_start_points;
use umbra_geom::receivers::{encode, gpu_cull_level_offsets, gpu_cull_words, ReceiverGrid, RECEIVER_SIDE};
use umbra_geom::silhouette::{caster_pieces, edge_pieces, TriangleSlots};
use umbra_geom::Aabb;

use crate::error::GlError;
use crate::gpu_buffer::{buffer_store, BufferApi, BufferData};
use crate::methods::method::VolumeFrame;
use crate::methods::receivers::{ReceiverPass, RECEIVERS_BINDING};
use crate::program::{link_program, uniform, ShaderSource};
use crate::scene::SceneGpu;

const CULL_COMP: &str = include_str!("cull.comp.glsl");
const RECEIVER_CELL_GLSL: &str = include_str!("../shared/receiver_cell.glsl");

/// Levels of the pyramid: the map's side, halved down to one cell.
const LEVELS: u32 = RECEIVER_SIDE.trailing_zeros() + 1;

/// `local_size_x` of the cull's compute shaders.
const WORKGROUP: u32 = 256;

// Shader-storage bindings of cull.comp.glsl (the pyramid at the scatter's own binding).
const POSITIONS: u32 = 1;
const INDICES: u32 = 2;
const PIECES: u32 = 3;
const NEEDED: u32 = 4;

/// Word offset of every level of the pyramid, then its words.
fn level_offsets() -> Vec<u32> {
    gpu_cull_level_offsets(RECEIVER_SIDE)
}

/// The pieces of one mesh, per triangle and per edge.
pub(crate) struct Pieces {
    /// Per triangle, its piece.
    pub(crate) per_triangle: Vec<u32>,
    /// Per edge of the scene's adjacency, its piece.
    pub(crate) per_edge: Vec<u32>,
    /// The number of pieces.
    pub(crate) count: u32,
}

impl Pieces {
    /// The pieces of `scene`'s mesh.
    pub(crate) fn new(scene: &SceneGpu) -> Result<Self, GlError> {
        let adj = scene.adjacency();
        let slots = TriangleSlots::build(scene.mesh(), adj)
            .map_err(|e| GlError::InvalidParams(format!("cs-silhouette cull: {e}")))?;
        let (per_triangle, count) = caster_pieces(scene.mesh().triangles.len(), adj, &slots);
        let per_edge = edge_pieces(adj, &slots, &per_triangle);
        Ok(Self { per_triangle, per_edge, count })
    }
}

/// See the module documentation.
pub(crate) struct GpuCull {
    /// Programs: raise, reduce, need, count.
    programs: [glow::Program; 4],
    /// The scatter (its own buffer unused here).
    receivers: ReceiverPass,
    /// The map and its pyramid.
    cells: glow::Buffer,
    /// Per triangle its piece; word 0 the triangles kept, 1 + p piece p needed.
    pieces: glow::Buffer,
    pub(crate) needed: glow::Buffer,
    /// `4 (1 + pieces)` zero bytes: the flags cleared.
    zeros: Vec<u8>,
    /// Bytes held by the pyramid and the pieces.
    bytes: usize,
    max_groups: u32,
}

impl GpuCull {
    /// Links the programs and uploads `pieces`.
    pub(crate) fn new(gl: &glow::Context, pieces: &Pieces, max_groups: u32) -> Result<Self, GlError> {
        let mut programs = Vec::new();
        let mut failure = None;
        for (define, name) in [
            ("UMBRA_CULL_RAISE", "cull raise"),
            ("UMBRA_CULL_REDUCE", "cull reduce"),
            ("UMBRA_CULL_NEED", "cull need"),
            ("UMBRA_CULL_COUNT", "cull count"),
        ] {
            let source = format!("#version 450 core\n#define {define}\n{RECEIVER_CELL_GLSL}\n{CULL_COMP}");
            let stage = ShaderSource { stage: glow::COMPUTE_SHADER, name: "gpu_cull/cull.comp.glsl", source: &source };
            match link_program(gl, name, &[stage], &[]) {
                Ok(p) => programs.push(p),
                Err(e) => {
                    failure = Some(e);
                    break;
                }
            }
        }
        let delete_programs = |programs: &[glow::Program]| {
            // SAFETY: programs we created, not used afterwards.
            unsafe {
                for &p in programs {
                    gl.delete_program(p);
                }
            }
        };
        if let Some(e) = failure {
            delete_programs(&programs);
            return Err(e);
        }
        let receivers = match ReceiverPass::new(gl) {
            Ok(r) => r,
            Err(e) => {
                delete_programs(&programs);
                return Err(e);
            }
        };
        let cells_bytes = 4 * level_offsets()[LEVELS as usize] as usize;
        let flags_bytes = 4 * (1 + pieces.count as usize);
        let buffers = match crate::methods::hier::buffers::allocate_buffers(
            gl,
            &[cells_bytes, 4 * pieces.per_triangle.len().max(1), flags_bytes],
            &["cull pyramid", "cull pieces", "cull needed"],
        ) {
            Ok(b) => b,
            Err(e) => {
                delete_programs(&programs);
                receivers.destroy(gl);
                return Err(e);
            }
        };
        let words: Vec<u8> = pieces.per_triangle.iter().flat_map(|w| w.to_le_bytes()).collect();
        if !words.is_empty() {
            if let Err(e) = buffer_store(
                gl,
                buffers[1],
                BufferApi::Dsa,
                BufferData::Bytes(&words),
                glow::STATIC_DRAW,
                "cull pieces",
            ) {
                delete_programs(&programs);
                receivers.destroy(gl);
                // SAFETY: our own buffers, never handed out.
                unsafe {
                    for b in buffers {
                        gl.delete_buffer(b);
                    }
                }
                return Err(e);
            }
        }
        Ok(Self {
            programs: [programs[0], programs[1], programs[2], programs[3]],
            receivers,
            cells: buffers[0],
            pieces: buffers[1],
            needed: buffers[2],
            zeros: vec![0; flags_bytes],
            bytes: cells_bytes + 4 * pieces.per_triangle.len().max(1),
            max_groups,
        })
    }

    /// Bytes of GPU memory held.
    pub(crate) fn gpu_bytes(&self) -> usize {
        self.bytes + self.zeros.len() + self.receivers.gpu_bytes()
    }

    /// Dispatches `count` invocations of `program` (current) in chunks of at most
    /// `max_groups` workgroups.
    fn dispatch(&self, gl: &glow::Context, program: glow::Program, count: usize) {
        let first = uniform(gl, program, "u_first");
        let per_dispatch = self.max_groups as usize * WORKGROUP as usize;
        let mut start = 0usize;
        // SAFETY: uniform writes and dispatches on the current program.
        unsafe {
            gl.uniform_1_u32(uniform(gl, program, "u_count").as_ref(), count as u32);
            while start < count {
                let n = (count - start).min(per_dispatch);
                gl.uniform_1_u32(first.as_ref(), start as u32);
                gl.dispatch_compute(n.div_ceil(WORKGROUP as usize) as u32, 1, 1);
                start += n;
            }
        }
    }

    /// The cull of `frame`'s light (the depth buffer bound with the frame's target): afterwards
    /// [`GpuCull::needed`] marks the pieces needed and word 0 counts their triangles, and the
    /// writes are visible to later shader-storage reads. `false` (nothing done) where the cull
    /// cannot be exact for this light: under z-pass, a point light's near pyramid that no
    /// one face of the map bounds.
    pub(crate) fn run(
        &self,
        gl: &glow::Context,
        scene: &SceneGpu,
        frame: &VolumeFrame<'_>,
        bounds: Aabb,
    ) -> Result<bool, GlError> {
        let light = frame.light;
        let grid = ReceiverGrid::new(light, bounds, RECEIVER_SIDE);
        // z-pass starts every count at the eye's near rectangle: its cells are raised to its
        // farthest point, so a triangle whose frustum holds a point of it is kept (as
        // cpu-silhouette's ReceiverMap::raise_hull).
        let raise = if frame.zpass {
            let near = zpass_start_points(&frame.clip_from_world.inverse(), frame.eye, frame.depth_convention());
            match grid.hull_raise(&near) {
                Some(r) => Some(r),
                None => return Ok(false),
            }
        } else {
            None
        };
        self.receivers.scatter(gl, scene, frame, &grid, self.cells);
        let offsets = level_offsets();
        let [raise_p, reduce, need, count] = self.programs;
        let triangles = scene.mesh().triangles.len();
        // SAFETY: our programs and buffers; the scene's position and index buffers are only
        // read; every dispatch covers exactly the items its shader bound-checks.
        unsafe {
            // Reason: no piece is needed and no triangle kept until this light's passes say so
            // (an API write, ordered before later commands).
            gl.named_buffer_sub_data_u8_slice(self.needed, 0, &self.zeros);
            // Reason: the scatter's atomics must land before the pyramid reads them.
            gl.memory_barrier(glow::SHADER_STORAGE_BARRIER_BIT);
            gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, RECEIVERS_BINDING, Some(self.cells));
            gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, POSITIONS, Some(scene.position_buffer()));
            gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, INDICES, Some(scene.index_buffer()));
            gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, PIECES, Some(self.pieces));
            gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, NEEDED, Some(self.needed));
            let common = |p: glow::Program| {
                gl.use_program(Some(p));
                gl.uniform_1_u32(uniform(gl, p, "u_side").as_ref(), grid.side());
                gl.uniform_1_u32(uniform(gl, p, "u_faces").as_ref(), grid.faces());
                gl.uniform_1_u32(uniform(gl, p, "u_top").as_ref(), LEVELS - 1);
                let mut level_offset = [0u32; 16];
                level_offset[..LEVELS as usize].copy_from_slice(&offsets[..LEVELS as usize]);
                gl.uniform_1_u32_slice(uniform(gl, p, "u_level_offset").as_ref(), &level_offset);
            };
            if let Some((face, rect, value)) = raise {
                common(raise_p);
                gl.uniform_4_u32_slice(uniform(gl, raise_p, "u_raise_rect").as_ref(), &rect);
                gl.uniform_1_u32(uniform(gl, raise_p, "u_raise_face").as_ref(), face);
                gl.uniform_1_u32(uniform(gl, raise_p, "u_raise_word").as_ref(), encode(value));
                self.dispatch(gl, raise_p, ((rect[1] - rect[0] + 1) * (rect[3] - rect[2] + 1)) as usize);
                // Reason: the raised cells before the pyramid reads them.
                gl.memory_barrier(glow::SHADER_STORAGE_BARRIER_BIT);
            }
            common(reduce);
            for level in 1..LEVELS {
                gl.uniform_1_u32(uniform(gl, reduce, "u_level").as_ref(), level);
                let side = (RECEIVER_SIDE >> level) as usize;
                self.dispatch(gl, reduce, grid.faces() as usize * side * side);
                // Reason: each level reads the one before.
                gl.memory_barrier(glow::SHADER_STORAGE_BARRIER_BIT);
            }
            common(need);
            gl.uniform_4_f32_slice(uniform(gl, need, "u_light").as_ref(), &light);
            if let ReceiverGrid::Flat { origin, u, v, travel, lo, scale, .. } = grid {
                gl.uniform_3_f32_slice(uniform(gl, need, "u_origin").as_ref(), &origin);
                gl.uniform_3_f32_slice(uniform(gl, need, "u_u").as_ref(), &u);
                gl.uniform_3_f32_slice(uniform(gl, need, "u_v").as_ref(), &v);
                gl.uniform_3_f32_slice(uniform(gl, need, "u_travel").as_ref(), &travel);
                gl.uniform_4_f32_slice(uniform(gl, need, "u_lo_scale").as_ref(), &[lo[0], lo[1], scale[0], scale[1]]);
                // Twice ReceiverMap::cells_of's widening, as umbra-wgpu's uniform has it.
                let words = gpu_cull_words(&grid, None);
                let margin = |j: usize| f32::from_bits(words[20 + j]);
                gl.uniform_2_f32_slice(uniform(gl, need, "u_margin").as_ref(), &[margin(0), margin(1)]);
            }
            self.dispatch(gl, need, triangles);
            // Reason: every piece's flag before the count reads them.
            gl.memory_barrier(glow::SHADER_STORAGE_BARRIER_BIT);
            gl.use_program(Some(count));
            self.dispatch(gl, count, triangles);
            // Reason: the flags before the silhouette and cap passes read them.
            gl.memory_barrier(glow::SHADER_STORAGE_BARRIER_BIT);
            for b in [RECEIVERS_BINDING, PIECES, NEEDED] {
                gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, b, None);
            }
        }
        Ok(true)
    }

    /// The triangles kept by the last [`GpuCull::run`] (a read-back: a stall).
    pub(crate) fn kept(&self, gl: &glow::Context) -> u32 {
        crate::methods::hier::buffers::read_words(gl, self.needed, 0, 1)[0]
    }

    /// Frees the programs and buffers.
    pub(crate) fn destroy(self, gl: &glow::Context) {
        // SAFETY: our own objects, not used afterwards.
        unsafe {
            for p in self.programs {
                gl.delete_program(p);
            }
            for b in [self.cells, self.pieces, self.needed] {
                gl.delete_buffer(b);
            }
        }
        self.receivers.destroy(gl);
    }
}
