//! The binned-SAH build of [`RayBvh`] (Wald, "On fast Construction of SAH-based Bounding Volume
//! Hierarchies", 2007: [`BINS`] bins of the centroids per axis, the split of least
//! `area * count` on either side), then the flattening into the GPU layout (siblings
//! adjacent, parent indices). Iterative throughout (an explicit stack): a degenerate SAH tree as
//! deep as the triangle count cannot overflow the thread's stack.

use super::{lex_greater, RayBvh, BINS, LEAF_BIT, LEAF_COUNT_BITS, MAX_LEAF, NODE_VEC4S, NO_PARENT, TRIANGLE_VEC4S};

#[derive(Clone, Copy)]
struct Bounds {
    lo: [f32; 3],
    hi: [f32; 3],
}

impl Bounds {
    const EMPTY: Bounds = Bounds { lo: [f32::INFINITY; 3], hi: [f32::NEG_INFINITY; 3] };

    fn grow(&mut self, p: [f32; 3]) {
        self.lo = [0, 1, 2].map(|k| self.lo[k].min(p[k]));
        self.hi = [0, 1, 2].map(|k| self.hi[k].max(p[k]));
    }

    fn join(&mut self, o: &Bounds) {
        self.grow(o.lo);
        self.grow(o.hi);
    }

    /// Half the surface area (f64: the SAH's weights), 0 when empty.
    fn half_area(&self) -> f64 {
        if self.lo[0] > self.hi[0] {
            return 0.0;
        }
        let d = [0, 1, 2].map(|k| f64::from(self.hi[k]) - f64::from(self.lo[k]));
        d[0] * d[1] + d[1] * d[2] + d[2] * d[0]
    }
}

enum Kind {
    Leaf {
        first: usize,
        count: usize,
    },
    /// `left` holds the centroids below the split along `axis`.
    Inner {
        left: usize,
        right: usize,
        axis: u32,
    },
}

struct Node {
    bounds: Bounds,
    kind: Kind,
}

/// Builds the hierarchy of the triangles `triangles` (indices into `positions`). Triangles with
/// a non-finite vertex, an index out of range or zero area (the f64 cross product of two f32
/// edges, exact but for its final sums) are left out and counted in [`RayBvh::skipped`]: no ray
/// hits them in the reference's watertight test either.
pub fn build(positions: &[[f32; 3]], triangles: &[[u32; 3]]) -> RayBvh {
    let mut refs: Vec<(u32, Bounds, [f32; 3])> = Vec::with_capacity(triangles.len());
    let mut scale = 0f32;
    let mut all = Bounds::EMPTY;
    for (id, t) in triangles.iter().enumerate() {
        let Some(v) = vertices(positions, t) else { continue };
        if v.iter().flatten().any(|c| !c.is_finite()) || zero_area(v) {
            continue;
        }
        let mut b = Bounds::EMPTY;
        for p in v {
            b.grow(p);
            scale = p.iter().fold(scale, |s, c| s.max(c.abs()));
        }
        all.join(&b);
        let centroid = [0, 1, 2].map(|k| 0.5 * b.lo[k] + 0.5 * b.hi[k]);
        refs.push((id as u32, b, centroid));
    }
    let skipped = triangles.len() - refs.len();
    let diagonal =
        if refs.is_empty() { 0.0 } else { (0..3).map(|k| (all.hi[k] - all.lo[k]).powi(2)).sum::<f32>().sqrt() };
    // The f32 slab test rounds (lo - o) and its product with 1 / d: relative errors of a few
    // 2^-24 of magnitudes up to the scene's scale, so a box widened by 2^-18 of it (64 such
    // roundings) is never missed by a ray that meets the unpadded box.
    let pad = scale.max(diagonal) * (1.0 / 262_144.0);
    let mut nodes: Vec<Node> = Vec::new();
    if !refs.is_empty() {
        split_all(&mut refs, &mut nodes);
    }
    let mut out = RayBvh { pad, skipped, ..RayBvh::default() };
    flatten(&nodes, &refs, positions, triangles, &mut out);
    out
}

fn vertices(positions: &[[f32; 3]], t: &[u32; 3]) -> Option<[[f32; 3]; 3]> {
    Some([*positions.get(t[0] as usize)?, *positions.get(t[1] as usize)?, *positions.get(t[2] as usize)?])
}

fn zero_area(v: [[f32; 3]; 3]) -> bool {
    let d = |i: usize, k: usize| f64::from(v[i][k]) - f64::from(v[0][k]);
    let n = [
        d(1, 1) * d(2, 2) - d(1, 2) * d(2, 1),
        d(1, 2) * d(2, 0) - d(1, 0) * d(2, 2),
        d(1, 0) * d(2, 1) - d(1, 1) * d(2, 0),
    ];
    n == [0.0; 3]
}

/// The nodes of `refs` (reordered in place so that every leaf is a range), root first, each
/// node's children after it.
fn split_all(refs: &mut [(u32, Bounds, [f32; 3])], nodes: &mut Vec<Node>) {
    // (node index, first ref, count)
    let mut todo = vec![(0usize, 0usize, refs.len())];
    nodes.push(Node { bounds: Bounds::EMPTY, kind: Kind::Leaf { first: 0, count: 0 } });
    while let Some((at, first, count)) = todo.pop() {
        let range = &mut refs[first..first + count];
        let mut bounds = Bounds::EMPTY;
        let mut centres = Bounds::EMPTY;
        for r in range.iter() {
            bounds.join(&r.1);
            centres.grow(r.2);
        }
        nodes[at].bounds = bounds;
        let Some((mid, axis)) = choose_split(range, &centres, bounds.half_area()) else {
            nodes[at].kind = Kind::Leaf { first, count };
            continue;
        };
        let (left, right) = (nodes.len(), nodes.len() + 1);
        for _ in 0..2 {
            nodes.push(Node { bounds: Bounds::EMPTY, kind: Kind::Leaf { first: 0, count: 0 } });
        }
        nodes[at].kind = Kind::Inner { left, right, axis };
        todo.push((left, first, mid));
        todo.push((right, first + mid, count - mid));
    }
}

/// Partitions `range` at the cheapest binned SAH split and returns the left side's size and the
/// axis, or
/// `None` to make it a leaf (at most [`MAX_LEAF`] triangles and no split cheaper than the leaf).
/// More than [`MAX_LEAF`] triangles whose centroids coincide are split in the middle.
fn choose_split(range: &mut [(u32, Bounds, [f32; 3])], centres: &Bounds, area: f64) -> Option<(usize, u32)> {
    let n = range.len();
    if n == 1 {
        return None;
    }
    // (cost, axis, bin boundary): the left side holds bins < boundary.
    let mut best: Option<(f64, usize, usize)> = None;
    for axis in 0..3 {
        let (lo, hi) = (centres.lo[axis], centres.hi[axis]);
        // Also skips NaN extents (none reach here: non-finite triangles are left out).
        if hi.partial_cmp(&lo) != Some(std::cmp::Ordering::Greater) {
            continue;
        }
        let bin_of = |c: f32| (((c - lo) / (hi - lo) * BINS as f32) as usize).min(BINS - 1);
        let mut bins = [(Bounds::EMPTY, 0usize); BINS];
        for r in range.iter() {
            let b = &mut bins[bin_of(r.2[axis])];
            b.0.join(&r.1);
            b.1 += 1;
        }
        let mut right_cost = [0f64; BINS];
        let mut acc = (Bounds::EMPTY, 0usize);
        for i in (1..BINS).rev() {
            acc.0.join(&bins[i].0);
            acc.1 += bins[i].1;
            right_cost[i] = acc.0.half_area() * acc.1 as f64;
        }
        let mut left = (Bounds::EMPTY, 0usize);
        for i in 1..BINS {
            left.0.join(&bins[i - 1].0);
            left.1 += bins[i - 1].1;
            if left.1 == 0 || left.1 == n {
                continue;
            }
            let cost = left.0.half_area() * left.1 as f64 + right_cost[i];
            if best.is_none_or(|b| cost < b.0) {
                best = Some((cost, axis, i));
            }
        }
    }
    match best {
        // A traversal step costs about one triangle test: a leaf costs n, a split 1 + its SAH.
        Some((cost, _, _)) if n <= MAX_LEAF && area > 0.0 && (n as f64) <= 1.0 + cost / area => None,
        Some((_, axis, boundary)) => {
            let (lo, hi) = (centres.lo[axis], centres.hi[axis]);
            let bin_of = |c: f32| (((c - lo) / (hi - lo) * BINS as f32) as usize).min(BINS - 1);
            let mut mid = 0;
            for i in 0..n {
                if bin_of(range[i].2[axis]) < boundary {
                    range.swap(i, mid);
                    mid += 1;
                }
            }
            Some((mid, axis as u32))
        }
        None if n <= MAX_LEAF => None,
        None => Some((n / 2, 0)),
    }
}

/// Writes `nodes` in the GPU layout: the root at 0, the two children of every inner node at
/// `c` (left, odd) and `c + 1` (right), each node with its parent's index; and the triangle
/// records in the leaves' order.
fn flatten(
    nodes: &[Node],
    refs: &[(u32, Bounds, [f32; 3])],
    positions: &[[f32; 3]],
    triangles: &[[u32; 3]],
    out: &mut RayBvh,
) {
    let n = nodes.len();
    out.nodes = vec![[0.0; 4]; NODE_VEC4S * n];
    out.triangles = Vec::with_capacity(TRIANGLE_VEC4S * refs.len());
    let pad = out.pad;
    let mut next = 1usize;
    // (node, its index, its parent's index, depth)
    let mut todo = if n > 0 { vec![(0usize, 0usize, NO_PARENT, 0usize)] } else { Vec::new() };
    while let Some((i, at, parent, depth)) = todo.pop() {
        out.depth = out.depth.max(depth);
        let b = nodes[i].bounds;
        let word = match nodes[i].kind {
            Kind::Leaf { first, count } => {
                let record = out.triangles.len() / TRIANGLE_VEC4S;
                for r in &refs[first..first + count] {
                    push_record(out, positions, triangles[r.0 as usize], r.0);
                }
                LEAF_BIT | ((record as u32) << LEAF_COUNT_BITS) | count as u32
            }
            Kind::Inner { left, right, axis } => {
                let c = next;
                next += 2;
                todo.push((right, c + 1, at as u32, depth + 1));
                todo.push((left, c, at as u32, depth + 1));
                ((c as u32) << 2) | axis
            }
        };
        out.nodes[NODE_VEC4S * at] = [b.lo[0] - pad, b.lo[1] - pad, b.lo[2] - pad, f32::from_bits(parent)];
        out.nodes[NODE_VEC4S * at + 1] = [b.hi[0] + pad, b.hi[1] + pad, b.hi[2] + pad, f32::from_bits(word)];
    }
}

fn push_record(out: &mut RayBvh, positions: &[[f32; 3]], t: [u32; 3], id: u32) {
    let v = t.map(|k| positions[k as usize]);
    let mut edges = 0u32;
    for k in 0..3 {
        if lex_greater(v[k], v[(k + 1) % 3]) {
            edges |= 1 << k;
        }
    }
    out.triangles.push([v[0][0], v[0][1], v[0][2], f32::from_bits(id)]);
    out.triangles.push([v[1][0], v[1][1], v[1][2], f32::from_bits(edges)]);
    out.triangles.push([v[2][0], v[2][1], v[2][2], 0.0]);
}
