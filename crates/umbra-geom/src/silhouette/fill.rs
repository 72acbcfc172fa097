//! [`estimate_fill`]: the pixels a volume's faces cover on screen, with and without the clamp,
//! so that a light is clamped only where that pays.
//!
//! Clamping a volume to its receivers ([`super::VolumeClamp`]) shortens its sides but closes
//! them with far caps, which z-pass never draws for a volume running to infinity; and under
//! z-pass the unclamped sides are clipped to the scene's box anyway. Which costs fewer
//! fragments depends on the view: on an indoor scene the sides are long and the clamp saves
//! most of them, over an open floor the far caps cover the whole shadow twice and the clamp
//! costs more. Both volumes give the same count at every visible sample (docs/exactness.md),
//! so the choice changes the cost only. The estimate is each face's polygon clipped as the
//! GPU clips it (the scene box under z-pass, the screen's four side planes, `w > 0`), its
//! projected area summed over faces: the fragments rasterization will produce, overlaps
//! counted as often as they are drawn. The light caps are the same in both and left out.

use glam::{DMat4, DVec4};

use super::indexed::{is_degenerate_cap, IndexedVolume};
use super::volume::extrude;
use crate::Light;

/// Screen area in pixels of both variants of one light's volume.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FillEstimate {
    /// Sides with their clamped far ends, and the far caps.
    pub clamped: f64,
    /// The same sides running to infinity, and the dark caps at infinity where they are drawn.
    pub unclamped: f64,
}

/// Where faces are clipped before they are rasterized.
pub struct ScreenClip {
    /// Camera clip space from world space (the frame's, infinite far plane).
    pub clip_from_world: DMat4,
    /// World-space planes `p . (x, y, z, w) >= 0` of the scene box the z-pass volumes are
    /// clipped to ([`crate::clearance::scene_clip_box`]); empty under z-fail.
    pub world_planes: Vec<[f64; 4]>,
    /// The viewport in pixels.
    pub width: u32,
    /// The viewport in pixels.
    pub height: u32,
}

const MAX_VERTICES: usize = 16;

/// Sutherland-Hodgman against `plane . v >= 0`, homogeneous.
fn clip_polygon(poly: &[DVec4], plane: DVec4, out: &mut Vec<DVec4>) {
    out.clear();
    let n = poly.len();
    for i in 0..n {
        let (a, b) = (poly[i], poly[(i + 1) % n]);
        let (da, db) = (plane.dot(a), plane.dot(b));
        if da >= 0.0 {
            out.push(a);
        }
        if (da >= 0.0) != (db >= 0.0) {
            let t = da / (da - db);
            out.push(a + (b - a) * t);
        }
        if out.len() >= MAX_VERTICES {
            break;
        }
    }
}

impl ScreenClip {
    /// Pixels covered by the polygon `world` (homogeneous world vertices, `w = 0` at
    /// infinity) once clipped.
    pub fn area(&self, world: &[[f32; 4]]) -> f64 {
        let mut a: Vec<DVec4> =
            world.iter().map(|v| DVec4::new(v[0] as f64, v[1] as f64, v[2] as f64, v[3] as f64)).collect();
        let mut b = Vec::with_capacity(MAX_VERTICES);
        for p in &self.world_planes {
            clip_polygon(&a, DVec4::from_array(*p), &mut b);
            std::mem::swap(&mut a, &mut b);
            if a.len() < 3 {
                return 0.0;
            }
        }
        for v in a.iter_mut() {
            *v = self.clip_from_world * *v;
        }
        // x <= w, -x <= w, y <= w, -y <= w; then w > 0 (a sliver of the eye's own point).
        for plane in [
            DVec4::new(-1.0, 0.0, 0.0, 1.0),
            DVec4::new(1.0, 0.0, 0.0, 1.0),
            DVec4::new(0.0, -1.0, 0.0, 1.0),
            DVec4::new(0.0, 1.0, 0.0, 1.0),
        ] {
            clip_polygon(&a, plane, &mut b);
            std::mem::swap(&mut a, &mut b);
            if a.len() < 3 {
                return 0.0;
            }
        }
        if a.iter().any(|v| v.w.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater)) {
            // Only the eye's own point has w = 0 inside the four planes: no area.
            a.retain(|v| v.w > 0.0);
            if a.len() < 3 {
                return 0.0;
            }
        }
        let mut twice = 0.0;
        let n = a.len();
        for i in 0..n {
            let (p, q) = (a[i], a[(i + 1) % n]);
            twice += (p.x / p.w) * (q.y / q.w) - (q.x / q.w) * (p.y / p.w);
        }
        // NDC spans 2 x 2 over width x height pixels.
        (0.5 * twice).abs() * 0.25 * self.width as f64 * self.height as f64
    }
}

/// Both variants' screen area of `volume`, extracted with a clamp ([`super::extract_clamped`])
/// from `positions` for `light`: its sides as drawn and with far ends at infinity, its far caps,
/// and, when `caps` (z-fail) and the light is a point light, the dark caps at infinity the
/// unclamped volume would draw instead.
pub fn estimate_fill(
    volume: &IndexedVolume,
    positions: &[[f32; 3]],
    light: Light,
    caps: bool,
    clip: &ScreenClip,
) -> FillEstimate {
    use rayon::prelude::*;
    let sides = volume
        .sides
        .par_chunks_exact(6)
        .map(|s| {
            // Quad [s0, s1, s2, s5]: s2 is s1's far end, s5 s0's (emit.rs's two windings).
            let at_infinity = |v: [f32; 4]| extrude([v[0], v[1], v[2]], light);
            let clamped = clip.area(&[s[0], s[1], s[2], s[5]]);
            let unclamped = clip.area(&[s[0], s[1], at_infinity(s[1]), at_infinity(s[0])]);
            (clamped, unclamped)
        })
        .reduce(|| (0.0, 0.0), |x, y| (x.0 + y.0, x.1 + y.1));
    let far_caps: f64 = volume.far_caps.par_chunks_exact(3).map(|t| clip.area(t)).sum();
    let dark_caps: f64 = if caps && light[3] != 0.0 {
        volume
            .caps
            .par_iter()
            .filter(|&&c| !is_degenerate_cap(c))
            .map(|c| clip.area(&c.map(|i| extrude(positions[i as usize], light))))
            .sum()
    } else {
        0.0
    };
    FillEstimate { clamped: sides.0 + far_caps, unclamped: sides.1 + dark_caps }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::{Camera, DepthConvention};

    fn clip(world_planes: Vec<[f64; 4]>) -> ScreenClip {
        let camera = Camera { eye: [0.0, 0.0, 5.0], target: [0.0; 3], fov_y_degrees: 90.0, ..Camera::default() };
        ScreenClip {
            clip_from_world: camera.clip_from_world_in(1.0, DepthConvention::ReversedZ),
            world_planes,
            width: 100,
            height: 100,
        }
    }

    #[test]
    fn a_face_covering_the_view_is_the_whole_viewport_and_one_behind_the_eye_is_nothing() {
        let c = clip(Vec::new());
        // At distance 5 a 90-degree view spans [-5, 5]: a larger square covers all 100 x 100.
        let big = [[-20.0, -20.0, 0.0, 1.0], [20.0, -20.0, 0.0, 1.0], [20.0, 20.0, 0.0, 1.0], [-20.0, 20.0, 0.0, 1.0]];
        assert!((c.area(&big) - 10_000.0).abs() < 1e-6, "{}", c.area(&big));
        // A quarter of the view: the square [0, 5] x [0, 5] at distance 5.
        let quarter = [[0.0, 0.0, 0.0, 1.0], [5.0, 0.0, 0.0, 1.0], [5.0, 5.0, 0.0, 1.0], [0.0, 5.0, 0.0, 1.0]];
        assert!((c.area(&quarter) - 2_500.0).abs() < 1e-6, "{}", c.area(&quarter));
        let behind = [[-1.0, -1.0, 9.0, 1.0], [1.0, -1.0, 9.0, 1.0], [0.0, 1.0, 9.0, 1.0]];
        assert_eq!(c.area(&behind), 0.0);
    }

    #[test]
    fn faces_are_clipped_to_the_scene_box_first() {
        // The box x <= 0 keeps the left half of the view.
        let c = clip(vec![[-1.0, 0.0, 0.0, 0.0]]);
        let big = [[-20.0, -20.0, 0.0, 1.0], [20.0, -20.0, 0.0, 1.0], [20.0, 20.0, 0.0, 1.0], [-20.0, 20.0, 0.0, 1.0]];
        assert!((c.area(&big) - 5_000.0).abs() < 1e-6, "{}", c.area(&big));
        // A side running to infinity (w = 0 vertices) away from the eye covers the view up to
        // its vanishing point, here the centre: the triangle (0,0)-(5,0)-(centre).
        let c = clip(Vec::new());
        let to_infinity = [[0.0, -5.0, 0.0, 1.0], [5.0, -5.0, 0.0, 1.0], [0.0, 0.0, -1.0, 0.0]];
        assert!((c.area(&to_infinity) - 1_250.0).abs() < 1e-6, "{}", c.area(&to_infinity));
    }
}
