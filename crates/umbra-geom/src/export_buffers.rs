//! The buffers paper 003's browser client draws from, built from a welded mesh.
//!
//! One implementation for both producers of these buffers: `umbra export` (umbra-cli) writes
//! them to files, and umbra-wasm computes them inside a browser from a three.js geometry.
//! Paper 003 (Milet et al., "Fast robust and precise shadow algorithm for WebGL 1.0
//! platform"), Section 2.6:
//!
//! | buffer | contents | elements |
//! | --- | --- | --- |
//! | `positions` | welded vertex positions, 3 × f32 | `3 v` |
//! | `normals` | flat unit normal per triangle ([`crate::mesh::flat_normal`], in f64), 3 × f32 | `3 t` |
//! | `indices` | triangles, 3 × u32, counter-clockwise = front | `3 t` |
//! | `sides_data` | `2 + maxMult` vec4 per edge record (Eq. 8, [`build_sides_data`]) | `4 (2 + maxMult) e` |
//! | `caps_data` | 3 vec4 per triangle (Eq. 9, [`build_caps_data`]) | `12 t` |
//! | `edge_triangles` | `maxMult` × i32 per edge record ([`build_edge_triangles`]) | `maxMult e` |
//!
//! `maxMult` is planned for [`PORTABLE_VERTEX_ATTRIBS`] vertex attributes, the minimum that
//! OpenGL 4.5, OpenGL ES 3.0 and WebGL 2 all guarantee ([`portable_max_mult`]). The bytes a
//! browser reads are the little-endian bytes of these vectors ([`le_bytes`]).

use crate::adjacency::EdgeAdjacency;
use crate::edge_triangles::{build_edge_triangles, EdgeTrianglesError};
use crate::mesh::{flat_normal, Aabb};
use crate::sides_data::{build_caps_data, build_sides_data, max_mult_for_attribs, SidesDataError, MAX_MULT_LIMIT};
use crate::weld::{triangle_bounds, WeldedMesh};

/// Vertex attributes every OpenGL 4.5, OpenGL ES 3.0 and WebGL 2 implementation offers
/// (GL_MAX_VERTEX_ATTRIBS is at least 16): the budget of one edge record, `2 + maxMult` vec4.
pub const PORTABLE_VERTEX_ATTRIBS: usize = 16;

/// Why the buffers could not be built (a welded mesh whose indices are out of range, or more
/// triangles than an i32 can name).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ExportBuffersError {
    /// Sides-data or caps-data.
    #[error(transparent)]
    SidesData(#[from] SidesDataError),
    /// The edge-triangle table.
    #[error(transparent)]
    EdgeTriangles(#[from] EdgeTrianglesError),
}

/// Every buffer of the module documentation's table, with the counts that describe them.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ExportBuffers {
    /// Welded positions, `x, y, z` per vertex.
    pub positions: Vec<f32>,
    /// Flat unit normal per triangle, `x, y, z` (zero for a zero-area triangle).
    pub normals: Vec<f32>,
    /// Three welded vertex indices per triangle.
    pub indices: Vec<u32>,
    /// Eq. 8: `2 + maxMult` vec4 per edge record.
    pub sides_data: Vec<f32>,
    /// Eq. 9: three vec4 `(P_i, 1)` per triangle.
    pub caps_data: Vec<f32>,
    /// `maxMult` signed triangle numbers per edge record.
    pub edge_triangles: Vec<i32>,
    /// Opposite-vertex slots per edge record (`maxMult` of Eq. 8); at least 1.
    pub max_mult: usize,
    /// Welded vertices.
    pub vertices: usize,
    /// Welded, non-degenerate triangles (`t` of Eq. 9).
    pub triangles: usize,
    /// Unique edges.
    pub edges: usize,
    /// Edge records (`e` of Eq. 8; more than `edges` when some were split).
    pub records: usize,
    /// Bounds of the vertices the triangles use; `None` without triangles.
    pub bounds: Option<Aabb>,
}

/// `maxMult` for `adj` with [`PORTABLE_VERTEX_ATTRIBS`] attributes and [`MAX_MULT_LIMIT`]
/// slots ([`max_mult_for_attribs`]).
pub fn portable_max_mult(adj: &EdgeAdjacency) -> usize {
    max_mult_for_attribs(adj, PORTABLE_VERTEX_ATTRIBS, MAX_MULT_LIMIT)
}

/// Builds every buffer of `mesh` (see the module documentation). A mesh without triangles
/// gives empty buffers, `maxMult` 1 and no bounds. Deterministic.
pub fn build_export_buffers(mesh: &WeldedMesh) -> Result<ExportBuffers, ExportBuffersError> {
    let adj = EdgeAdjacency::build(mesh);
    let max_mult = portable_max_mult(&adj);
    let sides = build_sides_data(mesh, &adj, max_mult)?;
    let caps = build_caps_data(mesh)?;
    let edge_triangles = build_edge_triangles(mesh, &adj, max_mult)?;
    Ok(ExportBuffers {
        positions: mesh.positions.iter().flatten().copied().collect(),
        normals: mesh.triangles.iter().flat_map(|&t| flat_normal(&mesh.positions, t)).collect(),
        indices: mesh.triangles.iter().flatten().copied().collect(),
        records: sides.records(),
        sides_data: sides.data.iter().flatten().copied().collect(),
        caps_data: caps.iter().flatten().copied().collect(),
        edge_triangles,
        max_mult,
        vertices: mesh.positions.len(),
        triangles: mesh.triangles.len(),
        edges: adj.len(),
        // build_caps_data has checked every index.
        bounds: triangle_bounds(mesh),
    })
}

/// A value a buffer holds, written little-endian.
pub trait LeBytes: Copy {
    /// The four little-endian bytes.
    fn le(self) -> [u8; 4];
}

impl LeBytes for f32 {
    fn le(self) -> [u8; 4] {
        self.to_le_bytes()
    }
}

impl LeBytes for u32 {
    fn le(self) -> [u8; 4] {
        self.to_le_bytes()
    }
}

impl LeBytes for i32 {
    fn le(self) -> [u8; 4] {
        self.to_le_bytes()
    }
}

/// The little-endian bytes of a buffer: what a browser reads into a typed array.
pub fn le_bytes<T: LeBytes>(values: &[T]) -> Vec<u8> {
    values.iter().flat_map(|v| v.le()).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sides_data::{caps_data_bytes, record_count, sides_data_bytes};
    use crate::weld::weld;
    use crate::Mesh;

    fn book(pages: usize) -> WeldedMesh {
        let mut m = Mesh { positions: vec![[0.0, 0.0, 0.0], [0.0, 1.0, 0.0]], ..Mesh::default() };
        for k in 0..pages {
            let a = k as f32;
            m.positions.push([a.cos(), 0.5, a.sin()]);
            m.triangles.push([0, 1, 2 + k as u32]);
        }
        weld(&m)
    }

    #[test]
    fn sizes_follow_eq8_and_eq9() {
        for pages in [1, 3, 20] {
            let mesh = book(pages);
            let b = build_export_buffers(&mesh).expect("buffers");
            let adj = EdgeAdjacency::build(&mesh);
            assert_eq!(b.records, record_count(&adj, b.max_mult));
            assert_eq!(4 * b.sides_data.len(), sides_data_bytes(b.records, b.max_mult));
            assert_eq!(4 * b.caps_data.len(), caps_data_bytes(b.triangles));
            assert_eq!(b.edge_triangles.len(), b.records * b.max_mult);
            assert_eq!((b.positions.len(), b.normals.len(), b.indices.len()), (3 * b.vertices, 3 * pages, 3 * pages));
            assert!(b.max_mult >= 1 && b.max_mult <= MAX_MULT_LIMIT);
        }
        assert_eq!(build_export_buffers(&book(20)).expect("buffers").max_mult, 14, "split at 16 - 2 slots");
    }

    #[test]
    fn no_triangles_gives_empty_buffers() {
        let b = build_export_buffers(&WeldedMesh::default()).expect("empty");
        assert_eq!((b.max_mult, b.records, b.bounds), (1, 0, None));
        assert!(b.sides_data.is_empty() && b.edge_triangles.is_empty());
    }

    #[test]
    fn le_bytes_are_little_endian() {
        assert_eq!(le_bytes(&[1u32, 256]), vec![1, 0, 0, 0, 0, 1, 0, 0]);
        assert_eq!(le_bytes(&[-1i32]), vec![255; 4]);
        assert_eq!(le_bytes(&[1.0f32]), 1.0f32.to_le_bytes().to_vec());
    }
}
