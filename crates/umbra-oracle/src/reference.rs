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
//!
//! Choices made here, each explained where it is implemented:
//! * The plane test is done in `f64` from the `f32` vertices of `T` (the cross product of two
//!   `f32` differences is then nearly exact), and `S` is first projected onto `T`'s plane.
//! * `T` itself is excluded from the occlusion test; its neighbours are not.
//! * `eps` is a *distance*, [`segment_epsilon`] = `1e-5` of the scene's scale.
//! * Background neighbours do not count as a class for the band.

use rayon::prelude::*;
use umbra_geom::{Light, WeldedMesh};

use crate::bvh::Bvh;
use crate::OracleError;

/// Relative size of the self-intersection epsilon, see [`segment_epsilon`].
pub const EPSILON_RELATIVE: f64 = 1e-5;
/// Samples with `|N.L| < GRAZING |N||L|` are grazing: they count as band.
pub const GRAZING: f64 = 1e-4;

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
pub fn reference(mesh: &WeldedMesh, bvh: &Bvh, samples: &Samples, light: Light, eye: [f32; 3]) -> Result<Reference, OracleError> {
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
            return Err(OracleError::VertexOutOfRange { triangle: t as usize, vertex: v, vertices: mesh.positions.len() });
        }
    }

    let eps = segment_epsilon(&mesh.positions);
    let shading = Shading::new(light, eye);
    let mut class = vec![SampleClass::Background; pixels];
    let mut grazing = vec![false; pixels];
    if width > 0 {
        class
            .par_chunks_mut(width as usize)
            .zip(grazing.par_chunks_mut(width as usize))
            .enumerate()
            .for_each(|(row, (class_row, grazing_row))| {
                let start = row * width as usize;
                for x in 0..width as usize {
                    let t = samples.triangle[start + x];
                    if t == u32::MAX {
                        continue;
                    }
                    let (c, g) = classify(mesh, bvh, eps, &shading, t, samples.world_pos[start + x]);
                    class_row[x] = c;
                    grazing_row[x] = g;
                }
            });
    }
    let band = boundary_band(width, height, &class, &grazing);
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
        Shading {
            point: (w != 0.0).then(|| xyz.map(|c| c / w)),
            towards: xyz,
            eye: eye.map(|c| c as f64),
        }
    }
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}
fn to_f64(p: [f32; 3]) -> [f64; 3] {
    p.map(|c| c as f64)
}

/// Class and grazing flag of one sample at `world_pos` on triangle `triangle` (in range).
fn classify(mesh: &WeldedMesh, bvh: &Bvh, eps: f64, shading: &Shading, triangle: u32, world_pos: [f32; 3]) -> (SampleClass, bool) {
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
    let occluded = match shading.point {
        Some(_) => {
            let len = ll.sqrt();
            // Parametric t along S -> light: eps as a distance is eps / |L| in t.
            let t_eps = eps / len;
            // A sample within 2 eps of the light: the segment is empty, nothing can occlude.
            t_eps < 0.5 && bvh.occluded(s, to_light, t_eps, 1.0 - t_eps, triangle)
        }
        None => {
            let len = ll.sqrt();
            let dir = to_light.map(|c| c / len);
            bvh.occluded(s, dir, eps, f64::INFINITY, triangle)
        }
    };
    (if occluded { SampleClass::Shadowed } else { SampleClass::Lit }, grazing)
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
