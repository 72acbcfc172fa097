//! CPU-side images as every backend reads them back, always TOP row first (row 0 is the top
//! of the picture), and PNG output. umbra-gl and umbra-wgpu re-export these types, so a frame
//! of either backend is the same `Image`.

use std::path::Path;

/// The triangle id of a background sample in a [`TriangleIdImage`] (the ray-traced oracle's
/// background id too).
pub const NO_TRIANGLE: u32 = u32::MAX;

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
/// Index into `WeldedMesh::triangles` per pixel, [`NO_TRIANGLE`] on background.
pub type TriangleIdImage = Image<u32>;
/// Stencil value per pixel.
pub type StencilImage = Image<u8>;
/// The renderer's lit decision per pixel for one light: 1 = the lighting pass shaded it
/// (classification passed and the seen side faces the light), 0 = not (shadowed, facing away,
/// or background).
pub type LitMaskImage = Image<u8>;

/// Writing a PNG failed.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("could not write PNG {path}: {detail}")]
pub struct PngError {
    /// The file written.
    pub path: String,
    /// The I/O or encoder error.
    pub detail: String,
}

impl<T: Copy> Image<T> {
    /// A `width x height` image with every pixel `fill`.
    pub fn new(width: u32, height: u32, fill: T) -> Self {
        Self { width, height, pixels: vec![fill; width as usize * height as usize] }
    }

    /// Builds an image from a bottom-row-first readback (GL's) by flipping the rows.
    pub fn from_bottom_up(width: u32, height: u32, bottom_up: Vec<T>) -> Self {
        let w = width as usize;
        let mut pixels = Vec::with_capacity(bottom_up.len());
        for row in bottom_up.chunks_exact(w.max(1)).rev() {
            pixels.extend_from_slice(row);
        }
        Self { width, height, pixels }
    }

    /// Pixel at column `x`, row `y` counted from the top; `None` outside.
    pub fn get(&self, x: u32, y: u32) -> Option<T> {
        (x < self.width && y < self.height).then(|| self.pixels[y as usize * self.width as usize + x as usize])
    }
}

impl RgbaImage {
    /// Writes an 8-bit RGBA PNG (deterministic bytes for equal pixels).
    pub fn save_png(&self, path: &Path) -> Result<(), PngError> {
        let bytes: Vec<u8> = self.pixels.iter().flatten().copied().collect();
        write_png(path, self.width, self.height, png::ColorType::Rgba, &bytes)
    }

    /// Per-pixel comparison: an image that is black where equal and red (scaled by the
    /// largest channel difference, at least 64) where not, and the number of differing pixels.
    pub fn difference(&self, other: &RgbaImage) -> Option<(RgbaImage, usize)> {
        if self.width != other.width || self.height != other.height {
            return None;
        }
        let mut count = 0;
        let pixels = self
            .pixels
            .iter()
            .zip(&other.pixels)
            .map(|(a, b)| {
                let d = (0..4).map(|i| a[i].abs_diff(b[i])).max().unwrap_or(0);
                if d == 0 {
                    [0, 0, 0, 255]
                } else {
                    count += 1;
                    [d.max(64), 0, 0, 255]
                }
            })
            .collect();
        Some((Image { width: self.width, height: self.height, pixels }, count))
    }
}

impl StencilImage {
    /// Writes an 8-bit grey PNG; `scale` multiplies the counts to make small ones visible.
    pub fn save_png(&self, path: &Path, scale: u8) -> Result<(), PngError> {
        let bytes: Vec<u8> = self.pixels.iter().map(|&s| s.wrapping_mul(scale)).collect();
        write_png(path, self.width, self.height, png::ColorType::Grayscale, &bytes)
    }
}

fn write_png(path: &Path, width: u32, height: u32, color: png::ColorType, bytes: &[u8]) -> Result<(), PngError> {
    let err = |detail: String| PngError { path: path.display().to_string(), detail };
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|e| err(e.to_string()))?;
    }
    let file = std::fs::File::create(path).map_err(|e| err(e.to_string()))?;
    let mut encoder = png::Encoder::new(std::io::BufWriter::new(file), width, height);
    encoder.set_color(color);
    encoder.set_depth(png::BitDepth::Eight);
    let mut writer = encoder.write_header().map_err(|e| err(e.to_string()))?;
    writer.write_image_data(bytes).map_err(|e| err(e.to_string()))?;
    writer.finish().map_err(|e| err(e.to_string()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn from_bottom_up_flips_rows() {
        // GL row 0 (bottom) = [1, 2], row 1 (top) = [3, 4].
        let img = Image::from_bottom_up(2, 2, vec![1, 2, 3, 4]);
        assert_eq!(img.pixels, vec![3, 4, 1, 2]);
        assert_eq!(img.get(0, 0), Some(3));
        assert_eq!(img.get(1, 1), Some(2));
        assert_eq!(img.get(2, 0), None);
    }

    #[test]
    fn difference_counts_changed_pixels() {
        let a = Image::new(3, 1, [10u8, 10, 10, 255]);
        let mut b = a.clone();
        b.pixels[1] = [10, 12, 10, 255];
        let (diff, n) = a.difference(&b).expect("same size");
        assert_eq!(n, 1);
        assert_eq!(diff.pixels[0], [0, 0, 0, 255]);
        assert_eq!(diff.pixels[1], [64, 0, 0, 255]);
        assert!(a.difference(&Image::new(1, 1, [0; 4])).is_none());
    }
}
