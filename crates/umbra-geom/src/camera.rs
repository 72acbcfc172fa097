//! Pinhole camera with an INFINITE far plane (Everitt & Kilgard 2002, "Practical and Robust
//! Stenciled Shadow Volumes", §"infinite view frustum"; used by paper 003 \[MHE*03\] to keep
//! the caps at infinity unclipped), in one of two depth conventions ([`DepthConvention`]).
//!
//! Standard (OpenGL's default clip convention, -w <= z <= w, depth = z_ndc / 2 + 1 / 2):
//! ```text
//! | f/aspect 0  0   0  |
//! | 0        f  0   0  |      f = 1 / tan(fov_y / 2)
//! | 0        0 -1  -2n |
//! | 0        0 -1   0  |
//! ```
//! A point at infinity (w = 0) maps to z_clip = w_clip, i.e. depth exactly 1; a finite point at
//! view distance d gets depth 1 - n / d.
//!
//! Reversed-Z (glClipControl(LOWER_LEFT, ZERO_TO_ONE) on OpenGL; wgpu's, Vulkan's, Metal's and
//! D3D's own clip convention), 0 <= z <= w, depth = z_ndc):
//! ```text
//! | f/aspect 0  0   0 |
//! | 0        f  0   0 |
//! | 0        0  0   n |
//! | 0        0 -1   0 |
//! ```
//! depth = n / d: 1 at the near plane, falling towards 0 with distance; a point at infinity
//! (w = 0) gets z_clip = 0 * w exactly, i.e. depth exactly 0 (the far plane). Because row 2 of
//! `clip_from_world` is then exactly (0, 0, 0, n), z_clip of a finite point is the constant n
//! and all rounding sits in w_clip = d, a relative error of ~2^-24: stored in a float depth
//! buffer, depth resolves distance to ~d * 2^-24 at every distance. The standard convention
//! with a 24-bit fixed-point buffer resolves only d^2 / (n * 2^24) (the quantum 2^-24 of
//! 1 - n / d), e.g. d = 30, n = 0.05: 1.1e-3 instead of 1.8e-6 — the difference between
//! volume sides that z-fight with a surface several pixels away from where they meet it and
//! ones that do not.
//!
//! Orthographic ([`Projection::Orthographic`]): parallel rays, w_clip = 1 everywhere, a FINITE
//! far plane (a point at infinity has clip w = 0 there, so no far plane at infinity exists):
//! ```text
//! | 2/(h aspect) 0    0   0 |      Standard:   a = -2/(far-near), b = -(far+near)/(far-near)
//! | 0            2/h  0   0 |      reversed-Z: a =  1/(far-near), b =  far/(far-near)
//! | 0            0    a   b |
//! | 0            0    0   1 |
//! ```
//! The depth is linear in the view distance d: (d - near)/(far - near) Standard,
//! (far - d)/(far - near) reversed-Z.
//!
//! Matrices are built in f64 and uploaded as f32.
//!
//! Shared by every backend (moved here from umbra-gl so that umbra-wgpu uses the very same
//! matrices): umbra-gl re-exports [`Camera`] and [`DepthConvention`] and adds the GL enums of
//! a convention (depth function, clip-control mode, depth format) in its `DepthConventionGl`
//! trait. Also here: the eye's near pyramid the auto z-pass test uses
//! ([`near_pyramid_points`]).

use glam::{DMat4, DVec3, DVec4};

/// How clip-space z maps to the depth buffer; see the module documentation.
///
/// Every convention-dependent choice of the renderer and the shadow methods is derived from
/// this value (projection, depth clear value, depth comparison, far-plane clip z, clip
/// control), so nothing else needs to know which one is in use.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum DepthConvention {
    /// OpenGL's default: clip z in [-w, w], depth 0 at the near plane, 1 at infinity, cleared
    /// to 1, nearer = LESS. Works on any GL (no glClipControl needed) and with any depth
    /// format; the renderer's own target then uses DEPTH24_STENCIL8.
    Standard,
    /// Reversed-Z: glClipControl(LOWER_LEFT, ZERO_TO_ONE), depth 1 at the near plane, 0 at
    /// infinity, cleared to 0, nearer = GREATER; the renderer's own target uses
    /// DEPTH32F_STENCIL8. Needs glClipControl (GL 4.5 / ARB_clip_control).
    #[default]
    ReversedZ,
}

impl DepthConvention {
    /// Clip-space z of the far plane as a multiple of clip w (paper 003 Eq. 6 pushes light caps
    /// there): 1 for Standard, 0 for ReversedZ.
    pub fn far_clip_z(self) -> f32 {
        match self {
            DepthConvention::Standard => 1.0,
            DepthConvention::ReversedZ => 0.0,
        }
    }

    /// Depth-buffer value of the far plane (and of the background): the depth clear value.
    pub fn far_depth(self) -> f32 {
        match self {
            DepthConvention::Standard => 1.0,
            DepthConvention::ReversedZ => 0.0,
        }
    }
}

/// A camera that defines no view ([`Camera::validate`]); the message says what is wrong.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct CameraError(pub String);

/// How view space maps to clip space: [`Camera::clip_from_view_in`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum Projection {
    /// Pinhole at the eye with the infinite far plane of the module documentation; the
    /// vertical field of view is [`Camera::fov_y_degrees`].
    #[default]
    Perspective,
    /// Parallel rays along the view direction, the eye at infinity behind the camera: a view
    /// `height` world units tall (the width follows the image's aspect), between the near
    /// plane ([`Camera::near`]) and a FINITE far plane at view distance `far` (> near). A
    /// point at infinity has clip w = 0 under an orthographic matrix, so there is no far
    /// plane at infinity: `far` must lie beyond everything drawn (umbra's CLI puts it beyond
    /// the scene's bounds). Standard convention: z_clip = (-2 z_view - (far + near)) /
    /// (far - near), w_clip = 1 (depth (d - near) / (far - near) at view distance d);
    /// reversed-Z: z_clip = (z_view + far) / (far - near) (depth (far - d) / (far - near)).
    Orthographic {
        /// View-space height of the image (world units).
        height: f64,
        /// View distance of the far plane.
        far: f64,
    },
}

/// Eye, target, up (world space), vertical field of view in degrees, near plane distance and
/// the [`Projection`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Eye position (world space).
    pub eye: [f64; 3],
    /// The point looked at (world space).
    pub target: [f64; 3],
    /// Up direction (world space; need not be unit length or orthogonal to the view).
    pub up: [f64; 3],
    /// Vertical field of view in degrees, in (0, 180).
    pub fov_y_degrees: f64,
    /// Near plane distance (> 0); the far plane is at infinity (perspective) or at the
    /// orthographic projection's `far`.
    pub near: f64,
    /// Perspective (the default) or orthographic.
    pub projection: Projection,
}

impl Default for Camera {
    fn default() -> Self {
        Self {
            eye: [0.0, 1.0, 3.0],
            target: [0.0; 3],
            up: [0.0, 1.0, 0.0],
            fov_y_degrees: 60.0,
            near: 0.05,
            projection: Projection::Perspective,
        }
    }
}

impl Camera {
    /// A camera at `eye` looking at `target`, +Y up, 60 degrees, near 0.05.
    ///
    /// Takes anything that converts into `[f64; 3]`: plain arrays, `mint::Point3<f64>` /
    /// `mint::Vector3<f64>` (mint's own `From` impls) or glam's `DVec3`, so a host can pass its
    /// own math types without umbra depending on them.
    pub fn look_at(eye: impl Into<[f64; 3]>, target: impl Into<[f64; 3]>) -> Self {
        Self { eye: eye.into(), target: target.into(), ..Self::default() }
    }

    /// This camera with up direction `up` (arrays, mint or glam vectors as in
    /// [`Camera::look_at`]).
    pub fn with_up(self, up: impl Into<[f64; 3]>) -> Self {
        Self { up: up.into(), ..self }
    }

    /// [`Camera::clip_from_world_in`] as plain column-major columns (`m[column][row]`), the
    /// layout of `mint::ColumnMatrix4<f64>` (which converts from it) and of glUniformMatrix4
    /// with `transpose = false`: the matrix a host's vertex shader must use for its depth
    /// when umbra counts shadows against it (umbra-gl's `Renderer::count_shadows`, umbra-wgpu's
    /// `ShadowVolumes`), after
    /// rounding to f32 exactly as [`to_f32_cols`] does.
    pub fn clip_from_world_cols(&self, aspect: f64, convention: DepthConvention) -> [[f64; 4]; 4] {
        self.clip_from_world_in(aspect, convention).to_cols_array_2d()
    }

    /// Rejects a camera that defines no view: eye == target, up parallel to the view
    /// direction, fov outside (0, 180), near <= 0 or anything non-finite.
    pub fn validate(&self) -> Result<(), CameraError> {
        let all = [self.eye, self.target, self.up].concat();
        if all.iter().chain([&self.fov_y_degrees, &self.near]).any(|v| !v.is_finite()) {
            return Err(CameraError(format!("camera has a non-finite value: {self:?}")));
        }
        let dir = DVec3::from(self.target) - DVec3::from(self.eye);
        if dir.length_squared() == 0.0 {
            return Err(CameraError("camera eye equals target".into()));
        }
        let up = DVec3::from(self.up);
        if dir.cross(up).length_squared() <= 1e-24 * dir.length_squared() * up.length_squared() {
            return Err(CameraError(format!("camera up {:?} is parallel to the view direction", self.up)));
        }
        if !(self.fov_y_degrees > 0.0 && self.fov_y_degrees < 180.0) {
            return Err(CameraError(format!("fov {} degrees is outside (0, 180)", self.fov_y_degrees)));
        }
        if self.near <= 0.0 {
            return Err(CameraError(format!("near plane {} must be > 0", self.near)));
        }
        if let Projection::Orthographic { height, far } = self.projection {
            if !(height.is_finite() && height > 0.0) {
                return Err(CameraError(format!("orthographic height {height} must be a finite number > 0")));
            }
            if !(far.is_finite() && far > self.near) {
                return Err(CameraError(format!(
                    "orthographic far plane {far} must be finite and beyond the near plane {}",
                    self.near
                )));
            }
        }
        Ok(())
    }

    /// Right-handed look-at: the camera looks down -Z in view space, +Y up.
    pub fn view_from_world(&self) -> DMat4 {
        DMat4::look_at_rh(self.eye.into(), self.target.into(), self.up.into())
    }

    /// [`Camera::clip_from_view_in`] in the Standard convention; `aspect` = width / height.
    pub fn clip_from_view(&self, aspect: f64) -> DMat4 {
        self.clip_from_view_in(aspect, DepthConvention::Standard)
    }

    /// Whether the projection is orthographic (the eye at infinity, parallel rays).
    pub fn is_orthographic(&self) -> bool {
        matches!(self.projection, Projection::Orthographic { .. })
    }

    /// The unit view direction, from the eye towards the target (world space).
    pub fn forward(&self) -> [f64; 3] {
        (DVec3::from(self.target) - DVec3::from(self.eye)).normalize_or_zero().into()
    }

    /// Infinite-far perspective or orthographic ([`Projection`]) in `convention` (see module
    /// doc).
    pub fn clip_from_view_in(&self, aspect: f64, convention: DepthConvention) -> DMat4 {
        if let Projection::Orthographic { height, far } = self.projection {
            return orthographic_clip_from_view(height, aspect, self.near, far, convention);
        }
        let f = 1.0 / (0.5 * self.fov_y_degrees.to_radians()).tan();
        let n = self.near;
        let (z, w) = match convention {
            // z_clip = -z_view - 2n, w_clip = -z_view.
            DepthConvention::Standard => (DVec4::new(0.0, 0.0, -1.0, -1.0), DVec4::new(0.0, 0.0, -2.0 * n, 0.0)),
            // z_clip = n * w_view, w_clip = -z_view.
            DepthConvention::ReversedZ => (DVec4::new(0.0, 0.0, 0.0, -1.0), DVec4::new(0.0, 0.0, n, 0.0)),
        };
        DMat4::from_cols(DVec4::new(f / aspect, 0.0, 0.0, 0.0), DVec4::new(0.0, f, 0.0, 0.0), z, w)
    }

    /// Standard-convention `clip_from_world`.
    pub fn clip_from_world(&self, aspect: f64) -> DMat4 {
        self.clip_from_world_in(aspect, DepthConvention::Standard)
    }

    /// `clip_from_world` in `convention`.
    pub fn clip_from_world_in(&self, aspect: f64, convention: DepthConvention) -> DMat4 {
        self.clip_from_view_in(aspect, convention) * self.view_from_world()
    }

    /// Where a world point lands in a `width x height` image: `[x, y, depth]` with x from the
    /// left edge and y from the TOP edge in pixels (pixel (i, j) covers [i, i+1) x [j, j+1)),
    /// depth in [0, 1] in the Standard convention. `None` when the point is not in front of
    /// the camera.
    pub fn project(&self, world: [f64; 3], width: u32, height: u32) -> Option<[f64; 3]> {
        self.project_in(world, width, height, DepthConvention::Standard)
    }

    /// [`Camera::project`] with the depth of `convention` (x and y do not depend on it).
    pub fn project_in(
        &self,
        world: [f64; 3],
        width: u32,
        height: u32,
        convention: DepthConvention,
    ) -> Option<[f64; 3]> {
        let m = self.clip_from_world_in(width as f64 / height as f64, convention);
        let clip = m * DVec4::new(world[0], world[1], world[2], 1.0);
        let in_front = match self.projection {
            Projection::Perspective => clip.w > 0.0,
            // w_clip is 1 everywhere: in front means beyond the eye's plane.
            Projection::Orthographic { .. } => {
                let view = self.view_from_world() * DVec4::new(world[0], world[1], world[2], 1.0);
                view.z < 0.0
            }
        };
        if !in_front {
            return None;
        }
        let ndc = clip.truncate() / clip.w;
        let depth = match convention {
            DepthConvention::Standard => ndc.z * 0.5 + 0.5,
            DepthConvention::ReversedZ => ndc.z,
        };
        Some([(ndc.x * 0.5 + 0.5) * width as f64, (0.5 - ndc.y * 0.5) * height as f64, depth])
    }
}

/// The orthographic clip_from_view of [`Projection::Orthographic`]: x and y scaled so that the
/// `height` x `height * aspect` view rectangle fills [-1, 1], view distance `near` at the near
/// plane's clip z (-1 Standard, 1 reversed-Z) and `far` at the far plane's (1, 0); w_clip = 1.
fn orthographic_clip_from_view(height: f64, aspect: f64, near: f64, far: f64, convention: DepthConvention) -> DMat4 {
    let (sx, sy) = (2.0 / (height * aspect), 2.0 / height);
    let span = far - near;
    // z_clip = a z_view + b with z_view = -d.
    let (a, b) = match convention {
        // d = near -> -1, d = far -> 1.
        DepthConvention::Standard => (-2.0 / span, -(far + near) / span),
        // d = near -> 1, d = far -> 0.
        DepthConvention::ReversedZ => (1.0 / span, far / span),
    };
    DMat4::from_cols(
        DVec4::new(sx, 0.0, 0.0, 0.0),
        DVec4::new(0.0, sy, 0.0, 0.0),
        DVec4::new(0.0, 0.0, a, 0.0),
        DVec4::new(0.0, 0.0, b, 1.0),
    )
}

/// Column-major f32 copy for glUniformMatrix4fv.
pub fn to_f32_cols(m: &DMat4) -> [f32; 16] {
    m.to_cols_array().map(|v| v as f32)
}

/// The eye and the corners of the near-plane rectangle (pushed 2 % outwards from its centre),
/// world space: the points whose hull with the light must be clear for z-pass
/// ([`crate::clearance`]). `world_from_clip` is the inverse of the frame's `clip_from_world`
/// in `convention`. Perspective cameras only: an orthographic camera's eye is at infinity, and
/// its z-pass counts from there with the finite volumes' winding 0 (docs/exactness.md,
/// "Orthographic views"), so the renderer takes no near pyramid for it.
pub fn near_pyramid_points(world_from_clip: &DMat4, eye: [f64; 3], convention: DepthConvention) -> Vec<[f64; 3]> {
    // Near plane in NDC: z = -1 (standard, [-1, 1] depth), z = 1 (reversed-Z, ZERO_TO_ONE).
    let z = match convention {
        DepthConvention::Standard => -1.0,
        DepthConvention::ReversedZ => 1.0,
    };
    let corners: Vec<[f64; 3]> = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
        .iter()
        .map(|&(x, y)| {
            let p = *world_from_clip * DVec4::new(x, y, z, 1.0);
            [p.x / p.w, p.y / p.w, p.z / p.w]
        })
        .collect();
    let mid: [f64; 3] = std::array::from_fn(|a| corners.iter().map(|c| c[a]).sum::<f64>() / 4.0);
    let mut points = vec![eye];
    points.extend(corners.iter().map(|c| std::array::from_fn(|a| mid[a] + 1.02 * (c[a] - mid[a]))));
    points
}

/// Where a z-pass count may start: [`near_pyramid_points`] with the corners pushed 2 % farther
/// from the eye, so that their hull holds the eye's whole near pyramid with room for rounding.
/// A receiver cull raises the receiver map over this hull (`ReceiverMap::raise_hull`), so that
/// no clamped volume ends inside it (docs/exactness.md, "Volumes clamped to their receivers").
pub fn zpass_start_points(world_from_clip: &DMat4, eye: [f64; 3], convention: DepthConvention) -> Vec<[f64; 3]> {
    let mut points = near_pyramid_points(world_from_clip, eye, convention);
    for p in points.iter_mut().skip(1) {
        *p = std::array::from_fn(|a| eye[a] + 1.02 * (p[a] - eye[a]));
    }
    points
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
    fn reversed_z_point_at_infinity_has_depth_exactly_zero() {
        let cam = Camera::look_at([1.0, 2.0, 3.0], [0.0, 0.0, 0.0]);
        let m = cam.clip_from_world_in(16.0 / 9.0, DepthConvention::ReversedZ);
        let m32 = to_f32_cols(&m);
        // As the GPU computes it: the f32 matrix times directions (w = 0) in several directions,
        // including ones off the view axis and behind the eye.
        for dir in [[-1.0f32, -2.0, -3.0], [0.3, -0.1, -0.9], [5.0, 1.0, -2.0], [1.0, 2.0, 3.0]] {
            let v = [dir[0], dir[1], dir[2], 0.0f32];
            let z: f32 = (0..4).map(|k| m32[4 * k + 2] * v[k]).sum();
            assert_eq!(z, 0.0, "{dir:?}");
        }
        // The f64 matrix agrees, and the point in front of the camera is inside the clip volume.
        let c = m * DVec4::new(-1.0, -2.0, -3.0, 0.0);
        assert!(c.w > 0.0);
        assert_eq!(c.z, 0.0);
        assert_eq!(DepthConvention::ReversedZ.far_clip_z(), 0.0);
        assert_eq!(DepthConvention::Standard.far_clip_z(), 1.0);
    }

    #[test]
    fn reversed_z_near_plane_maps_to_one_and_depth_is_near_over_distance() {
        let cam = Camera { near: 0.5, ..Camera::look_at([0.0, 0.0, 0.0], [0.0, 0.0, -1.0]) };
        let rz = DepthConvention::ReversedZ;
        let near = cam.project_in([0.0, 0.0, -0.5], 100, 100, rz).expect("in front");
        assert!((near[2] - 1.0).abs() < 1e-15, "{near:?}");
        for d in [1.0, 7.0, 1.0e3, 5.0e5] {
            let p = cam.project_in([0.0, 0.0, -d], 100, 100, rz).expect("in front");
            assert!((p[2] - 0.5 / d).abs() <= 1e-15 * (0.5 / d), "{d}: {p:?}");
        }
        // Row 2 of clip_from_world is exactly (0, 0, 0, n): z_clip of any finite point is n.
        let cam = Camera { near: 0.05, ..Camera::look_at([3.0, -2.0, 7.5], [0.1, 0.2, 0.3]) };
        let m = cam.clip_from_world_in(1.5, rz);
        assert_eq!(m.row(2), DVec4::new(0.0, 0.0, 0.0, 0.05));
        // x and y do not depend on the convention.
        let s = cam.project([0.5, 0.5, 0.5], 64, 48).expect("in front");
        let r = cam.project_in([0.5, 0.5, 0.5], 64, 48, rz).expect("in front");
        assert!((s[0] - r[0]).abs() < 1e-12 && (s[1] - r[1]).abs() < 1e-12);
    }

    #[test]
    fn orthographic_maps_the_view_box_to_the_clip_cube_in_both_conventions() {
        let proj = Projection::Orthographic { height: 4.0, far: 20.0 };
        let cam = Camera { near: 0.5, projection: proj, ..Camera::look_at([0.0, 0.0, 0.0], [0.0, 0.0, -1.0]) };
        assert!(cam.validate().is_ok() && cam.is_orthographic());
        let (w, h) = (200, 100); // aspect 2: 8 x 4 world units
        let s = cam.project([4.0, 2.0, -0.5], w, h).expect("in front");
        assert!((s[0] - 200.0).abs() < 1e-9 && s[1].abs() < 1e-9 && s[2].abs() < 1e-12, "{s:?}");
        let f = cam.project([-4.0, -2.0, -20.0], w, h).expect("in front");
        assert!(f[0].abs() < 1e-9 && (f[1] - 100.0).abs() < 1e-9 && (f[2] - 1.0).abs() < 1e-12, "{f:?}");
        let rz = DepthConvention::ReversedZ;
        let n = cam.project_in([1.0, 1.0, -0.5], w, h, rz).expect("in front");
        let m = cam.project_in([1.0, 1.0, -10.25], w, h, rz).expect("in front");
        assert!((n[2] - 1.0).abs() < 1e-12 && (m[2] - 0.5).abs() < 1e-12, "{n:?} {m:?}");
        // Parallel rays: x and y do not depend on the distance.
        assert!((n[0] - m[0]).abs() < 1e-9 && (n[1] - m[1]).abs() < 1e-9);
        assert!(cam.project([0.0, 0.0, 1.0], w, h).is_none(), "behind the eye");
        // A direction (w = 0) has clip w = 0: no far plane at infinity.
        let c = cam.clip_from_world(2.0) * DVec4::new(0.0, 0.0, -1.0, 0.0);
        assert_eq!(c.w, 0.0);
        for bad in [
            Projection::Orthographic { height: 0.0, far: 20.0 },
            Projection::Orthographic { height: -1.0, far: 20.0 },
            Projection::Orthographic { height: f64::NAN, far: 20.0 },
            Projection::Orthographic { height: 1.0, far: 0.25 },
        ] {
            assert!(Camera { projection: bad, ..cam }.validate().is_err(), "{bad:?}");
        }
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
