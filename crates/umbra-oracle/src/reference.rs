//! The per-sample shadow reference: which rasterized samples are in shadow, decided by ray
//! casting on the CPU, and the one-pixel shadow-boundary band where a GPU method may differ.
//!
//! Definition (the project issue "verify: per-sample exactness", followed exactly):
//! * Triangles are two-sided occluders: any triangle casts a shadow whichever way it faces.
//! * A sample `S` on triangle `T` is in shadow iff the camera and the light are on opposite
//!   sides of `T`'s plane (the side we see faces away from the light), or the segment from `S`
//!   to the light hits another triangle with `t` in `(eps, 1 - eps)`. For a directional light
//!   (`w = 0`) the segment is the ray towards the light (direction `xyz`), `t` in `(eps, inf)`.
//! * Boundary band: samples whose 3x3 neighbourhood holds both classes (lit and shadowed), and
//!   grazing samples, `|N.L| < 1e-4 |N||L|` with `L` the direction from `S` to the light.
//! * The band also holds the samples whose class is not decided by exact geometry but by the
//!   precision of the rasterizer and of the depth test, wherever they lie in the image (the
//!   3x3 rule only covers boundaries at least a pixel wide):
//!   - *snapped*: the pixel centre lies within [`SNAP_PIXELS`] of the line of an edge of its own
//!     triangle. Rasterizers snap vertices to a fixed-point grid (8 sub-pixel bits on llvmpipe
//!     and on most GPUs), so which side of that edge the sample is on, and hence whether the
//!     side quad extruded from that edge covers it in front or behind, is the grid's choice.
//!     Needs the view ([`RasterView`]); [`reference()`] without one skips it.
//!   - *near a shadow boundary*: the segment to the light passes within a margin of an
//!     occluder's edge without passing robustly through one ([`Bvh::occluded_near`]), and
//!     moving `S` by that margin across the segment changes its class: the sample lies that
//!     close to a shadow-volume side, which the depth test cannot resolve. The margin is the
//!     larger of [`NEAR_BOUNDARY_RELATIVE`] `(|S - eye| + |S|max)` (rounding of positions)
//!     and, with the view, [`DEPTH_QUANTA`] steps of the depth buffer along the view ray
//!     ([`RasterView::depth_margin`]; it grows with the square of the distance over the near
//!     plane: 2.4e-4 units at 10 units with a 0.1 near plane). Such
//!     samples only escape the 3x3 rule where a side meets the surface at a very shallow
//!     angle (under a degree), so the boundary runs along the surface for many pixels.
//!   - *edge-on*: pixels a shadow-volume side face seen almost exactly edge-on may cover
//!     ([`crate::edge_on`]). Needs the view.
//!   - *within eps*: samples lit only because an occluder lies within `eps` of them along the
//!     segment (the segment test's own tolerance, see [`segment_epsilon`]): a concave crease or
//!     an object touching the surface, which a method (it has no eps) may count as shadow.
//!
//! Choices made here, each explained where it is implemented:
//! * The plane test is done in `f64` from the `f32` vertices of `T` (the cross product of two
//!   `f32` differences is then nearly exact), and `S` is first projected onto `T`'s plane.
//! * `T` itself is excluded from the occlusion test; its neighbours are not.
//! * `eps` is a *distance*, [`segment_epsilon`] = `1e-5` of the scene's scale.
//! * Background neighbours do not count as a class for the band.

use std::collections::HashSet;

use rayon::prelude::*;
use umbra_geom::vec3::{cross, dot, sub};
use umbra_geom::{Light, WeldedMesh};

use crate::bvh::Bvh;
use crate::OracleError;

/// Relative size of the self-intersection epsilon, see [`segment_epsilon`].
pub const EPSILON_RELATIVE: f64 = 1e-5;
/// Samples with `|N.L| < GRAZING |N||L|` are grazing: they count as band.
pub const GRAZING: f64 = 1e-4;
/// A pixel centre closer than this (in pixels) to the line of an edge of its own triangle is
/// band (*snapped*, see the module doc): 4 times the largest displacement of an edge by
/// snapping vertices to 1/256 pixel (half a step per coordinate, times sqrt 2, is 1/362).
pub const SNAP_PIXELS: f64 = 1.0 / 128.0;
/// Relative margin of the *near a shadow boundary* band (see the module doc): 2^-20, i.e. 8 to
/// 16 units in the last place of an f32 depth or position at the sample's distance.
pub const NEAR_BOUNDARY_RELATIVE: f64 = 1.0 / 1_048_576.0;

/// Depth-buffer steps a sample must be away from a shadow-volume face for the depth test to
/// order them for sure: the face's depth is interpolated in f32 over its (often long, thin)
/// screen triangle, off by a few steps, and the sample's own depth is rounded once.
pub const DEPTH_QUANTA: f64 = 4.0;

/// The view the samples were rasterized with, for the *snapped* band.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RasterView {
    /// Clip space from world space, column-major (OpenGL's convention), in the depth
    /// convention the samples were rendered with (only [`RasterView::depth_margin`] reads z).
    pub clip_from_world: [f64; 16],
}

impl RasterView {
    fn clip(&self, p: [f64; 3]) -> [f64; 3] {
        let m = &self.clip_from_world;
        let row = |r: usize| m[r] * p[0] + m[4 + r] * p[1] + m[8 + r] * p[2] + m[12 + r];
        [row(0), row(1), row(3)]
    }

    /// The world distance along the view ray at `s` (seen from `eye`) that moves its window
    /// depth by [`DEPTH_QUANTA`] quanta of a depth buffer: below it the depth test cannot tell
    /// whether `s` lies in front of or behind a shadow-volume face through that point. The
    /// quantum is the larger of a 24-bit fixed-point step (2^-24) and the f32 spacing at the
    /// sample's depth (DEPTH24 or DEPTH32F, whichever the method used); the window depth is
    /// `(z/w + 1) / 2` for GL's default clip depth mode and `z/w` for reversed-Z (detected: its
    /// depth row has no x, y, z terms). `0` when the depth does not change along the ray (then
    /// only the other margins apply).
    // `!(x > 0.0)` is meant: it is also true for NaN, which must give no margin the same way.
    #[allow(clippy::neg_cmp_op_on_partial_ord)]
    pub fn depth_margin(&self, s: [f64; 3], eye: [f64; 3]) -> f64 {
        let m = &self.clip_from_world;
        let row = |r: usize, p: [f64; 3], w: f64| m[r] * p[0] + m[4 + r] * p[1] + m[8 + r] * p[2] + m[12 + r] * w;
        let reversed = m[2] == 0.0 && m[6] == 0.0 && m[10] == 0.0;
        let scale = if reversed { 1.0 } else { 0.5 };
        let d = sub(s, eye);
        let len = dot(d, d).sqrt();
        if !(len > 0.0) {
            return 0.0;
        }
        let v = d.map(|c| c / len);
        let (z, w) = (row(2, s, 1.0), row(3, s, 1.0));
        let (dz, dw) = (row(2, v, 0.0), row(3, v, 0.0));
        if !(w > 0.0) {
            return 0.0;
        }
        // d(z/w)/dt along the unit view direction, then to window depth.
        let slope = scale * ((dz * w - z * dw) / (w * w)).abs();
        let window = if reversed { z / w } else { 0.5 * (z / w + 1.0) };
        let ulp = (window.abs() as f32).max(f32::MIN_POSITIVE);
        let ulp = f64::from(f32::from_bits(ulp.to_bits() + 1) - ulp);
        let quantum = ulp.max(1.0 / 16_777_216.0);
        if slope > 0.0 && slope.is_finite() {
            DEPTH_QUANTA * quantum / slope
        } else {
            0.0
        }
    }

    /// Distance in pixels from the centre of pixel `(x, y)` (top row first) of a `width` x
    /// `height` image to the nearest line of the triangle's three edges, in homogeneous 2D
    /// clip coordinates (right for vertices behind the eye too: the line through two
    /// homogeneous points is their cross product). `None` when every line is degenerate.
    pub fn edge_distance_px(&self, tri: [[f64; 3]; 3], x: u32, y: u32, width: u32, height: u32) -> Option<f64> {
        let (w, h) = (width as f64, height as f64);
        let p = [(x as f64 + 0.5) / w * 2.0 - 1.0, 1.0 - (y as f64 + 0.5) / h * 2.0, 1.0];
        let v = tri.map(|q| self.clip(q));
        let mut best: Option<f64> = None;
        for k in 0..3 {
            let l = cross(v[k], v[(k + 1) % 3]);
            let g = (2.0 * l[0] / w).hypot(2.0 * l[1] / h);
            if g > 0.0 && g.is_finite() {
                let d = dot(l, p).abs() / g;
                best = Some(best.map_or(d, |b: f64| b.min(d)));
            }
        }
        best
    }
}

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
    pub band: Vec<bool>,
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

/// [`reference()`] with the view the samples were rasterized with, which adds the *snapped*
/// samples to the band (see the module doc). `umbra verify` and the torture suite use this.
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

    let eps = segment_epsilon(&mesh.positions);
    let shading = Shading::new(light, eye);
    // The edges that cast a side face for this light (one edge adjacency per reference), for
    // the *touching* and *edge-on* parts of the band (with the view only).
    let casting = view.map(|_| crate::edge_on::side_casting_edges(mesh, light));
    let mut class = vec![SampleClass::Background; pixels];
    let mut grazing = vec![false; pixels];
    if width > 0 {
        class.par_chunks_mut(width as usize).zip(grazing.par_chunks_mut(width as usize)).enumerate().for_each(
            |(row, (class_row, grazing_row))| {
                let start = row * width as usize;
                for x in 0..width as usize {
                    let t = samples.triangle[start + x];
                    if t == u32::MAX {
                        continue;
                    }
                    let (c, g) =
                        classify(mesh, bvh, eps, &shading, view, casting.as_ref(), t, samples.world_pos[start + x]);
                    class_row[x] = c;
                    let snapped = view.is_some_and(|v| {
                        let tri = mesh.triangles[t as usize].map(|k| to_f64(mesh.positions[k as usize]));
                        v.edge_distance_px(tri, x as u32, row as u32, width, height).is_some_and(|d| d < SNAP_PIXELS)
                    });
                    grazing_row[x] = g || snapped;
                }
            },
        );
    }
    let mut band = boundary_band(width, height, &class, &grazing);
    if let (Some(v), Some(casting)) = (view, casting.as_ref()) {
        let eye = eye.map(f64::from);
        crate::edge_on::mark_edge_on(mesh, casting, light, eye, v, width, height, &mut band, |i| {
            class[i] != SampleClass::Background
        });
    }
    Ok(Reference { width, height, class, band })
}

fn check_len(what: &'static str, actual: usize, expected: usize, width: u32, height: u32) -> Result<(), OracleError> {
    if actual != expected {
        return Err(OracleError::SizeMismatch { what, expected, actual, width, height });
    }
    Ok(())
}

/// Light and eye in `f64`. A homogeneous point light with `w != 1` is the point `xyz / w`.
struct Shading {
    /// Point light position, or `None` for a directional light.
    point: Option<[f64; 3]>,
    /// Direction *towards* a directional light (the light's `xyz`).
    towards: [f64; 3],
    eye: [f64; 3],
}

impl Shading {
    fn new(light: Light, eye: [f32; 3]) -> Shading {
        let xyz = [light[0] as f64, light[1] as f64, light[2] as f64];
        let w = light[3] as f64;
        Shading { point: (w != 0.0).then(|| xyz.map(|c| c / w)), towards: xyz, eye: eye.map(|c| c as f64) }
    }
}

/// Two unit vectors perpendicular to `d` and to each other (`d` non-zero).
fn perpendicular_basis(d: [f64; 3]) -> ([f64; 3], [f64; 3]) {
    let len = dot(d, d).sqrt();
    let n = d.map(|c| c / len);
    // Cross with the axis least aligned with d: never near-parallel.
    let axis = if n[0].abs() <= n[1].abs() && n[0].abs() <= n[2].abs() {
        [1.0, 0.0, 0.0]
    } else if n[1].abs() <= n[2].abs() {
        [0.0, 1.0, 0.0]
    } else {
        [0.0, 0.0, 1.0]
    };
    let u = cross(n, axis);
    let lu = dot(u, u).sqrt();
    let u = u.map(|c| c / lu);
    (u, cross(n, u))
}

fn to_f64(p: [f32; 3]) -> [f64; 3] {
    p.map(|c| c as f64)
}

/// Class and grazing flag of one sample at `world_pos` on triangle `triangle` (in range).
#[allow(clippy::too_many_arguments)]
fn classify(
    mesh: &WeldedMesh,
    bvh: &Bvh,
    eps: f64,
    shading: &Shading,
    view: Option<&RasterView>,
    casting: Option<&HashSet<[u32; 2]>>,
    triangle: u32,
    world_pos: [f32; 3],
) -> (SampleClass, bool) {
    let [ia, ib, ic] = mesh.triangles[triangle as usize];
    let a = to_f64(mesh.positions[ia as usize]);
    let b = to_f64(mesh.positions[ib as usize]);
    let c = to_f64(mesh.positions[ic as usize]);
    // Differences of f32 values are exact in f64, and so is each product of two of them: the
    // normal is rounded only by the final subtractions.
    let n = cross(sub(b, a), sub(c, a));
    let nn = dot(n, n);
    // Project S onto T's plane: the interpolated GPU position is off the plane by rounding, and
    // on the wrong side of it the ray towards the light could start behind a coplanar or
    // adjacent surface. On the plane, only true occluders or ones within eps remain.
    let mut s = to_f64(world_pos);
    if nn > 0.0 {
        let k = dot(n, sub(s, a)) / nn;
        s = [s[0] - k * n[0], s[1] - k * n[1], s[2] - k * n[2]];
    }
    // L: from S towards the light, and which side of T's plane the light is on.
    let (to_light, light_side) = match shading.point {
        Some(p) => (sub(p, s), dot(n, sub(p, a))),
        None => (shading.towards, dot(n, shading.towards)),
    };
    let eye_side = dot(n, sub(shading.eye, a));
    let ll = dot(to_light, to_light);
    // |N.L| < 1e-4 |N||L|, squared to avoid roots; a degenerate T (N = 0) or a sample at the
    // light (L = 0) has no defined angle and is grazing too.
    let nl = dot(n, to_light);
    let grazing = nn == 0.0 || ll == 0.0 || nl * nl < GRAZING * GRAZING * nn * ll;

    // Plane test: the side we see faces away from the light. A zero on either side (camera or
    // light in T's plane) is undecided here and falls through to the ray; such a sample is
    // grazing or edge-on to the camera, i.e. in the band or not rasterized at all.
    if (eye_side > 0.0 && light_side < 0.0) || (eye_side < 0.0 && light_side > 0.0) {
        return (SampleClass::Shadowed, grazing);
    }

    // Occlusion test. T itself is skipped: S lies on it, so it could only be met at t ~ 0,
    // where the answer is rounding noise, and its facing was decided by the plane test above.
    // Neighbours of T are NOT skipped: across a concave crease a neighbour really does shadow
    // T (a wall shading the floor); a coplanar neighbour meets the ray only at t ~ 0 < eps.
    // Near a shadow boundary (module doc): a world distance at S.
    // Rounding of positions: relative to the sample's distance and coordinates; depth-test
    // resolution: a few depth-buffer steps along the view ray (RasterView::depth_margin).
    let margin = (NEAR_BOUNDARY_RELATIVE
        * (dot(sub(s, shading.eye), sub(s, shading.eye)).sqrt() + s.iter().fold(0f64, |m, c| m.max(c.abs()))))
    .max(view.map_or(0.0, |v| v.depth_margin(s, shading.eye)));
    // The exact segment (or ray) from a start point towards the light, as (direction, t range).
    let segment = |from: [f64; 3]| -> Option<([f64; 3], f64, f64)> {
        match shading.point {
            Some(p) => {
                let to_light = sub(p, from);
                // Parametric t along S -> light: eps as a distance is eps / |L| in t.
                let t_eps = eps / dot(to_light, to_light).sqrt();
                // A sample within 2 eps of the light: the segment is empty, nothing can occlude.
                (t_eps < 0.5).then_some((to_light, t_eps, 1.0 - t_eps))
            }
            None => {
                let len = dot(to_light, to_light).sqrt();
                Some((to_light.map(|c| c / len), eps, f64::INFINITY))
            }
        }
    };
    let Some((dir, t_min, t_max)) = segment(s) else {
        return (SampleClass::Lit, grazing);
    };
    // Touching: an edge that casts a side face for this light lies within the margin of S
    // itself (an occluder resting on S's surface, a T-junction, a silhouette edge shared with
    // T). Its side face passes within the margin of S, and the depth test cannot order S and
    // that face, whatever the probes below say: moving S along its own surface need not
    // change the reference's answer while the face's depth still decides the method's count.
    // Found on Conference: a floor sample 1.3e-4 from the top edge of a table's side face
    // lying in the floor's plane, 1,960 units from the eye (4 depth steps = 0.28 units).
    // Edges that cast nothing (shared by coplanar neighbours, interior edges of flat
    // occluders) are not band.
    let touching = casting.is_some_and(|casting| {
        let len = dot(dir, dir).sqrt();
        let mut any = false;
        if len > 0.0 {
            bvh.near_edges(s, dir, -margin / len, margin / len, triangle, 2.0 * margin, |t, near| {
                let tri = mesh.triangles[t as usize];
                for k in 0..3 {
                    let (a, b) = (tri[k], tri[(k + 1) % 3]);
                    any |= near[k] && casting.contains(&[a.min(b), a.max(b)]);
                }
            });
        }
        any
    });
    // The exact answer, and whether some occluder's edge passes near the segment without one
    // occluder being hit robustly (the margin doubled: distances in the watertight test's
    // sheared plane are up to sqrt 3 longer than perpendicular ones). The margin stays a world
    // distance: the sheared plane does not depend on the direction's length.
    let (occluded, near) = bvh.occluded_near(s, dir, t_min, t_max, triangle, 2.0 * margin);
    // Near an edge: move S by the margin in 8 directions across the segment; if any of them
    // changes the answer, S lies within the margin of a shadow boundary. (An interior edge of
    // a flat occluder is near too, but every moved segment still hits one of its triangles.)
    let uncertain = near && {
        let (u, v) = perpendicular_basis(dir);
        (0..8).any(|k| {
            let (sin, cos) = (k as f64 * std::f64::consts::FRAC_PI_4).sin_cos();
            let moved = [0, 1, 2].map(|i| s[i] + margin * (cos * u[i] + sin * v[i]));
            let moved_occluded = match segment(moved) {
                Some((d, lo, hi)) => bvh.occluded(moved, d, lo, hi, triangle),
                None => false,
            };
            moved_occluded != occluded
        })
    };
    // Lit only because the reference's eps ignores what lies within eps along the segment (a
    // concave crease, an object resting on the surface): the method, which has no eps, may
    // shadow the sample. Band (*within eps*) when, with the segment starting at S instead of
    // eps away, an occluder is hit, or an occluder's edge passes within the margin and one of
    // the 8 moved segments is occluded. The range starts at t_min / 1024, not 0: a hit at
    // t ~ 0 is a surface through S itself (a coplanar neighbour met on its shared edge), not
    // an occluder in front of S.
    let within_eps = !occluded && t_min > 0.0 && {
        let from_s = |from: [f64; 3]| segment(from).map(|(d, lo, hi)| (d, lo / 1024.0, lo, hi));
        let (hit, near) = bvh.occluded_near(s, dir, t_min / 1024.0, t_min, triangle, 2.0 * margin);
        hit || (near && {
            let (u, v) = perpendicular_basis(dir);
            (0..8).any(|k| {
                let (sin, cos) = (k as f64 * std::f64::consts::FRAC_PI_4).sin_cos();
                let moved = [0, 1, 2].map(|i| s[i] + margin * (cos * u[i] + sin * v[i]));
                from_s(moved).is_some_and(|(d, start, _, hi)| bvh.occluded(moved, d, start, hi, triangle))
            })
        })
    };
    (if occluded { SampleClass::Shadowed } else { SampleClass::Lit }, grazing || touching || uncertain || within_eps)
}

/// Band: a non-background sample whose 3x3 neighbourhood (itself included, clipped at the
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
