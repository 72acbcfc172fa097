//! The stand-alone frame, for callers without a pass of their own (the CLI, the tests, the
//! headless example): the multi-pass stencil shadow-volume frame of Heidmann 1991 and
//! Everitt & Kilgard 2002 §2, the twin of umbra-gl's `Renderer::render`:
//!
//! 1. once per frame: [`ShadowVolumes::prepare`] (every light's compute work), then clear and
//!    depth + ambient (+ world position and triangle id when captured), normal clipping;
//! 2. per light: a pass with the stencil cleared to the light's [`crate::LightPlan`] value in
//!    which the method counts its volumes against that depth ([`ShadowVolumes::draw`]); the
//!    stencil optionally copied out (sample count 1, `TextureAspect::StencilOnly`);
//! 3. per light: diffuse + specular where the stencil is 0 AND the seen side of the triangle
//!    faces the light, depth EQUAL, no depth writes, additive blending; the same shader writes
//!    that decision into the lit mask, read back when asked.
//!
//! Reversed-Z with an infinite far plane (umbra-gl's default convention), in a
//! `Depth32FloatStencil8` target when the device offers it (`Depth24PlusStencil8` otherwise).
//! Everything of one frame is one command buffer, one submission.
//!
//! Files: `renderer/validate.rs` (the checks of [`FrameParams`] before any GPU work),
//! `renderer/pipelines.rs` (the scene pipelines), `renderer/target.rs` (the frame's own
//! textures), `renderer/encode.rs` (recording and submitting one frame).

mod encode;
mod pipelines;
mod target;
mod validate;

use crate::builders::uniform_slots;
use crate::error::{scoped, WgpuError};
use crate::image::Image;
use crate::readback::Readback;
use crate::scene::SceneGpu;
use crate::view::View;
use crate::volumes::{PassFormats, ShadowVolumes};

use encode::FrameUniform;
use pipelines::ScenePipelines;
use target::Target;
use validate::validate;

pub use umbra_geom::frame::FrameParams;
pub use umbra_geom::frame_images::{CaptureFlags, FrameImages, LightCapture, LitMask, StencilMask};
/// The triangle id of a background sample (umbra-geom's, as umbra-gl's).
pub use umbra_geom::image::NO_TRIANGLE;

/// Colour format of the frame.
pub const COLOR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;

/// The stand-alone renderer: scene pipelines and (for [`Renderer::render`]) its own target.
/// Make the methods it draws with [`Renderer::volumes`].
pub struct Renderer {
    depth_format: wgpu::TextureFormat,
    pipelines: ScenePipelines,
    frame_uniform: wgpu::Buffer,
    lights_uniform: Option<(wgpu::Buffer, wgpu::BindGroup, usize)>,
    target: Option<Target>,
    /// Count the fragments of every volume pass ([`Renderer::set_count_volume_fragments`]).
    count_volume_fragments: bool,
    /// Per light of the last counted frame.
    last_volume_fragments: Vec<Option<u64>>,
}

impl Renderer {
    /// The depth-stencil format the device allows: `Depth32FloatStencil8` (reversed-Z keeps its
    /// precision) when offered, else `Depth24PlusStencil8`.
    pub fn depth_format_for(device: &wgpu::Device) -> wgpu::TextureFormat {
        if device.features().contains(wgpu::Features::DEPTH32FLOAT_STENCIL8) {
            wgpu::TextureFormat::Depth32FloatStencil8
        } else {
            wgpu::TextureFormat::Depth24PlusStencil8
        }
    }

    /// The formats of the renderer's volume passes (depth-stencil only).
    pub fn volume_formats(&self) -> PassFormats {
        PassFormats { color: Vec::new(), depth_stencil: self.depth_format }
    }

    /// `method`'s volumes for this renderer's passes.
    pub fn volumes(&self, device: &wgpu::Device, method: &str) -> Result<ShadowVolumes, WgpuError> {
        ShadowVolumes::new(device, &self.volume_formats(), 1, method)
    }

    /// A shadow map with explicit options (bias, PCF) for this renderer's passes.
    pub fn shadow_map(
        &self,
        device: &wgpu::Device,
        config: crate::methods::shadow_map::ShadowMapConfig,
    ) -> Result<ShadowVolumes, WgpuError> {
        ShadowVolumes::shadow_map(device, &self.volume_formats(), 1, config)
    }

    /// Compiles the scene pipelines. The device needs [`crate::device::frame_features`].
    pub fn new(device: &wgpu::Device) -> Result<Self, WgpuError> {
        crate::device::check_features(
            "the device",
            device.features(),
            crate::device::frame_features(),
            "umbra's own frames (triangle ids, depth clamp, clip distances)",
        )?;
        scoped(device, "Renderer::new", || Ok(Self::build(device)))
    }

    fn build(device: &wgpu::Device) -> Self {
        let depth_format = Self::depth_format_for(device);
        let pipelines = ScenePipelines::new(device, depth_format);
        let frame_uniform = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("umbra frame uniform"),
            size: std::mem::size_of::<FrameUniform>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        Self {
            depth_format,
            pipelines,
            frame_uniform,
            lights_uniform: None,
            target: None,
            count_volume_fragments: false,
            last_volume_fragments: Vec::new(),
        }
    }

    /// The per-light lighting uniforms (one 256-byte slot per light), grown as needed.
    fn lights_uniform(&mut self, device: &wgpu::Device, lights: usize) -> (wgpu::Buffer, wgpu::BindGroup) {
        let needed = lights.max(1);
        if self.lights_uniform.as_ref().is_none_or(|(_, _, n)| *n < needed) {
            // One vec4 per light (`Light` of shaders/scene.wgsl).
            let (buffer, group) =
                uniform_slots(device, "umbra lighting lights", &self.pipelines.light_layout, needed, 16);
            self.lights_uniform = Some((buffer, group, needed));
        }
        let (b, g, _) = self.lights_uniform.as_ref().expect("made above");
        (b.clone(), g.clone())
    }

    /// Renders one frame into the renderer's own target (recreated when the size changes)
    /// with `volumes` (made by [`Renderer::volumes`]) and reads back colour and whatever
    /// `params.capture` asks for.
    pub fn render(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        scene: &SceneGpu,
        volumes: &mut ShadowVolumes,
        params: &FrameParams,
    ) -> Result<FrameImages, WgpuError> {
        validate(params)?;
        let view = View::from_camera(&params.camera, params.width, params.height)?;
        let pending =
            scoped(device, "frame", || self.encode(device, queue, scene, volumes, params, &view, true, None))?;
        self.read_fragments(device, &pending, volumes, params.lights.len())?;
        let read = |r: &Option<Readback>| -> Result<Option<Vec<u8>>, WgpuError> {
            r.as_ref().map(|r| r.read::<u8>(device)).transpose()
        };
        let (w, h) = (params.width, params.height);
        let color =
            pending.color.as_ref().ok_or(WgpuError::Readback { what: "colour", detail: "not recorded".into() })?;
        let rgba: Vec<[u8; 4]> = bytemuck::pod_collect_to_vec(&color.read::<u8>(device)?);
        let world_pos =
            read(&pending.world_pos)?.map(|b| Image { width: w, height: h, pixels: bytemuck::pod_collect_to_vec(&b) });
        let triangle_id = read(&pending.triangle_id)?.map(|b| Image {
            width: w,
            height: h,
            pixels: bytemuck::pod_collect_to_vec(&b),
        });
        let mut stencil = Vec::new();
        for (light, r) in &pending.stencil {
            stencil.push(StencilMask { light: *light, image: Image { width: w, height: h, pixels: r.read(device)? } });
        }
        let mut lit_masks = Vec::new();
        for (light, r) in &pending.lit_masks {
            // The R8Unorm attachment holds 255 where lit: 1 and 0 as umbra-gl's lit masks.
            let pixels = r.read::<u8>(device)?.into_iter().map(|v| u8::from(v != 0)).collect();
            lit_masks.push(LitMask { light: *light, image: Image { width: w, height: h, pixels } });
        }
        Ok(FrameImages {
            rgba: Image { width: w, height: h, pixels: rgba },
            world_pos,
            triangle_id,
            stencil,
            lit_masks,
        })
    }

    /// Draws one frame into the renderer's own target and submits it, reading nothing back
    /// (benchmarks: wait for it with `device.poll`). `params.capture` is ignored.
    pub fn draw_frame(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        scene: &SceneGpu,
        volumes: &mut ShadowVolumes,
        params: &FrameParams,
    ) -> Result<(), WgpuError> {
        let params = FrameParams { capture: CaptureFlags::default(), ..params.clone() };
        validate(&params)?;
        let view = View::from_camera(&params.camera, params.width, params.height)?;
        let pending =
            scoped(device, "frame", || self.encode(device, queue, scene, volumes, &params, &view, false, None))?;
        self.read_fragments(device, &pending, volumes, params.lights.len())?;
        Ok(())
    }

    /// [`Renderer::draw_frame`] with a GPU timestamp at every stage boundary, waited for:
    /// (stage, ms) summed over lights, in first-seen order — "prepare" (every light's compute
    /// work and shadow-map passes), "depth+ambient", "volumes", "lighting"; with volumes culled
    /// against the receivers, "depth+ambient", "receivers" (every light's receiver map, its
    /// read-back and the CPU's cull and extraction, the GPU idle meanwhile), "prepare". `None` when the
    /// device has no timestamp queries inside encoders.
    pub fn draw_frame_timed(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        scene: &SceneGpu,
        volumes: &mut ShadowVolumes,
        params: &FrameParams,
    ) -> Result<Option<Vec<(String, f64)>>, WgpuError> {
        let needed = wgpu::Features::TIMESTAMP_QUERY | wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS;
        if !device.features().contains(needed) {
            return Ok(None);
        }
        let params = FrameParams { capture: CaptureFlags::default(), ..params.clone() };
        validate(&params)?;
        let view = View::from_camera(&params.camera, params.width, params.height)?;
        // prepare or receivers + prepare, depth+ambient, per light volumes and lighting, end.
        let stamps = 4 + 2 * params.lights.len() as u32;
        let set = device.create_query_set(&wgpu::QuerySetDescriptor {
            label: Some("umbra stage timestamps"),
            ty: wgpu::QueryType::Timestamp,
            count: stamps,
        });
        let pending =
            scoped(device, "frame", || self.encode(device, queue, scene, volumes, &params, &view, false, Some(&set)))?;
        self.read_fragments(device, &pending, volumes, params.lights.len())?;
        let Some((labels, readback)) = pending.stamps else { return Ok(None) };
        let ticks: Vec<u64> = crate::readback::read_buffer(device, &readback, "timestamps")?;
        let period = f64::from(queue.get_timestamp_period());
        let mut stages: Vec<(String, f64)> = Vec::new();
        for (i, label) in labels.iter().enumerate().take(labels.len().saturating_sub(1)) {
            let ms = ticks[i + 1].saturating_sub(ticks[i]) as f64 * period / 1e6;
            match stages.iter_mut().find(|(n, _)| n == label) {
                Some((_, t)) => *t += ms,
                None => stages.push((label.to_string(), ms)),
            }
        }
        Ok(Some(stages))
    }
}

impl Renderer {
    /// Count the fragments every volume pass rasterizes from the next frame on, where the
    /// device has `PIPELINE_STATISTICS_QUERY` (`FRAGMENT_SHADER_INVOCATIONS`; the volume
    /// shaders write their depth, so every rasterized fragment runs them), the receiver map's
    /// scatter of a culled volume included. A counted frame waits for its counts.
    pub fn set_count_volume_fragments(&mut self, on: bool) {
        self.count_volume_fragments = on;
        self.last_volume_fragments.clear();
    }

    /// Per light of the last counted frame: its volume pass's fragments plus its receiver
    /// scatter's ([`Renderer::set_count_volume_fragments`]); `None` where the device cannot
    /// count, or for a method that draws no volumes (shadow maps, ray-bvh).
    pub fn last_volume_fragments(&self) -> &[Option<u64>] {
        &self.last_volume_fragments
    }

    /// Reads the last frame's fragment counts (a wait) when counting.
    fn read_fragments(
        &mut self,
        device: &wgpu::Device,
        pending: &encode::Pending,
        volumes: &ShadowVolumes,
        lights: usize,
    ) -> Result<(), WgpuError> {
        self.last_volume_fragments.clear();
        if !self.count_volume_fragments {
            return Ok(());
        }
        let counts = pending.fragments.as_ref().map(|q| q.read(device)).transpose()?;
        self.last_volume_fragments
            .extend((0..lights).map(|i| counts.as_ref().map(|c| c[i] + volumes.own_fragments(i).unwrap_or(0))));
        Ok(())
    }
}
