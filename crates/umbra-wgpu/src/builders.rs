//! Small wgpu builders every pipeline of the crate uses: bind group layout entries, bind
//! groups of whole buffers, dynamic uniform slots, compute pipelines and dispatch sizes.

/// Bytes of one light's uniform slot (the largest `min_uniform_buffer_offset_alignment`
/// wgpu allows is 256).
pub(crate) const LIGHT_SLOT_BYTES: u64 = 256;

/// The bind group layout entry of a buffer of type `ty` at `binding`.
fn buffer_entry(
    binding: u32,
    visibility: wgpu::ShaderStages,
    ty: wgpu::BufferBindingType,
    has_dynamic_offset: bool,
) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Buffer { ty, has_dynamic_offset, min_binding_size: None },
        count: None,
    }
}

/// The bind group layout entry of a uniform buffer at `binding` (`dynamic`: read at a
/// dynamic offset, one slot of [`uniform_slots`]).
pub(crate) fn uniform_entry(binding: u32, visibility: wgpu::ShaderStages, dynamic: bool) -> wgpu::BindGroupLayoutEntry {
    buffer_entry(binding, visibility, wgpu::BufferBindingType::Uniform, dynamic)
}

/// A uniform buffer of `slots` slots of [`LIGHT_SLOT_BYTES`] and its bind group for `layout`:
/// binding 0 sees `binding_bytes` from the dynamic offset of a slot.
pub(crate) fn uniform_slots(
    device: &wgpu::Device,
    label: &str,
    layout: &wgpu::BindGroupLayout,
    slots: usize,
    binding_bytes: u64,
) -> (wgpu::Buffer, wgpu::BindGroup) {
    let buffer = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: LIGHT_SLOT_BYTES * slots as u64,
        usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some(label),
        layout,
        entries: &[wgpu::BindGroupEntry {
            binding: 0,
            resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                buffer: &buffer,
                offset: 0,
                size: wgpu::BufferSize::new(binding_bytes),
            }),
        }],
    });
    (buffer, group)
}

/// A compute pipeline: `entry` of `module` with `layout`.
pub(crate) fn compute_pipeline(
    device: &wgpu::Device,
    label: &str,
    layout: &wgpu::PipelineLayout,
    module: &wgpu::ShaderModule,
    entry: &str,
) -> wgpu::ComputePipeline {
    device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some(label),
        layout: Some(layout),
        module,
        entry_point: Some(entry),
        compilation_options: Default::default(),
        cache: None,
    })
}

/// The bind group layout entry of a storage buffer at `binding`.
pub(crate) fn storage_entry(
    binding: u32,
    visibility: wgpu::ShaderStages,
    read_only: bool,
) -> wgpu::BindGroupLayoutEntry {
    buffer_entry(binding, visibility, wgpu::BufferBindingType::Storage { read_only }, false)
}

/// A bind group of whole buffers at bindings 0, 1, ...
pub(crate) fn buffers_group(
    device: &wgpu::Device,
    label: &str,
    layout: &wgpu::BindGroupLayout,
    buffers: &[&wgpu::Buffer],
) -> wgpu::BindGroup {
    let entries: Vec<wgpu::BindGroupEntry<'_>> = buffers
        .iter()
        .enumerate()
        .map(|(i, b)| wgpu::BindGroupEntry { binding: i as u32, resource: b.as_entire_binding() })
        .collect();
    device.create_bind_group(&wgpu::BindGroupDescriptor { label: Some(label), layout, entries: &entries })
}

/// Workgroups (x, y) of 256 invocations covering `items` (a dimension holds at most 65,535;
/// the shaders index `gid.x + gid.y * groups.x * 256`, volume.wgsl's `umbra_item`).
pub(crate) fn dispatch_size(items: u32) -> (u32, u32) {
    let groups = items.div_ceil(256);
    let x = groups.clamp(1, 65_535);
    (x, groups.div_ceil(x))
}
