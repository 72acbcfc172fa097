//! What a backend's frame reads back, and which of it to read: the same types for umbra-gl and
//! umbra-wgpu (both re-export them), so the tester compares either backend's frame the same way.
//! All images top row first ([`crate::image`]).

use crate::image::{LitMaskImage, RgbaImage, StencilImage, TriangleIdImage, WorldPosImage};

/// For which lights a per-light image is read back.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LightCapture {
    /// No light.
    #[default]
    None,
    /// Only the light with this index in the frame's lights.
    Light(usize),
    /// Every light.
    AllLights,
}

impl LightCapture {
    /// Whether light `light` is captured.
    pub fn includes(self, light: usize) -> bool {
        match self {
            LightCapture::None => false,
            LightCapture::Light(i) => i == light,
            LightCapture::AllLights => true,
        }
    }
}

/// Extra images a backend's `Renderer::render` reads back.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CaptureFlags {
    /// Read back the world position per pixel ([`FrameImages::world_pos`]).
    pub world_pos: bool,
    /// Read back the triangle id per pixel ([`FrameImages::triangle_id`]).
    pub triangle_id: bool,
    /// Read back the stencil after these lights' volume passes ([`FrameImages::stencil`]).
    pub stencil: LightCapture,
    /// The renderer's final per-pixel decision "lit by this light" ([`LitMask`]): what the
    /// image shows, whatever the method's classification. Own target only.
    pub lit_mask: LightCapture,
}

/// Per-light stencil mask after the volume pass.
#[derive(Clone, Debug, PartialEq)]
pub struct StencilMask {
    /// Index of the light in the frame's lights.
    pub light: usize,
    /// Its stencil, top row first.
    pub image: StencilImage,
}

/// Per-light lit mask after that light's lighting pass: 1 where the pixel received the
/// light's diffuse and specular term (the classification passed AND the seen side of the
/// triangle faces the light), 0 elsewhere (shadowed, facing away, background).
#[derive(Clone, Debug, PartialEq)]
pub struct LitMask {
    /// Index of the light in the frame's lights.
    pub light: usize,
    /// Its lit mask (1 lit, 0 not), top row first.
    pub image: LitMaskImage,
}

/// What a backend's `Renderer::render` reads back; all images top row first.
#[derive(Clone, Debug, PartialEq)]
pub struct FrameImages {
    /// The final colour.
    pub rgba: RgbaImage,
    /// World position per pixel, when captured.
    pub world_pos: Option<WorldPosImage>,
    /// Triangle id per pixel ([`crate::image::NO_TRIANGLE`] on background), when captured.
    pub triangle_id: Option<TriangleIdImage>,
    /// In light order, one per captured light.
    pub stencil: Vec<StencilMask>,
    /// In light order, one per captured light.
    pub lit_masks: Vec<LitMask>,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn light_capture_includes() {
        assert!(!LightCapture::None.includes(0));
        assert!(LightCapture::Light(2).includes(2) && !LightCapture::Light(2).includes(1));
        assert!(LightCapture::AllLights.includes(7));
    }
}
