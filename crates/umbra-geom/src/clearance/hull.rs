//! The convex hull `H` of the eye, the near-plane rectangle and the light, as the clearance
//! test uses it: face planes, edge directions and a box, and the conservative
//! separating-axis tests of a box and of a triangle against it.

use crate::vec3::{cross, dot, norm, sub};

type V3 = [f64; 3];

/// The convex hull `H` as the test uses it.
pub(super) struct Hull {
    points: Vec<V3>,
    /// Outward face normals (unit) with the largest projection of `H` on them.
    pub(super) faces: Vec<(V3, f64)>,
    /// Unit edge directions (every pair of points).
    edges: Vec<V3>,
    lo: V3,
    hi: V3,
    margin: f64,
}

impl Hull {
    pub(super) fn new(points: Vec<V3>, margin: f64) -> Hull {
        let n = points.len();
        let mut faces = Vec::new();
        for i in 0..n {
            for j in i + 1..n {
                for k in j + 1..n {
                    let normal = cross(sub(points[j], points[i]), sub(points[k], points[i]));
                    let len = norm(normal);
                    if !(len > 0.0) {
                        continue;
                    }
                    let u = normal.map(|c| c / len);
                    let d = dot(u, points[i]);
                    let (mut below, mut above) = (false, false);
                    for p in &points {
                        let s = dot(u, *p) - d;
                        below |= s < -margin;
                        above |= s > margin;
                    }
                    // A face plane: every point on one side (within the margin).
                    if !(below && above) {
                        let u = if above { u.map(|c| -c) } else { u };
                        let top = points.iter().map(|p| dot(u, *p)).fold(f64::NEG_INFINITY, f64::max);
                        faces.push((u, top));
                    }
                }
            }
        }
        let mut edges = Vec::new();
        for i in 0..n {
            for j in i + 1..n {
                let e = sub(points[j], points[i]);
                let len = norm(e);
                if len > 0.0 {
                    edges.push(e.map(|c| c / len));
                }
            }
        }
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for p in &points {
            for a in 0..3 {
                lo[a] = lo[a].min(p[a]);
                hi[a] = hi[a].max(p[a]);
            }
        }
        Hull { points, faces, edges, lo, hi, margin }
    }

    /// Projection interval of `H` on `axis`.
    pub(super) fn extent(&self, axis: V3) -> (f64, f64) {
        let mut lo = f64::INFINITY;
        let mut hi = f64::NEG_INFINITY;
        for p in &self.points {
            let s = dot(axis, *p);
            lo = lo.min(s);
            hi = hi.max(s);
        }
        (lo, hi)
    }

    /// True when the box `[lo, hi]` is proved apart from `H` (box axes, face planes of `H`).
    pub(super) fn box_apart(&self, lo: V3, hi: V3) -> bool {
        for a in 0..3 {
            if lo[a] > self.hi[a] + self.margin || hi[a] < self.lo[a] - self.margin {
                return true;
            }
        }
        for &(u, top) in &self.faces {
            // The box's smallest projection on the outward normal.
            let mut min = 0.0;
            for a in 0..3 {
                min += if u[a] >= 0.0 { u[a] * lo[a] } else { u[a] * hi[a] };
            }
            if min > top + self.margin {
                return true;
            }
        }
        false
    }

    /// True when triangle `t` is proved apart from `H` by more than the margin.
    pub(super) fn triangle_apart(&self, t: [V3; 3]) -> bool {
        let apart_on = |axis: V3| -> bool {
            let len = norm(axis);
            if !(len > 1e-300) {
                return false;
            }
            let u = axis.map(|c| c / len);
            let (h0, h1) = self.extent(u);
            let s = t.map(|p| dot(u, p));
            let t0 = s[0].min(s[1]).min(s[2]);
            let t1 = s[0].max(s[1]).max(s[2]);
            t0 > h1 + self.margin || t1 < h0 - self.margin
        };
        for &(u, top) in &self.faces {
            if t.iter().all(|p| dot(u, *p) > top + self.margin) {
                return true;
            }
        }
        let e = [sub(t[1], t[0]), sub(t[2], t[1]), sub(t[0], t[2])];
        if apart_on(cross(e[0], e[1])) {
            return true;
        }
        for he in &self.edges {
            for te in &e {
                if apart_on(cross(*he, *te)) {
                    return true;
                }
            }
        }
        false
    }
}
