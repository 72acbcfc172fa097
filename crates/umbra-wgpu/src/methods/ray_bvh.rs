//! `ray-bvh` on wgpu: one shadow ray per view sample through a BVH of the scene, the twin of
//! umbra-gl's `ray-bvh` (the same BVH, [`umbra_geom::ray_bvh`], built on the CPU once per scene
//! and uploaded once; the same walk and watertight test, shaders/ray_bvh.wgsl, which
//! umbra-three's WebGPU path shares; the resolve entry: shaders/ray_bvh_resolve.wgsl).
//!
//! The rays are traced where the decision is resolved into the caller's stencil (cleared to
//! 1, 0 where the ray meets nothing), like the shadow maps' resolve: the scene drawn with depth
//! EQUAL against the caller's depth gives each pixel's visible sample, its world position and
//! triangle id (`primitive_index`: the device needs [`wgpu::Features::PRIMITIVE_INDEX`]). The
//! host API's protocol hands a method no frame size before the caller's passes, so there is no
//! compute pass over the samples here; and no pass to resume a walk in: one fragment walks at
//! most [`ray_bvh::WGSL_BUDGET`] steps (lavapipe's loop limit, see the shader).
//!
//! Per scene: the BVH's two storage buffers and a uniform of the eps; per light: the light slot;
//! in the caller's pass, the resolve draw.

use umbra_geom::ray_bvh::{self, RayBvh};

use crate::builders::{storage_entry, uniform_entry};
use crate::common::{Common, LightPlan, RESOLVE_VERTEX};
use crate::error::WgpuError;
use crate::methods::method::{LightFrame, Method, MethodKind};
use crate::scene::{buffer_init, SceneGpu, SceneId};

/// Registry name.
pub const NAME: &str = "ray-bvh";

const VOLUME: &str = include_str!("../shaders/volume.wgsl");
const WALK: &str = include_str!("../shaders/ray_bvh.wgsl");
const SHADER: &str = include_str!("../shaders/ray_bvh_resolve.wgsl");

/// The shader's `Params`.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Params {
    eps: f32,
    eps_near: f32,
    nodes: u32,
    pad: u32,
}

struct SceneObjects {
    group: wgpu::BindGroup,
    bvh_bytes: u64,
    build_ms: f64,
    nodes: u32,
    depth: usize,
    positions: wgpu::Buffer,
    indices: (wgpu::Buffer, u32),
}

/// See the module documentation.
pub struct RayBvhMethod {
    layout: wgpu::BindGroupLayout,
    pipeline: wgpu::RenderPipeline,
    prepared: Option<SceneId>,
    scene: Option<SceneObjects>,
}

impl RayBvhMethod {
    /// The resolve pipeline for the pass formats of `common`; the device must offer
    /// `PRIMITIVE_INDEX`.
    pub(crate) fn new(device: &wgpu::Device, common: &Common) -> Result<Self, WgpuError> {
        crate::device::check_features(
            "the caller's device",
            device.features(),
            wgpu::Features::PRIMITIVE_INDEX,
            "ray-bvh (the triangle id of each sample, to skip its own triangle)",
        )?;
        let constants = ray_bvh::wgsl_constants();
        let module = Common::module(
            device,
            "ray_bvh.wgsl",
            &["enable clip_distances;\nenable primitive_index;", VOLUME, RESOLVE_VERTEX, &constants, WALK, SHADER],
        );
        let fragment = wgpu::ShaderStages::FRAGMENT;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("ray-bvh"),
            entries: &[
                storage_entry(0, fragment, true),
                storage_entry(1, fragment, true),
                storage_entry(2, fragment, true),
                storage_entry(3, fragment, true),
                uniform_entry(4, fragment, false),
            ],
        });
        let pl = common.pipeline_layout(device, "ray-bvh resolve", &[&layout]);
        let pipeline = common.surface_resolve_pipeline(device, "ray-bvh resolve", &pl, &module, "fs_resolve");
        Ok(Self { layout, pipeline, prepared: None, scene: None })
    }

    /// The prepared scene's BVH figures for `bench --json` (build ms, bytes, nodes, depth).
    pub(crate) fn figures(&self) -> Vec<(&'static str, f64)> {
        self.scene.as_ref().map_or(Vec::new(), |s| {
            vec![
                ("bvh_build_ms", s.build_ms),
                ("bvh_bytes", s.bvh_bytes as f64),
                ("bvh_nodes", f64::from(s.nodes)),
                ("bvh_depth", s.depth as f64),
            ]
        })
    }
}

fn vec4_bytes(v: &[[f32; 4]]) -> Vec<u8> {
    // At least one vec4: a binding of 0 bytes is invalid.
    let mut out: Vec<u8> = bytemuck::cast_slice(v).to_vec();
    if out.is_empty() {
        out.resize(16, 0);
    }
    out
}

impl Method for RayBvhMethod {
    fn name(&self) -> &'static str {
        NAME
    }

    fn kind(&self) -> MethodKind {
        MethodKind::Resolve
    }

    fn prepared_scene(&self) -> Option<SceneId> {
        self.prepared
    }

    fn prepare_scene(&mut self, device: &wgpu::Device, scene: &SceneGpu, _common: &Common) -> Result<(), WgpuError> {
        let mesh = scene.mesh();
        let started = std::time::Instant::now();
        let bvh: RayBvh = ray_bvh::build(&mesh.positions, &mesh.triangles);
        let build_ms = started.elapsed().as_secs_f64() * 1e3;
        let node_bytes = vec4_bytes(&bvh.nodes);
        let triangle_bytes = vec4_bytes(&bvh.triangles);
        let storage = wgpu::BufferUsages::STORAGE;
        let nodes = buffer_init(device, "ray-bvh nodes", &node_bytes, storage)?;
        let triangles = buffer_init(device, "ray-bvh triangles", &triangle_bytes, storage)?;
        let eps = ray_bvh::segment_epsilon(&mesh.positions) as f32;
        let params = Params { eps, eps_near: 0.5 * eps, nodes: bvh.node_count() as u32, pad: 0 };
        let params = buffer_init(device, "ray-bvh params", bytemuck::bytes_of(&params), wgpu::BufferUsages::UNIFORM)?;
        let group = crate::builders::buffers_group(
            device,
            "ray-bvh",
            &self.layout,
            &[&nodes, &triangles, scene.position_buffer(), scene.index_buffer(), &params],
        );
        self.scene = Some(SceneObjects {
            group,
            bvh_bytes: nodes.size() + triangles.size(),
            build_ms,
            nodes: bvh.node_count() as u32,
            depth: bvh.depth,
            positions: scene.position_buffer().clone(),
            indices: (scene.index_buffer().clone(), scene.index_count()),
        });
        self.prepared = Some(scene.id());
        Ok(())
    }

    fn prepare_light(
        &mut self,
        _device: &wgpu::Device,
        queue: &wgpu::Queue,
        _encoder: &mut wgpu::CommandEncoder,
        _scene: &SceneGpu,
        common: &Common,
        frame: &LightFrame,
    ) -> Result<(), WgpuError> {
        if self.scene.is_none() {
            return Err(WgpuError::InvalidParams(format!("{NAME}: prepare_light before prepare_scene")));
        }
        common.write_slot(queue, frame.slot, &frame.data);
        Ok(())
    }

    fn draw(&self, pass: &mut wgpu::RenderPass<'_>, common: &Common, slot: usize, _plan: LightPlan) {
        let Some(s) = &self.scene else { return };
        if s.indices.1 == 0 {
            return;
        }
        common.bind_slot_render(pass, slot);
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(1, &s.group, &[]);
        pass.set_vertex_buffer(0, s.positions.slice(..));
        pass.set_index_buffer(s.indices.0.slice(..), wgpu::IndexFormat::Uint32);
        pass.draw_indexed(0..s.indices.1, 0, 0..1);
    }

    fn gpu_bytes(&self) -> u64 {
        self.scene.as_ref().map_or(0, |s| s.bvh_bytes)
    }

    fn scene_figures(&self) -> Vec<(&'static str, f64)> {
        self.figures()
    }
}
