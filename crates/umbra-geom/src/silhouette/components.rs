//! The connected pieces of a caster: triangles joined across every edge they share, whatever
//! their orientation. The unit in which the GPU silhouette methods cull their volumes.
//!
//! CC shadow volumes (Lloyd, Wendt, Govindaraju, Manocha, EGSR 2004, Section 4.1) cull whole
//! casters whose shadow holds no receiver. Dropping a whole piece is exact for the same
//! reason as dropping one triangle (docs/exactness.md, "Volumes clamped to their receivers":
//! a sample's count is a sum over triangles, and a dropped triangle's frustum holds no visible
//! sample), and it creates no side: every edge of a piece has all its triangles in that piece,
//! so no edge loses some of its triangles and keeps others. Unlike [`super::keep_whole_regions`]
//! (regions of one orientation towards one light) the pieces do not depend on the light, so
//! they are found once per mesh and a GPU pass needs only a lookup per triangle.

use super::slots::TriangleSlots;
use crate::adjacency::EdgeAdjacency;

fn find(parent: &mut [u32], mut x: u32) -> u32 {
    while parent[x as usize] != x {
        let p = parent[x as usize];
        // Path halving.
        parent[x as usize] = parent[p as usize];
        x = p;
    }
    x
}

/// Per triangle of a mesh with `triangles` triangles, the number of its piece (dense, in the
/// order of each piece's first triangle), and the number of pieces. `adj` and `slots` must
/// be the mesh's ([`TriangleSlots::build`]).
pub fn caster_pieces(triangles: usize, adj: &EdgeAdjacency, slots: &TriangleSlots) -> (Vec<u32>, u32) {
    let mut parent: Vec<u32> = (0..triangles as u32).collect();
    for e in 0..adj.len() {
        let range = adj.opposite_start[e] as usize..adj.opposite_start[e + 1] as usize;
        let mut edge = slots.slots[range].iter().map(|&s| s >> 1);
        let Some(first) = edge.next() else { continue };
        for t in edge {
            let (a, b) = (find(&mut parent, first), find(&mut parent, t));
            if a != b {
                parent[a.max(b) as usize] = a.min(b);
            }
        }
    }
    // Roots are the smallest triangle of their piece: numbering roots in triangle order
    // numbers the pieces by their first triangle.
    let mut piece = vec![u32::MAX; triangles];
    let mut count = 0;
    for t in 0..triangles as u32 {
        let r = find(&mut parent, t);
        if r == t {
            piece[t as usize] = count;
            count += 1;
        } else {
            piece[t as usize] = piece[r as usize];
        }
    }
    (piece, count)
}

/// Per edge of `adj`, the piece of its triangles (all in one piece; [`caster_pieces`]'s
/// `piece`); 0 for an edge without triangles, which casts nothing.
pub fn edge_pieces(adj: &EdgeAdjacency, slots: &TriangleSlots, piece: &[u32]) -> Vec<u32> {
    (0..adj.len())
        .map(|e| {
            let first = adj.opposite_start[e] as usize;
            if first < adj.opposite_start[e + 1] as usize {
                piece[(slots.slots[first] >> 1) as usize]
            } else {
                0
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::Mesh;
    use crate::scene::cuboid;
    use crate::weld::weld;

    fn pieces_of(mesh: &Mesh) -> (Vec<u32>, u32) {
        let w = weld(mesh);
        let adj = EdgeAdjacency::build(&w);
        let slots = TriangleSlots::build(&w, &adj).expect("slots");
        caster_pieces(w.triangles.len(), &adj, &slots)
    }

    #[test]
    fn two_boxes_are_two_pieces() {
        let mut m = cuboid([0.0, 0.0, 0.0], [1.0, 1.0, 1.0]);
        m.append(&cuboid([5.0, 0.0, 0.0], [1.0, 1.0, 1.0]));
        let (piece, count) = pieces_of(&m);
        assert_eq!(count, 2);
        assert!(piece[..12].iter().all(|&p| p == 0) && piece[12..].iter().all(|&p| p == 1), "{piece:?}");
        // Every edge's piece is that of each of its triangles.
        let w = weld(&m);
        let adj = EdgeAdjacency::build(&w);
        let slots = TriangleSlots::build(&w, &adj).expect("slots");
        let edges = edge_pieces(&adj, &slots, &piece);
        for (e, &[a, b]) in adj.edges.iter().enumerate() {
            for (t, tri) in w.triangles.iter().enumerate() {
                if tri.contains(&a) && tri.contains(&b) {
                    assert_eq!(edges[e], piece[t], "edge {e}, triangle {t}");
                }
            }
        }
    }

    #[test]
    fn triangles_touching_at_a_vertex_only_are_separate_pieces() {
        let m = Mesh {
            positions: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]],
            triangles: vec![[0, 1, 2], [0, 3, 4]],
            normals: None,
        };
        assert_eq!(pieces_of(&m).1, 2);
    }

    #[test]
    fn a_non_manifold_fan_is_one_piece() {
        // Three triangles on one edge 0-1.
        let m = Mesh {
            positions: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]],
            triangles: vec![[0, 1, 2], [1, 0, 3], [0, 1, 4]],
            normals: None,
        };
        assert_eq!(pieces_of(&m), (vec![0, 0, 0], 1));
    }

    #[test]
    fn a_zero_area_triangle_joins_its_neighbours() {
        let m = Mesh {
            positions: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            triangles: vec![[0, 1, 2], [0, 2, 3]],
            normals: None,
        };
        assert_eq!(pieces_of(&m), (vec![0, 0], 1));
    }
}
