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
//! triangles keep their input order. Equal positions are found with a hash table.

use rayon::prelude::*;

use crate::mesh::{Aabb, Mesh};

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
    // Group of each input vertex: the first input vertex with the same key (any canonical
    // choice gives the same output, since a group's vertices share one welded position).
    let group = position_groups(&mesh.positions);
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
        let r = tri.map(|v| group[v as usize]);
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

/// For every position, the index of the first position with the same [`weld_key`]: an
/// open-addressing hash table (linear probing, at most half full) of vertex indices,
/// filled in index order, so the first vertex of a key is the one found.
fn position_groups(positions: &[[f32; 3]]) -> Vec<u32> {
    const EMPTY: u32 = u32::MAX;
    let bits = (2 * positions.len()).max(16).next_power_of_two().trailing_zeros();
    let mask = (1usize << bits) - 1;
    let mut table = vec![EMPTY; mask + 1];
    let keys: Vec<[u32; 3]> = positions.par_iter().map(|&p| weld_key(p)).collect();
    keys.iter()
        .enumerate()
        .map(|(v, key)| {
            let mut slot = (key_hash(*key) >> (64 - bits)) as usize;
            loop {
                let first = table[slot];
                if first == EMPTY {
                    table[slot] = v as u32;
                    return v as u32;
                }
                if keys[first as usize] == *key {
                    return first;
                }
                slot = (slot + 1) & mask;
            }
        })
        .collect()
}

/// A multiplicative hash of a key (FxHash-style: rotate, xor, multiply by an odd constant);
/// the table index is taken from its high bits, which mix all three words.
#[inline]
fn key_hash(key: [u32; 3]) -> u64 {
    const K: u64 = 0x517c_c1b7_2722_0a95;
    let mut h = 0u64;
    for word in key {
        h = (h.rotate_left(5) ^ u64::from(word)).wrapping_mul(K);
    }
    h
}

impl WeldedMesh {
    /// Welds a mesh; see [`weld`].
    pub fn from_mesh(mesh: &Mesh) -> Self {
        weld(mesh)
    }

    /// Every triangle's vertex indices are in range (a mesh built by hand may break what
    /// [`weld`] guarantees): checked before a backend uploads it.
    pub fn check_indices(&self) -> Result<(), IndexOutOfRange> {
        match self.triangles.iter().flatten().find(|&&i| i as usize >= self.positions.len()) {
            Some(&index) => Err(IndexOutOfRange { index, positions: self.positions.len() }),
            None => Ok(()),
        }
    }
}

/// A triangle names a vertex the mesh does not have ([`WeldedMesh::check_indices`]).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("triangle index {index} out of range for {positions} positions")]
pub struct IndexOutOfRange {
    /// The first index out of range.
    pub index: u32,
    /// The mesh's number of positions.
    pub positions: usize,
}

/// One unit normal per triangle ([`crate::mesh::flat_normal`]) as `[x, y, z, 0]`: the normal
/// buffer the GPU scenes of umbra-gl and umbra-wgpu upload.
pub fn triangle_normals(mesh: &WeldedMesh) -> Vec<[f32; 4]> {
    mesh.triangles
        .iter()
        .map(|&t| {
            let n = crate::mesh::flat_normal(&mesh.positions, t);
            [n[0], n[1], n[2], 0.0]
        })
        .collect()
}

/// Bounds of the vertices the triangles use (what the GPU scenes of umbra-gl and umbra-wgpu report as their bounds); `None`
/// without triangles.
pub fn triangle_bounds(mesh: &WeldedMesh) -> Option<Aabb> {
    let mut it = mesh.triangles.iter().flatten().map(|&i| mesh.positions[i as usize]);
    let first = it.next()?;
    Some(it.fold(Aabb { min: first, max: first }, |b, p| Aabb {
        min: [0, 1, 2].map(|k| b.min[k].min(p[k])),
        max: [0, 1, 2].map(|k| b.max[k].max(p[k])),
    }))
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::Light;

    /// xorshift64*: a deterministic stream for test inputs.
    pub(crate) struct Rng(u64);
    impl Rng {
        pub(crate) fn next(&mut self) -> u64 {
            self.0 ^= self.0 >> 12;
            self.0 ^= self.0 << 25;
            self.0 ^= self.0 >> 27;
            self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
        }
        pub(crate) fn below(&mut self, n: u64) -> u64 {
            self.next() % n
        }
    }

    /// Inputs the optimised weld, adjacency and extraction are checked against their
    /// straightforward references on: a large random soup on a coarse grid (coincident
    /// positions in many copies, `-0.0`, degenerate and duplicate triangles, non-manifold
    /// edges, out-of-range indices), an exploded (unwelded, shuffled) grid of UV spheres
    /// spanning many parallel chunks, a single triangle and an empty mesh.
    pub(crate) fn reference_inputs() -> Vec<Mesh> {
        let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
        let mut soup = Mesh::default();
        for _ in 0..6000 {
            let c = |rng: &mut Rng| match rng.below(8) {
                0 => -0.0,
                1 => (rng.below(1000) as f32) * 0.001 - 0.5,
                k => (rng.below(5) as f32 - 2.0) * 0.5 * (k as f32 - 1.0),
            };
            soup.positions.push([c(&mut rng), c(&mut rng), c(&mut rng)]);
        }
        let n = soup.positions.len() as u64;
        for _ in 0..20000 {
            let mut t = [0; 3].map(|_| rng.below(n) as u32);
            if rng.below(500) == 0 {
                t[rng.below(3) as usize] = n as u32 + 7; // out of range
            }
            soup.triangles.push(t);
            if rng.below(50) == 0 {
                soup.triangles.push([t[1], t[0], t[2]]); // duplicate, opposite winding
            }
        }
        let mut spheres = Mesh::default();
        for k in 0..9 {
            let s = crate::scene::uv_sphere([3.0 * (k % 3) as f32, 0.5 * k as f32, 3.0 * (k / 3) as f32], 1.0, 40, 25);
            spheres.append(&s);
        }
        // Explode: every triangle corner its own vertex, triangles in a shuffled order.
        let mut exploded = Mesh::default();
        let mut order: Vec<usize> = (0..spheres.triangles.len()).collect();
        for i in (1..order.len()).rev() {
            order.swap(i, rng.below(i as u64 + 1) as usize);
        }
        for t in order {
            let b = exploded.positions.len() as u32;
            for &v in &spheres.triangles[t] {
                exploded.positions.push(spheres.positions[v as usize]);
            }
            exploded.triangles.push([b, b + 1, b + 2]);
        }
        let single = Mesh {
            positions: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            triangles: vec![[0, 1, 2]],
            normals: None,
        };
        vec![soup, exploded, spheres, single, Mesh::default()]
    }

    /// Point lights inside the bounds and on the coarse grid (in the plane of many soup
    /// triangles: edge-on cases), directional lights along an axis and oblique.
    pub(crate) fn reference_lights(mesh: &WeldedMesh) -> [Light; 4] {
        let c = mesh.positions.first().copied().unwrap_or([0.0; 3]);
        [
            [c[0] + 0.123, c[1] + 0.71, c[2] - 0.05, 1.0],
            [0.5, 1.0, -0.5, 1.0],
            [0.0, 1.0, 0.0, 0.0],
            [0.3, 0.8, 0.2, 0.0],
        ]
    }

    /// The original sort-based weld the optimised one must reproduce exactly.
    fn reference_weld(mesh: &Mesh) -> WeldedMesh {
        let n = mesh.positions.len();
        let keys: Vec<[u32; 3]> = mesh.positions.iter().map(|&p| weld_key(p)).collect();
        let mut order: Vec<u32> = (0..n as u32).collect();
        order.sort_by_key(|&i| (keys[i as usize], i));
        let mut representative = vec![0u32; n];
        for i in 0..n {
            let first = if i > 0 && keys[order[i] as usize] == keys[order[i - 1] as usize] {
                representative[order[i - 1] as usize]
            } else {
                order[i]
            };
            representative[order[i] as usize] = first;
        }
        let mut welded_index = vec![u32::MAX; n];
        let mut out = WeldedMesh::default();
        for (t, tri) in mesh.triangles.iter().enumerate() {
            if tri.iter().any(|&v| v as usize >= n) {
                out.degenerate_triangles += 1;
                continue;
            }
            let r = tri.map(|v| representative[v as usize]);
            if r[0] == r[1] || r[1] == r[2] || r[0] == r[2] {
                out.degenerate_triangles += 1;
                continue;
            }
            let w = r.map(|v| {
                if welded_index[v as usize] == u32::MAX {
                    welded_index[v as usize] = out.positions.len() as u32;
                    out.positions.push(mesh.positions[v as usize].map(|c| if c == 0.0 { 0.0 } else { c }));
                }
                welded_index[v as usize]
            });
            out.triangles.push(w);
            out.source_triangle.push(t as u32);
        }
        out
    }

    fn position_bits(w: &WeldedMesh) -> Vec<[u32; 3]> {
        w.positions.iter().map(|p| p.map(f32::to_bits)).collect()
    }

    #[test]
    fn weld_matches_sort_reference() {
        for mesh in reference_inputs() {
            let (got, expected) = (weld(&mesh), reference_weld(&mesh));
            assert_eq!(position_bits(&got), position_bits(&expected));
            assert_eq!(got.triangles, expected.triangles);
            assert_eq!(got.source_triangle, expected.source_triangle);
            assert_eq!(got.degenerate_triangles, expected.degenerate_triangles);
        }
        // The inputs do exercise welding and dropping.
        let inputs = reference_inputs();
        let (soup, exploded) = (weld(&inputs[0]), weld(&inputs[1]));
        assert!(soup.degenerate_triangles > 0 && soup.positions.len() < inputs[0].positions.len());
        assert_eq!(exploded.positions.len(), 9 * (2 + 40 * 24));
    }

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

    #[test]
    fn check_indices_names_the_first_index_out_of_range() {
        let mut w = weld(&soup(&[[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]]));
        assert_eq!(w.check_indices(), Ok(()));
        w.triangles.push([0, 9, 3]);
        let e = w.check_indices().unwrap_err();
        assert_eq!(e, IndexOutOfRange { index: 9, positions: 3 });
        assert_eq!(e.to_string(), "triangle index 9 out of range for 3 positions");
    }

    #[test]
    fn triangle_normals_follow_the_winding_with_w_zero() {
        // Counter-clockwise seen from +y, clockwise seen from +y, and zero-area (collinear).
        let w = weld(&soup(&[
            [[0.0, 0.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]],
            [[0.0, 1.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 1.0]],
            [[0.0, 2.0, 0.0], [1.0, 2.0, 0.0], [2.0, 2.0, 0.0]],
        ]));
        assert_eq!(triangle_normals(&w), vec![[0.0, 1.0, 0.0, 0.0], [0.0, -1.0, 0.0, 0.0], [0.0; 4]]);
    }
}
