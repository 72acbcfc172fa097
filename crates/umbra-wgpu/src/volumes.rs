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
//!   builds the matrix from umbra's [`Camera`](umbra_geom::camera::Camera); [`View::from_matrix`] takes the host's own
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

use glam::DVec4;
use umbra_geom::camera::{near_pyramid_points, DepthConvention};
use umbra_geom::clearance::scene_clip_box;
use umbra_geom::Light;

use crate::common::{Common, LightSlot};
use crate::error::{scoped, WgpuError};
use crate::methods::{create_method, Method, MethodKind};
use crate::scene::SceneGpu;

pub use crate::common::{LightPlan, PassFormats};
pub use crate::view::{View, VolumeFrame, ZMode};

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

    /// Whether the method culls and clamps its volumes against the receivers when
    /// [`VolumeFrame::receivers`] gives it the caller's depth (`cpu-silhouette`).
    pub fn culls_volumes(&self) -> bool {
        self.method.culls_volumes()
    }

    /// Count the fragments of the method's own passes (the receiver map's scatter) from the
    /// next [`ShadowVolumes::prepare`] on, where the device has `PIPELINE_STATISTICS_QUERY`
    /// (each count waits for its pass).
    pub fn set_count_fragments(&mut self, on: bool) {
        self.method.set_count_fragments(on);
    }

    /// The fragments light `light`'s own passes shaded in the last counted
    /// [`ShadowVolumes::prepare`] (the receiver map's scatter of a culled volume); `None` when
    /// not counted, not culled or not countable. The volume pass itself is the caller's to
    /// count (it owns the pass; [`crate::Renderer::set_count_volume_fragments`] does).
    pub fn own_fragments(&self, light: usize) -> Option<u64> {
        self.method.own_fragments(light)
    }

    /// What light `light`'s volume drew in the last [`ShadowVolumes::prepare`]: triangles kept,
    /// silhouette edges, whether culled and clamped. `None` for methods that decide their
    /// volume on the GPU.
    pub fn drawn_volume(&self, light: usize) -> Option<crate::methods::DrawnVolume> {
        self.method.drawn_volume(light)
    }

    /// Bytes of GPU memory the method holds (buffers, textures), light slots included.
    pub fn gpu_bytes(&self) -> u64 {
        self.method.gpu_bytes()
    }

    /// Figures of the method's per-scene preprocessing, `(key, value)` (ray-bvh: its BVH's
    /// `bvh_build_ms`, `bvh_bytes`, `bvh_nodes`, `bvh_depth`); empty for most methods.
    pub fn scene_figures(&self) -> Vec<(&'static str, f64)> {
        self.method.scene_figures()
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
        let VolumeFrame { view, lights, zmode, receivers } = *frame;
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
                let receivers = receivers.filter(|_| self.method.culls_volumes());
                let light_frame = crate::methods::LightFrame { view, receivers, slot, plan, data };
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
        Ok(self.read_counts(device, queue, light)?.map(|w| (w[0], w[4])))
    }

    /// What light `light`'s volume drew in the last frame: [`ShadowVolumes::drawn_volume`]
    /// where the CPU knows it, otherwise read back from the GPU's counts (`cs-silhouette`; a
    /// wait, for tests and statistics); `None` for methods that know neither.
    pub fn read_drawn_volume(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        light: usize,
    ) -> Result<Option<crate::methods::DrawnVolume>, WgpuError> {
        if let Some(d) = self.method.drawn_volume(light) {
            return Ok(Some(d));
        }
        Ok(self.read_counts(device, queue, light)?.and_then(|w| self.method.drawn_from_counts(light, &w)))
    }

    /// The words of [`Method::copy_counts`] for `light`, read back.
    fn read_counts(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        light: usize,
    ) -> Result<Option<Vec<u32>>, WgpuError> {
        let readback = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("umbra volume counts"),
            size: 48,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut encoder =
            device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("umbra counts") });
        if !self.method.copy_counts(&mut encoder, light, &readback) {
            return Ok(None);
        }
        queue.submit([encoder.finish()]);
        Ok(Some(crate::readback::read_buffer(device, &readback, "volume counts")?))
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
