//! Edge triangles: for every opposite slot of the sides-data ([`crate::sides_data`]), the
//! triangle that slot stands for and the direction in which that triangle walks the edge.
//!
//! Paper 001 (Alg. 3) sums an edge's multiplicity over its opposite vertices, each term being
//! the orientation of triangle `A → B → O` towards the light computed through the triangle's
//! reference edge; paper 003 (Alg. 1, 2) evaluates that sum for the sides and the same
//! orientation again for the caps, in two vertex programs. Without `precise` (GLSL ES 3.00,
//! WGSL) two programs may round the same expression differently (fused multiply-adds), and a
//! triangle whose sides and cap disagree opens its volume. With this table a renderer
//! computes every triangle's orientation ONCE per light (one value per triangle) and reads
//! that same value for the caps and, signed, for every edge:
//!
//! `contribution(A, B, O_i) = sign_i · orientation(T_i)`, where `T_i` is the triangle behind
//! slot `i` and `sign_i` is `+1` when `T_i`, in its own winding, walks the edge from `A` to
//! `B` (so `A → B → O_i` is a rotation of it) and `-1` when it walks it from `B` to `A`.
//! Both sides are [`crate::multiplicity::comp_multiplicity`] of the same sorted vertices
//! with the same parity, so the identity holds bit for bit, not only in exact arithmetic.
//!
//! Layout (the WebGL viewer's `edge_triangles`, `umbra export`): `maxMult` signed 32-bit
//! integers per edge record, record for record and slot for slot as the sides-data:
//! `sign_i · (T_i + 1)` for the record's opposites, `0` for unused slots.

use crate::adjacency::EdgeAdjacency;
use crate::weld::WeldedMesh;

/// Why the table could not be built.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum EdgeTrianglesError {
    /// `maxMult` of 0 (the sides-data needs at least one slot per record).
    #[error("edge triangles: maxMult must be at least 1")]
    MaxMult,
    /// More triangles than a signed 32-bit `T + 1` can name.
    #[error("edge triangles: {0} triangles; at most {max} can be named", max = i32::MAX - 1)]
    TooManyTriangles(usize),
    /// The adjacency lists an opposite vertex that no triangle of the mesh has with that
    /// edge: `adj` was not built from `mesh`.
    #[error("edge triangles: edge {edge} ({a}, {b}), opposite slot {slot} (vertex {opposite}): no such triangle in the mesh")]
    NoTriangle {
        /// The edge index.
        edge: usize,
        /// Its two vertices, as the adjacency stores them.
        a: u32,
        /// See `a`.
        b: u32,
        /// The slot among the edge's opposites.
        slot: usize,
        /// The opposite vertex.
        opposite: u32,
    },
}

/// The table for `adj` (built from `mesh`) split into records of `max_mult` slots exactly as
/// [`crate::sides_data::build_sides_data`] splits the sides-data. Deterministic.
pub fn build_edge_triangles(
    mesh: &WeldedMesh,
    adj: &EdgeAdjacency,
    max_mult: usize,
) -> Result<Vec<i32>, EdgeTrianglesError> {
    if max_mult == 0 {
        return Err(EdgeTrianglesError::MaxMult);
    }
    if mesh.triangles.len() >= i32::MAX as usize {
        return Err(EdgeTrianglesError::TooManyTriangles(mesh.triangles.len()));
    }
    // Every directed edge of every triangle, keyed by its undirected vertex pair and sorted by
    // (pair, triangle): for each pair, its triangles in triangle order, the order in which
    // EdgeAdjacency lists the opposite vertices.
    let mut walks: Vec<([u32; 2], u32, u32, u32)> = Vec::with_capacity(3 * mesh.triangles.len());
    for (t, tri) in mesh.triangles.iter().enumerate() {
        for k in 0..3 {
            let (from, to, opposite) = (tri[k], tri[(k + 1) % 3], tri[(k + 2) % 3]);
            walks.push(([from.min(to), from.max(to)], t as u32, from, opposite));
        }
    }
    walks.sort_unstable_by_key(|w| (w.0, w.1));
    let mut out = Vec::new();
    for (e, &[a, b]) in adj.edges.iter().enumerate() {
        let key = [a.min(b), a.max(b)];
        let start = walks.partition_point(|w| w.0 < key);
        let opposites = adj.opposites(e);
        let mut refs = Vec::with_capacity(opposites.len());
        for (slot, &o) in opposites.iter().enumerate() {
            let missing = EdgeTrianglesError::NoTriangle { edge: e, a, b, slot, opposite: o };
            let &(pair, t, from, opposite) = walks.get(start + slot).ok_or(missing.clone())?;
            if pair != key || opposite != o {
                return Err(missing);
            }
            let sign = if from == a { 1 } else { -1 };
            refs.push(sign * (t as i32 + 1));
        }
        // Records as build_sides_data makes them: consecutive chunks of max_mult opposites,
        // one empty record for an edge without any.
        if refs.is_empty() {
            out.resize(out.len() + max_mult, 0);
        }
        for chunk in refs.chunks(max_mult) {
            out.extend_from_slice(chunk);
            out.resize(out.len() + max_mult - chunk.len(), 0);
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::Mesh;
    use crate::multiplicity::{opposite_contribution, triangle_orientation};
    use crate::sides_data::build_sides_data;
    use crate::weld::tests::{reference_inputs, reference_lights};
    use crate::weld::weld;

    /// Every slot of every record: the sides-data's opposite vertex is the named triangle's
    /// third vertex, and `sign · orientation(T)` equals the multiplicity term bit for bit.
    fn check(mesh: &WeldedMesh, max_mult: usize, lights: &[[f32; 4]]) {
        let adj = EdgeAdjacency::build(mesh);
        let sides = build_sides_data(mesh, &adj, max_mult).expect("sides-data");
        let refs = build_edge_triangles(mesh, &adj, max_mult).expect("edge triangles");
        assert_eq!(refs.len(), sides.records() * max_mult);
        for r in 0..sides.records() {
            let rec = sides.record(r);
            let (a, b, count) = (rec[0], rec[1], rec[0][3] as usize);
            for i in 0..max_mult {
                let v = refs[r * max_mult + i];
                if i >= count {
                    assert_eq!(v, 0, "record {r} slot {i} unused");
                    continue;
                }
                assert_ne!(v, 0);
                let tri = mesh.triangles[(v.unsigned_abs() - 1) as usize];
                let p = |k: usize| mesh.positions[tri[k] as usize];
                let o = [rec[2 + i][0], rec[2 + i][1], rec[2 + i][2]];
                assert!((0..3).any(|k| p(k) == o), "record {r} slot {i}: the triangle has the opposite vertex");
                for &l in lights {
                    let term = opposite_contribution([a[0], a[1], a[2]], [b[0], b[1], b[2]], o, l);
                    assert_eq!(v.signum() * triangle_orientation(&mesh.positions, tri, l), term, "record {r} slot {i}");
                }
            }
        }
    }

    #[test]
    fn every_slot_names_its_triangle_and_reproduces_the_multiplicity_term() {
        for mesh in reference_inputs() {
            let w = weld(&mesh);
            let lights = reference_lights(&w);
            for max_mult in [1, 2, 3, 14] {
                check(&w, max_mult, &lights);
            }
        }
    }

    #[test]
    fn walking_direction_gives_the_sign() {
        // Two triangles sharing edge (0, 1), consistently wound: one walks 0 -> 1, the
        // other 1 -> 0; a third, duplicated with the first's winding, non-manifold.
        let mesh = Mesh {
            positions: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, 1.0]],
            triangles: vec![[0, 1, 2], [1, 0, 3], [0, 1, 4]],
            normals: None,
        };
        let w = weld(&mesh);
        let adj = EdgeAdjacency::build(&w);
        let refs = build_edge_triangles(&w, &adj, 4).expect("table");
        let e = adj.edges.iter().position(|&[a, b]| a.min(b) == 0 && a.max(b) == 1).expect("edge 0-1");
        let from_a = if adj.edges[e][0] == 0 { 1 } else { -1 };
        assert_eq!(&refs[4 * e..4 * e + 4], &[from_a, -2 * from_a, 3 * from_a, 0]);
        check(&w, 1, &reference_lights(&w));
    }

    #[test]
    fn an_adjacency_of_another_mesh_is_refused() {
        let a = weld(&Mesh {
            positions: vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            triangles: vec![[0, 1, 2]],
            normals: None,
        });
        // b: two triangles, so edge (0, 1) has an opposite (vertex 3) that a does not have.
        let b = weld(&Mesh {
            positions: vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            triangles: vec![[0, 1, 2], [1, 0, 3]],
            normals: None,
        });
        let e = build_edge_triangles(&a, &EdgeAdjacency::build(&b), 2).unwrap_err();
        assert!(matches!(e, EdgeTrianglesError::NoTriangle { .. }), "{e}");
        assert_eq!(build_edge_triangles(&a, &EdgeAdjacency::build(&a), 0), Err(EdgeTrianglesError::MaxMult));
    }
}
