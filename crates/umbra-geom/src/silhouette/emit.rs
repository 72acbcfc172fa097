//! The parallel two-pass emission shared by [`extract`] and
//! [`extract_indexed`]: per chunk of edges (triangles) a count, exclusive
//! prefix sums over the chunks, then every chunk writes its vertices straight into its own
//! part of the output (split recursively with `rayon::join`, no allocation); and the
//! per-thread scratch that makes a warmed-up frame allocation-free.
//!
//! [`extract`]: super::extract
//! [`extract_indexed`]: super::extract_indexed

use rayon::prelude::*;

use super::kernels::orientations_batched;
use super::volume::{oriented, point};
use crate::adjacency::EdgeAdjacency;
use crate::weld::WeldedMesh;
use crate::Light;

/// Edges (or triangles) per parallel work item: large enough to amortise the scheduling,
/// small enough to balance two to many cores.
pub(super) const ITEMS_PER_CHUNK: usize = 4096;

/// The per-frame scratch of [`extract`], kept per calling thread so a
/// warmed-up frame does not allocate.
///
/// [`extract`]: super::extract
#[derive(Default)]
pub(super) struct Scratch {
    /// Multiplicity of every edge.
    pub(super) multiplicity: Vec<i32>,
    /// Orientation of every triangle towards the light (caps only).
    pub(super) orientation: Vec<i8>,
    /// Side vertices, resp. caps, before each chunk (exclusive prefix sums; one more entry
    /// than chunks).
    pub(super) side_offsets: Vec<usize>,
    pub(super) cap_offsets: Vec<usize>,
}

thread_local! {
    pub(super) static SCRATCH: std::cell::RefCell<Scratch> = std::cell::RefCell::new(Scratch::default());
}

/// Writes the side quads of edge `[a, b]` (`a < b`) with multiplicity `m != 0` at the start
/// of `out` (which holds at least `6 |m|` vertices); returns the number of vertices written.
/// `a_far`, `b_far` are the far ends of the side: the vertices extruded to infinity (001 Eq. 2)
/// or, for a volume clamped to its receivers, to their clamp distance ([`super::clamp`]).
#[inline(always)]
fn write_sides(out: &mut [[f32; 4]], a: [f32; 3], b: [f32; 3], a_far: [f32; 4], b_far: [f32; 4], m: i32) -> usize {
    let (a_inf, b_inf) = (a_far, b_far);
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
pub(super) fn set_len<T: Copy>(v: &mut Vec<T>, len: usize, zero: T) {
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
pub(super) trait SplitOutput: Send + Sized {
    fn split(self, at: usize) -> (Self, Self);
}

impl<T: Send> SplitOutput for &mut [T] {
    fn split(self, at: usize) -> (Self, Self) {
        self.split_at_mut(at)
    }
}

/// Light caps and dark caps of one chunk, three vertices per cap.
pub(super) type CapsOut<'a> = (&'a mut [[[f32; 4]; 3]], &'a mut [[[f32; 4]; 3]]);

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
pub(super) fn write_chunks<O: SplitOutput>(
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

/// Pass 1 and 2 of the sides, shared by [`extract`] and [`extract_indexed`]: every edge's
/// multiplicity (into `multiplicity`, with `|m|` summed per chunk into `side_offsets`), then
/// every chunk writes its quads into its own part of `sides`.
///
/// [`extract`]: super::extract
/// [`extract_indexed`]: super::extract_indexed
pub(super) fn emit_sides(
    positions: &[[f32; 3]],
    adj: &EdgeAdjacency,
    multiplicity: &mut Vec<i32>,
    side_offsets: &mut Vec<usize>,
    sides: &mut Vec<[f32; 4]>,
    multiplicities: &(impl Fn(usize, &mut [i32]) + Sync),
    far: &(impl Fn(u32) -> [f32; 4] + Sync),
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
                    let (pa, pb) = (positions[a as usize], positions[b as usize]);
                    at += write_sides(&mut piece[at..], pa, pb, far(a), far(b), m);
                }
            }
        }
    });
}

/// Every triangle's [`triangle_orientation`] into `orientation` (in parallel, vectorised),
/// and the number of caps (triangles not edge-on) before each chunk into `cap_offsets`
/// (exclusive prefix sums, one more entry than chunks). Shared by [`extract`] and
/// [`extract_indexed`]; returns the number of chunks.
///
/// [`triangle_orientation`]: crate::multiplicity::triangle_orientation
/// [`extract`]: super::extract
/// [`extract_indexed`]: super::extract_indexed
pub(super) fn cap_orientations(
    mesh: &WeldedMesh,
    light: Light,
    orientation: &mut Vec<i8>,
    cap_offsets: &mut Vec<usize>,
) -> usize {
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
pub(super) fn for_each_cap(tris: &[[u32; 3]], ss: &[i8], mut emit: impl FnMut([u32; 3])) {
    for (&tri, &s) in tris.iter().zip(ss) {
        if s != 0 {
            emit(oriented(tri, s));
        }
    }
}

/// The per-frame scratch, borrowed from this thread's [`SCRATCH`] (a fresh one when it is
/// already borrowed: a rayon worker ran another extraction while waiting).
pub(super) fn with_scratch<R>(f: impl FnOnce(&mut Scratch) -> R) -> R {
    SCRATCH.with(|cell| match cell.try_borrow_mut() {
        Ok(mut scratch) => f(&mut scratch),
        Err(_) => f(&mut Scratch::default()),
    })
}
