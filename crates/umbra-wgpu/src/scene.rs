//! A welded mesh uploaded once: positions (vertex and storage buffer, tightly packed `vec3`),
//! triangles (index and storage buffer) and one flat normal per triangle (storage buffer),
//! plus the per-mesh CPU data every method shares, built on first use: edge adjacency, the
//! triangle behind every (edge, opposite) slot and the z-pass clearance index (all from
//! umbra-geom, as umbra-gl's `SceneGpu` has them).
//!
//! Drawn as ONE indexed draw over all triangles in order, so `primitive_index` is the index
//! into `WeldedMesh::triangles` (the id the ray-traced oracle receives).

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, OnceLock};

use umbra_geom::clearance::ClearanceIndex;
use umbra_geom::silhouette::TriangleSlots;
use umbra_geom::weld::{triangle_bounds, triangle_normals};
use umbra_geom::{Aabb, EdgeAdjacency, WeldedMesh};
use wgpu::util::DeviceExt;

use crate::error::WgpuError;

/// Identifies one uploaded scene (unique per process), so a method knows whether it has
/// prepared for it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct SceneId(u64);

/// GPU copy of a [`WeldedMesh`]; the buffers are freed when it is dropped.
pub struct SceneGpu {
    id: SceneId,
    mesh: Arc<WeldedMesh>,
    adjacency: OnceLock<Arc<EdgeAdjacency>>,
    slots: OnceLock<Result<Arc<TriangleSlots>, String>>,
    clearance: OnceLock<Arc<ClearanceIndex>>,
    bounds: Option<Aabb>,
    positions: wgpu::Buffer,
    indices: wgpu::Buffer,
    normals: wgpu::Buffer,
    gpu_bytes: u64,
}

/// Bytes of a storage binding for `len` bytes of data: at least 16 (wgpu refuses empty
/// bindings; an empty mesh still gets buffers so every draw path stays uniform).
pub(crate) fn binding_bytes(len: usize) -> u64 {
    (len as u64).max(16).next_multiple_of(4)
}

/// A buffer of `bytes` (padded to [`binding_bytes`]) with `usage`, checked against the
/// device's limits first (a clear error, not a validation panic).
pub(crate) fn buffer_init(
    device: &wgpu::Device,
    label: &str,
    bytes: &[u8],
    usage: wgpu::BufferUsages,
) -> Result<wgpu::Buffer, WgpuError> {
    check_size(device, label, bytes.len() as u64)?;
    let size = binding_bytes(bytes.len());
    let mut padded;
    let contents = if size as usize == bytes.len() {
        bytes
    } else {
        padded = bytes.to_vec();
        padded.resize(size as usize, 0);
        &padded
    };
    Ok(device.create_buffer_init(&wgpu::util::BufferInitDescriptor { label: Some(label), contents, usage }))
}

/// A zero-filled buffer of `bytes` (padded to [`binding_bytes`]) with `usage`, checked against
/// the device's limits first.
pub(crate) fn buffer_zeroed(
    device: &wgpu::Device,
    label: &str,
    bytes: u64,
    usage: wgpu::BufferUsages,
) -> Result<wgpu::Buffer, WgpuError> {
    check_size(device, label, bytes)?;
    Ok(device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: binding_bytes(bytes as usize),
        usage,
        mapped_at_creation: false,
    }))
}

/// `bytes` fits one buffer and one storage binding of `device`.
pub(crate) fn check_size(device: &wgpu::Device, what: &str, bytes: u64) -> Result<(), WgpuError> {
    let limits = device.limits();
    let max = limits.max_buffer_size.min(limits.max_storage_buffer_binding_size);
    if bytes > max {
        return Err(WgpuError::InvalidParams(format!(
            "{what} needs {bytes} bytes, more than this device's largest storage buffer ({max} bytes)"
        )));
    }
    Ok(())
}

impl SceneGpu {
    /// Uploads `mesh` (positions, indices, flat normals).
    pub fn upload(device: &wgpu::Device, mesh: Arc<WeldedMesh>) -> Result<Self, WgpuError> {
        static NEXT_ID: AtomicU64 = AtomicU64::new(1);
        mesh.check_indices().map_err(|e| WgpuError::InvalidParams(e.to_string()))?;
        if mesh.triangles.len() >= (u32::MAX / 3) as usize {
            return Err(WgpuError::InvalidParams(format!(
                "{} triangles exceed one indexed draw",
                mesh.triangles.len()
            )));
        }
        let normals = triangle_normals(&mesh);
        let storage = wgpu::BufferUsages::STORAGE;
        let upload = || -> Result<_, WgpuError> {
            Ok((
                buffer_init(
                    device,
                    "umbra scene positions",
                    bytemuck::cast_slice(&mesh.positions),
                    storage | wgpu::BufferUsages::VERTEX,
                )?,
                buffer_init(
                    device,
                    "umbra scene indices",
                    bytemuck::cast_slice(&mesh.triangles),
                    storage | wgpu::BufferUsages::INDEX,
                )?,
                buffer_init(device, "umbra scene normals", bytemuck::cast_slice(&normals), storage)?,
            ))
        };
        let (positions, indices, normals) = crate::error::scoped(device, "scene upload", upload)?;
        Ok(Self {
            id: SceneId(NEXT_ID.fetch_add(1, Ordering::Relaxed)),
            gpu_bytes: positions.size() + indices.size() + normals.size(),
            bounds: triangle_bounds(&mesh),
            mesh,
            adjacency: OnceLock::new(),
            slots: OnceLock::new(),
            clearance: OnceLock::new(),
            positions,
            indices,
            normals,
        })
    }

    /// This upload's identity.
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

    /// The triangle behind every (edge, opposite) slot of [`SceneGpu::adjacency`]
    /// ([`TriangleSlots`]), built on first use.
    pub fn slots(&self) -> Result<&Arc<TriangleSlots>, WgpuError> {
        self.slots
            .get_or_init(|| TriangleSlots::build(&self.mesh, self.adjacency()).map(Arc::new).map_err(|e| e.to_string()))
            .as_ref()
            .map_err(|e| WgpuError::InvalidParams(e.clone()))
    }

    /// The z-pass clearance index ([`umbra_geom::clearance`]), built on first use.
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

    /// Positions: `vec3<f32>` tightly packed (12-byte stride); usage VERTEX | STORAGE. A host
    /// may draw its depth from it (`Float32x3` at location 0) to meet the invariance
    /// requirement of [`crate::ShadowVolumes`] with the very same bits.
    pub fn position_buffer(&self) -> &wgpu::Buffer {
        &self.positions
    }

    /// Triangles: 3 × `u32` each; usage INDEX | STORAGE.
    pub fn index_buffer(&self) -> &wgpu::Buffer {
        &self.indices
    }

    /// One `vec4<f32>` unit normal per triangle (w = 0; counter-clockwise = front), usage STORAGE.
    pub fn normal_buffer(&self) -> &wgpu::Buffer {
        &self.normals
    }

    /// Index count of the one indexed draw of all triangles.
    pub fn index_count(&self) -> u32 {
        (self.mesh.triangles.len() * 3) as u32
    }

    /// Bytes of GPU buffers owned by the scene.
    pub fn gpu_bytes(&self) -> u64 {
        self.gpu_bytes
    }
}
