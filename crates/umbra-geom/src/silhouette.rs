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
//! Two outputs of the same volume:
//! * [`extract`] (the reference): per frame, the multiplicities are evaluated 256 (edge,
//!   opposite vertex) pairs at a time in a loop the compiler vectorises, calling the very
//!   [`comp_multiplicity`] of [`crate::multiplicity`] on the very arguments Alg. 3 gives it
//!   (so the result is the same bit for bit); per-chunk sums of `|m|` and their prefix sums
//!   place every chunk's quads, which it then writes straight into `out`. Caps the same way,
//!   as vertex copies ([`VolumeGeometry`], 96 bytes per cap for a point light).
//! * [`extract_indexed`] (what the renderer draws): every triangle's orientation once (the
//!   same vectorised kernel as [`extract`]'s caps), each edge's multiplicity as the sum of
//!   its triangles' ± orientations through the per-mesh [`TriangleSlots`] (bit for bit the
//!   contributions of Alg. 3), the same side quads, and the caps as one oriented index triple
//!   per triangle into the welded positions ([`IndexedVolume`], 12 bytes), drawn from the
//!   mesh's static position buffer (light caps as they are, dark caps extruded in the vertex
//!   shader). [`IndexedVolume::expand_into`] turns the indices into the very vertices drawn.
//!
//! Both in parallel and, once warmed up, without allocating. Figures in
//! `docs/benchmarks.md`.

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
    /// Empties every list, keeping the allocations.
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
    /// Side vertices, resp. caps, before each chunk (exclusive prefix sums; one more entry
    /// than chunks).
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

/// [`triangle_orientation`] of every triangle of `tris`, a batch of up to [`BATCH`] at a time
/// through [`orientations`]: `f(batch, orientations)` for consecutive batches of `tris`.
#[inline(always)]
fn orientation_batches(
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
fn orientations_batched(positions: &[[f32; 3]], tris: &[[u32; 3]], ss: &mut [i8], light: Light) -> usize {
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

/// Light caps and dark caps of one chunk, three vertices per cap.
type CapsOut<'a> = (&'a mut [[[f32; 4]; 3]], &'a mut [[[f32; 4]; 3]]);

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

/// Whether a volume for `light` has dark caps: point lights only. A directional light
/// (`l_w = 0`) extrudes every vertex to the same point `-L.xyz`, so its dark caps would have
/// zero area.
#[inline]
pub fn has_dark_caps(light: Light) -> bool {
    light[3] != 0.0
}

/// The cap of a triangle with orientation `s != 0` ([`triangle_orientation`]): its vertices
/// wound so that it faces the light (the light cap's winding).
#[inline(always)]
fn oriented(tri: [u32; 3], s: i8) -> [u32; 3] {
    if s > 0 {
        tri
    } else {
        [tri[0], tri[2], tri[1]]
    }
}

/// The light cap and the dark cap of the oriented cap `[i0, i1, i2]` (see [`oriented`]): the
/// triangle `P0 P1 P2` at `w = 1` and, reversed so that it faces out of the volume, `P0∞ P2∞
/// P1∞` (001 Eq. 2). The one definition of both caps' geometry: [`extract`] writes it,
/// [`IndexedVolume::expand_into`] expands indexed caps with it, and the cpu-silhouette vertex
/// shader draws the same (light caps from the indices, dark caps from the same indices
/// extruded and drawn with the front face flipped).
#[inline(always)]
fn cap_vertices(positions: &[[f32; 3]], cap: [u32; 3], light: Light) -> ([[f32; 4]; 3], [[f32; 4]; 3]) {
    let [p0, p1, p2] = cap.map(|i| positions[i as usize]);
    ([point(p0), point(p1), point(p2)], [extrude(p0, light), extrude(p2, light), extrude(p1, light)])
}

/// Pass 1 and 2 of the sides, shared by [`extract`] and [`extract_indexed`]: every edge's
/// multiplicity (into `multiplicity`, with `|m|` summed per chunk into `side_offsets`), then
/// every chunk writes its quads into its own part of `sides`.
fn emit_sides(
    positions: &[[f32; 3]],
    adj: &EdgeAdjacency,
    light: Light,
    multiplicity: &mut Vec<i32>,
    side_offsets: &mut Vec<usize>,
    sides: &mut Vec<[f32; 4]>,
    multiplicities: &(impl Fn(usize, &mut [i32]) + Sync),
) {
    // Pass 1: multiplicities (`multiplicities(first_edge, ms)`), and |m| summed per chunk
    // into `side_offsets[chunk + 1]`.
    let edges = adj.len();
    let edge_chunks = edges.div_ceil(ITEMS_PER_CHUNK);
    set_len(multiplicity, edges, 0);
    set_len(side_offsets, edge_chunks + 1, 0);
    multiplicity.par_chunks_mut(ITEMS_PER_CHUNK).zip(side_offsets[1..].par_iter_mut()).enumerate().for_each(
        |(chunk, (ms, sum))| {
            multiplicities(chunk * ITEMS_PER_CHUNK, ms);
            *sum = ms.iter().map(|m| m.unsigned_abs() as usize).sum();
        },
    );
    prefix_sums(side_offsets, 6);

    // Pass 2: every chunk writes its quads into its own part of `sides`.
    set_len(sides, side_offsets[edge_chunks], [0.0; 4]);
    let ms: &[i32] = multiplicity;
    write_chunks(0..edge_chunks, side_offsets, &mut sides[..], &|chunk, piece: &mut [[f32; 4]]| {
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
}

/// Every triangle's [`triangle_orientation`] into `orientation` (in parallel, vectorised),
/// and the number of caps (triangles not edge-on) before each chunk into `cap_offsets`
/// (exclusive prefix sums, one more entry than chunks). Shared by [`extract`] and
/// [`extract_indexed`]; returns the number of chunks.
fn cap_orientations(mesh: &WeldedMesh, light: Light, orientation: &mut Vec<i8>, cap_offsets: &mut Vec<usize>) -> usize {
    let triangles = mesh.triangles.len();
    let tri_chunks = triangles.div_ceil(ITEMS_PER_CHUNK);
    set_len(orientation, triangles, 0);
    set_len(cap_offsets, tri_chunks + 1, 0);
    orientation
        .par_chunks_mut(ITEMS_PER_CHUNK)
        .zip(mesh.triangles.par_chunks(ITEMS_PER_CHUNK))
        .zip(cap_offsets[1..].par_iter_mut())
        .for_each(|((ss, tris), count)| {
            *count = orientations_batched(&mesh.positions, tris, ss, light);
        });
    prefix_sums(cap_offsets, 1);
    tri_chunks
}

/// The oriented caps of `tris` (those whose orientation in `ss` is not 0, in order), passed
/// to `emit` one at a time.
#[inline(always)]
fn for_each_cap(tris: &[[u32; 3]], ss: &[i8], mut emit: impl FnMut([u32; 3])) {
    for (&tri, &s) in tris.iter().zip(ss) {
        if s != 0 {
            emit(oriented(tri, s));
        }
    }
}

/// The per-frame scratch, borrowed from this thread's [`SCRATCH`] (a fresh one when it is
/// already borrowed: a rayon worker ran another extraction while waiting).
fn with_scratch<R>(f: impl FnOnce(&mut Scratch) -> R) -> R {
    SCRATCH.with(|cell| match cell.try_borrow_mut() {
        Ok(mut scratch) => f(&mut scratch),
        Err(_) => f(&mut Scratch::default()),
    })
}

/// Computes every edge's multiplicity (in parallel) and emits the volume into `out`
/// (its previous contents replaced, its capacity reused). `caps` adds the light and dark
/// caps z-fail needs, as vertex copies (96 bytes per cap and frame for a point light; the
/// renderer uses [`extract_indexed`], which writes 12).
///
/// Output order is deterministic (edge order, then triangle order). Two parallel passes per
/// output: multiplicities (or cap orientations) with a count per chunk, then, after prefix
/// sums over the chunks, every chunk writes its vertices straight into its own part of
/// `out`. Once warmed up (same thread, output not larger than before) a frame allocates
/// nothing.
pub fn extract(mesh: &WeldedMesh, adj: &EdgeAdjacency, light: Light, caps: bool, out: &mut VolumeGeometry) {
    with_scratch(|scratch| {
        let positions = &mesh.positions;
        let Scratch { multiplicity, orientation, side_offsets, cap_offsets } = scratch;
        let from_positions = |first: usize, ms: &mut [i32]| multiplicities_batched(positions, adj, first, ms, light);
        emit_sides(positions, adj, light, multiplicity, side_offsets, &mut out.sides, &from_positions);
        if !caps {
            out.light_caps.clear();
            out.dark_caps.clear();
            return;
        }
        let tri_chunks = cap_orientations(mesh, light, orientation, cap_offsets);
        let cap_count = cap_offsets[tri_chunks];
        set_len(&mut out.light_caps, 3 * cap_count, [0.0; 4]);
        set_len(&mut out.dark_caps, if has_dark_caps(light) { 3 * cap_count } else { 0 }, [0.0; 4]);
        let (ss, triangles): (&[i8], _) = (orientation, &mesh.triangles);
        let caps_out: CapsOut<'_> = (out.light_caps.as_chunks_mut().0, out.dark_caps.as_chunks_mut().0);
        write_chunks(0..tri_chunks, cap_offsets, caps_out, &|chunk, (light_caps, dark_caps): CapsOut<'_>| {
            let range = chunk * ITEMS_PER_CHUNK..((chunk + 1) * ITEMS_PER_CHUNK).min(triangles.len());
            let mut at = 0;
            for_each_cap(&triangles[range.clone()], &ss[range], |cap| {
                let (lit, dark) = cap_vertices(positions, cap, light);
                light_caps[at] = lit;
                if let Some(d) = dark_caps.get_mut(at) {
                    *d = dark;
                }
                at += 1;
            });
        });
    })
}

/// The shadow volume of [`extract`] with the caps as indices into the welded positions
/// instead of vertex copies: 12 bytes per triangle and frame instead of 96. The renderer
/// draws the caps from the mesh's static position buffer; [`IndexedVolume::expand_into`]
/// gives the vertices it draws, so tests can check the very volume drawn.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct IndexedVolume {
    /// Silhouette sides, exactly as [`VolumeGeometry::sides`].
    pub sides: Vec<[f32; 4]>,
    /// One cap per triangle of the mesh, in mesh order (empty without caps): the triangle
    /// wound so that it faces the light, by its [`triangle_orientation`] (through the
    /// reference edge, as the sides), or, when it is edge-on (orientation 0, no cap), the
    /// degenerate cap `[i0, i0, i0]`, which has zero area and draws nothing. Light cap: the
    /// triangle at `w = 1`, pushed to the far plane by the renderer. Dark cap (only if
    /// [`has_dark_caps`]): the same three vertices extruded to infinity with 001 Eq. 2 and
    /// the opposite winding. Keeping edge-on triangles as degenerate caps gives every
    /// triangle a fixed slot, so each chunk of triangles writes its caps in the same pass
    /// that orients them, without counting first.
    pub caps: Vec<[u32; 3]>,
}

/// Whether an [`IndexedVolume`] cap is the degenerate stand-in of an edge-on triangle.
#[inline]
pub fn is_degenerate_cap(cap: [u32; 3]) -> bool {
    cap[0] == cap[1] && cap[1] == cap[2]
}

impl IndexedVolume {
    /// Empties sides and caps, keeping the allocations.
    pub fn clear(&mut self) {
        self.sides.clear();
        self.caps.clear();
    }

    /// The vertices the renderer draws for this volume, into `out` (its contents replaced):
    /// the sides as they are, then per cap the light cap and, for point lights, the dark cap,
    /// degenerate caps included (as zero-area triangles). Without the degenerate caps this
    /// is, bit for bit, what [`extract`] writes for the same mesh and light. `positions`
    /// must be those of the mesh the volume was extracted from; an index out of their range
    /// is a programming error and panics.
    pub fn expand_into(&self, positions: &[[f32; 3]], light: Light, out: &mut VolumeGeometry) {
        out.clear();
        out.sides.extend_from_slice(&self.sides);
        for &cap in &self.caps {
            let (lit, dark) = cap_vertices(positions, cap, light);
            out.light_caps.extend_from_slice(&lit);
            if has_dark_caps(light) {
                out.dark_caps.extend_from_slice(&dark);
            }
        }
    }

    /// [`IndexedVolume::expand_into`] into a new [`VolumeGeometry`].
    pub fn expand(&self, positions: &[[f32; 3]], light: Light) -> VolumeGeometry {
        let mut out = VolumeGeometry::default();
        self.expand_into(positions, light, &mut out);
        out
    }
}

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
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TriangleSlots {
    /// Parallel to [`EdgeAdjacency::opposites`]: `t << 1 | against` for triangle `t`.
    slots: Vec<u32>,
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

/// The volume of [`extract`] with indexed caps ([`IndexedVolume`]), from one orientation per
/// triangle: pass 1 orients every triangle (the vectorised kernel of [`extract`]'s caps)
/// into the scratch and, with `caps`, writes its cap in the same go; pass 2 sums the
/// orientations per edge through `slots` ([`TriangleSlots`]) into the multiplicities; pass 3
/// writes the side quads exactly as [`extract`] does. The same multiplicities, sides and
/// caps as [`extract`] (bit for bit, checked by the unit tests) whenever the vertex order is
/// strict, i.e. without NaN coordinates; with NaN the sides follow the caps' orientations,
/// so the volume stays closed. Deterministic, parallel, and allocation-free once warmed up
/// (rayon's global queue allocates a block per 63 calls from outside its pool).
///
/// `slots` must be [`TriangleSlots::build`] of this mesh and adjacency; slots of another
/// mesh give a wrong volume or panic on an index out of range.
pub fn extract_indexed(
    mesh: &WeldedMesh,
    adj: &EdgeAdjacency,
    slots: &TriangleSlots,
    light: Light,
    caps: bool,
    out: &mut IndexedVolume,
) {
    // One job for the whole frame: the passes below fork and join on the pool's workers
    // instead of each queueing from outside.
    rayon::scope(|_| {
        with_scratch(|scratch| extract_indexed_with(mesh, adj, slots, light, caps, out, scratch));
    });
}

fn extract_indexed_with(
    mesh: &WeldedMesh,
    adj: &EdgeAdjacency,
    slots: &TriangleSlots,
    light: Light,
    caps: bool,
    out: &mut IndexedVolume,
    scratch: &mut Scratch,
) {
    let Scratch { multiplicity, orientation, side_offsets, .. } = scratch;
    let triangles = &mesh.triangles;
    // Pass 1: orientations, and the caps.
    set_len(orientation, triangles.len(), 0);
    if caps {
        set_len(&mut out.caps, triangles.len(), [0; 3]);
    } else {
        out.caps.clear();
    }
    let orient = |ss: &mut [i8], tris: &[[u32; 3]], mut caps_out: Option<&mut [[u32; 3]]>| {
        let mut at = 0;
        orientation_batches(&mesh.positions, tris, light, |tris, orientations| {
            for (s, &o) in ss[at..at + tris.len()].iter_mut().zip(orientations) {
                *s = o as i8;
            }
            if let Some(out) = caps_out.as_deref_mut() {
                for ((cap, &tri), &s) in out[at..at + tris.len()].iter_mut().zip(tris).zip(orientations) {
                    *cap = if s != 0 { oriented(tri, s as i8) } else { [tri[0]; 3] };
                }
            }
            at += tris.len();
        });
    };
    let chunks = orientation.par_chunks_mut(ITEMS_PER_CHUNK).zip(triangles.par_chunks(ITEMS_PER_CHUNK));
    if caps {
        chunks.zip(out.caps.par_chunks_mut(ITEMS_PER_CHUNK)).for_each(|((ss, tris), c)| orient(ss, tris, Some(c)));
    } else {
        chunks.for_each(|(ss, tris)| orient(ss, tris, None));
    }

    // Pass 2 and 3: multiplicities as sums of ± orientations, then the sides.
    let (ss, slots, start): (&[i8], &[u32], &[u32]) = (orientation, &slots.slots, &adj.opposite_start);
    let from_orientations = |first: usize, ms: &mut [i32]| {
        for (e, m) in (first..first + ms.len()).zip(ms.iter_mut()) {
            *m = slots[start[e] as usize..start[e + 1] as usize]
                .iter()
                .map(|&slot| ss[(slot >> 1) as usize] as i32 * (1 - 2 * (slot & 1) as i32))
                .sum();
        }
    };
    emit_sides(&mesh.positions, adj, light, multiplicity, side_offsets, &mut out.sides, &from_orientations);
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
        let mut indexed = IndexedVolume::default();
        let (mut nonempty, mut with_caps, mut degenerate) = (0, 0, 0);
        for mesh in reference_inputs() {
            let w = weld(&mesh);
            let adj = EdgeAdjacency::build(&w);
            let slots = TriangleSlots::build(&w, &adj).expect("the adjacency of the mesh");
            for light in reference_lights(&w) {
                for caps in [true, false] {
                    extract(&w, &adj, light, caps, &mut out);
                    let expected = reference_extract(&w, &adj, light, caps);
                    assert!(bits(&out) == bits(&expected), "light {light:?} caps {caps}");
                    nonempty += !out.sides.is_empty() as usize;
                    // The indexed caps stand for the very same vertices, plus degenerate caps
                    // exactly for the edge-on triangles.
                    extract_indexed(&w, &adj, &slots, light, caps, &mut indexed);
                    assert_eq!(indexed.sides, expected.sides, "indexed sides, light {light:?}");
                    assert_eq!(indexed.caps.len(), if caps { w.triangles.len() } else { 0 });
                    for (&cap, &tri) in indexed.caps.iter().zip(&w.triangles) {
                        let edge_on = triangle_orientation(&w.positions, tri, light) == 0;
                        assert_eq!(is_degenerate_cap(cap), edge_on, "{tri:?} {cap:?}");
                        degenerate += edge_on as usize;
                    }
                    let drawn = IndexedVolume {
                        sides: indexed.sides.clone(),
                        caps: indexed.caps.iter().copied().filter(|&c| !is_degenerate_cap(c)).collect(),
                    };
                    assert!(bits(&drawn.expand(&w.positions, light)) == bits(&expected), "indexed, light {light:?}");
                    with_caps += drawn.caps.len();
                }
            }
        }
        assert!(nonempty >= 8, "the inputs must cast silhouettes ({nonempty})");
        assert!(
            with_caps > 1000 && degenerate > 0,
            "the inputs must have caps ({with_caps}) and edge-on triangles ({degenerate})"
        );
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
        // The indexed variant reuses its own output the same way (its scratch is that of the
        // rayon worker that runs it).
        let mut indexed = IndexedVolume::default();
        let slots = TriangleSlots::build(&w, &adj).expect("the adjacency of the mesh");
        extract_indexed(&w, &adj, &slots, light, true, &mut indexed);
        assert!(!indexed.caps.is_empty());
        let warm_indexed = [indexed.sides.as_ptr() as usize, indexed.caps.as_ptr() as usize];
        for caps in [true, false, true] {
            extract_indexed(&w, &adj, &slots, light, caps, &mut indexed);
            assert_eq!([indexed.sides.as_ptr() as usize, indexed.caps.as_ptr() as usize], warm_indexed);
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
