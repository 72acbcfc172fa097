//! Synthetic rasterized samples by ray casting primary rays from a pinhole camera, for tests and
//! benchmarks of the reference without a GPU. `umbra verify` does NOT use this: it reads the
//! samples the GL renderer actually rasterized.
//!
//! Camera model: look-at pinhole, vertical field of view `fov_y`, square pixels, pixel centres
//! at `(x + 0.5, y + 0.5)`, row 0 at the top (the layout of [`crate::Samples`]).

use rayon::prelude::*;

use umbra_geom::vec3::cross;

use crate::bvh::Bvh;

/// A look-at pinhole camera.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PinholeCamera {
    pub eye: [f32; 3],
    pub target: [f32; 3],
    /// World up direction (must not be parallel to `target - eye`).
    pub up: [f32; 3],
    /// Vertical field of view in radians.
    pub fov_y: f32,
    pub width: u32,
    pub height: u32,
}

fn normalize(v: [f64; 3]) -> [f64; 3] {
    let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    v.map(|c| c / l)
}

/// Per pixel (row-major, top row first) the world position of the closest hit and its triangle
/// id, or `u32::MAX` (and the eye position) where the primary ray hits nothing.
pub fn primary_samples(bvh: &Bvh, camera: &PinholeCamera) -> (Vec<[f32; 3]>, Vec<u32>) {
    let eye = camera.eye.map(|c| c as f64);
    let forward = normalize([0, 1, 2].map(|k| camera.target[k] as f64 - eye[k]));
    let right = normalize(cross(forward, camera.up.map(|c| c as f64)));
    let up = cross(right, forward);
    let (w, h) = (camera.width as usize, camera.height as usize);
    let half_h = (camera.fov_y as f64 * 0.5).tan();
    let half_w = half_h * w as f64 / h.max(1) as f64;
    let pixel = |i: usize| {
        let (x, y) = (i % w, i / w);
        let u = (2.0 * (x as f64 + 0.5) / w as f64 - 1.0) * half_w;
        let v = (1.0 - 2.0 * (y as f64 + 0.5) / h as f64) * half_h;
        let d = [0, 1, 2].map(|k| forward[k] + u * right[k] + v * up[k]);
        match bvh.intersect(eye, d, 0.0, f64::INFINITY) {
            Some(hit) => ([0, 1, 2].map(|k| (eye[k] + hit.t * d[k]) as f32), hit.triangle),
            None => (camera.eye, u32::MAX),
        }
    };
    (0..w * h).into_par_iter().map(pixel).unzip()
}
