//! CPU-side images, always TOP row first (row 0 is the top of the picture), and PNG output:
//! umbra-geom's ([`umbra_geom::image`]), shared with umbra-wgpu, re-exported under their old
//! paths. A PNG error converts into [`crate::GlError::Png`].

pub use umbra_geom::image::{Image, LitMaskImage, PngError, RgbaImage, StencilImage, TriangleIdImage, WorldPosImage};
