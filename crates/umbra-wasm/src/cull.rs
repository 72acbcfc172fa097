//! Shadow volumes only where something receives them, in the page: the receiver map of one
//! light ([`Receivers`], `umbra_geom::receivers`), built from the cells the browser scattered,
//! and per caster the triangles it keeps and where each vertex's volume ends ([`CasterCull`],
//! `umbra_geom::receivers::ReceiverMap::cull_and_clamp`), what the drawer then draws: the
//! silhouette of the kept triangles ([`crate::Silhouette`]), its sides ending at the far
//! vertices, closed by far caps.
//!
//! **Spaces.** The map lives in world space: the page scatters every visible sample's world
//! position (umbra-three's position pass). A caster's silhouette and volumes live in the
//! caster's own space (its geometry is prepared once, drawn with its clip-from-object matrix
//! and the light moved into its space). So the cull runs in world space, on a copy of the
//! caster's welded positions moved by its world matrix `M` (f64, rounded to f32 once; none
//! for the identity), with the world light the map was made for; its far ends are then moved
//! back into the caster's space, where they are drawn:
//!
//! * point light: `v' = L + k_v (v - L)` (umbra_geom's `VolumeClamp::far`). An affine map
//!   keeps it with the same `k_v`: `M^-1 v' = M^-1 L + k_v (M^-1 v - M^-1 L)`, so the far
//!   vertex is `L_o + k_v (v - L_o)` with `v` the object-space vertex and `L_o` the
//!   object-space light the volumes are drawn with;
//! * directional light: `v' = v + K_v d` with `d` the unit world direction of travel; in the
//!   caster's space `v + K_v M^-1 d` (`M^-1`'s linear part, f64);
//! * a far end at infinity: `umbra_geom::silhouette::extrude` with `L_o`, the vertex the
//!   unclamped volume has (001 Eq. 2).
//!
//! Each far vertex is computed once, in f64 and rounded to f32 once, here, and every side and
//! far cap that uses it reads that one value: the clamped volumes close as the infinite ones
//! do (no shader recomputes it, so no compiler contraction can give it two values). The
//! roundings between the two spaces (about 1e-7 relative) lie far below the margins the map
//! and the far ends carry (`RECEIVER_MARGIN`, `RECEIVER_ROUND_UP`, `CLAMP_MARGIN`: proof in
//! `umbra_geom::silhouette`'s `clamp.rs` and docs/exactness.md).
//!
//! **Clamped only where it pays.** A clamped volume's sides end short, but it is closed by far
//! caps, which z-pass must draw and which a volume running to infinity does not have (its dark
//! caps at infinity: z-fail and point lights only). Which costs fewer fragments depends on the
//! view, so, as native umbra (`umbra_geom::silhouette::estimate_fill`, chosen per light),
//! [`CasterCull::choose_clamp`] sums the screen area of both variants of the caster's volume
//! (its sides and far caps as the drawer clips them: the viewport's four planes; light caps
//! are the same in both and left out) and keeps the cheaper one, per caster. Both give every
//! visible sample the same count (the kept triangles and the cull are the same), so the choice
//! changes the cost only.
//!
//! **Cells.** [`Receivers::build`] takes one f32 per cell, as the page's scatter wrote it: the
//! largest value of the cell's samples (`ReceiverGrid::sample_cell`'s expression) or `-inf`
//! for an empty cell. A NaN cell is taken as unbounded (`+inf`): nothing behind it is culled
//! or clamped.

use umbra_geom::adjacency::EdgeAdjacency;
use umbra_geom::receivers::{encode, gpu_cull_words, CullStats, ReceiverGrid, ReceiverMap, GPU_CULL_WORDS};
use umbra_geom::silhouette::{extrude, TriangleSlots, VolumeClamp};
use umbra_geom::{Aabb, Light, WeldedMesh};

/// Cells along a side of the page's maps: 6 x 128 x 128 cells for a point light, 128 x 128
/// for a directional one (small: the browser reads the map back every frame).
pub const PAGE_RECEIVER_SIDE: u32 = 128;

/// Floats of [`Receivers::params`].
pub const GRID_PARAMS: usize = 24;

/// One light's receiver map (module documentation).
#[derive(Clone, Debug, Default)]
pub struct Receivers {
    light: Light,
    grid: Option<ReceiverGrid>,
    map: Option<ReceiverMap>,
    cells: Vec<f32>,
    params: [f32; GRID_PARAMS],
    gpu_cull: Vec<u32>,
}

fn finite(values: &[f32]) -> bool {
    values.iter().all(|v| v.is_finite())
}

impl Receivers {
    /// An empty set-up, without a grid.
    pub fn new() -> Self {
        Self::default()
    }

    /// The grid of the world-space `light` (w = 0 directional, xyz towards the light) over the
    /// world-space box `bounds` of every sample, `side` cells a side (a power of two, 1 to
    /// 4096); the map of the previous grid is dropped. `false` (and no grid) for a light or box
    /// that is not finite, a directional light without a direction, an empty box or a bad side.
    pub fn set_grid(&mut self, light: Light, bounds: Aabb, side: u32) -> bool {
        self.grid = None;
        self.map = None;
        self.cells.clear();
        self.params = [0.0; GRID_PARAMS];
        let directional = light[3] == 0.0;
        let ok = finite(&light)
            && finite(&bounds.min)
            && finite(&bounds.max)
            && (0..3).all(|i| bounds.min[i] <= bounds.max[i])
            && side.is_power_of_two()
            && side <= 4096
            && !(directional && light[0] == 0.0 && light[1] == 0.0 && light[2] == 0.0);
        if !ok {
            return false;
        }
        let grid = ReceiverGrid::new(light, bounds, side);
        let p = &mut self.params;
        p[1] = side as f32;
        match grid {
            ReceiverGrid::Cube { light, .. } => {
                p[0] = 0.0;
                p[2..5].copy_from_slice(&light);
            }
            ReceiverGrid::Flat { origin, u, v, travel, lo, scale, .. } => {
                p[0] = 1.0;
                p[5..8].copy_from_slice(&origin);
                p[8..11].copy_from_slice(&u);
                p[11..14].copy_from_slice(&v);
                p[14..17].copy_from_slice(&travel);
                p[17..19].copy_from_slice(&lo);
                p[19..21].copy_from_slice(&scale);
            }
        }
        self.light = light;
        self.grid = Some(grid);
        self.cells.resize(grid.cells(), f32::NEG_INFINITY);
        true
    }

    /// The grid's parameters as the page's scatter reads them: `[kind (0 cube, 1 flat), side,
    /// light xyz (cube), origin xyz, u xyz, v xyz, travel xyz, lo uv, scale uv, 0 0 0]`, the
    /// f32 values of `ReceiverGrid` as they are.
    pub fn params(&self) -> &[f32; GRID_PARAMS] {
        &self.params
    }

    /// The grid, when one is set.
    pub fn grid(&self) -> Option<&ReceiverGrid> {
        self.grid.as_ref()
    }

    /// The world-space light of the grid.
    pub fn light(&self) -> Light {
        self.light
    }

    /// The cells the page writes before [`Receivers::build`]: `ReceiverGrid::cells` f32, cell
    /// `(face * side + j) * side + i` (empty without a grid).
    pub fn cells_mut(&mut self) -> &mut [f32] {
        &mut self.cells
    }

    /// Builds the map from the cells (module documentation); `false` without a grid.
    pub fn build(&mut self) -> bool {
        let Some(grid) = self.grid else { return false };
        let words: Vec<u32> = self
            .cells
            .iter()
            .map(|&c| {
                if c.is_nan() {
                    encode(f32::INFINITY)
                } else if c == f32::NEG_INFINITY {
                    0
                } else {
                    encode(c)
                }
            })
            .collect();
        self.map = ReceiverMap::from_encoded(grid, &words);
        self.map.is_some()
    }

    /// Builds the map from the samples themselves, scattered here with
    /// `ReceiverGrid::sample_cell` (the page's position target read back: `x, y, z, w` per pixel,
    /// `w` < 0 where no surface is seen, else the bits of the lights the sample's seen side
    /// clearly faces away from; the samples with bit `light_bit` set are left out, as the GPU
    /// scatter leaves them out). `false` without a grid.
    pub fn build_from_samples(&mut self, samples: &[f32], light_bit: u32) -> bool {
        let Some(grid) = self.grid else { return false };
        let points = samples
            .chunks_exact(4)
            .filter(|s| s[3] >= 0.0 && (s[3] as u32) & light_bit == 0)
            .map(|s| [s[0], s[1], s[2]]);
        self.map = Some(ReceiverMap::from_samples(grid, points));
        true
    }

    /// `ReceiverMap::raise_hull` with world-space `points` (z-pass: the eye's near pyramid);
    /// `false` when the map cannot bound them or there is no map: then nothing may be culled
    /// for this light, and the map is dropped.
    pub fn raise_hull(&mut self, points: &[[f64; 3]]) -> bool {
        let raised = match self.map.as_mut() {
            Some(map) => points.iter().flatten().all(|x| x.is_finite()) && map.raise_hull(points),
            None => false,
        };
        if !raised {
            self.map = None;
        }
        raised
    }

    /// The uniform of the GPU cull for this grid (`umbra_geom::receivers::gpu_cull_words`,
    /// what umbra-three's WebGPU path binds for umbra-wgpu's cull.wgsl), with the cells of
    /// world-space `points` (z-pass: the eye's near pyramid) raised when given; `None` without
    /// a grid, or when the grid cannot bound the points (then this light may not be culled).
    pub fn gpu_cull(&mut self, points: Option<&[[f64; 3]]>) -> Option<&[u32]> {
        let grid = self.grid.as_ref()?;
        let raise = match points {
            Some(p) if p.iter().flatten().all(|x| x.is_finite()) && !p.is_empty() => Some(grid.hull_raise(p)?),
            Some(_) => return None,
            None => None,
        };
        self.gpu_cull = gpu_cull_words(grid, raise).to_vec();
        debug_assert_eq!(self.gpu_cull.len(), GPU_CULL_WORDS);
        Some(&self.gpu_cull)
    }

    /// The built map.
    pub fn map(&self) -> Option<&ReceiverMap> {
        self.map.as_ref()
    }
}

/// A caster's world-space positions for one world matrix.
#[derive(Clone, Debug)]
struct WorldCopy {
    matrix: [f64; 16],
    mesh: WeldedMesh,
}

/// One caster's cull against a light's map (module documentation), and its reused buffers.
#[derive(Clone, Debug, Default)]
pub struct CasterCull {
    slots: Option<TriangleSlots>,
    world: Option<WorldCopy>,
    clamp: VolumeClamp,
    far: Vec<[f32; 4]>,
    stats: CullStats,
}

/// Where a caster's volume is drawn: its clip-from-object matrix (f64 of the f32 the drawer
/// uploads, column-major) and the viewport in pixels; and what a polygon costs.
#[derive(Clone, Copy, Debug)]
pub struct Screen {
    /// Clip space from the caster's space.
    pub clip_from_object: [f64; 16],
    /// Viewport width in pixels.
    pub width: f64,
    /// Viewport height in pixels.
    pub height: f64,
    /// The cost of drawing one polygon (a side or a far cap: the drawer's polygon pass and its
    /// fan's vertices), in pixels of fill.
    pub polygon_pixels: f64,
}

/// Most vertices a clipped quad can have (4 + one per plane).
const MAX_CLIPPED: usize = 8;

impl Screen {
    /// Pixels covered by the polygon `object` (homogeneous, the caster's space) once clipped to
    /// the viewport's four side planes (which also leave out what lies behind the eye), as the
    /// drawer's polygon pass clips it (`umbra_geom::silhouette::ScreenClip::area`'s arithmetic).
    fn area(&self, object: &[[f32; 4]], a: &mut Vec<[f64; 4]>, b: &mut Vec<[f64; 4]>) -> f64 {
        let m = &self.clip_from_object;
        a.clear();
        a.extend(object.iter().map(|v| {
            let v = v.map(f64::from);
            [0, 1, 2, 3].map(|r| m[r] * v[0] + m[4 + r] * v[1] + m[8 + r] * v[2] + m[12 + r] * v[3])
        }));
        for plane in [[-1.0, 0.0, 0.0, 1.0], [1.0, 0.0, 0.0, 1.0], [0.0, -1.0, 0.0, 1.0], [0.0, 1.0, 0.0, 1.0]] {
            b.clear();
            let dot = |v: &[f64; 4]| plane[0] * v[0] + plane[1] * v[1] + plane[2] * v[2] + plane[3] * v[3];
            for i in 0..a.len() {
                let (p, q) = (a[i], a[(i + 1) % a.len()]);
                let (dp, dq) = (dot(&p), dot(&q));
                if dp >= 0.0 {
                    b.push(p);
                }
                if (dp >= 0.0) != (dq >= 0.0) {
                    let t = dp / (dp - dq);
                    b.push([0, 1, 2, 3].map(|k| p[k] + (q[k] - p[k]) * t));
                }
                if b.len() >= MAX_CLIPPED {
                    break;
                }
            }
            std::mem::swap(a, b);
            if a.len() < 3 {
                return 0.0;
            }
        }
        // Only the eye's own point has w = 0 inside the four planes: no area.
        a.retain(|v| v[3] > 0.0);
        if a.len() < 3 {
            return 0.0;
        }
        let mut twice = 0.0;
        for i in 0..a.len() {
            let (p, q) = (a[i], a[(i + 1) % a.len()]);
            twice += (p[0] / p[3]) * (q[1] / q[3]) - (q[0] / q[3]) * (p[1] / p[3]);
        }
        let area = (0.5 * twice).abs() * 0.25 * self.width * self.height;
        if area.is_finite() {
            area
        } else {
            0.0
        }
    }
}

const IDENTITY: [f64; 16] = [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0];

/// `m` (column-major) applied to the point `p` (affine: the last row is not read).
fn transform(m: &[f64; 16], p: [f64; 3]) -> [f64; 3] {
    [0, 1, 2].map(|r| m[r] * p[0] + m[4 + r] * p[1] + m[8 + r] * p[2] + m[12 + r])
}

/// Whether `m` is affine (last row 0 0 0 1) and finite.
fn affine(m: &[f64; 16]) -> bool {
    m.iter().all(|x| x.is_finite()) && m[3] == 0.0 && m[7] == 0.0 && m[11] == 0.0 && m[15] == 1.0
}

impl CasterCull {
    /// Culls and clamps the caster `mesh` (its own space, with `adjacency`) against `receivers`'
    /// map: `world_from_object` and `object_from_world` its world matrix and that matrix's
    /// inverse (column-major f64, affine), `light_object` the light in its space as its volumes
    /// are drawn. Returns the kept flags (one per triangle) for the silhouette, or `None` when
    /// there is no map or the matrices are not affine and finite (then the caster is drawn
    /// unculled).
    pub fn cull(
        &mut self,
        mesh: &WeldedMesh,
        adjacency: &EdgeAdjacency,
        receivers: &Receivers,
        world_from_object: &[f64; 16],
        object_from_world: &[f64; 16],
        light_object: Light,
    ) -> Option<&[bool]> {
        let map = receivers.map()?;
        if !affine(world_from_object) || !affine(object_from_world) || !finite(&light_object) {
            return None;
        }
        if self.slots.is_none() {
            // The adjacency is the mesh's own: building its slots cannot fail; if it did, the
            // cull goes on without whole regions (keeping fewer triangles is still exact).
            self.slots = TriangleSlots::build(mesh, adjacency).ok();
        }
        let identity = self.update_world(mesh, world_from_object);
        let culled = match (&self.world, identity) {
            (Some(w), false) => &w.mesh,
            _ => mesh,
        };
        let light = receivers.light();
        let regions = self.slots.as_ref().map(|s| (adjacency, s));
        self.stats = map.cull_and_clamp(culled, light, regions, &mut self.clamp);
        self.far_vertices(mesh, object_from_world, light, light_object);
        Some(&self.clamp.keep)
    }

    /// Closes every volume of the caster `mesh` beyond the world box `bounds`, for an
    /// orthographic view ([`umbra_geom::receivers::clamp_beyond_box`], docs/exactness.md
    /// "Orthographic views": no far end at infinity, every far end finite and beyond every
    /// point of `bounds` in its triangle's frustum). `world_from_object`, `object_from_world`
    /// and `light_object` as for [`CasterCull::cull`]; `light_world` the world light the box
    /// test runs with (`light_object` moved into world space). `bounds` must hold every
    /// visible sample and every position of the caster in world space. Returns the kept flags
    /// (every triangle that can cast; a triangle the point light lies in the plane of is
    /// dropped), `Ok(None)` when the matrices are not affine and finite or a light is not
    /// finite, or the error of a far end that does not fit in an f32. The far vertices
    /// ([`CasterCull::far`]) are then all finite (w = 1) where kept.
    pub fn clamp_beyond_box(
        &mut self,
        mesh: &WeldedMesh,
        world_from_object: &[f64; 16],
        object_from_world: &[f64; 16],
        bounds: Aabb,
        light_world: Light,
        light_object: Light,
    ) -> Result<Option<&[bool]>, umbra_geom::receivers::FiniteClampError> {
        if !affine(world_from_object) || !affine(object_from_world) || !finite(&light_object) || !finite(&light_world) {
            return Ok(None);
        }
        let identity = self.update_world(mesh, world_from_object);
        let world = match (&self.world, identity) {
            (Some(w), false) => &w.mesh,
            _ => mesh,
        };
        self.stats = umbra_geom::receivers::clamp_beyond_box(world, light_world, bounds, &mut self.clamp)?;
        self.far_vertices(mesh, object_from_world, light_world, light_object);
        Ok(Some(&self.clamp.keep))
    }

    /// Keeps the world copy of `mesh` for `world_from_object` (made when the matrix changed);
    /// returns whether the matrix is the identity (no copy: the world mesh is `mesh`).
    fn update_world(&mut self, mesh: &WeldedMesh, world_from_object: &[f64; 16]) -> bool {
        let identity = *world_from_object == IDENTITY;
        if !identity && self.world.as_ref().is_none_or(|w| w.matrix != *world_from_object) {
            let positions = mesh
                .positions
                .iter()
                .map(|p| transform(world_from_object, p.map(f64::from)).map(|x| x as f32))
                .collect();
            let world = WeldedMesh { positions, ..mesh.clone() };
            self.world = Some(WorldCopy { matrix: *world_from_object, mesh: world });
        }
        identity
    }

    /// The far vertices of the last clamp (`self.clamp`, made with the world light `light`),
    /// in the caster's space: module documentation.
    fn far_vertices(&mut self, mesh: &WeldedMesh, object_from_world: &[f64; 16], light: Light, light_object: Light) {
        let lo = light_object.map(f64::from);
        let t = self.clamp.travel;
        let m = object_from_world;
        let travel = [0, 1, 2].map(|r| m[r] * t[0] + m[4 + r] * t[1] + m[8 + r] * t[2]);
        let point = light[3] != 0.0;
        self.far.clear();
        self.far.extend(mesh.positions.iter().zip(&self.clamp.far).map(|(&p, &k)| {
            if k == 0.0 {
                // A vertex of no kept triangle: never drawn.
                [0.0; 4]
            } else if !k.is_finite() {
                extrude(p, light_object)
            } else {
                let (v, k) = (p.map(f64::from), f64::from(k));
                let c = if point {
                    [0, 1, 2].map(|j| (lo[j] + k * (v[j] - lo[j])) as f32)
                } else {
                    [0, 1, 2].map(|j| (v[j] + k * travel[j]) as f32)
                };
                [c[0], c[1], c[2], 1.0]
            }
        }));
    }

    /// Keeps the clamp of the last [`CasterCull::cull`] where its volume costs less on `screen`
    /// (pixels covered, plus `polygon_pixels` per polygon) than the same kept triangles' volume
    /// running to infinity, else moves every far vertex to infinity (module documentation);
    /// returns whether it stays clamped.
    /// `silhouette`: computed with the cull's kept flags; `record_vertices`: the welded `A, B`
    /// of every edge record; `light_object`: the light as the volumes are drawn; `caps`: z-fail
    /// (a point light's unclamped volume then draws its dark caps at infinity).
    pub fn choose_clamp(
        &mut self,
        silhouette: &crate::Silhouette,
        record_vertices: &[u32],
        light_object: Light,
        screen: &Screen,
        caps: bool,
    ) -> bool {
        let positions = silhouette.positions();
        let point = light_object[3] != 0.0;
        let (mut a, mut b) = (Vec::with_capacity(MAX_CLIPPED), Vec::with_capacity(MAX_CLIPPED));
        let at = |i: u32| {
            let p = positions[i as usize];
            [p[0], p[1], p[2], 1.0]
        };
        let infinity = |i: u32| extrude(positions[i as usize], light_object);
        let (mut clamped, mut unclamped) = (0.0f64, 0.0f64);
        let mut far_caps = 0usize;
        for &r in silhouette.records() {
            let r = r as usize;
            let (ia, ib) = (record_vertices[2 * r], record_vertices[2 * r + 1]);
            let m = f64::from(silhouette.multiplicity(r).unsigned_abs());
            let far = |i: u32| self.far[i as usize];
            clamped += m * screen.area(&[at(ib), at(ia), far(ia), far(ib)], &mut a, &mut b);
            unclamped += m * screen.area(&[at(ib), at(ia), infinity(ia), infinity(ib)], &mut a, &mut b);
        }
        let infinite_caps = caps && point;
        let triangles = silhouette.triangle_vertices();
        for &t in silhouette.kept_triangles() {
            let [i0, i1, i2] = triangles[t as usize];
            let cap = [self.far[i0 as usize], self.far[i2 as usize], self.far[i1 as usize]];
            if infinite_caps || cap.iter().any(|v| v[3] != 0.0) {
                clamped += screen.area(&cap, &mut a, &mut b);
                far_caps += 1;
            }
            if infinite_caps {
                unclamped += screen.area(&[infinity(i0), infinity(i2), infinity(i1)], &mut a, &mut b);
            }
        }
        // The sides are as many either way; the clamp adds its far caps, less the dark caps a
        // point light's unclamped volume draws under z-fail.
        let dark_caps = if infinite_caps { silhouette.kept_triangles().len() } else { 0 };
        clamped += screen.polygon_pixels * far_caps as f64;
        unclamped += screen.polygon_pixels * dark_caps as f64;
        if clamped < unclamped {
            return true;
        }
        for (f, &p) in self.far.iter_mut().zip(positions) {
            if *f != [0.0; 4] {
                *f = extrude(p, light_object);
            }
        }
        false
    }

    /// The far vertex of every welded vertex of the last [`CasterCull::cull`] (homogeneous,
    /// the caster's space; `w = 0` at infinity, all zero for a vertex of no kept triangle).
    pub fn far(&self) -> &[[f32; 4]] {
        &self.far
    }

    /// What the last [`CasterCull::cull`] kept.
    pub fn stats(&self) -> CullStats {
        self.stats
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{prepare_welded, Silhouette};
    use umbra_geom::silhouette::{extract_clamped, extract_indexed, IndexedVolume};

    /// A unit square at y = 1 over a floor at y = 0 (10 x 10), both one mesh.
    fn scene() -> (WeldedMesh, EdgeAdjacency, crate::Prepared) {
        let p = [
            -5.0, 0.0, -5.0, 5.0, 0.0, -5.0, 5.0, 0.0, 5.0, -5.0, 0.0, 5.0, // floor
            0.0, 1.0, 0.0, 1.0, 1.0, 0.0, 1.0, 1.0, 1.0, 0.0, 1.0, 1.0, // square
        ];
        let index = [0, 2, 1, 0, 3, 2, 4, 6, 5, 4, 7, 6];
        let (prepared, welded) = prepare_welded("scene", &p, Some(&index)).expect("scene");
        let adj = EdgeAdjacency::build(&welded);
        (welded, adj, prepared)
    }

    fn bounds(mesh: &WeldedMesh) -> Aabb {
        let mut b = Aabb { min: [f32::MAX; 3], max: [f32::MIN; 3] };
        for p in &mesh.positions {
            b.min = [0, 1, 2].map(|i| b.min[i].min(p[i]));
            b.max = [0, 1, 2].map(|i| b.max[i].max(p[i]));
        }
        b
    }

    /// The receivers of samples at `points`, scattered as the page does (one f32 per cell).
    fn receivers_of(light: Light, b: Aabb, points: &[[f32; 3]]) -> Receivers {
        let mut r = Receivers::new();
        assert!(r.set_grid(light, b, PAGE_RECEIVER_SIDE));
        let grid = *r.grid().expect("grid");
        for &p in points {
            if let Some((c, v)) = grid.sample_cell(p) {
                let cell = &mut r.cells_mut()[c];
                *cell = cell.max(v);
            }
        }
        assert!(r.build());
        r
    }

    /// The map built from the read-back samples equals the one of the cells scattered one by
    /// one; samples without a surface or facing away from the light are left out.
    #[test]
    fn samples_build_the_map_the_scatter_builds() {
        let (mesh, adj, _) = scene();
        let b = bounds(&mesh);
        let light = [0.5, 4.0, 0.5, 1.0];
        let under = [[0.5, 0.0, 0.5], [0.2, 0.0, 0.7], [4.5, 0.0, -4.5]];
        let scattered = receivers_of(light, b, &under);
        let mut samples: Vec<f32> = under.iter().flat_map(|p| [p[0], p[1], p[2], 0.0]).collect();
        // No surface; a sample facing away from light 0 (bit 1), farther than every other one
        // (it would move the floor's far ends).
        samples.extend([9.0, 9.0, 9.0, -1.0, -5.0, 0.0, 5.0, 1.0]);
        let mut r = Receivers::new();
        assert!(!r.build_from_samples(&samples, 1), "no grid");
        assert!(r.set_grid(light, b, PAGE_RECEIVER_SIDE));
        assert!(r.build_from_samples(&samples, 1));
        let mut a = CasterCull::default();
        let mut c = CasterCull::default();
        let ka = a.cull(&mesh, &adj, &r, &IDENTITY, &IDENTITY, light).expect("culled").to_vec();
        let kc = c.cull(&mesh, &adj, &scattered, &IDENTITY, &IDENTITY, light).expect("culled").to_vec();
        assert_eq!(ka, kc);
        assert_eq!(a.far(), c.far());
    }

    #[test]
    fn bad_grids_are_refused() {
        let b = Aabb { min: [0.0; 3], max: [1.0; 3] };
        let mut r = Receivers::new();
        assert!(!r.set_grid([0.0, 0.0, 0.0, 0.0], b, 128), "no direction");
        assert!(!r.set_grid([f32::NAN, 0.0, 0.0, 1.0], b, 128));
        assert!(!r.set_grid([0.0, 2.0, 0.0, 1.0], b, 100), "not a power of two");
        assert!(!r.set_grid([0.0, 2.0, 0.0, 1.0], Aabb { min: [1.0; 3], max: [0.0; 3] }, 128));
        assert!(!r.build(), "no grid, no map");
        assert!(r.set_grid([0.0, 2.0, 0.0, 1.0], b, 128));
        assert_eq!(r.cells_mut().len(), 6 * 128 * 128);
        assert_eq!(r.params()[..5], [0.0, 128.0, 0.0, 2.0, 0.0]);
        assert!(r.set_grid([0.3, 1.0, 0.2, 0.0], b, 64));
        assert_eq!(r.cells_mut().len(), 64 * 64);
        assert_eq!(r.params()[..2], [1.0, 64.0]);
    }

    /// Samples only on the floor far from the square's shadow: the square's triangles are
    /// dropped; samples in its shadow keep them, clamped just past the floor; the far vertices
    /// in the caster's space equal `VolumeClamp::far_vertex` for the identity, and are moved
    /// with the caster for a translated one.
    #[test]
    fn cull_keeps_the_triangles_whose_shadow_is_seen_and_clamps_them() {
        let (mesh, adj, p) = scene();
        let b = bounds(&mesh);
        let light = [0.5, 4.0, 0.5, 1.0];
        let far_corner = [[4.5, 0.0, -4.5]];
        let mut cull = CasterCull::default();
        let r = receivers_of(light, b, &far_corner);
        let keep = cull.cull(&mesh, &adj, &r, &IDENTITY, &IDENTITY, light).expect("culled").to_vec();
        // The square (triangles 2, 3) shadows nothing seen; the floor is kept or not, the
        // square is dropped.
        assert!(!keep[2] && !keep[3], "{keep:?}");
        let under = [[0.5, 0.0, 0.5], [0.2, 0.0, 0.7], [4.5, 0.0, -4.5]];
        let r = receivers_of(light, b, &under);
        let keep = cull.cull(&mesh, &adj, &r, &IDENTITY, &IDENTITY, light).expect("culled").to_vec();
        assert!(keep[2] && keep[3], "{keep:?}");
        let clamp = cull.clamp.clone();
        for i in 4..8u32 {
            let k = clamp.far[i as usize];
            // Beyond the floor (distance ratio 4 / 3 from the light at height 4), finite.
            assert!(k.is_finite() && k > 4.0 / 3.0 && k < 2.0, "k = {k}");
            assert_eq!(cull.far()[i as usize], clamp.far_vertex(&mesh.positions, i));
        }
        // The silhouette of the kept triangles: the square's four edges.
        let b = &p.buffers;
        let mut s = Silhouette::new(&mesh, &b.sides_data, &b.edge_triangles, b.max_mult);
        s.compute(light, Some(&keep));
        assert!(s.kept_triangles().contains(&2) && s.kept_triangles().contains(&3));
        // Same sides as extract_clamped (its multiplicities from the same kept orientations).
        let slots = TriangleSlots::build(&mesh, &adj).expect("slots");
        let mut v = IndexedVolume::default();
        extract_clamped(&mesh, &adj, &slots, light, false, &clamp, &mut v);
        let sum_abs: usize = s
            .records()
            .iter()
            .map(|&r| {
                let r = r as usize;
                let count = b.sides_data[r * 4 * (2 + b.max_mult) + 3] as usize;
                let slots = &b.edge_triangles[r * b.max_mult..r * b.max_mult + count];
                slots
                    .iter()
                    .map(|&t| i32::from(s.orientation()[(t.unsigned_abs() - 1) as usize]) * t.signum())
                    .sum::<i32>()
                    .unsigned_abs() as usize
            })
            .sum();
        assert_eq!(sum_abs, v.sides.len() / 6);
        let mut unclamped = IndexedVolume::default();
        extract_indexed(&mesh, &adj, &slots, light, false, &mut unclamped);
        assert!(v.sides.len() <= unclamped.sides.len());

        // The same scene moved by +3 in x as a caster with a world matrix: the map of the moved
        // samples; the far vertices are those of the identity case, in the caster's space.
        let world = [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 3.0, 0.0, 0.0, 1.0];
        let inverse = [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, -3.0, 0.0, 0.0, 1.0];
        let moved: Vec<[f32; 3]> = under.iter().map(|p| [p[0] + 3.0, p[1], p[2]]).collect();
        let wl = [3.5, 4.0, 0.5, 1.0];
        let wb = Aabb { min: [-2.0, 0.0, -5.0], max: [8.0, 1.0, 5.0] };
        let r = receivers_of(wl, wb, &moved);
        let keep2 = cull.cull(&mesh, &adj, &r, &world, &inverse, light).expect("culled").to_vec();
        assert_eq!(keep2, keep);
        for i in 4..8u32 {
            let (a, c) = (cull.far()[i as usize], clamp.far_vertex(&mesh.positions, i));
            for j in 0..4 {
                assert!((a[j] - c[j]).abs() <= 1e-5 * (1.0 + c[j].abs()), "{a:?} {c:?}");
            }
        }
    }

    #[test]
    fn directional_far_vertices_follow_the_light_and_a_projective_matrix_is_not_culled() {
        let (mesh, adj, _) = scene();
        let b = bounds(&mesh);
        let light = [0.2, 1.0, 0.1, 0.0];
        let r = receivers_of(light, b, &[[0.3, 0.0, 0.4], [-0.1, 0.0, 0.2]]);
        let mut cull = CasterCull::default();
        let keep = cull.cull(&mesh, &adj, &r, &IDENTITY, &IDENTITY, light).expect("culled").to_vec();
        assert!(keep[2] || keep[3]);
        for i in 4..8u32 {
            if cull.clamp.far[i as usize] > 0.0 {
                assert_eq!(cull.far()[i as usize], cull.clamp.far_vertex(&mesh.positions, i));
            }
        }
        let mut projective = IDENTITY;
        projective[3] = 0.5;
        assert!(cull.cull(&mesh, &adj, &r, &projective, &IDENTITY, light).is_none());
        let empty = Receivers::new();
        assert!(cull.cull(&mesh, &adj, &empty, &IDENTITY, &IDENTITY, light).is_none());
    }

    /// The square over the floor seen from above and in front: its unclamped sides run down to
    /// their vanishing point, far larger on screen than the clamped ones and the far caps, so
    /// the clamp stays; a viewport of no pixels favours neither, and the far ends go to infinity.
    #[test]
    fn the_clamp_stays_where_it_covers_fewer_pixels() {
        use umbra_geom::camera::{Camera, DepthConvention};
        // The square alone casts; the floor only receives (its samples are in the map).
        let square = [0.0, 1.0, 0.0, 1.0, 1.0, 0.0, 1.0, 1.0, 1.0, 0.0, 1.0, 1.0];
        let (p, mesh) = prepare_welded("square", &square, Some(&[0, 2, 1, 0, 3, 2])).expect("square");
        let adj = EdgeAdjacency::build(&mesh);
        let b = Aabb { min: [-5.0, 0.0, -5.0], max: [5.0, 1.0, 5.0] };
        let light = [0.5, 4.0, 0.5, 1.0];
        let under = [[0.5, 0.0, 0.5], [0.2, 0.0, 0.7]];
        let r = receivers_of(light, b, &under);
        let mut cull = CasterCull::default();
        let keep = cull.cull(&mesh, &adj, &r, &IDENTITY, &IDENTITY, light).expect("culled").to_vec();
        let buffers = &p.buffers;
        let mut s = Silhouette::new(&mesh, &buffers.sides_data, &buffers.edge_triangles, buffers.max_mult);
        s.compute(light, Some(&keep));
        let adjacency = EdgeAdjacency::build(&mesh);
        let rv: Vec<u32> = umbra_geom::sides_data::record_ranges(&adjacency, buffers.max_mult)
            .flat_map(|r| adjacency.edges[r.edge])
            .collect();
        let camera = Camera { eye: [0.5, 3.0, 4.0], target: [0.5, 0.0, 0.5], fov_y_degrees: 60.0, ..Camera::default() };
        let clip = camera.clip_from_world_in(1.0, DepthConvention::ReversedZ).to_cols_array();
        let screen = Screen { clip_from_object: clip, width: 200.0, height: 200.0, polygon_pixels: 0.0 };
        let before = cull.far().to_vec();
        assert!(cull.choose_clamp(&s, &rv, light, &screen, false));
        assert_eq!(cull.far(), &before[..]);
        let nothing = Screen { clip_from_object: clip, width: 0.0, height: 0.0, polygon_pixels: 0.0 };
        assert!(!cull.choose_clamp(&s, &rv, light, &nothing, false));
        for (i, f) in cull.far().iter().enumerate() {
            let used = before[i] != [0.0; 4];
            assert_eq!(f[3] == 0.0 && *f == extrude(mesh.positions[i], light), used, "vertex {i}: {f:?}");
        }
    }

    #[test]
    fn raise_hull_keeps_the_eye_and_a_nan_cell_culls_nothing() {
        let (mesh, adj, _) = scene();
        let b = bounds(&mesh);
        let light = [0.5, 4.0, 0.5, 1.0];
        // The eye just under the square, between it and the floor: its pyramid is raised, so the
        // square is kept although no sample lies in its shadow.
        let mut r = receivers_of(light, b, &[[4.5, 0.0, -4.5]]);
        let eye = [[0.5, 0.5, 0.5], [0.45, 0.4, 0.45], [0.55, 0.4, 0.45], [0.55, 0.4, 0.55], [0.45, 0.4, 0.55]];
        assert!(r.raise_hull(&eye));
        let mut cull = CasterCull::default();
        let keep = cull.cull(&mesh, &adj, &r, &IDENTITY, &IDENTITY, light).expect("culled").to_vec();
        assert!(keep[2] && keep[3], "{keep:?}");
        // A NaN point: no raise, the map is dropped, nothing is culled.
        assert!(!r.raise_hull(&[[f64::NAN, 0.0, 0.0]]));
        assert!(r.map().is_none());
        // A NaN cell bounds nothing: every triangle kept, its far ends at infinity.
        let mut r = Receivers::new();
        assert!(r.set_grid(light, b, 128));
        r.cells_mut().fill(f32::NAN);
        assert!(r.build());
        let keep = cull.cull(&mesh, &adj, &r, &IDENTITY, &IDENTITY, light).expect("culled").to_vec();
        assert!(keep.iter().all(|&k| k));
        assert!(cull.far().iter().all(|v| v[3] == 0.0));
    }

    /// An orthographic view's volumes: every kept far end finite, and the same volume whether
    /// the caster is drawn in world space or moved there by its world matrix (the box test in
    /// world space, the far ends moved back into the caster's space).
    #[test]
    fn clamp_beyond_box_gives_finite_far_ends_in_the_casters_space() {
        let (mesh, _, _) = scene();
        let b = bounds(&mesh);
        let mut c = CasterCull::default();
        for light in [[0.3, 3.0, 0.4, 1.0], [0.2, 1.0, 0.3, 0.0]] {
            let keep =
                c.clamp_beyond_box(&mesh, &IDENTITY, &IDENTITY, b, light, light).expect("finite").expect("affine");
            assert!(keep.iter().all(|&k| k), "no triangle lies in a plane of the light");
            let here = c.far().to_vec();
            assert!(here.iter().all(|f| f[3] == 1.0 && f.iter().all(|x| x.is_finite())), "{here:?}");
            // The caster moved by t: the same far ends in its space, up to the roundings.
            let t = [2.0, 0.5, -1.0];
            let mut world = IDENTITY;
            let mut inverse = IDENTITY;
            for i in 0..3 {
                world[12 + i] = t[i];
                inverse[12 + i] = -t[i];
            }
            let moved =
                Aabb { min: [0, 1, 2].map(|i| b.min[i] + t[i] as f32), max: [0, 1, 2].map(|i| b.max[i] + t[i] as f32) };
            let lw = if light[3] == 0.0 {
                light
            } else {
                [0, 1, 2, 3].map(|i| light[i] + if i < 3 { t[i] as f32 } else { 0.0 })
            };
            c.clamp_beyond_box(&mesh, &world, &inverse, moved, lw, light).expect("finite").expect("affine");
            for (a, f) in here.iter().zip(c.far()) {
                for i in 0..4 {
                    assert!((a[i] - f[i]).abs() <= 1e-4 * (1.0 + a[i].abs()), "{a:?} against {f:?}");
                }
            }
        }
        // A matrix that is not affine: nothing closed.
        let mut projective = IDENTITY;
        projective[3] = 0.5;
        assert!(c
            .clamp_beyond_box(&mesh, &projective, &IDENTITY, b, [0.3, 3.0, 0.4, 1.0], [0.3, 3.0, 0.4, 1.0])
            .expect("ok")
            .is_none());
    }
}
