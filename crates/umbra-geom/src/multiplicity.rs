//! Deterministic edge multiplicity with a reference edge.
//!
//! Paper 001 (Milet, Kobrtek, Zemčík), Section 2.2, Algorithms 3 and 4, building on
//! Kim, Kim & Turk 2008 (multiplicity for non-manifold casters) and Pečiva et al. 2013
//! (deterministic multiplicity).
//!
//! The multiplicity of edge `A → B` (with `A < B` in the order of [`crate::order`]) is the
//! sum, over every triangle `(A, B, Oᵢ)` that contains the edge, of that triangle's
//! orientation towards the light as seen when it is wound `A → B → Oᵢ`. `|m|` is how many
//! times the edge's infinite side quad is drawn, `sgn(m)` its winding.
//!
//! Determinism: a triangle's orientation is always computed by [`comp_multiplicity`] on its
//! vertices *sorted* by the vertex order, so the reference edge (smallest → largest vertex,
//! `X = C - A` in Alg. 4) and every floating-point operation are the same whichever of the
//! triangle's three edges asks, and whether a cap or a side asks. The sign for the winding
//! actually wanted is the parity of the permutation from sorted order. Hence a triangle is
//! never counted as lit through one edge and as unlit through another: the volume closes.
//!
//! All arithmetic is f32, in the order written in Alg. 4; Rust never contracts `a * b + c`
//! into a fused multiply-add, so the result is bit-for-bit reproducible.

use crate::order::greater;
use crate::Light;

/// Alg. 4 of paper 001, `CompMultiplicity(A, B, C, L)` for `A < B < C`:
/// `sgn(((C - A) × (L.xyz - A·L.w)) · (B - A))`.
///
/// Equal to `sgn(n · (L.xyz - A·L.w))` with `n = (B - A) × (C - A)`: `+1` when the
/// triangle `A → B → C` (counter-clockwise, normal `n`) faces the light.
#[inline(always)]
pub fn comp_multiplicity(a: [f32; 3], b: [f32; 3], c: [f32; 3], light: Light) -> i32 {
    let x = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
    let y = [light[0] - a[0] * light[3], light[1] - a[1] * light[3], light[2] - a[2] * light[3]];
    let n = [x[1] * y[2] - x[2] * y[1], x[2] * y[0] - x[0] * y[2], x[0] * y[1] - x[1] * y[0]];
    let d = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let dot = n[0] * d[0] + n[1] * d[1] + n[2] * d[2];
    (dot > 0.0) as i32 - (dot < 0.0) as i32
}

/// Alg. 3 of paper 001: the multiplicity of edge `A → B` (`A < B`) over its opposite vertices.
///
/// `edge` holds vertex indices into `positions` with `positions[edge[0]] < positions[edge[1]]`
/// (as [`crate::EdgeAdjacency`] stores them).
#[inline]
pub fn edge_multiplicity(positions: &[[f32; 3]], edge: [u32; 2], opposites: &[u32], light: Light) -> i32 {
    let a = positions[edge[0] as usize];
    let b = positions[edge[1] as usize];
    let mut m = 0;
    for &o in opposites {
        m += opposite_contribution(a, b, positions[o as usize], light);
    }
    m
}

/// One opposite vertex `O` of edge `A → B` (`A < B`): the orientation of triangle
/// `A → B → O`, through the triangle's reference edge (the branches of Alg. 3).
#[inline(always)]
pub fn opposite_contribution(a: [f32; 3], b: [f32; 3], o: [f32; 3], light: Light) -> i32 {
    if greater(a, o) > 0 {
        // O < A < B: sorted (O, A, B); A → B → O is a rotation of it (even).
        comp_multiplicity(o, a, b, light)
    } else if greater(b, o) > 0 {
        // A < O < B: sorted (A, O, B); A → B → O swaps the last two (odd).
        -comp_multiplicity(a, o, b, light)
    } else {
        // A < B < O: already sorted.
        comp_multiplicity(a, b, o, light)
    }
}

/// Orientation of the triangle `p[t0] → p[t1] → p[t2]` towards the light: `+1` it faces the
/// light, `-1` it faces away, `0` edge-on (or degenerate). Computed through the triangle's
/// reference edge, so it agrees bit for bit with every [`opposite_contribution`] of the
/// triangle. Used to orient caps.
#[inline]
pub fn triangle_orientation(positions: &[[f32; 3]], tri: [u32; 3], light: Light) -> i32 {
    let [p0, p1, p2] = tri.map(|i| positions[i as usize]);
    // Sort the three vertices with a sorting network, tracking the permutation's parity.
    let (mut a, mut b, mut c) = (p0, p1, p2);
    let mut parity = 1;
    if greater(a, b) > 0 {
        std::mem::swap(&mut a, &mut b);
        parity = -parity;
    }
    if greater(b, c) > 0 {
        std::mem::swap(&mut b, &mut c);
        parity = -parity;
    }
    if greater(a, b) > 0 {
        std::mem::swap(&mut a, &mut b);
        parity = -parity;
    }
    parity * comp_multiplicity(a, b, c, light)
}

/// The older determinism of Pečiva et al. 2013, the one paper 001 compares against: the
/// triangle's orientation is computed through each of its three edges (each edge's own
/// plane with the light) and the triangle is discarded (0) when the three disagree.
#[inline]
pub fn triangle_orientation_3edge(positions: &[[f32; 3]], tri: [u32; 3], light: Light) -> i32 {
    let [p0, p1, p2] = tri.map(|i| positions[i as usize]);
    let s0 = edge_plane_side(p0, p1, p2, light);
    let s1 = edge_plane_side(p1, p2, p0, light);
    let s2 = edge_plane_side(p2, p0, p1, light);
    if s0 == s1 && s1 == s2 {
        s0
    } else {
        0
    }
}

/// Side of `o` with respect to the plane through edge `a → b` and the light (Kim 2008),
/// evaluated with the edge as the base: `sgn(((b - a) × (L - a·w)) · (o - a))`, negated so
/// that it equals the orientation of `a → b → o` towards the light.
#[inline(always)]
fn edge_plane_side(a: [f32; 3], b: [f32; 3], o: [f32; 3], light: Light) -> i32 {
    // comp_multiplicity(a, o, b) = sgn(((b - a) × L') · (o - a)) = orientation of a → o → b.
    -comp_multiplicity(a, o, b, light)
}

#[cfg(test)]
mod tests {
    use super::*;

    const UP_LIGHT: Light = [0.0, 10.0, 0.0, 1.0];

    #[test]
    fn triangle_facing_light_is_positive() {
        // CCW seen from +Y: normal +Y, light above.
        let p = [[0.0, 0.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]];
        assert_eq!(triangle_orientation(&p, [0, 1, 2], UP_LIGHT), 1);
        assert_eq!(triangle_orientation(&p, [0, 2, 1], UP_LIGHT), -1);
        assert_eq!(triangle_orientation(&p, [1, 2, 0], UP_LIGHT), 1);
        assert_eq!(triangle_orientation_3edge(&p, [0, 1, 2], UP_LIGHT), 1);
        // Directional light from above.
        assert_eq!(triangle_orientation(&p, [0, 1, 2], [0.0, 1.0, 0.0, 0.0]), 1);
        assert_eq!(triangle_orientation(&p, [0, 1, 2], [0.0, -1.0, 0.0, 0.0]), -1);
    }

    #[test]
    fn triangle_edge_on_is_zero() {
        let p = [[0.0, 0.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]];
        assert_eq!(triangle_orientation(&p, [0, 1, 2], [5.0, 0.0, 3.0, 1.0]), 0);
        assert_eq!(triangle_orientation(&p, [0, 1, 2], [1.0, 0.0, 0.0, 0.0]), 0);
    }

    #[test]
    fn manifold_silhouette_edge_has_multiplicity_two() {
        // Two triangles folded over the edge (0,0,0)-(0,0,1): one faces the light, the
        // other (consistently wound) faces away: Kim's multiplicity is ±2.
        let p = [[0.0, 0.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, -1.0, 0.5]];
        // Triangles (0,1,2) facing +Y, (1,0,3) consistent winding.
        let light = [0.5, 10.0, 0.5, 1.0];
        assert_eq!(triangle_orientation(&p, [0, 1, 2], light), 1);
        let m = edge_multiplicity(&p, [0, 1], &[2, 3], light);
        // (1,0,3) is a wall in the plane x = 0, normal -X: faces away from a light at x = 0.5.
        assert_eq!(triangle_orientation(&p, [1, 0, 3], light), -1);
        assert_eq!(m.abs(), 2);
        // Flat continuation (both face the light): not a silhouette.
        let q = [[0.0, 0.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [-1.0, 0.0, 0.5]];
        assert_eq!(edge_multiplicity(&q, [0, 1], &[2, 3], light), 0);
    }
}
