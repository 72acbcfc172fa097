//! umbra-oracle: the CPU ray-traced shadow reference that every GPU shadow method of umbra is
//! judged against, per sample. No GL.
//!
//! * [`watertight`]: Woop, Benthin, Wald 2013, "Watertight Ray/Triangle Intersection" (JCGT).
//! * [`bvh`]: binned-SAH BVH (Wald 2007), parallel build, robust traversal (Ize 2013);
//!   any-hit [`Bvh::occluded`] and closest-hit [`Bvh::intersect`].
//! * [`mod@reference`]: per-sample shadow classes of the rasterized samples and their band.
//! * [`edge_on`]: volume faces seen edge-on, where coverage and depth disagree (part of the band).
//! * [`nearer_contour`]: samples beside the projected edge of a nearer surface, whose volume's
//!   snapped faces may cover the pixel (part of the band).
//! * [`seen_surface`]: the surface a depth pass of another precision (an external mask's) sees
//!   at a pixel (part of the band for such masks).
//! * [`envelope`]: the precision envelope of a rasterized sample (GL's depth and sub-pixel
//!   precision, llvmpipe's interpolation), which defines the band once.
//! * [`metrics`]: mismatch counts of a method's stencil mask against the reference, and the
//!   diff image.
//! * [`synthetic`]: primary-ray samples from a pinhole camera, for tests and benchmarks only.

pub mod bvh;
pub mod edge_on;
pub mod envelope;
pub mod metrics;
pub mod nearer_contour;
#[cfg(test)]
mod pinned;
pub mod reference;
pub mod seen_surface;
pub mod synthetic;
pub mod watertight;

pub use bvh::{Bvh, Hit};
pub use envelope::{BandParts, DepthFormat, RasterView};
pub use metrics::{
    compare, compare_masked, diff_image, diff_image_masked, mismatches_outside_band, mismatches_outside_band_masked,
    Metrics,
};
pub use reference::{boundary_band, reference, reference_in_view, segment_epsilon, Reference, SampleClass, Samples};

/// Bad input to the oracle. Pixel coordinates are `(x, y)` with `y = 0` the top row.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum OracleError {
    #[error("triangle {triangle} references vertex {vertex}, but there are only {vertices} vertices")]
    VertexOutOfRange { triangle: usize, vertex: u32, vertices: usize },
    #[error("{count} triangles: triangle ids must stay below u32::MAX (reserved for background)")]
    TooManyTriangles { count: usize },
    #[error("the BVH was built over {bvh} triangles but the mesh has {mesh}")]
    BvhMismatch { bvh: usize, mesh: usize },
    #[error("{what} has {actual} entries, expected {expected} ({width}x{height} pixels)")]
    SizeMismatch { what: &'static str, expected: usize, actual: usize, width: u32, height: u32 },
    #[error("sample at pixel ({x}, {y}) names triangle {triangle}, but the mesh has {triangles} triangles")]
    TriangleOutOfRange { x: u32, y: u32, triangle: u32, triangles: usize },
    #[error("sample at pixel ({x}, {y}) has a non-finite world position {position:?}")]
    NonFiniteSample { x: u32, y: u32, position: [f32; 3] },
    #[error("invalid light {light:?}: coordinates must be finite, and a directional light (w = 0) needs a non-zero direction")]
    InvalidLight { light: [f32; 4] },
    #[error("non-finite eye position {eye:?}")]
    InvalidEye { eye: [f32; 3] },
}
