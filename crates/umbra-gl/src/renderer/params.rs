//! [`FrameParams`]: everything that defines one frame, and its defaults.

use crate::camera::{Camera, DepthConvention};
use crate::counter::Counter;
use umbra_geom::frame_images::CaptureFlags;
use umbra_geom::Light;

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
    /// ([`umbra_geom::clearance`]: no triangle meets the hull of the eye, the near-plane
    /// rectangle and the light), z-fail for the others. Exact like z-fail (the same count at
    /// every visible sample) and cheaper: no caps, and the volumes are clipped to the box
    /// around the scene and the eye instead of running to infinity. Counting methods
    /// ([`crate::methods::Classification::StencilZero`]) only. Default on. [`Renderer::last_zpass`](super::Renderer::last_zpass) tells
    /// which lights of the last frame counted z-pass.
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
    /// Which extra images [`Renderer::render`](super::Renderer::render) reads back.
    pub capture: CaptureFlags,
    /// Depth convention of the frame (default [`DepthConvention::ReversedZ`]). It also picks
    /// the depth format of the renderer's own target; with [`Renderer::draw_frame`](super::Renderer::draw_frame) the
    /// caller's framebuffer is drawn in it (reversed-Z is correct with any depth format but
    /// gains its precision only with a float one).
    pub depth_convention: DepthConvention,
    /// The shadow-volume counter ([`crate::counter`]): the 8-bit stencil (default; wraps at
    /// 256) or an f32 count resolved into the stencil, for methods that count in the stencil.
    pub counter: Counter,
}

impl Default for FrameParams {
    /// 1280x720, default camera, no lights, z-fail, light grey surfaces, ambient 0.15, white
    /// light, dark blue-grey background, reversed-Z.
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
        }
    }
}
