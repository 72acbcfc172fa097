//! What a frame's volumes are prepared for: its camera ([`View`], reversed-Z with an infinite
//! far plane), its lights and how they count ([`ZMode`]), together a [`VolumeFrame`].

use glam::DMat4;
use umbra_geom::camera::{to_f32_cols, Camera, DepthConvention};
use umbra_geom::Light;

use crate::error::WgpuError;

/// How the volumes count, per light.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ZMode {
    /// z-pass for every light, whatever the eye's position (wrong when the camera is inside a
    /// shadow volume).
    pub zpass: bool,
    /// z-pass for each light whose volumes provably leave the eye's near pyramid alone
    /// ([`umbra_geom::clearance`]), z-fail for the others. Exact like z-fail, cheaper (no
    /// caps, volumes clipped to the scene box). Counting methods only.
    pub auto_zpass: bool,
}

impl Default for ZMode {
    /// Automatic z-pass (exact).
    fn default() -> Self {
        Self { zpass: false, auto_zpass: true }
    }
}

/// The camera of a frame: reversed-Z, infinite far plane.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct View {
    clip_from_world: DMat4,
    pub(crate) world_from_clip: DMat4,
    pub(crate) eye: [f64; 3],
}

impl View {
    /// umbra's camera for a `width x height` frame:
    /// `camera.clip_from_world_in(width / height, DepthConvention::ReversedZ)`.
    pub fn from_camera(camera: &Camera, width: u32, height: u32) -> Result<Self, WgpuError> {
        camera.validate()?;
        if width == 0 || height == 0 {
            return Err(WgpuError::InvalidParams(format!("frame size {width}x{height}")));
        }
        let m = camera.clip_from_world_in(width as f64 / height as f64, DepthConvention::ReversedZ);
        Self::from_matrix(m.to_cols_array_2d(), camera.eye)
    }

    /// A host's own matrix (column-major, `m[column][row]`), reversed-Z with an infinite far
    /// plane (a point at infinity has clip z = 0), and its eye position. Must be finite and
    /// invertible.
    pub fn from_matrix(clip_from_world: [[f64; 4]; 4], eye: [f64; 3]) -> Result<Self, WgpuError> {
        let m = DMat4::from_cols_array_2d(&clip_from_world);
        let inverse = m.inverse();
        if !m.is_finite() || !inverse.is_finite() || !eye.iter().all(|c| c.is_finite()) {
            return Err(WgpuError::InvalidParams(format!(
                "view matrix {clip_from_world:?} with eye {eye:?} is not finite and invertible"
            )));
        }
        Ok(Self { clip_from_world: m, world_from_clip: inverse, eye })
    }

    /// The matrix the shaders use (f32 columns): the host's depth pass must use exactly this.
    pub fn clip_from_world_f32(&self) -> [f32; 16] {
        to_f32_cols(&self.clip_from_world)
    }

    /// The f64 matrix.
    pub fn clip_from_world(&self) -> DMat4 {
        self.clip_from_world
    }

    /// The eye (world space).
    pub fn eye(&self) -> [f64; 3] {
        self.eye
    }
}

/// One frame's lights as [`ShadowVolumes::prepare`](crate::ShadowVolumes::prepare) takes them.
#[derive(Clone, Copy, Debug)]
pub struct VolumeFrame<'a> {
    /// The camera the caller's depth was drawn with.
    pub view: &'a View,
    /// The lights (w = 1 point, w = 0 directional, light coming FROM xyz), in the order
    /// [`ShadowVolumes::draw`](crate::ShadowVolumes::draw) indexes them.
    pub lights: &'a [Light],
    /// How the volumes count.
    pub zmode: ZMode,
    /// The scene's depth as the caller drew it, already submitted, for the methods that cull
    /// and clamp their volumes against the visible samples (`cpu-silhouette`,
    /// [`ShadowVolumes::culls_volumes`](crate::ShadowVolumes::culls_volumes)); `None` draws
    /// every volume unculled. The texture needs `RENDER_ATTACHMENT | TEXTURE_BINDING`, one
    /// sample, and the device `PRIMITIVE_INDEX`. Culling costs a scene draw, a submission and
    /// a wait per light: the CPU needs each light's receiver map before it can extract the
    /// volume (docs/exactness.md, "Volumes clamped to their receivers").
    pub receivers: Option<&'a wgpu::Texture>,
}
