//! A welded mesh uploaded once: positions (vertex buffer), triangles (index buffer) and one
//! flat normal per triangle (shader storage buffer indexed by `gl_PrimitiveID`).
//!
//! Drawn with ONE `glDrawElements(GL_TRIANGLES)` over all triangles in order, so
//! `gl_PrimitiveID` == index into `WeldedMesh::triangles` (the triangle id the renderer
//! writes to the id attachment and the ray-traced oracle receives).
//!
//! GL state touched: none besides creating objects (direct state access, no bindings change);
//! `DEBUG_OUTPUT` is switched off during each upload and restored (`gpu_buffer`).
//!
//! A buffer the driver refuses (`GL_OUT_OF_MEMORY`, e.g. llvmpipe's malloc failing) is a
//! [`GlError::OutOfMemory`] naming the buffer; nothing is left behind and the context stays
//! usable (`tests/gl_failures.rs` provokes it for real).

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, OnceLock};

use glow::HasContext;
use umbra_geom::clearance::ClearanceIndex;
use umbra_geom::{Aabb, EdgeAdjacency, WeldedMesh};

/// Moved to umbra-geom (shared with umbra-wgpu); re-exported under their old paths.
pub use umbra_geom::mesh::flat_normal;
pub use umbra_geom::weld::triangle_bounds;
use umbra_geom::weld::triangle_normals;

use crate::error::GlError;
use crate::gpu_buffer::{buffer_with_data, checked_size, BufferApi, BufferData};

/// Identifies one uploaded scene (unique per process), so a method knows whether it has
/// prepared for it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct SceneId(u64);

/// Shader-storage binding point of the per-triangle normals (`vec4 normals[]`, xyz used).
pub const NORMALS_BINDING: u32 = 0;
/// Vertex attribute location of the position (`vec3`).
pub const POSITION_LOCATION: u32 = 0;
/// Binding point of the uniform block `UmbraSceneClip` (methods/shared/depth.glsl): six
/// clip-space planes of the box around the scene and the eye.
pub const SCENE_CLIP_BINDING: u32 = 14;
/// The scene's vertex shader (positions at [`POSITION_LOCATION`], invariant `gl_Position`),
/// shared by the depth, lighting and sample passes.
pub(crate) const SCENE_VERT: &str = include_str!("shaders/scene.vert.glsl");

/// GPU copy of a [`WeldedMesh`]. Delete with [`SceneGpu::destroy`] while its context is
/// current (dropping without it leaks the GL objects until the context dies).
pub struct SceneGpu {
    id: SceneId,
    mesh: Arc<WeldedMesh>,
    adjacency: OnceLock<Arc<EdgeAdjacency>>,
    clearance: OnceLock<Arc<ClearanceIndex>>,
    bounds: Option<Aabb>,
    vao: glow::VertexArray,
    positions: glow::Buffer,
    indices: glow::Buffer,
    normals: glow::Buffer,
    gpu_bytes: usize,
}

fn as_bytes<T: Copy>(v: &[T]) -> &[u8] {
    // SAFETY: T is a plain array of f32/u32 (no padding, every bit pattern valid as bytes);
    // the slice covers exactly size_of_val(v) initialised bytes.
    unsafe { std::slice::from_raw_parts(v.as_ptr().cast::<u8>(), std::mem::size_of_val(v)) }
}

impl SceneGpu {
    /// Uploads `mesh` (positions, indices, flat normals). Static data: `STATIC_DRAW`.
    pub fn upload(gl: &glow::Context, mesh: Arc<WeldedMesh>) -> Result<Self, GlError> {
        static NEXT_ID: AtomicU64 = AtomicU64::new(1);
        mesh.check_indices().map_err(|e| GlError::InvalidParams(e.to_string()))?;
        let index_count = mesh.triangles.len() * 3;
        if i32::try_from(index_count).is_err() {
            return Err(GlError::InvalidParams(format!(
                "{} triangles exceed one glDrawElements call",
                mesh.triangles.len()
            )));
        }
        let normals = triangle_normals(&mesh);
        let pos_bytes = as_bytes(&mesh.positions);
        let idx_bytes = as_bytes(&mesh.triangles);
        let nrm_bytes = as_bytes(&normals);
        for (b, what) in [(pos_bytes, "position buffer"), (idx_bytes, "index buffer"), (nrm_bytes, "normal buffer")] {
            checked_size(b.len(), what)?;
        }
        let bounds = triangle_bounds(&mesh);
        // Each store is checked right after its upload (crate::gpu_buffer): a refusal is this
        // call's OutOfMemory, and the buffers already made are deleted.
        // An empty mesh still gets (empty) buffers so every draw path stays uniform;
        // glNamedBufferData with size 0 is legal.
        let mut buffers = Vec::with_capacity(3);
        for (bytes, what) in [
            (pos_bytes, "the scene's position buffer"),
            (idx_bytes, "the scene's index buffer"),
            (nrm_bytes, "the scene's normal buffer"),
        ] {
            match buffer_with_data(gl, BufferApi::Dsa, BufferData::Bytes(bytes), glow::STATIC_DRAW, what) {
                Ok(b) => buffers.push(b),
                Err(e) => {
                    for b in buffers {
                        // SAFETY: buffers created just above, never handed out.
                        unsafe { gl.delete_buffer(b) };
                    }
                    return Err(e);
                }
            }
        }
        let (positions, indices, normals_buf) = (buffers[0], buffers[1], buffers[2]);
        // SAFETY: DSA object creation and vertex-array set-up on the current context; the
        // buffers are deleted if the vertex array cannot be created.
        unsafe {
            let delete = |buffers: &[glow::Buffer]| {
                for &b in buffers {
                    gl.delete_buffer(b);
                }
            };
            let vao = match gl.create_named_vertex_array() {
                Ok(v) => v,
                Err(detail) => {
                    delete(&buffers);
                    return Err(GlError::Create { what: "vertex array", detail });
                }
            };
            gl.vertex_array_vertex_buffer(vao, 0, Some(positions), 0, 12);
            gl.vertex_array_attrib_format_f32(vao, POSITION_LOCATION, 3, glow::FLOAT, false, 0);
            gl.vertex_array_attrib_binding_f32(vao, POSITION_LOCATION, 0);
            gl.enable_vertex_array_attrib(vao, POSITION_LOCATION);
            gl.vertex_array_element_buffer(vao, Some(indices));
            Ok(Self {
                id: SceneId(NEXT_ID.fetch_add(1, Ordering::Relaxed)),
                gpu_bytes: pos_bytes.len() + idx_bytes.len() + nrm_bytes.len(),
                mesh,
                adjacency: OnceLock::new(),
                clearance: OnceLock::new(),
                bounds,
                vao,
                positions,
                indices,
                normals: normals_buf,
            })
        }
    }

    /// This upload's identity (methods prepare per scene id).
    pub fn id(&self) -> SceneId {
        self.id
    }

    /// The CPU mesh (shared, e.g. with the oracle).
    pub fn mesh(&self) -> &Arc<WeldedMesh> {
        &self.mesh
    }

    /// Edge adjacency, built on first use (once per mesh) and shared by every method.
    pub fn adjacency(&self) -> &Arc<EdgeAdjacency> {
        self.adjacency.get_or_init(|| Arc::new(EdgeAdjacency::build(&self.mesh)))
    }

    /// The z-pass clearance index ([`umbra_geom::clearance`]), built on first use (once per
    /// mesh): the renderer asks it, per light and frame, whether the eye is outside every
    /// shadow volume.
    pub fn clearance(&self) -> &Arc<ClearanceIndex> {
        self.clearance.get_or_init(|| Arc::new(ClearanceIndex::build(&self.mesh)))
    }

    /// Bounds of the triangles' vertices; None for an empty mesh.
    pub fn bounds(&self) -> Option<Aabb> {
        self.bounds
    }

    /// Number of triangles (after welding).
    pub fn triangle_count(&self) -> usize {
        self.mesh.triangles.len()
    }

    /// VAO with the position attribute at location 0 and the index buffer.
    pub fn vertex_array(&self) -> glow::VertexArray {
        self.vao
    }

    /// `vec3` positions, tightly packed (12-byte stride).
    pub fn position_buffer(&self) -> glow::Buffer {
        self.positions
    }

    /// `uvec3` triangles.
    pub fn index_buffer(&self) -> glow::Buffer {
        self.indices
    }

    /// `vec4` per-triangle unit normals (w = 0).
    pub fn normal_buffer(&self) -> glow::Buffer {
        self.normals
    }

    /// Bytes of GPU buffers owned by the scene.
    pub fn gpu_bytes(&self) -> usize {
        self.gpu_bytes
    }

    /// Issues the single indexed draw of all triangles (VAO must be bound by the caller).
    pub(crate) fn draw_triangles(&self, gl: &glow::Context) {
        // SAFETY: the scene VAO is bound (caller), its element buffer holds exactly
        // 3 * triangle_count u32 indices, all checked < positions.len() at upload.
        unsafe { gl.draw_elements(glow::TRIANGLES, (self.mesh.triangles.len() * 3) as i32, glow::UNSIGNED_INT, 0) };
    }

    /// Deletes the GL objects (context must be current).
    pub fn destroy(self, gl: &glow::Context) {
        // SAFETY: objects created by this scene on this context, not used afterwards.
        unsafe {
            gl.delete_vertex_array(self.vao);
            gl.delete_buffer(self.positions);
            gl.delete_buffer(self.indices);
            gl.delete_buffer(self.normals);
        }
    }
}
