//! Watertight ray/triangle intersection: Sven Woop, Carsten Benthin, Ingo Wald,
//! "Watertight Ray/Triangle Intersection", Journal of Computer Graphics Techniques 2(1), 2013,
//! Section 3 (the algorithm) and Fig. 1-2 (its pseudocode), two-sided variant (no culling).
//!
//! The ray is sheared and scaled so that it becomes the +z axis from the origin; the triangle's
//! vertices are transformed the same way and the test becomes a 2D point-in-triangle test of
//! the origin with three *edge functions* `U`, `V`, `W` (scaled barycentrics).
//!
//! Why it is watertight: every vertex is transformed by the same operations whichever triangle
//! it belongs to, so two triangles sharing an edge see bit-identical transformed endpoints, and
//! the edge function of that edge is evaluated from the same products in the other order —
//! exactly its negation. By monotonicity of IEEE rounding, `fl(fl(p) - fl(q))` never has the
//! wrong sign, only possibly a false zero, and a zero edge function is accepted by the
//! triangles on *both* sides. So a ray through a shared edge or vertex can produce a double
//! hit, never a miss.
//!
//! Precision: we evaluate in `f64` from `f32` vertices. The paper evaluates in `f32` and redoes
//! the edge functions in `f64` when one of them is exactly zero, to remove false zeros; with
//! `f64` throughout false zeros need cancellation of ~50 bits and can only turn a miss next to
//! an edge into a hit *on* it, which cannot break watertightness, so we omit that fallback.
//! Degenerate (zero-area, or seen exactly edge-on) triangles give `det == 0` and never hit;
//! non-finite data gives NaN comparisons and never hits.

/// A ray prepared for the watertight test (paper Fig. 1, "precalculations per ray").
#[derive(Clone, Copy, Debug)]
pub struct ShearedRay {
    /// Ray origin.
    pub origin: [f64; 3],
    /// Index of the dominant direction axis (`z` after the permutation).
    kz: usize,
    kx: usize,
    ky: usize,
    /// Shear constants `Sx = d[kx]/d[kz]`, `Sy = d[ky]/d[kz]`, `Sz = 1/d[kz]`.
    sx: f64,
    sy: f64,
    sz: f64,
}

impl ShearedRay {
    /// Prepares the ray `origin + t * direction`. `t` is measured in units of `direction`.
    pub fn new(origin: [f64; 3], direction: [f64; 3]) -> ShearedRay {
        let abs = direction.map(f64::abs);
        // Dominant axis becomes z: the division by d[kz] is then as well conditioned as it gets.
        let kz = if abs[0] >= abs[1] && abs[0] >= abs[2] {
            0
        } else if abs[1] >= abs[2] {
            1
        } else {
            2
        };
        let mut kx = (kz + 1) % 3;
        let mut ky = (kx + 1) % 3;
        // Swapping keeps the winding of the transformed triangle (paper Fig. 1); irrelevant for a
        // two-sided test but kept so that the sign of `det` tells the facing consistently.
        if direction[kz] < 0.0 {
            std::mem::swap(&mut kx, &mut ky);
        }
        let sz = 1.0 / direction[kz];
        ShearedRay { origin, kz, kx, ky, sx: direction[kx] * sz, sy: direction[ky] * sz, sz }
    }

    /// The triangle in the ray's sheared space: its vertices relative to the origin, sheared
    /// and scaled so that the ray is the +z axis (paper Fig. 2, first block), and the scaled
    /// barycentric coordinates = 2D edge functions `u` (edge b c), `v` (c a), `w` (a b).
    #[inline]
    fn shear(&self, a: [f32; 3], b: [f32; 3], c: [f32; 3]) -> Sheared {
        let o = self.origin;
        // Vertices relative to the ray origin.
        let rel = |p: [f32; 3]| [p[0] as f64 - o[0], p[1] as f64 - o[1], p[2] as f64 - o[2]];
        let (kx, ky, kz) = (self.kx, self.ky, self.kz);
        let xy = |p: [f64; 3]| [p[kx] - self.sx * p[kz], p[ky] - self.sy * p[kz]];
        let (pa, pb, pc) = (rel(a), rel(b), rel(c));
        let (a2, b2, c2) = (xy(pa), xy(pb), xy(pc));
        Sheared {
            u: c2[0] * b2[1] - c2[1] * b2[0],
            v: a2[0] * c2[1] - a2[1] * c2[0],
            w: b2[0] * a2[1] - b2[1] * a2[0],
            xy: [a2, b2, c2],
            z: [self.sz * pa[kz], self.sz * pb[kz], self.sz * pc[kz]],
        }
    }

    /// Two-sided watertight intersection with triangle `(a, b, c)`; returns the ray parameter
    /// `t` if the ray hits it with `t_min < t < t_max` (open interval).
    #[inline]
    pub fn intersect(&self, a: [f32; 3], b: [f32; 3], c: [f32; 3], t_min: f64, t_max: f64) -> Option<f64> {
        let Sheared { u, v, w, z, .. } = self.shear(a, b, c);
        // Outside if the edge functions have mixed signs; zeros count as inside on both sides.
        if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
            return None;
        }
        let det = u + v + w;
        // Edge-on or degenerate: no area seen from the ray. NaN also fails here (`!(det != 0)`).
        if det == 0.0 || det.is_nan() {
            return None;
        }
        // Scaled hit distance, then t by one division (the paper defers it; we need t anyway).
        let t = (u * z[0] + v * z[1] + w * z[2]) / det;
        if t > t_min && t < t_max {
            Some(t)
        } else {
            None
        }
    }
}

/// A triangle in a ray's sheared space (see [`ShearedRay::shear`]).
struct Sheared {
    u: f64,
    v: f64,
    w: f64,
    /// The sheared 2D vertices a, b, c.
    xy: [[f64; 2]; 3],
    /// The scaled z of a, b, c.
    z: [f64; 3],
}

/// What [`ShearedRay::intersect_near`] found: the exact answer, and the answers for the
/// triangle grown and shrunk by a margin (each edge line moved outwards or inwards by that
/// distance, measured in the sheared plane perpendicular to the dominant axis).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct NearHit {
    /// The plain test of [`ShearedRay::intersect`] hits.
    pub exact: bool,
    /// The grown triangle is hit: the ray passes within the margin of the triangle.
    pub grown: bool,
    /// The shrunk triangle is hit: the ray passes through it at least the margin away from
    /// every edge, so moving the ray by less than the margin cannot make it miss.
    pub shrunk: bool,
}

impl ShearedRay {
    /// [`ShearedRay::intersect`] with a `margin` (a world distance, `>= 0`): also reports whether
    /// the ray hits the triangle grown and shrunk by `margin` (see [`NearHit`]). The `t` range is
    /// the same open interval for all three answers. Used to find samples whose shadow would
    /// change if the sample moved by less than the rounding of the GPU's depth test.
    ///
    /// The distance of the ray to an edge line is measured in the sheared plane: there an edge
    /// function is twice the area of the triangle (origin, edge), i.e. the edge's 2D length
    /// times the origin's distance to its line. Along the dominant axis the shear changes
    /// distances by at most a factor sqrt(3), which a band definition can afford.
    #[inline]
    pub fn intersect_near(
        &self,
        a: [f32; 3],
        b: [f32; 3],
        c: [f32; 3],
        t_min: f64,
        t_max: f64,
        margin: f64,
    ) -> NearHit {
        let Sheared { u, v, w, xy: [[ax, ay], [bx, by], [cx, cy]], z } = self.shear(a, b, c);
        let det = u + v + w;
        if det == 0.0 || det.is_nan() {
            return NearHit::default();
        }
        // Edge functions scaled to distances: u belongs to edge (b, c), v to (c, a), w to (a, b).
        let mu = margin * (cx - bx).hypot(cy - by);
        let mv = margin * (ax - cx).hypot(ay - cy);
        let mw = margin * (bx - ax).hypot(by - ay);
        let grown = (u >= -mu && v >= -mv && w >= -mw) || (u <= mu && v <= mv && w <= mw);
        if !grown {
            return NearHit::default();
        }
        let t = (u * z[0] + v * z[1] + w * z[2]) / det;
        if !(t > t_min && t < t_max) {
            return NearHit::default();
        }
        let exact = !((u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0));
        let shrunk = (u >= mu && v >= mv && w >= mw) || (u <= -mu && v <= -mv && w <= -mw);
        NearHit { exact, grown: true, shrunk: shrunk && exact }
    }
}

impl ShearedRay {
    /// Which edges of the triangle the ray passes within `margin` of (a world distance, as in
    /// [`ShearedRay::intersect_near`]), at a `t` in `(t_min, t_max)` where it meets the grown
    /// triangle's plane: `[ab, bc, ca]`, or `None` when it passes none (or the triangle is
    /// degenerate or edge-on to the ray).
    pub fn near_edges(
        &self,
        a: [f32; 3],
        b: [f32; 3],
        c: [f32; 3],
        t_min: f64,
        t_max: f64,
        margin: f64,
    ) -> Option<[bool; 3]> {
        let Sheared { u, v, w, xy: [[ax, ay], [bx, by], [cx, cy]], z } = self.shear(a, b, c);
        let det = u + v + w;
        if det == 0.0 || det.is_nan() {
            return None;
        }
        let mu = margin * (cx - bx).hypot(cy - by);
        let mv = margin * (ax - cx).hypot(ay - cy);
        let mw = margin * (bx - ax).hypot(by - ay);
        let grown = (u >= -mu && v >= -mv && w >= -mw) || (u <= mu && v <= mv && w <= mw);
        if !grown {
            return None;
        }
        let t = (u * z[0] + v * z[1] + w * z[2]) / det;
        if !(t > t_min && t < t_max) {
            return None;
        }
        let near = [w.abs() <= mw, u.abs() <= mu, v.abs() <= mv];
        near.iter().any(|&n| n).then_some(near)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hits_triangle_interior_at_expected_t() {
        let r = ShearedRay::new([0.25, 0.25, 5.0], [0.0, 0.0, -1.0]);
        let t = r.intersect([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], 0.0, f64::INFINITY);
        assert_eq!(t, Some(5.0));
    }

    #[test]
    fn misses_outside_and_respects_open_interval() {
        let r = ShearedRay::new([2.0, 2.0, 5.0], [0.0, 0.0, -1.0]);
        assert_eq!(r.intersect([0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], 0.0, f64::INFINITY), None);
        let r = ShearedRay::new([0.25, 0.25, 5.0], [0.0, 0.0, -1.0]);
        // t = 5 exactly is excluded by an open interval ending at 5.
        assert_eq!(r.intersect([0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], 0.0, 5.0), None);
        assert_eq!(r.intersect([0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], 5.0, 9.0), None);
    }

    #[test]
    fn degenerate_and_edge_on_triangles_never_hit() {
        let r = ShearedRay::new([0.5, 0.0, 5.0], [0.0, 0.0, -1.0]);
        // Collinear vertices.
        assert_eq!(r.intersect([0.0; 3], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0], 0.0, f64::INFINITY), None);
        // Triangle in the plane y = 0, containing the ray: edge-on.
        assert_eq!(r.intersect([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0], 0.0, f64::INFINITY), None);
    }

    #[test]
    fn non_finite_input_never_hits() {
        let r = ShearedRay::new([0.25, 0.25, 5.0], [0.0, 0.0, -1.0]);
        assert_eq!(r.intersect([f32::NAN, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], 0.0, f64::INFINITY), None);
        let r = ShearedRay::new([0.25, 0.25, 5.0], [0.0, 0.0, 0.0]);
        assert_eq!(r.intersect([0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], 0.0, f64::INFINITY), None);
    }
}
