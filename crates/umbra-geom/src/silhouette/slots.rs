//! [`TriangleSlots`]: the triangle behind every (edge, opposite vertex) slot of an
//! [`EdgeAdjacency`], so that a frame sums per-triangle orientations per edge instead of
//! evaluating paper 001's Alg. 3 per slot.

use crate::adjacency::EdgeAdjacency;
use crate::weld::WeldedMesh;

/// Static per-mesh data of [`extract_indexed`]: the triangle behind every (edge, opposite
/// vertex) slot of an [`EdgeAdjacency`], and whether that triangle runs along the edge as
/// stored (`A → B`) or against it. Built once per mesh, like the adjacency.
///
/// The contribution of opposite `O` to edge `A → B` (001 Alg. 3) is the orientation of the
/// triangle `A → B → O`, computed through the triangle's reference edge: bit for bit the
/// [`triangle_orientation`] of that triangle, negated when the triangle runs `B → A` (this
/// is what makes sides and caps agree; property (a) of `tests/volume_props.rs`). So a frame
/// can orient every triangle once and sum those orientations per edge, instead of evaluating
/// Alg. 4 three times per triangle for the sides and a fourth time for the caps.
///
/// [`extract_indexed`]: super::extract_indexed
/// [`triangle_orientation`]: crate::multiplicity::triangle_orientation
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TriangleSlots {
    /// Parallel to [`EdgeAdjacency::opposites`]: `t << 1 | against` for triangle `t`.
    pub(super) slots: Vec<u32>,
}

/// Why [`TriangleSlots::build`] failed: the adjacency is not that of the mesh.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum TriangleSlotsError {
    /// More than 2^31 triangles (the slot encoding has 31 bits for the triangle).
    #[error("triangle slots: {0} triangles, more than 2^31")]
    TooManyTriangles(usize),
    /// A triangle refers to a vertex the mesh does not have.
    #[error("triangle slots: triangle {triangle} refers to vertex {vertex}, but the mesh has {vertices} vertices")]
    Vertex {
        /// The triangle index.
        triangle: usize,
        /// The vertex index.
        vertex: u32,
        /// Vertices the mesh has.
        vertices: usize,
    },
    /// An edge of a triangle is not in the adjacency.
    #[error("triangle slots: edge {edge:?} of triangle {triangle} is not in the adjacency (or has fewer opposites)")]
    MissingEdge {
        /// The triangle index.
        triangle: usize,
        /// The edge as a vertex pair.
        edge: [u32; 2],
    },
    /// The adjacency does not belong to the mesh.
    #[error("triangle slots: the adjacency's opposites of edge {edge} are not those of the mesh's triangles, in triangle order")]
    Mismatch {
        /// The edge index in the adjacency.
        edge: usize,
    },
}

impl TriangleSlots {
    /// Maps every slot of `adj` (built from `mesh` by [`EdgeAdjacency::build`], whose
    /// opposites are in triangle order) to its triangle. Serial, `O(triangles)` with a
    /// per-vertex index of the edges.
    pub fn build(mesh: &WeldedMesh, adj: &EdgeAdjacency) -> Result<Self, TriangleSlotsError> {
        let triangles = mesh.triangles.len();
        if triangles > (u32::MAX >> 1) as usize {
            return Err(TriangleSlotsError::TooManyTriangles(triangles));
        }
        let vertices = mesh.positions.len();
        // Edges by their smaller vertex index (CSR): `edge_ids[row_start[v]..row_start[v + 1]]`.
        let mut row_start = vec![0u32; vertices + 1];
        for (edge, &[a, b]) in adj.edges.iter().enumerate() {
            let low = a.min(b) as usize;
            if a.max(b) as usize >= vertices {
                return Err(TriangleSlotsError::Mismatch { edge });
            }
            row_start[low + 1] += 1;
        }
        for v in 0..vertices {
            row_start[v + 1] += row_start[v];
        }
        let mut fill = row_start.clone();
        let mut edge_ids = vec![0u32; adj.len()];
        for (e, &[a, b]) in adj.edges.iter().enumerate() {
            let low = a.min(b) as usize;
            edge_ids[fill[low] as usize] = e as u32;
            fill[low] += 1;
        }
        // Each triangle takes the next free slot of each of its edges: the adjacency lists
        // an edge's opposites in triangle order.
        let mut cursor: Vec<u32> = adj.opposite_start[..adj.len()].to_vec();
        let mut slots = vec![0u32; adj.opposites.len()];
        for (t, &tri) in mesh.triangles.iter().enumerate() {
            if let Some(&vertex) = tri.iter().find(|&&v| v as usize >= vertices) {
                return Err(TriangleSlotsError::Vertex { triangle: t, vertex, vertices });
            }
            for k in 0..3 {
                let (u, v, w) = (tri[k], tri[(k + 1) % 3], tri[(k + 2) % 3]);
                let (low, high) = (u.min(v) as usize, u.max(v));
                let row = &edge_ids[row_start[low] as usize..row_start[low + 1] as usize];
                let missing = TriangleSlotsError::MissingEdge { triangle: t, edge: [u, v] };
                let e = *row.iter().find(|&&e| adj.edges[e as usize].contains(&high)).ok_or(missing.clone())? as usize;
                let slot = cursor[e] as usize;
                if slot >= adj.opposite_start[e + 1] as usize {
                    return Err(missing);
                }
                if adj.opposites[slot] != w {
                    return Err(TriangleSlotsError::Mismatch { edge: e });
                }
                cursor[e] += 1;
                slots[slot] = (t as u32) << 1 | (adj.edges[e][0] != u) as u32;
            }
        }
        if let Some(e) = (0..adj.len()).find(|&e| cursor[e] != adj.opposite_start[e + 1]) {
            return Err(TriangleSlotsError::Mismatch { edge: e });
        }
        Ok(Self { slots })
    }

    /// The slots, parallel to [`EdgeAdjacency::opposites`]: `t << 1 | against` for the
    /// triangle `t` behind each, `against` = 1 when it runs `B → A` along the edge `A → B`
    /// (for GPU methods that sum orientations per edge, e.g. umbra-wgpu's).
    pub fn slots(&self) -> &[u32] {
        &self.slots
    }

    /// Whether these slots fit `adj` (same number of slots).
    pub fn fits(&self, adj: &EdgeAdjacency) -> bool {
        self.slots.len() == adj.opposites.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::weld::tests::reference_inputs;
    use crate::weld::weld;

    /// Every slot names a triangle that has the slot's edge and opposite vertex, running along
    /// or against the edge as recorded; every triangle fills exactly three slots.
    #[test]
    fn triangle_slots_name_the_triangle_of_each_opposite() {
        for mesh in reference_inputs() {
            let w = weld(&mesh);
            let adj = EdgeAdjacency::build(&w);
            let slots = TriangleSlots::build(&w, &adj).expect("the adjacency of the mesh");
            assert!(slots.fits(&adj));
            let mut uses = vec![0; w.triangles.len()];
            for e in 0..adj.len() {
                let [a, b] = adj.edges[e];
                for slot in adj.opposite_start[e] as usize..adj.opposite_start[e + 1] as usize {
                    let (t, against) = ((slots.slots[slot] >> 1) as usize, slots.slots[slot] & 1 == 1);
                    let tri = w.triangles[t];
                    let k = (0..3).find(|&k| tri[(k + 2) % 3] == adj.opposites[slot]).expect("opposite in triangle");
                    let (u, v) = (tri[k], tri[(k + 1) % 3]);
                    assert_eq!([u, v], if against { [b, a] } else { [a, b] }, "slot {slot}");
                    uses[t] += 1;
                }
            }
            assert!(uses.iter().all(|&n| n == 3));
        }
    }

    /// Slots built for another adjacency are refused with a typed error, not a panic.
    #[test]
    fn triangle_slots_of_a_foreign_adjacency_are_an_error() {
        let inputs = reference_inputs();
        let (w0, w1) = (weld(&inputs[0]), weld(&inputs[1]));
        let adj1 = EdgeAdjacency::build(&w1);
        assert!(TriangleSlots::build(&w0, &adj1).is_err());
        let mut fewer = w0.clone();
        fewer.triangles.pop();
        assert!(TriangleSlots::build(&fewer, &EdgeAdjacency::build(&w0)).is_err());
        let mut wrong = w0.clone();
        wrong.triangles[0] = [0, 1, u32::MAX];
        assert!(matches!(
            TriangleSlots::build(&wrong, &EdgeAdjacency::build(&w0)),
            Err(TriangleSlotsError::Vertex { triangle: 0, vertex: u32::MAX, .. })
        ));
    }
}
