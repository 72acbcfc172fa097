//! Volume faces seen edge-on: where the rasterizer's coverage of a face and the depth it gives
//! the face disagree, and the sample's count can change although the face passes nowhere near
//! the sample.
//!
//! The mechanism (Mesa llvmpipe; Conference, default view at 640x360, pixel (114, 64)):
//! llvmpipe decides coverage with edge functions of the vertices snapped to
//! `GL_SUBPIXEL_BITS` (lp_setup_tri.c, `subpixel_snap`), but interpolates depth with a plane
//! equation set up from the unsnapped float window positions (lp_state_setup.c, `calc_coef4`;
//! see [`crate::envelope`]). A pixel centre covered by the snapped triangle may lie outside the
//! exact one, by up to the lateral bound `δ` ([`RasterView::lateral_pixels`]), and its depth is
//! then the face's *plane* extended beyond the face, along the pixel's ray. On a face seen at a
//! reasonable angle that depth is within `δ` pixels' worth of the face's boundary, and the
//! face across that boundary (the volume is closed: the face of the next edge through the same
//! extrusion ray, or the caster through the same edge) is covered at the same depth, so the
//! two cancel whatever the depth test says, unless the sample lies near that boundary (which
//! the envelope covers). On a face seen edge-on (the eye nearly in its plane: Conference's
//! pillar top edge, the eye 0.0064 units from the plane through the light and the edge) the
//! plane meets rays a fraction of a pixel apart at points hundreds of units apart: the pixel's
//! ray missed the face by 0.0009 pixel, the snapped face covered it, and its plane met the ray
//! 1,041 units from the eye, in front of the sample at 1,542, while the faces across its
//! boundary lay behind the sample: z-pass counted one face, a false shadow 500 units from the
//! face.
//!
//! The band this adds: the coverage can change only where the pixel centre lies within `δ` of
//! the projection of the face's boundary (its caster edge `A B` and its extrusion rays from `A`
//! and `B` away from the light), and the depth can then put the face on the other side of the
//! sample only if the face's plane passes within the sample's envelope (its radius `R` for
//! faces, [`crate::envelope`]): the face's depth at the pixel is its plane's along a ray within
//! `δ` of the pixel's, and the rays within `δ` of it meet the plane on both sides of the sample
//! only if the plane passes within `δ` footprints of it, which `R` bounds. So a sample is
//! [`BandParts::SIDE_FACE`] (an edge that casts) or [`BandParts::CANCELLING`] (one that does
//! not) when its pixel centre lies within `δ` of the projection of the boundary of the face of
//! an edge whose plane through the light passes within `R` of it. For a face seen at a
//! reasonable angle both conditions hold only near the face itself, which the envelope's
//! proximity test already marks; for a face seen edge-on they mark the thin line of pixels along
//! its projection where its plane passes near the samples.

use rayon::prelude::*;
use umbra_geom::vec3::{cross, dot, norm, sub};
use umbra_geom::WeldedMesh;

use crate::envelope::{BandParts, RasterView};

/// What one sample needs for the test: its position (on its triangle's plane) and the
/// envelope's radius for faces; `None` for samples the volumes do not decide (background, or
/// decided by the plane test).
pub(crate) type FaceEnvelope = Option<([f64; 3], f64)>;

/// The light as the faces are swept from it: a point, or the direction towards a directional
/// light.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Sweep {
    Point([f64; 3]),
    Towards([f64; 3]),
}

impl Sweep {
    /// The homogeneous point at infinity of the extrusion ray from `a` (away from the light).
    fn infinity(self, a: [f64; 3]) -> [f64; 4] {
        match self {
            Sweep::Point(l) => [a[0] - l[0], a[1] - l[1], a[2] - l[2], 0.0],
            Sweep::Towards(t) => [-t[0], -t[1], -t[2], 0.0],
        }
    }

    /// A normal of the plane through the light and the edge `a b` (zero when degenerate).
    fn face_normal(self, a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
        match self {
            Sweep::Point(l) => cross(sub(b, a), sub(l, a)),
            Sweep::Towards(t) => cross(sub(b, a), t),
        }
    }
}

/// Calls `f(x, y)` for every pixel centre `(x + 0.5, y + 0.5)` of a `width x height` image
/// within `delta` pixels of the segment `p q` (window coordinates, y down).
pub fn pixels_near_segment(p: [f64; 2], q: [f64; 2], delta: f64, width: u32, height: u32, mut f: impl FnMut(u32, u32)) {
    let (w, h) = (f64::from(width), f64::from(height));
    let d = [q[0] - p[0], q[1] - p[1]];
    let len2 = d[0] * d[0] + d[1] * d[1];
    let near = |c: [f64; 2]| {
        let t = if len2 > 0.0 { (((c[0] - p[0]) * d[0] + (c[1] - p[1]) * d[1]) / len2).clamp(0.0, 1.0) } else { 0.0 };
        (c[0] - p[0] - t * d[0]).hypot(c[1] - p[1] - t * d[1]) <= delta
    };
    // Walk the major axis; at each of its pixel centres the segment's minor coordinate (clamped
    // to the segment) and the centres within reach of it.
    let major = if d[0].abs() >= d[1].abs() { 0 } else { 1 };
    let minor = 1 - major;
    let (size_major, size_minor) = if major == 0 { (w, h) } else { (h, w) };
    let lo = (p[major].min(q[major]) - delta - 0.5).ceil().max(0.0);
    let hi = (p[major].max(q[major]) + delta - 0.5).floor().min(size_major - 1.0);
    if lo.is_nan() || hi.is_nan() || lo > hi {
        return;
    }
    // How far the minor coordinate of a point within `delta` can be from the segment's at the
    // same major coordinate (1 / cos of the segment's angle to the major axis), plus the ends.
    let slope = if d[major] != 0.0 { (d[minor] / d[major]).abs() } else { 0.0 };
    let reach = delta * (1.0 + slope * slope).sqrt() + delta * slope + delta;
    let mut k = lo;
    while k <= hi {
        let c = k + 0.5;
        let t = if d[major] != 0.0 { ((c - p[major]) / d[major]).clamp(0.0, 1.0) } else { 0.0 };
        let m = p[minor] + t * d[minor];
        let m_lo = (m - reach - 0.5).ceil().max(0.0);
        let m_hi = (m + reach - 0.5).floor().min(size_minor - 1.0);
        let mut j = m_lo;
        while j <= m_hi {
            let centre = if major == 0 { [c, j + 0.5] } else { [j + 0.5, c] };
            if near(centre) {
                let (x, y) = if major == 0 { (k, j) } else { (j, k) };
                f(x as u32, y as u32);
            }
            j += 1.0;
        }
        k += 1.0;
    }
}

/// The part of the homogeneous segment `a b` (clip `x, y, w`; what has `w < 0` lies behind the eye) inside
/// the viewport grown by `margin` NDC units, as window coordinates (y down); `None` if none.
pub(crate) fn clip_to_window(
    a: [f64; 3],
    b: [f64; 3],
    margin: f64,
    width: u32,
    height: u32,
) -> Option<([f64; 2], [f64; 2])> {
    let k = 1.0 + margin;
    // Planes p . (x, y, w) >= 0: the four sides, and w > 0 (a tiny fraction of the ends' w,
    // which the sides imply but for x = y = 0).
    let wmax = a[2].abs().max(b[2].abs());
    let planes = [[1.0, 0.0, k], [-1.0, 0.0, k], [0.0, 1.0, k], [0.0, -1.0, k], [0.0, 0.0, 1.0]];
    let (mut t0, mut t1) = (0f64, 1f64);
    for (i, pl) in planes.iter().enumerate() {
        let bias = if i == 4 { -1e-12 * wmax } else { 0.0 };
        let da = pl[0] * a[0] + pl[1] * a[1] + pl[2] * a[2] + bias;
        let db = pl[0] * b[0] + pl[1] * b[1] + pl[2] * b[2] + bias;
        if da < 0.0 && db < 0.0 {
            return None;
        }
        if da < 0.0 {
            t0 = t0.max(da / (da - db));
        } else if db < 0.0 {
            t1 = t1.min(da / (da - db));
        }
    }
    if t0.is_nan() || t1.is_nan() || t0 > t1 {
        return None;
    }
    let at = |t: f64| {
        let c = [0, 1, 2].map(|i| a[i] + t * (b[i] - a[i]));
        [(c[0] / c[2] + 1.0) * 0.5 * f64::from(width), (1.0 - c[1] / c[2]) * 0.5 * f64::from(height)]
    };
    let (p, q) = (at(t0), at(t1));
    (p.iter().chain(&q).all(|c| c.is_finite())).then_some((p, q))
}

/// Marks [`BandParts::SIDE_FACE`] or [`BandParts::CANCELLING`] (module doc) on `parts` for
/// every sample of `samples` (a `width x height` image, `size`) whose pixel centre lies within [`RasterView::lateral_pixels`] of
/// the projection of a face's boundary, the face's plane passing within the sample's radius.
/// `casts(a, b)` tells whether the edge `a b` (smaller index first) casts a side face.
/// `others` (sorted by pixel): the envelopes of other surfaces another depth pass may show at
/// a pixel ([`crate::seen_surface`]); a face that passes near one marks the pixel
/// [`BandParts::SEEN_SURFACE`] (that surface's decision is uncertain).
// The view, the light, the image and its samples, the casting edges and the output are the
// query itself; a struct would only rename them.
#[allow(clippy::too_many_arguments)]
pub(crate) fn mark_edge_on_faces(
    mesh: &WeldedMesh,
    view: &RasterView,
    sweep: Sweep,
    (width, height): (u32, u32),
    samples: &[FaceEnvelope],
    others: &[(usize, [f64; 3], f64)],
    casts: impl Fn([u32; 2]) -> bool + Sync,
    parts: &mut [BandParts],
) {
    let delta = view.lateral_pixels(width, height);
    // NDC margin of one pixel: a boundary just outside the viewport still reaches the border
    // pixels' centres within delta.
    let margin = 2.0 / f64::from(width.min(height).max(1));
    let pos = |k: u32| mesh.positions[k as usize].map(f64::from);
    // Every edge once (smaller index first), and each vertex's edges.
    let mut edges: Vec<[u32; 2]> = mesh
        .triangles
        .iter()
        .flat_map(|t| (0..3).map(move |k| [t[k].min(t[(k + 1) % 3]), t[k].max(t[(k + 1) % 3])]))
        .collect();
    edges.par_sort_unstable();
    edges.dedup();
    let mut start = vec![0usize; mesh.positions.len() + 1];
    for e in &edges {
        start[e[0] as usize + 1] += 1;
        start[e[1] as usize + 1] += 1;
    }
    for v in 0..mesh.positions.len() {
        start[v + 1] += start[v];
    }
    let mut fill = start.clone();
    let mut incident = vec![0u32; start[mesh.positions.len()]];
    for (i, e) in edges.iter().enumerate() {
        for v in e {
            incident[fill[*v as usize]] = i as u32;
            fill[*v as usize] += 1;
        }
    }
    // The face's plane (unit normal, through `a`) and its part.
    let face = |e: [u32; 2]| -> Option<([f64; 3], [f64; 3], BandParts)> {
        let (a, b) = (pos(e[0]), pos(e[1]));
        let n = sweep.face_normal(a, b);
        let len = norm(n);
        (len > 0.0 && len.is_finite()).then(|| {
            let part = if casts(e) { BandParts::SIDE_FACE } else { BandParts::CANCELLING };
            (n.map(|c| c / len), a, part)
        })
    };
    let clip = |p: [f64; 4]| {
        let m = &view.clip_from_world;
        let row = |r: usize| m[r] * p[0] + m[4 + r] * p[1] + m[8 + r] * p[2] + m[12 + r] * p[3];
        [row(0), row(1), row(3)]
    };
    // Boundaries: the extrusion ray of every vertex (shared by the faces of its edges) and
    // every edge (its own face's).
    let test = |pixel: usize, faces: &mut dyn Iterator<Item = [u32; 2]>, hits: &mut Vec<(usize, BandParts)>| {
        let first = others.partition_point(|o| o.0 < pixel);
        let rest = &others[first..others.partition_point(|o| o.0 <= pixel)];
        if samples[pixel].is_none() && rest.is_empty() {
            return;
        }
        for e in faces {
            if let Some((n, a, part)) = face(e) {
                if let Some((s, radius)) = samples[pixel] {
                    if dot(n, sub(s, a)).abs() <= radius {
                        hits.push((pixel, part));
                    }
                }
                if rest.iter().any(|&(_, s, radius)| dot(n, sub(s, a)).abs() <= radius) {
                    hits.push((pixel, BandParts::SEEN_SURFACE));
                }
            }
        }
    };
    let index = |x: u32, y: u32| y as usize * width as usize + x as usize;
    let from_rays: Vec<(usize, BandParts)> = (0..mesh.positions.len())
        .into_par_iter()
        .filter(|&v| start[v + 1] > start[v])
        .fold(Vec::new, |mut hits, v| {
            let a = pos(v as u32);
            // The ray from `a` to its point at infinity is the homogeneous segment between
            // them (positive weights); clipping it in clip space drops what lies behind the eye.
            if let Some((p, q)) =
                clip_to_window(clip([a[0], a[1], a[2], 1.0]), clip(sweep.infinity(a)), margin, width, height)
            {
                pixels_near_segment(p, q, delta, width, height, |x, y| {
                    let mut faces = incident[start[v]..start[v + 1]].iter().map(|&i| edges[i as usize]);
                    test(index(x, y), &mut faces, &mut hits);
                });
            }
            hits
        })
        .flatten()
        .collect();
    let from_edges: Vec<(usize, BandParts)> = edges
        .par_iter()
        .fold(Vec::new, |mut hits, &e| {
            let (a, b) = (pos(e[0]), pos(e[1]));
            let (ca, cb) = (clip([a[0], a[1], a[2], 1.0]), clip([b[0], b[1], b[2], 1.0]));
            if let Some((p, q)) = clip_to_window(ca, cb, margin, width, height) {
                pixels_near_segment(p, q, delta, width, height, |x, y| {
                    test(index(x, y), &mut std::iter::once(e), &mut hits);
                });
            }
            hits
        })
        .flatten()
        .collect();
    for (i, part) in from_rays.into_iter().chain(from_edges) {
        parts[i] |= part;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::envelope::segment_segment_distance;
    use crate::SampleClass;
    use umbra_geom::camera::Camera;

    /// Every pixel centre within `delta` of `p q`, by brute force.
    fn brute(p: [f64; 2], q: [f64; 2], delta: f64, width: u32, height: u32) -> Vec<(u32, u32)> {
        let mut out = Vec::new();
        for y in 0..height {
            for x in 0..width {
                let c = [f64::from(x) + 0.5, f64::from(y) + 0.5, 0.0];
                if segment_segment_distance(c, c, [p[0], p[1], 0.0], [q[0], q[1], 0.0]) <= delta {
                    out.push((x, y));
                }
            }
        }
        out
    }

    #[test]
    fn pixels_near_segment_finds_exactly_the_centres_within_delta() {
        let segments = [
            ([0.2, 0.3], [29.7, 17.1]),
            ([3.5, -4.0], [3.5, 40.0]),
            ([-10.0, 7.5], [50.0, 7.5]),
            ([12.49, 5.51], [12.49, 5.51]),
            ([25.0, 2.0], [1.0, 19.0]),
            ([8.5, 9.5], [9.5, 10.5]),
            ([-5.0, -5.0], [-1.0, -2.0]),
        ];
        for (p, q) in segments {
            for delta in [0.0065, 0.1, 0.5, 1.3] {
                let mut got = Vec::new();
                pixels_near_segment(p, q, delta, 30, 20, |x, y| got.push((x, y)));
                got.sort_by_key(|&(x, y)| (y, x));
                assert_eq!(got, brute(p, q, delta, 30, 20), "segment {p:?} {q:?}, delta {delta}");
            }
        }
    }

    #[test]
    fn homogeneous_clip_keeps_what_lies_in_front_of_the_eye() {
        // From the centre (w = 1) to a point behind the eye (w = -1) straight right: the ray
        // leaves the viewport on the right before it reaches w = 0.
        let (p, q) = clip_to_window([0.0, 0.0, 1.0], [1.0, 0.0, -1.0], 0.0, 100, 100).unwrap();
        assert!((p[0] - 50.0).abs() < 1e-9 && (q[0] - 100.0).abs() < 1e-9, "{p:?} {q:?}");
        // Wholly behind the eye.
        assert!(clip_to_window([0.0, 0.0, -1.0], [0.5, 0.0, -2.0], 0.0, 100, 100).is_none());
    }

    /// Conference (`/work/shared/scenes/conference.obj.gz`), default view at 640x360, default
    /// point light: the sample at pixel (114, 64) on the wall strip (triangle 737) and the
    /// pillar (triangle 204361) whose top edge's face every rasterizing method counted there
    /// on llvmpipe (a false shadow). The eye lies 0.0064 units from the plane through the light
    /// and that edge; the face passes hundreds of units from the sample, its projection
    /// 0.0009 pixel from the pixel centre.
    use crate::pinned::PinnedView as Conference;

    fn conference() -> Conference {
        let f = |b: [u32; 3]| b.map(f32::from_bits);
        let wall = [
            [1154394112, 1142516466, 3296404603],
            [1154394112, 1143116481, 3296404603],
            [3294799528, 1142516466, 3296404603],
        ];
        let pillar = [
            [1150092001, 1143116481, 3296664289],
            [1150074061, 1143116481, 3296732119],
            [1150074061, 1129502015, 3296732119],
        ];
        let mut positions: Vec<[f32; 3]> = wall.map(f).to_vec();
        positions.extend(pillar.map(f));
        Conference {
            positions,
            triangles: vec![[0, 1, 2], [3, 4, 5]],
            light: [630.4934, 454.36743, -72.89507, 1.0],
            // The GPU's interpolated position (1058.0953, 634.14587, -1004.57013).
            sample: f([1149518605, 1142851926, 3296404605]),
            camera: Camera {
                eye: [-208.34796142578125, 291.09605226516726, -193.58551025390625],
                target: [874.0280151367188, 193.13323488235474, -193.58551025390625],
                up: [0.0, 1.0, 0.0],
                fov_y_degrees: 60.0,
                near: 3.274343017578125,
                ..Camera::default()
            },
        }
    }

    /// The band parts of `scene`'s sample at 640x360 with llvmpipe's 8 sub-pixel bits.
    fn sample_parts(scene: &Conference) -> ((u32, u32), SampleClass, BandParts) {
        scene.judged(8, false, (640, 360))
    }

    #[test]
    fn conference_pillar_face_seen_edge_on_is_side_face_band() {
        let scene = conference();
        let (pixel, class, parts) = sample_parts(&scene);
        assert_eq!(pixel, (114, 64));
        assert_eq!(class, SampleClass::Lit);
        assert!(parts.contains(BandParts::SIDE_FACE), "{:?}", parts.names());
        // The face of the pillar's top edge passes nowhere near the sample: the segment to the
        // light misses the edge by tens of units (a pixel here is 4 units across), so the
        // envelope's proximity test alone does not mark it.
        let l = scene.light.map(f64::from);
        let (a, b) = (scene.positions[3].map(f64::from), scene.positions[4].map(f64::from));
        let d = segment_segment_distance(scene.sample.map(f64::from), [l[0], l[1], l[2]], a, b);
        assert!(d > 10.0, "{d}");
    }

    #[test]
    fn the_same_face_seen_from_off_its_plane_is_not_band() {
        // The eye 20 units off the plane (and the target with it): the face is seen at an
        // angle, its projection many pixels from the sample's.
        let mut scene = conference();
        scene.camera.eye[2] += 20.0;
        scene.camera.target[2] += 20.0;
        let (_, class, parts) = sample_parts(&scene);
        assert_eq!(class, SampleClass::Lit);
        assert!(!parts.contains(BandParts::SIDE_FACE), "{:?}", parts.names());
    }
}
