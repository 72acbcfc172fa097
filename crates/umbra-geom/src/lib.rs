//! umbra-geom: everything umbra knows about triangle soups, without GL.
//!
//! * [`mesh`]: the plain indexed triangle mesh every loader yields.
//! * [`load`]: Wavefront OBJ, glTF 2.0, PLY, STL, any of them gzip-compressed.
//! * [`scene`]: procedural scenes (`spheres:N`, `box`, `default`) and `--ground`.
//! * [`weld`]: exact-position welding; degenerate triangles dropped and counted.
//! * [`adjacency`]: every unique edge with all of its opposite vertices.
//! * [`order`]: the strict vertex order of paper 001, Eq. 1 / Alg. 2.
//! * [`multiplicity`]: deterministic multiplicity with a reference edge, 001 Alg. 3-4.
//! * [`silhouette`]: CPU shadow-volume sides and caps from the multiplicities, 001 Eq. 2.

pub mod adjacency;
pub mod load;
pub mod mesh;
pub mod multiplicity;
pub mod order;
pub mod scene;
pub mod sides_data;
pub mod silhouette;
pub mod weld;

pub use adjacency::EdgeAdjacency;
pub use mesh::{Aabb, Mesh};
pub use weld::WeldedMesh;

/// A light in homogeneous world coordinates: `w = 1` a point light at `(x, y, z)`,
/// `w = 0` a directional light shining *from* direction `(x, y, z)` (towards `-(x, y, z)`).
pub type Light = [f32; 4];
