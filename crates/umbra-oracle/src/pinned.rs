//! Test support: a view pinned from a real failure (delta-debugged triangles as f32 bit
//! patterns, the light, the sample and the camera), shared by the band parts' regression tests.

use umbra_geom::camera::Camera;

/// The triangles that decide one pixel, the light, the sample's world position and the camera
/// that saw it.
pub struct PinnedView {
    pub positions: Vec<[f32; 3]>,
    pub triangles: Vec<[u32; 3]>,
    pub light: [f32; 4],
    pub sample: [f32; 3],
    pub camera: Camera,
}
