//! The host API: [`ShadowVolumes`] counts one method's shadow volumes into the stencil of a
//! render pass the caller owns, in the style of wgpu libraries (glyphon, egui-wgpu): made once
//! for the caller's pass formats ([`ShadowVolumes::new`]), fed per frame
//! ([`ShadowVolumes::prepare`]: compute passes and uploads into the caller's encoder), drawn
//! into the caller's render pass ([`ShadowVolumes::draw`]). The library owns its pipelines and
//! buffers; the host owns device, queue, encoder, pass and depth-stencil attachment.
//!
//! # What the caller must provide
//!
//! * **A device** with [`crate::device::volume_features`] (`DEPTH_CLIP_CONTROL`,
//!   `CLIP_DISTANCES`), storage buffers in vertex shaders and compute shaders (every Vulkan,
//!   Metal and DX12 adapter; checked in [`ShadowVolumes::new`]).
//! * **Pass formats** ([`PassFormats`]): the colour formats of the render pass the volumes are
//!   drawn in (the volume pipelines write no colour but must match the pass) and its
//!   depth-stencil format, which must have a stencil aspect (`Depth24PlusStencil8`,
//!   `Depth32FloatStencil8`, `Stencil8` is refused: the volumes need the depth); the pass's
//!   sample count.
//! * **The scene's depth, drawn exactly as umbra would** in that depth-stencil attachment
//!   before the volumes: reversed-Z with an infinite far plane (depth 1 at the near plane, 0 at
//!   infinity, cleared to 0, nearer = `Greater`), the positions of the [`SceneGpu`] (the same
//!   `f32` bits; [`SceneGpu::position_buffer`] is a vertex buffer a host can draw from)
//!   transformed by exactly [`View::clip_from_world_f32`] as `clip_from_world * vec4(p, 1.0)`
//!   in a vertex shader whose `@builtin(position)` is `@invariant`, with normal clipping. Any
//!   other transform gives wrong counts along every silhouette and cap. [`View::from_camera`]
//!   builds the matrix from umbra's [`Camera`]; [`View::from_matrix`] takes the host's own
//!   (it must be reversed-Z and infinite-far).
//! * **Per light, a render pass** whose depth-stencil attachment holds that depth, with the
//!   depth loaded (read-only is enough) and the stencil cleared to
//!   [`LightPlan::stencil_clear`] (0, or the eye's winding number when z-pass counts from
//!   it, or 1 for a shadow map's resolve), in which [`ShadowVolumes::draw`] runs. Afterwards
//!   "lit by this light" is `stencil == 0` ([`ShadowVolumes::lit_stencil_test`]), which the
//!   caller's lighting pass tests with stencil reference 0.
//!
//! Nothing else of the caller's is touched: the draws bind their own pipelines and bind
//! groups (groups 0 and 1) and leave the pass's viewport, scissor, blend constant and stencil
//! reference as they were (the counting stencil test is `Always`).

use glam::{DMat4, DVec4};
use umbra_geom::camera::{near_pyramid_points, to_f32_cols, Camera, DepthConvention};
use umbra_geom::clearance::scene_clip_box;
use umbra_geom::Light;

use crate::error::{scoped, WgpuError};
use crate::methods::{create_method, Method, MethodKind};
use crate::scene::SceneGpu;

/// Bytes of one light's uniform slot (the largest `min_uniform_buffer_offset_alignment`
/// wgpu allows is 256).
pub(crate) const LIGHT_SLOT_BYTES: u64 = 256;

/// The formats of the render pass [`ShadowVolumes::draw`] draws into.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PassFormats {
    /// The pass's colour attachments, in order (`None` for an unused slot). The volumes write
    /// none of them.
    pub color: Vec<Option<wgpu::TextureFormat>>,
    /// The pass's depth-stencil attachment: a depth format with 8 stencil bits.
    pub depth_stencil: wgpu::TextureFormat,
}

/// How the volumes count, per light.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ZMode {
    /// z-pass for every light, whatever the eye's position (wrong when the camera is inside a
    /// shadow volume).
    pub zpass: bool,
    /// z-pass for each light whose volumes provably leave the eye's near pyramid alone
    /// ([`umbra_geom::clearance`]), z-fail for the others. Exact like z-fail, cheaper (no
    /// caps, volumes clipped to the scene box). Counting methods only.
    pub auto_zpass: bool,
}

impl Default for ZMode {
    /// Automatic z-pass (exact).
    fn default() -> Self {
        Self { zpass: false, auto_zpass: true }
    }
}

/// The camera of a frame: reversed-Z, infinite far plane.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct View {
    clip_from_world: DMat4,
    world_from_clip: DMat4,
    eye: [f64; 3],
}

impl View {
    /// umbra's camera for a `width x height` frame:
    /// `camera.clip_from_world_in(width / height, DepthConvention::ReversedZ)`.
    pub fn from_camera(camera: &Camera, width: u32, height: u32) -> Result<Self, WgpuError> {
        camera.validate()?;
        if width == 0 || height == 0 {
            return Err(WgpuError::InvalidParams(format!("frame size {width}x{height}")));
        }
        let m = camera.clip_from_world_in(width as f64 / height as f64, DepthConvention::ReversedZ);
        Self::from_matrix(m.to_cols_array_2d(), camera.eye)
    }

    /// A host's own matrix (column-major, `m[column][row]`), reversed-Z with an infinite far
    /// plane (a point at infinity has clip z = 0), and its eye position. Must be finite and
    /// invertible.
    pub fn from_matrix(clip_from_world: [[f64; 4]; 4], eye: [f64; 3]) -> Result<Self, WgpuError> {
        let m = DMat4::from_cols_array_2d(&clip_from_world);
        let inverse = m.inverse();
        if !m.is_finite() || !inverse.is_finite() || !eye.iter().all(|c| c.is_finite()) {
            return Err(WgpuError::InvalidParams(format!(
                "view matrix {clip_from_world:?} with eye {eye:?} is not finite and invertible"
            )));
        }
        Ok(Self { clip_from_world: m, world_from_clip: inverse, eye })
    }

    /// The matrix the shaders use (f32 columns): the host's depth pass must use exactly this.
    pub fn clip_from_world_f32(&self) -> [f32; 16] {
        to_f32_cols(&self.clip_from_world)
    }

    /// The f64 matrix.
    pub fn clip_from_world(&self) -> DMat4 {
        self.clip_from_world
    }

    /// The eye (world space).
    pub fn eye(&self) -> [f64; 3] {
        self.eye
    }
}

/// One frame's lights as [`ShadowVolumes::prepare`] takes them.
#[derive(Clone, Copy, Debug)]
pub struct VolumeFrame<'a> {
    /// The camera the caller's depth was drawn with.
    pub view: &'a View,
    /// The lights (w = 1 point, w = 0 directional, light coming FROM xyz), in the order
    /// [`ShadowVolumes::draw`] indexes them.
    pub lights: &'a [Light],
    /// How the volumes count.
    pub zmode: ZMode,
}

/// What [`ShadowVolumes::prepare`] decided for one light: how its volumes count and what the
/// stencil of its pass must be cleared to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LightPlan {
    /// Counted z-pass (forced, or chosen where provably exact) rather than z-fail.
    pub zpass: bool,
    /// The value the caller's pass must clear the stencil to before [`ShadowVolumes::draw`]:
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

impl Common {
    fn new(device: &wgpu::Device, formats: PassFormats, sample_count: u32) -> Self {
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
    fn reserve(&mut self, device: &wgpu::Device, slots: usize) {
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

/// The bind group layout entry of a buffer of type `ty` at `binding`.
fn buffer_entry(
    binding: u32,
    visibility: wgpu::ShaderStages,
    ty: wgpu::BufferBindingType,
    has_dynamic_offset: bool,
) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Buffer { ty, has_dynamic_offset, min_binding_size: None },
        count: None,
    }
}

/// The bind group layout entry of a uniform buffer at `binding` (`dynamic`: read at a
/// dynamic offset, one slot of [`uniform_slots`]).
pub(crate) fn uniform_entry(binding: u32, visibility: wgpu::ShaderStages, dynamic: bool) -> wgpu::BindGroupLayoutEntry {
    buffer_entry(binding, visibility, wgpu::BufferBindingType::Uniform, dynamic)
}

/// A uniform buffer of `slots` slots of [`LIGHT_SLOT_BYTES`] and its bind group for `layout`:
/// binding 0 sees `binding_bytes` from the dynamic offset of a slot.
pub(crate) fn uniform_slots(
    device: &wgpu::Device,
    label: &str,
    layout: &wgpu::BindGroupLayout,
    slots: usize,
    binding_bytes: u64,
) -> (wgpu::Buffer, wgpu::BindGroup) {
    let buffer = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: LIGHT_SLOT_BYTES * slots as u64,
        usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some(label),
        layout,
        entries: &[wgpu::BindGroupEntry {
            binding: 0,
            resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                buffer: &buffer,
                offset: 0,
                size: wgpu::BufferSize::new(binding_bytes),
            }),
        }],
    });
    (buffer, group)
}

/// A compute pipeline: `entry` of `module` with `layout`.
pub(crate) fn compute_pipeline(
    device: &wgpu::Device,
    label: &str,
    layout: &wgpu::PipelineLayout,
    module: &wgpu::ShaderModule,
    entry: &str,
) -> wgpu::ComputePipeline {
    device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some(label),
        layout: Some(layout),
        module,
        entry_point: Some(entry),
        compilation_options: Default::default(),
        cache: None,
    })
}

/// The bind group layout entry of a storage buffer at `binding`.
pub(crate) fn storage_entry(
    binding: u32,
    visibility: wgpu::ShaderStages,
    read_only: bool,
) -> wgpu::BindGroupLayoutEntry {
    buffer_entry(binding, visibility, wgpu::BufferBindingType::Storage { read_only }, false)
}

/// A bind group of whole buffers at bindings 0, 1, ...
pub(crate) fn buffers_group(
    device: &wgpu::Device,
    label: &str,
    layout: &wgpu::BindGroupLayout,
    buffers: &[&wgpu::Buffer],
) -> wgpu::BindGroup {
    let entries: Vec<wgpu::BindGroupEntry<'_>> = buffers
        .iter()
        .enumerate()
        .map(|(i, b)| wgpu::BindGroupEntry { binding: i as u32, resource: b.as_entire_binding() })
        .collect();
    device.create_bind_group(&wgpu::BindGroupDescriptor { label: Some(label), layout, entries: &entries })
}

/// Workgroups (x, y) of 256 invocations covering `items` (a dimension holds at most 65,535;
/// the shaders index `gid.x + gid.y * groups.x * 256`, volume.wgsl's `umbra_item`).
pub(crate) fn dispatch_size(items: u32) -> (u32, u32) {
    let groups = items.div_ceil(256);
    let x = groups.clamp(1, 65_535);
    (x, groups.div_ceil(x))
}

/// One shadow method's volumes, counted into the stencil of the caller's render pass. See the
/// module documentation for what the caller provides.
pub struct ShadowVolumes {
    method: Box<dyn Method>,
    common: Common,
    plans: Vec<LightPlan>,
}

impl ShadowVolumes {
    /// The pipelines of `method` (a name of [`crate::method_names`]) for render passes of
    /// `formats` with `sample_count` samples. Checks the device's features first.
    pub fn new(
        device: &wgpu::Device,
        formats: &PassFormats,
        sample_count: u32,
        method: &str,
    ) -> Result<Self, WgpuError> {
        Self::with_method(device, formats, sample_count, |device, common| create_method(device, common, method))
    }

    fn with_method(
        device: &wgpu::Device,
        formats: &PassFormats,
        sample_count: u32,
        make: impl FnOnce(&wgpu::Device, &Common) -> Result<Box<dyn Method>, WgpuError>,
    ) -> Result<Self, WgpuError> {
        crate::device::check_features(
            "the caller's device",
            device.features(),
            crate::device::volume_features(),
            "shadow volumes (depth clamp, near-plane clip of light caps)",
        )?;
        if !formats.depth_stencil.has_stencil_aspect() || !formats.depth_stencil.has_depth_aspect() {
            return Err(WgpuError::InvalidParams(format!(
                "depth-stencil format {:?} needs both a depth and a stencil aspect",
                formats.depth_stencil
            )));
        }
        if !matches!(sample_count, 1 | 2 | 4 | 8 | 16) {
            return Err(WgpuError::InvalidParams(format!("sample count {sample_count}")));
        }
        scoped(device, "ShadowVolumes::new", || {
            let common = Common::new(device, formats.clone(), sample_count);
            let method = make(device, &common)?;
            Ok(Self { method, common, plans: Vec::new() })
        })
    }

    /// A `shadow-map-cube` with explicit options (bias, PCF), for passes of `formats`.
    pub fn shadow_map(
        device: &wgpu::Device,
        formats: &PassFormats,
        sample_count: u32,
        config: crate::methods::shadow_map::ShadowMapConfig,
    ) -> Result<Self, WgpuError> {
        Self::with_method(device, formats, sample_count, |device, common| {
            crate::methods::create_shadow_map(device, common, config)
        })
    }

    /// The method's registry name.
    pub fn method_name(&self) -> &'static str {
        self.method.name()
    }

    /// Whether the method is exact by construction (the shadow-volume methods) rather than a
    /// shadow map.
    pub fn counts_volumes(&self) -> bool {
        matches!(self.method.kind(), MethodKind::Counting { .. })
    }

    /// Bytes of GPU memory the method holds (buffers, textures), light slots included.
    pub fn gpu_bytes(&self) -> u64 {
        self.method.gpu_bytes()
    }

    /// Per frame, before the caller's passes: the per-light work of every light of `frame`
    /// (uniforms through `queue`, compute passes and the shadow maps' depth passes into
    /// `encoder`), and for each light how it counts ([`LightPlan`], also
    /// [`ShadowVolumes::plans`]). Per-mesh preprocessing happens on the first frame of a scene.
    /// Each light keeps its own outputs until the next `prepare`, so the caller may draw the
    /// lights in any order afterwards.
    pub fn prepare(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        scene: &SceneGpu,
        frame: &VolumeFrame<'_>,
    ) -> Result<&[LightPlan], WgpuError> {
        let VolumeFrame { view, lights, zmode } = *frame;
        for (i, l) in lights.iter().enumerate() {
            umbra_geom::check_light(i, l)?;
        }
        scoped(device, "ShadowVolumes::prepare", || {
            if self.method.prepared_scene() != Some(scene.id()) {
                self.method.prepare_scene(device, scene, &self.common)?;
            }
            self.common.reserve(device, lights.len().max(1));
            let near_pyramid = near_pyramid_points(&view.world_from_clip, view.eye, DepthConvention::ReversedZ);
            let planes = scene.bounds().map(|b| scene_clip_box(b, view.eye));
            self.plans.clear();
            for (slot, &light) in lights.iter().enumerate() {
                let plan = self.plan(scene, &near_pyramid, light, zmode);
                // z-pass volumes clipped to the scene box (clip distances 1-6); z-fail ones not.
                let scene_clip = plan.zpass && planes.is_some() && self.counts_volumes();
                let mut scene_planes = [[0f32; 4]; 6];
                if let (Some(planes), true) = (planes, scene_clip) {
                    // A world plane p (p . (X, W) >= 0 inside) in clip space: (clip_from_world)^-T p.
                    let clip_from_plane = view.world_from_clip.transpose();
                    for (out, p) in scene_planes.iter_mut().zip(planes) {
                        *out = (clip_from_plane * DVec4::from_array(p)).to_array().map(|c| c as f32);
                    }
                }
                let data = LightSlot {
                    clip_from_world: view.clip_from_world_f32(),
                    light,
                    scene_planes,
                    far_clip_z: DepthConvention::ReversedZ.far_clip_z(),
                    scene_clip: scene_clip as u32,
                    vertices_per_cap: if light[3] != 0.0 { 6 } else { 3 },
                    triangles: scene.triangle_count() as u32,
                    records: 0,
                    max_mult: 0,
                    vertices: scene.mesh().positions.len() as u32,
                    pad: 0,
                    first_light_cap: 0,
                    first_dark_cap: 0,
                    pad2: [0; 2],
                };
                let light_frame = crate::methods::LightFrame { slot, plan, data };
                self.method.prepare_light(device, queue, encoder, scene, &self.common, &light_frame)?;
                self.plans.push(plan);
            }
            Ok(())
        })?;
        Ok(&self.plans)
    }

    /// How light `light` of the last [`ShadowVolumes::prepare`] counts.
    pub fn plans(&self) -> &[LightPlan] {
        &self.plans
    }

    /// z-pass where it is exact, z-fail elsewhere (the twin of umbra-gl's volume pass): with
    /// the eye's near pyramid inside `W0` volumes and crossed by none of their faces, z-pass
    /// counts `W(p) - W0`, so the stencil starts at `W0`.
    fn plan(&self, scene: &SceneGpu, near_pyramid: &[[f64; 3]], light: Light, zmode: ZMode) -> LightPlan {
        let (zpass, stencil_clear) = match self.method.kind() {
            MethodKind::Resolve => (false, 1),
            MethodKind::Counting { .. } if zmode.zpass => (true, 0),
            MethodKind::Counting { silhouette_sides } if zmode.auto_zpass => {
                let adjacency = silhouette_sides.then(|| scene.adjacency().as_ref());
                match scene.clearance().near_winding(scene.mesh(), adjacency, near_pyramid, light) {
                    Some(w0) => (true, w0 % 256),
                    None => (false, 0),
                }
            }
            MethodKind::Counting { .. } => (false, 0),
        };
        LightPlan { zpass, stencil_clear }
    }

    /// Draws light `light`'s volumes (an index into the `lights` of the last
    /// [`ShadowVolumes::prepare`]) into the caller's render pass, whose stencil was cleared to
    /// that light's [`LightPlan::stencil_clear`] and whose depth holds the scene (see the
    /// module documentation). A light index out of range draws nothing.
    pub fn draw(&self, pass: &mut wgpu::RenderPass<'_>, light: usize) {
        if let Some(plan) = self.plans.get(light) {
            self.method.draw(pass, &self.common, light, *plan);
        }
    }

    /// The side and cap vertex counts the GPU decided for light `light` in the last frame
    /// (methods that compact their volume on the GPU, `cs-silhouette`; `None` for the others):
    /// a readback that waits for the GPU, for tests and statistics.
    pub fn gpu_counts(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        light: usize,
    ) -> Result<Option<(u32, u32)>, WgpuError> {
        let readback = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("umbra volume counts"),
            size: 32,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut encoder =
            device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("umbra counts") });
        if !self.method.copy_counts(&mut encoder, light, &readback) {
            return Ok(None);
        }
        queue.submit([encoder.finish()]);
        let words: Vec<u32> = crate::readback::read_buffer(device, &readback, "volume counts")?;
        Ok(Some((words[0], words[4])))
    }

    /// The stencil test of "lit" after [`ShadowVolumes::draw`]: `Equal` against reference 0
    /// (set `pass.set_stencil_reference(0)`), nothing written.
    pub fn lit_stencil_test() -> wgpu::StencilFaceState {
        wgpu::StencilFaceState {
            compare: wgpu::CompareFunction::Equal,
            fail_op: wgpu::StencilOperation::Keep,
            depth_fail_op: wgpu::StencilOperation::Keep,
            pass_op: wgpu::StencilOperation::Keep,
        }
    }
}
