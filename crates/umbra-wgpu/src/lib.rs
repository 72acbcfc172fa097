//! umbra-wgpu: exact per-sample stencil shadow volumes for triangle soups on wgpu (Vulkan,
//! Metal, DX12; Mesa's lavapipe on machines without a GPU).
//!
//! The methods of umbra-gl that wgpu can express, with the same names and behaviour: z-fail
//! with caps at infinity (depth clamp through `unclipped_depth`, infinite far plane,
//! reversed-Z), z-pass where [`umbra_geom::clearance`] proves it exact, several point and
//! directional lights, silhouettes from paper 001's deterministic multiplicity with the
//! reference edge. Geometry- and tessellation-shader methods stay GL-only (wgpu has neither
//! stage). Every CPU step (adjacency, slots, clearance, the camera) is umbra-geom's.
//!
//! Robust by construction on every backend: WGSL has no `precise`, and drivers may contract
//! `a * b + c` differently in two pipelines. So each triangle's orientation towards the light
//! (001 Alg. 4 through the reference edge) is computed ONCE per light and frame, in one compute
//! pass writing one value per triangle (`shaders/orientation.wgsl`); the sides (an edge's
//! multiplicity is the sum of its triangles' ± orientations,
//! [`umbra_geom::silhouette::TriangleSlots`]) and the caps read that same value, so no
//! compiler can open a volume. Likewise every vertex is transformed to clip space once per light
//! (`shaders/transform.wgsl`; cpu-silhouette: one draw for its whole volume), and the volume
//! fragment shader writes the depth the test sees, a NaN made the far plane (lavapipe gave
//! needle side triangles NaN depths: a false shadow on Conference, pinned in
//! `umbra-verify/tests/wgpu_regressions.rs`). docs/wgpu.md has the details and the numbers.
//!
//! * [`volumes`]: the host API, [`ShadowVolumes`] (`new(device, formats, sample_count)`,
//!   `prepare(device, queue, encoder, ...)`, `draw(pass, light)`): shadow volumes counted into
//!   the stencil of the caller's render pass; its documentation lists what the caller must
//!   provide.
//! * [`renderer`]: the stand-alone frame ([`Renderer::render`]): depth + ambient (+ world
//!   position and triangle id for the verifier), per light volumes and lighting, PNG out,
//!   stencil and lit-mask readback.
//! * [`methods`]: the registry ([`method_names`]).
//! * [`FrameParams`]: umbra-geom's description of a frame, the one umbra-gl takes; a value
//!   this backend cannot draw (the f32 counter, the standard depth convention) is refused
//!   with [`WgpuError::Unsupported`].
//! * [`scene`]: [`SceneGpu`], a welded mesh uploaded once.
//! * [`device`]: [`HeadlessGpu`]; a missing adapter is [`WgpuError::NoAdapter`], which says what
//!   to install.
//!
//! # Example
//!
//! ```no_run
//! use std::sync::Arc;
//! use umbra_wgpu::{Camera, FrameParams, HeadlessGpu, Renderer, SceneGpu};
//!
//! let gpu = HeadlessGpu::new()?; // lavapipe without a GPU: apt-get install mesa-vulkan-drivers
//! let mut mesh = umbra_geom::scene::uv_sphere([0.0, 2.0, 0.0], 1.0, 32, 16);
//! mesh.append(&umbra_geom::scene::ground_plane([0.0; 3], 6.0));
//! let scene = SceneGpu::upload(&gpu.device, Arc::new(umbra_geom::weld::weld(&mesh)))?;
//! let mut renderer = Renderer::new(&gpu.device)?;
//! let mut volumes = renderer.volumes(&gpu.device, "cs-silhouette")?;
//! let params = FrameParams {
//!     camera: Camera::look_at([5.0, 5.0, 7.0], [0.0, 0.5, 0.0]),
//!     lights: vec![[1.0, 6.0, 0.5, 1.0]],
//!     ..FrameParams::default()
//! };
//! let frame = renderer.render(&gpu.device, &gpu.queue, &scene, &mut volumes, &params)?;
//! frame.rgba.save_png(std::path::Path::new("shadows.png"))?;
//! # Ok::<(), umbra_wgpu::WgpuError>(())
//! ```

#![warn(missing_docs)]

mod builders;
mod common;
pub mod device;
pub mod error;
mod fragments;
pub mod image;
pub mod methods;
mod readback;
mod receivers;
pub mod renderer;
pub mod scene;
mod view;
pub mod volumes;

pub use device::HeadlessGpu;
pub use error::WgpuError;
pub use image::{Image, LitMaskImage, RgbaImage, StencilImage, TriangleIdImage, WorldPosImage};
pub use methods::method_names;
pub use renderer::{
    CaptureFlags, FrameImages, FrameParams, LightCapture, LitMask, Renderer, StencilMask, COLOR_FORMAT, NO_TRIANGLE,
};
pub use scene::{SceneGpu, SceneId};
pub use umbra_geom::camera::Camera;
pub use volumes::{LightPlan, PassFormats, ShadowVolumes, View, VolumeFrame, ZMode};
/// wgpu, re-exported: use this one (wgpu 30) for the device, encoder and passes you hand umbra.
pub use wgpu;
