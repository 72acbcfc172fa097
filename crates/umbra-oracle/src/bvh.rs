//! Bounding volume hierarchy over triangles for the CPU shadow reference.
//!
//! Build: binned surface area heuristic, Ingo Wald, "On fast Construction of SAH-based Bounding
//! Volume Hierarchies", IEEE Symposium on Interactive Ray Tracing 2007, Section 3 (binning of
//! the triangles' box centres, up to 32 bins per axis, SAH sweep over the bin boundaries), with
//! the two child subtrees of large nodes built in parallel (`rayon::join`). Deterministic: the
//! same input gives the same tree whatever the thread count.
//!
//! Traversal: ordered stack traversal; the ray/box slab test is made conservative as in Thiago
//! Ize, "Robust BVH Ray Traversal", JCGT 2(2), 2013, Section 3 (each slab's far distance is
//! enlarged by `2 gamma(3)` of its magnitude so rounding can never cull a box the ray touches;
//! a zero direction component with the origin exactly on a box plane constrains nothing).
//! Triangles are tested with the watertight test of [`crate::watertight`], so together nothing
//! can slip between two triangles sharing an edge.
//!
//! Triangle ids are indices into the `triangles` slice given to [`Bvh::build`]. Triangles with a
//! non-finite vertex coordinate are left out (they could not be hit anyway) and counted.

use crate::watertight::ShearedRay;
use crate::OracleError;

/// Most bins per axis for the SAH sweep (Wald 2007 uses 16-32).
const BINS: usize = 32;
/// Maximum triangles per leaf; the SAH may choose smaller leaves.
const MAX_LEAF: usize = 8;
/// Depth cap: nodes at this depth become leaves whatever their size, so a fixed traversal stack
/// of `STACK` entries always suffices (each level pushes at most one node).
const MAX_DEPTH: usize = 60;
const STACK: usize = MAX_DEPTH + 4;
/// Subtrees with more triangles than this are built in parallel.
const PARALLEL_THRESHOLD: usize = 4096;
/// SAH cost of one traversal step relative to one triangle test.
const TRAVERSAL_COST: f32 = 1.0;

/// A ray hit: parameter `t` along the ray direction and the id of the triangle hit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    pub t: f64,
    pub triangle: u32,
}

/// One node, 32 bytes. `count == 0`: interior node with children `first` and `first + 1`;
/// otherwise a leaf holding triangles `first .. first + count` of the BVH order.
#[derive(Clone, Copy, Debug)]
struct Node {
    min: [f32; 3],
    first: u32,
    max: [f32; 3],
    count: u32,
}

/// The hierarchy: nodes plus the triangles' vertices copied in leaf order.
#[derive(Clone, Debug)]
pub struct Bvh {
    nodes: Vec<Node>,
    /// Vertices of the triangles in BVH order.
    vertices: Vec<[[f32; 3]; 3]>,
    /// Original triangle id of each entry of `vertices`.
    ids: Vec<u32>,
    /// Number of triangles in the input (ids range over `0..triangle_count`).
    triangle_count: usize,
}

#[derive(Clone, Copy, Debug)]
struct Bounds {
    min: [f32; 3],
    max: [f32; 3],
}

impl Bounds {
    const EMPTY: Bounds = Bounds { min: [f32::INFINITY; 3], max: [f32::NEG_INFINITY; 3] };
    // Plain compare-selects (one minss/maxss each): inputs are finite, non-finite triangles
    // having been left out, so the NaN rules of f32::min/max are not needed.
    #[inline]
    fn grow(&mut self, b: &Bounds) {
        for k in 0..3 {
            self.min[k] = if b.min[k] < self.min[k] { b.min[k] } else { self.min[k] };
            self.max[k] = if b.max[k] > self.max[k] { b.max[k] } else { self.max[k] };
        }
    }
    #[inline]
    fn grow_point(&mut self, p: [f32; 3]) {
        self.grow(&Bounds { min: p, max: p });
    }
    /// Half the surface area (the SAH only needs ratios); 0 for an empty box.
    fn half_area(&self) -> f32 {
        let e = [0, 1, 2].map(|k| (self.max[k] - self.min[k]).max(0.0));
        e[0] * e[1] + e[1] * e[2] + e[2] * e[0]
    }
}

/// What the builder sorts: one triangle's box, centroid and id.
#[derive(Clone, Copy, Debug)]
struct PrimRef {
    bounds: Bounds,
    centroid: [f32; 3],
    id: u32,
}

/// Build-time tree, flattened into [`Node`]s afterwards.
enum BuildNode {
    Leaf { bounds: Bounds, first: usize, count: usize },
    Interior { bounds: Bounds, children: Box<[BuildNode; 2]> },
}

impl BuildNode {
    fn bounds(&self) -> Bounds {
        match self {
            BuildNode::Leaf { bounds, .. } | BuildNode::Interior { bounds, .. } => *bounds,
        }
    }
}

impl Bvh {
    /// Builds the hierarchy over `triangles` (indices into `positions`), in parallel.
    ///
    /// Errors if a triangle indexes past `positions` or there are more than `u32::MAX - 1`
    /// triangles (`u32::MAX` is reserved for "no triangle").
    pub fn build(positions: &[[f32; 3]], triangles: &[[u32; 3]]) -> Result<Bvh, OracleError> {
        use rayon::prelude::*;
        if triangles.len() >= u32::MAX as usize {
            return Err(OracleError::TooManyTriangles { count: triangles.len() });
        }
        if let Some((triangle, vertex)) = triangles
            .iter()
            .enumerate()
            .find_map(|(i, t)| t.iter().find(|&&v| v as usize >= positions.len()).map(|&v| (i, v)))
        {
            return Err(OracleError::VertexOutOfRange { triangle, vertex, vertices: positions.len() });
        }
        let mut prims: Vec<PrimRef> = triangles
            .par_iter()
            .enumerate()
            .filter_map(|(i, t)| {
                let v = t.map(|k| positions[k as usize]);
                if v.iter().flatten().any(|c| !c.is_finite()) {
                    return None;
                }
                let mut bounds = Bounds::EMPTY;
                v.iter().for_each(|&p| bounds.grow_point(p));
                let centroid = [0, 1, 2].map(|k| 0.5 * (bounds.min[k] + bounds.max[k]));
                Some(PrimRef { bounds, centroid, id: i as u32 })
            })
            .collect();
        let root = if prims.is_empty() {
            BuildNode::Leaf { bounds: Bounds::EMPTY, first: 0, count: 0 }
        } else {
            let (bounds, centroids) = prims.par_chunks(16384).map(bounds_of).reduce(
                || (Bounds::EMPTY, Bounds::EMPTY),
                |mut a, b| {
                    a.0.grow(&b.0);
                    a.1.grow(&b.1);
                    a
                },
            );
            build_recursive(&mut prims, 0, 0, bounds, centroids)
        };
        let mut nodes = Vec::with_capacity(prims.len());
        let b = root.bounds();
        nodes.push(Node { min: b.min, first: 0, max: b.max, count: 0 });
        flatten(&root, 0, &mut nodes);
        let vertices = prims.par_iter().map(|p| triangles[p.id as usize].map(|k| positions[k as usize])).collect();
        let ids = prims.iter().map(|p| p.id).collect();
        Ok(Bvh { nodes, vertices, ids, triangle_count: triangles.len() })
    }

    /// Number of triangles the BVH was built from (including left-out non-finite ones).
    pub fn triangle_count(&self) -> usize {
        self.triangle_count
    }

    /// Number of triangles left out because a vertex coordinate was not finite.
    pub fn skipped_triangles(&self) -> usize {
        self.triangle_count - self.ids.len()
    }

    /// Number of nodes (for statistics).
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// Any-hit query: does `origin + t * direction` hit a triangle other than
    /// `ignore_triangle` (pass `u32::MAX` to ignore none) with `t_min < t < t_max`?
    /// Exits at the first hit found.
    pub fn occluded(
        &self,
        origin: [f64; 3],
        direction: [f64; 3],
        t_min: f64,
        t_max: f64,
        ignore_triangle: u32,
    ) -> bool {
        let mut found = false;
        self.traverse(origin, direction, t_min, t_max, 0.0, |bvh, i, ray, t_far| {
            if bvh.ids[i] == ignore_triangle {
                return None;
            }
            let [a, b, c] = bvh.vertices[i];
            if ray.intersect(a, b, c, t_min, t_far).is_some() {
                found = true;
                // Returning t_min as the new far limit empties the interval: traversal stops.
                Some(t_min)
            } else {
                None
            }
        });
        found
    }

    /// [`Bvh::occluded`] that also says whether the answer is *robust*: whether it would stay
    /// the same if every triangle were grown or shrunk by `margin` (a world distance; see
    /// [`crate::watertight::ShearedRay::intersect_near`]). Returns `(occluded, uncertain)`:
    /// `occluded` is exactly [`Bvh::occluded`]'s answer; `uncertain` is true when no triangle is
    /// hit at least `margin` inside its edges but some triangle is passed within `margin`
    /// (the ray grazes an edge: the sample is on a shadow boundary, up to `margin`).
    pub fn occluded_near(
        &self,
        origin: [f64; 3],
        direction: [f64; 3],
        t_min: f64,
        t_max: f64,
        ignore_triangle: u32,
        margin: f64,
    ) -> (bool, bool) {
        let (mut exact, mut grown, mut shrunk) = (false, false, false);
        self.traverse(origin, direction, t_min, t_max, margin, |bvh, i, ray, _t_far| {
            if bvh.ids[i] == ignore_triangle {
                return None;
            }
            let [a, b, c] = bvh.vertices[i];
            let hit = ray.intersect_near(a, b, c, t_min, t_max, margin);
            exact |= hit.exact;
            grown |= hit.grown;
            if hit.shrunk {
                shrunk = true;
                // A robust hit settles it: occluded, and certainly so. End the traversal.
                return Some(t_min);
            }
            None
        });
        (exact, grown && !shrunk)
    }

    /// Calls `found(triangle, [ab, bc, ca])` for every triangle but `ignore_triangle` whose
    /// edges the segment `origin + t direction`, `t_min < t < t_max`, passes within `margin`
    /// of ([`ShearedRay::near_edges`]), in the fixed traversal order.
    // The segment's four numbers, the triangle left out, the margin and the callback are the
    // query itself, the same ones `occluded_near` takes; a struct would only rename them.
    #[allow(clippy::too_many_arguments)]
    pub fn near_edges(
        &self,
        origin: [f64; 3],
        direction: [f64; 3],
        t_min: f64,
        t_max: f64,
        ignore_triangle: u32,
        margin: f64,
        mut found: impl FnMut(u32, [bool; 3]),
    ) {
        self.traverse(origin, direction, t_min, t_max, margin, |bvh, i, ray, _t_far| {
            if bvh.ids[i] != ignore_triangle {
                let [a, b, c] = bvh.vertices[i];
                if let Some(edges) = ray.near_edges(a, b, c, t_min, t_max, margin) {
                    found(bvh.ids[i], edges);
                }
            }
            None
        });
    }

    /// Calls `visit(triangle, vertices)` for every triangle but `ignore_triangle` whose
    /// bounding box the segment `origin + t direction`, `t_min < t < t_max`, passes within
    /// `margin` of (boxes grown by `margin`, conservative slab test), in the fixed traversal
    /// order, until `visit` returns `true`. The candidates of a proximity test: the caller
    /// measures the distances itself.
    // The segment's four numbers, the triangle left out, the margin and the callback are the
    // query itself, as in `near_edges`; a struct would only rename them.
    #[allow(clippy::too_many_arguments)]
    pub fn triangles_near_segment(
        &self,
        origin: [f64; 3],
        direction: [f64; 3],
        t_min: f64,
        t_max: f64,
        ignore_triangle: u32,
        margin: f64,
        mut visit: impl FnMut(u32, [[f32; 3]; 3]) -> bool,
    ) {
        self.traverse(origin, direction, t_min, t_max, margin, |bvh, i, _ray, _t_far| {
            if bvh.ids[i] != ignore_triangle && visit(bvh.ids[i], bvh.vertices[i]) {
                // Returning t_min as the new far limit empties the interval: traversal stops.
                return Some(t_min);
            }
            None
        });
    }

    /// Calls `visit(triangle, vertices)` for every triangle but `ignore_triangle` whose
    /// bounding box lies within `radius` of `point`, until `visit` returns `true`.
    pub fn triangles_near_point(
        &self,
        point: [f64; 3],
        radius: f64,
        ignore_triangle: u32,
        mut visit: impl FnMut(u32, [[f32; 3]; 3]) -> bool,
    ) {
        if self.ids.is_empty() || radius.is_nan() {
            return;
        }
        let near = |n: &Node| {
            let d2: f64 = (0..3)
                .map(|k| {
                    let d = (f64::from(n.min[k]) - point[k]).max(point[k] - f64::from(n.max[k])).max(0.0);
                    d * d
                })
                .sum();
            d2 <= radius * radius
        };
        let mut stack = [0u32; STACK];
        let mut top = 0usize;
        if !near(&self.nodes[0]) {
            return;
        }
        let mut node = 0usize;
        loop {
            let n = &self.nodes[node];
            if n.count > 0 {
                let first = n.first as usize;
                for i in first..first + n.count as usize {
                    if self.ids[i] != ignore_triangle && visit(self.ids[i], self.vertices[i]) {
                        return;
                    }
                }
            } else {
                let left = n.first as usize;
                match (near(&self.nodes[left]), near(&self.nodes[left + 1])) {
                    (true, true) => {
                        stack[top] = (left + 1) as u32;
                        top += 1;
                        node = left;
                        continue;
                    }
                    (true, false) => {
                        node = left;
                        continue;
                    }
                    (false, true) => {
                        node = left + 1;
                        continue;
                    }
                    (false, false) => {}
                }
            }
            if top == 0 {
                return;
            }
            top -= 1;
            node = stack[top] as usize;
        }
    }

    /// Closest-hit query over `t_min < t < t_max`. Among hits at exactly equal `t` (a ray through
    /// a shared edge) the one met first in the fixed traversal order wins, deterministically.
    pub fn intersect(&self, origin: [f64; 3], direction: [f64; 3], t_min: f64, t_max: f64) -> Option<Hit> {
        let mut best: Option<Hit> = None;
        self.traverse(origin, direction, t_min, t_max, 0.0, |bvh, i, ray, t_far| {
            let [a, b, c] = bvh.vertices[i];
            let t = ray.intersect(a, b, c, t_min, t_far)?;
            best = Some(Hit { t, triangle: bvh.ids[i] });
            Some(t)
        });
        best
    }

    /// Ordered stack traversal. `visit(bvh, index in BVH order, ray, current far limit)` returns
    /// `Some(new far limit)` to shrink the interval (closest hit) or end it (any hit).
    #[inline]
    fn traverse<F>(&self, origin: [f64; 3], direction: [f64; 3], t_min: f64, t_max: f64, margin: f64, mut visit: F)
    where
        F: FnMut(&Bvh, usize, &ShearedRay, f64) -> Option<f64>,
    {
        // `>=` is not `!<`: a NaN limit must also end the query.
        #[allow(clippy::neg_cmp_op_on_partial_ord)]
        let empty = !(t_min < t_max);
        if self.ids.is_empty() || empty {
            return;
        }
        let ray = ShearedRay::new(origin, direction);
        let slabs = SlabRay::new(origin, direction, margin);
        let mut t_far = t_max;
        let mut stack = [0u32; STACK];
        let mut top = 0usize;
        let mut node = 0usize;
        loop {
            let n = &self.nodes[node];
            if n.count > 0 {
                let first = n.first as usize;
                for i in first..first + n.count as usize {
                    if let Some(t) = visit(self, i, &ray, t_far) {
                        t_far = t;
                    }
                }
                if t_far <= t_min {
                    return;
                }
            } else {
                let left = n.first as usize;
                // The triangle test rounds t too: a hit computed slightly before a box's computed
                // entry must not be culled by the current far limit, so boxes are tested against
                // a limit enlarged by a relative 1e-9 (far above both rounding errors).
                let box_far = t_far + t_far.abs() * BOX_MARGIN;
                let hl = slabs.enter(&self.nodes[left], t_min, box_far);
                let hr = slabs.enter(&self.nodes[left + 1], t_min, box_far);
                match (hl, hr) {
                    (Some(dl), Some(dr)) => {
                        let (near, far) = if dl <= dr { (left, left + 1) } else { (left + 1, left) };
                        // Depth is capped at MAX_DEPTH so the stack holds at most one entry per level.
                        stack[top] = far as u32;
                        top += 1;
                        node = near;
                        continue;
                    }
                    (Some(_), None) => {
                        node = left;
                        continue;
                    }
                    (None, Some(_)) => {
                        node = left + 1;
                        continue;
                    }
                    (None, None) => {}
                }
            }
            if top == 0 {
                return;
            }
            top -= 1;
            node = stack[top] as usize;
        }
    }
}

/// Relative enlargement of the far limit for box tests, see [`Bvh::traverse`].
const BOX_MARGIN: f64 = 1e-9;

/// gamma(3) of Ize 2013 / PBRT for f64: `3u / (1 - 3u)`, u = 2^-53.
const GAMMA3: f64 = 3.0 * (f64::EPSILON * 0.5) / (1.0 - 3.0 * (f64::EPSILON * 0.5));

/// A ray prepared for the slab test: per axis the reciprocal direction and which box plane is
/// met first (`min` for a positive direction, `max` for a negative one, including -0.0).
struct SlabRay {
    origin: [f64; 3],
    inv: [f64; 3],
    negative: [bool; 3],
    /// Every box is grown by this distance on each side (0 for the exact queries: `x - 0.0`
    /// is `x`, so they are unchanged): a ray passing within it of a box may pass within it of
    /// a triangle inside, which [`Bvh::occluded_near`] must visit.
    margin: f64,
}

impl SlabRay {
    fn new(origin: [f64; 3], direction: [f64; 3], margin: f64) -> SlabRay {
        let inv = direction.map(|d| 1.0 / d);
        SlabRay { origin, inv, negative: inv.map(|i| i.is_sign_negative()), margin }
    }

    /// Conservative slab test (Ize 2013, Sec. 3): the entry distance if the interval
    /// `(t_min, t_max)` overlaps the box. The far distance of each slab is enlarged by
    /// `2 gamma(3)` of its magnitude, so rounding never culls a box the ray touches.
    ///
    /// Zero direction components: `inv = +-inf`, so a slab the origin lies strictly inside gives
    /// `(-inf, +inf)` and one it lies outside gives an empty interval, as it should. With the
    /// origin exactly on a plane, `0 * inf = NaN`: the ray runs inside that plane, i.e. within
    /// the slab, and the compare-selects below keep the current limit when the candidate is
    /// NaN (every comparison with NaN is false), so that plane constrains nothing.
    #[inline]
    fn enter(&self, n: &Node, t_min: f64, t_max: f64) -> Option<f64> {
        let mut near = t_min;
        let mut far = t_max;
        for k in 0..3 {
            // Per-ray constant branch: perfectly predicted.
            let (lo, hi) = (n.min[k] as f64 - self.margin, n.max[k] as f64 + self.margin);
            let (plane_near, plane_far) = if self.negative[k] { (hi, lo) } else { (lo, hi) };
            let t_near = (plane_near - self.origin[k]) * self.inv[k];
            let t_far = (plane_far - self.origin[k]) * self.inv[k];
            let t_far = t_far + t_far.abs() * (2.0 * GAMMA3);
            near = if t_near > near { t_near } else { near };
            far = if t_far < far { t_far } else { far };
        }
        if near <= far {
            Some(near)
        } else {
            None
        }
    }
}

/// Writes the children of `b` (whose own node is at `index`, already pushed) and recurses.
fn flatten(b: &BuildNode, index: usize, nodes: &mut Vec<Node>) {
    match b {
        BuildNode::Leaf { first, count, .. } => {
            nodes[index].first = *first as u32;
            nodes[index].count = *count as u32;
        }
        BuildNode::Interior { children, .. } => {
            let left = nodes.len();
            nodes[index].first = left as u32;
            nodes[index].count = 0;
            for c in children.iter() {
                let cb = c.bounds();
                nodes.push(Node { min: cb.min, first: 0, max: cb.max, count: 0 });
            }
            flatten(&children[0], left, nodes);
            flatten(&children[1], left + 1, nodes);
        }
    }
}

/// Bounds of the triangles and of their centroids.
fn bounds_of(prims: &[PrimRef]) -> (Bounds, Bounds) {
    let mut bounds = Bounds::EMPTY;
    let mut centroids = Bounds::EMPTY;
    for p in prims {
        bounds.grow(&p.bounds);
        centroids.grow_point(p.centroid);
    }
    (bounds, centroids)
}

/// Builds the subtree over `prims` (which start at `offset` in the global order), reordering
/// `prims` in place so that each leaf is a contiguous range. `bounds` / `centroids` are the
/// bounds of the triangles and of their centroids, computed by the caller's partition.
fn build_recursive(prims: &mut [PrimRef], offset: usize, depth: usize, bounds: Bounds, centroids: Bounds) -> BuildNode {
    let n = prims.len();
    let leaf = BuildNode::Leaf { bounds, first: offset, count: n };
    if n <= 2 || depth >= MAX_DEPTH {
        return leaf;
    }
    let split = best_split(prims, &bounds, &centroids);
    let mut mid = match split {
        Some((cost, axis, bin)) => {
            let leaf_cost = n as f32;
            if n <= MAX_LEAF && leaf_cost <= cost {
                return leaf;
            }
            let bins = bin_count(n);
            let (lo, scale) = bin_mapping(&centroids, axis, bins);
            partition(prims, |p| bin_of(p.centroid[axis], lo, scale, bins) < bin)
        }
        None => 0,
    };
    // A split that leaves one side empty (all centroids equal, or rounding) falls back to the
    // median along the widest centroid axis, or to halving by position when all are equal.
    if mid == 0 || mid == n {
        if n <= MAX_LEAF {
            return leaf;
        }
        let axis = widest_axis(&centroids);
        mid = n / 2;
        prims.select_nth_unstable_by(mid, |a, b| a.centroid[axis].total_cmp(&b.centroid[axis]));
    }
    let (left, right) = prims.split_at_mut(mid);
    let build = |part: &mut [PrimRef], at: usize| {
        let (b, c) = bounds_of(part);
        build_recursive(part, at, depth + 1, b, c)
    };
    let (l, r) = if n > PARALLEL_THRESHOLD {
        rayon::join(|| build(left, offset), || build(right, offset + mid))
    } else {
        (build(left, offset), build(right, offset + mid))
    };
    BuildNode::Interior { bounds, children: Box::new([l, r]) }
}

fn widest_axis(b: &Bounds) -> usize {
    let e = [0, 1, 2].map(|k| b.max[k] - b.min[k]);
    if e[0] >= e[1] && e[0] >= e[2] {
        0
    } else if e[1] >= e[2] {
        1
    } else {
        2
    }
}

/// Bins used for a node of `n` triangles: up to [`BINS`], but no more than the triangles (the
/// per-node sweep over the bins would otherwise dominate the many small nodes).
fn bin_count(n: usize) -> usize {
    n.clamp(2, BINS)
}

/// Centroid-to-bin mapping of Wald 2007 Eq. (2): `bin = floor(bins (1 - eps) (c - lo) / extent)`.
fn bin_mapping(centroids: &Bounds, axis: usize, bins: usize) -> (f32, f32) {
    let lo = centroids.min[axis];
    let extent = centroids.max[axis] - lo;
    let scale = if extent > 0.0 { bins as f32 * (1.0 - 1e-6) / extent } else { 0.0 };
    (lo, scale)
}

#[inline]
fn bin_of(c: f32, lo: f32, scale: f32, bins: usize) -> usize {
    (((c - lo) * scale) as usize).min(bins - 1)
}

/// Best SAH split `(cost, axis, first bin of the right side)` over all axes, costs in units of
/// one triangle test relative to the parent's area. One pass over the triangles bins all three
/// axes at once.
fn best_split(prims: &[PrimRef], bounds: &Bounds, centroids: &Bounds) -> Option<(f32, usize, usize)> {
    let parent_area = bounds.half_area();
    let bins = bin_count(prims.len());
    let maps = [0, 1, 2].map(|axis| bin_mapping(centroids, axis, bins));
    let mut counts = [[0u32; BINS]; 3];
    let mut boxes = [[Bounds::EMPTY; BINS]; 3];
    for p in prims {
        for axis in 0..3 {
            let (lo, scale) = maps[axis];
            let b = bin_of(p.centroid[axis], lo, scale, bins);
            counts[axis][b] += 1;
            boxes[axis][b].grow(&p.bounds);
        }
    }
    let mut best: Option<(f32, usize, usize)> = None;
    for axis in 0..3 {
        if maps[axis].1 == 0.0 {
            continue;
        }
        let (counts, boxes) = (&counts[axis], &boxes[axis]);
        // Right-to-left sweep: area * count of the right side for each split position.
        let mut right_cost = [0f32; BINS];
        let mut acc = Bounds::EMPTY;
        let mut count = 0u32;
        for i in (1..bins).rev() {
            acc.grow(&boxes[i]);
            count += counts[i];
            right_cost[i] = acc.half_area() * count as f32;
        }
        let mut acc = Bounds::EMPTY;
        let mut count = 0usize;
        for i in 1..bins {
            acc.grow(&boxes[i - 1]);
            count += counts[i - 1] as usize;
            if count == 0 || count == prims.len() {
                continue;
            }
            let cost = TRAVERSAL_COST
                + if parent_area > 0.0 {
                    (acc.half_area() * count as f32 + right_cost[i]) / parent_area
                } else {
                    prims.len() as f32
                };
            if best.is_none_or(|(c, _, _)| cost < c) {
                best = Some((cost, axis, i));
            }
        }
    }
    best
}

/// In-place partition (order not kept); returns the number of elements satisfying `pred`.
fn partition<F: Fn(&PrimRef) -> bool>(prims: &mut [PrimRef], pred: F) -> usize {
    let mut i = 0;
    let mut j = prims.len();
    while i < j {
        if pred(&prims[i]) {
            i += 1;
        } else {
            j -= 1;
            prims.swap(i, j);
        }
    }
    i
}
