//! The bounding-volume hierarchy of the `ray-bvh` shadow method: built on the CPU once per
//! scene (binned SAH, [`build`]), flattened into two arrays of `vec4` that GLSL (std430) and
//! WGSL read alike, and traversed per shadow ray by the GPU ([`RayBvh::walk`] is the same
//! traversal on the CPU, for tests and as the shaders' specification).
//!
//! It is not the ray-traced reference's BVH (`umbra-oracle`): the reference never shares code
//! with a method.
//!
//! # Layout
//!
//! * `nodes`, [`NODE_VEC4S`] `vec4` per node, the root first: `(lo.xyz, parent)`,
//!   `(hi.xyz, word)` as f32 bits of `u32` in the `w`s (the root's parent is [`NO_PARENT`]).
//!   The two children of an inner node are adjacent, the left one (centroids below the split)
//!   at an odd index: `word` = `left << 2 | axis` (the split's axis). A leaf's `word` is
//!   [`LEAF_BIT`] ` | first << LEAF_COUNT_BITS | count`: `count` (1 ..= [`MAX_LEAF`]) triangle
//!   records from `first`. The boxes are the triangles' f32 bounds padded by [`RayBvh::pad`].
//! * `triangles`, [`TRIANGLE_VEC4S`] `vec4` per record: `(a.xyz, id)`, `(b.xyz, edges)`,
//!   `(c.xyz, 0)`: the vertices, the id (index into the scene's triangles, the samples'
//!   triangle id) and three bits, bit k set when edge k (`ab`, `bc`, `ca`) runs against the
//!   lexicographic order of its endpoints (see [`edge_function`]).
//!
//! # The walk
//!
//! Hapala, Davidovič, Wald, Havran, Slusallek, "Efficient Stack-less BVH Traversal for Ray
//! Tracing" (SCCG 2011): the children in the ray's order (the near one first along the split
//! axis) without a stack, from the parent and sibling indices, so a walk's whole state is one
//! word, `node << 2 | how it was reached` ([`FROM_PARENT`], [`FROM_SIBLING`], [`FROM_CHILD`]):
//! a walk stopped by a step budget resumes from that word alone. Each node is entered at most
//! twice and left once, so a walk takes at most `3 x` the node count in steps.
//!
//! # The ray test
//!
//! Woop, Benthin and Wald, "Watertight Ray/Triangle Intersection" (JCGT 2013), in f32: the
//! vertices relative to the ray's origin, sheared so the ray is the +z axis, and the three 2-D
//! edge functions. Each edge function is computed from the edge's endpoints in lexicographic
//! order of their world positions and only then negated for the triangle's own order, so two
//! triangles sharing an edge get exactly opposite values for every ray (the same operations on
//! the same operands): a ray through a shared edge hits at least one of them, as in the
//! reference's f64 watertight test. Edges are closed (a zero edge function hits).

mod build;
#[cfg(test)]
mod tests;

pub use build::build;

/// `vec4` per node.
pub const NODE_VEC4S: usize = 2;
/// `vec4` per triangle record.
pub const TRIANGLE_VEC4S: usize = 3;
/// Most triangles in a leaf.
pub const MAX_LEAF: usize = 4;
/// Bits of a leaf word that hold the count (above them, the first record).
pub const LEAF_COUNT_BITS: u32 = 3;
/// The bit of a node's word that marks a leaf.
pub const LEAF_BIT: u32 = 1 << 31;
/// The root's parent index.
pub const NO_PARENT: u32 = u32::MAX;
/// Walk state: the node was reached from its parent (it is the near child).
pub const FROM_PARENT: u32 = 0;
/// Walk state: the node was reached from its sibling (it is the far child).
pub const FROM_SIBLING: u32 = 1;
/// Walk state: the walk returns to the node from one of its children.
pub const FROM_CHILD: u32 = 2;
/// Bins per axis of the SAH build.
pub const BINS: usize = 16;

/// Walk steps per shader invocation where one invocation walks the whole hierarchy (the WGSL
/// walk, umbra-wgpu's `ray_bvh.wgsl`): each step is at most 1 + 4 loop iterations, below
/// lavapipe's 65,535 loop iterations per invocation.
pub const WGSL_BUDGET: u32 = 12_000;

/// The constants `ray_bvh.wgsl` is prepended with, in WGSL: this module's layout, [`Ray::TINY`]
/// and [`WGSL_BUDGET`]. One text for every host of the shader (umbra-wgpu natively, the
/// WebAssembly module for umbra-three's WebGPU path), so that the walk reads the buffers
/// [`build`] wrote.
pub fn wgsl_constants() -> String {
    format!(
        "const NODE_VEC4S: u32 = {NODE_VEC4S}u;\nconst TRIANGLE_VEC4S: u32 = {TRIANGLE_VEC4S}u;\n\
         const LEAF_COUNT_BITS: u32 = {LEAF_COUNT_BITS}u;\nconst LEAF_BIT: u32 = {LEAF_BIT}u;\n\
         const FROM_PARENT: u32 = {FROM_PARENT}u;\nconst FROM_SIBLING: u32 = {FROM_SIBLING}u;\n\
         const FROM_CHILD: u32 = {FROM_CHILD}u;\nconst TINY: f32 = {:e};\nconst BUDGET: u32 = {WGSL_BUDGET}u;\n",
        Ray::TINY,
    )
}

/// The flattened hierarchy; see the module documentation.
#[derive(Clone, Debug, Default)]
pub struct RayBvh {
    /// [`NODE_VEC4S`] per node, depth-first preorder.
    pub nodes: Vec<[f32; 4]>,
    /// [`TRIANGLE_VEC4S`] per triangle record, in the leaves' order.
    pub triangles: Vec<[f32; 4]>,
    /// How much every box was widened on each side (world units).
    pub pad: f32,
    /// Triangles left out: a non-finite vertex or zero area in f64 (no ray hits them).
    pub skipped: usize,
    /// Depth of the deepest leaf (the root is depth 0).
    pub depth: usize,
}

/// The work of [`RayBvh::walk`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Walk {
    /// Steps taken.
    pub steps: usize,
    /// Nodes whose box was tested.
    pub nodes: usize,
    /// Triangles tested.
    pub triangles: usize,
}

impl RayBvh {
    /// Nodes in the hierarchy.
    pub fn node_count(&self) -> usize {
        self.nodes.len() / NODE_VEC4S
    }

    /// Triangle records (the scene's triangles less [`RayBvh::skipped`]).
    pub fn triangle_count(&self) -> usize {
        self.triangles.len() / TRIANGLE_VEC4S
    }

    /// Bytes of both arrays on the GPU.
    pub fn bytes(&self) -> usize {
        16 * (self.nodes.len() + self.triangles.len())
    }

    /// Node `i`'s `(lo, hi, parent, word)`.
    pub fn node(&self, i: usize) -> ([f32; 3], [f32; 3], u32, u32) {
        let a = self.nodes[NODE_VEC4S * i];
        let b = self.nodes[NODE_VEC4S * i + 1];
        ([a[0], a[1], a[2]], [b[0], b[1], b[2]], a[3].to_bits(), b[3].to_bits())
    }

    /// Record `r`'s vertices, triangle id and edge-order bits.
    pub fn record(&self, r: usize) -> ([[f32; 3]; 3], u32, u32) {
        let v = |k: usize| {
            let q = self.triangles[TRIANGLE_VEC4S * r + k];
            [q[0], q[1], q[2]]
        };
        let id = self.triangles[TRIANGLE_VEC4S * r][3].to_bits();
        let edges = self.triangles[TRIANGLE_VEC4S * r + 1][3].to_bits();
        ([v(0), v(1), v(2)], id, edges)
    }

    /// The child of inner node `i` (word `word`) the ray `dir` meets first along its split axis.
    fn near_child(word: u32, dir: [f32; 3]) -> u32 {
        let left = word >> 2;
        if dir[(word & 3) as usize] >= 0.0 {
            left
        } else {
            left + 1
        }
    }

    /// Whether the ray `origin + t dir` hits a triangle other than `skip_id` with its hit
    /// distance `t |dir|` in `(near, far)`, by the walk and test the shaders run (f32, module
    /// documentation), and the work it took. `t_end`: the ray's parameter range for the boxes
    /// (1 for a segment to a point light at `origin + dir`).
    pub fn occluded(
        &self,
        origin: [f32; 3],
        dir: [f32; 3],
        t_end: f32,
        near: f32,
        far: f32,
        skip_id: u32,
    ) -> (bool, Walk) {
        let mut walk = Walk::default();
        let out = self.walk(&Query { origin, dir, t_end, near, far, skip_id }, START, usize::MAX, &mut walk);
        (out == Outcome::Hit, walk)
    }

    /// The walk of `q` from `state` ([`START`], or an [`Outcome::Unfinished`] state) for at
    /// most `budget` steps, adding its work to `walk`.
    pub fn walk(&self, q: &Query, mut state: u32, budget: usize, walk: &mut Walk) -> Outcome {
        let ray = Ray::new(q.origin, q.dir);
        let len = (q.dir[0] * q.dir[0] + q.dir[1] * q.dir[1] + q.dir[2] * q.dir[2]).sqrt();
        if self.node_count() == 0 {
            return Outcome::Miss;
        }
        for _ in 0..budget {
            walk.steps += 1;
            let (cur, how) = (state >> 2, state & 3);
            let (lo, hi, parent, word) = self.node(cur as usize);
            let mut leave = false;
            if how == FROM_CHILD {
                if cur == 0 {
                    return Outcome::Miss;
                }
                let (_, _, _, parent_word) = self.node(parent as usize);
                state = if cur == Self::near_child(parent_word, q.dir) {
                    (sibling(cur) << 2) | FROM_SIBLING
                } else {
                    (parent << 2) | FROM_CHILD
                };
                continue;
            }
            walk.nodes += 1;
            if !ray.hits_box(lo, hi, q.t_end) {
                leave = true;
            } else if word & LEAF_BIT != 0 {
                let first = ((word & !LEAF_BIT) >> LEAF_COUNT_BITS) as usize;
                for r in first..first + (word & ((1 << LEAF_COUNT_BITS) - 1)) as usize {
                    walk.triangles += 1;
                    let (v, id, edges) = self.record(r);
                    if id == q.skip_id {
                        continue;
                    }
                    if let Some(t) = ray.hit(v, edges) {
                        let d = t * len;
                        if d > q.near && d < q.far {
                            return Outcome::Hit;
                        }
                    }
                }
                leave = true;
            } else {
                state = (Self::near_child(word, q.dir) << 2) | FROM_PARENT;
            }
            if leave {
                state = if cur == 0 {
                    return Outcome::Miss;
                } else if how == FROM_PARENT {
                    (sibling(cur) << 2) | FROM_SIBLING
                } else {
                    (parent << 2) | FROM_CHILD
                };
            }
        }
        Outcome::Unfinished(state)
    }
}

/// The other child of `node`'s parent (children are adjacent, the left one odd).
fn sibling(node: u32) -> u32 {
    if node & 1 == 1 {
        node + 1
    } else {
        node - 1
    }
}

/// The walk's first state: the root, reached from its (absent) parent.
pub const START: u32 = FROM_PARENT;

/// One shadow ray for [`RayBvh::walk`]: hits count with their distance `t |dir|` in
/// `(near, far)`, except on triangle `skip_id`; boxes are tested for `t` in `[0, t_end]`.
#[derive(Clone, Copy, Debug)]
pub struct Query {
    /// Where the ray starts.
    pub origin: [f32; 3],
    /// Its direction (towards a point light: the light minus the origin).
    pub dir: [f32; 3],
    /// The boxes' parameter range.
    pub t_end: f32,
    /// Hits at this distance or nearer do not count.
    pub near: f32,
    /// Hits at this distance or farther do not count.
    pub far: f32,
    /// The triangle id skipped (the sample's own).
    pub skip_id: u32,
}

/// How a walk ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Outcome {
    /// A triangle counts: the ray is occluded.
    Hit,
    /// None does.
    Miss,
    /// The budget ran out: continue from this state.
    Unfinished(u32),
}

/// A ray prepared for the box and triangle tests (f32, as in the shaders).
#[derive(Clone, Copy, Debug)]
pub struct Ray {
    origin: [f32; 3],
    /// 1 / dir, with components of magnitude below [`Ray::TINY`] replaced by +-TINY first.
    inv: [f32; 3],
    kx: usize,
    ky: usize,
    kz: usize,
    shear: [f32; 3],
}

impl Ray {
    /// Direction components smaller than this are taken as this (with their sign) for the box
    /// test: it keeps `1 / d` finite, and moves the ray by less than `1e-20 t`.
    pub const TINY: f32 = 1e-20;

    /// The ray from `origin` along `dir`.
    pub fn new(origin: [f32; 3], dir: [f32; 3]) -> Ray {
        let inv = dir.map(|d| 1.0 / if d.abs() < Self::TINY { Self::TINY.copysign(d) } else { d });
        // The largest component is the shear's z (Woop et al. 2013, Section 3); x, y follow
        // cyclically, swapped when it is negative to keep the winding.
        let a = dir.map(f32::abs);
        let kz = if a[0] > a[1] {
            if a[0] > a[2] {
                0
            } else {
                2
            }
        } else if a[1] > a[2] {
            1
        } else {
            2
        };
        let (mut kx, mut ky) = ((kz + 1) % 3, (kz + 2) % 3);
        if dir[kz] < 0.0 {
            std::mem::swap(&mut kx, &mut ky);
        }
        let shear = [dir[kx] / dir[kz], dir[ky] / dir[kz], 1.0 / dir[kz]];
        Ray { origin, inv, kx, ky, kz, shear }
    }

    /// The slab test against the box `[lo, hi]` for `t` in `[0, t_end]`.
    pub fn hits_box(&self, lo: [f32; 3], hi: [f32; 3], t_end: f32) -> bool {
        let mut t0 = 0f32;
        let mut t1 = t_end;
        for k in 0..3 {
            let a = (lo[k] - self.origin[k]) * self.inv[k];
            let b = (hi[k] - self.origin[k]) * self.inv[k];
            t0 = t0.max(a.min(b));
            t1 = t1.min(a.max(b));
        }
        t0 <= t1
    }

    /// The ray's parameter `t` where it meets the triangle `v` (closed, two-sided), if it does
    /// and the triangle's projected area is not 0; `edges` as in the triangle records.
    pub fn hit(&self, v: [[f32; 3]; 3], edges: u32) -> Option<f32> {
        let p = v.map(|q| {
            let a = [q[0] - self.origin[0], q[1] - self.origin[1], q[2] - self.origin[2]];
            [
                a[self.kx] - self.shear[0] * a[self.kz],
                a[self.ky] - self.shear[1] * a[self.kz],
                self.shear[2] * a[self.kz],
            ]
        });
        // Edge k runs from vertex k to vertex k + 1; Woop's U, V, W are the edges opposite
        // vertices 0, 1, 2: bc, ca, ab.
        let e = |k: usize| edge_function(p[k], p[(k + 1) % 3], edges >> k & 1 != 0);
        let (w, u, v) = (e(0), e(1), e(2));
        if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
            return None;
        }
        let det = u + v + w;
        if det == 0.0 {
            return None;
        }
        Some((u * p[0][2] + v * p[1][2] + w * p[2][2]) / det)
    }
}

/// The 2-D edge function of the sheared endpoints `p`, `q` (`q.x p.y - q.y p.x`, Woop's sign),
/// computed as `-(p.x q.y - p.y q.x)` from the endpoint that comes first in lexicographic order
/// of world position: `swapped` says `q` comes first. The same edge of two triangles is then
/// one computation on the same operands, its values exact negations of each other.
pub fn edge_function(p: [f32; 3], q: [f32; 3], swapped: bool) -> f32 {
    let (first, second) = if swapped { (q, p) } else { (p, q) };
    let canonical = first[0] * second[1] - first[1] * second[0];
    if swapped {
        canonical
    } else {
        -canonical
    }
}

/// Whether `a` comes after `b` in lexicographic order (x, then y, then z).
pub fn lex_greater(a: [f32; 3], b: [f32; 3]) -> bool {
    for k in 0..3 {
        if a[k] != b[k] {
            return a[k] > b[k];
        }
    }
    false
}

/// The ray-traced reference's self-intersection eps, which the shadow rays' limits must equal
/// (`umbra_oracle::segment_epsilon`; tested equal in umbra-verify's tests/ray_bvh.rs): `1e-5`
/// of the larger of the bounding-box diagonal and the largest absolute coordinate, over the
/// finite positions; 0 without one.
pub fn segment_epsilon(positions: &[[f32; 3]]) -> f64 {
    let mut min = [f64::INFINITY; 3];
    let mut max = [f64::NEG_INFINITY; 3];
    let mut largest = 0f64;
    for p in positions.iter().filter(|p| p.iter().all(|c| c.is_finite())) {
        for k in 0..3 {
            let c = f64::from(p[k]);
            min[k] = min[k].min(c);
            max[k] = max[k].max(c);
            largest = largest.max(c.abs());
        }
    }
    if min[0] > max[0] {
        return 0.0;
    }
    let diagonal = (0..3).map(|k| (max[k] - min[k]).powi(2)).sum::<f64>().sqrt();
    1e-5 * diagonal.max(largest)
}
