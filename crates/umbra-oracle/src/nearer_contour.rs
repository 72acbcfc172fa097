//! SURFACE's nearer contours ([`crate::envelope`]): a sample is band where the projected edge
//! of another surface *in front of it* passes within the rasterizer's lateral bound
//! ([`RasterView::lateral_pixels`]) of its pixel centre.
//!
//! The reference decides which surface a pixel shows by casting the exact ray through the
//! pixel centre; the volumes are rasterized with their vertices snapped to the rasterizer's
//! sub-pixel grid. Near the projected edge `e` of a triangle `X` that lies in front of the
//! sample (an occluding contour, a free edge), the exact ray misses `X` while the snapped faces
//! of `X`'s volume on `e` may or may not cover the pixel:
//! * z-fail: `X`'s light cap is pushed to the far plane (paper 003 Eq. 6) and counted wherever
//!   it covers the pixel, on the assumption that `X` then hides the sample. Covered within
//!   precision, it counts one more entry than the exact ray meets: a false shadow.
//! * z-pass: `X`'s side on `e` lies in front of the sample and counts where it covers the pixel;
//!   across `e`, the exact ray meets it and the snapped face may not (or the other way round).
//!
//! Either way the sample's count can change by one within the rasterizer's precision, whatever
//! `X`'s own decision, so the part needs no more than the edge's distance and the depth order.
//! No new constant: the lateral bound of the judged rasterizer's sub-pixel bits, and the
//! envelope's radius for "in front". Not counted as such an `X`:
//! * a triangle in the sample's own plane: the same surface (the sample moving along it is the
//!   envelope's lateral term);
//! * `T`'s neighbour across `e`, an edge of `T` itself (a crease): there the two triangles'
//!   caps share `e` and trade coverage, which changes nothing where both face the light alike;
//!   where they do not, `e` casts a side through the sample's envelope, which
//!   [`crate::BandParts::SIDE_FACE`] (or `CANCELLING`) marks already.
//!
//! Found on Crytek Sponza, fly-through keyframe 0 at 2560 x 1440, pixel (629, 1413), both
//! lights: the ray passes 0.001 pixel from the edge of a light-facing triangle 0.6 units in
//! front of the sample; gs-triangle, ts-triangle, gs- and ts-silhouette counted its cap (false
//! shadow), cpu-, vs- and cs-silhouette happened not to. Test below.
//!
//! An external mask's decisions come from its own depth pass, which may show `X` itself; that
//! is SEEN_SURFACE ([`crate::seen_surface`]), whose in-front candidates this part has already
//! made band.

use umbra_geom::vec3::{dot, sub};
use umbra_geom::WeldedMesh;

use crate::envelope::RasterView;
use crate::seen_surface::inverse_w_plane;

fn vertex(mesh: &WeldedMesh, k: u32) -> [f64; 3] {
    mesh.positions[k as usize].map(f64::from)
}

/// A sample as SURFACE's nearer contours and SEEN_SURFACE (`crate::reference`) test other surfaces
/// against it: its pixel, its triangle `T`, its position `s` projected onto `T`'s plane, and
/// `1/w` of that plane at the pixel centre.
pub struct PixelSurface {
    pub x: u32,
    pub y: u32,
    /// The image's width and height.
    pub size: (u32, u32),
    /// The pixel centre, window coordinates (y down).
    pub centre: [f64; 2],
    pub triangle: u32,
    /// A corner of `T` and its (unnormalised) normal.
    pub corner: [f64; 3],
    pub normal: [f64; 3],
    pub normal_len: f64,
    pub s: [f64; 3],
    /// [`RasterView::position_margin`] at `s`.
    pub position: f64,
    /// The sample's envelope radius for volume faces.
    pub radius: f64,
    /// [`inverse_w_plane`] of `T` at the pixel centre.
    pub own: Option<(f64, f64)>,
    /// How much `1/w` changes over a world unit along the view (`w`'s world gradient).
    pub w_gradient: f64,
}

impl PixelSurface {
    /// The same surface: `T`, or a triangle in `T`'s plane (the envelope covers the sample
    /// moving along it).
    pub fn same_surface(&self, mesh: &WeldedMesh, id: u32) -> bool {
        id == self.triangle
            || (self.normal_len > 0.0
                && mesh.triangles[id as usize].iter().all(|&k| {
                    (dot(self.normal, sub(vertex(mesh, k), self.corner)) / self.normal_len).abs() <= self.position
                }))
    }

    /// Whether edge `k` of triangle `id` is also an edge of `T` (welded): `id` is `T`'s
    /// neighbour across it.
    pub fn across_own_edge(&self, mesh: &WeldedMesh, id: u32, k: u8) -> bool {
        let other = mesh.triangles[id as usize];
        let own = mesh.triangles[self.triangle as usize];
        let (a, b) = (other[k as usize], other[(k as usize + 1) % 3]);
        own.contains(&a) && own.contains(&b)
    }

    /// Whether triangle `id`'s plane can lie in front of the sample somewhere within `delta`
    /// pixels of the pixel centre (its `1/w` exceed `T`'s by the envelope's radius); `true`
    /// where no such bound exists.
    pub fn in_front(&self, mesh: &WeldedMesh, view: &RasterView, id: u32, delta: f64) -> bool {
        let other = mesh.triangles[id as usize].map(|k| vertex(mesh, k));
        match (self.own, inverse_w_plane(view, other, self.centre, self.size.0, self.size.1)) {
            (Some((q, g)), Some((qx, gx))) => qx + gx * delta >= q - g * delta - q * q * self.w_gradient * self.radius,
            _ => true,
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::envelope::BandParts;
    use crate::SampleClass;
    use umbra_geom::camera::Camera;

    /// Crytek Sponza (`/work/shared/scenes/crytek-sponza.obj.gz`, scaled as loaded), fly-through
    /// keyframe 0 (`bench/sponza.flythrough`) at 2560 x 1440, directional light `0.3,1,0.2,0`,
    /// delta-debugged to two triangles (OBJ triangles 70469 and 70482): the sample on 70482
    /// at pixel (629, 1413), lit (the eye and the light on the same side of it), and 70469,
    /// 0.6 units nearer the eye, whose edge passes 0.001 pixel from the pixel centre.
    use crate::pinned::PinnedView as Keyframe;

    fn keyframe() -> Keyframe {
        let f = |b: [u32; 3]| b.map(f32::from_bits);
        let triangles = [
            [3234070528, 1054629891, 3216424957],
            [3233955839, 1053564940, 3215663103],
            [3233988609, 1053474813, 3215622142],
            [3233718271, 1052409862, 3217154044],
            [3233767425, 1053016057, 3216769024],
            [3233988609, 1053401094, 3216523263],
        ];
        Keyframe {
            positions: triangles.map(f).to_vec(),
            // The sample's triangle first (PinnedView::judged puts the sample on triangle 0).
            triangles: vec![[3, 4, 5], [0, 1, 2]],
            light: [0.3, 1.0, 0.2, 0.0],
            // The GPU's interpolated position (-6.0186143, 0.38197854, -1.4695661).
            sample: f([3233847421, 1053004465, 3216775870]),
            camera: Camera {
                eye: [-8.5, 1.5, -0.3],
                target: [4.0, 2.5, 0.0],
                up: [0.0, 1.0, 0.0],
                fov_y_degrees: 60.0,
                // The scene's diagonal / 1000 (umbra-cli's near plane); it moves depths only.
                near: 0.028967,
                ..Camera::default()
            },
        }
    }

    #[test]
    fn sponza_sample_beside_a_nearer_triangles_edge_is_surface_band() {
        let scene = keyframe();
        let (pixel, class, parts) = scene.judged(8, false, (2560, 1440));
        assert_eq!(pixel, (629, 1413));
        assert_eq!(class, SampleClass::Lit);
        assert!(parts.contains(BandParts::SURFACE), "{:?}", parts.names());
    }

    #[test]
    fn the_nearer_triangle_moved_off_the_pixel_is_not_band() {
        // The nearer triangle 0.01 units (about 5 pixels) up: its edge no longer passes near
        // the pixel centre, and nothing else marks the sample.
        let mut scene = keyframe();
        for p in &mut scene.positions[..3] {
            p[1] += 0.01;
        }
        let (_, class, parts) = scene.judged(8, false, (2560, 1440));
        assert_eq!(class, SampleClass::Lit);
        assert_eq!(parts, BandParts::NONE, "{:?}", parts.names());
    }
}
