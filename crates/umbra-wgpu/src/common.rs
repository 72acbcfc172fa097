//! What every method shares: the caller's pass formats ([`PassFormats`]), the per-light
//! uniform slots ([`LightSlot`], group 0 at a dynamic offset) and the counting pipeline
//! ([`Common`]), and what the volumes decided for a light ([`LightPlan`]).

use crate::builders::{uniform_slots, LIGHT_SLOT_BYTES};

/// The formats of the render pass [`ShadowVolumes::draw`](crate::ShadowVolumes::draw) draws into.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PassFormats {
    /// The pass's colour attachments, in order (`None` for an unused slot). The volumes write
    /// none of them.
    pub color: Vec<Option<wgpu::TextureFormat>>,
    /// The pass's depth-stencil attachment: a depth format with 8 stencil bits.
    pub depth_stencil: wgpu::TextureFormat,
}

/// What [`ShadowVolumes::prepare`](crate::ShadowVolumes::prepare) decided for one light: how its volumes count and what the
/// stencil of its pass must be cleared to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LightPlan {
    /// Counted z-pass (forced, or chosen where provably exact) rather than z-fail.
    pub zpass: bool,
    /// The value the caller's pass must clear the stencil to before [`ShadowVolumes::draw`](crate::ShadowVolumes::draw):
    /// 0; the eye's winding number `W0` mod 256 when z-pass counts from it (every ray from the
    /// eye's near pyramid to the light crosses the same `W0` triangles); 1 for a shadow map,
    /// whose draw writes 0 where the light reaches.
    pub stencil_clear: u32,
}

/// The per-light uniform slot (`UmbraLight` of shaders/volume.wgsl).
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub(crate) struct LightSlot {
    pub clip_from_world: [f32; 16],
    pub light: [f32; 4],
    pub scene_planes: [[f32; 4]; 6],
    pub far_clip_z: f32,
    pub scene_clip: u32,
    pub vertices_per_cap: u32,
    pub triangles: u32,
    pub records: u32,
    pub max_mult: u32,
    pub vertices: u32,
    pub pad: u32,
    pub first_light_cap: u32,
    pub first_dark_cap: u32,
    pub pad2: [u32; 2],
}

/// Resources every method shares: the per-light uniform slots (group 0, dynamic offset) and
/// the pipeline factory for the caller's pass formats.
pub(crate) struct Common {
    pub formats: PassFormats,
    pub sample_count: u32,
    light_layout: wgpu::BindGroupLayout,
    light_buffer: wgpu::Buffer,
    light_group: wgpu::BindGroup,
    slots: usize,
}

/// The vertex stage of [`Common::surface_resolve_pipeline`] (`vs_resolve`), a WGSL part to put
/// after volume.wgsl in the method's module.
pub const RESOLVE_VERTEX: &str = include_str!("shaders/resolve.wgsl");

impl Common {
    pub(crate) fn new(device: &wgpu::Device, formats: PassFormats, sample_count: u32) -> Self {
        let light_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("umbra light slot"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::VERTEX | wgpu::ShaderStages::FRAGMENT | wgpu::ShaderStages::COMPUTE,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: true,
                    min_binding_size: wgpu::BufferSize::new(std::mem::size_of::<LightSlot>() as u64),
                },
                count: None,
            }],
        });
        let (light_buffer, light_group) = Self::slots_buffer(device, &light_layout, 1);
        Self { formats, sample_count, light_layout, light_buffer, light_group, slots: 1 }
    }

    fn slots_buffer(
        device: &wgpu::Device,
        layout: &wgpu::BindGroupLayout,
        slots: usize,
    ) -> (wgpu::Buffer, wgpu::BindGroup) {
        uniform_slots(device, "umbra light slots", layout, slots, std::mem::size_of::<LightSlot>() as u64)
    }

    /// Room for `slots` lights.
    pub(crate) fn reserve(&mut self, device: &wgpu::Device, slots: usize) {
        if slots > self.slots {
            let (buffer, group) = Self::slots_buffer(device, &self.light_layout, slots);
            self.light_buffer = buffer;
            self.light_group = group;
            self.slots = slots;
        }
    }

    pub fn write_slot(&self, queue: &wgpu::Queue, slot: usize, data: &LightSlot) {
        queue.write_buffer(&self.light_buffer, slot as u64 * LIGHT_SLOT_BYTES, bytemuck::bytes_of(data));
    }

    /// Binds light `slot`'s uniforms as group 0.
    pub fn bind_slot_render(&self, pass: &mut wgpu::RenderPass<'_>, slot: usize) {
        pass.set_bind_group(0, &self.light_group, &[(slot as u64 * LIGHT_SLOT_BYTES) as u32]);
    }

    /// Binds light `slot`'s uniforms as group 0 of a compute pass.
    pub fn bind_slot_compute(&self, pass: &mut wgpu::ComputePass<'_>, slot: usize) {
        pass.set_bind_group(0, &self.light_group, &[(slot as u64 * LIGHT_SLOT_BYTES) as u32]);
    }

    /// A shader module from WGSL pieces (joined with newlines), named for its errors.
    pub fn module(device: &wgpu::Device, label: &str, parts: &[&str]) -> wgpu::ShaderModule {
        device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some(label),
            source: wgpu::ShaderSource::Wgsl(parts.join("\n").into()),
        })
    }

    /// A method's pipeline layout: the light slot as group 0, then `groups` from group 1 on.
    pub fn pipeline_layout(
        &self,
        device: &wgpu::Device,
        label: &str,
        groups: &[&wgpu::BindGroupLayout],
    ) -> wgpu::PipelineLayout {
        let layouts: Vec<Option<&wgpu::BindGroupLayout>> =
            std::iter::once(&self.light_layout).chain(groups.iter().copied()).map(Some).collect();
        device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some(label),
            bind_group_layouts: &layouts,
            immediate_size: 0,
        })
    }

    /// A resolve pipeline that writes a light's decision into the stencil on the caller's
    /// visible surface: the scene's positions drawn with `module`'s `vs_resolve` and the
    /// fragment entry `fs_entry` (which discards the shadowed fragments) over the caller's final
    /// depth (EQUAL), every surviving fragment setting its pixel's stencil to 0 (lit); no colour.
    /// The stencil holds 1 before (shadowed). Shared by the shadow map's and ray-bvh's resolves.
    pub fn surface_resolve_pipeline(
        &self,
        device: &wgpu::Device,
        label: &str,
        layout: &wgpu::PipelineLayout,
        module: &wgpu::ShaderModule,
        fs_entry: &str,
    ) -> wgpu::RenderPipeline {
        let positions =
            [wgpu::VertexAttribute { format: wgpu::VertexFormat::Float32x3, offset: 0, shader_location: 0 }];
        let buffers = [Some(wgpu::VertexBufferLayout {
            array_stride: 12,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &positions,
        })];
        let to_zero = wgpu::StencilFaceState {
            // Reason: every fragment that survives the decision marks its pixel lit (0).
            compare: wgpu::CompareFunction::Always,
            fail_op: wgpu::StencilOperation::Keep,
            depth_fail_op: wgpu::StencilOperation::Keep,
            pass_op: wgpu::StencilOperation::Zero,
        };
        let targets: Vec<Option<wgpu::ColorTargetState>> = self
            .formats
            .color
            .iter()
            .map(|f| {
                f.map(|format| wgpu::ColorTargetState { format, blend: None, write_mask: wgpu::ColorWrites::empty() })
            })
            .collect();
        device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some(label),
            layout: Some(layout),
            vertex: wgpu::VertexState {
                module,
                entry_point: Some("vs_resolve"),
                compilation_options: Default::default(),
                buffers: &buffers,
            },
            primitive: wgpu::PrimitiveState {
                topology: wgpu::PrimitiveTopology::TriangleList,
                strip_index_format: None,
                // Reason: irrelevant without culling.
                front_face: wgpu::FrontFace::Ccw,
                // Reason: two-sided surfaces, as in the caller's depth pass.
                cull_mode: None,
                // Reason: the same clipping as the caller's scene pass (depths must be equal).
                unclipped_depth: false,
                polygon_mode: wgpu::PolygonMode::Fill,
                conservative: false,
            },
            depth_stencil: Some(wgpu::DepthStencilState {
                format: self.formats.depth_stencil,
                // Reason: the caller's depth is final.
                depth_write_enabled: Some(false),
                // Reason: only the surface the caller's depth holds (bit-identical depths).
                depth_compare: Some(wgpu::CompareFunction::Equal),
                stencil: wgpu::StencilState { front: to_zero, back: to_zero, read_mask: 0xFF, write_mask: 0xFF },
                bias: wgpu::DepthBiasState::default(),
            }),
            multisample: wgpu::MultisampleState {
                count: self.sample_count,
                mask: !0,
                alpha_to_coverage_enabled: false,
            },
            fragment: Some(wgpu::FragmentState {
                module,
                entry_point: Some(fs_entry),
                compilation_options: Default::default(),
                // Reason: no colour is written (the caller's colour stays untouched).
                targets: &targets,
            }),
            multiview_mask: None,
            cache: None,
        })
    }

    /// The counting pipeline of a volume draw: z-fail or z-pass two-sided stencil. Per-field
    /// reasons next to each choice (the twin of umbra-gl's `GlState::shadow_volume_for`).
    #[allow(clippy::too_many_arguments)]
    pub fn counting_pipeline(
        &self,
        device: &wgpu::Device,
        label: &str,
        module: &wgpu::ShaderModule,
        entry: &str,
        layout: &wgpu::PipelineLayout,
        buffers: &[Option<wgpu::VertexBufferLayout<'_>>],
        zpass: bool,
        front_face: wgpu::FrontFace,
    ) -> wgpu::RenderPipeline {
        use wgpu::StencilOperation as Op;
        let counting = |depth_fail_op, pass_op| wgpu::StencilFaceState {
            // Reason: every volume fragment must reach the stencil op; the count is all we want.
            compare: wgpu::CompareFunction::Always,
            // Reason: the stencil test always passes, so this op never runs.
            fail_op: Op::Keep,
            depth_fail_op,
            pass_op,
        };
        let (front, back) = if zpass {
            // z-pass: count the volume faces IN FRONT of the visible sample: entering (front
            // face) +1, leaving (back face) -1. Wrong when the camera is inside a volume.
            (counting(Op::Keep, Op::IncrementWrap), counting(Op::Keep, Op::DecrementWrap))
        } else {
            // z-fail: count the faces BEHIND the sample: a back face behind it means the ray
            // leaves a volume it was inside of (+1), a front face behind it that it enters one
            // after the sample (-1). Correct wherever the camera is, given closed volumes.
            (counting(Op::DecrementWrap, Op::Keep), counting(Op::IncrementWrap, Op::Keep))
        };
        let targets: Vec<Option<wgpu::ColorTargetState>> = self
            .formats
            .color
            .iter()
            .map(|f| {
                f.map(|format| wgpu::ColorTargetState {
                    format,
                    blend: None,
                    // Reason: the volume pass only counts; the caller's colour is untouched.
                    write_mask: wgpu::ColorWrites::empty(),
                })
            })
            .collect();
        device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some(label),
            layout: Some(layout),
            vertex: wgpu::VertexState {
                module,
                entry_point: Some(entry),
                compilation_options: Default::default(),
                buffers,
            },
            primitive: wgpu::PrimitiveState {
                topology: wgpu::PrimitiveTopology::TriangleList,
                strip_index_format: None,
                // Reason: volume triangles are counter-clockwise seen from outside the volume
                // (cpu-silhouette's dark caps are drawn with Cw, which reverses their winding).
                front_face,
                // Reason: both faces are counted with different ops in one pass (two-sided
                // stencil); culling would drop half of them.
                cull_mode: None,
                // Reason: nothing of a volume may be clipped by the near or far plane, or the
                // count misses faces: vertices at infinity land exactly on the far plane and
                // rounding could put them beyond it; parts in front of the near plane are
                // clamped to the near depth and still counted (depth clamp).
                unclipped_depth: true,
                polygon_mode: wgpu::PolygonMode::Fill,
                conservative: false,
            },
            depth_stencil: Some(wgpu::DepthStencilState {
                format: self.formats.depth_stencil,
                // Reason: the volumes are invisible; the scene's depth must stay intact for the
                // lighting pass (depth EQUAL).
                depth_write_enabled: Some(false),
                // Reason: STRICTLY nearer (reversed-Z: GREATER): a light cap pushed to the far
                // plane (depth exactly 0) must FAIL at every sample, background included (depth
                // cleared to 0: 0 > 0 is false), so z-fail counts it consistently everywhere.
                depth_compare: Some(wgpu::CompareFunction::Greater),
                stencil: wgpu::StencilState {
                    front,
                    back,
                    read_mask: 0xFF,
                    // Reason: all 8 bits count; wrapping makes the count exact modulo 256.
                    write_mask: 0xFF,
                },
                // Reason: an offset would move volume faces relative to the scene depth and
                // break exactness; self-shadowing is solved by pushing light caps to the far plane.
                bias: wgpu::DepthBiasState::default(),
            }),
            multisample: wgpu::MultisampleState {
                count: self.sample_count,
                mask: !0,
                alpha_to_coverage_enabled: false,
            },
            // Reason: always a fragment stage, even without colour targets: it writes the
            // depth the test sees, NaN made far (shaders/volume.wgsl, fs_volume).
            fragment: Some(wgpu::FragmentState {
                module,
                entry_point: Some(if self.sample_count > 1 { "fs_volume_per_sample" } else { "fs_volume" }),
                compilation_options: Default::default(),
                targets: &targets,
            }),
            multiview_mask: None,
            cache: None,
        })
    }
}
