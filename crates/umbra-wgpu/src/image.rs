//! CPU-side images read back from the GPU, TOP row first (wgpu's texture rows are), and PNG
//! output.

use std::path::Path;

use crate::error::WgpuError;

/// A `width x height` image, row-major, top row first.
#[derive(Clone, Debug, PartialEq)]
pub struct Image<T> {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `width * height` pixels, row-major, top row first.
    pub pixels: Vec<T>,
}

/// RGBA8 colour.
pub type RgbaImage = Image<[u8; 4]>;
/// World-space position per pixel: `w = 1` where geometry was drawn, all zero on background.
pub type WorldPosImage = Image<[f32; 4]>;
/// Index into `WeldedMesh::triangles` per pixel, [`crate::NO_TRIANGLE`] on background.
pub type TriangleIdImage = Image<u32>;
/// Stencil value per pixel.
pub type StencilImage = Image<u8>;
/// The renderer's lit decision per pixel for one light: 1 = the lighting pass shaded it (the
/// stencil said lit and the seen side faces the light), 0 = not.
pub type LitMaskImage = Image<u8>;

impl<T: Copy> Image<T> {
    /// Pixel at column `x`, row `y` counted from the top; `None` outside.
    pub fn get(&self, x: u32, y: u32) -> Option<T> {
        (x < self.width && y < self.height).then(|| self.pixels[y as usize * self.width as usize + x as usize])
    }
}

impl RgbaImage {
    /// Writes an 8-bit RGBA PNG (deterministic bytes for equal pixels).
    pub fn save_png(&self, path: &Path) -> Result<(), WgpuError> {
        let err = |detail: String| WgpuError::Png { path: path.display().to_string(), detail };
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir).map_err(|e| err(e.to_string()))?;
        }
        let file = std::fs::File::create(path).map_err(|e| err(e.to_string()))?;
        let mut encoder = png::Encoder::new(std::io::BufWriter::new(file), self.width, self.height);
        encoder.set_color(png::ColorType::Rgba);
        encoder.set_depth(png::BitDepth::Eight);
        let mut writer = encoder.write_header().map_err(|e| err(e.to_string()))?;
        writer.write_image_data(bytemuck::cast_slice(&self.pixels)).map_err(|e| err(e.to_string()))?;
        writer.finish().map_err(|e| err(e.to_string()))
    }
}
