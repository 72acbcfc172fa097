//! CPU shadow volumes from deterministic multiplicities: silhouette sides and caps.
//!
//! Paper 001, Section 2.2: an edge with multiplicity `m` casts `|m|` side quads, extruded to
//! infinity with Eq. 2 (`C = (A·l_w - L.xyz, 0)`, `D = (B·l_w - L.xyz, 0)`; the paper writes
//! it for `l_w = 1`); Section 2.3: caps oriented by the same reference-edge test, so sides and
//! caps never disagree. Kim, Kim & Turk 2008 for the multiplicity itself.
//!
//! Orientation convention (what makes the stencil counts right): every triangle's own volume
//! is oriented so that the triangle, as a light cap, faces the light, and all faces are
//! counter-clockwise seen from *outside* the volume. For a triangle `A → B → C` facing the
//! light the volume is bounded by the light cap `A B C`, the dark cap `A∞ C∞ B∞` and, for
//! each edge `A → B`, the side `B A A∞ B∞` (the side must traverse the shared edge opposite
//! to the cap). Edge `A → B` with multiplicity `m > 0` thus emits `m` copies of the quad
//! `B A A∞ B∞`; `m < 0` emits `|m|` copies of `A B B∞ A∞`. The union of all triangles'
//! volumes then has winding number = the number of triangles between a point and the light,
//! never negative; the interior sides of adjacent lit triangles cancel, which is exactly
//! what `m = 0` means.
//!
//! Directional lights (`l_w = 0`): every vertex extrudes to the same point at infinity
//! `-L.xyz`, so dark caps have zero area and are not emitted.
//!
//! Per frame, in parallel and (once warmed up) without allocating: the multiplicities are
//! evaluated 256 (edge, opposite vertex) pairs at a time in a loop the compiler vectorises,
//! calling the very [`comp_multiplicity`] of [`crate::multiplicity`] on the very arguments
//! Alg. 3 gives it (so the result is the same bit for bit); per-chunk sums of `|m|` and their
//! prefix sums place every chunk's quads, which it then writes straight into `out`. Caps the
//! same way. Figures in `docs/benchmarks.md`.

use rayon::prelude::*;

use crate::adjacency::EdgeAdjacency;
use crate::multiplicity::{comp_multiplicity, edge_multiplicity, triangle_orientation};
use crate::order::greater;
use crate::weld::WeldedMesh;
use crate::Light;

/// Shadow-volume triangles in world space, homogeneous; every 3 vertices form a triangle,
/// counter-clockwise seen from outside the volume.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct VolumeGeometry {
    /// Silhouette sides: two vertices at `w = 1` on the edge, two at infinity (`w = 0`).
    pub sides: Vec<[f32; 4]>,
    /// Light caps: the light-facing-oriented triangles themselves (`w = 1`). The renderer
    /// pushes them to the far plane (paper 003, Eq. 6).
    pub light_caps: Vec<[f32; 4]>,
    /// Dark caps at infinity (`w = 0`), point lights only.
    pub dark_caps: Vec<[f32; 4]>,
}

impl VolumeGeometry {
    pub fn clear(&mut self) {
        self.sides.clear();
        self.light_caps.clear();
        self.dark_caps.clear();
    }
}

/// `P` extruded away from the light to infinity: `(P·l_w - L.xyz, 0)` (001 Eq. 2).
#[inline(always)]
pub fn extrude(p: [f32; 3], light: Light) -> [f32; 4] {
    [p[0] * light[3] - light[0], p[1] * light[3] - light[1], p[2] * light[3] - light[2], 0.0]
}

#[inline(always)]
fn point(p: [f32; 3]) -> [f32; 4] {
    [p[0], p[1], p[2], 1.0]
}

/// Edges (or triangles) per parallel work item: large enough to amortise the scheduling,
/// small enough to balance two to many cores.
const ITEMS_PER_CHUNK: usize = 4096;

/// The per-frame scratch of [`extract`], kept per calling thread so a warmed-up frame does
/// not allocate.
#[derive(Default)]
struct Scratch {
    /// Multiplicity of every edge.
    multiplicity: Vec<i32>,
    /// Orientation of every triangle towards the light (caps only).
    orientation: Vec<i8>,
    /// Output vertices before each chunk (exclusive prefix sums; one more entry than chunks).
    side_offsets: Vec<usize>,
    cap_offsets: Vec<usize>,
}

thread_local! {
    static SCRATCH: std::cell::RefCell<Scratch> = std::cell::RefCell::new(Scratch::default());
}

/// `greater(a, b) > 0` of [`crate::order`] (Alg. 2), as one boolean expression: the first
/// component whose comparison is not "equal" (neither `<` nor `>`, which includes NaN)
/// decides. Five comparisons and no branch instead of six comparisons and the weighted sum.
#[inline(always)]
// `!(x < y)` is meant: it is true for "equal" *and* for NaN, exactly as Alg. 2's zero.
#[allow(clippy::neg_cmp_op_on_partial_ord)]
fn above(a: [f32; 3], b: [f32; 3]) -> bool {
    (a[0] > b[0]) | (!(a[0] < b[0]) & ((a[1] > b[1]) | (!(a[1] < b[1]) & (a[2] > b[2]))))
}

/// [`edge_multiplicity`] for the per-frame loop, with the same result bit for bit: for each
/// opposite vertex the branch of Alg. 3 is *selected* (which sorted triple, which sign)
/// rather than branched on, and [`comp_multiplicity`] is called on exactly the arguments
/// [`crate::multiplicity::opposite_contribution`] gives it. The branches of Alg. 3 depend
/// on the geometry and mispredict about every other time; selects do not.
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
const BATCH: usize = 256;

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
fn multiplicities_batched(positions: &[[f32; 3]], adj: &EdgeAdjacency, first: usize, ms: &mut [i32], light: Light) {
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

/// [`triangle_orientation`] of every triangle of `tris` into `ss`, a batch at a time through
/// [`orientations`]; returns how many are not edge-on.
fn orientations_batched(positions: &[[f32; 3]], tris: &[[u32; 3]], ss: &mut [i8], light: Light) -> usize {
    let mut triples: Triples = [[0.0; BATCH]; 9];
    let mut orientation = [0i32; BATCH];
    let mut not_edge_on = 0;
    for (tris, ss) in tris.chunks(BATCH).zip(ss.chunks_mut(BATCH)) {
        for (slot, tri) in tris.iter().enumerate() {
            let [p0, p1, p2] = tri.map(|v| positions[v as usize]);
            let slot_values = [p0[0], p0[1], p0[2], p1[0], p1[1], p1[2], p2[0], p2[1], p2[2]];
            for k in 0..9 {
                triples[k][slot] = slot_values[k];
            }
        }
        if orientations(&triples, tris.len(), light, &mut orientation) {
            for (s, &o) in ss.iter_mut().zip(&orientation) {
                *s = o as i8;
            }
        } else {
            for (s, &tri) in ss.iter_mut().zip(tris) {
                *s = triangle_orientation(positions, tri, light) as i8;
            }
        }
        not_edge_on += ss.iter().filter(|&&s| s != 0).count();
    }
    not_edge_on
}

/// Writes the side quads of edge `[a, b]` (`a < b`) with multiplicity `m != 0` at the start
/// of `out` (which holds at least `6 |m|` vertices); returns the number of vertices written.
#[inline(always)]
fn write_sides(out: &mut [[f32; 4]], a: [f32; 3], b: [f32; 3], m: i32, light: Light) -> usize {
    let (a_inf, b_inf) = (extrude(a, light), extrude(b, light));
    let (a, b) = (point(a), point(b));
    // m > 0: quad B A A∞ B∞; m < 0: the reverse, A B B∞ A∞.
    let quad = if m > 0 { [b, a, a_inf, b, a_inf, b_inf] } else { [a, b, b_inf, a, b_inf, a_inf] };
    let n = 6 * m.unsigned_abs() as usize;
    for copy in out[..n].chunks_exact_mut(6) {
        copy.copy_from_slice(&quad);
    }
    n
}

/// Sets `v`'s length to `len`, reusing its capacity; the contents are overwritten by the
/// caller (only the part beyond the previous length is zero-filled first).
fn set_len<T: Copy>(v: &mut Vec<T>, len: usize, zero: T) {
    v.truncate(len);
    v.resize(len, zero);
}

/// Turns `counts[1..]` (per-chunk counts, `counts[0]` ignored) in place into exclusive
/// prefix sums scaled by `scale`: `counts[c]` = output vertices before chunk `c`.
fn prefix_sums(counts: &mut [usize], scale: usize) {
    counts[0] = 0;
    let mut total = 0;
    for c in counts.iter_mut() {
        total += *c * scale;
        *c = total;
    }
}

/// Output buffers that can be cut where a chunk's output starts.
trait SplitOutput: Send + Sized {
    fn split(self, at: usize) -> (Self, Self);
}

impl<T: Send> SplitOutput for &mut [T] {
    fn split(self, at: usize) -> (Self, Self) {
        self.split_at_mut(at)
    }
}

/// Light caps and dark caps of one chunk.
type CapsOut<'a> = (&'a mut [[f32; 4]], &'a mut [[f32; 4]]);

/// Light caps and dark caps, which have the same length or (directional light) no dark caps.
impl<T: Send> SplitOutput for (&mut [T], &mut [T]) {
    fn split(self, at: usize) -> (Self, Self) {
        let (l0, l1) = self.0.split_at_mut(at);
        if self.1.is_empty() {
            ((l0, &mut []), (l1, &mut []))
        } else {
            let (d0, d1) = self.1.split_at_mut(at);
            ((l0, d0), (l1, d1))
        }
    }
}

/// Runs `write(chunk, piece)` for every chunk in `chunks`, in parallel, where `piece` is the
/// part of `out` from `offsets[chunk]` to `offsets[chunk + 1]` (relative to
/// `offsets[chunks.start]`, where `out` starts). Splits recursively with `rayon::join`: no
/// allocation.
fn write_chunks<O: SplitOutput>(
    chunks: std::ops::Range<usize>,
    offsets: &[usize],
    out: O,
    write: &(impl Fn(usize, O) + Sync),
) {
    match chunks.len() {
        0 => {}
        1 => write(chunks.start, out),
        n => {
            let mid = chunks.start + n / 2;
            let (left, right) = out.split(offsets[mid] - offsets[chunks.start]);
            rayon::join(
                || write_chunks(chunks.start..mid, offsets, left, write),
                || write_chunks(mid..chunks.end, offsets, right, write),
            );
        }
    }
}

/// Computes every edge's multiplicity (in parallel) and emits the volume into `out`
/// (its previous contents replaced, its capacity reused). `caps` adds the light and dark
/// caps z-fail needs.
///
/// Output order is deterministic (edge order, then triangle order). Two parallel passes per
/// output: multiplicities (or cap orientations) with a count per chunk, then, after prefix
/// sums over the chunks, every chunk writes its vertices straight into its own part of
/// `out`. Once warmed up (same thread, output not larger than before) a frame allocates
/// nothing.
pub fn extract(mesh: &WeldedMesh, adj: &EdgeAdjacency, light: Light, caps: bool, out: &mut VolumeGeometry) {
    SCRATCH.with(|cell| match cell.try_borrow_mut() {
        Ok(mut scratch) => extract_with(mesh, adj, light, caps, out, &mut scratch),
        // Re-entered on this thread (a rayon worker ran another extract while waiting): use
        // a fresh scratch rather than share.
        Err(_) => extract_with(mesh, adj, light, caps, out, &mut Scratch::default()),
    })
}

fn extract_with(
    mesh: &WeldedMesh,
    adj: &EdgeAdjacency,
    light: Light,
    caps: bool,
    out: &mut VolumeGeometry,
    scratch: &mut Scratch,
) {
    let positions = &mesh.positions;
    let Scratch { multiplicity, orientation, side_offsets, cap_offsets } = scratch;

    // Pass 1: multiplicities, and |m| summed per chunk into `side_offsets[chunk + 1]`.
    let edges = adj.len();
    let edge_chunks = edges.div_ceil(ITEMS_PER_CHUNK);
    set_len(multiplicity, edges, 0);
    set_len(side_offsets, edge_chunks + 1, 0);
    multiplicity.par_chunks_mut(ITEMS_PER_CHUNK).zip(side_offsets[1..].par_iter_mut()).enumerate().for_each(
        |(chunk, (ms, sum))| {
            multiplicities_batched(positions, adj, chunk * ITEMS_PER_CHUNK, ms, light);
            *sum = ms.iter().map(|m| m.unsigned_abs() as usize).sum();
        },
    );
    prefix_sums(side_offsets, 6);

    // Pass 2: every chunk writes its quads into its own part of `out.sides`.
    set_len(&mut out.sides, side_offsets[edge_chunks], [0.0; 4]);
    let ms: &[i32] = multiplicity;
    write_chunks(0..edge_chunks, side_offsets, &mut out.sides[..], &|chunk, piece: &mut [[f32; 4]]| {
        let first = chunk * ITEMS_PER_CHUNK;
        let last = (first + ITEMS_PER_CHUNK).min(edges);
        let mut at = 0;
        // Most edges are not silhouettes: skip runs of zeros a block at a time (a vectorised
        // test), and read an edge's vertices only when it casts sides.
        const RUN: usize = 16;
        for (block, run) in ms[first..last].chunks(RUN).enumerate() {
            if run.iter().all(|&m| m == 0) {
                continue;
            }
            for (i, &m) in run.iter().enumerate() {
                if m != 0 {
                    let [a, b] = adj.edges[first + block * RUN + i];
                    at += write_sides(&mut piece[at..], positions[a as usize], positions[b as usize], m, light);
                }
            }
        }
    });

    if !caps {
        out.light_caps.clear();
        out.dark_caps.clear();
        return;
    }
    // Caps, the same way: orientations with a count per chunk, then the writes.
    let directional = light[3] == 0.0;
    let triangles = mesh.triangles.len();
    let tri_chunks = triangles.div_ceil(ITEMS_PER_CHUNK);
    set_len(orientation, triangles, 0);
    set_len(cap_offsets, tri_chunks + 1, 0);
    orientation
        .par_chunks_mut(ITEMS_PER_CHUNK)
        .zip(mesh.triangles.par_chunks(ITEMS_PER_CHUNK))
        .zip(cap_offsets[1..].par_iter_mut())
        .for_each(|((ss, tris), count)| {
            *count = orientations_batched(positions, tris, ss, light);
        });
    prefix_sums(cap_offsets, 3);
    let cap_vertices = cap_offsets[tri_chunks];
    set_len(&mut out.light_caps, cap_vertices, [0.0; 4]);
    set_len(&mut out.dark_caps, if directional { 0 } else { cap_vertices }, [0.0; 4]);
    let ss: &[i8] = orientation;
    let caps_out = (&mut out.light_caps[..], &mut out.dark_caps[..]);
    write_chunks(0..tri_chunks, cap_offsets, caps_out, &|chunk, (light_caps, dark_caps): CapsOut<'_>| {
        let first = chunk * ITEMS_PER_CHUNK;
        let last = (first + ITEMS_PER_CHUNK).min(triangles);
        let lit =
            mesh.triangles[first..last].iter().zip(&ss[first..last]).filter(|(_, &s)| s != 0).map(|(&tri, &s)| {
                // Wind the cap so that it faces the light.
                let [i0, i1, i2] = if s > 0 { tri } else { [tri[0], tri[2], tri[1]] };
                [i0, i1, i2].map(|i| positions[i as usize])
            });
        if directional {
            for (cap, [p0, p1, p2]) in light_caps.chunks_exact_mut(3).zip(lit) {
                cap.copy_from_slice(&[point(p0), point(p1), point(p2)]);
            }
        } else {
            for ((cap, dark), [p0, p1, p2]) in
                light_caps.chunks_exact_mut(3).zip(dark_caps.chunks_exact_mut(3)).zip(lit)
            {
                cap.copy_from_slice(&[point(p0), point(p1), point(p2)]);
                dark.copy_from_slice(&[extrude(p0, light), extrude(p2, light), extrude(p1, light)]);
            }
        }
    });
}

/// Per-edge multiplicities in edge order (for statistics and tests).
pub fn multiplicities(mesh: &WeldedMesh, adj: &EdgeAdjacency, light: Light) -> Vec<i32> {
    (0..adj.len())
        .into_par_iter()
        .map(|e| edge_multiplicity(&mesh.positions, adj.edges[e], adj.opposites(e), light))
        .collect()
}

/// Silhouette statistics for `umbra info`: edges with `m != 0` and the sum of `|m|`.
pub fn silhouette_stats(mesh: &WeldedMesh, adj: &EdgeAdjacency, light: Light) -> (usize, u64) {
    let m = multiplicities(mesh, adj, light);
    (m.iter().filter(|&&x| x != 0).count(), m.iter().map(|&x| x.unsigned_abs() as u64).sum())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::weld::tests::{reference_inputs, reference_lights};
    use crate::weld::weld;

    /// The straightforward serial emission (one edge after another, one triangle after
    /// another) that [`extract`] must reproduce exactly.
    fn reference_extract(mesh: &WeldedMesh, adj: &EdgeAdjacency, light: Light, caps: bool) -> VolumeGeometry {
        let mut out = VolumeGeometry::default();
        let p = &mesh.positions;
        for e in 0..adj.len() {
            let [a, b] = adj.edges[e];
            let m = edge_multiplicity(p, [a, b], adj.opposites(e), light);
            let (a, b) = (p[a as usize], p[b as usize]);
            let (a_inf, b_inf) = (extrude(a, light), extrude(b, light));
            let (a, b) = (point(a), point(b));
            let quad = if m > 0 { [b, a, a_inf, b, a_inf, b_inf] } else { [a, b, b_inf, a, b_inf, a_inf] };
            for _ in 0..m.unsigned_abs() {
                out.sides.extend_from_slice(&quad);
            }
        }
        if caps {
            for &tri in &mesh.triangles {
                let s = triangle_orientation(p, tri, light);
                if s == 0 {
                    continue;
                }
                let [i0, i1, i2] = if s > 0 { tri } else { [tri[0], tri[2], tri[1]] };
                let [p0, p1, p2] = [i0, i1, i2].map(|i| p[i as usize]);
                out.light_caps.extend_from_slice(&[point(p0), point(p1), point(p2)]);
                if light[3] != 0.0 {
                    out.dark_caps.extend_from_slice(&[extrude(p0, light), extrude(p2, light), extrude(p1, light)]);
                }
            }
        }
        out
    }

    /// Bit patterns, so that `-0.0 != 0.0` and NaN == NaN.
    fn bits(v: &VolumeGeometry) -> [Vec<[u32; 4]>; 3] {
        [&v.sides, &v.light_caps, &v.dark_caps].map(|l| l.iter().map(|x| x.map(f32::to_bits)).collect())
    }

    /// Many chunks, multiplicities up to ±n on non-manifold edges, edge-on triangles, both
    /// light kinds, caps on and off; one `out` reused across all of it, growing and
    /// shrinking: the parallel two-pass emission equals the serial one bit for bit.
    #[test]
    fn extract_matches_serial_reference_with_reused_output() {
        let mut out = VolumeGeometry::default();
        let mut nonempty = 0;
        for mesh in reference_inputs() {
            let w = weld(&mesh);
            let adj = EdgeAdjacency::build(&w);
            for light in reference_lights(&w) {
                for caps in [true, false] {
                    extract(&w, &adj, light, caps, &mut out);
                    let expected = reference_extract(&w, &adj, light, caps);
                    assert!(bits(&out) == bits(&expected), "light {light:?} caps {caps}");
                    nonempty += !out.sides.is_empty() as usize;
                }
            }
        }
        assert!(nonempty >= 8, "the inputs must cast silhouettes ({nonempty})");
    }

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

    /// A warmed-up frame of the same size reuses every buffer: the output's and the
    /// per-thread scratch's (no reallocation, hence no allocation of ours).
    #[test]
    fn extract_reuses_buffers_when_warm() {
        let w = weld(&reference_inputs()[1]);
        let adj = EdgeAdjacency::build(&w);
        let light = reference_lights(&w)[0];
        let mut out = VolumeGeometry::default();
        extract(&w, &adj, light, true, &mut out);
        assert!(!out.sides.is_empty() && !out.light_caps.is_empty() && !out.dark_caps.is_empty());
        let buffers = |out: &VolumeGeometry| {
            let s = SCRATCH.with(|cell| {
                let s = cell.borrow();
                [
                    s.multiplicity.as_ptr() as usize,
                    s.orientation.as_ptr() as usize,
                    s.side_offsets.as_ptr() as usize,
                    s.cap_offsets.as_ptr() as usize,
                ]
            });
            [
                out.sides.as_ptr() as usize,
                out.light_caps.as_ptr() as usize,
                out.dark_caps.as_ptr() as usize,
                s[0],
                s[1],
                s[2],
                s[3],
            ]
        };
        let warm = buffers(&out);
        for caps in [true, false, true] {
            extract(&w, &adj, light, caps, &mut out);
            assert_eq!(buffers(&out), warm, "caps {caps}");
        }
    }

    /// An extraction running inside another one on the same thread (a rayon worker picks up
    /// a second frame's job while it waits) gets its own scratch instead of a borrow panic.
    #[test]
    fn extract_reentrant_on_one_thread() {
        let mesh = &reference_inputs()[0];
        let w = weld(mesh);
        let adj = EdgeAdjacency::build(&w);
        let light = reference_lights(&w)[0];
        let expected = reference_extract(&w, &adj, light, true);
        SCRATCH.with(|cell| {
            let _held = cell.borrow_mut();
            let mut out = VolumeGeometry::default();
            extract(&w, &adj, light, true, &mut out);
            assert!(bits(&out) == bits(&expected));
        });
    }
}
