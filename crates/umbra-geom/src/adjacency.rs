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

/// Vertices per parallel work item of [`EdgeAdjacency::build`].
const VERTICES_PER_BLOCK: usize = 4096;
/// Triangles or records per parallel work item of the simple passes.
const ITEMS_PER_JOB: usize = 1 << 14;

/// `slice` cut into consecutive, non-overlapping mutable parts covering `ranges` (which must
/// be ascending and adjacent, starting at 0).
fn split_by_ranges<T>(mut slice: &mut [T], ranges: impl Iterator<Item = std::ops::Range<usize>>) -> Vec<&mut [T]> {
    let mut parts = Vec::new();
    let mut at = 0;
    for range in ranges {
        debug_assert_eq!(range.start, at);
        let (part, rest) = std::mem::take(&mut slice).split_at_mut(range.end - at);
        parts.push(part);
        slice = rest;
        at = range.end;
    }
    parts
}

/// All unique edges of a welded mesh with their opposite vertices (CSR layout).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct EdgeAdjacency {
    /// `[a, b]` with `a < b` in the vertex order (not by index).
    pub edges: Vec<[u32; 2]>,
    /// Opposite vertices of edge `e` are `opposites[opposite_start[e]..opposite_start[e + 1]]`.
    pub opposite_start: Vec<u32>,
    /// Opposite vertices of all edges, edge by edge (see `opposite_start`).
    pub opposites: Vec<u32>,
}

impl EdgeAdjacency {
    /// Builds the adjacency of `mesh` (whose triangles have three distinct vertices).
    ///
    /// One record per (triangle, edge) — the edge's high vertex index and its opposite
    /// vertex — is bucketed by the edge's low vertex index with a counting sort (stable, so
    /// each bucket is in triangle order), each bucket is stably sorted by high index, and
    /// runs of equal (low, high) become the edges: edges sorted by their vertex indices,
    /// opposites in triangle order.
    ///
    /// # Panics
    /// If a triangle indexes past `mesh.positions` (never the case for a [`crate::weld`]
    /// result).
    pub fn build(mesh: &WeldedMesh) -> Self {
        let vertices = mesh.positions.len();
        let largest_index =
            mesh.triangles.par_chunks(ITEMS_PER_JOB).map(|c| c.iter().flatten().copied().max()).max().flatten();
        assert!(
            largest_index.is_none_or(|v| (v as usize) < vertices),
            "EdgeAdjacency::build: a triangle indexes past the {vertices} positions"
        );
        // Counting sort by low vertex: bucket_start[v]..bucket_start[v + 1] are v's records.
        // In parallel over `parts` ranges of low vertices; each part scans every triangle
        // and keeps the edges whose low vertex is its own.
        let parts = rayon::current_num_threads().clamp(1, 8);
        let part = |j: usize| vertices * j / parts..vertices * (j + 1) / parts;
        let own = |range: &std::ops::Range<usize>, v: u32| (v as usize).wrapping_sub(range.start) < range.len();
        let mut bucket_start = vec![0u32; vertices + 1];
        split_by_ranges(&mut bucket_start[1..], (0..parts).map(part)).into_par_iter().enumerate().for_each(
            |(j, counts)| {
                let range = part(j);
                for &[i0, i1, i2] in &mesh.triangles {
                    for lo in [i0.min(i1), i1.min(i2), i2.min(i0)] {
                        if own(&range, lo) {
                            counts[lo as usize - range.start] += 1;
                        }
                    }
                }
            },
        );
        for v in 0..vertices {
            bucket_start[v + 1] += bucket_start[v];
        }
        // Record = (high vertex << 32) | opposite vertex, in triangle order within a bucket.
        let mut records = vec![0u64; 3 * mesh.triangles.len()];
        let part_records = |j: usize| bucket_start[part(j).start] as usize..bucket_start[part(j).end] as usize;
        split_by_ranges(&mut records, (0..parts).map(part_records)).into_par_iter().enumerate().for_each(
            |(j, records)| {
                let range = part(j);
                let base = bucket_start[range.start];
                let mut fill: Vec<u32> = bucket_start[range.clone()].iter().map(|&s| s - base).collect();
                for &[i0, i1, i2] in &mesh.triangles {
                    // Edge k of a triangle is (v[k], v[k+1]); its opposite vertex is v[k+2].
                    for (a, b, o) in [(i0, i1, i2), (i1, i2, i0), (i2, i0, i1)] {
                        let lo = a.min(b);
                        if own(&range, lo) {
                            let slot = &mut fill[lo as usize - range.start];
                            records[*slot as usize] = (u64::from(a.max(b)) << 32) | u64::from(o);
                            *slot += 1;
                        }
                    }
                }
            },
        );

        // Per block of vertices, in parallel: sort the buckets, count the edges.
        let blocks = vertices.div_ceil(VERTICES_PER_BLOCK);
        let block_records = |block: usize| {
            let first = bucket_start[block * VERTICES_PER_BLOCK] as usize;
            let last = bucket_start[((block + 1) * VERTICES_PER_BLOCK).min(vertices)] as usize;
            first..last
        };
        let mut edges_per_block: Vec<usize> = split_by_ranges(&mut records, (0..blocks).map(block_records))
            .into_par_iter()
            .enumerate()
            .map(|(block, recs)| {
                let base = bucket_start[block * VERTICES_PER_BLOCK];
                let mut edges = 0;
                for v in block * VERTICES_PER_BLOCK..((block + 1) * VERTICES_PER_BLOCK).min(vertices) {
                    let bucket = &mut recs[(bucket_start[v] - base) as usize..(bucket_start[v + 1] - base) as usize];
                    // Stable: records of one edge stay in triangle order.
                    bucket.sort_by_key(|record| record >> 32);
                    edges += bucket.chunk_by(|x, y| x >> 32 == y >> 32).count();
                }
                edges
            })
            .collect();
        // Exclusive prefix sums: the first edge of each block.
        let mut total_edges = 0;
        for count in &mut edges_per_block {
            let c = *count;
            *count = total_edges;
            total_edges += c;
        }
        edges_per_block.push(total_edges);

        // Per block, in parallel: write the edges (oriented by the vertex order) and where
        // their opposites start.
        let mut edges = vec![[0u32; 2]; total_edges];
        let mut opposite_start = vec![0u32; total_edges + 1];
        let edge_ranges = || (0..blocks).map(|b| edges_per_block[b]..edges_per_block[b + 1]);
        split_by_ranges(&mut edges, edge_ranges())
            .into_par_iter()
            .zip(split_by_ranges(&mut opposite_start[..total_edges], edge_ranges()))
            .enumerate()
            .for_each(|(block, (edges, starts))| {
                let mut e = 0;
                for lo in block * VERTICES_PER_BLOCK..((block + 1) * VERTICES_PER_BLOCK).min(vertices) {
                    let mut r = bucket_start[lo] as usize;
                    let bucket_end = bucket_start[lo + 1] as usize;
                    while r < bucket_end {
                        let hi = (records[r] >> 32) as u32;
                        let lo = lo as u32;
                        let in_order = greater(mesh.positions[lo as usize], mesh.positions[hi as usize]) < 0;
                        edges[e] = if in_order { [lo, hi] } else { [hi, lo] };
                        starts[e] = r as u32;
                        e += 1;
                        while r < bucket_end && (records[r] >> 32) as u32 == hi {
                            r += 1;
                        }
                    }
                }
            });
        opposite_start[total_edges] = records.len() as u32;

        let mut opposites = vec![0u32; records.len()];
        opposites.par_chunks_mut(ITEMS_PER_JOB).zip(records.par_chunks(ITEMS_PER_JOB)).for_each(|(o, r)| {
            for (o, &r) in o.iter_mut().zip(r) {
                *o = r as u32;
            }
        });
        EdgeAdjacency { edges, opposite_start, opposites }
    }

    /// Number of unique edges.
    pub fn len(&self) -> usize {
        self.edges.len()
    }

    /// Whether there are no edges.
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
