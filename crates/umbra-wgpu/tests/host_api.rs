//! The host API as a renderer of its own uses it (examples/host/mod.rs: the host's own
//! depth-stencil texture, shaders and passes; umbra's `ShadowVolumes::draw` inside the host's
//! render pass):
//! * with the same depth format, the stencil umbra counts in the host's attachment equals,
//!   value for value, the one umbra's own frame counts (`Renderer::render`), for every method
//!   (shadow maps: their resolve) and both light kinds;
//! * multisampled (4 samples) with `Depth24PlusStencil8`, the host's frame has no wgpu error
//!   and the shadow is where the light says.
//!
//! The host's image is written to target/test-output/host-api/ for inspection.

mod common;
#[path = "../examples/host/mod.rs"]
mod host;

use std::path::PathBuf;

use common::*;
use umbra_wgpu::wgpu;
use umbra_wgpu::{FrameParams, HeadlessGpu, LightCapture, Renderer, SceneGpu, View};

const W: u32 = 200;
const H: u32 = 150;

fn output_dir() -> PathBuf {
    std::env::var_os("UMBRA_TEST_OUTPUT")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../target/test-output"))
        .join("host-api")
}

/// Copies `aspect` of a single-sampled texture into a buffer and reads it (bytes per texel).
fn read(gpu: &HeadlessGpu, texture: &wgpu::Texture, aspect: wgpu::TextureAspect, texel: u32) -> Vec<u8> {
    let (w, h) = (texture.width(), texture.height());
    let row = (w * texel).next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT);
    let buffer = gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size: u64::from(row * h),
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    encoder.copy_texture_to_buffer(
        wgpu::TexelCopyTextureInfo { texture, mip_level: 0, origin: wgpu::Origin3d::ZERO, aspect },
        wgpu::TexelCopyBufferInfo {
            buffer: &buffer,
            layout: wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(row), rows_per_image: Some(h) },
        },
        wgpu::Extent3d { width: w, height: h, depth_or_array_layers: 1 },
    );
    gpu.queue.submit([encoder.finish()]);
    buffer.slice(..).map_async(wgpu::MapMode::Read, |r| r.expect("map"));
    gpu.device.poll(wgpu::PollType::wait_indefinitely()).expect("poll");
    let data = buffer.slice(..).get_mapped_range().expect("mapped");
    (0..h as usize).flat_map(|r| data[r * row as usize..][..(w * texel) as usize].to_vec()).collect()
}

fn color_target(gpu: &HeadlessGpu) -> wgpu::Texture {
    gpu.device.create_texture(&wgpu::TextureDescriptor {
        label: Some("host colour"),
        size: wgpu::Extent3d { width: W, height: H, depth_or_array_layers: 1 },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Rgba8Unorm,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    })
}

/// One host frame; returns the host's colour (RGBA8) and, single-sampled, its stencil.
fn host_frame(
    gpu: &HeadlessGpu,
    scene: &SceneGpu,
    lights: &[[f32; 4]],
    method: &str,
    depth: wgpu::TextureFormat,
    samples: u32,
) -> (Vec<u8>, Option<Vec<u8>>) {
    let mut host = host::HostRenderer::new(&gpu.device, wgpu::TextureFormat::Rgba8Unorm, depth, samples, method)
        .unwrap_or_else(|e| panic!("{method}: {e}"));
    let target = color_target(gpu);
    let view = View::from_camera(&default_camera(), W, H).expect("view");
    let scope = gpu.device.push_error_scope(wgpu::ErrorFilter::Validation);
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    host.frame(
        &gpu.device,
        &gpu.queue,
        &mut encoder,
        scene,
        &view,
        lights,
        &target.create_view(&Default::default()),
        (W, H),
    )
    .unwrap_or_else(|e| panic!("{method}: {e}"));
    gpu.queue.submit([encoder.finish()]);
    let error = pollster::block_on(scope.pop());
    assert!(error.is_none(), "{method}: {error:?}");
    let color = read(gpu, &target, wgpu::TextureAspect::All, 4);
    let stencil = (samples == 1).then(|| {
        let depth = host.depth_texture(&gpu.device, W, H).clone();
        read(gpu, &depth, wgpu::TextureAspect::StencilOnly, 1)
    });
    (color, stencil)
}

#[test]
fn host_stencil_equals_umbras_own_frame() {
    let Some(gpu) = gpu() else { return };
    let mesh = sphere_over_ground();
    let scene = SceneGpu::upload(&gpu.device, mesh.clone()).expect("upload");
    let mut renderer = Renderer::new(&gpu.device).expect("renderer");
    for lights in [vec![POINT_LIGHT], vec![[0.4, 1.0, 0.3, 0.0]]] {
        for &method in umbra_wgpu::method_names() {
            let (color, stencil) =
                host_frame(&gpu, &scene, &lights, method, wgpu::TextureFormat::Depth32FloatStencil8, 1);
            let mut volumes = renderer.volumes(&gpu.device, method).expect("method");
            let p = FrameParams {
                capture: umbra_wgpu::CaptureFlags { stencil: LightCapture::AllLights, ..Default::default() },
                ..params(default_camera(), lights.clone(), W, H)
            };
            let own = renderer.render(&gpu.device, &gpu.queue, &scene, &mut volumes, &p).expect("render");
            let (host, own) = (stencil.expect("single-sampled"), &own.stencil[0].image.pixels);
            let differing = host.iter().zip(own).filter(|(a, b)| a != b).count();
            assert_eq!(differing, 0, "{method} {lights:?}: the host's stencil differs from umbra's own frame's");
            if method != "none" {
                assert!(host.iter().any(|&v| v != 0), "{method}: a shadow is counted");
            }
            let dir = output_dir();
            let _ = std::fs::create_dir_all(&dir);
            let png = umbra_wgpu::RgbaImage { width: W, height: H, pixels: bytemuck::pod_collect_to_vec(&color) };
            let kind = if lights[0][3] == 0.0 { "directional" } else { "point" };
            png.save_png(&dir.join(format!("{}-{kind}.png", method.replace(':', "_")))).expect("png");
        }
    }
}

#[test]
fn multisampled_host_with_depth24_shadows_where_the_light_says() {
    let Some(gpu) = gpu() else { return };
    let scene = SceneGpu::upload(&gpu.device, sphere_over_ground()).expect("upload");
    let (color, stencil) =
        host_frame(&gpu, &scene, &[POINT_LIGHT], "cs-silhouette", wgpu::TextureFormat::Depth24PlusStencil8, 4);
    assert!(stencil.is_none());
    // The ground right under the sphere (the point light is straight above it) is shadowed;
    // a ground point 3 units away is lit.
    let camera = default_camera();
    let pixel = |p: [f64; 3]| {
        let q = camera.project(p, W, H).expect("in view");
        let i = 4 * (q[1] as usize * W as usize + q[0] as usize);
        color[i] as u32 + color[i + 1] as u32 + color[i + 2] as u32
    };
    let (under, away) = (pixel([0.0, 0.0, 0.0]), pixel([0.0, 0.0, 3.0]));
    assert!(away > under + 100, "lit ground {away} vs shadowed ground {under}");
}

/// A receiver cull asked against a depth the scatter cannot read as a texture is refused with
/// the reason (the usage it lacks), not drawn unculled in silence.
#[test]
fn culling_against_a_depth_without_texture_binding_is_refused() {
    let Some(gpu) = gpu() else { return };
    let scene = SceneGpu::upload(&gpu.device, sphere_over_ground()).expect("upload");
    let renderer = Renderer::new(&gpu.device).expect("renderer");
    let mut volumes = renderer.volumes(&gpu.device, "cpu-silhouette").expect("method");
    assert!(volumes.culls_volumes());
    let depth = gpu.device.create_texture(&wgpu::TextureDescriptor {
        label: Some("host depth, attachment only"),
        size: wgpu::Extent3d { width: W, height: H, depth_or_array_layers: 1 },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: Renderer::depth_format_for(&gpu.device),
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
        view_formats: &[],
    });
    let view = View::from_camera(&default_camera(), W, H).expect("view");
    let lights = [[0.0, 5.0, 0.0, 1.0]];
    let frame =
        umbra_wgpu::VolumeFrame { view: &view, lights: &lights, zmode: Default::default(), receivers: Some(&depth) };
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    let err = volumes.prepare(&gpu.device, &gpu.queue, &mut encoder, &scene, &frame).expect_err("refused");
    assert!(err.to_string().contains("TEXTURE_BINDING"), "{err}");
}
