//! Shared helpers of umbra-wgpu's integration tests: the device (skipped with a message when no
//! Vulkan/Metal/DX12 adapter exists; CI installs lavapipe), scenes, one-frame renders.

#![allow(dead_code)]

use std::sync::Arc;

use umbra_geom::scene::{ground_plane, uv_sphere};
use umbra_geom::{weld::weld, Mesh, WeldedMesh};
use umbra_wgpu::{
    Camera, CaptureFlags, FrameImages, FrameParams, HeadlessGpu, LightCapture, Renderer, SceneGpu, WgpuError,
};

pub const POINT_LIGHT: [f32; 4] = [0.0, 6.0, 0.0, 1.0];

/// The device, or `None` (with a SKIPPED message) when there is no adapter at all. Any other
/// failure (missing features, device creation) fails the test.
pub fn gpu() -> Option<HeadlessGpu> {
    match HeadlessGpu::new() {
        Ok(g) => Some(g),
        Err(e @ WgpuError::NoAdapter { .. }) => {
            eprintln!("SKIPPED: {e}");
            None
        }
        Err(e) => panic!("wgpu device: {e}"),
    }
}

/// UV sphere (radius 1 at (0, 2, 0), 48 x 24) above a 20 x 20 ground plane at y = 0.
pub fn sphere_over_ground() -> Arc<WeldedMesh> {
    let mut mesh: Mesh = uv_sphere([0.0, 2.0, 0.0], 1.0, 48, 24);
    mesh.append(&ground_plane([0.0, 0.0, 0.0], 10.0));
    Arc::new(weld(&mesh))
}

pub fn default_camera() -> Camera {
    Camera { near: 0.01, ..Camera::look_at([4.0, 5.0, 6.0], [0.0, 0.5, 0.0]) }
}

/// Frame parameters capturing everything (samples, stencil and lit mask of every light), with
/// the volumes unculled: the tests compare every pixel's stencil between frames, and a cull
/// against the receivers keeps the visible samples' counts only (its exactness is judged by
/// umbra-verify's `wgpu_volume_cull.rs` and torture suite).
pub fn params(camera: Camera, lights: Vec<[f32; 4]>, width: u32, height: u32) -> FrameParams {
    FrameParams {
        camera,
        width,
        height,
        lights,
        volume_cull: false,
        capture: CaptureFlags {
            world_pos: true,
            triangle_id: true,
            stencil: LightCapture::AllLights,
            lit_mask: LightCapture::AllLights,
        },
        ..FrameParams::default()
    }
}

/// Renders one frame with `method` on a fresh renderer.
pub fn render_once(gpu: &HeadlessGpu, mesh: &Arc<WeldedMesh>, method: &str, p: &FrameParams) -> FrameImages {
    let scene = SceneGpu::upload(&gpu.device, mesh.clone()).expect("upload");
    let mut renderer = Renderer::new(&gpu.device).expect("renderer");
    let mut volumes = renderer.volumes(&gpu.device, method).expect("method");
    renderer.render(&gpu.device, &gpu.queue, &scene, &mut volumes, p).unwrap_or_else(|e| panic!("{method}: {e}"))
}
