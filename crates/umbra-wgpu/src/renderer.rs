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

use umbra_geom::camera::Camera;
use umbra_geom::Light;

use crate::error::{scoped, WgpuError};
use crate::image::{Image, LitMaskImage, RgbaImage, StencilImage, TriangleIdImage, WorldPosImage};
use crate::readback::Readback;
use crate::scene::SceneGpu;
use crate::volumes::{
    storage_entry, uniform_entry, uniform_slots, PassFormats, ShadowVolumes, View, VolumeFrame, ZMode, LIGHT_SLOT_BYTES,
};

/// The triangle id of a background sample (umbra-geom's, as umbra-gl's).
pub use umbra_geom::image::NO_TRIANGLE;

const SCENE: &str = include_str!("shaders/scene.wgsl");

/// Colour format of the frame.
pub const COLOR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;

/// For which lights a per-light image is read back.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LightCapture {
    /// No light.
    #[default]
    None,
    /// Only the light with this index in [`FrameParams::lights`].
    Light(usize),
    /// Every light.
    AllLights,
}

impl LightCapture {
    /// Whether light `light` is captured.
    pub fn includes(self, light: usize) -> bool {
        match self {
            LightCapture::None => false,
            LightCapture::Light(i) => i == light,
            LightCapture::AllLights => true,
        }
    }
}

/// Extra images [`Renderer::render`] reads back.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CaptureFlags {
    /// World position per pixel ([`FrameImages::world_pos`]).
    pub world_pos: bool,
    /// Triangle id per pixel ([`FrameImages::triangle_id`]).
    pub triangle_id: bool,
    /// The stencil after these lights' volume passes ([`FrameImages::stencil`]).
    pub stencil: LightCapture,
    /// The final per-pixel decision "lit by this light" ([`FrameImages::lit_masks`]).
    pub lit_mask: LightCapture,
}

/// Everything that defines one frame (umbra-gl's `FrameParams`, reversed-Z only, 8-bit
/// stencil counter only).
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
    /// z-pass for every light (wrong when the camera is inside a shadow volume).
    pub zpass: bool,
    /// z-pass where provably exact, z-fail elsewhere (default on); see [`ZMode`].
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
    /// Which extra images [`Renderer::render`] reads back.
    pub capture: CaptureFlags,
}

impl Default for FrameParams {
    /// umbra-gl's defaults: 1280x720, default camera, no lights, auto z-pass, light grey
    /// surfaces, ambient 0.15, white light, dark blue-grey background.
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
        }
    }
}

impl FrameParams {
    /// How the volumes count.
    pub fn zmode(&self) -> ZMode {
        ZMode { zpass: self.zpass, auto_zpass: self.auto_zpass }
    }

    /// Camera, size, lights, capture indices and shading, checked before any GPU work.
    pub fn validate(&self) -> Result<(), WgpuError> {
        self.camera.validate()?;
        if self.width == 0 || self.height == 0 {
            return Err(WgpuError::InvalidParams(format!("frame size {}x{}", self.width, self.height)));
        }
        for (i, l) in self.lights.iter().enumerate() {
            umbra_geom::check_light(i, l)?;
        }
        for (what, capture) in [("stencil", self.capture.stencil), ("lit mask", self.capture.lit_mask)] {
            if let LightCapture::Light(i) = capture {
                if i >= self.lights.len() {
                    return Err(WgpuError::InvalidParams(format!(
                        "{what} capture of light {i}, but {} light(s)",
                        self.lights.len()
                    )));
                }
            }
        }
        let scalars = [self.ambient, self.specular, self.shininess];
        if scalars.iter().chain(&self.albedo).chain(&self.light_color).chain(&self.background).any(|v| !v.is_finite()) {
            return Err(WgpuError::InvalidParams("non-finite colour or shading parameter".into()));
        }
        Ok(())
    }
}

/// Per-light stencil after the volume pass.
#[derive(Clone, Debug, PartialEq)]
pub struct StencilMask {
    /// Index of the light in [`FrameParams::lights`].
    pub light: usize,
    /// Its stencil, top row first.
    pub image: StencilImage,
}

/// Per-light lit mask after that light's lighting pass (1 lit, 0 not).
#[derive(Clone, Debug, PartialEq)]
pub struct LitMask {
    /// Index of the light in [`FrameParams::lights`].
    pub light: usize,
    /// Its lit mask, top row first.
    pub image: LitMaskImage,
}

/// What [`Renderer::render`] reads back; all images top row first.
#[derive(Clone, Debug, PartialEq)]
pub struct FrameImages {
    /// The final colour.
    pub rgba: RgbaImage,
    /// World position per pixel, when captured.
    pub world_pos: Option<WorldPosImage>,
    /// Triangle id per pixel ([`NO_TRIANGLE`] on background), when captured.
    pub triangle_id: Option<TriangleIdImage>,
    /// In light order, one per captured light.
    pub stencil: Vec<StencilMask>,
    /// In light order, one per captured light.
    pub lit_masks: Vec<LitMask>,
}

/// The frame uniform (`Frame` of shaders/scene.wgsl).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct FrameUniform {
    clip_from_world: [f32; 16],
    ambient: [f32; 4],
    eye: [f32; 4],
    albedo: [f32; 4],
    light_color: [f32; 4],
    specular: [f32; 4],
}

/// The frame's textures.
struct Target {
    width: u32,
    height: u32,
    color: wgpu::Texture,
    world_pos: wgpu::Texture,
    triangle_id: wgpu::Texture,
    lit_mask: wgpu::Texture,
    depth: wgpu::Texture,
}

impl Target {
    fn new(device: &wgpu::Device, width: u32, height: u32, depth_format: wgpu::TextureFormat) -> Self {
        let texture = |label, format| {
            device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size: wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
                mip_level_count: 1,
                // Reason: the stencil copy needs one sample per pixel (and the verifier one
                // sample per pixel: the rasterized sample it ray-traces).
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
                view_formats: &[],
            })
        };
        Self {
            width,
            height,
            color: texture("umbra colour", COLOR_FORMAT),
            world_pos: texture("umbra world position", wgpu::TextureFormat::Rgba32Float),
            triangle_id: texture("umbra triangle id", wgpu::TextureFormat::R32Uint),
            lit_mask: texture("umbra lit mask", wgpu::TextureFormat::R8Unorm),
            depth: texture("umbra depth-stencil", depth_format),
        }
    }
}

fn view_of(t: &wgpu::Texture) -> wgpu::TextureView {
    t.create_view(&wgpu::TextureViewDescriptor::default())
}

/// A render pass of the frame on `depth`, its depth and stencil loaded as said and stored.
fn begin_pass<'e>(
    encoder: &'e mut wgpu::CommandEncoder,
    label: &str,
    color_attachments: &[Option<wgpu::RenderPassColorAttachment<'_>>],
    depth: &wgpu::TextureView,
    depth_load: wgpu::LoadOp<f32>,
    stencil_load: wgpu::LoadOp<u32>,
) -> wgpu::RenderPass<'e> {
    encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some(label),
        color_attachments,
        depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
            view: depth,
            depth_ops: Some(wgpu::Operations { load: depth_load, store: wgpu::StoreOp::Store }),
            stencil_ops: Some(wgpu::Operations { load: stencil_load, store: wgpu::StoreOp::Store }),
        }),
        timestamp_writes: None,
        occlusion_query_set: None,
        multiview_mask: None,
    })
}

/// The stand-alone renderer: scene pipelines and (for [`Renderer::render`]) its own target.
/// Make the methods it draws with [`Renderer::volumes`].
pub struct Renderer {
    depth_format: wgpu::TextureFormat,
    frame_layout: wgpu::BindGroupLayout,
    light_layout: wgpu::BindGroupLayout,
    /// [without, with] the world-position and triangle-id attachments.
    depth_pipelines: [wgpu::RenderPipeline; 2],
    /// [without, with] the lit mask.
    lighting_pipelines: [wgpu::RenderPipeline; 2],
    frame_uniform: wgpu::Buffer,
    lights_uniform: Option<(wgpu::Buffer, wgpu::BindGroup, usize)>,
    target: Option<Target>,
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
        let vf = wgpu::ShaderStages::VERTEX | wgpu::ShaderStages::FRAGMENT;
        let frame_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("umbra frame"),
            entries: &[uniform_entry(0, vf, false), storage_entry(1, wgpu::ShaderStages::FRAGMENT, true)],
        });
        let light_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("umbra lighting light"),
            entries: &[uniform_entry(0, wgpu::ShaderStages::FRAGMENT, true)],
        });
        let module = crate::volumes::Common::module(device, "scene.wgsl", &["enable primitive_index;", SCENE]);
        let depth_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("umbra depth"),
            bind_group_layouts: &[Some(&frame_layout)],
            immediate_size: 0,
        });
        let lighting_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("umbra lighting"),
            bind_group_layouts: &[Some(&frame_layout), Some(&light_layout)],
            immediate_size: 0,
        });
        let vertex = wgpu::VertexState {
            module: &module,
            entry_point: Some("vs_scene"),
            compilation_options: Default::default(),
            buffers: &[Some(wgpu::VertexBufferLayout {
                array_stride: 12,
                step_mode: wgpu::VertexStepMode::Vertex,
                attributes: &[wgpu::VertexAttribute {
                    format: wgpu::VertexFormat::Float32x3,
                    offset: 0,
                    shader_location: 0,
                }],
            })],
        };
        let primitive = wgpu::PrimitiveState {
            topology: wgpu::PrimitiveTopology::TriangleList,
            strip_index_format: None,
            // Reason: the stored normal is that of the counter-clockwise winding.
            front_face: wgpu::FrontFace::Ccw,
            // Reason: triangle soups are two-sided; every triangle is visible from both sides.
            cull_mode: None,
            // Reason: the scene uses normal near clipping; only volumes need clamping.
            unclipped_depth: false,
            polygon_mode: wgpu::PolygonMode::Fill,
            conservative: false,
        };
        // The depth and lighting pipelines differ in their depth-stencil state, fragment entry
        // and colour targets only.
        let pipeline = |label, layout, depth_stencil, entry, targets: &[Option<wgpu::ColorTargetState>]| {
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(label),
                layout: Some(layout),
                vertex: vertex.clone(),
                primitive,
                depth_stencil: Some(depth_stencil),
                multisample: wgpu::MultisampleState::default(),
                fragment: Some(wgpu::FragmentState {
                    module: &module,
                    entry_point: Some(entry),
                    compilation_options: Default::default(),
                    targets,
                }),
                multiview_mask: None,
                cache: None,
            })
        };
        let depth_pipelines = [false, true].map(|capture| {
            let mut targets = vec![Some(wgpu::ColorTargetState {
                format: COLOR_FORMAT,
                // Reason: opaque ambient base colour.
                blend: None,
                write_mask: wgpu::ColorWrites::ALL,
            })];
            if capture {
                for format in [wgpu::TextureFormat::Rgba32Float, wgpu::TextureFormat::R32Uint] {
                    targets.push(Some(wgpu::ColorTargetState {
                        format,
                        blend: None,
                        write_mask: wgpu::ColorWrites::ALL,
                    }));
                }
            }
            pipeline(
                if capture { "umbra depth+ambient+captures" } else { "umbra depth+ambient" },
                &depth_layout,
                wgpu::DepthStencilState {
                    format: depth_format,
                    depth_write_enabled: Some(true),
                    // Reason: nearest surface wins (reversed-Z: GREATER); ties keep the first
                    // triangle drawn (strict), the one the lighting pass's EQUAL selects.
                    depth_compare: Some(wgpu::CompareFunction::Greater),
                    // Reason: the stencil belongs to the per-light volume passes.
                    stencil: wgpu::StencilState::default(),
                    // Reason: depths must match the lighting pass and the volumes exactly.
                    bias: wgpu::DepthBiasState::default(),
                },
                if capture { "fs_depth" } else { "fs_depth_color" },
                &targets,
            )
        });
        let one_per_pixel = wgpu::StencilFaceState {
            // Reason: lit where the count is 0.
            compare: wgpu::CompareFunction::Equal,
            fail_op: wgpu::StencilOperation::Keep,
            depth_fail_op: wgpu::StencilOperation::Keep,
            // Reason: the first fragment shaded at a pixel bumps the stencil to 1, so a
            // coplanar duplicate triangle (common in soups) cannot add this light twice.
            pass_op: wgpu::StencilOperation::IncrementWrap,
        };
        let additive = wgpu::BlendComponent {
            src_factor: wgpu::BlendFactor::One,
            dst_factor: wgpu::BlendFactor::One,
            operation: wgpu::BlendOperation::Add,
        };
        let lighting_pipelines = [false, true].map(|lit_mask| {
            let mut targets = vec![Some(wgpu::ColorTargetState {
                format: COLOR_FORMAT,
                // Reason: each light adds its diffuse + specular onto ambient + earlier lights.
                blend: Some(wgpu::BlendState { color: additive, alpha: additive }),
                // Reason: alpha keeps pass 1's coverage value 1.
                write_mask: wgpu::ColorWrites::COLOR,
            })];
            if lit_mask {
                targets.push(Some(wgpu::ColorTargetState {
                    format: wgpu::TextureFormat::R8Unorm,
                    // Reason: min(1, dst + src) with src in {0, 1}: an OR, so a second fragment
                    // of a pixel cannot clear the bit.
                    blend: Some(wgpu::BlendState { color: additive, alpha: additive }),
                    write_mask: wgpu::ColorWrites::RED,
                }));
            }
            pipeline(
                if lit_mask { "umbra lighting+lit mask" } else { "umbra lighting" },
                &lighting_layout,
                wgpu::DepthStencilState {
                    format: depth_format,
                    // Reason: depth is final after pass 1.
                    depth_write_enabled: Some(false),
                    // Reason: shade exactly the surface pass 1 left visible (the same invariant
                    // vertex shader gives bit-identical depths).
                    depth_compare: Some(wgpu::CompareFunction::Equal),
                    stencil: wgpu::StencilState {
                        front: one_per_pixel,
                        back: one_per_pixel,
                        read_mask: 0xFF,
                        write_mask: 0xFF,
                    },
                    bias: wgpu::DepthBiasState::default(),
                },
                if lit_mask { "fs_lighting" } else { "fs_lighting_color" },
                &targets,
            )
        });
        let frame_uniform = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("umbra frame uniform"),
            size: std::mem::size_of::<FrameUniform>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        Self {
            depth_format,
            frame_layout,
            light_layout,
            depth_pipelines,
            lighting_pipelines,
            frame_uniform,
            lights_uniform: None,
            target: None,
        }
    }

    /// The per-light lighting uniforms (one 256-byte slot per light), grown as needed.
    fn lights_uniform(&mut self, device: &wgpu::Device, lights: usize) -> (wgpu::Buffer, wgpu::BindGroup) {
        let needed = lights.max(1);
        if self.lights_uniform.as_ref().is_none_or(|(_, _, n)| *n < needed) {
            // One vec4 per light (`Light` of shaders/scene.wgsl).
            let (buffer, group) = uniform_slots(device, "umbra lighting lights", &self.light_layout, needed, 16);
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
        params.validate()?;
        let view = View::from_camera(&params.camera, params.width, params.height)?;
        let pending =
            scoped(device, "frame", || self.encode(device, queue, scene, volumes, params, &view, true, None))?;
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
        params.validate()?;
        let view = View::from_camera(&params.camera, params.width, params.height)?;
        scoped(device, "frame", || self.encode(device, queue, scene, volumes, &params, &view, false, None))?;
        Ok(())
    }

    /// [`Renderer::draw_frame`] with a GPU timestamp at every stage boundary, waited for:
    /// (stage, ms) summed over lights, in first-seen order — "prepare" (every light's compute
    /// work and shadow-map passes), "depth+ambient", "volumes", "lighting". `None` when the
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
        params.validate()?;
        let view = View::from_camera(&params.camera, params.width, params.height)?;
        let stamps = 3 + 2 * params.lights.len() as u32;
        let set = device.create_query_set(&wgpu::QuerySetDescriptor {
            label: Some("umbra stage timestamps"),
            ty: wgpu::QueryType::Timestamp,
            count: stamps,
        });
        let pending =
            scoped(device, "frame", || self.encode(device, queue, scene, volumes, &params, &view, false, Some(&set)))?;
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

    /// Records and submits the frame; returns the readbacks to map (the colour only with
    /// `read_color`).
    #[allow(clippy::too_many_arguments)]
    fn encode(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        scene: &SceneGpu,
        volumes: &mut ShadowVolumes,
        params: &FrameParams,
        view: &View,
        read_color: bool,
        timestamps: Option<&wgpu::QuerySet>,
    ) -> Result<Pending, WgpuError> {
        let (w, h) = (params.width, params.height);
        if self.target.as_ref().is_none_or(|t| t.width != w || t.height != h) {
            self.target = Some(Target::new(device, w, h, self.depth_format));
        }
        let eye = params.camera.eye.map(|c| c as f32);
        let frame = FrameUniform {
            clip_from_world: view.clip_from_world_f32(),
            ambient: [
                params.albedo[0] * params.ambient,
                params.albedo[1] * params.ambient,
                params.albedo[2] * params.ambient,
                0.0,
            ],
            eye: [eye[0], eye[1], eye[2], 0.0],
            albedo: [params.albedo[0], params.albedo[1], params.albedo[2], 0.0],
            light_color: [params.light_color[0], params.light_color[1], params.light_color[2], 0.0],
            specular: [params.specular, params.shininess, 0.0, 0.0],
        };
        queue.write_buffer(&self.frame_uniform, 0, bytemuck::bytes_of(&frame));
        let (lights_buffer, lights_group) = self.lights_uniform(device, params.lights.len());
        for (i, l) in params.lights.iter().enumerate() {
            queue.write_buffer(&lights_buffer, i as u64 * LIGHT_SLOT_BYTES, bytemuck::cast_slice(l));
        }
        let frame_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("umbra frame"),
            layout: &self.frame_layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: self.frame_uniform.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: scene.normal_buffer().as_entire_binding() },
            ],
        });
        let target = self.target.as_ref().expect("made above");
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("umbra frame") });
        // Stage boundaries (bench): the label of the stage that starts at each timestamp.
        let mut labels: Vec<&'static str> = Vec::new();
        let mut stamp = |encoder: &mut wgpu::CommandEncoder, label: &'static str| {
            if let Some(set) = timestamps {
                encoder.write_timestamp(set, labels.len() as u32);
                labels.push(label);
            }
        };
        stamp(&mut encoder, "prepare");

        // ---- Every light's compute work, before any pass.
        let frame = VolumeFrame { view, lights: &params.lights, zmode: params.zmode() };
        let plans = volumes.prepare(device, queue, &mut encoder, scene, &frame)?.to_vec();

        // ---- Pass 1: depth + ambient (+ world position, triangle id).
        stamp(&mut encoder, "depth+ambient");
        let capture_samples = params.capture.world_pos || params.capture.triangle_id;
        let (color, world, ids, lit, depth) = (
            view_of(&target.color),
            view_of(&target.world_pos),
            view_of(&target.triangle_id),
            view_of(&target.lit_mask),
            view_of(&target.depth),
        );
        use wgpu::LoadOp::{Clear, Load};
        let attachment = |view, load| {
            Some(wgpu::RenderPassColorAttachment {
                view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations { load, store: wgpu::StoreOp::Store },
            })
        };
        let draw_scene = |pass: &mut wgpu::RenderPass<'_>| {
            pass.set_vertex_buffer(0, scene.position_buffer().slice(..));
            pass.set_index_buffer(scene.index_buffer().slice(..), wgpu::IndexFormat::Uint32);
            pass.draw_indexed(0..scene.index_count(), 0, 0..1);
        };
        {
            let bg = params.background.map(f64::from);
            let mut attachments =
                vec![attachment(&color, Clear(wgpu::Color { r: bg[0], g: bg[1], b: bg[2], a: bg[3] }))];
            if capture_samples {
                attachments.push(attachment(&world, Clear(wgpu::Color::TRANSPARENT)));
                attachments
                    .push(attachment(&ids, Clear(wgpu::Color { r: f64::from(NO_TRIANGLE), g: 0.0, b: 0.0, a: 0.0 })));
            }
            // Reason: reversed-Z: the far plane (and the background) is depth 0, which is also
            // where light caps are pushed (so they fail the strict test there too).
            let mut pass = begin_pass(&mut encoder, "umbra depth+ambient", &attachments, &depth, Clear(0.0), Clear(0));
            pass.set_pipeline(&self.depth_pipelines[capture_samples as usize]);
            pass.set_bind_group(0, &frame_group, &[]);
            draw_scene(&mut pass);
        }

        let mut stencil = Vec::new();
        let mut lit_masks = Vec::new();
        for (i, plan) in plans.iter().enumerate() {
            // ---- Pass 2: this light's volumes into a freshly cleared stencil.
            stamp(&mut encoder, "volumes");
            {
                // Reason: the scene's depth, read by the volumes' depth test, never written.
                let mut pass = begin_pass(&mut encoder, "umbra volumes", &[], &depth, Load, Clear(plan.stencil_clear));
                volumes.draw(&mut pass, i);
            }
            if params.capture.stencil.includes(i) {
                let r =
                    Readback::copy(device, &mut encoder, &target.depth, wgpu::TextureAspect::StencilOnly, 1, "stencil");
                stencil.push((i, r));
            }
            // ---- Pass 3: lighting where the stencil is 0.
            stamp(&mut encoder, "lighting");
            let capture_lit = params.capture.lit_mask.includes(i);
            {
                let mut attachments = vec![attachment(&color, Load)];
                if capture_lit {
                    attachments.push(attachment(&lit, Clear(wgpu::Color::TRANSPARENT)));
                }
                let mut pass = begin_pass(&mut encoder, "umbra lighting", &attachments, &depth, Load, Load);
                pass.set_pipeline(&self.lighting_pipelines[capture_lit as usize]);
                pass.set_stencil_reference(0);
                pass.set_bind_group(0, &frame_group, &[]);
                pass.set_bind_group(1, &lights_group, &[(i as u64 * LIGHT_SLOT_BYTES) as u32]);
                draw_scene(&mut pass);
            }
            if capture_lit {
                let r = Readback::copy(device, &mut encoder, &target.lit_mask, wgpu::TextureAspect::All, 1, "lit mask");
                lit_masks.push((i, r));
            }
        }
        stamp(&mut encoder, "end");
        let stamps = timestamps.map(|set| {
            let n = labels.len() as u32;
            let bytes = 8 * u64::from(n);
            let resolve = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("umbra timestamps"),
                size: bytes,
                usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            });
            let readback = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("umbra timestamps readback"),
                size: bytes,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            encoder.resolve_query_set(set, 0..n, &resolve, 0);
            encoder.copy_buffer_to_buffer(&resolve, 0, &readback, 0, bytes);
            (labels.clone(), readback)
        });
        let all = wgpu::TextureAspect::All;
        let pending = Pending {
            stamps,
            color: read_color.then(|| Readback::copy(device, &mut encoder, &target.color, all, 4, "colour")),
            world_pos: params
                .capture
                .world_pos
                .then(|| Readback::copy(device, &mut encoder, &target.world_pos, all, 16, "world position")),
            triangle_id: params
                .capture
                .triangle_id
                .then(|| Readback::copy(device, &mut encoder, &target.triangle_id, all, 4, "triangle id")),
            stencil,
            lit_masks,
        };
        queue.submit([encoder.finish()]);
        Ok(pending)
    }
}

/// Readbacks recorded in a frame's command buffer.
struct Pending {
    /// Stage labels and the buffer their timestamps are copied to.
    stamps: Option<(Vec<&'static str>, wgpu::Buffer)>,
    color: Option<Readback>,
    world_pos: Option<Readback>,
    triangle_id: Option<Readback>,
    stencil: Vec<(usize, Readback)>,
    lit_masks: Vec<(usize, Readback)>,
}
