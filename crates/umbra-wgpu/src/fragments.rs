//! Counting the fragments a pass rasterizes: a `FRAGMENT_SHADER_INVOCATIONS` pipeline
//! statistics query per pass, resolved and read back (a wait), where the device has
//! `PIPELINE_STATISTICS_QUERY`. The twin of umbra-gl's `renderer/fragments.rs`; the volume
//! shaders write their depth and the receiver scatter tests it early, so an invocation is a
//! rasterized fragment of a volume, or a visible sample scattered.

use crate::error::WgpuError;

/// `count` fragment counters and the buffers their results are read through.
pub(crate) struct FragmentQueries {
    pub(crate) set: wgpu::QuerySet,
    resolve: wgpu::Buffer,
    readback: wgpu::Buffer,
    count: u32,
}

impl FragmentQueries {
    /// `count` counters, or `None` where the device cannot count.
    pub(crate) fn new(device: &wgpu::Device, label: &str, count: u32) -> Option<Self> {
        if count == 0 || !device.features().contains(wgpu::Features::PIPELINE_STATISTICS_QUERY) {
            return None;
        }
        let set = device.create_query_set(&wgpu::QuerySetDescriptor {
            label: Some(label),
            ty: wgpu::QueryType::PipelineStatistics(wgpu::PipelineStatisticsTypes::FRAGMENT_SHADER_INVOCATIONS),
            count,
        });
        let buffer = |usage| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: 8 * u64::from(count),
                usage,
                mapped_at_creation: false,
            })
        };
        Some(Self {
            set,
            resolve: buffer(wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC),
            readback: buffer(wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST),
            count,
        })
    }

    /// Records the resolve and the copy for [`FragmentQueries::read`], after the passes.
    pub(crate) fn resolve(&self, encoder: &mut wgpu::CommandEncoder) {
        encoder.resolve_query_set(&self.set, 0..self.count, &self.resolve, 0);
        encoder.copy_buffer_to_buffer(&self.resolve, 0, &self.readback, 0, 8 * u64::from(self.count));
    }

    /// The counts, once the submission that resolved them is done (waits for it).
    pub(crate) fn read(&self, device: &wgpu::Device) -> Result<Vec<u64>, WgpuError> {
        crate::readback::read_buffer(device, &self.readback, "fragment counts")
    }
}
