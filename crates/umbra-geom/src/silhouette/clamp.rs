//! [`VolumeClamp`]: which triangles cast a volume at all, and where each vertex's volume ends.
//!
//! CC shadow volumes (Lloyd, Wendt, Govindaraju, Manocha, EGSR 2004) cull the volumes that
//! hold no receiver and clamp the others to where receivers lie. Here both follow exactly
//! from [`crate::receivers::ReceiverMap`], which bounds the visible samples per light-space
//! cell; the proof is in docs/exactness.md ("Volumes clamped to their receivers"). In short:
//!
//! * A sample's count is the sum over triangles of "the sample lies in the triangle's shadow
//!   frustum". A triangle whose frustum holds no visible sample is dropped: no visible count
//!   changes, and the silhouette is that of the kept triangles.
//! * A kept triangle `t`'s frustum is cut at its vertices' far ends `v' = L + k_v (v - L)`
//!   (point light) or `v' = v + K_v d` (directional, `d` the unit direction of travel) and closed
//!   by the far cap `t'`. A sample `p = L + a (q - L)` (`q` on `t`) lies in the cut volume iff
//!   `a` is below the ray's parameter on `t'`, a weighted harmonic mean of the `k_v` (weighted
//!   mean of the `K_v`), so at least `min k_v`. With `R` the farthest visible sample of the
//!   cells `t`'s cone covers and `d_t` the triangle's least distance from the light, every
//!   visible sample in the frustum has `a <= R / d_t` (directional: `a <= R - d_t`, depths), so
//!   `k_v > R / d_t` for every triangle at `v` keeps every count. Each vertex has one far end,
//!   shared by every side quad and far cap that uses it, so the clamped volumes close exactly
//!   as the infinite ones do and the sides of shared edges still cancel.

use crate::Light;

/// The relative margin by which a far end lies beyond the farthest receiver it must enclose:
/// far beyond the rounding of a sample's position or of the far vertex itself (f32).
pub const CLAMP_MARGIN: f64 = 1.0 / 256.0;

/// A far scale beyond which the far end is put at infinity (w = 0) instead: nothing is saved
/// there, and a finite f32 vertex that far out would only lose precision.
pub const CLAMP_LIMIT: f64 = 1048576.0;

/// Per triangle whether it casts, per welded vertex where its volume ends.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct VolumeClamp {
    /// The light the clamp was made for.
    pub light: Light,
    /// Per triangle of the welded mesh: whether its frustum may hold a visible sample.
    pub keep: Vec<bool>,
    /// Per welded vertex: its far scale `k_v` (point light: `v' = L + k_v (v - L)`) or far
    /// distance `K_v` (directional: `v' = v + K_v d`); `f32::INFINITY` for a far end at
    /// infinity (001 Eq. 2), 0 for a vertex of no kept triangle.
    pub far: Vec<f32>,
    /// The unit direction of travel of a directional light's rays (`-L.xyz`, normalised).
    pub travel: [f64; 3],
}

impl VolumeClamp {
    /// An unculled, unclamped volume for `triangles` triangles and `vertices` vertices: every
    /// triangle kept, every far end at infinity (the volume [`super::extract_indexed`] draws).
    pub fn unclamped(light: Light, triangles: usize, vertices: usize) -> Self {
        Self { light, keep: vec![true; triangles], far: vec![f32::INFINITY; vertices], travel: travel(light) }
    }

    /// Triangles kept.
    pub fn kept(&self) -> usize {
        self.keep.iter().filter(|&&k| k).count()
    }

    /// The far end of welded vertex `i` (at `positions[i]`), homogeneous.
    #[inline]
    pub fn far_vertex(&self, positions: &[[f32; 3]], i: u32) -> [f32; 4] {
        let p = positions[i as usize];
        let k = self.far[i as usize];
        let l = self.light;
        if !(k.is_finite()) {
            return super::extrude(p, l);
        }
        let k = k as f64;
        if l[3] != 0.0 {
            let c = [0, 1, 2].map(|j| (l[j] as f64 + k * (p[j] as f64 - l[j] as f64)) as f32);
            [c[0], c[1], c[2], 1.0]
        } else {
            let c = [0, 1, 2].map(|j| (p[j] as f64 + k * self.travel[j]) as f32);
            [c[0], c[1], c[2], 1.0]
        }
    }
}

/// The unit direction of travel of `light`'s rays when it is directional (zero for a point
/// light).
pub fn travel(light: Light) -> [f64; 3] {
    if light[3] != 0.0 {
        return [0.0; 3];
    }
    let d = [-(light[0] as f64), -(light[1] as f64), -(light[2] as f64)];
    let n = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    if n > 0.0 {
        d.map(|x| x / n)
    } else {
        [0.0; 3]
    }
}
