//! umbra-geom: everything umbra knows about triangle soups, without GL.
//!
//! * [`mesh`]: the plain indexed triangle mesh every loader yields.
//! * [`load`]: Wavefront OBJ, glTF 2.0, PLY, STL, any of them gzip-compressed.
//! * [`scene`]: procedural scenes (`spheres:N`, `box`, `default`) and `--ground`.
//! * [`weld`]: exact-position welding; degenerate triangles dropped and counted.
//! * [`adjacency`]: every unique edge with all of its opposite vertices.
//! * [`edge_triangles`]: the triangle behind every opposite slot of the sides-data.
//! * [`export_buffers`]: the buffers paper 003's browser client draws from.
//! * [`order`]: the strict vertex order of paper 001, Eq. 1 / Alg. 2.
//! * [`ray_bvh`]: the binned-SAH hierarchy the `ray-bvh` method traces its shadow rays through.
//! * [`multiplicity`]: deterministic multiplicity with a reference edge, 001 Alg. 3-4.
//! * [`silhouette`]: CPU shadow-volume sides and caps from the multiplicities, 001 Eq. 2.
//! * [`camera`]: the infinite-far camera and its depth conventions, shared by every backend.
//! * [`frame`]: [`FrameParams`], the description of one frame every backend takes, and its
//!   shadow-volume [`Counter`].
//! * [`shadow_map`]: the cube and directional shadow-map matrices of the shadow-map baseline.
//! * [`image`]: the images every backend reads back (top row first) and their PNG output.
//!
//! # Examples
//!
//! Loading a mesh from bytes (any format of [`load::Format`]); errors name the file and the
//! line or byte offset:
//!
//! ```
//! use umbra_geom::load::{load_bytes, Format, LoadError};
//!
//! // Two triangles of a unit quad, written as a soup (every vertex repeated).
//! let obj = b"v 0 0 0\nv 1 0 0\nv 1 0 1\nv 0 0 0\nv 1 0 1\nv 0 0 1\nf 1 2 3\nf 4 5 6\n";
//! let mesh = load_bytes(obj, Format::Obj, "quad.obj")?;
//! assert_eq!((mesh.positions.len(), mesh.triangles.len()), (6, 2));
//!
//! let err = load_bytes(b"v 0 0 0\nf 1 2 3\n", Format::Obj, "bad.obj").unwrap_err();
//! assert!(matches!(err, LoadError::IndexOutOfRange { index: 2, .. }));
//! assert!(err.to_string().starts_with("bad.obj: line 2"), "{err}");
//! # Ok::<(), LoadError>(())
//! ```
//!
//! Welding a soup by exact position, then the edge adjacency: every unique edge with all
//! of its opposite vertices, however many (open, manifold and non-manifold edges alike):
//!
//! ```
//! use umbra_geom::{weld::weld, EdgeAdjacency, Mesh};
//!
//! // A "book": three triangles sharing the edge (0,0,0)-(0,1,0), vertices duplicated.
//! let spine = [[0.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
//! let pages = [[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [-1.0, 0.0, 0.0]];
//! let mut soup = Mesh::default();
//! for page in pages {
//!     let n = soup.positions.len() as u32;
//!     soup.positions.extend([spine[0], spine[1], page]);
//!     soup.triangles.push([n, n + 1, n + 2]);
//! }
//! let welded = weld(&soup);
//! assert_eq!(welded.positions.len(), 5); // 9 soup vertices, 5 distinct positions
//! assert_eq!(welded.degenerate_triangles, 0);
//!
//! let adj = EdgeAdjacency::build(&welded);
//! assert_eq!(adj.len(), 7); // the spine + 2 open edges per page
//! assert_eq!(adj.max_opposites(), 3); // the spine has all three pages
//! assert_eq!(adj.nonmanifold_edges(), 1);
//! assert_eq!(adj.open_edges(), 6);
//! ```
//!
//! Deterministic multiplicity (paper 001, Alg. 3-4): an edge's multiplicity is the signed
//! number of volume sides it needs; 0 means it is not a silhouette edge. Two coplanar
//! triangles of a quad lit from above: their shared diagonal cancels, the four borders are
//! silhouette edges of multiplicity +-1:
//!
//! ```
//! use umbra_geom::silhouette::{multiplicities, silhouette_stats};
//! use umbra_geom::{weld::weld, EdgeAdjacency, Light, Mesh};
//!
//! let quad = Mesh {
//!     positions: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 0.0, 1.0], [0.0, 0.0, 1.0]],
//!     triangles: vec![[0, 2, 1], [0, 3, 2]],
//!     normals: None,
//! };
//! let mesh = weld(&quad);
//! let adj = EdgeAdjacency::build(&mesh);
//! let point_light: Light = [0.5, 4.0, 0.5, 1.0]; // w = 1: a point light
//!
//! let m = multiplicities(&mesh, &adj, point_light);
//! assert_eq!(m.len(), 5);
//! for (e, &mult) in m.iter().enumerate() {
//!     let shared = adj.opposites(e).len() == 2;
//!     assert_eq!(mult.abs(), if shared { 0 } else { 1 }, "edge {:?}", adj.edges[e]);
//! }
//! // The same from a directional light (w = 0), and umbra info's statistics.
//! let sun: Light = [0.3, 1.0, 0.2, 0.0];
//! assert_eq!(silhouette_stats(&mesh, &adj, sun), (4, 4));
//! ```

#![warn(missing_docs)]

pub mod adjacency;
pub mod camera;
pub mod clearance;
pub mod edge_triangles;
pub mod export_buffers;
pub mod frame;
pub mod frame_images;
pub mod image;
pub mod load;
pub mod mesh;
pub mod multiplicity;
pub mod order;
pub mod ray_bvh;
pub mod receivers;
pub mod scene;
pub mod shadow_map;
pub mod sides_data;
pub mod silhouette;
pub mod vec3;
pub mod weld;
pub mod winding_bound;

pub use adjacency::EdgeAdjacency;
pub use frame::{Counter, FrameParams, InvalidFrame, Receivers};
pub use mesh::{Aabb, Mesh};
pub use weld::WeldedMesh;

/// A light in homogeneous world coordinates: `w = 1` a point light at `(x, y, z)`,
/// `w = 0` a directional light shining *from* direction `(x, y, z)` (towards `-(x, y, z)`).
pub type Light = [f32; 4];

/// A light a frame cannot use ([`check_light`]); the message names the light and the problem.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct InvalidLight(pub String);

/// Light `index` of a frame: finite, `w` = 0 or 1, and a directional light has a direction.
pub fn check_light(index: usize, l: &Light) -> Result<(), InvalidLight> {
    if l.iter().any(|v| !v.is_finite()) || !(l[3] == 0.0 || l[3] == 1.0) {
        return Err(InvalidLight(format!("light {index} = {l:?}: expected finite xyz and w = 0 or 1")));
    }
    if l[3] == 0.0 && l[0] == 0.0 && l[1] == 0.0 && l[2] == 0.0 {
        return Err(InvalidLight(format!("light {index} is directional with a zero direction")));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn check_light_names_the_bad_light() {
        assert!(check_light(0, &[1.0, 2.0, 3.0, 1.0]).is_ok());
        assert!(check_light(0, &[0.0, 1.0, 0.0, 0.0]).is_ok());
        let e = check_light(2, &[0.0, 0.0, 0.0, 0.0]).unwrap_err();
        assert_eq!(e.to_string(), "light 2 is directional with a zero direction");
        assert!(check_light(1, &[0.0, f32::NAN, 0.0, 1.0]).unwrap_err().to_string().starts_with("light 1 = "));
        assert!(check_light(0, &[0.0, 1.0, 0.0, 2.0]).is_err(), "w must be 0 or 1");
    }
}
