//! The vectorised kernels of paper 001, Alg. 3-4: the contribution of every (edge, opposite
//! vertex) pair to the edge's multiplicity and every triangle's orientation towards the
//! light, [`BATCH`] at a time in structure-of-arrays form, in loops without data-dependent
//! control flow that the compiler vectorises. Each calls the very [`comp_multiplicity`] of
//! [`crate::multiplicity`] on the very arguments Alg. 3 gives it, so the results equal the
//! scalar forms bit for bit.

use crate::adjacency::EdgeAdjacency;
use crate::multiplicity::{comp_multiplicity, triangle_orientation};
use crate::order::greater;
use crate::Light;

/// `greater(a, b) > 0` of [`crate::order`] (Alg. 2), as one boolean expression: the first
/// component whose comparison is not "equal" (neither `<` nor `>`, which includes NaN)
/// decides. Five comparisons and no branch instead of six comparisons and the weighted sum.
#[inline(always)]
// `!(x < y)` is meant: it is true for "equal" *and* for NaN, exactly as Alg. 2's zero.
#[allow(clippy::neg_cmp_op_on_partial_ord)]
pub(super) fn above(a: [f32; 3], b: [f32; 3]) -> bool {
    (a[0] > b[0]) | (!(a[0] < b[0]) & ((a[1] > b[1]) | (!(a[1] < b[1]) & (a[2] > b[2]))))
}

/// [`edge_multiplicity`] for the per-frame loop, with the same result bit for bit: for each
/// opposite vertex the branch of Alg. 3 is *selected* (which sorted triple, which sign)
/// rather than branched on, and [`comp_multiplicity`] is called on exactly the arguments
/// [`crate::multiplicity::opposite_contribution`] gives it. The branches of Alg. 3 depend
/// on the geometry and mispredict about every other time; selects do not.
///
/// [`edge_multiplicity`]: crate::multiplicity::edge_multiplicity
#[inline(always)]
fn edge_multiplicity_select(positions: &[[f32; 3]], edge: [u32; 2], opposites: &[u32], light: Light) -> i32 {
    let a = positions[edge[0] as usize];
    let b = positions[edge[1] as usize];
    // The branches of Alg. 3 as a table, indexed by (O < A, O < B): which of [A, B, O] go
    // to `comp_multiplicity` in which order, and the parity of that permutation.
    const CASES: [([usize; 3], i32); 4] = [
        ([0, 1, 2], 1),  // A < B < O: (A, B, O), even
        ([0, 2, 1], -1), // A < O < B: (A, O, B), odd
        ([2, 0, 1], 1),  // O < A (< B): (O, A, B), even
        ([2, 0, 1], 1),
    ];
    let mut m = 0;
    for &o in opposites {
        let o = positions[o as usize];
        let p = [a, b, o, o]; // padded to 4: `& 3` below needs no bounds check
        let ([i, j, k], sign) = CASES[(above(a, o) as usize) << 1 | above(b, o) as usize];
        m += sign * comp_multiplicity(p[i & 3], p[j & 3], p[k & 3], light);
    }
    m
}

/// (edge, opposite vertex) pairs evaluated together by [`contributions`].
pub(super) const BATCH: usize = 256;

/// One batch of (A, B, O) triples in structure-of-arrays form: `[ax, ay, az, bx, by, bz, ox,
/// oy, oz]`, so that [`contributions`] runs over the lanes of SIMD registers.
type Triples = [[f32; BATCH]; 9];

/// `out[i]` = the contribution of opposite `O` to edge `A → B` for the `i`-th triple, as
/// [`edge_multiplicity_select`] computes it (same selected arguments to the same
/// [`comp_multiplicity`], hence the same result bit for bit), for `n` triples. Written as a
/// loop with no data-dependent control flow so the compiler vectorises it.
#[inline(never)]
fn contributions(t: &Triples, n: usize, light: Light, out: &mut [i32; BATCH]) {
    let [ax, ay, az, bx, by, bz, ox, oy, oz] = t;
    for i in 0..n.min(BATCH) {
        let (a, b, o) = ([ax[i], ay[i], az[i]], [bx[i], by[i], bz[i]], [ox[i], oy[i], oz[i]]);
        let o_below_a = above(a, o); // O < A < B: (O, A, B), even
        let o_below_b = above(b, o); // A < O < B: (A, O, B), odd; else (A, B, O), even
        let either = o_below_a | o_below_b;
        let first = [pick(o_below_a, o[0], a[0]), pick(o_below_a, o[1], a[1]), pick(o_below_a, o[2], a[2])];
        let second = [
            pick(o_below_a, a[0], pick(o_below_b, o[0], b[0])),
            pick(o_below_a, a[1], pick(o_below_b, o[1], b[1])),
            pick(o_below_a, a[2], pick(o_below_b, o[2], b[2])),
        ];
        let third = [pick(either, b[0], o[0]), pick(either, b[1], o[1]), pick(either, b[2], o[2])];
        let odd = !o_below_a & o_below_b;
        out[i] = comp_multiplicity(first, second, third, light) * (1 - 2 * odd as i32);
    }
}

#[inline(always)]
fn pick(c: bool, x: f32, y: f32) -> f32 {
    if c {
        x
    } else {
        y
    }
}

/// The multiplicities of edges `first..first + ms.len()` into `ms`: the edges' (A, B, O)
/// triples are gathered a batch at a time (the opposites of consecutive edges are
/// consecutive in the CSR layout), evaluated by [`contributions`] and summed per edge. An
/// edge with more than [`BATCH`] opposites is evaluated on its own.
pub(super) fn multiplicities_batched(
    positions: &[[f32; 3]],
    adj: &EdgeAdjacency,
    first: usize,
    ms: &mut [i32],
    light: Light,
) {
    let mut triples: Triples = [[0.0; BATCH]; 9];
    let mut contribution = [0i32; BATCH];
    let end = first + ms.len();
    let start = &adj.opposite_start;
    let mut e = first;
    while e < end {
        let base = start[e] as usize;
        let mut batch_end = e;
        while batch_end < end && start[batch_end + 1] as usize - base <= BATCH {
            batch_end += 1;
        }
        if batch_end == e {
            ms[e - first] = edge_multiplicity_select(positions, adj.edges[e], adj.opposites(e), light);
            e += 1;
            continue;
        }
        let mut slot = 0;
        for f in e..batch_end {
            let [ia, ib] = adj.edges[f];
            let (a, b) = (positions[ia as usize], positions[ib as usize]);
            for &o in adj.opposites(f) {
                let o = positions[o as usize];
                let slot_values = [a[0], a[1], a[2], b[0], b[1], b[2], o[0], o[1], o[2]];
                for k in 0..9 {
                    triples[k][slot] = slot_values[k];
                }
                slot += 1;
            }
        }
        contributions(&triples, slot, light, &mut contribution);
        for f in e..batch_end {
            let slots = start[f] as usize - base..start[f + 1] as usize - base;
            ms[f - first] = contribution[slots].iter().sum();
        }
        e = batch_end;
    }
}

/// `out[i]` = [`triangle_orientation`] of the `i`-th triangle, whose vertices are the `(A, B,
/// O)` of the `i`-th triple (`A → B → O` its winding), for `n` triangles: the vertices are
/// ranked by the three comparisons of Alg. 2 (no data-dependent swaps), [`comp_multiplicity`]
/// gets them in sorted order — exactly the arguments the sorting network of
/// [`triangle_orientation`] gives it — and the sign is the parity of the permutation.
/// Vectorised like [`contributions`]. Returns `false` when two vertices of a triangle tie
/// in the order (possible only with NaN coordinates): then `out` is not valid.
#[inline(never)]
fn orientations(t: &Triples, n: usize, light: Light, out: &mut [i32; BATCH]) -> bool {
    let [ax, ay, az, bx, by, bz, cx, cy, cz] = t;
    let mut tie = false;
    for i in 0..n.min(BATCH) {
        let (p0, p1, p2) = ([ax[i], ay[i], az[i]], [bx[i], by[i], bz[i]], [cx[i], cy[i], cz[i]]);
        let (g01, g12, g02) = (greater(p0, p1), greater(p1, p2), greater(p0, p2));
        tie |= (g01 == 0) | (g12 == 0) | (g02 == 0);
        let (g01, g12, g02) = (g01 > 0, g12 > 0, g02 > 0);
        let s0 = !g01 & !g02; // p0 is the smallest
        let s1 = g01 & !g12; // p1 is the smallest (else p2)
        let l0 = g01 & g02; // p0 is the largest
        let l1 = !g01 & g12; // p1 is the largest (else p2)
        let m0 = g01 ^ g02; // p0 is in the middle
        let m1 = !g01 ^ g12; // p1 is in the middle (else p2)
        let rank = |first: bool, second: bool, k: usize| pick(first, p0[k], pick(second, p1[k], p2[k]));
        let smallest = [rank(s0, s1, 0), rank(s0, s1, 1), rank(s0, s1, 2)];
        let middle = [rank(m0, m1, 0), rank(m0, m1, 1), rank(m0, m1, 2)];
        let largest = [rank(l0, l1, 0), rank(l0, l1, 1), rank(l0, l1, 2)];
        // Each inverted pair is one transposition of the permutation to sorted order.
        let odd = g01 ^ g12 ^ g02;
        out[i] = comp_multiplicity(smallest, middle, largest, light) * (1 - 2 * odd as i32);
    }
    !tie
}

/// [`triangle_orientation`] of every triangle of `tris`, a batch of up to [`BATCH`] at a time
/// through [`orientations`]: `f(batch, orientations)` for consecutive batches of `tris`.
#[inline(always)]
pub(super) fn orientation_batches(
    positions: &[[f32; 3]],
    tris: &[[u32; 3]],
    light: Light,
    mut f: impl FnMut(&[[u32; 3]], &[i32]),
) {
    let mut triples: Triples = [[0.0; BATCH]; 9];
    let mut orientation = [0i32; BATCH];
    for tris in tris.chunks(BATCH) {
        for (slot, tri) in tris.iter().enumerate() {
            let [p0, p1, p2] = tri.map(|v| positions[v as usize]);
            let slot_values = [p0[0], p0[1], p0[2], p1[0], p1[1], p1[2], p2[0], p2[1], p2[2]];
            for k in 0..9 {
                triples[k][slot] = slot_values[k];
            }
        }
        if !orientations(&triples, tris.len(), light, &mut orientation) {
            for (s, &tri) in orientation.iter_mut().zip(tris) {
                *s = triangle_orientation(positions, tri, light);
            }
        }
        f(tris, &orientation[..tris.len()]);
    }
}

/// [`triangle_orientation`] of every triangle of `tris` into `ss`; returns how many are not
/// edge-on.
pub(super) fn orientations_batched(positions: &[[f32; 3]], tris: &[[u32; 3]], ss: &mut [i8], light: Light) -> usize {
    let mut not_edge_on = 0;
    let mut at = 0;
    orientation_batches(positions, tris, light, |_, orientation| {
        for (s, &o) in ss[at..at + orientation.len()].iter_mut().zip(orientation) {
            *s = o as i8;
        }
        not_edge_on += orientation.iter().filter(|&&s| s != 0).count();
        at += orientation.len();
    });
    not_edge_on
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::multiplicity::edge_multiplicity;

    /// The select forms equal Alg. 3-4 as written in `multiplicity`, on every ordering of
    /// vertices from a small grid (ties between coordinates, equal vertices, NaN) and on
    /// point and directional lights, including lights in the triangles' planes.
    #[test]
    fn select_forms_match_multiplicity_module() {
        let grid = [-1.0f32, -0.0, 0.0, 0.5, 1.0];
        let mut points = Vec::new();
        for x in grid {
            for y in [0.0f32, 1.0] {
                for z in grid {
                    points.push([x, y, z]);
                }
            }
        }
        points.push([f32::NAN, 0.0, 0.0]);
        points.push([0.0, f32::NAN, 1.0]);
        let lights = [[0.5, 0.5, 0.5, 1.0], [0.0, 1.0, 0.0, 1.0], [0.0, 1.0, 0.0, 0.0], [1.0, 0.0, 0.5, 0.0]];
        let n = points.len() as u32;
        let (mut nonzero, mut negative) = (0, 0);
        // Triangles of three distinct vertices (the batches without ties) and, separately,
        // all triples (batches with ties, NaN: the fallback).
        let triples: Vec<[u32; 3]> = (0..n * n * n).map(|t| [t / (n * n), t / n % n, t % n]).collect();
        let strict =
            |t: &[u32; 3]| (0..3).all(|k| greater(points[t[k] as usize], points[t[(k + 1) % 3] as usize]) != 0);
        let distinct: Vec<[u32; 3]> = triples.iter().copied().filter(strict).collect();
        assert!(distinct.len() > 10 * BATCH);
        for light in lights {
            for tris in [&distinct, &triples] {
                let mut got = vec![0i8; tris.len()];
                let count = orientations_batched(&points, tris, &mut got, light);
                let want: Vec<i8> = tris.iter().map(|&t| triangle_orientation(&points, t, light) as i8).collect();
                assert_eq!(got, want, "{light:?}");
                assert_eq!(count, want.iter().filter(|&&s| s != 0).count());
            }
            for i in 0..n {
                for j in 0..n {
                    for k in 0..n {
                        let tri = [i, j, k];
                        let want = triangle_orientation(&points, tri, light);
                        nonzero += (want != 0) as usize;
                        let opposites = [k, j, i, k];
                        let want = edge_multiplicity(&points, [i, j], &opposites, light);
                        assert_eq!(edge_multiplicity_select(&points, [i, j], &opposites, light), want);
                        negative += (want < 0) as usize;
                    }
                }
            }
        }
        assert!(nonzero > 1000 && negative > 1000, "{nonzero} {negative}");
    }

    /// The branch-free order predicate equals Alg. 2 on every pair from the grid, with NaN.
    #[test]
    fn above_matches_greater() {
        let values = [-1.0f32, -0.0, 0.0, 2.0, f32::NAN, f32::INFINITY];
        let mut points = Vec::new();
        for x in values {
            for y in values {
                for z in values {
                    points.push([x, y, z]);
                }
            }
        }
        let mut both = [0; 2];
        for &a in &points {
            for &b in &points {
                let want = greater(a, b) > 0;
                assert_eq!(above(a, b), want, "{a:?} {b:?}");
                both[want as usize] += 1;
            }
        }
        assert!(both[0] > 0 && both[1] > 0);
    }
}
