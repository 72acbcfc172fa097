//! [`keep_whole_regions`]: the receiver cull widened to whole regions of one orientation, so
//! that it never cuts a surface the light sees as one piece.
//!
//! Dropping a triangle is exact whenever no visible sample lies in its shadow frustum
//! ([`crate::receivers`]), and so is keeping any triangle. But dropping one of two
//! neighbours that face the light the same way turns their shared edge, of multiplicity 0,
//! into a silhouette edge: a new side "curtain" from the edge to the far ends of the kept
//! neighbour, often larger on screen than all the fill the drop saved (a sphere over a floor
//! whose light-facing cap is half dropped hangs a curtain from its middle down to the floor).
//! So the kept set is widened to whole regions: triangles joined across every edge whose
//! contributions cancel (001 Alg. 3: opposite nonzero signs, the edge's multiplicity 0
//! between them), a union-find in triangle order; a region is kept whole when any of its
//! triangles is needed, dropped whole otherwise. Its boundary edges are silhouette or open
//! edges already, so no drop creates a side where the unculled volume had none between two
//! triangles of one region.

use rayon::prelude::*;

use super::slots::TriangleSlots;
use crate::adjacency::EdgeAdjacency;
use crate::multiplicity::triangle_orientation;
use crate::weld::WeldedMesh;
use crate::Light;

fn find(parent: &mut [u32], mut x: u32) -> u32 {
    while parent[x as usize] != x {
        let p = parent[x as usize];
        // Path halving.
        parent[x as usize] = parent[p as usize];
        x = p;
    }
    x
}

/// Widens `keep` (one flag per triangle of `mesh`) to whole regions of one orientation
/// towards `light` (module documentation). Returns the number of triangles it added.
/// `slots` must be [`TriangleSlots::build`] of this mesh and adjacency.
pub fn keep_whole_regions(
    mesh: &WeldedMesh,
    adj: &EdgeAdjacency,
    slots: &TriangleSlots,
    light: Light,
    keep: &mut [bool],
) -> usize {
    let n = mesh.triangles.len();
    assert_eq!(keep.len(), n, "one keep flag per triangle");
    let orientation: Vec<i8> =
        mesh.triangles.par_iter().map(|&t| triangle_orientation(&mesh.positions, t, light) as i8).collect();
    let mut parent: Vec<u32> = (0..n as u32).collect();
    for e in 0..adj.len() {
        let range = adj.opposite_start[e] as usize..adj.opposite_start[e + 1] as usize;
        let contribution = |slot: u32| {
            let t = slot >> 1;
            (t, orientation[t as usize] as i32 * (1 - 2 * (slot & 1) as i32))
        };
        let edge_slots = &slots.slots[range];
        // The first triangle of each sign, then every triangle joined with the first of the
        // other sign: all opposite pairs end up in one region.
        let first = |positive: bool| {
            edge_slots.iter().map(|&s| contribution(s)).find(|&(_, c)| if positive { c > 0 } else { c < 0 })
        };
        let (Some((plus, _)), Some((minus, _))) = (first(true), first(false)) else { continue };
        for &slot in edge_slots {
            let (t, c) = contribution(slot);
            let o = if c > 0 {
                minus
            } else if c < 0 {
                plus
            } else {
                continue;
            };
            let (a, b) = (find(&mut parent, t), find(&mut parent, o));
            if a != b {
                parent[a.max(b) as usize] = a.min(b);
            }
        }
    }
    let mut needed_root = vec![false; n];
    for t in 0..n as u32 {
        if keep[t as usize] {
            let r = find(&mut parent, t);
            needed_root[r as usize] = true;
        }
    }
    let mut added = 0;
    for t in 0..n as u32 {
        if !keep[t as usize] && orientation[t as usize] != 0 && needed_root[find(&mut parent, t) as usize] {
            keep[t as usize] = true;
            added += 1;
        }
    }
    added
}
