//! `cpu-silhouette` on wgpu: silhouette shadow volumes built on the CPU every frame.
//!
//! Paper 001, Sections 2.2-2.3 (deterministic edge multiplicity with a reference edge,
//! Alg. 2-4; sides extruded with Eq. 2; caps oriented by the same test), via
//! [`umbra_geom::silhouette::extract_indexed`] (rayon-parallel, every triangle oriented once,
//! orientations summed per edge through the mesh's [`umbra_geom::silhouette::TriangleSlots`]):
//! the twin of umbra-gl's `cpu-silhouette`. Rust never contracts `a * b + c`, so the CPU's
//! orientations are the same bits wherever they are read.
//!
//! Per light and frame: extract into a reused [`IndexedVolume`], expand it to its very
//! vertices ([`IndexedVolume::expand_into`]: sides, light caps, dark caps as homogeneous world
//! positions) and upload them into the light's own buffer (grown geometrically, never
//! shrunk); in the caller's pass ONE draw with one vertex shader (shaders/cpu_draw.wgsl), so
//! a vertex shared by a side and a cap is transformed by the same code into the same bits.
//! umbra-gl draws the caps from the mesh's positions with 12 bytes of indices per cap and
//! relies on GLSL's `invariant`; WGSL has no such guarantee, so wgpu pays 48 (directional) or
//! 96 (point light) bytes per cap.

use umbra_geom::silhouette::{extract_indexed, IndexedVolume, VolumeGeometry};

use crate::common::{Common, LightPlan};
use crate::error::WgpuError;
use crate::methods::method::{LightFrame, Method, MethodKind};
use crate::scene::{check_size, SceneGpu, SceneId};

/// Registry name.
pub const NAME: &str = "cpu-silhouette";

const VOLUME: &str = include_str!("../shaders/volume.wgsl");
const DRAW: &str = include_str!("../shaders/cpu_draw.wgsl");

/// A buffer rewritten every frame, grown geometrically and never shrunk.
struct StreamBuffer {
    buffer: Option<wgpu::Buffer>,
}

impl StreamBuffer {
    /// Uploads `bytes` at offset 0 (a bigger buffer when it does not fit).
    fn write(&mut self, device: &wgpu::Device, queue: &wgpu::Queue, bytes: &[u8]) -> Result<(), WgpuError> {
        let needed = (bytes.len() as u64).max(16).next_multiple_of(4);
        if self.buffer.as_ref().is_none_or(|b| b.size() < needed) {
            let size = needed.next_power_of_two();
            check_size(device, "cpu-silhouette volume", size)?;
            self.buffer = Some(device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("cpu-silhouette volume"),
                size,
                usage: wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }));
        }
        if let Some(b) = &self.buffer {
            queue.write_buffer(b, 0, bytes);
        }
        Ok(())
    }

    fn bytes(&self) -> u64 {
        self.buffer.as_ref().map_or(0, wgpu::Buffer::size)
    }
}

/// One light's volume.
struct PerLight {
    indexed: IndexedVolume,
    expanded: VolumeGeometry,
    /// Sides, light caps, dark caps, one after the other.
    vertices: Vec<[f32; 4]>,
    buffer: StreamBuffer,
    count: u32,
}

/// See the module documentation.
pub struct CpuSilhouette {
    /// [z-fail, z-pass].
    pipelines: [wgpu::RenderPipeline; 2],
    prepared: Option<SceneId>,
    lights: Vec<PerLight>,
}

impl CpuSilhouette {
    /// Pipelines for the pass formats of `common`.
    pub(crate) fn new(device: &wgpu::Device, common: &Common) -> Self {
        let module = Common::module(device, "cpu-silhouette cpu_draw.wgsl", &["enable clip_distances;", VOLUME, DRAW]);
        let layout = common.pipeline_layout(device, "cpu-silhouette", &[]);
        let vec4 = [wgpu::VertexAttribute { format: wgpu::VertexFormat::Float32x4, offset: 0, shader_location: 0 }];
        let buffers = [Some(wgpu::VertexBufferLayout {
            array_stride: 16,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &vec4,
        })];
        let pipelines = [false, true].map(|zpass| {
            let label = "cpu-silhouette volume";
            common.counting_pipeline(
                device,
                label,
                &module,
                "vs_volume",
                &layout,
                &buffers,
                zpass,
                wgpu::FrontFace::Ccw,
            )
        });
        Self { pipelines, prepared: None, lights: Vec::new() }
    }
}

impl Method for CpuSilhouette {
    fn name(&self) -> &'static str {
        NAME
    }

    fn kind(&self) -> MethodKind {
        MethodKind::Counting { silhouette_sides: true }
    }

    fn prepared_scene(&self) -> Option<SceneId> {
        self.prepared
    }

    fn prepare_scene(&mut self, _device: &wgpu::Device, scene: &SceneGpu, _common: &Common) -> Result<(), WgpuError> {
        self.prepared = None;
        // Built once per mesh (shared through the scene): adjacency and slots.
        scene.slots()?;
        self.prepared = Some(scene.id());
        Ok(())
    }

    fn prepare_light(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        _encoder: &mut wgpu::CommandEncoder,
        scene: &SceneGpu,
        common: &Common,
        frame: &LightFrame,
    ) -> Result<(), WgpuError> {
        while self.lights.len() <= frame.slot {
            self.lights.push(PerLight {
                indexed: IndexedVolume::default(),
                expanded: VolumeGeometry::default(),
                vertices: Vec::new(),
                buffer: StreamBuffer { buffer: None },
                count: 0,
            });
        }
        let light = frame.data.light;
        let l = &mut self.lights[frame.slot];
        let caps = !frame.plan.zpass;
        extract_indexed(scene.mesh(), scene.adjacency(), scene.slots()?, light, caps, &mut l.indexed);
        l.indexed.expand_into(&scene.mesh().positions, light, &mut l.expanded);
        l.vertices.clear();
        l.vertices.extend_from_slice(&l.expanded.sides);
        l.vertices.extend_from_slice(&l.expanded.light_caps);
        l.vertices.extend_from_slice(&l.expanded.dark_caps);
        l.buffer.write(device, queue, bytemuck::cast_slice(&l.vertices))?;
        l.count = l.vertices.len() as u32;
        let mut data = frame.data;
        data.first_light_cap = l.expanded.sides.len() as u32;
        data.first_dark_cap = data.first_light_cap + l.expanded.light_caps.len() as u32;
        common.write_slot(queue, frame.slot, &data);
        Ok(())
    }

    fn draw(&self, pass: &mut wgpu::RenderPass<'_>, common: &Common, slot: usize, plan: LightPlan) {
        let Some(l) = self.lights.get(slot) else { return };
        let Some(buffer) = &l.buffer.buffer else { return };
        if l.count == 0 {
            return;
        }
        common.bind_slot_render(pass, slot);
        pass.set_pipeline(&self.pipelines[plan.zpass as usize]);
        pass.set_vertex_buffer(0, buffer.slice(..));
        pass.draw(0..l.count, 0..1);
    }

    fn gpu_bytes(&self) -> u64 {
        self.lights.iter().map(|l| l.buffer.bytes()).sum()
    }
}
