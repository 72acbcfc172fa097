//! The scene clip box of the z-pass volumes: the scene and the eye with a margin, as six
//! world planes.

use crate::Aabb;

/// The box the z-pass volumes are clipped to (the renderers' volume pass; the shaders'
/// scene clip): the scene's triangles and the eye, enlarged by
/// 1 % of its diagonal (plus 1e-6 of its largest coordinate) so that rounding at its planes
/// lies far from every sample. As six world planes `(n, d)`, `n . X + d W >= 0` inside.
pub fn scene_clip_box(bounds: Aabb, eye: [f64; 3]) -> [[f64; 4]; 6] {
    let mut lo = bounds.min.map(f64::from);
    let mut hi = bounds.max.map(f64::from);
    for a in 0..3 {
        lo[a] = lo[a].min(eye[a]);
        hi[a] = hi[a].max(eye[a]);
    }
    let diag = ((hi[0] - lo[0]).powi(2) + (hi[1] - lo[1]).powi(2) + (hi[2] - lo[2]).powi(2)).sqrt();
    let big = lo.iter().chain(hi.iter()).fold(0.0f64, |m, c| m.max(c.abs()));
    let margin = 0.01 * diag + 1e-6 * big + 1e-6;
    [
        [1.0, 0.0, 0.0, -(lo[0] - margin)],
        [0.0, 1.0, 0.0, -(lo[1] - margin)],
        [0.0, 0.0, 1.0, -(lo[2] - margin)],
        [-1.0, 0.0, 0.0, hi[0] + margin],
        [0.0, -1.0, 0.0, hi[1] + margin],
        [0.0, 0.0, -1.0, hi[2] + margin],
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scene_clip_box_holds_the_scene_and_the_eye_with_a_margin() {
        let bounds = Aabb { min: [-1.0, 0.0, -2.0], max: [3.0, 1.0, 2.0] };
        let eye = [10.0, 0.5, 0.0];
        let planes = scene_clip_box(bounds, eye);
        let inside = |p: [f64; 3]| {
            planes.iter().map(|q| q[0] * p[0] + q[1] * p[1] + q[2] * p[2] + q[3]).fold(f64::MAX, f64::min)
        };
        for p in [eye, [-1.0, 0.0, -2.0], [3.0, 1.0, 2.0], [10.0, 1.0, -2.0]] {
            assert!(inside(p) > 0.1, "{p:?}: {}", inside(p));
        }
        assert!(inside([10.5, 0.5, 0.0]) < 0.0 && inside([0.0, -1.0, 0.0]) < 0.0);
    }
}
