//! `gs-silhouette` and `gs-silhouette-3edge`: silhouette shadow volumes computed in a geometry
//! shader.
//!
//! Paper 001, Section 2.2 (multiplicity with the reference edge, Alg. 3-4, sides extruded with
//! Eq. 2) in a geometry shader: the "GS" columns of Tables 1-5 and 8-9 the tessellation method
//! is compared with. One input point per edge patch, `|m|` quads out. `gs-silhouette-3edge`
//! uses Pečiva et al. 2013's older 3-edge test instead (Tables 1-4, first column of each pair).
//! Caps: the shared geometry-shader caps ([`crate::methods::silhouette_caps`]), oriented by the
//! same test.
//!
//! Input: the edge patches of ts-silhouette ([`crate::methods::ts_silhouette::patches`]: the
//! extended vertex buffer and the element buffer of Fig. 5), read by `gl_PrimitiveIDIn` from two
//! shader storage buffers (bindings [`ELEMENTS_BINDING`], [`VERTICES_BINDING`]). Each quad is a
//! 4-vertex strip whose two triangles are cpu-silhouette's, both starting on the edge (see
//! `sides.geom.glsl`). An edge with more opposite vertices than one invocation may output
//! quads for is split into several patches whose sub-multiplicities add up, so any
//! multiplicity works: the capacity `K` respects GL_MAX_GEOMETRY_OUTPUT_VERTICES (`4K`) and
//! GL_MAX_GEOMETRY_TOTAL_OUTPUT_COMPONENTS (`40K`: gl_Position and the face depth), queried at
//! prepare; the program is compiled for the chosen `K` (`max_vertices = 4K`).
//!
//! Face depths: every primitive carries its face's window depth function, flat,
//! computed in the geometry shader, once per patch ([`crate::methods::face_depth`]), which the
//! fragment shader writes as every fragment's `gl_FragDepth` (`shared/face_depth.frag.glsl`:
//! llvmpipe's interpolated depth is NaN or wrong on some faces).
//!
//! Once per mesh ([`ShadowMethod::prepare`]): patches, two static storage buffers, programs.
//! Per light per frame: uniforms, `glDrawArrays(GL_POINTS, 0, P)` for the sides, the caps draw
//! (z-fail only).
//!
//! [`ShadowMethod::gpu_bytes`] = `12 · (V + K) + 4 · (3 + K) · P`, the same formula as
//! [`crate::methods::ts_silhouette::patch_bytes`], but with the geometry-shader limit on `K`
//! (25 at the GL minimums, each output vertex carrying its face depth, instead of 29): the
//! same buffers as ts-silhouette unless some edge has more than 25 opposite vertices.
//!
//! Stages reported: "sides", "caps".

use glow::HasContext;

use crate::error::GlError;
use crate::gpu_buffer::{buffer_store, checked_size, BufferApi, BufferData};
use crate::methods::face_depth::DepthUniforms;
use crate::methods::method::{ShadowMethod, VolumeFrame};
use crate::methods::silhouette_caps::{fragment_source, with_prelude, SilhouetteCaps, THREE_EDGE_DEFINE};
use crate::methods::ts_silhouette::patches::{
    choose_capacity, gs_capacity_limit, EdgePatches, MIN_MAX_GEOMETRY_OUTPUT_VERTICES,
    MIN_MAX_GEOMETRY_TOTAL_OUTPUT_COMPONENTS,
};
use crate::program::{link_program, uniform, ShaderSource};
use crate::scene::{SceneGpu, SceneId};

/// Registry name.
pub const NAME: &str = "gs-silhouette";
/// Registry name of the three-edges-per-invocation variant.
pub const NAME_3EDGE: &str = "gs-silhouette-3edge";

/// Shader-storage binding of the element buffer (u32 per slot).
pub const ELEMENTS_BINDING: u32 = 1;
/// Shader-storage binding of the vertex buffer (vec3 as 3 floats).
pub const VERTICES_BINDING: u32 = 2;

const SIDES_VERT: &str = include_str!("sides.vert.glsl");
const SIDES_GEOM: &str = include_str!("sides.geom.glsl");

/// Patch capacity allowed by this GL's geometry-shader limits, capped at what the GL 3.2
/// minimums allow (25 quads per invocation).
fn capacity_limit(gl: &glow::Context) -> Result<usize, GlError> {
    // SAFETY: plain integer queries on the current context.
    let (max_vertices, max_components, storage_blocks) = unsafe {
        (
            gl.get_parameter_i32(glow::MAX_GEOMETRY_OUTPUT_VERTICES),
            gl.get_parameter_i32(glow::MAX_GEOMETRY_TOTAL_OUTPUT_COMPONENTS),
            gl.get_parameter_i32(glow::MAX_GEOMETRY_SHADER_STORAGE_BLOCKS),
        )
    };
    if storage_blocks < 2 {
        return Err(GlError::InvalidParams(format!(
            "gs-silhouette needs 2 shader storage blocks in the geometry stage, GL_MAX_GEOMETRY_SHADER_STORAGE_BLOCKS is {storage_blocks}"
        )));
    }
    let limit = gs_capacity_limit(max_vertices, max_components)
        .min(gs_capacity_limit(MIN_MAX_GEOMETRY_OUTPUT_VERTICES, MIN_MAX_GEOMETRY_TOTAL_OUTPUT_COMPONENTS));
    if limit == 0 {
        return Err(GlError::InvalidParams(format!(
            "gs-silhouette: GL_MAX_GEOMETRY_OUTPUT_VERTICES {max_vertices} / GL_MAX_GEOMETRY_TOTAL_OUTPUT_COMPONENTS {max_components} leave no room for one quad"
        )));
    }
    Ok(limit)
}

struct Program {
    program: glow::Program,
    /// `K` the program was compiled for.
    capacity: usize,
    u_clip_from_world: Option<glow::UniformLocation>,
    u_light: Option<glow::UniformLocation>,
    depth: DepthUniforms,
}

struct Buffers {
    /// Empty vertex array: the points carry no attributes, but core GL draws need one bound.
    vao: glow::VertexArray,
    vertices: glow::Buffer,
    elements: glow::Buffer,
    patch_count: i32,
    bytes: usize,
}

/// See the module documentation.
pub struct GsSilhouette {
    three_edge: bool,
    prepared: Option<SceneId>,
    program: Option<Program>,
    buffers: Option<Buffers>,
    caps: SilhouetteCaps,
}

impl GsSilhouette {
    /// `gs-silhouette` (reference edge, paper 001).
    pub fn new() -> Self {
        Self::with_three_edge(false)
    }

    /// `gs-silhouette-3edge` (Pečiva 2013's 3-edge test).
    pub fn new_three_edge() -> Self {
        Self::with_three_edge(true)
    }

    fn with_three_edge(three_edge: bool) -> Self {
        Self { three_edge, prepared: None, program: None, buffers: None, caps: SilhouetteCaps::new(three_edge) }
    }

    /// Opposite vertices per patch (`K`) of the prepared mesh.
    pub fn patch_capacity(&self) -> Option<usize> {
        self.buffers.as_ref().and(self.program.as_ref()).map(|p| p.capacity)
    }

    fn link(&self, gl: &glow::Context, capacity: usize) -> Result<Program, GlError> {
        let (vert, geom, frag) = (with_prelude(SIDES_VERT), with_prelude(SIDES_GEOM), fragment_source());
        let defines = [
            format!("UMBRA_PATCH_CAPACITY {capacity}"),
            format!("UMBRA_PATCH_STRIDE {}", capacity + 3),
            format!("UMBRA_ELEMENTS_BINDING {ELEMENTS_BINDING}"),
            format!("UMBRA_VERTICES_BINDING {VERTICES_BINDING}"),
        ];
        let mut defines: Vec<&str> = defines.iter().map(String::as_str).collect();
        if self.three_edge {
            defines.push(THREE_EDGE_DEFINE);
        }
        let program = link_program(
            gl,
            if self.three_edge { "gs-silhouette-3edge sides" } else { "gs-silhouette sides" },
            &[
                ShaderSource::vertex("gs_silhouette/sides.vert.glsl", &vert),
                ShaderSource { stage: glow::GEOMETRY_SHADER, name: "gs_silhouette/sides.geom.glsl", source: &geom },
                ShaderSource::fragment("silhouette_caps/volume.frag.glsl", &frag),
            ],
            &defines,
        )?;
        Ok(Program {
            capacity,
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

    fn delete_program(&mut self, gl: &glow::Context) {
        if let Some(p) = self.program.take() {
            // SAFETY: our own program, not used afterwards.
            unsafe { gl.delete_program(p.program) };
        }
    }
}

impl Default for GsSilhouette {
    fn default() -> Self {
        Self::new()
    }
}

fn as_bytes<T: Copy>(v: &[T]) -> &[u8] {
    // SAFETY: T is [f32; 3] or u32 (no padding, every byte initialised); the slice covers
    // exactly size_of_val(v) bytes.
    unsafe { std::slice::from_raw_parts(v.as_ptr().cast::<u8>(), std::mem::size_of_val(v)) }
}

fn non_empty(b: &[u8]) -> &[u8] {
    const FOUR_ZEROS: &[u8] = &[0; 4];
    if b.is_empty() {
        FOUR_ZEROS
    } else {
        b
    }
}

/// Uploads the patches into two new storage buffers (plus the empty vertex array).
fn upload(gl: &glow::Context, p: &EdgePatches) -> Result<Buffers, GlError> {
    let vertex_bytes = as_bytes(&p.vertices);
    let element_bytes = as_bytes(&p.elements);
    checked_size(vertex_bytes.len(), "gs-silhouette vertex buffer")?;
    checked_size(element_bytes.len(), "gs-silhouette element buffer")?;
    let patch_count = i32::try_from(p.patch_count())
        .map_err(|_| GlError::InvalidParams(format!("{} edge patches exceed one draw call", p.patch_count())))?;
    // SAFETY: DSA creation and static uploads on the current context; every object created
    // here is deleted if a later creation or store fails.
    unsafe {
        let vertices = gl
            .create_named_buffer()
            .map_err(|detail| GlError::Create { what: "gs-silhouette vertex buffer", detail })?;
        let elements = match gl.create_named_buffer() {
            Ok(b) => b,
            Err(detail) => {
                gl.delete_buffer(vertices);
                return Err(GlError::Create { what: "gs-silhouette element buffer", detail });
            }
        };
        let vao = match gl.create_named_vertex_array() {
            Ok(v) => v,
            Err(detail) => {
                gl.delete_buffer(vertices);
                gl.delete_buffer(elements);
                return Err(GlError::Create { what: "gs-silhouette vertex array", detail });
            }
        };
        // Static: built once per mesh, read by every frame. A zero-size store cannot be bound
        // as a storage buffer: an empty mesh gets 4 bytes (never read, no points are drawn).
        // A store the driver refuses is GlError::OutOfMemory: nothing of ours is left behind.
        let stores = buffer_store(
            gl,
            vertices,
            BufferApi::Dsa,
            BufferData::Bytes(non_empty(vertex_bytes)),
            glow::STATIC_DRAW,
            "gs-silhouette vertex buffer",
        )
        .and_then(|()| {
            buffer_store(
                gl,
                elements,
                BufferApi::Dsa,
                BufferData::Bytes(non_empty(element_bytes)),
                glow::STATIC_DRAW,
                "gs-silhouette element buffer",
            )
        });
        if let Err(e) = stores {
            gl.delete_vertex_array(vao);
            gl.delete_buffer(vertices);
            gl.delete_buffer(elements);
            return Err(e);
        }
        Ok(Buffers { vao, vertices, elements, patch_count, bytes: p.bytes() })
    }
}

impl ShadowMethod for GsSilhouette {
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
        let adj = scene.adjacency();
        let capacity = choose_capacity(adj, limit);
        if self.program.as_ref().is_some_and(|p| p.capacity != capacity) {
            self.delete_program(gl);
        }
        if self.program.is_none() {
            self.program = Some(self.link(gl, capacity)?);
        }
        self.caps.prepare(gl)?;
        let layout = EdgePatches::build(scene.mesh(), adj, capacity)?;
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
        // SAFETY: our program, vertex array and storage buffers; one point per patch, each
        // reading only its own 3 + K elements, all indices < V + K.
        unsafe {
            gl.use_program(Some(program.program));
            gl.uniform_matrix_4_f32_slice(program.u_clip_from_world.as_ref(), false, &frame.clip_from_world_f32());
            gl.uniform_4_f32_slice(program.u_light.as_ref(), &frame.light);
        }
        // The face depth functions every fragment's depth comes from (shared/side_plane.glsl).
        program.depth.set(gl, frame);
        // SAFETY: as above.
        unsafe {
            // The patches, read by gl_PrimitiveIDIn (bindings named in the shader's defines).
            gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, ELEMENTS_BINDING, Some(buffers.elements));
            gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, VERTICES_BINDING, Some(buffers.vertices));
            gl.bind_vertex_array(Some(buffers.vao));
            frame.mark(gl, "sides");
            if buffers.patch_count > 0 {
                gl.draw_arrays(glow::POINTS, 0, buffers.patch_count);
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
        self.delete_program(gl);
        self.caps.destroy(gl);
        self.prepared = None;
    }
}

#[cfg(test)]
mod tests;
