//! [`FrameParams`]: everything that defines one frame, shared by every backend, and the
//! shadow-volume [`Counter`] it names.
//!
//! A backend that cannot honour a value refuses the frame with a typed error before any GPU
//! work: umbra-wgpu draws reversed-Z with the 8-bit stencil counter and both faces only,
//! umbra-gl draws every value.

use crate::camera::{Camera, CameraError, DepthConvention};
use crate::frame_images::{CaptureFlags, LightCapture};
use crate::{check_light, InvalidLight, Light};

/// Which counter the volume pass uses.
///
/// Counting (Heidmann 1991 z-pass; Everitt & Kilgard 2002 z-fail): every volume face in
/// front of (z-pass) or behind (z-fail) a visible sample adds +1 or -1; the sum at a sample is
/// the number of triangles between it and the light, and the sample is lit iff it is 0. The
/// 8-bit stencil counts modulo 256, so 256 layers read as lit; [`crate::winding_bound`]
/// bounds the count per mesh and light to tell when that can happen.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Counter {
    /// The 8-bit stencil, INCR_WRAP / DECR_WRAP: exact only while every count is below 256.
    #[default]
    Stencil8,
    /// An f32 count resolved into the stencil: exact below 2^24.
    Float32,
}

impl Counter {
    /// "stencil8" or "float32".
    pub fn name(self) -> &'static str {
        match self {
            Counter::Stencil8 => "stencil8",
            Counter::Float32 => "float32",
        }
    }
}

/// Which faces of a triangle can be the surface a pixel shows: the depth pass (and every pass
/// that re-draws the scene with depth EQUAL) culls the others. Casters cast from both faces
/// whatever this says: the shadow volumes are the same either way.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Receivers {
    /// Both faces: a pixel shows the nearest triangle (triangle soups are two-sided).
    #[default]
    Both,
    /// Front faces only (counter-clockwise on the screen, GL's default `glFrontFace(GL_CCW)`):
    /// a pixel shows the nearest triangle that faces the eye, as three.js draws a `FrontSide`
    /// material, so a surface behind a back-facing sheet shows through it.
    Front,
}

impl Receivers {
    /// "both" or "front".
    pub fn name(self) -> &'static str {
        match self {
            Receivers::Both => "both",
            Receivers::Front => "front",
        }
    }
}

/// Everything that defines one frame.
#[derive(Clone, Debug, PartialEq)]
pub struct FrameParams {
    /// The camera (infinite far plane).
    pub camera: Camera,
    /// Frame width in pixels.
    pub width: u32,
    /// Frame height in pixels.
    pub height: u32,
    /// Homogeneous lights: w = 1 point, w = 0 directional (light comes FROM xyz).
    pub lights: Vec<Light>,
    /// Colour (and intensity) of every light.
    pub light_color: [f32; 3],
    /// z-pass counting instead of z-fail for every light, whatever the eye's position (wrong
    /// when the camera is inside a shadow volume).
    pub zpass: bool,
    /// z-pass counting for each light whose volumes provably leave the eye out
    /// ([`crate::clearance`]: no triangle meets the hull of the eye, the near-plane rectangle
    /// and the light), z-fail for the others. Exact like z-fail (the same count at every
    /// visible sample) and cheaper: no caps, and the volumes are clipped to the box around the
    /// scene and the eye instead of running to infinity. Counting methods (those lit where
    /// the stencil is 0) only. Default on; each backend's renderer tells which lights of the
    /// last frame counted z-pass.
    pub auto_zpass: bool,
    /// Ambient factor: pass 1 writes `albedo * ambient`.
    pub ambient: f32,
    /// Surface colour (all surfaces).
    pub albedo: [f32; 3],
    /// Blinn-Phong specular strength.
    pub specular: f32,
    /// Blinn-Phong specular exponent.
    pub shininess: f32,
    /// Clear colour (RGBA, 0..1).
    pub background: [f32; 4],
    /// Which extra images the renderer's `render` reads back.
    pub capture: CaptureFlags,
    /// Depth convention of the frame (default [`DepthConvention::ReversedZ`]). On umbra-gl it
    /// also picks the depth format of the renderer's own target, and a caller's framebuffer
    /// is drawn in it (reversed-Z is correct with any depth format but gains its precision
    /// only with a float one). umbra-wgpu draws reversed-Z only.
    pub depth_convention: DepthConvention,
    /// The shadow-volume counter: the 8-bit stencil (default; wraps at 256) or an f32 count
    /// resolved into the stencil, for methods that count in the stencil. umbra-wgpu counts in
    /// the 8-bit stencil only.
    pub counter: Counter,
    /// Cull and clamp the shadow volumes against each light's visible receivers (default on):
    /// the methods that can (cpu-silhouette on umbra-gl) drop the triangles whose shadow
    /// frustum holds no visible sample and end the others just beyond their farthest receiver
    /// (docs/exactness.md, "Volumes clamped to their receivers"); the same decision at every
    /// sample. Off: the unclamped volumes, to measure the difference.
    pub volume_cull: bool,
    /// Which faces the depth pass shows (default both; [`Receivers`]).
    pub receivers: Receivers,
}

impl Default for FrameParams {
    /// 1280x720, default camera, no lights, auto z-pass (z-fail where it cannot be proved
    /// exact), light grey surfaces, ambient 0.15, white light, dark blue-grey background,
    /// reversed-Z, the 8-bit stencil counter, volumes culled against their receivers, both faces shown.
    fn default() -> Self {
        Self {
            camera: Camera::default(),
            width: 1280,
            height: 720,
            lights: Vec::new(),
            light_color: [1.0; 3],
            zpass: false,
            auto_zpass: true,
            ambient: 0.15,
            albedo: [0.8; 3],
            specular: 0.25,
            shininess: 32.0,
            background: [0.10, 0.12, 0.16, 1.0],
            capture: CaptureFlags::default(),
            depth_convention: DepthConvention::default(),
            counter: Counter::default(),
            volume_cull: true,
            receivers: Receivers::Both,
        }
    }
}

/// A frame no backend can draw; the message names the parameter and the problem.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct InvalidFrame(pub String);

impl From<CameraError> for InvalidFrame {
    fn from(e: CameraError) -> Self {
        InvalidFrame(e.0)
    }
}

impl From<InvalidLight> for InvalidFrame {
    fn from(e: InvalidLight) -> Self {
        InvalidFrame(e.0)
    }
}

impl FrameParams {
    /// The checks every backend makes before drawing: [`Self::check_view`], every light
    /// ([`check_light`]), the capture flags naming an existing light, [`Self::check_shading`].
    pub fn check(&self) -> Result<(), InvalidFrame> {
        self.check_view()?;
        for (i, l) in self.lights.iter().enumerate() {
            check_light(i, l)?;
        }
        for (what, capture) in [("stencil", self.capture.stencil), ("lit mask", self.capture.lit_mask)] {
            if let LightCapture::Light(i) = capture {
                if i >= self.lights.len() {
                    return Err(InvalidFrame(format!(
                        "{what} capture of light {i}, but {} light(s)",
                        self.lights.len()
                    )));
                }
            }
        }
        self.check_shading()
    }

    /// The camera defines a view ([`Camera::validate`]) and the frame has pixels.
    pub fn check_view(&self) -> Result<(), InvalidFrame> {
        self.camera.validate()?;
        if self.width == 0 || self.height == 0 {
            return Err(InvalidFrame(format!("frame size {}x{}", self.width, self.height)));
        }
        Ok(())
    }

    /// Colours and shading parameters are finite.
    pub fn check_shading(&self) -> Result<(), InvalidFrame> {
        let scalars = [self.ambient, self.specular, self.shininess];
        if scalars.iter().chain(&self.albedo).chain(&self.light_color).chain(&self.background).any(|v| !v.is_finite()) {
            return Err(InvalidFrame("non-finite colour or shading parameter".into()));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults() {
        let p = FrameParams::default();
        assert_eq!((p.width, p.height), (1280, 720));
        assert!(!p.zpass && p.auto_zpass);
        assert_eq!(p.depth_convention, DepthConvention::ReversedZ);
        assert_eq!(p.counter, Counter::Stencil8);
        assert_eq!(Counter::Stencil8.name(), "stencil8");
        assert_eq!(Counter::Float32.name(), "float32");
        assert_eq!(p.receivers, Receivers::Both);
        assert_eq!((Receivers::Both.name(), Receivers::Front.name()), ("both", "front"));
    }

    #[test]
    fn check_names_the_bad_parameter() {
        assert!(FrameParams::default().check().is_ok());
        let empty = FrameParams { width: 0, ..FrameParams::default() };
        assert_eq!(empty.check().unwrap_err().to_string(), "frame size 0x720");
        let dark = FrameParams { lights: vec![[0.0; 4]], ..FrameParams::default() };
        assert_eq!(dark.check().unwrap_err().to_string(), "light 0 is directional with a zero direction");
        let capture = CaptureFlags { stencil: LightCapture::Light(1), ..CaptureFlags::default() };
        let unknown = FrameParams { lights: vec![[0.0, 1.0, 0.0, 0.0]], capture, ..FrameParams::default() };
        assert_eq!(unknown.check().unwrap_err().to_string(), "stencil capture of light 1, but 1 light(s)");
        let nan = FrameParams { ambient: f32::NAN, ..FrameParams::default() };
        assert_eq!(nan.check_shading().unwrap_err().to_string(), "non-finite colour or shading parameter");
    }
}
