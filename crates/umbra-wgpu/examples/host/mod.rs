//! A renderer of the host's own that uses umbra's shadows, as an engine would: its own
//! depth-stencil texture, its own shaders (depth + ambient, Lambert lighting), its own passes;
//! umbra's [`ShadowVolumes`] counts each light's shadow volumes into the host's stencil inside
//! the host's render pass, and the host's lighting pass tests `stencil == 0`.
//!
//! Shared by the winit example (`examples/winit_host.rs`, drawing into a window's surface)
//! and the host-API test (`tests/host_api.rs`, drawing offscreen).
//!
//! What the host does to meet [`umbra_wgpu::volumes`]'s requirements:
//! * its depth pass uses reversed-Z with an infinite far plane: depth cleared to 0, compare
//!   `Greater`, the matrix [`View::clip_from_world_f32`] and `clip_from_world * vec4(p, 1.0)`
//!   with an `@invariant` position, drawing umbra's [`SceneGpu`] buffers (the same bits);
//! * per light, one render pass that loads that depth and clears the stencil to the light's
//!   [`umbra_wgpu::LightPlan::stencil_clear`], in which `volumes.draw(pass, light)` runs
//!   first and the host's lighting (stencil `Equal` 0, reference 0) second — re-binding its
//!   own bind groups, since umbra's draw sets groups 0 and 1.

#![allow(dead_code)] // each user compiles in what it needs

use umbra_wgpu::wgpu;
use umbra_wgpu::{PassFormats, SceneGpu, ShadowVolumes, View, VolumeFrame, ZMode};

const SHADER: &str = r#"
struct Camera {
    clip_from_world: mat4x4<f32>,
    eye: vec4<f32>,
}
@group(0) @binding(0) var<uniform> camera: Camera;

struct Light {
    // w = 1 point light, w = 0 directional light coming FROM xyz.
    position: vec4<f32>,
    color: vec4<f32>,
}
@group(1) @binding(0) var<uniform> light: Light;

struct Vertex {
    // The expression umbra's volumes use for w = 1 vertices, invariant: equal depths.
    @builtin(position) @invariant position: vec4<f32>,
    @location(0) world: vec3<f32>,
}

@vertex
fn vs(@location(0) p: vec3<f32>) -> Vertex {
    var v: Vertex;
    v.world = p;
    v.position = camera.clip_from_world * vec4<f32>(p, 1.0);
    return v;
}

@fragment
fn fs_ambient(v: Vertex) -> @location(0) vec4<f32> {
    return vec4<f32>(0.10, 0.11, 0.13, 1.0);
}

@fragment
fn fs_light(v: Vertex) -> @location(0) vec4<f32> {
    // The host's own shading: a flat normal from screen-space derivatives, facing the eye.
    var n = normalize(cross(dpdx(v.world), dpdy(v.world)));
    if dot(n, camera.eye.xyz - v.world) < 0.0 {
        n = -n;
    }
    let l = normalize(light.position.xyz - v.world * light.position.w);
    return vec4<f32>(light.color.rgb * max(dot(n, l), 0.0), 0.0);
}
"#;

/// Bytes between two lights' uniforms (wgpu's largest offset alignment).
const SLOT: u64 = 256;

/// The host's renderer. See the module documentation.
pub struct HostRenderer {
    pub color_format: wgpu::TextureFormat,
    pub depth_format: wgpu::TextureFormat,
    pub sample_count: u32,
    camera: wgpu::Buffer,
    lights: wgpu::Buffer,
    camera_group: wgpu::BindGroup,
    light_group: wgpu::BindGroup,
    ambient: wgpu::RenderPipeline,
    lighting: wgpu::RenderPipeline,
    /// umbra's shadow volumes, made for this renderer's pass formats.
    pub volumes: ShadowVolumes,
    depth: Option<(wgpu::Texture, u32, u32)>,
    msaa: Option<wgpu::Texture>,
}

/// Up to this many lights per frame.
pub const MAX_LIGHTS: usize = 8;

impl HostRenderer {
    /// Pipelines for a colour target of `color_format`, a depth-stencil texture of
    /// `depth_format` (with stencil) and `sample_count` samples; umbra's `method`.
    pub fn new(
        device: &wgpu::Device,
        color_format: wgpu::TextureFormat,
        depth_format: wgpu::TextureFormat,
        sample_count: u32,
        method: &str,
    ) -> Result<Self, umbra_wgpu::WgpuError> {
        let formats = PassFormats { color: vec![Some(color_format)], depth_stencil: depth_format };
        let volumes = ShadowVolumes::new(device, &formats, sample_count, method)?;
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("host"),
            source: wgpu::ShaderSource::Wgsl(SHADER.into()),
        });
        let uniform = |dynamic| wgpu::BindGroupLayoutEntry {
            binding: 0,
            visibility: wgpu::ShaderStages::VERTEX | wgpu::ShaderStages::FRAGMENT,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Uniform,
                has_dynamic_offset: dynamic,
                min_binding_size: None,
            },
            count: None,
        };
        let camera_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("host camera"),
            entries: &[uniform(false)],
        });
        let light_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("host light"),
            entries: &[uniform(true)],
        });
        let buffer = |label, size| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        };
        let camera = buffer("host camera", 80);
        let lights = buffer("host lights", SLOT * MAX_LIGHTS as u64);
        let camera_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("host camera"),
            layout: &camera_layout,
            entries: &[wgpu::BindGroupEntry { binding: 0, resource: camera.as_entire_binding() }],
        });
        let light_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("host light"),
            layout: &light_layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                    buffer: &lights,
                    offset: 0,
                    size: wgpu::BufferSize::new(32),
                }),
            }],
        });
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("host"),
            bind_group_layouts: &[Some(&camera_layout), Some(&light_layout)],
            immediate_size: 0,
        });
        let attributes =
            [wgpu::VertexAttribute { format: wgpu::VertexFormat::Float32x3, offset: 0, shader_location: 0 }];
        let buffers = [Some(wgpu::VertexBufferLayout {
            array_stride: 12,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &attributes,
        })];
        let pipeline = |entry, depth_stencil, blend| {
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(entry),
                layout: Some(&layout),
                vertex: wgpu::VertexState {
                    module: &module,
                    entry_point: Some("vs"),
                    compilation_options: Default::default(),
                    buffers: &buffers,
                },
                primitive: wgpu::PrimitiveState { cull_mode: None, ..Default::default() },
                depth_stencil: Some(depth_stencil),
                multisample: wgpu::MultisampleState { count: sample_count, ..Default::default() },
                fragment: Some(wgpu::FragmentState {
                    module: &module,
                    entry_point: Some(entry),
                    compilation_options: Default::default(),
                    targets: &[Some(wgpu::ColorTargetState {
                        format: color_format,
                        blend,
                        write_mask: wgpu::ColorWrites::ALL,
                    })],
                }),
                multiview_mask: None,
                cache: None,
            })
        };
        // Depth + ambient: reversed-Z, nearer = Greater, depth written.
        let ambient = pipeline(
            "fs_ambient",
            wgpu::DepthStencilState {
                format: depth_format,
                depth_write_enabled: Some(true),
                depth_compare: Some(wgpu::CompareFunction::Greater),
                stencil: wgpu::StencilState::default(),
                bias: Default::default(),
            },
            None,
        );
        // Lighting: the visible surface (depth Equal) where umbra's stencil says lit.
        let lit = ShadowVolumes::lit_stencil_test();
        let add = wgpu::BlendComponent {
            src_factor: wgpu::BlendFactor::One,
            dst_factor: wgpu::BlendFactor::One,
            operation: wgpu::BlendOperation::Add,
        };
        let lighting = pipeline(
            "fs_light",
            wgpu::DepthStencilState {
                format: depth_format,
                depth_write_enabled: Some(false),
                depth_compare: Some(wgpu::CompareFunction::Equal),
                stencil: wgpu::StencilState { front: lit, back: lit, read_mask: 0xFF, write_mask: 0 },
                bias: Default::default(),
            },
            Some(wgpu::BlendState { color: add, alpha: add }),
        );
        Ok(Self {
            color_format,
            depth_format,
            sample_count,
            camera,
            lights,
            camera_group,
            light_group,
            ambient,
            lighting,
            volumes,
            depth: None,
            msaa: None,
        })
    }

    /// The host's depth-stencil texture for a `width x height` target (made on first use).
    pub fn depth_texture(&mut self, device: &wgpu::Device, width: u32, height: u32) -> &wgpu::Texture {
        if self.depth.as_ref().is_none_or(|(_, w, h)| (*w, *h) != (width, height)) {
            let texture = |label, format, usage| {
                device.create_texture(&wgpu::TextureDescriptor {
                    label: Some(label),
                    size: wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
                    mip_level_count: 1,
                    sample_count: self.sample_count,
                    dimension: wgpu::TextureDimension::D2,
                    format,
                    usage,
                    view_formats: &[],
                })
            };
            let depth_usage = wgpu::TextureUsages::RENDER_ATTACHMENT
                | if self.sample_count == 1 { wgpu::TextureUsages::COPY_SRC } else { wgpu::TextureUsages::empty() };
            self.depth = Some((texture("host depth-stencil", self.depth_format, depth_usage), width, height));
            self.msaa = (self.sample_count > 1)
                .then(|| texture("host msaa colour", self.color_format, wgpu::TextureUsages::RENDER_ATTACHMENT));
        }
        &self.depth.as_ref().expect("made above").0
    }

    /// Records one frame into `encoder`: umbra's per-light work, the host's depth + ambient
    /// pass, and per light one pass with umbra's volumes and the host's lighting. `target` is
    /// the colour view, of the colour format given to [`HostRenderer::new`] (resolved into
    /// when multisampled). Afterwards the stencil holds the last light's count (the lighting
    /// writes none of it).
    #[allow(clippy::too_many_arguments)]
    pub fn frame(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        scene: &SceneGpu,
        view: &View,
        lights: &[[f32; 4]],
        target: &wgpu::TextureView,
        size: (u32, u32),
    ) -> Result<(), umbra_wgpu::WgpuError> {
        let lights = &lights[..lights.len().min(MAX_LIGHTS)];
        let mut camera = [0f32; 20];
        camera[..16].copy_from_slice(&view.clip_from_world_f32());
        camera[16..19].copy_from_slice(&view.eye().map(|c| c as f32));
        queue.write_buffer(&self.camera, 0, bytemuck::cast_slice(&camera));
        for (i, l) in lights.iter().enumerate() {
            let data = [l[0], l[1], l[2], l[3], 0.7, 0.68, 0.62, 1.0];
            queue.write_buffer(&self.lights, i as u64 * SLOT, bytemuck::cast_slice(&data));
        }
        // umbra: every light's compute work, before the passes. No receiver cull: it needs the
        // depth drawn and submitted first, and a single-sample depth (this host multisamples).
        let frame = VolumeFrame { view, lights, zmode: ZMode::default(), receivers: None };
        let plans = self.volumes.prepare(device, queue, encoder, scene, &frame)?.to_vec();
        self.depth_texture(device, size.0, size.1);
        let depth = self.depth.as_ref().expect("made above").0.create_view(&Default::default());
        let msaa = self.msaa.as_ref().map(|t| t.create_view(&Default::default()));
        let (color, resolve) = match &msaa {
            Some(m) => (m, Some(target)),
            None => (target, None),
        };
        let color_attachment = |load| {
            Some(wgpu::RenderPassColorAttachment {
                view: color,
                depth_slice: None,
                resolve_target: resolve,
                ops: wgpu::Operations { load, store: wgpu::StoreOp::Store },
            })
        };
        let draw_scene = |pass: &mut wgpu::RenderPass<'_>| {
            pass.set_vertex_buffer(0, scene.position_buffer().slice(..));
            pass.set_index_buffer(scene.index_buffer().slice(..), wgpu::IndexFormat::Uint32);
            pass.draw_indexed(0..scene.index_count(), 0, 0..1);
        };
        {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("host depth+ambient"),
                color_attachments: &[color_attachment(wgpu::LoadOp::Clear(wgpu::Color::BLACK))],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &depth,
                    depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Clear(0.0), store: wgpu::StoreOp::Store }),
                    stencil_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Clear(0), store: wgpu::StoreOp::Store }),
                }),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(&self.ambient);
            pass.set_bind_group(0, &self.camera_group, &[]);
            pass.set_bind_group(1, &self.light_group, &[0]);
            draw_scene(&mut pass);
        }
        for (i, plan) in plans.iter().enumerate() {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("host light"),
                color_attachments: &[color_attachment(wgpu::LoadOp::Load)],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &depth,
                    depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Load, store: wgpu::StoreOp::Store }),
                    // umbra's requirement: the stencil cleared to the light's plan.
                    stencil_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(plan.stencil_clear),
                        store: wgpu::StoreOp::Store,
                    }),
                }),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            // umbra counts this light's shadow volumes into the host's stencil ...
            self.volumes.draw(&mut pass, i);
            // ... and the host lights where it stayed 0 (its bind groups set again: umbra's
            // draw set groups 0 and 1).
            pass.set_pipeline(&self.lighting);
            pass.set_stencil_reference(0);
            pass.set_bind_group(0, &self.camera_group, &[]);
            pass.set_bind_group(1, &self.light_group, &[(i as u64 * SLOT) as u32]);
            draw_scene(&mut pass);
        }
        Ok(())
    }
}
