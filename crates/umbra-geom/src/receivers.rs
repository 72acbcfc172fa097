//! The receiver map of one light: per light-space cell, the farthest visible sample from the
//! light. It turns the view's samples into what culls and clamps the shadow volumes exactly
//! ([`ReceiverMap::cull_and_clamp`] into a [`VolumeClamp`]).
//!
//! CC shadow volumes (Lloyd, Wendt, Govindaraju, Manocha, EGSR 2004, Section 4) cull and
//! clamp volumes against the regions of the light's view that hold receivers; there the
//! receivers were estimated, here they are the frame's visible samples themselves, bounded per
//! cell from above, so both operations are exact (the proof: [`crate::silhouette`]'s
//! `clamp.rs` and docs/exactness.md). A triangle shadows a sample S only when the segment from
//! S to the light meets it: S lies in the triangle's cone of directions and farther from the
//! light than the triangle.
//!
//! Cells ([`ReceiverGrid`]): a point light's directions on a cube of six `side x side` faces
//! (the face of the direction's largest coordinate; the other two divided by it, in
//! `[-1, 1]`); a directional light's plane `(u, v)` across its direction, over the scene's
//! box, `side x side` cells. A cell holds the largest [`ReceiverGrid::sample_cell`] value of
//! its samples: the distance from the light (point) or the depth along the light (directional),
//! rounded up by 2^-20 of the magnitudes involved. The renderer scatters the samples on the GPU
//! with the very f32 expressions of [`ReceiverGrid::sample_cell`] (umbra-gl's
//! `receivers/scatter.frag.glsl`); the triangles' cones are computed here in f64 and widened by
//! [`RECEIVER_MARGIN`] of the grid, far more than the rounding of a sample's cell coordinates,
//! so a sample inside the cone is always in one of the cells read.

use rayon::prelude::*;

use crate::adjacency::EdgeAdjacency;
use crate::silhouette::{keep_whole_regions, travel, TriangleSlots, VolumeClamp, CLAMP_LIMIT, CLAMP_MARGIN};
use crate::vec3::{cross, dot, norm, sub};
use crate::weld::WeldedMesh;
use crate::{Aabb, Light};

/// Cells along a side of the map's faces (a power of two).
pub const RECEIVER_SIDE: u32 = 256;

/// The widening of a triangle's cell rectangle, as a fraction of the grid's extent.
pub const RECEIVER_MARGIN: f64 = 1.0 / 16384.0;

/// The rounding up of a sample's value, relative to the magnitudes involved.
pub const RECEIVER_ROUND_UP: f32 = 1.0 / 1048576.0;

/// How a light's directions map to cells: the f32 parameters the GPU scatter uses as they are.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ReceiverGrid {
    /// A point light at `light`: six faces of `side x side` cells, face `2m + (negative)` for
    /// the major axis `m` of a direction.
    Cube {
        /// The light's position.
        light: [f32; 3],
        /// Cells along a face's side.
        side: u32,
    },
    /// A directional light: `side x side` cells over `(u, v)` coordinates relative to `origin`,
    /// cell `floor((uv - lo) * scale)`, clamped to the grid.
    Flat {
        /// Where the coordinates are measured from (the scene box's centre).
        origin: [f32; 3],
        /// First axis across the light.
        u: [f32; 3],
        /// Second axis across the light.
        v: [f32; 3],
        /// Unit direction of travel of the light's rays: a sample's value is its depth along it.
        travel: [f32; 3],
        /// Lower corner of the grid in `(u, v)`.
        lo: [f32; 2],
        /// Cells per unit of `u` and `v`.
        scale: [f32; 2],
        /// Cells along each axis.
        side: u32,
    },
}

/// The cell of `x` along one axis: `floor((x - lo) * scale)` clamped to `0..n`.
#[inline]
fn cell_f32(x: f32, lo: f32, scale: f32, n: u32) -> u32 {
    ((x - lo) * scale).floor().clamp(0.0, (n - 1) as f32) as u32
}

#[inline]
fn cell_f64(x: f64, lo: f64, scale: f64, n: u32) -> u32 {
    ((x - lo) * scale).floor().clamp(0.0, (n - 1) as f64) as u32
}

/// The axis of the largest of `a` (ties: x, then y), as the GPU scatter picks a cube face.
fn major(a: [f64; 3]) -> usize {
    if a[0] >= a[1] && a[0] >= a[2] {
        0
    } else if a[1] >= a[2] {
        1
    } else {
        2
    }
}

fn f64x3(p: [f32; 3]) -> [f64; 3] {
    p.map(|x| x as f64)
}

impl ReceiverGrid {
    /// The grid of `light` over a scene with bounds `bounds` (used for directional lights: every
    /// sample lies in the box).
    pub fn new(light: Light, bounds: Aabb, side: u32) -> Self {
        assert!(side.is_power_of_two(), "the receiver map's side must be a power of two");
        if light[3] != 0.0 {
            return ReceiverGrid::Cube { light: [light[0], light[1], light[2]], side };
        }
        let t = travel(light);
        // An axis across the light: the coordinate axis least aligned with it, made orthogonal.
        let a = if t[0].abs() <= t[1].abs() && t[0].abs() <= t[2].abs() {
            [1.0, 0.0, 0.0]
        } else if t[1].abs() <= t[2].abs() {
            [0.0, 1.0, 0.0]
        } else {
            [0.0, 0.0, 1.0]
        };
        let k = dot(a, t);
        let u = sub(a, t.map(|x| x * k));
        let n = norm(u);
        let u = u.map(|x| x / n);
        let v = cross(t, u);
        let (u, v, t) = (u.map(|x| x as f32), v.map(|x| x as f32), t.map(|x| x as f32));
        let origin = bounds.center();
        let (mut lo, mut hi) = ([f64::MAX; 2], [f64::MIN; 2]);
        for corner in 0..8 {
            let p = [0, 1, 2].map(|j| if corner & (1 << j) != 0 { bounds.max[j] } else { bounds.min[j] } as f64);
            let rel = sub(p, f64x3(origin));
            let uv = [dot(rel, f64x3(u)), dot(rel, f64x3(v))];
            for j in 0..2 {
                lo[j] = lo[j].min(uv[j]);
                hi[j] = hi[j].max(uv[j]);
            }
        }
        let extent = [0, 1].map(|j| (hi[j] - lo[j]).max(1e-30));
        let scale = [0, 1].map(|j| (side as f64 / extent[j]) as f32);
        ReceiverGrid::Flat { origin, u, v, travel: t, lo: [lo[0] as f32, lo[1] as f32], scale, side }
    }

    /// The larger extent of a directional light's grid across the light (0 for a point
    /// light's cube): the scale of its depths, below which no far end may come.
    pub fn extent(&self) -> f64 {
        match *self {
            ReceiverGrid::Cube { .. } => 0.0,
            ReceiverGrid::Flat { scale, side, .. } => {
                (side as f64 / scale[0] as f64).max(side as f64 / scale[1] as f64)
            }
        }
    }

    /// Cells along a side.
    pub fn side(&self) -> u32 {
        match *self {
            ReceiverGrid::Cube { side, .. } | ReceiverGrid::Flat { side, .. } => side,
        }
    }

    /// Faces: 6 for a point light, 1 for a directional one.
    pub fn faces(&self) -> u32 {
        match self {
            ReceiverGrid::Cube { .. } => 6,
            ReceiverGrid::Flat { .. } => 1,
        }
    }

    /// Cells in all.
    pub fn cells(&self) -> usize {
        (self.faces() * self.side() * self.side()) as usize
    }

    /// The cells the directions (point light) or the across-light coordinates (directional)
    /// of the convex hull of `points` may cover, widened by [`RECEIVER_MARGIN`] of the grid:
    /// `(face, [i0, i1, j0, j1])`; `None` for a point light when the hull's cone does not lie
    /// within one cube face by 4 cells (or reaches the light), so that the samples in it may
    /// lie on another face. The central projection of a hull onto a face is the hull of the
    /// projected points, so the rectangle of the points bounds it.
    pub fn cells_of(&self, points: &[[f64; 3]]) -> Option<(u32, [u32; 4])> {
        match *self {
            ReceiverGrid::Cube { light, side } => {
                let l = f64x3(light);
                let c = points.iter().fold([0.0; 3], |acc, &p| {
                    let d = sub(p, l);
                    [acc[0] + d[0], acc[1] + d[1], acc[2] + d[2]]
                });
                let m = major(c.map(f64::abs));
                let s = if c[m] < 0.0 { -1.0 } else { 1.0 };
                let (mut lo, mut hi) = ([f64::MAX; 2], [f64::MIN; 2]);
                for &p in points {
                    let d = sub(p, l);
                    let den = s * d[m];
                    if den.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
                        return None;
                    }
                    let uv = [d[(m + 1) % 3] / den, d[(m + 2) % 3] / den];
                    for j in 0..2 {
                        lo[j] = lo[j].min(uv[j]);
                        hi[j] = hi[j].max(uv[j]);
                    }
                }
                // Strictly inside the face by 4 cells: every direction of the cone has
                // coordinate m as its largest by far more than a sample's rounding, so the
                // samples in the cone lie on this face.
                let limit = 1.0 - 4.0 / side as f64;
                if lo[0] < -limit || lo[1] < -limit || hi[0] > limit || hi[1] > limit {
                    return None;
                }
                let scale = 0.5 * side as f64;
                let margin = 2.0 * RECEIVER_MARGIN;
                let rect = [
                    cell_f64(lo[0] - margin, -1.0, scale, side),
                    cell_f64(hi[0] + margin, -1.0, scale, side),
                    cell_f64(lo[1] - margin, -1.0, scale, side),
                    cell_f64(hi[1] + margin, -1.0, scale, side),
                ];
                Some((2 * m as u32 + u32::from(s < 0.0), rect))
            }
            ReceiverGrid::Flat { origin, u, v, lo: glo, scale, side, .. } => {
                let o = f64x3(origin);
                let (u, v) = (f64x3(u), f64x3(v));
                let (mut lo, mut hi) = ([f64::MAX; 2], [f64::MIN; 2]);
                for &p in points {
                    let rel = sub(p, o);
                    let uv = [dot(rel, u), dot(rel, v)];
                    for j in 0..2 {
                        lo[j] = lo[j].min(uv[j]);
                        hi[j] = hi[j].max(uv[j]);
                    }
                }
                let glo = [glo[0] as f64, glo[1] as f64];
                let scale = [scale[0] as f64, scale[1] as f64];
                let extent = [0, 1].map(|j| side as f64 / scale[j]);
                let margin = [0, 1].map(|j| (2.0 * extent[j] + 2.0 * glo[j].abs()) * RECEIVER_MARGIN);
                let rect = [
                    cell_f64(lo[0] - margin[0], glo[0], scale[0], side),
                    cell_f64(hi[0] + margin[0], glo[0], scale[0], side),
                    cell_f64(lo[1] - margin[1], glo[1], scale[1], side),
                    cell_f64(hi[1] + margin[1], glo[1], scale[1], side),
                ];
                Some((0, rect))
            }
        }
    }

    /// What [`ReceiverMap::raise_hull`] raises for the convex hull of `points`: the face, its
    /// cell rectangle ([`ReceiverGrid::cells_of`]) and the value every cell there must reach
    /// (the farthest point's, rounded up as a sample's twice over, then up to f32); `None`
    /// when the grid cannot bound the hull. Hosts that build the map on the GPU raise these
    /// cells there.
    pub fn hull_raise(&self, points: &[[f64; 3]]) -> Option<(u32, [u32; 4], f32)> {
        let (face, rect) = self.cells_of(points)?;
        // The farthest point's value, rounded up as a sample's (twice over).
        let value = match *self {
            ReceiverGrid::Cube { light, .. } => {
                let l = f64x3(light);
                let far = points.iter().map(|&p| norm(sub(p, l))).fold(0.0, f64::max);
                far * (1.0 + 2.0 * RECEIVER_ROUND_UP as f64)
            }
            ReceiverGrid::Flat { origin, travel, .. } => {
                let (o, t) = (f64x3(origin), f64x3(travel));
                let far = points.iter().map(|&p| dot(sub(p, o), t)).fold(f64::MIN, f64::max);
                let magnitude =
                    points.iter().map(|&p| sub(p, o).iter().map(|x| x.abs()).sum::<f64>()).fold(0.0, f64::max);
                far + 2.0 * magnitude * RECEIVER_ROUND_UP as f64
            }
        };
        if !value.is_finite() {
            return None;
        }
        let mut value32 = value as f32;
        if (value32 as f64) < value {
            value32 = value32.next_up();
        }
        Some((face, rect, value32))
    }

    /// The cell and the value of a visible sample at `p`, in f32, the very expressions of the
    /// GPU scatter: `None` for a sample at a point light (lit by it).
    pub fn sample_cell(&self, p: [f32; 3]) -> Option<(usize, f32)> {
        match *self {
            ReceiverGrid::Cube { light, side } => {
                let rel = [p[0] - light[0], p[1] - light[1], p[2] - light[2]];
                let a = rel.map(f32::abs);
                if (a[0] + a[1] + a[2]).partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
                    return None;
                }
                let m = if a[0] >= a[1] && a[0] >= a[2] {
                    0
                } else if a[1] >= a[2] {
                    1
                } else {
                    2
                };
                let face = 2 * m as u32 + u32::from(rel[m] < 0.0);
                let uv = [rel[(m + 1) % 3] / a[m], rel[(m + 2) % 3] / a[m]];
                let scale = 0.5 * side as f32;
                let ci = cell_f32(uv[0], -1.0, scale, side);
                let cj = cell_f32(uv[1], -1.0, scale, side);
                let length = (rel[0] * rel[0] + rel[1] * rel[1] + rel[2] * rel[2]).sqrt();
                Some((((face * side + cj) * side + ci) as usize, length * (1.0 + RECEIVER_ROUND_UP)))
            }
            ReceiverGrid::Flat { origin, u, v, travel, lo, scale, side } => {
                let rel = [p[0] - origin[0], p[1] - origin[1], p[2] - origin[2]];
                let d = |a: [f32; 3]| rel[0] * a[0] + rel[1] * a[1] + rel[2] * a[2];
                let ci = cell_f32(d(u), lo[0], scale[0], side);
                let cj = cell_f32(d(v), lo[1], scale[1], side);
                let magnitude = rel[0].abs() + rel[1].abs() + rel[2].abs();
                Some(((cj * side + ci) as usize, d(travel) + magnitude * RECEIVER_ROUND_UP))
            }
        }
    }
}

/// Words of the GPU cull's uniform ([`gpu_cull_words`]).
pub const GPU_CULL_WORDS: usize = 52;

/// Word offset of every level of a GPU max pyramid over a point light's six faces of `side`
/// cells a side (a directional light's one face uses face 0 of each level), then the words
/// of the whole pyramid: `log2(side) + 2` numbers.
pub fn gpu_cull_level_offsets(side: u32) -> Vec<u32> {
    let levels = side.trailing_zeros() + 1;
    let mut offsets = vec![0];
    for k in 0..levels {
        let s = side >> k;
        offsets.push(offsets[k as usize] + 6 * s * s);
    }
    offsets
}

/// The uniform of the GPU cull (`CullGrid` of umbra-wgpu's shaders/cull.wgsl, std140, 208
/// bytes), for `grid` and, under z-pass, the near pyramid's cells to raise
/// ([`ReceiverGrid::hull_raise`]): one layout for umbra-wgpu and for the page's WebGPU path
/// (umbra-wasm), so that neither writes it by hand. Words: origin, u, v, travel (xyz, 0),
/// lo and scale, the rectangle's widening along u and v (twice [`ReceiverGrid::cells_of`]'s,
/// f32 bits), the raised rectangle, its face and encoded value, side, faces, the coarsest
/// level's number, 3 of padding, and 16 level offsets ([`gpu_cull_level_offsets`]). The
/// side must be at most 2^15 (16 levels).
pub fn gpu_cull_words(grid: &ReceiverGrid, raise: Option<(u32, [u32; 4], f32)>) -> [u32; GPU_CULL_WORDS] {
    let mut w = [0u32; GPU_CULL_WORDS];
    let mut put = |at: usize, v: &[f32]| {
        for (k, x) in v.iter().enumerate() {
            w[at + k] = x.to_bits();
        }
    };
    if let ReceiverGrid::Flat { origin, u, v, travel, lo, scale, side } = *grid {
        put(0, &origin);
        put(4, &u);
        put(8, &v);
        put(12, &travel);
        put(16, &[lo[0], lo[1], scale[0], scale[1]]);
        let margin = |j: usize| {
            let extent = f64::from(side) / f64::from(scale[j]);
            ((4.0 * extent + 4.0 * f64::from(lo[j]).abs()) * RECEIVER_MARGIN) as f32
        };
        put(20, &[margin(0), margin(1)]);
    }
    if let Some((face, rect, value)) = raise {
        w[24..28].copy_from_slice(&rect);
        w[28] = face;
        w[29] = encode(value);
    }
    let side = grid.side();
    w[30] = side;
    w[31] = grid.faces();
    w[32] = side.trailing_zeros();
    let offsets = gpu_cull_level_offsets(side);
    for (k, &o) in offsets.iter().take(16).enumerate() {
        w[36 + k] = o;
    }
    w
}

/// Order-preserving f32 -> u32 (a larger float gives a larger word; 0 is below every float):
/// the GPU scatter's atomicMax works on these words.
pub fn encode(x: f32) -> u32 {
    let u = x.to_bits();
    if u & 0x8000_0000 != 0 {
        !u
    } else {
        u | 0x8000_0000
    }
}

/// The inverse of [`encode`]; the empty word 0 decodes to `None`.
pub fn decode(e: u32) -> Option<f32> {
    if e == 0 {
        None
    } else if e & 0x8000_0000 != 0 {
        Some(f32::from_bits(e & 0x7FFF_FFFF))
    } else {
        Some(f32::from_bits(!e))
    }
}

/// A filled receiver map: per cell the largest sample value (`-inf` where no sample lies),
/// with a max pyramid per face so that a large cone reads a few coarse cells.
#[derive(Clone, Debug)]
pub struct ReceiverMap {
    grid: ReceiverGrid,
    /// Level 0 (the cells), then each coarser level (side halved), all faces of a level
    /// together, face-major.
    levels: Vec<Vec<f32>>,
}

/// What [`ReceiverMap::cull_and_clamp`] did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CullStats {
    /// Triangles whose volume is drawn.
    pub kept: usize,
    /// Kept triangles whose far ends are at infinity (no finite clamp was possible).
    pub unclamped: usize,
}

impl ReceiverMap {
    /// The map of `grid` from the GPU scatter's encoded words ([`encode`], 0 empty), one per
    /// cell. `None` when `words` has not [`ReceiverGrid::cells`] entries.
    pub fn from_encoded(grid: ReceiverGrid, words: &[u32]) -> Option<Self> {
        if words.len() != grid.cells() {
            return None;
        }
        let cells = words.iter().map(|&w| decode(w).unwrap_or(f32::NEG_INFINITY)).collect();
        Some(Self::from_cells(grid, cells))
    }

    /// The map of `grid` from samples at `points`, scattered on the CPU with the GPU's
    /// expressions (tests, and hosts without a GPU scatter).
    pub fn from_samples(grid: ReceiverGrid, points: impl IntoIterator<Item = [f32; 3]>) -> Self {
        let mut cells = vec![f32::NEG_INFINITY; grid.cells()];
        for p in points {
            if let Some((c, value)) = grid.sample_cell(p) {
                cells[c] = cells[c].max(value);
            }
        }
        Self::from_cells(grid, cells)
    }

    fn from_cells(grid: ReceiverGrid, cells: Vec<f32>) -> Self {
        let faces = grid.faces() as usize;
        let mut levels = vec![cells];
        let mut side = grid.side() as usize;
        while side > 1 {
            let half = side / 2;
            let prev = levels.last().expect("level 0 exists");
            let mut next = vec![f32::NEG_INFINITY; faces * half * half];
            for f in 0..faces {
                for j in 0..half {
                    for i in 0..half {
                        let at = |ii: usize, jj: usize| prev[(f * side + jj) * side + ii];
                        next[(f * half + j) * half + i] = at(2 * i, 2 * j)
                            .max(at(2 * i + 1, 2 * j))
                            .max(at(2 * i, 2 * j + 1))
                            .max(at(2 * i + 1, 2 * j + 1));
                    }
                }
            }
            levels.push(next);
            side = half;
        }
        Self { grid, levels }
    }

    /// The grid.
    pub fn grid(&self) -> &ReceiverGrid {
        &self.grid
    }

    /// The largest value in the cells `i0..=i1` x `j0..=j1` of `face`, read from the finest
    /// level at which the rectangle spans at most 4 x 4 cells (a coarser cell's value bounds
    /// its finer cells'); `-inf` when no sample lies there.
    fn max_over(&self, face: u32, [i0, i1, j0, j1]: [u32; 4]) -> f32 {
        let mut level = 0;
        while (i1 >> level) - (i0 >> level) >= 4 || (j1 >> level) - (j0 >> level) >= 4 {
            level += 1;
        }
        let side = (self.grid.side() >> level) as usize;
        let cells = &self.levels[level];
        let base = face as usize * side * side;
        let mut r = f32::NEG_INFINITY;
        for j in (j0 >> level)..=(j1 >> level) {
            for i in (i0 >> level)..=(i1 >> level) {
                r = r.max(cells[base + j as usize * side + i as usize]);
            }
        }
        r
    }

    /// Raises every cell that the convex hull of `points` may cover to at least the farthest
    /// of them, so that every point of the hull keeps the count it has in the unclamped
    /// volumes (z-pass starts counting at the eye's near rectangle, [`ReceiverMap::cull_and_clamp`]
    /// must not change the count there). `false` when the map cannot bound the hull (a point
    /// light's cone of it across cube faces, or the light inside it): then nothing may be
    /// clamped for this light.
    pub fn raise_hull(&mut self, points: &[[f64; 3]]) -> bool {
        let Some((face, [i0, i1, j0, j1], value32)) = self.grid.hull_raise(points) else { return false };
        // Raised through every level of the pyramid.
        for (level, cells) in self.levels.iter_mut().enumerate() {
            let side = (self.grid.side() >> level) as usize;
            let base = face as usize * side * side;
            for j in (j0 >> level)..=(j1 >> level) {
                for i in (i0 >> level)..=(i1 >> level) {
                    let c = &mut cells[base + j as usize * side + i as usize];
                    *c = c.max(value32);
                }
            }
        }
        true
    }

    /// Whether triangle `q` may shadow a visible sample, and if so the bound `R` on the value
    /// (distance or depth) of every visible sample in its frustum and the triangle's least
    /// value `least`: `Some((R, least))`. A point light's cone that does not lie within one
    /// cube face (by 4 cells) is bounded by the largest value of the whole map.
    fn bound(&self, q: [[f64; 3]; 3]) -> Option<(f64, f64)> {
        let least = match self.grid {
            ReceiverGrid::Cube { light, .. } => distance_to_triangle(f64x3(light), q),
            ReceiverGrid::Flat { origin, travel, .. } => {
                let (o, t) = (f64x3(origin), f64x3(travel));
                q.iter().map(|&p| dot(sub(p, o), t)).fold(f64::MAX, f64::min)
            }
        };
        let r = match self.grid.cells_of(&q) {
            Some((face, rect)) => self.max_over(face, rect),
            None => self
                .levels
                .last()
                .map_or(f32::NEG_INFINITY, |top| top.iter().copied().fold(f32::NEG_INFINITY, f32::max)),
        } as f64;
        (r > least).then_some((r, least))
    }

    /// The far end of triangle `q` as if a sample lay at its own farthest point: a short
    /// volume for a triangle kept although no sample needs it.
    fn own_end(&self, q: [[f64; 3]; 3], point: bool) -> f32 {
        match self.grid {
            ReceiverGrid::Cube { light, .. } => {
                let l = f64x3(light);
                let far = q.iter().map(|&p| norm(sub(p, l))).fold(0.0, f64::max);
                far_end(far, distance_to_triangle(l, q), point, 0.0)
            }
            ReceiverGrid::Flat { origin, travel, .. } => {
                let (o, t) = (f64x3(origin), f64x3(travel));
                let depths = q.map(|p| dot(sub(p, o), t));
                let lo = depths.iter().copied().fold(f64::MAX, f64::min);
                let hi = depths.iter().copied().fold(f64::MIN, f64::max);
                far_end(hi, lo, point, self.grid.extent())
            }
        }
    }

    /// Which triangles of `mesh` may shadow a visible sample, and every vertex's far end
    /// ([`VolumeClamp`]), into `out` (its allocations reused). `mesh` must be the scene the
    /// samples were taken from, lit by the light of this map's grid (`light`). With
    /// `regions` (the mesh's adjacency and slots), the kept set is widened to whole regions
    /// of one orientation ([`keep_whole_regions`]), and a triangle kept only for that gets the
    /// far ends of a sample at its own farthest point.
    pub fn cull_and_clamp(
        &self,
        mesh: &WeldedMesh,
        light: Light,
        regions: Option<(&EdgeAdjacency, &TriangleSlots)>,
        out: &mut VolumeClamp,
    ) -> CullStats {
        let point = light[3] != 0.0;
        out.light = light;
        out.travel = travel(light);
        let n = mesh.triangles.len();
        // Per triangle: its far end (0 dropped, inf unclamped), in parallel.
        let mut ends = std::mem::take(&mut out.far);
        ends.clear();
        ends.resize(n, 0.0);
        ends.par_iter_mut().zip(mesh.triangles.par_iter()).for_each(|(end, tri)| {
            let q = tri.map(|i| f64x3(mesh.positions[i as usize]));
            *end = match self.bound(q) {
                None => 0.0,
                Some((r, least)) => far_end(r, least, point, self.grid.extent()),
            };
        });
        out.keep.clear();
        out.keep.extend(ends.iter().map(|&e| e > 0.0));
        if let Some((adj, slots)) = regions {
            if keep_whole_regions(mesh, adj, slots, light, &mut out.keep) > 0 {
                for ((end, &k), tri) in ends.iter_mut().zip(&out.keep).zip(&mesh.triangles) {
                    if k && *end == 0.0 {
                        // No visible sample lies in its frustum: any far end beyond the
                        // triangle encloses them all; the one of a sample at its farthest point.
                        let q = tri.map(|i| f64x3(mesh.positions[i as usize]));
                        *end = self.own_end(q, point);
                    }
                }
            }
        }
        let mut stats = CullStats::default();
        let mut far = vec![0.0f32; mesh.positions.len()];
        for (tri, &e) in mesh.triangles.iter().zip(&ends) {
            if e > 0.0 {
                stats.kept += 1;
                stats.unclamped += usize::from(e == f32::INFINITY);
                for &i in tri {
                    let f = &mut far[i as usize];
                    *f = f.max(e);
                }
            }
        }
        out.far = far;
        stats
    }
}

/// Why [`clamp_beyond_box`] cannot close a volume at a finite distance.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct FiniteClampError(pub String);

/// Every triangle's volume closed beyond the whole box `bounds` (the orthographic camera's
/// finite volumes, docs/exactness.md "Orthographic views"): into `out`, every triangle of
/// `mesh` that can cast kept, every vertex's far end FINITE and beyond every point of
/// `bounds` inside the triangle's frustum. The bound is [`ReceiverMap::cull_and_clamp`]'s
/// with the box's farthest corner as `R` (distance from a point light, depth along a
/// directional light's travel): `k_v > R / d_t` for every triangle at `v`. A triangle that
/// touches the point light (`d_t = 0`) has the light in its plane: its frustum is empty and
/// it is dropped (orientation 0, as an edge-on triangle). `bounds` must hold every position of
/// `mesh` and every sample. Fails when a far end does not fit in an f32.
pub fn clamp_beyond_box(
    mesh: &WeldedMesh,
    light: Light,
    bounds: Aabb,
    out: &mut VolumeClamp,
) -> Result<CullStats, FiniteClampError> {
    let point = light[3] != 0.0;
    out.light = light;
    out.travel = travel(light);
    let corners: Vec<[f64; 3]> = (0..8)
        .map(|c: usize| [0, 1, 2].map(|k| f64::from(if c >> k & 1 == 0 { bounds.min[k] } else { bounds.max[k] })))
        .collect();
    let lo = f64x3(bounds.min);
    let extent = norm(sub(f64x3(bounds.max), lo));
    let l = [0, 1, 2].map(|k| f64::from(light[k]) / if point { f64::from(light[3]) } else { 1.0 });
    let t = out.travel;
    // Distance from the light (point) or depth along the travel from the box's min corner.
    let value = |p: [f64; 3]| if point { norm(sub(p, l)) } else { dot(sub(p, lo), t) };
    let r = corners.iter().map(|&c| value(c)).fold(f64::MIN, f64::max);
    let n = mesh.triangles.len();
    let mut ends = vec![0.0f32; n];
    ends.par_iter_mut().zip(mesh.triangles.par_iter()).for_each(|(end, tri)| {
        let q = tri.map(|i| f64x3(mesh.positions[i as usize]));
        let least =
            if point { distance_to_triangle(l, q) } else { q.iter().map(|&p| value(p)).fold(f64::MAX, f64::min) };
        *end = if point && (least.is_nan() || least <= 0.0) { 0.0 } else { finite_far_end(r, least, point, extent) };
    });
    if let Some(i) = ends.iter().position(|e| !e.is_finite()) {
        return Err(FiniteClampError(format!(
            "triangle {i}'s shadow volume cannot be closed at a finite distance (f32) beyond the scene: \
             it lies too close to the light for an orthographic view"
        )));
    }
    out.keep.clear();
    out.keep.extend(ends.iter().map(|&e| e > 0.0));
    let mut far = vec![0.0f32; mesh.positions.len()];
    let mut stats = CullStats::default();
    for (tri, &e) in mesh.triangles.iter().zip(&ends) {
        if e > 0.0 {
            stats.kept += 1;
            for &i in tri {
                let f = &mut far[i as usize];
                *f = f.max(e);
            }
        }
    }
    out.far = far;
    Ok(stats)
}

/// [`far_end`] without its [`CLAMP_LIMIT`]: a finite far end whenever one fits in an f32.
fn finite_far_end(r: f64, least: f64, point: bool, extent: f64) -> f32 {
    let k = if point {
        r / least * (1.0 + CLAMP_MARGIN)
    } else {
        (r - least) + CLAMP_MARGIN * ((r - least).abs() + r.abs() + least.abs() + extent)
    };
    let f = k as f32;
    if (f as f64) < k {
        f.next_up()
    } else {
        f
    }
}

/// The far end (scale or distance, [`VolumeClamp::far`]) that encloses every sample of a
/// triangle's frustum nearer than `r` (distance or depth) when the triangle's least value is
/// `least`: `(r / least)(1 + CLAMP_MARGIN)` (point) or `(r - least)` plus the margin of the
/// magnitudes and of the grid's `extent` (directional: never a far end at the triangle),
/// rounded up to f32, infinity beyond [`CLAMP_LIMIT`].
fn far_end(r: f64, least: f64, point: bool, extent: f64) -> f32 {
    let k = if point {
        if least > 0.0 {
            r / least * (1.0 + CLAMP_MARGIN)
        } else {
            f64::INFINITY
        }
    } else {
        (r - least) + CLAMP_MARGIN * ((r - least).abs() + r.abs() + least.abs() + extent)
    };
    if k.is_finite() && k < CLAMP_LIMIT {
        // Rounded up to f32: never below the bound.
        let f = k as f32;
        if (f as f64) < k {
            f.next_up()
        } else {
            f
        }
    } else {
        f32::INFINITY
    }
}

/// The distance from `p` to the triangle `q` (Ericson, Real-Time Collision Detection, 5.1.5:
/// the closest point by Voronoi regions), in f64.
pub fn distance_to_triangle(p: [f64; 3], [a, b, c]: [[f64; 3]; 3]) -> f64 {
    let at = |base: [f64; 3], dir: [f64; 3], t: f64| [base[0] + dir[0] * t, base[1] + dir[1] * t, base[2] + dir[2] * t];
    let ab = sub(b, a);
    let ac = sub(c, a);
    let ap = sub(p, a);
    let d1 = dot(ab, ap);
    let d2 = dot(ac, ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return norm(ap);
    }
    let bp = sub(p, b);
    let d3 = dot(ab, bp);
    let d4 = dot(ac, bp);
    if d3 >= 0.0 && d4 <= d3 {
        return norm(bp);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return norm(sub(p, at(a, ab, d1 / (d1 - d3))));
    }
    let cp = sub(p, c);
    let d5 = dot(ab, cp);
    let d6 = dot(ac, cp);
    if d6 >= 0.0 && d5 <= d6 {
        return norm(cp);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return norm(sub(p, at(a, ac, d2 / (d2 - d6))));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return norm(sub(p, at(b, sub(c, b), (d4 - d3) / ((d4 - d3) + (d5 - d6)))));
    }
    let denom = 1.0 / (va + vb + vc);
    let (v, w) = (vb * denom, vc * denom);
    norm(sub(p, [a[0] + ab[0] * v + ac[0] * w, a[1] + ab[1] * v + ac[1] * w, a[2] + ab[2] * v + ac[2] * w]))
}

#[cfg(test)]
mod tests;
