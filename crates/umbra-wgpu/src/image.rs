//! CPU-side images read back from the GPU, TOP row first (wgpu's texture rows are), and PNG
//! output: umbra-geom's ([`umbra_geom::image`]), the same types as umbra-gl's. A PNG error
//! converts into [`crate::WgpuError::Png`].

pub use umbra_geom::image::{Image, LitMaskImage, PngError, RgbaImage, StencilImage, TriangleIdImage, WorldPosImage};
