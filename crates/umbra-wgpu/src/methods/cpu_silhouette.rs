//! `cpu-silhouette` on wgpu: silhouette shadow volumes built on the CPU every frame.
//!
//! Paper 001, Sections 2.2-2.3 (deterministic edge multiplicity with a reference edge,
//! Alg. 2-4; sides extruded with Eq. 2; caps oriented by the same test), via
//! [`umbra_geom::silhouette::extract_indexed`] (rayon-parallel, every triangle oriented once,
//! orientations summed per edge through the mesh's [`umbra_geom::silhouette::TriangleSlots`]):
//! the twin of umbra-gl's `cpu-silhouette`. Rust never contracts `a * b + c`, so the CPU's
//! orientations are the same bits wherever they are read.
//!
//! Per light and frame: extract into a reused [`IndexedVolume`], upload the side quads as
//! homogeneous vertices and the caps as one oriented index triple per triangle into the
//! light's own buffers (grown geometrically, never shrunk); in the caller's pass three draws
//! with the counting state: the sides as they are, the light caps from the scene's static
//! position buffer with the light's index buffer, pushed to the far plane, and the dark caps
//! from the same positions and indices extruded in the vertex shader and drawn with the front
//! face flipped (shaders/cpu_draw.wgsl).

use umbra_geom::silhouette::{extract_indexed, has_dark_caps, IndexedVolume};

use crate::error::WgpuError;
use crate::methods::{LightFrame, Method, MethodKind};
use crate::scene::{check_size, SceneGpu, SceneId};
use crate::volumes::{Common, LightPlan};

/// Registry name.
pub const NAME: &str = "cpu-silhouette";

const VOLUME: &str = include_str!("../shaders/volume.wgsl");
const DRAW: &str = include_str!("../shaders/cpu_draw.wgsl");

/// A buffer rewritten every frame, grown geometrically and never shrunk.
struct StreamBuffer {
    buffer: Option<wgpu::Buffer>,
    usage: wgpu::BufferUsages,
    label: &'static str,
}

impl StreamBuffer {
    fn new(label: &'static str, usage: wgpu::BufferUsages) -> Self {
        Self { buffer: None, usage: usage | wgpu::BufferUsages::COPY_DST, label }
    }

    /// Uploads `bytes` at offset 0 (a bigger buffer when it does not fit).
    fn write(&mut self, device: &wgpu::Device, queue: &wgpu::Queue, bytes: &[u8]) -> Result<(), WgpuError> {
        let needed = (bytes.len() as u64).max(16).next_multiple_of(4);
        if self.buffer.as_ref().is_none_or(|b| b.size() < needed) {
            let size = needed.next_power_of_two();
            check_size(device, self.label, size)?;
            self.buffer = Some(device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(self.label),
                size,
                usage: self.usage,
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
    volume: IndexedVolume,
    sides: StreamBuffer,
    caps: StreamBuffer,
    side_vertices: u32,
    cap_indices: u32,
    dark_caps: bool,
}

/// See the module documentation.
pub struct CpuSilhouette {
    /// [z-fail, z-pass].
    sides: [wgpu::RenderPipeline; 2],
    light_caps: wgpu::RenderPipeline,
    dark_caps: wgpu::RenderPipeline,
    prepared: Option<SceneId>,
    /// The scene's position buffer (the caps' vertices).
    positions: Option<wgpu::Buffer>,
    lights: Vec<PerLight>,
}

impl CpuSilhouette {
    /// Pipelines for the pass formats of `common`.
    pub(crate) fn new(device: &wgpu::Device, common: &Common) -> Self {
        let module = Common::module(device, "cpu-silhouette cpu_draw.wgsl", &["enable clip_distances;", VOLUME, DRAW]);
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("cpu-silhouette"),
            bind_group_layouts: &[Some(&common.light_layout)],
            immediate_size: 0,
        });
        let vec4 = [wgpu::VertexAttribute { format: wgpu::VertexFormat::Float32x4, offset: 0, shader_location: 0 }];
        let vec3 = [wgpu::VertexAttribute { format: wgpu::VertexFormat::Float32x3, offset: 0, shader_location: 0 }];
        let vertex = |attributes, stride| {
            [Some(wgpu::VertexBufferLayout {
                array_stride: stride,
                step_mode: wgpu::VertexStepMode::Vertex,
                attributes,
            })]
        };
        let homogeneous = vertex(&vec4[..], 16);
        let positions = vertex(&vec3[..], 12);
        let (ccw, cw) = (wgpu::FrontFace::Ccw, wgpu::FrontFace::Cw);
        let pipeline = |label, entry, buffers: &[Option<wgpu::VertexBufferLayout<'_>>], zpass, front| {
            common.counting_pipeline(device, label, &module, entry, &layout, buffers, zpass, front)
        };
        Self {
            sides: [false, true].map(|zpass| pipeline("cpu-silhouette sides", "vs_sides", &homogeneous, zpass, ccw)),
            light_caps: pipeline("cpu-silhouette light caps", "vs_light_caps", &positions, false, ccw),
            // Reason: the dark cap must face out of the volume (P0inf P2inf P1inf): the same
            // indices as the light cap with the winding reversed by the front face.
            dark_caps: pipeline("cpu-silhouette dark caps", "vs_dark_caps", &positions, false, cw),
            prepared: None,
            positions: None,
            lights: Vec::new(),
        }
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
        self.positions = Some(scene.position_buffer().clone());
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
                volume: IndexedVolume::default(),
                sides: StreamBuffer::new("cpu-silhouette sides", wgpu::BufferUsages::VERTEX),
                caps: StreamBuffer::new("cpu-silhouette caps", wgpu::BufferUsages::INDEX),
                side_vertices: 0,
                cap_indices: 0,
                dark_caps: false,
            });
        }
        common.write_slot(queue, frame.slot, &frame.data);
        let light = frame.data.light;
        let l = &mut self.lights[frame.slot];
        let caps = !frame.plan.zpass;
        extract_indexed(scene.mesh(), scene.adjacency(), scene.slots()?, light, caps, &mut l.volume);
        l.sides.write(device, queue, bytemuck::cast_slice(&l.volume.sides))?;
        l.caps.write(device, queue, bytemuck::cast_slice(&l.volume.caps))?;
        l.side_vertices = l.volume.sides.len() as u32;
        l.cap_indices = if caps { 3 * l.volume.caps.len() as u32 } else { 0 };
        l.dark_caps = has_dark_caps(light);
        Ok(())
    }

    fn draw(&self, pass: &mut wgpu::RenderPass<'_>, common: &Common, slot: usize, plan: LightPlan) {
        let Some(l) = self.lights.get(slot) else { return };
        let (Some(sides), Some(caps), Some(positions)) = (&l.sides.buffer, &l.caps.buffer, &self.positions) else {
            return;
        };
        common.bind_slot_render(pass, slot);
        if l.side_vertices > 0 {
            pass.set_pipeline(&self.sides[plan.zpass as usize]);
            pass.set_vertex_buffer(0, sides.slice(..));
            pass.draw(0..l.side_vertices, 0..1);
        }
        if !plan.zpass && l.cap_indices > 0 {
            pass.set_vertex_buffer(0, positions.slice(..));
            pass.set_index_buffer(caps.slice(..), wgpu::IndexFormat::Uint32);
            pass.set_pipeline(&self.light_caps);
            pass.draw_indexed(0..l.cap_indices, 0, 0..1);
            if l.dark_caps {
                pass.set_pipeline(&self.dark_caps);
                pass.draw_indexed(0..l.cap_indices, 0, 0..1);
            }
        }
    }

    fn gpu_bytes(&self) -> u64 {
        self.lights.iter().map(|l| l.sides.bytes() + l.caps.bytes()).sum()
    }
}
