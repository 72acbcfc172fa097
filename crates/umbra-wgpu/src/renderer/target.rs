//! The stand-alone frame's own textures: colour, world position, triangle id, lit mask and
//! depth-stencil, all one sample per pixel and copyable for readback.

use super::COLOR_FORMAT;

/// The frame's textures.
pub(super) struct Target {
    pub(super) width: u32,
    pub(super) height: u32,
    pub(super) color: wgpu::Texture,
    pub(super) world_pos: wgpu::Texture,
    pub(super) triangle_id: wgpu::Texture,
    pub(super) lit_mask: wgpu::Texture,
    pub(super) depth: wgpu::Texture,
}

impl Target {
    pub(super) fn new(device: &wgpu::Device, width: u32, height: u32, depth_format: wgpu::TextureFormat) -> Self {
        let texture = |label, format| {
            device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size: wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
                mip_level_count: 1,
                // Reason: the stencil copy needs one sample per pixel (and the verifier one
                // sample per pixel: the rasterized sample it ray-traces).
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format,
                // Reason: TEXTURE_BINDING for the depth, which the receiver maps of a culled
                // volume read (receivers.rs); harmless on the others.
                usage: wgpu::TextureUsages::RENDER_ATTACHMENT
                    | wgpu::TextureUsages::COPY_SRC
                    | wgpu::TextureUsages::TEXTURE_BINDING,
                view_formats: &[],
            })
        };
        Self {
            width,
            height,
            color: texture("umbra colour", COLOR_FORMAT),
            world_pos: texture("umbra world position", wgpu::TextureFormat::Rgba32Float),
            triangle_id: texture("umbra triangle id", wgpu::TextureFormat::R32Uint),
            lit_mask: texture("umbra lit mask", wgpu::TextureFormat::R8Unorm),
            depth: texture("umbra depth-stencil", depth_format),
        }
    }
}

/// The whole texture as a view.
pub(super) fn view_of(t: &wgpu::Texture) -> wgpu::TextureView {
    t.create_view(&wgpu::TextureViewDescriptor::default())
}
