//! The *edge-on* part of the boundary band: samples a shadow-volume face seen almost exactly
//! edge-on from the camera may cover.
//!
//! Every stencil method draws, for some edges `AB` of the mesh, a side face in the plane
//! through the light and `AB` (paper 001 Eq. 2: the quad `A, B, B - L, A - L` with the last two
//! at infinity; the per-triangle methods do so for every triangle edge). When the eye lies
//! within a pixel's angle of that plane the face rasterizes as a sliver: which pixel centres it
//! covers, and the depth its fragments get there (interpolated over a nearly degenerate
//! screen-space triangle), are decided by rounding, and a fragment landing in front of a sample
//! instead of behind it changes the z-fail count by one. In exact arithmetic such a face
//! contributes nothing (a view ray in its plane only grazes the volume), so the count is right
//! only up to that rounding: these samples are band, like the other precision classes of
//! [`crate::reference`](mod@crate::reference). Found on Conference (tiny edges at the foot of a wall whose side
//! planes pass within 0.1 units of the eye 1,800 units away).
//!
//! What is marked, per light: for every silhouette edge whose side face is seen thinner than
//! [`SLIVER_PIXELS`] at its nearest point, the pixels within [`EDGE_ON_PIXELS`] of the plane's
//! image (a line), restricted to the face's projected extent when the face lies wholly in
//! front of the eye (else the whole line). Conservative: a marked pixel need not be covered.

use umbra_geom::adjacency::EdgeAdjacency;
use umbra_geom::vec3::{cross, dot, norm, sub};
use umbra_geom::{Light, WeldedMesh};

use crate::reference::RasterView;

/// A side face seen thinner than this many pixels at its nearest point is a sliver (the
/// artifacts measured came from faces 0.03-0.15 pixel thick).
pub const SLIVER_PIXELS: f64 = 0.25;
/// The pixels whose centre lies within this distance of a sliver's image are band.
pub const EDGE_ON_PIXELS: f64 = 1.0;

fn add_scaled(a: [f64; 3], b: [f64; 3], s: f64) -> [f64; 3] {
    [a[0] + s * b[0], a[1] + s * b[1], a[2] + s * b[2]]
}

/// Distance from `p` to the ray `origin + t d`, `t >= 0`.
fn ray_distance(p: [f64; 3], origin: [f64; 3], d: [f64; 3]) -> f64 {
    let dd = dot(d, d);
    let t = if dd > 0.0 { (dot(sub(p, origin), d) / dd).max(0.0) } else { 0.0 };
    norm(sub(p, add_scaled(origin, d, t)))
}

/// Distance from `p` to the segment `a b`.
fn segment_distance(p: [f64; 3], a: [f64; 3], b: [f64; 3]) -> f64 {
    let d = sub(b, a);
    let dd = dot(d, d);
    let t = if dd > 0.0 { (dot(sub(p, a), d) / dd).clamp(0.0, 1.0) } else { 0.0 };
    norm(sub(p, add_scaled(a, d, t)))
}

/// The side face of edge `a b` for `light`: `a, b`, and the directions its two long edges run
/// to infinity (away from the light).
fn face(a: [f64; 3], b: [f64; 3], light: Light) -> ([f64; 3], [f64; 3]) {
    if light[3] != 0.0 {
        let l = [0, 1, 2].map(|k| f64::from(light[k]) / f64::from(light[3]));
        (sub(a, l), sub(b, l))
    } else {
        let away = [0, 1, 2].map(|k| -f64::from(light[k]));
        (away, away)
    }
}

/// Distance from the eye to the face `{a + s (b - a) + t d(s)}` (s in [0, 1], t >= 0, `d`
/// interpolating `da`, `db`), given the eye's distance `h` to the face's plane with unit normal
/// `n`: `h` if the eye's foot on the plane lies inside the face, else the distance to the
/// nearest of its three boundary pieces.
fn face_distance(
    eye: [f64; 3],
    n: [f64; 3],
    h_signed: f64,
    a: [f64; 3],
    b: [f64; 3],
    da: [f64; 3],
    db: [f64; 3],
) -> f64 {
    let foot = add_scaled(eye, n, -h_signed);
    // Inside test in the plane: the face is the convex region bounded by the segment and the
    // two rays; the foot is inside iff it is on the inner side of all three boundary lines.
    let ab = sub(b, a);
    let side = |origin: [f64; 3], dir: [f64; 3], inner: [f64; 3]| {
        let c = cross(dir, sub(foot, origin));
        let r = cross(dir, sub(inner, origin));
        dot(c, n) * dot(r, n) >= 0.0
    };
    let inner = add_scaled(add_scaled(a, ab, 0.5), add_scaled(da, db, 1.0), 0.5);
    let inside = side(a, ab, inner) && side(a, da, inner) && side(b, db, inner);
    if inside {
        return h_signed.abs();
    }
    segment_distance(eye, a, b).min(ray_distance(eye, a, da)).min(ray_distance(eye, b, db))
}

/// Whether edge `e` of `adjacency` casts a side face for `light` in some exact method: a
/// silhouette, i.e. a non-zero sum of its opposite vertices' sides of the plane (light, a, b)
/// (001 Alg. 3, here in f64), or a zero term (undecided). The per-triangle methods draw faces
/// on every edge, but on a non-silhouette edge two opposite faces cancel exactly (they are
/// drawn from the same endpoints).
pub fn casts_side(mesh: &WeldedMesh, adjacency: &EdgeAdjacency, e: usize, light: Light) -> bool {
    let pos = |k: u32| mesh.positions[k as usize].map(f64::from);
    let [ia, ib] = adjacency.edges[e];
    let (a, b) = (pos(ia), pos(ib));
    let towards = if light[3] != 0.0 {
        sub([0, 1, 2].map(|k| f64::from(light[k]) / f64::from(light[3])), a)
    } else {
        [0, 1, 2].map(|k| f64::from(light[k]))
    };
    let edge_normal = cross(sub(b, a), towards);
    let (mut m, mut undecided) = (0i64, false);
    for &o in adjacency.opposites(e) {
        let side = dot(edge_normal, sub(pos(o), a));
        undecided |= side == 0.0;
        m += if side > 0.0 {
            1
        } else if side < 0.0 {
            -1
        } else {
            0
        };
    }
    m != 0 || undecided
}

/// The edges (vertex pairs, smaller index first) that cast a side face for `light`
/// ([`casts_side`]).
pub fn side_casting_edges(mesh: &WeldedMesh, light: Light) -> std::collections::HashSet<[u32; 2]> {
    let adjacency = EdgeAdjacency::build(mesh);
    (0..adjacency.len())
        .filter(|&e| casts_side(mesh, &adjacency, e, light))
        .map(|e| {
            let [a, b] = adjacency.edges[e];
            [a.min(b), a.max(b)]
        })
        .collect()
}

/// Marks, in `band` (row-major, top row first, `width * height`), the pixels an almost
/// edge-on side face of some triangle edge may cover (module doc). Returns the number of such
/// faces. `casting` are the edges that cast a side face for `light`
/// ([`side_casting_edges`]); `is_sample(i)` says whether pixel `i` holds a sample (background
/// is never band).
#[allow(clippy::too_many_arguments)]
// `!(x > 0.0)` is meant: it is also true for NaN, which must be rejected the same way.
#[allow(clippy::neg_cmp_op_on_partial_ord)]
pub fn mark_edge_on(
    mesh: &WeldedMesh,
    casting: &std::collections::HashSet<[u32; 2]>,
    light: Light,
    eye: [f64; 3],
    view: &RasterView,
    width: u32,
    height: u32,
    band: &mut [bool],
    is_sample: impl Fn(usize) -> bool,
) -> usize {
    let m = &view.clip_from_world;
    // Q: world direction -> homogeneous screen point (x, y, w) rows of clip_from_world.
    let q = |d: [f64; 3], w: f64| -> [f64; 3] {
        let row = |r: usize| m[r] * d[0] + m[4 + r] * d[1] + m[8 + r] * d[2] + m[12 + r] * w;
        [row(0), row(1), row(3)]
    };
    // One pixel's angle at the image centre: clip y = f_y * y_view with |row 1| = f_y.
    let f_y = (m[1] * m[1] + m[5] * m[5] + m[9] * m[9]).sqrt();
    if !(f_y > 0.0) || width == 0 || height == 0 {
        return 0;
    }
    let pixel_angle = 2.0 / (f64::from(height) * f_y);
    let (w, h) = (f64::from(width), f64::from(height));
    let mut slivers = 0;
    let pos = |k: u32| mesh.positions[k as usize].map(f64::from);
    // Only edges that cast a side face for some exact method (sliver or not). The marks are
    // an OR, so the set's iteration order does not matter.
    for &[ia, ib] in casting {
        let (a, b) = (pos(ia), pos(ib));
        {
            let (da, db) = face(a, b, light);
            // The face's plane: through a, b and the directions to infinity.
            let n = cross(sub(b, a), add_scaled(da, db, 1.0));
            let nn = norm(n);
            if !(nn > 0.0) || !nn.is_finite() {
                continue;
            }
            let n = n.map(|c| c / nn);
            let h_signed = dot(n, sub(eye, a));
            // Cheap rejection first: a plane far from the eye relative to the edge's distance.
            let near = face_distance(eye, n, h_signed, a, b, da, db);
            if !(near > 0.0) || h_signed.abs() >= SLIVER_PIXELS * pixel_angle * near {
                continue;
            }
            slivers += 1;
            // The plane's image: screen points p with n . Q^-1 p = 0. Rather than inverting Q,
            // take the line through the images of two well separated points of the face.
            let pts = [q(a, 1.0), q(b, 1.0), q(da, 0.0), q(db, 0.0), q(add_scaled(a, da, 1.0), 1.0)];
            let mut best: Option<([f64; 3], f64)> = None;
            for i in 0..pts.len() {
                for j in i + 1..pts.len() {
                    let l = cross(pts[i], pts[j]);
                    let g = (2.0 * l[0] / w).hypot(2.0 * l[1] / h);
                    // Normalise so that l . p / g is a pixel distance (p = (x_ndc, y_ndc, 1)).
                    let len = norm(pts[i]) * norm(pts[j]);
                    let quality = if len > 0.0 { g / len } else { 0.0 };
                    if g > 0.0 && g.is_finite() && best.is_none_or(|(_, qb)| quality > qb) {
                        best = Some(([l[0] / g, l[1] / g, l[2] / g], quality));
                    }
                }
            }
            let Some((line, _)) = best else { continue };
            // In pixel coordinates (X right, Y down, pixel centres at +0.5): the signed pixel
            // distance to the line is N . (X, Y) + c with N a unit vector.
            let nrm = [2.0 * line[0] / w, -2.0 * line[1] / h];
            let c = line[2] - line[0] + line[1];
            let tangent = [-nrm[1], nrm[0]];
            // Extent along the line, when every point of the face is in front of the eye (w > 0
            // at a, b and both directions to infinity): between the images of those points.
            let all_front = pts[..4].iter().all(|c| c[2] > 0.0);
            let extent = all_front.then(|| {
                let along = |c: &[f64; 3]| {
                    let (px, py) = ((c[0] / c[2] + 1.0) * 0.5 * w, (1.0 - c[1] / c[2]) * 0.5 * h);
                    px * tangent[0] + py * tangent[1]
                };
                let (lo, hi) = pts[..4]
                    .iter()
                    .map(along)
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, u), v| (l.min(v), u.max(v)));
                (lo - EDGE_ON_PIXELS, hi + EDGE_ON_PIXELS)
            });
            let mut mark = |x: i64, y: i64| {
                if x < 0 || y < 0 || x >= i64::from(width) || y >= i64::from(height) {
                    return;
                }
                let (px, py) = (x as f64 + 0.5, y as f64 + 0.5);
                if (nrm[0] * px + nrm[1] * py + c).abs() >= EDGE_ON_PIXELS {
                    return;
                }
                if let Some((lo, hi)) = extent {
                    let v = px * tangent[0] + py * tangent[1];
                    if v < lo || v > hi {
                        return;
                    }
                }
                let i = y as usize * width as usize + x as usize;
                if is_sample(i) {
                    band[i] = true;
                }
            };
            // Walk the line along its dominant axis, a few pixels across it at each step.
            let reach = EDGE_ON_PIXELS.ceil() as i64 + 1;
            if nrm[1].abs() >= nrm[0].abs() {
                for x in 0..i64::from(width) {
                    let yc = (-(c + nrm[0] * (x as f64 + 0.5)) / nrm[1] - 0.5).round() as i64;
                    for y in yc - reach..=yc + reach {
                        mark(x, y);
                    }
                }
            } else {
                for y in 0..i64::from(height) {
                    let xc = (-(c + nrm[1] * (y as f64 + 0.5)) / nrm[0] - 0.5).round() as i64;
                    for x in xc - reach..=xc + reach {
                        mark(x, y);
                    }
                }
            }
        }
    }
    slivers
}
