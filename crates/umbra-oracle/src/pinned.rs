//! Test support: a view pinned from a real failure (delta-debugged triangles as f32 bit
//! patterns, the light, the sample and the camera), shared by the band parts' regression tests.

use umbra_geom::camera::{Camera, DepthConvention};
use umbra_geom::WeldedMesh;

use crate::envelope::{BandParts, RasterView};
use crate::{reference_in_view, Bvh, SampleClass, Samples};

/// The triangles that decide one pixel, the light, the sample's world position and the camera
/// that saw it.
pub struct PinnedView {
    pub positions: Vec<[f32; 3]>,
    pub triangles: Vec<[u32; 3]>,
    pub light: [f32; 4],
    pub sample: [f32; 3],
    pub camera: Camera,
}

impl PinnedView {
    /// Renders nothing but the reference: the pixel the sample projects to at `width x height`
    /// (reversed-Z, a float depth buffer, `bits` sub-pixel bits; judged as an external mask's
    /// with `other_depth_pass`), with the sample alone in the frame, and that sample's class and
    /// band parts.
    pub fn judged(
        &self,
        bits: u32,
        other_depth_pass: bool,
        (width, height): (u32, u32),
    ) -> ((u32, u32), SampleClass, BandParts) {
        let cols = self.camera.clip_from_world_cols(f64::from(width) / f64::from(height), DepthConvention::ReversedZ);
        let clip_from_world: [f64; 16] = std::array::from_fn(|i| cols[i / 4][i % 4]);
        let view = RasterView { subpixel_bits: bits, other_depth_pass, ..RasterView::new(clip_from_world) };
        let s = self.sample.map(f64::from);
        let [x, y] = view.window_xy(s, width, height).unwrap().map(|c| c.floor() as u32);
        let i = (y * width + x) as usize;
        let mut world_pos = vec![[0f32; 3]; (width * height) as usize];
        let mut triangle = vec![u32::MAX; (width * height) as usize];
        (world_pos[i], triangle[i]) = (self.sample, 0);
        let mesh = WeldedMesh {
            positions: self.positions.clone(),
            triangles: self.triangles.clone(),
            source_triangle: (0..self.triangles.len() as u32).collect(),
            degenerate_triangles: 0,
        };
        let bvh = Bvh::build(&mesh.positions, &mesh.triangles).unwrap();
        let samples = Samples { width, height, world_pos: &world_pos, triangle: &triangle };
        let eye = self.camera.eye.map(|c| c as f32);
        let r = reference_in_view(&mesh, &bvh, &samples, self.light, eye, Some(&view)).unwrap();
        ((x, y), r.class[i], r.parts[i])
    }
}
