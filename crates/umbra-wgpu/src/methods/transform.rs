//! The transform pass shared by `cs-silhouette` and `vs-silhouette` (shaders/transform.wgsl):
//! every welded vertex to clip space once per light, as a point and extruded to infinity, so
//! that sides and caps drawn by different pipelines read the same bits at their shared
//! vertices (a watertight volume whatever the compiler contracts).

use crate::builders::{buffers_group, compute_pipeline, dispatch_size, storage_entry};
use crate::common::Common;
use crate::error::WgpuError;
use crate::scene::{buffer_zeroed, SceneGpu};

const VOLUME: &str = include_str!("../shaders/volume.wgsl");
const TRANSFORM: &str = include_str!("../shaders/transform.wgsl");

/// The pipeline and its bind group layout.
pub(crate) struct Transform {
    layout: wgpu::BindGroupLayout,
    pipeline: wgpu::ComputePipeline,
}

/// One light's clip positions (`vec4` × 2 per vertex) and the bind group that writes them.
pub(crate) struct ClipPositions {
    pub buffer: wgpu::Buffer,
    group: wgpu::BindGroup,
}

impl Transform {
    pub fn new(device: &wgpu::Device, common: &Common) -> Self {
        let compute = wgpu::ShaderStages::COMPUTE;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("umbra transform"),
            entries: &[storage_entry(0, compute, true), storage_entry(1, compute, false)],
        });
        let module = Common::module(device, "transform.wgsl", &["enable clip_distances;", VOLUME, TRANSFORM]);
        let pipeline_layout = common.pipeline_layout(device, "umbra transform", &[&layout]);
        let pipeline = compute_pipeline(device, "umbra transform", &pipeline_layout, &module, "transform");
        Self { layout, pipeline }
    }

    /// A light's clip-position buffer for `scene`.
    pub fn buffers(&self, device: &wgpu::Device, scene: &SceneGpu) -> Result<ClipPositions, WgpuError> {
        let bytes = 32 * scene.mesh().positions.len() as u64;
        let buffer = buffer_zeroed(device, "umbra clip positions", bytes, wgpu::BufferUsages::STORAGE)?;
        let group = buffers_group(device, "umbra transform", &self.layout, &[scene.position_buffer(), &buffer]);
        Ok(ClipPositions { buffer, group })
    }

    /// Records the transform of `vertices` vertices for the light bound as group 0.
    pub fn dispatch(&self, pass: &mut wgpu::ComputePass<'_>, clip: &ClipPositions, vertices: u32) {
        if vertices == 0 {
            return;
        }
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(1, &clip.group, &[]);
        let (x, y) = dispatch_size(vertices);
        pass.dispatch_workgroups(x, y, 1);
    }
}
