//! The per-sample shadow reference: which rasterized samples are in shadow, decided by ray
//! casting on the CPU, and the band of samples whose decision lies within the precision of
//! the rasterizer and the depth test ([`crate::envelope`]).
//!
//! Definition (the project issue "verify: per-sample exactness", followed exactly):
//! * Triangles are two-sided occluders: any triangle casts a shadow whichever way it faces.
//! * A sample `S` on triangle `T` is in shadow iff the camera and the light are on opposite
//!   sides of `T`'s plane (the side we see faces away from the light), or the segment from `S`
//!   to the light hits another triangle with `t` in `(eps, 1 - eps)`. For a directional light
//!   (`w = 0`) the segment is the ray towards the light (direction `xyz`), `t` in `(eps, inf)`.
//! * Band: the samples for which some part of the machinery's decision lies within its
//!   precision ([`BandParts`], defined once in [`crate::envelope`] from the GL spec's depth and
//!   sub-pixel precision and llvmpipe's interpolation): a volume face, or another surface,
//!   passing within the sample's precision envelope, a facing decided within rounding, the
//!   reference's own tolerance, the near plane's cut. Computed per sample; nothing else is
//!   band (no neighbourhood rule; docs/exactness.md).
//!
//! Choices made here, each explained where it is implemented:
//! * The plane test is done in `f64` from the `f32` vertices of `T` (the cross product of two
//!   `f32` differences is then nearly exact), and `S` is first projected onto `T`'s plane.
//! * `T` itself is excluded from the occlusion test; its neighbours are not.
//! * `eps` is a *distance*, [`segment_epsilon`] = `1e-5` of the scene's scale.

use rayon::prelude::*;
use umbra_geom::vec3::{cross, dot, norm, sub};
use umbra_geom::{Light, WeldedMesh};

use crate::bvh::Bvh;
use crate::edge_on::{mark_edge_on_faces, FaceEnvelope, Sweep};
use crate::envelope::{
    casting_edges, point_triangle_distance, segment_segment_distance, segment_triangle_distance, BandParts, Casting,
    RasterView, LIGHTING_DOT,
};
use crate::seen_surface::near_edges;
use crate::OracleError;

mod surfaces;

/// A sample's position (on its triangle's plane) and its envelope's radius for volume faces.
type Envelope = ([f64; 3], f64);

/// Relative size of the self-intersection epsilon, see [`segment_epsilon`].
pub const EPSILON_RELATIVE: f64 = 1e-5;

/// The rasterized samples read back from the GPU, one per pixel, row-major, TOP row first.
#[derive(Clone, Copy, Debug)]
pub struct Samples<'a> {
    pub width: u32,
    pub height: u32,
    /// World position of the sample (the interpolated vertex position).
    pub world_pos: &'a [[f32; 3]],
    /// Index into `WeldedMesh::triangles` (gl_PrimitiveID); `u32::MAX` = background.
    pub triangle: &'a [u32],
}

/// Class of one pixel in the reference.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize)]
pub enum SampleClass {
    /// No triangle was rasterized here.
    Background,
    Lit,
    Shadowed,
}

/// The reference for one image: per pixel (row-major, top row first) its class and whether it
/// lies in the shadow-boundary band.
#[derive(Clone, Debug, PartialEq)]
pub struct Reference {
    pub width: u32,
    pub height: u32,
    pub class: Vec<SampleClass>,
    /// Band for every method: some part of [`Reference::parts`] is set.
    pub band: Vec<bool>,
    /// Which parts of each sample's decision lie within the machinery's precision
    /// ([`crate::envelope`]); a method is judged by the parts that apply to it
    /// ([`crate::compare_masked`]).
    pub parts: Vec<BandParts>,
}

/// The self-intersection epsilon, a world-space distance: `1e-5` of the scene's scale, where
/// the scale is the larger of the bounding-box diagonal and the largest absolute coordinate.
///
/// Why this size: the sample positions come from the GPU rasterizer, interpolated in `f32`, so
/// they are off by a few ulp of the *absolute* coordinates (`2^-24 |x|` ~ `6e-8 |x|` per
/// rounding, a few tens of roundings at most): `1e-5` is two orders of magnitude above that.
/// It must also stay far below one pixel's footprint so that the only samples it can
/// misclassify — those within `eps` of a concave crease whose other face occludes them, or of
/// an occluder touching the surface — lie inside the one-pixel band anyway; at 1280x720 a pixel
/// spans ~`1e-3` of a scene seen whole, so `1e-5` leaves a factor of ~100 on both sides.
/// An empty scene gets `eps = 0`.
pub fn segment_epsilon(positions: &[[f32; 3]]) -> f64 {
    let mut min = [f64::INFINITY; 3];
    let mut max = [f64::NEG_INFINITY; 3];
    let mut largest = 0f64;
    for p in positions {
        if p.iter().any(|c| !c.is_finite()) {
            continue;
        }
        for k in 0..3 {
            let c = p[k] as f64;
            min[k] = min[k].min(c);
            max[k] = max[k].max(c);
            largest = largest.max(c.abs());
        }
    }
    if min[0] > max[0] {
        // No finite position at all.
        return 0.0;
    }
    let diagonal = (0..3).map(|k| (max[k] - min[k]).powi(2)).sum::<f64>().sqrt();
    EPSILON_RELATIVE * diagonal.max(largest)
}

/// Computes the reference for `samples` rendered from `eye` with `light`, in parallel over rows.
///
/// `bvh` must have been built from `mesh.positions` / `mesh.triangles` (checked by count).
pub fn reference(
    mesh: &WeldedMesh,
    bvh: &Bvh,
    samples: &Samples,
    light: Light,
    eye: [f32; 3],
) -> Result<Reference, OracleError> {
    reference_in_view(mesh, bvh, samples, light, eye, None)
}

/// [`reference()`] with the view the samples were rasterized with, which adds the depth-test
/// and rasterizer terms to each sample's envelope and the near plane's cut
/// ([`crate::envelope`]). `umbra verify` and the torture suite use this.
pub fn reference_in_view(
    mesh: &WeldedMesh,
    bvh: &Bvh,
    samples: &Samples,
    light: Light,
    eye: [f32; 3],
    view: Option<&RasterView>,
) -> Result<Reference, OracleError> {
    let (width, height) = (samples.width, samples.height);
    let pixels = width as usize * height as usize;
    check_len("world_pos", samples.world_pos.len(), pixels, width, height)?;
    check_len("triangle", samples.triangle.len(), pixels, width, height)?;
    if bvh.triangle_count() != mesh.triangles.len() {
        return Err(OracleError::BvhMismatch { bvh: bvh.triangle_count(), mesh: mesh.triangles.len() });
    }
    let light_ok = light.iter().all(|c| c.is_finite()) && (light[3] != 0.0 || light[..3].iter().any(|&c| c != 0.0));
    if !light_ok {
        return Err(OracleError::InvalidLight { light });
    }
    if eye.iter().any(|c| !c.is_finite()) {
        return Err(OracleError::InvalidEye { eye });
    }
    for (i, (&t, p)) in samples.triangle.iter().zip(samples.world_pos).enumerate() {
        if t == u32::MAX {
            continue;
        }
        let (x, y) = ((i % width as usize) as u32, (i / width as usize) as u32);
        if t as usize >= mesh.triangles.len() {
            return Err(OracleError::TriangleOutOfRange { x, y, triangle: t, triangles: mesh.triangles.len() });
        }
        if p.iter().any(|c| !c.is_finite()) {
            return Err(OracleError::NonFiniteSample { x, y, position: *p });
        }
        // Vertex indices of a WeldedMesh are in range by construction, but its fields are
        // public: check the one we will read.
        if let Some(&v) = mesh.triangles[t as usize].iter().find(|&&v| v as usize >= mesh.positions.len()) {
            return Err(OracleError::VertexOutOfRange {
                triangle: t as usize,
                vertex: v,
                vertices: mesh.positions.len(),
            });
        }
    }

    let ctx = Context::new(mesh, bvh, light, eye, view, width, height);
    let mut class = vec![SampleClass::Background; pixels];
    let mut parts = vec![BandParts::NONE; pixels];
    let mut envelopes: Vec<FaceEnvelope> = vec![None; pixels];
    if width > 0 {
        class
            .par_chunks_mut(width as usize)
            .zip(parts.par_chunks_mut(width as usize))
            .zip(envelopes.par_chunks_mut(width as usize))
            .enumerate()
            .for_each(|(row, ((class_row, parts_row), envelope_row))| {
                let start = row * width as usize;
                for x in 0..width as usize {
                    let t = samples.triangle[start + x];
                    if t == u32::MAX {
                        continue;
                    }
                    let (c, p, e) = ctx.classify(t, samples.world_pos[start + x]);
                    class_row[x] = c;
                    parts_row[x] = p;
                    envelope_row[x] = e;
                }
            });
    }
    if let Some(v) = view {
        mark_near_cut(mesh, v, width, height, &mut parts, |i| class[i] != SampleClass::Background);
        let sweep = match ctx.point {
            Some(p) => Sweep::Point(p),
            None => Sweep::Towards(ctx.towards),
        };
        let near = near_edges(mesh, v, (width, height), |i| {
            class[i] != SampleClass::Background && !parts[i].intersects(BandParts::SILHOUETTE)
        });
        ctx.mark_nearer_contours(samples, &near, &mut parts);
        let others =
            if v.other_depth_pass { ctx.seen_surfaces(samples, &near, &class, &mut parts) } else { Vec::new() };
        let casting = &ctx.casting.edges;
        mark_edge_on_faces(mesh, v, sweep, (width, height), &envelopes, &others, |e| casting.contains(&e), &mut parts);
    }
    let band = parts.iter().map(|p| *p != BandParts::NONE).collect();
    Ok(Reference { width, height, class, band, parts })
}

fn check_len(what: &'static str, actual: usize, expected: usize, width: u32, height: u32) -> Result<(), OracleError> {
    if actual != expected {
        return Err(OracleError::SizeMismatch { what, expected, actual, width, height });
    }
    Ok(())
}

fn to_f64(p: [f32; 3]) -> [f64; 3] {
    p.map(|c| c as f64)
}

/// Everything one light of one view shares: the scene, the light and eye in f64, the
/// view's precision, the edges that cast side faces.
struct Context<'a> {
    mesh: &'a WeldedMesh,
    bvh: &'a Bvh,
    eps: f64,
    /// Point light position, or `None` for a directional light.
    point: Option<[f64; 3]>,
    /// Direction *towards* a directional light (the light's `xyz`).
    towards: [f64; 3],
    eye: [f64; 3],
    view: Option<&'a RasterView>,
    width: u32,
    height: u32,
    /// [`RasterView::lateral_pixels`] of this image (0 without a view).
    lateral_pixels: f64,
    casting: Casting,
    /// Centre and half diagonal of the scene's box: how far a directional light's ray must
    /// reach to leave the scene.
    centre: [f64; 3],
    half_diagonal: f64,
}

impl<'a> Context<'a> {
    fn new(
        mesh: &'a WeldedMesh,
        bvh: &'a Bvh,
        light: Light,
        eye: [f32; 3],
        view: Option<&'a RasterView>,
        width: u32,
        height: u32,
    ) -> Context<'a> {
        let xyz = [light[0] as f64, light[1] as f64, light[2] as f64];
        let w = light[3] as f64;
        let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        for p in &mesh.positions {
            if p.iter().all(|c| c.is_finite()) {
                for k in 0..3 {
                    lo[k] = lo[k].min(f64::from(p[k]));
                    hi[k] = hi[k].max(f64::from(p[k]));
                }
            }
        }
        let (centre, half_diagonal) = if lo[0] <= hi[0] {
            ([0, 1, 2].map(|k| 0.5 * (lo[k] + hi[k])), 0.5 * norm(sub(hi, lo)))
        } else {
            ([0.0; 3], 0.0)
        };
        Context {
            mesh,
            bvh,
            eps: segment_epsilon(&mesh.positions),
            point: (w != 0.0).then(|| xyz.map(|c| c / w)),
            towards: xyz,
            eye: eye.map(f64::from),
            view,
            width,
            height,
            lateral_pixels: view.map_or(0.0, |v| v.lateral_pixels(width, height)),
            casting: casting_edges(mesh, light),
            centre,
            half_diagonal,
        }
    }

    /// Where the pixel's ray through `p` starts: the eye, or, in an orthographic view, the
    /// point of the eye's plane behind `p` (the ray runs along the view direction). Any point
    /// on that ray behind `p` gives the same directions and sides; a point behind the eye's
    /// plane gets the one as far in front of it, so it still looks along the view direction.
    /// Position margins keep the camera's own eye (the larger distance).
    fn eye_for(&self, p: [f64; 3]) -> [f64; 3] {
        match self.view.and_then(|v| v.orthographic_forward) {
            None => self.eye,
            Some(f) => {
                let d = dot(sub(p, self.eye), f).abs();
                let d = if d > 0.0 { d } else { 1.0 };
                [0, 1, 2].map(|k| p[k] - d * f[k])
            }
        }
    }

    fn vertex(&self, k: u32) -> [f64; 3] {
        to_f64(self.mesh.positions[k as usize])
    }

    /// The exact segment (or ray) from `from` towards the light, as (direction, t range).
    fn segment(&self, from: [f64; 3]) -> Option<([f64; 3], f64, f64)> {
        match self.point {
            Some(p) => {
                let to_light = sub(p, from);
                // Parametric t along S -> light: eps as a distance is eps / |L| in t.
                let t_eps = self.eps / dot(to_light, to_light).sqrt();
                // A sample within 2 eps of the light: the segment is empty, nothing can occlude.
                (t_eps < 0.5).then_some((to_light, t_eps, 1.0 - t_eps))
            }
            None => {
                let len = dot(self.towards, self.towards).sqrt();
                Some((self.towards.map(|c| c / len), self.eps, f64::INFINITY))
            }
        }
    }

    /// Class and band parts of one sample at `world_pos` on triangle `triangle` (in range), and
    /// what [`crate::edge_on`] needs of it (with a view, when the volumes decide it).
    fn classify(&self, triangle: u32, world_pos: [f32; 3]) -> (SampleClass, BandParts, FaceEnvelope) {
        let tri = self.mesh.triangles[triangle as usize].map(|k| self.vertex(k));
        let [a, b, c] = tri;
        // Differences of f32 values are exact in f64, and so is each product of two of them:
        // the normal is rounded only by the final subtractions.
        let n = cross(sub(b, a), sub(c, a));
        let nn = dot(n, n);
        // Project S onto T's plane: the interpolated GPU position is off the plane by rounding,
        // and on the wrong side of it the ray towards the light could start behind a coplanar
        // or adjacent surface. On the plane, only true occluders or ones within eps remain.
        let mut s = to_f64(world_pos);
        if nn > 0.0 {
            let k = dot(n, sub(s, a)) / nn;
            s = [s[0] - k * n[0], s[1] - k * n[1], s[2] - k * n[2]];
        }
        // L: from S towards the light, and which side of T's plane the light is on.
        let (to_light, light_side) = match self.point {
            Some(p) => (sub(p, s), dot(n, sub(p, a))),
            None => (self.towards, dot(n, self.towards)),
        };
        let eye_side = dot(n, sub(self.eye_for(s), a));
        let ll = dot(to_light, to_light);
        let position = RasterView::position_margin(s, self.eye);

        // FACING: the lighting pass's `n.l > 0` in f32 (from the f32 unit normal and the
        // interpolated position, which subtends `position / |L|` at a point light), the
        // rasterizer's gl_FrontFacing from snapped vertices, and T's own f32 orientation
        // towards the light, which orients its volume. A degenerate T (N = 0) or a sample at
        // the light (L = 0) has no defined angle.
        let mut parts = BandParts::NONE;
        let nl = dot(n, to_light);
        let tau = LIGHTING_DOT + if self.point.is_some() && ll > 0.0 { position / ll.sqrt() } else { 0.0 };
        let facing = nn == 0.0
            || ll == 0.0
            || nl * nl <= tau * tau * nn * ll
            || self.casting.uncertain[triangle as usize]
            || self.view.is_some_and(|v| v.facing_uncertain(tri, self.width, self.height));
        if facing {
            parts |= BandParts::FACING;
        }

        // Plane test: the side we see faces away from the light. Then the lighting pass does
        // not light the sample whatever the volumes count: only its facing can be wrong. A zero
        // on either side (camera or light in T's plane) is undecided here and falls through to
        // the ray; such a sample is FACING band (or not rasterized at all).
        if (eye_side > 0.0 && light_side < 0.0) || (eye_side < 0.0 && light_side > 0.0) {
            return (SampleClass::Shadowed, parts, None);
        }

        // Occlusion test. T itself is skipped: S lies on it, so it could only be met at t ~ 0,
        // where the answer is rounding noise, and its facing was decided by the plane test
        // above. Neighbours of T are NOT skipped: across a concave crease a neighbour really
        // does shadow T (a wall shading the floor); a coplanar neighbour meets the ray only at
        // t ~ 0 < eps.
        let Some((dir, t_min, t_max)) = self.segment(s) else {
            return (SampleClass::Lit, parts, None);
        };
        let occluded = self.bvh.occluded(s, dir, t_min, t_max, triangle);
        let class = if occluded { SampleClass::Shadowed } else { SampleClass::Lit };

        // The envelope's radius for volume faces and for other surfaces (crate::envelope): half
        // the lateral bound is the other primitive's, half the sample's own triangle's, which
        // moves S along T's plane, stretched by 1 / |cos| of the angle T is seen at.
        let (lateral, slope, oblique) = self.lateral(n, nn, s);
        if oblique {
            parts |= BandParts::FACING;
        }
        let depth_for = |r: f64| if slope > 0.0 { crate::envelope::DEPTH_STEPS * r / slope } else { 0.0 };
        let face_radius = position + lateral + self.view.map_or(0.0, |v| depth_for(v.face_depth_step()));
        parts |= self.faces_near(triangle, s, dir, face_radius);

        // SURFACE: another triangle, not in T's plane, within the envelope of S. Its `r` is
        // the larger of T's and its own (both were depth-tested in the depth pass).
        let own_step = self.view.map_or(0.0, |v| v.triangle_depth_step(tri));
        let nlen = nn.sqrt();
        self.bvh.triangles_near_point(
            s,
            face_radius.max(position + lateral + depth_for(own_step)),
            triangle,
            |_, v| {
                let v = v.map(to_f64);
                let d = point_triangle_distance(s, v);
                let radius = position
                    + lateral
                    + self.view.map_or(0.0, |view| depth_for(own_step.max(view.triangle_depth_step(v))));
                let coplanar = nlen > 0.0 && v.iter().all(|&p| (dot(n, sub(p, a)) / nlen).abs() <= position);
                if d <= radius && !coplanar {
                    parts |= BandParts::SURFACE;
                    return true;
                }
                false
            },
        );

        // REFERENCE_EPS: lit only because the segment test skips the first eps. The range
        // starts at t_min / 1024, not 0: a hit at t ~ 0 is a surface through S itself (a
        // coplanar neighbour met on its shared edge; SURFACE covers the others).
        if !occluded && t_min > 0.0 && self.bvh.occluded(s, dir, t_min / 1024.0, t_min, triangle) {
            parts |= BandParts::REFERENCE_EPS;
        }
        (class, parts, self.view.map(|_| (s, face_radius)))
    }

    /// The envelope's lateral radius at `s` on a triangle of normal `n` (`nn = n.n`) and the
    /// slope of window depth along the view ray there (crate::envelope): half the lateral
    /// bound is the other primitive's, half the sample's own triangle's, which moves S along
    /// T's plane, stretched by 1 / |cos| of the angle T is seen at. `true` when T is seen so
    /// obliquely that the snapping moves S along T by more than a pixel: its position, and so
    /// its decision, is the rasterizer's choice (FACING).
    fn lateral(&self, n: [f64; 3], nn: f64, s: [f64; 3]) -> (f64, f64, bool) {
        let Some(v) = self.view else { return (0.0, 0.0, false) };
        let half = 0.5 * self.lateral_pixels;
        let eye = self.eye_for(s);
        let view_dir = sub(s, eye);
        let cos = dot(n, view_dir).abs() / (nn.sqrt() * norm(view_dir));
        let stretch = if cos > half { 1.0 / cos } else { 1.0 / half };
        (half * (1.0 + stretch) * v.footprint(s, self.width, self.height), v.depth_slope(s, eye), cos <= half)
    }

    /// The envelope's radius for volume faces of a sample at `s` on triangle `tri`.
    fn face_radius(&self, tri: [[f64; 3]; 3], s: [f64; 3]) -> f64 {
        let [a, b, c] = tri;
        let n = cross(sub(b, a), sub(c, a));
        let (lateral, _, _) = self.lateral(n, dot(n, n), s);
        let depth = self.view.map_or(0.0, |v| v.depth_margin(s, self.eye_for(s)));
        RasterView::position_margin(s, self.eye) + lateral + depth
    }

    /// SIDE_FACE, CANCELLING and ORIENTATION: the edges (and triangles of uncertain
    /// orientation) the segment from `s` towards the light passes within `radius` of, from
    /// `radius` behind `s` on. `triangle` (the sample's own) takes part with its edges.
    fn faces_near(&self, triangle: u32, s: [f64; 3], dir: [f64; 3], radius: f64) -> BandParts {
        let len = norm(dir);
        if !(len > 0.0 && radius.is_finite()) {
            return BandParts::NONE;
        }
        let t_lo = -radius / len;
        let t_hi = match self.point {
            Some(_) => 1.0,
            // Far enough to leave the scene's box.
            None => (norm(sub(s, self.centre)) + self.half_diagonal + radius) / len,
        };
        let p0 = [0, 1, 2].map(|k| s[k] + t_lo * dir[k]);
        let p1 = [0, 1, 2].map(|k| s[k] + t_hi * dir[k]);
        let all = BandParts::SIDE_FACE | BandParts::CANCELLING | BandParts::ORIENTATION;
        let mut parts = BandParts::NONE;
        self.bvh.triangles_near_segment(s, dir, t_lo, t_hi, u32::MAX, radius, |id, v| {
            let v = v.map(to_f64);
            let ids = self.mesh.triangles[id as usize];
            for k in 0..3 {
                let (i, j) = (ids[k], ids[(k + 1) % 3]);
                if !parts.contains(all & !BandParts::ORIENTATION)
                    && segment_segment_distance(p0, p1, v[k], v[(k + 1) % 3]) <= radius
                {
                    parts |= if self.casting.edges.contains(&[i.min(j), i.max(j)]) {
                        BandParts::SIDE_FACE
                    } else {
                        BandParts::CANCELLING
                    };
                }
            }
            if id != triangle
                && self.casting.uncertain[id as usize]
                && !parts.contains(BandParts::ORIENTATION)
                && segment_triangle_distance(p0, p1, v) <= radius
            {
                parts |= BandParts::ORIENTATION;
            }
            parts.contains(all)
        });
        parts
    }
}

/// NEAR_CUT (crate::envelope): marks the samples whose pixel centre lies within
/// [`RasterView::lateral_pixels`] of the image of a triangle's cut by the near plane (clip
/// `z = -w` standard, `z = w` reversed-Z: the depth pass's clip and the light caps'
/// `gl_ClipDistance[0]`, shared/depth.glsl, cut there with different arithmetic).
fn mark_near_cut(
    mesh: &WeldedMesh,
    view: &RasterView,
    width: u32,
    height: u32,
    parts: &mut [BandParts],
    is_sample: impl Fn(usize) -> bool,
) {
    let m = &view.clip_from_world;
    let reversed = view.reversed();
    let row = |r: usize, p: [f64; 3]| m[r] * p[0] + m[4 + r] * p[1] + m[8 + r] * p[2] + m[12 + r];
    // Signed distance to the near plane in clip units (positive in front), as shared/depth.glsl.
    let near = |p: [f64; 3]| if reversed { row(3, p) - row(2, p) } else { row(3, p) + row(2, p) };
    let reach = view.lateral_pixels(width, height);
    for t in &mesh.triangles {
        let v = t.map(|k| to_f64(mesh.positions[k as usize]));
        let d = v.map(near);
        if d.iter().all(|&x| x > 0.0) || d.iter().all(|&x| x < 0.0) || d.iter().any(|x| !x.is_finite()) {
            continue;
        }
        let mut cut = Vec::new();
        for k in 0..3 {
            let (p, q, dp, dq) = (v[k], v[(k + 1) % 3], d[k], d[(k + 1) % 3]);
            if dp == 0.0 {
                cut.push(p);
            } else if (dp < 0.0) != (dq < 0.0) && dq != 0.0 {
                let s = dp / (dp - dq);
                cut.push([0, 1, 2].map(|i| p[i] + s * (q[i] - p[i])));
            }
        }
        let ends: Vec<[f64; 2]> = cut.iter().filter_map(|&p| view.window_xy(p, width, height)).collect();
        if ends.len() < 2 {
            continue;
        }
        let (a, b) = (ends[0], ends[ends.len() - 1]);
        let lo = [a[0].min(b[0]) - reach - 1.0, a[1].min(b[1]) - reach - 1.0];
        let hi = [a[0].max(b[0]) + reach + 1.0, a[1].max(b[1]) + reach + 1.0];
        let x0 = lo[0].floor().max(0.0) as i64;
        let y0 = lo[1].floor().max(0.0) as i64;
        let x1 = (hi[0].ceil() as i64).min(i64::from(width) - 1);
        let y1 = (hi[1].ceil() as i64).min(i64::from(height) - 1);
        for y in y0..=y1 {
            for x in x0..=x1 {
                let c = [x as f64 + 0.5, y as f64 + 0.5, 0.0];
                if segment_segment_distance(c, c, [a[0], a[1], 0.0], [b[0], b[1], 0.0]) <= reach {
                    let i = y as usize * width as usize + x as usize;
                    if is_sample(i) {
                        parts[i] |= BandParts::NEAR_CUT;
                    }
                }
            }
        }
    }
}

/// The one-pixel neighbourhood rule, a measure only (not part of the reference's band,
/// [`crate::envelope`]): a non-background sample whose 3x3 neighbourhood (itself included, clipped at the
/// image border) holds both a lit and a shadowed sample, or that is grazing.
///
/// Background neighbours do not count as a class: the edge between a surface and the empty
/// background is a silhouette, not a shadow boundary, and nothing about the sample's shadow
/// is uncertain there. Background pixels themselves are never band.
///
/// `class` and `grazing` are row-major with `width * height` entries (shorter slices are
/// treated as background beyond their end).
pub fn boundary_band(width: u32, height: u32, class: &[SampleClass], grazing: &[bool]) -> Vec<bool> {
    let (w, h) = (width as usize, height as usize);
    let mut band = vec![false; w * h];
    let class_at = |i: usize| class.get(i).copied().unwrap_or(SampleClass::Background);
    if w == 0 {
        return band;
    }
    band.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
        for (x, out) in row.iter_mut().enumerate() {
            let i = y * w + x;
            if class_at(i) == SampleClass::Background {
                continue;
            }
            if grazing.get(i).copied().unwrap_or(false) {
                *out = true;
                continue;
            }
            let (mut lit, mut shadowed) = (false, false);
            for ny in y.saturating_sub(1)..(y + 2).min(h) {
                for nx in x.saturating_sub(1)..(x + 2).min(w) {
                    match class_at(ny * w + nx) {
                        SampleClass::Lit => lit = true,
                        SampleClass::Shadowed => shadowed = true,
                        SampleClass::Background => {}
                    }
                }
            }
            *out = lit && shadowed;
        }
    });
    band
}
