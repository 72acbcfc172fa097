//! The same verification for umbra-wgpu's methods: the samples come from the wgpu frame's own
//! depth pass (world position and triangle id per pixel, as rasterized by that backend), the
//! reference is computed for exactly those samples ([`crate::reference_from_samples`]), and
//! each method's per-light decision (its lit mask: the stencil said lit AND the seen side faces
//! the light) is compared with it by [`crate::compare_decisions`], under the one set of band
//! rules. The stencil after each volume pass is read back (a `StencilOnly` copy) and reported
//! as [`crate::MethodReport::stencil_metrics`]: on wgpu every method leaves "lit" as stencil 0
//! (shadow maps resolve into it).

use std::time::Instant;

use umbra_geom::camera::DepthConvention;
use umbra_gl::Classification;
use umbra_oracle::{BandParts, DepthFormat, RasterView};
use umbra_wgpu::{CaptureFlags, FrameParams, LightCapture, Renderer, SceneGpu, ShadowVolumes};

use crate::{
    compare_decisions, light_decisions, reference_from_samples, stencil_shadowed, MethodReport, VerifyError,
    ViewReference,
};

/// The view and the precision the wgpu renderer rasterizes `params` with, for the band
/// ([`umbra_oracle::envelope`]): its reversed-Z projection, the depth format
/// [`Renderer::depth_format_for`] picks, and the sub-pixel precision: 8 bits on lavapipe
/// (llvmpipe's rasterizer, whose `GL_SUBPIXEL_BITS` is 8), otherwise the least Vulkan allows
/// (`subPixelPrecisionBits` >= 4; wgpu does not report it).
pub fn raster_view(device: &wgpu::Device, params: &FrameParams) -> RasterView {
    let aspect = params.width as f64 / params.height.max(1) as f64;
    let clip_from_world = params.camera.clip_from_world_in(aspect, DepthConvention::ReversedZ).to_cols_array();
    let mut view = RasterView::new(clip_from_world);
    view.orthographic_forward = params.camera.is_orthographic().then(|| params.camera.forward());
    view.depth = if Renderer::depth_format_for(device) == wgpu::TextureFormat::Depth32FloatStencil8 {
        DepthFormat::Float32
    } else {
        DepthFormat::Fixed(24)
    };
    let adapter = device.adapter_info();
    if adapter.name.contains("llvmpipe") || adapter.driver.contains("llvmpipe") {
        view.subpixel_bits = 8;
    }
    view
}

fn wgpu_err(e: umbra_wgpu::WgpuError) -> VerifyError {
    VerifyError::Wgpu(e.to_string())
}

/// Renders the view's samples with `none` and computes the reference for every light.
pub fn view_reference(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    renderer: &mut Renderer,
    scene: &SceneGpu,
    params: &FrameParams,
) -> Result<ViewReference, VerifyError> {
    let p = FrameParams {
        capture: CaptureFlags { world_pos: true, triangle_id: true, ..CaptureFlags::default() },
        ..params.clone()
    };
    let mut none = renderer.volumes(device, "none").map_err(wgpu_err)?;
    let images = renderer.render(device, queue, scene, &mut none, &p).map_err(wgpu_err)?;
    let (Some(world), Some(ids)) = (images.world_pos, images.triangle_id) else {
        return Err(VerifyError::Wgpu("the renderer returned no world-position / triangle-id images".into()));
    };
    reference_from_samples(scene.mesh(), &params.camera, raster_view(device, params), &params.lights, &world, &ids)
}

/// Renders `volumes`' method once with every light of `params`, reads its per-sample decision
/// for each light and compares it with `view` (from [`view_reference`] for the same params).
pub fn verify_method(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    renderer: &mut Renderer,
    scene: &SceneGpu,
    volumes: &mut ShadowVolumes,
    params: &FrameParams,
    view: &ViewReference,
) -> Result<MethodReport, VerifyError> {
    let mut p = params.clone();
    p.capture.lit_mask = LightCapture::AllLights;
    p.capture.stencil = LightCapture::AllLights;
    let start = Instant::now();
    let images = renderer.render(device, queue, scene, volumes, &p).map_err(wgpu_err)?;
    let render_ms = crate::ms(start);
    // Every wgpu method leaves "lit" as stencil 0 (shadow maps resolve into it).
    let decisions = light_decisions(
        view,
        |light| images.lit_masks.iter().find(|m| m.light == light).map(|m| &m.image),
        |light| {
            let stencil = images.stencil.iter().find(|s| s.light == light)?;
            stencil_shadowed(Classification::StencilZero, &stencil.image.pixels)
        },
    )
    .map_err(VerifyError::Wgpu)?;
    // Every wgpu volume method is a silhouette method (no faces on edges that cast nothing);
    // ray-bvh depth-tests nothing (crate::RAY_BVH_BAND, as on GL).
    let band = if volumes.method_name() == umbra_wgpu::methods::ray_bvh::NAME {
        crate::RAY_BVH_BAND
    } else {
        BandParts::SILHOUETTE
    };
    compare_decisions(volumes.method_name().to_string(), band, view, &decisions, images.rgba, render_ms)
}
