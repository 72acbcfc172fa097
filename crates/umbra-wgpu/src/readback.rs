//! Texture readback: a copy into a mappable buffer with rows padded to wgpu's 256-byte
//! alignment, mapped after the submission and unpadded into top-row-first pixels.

use crate::error::WgpuError;

/// One texture aspect copied into a buffer, to be read after the submission.
pub(crate) struct Readback {
    buffer: wgpu::Buffer,
    width: u32,
    height: u32,
    texel_bytes: u32,
    padded_row: u32,
    what: &'static str,
}

impl Readback {
    /// Records the copy of `aspect` of `texture` (`texel_bytes` per texel in that aspect:
    /// 1 for a stencil aspect, 4 for RGBA8 and R32Uint, 16 for RGBA32F).
    pub fn copy(
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        texture: &wgpu::Texture,
        aspect: wgpu::TextureAspect,
        texel_bytes: u32,
        what: &'static str,
    ) -> Self {
        let (width, height) = (texture.width(), texture.height());
        let padded_row = (width * texel_bytes).next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT);
        let buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(what),
            size: u64::from(padded_row) * u64::from(height),
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        encoder.copy_texture_to_buffer(
            wgpu::TexelCopyTextureInfo { texture, mip_level: 0, origin: wgpu::Origin3d::ZERO, aspect },
            wgpu::TexelCopyBufferInfo {
                buffer: &buffer,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(padded_row),
                    rows_per_image: Some(height),
                },
            },
            wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
        );
        Self { buffer, width, height, texel_bytes, padded_row, what }
    }

    /// The texels, unpadded, top row first (after the submission that holds the copy).
    pub fn read<T: bytemuck::Pod>(&self, device: &wgpu::Device) -> Result<Vec<T>, WgpuError> {
        let padded: Vec<u8> = read_buffer(device, &self.buffer, self.what)?;
        let row = (self.width * self.texel_bytes) as usize;
        let mut bytes = Vec::with_capacity(row * self.height as usize);
        for r in 0..self.height as usize {
            let start = r * self.padded_row as usize;
            bytes.extend_from_slice(&padded[start..start + row]);
        }
        Ok(bytemuck::pod_collect_to_vec(&bytes))
    }
}

/// The whole of `buffer` (MAP_READ, after the submission that wrote it).
pub(crate) fn read_buffer<T: bytemuck::Pod>(
    device: &wgpu::Device,
    buffer: &wgpu::Buffer,
    what: &'static str,
) -> Result<Vec<T>, WgpuError> {
    let slice = buffer.slice(..);
    let (sender, receiver) = std::sync::mpsc::channel();
    slice.map_async(wgpu::MapMode::Read, move |r| {
        let _ = sender.send(r);
    });
    device
        .poll(wgpu::PollType::wait_indefinitely())
        .map_err(|e| WgpuError::Readback { what, detail: e.to_string() })?;
    match receiver.recv() {
        Ok(Ok(())) => {}
        Ok(Err(e)) => return Err(WgpuError::Readback { what, detail: e.to_string() }),
        Err(e) => return Err(WgpuError::Readback { what, detail: e.to_string() }),
    }
    let out = {
        let data = slice.get_mapped_range().map_err(|e| WgpuError::Readback { what, detail: e.to_string() })?;
        bytemuck::pod_collect_to_vec(&data)
    };
    buffer.unmap();
    Ok(out)
}
