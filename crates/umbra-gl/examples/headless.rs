//! The smallest umbra program: a sphere over a ground plane, one point light, one PNG.
//! Stencil shadow volumes with the deterministic multiplicity silhouette (paper 001), drawn
//! headlessly through EGL by [`umbra_gl::Renderer::render`].
//!
//! `cargo run --release -p umbra-gl --example headless -- [OUT.png]` (default `headless.png`)

use std::path::Path;
use std::sync::Arc;

use umbra_geom::scene::{ground_plane, uv_sphere};
use umbra_gl::{create_method, Camera, FrameParams, HeadlessContext, Renderer, SceneGpu};

/// Renders the frame into `out` and returns its parameters (camera, size, light).
pub fn render_png(out: &Path) -> Result<FrameParams, Box<dyn std::error::Error>> {
    // A GL 4.5 core context without a window (Mesa llvmpipe when there is no GPU).
    let ctx = HeadlessContext::new()?;
    let gl = ctx.gl();

    // Any triangle soup: positions + triangles, welded once, uploaded once.
    let mut mesh = uv_sphere([0.0, 2.0, 0.0], 1.0, 48, 24);
    mesh.append(&ground_plane([0.0, 0.0, 0.0], 6.0));
    let scene = SceneGpu::upload(gl, Arc::new(umbra_geom::weld::weld(&mesh)))?;

    let mut renderer = Renderer::new(gl)?;
    let mut method = create_method("cpu-silhouette")?;
    let params = FrameParams {
        camera: Camera::look_at([5.0, 5.0, 7.0], [0.0, 0.5, 0.0]),
        width: 480,
        height: 320,
        // w = 1: a point light at (1, 6, 0.5); w = 0 would be a directional light.
        lights: vec![[1.0, 6.0, 0.5, 1.0]],
        ..FrameParams::default()
    };
    let frame = renderer.render(gl, &scene, method.as_mut(), &params, None)?;
    frame.rgba.save_png(out)?;

    method.destroy(gl);
    renderer.destroy(gl);
    scene.destroy(gl);
    Ok(params)
}

#[allow(dead_code)] // also compiled into tests/examples.rs, which calls render_png
fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out = std::env::args().nth(1).unwrap_or_else(|| "headless.png".to_string());
    render_png(Path::new(&out))?;
    println!("wrote {out}");
    Ok(())
}
