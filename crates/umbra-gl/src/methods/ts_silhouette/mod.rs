//! `ts-silhouette` and `ts-silhouette-3edge`: silhouette shadow volumes computed in
//! tessellation shaders.
//!
//! Paper 001 (Milet, Kobrtek, Zemčík, "Fast and Robust Tessellation-Based Silhouette
//! Shadows"), Section 2.2-2.3: one patch per edge (Fig. 4, laid out with an element buffer over
//! the extended vertex buffer as in Fig. 5, see [`patches`]); the control shader computes the
//! edge's multiplicity (Alg. 3-4, reference edge) and sets the tessellation levels
//! (`2|m| - 1`, 1); the evaluation shader maps the tessellation coordinates onto `|m|`
//! overlapping side quads (Alg. 5, Eq. 2, Fig. 6). Caps come from a geometry shader oriented
//! by the same test ([`crate::methods::silhouette_caps`]).
//!
//! `ts-silhouette-3edge` is the same pipeline with the older determinism of Pečiva et al. 2013
//! that the paper compares against (Tables 1-4): every triangle tested against the planes
//! through all three of its edges, inconsistent triangles discarded, in sides and caps alike
//! (`silhouette_caps/determinism.glsl`).
//!
//! The paper's multiplicity limit (32, from a tessellation level of 64) does not apply: an edge
//! with more opposite vertices than a patch holds is split into several patches whose
//! sub-multiplicities add up ([`patches`]); the patch capacity `K` respects
//! GL_MAX_PATCH_VERTICES (`3 + K`) and GL_MAX_TESS_GEN_LEVEL (`2K - 1`), queried at prepare.
//!
//! Face depths: every primitive carries its face's window depth function, flat,
//! computed in the control shader, once per patch ([`crate::methods::face_depth`]), which the
//! fragment shader writes as every fragment's `gl_FragDepth` (`shared/face_depth.frag.glsl`:
//! llvmpipe's interpolated depth is NaN or wrong on some faces).
//!
//! Once per mesh ([`ShadowMethod::prepare`]): the edge patches (vertex + element buffer, static),
//! the vertex array, programs. Per light per frame: uniforms, one `glDrawElements(GL_PATCHES)`
//! for the sides, one `glDrawElements(GL_TRIANGLES)` of the scene through the caps' geometry
//! shader (z-fail only).
//!
//! [`ShadowMethod::gpu_bytes`] = [`patch_bytes`] = `12 · (V + K) + 4 · (3 + K) · P` (vertex
//! buffer of `V + K` vec3, element buffer of `P` patches of `3 + K` u32; see [`patches`]).
//!
//! Stages reported: "sides", "caps".

pub mod patches;

use glow::HasContext;
use umbra_geom::EdgeAdjacency;

use crate::error::GlError;
use crate::gpu_buffer::{buffer_store, checked_size, BufferApi, BufferData};
use crate::methods::face_depth::DepthUniforms;
use crate::methods::method::{ShadowMethod, VolumeFrame};
use crate::methods::silhouette_caps::{fragment_source, variant_defines, with_prelude, SilhouetteCaps};
use crate::program::{link_program, uniform, ShaderSource};
use crate::scene::{SceneGpu, SceneId};

use patches::{choose_capacity, ts_capacity_limit, EdgePatches, MIN_MAX_PATCH_VERTICES, MIN_MAX_TESS_GEN_LEVEL};

/// Registry name.
pub const NAME: &str = "ts-silhouette";
/// Registry name of the three-edges-per-patch variant.
pub const NAME_3EDGE: &str = "ts-silhouette-3edge";

const SIDES_VERT: &str = include_str!("sides.vert.glsl");
const SIDES_TESC: &str = include_str!("sides.tesc.glsl");
const SIDES_TESE: &str = include_str!("sides.tese.glsl");

/// Bytes of the ts-silhouette input for `adj`: extended vertex buffer + element buffer,
/// `12 · (V + K) + 4 · (3 + K) · P`, with `V` = 1 + the largest vertex index in `adj`,
/// `K = min(max_e n_e, 29)` opposite slots per patch (29: the most a patch holds under the
/// GL 4.0 minimums GL_MAX_PATCH_VERTICES 32 and GL_MAX_TESS_GEN_LEVEL 64) and
/// `P = Σ_edges ceil(n_e / K)` patches (the number of edges, unless some edge has more than 29
/// opposite vertices). Equals [`TsSilhouette`]'s `gpu_bytes()` after `prepare` on every GL
/// meeting those minimums (every GL 4.x).
pub fn patch_bytes(adj: &EdgeAdjacency) -> usize {
    let k = choose_capacity(adj, ts_capacity_limit(MIN_MAX_PATCH_VERTICES, MIN_MAX_TESS_GEN_LEVEL));
    patches::layout_bytes(patches::vertex_count(adj), patches::patch_count(adj, k), k)
}

/// The patch capacity this GL allows: the GL 4.0 minimums, or less if the implementation
/// reports less (then [`patch_bytes`] no longer predicts `gpu_bytes`).
fn capacity_limit(gl: &glow::Context) -> Result<usize, GlError> {
    // SAFETY: plain integer queries on the current context.
    let (max_patch_vertices, max_level) =
        unsafe { (gl.get_parameter_i32(glow::MAX_PATCH_VERTICES), gl.get_parameter_i32(glow::MAX_TESS_GEN_LEVEL)) };
    let limit = ts_capacity_limit(max_patch_vertices, max_level)
        .min(ts_capacity_limit(MIN_MAX_PATCH_VERTICES, MIN_MAX_TESS_GEN_LEVEL));
    if limit == 0 {
        return Err(GlError::InvalidParams(format!(
            "ts-silhouette: GL_MAX_PATCH_VERTICES {max_patch_vertices} / GL_MAX_TESS_GEN_LEVEL {max_level} leave no room for an opposite vertex"
        )));
    }
    Ok(limit)
}

struct Program {
    program: glow::Program,
    u_clip_from_world: Option<glow::UniformLocation>,
    u_light: Option<glow::UniformLocation>,
    depth: DepthUniforms,
}

struct Buffers {
    vao: glow::VertexArray,
    vertices: glow::Buffer,
    elements: glow::Buffer,
    /// `3 + K`.
    patch_vertices: i32,
    index_count: i32,
    bytes: usize,
}

/// See the module documentation.
pub struct TsSilhouette {
    three_edge: bool,
    prepared: Option<SceneId>,
    program: Option<Program>,
    buffers: Option<Buffers>,
    caps: SilhouetteCaps,
}

impl TsSilhouette {
    /// `ts-silhouette` (reference edge, paper 001).
    pub fn new() -> Self {
        Self::with_three_edge(false)
    }

    /// `ts-silhouette-3edge` (Pečiva 2013's 3-edge test).
    pub fn new_three_edge() -> Self {
        Self::with_three_edge(true)
    }

    fn with_three_edge(three_edge: bool) -> Self {
        Self { three_edge, prepared: None, program: None, buffers: None, caps: SilhouetteCaps::new(three_edge) }
    }

    /// Opposite vertices per patch (`K`) of the prepared mesh.
    pub fn patch_capacity(&self) -> Option<usize> {
        self.buffers.as_ref().map(|b| b.patch_vertices as usize - patches::HEADER_SLOTS)
    }

    fn link(&self, gl: &glow::Context) -> Result<Program, GlError> {
        let (vert, tesc, tese, frag) =
            (with_prelude(SIDES_VERT), with_prelude(SIDES_TESC), with_prelude(SIDES_TESE), fragment_source());
        let program = link_program(
            gl,
            if self.three_edge { "ts-silhouette-3edge sides" } else { "ts-silhouette sides" },
            &[
                ShaderSource::vertex("ts_silhouette/sides.vert.glsl", &vert),
                ShaderSource { stage: glow::TESS_CONTROL_SHADER, name: "ts_silhouette/sides.tesc.glsl", source: &tesc },
                ShaderSource {
                    stage: glow::TESS_EVALUATION_SHADER,
                    name: "ts_silhouette/sides.tese.glsl",
                    source: &tese,
                },
                ShaderSource::fragment("silhouette_caps/volume.frag.glsl", &frag),
            ],
            variant_defines(self.three_edge),
        )?;
        Ok(Program {
            u_clip_from_world: uniform(gl, program, "u_clip_from_world"),
            u_light: uniform(gl, program, "u_light"),
            depth: DepthUniforms::locate(gl, program),
            program,
        })
    }

    fn delete_buffers(&mut self, gl: &glow::Context) {
        if let Some(b) = self.buffers.take() {
            // SAFETY: our own objects, not used afterwards.
            unsafe {
                gl.delete_vertex_array(b.vao);
                gl.delete_buffer(b.vertices);
                gl.delete_buffer(b.elements);
            }
        }
    }
}

impl Default for TsSilhouette {
    fn default() -> Self {
        Self::new()
    }
}

fn as_bytes<T: Copy>(v: &[T]) -> &[u8] {
    // SAFETY: T is [f32; 3] or u32 (no padding, every byte initialised); the slice covers
    // exactly size_of_val(v) bytes.
    unsafe { std::slice::from_raw_parts(v.as_ptr().cast::<u8>(), std::mem::size_of_val(v)) }
}

/// Uploads the patches into a new vertex buffer, element buffer and vertex array.
fn upload(gl: &glow::Context, p: &EdgePatches) -> Result<Buffers, GlError> {
    let vertex_bytes = as_bytes(&p.vertices);
    let element_bytes = as_bytes(&p.elements);
    checked_size(vertex_bytes.len(), "ts-silhouette vertex buffer")?;
    checked_size(element_bytes.len(), "ts-silhouette element buffer")?;
    let index_count = i32::try_from(p.elements.len())
        .map_err(|_| GlError::InvalidParams(format!("{} patch indices exceed one draw call", p.elements.len())))?;
    // SAFETY: DSA creation and static uploads on the current context; every object created
    // here is deleted if a later creation or store fails.
    unsafe {
        let vertices = gl
            .create_named_buffer()
            .map_err(|detail| GlError::Create { what: "ts-silhouette vertex buffer", detail })?;
        let elements = match gl.create_named_buffer() {
            Ok(b) => b,
            Err(detail) => {
                gl.delete_buffer(vertices);
                return Err(GlError::Create { what: "ts-silhouette element buffer", detail });
            }
        };
        let vao = match gl.create_named_vertex_array() {
            Ok(v) => v,
            Err(detail) => {
                gl.delete_buffer(vertices);
                gl.delete_buffer(elements);
                return Err(GlError::Create { what: "ts-silhouette vertex array", detail });
            }
        };
        // Static: built once per mesh, read by every frame.
        // A store the driver refuses is GlError::OutOfMemory: nothing of ours is left behind.
        let stores = buffer_store(
            gl,
            vertices,
            BufferApi::Dsa,
            BufferData::Bytes(vertex_bytes),
            glow::STATIC_DRAW,
            "ts-silhouette vertex buffer",
        )
        .and_then(|()| {
            buffer_store(
                gl,
                elements,
                BufferApi::Dsa,
                BufferData::Bytes(element_bytes),
                glow::STATIC_DRAW,
                "ts-silhouette element buffer",
            )
        });
        if let Err(e) = stores {
            gl.delete_vertex_array(vao);
            gl.delete_buffer(vertices);
            gl.delete_buffer(elements);
            return Err(e);
        }
        // Attribute 0: vec3 (position, or count in x), tightly packed.
        gl.vertex_array_vertex_buffer(vao, 0, Some(vertices), 0, patches::VERTEX_BYTES as i32);
        gl.vertex_array_attrib_format_f32(vao, 0, 3, glow::FLOAT, false, 0);
        gl.vertex_array_attrib_binding_f32(vao, 0, 0);
        gl.enable_vertex_array_attrib(vao, 0);
        gl.vertex_array_element_buffer(vao, Some(elements));
        Ok(Buffers { vao, vertices, elements, patch_vertices: p.stride() as i32, index_count, bytes: p.bytes() })
    }
}

impl ShadowMethod for TsSilhouette {
    fn silhouette_sides(&self) -> bool {
        true
    }

    fn name(&self) -> &'static str {
        if self.three_edge {
            NAME_3EDGE
        } else {
            NAME
        }
    }

    fn stages(&self) -> &'static [&'static str] {
        &["sides", "caps"]
    }

    fn prepare(&mut self, gl: &glow::Context, scene: &SceneGpu) -> Result<(), GlError> {
        self.prepared = None;
        let limit = capacity_limit(gl)?;
        if self.program.is_none() {
            self.program = Some(self.link(gl)?);
        }
        self.caps.prepare(gl)?;
        let adj = scene.adjacency();
        let layout = EdgePatches::build(scene.mesh(), adj, choose_capacity(adj, limit))?;
        self.delete_buffers(gl);
        self.buffers = Some(upload(gl, &layout)?);
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
        let (Some(program), Some(buffers)) = (self.program.as_ref(), self.buffers.as_ref()) else {
            return Err(GlError::InvalidParams(format!("{}: draw_volumes before prepare", self.name())));
        };
        // Counting state: z-fail or z-pass two-sided stencil, depth clamp, no colour/depth
        // writes; the reason for every field is in GlState::shadow_volume.
        frame.shadow_volume_state().apply(gl);
        // SAFETY: our program, vertex array and element buffer; the draw covers exactly the
        // uploaded indices, all < V + K.
        unsafe {
            gl.use_program(Some(program.program));
            gl.uniform_matrix_4_f32_slice(program.u_clip_from_world.as_ref(), false, &frame.clip_from_world_f32());
            gl.uniform_4_f32_slice(program.u_light.as_ref(), &frame.light);
        }
        // The face depth functions every fragment's depth comes from (shared/side_plane.glsl).
        program.depth.set(gl, frame);
        // SAFETY: as above.
        unsafe {
            gl.bind_vertex_array(Some(buffers.vao));
            // Every patch is one edge (or part of one): A, B, count vertex, K opposite slots.
            gl.patch_parameter_i32(glow::PATCH_VERTICES, buffers.patch_vertices);
            frame.mark(gl, "sides");
            if buffers.index_count > 0 {
                gl.draw_elements(glow::PATCHES, buffers.index_count, glow::UNSIGNED_INT, 0);
            }
        }
        frame.mark(gl, "caps");
        self.caps.draw(gl, scene, frame)
    }

    fn gpu_bytes(&self) -> usize {
        self.buffers.as_ref().map_or(0, |b| b.bytes) + self.caps.gpu_bytes()
    }

    fn destroy(&mut self, gl: &glow::Context) {
        self.delete_buffers(gl);
        if let Some(p) = self.program.take() {
            // SAFETY: our own program, not used afterwards.
            unsafe { gl.delete_program(p.program) };
        }
        self.caps.destroy(gl);
        self.prepared = None;
    }
}

#[cfg(test)]
pub(crate) mod tests;
