//! The transform pass shared by `cs-silhouette` and `vs-silhouette` (shaders/transform.wgsl):
//! every welded vertex to clip space once per light, as a point and extruded to infinity, so
//! that sides and caps drawn by different pipelines read the same bits at their shared
//! vertices (a watertight volume whatever the compiler contracts).

use crate::error::WgpuError;
use crate::scene::{binding_bytes, check_size, SceneGpu};
use crate::volumes::{buffers_group, dispatch_size, storage_entry, Common};

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
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("umbra transform"),
            bind_group_layouts: &[Some(&common.light_layout), Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("umbra transform"),
            layout: Some(&pipeline_layout),
            module: &module,
            entry_point: Some("transform"),
            compilation_options: Default::default(),
            cache: None,
        });
        Self { layout, pipeline }
    }

    /// A light's clip-position buffer for `scene`.
    pub fn buffers(&self, device: &wgpu::Device, scene: &SceneGpu) -> Result<ClipPositions, WgpuError> {
        let bytes = 32 * scene.mesh().positions.len() as u64;
        check_size(device, "umbra clip positions", bytes)?;
        let buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("umbra clip positions"),
            size: binding_bytes(bytes as usize),
            usage: wgpu::BufferUsages::STORAGE,
            mapped_at_creation: false,
        });
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
