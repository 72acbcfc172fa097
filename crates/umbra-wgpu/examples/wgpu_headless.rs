//! The smallest umbra-wgpu program: a sphere over a ground plane, a point light and a
//! directional one, one PNG. Stencil shadow volumes with the compute-shader silhouette
//! (`cs-silhouette`: paper 001's deterministic multiplicity), drawn headlessly on wgpu (Vulkan
//! through Mesa's lavapipe when there is no GPU) by [`umbra_wgpu::Renderer::render`].
//!
//! `cargo run --release -p umbra-wgpu --example wgpu_headless -- [OUT.png] [METHOD]` (default
//! `headless-wgpu.png`, `cs-silhouette`)

use std::path::Path;
use std::sync::Arc;

use umbra_geom::scene::{ground_plane, uv_sphere};
use umbra_wgpu::{Camera, FrameParams, HeadlessGpu, Renderer, SceneGpu};

/// Renders the frame into `out` with `method` and returns its parameters.
pub fn render_png(out: &Path, method: &str) -> Result<FrameParams, Box<dyn std::error::Error>> {
    // A device without a window; a missing Vulkan/Metal/DX12 adapter is an error that says
    // what to install.
    let gpu = HeadlessGpu::new()?;

    // Any triangle soup: positions + triangles, welded once, uploaded once.
    let mut mesh = uv_sphere([0.0, 2.0, 0.0], 1.0, 48, 24);
    mesh.append(&ground_plane([0.0, 0.0, 0.0], 6.0));
    let scene = SceneGpu::upload(&gpu.device, Arc::new(umbra_geom::weld::weld(&mesh)))?;

    let mut renderer = Renderer::new(&gpu.device)?;
    let mut volumes = renderer.volumes(&gpu.device, method)?;
    let params = FrameParams {
        camera: Camera::look_at([5.0, 5.0, 7.0], [0.0, 0.5, 0.0]),
        width: 480,
        height: 320,
        // w = 1: a point light at (1, 6, 0.5); w = 0: a directional light from (-1, 2, 1).
        lights: vec![[1.0, 6.0, 0.5, 1.0], [-1.0, 2.0, 1.0, 0.0]],
        light_color: [0.6; 3],
        ..FrameParams::default()
    };
    let frame = renderer.render(&gpu.device, &gpu.queue, &scene, &mut volumes, &params)?;
    frame.rgba.save_png(out)?;
    Ok(params)
}

#[allow(dead_code)] // also compiled into tests/examples.rs, which calls render_png
fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out = std::env::args().nth(1).unwrap_or_else(|| "headless-wgpu.png".to_string());
    let method = std::env::args().nth(2).unwrap_or_else(|| "cs-silhouette".to_string());
    render_png(Path::new(&out), &method)?;
    println!("wrote {out}");
    Ok(())
}
