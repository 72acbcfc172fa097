//! `shadow-map-cube:RES[+pcf]` on wgpu: the shadow-mapping baseline the papers measure shadow
//! volumes against (Williams 1978; paper 003, Section 3.1, Tables 1-2; paper 001, Tables 6
//! and 8), the twin of umbra-gl's: a `RES x RES x 6` reversed-depth cube map per point light
//! (GL's face order and face selection, [`umbra_geom::shadow_map`]), one `RES x RES` map
//! fitted to the scene's bounds per directional light, constant + slope-scaled bias while
//! rendering the map, a hard test or 3 x 3 PCF majority vote. Not exact (aliasing, bias):
//! measured by the verifier, never failed.
//!
//! Differences from umbra-gl, both forced by wgpu: the six faces are six passes (no geometry
//! shader, so no layered pass; `--sm-faces` has no effect here), and the bias's constant part is
//! an integer number of depth units (`DepthBiasState::constant`; umbra-gl's glPolygonOffset
//! takes a float, so a fractional `--sm-bias` constant is rounded). The decision is resolved
//! into the caller's stencil (cleared to 1, 0 where the map sees the sample lit;
//! shaders/shadow_map.wgsl), so the host's lighting tests `stencil == 0` for every method.
//!
//! Per light (its own map: every light of a frame is prepared before any is drawn): the map's
//! depth passes in `prepare`; in the caller's pass, the resolve draw.

use glam::{DMat4, DVec3};
use umbra_geom::camera::to_f32_cols;
use umbra_geom::shadow_map::{face_clip_from_world, map_clip_from_world, map_from_world, parse_name, NEAR_FRACTION};
use umbra_geom::Aabb;

use crate::builders::{uniform_entry, uniform_slots, LIGHT_SLOT_BYTES};
use crate::common::{Common, LightPlan, RESOLVE_VERTEX};
use crate::error::WgpuError;
use crate::methods::method::{LightFrame, Method, MethodKind};
use crate::scene::{SceneGpu, SceneId};

/// Name prefix of the family: `shadow-map-cube:RES[+pcf]`, RES texels per face side.
pub const PREFIX: &str = umbra_geom::shadow_map::PREFIX;
/// The listed members (umbra-gl's): 1K and 2K per face.
pub const NAME_1024: &str = "shadow-map-cube:1024";
/// 2048 texels per face.
pub const NAME_2048: &str = "shadow-map-cube:2048";

/// Default constant bias, depth units (umbra-gl's default, an integer).
pub const DEFAULT_BIAS_CONSTANT: i32 = 4;
/// Default slope-scaled bias (umbra-gl's default).
pub const DEFAULT_BIAS_SLOPE: f32 = 1.5;

const VOLUME: &str = include_str!("../shaders/volume.wgsl");
const SHADER: &str = include_str!("../shaders/shadow_map.wgsl");
const MAP_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// Everything that defines a wgpu shadow-map method.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadowMapConfig {
    /// Texels per side of each cube face (and of the directional map).
    pub resolution: u32,
    /// Constant bias in depth units, pushing stored depths away from the light.
    pub bias_constant: i32,
    /// Slope-scaled bias (multiple of the primitive's depth slope).
    pub bias_slope: f32,
    /// 3 x 3 percentage-closer filtering, majority vote.
    pub pcf: bool,
}

impl ShadowMapConfig {
    /// Default bias, no PCF.
    pub fn new(resolution: u32) -> Self {
        Self { resolution, bias_constant: DEFAULT_BIAS_CONSTANT, bias_slope: DEFAULT_BIAS_SLOPE, pcf: false }
    }

    /// Parses `shadow-map-cube:RES[+pcf]` ([`umbra_geom::shadow_map::parse_name`]).
    pub fn from_name(name: &str) -> Option<Self> {
        let (resolution, pcf) = parse_name(name)?;
        Some(Self { pcf, ..Self::new(resolution) })
    }

    /// `shadow-map-cube:RES[+pcf]` (bias does not change the name;
    /// [`umbra_geom::shadow_map::name`]).
    pub fn name(&self) -> &'static str {
        umbra_geom::shadow_map::name(self.resolution, self.pcf)
    }
}

/// The resolve shader's per-light uniform (`Lookup` of shaders/shadow_map.wgsl).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Lookup {
    map_from_world: [f32; 16],
    light_near: [f32; 4],
    kind_resolution: [f32; 4],
}

/// One light's map.
struct PerLight {
    point: bool,
    texture: wgpu::Texture,
    /// One view per layer (6 for a point light, 1 for a directional one).
    layers: Vec<wgpu::TextureView>,
    /// Per layer: the light clip matrix, 256-byte slots.
    faces: wgpu::Buffer,
    faces_group: wgpu::BindGroup,
    lookup: wgpu::Buffer,
    resolve_group: wgpu::BindGroup,
}

/// See the module documentation.
pub struct ShadowMapCube {
    config: ShadowMapConfig,
    name: &'static str,
    faces_layout: wgpu::BindGroupLayout,
    resolve_layout: wgpu::BindGroupLayout,
    map_pipeline: wgpu::RenderPipeline,
    resolve_pipeline: wgpu::RenderPipeline,
    sampler: wgpu::Sampler,
    prepared: Option<SceneId>,
    bounds: Aabb,
    positions: Option<wgpu::Buffer>,
    indices: Option<(wgpu::Buffer, u32)>,
    lights: Vec<PerLight>,
}

impl ShadowMapCube {
    /// Pipelines for the pass formats of `common`; the resolution is checked against the
    /// device's largest 2D texture.
    pub(crate) fn new(device: &wgpu::Device, common: &Common, config: ShadowMapConfig) -> Result<Self, WgpuError> {
        let max = device.limits().max_texture_dimension_2d;
        if config.resolution == 0 || config.resolution > max {
            return Err(WgpuError::InvalidParams(format!(
                "{}: resolution {} exceeds this device's largest 2D texture ({max} texels)",
                config.name(),
                config.resolution
            )));
        }
        if !config.bias_slope.is_finite() {
            return Err(WgpuError::InvalidParams(format!("{}: slope bias {}", config.name(), config.bias_slope)));
        }
        let module =
            Common::module(device, "shadow_map.wgsl", &["enable clip_distances;", VOLUME, RESOLVE_VERTEX, SHADER]);
        let faces_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("shadow map faces"),
            entries: &[uniform_entry(0, wgpu::ShaderStages::VERTEX, true)],
        });
        let fragment = wgpu::ShaderStages::FRAGMENT;
        let resolve_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("shadow map resolve"),
            entries: &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: fragment,
                    ty: wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Depth,
                        view_dimension: wgpu::TextureViewDimension::D2Array,
                        multisampled: false,
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 1,
                    visibility: fragment,
                    ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Comparison),
                    count: None,
                },
                uniform_entry(2, fragment, false),
            ],
        });
        let positions =
            [wgpu::VertexAttribute { format: wgpu::VertexFormat::Float32x3, offset: 0, shader_location: 0 }];
        let buffers = [Some(wgpu::VertexBufferLayout {
            array_stride: 12,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &positions,
        })];
        let primitive = |unclipped_depth| wgpu::PrimitiveState {
            topology: wgpu::PrimitiveTopology::TriangleList,
            strip_index_format: None,
            // Reason: irrelevant without culling.
            front_face: wgpu::FrontFace::Ccw,
            // Reason: triangle soups are two-sided; either side of a triangle occludes / is seen.
            cull_mode: None,
            unclipped_depth,
            polygon_mode: wgpu::PolygonMode::Fill,
            conservative: false,
        };
        let map_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("shadow map depth"),
            bind_group_layouts: &[None, None, Some(&faces_layout)],
            immediate_size: 0,
        });
        let map_pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("shadow map depth"),
            layout: Some(&map_layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_map"),
                compilation_options: Default::default(),
                buffers: &buffers,
            },
            // Reason: an occluder nearer to the light than the near distance still occludes
            // everything behind it: clamped to depth 1 instead of being clipped away.
            primitive: primitive(true),
            depth_stencil: Some(wgpu::DepthStencilState {
                format: MAP_FORMAT,
                depth_write_enabled: Some(true),
                // Reason: reversed depth, larger = closer to the light: keep the closest occluder.
                depth_compare: Some(wgpu::CompareFunction::Greater),
                stencil: wgpu::StencilState::default(),
                // Reason: the constant + slope-scaled bias against self-shadowing ("acne"),
                // negated because reversed depth moves AWAY from the light towards 0.
                bias: wgpu::DepthBiasState {
                    constant: -config.bias_constant,
                    slope_scale: -config.bias_slope,
                    clamp: 0.0,
                },
            }),
            multisample: wgpu::MultisampleState::default(),
            // Reason: depth only.
            fragment: None,
            multiview_mask: None,
            cache: None,
        });
        let resolve_pl = common.pipeline_layout(device, "shadow map resolve", &[&resolve_layout]);
        let resolve_pipeline = common.surface_resolve_pipeline(
            device,
            "shadow map resolve",
            &resolve_pl,
            &module,
            if config.pcf { "fs_resolve_pcf" } else { "fs_resolve" },
        );
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("shadow map comparison"),
            address_mode_u: wgpu::AddressMode::ClampToEdge,
            address_mode_v: wgpu::AddressMode::ClampToEdge,
            address_mode_w: wgpu::AddressMode::ClampToEdge,
            // Reason: NEAREST = a hard test (umbra-gl's); PCF votes over texels explicitly.
            mag_filter: wgpu::FilterMode::Nearest,
            min_filter: wgpu::FilterMode::Nearest,
            mipmap_filter: wgpu::MipmapFilterMode::Nearest,
            // Reason: lit iff the sample's depth >= the stored (closest occluder's) depth.
            compare: Some(wgpu::CompareFunction::GreaterEqual),
            ..Default::default()
        });
        Ok(Self {
            name: config.name(),
            config,
            faces_layout,
            resolve_layout,
            map_pipeline,
            resolve_pipeline,
            sampler,
            prepared: None,
            bounds: Aabb { min: [-1.0; 3], max: [1.0; 3] },
            positions: None,
            indices: None,
            lights: Vec::new(),
        })
    }

    /// The configuration it was made with.
    pub fn config(&self) -> &ShadowMapConfig {
        &self.config
    }

    /// Makes light `slot`'s map (remade when the light kind changes).
    fn ensure_light(&mut self, device: &wgpu::Device, slot: usize, point: bool) {
        while self.lights.len() <= slot {
            let l = self.make_light(device, point);
            self.lights.push(l);
        }
        if self.lights[slot].point != point {
            self.lights[slot] = self.make_light(device, point);
        }
    }

    fn make_light(&self, device: &wgpu::Device, point: bool) -> PerLight {
        let layers = if point { 6 } else { 1 };
        let res = self.config.resolution;
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("shadow map"),
            size: wgpu::Extent3d { width: res, height: res, depth_or_array_layers: layers },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: MAP_FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        });
        let layer_views = (0..layers)
            .map(|layer| {
                texture.create_view(&wgpu::TextureViewDescriptor {
                    label: Some("shadow map layer"),
                    dimension: Some(wgpu::TextureViewDimension::D2),
                    base_array_layer: layer,
                    array_layer_count: Some(1),
                    ..Default::default()
                })
            })
            .collect();
        // One light clip matrix per layer.
        let (faces, faces_group) = uniform_slots(device, "shadow map faces", &self.faces_layout, layers as usize, 64);
        let lookup = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("shadow map lookup"),
            size: std::mem::size_of::<Lookup>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let array_view = texture.create_view(&wgpu::TextureViewDescriptor {
            label: Some("shadow map array"),
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            ..Default::default()
        });
        let resolve_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("shadow map resolve"),
            layout: &self.resolve_layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: wgpu::BindingResource::TextureView(&array_view) },
                wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::Sampler(&self.sampler) },
                wgpu::BindGroupEntry { binding: 2, resource: lookup.as_entire_binding() },
            ],
        });
        PerLight { point, texture, layers: layer_views, faces, faces_group, lookup, resolve_group }
    }
}

impl Method for ShadowMapCube {
    fn name(&self) -> &'static str {
        self.name
    }

    fn kind(&self) -> MethodKind {
        MethodKind::Resolve
    }

    fn prepared_scene(&self) -> Option<SceneId> {
        self.prepared
    }

    fn prepare_scene(&mut self, _device: &wgpu::Device, scene: &SceneGpu, _common: &Common) -> Result<(), WgpuError> {
        self.bounds = scene.bounds().unwrap_or(Aabb { min: [-1.0; 3], max: [1.0; 3] });
        self.positions = Some(scene.position_buffer().clone());
        self.indices = Some((scene.index_buffer().clone(), scene.index_count()));
        self.prepared = Some(scene.id());
        Ok(())
    }

    fn prepare_light(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        _scene: &SceneGpu,
        common: &Common,
        frame: &LightFrame,
    ) -> Result<(), WgpuError> {
        common.write_slot(queue, frame.slot, &frame.data);
        let light = frame.data.light;
        let point = light[3] != 0.0;
        let (bounds, resolution) = (self.bounds, self.config.resolution);
        let l3 = DVec3::new(f64::from(light[0]), f64::from(light[1]), f64::from(light[2]));
        // wgpu's clip z runs over [0, w]: zero_to_one.
        let (matrices, lookup): (Vec<DMat4>, Lookup) = if point {
            let near = NEAR_FRACTION * f64::from(bounds.diagonal()).max(1e-6);
            (
                (0..6).map(|f| face_clip_from_world(f, l3, near, true)).collect(),
                Lookup {
                    map_from_world: [0.0; 16],
                    light_near: [light[0], light[1], light[2], near as f32],
                    kind_resolution: [0.0, resolution as f32, 0.0, 0.0],
                },
            )
        } else {
            let m = map_from_world(l3, &bounds);
            (
                vec![map_clip_from_world(&m, true)],
                Lookup {
                    map_from_world: to_f32_cols(&m),
                    light_near: [0.0; 4],
                    kind_resolution: [1.0, resolution as f32, 0.0, 0.0],
                },
            )
        };
        let (positions, indices) = match (&self.positions, &self.indices) {
            (Some(p), Some(i)) => (p.clone(), i.clone()),
            _ => return Err(WgpuError::InvalidParams(format!("{}: prepare_light before prepare_scene", self.name))),
        };
        self.ensure_light(device, frame.slot, point);
        let map = &self.lights[frame.slot];
        queue.write_buffer(&map.lookup, 0, bytemuck::bytes_of(&lookup));
        for (layer, m) in matrices.iter().enumerate() {
            queue.write_buffer(&map.faces, layer as u64 * LIGHT_SLOT_BYTES, bytemuck::cast_slice(&to_f32_cols(m)));
        }
        for (layer, view) in map.layers.iter().enumerate() {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("shadow map face"),
                color_attachments: &[],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view,
                    // Reason: 0 = infinitely far (reversed depth).
                    depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Clear(0.0), store: wgpu::StoreOp::Store }),
                    stencil_ops: None,
                }),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            if indices.1 > 0 {
                pass.set_pipeline(&self.map_pipeline);
                pass.set_bind_group(2, &map.faces_group, &[(layer as u64 * LIGHT_SLOT_BYTES) as u32]);
                pass.set_vertex_buffer(0, positions.slice(..));
                pass.set_index_buffer(indices.0.slice(..), wgpu::IndexFormat::Uint32);
                pass.draw_indexed(0..indices.1, 0, 0..1);
            }
        }
        Ok(())
    }

    fn draw(&self, pass: &mut wgpu::RenderPass<'_>, common: &Common, slot: usize, _plan: LightPlan) {
        let (Some(l), Some(positions), Some((indices, count))) =
            (self.lights.get(slot), &self.positions, &self.indices)
        else {
            return;
        };
        if *count == 0 {
            return;
        }
        common.bind_slot_render(pass, slot);
        pass.set_pipeline(&self.resolve_pipeline);
        pass.set_bind_group(1, &l.resolve_group, &[]);
        pass.set_vertex_buffer(0, positions.slice(..));
        pass.set_index_buffer(indices.slice(..), wgpu::IndexFormat::Uint32);
        pass.draw_indexed(0..*count, 0, 0..1);
    }

    fn gpu_bytes(&self) -> u64 {
        self.lights
            .iter()
            .map(|l| {
                let s = l.texture.size();
                4 * u64::from(s.width) * u64::from(s.height) * u64::from(s.depth_or_array_layers)
            })
            .sum()
    }
}
