//! Welding by exact position.
//!
//! Real scenes are split per material (Crytek Sponza) or otherwise unwelded, so a shared
//! position appears as several vertices; edge adjacency (paper 001, Section 2.2: "arbitrary
//! triangle soup") needs them to be one. Welding is by *exact* position: no epsilon, so
//! no two distinct positions are ever merged and the vertex order of [`crate::order`] stays
//! strict over the welded vertices. `-0.0` is treated as `+0.0` (they compare equal).
//!
//! A triangle whose welded vertices are not three distinct ones is degenerate: it has no
//! area, casts no shadow and has no well-defined edges, so it is dropped and counted.
//! Zero-area triangles with three distinct vertices (collinear) are real input and kept.
//!
//! Deterministic: welded vertices are numbered in order of first use by the triangles, and
//! triangles keep their input order. Sort-based and parallel (rayon).

use rayon::prelude::*;

use crate::mesh::Mesh;

/// A welded mesh: every position occurs once, every triangle has three distinct vertices.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct WeldedMesh {
    /// Distinct positions, numbered in order of first use.
    pub positions: Vec<[f32; 3]>,
    /// Triangles with three distinct vertex indices, in input order.
    pub triangles: Vec<[u32; 3]>,
    /// For each welded triangle, the index of the input triangle it came from.
    pub source_triangle: Vec<u32>,
    /// Input triangles dropped because two of their welded vertices coincide
    /// (or because an index was out of range, which loaders never produce).
    pub degenerate_triangles: usize,
}

/// The bit pattern a position is welded by: `-0.0` mapped to `+0.0`.
#[inline]
fn weld_key(p: [f32; 3]) -> [u32; 3] {
    p.map(|c| if c == 0.0 { 0 } else { c.to_bits() })
}

/// Welds `mesh` by exact position and drops degenerate triangles.
pub fn weld(mesh: &Mesh) -> WeldedMesh {
    let n = mesh.positions.len();
    // Every input vertex, sorted by its position bits (ties by index: deterministic).
    let mut order: Vec<u32> = (0..n as u32).collect();
    let keys: Vec<[u32; 3]> = mesh.positions.par_iter().map(|&p| weld_key(p)).collect();
    order.par_sort_unstable_by_key(|&i| (keys[i as usize], i));
    // Representative of each input vertex: the first input vertex with the same key.
    let mut representative = vec![0u32; n];
    let mut i = 0;
    while i < n {
        let first = order[i];
        let mut j = i;
        while j < n && keys[order[j] as usize] == keys[first as usize] {
            representative[order[j] as usize] = first;
            j += 1;
        }
        i = j;
    }
    // Number welded vertices by first use in triangle order.
    const UNUSED: u32 = u32::MAX;
    let mut welded_index = vec![UNUSED; n];
    let mut positions = Vec::new();
    let mut triangles = Vec::with_capacity(mesh.triangles.len());
    let mut source_triangle = Vec::with_capacity(mesh.triangles.len());
    let mut degenerate_triangles = 0;
    for (t, tri) in mesh.triangles.iter().enumerate() {
        if tri.iter().any(|&v| v as usize >= n) {
            degenerate_triangles += 1;
            continue;
        }
        let r = tri.map(|v| representative[v as usize]);
        if r[0] == r[1] || r[1] == r[2] || r[0] == r[2] {
            degenerate_triangles += 1;
            continue;
        }
        let w = r.map(|v| {
            let slot = &mut welded_index[v as usize];
            if *slot == UNUSED {
                *slot = positions.len() as u32;
                let p = mesh.positions[v as usize];
                positions.push(p.map(|c| if c == 0.0 { 0.0 } else { c }));
            }
            *slot
        });
        triangles.push(w);
        source_triangle.push(t as u32);
    }
    WeldedMesh { positions, triangles, source_triangle, degenerate_triangles }
}

impl WeldedMesh {
    /// Welds a mesh; see [`weld`].
    pub fn from_mesh(mesh: &Mesh) -> Self {
        weld(mesh)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn soup(tris: &[[[f32; 3]; 3]]) -> Mesh {
        let mut m = Mesh::default();
        for t in tris {
            let b = m.positions.len() as u32;
            m.positions.extend_from_slice(t);
            m.triangles.push([b, b + 1, b + 2]);
        }
        m
    }

    #[test]
    fn weld_unwelded_quad() {
        let m = soup(&[
            [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0]],
            [[0.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]],
        ]);
        let w = weld(&m);
        assert_eq!(w.positions.len(), 4);
        assert_eq!(w.triangles, vec![[0, 1, 2], [0, 2, 3]]);
        assert_eq!(w.degenerate_triangles, 0);
    }

    #[test]
    fn weld_drops_degenerate_keeps_zero_area() {
        let m = soup(&[
            [[0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [1.0, 1.0, 0.0]], // two equal vertices
            [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]], // collinear: kept
        ]);
        let w = weld(&m);
        assert_eq!(w.degenerate_triangles, 1);
        assert_eq!(w.triangles.len(), 1);
        assert_eq!(w.source_triangle, vec![1]);
    }

    #[test]
    fn weld_signed_zero() {
        let m = soup(&[
            [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            [[-0.0, 0.0, -0.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]],
        ]);
        let w = weld(&m);
        assert_eq!(w.positions.len(), 4);
        assert!(w.positions.iter().all(|p| p.iter().all(|c| c.to_bits() != (-0.0f32).to_bits())));
    }

    #[test]
    fn weld_index_out_of_range_is_dropped_not_panic() {
        let m = Mesh { positions: vec![[0.0; 3]; 2], triangles: vec![[0, 1, 7]], normals: None };
        let w = weld(&m);
        assert_eq!(w.triangles.len(), 0);
        assert_eq!(w.degenerate_triangles, 1);
    }
}
