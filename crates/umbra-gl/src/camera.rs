//! Pinhole camera with an INFINITE far plane (Everitt & Kilgard 2002, "Practical and Robust
//! Stenciled Shadow Volumes", §"infinite view frustum"; used by paper 003 [MHE*03] to keep
//! the caps at infinity unclipped).
//!
//! `clip_from_view` (OpenGL clip conventions, -w <= z <= w):
//! ```text
//! | f/aspect 0  0   0  |
//! | 0        f  0   0  |      f = 1 / tan(fov_y / 2)
//! | 0        0 -1  -2n |
//! | 0        0 -1   0  |
//! ```
//! A point at infinity (w = 0) maps to z_clip = w_clip, i.e. depth exactly 1; finite points in
//! front of the near plane get depth 1 - n / distance < 1. Matrices are built in f64 and
//! uploaded as f32.

use glam::{DMat4, DVec3, DVec4};

use crate::error::GlError;

/// Eye, target, up (world space), vertical field of view in degrees, near plane distance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    pub eye: [f64; 3],
    pub target: [f64; 3],
    pub up: [f64; 3],
    pub fov_y_degrees: f64,
    pub near: f64,
}

impl Default for Camera {
    fn default() -> Self {
        Self { eye: [0.0, 1.0, 3.0], target: [0.0; 3], up: [0.0, 1.0, 0.0], fov_y_degrees: 60.0, near: 0.05 }
    }
}

impl Camera {
    /// A camera at `eye` looking at `target`, +Y up, 60 degrees, near 0.05.
    pub fn look_at(eye: [f64; 3], target: [f64; 3]) -> Self {
        Self { eye, target, ..Self::default() }
    }

    /// Rejects a camera that defines no view: eye == target, up parallel to the view
    /// direction, fov outside (0, 180), near <= 0 or anything non-finite.
    pub fn validate(&self) -> Result<(), GlError> {
        let all = [self.eye, self.target, self.up].concat();
        if all.iter().chain([&self.fov_y_degrees, &self.near]).any(|v| !v.is_finite()) {
            return Err(GlError::InvalidParams(format!("camera has a non-finite value: {self:?}")));
        }
        let dir = DVec3::from(self.target) - DVec3::from(self.eye);
        if dir.length_squared() == 0.0 {
            return Err(GlError::InvalidParams("camera eye equals target".into()));
        }
        let up = DVec3::from(self.up);
        if dir.cross(up).length_squared() <= 1e-24 * dir.length_squared() * up.length_squared() {
            return Err(GlError::InvalidParams(format!("camera up {:?} is parallel to the view direction", self.up)));
        }
        if !(self.fov_y_degrees > 0.0 && self.fov_y_degrees < 180.0) {
            return Err(GlError::InvalidParams(format!("fov {} degrees is outside (0, 180)", self.fov_y_degrees)));
        }
        if self.near <= 0.0 {
            return Err(GlError::InvalidParams(format!("near plane {} must be > 0", self.near)));
        }
        Ok(())
    }

    /// Right-handed look-at: the camera looks down -Z in view space, +Y up.
    pub fn view_from_world(&self) -> DMat4 {
        DMat4::look_at_rh(self.eye.into(), self.target.into(), self.up.into())
    }

    /// Infinite-far perspective (see module doc); `aspect` = width / height.
    pub fn clip_from_view(&self, aspect: f64) -> DMat4 {
        let f = 1.0 / (0.5 * self.fov_y_degrees.to_radians()).tan();
        let n = self.near;
        DMat4::from_cols(
            DVec4::new(f / aspect, 0.0, 0.0, 0.0),
            DVec4::new(0.0, f, 0.0, 0.0),
            DVec4::new(0.0, 0.0, -1.0, -1.0),
            DVec4::new(0.0, 0.0, -2.0 * n, 0.0),
        )
    }

    pub fn clip_from_world(&self, aspect: f64) -> DMat4 {
        self.clip_from_view(aspect) * self.view_from_world()
    }

    /// Where a world point lands in a `width x height` image: `[x, y, depth]` with x from the
    /// left edge and y from the TOP edge in pixels (pixel (i, j) covers [i, i+1) x [j, j+1)),
    /// depth in [0, 1]. `None` when the point is not in front of the camera.
    pub fn project(&self, world: [f64; 3], width: u32, height: u32) -> Option<[f64; 3]> {
        let clip = self.clip_from_world(width as f64 / height as f64) * DVec4::new(world[0], world[1], world[2], 1.0);
        if clip.w <= 0.0 {
            return None;
        }
        let ndc = clip.truncate() / clip.w;
        Some([
            (ndc.x * 0.5 + 0.5) * width as f64,
            (0.5 - ndc.y * 0.5) * height as f64,
            ndc.z * 0.5 + 0.5,
        ])
    }
}

/// Column-major f32 copy for glUniformMatrix4fv.
pub fn to_f32_cols(m: &DMat4) -> [f32; 16] {
    m.to_cols_array().map(|v| v as f32)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn point_at_infinity_has_depth_exactly_one() {
        let cam = Camera::look_at([1.0, 2.0, 3.0], [0.0, 0.0, 0.0]);
        let m = cam.clip_from_world(16.0 / 9.0);
        // Direction roughly along the view direction, w = 0.
        let c = m * DVec4::new(-1.0, -2.0, -3.0, 0.0);
        assert!(c.w > 0.0);
        assert_eq!(c.z, c.w);
    }

    #[test]
    fn near_plane_maps_to_depth_zero_and_far_points_approach_one() {
        let cam = Camera { near: 0.5, ..Camera::look_at([0.0, 0.0, 0.0], [0.0, 0.0, -1.0]) };
        let near = cam.project([0.0, 0.0, -0.5], 100, 100).expect("in front");
        assert!(near[2].abs() < 1e-12, "{near:?}");
        let far = cam.project([0.0, 0.0, -5.0e5], 100, 100).expect("in front");
        assert!(far[2] < 1.0 && far[2] > 0.999_998, "{far:?}");
        // The view centre projects to the image centre.
        assert!((near[0] - 50.0).abs() < 1e-9 && (near[1] - 50.0).abs() < 1e-9);
        assert!(cam.project([0.0, 0.0, 1.0], 100, 100).is_none());
    }

    #[test]
    fn y_grows_downwards_in_pixels() {
        let cam = Camera::look_at([0.0, 0.0, 5.0], [0.0, 0.0, 0.0]);
        let up = cam.project([0.0, 1.0, 0.0], 64, 64).expect("visible");
        assert!(up[1] < 32.0);
    }

    #[test]
    fn degenerate_cameras_are_rejected() {
        assert!(Camera::look_at([0.0; 3], [0.0; 3]).validate().is_err());
        assert!(Camera::look_at([0.0, 5.0, 0.0], [0.0; 3]).validate().is_err(), "up parallel to view");
        assert!(Camera { fov_y_degrees: 180.0, ..Camera::default() }.validate().is_err());
        assert!(Camera { near: 0.0, ..Camera::default() }.validate().is_err());
        assert!(Camera::default().validate().is_ok());
    }
}
