//! A triangle's footprint as seen from the light, in the unit square of one domain: its
//! central projection onto a face of the cube map around a point light (clipped to the
//! face's pyramid, Sutherland-Hodgman in f64), or its parallel projection along a directional
//! light's direction; a bounding rectangle with a margin plus the convex polygon for the
//! separating-axis test against a cell.

/// A rectangle in a domain's unit square: `[x0, x1] x [y0, y1]`.
#[derive(Clone, Copy, Debug)]
pub(super) struct Rect {
    pub(super) x0: f64,
    pub(super) x1: f64,
    pub(super) y0: f64,
    pub(super) y1: f64,
}

pub(super) const FULL: Rect = Rect { x0: 0.0, x1: 1.0, y0: 0.0, y1: 1.0 };

/// Margin added on every side of a footprint (in unit-square coordinates): far above the f64
/// rounding of the clipping and projection of f32 input.
const MARGIN: f64 = 1e-7;

/// One triangle's footprint in one domain: its bounding rectangle (with [`MARGIN`]) and the
/// convex polygon itself (empty = unknown shape, use the rectangle).
#[derive(Clone, Debug)]
pub(super) struct Footprint {
    pub(super) rect: Rect,
    pub(super) poly: Vec<[f64; 2]>,
}

impl Footprint {
    pub(super) fn full() -> Self {
        Footprint { rect: FULL, poly: Vec::new() }
    }

    pub(super) fn from_poly(poly: Vec<[f64; 2]>) -> Self {
        let mut r = Rect { x0: f64::INFINITY, x1: f64::NEG_INFINITY, y0: f64::INFINITY, y1: f64::NEG_INFINITY };
        for p in &poly {
            r.x0 = r.x0.min(p[0]);
            r.x1 = r.x1.max(p[0]);
            r.y0 = r.y0.min(p[1]);
            r.y1 = r.y1.max(p[1]);
        }
        let rect = Rect {
            x0: (r.x0 - MARGIN).max(0.0),
            x1: (r.x1 + MARGIN).min(1.0),
            y0: (r.y0 - MARGIN).max(0.0),
            y1: (r.y1 + MARGIN).min(1.0),
        };
        Footprint { rect, poly }
    }

    /// Whether the footprint (grown by [`MARGIN`]) may meet `cell`: separating-axis test of
    /// the convex polygon against the rectangle (the rectangle's own axes, then every polygon
    /// edge's normal). Conservative: only a clear separation says no.
    pub(super) fn touches(&self, cell: &Rect) -> bool {
        let r = &self.rect;
        if r.x1 < cell.x0 || r.x0 > cell.x1 || r.y1 < cell.y0 || r.y0 > cell.y1 {
            return false;
        }
        let n = self.poly.len();
        let corners = [[cell.x0, cell.y0], [cell.x1, cell.y0], [cell.x1, cell.y1], [cell.x0, cell.y1]];
        for i in 0..n {
            let (a, b) = (self.poly[i], self.poly[(i + 1) % n]);
            let axis = [b[1] - a[1], a[0] - b[0]];
            let len = (axis[0] * axis[0] + axis[1] * axis[1]).sqrt();
            if len == 0.0 {
                continue;
            }
            let dot = |p: [f64; 2]| p[0] * axis[0] + p[1] * axis[1];
            let (mut pmin, mut pmax) = (f64::INFINITY, f64::NEG_INFINITY);
            for &p in &self.poly {
                pmin = pmin.min(dot(p));
                pmax = pmax.max(dot(p));
            }
            let (mut cmin, mut cmax) = (f64::INFINITY, f64::NEG_INFINITY);
            for c in corners {
                cmin = cmin.min(dot(c));
                cmax = cmax.max(dot(c));
            }
            let eps = MARGIN * len;
            if pmax + eps < cmin || cmax + eps < pmin {
                return false;
            }
        }
        true
    }
}

/// The footprint of triangle `c` on cube face `face` (0..6: +x, -x, +y, -y, +z, -z) around
/// the point light `l`, in the face's unit square; `None` if it misses the face.
pub(super) fn cube_face_footprint(c: &[[f64; 3]; 3], l: [f64; 3], face: usize) -> Option<Footprint> {
    let k = face / 2;
    let s = if face.is_multiple_of(2) { 1.0 } else { -1.0 };
    let (a, b) = ((k + 1) % 3, (k + 2) % 3);
    let mut poly: Vec<[f64; 3]> = c.iter().map(|p| [p[0] - l[0], p[1] - l[1], p[2] - l[2]]).collect();
    let scale = poly.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
    if scale == 0.0 {
        // All three corners at the light: covers every direction.
        return Some(Footprint::full());
    }
    // The face's pyramid: s d_k - d_j >= 0 and s d_k + d_j >= 0 for j in {a, b}.
    for (j, sign) in [(a, 1.0), (a, -1.0), (b, 1.0), (b, -1.0)] {
        let f = |p: &[f64; 3]| s * p[k] - sign * p[j];
        poly = clip(&poly, f);
        if poly.is_empty() {
            return None;
        }
    }
    let mut out = Vec::with_capacity(poly.len());
    for p in &poly {
        let m = s * p[k];
        if m <= 1e-9 * scale {
            // A clipped corner at (or within rounding of) the light: the triangle passes
            // through the light; its direction there is unknown.
            return Some(Footprint::full());
        }
        out.push([(p[a] / m + 1.0) * 0.5, (p[b] / m + 1.0) * 0.5]);
    }
    Some(Footprint::from_poly(out))
}

/// Sutherland-Hodgman: the part of `poly` where `f >= 0`.
fn clip(poly: &[[f64; 3]], f: impl Fn(&[f64; 3]) -> f64) -> Vec<[f64; 3]> {
    let mut out = Vec::with_capacity(poly.len() + 2);
    for i in 0..poly.len() {
        let (p, q) = (poly[i], poly[(i + 1) % poly.len()]);
        let (fp, fq) = (f(&p), f(&q));
        if fp >= 0.0 {
            out.push(p);
        }
        if (fp >= 0.0) != (fq >= 0.0) {
            let t = fp / (fp - fq);
            out.push([0, 1, 2].map(|k| p[k] + t * (q[k] - p[k])));
        }
    }
    out
}

/// Footprints of the triangles projected along the directional light `d` onto the plane
/// orthogonal to it, in the unit square over their bounds.
pub(super) fn parallel_footprints(tris: &[[[f64; 3]; 3]], d: [f64; 3]) -> Vec<Footprint> {
    let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    let n = d.map(|v| v / len);
    // Any vector not parallel to n, then Gram-Schmidt.
    let helper = if n[0].abs() < 0.9 { [1.0, 0.0, 0.0] } else { [0.0, 1.0, 0.0] };
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let h = dot(helper, n);
    let e1 = {
        let v = [helper[0] - h * n[0], helper[1] - h * n[1], helper[2] - h * n[2]];
        let l = dot(v, v).sqrt();
        v.map(|x| x / l)
    };
    let e2 = [n[1] * e1[2] - n[2] * e1[1], n[2] * e1[0] - n[0] * e1[2], n[0] * e1[1] - n[1] * e1[0]];
    let raw: Vec<[[f64; 2]; 3]> = tris.iter().map(|c| c.map(|p| [dot(p, e1), dot(p, e2)])).collect();
    let (mut x0, mut x1, mut y0, mut y1) = (f64::INFINITY, f64::NEG_INFINITY, f64::INFINITY, f64::NEG_INFINITY);
    for p in raw.iter().flatten() {
        x0 = x0.min(p[0]);
        x1 = x1.max(p[0]);
        y0 = y0.min(p[1]);
        y1 = y1.max(p[1]);
    }
    // A square domain (same scale on both axes); a degenerate extent gets size 1.
    let size = (x1 - x0).max(y1 - y0);
    let size = if size > 0.0 && size.is_finite() { size } else { 1.0 };
    raw.iter()
        .map(|t| Footprint::from_poly(t.iter().map(|p| [(p[0] - x0) / size, (p[1] - y0) / size]).collect()))
        .collect()
}
