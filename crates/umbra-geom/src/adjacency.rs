//! Edge adjacency for triangle soups: every unique undirected edge with the list of *all*
//! its opposite vertices.
//!
//! Paper 001, Section 2.2 and Fig. 4-5 (an edge patch holds the edge's two vertices, the
//! number of opposite vertices and the opposite vertices); Kim, Kim & Turk 2008 for
//! non-manifold casters. No assumption of manifoldness or of consistent winding: an edge has
//! 1 (open), 2 (manifold) or any larger number (non-manifold) of opposite vertices, one per
//! triangle using it, duplicate triangles included.
//!
//! Each edge is stored as `[a, b]` with `positions[a] < positions[b]` in the vertex order of
//! [`crate::order`], which is the precondition of Alg. 3. Edges are sorted by their vertex
//! indices and opposite vertices listed in triangle order: deterministic.

use rayon::prelude::*;

use crate::order::greater;
use crate::weld::WeldedMesh;

/// All unique edges of a welded mesh with their opposite vertices (CSR layout).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct EdgeAdjacency {
    /// `[a, b]` with `a < b` in the vertex order (not by index).
    pub edges: Vec<[u32; 2]>,
    /// Opposite vertices of edge `e` are `opposites[opposite_start[e]..opposite_start[e + 1]]`.
    pub opposite_start: Vec<u32>,
    pub opposites: Vec<u32>,
}

impl EdgeAdjacency {
    /// Builds the adjacency of `mesh` (whose triangles have three distinct vertices).
    pub fn build(mesh: &WeldedMesh) -> Self {
        // One record per (triangle, edge): key = the edge's vertex indices (low, high),
        // tie-broken by the record's position so the sort is deterministic.
        let mut records: Vec<(u64, u32)> = mesh
            .triangles
            .par_iter()
            .enumerate()
            .flat_map_iter(|(t, &[i0, i1, i2])| {
                let key = |a: u32, b: u32| ((a.min(b) as u64) << 32) | a.max(b) as u64;
                let base = 3 * t as u32;
                [(key(i0, i1), base), (key(i1, i2), base + 1), (key(i2, i0), base + 2)]
            })
            .collect();
        records.par_sort_unstable();

        let mut edges = Vec::new();
        let mut opposite_start = Vec::new();
        let mut opposites = Vec::with_capacity(records.len());
        let mut i = 0;
        while i < records.len() {
            let key = records[i].0;
            let lo = (key >> 32) as u32;
            let hi = key as u32;
            let in_order = greater(mesh.positions[lo as usize], mesh.positions[hi as usize]) < 0;
            edges.push(if in_order { [lo, hi] } else { [hi, lo] });
            opposite_start.push(opposites.len() as u32);
            while i < records.len() && records[i].0 == key {
                let slot = records[i].1;
                let tri = mesh.triangles[(slot / 3) as usize];
                // Edge k of a triangle is (v[k], v[k+1]); its opposite vertex is v[k+2].
                opposites.push(tri[(slot as usize % 3 + 2) % 3]);
                i += 1;
            }
        }
        opposite_start.push(opposites.len() as u32);
        EdgeAdjacency { edges, opposite_start, opposites }
    }

    /// Number of unique edges.
    pub fn len(&self) -> usize {
        self.edges.len()
    }

    pub fn is_empty(&self) -> bool {
        self.edges.is_empty()
    }

    /// Opposite vertices of edge `edge`.
    #[inline]
    pub fn opposites(&self, edge: usize) -> &[u32] {
        &self.opposites[self.opposite_start[edge] as usize..self.opposite_start[edge + 1] as usize]
    }

    /// Edges with exactly one opposite vertex.
    pub fn open_edges(&self) -> usize {
        self.opposite_start.windows(2).filter(|w| w[1] - w[0] == 1).count()
    }

    /// Edges with three or more opposite vertices.
    pub fn nonmanifold_edges(&self) -> usize {
        self.opposite_start.windows(2).filter(|w| w[1] - w[0] >= 3).count()
    }

    /// The largest number of opposite vertices on one edge (0 for no edges).
    pub fn max_opposites(&self) -> usize {
        self.opposite_start.windows(2).map(|w| (w[1] - w[0]) as usize).max().unwrap_or(0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::Mesh;
    use crate::weld::tests::reference_inputs;
    use crate::weld::weld;

    /// The original sort-based build the optimised one must reproduce exactly: one record
    /// per (triangle, edge), sorted by (low index, high index, record position).
    fn reference_build(mesh: &WeldedMesh) -> EdgeAdjacency {
        let mut records: Vec<(u64, u32)> = Vec::new();
        for (t, &[i0, i1, i2]) in mesh.triangles.iter().enumerate() {
            let key = |a: u32, b: u32| ((a.min(b) as u64) << 32) | a.max(b) as u64;
            let base = 3 * t as u32;
            records.extend([(key(i0, i1), base), (key(i1, i2), base + 1), (key(i2, i0), base + 2)]);
        }
        records.sort();
        let mut adj = EdgeAdjacency::default();
        for (i, &(key, slot)) in records.iter().enumerate() {
            if i == 0 || records[i - 1].0 != key {
                let (lo, hi) = ((key >> 32) as u32, key as u32);
                let in_order = greater(mesh.positions[lo as usize], mesh.positions[hi as usize]) < 0;
                adj.edges.push(if in_order { [lo, hi] } else { [hi, lo] });
                adj.opposite_start.push(adj.opposites.len() as u32);
            }
            let tri = mesh.triangles[(slot / 3) as usize];
            adj.opposites.push(tri[(slot as usize % 3 + 2) % 3]);
        }
        adj.opposite_start.push(adj.opposites.len() as u32);
        adj
    }

    #[test]
    fn adjacency_matches_sort_reference() {
        let mut nonmanifold = 0;
        for mesh in reference_inputs() {
            let w = weld(&mesh);
            let got = EdgeAdjacency::build(&w);
            assert_eq!(got, reference_build(&w));
            nonmanifold += got.nonmanifold_edges();
        }
        assert!(nonmanifold > 0, "the inputs must include non-manifold edges");
    }

    #[test]
    fn adjacency_single_triangle_is_open() {
        let m = Mesh {
            positions: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            triangles: vec![[0, 1, 2]],
            normals: None,
        };
        let a = EdgeAdjacency::build(&weld(&m));
        assert_eq!(a.len(), 3);
        assert_eq!(a.open_edges(), 3);
        assert_eq!(a.max_opposites(), 1);
        for e in 0..3 {
            let [x, y] = a.edges[e];
            let o = a.opposites(e)[0];
            assert!(x != o && y != o);
        }
    }

    #[test]
    fn adjacency_book_of_pages() {
        // 5 pages sharing the spine (0,0,0)-(0,0,1), one duplicated with opposite winding.
        let mut m = Mesh { positions: vec![[0.0, 0.0, 0.0], [0.0, 0.0, 1.0]], ..Default::default() };
        for k in 0..5 {
            let a = k as f32;
            m.positions.push([a.cos(), a.sin(), 0.5]);
            m.triangles.push([0, 1, 2 + k]);
        }
        m.triangles.push([1, 0, 2]);
        let adj = EdgeAdjacency::build(&weld(&m));
        assert_eq!(adj.max_opposites(), 6);
        assert_eq!(adj.nonmanifold_edges(), 1);
        let spine = (0..adj.len()).find(|&e| adj.opposites(e).len() == 6).unwrap();
        assert_eq!(adj.edges[spine], [0, 1]);
    }
}
